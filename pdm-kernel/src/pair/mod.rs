//! One entry point for any pair of patches: picks the integration method the pair needs.
//!
//! - Two patches of one convex ball (cells of an outer sphere: `on_one_convex_ball`) cannot
//!   see each other: zero, without work.
//! - A patch whose image closes on itself (a whole disk, cylinder, cone or sphere as one
//!   patch) is first cut at its seam into pieces (`pieces`); every pair of pieces is then
//!   dispatched as below and the results are summed. A pair of pieces that overlap on one
//!   map, or where a corner of one lies inside an edge of the other (grids that do not meet
//!   edge to edge), is cut there first, into identical, touching and separate pairs.
//! - Two flat patches that see each other wholly, with no occluder able to cut between them,
//!   use the contour form (`contour/`), separate or touching: parallelograms with the inner
//!   line integral in closed form, flat patches with curved edges (disk and annulus sectors,
//!   planar Bézier patches, a disk against a parallelogram) with graded rules along both
//!   edges ([`Surface::point_and_partials`]). Exponential in the order at any gap, from far
//!   apart down to nearly coincident, along a shared edge (whole or partial) and at a shared
//!   vertex. Where its terms cancel beyond half the digits, a
//!   touching pair falls to the transforms below.
//! - Other touching pairs (shared edge or vertex, found by
//!   `classify_near`, also when they are only nearly touching) use the
//!   regularising transforms of `singular/`, converging exponentially with
//!   `singular_order`.
//! - A touching pair that an occluder may cut is first split, both patches 2 × 2, until the
//!   cells along the contact are clear of every occluder (at most `MAX_CONTACT_SPLITS`
//!   levels): a shadow across the pair would put a jump into the transformed integrand. The
//!   sub-pairs are dispatched as above and below.
//! - The same patch twice uses the identical-panel transform of `singular/`,
//!   converging exponentially with `singular_order` on a smooth patch.
//! - Other separate pairs use the PDM sum at `order`. With `boundaries` on, a pair that
//!   straddles a back-face cut (seen on the samples, or not proven absent by the patches'
//!   normal cones: `facing_settled`), that an occluder may cut, or whose patches are closer
//!   than their size gets the visibility boundaries placed into the inner rule and the inner patch
//!   refined towards each outer point (`boundary/`; when an occluder may cut, the outer
//!   events are placed into the outer rule where `boundary::outer_events_apply` gives them —
//!   two parallelograms across one sphere or flat convex occluders, cells of spheres with the
//!   occluding sphere's centre, against each other or around a parallelogram — and the outer patch is split `OCCLUDED_OUTER_SPLIT`²
//!   otherwise); smooth, distant, unoccludable pairs
//!   keep the plain sum. Without occluders the outer patch is, for a very near pair with one
//!   flat patch, the curved one; otherwise the one with fewer points that see none of the
//!   other, then the one whose points stay farther from the other's edges (`outer_is_b`).
//!   Where an occluder may cut, the flat one if only one is flat, else the smaller one
//!   (`occluded_outer_is_b`). Either way the choice does not depend on the argument order.
//!
//! Every value is checked against the physical bounds 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b) before
//! it is returned.
//!
//! The decisions above are made once for this mode and the tolerance mode: `route.rs` (the
//! route of a pair after the contour form) and `PairContext::separate_route` (a separate
//! pair's). Each pair is integrated from one `PairContext` (`context.rs`): its two sample
//! buffers are filled on first use and shared by every method, so b is sampled once per order.
//!
//! Files: the settings, the entry point and the dispatch here; `route.rs` (the route),
//! `context.rs` (the pair context), `pieces.rs` (closed patches cut at their seams),
//! `choose.rs` (near, resolved, which patch goes outside), `flat.rs` (the contour form's pairs).

use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::integrand::mutually_facing;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_unchecked, Adjacency};
use crate::surface::Surface;
use crate::vec3::Vec3;
use crate::visibility::Occluder;

