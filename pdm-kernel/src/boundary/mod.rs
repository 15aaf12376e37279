//! Visibility boundaries placed into the rule ("Visibility boundaries" in the references).
//!
//! A Gauss rule converges exponentially only on smooth integrands. The back-face cut (where
//! n·e changes sign inside a patch: the terminator of a sphere seen from a point, a kink) and
//! occluder shadows (a jump) are not smooth, and a fixed rule sampling across them converges
//! algebraically. Here the outer patch a is integrated with its Gauss points as usual; for each
//! outer point p the inner patch b is integrated line by line (t-lines, Gauss in s), with the
//! visibility changes placed into the rule at both inner levels:
//!
//! * **Along a t-line**, the parameters t where visibility changes are found — in closed form
//!   when b is a parallelogram ([`Surface::affine_map`]) and every occluder gives its
//!   polynomials ([`Occluder::line_polynomials`]: sphere, parallelogram, quadrilateral, disk,
//!   tube, cone, and their combinations): the roots of the two facing tests (linear in t) and of the occluders'
//!   quadratics, each piece between roots classified by the exact test at its midpoint; when
//!   b's t-lines are circles on which both facing tests are first-degree trigonometric
//!   polynomials ([`Surface::facing_along_t`]: a sphere's meridians, a cylinder's or a cone's
//!   circles) and no occluder can cut, or only a sphere with the centre of b's sphere (whose
//!   test on b is a plane's, `concentric.rs`), the roots of those, in closed form, likewise; otherwise
//!   bracketed on 2·order + 3 probes and bisected to machine precision. Each visible piece gets
//!   its own Gauss rule.
//! * **Along s**, the line integral is smooth except where the lines' visibility structure
//!   changes: a boundary crossing a t-edge (a kink) or tangent to the t-lines (two breaks
//!   meeting, a square-root end point). In closed form these are roots of a quadratic in s
//!   (a polynomial's root crossing t₀ or t₁) and of a quartic (its discriminant), kept where the
//!   structure differs on the two sides; anything else (two polynomials' roots crossing: a
//!   polygonal shadow's corner, two shadows meeting) is bracketed on the probe grid and
//!   bisected, continuing after each change until the next probe's structure is reached.
//!   Each piece is integrated with the graded map s = s* + H·x² (smoothstep with both ends
//!   singular), which turns √(s − s*) into a smooth function, and a piece next to a much
//!   narrower neighbour (or a singular point just beyond b's edge) is cut geometrically towards
//!   it, so that nearly coincident singular points do not slow the rule.
//!
//! With both levels in closed form the inner integral converges exponentially for every p
//! (measured against an independent closed-form-chord reference, `pdm-host/tests/
//! kernel_inner_visibility.rs`: 1.9e-9, 3.6e-13, 1.2e-16 at orders 8, 12, 16; ≤ 6e-11 over 45
//! point/face/radius cases at order 24). What remains non-smooth is the **outer** integrand
//! J(p), on curves of face a where a shadow boundary becomes tangent to an edge of b or passes
//! through a corner. Where a and b are both parallelograms, b lies on one side of a's plane,
//! and one occluder gives these curves ([`Occluder::event_quadrics`]: the sphere; a tube whose
//! rims the pair keeps clear of, with both patches outside it: two planes per corner of b; with
//! several, where two shadows meet is no occluder's curve), they are conics in a's parameters and
//! are placed into the outer rule the same way (`events.rs`): whole faces across a sphere then
//! converge exponentially (cube faces against the independent reference: 1.3e-8 / 1.6e-11 at
//! orders 8 / 12, `pdm-host/tests/outer_events.rs`), and so do squares across a long tube (1e-8 /
//! 1e-12 / 1e-16 at orders 8 / 12 / 16, `tests/integration/tests/adaptive.rs`). Across flat convex occluders that are
//! one polygon or the facets of one convex solid ([`Occluder::shadow_casters`]), the curves are
//! lines: planes through an occluder vertex and an edge of b, through a corner of b and an
//! occluder edge, and the facets' planes (`polygon_events.rs`; a half-plane screen between two
//! squares: 4e-11 at order 8, 1e-16 at order 12). Where such a flat pair touches, the contour
//! form takes the unoccluded exchange with its contact in closed form, and only the part the
//! occluders block is integrated here (`blocked.rs`): its outer integrand has no contact
//! singularity where the occluders keep away from the contact. A flat a against a curved b that no
//! occluder cuts gets b's own curves where b gives them ([`Surface::event_quadrics`]: a sphere's
//! cells). A curved a whose facing tests are trigonometric in both parameters
//! ([`Surface::facing_across_s`]: a sphere's cells) against a parallelogram b that no occluder
//! cuts goes outside with J(p) by the point-to-polygon form, whose only kinks are where a's
//! tangent plane passes a corner of b and where a crosses b's plane: circles on a sphere, found
//! in closed form (`events.rs`, [`TrigonometricEvents`]; sphere cells summed against a tilted
//! rectangle against Ω/4π, same test file). A sphere's cell against a cell of a sphere with
//! the same centre, across a sphere occluder with that centre or none, has only circles about
//! the centre for boundaries: its events are plane sections of the outer sphere, placed the
//! same way (`concentric.rs`; an octant's row inside a sphere around a concentric one against
//! the closed form 1 − (r/R)², `tests/integration/tests/adaptive.rs`). A sphere's cell against a
//! parallelogram in front of all its tangent planes, across one sphere occluder anywhere, has
//! the occluder's tangent planes through b's edges (circles) and per corner of b the cone from
//! it tangent to the occluder, which meets a's sphere in a curve L₁² = L₂ with L₁, L₂ plane
//! tests: a second-degree trigonometric polynomial along each meridian, its crossings and
//! tangencies found by a quartic (`sphere_flat.rs`; orders 12 and 20 within 1e-11,
//! `general_geometry::sphere_cells_against_parallelograms_across_a_sphere_anywhere`). A cell of a
//! sphere with another centre around such a concentric pair's inner cell has curves of the
//! same kind only (`concentric::offcentre_events`). Elsewhere the outer rule samples across
//! them (algebraic convergence), which patch grids (and the outer split in [`crate::pair`])
//! reduce.
//!
//! Per outer point p the machinery runs only where it is needed: if no occluder meets the cone
//! of segments from p to b's bounding ball ([`Occluder::may_block_between`] with p as a ball of
//! radius zero: the exact distance to the hull of two balls) and a flat b faces p at all four
//! corners, b gets the plain `order` × `order` rule; if b lies behind p's tangent plane, behind
//! its own, or inside an occluder's shadow cone (`Occluder::hides_ball_from`), p adds zero. If
//! nothing can cut and a flat b straddles p's tangent plane or lies closer to p than its own
//! size, the inner integral is the point-to-polygon (Lambert) form over b clipped by p's
//! tangent plane: exact at the cost of a few arctangents on a parallelogram, and along the
//! outline (`contour::Outline::point_form`, graded line integrals) on a flat b with curved
//! edges (a disk or annulus sector, a planar Bézier patch), where the lines above would need
//! b refined towards p (half a wall standing 0.1 above a 4 × 4 floor: 2.9e8 evaluations at
//! order 16 by the lines, 1.5e5 by the polygon form, the same value to 16 digits).
//! Where the only occluder that may cut is one sphere lying wholly between b's plane and p
//! (`Occluder::shadow_sphere`), J(p) over a parallelogram b is in closed form too: the
//! projected solid angle of b's clipped polygon minus that of its intersection with the
//! sphere's cone of directions, whose boundary is polygon arcs and one circle arc
//! (`Inner::point_past_sphere`; against the lines at order 20 over 400 random placements:
//! 3e-15 of J). Where every occluder that may cut from p is a flat convex polygon
//! (parallelograms, a mesh's quadrilaterals and triangles) with at most one sphere on p's side
//! of b's plane ([`Occluder::shadow_casters`]), J(p) over a parallelogram b is in closed form as
//! well: b less the polygons' shadows, each an intersection of half-planes in b's parameters,
//! cut into convex pieces, each piece less the sphere's cone (`shadows.rs`; against the lines at
//! order 20 over 300 random placements, boxes among them: 4e-12 of the solid angle b subtends).
//! A room's facets gave too many polynomials for one line's buffer, and its lines were
//! bracketed and bisected at every outer point. Elsewhere where some occluder may cut, the s-level probe sweep (below) runs only on intervals where at
//! least two polynomials have roots on the lines: a root enters a line's range only at a
//! candidate, so with fewer no two roots can cross.
//!
//! Cost per outer point on the boundary path: order lines × (a few polynomial roots and ≤ 16 exact visibility tests,
//! or 2·order + 3 probes + ≈ 60 bisection probes per boundary, + order evaluations per visible
//! piece), plus the s-level search (3 polynomial evaluations, ≤ 2 structure tests per
//! candidate). No allocation: breakpoints live in fixed-size arrays (at most [`MAX_BREAKS`]
//! per line; a part with more is halved, and after [`MAX_SPLITS`] halvings integrated by the plain
//! rule with the visibility tested per node).
//!
//! Limitation: without closed form, a visibility change narrower than the bracketing grid
//! spacing (a shadow sliver between two probes) is not seen; its contribution is then sampled
//! by the rule as usual.
//!
//! Files: the pair level (outer cells, outer points, culling) here; `events.rs` (the outer
//! events of two parallelograms), `polygon_events.rs` (their lines across flat occluders),
//! `blocked.rs` (the blocked part of a touching pair), `inner.rs` (J(p) for one outer point),
//! `shadows.rs` (J(p) past flat occluders and one sphere), `lines.rs` (one inner line in closed
//! form), `breaks.rs` (bracketing and bisection).

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::integrand::{self, kernel, mutually_facing};
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::{Ball, PatchSamples};
use crate::surface::{ParamRect, Surface};
use crate::vec3::{vec3, Vec3};
use crate::visibility::Occluder;

