//! `pdm-ff validate` end to end: the JSON contract, bad input, and real checks of the kernel
//! (the empty cube against C-11/C-14, the paper's grid against 1/6).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::process::{Command, Output};

use serde_json::Value;

const PAIRS: [&str; 15] =
    ["1-2", "1-3", "1-4", "1-5", "1-6", "2-3", "2-4", "2-5", "2-6", "3-4", "3-5", "3-6", "4-5", "4-6", "5-6"];
const C11: f64 = 0.1998248956983874; // Howell C-11, unit squares at distance 1
const C14: f64 = 0.2000437760754032; // Howell C-14, unit squares with a common edge

fn pdm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdm-ff")).args(args).output().expect("run pdm-ff")
}

fn validate_json(args: &[&str]) -> Value {
    let mut all = vec!["validate", "--format", "json"];
    all.extend_from_slice(args);
    let out = pdm(&all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "pdm {all:?} failed: {stderr}");
    // Nothing but the JSON object on stdout.
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("stdout is not one JSON value: {e}"))
}

fn numbers(v: &Value, n: usize) -> Vec<f64> {
    let a = v.as_array().unwrap_or_else(|| panic!("not an array: {v}"));
    assert_eq!(a.len(), n, "{v}");
    a.iter().map(|x| x.as_f64().unwrap_or_else(|| panic!("not a number: {x}"))).collect()
}

fn pair_numbers(v: &Value) -> Vec<f64> {
    let o = v.as_object().unwrap_or_else(|| panic!("not an object: {v}"));
    assert_eq!(o.len(), 15, "{v}");
    PAIRS.iter().map(|k| o.get(*k).and_then(Value::as_f64).unwrap_or_else(|| panic!("no number at {k}: {v}"))).collect()
}

fn is_opposite(pair: &str) -> bool {
    matches!(pair, "1-6" | "2-3" | "4-5")
}

#[test]
fn json_contract_small_grid() {
    let j = validate_json(&["--sphere-grid", "2x4", "--face-grid", "2", "--order", "3", "--repeat", "1"]);
    let s2f = numbers(&j["sphere_to_face"], 6);
    assert!(s2f.iter().all(|f| (f - 1.0 / 6.0).abs() < 0.05), "{s2f:?}");
    let ff = pair_numbers(&j["face_to_face"]);
    assert!(ff.iter().all(|f| *f > 0.1 && *f < 0.3), "{ff:?}");
    numbers(&j["face_sum"], 6);
    let r = &j["reference"];
    assert_eq!(numbers(&r["sphere_to_face"], 6), vec![1.0 / 6.0; 6]);
    assert_eq!(numbers(&r["face_sum"], 6), vec![1.0; 6]);
    let f2s = numbers(&r["face_to_sphere"], 6);
    assert!((f2s[0] - std::f64::consts::PI / 54.0).abs() < 1e-15);
    let o = r["face_to_face"].as_object().unwrap();
    assert_eq!(o.len(), 15);
    assert!(PAIRS.iter().all(|k| o.contains_key(*k)));
    // Settings.
    assert_eq!(j["mode"], "paper");
    assert_eq!(j["order"], 3);
    assert_eq!(j["precision"], "f64");
    assert_eq!(j["sphere_radius"], 1.0);
    assert_eq!(j["face_grid"], 2);
    assert_eq!(j["sphere_grid"], serde_json::json!([2, 4]));
    assert_eq!(j["patches"], 8 + 6 * 4);
    assert!(j["seconds"].as_f64().unwrap() >= 0.0);
    assert!(j["paper"].is_null(), "not one of the paper's grids");
}

