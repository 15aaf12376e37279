//! Seeded Monte Carlo ray estimator for form factors between general curved patches, with exact
//! ray–surface intersections, sharing no code with the kernel (own vectors [`super::vector`],
//! own parametrisations written from the kernel's documented maps).
//!
//! # Patches
//! A [`RtPatch`] is a parameter rectangle `[t0, t1] × [s0, s1]` of one surface kind, with the
//! same maps g(t, s), parameter order and radiating side as `pdm_kernel::surface`:
//! * parallelogram `o + t·e_t + s·e_s`, `(t, s) ∈ [0, 1]²`, radiating towards `e_t × e_s`;
//! * disk/annulus `c + r(cos θ u + sin θ w)`, `t = r`, `s = θ`, radiating towards the axis;
//! * cone/frustum (a cylinder is `r₀ = r₁`) `b + r(z)(cos θ u + sin θ w) + z·axis`,
//!   `r(z) = r₀ + (r₁ − r₀) z/h`, `t = θ`, `s = z`, radiating outwards (inner: inwards);
//! * sphere `c + R(sin φ cos θ u + sin φ sin θ w + cos φ axis)`, `t = φ`, `s = θ`, outwards
//!   (inner: inwards).
//!
//! `(u, w, axis)` is the orthonormal frame built from the axis by the branch-free construction
//! of Duff et al. (JCGT 2017), which the kernel documents for `Frame::from_axis` (reimplemented
//! here, [`Frame::from_axis`]); the sphere's default frame is the standard one (axis = z).
//! Bézier patches and user maps have no exact ray intersection and are not supported here; use
//! [`super::direct`] for them.
//!
//! # Estimator
//! A point uniform by area on the emitter (exact area-proportional sampling for every kind: r²
//! uniform on disks and cones, cos φ uniform on spheres), a cosine-weighted direction about its
//! unit radiating normal; the ray is intersected exactly (plane or quadric roots, then the
//! parameter range) with the receiver, every occluder (whole surfaces, blocking from both
//! sides, as the kernel's occluders do) and optionally the emitter's own surface. The ray
//! counts when the *first* hit is the receiver on its radiating side; a ray that reaches the
//! receiver's back is blocked by it. `F = hits/N`, `σ = √(F(1 − F)/N)`.
//!
//! Random numbers: xoshiro256++ ([`rand_xoshiro`]), uniform doubles with 53 random bits (`rand`). The rays are cut into fixed chunks of
//! [`CHUNK`] rays, chunk `k` drawing from `seed_from_u64(seed ⊕ φ·(k + 1))`; the chunks run on
//! rayon and the integer counts are summed, so a result depends only on the seed and the ray
//! count. Throughput ≈ 1e7 rays/s per scene surface on 2 cores (release).

use super::monte_carlo::McEstimate;
use super::vector::{add, axpy, cross, dot, norm, norm2, scale, sub, V3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Rays per chunk (one random stream each).
pub const CHUNK: u64 = 1 << 15;

/// An orthonormal frame `(u, w, axis)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// θ = 0 direction.
    pub u: V3,
    /// θ = π/2 direction.
    pub w: V3,
    /// Unit axis.
    pub axis: V3,
}

impl Frame {
    /// The standard frame: u = x, w = y, axis = z.
    pub const STANDARD: Self = Self { u: [1.0, 0.0, 0.0], w: [0.0, 1.0, 0.0], axis: [0.0, 0.0, 1.0] };

