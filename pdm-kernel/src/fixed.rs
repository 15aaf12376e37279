//! Form factors with the Gauss rules chosen by the caller: a compile-time order (`…_fixed`) or
//! rules built beforehand (`…_with_rules`), instead of the run-time orders of a [`Quadrature`].
//!
//! The functions of [`crate::form_factor`](mod@crate::form_factor) take a [`Quadrature`], i.e. orders known only at run
//! time, and so link the Gauss tables of every order 1..=[`MAX_ORDER`] (4.2 KB in f32, 8.4 KB in
//! f64). Firmware that uses one order can name it at compile time here and link that order's
//! table only (40 B for order 5 in f32); a module that offers a range of orders can build its
//! rules with [`GaussRule::new_up_to`] and link orders 1..=bound only.
//!
//! These are the bare PDM sum, nothing else linked: on pairs the sum resolves they are
//! bit-identical to the [`Quadrature`] versions (same rules, same sums in the same order), but
//! they do not hand touching, identical or too close patches to [`crate::pair_exchange`] as
//! those do. There the bare sum is wrong (perpendicular squares sharing an edge, C-14: 20 % off
//! at order 16): keep such pairs away from these functions, or use the [`Quadrature`] versions.
//!
//! ```
//! use pdm_kernel::{form_factor_between, Parallelogram, Patch, Quadrature, vec3};
//! use pdm_kernel::fixed::form_factor_between_fixed;
//! let lower = Parallelogram::new(vec3(0.0_f32, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
//! let upper = Parallelogram::new(vec3(0.0_f32, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
//! let (a, b) = (Patch::whole(&lower)?, Patch::whole(&upper)?);
//! // Order 5 on both patches, sample buffers of 5² = 25: only order 5's table is linked.
//! let f = form_factor_between_fixed::<f32, _, _, _, 5, 25>(&a, &b, &())?;
//! assert_eq!(f, form_factor_between::<f32, _, _, _, 25>(&a, &b, Quadrature::uniform(5), &())?);
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! [`Quadrature`]: crate::form_factor::Quadrature
//! [`MAX_ORDER`]: crate::gauss::MAX_ORDER

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::patch::{Patch, PatchGrid};
use crate::real::Real;
use crate::samples::PatchSamples;
use crate::sum::{exchange, form_factor};
use crate::surface::Surface;
use crate::visibility::Occluder;

/// [`crate::form_factor_between`] with the rules given: `rule_a` on both axes of `a`, `rule_b` on
/// both axes of `b` (buffers of capacity `CAP ≥ order²` on the stack).
///
/// ```
/// use pdm_kernel::{vec3, GaussRule, Parallelogram, Patch};
/// use pdm_kernel::fixed::form_factor_between_with_rules;
/// // C-11 (0.1998248956983874) with rules built once, linking only orders 1..=16.
/// let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let upper = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let rule = GaussRule::<f64>::new_up_to::<16>(16)?;
/// let (a, b) = (Patch::whole(&lower)?, Patch::whole(&upper)?);
/// let f = form_factor_between_with_rules::<f64, _, _, _, 256>(&a, &b, &rule, &rule, &())?;
/// assert!((f - 0.1998248956983874).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn form_factor_between_with_rules<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    rule_a: &GaussRule<T>,
    rule_b: &GaussRule<T>,
    occluders: &O,
) -> Result<T, PdmError>
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
    form_factor(&sa, &sb, occluders)
}

/// [`crate::surface_form_factor`] (substructuring, eqs. (25)–(26)) with the rules given: `rule_a`
/// on every patch of grid `a`, `rule_b` on every patch of grid `b`. The bare sum on every pair
/// (as [`crate::Method::Paper`]), so keep touching patches away (see the module docs).
///
/// ```
/// use pdm_kernel::{vec3, GaussRule, Parallelogram, PatchGrid};
/// use pdm_kernel::fixed::surface_form_factor_with_rules;
/// // C-11 with both squares cut 2 × 2 (no pair touches: they are 1 apart).
/// let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
/// let upper = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
/// let rule = GaussRule::<f64>::new(12)?;
/// let (a, b) = (PatchGrid::new(&lower, 2, 2)?, PatchGrid::new(&upper, 2, 2)?);
/// let f = surface_form_factor_with_rules::<f64, _, _, _, 144>(a, b, &rule, &rule, &())?;
/// assert!((f - 0.1998248956983874).abs() < 1e-12);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
pub fn surface_form_factor_with_rules<T, SA, SB, O, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    rule_a: &GaussRule<T>,
    rule_b: &GaussRule<T>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total_area = T::ZERO;
    let mut total_exchange = T::ZERO;
    let mut sa = PatchSamples::<T, CAP>::empty();
    let mut sb = PatchSamples::<T, CAP>::empty();
    for pa in a {
        sa.fill_with_rules(&pa, rule_a, rule_a)?;
        total_area += sa.area();
        for pb in b.clone() {
            sb.fill_with_rules(&pb, rule_b, rule_b)?;
            total_exchange += exchange(&sa, &sb, occluders)?;
        }
    }
    crate::bounds::form_factor(total_exchange / total_area)
}

/// [`crate::form_factor_between`] at the compile-time order `N` on both patches
/// (`Quadrature::uniform(N)`), with buffers of capacity `CAP`. `1 ≤ N ≤ MAX_ORDER` and
/// `N² ≤ CAP` are checked at compile time. Links only order N's Gauss table (an example is in
/// the [module docs](self)).
pub fn form_factor_between_fixed<T, SA, SB, O, const N: usize, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    const {
        assert!(N * N <= CAP, "CAP must hold N² samples");
    }
    let rule = GaussRule::<T>::fixed::<N>();
    form_factor_between_with_rules::<T, SA, SB, O, CAP>(a, b, &rule, &rule, occluders)
}

