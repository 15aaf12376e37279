//! Form factors between planar polygons by the contour (Stokes) form
//! `A₁F₁₂ = (1/2π) ∮_{C₁}∮_{C₂} ln r  dl₁·dl₂`
//! (Sparrow 1963; REFERENCES.md "Contour (Stokes) form"), which leaves only an integrable
//! logarithmic singularity where the two contours touch, so it is exact for polygons that share
//! an edge or a vertex.
//!
//! Each contour is the polygon's boundary traversed counter-clockwise seen from the side its
//! normal points to (right-hand rule). With both polygons oriented that way and their normals
//! facing each other the double contour integral is positive; this is the convention of
//! [`polygon_form_factor`] and is verified against the catalogue entries C-11 and C-14
//! (tests/reference_contour.rs).
//!
//! Evaluation, per pair of edges `x(s) = P + s·d₁`, `y(t) = Q + t·d₂` (`s, t ∈ [0,1]`), of
//! `(d₁·d₂) ∫₀¹∫₀¹ ln|x(s) − y(t)| ds dt`:
//! * perpendicular edges contribute nothing (`d₁·d₂ = 0`);
//! * close parallel edges (in particular collinear, overlapping ones, whose integrand is
//!   singular along a whole line) by the closed form
//!   `∫∫ ln r dx dy = −[K(b−d) − K(b−c) − K(a−d) + K(a−c)]` with
//!   `K(u) = ¼(u² − η²) ln(u² + η²) − ¾u² + η u atan(u/η)` (`K'' = ½ ln(u² + η²)`, `η` the
//!   distance between the two lines); for `η = 0` and identical edges this is the REFERENCES.md
//!   identity `∫₀ᴸ∫₀ᴸ ln (s − s′)² ds ds′ = L²(ln L² − 3)`. It is used only when
//!   `η² + gap² ≤ L₁L₂` (its terms are `O(η² + gap² + L²)` against a result `O(L₁L₂)`, so far
//!   apart it would cancel: at aspect 1:100 that cost 3e-13);
//! * all other pairs: the inner integral in closed form,
//!   `∫₀¹ ln|w − t d₂| dt = [G(L − t₀) − G(−t₀)]/(2L)`, `G(u) = u ln(u² + η²) − 2u + 2η atan(u/η)`,
//!   and the outer one by recursive adaptive Gauss–Legendre (own nodes; tolerance 1e-16 times
//!   the length, rounding floor 8ε∫|g|), split at the point of closest approach of the two
//!   lines and where the foot of `x(s)` passes the ends of segment 2. Edges sharing an endpoint
//!   give an `s ln s` singularity at the end of the range, resolved by the bisection.
//!
//! The geometry is translated to its centroid and scaled to unit size first (the form factor is
//! scale invariant), so the logarithms stay `O(1)`.
//!
//! Accuracy (tests/reference_contour.rs): C-11 and C-14 unit squares to ≤ 3e-16 relative; C-14
//! at aspect ratios 1:100 (either way) and 100:1 to ≤ 1e-14; two unit squares sharing an edge at
//! dihedral angles 0.01°…179.99° agree with 20-digit mpmath evaluations of the same contour
//! integral to ≤ 3e-16 absolute (≤ 2e-15 relative for F ≥ 1e-3; at 179°, F = 2.4e-5, the
//! `O(1)` terms of the contour sum cancel and the relative error is ~4e-12, i.e. 1e-16
//! absolute). Polygons must see each other entirely (no horizon clipping, no occlusion).

use super::quadrature::GaussLegendre;
use super::vector::{add, axpy, cross, dot, norm, scale, sub, V3};
use std::f64::consts::PI;

/// Area of a planar polygon (Newell's formula: half the length of `Σ vᵢ × vᵢ₊₁`).
/// Vertices in order; at least three; returns 0 for fewer.
pub fn polygon_area(p: &[[f64; 3]]) -> f64 {
    if p.len() < 3 {
        return 0.0;
    }
    0.5 * norm(newell(p))
}

/// Unnormalised Newell normal `Σ vᵢ × vᵢ₊₁` (length = twice the area, direction by right hand).
fn newell(p: &[[f64; 3]]) -> V3 {
    let mut n = [0.0; 3];
    for (a, b) in edges(p) {
        n = add(n, cross(a, b));
    }
    n
}