    /// Duff et al. 2017, "Building an orthonormal basis, revisited" (the kernel's documented
    /// construction). `None` for a zero or non-finite axis.
    pub fn from_axis(axis: V3) -> Option<Self> {
        let len = norm(axis);
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let n = scale(axis, 1.0 / len);
        let sign = if n[2] >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (sign + n[2]);
        let b = n[0] * n[1] * a;
        let u = [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
        let w = [b, sign + n[1] * n[1] * a, -n[1]];
        Some(Self { u, w, axis: n })
    }

    fn local(&self, q: V3) -> V3 {
        [dot(q, self.u), dot(q, self.w), dot(q, self.axis)]
    }

    fn world(&self, x: f64, y: f64, z: f64) -> V3 {
        add(add(scale(self.u, x), scale(self.w, y)), scale(self.axis, z))
    }
}

/// A surface kind with its geometry (see the module docs for the maps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// `o + t·e_t + s·e_s`.
    Parallelogram {
        /// Corner g(0, 0).
        origin: V3,
        /// ∂g/∂t.
        edge_t: V3,
        /// ∂g/∂s.
        edge_s: V3,
    },
    /// Plane disk (t = r, s = θ), radiating towards `frame.axis`.
    Disk {
        /// Centre.
        center: V3,
        /// Frame (axis = radiating normal).
        frame: Frame,
    },
    /// Cone/frustum or cylinder (t = θ, s = z).
    Cone {
        /// Centre of the z = 0 circle.
        base: V3,
        /// Frame.
        frame: Frame,
        /// Radius at z = 0.
        r0: f64,
        /// dr/dz.
        slope: f64,
        /// Radiating inwards.
        inner: bool,
    },
    /// Sphere (t = φ from the axis, s = θ).
    Sphere {
        /// Centre.
        center: V3,
        /// Radius.
        radius: f64,
        /// Frame (poles on the axis).
        frame: Frame,
        /// Radiating inwards.
        inner: bool,
    },
}

/// A parameter rectangle of a [`Shape`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RtPatch {
    /// The surface.
    pub shape: Shape,
    /// Parameter range `[t0, t1] × [s0, s1]`.
    pub rect: [f64; 4],
}

const TAU: f64 = 2.0 * PI;

impl RtPatch {
    /// The whole parallelogram `o + t·e_t + s·e_s`, radiating towards `e_t × e_s`.
    pub fn parallelogram(origin: V3, edge_t: V3, edge_s: V3) -> Self {
        Self { shape: Shape::Parallelogram { origin, edge_t, edge_s }, rect: [0.0, 1.0, 0.0, 1.0] }
    }

    /// The annulus `inner ≤ r ≤ outer` (a disk for `inner = 0`), radiating towards `axis`.
    pub fn annulus(center: V3, axis: V3, inner: f64, outer: f64) -> Option<Self> {
        Some(Self { shape: Shape::Disk { center, frame: Frame::from_axis(axis)? }, rect: [inner, outer, 0.0, TAU] })
    }

    /// A whole disk.
    pub fn disk(center: V3, axis: V3, radius: f64) -> Option<Self> {
        Self::annulus(center, axis, 0.0, radius)
    }

    /// A whole frustum from radius `r0` at the base to `r1` at height `h` along `axis`.
    pub fn cone(base: V3, axis: V3, r0: f64, r1: f64, h: f64, inner: bool) -> Option<Self> {
        if !(h > 0.0) {
            return None;
        }
        let frame = Frame::from_axis(axis)?;
        Some(Self { shape: Shape::Cone { base, frame, r0, slope: (r1 - r0) / h, inner }, rect: [0.0, TAU, 0.0, h] })
    }

    /// A whole open cylinder.
    pub fn cylinder(base: V3, axis: V3, radius: f64, h: f64, inner: bool) -> Option<Self> {
        Self::cone(base, axis, radius, radius, h, inner)
    }

    /// A whole sphere with poles on the z axis.
    pub fn sphere(center: V3, radius: f64, inner: bool) -> Self {
        Self { shape: Shape::Sphere { center, radius, frame: Frame::STANDARD, inner }, rect: [0.0, PI, 0.0, TAU] }
    }

    /// A whole sphere with poles on `axis` (frame from [`Frame::from_axis`]).
    pub fn sphere_with_axis(center: V3, radius: f64, axis: V3, inner: bool) -> Option<Self> {
        let frame = Frame::from_axis(axis)?;
        Some(Self { shape: Shape::Sphere { center, radius, frame, inner }, rect: [0.0, PI, 0.0, TAU] })
    }

    /// The same surface over another parameter rectangle.
    pub fn sub(&self, t0: f64, t1: f64, s0: f64, s1: f64) -> Self {
        Self { shape: self.shape, rect: [t0, t1, s0, s1] }
    }

