//! Scenes from files against exact values: each golden value cites its closed form
//! (`pdm_host::reference::closed_form`, catalogue entries C-11, C-14, C-41 of
//! `../shared/REFERENCES.md`, none of it using the kernel) or the independent cube reference.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing, clippy::panic)]

use pdm_host::reference::closed_form;
use pdm_host::scene::matrix::{compute, PairMethod};
use pdm_host::scene::report::{assemble, SceneReport};
use pdm_host::scene::{from_text, Format, Scene};

fn scene(text: &str) -> Scene {
    from_text(text, Format::Toml, "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene, method: PairMethod) -> SceneReport {
    let result = compute::<f64>(scene, method, None, 0, &|_| {}).unwrap_or_else(|e| panic!("{e:?}"));
    assemble(scene, &result, method)
}

fn index(r: &SceneReport, name: &str) -> usize {
    r.surfaces.names.iter().position(|n| n == name).unwrap_or_else(|| panic!("no surface {name}"))
}

fn factor(r: &SceneReport, a: &str, b: &str) -> f64 {
    r.surfaces.factors[index(r, a)][index(r, b)]
}

fn error(r: &SceneReport, a: &str, b: &str) -> f64 {
    r.surfaces.errors.as_ref().expect("tolerance mode")[index(r, a)][index(r, b)]
}

/// The actual error is within the tolerance and never above the estimate.
fn check(r: &SceneReport, a: &str, b: &str, exact: f64, tolerance: f64) {
    let (f, e) = (factor(r, a, b), error(r, a, b));
    let actual = (f - exact).abs();
    assert!(actual <= tolerance * exact, "{a} -> {b}: {f} against {exact}: {actual:e} > tolerance");
    assert!(actual <= e + 4.0 * f64::EPSILON * exact, "{a} -> {b}: actual {actual:e} above the estimate {e:e}");
}

const CUBE: &str = include_str!("../../examples/scenes/cube.toml");

#[test]
fn unit_cube_against_c11_and_c14() {
    let s = scene(CUBE);
    assert_eq!(s.patches.len(), 24);
    let r = run(&s, PairMethod::tolerance(1e-9));
    let opposite = closed_form::parallel_rectangles(1.0, 1.0, 1.0); // C-11
    let adjacent = closed_form::perpendicular_rectangles(1.0, 1.0, 1.0); // C-14
    for (a, b) in [("floor", "ceiling"), ("south", "north"), ("west", "east"), ("ceiling", "floor")] {
        check(&r, a, b, opposite, 1e-9);
    }
    for (a, b) in [("floor", "south"), ("floor", "east"), ("north", "ceiling"), ("west", "south"), ("east", "north")] {
        check(&r, a, b, adjacent, 1e-9);
    }
    for (i, sum) in r.surfaces.row_sums.iter().enumerate() {
        assert!((sum - 1.0).abs() < 1e-9, "row {i}: {sum}");
        assert_eq!(r.surfaces.factors[i][i], 0.0, "a flat face does not see itself");
    }
    assert!(r.diagnostics.enclosure_gaps.is_empty());
    // Patches of one face see nothing of each other: skipped, not integrated.
    assert!(r.diagnostics.pairs_skipped >= 6 * 10, "{}", r.diagnostics.pairs_skipped);
}

/// The same cube turned and moved gives the same matrix.
#[test]
fn placement_does_not_change_the_factors() {
    let s0 = scene(CUBE);
    let moved = CUBE.replace(
        "subdivide = [2, 2]",
        "subdivide = [2, 2]\nrotate = { axis = [1, 2, 3], degrees = 37 }\ntranslate = [5, -2, 0.5]",
    );
    let s1 = scene(&moved);
    let (r0, r1) = (run(&s0, PairMethod::tolerance(1e-9)), run(&s1, PairMethod::tolerance(1e-9)));
    for i in 0..6 {
        for j in 0..6 {
            let (a, b) = (r0.surfaces.factors[i][j], r1.surfaces.factors[i][j]);
            assert!((a - b).abs() <= 1e-9 * a.abs().max(1e-3), "[{i}][{j}]: {a} vs {b}");
        }
    }
}

/// A 1 cm cube 7 m from the origin in f32 (scene red-team): the corners computed at that
/// magnitude were 3e-5 of a patch's side off, 56 of 480 patch entries lay beyond their
/// estimates (up to 1.9×) and rows 4.6e-5 above 1 with a false overlap warning. In f32 the
/// scene is computed centred on the origin (`Scene::centred`): every patch entry against the
/// unit cube's f64 entries (the same factors, scale-free; the f64 values within 1e-12 of
/// C-11/C-14 by `unit_cube_against_c11_and_c14`) within its estimate, and the rows within
/// 1e-6 of 1.
#[test]
fn f32_cube_far_from_the_origin_is_computed_centred() {
    let unit = run(&scene(CUBE), PairMethod::tolerance(1e-9));
    // Every origin and edge scaled to 1 cm, then each face moved by one translation.
    let far: String = CUBE
        .lines()
        .map(|line| match line.split_once(" = [") {
            Some((key, rest)) if ["origin", "edge_t", "edge_s"].contains(&key) => {
                let numbers = rest.split(']').next().unwrap();
                let scaled: Vec<String> =
                    numbers.split(',').map(|x| format!("{}", x.trim().parse::<f64>().unwrap() * 0.01)).collect();
                format!("{key} = [{}]\n", scaled.join(", "))
            }
            _ if line.starts_with("subdivide") => format!("{line}\ntranslate = [5.003, 4.997, -3.001]\n"),
            _ => format!("{line}\n"),
        })
        .collect();
    let s = scene(&far);
    let result = compute::<f32>(&s, PairMethod::tolerance(1e-4), None, 0, &|_| {}).unwrap_or_else(|e| panic!("{e:?}"));
    let r = assemble(&s, &result, PairMethod::tolerance(1e-4));
    let errors = r.patches.errors.as_ref().expect("tolerance mode");
    let mut worst: f64 = 0.0;
    for (i, row) in r.patches.factors.iter().enumerate() {
        for (j, &f) in row.iter().enumerate() {
            let actual = (f - unit.patches.factors[i][j]).abs();
            assert!(
                actual <= errors[i][j],
                "[{i}][{j}]: {f} against {}, estimate {:e}",
                unit.patches.factors[i][j],
                errors[i][j]
            );
            worst = worst.max(actual);
        }
    }
    for (i, sum) in r.surfaces.row_sums.iter().enumerate() {
        assert!((sum - 1.0).abs() < 1e-6, "row {i}: {sum}");
    }
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
    println!("largest patch entry error {worst:e}");
}

#[test]
fn closed_cylinder_against_c41_and_the_sum_rule() {
    let s = scene(include_str!("../../examples/scenes/closed_cylinder.toml"));
    let r = run(&s, PairMethod::tolerance(1e-7));
    let disks = closed_form::coaxial_disks(1.0, 1.0, 1.0); // C-41
    check(&r, "bottom", "top", disks, 1e-7);
    check(&r, "bottom", "wall", 1.0 - disks, 1e-7); // enclosure sum rule
                                                    // Wall → each disk by reciprocity (A_disk / A_wall = 1/2), wall → wall by the sum rule.
    check(&r, "wall", "top", 0.5 * (1.0 - disks), 1e-7);
    check(&r, "wall", "wall", disks, 1e-7);
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
    assert_eq!(r.diagnostics.pairs_unconverged, 0);
}

/// The same tube with grids whose edges do not meet: the wall in 3 cells around, the bottom
/// disk in 4 sectors, the top in 5 (T-junctions along both rims, which the kernel cuts into
/// matching contacts; integrated as separate pairs they did not finish in 10 minutes).
#[test]
fn closed_cylinder_with_grids_that_do_not_match() {
    let text = include_str!("../../examples/scenes/closed_cylinder.toml")
        .replace("subdivide = [4, 2]        # 4 around x 2 up", "subdivide = [3, 2]")
        .replace("radius = 1\nsubdivide = [2, 4]\n", "radius = 1\nsubdivide = [1, 5]\n");
    assert!(text.contains("subdivide = [3, 2]") && text.contains("subdivide = [1, 5]"), "{text}");
    let s = scene(&text);
    let r = run(&s, PairMethod::tolerance(1e-7));
    let disks = closed_form::coaxial_disks(1.0, 1.0, 1.0); // C-41
    check(&r, "bottom", "top", disks, 1e-7);
    check(&r, "bottom", "wall", 1.0 - disks, 1e-7);
    check(&r, "top", "wall", 1.0 - disks, 1e-7);
    check(&r, "wall", "top", 0.5 * (1.0 - disks), 1e-7);
    check(&r, "wall", "wall", disks, 1e-7);
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
    assert_eq!(r.diagnostics.pairs_unconverged, 0);
}

/// A closed frustum (bottom radius 1, top 0.4, height 1.5; its wall's inner side): the wall
/// bounds a convex solid, so it cuts no segment between the disks or between a disk and
/// itself, and no pair is integrated across it (it was taken as an occluder of every pair,
/// and the scene did not finish in 300 s). Bottom → top by C-41, the rest by the sum rule
/// and reciprocity.
#[test]
fn closed_frustum_against_c41_and_the_sum_rule() {
    let s = scene(
        r#"
enclosure = true

[[surface]]
name = "bottom"
kind = "disk"
center = [0, 0, 0]
normal = [0, 0, 1]
radius = 1
subdivide = [2, 4]

[[surface]]
name = "top"
kind = "disk"
center = [0, 0, 1.5]
normal = [0, 0, -1]
radius = 0.4
subdivide = [1, 4]

[[surface]]
name = "wall"
kind = "cone"
base = [0, 0, 0]
axis = [0, 0, 1]
base_radius = 1
top_radius = 0.4
height = 1.5
side = "inner"
subdivide = [6, 3]
"#,
    );
    let r = run(&s, PairMethod::tolerance(1e-7));
    let (bottom, top) = (core::f64::consts::PI, core::f64::consts::PI * 0.16);
    let wall = core::f64::consts::PI * 1.4 * (1.5f64 * 1.5 + 0.6 * 0.6).sqrt();
    let up = closed_form::coaxial_disks(1.0, 0.4, 1.5); // C-41
    let down = up * bottom / top;
    check(&r, "bottom", "top", up, 1e-7);
    check(&r, "top", "bottom", down, 1e-7);
    check(&r, "bottom", "wall", 1.0 - up, 1e-7);
    check(&r, "top", "wall", 1.0 - down, 1e-7);
    let (to_bottom, to_top) = (bottom * (1.0 - up) / wall, top * (1.0 - down) / wall);
    check(&r, "wall", "bottom", to_bottom, 1e-7);
    check(&r, "wall", "wall", 1.0 - to_bottom - to_top, 1e-7);
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
    assert_eq!(r.diagnostics.pairs_unconverged, 0);
}

/// A flat closed tube (height 0.05 of its radius): the wall bounds a convex solid holding both
/// disks, so it is no occluder of the disk pair, nor of a disk with the wall, nor are the
/// disks of the wall with itself (their planes). Bottom → top by C-41, the rest by the sum
/// rule and reciprocity. No pair has an occluder.
#[test]
fn flat_closed_tube_against_c41_and_the_sum_rule() {
    let s = scene(
        r#"
enclosure = true

[[surface]]
name = "bottom"
kind = "disk"
center = [0, 0, 0]
normal = [0, 0, 1]
radius = 1

[[surface]]
name = "top"
kind = "disk"
center = [0, 0, 0.05]
normal = [0, 0, -1]
radius = 1

[[surface]]
name = "wall"
kind = "cylinder"
base = [0, 0, 0]
axis = [0, 0, 1]
radius = 1
height = 0.05
side = "inner"
"#,
    );
    let method = PairMethod::tolerance(1e-7);
    let result = compute::<f64>(&s, method, None, 0, &|_| {}).unwrap_or_else(|e| panic!("{e:?}"));
    assert!(result.pairs.iter().all(|p| p.occluders == 0), "{:?}", result.pairs);
    let r = assemble(&s, &result, method);
    let disks = closed_form::coaxial_disks(1.0, 1.0, 0.05); // C-41
    let (disk, wall) = (core::f64::consts::PI, 2.0 * core::f64::consts::PI * 0.05);
    check(&r, "bottom", "top", disks, 1e-7);
    check(&r, "bottom", "wall", 1.0 - disks, 1e-7);
    let to_disk = disk * (1.0 - disks) / wall;
    check(&r, "wall", "top", to_disk, 1e-7);
    check(&r, "wall", "wall", 1.0 - 2.0 * to_disk, 1e-6);
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
    assert_eq!(r.diagnostics.pairs_unconverged, 0);
}

/// A pipe through an annular chamber: an inner tube (outer side) inside an outer tube (inner
/// side), closed by two annuli. The outer tube's solid holds every patch, so it occludes
/// nothing (a whole tube's enclosing ball, centred off its axis, would not show it: the pipe is
/// bounded by its end circles); the pipe occludes the pairs that see across it. Order 4, so
/// that the pairs across the pipe are cheap;
/// the values are only checked against the physical bounds (each factor in [0, 1]) and each
/// row against 1 to within order 4's error.
#[test]
fn pipe_through_an_annular_chamber_has_only_the_pipe_as_occluder() {
    let s = scene(
        r#"
enclosure = true

[[surface]]
name = "bottom"
kind = "disk"
center = [0, 0, 0]
normal = [0, 0, 1]
radius = 1
inner_radius = 0.5

[[surface]]
name = "top"
kind = "disk"
center = [0, 0, 1]
normal = [0, 0, -1]
radius = 1
inner_radius = 0.5

[[surface]]
name = "outer"
kind = "cylinder"
base = [0, 0, 0]
axis = [0, 0, 1]
radius = 1
height = 1
side = "inner"

[[surface]]
name = "pipe"
kind = "cylinder"
base = [0, 0, 0]
axis = [0, 0, 1]
radius = 0.5
height = 1
side = "outer"
"#,
    );
    let method = PairMethod::Order { order: 4, singular_order: 6 };
    let result = compute::<f64>(&s, method, None, 0, &|_| {}).unwrap_or_else(|e| panic!("{e:?}"));
    let name = |i: usize| s.surfaces[s.patches[i].surface].name.as_str();
    let mut seen = 0;
    for p in &result.pairs {
        let (a, b) = (name(p.i), name(p.j));
        let across_the_pipe = matches!((a, b), ("bottom", "top") | ("bottom" | "top", "outer") | ("outer", "outer"));
        assert_eq!(p.occluders, usize::from(across_the_pipe), "{a} <-> {b}: {p:?}");
        seen += 1;
    }
    assert_eq!(seen, 7, "{:?}", result.pairs);
    let r = assemble(&s, &result, method);
    for (i, row) in r.surfaces.factors.iter().enumerate() {
        assert!(row.iter().all(|f| (0.0..=1.0).contains(f)), "row {i}: {row:?}");
        assert!((r.surfaces.row_sums[i] - 1.0).abs() < 1e-3, "row {i}: {}", r.surfaces.row_sums[i]);
    }
}

/// A sphere's inside in three zones about a tilted axis and, separately, in three lunes, each
/// cut 2 × 3: a chord of a ball never leaves it, so no zone (lune) occludes a pair of the
/// others, and every factor is A_j/(4πR²) (`sphere_interior_factor`, exact).
#[test]
fn zones_and_lunes_of_a_sphere_inside_do_not_occlude_each_other() {
    let radius = 1.5;
    let part = |name: &str, field: &str, range: [f64; 2]| {
        format!(
            "\n[[surface]]\nname = \"{name}\"\nkind = \"sphere\"\ncenter = [0.3, -0.2, 0.1]\nradius = {radius}\n\
             axis = [0.3, -0.5, 0.8]\n{field} = [{}, {}]\nside = \"inner\"\nsubdivide = [2, 3]\n",
            range[0], range[1]
        )
    };
    let zones = [("z0", [0.0, 40.0]), ("z1", [40.0, 110.0]), ("z2", [110.0, 180.0])];
    let lunes = [("l0", [0.0, 70.0]), ("l1", [70.0, 200.0]), ("l2", [200.0, 360.0])];
    for (field, parts) in [("phi", zones), ("theta", lunes)] {
        let text: String = parts.iter().map(|(name, range)| part(name, field, *range)).collect();
        let s = scene(&format!("enclosure = true\n{text}"));
        let method = PairMethod::tolerance(1e-8);
        let result = compute::<f64>(&s, method, None, 0, &|_| {}).unwrap_or_else(|e| panic!("{e:?}"));
        assert!(result.pairs.iter().all(|p| p.occluders == 0), "{field}: {:?}", result.pairs);
        let r = assemble(&s, &result, method);
        let area = |range: [f64; 2]| {
            let [from, to] = range.map(f64::to_radians);
            match field {
                "phi" => closed_form::sphere_patch_area(radius, from, to, 0.0, 2.0 * core::f64::consts::PI),
                _ => closed_form::sphere_patch_area(radius, 0.0, core::f64::consts::PI, from, to),
            }
        };
        for (a, _) in &parts {
            for (b, range) in &parts {
                let exact = closed_form::sphere_interior_factor(radius, area(*range));
                check(&r, a, b, exact, 1e-8);
            }
        }
        assert_eq!(r.diagnostics.pairs_unconverged, 0, "{field}");
    }
}

/// JSON reads into the same model: two coaxial disks of radii 1 and 2 at distance 1.5, the
/// smaller one as an annulus sector pair (4 sectors) and the larger subdivided by rings.
#[test]
fn coaxial_disks_from_json() {
    let json = r#"{
        "surface": [
            {"name": "small", "kind": "disk", "center": [0, 0, 0], "normal": [0, 0, 1], "radius": 1,
             "subdivide": [1, 4]},
            {"name": "large", "kind": "disk", "center": [0, 0, 1.5], "normal": [0, 0, -1], "radius": 2,
             "subdivide": [3, 1]}
        ]
    }"#;
    let s = from_text(json, Format::Json, "test.json").unwrap();
    let r = run(&s, PairMethod::tolerance(1e-8));
    let f = closed_form::coaxial_disks(1.0, 2.0, 1.5); // C-41
    check(&r, "small", "large", f, 1e-8);
    check(&r, "large", "small", f / 4.0, 1e-8); // reciprocity, areas π and 4π
}

