//! Gauss sample points of a patch, precomputed once and reused against every other patch.
//!
//! [`PatchSamples`] holds, for the p_t × p_s Gauss nodes of a patch, the point g(t, s), the unit
//! normal n/|n| and the weight w_t w_s J |n| (Gauss weights × interval Jacobian × area element),
//! so that Σ w = A (eq. 12) and ∫∫ f dA ≈ Σ w f. Arrays are fixed-size (structure of arrays,
//! capacity `CAP` chosen by the caller: 25 for order 5, 1024 for order 32), so sampling needs
//! no heap.
//!
//! Where the area element vanishes (a sphere's pole, the apex of a cone) the weight is zero and
//! the unit normal is set to zero: such a point contributes nothing and nothing is divided by |n|.

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::patch::Patch;
use crate::real::Real;
use crate::surface::Surface;
pub use crate::vec3::Ball;
use crate::vec3::{vec3, Vec3};

/// Precomputed Gauss samples of one patch (at most `CAP` of them).
#[derive(Clone, Debug)]
pub struct PatchSamples<T, const CAP: usize> {
    pub(crate) len: usize,
    pub(crate) x: [T; CAP],
    pub(crate) y: [T; CAP],
    pub(crate) z: [T; CAP],
    pub(crate) nx: [T; CAP],
    pub(crate) ny: [T; CAP],
    pub(crate) nz: [T; CAP],
    pub(crate) w: [T; CAP],
    pub(crate) area: T,
    pub(crate) bounds: Ball<T>,
}

impl<T: Real, const CAP: usize> PatchSamples<T, CAP> {
    /// Samples `patch` with the `order`-point rule on both axes.
    pub fn new<S: Surface<T> + ?Sized>(patch: &Patch<'_, T, S>, order: usize) -> Result<Self, PdmError> {
        Self::with_orders(patch, order, order)
    }

    /// Samples `patch` with `order_t` points along t and `order_s` along s.
    ///
    /// Errors: `UnsupportedOrder`; `CapacityExceeded` if `order_t·order_s > CAP`; `NonFinite` if
    /// the surface evaluates to NaN/∞; `Degenerate` if the patch area is zero, below
    /// `GEOMETRY_TOLERANCE²` times its squared extent, or its extent is below
    /// `GEOMETRY_TOLERANCE` times its distance from the origin (a point, up to rounding).
    pub fn with_orders<S: Surface<T> + ?Sized>(
        patch: &Patch<'_, T, S>,
        order_t: usize,
        order_s: usize,
    ) -> Result<Self, PdmError> {
        let mut out = Self::empty();
        out.fill(patch, order_t, order_s)?;
        Ok(out)
    }

    /// An empty set (no samples), to be filled in place with [`PatchSamples::fill`].
    #[must_use]
    pub const fn empty() -> Self {
        Self {
            len: 0,
            x: [T::ZERO; CAP],
            y: [T::ZERO; CAP],
            z: [T::ZERO; CAP],
            nx: [T::ZERO; CAP],
            ny: [T::ZERO; CAP],
            nz: [T::ZERO; CAP],
            w: [T::ZERO; CAP],
            area: T::ZERO,
            bounds: Ball { center: Vec3 { x: T::ZERO, y: T::ZERO, z: T::ZERO }, radius: T::ZERO },
        }
    }

    /// Re-samples `patch` into this buffer in place (no copy of the arrays: this is what keeps a
    /// form-factor call within a small stack on a microcontroller). Same errors as
    /// [`PatchSamples::with_orders`]; on error the buffer is left empty.
    pub fn fill<S: Surface<T> + ?Sized>(
        &mut self,
        patch: &Patch<'_, T, S>,
        order_t: usize,
        order_s: usize,
    ) -> Result<(), PdmError> {
        self.len = 0;
        self.area = T::ZERO;
        let rule_t = GaussRule::<T>::new(order_t)?;
        let rule_s = GaussRule::<T>::new(order_s)?;
        self.fill_with_rules(patch, &rule_t, &rule_s)
    }

    /// [`PatchSamples::fill`] with the rules given instead of their orders: `rule_t` along t,
    /// `rule_s` along s. With rules built by [`GaussRule::fixed`] a build links only those
    /// orders' tables. Same errors as [`PatchSamples::with_orders`] except `UnsupportedOrder`
    /// (a rule is always valid); on error the buffer is left empty.
    pub fn fill_with_rules<S: Surface<T> + ?Sized>(
        &mut self,
        patch: &Patch<'_, T, S>,
        rule_t: &GaussRule<T>,
        rule_s: &GaussRule<T>,
    ) -> Result<(), PdmError> {
        self.len = 0;
        self.area = T::ZERO;
        let needed = rule_t.order() * rule_s.order();
        if needed > CAP {
            return Err(PdmError::CapacityExceeded { needed, capacity: CAP });
        }
        let r = patch.rect();
        let surface = patch.surface();
        let ht = (r.t1 - r.t0) * T::HALF;
        let hs = (r.s1 - r.s0) * T::HALF;
        let jacobian = ht * hs;
        let mut k = 0;
        let mut area = T::ZERO;
        for (xt, wt) in rule_t.points() {
            let t = r.t0 + ht * (xt + T::ONE);
            for (xs, ws) in rule_s.points() {
                let s = r.s0 + hs * (xs + T::ONE);
                let (p, n) = surface.point_and_normal(t, s);
                if !(p.is_finite() && n.is_finite()) {
                    return Err(PdmError::NonFinite);
                }
                let len = n.norm();
                let unit = if len > T::ZERO { n.scale(T::ONE / len) } else { Vec3::ZERO };
                let w = wt * ws * jacobian * len;
                self.set(k, p, unit, w);
                area += w;
                k += 1;
            }
        }
        if !area.is_finite() {
            return Err(PdmError::NonFinite);
        }
        self.len = k;
        self.bounds = self.compute_bounds();
        let (extent, magnitude) = patch_extent(patch);
        let tiny = T::GEOMETRY_TOLERANCE * T::GEOMETRY_TOLERANCE * extent * extent;
        // A patch whose extent is lost in the rounding of its coordinates is a point.
        let lost_in_rounding = extent <= T::GEOMETRY_TOLERANCE * magnitude;
        if !(area > T::ZERO) || !(area > tiny) || !extent.is_finite() || lost_in_rounding {
            self.len = 0;
            return Err(PdmError::Degenerate);
        }
        self.area = area;
        Ok(())
    }

