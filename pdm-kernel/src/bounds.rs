//! The bounds physics puts on every result, checked once before a value leaves the kernel.
//!
//! A form factor lies in [0, 1], and reciprocity (A_a·F_{a→b} = A_b·F_{b→a}) then bounds the
//! exchange: 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b). A quadrature rule that cannot resolve a pair (a
//! receiver much closer than its size, a touching pair summed by the plain rule) breaks these
//! bounds long before it returns NaN, so every entry point checks them instead of returning a
//! value the physics forbids.

use crate::error::PdmError;
use crate::real::Real;

/// Relative band above the bound that is rounding, not error: 1024 ε (2.3e-13 in f64, 1.2e-4 in
/// f32). A value inside it is returned as the bound itself.
#[inline]
fn rounding_band<T: Real>() -> T {
    T::from_f64(1024.0) * T::EPSILON
}

/// `value` as an exchange A_a·F_{a→b} between patches of areas `area_a` and `area_b`:
/// `Err(InvalidResult)` unless it is finite and in [0, min(A_a, A_b)] (up to the rounding band,
/// where it is clamped to the bound). Not inlined: one copy serves every entry point (it sits in
/// the firmware's flash budget).
#[inline(never)]
pub(crate) fn exchange<T: Real>(value: T, area_a: T, area_b: T) -> Result<T, PdmError> {
    // Plain comparisons (no fmin: a library call on targets without the instruction). NaN
    // fails every comparison. The areas come from validated, finite samples.
    let bound = if area_a < area_b { area_a } else { area_b };
    if value >= T::ZERO && value <= bound * (T::ONE + rounding_band::<T>()) {
        Ok(if value < bound { value } else { bound })
    } else {
        Err(PdmError::InvalidResult)
    }
}

/// An intermediate quadrature value (a part of a sum, one of several approximations the
/// tolerance mode compares): finite, else `Err(InvalidResult)`. Its bounds are checked once,
/// on the value the entry point returns: an approximation may overshoot the bound of its own
/// part by its quadrature error while the total is right.
#[inline]
pub(crate) fn finite<T: Real>(value: T) -> Result<T, PdmError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PdmError::InvalidResult)
    }
}

/// `value` with an estimated absolute `error` as an exchange between areas `area_a`, `area_b`:
/// within `error` (plus the rounding band) of [0, min(A_a, A_b)] it is clamped into that
/// interval (which can only bring it closer to the true value, so `error` still bounds it);
/// farther out, or not finite, `Err(InvalidResult)`.
pub(crate) fn exchange_within<T: Real>(value: T, error: T, area_a: T, area_b: T) -> Result<T, PdmError> {
    let bound = if area_a < area_b { area_a } else { area_b };
    if !(error >= T::ZERO) || !error.is_finite() {
        return Err(PdmError::InvalidResult);
    }
    if value >= -error && value <= bound * (T::ONE + rounding_band::<T>()) + error {
        Ok(if value < T::ZERO {
            T::ZERO
        } else if value < bound {
            value
        } else {
            bound
        })
    } else {
        Err(PdmError::InvalidResult)
    }
}

/// `value` as a form factor: `Err(InvalidResult)` unless finite and in [0, 1] (up to the
/// rounding band, where it is clamped to 1).
pub(crate) fn form_factor<T: Real>(value: T) -> Result<T, PdmError> {
    exchange(value, T::ONE, T::ONE)
}

/// Whether a value was summed from terms over a thousand times larger: its rounding bound
/// (8 ε × the terms' magnitude) above 8000 ε of it. The quadrature error of the terms is then
/// amplified as much (the contour form on flat patches side by side, nearly in one plane).
/// Never looser than [`lost_digits`]: in f32 8000 ε (9.5e-4) is above √ε (3.5e-4), and a value
/// between the two would be neither handed to another method nor accepted.
#[cfg(feature = "closed-form")]
pub(crate) fn cancels<T: Real>(value: T, rounding: T) -> bool {
    rounding > (T::from_f64(8000.0) * T::EPSILON).min(T::EPSILON.sqrt()) * value.abs()
}

/// Whether a value has lost more than half its digits to cancellation: its rounding bound
/// above √ε of it (1.5e-8 in f64). The contour form's terms cancel so on long thin strips
/// close together.
pub(crate) fn lost_digits<T: Real>(value: T, rounding: T) -> bool {
    rounding > T::EPSILON.sqrt() * value.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_physical_range_and_refuses_the_rest() {
        assert_eq!(exchange(0.5_f64, 1.0, 2.0), Ok(0.5));
        assert_eq!(exchange(1.0_f64, 1.0, 2.0), Ok(1.0));
        assert_eq!(exchange(1.0 + 1e-14_f64, 1.0, 2.0), Ok(1.0));
        assert_eq!(exchange(1.0 + 1e-9_f64, 1.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange(2.5_f64, 3.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange(-1e-300_f64, 1.0, 1.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange(f64::NAN, 1.0, 1.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange(0.1_f64, 0.0, 1.0), Err(PdmError::InvalidResult));
        // With an error estimate: clamped within it, refused beyond it.
        assert_eq!(exchange_within(1.01_f64, 0.02, 1.0, 2.0), Ok(1.0));
        assert_eq!(exchange_within(-0.01_f64, 0.02, 1.0, 2.0), Ok(0.0));
        assert_eq!(exchange_within(1.03_f64, 0.02, 1.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange_within(-0.03_f64, 0.02, 1.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange_within(0.5_f64, f64::NAN, 1.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(exchange_within(f64::NAN, 0.1, 1.0, 2.0), Err(PdmError::InvalidResult));
        assert_eq!(form_factor(1.0 + 1e-5_f32), Ok(1.0));
        assert_eq!(form_factor(1.001_f32), Err(PdmError::InvalidResult));
    }
}
