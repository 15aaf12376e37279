//! pdm-kernel for JavaScript: a `#![no_std]`, allocation-free WebAssembly module
//! (wasm32-unknown-unknown cdylib) with a small C-ABI surface.
//!
//! A *pair* is a sphere (outer side) and a parallelogram, created once and referred to by a
//! small integer handle; form factors between them are computed by substructuring (grids of
//! patches, Gauss order per axis), with the sphere as occluder (it hides the far side of
//! itself, section 3 of the paper). Both f32 and f64 are exported.
//!
//! | export | returns |
//! | --- | --- |
//! | `pdm_pair_new_f64(cx, cy, cz, r, ox, oy, oz, tx, ty, tz, sx, sy, sz)` | handle ≥ 0, or an error code < 0 |
//! | `pdm_pair_new_f32(…same, f32…)` | handle ≥ 0, or an error code < 0 |
//! | `pdm_form_factor_f64(h, sphere_m, sphere_n, plane_m, plane_n, order)` | F(sphere → parallelogram) ≥ 0, or an error code < 0 |
//! | `pdm_form_factor_f32(…same…)` | the same, computed in f32 |
//! | `pdm_pair_free(h)` | 0, or an error code < 0 |
//! | `pdm_max_order()` | the largest supported `order` |
//! | `pdm_max_pairs()` | how many pairs can exist at once |
//!
//! The sphere is centred at (cx, cy, cz) with radius r; the parallelogram is
//! origin + t·(tx, ty, tz) + s·(sx, sy, sz), (t, s) ∈ [0, 1]², radiating towards edge_t × edge_s.
//! The sphere is split into sphere_m × sphere_n patches (polar × azimuth), the parallelogram
//! into plane_m × plane_n, with `order` × `order` Gauss points per patch (1 ≤ order ≤ 16). The
//! factor the other way follows by reciprocity: F(plane → sphere) = F(sphere → plane)·4πr²/area.
//!
//! Error codes (negative): see [`code`]. Nothing here allocates, panics, uses `std` or has an
//! `unsafe` block; the panic handler exists only because a `no_std` cdylib must have one.

#![no_std]

// The host build of the same crate (the `native` binary and the host cdylib) links std, which
// provides the panic handler there.
#[cfg(not(target_arch = "wasm32"))]
extern crate std;

use core::sync::atomic::{AtomicU32, AtomicU64, Ordering};

use pdm_kernel::fixed::surface_form_factor_with_rules;
use pdm_kernel::{vec3, GaussRule, Parallelogram, PatchGrid, PdmError, Real, Sphere, Surface};

/// Sample-buffer capacity per patch: order² ≤ CAP.
const CAP: usize = 256;
/// The largest supported Gauss order (order² ≤ CAP). The rules are built with
/// `GaussRule::new_up_to::<16>`, so the module holds the tables of orders 1…16 only.
const MAX_ORDER: usize = 16;
/// Pairs that can exist at once.
const SLOTS: usize = 8;
/// Parameters of a pair: sphere centre (3), radius, parallelogram origin (3), edge_t (3), edge_s (3).
const PARAMS: usize = 13;

/// Error codes returned (as negative numbers) by the exports.
pub mod code {
    /// `order` outside 1..=`pdm_max_order()` (the kernel's UnsupportedOrder).
    pub const UNSUPPORTED_ORDER: i32 = -1;
    /// A NaN or infinite input, or a non-finite intermediate value.
    pub const NON_FINITE: i32 = -2;
    /// A zero grid size (or an empty parameter range).
    pub const EMPTY_PARAMETER_RANGE: i32 = -3;
    /// Degenerate geometry: radius ≤ 0, parallel or zero edges, a zero-area patch.
    pub const DEGENERATE: i32 = -4;
    /// A patch outside its surface's domain.
    pub const OUTSIDE_DOMAIN: i32 = -5;
    /// `order`² samples do not fit the per-patch buffer.
    pub const CAPACITY_EXCEEDED: i32 = -6;
    /// The computed form factor is not finite and non-negative.
    pub const INVALID_RESULT: i32 = -7;
    /// A kernel error this module does not know (the kernel's error enum may grow).
    pub const OTHER_KERNEL_ERROR: i32 = -8;
    /// The handle is not a live pair.
    pub const BAD_HANDLE: i32 = -20;
    /// The handle is a pair of the other precision (an f32 pair used with an f64 call or vice versa).
    pub const WRONG_PRECISION: i32 = -21;
    /// All `pdm_max_pairs()` slots are in use.
    pub const NO_FREE_SLOT: i32 = -22;
    /// A grid size is negative.
    pub const BAD_ARGUMENT: i32 = -23;
}

