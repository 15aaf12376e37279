//! One entry point for any pair of patches: picks the integration method the pair needs.
//!
//! - Touching pairs (shared edge or vertex, found by [`crate::singular::classify_near`], also
//!   when they are only nearly touching) use the regularising
//!   transforms of [`crate::singular`], converging exponentially with `singular_order`.
//! - The same patch twice uses the interlaced-order self integral ([`crate::self_form_factor`]).
//! - Separate pairs use the PDM sum at `order`. With `boundaries` on, a pair that straddles a
//!   back-face cut or that an occluder may cut gets the visibility boundaries placed into the
//!   inner rule ([`crate::boundary`]; the outer patch is also split
//!   [`OCCLUDED_OUTER_SPLIT`]² when an occluder may cut); smooth, unoccludable pairs keep the
//!   plain sum.

use crate::adaptive::straddles_curvature_cut;
use crate::boundary::boundary_exchange_counted;
use crate::error::PdmError;
use crate::form_factor::exchange;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_exchange, Adjacency};
use crate::surface::Surface;
use crate::visibility::Occluder;

/// Cells per side into which the outer patch of a pair that an occluder may cut is split.
/// The inner integral is exponential in the order (closed-form boundaries), the outer one only
/// algebraic in the cell size (kinks where a shadow boundary meets the inner patch's corners or
/// edges), so finer outer cells at a lower order pay: on the paper's cube (280 patches,
/// face → face) 2 × 2 at order 12 gave 1.1e-6 in 10.6 s, 3 × 3 at order 8 6.5e-8 in 6.0 s and
/// at order 6 2.6e-7 in 2.4 s (R = 0.7 and 2 and 86 patches: the same ranking at equal cost).
pub const OCCLUDED_OUTER_SPLIT: usize = 3;

/// How to integrate a pair of patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairSettings {
    /// Gauss order per axis for separate pairs.
    pub order: usize,
    /// Gauss order per variable for touching pairs (6·order⁴ evaluations for a shared edge).
    pub singular_order: usize,
    /// Place visibility boundaries into the inner rule (exact inner integrals on straddling
    /// pairs) instead of letting the fixed rule sample across them.
    pub boundaries: bool,
}

impl PairSettings {
    /// Accurate defaults: order 16, singular order 12, boundaries on (≈1e-12 on smooth pairs).
    pub const ACCURATE: Self = Self { order: 16, singular_order: 12, boundaries: true };
}

/// A_a·F_{a→b} for any two patches (symmetric in a and b), by the method the pair needs.
/// `CAP` bounds the samples of one patch (≥ order²).
pub fn pair_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    pair_exchange_counted::<T, SA, SB, O, CAP>(a, b, settings, occluders).map(|(value, _)| value)
}

/// [`pair_exchange`] and the work it did, in integrand evaluations: kernel evaluations and
/// visibility probes on the boundary path ([`crate::boundary_exchange_counted`]), order⁴ for a
/// plain sum and order⁴ more for the straddle check, 6·p⁴ for a shared edge and 4·p⁴ for a
/// shared vertex (p = `singular_order`), (order·(order + 1))² for a self pair.
pub fn pair_exchange_counted<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (value, count) = dispatch::<T, SA, SB, O, CAP>(a, b, settings, occluders)?;
    let order = settings.order.max(2);
    let value = crate::bounds::exchange(value, a.area(order)?, b.area(order)?)?;
    Ok((value, count))
}

fn dispatch<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: PairSettings,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let p4 = (settings.order as u64).pow(4);
    let (adjacency, gap) = classify_near(a, b);
    match adjacency {
        Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. } => {
            let q4 = (settings.singular_order as u64).pow(4);
            let count = if matches!(adjacency, Adjacency::SharedEdge { .. }) { 6 * q4 } else { 4 * q4 };
            Ok((touching_exchange(a, b, adjacency, gap, settings.singular_order, occluders)?, count))
        }
        Adjacency::Identical => {
            let f = crate::form_factor::self_form_factor::<T, SA, O, CAP>(a, settings.order, occluders)?;
            let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
            let q = (settings.order * (settings.order + 1)) as u64;
            Ok((f * sa.area(), q * q))
        }
        Adjacency::Separate => {
            let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
            let sb = PatchSamples::<T, CAP>::new(b, settings.order)?;
            if !settings.boundaries {
                return Ok((exchange(&sa, &sb, occluders)?, p4));
            }
            // The sample balls decide for the plain sum; the integrand is smooth only if no
            // occluder cuts any segment between the patches (enclosing balls).
            let may_occlude = occluders.may_block_between(&sa.bounds(), &sb.bounds())
                || occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball());
            if may_occlude {
                // Shadow edges crossing b make the outer integrand kink where they touch b's
                // edges; the outer patch is split (see OCCLUDED_OUTER_SPLIT).
                let (mut total, mut count) = (T::ZERO, 0u64);
                let r = a.rect();
                let n = OCCLUDED_OUTER_SPLIT;
                for k in 0..n * n {
                    let child = Patch::new(a.surface(), r.cell(k / n, k % n, n, n))?;
                    let (v, c) = boundary_exchange_counted::<T, SA, SB, O, CAP>(&child, b, settings.order, occluders)?;
                    total += v;
                    count = count.saturating_add(c);
                }
                Ok((total, count))
            } else if straddles_curvature_cut(&sa, &sb) {
                let (v, c) = boundary_exchange_counted::<T, SA, SB, (), CAP>(a, b, settings.order, &())?;
                Ok((v, c.saturating_add(p4)))
            } else {
                // Smooth pair: nothing to place into the rule, no occluder can cut it.
                Ok((exchange(&sa, &sb, &())?, 2 * p4))
            }
        }
    }
}
