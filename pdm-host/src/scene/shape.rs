//! The surfaces a scene is made of: [`Geom`], the geometry in f64 as the file gave it (the
//! source of truth, with what the scene engine needs besides the kernel: the occluder of a
//! whole surface, the plane of a flat one, conservative bounds on a patch's signed distance
//! from a plane), and [`Shape`], the kernel surface it becomes in the working precision.

use pdm_kernel::{
    vec3, AnyOccluder, BezierPatch, Cone, Cylinder, Disk, Frame, Parallelogram, ParamRect, Patch, PdmError, Quadric,
    Quadrilateral, Real, Side, Sphere, Surface, Vec3,
};

/// One kernel surface of a scene: a built-in kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape<T> {
    /// A parallelogram (rectangle).
    Parallelogram(Parallelogram<T>),
    /// A disk or annulus (sectors by the patch's parameter range).
    Disk(Disk<T>),
    /// A sphere (zones and lunes by the parameter range).
    Sphere(Sphere<T>),
    /// An open tube.
    Cylinder(Cylinder<T>),
    /// A cone or frustum.
    Cone(Cone<T>),
    /// A bicubic Bézier patch.
    Bezier(BezierPatch<T>),
    /// A flat convex quadrilateral or triangle (a mesh facet).
    Quadrilateral(Quadrilateral<T>),
}

macro_rules! each {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Shape::Parallelogram($s) => $e,
            Shape::Disk($s) => $e,
            Shape::Sphere($s) => $e,
            Shape::Cylinder($s) => $e,
            Shape::Cone($s) => $e,
            Shape::Bezier($s) => $e,
            Shape::Quadrilateral($s) => $e,
        }
    };
}

impl<T: Real> Surface<T> for Shape<T> {
    fn domain(&self) -> ParamRect<T> {
        each!(self, s => s.domain())
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        each!(self, g => g.point(t, s))
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        each!(self, g => g.normal(t, s))
    }
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        each!(self, g => g.point_and_normal(t, s))
    }
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        each!(self, g => g.affine_map())
    }
    fn convex_ball(&self) -> Option<pdm_kernel::Ball<T>> {
        each!(self, g => g.convex_ball())
    }
    fn on_sphere(&self) -> Option<pdm_kernel::Ball<T>> {
        each!(self, g => g.on_sphere())
    }
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        each!(self, g => g.point_and_partials(t, s))
    }
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        each!(self, g => g.straight_corners(rect))
    }
    fn facing_along_t(&self, s: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        each!(self, g => g.facing_along_t(s, p, np))
    }
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        each!(self, g => g.facing_across_s(p, np))
    }
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(Quadric<T>)) -> bool {
        each!(self, g => g.event_quadrics(rect, out))
    }
}

/// A plane n̂·(x − o) = 0 with unit normal n̂ (f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point of the plane.
    pub origin: Vec3<f64>,
    /// Unit normal.
    pub normal: Vec3<f64>,
}

impl Plane {
    /// Signed distance of x from the plane.
    #[must_use]
    pub fn distance(&self, x: Vec3<f64>) -> f64 {
        self.normal.dot(x - self.origin)
    }
}

/// A parameter rectangle in f64.
pub type Rect = ParamRect<f64>;

