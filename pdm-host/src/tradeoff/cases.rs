//! The swept cases: four catalogue pairs and the paper's scene, each with exact or independent
//! reference values, and the sweep points (mode × subdivision × order or tolerance) of each.
//!
//! | case | geometry | reference |
//! |------|----------|-----------|
//! | `far` | unit squares facing each other at distance 5 | C-11 in 40-digit arithmetic ([`FAR_REFERENCE`]) |
//! | `near` | the same at distance 0.2 | C-11, `parallel_rectangles(1, 1, 0.2)` |
//! | `shared-edge` | perpendicular unit squares with a common edge | C-14, `perpendicular_rectangles(1, 1, 1)` |
//! | `curved` | unit sphere (eq. 19, pole towards the square) → square of side 2 at distance 2 from the centre | solid angle, `sphere_to_polygon` |
//! | `scene-sphere-face` | the paper's scene, sphere → each of the six faces (eq. 25) | 1/6 |
//! | `scene-face-face` | the paper's scene, the 15 face pairs with the sphere as occluder (eq. 26) | `reference::cube` (stored, ±7e-13 / ±2e-11) |
//!
//! Subdivision: for the pairs, both patches cut n × n (the sphere of `curved` n × 2n); for the
//! scene, sphere M × N and faces K × K ("MxN/K"). A case's error is the largest relative error
//! over its values (6 for sphere → face, 15 for face → face).

use std::time::Instant;

use clap::ValueEnum;
use pdm_kernel::{vec3, Parallelogram, Patch, PatchGrid, PdmError, Real, Sphere, Surface};

use super::engine::{solve, Method, Problem, Solution};
use crate::reference::closed_form::{parallel_rectangles, perpendicular_rectangles, sphere_to_polygon};
use crate::validate::scene::{Scene, FACE_PAIRS};

/// A swept case (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, ValueEnum)]
pub enum CaseId {
    /// C-11 unit squares at distance 5.
    Far,
    /// C-11 unit squares at distance 0.2.
    Near,
    /// C-14 perpendicular unit squares sharing an edge.
    SharedEdge,
    /// Unit sphere → square (solid angle).
    Curved,
    /// The paper's scene: sphere → faces.
    SceneSphereFace,
    /// The paper's scene: face → face with the sphere as occluder.
    SceneFaceFace,
}

impl CaseId {
    /// All cases, in report order.
    pub const ALL: [Self; 6] =
        [Self::Far, Self::Near, Self::SharedEdge, Self::Curved, Self::SceneSphereFace, Self::SceneFaceFace];

    /// The CSV name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Far => "far",
            Self::Near => "near",
            Self::SharedEdge => "shared-edge",
            Self::Curved => "curved",
            Self::SceneSphereFace => "scene-sphere-face",
            Self::SceneFaceFace => "scene-face-face",
        }
    }

    /// From the CSV name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }

    /// One line for plot titles and tables.
    #[must_use]
    pub fn title(self) -> &'static str {
        match self {
            Self::Far => "far: unit squares at distance 5 (C-11)",
            Self::Near => "near: unit squares at distance 0.2 (C-11)",
            Self::SharedEdge => "shared edge: perpendicular unit squares (C-14)",
            Self::Curved => "curved: sphere -> square (solid angle)",
            Self::SceneSphereFace => "paper's scene: sphere -> faces (1/6)",
            Self::SceneFaceFace => "paper's scene: face -> face, sphere occludes",
        }
    }

    /// `true` for the scene cases (run in parallel over patch pairs).
    #[must_use]
    pub fn is_scene(self) -> bool {
        matches!(self, Self::SceneSphereFace | Self::SceneFaceFace)
    }
}

/// Subdivision of a sweep point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grid {
    /// Both patches n × n (the sphere of `curved`: n × 2n).
    Uniform(usize),
    /// Sphere M × N, faces K × K.
    Scene {
        /// Sphere cells along φ.
        m: usize,
        /// Sphere cells along θ.
        n: usize,
        /// Face cells per side.
        k: usize,
    },
}

impl Grid {
    /// "n" or "MxN/K".
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Self::Uniform(n) => n.to_string(),
            Self::Scene { m, n, k } => format!("{m}x{n}/{k}"),
        }
    }
}

