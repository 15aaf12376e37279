//! One entry point for any pair of patches: picks the integration method the pair needs.
//!
//! - A patch whose image closes on itself (a whole disk, cylinder, cone or sphere as one
//!   patch) is first cut at its seam into pieces (`pieces`); every pair of pieces is then
//!   dispatched as below and the results are summed.
//! - Two flat patches that see each other wholly, with no occluder able to cut between them,
//!   use the contour form (`contour.rs`), separate or touching: parallelograms with the inner
//!   line integral in closed form, flat patches with curved edges (disk and annulus sectors,
//!   planar Bézier patches, a disk against a parallelogram) with graded rules along both
//!   edges ([`Surface::point_and_partials`]). Exponential in the order at any gap, from far
//!   apart down to nearly coincident, along a shared edge (whole or partial) and at a shared
//!   vertex. Where its terms cancel beyond half the digits, a
//!   touching pair falls to the transforms below.
//! - Other touching pairs (shared edge or vertex, found by
//!   `classify_near`, also when they are only nearly touching) use the
//!   regularising transforms of `singular.rs`, converging exponentially with
//!   `singular_order`.
//! - A touching pair that an occluder may cut is first split, both patches 2 × 2, until the
//!   cells along the contact are clear of every occluder (at most `MAX_CONTACT_SPLITS`
//!   levels): a shadow across the pair would put a jump into the transformed integrand. The
//!   sub-pairs are dispatched as above and below.
//! - The same patch twice uses the identical-panel transform of `singular.rs`,
//!   converging exponentially with `singular_order` on a smooth patch.
//! - Other separate pairs use the PDM sum at `order`. With `boundaries` on, a pair that
//!   straddles a back-face cut, that an occluder may cut, or whose patches are closer than
//!   their size gets the visibility boundaries placed into the inner rule and the inner patch
//!   refined towards each outer point (`boundary.rs`; the outer patch is also split
//!   `OCCLUDED_OUTER_SPLIT`² when an occluder may cut); smooth, distant, unoccludable pairs
//!   keep the plain sum. Without occluders the outer patch is, for a very near pair with one
//!   flat patch, the curved one; otherwise the one with fewer points that see none of the
//!   other, then the one whose points stay farther from the other's edges (`outer_is_b`).
//!   Where an occluder may cut, the flat one if only one is flat, else the smaller one
//!   (`occluded_outer_is_b`). Either way the choice does not depend on the argument order.
//!
//! Every value is checked against the physical bounds 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b) before
//! it is returned.

use crate::adaptive::straddles_curvature_cut;
use crate::boundary::boundary_unchecked;
use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::form_factor::exchange_unchecked;
use crate::integrand::mutually_facing;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_unchecked, Adjacency};
use crate::surface::Surface;
#[cfg(feature = "closed-form")]
use crate::vec3::Vec3;
use crate::visibility::Occluder;

/// Cells per side into which the outer patch of a pair that an occluder may cut is split.
/// The inner integral is exponential in the order (closed-form boundaries), the outer one only
/// algebraic in the cell size (kinks where a shadow boundary meets the inner patch's corners or
/// edges), so finer outer cells at a lower order pay: on the paper's cube, 3 × 3 beats 2 × 2 at
/// equal cost for every radius and grid tried (RESULTS.md, "Within 1e-6 in under a second").
#[doc(hidden)]
pub const OCCLUDED_OUTER_SPLIT: usize = 3;

/// Relative overshoot of the physical bounds that [`pair_exchange`] clamps as quadrature error
/// (its documented accuracy reaches 1e-4 across occluders); beyond it, `Err(InvalidResult)`.
const QUADRATURE_BAND: f64 = 1e-4;

/// How to integrate a pair of patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairSettings {
    /// Gauss order per axis for separate pairs.
    pub order: usize,
    /// Gauss order per variable for touching pairs (6·order⁴ evaluations for a shared edge).
    pub singular_order: usize,
    /// Place visibility boundaries into the inner rule (exact inner integrals on straddling
    /// pairs) instead of letting the fixed rule sample across them.
    pub boundaries: bool,
}

