//! Patches: a surface restricted to a sub-rectangle of its parameter domain, subdivision into
//! m × n grids without allocation, and patch areas by eq. (12).

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::real::Real;
use crate::surface::{ParamRect, Surface};
use crate::vec3::{vec3, Ball, Vec3};

/// A surface restricted to the parameter rectangle `rect` ⊆ its domain.
#[derive(Debug)]
pub struct Patch<'s, T, S: ?Sized> {
    surface: &'s S,
    rect: ParamRect<T>,
}

impl<T, S: ?Sized> Clone for Patch<'_, T, S>
where
    T: Copy,
{
    fn clone(&self) -> Self {
        *self
    }
}
impl<T: Copy, S: ?Sized> Copy for Patch<'_, T, S> {}

impl<'s, T: Real, S: Surface<T> + ?Sized> Patch<'s, T, S> {
    /// The patch of `surface` over `rect`. `Err(NonFinite)`/`Err(EmptyParameterRange)` for a bad
    /// rectangle, `Err(OutsideDomain)` if it leaves the surface's domain (beyond rounding).
    pub fn new(surface: &'s S, rect: ParamRect<T>) -> Result<Self, PdmError> {
        rect.validate()?;
        if !surface.domain().contains(&rect) {
            return Err(PdmError::OutsideDomain);
        }
        Ok(Self { surface, rect })
    }

    /// The whole surface as one patch.
    pub fn whole(surface: &'s S) -> Result<Self, PdmError> {
        Self::new(surface, surface.domain())
    }

