//! The PDM sum: form factors between patches, eqs. (15)–(16) (between subdivided surfaces by
//! substructuring, eqs. (25)–(26): `substructure.rs`).
//!
//! Eq. (15) gives F_{1→2} = 1/(π A₁) ∫∫∫∫ (n₁·e₁₂)(n₂·e₂₁)/L⁴ ds dt dφ dθ with unnormalised
//! normals. Eq. (16) writes its Gauss sum but omits the 1/π and the interval Jacobians (it is
//! stated on [−1, 1]); both are restored here:
//!
//! F_{a→b} = 1/(π A_a) Σ_k Σ_l w_k w_l · (n̂_k·e)(−n̂_l·e) / L⁴,   e = p_l − p_k, L = |e|,
//!
//! where w = (Gauss weights)·(Jacobian)·|n| comes from [`PatchSamples`] and only pairs that pass
//! the two-sided curvature test and are not occluded count (section 3).
//!
//! The term of the sum and the curvature test are the kernel's one integrand (`integrand.rs`),
//! evaluated as w_l · (n̂_k·e / L²) · (−n̂_l·e / L²) so that nothing overflows: the result is
//! unchanged (to a few ulps) for geometry scaled by 1e-12…1e12 in f64 and 1e-4…1e4 in f32
//! (tested).
//!
//! **Accuracy.** For patches well separated relative to their size (distance/size ≳ 2) the sum
//! converges exponentially with the order; a few digits at order 5, near machine precision by
//! order 12–16. Where the integrand is not smooth it converges algebraically: patches sharing an
//! edge or vertex (1/L² singularity: see the singular-pair treatment), and pairs straddling a
//! visibility boundary (terminator or shadow edge inside a patch).

use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::gauss::GaussRule;
use crate::integrand;
use crate::patch::{Patch, PatchGrid};
use crate::real::Real;
use crate::samples::{Ball, PatchSamples};
use crate::surface::Surface;
use crate::visibility::Occluder;

/// Settings of a patch-to-patch PDM sum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Quadrature {
    /// Gauss points per axis on the emitting patch a.
    pub order_a: usize,
    /// Gauss points per axis on the receiving patch b.
    pub order_b: usize,
}

impl Quadrature {
    /// The same order on both patches (the paper uses 5).
    #[must_use]
    pub const fn uniform(order: usize) -> Self {
        Self { order_a: order, order_b: order }
    }
}

/// The exchange integral A_a·F_{a→b} = (1/π) ∫∫ cos α_a cos α_b / L² dA_b dA_a, i.e. eq. (15) times A_a,
/// which is symmetric in a and b (reciprocity). Not divided by the area, so it adds over patches.
///
/// ```
/// use pdm_kernel::{exchange, vec3, Parallelogram, Patch, PatchSamples};
/// // Unit squares facing each other at distance 1 (C-11: F = 0.1998248956983874, A = 1),
/// // sampled once at order 16 and summed by eq. (16) in both directions.
/// let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let upper = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let a = PatchSamples::<f64, 256>::new(&Patch::whole(&lower)?, 16)?;
/// let b = PatchSamples::<f64, 256>::new(&Patch::whole(&upper)?, 16)?;
/// let (ab, ba) = (exchange(&a, &b, &())?, exchange(&b, &a, &())?);
/// assert!((ab - 0.1998248956983874).abs() < 1e-12 && (ab - ba).abs() < 1e-14);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn exchange<T, O, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    O: Occluder<T> + ?Sized,
{
    crate::bounds::exchange(exchange_sum(a, b, occluders), a.area(), b.area())
}

/// [`exchange`] without the bounds check (finite only): a part of a larger sum, or one of the
/// approximations the pair methods compare (see `bounds::finite`).
pub(crate) fn exchange_unchecked<T, O, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    O: Occluder<T> + ?Sized,
{
    crate::bounds::finite(exchange_sum(a, b, occluders))
}

