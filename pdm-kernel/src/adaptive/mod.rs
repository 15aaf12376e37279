//! Tolerance-driven integration: spend effort only where a pair of patches needs it.
//!
//! [`adaptive_exchange`] returns A_a·F_{a→b} with an error estimate, whether that estimate met
//! the tolerance, and the number of integrand evaluations it took. It takes the same route per
//! pair as [`crate::pair_exchange`] (`pair/route.rs`, `PairContext::separate_route`: the
//! decisions are made in one place) and differs in what it does on it. Per pair it
//! 1. classifies the pair (`classify_near`): flat pairs that see each other wholly use the
//!    contour form at two orders or more (where its terms cancel beyond the working precision,
//!    the paths below take the pair if their rules resolve it, else the contour value stands
//!    with its rounding bound in the estimate);
//!    touching pairs use the regularising transforms, raising the order by 2 from 4; the same
//!    patch twice uses the identical-panel transform (see below);
//! 2. for separate pairs, starts from an order chosen from the geometry — the Gauss error on an
//!    integrand whose nearest singularity lies at distance d from patches of size h falls like
//!    ρ^(−2p) with ρ ≈ 1 + 2d/h, so p₀ = ⌈ln(1/tol) / (2 ln ρ)⌉ (clamped to 2…12);
//! 3. skips the occlusion tests when no occluder can cut a segment between the two patches'
//!    bounding balls (`Occluder::may_block_between`), and takes the boundary path
//!    (`boundary/`: visibility boundaries placed into the inner rule, the
//!    inner patch refined towards close outer points) when the pair straddles a boundary
//!    (some sample pairs visible, some not; or the facing test not proven uniform on the
//!    whole pair from the normal cones, `pair::facing_settled`; or an occluder that may cut)
//!    or the patches are closer than their size; the outer patch is chosen as by `pair_exchange`: without
//!    occluders the patch whose points stay farther from the other's edges
//!    (`pair::outer_is_b`), across occluders the smaller one (`pair::occluded_outer_is_b`;
//!    `pair::occluded_outer`: the one whose outer events are placed, and between patches of
//!    one size the one no occluder touches);
//! 4. compares orders p, p + 2, …; when the estimate is still above the tolerance at
//!    `max_order`, splits the pair and recurses — a separate pair's larger patch in two across
//!    its longer side, a touching pair's both patches 2 × 2 (so that the cells along the
//!    contact share whole edges and corners again) — to depth ≤ `max_depth` (no
//!    allocation). Sides are
//!    measured by arc length (a 12-segment polyline along each edge and the mid-line of the
//!    parameter rectangle), so a side that closes on itself — the θ side of a whole disk or
//!    cylinder, whose corner chord is zero — is halved like any other.
//!
//! # The error estimate and `converged`
//! Each leaf pair's estimate is a difference between independent approximations, times a
//! safety factor where the convergence is only algebraic, plus a rounding allowance of
//! 128 ε·|value| (2.8e-14 relative in f64, 1.5e-5 in f32); the total is the sum over the
//! leaves. [`Estimate::converged`] is `true` if every leaf met the tolerance (estimate ≤
//! its share of the absolute budget + tolerance·|value|, or value and estimate both zero; the
//! budget [`Adaptive::absolute`] is halved with each halving of a pair, so the leaves' shares
//! add up to it) or the total estimate meets it against the total value; at the depth limit,
//! or where a split would go below the resolution of the coordinates (f32 cells far from the
//! origin), the best value is returned with its estimate
//! and `converged = false` — never silently above the tolerance, and never an error after
//! the work. A tolerance below 256 ε (5.7e-14
//! in f64, 3.1e-5 in f32) is below what any estimate can show: the refinement works to 256 ε
//! instead (it would otherwise split every pair to the depth limit, for minutes, without
//! getting closer) and the result says `converged = false` unless its estimate meets the
//! tolerance asked for. A caller who needs the tolerance checks the flag (or compares `error` with
//! its own budget).
//!
//! * Far from the origin for their size, the patches' points are computed at the magnitude of
//!   their coordinates, up to ε·|x| off: every pair's estimate also carries an allowance for
//!   that (`position_allowance`: the first-order change of the integrand under such moves,
//!   from the corners for two flat patches in front of each other, sampled at order 4
//!   otherwise, times a measured factor; zero where the coordinates are below about 5 sides of the patches).
//!   A 1 cm cell 100 m from the origin in f32 gets an estimate of about 1e-2 of its value.
//! * With a fast sine and cosine (the `micromath` feature, f32), the sample points of curved
//!   surfaces lie up to [`Real::ELEMENTARY_ERROR`] (2e-3 of the surface's size) off the
//!   surface: every pair's estimate also carries an allowance for that (`backend_allowance`:
//!   2·`ELEMENTARY_ERROR` times the pair's sensitivity to turned normals, summed at order 8;
//!   a median 2.4e-2 of the value on the sphere-in-cube scene's cell pairs, 4–170× the actual
//!   error on 46 red-team cases), and the refinement works to 8e-3 at least (a finer tolerance
//!   ends with `converged = false`). Separate patches closer than the sample points' error are
//!   refused (`Err(Unresolvable)`). With libm the allowance is zero.
//! * Smooth separate pairs and touching pairs (exponential convergence in the order): with
//!   d₂ the difference between the last two orders and d₁ the one before, max(d₂, √(d₁·d₂))
//!   (d₂ alone on a separate pair's first comparison, whose start order the geometry chose);
//!   touching pairs compare at least three orders. The geometric mean covers convergence that
//!   stalls for a step (checked against closed forms and the contour integral in the tests).
//! * Flat pairs by the contour form: where every edge pair is in closed form (parallel edges,
//!   edges from a common corner), the bound on the rounding of the cancelling terms alone;
//!   otherwise the difference between orders 8 and 16 (then 24, 32 until it meets the
//!   tolerance: the contour's 1-D rules are not bound by `max_order`) plus that bound.
//! * Pairs across visibility boundaries whose outer events are placed into the outer rule
//!   (`boundary/`: a flat outer patch against a parallelogram across one sphere, or against a
//!   sphere's cell; a sphere's cell against a parallelogram): they converge exponentially, and are estimated as smooth pairs by order
//!   doubling from order 4, accepted only after two comparisons (three orders).
//! * Other pairs across visibility boundaries: the outer integrand keeps kinks (a shadow edge meeting
//!   an inner edge), so successive orders — and a patch and its halves — can agree by
//!   accident. Four approximations are computed: the outer patch whole and split 2 × 2, each
//!   at orders p and p + 1 (both levels refined: the inner rule's order is the outer one's);
//!   the split at p + 1 is returned, and the estimate is 2 × the largest difference between
//!   the split at p + 1 and the other three and between the split at p and the two wholes.
//!   On 432 (geometry, order) cases with a cylinder occluder (parallel squares, walls inside
//!   a coaxial tube; references in closed form up to a 1-D integral) the largest |actual
//!   error| / difference is 1.01 outside the rounding level, hence the factor 2.
//! * The same patch twice (`Adjacency::Identical`) by the identical-panel transform
//!   (`singular/`): without an occluder that may cut the patch's view of itself, as a
//!   touching pair (orders 4, 6, …, both copies split 2 × 2 at `max_order`; a quarter of a
//!   tube's inside meets 1e-10 with 2.2e5 evaluations). With one, the shadow makes the
//!   integrand jump, and on a saddle the facing test puts kinks in it; the convergence is then
//!   algebraic: the value at p = `max_order` with 2 × the
//!   largest difference from orders p − 1, p − 2, p − 3 and p/2. Where that misses the
//!   tolerance, both copies are split 2 × 2 and the 16 sub-pairs routed anew (`split_where_cut`):
//!   the shadow falls on touching and separate sub-pairs, whose routes place it, and the
//!   sub-pairs along the diagonal shrink until none can be cut (a quarter of a sphere's inside
//!   from the pole to the equator around a concentric sphere: 9.4e-5 off as one leaf, 6e-13
//!   split, 0.7 s). At `max_depth` it says so with `converged = false` (three quarters of a
//!   tube's inside around a coaxial tube: 2.3e-6 actual against an estimate of 4.8e-4).
//!
//! * Self and edge pairs whose contact reaches a side collapsed to a point (a cone's apex)
//!   converge only algebraically (`singular/`): the same five-order estimate as an
//!   occluded self pair, not split where no occluder may cut (the cells at the apex stay
//!   algebraic at every level). Where one may, an edge pair is split 2 × 2 × 2 × 2 first, as
//!   any touching pair an occluder may cut: the shadow then falls on separate sub-pairs, whose
//!   boundary path places it, and the sub-pairs along the contact shrink until none can be
//!   cut (two quarters of a sphere's inside sharing a meridian from the pole, a concentric
//!   sphere inside: 7e-4 off as one algebraic leaf, 2e-8 split); a self pair is split as
//!   above where its leaf misses the tolerance.
//!
//! # Settings
//! `tolerance` must be positive and finite, `max_order` in 8..=[`MAX_ORDER`](crate::MAX_ORDER)
//! and `max_depth` ≤ [`MAX_DEPTH`]; anything else is `Err(InvalidSetting)`, checked before any
//! work. The sample buffers hold at most `max_order`² points, so `CAP` ≥ `max_order`²
//! (`Err(CapacityExceeded)` otherwise, also checked first).
//!
//! Files: the settings, the entry point and the recursion here; `leaves.rs` (leaf estimates),
//! `separate.rs` (separate pairs), `split.rs` (splitting).

