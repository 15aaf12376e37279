//! `pdm-ff matrix` end to end: output files, exit codes, one-line errors.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use std::process::{Command, Output};

fn pdm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdm-ff")).args(args).output().expect("run pdm-ff")
}

fn example(name: &str) -> String {
    format!("{}/../examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn writes_json_and_csv_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("cube.json");
    let out = pdm(&["matrix", &example("cube.toml"), "--tolerance", "1e-8", "--output", json.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("row sum") && stdout.contains("floor"), "{stdout}");
    let value: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let names = value["surfaces"]["names"].as_array().unwrap();
    assert_eq!(names.len(), 6);
    let f = value["surfaces"]["factors"][0][1].as_f64().unwrap();
    let exact = pdm_host::reference::closed_form::parallel_rectangles(1.0, 1.0, 1.0); // C-11
    assert!((f - exact).abs() < 1e-8, "{f}");
    assert_eq!(value["patches"]["names"].as_array().unwrap().len(), 24);
    // Only the output file is left in the folder (no temporary files).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    let csv = dir.path().join("cube.csv");
    let out = pdm(&["matrix", &example("cube.toml"), "--order", "8", "--output", csv.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("level,from,to,area_from,factor,error\nsurface,floor,ceiling,"), "{text}");
    assert_eq!(text.lines().filter(|l| l.starts_with("surface,")).count(), 30);

    // NumPy: an .npz archive (a zip of .npy files) and a bare .npy of the surface matrix.
    for name in ["cube.npz", "cube.NPY"] {
        let path = dir.path().join(name);
        let out = pdm(&["matrix", &example("cube.toml"), "--order", "6", "--output", path.to_str().unwrap()]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let bytes = std::fs::read(&path).unwrap();
        let magic: &[u8] = if name.ends_with("npz") { b"PK" } else { b"\x93NUMPY" };
        assert!(bytes.starts_with(magic), "{name}");
    }
}

#[test]
fn bad_input_is_one_line_and_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[[surface]]\nname = \"d\"\nkind = \"disk\"\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = -1\n",
    )
    .unwrap();
    for args in [
        vec!["matrix", bad.to_str().unwrap()],
        vec!["matrix", "/nonexistent/scene.toml"],
        vec!["matrix", bad.to_str().unwrap(), "--tolerance", "-1"],
        vec!["matrix", bad.to_str().unwrap(), "--absolute", "-1e-9"],
        vec!["matrix", bad.to_str().unwrap(), "--absolute", "nan"],
        vec!["matrix", bad.to_str().unwrap(), "--absolute", "1e-9", "--order", "8"],
    ] {
        let out = pdm(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error:"), "{stderr}");
    }
    let out = pdm(&["matrix", bad.to_str().unwrap(), "--absolute", "-1e-9"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("-1e-9") && stderr.contains("absolute tolerance must be in 0..=1"), "{stderr}");
    let out = pdm(&["matrix", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("bad.toml:1: surface #1 'd': field `radius` -1 must be positive"), "{stderr}");
    // An unknown output format is refused before any work, and nothing is written.
    let out = pdm(&["matrix", &example("cube.toml"), "--output", dir.path().join("m.xlsx").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!dir.path().join("m.xlsx").exists());
    // An output folder that does not exist is refused before any work, naming the path.
    let missing = dir.path().join("no such folder").join("m.json");
    let out = pdm(&["matrix", &example("sphere_in_cube.toml"), "--output", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no such folder") && stderr.contains("cannot write there"), "{stderr}");
    assert!(!String::from_utf8_lossy(&out.stdout).contains("row sum"), "it ran first");
    // A zero edge is named as such, not as the other edge.
    std::fs::write(
        &bad,
        "[[surface]]\nname = \"a\"\nkind = \"rectangle\"\norigin = [0, 0, 0]\nedge_t = [0, 0, 0]\nedge_s = [0, 1, 0]\n",
    )
    .unwrap();
    let out = pdm(&["matrix", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("field `edge_t`") && stderr.contains("is zero"), "{stderr}");
    // A value of the wrong type names its field; a length whose square underflows too.
    for (text, field) in [
        (
            "kind = \"rectangle\"\norigin = [0, 0, 0]\nedge_t = [1, 0, 0]\nedge_s = [0, 1, 0]\nsubdivide = [-2, 2]\n",
            "field `subdivide`",
        ),
        ("kind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1e-300\n", "field `radius` 1e-300 is out of range"),
    ] {
        std::fs::write(&bad, format!("[[surface]]\nname = \"a\"\n{text}")).unwrap();
        let out = pdm(&["matrix", bad.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{text}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(field), "{stderr}");
    }
}

/// Runs `pdm-ff` with its stdout closed at once, before anything is printed: the exit status
/// and what it wrote to stderr.
fn with_closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    use std::io::Read as _;
    let mut child = Command::new(env!("CARGO_BIN_EXE_pdm-ff"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let mut stderr = String::new();
    child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    (child.wait().unwrap(), stderr)
}

/// A reader that closes the pipe early (`pdm-ff matrix … | head -2`) ends the run quietly with
/// the code a shell gives a process SIGPIPE ended (141), not a panic; the `--output` file is
/// still written.
#[test]
fn a_closed_pipe_ends_quietly_and_the_output_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("m.json");
    let (status, stderr) = with_closed_stdout(&["matrix", &example("cube.toml"), "--output", json.to_str().unwrap()]);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(status.success() || status.code() == Some(141), "{status:?}: {stderr}");
    assert!(json.exists(), "{stderr}");
    // Elsewhere a write to the closed stdout ends the run (exit code 141), without a panic: a
    // slice's summary line, after its file is written.
    let slice = dir.path().join("s.json");
    let (status, stderr) =
        with_closed_stdout(&["matrix", &example("cube.toml"), "--shard", "1/2", "--output", slice.to_str().unwrap()]);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(status.code(), Some(141), "{stderr}");
    assert!(slice.exists());
}

/// Three slices computed separately and merged give the matrix of the whole run, value for
/// value; a missing or repeated slice is refused.
#[test]
fn slices_merge_into_the_whole() {
    let dir = tempfile::tempdir().unwrap();
    let scene = example("closed_cylinder.toml");
    let whole = dir.path().join("whole.json");
    let out = pdm(&["matrix", &scene, "--order", "8", "--output", whole.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut parts = Vec::new();
    for k in 1..=3 {
        let part = dir.path().join(format!("part{k}.json"));
        let shard = format!("{k}/3");
        let out = pdm(&["matrix", &scene, "--order", "8", "--shard", &shard, "--output", part.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stdout).starts_with(&format!("slice {k}/3 of")));
        parts.push(part.to_str().unwrap().to_string());
    }
    let merged = dir.path().join("merged.json");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(String::as_str));
    args.extend(["--output", merged.to_str().unwrap()]);
    let out = pdm(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let read =
        |p: &std::path::Path| -> serde_json::Value { serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap() };
    let (a, b) = (read(&whole), read(&merged));
    assert_eq!(a["surfaces"]["factors"], b["surfaces"]["factors"]);
    assert_eq!(a["patches"]["factors"], b["patches"]["factors"]);
    assert_eq!(a["diagnostics"]["pairs_integrated"], b["diagnostics"]["pairs_integrated"]);

    let out = pdm(&["merge", &parts[0], &parts[1]]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("slice 3/3 is missing"));
    let out = pdm(&["merge", &parts[0], &parts[1], &parts[1]]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("slice 2/3 is given twice"));
    let out = pdm(&["matrix", &scene, "--shard", "4/3", "--output", "x.json"]);
    assert_eq!(out.status.code(), Some(2));
}

fn pdm_in(dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdm-ff")).current_dir(dir).args(args).output().expect("run pdm-ff")
}

/// A View3D input file runs as it is: rows named as in it, View3D's own settings reported as
/// notes; its slices, computed in one folder and merged from another, find the file again.
#[test]
fn view3d_file_runs_unchanged_and_its_slices_merge_from_anywhere() {
    let models = tempfile::tempdir().unwrap();
    let vs3 = "T two squares\nC encl=0 maxU=8\nF 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 1 0 1\n\
               V 7 1 1 1\nV 8 0 1 1\nS 1 1 2 3 4 0 0 0.9 low\nS 2 5 8 7 6 0 0 0.9 high ! facing down\nE\n";
    std::fs::write(models.path().join("two.vs3"), vs3).unwrap();
    let out = pdm_in(models.path(), &["matrix", "two.vs3", "--tolerance", "1e-10"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let low = stdout.lines().find(|l| l.starts_with("low ")).unwrap_or_else(|| panic!("{stdout}"));
    assert!(low.contains("0.1998248957"), "C-11: {low}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("note: two.vs3: maxU = 8"));

    let work = tempfile::tempdir().unwrap();
    let file = models.path().join("two.vs3");
    let mut parts = Vec::new();
    for k in 1..=2 {
        let part = work.path().join(format!("p{k}.json"));
        let shard = format!("{k}/2");
        let out = pdm(&["matrix", file.to_str().unwrap(), "--shard", &shard, "--output", part.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        parts.push(part.to_str().unwrap().to_string());
    }
    let elsewhere = tempfile::tempdir().unwrap();
    let out = pdm_in(elsewhere.path(), &["merge", &parts[0], &parts[1]]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("0.1998248957"));

    std::fs::write(models.path().join("bad.vs3"), "F 3\nV 1 0 0 0\nS 1 1 2 3 0 0 0 0.9 a\n").unwrap();
    let out = pdm_in(models.path(), &["matrix", "bad.vs3"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("error: bad.vs3:3: surface 1 refers to vertex 2"), "{stderr}");
}
