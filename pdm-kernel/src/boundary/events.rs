//! Outer-level events: the curves on the outer patch where J(p) changes its structure, placed
//! into the outer rule: conics on a flat outer patch ([`Events`]), circles on a sphere's cell
//! against a parallelogram ([`TrigonometricEvents`]).
//!
//! With the inner integral exact for every p, what remains non-smooth is J itself: across an
//! occluder's shadow it has a kink where the shadow boundary passes through a corner of b
//! (the visible area changes like δ² on one side only) and a 3/2-power point where the
//! boundary becomes tangent to an edge of b (a cap of the shadow, δ^{3/2}); across b's plane
//! it has a kink (b starts facing p). On a parallelogram a and a parallelogram b these curves
//! are conics in a's parameters: each occluder gives, per corner and edge of b, quadrics in p
//! ([`Occluder::event_quadrics`]), and b's plane a line. A curved b that no occluder cuts gives
//! its own ([`Surface::event_quadrics`]: on a sphere's cell the outline seen from p passing a
//! corner, or touching a parallel or a meridian); a curve that is an event on part of its
//! quadric only carries a guard, and the ends of that part are breaks in s (there the
//! edge-tangency curve ends on a corner curve, a point singularity of J). The outer integral
//! is then taken as
//! nested line integrals, as the inner one is ("Visibility boundaries" in the references):
//!
//! * along s, breaks where a conic crosses one of a's t-edges (a quadratic in s) or becomes
//!   tangent to the t-lines (its discriminant in t, a quadratic in s);
//! * along each t-line, breaks at the conics' roots (quadratics in t);
//!
//! every piece integrated by the Gauss rule graded towards its break ends
//! (`graded_sum`, `graded`): the map x² turns δ^{3/2} and the square-root ends of a
//! tangency into smooth functions, so the outer rule converges with the order instead of
//! algebraically. Two conics crossing inside a is not a break: there J is the sum of the two
//! curves' singular parts to leading order. Curves are not trimmed to the part where they
//! are real events (the half of a corner's cone facing away from the occluder, a tangent
//! plane whose touching point misses the edge segment): a break where J is smooth costs
//! rule points, not accuracy.

use super::*;
use crate::visibility::Quadric;

/// Most event curves on one outer patch: the occluder gives two per corner of the part of b
/// that a sees (a sphere: [`QUADRICS_PER_CORNER`]; at most five corners where b straddles a's
/// plane, `front_part`) and b's plane one.
pub(crate) const MAX_EVENT_CURVES: usize = 5 * QUADRICS_PER_CORNER + 1;

/// Most quadrics one corner may give: one occluder's (a sphere's tangent cone from the corner
/// and its two tangent planes through the edge; a tube's two tangent planes through the corner
/// parallel to its axis). Where more come, several occluders cast
/// shadows on b, and where two shadows meet (one inside the other's edge, or touching) J
/// changes structure on curves that are no occluder's quadrics: the events are declined and
/// the outer rule samples across them as before.
const QUADRICS_PER_CORNER: usize = 2;

/// Most breaks along one outer line (two per curve) or in s (six per curve, four more at the
/// ends of a guarded curve), ends included.
const MAX_T_BREAKS: usize = 2 * MAX_EVENT_CURVES + 2;
const MAX_S_BREAKS: usize = 10 * MAX_EVENT_CURVES + 2;

/// A conic in the outer patch's parameters, Q(t, s) = tt·t² + ts·t·s + ss·s² + t·t + s·s + c,
/// as `[tt, ts, ss, t, s, c]`.
type Conic<T> = [T; 6];

/// A line in the outer patch's parameters, L(t, s) = a·t + b·s + c, as `[a, b, c]`.
type Line2<T> = [T; 3];

/// One event curve: Q = 0 where the guard (L₀·L₁ ≥ 0, if any) holds; `grade`: the outer rule's
/// pieces are graded towards its breaks (square-root and 3/2-power points, a sphere's
/// tangencies, and the contact of touching patches), or not (a kink between analytic sides,
/// which needs only the break).
#[derive(Clone, Copy)]
struct Curve<T> {
    conic: Conic<T>,
    guard: Option<[Line2<T>; 2]>,
    grade: bool,
}

impl<T: Real> Curve<T> {
    /// Whether (t, s) lies where the curve is an event, with a margin of rounding (a point
    /// let in wrongly costs a break, one kept out wrongly its accuracy).
    fn holds(&self, t: T, s: T) -> bool {
        self.guard.is_none_or(|lines| {
            let [l0, l1] = lines.map(|[a, b, c]| {
                let margin = T::from_f64(64.0) * T::EPSILON * ((a * t).abs() + (b * s).abs() + c.abs());
                (a * t + b * s + c, margin)
            });
            l0.0 * l1.0 >= T::ZERO || l0.0.abs() <= l0.1 || l1.0.abs() <= l1.1
        })
    }
}

impl<T: Real> Curve<T> {
    /// For a line (no quadratic terms): whether the part of it where the guard holds meets the
    /// rectangle `r`. The line is clipped to `r` (Liang–Barsky); the guard's two lines are
    /// linear along it, so their product is non-negative somewhere on the segment iff it is at
    /// an end or both change sign on it.
    fn line_meets(&self, r: ParamRect<T>) -> bool {
        let [_, _, _, a, b, c] = self.conic;
        let n2 = a * a + b * b;
        if !(n2 > T::ZERO) {
            return false;
        }
        // p(λ) = p₀ + λ·d on the line, d = (−b, a).
        let (t0, s0) = (-c * a / n2, -c * b / n2);
        let (dt, ds) = (-b, a);
        let (mut lo, mut hi) = (-T::MAX, T::MAX);
        for (p, d, min, max) in [(t0, dt, r.t0, r.t1), (s0, ds, r.s0, r.s1)] {
            if d == T::ZERO {
                if p < min || p > max {
                    return false;
                }
            } else {
                let (x, y) = ((min - p) / d, (max - p) / d);
                lo = lo.max(x.min(y));
                hi = hi.min(x.max(y));
            }
        }
        if lo > hi {
            return false;
        }
        let Some([g0, g1]) = self.guard else { return true };
        let value = |[ga, gb, gc]: Line2<T>, l: T| ga * (t0 + l * dt) + gb * (s0 + l * ds) + gc;
        let (u0, u1, w0, w1) = (value(g0, lo), value(g0, hi), value(g1, lo), value(g1, hi));
        u0 * w0 >= T::ZERO || u1 * w1 >= T::ZERO || (u0 * u1 <= T::ZERO && w0 * w1 <= T::ZERO)
    }
}

