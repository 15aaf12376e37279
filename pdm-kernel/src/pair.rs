//! One entry point for any pair of patches: picks the integration method the pair needs.
//!
//! - Touching pairs (shared edge or vertex, found by [`crate::singular::classify_near`], also
//!   when they are only nearly touching) use the regularising
//!   transforms of [`crate::singular`], converging exponentially with `singular_order`.
//! - The same patch twice uses the interlaced-order self integral ([`crate::self_form_factor`]).
//! - Separate pairs use the PDM sum at `order`, with the visibility boundaries (back-face cut
//!   and occluder shadows) placed into the inner rule when `boundaries` is on
//!   ([`crate::boundary`]).

use crate::boundary::boundary_exchange;
use crate::error::PdmError;
use crate::form_factor::exchange;
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::singular::{classify_near, touching_exchange, Adjacency};
use crate::surface::Surface;
use crate::visibility::Occluder;

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
            if settings.boundaries {
                boundary_exchange::<T, SA, SB, O, CAP>(a, b, settings.order, occluders)
            } else {
                let sa = PatchSamples::<T, CAP>::new(a, settings.order)?;
                let sb = PatchSamples::<T, CAP>::new(b, settings.order)?;
                exchange(&sa, &sb, occluders)
            }
        }
    }
}
