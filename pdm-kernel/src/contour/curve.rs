//! Two flat patches with curved edges: the double line integral along both outlines.

use super::*;

/// Cuts at most per edge pair where one edge passes close over the other (two per sampled
/// local minimum of the distance).
pub(super) const MAX_CROSSINGS: usize = 6;
/// Samples of the distance between two edges along the outer one.
pub(super) const CROSSING_SAMPLES: usize = 64;

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
pub(super) fn nearest<T: Real>(c: &impl Fn(T) -> (Vec3<T>, Vec3<T>), p: Vec3<T>) -> (T, T, u64) {
    let f = |tau: T| {
        let (q, d) = c(tau);
        let w = q - p;
        (w.dot(w), T::TWO * w.dot(d))
    };
    minimise(&f, T::ZERO, T::ONE)
}

/// ∫₀¹∫₀¹ ln |x(σ) − y(τ)| x′(σ)·y′(τ) dτ dσ for two curved edges, the same integral of the
/// integrand's magnitude, and the evaluations (see [`curve_exchange`]).
pub(super) fn curve_pair<T: Real>(
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
