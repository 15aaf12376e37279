//! Whole faces across a shadow: the outer events placed into the outer rule
//! (`pdm_kernel::boundary`, "Outer-level events") make the form factor between two whole faces
//! of a cube with a sphere inside converge exponentially with the order, against the
//! independent host reference (`reference::cube::cube_face_factors`: closed-form chords, no
//! kernel code; its uncertainty is printed beside each value and is below 1e-14 here).
//!
//! The cubes are not the paper's (side 6, R = 1), so that no event curve passes exactly
//! through a patch corner by the scene's symmetry: side 6 with R = 1.3, side 4 with R = 1.1.
//! Sampling across the shadow events instead (the outer patch cut 3 × 3, as before the events)
//! is 2e-5 to 6e-5 off on the opposite faces at these orders.

#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use pdm_host::reference::cube::cube_face_factors;
use pdm_kernel::{pair_exchange, vec3, PairSettings, Parallelogram, Patch, Sphere};

/// A cube of side `side` centred at the origin with a sphere of `radius` at its centre: the
/// sphere, the floor (z = −side/2), the ceiling (z = +side/2) and a wall (x = −side/2), each
/// facing in (the faces of `reference::cube`).
fn cube(side: f64, radius: f64) -> (Sphere<f64>, [Parallelogram<f64>; 3]) {
    let h = side / 2.0;
    let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), radius).unwrap();
    let floor = Parallelogram::new(vec3(-h, -h, -h), vec3(side, 0.0, 0.0), vec3(0.0, side, 0.0)).unwrap();
    let ceiling = Parallelogram::new(vec3(-h, -h, h), vec3(0.0, side, 0.0), vec3(side, 0.0, 0.0)).unwrap();
    let wall = Parallelogram::new(vec3(-h, -h, -h), vec3(0.0, side, 0.0), vec3(0.0, 0.0, side)).unwrap();
    (sphere, [floor, ceiling, wall])
}

/// (F(floor → ceiling), F(floor → wall)) for whole faces at `order` (both orders).
fn whole_faces(side: f64, radius: f64, order: usize) -> (f64, f64) {
    let (sphere, [floor, ceiling, wall]) = cube(side, radius);
    let settings = PairSettings { order, singular_order: order, boundaries: true };
    let f = |other: &Parallelogram<f64>| {
        let e = pair_exchange::<f64, _, _, _, 1024>(
            &Patch::whole(&floor).unwrap(),
            &Patch::whole(other).unwrap(),
            settings,
            &sphere,
        )
        .unwrap();
        e.value / (side * side)
    };
    (f(&ceiling), f(&wall))
}

#[test]
fn whole_faces_across_a_sphere_converge_exponentially() {
    for (side, radius) in [(6.0, 1.3), (4.0, 1.1)] {
        let r = cube_face_factors(side, radius);
        assert!(r.f_opposite_error < 1e-13 && r.f_adjacent_error < 1e-13, "{r:?}");
        let rel = |v: f64, reference: f64| ((v - reference) / reference).abs();
        let (opp8, adj8) = whole_faces(side, radius, 8);
        let (opp12, adj12) = whole_faces(side, radius, 12);
        let errors =
            [rel(opp8, r.f_opposite), rel(adj8, r.f_adjacent), rel(opp12, r.f_opposite), rel(adj12, r.f_adjacent)];
        println!(
            "side {side}, R {radius}: order 8 opposite {:.1e} adjacent {:.1e}; order 12 {:.1e} {:.1e}",
            errors[0], errors[1], errors[2], errors[3]
        );
        // Measured: 7.8e-9 / 1.2e-8 / 1.1e-12 / 1.2e-11 (side 6) and 6.9e-9 / 2.5e-9 /
        // 2.6e-12 / 3.4e-12 (side 4).
        assert!(errors[0] < 1e-7 && errors[1] < 1e-7, "order 8: {errors:?}");
        assert!(errors[2] < 1e-10 && errors[3] < 1e-10, "order 12: {errors:?}");
    }
}