use crate::error::PdmError;
pub use crate::estimate::Estimate;
use crate::pair::{route, Route};
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_evaluations, touching_unchecked, Adjacency};
use crate::surface::Surface;
use crate::visibility::Occluder;

mod leaves;
mod separate;
mod split;
use leaves::*;
use separate::*;
use split::*;

/// Largest accepted `max_depth`: at most 2^24 halvings deep. The recursion keeps no sample
/// buffer on the stack: they live in non-inlined frames that return before it recurses.
pub const MAX_DEPTH: u32 = 24;

/// Smallest accepted `max_order` (touching pairs compare orders 4, 6 and 8).
const MIN_ORDER: usize = 8;

/// Factor on the differences that estimate algebraically converging pairs (module docs).
const SAFETY: f64 = 2.0;

/// Rounding allowance on each leaf, in units of ε·|value|.
const ROUNDING: f64 = 128.0;

/// The smallest relative tolerance the refinement works to, in units of ε (twice the rounding
/// allowance, so that a leaf can meet it): 5.7e-14 in f64, 3.1e-5 in f32.
const PRECISION_FLOOR: f64 = 2.0 * ROUNDING;

/// Factor on [`Real::ELEMENTARY_ERROR`] times the pair's sensitivity magnitude in the allowance
/// for a fast sine and cosine ([`backend_allowance`]).
const BACKEND: f64 = 2.0;

