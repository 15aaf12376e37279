//! The integrand of the PDM, written once: the term of eq. (16) and the two-sided curvature
//! (facing) test of sections 3.1–3.2. Every method (the plain sum, the touching and identical
//! transforms, the visibility boundaries, the tolerance mode's probes) evaluates the kernel
//! through this file.
//!
//! Eq. (15)–(16): F_{a→b} = 1/(π A_a) ∫∫ (n_a·e)(n_b·(−e))/L⁴ dA_b dA_a, e = p_b − p_a, L = |e|,
//! summed over Gauss nodes with weights w. The term is evaluated as w · (n_a·e/L²)(−n_b·e/L²):
//! each factor scales like 1/length, so nothing is raised to the fourth power of the geometry's
//! scale (no overflow or underflow for coordinates from 1e-12 to 1e12 in f64).
//!
//! Sections 3.1–3.2: a pair of points counts only if each lies in front of the other's tangent
//! plane, n_a·e > 0 and −n_b·e > 0 ([`mutually_facing`]).
//!
//! The normals may be unit normals (the plain sum keeps |n| in its weights) or unnormalised
//! (the transforms and the boundary path carry the area element in n).

use crate::real::Real;
use crate::vec3::Vec3;
use crate::visibility::Occluder;

/// The two-sided curvature test of sections 3.1–3.2: `true` iff n_a·(p_b − p_a) > 0 and
/// n_b·(p_a − p_b) > 0.
///
/// ```
/// use pdm_kernel::{mutually_facing, vec3};
/// let (up, down) = (vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, -1.0));
/// // A floor point and a ceiling point above it face each other...
/// assert!(mutually_facing(vec3(0.0, 0.0, 0.0), up, vec3(0.3, 0.0, 1.0), down));
/// // ...but not when the ceiling's normal points up, away from the floor,
/// assert!(!mutually_facing(vec3(0.0, 0.0, 0.0), up, vec3(0.3, 0.0, 1.0), up));
/// // nor two points of one plane (grazing: the cosines are zero).
/// assert!(!mutually_facing(vec3(0.0, 0.0, 0.0), up, vec3(1.0, 0.0, 0.0), up));
/// ```
#[inline(always)]
#[must_use]
pub fn mutually_facing<T: Real>(p_a: Vec3<T>, n_a: Vec3<T>, p_b: Vec3<T>, n_b: Vec3<T>) -> bool {
    let (ca, cb, _) = cosines(p_a, n_a, p_b, n_b);
    facing(ca, cb)
}

/// The facing test on the cosine numerators of [`cosines`].
#[inline(always)]
pub(crate) fn facing<T: Real>(ca: T, cb: T) -> bool {
    ca > T::ZERO && cb > T::ZERO
}

/// The cosine numerators and squared distance of the pair: (n_a·e, −n_b·e, |e|²), e = p_b − p_a.
#[inline(always)]
pub(crate) fn cosines<T: Real>(p_a: Vec3<T>, n_a: Vec3<T>, p_b: Vec3<T>, n_b: Vec3<T>) -> (T, T, T) {
    let e = p_b - p_a;
    (n_a.dot(e), -n_b.dot(e), e.norm2())
}

/// The weighted term of eq. (16), w · (ca/L²)(cb/L²), where the pair passes the facing test and
/// the points are distinct (L² > 0), else 0. Branch-free: where the CPU has packed floating point
/// (x86 SSE2, AArch64 NEON) the non-short-circuit `&` leaves no branch, and LLVM turns the plain
/// sum's lanes into one packed loop body (BENCHMARKS.md). Elsewhere (Cortex-M FPU, wasm without
/// simd128) nothing is packed and the short-circuit form is smaller in flash.
#[inline(always)]
pub(crate) fn term<T: Real>(w: T, ca: T, cb: T, l2: T) -> T {
    #[cfg(any(target_arch = "x86_64", target_arch = "x86", target_arch = "aarch64"))]
    let counts = (ca > T::ZERO) & (cb > T::ZERO) & (l2 > T::ZERO);
    #[cfg(not(any(target_arch = "x86_64", target_arch = "x86", target_arch = "aarch64")))]
    let counts = facing(ca, cb) && l2 > T::ZERO;
    let inv = T::ONE / if counts { l2 } else { T::ONE };
    let value = w * (ca * inv) * (cb * inv);
    if counts {
        value
    } else {
        T::ZERO
    }
}

/// The kernel (n_a·e)(−n_b·e)/L⁴ of the pair, 0 where it fails the facing test.
#[inline(always)]
pub(crate) fn kernel<T: Real>(p_a: Vec3<T>, n_a: Vec3<T>, p_b: Vec3<T>, n_b: Vec3<T>) -> T {
    let (ca, cb, l2) = cosines(p_a, n_a, p_b, n_b);
    term(T::ONE, ca, cb, l2)
}

/// [`kernel`], and 0 where an occluder blocks the segment; the occlusion test runs only for
/// pairs that pass the facing test.
#[inline(always)]
pub(crate) fn kernel_occluded<T: Real, O: Occluder<T> + ?Sized>(
    p_a: Vec3<T>,
    n_a: Vec3<T>,
    p_b: Vec3<T>,
    n_b: Vec3<T>,
    occluders: &O,
) -> T {
    let k = kernel(p_a, n_a, p_b, n_b);
    if k > T::ZERO && occluders.blocks(p_a, p_b) {
        T::ZERO
    } else {
        k
    }
}