/// Reference values of a case's links (value, relative uncertainty), in link order.
#[must_use]
pub fn references(case: CaseId) -> Vec<(f64, f64)> {
    match case {
        CaseId::Far => vec![(FAR_REFERENCE, 0.0)],
        CaseId::Near => vec![(parallel_rectangles(1.0, 1.0, NEAR), 0.0)],
        CaseId::SharedEdge => vec![(perpendicular_rectangles(1.0, 1.0, 1.0), 0.0)],
        CaseId::Curved => vec![(sphere_to_polygon([0.0; 3], &CURVED_SQUARE), 0.0)],
        CaseId::SceneSphereFace => vec![(1.0 / 6.0, 0.0); 6],
        CaseId::SceneFaceFace => {
            let r = crate::validate::reference::compute(1.0, false);
            FACE_PAIRS
                .iter()
                .map(|&(a, b)| {
                    if crate::validate::scene::is_opposite(a, b) {
                        (r.opposite, r.opposite_uncertainty / r.opposite)
                    } else {
                        (r.adjacent, r.adjacent_uncertainty / r.adjacent)
                    }
                })
                .collect()
        }
    }
}

/// Distance of the `far` squares.
pub const FAR: f64 = 5.0;
/// C-11 for unit squares at distance 5 (X = Y = 0.2) evaluated in 40-digit arithmetic
/// (0.01240397731324510189774…). The f64 evaluation `parallel_rectangles(1, 1, 5)` is 5.0e-14
/// off (the bracket cancels like X·Y), which would otherwise be the floor of this case.
pub const FAR_REFERENCE: f64 = 0.012_403_977_313_245_102;
/// Distance of the `near` squares.
pub const NEAR: f64 = 0.2;
/// The `curved` case's square (side 2 in the plane z = −2, facing +z), counter-clockwise seen
/// from +z; the unit sphere sits at the origin.
pub const CURVED_SQUARE: [[f64; 3]; 4] = [[-1.0, -1.0, -2.0], [1.0, -1.0, -2.0], [1.0, 1.0, -2.0], [-1.0, 1.0, -2.0]];

fn v<T: Real>(x: f64, y: f64, z: f64) -> pdm_kernel::Vec3<T> {
    vec3(T::from_f64(x), T::from_f64(y), T::from_f64(z))
}

fn kernel_err(e: PdmError) -> String {
    format!("kernel error (building the geometry): {e}")
}

fn grid<'s, T: Real, S: Surface<T>>(surface: &'s S, m: usize, n: usize) -> Result<Vec<Patch<'s, T, S>>, String> {
    Ok(cells(surface, m, n)?.collect())
}

fn cells<'s, T: Real, S: Surface<T>>(surface: &'s S, m: usize, n: usize) -> Result<PatchGrid<'s, T, S>, String> {
    PatchGrid::new(surface, m, n).map_err(kernel_err)
}

/// The result of timing one sweep point.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The (last) solution.
    pub solution: Solution,
    /// Wall time of each repetition, seconds.
    pub seconds: Vec<f64>,
    /// Number of patches in the problem.
    pub patches: usize,
}

/// A point that runs longer than this is not repeated.
pub const LONG_POINT_SECONDS: f64 = 1.0;

/// Runs `f` `repeats` times (once if the first run takes longer than [`LONG_POINT_SECONDS`]):
/// the last solution and the wall time of each run.
pub fn time_solve(
    mut f: impl FnMut() -> Result<Solution, String>,
    repeats: usize,
) -> Result<(Solution, Vec<f64>), String> {
    let mut seconds = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let s = f()?;
        let dt = start.elapsed().as_secs_f64();
        seconds.push(dt);
        last = Some(s);
        if dt > LONG_POINT_SECONDS {
            break;
        }
    }
    last.map(|s| (s, seconds)).ok_or_else(|| "no repetition ran".to_string())
}