#[cfg(feature = "closed-form")]
mod blocked;
mod breaks;
#[cfg(feature = "closed-form")]
mod concentric;
#[cfg(feature = "closed-form")]
mod events;
mod inner;
mod lines;
#[cfg(feature = "closed-form")]
mod polygon_events;
#[cfg(feature = "closed-form")]
mod shadows;
#[cfg(feature = "closed-form")]
mod sphere_flat;
#[cfg(feature = "closed-form")]
pub(crate) use blocked::Blocked;
use breaks::*;
#[cfg(feature = "closed-form")]
use concentric::*;
#[cfg(feature = "closed-form")]
use events::*;
use inner::*;
use lines::*;
#[cfg(feature = "closed-form")]
use polygon_events::*;

/// Largest number of visibility changes located on one inner line or in s at once; a part of
/// the inner patch with more is halved (see [`MAX_SPLITS`]), and one that still has more is
/// integrated by the plain rule with visibility tested per node.
pub const MAX_BREAKS: usize = 16;

/// Most successive 2 × 2 refinements of the inner patch towards an outer point closer than its
/// size (a 2^-30 ≈ 1e-9 part of b's size; a gap below that is integrated at that resolution).
pub const MAX_NEAR_DEPTH: u32 = 30;

/// Most successive halvings of the inner patch when its visibility changes overflow
/// [`MAX_BREAKS`] (≤ 2^MAX_SPLITS parts per outer point, 8 per direction: room for about
/// 8 · [`MAX_BREAKS`] changes along one line, 60 shadows); past them the part takes the plain
/// rule with visibility tested per node. Changes that halving does not separate — rounding
/// noise where a boundary grazes b along a line, or a pattern finer than any part — would
/// otherwise cost 2^(depth + 1) attempts per outer point.
pub const MAX_SPLITS: u32 = 6;

/// A_a·F_{a→b} with visibility boundaries placed into the inner rule (see the module docs);
/// `order` points per axis on a and per line and per visible piece on b.
pub fn boundary_exchange<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (value, _, area_a, area_b) = boundary_unchecked::<T, SA, SB, O, CAP>(a, b, order, occluders)?;
    crate::bounds::exchange(value, area_a, area_b)
}

/// [`boundary_exchange`] without the bounds check (finite only; see `bounds::finite`), with
/// the number of integrand evaluations it made (kernel evaluations plus visibility probes,
/// each of which evaluates the surface and the visibility tests) and the two patches' areas
/// at `order`.
pub(crate) fn boundary_unchecked<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64, T, T), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut outer = PatchSamples::<T, CAP>::new(a, order)?;
    let area_a = outer.area();
    let inner_samples = PatchSamples::<T, CAP>::new(b, order)?; // validates b (area, finiteness)
    let (value, count) = boundary_sum(a, &mut outer, b, &inner_samples, order, occluders)?;
    Ok((value, count, area_a, inner_samples.area()))
}

/// The boundary path on samples the caller holds (the pair context's two buffers): `outer`
/// holds a's samples and `inner_samples` b's, both at `order` (b's also validate it: area,
/// finiteness). `outer` is re-filled in place where a is cut into cells (a very near pair), so
/// the pair needs no third buffer. (A_a·F_{a→b}, evaluations), finite but not bounds-checked.
pub(crate) fn boundary_sum<T, SA, SB, O, const CA: usize, const CB: usize>(
    a: &Patch<'_, T, SA>,
    outer: &mut PatchSamples<T, CA>,
    b: &Patch<'_, T, SB>,
    inner_samples: &PatchSamples<T, CB>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let count = core::cell::Cell::new(0u64);
    let r = b.rect();
    let surface = b.surface();
    // Closed form when b is a parallelogram and every occluder can give its polynomials.
    #[cfg(feature = "closed-form")]
    let affine = surface.affine_map();
    #[cfg(not(feature = "closed-form"))]
    let affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)> = None;
    // Whether an occluder can cut the integrand anywhere on b (not only at its Gauss points);
    // a flat b's corners give the smallest ball containing it.
    let inner_bounds = part_ball(surface, affine, r)?;
    let use_occluders = occluders.may_block_between(&a.enclosing_ball(), &inner_bounds);
    let closed_form = match affine {
        Some((o, et, _)) => {
            // Two facing tests plus the occluders' polynomials must fit one line's buffer.
            let mut polys = 2usize;
            !use_occluders
                || (occluder_polynomials(occluders, o + et, o, et, &mut |_| polys += 1) && polys <= MAX_POLYS)
        }
        None => false,
    };
    #[cfg(feature = "closed-form")]
    let concentric = match (affine, use_occluders) {
        (None, true) => Concentric::of(surface, &inner_bounds, &a.enclosing_ball(), occluders),
        _ => None,
    };
    let inner = Inner {
        surface,
        r,
        rule: GaussRule::<T>::new(order)?,
        probes: 2 * order + 3,
        affine: if closed_form { affine } else { None },
        #[cfg(feature = "closed-form")]
        parallelogram: affine,
        #[cfg(feature = "closed-form")]
        trigonometric: affine.is_none()
            && (!use_occluders || concentric.is_some())
            && surface.facing_along_t(r.s0, Vec3::ZERO, vec3(T::ZERO, T::ZERO, T::ONE)).is_some(),
        #[cfg(feature = "closed-form")]
        concentric,
        #[cfg(feature = "closed-form")]
        outline: if affine.is_none() { crate::contour::Outline::new(b) } else { None },
        #[cfg(feature = "closed-form")]
        line_rule: GaussRule::<T>::new(order.max(16))?,
        #[cfg(feature = "closed-form")]
        back_facets: match (a.surface().affine_map(), affine) {
            (Some(outer_map), Some(inner_map)) if use_occluders => {
                BackFacets::of_pair((outer_map, a.rect()), (inner_map, r), occluders, &inner_bounds)
            }
            _ => BackFacets::none(),
        },
        use_occluders,
        occluders,
        count: &count,
        scratch: core::cell::RefCell::new(LineScratch::new()),
        signature_line: core::cell::RefCell::new(Line::new()),
    };
    // The outer integrand J(p) varies on the scale of p's distance to b: where the pair is very
    // near (`very_near`; a sphere 1e-3 above a plate: J peaks under the closest point, and steps
    // where a passes over b's edges, both on the gap's scale), the outer rule over the whole of
    // a samples a layer it cannot resolve and its error does not fall with the order. a is then
    // cut into cells, each no closer to b than its own radius (`outer_cells`).
    let (cells, n_cells) = outer_cells(a, b, &inner)?;
    #[cfg(feature = "closed-form")]
    if let Some(total) = events_sum(a, cells.get(..n_cells).unwrap_or_default(), &inner, inner_samples, &inner_bounds)?
    {
        let value = crate::bounds::finite(total * T::FRAC_1_PI)?;
        return Ok((value, count.get()));
    }
    let mut total = T::ZERO;
    if n_cells > 1 {
        for cell in cells.iter().take(n_cells) {
            outer.fill(&Patch::new(a.surface(), *cell)?, order, order)?;
            total += outer_sum(outer, &inner, inner_samples, &inner_bounds)?;
        }
    } else {
        total = outer_sum(outer, &inner, inner_samples, &inner_bounds)?;
    }
    let value = crate::bounds::finite(total * T::FRAC_1_PI)?;
    Ok((value, count.get()))
}

