//! The computations a sweep point times: form factors between groups of patches by one of three
//! kernel methods, with the number of kernel evaluations each took.
//!
//! A [`Problem`] is a list of emitter groups, a list of receiver groups and the links
//! (emitter group → receiver group) whose factors are wanted, F = Σ_{a ∈ A} Σ_{b ∈ B}
//! A_a F_{a→b} / Σ_{a ∈ A} A_a (eqs. 25–26). Methods ([`Method`]):
//!
//! * `paper` — the paper's eq. (16) at a fixed order (`pdm_kernel::Method::Paper`); areas by
//!   eq. (12) with the same rule. Evaluations: order⁴ per patch pair.
//! * `pair` — [`pdm_kernel::pair_exchange`] with visibility boundaries, the singular order equal
//!   to the order (`Method::Pair`); areas with the same rule. Evaluations: the kernel's own
//!   count ([`pdm_kernel::Estimate::evaluations`]).
//! * `adaptive` — [`pdm_kernel::adaptive_exchange`] at a relative tolerance (max order 16, max
//!   depth 4; `Method::Tolerance`); areas at order 20. Evaluations: the kernel's own count.
//!
//! Work is split into one task per (link, emitter patch), each the emitter patch against the
//! receiver group's grid by the kernel's substructuring ([`pdm_kernel::surface_exchange`]);
//! the sample capacity is chosen by [`pdm_kernel::with_capacity`]. Tasks run on the current
//! rayon pool when `parallel`, and their results are added in task order, so values do not
//! depend on the thread count.

use pdm_kernel::{
    self as kernel, Adaptive, Occluder, PairSettings, Patch, PatchGrid, PdmError, Quadrature, Real, Surface, MAX_ORDER,
};
use rayon::prelude::*;

/// Largest Gauss order of the adaptive mode.
pub const ADAPTIVE_MAX_ORDER: usize = 16;
/// Largest subdivision depth of the adaptive mode.
pub const ADAPTIVE_MAX_DEPTH: u32 = 4;
/// Order of the emitter areas in adaptive mode (exact to rounding for every surface here).
pub const ADAPTIVE_AREA_ORDER: usize = 20;

/// How a problem is integrated (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Eq. (16) at a fixed order.
    Paper {
        /// Gauss points per axis.
        order: usize,
    },
    /// `pair_exchange` with visibility boundaries, singular order = order.
    Pair {
        /// Gauss points per axis (and per variable for touching pairs).
        order: usize,
    },
    /// `adaptive_exchange` at a relative tolerance.
    Adaptive {
        /// Relative tolerance per patch pair.
        tolerance: f64,
    },
}

impl Method {
    /// "paper", "pair" or "adaptive".
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper { .. } => "paper",
            Self::Pair { .. } => "pair",
            Self::Adaptive { .. } => "adaptive",
        }
    }

    /// The fixed order (0 for the adaptive mode).
    #[must_use]
    pub fn order(self) -> usize {
        match self {
            Self::Paper { order } | Self::Pair { order } => order,
            Self::Adaptive { .. } => 0,
        }
    }

    /// Order of the emitter areas: the method's order, [`ADAPTIVE_AREA_ORDER`] in adaptive mode.
    #[must_use]
    pub fn area_order(self) -> usize {
        match self {
            Self::Paper { order } | Self::Pair { order } => order,
            Self::Adaptive { .. } => ADAPTIVE_AREA_ORDER,
        }
    }

    /// The tolerance (adaptive mode only).
    #[must_use]
    pub fn tolerance(self) -> Option<f64> {
        match self {
            Self::Adaptive { tolerance } => Some(tolerance),
            _ => None,
        }
    }
}

/// Emitter groups, receiver groups, and the links whose factors are wanted.
#[derive(Debug)]
pub struct Problem<'s, T, SA: ?Sized, SB: ?Sized> {
    /// Emitter groups (a surface's patches each).
    pub a_groups: Vec<Vec<Patch<'s, T, SA>>>,
    /// Receiver groups (a grid of a surface's patches each).
    pub b_groups: Vec<PatchGrid<'s, T, SB>>,
    /// (emitter group, receiver group) pairs.
    pub links: Vec<(usize, usize)>,
}

/// The factors of a problem's links (in f64, after all arithmetic in `T`) and the kernel
/// evaluations spent.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// F for each link, in the order of `Problem::links`.
    pub values: Vec<f64>,
    /// Kernel evaluations (see the module docs for what counts).
    pub evaluations: u64,
}

fn kernel_err(context: &'static str) -> impl Fn(PdmError) -> String {
    move |e| match e {
        PdmError::InvalidResult | PdmError::Unresolvable => format!("{REFUSED} ({context}): {e}"),
        _ => format!("kernel error ({context}): {e}"),
    }
}

/// Start of the message of a sweep point whose value the kernel refused (outside the physical
/// bounds, or beyond the working precision): the sweep records no row for it and goes on.
pub const REFUSED: &str = "refused by the kernel";

