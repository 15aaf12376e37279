//! The parallelogram as an occluder: segment–plane intersection inside the parallelogram.

use super::*;

impl<T: Real> Occluder<T> for Parallelogram<T> {
    /// Segment–plane intersection, then the parallelogram coordinates of the hit point in [0, 1]².
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let n = self.normal;
        let d = q - p;
        let denom = n.dot(d);
        if denom == T::ZERO {
            return false;
        }
        let offset = n.dot(self.origin - p);
        let far_end = n.dot(self.origin - q);
        if on_plane(offset, n, p, self.origin) || on_plane(far_end, n, q, self.origin) {
            return false; // a segment from a point of the plane meets it only there
        }
        let tau = offset / denom;
        if !interior(tau) {
            return false;
        }
        let r = p + d.scale(tau) - self.origin;
        let nn = n.norm2();
        let u = r.cross(self.edge_s).dot(n) / nn;
        let v = self.edge_t.cross(r).dot(n) / nn;
        u >= T::ZERO && u <= T::ONE && v >= T::ZERO && v <= T::ONE
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let center = self.origin + (self.edge_t + self.edge_s).scale(T::HALF);
        let radius = (self.edge_t + self.edge_s).norm().max((self.edge_t - self.edge_s).norm()) * T::HALF;
        ball_may_cut_pair(center, radius, a, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        _b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        if self.may_block_between(from, bounds) {
            let (o, et, es) = (self.origin, self.edge_t, self.edge_s);
            out(Caster::Polygon(&[o, o + et, o + et + es, o + es]));
        }
        true
    }
    /// The crossing τ = offset / (n·w) and its coordinates (u, v) are ratios of polynomials
    /// linear in τ: the switches are n·w = 0, q on the plane, and u, v ∈ {0, 1} (numerators
    /// multiplied by n·w).
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let n = self.normal;
        let nn = n.norm2();
        let (w0, d) = (origin - p, direction);
        let offset = n.dot(self.origin - p);
        let (nw0, nd) = (n.dot(w0), n.dot(d));
        out([T::ZERO, nd, nw0]);
        out([T::ZERO, nd, nw0 - offset]);
        // (n·w)·(hit − o) = (p − o)(n·w) + offset·w, linear in τ: value at 0 and slope.
        let po = p - self.origin;
        let r0 = po.scale(nw0) + w0.scale(offset);
        let r1 = po.scale(nd) + d.scale(offset);
        let u = |r: Vec3<T>| r.cross(self.edge_s).dot(n);
        let v = |r: Vec3<T>| self.edge_t.cross(r).dot(n);
        out([T::ZERO, u(r1), u(r0)]);
        out([T::ZERO, u(r1) - nn * nd, u(r0) - nn * nw0]);
        out([T::ZERO, v(r1), v(r0)]);
        out([T::ZERO, v(r1) - nn * nd, v(r0) - nn * nw0]);
        true
    }
}
