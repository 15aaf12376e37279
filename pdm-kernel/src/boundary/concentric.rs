//! A sphere occluder concentric with the sphere the inner patch lies on (a sphere inside a
//! sphere): its shadow on b from a point p is bounded by a circle about the ray from the
//! centre through p, in closed form along b's lines; where the outer patch lies on a sphere
//! with the same centre too, every boundary is such a circle, and the outer events are in
//! closed form as well.
//!
//! With c the common centre, ρ the occluder's radius, d = |p − c| > ρ and R the radius of b's
//! sphere (> ρ), the segment from p to a point q of b misses the occluder exactly where the
//! angle ω at c between p and q is at most ψ = acos(ρ/d) + acos(ρ/R): in the plane of c, p, q
//! the occluder is a disk, and the segment is tangent to it where it makes those angles at c on
//! either side of the tangent point. So the occluder's test on b is the plane test
//! p̂·(q − c) ≥ R·cos ψ (p̂ the unit vector from c to p), which on a sphere's lines is
//! first-degree trigonometric like the facing tests ([`Surface::facing_along_t`]): the inner
//! rule places it in closed form ([`Concentric::plane`]). (Where p's own facing circle on b
//! is not centred on p's ray — a flat outer patch, or a sphere with another centre — it can
//! cross the occluder's inside b; the s-breaks do not place that crossing, and J converges
//! algebraically in s there.)
//!
//! Where the outer patch lies on a sphere with the same centre too (radius d), every boundary
//! of the visible part of b is a circle ω = ψₖ about p̂: the occluder's ψ, and where a facing
//! test changes sign inside b, cos ω = d/R (p's tangent plane) and cos ω = R/d (q's). J(p)
//! changes its structure only where such a circle passes a corner of b (the visible area grows
//! like δ² on one side: a jump in the second derivative) or touches one of b's edges (like
//! δ^{3/2}), and b's edges are
//! circles of its sphere (meridians and parallels, [`Surface::on_sphere`]), each the set
//! x̂·e = cos α. Both are plane sections of a's sphere: the corner q̂ᵢ where p̂·q̂ᵢ = cos ψₖ,
//! the edge where p̂·e = cos(ψₖ ± α) (two circles on a sphere touch where their centres are
//! the sum or the difference of their radii apart). Those are circles in a's parameters
//! ([`Surface::facing_across_s`] of the plane), placed into the outer rule as
//! [`TrigonometricEvents`] places a sphere's circles against a parallelogram, with the rule
//! along the t-lines graded towards every curve's roots: a corner's curve touches the
//! tangency curve of each edge through that corner (where the circle touches the edge at its
//! end), and ungraded there the outer rule converged only like n⁻⁷ on a cell holding that
//! point.
//!
//! The roles reversed: a parallelogram inside a sphere's inside, across a smaller sphere with
//! that sphere's centre, the sphere's cell outside ([`shell_flat_events`]). The boundaries on
//! the parallelogram are then conics, but the curves on the outer sphere where they change
//! their structure are again circles: a corner q is cut off at the angle acos(ρ/|q − c|) +
//! acos(ρ/R) from p̂, the outline touches an edge where p lies on a plane through the edge
//! tangent to the occluder, and p crosses the parallelogram's plane.

use super::*;

/// A sphere occluder with the centre of the sphere b lies on, inside it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Concentric<T> {
    pub(super) center: Vec3<T>,
    pub(super) occluder: T,
    pub(super) radius: T,
}

impl<T: Real> Concentric<T> {
    /// The concentric sphere occluder of a pair, where the only occluder that may cut segments
    /// from the ball `from` to b (`bounds`) is a sphere with the centre of b's sphere
    /// (`surface`), smaller than it; `None` elsewhere. (A point inside it has no plane:
    /// [`Concentric::plane`].)
    pub(super) fn of<SB, O>(surface: &SB, bounds: &Ball<T>, from: &Ball<T>, occluders: &O) -> Option<Self>
    where
        SB: Surface<T> + ?Sized,
        O: Occluder<T> + ?Sized,
    {
        let sphere = surface.on_sphere()?;
        let occluder = occluders.shadow_sphere(from, bounds)??;
        let margin = T::GEOMETRY_TOLERANCE * sphere.radius;
        let inside = occluder.radius + margin < sphere.radius;
        (same_centre(&occluder, &sphere) && inside && occluder.radius > T::ZERO).then_some(Self {
            center: sphere.center,
            occluder: occluder.radius,
            radius: sphere.radius,
        })
    }

