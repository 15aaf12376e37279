//! Flat convex quadrilaterals and triangles (mesh facets): the bilinear map of four coplanar
//! corners.

use super::{check_finite, lift, ParamRect, ParametricMap, Surface};
use crate::dual::Scalar;
use crate::error::PdmError;
use crate::real::Real;
use crate::vec3::Vec3;

/// A flat convex quadrilateral P₀P₁P₂P₃, or a triangle (P₃ = P₀), as the bilinear map
///
/// g(t, s) = (1 − t)(1 − s)·P₀ + t(1 − s)·P₁ + ts·P₂ + (1 − t)s·P₃,  (t, s) ∈ [0, 1]².
///
/// Every parameter line of a bilinear map is straight, so the patch over any parameter
/// rectangle is again a flat quadrilateral with straight edges, whose corners are the images of
/// the rectangle's corners ([`Surface::straight_corners`]): pairs of such patches that see each
/// other wholly take the contour form with its inner line integrals in closed form. The
/// normal ∂g/∂t × ∂g/∂s points to the side about which the corners turn counter-clockwise; on
/// a triangle it vanishes along the side t = 0, collapsed to P₀ (the area element is zero
/// there, as on a cone's apex). A parallelogram is the special case P₂ = P₁ + P₃ − P₀.
///
/// ```
/// use pdm_kernel::{pair_exchange, vec3, PairSettings, Patch, Quadrilateral};
/// // Two halves of perpendicular unit squares sharing the edge x = 0..1 (C-14 splits into
/// // such triangles): the contour form takes the pair.
/// let floor = Quadrilateral::triangle(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 0.0))?;
/// let wall = Quadrilateral::triangle(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 1.0))?;
/// let e = pair_exchange::<f64, _, _, _, 256>(&Patch::whole(&floor)?, &Patch::whole(&wall)?, PairSettings::ACCURATE, &())?;
/// assert!(e.value > 0.0 && e.value < 0.5);
/// # Ok::<(), pdm_kernel::PdmError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Quadrilateral<T> {
    pub(crate) corners: [Vec3<T>; 4],
    /// Twice the area vector, (P₂ − P₀) × (P₃ − P₁): the plane's normal, to the radiating side.
    pub(crate) normal: Vec3<T>,
    /// Whether the corners make a parallelogram (P₂ = P₁ + P₃ − P₀ to rounding): the map is
    /// then affine ([`Surface::affine_map`]).
    pub(crate) parallelogram: bool,
}

impl<T: Real> Quadrilateral<T> {
    /// A quadrilateral from its corners in order, radiating to the side about which they turn
    /// counter-clockwise. `Err(NonFinite)` for NaN/∞; `Err(Degenerate)` if the area is below
    /// `GEOMETRY_TOLERANCE` of the squared size, a corner lies off the plane of the others by
    /// more than `GEOMETRY_TOLERANCE` of the size, or the corners do not turn one way (not
    /// convex, or self-intersecting).
    pub fn new(corners: [Vec3<T>; 4]) -> Result<Self, PdmError> {
        for p in &corners {
            check_finite(&[p.x, p.y, p.z])?;
        }
        let [p0, p1, p2, p3] = corners;
        let normal = (p2 - p0).cross(p3 - p1);
        if !normal.is_finite() {
            return Err(PdmError::NonFinite);
        }
        let size = (p2 - p0).norm().max((p3 - p1).norm());
        let length = normal.norm();
        if !(length > T::GEOMETRY_TOLERANCE * size * size) || !size.is_finite() {
            return Err(PdmError::Degenerate);
        }
        let unit = normal.scale(T::ONE / length);
        let centre = (p0 + p1 + p2 + p3).scale(T::from_f64(0.25));
        let band = T::GEOMETRY_TOLERANCE * size;
        for (i, &p) in corners.iter().enumerate() {
            if unit.dot(p - centre).abs() > band {
                return Err(PdmError::Degenerate);
            }
            // Convex, counter-clockwise about the normal: each corner turns left (a repeated
            // corner, the triangle's, turns by zero).
            let (Some(&prev), Some(&next)) = (corners.get((i + 3) % 4), corners.get((i + 1) % 4)) else {
                return Err(PdmError::Degenerate);
            };
            if unit.dot((p - prev).cross(next - p)) < -band * size {
                return Err(PdmError::Degenerate);
            }
        }
        let twist = (p2 - p1 - p3 + p0).norm();
        let parallelogram = twist <= T::from_f64(16.0) * T::EPSILON * size;
        Ok(Self { corners, normal, parallelogram })
    }

