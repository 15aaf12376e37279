//! The reference values `validate` compares with. Nothing here uses `pdm_kernel`.
//!
//! * sphere → face: exactly 1/6 (a centred sphere radiates uniformly; each face subtends 4π/6);
//! * face → sphere: exactly 4πR²/(6·36) (reciprocity; π/54 for R = 1);
//! * face → face, R = 0: exact, Howell's C-11 (opposite) and C-14 (adjacent) for squares of
//!   side 6 (the unit-square values 0.1998248956983874 and 0.2000437760754032);
//! * face → face, R > 0: [`crate::reference::cube`], a deterministic integration that shares no
//!   code with the kernel's quadrature, with its error estimate;
//! * face sums: exactly 1.

use std::time::Instant;

use super::scene::{is_opposite, FACE_PAIRS, SIDE};
use super::ValidateError;
use crate::reference::closed_form::{cube_face_to_centred_sphere, parallel_rectangles, perpendicular_rectangles};

/// Where the face → face reference came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// Closed forms C-11 and C-14 (empty cube).
    ClosedForm,
    /// `pdm_host::reference::cube` (sphere as occluder), computed now.
    Independent,
    /// `pdm_host::reference::cube` for R = 1, stored ([`STORED_R1`]).
    Stored,
    /// The independent reference could not be computed (why); its values are NaN.
    Unavailable(String),
}

/// Reference values, in the shapes of [`super::Values`].
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// 1/6 for each face; `None` without a sphere.
    pub sphere_to_face: Option<[f64; 6]>,
    /// 4πR²/(6·36) for each face; `None` without a sphere.
    pub face_to_sphere: Option<[f64; 6]>,
    /// For the 15 pairs of [`FACE_PAIRS`].
    pub face_to_face: [f64; 15],
    /// Uncertainty (absolute) of each face → face value; 0 for closed forms.
    pub face_to_face_uncertainty: [f64; 15],
    /// 1 for each face.
    pub face_sum: [f64; 6],
    /// F between adjacent faces.
    pub adjacent: f64,
    /// F between opposite faces.
    pub opposite: f64,
    /// Absolute uncertainty of `adjacent`.
    pub adjacent_uncertainty: f64,
    /// Absolute uncertainty of `opposite`.
    pub opposite_uncertainty: f64,
    /// Where the face → face values came from.
    pub source: Source,
    /// Seconds spent computing the reference.
    pub seconds: f64,
}

impl Reference {
    /// 4·F_adj + F_opp + F_face→sphere − 1 (zero up to the reference's own error).
    #[must_use]
    pub fn sum_rule_residual(&self) -> f64 {
        let to_sphere = self.face_to_sphere.map_or(0.0, |f| f[0]);
        4.0 * self.adjacent + self.opposite + to_sphere - 1.0
    }

    /// One line saying what the face → face reference is.
    #[must_use]
    pub fn describe(&self) -> String {
        match &self.source {
            Source::ClosedForm => "face -> face: exact, Howell C-11 (opposite) and C-14 (adjacent)".into(),
            Source::Unavailable(why) => format!("face -> face: unavailable ({why})"),
            Source::Independent | Source::Stored => format!(
                "face -> face: independent host integration, pdm_host::reference::cube{}; \
                 uncertainty {:.0e} (adjacent), {:.0e} (opposite)",
                if self.source == Source::Stored { " (stored; --recompute-reference)" } else { "" },
                self.adjacent_uncertainty,
                self.opposite_uncertainty
            ),
        }
    }
}

/// `cube_face_factors(6, 1)` (adjacent, opposite, their error estimates), stored because it
/// takes seconds (reproduce: `cargo run --release -p pdm-host --example cube_reference`); `pdm-ff validate --recompute-reference` recomputes it, and the unit test
/// `stored_reference_matches_cube_module` checks it.
pub const STORED_R1: (f64, f64, f64, f64) =
    (0.19689310669952767, 0.15424993146874516, 6.071532165918825e-18, 2.8449465006019636e-16);

/// The independent obstructed face → face factors: (adjacent, opposite, their uncertainties),
/// from [`crate::reference::cube::face_pair_factor`] (side 6) for faces 1 → 2 and 1 → 6 (the
/// two pairs of [`crate::reference::cube::cube_face_factors`]), computed concurrently.
fn obstructed(radius: f64) -> Result<(f64, f64, f64, f64), ValidateError> {
    use crate::reference::cube::face_pair_factor;
    let (adj, opp) = rayon::join(|| face_pair_factor(SIDE, radius, 1, 2), || face_pair_factor(SIDE, radius, 1, 6));
    let none = || ValidateError::Reference(format!("pdm_host::reference::cube gave no value for R = {radius}"));
    let (adj, opp) = (adj.ok_or_else(none)?, opp.ok_or_else(none)?);
    let all = [adj.value, opp.value, adj.error, opp.error];
    if all.iter().all(|x| x.is_finite()) {
        Ok((adj.value, opp.value, adj.error, opp.error))
    } else {
        Err(none())
    }
}

/// `true` if [`compute`] integrates the independent reference (R > 0, and R ≠ 1 or
/// `recompute`); otherwise it is stored or closed-form and immediate.
#[must_use]
pub fn computes(radius: f64, recompute: bool) -> bool {
    radius > 0.0 && (radius != 1.0 || recompute)
}

