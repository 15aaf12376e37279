//! Closed patches (a whole disk, cylinder, cone or sphere as one patch) cut at their seams into
//! pieces, every pair of pieces dispatched on its own.

use super::*;
use crate::samples::Ball;
use crate::singular::{adjacency_tolerance, closest_on_line, corner_points};
use crate::surface::ParamRect;
use crate::visibility::Occluder;

/// Calls `f` on every pair of pieces of a and b (see [`pieces`]): the pair methods then see
/// only patches whose four corners are distinct unless an edge collapses to a point. A piece
/// pair is cut further where the pair methods would meet a contact they have no transform for
/// ([`contact_cuts`]): two patches on one map whose parameter rectangles overlap, or a corner
/// of one lying on an edge of the other (a T-junction: a disk's sector against a cylinder
/// wall's cell whose edges span other angles, two cells across a closed surface's seam).
pub(crate) fn for_each_piece_pair<'s, 'r, T, SA, SB, O>(
    a: &Patch<'s, T, SA>,
    b: &Patch<'r, T, SB>,
    occluders: &O,
    mut f: impl FnMut(&Patch<'s, T, SA>, &Patch<'r, T, SB>) -> Result<(), PdmError>,
) -> Result<(), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let ((ma, na), (mb, nb)) = (pieces(a), pieces(b));
    if ma * na * mb * nb == 1 {
        return each_cut_pair(a, b, occluders, &mut f);
    }
    let (ra, rb) = (a.rect(), b.rect());
    for i in 0..ma * na {
        let pa = Patch::new(a.surface(), ra.cell(i / na, i % na, ma, na))?;
        for j in 0..mb * nb {
            let pb = Patch::new(b.surface(), rb.cell(j / nb, j % nb, mb, nb))?;
            each_cut_pair(&pa, &pb, occluders, &mut f)?;
        }
    }
    Ok(())
}

/// Calls `f` on a piece pair, or on the pairs of its cells where [`contact_cuts`] cuts it.
fn each_cut_pair<'s, 'r, T, SA, SB, O>(
    a: &Patch<'s, T, SA>,
    b: &Patch<'r, T, SB>,
    occluders: &O,
    f: &mut impl FnMut(&Patch<'s, T, SA>, &Patch<'r, T, SB>) -> Result<(), PdmError>,
) -> Result<(), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let Some((ca, cb)) = contact_cuts(a, b, occluders) else { return f(a, b) };
    for x in ca.rects() {
        let xa = Patch::new(a.surface(), x)?;
        for y in cb.rects() {
            f(&xa, &Patch::new(b.surface(), y)?)?;
        }
    }
    Ok(())
}

/// How many piece pairs [`for_each_piece_pair`] visits for `a` × `b`.
pub(crate) fn piece_pairs<T, SA, SB, O>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, occluders: &O) -> usize
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let ((ma, na), (mb, nb)) = (pieces(a), pieces(b));
    let (ra, rb) = (a.rect(), b.rect());
    let mut count = 0usize;
    for i in 0..ma * na {
        let Ok(pa) = Patch::new(a.surface(), ra.cell(i / na, i % na, ma, na)) else {
            return ma * na * mb * nb;
        };
        for j in 0..mb * nb {
            let Ok(pb) = Patch::new(b.surface(), rb.cell(j / nb, j % nb, mb, nb)) else {
                return ma * na * mb * nb;
            };
            count += contact_cuts(&pa, &pb, occluders).map_or(1, |(ca, cb)| ca.count() * cb.count());
        }
    }
    count
}

/// Most cuts along one parameter of one patch (two from an overlap, four from corners on
/// edges).
const MAX_CUTS: usize = 6;

/// A cut closer to a bound than this fraction of the parameter range is not made: the sliver
/// it would leave is thinner than the touching transforms are tested for (aspect 1e4), and a
/// contact that near a corner is left to `classify_near`.
const MIN_CUT: f64 = 1e-4;

