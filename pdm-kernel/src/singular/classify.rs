//! Adjacency from the geometry: which edges or corners two patches share, exactly or nearly,
//! and the gap of a near contact ([`classify()`], [`classify_near`]).

use super::*;

/// How two patches touch, as found by [`classify()`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Adjacency {
    /// No corner in common.
    Separate,
    /// A common edge: local maps of A and B put it at η = 0, traversed the same way.
    SharedEdge {
        /// Map of patch A.
        a: SquareMap,
        /// Map of patch B.
        b: SquareMap,
    },
    /// A single common corner, at local (0, 0) of both.
    SharedVertex {
        /// Map of patch A.
        a: SquareMap,
        /// Map of patch B.
        b: SquareMap,
    },
    /// The same patch twice (or patches overlapping in more than an edge).
    Identical,
}

pub(crate) fn corner_points<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> [Vec3<T>; 4] {
    let r = p.rect();
    let s = p.surface();
    [s.point(r.t0, r.s0), s.point(r.t1, r.s0), s.point(r.t0, r.s1), s.point(r.t1, r.s1)]
}

/// The parameter-space centre of a patch.
pub(super) fn centre_of<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> (T, T) {
    let r = p.rect();
    ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF)
}

/// Relative tolerance for "the same point" in adjacency detection.
pub(crate) fn adjacency_tolerance<T: Real>() -> T {
    T::GEOMETRY_TOLERANCE.sqrt() * T::from_f64(0.01)
}

/// Finds how patches `a` and `b` touch (see the module docs for the tolerance).
#[must_use]
pub fn classify<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> Adjacency
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    contact(a, b, false).0
}

/// Relative gap below which a pair that does not touch is still integrated with the touching
/// transforms (graded towards the gap): 2 % of the shortest edge of the two patches. The
/// transforms are exact changes of variables for any pair; they pay off when the near-singularity
/// sits at the pyramids' apex, i.e. when the matched edge or corner is where the patches come
/// closest — so a near match is also required to be at most half as far apart as any other pair
/// of corners (not e.g. two parallel patches facing each other at a small distance).
pub const NEAR_CONTACT: f64 = 0.02;

/// Like [`classify()`], but corners closer than [`NEAR_CONTACT`] × the shortest edge also count as
/// shared; returns the adjacency and the gap (largest distance between matched points, relative
/// to the patch size — the larger of the two patches' diagonals; 0 up to rounding for patches
/// that truly touch).
///
/// A gap of `T::MAX` (finite, so callers that check the gap see a number) means the contact
/// cannot be resolved in the working precision (the rounding of the coordinates, 16 ε × their
/// magnitude, is not small against the shortest edge × the fold angle: f32 cells far from the
/// origin); [`touching_exchange`] then refuses the pair with `Err(Degenerate)` rather than
/// return a silently wrong value.
#[must_use]
pub fn classify_near<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> (Adjacency, T)
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    // A gap at the level of rounding is no gap: grading for it would only cost time.
    let rounding = T::from_f64(64.0) * T::EPSILON;
    let (exact, exact_gap) = contact(a, b, false);
    if exact != Adjacency::Separate {
        // Touching within the tight tolerance (or the same patch). A gap below the tolerance but
        // above rounding is still graded for.
        let gap = if exact == Adjacency::Identical || !(exact_gap > rounding) { T::ZERO } else { exact_gap };
        return (exact, gap);
    }
    let (adjacency, gap) = contact(a, b, true);
    if adjacency == Adjacency::Identical {
        // Nearly coincident but not the same patch: no transform applies.
        return (Adjacency::Separate, T::ZERO);
    }
    (adjacency, if gap > rounding { gap } else { T::ZERO })
}

/// Largest corner-to-corner distance of a patch.
pub(super) fn diameter<T: Real>(c: &[Vec3<T>; 4]) -> T {
    let mut m = T::ZERO;
    for p in c {
        for q in c {
            m = m.max((*p - *q).norm());
        }
    }
    m
}

/// The four edges of a patch as pairs of corner numbers (corner k ↦ (k & 1, k >> 1)).
pub(super) const EDGES: [(usize, usize); 4] = [(0, 1), (2, 3), (0, 2), (1, 3)];