/// A thin plate radiating from both sides between two plates: its front sees only the upper
/// plate, its back only the lower one (C-11 for 2 × 2 squares 1 apart), and the plate blocks
/// the view between the outer two completely.
#[test]
fn two_sided_plate_between_two_plates() {
    let s = scene(
        r#"
[[surface]]
name = "lower"
kind = "rectangle"
origin = [0, 0, -1]
edge_t = [2, 0, 0]
edge_s = [0, 2, 0]

[[surface]]
name = "plate"
kind = "rectangle"
origin = [0, 0, 0]
edge_t = [2, 0, 0]
edge_s = [0, 2, 0]
side = "both"
subdivide = [2, 2]

[[surface]]
name = "upper"
kind = "rectangle"
origin = [0, 0, 1]
edge_t = [0, 2, 0]
edge_s = [2, 0, 0]
"#,
    );
    assert_eq!(s.surfaces.len(), 4);
    let r = run(&s, PairMethod::tolerance(1e-9));
    let f = closed_form::parallel_rectangles(2.0, 2.0, 1.0); // C-11
    check(&r, "plate/front", "upper", f, 1e-9);
    check(&r, "plate/back", "lower", f, 1e-9);
    assert_eq!(factor(&r, "plate/front", "lower"), 0.0);
    assert_eq!(factor(&r, "plate/back", "upper"), 0.0);
    assert_eq!(factor(&r, "lower", "upper"), 0.0, "the plate hides the plates from each other");
}

