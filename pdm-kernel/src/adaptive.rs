//! Tolerance-driven integration: spend effort only where a pair of patches needs it.
//!
//! [`adaptive_exchange`] returns A_a·F_{a→b} with an error estimate, whether that estimate met
//! the tolerance, and the number of integrand evaluations it took. Per pair it
//! 1. classifies the pair (`classify_near`): flat pairs that see each other wholly use the
//!    contour form at two orders or more (where its terms cancel beyond the working precision,
//!    the paths below take the pair if their rules resolve it, else the contour value stands
//!    with its rounding bound in the estimate);
//!    touching pairs use the regularising transforms, raising the order by 2 from 4; the same
//!    patch twice uses the identical-panel transform (see below);
//! 2. for separate pairs, starts from an order chosen from the geometry — the Gauss error on an
//!    integrand whose nearest singularity lies at distance d from patches of size h falls like
//!    ρ^(−2p) with ρ ≈ 1 + 2d/h, so p₀ = ⌈ln(1/tol) / (2 ln ρ)⌉ (clamped to 2…12);
//! 3. skips the occlusion tests when no occluder can cut a segment between the two patches'
//!    bounding balls (`Occluder::may_block_between`), and takes the boundary path
//!    (`boundary.rs`: visibility boundaries placed into the inner rule, the
//!    inner patch refined towards close outer points) when the pair straddles a boundary
//!    (some sample pairs visible, some not, or an occluder that may cut) or the patches are
//!    closer than their size; the outer patch is chosen as by `pair_exchange`: without
//!    occluders the patch whose points stay farther from the other's edges
//!    (`pair::outer_is_b`), across occluders the smaller one (`pair::occluded_outer_is_b`);
//! 4. compares orders p, p + 2, …; when the estimate is still above the tolerance at
//!    `max_order`, splits the pair and recurses — a separate pair's larger patch in two across
//!    its longer side, a touching pair's both patches 2 × 2 (so that the cells along the
//!    contact share whole edges and corners again) — to depth ≤ `max_depth` (no
//!    allocation). Sides are
//!    measured by arc length (a 12-segment polyline along each edge and the mid-line of the
//!    parameter rectangle), so a side that closes on itself — the θ side of a whole disk or
//!    cylinder, whose corner chord is zero — is halved like any other.
//!
//! # The error estimate and `converged`
//! Each leaf pair's estimate is a difference between independent approximations, times a
//! safety factor where the convergence is only algebraic, plus a rounding allowance of
//! 128 ε·|value| (2.8e-14 relative in f64, 1.5e-5 in f32); the total is the sum over the
//! leaves. [`Estimate::converged`] is `true` if every leaf met the tolerance (estimate ≤
//! tolerance·|value|, or value and estimate both zero) or the total estimate meets it against
//! the total value; at the depth limit, or where a split would go below the resolution of the
//! coordinates (f32 cells far from the origin), the best value is returned with its estimate
//! and `converged = false` — never silently above the tolerance, and never an error after
//! the work. A tolerance below 256 ε (5.7e-14
//! in f64, 3.1e-5 in f32) is below what any estimate can show: the refinement works to 256 ε
//! instead (it would otherwise split every pair to the depth limit, for minutes, without
//! getting closer) and the result says `converged = false` unless its estimate meets the
//! tolerance asked for. A caller who needs the tolerance checks the flag (or compares `error` with
//! its own budget).
//!
//! * Smooth separate pairs and touching pairs (exponential convergence in the order): with
//!   d₂ the difference between the last two orders and d₁ the one before, max(d₂, √(d₁·d₂))
//!   (d₂ alone on a separate pair's first comparison, whose start order the geometry chose);
//!   touching pairs compare at least three orders. The geometric mean covers convergence that
//!   stalls for a step (checked against closed forms and the contour integral in the tests).
//! * Flat pairs by the contour form: the difference between orders 8 and 16 (then 24, 32
//!   until it meets the tolerance: the contour's 1-D rules are not bound by `max_order`) plus
//!   the bound on the rounding of the cancelling terms.
//! * Pairs across visibility boundaries: the outer integrand keeps kinks (a shadow edge meeting
//!   an inner edge), so successive orders — and a patch and its halves — can agree by
//!   accident. Four approximations are computed: the outer patch whole and split 2 × 2, each
//!   at orders p and p + 1 (both levels refined: the inner rule's order is the outer one's);
//!   the split at p + 1 is returned, and the estimate is 2 × the largest difference between
//!   the split at p + 1 and the other three and between the split at p and the two wholes.
//!   On 432 (geometry, order) cases with a cylinder occluder (parallel squares, walls inside
//!   a coaxial tube; references in closed form up to a 1-D integral) the largest |actual
//!   error| / difference is 1.01 outside the rounding level, hence the factor 2.
//! * The same patch twice (`Adjacency::Identical`) by the identical-panel transform
//!   (`singular.rs`): without an occluder that may cut the patch's view of itself, as a
//!   touching pair (orders 4, 6, …, both copies split 2 × 2 at `max_order`; a quarter of a
//!   tube's inside meets 1e-10 with 2.2e5 evaluations). With one, the shadow makes the
//!   integrand jump, and on a saddle the facing test puts kinks in it; the convergence is then
//!   algebraic: the value at p = `max_order` with 2 × the
//!   largest difference from orders p − 1, p − 2, p − 3 and p/2, not split (splitting a self
//!   pair that an occluder cuts multiplies the touching sub-pairs at every level); above the
//!   tolerance it says so with `converged = false` (three quarters of a tube's inside around
//!   a coaxial tube: 2.3e-6 actual against an estimate of 4.8e-4).
//!
//! * Self and edge pairs whose contact reaches a side collapsed to a point (a cone's apex)
//!   converge only algebraically (`singular.rs`): the same five-order estimate as an
//!   occluded self pair, not split (the cells at the apex stay algebraic at every level).
//!
//! # Settings
//! `tolerance` must be positive and finite, `max_order` in 8..=[`MAX_ORDER`](crate::MAX_ORDER)
//! and `max_depth` ≤ [`MAX_DEPTH`]; anything else is `Err(InvalidSetting)`, checked before any
//! work. The sample buffers hold at most `max_order`² points, so `CAP` ≥ `max_order`²
//! (`Err(CapacityExceeded)` otherwise, also checked first).