/// The eq. 16 sum of [`exchange`] times 1/π, unchecked (the bounds check also rejects NaN).
#[inline(always)]
fn exchange_sum<T, O, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
    occluders: &O,
) -> T
where
    T: Real,
    O: Occluder<T> + ?Sized,
{
    let sum = if occluders.may_block_between(&a.bounds(), &b.bounds()) {
        pdm_sum(a, b, Some(occluders))
    } else {
        pdm_sum::<T, O, CA, CB>(a, b, None)
    };
    sum * T::FRAC_1_PI
}

/// F_{a→b} between two sampled patches by eqs. (15)–(16) with the 1/π and Jacobians restored,
/// with the curvature tests and `occluders`. `Err(InvalidResult)` if the sum is not finite.
///
/// ```
/// use pdm_kernel::{form_factor, vec3, Parallelogram, Patch, PatchSamples, Sphere};
/// // A 2 × 2 square 1 below a 1 × 1 square, centred, facing it (catalogue C-11 generalised:
/// // the bigger one's view of the smaller is A_small/A_big times the other's).
/// let big = Parallelogram::new(vec3(-1.0, -1.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0))?;
/// let small = Parallelogram::new(vec3(-0.5, -0.5, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let a = PatchSamples::<f64, 256>::new(&Patch::whole(&big)?, 16)?;
/// let b = PatchSamples::<f64, 256>::new(&Patch::whole(&small)?, 16)?;
/// let (ab, ba) = (form_factor(&a, &b, &())?, form_factor(&b, &a, &())?);
/// assert!((4.0 * ab - ba).abs() < 1e-13); // reciprocity: A_a F_ab = A_b F_ba
/// // A ball between them hides part of the view.
/// let ball = Sphere::outer(vec3(0.0, 0.0, 0.5), 0.2)?;
/// assert!(form_factor(&a, &b, &ball)? < ab);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn form_factor<T, O, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    O: Occluder<T> + ?Sized,
{
    // `exchange` already bounds A_a·F_{a→b} by min(A_a, A_b), so F ≤ 1 here.
    Ok(exchange(a, b, occluders)? / a.area())
}

/// F_{a→b} between two patches by the PDM sum at the orders of `quadrature` (buffers of
/// capacity `CAP` on the stack: use `CAP ≥ order²`, e.g. 25 for the paper's order 5).
///
/// Where the sum cannot resolve the pair it is not used: patches that touch along an edge or at
/// a corner, or nearly (`classify_near`), the same patch twice, and patches closer than
/// [`RESOLVED_DISTANCE`] node spacings are integrated by [`crate::pair_exchange`] at the same
/// order instead (the touching transforms, the self integral, the visibility-boundary path;
/// `CAP ≥ (order + 1)²` keeps the order on a self pair, else it is lowered by one). The
/// compile-time-order twins in [`crate::fixed`] are the bare sum and do not do this.
///
/// ```
/// use pdm_kernel::{form_factor_between, Parallelogram, Patch, Quadrature, vec3};
/// // Two unit squares facing each other at distance 1 (catalogue C-11: 0.19982489569838…).
/// let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let upper = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let f = form_factor_between::<f64, _, _, _, 256>(
///     &Patch::whole(&lower)?, &Patch::whole(&upper)?, Quadrature::uniform(16), &())?;
/// assert!((f - 0.1998248956983874).abs() < 1e-12);
/// // Perpendicular squares sharing an edge (C-14: 0.2000437760754…): the bare sum at order 16
/// // is 20 % off here; the shared-edge transform takes the pair.
/// let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0))?;
/// let f = form_factor_between::<f64, _, _, _, 256>(
///     &Patch::whole(&lower)?, &Patch::whole(&wall)?, Quadrature::uniform(16), &())?;
/// assert!((f - 0.20004377607540316).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn form_factor_between<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    quadrature: Quadrature,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule_a = GaussRule::<T>::new(quadrature.order_a)?;
    let rule_b = GaussRule::<T>::new(quadrature.order_b)?;
    let (exchange, area) = resolved_exchange::<T, SA, SB, O, CAP>(a, b, &rule_a, &rule_b, occluders)?;
    crate::bounds::form_factor(exchange.value / area)
}

/// Node spacings (the larger patch's sample diameter over its order) below which two patches
/// are too close for the PDM sum: its integrand then varies within one spacing, and the error
/// falls only slowly with the order (facing unit squares 0.1 apart: 1 % off at order 16).
pub const RESOLVED_DISTANCE: usize = 2;

