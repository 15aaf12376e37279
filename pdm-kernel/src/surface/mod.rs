//! Parametric surfaces g(t, s) → R³ and their unnormalised normals (eqs. 1–4).
//!
//! A [`Surface`] gives the point g(t, s) and the normal n(t, s) = ∂g/∂t × ∂g/∂s (eq. 4), whose
//! length is the area element (eqs. 6–8), over a parameter rectangle ([`ParamRect`]). The normal
//! points to the side that radiates; a surface that radiates from its other side negates it
//! ([`Flipped`], or the `inner` constructors of the closed built-ins).
//!
//! Two ways to get the normal:
//! - closed form, written out for every built-in ([`Sphere`], [`Parallelogram`], [`Disk`],
//!   [`Cylinder`], [`Cone`], [`BezierPatch`], [`Quadrilateral`] (and triangles));
//! - automatically for any [`ParametricMap`], by forward-mode dual numbers: wrap it in
//!   [`AutoNormal`]. Every built-in is also a `ParametricMap`, and the tests check that both ways
//!   agree to rounding.

mod bezier;
mod cone;
mod cylinder;
mod disk;
mod parallelogram;
mod quadric;
mod quadrilateral;
mod sphere;

pub use bezier::BezierPatch;
pub use cone::Cone;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use parallelogram::Parallelogram;
pub use quadric::Quadric;
pub use quadrilateral::Quadrilateral;
pub use sphere::Sphere;

use crate::dual::{Dual, Scalar};
use crate::error::PdmError;
use crate::real::Real;
#[cfg(feature = "closed-form")]
use crate::vec3::Ball;
use crate::vec3::{vec3, Vec3};

/// A parameter rectangle [t0, t1] × [s0, s1].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParamRect<T> {
    /// Start of the t range.
    pub t0: T,
    /// End of the t range.
    pub t1: T,
    /// Start of the s range.
    pub s0: T,
    /// End of the s range.
    pub s1: T,
}

impl<T: Real> ParamRect<T> {
    /// A rectangle, validated: finite bounds and `t0 < t1`, `s0 < s1`.
    pub fn new(t0: T, t1: T, s0: T, s1: T) -> Result<Self, PdmError> {
        let r = Self { t0, t1, s0, s1 };
        r.validate()?;
        Ok(r)
    }

    /// `Err(NonFinite)` for a NaN/∞ bound, `Err(EmptyParameterRange)` for an empty interval.
    pub fn validate(&self) -> Result<(), PdmError> {
        if !(self.t0.is_finite() && self.t1.is_finite() && self.s0.is_finite() && self.s1.is_finite()) {
            return Err(PdmError::NonFinite);
        }
        if !(self.t0 < self.t1 && self.s0 < self.s1) {
            return Err(PdmError::EmptyParameterRange);
        }
        Ok(())
    }

    /// `true` if `inner` lies inside `self`, allowing a rounding tolerance relative to the size.
    #[must_use]
    pub fn contains(&self, inner: &Self) -> bool {
        let tol_t = (self.t1 - self.t0).abs() * T::GEOMETRY_TOLERANCE;
        let tol_s = (self.s1 - self.s0).abs() * T::GEOMETRY_TOLERANCE;
        inner.t0 >= self.t0 - tol_t
            && inner.t1 <= self.t1 + tol_t
            && inner.s0 >= self.s0 - tol_s
            && inner.s1 <= self.s1 + tol_s
    }

    /// Cell (i, j) of an m × n grid over this rectangle (i along t, j along s), computed so that
    /// neighbouring cells share their bounds exactly.
    #[must_use]
    pub fn cell(&self, i: usize, j: usize, m: usize, n: usize) -> Self {
        let at = |k: usize, cnt: usize, a: T, b: T| {
            if k == 0 {
                a
            } else if k >= cnt {
                b
            } else {
                let f = T::from_usize(k) / T::from_usize(cnt);
                a + (b - a) * f
            }
        };
        Self {
            t0: at(i, m, self.t0, self.t1),
            t1: at(i + 1, m, self.t0, self.t1),
            s0: at(j, n, self.s0, self.s1),
            s1: at(j + 1, n, self.s0, self.s1),
        }
    }
}