    /// Exact area of the patch.
    pub fn area(&self) -> f64 {
        let [t0, t1, s0, s1] = self.rect;
        match self.shape {
            Shape::Parallelogram { edge_t, edge_s, .. } => norm(cross(edge_t, edge_s)) * (t1 - t0) * (s1 - s0),
            Shape::Disk { .. } => 0.5 * (t1 * t1 - t0 * t0) * (s1 - s0),
            Shape::Cone { r0, slope, .. } => {
                let ra = r0 + slope * s0;
                let rb = r0 + slope * s1;
                (t1 - t0) * 0.5 * (ra + rb) * (s1 - s0) * (1.0 + slope * slope).sqrt()
            }
            Shape::Sphere { radius, .. } => radius * radius * (t0.cos() - t1.cos()) * (s1 - s0),
        }
    }

    /// Point g(t, s) and unnormalised radiating normal ∂g/∂t × ∂g/∂s (negated for inner sides),
    /// as in the kernel's surfaces.
    pub fn eval(&self, t: f64, s: f64) -> (V3, V3) {
        match self.shape {
            Shape::Parallelogram { origin, edge_t, edge_s } => {
                (add(origin, add(scale(edge_t, t), scale(edge_s, s))), cross(edge_t, edge_s))
            }
            Shape::Disk { center, frame } => {
                (add(center, frame.world(t * s.cos(), t * s.sin(), 0.0)), scale(frame.axis, t))
            }
            Shape::Cone { base, frame, r0, slope, inner } => {
                let r = r0 + slope * s;
                let (st, ct) = t.sin_cos();
                let p = add(base, frame.world(r * ct, r * st, s));
                let n = scale(frame.world(ct, st, -slope), if inner { -r } else { r });
                (p, n)
            }
            Shape::Sphere { center, radius, frame, inner } => {
                let (sp, cp) = t.sin_cos();
                let (st, ct) = s.sin_cos();
                let radial = frame.world(sp * ct, sp * st, cp);
                let k = radius * radius * sp;
                (axpy(center, radius, radial), scale(radial, if inner { -k } else { k }))
            }
        }
    }

    /// A point uniform by area from two uniforms in [0, 1), with its unit radiating normal.
    fn sample(&self, u1: f64, u2: f64) -> (V3, V3) {
        let [t0, t1, s0, s1] = self.rect;
        let lerp = |a: f64, b: f64, x: f64| a + (b - a) * x;
        let (t, s) = match self.shape {
            Shape::Parallelogram { .. } => (lerp(t0, t1, u1), lerp(s0, s1, u2)),
            Shape::Disk { .. } => ((t0 * t0 + u1 * (t1 * t1 - t0 * t0)).sqrt(), lerp(s0, s1, u2)),
            Shape::Cone { r0, slope, .. } => {
                let ra = r0 + slope * s0;
                let rb = r0 + slope * s1;
                // Density ∝ r(z): r² uniform between ra² and rb².
                let z = if (rb - ra).abs() <= 1e-12 * (ra + rb) {
                    lerp(s0, s1, u2)
                } else {
                    let r = (ra * ra + u2 * (rb * rb - ra * ra)).sqrt();
                    (s0 + (r - ra) / slope).clamp(s0, s1)
                };
                (lerp(t0, t1, u1), z)
            }
            Shape::Sphere { .. } => {
                let c = lerp(t0.cos(), t1.cos(), u1).clamp(-1.0, 1.0);
                (c.acos(), lerp(s0, s1, u2))
            }
        };
        let (p, n) = self.eval(t, s);
        let n = match self.shape {
            // The disk's normal vanishes at r = 0; its direction is the axis everywhere.
            Shape::Disk { frame, .. } => frame.axis,
            Shape::Sphere { center, frame, inner, .. } => {
                let d = sub(p, center);
                let l = norm(d);
                if l > 0.0 {
                    scale(d, if inner { -1.0 / l } else { 1.0 / l })
                } else {
                    frame.axis
                }
            }
            _ => scale(n, 1.0 / norm(n)),
        };
        (p, n)
    }

