//! The minimal embedding of pdm-kernel in Cortex-M firmware (README "Embedding"): the paper's
//! sphere → floor form factor in f32, printed over semihosting. run.sh builds and runs it.
//!
//! Cargo.toml: pdm-kernel = { path = "…", default-features = false }, cortex-m (feature
//! critical-section-single-core), cortex-m-rt, cortex-m-semihosting; memory.x and `-Tlink.x`.

#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use pdm_kernel::{
    surface_form_factor, vec3, Parallelogram, PatchGrid, PdmError, Quadrature, Sphere,
};

/// Unit sphere at the origin → floor of the cube of side 6 (≈ 1/6). Order 5 needs sample
/// buffers of 5² = 25 (the `25`); the sphere is its own occluder.
fn sphere_to_floor() -> Result<f32, PdmError> {
    let sphere = Sphere::outer(vec3(0.0_f32, 0.0, 0.0), 1.0)?;
    let floor = Parallelogram::new(
        vec3(-3.0_f32, -3.0, -3.0),
        vec3(6.0, 0.0, 0.0),
        vec3(0.0, 6.0, 0.0),
    )?;
    surface_form_factor::<f32, _, _, _, 25>(
        PatchGrid::new(&sphere, 4, 8)?,
        PatchGrid::new(&floor, 3, 3)?,
        Quadrature::uniform(5),
        &sphere,
    )
}

#[entry]
fn main() -> ! {
    match sphere_to_floor() {
        Ok(f) => hprintln!("F(sphere -> floor) = {}", f),
        Err(e) => hprintln!("error: {}", e),
    }
    debug::exit(debug::EXIT_SUCCESS);
    loop {}
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {}
}
