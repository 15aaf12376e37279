//! Two parallelograms: the inner line integral in closed form (G), the outer one by Gauss rules
//! graded towards the other's edges.

use super::*;

/// A straight edge: its start, its vector (start to end) and its length.
#[derive(Clone, Copy)]
pub(super) struct Edge<T> {
    pub(super) start: Vec3<T>,
    pub(super) vector: Vec3<T>,
    pub(super) length: T,
}

impl<T: Real> Edge<T> {
    pub(super) fn new(start: Vec3<T>, vector: Vec3<T>) -> Self {
        Self { start, vector, length: vector.norm() }
    }
}

/// Most geometric cuts towards one singular point (4^24 ≈ 3e14: any gap above rounding).
pub(super) const MAX_LEVELS: usize = 26;

/// A_a·F_{a→b}, the number of line-integrand evaluations, a bound on the rounding error of
/// the value, and whether every edge pair was in closed form (no rule: the value is exact to
/// that bound at any order), for two flat convex quadrilaterals
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
) -> Result<(T, u64, T, bool), PdmError> {
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
    let mut exact = true;
    let edges = |u: &[Vec3<T>; 4]| {
        let [c0, c1, c2, c3] = *u;
        [(c0, c1 - c0), (c1, c2 - c1), (c2, c3 - c2), (c3, c0 - c3)].map(|(p, d)| Edge::new(p, d))
    };
    let (ea, eb) = (edges(&ua), edges(&ub));
    for &a in &ea {
        for &b in &eb {
            let dot = a.vector.dot(b.vector);
            if dot.abs() <= T::EPSILON * a.length * b.length {
                continue;
            }
            let (v, m, n) = closed_edge_pair(a, b).unwrap_or_else(|| {
                exact = false;
                edge_pair(&rule, a, b)
            });
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
    Ok((total * scale, evaluations, rounding * scale, exact))
}

/// Whether a singular point of the outer integrand at distance δ (in lengths of the outer
/// edge) needs a cut at this order: not where the uncut rule is already exact to rounding. A
/// singularity at distance δ above the middle of the edge limits the `order`-point rule to
/// ρ^(−2·order), ρ = 2δ + √(1 + 4δ²); that is below ε where 2·order·ln ρ ≥ −ln ε (f64: beyond
/// 2.3 edge lengths at order 8, 0.69 at 16). Closer singular points are cut and graded towards
/// ([`graded_piece`]), so skipping the others saves work without costing accuracy.
fn needs_cut<T: Real>(delta: T, order: usize) -> bool {
    let two_delta = delta * T::TWO;
    let rho = two_delta + (T::ONE + two_delta * two_delta).sqrt();
    T::TWO * T::from_usize(order) * rho.ln() < -T::EPSILON.ln()
}

/// ∫₀¹∫₀¹ ln |P + σ d_a − Q − τ d_b| dτ dσ (see the module docs), the same integral of the
/// magnitudes of the closed form's two terms (what its rounding scales with), and the
/// evaluations.
pub(super) fn edge_pair<T: Real>(rule: &GaussRule<T>, a: Edge<T>, b: Edge<T>) -> (T, T, u64) {
    let (p, da, len_a) = (a.start, a.vector, a.length);
    let (q, db, len_b) = (b.start, b.vector, b.length);
    let e = db.scale(T::ONE / len_b);
    // Foot of x(σ) along e: u₀(σ) = f0 + σ f1.
    let (f0, f1) = ((p - q).dot(e), da.dot(e));
    let mut cuts = [T::ZERO; 5];
    let mut nc = 0usize;
    // A cut only where the uncut rule would not be exact to rounding ([`needs_cut`]).
    let distance = |s: T| segment_distance(p + da.scale(s) - q, db, len_b) / len_a;
    let mut add = |x: T| {
        if x > T::ZERO && x < T::ONE && needs_cut(distance(x), rule.order()) {
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
    let half_inv = T::HALF / len_b;
    // [G(L − u₀) − G(−u₀)]/2L with G's two arctangents as one: atan((L − u₀)/η) + atan(u₀/η)
    // = atan2(Lη, η² − u₀(L − u₀)) (their sum is L/η > 0, so the angle lies in (0, π)).
    let inner = |s: T| {
        let w = p + da.scale(s) - q;
        let u0 = w.dot(e);
        let eta = w.cross(e).norm();
        let (v1, v0) = (len_b - u0, u0);
        let eta2 = eta * eta;
        let (r1, r0) = (v1 * v1 + eta2, v0 * v0 + eta2);
        let log1 = if r1 > T::ZERO { v1 * r1.ln() } else { T::ZERO };
        let log0 = if r0 > T::ZERO { v0 * r0.ln() } else { T::ZERO };
        let angle = if eta > T::ZERO { T::TWO * eta * (len_b * eta).atan2(eta2 - v0 * v1) } else { T::ZERO };
        let linear = T::TWO * len_b;
        let value = log1 + log0 - linear + angle;
        (value * half_inv, (log1.abs() + log0.abs() + linear + angle) * half_inv)
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

/// Edge pairs whose double integral is elementary: parallel edges (collinear ones included)
/// and edges meeting at a common end, as ([`edge_pair`]'s value, magnitude, evaluations — one
/// per closed-form term). `None` for the others, and where the closed form's terms exceed
/// [`CLOSED_CANCELLATION`] times max(|value|, 1) (an edge short against its distance from the
/// other: the terms are differences of nearly equal values there, while the graded rule keeps
/// the digits). The geometry is at unit size, where ∫∫ |ln r| is O(1): the rule's own rounding
/// is about ε·max(|value|, 1), whatever the sign changes of ln r make of the value.
pub(super) fn closed_edge_pair<T: Real>(a: Edge<T>, b: Edge<T>) -> Option<(T, T, u64)> {
    let (p, da, len_a) = (a.start, a.vector, a.length);
    let (q, db, len_b) = (b.start, b.vector, b.length);
    let tiny = T::from_f64(16.0) * T::EPSILON;
    let parallel = tiny * len_a * len_b;
    let (value, magnitude, terms) = if da.cross(db).norm2() <= parallel * parallel {
        parallel_edges(a, b)
    } else {
        // A common end, and each edge as a vector away from it.
        let touch = tiny * len_a.max(len_b);
        let ends = [(p, da), (p + da, -da)];
        let (a, b) = ends.iter().find_map(|&(x, a)| {
            [(q, db), (q + db, -db)].iter().find_map(|&(y, b)| ((x - y).norm2() <= touch * touch).then_some((a, b)))
        })?;
        edges_from_one_point(a, len_a, b, len_b)
    };
    (value.is_finite() && magnitude <= T::from_f64(CLOSED_CANCELLATION) * value.abs().max(T::ONE))
        .then_some((value, magnitude, terms))
}

/// Largest ratio of the closed form's term magnitudes to max(|value|, 1) that
/// [`closed_edge_pair`] accepts (2.4 digits: the catalogue's squares, sharing edges or corners
/// or facing, reach 58).
const CLOSED_CANCELLATION: f64 = 256.0;

/// ∫₀¹∫₀¹ ln |x(σ) − y(τ)| for parallel edges: with u along b's direction, x(σ) runs over
/// u ∈ [u₀, u₁] at the constant distance h from b's line, y over [0, L_b], and
///
/// ∫∫ ln((u − v)² + h²) du dv = K(u₁) + K(u₀ − L_b) − K(u₁ − L_b) − K(u₀),
/// K(w) = ½(w² − h²) ln(w² + h²) − 3w²/2 + 2hw atan(w/h)  (K″ = ln(w² + h²), K′ = G),
///
/// divided by 2(u₁ − u₀)L_b; the polynomial part −3w²/2 sums to −3(u₁ − u₀)L_b exactly. Two identical collinear edges of length L give
/// L²(ln L² − 3)/(2L²) (`../shared/REFERENCES.md`).
fn parallel_edges<T: Real>(a: Edge<T>, b: Edge<T>) -> (T, T, u64) {
    let (len_a, len_b) = (a.length, b.length);
    let e = b.vector.scale(T::ONE / len_b);
    let w = a.start - b.start;
    let h = w.cross(e).norm();
    let (f0, f1) = (w.dot(e), a.vector.dot(e));
    let (u0, u1) = if f1 < T::ZERO { (f0 + f1, f0) } else { (f0, f0 + f1) };
    let terms = [big_k(u1, h), big_k(u0 - len_b, h), -big_k(u1 - len_b, h), -big_k(u0, h)];
    let scale = T::ONE / (T::TWO * len_a * len_b);
    let (sum, magnitude) = terms.iter().fold((T::ZERO, T::ZERO), |(s, m), &k| (s + k, m + k.abs()));
    // K's polynomial part −3w²/2 sums to −3(u₁ − u₀)L_b exactly: −3/2 after the scale.
    let poly = T::from_f64(1.5);
    (sum * scale - poly, magnitude * scale + poly, 4)
}

/// ∫₀¹∫₀¹ ln |σa − τb| for edges a, b leaving one point at an angle θ (cos θ = c,
/// sin θ = s, s > 0), lengths A, B. Splitting [0, A] × [0, B] along its diagonal, each triangle is
/// ρ ↦ (ρ, ρvβ) (β = B/A) or its mirror, and ln(p² + q² − 2pqc) = 2 ln ρ + ln((βv − c)² + s²)
/// separates:
///
/// I = (ln(AB) − 1)/2 + (M(B/A) + M(A/B))/4,  M(β) = ∫₀¹ ln((βv − c)² + s²) dv
///   = [G(β − c) − G(−c)]/β  (G at η = s).
fn edges_from_one_point<T: Real>(a: Vec3<T>, len_a: T, b: Vec3<T>, len_b: T) -> (T, T, u64) {
    let ab = len_a * len_b;
    let (c, s) = (a.dot(b) / ab, a.cross(b).norm() / ab);
    let g0 = big_g(-c, s);
    let m = |beta: T| {
        let g1 = big_g(beta - c, s);
        ((g1 - g0) / beta, (g1.abs() + g0.abs()) / beta)
    };
    let (m1, m2) = (m(len_b / len_a), m(len_a / len_b));
    let quarter = T::HALF * T::HALF;
    let log = (ab.ln() - T::ONE) * T::HALF;
    (log + (m1.0 + m2.0) * quarter, log.abs() + (m1.1 + m2.1) * quarter, 3)
}

/// K(w) + 3w²/2 = ½(w² − h²) ln(w² + h²) + 2hw atan(w/h) (K = ∫ G up to a constant; its
/// polynomial part is summed exactly by the caller).
#[inline]
pub(super) fn big_k<T: Real>(w: T, h: T) -> T {
    let (w2, h2) = (w * w, h * h);
    let r2 = w2 + h2;
    let log_term = if r2 > T::ZERO { (w2 - h2) * T::HALF * r2.ln() } else { T::ZERO };
    let angle = if h > T::ZERO { T::TWO * h * w * (w / h).atan() } else { T::ZERO };
    log_term + angle
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
