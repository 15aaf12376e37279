//! Deterministic high-accuracy face → face form factors of the paper's test scene (section 4)
//! with the sphere as occluder, by the REFERENCES.md technique "Visibility boundaries without
//! losing Gauss convergence". No code is shared with `pdm-kernel`.
//!
//! # Scene and face numbering
//! A cube of side `l` centred at the origin, faces at `±l/2` facing inwards, and a sphere of
//! radius `R` (`0 ≤ R < l/2`, `R = 0`: no sphere) at the centre. Faces are numbered as in the
//! paper: 1 and 6 are pierced by the pole axis (z) of the sphere's parameterisation, and the
//! opposite pairs are exactly those of the paper's Table 3 (1-6, 2-3, 4-5):
//!
//! | face | plane      | inward normal |
//! |------|------------|---------------|
//! | 1    | z = +l/2   | (0, 0, −1)    |
//! | 6    | z = −l/2   | (0, 0, +1)    |
//! | 2    | y = −l/2   | (0, +1, 0)    |
//! | 3    | y = +l/2   | (0, −1, 0)    |
//! | 4    | x = −l/2   | (+1, 0, 0)    |
//! | 5    | x = +l/2   | (−1, 0, 0)    |
//!
//! (Face 2 is "frontal" for a viewer on the −y side.)
//!
//! # Method
//! `F_ab = F⁰_ab − B_ab` with `F⁰` the unoccluded closed form (C-11 for opposite faces, C-14
//! for adjacent ones — exact, and it carries the whole shared-edge `1/r²` singularity) and
//! `B_ab = (1/A_a) ∫_a ∫_b cos θ_a cos θ_b/(π r²) · [segment p–q meets the ball] dq dp` the
//! blocked part. For points on two different faces of the cube, the line through `p` and `q`
//! meets the cube exactly in `[p, q]` and the ball lies inside the cube, so the segment is
//! blocked iff the *line* passes within `R` of the centre `c`:
//! `Q(q) = ((c−p)·(q−p))² − (|c−p|² − R²)|q−p|² ≥ 0` (REFERENCES.md's quadratic condition).
//! Blocked pairs are far from the shared edge (the blocked integrand is bounded), so `B` has
//! no singularity, only visibility boundaries, which are put into the rule at every level:
//! * innermost, along a line `q(t) = q_s + t·e₂` of face `b` (with `e₂` parallel to face `a`, so
//!   that the blocked set on each line is one bounded interval), `Q ≥ 0` is a quadratic in `t`
//!   with closed-form roots, and the kernel `(n_a·v)(−n_b·v)/(π|v|⁴)` is integrated over the
//!   blocked interval **in closed form** (`∫ (P₀ + a₁u)/(u² + ρ²)² du` by `atan`);
//! * along `s` on face `b`, the result is analytic between singular points where the shadow
//!   conic is tangent to the `s`-lines (square-root behaviour; the plane through `p` and the line
//!   tangent to the ball: a quadratic in `s`, well conditioned) or crosses the edges `t = ±l/2`
//!   (kinks; quadratic in `s`);
//! * over face `a`, `p ↦ I(p)` is analytic except on the curves where the shadow of the ball on
//!   face `b` changes topology: its boundary touching an edge line of `b` (the plane through `p`
//!   and the edge line tangent to the ball; `I ~ δ^{3/2}` one-sidedly) or passing through a
//!   corner of `b` (the segment from `p` to the corner tangent to the ball; `I ~ δ²`). Both are
//!   quadratic polynomials in `p`, i.e. conics on face `a` (sampled at six points); along each
//!   `t_a`-line their real roots are the singular points;
//! * the outermost `s_a` integral has singular points where those conics are tangent to the
//!   `t_a`-lines or cross the face edges.
//!
//! At every level the 1-D integral is split at its singular points and each piece integrated by
//! the cosine-mapped Gauss rule (exponentially convergent for `|x − x₀|^{k/2}` end behaviour),
//! graded geometrically towards an end when another singular point lies just outside it
//! ([`super::quadrature::GaussLegendre::integrate_graded`]); this matters where two events
//! nearly coincide (e.g. the shadow's extreme point sitting on a face edge), which otherwise
//! costs ~1e-12. The pair's mirror symmetries halve (adjacent) or quarter (opposite) face `a`.
//! Gauss–Legendre nodes are computed by Newton iteration ([`super::quadrature`]).
//!
//! Rounding guard: for `p` within ~1e-9 of the shared edge the expanded quadratic `Q` is
//! dominated by rounding next to `p`, where the kernel is huge; each blocked chord is therefore
//! re-checked at its midpoint directly from the vector `q − p` (ball in front of `p`, line within
//! `R`, `|q − p| ≥ |c − p| − R`). Without it the adjacent factor wobbled at 1e-12.
//!
//! # Accuracy
//! Error estimates are convergence based: the computation is repeated with the Gauss order
//! raised by 8 (from 16, until two successive results agree to 1e-14) and the last difference
//! is reported; the value is that of the higher order, so the estimate is conservative.
//! Checks (tests/reference_cube.rs): `R = 0` reproduces C-14/C-11; all 30 ordered face pairs
//! (each with its own parameterisation and event set) agree with their class; the sum rule
//! `4F_adj + F_opp + F_face→sphere = 1` holds to ≤ 7e-16 for `R/(l/2)` from 0.083 to 0.93 —
//! this checks the *total* blocked part against the exact `F_face→sphere = (4πR²/6)/l²` (every
//! ray that hits the sphere would otherwise have hit exactly one other face); the *split*
//! between adjacent and opposite faces is checked against the Monte Carlo estimator
//! ([`super::monte_carlo`], 10⁹ rays, agreement within its standard error).
//! Closer to touching (`R → l/2`) more Gauss orders are needed: `R = 2.999, l = 6` at a fixed
//! order 12 left a sum residual of 2e-7 that the order-difference estimate underestimated.
//!
//! # Reference numbers, l = 6 (release, `cube_face_factors`; error estimates ≤ 3e-16 unless noted)
//!
//! | R    | F_adj              | F_opp              | F_face→sphere      | time (release) |
//! |------|--------------------|--------------------|--------------------|----------------|
//! | 0.25 | 0.1999938867070458 | 0.1963883505634954 | 0.0036361026083215 | 2.1 s |
//! | 0.5  | 0.1996465146972331 | 0.1868695307777817 | 0.0145444104332861 | 1.4 s |
//! | 1    | 0.1968931066995277 | 0.1542499314687451 | 0.0581776417331443 (π/54) | 1.7 s |
//! | 1.5  | 0.1894948729250264 | 0.1111208144003199 | 0.1308996938995747 | 2.6 s |
//! | 2    | 0.1752262403088012 | 0.0663844718322183 | 0.2327105669325772 | 7.4 s (F_adj ± 2.4e-15) |
//! | 2.5  | 0.1519211482675258 | 0.0287051460977447 | 0.3636102608321520 | 19 s |
//! | 2.8  | 0.1327215998627418 | 0.0130008893611809 | 0.4561127111878514 | 46 s (F_adj ± 5.9e-15) |
//!
//! The last digit of F_opp varies by 1 ulp between orders (R = 1: ...451/...452). Monte Carlo for
//! R = 1 (10⁹ rays from face 1, seed 2024, `mc_cube_factors`, 96 s release on 2 cores):
//! F_adj = 0.1968967 ± 3.2e-6 (+1.1σ), F_opp = 0.1542440 ± 1.1e-5 (−0.5σ),
//! F_face→sphere = 0.0581692 ± 7.4e-6 (−1.1σ; exact π/54).
//! The paper's Table 3 (1.5400e-1 opposite; 2.0341e-1 / 2.0018e-1 adjacent) is therefore off by
//! 0.2% (opposite) and 1.7–3.3% (adjacent); its face-1 sums 1.0258 / 1.0128 should be 1.

