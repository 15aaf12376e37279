//! Checks that a Bézier net is a simple sheet: it neither folds over (the normal turning back
//! between neighbouring points) nor passes through itself. Both are checked on a grid of
//! `GRID` × `GRID` cells per patch: a fold as two neighbouring grid normals at an angle of 90°
//! or more, a crossing as an edge of the net's triangulated grid passing through a triangle it
//! shares no corner with. Features smaller than a grid cell are not seen.

use pdm_kernel::{vec3, Surface as _, Vec3};
use rstar::{RTree, RTreeObject, AABB};

use super::shape::Geom;

/// Grid cells along each side of each patch.
pub const GRID: usize = 12;

struct Tri {
    corners: [Vec3<f64>; 3],
    /// Indices of its corners in the list of distinct grid points.
    ids: [usize; 3],
}

impl RTreeObject for Tri {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        let [p, q, r] = self.corners;
        let lo = [p.x.min(q.x).min(r.x), p.y.min(q.y).min(r.y), p.z.min(q.z).min(r.z)];
        let hi = [p.x.max(q.x).max(r.x), p.y.max(q.y).max(r.y), p.z.max(q.z).max(r.z)];
        AABB::from_corners(lo, hi)
    }
}

/// Whether the segment from `p` to `q` crosses the triangle's interior away from both ends
/// (Möller–Trumbore; a segment in the triangle's plane does not count).
fn crosses(p: Vec3<f64>, q: Vec3<f64>, [a, b, c]: [Vec3<f64>; 3], eps: f64) -> bool {
    let d = q - p;
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() <= eps * d.norm() * e1.norm() * e2.norm() {
        return false;
    }
    let f = 1.0 / det;
    let w = p - a;
    let u = f * w.dot(h);
    let qv = w.cross(e1);
    let v = f * d.dot(qv);
    let tau = f * e2.dot(qv);
    u > eps && v > eps && u + v < 1.0 - eps && tau > eps && tau < 1.0 - eps
}

/// `None` if the Bézier patches `nets` make a simple sheet, else what is wrong, in words.
#[must_use]
pub fn bezier_problem(nets: &[Geom]) -> Option<String> {
    let mut points: Vec<Vec3<f64>> = Vec::new();
    let mut tris = Vec::new();
    // Distinct grid points: patches that share an edge give the same points there, to the bit
    // (points that differ by rounding only count as two, which makes their triangles
    // non-neighbours that merely touch, and touching is not crossing).
    let mut index = std::collections::HashMap::new();
    let mut id_of = |p: Vec3<f64>, points: &mut Vec<Vec3<f64>>| -> usize {
        *index.entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]).or_insert_with(|| {
            points.push(p);
            points.len() - 1
        })
    };
    for (k, g) in nets.iter().enumerate() {
        let Ok(shape) = g.shape::<f64>() else { continue };
        // A normal this short is zero up to rounding (a collapsed edge, where the kernel's sum
        // of points times weights leaves noise of the size of the coordinates times ε).
        let size = match g {
            Geom::Bezier { control } => {
                let flat: Vec<Vec3<f64>> = control.iter().flatten().copied().collect();
                let c = flat.iter().fold(vec3(0.0, 0.0, 0.0), |a, p| a + *p).scale(1.0 / 16.0);
                flat.iter().map(|p| (*p - c).norm() + c.norm()).fold(0.0, f64::max)
            }
            _ => 1.0,
        };
        let zero = 1e-10 * size * size;
        let at = |i: usize, j: usize| (i as f64 / GRID as f64, j as f64 / GRID as f64);
        let mut grid = vec![vec![(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 0.0)); GRID + 1]; GRID + 1];
        for (i, row) in grid.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                let (t, s) = at(i, j);
                *cell = shape.point_and_normal(t, s);
            }
        }
        for i in 0..=GRID {
            for j in 0..=GRID {
                let n = grid[i][j].1;
                for (a, b) in [(i + 1, j), (i, j + 1)] {
                    if let Some(m) = grid.get(a).and_then(|r| r.get(b)).map(|x| x.1) {
                        // Collapsed edges have zero normals: only two non-zero ones compare.
                        if n.norm() > zero && m.norm() > zero && n.dot(m) <= 0.0 {
                            let (t, s) = at(i, j);
                            return Some(format!(
                                "folds over in patch {} near (t, s) = ({t:.2}, {s:.2}): the normal turns back",
                                k + 1
                            ));
                        }
                    }
                }
            }
        }
        let mut ids = vec![vec![0; GRID + 1]; GRID + 1];
        for i in 0..=GRID {
            for j in 0..=GRID {
                ids[i][j] = id_of(grid[i][j].0, &mut points);
            }
        }
        for i in 0..GRID {
            for j in 0..GRID {
                for corner in [[(i, j), (i + 1, j), (i + 1, j + 1)], [(i, j), (i + 1, j + 1), (i, j + 1)]] {
                    let c = corner.map(|(a, b)| ids[a][b]);
                    if c[0] != c[1] && c[1] != c[2] && c[0] != c[2] {
                        tris.push(Tri { corners: c.map(|x| points[x]), ids: c });
                    }
                }
            }
        }
    }
    let tree = RTree::bulk_load(tris);
    let eps = 1e-9;
    for t in &tree {
        for (x, y) in [(0, 1), (1, 2), (2, 0)] {
            let (p, q) = (t.corners[x], t.corners[y]);
            let (ip, iq) = (t.ids[x], t.ids[y]);
            let lo = [p.x.min(q.x), p.y.min(q.y), p.z.min(q.z)];
            let hi = [p.x.max(q.x), p.y.max(q.y), p.z.max(q.z)];
            for other in tree.locate_in_envelope_intersecting(&AABB::from_corners(lo, hi)) {
                if other.ids.contains(&ip) || other.ids.contains(&iq) {
                    continue;
                }
                if crosses(p, q, other.corners, eps) {
                    let m = (p + q).scale(0.5);
                    return Some(format!("passes through itself near ({:.3}, {:.3}, {:.3})", m.x, m.y, m.z));
                }
            }
        }
    }
    None
}