/// Shortest edge of a patch longer than `collapsed` (a sphere's polar cell has an edge of length
/// 0); `T::MAX` if there is none.
pub(super) fn shortest_edge<T: Real>(c: &[Vec3<T>; 4], collapsed: T) -> T {
    let mut m = T::MAX;
    for (i, j) in EDGES {
        if let (Some(p), Some(q)) = (c.get(i), c.get(j)) {
            let l = (*p - *q).norm();
            if l > collapsed {
                m = m.min(l);
            }
        }
    }
    m
}

/// Fraction of the shortest edge (times the fold parameter, for a nearly folded edge pair) that
/// the rounding band of the coordinates (16 ε × their magnitude) may reach before a contact is
/// refused as unresolvable (see [`classify_near`]). A pair folded to θ moves by ≈ θ × its size
/// when θ changes by 100 %, so rounding must be small against θ × size, not just the size.
///
/// Measured (f32 against f64, touching flat pairs, 1°…163°, aspect up to 1 : 556, coordinates
/// 1…100 sizes from the origin): the relative error is ≈ 0.01…0.075 × q, q = band / (shortest
/// edge × min(1, fold)), at every angle and aspect — the rounding of the corners moves the
/// shared edge by ε × magnitude. At 1/1024 the error of an accepted f32 pair is ≤ ≈ 7e-5
/// (< 1e-4); f32 pairs at 90° are accepted up to coordinates ≈ 500 shortest edges, at 1° up to
/// ≈ 9 (f64: 4e12 and 7e10).
pub(super) const RESOLUTION: f64 = 1.0 / 1024.0;

