//! Fixed-order Gauss–Legendre rules on [−1, 1], orders 1 to [`MAX_ORDER`].
//!
//! An n-point rule integrates every polynomial of degree ≤ 2n − 1 exactly (up to rounding); on
//! an integrand analytic in a Bernstein ellipse of parameter ρ around [−1, 1] the error falls like
//! ρ^(−2n). The nodes and weights live in the generated file `gauss_tables.rs`: bit-exact
//! (correctly rounded) for f64, and correctly rounded from the high-precision value for f32 (not
//! rounded through f64). The host test `gauss_tables_are_bit_exact` in `pdm-host` regenerates them
//! with multi-precision arithmetic and fails if any bit differs.
//!
//! Nodes are stored sorted ascending; node k and node n−1−k are negatives of each other.
//!
//! **What a build links.** Each order and width has its own statics. [`GaussRule::new`] takes the
//! order at run time and therefore links the tables of every order (4.2 KB in f32, 8.4 KB in f64);
//! [`GaussRule::fixed`] takes it at compile time and links that order's 2·n values only (40 B for
//! order 5 in f32), and [`GaussRule::new_up_to`] takes a run-time order up to a compile-time
//! bound and links orders 1..=bound. The rules are the same bits whichever way they are built.

use crate::gauss_tables as tables;

use core::any::Any;

use crate::error::PdmError;
use crate::real::Real;

/// The largest tabulated order (number of points per axis).
pub const MAX_ORDER: usize = tables::MAX_ORDER;

/// A validated Gauss–Legendre rule: an order in `1..=MAX_ORDER` and its table.
///
/// Construct with [`GaussRule::new`]; an order outside the table is an [`PdmError::UnsupportedOrder`].
#[derive(Clone, Copy, Debug)]
pub struct GaussRule<T: Real> {
    nodes: &'static [T],
    weights: &'static [T],
}

impl<T: Real> GaussRule<T> {
    /// The n-point rule, or `Err(UnsupportedOrder)` if `order` is 0 or above [`MAX_ORDER`].
    pub fn new(order: usize) -> Result<Self, PdmError> {
        match T::gauss_table(order) {
            Some((nodes, weights)) => Ok(Self { nodes, weights }),
            None => Err(PdmError::UnsupportedOrder { order }),
        }
    }

    /// The N-point rule, N checked at compile time (`1 ≤ N ≤ MAX_ORDER`, else the build fails).
    /// Links only order N's table (2·N values), not the tables of every order as
    /// [`GaussRule::new`] does: for firmware that uses one order.
    ///
    /// ```
    /// use pdm_kernel::GaussRule;
    /// let rule = GaussRule::<f32>::fixed::<5>();
    /// assert_eq!(rule.order(), 5);
    /// assert_eq!(rule.nodes(), GaussRule::<f32>::new(5)?.nodes());
    /// # Ok::<(), pdm_kernel::PdmError>(())
    /// ```
    ///
    /// ```compile_fail
    /// let rule = pdm_kernel::GaussRule::<f32>::fixed::<0>(); // order 0: a build error
    /// ```
    #[inline(always)]
    #[must_use]
    pub fn fixed<const N: usize>() -> Self {
        const {
            assert!(N >= 1 && N <= tables::MAX_ORDER, "Gauss order must be in 1..=MAX_ORDER");
        }
        let (nodes, weights) = of_width::<T>(tables::fixed_f32::<N>, tables::fixed_f64::<N>);
        Self { nodes, weights }
    }

