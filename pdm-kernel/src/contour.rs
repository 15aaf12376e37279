//! Flat pairs by the contour (Stokes) form: for two flat patches that see each other wholly
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
//!
//! # Curved edges
//! The form holds for any two flat patches, whatever their edges: a disk or annulus sector, a
//! planar Bézier patch, a disk against a parallelogram ([`Outline`], [`curve_exchange`]). An
//! edge is then the image of a side of the parameter rectangle, x(σ) = g(t(σ), s(σ)) with
//! x′(σ) from the surface's partial derivatives, and the inner integral
//! ∫ ln |x − y(τ)| x′·y′(τ) dτ has no closed form. Its integrand is analytic except near the
//! point of y nearest to x (complex singularities at the distance η of x from y): it is cut
//! there and graded geometrically towards that point and the edge's ends, down to their
//! distances from x, so the inner rule converges exponentially at every gap. The outer
//! integrand is analytic except where x(σ) passes close to an end of y or comes closest to y
//! (where the edges cross, seen along the normal): cut and graded there the same way. A
//! parallel edge at a constant small distance (the rims of coaxial disks) needs no cut: the
//! outer integrand's singularities then lie only at the other edge's ends.

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::patch::Patch;
use crate::real::Real;
use crate::surface::{ParamRect, Surface};
use crate::vec3::{vec3, Vec3};

/// Most geometric cuts towards one singular point (4^24 ≈ 3e14: any gap above rounding).
const MAX_LEVELS: usize = 26;

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

/// (∫ f, ∫ |f|) over [x0, x1] by the rule, f given as x ↦ (f(x), |f(x)|).
fn rule_on<T: Real>(rule: &GaussRule<T>, x0: T, x1: T, f: &impl Fn(T) -> (T, T)) -> (T, T) {
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

/// A flat patch's boundary for the contour form: the four edges of its parameter rectangle,
/// (t0, s0) → (t1, s0) → (t1, s1) → (t0, s1) → (t0, s0), which run counter-clockwise about
/// ∂g/∂t × ∂g/∂s, with `sign` = −1 when the patch radiates to the other side (reversing a
/// closed contour negates its integral).
pub(crate) struct Outline<'p, T: Real, S: Surface<T> + ?Sized> {
    surface: &'p S,
    rect: ParamRect<T>,
    sign: T,
    /// Edges of non-zero length (a disk sector's edge at r = 0 is a point).
    live: [bool; 4],
    /// The unit radiating normal and a point of the plane (the patch's centre).
    pub(crate) normal: Vec3<T>,
    pub(crate) origin: Vec3<T>,
    /// The largest distance of the patch from `origin`.
    size: T,
}

/// Grid points per side on which [`Outline::new`] checks that a patch is flat.
const FLAT_GRID: usize = 7;

impl<'p, T: Real, S: Surface<T> + ?Sized> Outline<'p, T, S> {
    /// The outline of a flat patch whose surface gives its partial derivatives
    /// ([`Surface::point_and_partials`]); `None` if it gives none or the patch is not flat: its
    /// points on a 7 × 7 grid (edges included, interior nodes off the rational fractions)
    /// within 64 ε of its size from the plane through its centre, its unit normals there (where
    /// not zero) within 64 ε of the centre's. A sampled test: a map bent only between the nodes
    /// would pass it.
    pub(crate) fn new(p: &Patch<'p, T, S>) -> Option<Self> {
        let (surface, rect) = (p.surface(), p.rect());
        let (tm, sm) = ((rect.t0 + rect.t1) * T::HALF, (rect.s0 + rect.s1) * T::HALF);
        let (origin, gt, gs) = surface.point_and_partials(tm, sm)?;
        let normal = unit(surface.normal(tm, sm))?;
        let sign = if normal.dot(gt.cross(gs)) >= T::ZERO { T::ONE } else { -T::ONE };
        // The sides' ends, and interior points shifted off the rational fractions by the
        // golden ratio's fractional parts: a bump that vanishes with zero slope on a uniform
        // grid (sin² 6πt) would pass a uniform test.
        let node = |i: usize| {
            let uniform = T::from_usize(i) / T::from_usize(FLAT_GRID - 1);
            if i == 0 || i + 1 == FLAT_GRID {
                uniform
            } else {
                #[allow(clippy::cast_precision_loss)]
                let golden = (i as f64 * 0.618_033_988_749_895) % 1.0;
                uniform + T::from_f64(golden - 0.5) / T::from_usize(2 * (FLAT_GRID - 1))
            }
        };
        let at = |i: usize, j: usize| {
            let (x, y) = (node(i), node(j));
            surface.point_and_normal(rect.t0 + (rect.t1 - rect.t0) * x, rect.s0 + (rect.s1 - rect.s0) * y)
        };
        let mut size = T::ZERO;
        for k in 0..FLAT_GRID * FLAT_GRID {
            size = size.max((at(k / FLAT_GRID, k % FLAT_GRID).0 - origin).norm());
        }
        if !(size > T::ZERO) || !size.is_finite() {
            return None;
        }
        let tolerance = T::from_f64(64.0) * T::EPSILON;
        for k in 0..FLAT_GRID * FLAT_GRID {
            let (q, n) = at(k / FLAT_GRID, k % FLAT_GRID);
            if normal.dot(q - origin).abs() > tolerance * size {
                return None;
            }
            if let Some(n) = unit(n) {
                if n.dot(normal) < T::ONE - tolerance {
                    return None;
                }
            }
        }
        let mut outline = Self { surface, rect, sign, live: [true; 4], normal, origin, size };
        let mut live = [true; 4];
        for (k, slot) in live.iter_mut().enumerate() {
            let longest = [T::ZERO, T::HALF, T::ONE].iter().fold(T::ZERO, |m, &x| m.max(outline.edge(k, x).1.norm()));
            *slot = longest > size * T::GEOMETRY_TOLERANCE;
        }
        outline.live = live;
        Some(outline)
    }

