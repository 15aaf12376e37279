//! pdm-kernel on a Cortex-M4F (thumbv7em-none-eabihf), run under
//! `qemu-system-arm -machine mps2-an386 -cpu cortex-m4` with semihosting.
//!
//! Computes three f32 scenes (scenes/src/lib.rs: the paper's sphere → face factor on a coarse grid,
//! a shared-edge pair, a pair with an occluder), compares each with the value the build machine
//! computed for the same input (embedded by build.rs), measures the peak stack of each
//! form-factor call by stack painting, prints everything and exits with status 0 only if every
//! value is within its tolerance.
//!
//! There is no `#[global_allocator]` and no `alloc` anywhere: the link itself proves the kernel
//! allocates nothing.
//!
//! Features: `micromath` (kernel f32 functions from micromath), `defmt` (log with defmt over
//! semihosting, to be decoded by `defmt-print -e ELF`), `baseline` (kernel calls replaced by an
//! opaque stand-in, for the flash measurement), `runtime-order` and `generic` (the scenes through
//! the kernel's run-time-order API, or with concrete types instead of trait objects: flash
//! comparisons). See run.sh and BUDGETS.md.

#![no_std]
#![no_main]

use pdm_firmware_scenes as scenes;

use core::hint::black_box;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::debug;
use pdm_kernel::PdmError;

#[cfg(feature = "defmt")]
use defmt_semihosting as _;

mod expected {
    include!(concat!(env!("OUT_DIR"), "/expected.rs"));
}

/// The math backend this build uses.
const BACKEND: &str = if cfg!(feature = "micromath") {
    "micromath"
} else {
    "libm"
};

/// Tolerance per scene of the libm build, in units in the last place (ulp) of f32 between the
/// firmware's value and the host's (both positive: the ulp distance is the difference of the
/// bit patterns). The same IEEE-754 f32 operations run in the same order on both machines (no
/// FMA contraction; libm's functions are plain Rust, sqrt correctly rounded), so the values are
/// expected to be bit-identical (measured: 0 ulp in every scene); 4 ulp (≈ 5e-7 relative)
/// leaves room for a libm routine that rounds differently on another host architecture.
const TOL_ULP_LIBM: [u32; scenes::COUNT] = [4, 4, 4];

/// Relative tolerance per scene of the micromath build against the host's libm value: the
/// accuracy cost of the backend, measured (BUDGETS.md). The two parallelogram scenes use no
/// elementary function whose micromath value differs (their sample points are affine and the
/// unit normals of unit squares are exact even with micromath's sqrt): measured 0, tolerance
/// 1e-6. The sphere scene: measured −7.0e-4 (micromath's sin/cos are good to ~1e-3; the kernel
/// refines its sqrt by Newton steps and widens the on-surface band of the occlusion test to the
/// backend's error), tolerance 2e-3, the kernel's stated `ELEMENTARY_ERROR` for micromath. That
/// the micromath firmware computes exactly what the host computes with micromath is checked
/// separately by run.sh (bit patterns, ≤ 4 ulp).
const TOL_REL_MICROMATH: [f32; scenes::COUNT] = [2e-3, 1e-6, 1e-6];

/// Whether `value` is within the stated tolerance of scene `i`'s host value.
fn within_tolerance(i: usize, value: f32, expected: f32) -> bool {
    if cfg!(feature = "micromath") {
        ((value - expected) / expected).abs() <= TOL_REL_MICROMATH[i]
    } else {
        ulp_distance(value, expected) <= TOL_ULP_LIBM[i]
    }
}

/// Pattern written below the stack pointer before a call; the lowest word that no longer holds
/// it marks the deepest stack use.
const PAINT: u32 = 0xDEAD_BEEF;
/// Bytes of RAM painted below the stack pointer (bounded by the end of .bss).
const PAINT_BYTES: usize = 64 * 1024;

extern "C" {
    /// End of .bss/.uninit (start of the unused RAM between statics and the stack), from link.x.
    static __sheap: u32;
}

/// One scene, in its own stack frame: the stack measured is everything below the caller's SP.
#[inline(never)]
fn call_scene(i: usize) -> Result<f32, PdmError> {
    #[cfg(not(feature = "baseline"))]
    {
        scenes::run(black_box(i))
    }
    #[cfg(feature = "baseline")]
    {
        // No kernel code: an opaque value that may be Ok or Err, so the reporting code stays.
        let bits = black_box(expected::EXPECTED_BITS[i % scenes::COUNT]);
        if black_box(i) > 1000 {
            black_box(Err(PdmError::NonFinite))
        } else {
            black_box(Ok(f32::from_bits(bits)))
        }
    }
}