/// The outer integral over the cells of a flat a with the events placed into the outer rule
/// (`events.rs`); `None` where there are none to place ([`pair_events`]).
#[cfg(feature = "closed-form")]
#[inline(never)]
fn events_sum<T, SA, SB, O, const CB: usize>(
    a: &Patch<'_, T, SA>,
    cells: &[ParamRect<T>],
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
) -> Result<Option<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let surface = a.surface();
    if let Some(total) = concentric_sum(a, cells, inner, inner_samples, inner_bounds)? {
        return Ok(Some(total));
    }
    let events = match surface.affine_map() {
        Some(outer_map) => pair_events(
            outer_map,
            a.rect(),
            inner.surface,
            inner.r,
            inner.affine,
            inner.use_occluders,
            inner.occluders,
            inner_bounds,
        )
        .map(OuterEvents::Flat),
        None => curved_outer_events(surface, inner.affine, inner.r, inner.use_occluders).map(OuterEvents::Curved),
    };
    let Some(events) = events else {
        return polygon_events_sum(a, cells, inner, inner_samples, inner_bounds);
    };
    let mut f = |t: T, s: T| outer_integrand(surface, t, s, inner, inner_samples, inner_bounds);
    let mut total = T::ZERO;
    for cell in cells {
        total += match &events {
            OuterEvents::Flat(e) => e.integrate(*cell, &inner.rule, &mut f)?,
            OuterEvents::Curved(e) => e.integrate(*cell, &inner.rule, &mut f)?,
        };
    }
    Ok(Some(total))
}

/// The outer integral over the cells of a sphere's cell a against a cell of a sphere with the
/// same centre, across a sphere occluder concentric with both or none ([`concentric_events`]),
/// or against a parallelogram inside a's sphere across a sphere with its centre
/// ([`shell_flat_of`]), with the events placed into the outer rule (`concentric.rs`); `None`
/// where they are not available. In a frame of its own: the events take more room than the
/// other kinds'.
#[cfg(feature = "closed-form")]
#[inline(never)]
fn concentric_sum<T, SA, SB, O, const CB: usize>(
    a: &Patch<'_, T, SA>,
    cells: &[ParamRect<T>],
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
) -> Result<Option<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let surface = a.surface();
    let events = if inner.concentric.is_some() || !inner.use_occluders {
        concentric_events(surface, inner.surface, inner.r, inner.concentric.as_ref())
    } else if inner.parallelogram.is_some() && surface.on_sphere().is_some() {
        let part = Patch::new(inner.surface, inner.r)?;
        shell_flat_of(a, &part, inner.parallelogram, true, inner.occluders, inner_bounds)
    } else {
        None
    };
    let mut f = |t: T, s: T| outer_integrand(surface, t, s, inner, inner_samples, inner_bounds);
    let Some(events) = events else {
        // From a sphere with another centre: quadric sections only.
        let Some(occluder) = inner.concentric.as_ref() else { return Ok(None) };
        let Some(events) = offcentre_events(a, inner.surface, inner.r, occluder) else { return Ok(None) };
        let mut total = T::ZERO;
        for cell in cells {
            total += events.integrate(*cell, &inner.rule, &mut f)?;
        }
        return Ok(Some(total));
    };
    let mut total = T::ZERO;
    for cell in cells {
        total += events.integrate(*cell, &inner.rule, &mut f)?;
    }
    Ok(Some(total))
}

/// The outer events of a cell of a sphere (`a`) against a parallelogram across one sphere
/// occluder: inside the sphere around one with its centre (`concentric::shell_flat_events`,
/// all circles), else anywhere the parallelogram lies in front of the cell's tangent planes
/// (`sphere_flat::sphere_flat_events`, with a cone's section per corner); for the patch
/// `inner` (its surface's affine map `map`, inside the ball `bounds`); `None` where they do
/// not apply.
#[cfg(feature = "closed-form")]
fn shell_flat_of<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    inner: &Patch<'_, T, SB>,
    map: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    use_occluders: bool,
    occluders: &O,
    bounds: &Ball<T>,
) -> Option<ConcentricEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let map = map.filter(|_| use_occluders)?;
    let outer = a.surface();
    outer.on_sphere()?;
    let from = a.enclosing_ball();
    let occluder = occluders.shadow_sphere(&from, bounds)??;
    let r = inner.rect();
    let middle = |r: ParamRect<T>| ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    let (tm, sm) = middle(r);
    let n = inner.surface().normal(tm, sm);
    let length = n.norm();
    if !(length > T::ZERO) {
        return None;
    }
    let unit = n.scale(T::ONE / length);
    shell_flat_events(outer, (map, r), unit, &occluder).or_else(|| {
        let (ta, sa) = middle(a.rect());
        let cell = (a.rect(), &from, outer.point(ta, sa), outer.normal(ta, sa));
        sphere_flat::sphere_flat_events(outer, cell, (map, r), unit, &occluder)
    })
}

/// The corners of the parallelogram with affine map (o, e_t, e_s) over `r`, in order around it.
#[cfg(feature = "closed-form")]
fn map_corners<T: Real>((o, et, es): (Vec3<T>, Vec3<T>, Vec3<T>), r: ParamRect<T>) -> [Vec3<T>; 4] {
    let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
    [at(r.t0, r.s0), at(r.t1, r.s0), at(r.t1, r.s1), at(r.t0, r.s1)]
}

/// J(p) times a's area element at a's parameters (t, s).
#[cfg(feature = "closed-form")]
fn outer_integrand<T, SA, SB, O, const CB: usize>(
    surface: &SA,
    t: T,
    s: T,
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
) -> Result<T, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (p, n) = surface.point_and_normal(t, s);
    let area = n.norm();
    if !(area > T::ZERO) {
        return Ok(T::ZERO);
    }
    Ok(area * point_value(inner, inner_samples, inner_bounds, p, n.scale(T::ONE / area))?)
}

/// [`events_sum`] across flat convex occluders ([`PolygonEvents`]): its own frame, entered only
/// where a flat pair's occluders give no quadrics, so that the larger buffers stay off the path
/// of pairs across spheres.
#[cfg(feature = "closed-form")]
#[inline(never)]
fn polygon_events_sum<T, SA, SB, O, const CB: usize>(
    a: &Patch<'_, T, SA>,
    cells: &[ParamRect<T>],
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
) -> Result<Option<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let surface = a.surface();
    let (Some(outer_map), Some(inner_map), true) = (surface.affine_map(), inner.parallelogram, inner.use_occluders)
    else {
        return Ok(None);
    };
    let near = cells.len() > 1;
    let Some(events) =
        PolygonEvents::polygons((outer_map, a.rect()), (inner_map, inner.r), inner.occluders, inner_bounds, near, None)
    else {
        return Ok(None);
    };
    let mut f = |t: T, s: T| outer_integrand(surface, t, s, inner, inner_samples, inner_bounds);
    let mut total = T::ZERO;
    for cell in cells {
        total += events.integrate(*cell, &inner.rule, &mut f)?;
    }
    Ok(Some(total))
}

/// The outer events of a pair: on a flat outer patch ([`Events`]) or a curved one
/// ([`TrigonometricEvents`]).
#[cfg(feature = "closed-form")]
enum OuterEvents<T> {
    Flat(QuadricEvents<T>),
    Curved(SphereCellEvents<T>),
}

/// The outer events of a curved outer patch (`surface`) against a parallelogram inner patch
/// (affine map `affine` over `r`) that no occluder cuts (`use_occluders` false); `None`
/// elsewhere ([`TrigonometricEvents::new`]).
#[cfg(feature = "closed-form")]
fn curved_outer_events<T, SA>(
    surface: &SA,
    affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    r: ParamRect<T>,
    use_occluders: bool,
) -> Option<SphereCellEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
{
    if use_occluders {
        return None;
    }
    TrigonometricEvents::new(surface, affine?, r)
}