/// The paper's scene from a file at fixed order 8: the sphere's row is 1/6 per face by symmetry,
/// the face factors agree with the independent cube reference (`validate::reference::STORED_R1`,
/// uncertainty below 1e-15) to the accuracy of order 8 on 3 × 3 faces, and every row sums to 1.
#[test]
fn sphere_in_cube_against_the_independent_reference() {
    let s = scene(include_str!("../../examples/scenes/sphere_in_cube.toml"));
    assert_eq!(s.patches.len(), 86);
    let r = run(&s, PairMethod::Order { order: 8, singular_order: 8 });
    let (adjacent, opposite, _, _) = pdm_host::validate::reference::STORED_R1;
    for face in ["top", "bottom", "south", "north", "west", "east"] {
        let f = factor(&r, "sphere", face);
        assert!((f - 1.0 / 6.0).abs() < 1e-6, "sphere -> {face}: {f}");
        let back = factor(&r, face, "sphere");
        let exact = closed_form::cube_face_to_centred_sphere(6.0, 1.0);
        assert!((back - exact).abs() < 1e-6 * exact, "{face} -> sphere: {back}");
    }
    let rel = |f: f64, exact: f64| (f - exact).abs() / exact;
    assert!(rel(factor(&r, "top", "bottom"), opposite) < 1e-5, "{}", factor(&r, "top", "bottom"));
    assert!(rel(factor(&r, "top", "south"), adjacent) < 1e-5, "{}", factor(&r, "top", "south"));
    assert!(rel(factor(&r, "west", "north"), adjacent) < 1e-5, "{}", factor(&r, "west", "north"));
    for sum in &r.surfaces.row_sums {
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
    }
}

/// Concentric spheres: F(inner → outer) = 1, F(outer → inner) = (r₁/r₂)², F(outer → outer) =
/// 1 − (r₁/r₂)² (enclosure identities), with the inner sphere hiding part of the outer one from
/// itself.
#[test]
#[ignore = "slow: about 30 s (run with --ignored slow_)"]
fn slow_concentric_spheres() {
    let s = scene(include_str!("../../examples/scenes/concentric_spheres.toml"));
    let r = run(&s, PairMethod::Order { order: 12, singular_order: 12 });
    assert!((factor(&r, "inner", "outer") - 1.0).abs() < 1e-8);
    assert!((factor(&r, "outer", "inner") - 0.25).abs() < 1e-8);
    assert!((factor(&r, "outer", "outer") - 0.75).abs() < 1e-5 * 0.75);
}