/// One surface's geometry in f64, after rotation and translation, with its radiating side.
/// The fields are the kernel constructors' arguments of the same names.
#[allow(missing_docs)]
#[allow(clippy::large_enum_variant)] // a scene holds a few of them; Copy matters more
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geom {
    /// g(t, s) = origin + t·edge_t + s·edge_s on [0, 1]², radiating towards edge_t × edge_s.
    Parallelogram { origin: Vec3<f64>, edge_t: Vec3<f64>, edge_s: Vec3<f64> },
    /// The annulus r ∈ [inner, outer] around `center` in the plane normal to `frame.axis`,
    /// radiating towards the axis; t = r, s = θ.
    Disk { center: Vec3<f64>, frame: Frame<f64>, inner: f64, outer: f64 },
    /// t = φ from the axis, s = θ; `inner`: radiating inwards.
    Sphere { center: Vec3<f64>, radius: f64, frame: Frame<f64>, inner: bool },
    /// t = θ, s = z ∈ [0, height].
    Cylinder { base: Vec3<f64>, frame: Frame<f64>, radius: f64, height: f64, inner: bool },
    /// t = θ, s = z; radius r₀ + (r₁ − r₀) z / h.
    Cone { base: Vec3<f64>, frame: Frame<f64>, base_radius: f64, top_radius: f64, height: f64, inner: bool },
    /// Control net, rows along t.
    Bezier { control: [[Vec3<f64>; 4]; 4] },
    /// The bilinear map of four coplanar corners, counter-clockwise about the radiating side (a
    /// triangle repeats its first corner last).
    Quadrilateral { corners: [Vec3<f64>; 4] },
}

/// The corners of a parallelogram's patch on `r` (it is their convex hull).
pub fn corners(origin: Vec3<f64>, edge_t: Vec3<f64>, edge_s: Vec3<f64>, r: Rect) -> impl Iterator<Item = Vec3<f64>> {
    [(r.t0, r.s0), (r.t1, r.s0), (r.t0, r.s1), (r.t1, r.s1)]
        .into_iter()
        .map(move |(t, s)| origin + edge_t.scale(t) + edge_s.scale(s))
}

/// The bilinear map of four corners at (t, s) (`pdm_kernel::Quadrilateral`'s map).
#[must_use]
pub fn bilinear(c: &[Vec3<f64>; 4], t: f64, s: f64) -> Vec3<f64> {
    let [p0, p1, p2, p3] = *c;
    p0.scale((1.0 - t) * (1.0 - s)) + p1.scale(t * (1.0 - s)) + p2.scale(t * s) + p3.scale((1.0 - t) * s)
}

/// The control points of the cubic Bézier segment `c` (over [0, 1]) restricted to [a, b]: its
/// blossom at (a, a, a), (a, a, b), (a, b, b), (b, b, b).
fn cubic_sub_segment(c: [Vec3<f64>; 4], a: f64, b: f64) -> [Vec3<f64>; 4] {
    let blossom = |u: [f64; 3]| {
        let mut p = c;
        for (level, &x) in u.iter().enumerate() {
            for k in 0..3 - level {
                p[k] = p[k].scale(1.0 - x) + p[k + 1].scale(x);
            }
        }
        p[0]
    };
    [blossom([a, a, a]), blossom([a, a, b]), blossom([a, b, b]), blossom([b, b, b])]
}

/// The control net of the bicubic Bézier patch `control` (t along the first index, s along the
/// second, as `pdm_kernel::BezierPatch`) over the sub-rectangle `r` of [0, 1]².
fn bezier_sub_net(control: &[[Vec3<f64>; 4]; 4], r: Rect) -> [[Vec3<f64>; 4]; 4] {
    let rows = control.map(|row| cubic_sub_segment(row, r.s0, r.s1));
    let mut net = rows;
    for j in 0..4 {
        let column = cubic_sub_segment([rows[0][j], rows[1][j], rows[2][j], rows[3][j]], r.t0, r.t1);
        for (i, p) in column.into_iter().enumerate() {
            net[i][j] = p;
        }
    }
    net
}

/// Bounds [min, max] of a cos θ + b sin θ over θ ∈ [θ₀, θ₁] (exact: the ends and the
/// stationary points inside).
fn trig_range(a: f64, b: f64, t0: f64, t1: f64) -> (f64, f64) {
    let f = |t: f64| a * t.cos() + b * t.sin();
    let (mut lo, mut hi) = (f(t0).min(f(t1)), f(t0).max(f(t1)));
    if a != 0.0 || b != 0.0 {
        let peak = b.atan2(a);
        let first = ((t0 - peak) / core::f64::consts::PI).ceil();
        let last = ((t1 - peak) / core::f64::consts::PI).floor();
        let mut k = first;
        while k <= last {
            let v = f(peak + k * core::f64::consts::PI);
            lo = lo.min(v);
            hi = hi.max(v);
            k += 1.0;
        }
    }
    (lo, hi)
}

