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
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let center = self.base + self.frame.axis.scale(self.height * T::HALF);
        let radius = (self.radius * self.radius + self.height * self.height * T::HALF * T::HALF).sqrt();
        ball_may_cut_pair(center, radius, a, b)
    }
}
