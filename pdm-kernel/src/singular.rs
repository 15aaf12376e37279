//! Patches that touch: exact treatment of the shared-edge and shared-vertex singularities.
//!
//! When two patches share an edge, the integrand of eq. (15) grows like 1/L² near the edge and
//! a tensor Gauss rule converges only algebraically (two perpendicular unit squares are still
//! 20 % off at 16 points per axis). The paper's remedy (section 4.2, L'Hôpital at sample points
//! that nearly coincide) is a heuristic that leaves its face sums 1.3–2.6 % off. Here the
//! singularity is removed by the regularising transforms of Sauter & Schwab (*Boundary Element
//! Methods*, 2010, §5.2; after Duffy 1982):
//!
//! **Shared edge.** Both patches are mapped to the unit square so that the common edge is η = 0
//! and is traversed in the same direction: A(ξ, 0) = B(ξ, 0). With u = ξ_B − ξ_A the ξ-range
//! for fixed u has length 1 − |u| and is mapped to σ ∈ [0, 1]; the cube of (|u|, η_A, η_B) is
//! split into three pyramids by its largest coordinate, (|u|, η_A, η_B) = ζ(1, a, b),
//! ζ(a, 1, b), ζ(a, b, 1), Jacobian ζ². Two signs of u × three pyramids give six 4-D integrals
//! over (σ, ζ, a, b) ∈ [0, 1]⁴ whose integrands are analytic (the ζ² cancels the 1/L²), so a
//! tensor Gauss rule converges exponentially: machine precision for perpendicular unit squares
//! by order ≈ 12.
//!
//! **Any aspect ratio.** The variables are scaled by the physical side lengths (edge length L,
//! widths w_a, w_b; at a vertex the four sides) over the shortest side r₀, so the box of scaled
//! variables is [0, L/r₀] × [0, w_a/r₀] × [0, w_b/r₀]: the cube [0, 1]³ near the edge is
//! physically a cube and gets the pyramids above; the rest of each pyramid (the box cuts it
//! where ζ exceeds another side's extent; the ratios then run to min(1, extent/ζ)) is covered by
//! shells ζ ∈ [1, 4], [4, 16], … with breaks at the other extents. This is the cut of a long
//! pair into near-square sub-pairs done inside the transform, allocation-free, at O(log aspect)
//! extra shells.
//!
//! **Nearly folded pairs.** When the dihedral angle θ between the two patches is small (their
//! normals at the edge nearly opposite), the kernel inside two of the pyramids peaks along the
//! line where the other patch comes closest (equal scaled distances from the edge; 1 − g/ζ with a
//! gap g; the far side of the narrower patch beyond its width) with width ≈ θ. Per ζ node that
//! closest point is found on the other patch's coordinate line (golden section) and the ratio
//! variables are split geometrically around it and towards u = 0 (widths: closest distance /
//! line length), and ζ is also split upwards from the narrower side's extent and from the gap:
//! exponential convergence down to θ ≈ 1°, with or without a gap. Vertex
//! pairs do the same when one patch's edge from the vertex comes close to one of the other's
//! (cells along a nearly folded edge).
//!
//! **Shared vertex.** Both patches are mapped so that the common corner is (0, 0); the 4-cube is
//! split into four pyramids by its largest coordinate, Jacobian ζ³ (the singularity is 1/ζ²).
//!
//! **The same patch twice.** On a smooth patch the kernel stays bounded on the diagonal x = y
//! (n_x·e and −n_y·e both grow like L², cancelling the L⁴), but its limit depends on the
//! direction of approach, so a tensor rule on the two copies converges only algebraically
//! (≈ p^−1.3 on a tube's inside). With the offset z = y − x the x-range for fixed z is a box of
//! sides 1 − |z_i| (mapped to [0, 1]²); the two quadrants of z (the other two are their mirror
//! images, equal by the kernel's symmetry) are scaled by the physical side lengths and split
//! into two triangles by the larger coordinate, z = ζ(1, ρ) or ζ(ρ, 1), Jacobian ζ: the
//! direction becomes the variable ρ and the integrand is analytic in (ζ, ρ, σ₁, σ₂) — a thin
//! tube wall's self pair, 1.6e-2 off at order 12 by the plain self rule, is 2.2e-8 off (and
//! 2e-10 at order 16). Long patches get ζ-shells beyond the shorter side as above.
//!
//! **A side collapsed to a point.** A cone's apex, a disk's centre or a sphere's pole is a whole
//! side of the patches that meet there (the parameterisation collapses). Two patches touching
//! only at such a vertex are singular where both their radial variables vanish, for every value
//! of the variables along the collapsed sides: the pyramids then run over the radial variables
//! only (ζ^(k−1) for k of them) and the variables along the collapsed sides get the plain rule
//! (`collapsed_vertex_sum`): the opposite quarters of a cone's inside, once 5e-2 apart from
//! order 8 to 24, agree to 1e-10 at order 12. Self and edge pairs that reach the collapsed side
//! keep their transforms, which assume a regular map there and converge only algebraically
//! near it (a cone's inside against itself: 2.0e-5 at order 12, 6.6e-6 at 16).
//!
//! **Nearly touching** pairs (an edge or corner closer than the patch size but not shared) are
//! handled by the same transforms with the ζ-interval split geometrically down to the gap, so the
//! near-singular peak is resolved (error bounded independently of the gap). A near edge whose
//! gap tapers along it (the edges nearly meet at one end and diverge at a small angle: cells
//! side by side across a small fold) peaks at ζ ≈ the local gap: ζ is split from the narrow
//! end's gap and the variable along the edge is graded towards that end (`Taper`).
//!
//! Adjacency is detected from the geometry ([`classify`], [`classify_near`]): one to one, the
//! single best match — the edge of A and edge of B (either direction) whose end points are
//! closest, else the closest pair of corners — within `ADJACENCY_TOLERANCE × patch size +
//! 16 ε × coordinate magnitude` (exact contact) or [`NEAR_CONTACT`] × the shortest edge (near
//! contact; then also clearly the closest pair); an edge is shared when its quarter, mid and
//! three-quarter points coincide too (so the two parameterisations agree along it, as the
//! transform requires). `Identical` needs all four corners, the centres and the normals there to
//! agree. A contact the working precision cannot resolve (the rounding band not small against
//! the shortest edge × the fold angle) is refused with `Err(Degenerate)`; a near contact whose
//! only unresolved part is the fold angle (parallel patches facing each other across a small gap,
//! edge above edge) is nearly coincident, not nearly folded, and is reported as `Separate`.

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::integrand::kernel_occluded;
use crate::patch::Patch;
use crate::real::Real;
use crate::surface::Surface;
use crate::vec3::Vec3;
use crate::visibility::Occluder;

