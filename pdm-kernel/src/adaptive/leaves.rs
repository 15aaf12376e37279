//! Leaf estimates of the tolerance mode: the contour form at rising orders, touching and self
//! pairs by order doubling, and the algebraic leaves (occluded self pairs, collapsed sides).

use super::*;

/// The contour form ([`crate::pair::flat_pair`]) at `lo_order`; where every edge pair was in
/// closed form that value stands with its rounding bound, otherwise orders 2·`lo_order`, then up
/// by 8 to [`MAX_ORDER`](crate::MAX_ORDER) until the difference between the last two plus the
/// rounding bound, the estimate, meets the tolerance. Its rules are 1-D (cost ∝ p², no sample
/// buffers), so `max_order`, which bounds the 4-D rules, does not limit them. With the
/// estimate, whether the value has lost more than half its digits to cancellation
/// ([`crate::bounds::lost_digits`]). `None` if the pair is not a flat pair that sees itself
/// wholly.
#[cfg(feature = "closed-form")]
pub(super) fn contour_leaf<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    lo_order: usize,
    settings: Adaptive<T>,
    occluders: &O,
) -> Option<Result<(Tally<T>, bool), PdmError>>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let (mut lo, mut evaluations, rounding, exact) = match crate::pair::flat_pair(a, b, lo_order, occluders)? {
        Ok(x) => x,
        Err(e) => return Some(Err(e)),
    };
    // Every edge pair in closed form: the value is the same at every order, its error the
    // rounding alone.
    if exact {
        let estimate = Tally::leaf(lo, rounding, settings, evaluations);
        return Some(Ok((estimate, crate::bounds::lost_digits(lo, rounding))));
    }
    let mut order = 2 * lo_order;
    loop {
        let (hi, n, rounding, _) = match crate::pair::flat_pair(a, b, order, occluders)? {
            Ok(x) => x,
            Err(e) => return Some(Err(e)),
        };
        evaluations = evaluations.saturating_add(n);
        let estimate = Tally::leaf(hi, (hi - lo).abs() + rounding, settings, evaluations);
        if estimate.converged || order >= crate::gauss::MAX_ORDER {
            return Some(Ok((estimate, crate::bounds::lost_digits(hi, rounding))));
        }
        lo = hi;
        order = (order + 8).min(crate::gauss::MAX_ORDER);
    }
}

/// The same patch twice by the identical-panel transform
/// (`singular::identical_unchecked`). Without an occluder that may cut the patch's
/// view of itself the kernel is smooth in the transformed variables: orders 4, 6, … as for a
/// touching pair, splitting both copies 2 × 2 at `max_order`. With one, the shadow makes the
/// integrand jump, and on a patch that faces itself in some directions and away in others (a
/// saddle: `singular::faces_itself_mixed`) the facing test puts kinks in it: the convergence is
/// algebraic, so the value at p = `max_order` is estimated as 2 × the largest difference from
/// orders p − 1, p − 2, p − 3 and p/2 (module docs); where that misses the tolerance and an
/// occluder may cut, the pair is split ([`split_where_cut`]).
#[inline(never)]
pub(super) fn identical<T, S, O, const CAP: usize>(
    a: &Patch<'_, T, S>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    S: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let ball = a.enclosing_ball();
    if !occluders.may_block_between(&ball, &ball) && !crate::singular::faces_itself_mixed(a) {
        let eval = |p: usize| crate::singular::identical_unchecked(a, p, occluders);
        return by_order_doubling::<T, S, S, O, CAP>(a, a, settings, occluders, depth, eval, 4, Split::Both);
    }
    let leaf = algebraic_leaf(|p| crate::singular::identical_unchecked(a, p, occluders), settings)?;
    split_where_cut::<T, S, S, O, CAP>(a, a, leaf, settings, occluders, depth)
}

/// A self or edge pair whose contact reaches a side collapsed to a point (a cone's apex:
/// `singular::contact_reaches_collapsed_side`). The transforms converge only algebraically
/// there, so the
/// leaf is estimated like an occluded self pair: the value at p = `max_order`, 2 × the largest
/// difference from orders p − 1, p − 2, p − 3 and p/2 (a rate p^−a is bounded for a ≥ 0.6).
/// Not split: the cells at the collapsed point stay algebraic at every level.
#[inline(never)]
pub(super) fn collapsed_contact<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    adjacency: Adjacency,
    gap: T,
    settings: Adaptive<T>,
    occluders: &O,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let eval = |p: usize| -> Result<(T, u64), PdmError> {
        match adjacency {
            Adjacency::Identical => crate::singular::identical_unchecked(a, p, occluders),
            _ => Ok((touching_unchecked(a, b, adjacency, gap, p, occluders)?, touching_evaluations(adjacency, p))),
        }
    };
    algebraic_leaf(eval, settings)
}

