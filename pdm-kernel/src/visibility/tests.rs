//! Unit tests of the curvature test and the occluders.

use super::*;
use crate::integrand::mutually_facing;
use crate::surface::Side;
use crate::vec3::vec3;

fn o() -> Vec3<f64> {
    vec3(0.0, 0.0, 0.0)
}

#[test]
fn curvature_test_needs_both_dot_products() {
    let up = vec3(0.0, 0.0, 1.0);
    let down = vec3(0.0, 0.0, -1.0);
    let a = o();
    let b = vec3(0.3, 0.0, 1.0);
    assert!(mutually_facing(a, up, b, down));
    assert!(!mutually_facing(a, up, b, up), "fig. 4b: one dot product negative");
    assert!(!mutually_facing(a, down, b, up), "fig. 4c: both negative");
}

#[test]
fn sphere_blocks_through_not_from_surface() {
    let s = Sphere::outer(o(), 1.0).unwrap();
    assert!(s.blocks(vec3(-3.0, 0.0, 0.0), vec3(3.0, 0.0, 0.0)));
    assert!(!s.blocks(vec3(-3.0, 1.5, 0.0), vec3(3.0, 1.5, 0.0)));
    // From a point on the sphere outward: not blocked (its own surface at τ = 0).
    assert!(!s.blocks(vec3(1.0, 0.0, 0.0), vec3(3.0, 0.5, 0.0)));
    // From a point on the sphere through the ball: blocked.
    assert!(s.blocks(vec3(1.0, 0.0, 0.0), vec3(-3.0, 0.0, 0.0)));
    // Chord between two points on the inside: visible (concave side sees itself).
    assert!(!s.blocks(vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)));
    // Segment ending before the sphere.
    assert!(!s.blocks(vec3(-3.0, 0.0, 0.0), vec3(-2.0, 0.0, 0.0)));
}

#[test]
fn sphere_occlusion_is_scale_invariant() {
    for k in [1e-12, 1e-6, 1.0, 1e6, 1e12] {
        let s = Sphere::outer(o(), k).unwrap();
        assert!(s.blocks(vec3(-3.0 * k, 0.1 * k, 0.0), vec3(3.0 * k, 0.0, 0.2 * k)));
        assert!(!s.blocks(vec3(-3.0 * k, 1.1 * k, 0.0), vec3(3.0 * k, 1.1 * k, 0.0)));
    }
}

#[test]
fn parallelogram_and_disk() {
    let sq = Parallelogram::new(vec3(-1.0, -1.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0)).unwrap();
    assert!(sq.blocks(vec3(0.5, 0.5, -1.0), vec3(0.5, 0.5, 1.0)));
    assert!(!sq.blocks(vec3(1.5, 0.5, -1.0), vec3(1.5, 0.5, 1.0)));
    assert!(!sq.blocks(vec3(0.5, 0.5, 0.5), vec3(0.5, 0.5, 1.0)));
    assert!(!sq.blocks(vec3(0.0, 0.0, 1.0), vec3(1.0, 0.0, 1.0)), "parallel");
    let ring = Disk::annulus(o(), vec3(0.0, 0.0, 1.0), 0.5, 1.0).unwrap();
    assert!(ring.blocks(vec3(0.75, 0.0, -1.0), vec3(0.75, 0.0, 1.0)));
    assert!(!ring.blocks(vec3(0.2, 0.0, -1.0), vec3(0.2, 0.0, 1.0)), "through the hole");
    assert!(!ring.blocks(vec3(1.2, 0.0, -1.0), vec3(1.2, 0.0, 1.0)));
}

#[test]
fn cylinder_tube() {
    let c = Cylinder::new(o(), vec3(0.0, 0.0, 1.0), 1.0, 2.0, Side::Outer).unwrap();
    assert!(c.blocks(vec3(-3.0, 0.0, 1.0), vec3(3.0, 0.0, 1.0)));
    assert!(!c.blocks(vec3(-3.0, 0.0, 3.0), vec3(3.0, 0.0, 3.0)), "above the tube");
    assert!(!c.blocks(vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 3.0)), "along the axis, open ends");
    // Inside chord between two points on the wall: not blocked.
    assert!(!c.blocks(vec3(1.0, 0.0, 0.5), vec3(-1.0, 0.0, 1.5)));
    // Enters through the open top, leaves through the wall: blocked.
    assert!(c.blocks(vec3(0.0, 0.0, 2.5), vec3(3.0, 0.0, 0.5)));
}

/// Every change of `blocks(p, origin + τ·direction)` along a line lies at a root of one of
/// the occluder's `line_polynomials`: sampled densely on random lines, each change is
/// bracketed by two samples 1e-4 apart and must contain a candidate.
#[cfg(feature = "closed-form")]
fn check_line_breaks<O: Occluder<f64>>(occluder: &O, seed: u64) -> usize {
    check_line_breaks_from(occluder, seed, |x, y, z| vec3(3.0 * x, 3.0 * y, 3.0 + z))
}