/// Bad input: one line, naming the file, the line of the surface's table, the surface and the
/// field; never a panic.
#[test]
fn bad_scenes_are_named_errors() {
    let rect =
        "[[surface]]\nname = \"a\"\nkind = \"rectangle\"\norigin = [0, 0, 0]\nedge_t = [1, 0, 0]\nedge_s = [0, 1, 0]\n";
    let cases: Vec<(String, &[&str])> = vec![
        ("[[surface]\nname = ".to_string(), &["test.toml:1"]),
        (format!("{rect}colour = \"red\"\n"), &["unknown field `colour`"]),
        (rect.replace("rectangle", "torus"), &["unknown variant `torus`"]),
        (rect.replace("origin = [0, 0, 0]\n", ""), &["test.toml:1", "'a'", "`origin`", "missing"]),
        (format!("{rect}\n[[surface]]\nname = \"d\"\nkind = \"disk\"\ncenter = [0, 0, 0]\nnormal = [0, 0, 1]\nradius = -3\n"), &["test.toml:8", "#2 'd'", "`radius`", "-3"]),
        (rect.replace("[1, 0, 0]", "[nan, 0, 0]"), &["`edge_t`", "not finite"]),
        (rect.replace("edge_s = [0, 1, 0]", "edge_s = [2, 0, 0]"), &["`edge_s`", "zero area"]),
        ("units = \"m\"\n".to_string(), &["no surfaces"]),
        (format!("{rect}\n{rect}"), &["#2 'a'", "`name`", "already used"]),
        (format!("{rect}radius = 1\n"), &["`radius`", "does not belong to kind rectangle"]),
        (format!("{rect}subdivide = [0, 3]\n"), &["`subdivide`"]),
        (
            "[[surface]]\nname = \"t\"\nkind = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0]]\n".to_string(),
            &["'t'", "`vertices`", "must be 3 points, got 2"],
        ),
        (
            "[[surface]]\nname = \"t\"\nkind = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]\n".to_string(),
            &["'t'", "`vertices`", "zero area"],
        ),
        (
            "[[surface]]\nname = \"q\"\nkind = \"quadrilateral\"\nvertices = [[0, 0, 0], [2, 0, 0], [0.5, 0.5, 0], [0, 2, 0]]\n".to_string(),
            &["'q'", "`vertices`", "not convex"],
        ),
        (
            "[[surface]]\nname = \"q\"\nkind = \"quadrilateral\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0.2], [0, 1, 0]]\n".to_string(),
            &["'q'", "`vertices`", "not flat"],
        ),
        (format!("{rect}subdivide = [1000, 1000]\n"), &["more than 12000 patches"]),
        (format!("{rect}side = \"inner\"\n"), &["`side`", "front, back or both"]),
    ];
    for (text, needles) in &cases {
        let error = from_text(text, Format::Toml, "test.toml").expect_err(text).to_string();
        assert!(!error.contains('\n'), "not one line: {error}");
        for needle in *needles {
            assert!(error.contains(needle), "{error:?} lacks {needle:?} (input {text:?})");
        }
    }
    let json = from_text("{\"surface\": [{\"name\": 3}]}", Format::Json, "x.json").unwrap_err().to_string();
    assert!(json.starts_with("x.json:1: invalid type"), "{json}");
}

mod parser {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]
        /// Arbitrary text (and scene-like text with arbitrary values) gives a scene or an
        /// error, never a panic.
        #[test]
        fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
            let _ = from_text(&text, Format::Toml, "p.toml");
            let _ = from_text(&text, Format::Json, "p.json");
        }

        #[test]
        fn arbitrary_values_never_panic(
            kind in prop::sample::select(vec!["rectangle", "disk", "sphere", "cylinder", "cone", "bezier"]),
            a in prop::num::f64::ANY, b in prop::num::f64::ANY, c in prop::num::f64::ANY,
            m in 0usize..2000, n in 0usize..5,
        ) {
            let text = format!(
                "[[surface]]\nname = \"x\"\nkind = \"{kind}\"\noccludes = false\norigin = [{a:?}, 0, 0]\n\
                 center = [0, {b:?}, 0]\nradius = {c:?}\nheight = {a:?}\nsubdivide = [{m}, {n}]\n"
            ).replace("NaN", "nan");
            let _ = from_text(&text, Format::Toml, "p.toml");
        }

        /// View3D files: arbitrary text, and well-formed lines with arbitrary numbers and
        /// vertex, base and combination references, give surfaces or an error, never a panic.
        #[test]
        fn arbitrary_view3d_files_never_panic(
            text in "\\PC{0,200}",
            xs in prop::collection::vec(prop::num::f64::ANY, 12),
            refs in prop::collection::vec(0usize..7, 12),
            kinds in prop::collection::vec(prop::sample::select(vec!["S", "O", "N", "M"]), 3),
            blast in any::<bool>(),
        ) {
            use pdm_host::scene::vs3;
            if let Ok(v) = vs3::parse(&text) {
                let _ = vs3::groups(&v);
            }
            let mut t = String::from(if blast { "F 3a\n" } else { "F 3\n" });
            for (k, x) in xs.chunks(3).enumerate() {
                t += &format!("V {} {:?} {:?} {:?}\n", k + 1, x[0], x[1], x[2]);
            }
            for (k, kind) in kinds.iter().enumerate() {
                let r = &refs[4 * k..4 * k + 4];
                if blast {
                    t += &format!("{kind} {} Q {} {} 0.9 s{k}\n 0 0 0 {:?} {:?}\n", k + 1, r[0], r[1], xs[k], xs[k + 1]);
                    t += &format!("{:?} 0 1 0 1 1 0 {:?}\n", xs[k + 2], xs[k + 3]);
                } else {
                    t += &format!("{kind} {} {} {} {} {} {} {} 0.9 s{k}\n", k + 1, r[0], r[1], r[2], r[3], r[0] % 3, r[1] % 3);
                }
            }
            if let Ok(v) = vs3::parse(&t.replace("NaN", "nan")) {
                let _ = vs3::groups(&v);
            }
        }
    }
}

/// Two plates with a blocker between them, once as a kernel shape with a closed-form
/// occluder and once as another kind describing the same surface: a frustum with equal radii
/// is the tube, a flat Bézier net on a uniform grid is the rectangle (to the Bézier occluder's
/// stated tolerance). Any error in the cone or Bézier occluder changes the shadow.
#[test]
fn cone_and_bezier_occluders_cast_the_shadows_of_their_twins() {
    let plates = r#"
[[surface]]
name = "lower"
kind = "rectangle"
origin = [-1, -1, 0]
edge_t = [2, 0, 0]
edge_s = [0, 2, 0]

[[surface]]
name = "upper"
kind = "rectangle"
origin = [-1, -1, 2]
edge_t = [0, 2, 0]
edge_s = [2, 0, 0]
"#;
    let tube = "\n[[surface]]\nname = \"b\"\nkind = \"cylinder\"\nbase = [-1.5, 0, 1]\naxis = [1, 0, 0]\nradius = 0.3\nheight = 3\n";
    let cone = "\n[[surface]]\nname = \"b\"\nkind = \"cone\"\nbase = [-1.5, 0, 1]\naxis = [1, 0, 0]\nbase_radius = 0.3\ntop_radius = 0.3\nheight = 3\n";
    let square = "\n[[surface]]\nname = \"b\"\nkind = \"rectangle\"\norigin = [-0.4, -0.3, 1]\nedge_t = [0.9, 0, 0.2]\nedge_s = [0, 0.7, 0]\n";
    let mut net = String::from("\n[[surface]]\nname = \"b\"\nkind = \"bezier\"\ncontrol = [");
    for i in 0..4 {
        net += "[";
        for j in 0..4 {
            let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
            net += &format!("[{}, {}, {}],", -0.4 + 0.9 * u, -0.3 + 0.7 * v, 1.0 + 0.2 * u);
        }
        net += "],";
    }
    net += "]\n";
    let method = PairMethod::Order { order: 8, singular_order: 8 };
    let f = |extra: &str| factor(&run(&scene(&format!("{plates}{extra}")), method), "lower", "upper");
    let open = closed_form::parallel_rectangles(2.0, 2.0, 2.0); // C-11
    let (with_tube, with_cone) = (f(tube), f(cone));
    assert!(with_tube < open * 0.95, "the tube casts a shadow: {with_tube} vs {open}");
    assert!((with_tube - with_cone).abs() <= 1e-9 * with_tube, "{with_tube} vs {with_cone}");
    let (with_square, with_net) = (f(square), f(&net));
    assert!(with_square < open * 0.95, "{with_square} vs {open}");
    // The rectangle's outer events are placed into the rule (its value at order 8 is the same
    // to 13 digits at orders 12 and 16); the net's outer rule samples across the shadow's
    // kinks, 8e-6 off at order 8 and within 3e-6 of the rectangle at tolerance 1e-8.
    assert!((with_square - with_net).abs() <= 2e-5 * with_square, "{with_square} vs {with_net}");
}

