//! Forward-mode dual numbers with two infinitesimal directions, for normals from g alone.
//!
//! A [`Dual`] carries a value and its partial derivatives with respect to the two surface
//! parameters (t, s). Evaluating a user's map g(t, s) on `Dual::variable_t(t)` and
//! `Dual::variable_s(s)` yields g, ∂g/∂t and ∂g/∂s exactly (to rounding), so the normal of
//! eq. (4), n = ∂g/∂t × ∂g/∂s, needs nothing but g. No allocation, no_std.

use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::real::Real;

/// The arithmetic a parametric map is written in: a plain [`Real`] or a [`Dual`] over it.
///
/// Write a user surface's `map` generically over `S: Scalar<T>` and it can be evaluated both
/// ways; the kernel then differentiates it automatically (see
/// [`AutoNormal`](crate::surface::AutoNormal)).
pub trait Scalar<T: Real>:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// A constant (zero derivatives).
    fn constant(value: T) -> Self;
    /// The value part.
    fn value(self) -> T;
    /// sin.
    fn sin(self) -> Self;
    /// cos.
    fn cos(self) -> Self;
    /// Square root (derivative undefined at 0: gives ±∞ partials there, like the real function).
    fn sqrt(self) -> Self;
}

impl<T: Real> Scalar<T> for T {
    #[inline(always)]
    fn constant(value: T) -> Self {
        value
    }
    #[inline(always)]
    fn value(self) -> T {
        self
    }
    /// A plain value is a sample point's parameter: the fast sine ([`Real::sin_fast`]).
    #[inline(always)]
    fn sin(self) -> Self {
        Real::sin_fast(self)
    }
    /// A plain value is a sample point's parameter: the fast cosine ([`Real::cos_fast`]).
    #[inline(always)]
    fn cos(self) -> Self {
        Real::cos_fast(self)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Real::sqrt(self)
    }
}

/// A number v + d_t·ε_t + d_s·ε_s with ε_t² = ε_s² = ε_t·ε_s = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<T> {
    /// Value.
    pub v: T,
    /// ∂/∂t.
    pub dt: T,
    /// ∂/∂s.
    pub ds: T,
}

impl<T: Real> Dual<T> {
    /// The parameter t itself: value t, ∂/∂t = 1.
    #[must_use]
    pub fn variable_t(t: T) -> Self {
        Dual { v: t, dt: T::ONE, ds: T::ZERO }
    }
    /// The parameter s itself: value s, ∂/∂s = 1.
    #[must_use]
    pub fn variable_s(s: T) -> Self {
        Dual { v: s, dt: T::ZERO, ds: T::ONE }
    }
    #[inline(always)]
    fn chain(self, f: T, df: T) -> Self {
        Dual { v: f, dt: self.dt * df, ds: self.ds * df }
    }
}

impl<T: Real> Add for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Dual { v: self.v + o.v, dt: self.dt + o.dt, ds: self.ds + o.ds }
    }
}
impl<T: Real> Sub for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Dual { v: self.v - o.v, dt: self.dt - o.dt, ds: self.ds - o.ds }
    }
}
impl<T: Real> Mul for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Dual { v: self.v * o.v, dt: self.dt * o.v + self.v * o.dt, ds: self.ds * o.v + self.v * o.ds }
    }
}
impl<T: Real> Div for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = T::ONE / o.v;
        let q = self.v * inv;
        Dual { v: q, dt: (self.dt - q * o.dt) * inv, ds: (self.ds - q * o.ds) * inv }
    }
}
impl<T: Real> Neg for Dual<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Dual { v: -self.v, dt: -self.dt, ds: -self.ds }
    }
}

impl<T: Real> Scalar<T> for Dual<T> {
    #[inline(always)]
    fn constant(value: T) -> Self {
        Dual { v: value, dt: T::ZERO, ds: T::ZERO }
    }
    #[inline(always)]
    fn value(self) -> T {
        self.v
    }
    #[inline(always)]
    fn sin(self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    #[inline(always)]
    fn cos(self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        self.chain(r, T::HALF / r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_and_quotient_rules() {
        let t = Dual::variable_t(2.0_f64);
        let s = Dual::variable_s(3.0_f64);
        let f = t * t * s / (t + s); // f = t² s / (t + s)
        let (tv, sv) = (2.0, 3.0);
        assert!((f.v - tv * tv * sv / (tv + sv)).abs() < 1e-15);
        let dfdt = (2.0 * tv * sv * (tv + sv) - tv * tv * sv) / ((tv + sv) * (tv + sv));
        let dfds = (tv * tv * (tv + sv) - tv * tv * sv) / ((tv + sv) * (tv + sv));
        assert!((f.dt - dfdt).abs() < 1e-14);
        assert!((f.ds - dfds).abs() < 1e-14);
    }

    #[test]
    fn elementary_functions() {
        let t = Dual::variable_t(0.7_f64);
        let f = Scalar::sin(t) * Scalar::cos(t) + Scalar::sqrt(t);
        let d = (2.0 * 0.7_f64).cos() + 0.5 / 0.7_f64.sqrt();
        assert!((f.dt - d).abs() < 1e-14);
        assert_eq!(f.ds, 0.0);
    }
}
