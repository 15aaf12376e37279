//! Which occluders may cut a pair, found without testing them all: an R-tree (`rstar`) over the
//! occluders' bounding boxes, searched with the capsule around the pair's two enclosing balls.
//!
//! A segment from a point of patch a to a point of patch b lies in the convex hull of their
//! enclosing balls, and that hull lies in the capsule of radius max(r_a, r_b) around the segment
//! between the balls' centres. An occluder that can block such a segment therefore meets the
//! capsule, and so does its bounding box; a box that stays away from the capsule (tested as the
//! segment against the box grown by the radius, which holds the box's neighbourhood of that
//! radius) bounds occluders that cannot. A scene of N occluders then pays about log N box tests
//! per pair, plus the occluders near the pair's line of sight, instead of N.

use pdm_kernel::{vec3, Vec3};
use rstar::{RTree, RTreeObject, SelectionFunction, AABB};

use super::shape::{Geom, Plane, Rect};

/// One occluder: (surface, piece) in the scene and its axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Index of the surface.
    pub surface: usize,
    /// Index of the piece in that surface.
    pub piece: usize,
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Entry {
    /// The occluder `(surface, piece)` with geometry `geom` over `rect`, its box from the exact
    /// or conservative extents of [`Geom::distance_range`] along the three axes.
    #[must_use]
    pub fn new(surface: usize, piece: usize, geom: &Geom, rect: Rect) -> Self {
        let origin = vec3(0.0, 0.0, 0.0);
        let axis = |normal: Vec3<f64>| geom.distance_range(rect, &Plane { origin, normal });
        let (x, y, z) = (axis(vec3(1.0, 0.0, 0.0)), axis(vec3(0.0, 1.0, 0.0)), axis(vec3(0.0, 0.0, 1.0)));
        Self { surface, piece, lo: [x.0, y.0, z.0], hi: [x.1, y.1, z.1] }
    }
}

impl RTreeObject for Entry {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        AABB::from_corners(self.lo, self.hi)
    }
}

/// The occluders of a scene, searchable by capsule.
pub struct Occluders {
    tree: RTree<Entry>,
}

/// The capsule of radius `radius` around the segment from `a` to `b`.
struct Capsule {
    a: [f64; 3],
    b: [f64; 3],
    radius: f64,
}

impl Capsule {
    fn meets(&self, lo: &[f64; 3], hi: &[f64; 3]) -> bool {
        segment_meets_box(self.a, self.b, lo.map(|x| x - self.radius), hi.map(|x| x + self.radius))
    }
}

impl SelectionFunction<Entry> for Capsule {
    fn should_unpack_parent(&self, envelope: &AABB<[f64; 3]>) -> bool {
        self.meets(&envelope.lower(), &envelope.upper())
    }
    fn should_unpack_leaf(&self, leaf: &Entry) -> bool {
        self.meets(&leaf.lo, &leaf.hi)
    }
}

