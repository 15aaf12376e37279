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
use crate::surface::{ParamRect, Surface};
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
    let outer = PatchSamples::<T, CAP>::new(a, order)?;
    let inner_samples = PatchSamples::<T, CAP>::new(b, order)?; // validates b (area, finiteness)
    let use_occluders = occluders.may_block_between(&outer.bounds(), &inner_samples.bounds());
    let r = b.rect();
    let surface = b.surface();
    // Closed form when b's t-lines are straight and every occluder can list its switches.
    let closed_form = match surface.straight_t_line(r.s0) {
        Some((o, d)) => !use_occluders || occluders.line_breaks(o + d, o, d, &mut |_| {}),
        None => false,
    };
    let inner = Inner {
        surface,
        r,
        rule: GaussRule::<T>::new(order)?,
        probes: 2 * order + 3,
        closed_form,
        use_occluders,
        occluders,
        count: &count,
    };
    let mut total = T::ZERO;
    for sample in outer.iter() {
        if sample.weight == T::ZERO {
            continue;
        }
        total += sample.weight * inner.integral(sample.point, sample.unit_normal)?;
    }
    let value = total * T::FRAC_1_PI;
    if !value.is_finite() || value < T::ZERO {
        return Err(PdmError::InvalidResult);
    }
    Ok((value, count.get()))
}

/// The inner patch b with everything needed to integrate over its visible part from one point.
struct Inner<'x, T: Real, SB: ?Sized, O: ?Sized> {
    surface: &'x SB,
    r: ParamRect<T>,
    rule: GaussRule<T>,
    probes: usize,
    closed_form: bool,
    use_occluders: bool,
    occluders: &'x O,
    count: &'x core::cell::Cell<u64>,
}

