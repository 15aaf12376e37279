//! Quadrature rules of the reference module (no code shared with `pdm-kernel`): the
//! Gauss–Legendre nodes and weights come from the `gauss-quad` crate (Bogaert's method, with its
//! tabulated values for orders ≤ 100); on top of them, written here, the cosine-mapped Gauss
//! rule for integrands with square-root end behaviour, a recursive adaptive rule that compares a
//! Gauss rule on an interval with the same rule on its two halves, and a rule graded towards
//! singular points.

use std::f64::consts::PI;
use std::num::NonZeroUsize;

/// An `n`-point Gauss–Legendre rule on `[-1, 1]`.
#[derive(Debug, Clone)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// The nodes (roots of `P_n`, ascending) and weights of `gauss_quad::legendre::GaussLegendre`.
    /// For the orders 1..=64, measured against the 320-bit generator of the kernel's tables in
    /// this file's tests: nodes within 4.1e-16 absolute, weights within 1 ulp of the correctly
    /// rounded values. `n = 0` is treated as `n = 1`.
    pub fn new(n: usize) -> Self {
        let n = NonZeroUsize::new(n).unwrap_or(NonZeroUsize::MIN);
        let rule = gauss_quad::legendre::GaussLegendre::new(n);
        let (nodes, weights) = rule.into_node_weight_pairs().iter().copied().unzip();
        Self { nodes, weights }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Always false (a rule has at least one point).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Nodes and weights on `[-1, 1]`.
    pub fn iter(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.nodes.iter().copied().zip(self.weights.iter().copied())
    }

    /// `∫_a^b f(x) dx` by the plain rule.
    pub fn integrate<F: FnMut(f64) -> f64>(&self, a: f64, b: f64, mut f: F) -> f64 {
        let c = 0.5 * (a + b);
        let h = 0.5 * (b - a);
        let mut sum = 0.0;
        for (x, w) in self.iter() {
            sum += w * f(c + h * x);
        }
        sum * h
    }

    /// `∫_a^b f(x) dx` after the substitution `x = (a+b)/2 − (b−a)/2 · cos θ`, `θ ∈ [0, π]`,
    /// with the Gauss rule in `θ`. Functions of the form `A(x) + √(x−a)·B(x) + √(b−x)·C(x)` with
    /// analytic `A, B, C` become analytic in `θ`, so the rule converges exponentially on them.
    pub fn integrate_cos<F: FnMut(f64) -> f64>(&self, a: f64, b: f64, mut f: F) -> f64 {
        let c = 0.5 * (a + b);
        let h = 0.5 * (b - a);
        let mut sum = 0.0;
        for (x, w) in self.iter() {
            let theta = 0.5 * PI * (x + 1.0);
            sum += w * theta.sin() * f(c - h * theta.cos());
        }
        sum * h * 0.5 * PI
    }

    /// `(∫_a^b f, ∫_a^b |f|)` by the plain rule (the second for the rounding floor).
    fn integrate_with_abs<F: FnMut(f64) -> f64>(&self, a: f64, b: f64, f: &mut F) -> (f64, f64) {
        let c = 0.5 * (a + b);
        let h = 0.5 * (b - a);
        let mut sum = 0.0;
        let mut sum_abs = 0.0;
        for (x, w) in self.iter() {
            let v = f(c + h * x);
            sum += w * v;
            sum_abs += w * v.abs();
        }
        (sum * h, sum_abs * h.abs())
    }

    /// Recursive adaptive integration of `f` on `[a, b]`: the rule on an interval is compared
    /// with the rule on its two halves; an interval is accepted when the difference is below its
    /// share `tol·(length fraction)` of the absolute tolerance, or below the rounding floor
    /// `8 ε ∫|f|` of the interval, or at `max_depth`; at most `2^16` intervals are refined in
    /// total (a guard against unattainable tolerances). Returns the sum of the accepted
    /// half-interval values and the sum of the differences (a conservative error estimate: the
    /// accepted value is the finer of the two).
    pub fn adaptive<F: FnMut(f64) -> f64>(&self, a: f64, b: f64, tol: f64, max_depth: u32, f: &mut F) -> (f64, f64) {
        let whole = self.integrate_with_abs(a, b, f).0;
        let mut budget: u32 = 1 << 16;
        self.adaptive_rec(a, b, whole, tol, max_depth, &mut budget, f)
    }

    #[allow(clippy::too_many_arguments)]
    fn adaptive_rec<F: FnMut(f64) -> f64>(
        &self,
        a: f64,
        b: f64,
        whole: f64,
        tol: f64,
        depth: u32,
        budget: &mut u32,
        f: &mut F,
    ) -> (f64, f64) {
        let m = 0.5 * (a + b);
        let (left, left_abs) = self.integrate_with_abs(a, m, f);
        let (right, right_abs) = self.integrate_with_abs(m, b, f);
        let diff = (whole - (left + right)).abs();
        let floor = 8.0 * f64::EPSILON * (left_abs + right_abs);
        if diff <= tol.max(floor) || depth == 0 || *budget == 0 || !(m > a && m < b) {
            return (left + right, diff);
        }
        *budget -= 1;
        let (l, el) = self.adaptive_rec(a, m, left, 0.5 * tol, depth - 1, budget, f);
        let (r, er) = self.adaptive_rec(m, b, right, 0.5 * tol, depth - 1, budget, f);
        (l + r, el + er)
    }
}

