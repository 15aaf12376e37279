//! The disk (or annulus, or sector) as an occluder.

use super::*;

impl<T: Real> Occluder<T> for Disk<T> {
    /// Segment–plane intersection, then r_in ≤ |h − c| ≤ r_out.
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let n = self.frame.axis;
        let d = q - p;
        let denom = n.dot(d);
        if denom == T::ZERO {
            return false;
        }
        let offset = n.dot(self.center - p);
        if on_plane(offset, n, p, self.center) || on_plane(n.dot(self.center - q), n, q, self.center) {
            return false; // a segment from a point of the plane meets it only there
        }
        let tau = offset / denom;
        if !interior(tau) {
            return false;
        }
        let r2 = (p + d.scale(tau) - self.center).norm2();
        r2 >= self.inner_radius * self.inner_radius && r2 <= self.outer_radius * self.outer_radius
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        ball_may_cut_pair(self.center, self.outer_radius, a, b)
    }
    /// As for the parallelogram, with the radius conditions |(n·w)(hit − c)|² = r²(n·w)²
    /// quadratic in τ.
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let n = self.frame.axis;
        let (w0, d) = (origin - p, direction);
        let offset = n.dot(self.center - p);
        let (nw0, nd) = (n.dot(w0), n.dot(d));
        out([T::ZERO, nd, nw0]);
        out([T::ZERO, nd, nw0 - offset]);
        for radius in [self.inner_radius, self.outer_radius] {
            out(circle_crossing_polynomial(p - self.center, offset, (nw0, nd), (w0, d), radius));
        }
        true
    }
}
