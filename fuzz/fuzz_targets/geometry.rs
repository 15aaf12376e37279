//! Arbitrary bytes as geometry: two patches (parallelograms, spheres, disks, cylinders, cones,
//! Bézier patches, or a second patch derived from the first so that they share an edge or a
//! corner), built from raw f64/f32 bit patterns (so NaN, ±∞, subnormals and 1e±300 appear) and
//! from small integers and dyadic numbers (so exact contact is common), then every entry point
//! that pairs two patches: `classify`, `classify_near`, `touching_exchange` (with the found and
//! with an arbitrary adjacency and gap), `pair_exchange` (with and without visibility
//! boundaries), `form_factor_between`, `self_form_factor`, `surface_form_factor`, with and
//! without an occluder, in f32 or f64.
//!
//! The tolerance mode (`adaptive_exchange`, max order 6, max depth 2 so one input stays cheap)
//! and `pair_exchange` both ways round are called too.
//!
//! Asserted: no panic (libFuzzer reports it); every `Ok` is finite and ≥ 0; every `Ok` obeys
//! the physical bounds the kernel checks since bounds.rs: a form factor F ≤ 1 + rounding, an
//! exchange A_a·F_ab ≤ min(A_a, A_b) + rounding, with the areas measured at order 16 (or at the
//! order the kernel used, whichever is larger: a low-order area of a curved patch may be
//! short); the adaptive estimate finite and ≥ 0. See pdm-host/FUZZING.md.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use pdm_kernel::{adaptive_exchange, Ball, Quadric, form_factor_between, pair_exchange, self_form_factor, surface_form_factor, vec3, AnyOccluder, BezierPatch, Cone, Cylinder, Disk, Frame, PairSettings, Adaptive, Parallelogram, ParamRect, Patch, PatchGrid, PdmError, Quadrature, Real, Side, Sphere, Surface, Vec3};
use pdm_kernel::internals::{classify, classify_near, touching_exchange, Adjacency, SquareMap};

/// Sample capacity: (order + 1)² for order ≤ 6 (the self integral uses order + 1).
const CAP: usize = 49;

/// The tolerance mode's settings here: max order 6 (its separate pairs start at ≥ 6 and
/// compare with order + 2, so it needs (6 + 2)² samples), depth ≤ 2 (≤ 4 leaf pairs).
const ADAPTIVE_MAX_ORDER: usize = 6;
const ADAPTIVE_CAP: usize = (ADAPTIVE_MAX_ORDER + 2) * (ADAPTIVE_MAX_ORDER + 2);

/// A number: raw bits (anything, NaN and ∞ included), a small integer, or m·2^e.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Num {
    Bits(u64),
    Bits32(u32),
    Int(i8),
    Dyadic(i16, i8),
}