use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::form_factor::exchange_unchecked;
use crate::integrand::mutually_facing;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_evaluations, touching_unchecked, Adjacency};
use crate::surface::{ParamRect, Surface};
use crate::visibility::Occluder;

/// Largest accepted `max_depth`: at most 2^24 halvings deep. The recursion keeps no sample
/// buffer on the stack: they live in non-inlined frames that return before it recurses.
pub const MAX_DEPTH: u32 = 24;

/// Smallest accepted `max_order` (touching pairs compare orders 4, 6 and 8).
const MIN_ORDER: usize = 8;

/// Factor on the differences that estimate algebraically converging pairs (module docs).
const SAFETY: f64 = 2.0;

/// Rounding allowance on each leaf, in units of ε·|value|.
const ROUNDING: f64 = 128.0;

/// The smallest relative tolerance the refinement works to, in units of ε (twice the rounding
/// allowance, so that a leaf can meet it): 5.7e-14 in f64, 3.1e-5 in f32.
const PRECISION_FLOOR: f64 = 2.0 * ROUNDING;

/// Settings of the tolerance-driven mode (validated by [`adaptive_exchange`]; see the module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Adaptive<T> {
    /// Relative tolerance on each pair's exchange A_a·F_{a→b}: positive and finite. Below
    /// 256 ε (5.7e-14 in f64, 3.1e-5 in f32) the refinement works to 256 ε instead (the
    /// rounding allowance of every estimate, 128 ε, leaves nothing finer to reach), and the
    /// result has `converged = false` unless its estimate happens to meet the tolerance.
    pub tolerance: T,
    /// Largest Gauss order before a pair is subdivided instead: 8..=`MAX_ORDER` (32). `CAP` must
    /// be ≥ `max_order`².
    pub max_order: usize,
    /// Largest number of successive subdivisions of a pair: ≤ [`MAX_DEPTH`].
    pub max_depth: u32,
}

impl<T: Real> Adaptive<T> {
    /// `tolerance` with max order 12 and max depth 6 (`CAP` ≥ 144).
    #[must_use]
    pub fn new(tolerance: T) -> Self {
        Self { tolerance, max_order: 12, max_depth: 6 }
    }

