//! J(p) over a parallelogram b past flat convex occluders and at most one sphere, in closed
//! form: the visible part of b is b less the polygons' shadows, cut into convex pieces, and J is
//! Lambert's point-to-polygon form over those pieces, each less the sphere's cone of directions.
//!
//! A point q of b's plane is hidden from p by a convex polygon O exactly where the segment p → q
//! crosses O. Only the part O′ of O between b's plane and the plane through p parallel to it can
//! be crossed (the segment's height above b falls from p's to zero), and q is hidden by O′
//! exactly where it lies in the cone from p through O′: inside every plane through p and a side
//! of O′. On b's plane each such plane is a line, affine in b's parameters (t, s), so a shadow is
//! an intersection of half-planes in (t, s), with no projection to infinity where O′ reaches
//! p's height. The visible part is b, clipped by p's tangent plane, less each shadow in turn: a
//! convex piece less a shadow is the pieces outside each of its sides in turn (the part inside
//! all of them is dropped), and a piece that lies wholly outside one side is passed on whole.
//! Every piece keeps b's orientation, so J = ½ |Σ Lambert terms over all pieces|; the cuts
//! between pieces cancel. A sphere wholly on p's side of b's plane hides the directions of its
//! cone from p; each piece less that cone is taken as [`Inner::point_past_sphere`] takes b
//! (`polygon_past_sphere`), the pieces being disjoint.
//!
//! Polygons lying in b's plane (b itself, its neighbours on a mesh) or whose plane passes
//! through p to rounding (a, and a's neighbours; as `visibility::on_plane`) cast no shadow of
//! positive area and are left out. `None` where the occluders that may cut are not all flat
//! convex polygons and one sphere ([`Occluder::shadow_casters`]), where the pieces or their
//! vertices overflow the fixed buffers, or where the terms cancel beyond
//! [`polygon_cancellation`]: the caller then integrates by lines.

use super::*;
use crate::visibility::Caster;

/// Most occluder polygons casting a shadow on b from one point.
const MAX_SHADOWS: usize = 16;

/// Most sides of one shadow: a quadrilateral clipped by two planes.
const SHADOW_SIDES: usize = 6;

/// Most vertices of one piece of b (each side a cut adds at most one).
const PIECE_VERTICES: usize = 10;

/// Most pieces waiting to be cut by the later shadows.
const MAX_PIECES: usize = 24;

/// A line a·t + b·s + c in b's parameters, positive inside a shadow.
type Side<T> = [T; 3];

/// One shadow: the intersection of its sides' positive half-planes.
#[derive(Clone, Copy)]
struct Shadow<T> {
    sides: [Side<T>; SHADOW_SIDES],
    count: usize,
}

/// A convex piece of b in its parameters, and the first shadow still to cut it.
#[derive(Clone, Copy)]
struct Piece<T> {
    vertices: [(T, T); PIECE_VERTICES],
    count: usize,
    next: usize,
}

impl<T: Real> Piece<T> {
    fn vertices(&self) -> &[(T, T)] {
        self.vertices.get(..self.count).unwrap_or_default()
    }

    /// The part of the piece where `side` ≥ 0 (`keep_positive`) or ≤ 0 (Sutherland–Hodgman
    /// against one line); `None` if it overflows [`PIECE_VERTICES`].
    fn clip(&self, side: Side<T>, keep_positive: bool) -> Option<Self> {
        let mut out = Piece { vertices: [(T::ZERO, T::ZERO); PIECE_VERTICES], count: 0, next: self.next };
        self.clip_into(side, keep_positive, &mut out)?;
        Some(out)
    }

    /// [`Self::clip`] written into `out` (its vertices overwritten, `next` taken from `self`),
    /// which saves the copies of a returned piece in the loop over a shadow's sides.
    fn clip_into(&self, side: Side<T>, keep_positive: bool, out: &mut Self) -> Option<()> {
        let sign = if keep_positive { T::ONE } else { -T::ONE };
        let value = |(t, s): (T, T)| sign * (side[0] * t + side[1] * s + side[2]);
        out.count = 0;
        out.next = self.next;
        let verts = self.vertices();
        for (k, &v) in verts.iter().enumerate() {
            let w = *verts.get((k + 1) % verts.len())?;
            let (dv, dw) = (value(v), value(w));
            if dv >= T::ZERO {
                *out.vertices.get_mut(out.count)? = v;
                out.count += 1;
            }
            if (dv >= T::ZERO) != (dw >= T::ZERO) {
                let f = dv / (dv - dw);
                *out.vertices.get_mut(out.count)? = (v.0 + (w.0 - v.0) * f, v.1 + (w.1 - v.1) * f);
                out.count += 1;
            }
        }
        Some(())
    }

