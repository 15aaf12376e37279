//! `pdm-ff validate`: the paper's section 4 test (a sphere in a cube) recomputed, with the paper's
//! numbers, exact or independent reference values and relative errors beside ours.
//!
//! * sphere → face for each of the six faces (Table 1), eq. (25);
//! * face → face for the 15 pairs (Table 3), eq. (26), the sphere as occluder;
//! * each face's sum over the other faces and the sphere (Table 4), face → sphere by
//!   reciprocity with the same rule's areas;
//! * the processing time of each part (Tables 2 and 5), median of `repeat` runs.
//!
//! Two modes ([`Mode`]): `paper` is the paper's method as written (fixed grid, fixed order,
//! curvature and occlusion tests at the sample points, plain sums for edge-adjacent pairs);
//! `accurate` is the best the kernel can do ([`pdm_kernel::pair_exchange`]: shared-edge and
//! shared-vertex transforms, visibility boundaries placed into the rule).
//!
//! Face numbering: see [`scene`].

pub mod compute;
pub mod paper;
pub mod reference;
pub mod report;
pub mod scene;
pub mod stack;

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

use pdm_kernel::{PdmError, Real, MAX_ORDER};

pub use compute::{Times, Values};
pub use paper::PaperValues;
pub use reference::Reference;

/// Which method (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// The paper's method as written.
    Paper,
    /// Singular-pair transforms and visibility boundaries in the rule.
    Accurate,
}

impl Mode {
    /// "paper" or "accurate".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Accurate => "accurate",
        }
    }
}

/// Floating-point width of the kernel computation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// `f32`.
    F32,
    /// `f64`.
    F64,
}

impl Precision {
    /// "f32" or "f64".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::F32 => "f32",
            Self::F64 => "f64",
        }
    }
}

/// Largest face grid K (K × K patches per face) and sphere grid dimension accepted.
pub const MAX_FACE_GRID: usize = 64;
/// Largest sphere grid dimension (M or N) accepted.
pub const MAX_SPHERE_GRID: usize = 256;
/// Largest number of kernel evaluations of a paper-mode run ([`RunConfig::paper_evaluations`]):
/// 1e12, hours on this kind of machine; e.g. a 256 × 256 sphere grid is accepted up to order 16
/// (4e11) and refused at order 32 (7e12).
pub const MAX_PAPER_EVALUATIONS: f64 = 1e12;
/// Largest `--repeat`.
pub const MAX_REPEAT: usize = 1000;

/// The settings of one computation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunConfig {
    /// Method.
    pub mode: Mode,
    /// Sphere grid (M along φ, N along θ).
    pub sphere_grid: (usize, usize),
    /// Face grid K (K × K per face).
    pub face_grid: usize,
    /// Gauss order per axis (separate pairs).
    pub order: usize,
    /// Gauss order per variable for touching pairs (accurate mode).
    pub singular_order: usize,
    /// Sphere radius (0 = no sphere).
    pub radius: f64,
    /// Accurate mode only: `Some(tol)` computes every patch pair with
    /// [`pdm_kernel::adaptive_exchange`] to relative tolerance `tol` (order and subdivision
    /// chosen per pair) instead of the fixed orders.
    pub tolerance: Option<f64>,
}

impl RunConfig {
    /// Checks every setting; the error names the bad value.
    pub fn check(&self) -> Result<(), ValidateError> {
        let bad =
            |what: &str, value: String, why: &str| Err(ValidateError::BadSetting(format!("{what} {value}: {why}")));
        if !(self.radius >= 0.0 && self.radius < 3.0) {
            return bad("sphere radius", format!("{}", self.radius), "must satisfy 0 <= R < 3 (0 = no sphere)");
        }
        if !(1..=MAX_FACE_GRID).contains(&self.face_grid) {
            return bad("face grid", self.face_grid.to_string(), &format!("must be in 1..={MAX_FACE_GRID}"));
        }
        let (m, n) = self.sphere_grid;
        if !(1..=MAX_SPHERE_GRID).contains(&m) || !(1..=MAX_SPHERE_GRID).contains(&n) {
            return bad("sphere grid", format!("{m}x{n}"), &format!("both must be in 1..={MAX_SPHERE_GRID}"));
        }
        for (what, o) in [("order", self.order), ("singular order", self.singular_order)] {
            if !(1..=MAX_ORDER).contains(&o) {
                return bad(what, o.to_string(), &format!("Gauss order must be in 1..={MAX_ORDER}"));
            }
        }
        if let Some(tol) = self.tolerance {
            if !(tol.is_finite() && (MIN_TOLERANCE..=MAX_TOLERANCE).contains(&tol)) {
                return bad(
                    "tolerance",
                    format!("{tol:e}"),
                    &format!("must be in {MIN_TOLERANCE:e}..={MAX_TOLERANCE:e}"),
                );
            }
            if self.mode != Mode::Accurate {
                return bad("tolerance", format!("{tol:e}"), "applies to --mode accurate only");
            }
        }
        if self.mode == Mode::Paper {
            let evaluations = self.paper_evaluations();
            if evaluations > MAX_PAPER_EVALUATIONS {
                return bad(
                    "sphere grid",
                    format!("{m}x{n} with face grid {} and order {}", self.face_grid, self.order),
                    &format!(
                        "paper mode would take {evaluations:.1e} kernel evaluations (over {MAX_PAPER_EVALUATIONS:.0e}, \
                         hours); use a smaller grid or order"
                    ),
                );
            }
        }
        Ok(())
    }