fn to_t<T: Real>(v: Vec3<f64>) -> Vec3<T> {
    vec3(T::from_f64(v.x), T::from_f64(v.y), T::from_f64(v.z))
}

fn side(inner: bool) -> Side {
    if inner {
        Side::Inner
    } else {
        Side::Outer
    }
}

impl Geom {
    /// The kernel surface in precision `T` (its constructors check the geometry once more).
    pub fn shape<T: Real>(&self) -> Result<Shape<T>, PdmError> {
        let r = T::from_f64;
        Ok(match *self {
            Self::Parallelogram { origin, edge_t, edge_s } => {
                Shape::Parallelogram(Parallelogram::new(to_t(origin), to_t(edge_t), to_t(edge_s))?)
            }
            Self::Disk { center, frame, inner, outer } => {
                Shape::Disk(Disk::annulus(to_t(center), to_t(frame.axis), r(inner), r(outer))?)
            }
            Self::Sphere { center, radius, frame, inner } => {
                let frame = Frame { u: to_t(frame.u), w: to_t(frame.w), axis: to_t(frame.axis) };
                Shape::Sphere(Sphere::with_frame(to_t(center), r(radius), frame, side(inner))?)
            }
            Self::Cylinder { base, frame, radius, height, inner } => {
                Shape::Cylinder(Cylinder::new(to_t(base), to_t(frame.axis), r(radius), r(height), side(inner))?)
            }
            Self::Cone { base, frame, base_radius, top_radius, height, inner } => Shape::Cone(Cone::new(
                to_t(base),
                to_t(frame.axis),
                r(base_radius),
                r(top_radius),
                r(height),
                side(inner),
            )?),
            Self::Bezier { control } => Shape::Bezier(BezierPatch::new(control.map(|row| row.map(to_t)))?),
            Self::Quadrilateral { corners } => Shape::Quadrilateral(Quadrilateral::new(corners.map(to_t))?),
        })
    }

    /// The same geometry moved by `shift` (frames, radii and edges unchanged).
    #[must_use]
    pub fn translated(&self, shift: Vec3<f64>) -> Self {
        match *self {
            Self::Parallelogram { origin, edge_t, edge_s } => {
                Self::Parallelogram { origin: origin + shift, edge_t, edge_s }
            }
            Self::Disk { center, frame, inner, outer } => Self::Disk { center: center + shift, frame, inner, outer },
            Self::Sphere { center, radius, frame, inner } => {
                Self::Sphere { center: center + shift, radius, frame, inner }
            }
            Self::Cylinder { base, frame, radius, height, inner } => {
                Self::Cylinder { base: base + shift, frame, radius, height, inner }
            }
            Self::Cone { base, frame, base_radius, top_radius, height, inner } => {
                Self::Cone { base: base + shift, frame, base_radius, top_radius, height, inner }
            }
            Self::Bezier { control } => Self::Bezier { control: control.map(|row| row.map(|p| p + shift)) },
            Self::Quadrilateral { corners } => Self::Quadrilateral { corners: corners.map(|p| p + shift) },
        }
    }

    /// The parameter domain of the whole kind (the file's ranges select a part of it).
    #[must_use]
    pub fn domain(&self) -> Rect {
        let two_pi = 2.0 * core::f64::consts::PI;
        let (t1, s1) = match *self {
            Self::Parallelogram { .. } | Self::Bezier { .. } | Self::Quadrilateral { .. } => (1.0, 1.0),
            Self::Disk { outer, .. } => (outer, two_pi),
            Self::Sphere { .. } => (core::f64::consts::PI, two_pi),
            Self::Cylinder { height, .. } | Self::Cone { height, .. } => (two_pi, height),
        };
        let t0 = match *self {
            Self::Disk { inner, .. } => inner,
            _ => 0.0,
        };
        ParamRect { t0, t1, s0: 0.0, s1 }
    }