impl GaussLegendre {
    /// `∫_lo^hi f` for an `f` that is analytic except at the points `singular` (anywhere on
    /// the real line; points outside `[lo, hi]` matter when they are close), where it may
    /// behave like `|x − x₀|^{k/2}` (any integer `k ≥ 0`) or have a kink. The range is split at
    /// the interior singular points; each piece is graded geometrically towards an end that has
    /// another singular point closer outside it than its own length (sub-pieces of length equal
    /// to their distance from that point), and each sub-piece is integrated with the
    /// cosine-mapped rule [`GaussLegendre::integrate_cos`]. Singular points closer than
    /// `1e-7·(hi − lo)` are merged. The list is sorted in place.
    pub fn integrate_graded<F: FnMut(f64) -> f64>(&self, lo: f64, hi: f64, singular: &mut Vec<f64>, mut f: F) -> f64 {
        if !(hi > lo) {
            return 0.0;
        }
        // Singular points closer than `cluster` are one point: double roots computed from
        // rounded coefficients split by ~√ε, and grading towards such a partner would only
        // cost time (a singularity `d` outside a piece end costs ~d^{3/2}·amplitude at worst).
        let cluster = 1e-7 * (hi - lo);
        let tiny = 1e-13 * (hi - lo);
        singular.retain(|x| x.is_finite());
        singular.sort_by(f64::total_cmp);
        singular.dedup_by(|x, y| (*x - *y).abs() <= cluster);
        let mut breaks: Vec<f64> = Vec::with_capacity(singular.len() + 2);
        breaks.push(lo);
        breaks.extend(singular.iter().copied().filter(|x| *x > lo + tiny && *x < hi - tiny));
        breaks.push(hi);
        let mut total = 0.0;
        for w in breaks.windows(2) {
            let [a, b] = *w else { continue };
            let len = b - a;
            // nearest singular points strictly outside the piece
            let d_left = singular.iter().filter(|x| **x < a - tiny).map(|x| a - *x).fold(f64::INFINITY, f64::min);
            let d_right = singular.iter().filter(|x| **x > b + tiny).map(|x| *x - b).fold(f64::INFINITY, f64::min);
            let mut cuts: Vec<f64> = Vec::new();
            let mid = 0.5 * (a + b);
            if d_left < 0.5 * len {
                let mut x = a + d_left;
                let mut step = d_left;
                for _ in 0..80 {
                    if x >= mid {
                        break;
                    }
                    cuts.push(x);
                    step *= 2.0;
                    x = a + step + (step - d_left);
                }
            }
            if d_right < 0.5 * len {
                let mut x = b - d_right;
                let mut step = d_right;
                for _ in 0..80 {
                    if x <= mid {
                        break;
                    }
                    cuts.push(x);
                    step *= 2.0;
                    x = b - step - (step - d_right);
                }
            }
            if cuts.is_empty() {
                total += self.integrate_cos(a, b, &mut f);
                continue;
            }
            cuts.push(a);
            cuts.push(b);
            cuts.sort_by(f64::total_cmp);
            for c in cuts.windows(2) {
                if let [x0, x1] = *c {
                    if x1 > x0 {
                        total += self.integrate_cos(x0, x1, &mut f);
                    }
                }
            }
        }
        total
    }
}

