//! Form factors between patches by the PDM sum (`sum.rs`, eqs. (15)–(16)), with the pair
//! methods taking the pairs the sum cannot resolve; the self form factor of a concave patch.
//! Between subdivided surfaces: `substructure.rs` (eqs. (25)–(26)).

use crate::error::PdmError;
use crate::estimate::Estimate;
use crate::gauss::GaussRule;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
pub use crate::sum::{exchange, form_factor, RESOLVED_DISTANCE};
use crate::sum::{exchange_unchecked, samples_resolved};
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
