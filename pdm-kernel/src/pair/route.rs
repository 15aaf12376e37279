//! The route of a pair: which method it needs, decided once for the fixed-order mode
//! ([`pair_exchange`]) and the tolerance mode ([`crate::adaptive_exchange`]).
//!
//! Both modes first try the contour form on two flat patches that see each other wholly
//! ([`flat_pair`]: no occluder can cut between them), each with its own rule for a contour value
//! whose terms cancel. Every other pair takes the route [`route`] gives; a separate pair's
//! route is refined by [`PairContext::separate_route`] on its samples. The modes differ only in
//! what they do on a route: the fixed-order mode evaluates it once at the orders it was given,
//! the tolerance mode compares orders and splits cells until its estimate meets the tolerance.

use super::*;

/// Which method a pair needs (after the contour form; module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Route<T> {
    /// A touching pair that an occluder may cut: split both patches 2 × 2 and route the 16
    /// sub-pairs. The transforms test visibility only at their nodes, so a shadow across the
    /// pair puts a jump into the transformed integrand and their rules converge only
    /// algebraically; the cells along the contact shrink until no occluder can cut them, and
    /// the other sub-pairs are separate pairs, whose shadows the boundary path places.
    SplitContact,
    /// A shared edge or vertex: the regularising transforms (`singular/`). `collapsed`: the
    /// contact reaches a side collapsed to a point (a cone's apex), where they converge only
    /// algebraically.
    Touching { adjacency: Adjacency, gap: T, collapsed: bool },
    /// The same patch twice: the identical-panel transform (`collapsed` as above).
    Identical { gap: T, collapsed: bool },
    /// Separate patches: [`PairContext::separate_route`] decides on the samples.
    Separate,
    /// Parallelograms that touch, across flat convex occluders and spheres
    /// ([`contact_across_shadows`]): the unoccluded exchange by the contour form less the part
    /// the occluders block (`boundary/blocked.rs`), where that applies; else the boundary path
    /// over the whole pair as [`Route::Separate`].
    ContactPastShadows,
}

/// The route of the pair (a, b) whose contact `classify_near` found (module docs). `may_split`:
/// the caller may split a touching pair that an occluder may cut ([`Route::SplitContact`]; its
/// depth limit is not reached), also where the contact reaches a collapsed side: where the
/// occluder keeps away from the collapsed point, the cells along the contact shrink until it
/// cannot cut them, and only those at the point stay algebraic (one that reaches the point
/// leaves a chain of sub-pairs there split to the depth limit, 16 per level).
pub(crate) fn route<T, SA, SB, O>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    (adjacency, gap): (Adjacency, T),
    occluders: &O,
    may_split: bool,
) -> Route<T>
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    let collapsed = crate::singular::contact_reaches_collapsed_side(a, b, adjacency);
    match adjacency {
        Adjacency::SharedEdge { .. } | Adjacency::SharedVertex { .. } => {
            let may_cut = occluders.may_block_between(&a.enclosing_ball(), &b.enclosing_ball());
            // At any depth: the transforms' occlusion test per node is what this avoids.
            if may_cut && contact_across_shadows(a, b, occluders) {
                Route::ContactPastShadows
            } else if may_split && may_cut {
                Route::SplitContact
            } else {
                Route::Touching { adjacency, gap, collapsed }
            }
        }
        Adjacency::Identical => Route::Identical { gap, collapsed },
        Adjacency::Separate => Route::Separate,
    }
}

/// Whether a touching pair that an occluder may cut takes the boundary path whole instead of
/// [`Route::SplitContact`]: both patches parallelograms and the occluders flat convex polygons
/// and spheres, at least one polygon ([`Occluder::shadow_casters`], asked from a's ball). The inner integral from
/// every outer point is then exact however close the point comes to the contact
/// (`boundary/shadows.rs`), and the outer rule is graded towards b (`boundary::outer_cells`);
/// splitting cells along the contact instead ran the regularising transforms with the
/// occlusion tested at every node on 16 sub-pairs per level (a room's floor against the wall it
/// meets, a cabinet between: 257 s).
fn contact_across_shadows<T, SA, SB, O>(a: &Patch<'_, T, SA>, b: &Patch<'_, T, SB>, occluders: &O) -> bool
where
    T: Real,
    SA: Surface<T> + ?Sized,
    SB: Surface<T> + ?Sized,
    O: Occluder<T> + ?Sized,
{
    #[cfg(feature = "closed-form")]
    {
        let (Some(_), Some(_)) = (a.surface().affine_map(), b.surface().affine_map()) else { return false };
        let Some(corners) = b.surface().straight_corners(b.rect()) else { return false };
        // With spheres alone the contact is split as before: its separate sub-pairs get the
        // sphere's outer events (exponential), which the whole pair's outer rule would not.
        let mut polygons = false;
        let casters = occluders.shadow_casters(&a.enclosing_ball(), &corners, &b.enclosing_ball(), &mut |c| {
            polygons |= matches!(c, crate::visibility::Caster::Polygon(_));
        });
        casters && polygons
    }
    #[cfg(not(feature = "closed-form"))]
    {
        let _ = (a, b, occluders);
        false
    }
}