/// The event curves of one (outer, inner) pair: at most `N` curves, at most `SB` breaks in s
/// and `TB` along one outer line (ends included).
pub(super) struct Events<T, const N: usize, const SB: usize, const TB: usize> {
    curves: [Curve<T>; N],
    n: usize,
    /// Whether the curves pushed are graded ([`Curve`]).
    grade: bool,
    /// The outer patch's parameter rectangle, where the rule may reach past a cell towards a
    /// break just outside it ([`graded_sum`]); `None`: anywhere on the patch's surface. Past
    /// the patch J need not continue J inside it (an occluder standing on the patch's edge
    /// hides everything from beyond it).
    limit: Option<ParamRect<T>>,
    /// The sides of `limit` (t₀, t₁, s₀, s₁) towards which the rule is graded: an occluder
    /// touches the outer patch there, and J is singular along that side.
    graded_sides: [bool; 4],
    /// An occluder touches the outer patch inside it (a box standing on it): J is singular
    /// along the contact's outline.
    touched_inside: bool,
    /// Curves where two solids' shadows meet were added (`PolygonEvents::push_meeting`).
    meeting: bool,
}

/// The events of an occluder that gives its quadrics (a sphere), or of a curved inner patch.
pub(super) type QuadricEvents<T> = Events<T, MAX_EVENT_CURVES, MAX_S_BREAKS, MAX_T_BREAKS>;

impl<T: Real, const N: usize, const SB: usize, const TB: usize> Events<T, N, SB, TB> {
    /// No curves yet.
    pub(super) fn empty(grade: bool, limit: Option<ParamRect<T>>) -> Self {
        Self {
            curves: [Curve { conic: [T::ZERO; 6], guard: None, grade }; N],
            n: 0,
            grade,
            limit,
            graded_sides: [false; 4],
            touched_inside: false,
            meeting: false,
        }
    }

    /// Records that curves where two solids' shadows meet were added.
    pub(super) fn set_meeting(&mut self) {
        self.meeting = true;
    }

    /// Whether an occluder touches the outer patch inside it and two solids' shadows meet: the
    /// curves are many and the rule still converges only algebraically along the contact.
    pub(super) fn touched_and_meeting(&self) -> bool {
        self.touched_inside && self.meeting
    }

    /// Records that an occluder touches the outer patch inside it ([`Self::touches_side`]).
    pub(super) fn touch_inside(&mut self) {
        self.touched_inside = true;
    }

    /// Grades the rule towards side `k` (t₀, t₁, s₀, s₁) of the limit rectangle.
    pub(super) fn grade_side(&mut self, k: usize) {
        if let Some(side) = self.graded_sides.get_mut(k) {
            *side = true;
        }
    }

    /// Whether an occluder touches a side of the outer patch ([`Self::grade_side`]) or its
    /// inside ([`Self::touch_inside`]): J is then singular there, and the rule converges only
    /// algebraically with the order.
    pub(super) fn touches_side(&self) -> bool {
        self.touched_inside || self.graded_sides.iter().any(|&g| g)
    }

    /// Whether the rule is graded at `x` on the side `k` of the limit rectangle.
    fn side_graded(&self, k: usize, x: T) -> bool {
        let at = |l: ParamRect<T>| match k {
            0 => l.t0,
            1 => l.t1,
            2 => l.s0,
            _ => l.s1,
        };
        self.graded_sides.get(k).copied().unwrap_or(false) && self.limit.is_some_and(|l| at(l) == x)
    }

    /// The events of outer a (affine map `outer`: p = o + t·e_t + s·e_s, over the parameter
    /// rectangle `outer_rect`) against inner b (affine
    /// map `inner` over the parameter rectangle `rect`) across `occluders`, at the corners and
    /// edges of the part of b in front of a's plane; `None` if an occluder cannot give its
    /// quadrics, more than one occluder gives them ([`QUADRICS_PER_CORNER`]), or a coefficient
    /// is not finite.
    pub(super) fn new<O: Occluder<T> + ?Sized>(
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        outer_rect: ParamRect<T>,
        inner: (Vec3<T>, Vec3<T>, Vec3<T>),
        rect: ParamRect<T>,
        occluders: &O,
    ) -> Option<Self> {
        let (o, et, es) = outer;
        let (bo, bt, bs) = inner;
        let mut events = Self::empty(true, None);
        let mut overflow = false;
        // The part of b that a's points see (`front_part`: b clipped by a's plane where it
        // straddles it) has the corners and edges whose quadrics are the events.
        let (front, n_front) = front_part(outer, bo, &map_corners(inner, rect));
        let (a_corners, b_corners) = (map_corners(outer, outer_rect), front.get(..n_front).unwrap_or_default());
        overflow |= !events.push_edge_quadrics(outer, &a_corners, b_corners, occluders)?;
        // b's plane: b faces p only on its front side.
        let nb = bt.cross(bs);
        overflow |= !events.push([T::ZERO, T::ZERO, T::ZERO, nb.dot(et), nb.dot(es), nb.dot(o - bo)], None);
        if overflow {
            return None;
        }
        Some(events)
    }

    /// The events of outer a (affine map `outer`) against a curved inner patch (`surface` over
    /// `rect`, inside the ball `bounds`) that no occluder cuts: the curves the surface gives
    /// ([`Surface::event_quadrics`]). `None` if it gives none, they overflow the buffer, a
    /// coefficient is not finite, or `bounds` reaches a's plane (a's facing test would then
    /// cut b along a curve of its own).
    pub(super) fn curved<S: Surface<T> + ?Sized>(
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        surface: &S,
        rect: ParamRect<T>,
        bounds: &Ball<T>,
    ) -> Option<Self> {
        let (o, et, es) = outer;
        let na = et.cross(es);
        let height = na.dot(bounds.center - o) / na.norm();
        if !(height.abs() > bounds.radius * (T::ONE + T::GEOMETRY_TOLERANCE)) {
            return None;
        }
        let mut events = Self::empty(true, None);
        let mut overflow = false;
        let supported = surface.event_quadrics(rect, &mut |q| overflow |= !events.push_quadric(outer, q));
        (supported && !overflow && events.n > 0).then_some(events)
    }