/// An enclosure with a modelling gap is reported on every row it affects: the cube with its
/// ceiling lifted by half a side (a leak), and with its ceiling facing out (mis-oriented); the
/// complete cube is not.
#[test]
fn enclosure_gaps_are_reported() {
    let leaky = CUBE.replace(
        "origin = [0, 0, 1]\nedge_t = [0, 1, 0]\nedge_s = [1, 0, 0]",
        "origin = [0, 0, 1.5]\nedge_t = [0, 1, 0]\nedge_s = [1, 0, 0]",
    );
    let flipped = CUBE.replace("edge_s = [1, 0, 0]       # -z", "edge_s = [1, 0, 0]       # -z\nside = \"back\"");
    assert_ne!(leaky, CUBE);
    assert_ne!(flipped, CUBE);
    for (text, gaps) in [(CUBE.to_string(), 0), (leaky, 6), (flipped, 6)] {
        let r = run(&scene(&text), PairMethod::tolerance(1e-8));
        let found = &r.diagnostics.enclosure_gaps;
        assert_eq!(found.len(), gaps, "{found:?}");
        assert!(found.iter().all(|g| g.contains("row sum")), "{found:?}");
    }
}

/// f32 runs the same scenes to single precision.
#[test]
fn single_precision_matches_to_its_resolution() {
    let s = scene(CUBE);
    let result = compute::<f32>(&s, PairMethod::Order { order: 8, singular_order: 8 }, None, 0, &|_| {}).unwrap();
    let r = assemble(&s, &result, PairMethod::Order { order: 8, singular_order: 8 });
    let opposite = closed_form::parallel_rectangles(1.0, 1.0, 1.0); // C-11
    let adjacent = closed_form::perpendicular_rectangles(1.0, 1.0, 1.0); // C-14
    assert!((factor(&r, "floor", "ceiling") - opposite).abs() < 1e-6);
    assert!((factor(&r, "floor", "west") - adjacent).abs() < 1e-6);
}

/// The unit cube from an OBJ file (one object per face, 12 triangles) against C-11 and C-14:
/// every facet pair by the contour form, exact to rounding.
#[test]
fn obj_cube_against_c11_and_c14() {
    let path = format!("{}/../examples/scenes/cube_obj.toml", env!("CARGO_MANIFEST_DIR"));
    let s = pdm_host::scene::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.surfaces.len(), 6);
    assert_eq!(s.patches.len(), 12);
    let r = run(&s, PairMethod::tolerance(1e-8));
    let opposite = closed_form::parallel_rectangles(1.0, 1.0, 1.0); // C-11
    let adjacent = closed_form::perpendicular_rectangles(1.0, 1.0, 1.0); // C-14
    check(&r, "cube/floor", "cube/ceiling", opposite, 1e-9);
    check(&r, "cube/west", "cube/east", opposite, 1e-9);
    // Facet pairs take the contour form with closed-form inner integrals: exact to rounding.
    for (a, b) in [("cube/floor", "cube/south"), ("cube/floor", "cube/north"), ("cube/west", "cube/north")] {
        check(&r, a, b, adjacent, 1e-10);
    }
    for (i, sum) in r.surfaces.row_sums.iter().enumerate() {
        let allowed: f64 = r.surfaces.errors.as_ref().unwrap()[i].iter().sum();
        assert!((sum - 1.0).abs() <= allowed, "row {i}: {sum} beyond {allowed:e}");
    }
}

/// A temporary folder holding `scene.toml` and one mesh file (name, contents); the folder
/// lives as long as the returned guard.
fn scene_folder(scene_text: &str, (name, mesh): (&str, &str)) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(name), mesh).unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene_text).unwrap();
    (dir, path)
}

/// An STL file (ASCII; two triangles making a 2 × 2 square, facing up) under a parallel
/// rectangle: C-11. Facets radiate to the counter-clockwise side.
#[test]
fn stl_square_under_a_rectangle() {
    let stl = "solid sq\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 2 0 0\nvertex 2 2 0\nendloop\nendfacet\n\
               facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 2 2 0\nvertex 0 2 0\nendloop\nendfacet\nendsolid sq\n";
    let scene_text = "[[surface]]\nname = \"square\"\nkind = \"mesh\"\nfile = \"sq.stl\"\n\n\
                      [[surface]]\nname = \"top\"\nkind = \"rectangle\"\norigin = [0, 0, 1]\nedge_t = [0, 2, 0]\nedge_s = [2, 0, 0]\n";
    let (dir, path) = scene_folder(scene_text, ("sq.stl", stl));
    let s = pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let r = run(&s, PairMethod::tolerance(1e-9));
    check(&r, "square", "top", closed_form::parallel_rectangles(2.0, 2.0, 1.0), 1e-9); // C-11
                                                                                       // A missing mesh file is a named error.
    std::fs::remove_file(dir.path().join("sq.stl")).unwrap();
    let e = pdm_host::scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("surface #1 'square': field `file`") && e.contains("sq.stl"), "{e}");
}

/// The triangle and quadrilateral kinds: a unit square floor as two triangles (one of them
/// subdivided, so that patches at its collapsed corner are triangles too), a wall sharing its
/// edge and a ceiling as quadrilaterals, against C-14 and C-11; a quadrilateral radiating to
/// its back sees nothing.
#[test]
fn triangles_and_quadrilaterals_against_c11_and_c14() {
    let text = r#"
[[surface]]
name = "floor1"
kind = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0]]
subdivide = [3, 2]

[[surface]]
name = "floor2"
kind = "triangle"
vertices = [[0, 0, 0], [1, 1, 0], [0, 1, 0]]

[[surface]]
name = "wall"
kind = "quadrilateral"
vertices = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]
subdivide = [2, 2]

[[surface]]
name = "ceiling"
kind = "quadrilateral"
vertices = [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]

