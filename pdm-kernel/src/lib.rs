//! # pdm-kernel
//!
//! Form factors (view factors) between **curved parametric surfaces** by the Parametric
//! Differential Method (Baranoski), without cutting the surfaces into polygons. `#![no_std]`,
//! no allocation, no panics, generic over `f32` and `f64`.
//!
//! Each surface is a map g(t, s) → R³ with the unnormalised normal n = ∂g/∂t × ∂g/∂s (eq. 4); the
//! form factor between two patches is the 4-D integral of eq. (15), evaluated by the fixed-order
//! Gauss–Legendre sum of eq. (16), with the curvature (back-face) tests and exact occlusion tests
//! of section 3 deciding which sample pairs count.
//!
//! ```
//! use pdm_kernel::{surface_form_factor, Parallelogram, PatchGrid, Quadrature, Sphere, vec3};
//! // The paper's scene: a unit sphere centred in a cube of side 6. Sphere → floor face is 1/6.
//! let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0)?;
//! let floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0))?;
//! let f = surface_form_factor::<f64, _, _, _, 64>(
//!     PatchGrid::new(&sphere, 8, 16)?, PatchGrid::new(&floor, 4, 4)?, Quadrature::uniform(8), &sphere)?;
//! assert!((f - 1.0 / 6.0).abs() < 1e-4);
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! ## Stack
//!
//! Nothing is allocated: the samples of a patch live on the stack in a [`PatchSamples`]`<T, CAP>`
//! of 7·CAP values (7·CAP·`size_of::<T>()` bytes; 28 KiB for f32 at CAP 1024). What a call
//! needs, by entry point (measured by `pdm-host/tests/stack_usage.rs`; the host figures include
//! the test thread's own start-up frames, about 140 KiB; table in `pdm-host/VALIDATION.md`):
//!
//! - the plain sum ([`form_factor_between`], [`surface_form_factor`], [`fixed`]): two sample
//!   buffers and a few KiB of frames — 2 664 B in total at order 5, CAP 25, f32 on a Cortex-M4
//!   (`tests/firmware`). On the pairs it hands to [`pair_exchange`] (touching, identical, unresolved) the
//!   latter's figure applies;
//! - [`pair_exchange`]: about eight sample buffers plus 20 KiB (f32) / 160 KiB (f64) of frames
//!   (host, release: 160 KiB at CAP 25, 380 KiB at CAP 1024 for f32);
//! - [`adaptive_exchange`]: it recurses once per halving; about 43 sample buffers at depth 6
//!   (host, release, f32 CAP 1024: 1.4 MiB), linear in the depth.
//!
//! Debug builds need about 3.7× these. Give a thread that runs the tolerance mode at a large
//! capacity a stack to match (`std::thread::Builder::stack_size`); the `pdm-ff` command does.
//!
//! **Start with the [`guide`]**: one pair of patches, curved surfaces and occluders, subdivided
//! surfaces, the tolerance mode and the sample capacity, each with a runnable example.
//!
//! Modules: [`gauss`] (tables), [`surface`] (surfaces and normals), [`patch`] (patches, grids,
//! areas), [`samples`] (precomputed Gauss samples), [`visibility`] (curvature and occlusion
//! tests), [`form_factor`](mod@form_factor) (the PDM sum), [`pair`] (the method each pair
//! needs), [`adaptive`] (the tolerance mode), [`substructure`] (subdivided surfaces, every
//! method).

#![no_std]
#![forbid(unsafe_code)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented,
    missing_docs
)]
#![cfg_attr(test, allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing))]

pub mod adaptive;
mod boundary;
mod bounds;
#[cfg(feature = "closed-form")]
mod contour;
pub mod dual;
pub mod error;
mod estimate;
pub mod fixed;
pub mod form_factor;
pub mod gauss;
pub mod guide;
mod integrand;
mod math;
pub mod pair;
pub mod patch;
pub mod real;
pub mod samples;
mod singular;
pub mod substructure;
pub mod surface;
pub mod vec3;
pub mod visibility;

/// The crate README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

pub use adaptive::{adaptive_exchange, Adaptive};
pub use dual::{Dual, Scalar};
pub use error::PdmError;
pub use estimate::Estimate;
pub use form_factor::{exchange, form_factor, form_factor_between, self_form_factor, surface_form_factor, Quadrature};
pub use gauss::{GaussRule, MAX_ORDER};
pub use pair::{pair_exchange, PairSettings};
pub use patch::{Patch, PatchGrid};
pub use real::Real;
pub use samples::{Ball, PatchSamples, Sample};
pub use substructure::{capacity_for, surface_exchange, with_capacity, Method, WithCapacity, CAPACITIES};
pub use surface::{
    AutoNormal, BezierPatch, Cone, Cylinder, Disk, Flipped, Frame, Parallelogram, ParamRect, ParametricMap,
    Quadrilateral, Side, Sphere, Surface,
};
pub use vec3::{vec3, Vec3};
pub use visibility::{mutually_facing, AnyOccluder, Occluder};

/// The pieces of the pair methods that the workspace's own tests, benches and fuzz targets
/// reach directly (classification, the touching transforms and the boundary path on their own,
/// evaluation counts, internal limits). Not part of the API: no semver promise, no docs.
#[doc(hidden)]
pub mod internals {
    pub use crate::boundary::{boundary_exchange, MAX_BREAKS, MAX_NEAR_DEPTH, MAX_SPLITS};
    pub use crate::pair::{MAX_CONTACT_SPLITS, OCCLUDED_OUTER_SPLIT};
    pub use crate::singular::{classify, classify_near, touching_exchange, Adjacency, SquareMap, NEAR_CONTACT};
}
