//! Substructuring, eqs. (25)–(26), for every method: the exchange between two subdivided
//! surfaces is the sum of their patch pairs' exchanges,
//!
//! A_A·F_{A→B} = Σ_{pa ∈ A} Σ_{pb ∈ B} A_pa·F_{pa→pb},
//!
//! each pair integrated by the [`Method`] asked for, its error estimates (where the method has
//! them) and its work added up into one [`Estimate`]. Nothing is allocated: the grids are
//! iterated, not collected. [`with_capacity`] picks the sample capacity a method needs at run
//! time, so a host needs no table over `CAP`.

use crate::adaptive::{adaptive_exchange, Adaptive};
use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::form_factor::{exchange, resolved_exchange, Quadrature};
use crate::gauss::{GaussRule, MAX_ORDER};
use crate::pair::{pair_exchange, PairSettings};
use crate::patch::{Patch, PatchGrid};
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::surface::Surface;
use crate::visibility::Occluder;

/// How each patch pair of a substructured sum is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Method<T> {
    /// The paper's method: the PDM sum of eq. (16) at these orders on every pair, touching and
    /// identical pairs included (the Gauss nodes are interior, so touching patches never share
    /// a node; on the same patch twice at equal orders the coinciding nodes fail the facing
    /// test and drop out). Such pairs converge only algebraically. What
    /// [`crate::form_factor()`] computes, pair by pair.
    Paper(Quadrature),
    /// The PDM sum where it resolves the pair, [`crate::pair_exchange`] at the same order
    /// where it does not (touching, identical and too close pairs): what
    /// [`crate::form_factor_between`] computes, pair by pair.
    Plain(Quadrature),
    /// [`crate::pair_exchange`] on every pair: the method each pair needs, at fixed orders.
    Pair(PairSettings),
    /// [`crate::adaptive_exchange`] on every pair, each to the relative tolerance and an equal
    /// share of the absolute budget (the budget is the surface pair's); the estimates add up,
    /// and the total is `converged` if every pair met its tolerance or the summed estimate
    /// meets the tolerance and budget against the summed value.
    Tolerance(Adaptive<T>),
}

impl<T: Real> Method<T> {
    /// The sample capacity (`CAP`) the method needs: the largest order it samples a patch at,
    /// squared (the tolerance mode's `max_order`).
    #[must_use]
    pub fn capacity(&self) -> usize {
        let order = match self {
            Self::Paper(q) => q.order_a.max(q.order_b),
            // The unresolved pairs go to `pair_exchange` at this order, at least 2.
            Self::Plain(q) => q.order_a.max(q.order_b).max(2),
            Self::Pair(s) => s.order.max(2),
            Self::Tolerance(s) => s.max_order,
        };
        order.saturating_mul(order)
    }
}

/// A_A·F_{A→B} between the patches of grid `a` and grid `b` by eqs. (25)–(26), each pair by
/// `method`, with `occluders`: the value, the sum of the pairs' error estimates (tolerance mode
/// only), whether the tolerance was met, and the evaluations spent. Divide by A_A
/// ([`PatchGrid::area`], equal to the samples' area up to rounding) for F_{A→B}. The pairs are
/// added in the grids' order (rows of `a` outer), so the value is the sum of the single-pair
/// entry points' values in that order, bit for bit.
///
/// Each pair's value is checked by its method (0 ≤ A_pa·F_{pa→pb} ≤ min(A_pa, A_pb)), and the
/// total against 0 ≤ A_A·F_{A→B} ≤ min(A_A, A_B) with both areas summed over the grids at the
/// method's order (`Err(InvalidResult)` beyond the total's error estimate, or beyond 1e-4 of it
/// for the fixed-order methods). `CAP` ≥ [`Method::capacity`] (or use [`with_capacity`]).
///
/// ```
/// use pdm_kernel::{surface_exchange, vec3, Method, PairSettings, Parallelogram, PatchGrid, Sphere};
/// // The paper's scene: a unit sphere centred in a cube of side 6; sphere → floor is 1/6 by
/// // symmetry. The sphere cut 4 × 8, the floor 2 × 2, each pair by `pair_exchange` at order 8.
/// let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0)?;
/// let floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0))?;
/// let (a, b) = (PatchGrid::new(&sphere, 4, 8)?, PatchGrid::new(&floor, 2, 2)?);
/// let method = Method::Pair(PairSettings { order: 8, singular_order: 8, boundaries: true });
/// let e = surface_exchange::<f64, _, _, _, 64>(a.clone(), b, method, &())?;
/// assert!((e.value / a.area(8)? - 1.0 / 6.0).abs() < 1e-6);
/// assert_eq!(e.error, None); // fixed orders: no estimate (`Method::Tolerance` gives one)
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn surface_exchange<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
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
    if let Method::Tolerance(s) = method {
        s.validate()?;
    }
    let needed = method.capacity();
    if needed > CAP {
        return Err(PdmError::CapacityExceeded { needed, capacity: CAP });
    }
    // The areas of the total's bounds check: from the samples where the method keeps them (the
    // paper's sum), else by eq. (12) at the method's order.
    let (total, area_a, area_b) = match method {
        Method::Paper(q) => paper_rows::<T, SA, SB, O, CAP>(a, b, q, occluders)?,
        Method::Plain(q) => {
            let (rule_a, rule_b) = (GaussRule::<T>::new(q.order_a)?, GaussRule::<T>::new(q.order_b)?);
            let (total, area_a) = plain_total::<T, SA, SB, O, CAP>(a, b.clone(), &rule_a, &rule_b, occluders)?;
            (total, area_a, b.area(q.order_b)?)
        }
        Method::Pair(s) => {
            let pair = |pa: &Patch<'_, T, SA>, pb: &Patch<'_, T, SB>| {
                pair_exchange::<T, SA, SB, O, CAP>(pa, pb, s, occluders).map(|e| (e, T::ZERO))
            };
            let order = s.order.max(2);
            (sum_pairs(a.clone(), b.clone(), pair)?.0, a.area(order)?, b.area(order)?)
        }
        Method::Tolerance(s) => {
            // The absolute budget is the whole surface pair's: each patch pair gets its share.
            let s = s.share(PatchGrid::count(&a).saturating_mul(PatchGrid::count(&b)));
            let pair = |pa: &Patch<'_, T, SA>, pb: &Patch<'_, T, SB>| {
                adaptive_exchange::<T, SA, SB, O, CAP>(pa, pb, s, occluders).map(|e| (e, T::ZERO))
            };
            (sum_pairs(a.clone(), b.clone(), pair)?.0, a.area(s.max_order)?, b.area(s.max_order)?)
        }
    };
    let band = total.error.unwrap_or_else(|| total.value.abs() * T::from_f64(FIXED_BAND));
    let value = crate::bounds::exchange_within(total.value, band, area_a, area_b)?;
    let mut converged = total.converged;
    // A pair of tiny value may miss the tolerance against itself while the total meets it: the
    // summed estimates bound the total's error (judged against the value returned).
    if let (Method::Tolerance(s), Some(error)) = (method, total.error) {
        converged |= s.met(value, error);
    }
    Ok(Estimate { value, converged, ..total })
}

