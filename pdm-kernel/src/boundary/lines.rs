//! One inner line in closed form: the polynomials of the facing tests and the occluders along
//! the line, their roots in s (the visibility changes), and the graded pieces between them.

use super::*;

/// Most polynomials describing visibility along one line (two facing tests + the occluders').
pub(super) const MAX_POLYS: usize = 40;

/// The polynomials a τ² + b τ + c of one line.
pub(super) struct Polys<T> {
    pub(super) list: [[T; 3]; MAX_POLYS],
    pub(super) n: usize,
    pub(super) overflow: bool,
}

impl<T: Real> Polys<T> {
    pub(super) fn new() -> Self {
        Self { list: [[T::ZERO; 3]; MAX_POLYS], n: 0, overflow: false }
    }
    pub(super) fn push(&mut self, c: [T; 3]) {
        match self.list.get_mut(self.n) {
            Some(slot) => {
                *slot = c;
                self.n += 1;
            }
            None => self.overflow = true,
        }
    }
    pub(super) fn used(&self) -> &[[T; 3]] {
        self.list.get(..self.n).unwrap_or_default()
    }
}

/// Calls `f(lo, hi, graded_lo, graded_hi)` for the pieces of [start, end] between the sorted
/// singular points `breaks` (which include start and end). A piece next to a much narrower
/// neighbour has another singular point just beyond its end, where a Gauss rule converges
/// slowly; it is cut geometrically towards that end (widths w, 3w, 12w, … from the end, w the
/// neighbour's width), so every sub-piece sees that point at least its own length away. Only
/// ends at singular points are graded.
pub(super) fn for_each_piece<T: Real>(
    breaks: &[T],
    start: T,
    end: T,
    outside: Outside<T>,
    mut f: impl FnMut(T, T, bool, bool) -> Result<(), PdmError>,
) -> Result<(), PdmError> {
    const MAX_LEVELS: usize = 24;
    let n = breaks.len();
    for k in 0..n.saturating_sub(1) {
        let (Some(&lo), Some(&hi)) = (breaks.get(k), breaks.get(k + 1)) else { continue };
        if !(hi > lo) {
            continue;
        }
        let width = hi - lo;
        let quarter = width * T::HALF * T::HALF;
        let (grade_lo, grade_hi) = (lo > start, hi < end);
        // Neighbour widths (a singular point that close beyond the end).
        let before = if k == 0 { outside.0 } else { breaks.get(k - 1).copied() };
        let after = if k + 2 == n { outside.1 } else { breaks.get(k + 1 + 1).copied() };
        let left = match before {
            Some(l) if lo - l < quarter && lo - l > T::ZERO => Some(lo - l),
            _ => None,
        };
        let right = match after {
            Some(r) if r - hi < quarter && r - hi > T::ZERO => Some(r - hi),
            _ => None,
        };
        let mid = lo + width * T::HALF;
        // From the left: [lo, lo + w], [lo + w, lo + 4w], … up to the middle.
        let mut a = lo;
        if let Some(w) = left {
            let mut step = w;
            let mut first = true;
            for _ in 0..MAX_LEVELS {
                let b = lo + step;
                if !(b < mid) {
                    break;
                }
                f(a, b, first && grade_lo, false)?;
                first = false;
                a = b;
                step *= T::from_f64(4.0);
            }
        }
        // From the right, mirrored, collected as the cut points below `hi`.
        let mut b_end = hi;
        let mut cuts = [T::ZERO; MAX_LEVELS];
        let mut nc = 0usize;
        if let Some(w) = right {
            let mut step = w;
            for _ in 0..MAX_LEVELS {
                let c = hi - step;
                if !(c > mid) || !(c > a) {
                    break;
                }
                if let Some(slot) = cuts.get_mut(nc) {
                    *slot = c;
                    nc += 1;
                }
                step *= T::from_f64(4.0);
            }
            if let Some(&c) = nc.checked_sub(1).and_then(|j| cuts.get(j)) {
                b_end = c;
            }
        }
        f(a, b_end, grade_lo && left.is_none(), grade_hi && right.is_none())?;
        // The right cuts, innermost first: [c_{j}, c_{j-1}], …, [c_0, hi].
        for j in (0..nc).rev() {
            let (Some(&c), next) = (cuts.get(j), if j == 0 { Some(&hi) } else { cuts.get(j - 1) }) else { continue };
            let Some(&d) = next else { continue };
            f(c, d, false, j == 0 && grade_hi)?;
        }
    }
    Ok(())
}