/// One of the eight symmetries of the unit square, taking local coordinates (ξ, η) to patch
/// coordinates (x, y) ∈ [0, 1]²: optionally swap, then optionally mirror each axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SquareMap {
    swap: bool,
    flip_x: bool,
    flip_y: bool,
}

impl SquareMap {
    /// The identity.
    pub const IDENTITY: Self = Self { swap: false, flip_x: false, flip_y: false };

    #[inline(always)]
    fn apply<T: Real>(self, xi: T, eta: T) -> (T, T) {
        let (mut x, mut y) = if self.swap { (eta, xi) } else { (xi, eta) };
        if self.flip_x {
            x = T::ONE - x;
        }
        if self.flip_y {
            y = T::ONE - y;
        }
        (x, y)
    }

    /// The map sending local (0,0) to corner `origin` and local (1,0) to corner `along`
    /// (corners numbered k ↦ (k & 1, k >> 1)); `None` if they are not adjacent corners.
    fn from_corners(origin: usize, along: usize) -> Option<Self> {
        let corner = |k: usize| ((k & 1) as u8, ((k >> 1) & 1) as u8);
        for bits in 0..8u8 {
            let m = Self { swap: bits & 1 != 0, flip_x: bits & 2 != 0, flip_y: bits & 4 != 0 };
            let o = m.apply::<f64>(0.0, 0.0);
            let a = m.apply::<f64>(1.0, 0.0);
            let o = (o.0 as u8, o.1 as u8);
            let a = (a.0 as u8, a.1 as u8);
            if o == corner(origin) && a == corner(along) {
                return Some(m);
            }
        }
        None
    }
}

/// How two patches touch, as found by [`classify`].
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

/// A patch seen through a [`SquareMap`] on the unit square.
struct Local<'p, 's, T, S: ?Sized> {
    patch: &'p Patch<'s, T, S>,
    map: SquareMap,
}

impl<T: Real, S: Surface<T> + ?Sized> Local<'_, '_, T, S> {
    /// Point and normal×(parameter Jacobian) at local (ξ, η).
    #[inline(always)]
    fn eval(&self, xi: T, eta: T) -> (Vec3<T>, Vec3<T>) {
        let (x, y) = self.map.apply(xi, eta);
        let r = self.patch.rect();
        let (dt, ds) = (r.t1 - r.t0, r.s1 - r.s0);
        let (p, n) = self.patch.surface().point_and_normal(r.t0 + x * dt, r.s0 + y * ds);
        (p, n.scale(dt * ds))
    }
}

fn corner_points<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> [Vec3<T>; 4] {
    let r = p.rect();
    let s = p.surface();
    [s.point(r.t0, r.s0), s.point(r.t1, r.s0), s.point(r.t0, r.s1), s.point(r.t1, r.s1)]
}

/// The parameter-space centre of a patch.
fn centre_of<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> (T, T) {
    let r = p.rect();
    ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF)
}

/// Relative tolerance for "the same point" in adjacency detection.
fn adjacency_tolerance<T: Real>() -> T {
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

/// Like [`classify`], but corners closer than [`NEAR_CONTACT`] × the shortest edge also count as
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
fn diameter<T: Real>(c: &[Vec3<T>; 4]) -> T {
    let mut m = T::ZERO;
    for p in c {
        for q in c {
            m = m.max((*p - *q).norm());
        }
    }
    m
}

/// The four edges of a patch as pairs of corner numbers (corner k ↦ (k & 1, k >> 1)).
const EDGES: [(usize, usize); 4] = [(0, 1), (2, 3), (0, 2), (1, 3)];

/// Shortest edge of a patch longer than `collapsed` (a sphere's polar cell has an edge of length
/// 0); `T::MAX` if there is none.
fn shortest_edge<T: Real>(c: &[Vec3<T>; 4], collapsed: T) -> T {
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
const RESOLUTION: f64 = 1.0 / 1024.0;

/// Adjacency at the tight tolerance (`near` = false: [`adjacency_tolerance`] × patch size) or the
/// near-contact one, and the relative gap of the matched points (`T::MAX`: unresolvable).
///
/// Matching is one to one and picks the single best candidate: the edge of A and edge of B
/// (either direction) whose end points are closest (the larger of the two distances), else the
/// closest pair of corners. Far corners that also come close (thin strips, a pair folded to a
/// small angle) cannot add matches. `Identical` needs all four corners matched one to one, the
/// centres to coincide and the normals there to point the same way (a pair folded flat onto
/// itself has opposite normals).
fn contact<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, near: bool) -> (Adjacency, T)
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

/// Distance between corners `i` and `j` of one patch.
fn dist_within<T: Real>(c: &[Vec3<T>; 4], i: usize, j: usize) -> T {
    match (c.get(i), c.get(j)) {
        (Some(p), Some(q)) => (*p - *q).norm(),
        _ => T::ZERO,
    }
}

/// Gauss rule mapped to [0, 1]: (node, weight) with weights summing to 1.
#[inline(always)]
fn unit_points<T: Real>(rule: &GaussRule<T>) -> impl Iterator<Item = (T, T)> + '_ {
    rule.points().map(|(x, w)| ((x + T::ONE) * T::HALF, w * T::HALF))
}

/// The exchange A_a·F_{a→b} (symmetric) of two patches that share an edge or a vertex, by the
/// transforms in the module docs with the `order`-point rule on each of the four variables.
/// `gap` is the relative gap from [`classify_near`] (0 for patches that truly touch): for a
/// positive gap the radial variable ζ is split geometrically at gap·4ᵏ so the near-singular
/// peak is resolved. A gap of `T::MAX` (contact not resolvable in the working precision, see
/// [`classify_near`]) is refused with `Err(Degenerate)`.
/// `Separate` pairs are refused (`Err(Degenerate)`) — use the plain sum for them; `Identical`
/// pairs too (a patch's own F_ii: [`crate::pair_exchange`] with the patch twice). The result is checked
/// against the physical bounds 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b) (areas at `order`):
/// `Err(InvalidResult)` outside them (a caller-supplied adjacency that does not match the
/// geometry), clamped within rounding.
///
/// Patches of any aspect ratio: the variables are scaled by the physical lengths of the sides
/// (edge length and the two widths; the four sides at a vertex) so that the cube split into
/// pyramids is physically a cube of the shortest side, and the rest of each pyramid is covered
/// by shells ζ ∈ [1, 4], [4, 16], … (see `edge_sum`).
///
/// Cost: 6·order⁴ (edge) or 4·order⁴ (vertex) integrand evaluations for near-square patches
/// that truly touch, times the number of ζ-shells (≈ log₄ of the aspect ratio and of 1/gap);
/// each evaluates both surfaces (no precomputation is possible: the sample points depend on all
/// four variables).
pub fn touching_exchange<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    adjacency: Adjacency,
    gap: T,
    order: usize,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let value = touching_unchecked(a, b, adjacency, gap, order, occluders)?;
    // 0 ≤ A_a·F_ab ≤ min(A_a, A_b) (`Err(InvalidResult)` otherwise, rounding clamped).
    let order = order.max(2);
    crate::bounds::exchange(value, a.area(order)?, b.area(order)?)
}

