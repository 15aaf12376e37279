//! The form-factor matrices of a scene: every unordered patch pair computed once by the
//! kernel (the other direction by reciprocity, A_i·F_ij = A_j·F_ji), each against only the
//! occluders that can cut it, pairs that cannot see each other skipped, rayon over pairs.

use std::time::Instant;

use pdm_kernel::{
    adaptive_exchange, pair_exchange, Adaptive, Ball, Occluder as _, PairSettings, Patch, PdmError, Real, Vec3,
    WithCapacity,
};
use rayon::prelude::*;

use super::build::{Scene, ScenePatch};
use super::model::Kind;
use super::part::{Part, SceneOccluder};
use super::shape::{occluder_of, Geom, Plane, Shape};
use crate::validate::stack;

/// How each pair is integrated.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PairMethod {
    /// The tolerance mode (`adaptive_exchange`), with an error estimate for every entry. An
    /// entry counts as converged when its estimate is within `relative` of its value or within
    /// `absolute` (each surface-to-surface factor F_IJ and F_JI: every patch pair gets the share
    /// A_i·A_j / max(A_I, A_J) of it, so that the shares of one surface pair add up to it).
    Tolerance {
        /// Relative tolerance on each patch pair's exchange.
        relative: f64,
        /// Absolute tolerance on each surface-to-surface form factor.
        absolute: f64,
    },
    /// Fixed orders (`pair_exchange`): Gauss order for separate pairs, order of the touching
    /// transforms; no error estimate.
    Order {
        /// Gauss points per axis (separate pairs).
        order: usize,
        /// Gauss points per variable (touching pairs).
        singular_order: usize,
    },
}

/// Largest order of the tolerance mode here (as in `pdm-ff validate`).
pub const ADAPTIVE_MAX_ORDER: usize = 12;

/// The absolute tolerance of the tolerance mode, when not given, as a fraction of the relative
/// one: an entry of F below 1e-2 is then judged against 1e-2 · tolerance absolute instead of its
/// own value. An entry that is zero or tiny cannot meet a relative tolerance at any cost (the
/// satellite's body top face against the dish's concave side: F ≈ 1e-10 from slivers at the
/// rim, with estimates about as large; BENCHMARKS.md, "An absolute tolerance for scenes").
pub const DEFAULT_ABSOLUTE: f64 = 1e-2;

impl PairMethod {
    /// The tolerance mode at `relative`, with the default absolute tolerance
    /// ([`DEFAULT_ABSOLUTE`] × `relative`).
    #[must_use]
    pub fn tolerance(relative: f64) -> Self {
        Self::Tolerance { relative, absolute: DEFAULT_ABSOLUTE * relative }
    }

    /// The sample capacity the method needs (order², the kernel's `CAPACITIES`).
    #[must_use]
    pub fn capacity(&self) -> usize {
        match *self {
            Self::Tolerance { .. } => stack::capacity_for(ADAPTIVE_MAX_ORDER),
            Self::Order { order, .. } => stack::capacity_for(order),
        }
    }
}

/// One computed unordered pair (i ≤ j): E = A_i·F_ij = A_j·F_ji.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairValue {
    /// First patch.
    pub i: usize,
    /// Second patch.
    pub j: usize,
    /// A_i·F_ij.
    pub exchange: f64,
    /// Estimated absolute error of `exchange` (tolerance mode).
    pub error: Option<f64>,
    /// Whether the estimate met the tolerance.
    pub converged: bool,
    /// Kernel evaluations.
    pub evaluations: u64,
    /// Wall time of the kernel call (s).
    pub seconds: f64,
    /// Occluders the pair was tested against.
    pub occluders: usize,
}

/// One slice of the unordered pairs: those whose position in the list (i ≤ j, row by row) is
/// `index` modulo `count` (round robin, so that slices of one scene take similar times).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// 0-based slice number, below `count`.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl Shard {
    /// Whether the pair at `position` belongs to this slice.
    #[must_use]
    pub fn holds(&self, position: usize) -> bool {
        position % self.count.max(1) == self.index
    }
}

