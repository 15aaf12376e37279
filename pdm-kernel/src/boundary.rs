//! Visibility boundaries placed into the rule ("Visibility boundaries" in the references).
//!
//! A Gauss rule converges exponentially only on smooth integrands. The back-face cut (where
//! n·e changes sign inside a patch: the terminator of a sphere seen from a point, a kink) and
//! occluder shadows (a jump) are not smooth, and a fixed rule sampling across them converges
//! algebraically. Here the outer patch a is integrated with its Gauss points as usual; for each
//! outer point p the inner patch b is integrated line by line (Gauss in s), and on each line the
//! parameter values t where visibility changes are located — bracketed on a uniform grid of
//! 2·order + 3 points and refined by bisection to machine precision — and each visible
//! sub-interval gets its own Gauss rule. The inner integral is then exact to the rule's order
//! for every p; what remains non-smooth is the outer integrand where a boundary touches the
//! inner patch's edges, which finer patch grids handle.
//!
//! Cost per outer point: order lines × (2·order + 3 visibility probes + ≈ 60 bisection probes per
//! boundary + order evaluations per visible piece). No allocation: breakpoints live in a
//! fixed-size array (at most [`MAX_BREAKS`] per line; more is `Err(CapacityExceeded)`).
//!
//! Limitation: a visibility change narrower than the bracketing grid spacing (a shadow sliver
//! between two probes) is not seen; its contribution is then sampled by the rule as usual.

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::surface::Surface;
use crate::vec3::Vec3;
use crate::visibility::Occluder;

/// Largest number of visibility changes located on one inner line.
pub const MAX_BREAKS: usize = 16;

/// A_a·F_{a→b} with visibility boundaries placed into the inner rule (see the module docs);
/// `order` points per axis on a and per line and per visible piece on b.
pub fn boundary_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    boundary_exchange_counted::<T, SA, SB, O, CAP>(a, b, order, occluders).map(|(v, _)| v)
}

/// [`boundary_exchange`] and the number of integrand evaluations it made (kernel evaluations
/// plus visibility probes, each of which evaluates the surface and the visibility tests).
pub fn boundary_exchange_counted<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let count = core::cell::Cell::new(0u64);
    let tick = || count.set(count.get().saturating_add(1));
    let outer = PatchSamples::<T, CAP>::new(a, order)?;
    let inner_samples = PatchSamples::<T, CAP>::new(b, order)?; // validates b (area, finiteness)
    let use_occluders = occluders.may_block_between(&outer.bounds(), &inner_samples.bounds());
    let rule = GaussRule::<T>::new(order)?;
    let r = b.rect();
    let surface = b.surface();
    let probes = 2 * order + 3;
    let mut total = T::ZERO;
    for sample in outer.iter() {
        if sample.weight == T::ZERO {
            continue;
        }
        let p = sample.point;
        let np = sample.unit_normal;
        let visible = |q: Vec3<T>, nq: Vec3<T>| {
            tick();
            let e = q - p;
            np.dot(e) > T::ZERO && nq.dot(e) < T::ZERO && !(use_occluders && occluders.blocks(p, q))
        };
        // The inner integral J(s) = ∫ visible f dt is smooth in s except where a visibility
        // boundary crosses the patch's t-edges: split the s-range there too.
        let mut s_breaks = [T::ZERO; MAX_BREAKS + 2];
        let mut ns = 0usize;
        push(&mut s_breaks, &mut ns, r.s0)?;
        for t_edge in [r.t0, r.t1] {
            let vis_edge = |s: T| {
                let (q, nq) = surface.point_and_normal(t_edge, s);
                visible(q, nq)
            };
            locate_changes(&vis_edge, r.s0, r.s1, probes, &mut s_breaks, &mut ns)?;
        }
        push(&mut s_breaks, &mut ns, r.s1)?;
        let s_used = s_breaks.get_mut(..ns).unwrap_or_default();
        sort(s_used);
        let mut inner = T::ZERO;
        for w in s_used.windows(2) {
            let (s_lo, s_hi) = match w {
                [lo, hi] => (*lo, *hi),
                _ => continue,
            };
            if !(s_hi > s_lo) {
                continue;
            }
            let hs_piece = (s_hi - s_lo) * T::HALF;
            for (xs, ws) in rule.points() {
                let s = s_lo + hs_piece * (xs + T::ONE);
                let at = |t: T| surface.point_and_normal(t, s);
                let vis_at = |t: T| {
                    let (q, nq) = at(t);
                    visible(q, nq)
                };
                // Bracket visibility changes along the line, refine each by bisection.
                let mut breaks = [T::ZERO; MAX_BREAKS + 2];
                let mut nb = 0usize;
                push(&mut breaks, &mut nb, r.t0)?;
                locate_changes(&vis_at, r.t0, r.t1, probes, &mut breaks, &mut nb)?;
                push(&mut breaks, &mut nb, r.t1)?;
                // Integrate the visible pieces.
                let mut line = T::ZERO;
                for w in breaks.get(..nb).unwrap_or_default().windows(2) {
                    let (lo, hi) = match w {
                        [lo, hi] => (*lo, *hi),
                        _ => continue,
                    };
                    if !(hi > lo) {
                        continue;
                    }
                    let half = (hi - lo) * T::HALF;
                    if !vis_at(lo + half) {
                        continue;
                    }
                    let mut piece = T::ZERO;
                    for (xt, wt) in rule.points() {
                        let (q, nq) = at(lo + half * (xt + T::ONE));
                        tick();
                        piece += wt * kernel_unoccluded(p, np, q, nq);
                    }
                    line += piece * half;
                }
                inner += ws * hs_piece * line;
            }
        }
        total += sample.weight * inner;
    }
    let value = total * T::FRAC_1_PI;
    if !value.is_finite() || value < T::ZERO {
        return Err(PdmError::InvalidResult);
    }
    Ok((value, count.get()))
}