/// Times of [`compute`] by radius, seconds, on a 2-core machine: up to R = 2.8 the single-thread
/// release times of `reference::cube`'s table (both face pairs one after the other, an upper
/// bound now that they run concurrently); R = 2.9: the CPU time of both threads (185 s; 1204 s
/// wall with the machine's load average at 12). Between them [`estimated_seconds`]
/// interpolates log-linearly. The cost grows steeply as the sphere approaches the faces
/// (R → 3); see VALIDATION.md.
pub const MEASURED_SECONDS: [(f64, f64); 8] =
    [(0.25, 2.1), (0.5, 1.4), (1.0, 1.7), (1.5, 2.6), (2.0, 7.4), (2.5, 19.0), (2.8, 46.0), (2.9, 185.0)];

/// Roughly how long [`compute`] takes for `radius` on the machine of [`MEASURED_SECONDS`]
/// (0 when nothing is integrated; beyond the last radius, extrapolated at the last log-slope).
#[must_use]
pub fn estimated_seconds(radius: f64, recompute: bool) -> f64 {
    if !computes(radius, recompute) {
        return 0.0;
    }
    let log_interp = |(r0, t0): (f64, f64), (r1, t1): (f64, f64)| {
        let x = (radius - r0) / (r1 - r0);
        (f64::ln(t0) + x * (f64::ln(t1) - f64::ln(t0))).exp()
    };
    let mut last = None;
    for w in MEASURED_SECONDS.windows(2) {
        let [a, b] = *w else { continue };
        if radius <= a.0 {
            return a.1;
        }
        if radius <= b.0 {
            return log_interp(a, b);
        }
        last = Some((a, b));
    }
    last.map_or(0.0, |(a, b)| log_interp(a, b))
}

/// The reference values for a centred sphere of radius `radius` (0 = empty cube); for R = 1
/// the stored [`STORED_R1`] unless `recompute`. Never fails: if the independent reference
/// cannot be computed its values are NaN and `source` says why.
#[must_use]
pub fn compute(radius: f64, recompute: bool) -> Reference {
    let start = Instant::now();
    let (adjacent, opposite, adjacent_uncertainty, opposite_uncertainty, source) =
        if !computes(radius, recompute) && radius > 0.0 {
            let (a, o, ua, uo) = STORED_R1;
            (a, o, ua, uo, Source::Stored)
        } else if radius > 0.0 {
            match obstructed(radius) {
                Ok((a, o, ua, uo)) => (a, o, ua, uo, Source::Independent),
                Err(e) => (f64::NAN, f64::NAN, f64::NAN, f64::NAN, Source::Unavailable(e.to_string())),
            }
        } else {
            (
                perpendicular_rectangles(SIDE, SIDE, SIDE),
                parallel_rectangles(SIDE, SIDE, SIDE),
                0.0,
                0.0,
                Source::ClosedForm,
            )
        };
    let mut face_to_face = [0.0; 15];
    let mut face_to_face_uncertainty = [0.0; 15];
    for ((&(a, b), f), u) in FACE_PAIRS.iter().zip(&mut face_to_face).zip(&mut face_to_face_uncertainty) {
        (*f, *u) = if is_opposite(a, b) { (opposite, opposite_uncertainty) } else { (adjacent, adjacent_uncertainty) };
    }
    let sphere = radius > 0.0;
    Reference {
        sphere_to_face: sphere.then_some([1.0 / 6.0; 6]),
        face_to_sphere: sphere.then(|| [cube_face_to_centred_sphere(SIDE, radius); 6]),
        face_to_face,
        face_to_face_uncertainty,
        face_sum: [1.0; 6],
        adjacent,
        opposite,
        adjacent_uncertainty,
        opposite_uncertainty,
        source,
        seconds: start.elapsed().as_secs_f64(),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn empty_cube_reference_closes() {
        let r = compute(0.0, false);
        assert!((r.adjacent - 0.2000437760754032).abs() < 1e-15);
        assert!((r.opposite - 0.1998248956983874).abs() < 1e-15);
        assert!(r.sum_rule_residual().abs() < 1e-14, "{}", r.sum_rule_residual());
        assert!(r.sphere_to_face.is_none());
    }

    #[test]
    fn reference_time_estimate() {
        assert_eq!(estimated_seconds(0.0, true), 0.0);
        assert_eq!(estimated_seconds(1.0, false), 0.0);
        assert!(estimated_seconds(1.0, true) > 0.0);
        let mut last = 0.0;
        for r in [2.0, 2.5, 2.8, 2.9, 2.99] {
            let t = estimated_seconds(r, false);
            assert!(t > last, "R = {r}: {t} s");
            last = t;
        }
        assert!(estimated_seconds(2.9, false) > 60.0);
    }

    /// The stored R = 1 values are what the reference module computes (≈ 15 s).
    #[test]
    fn stored_reference_matches_cube_module() {
        let fresh = compute(1.0, true);
        let stored = compute(1.0, false);
        assert_eq!(fresh.source, Source::Independent);
        assert_eq!(stored.source, Source::Stored);
        assert!((fresh.adjacent - stored.adjacent).abs() <= 1e-14 + stored.adjacent_uncertainty);
        assert!((fresh.opposite - stored.opposite).abs() <= 1e-14 + stored.opposite_uncertainty);
        assert!(stored.sum_rule_residual().abs() < 1e-10, "{}", stored.sum_rule_residual());
    }
}
