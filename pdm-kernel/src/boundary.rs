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
//!   polynomials ([`Occluder::line_polynomials`]: sphere, parallelogram, disk, and their
//!   combinations): the roots of the two facing tests (linear in t) and of the occluders'
//!   quadratics, each piece between roots classified by the exact test at its midpoint;
//!   otherwise bracketed on 2·order + 3 probes and bisected to machine precision. Each visible
//!   piece gets its own Gauss rule.
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
//! through a corner; the outer rule samples across them (algebraic convergence), which patch
//! grids (and the outer split in [`crate::pair`]) reduce. The outer rule does not place those
//! curves: bracketing the count of inner singular points along outer t-lines converges along
//! each line, but the outer s-level then meets curves parallel to the t-lines, at 10× the time.
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
//! Where some occluder may cut, the s-level probe sweep (below) runs only on intervals where at
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

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::integrand::{self, kernel, mutually_facing};
use crate::patch::Patch;
use crate::real::Real;
use crate::samples::{Ball, PatchSamples};
use crate::surface::{ParamRect, Surface};
use crate::vec3::{vec3, Vec3};
use crate::visibility::Occluder;

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
    let count = core::cell::Cell::new(0u64);
    let mut outer = PatchSamples::<T, CAP>::new(a, order)?;
    let area_a = outer.area();
    let inner_samples = PatchSamples::<T, CAP>::new(b, order)?; // validates b (area, finiteness)
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
    let inner = Inner {
        surface,
        r,
        rule: GaussRule::<T>::new(order)?,
        probes: 2 * order + 3,
        affine: if closed_form { affine } else { None },
        #[cfg(feature = "closed-form")]
        outline: if affine.is_none() { crate::contour::Outline::new(b) } else { None },
        #[cfg(feature = "closed-form")]
        line_rule: GaussRule::<T>::new(order.max(16))?,
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
    let mut total = T::ZERO;
    if n_cells > 1 {
        for cell in cells.iter().take(n_cells) {
            outer.fill(&Patch::new(a.surface(), *cell)?, order, order)?;
            total += outer_sum(&outer, &inner, &inner_samples, &inner_bounds)?;
        }
    } else {
        total = outer_sum(&outer, &inner, &inner_samples, &inner_bounds)?;
    }
    let value = crate::bounds::finite(total * T::FRAC_1_PI)?;
    Ok((value, count.get(), area_a, inner_samples.area()))
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
        let lengths = crate::adaptive::side_lengths(&cell);
        let (Some(lo), Some(hi)) =
            (crate::adaptive::half_patch(&cell, lengths, 0), crate::adaptive::half_patch(&cell, lengths, 1))
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
fn outer_sum<T, SB, O, const CAP: usize>(
    outer: &PatchSamples<T, CAP>,
    inner: &Inner<'_, T, SB, O>,
    inner_samples: &PatchSamples<T, CAP>,
    inner_bounds: &Ball<T>,
) -> Result<T, PdmError>
where
    T: Real,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (use_occluders, occluders, count, r) = (inner.use_occluders, inner.occluders, inner.count, inner.r);
    let inner_bounds = *inner_bounds;
    let mut total = T::ZERO;
    for sample in outer.iter() {
        if sample.weight == T::ZERO {
            continue;
        }
        let (p, np) = (sample.point, sample.unit_normal);
        // From most points nothing cuts b: an occluder can cut only if it meets the cone of
        // segments from p to b's bounding ball, and on a flat b the facing tests are affine,
        // so b's corners decide them. The integrand is then smooth (plain rule) or zero.
        let occluded_from_p =
            use_occluders && occluders.may_block_between(&Ball { center: p, radius: T::ZERO }, &inner_bounds);
        if occluded_from_p && occluder_hides(occluders, p, &inner_bounds) {
            continue;
        }
        // A receiver closer to p than its size: its kernel peaks at p's foot, which a rule
        // over the whole of b cannot resolve; b is then refined towards p.
        let near = inner.near(p, &inner_bounds);
        let j = match (occluded_from_p, inner.facing_from(p, np)) {
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
        };
        total += sample.weight * j;
    }
    Ok(total)
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
/// a part falls below the coordinates' resolution, the centre points decide.
pub(crate) fn very_near<T, SA, SB>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>) -> Result<bool, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (ball_a, ball_b) = (a.enclosing_ball(), b.enclosing_ball());
    let limit = T::from_f64(VERY_NEAR) * ball_a.radius.min(ball_b.radius);
    if !(limit > T::ZERO) {
        return Ok(false);
    }
    parts_near(a, ball_a, b, ball_b, limit, 0)
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

/// How far the terms of [`Inner::point_to_polygon`] may cancel (the sum of their magnitudes over
/// the magnitude of their sum): 16 bounds its rounding to about 16·5ε of J.
const POLYGON_CANCELLATION: f64 = 16.0;

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

/// Most polynomials describing visibility along one line (two facing tests + the occluders').
const MAX_POLYS: usize = 40;

/// The polynomials a τ² + b τ + c of one line.
struct Polys<T> {
    list: [[T; 3]; MAX_POLYS],
    n: usize,
    overflow: bool,
}

impl<T: Real> Polys<T> {
    fn new() -> Self {
        Self { list: [[T::ZERO; 3]; MAX_POLYS], n: 0, overflow: false }
    }
    fn push(&mut self, c: [T; 3]) {
        match self.list.get_mut(self.n) {
            Some(slot) => {
                *slot = c;
                self.n += 1;
            }
            None => self.overflow = true,
        }
    }
    fn used(&self) -> &[[T; 3]] {
        self.list.get(..self.n).unwrap_or_default()
    }
}