/// Relative overshoot of the physical bounds that a fixed-order total may have as quadrature
/// error (as on a single pair, `pair/`).
const FIXED_BAND: f64 = 1e-4;

/// Σ over every pair of `a` × `b` (rows of `a` outer, `b` inner, added in that order) of
/// `pair`'s estimates, and Σ over the rows of the area of `a`'s patch that `pair` reports with
/// the row's first pair (zero where the method does not sample a; see
/// [`crate::surface_form_factor`]).
pub(crate) fn sum_pairs<'s, T, SA, SB>(
    a: PatchGrid<'s, T, SA>,
    b: PatchGrid<'s, T, SB>,
    mut pair: impl FnMut(&Patch<'s, T, SA>, &Patch<'s, T, SB>) -> Result<(Estimate<T>, T), PdmError>,
) -> Result<(Estimate<T>, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    // No pair (a grid already iterated to its end): no value, no estimate.
    let mut total = Estimate::fixed(T::ZERO, 0);
    let mut area_a = T::ZERO;
    let mut first = true;
    for pa in a {
        let mut row_area = None;
        for pb in b.clone() {
            let (e, area) = pair(&pa, &pb)?;
            total = if first { e } else { total.plus(e) };
            first = false;
            row_area.get_or_insert(area);
        }
        area_a += row_area.unwrap_or(T::ZERO);
    }
    Ok((total, area_a))
}

/// [`Method::Plain`] over the grids: each pair by [`crate::form_factor_between`]'s rule, and A_A
/// as the sum of `a`'s patch areas from their samples (the same rule's weights).
pub(crate) fn plain_total<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    rule_a: &GaussRule<T>,
    rule_b: &GaussRule<T>,
    occluders: &O,
) -> Result<(Estimate<T>, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    sum_pairs(a, b, |pa, pb| resolved_exchange::<T, SA, SB, O, CAP>(pa, pb, rule_a, rule_b, occluders))
}

/// [`Method::Paper`]: each patch of `a` sampled once, each of `b` once per row; two sample
/// buffers, in this frame only. With A_A and A_B from the samples' weights (eq. 12).
#[inline(never)]
fn paper_rows<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    q: Quadrature,
    occluders: &O,
) -> Result<(Estimate<T>, T, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (rule_a, rule_b) = (GaussRule::<T>::new(q.order_a)?, GaussRule::<T>::new(q.order_b)?);
    let mut sa = PatchSamples::<T, CAP>::empty();
    let mut sb = PatchSamples::<T, CAP>::empty();
    let (mut value, mut evaluations) = (T::ZERO, 0u64);
    let (mut area_a, mut area_b, mut first_row) = (T::ZERO, T::ZERO, true);
    for pa in a {
        sa.fill_with_rules(&pa, &rule_a, &rule_a)?;
        area_a += sa.area();
        for pb in b.clone() {
            sb.fill_with_rules(&pb, &rule_b, &rule_b)?;
            if first_row {
                area_b += sb.area();
            }
            value += exchange(&sa, &sb, occluders)?;
            evaluations = evaluations.saturating_add((sa.len() as u64).saturating_mul(sb.len() as u64));
        }
        first_row = false;
    }
    Ok((Estimate::fixed(value, evaluations), area_a, area_b))
}

