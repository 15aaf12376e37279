//! The computations a sweep point times: form factors between groups of patches by one of three
//! kernel methods, with the number of kernel evaluations each took.
//!
//! A [`Problem`] is a list of emitter groups, a list of receiver groups and the links
//! (emitter group → receiver group) whose factors are wanted, F = Σ_{a ∈ A} Σ_{b ∈ B}
//! A_a F_{a→b} / Σ_{a ∈ A} A_a (eqs. 25–26). Methods ([`Method`]):
//!
//! * `paper` — the paper's eq. (16) on precomputed samples ([`pdm_kernel::exchange`]) at a fixed
//!   order; areas by eq. (12) with the same rule. Evaluations: order⁴ per patch pair.
//! * `pair` — [`pdm_kernel::pair_exchange`] with visibility boundaries, the singular order equal
//!   to the order; areas with the same rule. The dispatch is repeated here with the counting
//!   variants of the same kernel functions ([`pair_counted`], tested to give `pair_exchange`'s
//!   value bit for bit). Evaluations: see [`pair_counted`].
//! * `adaptive` — [`pdm_kernel::adaptive_exchange`] at a relative tolerance (max order 16, max
//!   depth 4); areas at order 20. Evaluations: the estimate's own count.
//!
//! Work is split into one task per (link, emitter patch); tasks run on the current rayon pool
//! when `parallel`, and their results are added in task order, so values do not depend on the
//! thread count.

use pdm_kernel::{
    adaptive_exchange, exchange, Adaptive, Occluder, PairSettings, Patch, PatchSamples, PdmError, Real, Surface,
    MAX_ORDER,
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
    /// Receiver groups.
    pub b_groups: Vec<Vec<Patch<'s, T, SB>>>,
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
    let need = match method {
        Method::Paper { order } | Method::Pair { order } => {
            if !(1..=MAX_ORDER).contains(&order) {
                return Err(format!("order {order} outside 1..={MAX_ORDER}"));
            }
            order * order
        }
        Method::Adaptive { .. } => (ADAPTIVE_MAX_ORDER + 2) * (ADAPTIVE_MAX_ORDER + 2),
    };
    match need {
        0..=25 => solve_cap::<T, SA, SB, O, 25>(problem, method, occluders, parallel),
        26..=64 => solve_cap::<T, SA, SB, O, 64>(problem, method, occluders, parallel),
        65..=144 => solve_cap::<T, SA, SB, O, 144>(problem, method, occluders, parallel),
        145..=256 => solve_cap::<T, SA, SB, O, 256>(problem, method, occluders, parallel),
        257..=576 => solve_cap::<T, SA, SB, O, 576>(problem, method, occluders, parallel),
        _ => solve_cap::<T, SA, SB, O, { MAX_ORDER * MAX_ORDER }>(problem, method, occluders, parallel),
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

fn solve_cap<T, SA, SB, O, const CAP: usize>(
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
    let links = problem.links.len();
    let (exchanges, areas, evaluations): (Vec<T>, Vec<T>, u64) = match method {
        Method::Paper { order } => {
            let sample = |p: &Patch<'_, T, SA>| PatchSamples::<T, CAP>::new(p, order);
            let a_samples = problem
                .a_groups
                .iter()
                .map(|g| g.iter().map(sample).collect::<Result<Vec<_>, _>>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(kernel_err("sampling an emitter patch"))?;
            let b_samples = problem
                .b_groups
                .iter()
                .map(|g| g.iter().map(|p| PatchSamples::<T, CAP>::new(p, order)).collect::<Result<Vec<_>, _>>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(kernel_err("sampling a receiver patch"))?;
            let mut tasks = Vec::new();
            for (link, &(ga, gb)) in problem.links.iter().enumerate() {
                let (Some(sa), Some(sb)) = (a_samples.get(ga), b_samples.get(gb)) else {
                    return Err(format!("link {link}: no group {ga} or {gb}"));
                };
                tasks.extend(sa.iter().map(|s| (link, s, sb.as_slice())));
            }
            let results = map_tasks(&tasks, parallel, |&(link, sa, sbs)| {
                let mut acc = T::ZERO;
                let mut n = 0u64;
                for sb in sbs {
                    acc += exchange(sa, sb, occluders).map_err(kernel_err("paper-mode sum"))?;
                    n += (sa.len() * sb.len()) as u64;
                }
                Ok((link, acc, n))
            })?;
            let (sums, evaluations) = per_link(links, &results);
            let areas = a_samples.iter().map(|g| g.iter().fold(T::ZERO, |acc, s| acc + s.area())).collect();
            (sums, areas, evaluations)
        }
        Method::Pair { .. } | Method::Adaptive { .. } => {
            let order = method.order();
            let mut tasks = Vec::new();
            for (link, &(ga, gb)) in problem.links.iter().enumerate() {
                let (Some(pa), Some(pb)) = (problem.a_groups.get(ga), problem.b_groups.get(gb)) else {
                    return Err(format!("link {link}: no group {ga} or {gb}"));
                };
                tasks.extend(pa.iter().map(|p| (link, p, pb.as_slice())));
            }
            let tolerance = T::from_f64(method.tolerance().unwrap_or(1.0));
            let settings = Adaptive { tolerance, max_order: ADAPTIVE_MAX_ORDER, max_depth: ADAPTIVE_MAX_DEPTH };
            let results = map_tasks(&tasks, parallel, |&(link, pa, pbs)| {
                let mut acc = T::ZERO;
                let mut n = 0u64;
                for pb in pbs {
                    let (v, k) = match method {
                        Method::Adaptive { .. } => {
                            let e = adaptive_exchange::<T, SA, SB, O, CAP>(pa, pb, settings, occluders)
                                .map_err(kernel_err("adaptive_exchange"))?;
                            (e.value, e.evaluations)
                        }
                        _ => pair_counted::<T, SA, SB, O, CAP>(pa, pb, order, occluders)
                            .map_err(kernel_err("pair_exchange"))?,
                    };
                    acc += v;
                    n = n.saturating_add(k);
                }
                Ok((link, acc, n))
            })?;
            let (sums, evaluations) = per_link(links, &results);
            let area_order = match method {
                Method::Adaptive { .. } => ADAPTIVE_AREA_ORDER,
                _ => order,
            };
            let mut areas = Vec::with_capacity(problem.a_groups.len());
            for g in &problem.a_groups {
                let mut a = T::ZERO;
                for p in g {
                    a += p.area(area_order).map_err(kernel_err("patch area"))?;
                }
                areas.push(a);
            }
            (sums, areas, evaluations)
        }
    };
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

/// `pdm_kernel::internals::pair_exchange_counted` with `PairSettings { order, singular_order: order,
/// boundaries: true }`: (A_a F_{a→b}, evaluations), as the kernel counts them (kernel
/// evaluations and visibility probes on the boundary path, order⁴ for the straddle check and
/// for a plain sum, 6·order⁴ for a shared edge, 4·order⁴ for a shared vertex). The test
/// `pair_counted_is_pair_exchange` checks that the value is `pair_exchange`'s bit for bit.
pub fn pair_counted<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let settings = PairSettings { order, singular_order: order, boundaries: true };
    pdm_kernel::internals::pair_exchange_counted::<T, SA, SB, O, CAP>(a, b, settings, occluders)
}
