//! Culling a flat occluder from a pair of flat patches by a separating plane.
//!
//! A segment counted by the kernel runs from a point of patch a to a point of patch b, so it
//! lies in P = conv(a ∪ b). If a plane leaves P on one closed side and the occluder O on the
//! other, a segment can meet O only in that plane, and then (its two ends being on P's closed
//! side) it lies in the plane altogether: a set of segments of measure zero, which cannot
//! change the integral. Such a plane exists for polytopes that do not overlap, even when they
//! touch — the usual case in meshes, where a cabinet's side touches the floor patch in front of
//! it at a corner, and the bounding-ball test (which needs a gap) keeps the cabinet as an
//! occluder of every pair near it. By the separating-axis theorem for convex polytopes the
//! plane can be sought among the normals of P's faces, O's face, and the cross products of an
//! edge of P with an edge of O; every face normal and edge of P is a cross product of, or a
//! difference between, two of its (at most eight) points.

use pdm_kernel::Vec3;

use super::shape::{bilinear, corners, Geom, Rect};

/// The corners of a patch with straight edges (a parallelogram's or a quadrilateral's), which
/// it is the convex hull of; `None` for curved kinds.
#[must_use]
pub fn polygon(geom: &Geom, rect: Rect) -> Option<[Vec3<f64>; 4]> {
    match *geom {
        Geom::Parallelogram { origin, edge_t, edge_s } => {
            let mut c = corners(origin, edge_t, edge_s, rect);
            Some([c.next()?, c.next()?, c.next()?, c.next()?])
        }
        Geom::Quadrilateral { corners } => Some(
            [(rect.t0, rect.s0), (rect.t1, rect.s0), (rect.t1, rect.s1), (rect.t0, rect.s1)]
                .map(|(t, s)| bilinear(&corners, t, s)),
        ),
        _ => None,
    }
}

/// The differences between the points (zero ones left out): every edge of their convex hull
/// is one of them.
fn differences(points: &[Vec3<f64>]) -> Vec<Vec3<f64>> {
    let mut d = Vec::new();
    for (k, x) in points.iter().enumerate() {
        for y in &points[k + 1..] {
            let e = *y - *x;
            if e.norm2() > 0.0 {
                d.push(e);
            }
        }
    }
    d
}

/// The convex hull P of a pair's two patches, by its points and the candidates for its
/// edges: built once per pair, tested against each flat occluder that survives the cheaper
/// tests.
pub struct Hull {
    points: Vec<Vec3<f64>>,
    edges: Vec<Vec3<f64>>,
}

impl Hull {
    /// The hull of the given points.
    #[must_use]
    pub fn new(points: &[Vec3<f64>]) -> Self {
        Self { points: points.to_vec(), edges: differences(points) }
    }

    /// `true` if some plane has the hull on one closed side and all of `o` on the other, to
    /// within `tol` (a length): they do not overlap (they may touch).
    #[must_use]
    pub fn weakly_separated_from(&self, o: &[Vec3<f64>], tol: f64) -> bool {
        let separates = |n: Vec3<f64>| {
            let length = n.norm();
            if !(length > 0.0) || !length.is_finite() {
                return false;
            }
            let range = |points: &[Vec3<f64>]| {
                points
                    .iter()
                    .map(|x| n.dot(*x) / length)
                    .fold((f64::MAX, -f64::MAX), |(lo, hi), d| (lo.min(d), hi.max(d)))
            };
            let ((p_lo, p_hi), (o_lo, o_hi)) = (range(&self.points), range(o));
            p_hi <= o_lo + tol || o_hi <= p_lo + tol
        };
        let (pe, oe) = (&self.edges, differences(o));
        // O's plane (and, for degenerate O, its edges' cross products), then the edge–edge
        // planes, then P's faces.
        let pairs_within =
            |e: &[Vec3<f64>]| e.iter().enumerate().any(|(k, x)| e[k + 1..].iter().any(|y| separates(x.cross(*y))));
        pairs_within(&oe) || pe.iter().any(|x| oe.iter().any(|y| separates(x.cross(*y)))) || pairs_within(pe)
    }
}