/// The smallest relative tolerance the refinement works to with a fast sine and cosine, in
/// units of [`Real::ELEMENTARY_ERROR`]: twice the least allowance (8e-3 with micromath; 4e-15
/// with libm, below the rounding floor).
const BACKEND_FLOOR: f64 = 2.0 * BACKEND;

/// Sample pairs with cos θ down to this below zero count in [`backend_allowance`]: a turned
/// normal can bring them to face.
const TERMINATOR_MARGIN: f64 = 0.1;

/// π × the pair's sensitivity magnitude at Gauss order `order`, each sample pair weighted by
/// `extra(L)`: Σ w (sin θ_a cos⁺θ_b + cos⁺θ_a sin θ_b + 2 cos⁺θ_a cos⁺θ_b)·extra(L) / L² over
/// the sample pairs that face each other to within cos θ > −[`TERMINATOR_MARGIN`] on both
/// sides, visible or not (cos⁺ = max(cos, 0); [`backend_allowance`], [`position_allowance`]).
fn sensitivity<T, SA, SB, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    extra: impl Fn(T) -> T,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (sa, sb) = (PatchSamples::<T, CAP>::new(a, order)?, PatchSamples::<T, CAP>::new(b, order)?);
    let mut magnitude = T::ZERO;
    let margin = -T::from_f64(TERMINATOR_MARGIN);
    let sine = |c: T| (T::ONE - c * c).max(T::ZERO).sqrt();
    for p in sa.iter() {
        for q in sb.iter() {
            let d = q.point - p.point;
            let l2 = d.norm2();
            if !(l2 > T::ZERO) {
                continue;
            }
            let l = l2.sqrt();
            let e = d.scale(T::ONE / l);
            let (ca, cb) = (p.unit_normal.dot(e), -q.unit_normal.dot(e));
            if !(ca > margin && cb > margin) {
                continue;
            }
            let (pa, pb) = (ca.max(T::ZERO), cb.max(T::ZERO));
            let k = sine(ca) * pb + pa * sine(cb) + T::TWO * pa * pb;
            magnitude += p.weight * q.weight * k * extra(l) / l2;
        }
    }
    Ok(magnitude)
}

