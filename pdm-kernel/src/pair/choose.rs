//! Choices on the boundary path: whether a pair is near or resolved by the 4-D rule, and which
//! patch goes outside (independent of the argument order).

use super::*;

/// `true` if two patches are closer than the larger one's radius: the plain rule's error then
/// falls slowly with the order (the kernel's nearest singularity is within a patch size), and the
/// boundary path, which refines the inner patch towards each outer point, takes the pair.
pub(crate) fn near<T: Real>(a: &crate::samples::Ball<T>, b: &crate::samples::Ball<T>) -> bool {
    (a.center - b.center).norm() - a.radius - b.radius < a.radius.max(b.radius)
}

/// `true` if the facing test (`integrand::mutually_facing`) is proven to give one answer for
/// every pair of points of the two patches — all facing each other, or none — from their normal
/// cones ([`Patch::normal_cone`]) and enclosing balls: the directions y − x (x on a, y on b) lie
/// within β = asin((r_a + r_b)/|c_b − c_a|) of the line of centres, so a's normals all face b if
/// the angle of a's axis to that line plus a's half-angle plus β is below π/2, and all face away
/// if that angle minus both is above π/2 (the same for b). Samples alone cannot show this: a
/// patch that sees the other only in a sliver near the cut has every sample pair on one side at
/// low orders. `false` where it cannot be proven (overlapping balls, normals not within a cone):
/// the pair then takes the boundary path, which places the cut wherever it lies.
pub(crate) fn facing_settled<T, SA, SB>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    ball_a: &crate::samples::Ball<T>,
    ball_b: &crate::samples::Ball<T>,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let d = ball_b.center - ball_a.center;
    let distance = d.norm();
    let reach = ball_a.radius + ball_b.radius;
    if !(distance > reach) || !distance.is_finite() {
        return false;
    }
    let (Some((axis_a, half_a)), Some((axis_b, half_b))) = (a.normal_cone(), b.normal_cone()) else {
        return false;
    };
    let beta = reach.atan2(((distance - reach) * (distance + reach)).sqrt());
    let right = T::PI * T::HALF;
    let angle = |u: Vec3<T>, v: Vec3<T>| u.cross(v).norm().atan2(u.dot(v));
    let (gamma_a, gamma_b) = (angle(axis_a, d), angle(axis_b, -d));
    let all_front = |gamma: T, half: T| gamma + half + beta < right;
    let all_back = |gamma: T, half: T| gamma - half - beta > right;
    (all_front(gamma_a, half_a) && all_front(gamma_b, half_b)) || all_back(gamma_a, half_a) || all_back(gamma_b, half_b)
}

/// Whether the Gauss rules of order `order` resolve the pair
/// ([`crate::sum::samples_resolved`]), for a caller without a pair context (the
/// tolerance mode's recursion, which keeps no sample buffer in its own frames).
#[cfg(feature = "closed-form")]
#[inline(never)]
pub(crate) fn resolved<T, SA, SB, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    PairContext::<T, SA, SB, (), CAP>::new(a, b, &()).resolved(order)
}

/// Which patch of a pair an occluder may cut the boundary path should integrate outside
/// (`true`: b). The inner rule is in closed form only on a flat (affine) inner patch: when only
/// one of the two is flat, it goes inside. Otherwise the smaller one (enclosing ball) goes
/// outside: the outer integrand kinks where a shadow boundary on the inner patch meets that
/// patch's corners and edges, and jumps where an occluder cuts the outer patch itself; on the
/// larger inner patch a shadow more often lies wholly inside, and the smaller outer patch is
/// less often cut. It also makes the choice independent of the argument order.
/// `ball_a`, `ball_b`: the patches' enclosing balls.
pub(crate) fn occluded_outer_is_b<T, SA, SB>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    ball_a: &crate::samples::Ball<T>,
    ball_b: &crate::samples::Ball<T>,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (flat_a, flat_b) = (has_affine_map(a), has_affine_map(b));
    if flat_a != flat_b {
        return flat_a;
    }
    ball_b.radius < ball_a.radius
}