    /// `Ok` if every setting is in range (module docs), `Err(InvalidSetting)` naming the first
    /// that is not.
    pub fn validate(&self) -> Result<(), PdmError> {
        if !(self.tolerance > T::ZERO && self.tolerance.is_finite()) {
            return Err(PdmError::InvalidSetting { name: "tolerance", expected: "positive and finite" });
        }
        if !(MIN_ORDER..=crate::gauss::MAX_ORDER).contains(&self.max_order) {
            return Err(PdmError::InvalidSetting { name: "max_order", expected: "in 8..=32 (MAX_ORDER)" });
        }
        if self.max_depth > MAX_DEPTH {
            return Err(PdmError::InvalidSetting { name: "max_depth", expected: "at most 24 (adaptive::MAX_DEPTH)" });
        }
        Ok(())
    }
}

/// A partial result inside the tolerance mode: a value, its error estimate (always present),
/// whether it met the tolerance, and its cost. [`adaptive_exchange`] returns it as an
/// [`Tally`] with `error: Some(_)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tally<T> {
    value: T,
    error: T,
    converged: bool,
    evaluations: u64,
}

impl<T: Real> Tally<T> {
    /// A leaf's estimate: `difference` (already scaled) plus the rounding allowance; converged
    /// if within `tol`.
    fn leaf(value: T, difference: T, tol: T, evaluations: u64) -> Self {
        let error = difference.abs() + T::from_f64(ROUNDING) * T::EPSILON * value.abs();
        let converged = error <= tol * value.abs() || error <= T::MIN_POSITIVE;
        Self { value, error, converged, evaluations }
    }

    fn zero(evaluations: u64) -> Self {
        Self { value: T::ZERO, error: T::ZERO, converged: true, evaluations }
    }

    fn add(&mut self, other: Self) {
        self.value += other.value;
        self.error += other.error;
        self.converged &= other.converged;
        self.evaluations = self.evaluations.saturating_add(other.evaluations);
    }
}

/// A_a·F_{a→b} to relative tolerance `settings.tolerance`, with an error estimate and a
/// `converged` flag (see the module docs: check [`Estimate::converged`] — at the depth limit
/// the value is returned with `converged = false`). `CAP` ≥ `max_order`²; invalid settings are
/// `Err(InvalidSetting)`, a smaller `CAP` `Err(CapacityExceeded)`, both before any work. The
/// value is checked against 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b) (`Err(InvalidResult)` otherwise).
///
/// ```
/// use pdm_kernel::{adaptive_exchange, vec3, Adaptive, Parallelogram, Patch};
/// // Unit squares 1 apart (C-11: 0.1998248956983874) to a relative tolerance of 1e-8.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let ceiling = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (Patch::whole(&floor)?, Patch::whole(&ceiling)?);
/// let e = adaptive_exchange::<f64, _, _, _, 144>(&a, &b, Adaptive::new(1e-8), &())?;
/// assert!(e.converged, "check it: false means the tolerance was not met");
/// let error = e.error.expect("the tolerance mode always estimates its error");
/// assert!(error <= 1e-8 * e.value);
/// assert!((e.value - 0.1998248956983874).abs() <= error); // A_a = 1
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn adaptive_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Estimate<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    settings.validate()?;
    let needed = settings.max_order * settings.max_order;
    if needed > CAP {
        return Err(PdmError::CapacityExceeded { needed, capacity: CAP });
    }
    // Every leaf's estimate carries the rounding allowance ROUNDING·ε·|value|, so a leaf can
    // meet only a tolerance above it: below, the refinement would split every pair down to
    // `max_depth` without ever getting closer. It works to the precision floor instead, and
    // the result then says whether the tolerance asked for was met (it cannot be).
    let floor = T::from_f64(PRECISION_FLOOR) * T::EPSILON;
    let work = Adaptive { tolerance: settings.tolerance.max(floor), ..settings };
    // Closed patches are cut at their seams first, as in `pair_exchange`.
    let mut e = Tally::zero(0);
    crate::pair::for_each_piece_pair(a, b, |pa, pb| {
        e.add(recurse::<T, SA, SB, O, CAP>(pa, pb, work, occluders, 0)?);
        Ok(())
    })?;
    let (area_a, area_b) = (a.area(settings.max_order)?, b.area(settings.max_order)?);
    // The leaves are unchecked approximations: the total may overshoot [0, min(A_a, A_b)] by
    // its error, and is clamped there; beyond its error it is refused.
    e.value = crate::bounds::exchange_within(e.value, e.error, area_a, area_b)?;
    // The leaves judge their own estimates against their own values; a leaf of a tiny value
    // may miss that while the total meets the tolerance asked for (the pieces of a whole disk
    // far from the other's rim): the sum of the estimates bounds the total's error.
    e.converged |= e.error <= work.tolerance * e.value.abs();
    e.converged &= work.tolerance == settings.tolerance || e.error <= settings.tolerance * e.value.abs();
    Ok(Estimate { value: e.value, error: Some(e.error), converged: e.converged, evaluations: e.evaluations })
}