#[test]
fn json_paper_grid_86_sphere_to_face_within_one_percent() {
    let j = validate_json(&["--patches", "86", "--repeat", "1"]);
    assert_eq!(j["patches"], 86);
    assert_eq!(j["order"], 5);
    assert_eq!(j["sphere_grid"], serde_json::json!([4, 8]));
    let s2f = numbers(&j["sphere_to_face"], 6);
    for (f, v) in s2f.iter().enumerate() {
        println!("paper mode, 86 patches: sphere -> face {}: {v:.9e}", f + 1);
        assert!((v - 1.0 / 6.0).abs() < 0.01 / 6.0, "face {}: {v}", f + 1);
    }
    // The paper's numbers are reported beside ours.
    let paper = numbers(&j["paper"]["sphere_to_face"], 6);
    assert_eq!(paper[0], 1.6735e-1);
    assert_eq!(paper[1], 1.6693e-1);
    assert_eq!(j["paper"]["face_to_face"]["1-2"], 2.0341e-1);
}

/// The empty cube in accurate mode: the shared-edge and shared-vertex transforms must give the
/// closed forms to 1e-9, and each face's factors must sum to 1.
#[test]
fn empty_cube_accurate_matches_c11_c14() {
    let j = validate_json(&["--sphere-radius", "0", "--mode", "accurate", "--face-grid", "2", "--order", "10"]);
    assert!(j["sphere_to_face"].is_null());
    assert!(j["reference"]["sphere_to_face"].is_null());
    let ff = pair_numbers(&j["face_to_face"]);
    let reference = pair_numbers(&j["reference"]["face_to_face"]);
    for ((pair, ours), re) in PAIRS.iter().zip(&ff).zip(&reference) {
        let exact = if is_opposite(pair) { C11 } else { C14 };
        assert!((re - exact).abs() < 1e-15, "{pair}: reference {re}");
        assert!((ours - exact).abs() < 1e-9 * exact, "{pair}: {ours} vs {exact}");
    }
    for (f, s) in numbers(&j["face_sum"], 6).iter().enumerate() {
        assert!((s - 1.0).abs() < 1e-9, "face {} sums to {s}", f + 1);
    }
    assert_eq!(j["mode"], "accurate");
    assert_eq!(j["sphere_radius"], 0.0);
}

/// `--tolerance` selects the adaptive per-pair mode; on the empty cube (only touching and
/// smooth pairs, where the estimates are by order doubling) every factor meets it.
#[test]
fn tolerance_mode_meets_its_tolerance_on_the_empty_cube() {
    for tol in [1e-5, 1e-9] {
        let t = format!("{tol:e}");
        let j = validate_json(&["--sphere-radius", "0", "--tolerance", &t, "--face-grid", "2"]);
        assert_eq!(j["mode"], "accurate");
        assert_eq!(j["tolerance"], tol);
        let ff = pair_numbers(&j["face_to_face"]);
        for (pair, ours) in PAIRS.iter().zip(&ff) {
            let exact = if is_opposite(pair) { C11 } else { C14 };
            assert!((ours - exact).abs() <= tol * exact, "{pair} at {t}: {ours} vs {exact}");
        }
        // The kernel's own estimate is reported, meets the tolerance here, and bounds the
        // actual errors.
        let estimate = j["estimated_error"].as_f64().expect("estimated_error in tolerance mode");
        let worst = PAIRS
            .iter()
            .zip(&ff)
            .map(|(pair, ours)| {
                let exact = if is_opposite(pair) { C11 } else { C14 };
                (ours - exact).abs() / exact
            })
            .fold(0.0, f64::max);
        assert!(worst <= estimate && estimate <= tol, "at {t}: actual {worst:e}, estimate {estimate:e}");
    }
    // Fixed orders have no estimate.
    let j = validate_json(&["--sphere-radius", "0", "--face-grid", "2", "--mode", "accurate"]);
    assert!(j["estimated_error"].is_null());
}

/// Across the sphere's shadow the reported estimate is honest: at least the largest actual
/// error of the 21 factors (86-patch start, tolerance 1e-4: measured actual 1.7e-6, estimate
/// 9.8e-5).
#[test]
#[ignore = "slow (about 40 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_tolerance_mode_estimate_bounds_the_errors_with_the_sphere() {
    let j = validate_json(&["--tolerance", "1e-4", "--patches", "86"]);
    let estimate = j["estimated_error"].as_f64().expect("estimated_error in tolerance mode");
    let mut worst: f64 = 0.0;
    for key in ["sphere_to_face", "face_sum"] {
        for e in j["relative_error"][key].as_array().expect(key) {
            worst = worst.max(e.as_f64().expect("number").abs());
        }
    }
    for e in j["relative_error"]["face_to_face"].as_object().expect("face_to_face").values() {
        worst = worst.max(e.as_f64().expect("number").abs());
    }
    assert!(worst > 0.0 && worst <= estimate, "actual {worst:e}, estimate {estimate:e}");
}