/// A computation generic over the sample capacity, run by [`with_capacity`] with one chosen at
/// run time.
pub trait WithCapacity {
    /// What the computation returns.
    type Output;
    /// Runs the computation with sample buffers of capacity `CAP`.
    fn run<const CAP: usize>(self) -> Self::Output;
}

/// The capacities [`with_capacity`] chooses from: orders 5, 8, 12, 16, 24 and [`MAX_ORDER`],
/// squared.
pub const CAPACITIES: [usize; 6] = [25, 64, 144, 256, 576, MAX_ORDER * MAX_ORDER];

/// Runs `job` with the smallest capacity of [`CAPACITIES`] that holds `needed` samples per
/// patch ([`Method::capacity`]); `Err(CapacityExceeded)` above the largest. Each capacity is a
/// separate instance of the job's code: a host that calls this compiles six.
///
/// ```
/// use pdm_kernel::{surface_exchange, vec3, Estimate, Method, PairSettings, Parallelogram, PatchGrid, PdmError, WithCapacity, with_capacity};
/// struct Job<'s> { a: PatchGrid<'s, f64, Parallelogram<f64>>, b: PatchGrid<'s, f64, Parallelogram<f64>>, method: Method<f64> }
/// impl WithCapacity for Job<'_> {
///     type Output = Result<Estimate<f64>, PdmError>;
///     fn run<const CAP: usize>(self) -> Self::Output {
///         surface_exchange::<f64, _, _, _, CAP>(self.a, self.b, self.method, &())
///     }
/// }
/// // Perpendicular unit squares sharing an edge (C-14: 0.2000437760754...), cut 2 × 2 each.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0))?;
/// let method = Method::Pair(PairSettings { order: 10, singular_order: 10, boundaries: true });
/// let job = Job { a: PatchGrid::new(&floor, 2, 2)?, b: PatchGrid::new(&wall, 2, 2)?, method };
/// let e = with_capacity(method.capacity(), job)??; // capacity 144
/// assert!((e.value - 0.20004377607540316).abs() < 1e-10);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn with_capacity<J: WithCapacity>(needed: usize, job: J) -> Result<J::Output, PdmError> {
    const LARGEST: usize = MAX_ORDER * MAX_ORDER;
    // One arm per entry of CAPACITIES (a const generic needs a literal).
    Ok(match capacity_for(needed) {
        Some(25) => job.run::<25>(),
        Some(64) => job.run::<64>(),
        Some(144) => job.run::<144>(),
        Some(256) => job.run::<256>(),
        Some(576) => job.run::<576>(),
        Some(LARGEST) => job.run::<LARGEST>(),
        _ => return Err(PdmError::CapacityExceeded { needed, capacity: LARGEST }),
    })
}

/// The smallest of [`CAPACITIES`] that holds `needed` samples, `None` above the largest: the
/// capacity [`with_capacity`] runs a job with.
#[must_use]
pub fn capacity_for(needed: usize) -> Option<usize> {
    CAPACITIES.into_iter().find(|&c| c >= needed)
}

/// F_{A→B} between the patches of grid `a` and grid `b` by substructuring
/// ([`crate::surface_exchange`] with [`crate::Method::Plain`]): each patch pair as by
/// [`crate::form_factor_between`] (the PDM sum, or [`crate::pair_exchange`] on the pairs the sum cannot
/// resolve: adjacent and identical patches, patches closer than [`crate::form_factor::RESOLVED_DISTANCE`]
/// spacings), divided by A_A, the sum of the patch areas by eq. (12) with the same rule's
/// weights (so that a surface's factors to a closed enclosure sum to 1 up to the quadrature
/// error). Every patch is re-sampled for each pair; nothing is allocated.
///
/// ```
/// use pdm_kernel::{surface_form_factor, vec3, Parallelogram, PatchGrid, Quadrature};
/// // Perpendicular unit squares sharing an edge (C-14: 0.2000437760754...), each cut 2 × 2:
/// // the pairs along the shared edge go to the shared-edge transform, the others to the sum.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (PatchGrid::new(&floor, 2, 2)?, PatchGrid::new(&wall, 2, 2)?);
/// let f = surface_form_factor::<f64, _, _, _, 256>(a, b, Quadrature::uniform(12), &())?;
/// assert!((f - 0.20004377607540316).abs() < 1e-9);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn surface_form_factor<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    quadrature: Quadrature,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule_a = GaussRule::<T>::new(quadrature.order_a)?;
    let rule_b = GaussRule::<T>::new(quadrature.order_b)?;
    let (total, area) = plain_total::<T, SA, SB, O, CAP>(a, b, &rule_a, &rule_b, occluders)?;
    crate::bounds::form_factor(total.value / area)
}
