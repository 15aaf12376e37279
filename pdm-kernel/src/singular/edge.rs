//! The shared-edge transform: six 4-D integrals over the pyramids of (|u|, η_A, η_B), graded
//! towards a small gap or fold angle, tapered where a near edge's gap varies along it.

use super::*;

/// A near edge pair whose gap tapers along the edge: the two edges nearly meet at one end and
/// diverge towards the other (cells side by side across a small fold, a slightly rotated
/// neighbour). The near-singular peak then sits at ζ ≈ the local gap, which runs from `narrow`
/// to `wide` (both in units of the shortest side) along the edge: ζ is split geometrically
/// from the narrow end's gap, and the variable along the edge is graded towards the narrow end
/// with the width where the local gap grows by the current ζ.
#[derive(Clone, Copy, Debug)]
pub(super) struct Taper<T> {
    pub(super) narrow: T,
    wide: T,
    /// The narrow end is at the edge parameter 1 (else 0).
    at_one: bool,
}

impl<T: Real> Taper<T> {
    /// The gaps at both ends of the matched edge (points at parameter 0 and 1 of both local
    /// maps), in units of `r0`; `None` unless they differ by more than a factor of 2. A narrow
    /// end below the rounding (the edges meet there) is given 2⁻²⁰ of the wide one, enough
    /// shells to reach the scales where the rule's nodes stop seeing the difference.
    pub(super) fn of<SA, SB>(a: &Local<'_, '_, T, SA>, b: &Local<'_, '_, T, SB>, r0: T) -> Option<Self>
    where
        SA: Surface<T> + ?Sized,
        SB: Surface<T> + ?Sized,
    {
        if !(r0 > T::ZERO && r0 < T::MAX) {
            return None;
        }
        let end = |x: T| (a.eval(x, T::ZERO).0 - b.eval(x, T::ZERO).0).norm() / r0;
        let (g0, g1) = (end(T::ZERO), end(T::ONE));
        let (lo, hi) = (g0.min(g1), g0.max(g1));
        if !(hi.is_finite() && hi > T::TWO * lo) {
            return None;
        }
        let floor = hi * T::from_f64(1.0 / 1_048_576.0);
        Some(Self { narrow: lo.max(floor), wide: hi, at_one: g1 < g0 })
    }