/// A parameter rectangle cut along each parameter: its bounds in increasing order, `nt` along
/// t and `ns` along s (the ends included).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cuts<T> {
    t: [T; MAX_CUTS + 2],
    nt: usize,
    s: [T; MAX_CUTS + 2],
    ns: usize,
}

impl<T: Real> Cuts<T> {
    fn new(r: ParamRect<T>) -> Self {
        let (mut t, mut s) = ([r.t1; MAX_CUTS + 2], [r.s1; MAX_CUTS + 2]);
        (t[0], s[0]) = (r.t0, r.s0);
        Self { t, nt: 2, s, ns: 2 }
    }

    /// Inserts `x` among the bounds `v[..n]` if it lies inside them, farther than `MIN_CUT` of
    /// the range from every bound, and there is room.
    fn insert(v: &mut [T; MAX_CUTS + 2], n: &mut usize, x: T) {
        let (Some(&lo), Some(&hi)) = (v.first(), v.get(n.saturating_sub(1))) else { return };
        let gap = (hi - lo) * T::from_f64(MIN_CUT);
        if !(x > lo + gap && x < hi - gap) {
            return;
        }
        let k = v.iter().take(*n).position(|&b| b >= x).unwrap_or(*n);
        let near = |i: usize| v.get(i).is_some_and(|&b| (b - x).abs() <= gap);
        if k == 0 || near(k) || near(k - 1) {
            return;
        }
        // v[k..=n] moved up by one (v[n] is a spare copy of the last bound), x into v[k].
        if let Some(tail) = v.get_mut(k..=*n) {
            tail.rotate_right(1);
            if let Some(first) = tail.first_mut() {
                *first = x;
            }
            *n += 1;
        }
    }

    fn cut_t(&mut self, x: T) {
        Self::insert(&mut self.t, &mut self.nt, x);
    }

    fn cut_s(&mut self, x: T) {
        Self::insert(&mut self.s, &mut self.ns, x);
    }

    fn count(&self) -> usize {
        (self.nt - 1) * (self.ns - 1)
    }

    fn rects(self) -> impl Iterator<Item = ParamRect<T>> {
        let m = self.ns - 1;
        (0..self.count()).map(move |k| {
            let (i, j) = (k / m, k % m);
            let at = |v: &[T; MAX_CUTS + 2], i: usize| v.get(i).copied().unwrap_or(T::ZERO);
            ParamRect { t0: at(&self.t, i), t1: at(&self.t, i + 1), s0: at(&self.s, j), s1: at(&self.s, j + 1) }
        })
    }
}

/// `Some` cuts of both patches where the pair methods would otherwise meet a contact that no
/// transform of theirs matches, integrating it as separate with the 1/L² singularity on or
/// inside both patches, which the boundary path can only refine towards, at a cost without
/// bound (a cylinder wall in 3 cells closed by disks in 4 sectors: minutes per pair):
/// - patches on one map (the same points and normals of one direction at the corners and
///   centre of the common parameter rectangle) whose rectangles overlap without being the
///   same: each is cut where the other's bounds fall inside it, so that the common rectangle
///   is one cell of both, an identical pair;
/// - a corner of one patch on an edge of the other, not at its ends: the edge's patch is cut
///   there, so that the contact becomes a shared edge or vertex with matching corners.
///
/// Cutting is exact whatever the geometry (the integral is additive): a cut that was not
/// needed costs only work. `None` where nothing is cut, and for two flat patches with
/// straight edges that no occluder can cut between: the contour form integrates any contact
/// between those exactly (`pair::flat`), and the test would only cost it time.
pub(crate) fn contact_cuts<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    occluders: &O,
) -> Option<(Cuts<T>, Cuts<T>)>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (ra, rb) = (a.rect(), b.rect());
    let (mut ca, mut cb) = (Cuts::new(ra), Cuts::new(rb));
    if same_map_overlap(a, b) {
        for (c, r) in [(&mut ca, rb), (&mut cb, ra)] {
            c.cut_t(r.t0);
            c.cut_t(r.t1);
            c.cut_s(r.s0);
            c.cut_s(r.s1);
        }
    } else {
        let (sa, sb) = (straight(a), straight(b));
        let (ba, bb) = (contact_ball(a, sa), contact_ball(b, sb));
        let reach = (ba.radius + bb.radius) * T::from_f64(1.25);
        if !((ba.center - bb.center).norm() <= reach) {
            return None;
        }
        if sa.is_some() && sb.is_some() && !occluders.may_block_between(&ba, &bb) {
            return None;
        }
        corners_on_edges(a, sa, &corner_points(b), &mut ca);
        corners_on_edges(b, sb, &corner_points(a), &mut cb);
    }
    (ca.count() > 1 || cb.count() > 1).then_some((ca, cb))
}