    /// Point and derivative d/dτ of edge k at τ ∈ [0, 1] (NaN if the surface stops giving
    /// partial derivatives, which makes the sum non-finite and refused).
    fn edge(&self, k: usize, tau: T) -> (Vec3<T>, Vec3<T>) {
        let r = self.rect;
        let (wt, ws) = (r.t1 - r.t0, r.s1 - r.s0);
        let (t, s, along_t, forward) = match k {
            0 => (r.t0 + wt * tau, r.s0, true, true),
            1 => (r.t1, r.s0 + ws * tau, false, true),
            2 => (r.t1 - wt * tau, r.s1, true, false),
            _ => (r.t0, r.s1 - ws * tau, false, false),
        };
        // ∞ · 0: NaN, without a NaN constant in `Real`.
        let nan = T::MAX * T::TWO * T::ZERO;
        let nan = vec3(nan, nan, nan);
        let (p, gt, gs) = self.surface.point_and_partials(t, s).unwrap_or((nan, nan, nan));
        let d = if along_t { gt.scale(wt) } else { gs.scale(ws) };
        (p, if forward { d } else { -d })
    }

    /// Where the patch lies against the plane through `o` with unit normal `n`: `None` if some
    /// point is behind it by more than `band`, else whether some point is ahead of it by more
    /// than `band`. The height n·(x − o) is linear on a flat patch: least and largest on its
    /// edges, each searched by [`minimise`].
    pub(crate) fn ahead_of(&self, o: Vec3<T>, n: Vec3<T>, band: T) -> Option<bool> {
        let lowest = |n: Vec3<T>| {
            (0..4).fold(T::MAX, |m, k| {
                let height = |x: T| {
                    let (p, d) = self.edge(k, x);
                    (n.dot(p - o), n.dot(d))
                };
                m.min(minimise(&height, T::ZERO, T::ONE).1)
            })
        };
        if lowest(n) < -band {
            None
        } else {
            Some(-lowest(-n) > band)
        }
    }

    /// Its largest distance from its centre.
    pub(crate) fn size(&self) -> T {
        self.size
    }

