//! One pair of patches by `pair_exchange`: time per pair and relative error against the
//! closed form, for the flat pairs the contour form takes and the transform it replaced.
//!
//! `cargo bench -p pdm-host --bench pair -- --warm-up-time 1 --measurement-time 3`
//!
//! Cases (closed forms from `pdm_host::reference::closed_form`, `../shared/REFERENCES.md`):
//! the four flat pairs of issue 12's comparison with NIST View3D (a unit floor square
//! [0,1]² at z = 0 against)
//! - `c11`: the parallel unit square at distance 1 (C-11);
//! - `c14`: the perpendicular unit square sharing an edge (C-14, F = 0.2000437760754…); also
//!   by the edge transform (`touching_exchange`, 6·p⁴ kernel evaluations) that the contour
//!   form replaced for flat pairs (`c14/edge-transform`);
//! - `corner`: the wall square x ∈ [1, 2], z ∈ [0, 1] in the plane y = 1, sharing only the
//!   corner (1, 1, 0) (view-factor algebra on C-14: F(l = 2) − F(l = 1));
//! - `skew`: a unit square tilted 30° about a diagonal axis above it, no two edges parallel
//!   (corners below; reference: the host's independent contour integral
//!   `reference::contour::polygon_form_factor`, which an mpmath computation at 35 digits
//!   confirms to 1e-16);
//! - `c41`: coaxial unit disks 0.01 apart, whole (C-41; cut into 4 × 4 piece pairs, the contour
//!   form along the curved edges);
//! - `c14-back-to-back`: C-14's squares with the wall radiating away from the floor (exactly 0).
//!
//! - `half-wall-0.1`: half a cylinder wall (radius 0.5, height 1) standing 0.1 above a 4 × 4
//!   floor: curved against flat, straddling the back-face cut and near; the inner integral over
//!   the floor from each wall point by the point-to-polygon form (no closed form: the error
//!   printed is the difference from order 24);
//! - `disk-wall-0.1`: a whole unit disk 0.1 below a whole cylinder wall of radius 1 and height
//!   1 (the C-41 algebra, F(disk → disk at 0.1) − F(disk → disk at 1.1)); the inner integral over
//!   the disk by the point form along its outline.
//!
//! The relative errors and evaluation counts are printed once per case before timing.
//! Single-threaded.

#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pdm_host::reference::closed_form::{coaxial_disks, parallel_rectangles, perpendicular_rectangles};
use pdm_host::reference::contour::polygon_form_factor;
use pdm_kernel::internals::{classify_near, touching_exchange};
use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, Parallelogram, Patch, Quadrilateral};

/// The skew square's corners (counter-clockwise about its normal, which faces the floor).
const SKEW: [[f64; 3]; 4] = [
    [0.1, -0.1, 1.2],
    [0.16698729810778068, 0.8330127018922193, 0.8464466094067262],
    [1.1, 0.9, 1.2],
    [1.0330127018922193, -0.033012701892219325, 1.5535533905932737],
];

fn settings(order: usize) -> PairSettings {
    PairSettings { order, singular_order: order, boundaries: true }
}