/// Whether the closed segment from `a` to `b` meets the closed box [`lo`, `hi`] (slab test).
/// A box with a non-finite bound (an extent that could not be bounded) is met.
fn segment_meets_box(a: [f64; 3], b: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> bool {
    let (mut enter, mut leave) = (0.0_f64, 1.0_f64);
    for k in 0..3 {
        if !(lo[k].is_finite() && hi[k].is_finite()) {
            return true;
        }
        let d = b[k] - a[k];
        if d == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (t0, t1) = ((lo[k] - a[k]) / d, (hi[k] - a[k]) / d);
        enter = enter.max(t0.min(t1));
        leave = leave.min(t0.max(t1));
        if enter > leave {
            return false;
        }
    }
    true
}

impl Occluders {
    /// The tree over `entries`.
    #[must_use]
    pub fn new(entries: Vec<Entry>) -> Self {
        Self { tree: RTree::bulk_load(entries) }
    }

    /// Every occluder whose box comes within `radius` of the segment from `a` to `b`, as
    /// (surface, piece), sorted.
    #[must_use]
    pub fn near_segment(&self, a: Vec3<f64>, b: Vec3<f64>, radius: f64) -> Vec<(usize, usize)> {
        let capsule = Capsule { a: [a.x, a.y, a.z], b: [b.x, b.y, b.z], radius };
        let mut found: Vec<_> =
            self.tree.locate_with_selection_function(capsule).map(|e| (e.surface, e.piece)).collect();
        found.sort_unstable();
        found
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256StarStar;

    #[test]
    fn slab_test_against_sampling() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(11);
        let mut coord = || rng.random::<f64>() * 4.0 - 2.0;
        for _ in 0..4000 {
            let a = [coord(), coord(), coord()];
            let b = [coord(), coord(), coord()];
            let (p, q) = ([coord(), coord(), coord()], [coord(), coord(), coord()]);
            let lo = [p[0].min(q[0]), p[1].min(q[1]), p[2].min(q[2])];
            let hi = [p[0].max(q[0]), p[1].max(q[1]), p[2].max(q[2])];
            let sampled = (0..=2000).any(|k| {
                let t = f64::from(k) / 2000.0;
                (0..3).all(|c| {
                    let x = a[c] + (b[c] - a[c]) * t;
                    x >= lo[c] && x <= hi[c]
                })
            });
            // A sampled hit is a hit; a miss by sampling may be a graze the samples step over.
            if sampled {
                assert!(segment_meets_box(a, b, lo, hi), "{a:?} {b:?} {lo:?} {hi:?}");
            }
        }
        // Axis-parallel segments, and boxes of zero thickness (flat facets in a coordinate plane).
        assert!(segment_meets_box([0.5, -1.0, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0]));
        assert!(!segment_meets_box([0.5, -1.0, 0.1], [0.5, 1.0, 0.1], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0]));
        assert!(!segment_meets_box([2.0, 2.0, 2.0], [3.0, 3.0, 3.0], [0.0; 3], [1.0; 3]));
        assert!(segment_meets_box([2.0, 2.0, 2.0], [3.0, 3.0, 3.0], [0.0; 3], [f64::INFINITY, 1.0, 1.0]));
    }

    #[test]
    fn near_segment_keeps_every_box_the_capsule_meets() {
        // A 20 x 20 x 20 lattice of small boxes; the query must return exactly the boxes whose
        // grown box the segment meets (brute force over all of them).
        let square =
            |c: Vec3<f64>| Geom::Parallelogram { origin: c, edge_t: vec3(0.3, 0.0, 0.0), edge_s: vec3(0.0, 0.2, 0.1) };
        let mut entries = Vec::new();
        for i in 0..20_u32 {
            for j in 0..20 {
                for k in 0..20 {
                    let g = square(vec3(f64::from(i), f64::from(j), f64::from(k)));
                    entries.push(Entry::new((i * 400 + j * 20 + k) as usize, 0, &g, g.domain()));
                }
            }
        }
        let tree = Occluders::new(entries.clone());
        let mut rng = Xoshiro256StarStar::seed_from_u64(5);
        let mut point = || {
            let mut c = || rng.random::<f64>() * 22.0 - 1.0;
            vec3(c(), c(), c())
        };
        for n in 0..50 {
            let (a, b) = (point(), point());
            let radius = f64::from(n % 5) * 0.3;
            let found = tree.near_segment(a, b, radius);
            let capsule = Capsule { a: [a.x, a.y, a.z], b: [b.x, b.y, b.z], radius };
            let mut brute: Vec<_> =
                entries.iter().filter(|e| capsule.meets(&e.lo, &e.hi)).map(|e| (e.surface, e.piece)).collect();
            brute.sort_unstable();
            assert_eq!(found, brute);
            assert!(found.len() < entries.len() / 4, "the capsule holds {} of the boxes", found.len());
        }
    }

    #[test]
    fn boxes_hold_the_surfaces() {
        let geoms = [
            Geom::Quadrilateral {
                corners: [vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 1.0), vec3(0.0, 0.0, 0.0)],
            },
            Geom::Parallelogram {
                origin: vec3(1.0, 2.0, 3.0),
                edge_t: vec3(-1.0, 0.5, 0.0),
                edge_s: vec3(0.0, 0.0, 2.0),
            },
        ];
        for g in geoms {
            let e = Entry::new(0, 0, &g, g.domain());
            let shape = g.shape::<f64>().unwrap();
            use pdm_kernel::Surface as _;
            for i in 0..=20 {
                for j in 0..=20 {
                    let x = shape.point(f64::from(i) / 20.0, f64::from(j) / 20.0);
                    for (c, v) in [x.x, x.y, x.z].into_iter().enumerate() {
                        assert!(v >= e.lo[c] - 1e-12 && v <= e.hi[c] + 1e-12);
                    }
                }
            }
        }
    }
}