/// [`touching_exchange`] without the bounds check (finite only; see `bounds::finite`).
pub(crate) fn touching_unchecked<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    adjacency: Adjacency,
    gap: T,
    order: usize,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule = GaussRule::<T>::new(order)?;
    if gap >= T::MAX {
        return Err(PdmError::Degenerate);
    }
    // Every sample pair would test the occluders: skip them when none can cut the pair.
    let occluded = occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball());
    // A gap at the level of rounding is no gap (and a subnormal one would make hundreds of
    // graded intervals).
    let gap = if gap > T::from_f64(64.0) * T::EPSILON && gap.is_finite() { gap } else { T::ZERO };
    let scale = diameter(&corner_points(a)).max(diameter(&corner_points(b)));
    let sum = match adjacency {
        Adjacency::SharedEdge { a: ma, b: mb } => {
            let (la, lb) = (Local { patch: a, map: ma }, Local { patch: b, map: mb });
            let fold = fold_angle(&la, &lb);
            let half = T::HALF;
            let lengths = [
                line_length(&la, (T::ZERO, T::ZERO), (T::ONE, T::ZERO)),
                line_length(&la, (half, T::ZERO), (half, T::ONE)),
                line_length(&lb, (half, T::ZERO), (half, T::ONE)),
            ];
            let (ext, r0) = extents(lengths);
            let g = if r0 > T::ZERO { gap * scale / r0 } else { gap };
            let taper = if g > T::ZERO { Taper::of(&la, &lb, r0) } else { None };
            // A tapered gap grades ζ from its narrow end.
            let g = taper.map_or(g, |t| t.narrow);
            if occluded {
                edge_sum(&la, &lb, &rule, occluders, ext, at(&lengths, 0), g, fold, taper)
            } else {
                edge_sum(&la, &lb, &rule, &(), ext, at(&lengths, 0), g, fold, taper)
            }
        }
        Adjacency::SharedVertex { a: ma, b: mb } => {
            let (la, lb) = (Local { patch: a, map: ma }, Local { patch: b, map: mb });
            let (o, x, y) = ((T::ZERO, T::ZERO), (T::ONE, T::ZERO), (T::ZERO, T::ONE));
            let lengths =
                [line_length(&la, o, x), line_length(&la, o, y), line_length(&lb, o, x), line_length(&lb, o, y)];
            // A side through the vertex that collapses to it (a cone's apex): every point of
            // that side is the vertex, so the variable along it is not singular.
            let collapsed = collapsed_among(lengths);
            if collapsed.iter().any(|c| *c) {
                // The singular variables are the others: extents from their lengths only.
                let r0 = lengths.iter().zip(&collapsed).filter(|(_, c)| !**c).fold(T::MAX, |m, (l, _)| m.min(*l));
                let max = T::from_f64(MAX_EXTENT);
                let ext = lengths.map(|l| if r0 > T::ZERO { (l / r0).max(T::ONE).min(max) } else { T::ONE });
                let g = if r0 > T::ZERO && r0 < T::MAX { gap * scale / r0 } else { gap };
                let singular = collapsed.map(|c| !c);
                if occluded {
                    collapsed_vertex_sum(&la, &lb, &rule, occluders, ext, singular, g)
                } else {
                    collapsed_vertex_sum(&la, &lb, &rule, &(), ext, singular, g)
                }
            } else {
                let (ext, r0) = extents(lengths);
                let g = if r0 > T::ZERO { gap * scale / r0 } else { gap };
                if occluded {
                    vertex_sum(&la, &lb, &rule, occluders, ext, g)
                } else {
                    vertex_sum(&la, &lb, &rule, &(), ext, g)
                }
            }
        }
        Adjacency::Separate | Adjacency::Identical => return Err(PdmError::Degenerate),
    };
    crate::bounds::finite(sum * T::FRAC_1_PI)
}

/// A_a·F_{a→a} of a patch with itself by the identical-panel transform (module docs,
/// "The same patch twice"), with the `order`-point rule on each of the four variables, and the
/// number of integrand evaluations. Finite only, no bounds check (the pair entry points check
/// their totals).
///
/// The kernel of a smooth concave patch is bounded on the diagonal (n·e and −n'·e both grow
/// like L², so the L⁴ cancels) but its limit there depends on the direction of approach; the
/// transform makes that direction a variable of its own, so a tensor Gauss rule converges
/// exponentially where the plain self rule ([`crate::self_form_factor`]) converges only
/// algebraically. Flat and convex patches give zero. Cost: 4·order⁴ evaluations for a
/// near-square patch, times the ζ-shells (≈ log₄ of the aspect ratio).
pub(crate) fn identical_unchecked<T, S, O>(
    patch: &Patch<'_, T, S>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule = GaussRule::<T>::new(order)?;
    let local = Local { patch, map: SquareMap::IDENTITY };
    let half = T::HALF;
    let lengths =
        [line_length(&local, (T::ZERO, half), (T::ONE, half)), line_length(&local, (half, T::ZERO), (half, T::ONE))];
    let (ext, _) = extents(lengths);
    let ball = patch.enclosing_ball();
    let (sum, count) = if occluders.may_block_between(&ball, &ball) {
        identical_sum(&local, &rule, occluders, ext)
    } else {
        identical_sum(&local, &rule, &(), ext)
    };
    Ok((crate::bounds::finite(sum * T::FRAC_1_PI)?, count))
}

