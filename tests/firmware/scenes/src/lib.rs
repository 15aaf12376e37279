//! The three f32 scenes the firmware computes. This crate is compiled twice: for the firmware
//! (Cortex-M4F, the kernel with the firmware's features) and for its build script (the build
//! machine, the kernel with host libm), which embeds its results as the expected values.

#![no_std]

use pdm_kernel::{vec3, Occluder, Parallelogram, Patch, PatchGrid, PdmError, Sphere, Surface};

/// Gauss order per axis on each patch (the paper's 5).
pub const ORDER: usize = 5;
/// Sample-buffer capacity: ORDER².
pub const CAP: usize = ORDER * ORDER;

// How the scenes reach the kernel (BUDGETS.md, "Flash"). By default every surface and occluder
// is passed as a trait object, so the kernel's sampling and summation code is instantiated once
// (for `dyn Surface<f32>` / `dyn Occluder<f32>`) and shared by the three scenes, as firmware that
// watches its flash would do; the `generic` feature passes the concrete types instead (one copy
// of the kernel code per combination of surface and occluder types). Same values either way.
#[cfg(not(feature = "generic"))]
macro_rules! surface {
    ($s:expr) => {
        $s as &dyn Surface<f32>
    };
}
#[cfg(feature = "generic")]
macro_rules! surface {
    ($s:expr) => {
        $s
    };
}
#[cfg(not(feature = "generic"))]
macro_rules! occluder {
    ($o:expr) => {
        $o as &dyn Occluder<f32>
    };
}
#[cfg(feature = "generic")]
macro_rules! occluder {
    ($o:expr) => {
        $o
    };
}

/// Surface form factor at order [`ORDER`] through the compile-time-order entry point (links
/// order 5's Gauss table only), or with the `runtime-order` feature through the `Quadrature` one.
/// Both give the same bits.
fn surface_ff<SA, SB, O>(
    a: PatchGrid<'_, f32, SA>,
    b: PatchGrid<'_, f32, SB>,
    occluders: &O,
) -> Result<f32, PdmError>
where
    SA: Surface<f32> + ?Sized,
    SB: Surface<f32> + ?Sized,
    O: Occluder<f32> + ?Sized,
{
    #[cfg(not(feature = "runtime-order"))]
    {
        pdm_kernel::fixed::surface_form_factor_fixed::<f32, _, _, _, ORDER, CAP>(a, b, occluders)
    }
    #[cfg(feature = "runtime-order")]
    {
        let q = pdm_kernel::Quadrature::uniform(ORDER);
        pdm_kernel::surface_form_factor::<f32, _, _, _, CAP>(a, b, q, occluders)
    }
}

/// Patch-to-patch form factor at order [`ORDER`] (see [`surface_ff`]).
fn patch_ff<SA, SB, O>(
    a: &Patch<'_, f32, SA>,
    b: &Patch<'_, f32, SB>,
    occluders: &O,
) -> Result<f32, PdmError>
where
    SA: Surface<f32> + ?Sized,
    SB: Surface<f32> + ?Sized,
    O: Occluder<f32> + ?Sized,
{
    #[cfg(not(feature = "runtime-order"))]
    {
        pdm_kernel::fixed::form_factor_between_fixed::<f32, _, _, _, ORDER, CAP>(a, b, occluders)
    }
    #[cfg(feature = "runtime-order")]
    {
        let q = pdm_kernel::Quadrature::uniform(ORDER);
        pdm_kernel::form_factor_between::<f32, _, _, _, CAP>(a, b, q, occluders)
    }
}

/// Number of scenes.
pub const COUNT: usize = 3;
/// Scene names, in the order of [`run`]'s index.
pub const NAMES: [&str; COUNT] = ["sphere_to_face", "shared_edge", "occluded_pair"];

/// The paper's scene: unit sphere at the origin, cube of side 6; sphere → floor face (z = −3,
/// facing +z), the sphere as its own occluder, grids 4 × 8 (sphere) and 3 × 3 (face). ≈ 1/6.
#[inline(never)]
pub fn sphere_to_face() -> Result<f32, PdmError> {
    let sphere = Sphere::outer(vec3(0.0_f32, 0.0, 0.0), 1.0)?;
    let floor = Parallelogram::new(
        vec3(-3.0_f32, -3.0, -3.0),
        vec3(6.0, 0.0, 0.0),
        vec3(0.0, 6.0, 0.0),
    )?;
    surface_ff(
        PatchGrid::new(surface!(&sphere), 4, 8)?,
        PatchGrid::new(surface!(&floor), 3, 3)?,
        occluder!(&sphere),
    )
}

/// Two perpendicular unit squares sharing the edge [0,1]×{0}×{0}: the floor (normal +z) and the
/// wall in the plane y = 0 (normal (0,0,1)×(1,0,0) = +y), facing each other. Exact 0.2000438;
/// the plain Gauss rule overestimates it at a shared edge (the integrand is singular there).
#[inline(never)]
pub fn shared_edge() -> Result<f32, PdmError> {
    let floor = Parallelogram::new(
        vec3(0.0_f32, 0.0, 0.0),
        vec3(1.0, 0.0, 0.0),
        vec3(0.0, 1.0, 0.0),
    )?;
    let wall = Parallelogram::new(
        vec3(0.0_f32, 0.0, 0.0),
        vec3(0.0, 0.0, 1.0),
        vec3(1.0, 0.0, 0.0),
    )?;
    patch_ff(
        &Patch::whole(surface!(&floor))?,
        &Patch::whole(surface!(&wall))?,
        occluder!(&()),
    )
}

/// Two parallel unit squares at distance 1 facing each other (0.1998 unoccluded), with a
/// 0.5 × 0.5 square occluder centred between them in the plane z = 0.5.
#[inline(never)]
pub fn occluded_pair() -> Result<f32, PdmError> {
    let lower = Parallelogram::new(
        vec3(0.0_f32, 0.0, 0.0),
        vec3(1.0, 0.0, 0.0),
        vec3(0.0, 1.0, 0.0),
    )?;
    let upper = Parallelogram::new(
        vec3(0.0_f32, 0.0, 1.0),
        vec3(0.0, 1.0, 0.0),
        vec3(1.0, 0.0, 0.0),
    )?;
    let blocker = Parallelogram::new(
        vec3(0.25_f32, 0.25, 0.5),
        vec3(0.5, 0.0, 0.0),
        vec3(0.0, 0.5, 0.0),
    )?;
    patch_ff(
        &Patch::whole(surface!(&lower))?,
        &Patch::whole(surface!(&upper))?,
        occluder!(&blocker),
    )
}

/// Scene `i` (0..COUNT).
pub fn run(i: usize) -> Result<f32, PdmError> {
    match i {
        0 => sphere_to_face(),
        1 => shared_edge(),
        _ => occluded_pair(),
    }
}
