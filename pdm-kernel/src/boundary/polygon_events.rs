//! Outer events across flat convex occluders: the lines on a flat outer patch a where J(p) over
//! a parallelogram b changes its structure when the occluders are one convex polygon, or the
//! facets of one convex solid.
//!
//! J(p) is Lambert's form over b less the union of the occluders' shadows (`shadows.rs`); it is
//! analytic in p as long as the combinatorial structure of that region stays the same. For one
//! convex polygon O (or a convex solid's facets, whose shadows' union is the solid's shadow)
//! the structure changes only where
//!
//! * a shadow vertex crosses an edge of b: p lies in the plane through a vertex v of O and b's
//!   edge, on the part of it where the ray from p through v meets the edge segment (the visible
//!   area changes like δ² on one side);
//! * a shadow edge passes through a corner c of b: p lies in the plane through c and an edge of
//!   O, on the part where the segment from p to c crosses that edge (likewise δ²);
//! * p crosses O's own plane: the shadow folds through a segment, its area is ∝ |δ| (a kink);
//!   for a solid, a facet turns towards or away from p and the silhouette changes;
//! * p crosses b's plane (b starts facing p).
//!
//! "b" is the part of b that a sees ([`front_part`]): where b straddles a's plane, it is b
//! clipped by that plane, the same polygon from every point of a.
//!
//! All are planes, so on a flat a they are lines in a's parameters, each with a guard (the
//! double wedge about the line through v, or through c, where the event is real) placed into
//! the outer rule as [`Events`] places conics. A vertex or edge of O lying on or behind b's
//! plane is its own shadow there and moves with nothing; it gives no event. The part of O
//! beyond p's height casts its shadow beyond every bounded b, so p passing a vertex's height
//! is no event either.
//!
//! Several convex solids (and at most one sphere, whose events are `Events::new`'s: its shadow
//! through b's corners and tangent to b's edges) take the union of their events where their
//! shadows can never meet on b: no segment from a to b meets two of them, which a
//! separating-axis test proves ([`shadows_apart`]). J is then b less disjoint shadows, and its
//! structure changes only at each one's own events. Where two solids' shadows can meet, J also
//! changes where a vertex of one's shadow crosses an edge of the other's (planes through a
//! vertex of one solid and an edge of the other) and where two shadow edges cross on an edge
//! of b (p on a line meeting three lines: a quadric), which `push_meeting` adds. Each event
//! is kept only on the part of a where it can be real (`push_trimmed`: the ray through the
//! vertex lands on the edge and in b, the edge is on its solid's outline seen from p; a
//! quadric on the arc, sampled along b's edge, where its line meets both solids' edges between
//! p and b, both on their outlines: `real_arc`; most of the 576 candidates of two boxes are
//! real nowhere on a, and the rest on short arcs). A sphere's shadow that can meet a solid's, or three solids' that can all meet,
//! bring curves of other kinds: those pairs are declined (`None`), and the outer rule samples
//! across their events as before.
//!
//! The outer rule is a tensor product: every curve's ends and crossings of a's t-edges are
//! breaks along the whole of s, so n curves cost O(n²) pieces. Two boxes whose shadows meet
//! give one to two hundred curves and ~5·10⁴ outer points at order 4, where the value is
//! exact to 1e-10; sampling across them instead is cheap per order but converges
//! algebraically (a floor and a ceiling past two boxes: 4.6e-4 off at order 8, 2.4e-5 at 24).
//!
//! Occluders that cannot cut any segment from a to b (a separating plane between the occluder
//! and the hull of a and b, or lying on or behind a's or b's plane) are left out first, so a
//! room's walls do not count against a pair of other walls, nor a box's other facets against
//! one of its own. The polygons that can cut are grouped into solids by shared edges as long as
//! the group stays convex ([`label_solids`]), so that a cabinet standing in a hole of the floor
//! is one solid, not one with the floor. An occluder touching a's boundary (the cabinet's foot
//! on a floor facet's edge) makes J singular along that side: the rule is graded towards it,
//! and the pair is reported as not converging exponentially (`Events::touches_side`), so that
//! the pair takes the other patch outside or the tolerance mode's estimate for such pairs.

use super::*;
use crate::surface::Sphere;

use crate::visibility::{Caster, Quadric};

/// Most event curves of one pair across polygons. One box gives at most 86 lines (its eight
/// vertices against b's four edges, its twelve edges against b's four corners, its six facet
/// planes) before those that miss a are left out; two boxes whose shadows meet add up to 192
/// vertex–edge planes and 576 three-line quadrics, most of them real nowhere on a. A pair
/// whose curves overflow is declined: the outer rule samples across its events.
pub(crate) const MAX_POLYGON_EVENT_CURVES: usize = 384;

/// Breaks in s (a line crosses a's two t-edges and ends on its two guard lines; a conic
/// crosses each t-edge twice, is tangent to the t-lines twice and ends on its guard lines four
/// times) and along one outer line (two per conic), ends included.
const POLYGON_S_BREAKS: usize = 10 * MAX_POLYGON_EVENT_CURVES + 2;
const POLYGON_T_BREAKS: usize = 2 * MAX_POLYGON_EVENT_CURVES + 2;

/// A parallelogram: its affine map (origin, e_t, e_s) and parameter rectangle.
pub(super) type MappedRect<T> = ((Vec3<T>, Vec3<T>, Vec3<T>), ParamRect<T>);

/// The events of a pair across flat convex occluders.
pub(super) type PolygonEvents<T> = Events<T, MAX_POLYGON_EVENT_CURVES, POLYGON_S_BREAKS, POLYGON_T_BREAKS>;

/// Most facets of the one convex solid (a box has six).
const MAX_FACETS: usize = 12;

/// Most polygons that may cut from a's ball ([`Occluder::shadow_casters`]), of all solids: a
/// room's walls, a table's and a cabinet's facets.
const MAX_CASTERS: usize = 32;

/// Most separate convex solids whose events one pair takes (a table and a cabinet in a room,
/// with room for two more), besides at most one sphere.
const MAX_SOLIDS: usize = 4;

/// A polygon that may cut: its corners, their number, and whether a segment from a to b can
/// cross it (else it only closes a solid: [`label_solids`]).
type CasterPolygon<T> = ([Vec3<T>; FACET_CORNERS], usize, bool);

/// Most corners of one facet ([`Caster::Polygon`]: a quadrilateral, a triangle as one).
const FACET_CORNERS: usize = 6;

/// Most distinct vertices and edges of the solid.
const MAX_VERTICES: usize = 2 * MAX_FACETS + 8;
const MAX_EDGES: usize = MAX_FACETS * FACET_CORNERS / 2 + 8;

/// The occluder polygons that may cut the pair, with their distinct vertices and edges.
struct Solid<T> {
    facets: [([Vec3<T>; FACET_CORNERS], usize); MAX_FACETS],
    n_facets: usize,
    vertices: [Vec3<T>; MAX_VERTICES],
    n_vertices: usize,
    /// Each edge once (end points in either order), and how many facets have it.
    edges: [(Vec3<T>, Vec3<T>, u8); MAX_EDGES],
    n_edges: usize,
}

impl<T: Real> Solid<T> {
    fn new() -> Self {
        Self {
            facets: [([Vec3::ZERO; FACET_CORNERS], 0); MAX_FACETS],
            n_facets: 0,
            vertices: [Vec3::ZERO; MAX_VERTICES],
            n_vertices: 0,
            edges: [(Vec3::ZERO, Vec3::ZERO, 0); MAX_EDGES],
            n_edges: 0,
        }
    }

    /// The facets labelled `label` ([`label_solids`]).
    fn of_label(casters: &[CasterPolygon<T>], labels: &[u8; MAX_CASTERS], label: u8) -> Option<Self> {
        let mut solid = Self::new();
        for ((corners, n, _), _) in casters.iter().zip(labels.iter()).filter(|(_, &l)| l == label) {
            solid.push(corners.get(..*n).unwrap_or_default())?;
        }
        Some(solid)
    }

    fn facets(&self) -> impl Iterator<Item = &[Vec3<T>]> {
        self.facets.iter().take(self.n_facets).map(|(c, n)| c.get(..*n).unwrap_or_default())
    }

    fn vertices(&self) -> &[Vec3<T>] {
        self.vertices.get(..self.n_vertices).unwrap_or_default()
    }

    fn edges(&self) -> &[(Vec3<T>, Vec3<T>, u8)] {
        self.edges.get(..self.n_edges).unwrap_or_default()
    }

    /// The outward unit normals of the (at most two) facets that have the edge v → w: the
    /// edge is on the solid's outline seen from p exactly where p is outside one of them and
    /// not the other.
    fn edge_normals(&self, v: Vec3<T>, w: Vec3<T>) -> [Option<Vec3<T>>; 2] {
        let centre = self
            .vertices()
            .iter()
            .fold(Vec3::ZERO, |m, &x| m + x)
            .scale(T::ONE / T::from_f64(self.n_vertices.max(1) as f64));
        let mut found = [None, None];
        let mut k = 0usize;
        for facet in self.facets() {
            if !polygon_sides(facet).any(|(x, y)| (x == v && y == w) || (x == w && y == v)) {
                continue;
            }
            let Some((o, n)) = plane_of(facet) else { continue };
            let outward = if n.dot(centre - o) > T::ZERO { -n } else { n };
            if let Some(slot) = found.get_mut(k) {
                *slot = Some(outward);
                k += 1;
            }
        }
        found
    }

