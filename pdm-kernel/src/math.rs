//! The one place that decides which math library answers.
//!
//! By default every elementary function comes from `libm` (correctly rounded or within 1 ulp for
//! the functions used here). With the `micromath` feature the **f32** functions `sqrt`, `sin`,
//! `cos`, `atan`, `atan2` and `ln` come from micromath's fast approximations instead; f64 always
//! uses libm. Cargo features are additive: enabling `micromath` anywhere in a build enables it for
//! every user of the kernel in that build.
//!
//! Accuracy cost of `micromath` (measured by `tests/integration/tests/precision_backends.rs`,
//! see RESULTS.md "Precision backends"): micromath's `sin`/`cos`/`atan` are accurate to about 1e-3;
//! its `sqrt` (a bit-trick estimate, ≈ 5 % off) is refined here by two Newton steps to ≈ 1e-7.
//! On form factors in f32: C-11 squares 1.1e-6 (as libm: only `sqrt` is involved), C-41 disks
//! 3.7e-4, sphere → cube face 7.0e-4, against 6e-7…1e-6 with libm. Points placed by sin/cos lie
//! up to ≈ 1e-3 off their surface, so the occlusion tests widen their "on the surface" band to
//! [`crate::Real::ELEMENTARY_ERROR`]. Use micromath where three digits suffice.

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
    /// Relative error bound of micromath's sin/cos/atan (≈ 1e-3 measured, 2e-3 with margin).
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
        F32Ext::sin(x)
    }
    #[inline(always)]
    pub(crate) fn cos(x: f32) -> f32 {
        F32Ext::cos(x)
    }
    #[inline(always)]
    pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
        (F32Ext::sin(x), F32Ext::cos(x))
    }
    #[inline(always)]
    pub(crate) fn atan2(y: f32, x: f32) -> f32 {
        F32Ext::atan2(y, x)
    }
    #[inline(always)]
    pub(crate) fn atan(x: f32) -> f32 {
        F32Ext::atan(x)
    }
    #[inline(always)]
    pub(crate) fn ln(x: f32) -> f32 {
        F32Ext::ln(x)
    }
    #[inline(always)]
    pub(crate) fn abs(x: f32) -> f32 {
        F32Ext::abs(x)
    }
}