mod choose;
mod context;
#[cfg(feature = "closed-form")]
mod flat;
mod pieces;
mod route;
pub(crate) use choose::*;
pub(crate) use context::*;
#[cfg(feature = "closed-form")]
pub(crate) use flat::*;
pub(crate) use pieces::*;
pub(crate) use route::*;

/// Cells per side into which the outer patch of a pair that an occluder may cut is split,
/// where the outer events are not placed into the rule (`boundary/`: they are for two
/// parallelograms across sphere occluders). There the outer integral is only algebraic in the
/// cell size (kinks where a shadow boundary meets the inner patch's corners or edges), so finer
/// outer cells at a lower order pay: 3 × 3 beat 2 × 2 at equal cost on the paper's cube.
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

/// `Err(Unresolvable)` where the math backend places sample points less accurately than the
/// gap between two separate patches: with a fast sine and cosine ([`Real::sin_cos_fast`],
/// micromath's), points of a curved surface lie up to [`Real::ELEMENTARY_ERROR`] times its
/// size off it, and a sphere that far above a disk samples points below it (1e-3 of the
/// radius above a small disk: 13 % off at order 12, or a refinement without end). With libm
/// this is never the case.
pub(crate) fn backend_resolves<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> Result<(), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    if !crate::real::approximate_sin_cos::<T>() {
        return Ok(());
    }
    let limit = T::ELEMENTARY_ERROR * trig_size(a).max(trig_size(b));
    if classify_near(a, b).0 == Adjacency::Separate && crate::boundary::gap_below(a, b, limit)? {
        return Err(PdmError::Unresolvable);
    }
    Ok(())
}

/// The size of the surface a patch lies on (the radius of its whole domain's enclosing ball),
/// zero for a flat surface: the fast sine and cosine move a flat surface's points within its
/// plane (a disk's), which leaves every gap as it is.
fn trig_size<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> T {
    match Patch::whole(p.surface()) {
        Ok(whole) if !is_flat(&whole) => whole.enclosing_ball().radius,
        _ => T::ZERO,
    }
}

/// A_a·F_{a→b} for any two patches, by the method the pair needs (see the module docs), as an
/// [`Estimate`] without an error estimate (`error: None`, `converged: false`: a fixed-order
/// method) and with the work it did in `evaluations`: kernel evaluations and visibility probes
/// on the boundary path (`boundary/`), order⁴ for a plain sum and order⁴ more for the
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
/// - across occluders other than spheres, or with a curved patch (a shadow edge meeting the
///   inner patch's corners and edges, sampled by the outer rule): about 1e-7 to 1e-5 relative
///   (a tube between a small square and a large one: 2.1e-5 at 16, its shadow's boundaries
///   bisected rather than solved); a curved outer patch across a sphere, which gets no outer
///   events, converges slowly and not monotonically (cells of two spheres with a third
///   between: 9e-4 / 1e-3 / 2e-4 / 1e-4 at orders 8 / 12 / 16 / 20) — except a sphere's cell
///   around a parallelogram inside it across a sphere with its centre, a sphere's cell
///   against a parallelogram in front of all its tangent planes across any one sphere, and a
///   cell of a sphere inside a shell against a cell of the shell's inside in front of it,
///   across a sphere with the shell's centre, whose events are placed
///   (`boundary/concentric.rs`, `boundary/sphere_flat.rs`). Two parallelograms across one sphere have those curves placed
///   into the outer rule and converge exponentially (whole cube faces around a sphere: 1.3e-8
///   at order 8, 1.6e-11 at 12); an occluder that cuts through the outer patch itself makes the
///   outer integrand jump along the cut, and the outer rule converges only like 1/order (a
///   partition plate through two parallel rectangles, dividing both: 7.8e-4 at order 12,
///   5.1e-4 at 16; split the patches along the cut, or use the tolerance mode);
/// - a curved (not flat) patch closer to another patch than the smaller one's size: the outer
///   integrand has a layer on the scale of the gap (a peak under the closest point, a step
///   where one patch passes over the other's edge). The boundary path cuts the outer patch
///   into up to 32 cells graded towards the inner one and puts a flat patch inside
///   (`boundary/`); a sphere cell of radius 0.3 whose lowest point is 1e-1, 3e-2 or
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
    backend_resolves(a, b)?;
    if on_one_convex_ball(a, b) {
        return Ok(Estimate::fixed(T::ZERO, 0));
    }
    let (mut value, mut count, mut rounding) = (T::ZERO, 0u64, T::ZERO);
    for_each_piece_pair(a, b, occluders, |pa, pb| {
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
    let value = crate::bounds::exchange_within(value, band, a.bounds_area(order)?, b.bounds_area(order)?)?;
    Ok(Estimate::fixed(value, count))
}

/// Whether both patches lie on the sphere bounding one ball with their normals pointing out of
/// it ([`Surface::convex_ball`]: cells of one outer sphere, a cell and the whole sphere). A
/// segment from such a patch that passes its facing test leaves the ball at once, so it never
/// reaches the other patch: the exchange is exactly zero, and the pair takes no work (its
/// pieces would otherwise go through the touching and identical transforms to sum zeros).
/// The balls must agree to rounding: 16 ε of their size and position.
pub(crate) fn on_one_convex_ball<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    #[cfg(feature = "closed-form")]
    if let (Some(x), Some(y)) = (a.surface().convex_ball(), b.surface().convex_ball()) {
        let scale = x.radius + x.center.norm();
        let tight = T::from_f64(16.0) * T::EPSILON * scale;
        return (x.center - y.center).norm() <= tight && (x.radius - y.radius).abs() <= tight;
    }
    let _ = (a, b);
    false
}

