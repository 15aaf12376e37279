//! The two computations (`--mode paper` and `--mode accurate`), generic over the precision `T`
//! and the sample capacity `CAP` (≥ order²). Each task is one row of eqs. (25)–(26), an outer
//! patch against a whole face's grid, summed by the kernel's substructuring
//! ([`pdm_kernel::surface_exchange`]); the tasks run in parallel with rayon (the kernel itself
//! is single-threaded). Partial sums are collected in task order and added
//! sequentially, so results do not depend on the number of threads.

use std::time::Instant;

use pdm_kernel::{
    surface_exchange, Adaptive, Estimate, Method, Occluder, PairSettings, Parallelogram, Patch, PatchGrid, PdmError,
    Quadrature, Real, Sphere, Surface,
};
use rayon::prelude::*;

use super::scene::{Scene, FACE_PAIRS};
use super::{Mode, Progress, RunConfig, ValidateError};

/// What one computation produced, in f64 (converted from `T` after all arithmetic in `T`).
#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    /// F sphere → face, faces 1..6 (eq. 25); `None` without a sphere.
    pub sphere_to_face: Option<[f64; 6]>,
    /// F face → sphere by reciprocity, A_s F_s→f / A_f with the same rule's areas.
    pub face_to_sphere: Option<[f64; 6]>,
    /// F a → b for the 15 pairs of [`FACE_PAIRS`] (eq. 26).
    pub face_to_face: [f64; 15],
    /// Σ_b F a → b + F a → sphere, faces 1..6 (F b → a for b < a by reciprocity).
    pub face_sum: [f64; 6],
    /// Σ of the sphere patch areas by eq. (12) with the run's rule.
    pub sphere_area: Option<f64>,
    /// Face areas (Σ of the patch areas by eq. 12).
    pub face_area: [f64; 6],
    /// Tolerance mode only: the largest of the kernel's own error estimates over the 21
    /// factors, each the sum of its patch pairs' estimates relative to the factor
    /// (`adaptive_exchange`'s `Estimate::error`); `None` in the fixed modes.
    pub estimated_error: Option<f64>,
    /// Tolerance mode only: the number of rows (an outer patch against a whole face, eqs.
    /// 25–26) whose summed estimate did not meet the
    /// tolerance (`Estimate::converged` false: subdivision limit or precision floor);
    /// `None` in the fixed modes.
    pub unconverged_rows: Option<u64>,
}

/// Wall times of one computation, seconds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Times {
    /// Sphere → face part (sampling included).
    pub sphere_face: f64,
    /// Face → face part (sampling included).
    pub face_face: f64,
}

type Face<T> = Parallelogram<T>;

/// Face → face part: exchange sums of the 15 face pairs, the 6 face areas, and the sums of the
/// kernel's error estimates of the 15 pairs and the number of patch pairs that did not converge
/// (tolerance mode; zero otherwise).
type FaceFaceSums<T> = ([T; 15], [T; 6], [T; 15], u64);

fn kernel(context: &'static str) -> impl Fn(PdmError) -> ValidateError {
    move |error| ValidateError::Kernel { context, error }
}

/// Units of progress one computation reports (one per outer patch).
#[must_use]
pub fn work_units(cfg: &RunConfig) -> u64 {
    let face_patches = cfg.face_grid * cfg.face_grid;
    let sphere = if cfg.radius > 0.0 { 6 * cfg.sphere_grid.0 * cfg.sphere_grid.1 } else { 0 };
    (sphere + FACE_PAIRS.len() * face_patches) as u64
}