impl PairSettings {
    /// Accurate defaults: order 16, singular order 12, boundaries on (≈1e-12 on smooth pairs).
    pub const ACCURATE: Self = Self { order: 16, singular_order: 12, boundaries: true };
}

/// A_a·F_{a→b} for any two patches, by the method the pair needs (see the module docs), as an
/// [`Estimate`] without an error estimate (`error: None`, `converged: false`: a fixed-order
/// method) and with the work it did in `evaluations`: kernel evaluations and visibility probes
/// on the boundary path (`boundary.rs`), order⁴ for a plain sum and order⁴ more for the
/// straddle check, 6·p⁴ for a shared edge and 4·p⁴ for a shared vertex (p = `singular_order`),
/// 4·p⁴ for a self pair (times the ζ-shells of long patches).
///
/// The quantity is symmetric (A_a·F_{a→b} = A_b·F_{b→a}), and so, mostly, is the computation:
/// on the boundary path one patch is integrated outside (its Gauss points) and the other inside
/// (its visible part from each outer point), chosen from the geometry (module docs), so both
/// argument orders give the same value; where the geometry leaves a tie (two equal patches), a
/// goes outside and the two orders agree to the quadrature error. Divide by A_a
/// ([`Patch::area`]) for F_{a→b}.
///
/// Accuracy at [`PairSettings::ACCURATE`]: about 1e-12 on smooth, touching and flat pairs.
/// Where the outer integrand has a kink or a layer, the outer rule converges only
/// algebraically, and this fixed-order method has no estimate of it:
/// - a curved patch straddling the back-face cut of the other: the inner integral is exact,
///   but the outer integrand kinks where the visible part's boundary passes through a corner
///   of the inner patch or touches one of its edges. Where those curves miss the outer
///   patch's nodes or line up with its edges the pair is exact (an upright sphere cut 2 × 4
///   above a plate: 5e-16); elsewhere it is 1e-8 to 1e-6 on whole surfaces at order 16 (the
///   same sphere tilted: 1.6e-6 against the plate whole, 6.3e-8 cut 2 × 2) and worse for
///   single pairs (a sphere quarter against a disk quarter: 2.6e-4 at order 12; over the
///   whole sphere and disk such errors cancel to 1e-13). Finer grids reduce it;
/// - across occluders (a shadow edge meeting the inner patch's corners and edges): about 1e-7
///   to 1e-5 relative (a sphere inside a box, the floor's row to the other faces: 1.3e-6 at
///   order 12, 1.2e-6 at 16; a tube between a small square and a large one: 2.1e-5 at 16,
///   its shadow's boundaries bisected rather than solved); an occluder that cuts through the outer patch itself makes the
///   outer integrand jump along the cut, and the outer rule converges only like 1/order (a
///   partition plate through two parallel rectangles, dividing both: 7.8e-4 at order 12,
///   5.1e-4 at 16; split the patches along the cut, or use the tolerance mode);
/// - a curved (not flat) patch closer to another patch than the smaller one's size: the outer
///   integrand has a layer on the scale of the gap (a peak under the closest point, a step
///   where one patch passes over the other's edge). The boundary path cuts the outer patch
///   into up to 32 cells graded towards the inner one and puts a flat patch inside
///   (`boundary.rs`); a sphere cell of radius 0.3 whose lowest point is 1e-1, 3e-2 or
///   1e-3 above a plate cell near its corner: 6.0e-9 / 1.3e-9 / 1.3e-8 at order 12, 8.3e-10 /
///   9.3e-10 / 7.4e-9 at 16 (test `trust::sphere_cell_close_above_a_plate_cell`). Much closer
///   still, the 32 cells stop resolving the layer: subdivide such pairs towards the contact, or
///   use the tolerance mode. Two flat patches take the contour form instead, exact at any gap;
/// - self and edge pairs reaching a side that collapses to a point on a concave surface (the
///   pieces of a cone's inside at its apex: the whole wall against itself 2.0e-5 off at
///   singular order 12, 6.6e-6 at 16; a frustum, without the apex, 8e-11);
/// - a saddle against itself (it faces itself in some directions only: the facing test puts
///   kinks in the self kernel).
///
/// For a guaranteed accuracy use [`crate::adaptive_exchange`], whose estimate bounds the
/// error and whose `converged` flag says whether the tolerance was met.
///
/// Orientation: each patch radiates to the side its normal ∂g/∂t × ∂g/∂s points to (a
/// surface's `Side`, or [`crate::Flipped`]). `Ok(0.0)` means no segment between the two
/// patches passes the facing tests and the occluders: the patches are back to back, face
/// away from each other, are hidden, or one faces away from the other — a mistaken
/// orientation gives the same zero as a true one, so check the sides when a zero surprises.
///
/// `CAP` bounds the samples of one patch: ≥ order². Errors: bad input, `Err(InvalidResult)` for a value outside the physical
/// bounds by more than 1e-4 of itself (closer, the bound is returned), `Err(Unresolvable)` where the working precision cannot resolve the pair.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, PairSettings, Parallelogram, Patch};
/// // Two perpendicular unit squares sharing an edge (catalogue C-14: F = 0.2000437760754...).
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0))?;
/// let e = pair_exchange::<f64, _, _, _, 256>(
///     &Patch::whole(&floor)?, &Patch::whole(&wall)?, PairSettings::ACCURATE, &())?;
/// assert!((e.value - 0.20004377607540316).abs() < 1e-12); // A_floor = 1
/// assert_eq!(e.error, None); // a fixed-order method: no estimate (see `adaptive_exchange`)
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn pair_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
) -> Result<Estimate<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (mut value, mut count, mut rounding) = (T::ZERO, 0u64, T::ZERO);
    for_each_piece_pair(a, b, |pa, pb| {
        let (v, c, r) = split_occluded_contacts::<T, SA, SB, O, CAP>(pa, pb, settings, occluders, 0)?;
        value += v;
        count = count.saturating_add(c);
        rounding += r;
        Ok(())
    })?;
    // The contour form's terms can cancel beyond the working precision (long thin strips close
    // together): judged on the whole pair, not on its pieces (a whole disk's quarter that sees
    // little of the other disk has a small value and the usual rounding).
    if crate::bounds::lost_digits(value, rounding) {
        return Err(PdmError::Unresolvable);
    }
    let order = settings.order.max(2);
    // A pair whose exact value is the bound (an inner sphere inside an outer one: F = 1)
    // overshoots it by the quadrature error: within `QUADRATURE_BAND` the bound is returned
    // (which can only be closer to the true value); farther out the method is wrong for the
    // pair and the value is refused.
    let band = value.abs() * T::from_f64(QUADRATURE_BAND);
    let value = crate::bounds::exchange_within(value, band, a.area(order)?, b.area(order)?)?;
    Ok(Estimate::fixed(value, count))
}

