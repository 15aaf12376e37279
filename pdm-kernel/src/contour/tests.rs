//! Unit tests of the contour forms.

use super::*;

mod forms {
    use super::*;
    use crate::vec3::vec3;

    /// C-11 (parallel coaxial squares, Howell's catalogue): unit squares at distance h.
    fn c11(h: f64) -> f64 {
        let x = 1.0 / h;
        let y = 1.0 / h;
        let (x2, y2) = (1.0 + x * x, 1.0 + y * y);
        2.0 / (core::f64::consts::PI * x * y)
            * ((x2 * y2 / (1.0 + x * x + y * y)).sqrt().ln()
                + x * y2.sqrt() * (x / y2.sqrt()).atan()
                + y * x2.sqrt() * (y / x2.sqrt()).atan()
                - x * x.atan()
                - y * y.atan())
    }

    #[test]
    fn parallel_squares_at_every_gap() {
        for h in [1.0, 1e-1, 1e-3, 1e-6, 1e-8] {
            let lower = [vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(1.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0)];
            let upper = [vec3(0.0, 0.0, h), vec3(0.0, 1.0, h), vec3(1.0, 1.0, h), vec3(1.0, 0.0, h)];
            let (f, _, _, _) = quad_exchange::<f64>(&lower, &upper, 10).unwrap();
            let exact = c11(h);
            // The closed form's terms grow like 1/h² and cancel to O(1): it keeps about
            // ε/h² digits less, 1e-10 at h = 1e-8.
            let allowed = if h < 1e-6 { 1e-10 } else { 1e-12 };
            assert!(((f - exact) / exact).abs() < allowed, "h = {h}: {f} vs {exact}");
        }
    }

    /// The graded rules along curved edges against the closed-form inner integral, on
    /// parallelograms (whose edges either path takes): squares offset so that their edges cross
    /// seen along the normal, one tilted, gaps 0.3 … 1e-6 — the crossings, the ends passing
    /// close and the corners over the other's edges are the singular points the outer rule
    /// must find.
    #[test]
    fn graded_edges_agree_with_the_closed_form() {
        use crate::surface::Parallelogram;
        for h in [0.3, 1e-2, 1e-4, 1e-6] {
            for (offset, tilt) in [((0.0, 0.0), 0.0), ((0.37, 0.21), 0.0), ((0.5, -0.45), 0.1), ((0.999, 0.2), 0.0)] {
                let lower = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
                let upper =
                    Parallelogram::new(vec3(offset.0, offset.1, h), vec3(0.0, 0.8, tilt), vec3(1.2, 0.0, 0.0)).unwrap();
                let (pa, pb) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
                let (oa, ob) = (Outline::new(&pa).unwrap(), Outline::new(&pb).unwrap());
                let (curved, _, rounding) = curve_exchange(&oa, &ob, 16).unwrap();
                let corners = |p: &Parallelogram<f64>| {
                    let (o, et, es) = p.affine_map().unwrap();
                    [o, o + et, o + et + es, o + es]
                };
                let (cl, cu) = (corners(&lower), corners(&upper));
                // The upper one's corners run clockwise about +z, i.e. counter-clockwise about
                // its radiating normal (−z, towards the lower one).
                let (closed, _, _, _) = quad_exchange::<f64>(&cl, &cu, 16).unwrap();
                // Both sum O(1) terms to a value that can be far smaller (8e-4 where the squares
                // overlap by 1e-3): the quadrature error scales with the terms, as the rounding
                // bound (8 ε × their magnitude) does.
                let difference = (curved - closed).abs();
                assert!(
                    difference < 1e-12 * closed + 64.0 * rounding,
                    "h {h}, offset {offset:?}, tilt {tilt}: {curved} vs {closed}"
                );
            }
        }
    }

