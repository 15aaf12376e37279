//! The inner integral J(p) over patch b from one outer point p: the visible part of b found
//! line by line (closed form on a parallelogram, bracketing elsewhere), the refinement towards
//! a close p, and Lambert's point-to-polygon form where it applies.

use super::*;

/// Tag of a candidate that is a discriminant root (two roots of one polynomial meeting), or-ed
/// into its polynomial index.
const BRANCH_POINT: usize = 1 << 16;

/// The inner patch b with everything needed to integrate over its visible part from one point.
pub(super) struct Inner<'x, T: Real, SB: Surface<T> + ?Sized, O: ?Sized> {
    pub(super) surface: &'x SB,
    pub(super) r: ParamRect<T>,
    pub(super) rule: GaussRule<T>,
    pub(super) probes: usize,
    /// b's affine map when visibility is handled in closed form.
    pub(super) affine: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    /// b's affine map where b is a parallelogram, whether or not its lines are in closed form
    /// (too many occluders' polynomials for one line's buffer): b less flat occluders' shadows.
    #[cfg(feature = "closed-form")]
    pub(super) parallelogram: Option<(Vec3<T>, Vec3<T>, Vec3<T>)>,
    /// b's t-lines have trigonometric facing tests ([`Surface::facing_along_t`]) and no
    /// occluder can cut, or only a sphere concentric with b's ([`Inner::concentric`]):
    /// visibility along them in closed form.
    #[cfg(feature = "closed-form")]
    pub(super) trigonometric: bool,
    /// The one occluder that may cut, where it is a sphere with the centre of b's sphere
    /// (`concentric.rs`): its test on b is a plane's, trigonometric like the facing tests.
    #[cfg(feature = "closed-form")]
    pub(super) concentric: Option<Concentric<T>>,
    /// b's outline when b is flat but not a parallelogram (a disk or annulus sector, a planar
    /// Bézier patch): the point-to-region form along it.
    #[cfg(feature = "closed-form")]
    pub(super) outline: Option<crate::contour::Outline<'x, T, SB>>,
    /// The rule along the outline's edges: at least order 16, whose few hundred evaluations per
    /// outer point make J(p) exact to rounding at any outer order.
    #[cfg(feature = "closed-form")]
    pub(super) line_rule: GaussRule<T>,
    /// Facets J(p) may leave out where they face away from p ([`BackFacets`]).
    #[cfg(feature = "closed-form")]
    pub(super) back_facets: BackFacets<T>,
    pub(super) use_occluders: bool,
    pub(super) occluders: &'x O,
    pub(super) count: &'x core::cell::Cell<u64>,
    /// Buffers of [`Inner::line`] in closed form.
    pub(super) scratch: core::cell::RefCell<LineScratch<T>>,
    /// The line [`Inner::line_signature`] computes into.
    pub(super) signature_line: core::cell::RefCell<Line<T>>,
}