/// [`check_line_breaks`] with p = `point` of three numbers uniform in [−1, 1).
#[cfg(feature = "closed-form")]
fn check_line_breaks_from<O: Occluder<f64>>(
    occluder: &O,
    seed: u64,
    point: impl Fn(f64, f64, f64) -> Vec3<f64>,
) -> usize {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut changes = 0;
    for _ in 0..200 {
        let (x, y, z) = (next(), next(), next());
        let p = point(x, y, z);
        let origin = vec3(3.0 * next(), 3.0 * next(), -3.0 + next());
        let direction = vec3(next(), next(), 0.3 * next()).scale(4.0);
        let mut candidates = [0.0f64; 64];
        let mut n = 0;
        assert!(occluder.line_polynomials(p, origin, direction, &mut |[a, b, c]| {
            polynomial_roots(a, b, c, &mut |t| {
                if let Some(slot) = candidates.get_mut(n) {
                    *slot = t;
                    n += 1;
                }
            });
        }));
        let samples = 20_000;
        let at = |k: usize| -2.0 + 4.0 * k as f64 / samples as f64;
        let mut prev = occluder.blocks(p, origin + direction.scale(at(0)));
        for k in 1..=samples {
            let now = occluder.blocks(p, origin + direction.scale(at(k)));
            if now != prev {
                changes += 1;
                let (lo, hi) = (at(k - 1), at(k));
                let found = candidates.iter().take(n).any(|&c| c >= lo - 1e-9 && c <= hi + 1e-9);
                assert!(
                    found,
                    "change in [{lo}, {hi}] without a candidate (p {p:?}, line {origin:?} + t {direction:?})"
                );
            }
            prev = now;
        }
    }
    changes
}

#[cfg(feature = "closed-form")]
#[test]
fn line_polynomials_vanish_at_every_change_of_visibility() {
    use crate::surface::Cone;
    let sphere = Sphere::new(vec3(0.2, -0.1, 0.0), 1.3, Side::Outer).unwrap();
    let quad = Parallelogram::new(vec3(-1.0, -0.5, 0.3), vec3(2.0, 0.4, 0.1), vec3(-0.3, 1.5, 0.2)).unwrap();
    let disk = Disk::annulus(vec3(0.1, 0.2, -0.2), vec3(0.2, 0.1, 1.0), 0.4, 1.6).unwrap();
    // Each occluder must actually cast shadows on the sampled lines.
    assert!(check_line_breaks(&sphere, 1) > 100);
    assert!(check_line_breaks(&quad, 2) > 100);
    assert!(check_line_breaks(&disk, 3) > 100);
    let mixed = [AnyOccluder::Sphere(sphere), AnyOccluder::Parallelogram(quad), AnyOccluder::Disk(disk)];
    assert!(check_line_breaks(&mixed, 4) > 100);
    // Tubes and cones, upright and tilted, a frustum widening or narrowing, a cone to its apex.
    let tube = Cylinder::new(vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 1.0), 1.0, 2.0, Side::Outer).unwrap();
    let tilted = Cylinder::new(vec3(-0.3, 0.2, -1.2), vec3(0.4, -0.3, 1.0), 0.7, 2.5, Side::Outer).unwrap();
    let frustum = Cone::new(vec3(0.1, 0.0, -1.0), vec3(0.2, 0.1, 1.0), 1.2, 0.4, 2.0, Side::Outer).unwrap();
    let widening = Cone::new(vec3(0.0, 0.3, -0.8), vec3(-0.3, 0.2, 1.0), 0.3, 1.1, 1.7, Side::Outer).unwrap();
    let apex = Cone::new(vec3(0.0, 0.0, -1.0), vec3(0.0, 0.0, 1.0), 1.0, 0.0, 2.0, Side::Outer).unwrap();
    assert!(check_line_breaks(&tube, 5) > 100);
    assert!(check_line_breaks(&tilted, 6) > 100);
    assert!(check_line_breaks(&frustum, 7) > 100);
    assert!(check_line_breaks(&widening, 8) > 100);
    assert!(check_line_breaks(&apex, 9) > 100);
    let mixed = [AnyOccluder::Cylinder(tilted), AnyOccluder::Cone(frustum), AnyOccluder::Sphere(sphere)];
    assert!(check_line_breaks(&mixed, 10) > 100);
    // Seen from beside the tube and the frustum, from inside them, and from points of their
    // surfaces (a patch of the occluder itself: the second crossing passing p).
    let around = |x: f64, y: f64, z: f64| vec3(2.0 * x, 2.0 * y, 1.5 * z);
    assert!(check_line_breaks_from(&tube, 14, around) > 100);
    assert!(check_line_breaks_from(&frustum, 15, around) > 100);
    let on_tube = |x: f64, _: f64, z: f64| vec3((3.2 * x).cos(), (3.2 * x).sin(), z - 1e-3 * z.signum());
    assert!(check_line_breaks_from(&tube, 16, on_tube) > 100);
    let on_apex_cone = |x: f64, _: f64, z: f64| {
        let height = 0.9 * z;
        let radius = 1.0 - (height + 1.0) / 2.0;
        vec3(radius * (3.2 * x).cos(), radius * (3.2 * x).sin(), height)
    };
    assert!(check_line_breaks_from(&apex, 17, on_apex_cone) > 100);
}