    /// Adds a facet (repeated corners dropped) with its vertices and edges; `None` on overflow.
    fn push(&mut self, corners: &[Vec3<T>]) -> Option<()> {
        let mut facet = [Vec3::ZERO; FACET_CORNERS];
        let mut n = 0usize;
        for &c in corners {
            if n > 0 && facet.get(n - 1) == Some(&c) {
                continue;
            }
            *facet.get_mut(n)? = c;
            n += 1;
        }
        if n > 1 && facet.first() == facet.get(n - 1) {
            n -= 1;
        }
        if n < 3 {
            return Some(()); // no area, no shadow
        }
        *self.facets.get_mut(self.n_facets)? = (facet, n);
        self.n_facets += 1;
        for k in 0..n {
            let (&v, &w) = (facet.get(k)?, facet.get((k + 1) % n)?);
            if !self.vertices().contains(&v) {
                *self.vertices.get_mut(self.n_vertices)? = v;
                self.n_vertices += 1;
            }
            match self.edges.iter_mut().take(self.n_edges).find(|e| (e.0 == v && e.1 == w) || (e.0 == w && e.1 == v)) {
                Some(e) => e.2 = e.2.saturating_add(1),
                None => {
                    *self.edges.get_mut(self.n_edges)? = (v, w, 1);
                    self.n_edges += 1;
                }
            }
        }
        Some(())
    }

    /// Where the facets are several: whether they are facets of one convex solid H (the hull of
    /// their vertices) whose shadow their shadows make up for segments from a to b (corners
    /// `ac`, `bc`). Every vertex must lie on one side of every facet's plane (each facet is then
    /// a face of H); and either every edge belongs to two facets (H is closed), or no segment
    /// from a to b crosses the part of H's surface that no facet covers. That part's vertices
    /// are all on edges that belong to one facet (around such a vertex, covered and uncovered
    /// faces meet at one), so it lies in the hull of those vertices, which must be separated
    /// from the hull of a and b ([`separated`]). A segment that meets H's interior crosses its
    /// surface twice, at least once in a facet. A facet the caller left out as unable to cut
    /// (a scene's culled box side) is such an uncovered part.
    fn convex(&self, ac: &[Vec3<T>; 4], bc: &[Vec3<T>; 4], tolerance: T) -> bool {
        for facet in self.facets() {
            let Some((origin, normal)) = plane_of(facet) else { return false };
            let (mut above, mut below) = (false, false);
            for &v in self.vertices() {
                let h = normal.dot(v - origin);
                above |= h > tolerance;
                below |= h < -tolerance;
            }
            if above && below {
                return false;
            }
        }
        if self.edges().iter().any(|e| e.2 > 2) {
            return false;
        }
        let open = || self.edges().iter().filter(|e| e.2 == 1);
        if open().next().is_none() {
            return true;
        }
        let mut rim = [Vec3::ZERO; MAX_VERTICES];
        let mut n = 0usize;
        for &(v, w, _) in open() {
            for x in [v, w] {
                if !rim.get(..n).unwrap_or_default().contains(&x) {
                    let Some(slot) = rim.get_mut(n) else { return false };
                    *slot = x;
                    n += 1;
                }
            }
        }
        let rim = rim.get(..n).unwrap_or_default();
        let edges = open().map(|&(v, w, _)| w - v);
        let normals = open().flat_map(|&(v, w, _)| rim.iter().map(move |&x| (w - v).cross(x - v)));
        separated(rim, edges, normals, ac, bc, tolerance) || self.open_faces_separated(rim, ac, bc, tolerance)
    }

    /// Where the uncovered part is a set of whole faces of H, each bounded by one loop of open
    /// edges (a cabinet whose top a scene culled, standing on the floor without a bottom): each
    /// face separated from the hull of a and b on its own ([`separated`]). A loop bounds such a
    /// face where its vertices lie in one plane that every vertex of H lies on one side of and
    /// no facet lies in; a loop that does not (the band of uncovered sides between a given top
    /// and bottom, whose two loops bound one region) leaves the whole rim to the caller's test.
    fn open_faces_separated(&self, rim: &[Vec3<T>], ac: &[Vec3<T>; 4], bc: &[Vec3<T>; 4], tolerance: T) -> bool {
        let open = || self.edges().iter().filter(|e| e.2 == 1);
        // Loops by relaxation over shared vertices (a few dozen edges).
        let mut label = [0usize; MAX_VERTICES];
        for (k, l) in label.iter_mut().enumerate() {
            *l = k;
        }
        let index = |x: Vec3<T>| rim.iter().position(|&y| y == x);
        let mut changed = true;
        while changed {
            changed = false;
            for &(v, w, _) in open() {
                let (Some(i), Some(j)) = (index(v), index(w)) else { return false };
                let (Some(&li), Some(&lj)) = (label.get(i), label.get(j)) else { return false };
                if li != lj {
                    let low = li.min(lj);
                    for l in label.iter_mut().take(rim.len()) {
                        if *l == li || *l == lj {
                            *l = low;
                        }
                    }
                    changed = true;
                }
            }
        }
        for loop_label in 0..rim.len() {
            let in_loop = |x: &&Vec3<T>| index(**x).and_then(|i| label.get(i)) == Some(&loop_label);
            let points = || rim.iter().filter(in_loop);
            let Some(&first) = points().next() else { continue };
            // The loop's plane from its first point and the two spanning the largest triangle.
            let far = points().fold(first, |m, &x| if (x - first).norm2() > (m - first).norm2() { x } else { m });
            let normal = points().fold(Vec3::ZERO, |m, &x| {
                let n = (far - first).cross(x - first);
                if n.norm2() > m.norm2() {
                    n
                } else {
                    m
                }
            });
            let length = normal.norm();
            if !(length > T::ZERO) {
                return false;
            }
            let height = |x: Vec3<T>| normal.dot(x - first) / length;
            let planar = points().all(|&x| height(x).abs() <= tolerance);
            let (above, below) = self
                .vertices()
                .iter()
                .fold((false, false), |(a, b), &x| (a || height(x) > tolerance, b || height(x) < -tolerance));
            let covered = self.facets().any(|facet| facet.iter().all(|&x| height(x).abs() <= tolerance));
            if !planar || (above && below) || covered {
                return false;
            }
            let loop_points = || points().copied();
            let mut face = [Vec3::ZERO; MAX_VERTICES];
            let mut m = 0usize;
            for (slot, x) in face.iter_mut().zip(loop_points()) {
                *slot = x;
                m += 1;
            }
            let face = face.get(..m).unwrap_or_default();
            let edges =
                open().filter(|e| index(e.0).and_then(|i| label.get(i)) == Some(&loop_label)).map(|&(v, w, _)| w - v);
            if !separated(face, edges, core::iter::once(normal), ac, bc, tolerance) {
                return false;
            }
        }
        true
    }
}

/// Whether an occluder that may cut a segment from the parallelogram x (affine map `outer` over
/// `outer_rect`) to the parallelogram y (corners `other`, inside `bounds`) touches x: a facet
/// within the geometric tolerance of it (a box standing on the floor, its foot on a facet's
/// edge), or a sphere. J(p) is singular along such a contact, and a rule over x converges
/// slowly there. `None` where an occluder that may cut is neither a flat convex polygon nor a
/// sphere ([`Occluder::shadow_casters`]).
pub(super) fn occluders_touch<T: Real, O: Occluder<T> + ?Sized>(
    (outer, outer_rect): MappedRect<T>,
    other: &[Vec3<T>; 4],
    occluders: &O,
    bounds: &Ball<T>,
) -> Option<bool> {
    let xc = map_corners(outer, outer_rect);
    let (from, tolerance) = outer_frame(&xc, other);
    let mut touches = false;
    let supported = occluders.shadow_casters(&from, other, bounds, &mut |caster| match caster {
        Caster::Polygon(corners) => {
            touches |= polygon_sides(corners).any(|(v, w)| segment_to_polygon(v, w, &xc) <= tolerance)
                || polygon_sides(&xc).any(|(v, w)| segment_to_polygon(v, w, corners) <= tolerance);
        }
        Caster::Sphere(ball) => {
            touches |= segment_to_polygon(ball.center, ball.center, &xc) <= ball.radius + tolerance;
        }
    });
    supported.then_some(touches)
}

/// The ball about the outer parallelogram's corners `ac` (from their centre) and the pair's
/// geometric tolerance: `GEOMETRY_TOLERANCE` times the farthest corner of either from that
/// centre.
fn outer_frame<T: Real>(ac: &[Vec3<T>; 4], bc: &[Vec3<T>; 4]) -> (Ball<T>, T) {
    let centre = ac.iter().fold(Vec3::ZERO, |m, &c| m + c).scale(T::ONE / T::from_f64(4.0));
    let radius = ac.iter().fold(T::ZERO, |m, &c| m.max((c - centre).norm()));
    let size = ac.iter().chain(bc.iter()).fold(T::ZERO, |m, &c| m.max((c - centre).norm()));
    (Ball { center: centre, radius }, size * T::GEOMETRY_TOLERANCE)
}

/// The polygons that may cut a pair, their number, and the one sphere that may ([`pair_casters`]).
type PairCasters<T> = ([CasterPolygon<T>; MAX_CASTERS], usize, Option<Ball<T>>);

/// Every polygon that may cut a segment from a (affine map `outer`, corners `ac`) to b
/// (corners `bc`, normal `nb`), with whether a segment from a to b can cross it (else it only
/// closes a solid: [`label_solids`]), their number, and the one sphere that can cut; `None`
/// where an occluder is neither, a polygon has too many corners, there are too many, or two
/// spheres can cut.
fn pair_casters<T: Real, O: Occluder<T> + ?Sized>(
    outer: (Vec3<T>, Vec3<T>, Vec3<T>),
    (ac, bc): (&[Vec3<T>; 4], &[Vec3<T>; 4]),
    nb: Vec3<T>,
    occluders: &O,
    bounds: &Ball<T>,
) -> Option<PairCasters<T>> {
    let (from, tolerance) = outer_frame(ac, bc);
    let (a_hull, b_hull) = (Hull::of_quad(ac), Hull::of_quad(bc));
    let bo = *bc.first()?;
    // A polygon on or behind a's plane or b's (their radiating sides) cannot cut a segment
    // between points of a and b in front of each other: the rest of a box one of whose facets
    // is a or b.
    let na = outer.1.cross(outer.2);
    let behind = |corners: &[Vec3<T>]| {
        let below = |o: Vec3<T>, n: Vec3<T>| corners.iter().all(|&c| n.dot(c - o) <= tolerance * n.norm());
        below(outer.0, na) || below(bo, nb)
    };
    let mut casters = [([Vec3::ZERO; FACET_CORNERS], 0usize, false); MAX_CASTERS];
    let mut n_casters = 0usize;
    let mut sphere = None;
    let mut fits = true;
    let supported = occluders.shadow_casters(&from, bc, bounds, &mut |caster| match caster {
        Caster::Polygon(corners) => match (casters.get_mut(n_casters), corners.len() <= FACET_CORNERS) {
            (Some(slot), true) => {
                for (x, &c) in slot.0.iter_mut().zip(corners) {
                    *x = c;
                }
                let crossed = !behind(corners) && !facet_separated(corners, ac, bc, tolerance);
                *slot = (slot.0, corners.len(), crossed);
                n_casters += 1;
            }
            _ => fits = false,
        },
        Caster::Sphere(ball) => {
            if !apart_from_hull(&Hull::of_ball(&ball), &a_hull, &b_hull, tolerance) {
                fits &= sphere.is_none();
                sphere = Some(ball);
            }
        }
    });
    (supported && fits).then_some((casters, n_casters, sphere))
}