use super::closed_form::{cube_face_to_centred_sphere, parallel_rectangles, perpendicular_rectangles};
use super::quadrature::{quadratic_roots, GaussLegendre};
use super::vector::{axpy, cross, dot, norm2, sub, V3};
use std::f64::consts::PI;

/// Geometry of one face: `q(s, t) = centre + s·e1 + t·e2`, `s, t ∈ [−l/2, l/2]`, `normal` the
/// unit inward normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceFrame {
    /// Face centre.
    pub centre: V3,
    /// Unit inward normal.
    pub normal: V3,
    /// First unit tangent.
    pub e1: V3,
    /// Second unit tangent (`e1 × e2 = normal` is not required).
    pub e2: V3,
}

/// The face `face` (1..=6, numbering in the module documentation) of the cube of side `side`
/// centred at the origin; `None` for an invalid index.
pub fn face_frame(side: f64, face: usize) -> Option<FaceFrame> {
    let h = 0.5 * side;
    let (axis, sign) = face_axis(face)?;
    let mut centre = [0.0; 3];
    let mut normal = [0.0; 3];
    let (i1, i2) = match axis {
        0 => (1, 2),
        1 => (2, 0),
        _ => (0, 1),
    };
    let mut e1 = [0.0; 3];
    let mut e2 = [0.0; 3];
    for (k, (c, n)) in centre.iter_mut().zip(normal.iter_mut()).enumerate() {
        if k == axis {
            *c = sign * h;
            *n = -sign;
        }
    }
    for (k, (a, b)) in e1.iter_mut().zip(e2.iter_mut()).enumerate() {
        if k == i1 {
            *a = 1.0;
        }
        if k == i2 {
            *b = 1.0;
        }
    }
    Some(FaceFrame { centre, normal, e1, e2 })
}