/// Consecutive vertex pairs, closing the polygon.
fn edges(p: &[[f64; 3]]) -> impl Iterator<Item = (V3, V3)> + '_ {
    p.iter().copied().zip(p.iter().copied().cycle().skip(1))
}

/// Form factor `F₁₂` from planar polygon 1 to planar polygon 2 (two arbitrary planar polygons
/// in 3-D, any orientation, possibly sharing an edge or a vertex), by the contour form.
///
/// Vertices counter-clockwise seen from the side the normal points to. The polygons must be
/// fully visible to each other (each lies entirely in front of the other's plane; no
/// occlusion): the contour form does not clip at the horizon. Returns NaN for a polygon with
/// fewer than 3 vertices or zero area.
///
/// Accuracy about 1e-14 relative on the catalogue cases (see the module documentation).
pub fn polygon_form_factor(p1: &[[f64; 3]], p2: &[[f64; 3]]) -> f64 {
    if p1.len() < 3 || p2.len() < 3 {
        return f64::NAN;
    }
    // Normalise: centroid of all vertices to the origin, largest distance to 1.
    let count = (p1.len() + p2.len()) as f64;
    let mut centroid = [0.0; 3];
    for v in p1.iter().chain(p2.iter()) {
        centroid = add(centroid, *v);
    }
    centroid = scale(centroid, 1.0 / count);
    let mut size: f64 = 0.0;
    for v in p1.iter().chain(p2.iter()) {
        size = size.max(norm(sub(*v, centroid)));
    }
    if !(size > 0.0 && size.is_finite()) {
        return f64::NAN;
    }
    let normalise = |p: &[[f64; 3]]| -> Vec<V3> { p.iter().map(|v| scale(sub(*v, centroid), 1.0 / size)).collect() };
    let q1 = normalise(p1);
    let q2 = normalise(p2);
    let a1 = polygon_area(&q1);
    if a1 <= 0.0 {
        return f64::NAN;
    }
    contour_integral(&q1, &q2) / (2.0 * PI * a1)
}

/// `∮∮ ln r dl₁·dl₂` summed over all edge pairs.
fn contour_integral(p1: &[V3], p2: &[V3]) -> f64 {
    let rule = GaussLegendre::new(10);
    let mut total = 0.0;
    for (a0, a1) in edges(p1) {
        let d1 = sub(a1, a0);
        for (b0, b1) in edges(p2) {
            let d2 = sub(b1, b0);
            let dd = dot(d1, d2);
            let n12 = norm(d1) * norm(d2);
            if n12 == 0.0 || dd.abs() <= 1e-15 * n12 {
                continue;
            }
            total += dd * edge_pair_log_integral(&rule, a0, d1, b0, d2);
        }
    }
    total
}

/// `∫₀¹∫₀¹ ln|P + s·d₁ − Q − t·d₂| ds dt` for two segments in 3-D.
pub(crate) fn edge_pair_log_integral(rule: &GaussLegendre, p: V3, d1: V3, q: V3, d2: V3) -> f64 {
    let l1 = norm(d1);
    let l2 = norm(d2);
    if l1 == 0.0 || l2 == 0.0 {
        return 0.0;
    }
    let e2 = scale(d2, 1.0 / l2);
    let w0 = sub(p, q);
    let parallel = norm(cross(d1, d2)) <= 1e-13 * l1 * l2;
    if parallel {
        let xa0 = dot(w0, e2);
        let xb0 = xa0 + dot(d1, e2);
        let (xa, xb) = if xa0 <= xb0 { (xa0, xb0) } else { (xb0, xa0) };
        let eta = norm(cross(w0, e2));
        let gap = (xa - l2).max(-xb).max(0.0);
        // Close parallel segments (collinear and overlapping in particular, where the
        // integrand is singular along a line): the closed form. Its four K terms are
        // O(η² + gap² + L²) against a result O(L₁L₂), so it is used only where they are
        // comparable; farther apart the inner closed form with the adaptive outer rule below is
        // used (smooth there).
        if eta * eta + gap * gap <= l1 * l2 && xb > xa {
            let val =
                -(k_parallel(xb - l2, eta) - k_parallel(xb, eta) - k_parallel(xa - l2, eta) + k_parallel(xa, eta));
            return val / ((xb - xa) * l2);
        }
    }
    // Inner integral in closed form, outer adaptive.
    let mut g = |s: f64| {
        let w = sub(axpy(p, s, d1), q);
        let t0 = dot(w, e2);
        let eta = norm(cross(w, e2));
        (g_anti(l2 - t0, eta) - g_anti(-t0, eta)) / (2.0 * l2)
    };
    let mut splits = Vec::with_capacity(5);
    // closest approach of the two lines: minimise |w0 + s d1 − t d2|
    let a = dot(d1, d1);
    let b = dot(d1, d2);
    let cc = dot(d2, d2);
    let d = dot(d1, w0);
    let e = dot(d2, w0);
    let den = a * cc - b * b;
    if !parallel && den > 0.0 {
        splits.push((b * e - cc * d) / den);
    }
    // where the foot of x(s) on line 2 passes the ends of segment 2 (near-singular points when
    // the segments are nearly collinear)
    let de = dot(d1, e2);
    if de != 0.0 {
        let x0 = dot(w0, e2);
        splits.push(-x0 / de);
        splits.push((l2 - x0) / de);
    }
    // interior split points only (the ends 0 and 1 are always kept exactly)
    splits.retain(|s| s.is_finite() && *s > 1e-12 && *s < 1.0 - 1e-12);
    splits.push(0.0);
    splits.push(1.0);
    splits.sort_by(f64::total_cmp);
    splits.dedup_by(|x, y| (*x - *y).abs() <= 1e-12);
    let mut total = 0.0;
    for w in splits.windows(2) {
        if let [lo, hi] = *w {
            if hi > lo {
                let tol = 1e-16 * (hi - lo);
                total += rule.adaptive(lo, hi, tol, 70, &mut g).0;
            }
        }
    }
    total
}