/// One entry of [`BackFacets`]: a facet's first three corners, their number, its unit outward
/// normal, its solid.
type BackFacet<T> = ([Vec3<T>; 3], usize, Vec3<T>, u8);

/// Most facets J may skip ([`BackFacets`]).
const MAX_BACK_FACETS: usize = MAX_CASTERS;

/// The facets of a pair's convex solids (several facets each, [`Solid::convex`]) with their
/// outward normals: from a point p of a outside such a solid, a facet that faces away from p
/// hides nothing the facets facing p do not (a segment from p leaving the solid through it
/// entered through a facet facing p, or through a part of the solid no facet covers, which
/// `Solid::convex` proves no segment from a to b crosses), so J(p) may leave its shadow out
/// (`Inner::point_past_polygons`). Only from p outside the solid: p on its surface (a point of
/// a floor under a box standing on it) is behind every facet but the one it lies in, and
/// the solid hides everything from it. Each entry: the facet's first three corners as the
/// occluder gives them and their number (to recognise it: facets of a box share corners, no
/// two share three), its unit outward normal, and its solid.
pub(super) struct BackFacets<T> {
    facets: [BackFacet<T>; MAX_BACK_FACETS],
    n: usize,
}

impl<T: Real> BackFacets<T> {
    /// No facet skipped.
    pub(super) fn none() -> Self {
        Self { facets: [([Vec3::ZERO; 3], 0, Vec3::ZERO, 0); MAX_BACK_FACETS], n: 0 }
    }

    /// The facets of the convex solids among the occluders that may cut between the flat a
    /// (affine map and rectangle `outer`) and the parallelogram b (`inner`, inside `bounds`);
    /// none where the occluders are not all flat polygons and spheres or do not fit.
    pub(super) fn of_pair<O: Occluder<T> + ?Sized>(
        (outer, outer_rect): MappedRect<T>,
        (inner, rect): MappedRect<T>,
        occluders: &O,
        bounds: &Ball<T>,
    ) -> Self {
        Self::find(outer, outer_rect, inner, rect, occluders, bounds).unwrap_or_else(Self::none)
    }

    fn find<O: Occluder<T> + ?Sized>(
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        outer_rect: ParamRect<T>,
        inner: (Vec3<T>, Vec3<T>, Vec3<T>),
        rect: ParamRect<T>,
        occluders: &O,
        bounds: &Ball<T>,
    ) -> Option<Self> {
        let (ac, bc) = (map_corners(outer, outer_rect), map_corners(inner, rect));
        let (_, tolerance) = outer_frame(&ac, &bc);
        let (casters, n, _) = pair_casters(outer, (&ac, &bc), inner.1.cross(inner.2), occluders, bounds)?;
        let given = casters;
        let mut snapped = casters;
        let snapped = snapped.get_mut(..n).unwrap_or_default();
        snap_corners(snapped, tolerance);
        let (labels, solids) = label_solids(snapped, tolerance)?;
        let mut table = Self::none();
        for label in 1..=solids {
            let solid = Solid::of_label(snapped, &labels, label)?;
            if solid.n_facets < 2 || !solid.convex(&ac, &bc, tolerance) {
                continue;
            }
            let count = T::from_f64(solid.n_vertices.max(1) as f64);
            let centre = solid.vertices().iter().fold(Vec3::ZERO, |m, &v| m + v).scale(T::ONE / count);
            for (((corners, k, _), (own, _, _)), _) in
                snapped.iter().zip(given.iter()).zip(labels.iter()).filter(|(_, &l)| l == label)
            {
                let (o, normal) = plane_of(corners.get(..*k)?)?;
                let outward = if normal.dot(centre - o) > T::ZERO { -normal } else { normal };
                *table.facets.get_mut(table.n)? = ([*own.first()?, *own.get(1)?, *own.get(2)?], *k, outward, label);
                table.n += 1;
            }
        }
        Some(table)
    }

    /// Whether the polygon `corners` is one of the facets, faces away from p by more than
    /// rounding, and p lies outside its solid (in front of one of its facets) by more than
    /// rounding.
    pub(super) fn skips(&self, corners: &[Vec3<T>], p: Vec3<T>) -> bool {
        let Some(first) = corners.get(..3) else { return false };
        let facets = self.facets.get(..self.n).unwrap_or_default();
        let height = |c: &[Vec3<T>; 3], normal: Vec3<T>| {
            let h = normal.dot(p - c[0]);
            let margin = T::GEOMETRY_TOLERANCE * (p - c[0]).norm();
            (h < -margin, h > margin)
        };
        facets.iter().any(|(c, k, normal, solid)| {
            *k == corners.len()
                && c.as_slice() == first
                && height(c, *normal).0
                && facets.iter().any(|(d, _, m, own)| own == solid && height(d, *m).1)
        })
    }
}

/// Moves each corner within `tolerance` of an earlier one (of any polygon) onto it: facets
/// built from an origin and two edge vectors (a box of parallelograms) put a shared corner a
/// few units of rounding apart, and the shared edges that make the facets one solid
/// ([`label_solids`], [`Solid`]) are matched exactly. The events move by rounding; J, which
/// takes the occluders as given, does not.
fn snap_corners<T: Real>(casters: &mut [CasterPolygon<T>], tolerance: T) {
    for i in 0..casters.len() {
        let count = casters.get(i).map_or(0, |c| c.1);
        for k in 0..count {
            let Some(&c) = casters.get(i).and_then(|p| p.0.get(k)) else { continue };
            let earlier = (0..=i).find_map(|j| {
                let (corners, n, _) = casters.get(j)?;
                let end = if j == i { k } else { *n };
                corners.get(..end)?.iter().copied().find(|&d| d != c && (d - c).norm() <= tolerance)
            });
            if let Some(d) = earlier {
                if let Some(slot) = casters.get_mut(i).and_then(|p| p.0.get_mut(k)) {
                    *slot = d;
                }
            }
        }
    }
}

/// Groups the casters into convex solids: each crossed polygon not yet in one starts a solid,
/// which takes in every polygon sharing an edge with it for as long as all their vertices stay
/// on one side of every member's plane (so a cabinet standing in a hole of the floor does not
/// take in the floor, whose facets share its bottom edges). Polygons in no solid cannot cut.
/// The labels (0: none, k: solid k) and the number of solids; `None` for more than
/// [`MAX_SOLIDS`].
fn label_solids<T: Real>(casters: &[CasterPolygon<T>], tolerance: T) -> Option<([u8; MAX_CASTERS], u8)> {
    let corners = |k: usize| casters.get(k).map(|(c, n, _)| c.get(..*n).unwrap_or_default()).unwrap_or_default();
    let share_edge = |i: usize, j: usize| {
        let (p, q) = (corners(i), corners(j));
        let edge = |c: &[Vec3<T>], k: usize| (c.get(k).copied(), c.get((k + 1) % c.len().max(1)).copied());
        (0..p.len()).any(|k| {
            let (v, w) = edge(p, k);
            v != w && (0..q.len()).any(|m| edge(q, m) == (w, v) || edge(q, m) == (v, w))
        })
    };
    // The sides (1: above, 2: below) of polygon k's plane that the points lie on.
    let sides = |k: usize, points: &mut dyn Iterator<Item = Vec3<T>>| {
        let Some((o, n)) = plane_of(corners(k)) else { return 3u8 };
        points.fold(0u8, |f, v| {
            let h = n.dot(v - o);
            f | u8::from(h > tolerance) | (u8::from(h < -tolerance) << 1)
        })
    };
    let n = casters.len().min(MAX_CASTERS);
    let mut label = [0u8; MAX_CASTERS];
    // The sides of each member's plane its solid's vertices lie on.
    let mut side = [0u8; MAX_CASTERS];
    let mut count = 0u8;
    for seed in 0..n {
        if !casters.get(seed).is_some_and(|c| c.2) || label.get(seed) != Some(&0) {
            continue;
        }
        count += 1;
        if usize::from(count) > MAX_SOLIDS {
            return None;
        }
        let (Some(l), Some(f)) = (label.get_mut(seed), side.get_mut(seed)) else { return None };
        *l = count;
        *f = 0;
        // The crossed polygons first: an uncrossed neighbour taken in early (the floor around
        // a cabinet's foot) could keep out the solid's own facets.
        for crossed_only in [true, false] {
            let mut grew = true;
            while grew {
                grew = false;
                for j in 0..n {
                    let candidate = label.get(j) == Some(&0) && (!crossed_only || casters.get(j).is_some_and(|c| c.2));
                    if !candidate || !(0..n).any(|i| label.get(i) == Some(&count) && share_edge(i, j)) {
                        continue;
                    }
                    let members = || (0..n).filter(|&i| label.get(i) == Some(&count));
                    let own =
                        sides(j, &mut members().chain(core::iter::once(j)).flat_map(|i| corners(i).iter().copied()));
                    let joins = own != 3
                        && members()
                            .all(|i| side.get(i).is_some_and(|&f| f | sides(i, &mut corners(j).iter().copied()) != 3));
                    if joins {
                        for i in members() {
                            if let Some(f) = side.get_mut(i) {
                                *f |= sides(i, &mut corners(j).iter().copied());
                            }
                        }
                        let (Some(l), Some(f)) = (label.get_mut(j), side.get_mut(j)) else { return None };
                        *l = count;
                        *f = own;
                        grew = true;
                    }
                }
            }
        }
    }
    Some((label, count))
}