/// `true` if two patches are closer than the larger one's radius: the plain rule's error then
/// falls slowly with the order (the kernel's nearest singularity is within a patch size), and the
/// boundary path, which refines the inner patch towards each outer point, takes the pair.
pub(crate) fn near<T: Real>(a: &crate::samples::Ball<T>, b: &crate::samples::Ball<T>) -> bool {
    (a.center - b.center).norm() - a.radius - b.radius < a.radius.max(b.radius)
}

/// Calls `f` on every pair of pieces of a and b (see [`pieces`]): the pair methods then see
/// only patches whose four corners are distinct unless an edge collapses to a point.
pub(crate) fn for_each_piece_pair<'s, 'r, T, SA, SB>(
    a: &Patch<'s, T, SA>,
    b: &Patch<'r, T, SB>,
    mut f: impl FnMut(&Patch<'s, T, SA>, &Patch<'r, T, SB>) -> Result<(), PdmError>,
) -> Result<(), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (ma, na) = pieces(a);
    let (mb, nb) = pieces(b);
    if ma * na * mb * nb == 1 {
        return f(a, b);
    }
    let (ra, rb) = (a.rect(), b.rect());
    for i in 0..ma * na {
        let pa = Patch::new(a.surface(), ra.cell(i / na, i % na, ma, na))?;
        for j in 0..mb * nb {
            let pb = Patch::new(b.surface(), rb.cell(j / nb, j % nb, mb, nb))?;
            f(&pa, &pb)?;
        }
    }
    Ok(())
}