/// `K(u)` with `K''(u) = ½ ln(u² + η²)` (constant term dropped).
fn k_parallel(u: f64, eta: f64) -> f64 {
    let r2 = u * u + eta * eta;
    if r2 == 0.0 {
        return 0.0;
    }
    let at = if eta == 0.0 { 0.0 } else { eta * u * (u / eta).atan() };
    0.25 * (u * u - eta * eta) * r2.ln() - 0.75 * u * u + at
}

/// `G(u) = ∫ ln(u² + η²) du = u ln(u² + η²) − 2u + 2η atan(u/η)`.
fn g_anti(u: f64, eta: f64) -> f64 {
    let r2 = u * u + eta * eta;
    if r2 == 0.0 {
        return 0.0;
    }
    let lg = if u == 0.0 { 0.0 } else { u * r2.ln() };
    let at = if eta == 0.0 { 0.0 } else { 2.0 * eta * (u / eta).atan() };
    lg - 2.0 * u + at
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn k_second_derivative_is_half_log() {
        for &(u, eta) in &[(0.7, 0.3), (-1.2, 0.05), (2.0, 0.0), (0.3, 1.5)] {
            let h: f64 = 1e-3;
            let d2 = (k_parallel(u + h, eta) - 2.0 * k_parallel(u, eta) + k_parallel(u - h, eta)) / (h * h);
            let expect = 0.5 * (u * u + eta * eta).ln();
            assert!((d2 - expect).abs() < 1e-5, "{u} {eta} {d2} {expect}");
        }
    }

    #[test]
    fn collinear_identity() {
        // ∫₀ᴸ∫₀ᴸ ln (s − s′)² = L² (ln L² − 3) ⇒ ∫₀¹∫₀¹ ln|..| ds dt = (ln L² − 3)/2
        let rule = GaussLegendre::new(10);
        let l: f64 = 1.7;
        let v = edge_pair_log_integral(&rule, [0.0; 3], [l, 0.0, 0.0], [0.0; 3], [l, 0.0, 0.0]);
        assert!((v - 0.5 * ((l * l).ln() - 3.0)).abs() < 1e-15);
        // a slightly tilted (non-parallel) pair sharing its start vertex agrees with brute force
        let v2 = edge_pair_log_integral(&rule, [0.0; 3], [1.0, 0.0, 0.0], [0.0; 3], [0.6, 0.8, 0.0]);
        let g = GaussLegendre::new(10);
        let (brute, _) = g.adaptive(0.0, 1.0, 1e-14, 60, &mut |s: f64| {
            g.adaptive(0.0, 1.0, 1e-14, 60, &mut |t: f64| {
                let x = [s - 0.6 * t, -0.8 * t, 0.0];
                norm(x).max(1e-300).ln()
            })
            .0
        });
        assert!((v2 - brute).abs() < 1e-11, "{v2} {brute}");
    }
}