    /// cos ψ for a point at distance `d` from the centre (module docs): the largest angle at
    /// the centre between it and a visible point of b.
    fn cos_reach(&self, d: T) -> T {
        let (x, y) = (self.occluder / d, self.occluder / self.radius);
        x * y - ((T::ONE - x * x).max(T::ZERO) * (T::ONE - y * y).max(T::ZERO)).sqrt()
    }

    /// The occluder's test from p as a plane (x₀, n): q of b is visible past it exactly where
    /// n·(q − x₀) ≥ 0. `None` where p is not outside the occluder.
    pub(super) fn plane(&self, p: Vec3<T>) -> Option<(Vec3<T>, Vec3<T>)> {
        let v = p - self.center;
        let d = v.norm();
        if !(d > self.occluder) {
            return None;
        }
        let n = v.scale(T::ONE / d);
        Some((self.center + n.scale(self.radius * self.cos_reach(d)), n))
    }
}

/// Whether two spheres share their centre to within rounding of their size and position: the
/// plane tests and events hold only for a common centre.
pub(super) fn same_centre<T: Real>(a: &Ball<T>, b: &Ball<T>) -> bool {
    let scale = a.radius + b.radius + a.center.norm();
    (a.center - b.center).norm() <= T::from_f64(16.0) * T::EPSILON * scale
}

/// Most event curves of a concentric pair: per boundary angle (the occluder's and one facing
/// test's, [`angles`]) four corners and two circles for each of four edges.
const MAX_CONCENTRIC_CURVES: usize = 2 * 12;

/// Most quadric sections among a sphere cell's events (`sphere_flat::sphere_flat_events`: one
/// cone per corner of a parallelogram).
const MAX_QUADRATIC_CURVES: usize = 4;

/// The outer events of a concentric pair, or of a sphere's cell around a parallelogram across
/// a sphere (`sphere_flat`): [`TrigonometricEvents`] with room for their curves (in s, eight
/// breaks per plane section; per quadric section eight on the t-edges and, with its
/// tangencies, room for twelve more).
pub(super) type ConcentricEvents<T> = TrigonometricEvents<
    T,
    MAX_CONCENTRIC_CURVES,
    { 8 * MAX_CONCENTRIC_CURVES + 20 * MAX_QUADRATIC_CURVES + 2 },
    { 2 * MAX_CONCENTRIC_CURVES + 4 * MAX_QUADRATIC_CURVES + 2 },
    MAX_QUADRATIC_CURVES,
>;

/// cos ψₖ of the boundaries of the visible part of b's sphere (radius `rb`) from a point of
/// a's (radius `ra`; module docs): the occluder's where there is one, and the facing tests'
/// d/R and R/d where those are below 1 (at most one is); each `None` where it is no boundary.
fn angles<T: Real>(occluder: Option<&Concentric<T>>, ra: T, rb: T) -> [Option<T>; 2] {
    let open = |k: T| (k.abs() < T::ONE - T::from_f64(64.0) * T::EPSILON).then_some(k);
    let facing = if ra < rb { ra / rb } else { rb / ra };
    [occluder.and_then(|c| open(c.cos_reach(ra))), open(facing)]
}

/// The circle of b's sphere an edge of b lies on, as (e, cos α, sin α): x̂·e = cos α, through
/// the edge's start, quarter and middle (`points`, then its end), checked at its end (an edge
/// that is a whole parallel ends where it starts). `Some(None)` for an edge collapsed to a
/// point (a pole: its corner's curves cover it); `None` where the points do not give one
/// circle of the sphere to within the geometry's tolerance.
fn edge_circle<T: Real>(center: Vec3<T>, radius: T, points: [Vec3<T>; 4]) -> Option<Option<(Vec3<T>, T, T)>> {
    let [q0, quarter, middle, end] = points;
    let reach = (quarter - q0).norm().max((middle - q0).norm());
    if reach <= T::from_f64(1024.0) * T::EPSILON * radius {
        return Some(None);
    }
    let normal = (quarter - q0).cross(middle - q0);
    let length = normal.norm();
    if !(length > T::ZERO) {
        return None;
    }
    let e = normal.scale(T::ONE / length);
    if !((end - q0).dot(e).abs() <= T::GEOMETRY_TOLERANCE * radius) {
        return None;
    }
    let cos = ((q0 - center).dot(e) / radius).max(-T::ONE).min(T::ONE);
    let sin = (T::ONE - cos * cos).max(T::ZERO).sqrt();
    Some(Some((e, cos, sin)))
}

