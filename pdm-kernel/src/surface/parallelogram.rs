//! Flat parallelograms, including the paper's plane patch, eqs. (22)–(24).

use super::{check_finite, lift, ParamRect, ParametricMap, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::{vec3, Vec3};

/// The parallelogram g(t, s) = origin + t·edge_t + s·edge_s, (t, s) ∈ [0, 1]², with the constant
/// normal n = edge_t × edge_s (its length is the area). Rectangles and squares are special cases.
///
/// ```
/// use pdm_kernel::{form_factor_between, vec3, Parallelogram, Patch, Quadrature};
/// // Unit squares 5 apart, facing each other (catalogue C-11: 1.240397731324e-2), by the paper's
/// // plain sum; the normal edge_t × edge_s says which side radiates.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let ceiling = Parallelogram::new(vec3(0.0, 0.0, 5.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let f = form_factor_between::<f64, _, _, _, 64>(
///     &Patch::whole(&floor)?, &Patch::whole(&ceiling)?, Quadrature::uniform(8), &())?;
/// assert!((f - 1.240397731324e-2).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Parallelogram<T> {
    pub(crate) origin: Vec3<T>,
    pub(crate) edge_t: Vec3<T>,
    pub(crate) edge_s: Vec3<T>,
    pub(crate) normal: Vec3<T>,
}

impl<T: Real> Parallelogram<T> {
    /// A parallelogram from a corner and its two edge vectors; it radiates towards
    /// `edge_t × edge_s`. `Err(NonFinite)` for NaN/∞, `Err(Degenerate)` for parallel or zero edges
    /// (area ≤ 2¹²·ε·|edge_t|·|edge_s|).
    pub fn new(origin: Vec3<T>, edge_t: Vec3<T>, edge_s: Vec3<T>) -> Result<Self, PdmError> {
        check_finite(&[origin.x, origin.y, origin.z, edge_t.x, edge_t.y, edge_t.z, edge_s.x, edge_s.y, edge_s.z])?;
        let normal = edge_t.cross(edge_s);
        if !normal.is_finite() {
            return Err(PdmError::NonFinite);
        }
        let area = normal.norm();
        if !(area > T::GEOMETRY_TOLERANCE * edge_t.norm() * edge_s.norm()) {
            return Err(PdmError::Degenerate);
        }
        Ok(Self { origin, edge_t, edge_s, normal })
    }

    /// The paper's plane patch, eq. (22): g(t, s) = (a(2s − 1), d, b(2t − 1)), normal (0, 4ab, 0)
    /// (eq. 24 with l = 2a = 2b), i.e. the rectangle |x| ≤ a, |z| ≤ b in the plane y = d, facing +y.
    pub fn paper_plane(a: T, b: T, d: T) -> Result<Self, PdmError> {
        Self::new(vec3(-a, d, -b), vec3(T::ZERO, T::ZERO, T::TWO * b), vec3(T::TWO * a, T::ZERO, T::ZERO))
    }

    /// The corner g(0, 0).
    #[must_use]
    pub fn origin(&self) -> Vec3<T> {
        self.origin
    }
    /// ∂g/∂t.
    #[must_use]
    pub fn edge_t(&self) -> Vec3<T> {
        self.edge_t
    }
    /// ∂g/∂s.
    #[must_use]
    pub fn edge_s(&self) -> Vec3<T> {
        self.edge_s
    }
    /// The constant normal edge_t × edge_s (length = area).
    #[must_use]
    pub fn area_normal(&self) -> Vec3<T> {
        self.normal
    }
    /// The same parallelogram radiating to the other side (t and s swapped).
    #[must_use]
    pub fn reversed(&self) -> Self {
        Self { origin: self.origin, edge_t: self.edge_s, edge_s: self.edge_t, normal: -self.normal }
    }
}

impl<T: Real> ParametricMap<T> for Parallelogram<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::ONE, s0: T::ZERO, s1: T::ONE }
    }
    fn map<S: Scalar<T>>(&self, t: S, s: S) -> Vec3<S> {
        lift::<T, S>(self.origin)
            + vec3(S::constant(self.edge_t.x) * t, S::constant(self.edge_t.y) * t, S::constant(self.edge_t.z) * t)
            + vec3(S::constant(self.edge_s.x) * s, S::constant(self.edge_s.y) * s, S::constant(self.edge_s.z) * s)
    }
}

impl<T: Real> Surface<T> for Parallelogram<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    #[inline]
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.origin + self.edge_t.scale(t) + self.edge_s.scale(s)
    }
    /// Eqs. (23)–(24): constant.
    #[inline]
    fn normal(&self, _t: T, _s: T) -> Vec3<T> {
        self.normal
    }
    #[cfg(feature = "closed-form")]
    #[inline]
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        Some((self.origin, self.edge_t, self.edge_s))
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

    #[test]
    fn paper_plane_is_eq_22_to_24() {
        let p = Parallelogram::paper_plane(3.0, 3.0, -3.0).unwrap();
        let g = p.point(0.25, 0.75);
        assert_eq!((g.x, g.y, g.z), (3.0 * (2.0 * 0.75 - 1.0), -3.0, 3.0 * (2.0 * 0.25 - 1.0)));
        assert_eq!(p.normal(0.1, 0.2), vec3(0.0, 36.0, 0.0)); // (0, l², 0), l = 6
    }

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        let p = Parallelogram::new(vec3(1.0, -2.0, 0.5), vec3(0.3, 1.0, 2.0), vec3(-1.0, 0.2, 0.7)).unwrap();
        closed_form_matches_auto(&p, 1e-15);
        normal_matches_finite_differences(&p, 1e-8);
        closed_form_matches_auto(&p.reversed(), 1e-15);
    }

    #[test]
    fn degenerate_and_non_finite() {
        let o = vec3(0.0, 0.0, 0.0);
        let e = vec3(1.0, 0.0, 0.0);
        assert_eq!(Parallelogram::new(o, e, e.scale(2.0)), Err(PdmError::Degenerate));
        assert_eq!(Parallelogram::new(o, e, vec3(0.0, 0.0, 0.0)), Err(PdmError::Degenerate));
        assert_eq!(Parallelogram::new(o, e, vec3(0.0, f64::NAN, 0.0)), Err(PdmError::NonFinite));
        assert_eq!(Parallelogram::new(o, vec3(1e300, 0.0, 0.0), vec3(0.0, 1e300, 0.0)), Err(PdmError::NonFinite));
    }
}