/// Computes `case` at one sweep point in precision `T`, `repeats` times (once if the first run
/// takes longer than [`LONG_POINT_SECONDS`]); scene cases run on the current rayon pool, the
/// pairs on one thread. Geometry is built outside the timed region.
pub fn measure<T: Real>(case: CaseId, method: Method, grid_spec: Grid, repeats: usize) -> Result<Measured, String> {
    let parallel = case.is_scene();
    let uniform = match grid_spec {
        Grid::Uniform(n) => n,
        Grid::Scene { .. } => 0,
    };
    let scene_grid = match grid_spec {
        Grid::Scene { m, n, k } => Some((m, n, k)),
        Grid::Uniform(_) => None,
    };
    let need_uniform = || if uniform > 0 { Ok(uniform) } else { Err(format!("{}: needs a uniform grid", case.name())) };
    let need_scene = || scene_grid.ok_or_else(|| format!("{}: needs a scene grid MxN/K", case.name()));
    match case {
        CaseId::Far | CaseId::Near | CaseId::SharedEdge => {
            let n = need_uniform()?;
            let (a, b) = match case {
                CaseId::SharedEdge => (
                    Parallelogram::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)),
                    Parallelogram::new(v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)),
                ),
                _ => {
                    let d = if case == CaseId::Far { FAR } else { NEAR };
                    (
                        Parallelogram::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)),
                        Parallelogram::new(v(0.0, 0.0, d), v(0.0, 1.0, 0.0), v(1.0, 0.0, 0.0)),
                    )
                }
            };
            let (a, b): (Parallelogram<T>, Parallelogram<T>) = (a.map_err(kernel_err)?, b.map_err(kernel_err)?);
            let problem =
                Problem { a_groups: vec![grid(&a, n, n)?], b_groups: vec![cells(&b, n, n)?], links: vec![(0, 0)] };
            let (solution, seconds) = time_solve(|| solve(&problem, method, &(), parallel), repeats)?;
            Ok(Measured { solution, seconds, patches: 2 * n * n })
        }
        CaseId::Curved => {
            let n = need_uniform()?;
            let sphere = Sphere::<T>::outer(v(0.0, 0.0, 0.0), T::ONE).map_err(kernel_err)?;
            let [c0, c1, _, c3] = CURVED_SQUARE;
            let sub = |p: [f64; 3], q: [f64; 3]| v::<T>(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
            let square = Parallelogram::new(v(c0[0], c0[1], c0[2]), sub(c1, c0), sub(c3, c0)).map_err(kernel_err)?;
            let problem = Problem {
                a_groups: vec![grid(&sphere, n, 2 * n)?],
                b_groups: vec![cells(&square, n, n)?],
                links: vec![(0, 0)],
            };
            let (solution, seconds) = time_solve(|| solve(&problem, method, &(), parallel), repeats)?;
            Ok(Measured { solution, seconds, patches: 3 * n * n })
        }
        CaseId::SceneSphereFace | CaseId::SceneFaceFace => {
            let (m, n, k) = need_scene()?;
            let scene = Scene::<T>::new(1.0).map_err(kernel_err)?;
            let Some(sphere) = scene.sphere else {
                return Err("the scene has no sphere".into());
            };
            let faces = scene.faces.iter().map(|f| grid(f, k, k)).collect::<Result<Vec<_>, _>>()?;
            let face_grids = scene.faces.iter().map(|f| cells(f, k, k)).collect::<Result<Vec<_>, _>>()?;
            let patches = m * n + 6 * k * k;
            let (solution, seconds) = if case == CaseId::SceneSphereFace {
                // No occluder: the convex sphere's only visibility test is the curvature test
                // (as in `pdm-ff validate`).
                let problem = Problem {
                    a_groups: vec![grid(&sphere, m, n)?],
                    b_groups: face_grids,
                    links: (0..6).map(|f| (0, f)).collect(),
                };
                time_solve(|| solve(&problem, method, &(), parallel), repeats)?
            } else {
                let problem = Problem {
                    a_groups: faces,
                    b_groups: face_grids,
                    links: FACE_PAIRS.iter().map(|&(a, b)| (a - 1, b - 1)).collect(),
                };
                time_solve(|| solve(&problem, method, &sphere, parallel), repeats)?
            };
            Ok(Measured { solution, seconds, patches })
        }
    }
}

/// A series: one mode on one grid, its points in order of increasing cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The grid.
    pub grid: Grid,
    /// The points (same mode), cheapest first.
    pub methods: Vec<Method>,
}

fn orders(lo: usize, hi: usize, step: usize, kind: fn(usize) -> Method) -> Vec<Method> {
    (lo..=hi).step_by(step.max(1)).map(kind).collect()
}

fn paper(order: usize) -> Method {
    Method::Paper { order }
}

fn pair(order: usize) -> Method {
    Method::Pair { order }
}

/// Tolerances 10^−from … 10^−to, one per decade.
fn tolerances(from: i32, to: i32) -> Vec<Method> {
    (from..=to).map(|k| Method::Adaptive { tolerance: 10f64.powi(-k) }).collect()
}

