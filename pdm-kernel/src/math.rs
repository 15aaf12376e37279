//! The one place that decides which math library answers.
//!
//! By default every elementary function comes from `libm` (correctly rounded or within 1 ulp for
//! the functions used here). With the `micromath` feature two **f32** paths change: `sqrt`
//! comes from micromath's estimate refined by two Newton steps (≈ 1e-7, as accurate as the
//! kernel needs), and the sine and cosine that place a curved surface's sample points
//! (`Real::sin_cos_fast`: the points, normals and parameter maps of spheres, cylinders, cones and
//! disks — the per-sample cost) come from micromath's fast approximations. Every other `sin`,
//! `cos`, `atan`, `atan2` and `ln` stays libm's, and f64 always uses libm. Cargo features are
//! additive: enabling `micromath` anywhere in a build enables it for every user of the kernel
//! in that build.
//!
//! Why only those: the other calls are closed forms (the contour form's edge pairs, the
//! point-to-polygon J, a sphere's cone of directions), events and proofs (normal cones), whose
//! terms cancel to a value up to hundreds of times smaller. micromath's versions are off by
//! up to 1.1e-3 (`sin`, `cos`, absolute), 2.8e-3 (`atan2`), 6e-2 relative (`atan` near 0) and
//! 0.12 (`ln`, absolute); with them in the closed forms two adjacent cube faces came out
//! 4.4 % high and opposite faces past the sphere 4.5 %, their tolerance-mode estimates 10–1000×
//! below that.
//!
//! Accuracy cost of `micromath` (measured by `tests/integration/tests/precision_backends.rs`,
//! see RESULTS.md "Precision backends"): sample points lie up to ≈ 1e-3 (relative to the
//! surface's radius) off their surface, so the occlusion tests widen their "on the surface"
//! band to [`crate::Real::ELEMENTARY_ERROR`], and the tolerance mode counts it in every
//! estimate. Use micromath where three digits suffice.

/// f64 functions: always libm.
pub(crate) mod f64m {
    /// Relative error bound of the f64 elementary functions (libm: within an ulp or two).
    pub(crate) const ELEMENTARY_ERROR: f64 = 2.0 * f64::EPSILON;
    #[inline(always)]
    pub(crate) fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline(always)]
    pub(crate) fn sin(x: f64) -> f64 {
        libm::sin(x)
    }
    #[inline(always)]
    pub(crate) fn cos(x: f64) -> f64 {
        libm::cos(x)
    }
    #[inline(always)]
    pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
        libm::sincos(x)
    }
    /// The surfaces' sample points' sine and cosine: here the same as [`sin_cos`].
    #[inline(always)]
    pub(crate) fn sin_cos_fast(x: f64) -> (f64, f64) {
        sin_cos(x)
    }
    #[inline(always)]
    pub(crate) fn sin_fast(x: f64) -> f64 {
        sin(x)
    }
    #[inline(always)]
    pub(crate) fn cos_fast(x: f64) -> f64 {
        cos(x)
    }
    #[inline(always)]
    pub(crate) fn atan2(y: f64, x: f64) -> f64 {
        libm::atan2(y, x)
    }
    #[inline(always)]
    pub(crate) fn atan(x: f64) -> f64 {
        libm::atan(x)
    }
    #[inline(always)]
    pub(crate) fn ln(x: f64) -> f64 {
        libm::log(x)
    }
    #[inline(always)]
    pub(crate) fn abs(x: f64) -> f64 {
        libm::fabs(x)
    }
}

/// f32 functions: libm, or micromath with the `micromath` feature.
#[cfg(not(feature = "micromath"))]
pub(crate) mod f32m {
    /// Relative error bound of the f32 elementary functions (libm: within an ulp or two).
    pub(crate) const ELEMENTARY_ERROR: f32 = 2.0 * f32::EPSILON;
    #[inline(always)]
    pub(crate) fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline(always)]
    pub(crate) fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline(always)]
    pub(crate) fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline(always)]
    pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
        libm::sincosf(x)
    }
    /// The surfaces' sample points' sine and cosine: here the same as [`sin_cos`].
    #[inline(always)]
    pub(crate) fn sin_cos_fast(x: f32) -> (f32, f32) {
        sin_cos(x)
    }
    #[inline(always)]
    pub(crate) fn sin_fast(x: f32) -> f32 {
        sin(x)
    }
    #[inline(always)]
    pub(crate) fn cos_fast(x: f32) -> f32 {
        cos(x)
    }
    #[inline(always)]
    pub(crate) fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline(always)]
    pub(crate) fn atan(x: f32) -> f32 {
        libm::atanf(x)
    }
    #[inline(always)]
    pub(crate) fn ln(x: f32) -> f32 {
        libm::logf(x)
    }
    #[inline(always)]
    pub(crate) fn abs(x: f32) -> f32 {
        libm::fabsf(x)
    }
}

/// f32 functions: micromath's fast approximations.
#[cfg(feature = "micromath")]
pub(crate) mod f32m {
    use micromath::F32Ext;
    /// Error bound of micromath's sin/cos (1.09e-3 absolute measured over [−7, 7], 2e-3 with
    /// margin).
    pub(crate) const ELEMENTARY_ERROR: f32 = 2.0e-3;
    /// micromath's estimate (≈ 5 % off on its own) refined by two Newton steps
    /// y ← (y + x/y)/2, each squaring the relative error: ≈ 1e-7 afterwards.
    #[inline(always)]
    pub(crate) fn sqrt(x: f32) -> f32 {
        let y = F32Ext::sqrt(x);
        if !(y > 0.0) || !y.is_finite() {
            return y;
        }
        let y = 0.5 * (y + x / y);
        0.5 * (y + x / y)
    }
    #[inline(always)]
    pub(crate) fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline(always)]
    pub(crate) fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline(always)]
    pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
        libm::sincosf(x)
    }
    /// The surfaces' sample points' sine and cosine: micromath's approximations.
    #[inline(always)]
    pub(crate) fn sin_cos_fast(x: f32) -> (f32, f32) {
        (F32Ext::sin(x), F32Ext::cos(x))
    }
    #[inline(always)]
    pub(crate) fn sin_fast(x: f32) -> f32 {
        F32Ext::sin(x)
    }
    #[inline(always)]
    pub(crate) fn cos_fast(x: f32) -> f32 {
        F32Ext::cos(x)
    }
    #[inline(always)]
    pub(crate) fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline(always)]
    pub(crate) fn atan(x: f32) -> f32 {
        libm::atanf(x)
    }
    #[inline(always)]
    pub(crate) fn ln(x: f32) -> f32 {
        libm::logf(x)
    }
    #[inline(always)]
    pub(crate) fn abs(x: f32) -> f32 {
        F32Ext::abs(x)
    }
}