    /// Only flat patches have an outline: a cylinder's wall and a sphere cell have none, a disk
    /// sector and a planar Bézier patch do (the sector's edge at r = 0 collapses).
    #[test]
    fn outlines_of_flat_patches_only() {
        use crate::surface::{BezierPatch, Cylinder, Disk, ParamRect, Side, Sphere};
        let z = vec3(0.0, 0.0, 1.0);
        let wall = Cylinder::new(vec3(0.0, 0.0, 0.0), z, 1.0, 1.0, Side::Outer).unwrap();
        assert!(Outline::new(&Patch::whole(&wall).unwrap()).is_none());
        let ball = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
        let cell = ParamRect::new(0.5, 1.0, 0.0, 1.0).unwrap();
        assert!(Outline::new(&Patch::new(&ball, cell).unwrap()).is_none());
        let disk = Disk::new(vec3(0.0, 0.0, 0.0), z, 1.0).unwrap();
        let sector = Outline::new(&Patch::new(&disk, ParamRect::new(0.0, 1.0, 0.0, 1.0).unwrap()).unwrap()).unwrap();
        assert_eq!(sector.live, [true, true, true, false]);
        let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in control.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                *p = vec3(i as f64 + 0.1 * (j * j) as f64, j as f64, 0.0);
            }
        }
        let flat = BezierPatch::new(control).unwrap();
        assert!(Outline::new(&Patch::whole(&flat).unwrap()).is_some());
        if let Some(p) = control.get_mut(1).and_then(|row| row.get_mut(2)) {
            p.z = 0.01;
        }
        let bent = BezierPatch::new(control).unwrap();
        assert!(Outline::new(&Patch::whole(&bent).unwrap()).is_none());
        // Bumps that vanish with zero slope at t, s = k/6: a uniform 7 × 7 grid sees a plane.
        struct Bumps;
        impl crate::surface::ParametricMap<f64> for Bumps {
            fn domain(&self) -> ParamRect<f64> {
                ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
            }
            fn map<S: crate::dual::Scalar<f64>>(&self, t: S, s: S) -> crate::vec3::Vec3<S> {
                let six_pi = S::constant(6.0 * core::f64::consts::PI);
                let (a, b) = ((t * six_pi).sin(), (s * six_pi).sin());
                vec3(t, s, S::constant(0.05) - S::constant(0.1) * a * a * b * b)
            }
        }
        let bumps = crate::surface::AutoNormal(Bumps);
        assert!(Outline::new(&Patch::whole(&bumps).unwrap()).is_none());
    }
}

#[cfg(test)]
mod point_form_tests {
    use super::*;
    use crate::surface::Disk;
    use crate::vec3::vec3;

    /// Lambert's polygon form for the unit circle as an m-gon clipped by p's tangent plane
    /// (Sutherland–Hodgman, each clipped vertex summed as it is produced).
    fn polygon(p: Vec3<f64>, np: Vec3<f64>, m: usize) -> f64 {
        let corner = |k: usize| {
            let phi = 2.0 * core::f64::consts::PI * ((k % m) as f64) / m as f64;
            vec3(phi.cos(), phi.sin(), 0.0)
        };
        // The polygon's edges as its vertices come: (sum, first vertex, previous vertex).
        let mut state = (0.0, None::<Vec3<f64>>, None::<Vec3<f64>>);
        let add = |state: &mut (f64, Option<Vec3<f64>>, Option<Vec3<f64>>), v: Vec3<f64>| {
            if let Some(u) = state.2 {
                let (a, b) = (u - p, v - p);
                let c = a.cross(b);
                let sine = c.norm();
                if sine > 0.0 {
                    state.0 += sine.atan2(a.dot(b)) * np.dot(c) / sine;
                }
            } else {
                state.1 = Some(v);
            }
            state.2 = Some(v);
        };
        for k in 0..m {
            let (a, b) = (corner(k), corner(k + 1));
            let (da, db) = (np.dot(a - p), np.dot(b - p));
            if da > 0.0 {
                add(&mut state, a);
            }
            if (da > 0.0) != (db > 0.0) {
                add(&mut state, a + (b - a).scale(da / (da - db)));
            }
        }
        if let Some(v) = state.1 {
            add(&mut state, v);
        }
        let sum = state.0;
        0.5 * sum.abs()
    }