/// A parametric surface g(t, s) with its unnormalised normal n = ∂g/∂t × ∂g/∂s (eq. 4).
pub trait Surface<T: Real> {
    /// The parameter rectangle D over which g is defined.
    fn domain(&self) -> ParamRect<T>;
    /// The point g(t, s).
    fn point(&self, t: T, s: T) -> Vec3<T>;
    /// The normal ±(∂g/∂t × ∂g/∂s) at (t, s), pointing to the radiating side; its length is the
    /// area element |n| of eq. (8). Zero where the parameterisation degenerates (a sphere's poles).
    fn normal(&self, t: T, s: T) -> Vec3<T>;
    /// Point and normal together (override when they share work).
    #[inline]
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        (self.point(t, s), self.normal(t, s))
    }
    /// `Some((origin, edge_t, edge_s))` if the map is affine, g(t, s) = origin + t·edge_t +
    /// s·edge_s, with the constant normal ±edge_t × edge_s (a parallelogram). Visibility
    /// boundaries on such a patch are roots of low-degree polynomials, which
    /// `boundary/` solves in closed form instead of bisecting. Default: `None`.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        None
    }
    /// `Some((g, ∂g/∂t, ∂g/∂s))` at (t, s): the point and the tangents of the patch's edges,
    /// along which the contour form of two flat patches integrates ([`crate::pair_exchange`]:
    /// flat pairs with curved edges, such as disk and annulus sectors, nearly coincident or
    /// not). The built-in surfaces and [`AutoNormal`] provide them (exact, by dual numbers).
    /// Default: `None` (such a pair then takes the 4-D paths). With the `closed-form` feature
    /// (on by default), like the contour form that uses it.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        let _ = (t, s);
        None
    }
    /// `Some(corners)` if the patch over `rect` is flat with straight edges joining the images
    /// of the rectangle's corners (t0, s0), (t1, s0), (t1, s1), (t0, s1), in that order (a side
    /// collapsed to a point repeats a corner): a parallelogram's patches, a
    /// [`Quadrilateral`]'s or a triangle's. Two such patches that see each other wholly take
    /// the contour form with its inner line integrals in closed form. Default: the corners of
    /// the [`affine_map`](Surface::affine_map), if there is one.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        let (o, et, es) = self.affine_map()?;
        let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
        Some([at(rect.t0, rect.s0), at(rect.t1, rect.s0), at(rect.t1, rect.s1), at(rect.t0, rect.s1)])
    }
    /// `Some([f₁, f₂])` if, along the t-line at `s`, both facing tests of section 3.2 between a
    /// point p (unit normal `np`) and the line's points q(t) are first-degree trigonometric
    /// polynomials in t: f = [a, b, c] stands for a + b·cos t + c·sin t, and f₁ has the sign of
    /// n̂_p·(q − p), f₂ that of n̂_q·(p − q), wherever the normal is not zero (a sphere's
    /// meridians). Visibility changes along such a line are then the roots of f₁ and f₂, which
    /// `boundary/` solves in closed form instead of bracketing and bisecting. Default: `None`.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn facing_along_t(&self, s: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        let _ = (s, p, np);
        None
    }
    /// `Some([f₁, f₂])` where [`facing_along_t`](Surface::facing_along_t) gives, for every s,
    /// f = [a, b, c] (a + b·cos t + c·sin t) whose coefficients are themselves first-degree
    /// trigonometric polynomials in s: each as `[k₀, k_c, k_s]` for k₀ + k_c·cos s + k_s·sin s.
    /// The inner rule then finds in closed form where the visible set of the t-lines changes
    /// its structure across s (a test's zero set crossing a t-edge, or tangent to the t-lines)
    /// instead of probing the edges. Default: `None`.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        let _ = (p, np);
        None
    }
    /// Outer-level events of the patch over `rect` as the inner patch of a pair that no
    /// occluder cuts (used by `boundary/` to place them into the outer rule of a flat outer
    /// patch): passes to `out` quadrics F(p) such that the part of the patch whose facing test
    /// n_q·(p − q) > 0 holds changes its structure (its outline passing through a corner of
    /// the patch, or touching an edge) only where some F(p) = 0 (extra quadrics are harmless,
    /// a missing one is a bug), and returns `true`; or returns `false` (the default: the caller
    /// then samples across those events). Curves of the outer patch's own facing test are the
    /// caller's.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(Quadric<T>)) -> bool {
        let _ = (rect, out);
        false
    }
    /// `Some(ball)` if every point of the surface lies on the sphere bounding `ball` and its
    /// normal points out of it (an outer [`Sphere`]). A segment that starts on such a surface
    /// and passes the facing test there leaves the ball at once and never re-enters it (the ball
    /// is convex and lies behind every tangent plane), so that sphere as an occluder cannot cut
    /// any sample pair the pair counts: the pair methods then leave it out
    /// (`pair::PairContext::may_occlude`). Default: `None`.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn convex_ball(&self) -> Option<Ball<T>> {
        None
    }
    /// `Some(ball)` if every point of the surface lies on the sphere bounding `ball`, on either
    /// side ([`Sphere`]), and its t- and s-lines are circles of that sphere (meridians and
    /// parallels). Across a sphere occluder with the same centre, its shadow on such a surface
    /// from a point p is bounded by a circle about the ray from the centre through p, so that
    /// its test along the lines is in closed form; where p lies on such a surface too, every
    /// boundary of what p sees is such a circle, and the pair's outer events are in closed form
    /// (`boundary/`). Default: `None`.
    #[cfg(feature = "closed-form")]
    #[inline]
    fn on_sphere(&self) -> Option<Ball<T>> {
        None
    }
}