/// One full computation (both parts) in precision `T` with sample capacity `CAP`.
pub fn run_once<T: Real, const CAP: usize>(
    cfg: &RunConfig,
    progress: &dyn Progress,
) -> Result<(Values, Times), ValidateError> {
    let scene = Scene::<T>::new(cfg.radius).map_err(kernel("building the scene"))?;
    let k = cfg.face_grid;
    let mut face_patches: Vec<Vec<Patch<'_, T, Face<T>>>> = Vec::with_capacity(6);
    for face in &scene.faces {
        face_patches.push(PatchGrid::new(face, k, k).map_err(kernel("face grid"))?.collect());
    }

    // Part 1: sphere → face (Table 1), eq. (25).
    let start = Instant::now();
    let part1 = match &scene.sphere {
        Some(sphere) => {
            progress.stage("sphere -> face");
            let (m, n) = cfg.sphere_grid;
            let sphere_patches: Vec<Patch<'_, T, Sphere<T>>> =
                PatchGrid::new(sphere, m, n).map_err(kernel("sphere grid"))?.collect();
            Some(sphere_face::<T, CAP>(cfg, &sphere_patches, &scene.faces, &face_patches, progress)?)
        }
        None => None,
    };
    let sphere_face_seconds = start.elapsed().as_secs_f64();

    // Part 2: face → face (Table 3), eq. (26), the sphere as occluder.
    progress.stage("face -> face");
    let start = Instant::now();
    let (face_exchange, face_area, face_error, face_unconverged) =
        face_face::<T, CAP>(cfg, &scene.sphere, &scene.faces, &face_patches, progress)?;
    let face_face_seconds = start.elapsed().as_secs_f64();

    // The kernel's estimates relative to the exchange they belong to (tolerance mode).
    let estimated_error = cfg.tolerance.map(|_| {
        let relative = |e: T, x: T| if x.abs() > T::ZERO { (e / x.abs()).to_f64() } else { e.to_f64() };
        let faces = face_error.iter().zip(&face_exchange).map(|(&e, &x)| relative(e, x));
        let sphere = part1.iter().flat_map(|p| p.error.iter().zip(&p.exchange).map(|(&e, &x)| relative(e, x)));
        faces.chain(sphere).fold(0.0, f64::max)
    });
    let unconverged_rows = cfg.tolerance.map(|_| face_unconverged + part1.as_ref().map_or(0, |p| p.unconverged));
    let mut values = derive(part1, &face_exchange, &face_area)?;
    values.estimated_error = estimated_error;
    values.unconverged_rows = unconverged_rows;
    Ok((values, Times { sphere_face: sphere_face_seconds, face_face: face_face_seconds }))
}

/// Exchange sums per face (Σ A_ps F_ps→pf over the face's patches) and the sphere's area.
struct SpherePart<T> {
    exchange: [T; 6],
    /// Σ of the kernel's error estimates per face (tolerance mode; zero otherwise).
    error: [T; 6],
    /// Rows that did not converge (tolerance mode; zero otherwise).
    unconverged: u64,
    sphere_area: T,
    face_area: [T; 6],
}

/// F values from the exchange sums and areas, all in `T`.
fn derive<T: Real>(
    part1: Option<SpherePart<T>>,
    face_exchange: &[T; 15],
    face_area: &[T; 6],
) -> Result<Values, ValidateError> {
    let area_of = |f: usize| face_area.get(f.wrapping_sub(1)).copied().unwrap_or(T::ZERO);
    let mut face_to_face = [0.0; 15];
    let mut sums = [T::ZERO; 6];
    for ((&(a, b), &e), out) in FACE_PAIRS.iter().zip(face_exchange).zip(face_to_face.iter_mut()) {
        *out = (e / area_of(a)).to_f64();
        if let Some(s) = sums.get_mut(a - 1) {
            *s += e / area_of(a);
        }
        if let Some(s) = sums.get_mut(b - 1) {
            *s += e / area_of(b);
        }
    }
    let (sphere_to_face, face_to_sphere, sphere_area) = match part1 {
        Some(p) => {
            let mut s2f = [0.0; 6];
            let mut f2s = [0.0; 6];
            for (f, &e) in p.exchange.iter().enumerate() {
                let fa = p.face_area.get(f).copied().unwrap_or(T::ZERO);
                let to_sphere = e / fa;
                if let (Some(x), Some(y), Some(s)) = (s2f.get_mut(f), f2s.get_mut(f), sums.get_mut(f)) {
                    *x = (e / p.sphere_area).to_f64();
                    *y = to_sphere.to_f64();
                    *s += to_sphere;
                }
            }
            (Some(s2f), Some(f2s), Some(p.sphere_area.to_f64()))
        }
        None => (None, None, None),
    };
    let face_sum = sums.map(Real::to_f64);
    let all = face_to_face.iter().chain(&face_sum).chain(sphere_to_face.iter().flatten());
    if all.clone().any(|x| !x.is_finite()) {
        return Err(ValidateError::Kernel { context: "summing the patch factors", error: PdmError::InvalidResult });
    }
    Ok(Values {
        sphere_to_face,
        face_to_sphere,
        face_to_face,
        face_sum,
        sphere_area,
        face_area: face_area.map(Real::to_f64),
        estimated_error: None,
        unconverged_rows: None,
    })
}

