//! Pins every entry point's value, bit for bit, on a fixed set of pairs that reaches each method
//! (plain sum, substructuring, self pair, edge and vertex transforms, contour form, visibility
//! boundaries with and without occluders, very near pairs, the tolerance mode), in f64 and f32.
//!
//! This is a regression pin for refactoring, not an accuracy claim: `pins.txt` holds the values
//! the kernel printed when it was last regenerated, and a change that is meant to leave every
//! method's arithmetic alone must reproduce them to the last digit. Accuracy is checked against
//! independent references elsewhere (`trust.rs`, `general_geometry.rs`, the battery).
//!
//! A change that is meant to alter values regenerates the file and says why in its commit:
//! `PDM_PIN_WRITE=1 cargo test --release -p pdm-integration-tests --test pins`.

use pdm_kernel::{
    adaptive_exchange, form_factor_between, pair_exchange, surface_exchange, surface_form_factor, vec3, Adaptive,
    AnyOccluder, BezierPatch, Cone, Cylinder, Disk, Method, PairSettings, Parallelogram, ParamRect, Patch, PatchGrid,
    Quadrature, Real, Side, Sphere, Vec3,
};
use std::fmt::Write as _;

fn v<T: Real>(x: f64, y: f64, z: f64) -> Vec3<T> {
    vec3(T::from_f64(x), T::from_f64(y), T::from_f64(z))
}

fn rect<T: Real>(t0: f64, t1: f64, s0: f64, s1: f64) -> ParamRect<T> {
    ParamRect { t0: T::from_f64(t0), t1: T::from_f64(t1), s0: T::from_f64(s0), s1: T::from_f64(s1) }
}

fn settings(order: usize, singular_order: usize) -> PairSettings {
    PairSettings { order, singular_order, boundaries: true }
}