impl Num {
    fn get<T: Real>(self) -> T {
        match self {
            Num::Bits(b) => T::from_f64(f64::from_bits(b)),
            Num::Bits32(b) => T::from_f64(f64::from(f32::from_bits(b))),
            Num::Int(i) => T::from_f64(f64::from(i)),
            Num::Dyadic(m, e) => T::from_f64(f64::from(m) * 2f64.powi(i32::from(e))),
        }
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
struct V(Num, Num, Num);

impl V {
    fn get<T: Real>(self) -> Vec3<T> {
        vec3(self.0.get(), self.1.get(), self.2.get())
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum ShapeSpec {
    Parallelogram {
        origin: V,
        edge_t: V,
        edge_s: V,
        reversed: bool,
    },
    Sphere {
        center: V,
        radius: Num,
        inner: bool,
        axis: Option<V>,
    },
    Disk {
        center: V,
        axis: V,
        inner: Num,
        outer: Num,
    },
    Cylinder {
        base: V,
        axis: V,
        radius: Num,
        height: Num,
        inner: bool,
    },
    Cone {
        base: V,
        axis: V,
        r0: Num,
        r1: Num,
        height: Num,
        inner: bool,
    },
    /// A bicubic patch: a flat grid (origin, edges) with arbitrary offsets of four control points.
    Bezier {
        origin: V,
        edge_t: V,
        edge_s: V,
        bumps: [(u8, V); 4],
    },
}

/// The second patch.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum SecondSpec {
    Shape(ShapeSpec, RectSpec),
    /// A parallelogram on the segment between corners `from` and `to` of the first patch.
    SharedEdge {
        from: u8,
        to: u8,
        other: V,
        reversed: bool,
    },
    /// A parallelogram with one corner on a corner of the first patch.
    SharedVertex {
        corner: u8,
        edge_t: V,
        edge_s: V,
    },
    /// The patch of the first patch's surface next to it in parameter space (shares a true edge,
    /// curved or not), or diagonally next to it (shares a corner).
    Neighbour {
        side: u8,
        extent: u8,
    },
    /// The first patch again.
    Same,
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum RectSpec {
    Whole,
    /// Fractions (k/255) of the domain.
    Fraction(u8, u8, u8, u8),
    /// Raw bounds (may be outside the domain, empty or NaN).
    Raw(Num, Num, Num, Num),
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum OccluderSpec {
    Sphere(V, Num),
    Parallelogram(V, V, V),
    Disk(V, V, Num),
    Cylinder(V, V, Num, Num),
}

#[derive(Arbitrary, Debug, Clone, Copy)]
struct Input {
    wide: bool,
    first: ShapeSpec,
    first_rect: RectSpec,
    second: SecondSpec,
    order_a: u8,
    order_b: u8,
    singular_order: u8,
    grid: [u8; 4],
    boundaries: bool,
    occluder: Option<OccluderSpec>,
    /// An arbitrary adjacency handed to `touching_exchange` (corner maps from corner indices).
    forced: Option<(bool, bool, Num)>,
    /// The tolerance mode: `None` skips it; a tolerance 10^−(1 + k % 10), or a raw number.
    adaptive: Option<(u8, Option<Num>, u8)>,
}

/// Any of the built-ins, as one type so that a patch and its neighbour share it.
enum Shape<T> {
    Parallelogram(Parallelogram<T>),
    Sphere(Sphere<T>),
    Disk(Disk<T>),
    Cylinder(Cylinder<T>),
    Cone(Cone<T>),
    Bezier(BezierPatch<T>),
}

macro_rules! each {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Shape::Parallelogram($s) => $e,
            Shape::Sphere($s) => $e,
            Shape::Disk($s) => $e,
            Shape::Cylinder($s) => $e,
            Shape::Cone($s) => $e,
            Shape::Bezier($s) => $e,
        }
    };
}

impl<T: Real> Surface<T> for Shape<T> {
    fn domain(&self) -> ParamRect<T> {
        each!(self, s => s.domain())
    }
    fn point(&self, t: T, s: T) -> Vec3<T> {
        each!(self, x => x.point(t, s))
    }
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        each!(self, x => x.normal(t, s))
    }
    fn point_and_normal(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        each!(self, x => x.point_and_normal(t, s))
    }
    // Every closed-form hook forwarded, so that inputs reach the closed-form paths (the contour
    // form, the trigonometric inner rule, the outer events) as the built-ins do.
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        each!(self, x => x.affine_map())
    }
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        each!(self, x => x.point_and_partials(t, s))
    }
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        each!(self, x => x.straight_corners(rect))
    }
    fn facing_along_t(&self, s: T, p: Vec3<T>, np: Vec3<T>) -> Option<[[T; 3]; 2]> {
        each!(self, x => x.facing_along_t(s, p, np))
    }
    fn facing_across_s(&self, p: Vec3<T>, np: Vec3<T>) -> Option<[[[T; 3]; 3]; 2]> {
        each!(self, x => x.facing_across_s(p, np))
    }
    fn event_quadrics(&self, rect: ParamRect<T>, out: &mut dyn FnMut(Quadric<T>)) -> bool {
        each!(self, x => x.event_quadrics(rect, out))
    }
    fn convex_ball(&self) -> Option<Ball<T>> {
        each!(self, x => x.convex_ball())
    }
    fn on_sphere(&self) -> Option<Ball<T>> {
        each!(self, x => x.on_sphere())
    }
}

fn side(inner: bool) -> Side {
    if inner {
        Side::Inner
    } else {
        Side::Outer
    }
}

