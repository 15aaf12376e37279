//! The one result type of the pair methods and of substructuring.

use crate::real::Real;

/// What a pair method or a substructured sum returns: the value (an exchange A_a·F_{a→b}), its
/// error estimate where the method has one, whether that estimate met the tolerance asked for,
/// and the work it took.
///
/// - The fixed-order methods ([`crate::pair_exchange`], [`crate::Method::Paper`],
///   [`crate::Method::Plain`], [`crate::Method::Pair`]) promise no accuracy: `error` is `None`
///   and `converged` is `false` (nothing was checked).
/// - The tolerance mode ([`crate::adaptive_exchange`], [`crate::Method::Tolerance`]) gives
///   `error = Some(e)`, an estimate of the absolute error that is meant never to be below it,
///   and `converged = true` only where `e ≤ absolute + tolerance·|value|` ([`crate::Adaptive`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate<T> {
    /// The value: A_a·F_{a→b} (divide by A_a, [`crate::Patch::area`] or
    /// [`crate::PatchGrid::area`], for F_{a→b}).
    pub value: T,
    /// Estimated absolute error of `value`: for a substructured sum, the sum of its pairs'
    /// estimates. `None` where the method has no estimate (the fixed-order methods).
    pub error: Option<T>,
    /// `true` only if an estimate exists and met the tolerance (every pair's estimate within
    /// the tolerance of its value, or the total estimate within the tolerance of the total).
    /// `false` for the fixed-order methods, and where the subdivision limit or the precision
    /// floor stopped the tolerance mode first: `value` is then the best the settings allow,
    /// `error` its estimate, above the tolerance.
    pub converged: bool,
    /// Integrand evaluations spent (kernel evaluations and visibility probes).
    pub evaluations: u64,
}

impl<T: Real> Estimate<T> {
    /// A value from a fixed-order method: no estimate, not converged.
    pub(crate) fn fixed(value: T, evaluations: u64) -> Self {
        Self { value, error: None, converged: false, evaluations }
    }

    /// The sum of two estimates (two parts of one exchange): values, errors (`None` unless
    /// both have one), work; converged only if both are.
    pub(crate) fn plus(self, other: Self) -> Self {
        Self {
            value: self.value + other.value,
            error: match (self.error, other.error) {
                (Some(a), Some(b)) => Some(a + b),
                _ => None,
            },
            converged: self.converged && other.converged,
            evaluations: self.evaluations.saturating_add(other.evaluations),
        }
    }
}