#[test]
fn polynomial_roots_are_accurate_and_complete() {
    let roots = |a: f64, b: f64, c: f64| {
        let mut r = [f64::NAN; 2];
        let mut n = 0;
        polynomial_roots(a, b, c, &mut |x| {
            if let Some(slot) = r.get_mut(n) {
                *slot = x;
            }
            n += 1;
        });
        (n, r)
    };
    // (τ − 1e8)(τ − 1e-8): the small root without cancellation.
    let (n, r) = roots(1.0, -(1e8 + 1e-8), 1.0);
    assert_eq!(n, 2);
    assert!(r.iter().any(|&x| ((x - 1e-8) / 1e-8).abs() < 1e-15));
    assert_eq!(roots(0.0, 2.0, -1.0).0, 1);
    assert_eq!(roots(0.0, 2.0, -1.0).1[0], 0.5);
    assert_eq!(roots(0.0, 0.0, 1.0).0, 0);
    assert_eq!(roots(1.0, 0.0, 1.0).0, 0);
    assert_eq!(roots(1.0, -2.0, 1.0).0, 1);
}

#[test]
fn combinations() {
    let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
    let far = Sphere::outer(vec3(0.0, 10.0, 0.0), 1.0).unwrap();
    let (p, q) = (vec3(-3.0, 0.0, 0.0), vec3(3.0, 0.0, 0.0));
    assert!([far, s].blocks(p, q));
    assert!(![far].blocks(p, q));
    assert!((far, AnyOccluder::Sphere(s)).blocks(p, q));
    let mut v: heapless::Vec<AnyOccluder<f64>, 4> = heapless::Vec::new();
    assert!(!v.blocks(p, q));
    v.push(AnyOccluder::Sphere(s)).unwrap();
    assert!(v.blocks(p, q));
    assert!(!<() as Occluder<f64>>::blocks(&(), p, q));
    assert!(Some(s).blocks(p, q));
    let a = Ball { center: vec3(0.0, 5.0, -3.0), radius: 0.5 };
    let b = Ball { center: vec3(0.0, 5.0, 3.0), radius: 0.5 };
    assert!(!s.may_block_between(&a, &b));
    assert!(
        far.may_block_between(&Ball { center: p, radius: 0.5 }, &Ball { center: vec3(0.0, 13.0, 0.0), radius: 0.1 })
    );
}

/// A small deterministic generator for the geometric tests (xorshift64*), values in [-1, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        2.0 * (x as f64 / (1u64 << 53) as f64) - 1.0
    }
    fn vec(&mut self, scale: f64) -> Vec3<f64> {
        vec3(self.next() * scale, self.next() * scale, self.next() * scale)
    }
}

/// The hull of two balls is the union of the balls centred on the segment between their
/// centres with linearly interpolated radii: an independent way to get the distance.
#[test]
fn hull_distance_matches_union_of_interpolated_balls() {
    let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
    let mut inside = 0;
    for case in 0..2000 {
        let a = Ball { center: rng.vec(3.0), radius: if case % 5 == 0 { 0.0 } else { 1.0 + rng.next() } };
        let b = Ball { center: rng.vec(3.0), radius: 1.0 + rng.next() };
        let x = rng.vec(3.0);
        let mut brute = f64::INFINITY;
        for k in 0..=20_000 {
            let l = f64::from(k) / 20_000.0;
            let c = a.center.scale(1.0 - l) + b.center.scale(l);
            let r = a.radius * (1.0 - l) + b.radius * l;
            brute = brute.min(((x - c).norm() - r).max(0.0));
        }
        let d = distance_to_hull_of_balls(x, &a, &b);
        // The λ grid overestimates the minimum by at most (step · slope)² scale.
        assert!(d <= brute + 1e-12, "case {case}: {d} > {brute}");
        assert!(brute - d <= 1e-6, "case {case}: {d} vs {brute}");
        inside += usize::from(d == 0.0);
    }
    assert!(inside > 50 && inside < 1900, "cases inside the hull: {inside}");
}

/// Whenever the sphere claims to hide a ball from p, every probed segment from p into the
/// ball (surface and interior points) is blocked; and it does claim so in many cases.
#[test]
#[cfg(feature = "closed-form")]
fn sphere_hides_ball_only_when_every_segment_is_blocked() {
    let mut rng = Lcg(0x1234_5678_9abc_def1);
    let sphere = Sphere::outer(o(), 1.0).unwrap();
    let mut hidden = 0;
    for case in 0..4000 {
        // p outside, b roughly behind the sphere as seen from p.
        let p = rng.vec(1.0) + vec3(0.0, 0.0, 2.0 + 2.0 * rng.next().abs());
        let behind = (o() - p).scale(1.0 + 2.0 * rng.next().abs());
        let b = Ball { center: o() + behind + rng.vec(0.7), radius: 0.6 * rng.next().abs() };
        if !sphere.hides_ball_from(p, &b) {
            continue;
        }
        hidden += 1;
        for _ in 0..200 {
            let u = rng.vec(1.0);
            let dir = if u.norm() > 1e-9 { u.scale(1.0 / u.norm()) } else { vec3(1.0, 0.0, 0.0) };
            for f in [1.0, rng.next().abs()] {
                let q = b.center + dir.scale(b.radius * f);
                assert!(sphere.blocks(p, q), "case {case}: {p:?} -> {q:?} not blocked");
            }
        }
    }
    assert!(hidden > 200, "hidden in only {hidden} cases");
    // Not hidden: p inside, a ball overlapping the tangent cone's edge, a ball in front.
    let b = Ball { center: vec3(0.0, 0.0, -3.0), radius: 0.1 };
    assert!(sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &b));
    assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 0.5), &b));
    assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &Ball { center: vec3(1.9, 0.0, -3.0), radius: 0.5 }));
    assert!(!sphere.hides_ball_from(vec3(0.0, 0.0, 3.0), &Ball { center: vec3(0.0, 0.0, 1.5), radius: 0.1 }));
}