    /// The surface.
    #[must_use]
    pub fn surface(&self) -> &'s S {
        self.surface
    }

    /// The parameter rectangle.
    #[must_use]
    pub fn rect(&self) -> ParamRect<T> {
        self.rect
    }

    /// A ball containing the whole patch (not only its Gauss points): centred at g(mid), radius
    /// the largest distance to a 5 × 5 grid of points including the corners and edges, enlarged
    /// by 1/8. Exact up to that margin for flat patches (a parallelogram's farthest point is a
    /// corner); for curved ones the margin covers the bulge between grid points of any patch
    /// whose normal turns by less than a right angle (sphere, cylinder, cone, disk cells).
    /// Used to decide whether an occluder can cut the pair's integrand anywhere.
    #[must_use]
    pub fn enclosing_ball(&self) -> Ball<T> {
        const GRID: usize = 5;
        let r = self.rect;
        let center = self.surface.point((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
        let mut radius = T::ZERO;
        let step = T::ONE / T::from_usize(GRID - 1);
        for i in 0..GRID {
            let t = r.t0 + (r.t1 - r.t0) * (T::from_usize(i) * step);
            for j in 0..GRID {
                let s = r.s0 + (r.s1 - r.s0) * (T::from_usize(j) * step);
                radius = radius.max((self.surface.point(t, s) - center).norm());
            }
        }
        Ball { center, radius: radius * (T::ONE + T::from_f64(0.125)) }
    }

    /// A cone that holds the patch's unit normals: its axis and half-angle (radians), from the
    /// normals on a 5 × 5 grid over the parameter rectangle (corners and edges included),
    /// widened by the largest angle between neighbouring grid normals, as the enclosing ball
    /// is widened beyond its grid. `None` where the grid's normals do not fit in a cone of
    /// half-angle below π/2 (or none is finite and non-zero): the patch's normals are then not
    /// bounded to one side of any plane, and nothing can be settled from them.
    pub fn normal_cone(&self) -> Option<(Vec3<T>, T)> {
        const GRID: usize = 5;
        let r = self.rect;
        let step = T::ONE / T::from_usize(GRID - 1);
        let mut normals = [[None::<Vec3<T>>; GRID]; GRID];
        let mut sum = vec3(T::ZERO, T::ZERO, T::ZERO);
        for (i, row) in normals.iter_mut().enumerate() {
            let t = r.t0 + (r.t1 - r.t0) * (T::from_usize(i) * step);
            for (j, slot) in row.iter_mut().enumerate() {
                let s = r.s0 + (r.s1 - r.s0) * (T::from_usize(j) * step);
                let n = self.surface.normal(t, s);
                let len = n.norm();
                if len > T::ZERO && len.is_finite() {
                    let u = n.scale(T::ONE / len);
                    sum = sum + u;
                    *slot = Some(u);
                }
            }
        }
        let len = sum.norm();
        if !(len > T::ZERO && len.is_finite()) {
            return None;
        }
        let axis = sum.scale(T::ONE / len);
        let angle = |u: Vec3<T>, v: Vec3<T>| u.cross(v).norm().atan2(u.dot(v));
        let (mut spread, mut widen) = (T::ZERO, T::ZERO);
        for (i, row) in normals.iter().enumerate() {
            for (j, slot) in row.iter().enumerate() {
                let Some(u) = *slot else { continue };
                spread = spread.max(angle(axis, u));
                for (k, l) in [(i + 1, j), (i, j + 1)] {
                    if let Some(Some(v)) = normals.get(k).and_then(|row| row.get(l)) {
                        widen = widen.max(angle(u, *v));
                    }
                }
            }
        }
        let half_angle = spread + widen;
        (half_angle < T::PI * T::HALF).then_some((axis, half_angle))
    }

    /// Area by eq. (12), A = ∫∫ |n| ds dt, with the `order`-point Gauss rule on each axis.
    /// Exact (to rounding) when |n| is a polynomial of degree ≤ 2·order − 1 in each parameter
    /// (parallelograms, disks, cylinders); for the sphere zone the error falls like ρ^(−2·order).
    /// `Err` for an unsupported order, a non-finite normal, or a zero area.
    pub fn area(&self, order: usize) -> Result<T, PdmError> {
        let rule = GaussRule::<T>::new(order)?;
        let r = self.rect;
        let ht = (r.t1 - r.t0) * T::HALF;
        let hs = (r.s1 - r.s0) * T::HALF;
        let mut sum = T::ZERO;
        for (xt, wt) in rule.points() {
            let t = r.t0 + ht * (xt + T::ONE);
            let mut row = T::ZERO;
            for (xs, ws) in rule.points() {
                let s = r.s0 + hs * (xs + T::ONE);
                let n = self.surface.normal(t, s);
                if !n.is_finite() {
                    return Err(PdmError::NonFinite);
                }
                row += ws * n.norm();
            }
            sum += wt * row;
        }
        let area = sum * ht * hs;
        if !area.is_finite() {
            return Err(PdmError::NonFinite);
        }
        if !(area > T::ZERO) {
            return Err(PdmError::Degenerate);
        }
        Ok(area)
    }

    /// The area for the physical bounds of a pair: half the cross product of the diagonals for
    /// a flat patch with straight edges ([`Surface::straight_corners`], exact for any flat
    /// quadrilateral or triangle, and free of the rule's order² normals), else [`Patch::area`]
    /// at `order`.
    pub(crate) fn bounds_area(&self, order: usize) -> Result<T, PdmError> {
        #[cfg(feature = "closed-form")]
        if let Some([c0, c1, c2, c3]) = self.surface.straight_corners(self.rect) {
            let area = (c2 - c0).cross(c3 - c1).norm() * T::HALF;
            if !area.is_finite() {
                return Err(PdmError::NonFinite);
            }
            return if area > T::ZERO { Ok(area) } else { Err(PdmError::Degenerate) };
        }
        self.area(order)
    }

    /// The m × n grid of sub-patches of this patch (m along t, n along s), as an iterator.
    pub fn grid(&self, m: usize, n: usize) -> Result<PatchGrid<'s, T, S>, PdmError> {
        PatchGrid::over(self.surface, self.rect, m, n)
    }
}

/// An m × n grid of patches over a parameter rectangle; iterates row by row (t index outer),
/// without allocating. Neighbouring patches share their parameter bounds exactly.
#[derive(Debug)]
pub struct PatchGrid<'s, T, S: ?Sized> {
    surface: &'s S,
    rect: ParamRect<T>,
    m: usize,
    n: usize,
    next: usize,
}