/// Adds task results (in task order) in consecutive chunks of `chunk`: one total per chunk.
fn chunk_sums<T: Real, const N: usize>(partial: &[T], chunk: usize) -> [T; N] {
    let mut out = [T::ZERO; N];
    for (o, c) in out.iter_mut().zip(partial.chunks(chunk.max(1))) {
        let mut s = T::ZERO;
        for &x in c {
            s += x;
        }
        *o = s;
    }
    out
}

/// How every patch pair of a run is integrated: the paper's bare eq. (16) sum (paper mode),
/// [`pdm_kernel::pair_exchange`] at the configured orders, or [`pdm_kernel::adaptive_exchange`] to
/// the configured tolerance (accurate mode).
fn method<T: Real>(cfg: &RunConfig) -> Method<T> {
    match (cfg.mode, cfg.tolerance) {
        (Mode::Paper, _) => Method::Paper(Quadrature::uniform(cfg.order)),
        (Mode::Accurate, Some(tol)) => Method::Tolerance(Adaptive {
            tolerance: T::from_f64(tol),
            max_order: ADAPTIVE_MAX_ORDER,
            max_depth: super::stack::ADAPTIVE_MAX_DEPTH,
            absolute: T::ZERO,
        }),
        (Mode::Accurate, None) => {
            Method::Pair(PairSettings { order: cfg.order, singular_order: cfg.singular_order, boundaries: true })
        }
    }
}

/// Largest Gauss order the tolerance mode uses before subdividing a pair.
pub const ADAPTIVE_MAX_ORDER: usize = 12;

/// One row of eqs. (25)–(26): outer patch `pa` against every patch of grid `b`, by the kernel's
/// substructuring ([`surface_exchange`]).
fn row<T, SA, SB, O, const CAP: usize>(
    pa: &Patch<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    method: Method<T>,
    occluders: &O,
) -> Result<Estimate<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    surface_exchange::<T, SA, SB, O, CAP>(pa.grid(1, 1)?, b, method, occluders)
}