/// The cone occluder against a dense scan of the segment: the segment is blocked exactly when
/// the sign of r(z)² − |w⊥|² changes between interior samples at heights within [0, h].
#[test]
fn cone_blocks_where_a_scan_finds_a_crossing() {
    use crate::surface::Cone;
    let (r0, r1, h) = (1.0, 0.25, 1.5);
    let cone = Cone::new(o(), vec3(0.0, 0.0, 1.0), r0, r1, h, Side::Outer).unwrap();
    let field = |x: Vec3<f64>| {
        let rho = r0 + (r1 - r0) * x.z / h;
        x.x * x.x + x.y * x.y - rho * rho
    };
    // A deterministic spread of segments (a small linear congruential generator), crossing,
    // grazing, steeper and flatter than the side, inside and outside.
    let mut state = 12345u64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    let (mut blocked, mut clear) = (0, 0);
    for _ in 0..2000 {
        let p = vec3(next(), next(), next() + 0.75);
        let q = vec3(next(), next(), next() + 0.75);
        const N: usize = 4000;
        let mut crossings = 0;
        let mut prev: Option<f64> = None;
        for k in 1..N {
            let x = p + (q - p).scale(k as f64 / N as f64);
            let inside_height = x.z >= 0.0 && x.z <= h;
            let v = field(x);
            if let (Some(u), true) = (prev, inside_height) {
                if (u < 0.0) != (v < 0.0) {
                    crossings += 1;
                }
            }
            prev = inside_height.then_some(v);
        }
        // Segments whose scan brushes the surface or the rims are ambiguous at this sampling.
        let near_miss = (1..N).any(|k| {
            let x = p + (q - p).scale(k as f64 / N as f64);
            field(x).abs() < 1e-3 && (x.z.abs() < 1e-2 || (x.z - h).abs() < 1e-2 || x.z > 0.0 && x.z < h)
        });
        if crossings > 0 {
            assert!(cone.blocks(p, q), "{p:?} -> {q:?}: the scan crosses");
            blocked += 1;
        } else if !near_miss {
            assert!(!cone.blocks(p, q), "{p:?} -> {q:?}: the scan does not cross");
            clear += 1;
        }
    }
    assert!(blocked > 200 && clear > 200, "{blocked} blocked, {clear} clear");
    // From a point of the side outwards: not blocked; through the cone: blocked.
    assert!(!cone.blocks(vec3(1.0, 0.0, 0.0), vec3(3.0, 0.0, 0.5)));
    assert!(cone.blocks(vec3(1.0, 0.0, 0.0), vec3(-3.0, 0.0, 0.0)));
    // Beyond the top (the other nappe of the quadric lies past the apex of the full cone).
    assert!(!cone.blocks(vec3(-3.0, 0.0, 3.0), vec3(3.0, 0.0, 3.0)));
}