fn recurse<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (adjacency, gap) = classify_near(a, b);
    // Two flat patches that see each other wholly: the contour form at two orders.
    #[cfg(feature = "closed-form")]
    if crate::pair::contour_applies(adjacency) {
        let lo_order = 8usize.min(settings.max_order);
        // Where the contour terms cancel beyond the working precision (f32 cells close
        // together) or the gap is below the geometry's resolution (`Unresolvable`), the 4-D
        // path below takes the pair instead if its Gauss rules resolve the pair at
        // `max_order`; otherwise (long strips close together, whose ends no node comes near)
        // two approximations can agree on a wrong value: the contour value stands with its
        // rounding bound in the estimate, and the refusal of an unresolvable gap stands.
        match contour_leaf(a, b, lo_order, settings, occluders) {
            Some(Err(PdmError::Unresolvable))
                if adjacency != Adjacency::Separate
                    || crate::pair::resolved::<T, SA, SB, CAP>(a, b, settings.max_order)? => {}
            Some(Ok((_, true)))
                if adjacency != Adjacency::Separate
                    || crate::pair::resolved::<T, SA, SB, CAP>(a, b, settings.max_order)? => {}
            None => {}
            Some(result) => return result.map(|(estimate, _)| estimate),
        }
    }
    if crate::singular::contact_reaches_collapsed_side(a, b, adjacency) {
        return collapsed_contact::<T, SA, SB, O>(a, b, adjacency, gap, settings, occluders);
    }
    match adjacency {
        Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. } => {
            // The transforms test occlusion only at their sample points: with an occluder that
            // may cut the pair, successive orders can agree on a wrong value. Split both patches 2 × 2 until no occluder can cut a touching sub-pair;
            // the separate sub-pairs take the boundary-aware path.
            if depth < settings.max_depth && occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball()) {
                return split_both::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, 0);
            }
            let eval = |p: usize| {
                Ok((touching_unchecked(a, b, adjacency, gap, p, occluders)?, touching_evaluations(adjacency, p)))
            };
            by_order_doubling::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, eval, 4, Split::Both)
        }
        Adjacency::Identical => identical::<T, SA, O, CAP>(a, settings, occluders, depth),
        Adjacency::Separate => separate::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth),
    }
}

/// The contour form ([`crate::pair::flat_pair`]) at orders `lo_order`, 2·`lo_order`, then up
/// by 8 to [`MAX_ORDER`](crate::MAX_ORDER) until the difference between the last two plus the
/// rounding bound, the estimate, meets the tolerance. Its rules are 1-D (cost ∝ p², no sample
/// buffers), so `max_order`, which bounds the 4-D rules, does not limit them. With the
/// estimate, whether the value has lost more than half its digits to cancellation
/// ([`crate::bounds::lost_digits`]). `None` if the pair is not a flat pair that sees itself
/// wholly.
#[cfg(feature = "closed-form")]
fn contour_leaf<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    lo_order: usize,
    settings: Adaptive<T>,
    occluders: &O,
) -> Option<Result<(Tally<T>, bool), PdmError>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (mut lo, mut evaluations, _) = match crate::pair::flat_pair(a, b, lo_order, occluders)? {
        Ok(x) => x,
        Err(e) => return Some(Err(e)),
    };
    let mut order = 2 * lo_order;
    loop {
        let (hi, n, rounding) = match crate::pair::flat_pair(a, b, order, occluders)? {
            Ok(x) => x,
            Err(e) => return Some(Err(e)),
        };
        evaluations = evaluations.saturating_add(n);
        let estimate = Tally::leaf(hi, (hi - lo).abs() + rounding, settings.tolerance, evaluations);
        if estimate.converged || order >= crate::gauss::MAX_ORDER {
            return Some(Ok((estimate, crate::bounds::lost_digits(hi, rounding))));
        }
        lo = hi;
        order = (order + 8).min(crate::gauss::MAX_ORDER);
    }
}