/// Segments of the polylines that measure a side.
const SIDE_SEGMENTS: usize = 12;

/// Arc lengths of a patch's image along t and along s: the longest of the polylines (12
/// segments) along the two edges and the mid-line in each direction. A chord would be zero on a
/// side that closes on itself (the θ side of a whole disk, cylinder or sphere band).
pub(crate) fn side_lengths<T: Real, S: Surface<T> + ?Sized>(p: &Patch<'_, T, S>) -> (T, T) {
    let r = p.rect();
    let g = p.surface();
    let n = T::from_usize(SIDE_SEGMENTS);
    let polyline = |point: &dyn Fn(T) -> crate::vec3::Vec3<T>| {
        let mut length = T::ZERO;
        let mut prev = point(T::ZERO);
        for k in 1..=SIDE_SEGMENTS {
            let next = point(T::from_usize(k) / n);
            length += (next - prev).norm();
            prev = next;
        }
        length
    };
    let (mut along_t, mut along_s) = (T::ZERO, T::ZERO);
    for f in [T::ZERO, T::HALF, T::ONE] {
        let s = r.s0 + (r.s1 - r.s0) * f;
        let t = r.t0 + (r.t1 - r.t0) * f;
        along_t = along_t.max(polyline(&|x| g.point(r.t0 + (r.t1 - r.t0) * x, s)));
        along_s = along_s.max(polyline(&|x| g.point(t, r.s0 + (r.s1 - r.s0) * x)));
    }
    (along_t, along_s)
}

/// Half `k` (0 or 1) of a patch with side lengths `(along_t, along_s)`, split across the
/// longer one.
pub(crate) fn half_patch<'s, T: Real, S: Surface<T> + ?Sized>(
    p: &Patch<'s, T, S>,
    (along_t, along_s): (T, T),
    k: usize,
) -> Option<Patch<'s, T, S>> {
    let r: ParamRect<T> = p.rect();
    let cell = if along_t >= along_s { r.cell(k, 0, 2, 1) } else { r.cell(0, k, 1, 2) };
    Patch::new(p.surface(), cell).ok()
}

impl<T: Copy, S: ?Sized> Clone for PatchGrid<'_, T, S> {
    fn clone(&self) -> Self {
        Self { surface: self.surface, rect: self.rect, m: self.m, n: self.n, next: self.next }
    }
}

impl<'s, T: Real, S: Surface<T> + ?Sized> PatchGrid<'s, T, S> {
    /// The m × n grid over the whole domain of `surface`.
    pub fn new(surface: &'s S, m: usize, n: usize) -> Result<Self, PdmError> {
        Self::over(surface, surface.domain(), m, n)
    }

    /// The m × n grid over `rect`. `Err(EmptyParameterRange)` if m or n is 0; `Err` for a bad rect.
    pub fn over(surface: &'s S, rect: ParamRect<T>, m: usize, n: usize) -> Result<Self, PdmError> {
        if m == 0 || n == 0 {
            return Err(PdmError::EmptyParameterRange);
        }
        // m·n must be countable (the iterator indexes cells by k < m·n).
        if m.checked_mul(n).is_none() {
            return Err(PdmError::CapacityExceeded { needed: usize::MAX, capacity: usize::MAX });
        }
        rect.validate()?;
        if !surface.domain().contains(&rect) {
            return Err(PdmError::OutsideDomain);
        }
        Ok(Self { surface, rect, m, n, next: 0 })
    }

    /// Grid size (m, n).
    #[must_use]
    pub fn dims(&self) -> (usize, usize) {
        (self.m, self.n)
    }

    /// Number of patches, m·n.
    #[must_use]
    pub fn count(&self) -> usize {
        self.m.saturating_mul(self.n)
    }