/// Solves `problem` by `method` with `occluders` (see the module docs).
pub fn solve<T, SA, SB, O>(
    problem: &Problem<'_, T, SA, SB>,
    method: Method,
    occluders: &O,
    parallel: bool,
) -> Result<Solution, String>
where
    T: Real,
    SA: Surface<T> + Sync + ?Sized,
    SB: Surface<T> + Sync + ?Sized,
    O: Occluder<T> + Sync + ?Sized,
{
    let (kernel_method, need) = match method {
        Method::Paper { order } | Method::Pair { order } => {
            if !(1..=MAX_ORDER).contains(&order) {
                return Err(format!("order {order} outside 1..={MAX_ORDER}"));
            }
            let m = match method {
                Method::Paper { .. } => kernel::Method::Paper(Quadrature::uniform(order)),
                _ => kernel::Method::Pair(PairSettings { order, singular_order: order, boundaries: true }),
            };
            (m, order * order)
        }
        Method::Adaptive { tolerance } => {
            let settings = Adaptive {
                tolerance: T::from_f64(tolerance),
                max_order: ADAPTIVE_MAX_ORDER,
                max_depth: ADAPTIVE_MAX_DEPTH,
                absolute: T::ZERO,
            };
            (kernel::Method::Tolerance(settings), (ADAPTIVE_MAX_ORDER + 2) * (ADAPTIVE_MAX_ORDER + 2))
        }
    };
    let job = Job { problem, method: kernel_method, area_order: method.area_order(), occluders, parallel };
    kernel::with_capacity(need, job).map_err(kernel_err("choosing the sample capacity"))?
}

/// [`solve`] at one sample capacity, chosen by [`kernel::with_capacity`].
struct Job<'p, 's, T, SA: ?Sized, SB: ?Sized, O: ?Sized> {
    problem: &'p Problem<'s, T, SA, SB>,
    method: kernel::Method<T>,
    area_order: usize,
    occluders: &'p O,
    parallel: bool,
}

impl<T, SA, SB, O> kernel::WithCapacity for Job<'_, '_, T, SA, SB, O>
where
    T: Real,
    SA: Surface<T> + Sync + ?Sized,
    SB: Surface<T> + Sync + ?Sized,
    O: Occluder<T> + Sync + ?Sized,
{
    type Output = Result<Solution, String>;
    fn run<const CAP: usize>(self) -> Self::Output {
        solve_cap::<T, SA, SB, O, CAP>(self.problem, self.method, self.area_order, self.occluders, self.parallel)
    }
}

/// Runs `f` on every task, on the rayon pool if `parallel`, results in task order.
fn map_tasks<I: Sync, R: Send>(
    tasks: &[I],
    parallel: bool,
    f: impl Fn(&I) -> Result<R, String> + Sync + Send,
) -> Result<Vec<R>, String> {
    if parallel {
        tasks.par_iter().map(f).collect()
    } else {
        tasks.iter().map(f).collect()
    }
}

/// Adds (link, exchange, evaluations) task results per link, in task order.
fn per_link<T: Real>(links: usize, results: &[(usize, T, u64)]) -> (Vec<T>, u64) {
    let mut sums = vec![T::ZERO; links];
    let mut evaluations = 0u64;
    for &(link, value, n) in results {
        if let Some(s) = sums.get_mut(link) {
            *s += value;
        }
        evaluations = evaluations.saturating_add(n);
    }
    (sums, evaluations)
}

/// One task per (link, emitter patch): the emitter patch against the receiver group's grid by
/// the kernel's substructuring ([`kernel::surface_exchange`]).
fn solve_cap<T, SA, SB, O, const CAP: usize>(
    problem: &Problem<'_, T, SA, SB>,
    method: kernel::Method<T>,
    area_order: usize,
    occluders: &O,
    parallel: bool,
) -> Result<Solution, String>
where
    T: Real,
    SA: Surface<T> + Sync + ?Sized,
    SB: Surface<T> + Sync + ?Sized,
    O: Occluder<T> + Sync + ?Sized,
{
    let links = problem.links.len();
    let mut tasks = Vec::new();
    for (link, &(ga, gb)) in problem.links.iter().enumerate() {
        let (Some(pa), Some(grid_b)) = (problem.a_groups.get(ga), problem.b_groups.get(gb)) else {
            return Err(format!("link {link}: no group {ga} or {gb}"));
        };
        tasks.extend(pa.iter().map(|p| (link, p, grid_b)));
    }
    let what = match method {
        kernel::Method::Paper(_) => "paper-mode sum",
        kernel::Method::Tolerance(_) => "adaptive_exchange",
        _ => "pair_exchange",
    };
    let results = map_tasks(&tasks, parallel, |&(link, pa, grid_b)| {
        let grid_a = pa.grid(1, 1).map_err(kernel_err("emitter patch"))?;
        let e = kernel::surface_exchange::<T, SA, SB, O, CAP>(grid_a, grid_b.clone(), method, occluders)
            .map_err(kernel_err(what))?;
        Ok((link, e.value, e.evaluations))
    })?;
    let (exchanges, evaluations) = per_link(links, &results);
    let mut areas = Vec::with_capacity(problem.a_groups.len());
    for g in &problem.a_groups {
        let mut a = T::ZERO;
        for p in g {
            a += p.area(area_order).map_err(kernel_err("patch area"))?;
        }
        areas.push(a);
    }
    let mut values = Vec::with_capacity(links);
    for (&(ga, _), e) in problem.links.iter().zip(&exchanges) {
        let area = areas.get(ga).copied().unwrap_or(T::ZERO);
        let f = (*e / area).to_f64();
        if !f.is_finite() {
            return Err("non-finite form factor".into());
        }
        values.push(f);
    }
    Ok(Solution { values, evaluations })
}