    /// Keeps the quadrics `occluders` give for each edge of b's visible part (`corners` in
    /// order around it, at most five: [`Occluder::event_quadrics`]); `None` where an occluder
    /// gives none or more than [`QUADRICS_PER_CORNER`] per edge (more than one sphere), else
    /// whether all fitted.
    pub(super) fn push_edge_quadrics<O: Occluder<T> + ?Sized>(
        &mut self,
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        outer_corners: &[Vec3<T>],
        corners: &[Vec3<T>],
        occluders: &O,
    ) -> Option<bool> {
        let mut fitted = true;
        let count = corners.len();
        for k in 0..count {
            let (Some(&c), Some(&next)) = (corners.get(k), corners.get((k + 1) % count)) else { return None };
            let mut given = 0usize;
            let supported = occluders.event_quadrics(c, next - c, [outer_corners, corners], &mut |q| {
                given += 1;
                fitted &= self.push_quadric(outer, q);
            });
            if !supported || given > QUADRICS_PER_CORNER {
                return None;
            }
        }
        Some(fitted)
    }

    /// Keeps the quadric `q` restricted to a (affine map `outer`): with p = o + t·e_t + s·e_s and
    /// v₀ = o − origin, F = (v₀ + t·e_t + s·e_s)ᵀ M (…) + g·(…) + c, a conic in (t, s), and each
    /// guard g·v a line.
    pub(super) fn push_quadric(&mut self, outer: (Vec3<T>, Vec3<T>, Vec3<T>), q: Quadric<T>) -> bool {
        let (o, et, es) = outer;
        let v0 = o - q.origin;
        let guard = q.guard.map(|gs| gs.map(|g| scaled([g.dot(et), g.dot(es), g.dot(v0)])));
        self.push(conic_of(outer, &q), guard)
    }

    /// Keeps the quadric `q` (its own guard ignored) restricted to a as [`Self::push_quadric`],
    /// an event only where the line `guard` (in a's parameters) is non-negative; `false` on
    /// overflow.
    pub(super) fn push_quadric_within(
        &mut self,
        outer: (Vec3<T>, Vec3<T>, Vec3<T>),
        q: Quadric<T>,
        guard: Line2<T>,
    ) -> bool {
        self.push(conic_of(outer, &q), Some([scaled(guard), [T::ZERO, T::ZERO, T::ONE]]))
    }

    /// Keeps the line `line` (L(t, s) = a·t + b·s + c) as an event only between the guard
    /// lines `from` and `to` (each positive on the side of the part kept); `false` on overflow.
    pub(super) fn push_segment(&mut self, [a, b, c]: Line2<T>, from: Line2<T>, to: Line2<T>) -> bool {
        self.push([T::ZERO, T::ZERO, T::ZERO, a, b, c], Some([scaled(from), scaled(to)]))
    }

    /// Keeps a conic scaled to its largest coefficient 1 (the roots do not change, and the
    /// polynomials formed from it stay in range: a sphere's coefficients grow like the 6th
    /// power of the scene's size, their discriminants like the 12th); `false` for a
    /// non-finite conic or guard, or a full buffer.
    fn push(&mut self, conic: Conic<T>, guard: Option<[Line2<T>; 2]>) -> bool {
        let finite = |c: &[T]| c.iter().all(|c| c.is_finite());
        if !finite(&conic) || guard.is_some_and(|[l0, l1]| !finite(&l0) || !finite(&l1)) {
            return false;
        }
        match self.curves.get_mut(self.n) {
            Some(slot) => {
                *slot = Curve { conic: scaled(conic), guard, grade: self.grade };
                self.n += 1;
                true
            }
            None => false,
        }
    }

    fn used(&self) -> &[Curve<T>] {
        self.curves.get(..self.n).unwrap_or_default()
    }

    /// Leaves out the curves from `from` on if the last one is a line whose guarded part misses
    /// the rectangle `r` ([`Curve::line_meets`]).
    pub(super) fn keep_if_meets(&mut self, from: usize, r: ParamRect<T>) {
        if self.n > from && self.curves.get(self.n - 1).is_some_and(|curve| !curve.line_meets(r)) {
            self.n = from;
        }
    }

    /// Whether the curves pushed from now on are graded ([`Curve`]).
    pub(super) fn set_grade(&mut self, grade: bool) {
        self.grade = grade;
    }

    /// How many curves are kept.
    pub(super) fn len(&self) -> usize {
        self.n
    }

    /// ∫∫ f(t, s) dt ds over `r` with the events placed into the rule (module docs); `f` is the
    /// outer integrand at a's parameters (J times a's area element).
    pub(super) fn integrate(
        &self,
        r: ParamRect<T>,
        rule: &GaussRule<T>,
        f: &mut dyn FnMut(T, T) -> Result<T, PdmError>,
    ) -> Result<T, PdmError> {
        let mut breaks = [(T::ZERO, false); SB];
        let mut n = 0usize;
        let (grade_s0, grade_s1) = (self.side_graded(2, r.s0), self.side_graded(3, r.s1));
        let mut place = |x: T, grade: bool| place_near(x, grade, r.s0, r.s1, &mut breaks, &mut n);
        place(r.s0, grade_s0);
        for curve in self.used() {
            let mut add = |x: T| place(x, curve.grade);
            let [tt, ts, ss, t1, s1, c] = curve.conic;
            // A t-edge crossed: Q(t_edge, s) = 0.
            for te in [r.t0, r.t1] {
                roots_near_double(ss, ts * te + s1, (tt * te + t1) * te + c, &mut |s| {
                    if curve.holds(te, s) {
                        add(s);
                    }
                });
            }
            // Tangent to the t-lines: the discriminant in t of Q(·, s), at t = −(ts·s + t)/(2·tt).
            let four = T::TWO * T::TWO;
            roots_near_double(
                ts * ts - four * tt * ss,
                T::TWO * ts * t1 - four * tt * s1,
                t1 * t1 - four * tt * c,
                &mut |s| {
                    if tt == T::ZERO || curve.holds(-(ts * s + t1) / (T::TWO * tt), s) {
                        add(s);
                    }
                },
            );
            // The ends of a guarded curve: Q = 0 on a guard line.
            for [a, b, lc] in curve.guard.into_iter().flatten() {
                if a == T::ZERO && b == T::ZERO {
                    // A guard plane parallel to a: the guard is constant on it.
                } else if a.abs() >= b.abs() {
                    // t = −(b·s + lc)/a = k·s + m.
                    let (k, m) = (-b / a, -lc / a);
                    roots_near_double(
                        tt * k * k + ts * k + ss,
                        T::TWO * tt * k * m + ts * m + t1 * k + s1,
                        tt * m * m + t1 * m + c,
                        &mut |s| {
                            let t = k * s + m;
                            if t >= r.t0 && t <= r.t1 {
                                add(s);
                            }
                        },
                    );
                } else {
                    // s = −(a·t + lc)/b = k·t + m.
                    let (k, m) = (-a / b, -lc / b);
                    roots_near_double(
                        tt + ts * k + ss * k * k,
                        ts * m + T::TWO * ss * k * m + t1 + s1 * k,
                        ss * m * m + s1 * m + c,
                        &mut |t| {
                            if t >= r.t0 && t <= r.t1 {
                                add(k * t + m);
                            }
                        },
                    );
                }
            }
        }
        place(r.s1, grade_s1);
        let (lo, hi) = self.limit.map_or((-T::MAX, T::MAX), |l| (l.s0, l.s1));
        graded_sum(breaks.get_mut(..n).unwrap_or_default(), r.s0, r.s1, (lo, hi), rule, &mut |s| {
            self.line(r, s, rule, f)
        })
    }