/// A sphere cut into cells against a tilted, offset rectangle cut into cells (the sphere's
/// cells outside with the point-to-polygon form: the circles where a cell's tangent plane
/// passes a corner of the rectangle's cell, and where it crosses that cell's plane, placed into
/// the outer rule), summed, against F = Ω/4π (the solid angle the rectangle subtends
/// at the centre: `reference::closed_form::sphere_to_polygon`, Van Oosterom–Strackee, no
/// kernel code). Neither the grid nor the placement is the paper's, so no cell edge lines up
/// with the rectangle.
fn sphere_cells_to_rectangle(order: usize) -> f64 {
    use pdm_kernel::ParamRect;
    let (centre, radius) = (vec3(0.2, -0.1, 0.3), 0.9);
    let sphere = Sphere::outer(centre, radius).unwrap();
    let (o, et, es) = (vec3(-1.7, -1.2, 2.1), vec3(3.1, 0.4, 0.5), vec3(-0.3, 2.6, 0.9));
    // Normal et × es points away from the sphere: the rectangle radiates towards it.
    let rect = Parallelogram::new(o, es, et).unwrap();
    let (m, n, k) = (6usize, 5usize, 3usize);
    let pi = std::f64::consts::PI;
    let settings = PairSettings { order, singular_order: order, boundaries: true };
    let mut total = 0.0;
    for i in 0..m {
        for j in 0..n {
            let cell = ParamRect::new(
                pi * i as f64 / m as f64,
                pi * (i + 1) as f64 / m as f64,
                2.0 * pi * j as f64 / n as f64,
                2.0 * pi * (j + 1) as f64 / n as f64,
            )
            .unwrap();
            let a = Patch::new(&sphere, cell).unwrap();
            for u in 0..k {
                for v in 0..k + 1 {
                    let part = ParamRect::new(
                        u as f64 / k as f64,
                        (u + 1) as f64 / k as f64,
                        v as f64 / (k + 1) as f64,
                        (v + 1) as f64 / (k + 1) as f64,
                    )
                    .unwrap();
                    let b = Patch::new(&rect, part).unwrap();
                    total += pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, &()).unwrap().value;
                }
            }
        }
    }
    total / (4.0 * pi * radius * radius)
}

#[test]
fn sphere_cells_to_a_tilted_rectangle_converge_exponentially() {
    use pdm_host::reference::closed_form::sphere_to_polygon;
    let p = |v: pdm_kernel::Vec3<f64>| [v.x, v.y, v.z];
    let (o, et, es) = (vec3(-1.7, -1.2, 2.1), vec3(3.1, 0.4, 0.5), vec3(-0.3, 2.6, 0.9));
    let exact = sphere_to_polygon([0.2, -0.1, 0.3], &[p(o), p(o + et), p(o + et + es), p(o + es)]);
    let rel = |v: f64| ((v - exact) / exact).abs();
    let (e6, e8, e12) =
        (rel(sphere_cells_to_rectangle(6)), rel(sphere_cells_to_rectangle(8)), rel(sphere_cells_to_rectangle(12)));
    println!("sphere cells -> tilted rectangle, F = {exact:.16}: order 6 {e6:.1e}, 8 {e8:.1e}, 12 {e12:.1e}");
    // Measured: 6.8e-10 / 5.1e-13 / 1.8e-16 at orders 6 / 8 / 12.
    assert!(e8 < 1e-11 && e12 < 1e-14, "{e6:.1e} {e8:.1e} {e12:.1e}");
}