/// The four-variable sum of [`identical_unchecked`] (without the 1/π), and its evaluations.
///
/// With z = y − x the offset between the two points (local coordinates), the integral over
/// x, y ∈ [0, 1]² becomes one over z ∈ [−1, 1]² of the integral over the x-box of side lengths
/// 1 − |z_i| (mapped to σ ∈ [0, 1]²). The kernel is symmetric in x and y, so the quadrants
/// z ↦ −z are equal: two quadrants (sign of z₂ relative to z₁), counted twice. Each quadrant,
/// scaled by the physical side lengths (Z = |z|·ext), is split into two triangles by its larger
/// coordinate: Z_k = ζ, Z_o = ζ·m·ρ with m = min(1, ext_o/ζ), Jacobian ζ·m, and ζ ∈ [0, ext_k]
/// in shells [0, 1], [1, 4], … with a break at ext_o (`for_each_shell`), as in the touching
/// transforms.
fn identical_sum<T, S, O>(l: &Local<'_, '_, T, S>, rule: &GaussRule<T>, occ: &O, ext: [T; 2]) -> (T, u64)
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    let mut count = 0u64;
    let q2 = (rule.order() * rule.order()) as u64;
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1);
    for mirrored in [false, true] {
        for k in 0..2 {
            let o = 1 - k;
            let (ek, eo) = (at(&ext, k), at(&ext, o));
            for_each_shell(T::ZERO, ek, &[eo], |z0, z1| {
                let dz = z1 - z0;
                for (zu, wz) in unit_points(rule) {
                    let (zeta, wz) = (z0 + dz * zu, wz * dz);
                    let m = (eo / zeta).min(T::ONE);
                    let jac = zeta * m * jac_scale;
                    for (r, wr) in unit_points(rule) {
                        let mut z = [T::ZERO; 2];
                        if let Some(slot) = z.get_mut(k) {
                            *slot = (zeta * at(&c, k)).min(T::ONE);
                        }
                        if let Some(slot) = z.get_mut(o) {
                            *slot = (zeta * m * r * at(&c, o)).min(T::ONE);
                        }
                        let (z_t, z_s) = (at(&z, 0), at(&z, 1));
                        let (span_t, span_s) = (T::ONE - z_t, T::ONE - z_s);
                        let mut inner = T::ZERO;
                        for (st, wt) in unit_points(rule) {
                            // x_t ∈ [0, 1 − z_t], y_t = x_t + z_t.
                            let xt = st * span_t;
                            for (ss, ws) in unit_points(rule) {
                                // Same quadrant: y_s = x_s + z_s; mirrored: y_s = x_s − z_s.
                                let (xs, ys) = if mirrored {
                                    (z_s + ss * span_s, ss * span_s)
                                } else {
                                    (ss * span_s, ss * span_s + z_s)
                                };
                                let (pa, na) = l.eval(xt, xs);
                                let (pb, nb) = l.eval(xt + z_t, ys);
                                inner += wt * ws * kernel_occluded(pa, na, pb, nb, occ);
                            }
                        }
                        count = count.saturating_add(q2);
                        total.add(T::TWO * wz * wr * jac * span_t * span_s * inner);
                    }
                }
            });
        }
    }
    (total.value(), count)
}

/// Whether the patch faces itself in some directions and away from itself in others (a saddle,
/// or a surface concave in one region and convex in another): the section 3.2 facing test then
/// cuts the self kernel along directions where the curvature changes sign, and the
/// identical-panel transform converges only algebraically. Probed on a 5 × 5 grid of points,
/// each towards 8 neighbours an eighth of the patch away; a facing value counts only beyond
/// 1e-8 of |n|·|e| (flat patches, whose values are rounding, are not mixed).
pub(crate) fn faces_itself_mixed<T: Real, S: Surface<T> + ?Sized>(patch: &Patch<'_, T, S>) -> bool {
    let l = Local { patch, map: SquareMap::IDENTITY };
    let (mut toward, mut away) = (false, false);
    let step = T::from_f64(0.125);
    let tol = T::from_f64(1e-8);
    for i in 0..5 {
        for j in 0..5 {
            let (x, y) = (T::from_usize(i) * T::from_f64(0.25), T::from_usize(j) * T::from_f64(0.25));
            let (p, n) = l.eval(x, y);
            for (dx, dy) in
                [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0), (1.0, -1.0)]
            {
                let (xq, yq) = (x + step * T::from_f64(dx), y + step * T::from_f64(dy));
                if !(xq >= T::ZERO && xq <= T::ONE && yq >= T::ZERO && yq <= T::ONE) {
                    continue;
                }
                let (q, m) = l.eval(xq, yq);
                let (ca, cb, _) = crate::integrand::cosines(p, n, q, m);
                let l = (q - p).norm();
                let (sa, sb) = (tol * n.norm() * l, tol * m.norm() * l);
                toward |= ca > sa || cb > sb;
                away |= ca < -sa || cb < -sb;
                if toward && away {
                    return true;
                }
            }
        }
    }
    false
}

/// Whether the contact of a touching or identical pair reaches a side of a patch that
/// collapses to a point (a cone's apex, a disk's centre, a sphere's pole: shorter than 1e-6 of
/// the patch's longest side). The self and edge transforms assume a regular map along the
/// contact and converge only algebraically there: any collapsed side for the same patch twice,
/// a collapsed side at either end of a shared edge. Vertex pairs have their own sum for it
/// (`collapsed_vertex_sum`) and are not affected.
pub(crate) fn contact_reaches_collapsed_side<T, SA, SB>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    adjacency: Adjacency,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (o, x, y, xy) = ((T::ZERO, T::ZERO), (T::ONE, T::ZERO), (T::ZERO, T::ONE), (T::ONE, T::ONE));
    // Lengths of the local sides η = 0, η = 1, ξ = 0, ξ = 1, and whether each is collapsed.
    fn collapsed<T: Real, S: Surface<T> + ?Sized>(l: &Local<'_, '_, T, S>, sides: [(T, T); 5]) -> [bool; 4] {
        let [o, x, y, xy, _] = sides;
        collapsed_among([line_length(l, o, x), line_length(l, y, xy), line_length(l, o, y), line_length(l, x, xy)])
    }
    let sides = [o, x, y, xy, o];
    match adjacency {
        Adjacency::Identical => collapsed(&Local { patch: a, map: SquareMap::IDENTITY }, sides).iter().any(|c| *c),
        Adjacency::SharedEdge { a: ma, b: mb } => {
            // The shared edge is η = 0; its ends lie on the sides ξ = 0 and ξ = 1.
            let ca = collapsed(&Local { patch: a, map: ma }, sides);
            let cb = collapsed(&Local { patch: b, map: mb }, sides);
            ca.get(2..).is_some_and(|c| c.iter().any(|c| *c)) || cb.get(2..).is_some_and(|c| c.iter().any(|c| *c))
        }
        Adjacency::SharedVertex { .. } | Adjacency::Separate => false,
    }
}

/// Which of these side lengths collapse to a point: shorter than 1e-6 of the longest.
fn collapsed_among<T: Real>(lengths: [T; 4]) -> [bool; 4] {
    let longest = lengths.iter().fold(T::ZERO, |m, l| m.max(*l));
    lengths.map(|l| l < longest * T::from_f64(1e-6))
}