/// The Bézier occluder on a net that is exactly a sphere-free quadratic (the paraboloid
/// z = x² + y² over [−1, 1]², degree-elevated): a segment crosses it where the sign of
/// z − x² − y² changes inside the square, and its own points do not block segments leaving
/// towards either side.
#[test]
fn bezier_blocks_where_the_paraboloid_is_crossed() {
    use crate::surface::BezierPatch;
    let q = [1.0, -1.0 / 3.0, -1.0 / 3.0, 1.0];
    let mut net = [[o(); 4]; 4];
    for (i, row) in net.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            *p = vec3(-1.0 + 2.0 * i as f64 / 3.0, -1.0 + 2.0 * j as f64 / 3.0, q[i] + q[j]);
        }
    }
    // The same dish in the standard frame and turned about an oblique axis: the pruning of
    // sub-nets (balls, and slabs along each piece's own normal) must not depend on the frame.
    let turned = |x: Vec3<f64>| {
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let k = vec3(1.0, 2.0, -1.0).scale(1.0 / 6f64.sqrt());
        // Rodrigues: x cos + (k × x) sin + k (k·x)(1 − cos).
        x.scale(c) + k.cross(x).scale(s) + k.scale(k.dot(x) * (1.0 - c))
    };
    for turn in [false, true] {
        let map = |x: Vec3<f64>| if turn { turned(x) } else { x };
        let dish = BezierPatch::new(net.map(|row| row.map(map))).unwrap();
        let field = |x: Vec3<f64>| x.z - x.x * x.x - x.y * x.y;
        let inside = |x: Vec3<f64>| x.x.abs() <= 1.0 && x.y.abs() <= 1.0;
        let mut state = 777u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 3.0 - 1.5
        };
        let (mut blocked, mut clear) = (0, 0);
        for _ in 0..1000 {
            let p = vec3(next(), next(), next() + 1.0);
            let r = vec3(next(), next(), next() + 1.0);
            const N: usize = 4000;
            let (mut crossings, mut near, mut closest) = (0, false, f64::MAX);
            let mut prev: Option<f64> = None;
            for k in 1..N {
                let x = p + (r - p).scale(k as f64 / N as f64);
                let v = field(x);
                if inside(x) {
                    closest = closest.min(v.abs());
                    if let Some(u) = prev {
                        if (u < 0.0) != (v < 0.0) {
                            crossings += 1;
                            // A crossing next to the rim may fall either side of it.
                            near |= x.x.abs() > 0.99 || x.y.abs() > 0.99;
                        }
                    }
                    prev = Some(v);
                } else {
                    prev = None;
                }
            }
            // A segment that grazes the surface without crossing it at this sampling.
            near |= crossings == 0 && closest < 1e-2;
            if near {
                continue;
            }
            assert_eq!(dish.blocks(map(p), map(r)), crossings > 0, "{p:?} -> {r:?}, turned: {turn}");
            if crossings > 0 {
                blocked += 1;
            } else {
                clear += 1;
            }
        }
        assert!(blocked > 100 && clear > 100, "{blocked} blocked, {clear} clear");
        // From a point of the dish: up into the bowl and down below it, not blocked; across the
        // bowl to below the far rim, blocked.
        let on = map(vec3(0.5, 0.0, 0.25));
        assert!(!dish.blocks(on, map(vec3(0.4, 0.1, 2.0))));
        assert!(!dish.blocks(on, map(vec3(0.6, 0.0, -1.0))));
        assert!(dish.blocks(on, map(vec3(-2.0, 0.0, 1.0))));
    }
}

/// Short chords of the dish between its own points, on its concave side, are not blocked by it
/// (the corner triangles of the pieces around the end points lie off the surface).
#[test]
fn bezier_chords_of_its_own_points_are_clear() {
    use crate::surface::{BezierPatch, Surface};
    let q = [1.0, -1.0 / 3.0, -1.0 / 3.0, 1.0];
    let mut net = [[o(); 4]; 4];
    for (i, row) in net.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            *p = vec3(-1.0 + 2.0 * i as f64 / 3.0, -1.0 + 2.0 * j as f64 / 3.0, q[i] + q[j]);
        }
    }
    let dish = BezierPatch::new(net).unwrap();
    for k in 0..200 {
        let t = 0.05 + 0.9 * (k as f64 * 0.618_033_988_75).fract();
        let s = 0.05 + 0.9 * (k as f64 * 0.414_213_562_37).fract();
        for step in [1e-3, 1e-2, 0.1, 0.3] {
            let (a, b) = (dish.point(t, s), dish.point((t + step).min(1.0), (s + step * 0.5).min(1.0)));
            assert!(!dish.blocks(a, b), "chord ({t}, {s}) + {step}");
        }
    }
}

/// A flat Bézier patch (one subdivision level: the root is already flat) blocks segments whose
/// end points lie near it but off its plane, as the parallelogram it equals does; and a
/// triangle (a net with one side collapsed to a point) blocks as the triangle.
#[test]
fn flat_bezier_blocks_near_its_plane_like_the_parallelogram() {
    use crate::surface::BezierPatch;
    let (o_, et, es) = (vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0));
    let square = Parallelogram::new(o_, et, es).unwrap();
    let mut net = [[o(); 4]; 4];
    let mut tri = [[o(); 4]; 4];
    let (a, b, c) = (vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.0), vec3(0.0, 2.0, 0.0));
    for (i, (row, trow)) in net.iter_mut().zip(tri.iter_mut()).enumerate() {
        for (j, (p, tp)) in row.iter_mut().zip(trow.iter_mut()).enumerate() {
            let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
            *p = o_ + et.scale(u) + es.scale(v);
            *tp = a + (b - a + (c - b).scale(v)).scale(u);
        }
    }
    let flat = BezierPatch::new(net).unwrap();
    let triangle = BezierPatch::new(tri).unwrap();
    let mut state = 99u64;
    let mut next = || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 3.0 - 0.5
    };
    let (mut hits, mut tri_hits) = (0, 0);
    for _ in 0..2000 {
        // End points within the patch's ball, a little off its plane on either side.
        let p = vec3(next(), next(), 0.05 + 0.3 * next().abs());
        let q = vec3(next(), next(), -0.05 - 0.3 * next().abs());
        assert_eq!(flat.blocks(p, q), square.blocks(p, q), "{p:?} -> {q:?}");
        let d = q - p;
        let tau = -p.z / d.z;
        let x = p + d.scale(tau);
        let inside = x.x > 1e-9 && x.y > 1e-9 && x.x + x.y < 2.0 - 1e-9;
        let edge = x.x.abs() < 1e-6 || x.y.abs() < 1e-6 || (x.x + x.y - 2.0).abs() < 1e-6;
        if !edge {
            assert_eq!(triangle.blocks(p, q), inside, "{p:?} -> {q:?}");
        }
        hits += usize::from(square.blocks(p, q));
        tri_hits += usize::from(inside);
    }
    assert!(hits > 300 && tri_hits > 100 && tri_hits < hits, "{hits} {tri_hits}");
}

