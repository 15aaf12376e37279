//! Occluders for parts of surfaces: a sphere zone or lune, a disk sector, part of a tube or a
//! cone (a `theta` or `phi` range in the scene file). A segment is blocked where it crosses the
//! whole surface at a point whose parameters lie in the part's rectangle: the crossings are the
//! roots of the surface's quadric (or plane) along the segment, computed in f64, and each is
//! mapped back to the surface's (t, s).
//!
//! These occluders have no closed-form visibility along lines (`line_polynomials` answers
//! "not known"): the kernel's occluded paths bracket and bisect their edges instead.

use pdm_kernel::{AnyOccluder, Ball, Caster, Occluder, Quadric, Real, Vec3};

use super::shape::{Geom, Rect};

/// A part `rect` of the whole surface `geom`, with `whole` the whole surface's occluder (whose
/// culling is conservative for the part).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part<T> {
    whole: AnyOccluder<T>,
    geom: Geom,
    rect: Rect,
}

/// The scene's occluders: a kernel occluder of a whole surface, or a part of one.
// A part carries its surface's geometry beside the whole surface's occluder; the lists of a
// pair hold a handful, copied once per pair, next to kernel work of microseconds or more.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneOccluder<T> {
    /// A whole surface.
    Whole(AnyOccluder<T>),
    /// A part of one.
    Part(Part<T>),
}

fn f64v<T: Real>(v: Vec3<T>) -> Vec3<f64> {
    pdm_kernel::vec3(v.x.to_f64(), v.y.to_f64(), v.z.to_f64())
}

/// Real roots of a τ² + 2b τ + c = 0, stable form (a cone's leading coefficient may be of
/// either sign or zero).
fn roots(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a < 0.0 {
        return roots(-a, -b, -c);
    }
    if a == 0.0 {
        return (b != 0.0).then(|| (-c / (2.0 * b), f64::NAN));
    }
    let disc = b * b - a * c;
    if !(a > 0.0) || disc < 0.0 {
        return None;
    }
    let q = -(b + b.signum() * disc.sqrt());
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    Some((q / a, c / q))
}

/// The angle of `v` in the frame (u, w), in [0, 2π).
fn angle(v: Vec3<f64>, u: Vec3<f64>, w: Vec3<f64>) -> f64 {
    let a = v.dot(w).atan2(v.dot(u));
    if a < 0.0 {
        a + 2.0 * core::f64::consts::PI
    } else {
        a
    }
}

impl<T: Real> Part<T> {
    /// The part `rect` of `geom` (a sphere, disk, cylinder or cone); `None` for other kinds or
    /// when the kernel refuses the whole surface.
    #[must_use]
    pub fn new(geom: Geom, rect: Rect) -> Option<Self> {
        if !matches!(geom, Geom::Sphere { .. } | Geom::Disk { .. } | Geom::Cylinder { .. } | Geom::Cone { .. }) {
            return None;
        }
        let shape = geom.shape::<T>().ok()?;
        let whole = super::shape::occluder_of(&shape)?;
        Some(Self { whole, geom, rect })
    }

    /// The parameters (t, s) of a point `x` of the whole surface.
    fn parameters(&self, x: Vec3<f64>) -> (f64, f64) {
        match self.geom {
            Geom::Sphere { center, radius, frame, .. } => {
                let v = x - center;
                ((v.dot(frame.axis) / radius).clamp(-1.0, 1.0).acos(), angle(v, frame.u, frame.w))
            }
            Geom::Disk { center, frame, .. } => {
                let v = x - center;
                let radial = v - frame.axis.scale(v.dot(frame.axis));
                (radial.norm(), angle(v, frame.u, frame.w))
            }
            Geom::Cylinder { base, frame, .. } | Geom::Cone { base, frame, .. } => {
                let v = x - base;
                (angle(v, frame.u, frame.w), v.dot(frame.axis))
            }
            _ => (f64::NAN, f64::NAN),
        }
    }

