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
//! **Nearly folded pairs.** When the dihedral angle θ between the two patches is small (their
//! normals at the edge nearly opposite), the kernel inside two of the pyramids peaks in a corner
//! with width ≈ θ; those pyramids' inner variables are then split geometrically towards that
//! corner (θ, 4θ, 16θ, …), which keeps the convergence exponential down to θ ≈ 1°.
//!
//! **Shared vertex.** Both patches are mapped so that the common corner is (0, 0); the 4-cube is
//! split into four pyramids by its largest coordinate, Jacobian ζ³ (the singularity is 1/ζ²).
//!
//! **Nearly touching** pairs (an edge or corner closer than the patch size but not shared) are
//! handled by the same transforms with the ζ-interval split geometrically down to the gap, so the
//! near-singular peak is resolved (error bounded independently of the gap).
//!
//! Adjacency is detected from the geometry ([`classify`]): corners closer than
//! `ADJACENCY_TOLERANCE × patch size + 16 ε × coordinate magnitude` coincide; an edge is shared
//! when both its corners coincide and its quarter, mid and three-quarter points do too (so the
//! two parameterisations agree along it, as the transform requires).

use crate::error::PdmError;
use crate::gauss::GaussRule;
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
    contact(a, b, adjacency_tolerance::<T>()).0
}

/// Relative gap below which a pair that does not touch is still integrated with the touching
/// transforms (graded towards the gap): 2 % of the patch size. The transforms are exact changes
/// of variables for any pair; they pay off when the near-singularity sits at the pyramids' apex,
/// i.e. when the matched edge or corner is where the patches come closest — true for small gaps,
/// not for e.g. two parallel patches facing each other at a distance comparable to their size.
pub const NEAR_CONTACT: f64 = 0.02;

/// Like [`classify`], but corners closer than [`NEAR_CONTACT`] × size also count as shared;
/// returns the adjacency and the gap (largest distance between matched points, relative to the
/// patch size; 0 up to rounding for patches that truly touch).
#[must_use]
pub fn classify_near<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> (Adjacency, T)
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    // A gap at the level of rounding is no gap: grading for it would only cost time.
    let rounding = T::from_f64(64.0) * T::EPSILON;
    let (exact, exact_gap) = contact(a, b, adjacency_tolerance::<T>());
    if exact != Adjacency::Separate {
        // Touching within the tight tolerance (or the same patch): the near tolerance could
        // only blur it (a 1° fold brings the far corners within it too). A gap below the
        // tolerance but above rounding is still graded for.
        let gap = if exact == Adjacency::Identical || !(exact_gap > rounding) { T::ZERO } else { exact_gap };
        return (exact, gap);
    }
    let (adjacency, gap) = contact(a, b, T::from_f64(NEAR_CONTACT));
    if adjacency == Adjacency::Identical {
        // Nearly coincident but not the same patch (e.g. two close parallel patches): no
        // transform applies.
        return (Adjacency::Separate, T::ZERO);
    }
    (adjacency, if gap > rounding { gap } else { T::ZERO })
}