/// Adjacency at the tight tolerance (`near` = false: [`adjacency_tolerance`] × patch size) or the
/// near-contact one, and the relative gap of the matched points (`T::MAX`: unresolvable).
///
/// Matching is one to one and picks the single best candidate: the edge of A and edge of B
/// (either direction) whose end points are closest (the larger of the two distances), else the
/// closest pair of corners. Far corners that also come close (thin strips, a pair folded to a
/// small angle) cannot add matches. `Identical` needs all four corners matched one to one, the
/// centres to coincide and the normals there to point the same way (a pair folded flat onto
/// itself has opposite normals).
pub(super) fn contact<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, near: bool) -> (Adjacency, T)
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let ca = corner_points(a);
    let cb = corner_points(b);
    let magnitude = ca.iter().chain(cb.iter()).fold(T::ZERO, |m, p| m.max(p.max_abs()));
    let band = T::from_f64(16.0) * T::EPSILON * magnitude;
    let scale = diameter(&ca).max(diameter(&cb));
    let tight = adjacency_tolerance::<T>() * scale + band;
    let shortest = shortest_edge(&ca, tight).min(shortest_edge(&cb, tight));
    let tol = if near {
        if shortest < T::MAX {
            T::from_f64(NEAR_CONTACT) * shortest + band
        } else {
            band
        }
    } else {
        tight
    };
    let dist = |i: usize, j: usize| match (ca.get(i), cb.get(j)) {
        (Some(p), Some(q)) => (*p - *q).norm(),
        _ => T::MAX,
    };
    // A distance within the rounding band of the coordinates is no gap: grading the transform
    // towards it would place nodes where e = p_b − p_a is rounding noise (f64 cells 7e4 cell
    // sizes from the origin were 1e-8…1e-7 off that way).
    let gap_of = |p: Vec3<T>, q: Vec3<T>| {
        let d = (p - q).norm();
        if scale > T::ZERO && d > band {
            d / scale
        } else {
            T::ZERO
        }
    };
    // The geometry is resolved when the rounding band is small against every edge (times the
    // fold parameter for an edge pair); otherwise a contact found is reported with the gap `T::MAX`
    // (refused by touching_exchange).
    // Each patch as a whole must be resolved too: edges below the tight tolerance are skipped
    // as collapsed (a pole), so a patch smaller than the rounding of its coordinates (a tiny
    // sphere far from the origin) would otherwise pass on the other patch's edges alone and send
    // rounding noise through the graded transforms.
    let smallest_patch = diameter(&ca).min(diameter(&cb));
    // A near contact whose geometry is resolved but whose fold parameter is not (two parallel
    // patches facing each other across a small gap, edge above edge: nearly coincident rather
    // than nearly folded) is no contact the transforms can use: it is reported as separate, and
    // the separate paths integrate it.
    let flag = |adjacency: Adjacency, gap: T, sensitivity: T| {
        let resolution = T::from_f64(RESOLUTION);
        let geometry = shortest < T::MAX && band <= resolution * shortest && band <= resolution * smallest_patch;
        if geometry && band <= resolution * shortest * sensitivity.min(T::ONE) {
            (adjacency, gap)
        } else if geometry && near {
            (Adjacency::Separate, T::ZERO)
        } else {
            (adjacency, T::MAX)
        }
    };

    // Identical: a one-to-one match of all four corners, coinciding centres and normals.
    let mut used = [false; 4];
    let mut count = 0;
    for i in 0..4 {
        for j in 0..4 {
            let free = used.get(j).is_some_and(|u| !*u);
            if free && dist(i, j) <= tol {
                if let Some(u) = used.get_mut(j) {
                    *u = true;
                    count += 1;
                }
                break;
            }
        }
    }
    if count == 4 {
        let (ta, sa) = centre_of(a);
        let (tb, sb) = centre_of(b);
        let (pa, na) = a.surface().point_and_normal(ta, sa);
        let (pb, nb) = b.surface().point_and_normal(tb, sb);
        if (pa - pb).norm() <= tol && na.dot(nb) > T::ZERO {
            return (Adjacency::Identical, T::ZERO);
        }
    }

    // Best edge: A's edge (i1, i2) against B's edge (j1, j2) in either direction.
    let mut best: Option<(T, usize, usize, usize, usize)> = None;
    for (i1, i2) in EDGES {
        if dist_within(&ca, i1, i2) <= tight {
            continue; // a collapsed edge
        }
        for (k1, k2) in EDGES {
            if dist_within(&cb, k1, k2) <= tight {
                continue;
            }
            for (j1, j2) in [(k1, k2), (k2, k1)] {
                let cost = dist(i1, j1).max(dist(i2, j2));
                if best.is_none_or(|(c, ..)| cost < c) {
                    best = Some((cost, i1, i2, j1, j2));
                }
            }
        }
    }
    // In near contact the match must be clearly where the patches come closest: the nearest
    // other pair of corners at least twice as far apart.
    let clearly_closest = |gap_abs: T, skip: &[(usize, usize)]| {
        if !near {
            return true;
        }
        let mut other = T::MAX;
        for i in 0..4 {
            for j in 0..4 {
                if !skip.contains(&(i, j)) {
                    other = other.min(dist(i, j));
                }
            }
        }
        gap_abs * T::TWO <= other
    };
    if let Some((cost, i1, i2, j1, j2)) = best {
        if cost <= tol {
            if !clearly_closest(cost, &[(i1, j1), (i2, j2)]) {
                return (Adjacency::Separate, T::ZERO);
            }
            return match (SquareMap::from_corners(i1, i2), SquareMap::from_corners(j1, j2)) {
                (Some(ma), Some(mb)) => {
                    let la = Local { patch: a, map: ma };
                    let lb = Local { patch: b, map: mb };
                    let mut gap = T::ZERO;
                    let mut agree = true;
                    for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
                        let f = T::from_f64(f);
                        let (p, q) = (la.eval(f, T::ZERO).0, lb.eval(f, T::ZERO).0);
                        agree = agree && (p - q).norm() <= tol;
                        gap = gap.max(gap_of(p, q));
                    }
                    if agree {
                        flag(Adjacency::SharedEdge { a: ma, b: mb }, gap, fold_angle(&la, &lb))
                    } else {
                        // Two corners in common but the edge parameterised differently (or
                        // not one edge of both): the transform does not apply.
                        (Adjacency::Separate, T::ZERO)
                    }
                }
                _ => (Adjacency::Separate, T::ZERO),
            };
        }
    }

    // Best vertex.
    let mut best: Option<(T, usize, usize)> = None;
    for i in 0..4 {
        for j in 0..4 {
            let d = dist(i, j);
            if best.is_none_or(|(c, ..)| d < c) {
                best = Some((d, i, j));
            }
        }
    }
    match best {
        Some((d, i, j)) if d <= tol && clearly_closest(d, &[(i, j)]) => {
            if facing_tangency(a, i, b, j, tight) {
                return (Adjacency::Separate, T::ZERO);
            }
            let gap = match (ca.get(i), cb.get(j)) {
                (Some(p), Some(q)) => gap_of(*p, *q),
                _ => T::ZERO,
            };
            // Any local orientation with (0,0) at the shared corner.
            match (SquareMap::from_corners(i, i ^ 1), SquareMap::from_corners(j, j ^ 1)) {
                (Some(ma), Some(mb)) => flag(Adjacency::SharedVertex { a: ma, b: mb }, gap, T::ONE),
                _ => (Adjacency::Separate, T::ZERO),
            }
        }
        _ => (Adjacency::Separate, T::ZERO),
    }
}

