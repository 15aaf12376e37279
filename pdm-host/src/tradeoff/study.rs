//! Curved patches against polygons (the paper's central claim, measured). The paper's scene:
//! the unit sphere centred in the cube of side 6, the faces cut 3 × 3 as in the paper's
//! 86-patch discretisation; the quantity is F from the sphere to each of the 54 face cells,
//! whose exact value is the cell's solid angle over 4π (`sphere_to_polygon`). Every approach
//! uses the same kernel sum (eq. 16 at a fixed order, eq. 25 over the emitter's pieces, each
//! face cell one patch), with the emitter being
//!
//! * the sphere itself, cut into M × N parametric patches (`curved-paper`; `curved-pair` and
//!   `curved-adaptive` integrate it with `pair_exchange` and `adaptive_exchange`);
//! * a UV sphere of m × n flat facets (`uv-mxn`) or an icosphere of level L (`ico-L`, 20·4^L
//!   triangles), vertices on the sphere ([`super::polygon`]), turned by a fixed generic rotation
//!   ([`super::polygon::generic_rotation`]) so that no symmetry cancels their error;
//!
//! and a Monte Carlo ray estimator ([`super::mc`]) for comparison. The error is the largest
//! relative error over the 54 cells against the true sphere's values. For each polyhedron, its
//! exact factor to each cell ([`exact_floor`]) gives the **error floor** that no quadrature can
//! go below: the polygonisation error itself. All in f64.

use std::time::Instant;

use pdm_kernel::{Patch, PatchGrid, Surface};

use super::cases::time_solve;
use super::engine::{solve, Method, Problem, Solution};
use super::mc;
use super::polygon::{
    clipped_polyhedron_to_polygon, cube_face_cells, generic_rotation, icosphere, uv_sphere, Polyhedron,
};
use crate::reference::closed_form::sphere_to_polygon;
use crate::validate::median;
use crate::validate::scene::Scene;

/// Cells per face side of the receivers (the paper's 86-patch face grid).
pub const RECEIVER_GRID: usize = 3;

/// Columns of `polygons.csv`.
pub const COLUMNS: [&str; 14] = [
    "approach",
    "family",
    "grid",
    "elements",
    "order",
    "tolerance",
    "rays",
    "value",
    "rel_error",
    "polygon_floor",
    "evaluations",
    "seconds",
    "repeats",
    "threads",
];

/// One point of the study (a CSV record, fields in [`COLUMNS`] order).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StudyRow {
    /// "curved-paper", "curved-pair", "curved-adaptive", "uv-8x16", "ico-2", "monte-carlo".
    pub approach: String,
    /// "curved", "uv", "ico" or "mc".
    pub family: String,
    /// The emitter's subdivision: the sphere grid "MxN", the polyhedron's name, or "".
    pub grid: String,
    /// Sphere patches or facets (0 for Monte Carlo).
    pub elements: usize,
    /// Gauss order (0: adaptive or Monte Carlo).
    pub order: usize,
    /// Tolerance (adaptive), else NaN.
    #[serde(with = "crate::csv_num")]
    pub tolerance: f64,
    /// Rays (Monte Carlo), else 0.
    pub rays: u64,
    /// The cell value with the largest error.
    #[serde(with = "crate::csv_num")]
    pub value: f64,
    /// Largest relative error over the 54 cells against the sphere's exact values (Monte Carlo:
    /// root mean square over the repetitions' seeds).
    #[serde(with = "crate::csv_num")]
    pub rel_error: f64,
    /// The polyhedron's exact largest relative deviation from the sphere's values (NaN for the
    /// sphere and Monte Carlo).
    #[serde(with = "crate::csv_num")]
    pub polygon_floor: f64,
    /// Kernel evaluations (rays for Monte Carlo).
    pub evaluations: u64,
    /// Median wall time, seconds.
    #[serde(with = "crate::csv_num")]
    pub seconds: f64,
    /// Repetitions.
    pub repeats: usize,
    /// Threads.
    pub threads: usize,
}

/// The CSV text.
#[must_use]
pub fn to_csv(rows: &[StudyRow]) -> String {
    let mut w = csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new());
    // Writing to memory fails only on a serialization error, which these plain fields cannot raise.
    let _ = w.write_record(COLUMNS);
    for r in rows {
        let _ = w.serialize(r);
    }
    w.into_inner().map(|b| String::from_utf8_lossy(&b).into_owned()).unwrap_or_default()
}