[[surface]]
name = "away"
kind = "quadrilateral"
vertices = [[0, 0, 2], [0, 1, 2], [1, 1, 2], [1, 0, 2]]
side = "back"
occludes = false
"#;
    let s = scene(text);
    let r = run(&s, PairMethod::tolerance(1e-10));
    let (area1, area2) = (0.5, 0.5);
    // The floor's exchange with the wall and the ceiling, summed over its two halves.
    let to = |b: &str| area1 * factor(&r, "floor1", b) + area2 * factor(&r, "floor2", b);
    let err = |b: &str| area1 * error(&r, "floor1", b) + area2 * error(&r, "floor2", b);
    for (b, exact) in [
        ("wall", closed_form::perpendicular_rectangles(1.0, 1.0, 1.0)), // C-14
        ("ceiling", closed_form::parallel_rectangles(1.0, 1.0, 1.0)),   // C-11
    ] {
        let actual = (to(b) - exact).abs();
        assert!(
            actual <= 1e-10 * exact && actual <= err(b) + 1e-15,
            "floor -> {b}: {} vs {exact} (estimate {:e})",
            to(b),
            err(b)
        );
    }
    // The wall to the ceiling: C-14 again.
    check(&r, "wall", "ceiling", closed_form::perpendicular_rectangles(1.0, 1.0, 1.0), 1e-10);
    for b in ["floor1", "floor2", "wall", "ceiling"] {
        assert_eq!(factor(&r, "away", b), 0.0, "away -> {b}");
    }
}

/// A row above 1 is flagged in any scene: two large plates over a small one, the nearer not
/// an occluder, overlap in its view (F ≈ 0.9 + 0.8); with the nearer occluding, the farther is
/// hidden and nothing is flagged.
#[test]
fn rows_above_one_are_flagged_in_open_scenes() {
    let plates = |occludes: bool| {
        format!(
            "[[surface]]\nname = \"small\"\nkind = \"rectangle\"\norigin = [0, 0, 0]\nedge_t = [1, 0, 0]\nedge_s = [0, 1, 0]\n\n\
             [[surface]]\nname = \"near\"\nkind = \"rectangle\"\norigin = [-4.5, -4.5, 1]\nedge_t = [0, 10, 0]\nedge_s = [10, 0, 0]\noccludes = {occludes}\n\n\
             [[surface]]\nname = \"far\"\nkind = \"rectangle\"\norigin = [-4.5, -4.5, 2]\nedge_t = [0, 10, 0]\nedge_s = [10, 0, 0]\n"
        )
    };
    let r = run(&scene(&plates(false)), PairMethod::tolerance(1e-6));
    let sum = r.surfaces.row_sums[index(&r, "small")];
    assert!(sum > 1.5, "{sum}");
    let flagged = &r.diagnostics.overfull_rows;
    assert!(flagged.iter().any(|g| g.starts_with("surface small:")), "{flagged:?}");
    assert!(pdm_host::scene::report::text(&r).contains("sum to more than 1"));
    let r = run(&scene(&plates(true)), PairMethod::tolerance(1e-6));
    assert_eq!(factor(&r, "small", "far"), 0.0);
    assert!(r.diagnostics.overfull_rows.is_empty(), "{:?}", r.diagnostics.overfull_rows);
    assert!(pdm_host::scene::report::text(&r).contains("to space"));
}

/// The NumPy outputs read back: the .npz's arrays (names, areas, factors, row sums, errors at
/// both levels) equal the report's; the .npy is the surface matrix.
#[test]
fn numpy_outputs_read_back() {
    use std::io::Read as _;
    let s = scene(CUBE);
    let r = run(&s, PairMethod::tolerance(1e-6));
    let bytes = pdm_host::scene::report::encode(&r, std::path::Path::new("x.npz")).unwrap();
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    let mut read = |name: &str| {
        let mut file = archive.by_name(&format!("{name}.npy")).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut data = Vec::new();
        file.read_to_end(&mut data).unwrap();
        npyz::NpyFile::new(std::io::Cursor::new(data)).unwrap()
    };
    for (level, m) in [("surface", &r.surfaces), ("patch", &r.patches)] {
        let n = m.names.len() as u64;
        let names = read(&format!("{level}_names"));
        assert_eq!(names.shape(), &[n]);
        assert_eq!(names.into_vec::<String>().unwrap(), m.names);
        assert_eq!(read(&format!("{level}_areas")).into_vec::<f64>().unwrap(), m.areas);
        let factors = read(&format!("{level}_factors"));
        assert_eq!(factors.shape(), &[n, n]);
        assert_eq!(factors.into_vec::<f64>().unwrap(), m.factors.concat());
        assert_eq!(read(&format!("{level}_row_sums")).into_vec::<f64>().unwrap(), m.row_sums);
        let errors = read(&format!("{level}_errors")).into_vec::<f64>().unwrap();
        assert_eq!(errors, m.errors.as_ref().unwrap().concat());
    }
    let npy = pdm_host::scene::report::encode(&r, std::path::Path::new("x.npy")).unwrap();
    let matrix = npyz::NpyFile::new(&npy[..]).unwrap();
    assert_eq!(matrix.shape(), &[6, 6]);
    assert_eq!(matrix.into_vec::<f64>().unwrap(), r.surfaces.factors.concat());
    let e = pdm_host::scene::report::encode(&r, std::path::Path::new("x.mat")).unwrap_err();
    assert!(e.contains(".npz"), "{e}");
}

/// OBJ faces: a flat convex quad stays one facet (a square under a parallel rectangle: C-11),
/// a bent quad is cut into two triangles, a face of two vertices is a named error.
#[test]
fn obj_quads_stay_whole_and_bent_quads_are_cut() {
    let obj = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 5\nv 2 0 5\nv 2 2 5.5\nv 0 2 5\n\
               o square\nf 1 2 3 4\no bent\nf 5 8 7 6\n";
    let text = "[[surface]]\nname = \"m\"\nkind = \"mesh\"\nfile = \"m.obj\"\n\n\
                [[surface]]\nname = \"top\"\nkind = \"rectangle\"\norigin = [0, 0, 1]\nedge_t = [0, 2, 0]\nedge_s = [2, 0, 0]\noccludes = false\n";
    let (dir, path) = scene_folder(text, ("m.obj", obj));
    let s = pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let pieces = |name: &str| s.surfaces.iter().find(|x| x.name == name).unwrap().pieces.len();
    assert_eq!((pieces("m/square"), pieces("m/bent")), (1, 2));
    let r = run(&s, PairMethod::tolerance(1e-10));
    check(&r, "m/square", "top", closed_form::parallel_rectangles(2.0, 2.0, 1.0), 1e-10); // C-11
    std::fs::write(dir.path().join("m.obj"), "v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap();
    let e = pdm_host::scene::load(&path).unwrap_err().to_string();
    assert!(e.contains("field `file`") && e.contains("face 1 has 2 vertices"), "{e}");
}

/// The room example loads as described: one surface per OBJ object, its quad faces kept whole
/// (one patch each), the lamp a sphere. Its matrix is measured in BENCHMARKS.md, not here (its
/// occluded touching pairs take minutes).
#[test]
fn room_example_loads_with_quadrilateral_facets() {
    let path = format!("{}/../examples/scenes/room.toml", env!("CARGO_MANIFEST_DIR"));
    let s = pdm_host::scene::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let names: Vec<_> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "room/floor",
            "room/ceiling",
            "room/wall_south",
            "room/wall_north",
            "room/wall_west",
            "room/wall_east",
            "room/table",
            "room/cabinet",
            "lamp"
        ]
    );
    // 4 floor pieces around the cabinet, 5 room faces, 6 table faces, 5 cabinet faces, the lamp.
    assert_eq!(s.patches.len(), 4 + 5 + 6 + 5 + 1);
    assert!(s.enclosure);
}

