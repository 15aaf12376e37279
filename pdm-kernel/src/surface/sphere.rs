//! The sphere of the paper, eqs. (19)–(21).

use super::{check_finite, lift, Frame, ParamRect, ParametricMap, Side, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::Vec3;

/// A sphere of centre c and radius r, parameterised as in eq. (19):
/// g(φ, θ) = c + r (sin φ cos θ · u + sin φ sin θ · w + cos φ · axis), φ ∈ [0, π] (t), θ ∈ [0, 2π] (s).
///
/// With the standard frame (axis = z) this is exactly eq. (19); the poles (φ = 0, π) lie on the
/// axis. The closed-form normal is eq. (21), n = r² sin φ (sin φ cos θ, sin φ sin θ, cos φ),
/// which points outward and vanishes at the poles (the area element is zero there; the kernel
/// gives such points zero weight and never divides by |n|).
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, Patch, Sphere};
/// // A sphere of radius ½ whose centre is 1 above a coaxial disk of radius 1; the whole
/// // sphere as one patch (its seam and poles are handled). Sphere → coaxial disk:
/// // F = ½(1 − 1/√(1 + (a/h)²)) (sphere → polygon, Ω/4π), here ½(1 − 1/√2).
/// let sphere = Sphere::outer(vec3(0.0, 0.0, 1.0), 0.5)?;
/// let disk = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0)?;
/// let (a, b) = (Patch::whole(&sphere)?, Patch::whole(&disk)?);
/// let settings = PairSettings { order: 12, singular_order: 12, boundaries: true };
/// let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, settings, &())?.value / a.area(16)?;
/// assert!((f - 0.5 * (1.0 - 1.0 / 2.0_f64.sqrt())).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sphere<T> {
    pub(crate) center: Vec3<T>,
    pub(crate) radius: T,
    pub(crate) frame: Frame<T>,
    pub(crate) side: Side,
}

impl<T: Real> Sphere<T> {
    /// A sphere with its poles on the z axis (the paper's eq. 19), radiating from `side`.
    /// `Err` for a non-finite centre or radius, or a radius ≤ 0.
    pub fn new(center: Vec3<T>, radius: T, side: Side) -> Result<Self, PdmError> {
        Self::with_frame(center, radius, Frame::standard(), side)
    }

    /// A sphere whose poles lie on `frame.axis` and whose θ = 0 meridian is in the `frame.u` direction.
    pub fn with_frame(center: Vec3<T>, radius: T, frame: Frame<T>, side: Side) -> Result<Self, PdmError> {
        check_finite(&[center.x, center.y, center.z, radius])?;
        if !(radius > T::ZERO) {
            return Err(PdmError::Degenerate);
        }
        Ok(Self { center, radius, frame, side })
    }

    /// Radiating from the outside (convex side).
    pub fn outer(center: Vec3<T>, radius: T) -> Result<Self, PdmError> {
        Self::new(center, radius, Side::Outer)
    }

    /// Radiating from the inside (concave side).
    pub fn inner(center: Vec3<T>, radius: T) -> Result<Self, PdmError> {
        Self::new(center, radius, Side::Inner)
    }

    /// Centre.
    #[must_use]
    pub fn center(&self) -> Vec3<T> {
        self.center
    }
    /// Radius.
    #[must_use]
    pub fn radius(&self) -> T {
        self.radius
    }
    /// Radiating side.
    #[must_use]
    pub fn side(&self) -> Side {
        self.side
    }
}

impl<T: Real> ParametricMap<T> for Sphere<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::PI, s0: T::ZERO, s1: T::TWO * T::PI }
    }
    /// Eq. (19).
    fn map<S: Scalar<T>>(&self, phi: S, theta: S) -> Vec3<S> {
        let r = S::constant(self.radius);
        let sp = phi.sin();
        let local = self.frame.combine(r * sp * theta.cos(), r * sp * theta.sin(), r * phi.cos());
        lift::<T, S>(self.center) + local
    }
    fn flipped(&self) -> bool {
        self.side == Side::Inner
    }
}