/// The sweep of `case`: series of points (see TRADEOFF.md for the lists). `single` is `true`
/// for f32 (adaptive tolerances stop at 1e-6, below which f32 cannot converge).
#[must_use]
pub fn sweep(case: CaseId, quick: bool, max_order: usize, single: bool) -> Vec<Series> {
    let p = max_order.max(1);
    let tol_end = if single { 6 } else { 12 };
    let mut out = Vec::new();
    let mut add = |grid: Grid, methods: Vec<Method>| {
        if !methods.is_empty() {
            out.push(Series { grid, methods });
        }
    };
    let u = Grid::Uniform;
    let scene = |m, n, k| Grid::Scene { m, n, k };
    if quick {
        match case {
            CaseId::Far | CaseId::Near | CaseId::SharedEdge | CaseId::Curved => {
                add(u(1), orders(1, p.min(8), 1, paper));
                if case == CaseId::Near {
                    add(u(2), orders(1, p.min(6), 1, paper));
                }
                add(u(1), orders(2, p.min(6), 2, pair));
                add(u(1), tolerances(2, tol_end.min(6)));
            }
            CaseId::SceneSphereFace | CaseId::SceneFaceFace => {
                add(scene(2, 4, 1), orders(1, p.min(6), 1, paper));
                add(scene(4, 8, 3), orders(5, p.min(5), 1, paper));
                add(scene(2, 4, 1), orders(2, p.min(4), 2, pair));
                add(scene(2, 4, 1), tolerances(2, 3));
            }
        }
        return out;
    }
    match case {
        CaseId::Far | CaseId::Near | CaseId::SharedEdge | CaseId::Curved => {
            for n in [1, 2, 4] {
                add(u(n), orders(1, p, 1, paper));
            }
            for n in [1, 2] {
                add(u(n), orders(1, p, 1, pair));
            }
            add(u(1), tolerances(1, tol_end));
        }
        CaseId::SceneSphereFace | CaseId::SceneFaceFace => {
            for (m, n, k) in [(2, 4, 1), (4, 8, 3), (8, 8, 6)] {
                add(scene(m, n, k), orders(1, p.min(12), 1, paper));
            }
            for (m, n, k) in [(2, 4, 1), (4, 8, 3)] {
                add(scene(m, n, k), orders(2, p.min(12), 2, pair));
            }
            for (m, n, k) in [(2, 4, 1), (4, 8, 3)] {
                add(scene(m, n, k), tolerances(1, tol_end.min(10)));
            }
        }
    }
    out
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;

    /// The references against 40-digit evaluations (mpmath) of the same closed forms.
    #[test]
    #[allow(clippy::excessive_precision)]
    fn references_match_high_precision_values() {
        let high = [
            (CaseId::Far, 0.012_403_977_313_245_101_897_74),
            (CaseId::Near, 0.690_244_694_073_796_333_800_7),
            (CaseId::SharedEdge, 0.200_043_776_075_403_154_239_6),
            (CaseId::Curved, 0.064_094_216_848_974_931_611_87),
        ];
        for (case, exact) in high {
            let r = references(case)[0].0;
            assert!(((r - exact) / exact).abs() < 4e-16, "{}: {r} vs {exact}", case.name());
        }
        // The f64 C-11 at X = Y = 0.2 loses digits (why `far` stores its value).
        let f64_c11 = parallel_rectangles(1.0, 1.0, FAR);
        assert!(((f64_c11 - FAR_REFERENCE) / FAR_REFERENCE).abs() < 1e-13);
        assert_eq!(references(CaseId::SceneSphereFace).len(), 6);
        assert_eq!(references(CaseId::SceneFaceFace).len(), 15);
    }

    /// Paper mode on the scene equals `pdm-ff validate --mode paper` (same sums, same order of
    /// addition up to the grouping of partial sums).
    #[test]
    fn scene_paper_mode_matches_validate() {
        use crate::validate::{run, Mode, NoProgress, RunConfig};
        let cfg = RunConfig {
            mode: Mode::Paper,
            sphere_grid: (4, 8),
            face_grid: 3,
            order: 5,
            singular_order: 8,
            radius: 1.0,
            tolerance: None,
        };
        let out = run::<f64>(&cfg, 1, &NoProgress).unwrap();
        let grid = Grid::Scene { m: 4, n: 8, k: 3 };
        let sf = measure::<f64>(CaseId::SceneSphereFace, Method::Paper { order: 5 }, grid, 1).unwrap();
        let ff = measure::<f64>(CaseId::SceneFaceFace, Method::Paper { order: 5 }, grid, 1).unwrap();
        for (a, b) in sf.solution.values.iter().zip(out.values.sphere_to_face.unwrap()) {
            assert!((a - b).abs() < 1e-14 * b, "{a} vs {b}");
        }
        for (a, b) in ff.solution.values.iter().zip(out.values.face_to_face) {
            assert!((a - b).abs() < 1e-14 * b, "{a} vs {b}");
        }
        assert_eq!(sf.solution.evaluations, 6 * 32 * 9 * 625);
        assert_eq!(sf.patches, 86);
    }
}