    /// The plane of a flat kind (parallelogram, disk, quadrilateral, flat Bézier net), its normal on the radiating side.
    #[must_use]
    pub fn plane(&self) -> Option<Plane> {
        match *self {
            Self::Parallelogram { origin, edge_t, edge_s } => {
                let n = edge_t.cross(edge_s);
                Some(Plane { origin, normal: n.scale(1.0 / n.norm()) })
            }
            Self::Disk { center, frame, .. } => Some(Plane { origin: center, normal: frame.axis }),
            Self::Quadrilateral { corners: [p0, p1, p2, p3] } => {
                let n = (p2 - p0).cross(p3 - p1);
                Some(Plane { origin: p0, normal: n.scale(1.0 / n.norm()) })
            }
            Self::Bezier { control } => {
                // A flat net (a mesh facet): its control points in one plane, normal to the
                // diagonals of the corners, on the side of ∂g/∂t × ∂g/∂s.
                let [p00, p30, p03, p33] = [control[0][0], control[3][0], control[0][3], control[3][3]];
                let n = (p33 - p00).cross(p03 - p30);
                let length = n.norm();
                let size = control.iter().flatten().map(|p| (*p - p00).norm()).fold(0.0, f64::max);
                if !(length > 0.0) {
                    return None;
                }
                let normal = n.scale(1.0 / length);
                let flat = control.iter().flatten().all(|p| normal.dot(*p - p00).abs() <= 1e-12 * size);
                flat.then_some(Plane { origin: p00, normal })
            }
            _ => None,
        }
    }

    /// Whether the radiating side may be concave (the inside of a sphere, tube or cone; a Bézier
    /// piece unless it is sampled convex): such a surface can hide parts of the scene from its
    /// own patches.
    #[must_use]
    pub fn concave(&self) -> bool {
        match *self {
            Self::Sphere { inner, .. } | Self::Cylinder { inner, .. } | Self::Cone { inner, .. } => inner,
            Self::Bezier { .. } => {
                // Sampled: the radiating side is convex if every sample of a 9 × 9 grid lies
                // behind (or on) the tangent plane at every other sample (the surface of a
                // convex solid); otherwise it may hide parts of the scene from its own patches.
                let Ok(shape) = self.shape::<f64>() else { return true };
                use pdm_kernel::Surface as _;
                const N: usize = 9;
                let samples: Vec<_> = (0..N * N)
                    .map(|k| shape.point_and_normal((k / N) as f64 / (N - 1) as f64, (k % N) as f64 / (N - 1) as f64))
                    .collect();
                let size = samples.iter().map(|(p, _)| (*p - samples[0].0).norm()).fold(0.0, f64::max);
                samples.iter().any(|&(c, n)| {
                    let length = n.norm();
                    !(length > 0.0) || samples.iter().any(|&(p, _)| n.dot(p - c) / length > 1e-9 * size)
                })
            }
            _ => false,
        }
    }

