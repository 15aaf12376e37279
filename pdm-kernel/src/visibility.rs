//! Visibility: the curvature tests of sections 3.1–3.3 and exact occlusion tests (section 3).
//!
//! **Curvature test.** A pair of sample points (P_a, P_b) can exchange energy only if each lies in
//! front of the other's tangent plane: n_a·e_ab > 0 **and** n_b·e_ba > 0 (section 3.2: both dot
//! products, which is also correct for the plane–curved case of section 3.1 and for concave
//! surfaces, section 3.3). [`mutually_facing`] is that test; the PDM sum applies it to every pair.
//!
//! **Occlusion.** An [`Occluder`] answers whether the open segment P_a → P_b crosses it. The
//! built-in shapes are exact occluders (closed-form segment intersection): [`Sphere`],
//! [`Parallelogram`], [`Disk`] (annulus), [`Cylinder`] (open tube). Their *surface* is the
//! obstacle: a segment crosses it where it enters or leaves, so two points on the inside of a
//! sphere see each other, while the same sphere blocks segments passing through it. Crossings
//! within a relative distance [`Real::GEOMETRY_TOLERANCE`] of either end point are ignored, so
//! a patch's own surface never blocks its own sample points.
//!
//! **Self-occlusion of concave surfaces (section 3.3).** A concave surface may hide part of itself
//! (Fig. 5b). Pass the surface itself as an occluder: e.g. the inner side of a cylinder with the
//! same [`Cylinder`] as occluder. For a user surface, implement [`Occluder`].
//!
//! Several occluders combine without allocation: `&[O]`, `[O; N]`, `heapless::Vec<O, N>`, tuples
//! `(A, B)`, `(A, B, C)`, `Option<O>`, `()` (no occluder) and the enum [`AnyOccluder`] for mixed
//! built-in lists.

use crate::real::Real;
use crate::samples::Ball;
use crate::surface::{Cylinder, Disk, Parallelogram, Sphere};
use crate::vec3::Vec3;

/// The two-sided curvature test of sections 3.1–3.2: `true` iff n_a·(p_b − p_a) > 0 and
/// n_b·(p_a − p_b) > 0.
#[inline(always)]
#[must_use]
pub fn mutually_facing<T: Real>(p_a: Vec3<T>, n_a: Vec3<T>, p_b: Vec3<T>, n_b: Vec3<T>) -> bool {
    let d = p_b - p_a;
    n_a.dot(d) > T::ZERO && n_b.dot(d) < T::ZERO
}

/// Something that may block the line of sight between two points.
pub trait Occluder<T: Real> {
    /// `true` if the open segment from `p` to `q` crosses the occluder (crossings within a
    /// relative distance `GEOMETRY_TOLERANCE` of an end point do not count).
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool;

    /// Conservative culling: `false` only if no segment from a point in ball `a` to a point in
    /// ball `b` can be blocked. The default says "maybe" (`true`).
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let _ = (a, b);
        true
    }
}

/// `true` if the ball (c, r) can meet some segment between the balls `a` and `b`: every such
/// segment lies in the convex hull of the two balls, which lies within distance max(r_a, r_b) of
/// the segment between their centres.
#[inline]
pub(crate) fn ball_may_cut_pair<T: Real>(c: Vec3<T>, r: T, a: &Ball<T>, b: &Ball<T>) -> bool {
    let reach = r + a.radius.max(b.radius);
    distance_point_segment(c, a.center, b.center) <= reach * (T::ONE + T::GEOMETRY_TOLERANCE)
}

fn distance_point_segment<T: Real>(c: Vec3<T>, a: Vec3<T>, b: Vec3<T>) -> T {
    let d = b - a;
    let dd = d.norm2();
    let tau = if dd > T::ZERO { ((c - a).dot(d) / dd).max(T::ZERO).min(T::ONE) } else { T::ZERO };
    (c - (a + d.scale(tau))).norm()
}

/// `true` if the signed offset n·(o − x) of point x from the plane through o is zero up to rounding.
#[inline(always)]
fn on_plane<T: Real>(offset: T, n: Vec3<T>, x: Vec3<T>, o: Vec3<T>) -> bool {
    offset.abs() <= T::from_f64(64.0) * T::EPSILON * n.norm() * (x.max_abs() + o.max_abs() + (x - o).max_abs())
}

/// `true` if τ lies strictly inside (tol, 1 − tol).
#[inline(always)]
fn interior<T: Real>(tau: T) -> bool {
    tau > T::GEOMETRY_TOLERANCE && tau < T::ONE - T::GEOMETRY_TOLERANCE
}

