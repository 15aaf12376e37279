//! The general-geometry references themselves against closed forms: the ray estimator
//! (`reference::raytrace`) within 4σ at 1e6 rays, the deterministic 4-D integration
//! (`reference::direct`) to ~1e-12.

// Test code: panicking on failure is intended.
#![allow(clippy::panic, clippy::indexing_slicing, clippy::unreadable_literal)]

use pdm_host::reference::closed_form::{coaxial_disks, parallel_rectangles};
use pdm_host::reference::cube::cube_face_factors;
use pdm_host::reference::direct::{direct_form_factor, Bezier};
use pdm_host::reference::raytrace::{mc_form_factor, RtPatch, Scene};

const RAYS: u64 = 1_000_000;

fn scene(emitter: RtPatch, receiver: RtPatch, occluders: Vec<RtPatch>) -> Scene {
    Scene { emitter, receiver, occluders, emitter_occludes: false }
}

fn check_mc(name: &str, s: &Scene, exact: f64, seed: u64) {
    let Some(e) = mc_form_factor(s, RAYS, seed) else { panic!("{name}: no estimate") };
    let z = (e.value - exact) / e.std_error.max(1e-300);
    eprintln!("{name}: MC {:.6} ± {:.2e}, exact {exact:.10}, {z:+.2}σ", e.value, e.std_error);
    assert!(z.abs() <= 4.0, "{name}: {z:.2}σ");
}