/// The quadrilateral occluder: a parallelogram-shaped one blocks exactly as the
/// [`Parallelogram`]; a triangle blocks where the segment crosses the triangle's plane inside
/// it (barycentric test); and its line polynomials vanish at every change of visibility.
#[test]
fn quadrilateral_and_triangle_block_as_their_outlines() {
    use crate::surface::Quadrilateral;
    let (o_, et, es) = (vec3(-0.4, 0.1, 0.0), vec3(2.0, 0.3, 0.0), vec3(-0.2, 1.7, 0.0));
    let square = Parallelogram::new(o_, et, es).unwrap();
    let quad = Quadrilateral::new([o_, o_ + et, o_ + et + es, o_ + es]).unwrap();
    let (a, b, c) = (vec3(0.0, 0.0, 0.0), vec3(2.0, 0.2, 0.0), vec3(0.3, 1.9, 0.0));
    let triangle = Quadrilateral::triangle(a, b, c).unwrap();
    let mut rng = Lcg(7);
    // Coordinates in [-0.5, 2.5): around both outlines.
    let mut next = || 1.0 + 1.5 * rng.next();
    let (mut hits, mut tri_hits) = (0, 0);
    for _ in 0..4000 {
        let p = vec3(next(), next(), 0.01 + 0.3 * next().abs());
        let q = vec3(next(), next(), -0.01 - 0.3 * next().abs());
        assert_eq!(quad.blocks(p, q), square.blocks(p, q), "{p:?} -> {q:?}");
        assert_eq!(quad.reversed().blocks(p, q), square.blocks(p, q), "{p:?} -> {q:?}");
        let d = q - p;
        let x = p + d.scale(-p.z / d.z);
        // Barycentric coordinates of x in ABC.
        let area = |u: Vec3<f64>, v: Vec3<f64>, w: Vec3<f64>| (v - u).cross(w - u).z;
        let (l1, l2, l3) = (area(x, b, c), area(a, x, c), area(a, b, x));
        let total = area(a, b, c);
        let inside = l1 > 0.0 && l2 > 0.0 && l3 > 0.0;
        if l1.min(l2).min(l3).abs() > 1e-9 * total {
            assert_eq!(triangle.blocks(p, q), inside, "{p:?} -> {q:?}");
            assert_eq!(triangle.reversed().blocks(p, q), inside, "{p:?} -> {q:?}");
        }
        hits += usize::from(square.blocks(p, q));
        tri_hits += usize::from(inside);
    }
    assert!(hits > 500 && tri_hits > 200, "{hits} {tri_hits}");
    // From a point of its own plane, a segment does not cross it.
    assert!(!triangle.blocks(vec3(0.5, 0.5, 0.0), vec3(0.5, 0.5, 1.0)));
    #[cfg(feature = "closed-form")]
    {
        let tilted = Quadrilateral::new([
            vec3(-1.0, -0.5, 0.3),
            vec3(1.0, -0.1, 0.4),
            vec3(0.8, 1.2, 0.6),
            vec3(-1.3, 1.0, 0.5),
        ]);
        // Four corners of a plane: z = 0.3 + 0.05 (x + 1) + ... must be coplanar; build them so.
        let plane = |x: f64, y: f64| vec3(x, y, 0.3 + 0.05 * x + 0.1 * y);
        assert!(tilted.is_err(), "the corners above are not coplanar");
        let tilted =
            Quadrilateral::new([plane(-1.0, -0.5), plane(1.0, -0.1), plane(0.8, 1.2), plane(-1.3, 1.0)]).unwrap();
        assert!(check_line_breaks(&tilted, 11) > 100);
        let tri = Quadrilateral::triangle(plane(-1.0, -0.5), plane(1.2, 0.0), plane(0.0, 1.4)).unwrap();
        assert!(check_line_breaks(&tri, 12) > 100);
        assert!(check_line_breaks(&AnyOccluder::Quadrilateral(tri), 13) > 100);
    }
}