/// A_a·F_{a→b} by the PDM sum where it resolves the pair, else by [`crate::pair_exchange`] at
/// the same order (see [`form_factor_between`]), with its evaluations; and A_a from a's
/// samples.
pub(crate) fn resolved_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    rule_a: &GaussRule<T>,
    rule_b: &GaussRule<T>,
    occluders: &O,
) -> Result<(Estimate<T>, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (plain, area) = plain_if_resolved::<T, SA, SB, O, CAP>(a, b, rule_a, rule_b, occluders)?;
    if let Some(e) = plain {
        let points = |rule: &GaussRule<T>| (rule.order() * rule.order()) as u64;
        return Ok((Estimate::fixed(e, points(rule_a).saturating_mul(points(rule_b))), area));
    }
    let order = rule_a.order().max(rule_b.order()).max(2);
    let settings = crate::pair::PairSettings { order, singular_order: order, boundaries: true };
    Ok((crate::pair::pair_exchange::<T, SA, SB, O, CAP>(a, b, settings, occluders)?, area))
}

/// The PDM sum A_a·F_{a→b} if it resolves the pair (`None` if not: touching, identical or
/// closer than [`RESOLVED_DISTANCE`] spacings), and A_a. Its two sample buffers live in this
/// frame only, which returns before the pair path samples the patches again.
#[inline(never)]
fn plain_if_resolved<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    rule_a: &GaussRule<T>,
    rule_b: &GaussRule<T>,
    occluders: &O,
) -> Result<(Option<T>, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut sa = PatchSamples::<T, CAP>::empty();
    let mut sb = PatchSamples::<T, CAP>::empty();
    sa.fill_with_rules(a, rule_a, rule_a)?;
    sb.fill_with_rules(b, rule_b, rule_b)?;
    if crate::singular::classify_near(a, b).0 != crate::singular::Adjacency::Separate {
        return Ok((None, sa.area()));
    }
    if !samples_resolved(&sa, rule_a.order(), &sb, rule_b.order()) {
        return Ok((None, sa.area()));
    }
    Ok((Some(exchange(&sa, &sb, occluders)?), sa.area()))
}

/// Whether Gauss rules of orders `order_a`, `order_b` resolve the pair sampled as `sa`, `sb`:
/// its closest sample points are at least [`RESOLVED_DISTANCE`] node spacings apart (a
/// spacing: a patch's sample-ball diameter / its order), so the kernel varies over several
/// nodes of each rule.
pub(crate) fn samples_resolved<T: Real, const CA: usize, const CB: usize>(
    sa: &PatchSamples<T, CA>,
    order_a: usize,
    sb: &PatchSamples<T, CB>,
    order_b: usize,
) -> bool {
    let spacing = |ball: Ball<T>, order: usize| ball.radius * T::TWO / T::from_usize(order.max(1));
    let (ba, bb) = (sa.bounds(), sb.bounds());
    let limit = spacing(ba, order_a).max(spacing(bb, order_b)) * T::from_usize(RESOLVED_DISTANCE);
    let limit2 = limit * limit;
    // The sample balls' gap bounds every sample distance from below: far pairs skip the scan.
    let close = (ba.center - bb.center).norm() - ba.radius - bb.radius < limit
        && sa.iter().any(|p| {
            sb.iter().any(|q| {
                let e = q.point - p.point;
                e.dot(e) < limit2
            })
        });
    !close
}