/// The result of [`compute`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MatrixResult {
    /// Patch areas (the kernel's Gauss area at order 16).
    pub areas: Vec<f64>,
    /// Every pair that was integrated (skipped pairs are zero by geometry).
    pub pairs: Vec<PairValue>,
    /// Unordered pairs skipped without a kernel call (back to back, or on one convex surface).
    pub skipped: usize,
    /// Wall time of the whole computation (s; for merged slices, the sum of theirs).
    pub seconds: f64,
    /// The slice of the pairs computed (`None`: all).
    pub shard: Option<Shard>,
}

/// A failure of one pair, with the patches named (`i == j` for a patch on its own).
#[derive(Clone, Debug, PartialEq)]
pub struct PairError {
    /// First patch.
    pub i: usize,
    /// Second patch.
    pub j: usize,
    /// The kernel's error.
    pub error: PdmError,
}

/// Why [`compute`] failed.
#[derive(Clone, Debug, PartialEq)]
pub enum MatrixError {
    /// A pair (or a patch) the kernel refused.
    Pair(PairError),
    /// The worker threads could not be started.
    Threads(String),
}

impl From<PairError> for MatrixError {
    fn from(e: PairError) -> Self {
        Self::Pair(e)
    }
}

fn ball_f64<T: Real>(b: &Ball<T>) -> (Vec3<f64>, f64) {
    (pdm_kernel::vec3(b.center.x.to_f64(), b.center.y.to_f64(), b.center.z.to_f64()), b.radius.to_f64())
}

/// Per-patch data the pair loop needs.
struct PatchInfo<T> {
    ball: Ball<T>,
    area: T,
}

/// Whether the patch `p` lies within the closed convex solid that the surface `solid` (a
/// sphere, tube or cone, either side, whole or a part) lies on the boundary of: a segment
/// between two points of that solid stays inside it, which its surface cannot cut.
/// Conservative: `false` when unsure, and for every other kind.
///
/// The slack is `tol` but at most 1e-12 of the solid's extent (the rounding of points computed
/// on its boundary): a surface just outside the solid, which the solid's surface does block
/// from itself, must not pass for one inside it.
fn inside_solid(solid: &Geom, geom: &Geom, p: &ScenePatch, ball: (Vec3<f64>, f64), tol: f64) -> bool {
    let (bc, br) = ball;
    // Points and circles whose hull holds the patch (`Geom::cover`); the patch's enclosing
    // ball is a second bound, tighter for a small cell of a large surface. Comparisons are
    // written so that a NaN fails them.
    match *solid {
        Geom::Sphere { center, radius, .. } => {
            let tol = tol.min(1e-12 * (center.norm() + radius));
            let reach = |c: Vec3<f64>, r: f64| (c - center).norm() + r <= radius + tol;
            geom.cover(p.rect).iter().all(|&(c, r)| reach(c, r)) || reach(bc, br)
        }
        // A tube (r₀ = r₁) or a cone or frustum bounds a convex solid: 0 ≤ z ≤ h along the axis,
        // distance from the axis ≤ r(z) = r₀ + (r₁ − r₀)·z/h, linear in z. A point of the cover
        // is checked against the radius at its own z; a circle or ball of radius ρ against the
        // smaller radius over its axial span (its centre's z ± ρ, within the patch's: the
        // cover's circles are the patch's own edges or hold the whole patch).
        Geom::Cylinder { base, frame, radius: base_radius, height, .. }
        | Geom::Cone { base, frame, base_radius, height, .. } => {
            let top_radius = match *solid {
                Geom::Cone { top_radius, .. } => top_radius,
                _ => base_radius,
            };
            let tol = tol.min(1e-12 * (base.norm() + base_radius.max(top_radius) + height));
            let axial = Plane { origin: base, normal: frame.axis };
            let (lo, hi) = geom.distance_range(p.rect, &axial);
            if !(lo >= -tol && hi <= height + tol) {
                return false;
            }
            let radial = |x: Vec3<f64>| {
                let d = x - base;
                (d - frame.axis.scale(d.dot(frame.axis))).norm()
            };
            let radius_at = |z: f64| base_radius + (top_radius - base_radius) * (z / height).clamp(0.0, 1.0);
            let least_radius = |z0: f64, z1: f64| radius_at(z0.max(lo)).min(radius_at(z1.min(hi)));
            let by_cover = geom.cover(p.rect).iter().all(|&(c, r)| {
                let z = (c - base).dot(frame.axis);
                radial(c) + r <= least_radius(z - r, z + r) + tol
            });
            by_cover || radial(bc) + br <= least_radius(lo, hi) + tol
        }
        _ => false,
    }
}