    /// The point form over a whole unit disk (curved rim, seam, dead centre edge) against
    /// inscribed 2·10⁴- and 4·10⁴-gons extrapolated in 1/m² (Richardson), written here:
    /// points above the rim whose tangent plane touches it (a double root of the height),
    /// cuts a cap of half-angle 1.4e-5 or 1.4e-3 off it, or crosses the disk obliquely.
    #[test]
    fn point_form_agrees_with_fine_polygons() {
        let disk = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0_f64).unwrap();
        let patch = Patch::whole(&disk).unwrap();
        let outline = Outline::new(&patch).unwrap();
        let wall = |theta: f64, z: f64, shrink: f64| {
            (vec3(theta.cos() * shrink, theta.sin() * shrink, z), vec3(-theta.cos(), -theta.sin(), 0.0))
        };
        let cases = [
            (vec3(0.3, 0.2, 0.5), vec3(1.0, 0.5, 0.3).scale(1.0 / 1.34_f64.sqrt())),
            wall(0.3, 0.1, 1.0),
            wall(1.0, 0.15, 1.0),
            wall(4.0, 0.6, 1.0),
            wall(0.3, 0.1, 1.0 - 1e-10),
            wall(0.3, 0.1, 1.0 - 1e-6),
            wall(4.0, 0.6, 1.0 - 1e-3),
        ];
        for (p, np) in cases {
            let (coarse, fine) = (polygon(p, np, 20_000), polygon(p, np, 40_000));
            let reference = fine + (fine - coarse) / 3.0;
            for order in [12, 16] {
                let rule = GaussRule::<f64>::new(order).unwrap();
                let (j, _, _) = outline.point_form(&rule, p, np).unwrap();
                let rel = ((j - reference) / reference).abs();
                assert!(rel < 1e-12, "p {p:?} order {order}: {j} against {reference} ({rel:.1e})");
            }
        }
    }
}

/// Triangles and general quadrilaterals (straight corners, [`crate::Quadrilateral`]) by the
/// closed-form inner integrals against the same flat patches as Bézier nets, whose pairs take
/// the curved-outline rules (`curve.rs`: the inner integral by graded Gauss rules, no closed
/// form): separate, sharing an edge, sharing a vertex, and patches of subdivided triangles
/// (a patch at the collapsed corner is itself a triangle).
#[test]
fn triangles_and_quadrilaterals_match_their_bezier_nets() {
    use crate::surface::{BezierPatch, Quadrilateral};
    use crate::{adaptive_exchange, Adaptive, ParamRect};
    let net = |q: &Quadrilateral<f64>| {
        let mut n = [[vec3(0.0, 0.0, 0.0); 4]; 4];
        for (i, row) in n.iter_mut().enumerate() {
            for (j, p) in row.iter_mut().enumerate() {
                *p = q.point(i as f64 / 3.0, j as f64 / 3.0);
            }
        }
        BezierPatch::new(n).unwrap()
    };
    let (o, x, z) = (vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0));
    let floor = Quadrilateral::triangle(o, x, vec3(0.8, 1.1, 0.0)).unwrap();
    let floor_quad = Quadrilateral::new([o, x, vec3(1.2, 0.9, 0.0), vec3(-0.1, 0.7, 0.0)]).unwrap();
    let cases = [
        // Shared edge o–x, perpendicular.
        (floor, Quadrilateral::triangle(o, vec3(0.3, 0.0, 0.9), x).unwrap()),
        // Shared vertex o, at an angle.
        (floor, Quadrilateral::triangle(o, vec3(-0.5, 0.6, 0.4), vec3(-0.4, -0.3, 0.8)).unwrap()),
        // Separate, tilted, quadrilateral against triangle.
        (floor_quad, Quadrilateral::triangle(vec3(0.2, 0.1, 0.7), vec3(0.3, 0.9, 1.0), vec3(1.1, 0.4, 0.8)).unwrap()),
        // Shared edge between two quadrilaterals.
        (floor_quad, Quadrilateral::new([o, z, vec3(1.1, 0.0, 0.8), x]).unwrap()),
    ];
    let rects = [ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }, ParamRect { t0: 0.0, t1: 0.5, s0: 0.25, s1: 0.75 }];
    for (k, (a, b)) in cases.iter().enumerate() {
        for ra in rects {
            let (pa, pb) = (Patch::new(a, ra).unwrap(), Patch::whole(b).unwrap());
            let fast = adaptive_exchange::<f64, _, _, _, 256>(&pa, &pb, Adaptive::new(1e-12), &()).unwrap();
            let (na, nb) = (net(a), net(b));
            let (qa, qb) = (Patch::new(&na, ra).unwrap(), Patch::whole(&nb).unwrap());
            let slow = adaptive_exchange::<f64, _, _, _, 256>(&qa, &qb, Adaptive::new(1e-12), &()).unwrap();
            let rel = (fast.value - slow.value).abs() / slow.value;
            assert!(fast.value > 0.0 && rel < 1e-11, "case {k} {ra:?}: {} vs {} ({rel:e})", fast.value, slow.value);
            assert!(fast.error.unwrap() < 1e-11 * fast.value, "case {k}: {:?}", fast.error);
            // The closed-form inner integrals need far fewer evaluations than the graded ones.
            assert!(fast.evaluations * 10 < slow.evaluations, "case {k}: {} vs {}", fast.evaluations, slow.evaluations);
        }
    }
}