/// The inner patch b with everything needed to integrate over its visible part from one point.
struct Inner<'x, T: Real, SB: Surface<T> + ?Sized, O: ?Sized> {
    surface: &'x SB,
    r: ParamRect<T>,
    rule: GaussRule<T>,
    probes: usize,
    /// b's affine map when visibility is handled in closed form.
    affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    /// b's outline when b is flat but not a parallelogram (a disk or annulus sector, a planar
    /// Bézier patch): the point-to-region form along it.
    #[cfg(feature = "closed-form")]
    outline: Option<crate::contour::Outline<'x, T, SB>>,
    /// The rule along the outline's edges: at least order 16, whose few hundred evaluations per
    /// outer point make J(p) exact to rounding at any outer order.
    #[cfg(feature = "closed-form")]
    line_rule: GaussRule<T>,
    use_occluders: bool,
    occluders: &'x O,
    count: &'x core::cell::Cell<u64>,
    /// Buffers of [`Inner::line`] in closed form.
    scratch: core::cell::RefCell<LineScratch<T>>,
    /// The line [`Inner::line_signature`] computes into.
    signature_line: core::cell::RefCell<Line<T>>,
}

impl<T: Real, SB: Surface<T> + ?Sized, O: Occluder<T> + ?Sized> Inner<'_, T, SB, O> {
    fn tick(&self) {
        self.count.set(self.count.get().saturating_add(1));
    }

    /// On a flat b (closed-form mode), the facing tests from p over all of b, decided at b's
    /// corners (both are affine on b): `Some(true)` if every q of b and p face each other,
    /// `Some(false)` if none do, `None` if b straddles a facing boundary or is not flat.
    fn facing_from(&self, p: Vec3<T>, np: Vec3<T>) -> Option<bool> {
        let (o, et, es) = self.affine?;
        let r = self.r;
        let nq = self.surface.normal(r.t0, r.s0);
        let corners = [(r.t0, r.s0), (r.t1, r.s0), (r.t0, r.s1), (r.t1, r.s1)];
        let (mut sees, mut ahead_of_p, mut ahead_of_q) = (0usize, 0usize, 0usize);
        for (t, s) in corners {
            let (ca, cb, _) = integrand::cosines(p, np, o + et.scale(t) + es.scale(s), nq);
            let (towards_q, towards_p) = (ca > T::ZERO, cb > T::ZERO);
            sees += usize::from(towards_q && towards_p);
            ahead_of_p += usize::from(towards_q);
            ahead_of_q += usize::from(towards_p);
        }
        if sees == corners.len() {
            Some(true)
        } else if ahead_of_p == 0 || ahead_of_q == 0 {
            Some(false)
        } else {
            None
        }
    }

    /// Both facing tests and the occluders for the segment p → q.
    fn visible(&self, p: Vec3<T>, np: Vec3<T>, q: Vec3<T>, nq: Vec3<T>) -> bool {
        self.tick();
        mutually_facing(p, np, q, nq) && !(self.use_occluders && self.occluders.blocks(p, q))
    }

    /// The polynomials in t whose roots contain every visibility change on the t-line at s
    /// (closed-form mode): the two facing tests (linear) and the occluders'. `false` if the
    /// capacity is exceeded or an occluder declines.
    fn line_polys(&self, p: Vec3<T>, np: Vec3<T>, s: T, polys: &mut Polys<T>) -> bool {
        let Some((o, et, es)) = self.affine else { return false };
        let origin = o + es.scale(s);
        let w0 = origin - p;
        let nq = self.surface.normal(self.r.t0, s);
        polys.n = 0;
        polys.push([T::ZERO, np.dot(et), np.dot(w0)]);
        polys.push([T::ZERO, nq.dot(et), nq.dot(w0)]);
        if self.use_occluders && !occluder_polynomials(self.occluders, p, origin, et, &mut |c| polys.push(c)) {
            return false;
        }
        !polys.overflow
    }

    /// The visible pieces of the t-line of b at s over r's t-range, seen from p.
    fn line(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, s: T, line: &mut Line<T>) -> Result<(), PdmError> {
        let vis_at = |t: T| {
            let (q, nq) = self.surface.point_and_normal(t, s);
            self.visible(p, np, q, nq)
        };
        if self.affine.is_some() {
            // Reused buffers (zeroing them on every line cost ≈ 6 % of the run time); a fresh
            // set if they are in use (never: lines are not computed re-entrantly).
            let mut fresh = None;
            let mut borrowed = self.scratch.try_borrow_mut();
            let scratch: &mut LineScratch<T> = match borrowed.as_deref_mut() {
                Ok(scratch) => scratch,
                Err(_) => fresh.insert(LineScratch::new()),
            };
            let LineScratch { polys, candidates } = scratch;
            if self.line_polys(p, np, s, polys) && closed_form_line(polys.used(), r.t0, r.t1, &vis_at, candidates, line)
            {
                return Ok(());
            }
        }
        // Bracket visibility changes along the line, refine each by bisection.
        line.n = 0;
        line.ids = 0;
        push(&mut line.breaks, &mut line.n, r.t0)?;
        locate_changes(&vis_at, r.t0, r.t1, self.probes, &mut line.breaks, &mut line.n)?;
        push(&mut line.breaks, &mut line.n, r.t1)?;
        let first_hi = line.breaks.get(1).copied().unwrap_or(r.t1);
        line.first_visible = vis_at((r.t0 + first_hi) * T::HALF);
        Ok(())
    }

    /// The structure of a line: (number of breakpoints, visibility of the first piece, which
    /// polynomials make the breaks); an error counts as its own structure (it is reported
    /// again when the line is integrated).
    fn line_signature(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, s: T) -> (usize, bool, u64) {
        let mut fresh = None;
        let mut borrowed = self.signature_line.try_borrow_mut();
        let line: &mut Line<T> = match borrowed.as_deref_mut() {
            Ok(line) => line,
            Err(_) => fresh.insert(Line::new()),
        };
        match self.line(p, np, r, s, line) {
            Ok(()) => (line.n, line.first_visible, line.ids),
            Err(_) => (usize::MAX, false, 0),
        }
    }

    /// The singular points in s of the inner integral (closed-form mode): the lines' structure
    /// changes where a root of a polynomial crosses a t-edge (a quadratic in s) or two roots of
    /// one polynomial meet (its discriminant, a quartic in s); these candidates are found
    /// exactly and kept where the structure differs on the two sides. Other changes (two
    /// polynomials' roots crossing: a polygonal shadow's corner, two shadows meeting) are
    /// bracketed and bisected between them. Returns the nearest singular points just outside
    /// [s0, s1] (within a quarter of its width), towards which the end pieces are graded;
    /// `None` (with nothing pushed) if the lines' polynomials are not available from p.
    fn closed_form_events(
        &self,
        p: Vec3<T>,
        np: Vec3<T>,
        r: ParamRect<T>,
        out: &mut [T; MAX_BREAKS + 2],
        n: &mut usize,
    ) -> Result<Option<Outside<T>>, PdmError> {
        let h = r.s1 - r.s0;
        // The coefficients as quadratics in x ∈ [0, 1] (s = s0 + x·h), from three lines.
        let (mut p0, mut ph, mut p1) = (Polys::new(), Polys::new(), Polys::new());
        let ok = self.line_polys(p, np, r.s0, &mut p0)
            && self.line_polys(p, np, r.s0 + h * T::HALF, &mut ph)
            && self.line_polys(p, np, r.s1, &mut p1)
            && p0.n == ph.n
            && ph.n == p1.n;
        if !ok {
            return Ok(None);
        }
        // Candidates with the polynomial they come from; an overflow makes every sub-interval
        // count as possibly crossed (see below).
        let mut candidates = [(T::ZERO, 0usize); 4 * MAX_BREAKS];
        let mut nc = 0usize;
        let mut overflow = false;
        // Candidates just outside b count too: a singular point close beyond an edge slows the
        // rule on the piece at that edge (it is graded towards it).
        let reach = T::HALF * T::HALF;
        let fit = |v0: T, vh: T, v1: T| -> [T; 3] {
            let four = T::TWO * T::TWO;
            [v0, four * vh - T::from_f64(3.0) * v0 - v1, T::TWO * (v1 + v0) - four * vh]
        };
        // Each polynomial's coefficients (a, b, c) as quadratics in x.
        let mut fits = [[[T::ZERO; 3]; 3]; MAX_POLYS];
        let polys = p0.used().iter().zip(ph.used()).zip(p1.used());
        for (id, (((&[a0, b0, k0], &[ah, bh, kh]), &[a1, b1, k1]), slot)) in polys.zip(fits.iter_mut()).enumerate() {
            let (qa, qb, qc) = (fit(a0, ah, a1), fit(b0, bh, b1), fit(k0, kh, k1));
            *slot = [qa, qb, qc];
            let mut add = |x: T| {
                if x > -reach && x < T::ONE + reach {
                    match candidates.get_mut(nc) {
                        Some(c) => {
                            *c = (r.s0 + h * x, id);
                            nc += 1;
                        }
                        None => overflow = true,
                    }
                }
            };
            // A root crossing the t-edges: P(t_edge; x) = a(x) t² + b(x) t + c(x), coefficient by
            // coefficient in x.
            for t in [r.t0, r.t1] {
                let e = |k: usize| {
                    let g = |q: &[T; 3]| q.get(k).copied().unwrap_or(T::ZERO);
                    g(&qa) * t * t + g(&qb) * t + g(&qc)
                };
                crate::visibility::polynomial_roots(e(2), e(1), e(0), &mut add);
            }
            // Two roots meeting: D(x) = b(x)² − 4 a(x) c(x), a quartic (roots in (−¼, 1¼)).
            if qa.iter().any(|&c| c != T::ZERO) {
                let bb = square(&qb);
                let ac = product(&qa, &qc);
                let four = T::TWO * T::TWO;
                let d = [
                    bb[0] - four * ac[0],
                    bb[1] - four * ac[1],
                    bb[2] - four * ac[2],
                    bb[3] - four * ac[3],
                    bb[4] - four * ac[4],
                ];
                roots_in_interval(&d, -reach, T::ONE + reach, &mut add);
            }
        }
        let fits = fits.get(..p0.n).unwrap_or_default();
        let candidates = candidates.get_mut(..nc).unwrap_or_default();
        sort_by_position(candidates);
        let candidates = &*candidates;
        // How many polynomials have a root inside (t0, t1) somewhere in [from, hi]: those with
        // one at `from`, and those with a candidate inside (a root enters the line's range only
        // across a t-edge or as a double root, both candidates).
        let with_roots_inside = |from: T, hi: T| -> usize {
            let x = (from - r.s0) / h;
            let mut count = 0;
            for (id, [qa, qb, qc]) in fits.iter().enumerate() {
                let mut inside = candidates.iter().any(|&(c, i)| i == id && c > from && c < hi);
                if !inside {
                    let at = |q: &[T; 3]| horner(q, x);
                    crate::visibility::polynomial_roots(at(qa), at(qb), at(qc), &mut |t| {
                        inside |= t > r.t0 && t < r.t1;
                    });
                }
                count += usize::from(inside);
            }
            count
        };
        // Keep the candidates where the line structure actually changes.
        let delta = h * T::EPSILON.sqrt();
        let mut kept_at = [T::ZERO; MAX_BREAKS + 2];
        let mut kept = 0usize;
        let mut last = r.s0 - h;
        let mut outside: Outside<T> = (None, None);
        for &(c, _) in candidates {
            if c - last <= delta {
                continue;
            }
            if self.line_signature(p, np, r, c - delta) != self.line_signature(p, np, r, c + delta) {
                last = c;
                if c <= r.s0 + delta {
                    outside.0 = Some(c.min(r.s0 - delta));
                } else if c >= r.s1 - delta {
                    if outside.1.is_none() {
                        outside.1 = Some(c.max(r.s1 + delta));
                    }
                } else {
                    push(out, n, c)?;
                    push(&mut kept_at, &mut kept, c)?;
                }
            }
        }
        // Anything else between them (two polynomials' roots crossing): bracket and bisect,
        // where at least two polynomials have roots on the lines.
        let mut lo = r.s0;
        for k in 0..=kept {
            let next = if k < kept { kept_at.get(k).copied() } else { None };
            let hi = next.map_or(r.s1, |c| c - delta);
            let from = if k == 0 { lo } else { lo + delta };
            if hi > from && (overflow || with_roots_inside(from, hi) >= 2) {
                let span = (hi - from) / h;
                // Probes in proportion to the sub-interval's share of [s0, s1] (at least 3).
                let mut probes = 3;
                while probes < self.probes && T::from_usize(probes) < T::from_usize(self.probes) * span {
                    probes += 1;
                }
                locate_changes(&|s: T| self.line_signature(p, np, r, s), from, hi, probes, out, n)?;
            }
            lo = next.unwrap_or(r.s1);
        }
        Ok(Some(outside))
    }

    /// J(p) over the whole of a flat b (closed-form mode) with nothing between p and b, by the
    /// point-to-polygon (Lambert) form: the visible part of b is the polygon P = b ∩ {q : n̂_p·(q − p) > 0}
    /// (the other facing test is constant on a flat b), and with its vertices v_k seen from p,
    /// R_k = v_k − p,
    ///
    /// J(p) = ∫_P cos θ_p cos θ_q / L² dA = ½ |Σ_k γ_k n̂_p·(R_k × R_{k+1})/|R_k × R_{k+1}||,
    ///
    /// γ_k the angle between R_k and R_{k+1} (Hottel & Sarofim 1967; `../shared/REFERENCES.md`).
    /// Exact however close p comes to b, where a product rule over b needs refining towards p.
    /// The terms are O(γ) while J can be O(γ²) (a small polygon far from p): `None` where they
    /// cancel by more than [`POLYGON_CANCELLATION`], and the caller integrates by the rule.
    fn point_to_polygon(&self, p: Vec3<T>, np: Vec3<T>) -> Option<T> {
        let Some((o, et, es)) = self.affine else {
            return self.point_to_outline(p, np);
        };
        let r = self.r;
        let nq = self.surface.normal(r.t0, r.s0);
        let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
        let quad = [at(r.t0, r.s0), at(r.t1, r.s0), at(r.t1, r.s1), at(r.t0, r.s1)];
        if !(nq.dot(p - quad[0]) > T::ZERO) {
            return Some(T::ZERO);
        }
        // Clip by p's tangent plane (Sutherland–Hodgman against one plane): at most 5 vertices.
        let mut poly = [Vec3::ZERO; 5];
        let mut n = 0usize;
        let mut keep = |v: Vec3<T>| {
            if let Some(slot) = poly.get_mut(n) {
                *slot = v;
                n += 1;
            }
        };
        for k in 0..4 {
            let (Some(&a), Some(&b)) = (quad.get(k), quad.get((k + 1) % 4)) else { continue };
            let (da, db) = (np.dot(a - p), np.dot(b - p));
            if da > T::ZERO {
                keep(a);
            }
            if (da > T::ZERO) != (db > T::ZERO) {
                keep(a + (b - a).scale(da / (da - db)));
            }
        }
        self.tick();
        if n < 3 {
            return Some(T::ZERO);
        }
        let (mut sum, mut magnitude) = (T::ZERO, T::ZERO);
        let used = poly.get(..n).unwrap_or_default();
        for (k, &v) in used.iter().enumerate() {
            let Some(&w) = used.get((k + 1) % n) else { continue };
            let (a, b) = (v - p, w - p);
            let c = a.cross(b);
            let sine = c.norm();
            if !(sine > T::ZERO) {
                continue;
            }
            let term = sine.atan2(a.dot(b)) * np.dot(c) / sine;
            sum += term;
            magnitude += term.abs();
        }
        let j = sum.abs() * T::HALF;
        (j.is_finite() && magnitude <= T::from_f64(POLYGON_CANCELLATION) * sum.abs()).then_some(j)
    }

    /// [`Self::point_to_polygon`] on a flat b with curved edges, along its outline
    /// (`contour::Outline::point_form`); `None` where b has no outline.
    #[cfg(feature = "closed-form")]
    fn point_to_outline(&self, p: Vec3<T>, np: Vec3<T>) -> Option<T> {
        let (j, magnitude, n) = self.outline.as_ref()?.point_form(&self.line_rule, p, np)?;
        self.count.set(self.count.get().saturating_add(n));
        (magnitude <= T::from_f64(POLYGON_CANCELLATION) * j).then_some(j)
    }

    /// Without closed forms there is no outline form.
    #[cfg(not(feature = "closed-form"))]
    fn point_to_outline(&self, _p: Vec3<T>, _np: Vec3<T>) -> Option<T> {
        None
    }

    /// `true` if p lies closer to the ball than its radius: a rule over the ball's patch then
    /// converges slowly (the kernel's nearest singularity, at p, is within the patch's size).
    fn near(&self, p: Vec3<T>, ball: &Ball<T>) -> bool {
        (ball.center - p).norm() - ball.radius < ball.radius
    }

    /// The distance from `ball` to the part r of b ([`distance_to_part`]).
    fn distance_from(&self, ball: &Ball<T>, r: ParamRect<T>) -> Result<T, PdmError> {
        distance_to_part(self.surface, self.affine, ball, r, T::MAX, 0)
    }

    /// The smallest ball known to contain the part r of b (exact corners when flat).
    fn ball_of(&self, r: ParamRect<T>) -> Result<Ball<T>, PdmError> {
        part_ball(self.surface, self.affine, r)
    }

    /// J(p) = ∫_b visible (n̂_p·e)(−n_q·e)/L⁴ dq (without the 1/π) over the part r of b,
    /// refined towards p: a part that p is [`near`](Self::near) is split 2 × 2 (up to
    /// [`MAX_NEAR_DEPTH`] times), so that every part is integrated from at least its own radius
    /// away and the rule's error falls like 2^(−2·order) or faster whatever the gap.
    fn refined(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, depth: u32) -> Result<T, PdmError> {
        if depth < MAX_NEAR_DEPTH && self.near(p, &self.ball_of(r)?) {
            let mut sum = T::ZERO;
            for k in 0..4 {
                sum += self.refined(p, np, r.cell(k / 2, k % 2, 2, 2), depth + 1)?;
            }
            return Ok(sum);
        }
        self.integral_split(p, np, r, 0)
    }

    /// J(p) over the part r of b; where one part holds more visibility changes than the
    /// fixed buffers ([`MAX_BREAKS`] per line or in s), it is halved (alternately in s and t,
    /// at most [`MAX_SPLITS`] times) and the halves are integrated separately.
    fn integral_split(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, depth: u32) -> Result<T, PdmError> {
        match self.integral_over(p, np, r) {
            Err(PdmError::CapacityExceeded { .. }) if depth < MAX_SPLITS => {
                let (lo, hi) = if depth.is_multiple_of(2) {
                    let m = (r.s0 + r.s1) * T::HALF;
                    (ParamRect { s1: m, ..r }, ParamRect { s0: m, ..r })
                } else {
                    let m = (r.t0 + r.t1) * T::HALF;
                    (ParamRect { t1: m, ..r }, ParamRect { t0: m, ..r })
                };
                Ok(self.integral_split(p, np, lo, depth + 1)? + self.integral_split(p, np, hi, depth + 1)?)
            }
            Err(PdmError::CapacityExceeded { .. }) => Ok(self.integral_sampled(p, np, r)),
            other => other,
        }
    }

    /// J(p) over a part r of b that still holds more visibility changes than the buffers after
    /// [`MAX_SPLITS`] halvings (at most a ⅛ × ⅛ part of b: changes that halving does not
    /// separate, such as rounding noise where a boundary grazes b along a line): the tensor
    /// Gauss rule with the visibility tested at each node, as the plain sum does. Its error
    /// stays within that part.
    fn integral_sampled(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>) -> T {
        let (ht, hs) = ((r.t1 - r.t0) * T::HALF, (r.s1 - r.s0) * T::HALF);
        let mut sum = T::ZERO;
        for (xs, ws) in self.rule.points() {
            let s = r.s0 + hs * (xs + T::ONE);
            for (xt, wt) in self.rule.points() {
                let (q, nq) = self.surface.point_and_normal(r.t0 + ht * (xt + T::ONE), s);
                if self.visible(p, np, q, nq) {
                    sum += ws * wt * kernel(p, np, q, nq);
                }
            }
        }
        sum * ht * hs
    }

    /// J(p) over the part r of b (r's t- and s-ranges inside b's).
    fn integral_over(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>) -> Result<T, PdmError> {
        // J is smooth in s except where the visible set of the t-line changes its structure:
        // a boundary crossing a t-edge, or a boundary tangent to the t-lines (two breakpoints
        // meeting). Split the s-range there.
        let mut s_breaks = [T::ZERO; MAX_BREAKS + 2];
        let mut ns = 0usize;
        push(&mut s_breaks, &mut ns, r.s0)?;
        let mut outside = (None, None);
        let in_closed_form = match self.affine {
            Some(_) => self.closed_form_events(p, np, r, &mut s_breaks, &mut ns)?,
            None => None,
        };
        if let Some(o) = in_closed_form {
            outside = o;
        } else {
            // The edges are probed just inside b: an edge may be a pole or a disk's centre,
            // where the normal vanishes and no facing test is defined.
            let inset = (r.t1 - r.t0) * end_inset::<T>();
            for t_edge in [r.t0 + inset, r.t1 - inset] {
                let vis_edge = |s: T| {
                    let (q, nq) = self.surface.point_and_normal(t_edge, s);
                    self.visible(p, np, q, nq)
                };
                locate_changes(&vis_edge, r.s0, r.s1, self.probes, &mut s_breaks, &mut ns)?;
            }
        }
        push(&mut s_breaks, &mut ns, r.s1)?;
        let s_used = s_breaks.get_mut(..ns).unwrap_or_default();
        sort(s_used);
        let mut inner = T::ZERO;
        let mut line = Line::new();
        // Where two breakpoints of the t-lines meet (a boundary tangent to the lines) the
        // visible length grows like √(s − s*): J(s) has a square-root end point, which a
        // Gauss rule integrates only algebraically. s = s* + H·x² (or the smoothstep
        // 3x² − 2x³ with both ends graded) makes it smooth in x; at the other interior
        // breaks (a boundary crossing a t-edge) the map is harmless.
        for_each_piece(s_used, r.s0, r.s1, outside, |s_lo, s_hi, grade_lo, grade_hi| {
            let width = s_hi - s_lo;
            for (xs, ws) in self.rule.points() {
                let (u, du) = graded((xs + T::ONE) * T::HALF, grade_lo, grade_hi);
                let s = s_lo + width * u;
                self.line(p, np, r, s, &mut line)?;
                // Integrate the visible pieces (visibility alternates from the first piece).
                let mut sum = T::ZERO;
                let mut visible_piece = line.first_visible;
                for w in line.breaks.get(..line.n).unwrap_or_default().windows(2) {
                    let (lo, hi) = match w {
                        [lo, hi] => (*lo, *hi),
                        _ => continue,
                    };
                    let this_visible = visible_piece;
                    visible_piece = !visible_piece;
                    if !this_visible || !(hi > lo) {
                        continue;
                    }
                    let half = (hi - lo) * T::HALF;
                    let mut piece = T::ZERO;
                    for (xt, wt) in self.rule.points() {
                        let (q, nq) = self.surface.point_and_normal(lo + half * (xt + T::ONE), s);
                        self.tick();
                        piece += wt * kernel(p, np, q, nq);
                    }
                    sum += piece * half;
                }
                inner += ws * T::HALF * du * width * sum;
            }
            Ok(())
        })?;
        Ok(inner)
    }
}