    /// ∫ f(t, s) dt over [r.t0, r.t1] at one s, with breaks at the conics' roots.
    fn line(
        &self,
        r: ParamRect<T>,
        s: T,
        rule: &GaussRule<T>,
        f: &mut dyn FnMut(T, T) -> Result<T, PdmError>,
    ) -> Result<T, PdmError> {
        let mut breaks = [(T::ZERO, false); TB];
        let mut n = 0usize;
        let (grade_t0, grade_t1) = (self.side_graded(0, r.t0), self.side_graded(1, r.t1));
        let mut place = |x: T, grade: bool| place_near(x, grade, r.t0, r.t1, &mut breaks, &mut n);
        place(r.t0, grade_t0);
        for curve in self.used() {
            let [tt, ts, ss, t1, s1, c] = curve.conic;
            roots_near_double(tt, ts * s + t1, (ss * s + s1) * s + c, &mut |t| {
                if curve.holds(t, s) {
                    place(t, curve.grade);
                }
            });
        }
        place(r.t1, grade_t1);
        let (lo, hi) = self.limit.map_or((-T::MAX, T::MAX), |l| (l.t0, l.t1));
        graded_sum(breaks.get_mut(..n).unwrap_or_default(), r.t0, r.t1, (lo, hi), rule, &mut |t| f(t, s))
    }
}

/// The quadric `q` restricted to a (affine map `outer`): with p = o + t·e_t + s·e_s and
/// v₀ = o − origin, F = (v₀ + t·e_t + s·e_s)ᵀ M (…) + g·(…) + c, a conic in (t, s).
fn conic_of<T: Real>((o, et, es): (Vec3<T>, Vec3<T>, Vec3<T>), q: &Quadric<T>) -> Conic<T> {
    let v0 = o - q.origin;
    [
        q.bilinear(et, et),
        T::TWO * q.bilinear(et, es),
        q.bilinear(es, es),
        T::TWO * q.bilinear(v0, et) + q.g.dot(et),
        T::TWO * q.bilinear(v0, es) + q.g.dot(es),
        q.bilinear(v0, v0) + q.g.dot(v0) + q.c,
    ]
}

/// The coefficients scaled to the largest 1 (unchanged if all are zero).
fn scaled<const N: usize, T: Real>(c: [T; N]) -> [T; N] {
    let largest = c.iter().fold(T::ZERO, |m, c| m.max(c.abs()));
    if largest > T::ZERO {
        c.map(|c| c / largest)
    } else {
        c
    }
}

/// Keeps a break x in [lo, hi] (ends included) while `breaks` has room; each curve adds at most
/// six breaks in s and two along a line, which the buffers hold.
fn place<T: Real>(x: T, lo: T, hi: T, breaks: &mut [T], n: &mut usize) {
    if x.is_finite() && x >= lo && x <= hi {
        if let Some(slot) = breaks.get_mut(*n) {
            *slot = x;
            *n += 1;
        }
    }
}

/// Keeps a break x, and whether the rule is graded towards it, in [lo, hi] widened by its width
/// on both sides (a break just outside the interval limits the rule on it as much as one
/// inside, [`graded_sum`]) while `breaks` has room.
fn place_near<T: Real>(x: T, grade: bool, lo: T, hi: T, breaks: &mut [(T, bool)], n: &mut usize) {
    let width = hi - lo;
    if x.is_finite() && x >= lo - width && x <= hi + width {
        if let Some(slot) = breaks.get_mut(*n) {
            *slot = (x, grade);
            *n += 1;
        }
    }
}

/// The real roots of a·x² + b·x + c, and the double root −b/(2a) also where rounding has made
/// the discriminant slightly negative (a conic that is a pair of lines has a discriminant that
/// is a perfect square: its double root is where the lines cross).
fn roots_near_double<T: Real>(a: T, b: T, c: T, out: &mut dyn FnMut(T)) {
    let four = T::TWO * T::TWO;
    let disc = b * b - four * a * c;
    let scale = b * b + (four * a * c).abs();
    if disc < T::ZERO && -disc <= T::from_f64(64.0) * T::EPSILON * scale && a != T::ZERO {
        out(-b / (T::TWO * a));
        return;
    }
    crate::visibility::polynomial_roots(a, b, c, out);
}

/// How near a break outside [lo, hi] must be, in the end piece's widths divided by this, for
/// [`graded_sum`] to take the end piece through it. Nearer than that, a singularity just
/// outside slows the end piece's rule more than the longer, graded piece does; farther, the
/// longer piece loses more than it gains (J varies over it, and grading at both ends thins
/// the middle). 8 is the best of 1, 2, 4, 8 and 16 on the paper's scene, face 1 to face 6
/// cell by cell at orders 8, 12 and 16 (FUZZING.md, "Events just outside a cell").
const NEAR_OUTSIDE: f64 = 8.0;

