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

pub use crate::integrand::mutually_facing;

/// Something that may block the line of sight between two points.
///
/// Sphere, parallelogram, disk and cylinder are occluders; several combine as a tuple, an
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
    /// default). Contract used by `boundary.rs`: for fixed `p` and `direction` and
    /// origins on a line (origin = o + s·v), every call passes the same number of polynomials
    /// in the same order, each coefficient a polynomial of degree ≤ 2 in s (true of anything
    /// built from dot products of origin − p taken at most twice).
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        let _ = (p, origin, direction, out);
        false
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

/// Passes the real roots of a·τ² + b·τ + c (a linear or constant polynomial included) to
/// `out`, in a cancellation-free form; a double root is passed once, non-finite roots never.
pub(crate) fn polynomial_roots<T: Real>(a: T, b: T, c: T, out: &mut dyn FnMut(T)) {
    let mut emit = |x: T| {
        if x.is_finite() {
            out(x);
        }
    };
    if a == T::ZERO {
        if b != T::ZERO {
            emit(-c / b);
        }
        return;
    }
    let disc = b * b - T::TWO * T::TWO * a * c;
    if disc < T::ZERO {
        return;
    }
    let q = if b >= T::ZERO { -(b + disc.sqrt()) * T::HALF } else { (disc.sqrt() - b) * T::HALF };
    if q == T::ZERO {
        emit(T::ZERO);
        return;
    }
    emit(q / a);
    if disc > T::ZERO {
        emit(c / q);
    }
}

/// (m·w)² − k·|w|² along w(τ) = w₀ + τ·d, as the coefficients (a, b, c) of a τ² + b τ + c
/// (zero where w lies on the cone of directions from p tangent to a sphere, k = |m|² − R²).
#[cfg(feature = "closed-form")]
#[inline]
fn cone_polynomial<T: Real>(m: Vec3<T>, k: T, w0: Vec3<T>, d: Vec3<T>) -> (T, T, T) {
    let (md, mw) = (m.dot(d), m.dot(w0));
    (md * md - k * d.norm2(), T::TWO * (md * mw - k * d.dot(w0)), mw * mw - k * w0.norm2())
}

/// |x(τ) − c|² − r² for x(τ) = x₀ + τ·d, as (a, b, c).
#[cfg(feature = "closed-form")]
#[inline]
fn sphere_polynomial<T: Real>(x0: Vec3<T>, d: Vec3<T>, center: Vec3<T>, r: T) -> (T, T, T) {
    let f = x0 - center;
    (d.norm2(), T::TWO * f.dot(d), f.norm2() - r * r)
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

#[cfg(not(feature = "closed-form"))]
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
        let pc = p - self.center;
        let r0 = pc.scale(nw0) + w0.scale(offset);
        let r1 = pc.scale(nd) + d.scale(offset);
        for radius in [self.inner_radius, self.outer_radius] {
            let k = radius * radius;
            out([r1.norm2() - k * nd * nd, T::TWO * (r0.dot(r1) - k * nw0 * nd), r0.norm2() - k * nw0 * nw0]);
        }
        true
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
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        match self {
            Self::Sphere(o) => o.line_polynomials(p, origin, direction, out),
            Self::Parallelogram(o) => o.line_polynomials(p, origin, direction, out),
            Self::Disk(o) => o.line_polynomials(p, origin, direction, out),
            Self::Cylinder(o) => o.line_polynomials(p, origin, direction, out),
        }
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Sphere(o) => o.hides_ball_from(p, b),
            _ => false,
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
    #[cfg(feature = "closed-form")]
    fn line_polynomials(
        &self,
        _p: Vec3<T>,
        _origin: Vec3<T>,
        _direction: Vec3<T>,
        _out: &mut dyn FnMut([T; 3]),
    ) -> bool {
        true
    }
}