    /// The triangle ABC (the quadrilateral A B C A), radiating to the side about which A, B, C
    /// turn counter-clockwise. Errors as [`Quadrilateral::new`].
    pub fn triangle(a: Vec3<T>, b: Vec3<T>, c: Vec3<T>) -> Result<Self, PdmError> {
        Self::new([a, b, c, a])
    }

    /// The corners P₀ … P₃ (a triangle's P₃ is P₀).
    #[must_use]
    pub fn corners(&self) -> [Vec3<T>; 4] {
        self.corners
    }

    /// The area |(P₂ − P₀) × (P₃ − P₁)| / 2.
    #[must_use]
    pub fn area(&self) -> T {
        self.normal.norm() * T::HALF
    }

    /// The same quadrilateral radiating to the other side (corners in reverse order, P₀ kept).
    #[must_use]
    pub fn reversed(&self) -> Self {
        let [p0, p1, p2, p3] = self.corners;
        Self { corners: [p0, p3, p2, p1], normal: -self.normal, parallelogram: self.parallelogram }
    }

    /// ∂g/∂t and ∂g/∂s at (t, s).
    #[inline]
    fn partials(&self, t: T, s: T) -> (Vec3<T>, Vec3<T>) {
        let [p0, p1, p2, p3] = self.corners;
        let gt = (p1 - p0).scale(T::ONE - s) + (p2 - p3).scale(s);
        let gs = (p3 - p0).scale(T::ONE - t) + (p2 - p1).scale(t);
        (gt, gs)
    }
}

impl<T: Real> ParametricMap<T> for Quadrilateral<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::ONE, s0: T::ZERO, s1: T::ONE }
    }
    fn map<S: Scalar<T>>(&self, t: S, s: S) -> Vec3<S> {
        let [p0, p1, p2, p3] = self.corners.map(lift::<T, S>);
        let (one_t, one_s) = (S::constant(T::ONE) - t, S::constant(T::ONE) - s);
        let w = |p: Vec3<S>, k: S| crate::vec3::vec3(p.x * k, p.y * k, p.z * k);
        w(p0, one_t * one_s) + w(p1, t * one_s) + w(p2, t * s) + w(p3, one_t * s)
    }
}

