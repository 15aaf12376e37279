//! The part of a flat pair's exchange that flat occluders block, for pairs that touch.
//!
//! Where two parallelograms share an edge or a corner, J(p) (the inner integral from a point p
//! of a) is singular where p meets the contact, and an outer rule across it converges only
//! as fast as cells graded towards the contact let it (`outer_cells`: 1e-5 on a room's
//! ceiling against a wall, erratic in the order). The pair's exchange is the unoccluded
//! exchange, which the contour form takes exactly with its contact in closed form
//! (`contour/`), less the part the occluders block:
//!
//! B = ∫_a J_blocked(p) dA, J_blocked(p) = J_unoccluded(p) − J_visible(p),
//!
//! both in closed form per point: b clipped by p's tangent plane (`Inner::point_to_polygon`)
//! and the same less the occluders' shadows (`shadows.rs`), or less one sphere's cone
//! (`Inner::point_past_sphere`). The singular part near the contact is the same in both and
//! cancels; where the occluders stay away from the contact, J_blocked is zero or smooth there,
//! and its only kinks are the occluders' outer events ([`PolygonEvents`]), which the outer rule
//! takes as breaks: B converges with the order like a separate pair's. `None` where any of this
//! does not apply, or an occluder comes nearer the contact than [`CLEARANCE`] (the caller takes
//! the pair by its other route).

use super::*;

/// The blocked part B of a touching flat pair (module docs), set up once for any order: the
/// pair, b's map and ball, and the occluders' outer events, which do not depend on the order.
pub(crate) struct Blocked<'x, T: Real, SA: ?Sized, SB: ?Sized, O: ?Sized> {
    a: &'x Patch<'x, T, SA>,
    b: &'x Patch<'x, T, SB>,
    map: (Vec3<T>, Vec3<T>, Vec3<T>),
    bounds: Ball<T>,
    events: PolygonEvents<T>,
    occluders: &'x O,
}

impl<'x, T, SA, SB, O> Blocked<'x, T, SA, SB, O>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    /// `None` where a or b is not a parallelogram, they share no corner, or the occluders give
    /// no polygon events clear of the contact ([`CLEARANCE`]).
    pub(crate) fn new(
        a: &'x Patch<'x, T, SA>,
        b: &'x Patch<'x, T, SB>,
        occluders: &'x O,
    ) -> Result<Option<Self>, PdmError> {
        let (surface, r) = (b.surface(), b.rect());
        let (Some(outer_map), Some(map)) = (a.surface().affine_map(), surface.affine_map()) else { return Ok(None) };
        let bounds = part_ball(surface, Some(map), r)?;
        let Some(contact) = contact(outer_map, a.rect(), map, r) else { return Ok(None) };
        let events = PolygonEvents::polygons((outer_map, a.rect()), (map, r), occluders, &bounds, false, Some(contact))
            // a is outside here whichever patch an occluder touches: where one stands on a and
            // two shadows meet, the curves cost O(n²) pieces and the rule still converges only
            // algebraically along the contact (two boxes standing on a floor, a wall sharing
            // its edge: 20× the points of the wall outside, for the same value).
            .filter(|events| !events.touched_and_meeting());
        Ok(events.map(|events| Self { a, b, map, bounds, events, occluders }))
    }

    /// B at `order`: (A_a·F_blocked, evaluations), finite but not bounds-checked; `None` where
    /// some outer point's J_blocked is not in closed form.
    pub(crate) fn sum(&self, order: usize) -> Result<Option<(T, u64)>, PdmError> {
        let (outer, surface, r) = (self.a.surface(), self.b.surface(), self.b.rect());
        let count = core::cell::Cell::new(0u64);
        let inner = Inner {
            surface,
            r,
            rule: GaussRule::<T>::new(order)?,
            probes: 2 * order + 3,
            affine: None,
            parallelogram: Some(self.map),
            trigonometric: false,
            concentric: None,
            outline: None,
            line_rule: GaussRule::<T>::new(order.max(16))?,
            back_facets: match outer.affine_map() {
                Some(outer_map) => {
                    BackFacets::of_pair((outer_map, self.a.rect()), (self.map, r), self.occluders, &self.bounds)
                }
                None => BackFacets::none(),
            },
            use_occluders: true,
            occluders: self.occluders,
            count: &count,
            scratch: core::cell::RefCell::new(LineScratch::new()),
            signature_line: core::cell::RefCell::new(Line::new()),
        };
        let mut closed = true;
        let mut f = |t: T, s: T| -> Result<T, PdmError> {
            let (p, n) = outer.point_and_normal(t, s);
            let area = n.norm();
            if !(area > T::ZERO) {
                return Ok(T::ZERO);
            }
            inner.tick();
            match point_blocked(&inner, &self.bounds, p, n.scale(T::ONE / area)) {
                Some(j) => Ok(area * j),
                None => {
                    closed = false;
                    Ok(T::ZERO)
                }
            }
        };
        let total = self.events.integrate(self.a.rect(), &inner.rule, &mut f)?;
        if !closed {
            return Ok(None);
        }
        Ok(Some((crate::bounds::finite(total * T::FRAC_1_PI)?, count.get())))
    }
}