/// The box-in-a-room example (an OBJ file, every surface an occluder, as a user would run it):
/// each row of the enclosure sums to 1 within 1e-9 and within its estimates, every pair meets
/// the tolerance. The room's faces meet along edges with the box between them (the contour form
/// less the blocked part); before, the ceiling's row missed 1 by 6e-6, with 15 pairs above the
/// default tolerance.
#[test]
fn box_room_example_rows_sum_to_one() {
    let path = format!("{}/../examples/scenes/box_room.toml", env!("CARGO_MANIFEST_DIR"));
    let s = pdm_host::scene::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let r = run(&s, PairMethod::tolerance(1e-10));
    let errors = r.surfaces.errors.clone().expect("the tolerance mode gives estimates");
    for (i, sum) in r.surfaces.row_sums.iter().enumerate() {
        let estimate: f64 = errors[i].iter().sum();
        println!("{}: row sum misses 1 by {:.1e}, estimates {estimate:.1e}", r.surfaces.names[i], sum - 1.0);
        assert!((sum - 1.0).abs() < 1e-9 && (sum - 1.0).abs() <= estimate + 1e-14, "{}: {sum}", r.surfaces.names[i]);
    }
    assert!(r.diagnostics.enclosure_gaps.is_empty(), "{:?}", r.diagnostics.enclosure_gaps);
}

/// A unit cube as a View3D file (format F 3, vertices counter-clockwise seen from inside),
/// with a triangular window (a subsurface, `base` = 1) and a square null surface cut out of
/// the floor. The floor keeps what is left, so the floor and the window together are the
/// floor of the plain cube: their factors from the ceiling and a wall add up to C-11 and C-14,
/// and each row of the enclosure sums to 1.
const VS3_CUBE: &str = "T unit cube with a window in the floor
C encl=1 eps=1e-4
F 3
V 1 0 0 0
V 2 1 0 0
V 3 1 1 0
V 4 0 1 0
V 5 0 0 1
V 6 1 0 1
V 7 1 1 1
V 8 0 1 1
V 9 0.2 0.2 0
V 10 0.6 0.3 0
V 11 0.3 0.7 0
V 12 0.7 0.6 0
V 13 0.9 0.6 0
V 14 0.9 0.9 0
V 15 0.7 0.9 0
S 1 1 2 3 4 0 0 0.9 floor   ! faces up, into the cube
S 2 7 6 5 8 0 0 0.9 ceiling
S 3 1 5 6 2 0 0 0.9 south
S 4 7 8 4 3 0 0 0.9 north
S 5 1 4 8 5 0 0 0.9 west
S 6 7 3 2 6 0 0 0.9 east
S 7 9 10 11 0 1 0 0.9 window
N 8 12 15 14 13 1 0 0.9 vent
E
";

#[test]
fn view3d_file_with_a_window_against_c11_c14_and_the_sum_rule() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.vs3");
    std::fs::write(&path, VS3_CUBE).unwrap();
    let s = pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(s.enclosure, "encl=1");
    let names: Vec<_> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["floor", "ceiling", "south", "north", "west", "east", "window"]);
    let r = run(&s, PairMethod::tolerance(1e-10));
    let (window, vent) = (0.5 * 0.4f64.mul_add(0.5, -0.1 * 0.1), 0.2 * 0.3);
    assert!((r.surfaces.areas[index(&r, "window")] - window).abs() < 1e-14);
    assert!((r.surfaces.areas[index(&r, "floor")] - (1.0 - window - vent)).abs() < 1e-14);
    let opposite = closed_form::parallel_rectangles(1.0, 1.0, 1.0); // C-11
    let adjacent = closed_form::perpendicular_rectangles(1.0, 1.0, 1.0); // C-14
    for (from, whole) in [("ceiling", opposite), ("south", adjacent), ("east", adjacent)] {
        let sum = factor(&r, from, "floor") + factor(&r, from, "window");
        // The vent is a hole: what the floor loses to it nobody gains.
        assert!(sum < whole - 1e-3, "{from}: {sum} against {whole}");
    }
    // Without the vent the floor and the window make the whole floor again.
    let no_vent = VS3_CUBE.replace("N 8 12 15 14 13 1 0 0.9 vent\n", "");
    std::fs::write(&path, no_vent).unwrap();
    let s = pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let r = run(&s, PairMethod::tolerance(1e-10));
    for (from, whole) in [("ceiling", opposite), ("south", adjacent), ("north", adjacent), ("west", adjacent)] {
        let sum = factor(&r, from, "floor") + factor(&r, from, "window");
        assert!((sum - whole).abs() < 1e-9 * whole, "{from}: {sum} against {whole}");
    }
    for (i, sum) in r.surfaces.row_sums.iter().enumerate() {
        assert!((sum - 1.0).abs() < 1e-9, "row {}: {sum}", r.surfaces.names[i]);
    }
    assert_eq!(factor(&r, "floor", "window"), 0.0, "one plane");
    assert!(r.diagnostics.enclosure_gaps.is_empty());
}

/// View3D obstruction surfaces (`O`) block the view and get no row; one that covers the view
/// between two squares leaves nothing, one beside it changes nothing (C-11).
#[test]
fn view3d_obstructions_block_without_a_row() {
    let text = |o: &str| {
        format!(
            "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 0\nV 5 0 0 1\nV 6 1 0 1\nV 7 1 1 1\nV 8 0 1 1\n{o}\
             S 1 1 2 3 4 0 0 0.9 low\nS 2 5 8 7 6 0 0 0.9 high\nO 3 9 10 11 12\nE\n"
        )
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("o.vs3");
    let covering = "V 9 -1 -1 0.5\nV 10 2 -1 0.5\nV 11 2 2 0.5\nV 12 -1 2 0.5\n";
    let beside = "V 9 3 0 0\nV 10 4 0 0\nV 11 4 0 1\nV 12 3 0 1\n";
    for (vertices, expected) in [(covering, 0.0), (beside, closed_form::parallel_rectangles(1.0, 1.0, 1.0))] {
        std::fs::write(&path, text(vertices)).unwrap();
        let s = pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.surfaces.len(), 2);
        assert_eq!(s.obstructions.len(), 1);
        let r = run(&s, PairMethod::tolerance(1e-10));
        assert_eq!(r.surfaces.names, ["low", "high"]);
        assert!((factor(&r, "low", "high") - expected).abs() < 1e-10, "{}", factor(&r, "low", "high"));
    }
    // The same obstruction from a TOML file: `radiates = false`.
    let toml = "[[surface]]\nname = \"low\"\nkind = \"rectangle\"\norigin = [0, 0, 0]\nedge_t = [1, 0, 0]\nedge_s = [0, 1, 0]\n\n\
                [[surface]]\nname = \"high\"\nkind = \"rectangle\"\norigin = [0, 0, 1]\nedge_t = [0, 1, 0]\nedge_s = [1, 0, 0]\n\n\
                [[surface]]\nname = \"screen\"\nkind = \"rectangle\"\nradiates = false\norigin = [-1, -1, 0.5]\nedge_t = [3, 0, 0]\nedge_s = [0, 3, 0]\n";
    let r = run(&scene(toml), PairMethod::tolerance(1e-10));
    assert_eq!(r.surfaces.names, ["low", "high"]);
    assert_eq!(factor(&r, "low", "high"), 0.0);
    let e = from_text(&toml.replace("radiates = false", "radiates = false\noccludes = false"), Format::Toml, "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("field `radiates`"), "{e}");
}

/// Bad View3D files: one line naming the file and the line.
#[test]
fn bad_view3d_files_name_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.vs3");
    for (text, place, words) in [
        ("F 3\nV 1 0 0 0\nV 2 1 0 0\nS 1 1 2 3 0 0 0 0.9 a\n", "bad.vs3:4:", "vertex 3"),
        ("F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 1 1 0\nV 4 0 1 1\nS 1 1 2 3 4 0 0 0.9 a\n", "bad.vs3", "not flat"),
        ("F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nM 1 1 2 3 0 0 0 0.9 m\n", "bad.vs3:5:", "masking"),
    ] {
        std::fs::write(&path, text).unwrap();
        let e = pdm_host::scene::load(&path).unwrap_err().to_string();
        assert!(e.contains(place) && e.contains(words) && !e.contains('\n'), "{e}");
    }
}

