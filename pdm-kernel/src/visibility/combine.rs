//! Occluders combined without allocation: the enum of the built-in kinds, `()`, references,
//! slices, arrays, `heapless::Vec`, `Option` and tuples.

use super::*;

/// Any built-in occluder, for mixed lists such as `[AnyOccluder<f32>; 3]` or
/// `heapless::Vec<AnyOccluder<f64>, 8>`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AnyOccluder<T> {
    /// A sphere.
    Sphere(Sphere<T>),
    /// A parallelogram.
    Parallelogram(Parallelogram<T>),
    /// A disk or annulus.
    Disk(Disk<T>),
    /// An open cylinder.
    Cylinder(Cylinder<T>),
    /// A cone or frustum.
    Cone(crate::surface::Cone<T>),
    /// A bicubic Bézier patch (to a tolerance: [`super::BEZIER_FLATNESS`]).
    Bezier(crate::surface::BezierPatch<T>),
    /// A flat convex quadrilateral or triangle.
    Quadrilateral(crate::surface::Quadrilateral<T>),
}

impl<T: Real> Occluder<T> for AnyOccluder<T> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        match self {
            Self::Sphere(o) => o.blocks(p, q),
            Self::Parallelogram(o) => o.blocks(p, q),
            Self::Disk(o) => o.blocks(p, q),
            Self::Cylinder(o) => o.blocks(p, q),
            Self::Cone(o) => o.blocks(p, q),
            Self::Bezier(o) => o.blocks(p, q),
            Self::Quadrilateral(o) => o.blocks(p, q),
        }
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Sphere(o) => o.may_block_between(a, b),
            Self::Parallelogram(o) => o.may_block_between(a, b),
            Self::Disk(o) => o.may_block_between(a, b),
            Self::Cylinder(o) => o.may_block_between(a, b),
            Self::Cone(o) => o.may_block_between(a, b),
            Self::Bezier(o) => o.may_block_between(a, b),
            Self::Quadrilateral(o) => o.may_block_between(a, b),
        }
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        match self {
            Self::Sphere(o) => o.line_polynomials(p, origin, direction, out),
            Self::Parallelogram(o) => o.line_polynomials(p, origin, direction, out),
            Self::Disk(o) => o.line_polynomials(p, origin, direction, out),
            Self::Cylinder(o) => o.line_polynomials(p, origin, direction, out),
            Self::Cone(o) => o.line_polynomials(p, origin, direction, out),
            Self::Bezier(o) => o.line_polynomials(p, origin, direction, out),
            Self::Quadrilateral(o) => o.line_polynomials(p, origin, direction, out),
        }
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        match self {
            Self::Sphere(o) => o.hides_ball_from(p, b),
            _ => false,
        }
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        match self {
            Self::Parallelogram(o) => o.shadow_casters(from, b, bounds, out),
            Self::Quadrilateral(o) => o.shadow_casters(from, b, bounds, out),
            Self::Sphere(o) => o.shadow_casters(from, b, bounds, out),
            _ => !self.may_block_between(from, bounds),
        }
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        match self {
            Self::Sphere(o) => o.shadow_sphere(a, b),
            Self::Parallelogram(o) => o.shadow_sphere(a, b),
            Self::Disk(o) => o.shadow_sphere(a, b),
            Self::Cylinder(o) => o.shadow_sphere(a, b),
            Self::Cone(o) => o.shadow_sphere(a, b),
            Self::Bezier(o) => o.shadow_sphere(a, b),
            Self::Quadrilateral(o) => o.shadow_sphere(a, b),
        }
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        match self {
            Self::Sphere(o) => o.event_quadrics(corner, edge, pair, out),
            Self::Cylinder(o) => o.event_quadrics(corner, edge, pair, out),
            Self::Cone(o) => o.event_quadrics(corner, edge, pair, out),
            _ => false,
        }
    }
}

