//! Accuracy cost of the f32 math backends, measured on the same cases for libm and (when the
//! workspace is built with `--features pdm-kernel/micromath`) micromath. The backend in use is
//! read from `f32::ELEMENTARY_ERROR`. Run both:
//!
//! ```text
//! cargo test --release -p pdm-integration-tests --test precision_backends -- --nocapture
//! cargo test --release -p pdm-integration-tests --features pdm-kernel/micromath --test precision_backends -- --nocapture
//! ```

use pdm_host::reference::closed_form as exact;
use pdm_kernel::{
    form_factor_between, surface_form_factor, vec3, Disk, Parallelogram, Patch, PatchGrid, Quadrature, Real, Sphere,
};

fn micromath_active() -> bool {
    f32::ELEMENTARY_ERROR > 1e-4
}

/// (case, relative error) for the f32 kernel with the active backend.
fn measure() -> Vec<(&'static str, f64)> {
    let mut out = Vec::new();
    let o = vec3(0.0f32, 0.0, 0.0);
    let a = Parallelogram::new(o, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
    let b = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0)).unwrap();
    let f = form_factor_between::<f32, _, _, _, 256>(
        &Patch::whole(&a).unwrap(),
        &Patch::whole(&b).unwrap(),
        Quadrature::uniform(16),
        &(),
    )
    .unwrap();
    out.push((
        "C-11 unit squares (no elementary functions but sqrt)",
        rel(f as f64, exact::parallel_rectangles(1.0, 1.0, 1.0)),
    ));
    let d1 = Disk::new(o, vec3(0.0, 0.0, 1.0), 1.0).unwrap();
    let d2 = Disk::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, -1.0), 1.0).unwrap();
    let f = surface_form_factor::<f32, _, _, _, 400>(
        PatchGrid::new(&d1, 1, 4).unwrap(),
        PatchGrid::new(&d2, 1, 4).unwrap(),
        Quadrature::uniform(20),
        &(),
    )
    .unwrap();
    out.push(("C-41 coaxial disks (sin/cos of the angle)", rel(f as f64, exact::coaxial_disks(1.0, 1.0, 1.0))));
    let sphere = Sphere::outer(o, 1.0).unwrap();
    let floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let f = surface_form_factor::<f32, _, _, _, 64>(
        PatchGrid::new(&sphere, 8, 16).unwrap(),
        PatchGrid::new(&floor, 4, 4).unwrap(),
        Quadrature::uniform(8),
        &sphere,
    )
    .unwrap();
    out.push(("sphere -> cube face = 1/6, sphere as its own occluder", rel(f as f64, 1.0 / 6.0)));
    out
}

fn rel(got: f64, reference: f64) -> f64 {
    (got - reference).abs() / reference
}

#[test]
fn f32_backend_accuracy_cost() {
    let backend = if micromath_active() { "micromath" } else { "libm" };
    // Allowances: libm as in accuracy.rs; micromath as documented in pdm-kernel/src/math.rs.
    let allowed = if micromath_active() { 2e-3 } else { 1e-5 };
    for (case, e) in measure() {
        println!("f32 [{backend}] {case}: relative error {e:.2e} (allowed {allowed:.0e})");
        assert!(e < allowed, "{backend} {case}: {e:e}");
    }
}
