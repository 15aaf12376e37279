//! Bicubic Bézier patches.

use super::{check_finite, ParamRect, ParametricMap, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::{vec3, Vec3};

/// The bicubic Bézier patch g(t, s) = Σᵢ Σⱼ Bᵢ(t) Bⱼ(s) P\[i\]\[j\], (t, s) ∈ [0, 1]², with the cubic
/// Bernstein polynomials Bᵢ. Normal ∂g/∂t × ∂g/∂s from the Bernstein derivatives (closed form).
/// Rows of `control` go along t, columns along s.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, BezierPatch, PairSettings, Parallelogram, Patch};
/// // A flat Bézier patch whose control net is the uniform grid of the unit square, under a
/// // parallel unit square 1 above it (catalogue C-11: 0.1998248956983874).
/// let mut net = [[vec3(0.0, 0.0, 0.0); 4]; 4];
/// for (i, row) in net.iter_mut().enumerate() {
///     for (j, p) in row.iter_mut().enumerate() {
///         *p = vec3(i as f64 / 3.0, j as f64 / 3.0, 0.0);
///     }
/// }
/// let floor = BezierPatch::new(net)?;
/// let ceiling = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (Patch::whole(&floor)?, Patch::whole(&ceiling)?);
/// let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?.value / a.area(16)?;
/// assert!((f - 0.1998248956983874).abs() < 1e-13);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BezierPatch<T> {
    pub(crate) control: [[Vec3<T>; 4]; 4],
}

/// Cubic Bernstein basis and its derivative at x.
#[inline(always)]
fn bernstein<T: Real, S: Scalar<T>>(x: S) -> [S; 4] {
    let one = S::constant(T::ONE);
    let three = S::constant(T::from_f64(3.0));
    let y = one - x;
    [y * y * y, three * x * y * y, three * x * x * y, x * x * x]
}

#[inline(always)]
fn bernstein_derivative<T: Real>(x: T) -> [T; 4] {
    let y = T::ONE - x;
    let three = T::from_f64(3.0);
    let six = T::from_f64(6.0);
    [-three * y * y, three * y * y - six * x * y, six * x * y - three * x * x, three * x * x]
}

impl<T: Real> BezierPatch<T> {
    /// A patch from its 4 × 4 control net. `Err(NonFinite)` for NaN/∞ control points. (Whether the
    /// patch has positive area is checked when a patch of it is sampled.)
    pub fn new(control: [[Vec3<T>; 4]; 4]) -> Result<Self, PdmError> {
        for row in &control {
            for p in row {
                check_finite(&[p.x, p.y, p.z])?;
            }
        }
        Ok(Self { control })
    }

    fn combine(&self, bt: [T; 4], bs: [T; 4]) -> Vec3<T> {
        let mut acc = Vec3::ZERO;
        for (row, wt) in self.control.iter().zip(bt) {
            for (p, ws) in row.iter().zip(bs) {
                acc = acc + p.scale(wt * ws);
            }
        }
        acc
    }
}

impl<T: Real> ParametricMap<T> for BezierPatch<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::ONE, s0: T::ZERO, s1: T::ONE }
    }
    fn map<S: Scalar<T>>(&self, t: S, s: S) -> Vec3<S> {
        let bt = bernstein::<T, S>(t);
        let bs = bernstein::<T, S>(s);
        let zero = S::constant(T::ZERO);
        let mut acc = vec3(zero, zero, zero);
        for (row, wt) in self.control.iter().zip(bt) {
            for (p, ws) in row.iter().zip(bs) {
                let w = wt * ws;
                acc = acc + vec3(S::constant(p.x) * w, S::constant(p.y) * w, S::constant(p.z) * w);
            }
        }
        acc
    }
}

impl<T: Real> Surface<T> for BezierPatch<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.combine(bernstein::<T, T>(t), bernstein::<T, T>(s))
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        let gt = self.combine(bernstein_derivative(t), bernstein::<T, T>(s));
        let gs = self.combine(bernstein::<T, T>(t), bernstein_derivative(s));
        gt.cross(gs)
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

    fn wavy() -> BezierPatch<f64> {
        let mut c = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in c.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                let h = [0.0, 0.8, -0.5, 0.2][(i + 2 * j) % 4];
                *p = vec3(i as f64 / 3.0, j as f64 / 3.0 * 1.5, h);
            }
        }
        BezierPatch::new(c).unwrap()
    }

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        closed_form_matches_auto(&wavy(), 1e-13);
        normal_matches_finite_differences(&wavy(), 1e-7);
    }

    #[test]
    fn flat_control_net_is_a_rectangle() {
        let mut c = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in c.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                *p = vec3(2.0 * i as f64 / 3.0, j as f64 / 3.0, 0.0);
            }
        }
        let b = BezierPatch::new(c).unwrap();
        let n = b.normal(0.3, 0.8);
        assert!((n - vec3(0.0, 0.0, 2.0)).norm() < 1e-14);
    }

    #[test]
    fn bad_input() {
        let mut c = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        c[2][1].y = f64::NAN;
        assert_eq!(BezierPatch::new(c), Err(PdmError::NonFinite));
    }
}