    /// J(p) = ∫ cos θ_p cos θ_q / L² dA over the part of the patch in front of the tangent plane
    /// of p (unit normal `np`), nothing between them, by the line form of Lambert's
    /// point-to-polygon formula (`../shared/REFERENCES.md`):
    ///
    /// J(p) = ½ |n̂_p · ∮ r × dr / |r|²|,  r = x − p,
    ///
    /// around the boundary of that part: the pieces of the edges in front of the plane (between
    /// the edges' crossings of it; each piece cut at its point nearest to p and graded towards
    /// it and towards its ends, down to their distances from p, so the rule converges
    /// exponentially however close p comes) and the chords of the plane across the patch
    /// between consecutive crossings (straight: angle × unit normal, in closed form). Returns
    /// (J, the sum of the terms' magnitudes, evaluations); zero if the patch faces away from p;
    /// `None` if the crossings do not pair up (an edge tangent to the plane) or exceed the
    /// buffers. An edge's crossings are found between 16 samples and its extremes of height.
    pub(crate) fn point_form(&self, rule: &GaussRule<T>, p: Vec3<T>, np: Vec3<T>) -> Option<(T, T, u64)> {
        if !(self.normal.dot(p - self.origin) > T::ZERO) {
            return Some((T::ZERO, T::ZERO, 0));
        }
        let mut evaluations = 0u64;
        let (mut total, mut magnitude) = (T::ZERO, T::ZERO);
        // Crossing points of the plane, along the chord direction: boundaries run
        // counter-clockwise about m = ∂g/∂t × ∂g/∂s, so the part in front of the plane lies to
        // the left of d = n̂_p × m on each chord.
        let m = self.normal.scale(self.sign);
        let chord_dir = np.cross(m);
        let band = T::from_f64(64.0) * T::EPSILON * (self.size + (p - self.origin).norm());
        let mut crossings = [(T::ZERO, Vec3::ZERO); 2 * MAX_EDGE_CROSSINGS];
        let mut nx = 0usize;
        for k in 0..4 {
            if !self.live.get(k).copied().unwrap_or(false) {
                continue;
            }
            let edge = |tau: T| self.edge(k, tau);
            let height = |tau: T| {
                let (x, d) = edge(tau);
                (np.dot(x - p), np.dot(d))
            };
            // Break points: samples, the extremes of the height, its roots between them.
            let mut probes = [T::ZERO; EDGE_SAMPLES + 3];
            for (i, slot) in probes.iter_mut().enumerate().take(EDGE_SAMPLES + 1) {
                *slot = T::from_usize(i) / T::from_usize(EDGE_SAMPLES);
            }
            let (low, lowest, n1) = minimise(&height, T::ZERO, T::ONE);
            let (high, _, n2) = minimise(
                &|tau: T| {
                    let (h, dh) = height(tau);
                    (-h, -dh)
                },
                T::ZERO,
                T::ONE,
            );
            evaluations = evaluations.saturating_add(n1 + n2 + EDGE_SAMPLES as u64 + 1);
            if let Some(a) = probes.get_mut(EDGE_SAMPLES + 1) {
                *a = low;
            }
            if let Some(b) = probes.get_mut(EDGE_SAMPLES + 2) {
                *b = high;
            }
            sort(&mut probes);
            let mut breaks = [T::ZERO; MAX_EDGE_CROSSINGS + 2];
            let mut nb = 1usize;
            // An edge that reaches the plane only within the heights' rounding touches it (a
            // rim tangent to it): no crossing, nothing cut.
            let touches = !(lowest < -band);
            for w in probes.windows(2) {
                let (Some(&a), Some(&b)) = (w.first(), w.get(1)) else { continue };
                if touches {
                    break;
                }
                let (ha, hb) = (height(a).0, height(b).0);
                if (ha > T::ZERO) == (hb > T::ZERO) || !(b > a) {
                    continue;
                }
                // The root, by Illinois on h (or −h, rising from a to b).
                let sign = if ha > T::ZERO { -T::ONE } else { T::ONE };
                let rising = |tau: T| {
                    let (h, _) = height(tau);
                    (T::ZERO, sign * h)
                };
                let (root, _, n) = slope_root(&rising, (a, sign * ha), (b, sign * hb));
                evaluations = evaluations.saturating_add(n);
                let slot = breaks.get_mut(nb)?;
                *slot = root;
                nb += 1;
                let (point, _) = edge(root);
                *crossings.get_mut(nx)? = (chord_dir.dot(point - p), point);
                nx += 1;
            }
            *breaks.get_mut(nb)? = T::ONE;
            nb += 1;
            // The pieces in front of the plane.
            let (tau_near, d2, n) = nearest(&edge, p);
            evaluations = evaluations.saturating_add(n);
            let spacing = |tau: T, dist: T| {
                let speed = edge(tau).1.norm();
                if speed > T::ZERO {
                    dist / speed
                } else {
                    T::MAX
                }
            };
            let to = |tau: T| spacing(tau, (edge(tau).0 - p).norm());
            let near = spacing(tau_near, d2.sqrt());
            let f = |tau: T| {
                let (x, d) = edge(tau);
                let r = x - p;
                let r2 = r.dot(r);
                let v = if r2 > T::ZERO { np.dot(r.cross(d)) / r2 } else { T::ZERO };
                (v, v.abs())
            };
            for w in breaks.get(..nb).unwrap_or_default().windows(2) {
                let (Some(&lo), Some(&hi)) = (w.first(), w.get(1)) else { continue };
                if !(hi > lo) || !(height((lo + hi) * T::HALF).0 > if touches { -band } else { T::ZERO }) {
                    continue;
                }
                let mut add = |a: T, b: T, da: T, db: T| {
                    let ((v, mag), n) = graded_line(rule, a, b, da, db, &f);
                    total += v;
                    magnitude += mag;
                    evaluations = evaluations.saturating_add(n);
                };
                if tau_near > lo && tau_near < hi {
                    add(lo, tau_near, to(lo), near);
                    add(tau_near, hi, near, to(hi));
                } else {
                    add(lo, hi, to(lo), to(hi));
                }
            }
        }
        // The chords: the plane's line inside the patch between consecutive crossings.
        let used = crossings.get_mut(..nx).unwrap_or_default();
        if !nx.is_multiple_of(2) {
            return None;
        }
        for i in 1..used.len() {
            let mut j = i;
            while j > 0 {
                let (Some(&a), Some(&b)) = (used.get(j - 1), used.get(j)) else { break };
                if !(b.0 < a.0) {
                    break;
                }
                used.swap(j - 1, j);
                j -= 1;
            }
        }
        for pair in used.chunks_exact(2) {
            let (Some(&(_, from)), Some(&(_, to))) = (pair.first(), pair.get(1)) else { continue };
            let (a, b) = (from - p, to - p);
            let c = a.cross(b);
            let sine = c.norm();
            if sine > T::ZERO {
                let term = sine.atan2(a.dot(b)) * np.dot(c) / sine;
                total += term;
                magnitude += term.abs();
            }
        }
        let j = total.abs() * T::HALF;
        j.is_finite().then_some((j, magnitude * T::HALF, evaluations))
    }
}