/// Which patch of a separate, unoccluded pair the boundary path should integrate outside
/// (`true`: b). The outer integrand is smooth where every outer point sees part of the inner
/// patch; where some see none of it, the support's edge is a kink curve across the outer
/// patch: the patch with fewer blind sample points goes outside. On a tie, where an outer
/// point comes closer to the inner patch's edges than the outer rule's node spacing, the
/// inner integral changes on that distance's scale there (a disk 0.05 below a larger one:
/// across the small disk's rim), which the outer rule cannot resolve: the patch whose points
/// stay farther from the other's edges, in its own node spacings, goes outside (the small
/// disk over the large one). Otherwise the flat one (a curved outer patch sweeps its tangent
/// plane across the inner one, which adds kinks; a flat one does not). Before both, a very
/// near pair puts its flat patch inside; then a curved patch that gives its own outer events
/// against a parallelogram goes outside (a sphere's cell: J(p) is the exact point-to-polygon
/// form, cheap per outer point, and the circles where it kinks are in the outer rule), and
/// otherwise a flat patch against a curved one that gives its outer events goes outside (their
/// kinks are then in the outer rule, but each outer point integrates the curved patch by lines).
pub(crate) fn outer_is_b<T, SA, SB, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    sa: &PatchSamples<T, CAP>,
    sb: &PatchSamples<T, CAP>,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    // Very near (`boundary::very_near`) with exactly one patch flat: the flat one goes inside.
    // A point of the curved patch sees the flat one cut by one plane (its tangent plane), which
    // the inner rule places in closed form or brackets as a line; a point of the flat patch may
    // see only a small cap of the curved one (a sphere cell 1e-3 above a plate: a cap of radius
    // √(2·R·gap)), which a probe grid misses. The blind-point count below is a sample count
    // that changes with the order on such a pair.
    if is_flat(a) != is_flat(b) && crate::boundary::very_near(a, b).unwrap_or(false) {
        return is_flat(a);
    }
    // A curved patch that gives its outer events against a parallelogram (a sphere's cell,
    // `TrigonometricEvents`): the curved one outside, each outer point by the exact
    // point-to-polygon form. Else a flat patch against a curved one that gives its event
    // quadrics only: the flat one outside, where those events — the curved patch's outline
    // passing its corners and touching its edges, which also bound the blind points — are
    // placed into the outer rule.
    #[cfg(feature = "closed-form")]
    if has_affine_map(a) != has_affine_map(b) {
        let curved_outside = if has_affine_map(a) {
            crate::boundary::outer_events_apply(b, a, &())
        } else {
            crate::boundary::outer_events_apply(a, b, &())
        };
        if curved_outside {
            return has_affine_map(a);
        }
        let flat_outside = if has_affine_map(a) {
            crate::boundary::outer_events_apply(a, b, &())
        } else {
            crate::boundary::outer_events_apply(b, a, &())
        };
        if flat_outside {
            return has_affine_map(b);
        }
    }
    let (blind_a, blind_b) = (blind_points(sa, sb), blind_points(sb, sa));
    if blind_a != blind_b {
        return blind_b < blind_a;
    }
    let (clear_a, clear_b) = (edge_clearance(sa, b), edge_clearance(sb, a));
    if clear_a.min(clear_b) < T::ONE && clear_a != clear_b {
        return clear_b > clear_a;
    }
    is_flat(b) && !is_flat(a)
}

/// Segments per edge of the polylines that stand for a patch's edges in [`edge_clearance`].
pub(super) const EDGE_SEGMENTS: usize = 16;

/// The smallest distance from a sample of `outer` to the edges of `inner` (16-segment
/// polylines), in node spacings of the outer rule (its sample ball's diameter / order).
pub(super) fn edge_clearance<T, S, const CAP: usize>(outer: &PatchSamples<T, CAP>, inner: &Patch<'_, T, S>) -> T
where
    T: Real,
    S: Surface<T> + ?Sized,
{
    let r = inner.rect();
    let g = inner.surface();
    let n = T::from_usize(EDGE_SEGMENTS);
    let edge_point = |edge: usize, k: usize| {
        let x = T::from_usize(k) / n;
        let (t, s) = match edge {
            0 => (r.t0 + (r.t1 - r.t0) * x, r.s0),
            1 => (r.t1, r.s0 + (r.s1 - r.s0) * x),
            2 => (r.t0 + (r.t1 - r.t0) * x, r.s1),
            _ => (r.t0, r.s0 + (r.s1 - r.s0) * x),
        };
        g.point(t, s)
    };
    // Squared distances (a square that overflows only loses a comparison among far points).
    let mut nearest = T::MAX;
    for edge in 0..4 {
        let mut prev = edge_point(edge, 0);
        for k in 1..=EDGE_SEGMENTS {
            let next = edge_point(edge, k);
            let d = next - prev;
            let d2 = d.dot(d);
            for p in outer.iter() {
                let w = p.point - prev;
                let along = if d2 > T::ZERO { (w.dot(d) / d2).max(T::ZERO).min(T::ONE) } else { T::ZERO };
                nearest = nearest.min((w - d.scale(along)).norm2());
            }
            prev = next;
        }
    }
    let nearest = nearest.sqrt();
    let order = T::from_usize(outer.len()).sqrt().max(T::ONE);
    let spacing = outer.bounds().radius * T::TWO / order;
    if spacing > T::ZERO {
        nearest / spacing
    } else {
        T::MAX
    }
}

/// How many samples of `outer` see no sample of `inner` through the two-sided facing test
/// (section 3.2): points where the inner integral of the boundary path would vanish.
pub(super) fn blind_points<T: Real, const CAP: usize>(
    outer: &PatchSamples<T, CAP>,
    inner: &PatchSamples<T, CAP>,
) -> usize {
    outer
        .iter()
        .filter(|p| !inner.iter().any(|q| mutually_facing(p.point, p.unit_normal, q.point, q.unit_normal)))
        .count()
}

/// Whether the patch's surface is a parallelogram (an affine map), which the boundary path
/// integrates in closed form as the inner patch.
pub(super) fn has_affine_map<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> bool {
    #[cfg(feature = "closed-form")]
    return p.surface().affine_map().is_some();
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = p;
        false
    }
}

