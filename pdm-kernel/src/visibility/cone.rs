//! The cone or frustum as an occluder: crossings of its quadric between its end planes.

use super::*;
use crate::surface::Cone;

impl<T: Real> Occluder<T> for Cone<T> {
    /// Segment–cone: roots of |(p + τd − base)⊥|² = r(z)², r(z) = r₀ + (r₁ − r₀) z / h, whose
    /// height z along the axis lies in [0, h] (where r(z) ≥ 0: the other nappe of the quadric
    /// lies beyond the apex, outside that range).
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let axis = self.frame.axis;
        let k = (self.top_radius - self.base_radius) / self.height;
        let d = q - p;
        let f = p - self.base;
        let (f_ax, d_ax) = (f.dot(axis), d.dot(axis));
        let f_perp = f - axis.scale(f_ax);
        let d_perp = d - axis.scale(d_ax);
        // r along the segment: ρ₀ + τ ρ₁.
        let (rho0, rho1) = (self.base_radius + k * f_ax, k * d_ax);
        let g = q - self.base;
        let g_ax = g.dot(axis);
        let g_perp = g - axis.scale(g_ax);
        let rho_q = self.base_radius + k * g_ax;
        let (a, b) = (d_perp.norm2() - rho1 * rho1, f_perp.dot(d_perp) - rho0 * rho1);
        let (c_p, c_q) = (f_perp.norm2() - rho0 * rho0, g_perp.norm2() - rho_q * rho_q);
        let big = self.base_radius.max(self.top_radius);
        let scale = big * big + self.height * self.height * T::EPSILON;
        let in_height = |tau: T| {
            let z = f_ax + tau * d_ax;
            z >= T::ZERO && z <= self.height
        };
        // The quadratic's leading coefficient has either sign (a segment steeper than the
        // cone's side); the crossing test wants it positive.
        if a < T::ZERO {
            crossing_of_quadric(-a, -b, -c_p, -c_q, scale, in_height)
        } else if a > T::ZERO {
            crossing_of_quadric(a, b, c_p, c_q, scale, in_height)
        } else {
            // Linear: 2 b τ + c_p = 0.
            if b == T::ZERO || on_surface(c_p, scale) || on_surface(c_q, scale) {
                return false;
            }
            let tau = -c_p / (T::TWO * b);
            interior(tau) && in_height(tau)
        }
    }
    /// As for the tube, with the radius r₀ + (r₁ − r₀) z / h along the axis; one polynomial
    /// more: where the segment's direction crosses the cone's asymptotic directions (a root of
    /// the quadric through infinity).
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let k = (self.top_radius - self.base_radius) / self.height;
        let (base, axis) = (self.base, self.frame.axis);
        revolution_polynomials(base, axis, self.base_radius, k, self.height, p, origin, direction, out);
        true
    }
    /// A frustum with equal radii is a tube: the tube's planes ([`Cylinder`]'s
    /// `event_quadrics`). Other cones give none (`false`).
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        if self.top_radius != self.base_radius {
            return false;
        }
        let (base, frame, radius, height, side) = (self.base, self.frame, self.base_radius, self.height, self.side);
        Cylinder { base, frame, radius, height, side }.event_quadrics(corner, edge, pair, out)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let center = self.base + self.frame.axis.scale(self.height * T::HALF);
        let big = self.base_radius.max(self.top_radius);
        let radius = (big * big + self.height * self.height * T::HALF * T::HALF).sqrt();
        ball_may_cut_pair(center, radius, a, b)
    }
}