/// The nominal integrand evaluations of a touching transform at `order`: 6·order⁴ for a shared
/// edge, 4·order⁴ for a shared vertex (times the ζ-shells of long or gapped pairs, not counted).
pub(crate) fn touching_evaluations(adjacency: Adjacency, order: usize) -> u64 {
    let per = if matches!(adjacency, Adjacency::SharedEdge { .. }) { 6 } else { 4 };
    per * (order as u64).pow(4)
}

/// Length of the local coordinate line from `p` to `q` (a 4-segment polyline).
fn line_length<T: Real, S: Surface<T> + ?Sized>(l: &Local<'_, '_, T, S>, p: (T, T), q: (T, T)) -> T {
    let quarter = T::from_f64(0.25);
    let mut prev = l.eval(p.0, p.1).0;
    let mut total = T::ZERO;
    for k in 1..=4u8 {
        let f = T::from_f64(f64::from(k)) * quarter;
        let next = l.eval(p.0 + (q.0 - p.0) * f, p.1 + (q.1 - p.1) * f).0;
        total += (next - prev).norm();
        prev = next;
    }
    total
}

/// Largest scaled extent: aspect ratios beyond this are integrated as if they were this (bounds
/// the number of shells; 2⁴⁰ ≈ 1.1e12).
const MAX_EXTENT: f64 = 1_099_511_627_776.0;

/// The extents of the scaled variables (side length / shortest side, in [1, MAX_EXTENT]) and the
/// shortest side; all 1 (and 0) if the lengths are not usable.
fn extents<T: Real, const N: usize>(lengths: [T; N]) -> ([T; N], T) {
    let r0 = lengths.iter().fold(T::MAX, |m, l| m.min(*l));
    if !(r0 > T::ZERO && r0.is_finite() && lengths.iter().all(|l| l.is_finite())) {
        return ([T::ONE; N], T::ZERO);
    }
    let max = T::from_f64(MAX_EXTENT);
    (lengths.map(|l| (l / r0).max(T::ONE).min(max)), r0)
}

/// Most ζ-shells of one pyramid; the last one reaches the end whatever its length.
const MAX_SHELLS: usize = 128;

/// Calls `f(lo, hi)` for the ζ-shells of a pyramid of extent `end` (≥ 1): [0, g], [g, 4g], …
/// up to 1 (just [0, 1] when g = 0 or g is not small), then [1, 4], [4, 16], … up to `end`,
/// with a break at each of `breaks` (the other extents: where a ratio's upper limit
/// min(1, extent/ζ) has its kink).
fn for_each_shell<T: Real>(gap: T, end: T, breaks: &[T], mut f: impl FnMut(T, T)) {
    let four = T::from_f64(4.0);
    let mut lo = T::ZERO;
    let mut hi = if gap > T::ZERO && gap < T::from_f64(0.25) { gap } else { T::ONE.min(end) };
    for shell in 0..MAX_SHELLS {
        if shell + 1 == MAX_SHELLS {
            hi = end;
        }
        f(lo, hi);
        if !(hi < end) {
            return;
        }
        lo = hi;
        let mut next = hi * four;
        if lo < T::ONE {
            next = next.min(T::ONE);
        }
        for b in breaks {
            if *b > lo && *b < next {
                next = *b;
            }
        }
        hi = next.min(end);
    }
}

/// Component `k` of a small array (0 if out of range; never happens).
#[inline(always)]
fn at<T: Real, const N: usize>(v: &[T; N], k: usize) -> T {
    v.get(k).copied().unwrap_or(T::ZERO)
}

/// A near edge pair whose gap tapers along the edge: the two edges nearly meet at one end and
/// diverge towards the other (cells side by side across a small fold, a slightly rotated
/// neighbour). The near-singular peak then sits at ζ ≈ the local gap, which runs from `narrow`
/// to `wide` (both in units of the shortest side) along the edge: ζ is split geometrically
/// from the narrow end's gap, and the variable along the edge is graded towards the narrow end
/// with the width where the local gap grows by the current ζ.
#[derive(Clone, Copy, Debug)]
struct Taper<T> {
    narrow: T,
    wide: T,
    /// The narrow end is at the edge parameter 1 (else 0).
    at_one: bool,
}

impl<T: Real> Taper<T> {
    /// The gaps at both ends of the matched edge (points at parameter 0 and 1 of both local
    /// maps), in units of `r0`; `None` unless they differ by more than a factor of 2. A narrow
    /// end below the rounding (the edges meet there) is given 2⁻²⁰ of the wide one, enough
    /// shells to reach the scales where the rule's nodes stop seeing the difference.
    fn of<SA, SB>(a: &Local<'_, '_, T, SA>, b: &Local<'_, '_, T, SB>, r0: T) -> Option<Self>
    where
        SA: Surface<T> + ?Sized,
        SB: Surface<T> + ?Sized,
    {
        if !(r0 > T::ZERO && r0 < T::MAX) {
            return None;
        }
        let end = |x: T| (a.eval(x, T::ZERO).0 - b.eval(x, T::ZERO).0).norm() / r0;
        let (g0, g1) = (end(T::ZERO), end(T::ONE));
        let (lo, hi) = (g0.min(g1), g0.max(g1));
        if !(hi.is_finite() && hi > T::TWO * lo) {
            return None;
        }
        let floor = hi * T::from_f64(1.0 / 1_048_576.0);
        Some(Self { narrow: lo.max(floor), wide: hi, at_one: g1 < g0 })
    }

    /// The grading width along the edge (as a fraction of the line of length `span`) at radial
    /// distance `zeta`: where the local gap has grown by ζ.
    fn width(self, zeta: T, span: T) -> T {
        (zeta + self.narrow) / ((self.wide - self.narrow) * span)
    }
}