/// The error a fast sine and cosine ([`Real::sin_cos_fast`]: micromath's, ≈ 1e-3) put into the
/// pair's value, zero with libm's. Those place the sample points of curved surfaces up to
/// [`Real::ELEMENTARY_ERROR`] (relative to the surface's size) off the surface and turn their
/// normals by as much, so the value is that of slightly different surfaces: an error no
/// comparison of orders or halves can see. It is bounded by 2·`ELEMENTARY_ERROR` times the
/// pair's sensitivity magnitude S = ∫∫ (sin θ_a cos⁺θ_b + cos⁺θ_a sin θ_b + 2 cos⁺θ_a cos⁺θ_b)
/// / (π L²) dA_a dA_b (cos⁺ = max(cos, 0)) over the sample pairs that face each other to
/// within cos θ > −[`TERMINATOR_MARGIN`] on both sides, visible or not (a turned normal
/// changes cos θ by up to the turn times sin θ, so grazing and sliver pairs, whose values are
/// far below their S, get an allowance on S's scale), summed at order 8. The factor is measured,
/// not proved: on the sphere-in-cube scene's 355 cell pairs (sphere 4 × 8 and faces 3 × 3:
/// sphere cells against a face, faces against faces past the sphere; f32 with micromath
/// against f64) the largest error is 0.14 of the estimate, whose median is 2.4e-2 of the value.
#[inline(never)]
fn backend_allowance<T, SA, SB, const CAP: usize>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    if !crate::real::approximate_sin_cos::<T>() {
        return Ok(T::ZERO);
    }
    let magnitude = sensitivity::<T, SA, SB, CAP>(a, b, 8, |_| T::ONE)?;
    Ok(T::from_f64(BACKEND) * T::ELEMENTARY_ERROR * magnitude * T::FRAC_1_PI)
}

/// Factor on the positional model of [`position_allowance`] for two flat patches in front of
/// each other (measured, see there).
#[cfg_attr(not(feature = "closed-form"), allow(dead_code))]
const POSITION_FLAT: f64 = 0.3;

/// Factor on the sampled positional model of [`position_allowance`] (measured, see there).
const POSITION_SAMPLED: f64 = 0.1;

/// [`position_allowance`] is zero where the pair's reach times the sum of its patches'
/// perimeter / area is at most this (two squares of side ℓ: reach ≤ 5ℓ): its model would be
/// below a tenth of the rounding allowance there, unless a cosine is near zero.
const POSITION_GATE: f64 = 40.0;

/// Gauss order of the sampled positional model (curved, touching and occluded pairs).
const POSITION_ORDER: usize = 4;