/// The map x ↦ (u, du/dx) of [0, 1] onto itself with du/dx = 0 at the graded ends.
#[inline]
pub(super) fn graded<T: Real>(x: T, lo: bool, hi: bool) -> (T, T) {
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
/// its end, pieces alternately visible and hidden starting with `first_visible`; `ids` folds
/// which polynomial makes each interior break (closed form; 0 otherwise).
pub(super) struct Line<T> {
    pub(super) breaks: [T; MAX_BREAKS + 2],
    pub(super) n: usize,
    pub(super) first_visible: bool,
    pub(super) ids: u64,
}

impl<T: Real> Line<T> {
    pub(super) fn new() -> Self {
        Self { breaks: [T::ZERO; MAX_BREAKS + 2], n: 0, first_visible: false, ids: 0 }
    }
}

/// Buffers for computing one line in closed form, kept between lines.
pub(super) struct LineScratch<T> {
    pub(super) polys: Polys<T>,
    pub(super) candidates: [(T, u64); MAX_CANDIDATES],
}

impl<T: Real> LineScratch<T> {
    pub(super) fn new() -> Self {
        Self { polys: Polys::new(), candidates: [(T::ZERO, 0u64); MAX_CANDIDATES] }
    }
}

/// Most candidate switches gathered on one line.
pub(super) const MAX_CANDIDATES: usize = 2 * MAX_POLYS;

/// The visibility structure of the line t ∈ [t0, t1] from its polynomials: the candidate
/// switches are their real roots; each piece between consecutive candidates is classified by
/// the exact test at its midpoint, and equal neighbours merged. `false` if there are too many.
pub(super) fn closed_form_line<T: Real>(
    polys: &[[T; 3]],
    t0: T,
    t1: T,
    vis_at: &impl Fn(T) -> bool,
    candidates: &mut [(T, u64); MAX_CANDIDATES],
    line: &mut Line<T>,
) -> bool {
    let roots = |&[a, b, c]: &[T; 3], out: &mut dyn FnMut(T)| {
        crate::visibility::polynomial_roots(a, b, c, out);
        true
    };
    line_from_roots(polys, roots, t0, t1, vis_at, candidates, line)
}

/// The visibility structure of the line t ∈ [t0, t1] from the roots of the functions `fs`
/// (`roots` passes one function's roots and says whether it found them all): the roots inside
/// (t0, t1), each tagged with its function, are the candidate switches of
/// [`line_from_candidates`]. `false` if they overflow `candidates` or were not all found.
fn line_from_roots<T: Real>(
    fs: &[[T; 3]],
    roots: impl Fn(&[T; 3], &mut dyn FnMut(T)) -> bool,
    t0: T,
    t1: T,
    vis_at: &impl Fn(T) -> bool,
    candidates: &mut [(T, u64); MAX_CANDIDATES],
    line: &mut Line<T>,
) -> bool {
    let mut n = 0usize;
    let mut overflow = false;
    for (id, f) in fs.iter().enumerate() {
        let complete = roots(f, &mut |t| {
            if t > t0 && t < t1 {
                match candidates.get_mut(n) {
                    Some(slot) => {
                        *slot = (t, id as u64 + 1);
                        n += 1;
                    }
                    None => overflow = true,
                }
            }
        });
        overflow |= !complete;
    }
    !overflow && line_from_candidates(candidates.get_mut(..n).unwrap_or_default(), t0, t1, vis_at, line)
}

/// The visibility structure of the line t ∈ [t0, t1] from the candidate switches `used` (inside
/// (t0, t1), each with the id of the function whose root it is): each piece between consecutive
/// candidates is classified by the exact test at its midpoint, and equal neighbours merged.
/// `false` if the line's buffer is too small.
pub(super) fn line_from_candidates<T: Real>(
    used: &mut [(T, u64)],
    t0: T,
    t1: T,
    vis_at: &impl Fn(T) -> bool,
    line: &mut Line<T>,
) -> bool {
    sort_by_position(used);
    line.n = 0;
    line.ids = 0;
    let mut lo = t0;
    let mut lo_id = 0u64;
    let mut status: Option<bool> = None;
    // Candidates closer than this are one switch (two polynomials with a common root, e.g. a
    // facing test and the tangent plane of a sphere occluder the point lies on): the piece
    // between them is rounding, and the switch gets the smallest of their ids, so that the
    // line's structure does not change with which root rounds first.
    let merge = (t1 - t0) * end_inset::<T>();
    for &(hi, hi_id) in used.iter().chain(core::iter::once(&(t1, 0u64))) {
        if !(hi > lo + merge) {
            lo_id = lo_id.min(hi_id);
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
                line.ids = line.ids.wrapping_mul(MAX_POLYS as u64 + 1).wrapping_add(lo_id);
            }
            Some(_) => {}
        }
        status = Some(v);
        lo = hi;
        lo_id = hi_id;
    }
    if status.is_none() {
        line.first_visible = vis_at((t0 + t1) * T::HALF);
        if push(&mut line.breaks, &mut line.n, t0).is_err() {
            return false;
        }
    }
    push(&mut line.breaks, &mut line.n, t1).is_ok()
}