fn kernel_code(e: PdmError) -> i32 {
    match e {
        PdmError::UnsupportedOrder { .. } => code::UNSUPPORTED_ORDER,
        PdmError::NonFinite => code::NON_FINITE,
        PdmError::EmptyParameterRange => code::EMPTY_PARAMETER_RANGE,
        PdmError::Degenerate => code::DEGENERATE,
        PdmError::OutsideDomain => code::OUTSIDE_DOMAIN,
        PdmError::CapacityExceeded { .. } => code::CAPACITY_EXCEEDED,
        PdmError::InvalidResult => code::INVALID_RESULT,
        _ => code::OTHER_KERNEL_ERROR,
    }
}

/// f32 or f64 (the kernel's `Real` has the exact f64 conversions the slot storage needs).
trait Precision: Real {
    /// Slot tag of a pair of this precision.
    const KIND: u32;
}

impl Precision for f32 {
    const KIND: u32 = 1;
}

impl Precision for f64 {
    const KIND: u32 = 2;
}

/// A slot of the pair table: `kind` 0 = free, else `Precision::KIND`; parameters as f64 bits.
/// Atomics only so that the table can be a plain `static` without `unsafe`: wasm32 without the
/// threads proposal is single-threaded and compiles them to ordinary loads and stores.
struct Slot {
    kind: AtomicU32,
    params: [AtomicU64; PARAMS],
}

impl Slot {
    const fn new() -> Self {
        Self {
            kind: AtomicU32::new(0),
            params: [const { AtomicU64::new(0) }; PARAMS],
        }
    }
}

static PAIRS: [Slot; SLOTS] = [const { Slot::new() }; SLOTS];

fn build<T: Precision>(p: &[T; PARAMS]) -> Result<(Sphere<T>, Parallelogram<T>), PdmError> {
    let [cx, cy, cz, r, ox, oy, oz, tx, ty, tz, sx, sy, sz] = *p;
    let sphere = Sphere::outer(vec3(cx, cy, cz), r)?;
    let plane = Parallelogram::new(vec3(ox, oy, oz), vec3(tx, ty, tz), vec3(sx, sy, sz))?;
    Ok((sphere, plane))
}

fn pair_new<T: Precision>(p: [T; PARAMS]) -> i32 {
    if let Err(e) = build(&p) {
        return kernel_code(e);
    }
    for (handle, slot) in (0i32..).zip(PAIRS.iter()) {
        if slot
            .kind
            .compare_exchange(0, T::KIND, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
        {
            for (cell, v) in slot.params.iter().zip(p) {
                cell.store(v.to_f64().to_bits(), Ordering::Release);
            }
            return handle;
        }
    }
    code::NO_FREE_SLOT
}

fn slot(handle: i32) -> Result<&'static Slot, i32> {
    usize::try_from(handle)
        .ok()
        .and_then(|i| PAIRS.get(i))
        .ok_or(code::BAD_HANDLE)
}

fn load<T: Precision>(handle: i32) -> Result<[T; PARAMS], i32> {
    let s = slot(handle)?;
    match s.kind.load(Ordering::Acquire) {
        0 => return Err(code::BAD_HANDLE),
        k if k != T::KIND => return Err(code::WRONG_PRECISION),
        _ => {}
    }
    let mut p = [T::ZERO; PARAMS];
    for (v, cell) in p.iter_mut().zip(&s.params) {
        *v = T::from_f64(f64::from_bits(cell.load(Ordering::Acquire)));
    }
    Ok(p)
}

fn grid_size(n: i32) -> Result<usize, i32> {
    usize::try_from(n).map_err(|_| code::BAD_ARGUMENT)
}