/// The outer events of a flat outer patch (affine map `outer_map` over `outer_rect`) against the inner patch
/// (`surface` over `r`, inside `bounds`; `affine` its map where its lines are in closed form):
/// a flat inner patch across the occluders when `use_occluders` (else across none), a curved
/// one only where no occluder cuts.
#[cfg(feature = "closed-form")]
#[allow(clippy::too_many_arguments)]
fn pair_events<T, SB, O>(
    outer_map: (Vec3<T>, Vec3<T>, Vec3<T>),
    outer_rect: ParamRect<T>,
    surface: &SB,
    r: ParamRect<T>,
    affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    use_occluders: bool,
    occluders: &O,
    bounds: &Ball<T>,
) -> Option<QuadricEvents<T>>
where
    T: Real,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    match (affine, use_occluders) {
        (Some(inner_map), true) => Events::new(outer_map, outer_rect, inner_map, r, occluders),
        (Some(inner_map), false) => Events::new(outer_map, outer_rect, inner_map, r, &()),
        (None, false) => Events::curved(outer_map, surface, r, bounds),
        (None, true) => None,
    }
}

/// Whether [`boundary_sum`] places the outer events into the rule for this pair with `outer`
/// outside ([`pair_events`]: a flat outer patch, and a flat inner one whose occluders give
/// their quadrics or a curved one that gives its own; [`PolygonEvents`]: a flat pair across
/// one convex polygon or one convex solid's facets; [`curved_outer_events`]: a sphere's
/// cell against a parallelogram that no occluder cuts): the outer patch is then not split into
/// cells for its kinks, and its convergence in the order is exponential.
#[cfg(feature = "closed-form")]
pub(crate) fn outer_events_apply<T, SA, SB, O>(
    outer: &Patch<'_, T, SA>,
    inner: &Patch<'_, T, SB>,
    occluders: &O,
) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    outer_events_state(outer, inner, occluders) == Some(true)
}

/// The outer events with `outer` outside: `None` where none are placed, `Some(exponential)`
/// where they are: `Some(false)` where an occluder touches the outer patch ([`PolygonEvents`]:
/// a cabinet's foot on a floor facet's edge), so that its integral converges only
/// algebraically ([`outer_events_apply`] is then `false`).
#[cfg(feature = "closed-form")]
pub(crate) fn outer_events_state<T, SA, SB, O>(
    outer: &Patch<'_, T, SA>,
    inner: &Patch<'_, T, SB>,
    occluders: &O,
) -> Option<bool>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (surface, r) = (inner.surface(), inner.rect());
    let affine = surface.affine_map();
    let bounds = part_ball(surface, affine, r).ok()?;
    let use_occluders = occluders.may_block_between(&outer.enclosing_ball(), &bounds);
    match outer.surface().affine_map() {
        Some(outer_map) => {
            if pair_events(outer_map, outer.rect(), surface, r, affine, use_occluders, occluders, &bounds).is_some() {
                return Some(true);
            }
            let inner_map = affine.filter(|_| use_occluders)?;
            polygon_events_state(outer_map, outer.rect(), inner_map, r, occluders, &bounds)
        }
        None => curved_outer_events(outer.surface(), affine, r, use_occluders)
            .map(|_| true)
            .or_else(|| {
                let concentric = match use_occluders {
                    true => Some(Concentric::of(surface, &bounds, &outer.enclosing_ball(), occluders)?),
                    false => None,
                };
                concentric_events(outer.surface(), surface, r, concentric.as_ref())
                    .map(|_| true)
                    .or_else(|| offcentre_events(outer, surface, r, concentric.as_ref()?).map(|_| true))
            })
            .or_else(|| shell_flat_of(outer, inner, affine, use_occluders, occluders, &bounds).map(|_| true)),
    }
}

/// Whether an occluder that may cut the flat pair touches `patch` (`polygon_events::occluders_touch`:
/// J is singular along the contact, and the rule over that patch converges slowly); `None`
/// where either patch is not flat or an occluder is neither a flat convex polygon nor a sphere.
#[cfg(feature = "closed-form")]
#[inline(never)]
pub(crate) fn occluders_touch<T, SA, SB, O>(
    patch: &Patch<'_, T, SA>,
    other: &Patch<'_, T, SB>,
    occluders: &O,
) -> Option<bool>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (map, other_map) = (patch.surface().affine_map()?, other.surface().affine_map()?);
    let bounds = part_ball(other.surface(), Some(other_map), other.rect()).ok()?;
    polygon_events::occluders_touch((map, patch.rect()), &map_corners(other_map, other.rect()), occluders, &bounds)
}

/// Whether a flat pair's events across flat convex occluders are placed ([`PolygonEvents`]):
/// `Some(true)` where they make the outer integral converge exponentially, `Some(false)` where
/// an occluder touches the outer patch (a cabinet's corner on the floor's makes J singular
/// there); in a frame of its own as [`polygon_events_sum`].
#[cfg(feature = "closed-form")]
#[inline(never)]
fn polygon_events_state<T: Real, O: Occluder<T> + ?Sized>(
    outer_map: (Vec3<T>, Vec3<T>, Vec3<T>),
    outer_rect: ParamRect<T>,
    inner_map: (Vec3<T>, Vec3<T>, Vec3<T>),
    r: ParamRect<T>,
    occluders: &O,
    bounds: &Ball<T>,
) -> Option<bool> {
    PolygonEvents::polygons((outer_map, outer_rect), (inner_map, r), occluders, bounds, false, None)
        .map(|events| !events.touches_side())
}

/// Most cells into which [`outer_cells`] cuts the outer patch (each costs one outer rule).
pub(crate) const MAX_OUTER_CELLS: usize = 32;

/// The outer patch a cut, by halving across its longer side (arc length), until no cell is
/// closer to b than its own radius, at most [`MAX_OUTER_CELLS`] cells; the cell closest to b
/// relative to its radius is halved first, so that the cells grade towards where a comes
/// closest to b. One cell (a itself) for a pair that is not [`very_near`].
fn outer_cells<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    inner_patch: &Patch<'_, T, SB>,
    inner: &Inner<'_, T, SB, O>,
) -> Result<([ParamRect<T>; MAX_OUTER_CELLS], usize), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let g = a.surface();
    // A cell's distance to b in its own radii (below 1: to be halved).
    let ratio = |r: ParamRect<T>| -> Result<T, PdmError> {
        let ball = Patch::new(g, r)?.enclosing_ball();
        if !(ball.radius > T::ZERO) {
            return Ok(T::MAX);
        }
        Ok(inner.distance_from(&ball, inner.r)? / ball.radius)
    };
    // A pair that is not very near keeps one cell: its layer is resolved by the rule over a.
    let mut cells = [a.rect(); MAX_OUTER_CELLS];
    if !very_near(a, inner_patch)? {
        return Ok((cells, 1));
    }
    let mut ratios = [ratio(a.rect())?; MAX_OUTER_CELLS];
    let mut n = 1usize;
    while n < MAX_OUTER_CELLS {
        let mut pick = None;
        let mut least = T::ONE;
        for (k, &q) in ratios.iter().enumerate().take(n) {
            if q < least {
                least = q;
                pick = Some(k);
            }
        }
        let Some(k) = pick else { break };
        let Some(&r) = cells.get(k) else { break };
        // Halved across its longer side by arc length; a half below the coordinates'
        // resolution ends the grading.
        let cell = Patch::new(g, r)?;
        let lengths = crate::patch::side_lengths(&cell);
        let (Some(lo), Some(hi)) =
            (crate::patch::half_patch(&cell, lengths, 0), crate::patch::half_patch(&cell, lengths, 1))
        else {
            break;
        };
        let (lo, hi) = (lo.rect(), hi.rect());
        let (q_lo, q_hi) = (ratio(lo)?, ratio(hi)?);
        if let (Some(c), Some(q)) = (cells.get_mut(k), ratios.get_mut(k)) {
            *c = lo;
            *q = q_lo;
        }
        if let (Some(c), Some(q)) = (cells.get_mut(n), ratios.get_mut(n)) {
            *c = hi;
            *q = q_hi;
        }
        n += 1;
    }
    Ok((cells, n))
}

/// The outer sum Σ w_p J(p) over one set of outer samples (see [`boundary_unchecked`]).
fn outer_sum<T, SB, O, const CA: usize, const CB: usize>(
    outer: &PatchSamples<T, CA>,
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
) -> Result<T, PdmError>
where
    T: Real,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = T::ZERO;
    for sample in outer.iter() {
        if sample.weight == T::ZERO {
            continue;
        }
        total += sample.weight * point_value(inner, inner_samples, inner_bounds, sample.point, sample.unit_normal)?;
    }
    Ok(total)
}