/// The visibility structure of the line t ∈ [t0, t1] whose visibility changes are among the
/// roots of the first-degree trigonometric polynomials `fs` ([`Surface::facing_along_t`]);
/// `false` if there are too many candidates.
#[cfg(feature = "closed-form")]
pub(super) fn trigonometric_line<T: Real>(
    fs: &[[T; 3]],
    t0: T,
    t1: T,
    vis_at: &impl Fn(T) -> bool,
    candidates: &mut [(T, u64); MAX_CANDIDATES],
    line: &mut Line<T>,
) -> bool {
    let roots = |&f: &[T; 3], out: &mut dyn FnMut(T)| trigonometric_roots(f, t0, t1, &mut |t| out(t));
    line_from_roots(fs, roots, t0, t1, vis_at, candidates, line)
}

/// The roots in (t0, t1) of a + b·cos t + c·sin t: with ρ = √(b² + c²) and δ = atan2(c, b) it
/// is a + ρ·cos(t − δ), so t = δ ± acos(−a/ρ) + 2πk; each root is polished by Newton steps
/// (which also recover the accuracy acos loses near ±1). A double root (the line tangent to a
/// boundary) does not change the sign and may be missed. `false` if the roots could not all be
/// found (coefficients not finite, a range of more than 60 periods): the caller then brackets.
#[cfg(feature = "closed-form")]
pub(super) fn trigonometric_roots<T: Real>(f: [T; 3], t0: T, t1: T, out: &mut impl FnMut(T)) -> bool {
    // Scaled by the largest coefficient, so that b² + c² neither underflows nor overflows.
    let scale = f.iter().fold(T::ZERO, |m, x| m.max(x.abs()));
    if !f.iter().all(|x| x.is_finite()) || !t0.is_finite() || !t1.is_finite() {
        return false;
    }
    if !(scale > T::ZERO) || !(t1 > t0) {
        return true;
    }
    let [a, b, c] = f.map(|x| x / scale);
    let period = T::TWO * T::PI;
    if (t1 - t0) > T::from_usize(60) * period {
        return false;
    }
    let rho = (b * b + c * c).sqrt();
    if !(rho > T::ZERO) {
        return true;
    }
    let x = -a / rho;
    if !(x.abs() <= T::ONE) {
        return true;
    }
    let alpha = (T::ONE - x * x).max(T::ZERO).sqrt().atan2(x);
    let delta = c.atan2(b);
    let f = |t: T| a + b * t.cos() + c * t.sin();
    let families = if alpha > T::ZERO { 2 } else { 1 };
    for base in [delta + alpha, delta - alpha].into_iter().take(families) {
        // The first root of this family at or above t0 − 2π, then every period up to t1 (a
        // parameter range spans a few periods at most: the loops are bounded).
        // (base lies in (−2π, 2π]; a range more than 256 periods away from it is refused.)
        let mut t = base;
        let mut steps = 0;
        while t > t0 {
            t -= period;
            steps += 1;
            if steps > 256 {
                return false;
            }
        }
        while t < t0 {
            t += period;
            steps += 1;
            if steps > 256 {
                return false;
            }
        }
        while t < t1 {
            let mut root = t;
            for _ in 0..2 {
                let slope = c * root.cos() - b * root.sin();
                if !(slope.abs() > T::ZERO) {
                    break;
                }
                let next = root - f(root) / slope;
                if !(next.is_finite() && f(next).abs() <= f(root).abs()) {
                    break;
                }
                root = next;
            }
            if root > t0 && root < t1 {
                out(root);
            }
            t += period;
        }
    }
    true
}