impl<T: Real, SB: Surface<T> + ?Sized, O: Occluder<T> + ?Sized> Inner<'_, T, SB, O> {
    fn tick(&self) {
        self.count.set(self.count.get().saturating_add(1));
    }

    /// Both facing tests and the occluders for the segment p → q.
    fn visible(&self, p: Vec3<T>, np: Vec3<T>, q: Vec3<T>, nq: Vec3<T>) -> bool {
        self.tick();
        let e = q - p;
        np.dot(e) > T::ZERO && nq.dot(e) < T::ZERO && !(self.use_occluders && self.occluders.blocks(p, q))
    }

    /// The visible pieces of the t-line of b at s, seen from p.
    fn line(&self, p: Vec3<T>, np: Vec3<T>, s: T, line: &mut Line<T>) -> Result<(), PdmError> {
        let r = self.r;
        let vis_at = |t: T| {
            let (q, nq) = self.surface.point_and_normal(t, s);
            self.visible(p, np, q, nq)
        };
        if self.closed_form {
            if let Some((origin, direction)) = self.surface.straight_t_line(s) {
                let nq = self.surface.normal(r.t0, s);
                let occ = self.use_occluders;
                if closed_form_line(p, np, nq, origin, direction, r.t0, r.t1, occ, self.occluders, &vis_at, line) {
                    return Ok(());
                }
            }
        }
        // Bracket visibility changes along the line, refine each by bisection.
        line.n = 0;
        push(&mut line.breaks, &mut line.n, r.t0)?;
        locate_changes(&vis_at, r.t0, r.t1, self.probes, &mut line.breaks, &mut line.n)?;
        push(&mut line.breaks, &mut line.n, r.t1)?;
        let first_hi = line.breaks.get(1).copied().unwrap_or(r.t1);
        line.first_visible = vis_at((r.t0 + first_hi) * T::HALF);
        Ok(())
    }

    /// The structure of a line: (number of breakpoints, visibility of the first piece); an
    /// error counts as its own structure (it is reported again when the line is integrated).
    fn line_signature(&self, p: Vec3<T>, np: Vec3<T>, s: T) -> (usize, bool) {
        let mut line = Line::new();
        match self.line(p, np, s, &mut line) {
            Ok(()) => (line.n, line.first_visible),
            Err(_) => (usize::MAX, false),
        }
    }

    /// J(p) = ∫_b visible (n̂_p·e)(−n_q·e)/L⁴ dq (without the 1/π).
    fn integral(&self, p: Vec3<T>, np: Vec3<T>) -> Result<T, PdmError> {
        let r = self.r;
        // J is smooth in s except where the visible set of the t-line changes its structure:
        // a boundary crossing a t-edge, or a boundary tangent to the t-lines (two breakpoints
        // meeting). Split the s-range there.
        let mut s_breaks = [T::ZERO; MAX_BREAKS + 2];
        let mut ns = 0usize;
        push(&mut s_breaks, &mut ns, r.s0)?;
        if self.closed_form {
            // The line structure is cheap in closed form: bracket its changes and bisect.
            let signature = |s: T| self.line_signature(p, np, s);
            locate_changes(&signature, r.s0, r.s1, self.probes, &mut s_breaks, &mut ns)?;
        } else {
            for t_edge in [r.t0, r.t1] {
                let vis_edge = |s: T| {
                    let (q, nq) = self.surface.point_and_normal(t_edge, s);
                    self.visible(p, np, q, nq)
                };
                locate_changes(&vis_edge, r.s0, r.s1, self.probes, &mut s_breaks, &mut ns)?;
            }
        }
        push(&mut s_breaks, &mut ns, r.s1)?;
        let s_used = s_breaks.get_mut(..ns).unwrap_or_default();
        sort(s_used);
        let mut inner = T::ZERO;
        let mut line = Line::new();
        for w in s_used.windows(2) {
            let (s_lo, s_hi) = match w {
                [lo, hi] => (*lo, *hi),
                _ => continue,
            };
            if !(s_hi > s_lo) {
                continue;
            }
            // Where two breakpoints of the t-lines meet (a boundary tangent to the lines) the
            // visible length grows like √(s − s*): J(s) has a square-root end point, which a
            // Gauss rule integrates only algebraically. s = s* + H·x² (or the smoothstep
            // 3x² − 2x³ with both ends graded) makes it smooth in x; at the other interior
            // breaks (a boundary crossing a t-edge) the map is harmless.
            let (grade_lo, grade_hi) = (s_lo > r.s0, s_hi < r.s1);
            let width = s_hi - s_lo;
            for (xs, ws) in self.rule.points() {
                let (u, du) = graded((xs + T::ONE) * T::HALF, grade_lo, grade_hi);
                let s = s_lo + width * u;
                self.line(p, np, s, &mut line)?;
                // Integrate the visible pieces (visibility alternates from the first piece).
                let mut sum = T::ZERO;
                let mut visible_piece = line.first_visible;
                for w in line.breaks.get(..line.n).unwrap_or_default().windows(2) {
                    let (lo, hi) = match w {
                        [lo, hi] => (*lo, *hi),
                        _ => continue,
                    };
                    let this_visible = visible_piece;
                    visible_piece = !visible_piece;
                    if !this_visible || !(hi > lo) {
                        continue;
                    }
                    let half = (hi - lo) * T::HALF;
                    let mut piece = T::ZERO;
                    for (xt, wt) in self.rule.points() {
                        let (q, nq) = self.surface.point_and_normal(lo + half * (xt + T::ONE), s);
                        self.tick();
                        piece += wt * kernel_unoccluded(p, np, q, nq);
                    }
                    sum += piece * half;
                }
                inner += ws * T::HALF * du * width * sum;
            }
        }
        Ok(inner)
    }
}

/// The map x ↦ (u, du/dx) of [0, 1] onto itself with du/dx = 0 at the graded ends.
#[inline]
fn graded<T: Real>(x: T, lo: bool, hi: bool) -> (T, T) {
    let three = T::from_f64(3.0);
    match (lo, hi) {
        (true, true) => (x * x * (three - T::TWO * x), T::from_f64(6.0) * x * (T::ONE - x)),
        (true, false) => (x * x, T::TWO * x),
        (false, true) => {
            let y = T::ONE - x;
            (T::ONE - y * y, T::TWO * y)
        }
        (false, false) => (x, T::ONE),
    }
}