/// ∫_lo^hi f with the rule on pieces graded geometrically (ratio 2) from each end towards the
/// middle, the first piece at an end as wide as the distance `d_lo` / `d_hi` of that end from
/// the integrand's nearest singularity (in parameter units): every piece then sees its
/// singularities at least its own half-width beyond its ends, where the rule's error falls like
/// 5^(−2·order). Returns ((∫ f, ∫ |f|), evaluations).
fn graded_line<T: Real>(
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
const GRADED_LEVELS: usize = 48;

/// Samples of the height over p's tangent plane along an edge in [`Outline::point_form`].
const EDGE_SAMPLES: usize = 16;
/// Most crossings of p's tangent plane with one edge in [`Outline::point_form`].
const MAX_EDGE_CROSSINGS: usize = 8;

/// The unit vector along n, `None` for a zero or non-finite n.
fn unit<T: Real>(n: Vec3<T>) -> Option<Vec3<T>> {
    let length = n.norm();
    (length > T::ZERO && length.is_finite()).then(|| n.scale(T::ONE / length))
}

/// Samples per interval in [`minimise`].
const MIN_SAMPLES: usize = 8;

/// The least value of a smooth f on [lo, hi], given as x ↦ (f(x), f′(x)): the least of nine
/// equally spaced samples, refined by a root of f′ (Illinois) in the bracket around it when f′
/// changes sign there. Returns (x, f(x), evaluations).
fn minimise<T: Real>(f: &impl Fn(T) -> (T, T), lo: T, hi: T) -> (T, T, u64) {
    let step = (hi - lo) / T::from_usize(MIN_SAMPLES);
    let at = |k: usize| if k == MIN_SAMPLES { hi } else { lo + step * T::from_usize(k) };
    let mut best = (0usize, T::MAX);
    let mut samples = [(T::ZERO, T::ZERO); MIN_SAMPLES + 1];
    for (k, slot) in samples.iter_mut().enumerate() {
        *slot = f(at(k));
        if slot.0 < best.1 {
            best = (k, slot.0);
        }
    }
    let mut evaluations = (MIN_SAMPLES + 1) as u64;
    let (k, value) = best;
    let (below, above) = (k.saturating_sub(1), (k + 1).min(MIN_SAMPLES));
    let (Some(&(_, slope_lo)), Some(&(_, slope_hi))) = (samples.get(below), samples.get(above)) else {
        return (at(k), value, evaluations);
    };
    if !(slope_lo < T::ZERO && slope_hi > T::ZERO) {
        return (at(k), value, evaluations);
    }
    let (x, v, n) = slope_root(f, (at(below), slope_lo), (at(above), slope_hi));
    evaluations += n;
    if v < value {
        (x, v, evaluations)
    } else {
        (at(k), value, evaluations)
    }
}

/// A root of f′ between a (f′ < 0) and b (f′ > 0) by the Illinois variant of regula falsi,
/// to a few ulps: (x, f(x), evaluations).
fn slope_root<T: Real>(f: &impl Fn(T) -> (T, T), a: (T, T), b: (T, T)) -> (T, T, u64) {
    let ((mut lo, mut slo), (mut hi, mut shi)) = (a, b);
    let mut side = 0i8;
    let mut evaluations = 0u64;
    let mut last = (lo, T::MAX);
    for _ in 0..64 {
        let mut x = (lo * shi - hi * slo) / (shi - slo);
        if !(x > lo && x < hi) {
            x = (lo + hi) * T::HALF;
        }
        let (v, s) = f(x);
        evaluations += 1;
        last = (x, v);
        if s < T::ZERO {
            lo = x;
            slo = s;
            if side < 0 {
                shi *= T::HALF;
            }
            side = -1;
        } else if s > T::ZERO {
            hi = x;
            shi = s;
            if side > 0 {
                slo *= T::HALF;
            }
            side = 1;
        } else {
            break;
        }
        if !(hi - lo > T::from_f64(4.0) * T::EPSILON * (lo.abs() + hi.abs())) {
            break;
        }
    }
    (last.0, last.1, evaluations)
}

/// Cuts at most per edge pair where one edge passes close over the other (two per sampled
/// local minimum of the distance).
const MAX_CROSSINGS: usize = 6;
/// Samples of the distance between two edges along the outer one.
const CROSSING_SAMPLES: usize = 64;

/// A_a·F_{a→b}, the evaluations and a bound on the value's rounding error for two flat patches
/// with curved edges ([`Outline`]), each wholly in front of (or on) the other's plane, no
/// occluder between them: the contour form over their edges. There is no closed form for the
/// inner line integral along a curved edge: for each outer point x it is summed on pieces cut at
/// the edge's point nearest to x and graded geometrically towards it and towards the ends, down
/// to the distance of x from them, which makes the inner rule exponential at every gap; the
/// outer rule is cut where the outer edge passes nearest to the inner edge's ends and where it
/// comes closest to the inner edge (up to six such places, both halves of each sampled minimum searched), graded the same way. The rounding
/// is bounded and refused as in [`quad_exchange`].
pub(crate) fn curve_exchange<T, SA, SB>(
    a: &Outline<'_, T, SA>,
    b: &Outline<'_, T, SB>,
    order: usize,
) -> Result<(T, u64, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let rule = GaussRule::<T>::new(order)?;
    let centroid = (a.origin + b.origin).scale(T::HALF);
    let size = ((a.origin - centroid).norm() + a.size).max((b.origin - centroid).norm() + b.size);
    if !(size > T::ZERO) || !size.is_finite() {
        return Err(PdmError::Degenerate);
    }
    let inv = T::ONE / size;
    let mut total = T::ZERO;
    let mut magnitude = T::ZERO;
    let mut evaluations = 0u64;
    for i in (0..4).filter(|&i| a.live.get(i) == Some(&true)) {
        let x = |s: T| {
            let (p, d) = a.edge(i, s);
            ((p - centroid).scale(inv), d.scale(inv))
        };
        for j in (0..4).filter(|&j| b.live.get(j) == Some(&true)) {
            let y = |s: T| {
                let (p, d) = b.edge(j, s);
                ((p - centroid).scale(inv), d.scale(inv))
            };
            let (v, m, n) = curve_pair(&rule, &x, &y);
            total += v;
            magnitude += m;
            evaluations = evaluations.saturating_add(n);
        }
    }
    if !total.is_finite() || !magnitude.is_finite() {
        return Err(PdmError::InvalidResult);
    }
    let rounding = T::from_f64(8.0) * T::EPSILON * magnitude;
    let scale = size * size * T::FRAC_1_PI * T::HALF * a.sign * b.sign;
    Ok((total * scale, evaluations, rounding * scale.abs()))
}

/// The point of curve c (τ ↦ (point, d/dτ)) nearest to p: (τ, squared distance, evaluations).
fn nearest<T: Real>(c: &impl Fn(T) -> (Vec3<T>, Vec3<T>), p: Vec3<T>) -> (T, T, u64) {
    let f = |tau: T| {
        let (q, d) = c(tau);
        let w = q - p;
        (w.dot(w), T::TWO * w.dot(d))
    };
    minimise(&f, T::ZERO, T::ONE)
}

/// ∫₀¹∫₀¹ ln |x(σ) − y(τ)| x′(σ)·y′(τ) dτ dσ for two curved edges, the same integral of the
/// integrand's magnitude, and the evaluations (see [`curve_exchange`]).
fn curve_pair<T: Real>(
    rule: &GaussRule<T>,
    x: &impl Fn(T) -> (Vec3<T>, Vec3<T>),
    y: &impl Fn(T) -> (Vec3<T>, Vec3<T>),
) -> (T, T, u64) {
    let count = core::cell::Cell::new(0u64);
    let tally = |n: u64| count.set(count.get().saturating_add(n));
    // Squared distance from x(σ) to curve y and its σ-derivative (envelope theorem).
    let gap = |s: T| {
        let (p, d) = x(s);
        let (tau, d2, n) = nearest(y, p);
        tally(n + 2);
        (d2, T::TWO * (p - y(tau).0).dot(d))
    };
    let (y0, y1) = (y(T::ZERO).0, y(T::ONE).0);
    let mut cuts = [T::ZERO; 2 + MAX_CROSSINGS];
    let mut nc = 0usize;
    let mut add = |c: T| {
        if c > T::ZERO && c < T::ONE {
            if let Some(slot) = cuts.get_mut(nc) {
                *slot = c;
                nc += 1;
            }
        }
    };
    for end in [y0, y1] {
        let towards = |s: T| {
            let (p, d) = x(s);
            let w = p - end;
            (w.dot(w), T::TWO * w.dot(d))
        };
        let (s, _, n) = minimise(&towards, T::ZERO, T::ONE);
        tally(n);
        add(s);
    }
    // Where x passes close over y: interior local minima of the distance, well below its
    // largest value (a parallel edge at a constant distance has none and needs none).
    let mut d2 = [T::ZERO; CROSSING_SAMPLES + 1];
    for (k, slot) in d2.iter_mut().enumerate() {
        *slot = gap(T::from_usize(k) / T::from_usize(CROSSING_SAMPLES)).0;
    }
    let largest = d2.iter().fold(T::ZERO, |m, &v| m.max(v));
    let mut found = 0usize;
    // A sample at an end counts too: the closest approach may lie between it and the next
    // sample, inside the edge (an arc crossing a square's edge just short of its corner).
    for k in 0..=CROSSING_SAMPLES {
        let (before, after) = (k.saturating_sub(1), (k + 1).min(CROSSING_SAMPLES));
        let (Some(&below), Some(&here), Some(&above)) = (d2.get(before), d2.get(k), d2.get(after)) else { continue };
        if found + 2 <= MAX_CROSSINGS && here <= below && here <= above && here < largest * T::HALF * T::HALF {
            // Each half of the bracket on its own: an edge that clips a shallow cap off a
            // curved one crosses it twice within a sample spacing, and both need a cut.
            let step = T::ONE / T::from_usize(CROSSING_SAMPLES);
            let (lo, mid, hi) = (step * T::from_usize(before), step * T::from_usize(k), step * T::from_usize(after));
            let (left, _, _) = minimise(&gap, lo, mid);
            let (right, _, _) = minimise(&gap, mid, hi);
            add(left);
            if right != left {
                add(right);
            }
            found += 2;
        }
    }
    let used = cuts.get_mut(..nc).unwrap_or_default();
    sort(used);
    // Distance from x(σ) to y in σ units.
    let distance = |s: T| {
        let (d2, _) = gap(s);
        let speed = x(s).1.norm();
        if speed > T::ZERO {
            d2.sqrt() / speed
        } else {
            T::MAX
        }
    };
    let inner = |s: T| {
        let (p, dp) = x(s);
        let (tau, d2, n) = nearest(y, p);
        tally(n);
        let f = |t: T| {
            let (q, dq) = y(t);
            let w = q - p;
            let r2 = w.dot(w);
            let log = if r2 > T::ZERO { T::HALF * r2.ln() } else { T::ZERO };
            let v = log * dp.dot(dq);
            (v, v.abs())
        };
        let spacing = |t: T, dist: T| {
            let speed = y(t).1.norm();
            if speed > T::ZERO {
                dist / speed
            } else {
                T::MAX
            }
        };
        let to_end = |t: T, q: Vec3<T>| spacing(t, (q - p).norm());
        let near = spacing(tau, d2.sqrt());
        let mut sum = (T::ZERO, T::ZERO);
        if tau > T::ZERO {
            let (v, n) = graded_piece(rule, T::ZERO, tau, to_end(T::ZERO, y0), near, &f);
            sum = (sum.0 + v.0, sum.1 + v.1);
            tally(n);
        }
        if tau < T::ONE {
            let (v, n) = graded_piece(rule, tau, T::ONE, near, to_end(T::ONE, y1), &f);
            sum = (sum.0 + v.0, sum.1 + v.1);
            tally(n);
        }
        sum
    };
    let mut total = (T::ZERO, T::ZERO);
    let mut lo = T::ZERO;
    for hi in used.iter().copied().chain(core::iter::once(T::ONE)) {
        if hi > lo {
            let (v, n) = graded_piece(rule, lo, hi, distance(lo), distance(hi), &inner);
            total = (total.0 + v.0, total.1 + v.1);
            tally(n);
        }
        lo = hi;
    }
    (total.0, total.1, count.get())
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

    /// The graded rules along curved edges against the closed-form inner integral, on
    /// parallelograms (whose edges either path takes): squares offset so that their edges cross
    /// seen along the normal, one tilted, gaps 0.3 … 1e-6 — the crossings, the ends passing
    /// close and the corners over the other's edges are the singular points the outer rule
    /// must find.
    #[test]
    fn graded_edges_agree_with_the_closed_form() {
        use crate::surface::Parallelogram;
        for h in [0.3, 1e-2, 1e-4, 1e-6] {
            for (offset, tilt) in [((0.0, 0.0), 0.0), ((0.37, 0.21), 0.0), ((0.5, -0.45), 0.1), ((0.999, 0.2), 0.0)] {
                let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
                let upper =
                    Parallelogram::new(vec3(offset.0, offset.1, h), vec3(0.0, 0.8, tilt), vec3(1.2, 0.0, 0.0)).unwrap();
                let (pa, pb) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
                let (oa, ob) = (Outline::new(&pa).unwrap(), Outline::new(&pb).unwrap());
                let (curved, _, rounding) = curve_exchange(&oa, &ob, 16).unwrap();
                let corners = |p: &Parallelogram<f64>| {
                    let (o, et, es) = p.affine_map().unwrap();
                    [o, o + et, o + et + es, o + es]
                };
                let (cl, cu) = (corners(&lower), corners(&upper));
                // The upper one's corners run clockwise about +z, i.e. counter-clockwise about
                // its radiating normal (−z, towards the lower one).
                let (closed, _, _) = quad_exchange::<f64>(&cl, &cu, 16).unwrap();
                // Both sum O(1) terms to a value that can be far smaller (8e-4 where the squares
                // overlap by 1e-3): the quadrature error scales with the terms, as the rounding
                // bound (8 ε × their magnitude) does.
                let difference = (curved - closed).abs();
                assert!(
                    difference < 1e-12 * closed + 64.0 * rounding,
                    "h {h}, offset {offset:?}, tilt {tilt}: {curved} vs {closed}"
                );
            }
        }
    }

    /// Only flat patches have an outline: a cylinder's wall and a sphere cell have none, a disk
    /// sector and a planar Bézier patch do (the sector's edge at r = 0 collapses).
    #[test]
    fn outlines_of_flat_patches_only() {
        use crate::surface::{BezierPatch, Cylinder, Disk, ParamRect, Side, Sphere};
        let z = vec3(0.0, 0.0, 1.0);
        let wall = Cylinder::new(vec3(0.0, 0.0, 0.0), z, 1.0, 1.0, Side::Outer).unwrap();
        assert!(Outline::new(&Patch::whole(&wall).unwrap()).is_none());
        let ball = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let cell = ParamRect::new(0.5, 1.0, 0.0, 1.0).unwrap();
        assert!(Outline::new(&Patch::new(&ball, cell).unwrap()).is_none());
        let disk = Disk::new(vec3(0.0, 0.0, 0.0), z, 1.0).unwrap();
        let sector = Outline::new(&Patch::new(&disk, ParamRect::new(0.0, 1.0, 0.0, 1.0).unwrap()).unwrap()).unwrap();
        assert_eq!(sector.live, [true, true, true, false]);
        let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in control.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                *p = vec3(i as f64 + 0.1 * (j * j) as f64, j as f64, 0.0);
            }
        }
        let flat = BezierPatch::new(control).unwrap();
        assert!(Outline::new(&Patch::whole(&flat).unwrap()).is_some());
        if let Some(p) = control.get_mut(1).and_then(|row| row.get_mut(2)) {
            p.z = 0.01;
        }
        let bent = BezierPatch::new(control).unwrap();
        assert!(Outline::new(&Patch::whole(&bent).unwrap()).is_none());
        // Bumps that vanish with zero slope at t, s = k/6: a uniform 7 × 7 grid sees a plane.
        struct Bumps;
        impl crate::surface::ParametricMap<f64> for Bumps {
            fn domain(&self) -> ParamRect<f64> {
                ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
            }
            fn map<S: crate::dual::Scalar<f64>>(&self, t: S, s: S) -> crate::vec3::Vec3<S> {
                let six_pi = S::constant(6.0 * core::f64::consts::PI);
                let (a, b) = ((t * six_pi).sin(), (s * six_pi).sin());
                vec3(t, s, S::constant(0.05) - S::constant(0.1) * a * a * b * b)
            }
        }
        let bumps = crate::surface::AutoNormal(Bumps);
        assert!(Outline::new(&Patch::whole(&bumps).unwrap()).is_none());
    }
}

