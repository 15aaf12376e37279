//! The cube-and-sphere scene of the paper (section 4): deterministic reference
//! (`reference::cube`) against the closed forms, the sum rule, its own symmetry and the seeded
//! Monte Carlo estimator (`reference::monte_carlo`).
//!
//! Default tests take a few seconds in a debug build. The large Monte Carlo comparison
//! (10⁹ rays, ~100 s on 2 cores in release) and the radius sweep (~80 s) are `#[ignore]`d:
//! `cargo test --release -p pdm-host --test reference_cube -- --ignored --nocapture`.

// Test code: panicking on failure and indexing fixed-size test data is intended.
#![allow(clippy::panic, clippy::indexing_slicing, clippy::excessive_precision, clippy::unreadable_literal)]

use pdm_host::reference::closed_form::{cube_face_to_centred_sphere, parallel_rectangles, perpendicular_rectangles};
use pdm_host::reference::cube::{cube_face_factors, cube_face_factors_with_order, face_pair_factor_with_order};
use pdm_host::reference::monte_carlo::{mc_cube_factors, mc_face_pair, mc_sphere_to_face};

/// Reference values for l = 6, R = 1 (`cube_face_factors`, converged to machine precision:
/// successive Gauss orders agree to ≤ 3e-16, sum-rule residual ≤ 2e-16). Monte Carlo, 10⁹ rays
/// (seed 2024): F_adj = 0.1968967 ± 3.2e-6, F_opp = 0.1542440 ± 1.1e-5, F_face→sphere =
/// 0.0581692 ± 7.4e-6 (π/54 = 0.0581776).
const F_ADJ_L6_R1: f64 = 0.1968931066995277;
const F_OPP_L6_R1: f64 = 0.1542499314687451;

#[test]
fn no_sphere_gives_the_catalogue_values() {
    // R = 0: C-14 (adjacent) and C-11 (opposite) exactly.
    let r = cube_face_factors(6.0, 0.0);
    assert!((r.f_adjacent - 0.2000437760754032).abs() < 1e-13);
    assert!((r.f_opposite - 0.1998248956983874).abs() < 1e-13);
    assert!((r.f_adjacent - perpendicular_rectangles(1.0, 1.0, 1.0)).abs() < 1e-15);
    assert!((r.f_opposite - parallel_rectangles(1.0, 1.0, 1.0)).abs() < 1e-15);
    assert!(r.sum_rule_residual.abs() < 1e-15);
}

#[test]
fn paper_scene_l6_r1_sum_rule_and_reference_values() {
    // Fixed order 12 (value at order 20): a few seconds in debug. The default escalating
    // `cube_face_factors` is exercised by the ignored `radius_sweep`.
    let t = std::time::Instant::now();
    let r = cube_face_factors_with_order(6.0, 1.0, 12);
    eprintln!("l=6 R=1: {r:?} ({:?})", t.elapsed());
    assert!((r.f_face_to_sphere - std::f64::consts::PI / 54.0).abs() < 1e-16);
    // sum rule 4 F_adj + F_opp + π/54 = 1
    assert!(r.sum_rule_residual.abs() < 1e-10, "{}", r.sum_rule_residual);
    assert!(r.sum_rule_residual.abs() < 1e-14, "{}", r.sum_rule_residual);
    assert!(r.f_adjacent_error < 1e-10 && r.f_opposite_error < 1e-10, "{r:?}");
    assert!((r.f_adjacent - F_ADJ_L6_R1).abs() < 1e-14);
    assert!((r.f_opposite - F_OPP_L6_R1).abs() < 1e-14);
    // scale invariance: l = 1, R = 1/6
    let s = cube_face_factors_with_order(1.0, 1.0 / 6.0, 8);
    assert!((s.f_adjacent - F_ADJ_L6_R1).abs() < 1e-12 && (s.f_opposite - F_OPP_L6_R1).abs() < 1e-12, "{s:?}");
}

#[test]
fn extra_radii_close_the_sum_rule() {
    // (R, F_adj, F_opp) for l = 6, converged values (release run of `radius_sweep`)
    for &(radius, adj, opp) in
        &[(0.5, 0.1996465146972331, 0.1868695307777818), (2.0, 0.1752262403088012, 0.0663844718322179)]
    {
        let r = cube_face_factors_with_order(6.0, radius, 8);
        eprintln!("l=6 R={radius}: {r:?}");
        assert!(r.sum_rule_residual.abs() < 1e-10, "{}", r.sum_rule_residual);
        assert!((r.f_adjacent - adj).abs() < 1e-11 && (r.f_opposite - opp).abs() < 1e-10, "{r:?}");
        assert!((r.f_adjacent - adj).abs() <= 10.0 * r.f_adjacent_error.max(1e-15));
        assert!((r.f_opposite - opp).abs() <= 10.0 * r.f_opposite_error.max(1e-15));
    }
}