/// How far from the contact, in the larger patch's diagonals, the occluders must keep
/// ([`contact`]): J_blocked is analytic within about that distance of the contact, and the outer
/// rule converges at a rate set by it. An occluder on the contact (a screen standing on the
/// shared edge) makes J_blocked singular there: 7e-3 off at order 6, where the boundary path
/// over the whole pair, graded towards the contact, is 9e-6 off.
const CLEARANCE: f64 = 0.125;

/// The contact of two touching parallelograms (corners of either lying on the other, to
/// rounding) as a segment (a point twice for a shared corner), with the clearance the occluders
/// must keep from it ([`CLEARANCE`]); `None` where no corner lies on the other patch.
fn contact<T: Real>(
    a: (Vec3<T>, Vec3<T>, Vec3<T>),
    ra: ParamRect<T>,
    b: (Vec3<T>, Vec3<T>, Vec3<T>),
    rb: ParamRect<T>,
) -> Option<(Vec3<T>, Vec3<T>, T)> {
    let (ac, bc) = (map_corners(a, ra), map_corners(b, rb));
    let diagonal = |c: &[Vec3<T>; 4]| (c[2] - c[0]).norm().max((c[3] - c[1]).norm());
    let size = diagonal(&ac).max(diagonal(&bc));
    let tolerance = size * T::GEOMETRY_TOLERANCE;
    let mut on = ac
        .iter()
        .filter(|&&x| distance_to_parallelogram(x, b, rb) <= tolerance)
        .chain(bc.iter().filter(|&&x| distance_to_parallelogram(x, a, ra) <= tolerance));
    let c0 = *on.next()?;
    let c1 = on.fold(c0, |far, &x| if (x - c0).norm() > (far - c0).norm() { x } else { far });
    Some((c0, c1, size * T::from_f64(CLEARANCE)))
}

/// J_blocked(p) = J_unoccluded(p) − J_visible(p), each in closed form; zero where no occluder
/// may cut from p, `None` where either side is not in closed form.
fn point_blocked<T, SB, O>(inner: &Inner<'_, T, SB, O>, bounds: &Ball<T>, p: Vec3<T>, np: Vec3<T>) -> Option<T>
where
    T: Real,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let from = Ball { center: p, radius: T::ZERO };
    if !inner.occluders.may_block_between(&from, bounds) {
        return Some(T::ZERO);
    }
    let unoccluded = inner.point_to_polygon(p, np)?;
    if occluder_hides(inner.occluders, p, bounds) {
        return Some(unoccluded);
    }
    let visible = match inner.occluders.shadow_sphere(&from, bounds) {
        Some(None) => return Some(T::ZERO),
        Some(Some(ball)) => inner.point_past_sphere(p, np, &ball)?,
        None if inner.polygons_only(p, bounds) => inner.point_past_polygons(p, np, bounds)?,
        None => return None,
    };
    Some(unoccluded - visible)
}