/// Roots of a τ² + 2 b τ + c = 0 (a > 0), in a numerically stable form; `None` if none are real
/// or the segment only grazes (double root).
#[inline]
fn quadratic_roots<T: Real>(a: T, b: T, c: T) -> Option<(T, T)> {
    let disc = b * b - a * c;
    if !(disc > T::ZERO) || !(a > T::ZERO) {
        return None;
    }
    let sq = disc.sqrt();
    let q = if b >= T::ZERO { -(b + sq) } else { -b + sq };
    if q == T::ZERO {
        return Some((T::ZERO, T::ZERO));
    }
    Some((q / a, c / q))
}

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
}

/// Whether the segment crosses a quadric surface f(τ) = a τ² + 2 b τ + c_p with f(1) = c_q,
/// at an interior τ accepted by `accept`. An end point lying on the surface (|c| within
/// rounding, [`on_surface`]) is a root τ = 0 or 1 *exactly*: the other root then follows from
/// Vieta's formulas, so rounding in c never creates a spurious crossing next to an end point
/// (which for short chords in f32 would otherwise exceed any fixed τ tolerance).
#[inline]
fn crossing_of_quadric<T: Real>(a: T, b: T, c_p: T, c_q: T, scale: T, accept: impl Fn(T) -> bool) -> bool {
    if !(a > T::ZERO) {
        return false;
    }
    let p_on = on_surface(c_p, scale);
    let q_on = on_surface(c_q, scale);
    match (p_on, q_on) {
        // A chord between two points of the surface: it meets the surface only at its ends.
        (true, true) => false,
        // Roots 0 and −2b/a.
        (true, false) => {
            let t = -T::TWO * b / a;
            interior(t) && accept(t)
        }
        // Roots 1 and c_p/a (product of the roots).
        (false, true) => {
            let t = c_p / a;
            interior(t) && accept(t)
        }
        (false, false) => match quadratic_roots(a, b, c_p) {
            Some((t1, t2)) => (interior(t1) && accept(t1)) || (interior(t2) && accept(t2)),
            None => false,
        },
    }
}

/// `true` if a quadric's value `c` at a point is zero up to the rounding of evaluating it at
/// that scale (`scale` ≈ R²) — and up to the error of the elementary functions that placed the
/// point ([`Real::ELEMENTARY_ERROR`], large with micromath): the point lies on the surface.
#[inline(always)]
fn on_surface<T: Real>(c: T, scale: T) -> bool {
    c.abs() <= (T::from_f64(64.0) * T::EPSILON + T::from_f64(16.0) * T::ELEMENTARY_ERROR) * scale
}

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
}

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
}

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

/// Any built-in occluder, for mixed lists such as `[AnyOccluder<f32>; 3]` or
/// `heapless::Vec<AnyOccluder<f64>, 8>`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AnyOccluder<T> {
    /// A sphere.
    Sphere(Sphere<T>),
    /// A parallelogram.
    Parallelogram(Parallelogram<T>),
    /// A disk or annulus.
    Disk(Disk<T>),
    /// An open cylinder.
    Cylinder(Cylinder<T>),
}

impl<T: Real> Occluder<T> for AnyOccluder<T> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        match self {
            Self::Sphere(o) => o.blocks(p, q),
            Self::Parallelogram(o) => o.blocks(p, q),
            Self::Disk(o) => o.blocks(p, q),
            Self::Cylinder(o) => o.blocks(p, q),
        }
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Sphere(o) => o.may_block_between(a, b),
            Self::Parallelogram(o) => o.may_block_between(a, b),
            Self::Disk(o) => o.may_block_between(a, b),
            Self::Cylinder(o) => o.may_block_between(a, b),
        }
    }
}

/// No occluder.
impl<T: Real> Occluder<T> for () {
    fn blocks(&self, _p: Vec3<T>, _q: Vec3<T>) -> bool {
        false
    }
    fn may_block_between(&self, _a: &Ball<T>, _b: &Ball<T>) -> bool {
        false
    }
}