/// Into how many pieces (along t, along s) a patch is cut before integration: a direction in
/// which the patch's image closes on itself, or nearly (the chord between its ends less than
/// half the arc through its middle: the seam of a whole disk, cylinder, cone or sphere at
/// θ = 0 = 2π), is cut into 4 pieces, one that bends by more than about a half turn (chord
/// below ¾ of the arc: a sphere from pole to pole) into 2. The touching-pair classification
/// compares corners and edges, which a closed patch does not have apart; the transforms and
/// the splitter assume pieces that bend by much less than a full turn.
pub(crate) fn pieces<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> (usize, usize) {
    let r = p.rect();
    let g = p.surface();
    let (tm, sm) = ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    let count = |chord: T, arc: T| -> usize {
        if !(arc > T::ZERO) || !chord.is_finite() || !arc.is_finite() {
            1
        } else if chord < arc * T::HALF {
            4
        } else if chord < arc * T::from_f64(0.75) {
            2
        } else {
            1
        }
    };
    let along_t = |t0: T, t1: T| (g.point(t1, sm) - g.point(t0, sm)).norm();
    let along_s = |s0: T, s1: T| (g.point(tm, s1) - g.point(tm, s0)).norm();
    let arc = |seg: &dyn Fn(T, T) -> T, lo: T, hi: T| -> T {
        const SEGMENTS: usize = 16;
        let mut length = T::ZERO;
        for k in 0..SEGMENTS {
            let x0 = lo + (hi - lo) * T::from_usize(k) / T::from_usize(SEGMENTS);
            let x1 = lo + (hi - lo) * T::from_usize(k + 1) / T::from_usize(SEGMENTS);
            length += seg(x0, x1);
        }
        length
    };
    let m = count(along_t(r.t0, r.t1), arc(&along_t, r.t0, r.t1));
    let n = count(along_s(r.s0, r.s1), arc(&along_s, r.s0, r.s1));
    (m, n)
}

/// Most successive 2 × 2 × 2 × 2 splits of a touching pair that an occluder may cut, before
/// the touching transforms take the remaining cells along the contact (module docs).
#[doc(hidden)]
pub const MAX_CONTACT_SPLITS: u32 = 4;

/// One piece pair, with touching pairs that an occluder may cut split first: the touching
/// transforms regularise the kernel at the contact, but a shadow crossing the pair puts a jump
/// into the transformed integrand, and their rules then converge only algebraically (a box
/// floor against a wall it shares an edge with, a sphere inside: 4e-4 at singular order 12).
/// Both patches are split 2 × 2 and the 16 sub-pairs dispatched anew: the cells along the
/// contact shrink until no occluder can cut between them (the transforms are then exact), and
/// the others are separate pairs, which the boundary path integrates with the shadows placed
/// into its inner rule. After `MAX_CONTACT_SPLITS` levels (an occluder that reaches the
/// contact itself), the touching transforms take the remaining cells as they are.
/// The recursion keeps no sample buffer in its own frame: [`dispatch`] holds them.
fn split_occluded_contacts<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
    depth: u32,
) -> Result<(T, u64, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (adjacency, gap) = classify_near(a, b);
    let touching = matches!(adjacency, Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. });
    if settings.boundaries
        && touching
        && depth < MAX_CONTACT_SPLITS
        && occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball())
    {
        let (mut value, mut count, mut rounding) = (T::ZERO, 0u64, T::ZERO);
        let (ra, rb) = (a.rect(), b.rect());
        for i in 0..4 {
            let pa = Patch::new(a.surface(), ra.cell(i / 2, i % 2, 2, 2))?;
            for j in 0..4 {
                let pb = Patch::new(b.surface(), rb.cell(j / 2, j % 2, 2, 2))?;
                let (v, c, r) = split_occluded_contacts::<T, SA, SB, O, CAP>(&pa, &pb, settings, occluders, depth + 1)?;
                value += v;
                count = count.saturating_add(c);
                rounding += r;
            }
        }
        return Ok((value, count, rounding));
    }
    dispatch::<T, SA, SB, O, CAP>(a, b, (adjacency, gap), settings, occluders)
}