/// Calls `f(lo, hi, graded_lo, graded_hi)` for the pieces of [start, end] between the sorted
/// singular points `breaks` (which include start and end). A piece next to a much narrower
/// neighbour has another singular point just beyond its end, where a Gauss rule converges
/// slowly; it is cut geometrically towards that end (widths w, 3w, 12w, … from the end, w the
/// neighbour's width), so every sub-piece sees that point at least its own length away. Only
/// ends at singular points are graded.
fn for_each_piece<T: Real>(
    breaks: &[T],
    start: T,
    end: T,
    outside: Outside<T>,
    mut f: impl FnMut(T, T, bool, bool) -> Result<(), PdmError>,
) -> Result<(), PdmError> {
    const MAX_LEVELS: usize = 24;
    let n = breaks.len();
    for k in 0..n.saturating_sub(1) {
        let (Some(&lo), Some(&hi)) = (breaks.get(k), breaks.get(k + 1)) else { continue };
        if !(hi > lo) {
            continue;
        }
        let width = hi - lo;
        let quarter = width * T::HALF * T::HALF;
        let (grade_lo, grade_hi) = (lo > start, hi < end);
        // Neighbour widths (a singular point that close beyond the end).
        let before = if k == 0 { outside.0 } else { breaks.get(k - 1).copied() };
        let after = if k + 2 == n { outside.1 } else { breaks.get(k + 1 + 1).copied() };
        let left = match before {
            Some(l) if lo - l < quarter && lo - l > T::ZERO => Some(lo - l),
            _ => None,
        };
        let right = match after {
            Some(r) if r - hi < quarter && r - hi > T::ZERO => Some(r - hi),
            _ => None,
        };
        let mid = lo + width * T::HALF;
        // From the left: [lo, lo + w], [lo + w, lo + 4w], … up to the middle.
        let mut a = lo;
        if let Some(w) = left {
            let mut step = w;
            let mut first = true;
            for _ in 0..MAX_LEVELS {
                let b = lo + step;
                if !(b < mid) {
                    break;
                }
                f(a, b, first && grade_lo, false)?;
                first = false;
                a = b;
                step *= T::from_f64(4.0);
            }
        }
        // From the right, mirrored, collected as the cut points below `hi`.
        let mut b_end = hi;
        let mut cuts = [T::ZERO; MAX_LEVELS];
        let mut nc = 0usize;
        if let Some(w) = right {
            let mut step = w;
            for _ in 0..MAX_LEVELS {
                let c = hi - step;
                if !(c > mid) || !(c > a) {
                    break;
                }
                if let Some(slot) = cuts.get_mut(nc) {
                    *slot = c;
                    nc += 1;
                }
                step *= T::from_f64(4.0);
            }
            if let Some(&c) = nc.checked_sub(1).and_then(|j| cuts.get(j)) {
                b_end = c;
            }
        }
        f(a, b_end, grade_lo && left.is_none(), grade_hi && right.is_none())?;
        // The right cuts, innermost first: [c_{j}, c_{j-1}], …, [c_0, hi].
        for j in (0..nc).rev() {
            let (Some(&c), next) = (cuts.get(j), if j == 0 { Some(&hi) } else { cuts.get(j - 1) }) else { continue };
            let Some(&d) = next else { continue };
            f(c, d, false, j == 0 && grade_hi)?;
        }
    }
    Ok(())
}