    /// Number of sphere patches (0 without a sphere).
    #[must_use]
    pub fn sphere_patches(&self) -> usize {
        if self.radius > 0.0 {
            self.sphere_grid.0 * self.sphere_grid.1
        } else {
            0
        }
    }

    /// Kernel evaluations of a paper-mode run: order⁴ for each of its patch pairs (every
    /// sphere patch against the 6 K² face patches, and the 15 face pairs' K⁴ patch pairs).
    #[must_use]
    pub fn paper_evaluations(&self) -> f64 {
        let k2 = (self.face_grid * self.face_grid) as f64;
        let pairs = self.sphere_patches() as f64 * 6.0 * k2 + 15.0 * k2 * k2;
        pairs * (self.order as f64).powi(4)
    }

    /// Total patch count: sphere patches + 6 K².
    #[must_use]
    pub fn total_patches(&self) -> usize {
        self.sphere_patches() + 6 * self.face_grid * self.face_grid
    }
}

/// Why `validate` failed.
#[derive(Clone, Debug, PartialEq)]
pub enum ValidateError {
    /// A setting out of range (the message names the value).
    BadSetting(String),
    /// The kernel refused a computation.
    Kernel {
        /// What was being computed.
        context: &'static str,
        /// The kernel's error.
        error: PdmError,
    },
    /// The reference could not be computed.
    Reference(String),
    /// The worker threads could not be started.
    Threads(String),
}

impl fmt::Display for ValidateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadSetting(m) => f.write_str(m),
            Self::Kernel { context, error } => write!(f, "kernel error while {context}: {error}"),
            Self::Reference(m) => write!(f, "reference: {m}"),
            Self::Threads(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for ValidateError {}

/// Progress reporting (a progress bar in the command line; nothing in tests).
pub trait Progress: Sync {
    /// The computation moves to part `label`.
    fn stage(&self, label: &str);
    /// `n` more units done (one unit = one outer patch against a whole surface).
    fn advance(&self, n: u64);
}

/// Reports nothing.
#[derive(Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn stage(&self, _label: &str) {}
    fn advance(&self, _n: u64) {}
}

/// Counts units (for tests).
#[derive(Debug, Default)]
pub struct CountProgress(pub AtomicU64);

impl Progress for CountProgress {
    fn stage(&self, _label: &str) {}
    fn advance(&self, n: u64) {
        self.0.fetch_add(n, Ordering::Relaxed);
    }
}

/// The result of one precision: values, and the time of every repetition.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The precision.
    pub precision: Precision,
    /// The values (identical in every repetition: the computation is deterministic).
    pub values: Values,
    /// Wall times of each repetition.
    pub times: Vec<Times>,
}

impl Outcome {
    /// Median wall time of the sphere → face part.
    #[must_use]
    pub fn sphere_face_seconds(&self) -> f64 {
        median(self.times.iter().map(|t| t.sphere_face).collect())
    }
    /// Median wall time of the face → face part.
    #[must_use]
    pub fn face_face_seconds(&self) -> f64 {
        median(self.times.iter().map(|t| t.face_face).collect())
    }
    /// Median wall time of a whole computation (both parts).
    #[must_use]
    pub fn total_seconds(&self) -> f64 {
        median(self.times.iter().map(|t| t.sphere_face + t.face_face).collect())
    }
}

/// Median (mean of the middle two for an even count; 0 for none).
#[must_use]
pub fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    match (xs.get(n.wrapping_sub(1) / 2), xs.get(n / 2)) {
        (Some(a), Some(b)) => 0.5 * (a + b),
        _ => 0.0,
    }
}

/// Runs the computation `repeat` times (at least once) in precision `T`, on a rayon pool of as
/// many workers as the current pool has, with stacks sized for the run's sample capacity
/// ([`stack::thread_stack`]; the calling thread only waits).
pub fn run<T: Real>(cfg: &RunConfig, repeat: usize, progress: &dyn Progress) -> Result<Outcome, ValidateError> {
    cfg.check()?;
    let pool = stack::pool::<T>(0, capacity(cfg)).map_err(ValidateError::Threads)?;
    pool.install(|| run_repeated::<T>(cfg, repeat, progress))
}

fn run_repeated<T: Real>(cfg: &RunConfig, repeat: usize, progress: &dyn Progress) -> Result<Outcome, ValidateError> {
    let precision = if T::MANTISSA_DIGITS == 24 { Precision::F32 } else { Precision::F64 };
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeat.max(1) {
        let (values, t) = run_dispatch::<T>(cfg, progress)?;
        times.push(t);
        last = Some(values);
    }
    match last {
        Some(values) => Ok(Outcome { precision, values, times }),
        None => Err(ValidateError::BadSetting("repeat 0: must be at least 1".into())),
    }
}