/// `(axis, sign)` of a face: its plane is `x_axis = sign·l/2`.
fn face_axis(face: usize) -> Option<(usize, f64)> {
    match face {
        1 => Some((2, 1.0)),
        6 => Some((2, -1.0)),
        2 => Some((1, -1.0)),
        3 => Some((1, 1.0)),
        4 => Some((0, -1.0)),
        5 => Some((0, 1.0)),
        _ => None,
    }
}

/// A form factor with its (convergence-based) error estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceFactor {
    /// The form factor.
    pub value: f64,
    /// Estimated absolute error.
    pub error: f64,
}

/// Reference form factors of the cube-and-sphere scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubeReference {
    /// Cube side `l`.
    pub side: f64,
    /// Sphere radius `R`.
    pub radius: f64,
    /// Face → adjacent face (faces 1 → 2), occluded by the sphere.
    pub f_adjacent: f64,
    /// Estimated absolute error of `f_adjacent`.
    pub f_adjacent_error: f64,
    /// Face → opposite face (faces 1 → 6), occluded by the sphere.
    pub f_opposite: f64,
    /// Estimated absolute error of `f_opposite`.
    pub f_opposite_error: f64,
    /// Face → sphere, exact: `(4πR²/6)/l²`.
    pub f_face_to_sphere: f64,
    /// `4·F_adj + F_opp + F_face→sphere − 1` (should vanish).
    pub sum_rule_residual: f64,
}

/// First Gauss order of the escalation in [`cube_face_factors`] / [`face_pair_factor`].
pub const DEFAULT_ORDER: usize = 16;
/// Highest Gauss order the escalation goes to.
pub const MAX_ORDER: usize = 64;
/// The escalation stops when two successive orders (8 apart) agree to this (absolute).
pub const TARGET_AGREEMENT: f64 = 1e-14;

/// The adjacent (faces 1 → 2) and opposite (1 → 6) face factors of the cube of side `side`
/// with a centred sphere of radius `radius` (`0 ≤ R < l/2`), with convergence-based error
/// estimates, the exact face → sphere factor and the sum-rule residual. The Gauss order is
/// raised from [`DEFAULT_ORDER`] in steps of 8 until two successive results agree to
/// [`TARGET_AGREEMENT`] (or [`MAX_ORDER`]); the error estimate is the last difference (a
/// conservative bound: the reported value is the higher-order one of an exponentially
/// converging sequence). Invalid input (`side ≤ 0`, `R < 0`, `R ≥ l/2`, non-finite): all
/// value fields NaN.
///
/// Runtime (l = 6, R = 1): about 1.5 s release, 3–5 s debug. Validated for `R ≤ 0.93·l/2`
/// (tests/reference_cube.rs); closer to touching the faces the rule needs higher orders.
pub fn cube_face_factors(side: f64, radius: f64) -> CubeReference {
    assemble(side, radius, face_pair_factor(side, radius, 1, 2), face_pair_factor(side, radius, 1, 6))
}

