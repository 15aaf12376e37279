//! The pair context: one pair of patches as every method of the dispatch sees it.

use super::*;
use crate::boundary::boundary_sum;
use crate::samples::Ball;

/// How a separate pair is integrated: decided once, by [`PairContext::separate_route`], for
/// the fixed-order and the tolerance modes alike.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SeparateRoute {
    /// Nothing to place into the rule and no occluder can cut: the plain sum.
    Plain,
    /// The pair straddles a back-face cut (a kink in the integrand; seen on the samples, or
    /// not proven absent: [`facing_settled`]), or is closer than its
    /// size (the plain rule's nodes do not resolve the kernel's peak, and two orders can agree
    /// on a wrong value), and no occluder can cut: the boundary path, which places the cut into
    /// the inner rule and refines the inner patch towards close outer points, with the outer
    /// patch chosen by [`outer_is_b`] (`true`: b).
    Boundary { outer_b: bool },
    /// An occluder may cut a segment between the patches: the boundary path across the
    /// occluders, the outer patch chosen by [`occluded_outer_is_b`].
    Occluded { outer_b: bool },
}

/// One pair of patches as the dispatch and its methods see it, built once per pair: the two
/// patches, the occluders, their enclosing balls (computed once, on first use) and the pair's
/// two sample buffers. A buffer is filled at the order a method asks for, the first time it
/// asks (the contour form and the touching transforms need none), and kept for the next method
/// at that order. The boundary path takes the two buffers as its outer and inner samples and
/// re-fills the outer one in place for each cell of the outer patch, so a pair never holds
/// more than these two buffers, and the inner patch is sampled once per order.
pub(crate) struct PairContext<'x, 'p, T, SA, SB, O, const CAP: usize>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    pub(crate) a: &'x Patch<'p, T, SA>,
    pub(crate) b: &'x Patch<'p, T, SB>,
    pub(crate) occluders: &'x O,
    sa: PatchSamples<T, CAP>,
    sb: PatchSamples<T, CAP>,
    /// The order at which `sa` holds a's samples (`None`: empty, or re-filled with a cell).
    order_a: Option<usize>,
    /// The order at which `sb` holds b's samples.
    order_b: Option<usize>,
    balls: Option<(Ball<T>, Ball<T>)>,
}

