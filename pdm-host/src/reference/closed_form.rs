//! Closed-form configuration factors and textbook identities (REFERENCES.md, "Flat pairs" and
//! "Sphere pairs"; Howell's catalogue entries C-11, C-14, C-41). All functions are plain `f64`
//! expressions, accurate to a few ulp unless stated otherwise. Inputs outside a formula's
//! domain give NaN (documented per function), never a panic.

use super::vector::{cross, dot, norm, sub, V3};
use std::f64::consts::PI;

/// **C-11** (Howell): parallel, directly opposed rectangles `a × b` at distance `c`.
/// With `X = a/c`, `Y = b/c`:
/// ```text
/// F = 2/(πXY) { ln √[(1+X²)(1+Y²)/(1+X²+Y²)] + X√(1+Y²) atan(X/√(1+Y²))
///               + Y√(1+X²) atan(Y/√(1+X²)) − X atan X − Y atan Y }
/// ```
/// Unit squares at distance 1: 0.1998248956983874. Accuracy: a few ulp (relative ≤ 1e-15 for
/// `X, Y ∈ [1e-3, 1e3]`; the bracket cancels like `XY` for small `X, Y`).
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let x = a / c;
    let y = b / c;
    let x2 = x * x;
    let y2 = y * y;
    let sy = (1.0 + y2).sqrt();
    let sx = (1.0 + x2).sqrt();
    let lg = 0.5 * (((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).ln();
    let br = lg + x * sy * (x / sy).atan() + y * sx * (y / sx).atan() - x * x.atan() - y * y.atan();
    2.0 / (PI * x * y) * br
}

/// **C-14** (Howell): perpendicular rectangles with a common edge of length `l`; the emitter
/// has width `w`, the receiver height `h` (both perpendicular to the edge). `H = h/l`,
/// `W = w/l`:
/// ```text
/// F_{w→h} = 1/(πW) { W atan(1/W) + H atan(1/H) − √(H²+W²) atan(1/√(H²+W²))
///     + ¼ ln[ (1+W²)(1+H²)/(1+W²+H²) · (W²(1+W²+H²)/((1+W²)(W²+H²)))^{W²}
///                                    · (H²(1+W²+H²)/((1+H²)(W²+H²)))^{H²} ] }
/// ```
/// The logarithm of the product is evaluated as a sum of `ln_1p` terms (cancellation free).
/// Unit squares: 0.2000437760754032. Reciprocity: `w·F_{w→h}(l,w,h) = h·F_{h→w}(l,h,w)`. Accuracy: a few ulp
/// (checked against the contour form to ≤ 1e-14 for aspect ratios up to 1:100).
pub fn perpendicular_rectangles(l: f64, w: f64, h: f64) -> f64 {
    let ww = w / l;
    let hh = h / l;
    let w2 = ww * ww;
    let h2 = hh * hh;
    let s = (w2 + h2).sqrt();
    let term = ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan();
    // Each ratio is written as 1 + δ and its logarithm taken with ln_1p:
    // (1+W²)(1+H²)/(1+W²+H²) = 1 + W²H²/(1+W²+H²),
    // W²(1+W²+H²)/((1+W²)(W²+H²)) = 1 − H²/((1+W²)(W²+H²)),
    // H²(1+W²+H²)/((1+H²)(W²+H²)) = 1 − W²/((1+H²)(W²+H²)).
    // (The plain ratios lose ~8 digits at aspect 1:100, where they are multiplied by 10⁴.)
    let l0 = (w2 * h2 / (1.0 + w2 + h2)).ln_1p();
    let lw = w2 * (-h2 / ((1.0 + w2) * (w2 + h2))).ln_1p();
    let lh = h2 * (-w2 / ((1.0 + h2) * (w2 + h2))).ln_1p();
    (term + 0.25 * (l0 + lw + lh)) / (PI * ww)
}

/// **C-41** (Howell): coaxial parallel disks, emitter radius `r1`, receiver radius `r2`,
/// distance `h`. `Rᵢ = rᵢ/h`, `X = 1 + (1 + R₂²)/R₁²`: `F = ½[X − √(X² − 4(R₂/R₁)²)]`.
/// `r₁ = r₂ = h`: `(3 − √5)/2` = 0.3819660112501052. Accuracy: a few ulp (the difference is
/// evaluated in the cancellation-free form `2(R₂/R₁)² / (X + √(X² − 4(R₂/R₁)²))`, and
/// `X² − 4(R₂/R₁)² = (X − 2R₂/R₁)(X + 2R₂/R₁)` with `X − 2R₂/R₁ = (1 + (R₁ − R₂)²)/R₁²` exactly,
/// so h ≪ r does not cancel: equal disks at h = 1e-8 r give 1 − h/r + h²/(2r²)).
pub fn coaxial_disks(r1: f64, r2: f64, h: f64) -> f64 {
    let rr1 = r1 / h;
    let rr2 = r2 / h;
    let x = 1.0 + (1.0 + rr2 * rr2) / (rr1 * rr1);
    let q = rr2 / rr1;
    let d = rr1 - rr2;
    let x_minus = (1.0 + d * d) / (rr1 * rr1);
    let root = (x_minus * (x + 2.0 * q)).sqrt();
    // ½(X − √(X² − 4q²)) = 2q² / (X + √(X² − 4q²))
    2.0 * q * q / (x + root)
}

/// Signed solid angle of the triangle `(a, b, c)` seen from `o` by the Van Oosterom–Strackee
/// formula `tan(Ω/2) = [A·(B×C)] / (|A||B||C| + (A·B)|C| + (A·C)|B| + (B·C)|A|)` with
/// `A = a − o` etc. The sign is that of the triple product `A·(B×C)`. Accuracy: a few ulp (atan2 of the exact ratio).
pub fn triangle_solid_angle(o: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let va = sub(a, o);
    let vb = sub(b, o);
    let vc = sub(c, o);
    let (la, lb, lc) = (norm(va), norm(vb), norm(vc));
    let num = dot(va, cross(vb, vc));
    let den = la * lb * lc + dot(va, vb) * lc + dot(va, vc) * lb + dot(vb, vc) * la;
    2.0 * num.atan2(den)
}

/// Solid angle (non-negative) of a convex planar polygon seen from `o`, by fan triangulation
/// from the first vertex with [`triangle_solid_angle`]; the signed triangle angles are summed
/// and the absolute value taken. Fewer than 3 vertices: 0.
pub fn polygon_solid_angle(o: [f64; 3], poly: &[[f64; 3]]) -> f64 {
    let Some((&first, rest)) = poly.split_first() else {
        return 0.0;
    };
    let mut sum = 0.0;
    for w in rest.windows(2) {
        if let [b, c] = *w {
            sum += triangle_solid_angle(o, first, b, c);
        }
    }
    sum.abs()
}

/// Sphere (centre `centre`, any radius) → convex planar polygon that does not cut the sphere:
/// `F = Ω/(4π)` with `Ω` the solid angle of the polygon at the centre (REFERENCES.md "Sphere →
/// any planar polygon"; the sphere radiates uniformly). Sphere centred in a cube → one face:
/// 1/6. Accuracy: a few ulp.
pub fn sphere_to_polygon(centre: [f64; 3], poly: &[[f64; 3]]) -> f64 {
    polygon_solid_angle(centre, poly) / (4.0 * PI)
}

/// Differential area → sphere of radius `radius` whose centre is at distance `distance`, the
/// area's normal tilted `tilt` (radians) from the direction to the centre:
/// `F = cos φ (R/D)²`, valid when the whole sphere is above the horizon, `φ ≤ acos(R/D)`
/// (REFERENCES.md). Outside that domain (or `R ≥ D`) returns NaN. Exact.
pub fn differential_area_to_sphere(radius: f64, distance: f64, tilt: f64) -> f64 {
    if !(radius >= 0.0 && distance > radius && tilt.abs() <= (radius / distance).acos()) {
        return f64::NAN;
    }
    let q = radius / distance;
    tilt.cos() * q * q
}

/// Face of a cube of side `side` → a sphere of radius `radius` centred in the cube, by
/// reciprocity from sphere → face = 1/6: `F = (4πR²/6)/l²`. `l = 6, R = 1`: `π/54` =
/// 0.05817764173314432. Exact.
pub fn cube_face_to_centred_sphere(side: f64, radius: f64) -> f64 {
    4.0 * PI * radius * radius / 6.0 / (side * side)
}

/// Point kernel `cos θᵢ cos θⱼ/(π r²)` between two points on the inside of a sphere of radius
/// `R`: constant `1/(4πR²)` (since `cos θᵢ = cos θⱼ = r/(2R)`, so `cos θᵢ cos θⱼ / r² = 1/(4R²)`).
pub fn sphere_interior_kernel(radius: f64) -> f64 {
    1.0 / (4.0 * PI * radius * radius)
}

/// Form factor between two patches on the inside of one sphere of radius `R`:
/// `F_{i→j} = A_j/(4πR²)`, independent of the emitting patch (integrate the constant kernel
/// [`sphere_interior_kernel`]). Exact.
pub fn sphere_interior_factor(radius: f64, receiver_area: f64) -> f64 {
    receiver_area / (4.0 * PI * radius * radius)
}

/// Area of the sphere zone between the planes `z = z0` and `z = z1` (`−R ≤ z0 ≤ z1 ≤ R`):
/// `2πR (z1 − z0)` (Archimedes). Exact.
pub fn sphere_zone_area(radius: f64, z0: f64, z1: f64) -> f64 {
    2.0 * PI * radius * (z1 - z0)
}

/// Area of the sphere patch `φ ∈ [φ0, φ1]` (polar angle from +z, the paper's eq. 19),
/// `θ ∈ [θ0, θ1]` (azimuth): `R² (θ1 − θ0)(cos φ0 − cos φ1)`. Exact.
pub fn sphere_patch_area(radius: f64, phi0: f64, phi1: f64, theta0: f64, theta1: f64) -> f64 {
    radius * radius * (theta1 - theta0) * (phi0.cos() - phi1.cos())
}

/// Lateral area of the cylinder band of radius `R` between heights `z0` and `z1`:
/// `2πR (z1 − z0)`. Exact.
pub fn cylinder_band_area(radius: f64, z0: f64, z1: f64) -> f64 {
    2.0 * PI * radius * (z1 - z0)
}

/// Area of the cylinder patch `θ ∈ [θ0, θ1]`, `z ∈ [z0, z1]`: `R (θ1 − θ0)(z1 − z0)`. Exact.
pub fn cylinder_patch_area(radius: f64, theta0: f64, theta1: f64, z0: f64, z1: f64) -> f64 {
    radius * (theta1 - theta0) * (z1 - z0)
}

/// Solid angle helper exposed for tests: vertices of the cube face `z = +l/2` of a cube of
/// side `l` centred at the origin, counter-clockwise seen from the centre.
pub fn cube_top_face(side: f64) -> [V3; 4] {
    let h = 0.5 * side;
    [[-h, -h, h], [-h, h, h], [h, h, h], [h, -h, h]]
}