impl<T: Real, SB: Surface<T> + ?Sized, O: Occluder<T> + ?Sized> Inner<'_, T, SB, O> {
    pub(super) fn tick(&self) {
        self.count.set(self.count.get().saturating_add(1));
    }

    /// On a flat b (closed-form mode), the facing tests from p over all of b, decided at b's
    /// corners (both are affine on b): `Some(true)` if every q of b and p face each other,
    /// `Some(false)` if none do, `None` if b straddles a facing boundary or is not flat.
    pub(super) fn facing_from(&self, p: Vec3<T>, np: Vec3<T>) -> Option<bool> {
        let (o, et, es) = self.map()?;
        let r = self.r;
        let nq = self.surface.normal(r.t0, r.s0);
        let corners = [(r.t0, r.s0), (r.t1, r.s0), (r.t0, r.s1), (r.t1, r.s1)];
        let (mut sees, mut ahead_of_p, mut ahead_of_q) = (0usize, 0usize, 0usize);
        for (t, s) in corners {
            let (ca, cb, _) = integrand::cosines(p, np, o + et.scale(t) + es.scale(s), nq);
            let (towards_q, towards_p) = (ca > T::ZERO, cb > T::ZERO);
            sees += usize::from(towards_q && towards_p);
            ahead_of_p += usize::from(towards_q);
            ahead_of_q += usize::from(towards_p);
        }
        if sees == corners.len() {
            Some(true)
        } else if ahead_of_p == 0 || ahead_of_q == 0 {
            Some(false)
        } else {
            None
        }
    }

    /// Both facing tests and the occluders for the segment p → q.
    pub(super) fn visible(&self, p: Vec3<T>, np: Vec3<T>, q: Vec3<T>, nq: Vec3<T>) -> bool {
        self.tick();
        mutually_facing(p, np, q, nq) && !(self.use_occluders && self.occluders.blocks(p, q))
    }

    /// The polynomials in t whose roots contain every visibility change on the t-line at s
    /// (closed-form mode): the two facing tests (linear) and the occluders'. `false` if the
    /// capacity is exceeded or an occluder declines.
    pub(super) fn line_polys(&self, p: Vec3<T>, np: Vec3<T>, s: T, polys: &mut Polys<T>) -> bool {
        let Some((o, et, es)) = self.affine else { return false };
        let origin = o + es.scale(s);
        let w0 = origin - p;
        let nq = self.surface.normal(self.r.t0, s);
        polys.n = 0;
        polys.push([T::ZERO, np.dot(et), np.dot(w0)]);
        polys.push([T::ZERO, nq.dot(et), nq.dot(w0)]);
        if self.use_occluders && !occluder_polynomials(self.occluders, p, origin, et, &mut |c| polys.push(c)) {
            return false;
        }
        !polys.overflow
    }

    /// The visible pieces of the t-line of b at s over r's t-range, seen from p.
    pub(super) fn line(
        &self,
        p: Vec3<T>,
        np: Vec3<T>,
        r: ParamRect<T>,
        s: T,
        line: &mut Line<T>,
    ) -> Result<(), PdmError> {
        let vis_at = |t: T| {
            let (q, nq) = self.surface.point_and_normal(t, s);
            self.visible(p, np, q, nq)
        };
        #[cfg(feature = "closed-form")]
        let closed = self.affine.is_some() || self.trigonometric;
        #[cfg(not(feature = "closed-form"))]
        let closed = self.affine.is_some();
        if closed {
            // Reused buffers (zeroing them on every line cost ≈ 6 % of the run time); a fresh
            // set if they are in use (never: lines are not computed re-entrantly).
            let mut fresh = None;
            let mut borrowed = self.scratch.try_borrow_mut();
            let scratch: &mut LineScratch<T> = match borrowed.as_deref_mut() {
                Ok(scratch) => scratch,
                Err(_) => fresh.insert(LineScratch::new()),
            };
            let LineScratch { polys, candidates } = scratch;
            if self.affine.is_some()
                && self.line_polys(p, np, s, polys)
                && closed_form_line(polys.used(), r.t0, r.t1, &vis_at, candidates, line)
            {
                return Ok(());
            }
            #[cfg(feature = "closed-form")]
            if self.trigonometric {
                if let Some((tests, n)) = self.line_tests(p, np, s) {
                    let tests = tests.get(..n).unwrap_or_default();
                    if trigonometric_line(tests, r.t0, r.t1, &vis_at, candidates, line) {
                        return Ok(());
                    }
                }
            }
        }
        // Bracket visibility changes along the line, refine each by bisection.
        line.n = 0;
        line.ids = 0;
        push(&mut line.breaks, &mut line.n, r.t0)?;
        locate_changes(&vis_at, r.t0, r.t1, self.probes, &mut line.breaks, &mut line.n)?;
        push(&mut line.breaks, &mut line.n, r.t1)?;
        let first_hi = line.breaks.get(1).copied().unwrap_or(r.t1);
        line.first_visible = vis_at((r.t0 + first_hi) * T::HALF);
        Ok(())
    }

    /// The tests along the t-line at s whose roots hold every visibility change from p
    /// ([`Surface::facing_along_t`]): both facing tests, and the concentric occluder's plane
    /// where there is one; `None` where the surface does not give them.
    #[cfg(feature = "closed-form")]
    fn line_tests(&self, p: Vec3<T>, np: Vec3<T>, s: T) -> Option<([[T; 3]; 3], usize)> {
        let [f1, f2] = self.surface.facing_along_t(s, p, np)?;
        match &self.concentric {
            None => Some(([f1, f2, [T::ZERO; 3]], 2)),
            Some(c) => {
                let (x0, n) = c.plane(p)?;
                let [f3, _] = self.surface.facing_along_t(s, x0, n)?;
                Some(([f1, f2, f3], 3))
            }
        }
    }

    /// The structure of a line: (number of breakpoints, visibility of the first piece, which
    /// polynomials make the breaks); an error counts as its own structure (it is reported
    /// again when the line is integrated).
    pub(super) fn line_signature(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, s: T) -> (usize, bool, u64) {
        let mut fresh = None;
        let mut borrowed = self.signature_line.try_borrow_mut();
        let line: &mut Line<T> = match borrowed.as_deref_mut() {
            Ok(line) => line,
            Err(_) => fresh.insert(Line::new()),
        };
        match self.line(p, np, r, s, line) {
            Ok(()) => (line.n, line.first_visible, line.ids),
            Err(_) => (usize::MAX, false, 0),
        }
    }

    /// The singular points in s of the inner integral (closed-form mode): the lines' structure
    /// changes where a root of a polynomial crosses a t-edge (a quadratic in s) or two roots of
    /// one polynomial meet (its discriminant, a quartic in s); these candidates are found
    /// exactly and kept where the structure differs on the two sides, and a discriminant root
    /// also where it does not (a branch point next to a piece; added while room is left). Other changes (two
    /// polynomials' roots crossing: a polygonal shadow's corner, two shadows meeting) are
    /// bracketed and bisected between them. Returns the nearest singular points just outside
    /// [s0, s1] (within a quarter of its width), towards which the end pieces are graded;
    /// `None` (with nothing pushed) if the lines' polynomials are not available from p.
    pub(super) fn closed_form_events(
        &self,
        p: Vec3<T>,
        np: Vec3<T>,
        r: ParamRect<T>,
        out: &mut [T; MAX_BREAKS + 2],
        n: &mut usize,
    ) -> Result<Option<Outside<T>>, PdmError> {
        let h = r.s1 - r.s0;
        // The coefficients as quadratics in x ∈ [0, 1] (s = s0 + x·h), from three lines.
        let (mut p0, mut ph, mut p1) = (Polys::new(), Polys::new(), Polys::new());
        let ok = self.line_polys(p, np, r.s0, &mut p0)
            && self.line_polys(p, np, r.s0 + h * T::HALF, &mut ph)
            && self.line_polys(p, np, r.s1, &mut p1)
            && p0.n == ph.n
            && ph.n == p1.n;
        if !ok {
            return Ok(None);
        }
        // Candidates with the polynomial they come from; an overflow makes every sub-interval
        // count as possibly crossed (see below).
        let mut candidates = [(T::ZERO, 0usize); 4 * MAX_BREAKS];
        let mut nc = 0usize;
        let mut overflow = false;
        // Candidates just outside b count too: a singular point close beyond an edge slows the
        // rule on the piece at that edge (it is graded towards it).
        let reach = T::HALF * T::HALF;
        let fit = |v0: T, vh: T, v1: T| -> [T; 3] {
            let four = T::TWO * T::TWO;
            [v0, four * vh - T::from_f64(3.0) * v0 - v1, T::TWO * (v1 + v0) - four * vh]
        };
        // Each polynomial's coefficients (a, b, c) as quadratics in x.
        let mut fits = [[[T::ZERO; 3]; 3]; MAX_POLYS];
        let polys = p0.used().iter().zip(ph.used()).zip(p1.used());
        for (id, (((&[a0, b0, k0], &[ah, bh, kh]), &[a1, b1, k1]), slot)) in polys.zip(fits.iter_mut()).enumerate() {
            let (qa, qb, qc) = (fit(a0, ah, a1), fit(b0, bh, b1), fit(k0, kh, k1));
            *slot = [qa, qb, qc];
            let mut add_tagged = |x: T, tag: usize| {
                if x > -reach && x < T::ONE + reach {
                    match candidates.get_mut(nc) {
                        Some(c) => {
                            *c = (r.s0 + h * x, id | tag);
                            nc += 1;
                        }
                        None => overflow = true,
                    }
                }
            };
            let mut add = |x: T| add_tagged(x, 0);
            // A root crossing the t-edges: P(t_edge; x) = a(x) t² + b(x) t + c(x), coefficient by
            // coefficient in x.
            for t in [r.t0, r.t1] {
                let e = |k: usize| {
                    let g = |q: &[T; 3]| q.get(k).copied().unwrap_or(T::ZERO);
                    g(&qa) * t * t + g(&qb) * t + g(&qc)
                };
                crate::visibility::polynomial_roots(e(2), e(1), e(0), &mut add);
            }
            // Two roots meeting: D(x) = b(x)² − 4 a(x) c(x), a quartic (roots in (−¼, 1¼)).
            if qa.iter().any(|&c| c != T::ZERO) {
                let bb = square(&qb);
                let ac = product(&qa, &qc);
                let four = T::TWO * T::TWO;
                let d = [
                    bb[0] - four * ac[0],
                    bb[1] - four * ac[1],
                    bb[2] - four * ac[2],
                    bb[3] - four * ac[3],
                    bb[4] - four * ac[4],
                ];
                roots_in_interval(&d, -reach, T::ONE + reach, &mut |x| add_tagged(x, BRANCH_POINT));
            }
        }
        let fits = fits.get(..p0.n).unwrap_or_default();
        let candidates = candidates.get_mut(..nc).unwrap_or_default();
        sort_by_position(candidates);
        let candidates = &*candidates;
        // How many polynomials have a root inside (t0, t1) somewhere in [from, hi]: those with
        // one at `from`, and those with a candidate inside (a root enters the line's range only
        // across a t-edge or as a double root, both candidates).
        let with_roots_inside = |from: T, hi: T| -> usize {
            let x = (from - r.s0) / h;
            let mut count = 0;
            for (id, [qa, qb, qc]) in fits.iter().enumerate() {
                let mut inside = candidates.iter().any(|&(c, i)| i & !BRANCH_POINT == id && c > from && c < hi);
                if !inside {
                    let at = |q: &[T; 3]| horner(q, x);
                    crate::visibility::polynomial_roots(at(qa), at(qb), at(qc), &mut |t| {
                        inside |= t > r.t0 && t < r.t1;
                    });
                }
                count += usize::from(inside);
            }
            count
        };
        // Keep the candidates where the line structure actually changes.
        let delta = h * T::EPSILON.sqrt();
        let mut kept_at = [T::ZERO; MAX_BREAKS + 2];
        let mut kept = 0usize;
        let mut last = r.s0 - h;
        let mut outside: Outside<T> = (None, None);
        let mut branch_points = [T::ZERO; MAX_BREAKS];
        let mut nb = 0usize;
        for &(c, tag) in candidates {
            if c - last <= delta {
                continue;
            }
            let changes = self.line_signature(p, np, r, c - delta) != self.line_signature(p, np, r, c + delta);
            if !changes && tag & BRANCH_POINT != 0 {
                // Two roots of one polynomial meeting where the structure does not change
                // (outside b's t-range, or a polynomial that decides nothing there): a root
                // that is inside on a neighbouring piece grows like √(s − c) from it, a branch
                // point just beyond that piece's end. As a break it grades that piece towards
                // it (`for_each_piece`); the piece it bounds on the other side is smooth. Kept
                // apart and added last, where room is left: the breaks that change the
                // structure come first.
                if c > r.s0 + delta && c < r.s1 - delta {
                    let repeated = branch_points.get(..nb).unwrap_or_default().iter().any(|&x| (x - c).abs() <= delta);
                    if !repeated {
                        if let Some(slot) = branch_points.get_mut(nb) {
                            *slot = c;
                            nb += 1;
                        }
                    }
                } else if c <= r.s0 + delta {
                    outside.0 = Some(outside.0.map_or(c, |o: T| o.max(c)).min(r.s0 - delta));
                } else if outside.1.is_none() {
                    outside.1 = Some(c.max(r.s1 + delta));
                }
                continue;
            }
            if changes {
                last = c;
                if c <= r.s0 + delta {
                    outside.0 = Some(c.min(r.s0 - delta));
                } else if c >= r.s1 - delta {
                    if outside.1.is_none() {
                        outside.1 = Some(c.max(r.s1 + delta));
                    }
                } else {
                    push(out, n, c)?;
                    push(&mut kept_at, &mut kept, c)?;
                }
            }
        }
        // Anything else between them (two polynomials' roots crossing): bracket and bisect,
        // where at least two polynomials have roots on the lines.
        let mut lo = r.s0;
        for k in 0..=kept {
            let next = if k < kept { kept_at.get(k).copied() } else { None };
            let hi = next.map_or(r.s1, |c| c - delta);
            let from = if k == 0 { lo } else { lo + delta };
            if hi > from && (overflow || with_roots_inside(from, hi) >= 2) {
                let span = (hi - from) / h;
                // Probes in proportion to the sub-interval's share of [s0, s1] (at least 3).
                let mut probes = 3;
                while probes < self.probes && T::from_usize(probes) < T::from_usize(self.probes) * span {
                    probes += 1;
                }
                locate_changes(&|s: T| self.line_signature(p, np, r, s), from, hi, probes, out, n)?;
            }
            lo = next.unwrap_or(r.s1);
        }
        // The branch points, while one slot stays free for the caller's end point.
        for &c in branch_points.get(..nb).unwrap_or_default() {
            if *n + 1 >= MAX_BREAKS + 2 {
                break;
            }
            push(out, n, c)?;
        }
        Ok(Some(outside))
    }

    /// The s-breaks of a curved b whose facing tests are trigonometric in both parameters
    /// ([`Surface::facing_across_s`]; with a concentric sphere occluder its plane's test too,
    /// [`Inner::concentric`]): for each test f = a(s) + b(s)·cos t + c(s)·sin t, where
    /// its zero set crosses a t-edge (f(t_edge, s) = 0, first-degree in s) and, where a and b
    /// do not depend on s, where it is tangent to the t-lines (b² + c(s)² = a², i.e.
    /// c(s) = ±√(a² − b²)), all solved by [`trigonometric_roots`]. Roots just outside [s0, s1]
    /// (within a quarter of its width) are returned as the nearest singular points beyond its
    /// ends; `None` (nothing pushed) where the surface has no such form or a root cannot be
    /// found (the caller probes the edges instead).
    #[cfg(feature = "closed-form")]
    pub(super) fn trigonometric_events(
        &self,
        p: Vec3<T>,
        np: Vec3<T>,
        r: ParamRect<T>,
        out: &mut [T; MAX_BREAKS + 2],
        n: &mut usize,
    ) -> Result<Option<Outside<T>>, PdmError> {
        let Some([f1, f2]) = self.surface.facing_across_s(p, np) else { return Ok(None) };
        let zero = [[T::ZERO; 3]; 3];
        let tests = match &self.concentric {
            None => [f1, f2, zero],
            Some(c) => {
                let Some((x0, n)) = c.plane(p) else { return Ok(None) };
                let Some([f3, _]) = self.surface.facing_across_s(x0, n) else { return Ok(None) };
                [f1, f2, f3]
            }
        };
        let reach = (r.s1 - r.s0) * T::HALF * T::HALF;
        let (lo, hi) = (r.s0 - reach, r.s1 + reach);
        let mut roots = [T::ZERO; MAX_BREAKS];
        let mut nr = 0usize;
        let full = core::cell::Cell::new(false);
        let mut add = |s: T| match roots.get_mut(nr) {
            Some(slot) => {
                *slot = s;
                nr += 1;
            }
            None => full.set(true),
        };
        let mut ok = true;
        for [a, b, c] in tests {
            for te in [r.t0, r.t1] {
                let (st, ct) = te.sin_cos();
                let f = [a[0] + b[0] * ct + c[0] * st, a[1] + b[1] * ct + c[1] * st, a[2] + b[2] * ct + c[2] * st];
                ok &= trigonometric_roots(f, lo, hi, &mut add);
            }
            if a[1] == T::ZERO && a[2] == T::ZERO && b[1] == T::ZERO && b[2] == T::ZERO {
                let k2 = a[0] * a[0] - b[0] * b[0];
                if k2 >= T::ZERO {
                    let k = k2.sqrt();
                    for sign in [T::ONE, -T::ONE] {
                        ok &= trigonometric_roots([c[0] - sign * k, c[1], c[2]], lo, hi, &mut add);
                    }
                }
            } else {
                ok = false;
            }
        }
        if !ok || full.get() {
            return Ok(None);
        }
        let mut outside: Outside<T> = (None, None);
        for &x in roots.get(..nr).unwrap_or_default() {
            if x <= r.s0 {
                outside.0 = Some(outside.0.map_or(x, |o: T| o.max(x)));
            } else if x >= r.s1 {
                outside.1 = Some(outside.1.map_or(x, |o: T| o.min(x)));
            } else if *n + 1 < MAX_BREAKS + 2 {
                push(out, n, x)?;
            } else {
                return Err(PdmError::CapacityExceeded { needed: *n + 2, capacity: MAX_BREAKS + 2 });
            }
        }
        Ok(Some(outside))
    }

    /// J(p) over the whole of a flat b (closed-form mode) with nothing between p and b, by the
    /// point-to-polygon (Lambert) form: the visible part of b is the polygon P = b ∩ {q : n̂_p·(q − p) > 0}
    /// (the other facing test is constant on a flat b), and with its vertices v_k seen from p,
    /// R_k = v_k − p,
    ///
    /// J(p) = ∫_P cos θ_p cos θ_q / L² dA = ½ |Σ_k γ_k n̂_p·(R_k × R_{k+1})/|R_k × R_{k+1}||,
    ///
    /// γ_k the angle between R_k and R_{k+1} (Hottel & Sarofim 1967; `../shared/REFERENCES.md`).
    /// Exact however close p comes to b, where a product rule over b needs refining towards p.
    /// The terms are O(γ) while J can be O(γ²) (a small polygon far from p): `None` where they
    /// cancel by more than [`polygon_cancellation`] against both J and the solid angle b would
    /// subtend facing p squarely ([`Self::reach`]), and the caller integrates by the rule. A
    /// sliver of b left above p's horizon has a J far below its terms, but their rounding then
    /// stays below 2e-13 of what b gives a point facing it, while the lines that took such
    /// points were 1e-10 of J off at order 7 (a sphere's cells against a cube face).
    pub(super) fn point_to_polygon(&self, p: Vec3<T>, np: Vec3<T>) -> Option<T> {
        if self.map().is_none() {
            return self.point_to_outline(p, np);
        }
        let (poly, n) = self.clipped(p, np)?;
        self.tick();
        let used = poly.get(..n).unwrap_or_default();
        let (sum, magnitude) = arcs(p, np, used);
        let j = sum.abs() * T::HALF;
        let limit = polygon_cancellation::<T>();
        let settled = magnitude <= limit * sum.abs() || magnitude <= limit * T::TWO * self.reach(p);
        (j.is_finite() && settled).then_some(j)
    }

    /// The solid angle b would subtend from p facing it squarely, at most 2π: area / distance²
    /// to its centre (a parallelogram; zero otherwise).
    pub(super) fn reach(&self, p: Vec3<T>) -> T {
        let Some((o, et, es)) = self.map() else { return T::ZERO };
        let r = self.r;
        let (dt, ds) = (r.t1 - r.t0, r.s1 - r.s0);
        let centre = o + et.scale(r.t0 + dt * T::HALF) + es.scale(r.s0 + ds * T::HALF);
        let area = et.cross(es).norm() * dt.abs() * ds.abs();
        (area / (centre - p).norm2()).min(T::TWO * T::PI)
    }

    /// b (a parallelogram) clipped by p's tangent plane (Sutherland–Hodgman against one plane:
    /// at most 5 vertices), with the number of vertices; no vertices where b faces away from
    /// p, `None` where b is not a parallelogram.
    fn clipped(&self, p: Vec3<T>, np: Vec3<T>) -> Option<([Vec3<T>; 5], usize)> {
        let (o, et, es) = self.map()?;
        let r = self.r;
        let nq = self.surface.normal(r.t0, r.s0);
        let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
        let quad = [at(r.t0, r.s0), at(r.t1, r.s0), at(r.t1, r.s1), at(r.t0, r.s1)];
        let mut poly = [Vec3::ZERO; 5];
        if !(nq.dot(p - quad[0]) > T::ZERO) {
            return Some((poly, 0));
        }
        let mut n = 0usize;
        let mut keep = |v: Vec3<T>| {
            if let Some(slot) = poly.get_mut(n) {
                *slot = v;
                n += 1;
            }
        };
        for k in 0..4 {
            let (Some(&a), Some(&b)) = (quad.get(k), quad.get((k + 1) % 4)) else { continue };
            let (da, db) = (np.dot(a - p), np.dot(b - p));
            if da > T::ZERO {
                keep(a);
            }
            if (da > T::ZERO) != (db > T::ZERO) {
                keep(a + (b - a).scale(da / (da - db)));
            }
        }
        Some((poly, n))
    }

    /// J(p) over a parallelogram b past one sphere occluder (`ball`) that lies wholly between
    /// b's plane and p's side of it, in closed form: every ray from p that meets the sphere
    /// meets it before b's plane, so the visible part of b is, in directions from p, the
    /// polygon P (b clipped by p's tangent plane) minus the sphere's cone C (axis ŵ towards the
    /// centre, half-angle α, sin α = R/|c − p|), and J = Π(P \ C) with Π the projected solid
    /// angle ½ ∮ n̂_p·(u × du) over a region's boundary: P's edges where they run outside C
    /// (great-circle arcs: Lambert's terms, as [`Self::point_to_polygon`]) and C's circle where
    /// it runs inside P (P ∩ C is convex), backwards from each point where an edge enters C to
    /// the one where an edge last left it, whose term is in closed form: with
    /// u(ψ) = cos α·ŵ + sin α·(cos ψ·e₁ + sin ψ·e₂),
    ///
    /// ∫ n̂_p·(u × u′) dψ = sin²α (n̂_p·ŵ) Δψ − sin α cos α [(n̂_p·e₁) Δsin ψ − (n̂_p·e₂) Δcos ψ].
    ///
    /// The circle's terms are taken from the crossings' directions, and P's boundary is walked
    /// piece by piece (inside C or not), so that a crossing at a vertex of P counts once.
    ///
    /// `None` where the sphere does not lie wholly on p's side of b's plane, p is inside it, or
    /// the terms cancel by more than [`polygon_cancellation`] against both J and P's
    /// unshadowed J: the caller then integrates by lines.
    #[cfg(feature = "closed-form")]
    pub(super) fn point_past_sphere(&self, p: Vec3<T>, np: Vec3<T>, ball: &Ball<T>) -> Option<T> {
        let (o, et, es) = self.map()?;
        let nb = et.cross(es);
        let nb = nb.scale(T::ONE / nb.norm());
        // The sphere strictly between b's plane and p's side (with a relative margin).
        let margin = ball.radius * T::GEOMETRY_TOLERANCE.sqrt();
        let side = nb.dot(p - o);
        if !(side > T::ZERO && nb.dot(ball.center - o) > ball.radius + margin) {
            return None;
        }
        let (mut poly, n) = self.clipped(p, np)?;
        self.tick();
        if n < 3 {
            return Some(T::ZERO);
        }
        let used = poly.get_mut(..n).unwrap_or_default();
        let (visible, magnitude) = polygon_past_sphere(p, np, used, ball)?;
        // The terms' rounding against J, or, where the cone leaves only slivers of P, against
        // P's own (unshadowed) J: a sliver's J is a difference of nearly equal angles however
        // it is computed (the lines round the ends of its pieces alike), so no method holds it
        // to better than a few ε of the unshadowed J.
        let j = visible * T::HALF;
        let limit = polygon_cancellation::<T>();
        let settled = magnitude <= limit * visible || magnitude <= limit * arcs(p, np, used).0.abs();
        let rounding = T::from_f64(5.0) * T::EPSILON * magnitude;
        (j.is_finite() && j >= -rounding && settled).then_some(j.max(T::ZERO))
    }

    /// [`Self::point_to_polygon`] on a flat b with curved edges, along its outline
    /// (`contour::Outline::point_form`); `None` where b has no outline.
    #[cfg(feature = "closed-form")]
    pub(super) fn point_to_outline(&self, p: Vec3<T>, np: Vec3<T>) -> Option<T> {
        let (j, magnitude, n) = self.outline.as_ref()?.point_form(&self.line_rule, p, np)?;
        self.count.set(self.count.get().saturating_add(n));
        (magnitude <= polygon_cancellation::<T>() * j).then_some(j)
    }

    /// Without closed forms there is no outline form.
    #[cfg(not(feature = "closed-form"))]
    pub(super) fn point_to_outline(&self, _p: Vec3<T>, _np: Vec3<T>) -> Option<T> {
        None
    }

    /// `true` if p lies closer to the ball than its radius: a rule over the ball's patch then
    /// converges slowly (the kernel's nearest singularity, at p, is within the patch's size).
    pub(super) fn near(&self, p: Vec3<T>, ball: &Ball<T>) -> bool {
        (ball.center - p).norm() - ball.radius < ball.radius
    }

    /// The distance from `ball` to the part r of b: exact on a parallelogram (the nearest
    /// point of its plane, or of its sides where that falls outside), else by refinement
    /// ([`distance_to_part`], which along a contact refines b down to the ball's size: cells
    /// of an outer patch graded towards a touching b took 10⁵ parts each).
    pub(super) fn distance_from(&self, ball: &Ball<T>, r: ParamRect<T>) -> Result<T, PdmError> {
        if let Some(map) = self.map() {
            return Ok((distance_to_parallelogram(ball.center, map, r) - ball.radius).max(T::ZERO));
        }
        distance_to_part(self.surface, self.affine, ball, r, T::MAX, 0)
    }

    /// b's affine map where b is a parallelogram (whether or not its lines are in closed form:
    /// the facing tests at b's corners, the point-to-polygon form and the distance to b need
    /// only the map; with a dozen flat occluders the lines were not in closed form, and a
    /// touching pair's points that nothing shaded went by lines, 7.5 s on one room pair).
    pub(super) fn map(&self) -> Option<(Vec3<T>, Vec3<T>, Vec3<T>)> {
        #[cfg(feature = "closed-form")]
        return self.parallelogram.or(self.affine);
        #[cfg(not(feature = "closed-form"))]
        self.affine
    }

    /// The smallest ball known to contain the part r of b (exact corners when flat).
    pub(super) fn ball_of(&self, r: ParamRect<T>) -> Result<Ball<T>, PdmError> {
        part_ball(self.surface, self.map(), r)
    }

    /// J(p) = ∫_b visible (n̂_p·e)(−n_q·e)/L⁴ dq (without the 1/π) over the part r of b,
    /// refined towards p: a part that p is [`near`](Self::near) is split 2 × 2 (up to
    /// [`MAX_NEAR_DEPTH`] times), so that every part is integrated from at least its own radius
    /// away and the rule's error falls like 2^(−2·order) or faster whatever the gap. A part
    /// whose halves the working precision cannot hold (f32, with p on b to within rounding or
    /// the sample points' own error) is integrated as it is.
    pub(super) fn refined(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, depth: u32) -> Result<T, PdmError> {
        let halves = || r.cell(0, 0, 2, 2).validate().is_ok() && r.cell(1, 1, 2, 2).validate().is_ok();
        if depth < MAX_NEAR_DEPTH && self.near(p, &self.ball_of(r)?) && halves() {
            let mut sum = T::ZERO;
            for k in 0..4 {
                sum += self.refined(p, np, r.cell(k / 2, k % 2, 2, 2), depth + 1)?;
            }
            return Ok(sum);
        }
        self.integral_split(p, np, r, 0)
    }

    /// J(p) over the part r of b; where one part holds more visibility changes than the
    /// fixed buffers ([`MAX_BREAKS`] per line or in s), it is halved (alternately in s and t,
    /// at most [`MAX_SPLITS`] times) and the halves are integrated separately.
    pub(super) fn integral_split(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>, depth: u32) -> Result<T, PdmError> {
        match self.integral_over(p, np, r) {
            Err(PdmError::CapacityExceeded { .. }) if depth < MAX_SPLITS => {
                let (lo, hi) = if depth.is_multiple_of(2) {
                    let m = (r.s0 + r.s1) * T::HALF;
                    (ParamRect { s1: m, ..r }, ParamRect { s0: m, ..r })
                } else {
                    let m = (r.t0 + r.t1) * T::HALF;
                    (ParamRect { t1: m, ..r }, ParamRect { t0: m, ..r })
                };
                Ok(self.integral_split(p, np, lo, depth + 1)? + self.integral_split(p, np, hi, depth + 1)?)
            }
            Err(PdmError::CapacityExceeded { .. }) => Ok(self.integral_sampled(p, np, r)),
            other => other,
        }
    }

    /// J(p) over a part r of b that still holds more visibility changes than the buffers after
    /// [`MAX_SPLITS`] halvings (at most a ⅛ × ⅛ part of b: changes that halving does not
    /// separate, such as rounding noise where a boundary grazes b along a line): the tensor
    /// Gauss rule with the visibility tested at each node, as the plain sum does. Its error
    /// stays within that part.
    pub(super) fn integral_sampled(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>) -> T {
        let (ht, hs) = ((r.t1 - r.t0) * T::HALF, (r.s1 - r.s0) * T::HALF);
        let mut sum = T::ZERO;
        for (xs, ws) in self.rule.points() {
            let s = r.s0 + hs * (xs + T::ONE);
            for (xt, wt) in self.rule.points() {
                let (q, nq) = self.surface.point_and_normal(r.t0 + ht * (xt + T::ONE), s);
                if self.visible(p, np, q, nq) {
                    sum += ws * wt * kernel(p, np, q, nq);
                }
            }
        }
        sum * ht * hs
    }

    /// J(p) over the part r of b (r's t- and s-ranges inside b's).
    pub(super) fn integral_over(&self, p: Vec3<T>, np: Vec3<T>, r: ParamRect<T>) -> Result<T, PdmError> {
        // J is smooth in s except where the visible set of the t-line changes its structure:
        // a boundary crossing a t-edge, or a boundary tangent to the t-lines (two breakpoints
        // meeting). Split the s-range there.
        let mut s_breaks = [T::ZERO; MAX_BREAKS + 2];
        let mut ns = 0usize;
        push(&mut s_breaks, &mut ns, r.s0)?;
        let mut outside = (None, None);
        let in_closed_form = match self.affine {
            Some(_) => self.closed_form_events(p, np, r, &mut s_breaks, &mut ns)?,
            #[cfg(feature = "closed-form")]
            None if self.trigonometric => self.trigonometric_events(p, np, r, &mut s_breaks, &mut ns)?,
            None => None,
        };
        if let Some(o) = in_closed_form {
            outside = o;
        } else {
            // The edges are probed just inside b: an edge may be a pole or a disk's centre,
            // where the normal vanishes and no facing test is defined.
            let inset = (r.t1 - r.t0) * end_inset::<T>();
            for t_edge in [r.t0 + inset, r.t1 - inset] {
                let vis_edge = |s: T| {
                    let (q, nq) = self.surface.point_and_normal(t_edge, s);
                    self.visible(p, np, q, nq)
                };
                locate_changes(&vis_edge, r.s0, r.s1, self.probes, &mut s_breaks, &mut ns)?;
            }
        }
        push(&mut s_breaks, &mut ns, r.s1)?;
        let s_used = s_breaks.get_mut(..ns).unwrap_or_default();
        sort(s_used);
        let mut inner = T::ZERO;
        let mut line = Line::new();
        // Where two breakpoints of the t-lines meet (a boundary tangent to the lines) the
        // visible length grows like √(s − s*): J(s) has a square-root end point, which a
        // Gauss rule integrates only algebraically. s = s* + H·x² (or the smoothstep
        // 3x² − 2x³ with both ends graded) makes it smooth in x; at the other interior
        // breaks (a boundary crossing a t-edge) the map is harmless.
        for_each_piece(s_used, r.s0, r.s1, outside, |s_lo, s_hi, grade_lo, grade_hi| {
            let width = s_hi - s_lo;
            for (xs, ws) in self.rule.points() {
                let (u, du) = graded((xs + T::ONE) * T::HALF, grade_lo, grade_hi);
                let s = s_lo + width * u;
                self.line(p, np, r, s, &mut line)?;
                // Integrate the visible pieces (visibility alternates from the first piece).
                let mut sum = T::ZERO;
                let mut visible_piece = line.first_visible;
                for w in line.breaks.get(..line.n).unwrap_or_default().windows(2) {
                    let (lo, hi) = match w {
                        [lo, hi] => (*lo, *hi),
                        _ => continue,
                    };
                    let this_visible = visible_piece;
                    visible_piece = !visible_piece;
                    if !this_visible || !(hi > lo) {
                        continue;
                    }
                    let half = (hi - lo) * T::HALF;
                    let mut piece = T::ZERO;
                    for (xt, wt) in self.rule.points() {
                        let (q, nq) = self.surface.point_and_normal(lo + half * (xt + T::ONE), s);
                        self.tick();
                        piece += wt * kernel(p, np, q, nq);
                    }
                    sum += piece * half;
                }
                inner += ws * T::HALF * du * width * sum;
            }
            Ok(())
        })?;
        Ok(inner)
    }
}

