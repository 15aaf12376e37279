//! Tiny 3-vector helpers on plain `[f64; 3]` (deliberately independent of `pdm_kernel::vec3`).

/// A point or vector in 3-D.
pub type V3 = [f64; 3];

/// `a + b`.
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `k · a`.
#[inline]
pub fn scale(a: V3, k: f64) -> V3 {
    [k * a[0], k * a[1], k * a[2]]
}

/// `a + k · b`.
#[inline]
pub fn axpy(a: V3, k: f64, b: V3) -> V3 {
    [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]]
}

/// Dot product.
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
#[inline]
pub fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Squared Euclidean norm.
#[inline]
pub fn norm2(a: V3) -> f64 {
    dot(a, a)
}

/// Euclidean norm.
#[inline]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