/// F_{a→a}: the fraction of a concave patch's radiation that falls on the patch itself
/// (section 3.3, F_ii ≠ 0). The two copies of the patch are sampled at orders p and p + 1,
/// whose Gauss nodes interlace and never coincide, so no sample pair has L = 0. Exact (to the
/// rule) when the integrand is smooth, e.g. on the inside of a sphere where it is constant;
/// zero for flat and convex patches. Elsewhere the kernel's direction-dependent limit on the
/// diagonal makes it converge only algebraically (≈ p^−1.3 on a tube's inside);
/// [`crate::pair_exchange`] with the patch twice uses the identical-panel transform instead,
/// which converges exponentially. Needs `order + 1 ≤ MAX_ORDER` and `CAP ≥ (order + 1)²`.
///
/// ```
/// use pdm_kernel::{self_form_factor, vec3, ParamRect, Patch, Sphere};
/// use core::f64::consts::PI;
/// // Inside a sphere every element sees any area A in the fraction A / (4πR²): a patch of the
/// // inside of a unit sphere sees itself in the fraction of the sphere it covers.
/// let sphere = Sphere::inner(vec3(0.0, 0.0, 0.0), 1.0)?;
/// let patch = Patch::new(&sphere, ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 2.0 })?;
/// let f = self_form_factor::<f64, _, _, 256>(&patch, 12, &())?;
/// assert!((f - patch.area(16)? / (4.0 * PI)).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn self_form_factor<T, S, O, const CAP: usize>(
    patch: &Patch<'_, T, S>,
    order: usize,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (e, area) = self_exchange_unchecked::<T, S, O, CAP>(patch, order, occluders)?;
    crate::bounds::form_factor(e / area)
}

/// A_a·F_{a→a} by [`self_form_factor`]'s rule without the bounds check, and the area it is
/// normalised by (the mean of the two copies' areas, which keeps reciprocity exact).
pub(crate) fn self_exchange_unchecked<T, S, O, const CAP: usize>(
    patch: &Patch<'_, T, S>,
    order: usize,
    occluders: &O,
) -> Result<(T, T), PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let a = PatchSamples::<T, CAP>::new(patch, order)?;
    let b = PatchSamples::<T, CAP>::new(patch, order.saturating_add(1))?;
    Ok((exchange_unchecked(&a, &b, occluders)?, (a.area() + b.area()) * T::HALF))
}

/// F_{A→B} between the patches of grid `a` and grid `b` by substructuring
/// ([`crate::surface_exchange`] with [`crate::Method::Plain`]): each patch pair as by
/// [`form_factor_between`] (the PDM sum, or [`crate::pair_exchange`] on the pairs the sum cannot
/// resolve: adjacent and identical patches, patches closer than [`RESOLVED_DISTANCE`]
/// spacings), divided by A_A, the sum of the patch areas by eq. (12) with the same rule's
/// weights (so that a surface's factors to a closed enclosure sum to 1 up to the quadrature
/// error). Every patch is re-sampled for each pair; nothing is allocated.
///
/// ```
/// use pdm_kernel::{surface_form_factor, vec3, Parallelogram, PatchGrid, Quadrature};
/// // Perpendicular unit squares sharing an edge (C-14: 0.2000437760754...), each cut 2 × 2:
/// // the pairs along the shared edge go to the shared-edge transform, the others to the sum.
/// let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 0.0))?;
/// let (a, b) = (PatchGrid::new(&floor, 2, 2)?, PatchGrid::new(&wall, 2, 2)?);
/// let f = surface_form_factor::<f64, _, _, _, 256>(a, b, Quadrature::uniform(12), &())?;
/// assert!((f - 0.20004377607540316).abs() < 1e-9);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn surface_form_factor<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    quadrature: Quadrature,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule_a = GaussRule::<T>::new(quadrature.order_a)?;
    let rule_b = GaussRule::<T>::new(quadrature.order_b)?;
    let (total, area) = crate::substructure::plain_total::<T, SA, SB, O, CAP>(a, b, &rule_a, &rule_b, occluders)?;
    crate::bounds::form_factor(total.value / area)
}

/// Σ_k w_k Σ_l w_l (n̂_k·e / L²)(−n̂_l·e / L²) over mutually facing, unoccluded pairs.
#[inline]
fn pdm_sum<T, O, const CA: usize, const CB: usize>(
    a: &PatchSamples<T, CA>,
    b: &PatchSamples<T, CB>,
    occluders: Option<&O>,
) -> T
where
    T: Real,
    O: Occluder<T> + ?Sized,
{
    let (ax, ay, az, anx, any, anz, aw) = a.columns();
    let cols = b.columns();
    let mut total = T::ZERO;
    let outer = ax.iter().zip(ay).zip(az).zip(anx).zip(any).zip(anz).zip(aw);
    for ((((((&px, &py), &pz), &nxa), &nya), &nza), &wa) in outer {
        let inner = match occluders {
            None => inner_sum_unoccluded([px, py, pz], [nxa, nya, nza], cols),
            Some(o) => inner_sum_occluded([px, py, pz], [nxa, nya, nza], cols, o),
        };
        total += wa * inner;
    }
    total
}

