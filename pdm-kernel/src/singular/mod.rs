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
//! edge above edge) is nearly coincident, not nearly folded, and is reported as `Separate`. So is
//! a vertex where the patches touch face to face (each with one tangent plane there, the normals
//! pointing at each other: a sphere's pole resting on a disk's centre): the transforms assume
//! patches that leave the common point at an angle.
//!
//! Files: the local maps, the dispatch over the transforms and the shared grading here;
//! `classify.rs` (adjacency), `edge.rs`, `vertex.rs`, `identical.rs` (the transforms).

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::integrand::kernel_occluded;
use crate::patch::Patch;
use crate::real::Real;
use crate::surface::Surface;
use crate::vec3::Vec3;
use crate::visibility::Occluder;

mod classify;
mod edge;
mod identical;
#[cfg(test)]
mod tests;
mod vertex;
pub use classify::*;
use edge::*;
pub(crate) use identical::*;
use vertex::*;

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
    let per = if matches!(adjacency, Adjacency::SharedEdge { .. }) { 6u64 } else { 4 };
    per.saturating_mul((order as u64).saturating_pow(4))
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
pub(crate) fn closest_on_line<T: Real>(p: Vec3<T>, line: &dyn Fn(T) -> Vec3<T>) -> (T, T) {
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