#[test]
fn every_face_pair_matches_its_class() {
    // Each pair uses its own geometry (different parameterisations and event sets), so this
    // exercises the method, not just a symmetric copy. Paper numbering: opposite 1-6, 2-3, 4-5.
    let opposite = |a: usize, b: usize| matches!((a.min(b), a.max(b)), (1, 6) | (2, 3) | (4, 5));
    for (a, b) in [(1, 2), (2, 1), (3, 5), (5, 3), (4, 6), (6, 2), (1, 6), (3, 2), (4, 5), (5, 4)] {
        let f = face_pair_factor_with_order(6.0, 1.0, a, b, 4).map(|f| f.value).unwrap_or(f64::NAN);
        let expect = if opposite(a, b) { F_OPP_L6_R1 } else { F_ADJ_L6_R1 };
        assert!((f - expect).abs() < 1e-10, "{a}->{b}: {f} vs {expect}");
    }
    assert_eq!(face_pair_factor_with_order(6.0, 1.0, 3, 3, 8).map(|f| f.value), Some(0.0));
    assert!(face_pair_factor_with_order(6.0, 1.0, 0, 3, 8).is_none());
    assert!(face_pair_factor_with_order(6.0, 3.0, 1, 3, 8).is_none());
}

#[test]
fn monte_carlo_agrees_with_deterministic_reference_small() {
    let rays = 4_000_000;
    let t = std::time::Instant::now();
    let Some(mc) = mc_cube_factors(6.0, 1.0, rays, 0x5EED) else { panic!("invalid scene") };
    eprintln!("MC {rays} rays: {mc:?} ({:?})", t.elapsed());
    for (est, exact) in [
        (mc.f_adjacent, F_ADJ_L6_R1),
        (mc.f_opposite, F_OPP_L6_R1),
        (mc.f_face_to_sphere, cube_face_to_centred_sphere(6.0, 1.0)),
    ] {
        assert!((est.value - exact).abs() < 4.0 * est.std_error, "{est:?} vs {exact}");
    }
    // the same rays give the same answer (seeded, independent of the thread count)
    let again = mc_face_pair(6.0, 1.0, 1, 6, rays, 0x5EED).map(|e| e.value);
    assert_eq!(again, Some(mc.f_opposite.value));
}

#[test]
fn monte_carlo_sphere_to_face_and_single_pairs() {
    let Some(s) = mc_sphere_to_face(6.0, 1.0, 2, 2_000_000, 7) else { panic!("invalid scene") };
    assert!((s.value - 1.0 / 6.0).abs() < 4.0 * s.std_error, "{s:?}");
    let Some(e) = mc_face_pair(6.0, 1.0, 3, 4, 2_000_000, 11) else { panic!("invalid scene") };
    assert!((e.value - F_ADJ_L6_R1).abs() < 4.0 * e.std_error, "{e:?}");
    let Some(e) = mc_face_pair(6.0, 0.0, 4, 5, 2_000_000, 13) else { panic!("invalid scene") };
    assert!((e.value - parallel_rectangles(1.0, 1.0, 1.0)).abs() < 4.0 * e.std_error, "{e:?}");
    let Some(e) = mc_face_pair(6.0, 1.0, 2, 0, 2_000_000, 17) else { panic!("invalid scene") };
    assert!((e.value - std::f64::consts::PI / 54.0).abs() < 4.0 * e.std_error, "{e:?}");
}

#[test]
#[ignore = "10⁹ rays: about 100 s in release on 2 cores"]
fn monte_carlo_agrees_with_deterministic_reference_large() {
    let rays = 1_000_000_000;
    let t = std::time::Instant::now();
    let Some(mc) = mc_cube_factors(6.0, 1.0, rays, 2024) else { panic!("invalid scene") };
    eprintln!("MC {rays} rays: {mc:?} ({:?})", t.elapsed());
    for (name, est, exact) in [
        ("adjacent", mc.f_adjacent, F_ADJ_L6_R1),
        ("opposite", mc.f_opposite, F_OPP_L6_R1),
        ("sphere", mc.f_face_to_sphere, cube_face_to_centred_sphere(6.0, 1.0)),
    ] {
        eprintln!(
            "{name}: MC {:.7} ± {:.1e}  deterministic {exact:.16}  ({:+.2} σ)",
            est.value,
            est.std_error,
            (est.value - exact) / est.std_error
        );
        assert!((est.value - exact).abs() < 4.0 * est.std_error, "{est:?} vs {exact}");
    }
}

#[test]
#[ignore = "radius sweep, about 80 s in release"]
fn radius_sweep() {
    for r in [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 2.8] {
        let t = std::time::Instant::now();
        let x = cube_face_factors(6.0, r);
        eprintln!(
            "l=6 R={r}: F_adj {:.16} ± {:.1e}  F_opp {:.16} ± {:.1e}  F_face→sphere {:.16}  sum−1 {:.1e}  ({:?})",
            x.f_adjacent,
            x.f_adjacent_error,
            x.f_opposite,
            x.f_opposite_error,
            x.f_face_to_sphere,
            x.sum_rule_residual,
            t.elapsed()
        );
        assert!(x.sum_rule_residual.abs() < 1e-12);
        assert!(x.f_adjacent_error < 1e-12 && x.f_opposite_error < 1e-12);
    }
}