/// Adjacency at relative tolerance `rel_tol`, and the relative gap of the matched points.
fn contact<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, rel_tol: T) -> (Adjacency, T)
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let ca = corner_points(a);
    let cb = corner_points(b);
    let size = |c: &[Vec3<T>; 4]| {
        let mut m = T::ZERO;
        for p in c {
            for q in c {
                m = m.max((*p - *q).norm());
            }
        }
        m
    };
    let magnitude = ca.iter().chain(cb.iter()).fold(T::ZERO, |m, p| m.max(p.max_abs()));
    let scale = size(&ca).max(size(&cb));
    let tol = rel_tol * scale + T::from_f64(16.0) * T::EPSILON * magnitude;
    let same = |p: Vec3<T>, q: Vec3<T>| (p - q).norm() <= tol;
    let gap_of = |p: Vec3<T>, q: Vec3<T>| if scale > T::ZERO { (p - q).norm() / scale } else { T::ZERO };
    // matches[i] = Some(j) if corner i of A coincides with corner j of B.
    // One-to-one: a corner of B is matched at most once (a patch with a collapsed edge — a
    // sphere's polar cell, a cone's apex — has two equal corners).
    let mut matches = [None; 4];
    let mut used = [false; 4];
    let mut count = 0;
    for (i, p) in ca.iter().enumerate() {
        for (j, q) in cb.iter().enumerate() {
            let free = used.get(j).is_some_and(|u| !*u);
            if free && same(*p, *q) {
                if let (Some(m), Some(u)) = (matches.get_mut(i), used.get_mut(j)) {
                    if m.is_none() {
                        *m = Some(j);
                        *u = true;
                        count += 1;
                    }
                }
            }
        }
    }
    match count {
        0 => (Adjacency::Separate, T::ZERO),
        1 => {
            let Some((i, j)) = matches.iter().enumerate().find_map(|(i, m)| m.map(|j| (i, j))) else {
                return (Adjacency::Separate, T::ZERO);
            };
            let gap = match (ca.get(i), cb.get(j)) {
                (Some(p), Some(q)) => gap_of(*p, *q),
                _ => T::ZERO,
            };
            // Any local orientation with (0,0) at the shared corner.
            match (SquareMap::from_corners(i, i ^ 1), SquareMap::from_corners(j, j ^ 1)) {
                (Some(ma), Some(mb)) => (Adjacency::SharedVertex { a: ma, b: mb }, gap),
                _ => (Adjacency::Separate, T::ZERO),
            }
        }
        2 => {
            let mut it = matches.iter().enumerate().filter_map(|(i, m)| m.map(|j| (i, j)));
            let (Some((i1, j1)), Some((i2, j2))) = (it.next(), it.next()) else {
                return (Adjacency::Separate, T::ZERO);
            };
            match (SquareMap::from_corners(i1, i2), SquareMap::from_corners(j1, j2)) {
                (Some(ma), Some(mb)) => {
                    let la = Local { patch: a, map: ma };
                    let lb = Local { patch: b, map: mb };
                    let mut gap = T::ZERO;
                    let mut agree = true;
                    for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
                        let f = T::from_f64(f);
                        let (p, q) = (la.eval(f, T::ZERO).0, lb.eval(f, T::ZERO).0);
                        agree = agree && same(p, q);
                        gap = gap.max(gap_of(p, q));
                    }
                    if agree {
                        (Adjacency::SharedEdge { a: ma, b: mb }, gap)
                    } else {
                        // Two corners in common that are not one edge of both, or an edge
                        // parameterised differently: the transform does not apply.
                        (Adjacency::Separate, T::ZERO)
                    }
                }
                _ => (Adjacency::Separate, T::ZERO),
            }
        }
        _ => {
            // Three or four corners in common: the same patch only if the centres coincide too
            // (two polar cells of a sphere share all their corners but not their centres).
            let (ta, sa) = centre_of(a);
            let (tb, sb) = centre_of(b);
            if count == 4 && same(a.surface().point(ta, sa), b.surface().point(tb, sb)) {
                (Adjacency::Identical, T::ZERO)
            } else {
                // Several shared edges (or an ambiguous match): no single transform applies.
                (Adjacency::Separate, T::ZERO)
            }
        }
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
/// peak is resolved.
/// `Separate` pairs are refused (`Err(Degenerate)`) — use the plain sum for them; `Identical`
/// pairs too (a patch's own F_ii needs [`crate::self_form_factor`]).
///
/// Cost: 6·order⁴ (edge) or 4·order⁴ (vertex) integrand evaluations; each evaluates both surfaces
/// (no precomputation is possible: the sample points depend on all four variables).
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
    let rule = GaussRule::<T>::new(order)?;
    // A gap at the level of rounding is no gap (and a subnormal one would make hundreds of
    // graded intervals).
    let gap = if gap > T::from_f64(64.0) * T::EPSILON && gap.is_finite() { gap } else { T::ZERO };
    let sum = match adjacency {
        Adjacency::SharedEdge { a: ma, b: mb } => {
            let (la, lb) = (Local { patch: a, map: ma }, Local { patch: b, map: mb });
            let fold = fold_angle(&la, &lb);
            graded(gap, |z0, z1| edge_sum(&la, &lb, &rule, occluders, z0, z1, fold))
        }
        Adjacency::SharedVertex { a: ma, b: mb } => {
            let (la, lb) = (Local { patch: a, map: ma }, Local { patch: b, map: mb });
            graded(gap, |z0, z1| vertex_sum(&la, &lb, &rule, occluders, z0, z1))
        }
        Adjacency::Separate | Adjacency::Identical => return Err(PdmError::Degenerate),
    };
    let value = sum * T::FRAC_1_PI;
    if !value.is_finite() || value < T::ZERO {
        return Err(PdmError::InvalidResult);
    }
    Ok(value)
}

/// Σ over ζ-intervals [0, g], [g, 4g], [4g, 16g], … up to 1 (or just [0, 1] when g = 0 or g is
/// not small).
fn graded<T: Real>(gap: T, mut integral: impl FnMut(T, T) -> T) -> T {
    if !(gap > T::ZERO) || !(gap < T::from_f64(0.25)) {
        return integral(T::ZERO, T::ONE);
    }
    let four = T::from_f64(4.0);
    let mut lo = T::ZERO;
    let mut hi = gap;
    let mut total = T::ZERO;
    while lo < T::ONE {
        total += integral(lo, hi);
        lo = hi;
        hi = (hi * four).min(T::ONE);
    }
    total
}