/// The same patch twice by the identical-panel transform
/// (`singular::identical_unchecked`). Without an occluder that may cut the patch's
/// view of itself the kernel is smooth in the transformed variables: orders 4, 6, … as for a
/// touching pair, splitting both copies 2 × 2 at `max_order`. With one, the shadow makes the
/// integrand jump, and on a patch that faces itself in some directions and away in others (a
/// saddle: `singular::faces_itself_mixed`) the facing test puts kinks in it: the convergence is
/// algebraic, so the value at p = `max_order` is estimated as 2 × the largest difference from
/// orders p − 1, p − 2, p − 3 and p/2 (module docs), not split.
#[inline(never)]
fn identical<T, S, O, const CAP: usize>(
    a: &Patch<'_, T, S>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let ball = a.enclosing_ball();
    if !occluders.may_block_between(&ball, &ball) && !crate::singular::faces_itself_mixed(a) {
        let eval = |p: usize| crate::singular::identical_unchecked(a, p, occluders);
        return by_order_doubling::<T, S, S, O, CAP>(a, a, settings, occluders, depth, eval, 4, Split::Both);
    }
    algebraic_leaf(|p| crate::singular::identical_unchecked(a, p, occluders), settings)
}

/// A self or edge pair whose contact reaches a side collapsed to a point (a cone's apex:
/// `singular::contact_reaches_collapsed_side`). The transforms converge only algebraically
/// there, so the
/// leaf is estimated like an occluded self pair: the value at p = `max_order`, 2 × the largest
/// difference from orders p − 1, p − 2, p − 3 and p/2 (a rate p^−a is bounded for a ≥ 0.6).
/// Not split: the cells at the collapsed point stay algebraic at every level.
#[inline(never)]
fn collapsed_contact<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    adjacency: Adjacency,
    gap: T,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let eval = |p: usize| -> Result<(T, u64), PdmError> {
        match adjacency {
            Adjacency::Identical => crate::singular::identical_unchecked(a, p, occluders),
            _ => Ok((touching_unchecked(a, b, adjacency, gap, p, occluders)?, touching_evaluations(adjacency, p))),
        }
    };
    algebraic_leaf(eval, settings)
}

/// The value at p = `max_order` and 2 × the largest difference from orders p − 1, p − 2,
/// p − 3 and p/2: the estimate of a leaf that converges only algebraically in the order.
fn algebraic_leaf<T: Real>(
    eval: impl Fn(usize) -> Result<(T, u64), PdmError>,
    settings: Adaptive<T>,
) -> Result<Tally<T>, PdmError> {
    let p = settings.max_order;
    let (hi, mut evaluations) = eval(p)?;
    let mut difference = T::ZERO;
    for q in [p - 1, p - 2, p - 3, p / 2] {
        let (v, n) = eval(q)?;
        difference = difference.max((hi - v).abs());
        evaluations = evaluations.saturating_add(n);
    }
    Ok(Tally::leaf(hi, T::from_f64(SAFETY) * difference, settings.tolerance, evaluations))
}