impl<T: Real, S: Surface<T> + ?Sized> Surface<T> for &S {
    fn domain(&self) -> ParamRect<T> {
        (**self).domain()
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        (**self).point(t, s)
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        (**self).normal(t, s)
    }
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        (**self).point_and_normal(t, s)
    }
    #[cfg(feature = "closed-form")]
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        (**self).affine_map()
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        (**self).point_and_partials(t, s)
    }
    #[cfg(feature = "closed-form")]
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        (**self).straight_corners(rect)
    }
    #[cfg(feature = "closed-form")]
    fn facing_along_t(&self, s: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        (**self).facing_along_t(s, p, np)
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(Quadric<T>)) -> bool {
        (**self).event_quadrics(rect, out)
    }
    #[cfg(feature = "closed-form")]
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        (**self).facing_across_s(p, np)
    }
    #[cfg(feature = "closed-form")]
    fn convex_ball(&self) -> Option<Ball<T>> {
        (**self).convex_ball()
    }
    #[cfg(feature = "closed-form")]
    fn on_sphere(&self) -> Option<Ball<T>> {
        (**self).on_sphere()
    }
}

/// A map g(t, s) written once, generically over the arithmetic, so that the kernel can
/// differentiate it: implement this for your own surface and wrap it in [`AutoNormal`].
///
/// ```
/// use pdm_kernel::{AutoNormal, ParametricMap, ParamRect, Scalar, Surface, Vec3, vec3};
/// /// A paraboloid cap z = x² + y² over the unit square.
/// struct Paraboloid;
/// impl ParametricMap<f64> for Paraboloid {
///     fn domain(&self) -> ParamRect<f64> { ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 } }
///     fn map<S: Scalar<f64>>(&self, t: S, s: S) -> Vec3<S> { vec3(t, s, t * t + s * s) }
/// }
/// let n = AutoNormal(Paraboloid).normal(0.5, 0.25);
/// // ∂g/∂t × ∂g/∂s = (1,0,2t) × (0,1,2s) = (−2t, −2s, 1)
/// assert_eq!((n.x, n.y, n.z), (-1.0, -0.5, 1.0));
/// ```
pub trait ParametricMap<T: Real> {
    /// The parameter rectangle D.
    fn domain(&self) -> ParamRect<T>;
    /// g(t, s), in any [`Scalar`] arithmetic (plain reals or dual numbers).
    fn map<S: Scalar<T>>(&self, t: S, s: S) -> Vec3<S>;
    /// `true` if the surface radiates from the side opposite to ∂g/∂t × ∂g/∂s.
    fn flipped(&self) -> bool {
        false
    }
}

