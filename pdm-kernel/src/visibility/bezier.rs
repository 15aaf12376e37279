//! The bicubic Bézier patch as an occluder, to a stated tolerance: the segment is tested
//! against the patch by recursive subdivision of its control net (de Casteljau at ½ in both
//! directions), pruned by a ball around each sub-net's control points (the convex-hull
//! property), down to sub-nets that are flat to `BEZIER_FLATNESS` of the patch's size, whose two
//! corner triangles are intersected exactly.

use super::*;
use crate::surface::BezierPatch;
use crate::vec3::vec3;

/// Flatness at which a sub-net is replaced by its two corner triangles, relative to the whole
/// net's diameter (f64; f32 uses 256 ε instead when larger): segments passing within about this
/// distance of the surface may be classified either way.
pub const BEZIER_FLATNESS: f64 = 1e-7;

/// Most subdivision levels (a sub-net then spans 1/4096 of the patch along each side).
const MAX_LEVELS: u32 = 12;

type Net<T> = [[Vec3<T>; 4]; 4];

/// The ball (centroid, largest distance) around a net's control points: it contains the
/// sub-patch (convex-hull property).
fn net_ball<T: Real>(net: &Net<T>) -> (Vec3<T>, T) {
    let mut c = vec3(T::ZERO, T::ZERO, T::ZERO);
    for row in net {
        for &p in row {
            c = c + p;
        }
    }
    let c = c.scale(T::ONE / T::from_f64(16.0));
    let mut r2 = T::ZERO;
    for row in net {
        for &p in row {
            r2 = r2.max((p - c).norm2());
        }
    }
    // One root of the largest square (a square that overflows or underflows falls back to
    // the distances one by one).
    if r2 < T::MAX && r2 > T::MIN_POSITIVE / T::EPSILON {
        return (c, r2.sqrt());
    }
    let mut r = T::ZERO;
    for row in net {
        for &p in row {
            r = r.max((p - c).norm());
        }
    }
    (c, r)
}

/// How far the net is from the two triangles of its corners: the largest distance of a control
/// point from the bilinear map of the corners at its parameter (i/3, j/3), plus a quarter of
/// the corners' twist (the bilinear surface's largest distance from the two triangles).
fn flatness<T: Real>(net: &Net<T>) -> T {
    let (p00, p30, p03, p33) = (net[0][0], net[3][0], net[0][3], net[3][3]);
    let mut worst = T::ZERO;
    for (i, row) in net.iter().enumerate() {
        let u = T::from_usize(i) / T::from_f64(3.0);
        for (j, &p) in row.iter().enumerate() {
            let v = T::from_usize(j) / T::from_f64(3.0);
            let bilinear = p00.scale((T::ONE - u) * (T::ONE - v))
                + p30.scale(u * (T::ONE - v))
                + p03.scale((T::ONE - u) * v)
                + p33.scale(u * v);
            worst = worst.max((p - bilinear).norm());
        }
    }
    worst + (p00 - p30 - p03 + p33).norm() * T::from_f64(0.25)
}

/// De Casteljau at ½ of four points: the two halves.
fn halve<T: Real>(p: [Vec3<T>; 4]) -> ([Vec3<T>; 4], [Vec3<T>; 4]) {
    let h = T::HALF;
    let (a, b, c) = ((p[0] + p[1]).scale(h), (p[1] + p[2]).scale(h), (p[2] + p[3]).scale(h));
    let (ab, bc) = ((a + b).scale(h), (b + c).scale(h));
    let m = (ab + bc).scale(h);
    ([p[0], a, ab, m], [m, bc, c, p[3]])
}

/// The net split at s = ½ (columns) into two nets.
fn split_s<T: Real>(net: &Net<T>) -> (Net<T>, Net<T>) {
    let halves = net.map(halve);
    (halves.map(|h| h.0), halves.map(|h| h.1))
}

/// The net split at t = ½ (rows) into two nets: de Casteljau on whole rows, as [`halve`]
/// on each column.
fn split_t<T: Real>(net: &Net<T>) -> (Net<T>, Net<T>) {
    let mix = |a: [Vec3<T>; 4], b: [Vec3<T>; 4]| {
        let h = T::HALF;
        [(a[0] + b[0]).scale(h), (a[1] + b[1]).scale(h), (a[2] + b[2]).scale(h), (a[3] + b[3]).scale(h)]
    };
    let [r0, r1, r2, r3] = *net;
    let (a, b, c) = (mix(r0, r1), mix(r1, r2), mix(r2, r3));
    let (ab, bc) = (mix(a, b), mix(b, c));
    let m = mix(ab, bc);
    ([r0, a, ab, m], [m, bc, c, r3])
}

/// Segment p + τ d, τ ∈ (0, 1), against triangle (a, b, c) (Möller–Trumbore): the crossing's τ.
fn triangle_crossing<T: Real>(p: Vec3<T>, d: Vec3<T>, a: Vec3<T>, b: Vec3<T>, c: Vec3<T>) -> Option<T> {
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det == T::ZERO || !det.is_finite() {
        return None;
    }
    let inv = T::ONE / det;
    let s = p - a;
    let u = s.dot(h) * inv;
    if !(u >= T::ZERO && u <= T::ONE) {
        return None;
    }
    let qv = s.cross(e1);
    let v = d.dot(qv) * inv;
    if !(v >= T::ZERO && u + v <= T::ONE) {
        return None;
    }
    Some(e2.dot(qv) * inv)
}

