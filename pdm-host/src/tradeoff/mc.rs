//! A Monte Carlo ray estimator of sphere → face factors in the paper's scene, for the
//! error-against-time comparison. Shares no code with the kernel.
//!
//! Each ray starts at a uniformly distributed point of the sphere (radius R, centred in the cube
//! of side 6) in a cosine-distributed direction about the outward normal; it leaves the cube
//! through exactly one face (the sphere is convex and inside the cube, so nothing blocks), and
//! F_{sphere→f} is the fraction of rays through face f. Its standard error is
//! √(F(1 − F)/N), i.e. a relative error of √5/√N for F = 1/6.
//!
//! Rays are drawn in chunks of [`CHUNK`] with independent SplitMix64 streams
//! ([`rand_xoshiro::SplitMix64`], uniform doubles with 53 random bits from `rand`) seeded from
//! (seed, chunk index), so the estimate does not depend on the number of threads; chunks run
//! on the current rayon pool.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::SplitMix64;
use rayon::prelude::*;

/// Rays per independent stream.
pub const CHUNK: u64 = 1 << 16;

/// Face (0-based, the validation's numbering 1..6 minus one) through which the ray p + t·d,
/// t > 0, leaves the cube |x|, |y|, |z| ≤ h, and the t of the exit point.
fn exit_face(p: [f64; 3], d: [f64; 3], h: f64) -> (usize, f64) {
    let mut best = f64::INFINITY;
    let mut face = 0;
    // (axis, positive side) → face index: x− 4, x+ 5, y− 2, y+ 3, z− 6, z+ 1 (0-based below).
    const FACE: [[usize; 2]; 3] = [[3, 4], [1, 2], [5, 0]];
    for ((&pa, &da), sides) in p.iter().zip(&d).zip(&FACE) {
        if da == 0.0 {
            continue;
        }
        let positive = da > 0.0;
        let t = ((if positive { h } else { -h }) - pa) / da;
        if t < best {
            best = t;
            face = if positive { sides[1] } else { sides[0] };
        }
    }
    (face, best)
}

/// Shoots `rays` rays from the sphere of radius `radius` centred in the cube of half side
/// `half_side` (see the module docs) and counts them in `bins` bins: `bin(face, exit point)`
/// (face 0-based in the validation's numbering) names the bin of each ray (out of range: not
/// counted).
pub fn sphere_rays(
    radius: f64,
    half_side: f64,
    rays: u64,
    seed: u64,
    bins: usize,
    bin: impl Fn(usize, [f64; 3]) -> usize + Sync,
) -> Vec<u64> {
    let chunks = rays.div_ceil(CHUNK);
    let per_chunk = |c: u64| {
        let mut rng = SplitMix64::seed_from_u64(seed ^ c.wrapping_mul(0xD1B5_4A32_D192_ED03));
        let n = CHUNK.min(rays - c * CHUNK);
        let mut hits = vec![0u64; bins];
        for _ in 0..n {
            // Uniform point on the sphere (Archimedes: z uniform).
            let z = 1.0 - 2.0 * rng.random::<f64>();
            let phi = std::f64::consts::TAU * rng.random::<f64>();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let nrm = [r * phi.cos(), r * phi.sin(), z];
            // Cosine-distributed direction about the normal (Malley), in an orthonormal frame
            // (Duff et al. 2017).
            let u1 = rng.random::<f64>();
            let a = std::f64::consts::TAU * rng.random::<f64>();
            let (lx, ly, lz) = (u1.sqrt() * a.cos(), u1.sqrt() * a.sin(), (1.0 - u1).sqrt());
            let sign = if nrm[2] >= 0.0 { 1.0 } else { -1.0 };
            let aa = -1.0 / (sign + nrm[2]);
            let b = nrm[0] * nrm[1] * aa;
            let t1 = [1.0 + sign * nrm[0] * nrm[0] * aa, sign * b, -sign * nrm[0]];
            let t2 = [b, sign + nrm[1] * nrm[1] * aa, -nrm[1]];
            let d = [
                lx * t1[0] + ly * t2[0] + lz * nrm[0],
                lx * t1[1] + ly * t2[1] + lz * nrm[1],
                lx * t1[2] + ly * t2[2] + lz * nrm[2],
            ];
            let p = [radius * nrm[0], radius * nrm[1], radius * nrm[2]];
            let (face, t) = exit_face(p, d, half_side);
            let x = [p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]];
            if let Some(h) = hits.get_mut(bin(face, x)) {
                *h += 1;
            }
        }
        hits
    };
    (0..chunks).into_par_iter().map(per_chunk).reduce(
        || vec![0u64; bins],
        |mut a, b| {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
            a
        },
    )
}