/// ∫ g over [lo, hi] by the rule on the pieces between the `breaks` (which hold lo and hi, and
/// may hold breaks outside [lo, hi]; the rule reaches past lo or hi only within
/// [lowest, highest]), each graded ([`graded`]) at every end where a graded
/// curve's break lies ([`Curve`]).
///
/// A break just outside, at distance δ from an end, is a singularity at distance δ from the
/// end piece: its rule converges at a rate that falls with δ / width (a tangency 1e-4 of the
/// width past the end: 1e-7 at order 16), and on a grid of cells every event that crosses
/// one cell passes just outside its neighbours, or on its edge, rounded to either side. Where
/// δ is at most the end piece's width / [`NEAR_OUTSIDE`], the end piece [x, hi] is taken as
/// [x, hi + δ] minus [hi, hi + δ], each graded towards the break if its curve is: one piece
/// more, and both
/// converge with the order. Unlike the inner rule's pieces
/// (`for_each_piece`), a piece next to a much narrower one is not cut geometrically towards
/// it: the outer curves of one pair often nearly meet (every corner and edge of b gives one,
/// and they pass close to each other), and those cuts multiplied the outer points several-fold
/// (up to 60× on a whole face) for little accuracy (BENCHMARKS.md, "Outer events").
fn graded_sum<T: Real>(
    breaks: &mut [(T, bool)],
    lo: T,
    hi: T,
    (lowest, highest): (T, T),
    rule: &GaussRule<T>,
    g: &mut dyn FnMut(T) -> Result<T, PdmError>,
) -> Result<T, PdmError> {
    sort_by_position(breaks);
    // One entry per position, graded if any break there is.
    let mut m = 0usize;
    for k in 0..breaks.len() {
        let Some(&(x, grade)) = breaks.get(k) else { break };
        match m.checked_sub(1).and_then(|last| breaks.get_mut(last)) {
            Some(last) if last.0 == x => last.1 |= grade,
            _ => {
                if let Some(slot) = breaks.get_mut(m) {
                    *slot = (x, grade);
                }
                m += 1;
            }
        }
    }
    let breaks = breaks.get(..m).unwrap_or_default();
    let at_lo = breaks.iter().any(|&(x, grade)| x == lo && grade);
    let at_hi = breaks.iter().any(|&(x, grade)| x == hi && grade);
    let inside = |x: &&(T, bool)| x.0 >= lo && x.0 <= hi;
    let near = T::from_f64(NEAR_OUTSIDE);
    let first_end = breaks.iter().filter(inside).find(|x| x.0 > lo).map_or(hi, |x| x.0);
    let last_start = breaks.iter().filter(inside).rev().find(|x| x.0 < hi).map_or(lo, |x| x.0);
    let below = breaks
        .iter()
        .rev()
        .find(|x| x.0 < lo)
        .copied()
        .filter(|x| !at_lo && (lo - x.0) * near <= first_end - lo && x.0 >= lowest);
    let above = breaks
        .iter()
        .find(|x| x.0 > hi)
        .copied()
        .filter(|x| !at_hi && (x.0 - hi) * near <= hi - last_start && x.0 <= highest);
    let mut total = T::ZERO;
    for w in breaks.windows(2) {
        let &[a, b] = w else { continue };
        if !(b.0 > a.0) || a.0 < lo || b.0 > hi {
            continue;
        }
        let a = if a.0 == lo { below.unwrap_or(a) } else { a };
        let b = if b.0 == hi { above.unwrap_or(b) } else { b };
        total += piece(a.0, b.0, a.1, b.1, rule, g)?;
    }
    if let Some((x, grade)) = below {
        total -= piece(x, lo, grade, false, rule, g)?;
    }
    if let Some((x, grade)) = above {
        total -= piece(hi, x, false, grade, rule, g)?;
    }
    Ok(total)
}

/// ∫ g by the rule on the pieces between the `breaks` (sorted here), each piece graded
/// ([`graded`]) at the ends where `grade` holds.
fn sum_pieces<T: Real>(
    breaks: &mut [T],
    rule: &GaussRule<T>,
    grade: &dyn Fn(T) -> bool,
    g: &mut dyn FnMut(T) -> Result<T, PdmError>,
) -> Result<T, PdmError> {
    sort(breaks);
    let mut total = T::ZERO;
    for w in breaks.windows(2) {
        let &[a, b] = w else { continue };
        if b > a {
            total += piece(a, b, grade(a), grade(b), rule, g)?;
        }
    }
    Ok(total)
}

/// ∫ g over [a, b] by the rule, graded ([`graded`]) at the ends flagged.
fn piece<T: Real>(
    a: T,
    b: T,
    grade_a: bool,
    grade_b: bool,
    rule: &GaussRule<T>,
    g: &mut dyn FnMut(T) -> Result<T, PdmError>,
) -> Result<T, PdmError> {
    let width = b - a;
    let mut total = T::ZERO;
    for (x, wx) in rule.points() {
        let (u, du) = graded((x + T::ONE) * T::HALF, grade_a, grade_b);
        total += wx * T::HALF * du * width * g(a + width * u)?;
    }
    Ok(total)
}