/// P \ C for a convex polygon P (vertices `poly`, reordered to positive orientation about the
/// directions from p) and the cone C of directions from p to the sphere `ball` (p outside
/// it): twice the projected solid angle of the region, and the sum of its terms' magnitudes
/// ([`Inner::point_past_sphere`], whose docs give the method); `(0, 0)` where P lies wholly
/// inside C, `None` where the walk around P does not close.
#[cfg(feature = "closed-form")]
pub(super) fn polygon_past_sphere<T: Real>(
    p: Vec3<T>,
    np: Vec3<T>,
    poly: &mut [Vec3<T>],
    ball: &Ball<T>,
) -> Option<(T, T)> {
    // Positive orientation about the directions from p (P's normal by the right-hand rule
    // pointing away from p), which the cone's circle shares with increasing ψ below.
    // The orientation from the whole outline (its area vector), not from three corners,
    // which may lie on one line (a piece of b clipped through a corner repeats it).
    let n = poly.len();
    let first = poly.first().copied().unwrap_or(Vec3::ZERO);
    let area = poly
        .iter()
        .zip(poly.iter().cycle().skip(1))
        .fold(Vec3::ZERO, |sum, (&v, &w)| sum + (v - first).cross(w - first));
    if area.dot(first - p) < T::ZERO {
        poly.reverse();
    }
    let used: &[Vec3<T>] = poly;
    let w = ball.center - p;
    let dist2 = w.norm2();
    let r2 = ball.radius * ball.radius;
    if !(dist2 > r2) {
        return None;
    }
    let k = dist2 - r2;
    let inside = |d: Vec3<T>| {
        let wd = w.dot(d);
        wd > T::ZERO && wd * wd >= k * d.norm2()
    };
    // The cone's frame: ŵ, e₁, e₂ right-handed.
    let dist = dist2.sqrt();
    let axis = w.scale(T::ONE / dist);
    let helper = if axis.x.abs() < T::HALF { vec3(T::ONE, T::ZERO, T::ZERO) } else { vec3(T::ZERO, T::ONE, T::ZERO) };
    let e1 = helper.cross(axis);
    let e1 = e1.scale(T::ONE / e1.norm());
    let e2 = axis.cross(e1);
    let (sin_a, cos_a) = (ball.radius / dist, k.sqrt() / dist);
    // A point of C's circle as its unit direction (cos ψ, sin ψ) about the axis.
    let angle = |d: Vec3<T>| {
        let (x, y) = (d.dot(e1), d.dot(e2));
        let r = (x * x + y * y).sqrt();
        if r > T::ZERO {
            (x / r, y / r)
        } else {
            (T::ONE, T::ZERO)
        }
    };
    // The circle's term from ψ₀ to ψ₁ (counter-clockwise, Δ = ψ₁ − ψ₀ in [0, 2π)), with
    // Δsin ψ = 2 cos ψ̄ sin(Δ/2) and Δcos ψ = −2 sin ψ̄ sin(Δ/2) (ψ̄ the mid-angle) and Δ
    // from the two directions: relative to the arc's length, where differences of angles
    // and of their sines would carry an absolute ε (a thin sliver of b left visible
    // beside the cone has short arcs and a J many orders below b's).
    let circle = |(x0, y0): (T, T), (x1, y1): (T, T)| {
        let mut delta = (x0 * y1 - y0 * x1).atan2(x0 * x1 + y0 * y1);
        if delta < T::ZERO {
            delta += T::TWO * T::PI;
        }
        let (sh, ch) = (delta * T::HALF).sin_cos();
        let (mx, my) = (x0 * ch - y0 * sh, x0 * sh + y0 * ch);
        sin_a * (sin_a * np.dot(axis) * delta - cos_a * T::TWO * sh * (np.dot(e1) * mx + np.dot(e2) * my))
    };
    // The visible region P \ C directly (no difference of two projected solid angles that
    // cancel where the shadow covers most of b): P's edges outside C, and C's circle inside
    // P traversed backwards.
    // Whether each piece of P's boundary lies in C, piece by piece around P: C's boundary is
    // crossed where that changes, also at a vertex of P that lies on it (rounding there
    // can put the edge's root just outside the edge).
    let mut walk =
        Crossings { visible: T::ZERO, magnitude: T::ZERO, entries: 0, exits: 0, first_entry: None, pending_exit: None };
    let mut outside = false;
    let (mut previous, mut first): (Option<bool>, Option<bool>) = (None, None);
    for (j, &a) in used.iter().enumerate() {
        let Some(&b) = used.get((j + 1) % n) else { continue };
        let (da, e) = (a - p, b - a);
        // g(λ) = (w·d)² − k|d|² along d = da + λ·e: C's boundary where it vanishes.
        let (wa, we) = (w.dot(da), w.dot(e));
        let qa = we * we - k * e.norm2();
        let qb = T::TWO * (wa * we - k * da.dot(e));
        let qc = wa * wa - k * da.norm2();
        let mut cuts = [T::ZERO, T::ONE, T::ONE, T::ONE];
        let mut nc = 1usize;
        crate::visibility::polynomial_roots(qa, qb, qc, &mut |x| {
            if x > T::ZERO && x < T::ONE {
                if let Some(slot) = cuts.get_mut(nc) {
                    *slot = x;
                    nc += 1;
                }
            }
        });
        let cuts = cuts.get_mut(..=nc).unwrap_or_default();
        super::breaks::sort(cuts);
        for piece in cuts.windows(2) {
            let &[lo, hi] = piece else { continue };
            if !(hi > lo) {
                continue;
            }
            let (u, v) = (da + e.scale(lo), da + e.scale(hi));
            let now = inside(da + e.scale((lo + hi) * T::HALF));
            if previous == Some(!now) {
                walk.cross(now, angle(u), &circle);
            }
            previous = Some(now);
            first.get_or_insert(now);
            if !now {
                outside = true;
                let (term, size) = arc(np, u, v);
                walk.visible += term;
                walk.magnitude += size;
            }
        }
    }
    // Around the last vertex back to the first.
    if let (Some(last), Some(now), Some(&a)) = (previous, first, used.first()) {
        if last != now {
            walk.cross(now, angle(a - p), &circle);
        }
    }
    let Crossings { mut visible, mut magnitude, entries, exits, first_entry, pending_exit } = walk;
    if entries != exits {
        return None;
    }
    if !outside && entries == 0 {
        // P lies wholly inside C: b is hidden from p.
        return Some((T::ZERO, T::ZERO));
    }
    match (pending_exit, first_entry) {
        (Some(exit), Some(entry)) => {
            let term = circle(exit, entry);
            visible -= term;
            magnitude += term.abs();
        }
        (None, None) if entries == 0 => {
            // No edge runs inside C: C lies wholly inside P (its axis inside every edge's
            // half-space), or apart from it.
            let within = used
                .iter()
                .enumerate()
                .all(|(j, &a)| used.get((j + 1) % n).is_some_and(|&b| axis.dot((a - p).cross(b - p)) > T::ZERO));
            if within {
                let cap = T::TWO * T::PI * sin_a * sin_a * np.dot(axis);
                visible -= cap;
                magnitude += cap.abs();
            }
        }
        (None, None) => {}
        _ => return None,
    }
    Some((visible, magnitude))
}