/// The error that the rounding of the coordinates puts into the pair's value: a point of a
/// patch is computed at the magnitude of its coordinates, so it lies up to δ = ε·X off
/// (X the largest distance of the pair's points from the origin), which on patches far from
/// the origin for their size (a 1 cm cell at 10 m in f32: δ/side = 1.2e-4) moves every
/// corner, gap and shadow by far more than the rounding allowance covers. No comparison of
/// orders or halves can see it: the patches are, to the working precision, other patches.
///
/// The model is the first-order change of the integrand under moves of δ: the relative
/// change of the area elements (δ × perimeter / area per patch), of L² (2·2δ/L) and of each
/// cosine (for flat patches cos θ_a = h_a/L with h_a the height over a's plane: 2δ/h_a). For
/// two patches with straight edges, each on or in front of the other's plane with nothing
/// between, it is δ·(P_a + P_b + 2/h_a + 2/h_b + 4/max(h_a, h_b))·|value| with h the least
/// corner height (a quarter of the largest where the corners touch the plane), from the
/// corners alone;
/// otherwise δ·Σ w (2 cos⁺θ_a cos⁺θ_b + sin θ_a cos⁺θ_b + cos⁺θ_a sin θ_b)(P_a + P_b + 2/L)
/// / (π L²) at order [`POSITION_ORDER`] over the sample pairs that face each other (the
/// [`backend_allowance`] sensitivity, whose sine terms are the turns of the cosines). Times
/// [`POSITION_FLAT`] or [`POSITION_SAMPLED`]: the model assumes every point moved the worst
/// way at once, which the rounding errors of a pair's points are not; the factors are
/// measured, not proved: on 13 pair kinds (parallel cells, perpendicular cells touching along
/// an edge, at a corner and apart, cells on 2° and 10° folds and in a 10° V, a skew pair, a
/// sphere's and a cylinder's cell, coaxial disks, plates across a sphere) at 400 random
/// placements each, 10 to 10⁵ sizes from the origin, in f32 against f64, the least estimate /
/// actual error is 3.05 (parallel cells; the sampled model's least is 4.3) (BENCHMARKS.md,
/// "Far from the origin", and the `far_from_origin` example). Zero below [`POSITION_GATE`].
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn position_allowance<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    value: T,
    area_a: T,
    area_b: T,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    if !(area_a > T::ZERO && area_b > T::ZERO) {
        return Ok(T::ZERO);
    }
    let gate = T::from_f64(POSITION_GATE);
    // Patches with straight edges: the reach and perimeters from their corners.
    #[cfg(feature = "closed-form")]
    let corners = crate::pair::flat_corners(a).zip(crate::pair::flat_corners(b));
    #[cfg(not(feature = "closed-form"))]
    let corners: Option<(
        ([crate::vec3::Vec3<T>; 4], crate::vec3::Vec3<T>),
        ([crate::vec3::Vec3<T>; 4], crate::vec3::Vec3<T>),
    )> = None;
    let (reach, relative) = if let Some(((ca, _), (cb, _))) = corners {
        let reach = ca.iter().chain(cb.iter()).fold(T::ZERO, |m, c| m.max(c.norm()));
        let perimeter = |c: &[crate::vec3::Vec3<T>; 4]| {
            (c[1] - c[0]).norm() + (c[2] - c[1]).norm() + (c[3] - c[2]).norm() + (c[0] - c[3]).norm()
        };
        (reach, perimeter(&ca) / area_a + perimeter(&cb) / area_b)
    } else {
        let (ball_a, ball_b) = (a.enclosing_ball(), b.enclosing_ball());
        let reach = (ball_a.center.norm() + ball_a.radius).max(ball_b.center.norm() + ball_b.radius);
        // A cheap test first: a patch's perimeter by `side_lengths` stays below 10 × its
        // enclosing radius (a whole disk of radius R, about the worst: 14.4 R against a ball
        // of 1.69 R; a whole sphere 18.7 R against 2.25 R).
        let ten = T::from_f64(10.0);
        if !(reach * ten * (ball_a.radius / area_a + ball_b.radius / area_b) > gate) {
            return Ok(T::ZERO);
        }
        let perimeter = |(along_t, along_s): (T, T)| T::TWO * (along_t + along_s);
        (reach, perimeter(crate::patch::side_lengths(a)) / area_a + perimeter(crate::patch::side_lengths(b)) / area_b)
    };
    if !(reach * relative > gate) {
        return Ok(T::ZERO);
    }
    let delta = T::EPSILON * reach;
    #[cfg(feature = "closed-form")]
    if let Some(((ca, na), (cb, nb))) = corners {
        // The heights of one's corners over the other's plane: the least where all are above
        // it, a quarter of the largest where the patches touch the plane (a shared edge or
        // corner, a fold: the cosine is small only near the contact), none if a corner lies
        // behind it (a visibility cut; sampled). On the plane: within 8 δ, the heights' own
        // rounding.
        let band = T::from_f64(8.0) * delta;
        let height = |corners: &[crate::vec3::Vec3<T>; 4], origin: crate::vec3::Vec3<T>, n: crate::vec3::Vec3<T>| {
            let (least, most) = corners
                .iter()
                .fold((T::MAX, T::ZERO), |(lo, hi), &q| (lo.min(n.dot(q - origin)), hi.max(n.dot(q - origin))));
            if least > band {
                least
            } else if least >= -band {
                most * T::HALF * T::HALF
            } else {
                T::ZERO
            }
        };
        let (ha, hb) = (height(&cb, ca[0], na), height(&ca, cb[0], nb));
        if ha > T::ZERO
            && hb > T::ZERO
            && !occluders.may_block_between(&crate::pair::corner_ball(&ca), &crate::pair::corner_ball(&cb))
        {
            let two = T::TWO;
            let model = relative + two / ha + two / hb + two * two / ha.max(hb);
            return Ok(T::from_f64(POSITION_FLAT) * delta * model * value.abs());
        }
    }
    #[cfg(not(feature = "closed-form"))]
    let _ = (occluders, value);
    let magnitude = sensitivity::<T, SA, SB, CAP>(a, b, POSITION_ORDER, |l| relative + T::TWO / l)?;
    Ok(T::from_f64(POSITION_SAMPLED) * delta * magnitude * T::FRAC_1_PI)
}

