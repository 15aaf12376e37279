//! The open cylinder (tube) as an occluder: crossings of its quadric between its end planes.

use super::*;

impl<T: Real> Occluder<T> for Cylinder<T> {
    /// Segment–tube: roots of |(p + τd − base)⊥|² = R² (⊥: component normal to the axis) whose
    /// height along the axis lies in [0, h].
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let axis = self.frame.axis;
        let d = q - p;
        let f = p - self.base;
        let f_ax = f.dot(axis);
        let d_ax = d.dot(axis);
        let f_perp = f - axis.scale(f_ax);
        let d_perp = d - axis.scale(d_ax);
        let r2 = self.radius * self.radius;
        let g = q - self.base;
        let g_perp = g - axis.scale(g.dot(axis));
        let in_height = |tau: T| {
            let z = f_ax + tau * d_ax;
            z >= T::ZERO && z <= self.height
        };
        crossing_of_quadric(d_perp.norm2(), f_perp.dot(d_perp), f_perp.norm2() - r2, g_perp.norm2() - r2, r2, in_height)
    }
    /// Whether the segment from p to x(τ) crosses the tube changes only where it becomes
    /// tangent to the infinite cylinder, x (or, for p on it, the second crossing) passes through
    /// it, or the crossing passes a rim circle: five polynomials of degree ≤ 2 in τ.
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let (base, axis) = (self.base, self.frame.axis);
        revolution_polynomials(base, axis, self.radius, T::ZERO, self.height, p, origin, direction, out);
        true
    }
    /// Where the pair keeps clear of the tube's rims (both polygons on one side of a rim's plane,
    /// or no segment between their balls within R of its centre) and both polygons lie outside
    /// the infinite cylinder,
    /// a segment of the pair is blocked exactly when its projection across the axis crosses
    /// the circle: the shadow on b is bounded by the traces of the two tangent planes from p
    /// parallel to the axis (their ends, the lines of tangency, lie on the tube, off b). Such a
    /// trace passes the corner where p lies on one of the two planes through the corner
    /// parallel to the axis and tangent to the tube; it cannot become tangent to an edge, only
    /// lie along it. Those two planes are the events. Nothing where the tube cannot cut the
    /// pair; `false` where a rim may, or a polygon reaches into the cylinder.
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        let _ = edge;
        let (axis, r) = (self.frame.axis, self.radius);
        let [a, b] = pair;
        let (Some(ball_a), Some(ball_b)) = (polygon_ball(a), polygon_ball(b)) else { return false };
        if !self.may_block_between(&ball_a, &ball_b) {
            return true;
        }
        // A rim no segment of the pair comes near: both polygons on one side of its plane, up
        // to rounding (a segment then meets the plane at most at its end points, or lies in it,
        // on polygons that keep clear of the cylinder, below), or the segments between the
        // balls pass it farther than R.
        let (mut low, mut high) = (T::MAX, -T::MAX);
        for &c in a.iter().chain(b.iter()) {
            let z = axis.dot(c - self.base);
            (low, high) = (low.min(z), high.max(z));
        }
        let slack = T::from_f64(64.0) * T::EPSILON * (self.height + r + low.abs().max(high.abs()));
        // Both beyond the same end: no segment between them meets the tube's side.
        if high <= slack || low >= self.height - slack {
            return true;
        }
        let clear = |z: T, centre: Vec3<T>| {
            high <= z + slack || low >= z - slack || !ball_may_cut_pair(centre, r, &ball_a, &ball_b)
        };
        if !clear(T::ZERO, self.base) || !clear(self.height, self.base + axis.scale(self.height)) {
            return false;
        }
        if !clear_of_axis(a, self.base, axis, r) || !clear_of_axis(b, self.base, axis, r) {
            return false;
        }
        let offset = corner - self.base;
        let across = offset - axis.scale(offset.dot(axis));
        let distance = across.norm();
        if !(distance > r) || !distance.is_finite() {
            return false;
        }
        let u = across.scale(T::ONE / distance);
        let w = axis.cross(u);
        let (cos, sin) = (r / distance, (T::ONE - (r / distance) * (r / distance)).max(T::ZERO).sqrt());
        out(Quadric::plane(corner, u.scale(cos) + w.scale(sin)));
        out(Quadric::plane(corner, u.scale(cos) - w.scale(sin)));
        true
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let center = self.base + self.frame.axis.scale(self.height * T::HALF);
        let radius = (self.radius * self.radius + self.height * self.height * T::HALF * T::HALF).sqrt();
        ball_may_cut_pair(center, radius, a, b)
    }
}

/// The ball around a polygon's corners (their centroid, the farthest corner); `None` for no
/// corners or a non-finite one.
#[cfg(feature = "closed-form")]
fn polygon_ball<T: Real>(corners: &[Vec3<T>]) -> Option<Ball<T>> {
    if corners.is_empty() {
        return None;
    }
    let sum = corners.iter().fold(Vec3::ZERO, |s, &c| s + c);
    let center = sum.scale(T::ONE / T::from_usize(corners.len()));
    let radius = corners.iter().fold(T::ZERO, |m, &c| m.max((c - center).norm()));
    (radius.is_finite() && center.x.is_finite() && center.y.is_finite() && center.z.is_finite())
        .then_some(Ball { center, radius })
}

/// Whether the convex polygon `corners` keeps farther than `r` (with a relative margin) from
/// the line through `base` along the unit `axis`. Across the axis each projected side must pass
/// the line's point farther than `r`, and the point must not lie inside the projection: that
/// needs every side to turn the same way about it, each by at least |side|·r (its distance
/// from the side's line; tested against half that), which a projection flattened to a segment
/// (a polygon parallel to the axis) never does.
#[cfg(feature = "closed-form")]
fn clear_of_axis<T: Real>(corners: &[Vec3<T>], base: Vec3<T>, axis: Vec3<T>, r: T) -> bool {
    let across = |x: Vec3<T>| {
        let v = x - base;
        v - axis.scale(v.dot(axis))
    };
    let n = corners.len();
    let reach = r * (T::ONE + T::GEOMETRY_TOLERANCE.sqrt());
    let (mut positive, mut negative, mut wide) = (false, false, true);
    for k in 0..n {
        let (Some(&c), Some(&d)) = (corners.get(k), corners.get((k + 1) % n)) else { return false };
        let (u, w) = (across(c), across(d));
        let side = w - u;
        let turn = u.cross(w).dot(axis);
        positive |= turn > T::ZERO;
        negative |= turn < T::ZERO;
        wide &= turn.abs() >= T::HALF * r * side.norm();
        let length2 = side.norm2();
        let tau = if length2 > T::ZERO { (-u.dot(side) / length2).max(T::ZERO).min(T::ONE) } else { T::ZERO };
        if !((u + side.scale(tau)).norm() > reach) {
            return false;
        }
    }
    let inside = !(positive && negative) && wide;
    !inside
}