    /// Conservative bounds [min, max] of the signed distance from `plane` over the patch on
    /// `rect`: exact for parallelograms, quadrilaterals, disks, tubes and cones (closed-form extremes), the
    /// control points for a whole Bézier net (its convex hull holds it), the patch's enclosing
    /// ball ([`Patch::enclosing_ball`]) for spheres and parts of Bézier nets.
    #[must_use]
    pub fn distance_range(&self, rect: Rect, plane: &Plane) -> (f64, f64) {
        let n = plane.normal;
        match *self {
            Self::Parallelogram { origin, edge_t, edge_s } => corners(origin, edge_t, edge_s, rect)
                .map(|x| plane.distance(x))
                .fold((f64::MAX, -f64::MAX), |(lo, hi), d| (lo.min(d), hi.max(d))),
            // A patch of the bilinear map is the convex quadrilateral of its corners' images.
            Self::Quadrilateral { corners } => {
                [(rect.t0, rect.s0), (rect.t1, rect.s0), (rect.t1, rect.s1), (rect.t0, rect.s1)]
                    .into_iter()
                    .map(|(t, s)| plane.distance(bilinear(&corners, t, s)))
                    .fold((f64::MAX, -f64::MAX), |(lo, hi), d| (lo.min(d), hi.max(d)))
            }
            Self::Disk { center, frame, .. } => {
                let c = plane.distance(center);
                let (lo, hi) = trig_range(n.dot(frame.u), n.dot(frame.w), rect.s0, rect.s1);
                // r ≥ 0 scales the angular part: the extremes lie at the radial ends.
                let (a, b) = (rect.t0, rect.t1);
                (c + (a * lo).min(b * lo), c + (a * hi).max(b * hi))
            }
            Self::Cylinder { base, frame, radius, .. } => {
                let c = plane.distance(base);
                let (lo, hi) = trig_range(n.dot(frame.u), n.dot(frame.w), rect.t0, rect.t1);
                let g = n.dot(frame.axis);
                let (z0, z1) = ((g * rect.s0).min(g * rect.s1), (g * rect.s0).max(g * rect.s1));
                (c + radius * lo + z0, c + radius * hi + z1)
            }
            Self::Cone { base, frame, base_radius, top_radius, height, .. } => {
                // Linear in z for each θ: the extremes lie on the two z ends.
                let c = plane.distance(base);
                let (lo, hi) = trig_range(n.dot(frame.u), n.dot(frame.w), rect.t0, rect.t1);
                let g = n.dot(frame.axis);
                let mut range = (f64::MAX, -f64::MAX);
                for z in [rect.s0, rect.s1] {
                    let radius = base_radius + (top_radius - base_radius) * z / height;
                    range.0 = range.0.min(c + radius * lo + g * z);
                    range.1 = range.1.max(c + radius * hi + g * z);
                }
                range
            }
            // The net of the patch (the whole net, or the part over `rect` by blossoming): the
            // convex hull of its control points holds the surface.
            Self::Bezier { control } => {
                let d = bezier_sub_net(&control, rect).into_iter().flatten().map(|p| plane.distance(p));
                d.fold((f64::MAX, -f64::MAX), |(lo, hi), x| (lo.min(x), hi.max(x)))
            }
            Self::Sphere { .. } => match self.shape::<f64>() {
                Ok(shape) => match Patch::new(&shape, rect) {
                    Ok(patch) => {
                        let ball = patch.enclosing_ball();
                        let c = plane.distance(ball.center);
                        (c - ball.radius, c + ball.radius)
                    }
                    Err(_) => (-f64::MAX, f64::MAX),
                },
                Err(_) => (-f64::MAX, f64::MAX),
            },
        }
    }

    /// Balls (centre, radius; points have radius 0) whose union's convex hull holds the patch
    /// on `rect`: the corners of a flat patch with straight edges, a Bézier patch's sub-net,
    /// the two end circles of a tube's or cone's patch (each point is the convex combination of
    /// the end circles' points at its θ), the whole disk or sphere. A convex 1-Lipschitz
    /// function (the distance from a point or a line) is at most max(f(c) + ρ) over them.
    /// Each ball is either a point or circle of the patch itself (the circles are its edges)
    /// or holds the whole patch, so the points the hull needs lie within the patch's own
    /// extent along any direction (`inside_solid` relies on that).
    #[must_use]
    pub fn cover(&self, rect: Rect) -> Vec<(Vec3<f64>, f64)> {
        match *self {
            Self::Parallelogram { origin, edge_t, edge_s } => {
                corners(origin, edge_t, edge_s, rect).map(|x| (x, 0.0)).collect()
            }
            Self::Quadrilateral { corners } => {
                [(rect.t0, rect.s0), (rect.t1, rect.s0), (rect.t1, rect.s1), (rect.t0, rect.s1)]
                    .into_iter()
                    .map(|(t, s)| (bilinear(&corners, t, s), 0.0))
                    .collect()
            }
            Self::Bezier { control } => {
                bezier_sub_net(&control, rect).into_iter().flatten().map(|x| (x, 0.0)).collect()
            }
            Self::Disk { center, outer, .. } => vec![(center, outer)],
            Self::Sphere { center, radius, .. } => vec![(center, radius)],
            Self::Cylinder { base, frame, radius, .. } => {
                [rect.s0, rect.s1].into_iter().map(|z| (base + frame.axis.scale(z), radius)).collect()
            }
            Self::Cone { base, frame, base_radius, top_radius, height, .. } => [rect.s0, rect.s1]
                .into_iter()
                .map(|z| (base + frame.axis.scale(z), base_radius + (top_radius - base_radius) * z / height))
                .collect(),
        }
    }
}