/// The distance from x to the part r of the parallelogram o + t·et + s·es: to the foot of the
/// perpendicular where it falls inside, else to the nearest of the four sides.
pub(super) fn distance_to_parallelogram<T: Real>(
    x: Vec3<T>,
    (o, et, es): (Vec3<T>, Vec3<T>, Vec3<T>),
    r: ParamRect<T>,
) -> T {
    let d = x - o;
    let (tt, ts, ss) = (et.dot(et), et.dot(es), es.dot(es));
    let (bt, bs) = (et.dot(d), es.dot(d));
    let det = tt * ss - ts * ts;
    if det > T::ZERO {
        let (t, s) = ((bt * ss - bs * ts) / det, (bs * tt - bt * ts) / det);
        if t >= r.t0 && t <= r.t1 && s >= r.s0 && s <= r.s1 {
            return (x - (o + et.scale(t) + es.scale(s))).norm();
        }
    }
    let at = |t: T, s: T| o + et.scale(t) + es.scale(s);
    let corners = [at(r.t0, r.s0), at(r.t1, r.s0), at(r.t1, r.s1), at(r.t0, r.s1)];
    let mut best = T::MAX;
    for (k, &a) in corners.iter().enumerate() {
        let b = corners.get((k + 1) % 4).copied().unwrap_or(a);
        let e = b - a;
        let length2 = e.norm2();
        let f = if length2 > T::ZERO { ((x - a).dot(e) / length2).max(T::ZERO).min(T::ONE) } else { T::ZERO };
        best = best.min((x - (a + e.scale(f))).norm());
    }
    best
}