/// One piece pair by the method it needs, given its classification (`classify_near`):
/// (value, evaluations, bound on the contour form's rounding — zero for the other methods).
#[inline(never)]
fn dispatch<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    (adjacency, gap): (Adjacency, T),
    settings: PairSettings,
    occluders: &O,
) -> Result<(T, u64, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let p4 = (settings.order as u64).pow(4);
    #[cfg(feature = "closed-form")]
    if settings.boundaries && contour_applies(adjacency) {
        match flat_pair(a, b, settings.order, occluders) {
            // A touching pair whose contour terms cancel beyond the working precision, or
            // below the geometry's resolution: the transforms below take it.
            Some(Err(PdmError::Unresolvable)) if adjacency != Adjacency::Separate => {}
            Some(Ok((v, _, r))) if adjacency != Adjacency::Separate && crate::bounds::lost_digits(v, r) => {}
            // A separate pair whose value is far below its contour terms (flat patches side by
            // side, nearly in one plane: the terms' quadrature error is amplified as much):
            // the 4-D paths below take it where their rules resolve it; otherwise the contour
            // value goes on with its rounding bound, which the whole pair's check refuses if it
            // lost half the digits.
            Some(Ok((v, _, r)))
                if adjacency == Adjacency::Separate
                    && crate::bounds::cancels(v, r)
                    && resolved::<T, SA, SB, CAP>(a, b, settings.order)? => {}
            Some(result) => return result,
            None => {}
        }
    }
    let exact = |(v, c): (T, u64)| (v, c, T::ZERO);
    match adjacency {
        Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. } => {
            let count = crate::singular::touching_evaluations(adjacency, settings.singular_order);
            Ok(exact((touching_unchecked(a, b, adjacency, gap, settings.singular_order, occluders)?, count)))
        }
        Adjacency::Identical => crate::singular::identical_unchecked(a, settings.singular_order, occluders).map(exact),
        Adjacency::Separate => {
            let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
            let sb = PatchSamples::<T, CAP>::new(b, settings.order)?;
            if !settings.boundaries {
                return Ok(exact((exchange_unchecked(&sa, &sb, occluders)?, p4)));
            }
            // The sample balls decide for the plain sum; the integrand is smooth only if no
            // occluder cuts any segment between the patches (enclosing balls).
            let may_occlude = occluders.may_block_between(&sa.bounds(), &sb.bounds())
                || occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball());
            if may_occlude {
                if !occluded_outer_is_b(a, b) {
                    occluded::<T, SA, SB, O, CAP>(a, b, settings.order, occluders).map(exact)
                } else {
                    occluded::<T, SB, SA, O, CAP>(b, a, settings.order, occluders).map(exact)
                }
            } else if straddles_curvature_cut(&sa, &sb) || near(&a.enclosing_ball(), &b.enclosing_ball()) {
                let swap = outer_is_b(a, b, &sa, &sb);
                let (v, c, _, _) = if swap {
                    boundary_unchecked::<T, SB, SA, (), CAP>(b, a, settings.order, &())?
                } else {
                    boundary_unchecked::<T, SA, SB, (), CAP>(a, b, settings.order, &())?
                };
                Ok(exact((v, c.saturating_add(p4))))
            } else {
                // Smooth pair: nothing to place into the rule, no occluder can cut it.
                Ok(exact((exchange_unchecked(&sa, &sb, &())?, 2 * p4)))
            }
        }
    }
}

/// Whether the Gauss rules of order `order` resolve the pair
/// ([`crate::form_factor::samples_resolved`]).
#[cfg(feature = "closed-form")]
pub(crate) fn resolved<T, SA, SB, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let sa = PatchSamples::<T, CAP>::new(a, order)?;
    let sb = PatchSamples::<T, CAP>::new(b, order)?;
    Ok(crate::form_factor::samples_resolved(&sa, order, &sb, order))
}