#[allow(clippy::too_many_arguments)]
fn edge_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 3],
    edge_length: T,
    gap: T,
    fold: T,
    taper: Option<Taper<T>>,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Compensated: up to 6·order⁴·(shells) terms, summed in f32 too.
    let mut total = Compensated::default();
    // Scaled variables X = (|u|, η_a, η_b) · ext ∈ [0, ext]: physically isotropic near the
    // edge. Pyramid k: X_k = ζ is the largest; the other two are ζ·m_j(ζ)·ρ_j with
    // m_j = min(1, ext_j/ζ) (the box cuts the pyramid beyond ζ = ext_j), ρ_j ∈ [0, 1].
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1) * at(&c, 2);
    let folded = fold > T::ZERO && fold < T::ONE;
    for pyramid in 0..3 {
        let (o1, o2) = match pyramid {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let (ek, e1, e2) = (at(&ext, pyramid), at(&ext, o1), at(&ext, o2));
        // In pyramids 1 and 2 the kernel of two nearly folded patches peaks at ρ₁ → 0 (u = 0)
        // and at the ρ₂ where the other patch's line comes closest to the point at distance ζ
        // from the edge (ρ₂ = 1 for equal scaled distances without a gap; 1 − g/ζ with a gap g
        // along the patch; the far side of the narrower patch beyond its extent), with a
        // width ≈ (closest distance) / (length of the line): both are found per ζ node and
        // the ρ intervals graded towards them.
        let grade = folded && pyramid != 0;
        for_each_shell(gap, ek, &[e1, e2], |s0, s1| {
            // Beyond the narrower patch's extent (ζ > e2 ≥ 1 in pyramid 1 or 2) its free edge
            // hovers ≈ θ·(its width) over the other patch: the kernel also peaks at ζ → e2⁺;
            // grade ζ towards e2 too. Likewise at ζ = gap, where the peak line of a gapped
            // pair enters the pyramid.
            let toward_break = if (s0 == e2 || s0 == gap) && grade { fold * s0 / (s1 - s0) } else { T::ZERO };
            // Below the gap (the shell [0, g]) the same peak line reaches ρ₂ = 0 at ζ = g from
            // below, where the two patches are only ≈ θ·g apart: grade ζ towards its upper end.
            let toward_gap = if s1 == gap && s0 < s1 && grade { fold * s1 / (s1 - s0) } else { T::ZERO };
            let (grading, toward_one) = if toward_gap > T::ZERO { (toward_gap, true) } else { (toward_break, false) };
            for_each_interval(grading, toward_one, |t0, t1| {
                let (z0, z1) = (s0 + (s1 - s0) * t0, s0 + (s1 - s0) * t1);
                let dz = z1 - z0;
                for (zu, wz) in unit_points(rule) {
                    let (zeta, wz) = (z0 + dz * zu, wz * dz);
                    let (m1, m2) = ((e1 / zeta).min(T::ONE), (e2 / zeta).min(T::ONE));
                    let jac = zeta * zeta * m1 * m2 * jac_scale;
                    let (p_width, q_centre, q_width) = if grade {
                        let half = T::HALF;
                        let (point, line): (Vec3<T>, &dyn Fn(T) -> Vec3<T>) = if pyramid == 1 {
                            (a.eval(half, (zeta * at(&c, 1)).min(T::ONE)).0, &|r: T| {
                                b.eval(half, (zeta * m2 * r * at(&c, 2)).min(T::ONE)).0
                            })
                        } else {
                            (b.eval(half, (zeta * at(&c, 2)).min(T::ONE)).0, &|r: T| {
                                a.eval(half, (zeta * m2 * r * at(&c, 1)).min(T::ONE)).0
                            })
                        };
                        let (r_star, d_min) = closest_on_line(point, line);
                        let speed = (line(T::ONE) - line(T::ZERO)).norm();
                        let u_length = edge_length * at(&c, 0) * zeta * m1;
                        (ratio(d_min, u_length), r_star, ratio(d_min, speed))
                    } else {
                        (T::ZERO, T::ONE, T::ONE)
                    };
                    for_each_interval(p_width, false, |p0, p1| {
                        for_each_interval_around(q_centre, q_width, |q0, q1| {
                            let (dp, dq) = (p1 - p0, q1 - q0);
                            for (pu, wp) in unit_points(rule) {
                                let (p, wp) = (p0 + dp * pu, wp * dp);
                                for (qu, wq) in unit_points(rule) {
                                    let (q, wq) = (q0 + dq * qu, wq * dq);
                                    let (x1, x2) = (zeta * m1 * p, zeta * m2 * q);
                                    let (xu, xa, xb) = match pyramid {
                                        0 => (zeta, x1, x2),
                                        1 => (x1, zeta, x2),
                                        _ => (x1, x2, zeta),
                                    };
                                    let abs_u = (xu * at(&c, 0)).min(T::ONE);
                                    let (eta_a, eta_b) = ((xa * at(&c, 1)).min(T::ONE), (xb * at(&c, 2)).min(T::ONE));
                                    let span = T::ONE - abs_u;
                                    let mut line = T::ZERO;
                                    let (width, toward_one) =
                                        taper.map_or((T::ONE, false), |t| (t.width(zeta, span), t.at_one));
                                    for_each_interval(width, toward_one, |l0, l1| {
                                        for (sigma, ws) in unit_points(rule) {
                                            let lo = (l0 + (l1 - l0) * sigma) * span;
                                            // u > 0: ξ_a = σ(1−u), ξ_b = ξ_a + u;
                                            // u < 0: ξ_b = σ(1−|u|), ξ_a = ξ_b + |u|.
                                            let (pa, na) = a.eval(lo, eta_a);
                                            let (pb, nb) = b.eval(lo + abs_u, eta_b);
                                            let mut k = kernel_occluded(pa, na, pb, nb, occ);
                                            let (pa2, na2) = a.eval(lo + abs_u, eta_a);
                                            let (pb2, nb2) = b.eval(lo, eta_b);
                                            k += kernel_occluded(pa2, na2, pb2, nb2, occ);
                                            line += ws * (l1 - l0) * k;
                                        }
                                    });
                                    total.add(wz * wp * wq * jac * span * line);
                                }
                            }
                        });
                    });
                }
            });
        });
    }
    total.value()
}

/// `num / den` as a grading width: 1 (no grading) when the quotient is not a small positive
/// number.
#[inline(always)]
fn ratio<T: Real>(num: T, den: T) -> T {
    let r = num / den;
    if r > T::ZERO && r < T::ONE {
        r
    } else {
        T::ONE
    }
}

/// The parameter ρ ∈ [0, 1] where `line(ρ)` comes closest to `p` and that distance, by golden
/// section (the distance along a patch's coordinate line is unimodal for the flat and gently
/// curved pairs that need it; an approximate centre only shifts the grading).
fn closest_on_line<T: Real>(p: Vec3<T>, line: &dyn Fn(T) -> Vec3<T>) -> (T, T) {
    let d = |r: T| (line(r) - p).norm();
    let g = T::from_f64(0.381_966_011_250_105_1);
    let (mut lo, mut hi) = (T::ZERO, T::ONE);
    let mut x1 = lo + g * (hi - lo);
    let mut x2 = hi - g * (hi - lo);
    let (mut f1, mut f2) = (d(x1), d(x2));
    for _ in 0..48 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = lo + g * (hi - lo);
            f1 = d(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = hi - g * (hi - lo);
            f2 = d(x2);
        }
    }
    // The ends too (the minimum of a monotone distance is at an end).
    let mut best = if f1 <= f2 { (x1, f1) } else { (x2, f2) };
    for r in [T::ZERO, T::ONE] {
        let f = d(r);
        if f < best.1 {
            best = (r, f);
        }
    }
    best
}

