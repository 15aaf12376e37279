//! Closed patches (a whole disk, cylinder, cone or sphere as one patch) cut at their seams into
//! pieces, every pair of pieces dispatched on its own.

use super::*;

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
    if piece_pairs(a, b) == 1 {
        return f(a, b);
    }
    let ((ma, na), (mb, nb)) = (pieces(a), pieces(b));
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

/// How many piece pairs [`for_each_piece_pair`] visits for `a` × `b`.
pub(crate) fn piece_pairs<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> usize
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let ((ma, na), (mb, nb)) = (pieces(a), pieces(b));
    ma * na * mb * nb
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
    // A flat patch with straight edges cannot close on itself.
    #[cfg(feature = "closed-form")]
    if g.straight_corners(r).is_some() {
        return (1, 1);
    }
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