/// [`cube_face_factors`] with a fixed inner Gauss order (≥ 4): the value is computed at
/// `order + 8` and the error estimate is the difference from `order`. Lower orders are faster
/// and less accurate.
pub fn cube_face_factors_with_order(side: f64, radius: f64, order: usize) -> CubeReference {
    assemble(
        side,
        radius,
        face_pair_factor_with_order(side, radius, 1, 2, order),
        face_pair_factor_with_order(side, radius, 1, 6, order),
    )
}

fn assemble(side: f64, radius: f64, adj: Option<FaceFactor>, opp: Option<FaceFactor>) -> CubeReference {
    let nan = FaceFactor { value: f64::NAN, error: f64::NAN };
    let adj = adj.unwrap_or(nan);
    let opp = opp.unwrap_or(nan);
    let fs = if valid(side, radius) { cube_face_to_centred_sphere(side, radius) } else { f64::NAN };
    CubeReference {
        side,
        radius,
        f_adjacent: adj.value,
        f_adjacent_error: adj.error,
        f_opposite: opp.value,
        f_opposite_error: opp.error,
        f_face_to_sphere: fs,
        sum_rule_residual: 4.0 * adj.value + opp.value + fs - 1.0,
    }
}

fn valid(side: f64, radius: f64) -> bool {
    side.is_finite() && radius.is_finite() && side > 0.0 && radius >= 0.0 && radius < 0.5 * side
}

/// Form factor from face `face_a` to face `face_b` (numbering in the module documentation) of
/// the cube of side `side` with a centred sphere of radius `radius` as occluder, with the
/// order escalation of [`cube_face_factors`]. Same face: 0. `None` for invalid faces or
/// geometry (see [`cube_face_factors`]).
pub fn face_pair_factor(side: f64, radius: f64, face_a: usize, face_b: usize) -> Option<FaceFactor> {
    let (fa, fb, unoccluded) = match pair_setup(side, radius, face_a, face_b)? {
        Setup::Done(f) => return Some(f),
        Setup::Pair(fa, fb, u) => (fa, fb, u),
    };
    let mut order = DEFAULT_ORDER;
    let mut prev = blocked_part(side, radius, fa, fb, order);
    loop {
        let next = blocked_part(side, radius, fa, fb, order + 8);
        let diff = (next - prev).abs();
        order += 8;
        if diff <= TARGET_AGREEMENT || order >= MAX_ORDER {
            return Some(FaceFactor { value: unoccluded - next, error: diff });
        }
        prev = next;
    }
}

/// [`face_pair_factor`] with a fixed inner Gauss order (value at `order + 8`, error estimate
/// the difference from `order`).
pub fn face_pair_factor_with_order(
    side: f64,
    radius: f64,
    face_a: usize,
    face_b: usize,
    order: usize,
) -> Option<FaceFactor> {
    let (fa, fb, unoccluded) = match pair_setup(side, radius, face_a, face_b)? {
        Setup::Done(f) => return Some(f),
        Setup::Pair(fa, fb, u) => (fa, fb, u),
    };
    let order = order.max(4);
    let coarse = blocked_part(side, radius, fa, fb, order);
    let fine = blocked_part(side, radius, fa, fb, order + 8);
    Some(FaceFactor { value: unoccluded - fine, error: (fine - coarse).abs() })
}

enum Setup {
    Done(FaceFactor),
    Pair(FaceFrame, FaceFrame, f64),
}

/// Validates the input; trivial cases (same face, no sphere) are answered directly.
fn pair_setup(side: f64, radius: f64, face_a: usize, face_b: usize) -> Option<Setup> {
    if !valid(side, radius) {
        return None;
    }
    let fa = face_frame(side, face_a)?;
    let fb = face_frame(side, face_b)?;
    if face_a == face_b {
        return Some(Setup::Done(FaceFactor { value: 0.0, error: 0.0 }));
    }
    let opposite = dot(fa.normal, fb.normal) < -0.5;
    // C-11 (opposite) or C-14 (adjacent) for l × l squares
    let unoccluded =
        if opposite { parallel_rectangles(side, side, side) } else { perpendicular_rectangles(side, side, side) };
    if radius == 0.0 {
        return Some(Setup::Done(FaceFactor { value: unoccluded, error: 0.0 }));
    }
    Some(Setup::Pair(fa, fb, unoccluded))
}

/// A quadratic polynomial `css s² + cst s t + ctt t² + cs s + ct t + c0` on a face.
#[derive(Debug, Clone, Copy)]
struct Conic {
    css: f64,
    cst: f64,
    ctt: f64,
    cs: f64,
    ct: f64,
    c0: f64,
}