/// A convex set for the separating-axis tests between occluders: the hull of `points` grown by
/// `radius` (a solid's vertices with radius zero, a sphere's centre with its radius), with its
/// edges and facet normals as candidate axes.
struct Hull<T> {
    points: [Vec3<T>; MAX_VERTICES],
    n_points: usize,
    radius: T,
    edges: [(Vec3<T>, Vec3<T>); MAX_EDGES],
    n_edges: usize,
    normals: [Vec3<T>; MAX_FACETS],
    n_normals: usize,
}

impl<T: Real> Hull<T> {
    fn empty() -> Self {
        Self {
            points: [Vec3::ZERO; MAX_VERTICES],
            n_points: 0,
            radius: T::ZERO,
            edges: [(Vec3::ZERO, Vec3::ZERO); MAX_EDGES],
            n_edges: 0,
            normals: [Vec3::ZERO; MAX_FACETS],
            n_normals: 0,
        }
    }

    /// The solid's hull; `None` on overflow.
    fn of_solid(solid: &Solid<T>) -> Option<Self> {
        let mut hull = Self::empty();
        for (slot, &v) in hull.points.iter_mut().zip(solid.vertices()) {
            *slot = v;
        }
        hull.n_points = solid.n_vertices.min(MAX_VERTICES);
        for (slot, &(v, w, _)) in hull.edges.iter_mut().zip(solid.edges()) {
            *slot = (v, w);
        }
        hull.n_edges = solid.n_edges.min(MAX_EDGES);
        for facet in solid.facets() {
            *hull.normals.get_mut(hull.n_normals)? = plane_of(facet)?.1;
            hull.n_normals += 1;
        }
        Some(hull)
    }

    fn of_ball(ball: &Ball<T>) -> Self {
        let mut hull = Self::empty();
        if let Some(slot) = hull.points.first_mut() {
            *slot = ball.center;
            hull.n_points = 1;
        }
        hull.radius = ball.radius;
        hull
    }

    /// A parallelogram's hull (its corners in order).
    fn of_quad(corners: &[Vec3<T>; 4]) -> Self {
        let mut hull = Self::empty();
        for (k, &c) in corners.iter().enumerate() {
            if let (Some(point), Some(edge), Some(&next)) =
                (hull.points.get_mut(k), hull.edges.get_mut(k), corners.get((k + 1) % 4))
            {
                (*point, *edge) = (c, (c, next));
                hull.n_points += 1;
                hull.n_edges += 1;
            }
        }
        if let (Some((_, n)), Some(slot)) = (plane_of(corners), hull.normals.first_mut()) {
            *slot = n;
            hull.n_normals = 1;
        }
        hull
    }

    fn points(&self) -> &[Vec3<T>] {
        self.points.get(..self.n_points).unwrap_or_default()
    }

    fn edges(&self) -> &[(Vec3<T>, Vec3<T>)] {
        self.edges.get(..self.n_edges).unwrap_or_default()
    }

    fn normals(&self) -> &[Vec3<T>] {
        self.normals.get(..self.n_normals).unwrap_or_default()
    }

    fn centre(&self) -> Vec3<T> {
        let sum = self.points().iter().fold(Vec3::ZERO, |m, &v| m + v);
        sum.scale(T::ONE / T::from_f64(self.n_points.max(1) as f64))
    }

    /// The projection onto `axis`.
    fn range(&self, axis: Vec3<T>) -> (T, T) {
        let grow = self.radius * axis.norm();
        let (lo, hi) = self.points().iter().fold((T::MAX, -T::MAX), |(lo, hi), &x| {
            let d = axis.dot(x);
            (lo.min(d), hi.max(d))
        });
        (lo - grow, hi + grow)
    }
}

/// Whether `y` and the hull of `p` ∪ `x` are apart by more than `tolerance` along one of the
/// candidate axes: the coordinate axes, the directions between their centres, their facet
/// normals, the planes through an edge of `p` and a point of `x` (tangent to `x` for a ball)
/// or an edge of `x` and a point of `p` (the faces of that hull), and the cross products of
/// `y`'s edges with the others'. An axis missed keeps the two together, which declines the
/// events, never costs accuracy.
fn apart_from_hull<T: Real>(y: &Hull<T>, p: &Hull<T>, x: &Hull<T>, tolerance: T) -> bool {
    let test = |axis: Vec3<T>| {
        let length = axis.norm();
        if !(length > T::ZERO) {
            return false;
        }
        let (y0, y1) = y.range(axis);
        let ((p0, p1), (x0, x1)) = (p.range(axis), x.range(axis));
        let slack = tolerance * length;
        y1 < p0.min(x0) - slack || p1.max(x1) < y0 - slack
    };
    let (o, i) = (T::ZERO, T::ONE);
    let coordinate = [vec3(i, o, o), vec3(o, i, o), vec3(o, o, i)];
    if coordinate.into_iter().any(test) || test(y.centre() - x.centre()) || test(y.centre() - p.centre()) {
        return true;
    }
    if y.normals().iter().chain(x.normals()).chain(p.normals()).any(|&n| test(n)) {
        return true;
    }
    if y.radius > T::ZERO && x.points().iter().chain(p.points()).any(|&q| test(y.centre() - q)) {
        return true;
    }
    for &(v, w) in p.edges() {
        for &q in x.points() {
            let found = if x.radius > T::ZERO {
                tangent_normals(v, w, q, x.radius).into_iter().flatten().any(test)
            } else {
                test((w - v).cross(q - v))
            };
            if found {
                return true;
            }
        }
    }
    if x.edges().iter().any(|&(v, w)| p.points().iter().any(|&c| test((w - v).cross(c - v)))) {
        return true;
    }
    y.edges().iter().any(|&(v, w)| x.edges().iter().chain(p.edges()).any(|&(e0, e1)| test((w - v).cross(e1 - e0))))
}

/// The normals of the two planes through the line v → w tangent to the ball (c, r); none where
/// the line meets the ball.
fn tangent_normals<T: Real>(v: Vec3<T>, w: Vec3<T>, c: Vec3<T>, r: T) -> [Option<Vec3<T>>; 2] {
    let d = w - v;
    let (dd, m) = (d.norm2(), c - v);
    if !(dd > T::ZERO) {
        return [None, None];
    }
    let u = m - d.scale(d.dot(m) / dd);
    let h = u.norm();
    if !(h > r) {
        return [None, None];
    }
    let e1 = u.scale(T::ONE / h);
    let e2 = d.cross(e1).scale(T::ONE / dd.sqrt());
    let sin = r / h;
    let cos = (T::ONE - sin * sin).max(T::ZERO).sqrt();
    [Some(e1.scale(sin) + e2.scale(cos)), Some(e1.scale(sin) - e2.scale(cos))]
}

/// Whether no segment from a (corners `a`) to b (`b`) can meet both `x` and `y`: a segment
/// meeting x before y meets y within the hull of x and b, one meeting y first within the hull
/// of a and x; so y apart from both hulls suffices, as does x apart from the hulls of a and y
/// and of y and b. Then the two shadows never meet on b, and J's structure changes only at
/// each one's own events.
fn shadows_apart<T: Real>(x: &Hull<T>, y: &Hull<T>, a: &Hull<T>, b: &Hull<T>, tolerance: T) -> bool {
    (apart_from_hull(y, a, x, tolerance) && apart_from_hull(y, b, x, tolerance))
        || (apart_from_hull(x, a, y, tolerance) && apart_from_hull(x, b, y, tolerance))
}

/// A condition on p for an event to be real: g₀·(p − o) ≥ 0, or, with g₁,
/// (g₀·(p − o))·(g₁·(p − o)) ≥ 0 (a double wedge about a line through o).
type Condition<T> = (Vec3<T>, Vec3<T>, Option<Vec3<T>>);

/// The condition that the edge v → w of `solid` is on its outline seen from p (p outside one of
/// its two facets and not the other); none for an edge of one facet.
fn outline<T: Real>(solid: &Solid<T>, v: Vec3<T>, w: Vec3<T>) -> Option<Condition<T>> {
    match solid.edge_normals(v, w) {
        [Some(n1), Some(n2)] => Some((v, n1, Some(-n2))),
        _ => None,
    }
}

/// Whether x lies on the flat patch (affine map `outer` over `rect`) to within `tolerance`
/// of its plane, its parameters inside the rectangle.
fn on_patch<T: Real>((o, et, es): (Vec3<T>, Vec3<T>, Vec3<T>), rect: ParamRect<T>, x: Vec3<T>, tolerance: T) -> bool {
    let n = et.cross(es);
    let length = n.norm();
    if !(length > T::ZERO) || !(n.dot(x - o).abs() <= tolerance * length) {
        return false;
    }
    let (g11, g12, g22) = (et.dot(et), et.dot(es), es.dot(es));
    let w = x - o;
    let (bt, bs) = (et.dot(w), es.dot(w));
    let det = g11 * g22 - g12 * g12;
    let (t, s) = ((g22 * bt - g12 * bs) / det, (g11 * bs - g12 * bt) / det);
    t >= rect.t0.min(rect.t1) && t <= rect.t0.max(rect.t1) && s >= rect.s0.min(rect.s1) && s <= rect.s0.max(rect.s1)
}

/// Where the segments [w0, w1] and [c, d], both in the plane with unit normal `unit`, cross
/// inside both (their ends excluded: a crossing at an end is a vertex or a corner, whose
/// events are placed already); `None` where they do not or are parallel.
fn segments_cross<T: Real>(
    w0: Vec3<T>,
    w1: Vec3<T>,
    c: Vec3<T>,
    d: Vec3<T>,
    unit: Vec3<T>,
    tolerance: T,
) -> Option<Vec3<T>> {
    let (r, q) = (w1 - w0, d - c);
    let denom = r.cross(q).dot(unit);
    if !(denom.abs() > T::GEOMETRY_TOLERANCE * r.norm() * q.norm()) {
        return None;
    }
    let (t, u) = ((c - w0).cross(q).dot(unit) / denom, (c - w0).cross(r).dot(unit) / denom);
    let (mt, mu) = (tolerance / r.norm(), tolerance / q.norm());
    (t > mt && t < T::ONE - mt && u > mu && u < T::ONE - mu).then(|| w0 + r.scale(t))
}

