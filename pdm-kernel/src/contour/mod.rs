//! Flat pairs by the contour (Stokes) form: for two flat patches that see each other wholly
//! (each in the closed half-space in front of the other, nothing between them),
//!
//! A_a·F_{a→b} = (1/2π) ∮_{∂a} ∮_{∂b} ln r  dl_a·dl_b
//!
//! (Sparrow 1963; `../shared/REFERENCES.md`, "Contour (Stokes) form"), both boundaries
//! counter-clockwise about their radiating normals. It replaces the 4-D integral by 16 double
//! line integrals over pairs of edges, whose only singularity is logarithmic, so it stays exact
//! however close the polygons come (a gap of 1e-8 of their size, strips of any aspect) where the
//! 4-D rule sums a peak it cannot see.
//!
//! Per pair of edges x(σ) = P + σ d_a, y(τ) = Q + τ d_b (σ, τ ∈ [0, 1]) the inner integral is in
//! closed form: with u₀(σ) the foot of x(σ) along the unit direction ê of d_b and η(σ) the
//! distance of x(σ) from that line,
//!
//! ∫₀¹ ln |x − y(τ)| dτ = [G(L − u₀) − G(−u₀)] / (2L),  G(v) = v ln(v² + η²) − 2v + 2η atan(v/η),
//!
//! L = |d_b|. The outer integrand is analytic except near the points where x(σ) comes close to
//! edge b (its complex singularities lie at the distance of x(σ) from the edge): where the foot
//! passes either end of edge b (u₀ = 0, u₀ = L) and where the two lines come closest. The outer
//! rule is split there and cut geometrically towards each such point down to that distance
//! (widths d, 4d, 16d, …), so it converges exponentially in the order for every gap.
//! Perpendicular edges contribute nothing (d_a·d_b = 0). Two kinds of edge pairs need no
//! outer rule at all, and they are the ones where it would cut geometrically down to rounding:
//! parallel edges (collinear ones included: a shared edge) and edges leaving a common end (a
//! shared corner) have the whole double integral in closed form (`quad.rs`:
//! `closed_edge_pair`), so C-11, C-14 and squares sharing a corner cost 16–32 closed-form
//! terms at any order. The geometry is translated to its
//! centroid and scaled to unit size first (the ln of the scale integrates to zero over a closed
//! contour), so the logarithms stay O(1) at any scale.
//!
//! # Curved edges
//! The form holds for any two flat patches, whatever their edges: a disk or annulus sector, a
//! planar Bézier patch, a disk against a parallelogram ([`Outline`], [`curve_exchange`]). An
//! edge is then the image of a side of the parameter rectangle, x(σ) = g(t(σ), s(σ)) with
//! x′(σ) from the surface's partial derivatives, and the inner integral
//! ∫ ln |x − y(τ)| x′·y′(τ) dτ has no closed form. Its integrand is analytic except near the
//! point of y nearest to x (complex singularities at the distance η of x from y): it is cut
//! there and graded geometrically towards that point and the edge's ends, down to their
//! distances from x, so the inner rule converges exponentially at every gap. The outer
//! integrand is analytic except where x(σ) passes close to an end of y or comes closest to y
//! (where the edges cross, seen along the normal): cut and graded there the same way. A
//! parallel edge at a constant small distance (the rims of coaxial disks) needs no cut: the
//! outer integrand's singularities then lie only at the other edge's ends.
//!
//! Files: `quad.rs` (two parallelograms), `curve.rs` (curved outlines), `outline.rs` (a flat
//! patch's outline and the point-to-polygon form), `grading.rs` (graded rules on line
//! pieces).

use crate::error::PdmError;
use crate::gauss::GaussRule;
use crate::patch::Patch;
use crate::real::Real;
use crate::surface::{ParamRect, Surface};
use crate::vec3::{vec3, Vec3};

mod curve;
mod grading;
mod outline;
mod quad;
#[cfg(test)]
mod tests;
pub(crate) use curve::*;
use grading::*;
pub(crate) use outline::*;
pub(crate) use quad::*;

/// Insertion sort (at most a handful of entries; NaN never moves).
fn sort<T: Real>(xs: &mut [T]) {
    for i in 1..xs.len() {
        let mut j = i;
        while j > 0 {
            let (Some(&x), Some(&y)) = (xs.get(j - 1), xs.get(j)) else { break };
            if x > y {
                xs.swap(j - 1, j);
                j -= 1;
            } else {
                break;
            }
        }
    }
}
