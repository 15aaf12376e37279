//! Flat disks and annuli.

use super::{check_finite, lift, Frame, ParamRect, ParametricMap, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::Vec3;

/// The annulus r_in ≤ r ≤ r_out (a disk when r_in = 0) in the plane through `center` normal to
/// `frame.axis`: g(r, θ) = c + r (cos θ · u + sin θ · w), r ∈ [r_in, r_out] (t), θ ∈ [0, 2π] (s).
/// Normal ∂g/∂r × ∂g/∂θ = r · axis (zero at the centre of a full disk), so the disk radiates
/// towards `axis`; use [`Flipped`](super::Flipped) or a reversed axis for the other side.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, ParamRect, Patch};
/// // Two coaxial unit disks 1 apart facing each other (catalogue C-41: (3 − √5)/2).
/// let lower = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0)?;
/// let upper = Disk::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, -1.0), 1.0)?;
/// let (a, b) = (Patch::whole(&lower)?, Patch::whole(&upper)?);
/// let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?.value / a.area(16)?;
/// assert!((f - (3.0 - 5.0_f64.sqrt()) / 2.0).abs() < 1e-13);
/// // Half of the lower disk (θ ∈ [0, π]) sees the upper one alike, by symmetry.
/// let half = Patch::new(&lower, ParamRect::new(0.0, 1.0, 0.0, core::f64::consts::PI)?)?;
/// let g = pair_exchange::<f64, _, _, _, 256>(&half, &b, PairSettings::ACCURATE, &())?.value / half.area(16)?;
/// assert!((g - f).abs() < 1e-13);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Disk<T> {
    pub(crate) center: Vec3<T>,
    pub(crate) frame: Frame<T>,
    pub(crate) inner_radius: T,
    pub(crate) outer_radius: T,
}

impl<T: Real> Disk<T> {
    /// A full disk of radius `radius` radiating towards `axis`.
    pub fn new(center: Vec3<T>, axis: Vec3<T>, radius: T) -> Result<Self, PdmError> {
        Self::annulus(center, axis, T::ZERO, radius)
    }

    /// An annulus. `Err` for non-finite input, a zero axis, `inner < 0` or `outer <= inner`.
    pub fn annulus(center: Vec3<T>, axis: Vec3<T>, inner: T, outer: T) -> Result<Self, PdmError> {
        check_finite(&[center.x, center.y, center.z, inner, outer])?;
        let frame = Frame::from_axis(axis)?;
        if !(inner >= T::ZERO && outer > inner) {
            return Err(PdmError::Degenerate);
        }
        Ok(Self { center, frame, inner_radius: inner, outer_radius: outer })
    }

    /// Centre.
    #[must_use]
    pub fn center(&self) -> Vec3<T> {
        self.center
    }
    /// Unit normal (radiating direction).
    #[must_use]
    pub fn axis(&self) -> Vec3<T> {
        self.frame.axis
    }
    /// Inner radius (0 for a disk).
    #[must_use]
    pub fn inner_radius(&self) -> T {
        self.inner_radius
    }
    /// Outer radius.
    #[must_use]
    pub fn outer_radius(&self) -> T {
        self.outer_radius
    }
}

impl<T: Real> ParametricMap<T> for Disk<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: self.inner_radius, t1: self.outer_radius, s0: T::ZERO, s1: T::TWO * T::PI }
    }
    fn map<S: Scalar<T>>(&self, r: S, theta: S) -> Vec3<S> {
        lift::<T, S>(self.center) + self.frame.combine(r * theta.cos(), r * theta.sin(), S::constant(T::ZERO))
    }
}

impl<T: Real> Surface<T> for Disk<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    fn point(&self, r: T, theta: T) -> Vec3<T> {
        self.map(r, theta)
    }
    fn normal(&self, r: T, _theta: T) -> Vec3<T> {
        self.frame.axis.scale(r)
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        Some(super::dual_partials(self, t, s))
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::vec3::vec3;

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        let d = Disk::annulus(vec3(1.0, 2.0, 3.0), vec3(0.2, -1.0, 0.4), 0.5, 2.0).unwrap();
        closed_form_matches_auto(&d, 1e-14);
        normal_matches_finite_differences(&d, 1e-8);
        let full = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, -1.0), 1.0).unwrap();
        closed_form_matches_auto(&full, 1e-14);
        assert!(full.normal(0.5, 0.3).z < 0.0);
    }

    #[test]
    fn bad_input() {
        let c = vec3(0.0, 0.0, 0.0);
        let z = vec3(0.0, 0.0, 1.0);
        assert_eq!(Disk::new(c, z, 0.0), Err(PdmError::Degenerate));
        assert_eq!(Disk::annulus(c, z, 2.0, 1.0), Err(PdmError::Degenerate));
        assert_eq!(Disk::new(c, vec3(0.0, 0.0, 0.0), 1.0), Err(PdmError::Degenerate));
        assert_eq!(Disk::new(c, z, f64::NAN), Err(PdmError::NonFinite));
    }
}