/// The starting order of a separate pair from its geometry (module docs, item 2), capped at
/// `max_order`, whether the pair straddles a visibility boundary at that order (or is closer
/// than its size), and whether b should be the outer patch of the boundary path (unoccluded
/// pairs, `pair::outer_is_b`; across occluders, `pair::occluded_outer_is_b`).
#[inline(never)]
fn separate_plan<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<(usize, bool, bool), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let probe = PatchSamples::<T, CAP>::new(a, 2)?;
    let probe_b = PatchSamples::<T, CAP>::new(b, 2)?;
    let (ba, bb) = (probe.bounds(), probe_b.bounds());
    let size = (ba.radius + bb.radius).max(T::MIN_POSITIVE);
    let dist = ((ba.center - bb.center).norm() - ba.radius - bb.radius).max(T::ZERO);
    let rho = T::ONE + T::TWO * dist / size;
    let digits = (T::ONE / settings.tolerance).ln();
    // Smallest p in 2..=12 with ρ^(2p) ≥ 1/tol, i.e. 2p·ln ρ ≥ ln(1/tol).
    let ln_rho = rho.ln();
    let mut p: usize = 2;
    while p < 12 && !(T::from_usize(2 * p) * ln_rho >= digits) {
        p += 1;
    }
    let p = p.min(settings.max_order);
    let sa = PatchSamples::<T, CAP>::new(a, p)?;
    let sb = PatchSamples::<T, CAP>::new(b, p)?;
    let (ball_a, ball_b) = (a.enclosing_ball(), b.enclosing_ball());
    // Patches closer than their size: the plain rule's nodes do not resolve the kernel's peak,
    // and two orders can agree by accident (a separate pair folded to 33° with the gap a
    // quarter of its size: orders 10 and 12 agreed to 9e-7 with the value 4.4e-6 off). The
    // boundary path refines the inner patch towards each close outer point, and its estimate
    // compares the outer patch whole and split.
    let occluded = occluders.may_block_between(&ball_a, &ball_b);
    let across = occluded || crate::pair::near(&ball_a, &ball_b) || straddles_curvature_cut(&sa, &sb);
    let swap = across
        && if occluded { crate::pair::occluded_outer_is_b(a, b) } else { crate::pair::outer_is_b(a, b, &sa, &sb) };
    Ok((p, across, swap))
}

/// The plain PDM sum at `order` on both patches and its evaluations.
#[inline(never)]
fn plain<T, SA, SB, O, const CAP: usize>(
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
    let sa = PatchSamples::<T, CAP>::new(a, order)?;
    let sb = PatchSamples::<T, CAP>::new(b, order)?;
    Ok((exchange_unchecked(&sa, &sb, occluders)?, (sa.len() * sb.len()) as u64))
}

fn separate<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (p, across, swap) = separate_plan::<T, SA, SB, O, CAP>(a, b, settings, occluders)?;
    if across {
        // A_a·F_{a→b} = A_b·F_{b→a}: the outer patch is the one the plan chose.
        return if swap {
            across_boundaries::<T, SB, SA, O, CAP>(b, a, settings, occluders, depth)
        } else {
            across_boundaries::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth)
        };
    }
    // Below order 4 two successive orders can agree by accident; start there.
    let p = p.max(4).min(settings.max_order - 2);
    let eval = |order: usize| plain::<T, SA, SB, O, CAP>(a, b, order, occluders);
    by_order_doubling::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, eval, p, Split::Larger)
}

/// How a pair that reaches `max_order` is subdivided.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Split {
    /// The larger patch in two ([`split`]): separate pairs.
    Larger,
    /// Both patches 2 × 2 ([`split_both`]): touching pairs, whose cells along the contact must
    /// share whole edges or corners to be recognised as touching again (halving one patch
    /// leaves a partial shared edge, which the plain rule would integrate across). Touching
    /// pairs also need two comparisons (three orders, from 4) before they are accepted: their
    /// low orders are cheap, and the convergence rate of the transforms varies with the
    /// geometry.
    Both,
}