impl<T: Real> Surface<T> for Sphere<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.point_and_normal(t, s).0
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        self.point_and_normal(t, s).1
    }
    /// Eq. (19) and eq. (21): n = r² sin φ · (unit radial direction).
    fn point_and_normal(&self, phi: T, theta: T) -> (Vec3<T>, Vec3<T>) {
        let (sp, cp) = phi.sin_cos_fast();
        let (st, ct) = theta.sin_cos_fast();
        let radial = self.frame.combine(sp * ct, sp * st, cp);
        let p = self.center + radial.scale(self.radius);
        let n = radial.scale(self.radius * self.radius * sp);
        (p, if self.side == Side::Inner { -n } else { n })
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        Some(super::dual_partials(self, t, s))
    }
    /// Along a meridian θ = s: q(φ) = c + r·(cos φ·axis + sin φ·u_θ), u_θ = cos θ·u + sin θ·w,
    /// and n̂_q = ±(cos φ·axis + sin φ·u_θ) for φ ∈ (0, π). So n̂_p·(q − p) =
    /// n̂_p·(c − p) + r (n̂_p·axis) cos φ + r (n̂_p·u_θ) sin φ, and n̂_q·(p − q) =
    /// ±((p − c)·axis cos φ + (p − c)·u_θ sin φ − r).
    #[cfg(feature = "closed-form")]
    fn facing_along_t(&self, theta: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        let (st, ct) = (theta.sin(), theta.cos());
        let axis = self.frame.combine(T::ZERO, T::ZERO, T::ONE);
        let u = self.frame.combine(ct, st, T::ZERO);
        let r = self.radius;
        let d = p - self.center;
        let from_p = [-np.dot(d), r * np.dot(axis), r * np.dot(u)];
        let from_q = [-r, d.dot(axis), d.dot(u)];
        let from_q = if self.side == Side::Inner { from_q.map(|x| -x) } else { from_q };
        Some([from_p, from_q])
    }
    /// [`facing_along_t`](Surface::facing_along_t)'s coefficients as functions of θ: only the
    /// sin φ coefficient varies, through u_θ = cos θ·u + sin θ·w.
    #[cfg(feature = "closed-form")]
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        let axis = self.frame.combine(T::ZERO, T::ZERO, T::ONE);
        let (u, w) = (self.frame.combine(T::ONE, T::ZERO, T::ZERO), self.frame.combine(T::ZERO, T::ONE, T::ZERO));
        let (r, z) = (self.radius, T::ZERO);
        let d = p - self.center;
        let from_p = [[-np.dot(d), z, z], [r * np.dot(axis), z, z], [z, r * np.dot(u), r * np.dot(w)]];
        let from_q = [[-r, z, z], [d.dot(axis), z, z], [z, d.dot(u), d.dot(w)]];
        let from_q = if self.side == Side::Inner { from_q.map(|k| k.map(|x| -x)) } else { from_q };
        Some([from_p, from_q])
    }
    /// The outer side lies on the ball's boundary with its normals pointing out; the inner side
    /// faces into the ball, whose chords it sees.
    #[cfg(feature = "closed-form")]
    fn convex_ball(&self) -> Option<crate::vec3::Ball<T>> {
        (self.side == Side::Outer).then_some(crate::vec3::Ball { center: self.center, radius: self.radius })
    }
    /// Its ball, either side: the t-lines are meridians, the s-lines parallels.
    #[cfg(feature = "closed-form")]
    fn on_sphere(&self) -> Option<crate::vec3::Ball<T>> {
        Some(crate::vec3::Ball { center: self.center, radius: self.radius })
    }
    /// A point p sees the sphere's cap (p − c)·x̂ > r (either side: the inside sees the rest);
    /// over a cell [φ₀, φ₁] × [θ₀, θ₁] that cap's outline passes through a corner x̂ᵢ where
    /// (p − c)·x̂ᵢ = r (a plane), and touches a parallel φᵢ or a meridian θᵢ on the envelope of
    /// the tangent planes along that circle ([`super::Quadric::sphere_circle_envelope`]: a cone,
    /// the cylinder for a meridian's great circle). The outline touches a circle at the point of
    /// it nearest the cap's centre or farthest from it, which lies on the cell's edge only where
    /// p's azimuth (for a parallel) or p's polar angle in the meridian's plane (for a meridian)
    /// lies in the cell's range or opposite it: the guard, a double wedge about the axis or the
    /// meridian plane's normal (none for a range of π or more). Corners and circles that
    /// coincide (at a pole, or θ₀ and θ₁ a turn apart) are given once; a pole's parallel is a
    /// point, whose events are its corner's.
    #[cfg(feature = "closed-form")]
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(super::Quadric<T>)) -> bool {
        let r = self.radius;
        let radial = |phi: T, theta: T| {
            let sp = phi.sin();
            self.frame.combine(sp * theta.cos(), sp * theta.sin(), phi.cos())
        };
        let same = |x: Vec3<T>, y: Vec3<T>| (x - y).norm() <= T::GEOMETRY_TOLERANCE;
        let corners =
            [radial(rect.t0, rect.s0), radial(rect.t1, rect.s0), radial(rect.t1, rect.s1), radial(rect.t0, rect.s1)];
        for (k, &x) in corners.iter().enumerate() {
            if !corners.iter().take(k).any(|&y| same(x, y)) {
                out(super::Quadric { origin: self.center, m: [T::ZERO; 6], g: x, c: -r, guard: None });
            }
        }
        let axis = self.frame.combine(T::ZERO, T::ZERO, T::ONE);
        // In-plane direction at angle a from e₀ towards e₁: sin(angle − a) ∝ v·(cos a·e₁ − sin a·e₀).
        let wedge = |e0: Vec3<T>, e1: Vec3<T>, lo: T, hi: T| {
            let after = |a: T| e1.scale(a.cos()) - e0.scale(a.sin());
            (hi - lo < T::PI).then(|| (after(lo), -after(hi)))
        };
        let u_at = |theta: T| self.frame.combine(theta.cos(), theta.sin(), T::ZERO);
        let (u, w) = (u_at(T::ZERO), u_at(T::HALF * T::PI));
        let azimuth = wedge(u, w, rect.s0, rect.s1);
        for phi in [rect.t0, rect.t1] {
            if phi.sin().abs() > T::GEOMETRY_TOLERANCE {
                let q = super::Quadric::sphere_circle_envelope(self.center, r, axis, r * phi.cos());
                out(azimuth.map_or(q, |(g0, g1)| q.guarded(g0, g1)));
            }
        }
        let meridian = |theta: T| self.frame.combine(-theta.sin(), theta.cos(), T::ZERO);
        for (k, theta) in [rect.s0, rect.s1].into_iter().enumerate() {
            let m = meridian(theta);
            if k == 1 && same(m, meridian(rect.s0)) {
                continue;
            }
            let q = super::Quadric::sphere_circle_envelope(self.center, r, m, T::ZERO);
            // Polar angle in the meridian's half-plane, from the axis towards u_θ.
            let polar = wedge(axis, u_at(theta), rect.t0, rect.t1);
            out(polar.map_or(q, |(g0, g1)| q.guarded(g0, g1)));
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::vec3::vec3;

    #[test]
    fn normal_is_eq_21() {
        let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 2.0).unwrap();
        let (phi, theta) = (0.7_f64, 2.1_f64);
        let n = s.normal(phi, theta);
        let r2 = 4.0;
        let expect = vec3(
            r2 * phi.sin().powi(2) * theta.cos(),
            r2 * phi.sin().powi(2) * theta.sin(),
            r2 * phi.cos() * phi.sin(),
        );
        assert!((n - expect).norm() < 1e-14);
        assert_eq!(s.normal(0.0, 1.0).norm(), 0.0, "pole has zero area element");
    }

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        let frame = Frame::from_axis(vec3(1.0, -2.0, 0.5)).unwrap();
        for side in [Side::Outer, Side::Inner] {
            closed_form_matches_auto(&Sphere::with_frame(vec3(1.0, 2.0, 3.0), 1.5, frame, side).unwrap(), 1e-14);
            normal_matches_finite_differences(
                &Sphere::with_frame(vec3(1.0, 2.0, 3.0), 1.5, frame, side).unwrap(),
                1e-8,
            );
        }
    }

    #[test]
    fn sides_point_out_and_in() {
        let out = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let inn = Sphere::inner(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let (p, n) = out.point_and_normal(1.0, 1.0);
        assert!(p.dot(n) > 0.0);
        assert!(p.dot(inn.normal(1.0, 1.0)) < 0.0);
    }

    #[test]
    fn bad_input() {
        assert_eq!(Sphere::outer(vec3(0.0, 0.0, 0.0), 0.0), Err(PdmError::Degenerate));
        assert_eq!(Sphere::outer(vec3(0.0, f64::NAN, 0.0), 1.0), Err(PdmError::NonFinite));
        assert_eq!(Sphere::outer(vec3(0.0, 0.0, 0.0), f64::INFINITY), Err(PdmError::NonFinite));
        assert_eq!(Sphere::outer(vec3(0.0_f32, 0.0, 0.0), -1.0), Err(PdmError::Degenerate));
    }

    /// `facing_along_t` gives both facing tests along a meridian up to a positive factor: its
    /// signs agree with n̂_p·(q − p) and n̂_q·(p − q) computed from the points and normals,
    /// for both sides, a moved centre, points inside and outside, and through `Flipped`.
    #[cfg(feature = "closed-form")]
    #[test]
    fn facing_along_t_has_the_signs_of_the_facing_tests() {
        use crate::surface::Flipped;
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for side in [Side::Outer, Side::Inner] {
            // The shared check too, over the whole domain from points around the sphere.
            let sphere = Sphere::new(vec3(0.3, -0.2, 0.5), 1.3, side).unwrap();
            assert!(facing_along_t_matches(sphere, 4.0, 3000) > 11_000);
        }
        let mut checked = 0;
        for k in 0..4000 {
            let centre = vec3(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0);
            let radius = 0.2 + next() * 2.0;
            let sphere =
                if k % 2 == 0 { Sphere::outer(centre, radius) } else { Sphere::inner(centre, radius) }.unwrap();
            let p = vec3(next() * 8.0 - 4.0, next() * 8.0 - 4.0, next() * 8.0 - 4.0);
            let np = vec3(next() - 0.5, next() - 0.5, next() - 0.5);
            let np = np.scale(1.0 / np.norm());
            let (phi, theta) = (0.01 + next() * (core::f64::consts::PI - 0.02), next() * 7.0 - 0.5);
            let eval = |[a, b, c]: [f64; 3]| a + b * phi.cos() + c * phi.sin();
            let (q, nq) = sphere.point_and_normal(phi, theta);
            let nq = nq.scale(1.0 / nq.norm());
            let (towards_q, towards_p) = (np.dot(q - p), nq.dot(p - q));
            let [f1, f2] = sphere.facing_along_t(theta, p, np).unwrap();
            let [g1, g2] = Flipped(sphere).facing_along_t(theta, p, np).unwrap();
            for (got, want) in
                [(eval(f1), towards_q), (eval(f2), towards_p), (eval(g1), towards_q), (eval(g2), -towards_p)]
            {
                if want.abs() > 1e-9 {
                    assert_eq!(got > 0.0, want > 0.0, "k = {k}: {got} against {want}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 15_000);
    }
}