/// The receivers' polygons (faces 1..6, each 3 × 3 cells in `PatchGrid` order).
#[must_use]
pub fn receiver_cells() -> Vec<Vec<[f64; 3]>> {
    (1..=6).flat_map(|k| cube_face_cells(k, RECEIVER_GRID)).collect()
}

/// The exact sphere → cell factors (solid angle / 4π), in receiver order.
#[must_use]
pub fn exact_cells() -> Vec<f64> {
    receiver_cells().iter().map(|c| sphere_to_polygon([0.0; 3], c)).collect()
}

/// Largest relative error of `values` against `exact`, and the value attaining it.
fn worst(values: &[f64], exact: &[f64]) -> (f64, f64) {
    let mut out = (f64::NAN, 0.0);
    for (&v, &x) in values.iter().zip(exact) {
        let e = ((v - x) / x).abs();
        if !(e <= out.1) {
            out = (v, e);
        }
    }
    out
}

/// The tessellations of the study, rotated (`quick`: the smallest ones).
#[must_use]
pub fn polyhedra(quick: bool) -> Vec<Polyhedron> {
    let c = [0.0; 3];
    let uv: &[(usize, usize)] = if quick { &[(4, 8), (8, 16)] } else { &[(4, 8), (8, 16), (16, 32), (32, 64)] };
    let ico = if quick { 0..=2 } else { 0..=4 };
    let mut out: Vec<Polyhedron> = uv.iter().map(|&(m, n)| uv_sphere(c, 1.0, m, n)).collect();
    out.extend(ico.map(|l| icosphere(c, 1.0, l)));
    let r = generic_rotation();
    out.iter().map(|p| p.rotated(c, r)).collect()
}

/// The polyhedron's own exact factors to the receiver cells and its floor: the largest relative
/// deviation from the sphere's exact values. Computed by
/// [`clipped_polyhedron_to_polygon`] (back-face cut removed by clipping, so exponentially
/// convergent; 14 points per axis on the cells, 8/6/4 on the facets for ≤ 128/≤ 512/more
/// facets), which the tests check against the contour reference to 1e-10.
pub fn exact_floor(poly: &Polyhedron) -> Result<(Vec<f64>, f64), String> {
    use rayon::prelude::*;
    let cells = receiver_cells();
    let order_facet = match poly.len() {
        0..=128 => 8,
        129..=512 => 6,
        _ => 4,
    };
    let f = cells
        .par_iter()
        .map(|c| clipped_polyhedron_to_polygon(poly, c, order_facet, 14))
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|e| format!("{}: exact factors: {e}", poly.name))?;
    let floor = worst(&f, &exact_cells()).1;
    Ok((f, floor))
}

/// Settings of the study.
#[derive(Clone, Copy, Debug)]
pub struct StudySettings {
    /// Reduced lists.
    pub quick: bool,
    /// Timed repetitions (Monte Carlo: seeds).
    pub repeats: usize,
    /// A series stops after a point slower than this.
    pub series_budget: f64,
    /// Highest order swept.
    pub max_order: usize,
    /// Print progress to stderr.
    pub verbose: bool,
}

