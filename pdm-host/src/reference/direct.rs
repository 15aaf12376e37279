//! Deterministic reference for **unoccluded, separate, smooth** patch pairs: the 4-D form-factor
//! integral `A_a F_ab = ∫_a ∫_b (n_a·e)⁺(−n_b·e)⁺ / (π |e|⁴) db da` (`e = q − p`, `n` the
//! unnormalised radiating normals ∂g/∂t × ∂g/∂s, so the area elements are included) by tensor
//! Gauss–Legendre rules from [`super::quadrature`] (own nodes, no kernel code), on `m × m` cells
//! of each patch, raising the order 8, 12, …, 32 until two successive results agree to the
//! tolerance, and refining the cells (`m` = 1, 2, 4, 8) when they do not.
//!
//! On pairs that see each other entirely (no back-face cut across either patch) at a distance
//! comparable to their size the integrand is analytic and the convergence is exponential: the
//! returned `error` (the last difference) is then a wide bound and values reach ~1e-13. It is
//! **not** valid for touching pairs, pairs straddling a back-face cut (kinks: algebraic
//! convergence, the estimate may be optimistic) or occluded pairs.

use super::quadrature::GaussLegendre;
use super::raytrace::RtPatch;
use super::vector::{dot, norm, sub, V3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// A parametric patch: its parameter rectangle and g(t, s) with its unnormalised radiating
/// normal.
pub trait ParamSurface: Sync {
    /// `[t0, t1, s0, s1]`.
    fn rect(&self) -> [f64; 4];
    /// Point and ∂g/∂t × ∂g/∂s (radiating side).
    fn eval(&self, t: f64, s: f64) -> (V3, V3);
}

impl ParamSurface for RtPatch {
    fn rect(&self) -> [f64; 4] {
        self.rect
    }
    fn eval(&self, t: f64, s: f64) -> (V3, V3) {
        RtPatch::eval(self, t, s)
    }
}

/// A bicubic Bézier patch Σ Bᵢ(t) Bⱼ(s) P\[i\]\[j\] (rows along t) over a sub-rectangle of
/// [0, 1]², radiating towards ∂g/∂t × ∂g/∂s (the kernel's `BezierPatch` convention).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bezier {
    /// Control net.
    pub control: [[V3; 4]; 4],
    /// Parameter rectangle.
    pub rect: [f64; 4],
}

fn bernstein(x: f64) -> ([f64; 4], [f64; 4]) {
    let y = 1.0 - x;
    (
        [y * y * y, 3.0 * x * y * y, 3.0 * x * x * y, x * x * x],
        [-3.0 * y * y, 3.0 * y * y - 6.0 * x * y, 6.0 * x * y - 3.0 * x * x, 3.0 * x * x],
    )
}

impl ParamSurface for Bezier {
    fn rect(&self) -> [f64; 4] {
        self.rect
    }
    fn eval(&self, t: f64, s: f64) -> (V3, V3) {
        let (bt, dbt) = bernstein(t);
        let (bs, dbs) = bernstein(s);
        let mut p = [0.0; 3];
        let mut gt = [0.0; 3];
        let mut gs = [0.0; 3];
        for (i, row) in self.control.iter().enumerate() {
            for (j, c) in row.iter().enumerate() {
                let (wt, wdt) = (bt.get(i).copied().unwrap_or(0.0), dbt.get(i).copied().unwrap_or(0.0));
                let (ws, wds) = (bs.get(j).copied().unwrap_or(0.0), dbs.get(j).copied().unwrap_or(0.0));
                for k in 0..3 {
                    let ck = c.get(k).copied().unwrap_or(0.0);
                    if let (Some(pk), Some(tk), Some(sk)) = (p.get_mut(k), gt.get_mut(k), gs.get_mut(k)) {
                        *pk += wt * ws * ck;
                        *tk += wdt * ws * ck;
                        *sk += wt * wds * ck;
                    }
                }
            }
        }
        (p, super::vector::cross(gt, gs))
    }
}