fn form_factor<T: Precision>(
    handle: i32,
    sphere_m: i32,
    sphere_n: i32,
    plane_m: i32,
    plane_n: i32,
    order: i32,
) -> Result<T, i32> {
    let p = load::<T>(handle)?;
    let (sphere, plane) = build(&p).map_err(kernel_code)?;
    let order = usize::try_from(order).map_err(|_| code::UNSUPPORTED_ORDER)?;
    let rule = GaussRule::<T>::new_up_to::<MAX_ORDER>(order).map_err(kernel_code)?;
    // Both grids over `dyn Surface`: one copy of the sampling code per width instead of one per
    // surface type (smaller module; the values are the same).
    let (sphere_dyn, plane_dyn): (&dyn Surface<T>, &dyn Surface<T>) = (&sphere, &plane);
    let sg = PatchGrid::new(sphere_dyn, grid_size(sphere_m)?, grid_size(sphere_n)?)
        .map_err(kernel_code)?;
    let pg =
        PatchGrid::new(plane_dyn, grid_size(plane_m)?, grid_size(plane_n)?).map_err(kernel_code)?;
    surface_form_factor_with_rules::<T, _, _, _, CAP>(sg, pg, &rule, &rule, &sphere)
        .map_err(kernel_code)
}

fn value_or_code<T: Precision>(r: Result<T, i32>) -> T {
    r.unwrap_or_else(|c| T::from_f64(f64::from(c)))
}

/// Creates an f64 sphere/parallelogram pair; returns its handle (≥ 0) or an error code (< 0).
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn pdm_pair_new_f64(
    cx: f64,
    cy: f64,
    cz: f64,
    r: f64,
    ox: f64,
    oy: f64,
    oz: f64,
    tx: f64,
    ty: f64,
    tz: f64,
    sx: f64,
    sy: f64,
    sz: f64,
) -> i32 {
    pair_new([cx, cy, cz, r, ox, oy, oz, tx, ty, tz, sx, sy, sz])
}

/// Creates an f32 sphere/parallelogram pair; returns its handle (≥ 0) or an error code (< 0).
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn pdm_pair_new_f32(
    cx: f32,
    cy: f32,
    cz: f32,
    r: f32,
    ox: f32,
    oy: f32,
    oz: f32,
    tx: f32,
    ty: f32,
    tz: f32,
    sx: f32,
    sy: f32,
    sz: f32,
) -> i32 {
    pair_new([cx, cy, cz, r, ox, oy, oz, tx, ty, tz, sx, sy, sz])
}

/// Releases a pair; 0, or `BAD_HANDLE`.
#[no_mangle]
pub extern "C" fn pdm_pair_free(handle: i32) -> i32 {
    match slot(handle) {
        Ok(s) if s.kind.swap(0, Ordering::AcqRel) != 0 => 0,
        _ => code::BAD_HANDLE,
    }
}

/// Form factor sphere → parallelogram of an f64 pair, or an error code (< 0).
#[no_mangle]
pub extern "C" fn pdm_form_factor_f64(
    handle: i32,
    sphere_m: i32,
    sphere_n: i32,
    plane_m: i32,
    plane_n: i32,
    order: i32,
) -> f64 {
    value_or_code(form_factor::<f64>(
        handle, sphere_m, sphere_n, plane_m, plane_n, order,
    ))
}

/// Form factor sphere → parallelogram of an f32 pair, computed in f32, or an error code (< 0).
#[no_mangle]
pub extern "C" fn pdm_form_factor_f32(
    handle: i32,
    sphere_m: i32,
    sphere_n: i32,
    plane_m: i32,
    plane_n: i32,
    order: i32,
) -> f32 {
    value_or_code(form_factor::<f32>(
        handle, sphere_m, sphere_n, plane_m, plane_n, order,
    ))
}

/// The largest supported Gauss order per axis.
#[no_mangle]
pub extern "C" fn pdm_max_order() -> i32 {
    MAX_ORDER as i32
}

/// How many pairs can exist at once.
#[no_mangle]
pub extern "C" fn pdm_max_pairs() -> i32 {
    SLOTS as i32
}

#[cfg(all(target_arch = "wasm32", not(test)))]
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    core::arch::wasm32::unreachable()
}