/// The sphere's event quadrics against their geometry, for random corners, edges and points:
/// the corner quadric is |v|²(dist(centre, line(p, c))² − R²), the edge quadric
/// |d × v|²(dist(centre, plane(edge line, p))² − R²) (v = p − c), so each has the sign of the
/// distance minus the radius and vanishes exactly where the line or the plane is tangent.
#[test]
#[cfg(feature = "closed-form")]
fn sphere_event_quadrics_vanish_where_the_tangents_are() {
    let mut rng = Lcg(0x2545_f491_4f6c_dd1d);
    let sphere = Sphere::outer(vec3(0.3, -0.2, 0.1), 0.8).unwrap();
    let (centre, r) = (sphere.center, sphere.radius);
    for _ in 0..2000 {
        let (c, d, p) = (rng.vec(4.0), rng.vec(2.0), rng.vec(4.0));
        let mut quadrics = [Quadric::cone(Vec3::ZERO, [0.0; 6]); 2];
        let mut n = 0;
        assert!(sphere.event_quadrics(c, d, [&[], &[]], &mut |q| {
            quadrics[n] = q;
            n += 1;
        }));
        assert_eq!(n, 2);
        let v = p - c;
        let w = centre - c;
        let line_distance = w.cross(v).norm() / v.norm();
        let expected_corner = v.norm2() * (line_distance * line_distance - r * r);
        let normal = d.cross(v);
        let plane_distance = normal.dot(w).abs() / normal.norm();
        let expected_edge = normal.norm2() * (plane_distance * plane_distance - r * r);
        let scale = |e: f64, a: f64| e.abs().max(a.abs()).max(1e-300);
        let (corner, edge) = (quadrics[0].at(p), quadrics[1].at(p));
        assert!(
            (corner - expected_corner).abs() <= 1e-9 * scale(expected_corner, v.norm2() * w.norm2()),
            "{corner} {expected_corner}"
        );
        assert!(
            (edge - expected_edge).abs() <= 1e-9 * scale(expected_edge, normal.norm2() * w.norm2()),
            "{edge} {expected_edge}"
        );
    }
}

/// [`Quadric::sphere_circle_envelope`] vanishes on the envelope of the sphere's tangent planes
/// along a circle: points x + λ·d with x on the circle and d the direction, in the tangent
/// plane at x, across the circle (so the outline seen from the point touches the circle at x).
/// Points off the envelope give values of either sign, here checked to be away from zero
/// for most random points (a quadric that is zero everywhere would pass the first check).
#[test]
#[cfg(feature = "closed-form")]
fn sphere_circle_envelope_vanishes_on_the_tangent_planes_along_the_circle() {
    let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
    let mut off = 0;
    for _ in 0..2000 {
        let (centre, r) = (rng.vec(2.0), 0.3 + rng.next().abs());
        let n = rng.vec(1.0);
        let n = n.scale(1.0 / n.norm());
        let h = r * 0.95 * rng.next();
        let q = Quadric::sphere_circle_envelope(centre, r, n, h);
        let e1 = n.cross(vec3(0.3, -0.7, 0.2));
        let e1 = e1.scale(1.0 / e1.norm());
        let e2 = n.cross(e1);
        let a = 6.0 * rng.next();
        let rho = (r * r - h * h).sqrt();
        let x = centre + n.scale(h) + e1.scale(rho * a.cos()) + e2.scale(rho * a.sin());
        let xh = (x - centre).scale(1.0 / r);
        let tau = n.cross(xh);
        let d = xh.cross(tau.scale(1.0 / tau.norm()));
        let p = x + d.scale(4.0 * rng.next());
        let w2 = (p - centre).norm2();
        let scale = r * r * (w2 + r * r);
        assert!(q.at(p).abs() <= 1e-9 * scale, "{} against {scale}", q.at(p));
        let random = centre + rng.vec(4.0);
        let w2 = (random - centre).norm2();
        if q.at(random).abs() > 1e-3 * r * r * (w2 + r * r) {
            off += 1;
        }
    }
    assert!(off > 1900, "{off}");
}

