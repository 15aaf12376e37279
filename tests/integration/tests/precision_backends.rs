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
    adaptive_exchange, form_factor_between, surface_exchange, surface_form_factor, vec3, Adaptive, Disk, Method,
    PairSettings, Parallelogram, Patch, PatchGrid, Quadrature, Real, Sphere,
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
    // Adjacent unit squares cut 3 x 3 each: the cells along the shared edge and corner go by
    // the contour form's closed edge pairs (ln, atan2), whose terms cancel up to 25x.
    let wall = Parallelogram::new(o, vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0)).unwrap();
    let settings = PairSettings { order: 8, singular_order: 12, boundaries: true };
    let e = surface_exchange::<f32, _, _, _, 256>(
        PatchGrid::new(&a, 3, 3).unwrap(),
        PatchGrid::new(&wall, 3, 3).unwrap(),
        Method::Pair(settings),
        &(),
    )
    .unwrap();
    out.push((
        "C-14 squares sharing an edge, 3 x 3 cells each (closed forms: ln, atan2)",
        rel(e.value as f64, exact::perpendicular_rectangles(1.0, 1.0, 1.0)),
    ));
    out
}

/// The tolerance mode's estimate covers the backend's error: whole sphere to a cube face
/// (A_s F = 4π/6) and one sphere cell that sees the face only near its terminator.
#[test]
fn f32_tolerance_mode_estimates_cover_the_backend() {
    let sphere = Sphere::outer(vec3(0.0f32, 0.0, 0.0), 1.0).unwrap();
    let floor = Parallelogram::new(vec3(-3.0f32, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let face = Patch::whole(&floor).unwrap();
    let whole = Patch::whole(&sphere).unwrap();
    let reference = 4.0 * core::f64::consts::PI / 6.0;
    for tol in [1e-2f32, 1e-4] {
        let e = adaptive_exchange::<f32, _, _, _, 144>(&whole, &face, Adaptive::new(tol), &()).unwrap();
        let (error, estimate) = ((e.value as f64 - reference).abs(), e.error.unwrap() as f64);
        println!(
            "sphere -> face, tolerance {tol:.0e}: error {:.2e}, estimate {:.2e}, converged {}",
            error / reference,
            estimate / reference,
            e.converged
        );
        assert!(error <= estimate, "tolerance {tol:e}: error {error:e} above the estimate {estimate:e}");
        assert!(!e.converged || error <= tol as f64 * reference);
    }
    // A cell just above the equator of the sphere's lower half facing away: it sees the floor
    // only in a sliver. Reference: the same pair in f64 (libm in every build).
    let cell = |s| ((0.45 * core::f64::consts::PI, 0.55 * core::f64::consts::PI), s);
    let ((p0, p1), _) = cell(0);
    let s64 = Sphere::outer(vec3(0.0f64, 0.0, 0.0), 1.0).unwrap();
    let f64floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let rect64 = pdm_kernel::ParamRect::new(p0, p1, 0.0, 0.5).unwrap();
    let r = adaptive_exchange::<f64, _, _, _, 144>(
        &Patch::new(&s64, rect64).unwrap(),
        &Patch::whole(&f64floor).unwrap(),
        Adaptive::new(1e-12),
        &(),
    )
    .unwrap();
    let rect = pdm_kernel::ParamRect::new(p0 as f32, p1 as f32, 0.0, 0.5).unwrap();
    let e =
        adaptive_exchange::<f32, _, _, _, 144>(&Patch::new(&sphere, rect).unwrap(), &face, Adaptive::new(1e-3), &())
            .unwrap();
    let (error, estimate) = ((e.value as f64 - r.value).abs(), e.error.unwrap() as f64);
    println!(
        "sphere cell at the terminator -> face: error {:.2e}, estimate {:.2e}",
        error / r.value,
        estimate / r.value
    );
    assert!(r.value > 0.0 && error <= estimate, "error {error:e} above the estimate {estimate:e}");
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