impl<T: Real, O: Occluder<T> + ?Sized> Occluder<T> for &O {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        (**self).blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        (**self).may_block_between(a, b)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for [O] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.iter().any(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.iter().any(|o| o.may_block_between(a, b))
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for [O; N] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for heapless::Vec<O, N> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for Option<O> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_ref().is_some_and(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_ref().is_some_and(|o| o.may_block_between(a, b))
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>> Occluder<T> for (A, B) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b)
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>, C: Occluder<T>> Occluder<T> for (A, B, C) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q) || self.2.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b) || self.2.may_block_between(a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::Side;
    use crate::vec3::vec3;

    fn o() -> Vec3<f64> {
        vec3(0.0, 0.0, 0.0)
    }

    #[test]
    fn curvature_test_needs_both_dot_products() {
        let up = vec3(0.0, 0.0, 1.0);
        let down = vec3(0.0, 0.0, -1.0);
        let a = o();
        let b = vec3(0.3, 0.0, 1.0);
        assert!(mutually_facing(a, up, b, down));
        assert!(!mutually_facing(a, up, b, up), "fig. 4b: one dot product negative");
        assert!(!mutually_facing(a, down, b, up), "fig. 4c: both negative");
    }

    #[test]
    fn sphere_blocks_through_not_from_surface() {
        let s = Sphere::outer(o(), 1.0).unwrap();
        assert!(s.blocks(vec3(-3.0, 0.0, 0.0), vec3(3.0, 0.0, 0.0)));
        assert!(!s.blocks(vec3(-3.0, 1.5, 0.0), vec3(3.0, 1.5, 0.0)));
        // From a point on the sphere outward: not blocked (its own surface at τ = 0).
        assert!(!s.blocks(vec3(1.0, 0.0, 0.0), vec3(3.0, 0.5, 0.0)));
        // From a point on the sphere through the ball: blocked.
        assert!(s.blocks(vec3(1.0, 0.0, 0.0), vec3(-3.0, 0.0, 0.0)));
        // Chord between two points on the inside: visible (concave side sees itself).
        assert!(!s.blocks(vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)));
        // Segment ending before the sphere.
        assert!(!s.blocks(vec3(-3.0, 0.0, 0.0), vec3(-2.0, 0.0, 0.0)));
    }

    #[test]
    fn sphere_occlusion_is_scale_invariant() {
        for k in [1e-12, 1e-6, 1.0, 1e6, 1e12] {
            let s = Sphere::outer(o(), k).unwrap();
            assert!(s.blocks(vec3(-3.0 * k, 0.1 * k, 0.0), vec3(3.0 * k, 0.0, 0.2 * k)));
            assert!(!s.blocks(vec3(-3.0 * k, 1.1 * k, 0.0), vec3(3.0 * k, 1.1 * k, 0.0)));
        }
    }

    #[test]
    fn parallelogram_and_disk() {
        let sq = Parallelogram::new(vec3(-1.0, -1.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0)).unwrap();
        assert!(sq.blocks(vec3(0.5, 0.5, -1.0), vec3(0.5, 0.5, 1.0)));
        assert!(!sq.blocks(vec3(1.5, 0.5, -1.0), vec3(1.5, 0.5, 1.0)));
        assert!(!sq.blocks(vec3(0.5, 0.5, 0.5), vec3(0.5, 0.5, 1.0)));
        assert!(!sq.blocks(vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 1.0)), "parallel");
        let ring = Disk::annulus(o(), vec3(0.0, 0.0, 1.0), 0.5, 1.0).unwrap();
        assert!(ring.blocks(vec3(0.75, 0.0, -1.0), vec3(0.75, 0.0, 1.0)));
        assert!(!ring.blocks(vec3(0.2, 0.0, -1.0), vec3(0.2, 0.0, 1.0)), "through the hole");
        assert!(!ring.blocks(vec3(1.2, 0.0, -1.0), vec3(1.2, 0.0, 1.0)));
    }

    #[test]
    fn cylinder_tube() {
        let c = Cylinder::new(o(), vec3(0.0, 0.0, 1.0), 1.0, 2.0, Side::Outer).unwrap();
        assert!(c.blocks(vec3(-3.0, 0.0, 1.0), vec3(3.0, 0.0, 1.0)));
        assert!(!c.blocks(vec3(-3.0, 0.0, 3.0), vec3(3.0, 0.0, 3.0)), "above the tube");
        assert!(!c.blocks(vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 3.0)), "along the axis, open ends");
        // Inside chord between two points on the wall: not blocked.
        assert!(!c.blocks(vec3(1.0, 0.0, 0.5), vec3(-1.0, 0.0, 1.5)));
        // Enters through the open top, leaves through the wall: blocked.
        assert!(c.blocks(vec3(0.0, 0.0, 2.5), vec3(3.0, 0.0, 0.5)));
    }

    #[test]
    fn combinations() {
        let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let far = Sphere::outer(vec3(0.0, 10.0, 0.0), 1.0).unwrap();
        let (p, q) = (vec3(-3.0, 0.0, 0.0), vec3(3.0, 0.0, 0.0));
        assert!([far, s].blocks(p, q));
        assert!(![far].blocks(p, q));
        assert!((far, AnyOccluder::Sphere(s)).blocks(p, q));
        let mut v: heapless::Vec<AnyOccluder<f64>, 4> = heapless::Vec::new();
        assert!(!v.blocks(p, q));
        v.push(AnyOccluder::Sphere(s)).unwrap();
        assert!(v.blocks(p, q));
        assert!(!<() as Occluder<f64>>::blocks(&(), p, q));
        assert!(Some(s).blocks(p, q));
        let a = Ball { center: vec3(0.0, 5.0, -3.0), radius: 0.5 };
        let b = Ball { center: vec3(0.0, 5.0, 3.0), radius: 0.5 };
        assert!(!s.may_block_between(&a, &b));
        assert!(far
            .may_block_between(&Ball { center: p, radius: 0.5 }, &Ball { center: vec3(0.0, 13.0, 0.0), radius: 0.1 }));
    }
}
