//! Splitting a pair that has not met its tolerance: halving by arc length, both patches 2 × 2
//! for touching pairs.

use super::*;
use crate::patch::{half_patch, side_lengths};

/// The children of a subdivision, or — where the working precision cannot carry it out (cells
/// below the geometry's resolution: `Err(Degenerate)` or `Err(Unresolvable)` from a child) —
/// the parent's value with its estimate, `converged = false`: that estimate was computed
/// before the split and was above the tolerance, which is what the result then says.
pub(super) fn or_parent<T: Real>(children: Result<Tally<T>, PdmError>, parent: Tally<T>) -> Result<Tally<T>, PdmError> {
    match children {
        Err(PdmError::Degenerate | PdmError::Unresolvable) => Ok(Tally { converged: false, ..parent }),
        other => other,
    }
}

/// Splits both patches 2 × 2 at their parameter midpoints and recurses on the 16 sub-pairs;
/// `spent` evaluations are carried into the total (touching pairs stay edge- or vertex-adjacent when both maps divide the shared edge in
/// proportion, as the built-in surfaces' grids do).
pub(super) fn split_both<T, SA, SB, O, const CAP: usize>(
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
    let settings = settings.share(16);
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
pub(super) fn split<T, SA, SB, O, const CAP: usize>(
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
    let settings = settings.share(2);
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

/// An algebraic leaf of a self pair (`leaf`) that has not met its tolerance, where an occluder
/// may cut the pair: both copies split 2 × 2 and the 16 sub-pairs routed anew, as a touching
/// pair an occluder may cut. The shadow then falls on separate and touching sub-pairs, whose
/// routes place it, and the sub-pairs along the diagonal shrink until none can be cut (a
/// quarter of a sphere's inside from the pole to the equator, a concentric sphere inside:
/// 9.4e-5 off as one leaf, 6e-13 split). Elsewhere, or at `max_depth`, the leaf stands.
pub(super) fn split_where_cut<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    leaf: Tally<T>,
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
    if leaf.converged
        || depth >= settings.max_depth
        || !occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball())
    {
        return Ok(leaf);
    }
    or_parent(split_both::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, leaf.evaluations), leaf)
}
