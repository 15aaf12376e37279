//! Quadrics in space: the form in which occluders and surfaces give their outer-level events.

use crate::real::Real;
use crate::vec3::Vec3;

/// A quadric F(p) = vᵀ M v + g·v + c with v = p − `origin`: where F changes sign, the part of
/// an inner patch that a point p sees may change its structure ([`crate::visibility::Occluder::event_quadrics`],
/// [`super::Surface::event_quadrics`]). `boundary/` restricts it to a flat outer patch, where it
/// is a conic in the patch's parameters, and places its roots into the outer rule. Where the
/// quadric is an event only on part of its surface, `guard` says which part, so that the outer
/// rule is not cut where nothing happens.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Quadric<T> {
    /// The point v is measured from.
    pub origin: Vec3<T>,
    /// The symmetric M as its entries `[xx, yy, zz, xy, xz, yz]`.
    pub m: [T; 6],
    /// The linear part g.
    pub g: Vec3<T>,
    /// The constant c.
    pub c: T,
    /// `Some([g₀, g₁])`: F = 0 is an event only where (g₀·v)(g₁·v) ≥ 0 (a double wedge about a
    /// line through `origin`; where it ends inside the outer patch, the ends are breaks of the
    /// outer rule too). `None`: everywhere.
    pub guard: Option<[Vec3<T>; 2]>,
}

impl<T: Real> Quadric<T> {
    /// The cone (p − apex)ᵀ M (p − apex).
    #[must_use]
    pub fn cone(apex: Vec3<T>, m: [T; 6]) -> Self {
        Self { origin: apex, m, g: Vec3::ZERO, c: T::ZERO, guard: None }
    }

    /// The plane normal·(p − point) (positive on the side `normal` points to).
    #[must_use]
    pub fn plane(point: Vec3<T>, normal: Vec3<T>) -> Self {
        Self { origin: point, m: [T::ZERO; 6], g: normal, c: T::ZERO, guard: None }
    }

    /// The envelope of the sphere's tangent planes along its circle {x : n·(x − centre) = h}
    /// (n a unit vector, |h| < r): the points p from which the circle of tangency of the
    /// sphere's cone of tangents (the outline a point sees) touches that circle. It is the cone
    /// with apex centre + (r²/h)·n, or the cylinder of radius r around the axis n for a great
    /// circle (h = 0). With w = p − centre the two outlines are the circles of the planes
    /// w·x = r² and n·x = h on the sphere; they touch where
    /// r²(w·n − h)² = (|w|² − r²)(r² − h²), which is this quadric equal to zero.
    #[must_use]
    pub fn sphere_circle_envelope(centre: Vec3<T>, r: T, n: Vec3<T>, h: T) -> Self {
        let (r2, k) = (r * r, r * r - h * h);
        let m = [
            r2 * n.x * n.x - k,
            r2 * n.y * n.y - k,
            r2 * n.z * n.z - k,
            r2 * n.x * n.y,
            r2 * n.x * n.z,
            r2 * n.y * n.z,
        ];
        Self { origin: centre, m, g: n.scale(-T::TWO * r2 * h), c: r2 * r2, guard: None }
    }

    /// The same quadric, an event only where (g₀·v)(g₁·v) ≥ 0.
    #[must_use]
    pub fn guarded(self, g0: Vec3<T>, g1: Vec3<T>) -> Self {
        Self { guard: Some([g0, g1]), ..self }
    }

    /// Whether p lies where the quadric is an event (`guard`).
    #[must_use]
    pub fn guard_holds(&self, p: Vec3<T>) -> bool {
        let v = p - self.origin;
        self.guard.is_none_or(|[g0, g1]| g0.dot(v) * g1.dot(v) >= T::ZERO)
    }

    /// xᵀ M y.
    #[must_use]
    pub fn bilinear(&self, x: Vec3<T>, y: Vec3<T>) -> T {
        let [xx, yy, zz, xy, xz, yz] = self.m;
        x.x * (xx * y.x + xy * y.y + xz * y.z)
            + x.y * (xy * y.x + yy * y.y + yz * y.z)
            + x.z * (xz * y.x + yz * y.y + zz * y.z)
    }

    /// F(p).
    #[must_use]
    pub fn at(&self, p: Vec3<T>) -> T {
        let v = p - self.origin;
        self.bilinear(v, v) + self.g.dot(v) + self.c
    }
}