/// Hits per face (faces 1..6 at indices 0..5) for `rays` rays (see the module docs).
#[must_use]
pub fn sphere_to_faces_counts(radius: f64, half_side: f64, rays: u64, seed: u64) -> [u64; 6] {
    let v = sphere_rays(radius, half_side, rays, seed, 6, |face, _| face);
    let mut out = [0u64; 6];
    for (o, x) in out.iter_mut().zip(v) {
        *o = x;
    }
    out
}

/// F sphere → each of the K × K cells of the validation cube's faces (index face·K² + i·K + j,
/// cell (i, j) along the face's (t, s) edges as in `PatchGrid`), from `rays` rays; the sphere
/// of radius `radius` at the centre of the cube of side 6.
#[must_use]
pub fn sphere_to_face_cells(radius: f64, cells: usize, rays: u64, seed: u64) -> Vec<f64> {
    use crate::validate::scene::{FACES, HALF_SIDE};
    let k = cells.max(1);
    let cell = |x: f64| ((x * k as f64) as usize).min(k - 1);
    let counts = sphere_rays(radius, HALF_SIDE, rays, seed, 6 * k * k, |face, x| {
        let Some((o, t, s)) = FACES.get(face) else { return usize::MAX };
        let rel = [x[0] - o[0], x[1] - o[1], x[2] - o[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (a, b) = (dot(rel, *t) / dot(*t, *t), dot(rel, *s) / dot(*s, *s));
        face * k * k + cell(a.max(0.0)) * k + cell(b.max(0.0))
    });
    counts.into_iter().map(|c| c as f64 / rays.max(1) as f64).collect()
}

/// F sphere → faces 1..6 estimated from `rays` rays (see the module docs).
#[must_use]
pub fn sphere_to_faces(radius: f64, half_side: f64, rays: u64, seed: u64) -> [f64; 6] {
    let counts = sphere_to_faces_counts(radius, half_side, rays, seed);
    counts.map(|c| c as f64 / rays.max(1) as f64)
}

#[cfg(test)]
#[allow(clippy::indexing_slicing)]
mod tests {
    use super::*;

    #[test]
    fn every_ray_leaves_through_one_face_and_faces_get_one_sixth() {
        let rays = 600_000;
        let counts = sphere_to_faces_counts(1.0, 3.0, rays, 7);
        assert_eq!(counts.iter().sum::<u64>(), rays);
        let sigma = (5.0f64 / rays as f64).sqrt(); // relative standard error for F = 1/6
        for c in counts {
            let rel = (c as f64 / rays as f64 - 1.0 / 6.0).abs() * 6.0;
            assert!(rel < 5.0 * sigma, "{counts:?}");
        }
        // Deterministic for a seed, different across seeds.
        assert_eq!(sphere_to_faces_counts(1.0, 3.0, 100_000, 3), sphere_to_faces_counts(1.0, 3.0, 100_000, 3));
        assert_ne!(sphere_to_faces_counts(1.0, 3.0, 100_000, 3), sphere_to_faces_counts(1.0, 3.0, 100_000, 4));
    }

    /// Cells add up to faces, and a cell's estimate is within a few standard errors of its
    /// solid-angle value.
    #[test]
    fn cells_match_solid_angles() {
        let rays = 400_000;
        let cells = sphere_to_face_cells(1.0, 3, rays, 11);
        assert_eq!(cells.len(), 54);
        assert!((cells.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for face in 1..=6 {
            for (c, poly) in super::super::polygon::cube_face_cells(face, 3).iter().enumerate() {
                let exact = crate::reference::closed_form::sphere_to_polygon([0.0; 3], poly);
                let est = cells[(face - 1) * 9 + c];
                let sigma = (exact * (1.0 - exact) / rays as f64).sqrt();
                assert!((est - exact).abs() < 5.0 * sigma, "face {face} cell {c}: {est} vs {exact}");
            }
        }
    }

    #[test]
    fn exit_faces_follow_the_scene_numbering() {
        let o = [0.0; 3];
        assert_eq!(exit_face(o, [0.0, 0.0, 1.0], 3.0), (0, 3.0)); // face 1: z = +3
        assert_eq!(exit_face(o, [0.0, -1.0, 0.0], 3.0).0, 1); // face 2: y = −3
        assert_eq!(exit_face(o, [0.0, 1.0, 0.1], 3.0).0, 2); // face 3: y = +3
        assert_eq!(exit_face(o, [-1.0, 0.2, 0.0], 3.0).0, 3); // face 4: x = −3
        assert_eq!(exit_face(o, [1.0, 0.0, 0.0], 3.0).0, 4); // face 5: x = +3
        assert_eq!(exit_face(o, [0.1, 0.0, -1.0], 3.0).0, 5); // face 6: z = −3
    }
}