/// A segment by its two ends.
type Segment<T> = (Vec3<T>, Vec3<T>);

/// Samples along b's edge where [`real_arc`] looks for the part of a three-line quadric that
/// is an event.
const ARC_SAMPLES: usize = 48;

/// Where on a a three-line quadric ([`three_lines`]) is an event.
enum Arc<T> {
    /// Nowhere on the samples.
    Never,
    /// Where this line in a's parameters is non-negative.
    Within([T; 3]),
    /// Anywhere it can be (the samples could not bound it).
    Whole,
}

/// The part of the quadric of lines meeting the segments `i`, `j` (edges of two solids, on
/// their outlines where `outlines` hold) and `k` (an edge of b) that is an event on a (affine
/// map `outer` over `rect`, widened by half on each side): each point x of k has one line
/// through it meeting the lines of i and j, which meets a's plane in one point p(x), so the
/// conic on a is p over k's line. Along k, at [`ARC_SAMPLES`] points, the sample is real
/// where the line meets i and j inside the segments, between p and x, p lies on the widened
/// a, and both edges are on their solids' outlines seen from p. `Never` where no sample is;
/// else the chord through the ends of the real samples (widened by a step on each side,
/// where the conic's arc between them lies on the side of the middle sample), or `Whole`
/// where that chord is degenerate or the arc passes through infinity. A part shorter than a
/// step can be missed: its event is then not placed, which costs convergence there, never a
/// bound (the tolerance mode's orders show it).
fn real_arc<T: Real>(
    outer: (Vec3<T>, Vec3<T>, Vec3<T>),
    rect: ParamRect<T>,
    ((i0, i1), (j0, j1), (k0, k1)): (Segment<T>, Segment<T>, Segment<T>),
    (outline_i, outline_j): (Option<Condition<T>>, Option<Condition<T>>),
    tolerance: T,
) -> Arc<T> {
    let (o, et, es) = outer;
    let na = et.cross(es);
    let (di, dj, dk) = (i1 - i0, j1 - j0, k1 - k0);
    let (g11, g12, g22) = (et.dot(et), et.dot(es), es.dot(es));
    let det = g11 * g22 - g12 * g12;
    if !(det > T::ZERO) {
        return Arc::Whole;
    }
    let (dt, ds) = ((rect.t1 - rect.t0).abs(), (rect.s1 - rect.s0).abs());
    let (tlo, thi) = (rect.t0.min(rect.t1) - dt * T::HALF, rect.t0.max(rect.t1) + dt * T::HALF);
    let (slo, shi) = (rect.s0.min(rect.s1) - ds * T::HALF, rect.s0.max(rect.s1) + ds * T::HALF);
    let holds = |c: Option<Condition<T>>, p: Vec3<T>| {
        c.is_none_or(|(co, g0, g1)| {
            let (f0, f1) = (g0.dot(p - co), g1.map_or(T::ONE, |g| g.dot(p - co)));
            f0 * f1 >= -(tolerance * tolerance) * g0.norm() * g1.map_or(T::ONE, |g| g.norm())
        })
    };
    // The sample at u along k: p's parameters (t, s), whether it is real, and the side of a's
    // plane the line runs towards from x; `None` where the line is undefined or parallel to
    // a's plane.
    let sample = |u: T| -> Option<((T, T), bool, bool)> {
        let x = k0 + dk.scale(u);
        let (ni, nj) = (di.cross(x - i0), dj.cross(x - j0));
        let dir = ni.cross(nj);
        let along = na.dot(dir);
        if !(along.abs() > T::GEOMETRY_TOLERANCE * na.norm() * dir.norm()) {
            return None;
        }
        let lambda = na.dot(o - x) / along;
        let p = x + dir.scale(lambda);
        let w = p - o;
        let (bt, bs) = (et.dot(w), es.dot(w));
        let (t, s) = ((g22 * bt - g12 * bs) / det, (g11 * bs - g12 * bt) / det);
        // Where the line meets segment (e0, d): its parameter along the segment and along the line.
        let hit = |e0: Vec3<T>, d: Vec3<T>| {
            let c = d.cross(dir);
            let cc = c.norm2();
            (cc > T::ZERO).then(|| ((x - e0).cross(dir).dot(c) / cc, (x - e0).cross(d).dot(c) / cc))
        };
        let between = |h: Option<(T, T)>| {
            h.is_some_and(|(nu, mu)| {
                let m = T::GEOMETRY_TOLERANCE.sqrt();
                nu >= -m && nu <= T::ONE + m && mu * lambda >= T::ZERO && mu.abs() <= lambda.abs()
            })
        };
        let real = between(hit(i0, di))
            && between(hit(j0, dj))
            && t >= tlo
            && t <= thi
            && s >= slo
            && s <= shi
            && holds(outline_i, p)
            && holds(outline_j, p);
        (t.is_finite() && s.is_finite()).then_some(((t, s), real, along > T::ZERO))
    };
    let step = T::ONE / T::from_usize(ARC_SAMPLES - 1);
    let at = |m: T| sample(m * step);
    let (mut first, mut last) = (None, None);
    // Each sample's side of a's plane, for the check below.
    let mut sides = [false; ARC_SAMPLES];
    for (m, slot) in sides.iter_mut().enumerate() {
        let Some((_, real, side)) = at(T::from_usize(m)) else { return Arc::Whole };
        *slot = side;
        if real {
            first = first.or(Some(m));
            last = Some(m);
        }
    }
    let (Some(first), Some(last)) = (first, last) else { return Arc::Never };
    // The arc from a step before the first real sample to a step past the last, through the
    // one halfway; where the line turns to the other side of a's plane on it, p passes
    // through infinity and no chord bounds it.
    let (lo, hi) = (T::from_usize(first) - T::ONE, T::from_usize(last) + T::ONE);
    let (Some((a, _, towards)), Some((b, _, beyond)), Some((middle, _, _))) = (at(lo), at(hi), at((lo + hi) * T::HALF))
    else {
        return Arc::Whole;
    };
    let within = sides.get(first.saturating_sub(1)..=last.min(ARC_SAMPLES - 1)).unwrap_or_default();
    if beyond != towards || within.iter().any(|&side| side != towards) {
        return Arc::Whole;
    }
    let (vt, vs) = (b.0 - a.0, b.1 - a.1);
    let side = |(t, s): (T, T)| vt * (s - a.1) - vs * (t - a.0);
    let size = (vt * vt + vs * vs).sqrt();
    let bulge = side(middle);
    if !(size > T::ZERO) || !(bulge.abs() > T::GEOMETRY_TOLERANCE * size * (dt + ds)) {
        return Arc::Whole;
    }
    let sign = if bulge > T::ZERO { T::ONE } else { -T::ONE };
    // side(t, s) = vt·s − vs·t − (vt·a.1 − vs·a.0), non-negative on the middle's side.
    Arc::Within([-vs * sign, vt * sign, (vs * a.0 - vt * a.1) * sign])
}

/// The quadric of the points on a line that meets the three lines through the segments `i`,
/// `j` and `k` (not as segments): p is on one exactly where the planes through p and each line
/// share a line, i.e. where their normals dᵢ × (p − i₀), … are linearly dependent. Their
/// determinant's cubic part det[dᵢ × v, dⱼ × v, dₖ × v] vanishes (three vectors normal to v),
/// so with v = p − i₀ it is the quadric
/// det[dᵢ×v, mⱼ, dₖ×v] + det[dᵢ×v, dⱼ×v, mₖ] + det[dᵢ×v, mⱼ, mₖ], mⱼ = dⱼ × (i₀ − j₀),
/// mₖ = dₖ × (i₀ − k₀), whose coefficients are read off by polarisation. `None` where it
/// vanishes identically to rounding (three lines in one plane, or through one point: every
/// line there meets all three, and the events are the planes through a vertex and an edge).
fn three_lines<T: Real>(
    (i0, i1): (Vec3<T>, Vec3<T>),
    (j0, j1): (Vec3<T>, Vec3<T>),
    (k0, k1): (Vec3<T>, Vec3<T>),
) -> Option<Quadric<T>> {
    let (di, dj, dk) = (i1 - i0, j1 - j0, k1 - k0);
    let (mj, mk) = (dj.cross(i0 - j0), dk.cross(i0 - k0));
    let det = |a: Vec3<T>, b: Vec3<T>, c: Vec3<T>| a.dot(b.cross(c));
    let q = |v: Vec3<T>| det(di.cross(v), mj, dk.cross(v)) + det(di.cross(v), dj.cross(v), mk);
    let l = |v: Vec3<T>| det(di.cross(v), mj, mk);
    let (o, e) = (T::ZERO, T::ONE);
    let (ex, ey, ez) = (vec3(e, o, o), vec3(o, e, o), vec3(o, o, e));
    let (xx, yy, zz) = (q(ex), q(ey), q(ez));
    let m = [
        xx,
        yy,
        zz,
        (q(ex + ey) - xx - yy) * T::HALF,
        (q(ex + ez) - xx - zz) * T::HALF,
        (q(ey + ez) - yy - zz) * T::HALF,
    ];
    let g = vec3(l(ex), l(ey), l(ez));
    let length = di.norm() + dj.norm() + dk.norm() + (i0 - j0).norm() + (i0 - k0).norm();
    let size = m.iter().fold(T::ZERO, |s, x| s.max(x.abs())) * length * length + g.norm() * length;
    let scale = di.norm() * dj.norm() * dk.norm() * length * length * length;
    (size > T::GEOMETRY_TOLERANCE * scale).then_some(Quadric { origin: i0, m, g, c: T::ZERO, guard: None })
}

