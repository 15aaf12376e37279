//! Cones and conical frusta.

use super::{check_finite, lift, Frame, ParamRect, ParametricMap, Side, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::Vec3;

/// A conical frustum around `axis` whose radius goes linearly from r₀ at z = 0 to r₁ at z = h
/// (r₁ = 0: a cone with its apex at z = h):
/// g(θ, z) = base + r(z)(cos θ · u + sin θ · w) + z · axis, r(z) = r₀ + (r₁ − r₀) z / h,
/// θ ∈ [0, 2π] (t), z ∈ [0, h] (s). Normal ∂g/∂θ × ∂g/∂z = r(z)(cos θ · u + sin θ · w − k · axis)
/// with k = (r₁ − r₀)/h: outward for [`Side::Outer`]; zero at an apex.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, Cone, Disk, PairSettings, Patch, Side};
/// // The base disk of a cone (radius ½, height 1) sees only the cone's inside: F = 1
/// // (enclosure sum rule; the flat base does not see itself).
/// let base = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 0.5)?;
/// let cone = Cone::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 0.5, 0.0, 1.0, Side::Inner)?;
/// let (a, b) = (Patch::whole(&base)?, Patch::whole(&cone)?);
/// let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?.value / a.area(16)?;
/// assert!((f - 1.0).abs() < 1e-11);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cone<T> {
    pub(crate) base: Vec3<T>,
    pub(crate) frame: Frame<T>,
    pub(crate) base_radius: T,
    pub(crate) top_radius: T,
    pub(crate) height: T,
    pub(crate) side: Side,
}

impl<T: Real> Cone<T> {
    /// A frustum; `Err` for non-finite input, a zero axis, a negative radius, both radii zero, or
    /// height ≤ 0.
    pub fn new(
        base: Vec3<T>,
        axis: Vec3<T>,
        base_radius: T,
        top_radius: T,
        height: T,
        side: Side,
    ) -> Result<Self, PdmError> {
        check_finite(&[base.x, base.y, base.z, base_radius, top_radius, height])?;
        let frame = Frame::from_axis(axis)?;
        if !(base_radius >= T::ZERO && top_radius >= T::ZERO && base_radius + top_radius > T::ZERO && height > T::ZERO)
        {
            return Err(PdmError::Degenerate);
        }
        Ok(Self { base, frame, base_radius, top_radius, height, side })
    }

    #[inline]
    fn slope(&self) -> T {
        (self.top_radius - self.base_radius) / self.height
    }
}

impl<T: Real> ParametricMap<T> for Cone<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::TWO * T::PI, s0: T::ZERO, s1: self.height }
    }
    fn map<S: Scalar<T>>(&self, theta: S, z: S) -> Vec3<S> {
        let r = S::constant(self.base_radius) + S::constant(self.slope()) * z;
        lift::<T, S>(self.base) + self.frame.combine(r * theta.cos(), r * theta.sin(), z)
    }
    fn flipped(&self) -> bool {
        self.side == Side::Inner
    }
}

impl<T: Real> Surface<T> for Cone<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    fn point(&self, theta: T, z: T) -> Vec3<T> {
        self.map(theta, z)
    }
    fn normal(&self, theta: T, z: T) -> Vec3<T> {
        let k = self.slope();
        let r = self.base_radius + k * z;
        let (sin, cos) = theta.sin_cos_fast();
        let n = self.frame.combine(cos, sin, -k).scale(r);
        if self.side == Side::Inner {
            -n
        } else {
            n
        }
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        Some(super::dual_partials(self, t, s))
    }
    /// Along the circle z = s, of radius ρ = base radius + slope·z: q(θ) = base + z·axis +
    /// ρ·(cos θ·u + sin θ·w), and n = ρ·((cos θ·u + sin θ·w) − slope·axis) (ρ ≥ 0; zero at an
    /// apex). So n̂_p·(q − p) = n̂_p·(base + z·axis − p) + ρ (n̂_p·u) cos θ + ρ (n̂_p·w) sin θ,
    /// and n̂_q·(p − q) has the sign of ±(d·u cos θ + d·w sin θ − ρ − slope·(d·axis − z)),
    /// d = p − base.
    #[cfg(feature = "closed-form")]
    fn facing_along_t(&self, z: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        let (u, w, axis) = (self.frame.u, self.frame.w, self.frame.axis);
        let slope = self.slope();
        let rho = self.base_radius + slope * z;
        let d = p - self.base;
        let from_p = [np.dot(self.base + axis.scale(z) - p), rho * np.dot(u), rho * np.dot(w)];
        let from_q = [-rho - slope * (d.dot(axis) - z), d.dot(u), d.dot(w)];
        let from_q = if self.side == Side::Inner { from_q.map(|x| -x) } else { from_q };
        Some([from_p, from_q])
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::vec3::vec3;

    #[cfg(feature = "closed-form")]
    #[test]
    fn facing_along_t_has_the_signs_of_the_facing_tests() {
        for side in [Side::Outer, Side::Inner] {
            // A cone to its apex, a frustum widening upwards and one narrowing.
            for (r0, r1) in [(1.2, 0.0), (0.3, 1.1), (0.9, 0.4)] {
                let c = Cone::new(vec3(0.5, 0.0, -1.0), vec3(0.0, 1.0, 1.0), r0, r1, 2.0, side).unwrap();
                assert!(facing_along_t_matches(c, 4.0, 3000) > 11_000);
            }
        }
    }

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        for side in [Side::Outer, Side::Inner] {
            let c = Cone::new(vec3(0.5, 0.0, -1.0), vec3(0.0, 1.0, 1.0), 1.2, 0.0, 2.0, side).unwrap();
            closed_form_matches_auto(&c, 1e-14);
            normal_matches_finite_differences(&c, 1e-8);
            let f = Cone::new(vec3(0.5, 0.0, -1.0), vec3(0.0, 1.0, 1.0), 0.3, 1.1, 2.0, side).unwrap();
            closed_form_matches_auto(&f, 1e-14);
        }
    }

    #[test]
    fn bad_input() {
        let z = vec3(0.0, 0.0, 1.0);
        let o = vec3(0.0, 0.0, 0.0);
        assert_eq!(Cone::new(o, z, 0.0, 0.0, 1.0, Side::Outer), Err(PdmError::Degenerate));
        assert_eq!(Cone::new(o, z, -1.0, 1.0, 1.0, Side::Outer), Err(PdmError::Degenerate));
        assert_eq!(Cone::new(o, z, 1.0, 1.0, 0.0, Side::Outer), Err(PdmError::Degenerate));
    }
}