/// Real roots of `a x² + b x + c = 0` by the cancellation-free formula; degenerates gracefully
/// to the linear case. Returns `(count, [r0, r1])` with `r0 ≤ r1` when two.
pub fn quadratic_roots(a: f64, b: f64, c: f64) -> (usize, [f64; 2]) {
    let scale_ = a.abs().max(b.abs()).max(c.abs());
    if scale_ == 0.0 || !scale_.is_finite() {
        return (0, [0.0, 0.0]);
    }
    let (a, b, c) = (a / scale_, b / scale_, c / scale_);
    if a.abs() <= 1e-300 {
        if b.abs() <= 1e-300 {
            return (0, [0.0, 0.0]);
        }
        return (1, [-c / b, -c / b]);
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return (0, [0.0, 0.0]);
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return (1, [0.0, 0.0]);
    }
    let r0 = q / a;
    let r1 = c / q;
    if r0 <= r1 {
        (2, [r0, r1])
    } else {
        (2, [r1, r0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_and_exponentials() {
        for n in [1usize, 2, 5, 10, 20, 40, 80] {
            let g = GaussLegendre::new(n);
            let wsum: f64 = g.iter().map(|(_, w)| w).sum();
            assert!((wsum - 2.0).abs() < 1e-14, "n={n} weight sum {wsum}");
            // exact for degree 2n−1
            let deg = 2 * n - 1;
            let v = g.integrate(0.0, 1.0, |x| x.powi(deg as i32));
            assert!((v - 1.0 / (deg as f64 + 1.0)).abs() < 1e-14, "n={n}");
        }
        let g = GaussLegendre::new(20);
        let v = g.integrate(0.0, 2.0, f64::exp);
        assert!((v - (2f64.exp() - 1.0)).abs() < 1e-14);
        // sqrt end behaviour handled by the cosine map
        let v = g.integrate_cos(0.0, 1.0, |x| (x * (1.0 - x)).sqrt());
        assert!((v - PI / 8.0).abs() < 1e-15, "{v}");
    }

    #[test]
    fn graded_handles_nearby_outside_singularity() {
        let g = GaussLegendre::new(20);
        // f = (x − x0)^{3/2} on [0, 1] with x0 = −1e-9 (just outside) plus a kink at 0.5
        let x0 = -1e-9;
        let f = |x: f64| (x - x0).powf(1.5) + (x - 0.5).abs();
        let exact = (2.0 / 5.0) * ((1.0 - x0).powf(2.5) - (-x0).powf(2.5)) + 0.25;
        let v = g.integrate_graded(0.0, 1.0, &mut vec![x0, 0.5], f);
        assert!((v - exact).abs() < 1e-15, "{v} {exact}");
    }

    #[test]
    fn adaptive_handles_log_endpoint() {
        let g = GaussLegendre::new(10);
        let (v, e) = g.adaptive(0.0, 1.0, 1e-15, 80, &mut |x: f64| if x > 0.0 { x.ln() } else { 0.0 });
        assert!((v + 1.0).abs() < 1e-14, "{v} {e}");
    }
}

/// `gauss-quad`'s rules against the kernel table generator's 320-bit Newton values
/// ([`crate::gauss_gen`], host code that the reference only meets here, in a test).
#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod against_the_generator {
    use super::GaussLegendre;
    use crate::gauss_gen::{exact, exact_f64, hp_rule, round_to_f64};
    use dashu_int::ops::Abs;

    /// The orders the reference uses: up to `cube::MAX_ORDER` = 64 (also the generator's limit).
    const ORDERS: std::ops::RangeInclusive<usize> = 1..=64;

    /// Measured: nodes within 4.1e-16 absolute (1.9 ε; in the negative half, which `gauss-quad`
    /// computes as cos(π − θ); the positive half within 1.5e-16), weights within 1.6e-16
    /// relative and at most 1 ulp from the correctly rounded values. The hand-written Newton
    /// rule this replaced had nodes within 1.1e-16 but weights up to 9.3e-14 relative (762 ulp).
    #[test]
    fn gauss_quad_rules_are_within_a_few_ulp_of_the_320_bit_reference() {
        // largest node error (absolute), weight error (relative), weight distance in ulp
        let (mut node, mut weight, mut ulps) = (0.0_f64, 0.0_f64, 0_u64);
        for n in ORDERS {
            let hp = hp_rule(n).unwrap();
            let bits = hp.precision;
            let rule = GaussLegendre::new(n);
            assert_eq!(rule.len(), n, "order {n}");
            assert!(rule.nodes.windows(2).all(|p| p[0] < p[1]), "order {n}: nodes not ascending");
            for ((x, w), (hx, hw)) in rule.iter().zip(hp.nodes.iter().zip(&hp.weights)) {
                node = node.max((exact_f64(x).unwrap() - exact(hx)).abs().to_f64().value());
                let relative = (exact_f64(w).unwrap() - exact(hw)).abs().to_f64().value() / hw.to_f64().value();
                weight = weight.max(relative);
                ulps = ulps.max(w.to_bits().abs_diff(round_to_f64(hw, bits).unwrap().to_bits()));
            }
        }
        println!("gauss-quad, orders 1..=64: nodes within {node:.2e} absolute, weights within {weight:.2e} relative ({ulps} ulp)");
        assert!(node <= 3.0 * f64::EPSILON, "node error {node:e}");
        assert!(weight <= f64::EPSILON, "weight error {weight:e}");
        assert!(ulps <= 1, "a weight {ulps} ulp from the correctly rounded value");
    }
}
