//! The outline of a flat patch with curved edges, and Lambert's point-to-polygon form over it
//! clipped by a tangent plane (`Outline::point_form`).

use super::*;

/// A flat patch's boundary for the contour form: the four edges of its parameter rectangle,
/// (t0, s0) → (t1, s0) → (t1, s1) → (t0, s1) → (t0, s0), which run counter-clockwise about
/// ∂g/∂t × ∂g/∂s, with `sign` = −1 when the patch radiates to the other side (reversing a
/// closed contour negates its integral).
pub(crate) struct Outline<'p, T: Real, S: Surface<T> + ?Sized> {
    pub(super) surface: &'p S,
    pub(super) rect: ParamRect<T>,
    pub(super) sign: T,
    /// Edges of non-zero length (a disk sector's edge at r = 0 is a point).
    pub(super) live: [bool; 4],
    /// The unit radiating normal and a point of the plane (the patch's centre).
    pub(crate) normal: Vec3<T>,
    pub(crate) origin: Vec3<T>,
    /// The largest distance of the patch from `origin`.
    pub(super) size: T,
}

/// Grid points per side on which [`Outline::new`] checks that a patch is flat.
pub(super) const FLAT_GRID: usize = 7;

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
    pub(super) fn edge(&self, k: usize, tau: T) -> (Vec3<T>, Vec3<T>) {
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

/// Samples of the height over p's tangent plane along an edge in [`Outline::point_form`].
pub(super) const EDGE_SAMPLES: usize = 16;
/// Most crossings of p's tangent plane with one edge in [`Outline::point_form`].
pub(super) const MAX_EDGE_CROSSINGS: usize = 8;

/// The unit vector along n, `None` for a zero or non-finite n.
pub(super) fn unit<T: Real>(n: Vec3<T>) -> Option<Vec3<T>> {
    let length = n.norm();
    (length > T::ZERO && length.is_finite()).then(|| n.scale(T::ONE / length))
}

/// Samples per interval in [`minimise`].
pub(super) const MIN_SAMPLES: usize = 8;

/// The least value of a smooth f on [lo, hi], given as x ↦ (f(x), f′(x)): the least of nine
/// equally spaced samples, refined by a root of f′ (Illinois) in the bracket around it when f′
/// changes sign there. Returns (x, f(x), evaluations).
pub(super) fn minimise<T: Real>(f: &impl Fn(T) -> (T, T), lo: T, hi: T) -> (T, T, u64) {
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
pub(super) fn slope_root<T: Real>(f: &impl Fn(T) -> (T, T), a: (T, T), b: (T, T)) -> (T, T, u64) {
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
