//! Root finding for the occlusion tests: real roots of quadratics without cancellation, the
//! crossings of a segment with a quadric surface (end points on the surface deflated exactly),
//! and the polynomials along a line that the closed-form visibility boundaries solve.

use super::*;

/// Passes the real roots of a·τ² + b·τ + c (a linear or constant polynomial included) to
/// `out`, in a cancellation-free form; a double root is passed once, non-finite roots never.
pub(crate) fn polynomial_roots<T: Real>(a: T, b: T, c: T, out: &mut dyn FnMut(T)) {
    let mut emit = |x: T| {
        if x.is_finite() {
            out(x);
        }
    };
    if a == T::ZERO {
        if b != T::ZERO {
            emit(-c / b);
        }
        return;
    }
    let disc = b * b - T::TWO * T::TWO * a * c;
    if disc < T::ZERO {
        return;
    }
    let q = if b >= T::ZERO { -(b + disc.sqrt()) * T::HALF } else { (disc.sqrt() - b) * T::HALF };
    if q == T::ZERO {
        emit(T::ZERO);
        return;
    }
    emit(q / a);
    if disc > T::ZERO {
        emit(c / q);
    }
}

/// (m·w)² − k·|w|² along w(τ) = w₀ + τ·d, as the coefficients (a, b, c) of a τ² + b τ + c
/// (zero where w lies on the cone of directions from p tangent to a sphere, k = |m|² − R²).
#[cfg(feature = "closed-form")]
#[inline]
pub(super) fn cone_polynomial<T: Real>(m: Vec3<T>, k: T, w0: Vec3<T>, d: Vec3<T>) -> (T, T, T) {
    let (md, mw) = (m.dot(d), m.dot(w0));
    (md * md - k * d.norm2(), T::TWO * (md * mw - k * d.dot(w0)), mw * mw - k * w0.norm2())
}

/// |x(τ) − c|² − r² for x(τ) = x₀ + τ·d, as (a, b, c).
#[cfg(feature = "closed-form")]
#[inline]
pub(super) fn sphere_polynomial<T: Real>(x0: Vec3<T>, d: Vec3<T>, center: Vec3<T>, r: T) -> (T, T, T) {
    let f = x0 - center;
    (d.norm2(), T::TWO * f.dot(d), f.norm2() - r * r)
}

/// Roots of a τ² + 2 b τ + c = 0 (a > 0), in a numerically stable form; `None` if none are real
/// or the segment only grazes (double root).
#[inline]
pub(super) fn quadratic_roots<T: Real>(a: T, b: T, c: T) -> Option<(T, T)> {
    let disc = b * b - a * c;
    if !(disc > T::ZERO) || !(a > T::ZERO) {
        return None;
    }
    let sq = disc.sqrt();
    let q = if b >= T::ZERO { -(b + sq) } else { -b + sq };
    if q == T::ZERO {
        return Some((T::ZERO, T::ZERO));
    }
    Some((q / a, c / q))
}

/// Whether the segment crosses a quadric surface f(τ) = a τ² + 2 b τ + c_p with f(1) = c_q,
/// at an interior τ accepted by `accept`. An end point lying on the surface (|c| within
/// rounding, [`on_surface`]) is a root τ = 0 or 1 *exactly*: the other root then follows from
/// Vieta's formulas, so rounding in c never creates a spurious crossing next to an end point
/// (which for short chords in f32 would otherwise exceed any fixed τ tolerance).
#[inline]
pub(super) fn crossing_of_quadric<T: Real>(a: T, b: T, c_p: T, c_q: T, scale: T, accept: impl Fn(T) -> bool) -> bool {
    if !(a > T::ZERO) {
        return false;
    }
    let p_on = on_surface(c_p, scale);
    let q_on = on_surface(c_q, scale);
    match (p_on, q_on) {
        // A chord between two points of the surface: it meets the surface only at its ends.
        (true, true) => false,
        // Roots 0 and −2b/a.
        (true, false) => {
            let t = -T::TWO * b / a;
            interior(t) && accept(t)
        }
        // Roots 1 and c_p/a (product of the roots).
        (false, true) => {
            let t = c_p / a;
            interior(t) && accept(t)
        }
        (false, false) => match quadratic_roots(a, b, c_p) {
            Some((t1, t2)) => (interior(t1) && accept(t1)) || (interior(t2) && accept(t2)),
            None => false,
        },
    }
}

/// `true` if a quadric's value `c` at a point is zero up to the rounding of evaluating it at
/// that scale (`scale` ≈ R²) — and up to the error of the elementary functions that placed the
/// point ([`Real::ELEMENTARY_ERROR`], large with micromath): the point lies on the surface.
#[inline(always)]
pub(super) fn on_surface<T: Real>(c: T, scale: T) -> bool {
    c.abs() <= (T::from_f64(64.0) * T::EPSILON + T::from_f64(16.0) * T::ELEMENTARY_ERROR) * scale
}