/// Which patch of a pair an occluder may cut the boundary path should integrate outside
/// (`true`: b). The inner rule is in closed form only on a flat (affine) inner patch: when only
/// one of the two is flat, it goes inside. Otherwise the smaller one (enclosing ball) goes
/// outside: the outer integrand kinks where a shadow boundary on the inner patch meets that
/// patch's corners and edges, and jumps where an occluder cuts the outer patch itself; on the
/// larger inner patch a shadow more often lies wholly inside, and the smaller outer patch is
/// less often cut. It also makes the choice independent of the argument order.
pub(crate) fn occluded_outer_is_b<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (flat_a, flat_b) = (has_affine_map(a), has_affine_map(b));
    if flat_a != flat_b {
        return flat_a;
    }
    b.enclosing_ball().radius < a.enclosing_ball().radius
}

/// Which patch of a separate, unoccluded pair the boundary path should integrate outside
/// (`true`: b). The outer integrand is smooth where every outer point sees part of the inner
/// patch; where some see none of it, the support's edge is a kink curve across the outer
/// patch: the patch with fewer blind sample points goes outside. On a tie, where an outer
/// point comes closer to the inner patch's edges than the outer rule's node spacing, the
/// inner integral changes on that distance's scale there (a disk 0.05 below a larger one:
/// across the small disk's rim), which the outer rule cannot resolve: the patch whose points
/// stay farther from the other's edges, in its own node spacings, goes outside (the small
/// disk over the large one). Otherwise the flat one (a curved outer patch sweeps its tangent
/// plane across the inner one, which adds kinks; a flat one does not).
pub(crate) fn outer_is_b<T, SA, SB, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    sa: &PatchSamples<T, CAP>,
    sb: &PatchSamples<T, CAP>,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    // Very near (`boundary::very_near`) with exactly one patch flat: the flat one goes inside.
    // A point of the curved patch sees the flat one cut by one plane (its tangent plane), which
    // the inner rule places in closed form or brackets as a line; a point of the flat patch may
    // see only a small cap of the curved one (a sphere cell 1e-3 above a plate: a cap of radius
    // √(2·R·gap)), which a probe grid misses. The blind-point count below is a sample count
    // that changes with the order on such a pair.
    if is_flat(a) != is_flat(b) && crate::boundary::very_near(a, b).unwrap_or(false) {
        return is_flat(a);
    }
    let (blind_a, blind_b) = (blind_points(sa, sb), blind_points(sb, sa));
    if blind_a != blind_b {
        return blind_b < blind_a;
    }
    let (clear_a, clear_b) = (edge_clearance(sa, b), edge_clearance(sb, a));
    if clear_a.min(clear_b) < T::ONE && clear_a != clear_b {
        return clear_b > clear_a;
    }
    is_flat(b) && !is_flat(a)
}

/// Segments per edge of the polylines that stand for a patch's edges in [`edge_clearance`].
const EDGE_SEGMENTS: usize = 16;

