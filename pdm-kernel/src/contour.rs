//! Flat pairs by the contour (Stokes) form: for two planar polygons that see each other wholly
//! (each in the closed half-space in front of the other, nothing between them),
//!
//! A_a·F_{a→b} = (1/2π) ∮_{∂a} ∮_{∂b} ln r  dl_a·dl_b
//!
//! (Sparrow 1963; `../shared/REFERENCES.md`, "Contour (Stokes) form"), both boundaries
//! counter-clockwise about their radiating normals. It replaces the 4-D integral by 16 double
//! line integrals over pairs of edges, whose only singularity is logarithmic, so it stays exact
//! however close the polygons come (a gap of 1e-8 of their size, strips of any aspect) where the
//! 4-D rule sums a peak it cannot see.
//!
//! Per pair of edges x(σ) = P + σ d_a, y(τ) = Q + τ d_b (σ, τ ∈ [0, 1]) the inner integral is in
//! closed form: with u₀(σ) the foot of x(σ) along the unit direction ê of d_b and η(σ) the
//! distance of x(σ) from that line,
//!
//! ∫₀¹ ln |x − y(τ)| dτ = [G(L − u₀) − G(−u₀)] / (2L),  G(v) = v ln(v² + η²) − 2v + 2η atan(v/η),
//!
//! L = |d_b|. The outer integrand is analytic except near the points where x(σ) comes close to
//! edge b (its complex singularities lie at the distance of x(σ) from the edge): where the foot
//! passes either end of edge b (u₀ = 0, u₀ = L) and where the two lines come closest. The outer
//! rule is split there and cut geometrically towards each such point down to that distance
//! (widths d, 4d, 16d, …), so it converges exponentially in the order for every gap.
//! Perpendicular edges contribute nothing (d_a·d_b = 0). The geometry is translated to its
//! centroid and scaled to unit size first (the ln of the scale integrates to zero over a closed
//! contour), so the logarithms stay O(1) at any scale.

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::real::Real;
use crate::vec3::Vec3;

/// Most geometric cuts towards one singular point (4^24 ≈ 3e14: any gap above rounding).
const MAX_LEVELS: usize = 26;

/// A_a·F_{a→b}, the number of line-integrand evaluations and a bound on the rounding error of
/// the value, for two flat convex quadrilaterals
/// given by their corners in order, counter-clockwise about their radiating normals, each
/// wholly in front of (or on) the other's plane and with no occluder between them.
///
/// The edge-pair terms are O(L² ln L) for edges of length L, the result only O(A·F): for long
/// thin strips they cancel by many digits. The rounding of the sum is bounded by 8ε times the
/// sum of the terms' magnitudes; where that bound exceeds √ε of the value (1.5e-8 in f64) the
/// pair is refused with `Err(Unresolvable)` rather than returned with lost digits.
pub(crate) fn quad_exchange<T: Real>(
    a: &[Vec3<T>; 4],
    b: &[Vec3<T>; 4],
    order: usize,
) -> Result<(T, u64, T), PdmError> {
    let rule = GaussRule::<T>::new(order)?;
    // Centroid to the origin, largest distance to 1.
    let mut centroid = crate::vec3::vec3(T::ZERO, T::ZERO, T::ZERO);
    for p in a.iter().chain(b.iter()) {
        centroid = centroid + *p;
    }
    centroid = centroid.scale(T::ONE / T::from_usize(8));
    let mut size = T::ZERO;
    for p in a.iter().chain(b.iter()) {
        size = size.max((*p - centroid).norm());
    }
    if !(size > T::ZERO) || !size.is_finite() {
        return Err(PdmError::Degenerate);
    }
    let inv = T::ONE / size;
    let unit = |p: &[Vec3<T>; 4]| p.map(|q| (q - centroid).scale(inv));
    let (ua, ub) = (unit(a), unit(b));
    let mut total = T::ZERO;
    let mut magnitude = T::ZERO;
    let mut evaluations = 0u64;
    for i in 0..4 {
        let (Some(&p0), Some(&p1)) = (ua.get(i), ua.get((i + 1) % 4)) else { continue };
        let da = p1 - p0;
        for j in 0..4 {
            let (Some(&q0), Some(&q1)) = (ub.get(j), ub.get((j + 1) % 4)) else { continue };
            let db = q1 - q0;
            let dot = da.dot(db);
            if dot.abs() <= T::EPSILON * da.norm() * db.norm() {
                continue;
            }
            let (v, m, n) = edge_pair(&rule, p0, da, q0, db);
            total += dot * v;
            magnitude += dot.abs() * m;
            evaluations = evaluations.saturating_add(n);
        }
    }
    if !total.is_finite() {
        return Err(PdmError::InvalidResult);
    }
    let rounding = T::from_f64(8.0) * T::EPSILON * magnitude;
    if rounding > T::EPSILON.sqrt() * total.abs() {
        return Err(PdmError::Unresolvable);
    }
    let scale = size * size * T::FRAC_1_PI * T::HALF;
    Ok((total * scale, evaluations, rounding * scale))
}