/// Settings of the tolerance-driven mode (validated by [`adaptive_exchange`]; see the module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Adaptive<T> {
    /// Relative tolerance on each pair's exchange A_a·F_{a→b}: positive and finite. Below
    /// 256 ε (5.7e-14 in f64, 3.1e-5 in f32) the refinement works to 256 ε instead (the
    /// rounding allowance of every estimate, 128 ε, leaves nothing finer to reach), and the
    /// result has `converged = false` unless its estimate happens to meet the tolerance. With
    /// the `micromath` feature the f32 floor is 8e-3 (module docs).
    pub tolerance: T,
    /// Largest Gauss order before a pair is subdivided instead: 8..=`MAX_ORDER` (32). `CAP` must
    /// be ≥ `max_order`².
    pub max_order: usize,
    /// Largest number of successive subdivisions of a pair: ≤ [`MAX_DEPTH`].
    pub max_depth: u32,
    /// Absolute error budget on the pair's exchange A_a·F_{a→b} (area units): finite and ≥ 0.
    /// The result is converged when its estimate is at most `absolute + tolerance·|value|`.
    /// [`Adaptive::new`] sets 0: relative only. A pair whose exchange is zero or tiny (a cell
    /// that sees the other only past an occluder's rim, in a sliver) cannot meet a relative
    /// tolerance: without a budget it is refined to `max_depth` whatever the cost. The budget is
    /// shared out among the pieces a pair is split into (halves get half each, a 2 × 2 × 2 × 2
    /// split a sixteenth), so the sum of the leaves' estimates meets it.
    pub absolute: T,
}

impl<T: Real> Adaptive<T> {
    /// `tolerance` with max order 12 and max depth 6 (`CAP` ≥ 144).
    #[must_use]
    pub fn new(tolerance: T) -> Self {
        Self { tolerance, max_order: 12, max_depth: 6, absolute: T::ZERO }
    }

    /// The same settings with the absolute budget divided by `parts`: the share of each of
    /// `parts` pieces of a pair.
    pub(crate) fn share(self, parts: usize) -> Self {
        Self { absolute: self.absolute / T::from_usize(parts.max(1)), ..self }
    }

    /// Whether `error` meets the tolerance against `value`: at most `absolute +
    /// tolerance·|value|` (or below the smallest positive number: zero and zero).
    pub(crate) fn met(&self, value: T, error: T) -> bool {
        error <= self.absolute + self.tolerance * value.abs() || error <= T::MIN_POSITIVE
    }

    /// `Ok` if every setting is in range (module docs), `Err(InvalidSetting)` naming the first
    /// that is not.
    pub fn validate(&self) -> Result<(), PdmError> {
        if !(self.tolerance > T::ZERO && self.tolerance.is_finite()) {
            return Err(PdmError::InvalidSetting { name: "tolerance", expected: "positive and finite" });
        }
        if !(MIN_ORDER..=crate::gauss::MAX_ORDER).contains(&self.max_order) {
            return Err(PdmError::InvalidSetting { name: "max_order", expected: "in 8..=32 (MAX_ORDER)" });
        }
        if self.max_depth > MAX_DEPTH {
            return Err(PdmError::InvalidSetting { name: "max_depth", expected: "at most 24 (adaptive::MAX_DEPTH)" });
        }
        if !(self.absolute >= T::ZERO && self.absolute.is_finite()) {
            return Err(PdmError::InvalidSetting { name: "absolute", expected: "finite and at least 0" });
        }
        Ok(())
    }
}

/// A partial result inside the tolerance mode: a value, its error estimate (always present),
/// whether it met the tolerance, and its cost. [`adaptive_exchange`] returns it as an
/// [`Estimate`] with `error: Some(_)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tally<T> {
    value: T,
    error: T,
    converged: bool,
    evaluations: u64,
}

impl<T: Real> Tally<T> {
    /// A leaf's estimate: `difference` (already scaled) plus the rounding allowance; converged
    /// if it meets the settings' tolerance and budget ([`Adaptive::met`]).
    fn leaf(value: T, difference: T, settings: Adaptive<T>, evaluations: u64) -> Self {
        let error = difference.abs() + T::from_f64(ROUNDING) * T::EPSILON * value.abs();
        let converged = settings.met(value, error);
        Self { value, error, converged, evaluations }
    }

    fn zero(evaluations: u64) -> Self {
        Self { value: T::ZERO, error: T::ZERO, converged: true, evaluations }
    }