/// The roots in (t0, t1) where (a₁ + b₁·cos t + c₁·sin t)² − (a₂ + b₂·cos t + c₂·sin t)
/// changes sign (`l1`, `l2` as `[a, b, c]`): a second-degree trigonometric polynomial, with at
/// most four roots per period. On pieces of at most a quarter turn about their middle m, the
/// half-angle substitution x = tan((t − m)/2) makes (1 + x²)² times it a quartic in x
/// (x within ±tan(π/8)), whose sign changes [`roots_in_interval`] brackets; each root is
/// polished by Newton steps on the trigonometric form. A double root (a tangency) does not
/// change the sign and is not passed. `false` where a coefficient or an end is not finite or
/// the range spans more than 60 periods.
#[cfg(feature = "closed-form")]
pub(super) fn squared_trigonometric_roots<T: Real>(
    l1: [T; 3],
    l2: [T; 3],
    t0: T,
    t1: T,
    out: &mut dyn FnMut(T),
) -> bool {
    if !l1.iter().chain(l2.iter()).all(|x| x.is_finite()) || !t0.is_finite() || !t1.is_finite() {
        return false;
    }
    if !(t1 > t0) {
        return true;
    }
    if (t1 - t0) > T::from_usize(60) * T::TWO * T::PI {
        return false;
    }
    let [a1, b1, c1] = l1;
    let [a2, b2, c2] = l2;
    let f = |t: T| {
        let (st, ct) = t.sin_cos();
        let l = a1 + b1 * ct + c1 * st;
        (l * l - (a2 + b2 * ct + c2 * st), T::TWO * l * (c1 * ct - b1 * st) - (c2 * ct - b2 * st))
    };
    let quarter = T::PI * T::HALF;
    let mut lo = t0;
    // At most 4·60 + 1 pieces (the range is checked above).
    for _ in 0..242 {
        if !(lo < t1) {
            break;
        }
        let hi = (lo + quarter).min(t1);
        let (m, h) = ((lo + hi) * T::HALF, (hi - lo) * T::HALF);
        let (sm, cm) = m.sin_cos();
        // L(m + τ) = a + (b·cos m + c·sin m)·cos τ + (c·cos m − b·sin m)·sin τ, and with
        // x = tan(τ/2): (1 + x²)·L = (a + b') + 2c'·x + (a − b')·x².
        let half_angle = |[a, b, c]: [T; 3]| {
            let (b, c) = (b * cm + c * sm, c * cm - b * sm);
            [a + b, T::TWO * c, a - b]
        };
        let (q1, q2) = (half_angle(l1), half_angle(l2));
        let square = square(&q1);
        let linear = product(&q2, &[T::ONE, T::ZERO, T::ONE]);
        let mut quartic = [T::ZERO; 5];
        for ((q, s), l) in quartic.iter_mut().zip(square).zip(linear) {
            *q = s - l;
        }
        let (sh, ch) = (h * T::HALF).sin_cos();
        let end = sh / ch;
        roots_in_interval(&quartic, -end, end, &mut |x| {
            let mut root = m + T::TWO * x.atan();
            for _ in 0..2 {
                let (value, slope) = f(root);
                if !(slope.abs() > T::ZERO) {
                    break;
                }
                let next = root - value / slope;
                if !(next.is_finite() && next > lo && next < hi && f(next).0.abs() <= value.abs()) {
                    break;
                }
                root = next;
            }
            if root > t0 && root < t1 {
                out(root);
            }
        });
        lo = hi;
    }
    true
}

/// (q(x))² for a quadratic q, as quartic coefficients (ascending powers).
pub(super) fn square<T: Real>(q: &[T; 3]) -> [T; 5] {
    product(q, q)
}

/// p(x)·q(x) for two quadratics, as quartic coefficients (ascending powers).
pub(super) fn product<T: Real>(p: &[T; 3], q: &[T; 3]) -> [T; 5] {
    let mut out = [T::ZERO; 5];
    for (i, &a) in p.iter().enumerate() {
        for (j, &b) in q.iter().enumerate() {
            if let Some(o) = out.get_mut(i + j) {
                *o += a * b;
            }
        }
    }
    out
}