/// [`crate::surface_form_factor`] at the compile-time order `N` on every patch
/// (`Quadrature::uniform(N)`), with buffers of capacity `CAP`. `1 ≤ N ≤ MAX_ORDER` and
/// `N² ≤ CAP` are checked at compile time. Links only order N's Gauss table.
///
/// ```
/// use pdm_kernel::{surface_form_factor, vec3, Parallelogram, PatchGrid, Quadrature, Sphere};
/// use pdm_kernel::fixed::surface_form_factor_fixed;
/// let sphere = Sphere::outer(vec3(0.0_f32, 0.0, 0.0), 1.0)?;
/// let floor = Parallelogram::new(vec3(-3.0_f32, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0))?;
/// let (sg, fg) = (PatchGrid::new(&sphere, 4, 8)?, PatchGrid::new(&floor, 3, 3)?);
/// let f = surface_form_factor_fixed::<f32, _, _, _, 5, 25>(sg.clone(), fg.clone(), &sphere)?;
/// // The paper's order 5: within 1e-4 with libm, 7e-4 with micromath's f32 sin/cos.
/// assert!((f - 1.0 / 6.0).abs() < 1e-3);
/// assert_eq!(f, surface_form_factor::<f32, _, _, _, 25>(sg, fg, Quadrature::uniform(5), &sphere)?);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
///
/// An order whose samples do not fit is a build error:
///
/// ```compile_fail
/// use pdm_kernel::{vec3, Parallelogram, PatchGrid};
/// let p = Parallelogram::new(vec3(0.0_f32, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
/// let g = PatchGrid::new(&p, 1, 1).unwrap();
/// let _ = pdm_kernel::fixed::surface_form_factor_fixed::<f32, _, _, _, 6, 25>(g.clone(), g, &());
/// ```
pub fn surface_form_factor_fixed<T, SA, SB, O, const N: usize, const CAP: usize>(
    a: PatchGrid<'_, T, SA>,
    b: PatchGrid<'_, T, SB>,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    const {
        assert!(N * N <= CAP, "CAP must hold N² samples");
    }
    let rule = GaussRule::<T>::fixed::<N>();
    surface_form_factor_with_rules::<T, SA, SB, O, CAP>(a, b, &rule, &rule, occluders)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::form_factor::{form_factor_between, Quadrature};
    use crate::substructure::surface_form_factor;
    use crate::surface::{Parallelogram, Sphere};
    use crate::vec3::vec3;

    /// The fixed-order and with-rules entry points give the same bits as the Quadrature ones.
    fn same_as_quadrature<T: Real>() {
        let sphere = Sphere::outer(vec3(T::ZERO, T::ZERO, T::ZERO), T::ONE).unwrap();
        let three = T::from_f64(3.0);
        let six = T::from_f64(6.0);
        let floor =
            Parallelogram::new(vec3(-three, -three, -three), vec3(six, T::ZERO, T::ZERO), vec3(T::ZERO, six, T::ZERO))
                .unwrap();
        let sg = PatchGrid::new(&sphere, 2, 4).unwrap();
        let fg = PatchGrid::new(&floor, 2, 2).unwrap();
        let q = surface_form_factor::<T, _, _, _, 49>(sg.clone(), fg.clone(), Quadrature::uniform(5), &sphere).unwrap();
        let f = surface_form_factor_fixed::<T, _, _, _, 5, 49>(sg.clone(), fg.clone(), &sphere).unwrap();
        assert_eq!(f, q);
        let q = surface_form_factor::<T, _, _, _, 49>(
            sg.clone(),
            fg.clone(),
            Quadrature { order_a: 4, order_b: 7 },
            &sphere,
        )
        .unwrap();
        let (r4, r7) = (GaussRule::<T>::fixed::<4>(), GaussRule::<T>::new_up_to::<7>(7).unwrap());
        let f = surface_form_factor_with_rules::<T, _, _, _, 49>(sg, fg, &r4, &r7, &sphere).unwrap();
        assert_eq!(f, q);

        let a = Patch::whole(&floor).unwrap();
        let b = Patch::whole(&sphere).unwrap();
        let q = form_factor_between::<T, _, _, _, 64>(&a, &b, Quadrature::uniform(8), &()).unwrap();
        let f = form_factor_between_fixed::<T, _, _, _, 8, 64>(&a, &b, &()).unwrap();
        assert_eq!(f, q);
        assert!(f > T::ZERO);
    }

    #[test]
    fn fixed_equals_quadrature_f32() {
        same_as_quadrature::<f32>();
    }

    #[test]
    fn fixed_equals_quadrature_f64() {
        same_as_quadrature::<f64>();
    }

    #[test]
    fn errors_are_reported() {
        let p = Parallelogram::new(vec3(0.0_f64, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let a = Patch::whole(&p).unwrap();
        // A rule too large for the buffers.
        let r = GaussRule::<f64>::fixed::<6>();
        assert!(matches!(
            form_factor_between_with_rules::<f64, _, _, _, 25>(&a, &a, &r, &r, &()),
            Err(PdmError::CapacityExceeded { needed: 36, capacity: 25 })
        ));
        // Coplanar patches face away from each other: zero, not an error.
        assert_eq!(form_factor_between_fixed::<f64, _, _, _, 3, 9>(&a, &a, &()).unwrap(), 0.0);
    }
}