#[cfg(test)]
mod point_form_tests {
    use super::*;
    use crate::surface::Disk;
    use crate::vec3::vec3;

    /// Lambert's polygon form for the unit circle as an m-gon clipped by p's tangent plane
    /// (Sutherland–Hodgman, each clipped vertex summed as it is produced).
    fn polygon(p: Vec3<f64>, np: Vec3<f64>, m: usize) -> f64 {
        let corner = |k: usize| {
            let phi = 2.0 * core::f64::consts::PI * ((k % m) as f64) / m as f64;
            vec3(phi.cos(), phi.sin(), 0.0)
        };
        // The polygon's edges as its vertices come: (sum, first vertex, previous vertex).
        let mut state = (0.0, None::<Vec3<f64>>, None::<Vec3<f64>>);
        let add = |state: &mut (f64, Option<Vec3<f64>>, Option<Vec3<f64>>), v: Vec3<f64>| {
            if let Some(u) = state.2 {
                let (a, b) = (u - p, v - p);
                let c = a.cross(b);
                let sine = c.norm();
                if sine > 0.0 {
                    state.0 += sine.atan2(a.dot(b)) * np.dot(c) / sine;
                }
            } else {
                state.1 = Some(v);
            }
            state.2 = Some(v);
        };
        for k in 0..m {
            let (a, b) = (corner(k), corner(k + 1));
            let (da, db) = (np.dot(a - p), np.dot(b - p));
            if da > 0.0 {
                add(&mut state, a);
            }
            if (da > 0.0) != (db > 0.0) {
                add(&mut state, a + (b - a).scale(da / (da - db)));
            }
        }
        if let Some(v) = state.1 {
            add(&mut state, v);
        }
        let sum = state.0;
        0.5 * sum.abs()
    }

