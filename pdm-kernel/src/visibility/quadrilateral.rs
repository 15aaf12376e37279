//! The quadrilateral or triangle as an occluder: segment–plane intersection inside the convex
//! outline.

use super::*;
use crate::surface::Quadrilateral;

impl<T: Real> Quadrilateral<T> {
    /// The sides P_i → P_{i+1} of non-zero length (a triangle has three), as (start, direction).
    fn sides(&self) -> impl Iterator<Item = (Vec3<T>, Vec3<T>)> + '_ {
        let c = &self.corners;
        c.iter().zip(c.iter().cycle().skip(1)).map(|(&p, &q)| (p, q - p)).filter(|(_, d)| d.norm2() > T::ZERO)
    }
}

impl<T: Real> Occluder<T> for Quadrilateral<T> {
    /// Segment–plane intersection, then the hit point on the inner side of every side (the
    /// outline is convex and counter-clockwise about the normal).
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let n = self.normal;
        let [origin, ..] = self.corners;
        let d = q - p;
        let denom = n.dot(d);
        if denom == T::ZERO {
            return false;
        }
        let offset = n.dot(origin - p);
        let far_end = n.dot(origin - q);
        if on_plane(offset, n, p, origin) || on_plane(far_end, n, q, origin) {
            return false; // a segment from a point of the plane meets it only there
        }
        let tau = offset / denom;
        if !interior(tau) {
            return false;
        }
        let hit = p + d.scale(tau);
        self.sides().all(|(start, side)| side.cross(hit - start).dot(n) >= T::ZERO)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let [p0, p1, p2, p3] = self.corners;
        let center = (p0 + p1 + p2 + p3).scale(T::from_f64(0.25));
        let radius = self.corners.iter().fold(T::ZERO, |r, &p| r.max((p - center).norm()));
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
            out(Caster::Polygon(&self.corners));
        }
        true
    }
    /// The crossing τ = offset / (n·w) and the side functions at the hit point are ratios of
    /// polynomials linear in τ: the switches are n·w = 0, q on the plane, and each side
    /// function zero (numerators multiplied by n·w).
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let n = self.normal;
        let (w0, d) = (origin - p, direction);
        let [o, ..] = self.corners;
        let offset = n.dot(o - p);
        let (nw0, nd) = (n.dot(w0), n.dot(d));
        out([T::ZERO, nd, nw0]);
        out([T::ZERO, nd, nw0 - offset]);
        for (start, side) in self.sides() {
            // (n·w)·(hit − start) = (p − start)(n·w) + offset·w, linear in τ.
            let ps = p - start;
            let r0 = ps.scale(nw0) + w0.scale(offset);
            let r1 = ps.scale(nd) + d.scale(offset);
            let f = |r: Vec3<T>| side.cross(r).dot(n);
            out([T::ZERO, f(r1), f(r0)]);
        }
        true
    }
}