    /// The quadric of the whole surface along the segment p + τ(q − p): coefficients (a, b,
    /// c) of a τ² + 2b τ + c, its value at q, and its scale (a squared radius); a plane is
    /// the linear case a = 0 with its signed distances.
    fn quadric(&self, p: Vec3<f64>, q: Vec3<f64>) -> Option<(f64, f64, f64, f64, f64)> {
        let d = q - p;
        Some(match self.geom {
            Geom::Sphere { center, radius, .. } => {
                let (f, g) = (p - center, q - center);
                let r2 = radius * radius;
                (d.dot(d), f.dot(d), f.dot(f) - r2, g.dot(g) - r2, r2)
            }
            Geom::Cylinder { base, frame, radius, .. } => {
                let perp = |v: Vec3<f64>| v - frame.axis.scale(v.dot(frame.axis));
                let (f, e, g) = (perp(p - base), perp(d), perp(q - base));
                let r2 = radius * radius;
                (e.dot(e), f.dot(e), f.dot(f) - r2, g.dot(g) - r2, r2)
            }
            Geom::Cone { base, frame, base_radius, top_radius, height, .. } => {
                // |x⊥|² = r(z)², r(z) = r₀ + k z, z = z₀ + τ z₁: a quadratic in τ.
                let perp = |v: Vec3<f64>| v - frame.axis.scale(v.dot(frame.axis));
                let (f, e, g) = (perp(p - base), perp(d), perp(q - base));
                let k = (top_radius - base_radius) / height;
                let (z0, z1) = ((p - base).dot(frame.axis), d.dot(frame.axis));
                let (r0, r1) = (base_radius + k * z0, k * z1);
                let rq = r0 + r1;
                let scale = base_radius.max(top_radius).powi(2);
                (e.dot(e) - r1 * r1, f.dot(e) - r0 * r1, f.dot(f) - r0 * r0, g.dot(g) - rq * rq, scale)
            }
            _ => return None,
        })
    }

    /// The τ ∈ (0, 1) where the segment p + τ(q − p) crosses the whole surface. An end point
    /// on the surface (within the rounding of the precision `T` that placed it, as the
    /// kernel's occluders decide) is a root at exactly 0 or 1, which does not count: a segment
    /// from a point of the surface meets it again only at the other root.
    fn crossings(&self, p: Vec3<f64>, q: Vec3<f64>) -> [Option<f64>; 2] {
        let on = |value: f64, scale: f64| {
            value.abs() <= (64.0 * T::EPSILON.to_f64() + 16.0 * T::ELEMENTARY_ERROR.to_f64()) * scale
        };
        if let Geom::Disk { center, frame, outer, .. } = self.geom {
            let (dp, dq) = (frame.axis.dot(p - center), frame.axis.dot(q - center));
            if on(dp, outer) || on(dq, outer) || dp == dq {
                return [None, None];
            }
            return [Some(dp / (dp - dq)), None];
        }
        let Some((a, b, c, c_q, scale)) = self.quadric(p, q) else { return [None, None] };
        match (on(c, scale), on(c_q, scale)) {
            (true, true) => [None, None],
            // Roots 0 and −2b/a.
            (true, false) => [(a != 0.0).then(|| -2.0 * b / a), None],
            // Roots 1 and c/a (the product of the roots).
            (false, true) => [(a != 0.0).then(|| c / a), None],
            (false, false) => match roots(a, b, c) {
                Some((x, y)) => [Some(x), Some(y)],
                None => [None, None],
            },
        }
    }
}

impl<T: Real> Occluder<T> for Part<T> {
    /// The segment crosses the whole surface inside the open segment (away from its ends by
    /// the kernel's relative `GEOMETRY_TOLERANCE`, as every occluder) at a point of the part.
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let (p, q) = (f64v(p), f64v(q));
        let tol = T::GEOMETRY_TOLERANCE.to_f64();
        let r = self.rect;
        self.crossings(p, q).into_iter().flatten().any(|tau| {
            if !(tau > tol && tau < 1.0 - tol) {
                return false;
            }
            let (t, s) = self.parameters(p + (q - p).scale(tau));
            t >= r.t0 && t <= r.t1 && s >= r.s0 && s <= r.s1
        })
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.whole.may_block_between(a, b)
    }
}