/// Everything the pair loop reads, shared by the workers.
struct Context<'s, T> {
    scene: &'s Scene,
    shapes: Vec<Vec<Shape<T>>>,
    /// Per surface, one occluder per piece (empty: the surface does not occlude).
    occluders: Vec<Vec<SceneOccluder<T>>>,
    info: Vec<PatchInfo<T>>,
    /// Per surface (side): the summed area of its patches.
    surface_areas: Vec<f64>,
    balls: Vec<(Vec3<f64>, f64)>,
    planes: Vec<Option<Plane>>,
    /// Per surface and piece: whether the radiating side may be concave, and the plane of a
    /// flat piece (computed once: a Bézier piece's concavity is sampled).
    piece_concave: Vec<Vec<bool>>,
    piece_planes: Vec<Vec<Option<Plane>>>,
    /// Per surface and piece: the corners of a whole flat piece with straight edges (the
    /// occluder's polygon, [`super::separate`]).
    piece_polygons: Vec<Vec<Option<[Vec3<f64>; 4]>>>,
    /// Per patch: its corners, if it has straight edges.
    polygons: Vec<Option<[Vec3<f64>; 4]>>,
    /// The occluders by bounding box: one per piece of each surface that stands for its
    /// entry's (or mesh group's) occluder, the first of the two sides that occludes.
    tree: super::bvh::Occluders,
    tol: f64,
}

/// What to do with one unordered pair.
enum Plan<T> {
    /// Zero by geometry.
    Skip,
    /// Integrate against these occluders.
    Integrate(Vec<SceneOccluder<T>>),
}

