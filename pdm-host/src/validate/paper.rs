//! The paper's published numbers (section 4, Tables 1–5), for the columns printed beside ours.
//!
//! The paper used 86 patches (32 sphere + 9 per face) and 280 patches (64 sphere + 36 per face),
//! five Gauss points, a sphere of radius 1 in a cube of side 6, on a SUN SPARCstation 1+.

use super::scene::is_opposite;

/// The paper's numbers for one of its two discretisations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperValues {
    /// Total patch count (86 or 280).
    pub patches: usize,
    /// Table 1: sphere → face for faces 1 and 6 (the pole faces).
    pub sphere_to_pole_face: f64,
    /// Table 1: sphere → face for faces 2–5.
    pub sphere_to_side_face: f64,
    /// Table 3: opposite faces (1-6, 2-3, 4-5).
    pub opposite: f64,
    /// Table 3: adjacent faces (the other 12 pairs).
    pub adjacent: f64,
    /// Table 4: the sum of face 1's factors (the paper gives face 1 only).
    pub face1_sum: f64,
    /// Table 2: processing time of the sphere → face factors, seconds.
    pub sphere_face_seconds: f64,
    /// Table 5: processing time of the face → face factors, seconds.
    pub face_face_seconds: f64,
}

/// 86 patches: 32 on the sphere, 3 × 3 per face.
pub const PAPER_86: PaperValues = PaperValues {
    patches: 86,
    sphere_to_pole_face: 1.6735e-1,
    sphere_to_side_face: 1.6693e-1,
    opposite: 1.5400e-1,
    adjacent: 2.0341e-1,
    face1_sum: 1.0258,
    sphere_face_seconds: 36.0,
    face_face_seconds: 82.0,
};

/// 280 patches: 64 on the sphere, 6 × 6 per face.
pub const PAPER_280: PaperValues = PaperValues {
    patches: 280,
    sphere_to_pole_face: 1.6683e-1,
    sphere_to_side_face: 1.6673e-1,
    opposite: 1.5400e-1,
    adjacent: 2.0018e-1,
    face1_sum: 1.0128,
    sphere_face_seconds: 300.0,
    face_face_seconds: 1278.0,
};

impl PaperValues {
    /// The paper's values for a discretisation with `sphere_patches` sphere patches and a
    /// `face_grid` × `face_grid` grid per face, of a sphere of radius `radius`; `None` unless
    /// it is one of the paper's two (R = 1, 32 + 3×3 or 64 + 6×6).
    #[must_use]
    pub fn for_grid(sphere_patches: usize, face_grid: usize, radius: f64) -> Option<Self> {
        if radius != 1.0 {
            return None;
        }
        match (sphere_patches, face_grid) {
            (32, 3) => Some(PAPER_86),
            (64, 6) => Some(PAPER_280),
            _ => None,
        }
    }

    /// Table 1 for face `f` (1..6).
    #[must_use]
    pub fn sphere_to_face(&self, f: usize) -> f64 {
        if f == 1 || f == 6 {
            self.sphere_to_pole_face
        } else {
            self.sphere_to_side_face
        }
    }

    /// Table 3 for the pair a-b.
    #[must_use]
    pub fn face_to_face(&self, a: usize, b: usize) -> f64 {
        if is_opposite(a, b) {
            self.opposite
        } else {
            self.adjacent
        }
    }

    /// Table 4 for face `f`: the paper gives face 1 only.
    #[must_use]
    pub fn face_sum(&self, f: usize) -> Option<f64> {
        (f == 1).then_some(self.face1_sum)
    }
}

/// Seconds as the paper writes them ("36 s", "1 min 22 s", "21 min 18 s").
#[must_use]
pub fn paper_duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match (s / 60, s % 60) {
        (0, s) => format!("{s} s"),
        (m, 0) => format!("{m} min"),
        (m, s) => format!("{m} min {s} s"),
    }
}