/// The corners of `surface` over `r` in order around it, and per edge (s = s₀, s = s₁,
/// t = t₀, t = t₁) its start, quarter, middle and end points ([`edge_circle`]'s samples).
fn corners_and_edges<T: Real, S: Surface<T> + ?Sized>(
    surface: &S,
    r: ParamRect<T>,
) -> ([Vec3<T>; 4], [[Vec3<T>; 4]; 4]) {
    let p = |t: T, s: T| surface.point(t, s);
    let corners = [p(r.t0, r.s0), p(r.t1, r.s0), p(r.t1, r.s1), p(r.t0, r.s1)];
    let (tm, sm) = ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    let quarter = |a: T, b: T| a + (b - a) * T::HALF * T::HALF;
    let (tq, sq) = (quarter(r.t0, r.t1), quarter(r.s0, r.s1));
    let edges = [
        [p(r.t0, r.s0), p(tq, r.s0), p(tm, r.s0), p(r.t1, r.s0)],
        [p(r.t0, r.s1), p(tq, r.s1), p(tm, r.s1), p(r.t1, r.s1)],
        [p(r.t0, r.s0), p(r.t0, sq), p(r.t0, sm), p(r.t0, r.s1)],
        [p(r.t1, r.s0), p(r.t1, sq), p(r.t1, sm), p(r.t1, r.s1)],
    ];
    (corners, edges)
}

/// The outer events of the sphere cell `outer` against the sphere cell `inner` over `r` with
/// the same centre, across the concentric `occluder` or none (module docs); `None` where
/// either surface does not lie on a sphere, the spheres do not share the centre, the occluder
/// reaches a's sphere, the outer surface does not give its plane sections in trigonometric
/// form, or an edge of b is not a circle of its sphere.
pub(super) fn concentric_events<T, SA, SB>(
    outer: &SA,
    inner: &SB,
    r: ParamRect<T>,
    occluder: Option<&Concentric<T>>,
) -> Option<ConcentricEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (ball, inner_ball) = (outer.on_sphere()?, inner.on_sphere()?);
    let c = inner_ball.center;
    if !same_centre(&ball, &inner_ball) {
        return None;
    }
    let ra = ball.radius;
    if occluder.is_some_and(|o| !(o.occluder + T::GEOMETRY_TOLERANCE * ra < ra)) {
        return None;
    }
    let mut events = ConcentricEvents::empty();
    // The plane section p̂·e = k of a's sphere: e·(p − (c + ra·k·e)) = 0.
    let mut section = |e: Vec3<T>, k: T, grade: bool| -> Option<()> {
        let [curve, _] = outer.facing_across_s(c + e.scale(ra * k), e)?;
        events.push(curve, grade)
    };
    let rb = inner_ball.radius;
    let (corners, edges) = corners_and_edges(inner, r);
    let mut circles = [None; 4];
    for (slot, edge) in circles.iter_mut().zip(edges) {
        *slot = edge_circle(c, rb, edge)?;
    }
    for cos_psi in angles(occluder, ra, rb).into_iter().flatten() {
        let sin_psi = (T::ONE - cos_psi * cos_psi).max(T::ZERO).sqrt();
        for q in corners {
            let v = q - c;
            let n = v.norm();
            if !(n > T::ZERO) {
                return None;
            }
            section(v.scale(T::ONE / n), cos_psi, true)?;
        }
        for (e, cos_a, sin_a) in circles.iter().flatten() {
            // cos(ψ ∓ α): the circles touch with their centres ψ + α or |ψ − α| apart.
            section(*e, cos_psi * *cos_a - sin_psi * *sin_a, true)?;
            section(*e, cos_psi * *cos_a + sin_psi * *sin_a, true)?;
        }
    }
    Some(events)
}