/// ∫₀¹∫₀¹ ln |P + σ d_a − Q − τ d_b| dτ dσ (see the module docs), the same integral of the
/// magnitudes of the closed form's two terms (what its rounding scales with), and the
/// evaluations.
fn edge_pair<T: Real>(rule: &GaussRule<T>, p: Vec3<T>, da: Vec3<T>, q: Vec3<T>, db: Vec3<T>) -> (T, T, u64) {
    let len_b = db.norm();
    let len_a = da.norm();
    let e = db.scale(T::ONE / len_b);
    // Foot of x(σ) along e: u₀(σ) = f0 + σ f1.
    let (f0, f1) = ((p - q).dot(e), da.dot(e));
    let mut cuts = [T::ZERO; 5];
    let mut nc = 0usize;
    let mut add = |x: T| {
        if x > T::ZERO && x < T::ONE {
            if let Some(slot) = cuts.get_mut(nc) {
                *slot = x;
                nc += 1;
            }
        }
    };
    if f1 != T::ZERO {
        add(-f0 / f1);
        add((len_b - f0) / f1);
    }
    // Closest approach of the two lines: minimise |w(σ) × e|², w = p − q + σ d_a.
    let (c0, c1) = ((p - q).cross(e), da.cross(e));
    let c11 = c1.norm2();
    if c11 > T::EPSILON * len_a * len_a {
        add(-c0.dot(c1) / c11);
    }
    let used = cuts.get_mut(..nc).unwrap_or_default();
    sort(used);
    let distance = |s: T| segment_distance(p + da.scale(s) - q, db, len_b) / len_a;
    let inner = |s: T| {
        let w = p + da.scale(s) - q;
        let u0 = w.dot(e);
        let eta = w.cross(e).norm();
        let (g1, g0) = (big_g(len_b - u0, eta), big_g(-u0, eta));
        ((g1 - g0) / (T::TWO * len_b), (g1.abs() + g0.abs()) / (T::TWO * len_b))
    };
    let mut total = (T::ZERO, T::ZERO);
    let mut evaluations = 0u64;
    let mut lo = T::ZERO;
    let ends = used.iter().copied().chain(core::iter::once(T::ONE));
    for hi in ends {
        if hi > lo {
            let (v, n) = graded_piece(rule, lo, hi, distance(lo), distance(hi), &inner);
            total = (total.0 + v.0, total.1 + v.1);
            evaluations = evaluations.saturating_add(n);
        }
        lo = hi;
    }
    (total.0, total.1, evaluations)
}

/// ∫_lo^hi f with the rule, cut geometrically towards an end whose singularity lies at
/// parameter distance `d_lo` / `d_hi` (closer than a quarter of the piece).
fn graded_piece<T: Real>(
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
        let half = (x1 - x0) * T::HALF;
        let (mut sum, mut abs) = (T::ZERO, T::ZERO);
        for (x, w) in rule.points() {
            let (v, m) = f(x0 + half * (x + T::ONE));
            sum += w * v;
            abs += w * m;
        }
        total = (total.0 + sum * half, total.1 + abs * half);
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

/// G(v) = ∫ ln(v² + η²) dv = v ln(v² + η²) − 2v + 2η atan(v/η) (0 at v = 0).
#[inline]
fn big_g<T: Real>(v: T, eta: T) -> T {
    let r2 = v * v + eta * eta;
    let log_term = if r2 > T::ZERO { v * r2.ln() } else { T::ZERO };
    let angle = if eta > T::ZERO { T::TWO * eta * (v / eta).atan() } else { T::ZERO };
    log_term - T::TWO * v + angle
}

/// Distance from the point w (relative to the segment's start) to the segment τ d, τ ∈ [0, 1].
#[inline]
fn segment_distance<T: Real>(w: Vec3<T>, d: Vec3<T>, len: T) -> T {
    let tau = (w.dot(d) / (len * len)).max(T::ZERO).min(T::ONE);
    (w - d.scale(tau)).norm()
}

/// Insertion sort (at most a handful of entries; NaN never moves).
fn sort<T: Real>(xs: &mut [T]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&x), Some(&y)) = (xs.get(j - 1), xs.get(j)) else { break };
            if x > y {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::vec3;

    /// C-11 (parallel coaxial squares, Howell's catalogue): unit squares at distance h.
    fn c11(h: f64) -> f64 {
        let x = 1.0 / h;
        let y = 1.0 / h;
        let (x2, y2) = (1.0 + x * x, 1.0 + y * y);
        2.0 / (core::f64::consts::PI * x * y)
            * ((x2 * y2 / (1.0 + x * x + y * y)).sqrt().ln()
                + x * y2.sqrt() * (x / y2.sqrt()).atan()
                + y * x2.sqrt() * (y / x2.sqrt()).atan()
                - x * x.atan()
                - y * y.atan())
    }

    #[test]
    fn parallel_squares_at_every_gap() {
        for h in [1.0, 1e-1, 1e-3, 1e-6, 1e-8] {
            let lower = [vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0)];
            let upper = [vec3(0.0, 0.0, h), vec3(0.0, 1.0, h), vec3(1.0, 1.0, h), vec3(1.0, 0.0, h)];
            let (f, _, _) = quad_exchange::<f64>(&lower, &upper, 10).unwrap();
            let exact = c11(h);
            // The closed form's terms grow like 1/h² and cancel to O(1): it keeps about
            // ε/h² digits less, 1e-10 at h = 1e-8.
            let allowed = if h < 1e-6 { 1e-10 } else { 1e-12 };
            assert!(((f - exact) / exact).abs() < allowed, "h = {h}: {f} vs {exact}");
        }
    }
}