impl Conic {
    /// Recovers the coefficients of an exactly quadratic `f(s, t)` from six values.
    fn sample<F: Fn(f64, f64) -> f64>(h: f64, f: F) -> Self {
        let f00 = f(0.0, 0.0);
        let fp0 = f(h, 0.0);
        let fm0 = f(-h, 0.0);
        let f0p = f(0.0, h);
        let f0m = f(0.0, -h);
        let fpp = f(h, h);
        let css = (0.5 * (fp0 + fm0) - f00) / (h * h);
        let cs = 0.5 * (fp0 - fm0) / h;
        let ctt = (0.5 * (f0p + f0m) - f00) / (h * h);
        let ct = 0.5 * (f0p - f0m) / h;
        let cst = (fpp - f00 - css * h * h - ctt * h * h - cs * h - ct * h) / (h * h);
        Self { css, cst, ctt, cs, ct, c0: f00 }
    }

    /// Roots in `t` at fixed `s`.
    fn roots_t(&self, s: f64) -> (usize, [f64; 2]) {
        quadratic_roots(self.ctt, self.cst * s + self.ct, (self.css * s + self.cs) * s + self.c0)
    }

    /// `s` where the conic is tangent to a `t`-line (zero discriminant in `t`).
    fn tangent_s(&self) -> (usize, [f64; 2]) {
        // (cst s + ct)² − 4 ctt (css s² + cs s + c0)
        let a = self.cst * self.cst - 4.0 * self.ctt * self.css;
        let b = 2.0 * self.cst * self.ct - 4.0 * self.ctt * self.cs;
        let c = self.ct * self.ct - 4.0 * self.ctt * self.c0;
        quadratic_roots(a, b, c)
    }

    /// `s` where the conic crosses the line `t = t_fixed`.
    fn crossing_s(&self, t_fixed: f64) -> (usize, [f64; 2]) {
        quadratic_roots(self.css, self.cst * t_fixed + self.cs, (self.ctt * t_fixed + self.ct) * t_fixed + self.c0)
    }
}

/// Appends the real roots.
fn push_roots(out: &mut Vec<f64>, roots: (usize, [f64; 2])) {
    let (n, r) = roots;
    out.extend(r.iter().take(n).copied().filter(|x| x.is_finite()));
}

/// The outer face's parameterisation for the pair: `e1` parallel to face b (the common edge
/// for adjacent faces), so that `s_a → −s_a` is a symmetry of the pair; for opposite faces
/// `t_a → −t_a` is one too.
fn outer_frame(fa: &FaceFrame, fb: &FaceFrame) -> (FaceFrame, bool) {
    let cn = cross(fa.normal, fb.normal);
    if norm2(cn) > 0.5 {
        let e1 = cn; // unit: the normals are orthogonal unit vectors
        (FaceFrame { e1, e2: cross(fa.normal, e1), ..*fa }, false)
    } else {
        (*fa, true)
    }
}

/// The inner face's parameterisation: `e2` parallel to face a, so that the blocked set on
/// each `t`-line of face b is one bounded interval (the quadratic's leading coefficient is
/// `R² − dist(c, line through p along e2)² < 0`, that line lying in face a's plane).
fn inner_frame(fa: &FaceFrame, fb: &FaceFrame) -> FaceFrame {
    let cn = cross(fa.normal, fb.normal);
    if norm2(cn) > 0.5 {
        FaceFrame { e1: cross(fb.normal, cn), e2: cn, ..*fb }
    } else {
        *fb
    }
}

/// The blocked part of the point-to-face factor, (1/π) ∫_b cos θ_p cos θ_q / r² · [the segment
/// p–q meets the ball] dq, for a point `p` of face `face_a` and the whole face `face_b`, by the
/// same closed-form chords and singular points in s as [`cube_face_factors`] (Gauss order
/// `order` on each piece). For checking a kernel's inner integral point by point; `None` for
/// invalid input or the same face.
#[must_use]
pub fn blocked_point_factor(side: f64, radius: f64, face_a: usize, face_b: usize, p: V3, order: usize) -> Option<f64> {
    let Setup::Pair(fa, fb, _) = pair_setup(side, radius, face_a, face_b)? else { return Some(0.0) };
    let (fa, _) = outer_frame(&fa, &fb);
    let fb = inner_frame(&fa, &fb);
    let rule = GaussLegendre::new(order);
    let inner = Inner { fb, na: fa.normal, h: 0.5 * side, r2: radius * radius, c: [0.0; 3], rule: &rule };
    Some(inner.blocked_integral(p))
}