/// Whether no point of a (corners `ac`) lies on a line from a point of the segment `from`
/// through one of `through`, beyond it: such points are (1 − λ)·x + λ·y with λ ≥ 1, and at
/// most `reach` (the farthest of a from b) over the segments' distance, so within the hull of
/// `through` and the four points at that λ, which a separating axis shows apart from a. Axes
/// are tried from the likeliest (a's normal) on; one missed keeps the event (a break more).
fn fan_misses<T: Real>(
    (b0, b1): (Vec3<T>, Vec3<T>),
    (e0, e1): (Vec3<T>, Vec3<T>),
    ac: &[Vec3<T>; 4],
    reach: T,
    tolerance: T,
) -> bool {
    let gap = segment_to_segment(b0, b1, e0, e1);
    if !(gap > tolerance) {
        return false;
    }
    let lambda = (reach / gap).max(T::ONE);
    let far = |b: Vec3<T>, e: Vec3<T>| b + (e - b).scale(lambda);
    let points = [e0, e1, far(b0, e0), far(b0, e1), far(b1, e0), far(b1, e1)];
    let apart = |axis: Vec3<T>| {
        let length = axis.norm();
        if !(length > T::ZERO) {
            return false;
        }
        let range = |ps: &[Vec3<T>]| {
            ps.iter().fold((T::MAX, -T::MAX), |(lo, hi), &x| (lo.min(axis.dot(x)), hi.max(axis.dot(x))))
        };
        let ((p0, p1), (a0, a1)) = (range(&points), range(ac));
        let slack = tolerance * length;
        p1 < a0 - slack || a1 < p0 - slack
    };
    let (Some(&c0), Some(&c1), Some(&c3)) = (ac.first(), ac.get(1), ac.get(3)) else { return false };
    let a_edges = [c1 - c0, c3 - c0];
    if apart(a_edges[0].cross(a_edges[1])) {
        return true;
    }
    let (de, db) = (e1 - e0, b1 - b0);
    if apart(de.cross(db)) {
        return true;
    }
    let connectors = points.iter().skip(2).flat_map(|&f| [f - e0, f - e1]);
    let hull_edges = || [de, db].into_iter().chain(connectors.clone());
    hull_edges().any(|h| hull_edges().chain(a_edges).any(|g| apart(h.cross(g))))
}

/// The distance from the segment [c0, c1] to the convex polygon (zero where they meet).
fn segment_to_polygon<T: Real>(c0: Vec3<T>, c1: Vec3<T>, polygon: &[Vec3<T>]) -> T {
    let Some((o, n)) = plane_of(polygon) else { return T::ZERO };
    let inside = |x: Vec3<T>| polygon_sides(polygon).all(|(v, w)| (w - v).cross(x - v).dot(n) >= T::ZERO);
    let (h0, h1) = (n.dot(c0 - o), n.dot(c1 - o));
    if h0 * h1 <= T::ZERO && h0 != h1 && inside(c0 + (c1 - c0).scale(h0 / (h0 - h1))) {
        return T::ZERO;
    }
    let to_point = |x: Vec3<T>| {
        let h = n.dot(x - o);
        if inside(x - n.scale(h)) {
            h.abs()
        } else {
            polygon_sides(polygon).fold(T::MAX, |m, (v, w)| m.min(segment_to_segment(x, x, v, w)))
        }
    };
    let edges = polygon_sides(polygon).fold(T::MAX, |m, (v, w)| m.min(segment_to_segment(c0, c1, v, w)));
    to_point(c0).min(to_point(c1)).min(edges)
}

/// The distance between the segments [p0, p1] and [q0, q1] (either may be a point): the closest
/// pair of the lines clamped to the segments, and each end against the other segment.
fn segment_to_segment<T: Real>(p0: Vec3<T>, p1: Vec3<T>, q0: Vec3<T>, q1: Vec3<T>) -> T {
    let to_segment = |x: Vec3<T>, a: Vec3<T>, b: Vec3<T>| {
        let d = b - a;
        let dd = d.norm2();
        let tau = if dd > T::ZERO { ((x - a).dot(d) / dd).max(T::ZERO).min(T::ONE) } else { T::ZERO };
        (x - a - d.scale(tau)).norm()
    };
    let ends =
        to_segment(p0, q0, q1).min(to_segment(p1, q0, q1)).min(to_segment(q0, p0, p1)).min(to_segment(q1, p0, p1));
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, b, c, f) = (d1.norm2(), d2.norm2(), d1.dot(d2), d1.dot(r), d2.dot(r));
    let denom = a * e - b * b;
    if !(denom > T::EPSILON * a * e) {
        return ends;
    }
    let s = ((b * f - c * e) / denom).max(T::ZERO).min(T::ONE);
    let t = ((b * s + f) / e).max(T::ZERO).min(T::ONE);
    ends.min((p0 + d1.scale(s) - q0 - d2.scale(t)).norm())
}

/// The sides of a closed polygon as pairs of corners.
fn polygon_sides<T: Real>(p: &[Vec3<T>]) -> impl Iterator<Item = (Vec3<T>, Vec3<T>)> + '_ {
    let n = p.len();
    (0..n).filter_map(move |k| Some((*p.get(k)?, *p.get((k + 1) % n)?)))
}

/// The edge vectors of a closed polygon.
fn polygon_edges<T: Real>(p: &[Vec3<T>]) -> impl Iterator<Item = Vec3<T>> + '_ {
    polygon_sides(p).map(|(v, w)| w - v)
}

/// A point of the facet and its unit normal (Newell's sum, robust to a repeated corner).
fn plane_of<T: Real>(facet: &[Vec3<T>]) -> Option<(Vec3<T>, Vec3<T>)> {
    let first = *facet.first()?;
    let mut normal = Vec3::ZERO;
    for (k, &v) in facet.iter().enumerate() {
        let w = *facet.get((k + 1) % facet.len())?;
        normal = normal + (v - first).cross(w - first);
    }
    let length = normal.norm();
    (length > T::ZERO).then(|| (first, normal.scale(T::ONE / length)))
}

/// Whether the convex hull of `points` (with edge directions `edges` and face normals
/// `normals` as candidate axes: a facet's sides and normal) and the hull of a's and b's corners
/// are separated by a plane (touching allowed): then no segment from a to b crosses the former's
/// interior. The axes tried are the given normals, a's and b's normals, the cross products of
/// the given edges with the pair's candidate edges (a's, b's and those between them), and of
/// a's and b's edges with the edges between them (the pair's hull's side faces); a separation
/// missed keeps the polygons, which costs events or declines them, never accuracy.
fn separated<T: Real>(
    points: &[Vec3<T>],
    edges: impl Iterator<Item = Vec3<T>>,
    normals: impl Iterator<Item = Vec3<T>>,
    a: &[Vec3<T>; 4],
    b: &[Vec3<T>; 4],
    tolerance: T,
) -> bool {
    let hull = || a.iter().chain(b.iter()).copied();
    let apart = |axis: Vec3<T>| {
        let length = axis.norm();
        if !(length > T::ZERO) {
            return false;
        }
        let range = |points: &mut dyn Iterator<Item = Vec3<T>>| {
            points.fold((T::MAX, -T::MAX), |(lo, hi), x| {
                let d = axis.dot(x);
                (lo.min(d), hi.max(d))
            })
        };
        let (f0, f1) = range(&mut points.iter().copied());
        let (h0, h1) = range(&mut hull());
        let slack = tolerance * length;
        f1 <= h0 + slack || h1 <= f0 + slack
    };
    let normal = |p: &[Vec3<T>]| plane_of(p).map_or(Vec3::ZERO, |(_, n)| n);
    let mut normals = normals;
    if apart(normal(a)) || apart(normal(b)) || normals.any(apart) {
        return true;
    }
    let links = || a.iter().flat_map(|&x| b.iter().map(move |&y| y - x));
    let hull_edges = || polygon_edges(a).chain(polygon_edges(b)).chain(links());
    let mut edges = edges;
    if edges.any(|e| hull_edges().any(|h| apart(e.cross(h)))) {
        return true;
    }
    polygon_edges(a).chain(polygon_edges(b)).any(|e| links().any(|l| apart(e.cross(l))))
}

/// [`separated`] for one convex polygon.
fn facet_separated<T: Real>(facet: &[Vec3<T>], a: &[Vec3<T>; 4], b: &[Vec3<T>; 4], tolerance: T) -> bool {
    let normal = plane_of(facet).map_or(Vec3::ZERO, |(_, n)| n);
    separated(facet, polygon_edges(facet), core::iter::once(normal), a, b, tolerance)
}