    /// The summed area of the patches the grid has yet to yield (all of them for a new grid),
    /// each by eq. (12) with the `order`-point rule ([`Patch::area`]): A_A of eqs. (25)–(26).
    pub fn area(&self, order: usize) -> Result<T, PdmError> {
        let mut total = T::ZERO;
        for p in self.clone() {
            total += p.area(order)?;
        }
        Ok(total)
    }

    /// Patch (i, j): i-th along t, j-th along s; `None` outside the grid.
    #[must_use]
    pub fn cell(&self, i: usize, j: usize) -> Option<Patch<'s, T, S>> {
        if i >= self.m || j >= self.n {
            return None;
        }
        Some(Patch { surface: self.surface, rect: self.rect.cell(i, j, self.m, self.n) })
    }
}

impl<'s, T: Real, S: Surface<T> + ?Sized> Iterator for PatchGrid<'s, T, S> {
    type Item = Patch<'s, T, S>;
    fn next(&mut self) -> Option<Self::Item> {
        if self.next >= self.m.saturating_mul(self.n) {
            return None;
        }
        let k = self.next;
        self.next += 1;
        self.cell(k / self.n, k % self.n)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.m.saturating_mul(self.n)).saturating_sub(self.next);
        (left, Some(left))
    }
}

impl<T: Real, S: Surface<T> + ?Sized> ExactSizeIterator for PatchGrid<'_, T, S> {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Cylinder, Parallelogram, Side, Sphere};
    use crate::vec3::{vec3, Vec3};

    /// Every point of a dense grid lies in the enclosing ball, for flat and curved cells up to
    /// a whole hemisphere band; for a flat cell the ball is the corners' (up to the 1/8 margin).
    #[test]
    fn enclosing_ball_contains_the_whole_patch() {
        let sphere = Sphere::outer(vec3(0.5, -1.0, 2.0), 1.3).unwrap();
        let cylinder = Cylinder::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 0.7, 2.0, Side::Outer).unwrap();
        let square = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let check = |patch_points: &dyn Fn(f64, f64) -> Vec3<f64>, ball: Ball<f64>| {
            for i in 0..=200 {
                for j in 0..=200 {
                    let x = patch_points(f64::from(i) / 200.0, f64::from(j) / 200.0);
                    assert!((x - ball.center).norm() <= ball.radius, "{x:?} outside {ball:?}");
                }
            }
        };
        for (m, n) in [(1, 1), (2, 2), (2, 4), (8, 8)] {
            for patch in PatchGrid::new(&sphere, m, n).unwrap() {
                let r = patch.rect();
                check(&|u, v| sphere.point(r.t0 + u * (r.t1 - r.t0), r.s0 + v * (r.s1 - r.s0)), patch.enclosing_ball());
            }
            for patch in PatchGrid::new(&cylinder, m, n).unwrap() {
                let r = patch.rect();
                check(
                    &|u, v| cylinder.point(r.t0 + u * (r.t1 - r.t0), r.s0 + v * (r.s1 - r.s0)),
                    patch.enclosing_ball(),
                );
            }
        }
        let ball = Patch::whole(&square).unwrap().enclosing_ball();
        let half_diagonal = 5.0f64.sqrt() / 2.0;
        assert!((ball.radius / half_diagonal - 1.125).abs() < 1e-12, "{ball:?}");
        assert!((ball.center - vec3(1.0, 0.5, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn sphere_zone_area_converges_to_exact() {
        // Zone between polar angles φ0 and φ1 over the full circle: 2πR²(cos φ0 − cos φ1).
        let r = 1.7;
        let s = Sphere::outer(vec3(0.0, 0.0, 0.0), r).unwrap();
        let (p0, p1) = (0.3_f64, 1.9_f64);
        let rect = ParamRect::new(p0, p1, 0.0, 2.0 * core::f64::consts::PI).unwrap();
        let exact = 2.0 * core::f64::consts::PI * r * r * (p0.cos() - p1.cos());
        let patch = Patch::new(&s, rect).unwrap();
        let coarse = (patch.area(3).unwrap() - exact).abs() / exact;
        let fine = (patch.area(12).unwrap() - exact).abs() / exact;
        assert!(coarse > 1e-6, "order 3 should not be exact: {coarse}");
        assert!(fine < 1e-14, "order 12 relative error {fine}");
        // f32
        let s32 = Sphere::outer(vec3(0.0_f32, 0.0, 0.0), r as f32).unwrap();
        let rect32 = ParamRect::new(p0 as f32, p1 as f32, 0.0, 2.0 * core::f32::consts::PI).unwrap();
        let a32 = Patch::new(&s32, rect32).unwrap().area(12).unwrap() as f64;
        let allowed = if cfg!(feature = "micromath") { 5e-3 } else { 2e-6 };
        assert!((a32 - exact).abs() / exact < allowed, "f32 {a32} vs {exact}");
    }

    #[test]
    fn whole_sphere_area() {
        let s = Sphere::outer(vec3(1.0, 2.0, 3.0), 2.0).unwrap();
        let total: f64 = PatchGrid::new(&s, 8, 16).unwrap().map(|p| p.area(8).unwrap()).sum();
        let exact = 4.0 * core::f64::consts::PI * 4.0;
        assert!((total - exact).abs() / exact < 1e-14);
    }

    #[test]
    fn cylinder_band_and_parallelogram_areas_are_exact() {
        let c = Cylinder::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), 0.8, 3.0, Side::Inner).unwrap();
        let band = Patch::new(&c, ParamRect::new(0.5, 2.0, 1.0, 2.5).unwrap()).unwrap();
        let exact = 0.8 * 1.5 * 1.5;
        assert!((band.area(2).unwrap() - exact).abs() / exact < 1e-15);
        let p = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.5, 3.0, 0.0)).unwrap();
        assert!((Patch::whole(&p).unwrap().area(1).unwrap() - 6.0).abs() < 1e-15);
        let p32 = Parallelogram::new(vec3(0.0_f32, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.5, 3.0, 0.0)).unwrap();
        // Exact with libm's square root; within its error with micromath's approximation.
        let area32 = Patch::whole(&p32).unwrap().area(1).unwrap();
        assert!((area32 - 6.0).abs() <= 6.0 * <f32 as crate::real::Real>::ELEMENTARY_ERROR, "{area32}");
    }

    #[test]
    fn grid_iterates_every_cell_once_and_tiles_the_domain() {
        let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let g = PatchGrid::new(&s, 4, 8).unwrap();
        assert_eq!(g.len(), 32);
        let cells: heapless::Vec<_, 32> = g.map(|p| p.rect()).collect();
        assert_eq!(cells.len(), 32);
        assert_eq!(cells[0].t0, 0.0);
        assert_eq!(cells[31].t1, core::f64::consts::PI);
        assert_eq!(cells[31].s1, 2.0 * core::f64::consts::PI);
        assert_eq!(cells[0].s1, cells[1].s0);
        assert_eq!(cells[0].t1, cells[8].t0);
    }

    #[test]
    fn bad_patches_are_errors() {
        let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        assert_eq!(PatchGrid::new(&s, 0, 3).err(), Some(PdmError::EmptyParameterRange));
        let outside = ParamRect { t0: -1.0, t1: 1.0, s0: 0.0, s1: 1.0 };
        assert_eq!(Patch::new(&s, outside).err(), Some(PdmError::OutsideDomain));
        let nan = ParamRect { t0: f64::NAN, t1: 1.0, s0: 0.0, s1: 1.0 };
        assert_eq!(Patch::new(&s, nan).err(), Some(PdmError::NonFinite));
        let empty = ParamRect { t0: 1.0, t1: 1.0, s0: 0.0, s1: 1.0 };
        assert_eq!(Patch::new(&s, empty).err(), Some(PdmError::EmptyParameterRange));
        let whole = Patch::whole(&s).unwrap();
        assert_eq!(whole.area(0).err(), Some(PdmError::UnsupportedOrder { order: 0 }));
        assert_eq!(whole.area(33).err(), Some(PdmError::UnsupportedOrder { order: 33 }));
    }
}
