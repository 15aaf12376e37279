//! The sphere as an occluder: a segment crosses its surface where it enters or leaves.

use super::*;

impl<T: Real> Occluder<T> for Sphere<T> {
    /// Segment–sphere: roots of |p + τ(q − p) − c|² = R², i.e. τ² a + 2τ b + c₀ = 0.
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let d = q - p;
        let f = p - self.center;
        let r2 = self.radius * self.radius;
        crossing_of_quadric(d.norm2(), f.dot(d), f.norm2() - r2, (q - self.center).norm2() - r2, r2, |_| true)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        ball_may_cut_pair(self.center, self.radius, a, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        let cuts = self.may_block_between(a, b);
        Some(cuts.then_some(Ball { center: self.center, radius: self.radius }))
    }
    /// The sphere itself where it may cut a segment from a point of `from` to the convex
    /// polygon b: nothing where it lies outside the hull of `from` and b's ball, or, from a
    /// point p (`from` of radius zero), beyond one face plane of the pyramid with apex p over b
    /// (b's plane and the planes through p and each side of b) by its radius. A room's lamp,
    /// which the ball of a whole wall takes in, passes the second test from most points of the
    /// room.
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        let ball = Ball { center: self.center, radius: self.radius };
        if !self.may_block_between(from, bounds) {
            return true;
        }
        let (p, n) = (from.center, b.len());
        if n < 3 || from.radius != T::ZERO {
            out(Caster::Sphere(ball));
            return true;
        }
        let centroid = b.iter().fold(Vec3::ZERO, |c, &v| c + v).scale(T::ONE / T::from_usize(n));
        // Beyond the plane through x with normal m (either way round: the side away from
        // `inside`) by more than the radius.
        let beyond = |x: Vec3<T>, m: Vec3<T>, inside: Vec3<T>| {
            let length = m.norm();
            if !(length > T::ZERO) {
                return false;
            }
            let m = if m.dot(inside - x) > T::ZERO { -m } else { m };
            m.dot(self.center - x) > self.radius * length * (T::ONE + T::GEOMETRY_TOLERANCE.sqrt())
        };
        let (Some(&b0), Some(&b1), Some(&b2)) = (b.first(), b.get(1), b.get(2)) else { return true };
        let apart = beyond(b0, (b1 - b0).cross(b2 - b0), p)
            || (0..n).any(|k| {
                let (v, w) = (b.get(k).copied().unwrap_or(b0), b.get((k + 1) % n).copied().unwrap_or(b0));
                beyond(p, (v - p).cross(w - p), centroid)
            });
        if !apart {
            out(Caster::Sphere(ball));
        }
        true
    }
    /// Every segment from p into ball b crosses the sphere when b's cone from p (half-angle β,
    /// sin β = r_b/|c_b − p|) lies inside the sphere's tangent cone (half-angle α,
    /// sin α = R/|c − p|) with margin, θ + β < α for the angle θ between the axes (compared
    /// through cosines, no trigonometry), and b's nearest point lies beyond the tangent length
    /// √(|c − p|² − R²), past which every ray inside the tangent cone has entered the sphere.
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        let m = self.center - p;
        let d = b.center - p;
        let (m2, d2) = (m.norm2(), d.norm2());
        let (r2, rb2) = (self.radius * self.radius, b.radius * b.radius);
        if !(m2 > r2 && d2 > rb2) {
            return false;
        }
        let (dm, dd) = (m2.sqrt(), d2.sqrt());
        let tangent = (m2 - r2).sqrt();
        // A relative margin far above rounding: a point this close to the boundary is left to
        // the exact computation.
        let margin = T::GEOMETRY_TOLERANCE.sqrt();
        if !(dd - b.radius > tangent * (T::ONE + margin)) {
            return false;
        }
        let cos_theta = m.dot(d) / (dm * dd);
        let sin_theta = (T::ONE - cos_theta * cos_theta).max(T::ZERO).sqrt();
        let (sin_beta, cos_beta) = (b.radius / dd, (T::ONE - rb2 / d2).max(T::ZERO).sqrt());
        let cos_alpha = tangent / dm;
        // θ + β < α ⇔ cos(θ + β) > cos α, with θ + β < π (θ > π/2 fails anyway).
        cos_theta > T::ZERO && cos_theta * cos_beta - sin_theta * sin_beta > cos_alpha * (T::ONE + margin) + margin
    }
    /// The segment from p to the corner c touches the sphere where the line through them is
    /// tangent to it: |w × v|² = R²|v|² with w = centre − c, v = p − c, i.e.
    /// vᵀ((|w|² − R²) I − w wᵀ) v = 0 (the double cone of tangents from c). The shadow becomes
    /// tangent to the edge line (c, d) where the plane through it and p is tangent to the
    /// sphere: (v·(w × d))² = R²|d × v|², i.e. vᵀ(g gᵀ − R²(|d|² I − d dᵀ)) v = 0 with
    /// g = w × d (the two tangent planes through the line).
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        _pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        let w = self.center - corner;
        let r2 = self.radius * self.radius;
        let k = w.norm2() - r2;
        out(Quadric::cone(corner, [k - w.x * w.x, k - w.y * w.y, k - w.z * w.z, -w.x * w.y, -w.x * w.z, -w.y * w.z]));
        let (g, d) = (w.cross(edge), edge);
        let dd = d.norm2();
        out(Quadric::cone(
            corner,
            [
                g.x * g.x - r2 * (dd - d.x * d.x),
                g.y * g.y - r2 * (dd - d.y * d.y),
                g.z * g.z - r2 * (dd - d.z * d.z),
                g.x * g.y + r2 * d.x * d.y,
                g.x * g.z + r2 * d.x * d.z,
                g.y * g.z + r2 * d.y * d.z,
            ],
        ));
        true
    }
    /// With w = q − p and m = c − p the segment meets the sphere iff its direction lies in the
    /// tangent cone ((m·w)² ≥ (|m|² − R²)|w|²), in front of p (m·w > 0), and it reaches the
    /// sphere (q inside, or the closest approach m·w/|w|² < 1, i.e. w·(q − c) > 0); p on the
    /// sphere switches at m·w = 0. All are polynomials of degree ≤ 2 in τ.
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let m = self.center - p;
        let w0 = origin - p;
        let d = direction;
        let r2 = self.radius * self.radius;
        let k = m.norm2() - r2;
        if on_surface(k, r2) {
            // p on the sphere (a patch of the occluder itself): the tangent cone degenerates
            // to p's tangent plane, and its polynomial to rounding noise with a double root.
            // A segment into the sphere (m·w > 0) meets it again at τ = 2 m·w/|w|², i.e. is
            // blocked iff q lies outside: |w|² − 2 m·w > 0.
            let (e0, e1) = (w0 - m.scale(T::TWO), d);
            out([d.dot(e1), w0.dot(e1) + d.dot(e0), w0.dot(e0)]);
        } else {
            let (a, b, c) = cone_polynomial(m, k, w0, d);
            out([a, b, c]);
        }
        out([T::ZERO, m.dot(d), m.dot(w0)]);
        let (a, b, c) = sphere_polynomial(origin, d, self.center, self.radius);
        out([a, b, c]);
        // w·(q − c) with q − c = w − m.
        let (e0, e1) = (w0 - m, d);
        out([d.dot(e1), w0.dot(e1) + d.dot(e0), w0.dot(e0)]);
        true
    }
}
