//! The same patch twice: the identical-panel transform (offset z = y − x, two quadrants, two
//! triangles each, ζ-shells on long patches).

use super::*;

/// A_a·F_{a→a} of a patch with itself by the identical-panel transform (module docs,
/// "The same patch twice"), with the `order`-point rule on each of the four variables, and the
/// number of integrand evaluations. Finite only, no bounds check (the pair entry points check
/// their totals).
///
/// The kernel of a smooth concave patch is bounded on the diagonal (n·e and −n'·e both grow
/// like L², so the L⁴ cancels) but its limit there depends on the direction of approach; the
/// transform makes that direction a variable of its own, so a tensor Gauss rule converges
/// exponentially where the plain self rule ([`crate::self_form_factor`]) converges only
/// algebraically. Flat and convex patches give zero. Cost: 4·order⁴ evaluations for a
/// near-square patch, times the ζ-shells (≈ log₄ of the aspect ratio).
pub(crate) fn identical_unchecked<T, S, O>(
    patch: &Patch<'_, T, S>,
    order: usize,
    occluders: &O,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let rule = GaussRule::<T>::new(order)?;
    let local = Local { patch, map: SquareMap::IDENTITY };
    let half = T::HALF;
    let lengths =
        [line_length(&local, (T::ZERO, half), (T::ONE, half)), line_length(&local, (half, T::ZERO), (half, T::ONE))];
    let (ext, _) = extents(lengths);
    let ball = patch.enclosing_ball();
    let (sum, count) = if occluders.may_block_between(&ball, &ball) {
        identical_sum(&local, &rule, occluders, ext)
    } else {
        identical_sum(&local, &rule, &(), ext)
    };
    Ok((crate::bounds::finite(sum * T::FRAC_1_PI)?, count))
}

/// The four-variable sum of [`identical_unchecked`] (without the 1/π), and its evaluations.
///
/// With z = y − x the offset between the two points (local coordinates), the integral over
/// x, y ∈ [0, 1]² becomes one over z ∈ [−1, 1]² of the integral over the x-box of side lengths
/// 1 − |z_i| (mapped to σ ∈ [0, 1]²). The kernel is symmetric in x and y, so the quadrants
/// z ↦ −z are equal: two quadrants (sign of z₂ relative to z₁), counted twice. Each quadrant,
/// scaled by the physical side lengths (Z = |z|·ext), is split into two triangles by its larger
/// coordinate: Z_k = ζ, Z_o = ζ·m·ρ with m = min(1, ext_o/ζ), Jacobian ζ·m, and ζ ∈ [0, ext_k]
/// in shells [0, 1], [1, 4], … with a break at ext_o (`for_each_shell`), as in the touching
/// transforms.
pub(super) fn identical_sum<T, S, O>(l: &Local<'_, '_, T, S>, rule: &GaussRule<T>, occ: &O, ext: [T; 2]) -> (T, u64)
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let mut total = Compensated::default();
    let mut count = 0u64;
    let q2 = (rule.order() * rule.order()) as u64;
    let c = ext.map(|e| T::ONE / e);
    let jac_scale = at(&c, 0) * at(&c, 1);
    for mirrored in [false, true] {
        for k in 0..2 {
            let o = 1 - k;
            let (ek, eo) = (at(&ext, k), at(&ext, o));
            for_each_shell(T::ZERO, ek, &[eo], |z0, z1| {
                let dz = z1 - z0;
                for (zu, wz) in unit_points(rule) {
                    let (zeta, wz) = (z0 + dz * zu, wz * dz);
                    let m = (eo / zeta).min(T::ONE);
                    let jac = zeta * m * jac_scale;
                    for (r, wr) in unit_points(rule) {
                        let mut z = [T::ZERO; 2];
                        if let Some(slot) = z.get_mut(k) {
                            *slot = (zeta * at(&c, k)).min(T::ONE);
                        }
                        if let Some(slot) = z.get_mut(o) {
                            *slot = (zeta * m * r * at(&c, o)).min(T::ONE);
                        }
                        let (z_t, z_s) = (at(&z, 0), at(&z, 1));
                        let (span_t, span_s) = (T::ONE - z_t, T::ONE - z_s);
                        let mut inner = T::ZERO;
                        for (st, wt) in unit_points(rule) {
                            // x_t ∈ [0, 1 − z_t], y_t = x_t + z_t.
                            let xt = st * span_t;
                            for (ss, ws) in unit_points(rule) {
                                // Same quadrant: y_s = x_s + z_s; mirrored: y_s = x_s − z_s.
                                let (xs, ys) = if mirrored {
                                    (z_s + ss * span_s, ss * span_s)
                                } else {
                                    (ss * span_s, ss * span_s + z_s)
                                };
                                let (pa, na) = l.eval(xt, xs);
                                let (pb, nb) = l.eval(xt + z_t, ys);
                                inner += wt * ws * kernel_occluded(pa, na, pb, nb, occ);
                            }
                        }
                        count = count.saturating_add(q2);
                        total.add(T::TWO * wz * wr * jac * span_t * span_s * inner);
                    }
                }
            });
        }
    }
    (total.value(), count)
}

/// Whether the patch faces itself in some directions and away from itself in others (a saddle,
/// or a surface concave in one region and convex in another): the section 3.2 facing test then
/// cuts the self kernel along directions where the curvature changes sign, and the
/// identical-panel transform converges only algebraically. Probed on a 5 × 5 grid of points,
/// each towards 8 neighbours an eighth of the patch away; a facing value counts only beyond
/// 1e-8 of |n|·|e| (flat patches, whose values are rounding, are not mixed).
pub(crate) fn faces_itself_mixed<T: Real, S: Surface<T> + ?Sized>(patch: &Patch<'_, T, S>) -> bool {
    let l = Local { patch, map: SquareMap::IDENTITY };
    let (mut toward, mut away) = (false, false);
    let step = T::from_f64(0.125);
    let tol = T::from_f64(1e-8);
    for i in 0..5 {
        for j in 0..5 {
            let (x, y) = (T::from_usize(i) * T::from_f64(0.25), T::from_usize(j) * T::from_f64(0.25));
            let (p, n) = l.eval(x, y);
            for (dx, dy) in
                [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0), (1.0, -1.0)]
            {
                let (xq, yq) = (x + step * T::from_f64(dx), y + step * T::from_f64(dy));
                if !(xq >= T::ZERO && xq <= T::ONE && yq >= T::ZERO && yq <= T::ONE) {
                    continue;
                }
                let (q, m) = l.eval(xq, yq);
                let (ca, cb, _) = crate::integrand::cosines(p, n, q, m);
                let l = (q - p).norm();
                let (sa, sb) = (tol * n.norm() * l, tol * m.norm() * l);
                toward |= ca > sa || cb > sb;
                away |= ca < -sa || cb < -sb;
                if toward && away {
                    return true;
                }
            }
        }
    }
    false
}
