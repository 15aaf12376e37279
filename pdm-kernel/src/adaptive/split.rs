//! Splitting a pair that has not met its tolerance: halving by arc length, both patches 2 × 2
//! for touching pairs, and the straddle test.

use super::*;

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
pub(super) const SIDE_SEGMENTS: usize = 12;

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