/// Smallest `--tolerance` (below it the f64 rounding of the sums dominates).
pub const MIN_TOLERANCE: f64 = 1e-13;
/// Largest `--tolerance`.
pub const MAX_TOLERANCE: f64 = 0.1;

/// The sample capacity of a run: [`stack::capacity_for`] the largest order it samples
/// (CAP ≥ order²; the tolerance mode's orders go to [`compute::ADAPTIVE_MAX_ORDER`] + 2).
#[must_use]
pub fn capacity(cfg: &RunConfig) -> usize {
    let order = if cfg.tolerance.is_some() { cfg.order.max(compute::ADAPTIVE_MAX_ORDER + 2) } else { cfg.order };
    stack::capacity_for(order)
}

/// Runs [`compute::run_once`] with the capacity [`capacity`] picks
/// ([`pdm_kernel::with_capacity`]).
fn run_dispatch<T: Real>(cfg: &RunConfig, progress: &dyn Progress) -> Result<(Values, Times), ValidateError> {
    struct Run<'c, T> {
        cfg: &'c RunConfig,
        progress: &'c dyn Progress,
        precision: std::marker::PhantomData<T>,
    }
    impl<T: Real> pdm_kernel::WithCapacity for Run<'_, T> {
        type Output = Result<(Values, Times), ValidateError>;
        fn run<const CAP: usize>(self) -> Self::Output {
            compute::run_once::<T, CAP>(self.cfg, self.progress)
        }
    }
    let run = Run::<T> { cfg, progress, precision: std::marker::PhantomData };
    pdm_kernel::with_capacity(capacity(cfg), run)
        .map_err(|error| ValidateError::Kernel { context: "choosing the sample capacity", error })?
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]
mod tests {
    use super::*;

    fn cfg(mode: Mode, sphere_grid: (usize, usize), k: usize, order: usize, radius: f64) -> RunConfig {
        RunConfig { mode, sphere_grid, face_grid: k, order, singular_order: 8, radius, tolerance: None }
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(vec![]), 0.0);
    }

    #[test]
    fn bad_settings_are_named() {
        let c = cfg(Mode::Paper, (4, 8), 3, 5, 3.0);
        assert!(c.check().unwrap_err().to_string().contains("sphere radius 3"));
        let c = cfg(Mode::Paper, (4, 0), 3, 5, 1.0);
        assert!(c.check().unwrap_err().to_string().contains("4x0"));
        let c = cfg(Mode::Paper, (4, 8), 3, 33, 1.0);
        assert!(c.check().unwrap_err().to_string().contains("order 33"));
    }

    /// The sphere is convex: passing it as occluder for sphere → face changes nothing (no
    /// mutually facing sample pair is blocked; the sums agree to rounding — the two code paths
    /// add in a different order).
    #[test]
    fn sphere_as_its_own_occluder_changes_nothing() {
        use pdm_kernel::{form_factor, mutually_facing, Occluder, PatchGrid, PatchSamples};
        let scene = scene::Scene::<f64>::new(1.0).unwrap();
        let sphere = scene.sphere.unwrap();
        for face in &scene.faces {
            for ps in PatchGrid::new(&sphere, 4, 8).unwrap() {
                let sa = PatchSamples::<f64, 25>::new(&ps, 5).unwrap();
                for pf in PatchGrid::new(face, 3, 3).unwrap() {
                    let sb = PatchSamples::<f64, 25>::new(&pf, 5).unwrap();
                    for p in sa.iter() {
                        for q in sb.iter() {
                            if mutually_facing(p.point, p.unit_normal, q.point, q.unit_normal) {
                                assert!(!sphere.blocks(p.point, q.point));
                            }
                        }
                    }
                    let (free, occluded) =
                        (form_factor(&sa, &sb, &()).unwrap(), form_factor(&sa, &sb, &sphere).unwrap());
                    assert!((free - occluded).abs() <= 1e-15 * free, "{free} vs {occluded}");
                }
            }
        }
    }

    /// Symmetries of the scene: faces 2–5 agree, as do 1 and 6; all adjacent pairs agree.
    #[test]
    fn paper_mode_is_symmetric_and_counts_progress() {
        let c = cfg(Mode::Paper, (4, 8), 2, 4, 1.0);
        let progress = CountProgress::default();
        let out = run::<f64>(&c, 1, &progress).unwrap();
        assert_eq!(progress.0.load(Ordering::Relaxed), compute::work_units(&c));
        let s = out.values.sphere_to_face.unwrap();
        for f in [1, 2, 3] {
            assert!((s[f] - s[4]).abs() < 1e-14 * s[4], "{s:?}");
        }
        assert!((s[0] - s[5]).abs() < 1e-14, "{s:?}");
        let ff = out.values.face_to_face;
        for (k, &(a, b)) in scene::FACE_PAIRS.iter().enumerate() {
            let same = if scene::is_opposite(a, b) { ff[4] } else { ff[0] };
            assert!((ff[k] - same).abs() < 1e-12, "{a}-{b}: {ff:?}");
        }
    }
}
