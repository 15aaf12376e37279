//! Visibility: the curvature tests of sections 3.1–3.3 and exact occlusion tests (section 3).
//!
//! **Curvature test.** A pair of sample points (P_a, P_b) can exchange energy only if each lies in
//! front of the other's tangent plane: n_a·e_ab > 0 **and** n_b·e_ba > 0 (section 3.2: both dot
//! products, which is also correct for the plane–curved case of section 3.1 and for concave
//! surfaces, section 3.3). [`crate::mutually_facing`] is that test; the PDM sum applies it to every pair.
//!
//! **Occlusion.** An [`Occluder`] answers whether the open segment P_a → P_b crosses it. The
//! built-in shapes are exact occluders (closed-form segment intersection): [`Sphere`],
//! [`Parallelogram`], [`Quadrilateral`](crate::Quadrilateral) (and triangle), [`Disk`] (annulus), [`Cylinder`] (open tube), [`Cone`](crate::Cone)
//! (cone or frustum); the [`BezierPatch`](crate::BezierPatch) occludes to a stated tolerance
//! ([`BEZIER_FLATNESS`], by subdivision of its control net). Their *surface* is the
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
//!
//! Files: the trait and the bounding-ball tests here; one file per built-in shape
//! (`sphere.rs`, `parallelogram.rs`, `quadrilateral.rs`, `disk.rs`, `cylinder.rs`, `cone.rs`, `bezier.rs`); the root finding they share
//! (`roots.rs`); the combinations (`combine.rs`).

use crate::real::Real;
use crate::samples::Ball;
use crate::surface::{Cylinder, Disk, Parallelogram, Sphere};
use crate::vec3::Vec3;

mod bezier;
mod combine;
mod cone;
mod cylinder;
mod disk;
mod parallelogram;
mod quadrilateral;
mod roots;
mod sphere;
#[cfg(test)]
mod tests;

pub use crate::surface::Quadric;
pub use bezier::BEZIER_FLATNESS;
pub use combine::AnyOccluder;
pub(crate) use roots::polynomial_roots;
use roots::*;

/// An occluder as [`Occluder::shadow_casters`] passes it: a flat convex polygon (its corners in
/// order around the outline; a repeated corner is allowed, a triangle as a quadrilateral) or a
/// sphere.
#[cfg(feature = "closed-form")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Caster<'x, T> {
    /// A flat convex polygon.
    Polygon(&'x [Vec3<T>]),
    /// A sphere (centre and radius).
    Sphere(Ball<T>),
}

/// Something that may block the line of sight between two points.
///
/// Sphere, parallelogram, quadrilateral (and triangle), disk, cylinder, cone and Bézier patch are occluders; several combine as a tuple, an
/// array, a slice or a `heapless::Vec` (of [`AnyOccluder`] to mix kinds), and `&()` means none.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, Parallelogram, Patch, Sphere};
/// // Unit squares 1 apart (C-11: 0.1998248956983874). A sphere far to the side blocks
/// // nothing; a large disk between them blocks everything.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let ceiling = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (Patch::whole(&floor)?, Patch::whole(&ceiling)?);
/// let far = Sphere::outer(vec3(5.0, 5.0, 0.5), 1.0)?;
/// let screen = Disk::new(vec3(0.5, 0.5, 0.5), vec3(0.0, 0.0, 1.0), 2.0)?;
/// let seen = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &far)?.value;
/// let hidden = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &(far, screen))?.value;
/// assert!((seen - 0.1998248956983874).abs() < 1e-13 && hidden == 0.0);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
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

    /// Closed-form visibility along a straight line: passes to `out` polynomials
    /// `[a, b, c]` (a τ² + b τ + c) such that `blocks(p, origin + τ·direction)` can change value
    /// only at their real roots (extra polynomials are harmless, a missing one is a bug), and
    /// returns `true`; or returns `false`, and the caller brackets and bisects instead (the
    /// default). Contract used by `boundary/`: for fixed `p` and `direction` and
    /// origins on a line (origin = o + s·v), every call passes the same number of polynomials
    /// in the same order, each coefficient a polynomial of degree ≤ 2 in s (true of anything
    /// built from dot products of origin − p taken at most twice).
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let _ = (p, origin, direction, out);
        false
    }

    /// Outer-level events for an inner parallelogram (used by `boundary/` to place them into
    /// the outer rule): for the inner patch's corner `corner` and its edge from `corner` to
    /// `corner + edge`, passes to `out` quadrics F(p) such that the visible part of the inner
    /// patch seen from a point p changes its structure (this occluder's shadow boundary passing
    /// through the corner, or becoming tangent to the edge) only where some F(p) = 0 (extra
    /// quadrics are harmless, a missing one is a bug), for every p on the outer patch, and
    /// returns `true`; or returns `false` (the default: the caller then samples across those
    /// events). `pair` holds the outer patch's corners and those of the part of the inner
    /// patch that it sees (convex polygons, in order around them): an occluder whose shadow has
    /// more kinds of boundary than it can give curves for may still give them where the pair
    /// keeps clear of the others (a tube whose rims no segment of the pair comes near).
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        let _ = (corner, edge, pair, out);
        false
    }

    /// The one sphere that may cut segments between points of balls `a` and `b`:
    /// `Some(Some(ball))` if this occluder is a sphere that may (a combination: exactly one of
    /// its parts is such a sphere and no other part may cut), `Some(None)` if nothing may cut
    /// ([`may_block_between`](Occluder::may_block_between)), `None` otherwise. With `a` a point
    /// (radius zero), `boundary/` then takes the inner integral over a parallelogram b from that
    /// point in closed form: b's directions minus the sphere's cone of directions; with `a` a
    /// patch's ball, the pair methods leave out a sphere the patch lies on
    /// ([`Surface::convex_ball`](crate::Surface::convex_ball)).
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        (!self.may_block_between(a, b)).then_some(None)
    }

    /// The occluders that may cut a segment from a point of the ball `from` (a point: radius
    /// zero) to the flat convex polygon `b` (inside `bounds`), where each is a flat convex
    /// polygon or a sphere: passes each to `out`
    /// ([`Caster`]) and returns `true`; or returns `false` where some part that may cut is
    /// neither. `boundary/` then takes the inner integral over a parallelogram b from a point p
    /// in closed form (b less the polygons' shadows, less one sphere's cone of directions), and
    /// asked from a whole flat outer patch places the polygons' outer events into its rule. The
    /// default passes nothing and says whether nothing may cut
    /// ([`may_block_between`](Occluder::may_block_between) from `from` to `bounds`).
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        let _ = (b, out);
        !self.may_block_between(from, bounds)
    }

    /// Conservative culling the other way: `true` only if every segment from `p` to a point of
    /// ball `b` is blocked (then nothing of b is visible from p). The default says "not sure"
    /// (`false`).
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        let _ = (p, b);
        false
    }
}