/// The value at p = `max_order` and 2 × the largest difference from orders p − 1, p − 2,
/// p − 3 and p/2: the estimate of a leaf that converges only algebraically in the order.
pub(super) fn algebraic_leaf<T: Real>(
    eval: impl Fn(usize) -> Result<(T, u64), PdmError>,
    settings: Adaptive<T>,
) -> Result<Tally<T>, PdmError> {
    let p = settings.max_order;
    let (hi, mut evaluations) = eval(p)?;
    let mut difference = T::ZERO;
    for q in [p - 1, p - 2, p - 3, p / 2] {
        let (v, n) = eval(q)?;
        difference = difference.max((hi - v).abs());
        evaluations = evaluations.saturating_add(n);
    }
    Ok(Tally::leaf(hi, T::from_f64(SAFETY) * difference, settings, evaluations))
}

/// How a pair that reaches `max_order` is subdivided.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Split {
    /// The larger patch in two ([`split`]): separate pairs.
    Larger,
    /// The larger patch in two, as `Larger`, but accepted only after two comparisons (three
    /// orders, as `Both`): pairs across visibility boundaries whose outer events are placed
    /// into the rule (`boundary/`, outer events), whose first orders on the graded pieces can
    /// agree by accident while the pieces are still coarse. (The events are closed-form only.)
    #[cfg_attr(not(feature = "closed-form"), allow(dead_code))]
    LargerChecked,
    /// Both patches 2 × 2 ([`split_both`]): touching pairs, whose cells along the contact must
    /// share whole edges or corners to be recognised as touching again (halving one patch
    /// leaves a partial shared edge, which the plain rule would integrate across). Touching
    /// pairs also need two comparisons (three orders, from 4) before they are accepted: their
    /// low orders are cheap, and the convergence rate of the transforms varies with the
    /// geometry.
    Both,
}

/// Evaluates the pair at orders p, p + 2, … (`eval` gives the value and its evaluations) until
/// the estimate meets the tolerance; when the next order would pass `max_order`, splits the
/// pair as `how` says (or, at the depth limit, returns the last value with its estimate, not
/// converged).
///
/// The estimate of Q_{p+2} is max(d₂, √(d₁·d₂)) with d₂ = |Q_{p+2} − Q_p| and d₁ =
/// |Q_p − Q_{p−2}| (d₂ alone on the first comparison): convergence that stalls for a step —
/// one part of the integrand converging at a slower rate than the rest — makes d₂ alone
/// accidentally small (a touching pair at 28.6°: orders 4 / 6 / 8 off by 8.4e-5 / −2.5e-9 /
/// −3.6e-9, d₂ = 1.1e-9 below the error); the geometric mean with the previous step holds the
/// estimate at the rate seen so far.
#[allow(clippy::too_many_arguments)]
pub(super) fn by_order_doubling<T, SA, SB, O, const CAP: usize>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    settings: Adaptive<T>,
    occluders: &O,
    depth: u32,
    eval: impl Fn(usize) -> Result<(T, u64), PdmError>,
    first_order: usize,
    how: Split,
) -> Result<Tally<T>, PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let last_order = settings.max_order;
    let mut p = first_order;
    let (mut prev, mut evaluations) = eval(p)?;
    let mut previous_difference: Option<T> = None;
    loop {
        let next_p = p + 2;
        let (next, n) = eval(next_p)?;
        evaluations = evaluations.saturating_add(n);
        let difference = (next - prev).abs();
        let estimate = previous_difference.map_or(difference, |d1| difference.max((d1 * difference).sqrt()));
        let leaf = Tally::leaf(next, estimate, settings, evaluations);
        let accepted = leaf.converged && (how == Split::Larger || previous_difference.is_some());
        if accepted || (next_p + 2 > last_order && depth >= settings.max_depth) {
            return Ok(Tally { converged: accepted, ..leaf });
        }
        if next_p + 2 > last_order {
            let children = match how {
                Split::Larger | Split::LargerChecked => {
                    split::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, evaluations)
                }
                Split::Both => split_both::<T, SA, SB, O, CAP>(a, b, settings, occluders, depth, evaluations),
            };
            return or_parent(children, leaf);
        }
        previous_difference = Some(difference);
        prev = next;
        p = next_p;
    }
}