/// Every example scene builds (checked geometry, mesh and View3D files found and valid; the
/// satellite's Bézier dish passes the fold and self-crossing check), and a folded net is a
/// named error.
#[test]
fn every_example_builds_and_a_folded_net_is_refused() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes");
    let mut count = 0;
    for dir in [root.clone(), root.join("scale")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
            if matches!(ext, "toml" | "json" | "vs3") {
                pdm_host::scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
                count += 1;
            }
        }
    }
    assert!(count >= 15, "{count} examples");
    let folded = "[[surface]]\nname = \"dish\"\nkind = \"bezier\"\ncontrol = [\n\
        [[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]],\n\
        [[-2.7, 0, 0], [-2.7, 1, 0], [-2.7, 2, 0], [-2.7, 3, 0]],\n\
        [[2, 0, 0], [2, 1, 0], [2, 2, 0], [2, 3, 0]],\n\
        [[3, 0, 0], [3, 1, 0], [3, 2, 0], [3, 3, 0]]]\n";
    let e = from_text(folded, Format::Toml, "f.toml").unwrap_err().to_string();
    assert!(e.contains("field `control` the net folds over"), "{e}");
}

/// Parts of surfaces occlude: a sphere between two plates cut into two zones (phi), a tube
/// into two halves (theta), a disk into an annulus sector and the rest cast the shadow of the
/// whole surface, and a zone out of the line of sight casts none (C-11). Slow (minutes): the
/// parts' shadow edges are bracketed and bisected.
#[test]
#[ignore = "slow: run with --ignored slow_"]
fn slow_parts_of_surfaces_cast_the_shadow_of_the_whole() {
    let plates = "[[surface]]\nname = \"lower\"\nkind = \"rectangle\"\norigin = [-1, -1, 0]\nedge_t = [2, 0, 0]\nedge_s = [0, 2, 0]\n\n\
                  [[surface]]\nname = \"upper\"\nkind = \"rectangle\"\norigin = [-1, -1, 2]\nedge_t = [0, 2, 0]\nedge_s = [2, 0, 0]\n";
    let method = PairMethod::tolerance(1e-6);
    let f = |extra: &str| {
        let r = run(&scene(&format!("{plates}{extra}")), method);
        (factor(&r, "lower", "upper"), error(&r, "lower", "upper"))
    };
    let sphere = |name: &str, range: &str| {
        format!("\n[[surface]]\nname = \"{name}\"\nkind = \"sphere\"\ncenter = [0.2, 0.1, 1]\nradius = 0.5\naxis = [0.3, 0, 1]\n{range}\n")
    };
    let tube = |name: &str, range: &str| {
        format!("\n[[surface]]\nname = \"{name}\"\nkind = \"cylinder\"\nbase = [-1.5, 0, 1]\naxis = [1, 0, 0.1]\nradius = 0.3\nheight = 3\n{range}\n")
    };
    let disk = |name: &str, range: &str| {
        format!("\n[[surface]]\nname = \"{name}\"\nkind = \"disk\"\ncenter = [0, 0.2, 1]\nnormal = [0.1, 0, 1]\nradius = 0.6\n{range}\n")
    };
    let cases = [
        (sphere("s", ""), sphere("s1", "phi = [0, 70]") + &sphere("s2", "phi = [70, 180]")),
        (tube("t", ""), tube("t1", "theta = [0, 130]") + &tube("t2", "theta = [130, 360]")),
        (
            disk("d", "inner_radius = 0.2"),
            disk("d1", "inner_radius = 0.2\ntheta = [0, 100]") + &disk("d2", "inner_radius = 0.2\ntheta = [100, 360]"),
        ),
    ];
    let open = closed_form::parallel_rectangles(2.0, 2.0, 2.0); // C-11
    for (whole, parts) in cases {
        let ((a, ea), (b, eb)) = (f(&whole), f(&parts));
        assert!(a < 0.97 * open, "{whole}: {a}");
        assert!((a - b).abs() <= ea + eb + 1e-12, "{whole}: {a} ± {ea:e} vs parts {b} ± {eb:e}");
    }
    // The upper cap of a sphere that sits beside the plates' line of sight blocks nothing.
    let beside = "\n[[surface]]\nname = \"cap\"\nkind = \"sphere\"\ncenter = [0, 0, -3]\nradius = 1\nphi = [0, 60]\n";
    let (c, e) = f(beside);
    assert!((c - open).abs() <= e + 1e-12, "{c} vs {open}");
}

/// The absolute tolerance is shared out among the patch pairs so that every surface factor's
/// summed estimate meets it (plus the relative part) in both directions, and the values stay
/// within their estimates of the closed form (C-41 for the ends; the wall by the sum rule).
#[test]
fn the_absolute_tolerance_bounds_every_surface_factor() {
    let s = scene(include_str!("../../examples/scenes/closed_cylinder.toml"));
    let (relative, absolute) = (1e-12, 2e-9);
    let r = run(&s, PairMethod::Tolerance { relative, absolute });
    assert_eq!(r.diagnostics.pairs_unconverged, 0, "{:?}", r.diagnostics);
    let errors = r.surfaces.errors.as_ref().unwrap();
    for (i, row) in r.surfaces.factors.iter().enumerate() {
        for (j, f) in row.iter().enumerate() {
            assert!(errors[i][j] <= absolute + relative * f, "F[{i}][{j}] = {f}: estimate {:e}", errors[i][j]);
        }
    }
    // Relative alone would have asked for 1e-12 on every pair: the absolute tolerance is what
    // stopped them (some estimate is far above the relative part).
    assert!(r.diagnostics.largest_relative_error.unwrap() > 1e3 * relative, "{:?}", r.diagnostics);
    let disks = closed_form::coaxial_disks(1.0, 1.0, 1.0); // C-41
    let exact = [
        ("bottom", "top", disks),
        ("top", "bottom", disks),
        ("bottom", "wall", 1.0 - disks),
        ("wall", "top", 0.5 * (1.0 - disks)),
        ("wall", "wall", disks),
    ];
    for (a, b, x) in exact {
        let (f, e) = (factor(&r, a, b), error(&r, a, b));
        assert!((f - x).abs() <= e + 4.0 * f64::EPSILON, "{a} -> {b}: {f} against {x}, estimate {e:e}");
    }
}

/// A sphere inside a concave sphere: a segment from the inner sphere to the outer one stays
/// inside the outer ball, so the outer sphere cannot block it and is not passed as an occluder
/// of those pairs. (The parts of the inner sphere were judged by their balls, which reach
/// beyond the outer sphere: the outer sphere was passed, and the tolerance mode took the pairs
/// as occluded, ending 2.1e-2 off with an honest estimate of 4.8e-2.) Every ray leaving the
/// inner sphere reaches the outer one: F = 1 (sum rule).
#[test]
fn a_sphere_inside_a_sphere_sees_it_whole() {
    let s = scene(
        "[[surface]]\nname = \"inner\"\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nsubdivide = [1, 2]\n\
         occludes = false\n\n[[surface]]\nname = \"outer\"\nkind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2\n\
         side = \"inner\"\nsubdivide = [1, 2]\n",
    );
    let r = run(&s, PairMethod::tolerance(1e-6));
    check(&r, "inner", "outer", 1.0, 1e-6);
    for row in &r.surfaces.factors {
        assert!(row.iter().all(|f| (0.0..=1.0).contains(f)), "{:?}", r.surfaces.factors);
    }
}