/// The least value over the rectangle `r` of f(t, s) = a + b·cos t + c(s)·sin t (`curve` in
/// [`Surface::facing_across_s`]'s form, a and b constant in s): at a corner, on an edge where
/// its first-degree trigonometric restriction turns, or inside where both derivatives vanish
/// (c'(s) = 0 and tan t = c(s)/b); T::MAX's negative, −∞ in effect, where a or b varies.
pub(super) fn trigonometric_least<T: Real>([a, b, c]: [[T; 3]; 3], r: ParamRect<T>) -> T {
    let constant = |k: [T; 3]| k[1] == T::ZERO && k[2] == T::ZERO;
    if !constant(a) || !constant(b) {
        return -T::MAX;
    }
    let f = |t: T, s: T| {
        let (st, ct) = t.sin_cos();
        let (ss, cs) = s.sin_cos();
        a[0] + b[0] * ct + (c[0] + c[1] * cs + c[2] * ss) * st
    };
    // Turning points of k₀ + k_c·cos x + k_s·sin x: x = atan2(k_s, k_c) + jπ.
    let turns = |kc: T, ks: T, lo: T, hi: T, out: &mut dyn FnMut(T)| {
        let base = ks.atan2(kc);
        for j in -4i32..=4 {
            let x = base + T::PI * T::from_f64(f64::from(j));
            if x > lo && x < hi {
                out(x);
            }
        }
    };
    let mut least = T::MAX;
    for (t, s) in [(r.t0, r.s0), (r.t1, r.s0), (r.t0, r.s1), (r.t1, r.s1)] {
        least = least.min(f(t, s));
    }
    for te in [r.t0, r.t1] {
        // Along the edge: a + b·cos tₑ + sin tₑ·(k₀ + k_c·cos s + k_s·sin s).
        let st = te.sin();
        turns(c[1] * st, c[2] * st, r.s0, r.s1, &mut |s| least = least.min(f(te, s)));
    }
    let along_t = |s: T, least: &mut T| {
        let (ss, cs) = s.sin_cos();
        let cs_value = c[0] + c[1] * cs + c[2] * ss;
        turns(b[0], cs_value, r.t0, r.t1, &mut |t| *least = least.min(f(t, s)));
    };
    for se in [r.s0, r.s1] {
        along_t(se, &mut least);
    }
    turns(c[1], c[2], r.s0, r.s1, &mut |s| along_t(s, &mut least));
    least
}

/// Whether L₁² − L₂ = 0 may hold somewhere in `r`: the ranges of L₁ and L₂ over it
/// ([`trigonometric_least`] of each and of its negative) allow L₁² = L₂.
fn may_meet<T: Real>([l1, l2]: [Trigonometric<T>; 2], r: ParamRect<T>) -> bool {
    let negative = |l: Trigonometric<T>| l.map(|k| k.map(|x| -x));
    let (lo1, hi1) = (trigonometric_least(l1, r), -trigonometric_least(negative(l1), r));
    let (lo2, hi2) = (trigonometric_least(l2, r), -trigonometric_least(negative(l2), r));
    let least_square = if lo1 <= T::ZERO && hi1 >= T::ZERO { T::ZERO } else { (lo1 * lo1).min(hi1 * hi1) };
    let most_square = (lo1 * lo1).max(hi1 * hi1);
    // A margin of rounding on both comparisons: a curve kept wrongly costs breaks only.
    let slack = T::from_f64(64.0) * T::EPSILON * (most_square + hi2.abs().max(lo2.abs()));
    !(least_square > hi2 + slack || most_square + slack < lo2)
}

/// Samples along s at which [`meridian_tangencies`] counts a curve's crossings of the t-lines.
const TANGENCY_SAMPLES: usize = 48;

/// The s in (r.s0, r.s1) where the curve L₁² − L₂ = 0 on a sphere touches a t-line at a t in
/// [r.t0, r.t1]: there the part of a line on one side grows like √(s − s*), a singular end the
/// outer rule is graded towards. Each t-line extended to its whole great circle (t over a full
/// turn) crosses the curve an even number of times, which changes only where the curve touches
/// it; the count is taken at [`TANGENCY_SAMPLES`] values of s and each change bisected to
/// rounding, its t the middle of the two crossings nearest each other just past it. (A curve
/// that touches two t-lines between neighbouring samples, a loop narrower than the spacing,
/// gives no break: its outer rule converges more slowly there.)
fn meridian_tangencies<T: Real>(
    [l1, l2]: [Trigonometric<T>; 2],
    r: ParamRect<T>,
    out: &mut dyn FnMut(T),
) -> Result<(), PdmError> {
    const MOST: usize = 64;
    let crossings = |s: T, roots: &mut [T; MOST]| -> Result<usize, PdmError> {
        let (ss, cs) = s.sin_cos();
        let at = |k: [T; 3]| k[0] + k[1] * cs + k[2] * ss;
        let along = |[a, b, c]: Trigonometric<T>| [at(a), at(b), at(c)];
        let mut n = 0usize;
        let complete = squared_trigonometric_roots(along(l1), along(l2), -T::PI, T::PI, &mut |t| {
            if let Some(slot) = roots.get_mut(n) {
                *slot = t;
                n += 1;
            }
        });
        if !complete {
            return Err(PdmError::NonFinite);
        }
        Ok(n)
    };
    let mut roots = [T::ZERO; MOST];
    let width = r.s1 - r.s0;
    let step = width / T::from_usize(TANGENCY_SAMPLES);
    let mut prev = (r.s0, crossings(r.s0, &mut roots)?);
    for k in 1..=TANGENCY_SAMPLES {
        let s = if k == TANGENCY_SAMPLES { r.s1 } else { r.s0 + step * T::from_usize(k) };
        let here = (s, crossings(s, &mut roots)?);
        if here.1 != prev.1 {
            let (mut lo, mut hi) = (prev, here);
            let resolution = width * T::from_f64(1e-12);
            for _ in 0..(T::MANTISSA_DIGITS + 4) {
                let mid = (lo.0 + hi.0) * T::HALF;
                if !(mid > lo.0 && mid < hi.0) || hi.0 - lo.0 <= resolution {
                    break;
                }
                let count = crossings(mid, &mut roots)?;
                if count == lo.1 {
                    lo = (mid, count);
                } else {
                    hi = (mid, count);
                }
            }
            // The side with more crossings: the two nearest each other (around the circle)
            // are the pair that meets at the tangency.
            let richer = if hi.1 > lo.1 { hi.0 } else { lo.0 };
            let n = crossings(richer, &mut roots)?;
            let found = roots.get_mut(..n).unwrap_or_default();
            sort(found);
            let mut best: Option<(T, T)> = None;
            for (i, &x) in found.iter().enumerate() {
                let (next, wrap) = match found.get(i + 1) {
                    Some(&y) => (y, T::ZERO),
                    None => (found.first().copied().unwrap_or(x), T::TWO * T::PI),
                };
                let gap = next + wrap - x;
                if n > 1 && best.is_none_or(|(g, _)| gap < g) {
                    best = Some((gap, x + gap * T::HALF));
                }
            }
            let margin = (r.t1 - r.t0) * T::from_f64(1e-6);
            let on_cell = |t: T| {
                let turn = T::TWO * T::PI;
                [t - turn, t, t + turn].iter().any(|&t| t >= r.t0 - margin && t <= r.t1 + margin)
            };
            if best.is_none_or(|(_, t)| on_cell(t)) {
                out((lo.0 + hi.0) * T::HALF);
            }
        }
        prev = here;
    }
    Ok(())
}