/// `name = value` lines for one precision; the value is Rust's shortest round-trip form, or the
/// error's `Debug` form.
fn lines<T: Real + std::fmt::Debug>(label: &str) -> String {
    let mut out = String::new();
    let mut put = |name: &str, r: Result<String, pdm_kernel::PdmError>| {
        let text = r.unwrap_or_else(|e| format!("Err({e:?})"));
        writeln!(out, "{label} {name} = {text}").unwrap();
    };
    let fmt = |x: T| format!("{x:?}");
    let est = |e: pdm_kernel::Estimate<T>| {
        let error = e.error.map_or_else(|| "none".to_string(), |x| format!("{x:?}"));
        format!("{:?} ± {error} converged {} evals {}", e.value, e.converged, e.evaluations)
    };

    // Unit squares facing each other at distance 1 (C-11), and perpendicular ones sharing an edge
    // (C-14) or a vertex.
    let bottom = Parallelogram::new(v::<T>(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)).unwrap();
    let top = Parallelogram::new(v::<T>(0.0, 0.0, 1.0), v(0.0, 1.0, 0.0), v(1.0, 0.0, 0.0)).unwrap();
    let wall = Parallelogram::new(v::<T>(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)).unwrap();
    let corner = Parallelogram::new(v::<T>(1.0, 1.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 1.0)).unwrap();
    let pb = Patch::whole(&bottom).unwrap();
    let pt = Patch::whole(&top).unwrap();
    let pw = Patch::whole(&wall).unwrap();
    let pc = Patch::whole(&corner).unwrap();
    put("c11 plain 8", form_factor_between::<T, _, _, _, 64>(&pb, &pt, Quadrature::uniform(8), &()).map(fmt));
    put("c11 pair 12", pair_exchange::<T, _, _, _, 256>(&pb, &pt, settings(12, 12), &()).map(|e| e.value).map(fmt));
    put("c14 pair 8", pair_exchange::<T, _, _, _, 256>(&pb, &pw, settings(8, 8), &()).map(|e| e.value).map(fmt));
    put("c14 plain 8", form_factor_between::<T, _, _, _, 64>(&pb, &pw, Quadrature::uniform(8), &()).map(fmt));
    put("vertex pair 8", pair_exchange::<T, _, _, _, 256>(&pb, &pc, settings(8, 8), &()).map(|e| e.value).map(fmt));
    put("c14 tol 1e-5", adaptive_exchange::<T, _, _, _, 256>(&pb, &pw, Adaptive::new(T::from_f64(1e-5)), &()).map(est));

    // A sphere between the squares as occluder (boundary path with a curved occluder).
    let ball = Sphere::outer(v::<T>(0.5, 0.5, 0.5), T::from_f64(0.3)).unwrap();
    put(
        "c11 sphere-occluded plain 8",
        form_factor_between::<T, _, _, _, 64>(&pb, &pt, Quadrature::uniform(8), &ball).map(fmt),
    );
    put(
        "c11 sphere-occluded pair 10",
        pair_exchange::<T, _, _, _, 256>(&pb, &pt, settings(10, 10), &ball).map(|e| e.value).map(fmt),
    );
    let tube = Cylinder::new(v::<T>(-0.5, 0.5, 0.5), v(1.0, 0.0, 0.0), T::from_f64(0.2), T::from_f64(2.0), Side::Outer)
        .unwrap();
    let occ: [AnyOccluder<T>; 2] = [AnyOccluder::Sphere(ball), AnyOccluder::Cylinder(tube)];
    put(
        "c11 two-occluders pair 8",
        pair_exchange::<T, _, _, _, 256>(&pb, &pt, settings(8, 8), &occ[..]).map(|e| e.value).map(fmt),
    );
    put(
        "c11 sphere-occluded tol 1e-3",
        adaptive_exchange::<T, _, _, _, 256>(&pb, &pt, Adaptive::new(T::from_f64(1e-3)), &ball).map(est),
    );

    // Curved pairs: a sphere cell over a plate cell (straddling the back-face cut, then very near),
    // a sphere grid over a disk, the self pair of a cylinder's inside, a cone's base disk against
    // its wall (shared rim), a Bézier dome over a square.
    let plate = Parallelogram::new(v::<T>(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)).unwrap();
    let plate_cell = Patch::new(&plate, rect(0.5, 1.0, 0.0, 0.5)).unwrap();
    let pi = core::f64::consts::PI;
    for (label_gap, gap) in [("gap 1e-1", 1e-1), ("gap 1e-2", 1e-2)] {
        let s = Sphere::outer(v::<T>(0.95, 0.1, 0.3 + gap), T::from_f64(0.3)).unwrap();
        let cell = Patch::new(&s, rect(0.75 * pi, pi, 1.75 * pi, 2.0 * pi)).unwrap();
        put(
            &format!("sphere cell {label_gap} pair 12"),
            pair_exchange::<T, _, _, _, 256>(&cell, &plate_cell, settings(12, 12), &()).map(|e| e.value).map(fmt),
        );
        put(
            &format!("plate cell {label_gap} pair 12"),
            pair_exchange::<T, _, _, _, 256>(&plate_cell, &cell, settings(12, 12), &()).map(|e| e.value).map(fmt),
        );
    }
    let sphere = Sphere::outer(v::<T>(0.0, 0.0, 1.0), T::from_f64(0.5)).unwrap();
    let disk = Disk::new(v::<T>(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), T::from_f64(1.0)).unwrap();
    put(
        "sphere 2x4 -> disk 1x4 surface plain 8",
        surface_form_factor::<T, _, _, _, 64>(
            PatchGrid::new(&sphere, 2, 4).unwrap(),
            PatchGrid::new(&disk, 1, 4).unwrap(),
            Quadrature::uniform(8),
            &(),
        )
        .map(fmt),
    );
    let quarter_s = Patch::new(&sphere, rect(0.0, 0.5 * pi, 0.0, 0.5 * pi)).unwrap();
    let quarter_d = Patch::new(&disk, rect(0.0, 1.0, 0.0, 0.5 * pi)).unwrap();
    put(
        "sphere quarter -> disk quarter pair 12",
        pair_exchange::<T, _, _, _, 256>(&quarter_s, &quarter_d, settings(12, 12), &()).map(|e| e.value).map(fmt),
    );
    put(
        "disk quarter -> sphere quarter pair 12",
        pair_exchange::<T, _, _, _, 256>(&quarter_d, &quarter_s, settings(12, 12), &()).map(|e| e.value).map(fmt),
    );
    let inside =
        Cylinder::new(v::<T>(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), T::from_f64(0.5), T::from_f64(1.0), Side::Inner)
            .unwrap();
    let cell = Patch::new(&inside, rect(0.0, 0.5 * pi, 0.0, 0.5)).unwrap();
    put(
        "cylinder inside self pair 8",
        pair_exchange::<T, _, _, _, 256>(&cell, &cell, settings(8, 8), &()).map(|e| e.value).map(fmt),
    );
    let cone = Cone::new(
        v::<T>(0.0, 0.0, 0.0),
        v(0.0, 0.0, 1.0),
        T::from_f64(1.0),
        T::from_f64(0.4),
        T::from_f64(0.7),
        Side::Inner,
    )
    .unwrap();
    let base = Disk::new(v::<T>(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), T::from_f64(1.0)).unwrap();
    let wall_q = Patch::new(&cone, rect(0.0, 0.5 * pi, 0.0, 0.7)).unwrap();
    let base_q = Patch::new(&base, rect(0.0, 1.0, 0.0, 0.5 * pi)).unwrap();
    put(
        "cone base -> wall pair 8",
        pair_exchange::<T, _, _, _, 256>(&base_q, &wall_q, settings(8, 8), &()).map(|e| e.value).map(fmt),
    );
    let mut control = [[v::<T>(0.0, 0.0, 0.0); 4]; 4];
    for (i, row) in control.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            let (x, y) = (j as f64 / 3.0, i as f64 / 3.0);
            let z = 1.5 - 0.4 * (i == 1 || i == 2) as u8 as f64 * (j == 1 || j == 2) as u8 as f64;
            *c = v(x, y, z);
        }
    }
    let dome = BezierPatch::new(control).unwrap();
    let pd = Patch::whole(&dome).unwrap();
    put(
        "bezier -> square pair 10",
        pair_exchange::<T, _, _, _, 256>(&pd, &pb, settings(10, 10), &()).map(|e| e.value).map(fmt),
    );
    put(
        "square -> bezier plain 8",
        form_factor_between::<T, _, _, _, 64>(&pb, &pd, Quadrature::uniform(8), &()).map(fmt),
    );

    // Coaxial disks (contour form) and a disk closing a cylinder (shared rim).
    let upper = Disk::new(v::<T>(0.0, 0.0, 0.5), v(0.0, 0.0, -1.0), T::from_f64(0.8)).unwrap();
    let pu = Patch::whole(&upper).unwrap();
    let pdisk = Patch::whole(&disk).unwrap();
    put(
        "coaxial disks pair 12",
        pair_exchange::<T, _, _, _, 256>(&pdisk, &pu, settings(12, 12), &()).map(|e| e.value).map(fmt),
    );
    put(
        "coaxial disks tol 1e-7",
        adaptive_exchange::<T, _, _, _, 256>(&pdisk, &pu, Adaptive::new(T::from_f64(1e-7)), &()).map(est),
    );
    // Substructuring for every method: the disk cut 1 × 4 against a coaxial disk of radius 0.5
    // at height 0.5 facing it, cut 2 × 2.
    let upper = Disk::new(v::<T>(0.0, 0.0, 0.5), v(0.0, 0.0, -1.0), T::from_f64(0.5)).unwrap();
    let methods = [
        ("paper 6", Method::Paper(Quadrature::uniform(6))),
        ("plain 8", Method::Plain(Quadrature::uniform(8))),
        ("pair 10", Method::Pair(settings(10, 10))),
        ("tol 1e-6", Method::Tolerance(Adaptive::new(T::from_f64(1e-6)))),
    ];
    for (name, method) in methods {
        let (a, b) = (PatchGrid::new(&disk, 1, 4).unwrap(), PatchGrid::new(&upper, 2, 2).unwrap());
        put(
            &format!("disk 1x4 -> disk 2x2 surface_exchange {name}"),
            surface_exchange::<T, _, _, _, 256>(a, b, method, &()).map(est),
        );
    }
    out
}