struct Probe<T> {
    p: Vec3<T>,
    q: Vec3<T>,
    d: Vec3<T>,
    /// Flatness at which a sub-net counts as its triangles.
    flat: T,
    /// Crossings closer than this to an end point do not count (the end point lies on the
    /// surface up to the flatness).
    margin: T,
    length: T,
}

impl<T: Real> Probe<T> {
    fn accept(&self, tau: T) -> bool {
        interior(tau) && tau * self.length > self.margin && (T::ONE - tau) * self.length > self.margin
    }

    /// Whether the segment misses the slab that holds the net's control points (the plane
    /// through `c` normal to the corners' diagonals, as thick as the farthest control point,
    /// plus the flatness) within the ball (`c`, `r`) plus the flatness: the sub-patch lies in
    /// both (convex-hull property). The slab shrinks about four times per subdivision where the
    /// ball halves, so a segment leaving a nearly flat piece steeply is cut off levels earlier.
    fn misses_slab(&self, net: &Net<T>, c: Vec3<T>, r: T) -> bool {
        let normal = (net[3][3] - net[0][0]).cross(net[0][3] - net[3][0]);
        let length = normal.norm();
        if !(length > T::ZERO) || !length.is_finite() {
            return false;
        }
        let n = normal.scale(T::ONE / length);
        let mut thickness = T::ZERO;
        for row in net {
            for &x in row {
                thickness = thickness.max(n.dot(x - c).abs());
            }
        }
        let half = thickness + self.flat;
        // n·(p + τd − c) = a + τ·b, within ±half on τ ∈ [0, 1].
        let (a, b) = (n.dot(self.p - c), n.dot(self.d));
        let (lo, hi) = if b == T::ZERO {
            if a.abs() > half {
                return true;
            }
            (T::ZERO, T::ONE)
        } else {
            let (x, y) = ((-half - a) / b, (half - a) / b);
            (x.min(y).max(T::ZERO), x.max(y).min(T::ONE))
        };
        if !(lo <= hi) {
            return true;
        }
        let (from, to) = (self.p + self.d.scale(lo), self.p + self.d.scale(hi));
        distance_point_segment(c, from, to) > r + self.flat
    }

    fn hits(&self, net: &Net<T>, level: u32) -> bool {
        let (c, r) = net_ball(net);
        if distance_point_segment(c, self.p, self.q) > r + self.flat || self.misses_slab(net, c, r) {
            return false;
        }
        if level >= MAX_LEVELS || flatness(net) <= self.flat {
            // An end point on this nearly flat piece (within its ball and twice the flatness of
            // its plane): the segment starts (or ends) on the surface here and does not cross
            // it again within the piece (its corner triangles lie off the surface by up to the
            // flatness, which a segment leaving at a shallow angle would cross).
            let (p00, p30, p03, p33) = (net[0][0], net[3][0], net[0][3], net[3][3]);
            // The piece's plane: through its corners' centroid, normal to the diagonals (also for
            // a corner collapsed to a point, a triangle).
            let normal = (p33 - p00).cross(p03 - p30);
            let length = normal.norm();
            let centre = (p00 + p30 + p03 + p33).scale(T::from_f64(0.25));
            let reach = r + self.flat;
            let on_piece = |x: Vec3<T>| {
                (x - c).norm() <= reach
                    && (length > T::ZERO)
                    && (normal.dot(x - centre) / length).abs() <= T::TWO * self.flat
            };
            if on_piece(self.p) || on_piece(self.q) {
                return false;
            }
            let first = triangle_crossing(self.p, self.d, p00, p30, p33).is_some_and(|t| self.accept(t));
            return first || triangle_crossing(self.p, self.d, p00, p33, p03).is_some_and(|t| self.accept(t));
        }
        let (lo, hi) = split_t(net);
        let (a, b) = split_s(&lo);
        if self.hits(&a, level + 1) || self.hits(&b, level + 1) {
            return true;
        }
        let (a, b) = split_s(&hi);
        self.hits(&a, level + 1) || self.hits(&b, level + 1)
    }
}

impl<T: Real> Occluder<T> for BezierPatch<T> {
    /// Recursive subdivision (module docs): exact up to [`BEZIER_FLATNESS`] × the net's
    /// diameter. Crossings within 4 × that distance of an end point, or in the smallest piece
    /// around an end point that lies on the patch, do not count, so that segments from the
    /// patch's own points are not blocked by the piece they start on.
    fn blocks(&self, p: Vec3<T>, q: Vec3<T>) -> bool {
        let d = q - p;
        let length = d.norm();
        if !(length > T::ZERO) || !length.is_finite() {
            return false;
        }
        let (_, radius) = net_ball(&self.control);
        let relative = T::from_f64(BEZIER_FLATNESS).max(T::from_f64(256.0) * T::EPSILON);
        let flat = T::TWO * radius * relative;
        let probe = Probe { p, q, d, flat, margin: T::from_f64(4.0) * flat, length };
        probe.hits(&self.control, 0)
    }
    fn may_block_between(&self, a: &Ball<T>, b: &Ball<T>) -> bool {
        let (c, r) = net_ball(&self.control);
        ball_may_cut_pair(c, r, a, b)
    }
}