/// A [`ParametricMap`] whose normal is computed automatically (exact derivatives by dual numbers).
#[derive(Clone, Copy, Debug)]
pub struct AutoNormal<M>(pub M);

impl<T: Real, M: ParametricMap<T>> Surface<T> for AutoNormal<M> {
    fn domain(&self) -> ParamRect<T> {
        self.0.domain()
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.0.map(t, s)
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        self.point_and_normal(t, s).1
    }
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        let g = self.0.map(Dual::variable_t(t), Dual::variable_s(s));
        let p = vec3(g.x.v, g.y.v, g.z.v);
        let gt = vec3(g.x.dt, g.y.dt, g.z.dt);
        let gs = vec3(g.x.ds, g.y.ds, g.z.ds);
        let n = gt.cross(gs);
        (p, if self.0.flipped() { -n } else { n })
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        Some(dual_partials(&self.0, t, s))
    }
}

/// g, ∂g/∂t and ∂g/∂s of a [`ParametricMap`] by dual numbers (exact to rounding).
#[cfg(feature = "closed-form")]
pub(crate) fn dual_partials<T: Real, M: ParametricMap<T> + ?Sized>(m: &M, t: T, s: T) -> (Vec3<T>, Vec3<T>, Vec3<T>) {
    let g = m.map(Dual::variable_t(t), Dual::variable_s(s));
    (vec3(g.x.v, g.y.v, g.z.v), vec3(g.x.dt, g.y.dt, g.z.dt), vec3(g.x.ds, g.y.ds, g.z.ds))
}

/// Any surface, radiating from its other side (normal negated).
#[derive(Clone, Copy, Debug)]
pub struct Flipped<S>(pub S);

impl<T: Real, S: Surface<T>> Surface<T> for Flipped<S> {
    fn domain(&self) -> ParamRect<T> {
        self.0.domain()
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.0.point(t, s)
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        -self.0.normal(t, s)
    }
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        let (p, n) = self.0.point_and_normal(t, s);
        (p, -n)
    }
    #[cfg(feature = "closed-form")]
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        self.0.affine_map()
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        self.0.point_and_partials(t, s)
    }
    #[cfg(feature = "closed-form")]
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        self.0.straight_corners(rect)
    }
    /// The surface's, with the test on q's side negated (its normal is).
    #[cfg(feature = "closed-form")]
    fn facing_along_t(&self, s: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        let [f1, [a, b, c]] = self.0.facing_along_t(s, p, np)?;
        Some([f1, [-a, -b, -c]])
    }
    /// The surface's: the facing region flips, its outline does not.
    #[cfg(feature = "closed-form")]
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(Quadric<T>)) -> bool {
        self.0.event_quadrics(rect, out)
    }
    /// The surface's, with the test on q's side negated.
    #[cfg(feature = "closed-form")]
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        let [f1, f2] = self.0.facing_across_s(p, np)?;
        Some([f1, f2.map(|k| k.map(|x| -x))])
    }
    /// The surface's: its points and lines do not change.
    #[cfg(feature = "closed-form")]
    fn on_sphere(&self) -> Option<Ball<T>> {
        self.0.on_sphere()
    }
}

/// Which side of a closed built-in (sphere, cylinder, cone) radiates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Side {
    /// The convex, outward-facing side.
    Outer,
    /// The concave, inward-facing side (a patch on it may see itself: F_ii ≠ 0).
    Inner,
}

/// An orthonormal right-handed frame (u, w, axis) with u × w = axis.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame<T> {
    /// First in-plane unit vector (θ = 0 direction).
    pub u: Vec3<T>,
    /// Second in-plane unit vector (θ = π/2 direction).
    pub w: Vec3<T>,
    /// Unit axis.
    pub axis: Vec3<T>,
}