impl<T: Real> Context<'_, T> {
    fn patch(&self, i: usize) -> Result<Patch<'_, T, Shape<T>>, PdmError> {
        let p = &self.scene.patches[i];
        let r = p.rect;
        let rect = pdm_kernel::ParamRect {
            t0: T::from_f64(r.t0),
            t1: T::from_f64(r.t1),
            s0: T::from_f64(r.s0),
            s1: T::from_f64(r.s1),
        };
        Patch::new(&self.shapes[p.surface][p.piece], rect)
    }

    /// `true` if patch `j` lies wholly behind or in the plane of the flat patch `i`.
    fn behind(&self, i: usize, j: usize) -> bool {
        match &self.planes[i] {
            Some(plane) => {
                let pj = &self.scene.patches[j];
                self.scene.geom(pj).distance_range(pj.rect, plane).1 <= self.tol
            }
            None => false,
        }
    }

    /// Whether surface `k`'s occluders may cut the segments between patches `i` and `j` by
    /// what the surfaces are (a surface does not block chords of its own convex side).
    fn surface_may_cut(&self, k: usize, i: usize, j: usize) -> bool {
        let scene = self.scene;
        let (pi, pj) = (&scene.patches[i], &scene.patches[j]);
        let (si, sj, s) = (&scene.surfaces[pi.surface], &scene.surfaces[pj.surface], scene.any_surface(k));
        // A mesh's facets are occluders one by one: a pair's own facets are left out by the
        // plane test, like any flat occluder with both patches on one side.
        if (s.entry == si.entry || s.entry == sj.entry) && s.kind != Kind::Mesh {
            // A segment between two points of one surface is a chord of its solid (a Bézier
            // sheet is taken to be part of a convex surface, SCENES.md); a flat sheet or a
            // convex side never blocks a segment that starts on it and passes the facing
            // test; a concave side (or a Bézier piece that bends both ways) blocks only
            // segments that leave its solid.
            if si.entry == sj.entry {
                return false;
            }
            let (on, other) = if s.entry == si.entry { (pi, j) } else { (pj, i) };
            if !self.piece_concave[on.surface][on.piece] {
                return false;
            }
            let po = &scene.patches[other];
            if inside_solid(scene.geom(on), scene.geom(po), po, self.balls[other], self.tol) {
                return false;
            }
        }
        true
    }

    fn plan(&self, i: usize, j: usize) -> Plan<T> {
        let scene = self.scene;
        let (pi, pj) = (&scene.patches[i], &scene.patches[j]);
        let (si, sj) = (&scene.surfaces[pi.surface], &scene.surfaces[pj.surface]);
        let (gi, gj) = (scene.geom(pi), scene.geom(pj));
        // Patches of one convex side of a sphere, tube or cone, or one flat sheet, never see
        // each other (a chord of a convex solid leaves it only at its ends).
        let concave = |p: &ScenePatch| self.piece_concave[p.surface][p.piece];
        // A mesh group's facets (quadrilaterals) may face each other; one facet's patches do not.
        let one_sheet = match gi {
            Geom::Bezier { .. } => false,
            Geom::Quadrilateral { .. } => pi.piece == pj.piece,
            _ => true,
        };
        if si.entry == sj.entry && pi.surface == pj.surface && !concave(pi) && one_sheet {
            return Plan::Skip;
        }
        // The two sides of one sheet or closed surface: a segment between two of its points is
        // a chord on the concave side of both (flat, sphere, tube, cone), which the convex side
        // does not face. A Bézier sheet is taken to be such a part of a convex surface (a dish,
        // a curved panel); a wavy sheet whose front sees its own back is not supported
        // (SCENES.md).
        if si.entry == sj.entry && si.group == sj.group && pi.surface != pj.surface {
            return Plan::Skip;
        }
        if self.behind(i, j) || self.behind(j, i) {
            return Plan::Skip;
        }
        let (bi, bj) = (&self.info[i].ball, &self.info[j].ball);
        let mut list = Vec::new();
        // The two patches' hull, built when a flat occluder first needs it.
        let mut hull = None;
        // Only the occluders whose boxes come near the pair's capsule (`bvh`), in scene order.
        let reach = bi.radius.to_f64().max(bj.radius.to_f64()) + self.tol;
        let near = self.tree.near_segment(self.balls[i].0, self.balls[j].0, reach);
        let mut surface_ok: Option<(usize, bool)> = None;
        for (k, piece) in near {
            let ok = match surface_ok {
                Some((at, ok)) if at == k => ok,
                _ => {
                    let ok = self.surface_may_cut(k, i, j);
                    surface_ok = Some((k, ok));
                    ok
                }
            };
            if !ok {
                continue;
            }
            // A piece of a sphere, tube or cone lies on the boundary of a convex solid; a
            // segment between two points of that solid stays in it and meets its boundary only
            // at its ends or along a line of it (a set of measure zero), so the piece cannot
            // cut a pair that the solid holds (the ends of a closed tube, a ball's contents).
            if let Some(piece_geom) = scene.any_surface(k).pieces.get(piece).map(|p| &p.geom) {
                if inside_solid(piece_geom, gi, pi, self.balls[i], self.tol)
                    && inside_solid(piece_geom, gj, pj, self.balls[j], self.tol)
                {
                    continue;
                }
            }
            let (Some(occluder), Some(plane), Some(polygon)) =
                (self.occluders[k].get(piece), self.piece_planes[k].get(piece), self.piece_polygons[k].get(piece))
            else {
                continue;
            };
            if !occluder.may_block_between(bi, bj) {
                continue;
            }
            if let Some(plane) = plane {
                let (lo_i, hi_i) = gi.distance_range(pi.rect, plane);
                let (lo_j, hi_j) = gj.distance_range(pj.rect, plane);
                if (lo_i >= -self.tol && lo_j >= -self.tol) || (hi_i <= self.tol && hi_j <= self.tol) {
                    continue;
                }
            }
            // Flat polygons touching the pair's hull (a mesh's neighbours): a separating plane.
            if let (Some(o), Some(a), Some(b)) = (polygon, &self.polygons[i], &self.polygons[j]) {
                let hull = hull.get_or_insert_with(|| super::separate::Hull::new(&[*a, *b].concat()));
                if hull.weakly_separated_from(o, self.tol) {
                    continue;
                }
            }
            list.push(*occluder);
        }
        Plan::Integrate(list)
    }

    fn pair<const CAP: usize>(&self, i: usize, j: usize, method: PairMethod) -> Result<Option<PairValue>, PairError> {
        let occluders = match self.plan(i, j) {
            Plan::Skip => return Ok(None),
            Plan::Integrate(list) => list,
        };
        let wrap = |error| PairError { i, j, error };
        let (a, b) = (self.patch(i).map_err(wrap)?, self.patch(j).map_err(wrap)?);
        let start = Instant::now();
        let estimate = match method {
            PairMethod::Tolerance { relative, absolute } => {
                // This pair's share of the surface pair's absolute tolerance (on F_IJ and F_JI).
                let (pi, pj) = (&self.scene.patches[i], &self.scene.patches[j]);
                let (ai, aj) = (self.info[i].area.to_f64(), self.info[j].area.to_f64());
                let larger = self.surface_areas[pi.surface].max(self.surface_areas[pj.surface]);
                let settings = Adaptive {
                    tolerance: T::from_f64(relative),
                    max_order: ADAPTIVE_MAX_ORDER,
                    max_depth: stack::ADAPTIVE_MAX_DEPTH,
                    absolute: T::from_f64(absolute * ai * aj / larger),
                };
                adaptive_exchange::<T, _, _, [SceneOccluder<T>], CAP>(&a, &b, settings, occluders.as_slice())
            }
            PairMethod::Order { order, singular_order } => {
                let settings = PairSettings { order, singular_order, boundaries: true };
                pair_exchange::<T, _, _, [SceneOccluder<T>], CAP>(&a, &b, settings, occluders.as_slice())
            }
        }
        .map_err(wrap)?;
        Ok(Some(PairValue {
            i,
            j,
            exchange: estimate.value.to_f64(),
            error: estimate.error.map(Real::to_f64),
            converged: estimate.converged,
            evaluations: estimate.evaluations,
            seconds: start.elapsed().as_secs_f64(),
            occluders: occluders.len(),
        }))
    }
}