    /// A scale of the surface (for intersection tolerances).
    fn size(&self) -> f64 {
        match self.shape {
            Shape::Parallelogram { edge_t, edge_s, .. } => norm(edge_t).max(norm(edge_s)),
            Shape::Disk { .. } => self.rect[1],
            Shape::Cone { r0, slope, .. } => r0.abs().max((r0 + slope * self.rect[3]).abs()).max(self.rect[3]),
            Shape::Sphere { radius, .. } => radius,
        }
    }

    /// Whether the angle `th` ∈ [0, 2π) lies in `[a, b]` (ranges inside [0, 2π] as the kernel's).
    fn angle_in(th: f64, a: f64, b: f64) -> bool {
        let th = if th < 0.0 { th + TAU } else { th };
        (th >= a && th <= b) || (th + TAU >= a && th + TAU <= b) || (th - TAU >= a && th - TAU <= b)
    }

    /// Parameters of a surface point `x` if they lie in the patch's rectangle.
    fn contains(&self, x: V3) -> bool {
        let [t0, t1, s0, s1] = self.rect;
        match self.shape {
            Shape::Parallelogram { origin, edge_t, edge_s } => {
                let n = cross(edge_t, edge_s);
                let nn = norm2(n);
                let q = sub(x, origin);
                let t = dot(cross(q, edge_s), n) / nn;
                let s = dot(cross(edge_t, q), n) / nn;
                t >= t0 && t <= t1 && s >= s0 && s <= s1
            }
            Shape::Disk { center, frame } => {
                let l = frame.local(sub(x, center));
                let r = l[0].hypot(l[1]);
                r >= t0 && r <= t1 && (s1 - s0 >= TAU || Self::angle_in(l[1].atan2(l[0]), s0, s1))
            }
            Shape::Cone { base, frame, .. } => {
                let l = frame.local(sub(x, base));
                l[2] >= s0 && l[2] <= s1 && (t1 - t0 >= TAU || Self::angle_in(l[1].atan2(l[0]), t0, t1))
            }
            Shape::Sphere { center, radius, frame, .. } => {
                let l = frame.local(sub(x, center));
                let phi = (l[2] / radius).clamp(-1.0, 1.0).acos();
                phi >= t0 && phi <= t1 && (s1 - s0 >= TAU || Self::angle_in(l[1].atan2(l[0]), s0, s1))
            }
        }
    }

    /// Radiating normal direction (not normalised) at a surface point `x`.
    fn normal_at(&self, x: V3) -> V3 {
        match self.shape {
            Shape::Parallelogram { edge_t, edge_s, .. } => cross(edge_t, edge_s),
            Shape::Disk { frame, .. } => frame.axis,
            Shape::Cone { base, frame, slope, inner, .. } => {
                let l = frame.local(sub(x, base));
                let radial = frame.world(l[0], l[1], 0.0);
                let lr = norm(radial);
                let dir = if lr > 0.0 { scale(radial, 1.0 / lr) } else { radial };
                let n = axpy(dir, -slope, frame.axis);
                if inner {
                    scale(n, -1.0)
                } else {
                    n
                }
            }
            Shape::Sphere { center, inner, .. } => {
                let d = sub(x, center);
                if inner {
                    scale(d, -1.0)
                } else {
                    d
                }
            }
        }
    }

    /// The nearest hit of the ray `o + τ·d`, `τ > tmin`, with the patch: `(τ, front)`, `front`
    /// when the ray meets the radiating side.
    pub fn intersect(&self, o: V3, d: V3, tmin: f64) -> Option<(f64, bool)> {
        let mut roots = [f64::NAN; 2];
        match self.shape {
            Shape::Parallelogram { origin, edge_t, edge_s } => {
                let n = cross(edge_t, edge_s);
                roots[0] = plane_hit(o, d, origin, n);
            }
            Shape::Disk { center, frame } => roots[0] = plane_hit(o, d, center, frame.axis),
            Shape::Cone { base, frame, r0, slope, .. } => {
                let q = frame.local(sub(o, base));
                let v = frame.local(d);
                let rq = r0 + slope * q[2];
                let a = v[0] * v[0] + v[1] * v[1] - slope * slope * v[2] * v[2];
                let b = 2.0 * (q[0] * v[0] + q[1] * v[1] - slope * rq * v[2]);
                let c = q[0] * q[0] + q[1] * q[1] - rq * rq;
                roots = quadratic(a, b, c);
            }
            Shape::Sphere { center, radius, .. } => {
                let q = sub(o, center);
                roots = quadratic(norm2(d), 2.0 * dot(q, d), norm2(q) - radius * radius);
            }
        }
        let mut best: Option<(f64, bool)> = None;
        for tau in roots {
            if !(tau > tmin) || best.is_some_and(|(b, _)| b <= tau) {
                continue;
            }
            let x = axpy(o, tau, d);
            if let Shape::Cone { base, frame, r0, slope, .. } = self.shape {
                // Only the nappe with r(z) ≥ 0.
                if r0 + slope * dot(sub(x, base), frame.axis) < 0.0 {
                    continue;
                }
            }
            if self.contains(x) {
                best = Some((tau, dot(d, self.normal_at(x)) < 0.0));
            }
        }
        best
    }
}