#[test]
fn both_precisions_nest_f32() {
    let j = validate_json(&["--sphere-radius", "0", "--face-grid", "2", "--precision", "both", "--repeat", "1"]);
    assert_eq!(j["precision"], "f64");
    assert_eq!(j["f32"]["precision"], "f32");
    let a = pair_numbers(&j["face_to_face"]);
    let b = pair_numbers(&j["f32"]["face_to_face"]);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-5 * x, "f64 {x} vs f32 {y}");
    }
}

/// f32 accurate mode on the paper's 280-patch grid with the sphere: every face pair computes
/// (the contour form's unoccluded pairs whose terms cancel past √ε in f32 go to the 4-D rules
/// instead of being refused) and stays within 5e-6 of f64 (measured 2.4e-6 at orders 5/6; at
/// 8/12 every f32 value is within 9.3e-7 of the references).
#[test]
fn f32_accurate_mode_computes_every_pair_of_the_280_patch_grid() {
    let j = validate_json(&[
        "--mode",
        "accurate",
        "--patches",
        "280",
        "--order",
        "5",
        "--singular-order",
        "6",
        "--precision",
        "both",
        "--repeat",
        "1",
    ]);
    let a = pair_numbers(&j["face_to_face"]);
    let b = pair_numbers(&j["f32"]["face_to_face"]);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 5e-6 * x, "f64 {x} vs f32 {y}");
    }
}