impl<'x, 'p, T, SA, SB, O, const CAP: usize> PairContext<'x, 'p, T, SA, SB, O, CAP>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    /// The context of the pair (a, b) with nothing computed yet.
    pub(crate) fn new(a: &'x Patch<'p, T, SA>, b: &'x Patch<'p, T, SB>, occluders: &'x O) -> Self {
        Self {
            a,
            b,
            occluders,
            sa: PatchSamples::empty(),
            sb: PatchSamples::empty(),
            order_a: None,
            order_b: None,
            balls: None,
        }
    }

    /// The enclosing balls of a and b ([`Patch::enclosing_ball`]).
    pub(crate) fn balls(&mut self) -> (Ball<T>, Ball<T>) {
        *self.balls.get_or_insert_with(|| (self.a.enclosing_ball(), self.b.enclosing_ball()))
    }

    fn fill_a(&mut self, order: usize) -> Result<(), PdmError> {
        if self.order_a != Some(order) {
            self.order_a = None;
            self.sa.fill(self.a, order, order)?;
            self.order_a = Some(order);
        }
        Ok(())
    }

    fn fill_b(&mut self, order: usize) -> Result<(), PdmError> {
        if self.order_b != Some(order) {
            self.order_b = None;
            self.sb.fill(self.b, order, order)?;
            self.order_b = Some(order);
        }
        Ok(())
    }

    /// Both patches' samples at `order` (`order` × `order` Gauss points; a fills first, so a
    /// bad a is the error reported).
    pub(crate) fn samples(&mut self, order: usize) -> Result<(&PatchSamples<T, CAP>, &PatchSamples<T, CAP>), PdmError> {
        self.fill_a(order)?;
        self.fill_b(order)?;
        Ok((&self.sa, &self.sb))
    }

    /// Whether an occluder may cut a segment between the patches: judged on the sample balls at
    /// `order`, then on the enclosing balls (the integrand is smooth only if no occluder cuts
    /// any segment between the patches, not only between their samples). A sphere that one of
    /// the patches lies on, facing out of it ([`Surface::convex_ball`]), cuts no segment the
    /// facing test lets through: when it is the only occluder that may cut, the pair is not
    /// occluded (its terminator is then a boundary of the unoccluded paths, which place it,
    /// where the occluded ones would see it only through the samples).
    pub(crate) fn may_occlude(&mut self, order: usize) -> Result<bool, PdmError> {
        let occluders = self.occluders;
        let (sa, sb) = self.samples(order)?;
        let cut = occluders.may_block_between(&sa.bounds(), &sb.bounds()) || {
            let (ball_a, ball_b) = self.balls();
            occluders.may_block_between(&ball_a, &ball_b)
        };
        Ok(cut && !self.only_own_sphere_cuts())
    }

    /// Whether the only occluder that may cut the pair is a sphere that a or b lies on, facing
    /// out ([`Surface::convex_ball`]).
    #[cfg(feature = "closed-form")]
    fn only_own_sphere_cuts(&mut self) -> bool {
        let (ball_a, ball_b) = self.balls();
        match self.occluders.shadow_sphere(&ball_a, &ball_b) {
            Some(Some(sphere)) => {
                self.a.surface().convex_ball() == Some(sphere) || self.b.surface().convex_ball() == Some(sphere)
            }
            _ => false,
        }
    }

    #[cfg(not(feature = "closed-form"))]
    fn only_own_sphere_cuts(&mut self) -> bool {
        false
    }

    /// Whether the Gauss rules of order `order` resolve the pair
    /// ([`crate::sum::samples_resolved`]).
    #[cfg(feature = "closed-form")]
    pub(crate) fn resolved(&mut self, order: usize) -> Result<bool, PdmError> {
        let (sa, sb) = self.samples(order)?;
        Ok(crate::sum::samples_resolved(sa, order, sb, order))
    }

    /// Whether some sample pairs at `order` face each other and some do not (the pair straddles
    /// a back-face cut: [`straddles_curvature_cut`]).
    pub(crate) fn straddles(&mut self, order: usize) -> Result<bool, PdmError> {
        let (sa, sb) = self.samples(order)?;
        Ok(straddles_curvature_cut(sa, sb))
    }

    /// Whether the facing test is proven to give one answer on the whole pair
    /// ([`facing_settled`]).
    pub(crate) fn facing_settled(&mut self) -> bool {
        let (ball_a, ball_b) = self.balls();
        facing_settled(self.a, self.b, &ball_a, &ball_b)
    }

    /// Whether the patches are closer than the larger one's radius ([`near`]).
    pub(crate) fn near(&mut self) -> bool {
        let (ball_a, ball_b) = self.balls();
        near(&ball_a, &ball_b)
    }

    /// Which patch the boundary path integrates outside when an occluder may cut the pair
    /// (`true`: b; [`occluded_outer_is_b`]).
    pub(crate) fn occluded_outer_is_b(&mut self) -> bool {
        let (ball_a, ball_b) = self.balls();
        occluded_outer_is_b(self.a, self.b, &ball_a, &ball_b)
    }

    /// Which patch the boundary path integrates outside on an unoccluded pair (`true`: b;
    /// [`outer_is_b`], from the samples at `order`).
    pub(crate) fn outer_is_b(&mut self, order: usize) -> Result<bool, PdmError> {
        let (a, b) = (self.a, self.b);
        let (sa, sb) = self.samples(order)?;
        Ok(outer_is_b(a, b, sa, sb))
    }

    /// The route of a separate pair, judged on the samples at `order` (module docs of
    /// [`crate::pair`]): occluded if an occluder may cut ([`PairContext::may_occlude`]), else the
    /// boundary path if the pair straddles a back-face cut, is near, or is not proven to lie wholly on
    /// one side of the cut ([`facing_settled`]), else the plain sum.
    pub(crate) fn separate_route(&mut self, order: usize) -> Result<SeparateRoute, PdmError> {
        if self.may_occlude(order)? {
            Ok(SeparateRoute::Occluded { outer_b: self.occluded_outer_is_b() })
        } else if self.straddles(order)? || self.near() || !self.facing_settled() {
            Ok(SeparateRoute::Boundary { outer_b: self.outer_is_b(order)? })
        } else {
            Ok(SeparateRoute::Plain)
        }
    }

    /// The plain PDM sum at `order` on both patches and its evaluations (`order`⁴).
    pub(crate) fn plain<P: Occluder<T> + ?Sized>(&mut self, order: usize, occluders: &P) -> Result<(T, u64), PdmError> {
        let (sa, sb) = self.samples(order)?;
        let evaluations = (sa.len() as u64).saturating_mul(sb.len() as u64);
        Ok((crate::sum::exchange_unchecked(sa, sb, occluders)?, evaluations))
    }

    /// A_a·F_{a→b} by the boundary path (`boundary/`) at `order`, the outer patch (b if
    /// `outer_b`, else a) cut into `split` × `split` cells, across `occluders` (the pair's own,
    /// or `()` where none can cut); with its evaluations. The inner patch's samples are the
    /// pair's; the outer buffer is re-filled for each cell.
    pub(crate) fn boundary<P: Occluder<T> + ?Sized>(
        &mut self,
        order: usize,
        outer_b: bool,
        split: usize,
        occluders: &P,
    ) -> Result<(T, u64), PdmError> {
        let whole = split <= 1;
        if outer_b {
            self.fill_a(order)?;
            if whole {
                self.fill_b(order)?;
            }
            self.order_b = None;
            boundary_cells(self.b, &mut self.sb, whole, self.a, &self.sa, order, split, occluders)
        } else {
            self.fill_b(order)?;
            if whole {
                self.fill_a(order)?;
            }
            self.order_a = None;
            boundary_cells(self.a, &mut self.sa, whole, self.b, &self.sb, order, split, occluders)
        }
    }
}

/// The boundary path with `outer_patch` cut into `split` × `split` cells, each sampled into
/// `outer` (which already holds the whole patch's samples at `order` if `filled`).
#[allow(clippy::too_many_arguments)]
fn boundary_cells<T, SA, SB, P, const CAP: usize>(
    outer_patch: &Patch<'_, T, SA>,
    outer: &mut PatchSamples<T, CAP>,
    filled: bool,
    inner_patch: &Patch<'_, T, SB>,
    inner: &PatchSamples<T, CAP>,
    order: usize,
    split: usize,
    occluders: &P,
) -> Result<(T, u64), PdmError>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    P: Occluder<T> + ?Sized,
{
    if split <= 1 {
        if !filled {
            outer.fill(outer_patch, order, order)?;
        }
        return boundary_sum(outer_patch, outer, inner_patch, inner, order, occluders);
    }
    let (mut total, mut count) = (T::ZERO, 0u64);
    let r = outer_patch.rect();
    for k in 0..split * split {
        let cell = Patch::new(outer_patch.surface(), r.cell(k / split, k % split, split, split))?;
        outer.fill(&cell, order, order)?;
        let (v, c) = boundary_sum(&cell, outer, inner_patch, inner, order, occluders)?;
        total += v;
        count = count.saturating_add(c);
    }
    Ok((total, count))
}
