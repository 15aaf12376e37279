//! The paper's test scene (section 4, Figure 6): a cube of side 6 centred at the origin whose
//! six faces radiate inwards, and a sphere of radius R (the paper: 1) at its centre.
//!
//! **Face numbering** (the paper's, Table 3 lists 1-6, 2-3 and 4-5 as the opposite pairs):
//!
//! | face | plane  | normal | note |
//! |------|--------|--------|------|
//! | 1    | z = +3 | −z     | holds the north pole (φ = 0) of the sphere's parameterisation, eq. (19) |
//! | 2    | y = −3 | +y     | the paper's plane patch, eq. (22), with d = −3 ("face 2 is frontal") |
//! | 3    | y = +3 | −y     | |
//! | 4    | x = −3 | +x     | |
//! | 5    | x = +3 | −x     | |
//! | 6    | z = −3 | +z     | holds the south pole (φ = π) |
//!
//! The sphere is eq. (19) with its poles on the z axis, so faces 1 and 6 are the faces the
//! paper's Table 1 singles out ("a small variation concerning the form factors of the faces 1
//! and 6 due to the characteristics of the parametric equations"). Faces 2–5 are equivalent
//! under the sphere grid's θ-symmetry when the number of θ cells is a multiple of 4.
//!
//! Each face is `Parallelogram::new(origin, edge_t, edge_s)` with `edge_t × edge_s` pointing
//! into the cube; face patches form a K × K grid (t × s), sphere patches an M × N grid
//! (φ × θ).

use pdm_kernel::{vec3, Parallelogram, PdmError, Real, Sphere, Vec3};

/// Cube side (the paper's l = 6).
pub const SIDE: f64 = 6.0;

/// Half the side: faces lie at ±3 (the paper's d = 3).
pub const HALF_SIDE: f64 = 3.0;

/// (origin, edge_t, edge_s) of faces 1..6 in the paper's numbering (see the module docs).
pub const FACES: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
    // 1: z = +3, facing −z: (0,6,0) × (6,0,0) = (0,0,−36).
    ([-3.0, -3.0, 3.0], [0.0, 6.0, 0.0], [6.0, 0.0, 0.0]),
    // 2: y = −3, facing +y: (0,0,6) × (6,0,0) = (0,36,0) — eq. (22): x = a(2s−1), z = b(2t−1).
    ([-3.0, -3.0, -3.0], [0.0, 0.0, 6.0], [6.0, 0.0, 0.0]),
    // 3: y = +3, facing −y: (6,0,0) × (0,0,6) = (0,−36,0).
    ([-3.0, 3.0, -3.0], [6.0, 0.0, 0.0], [0.0, 0.0, 6.0]),
    // 4: x = −3, facing +x: (0,6,0) × (0,0,6) = (36,0,0).
    ([-3.0, -3.0, -3.0], [0.0, 6.0, 0.0], [0.0, 0.0, 6.0]),
    // 5: x = +3, facing −x: (0,0,6) × (0,6,0) = (−36,0,0).
    ([3.0, -3.0, -3.0], [0.0, 0.0, 6.0], [0.0, 6.0, 0.0]),
    // 6: z = −3, facing +z: (6,0,0) × (0,6,0) = (0,0,36).
    ([-3.0, -3.0, -3.0], [6.0, 0.0, 0.0], [0.0, 6.0, 0.0]),
];

/// The 15 unordered face pairs (a < b, faces numbered 1..6) in the order of the paper's Table 3.
pub const FACE_PAIRS: [(usize, usize); 15] = [
    (1, 2),
    (1, 3),
    (1, 4),
    (1, 5),
    (1, 6),
    (2, 3),
    (2, 4),
    (2, 5),
    (2, 6),
    (3, 4),
    (3, 5),
    (3, 6),
    (4, 5),
    (4, 6),
    (5, 6),
];

/// `true` for the three pairs of opposite (parallel) faces: 1-6, 2-3, 4-5.
#[must_use]
pub fn is_opposite(a: usize, b: usize) -> bool {
    matches!((a.min(b), a.max(b)), (1, 6) | (2, 3) | (4, 5))
}