/// `true` if some plane has all of `p` on one closed side and all of `o` on the other, to
/// within `tol` (a length): conv(p) and conv(o) do not overlap (they may touch).
#[must_use]
pub fn weakly_separated(p: &[Vec3<f64>], o: &[Vec3<f64>], tol: f64) -> bool {
    Hull::new(p).weakly_separated_from(o, tol)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdm_kernel::vec3;

    fn square(z: f64, x0: f64) -> [Vec3<f64>; 4] {
        [vec3(x0, 0.0, z), vec3(x0 + 1.0, 0.0, z), vec3(x0 + 1.0, 1.0, z), vec3(x0, 1.0, z)]
    }

    #[test]
    fn separated_touching_and_overlapping() {
        // Two parallel squares 1 apart; a small plate between them overlaps their hull.
        let mut pair: Vec<_> = square(0.0, 0.0).to_vec();
        pair.extend(square(1.0, 0.0));
        let plate = [vec3(0.4, 0.4, 0.5), vec3(0.6, 0.4, 0.5), vec3(0.6, 0.6, 0.5), vec3(0.4, 0.6, 0.5)];
        assert!(!weakly_separated(&pair, &plate, 1e-12));
        // Beside the hull: separated; touching its side face x = 1: still separated.
        let beside = [vec3(1.5, 0.4, 0.2), vec3(1.5, 0.6, 0.2), vec3(1.5, 0.6, 0.8), vec3(1.5, 0.4, 0.8)];
        assert!(weakly_separated(&pair, &beside, 1e-12));
        let touching = [vec3(1.0, 0.4, 0.2), vec3(1.5, 0.4, 0.2), vec3(1.5, 0.6, 0.8), vec3(1.0, 0.6, 0.8)];
        assert!(weakly_separated(&pair, &touching, 1e-12));
        // Poking into the hull by 0.01: overlapping.
        let poking = [vec3(0.99, 0.4, 0.2), vec3(1.5, 0.4, 0.2), vec3(1.5, 0.6, 0.8), vec3(0.99, 0.6, 0.8)];
        assert!(!weakly_separated(&pair, &poking, 1e-12));
        // A tilted pair: a plate near the hull's slanted face (only a cross-product axis
        // separates it).
        let mut tilted: Vec<_> = square(0.0, 0.0).to_vec();
        tilted.extend(square(1.0, 2.0));
        let near_face = [vec3(1.2, -0.5, 0.1), vec3(1.6, -0.5, 0.1), vec3(1.6, 1.5, 0.1), vec3(1.2, 1.5, 0.1)];
        let cut = near_face.map(|p| p + vec3(-0.3, 0.0, 0.2));
        assert!(weakly_separated(&tilted, &near_face, 1e-12));
        assert!(!weakly_separated(&tilted, &cut, 1e-12));
    }

    /// Against sampling: whenever the test says separated, no segment between random points
    /// of the two squares crosses the occluder's interior.
    #[test]
    fn separated_means_no_segment_crosses() {
        use pdm_kernel::Occluder as _;
        let mut state = 3u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut separated, mut kept) = (0, 0);
        for _ in 0..300 {
            let mut r = |s: f64| vec3(s * (next() - 0.5), s * (next() - 0.5), s * (next() - 0.5));
            let (c, e1, e2) = (r(3.0), r(1.0), r(1.0));
            let o = [c, c + e1, c + e1 + e2, c + e2];
            let Ok(occ) = pdm_kernel::Parallelogram::new(c, e1, e2) else { continue };
            let a = [vec3(-1.0, -1.0, -1.0), vec3(0.0, -1.0, -1.0), vec3(0.0, 0.0, -1.0), vec3(-1.0, 0.0, -1.0)];
            let b = [vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 1.0), vec3(1.0, 1.0, 1.0), vec3(0.0, 1.0, 1.0)];
            let pts: Vec<_> = a.iter().chain(b.iter()).copied().collect();
            if !weakly_separated(&pts, &o, 1e-12) {
                kept += 1;
                continue;
            }
            separated += 1;
            for _ in 0..400 {
                let (u, v, w, z) = (next(), next(), next(), next());
                let x = vec3(-1.0 + u, -1.0 + v, -1.0);
                let y = vec3(w, z, 1.0);
                assert!(!occ.blocks(x, y), "{o:?} blocks {x:?} -> {y:?}");
            }
        }
        assert!(separated > 30 && kept > 30, "{separated} {kept}");
    }
}