/// No occluder.
impl<T: Real> Occluder<T> for () {
    fn blocks(&self, _p: Vec3<T>, _q: Vec3<T>) -> bool {
        false
    }
    fn may_block_between(&self, _a: &Ball<T>, _b: &Ball<T>) -> bool {
        false
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(
        &self,
        _p: Vec3<T>,
        _origin: Vec3<T>,
        _direction: Vec3<T>,
        _out: &mut dyn FnMut([T; 3]),
    ) -> bool {
        true
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        _corner: Vec3<T>,
        _edge: Vec3<T>,
        _pair: [&[Vec3<T>]; 2],
        _out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        true
    }
}

impl<T: Real, O: Occluder<T> + ?Sized> Occluder<T> for &O {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        (**self).blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        (**self).may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        (**self).line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        (**self).hides_ball_from(p, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        (**self).shadow_casters(from, b, bounds, out)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        (**self).shadow_sphere(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        (**self).event_quadrics(corner, edge, pair, out)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for [O] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.iter().any(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.iter().any(|o| o.may_block_between(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.iter().any(|o| o.hides_ball_from(p, b))
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.iter().all(|o| o.shadow_casters(from, b, bounds, out))
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        self.iter().try_fold(None, |one, o| one_shadow(Some(one), o.shadow_sphere(a, b)))
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.iter().all(|o| o.event_quadrics(corner, edge, pair, out))
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for [O; N] {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_slice().hides_ball_from(p, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.as_slice().shadow_casters(from, b, bounds, out)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        self.as_slice().shadow_sphere(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.as_slice().event_quadrics(corner, edge, pair, out)
    }
}

impl<T: Real, O: Occluder<T>, const N: usize> Occluder<T> for heapless::Vec<O, N> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_slice().blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_slice().may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.iter().all(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_slice().hides_ball_from(p, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.as_slice().shadow_casters(from, b, bounds, out)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        self.as_slice().shadow_sphere(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.as_slice().event_quadrics(corner, edge, pair, out)
    }
}

impl<T: Real, O: Occluder<T>> Occluder<T> for Option<O> {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.as_ref().is_some_and(|o| o.blocks(p, q))
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.as_ref().is_some_and(|o| o.may_block_between(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.as_ref().is_none_or(|o| o.line_polynomials(p, origin, direction, out))
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.as_ref().is_some_and(|o| o.hides_ball_from(p, b))
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.as_ref().is_none_or(|o| o.shadow_casters(from, b, bounds, out))
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        self.as_ref().map_or(Some(None), |o| o.shadow_sphere(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.as_ref().is_none_or(|o| o.event_quadrics(corner, edge, pair, out))
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>> Occluder<T> for (A, B) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.0.line_polynomials(p, origin, direction, out) && self.1.line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.0.hides_ball_from(p, b) || self.1.hides_ball_from(p, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.0.shadow_casters(from, b, bounds, out) && self.1.shadow_casters(from, b, bounds, out)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        one_shadow(self.0.shadow_sphere(a, b), self.1.shadow_sphere(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.0.event_quadrics(corner, edge, pair, out) && self.1.event_quadrics(corner, edge, pair, out)
    }
}

impl<T: Real, A: Occluder<T>, B: Occluder<T>, C: Occluder<T>> Occluder<T> for (A, B, C) {
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        self.0.blocks(p, q) || self.1.blocks(p, q) || self.2.blocks(p, q)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        self.0.may_block_between(a, b) || self.1.may_block_between(a, b) || self.2.may_block_between(a, b)
    }
    #[cfg(feature = "closed-form")]
    fn line_polynomials(&self, p: Vec3<T>, origin: Vec3<T>, direction: Vec3<T>, out: &mut dyn FnMut([T; 3])) -> bool {
        self.0.line_polynomials(p, origin, direction, out)
            && self.1.line_polynomials(p, origin, direction, out)
            && self.2.line_polynomials(p, origin, direction, out)
    }
    #[cfg(feature = "closed-form")]
    fn hides_ball_from(&self, p: Vec3<T>, b: &Ball<T>) -> bool {
        self.0.hides_ball_from(p, b) || self.1.hides_ball_from(p, b) || self.2.hides_ball_from(p, b)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_casters(
        &self,
        from: &Ball<T>,
        b: &[Vec3<T>],
        bounds: &Ball<T>,
        out: &mut dyn FnMut(Caster<'_, T>),
    ) -> bool {
        self.0.shadow_casters(from, b, bounds, out)
            && self.1.shadow_casters(from, b, bounds, out)
            && self.2.shadow_casters(from, b, bounds, out)
    }
    #[cfg(feature = "closed-form")]
    fn shadow_sphere(&self, a: &Ball<T>, b: &Ball<T>) -> Option<Option<Ball<T>>> {
        one_shadow(one_shadow(self.0.shadow_sphere(a, b), self.1.shadow_sphere(a, b)), self.2.shadow_sphere(a, b))
    }
    #[cfg(feature = "closed-form")]
    fn event_quadrics(
        &self,
        corner: Vec3<T>,
        edge: Vec3<T>,
        pair: [&[Vec3<T>]; 2],
        out: &mut dyn FnMut(Quadric<T>),
    ) -> bool {
        self.0.event_quadrics(corner, edge, pair, out)
            && self.1.event_quadrics(corner, edge, pair, out)
            && self.2.event_quadrics(corner, edge, pair, out)
    }
}

/// Two answers of [`Occluder::shadow_sphere`] combined: nothing from either, the one sphere one
/// of them gives, or `None` (two spheres, or anything unknown).
#[cfg(feature = "closed-form")]
fn one_shadow<T>(x: Option<Option<Ball<T>>>, y: Option<Option<Ball<T>>>) -> Option<Option<Ball<T>>> {
    match (x?, y?) {
        (None, one) | (one, None) => Some(one),
        (Some(_), Some(_)) => None,
    }
}