/// The JSON key of a face pair, "a-b".
#[must_use]
pub fn pair_key(a: usize, b: usize) -> String {
    format!("{a}-{b}")
}

fn v<T: Real>(p: [f64; 3]) -> Vec3<T> {
    vec3(T::from_f64(p[0]), T::from_f64(p[1]), T::from_f64(p[2]))
}

/// The scene in precision `T`: six faces (index 0 = face 1) and the sphere (`None` for R = 0).
#[derive(Clone, Debug)]
pub struct Scene<T> {
    /// Faces 1..6 (index = face number − 1), radiating into the cube.
    pub faces: [Parallelogram<T>; 6],
    /// The centred sphere radiating outwards, eq. (19); `None` for the empty cube.
    pub sphere: Option<Sphere<T>>,
}

impl<T: Real> Scene<T> {
    /// Builds the scene for sphere radius `radius` (0 = no sphere).
    pub fn new(radius: f64) -> Result<Self, PdmError> {
        let [f1, f2, f3, f4, f5, f6] = FACES;
        let face = |(o, t, s): ([f64; 3], [f64; 3], [f64; 3])| Parallelogram::new(v::<T>(o), v(t), v(s));
        let faces = [face(f1)?, face(f2)?, face(f3)?, face(f4)?, face(f5)?, face(f6)?];
        let sphere = if radius > 0.0 {
            Some(Sphere::outer(vec3(T::ZERO, T::ZERO, T::ZERO), T::from_f64(radius))?)
        } else {
            None
        };
        Ok(Self { faces, sphere })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;

    #[test]
    fn faces_point_into_the_cube_and_sit_where_documented() {
        let scene = Scene::<f64>::new(1.0).unwrap();
        // (axis, coordinate of the plane) for faces 1..6
        let planes = [(2, 3.0), (1, -3.0), (1, 3.0), (0, -3.0), (0, 3.0), (2, -3.0)];
        for (k, face) in scene.faces.iter().enumerate() {
            let n = face.area_normal();
            let centre = face.origin() + (face.edge_t() + face.edge_s()).scale(0.5);
            assert!(n.dot(centre) < 0.0, "face {} must face the centre", k + 1);
            assert!((n.norm() - 36.0).abs() < 1e-12);
            let (axis, c) = planes[k];
            let coords = [centre.x, centre.y, centre.z];
            assert_eq!(coords[axis], c, "face {}", k + 1);
            for corner in [face.origin(), face.origin() + face.edge_t(), face.origin() + face.edge_s()] {
                let cc = [corner.x, corner.y, corner.z];
                assert_eq!(cc[axis], c);
                assert!(cc.iter().all(|x| x.abs() == 3.0));
            }
        }
    }

    #[test]
    fn opposite_pairs_are_the_papers() {
        let opposite: Vec<_> = FACE_PAIRS.iter().filter(|(a, b)| is_opposite(*a, *b)).collect();
        assert_eq!(opposite, [&(1, 6), &(2, 3), &(4, 5)]);
        // Opposite faces have antiparallel normals, adjacent ones perpendicular normals.
        let scene = Scene::<f64>::new(1.0).unwrap();
        for (a, b) in FACE_PAIRS {
            let d = scene.faces[a - 1].area_normal().dot(scene.faces[b - 1].area_normal());
            if is_opposite(a, b) {
                assert_eq!(d, -36.0 * 36.0);
            } else {
                assert_eq!(d, 0.0);
            }
        }
    }

    #[test]
    fn poles_face_faces_1_and_6() {
        let scene = Scene::<f64>::new(1.0).unwrap();
        let sphere = scene.sphere.unwrap();
        use pdm_kernel::Surface;
        let north = sphere.point(0.0, 0.0);
        let south = sphere.point(core::f64::consts::PI, 0.0);
        assert!((north.z - 1.0).abs() < 1e-15 && (south.z + 1.0).abs() < 1e-15);
        assert!(Scene::<f64>::new(0.0).unwrap().sphere.is_none());
    }
}