/// Bytes a run over `patches` patches needs at its peak, roughly: the integrated pairs of one of
/// `slices` slices, and (for a whole run) the report's dense patch matrices, two N × N matrices
/// of exchanges and errors, the two of factors and errors made from them and an output
/// buffer, with a tenth more (10 092 patches: 8.4 GB estimated, 8.2 GB measured).
#[must_use]
pub fn memory_needed(patches: usize, slices: usize) -> u64 {
    let n = patches as u64;
    let pairs = n * (n + 1) / 2 / slices.max(1) as u64;
    let matrices = if slices > 1 { 0 } else { 5 * n * n * 8 };
    (pairs * std::mem::size_of::<PairValue>() as u64 + matrices) * 11 / 10
}

/// Computes every unordered pair of the scene (or of one `shard` of them) in precision `T`
/// with `threads` workers (0: all cores); `progress` is called with the number of pairs done so
/// far.
pub fn compute<T: Real>(
    scene: &Scene,
    method: PairMethod,
    shard: Option<Shard>,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<MatrixResult, MatrixError> {
    struct Job<'a, T> {
        scene: &'a Scene,
        method: PairMethod,
        shard: Option<Shard>,
        threads: usize,
        progress: &'a (dyn Fn(u64) + Sync),
        precision: std::marker::PhantomData<T>,
    }
    impl<T: Real> WithCapacity for Job<'_, T> {
        type Output = Result<MatrixResult, MatrixError>;
        fn run<const CAP: usize>(self) -> Self::Output {
            compute_with::<T, CAP>(self.scene, self.method, self.shard, self.threads, self.progress)
        }
    }
    // Below f64, on the scene centred on the origin (`Scene::centred`).
    let centred;
    let scene = if T::EPSILON.to_f64() > f64::EPSILON {
        centred = scene.centred();
        &centred
    } else {
        scene
    };
    let job = Job::<T> { scene, method, shard, threads, progress, precision: std::marker::PhantomData };
    pdm_kernel::with_capacity(method.capacity(), job).map_err(|error| MatrixError::Threads(error.to_string()))?
}