/// A curve on a curved outer patch: f(t, s) = a(s) + b(s)·cos t + c(s)·sin t = 0, each of a, b,
/// c as `[k₀, k_c, k_s]` for k₀ + k_c·cos s + k_s·sin s ([`Surface::facing_across_s`]'s form),
/// with a and b constant in s (c(s) = ±√(a² − b²) then gives the tangencies in closed form).
type Trigonometric<T> = [[T; 3]; 3];

/// Most event curves of a curved outer patch against a parallelogram: its four corners and its
/// plane.
const MAX_TRIGONOMETRIC_CURVES: usize = 5;

/// Most breaks in s: per curve two on each t-edge and two per tangency sign; ends included.
const MAX_TRIGONOMETRIC_S_BREAKS: usize = 8 * MAX_TRIGONOMETRIC_CURVES + 2;

/// The outer events of a curved outer patch whose facing tests are trigonometric in both
/// parameters ([`Surface::facing_across_s`]: a sphere's cells) against a parallelogram b that
/// no occluder cuts. J(p) is the point-to-polygon form over b clipped by p's tangent plane
/// (exact), so it changes structure only where that plane passes through a corner of b (the
/// clipped part grows like δ², its weight like δ: a δ³ kink) and where p crosses b's plane
/// (b starts facing p). Both are zero sets of facing tests of the outer surface: towards the
/// corner (n_p·(c − p) = 0) and from the plane (n_b·(p − o_b) = 0); on a sphere they are
/// circles, a + b·cos φ + c(θ)·sin φ = 0 in its parameters, found in closed form like the
/// conics above: along s where one crosses a t-edge or is tangent to the t-lines, along each
/// t-line at its roots, every piece graded towards its breaks.
///
/// Generic over its capacity: `N` curves, `S` breaks in s and `TB` along a t-line (ends
/// included); [`SphereCellEvents`] for these, `concentric::ConcentricEvents` for a pair across
/// a concentric sphere occluder, whose curves are also plane sections of the outer sphere.
pub(super) struct TrigonometricEvents<T, const N: usize, const S: usize, const TB: usize, const Q: usize = 0> {
    curves: [Trigonometric<T>; N],
    /// Whether the rule along a t-line is graded towards the curve's roots (a 3/2-power point
    /// of J where a boundary touches an edge of b), per curve.
    graded: [bool; N],
    n: usize,
    /// Curves L₁² − L₂ = 0 with L₁, L₂ in the form above: a quadric's section of the outer
    /// sphere whose equation on the sphere reduces to that (a cone tangent to a sphere
    /// occluder from a corner of b: [`TrigonometricEvents::push_quadratic`]); the rule along
    /// the t-lines is graded towards their roots.
    quadratics: [[Trigonometric<T>; 2]; Q],
    nq: usize,
}

/// The events of a sphere's cell against a parallelogram ([`TrigonometricEvents::new`]).
pub(super) type SphereCellEvents<T> =
    TrigonometricEvents<T, MAX_TRIGONOMETRIC_CURVES, MAX_TRIGONOMETRIC_S_BREAKS, MAX_T_BREAKS>;

impl<T: Real> SphereCellEvents<T> {
    /// The events of the curved outer surface against the parallelogram with affine map
    /// `inner` over `rect`; `None` if the surface does not give its facing tests in this form,
    /// a coefficient is not finite, or a curve's a or b varies with s.
    pub(super) fn new<S: Surface<T> + ?Sized>(
        outer: &S,
        inner: (Vec3<T>, Vec3<T>, Vec3<T>),
        rect: ParamRect<T>,
    ) -> Option<Self> {
        let (bo, bt, bs) = inner;
        let nb = bt.cross(bs);
        let unit = nb.scale(T::ONE / nb.norm());
        let mut events = Self::empty();
        let corner = |t: T, s: T| bo + bt.scale(t) + bs.scale(s);
        let corners =
            [corner(rect.t0, rect.s0), corner(rect.t1, rect.s0), corner(rect.t1, rect.s1), corner(rect.t0, rect.s1)];
        for c in corners {
            // The second test: the tangent plane at q passing through c.
            let [_, towards] = outer.facing_across_s(c, unit)?;
            events.push(towards, false)?;
        }
        let [plane, _] = outer.facing_across_s(bo, unit)?;
        events.push(plane, false)?;
        Some(events)
    }
}

impl<T: Real, const N: usize, const S: usize, const TB: usize, const Q: usize> TrigonometricEvents<T, N, S, TB, Q> {
    /// No curves yet.
    pub(super) fn empty() -> Self {
        Self {
            curves: [[[T::ZERO; 3]; 3]; N],
            graded: [false; N],
            n: 0,
            quadratics: [[[[T::ZERO; 3]; 3]; 2]; Q],
            nq: 0,
        }
    }

    /// Keeps the curve L₁² − L₂ = 0 (each in [`Surface::facing_across_s`]'s form), scaled so
    /// that its larger side's largest coefficient is 1; `None` where it is not finite, a or b
    /// of either varies with s, or the buffer is full.
    pub(super) fn push_quadratic(&mut self, l1: Trigonometric<T>, l2: Trigonometric<T>) -> Option<()> {
        let constant = |k: [T; 3]| k[1] == T::ZERO && k[2] == T::ZERO;
        for [a, b, _] in [l1, l2] {
            if !constant(a) || !constant(b) {
                return None;
            }
        }
        let all = l1.iter().chain(l2.iter()).flatten();
        if !all.clone().all(|x| x.is_finite()) {
            return None;
        }
        let largest = |l: &Trigonometric<T>| l.iter().flatten().fold(T::ZERO, |m, x| m.max(x.abs()));
        let (k1, k2) = (largest(&l1), largest(&l2));
        let scale = (k1 * k1).max(k2);
        if !(scale > T::ZERO) || !scale.is_finite() {
            return None;
        }
        let root = scale.sqrt();
        *self.quadratics.get_mut(self.nq)? = [l1.map(|k| k.map(|x| x / root)), l2.map(|k| k.map(|x| x / scale))];
        self.nq += 1;
        Some(())
    }