/// Whether the patch is flat: its unit normals at the centre and near the four corners agree to
/// rounding (a parallelogram, a disk or annulus sector, a planar Bézier patch).
pub(super) fn is_flat<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> bool {
    let r = p.rect();
    let g = p.surface();
    let at = |x: T, y: T| {
        let n = g.normal(r.t0 + (r.t1 - r.t0) * x, r.s0 + (r.s1 - r.s0) * y);
        let length = n.norm();
        if length > T::ZERO && length.is_finite() {
            Some(n.scale(T::ONE / length))
        } else {
            None
        }
    };
    let (lo, hi) = (T::from_f64(0.125), T::from_f64(0.875));
    let Some(centre) = at(T::HALF, T::HALF) else { return false };
    let limit = T::ONE - T::from_f64(64.0) * T::EPSILON;
    [(lo, lo), (hi, lo), (lo, hi), (hi, hi)].iter().all(|&(x, y)| at(x, y).is_some_and(|n| n.dot(centre) >= limit))
}

/// `true` if some sample pairs pass the two-sided curvature test and others do not.
pub(crate) fn straddles_curvature_cut<T: Real, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
) -> bool {
    let mut seen_visible = false;
    let mut seen_hidden = false;
    for sa in a.iter() {
        for sb in b.iter() {
            let visible = mutually_facing(sa.point, sa.unit_normal, sb.point, sb.unit_normal);
            seen_visible |= visible;
            seen_hidden |= !visible;
            if seen_visible && seen_hidden {
                return true;
            }
        }
    }
    false
}

/// The outer patch of an occluded pair (`true`: b) and whether its outer events are placed:
/// [`events_outer`]'s choice where they are; otherwise `preferred`, except between patches of
/// the same size (enclosing balls of equal radius, where [`occluded_outer_is_b`] keeps the
/// first argument outside): there, if an occluder touches the preferred patch and none
/// touches the other, the other goes outside ([`crate::boundary::occluders_touch`]: J is
/// singular along a contact, and the outer rule converges slowly across it; a box standing on
/// a floor, the ceiling of the same size above it: the ceiling outside, whichever argument
/// comes first). Between patches of different sizes the smaller stays outside: the larger one
/// outside is no better in general (a floor strip touched by a cabinet's foot against the
/// wall 0.1 behind the cabinet: 5e-8 with the strip outside, 2e-3 with the wall).
#[cfg(feature = "closed-form")]
pub(crate) fn occluded_outer<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    occluders: &O,
    preferred: bool,
) -> (bool, bool)
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    if let Some(outer_b) = events_outer(a, b, occluders, preferred) {
        return (true, outer_b);
    }
    let (ra, rb) = (a.enclosing_ball().radius, b.enclosing_ball().radius);
    if !((ra - rb).abs() <= T::GEOMETRY_TOLERANCE * ra.max(rb)) {
        return (false, preferred);
    }
    let touches = |outer_b: bool| {
        if outer_b {
            crate::boundary::occluders_touch(b, a, occluders)
        } else {
            crate::boundary::occluders_touch(a, b, occluders)
        }
    };
    let swap = touches(preferred) == Some(true) && touches(!preferred) == Some(false);
    (false, preferred != swap)
}

/// Which patch of an occluded pair goes outside with its outer events placed into the rule
/// ([`crate::boundary::outer_events_apply`]): `preferred` (`true`: b) where its events are
/// placed; the other where `preferred`'s are placed but an occluder touches it (a cabinet's
/// foot on a floor facet's edge makes J singular there, and the floor facet outside converges
/// only algebraically; the wall it faces, outside, is not touched) and the other's are placed;
/// else `None`.
#[cfg(feature = "closed-form")]
pub(crate) fn events_outer<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    occluders: &O,
    preferred: bool,
) -> Option<bool>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let state = |outer_b: bool| {
        if outer_b {
            crate::boundary::outer_events_state(b, a, occluders)
        } else {
            crate::boundary::outer_events_state(a, b, occluders)
        }
    };
    match state(preferred) {
        Some(true) => Some(preferred),
        Some(false) => (state(!preferred) == Some(true)).then_some(!preferred),
        None => None,
    }
}