impl<T: Real> Frame<T> {
    /// A frame around `axis` (normalised here); `Err` for a zero or non-finite axis.
    /// The in-plane vectors follow Duff et al., "Building an orthonormal basis, revisited" (2017).
    pub fn from_axis(axis: Vec3<T>) -> Result<Self, PdmError> {
        if !axis.is_finite() {
            return Err(PdmError::NonFinite);
        }
        let len = axis.norm();
        if !(len > T::ZERO) {
            return Err(PdmError::Degenerate);
        }
        let n = axis.scale(T::ONE / len);
        let sign = if n.z >= T::ZERO { T::ONE } else { -T::ONE };
        let a = -T::ONE / (sign + n.z);
        let b = n.x * n.y * a;
        let u = vec3(T::ONE + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let w = vec3(b, sign + n.y * n.y * a, -n.y);
        Ok(Self { u, w, axis: n })
    }

    /// The frame with the z axis as axis: u = x̂, w = ŷ.
    #[must_use]
    pub fn standard() -> Self {
        Self {
            u: vec3(T::ONE, T::ZERO, T::ZERO),
            w: vec3(T::ZERO, T::ONE, T::ZERO),
            axis: vec3(T::ZERO, T::ZERO, T::ONE),
        }
    }

    /// u·a + w·b + axis·c for scalar coordinates in any arithmetic.
    #[inline(always)]
    pub(crate) fn combine<S: Scalar<T>>(&self, a: S, b: S, c: S) -> Vec3<S> {
        let k = |v: T| S::constant(v);
        vec3(
            k(self.u.x) * a + k(self.w.x) * b + k(self.axis.x) * c,
            k(self.u.y) * a + k(self.w.y) * b + k(self.axis.y) * c,
            k(self.u.z) * a + k(self.w.z) * b + k(self.axis.z) * c,
        )
    }
}

/// Lifts a constant point into any arithmetic.
#[inline(always)]
pub(crate) fn lift<T: Real, S: Scalar<T>>(p: Vec3<T>) -> Vec3<S> {
    vec3(S::constant(p.x), S::constant(p.y), S::constant(p.z))
}

/// `Err(NonFinite)` unless every value is finite.
pub(crate) fn check_finite<T: Real>(values: &[T]) -> Result<(), PdmError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(PdmError::NonFinite)
    }
}

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;

    /// Checks [`Surface::facing_along_t`] against the facing tests computed from points and
    /// normals: at `cases` random (t, s) inside the domain, points p in a box of half-width
    /// `reach` around the origin and random unit normals, each form's sign equals that of
    /// n̂_p·(q − p) and n̂_q·(p − q) wherever those are not within 1e-9 of zero; the same
    /// through [`Flipped`]. Returns how many signs were compared.
    #[cfg(feature = "closed-form")]
    pub(crate) fn facing_along_t_matches<S: Surface<f64> + Copy>(surface: S, reach: f64, cases: usize) -> usize {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let d = surface.domain();
        let mut checked = 0;
        for k in 0..cases {
            let t = d.t0 + (d.t1 - d.t0) * (0.005 + 0.99 * next());
            let s = d.s0 + (d.s1 - d.s0) * next();
            let p = vec3(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0).scale(reach);
            let np = vec3(next() - 0.5, next() - 0.5, next() - 0.5);
            let np = np.scale(1.0 / np.norm());
            let (q, nq) = surface.point_and_normal(t, s);
            if !(nq.norm() > 1e-12) {
                continue;
            }
            let nq = nq.scale(1.0 / nq.norm());
            let (towards_q, towards_p) = (np.dot(q - p), nq.dot(p - q));
            let eval = |[a, b, c]: [f64; 3]| a + b * t.cos() + c * t.sin();
            let [f1, f2] = surface.facing_along_t(s, p, np).expect("a trigonometric surface");
            let [g1, g2] = Flipped(surface).facing_along_t(s, p, np).expect("through Flipped");
            for (got, want) in
                [(eval(f1), towards_q), (eval(f2), towards_p), (eval(g1), towards_q), (eval(g2), -towards_p)]
            {
                if want.abs() > 1e-9 {
                    assert_eq!(got > 0.0, want > 0.0, "case {k} at ({t}, {s}): {got} against {want}");
                    checked += 1;
                }
            }
        }
        checked
    }

    /// Checks that a built-in's closed-form normal equals the automatic one (dual numbers) and
    /// that `point` equals the map, at a grid of interior parameter points.
    pub(crate) fn closed_form_matches_auto<S>(surface: &S, rel_tol: f64)
    where
        S: Surface<f64> + ParametricMap<f64> + Clone,
    {
        let d = Surface::domain(surface);
        let auto = AutoNormal(surface.clone());
        let mut checked = 0;
        for i in 0..7 {
            for j in 0..7 {
                let t = d.t0 + (d.t1 - d.t0) * (0.05 + 0.15 * i as f64);
                let s = d.s0 + (d.s1 - d.s0) * (0.03 + 0.155 * j as f64);
                let (p, n) = surface.point_and_normal(t, s);
                let (pa, na) = auto.point_and_normal(t, s);
                let scale = na.norm().max(1e-300);
                assert!((n - na).norm() <= rel_tol * scale, "normal at ({t},{s}): closed {n:?} vs auto {na:?}");
                assert!((p - pa).norm() <= rel_tol * (1.0 + p.norm()), "point at ({t},{s})");
                assert!((surface.normal(t, s) - n).norm() <= rel_tol * scale);
                assert!((surface.point(t, s) - p).norm() <= rel_tol * (1.0 + p.norm()));
                checked += 1;
            }
        }
        assert_eq!(checked, 49);
    }

    /// A second, independent check: n ≈ central finite differences of g.
    pub(crate) fn normal_matches_finite_differences<S: Surface<f64>>(surface: &S, rel_tol: f64) {
        let d = surface.domain();
        let h = 1e-6;
        for (ft, fs) in [(0.3, 0.4), (0.71, 0.13), (0.5, 0.9)] {
            let t = d.t0 + (d.t1 - d.t0) * ft;
            let s = d.s0 + (d.s1 - d.s0) * fs;
            let gt = (surface.point(t + h, s) - surface.point(t - h, s)).scale(0.5 / h);
            let gs = (surface.point(t, s + h) - surface.point(t, s - h)).scale(0.5 / h);
            let fd = gt.cross(gs);
            let n = surface.normal(t, s);
            let same = (n - fd).norm() <= rel_tol * n.norm();
            let opposite = (n + fd).norm() <= rel_tol * n.norm();
            assert!(same || opposite, "normal {n:?} vs finite difference {fd:?}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_right_handed() {
        for axis in [vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, -1.0), vec3(1.0, 2.0, -3.0), vec3(-1e-9, 1e-9, -1.0)] {
            let f = Frame::<f64>::from_axis(axis).unwrap();
            assert!((f.u.norm() - 1.0).abs() < 1e-14);
            assert!((f.w.norm() - 1.0).abs() < 1e-14);
            assert!(f.u.dot(f.w).abs() < 1e-14);
            assert!((f.u.cross(f.w) - f.axis).norm() < 1e-14, "{f:?}");
        }
        assert_eq!(Frame::<f64>::from_axis(vec3(0.0, 0.0, 0.0)), Err(PdmError::Degenerate));
        assert_eq!(Frame::<f64>::from_axis(vec3(f64::NAN, 0.0, 1.0)), Err(PdmError::NonFinite));
    }

    #[test]
    fn rect_validation_and_cells() {
        assert_eq!(ParamRect::new(1.0, 1.0, 0.0, 1.0), Err(PdmError::EmptyParameterRange));
        assert_eq!(ParamRect::new(0.0, f64::INFINITY, 0.0, 1.0), Err(PdmError::NonFinite));
        let r = ParamRect::new(0.0, 3.0, -1.0, 1.0).unwrap();
        let c = r.cell(2, 0, 3, 4);
        assert_eq!((c.t0, c.t1, c.s0, c.s1), (2.0, 3.0, -1.0, -0.5));
        assert_eq!(r.cell(0, 1, 3, 4).t1, r.cell(1, 1, 3, 4).t0);
    }
}