/// J(p): the inner integral over b seen from the outer point p with unit normal np, by the
/// cheapest method that is exact for p (see the module docs).
fn point_value<T, SB, O, const CB: usize>(
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CB>,
    inner_bounds: &Ball<T>,
    p: Vec3<T>,
    np: Vec3<T>,
) -> Result<T, PdmError>
where
    T: Real,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (use_occluders, occluders, count, r) = (inner.use_occluders, inner.occluders, inner.count, inner.r);
    // From most points nothing cuts b: an occluder can cut only if it meets the cone of
    // segments from p to b's bounding ball, and on a flat b the facing tests are affine,
    // so b's corners decide them. The integrand is then smooth (plain rule) or zero.
    let occluded_from_p =
        use_occluders && occluders.may_block_between(&Ball { center: p, radius: T::ZERO }, inner_bounds);
    if occluded_from_p && occluder_hides(occluders, p, inner_bounds) {
        return Ok(T::ZERO);
    }
    // A receiver closer to p than its size: its kernel peaks at p's foot, which a rule
    // over the whole of b cannot resolve; b is then refined towards p.
    // One sphere between p and a parallelogram b: b's directions minus the sphere's cone, in
    // closed form.
    #[cfg(feature = "closed-form")]
    if occluded_from_p {
        if let Some(Some(ball)) = occluders.shadow_sphere(&Ball { center: p, radius: T::ZERO }, inner_bounds) {
            if let Some(j) = inner.point_past_sphere(p, np, &ball) {
                return Ok(j);
            }
        }
        // Flat convex occluders and at most one sphere: b less their shadows, in closed form.
        if inner.polygons_only(p, inner_bounds) {
            if let Some(j) = inner.point_past_polygons(p, np, inner_bounds) {
                return Ok(j);
            }
        }
    }
    let near = inner.near(p, inner_bounds);
    Ok(match (occluded_from_p, inner.facing_from(p, np)) {
        (_, Some(false)) => T::ZERO,
        (false, Some(true)) if !near => {
            let (x, y, z, nx, ny, nz, w) = inner_samples.columns();
            let mut sum = T::ZERO;
            for k in 0..w.len() {
                if let (Some(&qx), Some(&qy), Some(&qz), Some(&ax), Some(&ay), Some(&az), Some(&wk)) =
                    (x.get(k), y.get(k), z.get(k), nx.get(k), ny.get(k), nz.get(k), w.get(k))
                {
                    sum += wk * kernel(p, np, vec3(qx, qy, qz), vec3(ax, ay, az));
                }
            }
            count.set(count.get().saturating_add(w.len() as u64));
            sum
        }
        // From a point no occluder cuts b from, on a flat b whose integrand a rule over b
        // cannot resolve (p near b, or b straddling p's tangent plane), the inner integral
        // is the point-to-polygon form in closed form.
        (false, _) if cfg!(feature = "closed-form") => match inner.point_to_polygon(p, np) {
            Some(j) => j,
            None => inner.refined(p, np, r, 0)?,
        },
        _ => inner.refined(p, np, r, 0)?,
    })
}

/// The distance from `ball` to the part r of a surface, to within the ball's radius (parts
/// refined 2 × 2 down to a quarter of it, at most [`MAX_NEAR_DEPTH`] times; parts no closer
/// than `best` pruned). A lower bound: 0 where the ball reaches the surface.
fn distance_to_part<T: Real, S: Surface<T> + ?Sized>(
    surface: &S,
    affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    ball: &Ball<T>,
    r: ParamRect<T>,
    best: T,
    depth: u32,
) -> Result<T, PdmError> {
    let part = part_ball(surface, affine, r)?;
    let centres = (part.center - ball.center).norm();
    let gap = (centres - part.radius - ball.radius).max(T::ZERO);
    if !(gap < best) {
        return Ok(best);
    }
    if part.radius * T::from_f64(4.0) <= ball.radius || depth >= MAX_NEAR_DEPTH {
        return Ok(gap.min(best));
    }
    let mut best = best;
    for k in 0..4 {
        // A part below the coordinates' resolution (f32) ends the refinement at its parent.
        match distance_to_part(surface, affine, ball, r.cell(k / 2, k % 2, 2, 2), best, depth + 1) {
            Ok(d) => best = d,
            Err(_) => return Ok(gap.min(best)),
        }
    }
    Ok(best)
}

/// Whether the gap between the patches is below [`VERY_NEAR`] of the smaller one's radius
/// (enclosing balls). Pairs of parts of the two are refined, the larger part 2 × 2 first: a
/// pair whose balls are farther apart than that gap is not very near; one whose centre points
/// (the surfaces at the parts' parameter centres) are closer is. Where the parts' balls are
/// below [`NEAR_RESOLUTION`] of the limit, past [`MAX_NEAR_DEPTH`] halvings of both, or where
/// a part falls below the coordinates' resolution, the centre points decide. Where one patch
/// is a parallelogram its distance from a point is exact ([`distance_to_parallelogram`]), and
/// only the other is refined ([`parts_near_parallelogram`]): the pairs of parts along a gap
/// close to the limit were refined to the resolution on both sides (a half sphere 1 above a
/// 2 × 2 square: 8 ms per call, whatever the order).
pub(crate) fn very_near<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let limit = T::from_f64(VERY_NEAR) * a.enclosing_ball().radius.min(b.enclosing_ball().radius);
    gap_below(a, b, limit)
}

/// Whether the gap between the patches is below `limit`, to within [`NEAR_RESOLUTION`] of it
/// (as [`very_near`] decides).
pub(crate) fn gap_below<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, limit: T) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (ball_a, ball_b) = (a.enclosing_ball(), b.enclosing_ball());
    if !(limit > T::ZERO) {
        return Ok(false);
    }
    #[cfg(feature = "closed-form")]
    {
        if let Some(map) = b.surface().affine_map() {
            return Ok(parts_near_parallelogram(a, ball_a, map, b.rect(), limit, 0));
        }
        if let Some(map) = a.surface().affine_map() {
            return Ok(parts_near_parallelogram(b, ball_b, map, a.rect(), limit, 0));
        }
    }
    parts_near(a, ball_a, b, ball_b, limit, 0)
}

/// [`very_near`] on the part a (ball `ba`) against the part r of the parallelogram `map`: a
/// part whose ball is farther from it than the limit is not very near; one whose centre point
/// is closer is. Where the part's ball is below [`NEAR_RESOLUTION`] of the limit, past
/// 2·[`MAX_NEAR_DEPTH`] halvings, or where a part falls below the coordinates' resolution, the
/// centre point decides.
#[cfg(feature = "closed-form")]
fn parts_near_parallelogram<T, S>(
    a: &Patch<'_, T, S>,
    ba: Ball<T>,
    map: (Vec3<T>, Vec3<T>, Vec3<T>),
    r: ParamRect<T>,
    limit: T,
    depth: u32,
) -> bool
where
    T: Real,
    S: Surface<T> + ?Sized,
{
    let distance = distance_to_parallelogram(ba.center, map, r);
    if !(distance - ba.radius < limit) {
        return false;
    }
    let decided = distance < limit;
    if decided || ba.radius < T::from_f64(NEAR_RESOLUTION) * limit || depth >= 2 * MAX_NEAR_DEPTH {
        return decided;
    }
    (0..4).any(|k| match Patch::new(a.surface(), a.rect().cell(k / 2, k % 2, 2, 2)) {
        Ok(part) => parts_near_parallelogram(&part, part.enclosing_ball(), map, r, limit, depth + 1),
        Err(_) => decided,
    })
}

/// [`very_near`] on the parts a and b (patches of the original two) with balls `ba`, `bb`.
fn parts_near<T, SA, SB>(
    a: &Patch<'_, T, SA>,
    ba: Ball<T>,
    b: &Patch<'_, T, SB>,
    bb: Ball<T>,
    limit: T,
    depth: u32,
) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    if !((ba.center - bb.center).norm() - ba.radius - bb.radius < limit) {
        return Ok(false);
    }
    // An enclosing ball is centred on the surface at the part's parameter centre. Parts whose
    // balls are small against the limit decide by their centre points: the gap is judged to
    // within NEAR_RESOLUTION of the limit, which bounds the refinement where the gap is close to
    // the limit (otherwise every part pair along the whole near region is refined to the depth cap).
    let decided = (ba.center - bb.center).norm() < limit;
    let resolved = ba.radius + bb.radius < T::from_f64(NEAR_RESOLUTION) * limit;
    if decided || resolved || depth >= 2 * MAX_NEAR_DEPTH {
        return Ok(decided);
    }
    for k in 0..4 {
        // A part below the coordinates' resolution (f32): the centre points decide.
        let found = if ba.radius >= bb.radius {
            let Ok(part) = Patch::new(a.surface(), a.rect().cell(k / 2, k % 2, 2, 2)) else { return Ok(decided) };
            parts_near(&part, part.enclosing_ball(), b, bb, limit, depth + 1)?
        } else {
            let Ok(part) = Patch::new(b.surface(), b.rect().cell(k / 2, k % 2, 2, 2)) else { return Ok(decided) };
            parts_near(a, ba, &part, part.enclosing_ball(), limit, depth + 1)?
        };
        if found {
            return Ok(true);
        }
    }
    Ok(false)
}