/// Horner evaluation of Σ c_k x^k.
pub(super) fn horner<T: Real>(c: &[T], x: T) -> T {
    let mut v = T::ZERO;
    for &k in c.iter().rev() {
        v = v * x + k;
    }
    v
}

/// Passes the real roots in (x0, x1) of Σ c_k x^k (degree ≤ 4) where the polynomial changes
/// sign: the roots of its derivative split (x0, x1) into monotone pieces, each bisected.
pub(super) fn roots_in_interval<T: Real>(c: &[T; 5], x0: T, x1: T, out: &mut dyn FnMut(T)) {
    let degree = c.iter().rposition(|&k| k != T::ZERO).unwrap_or(0);
    if degree <= 2 {
        let g = |k: usize| c.get(k).copied().unwrap_or(T::ZERO);
        crate::visibility::polynomial_roots(g(2), g(1), g(0), &mut |x| {
            if x > x0 && x < x1 {
                out(x);
            }
        });
        return;
    }
    // Critical points: roots of the derivative (degree ≤ 3), recursively.
    let mut derivative = [T::ZERO; 5];
    for (k, d) in derivative.iter_mut().enumerate().take(degree) {
        *d = c.get(k + 1).copied().unwrap_or(T::ZERO) * T::from_usize(k + 1);
    }
    let mut critical = [x0; 6];
    let mut nc = 1usize;
    roots_in_interval(&derivative, x0, x1, &mut |x| {
        if let Some(slot) = critical.get_mut(nc) {
            *slot = x;
            nc += 1;
        }
    });
    if let Some(slot) = critical.get_mut(nc) {
        *slot = x1;
        nc += 1;
    }
    let pts = critical.get_mut(..nc).unwrap_or_default();
    sort(pts);
    let coeffs = c.get(..=degree).unwrap_or_default();
    for w in pts.windows(2) {
        let (mut lo, mut hi) = match w {
            [lo, hi] => (*lo, *hi),
            _ => continue,
        };
        let (f_lo, f_hi) = (horner(coeffs, lo), horner(coeffs, hi));
        if f_lo == T::ZERO && lo > x0 {
            out(lo);
        }
        if !((f_lo < T::ZERO && f_hi > T::ZERO) || (f_lo > T::ZERO && f_hi < T::ZERO)) {
            continue;
        }
        let rising = f_hi > T::ZERO;
        for _ in 0..(T::MANTISSA_DIGITS + 4) {
            let mid = (lo + hi) * T::HALF;
            if mid <= lo || mid >= hi {
                break;
            }
            if (horner(coeffs, mid) > T::ZERO) == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        out((lo + hi) * T::HALF);
    }
}

#[cfg(all(test, feature = "closed-form"))]
mod tests {
    use super::*;

    /// Every sign change of a + b·cos t + c·sin t on a fine grid over (t0, t1) holds a root the
    /// closed form reports, and every reported root is one (|f| at rounding level), over
    /// random coefficients and ranges of up to three periods, near-tangent cases included.
    /// A xorshift stream of numbers uniform in [−1, 1) from `state`.
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The sign changes of `f` on a grid of 20 000 steps over (t0, t1), each asserted to hold
    /// one of `roots` (case `k` in the message).
    fn sign_changes_have_roots(f: &dyn Fn(f64) -> f64, t0: f64, t1: f64, roots: &[f64], k: usize) -> usize {
        let n = 20_000;
        let mut changes = 0;
        let mut prev = f(t0);
        for i in 1..=n {
            let x = t0 + (t1 - t0) * i as f64 / n as f64;
            let y = f(x);
            if (prev > 0.0) != (y > 0.0) && prev != 0.0 && y != 0.0 {
                let lo = x - (t1 - t0) / n as f64;
                assert!(
                    roots.iter().any(|&r| r >= lo - 1e-9 && r <= x + 1e-9),
                    "k = {k}: sign change in [{lo}, {x}] without a root ({roots:?})"
                );
                changes += 1;
            }
            prev = y;
        }
        changes
    }

    /// Every sign change of (a₁ + b₁ cos t + c₁ sin t)² − (a₂ + b₂ cos t + c₂ sin t) on a fine
    /// grid has a root of `squared_trigonometric_roots` within it, each root is one to rounding,
    /// and ranges over many periods and near-tangent cases are covered.
    #[test]
    fn squared_trigonometric_roots_are_every_sign_change() {
        let mut next = uniform(0x2545_f491_4f6c_dd1d_u64);
        let mut changes = 0;
        for k in 0..2000 {
            let l1 = [next() * 2.0, next() * 2.0, next() * 2.0];
            let mut l2 = [next() * 3.0, next() * 3.0, next() * 3.0];
            if k % 4 == 0 {
                // Near a double root: shift the constant so that f has a minimum near 0.
                let f = |t: f64| {
                    let l = l1[0] + l1[1] * t.cos() + l1[2] * t.sin();
                    l * l - (l2[0] + l2[1] * t.cos() + l2[2] * t.sin())
                };
                let t = next() * 3.0;
                l2[0] += f(t) * (1.0 + 1e-4 * next());
            }
            let t0 = next() * 8.0;
            let t1 = t0 + 0.05 + next().abs() * 14.0;
            let f = |t: f64| {
                let l = l1[0] + l1[1] * t.cos() + l1[2] * t.sin();
                l * l - (l2[0] + l2[1] * t.cos() + l2[2] * t.sin())
            };
            let scale = 1.0 + l1.iter().map(|x| x * x).sum::<f64>() + l2.iter().map(|x| x.abs()).sum::<f64>();
            let (mut found, mut count) = ([0.0_f64; 128], 0usize);
            assert!(squared_trigonometric_roots(l1, l2, t0, t1, &mut |t| {
                found[count] = t;
                count += 1;
            }));
            let roots = &found[..count];
            for &t in roots {
                assert!(t > t0 && t < t1);
                assert!(f(t).abs() <= 1e-11 * scale, "k = {k}: f({t}) = {}", f(t));
            }
            changes += sign_changes_have_roots(&f, t0, t1, roots, k);
        }
        assert!(changes > 2000, "{changes}");
        assert!(!squared_trigonometric_roots([f64::NAN, 1.0, 0.0], [0.0; 3], 0.0, 1.0, &mut |_| {}));
        assert!(!squared_trigonometric_roots([1.0, 1.0, 0.0], [0.0; 3], 0.0, 1e6, &mut |_| {}));
    }

    #[test]
    fn trigonometric_roots_are_every_sign_change() {
        let mut next = uniform(0x9e37_79b9_7f4a_7c15_u64);
        let mut changes = 0;
        for k in 0..3000 {
            let (b, c) = (next() * 3.0, next() * 3.0);
            let rho = (b * b + c * c).sqrt();
            // Every fourth case is within 1e-3 of tangent.
            let a = if k % 4 == 0 { rho * (1.0 - 1e-3 * next().abs()) * next().signum() } else { next() * 4.0 };
            let t0 = next() * 8.0;
            let t1 = t0 + 0.1 + next().abs() * 18.0;
            let f = |t: f64| a + b * t.cos() + c * t.sin();
            let (mut found, mut count) = ([0.0_f64; 64], 0usize);
            let complete = trigonometric_roots([a, b, c], t0, t1, &mut |t| {
                found[count] = t;
                count += 1;
            });
            assert!(complete);
            let roots = &found[..count];
            for &t in roots {
                assert!(t > t0 && t < t1);
                assert!(f(t).abs() <= 1e-12 * (a.abs() + rho), "k = {k}: f({t}) = {}", f(t));
            }
            changes += sign_changes_have_roots(&f, t0, t1, roots, k);
        }
        assert!(changes > 3000);
        // Scaled coefficients: the same roots at 1e-30 and 1e30 in f32 as at 1.
        for scale in [1e-30_f32, 1.0, 1e30] {
            let (mut roots, mut n) = ([0.0_f32; 4], 0);
            assert!(trigonometric_roots([0.5 * scale, scale, 0.0], 0.0, 6.0, &mut |t| {
                roots[n] = t;
                n += 1;
            }));
            assert_eq!(n, 2, "scale {scale}");
            assert!((roots[0] - 2.0 * core::f32::consts::FRAC_PI_3).abs() < 1e-5);
        }
        // What cannot be solved is refused, so that the caller brackets instead.
        assert!(!trigonometric_roots([f64::NAN, 1.0, 0.0], 0.0, 1.0, &mut |_| {}));
        assert!(!trigonometric_roots([0.0, 1.0, 0.0], 0.0, 1e4, &mut |_| {}));
        assert!(!trigonometric_roots([0.0, 1.0, 0.0], 1e6, 1e6 + 1.0, &mut |_| {}));
    }
}