fn build<T: Real>(spec: ShapeSpec) -> Result<Shape<T>, PdmError> {
    Ok(match spec {
        ShapeSpec::Parallelogram { origin, edge_t, edge_s, reversed } => {
            let p = Parallelogram::new(origin.get(), edge_t.get(), edge_s.get())?;
            Shape::Parallelogram(if reversed { p.reversed() } else { p })
        }
        ShapeSpec::Sphere { center, radius, inner, axis } => match axis {
            None => Shape::Sphere(Sphere::new(center.get(), radius.get(), side(inner))?),
            Some(axis) => Shape::Sphere(Sphere::with_frame(
                center.get(),
                radius.get(),
                Frame::from_axis(axis.get())?,
                side(inner),
            )?),
        },
        ShapeSpec::Disk { center, axis, inner, outer } => {
            Shape::Disk(Disk::annulus(center.get(), axis.get(), inner.get(), outer.get())?)
        }
        ShapeSpec::Cylinder { base, axis, radius, height, inner } => {
            Shape::Cylinder(Cylinder::new(base.get(), axis.get(), radius.get(), height.get(), side(inner))?)
        }
        ShapeSpec::Cone { base, axis, r0, r1, height, inner } => {
            Shape::Cone(Cone::new(base.get(), axis.get(), r0.get(), r1.get(), height.get(), side(inner))?)
        }
        ShapeSpec::Bezier { origin, edge_t, edge_s, bumps } => {
            let (o, et, es) = (origin.get::<T>(), edge_t.get::<T>(), edge_s.get::<T>());
            let mut control = [[Vec3::ZERO; 4]; 4];
            for (i, row) in control.iter_mut().enumerate() {
                for (j, p) in row.iter_mut().enumerate() {
                    let (fi, fj) = (T::from_usize(i) / T::from_f64(3.0), T::from_usize(j) / T::from_f64(3.0));
                    *p = o + et.scale(fi) + es.scale(fj);
                }
            }
            for (k, bump) in bumps {
                let (i, j) = (usize::from(k & 3), usize::from((k >> 2) & 3));
                if let Some(p) = control.get_mut(i).and_then(|r| r.get_mut(j)) {
                    *p = *p + bump.get();
                }
            }
            Shape::Bezier(BezierPatch::new(control)?)
        }
    })
}

fn rect<T: Real>(spec: RectSpec, domain: ParamRect<T>) -> Result<ParamRect<T>, PdmError> {
    match spec {
        RectSpec::Whole => Ok(domain),
        RectSpec::Fraction(a, b, c, d) => {
            let f = |lo: T, hi: T, k: u8| lo + (hi - lo) * T::from_f64(f64::from(k) / 255.0);
            let (t0, t1) = (f(domain.t0, domain.t1, a.min(b)), f(domain.t0, domain.t1, a.max(b)));
            let (s0, s1) = (f(domain.s0, domain.s1, c.min(d)), f(domain.s0, domain.s1, c.max(d)));
            ParamRect::new(t0, t1, s0, s1)
        }
        RectSpec::Raw(a, b, c, d) => ParamRect::new(a.get(), b.get(), c.get(), d.get()),
    }
}

fn corners<T: Real>(p: &Patch<'_, T, Shape<T>>) -> [Vec3<T>; 4] {
    let (r, s) = (p.rect(), p.surface());
    [s.point(r.t0, r.s0), s.point(r.t1, r.s0), s.point(r.t0, r.s1), s.point(r.t1, r.s1)]
}

fn order(k: u8) -> usize {
    // 0 and 7 are out of range for CAP (0: UnsupportedOrder, 7: CapacityExceeded).
    usize::from(k % 8)
}

/// Every `Ok` must be a finite number ≥ 0.
fn check<T: Real>(what: &str, r: Result<T, PdmError>) -> Option<T> {
    match r {
        Ok(v) => {
            assert!(v.is_finite() && v >= T::ZERO, "{what}: Ok({v}) is not finite and >= 0");
            Some(v)
        }
        Err(_) => None,
    }
}

/// Relative rounding band above a physical bound: the kernel clamps within 1024 ε; 4096 ε here
/// (9e-13 in f64, 4.9e-4 in f32).
fn band<T: Real>() -> T {
    T::from_f64(4096.0) * T::EPSILON
}

/// A patch's area for the bound checks: the larger of order 16 and the order the kernel used
/// (`None` if neither is a usable positive number).
fn area_for_bounds<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>, order: usize) -> Option<T> {
    let a = p.area(16).ok().filter(|a| a.is_finite() && *a > T::ZERO);
    let b = p.area(order.max(2)).ok().filter(|a| a.is_finite() && *a > T::ZERO);
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (x, y) => x.or(y),
    }
}