/// The map x ↦ (u, du/dx) of [0, 1] onto itself with du/dx = 0 at the graded ends.
#[inline]
fn graded<T: Real>(x: T, lo: bool, hi: bool) -> (T, T) {
    let three = T::from_f64(3.0);
    match (lo, hi) {
        (true, true) => (x * x * (three - T::TWO * x), T::from_f64(6.0) * x * (T::ONE - x)),
        (true, false) => (x * x, T::TWO * x),
        (false, true) => {
            let y = T::ONE - x;
            (T::ONE - y * y, T::TWO * y)
        }
        (false, false) => (x, T::ONE),
    }
}

/// The visibility structure of one inner line: `breaks[..n]` ascending from the line's start to
/// its end, pieces alternately visible and hidden starting with `first_visible`; `ids` folds
/// which polynomial makes each interior break (closed form; 0 otherwise).
struct Line<T> {
    breaks: [T; MAX_BREAKS + 2],
    n: usize,
    first_visible: bool,
    ids: u64,
}

impl<T: Real> Line<T> {
    fn new() -> Self {
        Self { breaks: [T::ZERO; MAX_BREAKS + 2], n: 0, first_visible: false, ids: 0 }
    }
}

/// Buffers for computing one line in closed form, kept between lines.
struct LineScratch<T> {
    polys: Polys<T>,
    candidates: [(T, u64); MAX_CANDIDATES],
}

