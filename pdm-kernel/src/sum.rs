//! The PDM sum on sampled patches, eqs. (15)–(16) (its entry points on patches: `form_factor.rs`;
//! between subdivided surfaces by substructuring, eqs. (25)–(26): `substructure.rs`).
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
use crate::integrand;
use crate::real::Real;
use crate::samples::{Ball, PatchSamples};
use crate::visibility::Occluder;

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

/// Node spacings (the larger patch's sample diameter over its order) below which two patches
/// are too close for the PDM sum: its integrand then varies within one spacing, and the error
/// falls only slowly with the order (facing unit squares 0.1 apart: 1 % off at order 16).
pub const RESOLVED_DISTANCE: usize = 2;

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