/// Evaluates the pair at orders p, p + 2, … (`eval` gives the value and its evaluations) until
/// the estimate meets the tolerance; when the next order would pass `max_order`, splits the
/// pair as `how` says (or, at the depth limit, returns the last value with its estimate, not
/// converged).
///
/// The estimate of Q_{p+2} is max(d₂, √(d₁·d₂)) with d₂ = |Q_{p+2} − Q_p| and d₁ =
/// |Q_p − Q_{p−2}| (d₂ alone on the first comparison): convergence that stalls for a step —
/// one part of the integrand converging at a slower rate than the rest — makes d₂ alone
/// accidentally small (a touching pair at 28.6°: orders 4 / 6 / 8 off by 8.4e-5 / −2.5e-9 /
/// −3.6e-9, d₂ = 1.1e-9 below the error); the geometric mean with the previous step holds the
/// estimate at the rate seen so far.
#[allow(clippy::too_many_arguments)]
fn by_order_doubling<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
    eval: impl Fn(usize) -> Result<(T, u64), PdmError>,
    first_order: usize,
    how: Split,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let last_order = settings.max_order;
    let mut p = first_order;
    let (mut prev, mut evaluations) = eval(p)?;
    let mut previous_difference: Option<T> = None;
    loop {
        let next_p = p + 2;
        let (next, n) = eval(next_p)?;
        evaluations = evaluations.saturating_add(n);
        let difference = (next - prev).abs();
        let estimate = previous_difference.map_or(difference, |d1| difference.max((d1 * difference).sqrt()));
        let leaf = Tally::leaf(next, estimate, settings.tolerance, evaluations);
        let accepted = leaf.converged && (how == Split::Larger || previous_difference.is_some());
        if accepted || (next_p + 2 > last_order && depth >= settings.max_depth) {
            return Ok(Tally { converged: accepted, ..leaf });
        }
        if next_p + 2 > last_order {
            let children = match how {
                Split::Larger => split::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, evaluations),
                Split::Both => split_both::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, evaluations),
            };
            return or_parent(children, leaf);
        }
        previous_difference = Some(difference);
        prev = next;
        p = next_p;
    }
}

/// The four approximations of a pair across visibility boundaries (module docs): the outer
/// patch whole and split 2 × 2 at orders p and p + 1.
#[inline(never)]
fn across_leaf<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Inner order from the tolerance (the inner rule converges exponentially where its
    // boundaries are in closed form): ≈ 1 digit per order above 4, within 6..max_order.
    let digits = (T::ONE / settings.tolerance).ln() / T::from_f64(core::f64::consts::LN_10);
    let mut p = 6usize;
    while p + 1 < settings.max_order && T::from_usize(p) < digits + T::TWO {
        p += 1;
    }
    let r = a.rect();
    let mut evaluations = 0u64;
    let mut at = |order: usize| -> Result<(T, T), PdmError> {
        let (whole, n, _, _) = crate::boundary::boundary_unchecked::<T, SA, SB, O, CAP>(a, b, order, occluders)?;
        evaluations = evaluations.saturating_add(n);
        let mut quarters = T::ZERO;
        for k in 0..4 {
            let child = Patch::new(a.surface(), r.cell(k / 2, k % 2, 2, 2))?;
            let (v, n, _, _) = crate::boundary::boundary_unchecked::<T, SA, SB, O, CAP>(&child, b, order, occluders)?;
            quarters += v;
            evaluations = evaluations.saturating_add(n);
        }
        Ok((whole, quarters))
    };
    let (whole, quarters) = at(p)?;
    let (whole_next, best) = at(p + 1)?;
    let difference = [best - whole, best - whole_next, best - quarters, quarters - whole, quarters - whole_next]
        .iter()
        .fold(T::ZERO, |m, d| m.max(d.abs()));
    Ok(Tally::leaf(best, T::from_f64(SAFETY) * difference, settings.tolerance, evaluations))
}

/// A pair that a visibility boundary crosses. The boundaries are placed into the inner rule
/// (`boundary.rs`), but the outer integrand still has kinks where a boundary
/// meets the inner patch's edges, and two Gauss orders can agree there by accident. So the error is estimated from the outer patch whole and split
/// 2 × 2 at two orders ([`across_leaf`], module docs), and the pair is subdivided further while
/// the estimate exceeds the tolerance.
fn across_boundaries<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let leaf = across_leaf::<T, SA, SB, O, CAP>(a, b, settings, occluders)?;
    if leaf.converged || depth >= settings.max_depth {
        return Ok(leaf);
    }
    or_parent(split::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, leaf.evaluations), leaf)
}

/// The children of a subdivision, or — where the working precision cannot carry it out (cells
/// below the geometry's resolution: `Err(Degenerate)` or `Err(Unresolvable)` from a child) —
/// the parent's value with its estimate, `converged = false`: that estimate was computed
/// before the split and was above the tolerance, which is what the result then says.
fn or_parent<T: Real>(children: Result<Tally<T>, PdmError>, parent: Tally<T>) -> Result<Tally<T>, PdmError> {
    match children {
        Err(PdmError::Degenerate | PdmError::Unresolvable) => Ok(Tally { converged: false, ..parent }),
        other => other,
    }
}