/// Appends to `out` every point of (lo, hi) where `f` changes value, found on a uniform grid of
/// `probes` points and refined by bisection; ascending.
fn locate_changes<T: Real>(
    f: &impl Fn(T) -> bool,
    lo: T,
    hi: T,
    probes: usize,
    out: &mut [T; MAX_BREAKS + 2],
    n: &mut usize,
) -> Result<(), PdmError> {
    let step = (hi - lo) / T::from_usize(probes - 1);
    let mut prev_t = lo;
    let mut prev_v = f(prev_t);
    for k in 1..probes {
        let t = if k == probes - 1 { hi } else { lo + step * T::from_usize(k) };
        let v = f(t);
        if v != prev_v {
            push(out, n, bisect(f, prev_t, t, prev_v))?;
        }
        prev_t = t;
        prev_v = v;
    }
    Ok(())
}

/// Insertion sort (few elements, no allocation, no panics on NaN: NaN never moves).
fn sort<T: Real>(xs: &mut [T]) {
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

fn push<T: Copy>(breaks: &mut [T; MAX_BREAKS + 2], n: &mut usize, t: T) -> Result<(), PdmError> {
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
fn bisect<T: Real>(f: &impl Fn(T) -> bool, mut lo: T, mut hi: T, f_lo: bool) -> T {
    for _ in 0..(T::MANTISSA_DIGITS + 4) {
        let mid = (lo + hi) * T::HALF;
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) == f_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo + hi) * T::HALF
}

/// (n̂_p·e)(−n_q·e)/L⁴ with n_q unnormalised (area element), clamped at the facing boundary.
#[inline(always)]
fn kernel_unoccluded<T: Real>(p: Vec3<T>, np: Vec3<T>, q: Vec3<T>, nq: Vec3<T>) -> T {
    let e = q - p;
    let l2 = e.norm2();
    let ca = np.dot(e).max(T::ZERO);
    let cb = (-nq.dot(e)).max(T::ZERO);
    if !(l2 > T::ZERO) {
        return T::ZERO;
    }
    let inv = T::ONE / l2;
    (ca * inv) * (cb * inv)
}