/// Calls `f(lo, hi)` for the intervals of [0, 1] graded geometrically on both sides of `centre`:
/// [c − δ, c + δ] ∩ [0, 1], then [c + δ, c + 4δ], [c − 4δ, c − δ], …; just [0, 1] when δ is not
/// in (0, 1) or the centre is not in [0, 1].
fn for_each_interval_around<T: Real>(centre: T, width: T, mut f: impl FnMut(T, T)) {
    let width = width.max(T::from_f64(1e-12));
    if !(width < T::ONE && centre >= T::ZERO && centre <= T::ONE) {
        f(T::ZERO, T::ONE);
        return;
    }
    let four = T::from_f64(4.0);
    let (mut lo, mut hi) = ((centre - width).max(T::ZERO), (centre + width).min(T::ONE));
    f(lo, hi);
    let mut step = width;
    while hi < T::ONE {
        step *= four;
        let next = (centre + step).min(T::ONE);
        f(hi, next);
        hi = next;
    }
    step = width;
    while lo > T::ZERO {
        step *= four;
        let next = (centre - step).max(T::ZERO);
        f(next, lo);
        lo = next;
    }
}

/// Kahan–Babuška (Neumaier) compensated sum.
#[derive(Clone, Copy, Default)]
struct Compensated<T> {
    sum: T,
    carry: T,
}

impl<T: Real> Compensated<T> {
    #[inline(always)]
    fn add(&mut self, x: T) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.carry += (self.sum - t) + x;
        } else {
            self.carry += (x - t) + self.sum;
        }
        self.sum = t;
    }
    #[inline(always)]
    fn value(self) -> T {
        self.sum + self.carry
    }
}

/// Calls `f(lo, hi)` for the intervals of [0, 1] graded geometrically towards 0 (or towards 1
/// if `toward_one`): [0, δ], [δ, 4δ], [4δ, 16δ], …; just [0, 1] when δ is 0 or ≥ 1.
fn for_each_interval<T: Real>(scale: T, toward_one: bool, mut f: impl FnMut(T, T)) {
    if !(scale > T::ZERO && scale < T::ONE) {
        f(T::ZERO, T::ONE);
        return;
    }
    let four = T::from_f64(4.0);
    let (mut lo, mut hi) = (T::ZERO, scale);
    while lo < T::ONE {
        if toward_one {
            f(T::ONE - hi, T::ONE - lo);
        } else {
            f(lo, hi);
        }
        lo = hi;
        hi = (hi * four).min(T::ONE);
    }
}

/// The fold parameter of an edge pair: ≈ the dihedral angle when the two patches are nearly
/// folded onto each other (normals at the middle of the common edge nearly opposite), from
/// |n̂_a + n̂_b|; large (no grading) otherwise.
fn fold_angle<T, SA, SB>(a: &Local<'_, '_, T, SA>, b: &Local<'_, '_, T, SB>) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (_, na) = a.eval(T::HALF, T::ZERO);
    let (_, nb) = b.eval(T::HALF, T::ZERO);
    let (la, lb) = (na.norm(), nb.norm());
    if !(la > T::ZERO && lb > T::ZERO) {
        return T::ONE;
    }
    (na.scale(T::ONE / la) + nb.scale(T::ONE / lb)).norm()
}

/// The vertex sum when a side through the common vertex collapses to it (module docs, "A side
/// collapsed to a point"): variables x = (ξ_a, η_a, ξ_b, η_b); `singular[i]` marks the variables
/// that vanish at the contact (the others run along a collapsed side and stay free). The
/// singular ones, scaled by `ext`, are split into pyramids by the largest (ζ, the others
/// ζ·m·ρ, Jacobian ζ^(k−1)·Π m for k singular variables) in ζ-shells as in `vertex_sum`; the
/// free ones get the plain rule.
#[allow(clippy::too_many_arguments)]
fn collapsed_vertex_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 4],
    singular: [bool; 4],
    gap: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    let is_singular = |i: usize| singular.get(i).copied().unwrap_or(false);
    let k = singular.iter().filter(|s| **s).count();
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = (0..4).filter(|&i| is_singular(i)).fold(T::ONE, |j, i| j * at(&c, i));
    for pyramid in (0..4).filter(|&i| is_singular(i)) {
        let others: [usize; 3] = match pyramid {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let ek = at(&ext, pyramid);
        let mut breaks = [T::ZERO; 3];
        for (slot, &i) in breaks.iter_mut().zip(&others) {
            *slot = if is_singular(i) { at(&ext, i) } else { T::ZERO };
        }
        for_each_shell(gap, ek, &breaks, |z0, z1| {
            let dz = z1 - z0;
            for (zu, wz) in unit_points(rule) {
                let (zeta, wz) = (z0 + dz * zu, wz * dz);
                // m_i = min(1, ext_i/ζ) for the singular ratios, 1 for the free variables.
                let m = others.map(|i| if is_singular(i) { (at(&ext, i) / zeta).min(T::ONE) } else { T::ONE });
                let mut jac = jac_scale;
                for _ in 1..k {
                    jac *= zeta;
                }
                for (slot, &i) in others.iter().enumerate() {
                    if is_singular(i) {
                        jac *= at(&m, slot);
                    }
                }
                let var = |slot: usize, r: T| {
                    let i = others.get(slot).copied().unwrap_or(0);
                    if is_singular(i) {
                        (zeta * at(&m, slot) * r * at(&c, i)).min(T::ONE)
                    } else {
                        r
                    }
                };
                let xz = (zeta * at(&c, pyramid)).min(T::ONE);
                for (pu, wp) in unit_points(rule) {
                    for (qu, wq) in unit_points(rule) {
                        let mut line = T::ZERO;
                        for (ru, wr) in unit_points(rule) {
                            let (x1, x2, x3) = (var(0, pu), var(1, qu), var(2, ru));
                            let x = match pyramid {
                                0 => [xz, x1, x2, x3],
                                1 => [x1, xz, x2, x3],
                                2 => [x1, x2, xz, x3],
                                _ => [x1, x2, x3, xz],
                            };
                            let (pa, na) = a.eval(at(&x, 0), at(&x, 1));
                            let (pb, nb) = b.eval(at(&x, 2), at(&x, 3));
                            line += wr * kernel_occluded(pa, na, pb, nb, occ);
                        }
                        total.add(wz * wp * wq * jac * line);
                    }
                }
            }
        });
    }
    total.value()
}