/// The outer events of a cell of a sphere (the outer patch, `outer`) against a parallelogram
/// inside it (its affine map over a rectangle, unit normal `normal` to the side it radiates to), across one
/// sphere occluder with the outer sphere's centre c and radius ρ, clear of the parallelogram:
/// every boundary of what p sees of the parallelogram changes its structure on a plane
/// section of the outer sphere (radius R; p = c + R·p̂):
/// - a corner q is cut off where the segment p–q touches the occluder: the angle at c between
///   p and q is acos(ρ/|q − c|) + acos(ρ/R) (as [`Concentric::plane`] with the roles swapped);
/// - the shadow's outline touches an edge's line where p lies on one of the two planes through
///   that line tangent to the occluder: with d the line's distance from c, v the unit vector
///   from c to its foot and e its direction, the planes' normals are (ρ/d)·v ± √(1 − ρ²/d²)·
///   e × v, and p̂·n = ρ/R on them;
/// - p crosses the parallelogram's plane (its facing test changes sign for the whole of it).
///
/// p's own facing test passes for every point inside its sphere (the chord from p leaves
/// along the inward normal), so it puts no boundary on the parallelogram. `None` where the
/// parallelogram reaches outside the outer sphere, the occluder is not concentric with it and
/// smaller, or the parallelogram comes within the occluder. (Where its plane cuts the
/// occluder, the part of the shadow's outline on the parallelogram is still the tangent
/// cone's: the outline leaves it only on the occluder itself.)
pub(super) fn shell_flat_events<T, SA>(
    outer: &SA,
    (map, r): MappedRect<T>,
    normal: Vec3<T>,
    occluder: &Ball<T>,
) -> Option<ConcentricEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
{
    let shell = outer.on_sphere()?;
    let (c, big, rho) = (shell.center, shell.radius, occluder.radius);
    let margin = T::GEOMETRY_TOLERANCE * big;
    if !(same_centre(occluder, &shell) && rho > T::ZERO && rho + margin < big) {
        return None;
    }
    let corners = map_corners(map, r);
    let [q0, ..] = corners;
    let clear = distance_to_parallelogram(c, map, r) > rho + margin;
    if !clear || !corners.iter().all(|q| (*q - c).norm() + margin < big) {
        return None;
    }
    let mut events = ConcentricEvents::empty();
    let mut section = |e: Vec3<T>, k: T| -> Option<()> {
        let [curve, _] = outer.facing_across_s(c + e.scale(big * k), e)?;
        events.push(curve, true)
    };
    let y = rho / big;
    let sin_y = (T::ONE - y * y).max(T::ZERO).sqrt();
    for q in corners {
        let v = q - c;
        let d = v.norm();
        let x = rho / d;
        let cos_psi = x * y - (T::ONE - x * x).max(T::ZERO).sqrt() * sin_y;
        section(v.scale(T::ONE / d), cos_psi)?;
    }
    for (_, n) in edge_tangent_planes(&corners, c, rho, margin, T::ZERO).into_iter().flatten() {
        section(n, y)?;
    }
    let k = normal.dot(q0 - c) / big;
    if k.abs() < T::ONE {
        section(normal, k)?;
    }
    Some(events)
}

/// The planes through the lines of a quadrilateral's edges (`corners` in order) tangent to
/// the ball (centre `c`, radius `rho`), two per edge, as (foot of the line's perpendicular from
/// c, unit normal): with d the line's distance from c, v the unit vector from c to the foot
/// and e the line's direction, the normals are (ρ/d)·v ± √(1 − ρ²/d²)·e × v. `None` for an
/// edge shorter than `margin` and for a line within `clearance` of the ball (every plane
/// through a line that passes through the ball cuts it: the outline crosses the line and
/// never touches it).
pub(super) fn edge_tangent_planes<T: Real>(
    corners: &[Vec3<T>; 4],
    c: Vec3<T>,
    rho: T,
    margin: T,
    clearance: T,
) -> [Option<(Vec3<T>, Vec3<T>)>; 8] {
    let mut planes = [None; 8];
    for (i, (&q, slots)) in corners.iter().zip(planes.chunks_mut(2)).enumerate() {
        let Some(&next) = corners.get((i + 1) % 4) else { continue };
        let edge = next - q;
        let length = edge.norm();
        if !(length > margin) {
            continue;
        }
        let e = edge.scale(T::ONE / length);
        let foot = q + e.scale((c - q).dot(e));
        let to_foot = foot - c;
        let d = to_foot.norm();
        if !(d - rho > clearance) {
            continue;
        }
        let v = to_foot.scale(T::ONE / d);
        let w = e.cross(v);
        let (along, across) = (rho / d, (T::ONE - (rho / d) * (rho / d)).max(T::ZERO).sqrt());
        for (slot, sign) in slots.iter_mut().zip([T::ONE, -T::ONE]) {
            *slot = Some((foot, v.scale(along) + w.scale(sign * across)));
        }
    }
    planes
}

/// Most curves of an off-centre pair ([`offcentre_events`]): four corners and two per edge.
const MAX_OFFCENTRE_CURVES: usize = 12;

