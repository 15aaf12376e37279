//! f32 error estimates far from the origin (BENCHMARKS.md, "Far from the origin"): thirteen pair
//! kinds at random placements 10 to 10⁵ sizes from the origin, each computed by
//! `adaptive_exchange` in f32 and, at the same placement, in f64 at tolerance 1e-11 (whose own
//! error, ≤ 1e-10 relative there, is far below f32's); prints per kind the least estimate /
//! actual error (below 1: an estimate below the error) and the largest relative error.
//!
//! `cargo run --release -p pdm-host --example far_from_origin -- [TOL] [PLACEMENTS] [SEED]`
//! (defaults 1e-4, 400 per kind, 987654321).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use pdm_kernel::*;

const NAMES: [&str; 14] = [
    "parallel cells",
    "parallel cells, diagonal",
    "perpendicular cells, shared edge",
    "perpendicular cells, apart",
    "skew parallelograms",
    "",
    "sphere cell over a square",
    "coaxial disks",
    "plates across a sphere",
    "cells sharing a corner",
    "cylinder cell and base-disk cell",
    "cells on a 10° fold (nearly coplanar)",
    "cells on a 2° fold (nearly coplanar)",
    "cells in a 10° V",
];
const CASES: [usize; 13] = [0, 1, 2, 3, 4, 6, 7, 8, 9, 10, 11, 12, 13];

/// Point `x` scaled by `k` and moved by `o`.
fn v<T: Real>(x: [f64; 3], k: f64, o: [f64; 3]) -> Vec3<T> {
    vec3(T::from_f64(x[0] * k + o[0]), T::from_f64(x[1] * k + o[1]), T::from_f64(x[2] * k + o[2]))
}
/// Vector `x` scaled by `k`.
fn d<T: Real>(x: [f64; 3], k: f64) -> Vec3<T> {
    vec3(T::from_f64(x[0] * k), T::from_f64(x[1] * k), T::from_f64(x[2] * k))
}
/// A parameter rectangle.
fn rect<T: Real>(t0: f64, t1: f64, s0: f64, s1: f64) -> surface::ParamRect<T> {
    surface::ParamRect::new(T::from_f64(t0), T::from_f64(t1), T::from_f64(s0), T::from_f64(s1)).unwrap()
}