/// The visibility structure of one inner line: `breaks[..n]` ascending from the line's start to
/// its end, pieces alternately visible and hidden starting with `first_visible`.
struct Line<T> {
    breaks: [T; MAX_BREAKS + 2],
    n: usize,
    first_visible: bool,
}

impl<T: Real> Line<T> {
    fn new() -> Self {
        Self { breaks: [T::ZERO; MAX_BREAKS + 2], n: 0, first_visible: false }
    }
}

/// Most candidate switches gathered on one straight line before falling back to bisection.
const MAX_CANDIDATES: usize = 4 * MAX_BREAKS;

/// The visibility structure of the straight line origin + t·direction, t ∈ [t0, t1], with the
/// constant normal `nq`, seen from p: the candidate switches are the roots of the two facing
/// tests (linear in t) and the occluders' [`Occluder::line_breaks`]; each piece between
/// consecutive candidates is classified by the exact test at its midpoint, and equal
/// neighbours merged. `false` if some occluder cannot list its switches or there are too many.
#[allow(clippy::too_many_arguments)]
fn closed_form_line<T: Real, O: Occluder<T> + ?Sized>(
    p: Vec3<T>,
    np: Vec3<T>,
    nq: Vec3<T>,
    origin: Vec3<T>,
    direction: Vec3<T>,
    t0: T,
    t1: T,
    use_occluders: bool,
    occluders: &O,
    vis_at: &impl Fn(T) -> bool,
    line: &mut Line<T>,
) -> bool {
    let mut candidates = [T::ZERO; MAX_CANDIDATES];
    let mut n = 0usize;
    let mut overflow = false;
    let mut add = |t: T| {
        if t > t0 && t < t1 {
            match candidates.get_mut(n) {
                Some(slot) => {
                    *slot = t;
                    n += 1;
                }
                None => overflow = true,
            }
        }
    };
    let w0 = origin - p;
    crate::visibility::polynomial_roots(T::ZERO, np.dot(direction), np.dot(w0), &mut add);
    crate::visibility::polynomial_roots(T::ZERO, nq.dot(direction), nq.dot(w0), &mut add);
    if use_occluders && !occluders.line_breaks(p, origin, direction, &mut add) {
        return false;
    }
    if overflow {
        return false;
    }
    let used = candidates.get_mut(..n).unwrap_or_default();
    sort(used);
    line.n = 0;
    let mut lo = t0;
    let mut status: Option<bool> = None;
    for &hi in used.iter().chain(core::iter::once(&t1)) {
        if !(hi > lo) {
            continue;
        }
        let v = vis_at((lo + hi) * T::HALF);
        match status {
            None => {
                line.first_visible = v;
                if push(&mut line.breaks, &mut line.n, t0).is_err() {
                    return false;
                }
            }
            Some(prev) if prev != v => {
                if push(&mut line.breaks, &mut line.n, lo).is_err() {
                    return false;
                }
            }
            Some(_) => {}
        }
        status = Some(v);
        lo = hi;
    }
    if status.is_none() {
        line.first_visible = vis_at((t0 + t1) * T::HALF);
        if push(&mut line.breaks, &mut line.n, t0).is_err() {
            return false;
        }
    }
    push(&mut line.breaks, &mut line.n, t1).is_ok()
}

/// Appends to `out` every point of (lo, hi) where `f` changes value, found on a uniform grid of
/// `probes` points and refined by bisection; ascending.
fn locate_changes<T: Real, K: PartialEq + Copy>(
    f: &impl Fn(T) -> K,
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
/// The bracket [lo, hi] (adjacent floating-point numbers, or 4 bits short of them) around the
/// first point where `f` switches from `f_lo`, and the value of `f` at `hi`.
fn bisect<T: Real, K: PartialEq + Copy>(f: &impl Fn(T) -> K, mut lo: T, mut hi: T, f_lo: K) -> (T, T, K) {
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