/// Splits both patches 2 × 2 at their parameter midpoints and recurses on the 16 sub-pairs;
/// `spent` evaluations are carried into the total (touching pairs stay edge- or vertex-adjacent when both maps divide the shared edge in
/// proportion, as the built-in surfaces' grids do).
fn split_both<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
    spent: u64,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Tally::zero(spent);
    let (ra, rb) = (a.rect(), b.rect());
    for k in 0..4 {
        let ca = Patch::new(a.surface(), ra.cell(k / 2, k % 2, 2, 2))?;
        for l in 0..4 {
            let cb = Patch::new(b.surface(), rb.cell(l / 2, l % 2, 2, 2))?;
            total.add(recurse::<T, SA, SB, O, CAP>(&ca, &cb, settings, occluders, depth + 1)?);
        }
    }
    Ok(total)
}

/// Splits the larger patch (by the arc length of its longer side) in two across that side and
/// recurses on both halves; `spent` evaluations are carried into the total.
fn split<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
    spent: u64,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Tally::zero(spent);
    let (la, lb) = (side_lengths(a), side_lengths(b));
    let split_a = la.0.max(la.1) >= lb.0.max(lb.1);
    for half in 0..2 {
        let e = if split_a {
            let Some(ca) = half_patch(a, la, half) else { return Err(PdmError::Degenerate) };
            recurse::<T, SA, SB, O, CAP>(&ca, b, settings, occluders, depth + 1)?
        } else {
            let Some(cb) = half_patch(b, lb, half) else { return Err(PdmError::Degenerate) };
            recurse::<T, SA, SB, O, CAP>(a, &cb, settings, occluders, depth + 1)?
        };
        total.add(e);
    }
    Ok(total)
}

/// Segments of the polylines that measure a side.
const SIDE_SEGMENTS: usize = 12;

/// Arc lengths of a patch's image along t and along s: the longest of the polylines (12
/// segments) along the two edges and the mid-line in each direction. A chord would be zero on a
/// side that closes on itself (the θ side of a whole disk, cylinder or sphere band).
pub(crate) fn side_lengths<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> (T, T) {
    let r = p.rect();
    let g = p.surface();
    let n = T::from_usize(SIDE_SEGMENTS);
    let polyline = |point: &dyn Fn(T) -> crate::vec3::Vec3<T>| {
        let mut length = T::ZERO;
        let mut prev = point(T::ZERO);
        for k in 1..=SIDE_SEGMENTS {
            let next = point(T::from_usize(k) / n);
            length += (next - prev).norm();
            prev = next;
        }
        length
    };
    let (mut along_t, mut along_s) = (T::ZERO, T::ZERO);
    for f in [T::ZERO, T::HALF, T::ONE] {
        let s = r.s0 + (r.s1 - r.s0) * f;
        let t = r.t0 + (r.t1 - r.t0) * f;
        along_t = along_t.max(polyline(&|x| g.point(r.t0 + (r.t1 - r.t0) * x, s)));
        along_s = along_s.max(polyline(&|x| g.point(t, r.s0 + (r.s1 - r.s0) * x)));
    }
    (along_t, along_s)
}

/// Half `k` (0 or 1) of a patch with side lengths `(along_t, along_s)`, split across the
/// longer one.
pub(crate) fn half_patch<'s, T: Real, S: Surface<T> + ?Sized>(
    p: &Patch<'s, T, S>,
    (along_t, along_s): (T, T),
    k: usize,
) -> Option<Patch<'s, T, S>> {
    let r: ParamRect<T> = p.rect();
    let cell = if along_t >= along_s { r.cell(k, 0, 2, 1) } else { r.cell(0, k, 1, 2) };
    Patch::new(p.surface(), cell).ok()
}

/// `true` if some sample pairs pass the two-sided curvature test and others do not.
pub(crate) fn straddles_curvature_cut<T: Real, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
) -> bool {
    let mut seen_visible = false;
    let mut seen_hidden = false;
    for sa in a.iter() {
        for sb in b.iter() {
            let visible = mutually_facing(sa.point, sa.unit_normal, sb.point, sb.unit_normal);
            seen_visible |= visible;
            seen_hidden |= !visible;
            if seen_visible && seen_hidden {
                return true;
            }
        }
    }
    false
}