impl<T: Real> LineScratch<T> {
    fn new() -> Self {
        Self { polys: Polys::new(), candidates: [(T::ZERO, 0u64); MAX_CANDIDATES] }
    }
}

/// Most candidate switches gathered on one line.
const MAX_CANDIDATES: usize = 2 * MAX_POLYS;

/// The visibility structure of the line t ∈ [t0, t1] from its polynomials: the candidate
/// switches are their real roots; each piece between consecutive candidates is classified by
/// the exact test at its midpoint, and equal neighbours merged. `false` if there are too many.
fn closed_form_line<T: Real>(
    polys: &[[T; 3]],
    t0: T,
    t1: T,
    vis_at: &impl Fn(T) -> bool,
    candidates: &mut [(T, u64); MAX_CANDIDATES],
    line: &mut Line<T>,
) -> bool {
    let mut n = 0usize;
    let mut overflow = false;
    for (id, &[a, b, c]) in polys.iter().enumerate() {
        crate::visibility::polynomial_roots(a, b, c, &mut |t| {
            if t > t0 && t < t1 {
                match candidates.get_mut(n) {
                    Some(slot) => {
                        *slot = (t, id as u64 + 1);
                        n += 1;
                    }
                    None => overflow = true,
                }
            }
        });
    }
    if overflow {
        return false;
    }
    let used = candidates.get_mut(..n).unwrap_or_default();
    sort_by_position(used);
    line.n = 0;
    line.ids = 0;
    let mut lo = t0;
    let mut lo_id = 0u64;
    let mut status: Option<bool> = None;
    // Candidates closer than this are one switch (two polynomials with a common root, e.g. a
    // facing test and the tangent plane of a sphere occluder the point lies on): the piece
    // between them is rounding, and the switch gets the smallest of their ids, so that the
    // line's structure does not change with which root rounds first.
    let merge = (t1 - t0) * end_inset::<T>();
    for &(hi, hi_id) in used.iter().chain(core::iter::once(&(t1, 0u64))) {
        if !(hi > lo + merge) {
            lo_id = lo_id.min(hi_id);
            continue;
        }
        let v = vis_at((lo + hi) * T::HALF);
        match status {
            None => {
                line.first_visible = v;
                if push(&mut line.breaks, &mut line.n, t0).is_err() {
                    return false;
                }
            }
            Some(prev) if prev != v => {
                if push(&mut line.breaks, &mut line.n, lo).is_err() {
                    return false;
                }
                line.ids = line.ids.wrapping_mul(MAX_POLYS as u64 + 1).wrapping_add(lo_id);
            }
            Some(_) => {}
        }
        status = Some(v);
        lo = hi;
        lo_id = hi_id;
    }
    if status.is_none() {
        line.first_visible = vis_at((t0 + t1) * T::HALF);
        if push(&mut line.breaks, &mut line.n, t0).is_err() {
            return false;
        }
    }
    push(&mut line.breaks, &mut line.n, t1).is_ok()
}