fn bench_pairs(c: &mut Criterion) {
    let quad = |p: [[f64; 3]; 4]| Quadrilateral::new(p.map(|[x, y, z]| vec3(x, y, z))).unwrap();
    let floor_corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let floor = quad(floor_corners);
    let walls = [
        (
            "c11",
            [[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]],
            parallel_rectangles(1.0, 1.0, 1.0),
        ),
        (
            "c14",
            [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 0.0]],
            perpendicular_rectangles(1.0, 1.0, 1.0),
        ),
        (
            "corner",
            [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [2.0, 1.0, 1.0], [1.0, 1.0, 1.0]],
            perpendicular_rectangles(2.0, 1.0, 1.0) - perpendicular_rectangles(1.0, 1.0, 1.0),
        ),
        ("skew", SKEW, polygon_form_factor(&floor_corners, &SKEW)),
    ];
    let pf = Patch::whole(&floor).unwrap();
    let mut group = c.benchmark_group("pair");
    for (name, corners, exact) in walls {
        let wall = quad(corners);
        let pw = Patch::whole(&wall).unwrap();
        for order in [2, 3, 4, 6, 8] {
            if name != "skew" && order != 2 && order != 8 {
                continue;
            }
            let e = pair_exchange::<f64, _, _, _, 64>(&pf, &pw, settings(order), &()).unwrap();
            eprintln!(
                "{name} order {order}: relative error {:.1e}, {} evaluations",
                (e.value - exact).abs() / exact,
                e.evaluations
            );
            let s = settings(order);
            group.bench_with_input(BenchmarkId::new(name, order), &order, |bench, _| {
                bench.iter(|| pair_exchange::<f64, _, _, _, 64>(black_box(&pf), black_box(&pw), s, &()).unwrap().value);
            });
        }
    }
    // The edge transform the contour form replaced, on C-14.
    let square = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
    let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0)).unwrap();
    let (ps, pw) = (Patch::whole(&square).unwrap(), Patch::whole(&wall).unwrap());
    let (adjacency, gap) = classify_near(&ps, &pw);
    let c14 = perpendicular_rectangles(1.0, 1.0, 1.0);
    for order in [8, 12] {
        let transform = touching_exchange(&ps, &pw, adjacency, gap, order, &()).unwrap();
        eprintln!("c14 edge transform order {order}: relative error {:.1e}", (transform - c14).abs() / c14);
        group.bench_with_input(BenchmarkId::new("c14/edge-transform", order), &order, |bench, _| {
            bench.iter(|| touching_exchange(black_box(&ps), black_box(&pw), adjacency, gap, order, &()).unwrap());
        });
    }
    let lower = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0).unwrap();
    let upper = Disk::new(vec3(0.0, 0.0, 0.01), vec3(0.0, 0.0, -1.0), 1.0).unwrap();
    let (pl, pu) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
    let disks = std::f64::consts::PI * coaxial_disks(1.0, 1.0, 0.01);
    for order in [8, 12, 16] {
        let s = settings(order);
        let coaxial = pair_exchange::<f64, _, _, _, 256>(&pl, &pu, s, &()).unwrap().value;
        eprintln!("c41 disks at 0.01, order {order}: relative error {:.1e}", (coaxial - disks).abs() / disks);
        group.bench_with_input(BenchmarkId::new("c41-0.01/contour", order), &order, |bench, _| {
            bench.iter(|| pair_exchange::<f64, _, _, _, 256>(black_box(&pl), black_box(&pu), s, &()).unwrap().value);
        });
    }
    // The wall radiating away from the floor: back to back, exactly 0.
    let back = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0)).unwrap();
    let pk = Patch::whole(&back).unwrap();
    let s = settings(8);
    assert_eq!(pair_exchange::<f64, _, _, _, 256>(&ps, &pk, s, &()).unwrap().value, 0.0);
    group.bench_with_input(BenchmarkId::new("c14-back-to-back", 8), &8, |bench, _| {
        bench.iter(|| pair_exchange::<f64, _, _, _, 256>(black_box(&ps), black_box(&pk), s, &()).unwrap().value);
    });
    group.finish();
    near_flat(c);
    sphere_cells(c);
}