/// The outer events of a sphere's cell around a concentric pair's inner cell from off the
/// centre ([`TrigonometricEvents`] with room for twelve quadric sections).
pub(super) type OffCentreEvents<T> = TrigonometricEvents<
    T,
    1,
    { 20 * MAX_OFFCENTRE_CURVES + 2 },
    { 4 * MAX_OFFCENTRE_CURVES + 2 },
    MAX_OFFCENTRE_CURVES,
>;

/// The outer events of a cell (`a`) of a sphere whose centre C is not the concentric pair's
/// centre c, against the cell `inner` over `r` of the concentric sphere b's inside (radius
/// R), across the occluder of radius ρ with centre c (module docs): where b lies in front of
/// every tangent plane of a's cell and the cell lies inside b's sphere and outside the
/// occluder, p sees the cap of b about p̂ of angle ψ(d) = acos(ρ/d) + acos(ρ/R), d = |p − c|,
/// whose outline passes a corner q̂ where p̂·q̂ = cos ψ and touches an edge (the circle
/// x̂·e = cos α) where p̂·e = cos(ψ ± α). With γ = acos(ρ/R) ∓ α (α = 0 for a corner) and
/// S = √(d² − ρ²), d·cos(ψ ± α) = ρ·cos γ − S·sin γ, so each is (e·(p − c) − ρ·cos γ)² =
/// sin²γ·(|p − c|² − ρ²) on the branch where the left factor is negative; on a's sphere
/// |p − c|² is affine in p, and the curve is L₁² = L₂ with plane tests
/// ([`TrigonometricEvents::push_quadratic`]; the other branch costs breaks, not accuracy).
/// `None` where a condition fails, the centres coincide (then [`concentric_events`]), or an
/// edge of b is not a circle of its sphere.
pub(super) fn offcentre_events<T, SA, SB>(
    a: &Patch<'_, T, SA>,
    inner: &SB,
    r: ParamRect<T>,
    occluder: &Concentric<T>,
) -> Option<OffCentreEvents<T>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let outer = a.surface();
    let (sphere, inner_ball) = (outer.on_sphere()?, inner.on_sphere()?);
    let (big_c, ra) = (sphere.center, sphere.radius);
    let (c, rb, rho) = (occluder.center, occluder.radius, occluder.occluder);
    if same_centre(&sphere, &inner_ball) {
        return None;
    }
    let margin = T::GEOMETRY_TOLERANCE * (ra + rb + (big_c - c).norm());
    let cell = a.rect();
    let (tm, sm) = ((cell.t0 + cell.t1) * T::HALF, (cell.s0 + cell.s1) * T::HALF);
    // The side a's cell faces (+1 out of its sphere), and b's inside: its normal towards c.
    let side = outer.normal(tm, sm).dot(outer.point(tm, sm) - big_c);
    let (tb, sb) = ((r.t0 + r.t1) * T::HALF, (r.s0 + r.s1) * T::HALF);
    if !(inner.normal(tb, sb).dot(inner.point(tb, sb) - c) < T::ZERO) || side == T::ZERO {
        return None;
    }
    let sign = if side > T::ZERO { T::ONE } else { -T::ONE };
    // |p − c|² − k₀ = g·(p − x₀) on a's sphere: |p − c|² = Rₐ² + |w|² + 2w·(p − C), w = C − c.
    let w = big_c - c;
    let w2 = w.dot(w);
    let distance_form = |k0: T, scale: T| -> Option<[[T; 3]; 3]> {
        let k = (ra * ra + w2 - k0) / (T::TWO * w2);
        let [form, _] = outer.facing_across_s(big_c - w.scale(k), w.scale(T::TWO * scale))?;
        Some(form)
    };
    let least = |form: [[T; 3]; 3]| trigonometric_least(form, cell);
    let negative = |form: [[T; 3]; 3]| form.map(|k| k.map(|x| -x));
    // Outside the occluder and inside b's sphere: ρ² < |p − c|² < R².
    if !(least(distance_form(rho * rho, T::ONE)?) > margin * rho)
        || !(least(negative(distance_form(rb * rb, T::ONE)?)) > margin * rb)
    {
        return None;
    }
    // b in front of every tangent plane of a's cell, by b's enclosing ball (centre m, radius
    // ρ_b): sign·((m − C)·(p − C) − Rₐ²) > Rₐ·ρ_b.
    let ball = Patch::new(inner, r).ok()?.enclosing_ball();
    let v = ball.center - big_c;
    let v2 = v.dot(v);
    if !(v2 > T::ZERO) {
        return None;
    }
    let [facing, _] = outer.facing_across_s(big_c + v.scale(ra * ra / v2), v.scale(sign))?;
    if !(least(facing) > ra * ball.radius + margin * ra) {
        return None;
    }
    let (corners, edges) = corners_and_edges(inner, r);
    let gamma = (rho / rb).max(-T::ONE).min(T::ONE);
    let (cos_g, sin_g) = (gamma, (T::ONE - gamma * gamma).max(T::ZERO).sqrt());
    let mut events = OffCentreEvents::empty();
    // (e·(p − c) − ρ·cos γ')² = sin²γ'·(|p − c|² − ρ²), for a unit e.
    let mut push = |e: Vec3<T>, cos: T, sin: T| -> Option<()> {
        let [l1, _] = outer.facing_across_s(c + e.scale(rho * cos), e)?;
        events.push_quadratic(l1, distance_form(rho * rho, sin * sin)?)
    };
    for q in corners {
        let v = q - c;
        let n = v.norm();
        if !(n > T::ZERO) {
            return None;
        }
        push(v.scale(T::ONE / n), cos_g, sin_g)?;
    }
    for edge in edges {
        let Some((e, cos_a, sin_a)) = edge_circle(c, rb, edge)? else { continue };
        // γ ∓ α for the outline touching from outside and inside the circle.
        push(e, cos_g * cos_a + sin_g * sin_a, sin_g * cos_a - cos_g * sin_a)?;
        push(e, cos_g * cos_a - sin_g * sin_a, sin_g * cos_a + cos_g * sin_a)?;
    }
    Some(events)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::surface::{Side, Sphere};

    /// The plane test from p agrees with the occluder's own segment test on b's sphere, from
    /// points inside and outside that sphere, except within rounding of the boundary.
    #[test]
    fn the_plane_is_the_occluders_test() {
        let center = vec3(0.1, -0.2, 0.3);
        let occluder = Sphere::outer(center, 0.7).unwrap();
        let shell = Sphere::new(center, 1.6, Side::Inner).unwrap();
        let bounds = Ball { center, radius: 1.6 };
        let from = Ball { center, radius: 2.5 };
        let concentric = Concentric::of(&shell, &bounds, &from, &occluder).unwrap();
        let (mut visible, mut hidden) = (0, 0);
        for k in 0..40 {
            let (u, v) = (0.37 * k as f64, 0.91 * k as f64);
            let d = 0.75 + 0.045 * k as f64;
            let p = center + vec3(u.sin() * v.cos(), u.sin() * v.sin(), u.cos()).scale(d);
            let (x0, n) = concentric.plane(p).unwrap();
            for i in 1..20 {
                for j in 0..24 {
                    let q = shell.point(i as f64 * 0.157, j as f64 * 0.2618);
                    let test = n.dot(q - x0);
                    if test.abs() <= 1e-9 {
                        continue;
                    }
                    let blocked = occluder.blocks(p, q);
                    assert_eq!(test > 0.0, !blocked, "p {p:?}, q {q:?}: plane {test:e}");
                    if blocked {
                        hidden += 1;
                    } else {
                        visible += 1;
                    }
                }
            }
        }
        assert!(visible > 1000 && hidden > 1000, "{visible} visible, {hidden} hidden");
        assert!(concentric.plane(center + vec3(0.5, 0.0, 0.0)).is_none(), "inside the occluder");
    }

    /// Two cells inside a sphere across a concentric sphere get their outer events; with the
    /// occluder moved off the centre, or of the size of the shell, they do not.
    #[test]
    fn events_only_for_a_concentric_occluder() {
        let center = vec3(1.0, 2.0, -0.5);
        let shell = Sphere::new(center, 2.0, Side::Inner).unwrap();
        let cell = |t0: f64, s0: f64| Patch::new(&shell, ParamRect::new(t0, t0 + 0.8, s0, s0 + 0.8).unwrap()).unwrap();
        let (a, b) = (cell(0.9, 0.0), cell(1.1, 2.4));
        let inside = Sphere::outer(center, 1.0).unwrap();
        assert!(outer_events_apply(&a, &b, &inside));
        assert!(outer_events_apply(&b, &a, &inside));
        let moved = Sphere::outer(center + vec3(0.0, 0.0, 1e-3), 1.0).unwrap();
        assert!(!outer_events_apply(&a, &b, &moved));
        let whole = Sphere::outer(center, 2.0).unwrap();
        assert!(!outer_events_apply(&a, &b, &whole));
    }
}