/// Fills [bottom, SP − 64) with `PAINT` (SP of this leaf function; 64 bytes of margin).
#[inline(never)]
fn paint(bottom: usize) {
    let sp = cortex_m::register::msp::read() as usize;
    let top = (sp - 64) & !3;
    let mut p = bottom;
    while p < top {
        // SAFETY: [bottom, top) is RAM between the end of .bss and below this function's
        // stack frame; nothing else is live there (no interrupts are enabled).
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// Address of the lowest word in [bottom, top) that no longer holds `PAINT` (or `top`).
fn lowest_touched(bottom: usize, top: usize) -> usize {
    let mut p = bottom;
    while p < top {
        // SAFETY: reading RAM in the painted range, which is valid memory.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != PAINT {
            return p;
        }
        p += 4;
    }
    top
}

/// ulp distance between two finite f32 of the same sign.
fn ulp_distance(a: f32, b: f32) -> u32 {
    a.to_bits().abs_diff(b.to_bits())
}

struct Outcome {
    value: Result<f32, PdmError>,
    expected: f32,
    ulps: u32,
    stack: usize,
    ok: bool,
}

#[entry]
fn main() -> ! {
    // Only the address of the linker symbol is taken (no read).
    let heap_start = core::ptr::addr_of!(__sheap) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    let bottom = core::cmp::max((heap_start + 3) & !3, sp.saturating_sub(PAINT_BYTES) & !3);

    let mut all_ok = true;
    let mut max_stack = 0usize;
    start_log();
    for i in 0..scenes::COUNT {
        paint(bottom);
        let sp_call = cortex_m::register::msp::read() as usize;
        let value = call_scene(i);
        let stack = sp_call - lowest_touched(bottom, sp_call);
        let expected = f32::from_bits(expected::EXPECTED_BITS[i]);
        let (ulps, ok) = match value {
            Ok(v) if v.is_finite() => (ulp_distance(v, expected), within_tolerance(i, v, expected)),
            _ => (u32::MAX, false),
        };
        all_ok &= ok;
        max_stack = max_stack.max(stack);
        log_outcome(
            i,
            &Outcome {
                value,
                expected,
                ulps,
                stack,
                ok,
            },
        );
    }
    finish_log(max_stack, all_ok);
    debug::exit(if all_ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

// ---- logging: semihosting text (default) -------------------------------------------------

#[cfg(not(feature = "defmt"))]
fn start_log() {
    cortex_m_semihosting::hprintln!(
        "pdm-firmware: backend={} order={} cap={} baseline={}",
        BACKEND,
        scenes::ORDER,
        scenes::CAP,
        cfg!(feature = "baseline")
    );
}

#[cfg(not(feature = "defmt"))]
fn log_outcome(i: usize, o: &Outcome) {
    let name = scenes::NAMES[i];
    match o.value {
        Ok(v) => cortex_m_semihosting::hprintln!(
            "CASE {} value={:e} bits=0x{:08x} host={:e} host_bits=0x{:08x} diff_ulp={} rel={:e} tolerance={} stack={} {}",
            name,
            v,
            v.to_bits(),
            o.expected,
            o.expected.to_bits(),
            o.ulps,
            (v - o.expected) / o.expected,
            Tolerance(i),
            o.stack,
            if o.ok { "ok" } else { "MISMATCH" }
        ),
        Err(e) => cortex_m_semihosting::hprintln!("CASE {} error={:?} stack={} MISMATCH", name, e, o.stack),
    }
}

/// Displays scene `i`'s tolerance with its unit.
#[cfg(not(feature = "defmt"))]
struct Tolerance(usize);

#[cfg(not(feature = "defmt"))]
impl core::fmt::Display for Tolerance {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if cfg!(feature = "micromath") {
            write!(f, "{:e}rel", TOL_REL_MICROMATH[self.0])
        } else {
            write!(f, "{}ulp", TOL_ULP_LIBM[self.0])
        }
    }
}

#[cfg(not(feature = "defmt"))]
fn finish_log(max_stack: usize, ok: bool) {
    cortex_m_semihosting::hprintln!("STACK_MAX {}", max_stack);
    cortex_m_semihosting::hprintln!("RESULT {}", if ok { "PASS" } else { "FAIL" });
}

// ---- logging: defmt over semihosting -----------------------------------------------------

#[cfg(feature = "defmt")]
fn start_log() {
    defmt::info!(
        "pdm-firmware (defmt): backend={=str} quadrature={} cap={=usize}",
        BACKEND,
        pdm_kernel::Quadrature::uniform(scenes::ORDER),
        scenes::CAP
    );
    // The kernel's defmt::Format derives, end to end: an error value as the kernel reports it.
    #[cfg(not(feature = "baseline"))]
    {
        let bad = pdm_kernel::Sphere::outer(pdm_kernel::vec3(0.0_f32, 0.0, 0.0), black_box(-1.0));
        defmt::info!("negative radius -> {}", bad.err());
    }
}

#[cfg(feature = "defmt")]
fn log_outcome(i: usize, o: &Outcome) {
    let name = scenes::NAMES[i];
    defmt::info!(
        "CASE {=str} result={} bits={=u32:#010x} host={=f32} host_bits={=u32:#010x} diff_ulp={=u32} stack={=usize} ok={=bool}",
        name,
        o.value,
        o.value.map(f32::to_bits).unwrap_or(0),
        o.expected,
        o.expected.to_bits(),
        o.ulps,
        o.stack,
        o.ok
    );
}

#[cfg(feature = "defmt")]
fn finish_log(max_stack: usize, ok: bool) {
    defmt::info!("STACK_MAX {=usize}", max_stack);
    if ok {
        defmt::info!("RESULT PASS");
    } else {
        defmt::error!("RESULT FAIL");
    }
}

// ---- faults --------------------------------------------------------------------------------

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}
