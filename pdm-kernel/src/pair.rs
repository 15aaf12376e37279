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
use crate::boundary::boundary_exchange;
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
    let (adjacency, gap) = classify_near(a, b);
    match adjacency {
        Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. } => {
            touching_exchange(a, b, adjacency, gap, settings.singular_order, occluders)
        }
        Adjacency::Identical => {
            let f = crate::form_factor::self_form_factor::<T, SA, O, CAP>(a, settings.order, occluders)?;
            let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
            Ok(f * sa.area())
        }
        Adjacency::Separate => {
            let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
            let sb = PatchSamples::<T, CAP>::new(b, settings.order)?;
            if !settings.boundaries {
                return exchange(&sa, &sb, occluders);
            }
            let may_occlude = occluders.may_block_between(&sa.bounds(), &sb.bounds());
            if may_occlude {
                // Shadow edges crossing b make the outer integrand kink where they touch b's
                // edges; the outer patch is split (see OCCLUDED_OUTER_SPLIT).
                let mut total = T::ZERO;
                let r = a.rect();
                let n = OCCLUDED_OUTER_SPLIT;
                for k in 0..n * n {
                    let child = Patch::new(a.surface(), r.cell(k / n, k % n, n, n))?;
                    total += boundary_exchange::<T, SA, SB, O, CAP>(&child, b, settings.order, occluders)?;
                }
                Ok(total)
            } else if straddles_curvature_cut(&sa, &sb) {
                boundary_exchange::<T, SA, SB, (), CAP>(a, b, settings.order, &())
            } else {
                // Smooth pair: nothing to place into the rule, no occluder can cut it.
                exchange(&sa, &sb, &())
            }
        }
    }
}