/// (q(x))² for a quadratic q, as quartic coefficients (ascending powers).
fn square<T: Real>(q: &[T; 3]) -> [T; 5] {
    product(q, q)
}

/// p(x)·q(x) for two quadratics, as quartic coefficients (ascending powers).
fn product<T: Real>(p: &[T; 3], q: &[T; 3]) -> [T; 5] {
    let mut out = [T::ZERO; 5];
    for (i, &a) in p.iter().enumerate() {
        for (j, &b) in q.iter().enumerate() {
            if let Some(o) = out.get_mut(i + j) {
                *o += a * b;
            }
        }
    }
    out
}

/// Horner evaluation of Σ c_k x^k.
fn horner<T: Real>(c: &[T], x: T) -> T {
    let mut v = T::ZERO;
    for &k in c.iter().rev() {
        v = v * x + k;
    }
    v
}

/// Passes the real roots in (x0, x1) of Σ c_k x^k (degree ≤ 4) where the polynomial changes
/// sign: the roots of its derivative split (x0, x1) into monotone pieces, each bisected.
fn roots_in_interval<T: Real>(c: &[T; 5], x0: T, x1: T, out: &mut dyn FnMut(T)) {
    let degree = c.iter().rposition(|&k| k != T::ZERO).unwrap_or(0);
    if degree <= 2 {
        let g = |k: usize| c.get(k).copied().unwrap_or(T::ZERO);
        crate::visibility::polynomial_roots(g(2), g(1), g(0), &mut |x| {
            if x > x0 && x < x1 {
                out(x);
            }
        });
        return;
    }
    // Critical points: roots of the derivative (degree ≤ 3), recursively.
    let mut derivative = [T::ZERO; 5];
    for (k, d) in derivative.iter_mut().enumerate().take(degree) {
        *d = c.get(k + 1).copied().unwrap_or(T::ZERO) * T::from_usize(k + 1);
    }
    let mut critical = [x0; 6];
    let mut nc = 1usize;
    roots_in_interval(&derivative, x0, x1, &mut |x| {
        if let Some(slot) = critical.get_mut(nc) {
            *slot = x;
            nc += 1;
        }
    });
    if let Some(slot) = critical.get_mut(nc) {
        *slot = x1;
        nc += 1;
    }
    let pts = critical.get_mut(..nc).unwrap_or_default();
    sort(pts);
    let coeffs = c.get(..=degree).unwrap_or_default();
    for w in pts.windows(2) {
        let (mut lo, mut hi) = match w {
            [lo, hi] => (*lo, *hi),
            _ => continue,
        };
        let (f_lo, f_hi) = (horner(coeffs, lo), horner(coeffs, hi));
        if f_lo == T::ZERO && lo > x0 {
            out(lo);
        }
        if !((f_lo < T::ZERO && f_hi > T::ZERO) || (f_lo > T::ZERO && f_hi < T::ZERO)) {
            continue;
        }
        let rising = f_hi > T::ZERO;
        for _ in 0..(T::MANTISSA_DIGITS + 4) {
            let mid = (lo + hi) * T::HALF;
            if mid <= lo || mid >= hi {
                break;
            }
            if (horner(coeffs, mid) > T::ZERO) == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        out((lo + hi) * T::HALF);
    }
}

/// Appends to `out` every point of (lo, hi) where `f` changes value, found on a uniform grid of
/// `probes` points and refined by bisection; ascending.
fn locate_changes<T: Real, K: PartialEq + Copy>(
    f: &impl Fn(T) -> K,
    lo: T,
    hi: T,
    probes: usize,
    out: &mut [T; MAX_BREAKS + 2],
    n: &mut usize,
) -> Result<(), PdmError> {
    let step = (hi - lo) / T::from_usize(probes - 1);
    // The end probes sit just inside the interval: an end may be a point where the surface's
    // normal vanishes (a pole, a disk's centre), whose facing tests fail although every point
    // next to it passes; probing it would report a change that is not there.
    let inset = (hi - lo) * end_inset::<T>();
    let mut prev_t = lo + inset;
    let mut prev_v = f(prev_t);
    for k in 1..probes {
        let t = if k == probes - 1 { hi - inset } else { lo + step * T::from_usize(k) };
        let v = f(t);
        // Several changes between two probes (A → B → C) show as a value after the first
        // change that is not yet the probe's: keep bisecting from there. (A → B → A pairs
        // narrower than the probe spacing stay unseen.)
        let (mut from, mut from_v) = (prev_t, prev_v);
        let mut guard = 0;
        while from_v != v && guard < MAX_BREAKS {
            let (lo_end, hi_end, hi_v) = bisect(f, from, t, from_v);
            push(out, n, (lo_end + hi_end) * T::HALF)?;
            if !(hi_end < t) {
                break;
            }
            (from, from_v) = (hi_end, hi_v);
            guard += 1;
        }
        prev_t = t;
        prev_v = v;
    }
    Ok(())
}

/// Relative distance from an interval's ends at which visibility is probed instead of the end
/// itself (ε^¾: 1.8e-12 in f64, 6.4e-6 in f32). A change closer to an end than this is not
/// placed into the rule; the rule then integrates across it on a piece of that width.
#[inline]
fn end_inset<T: Real>() -> T {
    let e = T::EPSILON.sqrt();
    e * e.sqrt()
}

/// Insertion sort of (position, tag) pairs by position (few elements, no allocation, no
/// panics on NaN: NaN never moves).
fn sort_by_position<T: Real, K: Copy>(xs: &mut [(T, K)]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&x), Some(&y)) = (xs.get(j - 1), xs.get(j)) else { break };
            if x.0 > y.0 {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}

