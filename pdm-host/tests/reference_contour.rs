//! Contour-form polygon factors against the catalogue (C-11, C-14) and consistency checks.

use pdm_host::reference::closed_form::{parallel_rectangles, perpendicular_rectangles};
use pdm_host::reference::contour::{polygon_area, polygon_form_factor};

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Unit square in z = 0, normal +z, and the square folded about the x axis so that the interior
/// dihedral angle is `theta`, normal facing the first square.
fn folded_pair(theta: f64, len: f64, w1: f64, w2: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let p1 = vec![[0.0, 0.0, 0.0], [len, 0.0, 0.0], [len, w1, 0.0], [0.0, w1, 0.0]];
    let (c, s) = (theta.cos(), theta.sin());
    let m = [0.0, w2 * c, w2 * s];
    let p2 = vec![[0.0, 0.0, 0.0], m, [len, m[1], m[2]], [len, 0.0, 0.0]];
    (p1, p2)
}

#[test]
fn c11_unit_squares() {
    // C-11: square z = 0 (normal +z, CCW seen from +z) and z = 1 (normal −z).
    let p1 = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let p2 = [[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]];
    let f = polygon_form_factor(&p1, &p2);
    eprintln!("C-11 contour {f:.17}");
    assert!(rel(f, 0.1998248956983874) < 1e-13, "{f:.17}");
    let f = polygon_form_factor(&p2, &p1);
    assert!(rel(f, 0.1998248956983874) < 1e-13, "{f:.17}");
    // rectangles 2 × 0.5 at distance 0.3
    let q1 = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 0.5, 0.0], [0.0, 0.5, 0.0]];
    let q2 = [[0.0, 0.0, 0.3], [0.0, 0.5, 0.3], [2.0, 0.5, 0.3], [2.0, 0.0, 0.3]];
    let f = polygon_form_factor(&q1, &q2);
    assert!(rel(f, parallel_rectangles(2.0, 0.5, 0.3)) < 1e-13, "{f:.17}");
}

#[test]
fn c14_unit_squares_and_aspect_ratios() {
    let pi2 = std::f64::consts::FRAC_PI_2;
    for &(l, w, h) in &[
        (1.0, 1.0, 1.0),
        (1.0, 1.0, 100.0),
        (1.0, 100.0, 1.0),
        (1.0, 1.0, 0.01),
        (100.0, 1.0, 1.0),
        (0.01, 1.0, 1.0),
        (2.0, 0.5, 3.0),
    ] {
        let (p1, p2) = folded_pair(pi2, l, w, h);
        let f = polygon_form_factor(&p1, &p2);
        let exact = perpendicular_rectangles(l, w, h);
        eprintln!("C-14 l={l} w={w} h={h}: contour {f:.17} exact {exact:.17} rel {:.2e}", rel(f, exact));
        assert!(rel(f, exact) < 1e-12, "l={l} w={w} h={h}: {f:.17} vs {exact:.17}");
        // reciprocity through the contour form itself
        let b = polygon_form_factor(&p2, &p1);
        assert!(rel(polygon_area(&p1) * f, polygon_area(&p2) * b) < 1e-12);
    }
}

#[test]
fn dihedral_sweep_shared_edge() {
    let deg = std::f64::consts::PI / 180.0;
    let mut prev = f64::INFINITY;
    for &a in &[0.01, 1.0, 30.0, 60.0, 90.0, 120.0, 150.0, 179.0, 179.99] {
        let (p1, p2) = folded_pair(a * deg, 1.0, 1.0, 1.0);
        let f = polygon_form_factor(&p1, &p2);
        // additivity: split the receiver into 2 × 2 and the emitter into 2 × 2
        let sub = |p: &[[f64; 3]]| -> Vec<Vec<[f64; 3]>> {
            let (o, u, v) = (p[0], sub3(p[3], p[0]), sub3(p[1], p[0]));
            let mut out = Vec::new();
            for i in 0..2 {
                for j in 0..2 {
                    let c = |x: f64, y: f64| {
                        [o[0] + x * u[0] + y * v[0], o[1] + x * u[1] + y * v[1], o[2] + x * u[2] + y * v[2]]
                    };
                    let (x0, y0) = (0.5 * i as f64, 0.5 * j as f64);
                    out.push(vec![c(x0, y0), c(x0, y0 + 0.5), c(x0 + 0.5, y0 + 0.5), c(x0 + 0.5, y0)]);
                }
            }
            out
        };
        let parts1 = sub(&p1);
        let parts2 = sub(&p2);
        let mut a1f = 0.0;
        for q1 in &parts1 {
            for q2 in &parts2 {
                a1f += polygon_area(q1) * polygon_form_factor(q1, q2);
            }
        }
        let f_split = a1f / polygon_area(&p1);
        eprintln!("dihedral {a:>6}°: F = {f:.16}  split {f_split:.16}  diff {:.1e}", (f - f_split).abs());
        assert!(rel(f, f_split) < 1e-12, "{a}: {f} vs {f_split}");
        if a == 90.0 {
            assert!(rel(f, 0.2000437760754032) < 1e-13);
        }
        assert!(f < prev, "monotone in the angle");
        prev = f;
        if a < 0.1 {
            assert!(f > 0.999, "{f}");
        }
        if a > 179.9 {
            assert!(f < 1e-3, "{f}");
        }
    }
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