/// The smallest distance from a sample of `outer` to the edges of `inner` (16-segment
/// polylines), in node spacings of the outer rule (its sample ball's diameter / order).
fn edge_clearance<T, S, const CAP: usize>(outer: &PatchSamples<T, CAP>, inner: &Patch<'_, T, S>) -> T
where
    T: Real,
    S: Surface<T> + ?Sized,
{
    let r = inner.rect();
    let g = inner.surface();
    let n = T::from_usize(EDGE_SEGMENTS);
    let edge_point = |edge: usize, k: usize| {
        let x = T::from_usize(k) / n;
        let (t, s) = match edge {
            0 => (r.t0 + (r.t1 - r.t0) * x, r.s0),
            1 => (r.t1, r.s0 + (r.s1 - r.s0) * x),
            2 => (r.t0 + (r.t1 - r.t0) * x, r.s1),
            _ => (r.t0, r.s0 + (r.s1 - r.s0) * x),
        };
        g.point(t, s)
    };
    let mut nearest = T::MAX;
    for edge in 0..4 {
        let mut prev = edge_point(edge, 0);
        for k in 1..=EDGE_SEGMENTS {
            let next = edge_point(edge, k);
            let d = next - prev;
            let d2 = d.dot(d);
            for p in outer.iter() {
                let w = p.point - prev;
                let along = if d2 > T::ZERO { (w.dot(d) / d2).max(T::ZERO).min(T::ONE) } else { T::ZERO };
                nearest = nearest.min((w - d.scale(along)).norm());
            }
            prev = next;
        }
    }
    let order = T::from_usize(outer.len()).sqrt().max(T::ONE);
    let spacing = outer.bounds().radius * T::TWO / order;
    if spacing > T::ZERO {
        nearest / spacing
    } else {
        T::MAX
    }
}

/// How many samples of `outer` see no sample of `inner` through the two-sided facing test
/// (section 3.2): points where the inner integral of the boundary path would vanish.
fn blind_points<T: Real, const CAP: usize>(outer: &PatchSamples<T, CAP>, inner: &PatchSamples<T, CAP>) -> usize {
    outer
        .iter()
        .filter(|p| !inner.iter().any(|q| mutually_facing(p.point, p.unit_normal, q.point, q.unit_normal)))
        .count()
}

/// The boundary path with the outer patch split `OCCLUDED_OUTER_SPLIT`²: shadow edges
/// crossing b make the outer integrand kink where they touch b's edges.
fn occluded<T, SA, SB, O, const CAP: usize>(
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
    let (mut total, mut count) = (T::ZERO, 0u64);
    let r = a.rect();
    let n = OCCLUDED_OUTER_SPLIT;
    for k in 0..n * n {
        let child = Patch::new(a.surface(), r.cell(k / n, k % n, n, n))?;
        let (v, c, _, _) = boundary_unchecked::<T, SA, SB, O, CAP>(&child, b, order, occluders)?;
        total += v;
        count = count.saturating_add(c);
    }
    Ok((total, count))
}

/// Whether the patch's surface is a parallelogram (an affine map), which the boundary path
/// integrates in closed form as the inner patch.
fn has_affine_map<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> bool {
    #[cfg(feature = "closed-form")]
    return p.surface().affine_map().is_some();
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = p;
        false
    }
}

/// Whether the patch is flat: its unit normals at the centre and near the four corners agree to
/// rounding (a parallelogram, a disk or annulus sector, a planar Bézier patch).
fn is_flat<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> bool {
    let r = p.rect();
    let g = p.surface();
    let at = |x: T, y: T| {
        let n = g.normal(r.t0 + (r.t1 - r.t0) * x, r.s0 + (r.s1 - r.s0) * y);
        let length = n.norm();
        if length > T::ZERO && length.is_finite() {
            Some(n.scale(T::ONE / length))
        } else {
            None
        }
    };
    let (lo, hi) = (T::from_f64(0.125), T::from_f64(0.875));
    let Some(centre) = at(T::HALF, T::HALF) else { return false };
    let limit = T::ONE - T::from_f64(64.0) * T::EPSILON;
    [(lo, lo), (hi, lo), (lo, hi), (hi, hi)].iter().all(|&(x, y)| at(x, y).is_some_and(|n| n.dot(centre) >= limit))
}

/// Whether a pair of the given contact may take the contour form (if both patches are flat
/// and see each other wholly, [`flat_pair`]): separate, nearly touching and touching pairs —
/// along a shared edge the collinear edge term is the closed form at η = 0, whose logarithm
/// the outer rule's grading towards the edge's ends integrates (C-14 at order 12 to 3e-16 with
/// 672 line evaluations, where the edge transform needs 6·p⁴), and a partial shared edge (a
/// short edge lying along a longer one from a common corner, a non-conforming grid) is
/// covered the same way. The same patch twice takes the identical-panel transform.
#[cfg(feature = "closed-form")]
pub(crate) fn contour_applies(adjacency: Adjacency) -> bool {
    adjacency != Adjacency::Identical
}