/// Most successive 2 × 2 × 2 × 2 splits of a touching pair that an occluder may cut, before
/// the touching transforms take the remaining cells along the contact (module docs).
#[doc(hidden)]
pub const MAX_CONTACT_SPLITS: u32 = 4;

/// One piece pair: its route ([`route`]), with a touching pair that an occluder may cut split
/// first ([`Route::SplitContact`]: a shadow across the pair puts a jump into the transformed
/// integrand, and the transforms' rules then converge only algebraically — a box floor against
/// a wall it shares an edge with, a sphere inside: 4e-4 at singular order 12). Both patches are
/// split 2 × 2 and the 16 sub-pairs routed anew: the cells along the contact shrink until no
/// occluder can cut between them, and the others are separate pairs, which the boundary path
/// integrates with the shadows placed into its inner rule. After `MAX_CONTACT_SPLITS` levels
/// (an occluder that reaches the contact itself), the touching transforms take the remaining
/// cells as they are. The recursion keeps no sample buffer in its own frame: [`dispatch`]
/// holds them.
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
    if let Some(done) = dispatch::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth)? {
        return Ok(done);
    }
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
    Ok((value, count, rounding))
}

/// One piece pair by the method it needs: the contour form where it applies, else by its
/// [`route`]: (value, evaluations, bound on the contour form's rounding — zero for the other
/// methods), or `None` for a pair to be split ([`Route::SplitContact`]). The pair's context
/// (its two sample buffers) lives in this frame, which returns before the recursion above
/// descends.
#[inline(never)]
fn dispatch<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
    depth: u32,
) -> Result<Option<(T, u64, T)>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // The contour form first: most flat pairs end here, before the classification and the
    // sample buffers below (which only its refusals need).
    #[cfg(feature = "closed-form")]
    let flat = settings
        .boundaries
        .then(|| flat_pair(a, b, settings.order, occluders).map(|result| result.map(|(v, c, r, _)| (v, c, r))))
        .flatten();
    #[cfg(feature = "closed-form")]
    if let Some(Ok((v, c, r))) = flat {
        // (`cancels` is the stricter test: a value that passes it has not lost its digits.)
        if !crate::bounds::cancels(v, r) {
            return Ok(Some((v, c, r)));
        }
    }
    let (adjacency, gap) = classify_near(a, b);
    let mut pair = PairContext::<T, SA, SB, O, CAP>::new(a, b, occluders);
    #[cfg(feature = "closed-form")]
    if contour_applies(adjacency) {
        match flat {
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
                    && pair.resolved(settings.order)? => {}
            Some(result) => return result.map(Some),
            None => {}
        }
    }
    let may_split = settings.boundaries && depth < MAX_CONTACT_SPLITS;
    let exact = |(v, c): (T, u64)| Some((v, c, T::ZERO));
    match route(a, b, (adjacency, gap), occluders, may_split) {
        Route::SplitContact => Ok(None),
        Route::Touching { adjacency, gap, .. } => {
            let count = crate::singular::touching_evaluations(adjacency, settings.singular_order);
            Ok(exact((touching_unchecked(a, b, adjacency, gap, settings.singular_order, occluders)?, count)))
        }
        Route::Identical { .. } => {
            crate::singular::identical_unchecked(a, settings.singular_order, occluders).map(exact)
        }
        Route::Separate => separate(&mut pair, settings).map(exact),
        Route::ContactPastShadows => {
            #[cfg(feature = "closed-form")]
            if let Some(value) = contact_past_shadows(a, b, settings.order, occluders)? {
                return Ok(Some(value));
            }
            separate(&mut pair, settings).map(exact)
        }
    }
}