/// The polynomials along a line (contract of [`Occluder::line_polynomials`]) of a finite
/// surface of revolution about the unit `axis` through `base`, of radius ρ(z) = `r0` + `k`·z
/// at height z ∈ [0, `height`] (a tube: k = 0; a cone or frustum otherwise), seen from `p`
/// towards x(τ) = origin + τ·direction. With w = x − p, A = p − base across the axis and
/// ρ_p = ρ at p's height, the segment p + λw meets the quadric where
/// α λ² + 2β λ + C = 0, α = |w⊥|² − k²w_ax², β = A·w⊥ − ρ_p k w_ax, C = |A|² − ρ_p²; the
/// blocking crossings are the roots λ ∈ (0, 1) at heights in [0, h]. That set changes only where
/// a root appears or vanishes (the discriminant β² − αC, the line tangent to the quadric), passes
/// λ = 1 (x on the quadric) or λ = 0 (β = 0, for p on it), or passes a rim (the crossing of an
/// end plane on the rim circle: |A_e w_ax + e w| = ρ_e |w_ax| as for a disk, e the plane's height
/// above p), or where α changes sign (a root through infinity). All are of degree ≤ 2 in τ, built
/// from dot products of w taken at most twice.
#[cfg(feature = "closed-form")]
#[allow(clippy::too_many_arguments)]
pub(super) fn revolution_polynomials<T: Real>(
    base: Vec3<T>,
    axis: Vec3<T>,
    r0: T,
    k: T,
    height: T,
    p: Vec3<T>,
    origin: Vec3<T>,
    direction: Vec3<T>,
    out: &mut dyn FnMut([T; 3]),
) {
    let across = |v: Vec3<T>| v - axis.scale(v.dot(axis));
    let (w0, d) = (origin - p, direction);
    let offset = p - base;
    let (a, p_ax) = (across(offset), offset.dot(axis));
    let (w0p, dp) = (across(w0), across(d));
    let (w0a, da) = (w0.dot(axis), d.dot(axis));
    let rho_p = r0 + k * p_ax;
    let kk = k * k;
    // α, β (β linear: β₀ + τβ₁) and C.
    let alpha = [dp.norm2() - kk * da * da, T::TWO * (w0p.dot(dp) - kk * w0a * da), w0p.norm2() - kk * w0a * w0a];
    let (beta0, beta1) = (a.dot(w0p) - rho_p * k * w0a, a.dot(dp) - rho_p * k * da);
    let c = a.norm2() - rho_p * rho_p;
    out([beta1 * beta1 - c * alpha[0], T::TWO * beta0 * beta1 - c * alpha[1], beta0 * beta0 - c * alpha[2]]);
    out([T::ZERO, beta1, beta0]);
    // x on the quadric: |A + w⊥|² − (ρ_p + k w_ax)².
    let f0 = a + w0p;
    let (g0, g1) = (rho_p + k * w0a, k * da);
    out([dp.norm2() - g1 * g1, T::TWO * (f0.dot(dp) - g0 * g1), f0.norm2() - g0 * g0]);
    if k != T::ZERO {
        out(alpha);
    }
    // The rims: the end plane at height z crossed at distance ρ(z) from the axis.
    for z in [T::ZERO, height] {
        out(circle_crossing_polynomial(offset - axis.scale(z), z - p_ax, (w0a, da), (w0, d), r0 + k * z));
    }
}

/// Where the segment from p to x(τ) = origin + τ·d crosses the plane of a circle (unit normal n,
/// centre c, radius `radius`) on the circle: with `pc` = p − c, `offset` = n·(c − p), the
/// crossing is p + (offset / n·w) w and its distance from c is |pc (n·w) + offset·w| / |n·w|,
/// so |pc (n·w) + offset·w|² − radius² (n·w)² = 0, quadratic in τ; `normal_parts` = (n·w₀, n·d),
/// `line` = (w₀, d) with w = w₀ + τ·d.
#[cfg(feature = "closed-form")]
pub(super) fn circle_crossing_polynomial<T: Real>(
    pc: Vec3<T>,
    offset: T,
    normal_parts: (T, T),
    line: (Vec3<T>, Vec3<T>),
    radius: T,
) -> [T; 3] {
    let ((nw0, nd), (w0, d)) = (normal_parts, line);
    let r0 = pc.scale(nw0) + w0.scale(offset);
    let r1 = pc.scale(nd) + d.scale(offset);
    let k = radius * radius;
    [r1.norm2() - k * nd * nd, T::TWO * (r0.dot(r1) - k * nw0 * nd), r0.norm2() - k * nw0 * nw0]
}
