//! Gauss rules on pieces of a line graded towards its singular ends.

use super::*;

/// (∫ f, ∫ |f|) over [x0, x1] by the rule, f given as x ↦ (f(x), |f(x)|).
pub(super) fn rule_on<T: Real>(rule: &GaussRule<T>, x0: T, x1: T, f: &impl Fn(T) -> (T, T)) -> (T, T) {
    let half = (x1 - x0) * T::HALF;
    let (mut sum, mut abs) = (T::ZERO, T::ZERO);
    for (x, w) in rule.points() {
        let (v, m) = f(x0 + half * (x + T::ONE));
        sum += w * v;
        abs += w * m;
    }
    (sum * half, abs * half)
}

/// ∫_lo^hi f with the rule, cut geometrically towards an end whose singularity lies at
/// parameter distance `d_lo` / `d_hi` (closer than a quarter of the piece).
pub(super) fn graded_piece<T: Real>(
    rule: &GaussRule<T>,
    lo: T,
    hi: T,
    d_lo: T,
    d_hi: T,
    f: &impl Fn(T) -> (T, T),
) -> ((T, T), u64) {
    let width = hi - lo;
    let mid = lo + width * T::HALF;
    let quarter = width * T::HALF * T::HALF;
    let four = T::TWO * T::TWO;
    let mut total = (T::ZERO, T::ZERO);
    let mut evaluations = 0u64;
    let mut piece = |x0: T, x1: T| {
        let (sum, abs) = rule_on(rule, x0, x1, f);
        total = (total.0 + sum, total.1 + abs);
        evaluations = evaluations.saturating_add(rule.order() as u64);
    };
    // From lo upwards: [lo, lo + d], [lo + d, lo + 4d], … while below the middle.
    let mut a = lo;
    if d_lo < quarter {
        let mut step = d_lo.max(width * T::EPSILON);
        for _ in 0..MAX_LEVELS {
            let b = lo + step;
            if !(b < mid) {
                break;
            }
            piece(a, b);
            a = b;
            step *= four;
        }
    }
    // From hi downwards, mirrored.
    let mut cuts = [T::ZERO; MAX_LEVELS];
    let mut nc = 0usize;
    if d_hi < quarter {
        let mut step = d_hi.max(width * T::EPSILON);
        for slot in cuts.iter_mut() {
            let c = hi - step;
            if !(c > mid) || !(c > a) {
                break;
            }
            *slot = c;
            nc += 1;
            step *= four;
        }
    }
    let inner_end = nc.checked_sub(1).and_then(|k| cuts.get(k)).copied().unwrap_or(hi);
    piece(a, inner_end);
    for k in (0..nc).rev() {
        let (Some(&c0), c1) = (cuts.get(k), if k == 0 { Some(&hi) } else { cuts.get(k - 1) }) else { continue };
        if let Some(&c1) = c1 {
            piece(c0, c1);
        }
    }
    (total, evaluations)
}

/// ∫_lo^hi f with the rule on pieces graded geometrically (ratio 2) from each end towards the
/// middle, the first piece at an end as wide as the distance `d_lo` / `d_hi` of that end from
/// the integrand's nearest singularity (in parameter units): every piece then sees its
/// singularities at least its own half-width beyond its ends, where the rule's error falls like
/// 5^(−2·order). Returns ((∫ f, ∫ |f|), evaluations).
pub(super) fn graded_line<T: Real>(
    rule: &GaussRule<T>,
    lo: T,
    hi: T,
    d_lo: T,
    d_hi: T,
    f: &impl Fn(T) -> (T, T),
) -> ((T, T), u64) {
    let mid = (lo + hi) * T::HALF;
    let mut total = (T::ZERO, T::ZERO);
    let mut evaluations = 0u64;
    let mut piece = |x0: T, x1: T| {
        let (sum, abs) = rule_on(rule, x0, x1, f);
        total = (total.0 + sum, total.1 + abs);
        evaluations = evaluations.saturating_add(rule.order() as u64);
    };
    let floor = (hi - lo) * T::EPSILON;
    // From lo: [lo, lo + d], [lo + d, lo + 3d], [lo + 3d, lo + 7d], … below the middle.
    let mut a = lo;
    let mut step = d_lo.max(floor);
    for _ in 0..GRADED_LEVELS {
        let b = a + step;
        if !(b < mid) {
            break;
        }
        piece(a, b);
        a = b;
        step *= T::TWO;
    }
    // From hi, mirrored: the cuts collected first, integrated after the middle piece.
    let mut cuts = [T::ZERO; GRADED_LEVELS];
    let mut nc = 0usize;
    let mut c = hi;
    let mut step = d_hi.max(floor);
    for slot in cuts.iter_mut() {
        let next = c - step;
        if !(next > mid) || !(next > a) {
            break;
        }
        *slot = next;
        nc += 1;
        c = next;
        step *= T::TWO;
    }
    piece(a, c);
    for k in (0..nc).rev() {
        let (Some(&c0), c1) = (cuts.get(k), if k == 0 { Some(&hi) } else { cuts.get(k - 1) }) else { continue };
        if let Some(&c1) = c1 {
            piece(c0, c1);
        }
    }
    (total, evaluations)
}

/// Most pieces from one end in [`graded_line`] (2^48 ≈ 3e14: any distance above rounding).
pub(super) const GRADED_LEVELS: usize = 48;