    /// The point form over a whole unit disk (curved rim, seam, dead centre edge) against
    /// inscribed 2·10⁴- and 4·10⁴-gons extrapolated in 1/m² (Richardson), written here:
    /// points above the rim whose tangent plane touches it (a double root of the height),
    /// cuts a cap of half-angle 1.4e-5 or 1.4e-3 off it, or crosses the disk obliquely.
    #[test]
    fn point_form_agrees_with_fine_polygons() {
        let disk = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0_f64).unwrap();
        let patch = Patch::whole(&disk).unwrap();
        let outline = Outline::new(&patch).unwrap();
        let wall = |theta: f64, z: f64, shrink: f64| {
            (vec3(theta.cos() * shrink, theta.sin() * shrink, z), vec3(-theta.cos(), -theta.sin(), 0.0))
        };
        let cases = [
            (vec3(0.3, 0.2, 0.5), vec3(1.0, 0.5, 0.3).scale(1.0 / 1.34_f64.sqrt())),
            wall(0.3, 0.1, 1.0),
            wall(1.0, 0.15, 1.0),
            wall(4.0, 0.6, 1.0),
            wall(0.3, 0.1, 1.0 - 1e-10),
            wall(0.3, 0.1, 1.0 - 1e-6),
            wall(4.0, 0.6, 1.0 - 1e-3),
        ];
        for (p, np) in cases {
            let (coarse, fine) = (polygon(p, np, 20_000), polygon(p, np, 40_000));
            let reference = fine + (fine - coarse) / 3.0;
            for order in [12, 16] {
                let rule = GaussRule::<f64>::new(order).unwrap();
                let (j, _, _) = outline.point_form(&rule, p, np).unwrap();
                let rel = ((j - reference) / reference).abs();
                assert!(rel < 1e-12, "p {p:?} order {order}: {j} against {reference} ({rel:.1e})");
            }
        }
    }
}