/// How far the terms of the point-to-polygon forms ([`Inner::point_to_polygon`],
/// [`Inner::point_past_sphere`], [`Inner::point_to_outline`]) may cancel (the sum of their
/// magnitudes over the magnitude of their sum): until their rounding, about 5ε of each term's
/// magnitude, reaches 2e-13 of J, and at least 16 times (f64: 180; f32: 16, 1e-5 of J). Past
/// it the caller integrates by lines, whose error falls only with the order: on the paper's
/// scene a sphere hiding most of a receiving cell makes its terms cancel 18–30 times, and
/// those cells took the lines from every outer point (1e-7 off at order 8, and 2.5× the time).
/// Past a sphere ([`Inner::point_past_sphere`]) the same limit also holds against b's
/// unshadowed J, which bounds what any method can resolve of a sliver left beside the shadow.
fn polygon_cancellation<T: Real>() -> T {
    let rounding = T::from_f64(5.0) * T::EPSILON;
    (T::from_f64(2e-13) / rounding).max(T::from_f64(16.0))
}

/// Relative resolution of [`very_near`]'s decision: a gap within this fraction of the limit
/// may count either way.
const NEAR_RESOLUTION: f64 = 0.125;

/// The gap, in the smaller patch's radius, below which a pair counts as very near
/// ([`very_near`]): its outer integrand has a layer on the gap's scale.
pub(crate) const VERY_NEAR: f64 = 0.75;

/// The smallest ball known to contain the part r of a surface: from its corners when the
/// surface is flat (`affine`, its affine map), else [`Patch::enclosing_ball`].
fn part_ball<T: Real, S: Surface<T> + ?Sized>(
    surface: &S,
    affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    r: ParamRect<T>,
) -> Result<Ball<T>, PdmError> {
    Ok(match affine {
        Some((o, et, es)) => {
            let corner = |t: T, s: T| o + et.scale(t) + es.scale(s);
            let center = corner((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
            let radius = [(r.t0, r.s0), (r.t1, r.s0), (r.t0, r.s1), (r.t1, r.s1)]
                .iter()
                .fold(T::ZERO, |acc, &(t, s)| acc.max((corner(t, s) - center).norm()));
            Ball { center, radius: radius * (T::ONE + T::GEOMETRY_TOLERANCE) }
        }
        None => Patch::new(surface, r)?.enclosing_ball(),
    })
}

/// The nearest singular points just outside an interval, before and after it.
type Outside<T> = (Option<T>, Option<T>);

/// [`Occluder::hides_ball_from`] when the `closed-form` feature is on; `false` otherwise.
#[inline]
fn occluder_hides<T: Real, O: Occluder<T> + ?Sized>(occluders: &O, p: Vec3<T>, b: &Ball<T>) -> bool {
    #[cfg(feature = "closed-form")]
    return occluders.hides_ball_from(p, b);
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = (occluders, p, b);
        false
    }
}

/// [`Occluder::line_polynomials`] when the `closed-form` feature is on; `false` otherwise.
#[inline]
fn occluder_polynomials<T: Real, O: Occluder<T> + ?Sized>(
    occluders: &O,
    p: Vec3<T>,
    origin: Vec3<T>,
    direction: Vec3<T>,
    out: &mut dyn FnMut([T; 3]),
) -> bool {
    #[cfg(feature = "closed-form")]
    return occluders.line_polynomials(p, origin, direction, out);
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = (occluders, p, origin, direction, out);
        false
    }
}

#[cfg(all(test, feature = "closed-form"))]
mod tests {
    use super::*;
    use crate::surface::{Parallelogram, Sphere};

    /// `f` on the inner integral over `plate` at order 20 across `occluders` (none if
    /// `use_occluders` is false).
    fn at_order_20<O: Occluder<f64>, R>(
        plate: &Parallelogram<f64>,
        occluders: &O,
        use_occluders: bool,
        f: impl FnOnce(&Inner<'_, f64, Parallelogram<f64>, O>, ParamRect<f64>) -> R,
    ) -> R {
        let r = Patch::whole(plate).unwrap().rect();
        let count = core::cell::Cell::new(0u64);
        let inner = Inner {
            surface: plate,
            r,
            rule: GaussRule::<f64>::new(20).unwrap(),
            probes: 43,
            affine: plate.affine_map(),
            parallelogram: plate.affine_map(),
            trigonometric: false,
            concentric: None,
            outline: None,
            line_rule: GaussRule::<f64>::new(20).unwrap(),
            back_facets: BackFacets::none(),
            use_occluders,
            occluders,
            count: &count,
            scratch: core::cell::RefCell::new(LineScratch::new()),
            signature_line: core::cell::RefCell::new(Line::new()),
        };
        f(&inner, r)
    }

    /// J(p) over `plate` past `sphere`: (the cone subtraction if it answers, the lines at order
    /// 20, the unshadowed J), or `None` where the cone subtraction does not answer.
    fn past_sphere(
        plate: &Parallelogram<f64>,
        sphere: &Sphere<f64>,
        p: Vec3<f64>,
        np: Vec3<f64>,
    ) -> Option<(f64, f64, f64)> {
        at_order_20(plate, sphere, true, |inner, r| {
            let ball = Ball { center: sphere.center(), radius: sphere.radius() };
            let closed = inner.point_past_sphere(p, np, &ball)?;
            let lines = inner.refined(p, np, r, 0).unwrap();
            let unshadowed = inner.point_to_polygon(p, np).unwrap_or(1.0).max(1e-300);
            Some((closed, lines, unshadowed))
        })
    }

    /// Uniform numbers in [−1, 1) from an xorshift generator seeded with `state`.
    fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// A random parallelogram in the plane z = 0 (normal +z) centred on the origin, sides
    /// 0.5 … 1.5 long, tilted off the axes.
    fn random_plate(next: &mut impl FnMut() -> f64) -> Parallelogram<f64> {
        let et = vec3(1.0 + 0.5 * next(), 0.3 * next(), 0.0);
        let es = vec3(0.3 * next(), 1.0 + 0.5 * next(), 0.0);
        let o = vec3(-0.5 * et.x - 0.5 * es.x, -0.5 * et.y - 0.5 * es.y, 0.0);
        Parallelogram::new(o, et, es).unwrap()
    }

    /// J(p) over `plate` past flat occluders: (b less their shadows if it answers, the lines at
    /// order 20 with the occluders' polynomials, the solid angle `plate` subtends facing p
    /// squarely), or `None`.
    fn past_polygons<O: Occluder<f64>>(
        plate: &Parallelogram<f64>,
        occluders: &O,
        p: Vec3<f64>,
        np: Vec3<f64>,
    ) -> Option<(f64, f64, f64)> {
        at_order_20(plate, occluders, true, |inner, r| {
            let bounds = Patch::whole(plate).unwrap().enclosing_ball();
            let closed = inner.point_past_polygons(p, np, &bounds)?;
            let lines = inner.refined(p, np, r, 0).unwrap();
            Some((closed, lines, inner.reach(p)))
        })
    }

    /// A slab seen edge-on (p at the height of a table top 0.04 thick, near the plane of its
    /// end) and a sphere off to one side whose cone meets none of the slab's shadows: b less
    /// the slab's shadows is cut into slivers, and each sliver less the sphere's cone must keep
    /// its orientation and its corners once. The reference is inclusion–exclusion with the
    /// methods checked on their own (the slab alone against the lines, the sphere alone
    /// against the lines, b unshadowed): J = J_slab + J_sphere − J_b. The lines with both
    /// occluders are no reference here: they move by 1e-4 of J from point to point.
    #[test]
    fn slivers_past_a_slab_and_a_sphere_match_inclusion_exclusion() {
        use crate::visibility::AnyOccluder;
        let q = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
            AnyOccluder::Parallelogram(
                Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap(),
            )
        };
        let (z0, z1) = (0.72, 0.76);
        let lamp = Sphere::outer(vec3(2.0, 3.5, 2.1), 0.15).unwrap();
        let slab = [
            q([1.0, 1.5, z0], [0.0, 0.9, 0.0], [1.4, 0.0, 0.0]),
            q([1.0, 1.5, z1], [1.4, 0.0, 0.0], [0.0, 0.9, 0.0]),
            q([1.0, 1.5, z0], [1.4, 0.0, 0.0], [0.0, 0.0, z1 - z0]),
            q([1.0, 2.4, z0], [0.0, 0.0, z1 - z0], [1.4, 0.0, 0.0]),
            q([1.0, 1.5, z0], [0.0, 0.0, z1 - z0], [0.0, 0.9, 0.0]),
            q([2.4, 1.5, z0], [0.0, 0.9, 0.0], [0.0, 0.0, z1 - z0]),
        ];
        let mut both = [AnyOccluder::Sphere(lamp); 7];
        both[..6].copy_from_slice(&slab);
        let wall = Parallelogram::new(vec3(0.0, 5.0, 2.5), vec3(0.0, 0.0, -2.5), vec3(4.0, 0.0, 0.0)).unwrap();
        let np = vec3(0.0, 1.0, 0.0);
        let mut worst = 0.0f64;
        for k in 0..24 {
            for m in 0..24 {
                let p = vec3(2.3 + 0.1 * (k as f64 + 0.5) / 24.0, 0.0, 0.70 + 0.08 * (m as f64 + 0.5) / 24.0);
                let (closed, _, reach) = past_polygons(&wall, &both.as_slice(), p, np).expect("closed form answers");
                let (slab_only, slab_lines, _) = past_polygons(&wall, &slab.as_slice(), p, np).unwrap();
                let (sphere_only, sphere_lines, unshadowed) = past_sphere(&wall, &lamp, p, np).unwrap();
                assert!((slab_only - slab_lines).abs() < 1e-11 * reach, "{p:?}: slab alone off the lines");
                assert!((sphere_only - sphere_lines).abs() < 1e-11 * reach, "{p:?}: sphere alone off the lines");
                worst = worst.max((closed - (slab_only + sphere_only - unshadowed)).abs() / reach);
            }
        }
        assert!(worst < 1e-12, "{worst:e} of the solid angle off");
    }

