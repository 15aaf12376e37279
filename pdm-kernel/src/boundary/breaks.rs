//! Locating visibility changes without closed form: bracketing on a probe grid and bisection,
//! and the small sorted buffers the breaks are kept in.

use super::*;

/// Appends to `out` every point of (lo, hi) where `f` changes value, found on a uniform grid of
/// `probes` points and refined by bisection; ascending.
pub(super) fn locate_changes<T: Real, K: PartialEq + Copy>(
    f: &impl Fn(T) -> K,
    lo: T,
    hi: T,
    probes: usize,
    out: &mut [T; MAX_BREAKS + 2],
    n: &mut usize,
) -> Result<(), PdmError> {
    let step = (hi - lo) / T::from_usize(probes - 1);
    // The end probes sit just inside the interval: an end may be a point where the surface's
    // normal vanishes (a pole, a disk's centre), whose facing tests fail although every point
    // next to it passes; probing it would report a change that is not there.
    let inset = (hi - lo) * end_inset::<T>();
    let mut prev_t = lo + inset;
    let mut prev_v = f(prev_t);
    for k in 1..probes {
        let t = if k == probes - 1 { hi - inset } else { lo + step * T::from_usize(k) };
        let v = f(t);
        // Several changes between two probes (A → B → C) show as a value after the first
        // change that is not yet the probe's: keep bisecting from there. (A → B → A pairs
        // narrower than the probe spacing stay unseen.)
        let (mut from, mut from_v) = (prev_t, prev_v);
        let mut guard = 0;
        while from_v != v && guard < MAX_BREAKS {
            let (lo_end, hi_end, hi_v) = bisect(f, from, t, from_v);
            push(out, n, (lo_end + hi_end) * T::HALF)?;
            if !(hi_end < t) {
                break;
            }
            (from, from_v) = (hi_end, hi_v);
            guard += 1;
        }
        prev_t = t;
        prev_v = v;
    }
    Ok(())
}

/// Relative distance from an interval's ends at which visibility is probed instead of the end
/// itself (ε^¾: 1.8e-12 in f64, 6.4e-6 in f32). A change closer to an end than this is not
/// placed into the rule; the rule then integrates across it on a piece of that width.
#[inline]
pub(super) fn end_inset<T: Real>() -> T {
    let e = T::EPSILON.sqrt();
    e * e.sqrt()
}

/// Insertion sort of (position, tag) pairs by position (few elements, no allocation, no
/// panics on NaN: NaN never moves).
pub(super) fn sort_by_position<T: Real, K: Copy>(xs: &mut [(T, K)]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&x), Some(&y)) = (xs.get(j - 1), xs.get(j)) else { break };
            if x.0 > y.0 {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}

/// Insertion sort (few elements, no allocation, no panics on NaN: NaN never moves).
pub(super) fn sort<T: Real>(xs: &mut [T]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&a), Some(&b)) = (xs.get(j - 1), xs.get(j)) else { break };
            if a > b {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}

pub(super) fn push<T: Copy>(breaks: &mut [T; MAX_BREAKS + 2], n: &mut usize, t: T) -> Result<(), PdmError> {
    match breaks.get_mut(*n) {
        Some(slot) => {
            *slot = t;
            *n += 1;
            Ok(())
        }
        None => Err(PdmError::CapacityExceeded { needed: *n + 1, capacity: MAX_BREAKS + 2 }),
    }
}

/// The point in [lo, hi] where `f` switches from `f_lo`, to within rounding of the interval.
/// The bracket [lo, hi] (adjacent floating-point numbers, or 4 bits short of them) around the
/// first point where `f` switches from `f_lo`, and the value of `f` at `hi`.
pub(super) fn bisect<T: Real, K: PartialEq + Copy>(f: &impl Fn(T) -> K, mut lo: T, mut hi: T, f_lo: K) -> (T, T, K) {
    let mut f_hi = f(hi);
    for _ in 0..(T::MANTISSA_DIGITS + 4) {
        let mid = (lo + hi) * T::HALF;
        if mid <= lo || mid >= hi {
            break;
        }
        let f_mid = f(mid);
        if f_mid == f_lo {
            lo = mid;
        } else {
            hi = mid;
            f_hi = f_mid;
        }
    }
    (lo, hi, f_hi)
}