    /// Whether the whole piece lies on the non-positive side of `side`, to rounding.
    fn outside(&self, side: Side<T>) -> bool {
        let margin = T::from_f64(64.0) * T::EPSILON;
        self.vertices().iter().all(|&(t, s)| {
            let size = (side[0] * t).abs() + (side[1] * s).abs() + side[2].abs();
            side[0] * t + side[1] * s + side[2] <= margin * size
        })
    }
}

impl<T: Real, SB: Surface<T> + ?Sized, O: Occluder<T> + ?Sized> Inner<'_, T, SB, O> {
    /// b's corners where b is a parallelogram.
    fn corners(&self) -> Option<[Vec3<T>; 4]> {
        Some(map_corners(self.parallelogram?, self.r))
    }

    /// Whether b is a parallelogram and every occluder that may cut a segment from p to it is
    /// a flat convex polygon or a sphere ([`Occluder::shadow_casters`]): the check before
    /// [`Self::point_past_polygons`], whose buffers are not put on the stack otherwise.
    pub(super) fn polygons_only(&self, p: Vec3<T>, bounds: &Ball<T>) -> bool {
        self.corners().is_some_and(|corners| {
            self.occluders.shadow_casters(&Ball { center: p, radius: T::ZERO }, &corners, bounds, &mut |_| {})
        })
    }

    /// J(p) over a parallelogram b whose possible occluders from p are flat convex polygons and
    /// at most one sphere ([`Occluder::shadow_casters`]), in closed form (module docs); `None`
    /// where it does not apply or its terms cancel: the caller integrates by lines.
    #[inline(never)]
    pub(super) fn point_past_polygons(&self, p: Vec3<T>, np: Vec3<T>, bounds: &Ball<T>) -> Option<T> {
        let (o, et, es) = self.parallelogram?;
        let r = self.r;
        let nq = self.surface.normal(r.t0, r.s0);
        let nq = nq.scale(T::ONE / nq.norm());
        let hp = nq.dot(p - o);
        if !(hp > T::ZERO) {
            return Some(T::ZERO);
        }
        // b in its parameters, clipped by p's tangent plane.
        let mut start = Piece { vertices: [(T::ZERO, T::ZERO); PIECE_VERTICES], count: 4, next: 0 };
        for (slot, corner) in start.vertices.iter_mut().zip([(r.t0, r.s0), (r.t1, r.s0), (r.t1, r.s1), (r.t0, r.s1)]) {
            *slot = corner;
        }
        let start = start.clip([np.dot(et), np.dot(es), np.dot(o - p)], true)?;
        if start.count < 3 {
            return Some(T::ZERO);
        }
        let flat = T::GEOMETRY_TOLERANCE * bounds.radius.max(T::MIN_POSITIVE);
        let mut shadows = [Shadow { sides: [[T::ZERO; 3]; SHADOW_SIDES], count: 0 }; MAX_SHADOWS];
        let mut found = 0usize;
        let mut overflow = false;
        let corners = self.corners()?;
        let mut sphere: Option<Ball<T>> = None;
        let supported =
            self.occluders.shadow_casters(&Ball { center: p, radius: T::ZERO }, &corners, bounds, &mut |caster| {
                if overflow {
                    return;
                }
                let corners = match caster {
                    Caster::Polygon(corners) => corners,
                    // One sphere, wholly on p's side of b's plane (with a relative margin): every
                    // ray from p that meets it does so before b's plane, so its shadow is the cone
                    // of directions to it, taken from every piece (`polygon_past_sphere`).
                    Caster::Sphere(ball) => {
                        let margin = ball.radius * T::GEOMETRY_TOLERANCE.sqrt();
                        overflow |= sphere.is_some() || !(nq.dot(ball.center - o) > ball.radius + margin);
                        sphere = Some(ball);
                        return;
                    }
                };
                // A facet of a convex solid facing away from p: the facets facing p hide
                // everything it does.
                if self.back_facets.skips(corners, p) {
                    return;
                }
                match shadow_of(corners, p, hp, nq, o, et, es, flat) {
                    // A shadow that misses the part of b in front of p takes no slot.
                    Some(Some(shadow))
                        if shadow
                            .sides
                            .get(..shadow.count)
                            .unwrap_or_default()
                            .iter()
                            .any(|&side| start.outside(side)) => {}
                    Some(Some(shadow)) => match shadows.get_mut(found) {
                        Some(slot) => {
                            *slot = shadow;
                            found += 1;
                        }
                        None => overflow = true,
                    },
                    Some(None) => {}
                    None => overflow = true,
                }
            });
        if !supported || overflow {
            return None;
        }
        self.tick();
        let shadows = shadows.get(..found).unwrap_or_default();
        let mut stack = [start; MAX_PIECES];
        let mut pending = 1usize;
        let (mut sum, mut magnitude) = (T::ZERO, T::ZERO);
        while pending > 0 {
            pending -= 1;
            let mut piece = *stack.get(pending)?;
            if piece.count < 3 {
                continue;
            }
            // The next shadow that reaches into the piece.
            while let Some(shadow) = shadows.get(piece.next) {
                let sides = shadow.sides.get(..shadow.count).unwrap_or_default();
                if sides.iter().any(|&side| piece.outside(side)) {
                    piece.next += 1;
                } else {
                    break;
                }
            }
            let Some(shadow) = shadows.get(piece.next) else {
                // Visible: Lambert's terms along its outline, or the piece less the sphere's
                // cone.
                let at = |(t, s): (T, T)| o + et.scale(t) + es.scale(s);
                let verts = piece.vertices();
                if let Some(ball) = sphere {
                    // The piece's corners, each once (a cut through a corner repeats it).
                    let mut poly = [Vec3::ZERO; PIECE_VERTICES];
                    let mut m = 0usize;
                    for &v in verts {
                        let x = at(v);
                        if m == 0 || poly.get(m - 1) != Some(&x) {
                            *poly.get_mut(m)? = x;
                            m += 1;
                        }
                    }
                    if m > 1 && poly.first() == poly.get(m - 1) {
                        m -= 1;
                    }
                    if m < 3 {
                        continue;
                    }
                    let (visible, size) = polygon_past_sphere(p, np, poly.get_mut(..m)?, &ball)?;
                    sum += visible;
                    magnitude += size;
                    continue;
                }
                for (k, &v) in verts.iter().enumerate() {
                    let (term, size) = arc(np, at(v) - p, at(*verts.get((k + 1) % verts.len())?) - p);
                    sum += term;
                    magnitude += size;
                }
                continue;
            };
            // The piece less the shadow: outside side 1, then inside 1 and outside 2, ...
            let (mut first, mut second) = (Piece { next: piece.next + 1, ..piece }, piece);
            let (mut rest, mut spare) = (&mut first, &mut second);
            for &side in shadow.sides.get(..shadow.count).unwrap_or_default() {
                // The part outside this side waits on the stack (a full stack: a piece of
                // its own, which must then be empty).
                let mut overflow = piece;
                let slot = match stack.get_mut(pending) {
                    Some(slot) => slot,
                    None => &mut overflow,
                };
                rest.clip_into(side, false, slot)?;
                if slot.count >= 3 {
                    if pending >= MAX_PIECES {
                        return None;
                    }
                    pending += 1;
                }
                rest.clip_into(side, true, spare)?;
                core::mem::swap(&mut rest, &mut spare);
                if rest.count < 3 {
                    break;
                }
            }
        }
        let j = sum.abs() * T::HALF;
        let limit = polygon_cancellation::<T>();
        let settled = magnitude <= limit * sum.abs() || magnitude <= limit * T::TWO * self.reach(p);
        (j.is_finite() && settled).then_some(j)
    }
}