/// A long tube between two squares whose segments keep clear of its rims, the whole placement
/// turned at random: every corner gives the two planes through it parallel to the axis and
/// tangent to the tube (a line of such a plane through the corner passes the axis at distance
/// R), and crossing either plane beyond the line of tangency changes whether the corner is seen
/// (each plane is where the shadow's edge passes the corner). Near a rim, with a square
/// reaching into the cylinder, or with nothing to cut, the tube declines or gives nothing.
#[test]
#[cfg(feature = "closed-form")]
fn cylinder_event_planes_are_where_the_shadow_passes_a_corner() {
    let mut rng = Lcg(0x5851_f42d_4c95_7f2d);
    let turn = |x: Vec3<f64>, k: Vec3<f64>, angle: f64| {
        let (c, s) = (angle.cos(), angle.sin());
        x.scale(c) + k.cross(x).scale(s) + k.scale(k.dot(x) * (1.0 - c))
    };
    let mut switched = 0;
    for _ in 0..200 {
        let k = rng.vec(1.0);
        let k = k.scale(1.0 / k.norm());
        let angle = 3.0 * rng.next();
        let shift = rng.vec(5.0);
        let place = |x: Vec3<f64>| turn(x, k, angle) + shift;
        let square = |z: f64| [vec3(0.0, 0.0, z), vec3(1.0, 0.0, z), vec3(1.0, 1.0, z), vec3(0.0, 1.0, z)].map(place);
        let (a, b) = (square(0.0), square(2.0));
        let (r, x0, z0) = (0.2 + 0.2 * rng.next().abs(), 0.3 + 0.4 * rng.next().abs(), 0.8 + 0.4 * rng.next().abs());
        let base = place(vec3(x0, -20.0, z0));
        let axis = turn(vec3(0.0, 1.0, 0.0), k, angle);
        let tube = Cylinder::new(base, axis, r, 40.0, Side::Outer).unwrap();
        for (corner, next) in b.iter().zip(b.iter().cycle().skip(1)) {
            let mut planes = [Quadric::plane(Vec3::ZERO, Vec3::ZERO); 2];
            let mut n = 0;
            assert!(tube.event_quadrics(*corner, *next - *corner, [&a, &b], &mut |q| {
                planes[n.min(1)] = q;
                n += 1;
            }));
            assert_eq!(n, 2);
            for plane in planes {
                let normal = plane.g.scale(1.0 / plane.g.norm());
                assert!(normal.dot(axis).abs() < 1e-12, "parallel to the axis");
                // The plane's distance from the axis is R.
                assert!((normal.dot(base - *corner).abs() - r).abs() < 1e-12 * (1.0 + shift.norm()));
                // Beyond the line of tangency, seen from the corner: the contact point is the
                // axis point's foot on the plane; p lies past it in the plane, at a height along
                // the axis within the tube.
                let foot = base - normal.scale(normal.dot(base - *corner));
                let along = axis.scale(axis.dot(*corner - base) + 2.0 * rng.next());
                let contact = foot + along - axis.scale(axis.dot(foot - base));
                let p = *corner + (contact - *corner).scale(1.5 + rng.next().abs());
                let delta = 1e-6;
                let (inside, outside) = (p + normal.scale(delta), p - normal.scale(delta));
                if tube.blocks(inside, *corner) != tube.blocks(outside, *corner) {
                    switched += 1;
                }
            }
        }
        // A tube from one side of the squares to the other (its rims in the planes of their
        // edges) gives the planes too; one ending over the squares (its rim in reach), one
        // reaching into the lower square's cylinder decline; one far to the side gives nothing.
        let flush = Cylinder::new(place(vec3(x0, 0.0, z0)), axis, r, 1.0, Side::Outer).unwrap();
        let mut given = 0;
        assert!(flush.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| given += 1));
        assert_eq!(given, 2);
        // A frustum with equal radii is the tube and gives its planes; a narrowing one none.
        let (mut tube_planes, mut cone_planes) = ([None; 2], [None; 2]);
        let twin = crate::surface::Cone::new(place(vec3(x0, 0.0, z0)), axis, r, r, 1.0, Side::Outer).unwrap();
        let mut count = 0;
        assert!(flush.event_quadrics(b[2], b[3] - b[2], [&a, &b], &mut |q| {
            tube_planes[count.min(1)] = Some(q);
            count += 1;
        }));
        count = 0;
        assert!(twin.event_quadrics(b[2], b[3] - b[2], [&a, &b], &mut |q| {
            cone_planes[count.min(1)] = Some(q);
            count += 1;
        }));
        assert_eq!(tube_planes, cone_planes);
        let narrowing =
            crate::surface::Cone::new(place(vec3(x0, 0.0, z0)), axis, r, 0.5 * r, 1.0, Side::Outer).unwrap();
        assert!(!narrowing.event_quadrics(b[2], b[3] - b[2], [&a, &b], &mut |_| {}));
        let short = Cylinder::new(place(vec3(x0, -20.0, z0)), axis, r, 20.5, Side::Outer).unwrap();
        assert!(!short.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| {}));
        let low = Cylinder::new(place(vec3(x0, -20.0, 0.1)), axis, 0.3, 40.0, Side::Outer).unwrap();
        assert!(!low.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| {}));
        // A tube standing through the upper square (its axis pierces it between the rims)
        // declines; one wholly beyond the squares' sides gives nothing; one whose rim plane the
        // pair straddles far from the rim (a tube off to the side, 3 from the squares) gives
        // its planes.
        let (up, at_b) = (turn(vec3(0.0, 0.0, 1.0), k, angle), place(vec3(0.5, 0.5, 1.0)));
        let pierced = Cylinder::new(at_b - up.scale(0.5), up, 0.1, 2.0, Side::Outer).unwrap();
        assert!(!pierced.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| {}));
        let beyond = Cylinder::new(place(vec3(x0, 1.5, z0)), axis, r, 5.0, Side::Outer).unwrap();
        let mut given = 0;
        assert!(beyond.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| given += 1));
        assert_eq!(given, 0);
        let aside = Cylinder::new(place(vec3(x0, 0.5, 5.0)), axis, r, 20.0, Side::Outer).unwrap();
        let mut given = 0;
        assert!(aside.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| given += 1));
        assert_eq!(given, 2);
        let far = Cylinder::new(place(vec3(30.0, -20.0, z0)), axis, r, 40.0, Side::Outer).unwrap();
        let mut given = 0;
        assert!(far.event_quadrics(b[0], b[1] - b[0], [&a, &b], &mut |_| given += 1));
        assert_eq!(given, 0);
    }
    assert_eq!(switched, 1600, "every plane crossing beyond the line of contact changes the view");
}