#[test]
fn every_entry_point_reproduces_its_pinned_values() {
    let now = format!("{}{}", lines::<f64>("f64"), lines::<f32>("f32"));
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/pins.txt");
    if std::env::var_os("PDM_PIN_WRITE").is_some() {
        std::fs::write(path, &now).unwrap();
        return;
    }
    let pinned = std::fs::read_to_string(path).unwrap();
    let mut differ = 0;
    for (a, b) in pinned.lines().zip(now.lines()) {
        if a != b {
            println!("pinned: {a}\n   now: {b}");
            differ += 1;
        }
    }
    assert_eq!(pinned.lines().count(), now.lines().count(), "a different set of pins:\n{now}");
    assert_eq!(differ, 0, "{differ} values differ from the pins");
}

/// Substructuring adds its pairs' results in the grid's order: for every method, the value is
/// the sum of the single-pair entry points' values bit for bit, the error the sum of their
/// estimates (tolerance mode), and the work the sum of theirs.
#[test]
fn surface_exchange_is_the_sum_of_its_pairs() {
    // A disk and a smaller coaxial one facing it, a small square screen between them (the
    // tolerance mode without it: across an occluder it takes a minute here).
    let disk = Disk::new(v::<f64>(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), 1.0).unwrap();
    let upper = Disk::new(v::<f64>(0.0, 0.0, 0.6), v(0.0, 0.0, -1.0), 0.5).unwrap();
    let screen = Parallelogram::new(v::<f64>(-0.2, -0.2, 0.3), v(0.4, 0.0, 0.0), v(0.0, 0.4, 0.0)).unwrap();
    let (a, b) = (PatchGrid::new(&disk, 1, 3).unwrap(), PatchGrid::new(&upper, 2, 2).unwrap());
    let s = settings(8, 8);
    let tol = Adaptive::new(1e-5);
    let mut every_pair_converged = true;
    let (mut pair, mut pair_evals) = (0.0, 0u64);
    let (mut adaptive, mut adaptive_error, mut adaptive_evals) = (0.0, 0.0, 0u64);
    let mut first = true;
    for pa in a.clone() {
        for pb in b.clone() {
            let e = pair_exchange::<f64, _, _, _, 256>(&pa, &pb, s, &screen).unwrap();
            let t = adaptive_exchange::<f64, _, _, _, 256>(&pa, &pb, tol, &()).unwrap();
            // The first pair is the starting value (0.0 + x = x, so the two are the same).
            if first {
                (pair, adaptive, adaptive_error) = (e.value, t.value, t.error.unwrap());
                first = false;
            } else {
                pair += e.value;
                adaptive += t.value;
                adaptive_error += t.error.unwrap();
            }
            pair_evals += e.evaluations;
            adaptive_evals += t.evaluations;
            every_pair_converged &= t.converged;
        }
    }
    let by_pair = surface_exchange::<f64, _, _, _, 256>(a.clone(), b.clone(), Method::Pair(s), &screen).unwrap();
    assert_eq!((by_pair.value, by_pair.evaluations, by_pair.error), (pair, pair_evals, None));
    let by_tol = surface_exchange::<f64, _, _, _, 256>(a.clone(), b.clone(), Method::Tolerance(tol), &()).unwrap();
    assert_eq!((by_tol.value, by_tol.evaluations, by_tol.error), (adaptive, adaptive_evals, Some(adaptive_error)));
    let total_met = adaptive_error <= 1e-5 * adaptive;
    assert_eq!(by_tol.converged, every_pair_converged || total_met);
    // The paper's bare sum: `exchange` on each pair's samples, added in the same order.
    let (mut paper, mut first) = (0.0, true);
    for pa in a.clone() {
        let sa = pdm_kernel::PatchSamples::<f64, 64>::new(&pa, 6).unwrap();
        for pb in b.clone() {
            let sb = pdm_kernel::PatchSamples::<f64, 64>::new(&pb, 6).unwrap();
            let x = pdm_kernel::exchange(&sa, &sb, &screen).unwrap();
            paper = if first { x } else { paper + x };
            first = false;
        }
    }
    let by_paper =
        surface_exchange::<f64, _, _, _, 64>(a.clone(), b.clone(), Method::Paper(Quadrature::uniform(6)), &screen)
            .unwrap();
    assert_eq!((by_paper.value, by_paper.error, by_paper.converged), (paper, None, false));
    // A grid iterated to its end has no pair left: zero, no estimate, not converged.
    let mut spent = a.clone();
    spent.by_ref().for_each(drop);
    let empty = surface_exchange::<f64, _, _, _, 256>(spent, b.clone(), Method::Tolerance(tol), &()).unwrap();
    assert_eq!((empty.value, empty.error, empty.converged, empty.evaluations), (0.0, None, false, 0));
    // Settings are checked before the capacity.
    let bad = Adaptive { max_order: 40, ..tol };
    let refused = surface_exchange::<f64, _, _, _, 256>(a.clone(), b.clone(), Method::Tolerance(bad), &());
    assert!(matches!(refused, Err(pdm_kernel::PdmError::InvalidSetting { name: "max_order", .. })), "{refused:?}");
    // Too small a capacity is refused before any work.
    let small = surface_exchange::<f64, _, _, _, 64>(a, b, Method::Tolerance(tol), &screen);
    assert_eq!(small, Err(pdm_kernel::PdmError::CapacityExceeded { needed: 144, capacity: 64 }));
}