/// The tolerance mode on sphere cells that see a cube face's cell only in a sliver (the paper's
/// sphere, R 1, 8 × 8 cells, against the face x = 3 cut 6 × 6): its estimate must cover its
/// error. The reference is the fixed-order pair at order 24, which agrees with order 20 to
/// 1e-12 on these pairs (checked here). Judging the route on 2 × 2 or 3 × 3 samples, as the
/// tolerance mode did from its geometric start order, missed the back-face cut on such pairs:
/// the plain sum's orders agreed on values 1e-3 off, with estimates of 3e-9.
#[test]
fn tolerance_mode_estimates_cover_sphere_cell_slivers() {
    use pdm_kernel::{adaptive_exchange, Adaptive, ParamRect};
    let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
    let face = Parallelogram::new(vec3(3.0, -3.0, -3.0), vec3(0.0, 0.0, 6.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let pi = std::f64::consts::PI;
    for (i, j, u, v) in [(6, 6, 2, 5), (6, 2, 1, 1), (0, 0, 2, 4), (2, 5, 3, 2), (7, 1, 2, 3), (3, 0, 3, 3)] {
        let cell = ParamRect::new(
            pi * i as f64 / 8.0,
            pi * (i + 1) as f64 / 8.0,
            pi * j as f64 / 4.0,
            pi * (j + 1) as f64 / 4.0,
        )
        .unwrap();
        let part = ParamRect::new(u as f64 / 6.0, (u + 1) as f64 / 6.0, v as f64 / 6.0, (v + 1) as f64 / 6.0).unwrap();
        let (a, b) = (Patch::new(&sphere, cell).unwrap(), Patch::new(&face, part).unwrap());
        let fixed = |order: usize| {
            let settings = PairSettings { order, singular_order: order, boundaries: true };
            pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, &()).unwrap().value
        };
        let reference = fixed(24);
        assert!(((fixed(20) - reference) / reference).abs() < 1e-12, "reference not converged");
        for tol in [1e-3, 1e-4, 1e-6, 1e-8] {
            let e = adaptive_exchange::<f64, _, _, _, 1024>(&a, &b, Adaptive::new(tol), &()).unwrap();
            let (actual, estimate) = ((e.value - reference).abs(), e.error.unwrap());
            assert!(
                actual <= estimate && (!e.converged || estimate <= tol * e.value),
                "cell ({i},{j}) face ({u},{v}) tol {tol:.0e}: off {:.1e}, estimate {:.1e}, converged {}",
                actual / reference,
                estimate / e.value,
                e.converged
            );
        }
    }
}

/// The floor of a cube (side 6, sphere R 1.3) cut into 3 × 3 cells against the whole ceiling,
/// summed, against the independent reference. The tangent planes through the ceiling's edges
/// meet the floor on the lines x, y = ±y₀ (the J(p) of a tangency, δ^{3/2}); the cuts are
/// placed `past` × the middle cell's width outside them (0: on them, where rounding puts the
/// event on either side of the cell's edge; 1e-4: just past them). A singularity just outside a cell is
/// as hard for the cell's rule as one inside: before the outer rule took the end piece through
/// it ("Events just outside a cell", FUZZING.md), the cells converged like p⁻³.
fn floor_cells_to_ceiling(past: f64, order: usize) -> f64 {
    use pdm_kernel::ParamRect;
    let (side, radius) = (6.0_f64, 1.3_f64);
    let h = side / 2.0;
    let (sphere, [floor, ceiling, _]) = cube(side, radius);
    // The line through (y, z) = (h, h) and (y₀, −h) tangent to the circle of radius R:
    // (h² − R²) y₀² + 2h(h² + R²) y₀ + h⁴ − 5R²h² = 0, the root inside the face.
    let (qa, qb, qc) =
        (h * h - radius * radius, 2.0 * h * (h * h + radius * radius), h.powi(4) - 5.0 * radius * radius * h * h);
    let y0 = ((-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa)).abs();
    assert!(y0 > 0.01 && y0 < h, "{y0}");
    let cut = y0 * (1.0 + 2.0 * past) / side;
    let edges = [0.0, 0.5 - cut, 0.5 + cut, 1.0];
    let settings = PairSettings { order, singular_order: order, boundaries: true };
    let b = Patch::whole(&ceiling).unwrap();
    let mut total = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let part = ParamRect::new(edges[i], edges[i + 1], edges[j], edges[j + 1]).unwrap();
            let a = Patch::new(&floor, part).unwrap();
            total += pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, &sphere).unwrap().value;
        }
    }
    total / (side * side)
}

#[test]
fn cells_with_a_tangency_on_or_just_past_their_edge_converge_exponentially() {
    let r = cube_face_factors(6.0, 1.3);
    assert!(r.f_opposite_error < 1e-13, "{r:?}");
    for past in [0.0, 1e-4] {
        let e: Vec<f64> =
            [12, 16].iter().map(|&o| ((floor_cells_to_ceiling(past, o) - r.f_opposite) / r.f_opposite).abs()).collect();
        println!("cuts {past:.0e} of a cell past the tangency lines: order 12 {:.1e}, 16 {:.1e}", e[0], e[1]);
        // Measured: 2.4e-11 / 2.0e-14 on the lines, 2.3e-11 / 1.6e-14 past them; with the end
        // pieces not taken through the events, 2.6e-8 / 6.3e-9 and 5.2e-8 / 1.3e-8.
        assert!(e[0] < 1e-10 && e[1] < 1e-12, "{e:?}");
    }
}

/// The floor and the ceiling of the cube (side 6, sphere R 1) each cut 5 × 5, every cell pair
/// summed, against the independent reference. From most floor points the sphere hides much of
/// a ceiling cell, and the closed form of b's directions minus the sphere's cone cancels 18–30
/// times there: with that taken as too much (16), those points took the lines, whose error
/// falls only slowly with the order (1.9e-11 at order 10).
#[test]
fn cells_across_a_sphere_take_its_shadow_in_closed_form() {
    use pdm_kernel::ParamRect;
    let (side, radius, n) = (6.0_f64, 1.0_f64, 5usize);
    let r = cube_face_factors(side, radius);
    assert!(r.f_opposite_error < 1e-13, "{r:?}");
    let (sphere, [floor, ceiling, _]) = cube(side, radius);
    let cells = |s| {
        (0..n * n).map(move |k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            let m = n as f64;
            Patch::new(s, ParamRect::new(i / m, (i + 1.0) / m, j / m, (j + 1.0) / m).unwrap()).unwrap()
        })
    };
    let settings = PairSettings { order: 10, singular_order: 10, boundaries: true };
    let mut total = 0.0;
    for a in cells(&floor) {
        for b in cells(&ceiling) {
            total += pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, &sphere).unwrap().value;
        }
    }
    let e = ((total / (side * side) - r.f_opposite) / r.f_opposite).abs();
    println!("floor 5 x 5 -> ceiling 5 x 5 past R 1, order 10: {e:.1e}");
    // Measured: 9.3e-13 (1.9e-11 with the cancellation limit at 16).
    assert!(e < 5e-12, "{e:.1e}");
}
