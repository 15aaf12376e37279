//! The one place that decides which math library answers.
//!
//! By default every elementary function comes from `libm` (correctly rounded or within 1 ulp for
//! the functions used here). With the `micromath` feature the **f32** functions `sqrt`, `sin`,
//! `cos`, `atan`, `atan2` and `ln` come from micromath's fast approximations instead; f64 always
//! uses libm. Cargo features are additive: enabling `micromath` anywhere in a build enables it for
//! every user of the kernel in that build.
//!
//! Accuracy cost of `micromath` (measured by `cargo test -p pdm-kernel --features micromath
//! --test-threads ... micromath_cost`, see README "Precision backends"): the per-function error
//! bounds micromath documents are about 1e-3 relative for `sin`/`cos`, and its `sqrt` is a
//! bit-trick estimate refined once; on form factors the relative error grows to the 1e-4…1e-3
//! range. Use it only where three digits suffice.

/// f64 functions: always libm.
pub(crate) mod f64m {
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
    #[inline(always)]
    pub(crate) fn sqrt(x: f32) -> f32 {
        F32Ext::sqrt(x)
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