fn vertex_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 4],
    gap: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    // Scaled variables X = (ξ_a, η_a, ξ_b, η_b) · ext ∈ [0, ext]; pyramid k: X_k = ζ is the
    // largest, the others ζ·m_j(ζ)·ρ_j with m_j = min(1, ext_j/ζ).
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1) * at(&c, 2) * at(&c, 3);
    // The point at local variables x (physical, in [0, 1]): index 0, 1 on A, 2, 3 on B.
    let point =
        |x: [T; 4], on_b: bool| if on_b { b.eval(at(&x, 2), at(&x, 3)).0 } else { a.eval(at(&x, 0), at(&x, 1)).0 };
    let vertex = a.eval(T::ZERO, T::ZERO).0;
    for pyramid in 0..4 {
        let others: [usize; 3] = match pyramid {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let [o1, o2, o3] = others;
        let (ek, e1, e2, e3) = (at(&ext, pyramid), at(&ext, o1), at(&ext, o2), at(&ext, o3));
        let on_b = pyramid >= 2;
        for_each_shell(gap, ek, &[e1, e2, e3], |z0, z1| {
            let dz = z1 - z0;
            for (zu, wz) in unit_points(rule) {
                let (zeta, wz) = (z0 + dz * zu, wz * dz);
                let m = [(e1 / zeta).min(T::ONE), (e2 / zeta).min(T::ONE), (e3 / zeta).min(T::ONE)];
                let jac = zeta * zeta * zeta * at(&m, 0) * at(&m, 1) * at(&m, 2) * jac_scale;
                // Local variable value of ratio slot s at ratio r.
                let var = |s: usize, r: T| {
                    let k = others.get(s).copied().unwrap_or(0);
                    (zeta * at(&m, s) * r * at(&c, k)).min(T::ONE)
                };
                let with = |k: usize, v: T| {
                    let mut x = [T::ZERO; 4];
                    if let Some(slot) = x.get_mut(pyramid) {
                        *slot = (zeta * at(&c, pyramid)).min(T::ONE);
                    }
                    if let Some(slot) = x.get_mut(k) {
                        *slot = v;
                    }
                    x
                };
                // Nearly folded vertex pairs (cells along a folded edge): the point at ζ on this
                // patch's edge may come close to an edge of the other patch (distance ≪ its
                // distance from the vertex); then grade that ratio around the closest point and
                // the other two ratios towards 0, with widths (closest distance)/(line length).
                let p = point(with(pyramid, (zeta * at(&c, pyramid)).min(T::ONE)), on_b);
                let reach = (p - vertex).norm();
                let mut centre = [T::ZERO; 3];
                let mut width = [T::ONE; 3];
                // Slots of the other patch's two variables, and of this patch's other one.
                let (s_other, s_same): ([usize; 2], usize) = if on_b { ([0, 1], 2) } else { ([1, 2], 0) };
                let mut best: Option<(usize, T, T)> = None;
                for s in s_other {
                    let k = others.get(s).copied().unwrap_or(0);
                    let line = |r: T| point(with(k, var(s, r)), !on_b);
                    let (r_star, d_min) = closest_on_line(p, &line);
                    if best.is_none_or(|(_, _, d)| d_min < d) {
                        best = Some((s, r_star, d_min));
                    }
                }
                if let Some((s_near, r_star, d_min)) = best {
                    if d_min < T::from_f64(0.25) * reach {
                        for s in [s_other[0], s_other[1], s_same] {
                            let k = others.get(s).copied().unwrap_or(0);
                            let same = s == s_same;
                            let speed = (point(with(k, var(s, T::ONE)), same == on_b)
                                - point(with(k, var(s, T::ZERO)), same == on_b))
                            .norm();
                            if let (Some(w), Some(cen)) = (width.get_mut(s), centre.get_mut(s)) {
                                *w = ratio(d_min, speed);
                                if s == s_near {
                                    *cen = r_star;
                                }
                            }
                        }
                    }
                }
                for_each_interval_around(at(&centre, 0), at(&width, 0), |p0, p1| {
                    for_each_interval_around(at(&centre, 1), at(&width, 1), |q0, q1| {
                        for_each_interval_around(at(&centre, 2), at(&width, 2), |r0, r1| {
                            let (dp, dq, dr) = (p1 - p0, q1 - q0, r1 - r0);
                            for (pu, wp) in unit_points(rule) {
                                let (p, wp) = (p0 + dp * pu, wp * dp);
                                for (qu, wq) in unit_points(rule) {
                                    let (q, wq) = (q0 + dq * qu, wq * dq);
                                    for (ru, wr) in unit_points(rule) {
                                        let (r, wr) = (r0 + dr * ru, wr * dr);
                                        let (x1, x2, x3) = (var(0, p), var(1, q), var(2, r));
                                        let xz = (zeta * at(&c, pyramid)).min(T::ONE);
                                        let x = match pyramid {
                                            0 => [xz, x1, x2, x3],
                                            1 => [x1, xz, x2, x3],
                                            2 => [x1, x2, xz, x3],
                                            _ => [x1, x2, x3, xz],
                                        };
                                        let (pa, na) = a.eval(at(&x, 0), at(&x, 1));
                                        let (pb, nb) = b.eval(at(&x, 2), at(&x, 3));
                                        total.add(wz * wp * wq * wr * jac * kernel_occluded(pa, na, pb, nb, occ));
                                    }
                                }
                            }
                        });
                    });
                });
            }
        });
    }
    total.value()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{BezierPatch, Cylinder, Disk, Side, Sphere};
    use crate::vec3::vec3;

    #[test]
    fn mixed_self_facing_is_found_on_saddles_only() {
        // z = (x − ½)(y − ½): bilinear, so the bicubic control net holds it exactly.
        let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in control.iter_mut().enumerate() {
            for (j, c) in row.iter_mut().enumerate() {
                let (x, y) = (i as f64 / 3.0, j as f64 / 3.0);
                *c = vec3(x, y, (x - 0.5) * (y - 0.5));
            }
        }
        let saddle = BezierPatch::new(control).unwrap();
        assert!(faces_itself_mixed(&Patch::whole(&saddle).unwrap()));
        let o = vec3(0.0, 0.0, 0.0);
        let z = vec3(0.0, 0.0, 1.0);
        let tube = Cylinder::new(o, z, 0.5, 1.0, Side::Inner).unwrap();
        let outside = Cylinder::new(o, z, 0.5, 1.0, Side::Outer).unwrap();
        let ball = Sphere::inner(o, 1.0).unwrap();
        let disk = Disk::new(o, z, 1.0).unwrap();
        let quarter = |s: &dyn Surface<f64>| {
            let r = Patch::whole(s).unwrap().rect();
            !faces_itself_mixed(&Patch::new(s, r.cell(0, 0, 4, 2)).unwrap())
        };
        assert!(quarter(&tube) && quarter(&outside) && quarter(&ball) && quarter(&disk));
    }
}
