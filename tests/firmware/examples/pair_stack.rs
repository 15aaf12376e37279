//! Peak stack of `pair_exchange` (the pair path: context, dispatch, boundary path) in f32 at
//! order 5, CAP 25, measured by stack painting under QEMU. run.sh builds and runs it and
//! enforces `PAIR_STACK_LIMIT` (BUDGETS.md).
//!
//! Cases, each a path of the dispatch that samples both patches:
//! - `occluded`: a floor cell of the paper's cube below the unit sphere, the sphere as occluder
//!   (the boundary path with the outer patch split 3 × 3);
//! - `straddling`: a sphere cell at the equator against the floor cell, no occluder (the boundary path on a
//!   pair that straddles the back-face cut);
//! - `plain`: a cell of the sphere's bottom cap above a small floor cell (the plain sum).
//!
//! Each line: `PAIR <case> value=<A·F> stack=<bytes>`; then `PAIR_STACK_MAX <bytes>`. The
//! values are checked for finiteness and the physical bounds only: the scenes' values are
//! checked against the host by the main firmware.

#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use pdm_kernel::{
    pair_exchange, vec3, Occluder, PairSettings, Parallelogram, ParamRect, Patch, PdmError,
    Sphere, Surface,
};

use core::f32::consts::{FRAC_PI_2 as HALF_PI, FRAC_PI_4 as QUARTER_PI, PI};

const PAINT: u32 = 0xDEAD_BEEF;
const PAINT_BYTES: usize = 64 * 1024;

extern "C" {
    static __sheap: u32;
}

const SETTINGS: PairSettings = PairSettings {
    order: 5,
    singular_order: 5,
    boundaries: true,
};

fn pair(
    a: &Patch<'_, f32, dyn Surface<f32>>,
    b: &Patch<'_, f32, dyn Surface<f32>>,
    occluders: &dyn Occluder<f32>,
) -> Result<(f32, f32, f32), PdmError> {
    let e = pair_exchange::<f32, _, _, _, 25>(a, b, SETTINGS, occluders)?;
    Ok((e.value, a.area(5)?, b.area(5)?))
}

#[inline(never)]
fn case(i: usize) -> Result<(f32, f32, f32), PdmError> {
    let sphere = Sphere::outer(vec3(0.0_f32, 0.0, 0.0), 1.0)?;
    let floor = Parallelogram::new(
        vec3(-3.0_f32, -3.0, -3.0),
        vec3(6.0, 0.0, 0.0),
        vec3(0.0, 6.0, 0.0),
    )?;
    let s: &dyn Surface<f32> = &sphere;
    let f: &dyn Surface<f32> = &floor;
    let cell = Patch::new(f, ParamRect::new(2.0 / 3.0, 1.0, 1.0 / 3.0, 2.0 / 3.0)?)?;
    match i {
        0 => pair(&Patch::new(s, ParamRect::new(HALF_PI, 3.0 * QUARTER_PI, 0.0, HALF_PI)?)?, &cell, &sphere),
        1 => pair(&Patch::new(s, ParamRect::new(HALF_PI, 3.0 * QUARTER_PI, 0.0, HALF_PI)?)?, &cell, &()),
        _ => {
            let top = Patch::new(s, ParamRect::new(3.0 * QUARTER_PI, PI, 0.0, HALF_PI)?)?;
            let small = Patch::new(f, ParamRect::new(0.45, 0.55, 0.45, 0.55)?)?;
            pair(&top, &small, &())
        }
    }
}

#[inline(never)]
fn paint(bottom: usize) {
    let sp = cortex_m::register::msp::read() as usize;
    let top = (sp - 64) & !3;
    let mut p = bottom;
    while p < top {
        // SAFETY: RAM between the end of .bss and below this frame; nothing else lives there.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

fn lowest_touched(bottom: usize, top: usize) -> usize {
    let mut p = bottom;
    while p < top {
        // SAFETY: reading RAM in the painted range.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != PAINT {
            return p;
        }
        p += 4;
    }
    top
}

#[entry]
fn main() -> ! {
    let heap_start = core::ptr::addr_of!(__sheap) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    let bottom = core::cmp::max((heap_start + 3) & !3, sp.saturating_sub(PAINT_BYTES) & !3);
    let mut ok = true;
    let mut max_stack = 0usize;
    for (i, name) in ["occluded", "straddling", "plain"].iter().enumerate() {
        paint(bottom);
        let sp_call = cortex_m::register::msp::read() as usize;
        let result = case(black_box(i));
        let stack = sp_call - lowest_touched(bottom, sp_call);
        max_stack = max_stack.max(stack);
        match result {
            Ok((v, area_a, area_b)) if v.is_finite() && v > 0.0 && v <= area_a.min(area_b) => {
                hprintln!("PAIR {} value={:e} stack={}", name, v, stack);
            }
            other => {
                ok = false;
                hprintln!("PAIR {} BAD {:?} stack={}", name, other.map(|x| x.0), stack);
            }
        }
    }
    hprintln!("PAIR_STACK_MAX {}", max_stack);
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    debug::exit(debug::EXIT_FAILURE);
    loop {}
}