fn near_flat(c: &mut Criterion) {
    use pdm_kernel::{Cylinder, ParamRect, Side};
    let up = vec3(0.0, 0.0, 1.0);
    let half_wall = Cylinder::new(vec3(0.0, 0.0, 0.1), up, 0.5, 1.0, Side::Outer).unwrap();
    let big_floor = Parallelogram::new(vec3(-2.0, -2.0, 0.0), vec3(4.0, 0.0, 0.0), vec3(0.0, 4.0, 0.0)).unwrap();
    let ph = Patch::new(&half_wall, ParamRect { t0: 0.0, t1: std::f64::consts::PI, s0: 0.0, s1: 1.0 }).unwrap();
    let pb = Patch::whole(&big_floor).unwrap();
    let disk = Disk::new(vec3(0.0, 0.0, 0.0), up, 1.0).unwrap();
    let wall = Cylinder::new(vec3(0.0, 0.0, 0.1), up, 1.0, 1.0, Side::Inner).unwrap();
    let (pd, pw) = (Patch::whole(&disk).unwrap(), Patch::whole(&wall).unwrap());
    let disk_wall = std::f64::consts::PI * (coaxial_disks(1.0, 1.0, 0.1) - coaxial_disks(1.0, 1.0, 1.1));
    let wall_24 = pair_exchange::<f64, _, _, _, 625>(&ph, &pb, settings(24), &()).unwrap().value;
    let mut group = c.benchmark_group("pair");
    group.sample_size(10);
    for order in [12, 16] {
        let s = PairSettings { order, singular_order: 12, boundaries: true };
        let w = pair_exchange::<f64, _, _, _, 256>(&ph, &pb, s, &()).unwrap().value;
        let d = pair_exchange::<f64, _, _, _, 256>(&pd, &pw, s, &()).unwrap().value;
        eprintln!(
            "order {order}: half wall 0.1 above a floor {:.1e} (against order 24), disk 0.1 below a wall {:.1e}",
            (w - wall_24).abs() / wall_24,
            (d - disk_wall).abs() / disk_wall
        );
        group.bench_with_input(BenchmarkId::new("half-wall-0.1", order), &order, |bench, _| {
            bench.iter(|| pair_exchange::<f64, _, _, _, 256>(black_box(&ph), black_box(&pb), s, &()).unwrap().value);
        });
        group.bench_with_input(BenchmarkId::new("disk-wall-0.1", order), &order, |bench, _| {
            bench.iter(|| pair_exchange::<f64, _, _, _, 256>(black_box(&pd), black_box(&pw), s, &()).unwrap().value);
        });
    }
    group.finish();
}

/// A cell of the unit sphere (φ ∈ [π/2, 3π/4], θ ∈ [0, π/2]) against the floor cell of the
/// paper's cube below it (z = −3, x ∈ [1, 3], y ∈ [−1, 1]): with the sphere as occluder (the
/// boundary path, outer patch split 3 × 3) and without (the pair straddles the back-face cut);
/// and a cell of the bottom cap against a small floor cell (the plain sum). The same pairs as
/// the firmware's `pair_stack` example, here in f64. The value printed is A·F; no closed form.
fn sphere_cells(c: &mut Criterion) {
    use pdm_kernel::{ParamRect, Sphere};
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
    let floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let side = Patch::new(&sphere, ParamRect::new(FRAC_PI_2, 3.0 * FRAC_PI_4, 0.0, FRAC_PI_2).unwrap()).unwrap();
    let cap = Patch::new(&sphere, ParamRect::new(3.0 * FRAC_PI_4, PI, 0.0, FRAC_PI_2).unwrap()).unwrap();
    let cell = Patch::new(&floor, ParamRect::new(2.0 / 3.0, 1.0, 1.0 / 3.0, 2.0 / 3.0).unwrap()).unwrap();
    let small = Patch::new(&floor, ParamRect::new(0.45, 0.55, 0.45, 0.55).unwrap()).unwrap();
    let mut group = c.benchmark_group("sphere-cell");
    for order in [5, 8] {
        let s = PairSettings { order, singular_order: order, boundaries: true };
        let occluded = pair_exchange::<f64, _, _, _, 64>(&side, &cell, s, &sphere).unwrap().value;
        let straddling = pair_exchange::<f64, _, _, _, 64>(&side, &cell, s, &()).unwrap().value;
        let plain = pair_exchange::<f64, _, _, _, 64>(&cap, &small, s, &()).unwrap().value;
        eprintln!("order {order}: occluded {occluded:.16e}, straddling {straddling:.16e}, plain {plain:.16e}");
        group.bench_with_input(BenchmarkId::new("occluded", order), &order, |bench, _| {
            bench.iter(|| {
                pair_exchange::<f64, _, _, _, 64>(black_box(&side), black_box(&cell), s, &sphere).unwrap().value
            });
        });
        group.bench_with_input(BenchmarkId::new("straddling", order), &order, |bench, _| {
            bench.iter(|| pair_exchange::<f64, _, _, _, 64>(black_box(&side), black_box(&cell), s, &()).unwrap().value);
        });
        group.bench_with_input(BenchmarkId::new("plain", order), &order, |bench, _| {
            bench.iter(|| pair_exchange::<f64, _, _, _, 64>(black_box(&cap), black_box(&small), s, &()).unwrap().value);
        });
    }
    group.finish();
}

criterion_group!(benches, bench_pairs);
criterion_main!(benches);
