//! Two flat patches that see each other wholly: the contour form (parallelograms in closed form,
//! curved outlines by graded rules).

use super::*;

/// Whether a pair of the given contact may take the contour form (if both patches are flat
/// and see each other wholly, [`flat_pair`]): separate, nearly touching and touching pairs —
/// along a shared edge the collinear edge pair and at a shared corner the edges leaving it
/// are in closed form (C-14 exact with 16 terms, where the edge transform needs 6·p⁴
/// evaluations), and a partial shared edge (a short edge lying along a longer one from a
/// common corner, a non-conforming grid) is a collinear pair too. The same patch twice takes the identical-panel transform.
#[cfg(feature = "closed-form")]
pub(crate) fn contour_applies(adjacency: Adjacency) -> bool {
    adjacency != Adjacency::Identical
}

/// Two flat patches that see each other wholly — each in the closed half-space in front of the
/// other, not coplanar, no occluder able to cut a segment between them — by the contour form
/// ([`crate::contour`]: parallelograms in closed form along the inner edge, curved edges by
/// graded rules), exponential at any gap and aspect ratio; `None` if the pair is not such a
/// pair. Gives the value, the evaluations, a bound on the value's rounding error (the
/// caller refuses values that lost half their digits, [`crate::bounds::lost_digits`]) and
/// whether every edge pair was in closed form (the value is then the same at every order).
#[cfg(feature = "closed-form")]
pub(crate) fn flat_pair<'p, 'r, T, SA, SB, O>(
    a: &Patch<'p, T, SA>,
    b: &Patch<'r, T, SB>,
    order: usize,
    occluders: &O,
) -> Option<Result<(T, u64, T, bool), PdmError>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Parallelograms by their corners, other flat patches by their outlines; each wholly in
    // front of (or on) the other's plane, and not both in one plane.
    let (shape, b_ahead, a_ahead, cos) = if let (Some((ca, na)), Some((cb, nb))) = (flat_corners(a), flat_corners(b)) {
        let size = ca.iter().chain(cb.iter()).fold(T::ZERO, |m, &p| m.max((p - ca[0]).norm()));
        let band = size * T::GEOMETRY_TOLERANCE;
        // Where each one's corners lie against the other's plane: (some ahead, some behind),
        // beyond the band.
        let sides = |corners: &[Vec3<T>; 4], origin: Vec3<T>, n: Vec3<T>| {
            corners.iter().fold((false, false), |(ahead, behind), &q| {
                let h = n.dot(q - origin);
                (ahead || h > band, behind || h < -band)
            })
        };
        let (b_side, a_side) = (sides(&cb, ca[0], na), sides(&ca, cb[0], nb));
        // One parallelogram wholly behind the other's plane (none of its corners ahead, one
        // beyond the band): no sample pair passes the facing test, the exchange is exactly 0
        // (back-to-back facets of a mesh, touching or not), whatever occludes.
        if b_side == (false, true) || a_side == (false, true) {
            return Some(Ok((T::ZERO, 0, T::ZERO, true)));
        }
        // Each wholly in front of (or on) the other's plane, or not a flat pair.
        let side = |(ahead, behind): (bool, bool)| (!behind).then_some(ahead);
        (FlatShape::Corners(ca, cb), side(b_side)?, side(a_side)?, na.dot(nb))
    } else {
        let oa = crate::contour::Outline::new(a)?;
        let ob = crate::contour::Outline::new(b)?;
        let band = oa.size().max(ob.size()) * T::GEOMETRY_TOLERANCE;
        let (b_ahead, a_ahead) = (ob.ahead_of(oa.origin, oa.normal, band)?, oa.ahead_of(ob.origin, ob.normal, band)?);
        let cos = oa.normal.dot(ob.normal);
        (FlatShape::Outlines(oa, ob), b_ahead, a_ahead, cos)
    };
    if b_ahead && a_ahead {
        let balls = match &shape {
            FlatShape::Corners(ca, cb) => (corner_ball(ca), corner_ball(cb)),
            FlatShape::Outlines(..) => (a.enclosing_ball(), b.enclosing_ball()),
        };
        if occluders.may_block_between(&balls.0, &balls.1) {
            return None;
        }
        let order = order.max(2);
        return Some(match shape {
            FlatShape::Corners(ca, cb) => crate::contour::quad_exchange(&ca, &cb, order),
            FlatShape::Outlines(oa, ob) => {
                crate::contour::curve_exchange(&oa, &ob, order).map(|(v, n, r)| (v, n, r, false))
            }
        });
    }
    // Each within the other's plane to the working precision while facing each other: a gap
    // below the geometry's resolution (f32 plates 1e-6 apart), which no path can integrate
    // (the 4-D rules would return a value off by percents).
    (!b_ahead && !a_ahead && cos < T::ZERO).then_some(Err(PdmError::Unresolvable))
}

/// The ball about a convex polygon's corners that holds it: centred at their mean, through the
/// farthest, widened by 1/8 as [`Patch::enclosing_ball`] is (the culling tests treat it as a
/// bound, and the corners' rounding must stay inside).
#[cfg(feature = "closed-form")]
pub(crate) fn corner_ball<T: Real>(corners: &[Vec3<T>; 4]) -> crate::vec3::Ball<T> {
    let [c0, c1, c2, c3] = *corners;
    let center = (c0 + c1 + c2 + c3).scale(T::HALF * T::HALF);
    let radius = corners.iter().fold(T::ZERO, |r, &c| r.max((c - center).norm()));
    crate::vec3::Ball { center, radius: radius * (T::ONE + T::from_f64(0.125)) }
}

/// The two flat patches of [`flat_pair`]: parallelograms by their corners (inner line
/// integrals in closed form), any other flat patches by their outlines.
#[cfg(feature = "closed-form")]
pub(super) enum FlatShape<'p, 'r, T: Real, SA: Surface<T> + ?Sized, SB: Surface<T> + ?Sized> {
    Corners([Vec3<T>; 4], [Vec3<T>; 4]),
    Outlines(crate::contour::Outline<'p, T, SA>, crate::contour::Outline<'r, T, SB>),
}

/// A flat patch's corners counter-clockwise about its radiating normal, and its unit normal:
/// patches with straight edges ([`Surface::straight_corners`]: parallelograms, quadrilaterals,
/// triangles, whose repeated corner is an edge of length zero that contributes nothing).
#[cfg(feature = "closed-form")]
pub(crate) fn flat_corners<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> Option<([Vec3<T>; 4], Vec3<T>)> {
    let r = p.rect();
    let corners = p.surface().straight_corners(r)?;
    let normal = p.surface().normal((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    let length = normal.norm();
    if !(length > T::ZERO) || !length.is_finite() {
        return None;
    }
    let n = normal.scale(T::ONE / length);
    let [c0, c1, c2, c3] = corners;
    // The diagonals' cross product is twice the area vector of any planar quadrilateral.
    Some(if n.dot((c2 - c0).cross(c3 - c1)) >= T::ZERO { (corners, n) } else { ([c0, c3, c2, c1], n) })
}