    fn add(&mut self, other: Self) {
        self.value += other.value;
        self.error += other.error;
        self.converged &= other.converged;
        self.evaluations = self.evaluations.saturating_add(other.evaluations);
    }
}

/// A_a·F_{a→b} to relative tolerance `settings.tolerance`, with an error estimate and a
/// `converged` flag (see the module docs: check [`Estimate::converged`] — at the depth limit
/// the value is returned with `converged = false`). `CAP` ≥ `max_order`²; invalid settings are
/// `Err(InvalidSetting)`, a smaller `CAP` `Err(CapacityExceeded)`, both before any work. The
/// value is checked against 0 ≤ A_a·F_{a→b} ≤ min(A_a, A_b) (`Err(InvalidResult)` otherwise).
///
/// ```
/// use pdm_kernel::{adaptive_exchange, vec3, Adaptive, Parallelogram, Patch};
/// // Unit squares 1 apart (C-11: 0.1998248956983874) to a relative tolerance of 1e-8.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let ceiling = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (Patch::whole(&floor)?, Patch::whole(&ceiling)?);
/// let e = adaptive_exchange::<f64, _, _, _, 144>(&a, &b, Adaptive::new(1e-8), &())?;
/// assert!(e.converged, "check it: false means the tolerance was not met");
/// let error = e.error.expect("the tolerance mode always estimates its error");
/// assert!(error <= 1e-8 * e.value);
/// assert!((e.value - 0.1998248956983874).abs() <= error); // A_a = 1
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn adaptive_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Estimate<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    settings.validate()?;
    let needed = settings.max_order * settings.max_order;
    if needed > CAP {
        return Err(PdmError::CapacityExceeded { needed, capacity: CAP });
    }
    crate::pair::backend_resolves(a, b)?;
    if crate::pair::on_one_convex_ball(a, b) {
        return Ok(Estimate { value: T::ZERO, error: Some(T::ZERO), converged: true, evaluations: 0 });
    }
    // Every leaf's estimate carries the rounding allowance ROUNDING·ε·|value|, so a leaf can
    // meet only a tolerance above it: below, the refinement would split every pair down to
    // `max_depth` without ever getting closer. It works to the precision floor instead, and
    // the result then says whether the tolerance asked for was met (it cannot be).
    let floor = (T::from_f64(PRECISION_FLOOR) * T::EPSILON).max(T::from_f64(BACKEND_FLOOR) * T::ELEMENTARY_ERROR);
    let work = Adaptive { tolerance: settings.tolerance.max(floor), ..settings };
    // Closed patches are cut at their seams first, as in `pair_exchange`.
    let mut e = Tally::zero(0);
    let pieces = work.share(crate::pair::piece_pairs(a, b, occluders));
    crate::pair::for_each_piece_pair(a, b, occluders, |pa, pb| {
        e.add(recurse::<T, SA, SB, O, CAP>(pa, pb, pieces, occluders, 0)?);
        Ok(())
    })?;
    e.error += backend_allowance::<T, SA, SB, CAP>(a, b)?;
    let (area_a, area_b) = (a.bounds_area(settings.max_order)?, b.bounds_area(settings.max_order)?);
    e.error += position_allowance::<T, SA, SB, O, CAP>(a, b, e.value, area_a, area_b, occluders)?;
    e.converged &= work.met(e.value, e.error);
    // The leaves are unchecked approximations: the total may overshoot [0, min(A_a, A_b)] by
    // its error, and is clamped there; beyond its error it is refused.
    e.value = crate::bounds::exchange_within(e.value, e.error, area_a, area_b)?;
    // The leaves judge their own estimates against their own values; a leaf of a tiny value
    // may miss that while the total meets the tolerance asked for (the pieces of a whole disk
    // far from the other's rim): the sum of the estimates bounds the total's error.
    e.converged |= work.met(e.value, e.error);
    e.converged &= work.tolerance == settings.tolerance || settings.met(e.value, e.error);
    Ok(Estimate { value: e.value, error: Some(e.error), converged: e.converged, evaluations: e.evaluations })
}