/// Emitter patches → the 54 receiver cells, each cell its own group, on the current pool.
fn measure_emitter<S: Surface<f64> + Sync>(
    emitter: &[Patch<'_, f64, S>],
    scene: &Scene<f64>,
    method: Method,
    repeats: usize,
) -> Result<(Solution, Vec<f64>), String> {
    let mut b_groups = Vec::new();
    for face in &scene.faces {
        let g = PatchGrid::new(face, RECEIVER_GRID, RECEIVER_GRID).map_err(|e| format!("face grid: {e}"))?;
        for p in g {
            b_groups.push(p.grid(1, 1).map_err(|e| format!("receiver cell: {e}"))?);
        }
    }
    let links = (0..b_groups.len()).map(|g| (0, g)).collect();
    let problem = Problem { a_groups: vec![emitter.to_vec()], b_groups, links };
    time_solve(|| solve(&problem, method, &(), true), repeats)
}

/// Runs the study on the current rayon pool.
pub fn run(settings: &StudySettings) -> Result<Vec<StudyRow>, String> {
    let threads = rayon::current_num_threads();
    let quick = settings.quick;
    let max_order = settings.max_order.max(1);
    let exact = exact_cells();
    let scene = Scene::<f64>::new(1.0).map_err(|e| format!("scene: {e}"))?;
    let Some(sphere) = scene.sphere else {
        return Err("the scene has no sphere".into());
    };
    let mut rows = Vec::new();
    let log = |s: String| {
        if settings.verbose {
            eprintln!("{s}");
        }
    };
    let mut push = |approach: &str,
                    family: &str,
                    grid: String,
                    elements: usize,
                    method: Method,
                    r: &(Solution, Vec<f64>),
                    floor: f64| {
        let (value, rel_error) = worst(&r.0.values, &exact);
        let seconds = median(r.1.clone());
        rows.push(StudyRow {
            approach: approach.into(),
            family: family.into(),
            grid,
            elements,
            order: method.order(),
            tolerance: method.tolerance().unwrap_or(f64::NAN),
            rays: 0,
            value,
            rel_error,
            polygon_floor: floor,
            evaluations: r.0.evaluations,
            seconds,
            repeats: r.1.len(),
            threads,
        });
        seconds
    };

    // The curved sphere.
    let t0 = Instant::now();
    let sphere_grids: &[(usize, usize)] = if quick { &[(2, 4)] } else { &[(2, 4), (4, 8), (8, 16)] };
    let top = if quick { 6 } else { 16 };
    let pair_top = if quick { 4 } else { 12 };
    let tol_end = if quick { 3 } else { 10 };
    let mut series: Vec<(&str, (usize, usize), Vec<Method>)> = Vec::new();
    for &g in sphere_grids {
        series.push(("curved-paper", g, (1..=max_order.min(top)).map(|order| Method::Paper { order }).collect()));
    }
    series.push((
        "curved-pair",
        (2, 4),
        (2..=max_order.min(pair_top)).step_by(2).map(|order| Method::Pair { order }).collect(),
    ));
    series.push((
        "curved-adaptive",
        (2, 4),
        (1..=tol_end).map(|e| Method::Adaptive { tolerance: 10f64.powi(-e) }).collect(),
    ));
    for (approach, (m, n), methods) in series {
        let patches: Vec<_> = PatchGrid::new(&sphere, m, n).map_err(|e| format!("sphere grid: {e}"))?.collect();
        for method in methods {
            let r = measure_emitter(&patches, &scene, method, settings.repeats)?;
            if push(approach, "curved", format!("{m}x{n}"), m * n, method, &r, f64::NAN) > settings.series_budget {
                break;
            }
        }
    }
    log(format!("polygons: curved sphere done ({:.1} s)", t0.elapsed().as_secs_f64()));

    // Polyhedra.
    for poly in polyhedra(quick) {
        let t0 = Instant::now();
        let (_, floor) = exact_floor(&poly)?;
        let facets = poly.surfaces::<f64>().map_err(|e| format!("{}: {e}", poly.name))?;
        let patches = facets
            .iter()
            .map(Patch::whole)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| format!("{}: {e}", poly.name))?;
        let orders = if quick { 4 } else { 8 };
        for order in 1..=max_order.min(orders) {
            let method = Method::Paper { order };
            let r = measure_emitter(&patches, &scene, method, settings.repeats)?;
            if push(&poly.name, poly.family, poly.name.clone(), poly.len(), method, &r, floor) > settings.series_budget
            {
                break;
            }
        }
        log(format!(
            "polygons: {} ({} facets, exact floor {floor:.2e}) done ({:.1} s)",
            poly.name,
            poly.len(),
            t0.elapsed().as_secs_f64()
        ));
    }

    // Monte Carlo.
    let top = if quick { 5 } else { 8 };
    for e in 3..=top {
        let rays = 10u64.pow(e);
        let mut secs = Vec::new();
        let mut sq = 0.0;
        let mut last = (0.0, 0.0);
        let reps = settings.repeats.max(1);
        for seed in 0..reps {
            let start = Instant::now();
            let f = mc::sphere_to_face_cells(1.0, RECEIVER_GRID, rays, 0x5EED + seed as u64);
            secs.push(start.elapsed().as_secs_f64());
            last = worst(&f, &exact);
            sq += last.1 * last.1;
        }
        rows.push(StudyRow {
            approach: "monte-carlo".into(),
            family: "mc".into(),
            grid: String::new(),
            elements: 0,
            order: 0,
            tolerance: f64::NAN,
            rays,
            value: last.0,
            rel_error: (sq / reps as f64).sqrt(),
            polygon_floor: f64::NAN,
            evaluations: rays,
            seconds: median(secs.clone()),
            repeats: secs.len(),
            threads,
        });
    }
    log("polygons: monte carlo done".into());
    Ok(rows)
}