/// The edge pairs in closed form ([`closed_edge_pair`]: parallel, and from one point) against
/// known integrals and against the graded rule with the closed-form inner integral
/// ([`edge_pair`] at order 24) on pseudo-random placements: collinear overlapping, collinear
/// apart, parallel at any offset, either direction; edges leaving a common end at any angle,
/// whichever ends they share.
#[test]
fn closed_edge_pairs_match_known_integrals_and_the_graded_rule() {
    use crate::vec3::vec3;
    let (o, x, y) = (vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0));
    // ∫₀¹∫₀¹ ln |s − s′| = −3/2; ∫₀¹∫₀¹ ½ ln(s² + s′²) = (ln 2 − 3 + π/2)/2.
    let same = closed_edge_pair(Edge::new(o, x), Edge::new(o, x)).unwrap().0;
    assert!((same + 1.5).abs() < 1e-15, "{same}");
    let right = closed_edge_pair(Edge::new(o, x), Edge::new(o, y)).unwrap().0;
    let exact = (2f64.ln() - 3.0 + core::f64::consts::FRAC_PI_2) / 2.0;
    assert!((right - exact).abs() < 1e-15, "{right} vs {exact}");
    // Skew and crossing edges have no closed form here.
    assert!(closed_edge_pair(Edge::new(o, x), Edge::new(vec3(0.5, -0.5, 0.3), y)).is_none());
    assert!(closed_edge_pair(Edge::new(o, x), Edge::new(vec3(0.5, -0.5, 0.0), y)).is_none());

    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let rule = GaussRule::<f64>::new(24).unwrap();
    let (mut parallel, mut pointed) = (0, 0);
    for case in 0..400 {
        let p = vec3(next(), next(), next());
        let da = vec3(next(), next(), next());
        let (q, db) = if case % 2 == 0 {
            // Parallel: b along ±da, offset anywhere (a quarter of them on a's line).
            let along = da.scale(next() * 1.5);
            let off = if case % 8 == 0 { da.scale(next() * 2.0) } else { vec3(next(), next(), next()) };
            (p + off, if along.norm() > 1e-3 { along } else { da })
        } else {
            // From one point: b starts or ends where a starts or ends.
            let db = vec3(next(), next(), next());
            let start = if case % 4 == 1 { p } else { p + da };
            if case % 3 == 0 {
                (start, db)
            } else {
                (start - db, db)
            }
        };
        let Some((closed, magnitude, _)) = closed_edge_pair(Edge::new(p, da), Edge::new(q, db)) else { continue };
        if case % 2 == 0 {
            parallel += 1;
        } else {
            pointed += 1;
        }
        let (graded, _, _) = edge_pair(&rule, Edge::new(p, da), Edge::new(q, db));
        assert!(
            (closed - graded).abs() < 1e-14 * magnitude.max(1.0),
            "case {case}: {closed} vs {graded} (magnitude {magnitude})"
        );
    }
    // The cancellation limit refuses only short edges far from the other.
    assert!(parallel > 150 && pointed > 150, "{parallel} parallel, {pointed} from one point");
}