fn unit_square(z: f64, up: bool) -> RtPatch {
    if up {
        RtPatch::parallelogram([0.0, 0.0, z], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    } else {
        RtPatch::parallelogram([0.0, 0.0, z], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
    }
}

#[test]
fn mc_c11_squares() {
    // C-11 unit squares at distance 1: 0.1998248956983874.
    let s = scene(unit_square(0.0, true), unit_square(1.0, false), vec![]);
    check_mc("C-11", &s, parallel_rectangles(1.0, 1.0, 1.0), 1);
    // Receiver facing away: every ray that reaches it hits its back, F = 0 exactly.
    let away = scene(unit_square(0.0, true), unit_square(1.0, true), vec![]);
    assert_eq!(mc_form_factor(&away, 100_000, 2).map(|e| e.value), Some(0.0));
    // An occluding square between them, larger than both: F = 0.
    let big = RtPatch::parallelogram([-1.0, -1.0, 0.5], [3.0, 0.0, 0.0], [0.0, 3.0, 0.0]);
    let blocked = scene(unit_square(0.0, true), unit_square(1.0, false), vec![big]);
    assert_eq!(mc_form_factor(&blocked, 100_000, 3).map(|e| e.value), Some(0.0));
}

#[test]
fn mc_c41_disks_and_the_wall_between() {
    // C-41 r1 = r2 = h = 1: (3 − √5)/2; the cylinder wall closing them: 1 − C-41.
    let Some(bottom) = RtPatch::disk([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0) else { panic!() };
    let Some(top) = RtPatch::disk([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 1.0) else { panic!() };
    let Some(wall) = RtPatch::cylinder([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0, 1.0, true) else { panic!() };
    let c41 = coaxial_disks(1.0, 1.0, 1.0);
    check_mc("C-41", &scene(bottom, top, vec![wall]), c41, 4);
    check_mc("disk → wall", &scene(bottom, wall, vec![top]), 1.0 - c41, 5);
    // The wall as emitter (reciprocity: A_wall F_wall→disk = A_disk (1 − C-41)).
    let wall_to_top = (1.0 - c41) * bottom.area() / wall.area();
    check_mc("wall → top", &scene(wall, top, vec![bottom]), wall_to_top, 6);
    // An annulus of the top disk and a sector of the bottom one (1/4 of the disk: by symmetry the
    // sector's factor to the whole top disk is C-41).
    let sector = bottom.sub(0.0, 1.0, 0.0, std::f64::consts::FRAC_PI_2);
    check_mc("sector → top", &scene(sector, top, vec![]), c41, 7);
    // Frustum closed by two disks of radii 1 (bottom) and 0.5 (top) at h = 1: the frustum's
    // inside receives 1 − C-41(1, 0.5, 1) of the bottom disk.
    let Some(small) = RtPatch::disk([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.5) else { panic!() };
    let Some(frustum) = RtPatch::cone([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0, 0.5, 1.0, true) else { panic!() };
    check_mc("disk → frustum", &scene(bottom, frustum, vec![small]), 1.0 - coaxial_disks(1.0, 0.5, 1.0), 8);
    check_mc("disk → small top", &scene(bottom, small, vec![frustum]), coaxial_disks(1.0, 0.5, 1.0), 9);
}

#[test]
fn mc_sphere_to_disk_and_the_cube() {
    // Sphere radius 0.5 centred 1 above a coaxial disk of radius 1:
    // F = ½(1 − 1/√(1 + (a/h)²)) (sphere → coaxial disk, the solid-angle form Ω/4π).
    let sphere = RtPatch::sphere([0.0, 0.0, 1.0], 0.5, false);
    let Some(disk) = RtPatch::disk([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0) else { panic!() };
    let exact = 0.5 * (1.0 - 1.0 / 2f64.sqrt());
    check_mc("sphere → disk", &scene(sphere, disk, vec![]), exact, 10);
    // The disk → sphere direction by reciprocity.
    check_mc("disk → sphere", &scene(disk, sphere, vec![]), exact * sphere.area() / disk.area(), 11);
    // The paper's cube, face 1 → face 6 with the sphere between (reference::cube, ≤ 3e-16).
    let reference = cube_face_factors(6.0, 1.0);
    let f1 = RtPatch::parallelogram([-3.0, -3.0, 3.0], [0.0, 6.0, 0.0], [6.0, 0.0, 0.0]);
    let f6 = RtPatch::parallelogram([-3.0, -3.0, -3.0], [6.0, 0.0, 0.0], [0.0, 6.0, 0.0]);
    let ball = RtPatch::sphere([0.0; 3], 1.0, false);
    check_mc("cube opposite", &scene(f1, f6, vec![ball]), reference.f_opposite, 12);
    check_mc("cube face → sphere", &scene(f1, ball, vec![]), std::f64::consts::PI / 54.0, 13);
}

#[test]
fn mc_is_reproducible() {
    let s = scene(unit_square(0.0, true), unit_square(1.0, false), vec![]);
    assert_eq!(mc_form_factor(&s, 200_000, 42), mc_form_factor(&s, 200_000, 42));
    assert_ne!(mc_form_factor(&s, 200_000, 42), mc_form_factor(&s, 200_000, 43));
}

#[test]
fn direct_against_closed_forms() {
    let f = direct_form_factor(&unit_square(0.0, true), &unit_square(1.0, false), 1e-13);
    let Some(f) = f else { panic!("C-11 not converged") };
    let exact = parallel_rectangles(1.0, 1.0, 1.0);
    eprintln!("direct C-11 {:.16} (est {:.1e}) exact {exact:.16}", f.value, f.error);
    assert!((f.value - exact).abs() < 1e-13);
    let Some(a) = RtPatch::disk([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0) else { panic!() };
    let Some(b) = RtPatch::annulus([0.0, 0.0, 1.5], [0.0, 0.0, -1.0], 0.0, 2.0) else { panic!() };
    let Some(f) = direct_form_factor(&a, &b, 1e-13) else { panic!("C-41 not converged") };
    let exact = coaxial_disks(1.0, 2.0, 1.5);
    eprintln!("direct C-41 {:.16} (est {:.1e}) exact {exact:.16}", f.value, f.error);
    assert!((f.value - exact).abs() < 1e-12);
    // A Bézier patch with a flat control net is the unit square: C-11 again.
    let mut control = [[[0.0; 3]; 4]; 4];
    for (i, row) in control.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            *p = [i as f64 / 3.0, j as f64 / 3.0, 0.0];
        }
    }
    let bez = Bezier { control, rect: [0.0, 1.0, 0.0, 1.0] };
    let Some(f) = direct_form_factor(&bez, &unit_square(1.0, false), 1e-13) else { panic!() };
    assert!((f.value - parallel_rectangles(1.0, 1.0, 1.0)).abs() < 1e-13, "{}", f.value);
}

#[test]
fn battery_flat_references_agree() {
    // The battery's nearly coincident squares and strips use C-11; the contour integral (an
    // independent method, well conditioned for small gaps) must give the same values.
    use pdm_host::reference::contour::polygon_form_factor;
    for gap in [1e-1, 1e-2, 1e-3, 1e-5, 1e-8] {
        let lo = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let hi = [[0.0, 0.0, gap], [0.0, 1.0, gap], [1.0, 1.0, gap], [1.0, 0.0, gap]];
        let (c, k) = (polygon_form_factor(&lo, &hi), parallel_rectangles(1.0, 1.0, gap));
        eprintln!("gap {gap:e}: contour {c:.15} C-11 {k:.15}");
        assert!(((c - k) / k).abs() < 1e-9, "gap {gap}: {c} vs {k}");
    }
    for a in [1e1, 1e2] {
        let b = 1.0 / a;
        let lo = [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]];
        let hi = [[0.0, 0.0, 1.0], [0.0, b, 1.0], [a, b, 1.0], [a, 0.0, 1.0]];
        let (c, k) = (polygon_form_factor(&lo, &hi), parallel_rectangles(a, b, 1.0));
        eprintln!("strip {a:e}: contour {c:.15e} C-11 {k:.15e}");
        assert!(((c - k) / k).abs() < 1e-9, "strip {a}: {c} vs {k}");
    }
    // MC at gap 0.1 as a third opinion (the kernel's 0.83527 would be 15σ away).
    let s = scene(unit_square(0.0, true), unit_square(0.1, false), vec![]);
    check_mc("C-11 gap 0.1", &s, parallel_rectangles(1.0, 1.0, 0.1), 14);
}