/// Insertion sort (few elements, no allocation, no panics on NaN: NaN never moves).
fn sort<T: Real>(xs: &mut [T]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&a), Some(&b)) = (xs.get(j - 1), xs.get(j)) else { break };
            if a > b {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}

fn push<T: Copy>(breaks: &mut [T; MAX_BREAKS + 2], n: &mut usize, t: T) -> Result<(), PdmError> {
    match breaks.get_mut(*n) {
        Some(slot) => {
            *slot = t;
            *n += 1;
            Ok(())
        }
        None => Err(PdmError::CapacityExceeded { needed: *n + 1, capacity: MAX_BREAKS + 2 }),
    }
}

/// The point in [lo, hi] where `f` switches from `f_lo`, to within rounding of the interval.
/// The bracket [lo, hi] (adjacent floating-point numbers, or 4 bits short of them) around the
/// first point where `f` switches from `f_lo`, and the value of `f` at `hi`.
fn bisect<T: Real, K: PartialEq + Copy>(f: &impl Fn(T) -> K, mut lo: T, mut hi: T, f_lo: K) -> (T, T, K) {
    let mut f_hi = f(hi);
    for _ in 0..(T::MANTISSA_DIGITS + 4) {
        let mid = (lo + hi) * T::HALF;
        if mid <= lo || mid >= hi {
            break;
        }
        let f_mid = f(mid);
        if f_mid == f_lo {
            lo = mid;
        } else {
            hi = mid;
            f_hi = f_mid;
        }
    }
    (lo, hi, f_hi)
}
