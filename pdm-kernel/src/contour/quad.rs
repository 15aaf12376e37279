//! Two parallelograms: the inner line integral in closed form (G), the outer one by Gauss rules
//! graded towards the other's edges.

use super::*;

/// Most geometric cuts towards one singular point (4^24 ≈ 3e14: any gap above rounding).
pub(super) const MAX_LEVELS: usize = 26;

/// A_a·F_{a→b}, the number of line-integrand evaluations and a bound on the rounding error of
/// the value, for two flat convex quadrilaterals
/// given by their corners in order, counter-clockwise about their radiating normals, each
/// wholly in front of (or on) the other's plane and with no occluder between them.
///
/// The edge-pair terms are O(L² ln L) for edges of length L, the result only O(A·F): for long
/// thin strips they cancel by many digits. The rounding of the sum is bounded by 8ε times the
/// sum of the terms' magnitudes; the caller refuses a value whose bound exceeds √ε of it
/// ([`crate::bounds::lost_digits`]) rather than return it with lost digits.
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
    let scale = size * size * T::FRAC_1_PI * T::HALF;
    Ok((total * scale, evaluations, rounding * scale))
}

/// ∫₀¹∫₀¹ ln |P + σ d_a − Q − τ d_b| dτ dσ (see the module docs), the same integral of the
/// magnitudes of the closed form's two terms (what its rounding scales with), and the
/// evaluations.
pub(super) fn edge_pair<T: Real>(rule: &GaussRule<T>, p: Vec3<T>, da: Vec3<T>, q: Vec3<T>, db: Vec3<T>) -> (T, T, u64) {
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

/// G(v) = ∫ ln(v² + η²) dv = v ln(v² + η²) − 2v + 2η atan(v/η) (0 at v = 0).
#[inline]
pub(super) fn big_g<T: Real>(v: T, eta: T) -> T {
    let r2 = v * v + eta * eta;
    let log_term = if r2 > T::ZERO { v * r2.ln() } else { T::ZERO };
    let angle = if eta > T::ZERO { T::TWO * eta * (v / eta).atan() } else { T::ZERO };
    log_term - T::TWO * v + angle
}

/// Distance from the point w (relative to the segment's start) to the segment τ d, τ ∈ [0, 1].
#[inline]
pub(super) fn segment_distance<T: Real>(w: Vec3<T>, d: Vec3<T>, len: T) -> T {
    let tau = (w.dot(d) / (len * len)).max(T::ZERO).min(T::ONE);
    (w - d.scale(tau)).norm()
}