#[test]
fn table_fits_80_columns_and_csv_has_rows() {
    for args in [
        &["validate", "--patches", "86", "--repeat", "1"][..],
        &["validate", "--sphere-radius", "0", "--face-grid", "2", "--precision", "both", "--repeat", "1"][..],
    ] {
        let out = pdm(args);
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        for line in text.lines() {
            assert!(line.chars().count() <= 80, "{} columns: {line}", line.chars().count());
        }
        assert!(text.contains("Table 3") && text.contains("Table 4"), "{text}");
    }
    let out = pdm(&["validate", "--format", "csv", "--sphere-radius", "0", "--face-grid", "2", "--repeat", "1"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("table,item,precision,paper,ours,reference,relative_error,reference_uncertainty"));
    assert_eq!(text.lines().filter(|l| l.starts_with("face_to_face,")).count(), 15);
    assert_eq!(text.lines().filter(|l| l.starts_with("face_sum,")).count(), 6);
    assert!(text.lines().all(|l| l.split(',').count() == 8), "{text}");
}

/// Bad input: one line on stderr naming the value, a non-zero exit, no panic.
#[test]
fn bad_input_is_one_line_naming_the_value() {
    let cases: &[(&[&str], &str)] = &[
        (&["--sphere-radius", "3"], "3"),
        (&["--sphere-radius", "-0.5"], "-0.5"),
        (&["--sphere-radius", "nan"], "nan"),
        (&["--sphere-radius", "abc"], "abc"),
        (&["--order", "0"], "0"),
        (&["--order", "99"], "99"),
        (&["--order", "five"], "five"),
        (&["--singular-order", "40"], "40"),
        (&["--face-grid", "0"], "0"),
        (&["--face-grid", "-2"], "-2"),
        (&["--sphere-grid", "4x0"], "4x0"),
        (&["--sphere-grid", "-4x8"], "-4x8"),
        (&["--sphere-grid", "4by8"], "4by8"),
        (&["--patches", "100"], "100"),
        (&["--precision", "f16"], "f16"),
        (&["--format", "xml"], "xml"),
        (&["--mode", "fast"], "fast"),
        (&["--repeat", "0"], "0"),
        (&["--tolerance", "0"], "0"),
        (&["--tolerance", "1e-20"], "1e-20"),
        (&["--tolerance", "nan"], "nan"),
        (&["--tolerance", "-1e-3"], "-1e-3"),
        (&["--tolerance", "inf"], "inf"),
        (&["--tolerance", "0.5"], "0.5"),
        (&["--order", "33"], "33"),
        (&["--order", "-1"], "-1"),
        (&["--singular-order", "0"], "0"),
        (&["--face-grid", "65"], "65"),
        (&["--sphere-grid", "257x8"], "257x8"),
        (&["--repeat", "1001"], "1001"),
        (&["--threads", "-1"], "-1"),
        (&["--threads", "5000"], "5000"),
        // Paper mode at 7e12 kernel evaluations: hours.
        (&["--sphere-grid", "256x256", "--order", "32"], "256x256"),
        (&["--mode", "paper", "--tolerance", "1e-6"], "tolerance"),
        (&["--bogus"], "--bogus"),
        (&["--patches", "86", "--face-grid", "4"], "--face-grid"),
    ];
    for (args, named) in cases {
        let mut all = vec!["validate"];
        all.extend_from_slice(args);
        let out = pdm(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{all:?} succeeded");
        assert_eq!(out.status.code(), Some(2), "{all:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{all:?}: {stderr}");
        let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
        assert_eq!(lines.len(), 1, "{all:?}: not one line: {stderr}");
        assert!(lines[0].starts_with("error:"), "{all:?}: {stderr}");
        assert!(lines[0].contains(named), "{all:?}: does not name {named}: {stderr}");
        assert!(out.stdout.is_empty(), "{all:?}: wrote to stdout");
    }
}

/// The tolerance mode at the largest sample capacity (order 28: CAP = 1024) used to overflow
/// rayon's 2 MiB worker stacks; the workers now get stacks sized for the capacity
/// (`pdm_host::validate::stack`). Also in debug builds.
#[test]
#[ignore = "slow (about 25 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_largest_capacity_in_tolerance_mode_does_not_overflow() {
    let j = validate_json(&["--tolerance", "1e-3", "--order", "28"]);
    let s2f = numbers(&j["sphere_to_face"], 6);
    assert!(s2f.iter().all(|f| (f - 1.0 / 6.0).abs() < 1e-3), "{s2f:?}");
}

#[test]
fn help_and_no_subcommand() {
    let out = pdm(&["validate", "--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("--sphere-radius") && text.contains("--patches"), "{text}");
    let out = pdm(&[]);
    assert!(!out.status.success());
}

/// `pdm-ff validate` with no options: the paper's printed values, our paper mode and our
/// accurate mode side by side at the 280-patch grid. Each row's last column is the accurate
/// mode's worst relative error against the references (1/6, the independent cube reference,
/// 1), within 1e-10 at its default orders (issue 12, item 3); the paper mode's plain sums for
/// touching patches are visibly off.
#[test]
fn no_options_prints_the_overview_at_280_patches() {
    let out = pdm(&["validate"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("280 patches (sphere 8x8, faces 6x6)"), "{text}");
    let err = |token: &str| token.parse::<f64>().unwrap_or_else(|_| panic!("{token} in {text}"));
    for label in
        ["sphere -> face 1, 6", "sphere -> face 2-5", "face -> adjacent (12)", "face -> opposite (3)", "face sums (6)"]
    {
        let line = text.lines().find(|l| l.starts_with(label)).unwrap_or_else(|| panic!("no {label}: {text}"));
        let tokens: Vec<&str> = line[label.len()..].split_whitespace().collect();
        assert_eq!(tokens.len(), 7, "{line}");
        let (paper_mode, accurate) = (err(tokens[4]), err(tokens[6]));
        assert!(accurate < 1e-10, "{line}");
        if label.starts_with("face -> adjacent") || label.starts_with("face sums") {
            assert!(paper_mode > 1e-2, "{line}");
        }
    }
    assert!(text.lines().any(|l| l.starts_with("time") && l.contains("26 min 18 s")), "{text}");
}
