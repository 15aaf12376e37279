//! The shared-vertex transform: four pyramids of the 4-cube (Jacobian ζ³), and the variant for
//! a vertex that is a whole collapsed side (a cone's apex, a disk's centre, a sphere's pole).

use super::*;

/// The vertex sum when a side through the common vertex collapses to it (module docs, "A side
/// collapsed to a point"): variables x = (ξ_a, η_a, ξ_b, η_b); `singular[i]` marks the variables
/// that vanish at the contact (the others run along a collapsed side and stay free). The
/// singular ones, scaled by `ext`, are split into pyramids by the largest (ζ, the others
/// ζ·m·ρ, Jacobian ζ^(k−1)·Π m for k singular variables) in ζ-shells as in `vertex_sum`; the
/// free ones get the plain rule.
#[allow(clippy::too_many_arguments)]
pub(super) fn collapsed_vertex_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 4],
    singular: [bool; 4],
    gap: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    let is_singular = |i: usize| singular.get(i).copied().unwrap_or(false);
    let k = singular.iter().filter(|s| **s).count();
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = (0..4).filter(|&i| is_singular(i)).fold(T::ONE, |j, i| j * at(&c, i));
    for pyramid in (0..4).filter(|&i| is_singular(i)) {
        let others: [usize; 3] = match pyramid {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let ek = at(&ext, pyramid);
        let mut breaks = [T::ZERO; 3];
        for (slot, &i) in breaks.iter_mut().zip(&others) {
            *slot = if is_singular(i) { at(&ext, i) } else { T::ZERO };
        }
        for_each_shell(gap, ek, &breaks, |z0, z1| {
            let dz = z1 - z0;
            for (zu, wz) in unit_points(rule) {
                let (zeta, wz) = (z0 + dz * zu, wz * dz);
                // m_i = min(1, ext_i/ζ) for the singular ratios, 1 for the free variables.
                let m = others.map(|i| if is_singular(i) { (at(&ext, i) / zeta).min(T::ONE) } else { T::ONE });
                let mut jac = jac_scale;
                for _ in 1..k {
                    jac *= zeta;
                }
                for (slot, &i) in others.iter().enumerate() {
                    if is_singular(i) {
                        jac *= at(&m, slot);
                    }
                }
                let var = |slot: usize, r: T| {
                    let i = others.get(slot).copied().unwrap_or(0);
                    if is_singular(i) {
                        (zeta * at(&m, slot) * r * at(&c, i)).min(T::ONE)
                    } else {
                        r
                    }
                };
                let xz = (zeta * at(&c, pyramid)).min(T::ONE);
                for (pu, wp) in unit_points(rule) {
                    for (qu, wq) in unit_points(rule) {
                        let mut line = T::ZERO;
                        for (ru, wr) in unit_points(rule) {
                            let (x1, x2, x3) = (var(0, pu), var(1, qu), var(2, ru));
                            let x = match pyramid {
                                0 => [xz, x1, x2, x3],
                                1 => [x1, xz, x2, x3],
                                2 => [x1, x2, xz, x3],
                                _ => [x1, x2, x3, xz],
                            };
                            let (pa, na) = a.eval(at(&x, 0), at(&x, 1));
                            let (pb, nb) = b.eval(at(&x, 2), at(&x, 3));
                            line += wr * kernel_occluded(pa, na, pb, nb, occ);
                        }
                        total.add(wz * wp * wq * jac * line);
                    }
                }
            }
        });
    }
    total.value()
}