fn compute_with<T: Real, const CAP: usize>(
    scene: &Scene,
    method: PairMethod,
    shard: Option<Shard>,
    threads: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<MatrixResult, MatrixError> {
    let start = Instant::now();
    let at = |i: usize| move |error| PairError { i, j: i, error };
    // Indexed by surface, the obstructions after the radiating surfaces.
    let all: Vec<_> = scene.all_surfaces().collect();
    let mut shapes = Vec::with_capacity(all.len());
    let mut occluders = Vec::with_capacity(all.len());
    for (k, s) in all.iter().enumerate() {
        let first = scene.patches.iter().position(|p| p.surface == k).unwrap_or(0);
        let list = s.pieces.iter().map(|p| p.geom.shape::<T>()).collect::<Result<Vec<_>, _>>().map_err(at(first))?;
        // Every piece of an occluding surface is one: a whole surface the kernel's occluder, a
        // part of one (a `theta` or `phi` range) a `Part`.
        let mut own = Vec::new();
        if s.occludes {
            for (piece, shape) in s.pieces.iter().zip(&list) {
                let occluder = if piece.rect == piece.geom.domain() {
                    occluder_of(shape).map(SceneOccluder::Whole)
                } else {
                    Part::new(piece.geom, piece.rect).map(SceneOccluder::Part)
                };
                own.push(occluder.ok_or(PdmError::Degenerate).map_err(at(first))?);
            }
        }
        occluders.push(own);
        shapes.push(list);
    }
    let stands: Vec<bool> = (0..all.len())
        .map(|k| {
            let s = all[k];
            !occluders[k].is_empty()
                && !all[..k]
                    .iter()
                    .zip(&occluders)
                    .any(|(o, list)| o.entry == s.entry && o.group == s.group && !list.is_empty())
        })
        .collect();
    let mut entries = Vec::new();
    for (k, s) in all.iter().enumerate() {
        if stands[k] {
            for (p, piece) in s.pieces.iter().enumerate() {
                entries.push(super::bvh::Entry::new(k, p, &piece.geom, piece.geom.domain()));
            }
        }
    }
    let tree = super::bvh::Occluders::new(entries);
    let piece_concave = all.iter().map(|s| s.pieces.iter().map(|p| p.geom.concave()).collect()).collect();
    let piece_planes = all.iter().map(|s| s.pieces.iter().map(|p| p.geom.plane()).collect()).collect();
    let piece_polygons = all
        .iter()
        .map(|s| s.pieces.iter().map(|p| super::separate::polygon(&p.geom, p.geom.domain())).collect())
        .collect();
    let polygons = scene.patches.iter().map(|p| super::separate::polygon(scene.geom(p), p.rect)).collect();
    let mut ctx = Context {
        scene,
        shapes,
        occluders,
        info: Vec::new(),
        surface_areas: vec![0.0; scene.surfaces.len()],
        balls: Vec::new(),
        planes: Vec::new(),
        piece_concave,
        piece_planes,
        piece_polygons,
        polygons,
        tree,
        tol: 0.0,
    };
    let mut info = Vec::with_capacity(scene.patches.len());
    for (i, p) in scene.patches.iter().enumerate() {
        let patch = ctx.patch(i).map_err(at(i))?;
        let area = patch.area(16).map_err(at(i))?;
        info.push(PatchInfo { ball: patch.enclosing_ball(), area });
        ctx.planes.push(scene.geom(p).plane());
    }
    for (p, x) in scene.patches.iter().zip(&info) {
        ctx.surface_areas[p.surface] += x.area.to_f64();
    }
    ctx.balls = info.iter().map(|x| ball_f64(&x.ball)).collect();
    let scale = ctx.balls.iter().map(|(c, r)| c.max_abs() + r).fold(0.0, f64::max);
    ctx.tol = 1e-9 * scale;
    ctx.info = info;

    let n = scene.patches.len();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (i..n).map(move |j| (i, j)))
        .enumerate()
        .filter(|(position, _)| shard.is_none_or(|s| s.holds(*position)))
        .map(|(_, pair)| pair)
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let pool = stack::pool::<T>(threads, CAP).map_err(MatrixError::Threads)?;
    let results: Vec<Result<Option<PairValue>, PairError>> = pool.install(|| {
        pairs
            .par_iter()
            .map(|&(i, j)| {
                let r = ctx.pair::<CAP>(i, j, method);
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if k.is_multiple_of(64) || k as usize == pairs.len() {
                    progress(k);
                }
                r
            })
            .collect()
    });
    let mut out = Vec::new();
    let mut skipped = 0;
    for r in results {
        match r? {
            Some(v) => out.push(v),
            None => skipped += 1,
        }
    }
    Ok(MatrixResult {
        areas: ctx.info.iter().map(|x| x.area.to_f64()).collect(),
        pairs: out,
        skipped,
        seconds: start.elapsed().as_secs_f64(),
        shard,
    })
}