/// Whether the patches meet at their corners `i` (of a) and `j` (of b) as two surfaces that
/// touch face to face: each has one tangent plane there ([`tangent_normal`]) and the two
/// normals point at each other (a sphere resting on a disk, its pole on the disk's centre).
/// The vertex transforms assume the patches leave the common point at an angle; across a
/// tangency they were 18 % off at order 12 (sphere on disk, exact contact and gaps down to
/// 1e-13) and grew with the gap's grading. Such a pair is separate: the boundary path grades its
/// outer patch towards the contact (`boundary::very_near`).
fn facing_tangency<T, SA, SB>(a: &Patch<'_, T, SA>, i: usize, b: &Patch<'_, T, SB>, j: usize, tight: T) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    match (tangent_normal(a, i, tight), tangent_normal(b, j, tight)) {
        (Some(na), Some(nb)) => na.dot(nb) < -(T::ONE - T::from_f64(TANGENT_SPREAD)),
        _ => false,
    }
}

/// How far (1 − cos) unit normals may differ to count as one tangent plane
/// ([`tangent_normal`]) and as pointing at each other ([`facing_tangency`]): about 0.06°.
/// Around a sphere's pole sampled 1e-4 of the patch inside they differ by 2e-7; around a
/// cone's apex by the cone's opening; two flat patches folded to 1° at a common corner by
/// 1.5e-4 (those leave the corner at an angle, and the vertex transforms hold).
const TANGENT_SPREAD: f64 = 5e-7;

/// The unit normal of the patch's tangent plane at corner `k` (corner k ↦ (k & 1, k >> 1)),
/// if it has one: the unit normals at 1e-4 of the patch inside from the corner, along both
/// sides through it (or, where one of them collapses to the corner, a pole or a disk's
/// centre, all along the collapsed side) agree to [`TANGENT_SPREAD`]. `None` at a cone's apex
/// or where a normal vanishes.
fn tangent_normal<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>, k: usize, tight: T) -> Option<Vec3<T>> {
    let r = p.rect();
    let g = p.surface();
    let (tc, to) = if k & 1 == 0 { (r.t0, r.t1) } else { (r.t1, r.t0) };
    let (sc, so) = if (k >> 1) & 1 == 0 { (r.s0, r.s1) } else { (r.s1, r.s0) };
    let corner = g.point(tc, sc);
    let along_t = (g.point(to, sc) - corner).norm() <= tight;
    let along_s = (g.point(tc, so) - corner).norm() <= tight;
    let inset = T::from_f64(1e-4);
    let at = |u: T, v: T| -> Option<Vec3<T>> {
        let n = g.normal(tc + (to - tc) * u, sc + (so - sc) * v);
        let length = n.norm();
        (length > T::ZERO && length.is_finite()).then(|| n.scale(T::ONE / length))
    };
    let quarter = T::from_f64(0.25);
    let (samples, count): ([(T, T); 5], usize) = match (along_t, along_s) {
        (false, false) => {
            ([(inset, inset), (inset, T::ZERO), (T::ZERO, inset), (T::ZERO, T::ZERO), (T::ZERO, T::ZERO)], 3)
        }
        // The side along t collapses: the normals along it, just inside in s.
        (true, false) => ([T::ZERO, quarter, T::HALF, T::HALF + quarter, T::ONE].map(|u| (u, inset)), 5),
        (false, true) => ([T::ZERO, quarter, T::HALF, T::HALF + quarter, T::ONE].map(|v| (inset, v)), 5),
        (true, true) => return None,
    };
    let first = at(samples[0].0, samples[0].1)?;
    let limit = T::ONE - T::from_f64(TANGENT_SPREAD);
    for &(u, v) in samples.iter().take(count).skip(1) {
        if !(at(u, v)?.dot(first) >= limit) {
            return None;
        }
    }
    Some(first)
}

/// Distance between corners `i` and `j` of one patch.
pub(super) fn dist_within<T: Real>(c: &[Vec3<T>; 4], i: usize, j: usize) -> T {
    match (c.get(i), c.get(j)) {
        (Some(p), Some(q)) => (*p - *q).norm(),
        _ => T::ZERO,
    }
}