impl<T: Real, O: Occluder<T> + ?Sized> Occluder<T> for &O {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        (**self).blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        (**self).may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        (**self).line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        (**self).hides_ball_from(p, b)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for [O] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.iter().any(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.iter().any(|o| o.may_block_between(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.iter().any(|o| o.hides_ball_from(p, b))
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for [O; N] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_slice().hides_ball_from(p, b)
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for heapless::Vec<O, N> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_slice().hides_ball_from(p, b)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for Option<O> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_ref().is_some_and(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_ref().is_some_and(|o| o.may_block_between(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.as_ref().is_none_or(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_ref().is_some_and(|o| o.hides_ball_from(p, b))
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>> Occluder<T> for (A, B) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.0.line_polynomials(p, origin, direction, out) && self.1.line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.0.hides_ball_from(p, b) || self.1.hides_ball_from(p, b)
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>, C: Occluder<T>> Occluder<T> for (A, B, C) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q) || self.2.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b) || self.2.may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.0.line_polynomials(p, origin, direction, out)
            && self.1.line_polynomials(p, origin, direction, out)
            && self.2.line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.0.hides_ball_from(p, b) || self.1.hides_ball_from(p, b) || self.2.hides_ball_from(p, b)
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

    /// Every change of `blocks(p, origin + τ·direction)` along a line lies at a root of one of
    /// the occluder's `line_polynomials`: sampled densely on random lines, each change is
    /// bracketed by two samples 1e-4 apart and must contain a candidate.
    #[cfg(feature = "closed-form")]
    fn check_line_breaks<O: Occluder<f64>>(occluder: &O, seed: u64) -> usize {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut changes = 0;
        for _ in 0..200 {
            let p = vec3(3.0 * next(), 3.0 * next(), 3.0 + next());
            let origin = vec3(3.0 * next(), 3.0 * next(), -3.0 + next());
            let direction = vec3(next(), next(), 0.3 * next()).scale(4.0);
            let mut candidates = [0.0f64; 64];
            let mut n = 0;
            assert!(occluder.line_polynomials(p, origin, direction, &mut |[a, b, c]| {
                polynomial_roots(a, b, c, &mut |t| {
                    if let Some(slot) = candidates.get_mut(n) {
                        *slot = t;
                        n += 1;
                    }
                });
            }));
            let samples = 20_000;
            let at = |k: usize| -2.0 + 4.0 * k as f64 / samples as f64;
            let mut prev = occluder.blocks(p, origin + direction.scale(at(0)));
            for k in 1..=samples {
                let now = occluder.blocks(p, origin + direction.scale(at(k)));
                if now != prev {
                    changes += 1;
                    let (lo, hi) = (at(k - 1), at(k));
                    let found = candidates.iter().take(n).any(|&c| c >= lo - 1e-9 && c <= hi + 1e-9);
                    assert!(
                        found,
                        "change in [{lo}, {hi}] without a candidate (p {p:?}, line {origin:?} + t {direction:?})"
                    );
                }
                prev = now;
            }
        }
        changes
    }

    #[cfg(feature = "closed-form")]
    #[test]
    fn line_polynomials_vanish_at_every_change_of_visibility() {
        let sphere = Sphere::new(vec3(0.2, -0.1, 0.0), 1.3, Side::Outer).unwrap();
        let quad = Parallelogram::new(vec3(-1.0, -0.5, 0.3), vec3(2.0, 0.4, 0.1), vec3(-0.3, 1.5, 0.2)).unwrap();
        let disk = Disk::annulus(vec3(0.1, 0.2, -0.2), vec3(0.2, 0.1, 1.0), 0.4, 1.6).unwrap();
        // Each occluder must actually cast shadows on the sampled lines.
        assert!(check_line_breaks(&sphere, 1) > 100);
        assert!(check_line_breaks(&quad, 2) > 100);
        assert!(check_line_breaks(&disk, 3) > 100);
        let mixed = [AnyOccluder::Sphere(sphere), AnyOccluder::Parallelogram(quad), AnyOccluder::Disk(disk)];
        assert!(check_line_breaks(&mixed, 4) > 100);
        let tube = Cylinder::new(vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 1.0), 1.0, 2.0, Side::Outer).unwrap();
        assert!(!tube.line_polynomials(vec3(0.0, 0.0, 3.0), vec3(0.0, 0.0, -3.0), vec3(1.0, 0.0, 0.0), &mut |_| {}));
    }

    #[test]
    fn polynomial_roots_are_accurate_and_complete() {
        let roots = |a: f64, b: f64, c: f64| {
            let mut r = [f64::NAN; 2];
            let mut n = 0;
            polynomial_roots(a, b, c, &mut |x| {
                if let Some(slot) = r.get_mut(n) {
                    *slot = x;
                }
                n += 1;
            });
            (n, r)
        };
        // (τ − 1e8)(τ − 1e-8): the small root without cancellation.
        let (n, r) = roots(1.0, -(1e8 + 1e-8), 1.0);
        assert_eq!(n, 2);
        assert!(r.iter().any(|&x| ((x - 1e-8) / 1e-8).abs() < 1e-15));
        assert_eq!(roots(0.0, 2.0, -1.0).0, 1);
        assert_eq!(roots(0.0, 2.0, -1.0).1[0], 0.5);
        assert_eq!(roots(0.0, 0.0, 1.0).0, 0);
        assert_eq!(roots(1.0, 0.0, 1.0).0, 0);
        assert_eq!(roots(1.0, -2.0, 1.0).0, 1);
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

    /// A small deterministic generator for the geometric tests (xorshift64*), values in [-1, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            2.0 * (x as f64 / (1u64 << 53) as f64) - 1.0
        }
        fn vec(&mut self, scale: f64) -> Vec3<f64> {
            vec3(self.next() * scale, self.next() * scale, self.next() * scale)
        }
    }

    /// The hull of two balls is the union of the balls centred on the segment between their
    /// centres with linearly interpolated radii: an independent way to get the distance.
    #[test]
    fn hull_distance_matches_union_of_interpolated_balls() {
        let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
        let mut inside = 0;
        for case in 0..2000 {
            let a = Ball { center: rng.vec(3.0), radius: if case % 5 == 0 { 0.0 } else { 1.0 + rng.next() } };
            let b = Ball { center: rng.vec(3.0), radius: 1.0 + rng.next() };
            let x = rng.vec(3.0);
            let mut brute = f64::INFINITY;
            for k in 0..=20_000 {
                let l = f64::from(k) / 20_000.0;
                let c = a.center.scale(1.0 - l) + b.center.scale(l);
                let r = a.radius * (1.0 - l) + b.radius * l;
                brute = brute.min(((x - c).norm() - r).max(0.0));
            }
            let d = distance_to_hull_of_balls(x, &a, &b);
            // The λ grid overestimates the minimum by at most (step · slope)² scale.
            assert!(d <= brute + 1e-12, "case {case}: {d} > {brute}");
            assert!(brute - d <= 1e-6, "case {case}: {d} vs {brute}");
            inside += usize::from(d == 0.0);
        }
        assert!(inside > 50 && inside < 1900, "cases inside the hull: {inside}");
    }

    /// Whenever the sphere claims to hide a ball from p, every probed segment from p into the
    /// ball (surface and interior points) is blocked; and it does claim so in many cases.
    #[test]
    #[cfg(feature = "closed-form")]
    fn sphere_hides_ball_only_when_every_segment_is_blocked() {
        let mut rng = Lcg(0x1234_5678_9abc_def1);
        let sphere = Sphere::outer(o(), 1.0).unwrap();
        let mut hidden = 0;
        for case in 0..4000 {
            // p outside, b roughly behind the sphere as seen from p.
            let p = rng.vec(1.0) + vec3(0.0, 0.0, 2.0 + 2.0 * rng.next().abs());
            let behind = (o() - p).scale(1.0 + 2.0 * rng.next().abs());
            let b = Ball { center: o() + behind + rng.vec(0.7), radius: 0.6 * rng.next().abs() };
            if !sphere.hides_ball_from(p, &b) {
                continue;
            }
            hidden += 1;
            for _ in 0..200 {
                let u = rng.vec(1.0);
                let dir = if u.norm() > 1e-9 { u.scale(1.0 / u.norm()) } else { vec3(1.0, 0.0, 0.0) };
                for f in [1.0, rng.next().abs()] {
                    let q = b.center + dir.scale(b.radius * f);
                    assert!(sphere.blocks(p, q), "case {case}: {p:?} -> {q:?} not blocked");
                }
            }
        }
        assert!(hidden > 200, "hidden in only {hidden} cases");
        // Not hidden: p inside, a ball overlapping the tangent cone's edge, a ball in front.
        let b = Ball { center: vec3(0.0, 0.0, -3.0), radius: 0.1 };
        assert!(sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &b));
        assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 0.5), &b));
        assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &Ball { center: vec3(1.9, 0.0, -3.0), radius: 0.5 }));
        assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &Ball { center: vec3(0.0, 0.0, 1.5), radius: 0.1 }));
    }
}