impl<T: Real> Occluder<T> for SceneOccluder<T> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        match self {
            Self::Whole(o) => o.blocks(p, q),
            Self::Part(o) => o.blocks(p, q),
        }
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Whole(o) => o.may_block_between(a, b),
            Self::Part(o) => o.may_block_between(a, b),
        }
    }
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        match self {
            Self::Whole(o) => o.line_polynomials(p, origin, direction, out),
            Self::Part(_) => false,
        }
    }
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Whole(o) => o.hides_ball_from(p, b),
            Self::Part(_) => false,
        }
    }
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        match self {
            Self::Whole(o) => o.event_quadrics(corner, edge, pair, out),
            Self::Part(_) => false,
        }
    }
    /// A whole flat polygon or sphere says so; a part of a surface only "nothing may cut".
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        match self {
            Self::Whole(o) => o.shadow_casters(from, b, bounds, out),
            Self::Part(o) => !o.may_block_between(from, bounds),
        }
    }
    /// A whole sphere says so (the kernel then takes a point's view of a parallelogram past it
    /// in closed form); a part of a surface gives only "nothing may cut".
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        match self {
            Self::Whole(o) => o.shadow_sphere(a, b),
            Self::Part(o) => (!o.may_block_between(a, b)).then_some(None),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;
    use pdm_kernel::{vec3, Frame, Surface as _};
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256StarStar;

    fn kinds() -> Vec<Geom> {
        let frame = Frame::from_axis(vec3(0.3, -0.2, 1.0)).unwrap();
        let c = vec3(0.1, 0.2, -0.3);
        vec![
            Geom::Sphere { center: c, radius: 1.1, frame, inner: false },
            Geom::Disk { center: c, frame, inner: 0.2, outer: 1.3 },
            Geom::Cylinder { base: c, frame, radius: 0.9, height: 1.5, inner: false },
            Geom::Cone { base: c, frame, base_radius: 1.2, top_radius: 0.4, height: 1.4, inner: true },
        ]
    }

    /// The parameters found for a point of the surface are those it was made from, and a
    /// segment through that point is blocked by a small part around it and by no part beside.
    #[test]
    fn crossings_map_back_to_their_parameters() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(3);
        for geom in kinds() {
            let shape = geom.shape::<f64>().unwrap();
            let d = geom.domain();
            for _ in 0..300 {
                let t = d.t0 + (d.t1 - d.t0) * (0.05 + 0.9 * rng.random::<f64>());
                let s = d.s0 + (d.s1 - d.s0) * (0.05 + 0.9 * rng.random::<f64>());
                let (x, n) = shape.point_and_normal(t, s);
                let part = Part::<f64>::new(geom, d).unwrap();
                let (pt, ps) = part.parameters(x);
                assert!((pt - t).abs() < 1e-9 && (ps - s).abs() < 1e-9, "{geom:?}: ({t}, {s}) -> ({pt}, {ps})");
                // A short segment across the surface at x, tilted off the normal.
                let n = n.scale(1.0 / n.norm());
                let tilt = vec3(0.2 * rng.random::<f64>(), 0.1, -0.15);
                let (p, q) = (x - (n + tilt).scale(0.01), x + (n - tilt).scale(0.01));
                let h = 0.01 * (d.t1 - d.t0);
                let k = 0.01 * (d.s1 - d.s0);
                let around = Part::<f64>::new(geom, Rect { t0: t - h, t1: t + h, s0: s - k, s1: s + k }).unwrap();
                assert!(around.blocks(p, q), "{geom:?} at ({t}, {s})");
                let beside =
                    Part::<f64>::new(geom, Rect { t0: t + 2.0 * h, t1: t + 4.0 * h, s0: s - k, s1: s + k }).unwrap();
                assert!(!beside.blocks(p, q), "{geom:?} at ({t}, {s})");
                // The whole surface's part blocks as the kernel's occluder does.
                assert_eq!(part.blocks(p, q), part.whole.blocks(p, q));
            }
        }
    }

    /// A segment that starts on the part itself and leaves it along the normal is not blocked
    /// by it, in f32 far from the origin too (the end point is on the surface only to f32's
    /// rounding); one that enters a closed sphere's zone from a point on it is, at its far side.
    #[test]
    fn segments_from_the_surface_itself() {
        let frame = Frame::from_axis(vec3(0.0, 0.0, 1.0)).unwrap();
        let far = vec3(50.0, 0.0, 0.0);
        let geoms = [
            Geom::Sphere { center: far, radius: 1.0, frame, inner: false },
            Geom::Cylinder { base: far, frame, radius: 0.7, height: 1.0, inner: false },
            Geom::Cone { base: far, frame, base_radius: 0.8, top_radius: 0.3, height: 1.0, inner: false },
            Geom::Disk { center: far, frame, inner: 0.0, outer: 1.0 },
        ];
        for geom in geoms {
            let d = geom.domain();
            let rect = Rect { t0: d.t0 + 0.1 * (d.t1 - d.t0), t1: d.t1 - 0.1 * (d.t1 - d.t0), s0: 0.1, s1: 3.0 };
            let shape = geom.shape::<f32>().unwrap();
            let part = Part::<f32>::new(geom, rect).unwrap();
            for i in 1..20 {
                for j in 1..20 {
                    let t = rect.t0 + (rect.t1 - rect.t0) * f64::from(i) / 20.0;
                    let s = rect.s0 + (rect.s1 - rect.s0) * f64::from(j) / 20.0;
                    let (x, n) = shape.point_and_normal(t as f32, s as f32);
                    let n = n.scale(0.3 / n.norm());
                    assert!(!part.blocks(x, x + n), "{geom:?} at ({t}, {s})");
                    assert!(!part.blocks(x + n, x), "{geom:?} at ({t}, {s})");
                }
            }
        }
        // Into the sphere from its zone: the segment leaves through the opposite side.
        let sphere = Geom::Sphere { center: far, radius: 1.0, frame, inner: false };
        let whole = Part::<f64>::new(sphere, sphere.domain()).unwrap();
        let top = vec3(50.0, 0.0, 1.0);
        assert!(whole.blocks(top, vec3(50.0, 0.0, -2.0)));
        assert!(!whole.blocks(top, vec3(50.0, 0.0, -0.5)));
    }

    /// Two halves of a surface block a segment exactly when the whole does (random segments).
    #[test]
    fn halves_block_as_the_whole() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(8);
        let mut point =
            || vec3(rng.random::<f64>() * 4.0 - 2.0, rng.random::<f64>() * 4.0 - 2.0, rng.random::<f64>() * 4.0 - 2.0);
        for geom in kinds() {
            let d = geom.domain();
            let whole = Part::<f64>::new(geom, d).unwrap();
            let (tm, sm) = (0.37 * d.t0 + 0.63 * d.t1, 0.55 * d.s0 + 0.45 * d.s1);
            let halves = [
                Part::<f64>::new(geom, Rect { t1: tm, ..d }).unwrap(),
                Part::<f64>::new(geom, Rect { t0: tm, s1: sm, ..d }).unwrap(),
                Part::<f64>::new(geom, Rect { t0: tm, s0: sm, ..d }).unwrap(),
            ];
            let mut hits = 0;
            for _ in 0..3000 {
                let (p, q) = (point(), point());
                let kernel = whole.whole.blocks(p, q);
                assert_eq!(halves.iter().any(|h| h.blocks(p, q)), kernel, "{geom:?}: {p:?} {q:?}");
                hits += usize::from(kernel);
            }
            assert!(hits > 300, "{geom:?}: {hits} blocked segments");
        }
    }

    /// A whole sphere in the scene's occluder list names itself to the kernel (which then takes
    /// a point's view of a parallelogram past it in closed form); a part of a sphere does not,
    /// and neither says anything but "nothing may cut" where nothing may.
    #[test]
    fn a_whole_sphere_names_itself_as_the_one_shadow() {
        let frame = Frame::from_axis(vec3(0.0, 0.0, 1.0)).unwrap();
        let geom = Geom::Sphere { center: vec3(0.0, 0.0, 0.0), radius: 1.0, frame, inner: false };
        let shape = geom.shape::<f64>().unwrap();
        let whole = SceneOccluder::Whole(super::super::shape::occluder_of(&shape).unwrap());
        let d = geom.domain();
        let part =
            SceneOccluder::Part(Part::<f64>::new(geom, Rect { t0: d.t0, t1: d.t1 * 0.5, s0: d.s0, s1: d.s1 }).unwrap());
        let point = |z: f64| Ball { center: vec3(0.0, 0.0, z), radius: 0.0 };
        let (below, beside) =
            (Ball { center: vec3(0.0, 0.0, -3.0), radius: 0.5 }, Ball { center: vec3(5.0, 0.0, 3.0), radius: 0.5 });
        let ball = Ball { center: vec3(0.0, 0.0, 0.0), radius: 1.0 };
        assert_eq!(whole.shadow_sphere(&point(3.0), &below), Some(Some(ball)));
        assert_eq!(part.shadow_sphere(&point(3.0), &below), None);
        assert_eq!(whole.shadow_sphere(&point(3.0), &beside), Some(None));
        assert_eq!(part.shadow_sphere(&point(3.0), &beside), Some(None));
    }
}