/// The built-in occluder of a whole surface in precision `T` (the Bézier patch's to
/// `pdm_kernel::visibility::BEZIER_FLATNESS`).
#[must_use]
pub fn occluder_of<T: Real>(shape: &Shape<T>) -> Option<AnyOccluder<T>> {
    match *shape {
        Shape::Parallelogram(p) => Some(AnyOccluder::Parallelogram(p)),
        Shape::Disk(d) => Some(AnyOccluder::Disk(d)),
        Shape::Sphere(s) => Some(AnyOccluder::Sphere(s)),
        Shape::Cylinder(c) => Some(AnyOccluder::Cylinder(c)),
        Shape::Cone(c) => Some(AnyOccluder::Cone(c)),
        Shape::Bezier(b) => Some(AnyOccluder::Bezier(b)),
        Shape::Quadrilateral(q) => Some(AnyOccluder::Quadrilateral(q)),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn dish() -> [[Vec3<f64>; 4]; 4] {
        // A bowl, skewed so that no axis is special.
        core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let (x, y) = (i as f64 / 3.0 - 0.5, j as f64 / 3.0 - 0.5);
                vec3(x + 0.1 * y, y, 0.6 + x * x + 0.7 * y * y + 0.2 * x * y)
            })
        })
    }

    #[test]
    fn a_bezier_sub_net_is_the_patch_over_its_rectangle() {
        let control = dish();
        let whole = BezierPatch::new(control).unwrap();
        let r = Rect { t0: 0.25, t1: 0.75, s0: 0.5, s1: 0.875 };
        let part = BezierPatch::new(bezier_sub_net(&control, r)).unwrap();
        for (u, v) in [(0.0, 0.0), (1.0, 1.0), (0.3, 0.9), (0.5, 0.1), (1.0, 0.0)] {
            let (t, s) = (r.t0 + u * (r.t1 - r.t0), r.s0 + v * (r.s1 - r.s0));
            let (p, q) = (whole.point(t, s), part.point(u, v));
            assert!((p - q).norm() < 1e-14, "({u}, {v}): {p:?} against {q:?}");
        }
    }

    #[test]
    fn a_bezier_cell_above_a_plane_is_bounded_by_its_own_net() {
        // The cell's net is a tighter bound than a ball around the cell: a plane below the
        // bowl's bottom that the ball of a wall cell would reach.
        let geom = Geom::Bezier { control: dish() };
        let plane = Plane { origin: vec3(0.0, 0.0, 0.55), normal: vec3(0.0, 0.0, 1.0) };
        let r = Rect { t0: 0.5, t1: 1.0, s0: 0.5, s1: 1.0 };
        let (lo, hi) = geom.distance_range(r, &plane);
        let shape = BezierPatch::new(dish()).unwrap();
        let (mut slo, mut shi) = (f64::MAX, -f64::MAX);
        for k in 0..=20 {
            for l in 0..=20 {
                let p = shape.point(0.5 + k as f64 / 40.0, 0.5 + l as f64 / 40.0);
                let d = plane.distance(p);
                (slo, shi) = (slo.min(d), shi.max(d));
            }
        }
        assert!(lo <= slo && shi <= hi, "[{lo}, {hi}] does not hold [{slo}, {shi}]");
        assert!(lo > 0.0, "the cell lies above the plane: {lo}");
    }
}