/// Σ of the patch areas by eq. (12) with the run's rule.
fn areas<T: Real, S: pdm_kernel::Surface<T> + Sync + ?Sized>(
    patches: &[Patch<'_, T, S>],
    order: usize,
) -> Result<T, ValidateError> {
    let each =
        patches.par_iter().map(|p| p.area(order).map_err(kernel("patch area"))).collect::<Result<Vec<T>, _>>()?;
    let mut a = T::ZERO;
    for x in each {
        a += x;
    }
    Ok(a)
}

/// Per-task estimates (in task order) as chunked exchange sums, chunked sums of the error
/// estimates (zero where there are none), and the number of tasks that did not converge
/// (tolerance mode only).
fn totals<T: Real, const N: usize>(rows: &[Estimate<T>], chunk: usize) -> ([T; N], [T; N], u64) {
    let values: Vec<T> = rows.iter().map(|e| e.value).collect();
    let errors: Vec<T> = rows.iter().map(|e| e.error.unwrap_or(T::ZERO)).collect();
    let unconverged = rows.iter().filter(|e| e.error.is_some() && !e.converged).count() as u64;
    (chunk_sums(&values, chunk), chunk_sums(&errors, chunk), unconverged)
}

/// Part 1, eq. (25): every sphere patch against every face's grid, no occluder (the sphere is
/// convex: the curvature test is its only visibility test against the faces).
fn sphere_face<T: Real, const CAP: usize>(
    cfg: &RunConfig,
    sphere_patches: &[Patch<'_, T, Sphere<T>>],
    faces: &[Face<T>],
    face_patches: &[Vec<Patch<'_, T, Face<T>>>],
    progress: &dyn Progress,
) -> Result<SpherePart<T>, ValidateError> {
    let method = method::<T>(cfg);
    let k = cfg.face_grid;
    type Task<'a, 'p, T> = (&'a Patch<'p, T, Sphere<T>>, &'a Face<T>);
    let tasks: Vec<Task<'_, '_, T>> =
        faces.iter().flat_map(|face| sphere_patches.iter().map(move |s| (s, face))).collect();
    let rows = tasks
        .par_iter()
        .map(|&(ps, face)| {
            let grid = PatchGrid::new(face, k, k).map_err(kernel("face grid"))?;
            let e = row::<T, _, _, _, CAP>(ps, grid, method, &()).map_err(kernel("sphere patch -> face"))?;
            progress.advance(1);
            Ok(e)
        })
        .collect::<Result<Vec<Estimate<T>>, ValidateError>>()?;
    let (exchange, error, unconverged) = totals(&rows, sphere_patches.len());
    let mut face_area = [T::ZERO; 6];
    for (a, f) in face_area.iter_mut().zip(face_patches) {
        *a = areas(f, cfg.order)?;
    }
    Ok(SpherePart { exchange, error, unconverged, sphere_area: areas(sphere_patches, cfg.order)?, face_area })
}

/// Part 2, eq. (26): every patch of face a against face b's grid for the 15 face pairs, the
/// sphere as occluder. In paper mode edge-adjacent patch pairs get the bare sum too (Gauss
/// nodes are interior, so L never vanishes and the paper's L'Hôpital correction never
/// triggers); in accurate mode the shared-edge and shared-vertex transforms take them.
fn face_face<T: Real, const CAP: usize>(
    cfg: &RunConfig,
    sphere: &Option<Sphere<T>>,
    faces: &[Face<T>],
    face_patches: &[Vec<Patch<'_, T, Face<T>>>],
    progress: &dyn Progress,
) -> Result<FaceFaceSums<T>, ValidateError> {
    let method = method::<T>(cfg);
    let k = cfg.face_grid;
    type Task<'a, 'p, T> = (&'a Patch<'p, T, Face<T>>, &'a Face<T>);
    let mut tasks: Vec<Task<'_, '_, T>> = Vec::new();
    for &(a, b) in &FACE_PAIRS {
        if let (Some(fa), Some(fb)) = (face_patches.get(a - 1), faces.get(b - 1)) {
            tasks.extend(fa.iter().map(|p| (p, fb)));
        }
    }
    let rows = tasks
        .par_iter()
        .map(|&(pa, face_b)| {
            let grid = PatchGrid::new(face_b, k, k).map_err(kernel("face grid"))?;
            let e = row::<T, _, _, _, CAP>(pa, grid, method, sphere).map_err(kernel("face patch -> face"))?;
            progress.advance(1);
            Ok(e)
        })
        .collect::<Result<Vec<Estimate<T>>, ValidateError>>()?;
    let (exchange, error, unconverged) = totals(&rows, k * k);
    let mut face_area = [T::ZERO; 6];
    for (a, f) in face_area.iter_mut().zip(face_patches) {
        *a = areas(f, cfg.order)?;
    }
    Ok((exchange, face_area, error, unconverged))
}