/// A touching flat pair across flat occluders ([`Route::ContactPastShadows`]) at `order`: the
/// unoccluded exchange by the contour form less the part the occluders block
/// ([`crate::boundary::Blocked`]), as `dispatch` returns it (the contour form's
/// rounding bound with it); `None` where either part does not apply.
#[cfg(feature = "closed-form")]
#[inline(never)]
pub(crate) fn contact_past_shadows<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<Option<(T, u64, T)>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let Some(Ok((unoccluded, count, rounding, _))) = flat_pair(a, b, order, &()) else { return Ok(None) };
    if crate::bounds::cancels(unoccluded, rounding) {
        return Ok(None);
    }
    let Some(part) = crate::boundary::Blocked::new(a, b, occluders)? else { return Ok(None) };
    let Some((blocked, blocked_count)) = part.sum(order)? else { return Ok(None) };
    Ok(Some((unoccluded - blocked, count.saturating_add(blocked_count), rounding)))
}

/// A separate pair: the plain sum where the integrand is smooth, else the boundary path. Where
/// an occluder may cut, shadow edges crossing the inner patch make the outer integrand kink
/// where they touch its edges: where `boundary::outer_events_apply` gives those curves (two
/// parallelograms across one sphere or flat convex occluders, cells of spheres with the
/// occluding sphere's centre, against each other or around a parallelogram) they are placed into the outer rule, elsewhere the outer patch
/// is split `OCCLUDED_OUTER_SPLIT`².
fn separate<T, SA, SB, O, const CAP: usize>(
    pair: &mut PairContext<'_, '_, T, SA, SB, O, CAP>,
    settings: PairSettings,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let order = settings.order;
    let p4 = (order as u64).saturating_pow(4);
    let occluders = pair.occluders;
    if !settings.boundaries {
        let (value, _) = pair.plain(order, occluders)?;
        return Ok((value, p4));
    }
    match pair.separate_route(order)? {
        SeparateRoute::Occluded { outer_b } => {
            // With the outer events placed into the rule the outer patch needs no cells.
            #[cfg(feature = "closed-form")]
            let (events, outer_b) = occluded_outer(pair.a, pair.b, occluders, outer_b);
            #[cfg(not(feature = "closed-form"))]
            let events = false;
            let split = if events { 1 } else { OCCLUDED_OUTER_SPLIT };
            pair.boundary(order, outer_b, split, occluders)
        }
        SeparateRoute::Boundary { outer_b } => {
            let (value, count) = pair.boundary(order, outer_b, 1, &())?;
            Ok((value, count.saturating_add(p4)))
        }
        // Smooth pair: nothing to place into the rule, no occluder can cut it.
        SeparateRoute::Plain => {
            let (value, _) = pair.plain(order, &())?;
            Ok((value, 2 * p4))
        }
    }
}
