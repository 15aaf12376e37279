//! Separate pairs in the tolerance mode: the start order from the geometry, the plain sum, and
//! pairs across visibility boundaries (four approximations, outer patch whole and split).

use super::*;
use crate::pair::SeparateRoute;

/// The least order whose samples judge a separate pair's route (whether sample pairs on both
/// sides of a back-face cut exist). The start order from the geometry can be 2 or 3 for a loose
/// tolerance, and on 2 × 2 or 3 × 3 samples a sphere cell that sees a face cell only in a sliver
/// looked wholly hidden: the plain sum's orders then agreed on values 1e-3 off
/// (`outer_events::tolerance_mode_estimates_cover_sphere_cell_slivers`). 8 × 8 samples are what
/// the fixed mode judges on at its default order. Samples can only show a straddle: a pair
/// whose samples show none takes the plain sum only where the normal cones prove the facing
/// test uniform (`pair::facing_settled`; a half of such a sliver pair, split at `max_order`,
/// has every 8 × 8 sample pair on one side).
const ROUTE_ORDER: usize = 8;

/// The starting order of a separate pair from its geometry (module docs, item 2), capped at
/// `max_order`, and the pair's route judged at that order or [`ROUTE_ORDER`], whichever is
/// higher (`PairContext::separate_route`, the same decision as the fixed-order mode's: the
/// plain sum, or the boundary path with its outer patch).
#[inline(never)]
pub(super) fn separate_plan<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<(usize, SeparateRoute), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut pair = crate::pair::PairContext::<T, SA, SB, O, CAP>::new(a, b, occluders);
    let (probe, probe_b) = pair.samples(2)?;
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
    let route = pair.separate_route(p.max(ROUTE_ORDER))?;
    Ok((p, route))
}

/// The plain PDM sum at `order` on both patches and its evaluations.
#[inline(never)]
pub(super) fn plain<T, SA, SB, O, const CAP: usize>(
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
    crate::pair::PairContext::<T, SA, SB, O, CAP>::new(a, b, occluders).plain(order, occluders)
}

pub(super) fn separate<T, SA, SB, O, const CAP: usize>(
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
    let (p, route) = separate_plan::<T, SA, SB, O, CAP>(a, b, settings, occluders)?;
    // A_a·F_{a→b} = A_b·F_{b→a}: the outer patch is the one the route chose. Off the occluded
    // route no occluder can cut a segment the pair counts (`PairContext::may_occlude`), and the
    // pair and its halves are integrated without them, as in the fixed-order mode: an occluder
    // left in would put its shadow machinery back where the route found none.
    match route {
        SeparateRoute::Occluded { outer_b: true } => {
            across_boundaries::<T, SB, SA, O, CAP>(b, a, settings, occluders, depth)
        }
        SeparateRoute::Occluded { outer_b: false } => {
            across_boundaries::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth)
        }
        SeparateRoute::Boundary { outer_b: true } => {
            across_boundaries::<T, SB, SA, (), CAP>(b, a, settings, &(), depth)
        }
        SeparateRoute::Boundary { outer_b: false } => {
            across_boundaries::<T, SA, SB, (), CAP>(a, b, settings, &(), depth)
        }
        SeparateRoute::Plain => {
            // Below order 4 two successive orders can agree by accident; start there.
            let p = p.max(4).min(settings.max_order - 2);
            let eval = |order: usize| plain::<T, SA, SB, (), CAP>(a, b, order, &());
            by_order_doubling::<T, SA, SB, (), CAP>(a, b, settings, &(), depth, eval, p, Split::Larger)
        }
    }
}

/// The four approximations of a pair across visibility boundaries (module docs): the outer
/// patch whole and split 2 × 2 at orders p and p + 1.
#[inline(never)]
pub(super) fn across_leaf<T, SA, SB, O, const CAP: usize>(
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
    // One pair context: b's samples are shared by the whole patch a and its quarters at each
    // order; a's buffer is re-filled for each.
    let mut pair = crate::pair::PairContext::<T, SA, SB, O, CAP>::new(a, b, occluders);
    let mut evaluations = 0u64;
    let mut at = |order: usize| -> Result<(T, T), PdmError> {
        let (whole, n) = pair.boundary(order, false, 1, occluders)?;
        evaluations = evaluations.saturating_add(n);
        let (quarters, n) = pair.boundary(order, false, 2, occluders)?;
        evaluations = evaluations.saturating_add(n);
        Ok((whole, quarters))
    };
    let (whole, quarters) = at(p)?;
    let (whole_next, best) = at(p + 1)?;
    let difference = [best - whole, best - whole_next, best - quarters, quarters - whole, quarters - whole_next]
        .iter()
        .fold(T::ZERO, |m, d| m.max(d.abs()));
    Ok(Tally::leaf(best, T::from_f64(SAFETY) * difference, settings, evaluations))
}

/// A pair that a visibility boundary crosses. The boundaries are placed into the inner rule
/// (`boundary/`). Where the outer events are placed into the outer rule too (a flat outer
/// patch against a parallelogram across one sphere, or against a sphere's cell; a sphere's
/// cell against a parallelogram), the pair
/// converges exponentially and is estimated by order doubling ([`by_order_doubling`], three
/// orders at least). Elsewhere the outer integrand still has kinks where a boundary meets the
/// inner patch's edges, and two Gauss orders can agree there by accident: the error is
/// estimated from the outer patch whole and split 2 × 2 at two orders ([`across_leaf`],
/// module docs). Either way the pair is subdivided further while the estimate exceeds the
/// tolerance.
pub(super) fn across_boundaries<T, SA, SB, O, const CAP: usize>(
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
    // With the outer events placed into the rule the pair converges exponentially in the
    // order, like a smooth pair: orders 2, 4, 6, … compared as such (three at least), the
    // larger patch halved at `max_order`. Order 2 is the start: with many events the pieces
    // are small and the low orders already close (two shadows that meet: ~300 curves, and
    // order 4 within 1e-10), and where they are not, its step only adds a cheap evaluation.
    #[cfg(feature = "closed-form")]
    match crate::pair::occluded_outer(a, b, occluders, false) {
        (true, outer_b) => {
            let eval = |order: usize| {
                crate::pair::PairContext::<T, SA, SB, O, CAP>::new(a, b, occluders)
                    .boundary(order, outer_b, 1, occluders)
            };
            return by_order_doubling::<T, SA, SB, O, CAP>(
                a,
                b,
                settings,
                occluders,
                depth,
                eval,
                2,
                Split::LargerChecked,
            );
        }
        // An occluder touches a and none touches b: b outside (the call with b first keeps it).
        (false, true) => return across_boundaries::<T, SB, SA, O, CAP>(b, a, settings, occluders, depth),
        (false, false) => {}
    }
    let leaf = across_leaf::<T, SA, SB, O, CAP>(a, b, settings, occluders)?;
    if leaf.converged || depth >= settings.max_depth {
        return Ok(leaf);
    }
    or_parent(split::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, leaf.evaluations), leaf)
}