/// Case `case` at scale `k`, moved by `o`: A_a·F_ab by `adaptive_exchange` at tolerance `tol`
/// (value, estimate, converged).
fn run<T: Real>(case: usize, k: f64, o: [f64; 3], tol: f64) -> Result<(f64, f64, bool), PdmError> {
    let settings = Adaptive { tolerance: T::from_f64(tol), max_order: 12, max_depth: 6, absolute: T::ZERO };
    macro_rules! ad {
        ($a:expr, $b:expr) => {{
            let e = adaptive_exchange::<T, _, _, _, 144>($a, $b, settings, &())?;
            Ok((e.value.to_f64(), e.error.unwrap().to_f64(), e.converged))
        }};
    }
    match case {
        // parallel squares, cells
        0 | 1 => {
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let c = Parallelogram::new(v::<T>([0., 0., 1.], k, o), d([0., 1., 0.], k), d([1., 0., 0.], k))?;
            let a = Patch::new(&f, rect(0.5, 1.0, 0.0, 0.5))?;
            let b = if case == 0 {
                Patch::new(&c, rect(0.0, 0.5, 0.5, 1.0))?
            } else {
                Patch::new(&c, rect(0.5, 1.0, 0.5, 1.0))?
            };
            ad!(&a, &b)
        }
        // perpendicular shared edge cells, and a non-touching perpendicular cell
        2 | 3 => {
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let w = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([0., 0., 1.], k), d([1., 0., 0.], k))?;
            let a = Patch::new(&f, rect(0.5, 1.0, 0.0, 0.5))?;
            let b = if case == 2 {
                Patch::new(&w, rect(0.0, 0.5, 0.5, 1.0))?
            } else {
                Patch::new(&w, rect(0.5, 1.0, 0.0, 0.5))?
            };
            ad!(&a, &b)
        }
        // skew general pair
        4 => {
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0.2, 0.], k), d([0.1, 1., 0.], k))?;
            let g = Parallelogram::new(v::<T>([0.3, -0.2, 0.7], k, o), d([0.2, 0.9, 0.5], k), d([1.0, 0.0, 0.3], k))?;
            let (a, b) = (Patch::whole(&f)?, Patch::whole(&g)?);
            ad!(&a, &b)
        }
        // sphere cell above a square
        6 => {
            let s = Sphere::new(v::<T>([0.5, 0.5, 1.0], k, o), T::from_f64(0.3 * k), surface::Side::Outer)?;
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let a = Patch::new(&s, rect(2.0, 3.0, 0.0, 1.5))?;
            let b = Patch::whole(&f)?;
            ad!(&a, &b)
        }
        // coaxial disks
        7 => {
            let p = Disk::new(v::<T>([0., 0., 0.], k, o), d([0., 0., 1.], 1.0), T::from_f64(0.5 * k))?;
            let q = Disk::new(v::<T>([0., 0., 0.8], k, o), d([0., 0., -1.], 1.0), T::from_f64(0.4 * k))?;
            let (a, b) = (Patch::whole(&p)?, Patch::whole(&q)?);
            ad!(&a, &b)
        }
        // plates across a sphere
        8 => {
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let c = Parallelogram::new(v::<T>([0., 0., 1.], k, o), d([0., 1., 0.], k), d([1., 0., 0.], k))?;
            let s = Sphere::new(v::<T>([0.4, 0.5, 0.5], k, o), T::from_f64(0.2 * k), surface::Side::Outer)?;
            let (a, b) = (Patch::whole(&f)?, Patch::whole(&c)?);
            let e = adaptive_exchange::<T, _, _, _, 144>(&a, &b, settings, &s)?;
            Ok((e.value.to_f64(), e.error.unwrap().to_f64(), e.converged))
        }
        // cells sharing a corner
        9 => {
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let a = Patch::new(&f, rect(0.0, 0.5, 0.0, 0.5))?;
            let g = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([-1., 0., 0.], k), d([0., 0., 1.], k))?;
            let bb = Patch::new(&g, rect(0.0, 0.5, 0.0, 0.5))?;
            ad!(&a, &bb)
        }
        // cylinder cell (inside) against its base disk cell
        10 => {
            let cyl = Cylinder::new(
                v::<T>([0., 0., 0.], k, o),
                d([0., 0., 1.], 1.0),
                T::from_f64(0.5 * k),
                T::from_f64(1.0 * k),
                surface::Side::Inner,
            )?;
            let p = Disk::new(v::<T>([0., 0., 0.], k, o), d([0., 0., 1.], 1.0), T::from_f64(0.5 * k))?;
            let a = Patch::new(&cyl, rect(0.0, 1.5, 0.2 * k, 0.6 * k))?;
            let b = Patch::new(&p, rect(0.0, 0.5 * k, 3.0, 5.0))?;
            ad!(&a, &b)
        }
        // cells sharing an edge, folded by `angle` out of a's plane (10°, 2°: nearly coplanar;
        // 170°: a narrow V)
        11..=13 => {
            let angle = [10f64, 2.0, 170.0][case - 11].to_radians();
            let f = Parallelogram::new(v::<T>([0., 0., 0.], k, o), d([1., 0., 0.], k), d([0., 1., 0.], k))?;
            let g = Parallelogram::new(
                v::<T>([1., 0., 0.], k, o),
                d([angle.cos(), 0., angle.sin()], k),
                d([0., 1., 0.], k),
            )?;
            let (a, b) = (Patch::new(&f, rect(0.5, 1.0, 0.0, 0.5))?, Patch::new(&g, rect(0.0, 0.5, 0.0, 0.5))?);
            ad!(&a, &b)
        }
        _ => unreachable!(),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tol: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e-4);
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(400);
    let mut seed: u64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(987_654_321);
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut least = [f64::MAX; 14];
    let mut largest = [0.0f64; 14];
    let mut refused = [0usize; 14];
    for _ in 0..n {
        for case in CASES {
            let k = [1.0, 0.01, 37.3][(rnd() * 3.0) as usize % 3];
            let m = 10f64.powf(1.0 + 4.0 * rnd());
            let dir = [rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0];
            let nd = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
            let o = [dir[0] / nd * m * k, dir[1] / nd * m * k, dir[2] / nd * m * k];
            match (run::<f64>(case, k, o, 1e-11), run::<f32>(case, k, o, tol)) {
                (Ok((reference, _, _)), Ok((value, estimate, _))) => {
                    let error = (value - reference).abs();
                    least[case] = least[case].min(estimate / error.max(f64::MIN_POSITIVE));
                    largest[case] = largest[case].max(error / reference.abs());
                }
                // f32 refuses contacts its coordinates cannot resolve (Err(Degenerate)).
                (Ok(_), Err(_)) => refused[case] += 1,
                (Err(e), _) => panic!("case {case} at {o:?}: f64 {e:?}"),
            }
        }
    }
    println!("{n} placements per kind, f32 tolerance {tol:e}");
    println!("{:<34} {:>16} {:>16} {:>8}", "pair", "least est/error", "largest error", "refused");
    for case in CASES {
        println!("{:<34} {:>16.2} {:>16.2e} {:>8}", NAMES[case], least[case], largest[case], refused[case]);
    }
}