/// Whether `a` and `b` lie on one map with parameter rectangles that overlap in more than an
/// edge and are not the same (see [`contact_cuts`]).
fn same_map_overlap<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (ra, rb) = (a.rect(), b.rect());
    if ra == rb {
        return false;
    }
    let common = ParamRect { t0: ra.t0.max(rb.t0), t1: ra.t1.min(rb.t1), s0: ra.s0.max(rb.s0), s1: ra.s1.min(rb.s1) };
    if !(common.t0 < common.t1 && common.s0 < common.s1) {
        return false;
    }
    let (ga, gb) = (a.surface(), b.surface());
    let size = (ga.point(common.t0, common.s0) - ga.point(common.t1, common.s1))
        .norm()
        .max((ga.point(common.t1, common.s0) - ga.point(common.t0, common.s1)).norm());
    if !(size > T::ZERO && size.is_finite()) {
        return false;
    }
    let tolerance = size * adjacency_tolerance::<T>();
    let (tm, sm) = ((common.t0 + common.t1) * T::HALF, (common.s0 + common.s1) * T::HALF);
    let at = [(common.t0, common.s0), (common.t1, common.s0), (common.t0, common.s1), (common.t1, common.s1), (tm, sm)];
    at.iter().all(|&(t, s)| (ga.point(t, s) - gb.point(t, s)).norm() <= tolerance)
        && ga.normal(tm, sm).dot(gb.normal(tm, sm)) > T::ZERO
}

/// The corners of a flat patch with straight edges ([`Surface::straight_corners`]); `None`
/// for any other, and without the `closed-form` feature.
fn straight<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> Option<[Vec3<T>; 4]> {
    #[cfg(feature = "closed-form")]
    return p.surface().straight_corners(p.rect());
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = p;
        None
    }
}

/// A ball holding the patch for the contact test of [`contact_cuts`]: from the corners of a
/// flat patch with straight edges (`straight`; exact for a convex polygon), else
/// [`Patch::enclosing_ball`].
fn contact_ball<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>, straight: Option<[Vec3<T>; 4]>) -> Ball<T> {
    let Some(c) = straight else { return p.enclosing_ball() };
    let center = c.iter().fold(Vec3::ZERO, |s, x| s + *x).scale(T::from_f64(0.25));
    let radius = c.iter().fold(T::ZERO, |m, x| m.max((*x - center).norm()));
    Ball { center, radius }
}