pub(super) fn vertex_sum<T, SA, SB, O>(
    a: &Local<'_, '_, T, SA>,
    b: &Local<'_, '_, T, SB>,
    rule: &GaussRule<T>,
    occ: &O,
    ext: [T; 4],
    gap: T,
) -> T
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    // Scaled variables X = (ξ_a, η_a, ξ_b, η_b) · ext ∈ [0, ext]; pyramid k: X_k = ζ is the
    // largest, the others ζ·m_j(ζ)·ρ_j with m_j = min(1, ext_j/ζ).
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1) * at(&c, 2) * at(&c, 3);
    // The point at local variables x (physical, in [0, 1]): index 0, 1 on A, 2, 3 on B.
    let point =
        |x: [T; 4], on_b: bool| if on_b { b.eval(at(&x, 2), at(&x, 3)).0 } else { a.eval(at(&x, 0), at(&x, 1)).0 };
    let vertex = a.eval(T::ZERO, T::ZERO).0;
    for pyramid in 0..4 {
        let others: [usize; 3] = match pyramid {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        let [o1, o2, o3] = others;
        let (ek, e1, e2, e3) = (at(&ext, pyramid), at(&ext, o1), at(&ext, o2), at(&ext, o3));
        let on_b = pyramid >= 2;
        for_each_shell(gap, ek, &[e1, e2, e3], |z0, z1| {
            let dz = z1 - z0;
            for (zu, wz) in unit_points(rule) {
                let (zeta, wz) = (z0 + dz * zu, wz * dz);
                let m = [(e1 / zeta).min(T::ONE), (e2 / zeta).min(T::ONE), (e3 / zeta).min(T::ONE)];
                let jac = zeta * zeta * zeta * at(&m, 0) * at(&m, 1) * at(&m, 2) * jac_scale;
                // Local variable value of ratio slot s at ratio r.
                let var = |s: usize, r: T| {
                    let k = others.get(s).copied().unwrap_or(0);
                    (zeta * at(&m, s) * r * at(&c, k)).min(T::ONE)
                };
                let with = |k: usize, v: T| {
                    let mut x = [T::ZERO; 4];
                    if let Some(slot) = x.get_mut(pyramid) {
                        *slot = (zeta * at(&c, pyramid)).min(T::ONE);
                    }
                    if let Some(slot) = x.get_mut(k) {
                        *slot = v;
                    }
                    x
                };
                // Nearly folded vertex pairs (cells along a folded edge): the point at ζ on this
                // patch's edge may come close to an edge of the other patch (distance ≪ its
                // distance from the vertex); then grade that ratio around the closest point and
                // the other two ratios towards 0, with widths (closest distance)/(line length).
                let p = point(with(pyramid, (zeta * at(&c, pyramid)).min(T::ONE)), on_b);
                let reach = (p - vertex).norm();
                let mut centre = [T::ZERO; 3];
                let mut width = [T::ONE; 3];
                // Slots of the other patch's two variables, and of this patch's other one.
                let (s_other, s_same): ([usize; 2], usize) = if on_b { ([0, 1], 2) } else { ([1, 2], 0) };
                let mut best: Option<(usize, T, T)> = None;
                for s in s_other {
                    let k = others.get(s).copied().unwrap_or(0);
                    let line = |r: T| point(with(k, var(s, r)), !on_b);
                    let (r_star, d_min) = closest_on_line(p, &line);
                    if best.is_none_or(|(_, _, d)| d_min < d) {
                        best = Some((s, r_star, d_min));
                    }
                }
                if let Some((s_near, r_star, d_min)) = best {
                    if d_min < T::from_f64(0.25) * reach {
                        for s in [s_other[0], s_other[1], s_same] {
                            let k = others.get(s).copied().unwrap_or(0);
                            let same = s == s_same;
                            let speed = (point(with(k, var(s, T::ONE)), same == on_b)
                                - point(with(k, var(s, T::ZERO)), same == on_b))
                            .norm();
                            if let (Some(w), Some(cen)) = (width.get_mut(s), centre.get_mut(s)) {
                                *w = ratio(d_min, speed);
                                if s == s_near {
                                    *cen = r_star;
                                }
                            }
                        }
                    }
                }
                for_each_interval_around(at(&centre, 0), at(&width, 0), |p0, p1| {
                    for_each_interval_around(at(&centre, 1), at(&width, 1), |q0, q1| {
                        for_each_interval_around(at(&centre, 2), at(&width, 2), |r0, r1| {
                            let (dp, dq, dr) = (p1 - p0, q1 - q0, r1 - r0);
                            for (pu, wp) in unit_points(rule) {
                                let (p, wp) = (p0 + dp * pu, wp * dp);
                                for (qu, wq) in unit_points(rule) {
                                    let (q, wq) = (q0 + dq * qu, wq * dq);
                                    for (ru, wr) in unit_points(rule) {
                                        let (r, wr) = (r0 + dr * ru, wr * dr);
                                        let (x1, x2, x3) = (var(0, p), var(1, q), var(2, r));
                                        let xz = (zeta * at(&c, pyramid)).min(T::ONE);
                                        let x = match pyramid {
                                            0 => [xz, x1, x2, x3],
                                            1 => [x1, xz, x2, x3],
                                            2 => [x1, x2, xz, x3],
                                            _ => [x1, x2, x3, xz],
                                        };
                                        let (pa, na) = a.eval(at(&x, 0), at(&x, 1));
                                        let (pb, nb) = b.eval(at(&x, 2), at(&x, 3));
                                        total.add(wz * wp * wq * wr * jac * kernel_occluded(pa, na, pb, nb, occ));
                                    }
                                }
                            }
                        });
                    });
                });
            }
        });
    }
    total.value()
}