impl<T: Real> Surface<T> for Quadrilateral<T> {
    fn domain(&self) -> ParamRect<T> {
        ParametricMap::domain(self)
    }
    #[inline]
    fn point(&self, t: T, s: T) -> Vec3<T> {
        let [p0, p1, p2, p3] = self.corners;
        let (one_t, one_s) = (T::ONE - t, T::ONE - s);
        p0.scale(one_t * one_s) + p1.scale(t * one_s) + p2.scale(t * s) + p3.scale(one_t * s)
    }
    /// Eq. (4): ∂g/∂t × ∂g/∂s, parallel to the constant plane normal.
    #[inline]
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        let (gt, gs) = self.partials(t, s);
        gt.cross(gs)
    }
    /// A parallelogram's map is affine (the bilinear term's coefficient P₂ − P₁ − P₃ + P₀
    /// vanishes); other quadrilaterals and triangles have none.
    #[cfg(feature = "closed-form")]
    fn affine_map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        let [p0, p1, _, p3] = self.corners;
        self.parallelogram.then_some((p0, p1 - p0, p3 - p0))
    }
    #[cfg(feature = "closed-form")]
    fn point_and_partials(&self, t: T, s: T) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        let (gt, gs) = self.partials(t, s);
        Some((self.point(t, s), gt, gs))
    }
    #[cfg(feature = "closed-form")]
    fn straight_corners(&self, rect: ParamRect<T>) -> Option<[Vec3<T>; 4]> {
        Some([
            self.point(rect.t0, rect.s0),
            self.point(rect.t1, rect.s0),
            self.point(rect.t1, rect.s1),
            self.point(rect.t0, rect.s1),
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::*;
    use super::*;
    use crate::vec3::vec3;

    #[test]
    fn closed_form_agrees_with_dual_numbers() {
        let q =
            Quadrilateral::new([vec3(0.0, 0.0, 0.0), vec3(2.0, 0.1, 0.0), vec3(1.7, 1.3, 0.0), vec3(-0.2, 0.9, 0.0)])
                .unwrap();
        closed_form_matches_auto(&q, 1e-15);
        normal_matches_finite_differences(&q, 1e-8);
        closed_form_matches_auto(&q.reversed(), 1e-15);
        let t = Quadrilateral::triangle(vec3(1.0, 2.0, 3.0), vec3(2.0, 2.5, 3.0), vec3(1.5, 3.0, 4.0)).unwrap();
        // Near the collapsed side the normal is a small difference of products: rounding.
        closed_form_matches_auto(&t, 1e-13);
    }

    #[test]
    fn area_and_orientation() {
        let t = Quadrilateral::triangle(vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 3.0, 0.0)).unwrap();
        assert_eq!(t.area(), 3.0);
        // The normal points along +z (counter-clockwise seen from +z), zero on the collapsed side.
        assert!(t.normal(0.5, 0.5).z > 0.0);
        assert_eq!(t.normal(0.0, 0.3), vec3(0.0, 0.0, 0.0));
        assert!(t.reversed().normal(0.5, 0.5).z < 0.0);
        // ∫|n| over the domain is the area (|n| is linear in t, bilinear overall: order 2 exact).
        let rule = crate::gauss::GaussRule::<f64>::new(2).unwrap();
        let area = rule.integrate(0.0, 1.0, |x| rule.integrate(0.0, 1.0, |y| t.normal(x, y).norm()));
        assert!((area - 3.0).abs() < 1e-14, "{area}");
    }

    #[test]
    fn degenerate_non_planar_non_convex_and_non_finite() {
        let (o, x, y) = (vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0));
        assert_eq!(Quadrilateral::triangle(o, x, x.scale(2.0)), Err(PdmError::Degenerate));
        assert_eq!(Quadrilateral::triangle(o, x, x), Err(PdmError::Degenerate));
        assert_eq!(Quadrilateral::triangle(o, x, vec3(f64::NAN, 0.0, 0.0)), Err(PdmError::NonFinite));
        // Non-planar: the fourth corner 0.1 above the plane of the other three.
        assert_eq!(Quadrilateral::new([o, x, vec3(1.0, 1.0, 0.1), y]), Err(PdmError::Degenerate));
        // Non-convex (a dart) and self-intersecting (a bow tie).
        assert_eq!(
            Quadrilateral::new([o, vec3(2.0, 0.0, 0.0), vec3(0.5, 0.5, 0.0), y.scale(2.0)]),
            Err(PdmError::Degenerate)
        );
        assert_eq!(Quadrilateral::new([o, x, y, vec3(1.0, 1.0, 0.0)]), Err(PdmError::Degenerate));
        let square = Quadrilateral::new([o, x, vec3(1.0, 1.0, 0.0), y]).unwrap();
        // A parallelogram has an affine map (the bilinear term vanishes), others none.
        #[cfg(feature = "closed-form")]
        {
            assert_eq!(square.affine_map(), Some((o, x, y)));
            assert_eq!(square.reversed().affine_map(), Some((o, y, x)));
            assert!(Quadrilateral::new([o, x, vec3(1.2, 1.0, 0.0), y]).unwrap().affine_map().is_none());
            assert!(Quadrilateral::triangle(o, x, y).unwrap().affine_map().is_none());
        }
        let _ = square;
    }
}
