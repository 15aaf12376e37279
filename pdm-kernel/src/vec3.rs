//! A minimal 3-vector over any arithmetic scalar (a [`Real`](crate::Real) or a
//! [`Dual`](crate::dual::Dual) number).

use core::ops::{Add, Mul, Neg, Sub};

/// A 3-vector (x, y, z).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Vec3<S> {
    /// x component.
    pub x: S,
    /// y component.
    pub y: S,
    /// z component.
    pub z: S,
}

/// Shorthand constructor.
#[inline(always)]
#[must_use]
pub const fn vec3<S>(x: S, y: S, z: S) -> Vec3<S> {
    Vec3 { x, y, z }
}

impl<S> Vec3<S>
where
    S: Copy + Add<Output = S> + Sub<Output = S> + Mul<Output = S>,
{
    /// Dot product.
    #[inline(always)]
    #[must_use]
    pub fn dot(self, o: Self) -> S {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product `self × o`.
    #[inline(always)]
    #[must_use]
    pub fn cross(self, o: Self) -> Self {
        Vec3 { x: self.y * o.z - self.z * o.y, y: self.z * o.x - self.x * o.z, z: self.x * o.y - self.y * o.x }
    }

    /// Squared length.
    #[inline(always)]
    #[must_use]
    pub fn norm2(self) -> S {
        self.dot(self)
    }

    /// Multiplies every component by `k`.
    #[inline(always)]
    #[must_use]
    pub fn scale(self, k: S) -> Self {
        Vec3 { x: self.x * k, y: self.y * k, z: self.z * k }
    }
}

impl<T: crate::real::Real> Vec3<T> {
    /// The zero vector.
    pub const ZERO: Self = Vec3 { x: T::ZERO, y: T::ZERO, z: T::ZERO };

    /// Euclidean length, computed without overflow or underflow for any finite input (scaled by
    /// the largest component).
    #[inline]
    #[must_use]
    pub fn norm(self) -> T {
        // Directly where the squares neither overflow nor lose the largest component to
        // underflow (the smaller ones' loss is then below ε of the result); scaled otherwise.
        let n2 = self.norm2();
        if n2 < T::MAX && n2 > T::MIN_POSITIVE / T::EPSILON {
            return n2.sqrt();
        }
        self.norm_scaled()
    }

    /// [`Self::norm`] scaled by the largest component (rare: huge, tiny or non-finite input).
    #[cold]
    #[inline(never)]
    fn norm_scaled(self) -> T {
        let m = self.max_abs();
        if m == T::ZERO || !m.is_finite() {
            return m;
        }
        let inv = T::ONE / m;
        self.scale(inv).norm2().sqrt() * m
    }

    /// Largest absolute component.
    #[inline]
    #[must_use]
    pub fn max_abs(self) -> T {
        self.x.abs().max(self.y.abs()).max(self.z.abs())
    }

    /// `true` if every component is finite.
    #[inline]
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// Converts between widths (through f64).
    #[inline]
    #[must_use]
    pub fn cast<U: crate::real::Real>(self) -> Vec3<U> {
        Vec3 { x: U::from_f64(self.x.to_f64()), y: U::from_f64(self.y.to_f64()), z: U::from_f64(self.z.to_f64()) }
    }
}

impl<S: Add<Output = S>> Add for Vec3<S> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Vec3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl<S: Sub<Output = S>> Sub for Vec3<S> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Vec3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

impl<S: Neg<Output = S>> Neg for Vec3<S> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Vec3 { x: -self.x, y: -self.y, z: -self.z }
    }
}

/// A ball (centre, radius) bounding a set of points.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Ball<T> {
    /// Centre.
    pub center: Vec3<T>,
    /// Radius.
    pub radius: T,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cross_is_right_handed() {
        let x = vec3(1.0, 0.0, 0.0);
        let y = vec3(0.0, 1.0, 0.0);
        assert_eq!(x.cross(y), vec3(0.0, 0.0, 1.0));
    }

    #[test]
    fn norm_does_not_overflow_or_underflow() {
        let big = vec3(3.0e300_f64, 4.0e300, 0.0);
        assert!((big.norm() / 5.0e300 - 1.0).abs() < 1e-15);
        let tiny = vec3(3.0e-300_f64, 4.0e-300, 0.0);
        assert!((tiny.norm() / 5.0e-300 - 1.0).abs() < 1e-15);
        let big32 = vec3(3.0e30_f32, 4.0e30, 0.0);
        assert!((big32.norm() / 5.0e30 - 1.0).abs() < 1e-6);
    }
}