/// Lanes of the branch-free inner loop: independent partial sums that the compiler keeps in
/// SIMD registers (no reassociation of one sum is needed, so no fast-math).
const LANES: usize = 8;

type Columns<'c, T> = (&'c [T], &'c [T], &'c [T], &'c [T], &'c [T], &'c [T], &'c [T]);

/// One term of the sum: w_b (n̂_a·e/L²)(−n̂_b·e/L²) if the pair passes both curvature tests
/// (sections 3.1–3.2), else 0; branch-free ([`integrand::term`]).
#[inline(always)]
fn term<T: Real>(p: [T; 3], n: [T; 3], q: [T; 3], m: [T; 3], wb: T) -> T {
    let v = |c: [T; 3]| crate::vec3::vec3(c[0], c[1], c[2]);
    let (ca, cb, l2) = integrand::cosines(v(p), v(n), v(q), v(m));
    integrand::term(wb, ca, cb, l2)
}

/// Inner sum without occluders, in `LANES` independent partial sums.
#[inline(always)]
fn inner_sum_unoccluded<T: Real>(p: [T; 3], n: [T; 3], cols: Columns<'_, T>) -> T {
    let (bx, by, bz, bnx, bny, bnz, bw) = cols;
    let mut lanes = [T::ZERO; LANES];
    let chunks = bx
        .chunks_exact(LANES)
        .zip(by.chunks_exact(LANES))
        .zip(bz.chunks_exact(LANES))
        .zip(bnx.chunks_exact(LANES))
        .zip(bny.chunks_exact(LANES))
        .zip(bnz.chunks_exact(LANES))
        .zip(bw.chunks_exact(LANES));
    for ((((((cx, cy), cz), cnx), cny), cnz), cw) in chunks {
        let lane_iter = lanes.iter_mut().zip(cx).zip(cy).zip(cz).zip(cnx).zip(cny).zip(cnz).zip(cw);
        for (((((((acc, &qx), &qy), &qz), &mx), &my), &mz), &wb) in lane_iter {
            *acc += term(p, n, [qx, qy, qz], [mx, my, mz], wb);
        }
    }
    let done = bx.len() - bx.len() % LANES;
    fn rest<T>(c: &[T], done: usize) -> &[T] {
        c.get(done..).unwrap_or_default()
    }
    let rest = |c| rest(c, done);
    let tail = rest(bx).iter().zip(rest(by)).zip(rest(bz)).zip(rest(bnx)).zip(rest(bny)).zip(rest(bnz)).zip(rest(bw));
    let mut sum = T::ZERO;
    for ((((((&qx, &qy), &qz), &mx), &my), &mz), &wb) in tail {
        sum += term(p, n, [qx, qy, qz], [mx, my, mz], wb);
    }
    for lane in lanes {
        sum += lane;
    }
    sum
}

/// Inner sum with occluders: the occlusion test runs only for pairs that pass the curvature test.
#[inline(always)]
fn inner_sum_occluded<T: Real, O: Occluder<T> + ?Sized>(
    p: [T; 3],
    n: [T; 3],
    cols: Columns<'_, T>,
    occluders: &O,
) -> T {
    let (bx, by, bz, bnx, bny, bnz, bw) = cols;
    let pv = crate::vec3::vec3(p[0], p[1], p[2]);
    let mut inner = T::ZERO;
    let it = bx.iter().zip(by).zip(bz).zip(bnx).zip(bny).zip(bnz).zip(bw);
    for ((((((&qx, &qy), &qz), &mx), &my), &mz), &wb) in it {
        let t = term(p, n, [qx, qy, qz], [mx, my, mz], wb);
        if t > T::ZERO && !occluders.blocks(pv, crate::vec3::vec3(qx, qy, qz)) {
            inner += t;
        }
    }
    inner
}