    /// b less the shadows of flat convex occluders ([`Inner::point_past_polygons`]) against
    /// the lines with the occluders' polynomials ([`Inner::refined`] at order 20, a different
    /// method), from random points above random parallelograms: up to three random
    /// quadrilaterals and triangles, tilted, reaching above p's height or below b's plane,
    /// overlapping one another, in some cases with a sphere between; a closed box (six faces sharing edges, shadows overlapping and
    /// meeting along their sides); b itself among the occluders. Every answer must agree with
    /// the lines to 1e-11 of the solid angle b subtends facing p squarely (measured: 4e-12;
    /// the lines' own accuracy: at order 32 they move by up to 2e-10 of J where polygon
    /// shadows' corners meet, while the closed form agrees with the point-to-polygon form to
    /// rounding where nothing is shadowed), every case must answer, and most must be shadowed.
    #[test]
    fn polygon_shadows_match_the_lines() {
        use crate::surface::Quadrilateral;
        use crate::visibility::AnyOccluder;
        let mut next = xorshift(0x2545_f491_4f6c_dd1d);
        let (mut answered, mut shadowed, mut worst) = (0usize, 0usize, 0.0f64);
        let cases = 300;
        for case in 0..cases {
            let plate = random_plate(&mut next);
            let p = vec3(0.8 * next(), 0.8 * next(), 1.0 + 0.8 * next().abs());
            let np = vec3(0.6 * next(), 0.6 * next(), -0.5 + 0.5 * next());
            let np = np.scale(1.0 / np.norm());
            let mut list: heapless::Vec<AnyOccluder<f64>, 8> = heapless::Vec::new();
            if case % 5 == 4 {
                // A box between p and b: six faces, each counter-clockwise seen from outside.
                let c = vec3(0.5 * next(), 0.5 * next(), 0.3 + 0.4 * (next() + 1.0) * 0.5 * p.z);
                let (hx, hy, hz) = (0.1 + 0.2 * next().abs(), 0.1 + 0.2 * next().abs(), 0.05 + 0.1 * next().abs());
                let v = |i: usize| {
                    vec3(
                        c.x + if i & 1 == 0 { -hx } else { hx },
                        c.y + if i & 2 == 0 { -hy } else { hy },
                        c.z + if i & 4 == 0 { -hz } else { hz },
                    )
                };
                for f in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
                    let q = Quadrilateral::new([v(f[0]), v(f[1]), v(f[2]), v(f[3])]).unwrap();
                    list.push(AnyOccluder::Quadrilateral(q)).ok();
                }
            } else {
                for k in 0..(1 + case % 3) {
                    let c = vec3(0.7 * next(), 0.7 * next(), (0.5 + 0.5 * next()) * p.z);
                    let u = vec3(0.4 * next(), 0.4 * next(), 0.3 * next());
                    let w = vec3(0.4 * next(), 0.4 * next(), 0.3 * next());
                    let corners = if k == 1 {
                        [c - u, c + u, c + w, c + w] // a triangle
                    } else {
                        [c - u - w, c + u - w, c + u + w, c - u + w]
                    };
                    if let Ok(q) = Quadrilateral::new(corners) {
                        list.push(AnyOccluder::Quadrilateral(q)).ok();
                    }
                }
                if case % 7 == 0 {
                    list.push(AnyOccluder::Parallelogram(plate)).ok();
                }
                if case % 4 == 1 {
                    let h = 0.2 + (p.z - 0.35) * 0.5 * (next() + 1.0);
                    let centre = vec3(p.x + 0.6 * next(), p.y + 0.6 * next(), h);
                    let radius = (0.05 + 0.3 * next().abs()).min(0.9 * h).min(0.9 * (centre - p).norm());
                    list.push(AnyOccluder::Sphere(Sphere::outer(centre, radius).unwrap())).ok();
                }
            }
            let Some((closed, lines, reach)) = past_polygons(&plate, &list, p, np) else { continue };
            let unshadowed = past_polygons(&plate, &(), p, np).unwrap().0;
            answered += 1;
            if lines < unshadowed * (1.0 - 1e-6) {
                shadowed += 1;
            }
            worst = worst.max((closed - lines).abs() / reach);
            assert!(
                (closed - lines).abs() <= 1e-11 * reach,
                "case {case}: p {p:?} n {np:?}: closed {closed:e}, lines {lines:e}, unshadowed {unshadowed:e}, reach {reach:e}"
            );
        }
        assert!(
            answered == cases && shadowed > cases / 2,
            "answered {answered} of {cases}, {shadowed} shadowed, worst {worst:.1e}"
        );
    }

    /// A point of a flat outer patch that rounding puts just below its plane (a cabinet's top at
    /// z = 1.8 seen against a wall beside it): the patch's own polygon, among the occluders as
    /// every surface of a scene is, passes through p to rounding and casts no shadow. Taken as
    /// an occluder 2e-16 above p it hid the whole wall (J = 7e-17 against 0.464), and a
    /// cabinet-top-to-wall pair in a room was 1e-3 off.
    #[test]
    fn a_polygon_through_p_casts_no_shadow() {
        use crate::surface::Quadrilateral;
        use crate::visibility::AnyOccluder;
        let wall = Parallelogram::new(vec3(4.0, 0.0, 0.0), vec3(0.0, 0.0, 2.5), vec3(0.0, 5.0, 0.0)).unwrap();
        let top =
            Quadrilateral::new([vec3(3.3, 2.2, 1.8), vec3(3.3, 1.0, 1.8), vec3(3.9, 1.0, 1.8), vec3(3.9, 2.2, 1.8)])
                .unwrap();
        let side =
            Quadrilateral::new([vec3(3.9, 1.0, 1.8), vec3(3.9, 1.0, 0.0), vec3(3.9, 2.2, 0.0), vec3(3.9, 2.2, 1.8)])
                .unwrap();
        let occluders = [AnyOccluder::Quadrilateral(top), AnyOccluder::Quadrilateral(side)];
        for z in [1.8, 1.7999999999999998, 1.8000000000000003] {
            let p = vec3(3.893056815579702, 1.6034715922101486, z);
            let np = vec3(0.0, 0.0, 1.0);
            let open = past_polygons(&wall, &(), p, np).unwrap().0;
            let (closed, lines, reach) = past_polygons(&wall, &occluders, p, np).unwrap();
            assert!(
                (closed - open).abs() <= 1e-14 * reach && (lines - open).abs() <= 1e-12 * reach,
                "z {z}: {closed:e} with the occluders, {open:e} without, lines {lines:e}"
            );
        }
    }

    /// A sphere whose cone of directions from p covers all of a square but thin slivers at its
    /// four corners (the cone's half-angle short of the corners' by 1e-2 … 1e-7 of itself): the
    /// visible J is 1e-3 … 1e-13 of the unshadowed one, and the terms of the cone subtraction
    /// cancel by up to 1e12. It must still answer (the lines cost many times more) and agree
    /// with the lines to 1e-15 of the unshadowed J (measured: at most 1.3e-16; relative to the
    /// sliver's own J, from 1e-13 at a visible 2e-4 to 5e-3 at 2e-14: its width is a
    /// difference of nearly equal angles, and both methods round it).
    #[test]
    fn a_sphere_hiding_all_but_slivers_of_b_is_in_closed_form() {
        let plate = Parallelogram::new(vec3(-0.5, -0.5, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let p = vec3(0.0, 0.0, 2.0);
        let np = vec3(0.0, 0.0, -1.0);
        let corner = (0.5f64.sqrt() / 2.0).atan();
        for shortfall in [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
            let radius = (corner * (1.0 - shortfall)).sin();
            let sphere = Sphere::outer(vec3(0.0, 0.0, 1.0), radius).unwrap();
            let (closed, lines, unshadowed) = past_sphere(&plate, &sphere, p, np).expect("answers");
            let gap = (closed - lines).abs();
            assert!(
                gap <= 1e-15 * unshadowed,
                "shortfall {shortfall:e}: closed {closed:e}, lines {lines:e}, unshadowed {unshadowed:e}"
            );
        }
    }

    /// p's tangent plane leaves only a strip of a square in front of p (its width 1e-2 … 1e-6
    /// of the square's): J is 1e-4 … 1e-12 of the terms of the point-to-polygon form, which
    /// must still answer (the lines cost many times more) and agree with the lines at order
    /// 20 to 1e-15 of the solid angle the square subtends from p (measured: 1.2e-16 at the
    /// narrowest strip, whose J is 2e-13 of that angle; the old limit sent every strip here to
    /// the lines).
    #[test]
    fn a_strip_of_b_above_the_horizon_is_in_closed_form() {
        let plate = Parallelogram::new(vec3(-0.5, -0.5, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let p = vec3(0.1, -0.2, 1.5);
        for width in [1e-2, 1e-3, 1e-4, 1e-5, 1e-6] {
            // The plane through p and the line y = 0.5 − width on b, facing +y.
            let (a, b) = (vec3(0.0, 0.5 - width, 0.0), vec3(1.0, 0.5 - width, 0.0));
            let np = (b - a).cross(p - a);
            let np = np.scale(if np.y > 0.0 { 1.0 } else { -1.0 } / np.norm());
            let (closed, lines, reach) = in_front(&plate, p, np).expect("answers");
            assert!(
                (closed - lines).abs() <= 1e-15 * reach && closed > 0.0,
                "width {width:e}: closed {closed:e}, lines {lines:e}, reach {reach:e}"
            );
        }
    }

    /// J(p) over `plate` with nothing between: (the point-to-polygon form if it answers, the
    /// lines at order 20, the solid angle `plate` subtends facing p squarely), or `None`.
    fn in_front(plate: &Parallelogram<f64>, p: Vec3<f64>, np: Vec3<f64>) -> Option<(f64, f64, f64)> {
        at_order_20(plate, &(), false, |inner, r| {
            let closed = inner.point_to_polygon(p, np)?;
            let lines = inner.refined(p, np, r, 0).unwrap();
            Some((closed, lines, inner.reach(p)))
        })
    }

    /// J(p) past one sphere by the cone subtraction ([`Inner::point_past_sphere`]) against the
    /// lines with the sphere's polynomials ([`Inner::refined`], order 20: exponential in the
    /// order, a different method), from random points in front of random parallelograms with a
    /// random sphere between: shadows across corners, across edges, inside b, covering b, and
    /// below p's horizon. Every case where the closed form answers must agree to 1e-11 of the
    /// unshadowed J; most cases must answer.
    #[test]
    fn cone_subtraction_matches_the_lines() {
        let mut next = xorshift(0x5851_f42d_4c95_7f2d);
        let (mut answered, mut shadowed, mut worst) = (0usize, 0usize, 0.0f64);
        let cases = 400;
        for _ in 0..cases {
            // b in the plane z = 0 (normal +z), p above it, the sphere between.
            let plate = random_plate(&mut next);
            let p = vec3(0.8 * next(), 0.8 * next(), 1.0 + 0.8 * next().abs());
            let np = vec3(0.6 * next(), 0.6 * next(), 0.5 + 0.5 * next());
            let np = np.scale(1.0 / np.norm());
            let h = 0.2 + (p.z - 0.35) * 0.5 * (next() + 1.0);
            let centre = vec3(p.x + 0.6 * next(), p.y + 0.6 * next(), h);
            let radius = (0.05 + 0.3 * next().abs()).min(0.9 * h).min(0.9 * (centre - p).norm());
            let sphere = Sphere::outer(centre, radius).unwrap();
            let Some((closed, lines, unshadowed)) = past_sphere(&plate, &sphere, p, np) else { continue };
            answered += 1;
            if lines < unshadowed * (1.0 - 1e-6) {
                shadowed += 1;
            }
            worst = worst.max((closed - lines).abs() / unshadowed);
            assert!(
                (closed - lines).abs() <= 1e-11 * unshadowed,
                "p {p:?} n {np:?} sphere {centre:?} {radius}: closed {closed:e}, lines {lines:e}"
            );
        }
        assert!(
            answered > cases / 2 && shadowed > cases / 4,
            "answered {answered} of {cases}, {shadowed} shadowed, worst {worst:.1e}"
        );
    }

    /// `very_near` against a parallelogram refines only the other patch, with the exact
    /// distance to the parallelogram; it decides as the refinement of both patches
    /// (`parts_near`) and as the true gap does, wherever that gap is not within the decision's
    /// resolution of the limit. Sphere cells (the lower hemisphere in halves, its pole cap, a
    /// cell off the pole) above a 2 × 2 square, gaps from 1e-3 to 4 radii, both argument
    /// orders.
    #[test]
    fn very_near_against_a_parallelogram_decides_as_the_gap() {
        let square = Parallelogram::new(vec3(-1.0, -1.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0)).unwrap();
        let plate = Patch::whole(&square).unwrap();
        let pi = core::f64::consts::PI;
        let mut decided = [0usize; 2];
        for gap in [1e-3, 0.05, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.5, 2.0, 4.0] {
            let sphere = Sphere::outer(vec3(0.1, -0.2, 1.0 + gap), 1.0).unwrap();
            for rect in [
                ParamRect::new(pi / 2.0, pi, 0.0, pi).unwrap(),
                ParamRect::new(pi / 2.0, pi, pi, 2.0 * pi).unwrap(),
                ParamRect::new(7.0 * pi / 8.0, pi, 0.0, 2.0 * pi).unwrap(),
                ParamRect::new(pi / 2.0, 3.0 * pi / 4.0, 0.5, 1.5).unwrap(),
            ] {
                let cell = Patch::new(&sphere, rect).unwrap();
                let (ball_cell, ball_plate) = (cell.enclosing_ball(), plate.enclosing_ball());
                let limit = VERY_NEAR * ball_cell.radius.min(ball_plate.radius);
                let both = parts_near(&cell, ball_cell, &plate, ball_plate, limit, 0).unwrap();
                let one = very_near(&cell, &plate).unwrap();
                assert_eq!(one, very_near(&plate, &cell).unwrap());
                // The cell's lowest points: on its parallel nearest the south pole (φ = π), some
                // of them straight above the square.
                let lowest = 1.0 + rect.t1.cos() + gap;
                if (lowest - limit).abs() > 2.0 * NEAR_RESOLUTION * limit {
                    assert_eq!(one, lowest < limit, "gap {gap}, cell {rect:?}: limit {limit}, lowest {lowest}");
                    assert_eq!(one, both, "gap {gap}, cell {rect:?}");
                    decided[usize::from(one)] += 1;
                }
            }
        }
        assert!(decided[0] >= 8 && decided[1] >= 8, "{decided:?}");
    }
}