/// A user map given as a closure returning the point and the unnormalised radiating normal.
pub struct MapSurface<F> {
    /// `(t, s) ↦ (g, ∂g/∂t × ∂g/∂s)`.
    pub map: F,
    /// Parameter rectangle.
    pub rect: [f64; 4],
}

impl<F: Fn(f64, f64) -> (V3, V3) + Sync> ParamSurface for MapSurface<F> {
    fn rect(&self) -> [f64; 4] {
        self.rect
    }
    fn eval(&self, t: f64, s: f64) -> (V3, V3) {
        (self.map)(t, s)
    }
}

/// A deterministic value with its convergence estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectEstimate {
    /// F_{a→b}.
    pub value: f64,
    /// Estimated absolute error of `value` (last order difference).
    pub error: f64,
    /// Area of a (same rule).
    pub area_a: f64,
    /// Area of b.
    pub area_b: f64,
}

/// Gauss samples (point, weighted normal) of `m × m` cells at `order` points per axis.
fn samples<S: ParamSurface + ?Sized>(s: &S, m: usize, rule: &GaussLegendre) -> Vec<(V3, V3)> {
    let [t0, t1, s0, s1] = s.rect();
    let (ht, hs) = ((t1 - t0) / m as f64, (s1 - s0) / m as f64);
    let mut out = Vec::with_capacity(m * m * rule.len() * rule.len());
    for i in 0..m {
        for j in 0..m {
            let (ct, cs) = (t0 + (i as f64 + 0.5) * ht, s0 + (j as f64 + 0.5) * hs);
            for (x, wx) in rule.iter() {
                for (y, wy) in rule.iter() {
                    let (p, n) = s.eval(ct + 0.5 * ht * x, cs + 0.5 * hs * y);
                    let w = wx * wy * 0.25 * ht * hs;
                    out.push((p, [n[0] * w, n[1] * w, n[2] * w]));
                }
            }
        }
    }
    out
}

fn exchange(a: &[(V3, V3)], b: &[(V3, V3)]) -> f64 {
    a.par_iter()
        .map(|&(p, na)| {
            let mut acc = 0.0;
            for &(q, nb) in b {
                let e = sub(q, p);
                let ca = dot(na, e);
                let cb = -dot(nb, e);
                if ca > 0.0 && cb > 0.0 {
                    let l2 = dot(e, e);
                    acc += ca * cb / (l2 * l2);
                }
            }
            acc
        })
        .sum::<f64>()
        / PI
}

/// Area of a patch, ∫|∂g/∂t × ∂g/∂s|, by a 32-point rule on 4 × 4 cells (≈ 1e-15 relative on
/// smooth patches).
pub fn patch_area<S: ParamSurface + ?Sized>(s: &S) -> f64 {
    samples(s, 4, &GaussLegendre::new(32)).iter().map(|&(_, n)| norm(n)).sum()
}

/// F_{a→b} to relative tolerance `rel_tol` (see the module docs for validity). `None` if the
/// tolerance is not reached with 8 × 8 cells at order 32 or the area is not positive.
pub fn direct_form_factor<A, B>(a: &A, b: &B, rel_tol: f64) -> Option<DirectEstimate>
where
    A: ParamSurface + ?Sized,
    B: ParamSurface + ?Sized,
{
    for m in [1usize, 2, 4, 8] {
        let mut previous: Option<f64> = None;
        for order in (8..=32).step_by(4) {
            // 8 × 8 cells only at moderate orders (≤ 4e8 pairs).
            if m == 8 && order > 20 {
                break;
            }
            let rule = GaussLegendre::new(order);
            let sa = samples(a, m, &rule);
            let sb = samples(b, m, &rule);
            let e = exchange(&sa, &sb);
            if let Some(prev) = previous {
                let err = (e - prev).abs();
                if err <= rel_tol * e.abs() {
                    let area_a: f64 = sa.iter().map(|&(_, n)| norm(n)).sum();
                    let area_b: f64 = sb.iter().map(|&(_, n)| norm(n)).sum();
                    if !(area_a > 0.0) {
                        return None;
                    }
                    return Some(DirectEstimate { value: e / area_a, error: err / area_a, area_a, area_b });
                }
            }
            previous = Some(e);
        }
    }
    None
}