/// Every `Ok` exchange must be finite, ≥ 0 and ≤ min(A_a, A_b) (+ rounding).
fn check_exchange<T: Real, SA: Surface<T> + ?Sized, SB: Surface<T> + ?Sized>(
    what: &str,
    r: Result<T, PdmError>,
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
) -> Option<T> {
    let v = check(what, r)?;
    if let (Some(area_a), Some(area_b)) = (area_for_bounds(a, order), area_for_bounds(b, order)) {
        let bound = area_a.min(area_b);
        assert!(
            v <= bound * (T::ONE + band::<T>()),
            "{what}: A_a·F_ab = {v} > min(A_a, A_b) = {bound} (A_a {area_a}, A_b {area_b})"
        );
    }
    Some(v)
}

/// Every `Ok` form factor must be finite and in [0, 1 + rounding].
fn check_factor<T: Real>(what: &str, r: Result<T, PdmError>) -> Option<T> {
    let v = check(what, r)?;
    assert!(v <= T::ONE + band::<T>(), "{what}: F = {v} > 1");
    Some(v)
}

fn occluder<T: Real>(spec: OccluderSpec) -> Option<AnyOccluder<T>> {
    match spec {
        OccluderSpec::Sphere(c, r) => Sphere::outer(c.get(), r.get()).ok().map(AnyOccluder::Sphere),
        OccluderSpec::Parallelogram(o, a, b) => {
            Parallelogram::new(o.get(), a.get(), b.get()).ok().map(AnyOccluder::Parallelogram)
        }
        OccluderSpec::Disk(c, a, r) => Disk::new(c.get(), a.get(), r.get()).ok().map(AnyOccluder::Disk),
        OccluderSpec::Cylinder(b, a, r, h) => {
            Cylinder::new(b.get(), a.get(), r.get(), h.get(), Side::Outer).ok().map(AnyOccluder::Cylinder)
        }
    }
}