/// The blocked part `B_ab` with Gauss order `order` at every level.
fn blocked_part(side: f64, radius: f64, fa: FaceFrame, fb: FaceFrame, order: usize) -> f64 {
    let h = 0.5 * side;
    let c: V3 = [0.0; 3];
    let (fa, t_symmetric) = outer_frame(&fa, &fb);
    let fb = inner_frame(&fa, &fb);
    let rule = GaussLegendre::new(order);
    let inner = Inner { fb, na: fa.normal, h, r2: radius * radius, c, rule: &rule };
    let events = face_events(&fa, &fb, h, radius, c);
    // s_a singular points: event conics tangent to t_a-lines or crossing the edges t_a = ±h
    let mut sa_sing = Vec::new();
    for ev in &events {
        push_roots(&mut sa_sing, ev.tangent_s());
        push_roots(&mut sa_sing, ev.crossing_s(h));
        push_roots(&mut sa_sing, ev.crossing_s(-h));
        if t_symmetric {
            push_roots(&mut sa_sing, ev.crossing_s(0.0));
        }
    }
    let t_lo = if t_symmetric { 0.0 } else { -h };
    let g = |sa: f64| line_integral(&fa, &events, &inner, sa, t_lo);
    // s_a ∈ [0, h] by the symmetry s_a → −s_a
    let value = rule.integrate_graded(0.0, h, &mut sa_sing, g);
    let weight = if t_symmetric { 4.0 } else { 2.0 };
    weight * value / (side * side)
}

/// The event conics on face a (module documentation): the shadow boundary tangent to an edge
/// line of face b, and the shadow boundary through a corner of face b.
fn face_events(fa: &FaceFrame, fb: &FaceFrame, h: f64, radius: f64, c: V3) -> Vec<Conic> {
    let pa = |s: f64, t: f64| axpy(axpy(fa.centre, s, fa.e1), t, fa.e2);
    let mut events: Vec<Conic> = Vec::with_capacity(8);
    let r2 = radius * radius;
    for (sgn, dir, off) in [(1.0, fb.e2, fb.e1), (-1.0, fb.e2, fb.e1), (1.0, fb.e1, fb.e2), (-1.0, fb.e1, fb.e2)] {
        let e0 = axpy(fb.centre, sgn * h, off);
        events.push(Conic::sample(h, |s, t| {
            let n = cross(dir, sub(pa(s, t), e0));
            let d = dot(n, sub(c, e0));
            d * d - r2 * norm2(n)
        }));
    }
    for (si, ti) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        let corner = axpy(axpy(fb.centre, si * h, fb.e1), ti * h, fb.e2);
        events.push(Conic::sample(h, |s, t| {
            let p = pa(s, t);
            let w = sub(c, p);
            let v = sub(corner, p);
            norm2(cross(w, v)) - r2 * norm2(v)
        }));
    }
    events
}

/// `G(s_a) = ∫_{t_lo}^{h} I(p(s_a, t_a)) dt_a`, singular where the line crosses event conics.
fn line_integral(fa: &FaceFrame, events: &[Conic], inner: &Inner<'_>, sa: f64, t_lo: f64) -> f64 {
    let mut sing = Vec::with_capacity(16);
    for ev in events {
        push_roots(&mut sing, ev.roots_t(sa));
    }
    let base = axpy(fa.centre, sa, fa.e1);
    inner.rule.integrate_graded(t_lo, inner.h, &mut sing, |ta| inner.blocked_integral(axpy(base, ta, fa.e2)))
}

/// The inner integral over face b, for one outer point.
struct Inner<'a> {
    fb: FaceFrame,
    na: V3,
    h: f64,
    r2: f64,
    c: V3,
    rule: &'a GaussLegendre,
}