    /// The n-point rule for a run-time `order` in `1..=MAX` (`MAX ≤ MAX_ORDER`, checked at compile
    /// time), `Err(UnsupportedOrder)` otherwise. Links the tables of orders 1..=MAX only.
    ///
    /// ```
    /// use pdm_kernel::GaussRule;
    /// assert_eq!(GaussRule::<f64>::new_up_to::<16>(8)?.weights(), GaussRule::<f64>::new(8)?.weights());
    /// assert!(GaussRule::<f64>::new_up_to::<16>(17).is_err());
    /// # Ok::<(), pdm_kernel::PdmError>(())
    /// ```
    pub fn new_up_to<const MAX: usize>(order: usize) -> Result<Self, PdmError> {
        const {
            assert!(MAX <= tables::MAX_ORDER, "MAX must not exceed MAX_ORDER");
        }
        // One match per width over the orders up to MAX (the other arms are dead code the
        // compiler drops, with their tables); the width is chosen once, outside the match.
        macro_rules! select {
            ($table:ident: $($n:literal)*) => {
                match order {
                    $($n if $n <= MAX => tables::$table::<$n>(),)*
                    _ => (&[], &[]),
                }
            };
        }
        let (nodes, weights) = of_width::<T>(
            || select!(fixed_f32: 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32),
            || select!(fixed_f64: 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32),
        );
        if nodes.is_empty() {
            return Err(PdmError::UnsupportedOrder { order });
        }
        Ok(Self { nodes, weights })
    }

    /// Number of points n.
    #[inline]
    #[must_use]
    pub fn order(&self) -> usize {
        self.nodes.len()
    }

    /// Nodes on [−1, 1], ascending.
    #[inline]
    #[must_use]
    pub fn nodes(&self) -> &'static [T] {
        self.nodes
    }

    /// Weights, summing to 2.
    #[inline]
    #[must_use]
    pub fn weights(&self) -> &'static [T] {
        self.weights
    }

    /// (node, weight) pairs.
    #[inline]
    pub fn points(&self) -> impl Iterator<Item = (T, T)> + '_ {
        self.nodes.iter().copied().zip(self.weights.iter().copied())
    }

    /// ∫ₐᵇ f(x) dx by this rule (exact for polynomials of degree ≤ 2n − 1).
    pub fn integrate(&self, a: T, b: T, mut f: impl FnMut(T) -> T) -> T {
        let half = (b - a) * T::HALF;
        let mid = (a + b) * T::HALF;
        let mut sum = T::ZERO;
        for (x, w) in self.points() {
            sum += w * f(mid + half * x);
        }
        sum * half
    }
}