fn run<T: Real>(input: &Input) {
    let Ok(first) = build::<T>(input.first) else {
        return;
    };
    let Ok(first_rect) = rect(input.first_rect, first.domain()) else {
        return;
    };
    let Ok(a) = Patch::new(&first, first_rect) else {
        return;
    };
    let ca = corners(&a);
    // The second surface (unused for Neighbour/Same, which reuse the first).
    let second = match input.second {
        SecondSpec::Shape(spec, _) => build::<T>(spec).ok(),
        SecondSpec::SharedEdge { from, to, other, reversed } => {
            let (p, q) = (ca[usize::from(from & 3)], ca[usize::from(to & 3)]);
            Parallelogram::new(p, q - p, other.get())
                .ok()
                .map(|x| Shape::Parallelogram(if reversed { x.reversed() } else { x }))
        }
        SecondSpec::SharedVertex { corner, edge_t, edge_s } => {
            Parallelogram::new(ca[usize::from(corner & 3)], edge_t.get(), edge_s.get()).ok().map(Shape::Parallelogram)
        }
        SecondSpec::Neighbour { .. } | SecondSpec::Same => None,
    };
    let b = match (input.second, &second) {
        (SecondSpec::Shape(_, spec), Some(s)) => {
            let Ok(r) = rect(spec, s.domain()) else {
                return;
            };
            Patch::new(s, r)
        }
        (SecondSpec::SharedEdge { .. } | SecondSpec::SharedVertex { .. }, Some(s)) => Patch::whole(s),
        (SecondSpec::Neighbour { side, extent }, _) => {
            let (r, d) = (a.rect(), first.domain());
            let f = T::from_f64(f64::from(extent) / 255.0);
            let (t_up, s_up) = (r.t1 + (d.t1 - r.t1) * f, r.s1 + (d.s1 - r.s1) * f);
            let (t_down, s_down) = (r.t0 - (r.t0 - d.t0) * f, r.s0 - (r.s0 - d.s0) * f);
            let nr = match side % 6 {
                0 => ParamRect::new(r.t1, t_up, r.s0, r.s1),
                1 => ParamRect::new(t_down, r.t0, r.s0, r.s1),
                2 => ParamRect::new(r.t0, r.t1, r.s1, s_up),
                3 => ParamRect::new(r.t0, r.t1, s_down, r.s0),
                4 => ParamRect::new(r.t1, t_up, r.s1, s_up),
                _ => ParamRect::new(t_down, r.t0, s_down, r.s0),
            };
            let Ok(nr) = nr else { return };
            Patch::new(&first, nr)
        }
        (SecondSpec::Same, _) => Ok(a),
        _ => return,
    };
    let Ok(b) = b else { return };

    let (oa, ob, os) = (order(input.order_a), order(input.order_b), order(input.singular_order));
    let occ: Option<AnyOccluder<T>> = input.occluder.and_then(occluder);

    // Adjacency detection, both ways round: no panic. (Whether the kind of contact is the same
    // both ways round is not asserted: it is not, for patches with a collapsed edge such as a
    // whole sphere or a pole cell — a known kernel bug with its own regression test in
    // pdm-host/tests/fuzz_singular.rs.)
    let _ = (classify(&a, &b), classify(&b, &a));
    let (near, gap) = classify_near(&a, &b);
    assert!(gap.is_finite() && gap >= T::ZERO, "classify_near gap {gap}");

    let settings = PairSettings { order: oa, singular_order: os, boundaries: input.boundaries };
    let bo = oa.max(os);
    check_exchange("pair_exchange", pair_exchange::<T, _, _, _, CAP>(&a, &b, settings, &occ).map(|e| e.value), &a, &b, bo);
    check_exchange("pair_exchange (b, a)", pair_exchange::<T, _, _, _, CAP>(&b, &a, settings, &occ).map(|e| e.value), &b, &a, bo);
    check_exchange("pair_exchange (no occluder)", pair_exchange::<T, _, _, _, CAP>(&a, &b, settings, &()).map(|e| e.value), &a, &b, bo);
    check_exchange("touching_exchange", touching_exchange(&a, &b, near, gap, os, &occ), &a, &b, os);
    if let Some((k, raw, depth)) = input.adaptive {
        let tolerance = match raw {
            Some(x) => x.get::<T>(),
            None => T::from_f64(10f64.powi(-1 - i32::from(k % 10))),
        };
        // An absolute budget on every other input: 0, or the tolerance times a tenth of the smaller area.
        let area = |p: &Patch<'_, T, _>| p.area(8).unwrap_or(T::ZERO);
        let absolute = if k % 2 == 0 { T::ZERO } else { tolerance * T::from_f64(0.1) * area(&a).min(area(&b)) };
        let settings = Adaptive { tolerance, max_order: ADAPTIVE_MAX_ORDER, max_depth: u32::from(depth % 3), absolute };
        let r = adaptive_exchange::<T, _, _, _, ADAPTIVE_CAP>(&a, &b, settings, &occ);
        if let Ok(e) = r {
            let error = e.error.expect("adaptive_exchange: the tolerance mode always estimates");
            assert!(error.is_finite() && error >= T::ZERO, "adaptive_exchange: estimate {error}");
        }
        // The tolerance mode goes up to order max(max_order, 8) + 2 on touching pairs.
        check_exchange("adaptive_exchange", r.map(|e| e.value), &a, &b, 10);
    }
    if let Some((edge, swap, g)) = input.forced {
        // A caller-supplied adjacency that need not match the geometry (only IDENTITY and the
        // maps classify found are constructible outside the kernel), with any gap.
        let (ma, mb) = match near {
            Adjacency::SharedEdge { a: ma, b: mb } | Adjacency::SharedVertex { a: ma, b: mb } => (ma, mb),
            _ => (SquareMap::IDENTITY, SquareMap::IDENTITY),
        };
        let (ma, mb) = if swap { (mb, ma) } else { (ma, mb) };
        let adjacency =
            if edge { Adjacency::SharedEdge { a: ma, b: mb } } else { Adjacency::SharedVertex { a: ma, b: mb } };
        check_exchange("touching_exchange (forced)", touching_exchange(&a, &b, adjacency, g.get(), os, &()), &a, &b, os);
    }
    check_factor(
        "form_factor_between",
        form_factor_between::<T, _, _, _, CAP>(&a, &b, Quadrature { order_a: oa, order_b: ob }, &occ),
    );
    check_factor("self_form_factor", self_form_factor::<T, _, _, CAP>(&a, oa, &()));
    let dims = input.grid.map(|k| usize::from(k % 3) + 1);
    if let (Ok(ga), Ok(gb)) = (a.grid(dims[0], dims[1]), b.grid(dims[2], dims[3])) {
        check_factor(
            "surface_form_factor",
            surface_form_factor::<T, _, _, _, CAP>(ga, gb, Quadrature { order_a: oa, order_b: ob }, &occ),
        );
    }
    if let Ok(g) = PatchGrid::new(&first, dims[0], dims[1]) {
        check_factor(
            "surface_form_factor (self)",
            surface_form_factor::<T, _, _, _, CAP>(g.clone(), g, Quadrature::uniform(oa), &()),
        );
    }
}

fuzz_target!(|input: Input| {
    if input.wide {
        run::<f64>(&input);
    } else {
        run::<f32>(&input);
    }
});