impl Inner<'_> {
    /// `I(p) = ∫_b cos θ_a cos θ_b/(π r²) [blocked] dq`.
    fn blocked_integral(&self, p: V3) -> f64 {
        let fb = &self.fb;
        let h = self.h;
        let w = sub(self.c, p);
        let kappa = norm2(w) - self.r2;
        if kappa <= 0.0 {
            return 0.0;
        }
        let dist_to_ball = norm2(w).sqrt() - self.r2.sqrt();
        let v0 = sub(fb.centre, p);
        let beta1 = dot(w, fb.e1);
        let beta2 = dot(w, fb.e2);
        let alpha = dot(w, v0);
        let gamma1 = dot(v0, fb.e1);
        let gamma2 = dot(v0, fb.e2);
        // Q(s, t) = qa t² + (b0 + b1 s) t + (c0 + c1 s + c2 s²) ≥ 0 ⇔ blocked
        let qa = beta2 * beta2 - kappa; // < 0 by the choice of e2
        if qa >= 0.0 {
            return 0.0;
        }
        let b1 = 2.0 * beta2 * beta1;
        let b0 = 2.0 * beta2 * alpha - 2.0 * kappa * gamma2;
        let c2 = beta1 * beta1 - kappa;
        let c1 = 2.0 * alpha * beta1 - 2.0 * kappa * gamma1;
        let c0 = alpha * alpha - kappa * norm2(v0);
        // singular points in s: the shadow conic tangent to an s-line (the plane through p and
        // the line tangent to the ball; well conditioned form) and crossing t = ±h.
        let n0 = cross(fb.e2, v0);
        let n1 = cross(fb.e2, fb.e1);
        let (n0w, n1w) = (dot(n0, w), dot(n1, w));
        let mut sing = Vec::with_capacity(6);
        push_roots(
            &mut sing,
            quadratic_roots(
                n1w * n1w - self.r2 * norm2(n1),
                2.0 * n0w * n1w - 2.0 * self.r2 * dot(n0, n1),
                n0w * n0w - self.r2 * norm2(n0),
            ),
        );
        for te in [h, -h] {
            push_roots(&mut sing, quadratic_roots(c2, c1 + te * b1, c0 + te * b0 + qa * te * te));
        }
        let nb = fb.normal;
        let na = self.na;
        let chord = |s: f64| -> f64 {
            let bs = b0 + b1 * s;
            let cs = (c2 * s + c1) * s + c0;
            let (n, roots) = quadratic_roots(qa, bs, cs);
            if n < 2 {
                return 0.0;
            }
            let [r0, r1] = roots;
            let lo = r0.max(-h);
            let hi = r1.min(h);
            if hi <= lo {
                return 0.0;
            }
            // Guard against rounding artefacts: the bounded interval Q ≥ 0 lies in one nappe of
            // the double cone; keep it only if, at its midpoint (evaluated directly from the
            // vector q − p, not from the expanded coefficients), the line passes within R of
            // the centre, the ball is in front of p, and q lies beyond the ball's near surface
            // (|q − p| ≥ |c − p| − R, necessary for a blocked segment). For p within ~1e-9 of
            // the shared edge the expanded quadratic is dominated by rounding near p, where the
            // kernel is huge; exactly, no blocked q lies there.
            let vm = axpy(axpy(v0, s, fb.e1), 0.5 * (lo + hi), fb.e2);
            let wv = dot(w, vm);
            let vm2 = norm2(vm);
            if wv <= 0.0 || wv * wv - kappa * vm2 < 0.0 || vm2.sqrt() < dist_to_ball {
                return 0.0;
            }
            // closed form of ∫ (n_a·v)(−n_b·v)/(π |v|⁴) dt, v = v_s + t e2, n_b·e2 = 0:
            // |v|² = u² + ρ² with u = t + τ; n_a·v = P₀ + a₁u.
            let vs = axpy(v0, s, fb.e1);
            let tau = dot(vs, fb.e2);
            let rho2 = norm2(cross(vs, fb.e2));
            let rho = rho2.sqrt();
            let cb = -dot(nb, vs);
            let a1 = dot(na, fb.e2);
            let p0 = dot(na, vs) - a1 * tau;
            let prim = |u: f64| {
                let d = u * u + rho2;
                p0 * (u / (2.0 * rho2 * d) + (u / rho).atan() / (2.0 * rho2 * rho)) - a1 / (2.0 * d)
            };
            cb * (prim(hi + tau) - prim(lo + tau)) / PI
        };
        self.rule.integrate_graded(-h, h, &mut sing, chord)
    }
}