    /// The grading width along the edge (as a fraction of the line of length `span`) at radial
    /// distance `zeta`: where the local gap has grown by ζ.
    fn width(self, zeta: T, span: T) -> T {
        (zeta + self.narrow) / ((self.wide - self.narrow) * span)
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn edge_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 3],
    edge_length: T,
    gap: T,
    fold: T,
    taper: Option<Taper<T>>,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    // Compensated: up to 6·order⁴·(shells) terms, summed in f32 too.
    let mut total = Compensated::default();
    // Scaled variables X = (|u|, η_a, η_b) · ext ∈ [0, ext]: physically isotropic near the
    // edge. Pyramid k: X_k = ζ is the largest; the other two are ζ·m_j(ζ)·ρ_j with
    // m_j = min(1, ext_j/ζ) (the box cuts the pyramid beyond ζ = ext_j), ρ_j ∈ [0, 1].
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1) * at(&c, 2);
    let folded = fold > T::ZERO && fold < T::ONE;
    for pyramid in 0..3 {
        let (o1, o2) = match pyramid {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let (ek, e1, e2) = (at(&ext, pyramid), at(&ext, o1), at(&ext, o2));
        // In pyramids 1 and 2 the kernel of two nearly folded patches peaks at ρ₁ → 0 (u = 0)
        // and at the ρ₂ where the other patch's line comes closest to the point at distance ζ
        // from the edge (ρ₂ = 1 for equal scaled distances without a gap; 1 − g/ζ with a gap g
        // along the patch; the far side of the narrower patch beyond its extent), with a
        // width ≈ (closest distance) / (length of the line): both are found per ζ node and
        // the ρ intervals graded towards them.
        let grade = folded && pyramid != 0;
        for_each_shell(gap, ek, &[e1, e2], |s0, s1| {
            // Beyond the narrower patch's extent (ζ > e2 ≥ 1 in pyramid 1 or 2) its free edge
            // hovers ≈ θ·(its width) over the other patch: the kernel also peaks at ζ → e2⁺;
            // grade ζ towards e2 too. Likewise at ζ = gap, where the peak line of a gapped
            // pair enters the pyramid.
            let toward_break = if (s0 == e2 || s0 == gap) && grade { fold * s0 / (s1 - s0) } else { T::ZERO };
            // Below the gap (the shell [0, g]) the same peak line reaches ρ₂ = 0 at ζ = g from
            // below, where the two patches are only ≈ θ·g apart: grade ζ towards its upper end.
            let toward_gap = if s1 == gap && s0 < s1 && grade { fold * s1 / (s1 - s0) } else { T::ZERO };
            let (grading, toward_one) = if toward_gap > T::ZERO { (toward_gap, true) } else { (toward_break, false) };
            for_each_interval(grading, toward_one, |t0, t1| {
                let (z0, z1) = (s0 + (s1 - s0) * t0, s0 + (s1 - s0) * t1);
                let dz = z1 - z0;
                for (zu, wz) in unit_points(rule) {
                    let (zeta, wz) = (z0 + dz * zu, wz * dz);
                    let (m1, m2) = ((e1 / zeta).min(T::ONE), (e2 / zeta).min(T::ONE));
                    let jac = zeta * zeta * m1 * m2 * jac_scale;
                    let (p_width, q_centre, q_width) = if grade {
                        let half = T::HALF;
                        let (point, line): (Vec3<T>, &dyn Fn(T) -> Vec3<T>) = if pyramid == 1 {
                            (a.eval(half, (zeta * at(&c, 1)).min(T::ONE)).0, &|r: T| {
                                b.eval(half, (zeta * m2 * r * at(&c, 2)).min(T::ONE)).0
                            })
                        } else {
                            (b.eval(half, (zeta * at(&c, 2)).min(T::ONE)).0, &|r: T| {
                                a.eval(half, (zeta * m2 * r * at(&c, 1)).min(T::ONE)).0
                            })
                        };
                        let (r_star, d_min) = closest_on_line(point, line);
                        let speed = (line(T::ONE) - line(T::ZERO)).norm();
                        let u_length = edge_length * at(&c, 0) * zeta * m1;
                        (ratio(d_min, u_length), r_star, ratio(d_min, speed))
                    } else {
                        (T::ZERO, T::ONE, T::ONE)
                    };
                    for_each_interval(p_width, false, |p0, p1| {
                        for_each_interval_around(q_centre, q_width, |q0, q1| {
                            let (dp, dq) = (p1 - p0, q1 - q0);
                            for (pu, wp) in unit_points(rule) {
                                let (p, wp) = (p0 + dp * pu, wp * dp);
                                for (qu, wq) in unit_points(rule) {
                                    let (q, wq) = (q0 + dq * qu, wq * dq);
                                    let (x1, x2) = (zeta * m1 * p, zeta * m2 * q);
                                    let (xu, xa, xb) = match pyramid {
                                        0 => (zeta, x1, x2),
                                        1 => (x1, zeta, x2),
                                        _ => (x1, x2, zeta),
                                    };
                                    let abs_u = (xu * at(&c, 0)).min(T::ONE);
                                    let (eta_a, eta_b) = ((xa * at(&c, 1)).min(T::ONE), (xb * at(&c, 2)).min(T::ONE));
                                    let span = T::ONE - abs_u;
                                    let mut line = T::ZERO;
                                    let (width, toward_one) =
                                        taper.map_or((T::ONE, false), |t| (t.width(zeta, span), t.at_one));
                                    for_each_interval(width, toward_one, |l0, l1| {
                                        for (sigma, ws) in unit_points(rule) {
                                            let lo = (l0 + (l1 - l0) * sigma) * span;
                                            // u > 0: ξ_a = σ(1−u), ξ_b = ξ_a + u;
                                            // u < 0: ξ_b = σ(1−|u|), ξ_a = ξ_b + |u|.
                                            let (pa, na) = a.eval(lo, eta_a);
                                            let (pb, nb) = b.eval(lo + abs_u, eta_b);
                                            let mut k = kernel_occluded(pa, na, pb, nb, occ);
                                            let (pa2, na2) = a.eval(lo + abs_u, eta_a);
                                            let (pb2, nb2) = b.eval(lo, eta_b);
                                            k += kernel_occluded(pa2, na2, pb2, nb2, occ);
                                            line += ws * (l1 - l0) * k;
                                        }
                                    });
                                    total.add(wz * wp * wq * jac * span * line);
                                }
                            }
                        });
                    });
                }
            });
        });
    }
    total.value()
}

/// The fold parameter of an edge pair: ≈ the dihedral angle when the two patches are nearly
/// folded onto each other (normals at the middle of the common edge nearly opposite), from
/// |n̂_a + n̂_b|; large (no grading) otherwise.
pub(super) fn fold_angle<T, SA, SB>(a: &Local<'_, '_, T, SA>, b: &Local<'_, '_, T, SB>) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
{
    let (_, na) = a.eval(T::HALF, T::ZERO);
    let (_, nb) = b.eval(T::HALF, T::ZERO);
    let (la, lb) = (na.norm(), nb.norm());
    if !(la > T::ZERO && lb > T::ZERO) {
        return T::ONE;
    }
    (na.scale(T::ONE / la) + nb.scale(T::ONE / lb)).norm()
}
