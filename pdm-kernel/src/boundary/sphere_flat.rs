//! A sphere's cell outside against a parallelogram across a sphere occluder anywhere: the
//! outer events, as sections of the cell's sphere.
//!
//! With b wholly in front of every tangent plane of the cell (p's facing test passes on all of
//! b, so the part of b that p sees is b less the occluder's shadow) and the occluder clear of
//! b's plane on b's side, the shadow on b is the cone from p tangent to the occluder (centre
//! c, radius ρ), cut by b's plane: a conic. J(p) changes its structure where
//!
//! * the shadow's outline passes a corner q of b: the segment from p to q touches the
//!   occluder, p on the cone with apex q and axis u = (c − q)/|c − q| of half-angle α,
//!   sin α = ρ/|c − q|: ((p − q)·u)² = cos²α·|p − q|². On the cell's sphere (centre C, radius
//!   R), |p − q|² = R² + |q − C|² − 2·(q − C)·(p − C) is affine in p, so the curve is L₁² = L₂
//!   with L₁, L₂ affine: a second-degree trigonometric polynomial along each t-line
//!   ([`TrigonometricEvents::push_quadratic`]; the other nappe and the part of the cone
//!   nearer q than the occluder are in it too, which costs breaks where J is smooth, not
//!   accuracy);
//! * the outline touches an edge's line (like δ^{3/2}): p on one of the two planes through
//!   that line tangent to the occluder, a plane section of the sphere;
//! * p crosses b's plane (b turns away).
//!
//! Where the cell's tangent planes can cut b, the line where they do moves across b and
//! across the shadow, and J changes its structure also where that line and the shadow's
//! outline meet on an edge of b (no curve of this kind): such pairs are declined, as are
//! occluders that reach b's plane, a corner of b or the cell.

use super::*;

/// The outer events of a cell (ball `cell`) of the sphere the surface `outer` lies on, against
/// the parallelogram with affine map `map` over `r` (unit normal `normal` towards the side it
/// radiates to), across the sphere occluder `occluder` (module docs); `None` where the surface
/// does not lie on a sphere or give its plane sections in trigonometric form, where b can
/// reach behind a tangent plane of the cell, or where the occluder comes within the rounding
/// of b's plane, one of b's corners or the cell.
pub(super) fn sphere_flat_events<T, SA>(
    outer: &SA,
    (cell_rect, ball, p_mid, n_mid): (ParamRect<T>, &Ball<T>, Vec3<T>, Vec3<T>),
    (map, r): MappedRect<T>,
    normal: Vec3<T>,
    occluder: &Ball<T>,
) -> Option<ConcentricEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
{
    let sphere = outer.on_sphere()?;
    let (big_c, big_r) = (sphere.center, sphere.radius);
    let (c, rho) = (occluder.center, occluder.radius);
    let margin = T::GEOMETRY_TOLERANCE * (big_r + rho + (c - big_c).norm());
    if !(rho > margin) {
        return None;
    }
    // The side the cell faces: out of its sphere (+1) or into it (−1).
    let side = n_mid.dot(p_mid - big_c);
    if !(side.abs() > T::ZERO) {
        return None;
    }
    let outward = side > T::ZERO;
    let corners = map_corners(map, r);
    // b in front of every tangent plane: (x − C)·(p − C) − R² > 0 (outward) or < 0 (inward)
    // for every p of the cell, at every corner x (the test is affine in x); on the sphere this
    // is a plane's test, whose extremes over the cell are in closed form (`trigonometric_least`).
    let r2 = big_r * big_r;
    for &x in &corners {
        let v = x - big_c;
        let v2 = v.dot(v);
        if !(v2 > T::ZERO) {
            return None;
        }
        let sign = if outward { T::ONE } else { -T::ONE };
        let [test, _] = outer.facing_across_s(big_c + v.scale(r2 / v2), v.scale(sign))?;
        if !(trigonometric_least(test, cell_rect) > margin * v2.sqrt()) {
            return None;
        }
    }
    let [q0, ..] = corners;
    let height = normal.dot(c - q0);
    if !((height.abs() - rho) > margin) {
        return None;
    }
    if corners.iter().any(|&q| !((q - c).norm() - rho > margin)) {
        return None;
    }
    // The occluder clear of the cell: of its whole sphere, or else of its ball.
    let from_centre = (c - big_c).norm();
    let off_sphere = from_centre - rho > big_r + margin || from_centre + rho + margin < big_r;
    if !off_sphere && !((c - ball.center).norm() - rho - ball.radius > margin) {
        return None;
    }
    let mut events = ConcentricEvents::empty();
    let section = |x0: Vec3<T>, n: Vec3<T>| -> Option<[[T; 3]; 3]> {
        let [curve, _] = outer.facing_across_s(x0, n)?;
        Some(curve)
    };
    events.push(section(q0, normal)?, false)?;
    if height < T::ZERO {
        // Behind b's plane the occluder casts no shadow on b from any p that b faces.
        return Some(events);
    }
    for q in corners {
        let v = q - c;
        let d = v.norm();
        let u = v.scale(-T::ONE / d);
        let cos2 = T::ONE - (rho / d) * (rho / d);
        let w = q - big_c;
        let w2 = w.dot(w);
        if !(w2 > T::ZERO) {
            return None;
        }
        // L₂ = cos²α·(R² + |w|² − 2 w·(p − C)) = g·(p − x₀) with g = −2cos²α·w and
        // x₀ = C + k·w, k = (R² + |w|²)/(2|w|²).
        let k = (r2 + w2) / (T::TWO * w2);
        let l2 = section(big_c + w.scale(k), w.scale(-T::TWO * cos2))?;
        events.push_quadratic(section(q, u)?, l2)?;
    }
    for (foot, n) in edge_tangent_planes(&corners, c, rho, margin, margin).into_iter().flatten() {
        events.push(section(foot, n)?, true)?;
    }
    Some(events)
}