/// The kernel (n_a·e)(−n_b·e)/L⁴ with unnormalised (Jacobian-scaled) normals, zero where the
/// curvature test or an occluder says the points do not see each other.
#[inline(always)]
fn kernel<T: Real, O: Occluder<T> + ?Sized>(pa: Vec3<T>, na: Vec3<T>, pb: Vec3<T>, nb: Vec3<T>, occluders: &O) -> T {
    let e = pb - pa;
    let l2 = e.norm2();
    let ca = na.dot(e);
    let cb = -nb.dot(e);
    if !(ca > T::ZERO && cb > T::ZERO && l2 > T::ZERO) || occluders.blocks(pa, pb) {
        return T::ZERO;
    }
    let inv = T::ONE / l2;
    (ca * inv) * (cb * inv)
}

fn edge_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    z0: T,
    z1: T,
    fold: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Compensated: up to 6·order⁴·(grading) terms, summed in f32 too.
    let mut total = Compensated::default();
    let dz = z1 - z0;
    // Pyramid k: the largest of (|u|, η_a, η_b) is ζ. In pyramids 1 and 2 the kernel of two
    // nearly folded patches peaks at p → 0 (u = 0), q → 1 (η_a = η_b) with width ≈ the fold
    // angle: grade p and q towards that corner.
    for pyramid in 0..3 {
        let scale = if pyramid == 0 { T::ZERO } else { fold };
        for_each_interval(scale, false, |p0, p1| {
            for_each_interval(scale, true, |q0, q1| {
                let (dp, dq) = (p1 - p0, q1 - q0);
                for (zu, wz) in unit_points(rule) {
                    let (zeta, wz) = (z0 + dz * zu, wz * dz);
                    let jac_zeta = zeta * zeta;
                    for (pu, wp) in unit_points(rule) {
                        let (p, wp) = (p0 + dp * pu, wp * dp);
                        for (qu, wq) in unit_points(rule) {
                            let (q, wq) = (q0 + dq * qu, wq * dq);
                            let (abs_u, eta_a, eta_b) = match pyramid {
                                0 => (zeta, zeta * p, zeta * q),
                                1 => (zeta * p, zeta, zeta * q),
                                _ => (zeta * p, zeta * q, zeta),
                            };
                            let span = T::ONE - abs_u;
                            let mut line = T::ZERO;
                            for (sigma, ws) in unit_points(rule) {
                                let lo = sigma * span;
                                // u > 0: ξ_a = σ(1−u), ξ_b = ξ_a + u;  u < 0: ξ_b = σ(1−|u|), ξ_a = ξ_b + |u|.
                                let (pa, na) = a.eval(lo, eta_a);
                                let (pb, nb) = b.eval(lo + abs_u, eta_b);
                                let mut k = kernel(pa, na, pb, nb, occ);
                                let (pa2, na2) = a.eval(lo + abs_u, eta_a);
                                let (pb2, nb2) = b.eval(lo, eta_b);
                                k += kernel(pa2, na2, pb2, nb2, occ);
                                line += ws * k;
                            }
                            total.add(wz * wp * wq * jac_zeta * span * line);
                        }
                    }
                }
            });
        });
    }
    total.value()
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

fn vertex_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    z0: T,
    z1: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    let dz = z1 - z0;
    for (zu, wz) in unit_points(rule) {
        let (zeta, wz) = (z0 + dz * zu, wz * dz);
        let jac = zeta * zeta * zeta;
        for (p, wp) in unit_points(rule) {
            for (q, wq) in unit_points(rule) {
                for (r, wr) in unit_points(rule) {
                    let (zp, zq, zr) = (zeta * p, zeta * q, zeta * r);
                    let mut k = T::ZERO;
                    // Four pyramids: the largest of (ξ_a, η_a, ξ_b, η_b) is ζ.
                    for (xa, ya, xb, yb) in
                        [(zeta, zp, zq, zr), (zp, zeta, zq, zr), (zp, zq, zeta, zr), (zp, zq, zr, zeta)]
                    {
                        let (pa, na) = a.eval(xa, ya);
                        let (pb, nb) = b.eval(xb, yb);
                        k += kernel(pa, na, pb, nb, occ);
                    }
                    total.add(wz * wp * wq * wr * jac * k);
                }
            }
        }
    }
    total.value()
}