/// Lambert's terms over a polygon seen from p: the sum of γ_k n̂_p·(R_k × R_{k+1})/|R_k × R_{k+1}|
/// over its edges (twice the projected solid angle, signed by the polygon's orientation) and the
/// sum of their magnitudes.
fn arcs<T: Real>(p: Vec3<T>, np: Vec3<T>, poly: &[Vec3<T>]) -> (T, T) {
    let (mut sum, mut magnitude) = (T::ZERO, T::ZERO);
    for (k, &v) in poly.iter().enumerate() {
        let Some(&w) = poly.get((k + 1) % poly.len()) else { continue };
        let (term, size) = arc(np, v - p, w - p);
        sum += term;
        magnitude += size;
    }
    (sum, magnitude)
}

/// One great-circle arc's term from direction a to direction b: γ n̂_p·(a × b)/|a × b| (γ the
/// angle between them), and its magnitude; zero for parallel directions.
pub(super) fn arc<T: Real>(np: Vec3<T>, a: Vec3<T>, b: Vec3<T>) -> (T, T) {
    let c = a.cross(b);
    let sine = c.norm();
    if !(sine > T::ZERO) {
        return (T::ZERO, T::ZERO);
    }
    let term = sine.atan2(a.dot(b)) * np.dot(c) / sine;
    (term, term.abs())
}

/// The crossings of P's boundary with the circle of a sphere's cone in [`Inner::point_past_sphere`],
/// in order around P: each exit from C is joined to the next entry by C's circle, traversed
/// backwards (its terms subtracted from `visible`).
#[cfg(feature = "closed-form")]
struct Crossings<T> {
    visible: T,
    magnitude: T,
    entries: usize,
    exits: usize,
    first_entry: Option<(T, T)>,
    pending_exit: Option<(T, T)>,
}

#[cfg(feature = "closed-form")]
impl<T: Real> Crossings<T> {
    /// C's boundary crossed at the direction `at` about its axis ((cos ψ, sin ψ)), into C
    /// (`entering`) or out of it; `circle(from, to)` is the term of C's circle from one
    /// direction to the other.
    fn cross(&mut self, entering: bool, at: (T, T), circle: &dyn Fn((T, T), (T, T)) -> T) {
        if !entering {
            self.exits += 1;
            self.pending_exit = Some(at);
            return;
        }
        self.entries += 1;
        match self.pending_exit.take() {
            Some(exit) => {
                let term = circle(exit, at);
                self.visible -= term;
                self.magnitude += term.abs();
            }
            None => self.first_entry = Some(at),
        }
    }
}