/// τ of the ray–plane hit (NaN when parallel).
fn plane_hit(o: V3, d: V3, p: V3, n: V3) -> f64 {
    let den = dot(d, n);
    if den == 0.0 {
        return f64::NAN;
    }
    dot(sub(p, o), n) / den
}

/// Real roots of `a x² + b x + c` (NaN for missing ones), cancellation free.
fn quadratic(a: f64, b: f64, c: f64) -> [f64; 2] {
    if a == 0.0 {
        return [if b != 0.0 { -c / b } else { f64::NAN }, f64::NAN];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [f64::NAN; 2];
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return [0.0, 0.0];
    }
    [q / a, c / q]
}

/// A scene: emitter, receiver and occluders (whole surfaces or patches, blocking both sides).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Emitting patch.
    pub emitter: RtPatch,
    /// Receiving patch (counts when hit first on its radiating side).
    pub receiver: RtPatch,
    /// Occluders.
    pub occluders: Vec<RtPatch>,
    /// Whether the emitter's own patch blocks (concave emitters).
    pub emitter_occludes: bool,
}

/// A unit vector orthogonal to `n` and a second completing the frame (Duff et al.).
fn tangent_frame(n: V3) -> (V3, V3) {
    match Frame::from_axis(n) {
        Some(f) => (f.u, f.w),
        None => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    }
}

/// Uniform in `[0, 1)` with 53 random bits.
fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
    rng.random::<f64>()
}

/// One ray: whether it reaches the receiver's radiating side first.
fn trace(scene: &Scene, rng: &mut Xoshiro256PlusPlus, tmin: f64) -> bool {
    let (p, n) = scene.emitter.sample(uniform(rng), uniform(rng));
    let u1 = uniform(rng);
    let u2 = uniform(rng);
    let r = u1.sqrt();
    let (s2, c2) = (TAU * u2).sin_cos();
    let (tu, tw) = tangent_frame(n);
    let d = add(add(scale(tu, r * c2), scale(tw, r * s2)), scale(n, (1.0 - u1).max(0.0).sqrt()));
    let Some((tr, front)) = scene.receiver.intersect(p, d, tmin) else {
        return false;
    };
    if !front {
        return false;
    }
    let blocked = |o: &RtPatch| o.intersect(p, d, tmin).is_some_and(|(t, _)| t < tr);
    if scene.occluders.iter().any(blocked) {
        return false;
    }
    !(scene.emitter_occludes && blocked(&scene.emitter))
}

/// F_{emitter → receiver} by `rays` rays from `seed` (see the module docs). `None` for zero rays
/// or an emitter of zero area.
pub fn mc_form_factor(scene: &Scene, rays: u64, seed: u64) -> Option<McEstimate> {
    if rays == 0 || !(scene.emitter.area() > 0.0) {
        return None;
    }
    let tmin = 1e-10 * scene.emitter.size();
    let chunks = rays.div_ceil(CHUNK);
    let hits: u64 = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ (k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let n = CHUNK.min(rays - k * CHUNK);
            (0..n).filter(|_| trace(scene, &mut rng, tmin)).count() as u64
        })
        .sum();
    let f = hits as f64 / rays as f64;
    Some(McEstimate { value: f, std_error: (f * (1.0 - f) / rays as f64).sqrt(), rays })
}