    fn used_quadratics(&self) -> &[[Trigonometric<T>; 2]] {
        self.quadratics.get(..self.nq).unwrap_or_default()
    }

    /// Keeps a curve scaled to its largest coefficient 1, with the rule along the t-lines
    /// graded towards its roots where `graded`; `None` where it is not finite, its a or b
    /// varies with s, or the buffer is full.
    pub(super) fn push(&mut self, curve: Trigonometric<T>, graded: bool) -> Option<()> {
        let [a, b, _] = curve;
        let constant = |k: [T; 3]| k[1] == T::ZERO && k[2] == T::ZERO;
        if !curve.iter().flatten().all(|x| x.is_finite()) || !constant(a) || !constant(b) {
            return None;
        }
        let largest = curve.iter().flatten().fold(T::ZERO, |m, x| m.max(x.abs()));
        let scaled = if largest > T::ZERO { curve.map(|k| k.map(|x| x / largest)) } else { curve };
        *self.curves.get_mut(self.n)? = scaled;
        *self.graded.get_mut(self.n)? = graded;
        self.n += 1;
        Some(())
    }

    fn used(&self) -> &[Trigonometric<T>] {
        self.curves.get(..self.n).unwrap_or_default()
    }

    /// ∫∫ f(t, s) dt ds over `r` with the events placed into the rule (as
    /// [`Events::integrate`]).
    pub(super) fn integrate(
        &self,
        r: ParamRect<T>,
        rule: &GaussRule<T>,
        f: &mut dyn FnMut(T, T) -> Result<T, PdmError>,
    ) -> Result<T, PdmError> {
        let mut breaks = [T::ZERO; S];
        let mut n = 0usize;
        let mut tangencies = [T::ZERO; S];
        let mut nt = 0usize;
        let mut add = |x: T| place(x, r.s0, r.s1, &mut breaks, &mut n);
        add(r.s0);
        for &[a, b, c] in self.used() {
            // A t-edge crossed: f(t_edge, s) = 0, first-degree trigonometric in s.
            for te in [r.t0, r.t1] {
                let (st, ct) = te.sin_cos();
                let g = [a[0] + b[0] * ct + c[0] * st, c[1] * st, c[2] * st];
                trigonometric_roots(g, r.s0, r.s1, &mut add);
            }
            // Tangent to the t-lines: a² = b² + c(s)², c(s) = ±√(a² − b²). The visible part of
            // a line grows like √(s − s*) there, a singular end point: graded.
            let k2 = a[0] * a[0] - b[0] * b[0];
            if k2 >= T::ZERO {
                let k = k2.sqrt();
                for sign in [T::ONE, -T::ONE] {
                    trigonometric_roots([c[0] - sign * k, c[1], c[2]], r.s0, r.s1, &mut |s| {
                        add(s);
                        place(s, r.s0, r.s1, &mut tangencies, &mut nt);
                    });
                }
            }
        }
        let mut active = [false; Q];
        for (&[l1, l2], on) in self.used_quadratics().iter().zip(active.iter_mut()) {
            *on = may_meet([l1, l2], r);
            if !*on {
                continue;
            }
            for te in [r.t0, r.t1] {
                let (st, ct) = te.sin_cos();
                let at_edge = |[a, b, c]: Trigonometric<T>| [a[0] + b[0] * ct + c[0] * st, c[1] * st, c[2] * st];
                if !squared_trigonometric_roots(at_edge(l1), at_edge(l2), r.s0, r.s1, &mut |s| add(s)) {
                    return Err(PdmError::NonFinite);
                }
            }
            meridian_tangencies([l1, l2], r, &mut |s| {
                add(s);
                place(s, r.s0, r.s1, &mut tangencies, &mut nt);
            })?;
        }
        add(r.s1);
        let tangencies = tangencies.get(..nt).unwrap_or_default();
        let grade = |x: T| tangencies.contains(&x);
        sum_pieces(breaks.get_mut(..n).unwrap_or_default(), rule, &grade, &mut |s| self.line(r, s, &active, rule, f))
    }

    /// ∫ f(t, s) dt over [r.t0, r.t1] at one s, with breaks at the curves' roots.
    fn line(
        &self,
        r: ParamRect<T>,
        s: T,
        active: &[bool; Q],
        rule: &GaussRule<T>,
        f: &mut dyn FnMut(T, T) -> Result<T, PdmError>,
    ) -> Result<T, PdmError> {
        let mut breaks = [T::ZERO; TB];
        let mut n = 0usize;
        let mut graded = [T::ZERO; TB];
        let mut ng = 0usize;
        place(r.t0, r.t0, r.t1, &mut breaks, &mut n);
        let (ss, cs) = s.sin_cos();
        let at = |k: [T; 3]| k[0] + k[1] * cs + k[2] * ss;
        let flags = self.graded.get(..self.n).unwrap_or_default();
        for (&[a, b, c], &grade) in self.used().iter().zip(flags) {
            trigonometric_roots([at(a), at(b), at(c)], r.t0, r.t1, &mut |t| {
                place(t, r.t0, r.t1, &mut breaks, &mut n);
                if grade {
                    place(t, r.t0, r.t1, &mut graded, &mut ng);
                }
            });
        }
        for (&[l1, l2], _) in self.used_quadratics().iter().zip(active).filter(|(_, &on)| on) {
            let along = |[a, b, c]: Trigonometric<T>| [at(a), at(b), at(c)];
            if !squared_trigonometric_roots(along(l1), along(l2), r.t0, r.t1, &mut |t| {
                place(t, r.t0, r.t1, &mut breaks, &mut n);
                place(t, r.t0, r.t1, &mut graded, &mut ng);
            }) {
                return Err(PdmError::NonFinite);
            }
        }
        place(r.t1, r.t0, r.t1, &mut breaks, &mut n);
        // Kinks with smooth sides (δ³ at a sphere cell's corner circle, linear at a plane's)
        // take the plain rule on each piece; the rule is graded towards the roots of the curves
        // pushed as graded (a concentric pair's: δ^{3/2} where a boundary touches an edge, and
        // the corner curves that touch those at the edges' ends).
        let graded = graded.get(..ng).unwrap_or_default();
        sum_pieces(breaks.get_mut(..n).unwrap_or_default(), rule, &|x| graded.contains(&x), &mut |t| f(t, s))
    }
}
