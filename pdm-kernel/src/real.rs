//! The sealed floating-point trait every kernel algorithm is generic over.
//!
//! [`Real`] is implemented for `f32` and `f64` only (it is sealed): it carries the constants,
//! the elementary functions (forwarded to `math.rs`, which picks libm or micromath), the
//! Gauss–Legendre tables of the width, and the tolerances the kernel uses for that width.

use core::fmt::{Debug, Display};
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

use crate::math;

mod private {
    /// Seal: only this crate can implement [`super::Real`].
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A floating-point type the kernel computes in: `f32` or `f64`.
///
/// Sealed: the kernel's accuracy statements are made for these two widths only.
pub trait Real:
    private::Sealed
    + Copy
    + Clone
    + Debug
    + Display
    + Default
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + Send
    + Sync
    + 'static
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// 1/2.
    const HALF: Self;
    /// π.
    const PI: Self;
    /// 1/π.
    const FRAC_1_PI: Self;
    /// Machine epsilon (distance from 1 to the next larger number).
    const EPSILON: Self;
    /// Largest finite value.
    const MAX: Self;
    /// Smallest positive normal value.
    const MIN_POSITIVE: Self;
    /// Relative tolerance used to exclude the end points of a segment from occlusion tests and to
    /// decide that a length is zero relative to the patch size (≈ 2¹² ε).
    const GEOMETRY_TOLERANCE: Self;
    /// Number of mantissa bits (24 or 53); used in docs and tests.
    const MANTISSA_DIGITS: u32;
    /// Error bound of [`Self::sin_cos_fast`] (a couple of ε with libm; 2e-3 for f32 with the
    /// `micromath` feature): sample points of curved surfaces lie this far, relative to the
    /// surface's size, off their exact surface.
    const ELEMENTARY_ERROR: Self;

    /// Converts an `f64` constant to this width (rounding to nearest for `f32`).
    fn from_f64(x: f64) -> Self;
    /// Widens to `f64` (exact).
    fn to_f64(self) -> f64;
    /// Converts a small count (a loop index, an order) exactly.
    fn from_usize(n: usize) -> Self;
    /// Square root (through the math backend).
    fn sqrt(self) -> Self;
    /// Sine (through the math backend).
    fn sin(self) -> Self;
    /// Cosine (through the math backend).
    fn cos(self) -> Self;
    /// Sine and cosine together (one argument reduction with libm).
    fn sin_cos(self) -> (Self, Self);
    /// Sine and cosine of a surface parameter where a sample point or its normal is placed:
    /// micromath's approximations for f32 with the `micromath` feature (about 1e-3), else
    /// [`Self::sin_cos`]. Only the surfaces' point and normal maps call it; closed forms,
    /// events and proofs use the accurate functions.
    fn sin_cos_fast(self) -> (Self, Self);
    /// Sine of a surface parameter, as [`Self::sin_cos_fast`].
    fn sin_fast(self) -> Self;
    /// Cosine of a surface parameter, as [`Self::sin_cos_fast`].
    fn cos_fast(self) -> Self;
    /// Four-quadrant arctangent of `self / x` (through the math backend).
    fn atan2(self, x: Self) -> Self;
    /// Arctangent (through the math backend).
    fn atan(self) -> Self;
    /// Natural logarithm (through the math backend).
    fn ln(self) -> Self;
    /// Absolute value (exact).
    fn abs(self) -> Self;
    /// `true` unless NaN or ±∞.
    fn is_finite(self) -> bool;
    /// The larger of two values; NaN-ignoring like `f64::max`.
    fn max(self, other: Self) -> Self;
    /// The smaller of two values; NaN-ignoring like `f64::min`.
    fn min(self, other: Self) -> Self;
    /// The Gauss–Legendre nodes and weights of an order, or `None` outside `1..=MAX_ORDER`.
    fn gauss_table(order: usize) -> Option<(&'static [Self], &'static [Self])>;
}

/// `true` where [`Real::sin_cos_fast`] is an approximation (micromath's, f32) rather than
/// libm's: sample points of curved surfaces then lie [`Real::ELEMENTARY_ERROR`] off their
/// surface, which the pair methods refuse or allow for (`pair::backend_resolves`,
/// `adaptive::backend_allowance`).
pub(crate) fn approximate_sin_cos<T: Real>() -> bool {
    T::ELEMENTARY_ERROR > T::from_f64(16.0) * T::EPSILON
}

macro_rules! impl_real {
    ($t:ty, $nodes:ident, $weights:ident, $tol:expr, $math:ident) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TWO: Self = 2.0;
            const HALF: Self = 0.5;
            const PI: Self = core::f64::consts::PI as $t;
            const FRAC_1_PI: Self = core::f64::consts::FRAC_1_PI as $t;
            const EPSILON: Self = <$t>::EPSILON;
            const MAX: Self = <$t>::MAX;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;
            const GEOMETRY_TOLERANCE: Self = $tol;
            const MANTISSA_DIGITS: u32 = <$t>::MANTISSA_DIGITS;
            const ELEMENTARY_ERROR: Self = math::$math::ELEMENTARY_ERROR;

            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn from_usize(n: usize) -> Self {
                n as $t
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                math::$math::sqrt(self)
            }
            #[inline(always)]
            fn sin(self) -> Self {
                math::$math::sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                math::$math::cos(self)
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                math::$math::sin_cos(self)
            }
            #[inline(always)]
            fn sin_cos_fast(self) -> (Self, Self) {
                math::$math::sin_cos_fast(self)
            }
            #[inline(always)]
            fn sin_fast(self) -> Self {
                math::$math::sin_fast(self)
            }
            #[inline(always)]
            fn cos_fast(self) -> Self {
                math::$math::cos_fast(self)
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                math::$math::atan2(self, x)
            }
            #[inline(always)]
            fn atan(self) -> Self {
                math::$math::atan(self)
            }
            #[inline(always)]
            fn ln(self) -> Self {
                math::$math::ln(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                math::$math::abs(self)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$t>::max(self, other)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$t>::min(self, other)
            }
            #[inline]
            fn gauss_table(order: usize) -> Option<(&'static [Self], &'static [Self])> {
                rule_slices(&crate::gauss_tables::$nodes, &crate::gauss_tables::$weights, order)
            }
        }
    };
}

/// Order `order`'s nodes and weights out of the generated per-order index (`NODES_F32`, …:
/// entry n is order n's table); `None` outside `1..=MAX_ORDER`.
fn rule_slices<T>(
    nodes: &'static [&'static [T]],
    weights: &'static [&'static [T]],
    order: usize,
) -> Option<(&'static [T], &'static [T])> {
    if order == 0 || order > crate::gauss_tables::MAX_ORDER {
        return None;
    }
    Some((*nodes.get(order)?, *weights.get(order)?))
}

impl_real!(f32, NODES_F32, WEIGHTS_F32, 1.0e-5, f32m);
impl_real!(f64, NODES_F64, WEIGHTS_F64, 1.0e-11, f64m);

#[cfg(test)]
mod tests {
    use super::Real;

    fn constants_are_consistent<T: Real>() {
        assert!((T::PI * T::FRAC_1_PI - T::ONE).abs() <= T::EPSILON * T::TWO);
        assert_eq!(T::HALF + T::HALF, T::ONE);
        assert!(T::GEOMETRY_TOLERANCE > T::EPSILON);
        assert!(T::GEOMETRY_TOLERANCE.sqrt() < T::ONE);
    }

    #[test]
    fn constants_f32() {
        constants_are_consistent::<f32>();
    }

    #[test]
    fn constants_f64() {
        constants_are_consistent::<f64>();
    }
}