impl<T: Real> PolygonEvents<T> {
    /// The events of outer a (affine map `outer` over `outer_rect`) against the parallelogram b
    /// (affine map `inner` over `rect`, inside `bounds`) across `occluders` (module docs);
    /// `None` where an occluder that may cut is neither a flat convex polygon nor one sphere,
    /// the polygons are not the facets of at most [`MAX_SOLIDS`] convex solids, a solid's and the
    /// sphere's shadows, or three solids' that each meet the others', may meet on b, a solid
    /// whose shadow may meet another's reaches behind b's plane, a sphere is the only occluder near
    /// (`Events::new` places it), or the curves overflow [`MAX_POLYGON_EVENT_CURVES`]. Where b
    /// straddles a's plane, the corners and edges are those of its part in front
    /// ([`front_part`]). The lines are kinks between analytic sides, and the
    /// outer rule takes them as plain breaks, except where a comes very near b (`near`: a cut
    /// into cells graded towards b): there the lines run into the contact, where J is singular,
    /// and the rule is graded towards them (perpendicular squares sharing an edge, a screen on
    /// it: 3e-8 at order 10 graded, 8e-6 not). `clear_of` (c₀, c₁, d): `None` also where a
    /// facet of a solid, or the sphere, comes closer than d to the segment [c₀, c₁].
    pub(super) fn polygons<O: Occluder<T> + ?Sized>(
        (outer, outer_rect): MappedRect<T>,
        (inner, rect): MappedRect<T>,
        occluders: &O,
        bounds: &Ball<T>,
        near: bool,
        clear_of: Option<(Vec3<T>, Vec3<T>, T)>,
    ) -> Option<Self> {
        let (bo, bt, bs) = inner;
        let (ac, bc) = (map_corners(outer, outer_rect), map_corners(inner, rect));
        // The events are those of the part of b in front of a's plane; the tests of which
        // occluders may cut keep the whole of b (more segments: never fewer events).
        let (front, n_front) = front_part(outer, bo, &bc);
        let front = front.get(..n_front).unwrap_or_default();
        let (_, tolerance) = outer_frame(&ac, &bc);
        let (a_hull, b_hull) = (Hull::of_quad(&ac), Hull::of_quad(&bc));
        let nb = bt.cross(bs);
        let (mut casters, n_casters, sphere) = pair_casters(outer, (&ac, &bc), nb, occluders, bounds)?;
        let casters = casters.get_mut(..n_casters).unwrap_or_default();
        snap_corners(casters, tolerance);
        let casters = &*casters;
        let (labels, solids) = label_solids(casters, tolerance)?;
        if n_casters == 0 && sphere.is_some() {
            // A sphere alone, with no polygon near: `Events::new` places its quadrics (for a
            // touching pair, the pair takes its other route).
            return None;
        }
        let mut events = Self::empty(near, Some(outer_rect));
        let mut room = true;
        let unit_b = nb.scale(T::ONE / nb.norm());
        // Above b's plane by more than rounding: a vertex there has a shadow that moves with p.
        let above_b = |x: Vec3<T>| unit_b.dot(x - bo) > tolerance;
        // The plane through x spanned by u and w, where the ray from p through x meets the
        // segment between x + u and x + w (their double wedge) and `more` holds; none where u
        // and w are parallel to rounding (a vertex on b's edge line, an edge through b's
        // corner).
        let mut wedge_plane = |events: &mut Self, x: Vec3<T>, u: Vec3<T>, w: Vec3<T>, more: Option<Condition<T>>| {
            let n = u.cross(w);
            if n.norm() > T::GEOMETRY_TOLERANCE * u.norm() * w.norm() {
                let conditions = [Some((x, n.cross(u), Some(w.cross(n)))), more];
                room &= events.push_trimmed(outer, outer_rect, (x, n), &conditions, tolerance);
            }
        };
        let mut planes = true;
        let mut hulls: [Option<Hull<T>>; MAX_SOLIDS + 1] = core::array::from_fn(|_| None);
        for (label, hull) in (1..=solids).zip(hulls.iter_mut()) {
            let solid = Solid::of_label(casters, &labels, label)?;
            if solid.n_facets > 1 && !solid.convex(&ac, &bc, tolerance) {
                return None;
            }
            if let Some((c0, c1, clearance)) = clear_of {
                if solid.facets().any(|facet| !(segment_to_polygon(c0, c1, facet) >= clearance)) {
                    return None;
                }
            }
            for &v in solid.vertices().iter().filter(|&&v| above_b(v)) {
                for k in 0..front.len() {
                    let (Some(&c), Some(&d)) = (front.get(k), front.get((k + 1) % front.len())) else {
                        return None;
                    };
                    // Only p above v: the part of a solid beyond p's height casts no shadow.
                    wedge_plane(&mut events, v, c - v, d - v, Some((v, unit_b, None)));
                }
            }
            for &(v, w, _) in solid.edges().iter().filter(|e| above_b(e.0) || above_b(e.1)) {
                for &c in front {
                    // Only where the edge is on the solid's outline seen from p.
                    wedge_plane(&mut events, c, v - c, w - c, outline(&solid, v, w));
                }
            }
            // A vertex on a's plane inside a (a box standing on the floor a): J is singular
            // along the box's footprint, as along a side a facet stands on.
            if solid.vertices().iter().any(|&v| on_patch(outer, outer_rect, v, tolerance)) {
                events.touch_inside();
            }
            for facet in solid.facets() {
                let (origin, normal) = plane_of(facet)?;
                planes &= events.push_line(outer, outer_rect, Quadric::plane(origin, normal));
                // A facet standing on a side of a (a cabinet's side on the floor's edge):
                // J is singular along that side, and the rule is graded towards it.
                for (k, (i, j)) in [(3, 0), (1, 2), (0, 1), (2, 3)].into_iter().enumerate() {
                    if let (Some(&c0), Some(&c1)) = (ac.get(i), ac.get(j)) {
                        if segment_to_polygon(c0, c1, facet) <= tolerance {
                            events.grade_side(k);
                        }
                    }
                }
            }
            *hull = Some(Hull::of_solid(&solid)?);
        }
        if let Some(ball) = sphere {
            if let Some((c0, c1, clearance)) = clear_of {
                if !(segment_to_segment(c0, c1, ball.center, ball.center) - ball.radius >= clearance) {
                    return None;
                }
            }
            // The sphere's shadow through b's corners and tangent to its edges, graded as in
            // `Events::new`.
            let sphere = Sphere::outer(ball.center, ball.radius).ok()?;
            events.set_grade(true);
            room &= events.push_edge_quadrics(outer, &ac, front, &sphere)?;
            events.set_grade(near);
            *hulls.get_mut(usize::from(solids))? = Some(Hull::of_ball(&ball));
        }
        // Two solids whose shadows can meet on b add the events where they meet; a solid's and
        // the sphere's, or three solids' that can all meet one another, are declined.
        let mut meets = [[false; MAX_SOLIDS + 1]; MAX_SOLIDS + 1];
        for (i, x) in hulls.iter().enumerate() {
            for (j, y) in hulls.iter().enumerate().skip(i + 1) {
                if let (Some(x), Some(y)) = (x, y) {
                    let meet = !shadows_apart(x, y, &a_hull, &b_hull, tolerance);
                    *meets.get_mut(i)?.get_mut(j)? = meet;
                    *meets.get_mut(j)?.get_mut(i)? = meet;
                }
            }
        }
        let count = usize::from(solids);
        for (i, row) in meets.iter().enumerate() {
            for j in (i + 1)..=MAX_SOLIDS {
                if !row.get(j).copied().unwrap_or(false) {
                    continue;
                }
                if i >= count || j >= count {
                    return None;
                }
                if (0..=MAX_SOLIDS)
                    .any(|k| row.get(k) == Some(&true) && meets.get(j).and_then(|r| r.get(k)) == Some(&true))
                {
                    return None;
                }
                let x = Solid::of_label(casters, &labels, u8::try_from(i + 1).ok()?)?;
                let y = Solid::of_label(casters, &labels, u8::try_from(j + 1).ok()?)?;
                room &= events.push_meeting(outer, outer_rect, (&x, &y), front, (bo, unit_b), &ac, tolerance)?;
                events.set_meeting();
            }
        }
        planes &= events.push_line(outer, outer_rect, Quadric::plane(bo, unit_b));
        (room && planes).then_some(events)
    }

    /// The events where the shadows of two convex solids `x` and `y` meet on b's visible part
    /// (corners `front`; b's plane through `origin` with unit normal `unit`), each solid's own
    /// being placed already. Their shadows' union changes structure where
    ///
    /// * a vertex of one's shadow crosses an edge of the other's: p in the plane through a
    ///   vertex v of one solid and an edge of the other, guarded to the double wedge about v
    ///   that the edge spans (the ray from p through v meets the edge);
    /// * an edge of one's shadow crosses a corner of the other's clipped by b: p in the plane
    ///   through the fixed point where an edge of one solid lying in b's plane crosses an edge
    ///   of b, and an edge of the other;
    /// * two shadow edges cross on an edge of b: p on a line meeting an edge of each solid and
    ///   an edge of b ([`three_lines`], a quadric), left out where the fans from b's edge
    ///   through either solid's edge miss a ([`fan_misses`]), and kept on the arc where it is
    ///   real, sampled along b's edge ([`real_arc`]; guarded to where the line meets b's edge
    ///   within its segment where the samples cannot bound it).
    ///
    /// The overlap of the two shadows grows like δ² on one side of each, as a corner's does.
    /// `None` where a vertex lies behind b's plane (the solid's part in front has vertices
    /// of its own there); else whether all fitted.
    #[allow(clippy::too_many_arguments)]
    fn push_meeting(
        &mut self,
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        outer_rect: ParamRect<T>,
        (x, y): (&Solid<T>, &Solid<T>),
        front: &[Vec3<T>],
        (origin, unit): (Vec3<T>, Vec3<T>),
        ac: &[Vec3<T>; 4],
        tolerance: T,
    ) -> Option<bool> {
        let height = |v: Vec3<T>| unit.dot(v - origin);
        if x.vertices().iter().chain(y.vertices()).any(|&v| height(v) < -tolerance) {
            return None;
        }
        let above = |v: Vec3<T>| height(v) > tolerance;
        let moving = |e: &&(Vec3<T>, Vec3<T>, u8)| above(e.0) || above(e.1);
        let centre =
            front.iter().fold(Vec3::ZERO, |m, &c| m + c).scale(T::ONE / T::from_f64(front.len().max(1) as f64));
        let inside_front = |q: Vec3<T>| {
            polygon_sides(front).all(|(c, d)| {
                (d - c).cross(q - c).dot(unit) * (d - c).cross(centre - c).dot(unit) >= -tolerance * tolerance
            })
        };
        let mut room = true;
        for (one, other) in [(x, y), (y, x)] {
            for &v in one.vertices() {
                if !above(v) && !inside_front(v) {
                    continue;
                }
                for &(w0, w1, _) in other.edges().iter().filter(|e| above(v) || moving(e)) {
                    let (u, w) = (w0 - v, w1 - v);
                    let n = u.cross(w);
                    let mut conditions = [None; 8];
                    conditions[0] = Some((v, n.cross(u), Some(w.cross(n))));
                    conditions[1] = outline(other, w0, w1);
                    if above(v) {
                        // p above v, and the ray from p through v landing in b's visible part.
                        conditions[2] = Some((v, unit, None));
                        for ((c, d), slot) in polygon_sides(front).zip(conditions.iter_mut().skip(3)) {
                            let m = (c - v).cross(d - v);
                            let side = m.dot(v - centre);
                            if side != T::ZERO {
                                *slot = Some((v, if side > T::ZERO { m } else { -m }, None));
                            }
                        }
                    }
                    room &= self.push_trimmed(outer, outer_rect, (v, n), &conditions, tolerance);
                }
            }
            for &(w0, w1, _) in one.edges().iter().filter(|e| !moving(e)) {
                for (c, d) in polygon_sides(front) {
                    let Some(cross) = segments_cross(w0, w1, c, d, unit, tolerance) else { continue };
                    for &(e0, e1, _) in other.edges().iter().filter(moving) {
                        let (u, w) = (e0 - cross, e1 - cross);
                        let n = u.cross(w);
                        let mut conditions = [None; 8];
                        conditions[0] = Some((cross, n.cross(u), Some(w.cross(n))));
                        conditions[1] = outline(other, e0, e1);
                        room &= self.push_trimmed(outer, outer_rect, (cross, n), &conditions, tolerance);
                    }
                }
            }
        }
        let reach = ac.iter().flat_map(|&p| front.iter().map(move |&c| (p - c).norm())).fold(T::ZERO, T::max);
        for &(i0, i1, _) in x.edges().iter().filter(moving) {
            for &(j0, j1, _) in y.edges().iter().filter(moving) {
                for (b0, b1) in polygon_sides(front) {
                    if fan_misses((b0, b1), (i0, i1), ac, reach, tolerance)
                        || fan_misses((b0, b1), (j0, j1), ac, reach, tolerance)
                    {
                        continue;
                    }
                    let Some(quadric) = three_lines((i0, i1), (j0, j1), (b0, b1)) else { continue };
                    let lines = ((i0, i1), (j0, j1), (b0, b1));
                    let outlines = (outline(x, i0, i1), outline(y, j0, j1));
                    match real_arc(outer, outer_rect, lines, outlines, tolerance) {
                        Arc::Never => {}
                        Arc::Within(guard) => room &= self.push_quadric_within(outer, quadric, guard),
                        Arc::Whole => {
                            let di = i1 - i0;
                            room &= self.push_quadric(outer, quadric.guarded(di.cross(b0 - i0), -di.cross(b1 - i0)));
                        }
                    }
                }
            }
        }
        Some(room)
    }

