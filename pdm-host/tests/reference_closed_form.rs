//! Closed-form references against the REFERENCES.md 16-digit values (Howell's catalogue).

// Test code: panicking on failure and indexing fixed-size test data is intended.
#![allow(clippy::panic, clippy::indexing_slicing, clippy::excessive_precision, clippy::unreadable_literal)]

use pdm_host::reference::closed_form::*;
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn c11_unit_squares() {
    // C-11, unit squares at distance 1.
    let f = parallel_rectangles(1.0, 1.0, 1.0);
    assert!(rel(f, 0.1998248956983874) < 2e-15, "{f:.17}");
    // scale invariance
    assert!(rel(parallel_rectangles(6.0, 6.0, 6.0), f) < 2e-15);
}

#[test]
fn c14_unit_squares_and_cube_sum_rule() {
    // C-14, unit squares with a common edge.
    let f14 = perpendicular_rectangles(1.0, 1.0, 1.0);
    assert!(rel(f14, 0.2000437760754032) < 2e-15, "{f14:.17}");
    let f11 = parallel_rectangles(1.0, 1.0, 1.0);
    // cube: 4·F_adj + F_opp = 1
    assert!((4.0 * f14 + f11 - 1.0).abs() < 1e-15, "{}", 4.0 * f14 + f11 - 1.0);
}

#[test]
fn c14_reciprocity() {
    for &(l, w, h) in &[(1.0, 2.0, 0.5), (3.0, 0.1, 7.0), (1.0, 1.0, 100.0), (0.2, 5.0, 1.3)] {
        let fwh = perpendicular_rectangles(l, w, h);
        let fhw = perpendicular_rectangles(l, h, w);
        assert!(rel(w * fwh, h * fhw) < 1e-14, "{l} {w} {h}: {} {}", w * fwh, h * fhw);
    }
}

#[test]
fn c41_coaxial_disks() {
    let f = coaxial_disks(1.0, 1.0, 1.0);
    assert!(rel(f, 0.3819660112501052) < 2e-15, "{f:.17}");
    assert!(rel(f, (3.0 - 5f64.sqrt()) / 2.0) < 2e-15);
    // reciprocity r1² F12 = r2² F21
    let (r1, r2, h) = (0.7, 2.3, 1.1);
    assert!(rel(r1 * r1 * coaxial_disks(r1, r2, h), r2 * r2 * coaxial_disks(r2, r1, h)) < 1e-14);
}

#[test]
fn sphere_to_cube_face_is_one_sixth() {
    for side in [1.0, 6.0] {
        let face = cube_top_face(side);
        let f = sphere_to_polygon([0.0; 3], &face);
        assert!(rel(f, 1.0 / 6.0) < 1e-15, "{f}");
    }
    // all six faces sum to 4π
    let h = 3.0;
    let faces: [[[f64; 3]; 4]; 6] = [
        [[-h, -h, h], [h, -h, h], [h, h, h], [-h, h, h]],
        [[-h, -h, -h], [h, -h, -h], [h, h, -h], [-h, h, -h]],
        [[-h, h, -h], [h, h, -h], [h, h, h], [-h, h, h]],
        [[-h, -h, -h], [h, -h, -h], [h, -h, h], [-h, -h, h]],
        [[h, -h, -h], [h, h, -h], [h, h, h], [h, -h, h]],
        [[-h, -h, -h], [-h, h, -h], [-h, h, h], [-h, -h, h]],
    ];
    // an off-centre point: solid angles still sum to 4π
    let o = [0.4, -1.1, 2.2];
    let total: f64 = faces.iter().map(|f| polygon_solid_angle(o, f)).sum();
    assert!((total - 4.0 * PI).abs() < 1e-13, "{total}");
}

#[test]
fn triangle_solid_angle_octant() {
    // The triangle (e_x, e_y, e_z) subtends one octant, 4π/8, from the origin.
    let o = triangle_solid_angle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    assert!(rel(o, PI / 2.0) < 1e-15);
    let o2 = triangle_solid_angle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    assert!(rel(o2, -PI / 2.0) < 1e-15);
}

#[test]
fn sphere_identities() {
    // Face of a cube of side 6 → centred sphere of radius 1: π/54.
    let f = cube_face_to_centred_sphere(6.0, 1.0);
    assert!(rel(f, 0.05817764173314432) < 2e-15);
    assert!(rel(f, PI / 54.0) < 2e-15);
    // differential area → sphere
    assert!(rel(differential_area_to_sphere(1.0, 3.0, 0.0), 1.0 / 9.0) < 1e-15);
    assert!(rel(differential_area_to_sphere(1.0, 2.0, 0.5), 0.5f64.cos() / 4.0) < 1e-15);
    assert!(differential_area_to_sphere(1.0, 2.0, 1.2).is_nan()); // sphere cut by the horizon
                                                                  // inside of a sphere: F = A_j / (4πR²); a hemisphere sees half.
    let r = 2.0;
    let hemi = sphere_zone_area(r, 0.0, r);
    assert!(rel(sphere_interior_factor(r, hemi), 0.5) < 1e-15);
    assert!(rel(sphere_patch_area(r, 0.0, PI, 0.0, 2.0 * PI), 4.0 * PI * r * r) < 1e-15);
    assert!(rel(sphere_patch_area(r, 0.0, PI / 2.0, 0.0, 2.0 * PI), hemi) < 1e-15);
    assert!(rel(sphere_interior_kernel(r) * 4.0 * PI * r * r, 1.0) < 1e-15);
    assert!(rel(cylinder_band_area(1.5, -1.0, 2.0), 2.0 * PI * 1.5 * 3.0) < 1e-15);
    assert!(rel(cylinder_patch_area(1.5, 0.0, 2.0 * PI, -1.0, 2.0), cylinder_band_area(1.5, -1.0, 2.0)) < 1e-15);
}