fn recurse<T, SA, SB, O, const CAP: usize>(
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
    let (adjacency, gap) = classify_near(a, b);
    // Two flat patches that see each other wholly: the contour form at two orders.
    #[cfg(feature = "closed-form")]
    if crate::pair::contour_applies(adjacency) {
        let lo_order = 8usize.min(settings.max_order);
        // Where the contour terms cancel beyond the working precision (f32 cells close
        // together) or the gap is below the geometry's resolution (`Unresolvable`), the 4-D
        // path below takes the pair instead if its Gauss rules resolve the pair at
        // `max_order`; otherwise (long strips close together, whose ends no node comes near)
        // two approximations can agree on a wrong value: the contour value stands with its
        // rounding bound in the estimate, and the refusal of an unresolvable gap stands.
        match contour_leaf(a, b, lo_order, settings, occluders) {
            Some(Err(PdmError::Unresolvable))
                if adjacency != Adjacency::Separate
                    || crate::pair::resolved::<T, SA, SB, CAP>(a, b, settings.max_order)? => {}
            Some(Ok((_, true)))
                if adjacency != Adjacency::Separate
                    || crate::pair::resolved::<T, SA, SB, CAP>(a, b, settings.max_order)? => {}
            None => {}
            Some(result) => return result.map(|(estimate, _)| estimate),
        }
    }
    match route(a, b, (adjacency, gap), occluders, depth < settings.max_depth) {
        // The transforms test occlusion only at their nodes: with an occluder that may cut the
        // pair, successive orders can agree on a wrong value.
        Route::SplitContact => split_both::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, 0),
        Route::Touching { adjacency, gap, collapsed: true } => {
            collapsed_contact::<T, SA, SB, O>(a, b, adjacency, gap, settings, occluders)
        }
        Route::Identical { gap, collapsed: true } => {
            let leaf = collapsed_contact::<T, SA, SB, O>(a, b, Adjacency::Identical, gap, settings, occluders)?;
            split_where_cut::<T, SA, SB, O, CAP>(a, b, leaf, settings, occluders, depth)
        }
        Route::Touching { adjacency, gap, collapsed: false } => {
            let eval = |p: usize| {
                Ok((touching_unchecked(a, b, adjacency, gap, p, occluders)?, touching_evaluations(adjacency, p)))
            };
            by_order_doubling::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, eval, 4, Split::Both)
        }
        Route::Identical { collapsed: false, .. } => identical::<T, SA, O, CAP>(a, settings, occluders, depth),
        Route::Separate => separate::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth),
        Route::ContactPastShadows => {
            #[cfg(feature = "closed-form")]
            if let Some(tally) = contact_past_shadows::<T, SA, SB, O, CAP>(a, b, settings, occluders)? {
                return Ok(tally);
            }
            separate::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth)
        }
    }
}

/// A touching flat pair across flat occluders ([`Route::ContactPastShadows`]): the unoccluded
/// exchange U in the tolerance mode at half the tolerance, less the blocked part B
/// ([`crate::boundary::Blocked`]) at orders 4, 6, … until its estimate (as
/// [`by_order_doubling`]'s, three orders at least) is within the other half of the tolerance
/// on U − B; the estimate is the sum of both. `None` where B does not apply or does not meet
/// its half by `max_order` (the caller then takes the pair by its other route, which splits).
#[cfg(feature = "closed-form")]
#[inline(never)]
fn contact_past_shadows<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Option<Tally<T>>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let half = Adaptive { tolerance: settings.tolerance * T::HALF, ..settings.share(2) };
    let Some(part) = crate::boundary::Blocked::new(a, b, occluders)? else { return Ok(None) };
    let blocked = |order: usize| part.sum(order);
    let first = 4usize.min(settings.max_order);
    let Some((mut previous, mut evaluations)) = blocked(first)? else { return Ok(None) };
    let unoccluded = recurse::<T, SA, SB, (), CAP>(a, b, half, &(), 0)?;
    evaluations = evaluations.saturating_add(unoccluded.evaluations);
    let mut previous_difference: Option<T> = None;
    let mut order = first + 2;
    while order <= settings.max_order {
        let Some((next, n)) = blocked(order)? else { return Ok(None) };
        evaluations = evaluations.saturating_add(n);
        let difference = (next - previous).abs();
        let estimate = previous_difference.map_or(difference, |d1| difference.max((d1 * difference).sqrt()))
            + T::from_f64(ROUNDING) * T::EPSILON * next.abs();
        let value = unoccluded.value - next;
        if previous_difference.is_some() && half.met(value, estimate) {
            return Ok(Some(Tally {
                value,
                error: unoccluded.error + estimate,
                converged: unoccluded.converged,
                evaluations,
            }));
        }
        previous = next;
        previous_difference = Some(difference);
        order += 2;
    }
    Ok(None)
}