/// Joins the results of slices `0..count` of one scene, each present once: the result of
/// computing the whole scene at once, pairs in the same order (so the matrices are the same to
/// the bit). `Err` names what is missing or repeated.
pub fn merge(parts: Vec<MatrixResult>) -> Result<MatrixResult, String> {
    let Some(first) = parts.first() else { return Err("no slices to merge".into()) };
    let count = first.shard.map_or(1, |s| s.count);
    let mut seen = vec![false; count];
    for p in &parts {
        let Some(s) = p.shard else { return Err("a file holds a whole scene, not a slice (--shard)".into()) };
        if s.count != count {
            return Err(format!("slice {}/{} does not belong with slices of {count}", s.index + 1, s.count));
        }
        if p.areas != first.areas {
            return Err(format!("slice {}/{count} has other patch areas: another scene or precision", s.index + 1));
        }
        match seen.get_mut(s.index) {
            Some(flag) if !*flag => *flag = true,
            Some(_) => return Err(format!("slice {}/{count} is given twice", s.index + 1)),
            None => return Err(format!("slice {}/{count} is out of range", s.index + 1)),
        }
    }
    if let Some(missing) = seen.iter().position(|&s| !s) {
        return Err(format!("slice {}/{count} is missing", missing + 1));
    }
    let areas = first.areas.clone();
    let mut merged = MatrixResult { areas, pairs: Vec::new(), skipped: 0, seconds: 0.0, shard: None };
    for p in parts {
        merged.pairs.extend(p.pairs);
        merged.skipped += p.skipped;
        merged.seconds += p.seconds;
    }
    // The whole run's order (row by row), so that the sums come out the same to the bit.
    merged.pairs.sort_by_key(|p| (p.i, p.j));
    Ok(merged)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

    use super::*;
    use crate::scene::shape::Rect;
    use pdm_kernel::{vec3, Frame};

    fn patch(rect: Rect) -> ScenePatch {
        ScenePatch { surface: 0, piece: 0, cell: (0, 0), rect }
    }

    fn frame() -> Frame<f64> {
        Frame::from_axis(vec3(0.0, 0.0, 1.0)).unwrap()
    }

    /// `inside_solid` with the enclosing-ball fallback disabled (a ball far away), so that the
    /// cover decides.
    fn inside(solid: &Geom, geom: &Geom, rect: Rect) -> bool {
        inside_solid(solid, geom, &patch(rect), (vec3(1e3, 0.0, 0.0), 1.0), 1e-9)
    }

    fn sphere(radius: f64) -> Geom {
        Geom::Sphere { center: vec3(0.0, 0.0, 0.0), radius, frame: frame(), inner: false }
    }

    fn tube(radius: f64, height: f64) -> Geom {
        Geom::Cylinder { base: vec3(0.0, 0.0, 0.0), frame: frame(), radius, height, inner: false }
    }

    fn whole(geom: &Geom) -> Rect {
        geom.domain()
    }

    /// A sphere just outside another (1e-10 of its radius, below the scene's slack of 1e-9 but
    /// above rounding) is not inside it: the inner sphere blocks the outer one's chords.
    #[test]
    fn a_shell_just_outside_a_ball_is_not_inside() {
        let (core, shell) = (sphere(1.0), sphere(1.0 + 1e-10));
        assert!(!inside(&core, &shell, whole(&shell)));
        assert!(inside(&shell, &core, whole(&core)));
        assert!(inside(&core, &core, whole(&core)), "a sphere's own cells lie in its ball");
    }

    /// The disks closing a tube, a coaxial tube inside it and a cone's top disk are inside;
    /// the same moved off the axis or widened are not.
    #[test]
    fn tubes_cones_and_disks_in_a_tube_or_frustum() {
        let (outer, pipe) = (tube(1.0, 1.0), tube(0.5, 1.0));
        let disk =
            |z: f64, x: f64, outer: f64| Geom::Disk { center: vec3(x, 0.0, z), frame: frame(), inner: 0.0, outer };
        assert!(inside(&outer, &pipe, whole(&pipe)), "a coaxial pipe, by its end circles");
        assert!(inside(&outer, &disk(1.0, 0.0, 1.0), whole(&disk(1.0, 0.0, 1.0))));
        assert!(!inside(&outer, &disk(1.0, 1e-6, 1.0), whole(&disk(1.0, 1e-6, 1.0))));
        assert!(!inside(&outer, &disk(1.0 + 1e-6, 0.0, 0.5), whole(&disk(1.0 + 1e-6, 0.0, 0.5))), "above the top");
        let shifted =
            Geom::Cylinder { base: vec3(0.6, 0.0, 0.0), frame: frame(), radius: 0.5, height: 1.0, inner: false };
        assert!(!inside(&outer, &shifted, whole(&shifted)));
        let frustum = Geom::Cone {
            base: vec3(0.0, 0.0, 0.0),
            frame: frame(),
            base_radius: 1.0,
            top_radius: 0.4,
            height: 1.5,
            inner: true,
        };
        assert!(inside(&frustum, &disk(1.5, 0.0, 0.4), whole(&disk(1.5, 0.0, 0.4))));
        assert!(!inside(&frustum, &disk(1.5, 0.0, 0.4 + 1e-6), whole(&disk(1.5, 0.0, 0.4 + 1e-6))));
        // A disk of radius 0.7 halfway up fits (r(0.75) = 0.7), one of 0.71 does not.
        assert!(inside(&frustum, &disk(0.75, 0.0, 0.7), whole(&disk(0.75, 0.0, 0.7))));
        assert!(!inside(&frustum, &disk(0.75, 0.0, 0.71), whole(&disk(0.75, 0.0, 0.71))));
        // A quarter of the pipe's wall by its own end circles.
        let quarter = Rect::new(0.0, core::f64::consts::FRAC_PI_2, 0.25, 0.75).unwrap();
        assert!(inside(&outer, &pipe, quarter));
    }

    /// Every point of a patch is within max(f(c) + ρ) of the cover, for f the distance from a
    /// point and from a line: sampled on tube, cone, disk and sphere patches.
    #[test]
    fn the_cover_bounds_sampled_points() {
        let tilted = Frame::from_axis(vec3(0.3, -0.5, 0.8)).unwrap();
        let geoms = [
            Geom::Cylinder { base: vec3(0.2, 0.1, -0.3), frame: tilted, radius: 0.7, height: 1.3, inner: false },
            Geom::Cone {
                base: vec3(0.2, 0.1, -0.3),
                frame: tilted,
                base_radius: 0.9,
                top_radius: 0.2,
                height: 1.1,
                inner: true,
            },
            Geom::Disk { center: vec3(0.4, -0.2, 0.5), frame: tilted, inner: 0.3, outer: 0.8 },
            Geom::Sphere { center: vec3(-0.1, 0.3, 0.2), radius: 0.6, frame: tilted, inner: false },
        ];
        let (point, axis_point, axis) = (vec3(1.5, -0.7, 0.9), vec3(-0.4, 0.2, 0.1), vec3(0.6, 0.8, 0.0));
        let to_line = |x: Vec3<f64>| {
            let d = x - axis_point;
            (d - axis.scale(d.dot(axis))).norm()
        };
        for geom in &geoms {
            let shape = geom.shape::<f64>().unwrap();
            let d = geom.domain();
            let rect =
                Rect::new(d.t0 + 0.1 * (d.t1 - d.t0), d.t0 + 0.6 * (d.t1 - d.t0), d.s0 + 0.2 * (d.s1 - d.s0), d.s1)
                    .unwrap();
            let cover = geom.cover(rect);
            let bound = |f: &dyn Fn(Vec3<f64>) -> f64| cover.iter().map(|&(c, r)| f(c) + r).fold(f64::MIN, f64::max);
            let (to_point, line) = (bound(&|x| (x - point).norm()), bound(&to_line));
            for i in 0..=20 {
                for j in 0..=20 {
                    let (t, s) = (
                        rect.t0 + (rect.t1 - rect.t0) * i as f64 / 20.0,
                        rect.s0 + (rect.s1 - rect.s0) * j as f64 / 20.0,
                    );
                    let x = pdm_kernel::Surface::point(&shape, t, s);
                    assert!((x - point).norm() <= to_point + 1e-12, "{geom:?} at ({t}, {s})");
                    assert!(to_line(x) <= line + 1e-12, "{geom:?} at ({t}, {s})");
                }
            }
        }
    }
}