/// Two flat patches that see each other wholly — each in the closed half-space in front of the
/// other, not coplanar, no occluder able to cut a segment between them — by the contour form
/// ([`crate::contour`]: parallelograms in closed form along the inner edge, curved edges by
/// graded rules), exponential at any gap and aspect ratio; `None` if the pair is not such a
/// pair. Gives the value, the evaluations and a bound on the value's rounding error (the
/// caller refuses values that lost half their digits, [`crate::bounds::lost_digits`]).
#[cfg(feature = "closed-form")]
pub(crate) fn flat_pair<'p, 'r, T, SA, SB, O>(
    a: &Patch<'p, T, SA>,
    b: &Patch<'r, T, SB>,
    order: usize,
    occluders: &O,
) -> Option<Result<(T, u64, T), PdmError>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Parallelograms by their corners, other flat patches by their outlines; each wholly in
    // front of (or on) the other's plane, and not both in one plane.
    let (shape, b_ahead, a_ahead, cos) = if let (Some((ca, na)), Some((cb, nb))) = (flat_corners(a), flat_corners(b)) {
        let size = ca.iter().chain(cb.iter()).fold(T::ZERO, |m, &p| m.max((p - ca[0]).norm()));
        let band = size * T::GEOMETRY_TOLERANCE;
        let side = |corners: &[Vec3<T>; 4], origin: Vec3<T>, n: Vec3<T>| {
            let mut ahead = false;
            for &q in corners {
                let h = n.dot(q - origin);
                if h < -band {
                    return None;
                }
                ahead |= h > band;
            }
            Some(ahead)
        };
        (FlatShape::Corners(ca, cb), side(&cb, ca[0], na)?, side(&ca, cb[0], nb)?, na.dot(nb))
    } else {
        let oa = crate::contour::Outline::new(a)?;
        let ob = crate::contour::Outline::new(b)?;
        let band = oa.size().max(ob.size()) * T::GEOMETRY_TOLERANCE;
        let (b_ahead, a_ahead) = (ob.ahead_of(oa.origin, oa.normal, band)?, oa.ahead_of(ob.origin, ob.normal, band)?);
        let cos = oa.normal.dot(ob.normal);
        (FlatShape::Outlines(oa, ob), b_ahead, a_ahead, cos)
    };
    if b_ahead && a_ahead {
        if occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball()) {
            return None;
        }
        let order = order.max(4);
        return Some(match shape {
            FlatShape::Corners(ca, cb) => crate::contour::quad_exchange(&ca, &cb, order),
            FlatShape::Outlines(oa, ob) => crate::contour::curve_exchange(&oa, &ob, order),
        });
    }
    // Each within the other's plane to the working precision while facing each other: a gap
    // below the geometry's resolution (f32 plates 1e-6 apart), which no path can integrate
    // (the 4-D rules would return a value off by percents).
    (!b_ahead && !a_ahead && cos < T::ZERO).then_some(Err(PdmError::Unresolvable))
}

/// The two flat patches of [`flat_pair`]: parallelograms by their corners (inner line
/// integrals in closed form), any other flat patches by their outlines.
#[cfg(feature = "closed-form")]
enum FlatShape<'p, 'r, T: Real, SA: Surface<T> + ?Sized, SB: Surface<T> + ?Sized> {
    Corners([Vec3<T>; 4], [Vec3<T>; 4]),
    Outlines(crate::contour::Outline<'p, T, SA>, crate::contour::Outline<'r, T, SB>),
}

/// A flat patch's corners counter-clockwise about its radiating normal, and its unit normal.
#[cfg(feature = "closed-form")]
fn flat_corners<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> Option<([Vec3<T>; 4], Vec3<T>)> {
    let (o, et, es) = p.surface().affine_map()?;
    let r = p.rect();
    let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
    let corners = [at(r.t0, r.s0), at(r.t1, r.s0), at(r.t1, r.s1), at(r.t0, r.s1)];
    let normal = p.surface().normal((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    let length = normal.norm();
    if !(length > T::ZERO) || !length.is_finite() {
        return None;
    }
    let n = normal.scale(T::ONE / length);
    let [c0, c1, c2, c3] = corners;
    Some(if n.dot(et.cross(es)) >= T::ZERO { (corners, n) } else { ([c0, c3, c2, c1], n) })
}
