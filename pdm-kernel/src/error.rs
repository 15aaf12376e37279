//! The kernel's error type: every bad input is an `Err`, never a panic or a NaN.

use core::fmt;

/// Why a kernel computation was refused.
///
/// Every public entry point validates its input and returns one of these instead of panicking or
/// returning a non-finite number.
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PdmError {
    /// A Gauss–Legendre order outside `1..=MAX_ORDER`.
    UnsupportedOrder {
        /// The order that was asked for.
        order: usize,
    },
    /// A coordinate, parameter, radius or other input was NaN or infinite, or a surface evaluated
    /// to a non-finite point or normal.
    NonFinite,
    /// A parameter interval with `start >= end` (or a zero-size subdivision).
    EmptyParameterRange,
    /// A patch or surface whose area is zero or negative (collinear edges, zero radius, a patch
    /// collapsed onto a pole…), or a shape parameter that makes the surface degenerate.
    Degenerate,
    /// A patch range that is not inside its surface's parameter domain.
    OutsideDomain,
    /// A fixed-capacity buffer (sample buffer, occluder list) is too small for the request.
    CapacityExceeded {
        /// Entries needed.
        needed: usize,
        /// Entries available.
        capacity: usize,
    },
    /// The computed form factor (or exchange) is outside what physics allows: not finite,
    /// negative, F > 1, or A_a·F_{a→b} > min(A_a, A_b) (beyond a rounding band). A quadrature
    /// rule that cannot resolve the pair (too close, too thin) gives such values; they are
    /// refused instead of returned.
    InvalidResult,
    /// The working precision cannot resolve this pair: its result would keep fewer than half
    /// the precision's digits (terms cancelling by many orders of magnitude, as for strips of
    /// extreme aspect ratio), or (with the `micromath` feature, f32) the gap between two
    /// separate patches is below the error with which its fast sine and cosine place a curved
    /// surface's points; it is refused instead of returned inexact. Use `f64` (or libm), or
    /// split the surfaces.
    Unresolvable,
    /// A setting outside its valid range (a tolerance that is not positive and finite, a
    /// maximum order the kernel cannot use, …).
    InvalidSetting {
        /// The setting.
        name: &'static str,
        /// What it must be.
        expected: &'static str,
    },
}

impl fmt::Display for PdmError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnsupportedOrder { order } => {
                write!(
                    f,
                    "unsupported Gauss-Legendre order {order} (supported: 1..={})",
                    crate::gauss_tables::MAX_ORDER
                )
            }
            Self::NonFinite => f.write_str("non-finite (NaN or infinite) input or intermediate value"),
            Self::EmptyParameterRange => f.write_str("empty parameter range (start >= end)"),
            Self::Degenerate => f.write_str("degenerate geometry (zero area or invalid shape parameter)"),
            Self::OutsideDomain => f.write_str("patch parameter range lies outside the surface's domain"),
            Self::CapacityExceeded { needed, capacity } => {
                write!(f, "fixed capacity exceeded: need {needed}, have {capacity}")
            }
            Self::InvalidResult => f.write_str(
                "form factor outside the physical bounds (not finite, F < 0, F > 1 or A_a*F_ab > min(A_a, A_b))",
            ),
            Self::Unresolvable => f.write_str(
                "the working precision cannot resolve this pair (its terms cancel by more than half the digits, or its gap is below the fast sine and cosine's error)",
            ),
            Self::InvalidSetting { name, expected } => write!(f, "invalid setting {name}: must be {expected}"),
        }
    }
}

impl core::error::Error for PdmError {}