/// The shadow of the convex polygon `corners` from p on b's plane (through `o`, unit normal
/// `nq` towards p, at height `hp` below p; parameters along `et`, `es`): `Some(None)` where it
/// has no area (the polygon lies in b's plane, outside the slab between b's plane and p, or
/// in a plane through p), `None` where the polygon has too many sides.
#[allow(clippy::too_many_arguments)]
fn shadow_of<T: Real>(
    corners: &[Vec3<T>],
    p: Vec3<T>,
    hp: T,
    nq: Vec3<T>,
    o: Vec3<T>,
    et: Vec3<T>,
    es: Vec3<T>,
    flat: T,
) -> Option<Option<Shadow<T>>> {
    if corners.len() > 4 {
        return None;
    }
    if corners.iter().all(|&c| nq.dot(c - o).abs() <= flat) {
        return Some(None);
    }
    // A polygon whose plane passes through p to rounding (a itself, or p's rounding just below
    // a's plane): segments from p meet it only at p, as the occluders' own test says
    // (`visibility::on_plane`).
    let &first_corner = corners.first()?;
    let normal = corners.iter().enumerate().fold(Vec3::ZERO, |n, (k, &v)| {
        let w = corners.get((k + 1) % corners.len()).copied().unwrap_or(v);
        n + (v - first_corner).cross(w - first_corner)
    });
    let offset = normal.dot(first_corner - p);
    let scale = p.max_abs() + first_corner.max_abs() + (p - first_corner).max_abs();
    if !(offset.abs() > T::from_f64(64.0) * T::EPSILON * normal.norm() * scale) {
        return Some(None);
    }
    // Clip to the slab 0 ≤ h ≤ hp (Sutherland–Hodgman, two planes).
    let mut poly = [Vec3::ZERO; SHADOW_SIDES];
    let mut n = 0usize;
    let mut first = [Vec3::ZERO; SHADOW_SIDES];
    let mut m = 0usize;
    let height = |x: Vec3<T>| nq.dot(x - o);
    for (k, &v) in corners.iter().enumerate() {
        let w = *corners.get((k + 1) % corners.len())?;
        let (hv, hw) = (height(v), height(w));
        if hv >= T::ZERO {
            *first.get_mut(m)? = v;
            m += 1;
        }
        if (hv >= T::ZERO) != (hw >= T::ZERO) {
            *first.get_mut(m)? = v + (w - v).scale(hv / (hv - hw));
            m += 1;
        }
    }
    let first = first.get(..m).unwrap_or_default();
    for (k, &v) in first.iter().enumerate() {
        let w = *first.get((k + 1) % first.len())?;
        let (hv, hw) = (hp - height(v), hp - height(w));
        if hv >= T::ZERO {
            *poly.get_mut(n)? = v;
            n += 1;
        }
        if (hv >= T::ZERO) != (hw >= T::ZERO) {
            *poly.get_mut(n)? = v + (w - v).scale(hv / (hv - hw));
            n += 1;
        }
    }
    if n < 3 {
        return Some(None);
    }
    let poly = poly.get(..n).unwrap_or_default();
    let centre = poly.iter().fold(Vec3::ZERO, |c, &v| c + v).scale(T::ONE / T::from_usize(n));
    // The planes through p and each side, oriented so that the polygon's centre is inside.
    let mut shadow = Shadow { sides: [[T::ZERO; 3]; SHADOW_SIDES], count: 0 };
    let (mut signed, mut size) = (T::ZERO, T::ZERO);
    for (k, &v) in poly.iter().enumerate() {
        let w = *poly.get((k + 1) % n)?;
        let normal = (v - p).cross(w - p);
        signed += normal.dot(centre - p);
        size += normal.norm() * (centre - p).norm();
    }
    // The polygon's plane passes through p (to rounding): its shadow has no area.
    if !(signed.abs() > T::from_f64(64.0) * T::EPSILON * size) {
        return Some(None);
    }
    let orientation = if signed > T::ZERO { T::ONE } else { -T::ONE };
    for (k, &v) in poly.iter().enumerate() {
        let w = *poly.get((k + 1) % n)?;
        let normal = (v - p).cross(w - p).scale(orientation);
        if !(normal.norm2() > T::ZERO) {
            continue;
        }
        *shadow.sides.get_mut(shadow.count)? = [normal.dot(et), normal.dot(es), normal.dot(o - p)];
        shadow.count += 1;
    }
    Some((shadow.count >= 3).then_some(shadow))
}
