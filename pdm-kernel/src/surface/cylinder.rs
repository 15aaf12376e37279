//! Finite circular cylinders (open tubes).

use super::{check_finite, lift, Frame, ParamRect, ParametricMap, Side, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::Vec3;

/// The tube of radius R around the axis from `base` to `base + height·axis`:
/// g(θ, z) = base + R (cos θ · u + sin θ · w) + z · axis, θ ∈ [0, 2π] (t), z ∈ [0, h] (s).
/// Normal ∂g/∂θ × ∂g/∂z = R (cos θ · u + sin θ · w): outward for [`Side::Outer`], negated for
/// [`Side::Inner`] (the inside of a tube, which sees itself).
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, Cylinder, Disk, PairSettings, Patch, Side};
/// // A tube of radius 1 and height 1 closed by two disks: the base sees the top by C-41,
/// // (3 − √5)/2, and the inside of the wall by the rest (enclosure sum rule). The base and the
/// // wall share a curved edge (the rim).
/// let base = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0)?;
/// let wall = Cylinder::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0, 1.0, Side::Inner)?;
/// let (a, b) = (Patch::whole(&base)?, Patch::whole(&wall)?);
/// let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?.value / a.area(16)?;
/// assert!((f - (1.0 - (3.0 - 5.0_f64.sqrt()) / 2.0)).abs() < 1e-13);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cylinder<T> {
    pub(crate) base: Vec3<T>,
    pub(crate) frame: Frame<T>,
    pub(crate) radius: T,
    pub(crate) height: T,
    pub(crate) side: Side,
}

impl<T: Real> Cylinder<T> {
    /// A tube; `Err` for non-finite input, a zero axis, or radius/height ≤ 0.
    pub fn new(base: Vec3<T>, axis: Vec3<T>, radius: T, height: T, side: Side) -> Result<Self, PdmError> {
        check_finite(&[base.x, base.y, base.z, radius, height])?;
        let frame = Frame::from_axis(axis)?;
        if !(radius > T::ZERO && height > T::ZERO) {
            return Err(PdmError::Degenerate);
        }
        Ok(Self { base, frame, radius, height, side })
    }

    /// Centre of the base circle.
    #[must_use]
    pub fn base(&self) -> Vec3<T> {
        self.base
    }
    /// Unit axis.
    #[must_use]
    pub fn axis(&self) -> Vec3<T> {
        self.frame.axis
    }
    /// Radius.
    #[must_use]
    pub fn radius(&self) -> T {
        self.radius
    }
    /// Height.
    #[must_use]
    pub fn height(&self) -> T {
        self.height
    }
}

impl<T: Real> ParametricMap<T> for Cylinder<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::TWO * T::PI, s0: T::ZERO, s1: self.height }
    }
    fn map<S: Scalar<T>>(&self, theta: S, z: S) -> Vec3<S> {
        let r = S::constant(self.radius);
        lift::<T, S>(self.base) + self.frame.combine(r * theta.cos(), r * theta.sin(), z)
    }
    fn flipped(&self) -> bool {
        self.side == Side::Inner
    }
}

impl<T: Real> Surface<T> for Cylinder<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    fn point(&self, theta: T, z: T) -> Vec3<T> {
        self.map(theta, z)
    }
    fn normal(&self, theta: T, _z: T) -> Vec3<T> {
        let (sin, cos) = theta.sin_cos_fast();
        let n = self.frame.combine(cos, sin, T::ZERO).scale(self.radius);
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
    /// Along the circle z = s: q(θ) = base + z·axis + r·(cos θ·u + sin θ·w), n̂_q = ±(cos θ·u +
    /// sin θ·w). So n̂_p·(q − p) = n̂_p·(base + z·axis − p) + r (n̂_p·u) cos θ + r (n̂_p·w) sin θ,
    /// and n̂_q·(p − q) = ±(d·u cos θ + d·w sin θ − r) with d = p − base.
    #[cfg(feature = "closed-form")]
    fn facing_along_t(&self, z: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        let (u, w, axis) = (self.frame.u, self.frame.w, self.frame.axis);
        let r = self.radius;
        let d = p - self.base;
        let from_p = [np.dot(self.base + axis.scale(z) - p), r * np.dot(u), r * np.dot(w)];
        let from_q = [-r, d.dot(u), d.dot(w)];
        let from_q = if self.side == Side::Inner { from_q.map(|x| -x) } else { from_q };
        Some([from_p, from_q])
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::vec3::vec3;

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        for side in [Side::Outer, Side::Inner] {
            let c = Cylinder::new(vec3(1.0, 0.0, -1.0), vec3(1.0, 1.0, 1.0), 0.7, 2.5, side).unwrap();
            closed_form_matches_auto(&c, 1e-14);
            normal_matches_finite_differences(&c, 1e-8);
        }
    }

    #[cfg(feature = "closed-form")]
    #[test]
    fn facing_along_t_has_the_signs_of_the_facing_tests() {
        for side in [Side::Outer, Side::Inner] {
            let c = Cylinder::new(vec3(1.0, 0.0, -1.0), vec3(1.0, 1.0, 1.0), 0.7, 2.5, side).unwrap();
            assert!(facing_along_t_matches(c, 4.0, 3000) > 11_000);
        }
    }

    #[test]
    fn bad_input() {
        let z = vec3(0.0, 0.0, 1.0);
        let o = vec3(0.0, 0.0, 0.0);
        assert_eq!(Cylinder::new(o, z, 0.0, 1.0, Side::Outer), Err(PdmError::Degenerate));
        assert_eq!(Cylinder::new(o, z, 1.0, -1.0, Side::Outer), Err(PdmError::Degenerate));
        assert_eq!(Cylinder::new(o, z, f64::INFINITY, 1.0, Side::Outer), Err(PdmError::NonFinite));
    }
}