    fn set(&mut self, k: usize, p: Vec3<T>, n: Vec3<T>, w: T) {
        if let (Some(x), Some(y), Some(z), Some(nx), Some(ny), Some(nz), Some(wk)) = (
            self.x.get_mut(k),
            self.y.get_mut(k),
            self.z.get_mut(k),
            self.nx.get_mut(k),
            self.ny.get_mut(k),
            self.nz.get_mut(k),
            self.w.get_mut(k),
        ) {
            (*x, *y, *z, *nx, *ny, *nz, *wk) = (p.x, p.y, p.z, n.x, n.y, n.z, w);
        }
    }

    fn compute_bounds(&self) -> Ball<T> {
        let mut c = Vec3::ZERO;
        let mut count = T::ZERO;
        for s in self.iter() {
            c = c + s.point;
            count += T::ONE;
        }
        let center = if count > T::ZERO { c.scale(T::ONE / count) } else { c };
        let mut radius = T::ZERO;
        for s in self.iter() {
            radius = radius.max((s.point - center).norm());
        }
        Ball { center, radius }
    }

    /// Number of samples (order_t · order_s).
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` if there are no samples (never, for a successfully built set).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The patch area by eq. (12): Σ w.
    #[must_use]
    pub fn area(&self) -> T {
        self.area
    }

    /// A ball containing every sample point (used to skip occluders that cannot cut a pair).
    #[must_use]
    pub fn bounds(&self) -> Ball<T> {
        self.bounds
    }

    /// Sample k, if it exists.
    #[must_use]
    pub fn get(&self, k: usize) -> Option<Sample<T>> {
        if k >= self.len {
            return None;
        }
        Some(Sample {
            point: vec3(*self.x.get(k)?, *self.y.get(k)?, *self.z.get(k)?),
            unit_normal: vec3(*self.nx.get(k)?, *self.ny.get(k)?, *self.nz.get(k)?),
            weight: *self.w.get(k)?,
        })
    }

    /// All samples.
    pub fn iter(&self) -> impl Iterator<Item = Sample<T>> + '_ {
        (0..self.len).filter_map(move |k| self.get(k))
    }

    /// The live parts of the structure-of-arrays storage: (x, y, z, nx, ny, nz, w).
    #[allow(clippy::type_complexity)]
    pub(crate) fn columns(&self) -> (&[T], &[T], &[T], &[T], &[T], &[T], &[T]) {
        let n = self.len;
        (
            cut(&self.x, n),
            cut(&self.y, n),
            cut(&self.z, n),
            cut(&self.nx, n),
            cut(&self.ny, n),
            cut(&self.nz, n),
            cut(&self.w, n),
        )
    }
}

/// One Gauss sample of a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample<T> {
    /// g(t_k, s_k).
    pub point: Vec3<T>,
    /// n/|n| (zero where |n| = 0).
    pub unit_normal: Vec3<T>,
    /// w_t w_s J |n|: this sample's share of the area.
    pub weight: T,
}

#[inline(always)]
fn cut<T, const CAP: usize>(a: &[T; CAP], n: usize) -> &[T] {
    a.get(..n).unwrap_or_default()
}

/// (Largest distance of the patch's 3 × 3 grid of corner, edge-midpoint and centre points from
/// its centre point, largest coordinate magnitude among them): a cheap size estimate used only
/// to recognise degenerate patches.
fn patch_extent<T: Real, S: Surface<T> + ?Sized>(patch: &Patch<'_, T, S>) -> (T, T) {
    let r = patch.rect();
    let surface = patch.surface();
    let mid_t = (r.t0 + r.t1) * T::HALF;
    let mid_s = (r.s0 + r.s1) * T::HALF;
    let center = surface.point(mid_t, mid_s);
    let mut extent = T::ZERO;
    let mut magnitude = center.max_abs();
    for t in [r.t0, mid_t, r.t1] {
        for s in [r.s0, mid_s, r.s1] {
            let p = surface.point(t, s);
            extent = extent.max((p - center).norm());
            magnitude = magnitude.max(p.max_abs());
        }
    }
    (extent, magnitude)
}