/// The f32 or the f64 table as `T`'s (`Real` is sealed to these two widths). The width test is a
/// comparison of type ids that the compiler resolves, so only the matching branch, and only its
/// tables, remain in the build.
#[inline(always)]
fn of_width<T: Real>(
    f32s: impl FnOnce() -> (&'static [f32], &'static [f32]),
    f64s: impl FnOnce() -> (&'static [f64], &'static [f64]),
) -> (&'static [T], &'static [T]) {
    let mut out: Option<(&'static [T], &'static [T])> = None;
    let slot: &mut dyn Any = &mut out;
    if let Some(o) = slot.downcast_mut::<Option<(&'static [f32], &'static [f32])>>() {
        *o = Some(f32s());
    } else if let Some(o) = slot.downcast_mut::<Option<(&'static [f64], &'static [f64])>>() {
        *o = Some(f64s());
    }
    out.unwrap_or((&[], &[]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn weights_sum_to_two<T: Real>(tol: f64) {
        for n in 1..=MAX_ORDER {
            let rule = GaussRule::<T>::new(n).unwrap();
            let s: f64 = rule.weights().iter().map(|w| w.to_f64()).sum();
            assert!((s - 2.0).abs() <= tol, "order {n}: weights sum to {s}");
        }
    }

    fn nodes_symmetric_sorted<T: Real>() {
        for n in 1..=MAX_ORDER {
            let rule = GaussRule::<T>::new(n).unwrap();
            assert_eq!(rule.order(), n);
            let x = rule.nodes();
            let w = rule.weights();
            for k in 0..n {
                assert_eq!(x[k], -x[n - 1 - k], "order {n} node {k} not symmetric");
                assert_eq!(w[k], w[n - 1 - k], "order {n} weight {k} not symmetric");
                assert!(x[k] > -T::ONE && x[k] < T::ONE);
                assert!(w[k] > T::ZERO);
                if k > 0 {
                    assert!(x[k - 1] < x[k], "order {n} not sorted at {k}");
                }
            }
        }
    }

    /// ∫₋₁¹ x^d dx = 2/(d+1) for even d, 0 for odd d.
    fn exact_for_degree_2n_minus_1<T: Real>(unit_tol: f64) {
        for n in 1..=MAX_ORDER {
            // Rounding of the stored nodes perturbs x^d by about d·ε.
            let tol = unit_tol * (2 * n) as f64;
            let rule = GaussRule::<T>::new(n).unwrap();
            for d in 0..2 * n {
                let got: f64 = rule.points().map(|(x, w)| w.to_f64() * x.to_f64().powi(d as i32)).sum();
                let exact = if d % 2 == 0 { 2.0 / (d as f64 + 1.0) } else { 0.0 };
                assert!((got - exact).abs() <= tol, "order {n}, degree {d}: {got} vs {exact}");
            }
            // And the rule is not exact at degree 2n (so the test can fail): x^{2n} is off by
            // 2^{2n+1}(n!)^4/((2n+1)((2n)!)^2), which is far above rounding for small n.
            if n > 4 {
                continue;
            }
            let d = 2 * n;
            let got: f64 = rule.points().map(|(x, w)| w.to_f64() * x.to_f64().powi(d as i32)).sum();
            assert!((got - 2.0 / (d as f64 + 1.0)).abs() > tol, "order {n} exact at degree 2n?");
        }
    }

    #[test]
    fn weights_f64() {
        weights_sum_to_two::<f64>(4.0 * f64::EPSILON * 2.0 * 32.0);
    }
    #[test]
    fn weights_f32() {
        weights_sum_to_two::<f32>(2.0 * f32::EPSILON as f64 * 32.0);
    }
    #[test]
    fn symmetric_f64() {
        nodes_symmetric_sorted::<f64>();
    }
    #[test]
    fn symmetric_f32() {
        nodes_symmetric_sorted::<f32>();
    }
    #[test]
    fn polynomial_exactness_f64() {
        exact_for_degree_2n_minus_1::<f64>(8.0 * f64::EPSILON);
    }
    #[test]
    fn polynomial_exactness_f32() {
        exact_for_degree_2n_minus_1::<f32>(8.0 * f32::EPSILON as f64);
    }
    #[test]
    fn unsupported_orders_are_errors() {
        assert!(matches!(GaussRule::<f64>::new(0), Err(PdmError::UnsupportedOrder { order: 0 })));
        assert!(GaussRule::<f32>::new(MAX_ORDER + 1).is_err());
        assert!(GaussRule::<f64>::new(usize::MAX).is_err());
    }
    /// Same bits whichever constructor builds the rule, for every order and both widths.
    fn constructors_agree<T: Real>() {
        macro_rules! check {
            ($($n:literal)*) => {$(
                let by_order = GaussRule::<T>::new($n).unwrap();
                for rule in [GaussRule::<T>::fixed::<$n>(), GaussRule::<T>::new_up_to::<MAX_ORDER>($n).unwrap()] {
                    assert_eq!(rule.order(), $n);
                    assert!(core::ptr::eq(rule.nodes(), by_order.nodes()), "order {}: other nodes", $n);
                    assert!(core::ptr::eq(rule.weights(), by_order.weights()), "order {}: other weights", $n);
                }
            )*};
        }
        check!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32);
        assert_eq!(MAX_ORDER, 32);
        for n in 0..=MAX_ORDER + 1 {
            let bounded = GaussRule::<T>::new_up_to::<5>(n);
            if (1..=5).contains(&n) {
                assert_eq!(bounded.unwrap().nodes(), GaussRule::<T>::new(n).unwrap().nodes());
            } else {
                assert!(matches!(bounded, Err(PdmError::UnsupportedOrder { order }) if order == n));
            }
        }
    }
    #[test]
    fn constructors_agree_f32() {
        constructors_agree::<f32>();
    }
    #[test]
    fn constructors_agree_f64() {
        constructors_agree::<f64>();
    }
    #[test]
    fn integrate_maps_interval() {
        let r = GaussRule::<f64>::new(3).unwrap();
        // ∫_1^3 x^5 dx = (729 - 1)/6
        let v = r.integrate(1.0, 3.0, |x| x.powi(5));
        assert!((v - 728.0 / 6.0).abs() < 1e-12);
    }
}