/// [`corners_on_edges`] for a flat patch with straight edges (`straight`, its corners in
/// order): each corner's foot on each edge's segment in closed form, the cut where it lies
/// inside the segment within the tolerance and the patch's own point at that parameter (the
/// parameterisation along a straight edge need not be linear) is within it too.
fn corners_on_straight_edges<T, S>(
    p: &Patch<'_, T, S>,
    straight: [Vec3<T>; 4],
    corners: &[Vec3<T>; 4],
    cuts: &mut Cuts<T>,
) where
    T: Real,
    S: Surface<T> + ?Sized,
{
    let (r, g) = (p.rect(), p.surface());
    let [c0, c1, c2, c3] = straight;
    for (along_t, fixed, x0, x1) in
        [(true, r.s0, c0, c1), (true, r.s1, c3, c2), (false, r.t0, c0, c3), (false, r.t1, c1, c2)]
    {
        let e = x1 - x0;
        let l2 = e.dot(e);
        if !(l2 > T::ZERO && l2.is_finite()) {
            continue;
        }
        let tolerance = l2.sqrt() * adjacency_tolerance::<T>();
        let (lo, hi) = if along_t { (r.t0, r.t1) } else { (r.s0, r.s1) };
        for &q in corners {
            let u = (q - x0).dot(e) / l2;
            let inside = u > T::from_f64(MIN_CUT) && u < T::ONE - T::from_f64(MIN_CUT);
            if !inside || !((q - x0 - e.scale(u)).norm() <= tolerance) {
                continue;
            }
            let x = lo + (hi - lo) * u;
            let at = if along_t { g.point(x, fixed) } else { g.point(fixed, x) };
            if (at - q).norm() <= tolerance {
                if along_t {
                    cuts.cut_t(x);
                } else {
                    cuts.cut_s(x);
                }
            }
        }
    }
}

/// Samples along an edge when looking for corners on it.
const EDGE_SAMPLES: usize = 17;

/// Cuts `p` where one of `corners` lies on one of its edges, strictly between the edge's ends
/// (within `adjacency_tolerance` of the edge's length, as `classify` matches corners): in
/// closed form for straight edges (`straight`, [`corners_on_straight_edges`]); else the
/// nearest of `EDGE_SAMPLES` points along the edge, then the nearest point between its
/// neighbours ([`closest_on_line`]). A corner farther from every sample than half the largest
/// sample spacing (plus the tolerance), or at an end of the edge, costs no search.
fn corners_on_edges<T, S>(
    p: &Patch<'_, T, S>,
    straight: Option<[Vec3<T>; 4]>,
    corners: &[Vec3<T>; 4],
    cuts: &mut Cuts<T>,
) where
    T: Real,
    S: Surface<T> + ?Sized,
{
    if let Some(straight) = straight {
        corners_on_straight_edges(p, straight, corners, cuts);
        return;
    }
    let (r, g) = (p.rect(), p.surface());
    // (along t?, the fixed other parameter)
    for (along_t, fixed) in [(true, r.s0), (true, r.s1), (false, r.t0), (false, r.t1)] {
        let (lo, hi) = if along_t { (r.t0, r.t1) } else { (r.s0, r.s1) };
        let at = |u: T| if along_t { g.point(u, fixed) } else { g.point(fixed, u) };
        let param = |k: usize| lo + (hi - lo) * (T::from_usize(k) / T::from_usize(EDGE_SAMPLES - 1));
        let mut samples = [Vec3::ZERO; EDGE_SAMPLES];
        for (k, x) in samples.iter_mut().enumerate() {
            *x = at(param(k));
        }
        let (mut length, mut spacing) = (T::ZERO, T::ZERO);
        for w in samples.windows(2) {
            if let [x, y] = w {
                let d = (*y - *x).norm();
                length += d;
                spacing = spacing.max(d);
            }
        }
        if !(length > T::ZERO && length.is_finite()) {
            continue;
        }
        let tolerance = length * adjacency_tolerance::<T>();
        for &c in corners {
            let Some((k, d)) = samples
                .iter()
                .map(|x| (*x - c).norm())
                .enumerate()
                .min_by(|x, y| x.1.partial_cmp(&y.1).unwrap_or(core::cmp::Ordering::Equal))
            else {
                continue;
            };
            let at_end = k == 0 || k + 1 == EDGE_SAMPLES;
            if !(d <= spacing * T::HALF + tolerance) || (at_end && d <= tolerance) {
                continue;
            }
            let (x0, x1) = (param(k.saturating_sub(1)), param((k + 1).min(EDGE_SAMPLES - 1)));
            let (rho, f) = closest_on_line(c, &|rho: T| at(x0 + (x1 - x0) * rho));
            if f <= tolerance {
                let u = x0 + (x1 - x0) * rho;
                if along_t {
                    cuts.cut_t(u);
                } else {
                    cuts.cut_s(u);
                }
            }
        }
    }
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