#[cfg(test)]
#[allow(clippy::indexing_slicing)]
mod tests {
    use super::*;

    fn net(f: impl Fn(f64, f64) -> Vec3<f64>) -> Geom {
        let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (a, row) in control.iter_mut().enumerate() {
            for (b, p) in row.iter_mut().enumerate() {
                *p = f(a as f64 / 3.0, b as f64 / 3.0);
            }
        }
        Geom::Bezier { control }
    }

    #[test]
    fn flat_and_curved_sheets_pass() {
        assert_eq!(bezier_problem(&[net(|u, v| vec3(u, v, 0.0))]), None);
        assert_eq!(bezier_problem(&[net(|u, v| vec3(u, v, 0.3 * (u * u + v * v)))]), None);
        // Two patches sharing an edge (a dish's neighbours).
        let (a, b) = (net(|u, v| vec3(u, v, 0.2 * u * u)), net(|u, v| vec3(u, 1.0 + v, 0.2 * u * u)));
        assert_eq!(bezier_problem(&[a, b]), None);
        // A collapsed edge (a triangle-shaped net) is no fold, wherever it is.
        assert_eq!(bezier_problem(&[net(|u, v| vec3(u, u * v, 0.0))]), None);
        for apex in [vec3(0.3, 0.2, 1.0), vec3(10.0, -3.0, 5.0)] {
            // A cone-shaped net: the row u = 0 collapsed to the apex, the base a quarter arc.
            let cone = net(|u, v| {
                let a = v * core::f64::consts::FRAC_PI_2;
                apex + (vec3(a.cos(), a.sin(), -1.0)).scale(u)
            });
            assert_eq!(bezier_problem(&[cone]), None, "apex {apex:?}");
        }
    }

    #[test]
    fn folds_and_crossings_are_found() {
        // The second row of control points pulled back behind the first: the sheet folds.
        let mut fold = net(|u, v| vec3(u, v, 0.0));
        if let Geom::Bezier { control } = &mut fold {
            for p in &mut control[1] {
                p.x = -0.9;
            }
        }
        let e = bezier_problem(&[fold]).unwrap_or_default();
        assert!(e.contains("folds over"), "{e:?}");
        // Two patches that cross each other (a net whose pieces intersect).
        let (a, b) = (net(|u, v| vec3(u, v, 0.0)), net(|u, v| vec3(0.47, 0.1 + 0.8 * u, v - 0.53)));
        let e = bezier_problem(&[a, b]).unwrap_or_default();
        assert!(e.contains("passes through itself"), "{e:?}");
    }
}