    /// Keeps the plane through `x` with normal `normal` as a line in a's parameters, only on
    /// the part of it (within a widened by half its size on each side) where every one of
    /// `conditions` holds, or the hull of that part where a condition leaves two; nothing
    /// where that part is empty or the plane is parallel to a. `false` on overflow.
    fn push_trimmed(
        &mut self,
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        r: ParamRect<T>,
        (x, normal): (Vec3<T>, Vec3<T>),
        conditions: &[Option<Condition<T>>],
        tolerance: T,
    ) -> bool {
        let (oa, et, es) = outer;
        let (a, b, c) = (normal.dot(et), normal.dot(es), normal.dot(oa - x));
        let (dt, ds) = ((r.t1 - r.t0).abs(), (r.s1 - r.s0).abs());
        let reach = normal.norm() * (et.norm() * dt + es.norm() * ds);
        if !((a * dt).abs() + (b * ds).abs() > reach * T::GEOMETRY_TOLERANCE) {
            return true;
        }
        // The line (t, s) = p₀ + λ·(−b, a), clipped to a widened by half on each side.
        let n2 = a * a + b * b;
        let (t0, s0, vt, vs) = (-c * a / n2, -c * b / n2, -b, a);
        let (mut lo, mut hi) = (-T::MAX, T::MAX);
        for (p, d, min, max) in [
            (t0, vt, r.t0.min(r.t1) - dt * T::HALF, r.t0.max(r.t1) + dt * T::HALF),
            (s0, vs, r.s0.min(r.s1) - ds * T::HALF, r.s0.max(r.s1) + ds * T::HALF),
        ] {
            if d == T::ZERO {
                if p < min || p > max {
                    return true;
                }
            } else {
                let (u, w) = ((min - p) / d, (max - p) / d);
                lo = lo.max(u.min(w));
                hi = hi.min(u.max(w));
            }
        }
        let (p0, dp) = (oa + et.scale(t0) + es.scale(s0), et.scale(vt) + es.scale(vs));
        // Each factor g·(p − o) = α + β·λ along the line; the root, widened by the tolerance.
        let factor = |o: Vec3<T>, g: Vec3<T>| (g.dot(p0 - o), g.dot(dp), tolerance * g.norm());
        for &(o, g0, g1) in conditions.iter().flatten() {
            let (a0, b0, m0) = factor(o, g0);
            match g1 {
                None => {
                    if b0 > T::ZERO {
                        lo = lo.max((-m0 - a0) / b0);
                    } else if b0 < T::ZERO {
                        hi = hi.min((-m0 - a0) / b0);
                    } else if a0 < -m0 {
                        return true;
                    }
                }
                Some(g1) => {
                    let (a1, b1, m1) = factor(o, g1);
                    if b0 == T::ZERO || b1 == T::ZERO {
                        // One factor constant: the other's sign alone, or no condition.
                        let ((ac, mc), (av, bv, mv)) =
                            if b0 == T::ZERO { ((a0, m0), (a1, b1, m1)) } else { ((a1, m1), (a0, b0, m0)) };
                        if ac.abs() <= mc || bv == T::ZERO {
                            if bv == T::ZERO && ac * av < -(mc * mv) && ac.abs() > mc && av.abs() > mv {
                                return true;
                            }
                            continue;
                        }
                        let (av, bv) = if ac > T::ZERO { (av, bv) } else { (-av, -bv) };
                        if bv > T::ZERO {
                            lo = lo.max((-mv - av) / bv);
                        } else {
                            hi = hi.min((-mv - av) / bv);
                        }
                        continue;
                    }
                    let (r0, r1) = (-a0 / b0, -a1 / b1);
                    let widen = m0 / b0.abs() + m1 / b1.abs();
                    let (first, last) = (r0.min(r1), r0.max(r1));
                    if b0 * b1 < T::ZERO {
                        // Same sign only between the roots.
                        lo = lo.max(first - widen);
                        hi = hi.min(last + widen);
                    } else if first + widen < last - widen {
                        // Same sign only outside the roots: [lo, hi] less the gap between.
                        let (gap0, gap1) = (first + widen, last - widen);
                        if lo >= gap0 && hi <= gap1 {
                            return true;
                        } else if lo >= gap0 {
                            lo = lo.max(gap1);
                        } else if hi <= gap1 {
                            hi = hi.min(gap0);
                        }
                    }
                }
            }
            if lo > hi {
                return true;
            }
        }
        let (from, to) = ((t0 + lo * vt, s0 + lo * vs), (t0 + hi * vt, s0 + hi * vs));
        self.push_segment([a, b, c], [vt, vs, -(vt * from.0 + vs * from.1)], [-vt, -vs, vt * to.0 + vs * to.1])
    }

    /// Keeps the plane `quadric` (guarded or not) as a line in a's parameters; `false` on
    /// overflow. A plane that a lies in or is parallel to, or whose guarded part misses a
    /// widened by half its size on each side, is left out.
    fn push_line(&mut self, outer: (Vec3<T>, Vec3<T>, Vec3<T>), r: ParamRect<T>, quadric: Quadric<T>) -> bool {
        let (_, et, es) = outer;
        let normal = quadric.g;
        let (dt, ds) = ((r.t1 - r.t0).abs(), (r.s1 - r.s0).abs());
        let across = (normal.dot(et) * dt).abs() + (normal.dot(es) * ds).abs();
        let reach = normal.norm() * (et.norm() * dt + es.norm() * ds);
        if !(across > reach * T::GEOMETRY_TOLERANCE) {
            return true;
        }
        let before = self.len();
        if !self.push_quadric(outer, quadric) {
            return false;
        }
        let widened = ParamRect {
            t0: r.t0.min(r.t1) - dt * T::HALF,
            t1: r.t0.max(r.t1) + dt * T::HALF,
            s0: r.s0.min(r.s1) - ds * T::HALF,
            s1: r.s0.max(r.s1) + ds * T::HALF,
        };
        self.keep_if_meets(before, widened);
        true
    }
}

/// The part of b (its `corners` in order; `origin` a point of its plane) that points of a flat
/// a can see: b itself where no corner lies behind a's plane beyond rounding, else b clipped by
/// that plane (Sutherland–Hodgman against one plane: 3 to 5 corners, two of them on a's plane),
/// with the number of corners; b's corners where none lies in front. From a point p of a flat
/// a, p's tangent plane is a's plane, so J(p) is taken over this one fixed polygon
/// (`Inner::clipped`), and its corners and edges are where J changes structure: a b that
/// straddles a's plane (a wall against a table top) has the events of its front part.
pub(super) fn front_part<T: Real>(
    outer: (Vec3<T>, Vec3<T>, Vec3<T>),
    origin: Vec3<T>,
    corners: &[Vec3<T>; 4],
) -> ([Vec3<T>; 5], usize) {
    let (o, et, es) = outer;
    let na = et.cross(es);
    let size = corners.iter().fold(T::ZERO, |m, &c| m.max((c - origin).norm())).max(et.norm()).max(es.norm());
    let band = na.norm() * size * T::GEOMETRY_TOLERANCE;
    let height = |c: Vec3<T>| na.dot(c - o);
    let mut part = [Vec3::ZERO; 5];
    let mut n = 0usize;
    if corners.iter().all(|&c| height(c) >= -band) || corners.iter().all(|&c| height(c) <= band) {
        for (slot, &c) in part.iter_mut().zip(corners) {
            *slot = c;
        }
        return (part, 4);
    }
    for (k, &c) in corners.iter().enumerate() {
        let Some(&next) = corners.get((k + 1) % 4) else { continue };
        let (hc, hn) = (height(c), height(next));
        let mut keep = |x: Vec3<T>| {
            if let Some(slot) = part.get_mut(n) {
                *slot = x;
                n += 1;
            }
        };
        if hc >= -band {
            keep(c);
        }
        // An edge from one side to the other beyond the band: its point on a's plane.
        if (hc > band && hn < -band) || (hc < -band && hn > band) {
            keep(c + (next - c).scale(hc / (hc - hn)));
        }
    }
    (part, n)
}