/// `true` if the ball (c, r) can meet some segment between the balls `a` and `b`: every such
/// segment lies in the convex hull of the two balls (a round cone), so the test is the exact
/// distance from c to that hull against r (with a relative slack of `GEOMETRY_TOLERANCE`). A
/// ball of radius zero is a point: the hull is then the cone of segments from it.
/// Without the `closed-form` feature (embedded builds, where flash counts) the hull is replaced
/// by the looser tube of radius max(r_a, r_b) around the segment between the centres.
#[inline]
pub(crate) fn ball_may_cut_pair<T: Real>(c: Vec3<T>, r: T, a: &Ball<T>, b: &Ball<T>) -> bool {
    let scale = r + a.radius + b.radius + (b.center - a.center).norm();
    #[cfg(feature = "closed-form")]
    let distance = distance_to_hull_of_balls(c, a, b);
    #[cfg(not(feature = "closed-form"))]
    let distance = distance_point_segment(c, a.center, b.center) - a.radius.max(b.radius);
    distance <= r + scale * T::GEOMETRY_TOLERANCE
}

/// Distance from c to the segment a–b.
fn distance_point_segment<T: Real>(c: Vec3<T>, a: Vec3<T>, b: Vec3<T>) -> T {
    let d = b - a;
    let dd = d.norm2();
    let tau = if dd > T::ZERO { ((c - a).dot(d) / dd).max(T::ZERO).min(T::ONE) } else { T::ZERO };
    (c - (a + d.scale(tau))).norm()
}

/// Distance from x to the convex hull of two balls (zero inside; exact). The hull is a cone
/// frustum closed by the two spherical caps; in the plane of its axis and x, with `axial` and
/// `radial` the coordinates of x from a's centre, the frustum's side is the line at slope
/// (r_a − r_b)/h tangent to both circles.
#[cfg(any(feature = "closed-form", test))]
fn distance_to_hull_of_balls<T: Real>(x: Vec3<T>, a: &Ball<T>, b: &Ball<T>) -> T {
    let axis = b.center - a.center;
    let h = axis.norm();
    let (ra, rb) = (a.radius, b.radius);
    let to_a = x - a.center;
    if !(h > (ra - rb).abs()) {
        // One ball contains the other (or their centres coincide).
        let (big, radius) = if ra >= rb { (a.center, ra) } else { (b.center, rb) };
        return ((x - big).norm() - radius).max(T::ZERO);
    }
    let unit = axis.scale(T::ONE / h);
    let axial = to_a.dot(unit);
    let radial = (to_a - unit.scale(axial)).norm();
    let slope = (ra - rb) / h;
    let cosine = (T::ONE - slope * slope).max(T::ZERO).sqrt();
    let along_side = cosine * axial - slope * radial;
    let distance = if along_side < T::ZERO {
        to_a.norm() - ra
    } else if along_side > cosine * h {
        (x - b.center).norm() - rb
    } else {
        cosine * radial + slope * axial - ra
    };
    distance.max(T::ZERO)
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
