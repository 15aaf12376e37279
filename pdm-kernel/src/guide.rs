//! # A guide: from one pair of patches to a subdivided scene to a guaranteed tolerance
//!
//! Every example below runs as a test and checks its result against a closed form.
//!
//! ## 1. One pair of patches
//!
//! A surface is a map g(t, s) → R³ over a parameter rectangle; its normal ∂g/∂t × ∂g/∂s
//! (eq. 4) points to the side it radiates to. A [`Patch`](crate::Patch) is a surface over a
//! part of its rectangle ([`Patch::whole`](crate::Patch::whole) for all of it).
//! [`pair_exchange`](crate::pair_exchange) integrates A_a·F_{a→b} by the method the pair
//! needs (the PDM sum, the touching-pair transforms, the contour form of two flat patches,
//! visibility boundaries) and returns an [`Estimate`](crate::Estimate): the value, its error
//! estimate where the method has one, and the work it took. Divide by A_a for F_{a→b}.
//!
//! ```
//! use pdm_kernel::{pair_exchange, vec3, PairSettings, Parallelogram, Patch};
//! // Two unit squares facing each other at distance 1 (catalogue C-11: 0.1998248956983874).
//! // The floor's normal e_x × e_y points up, the ceiling's e_y × e_x down: they face.
//! let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0))?;
//! let ceiling = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0))?;
//! let (a, b) = (Patch::whole(&floor)?, Patch::whole(&ceiling)?);
//! // `256` is the sample capacity: at least order² (16² here). Nothing is allocated.
//! let e = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?;
//! let f = e.value / a.area(16)?;
//! assert!((f - 0.1998248956983874).abs() < 1e-13);
//! assert_eq!(e.error, None); // a fixed-order method promises no accuracy: see section 4
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! ## 2. Curved surfaces, and what blocks the view
//!
//! The built-in surfaces ([`Sphere`](crate::Sphere), [`Cylinder`](crate::Cylinder),
//! [`Cone`](crate::Cone), [`Disk`](crate::Disk), [`Parallelogram`](crate::Parallelogram),
//! [`BezierPatch`](crate::BezierPatch)) write their normals in closed form; your own map gets
//! exact normals by automatic differentiation ([`AutoNormal`](crate::AutoNormal)). Anything
//! between two patches that may block segments is an [`Occluder`](crate::Occluder): a sphere,
//! a parallelogram, a disk, a cylinder, and tuples, slices and `heapless::Vec`s of them.
//!
//! ```
//! use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, Patch, Sphere};
//! // A sphere of radius 0.5 centred 1 above a disk of radius 1 facing it:
//! // F_sphere→disk = ½ (1 − 1/√(1 + (R/h)²)) (sphere to coaxial disk, catalogue).
//! let sphere = Sphere::outer(vec3(0.0, 0.0, 1.0), 0.5)?;
//! let disk = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0)?;
//! let (a, b) = (Patch::whole(&sphere)?, Patch::whole(&disk)?);
//! let exact = 0.5 * (1.0 - 1.0 / 2f64.sqrt());
//! let f = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &())?.value / a.area(16)?;
//! assert!((f - exact).abs() < 1e-9);
//!
//! // A second disk of radius 2 between them hides the sphere from the first one entirely.
//! let screen = Disk::new(vec3(0.0, 0.0, 0.3), vec3(0.0, 0.0, 1.0), 2.0)?;
//! let hidden = pair_exchange::<f64, _, _, _, 256>(&a, &b, PairSettings::ACCURATE, &screen)?.value;
//! assert_eq!(hidden, 0.0);
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! ## 3. Subdivided surfaces: substructuring
//!
//! A [`PatchGrid`](crate::PatchGrid) cuts a surface into m × n patches.
//! [`surface_exchange`](crate::surface_exchange) adds the exchanges of every patch pair of two
//! grids (eqs. 25–26), each pair by the [`Method`](crate::Method) you choose: the paper's bare
//! sum, the plain sum with the pair methods where it cannot resolve a pair, the pair method on
//! every pair, or the tolerance mode. Divide by the emitter's area
//! ([`PatchGrid::area`](crate::PatchGrid::area)) for the surface-to-surface factor.
//!
//! ```
//! use pdm_kernel::{surface_exchange, vec3, Method, PairSettings, Parallelogram, PatchGrid, Sphere};
//! // The paper's scene: a unit sphere centred in a cube of side 6. The factors from the
//! // sphere to the six faces add up to 1 (an enclosure), each 1/6 by symmetry.
//! let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0)?;
//! let (o, x, y, z) = (vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0), vec3(0.0, 0.0, 6.0));
//! let faces = [
//!     Parallelogram::new(o, x, y)?,         // floor (z = -3), normal +z
//!     Parallelogram::new(o + z, y, x)?,     // ceiling, normal -z
//!     Parallelogram::new(o, z, x)?,         // y = -3, normal +y
//!     Parallelogram::new(o + y, x, z)?,     // y = +3, normal -y
//!     Parallelogram::new(o, y, z)?,         // x = -3, normal +x
//!     Parallelogram::new(o + x, z, y)?,     // x = +3, normal -x
//! ];
//! let method = Method::Pair(PairSettings { order: 8, singular_order: 8, boundaries: true });
//! let grid = PatchGrid::new(&sphere, 4, 8)?;
//! let area = grid.area(8)?;
//! let mut row = 0.0;
//! for face in &faces {
//!     let e = surface_exchange::<f64, _, _, _, 64>(grid.clone(), PatchGrid::new(face, 2, 2)?, method, &())?;
//!     assert!((e.value / area - 1.0 / 6.0).abs() < 1e-6);
//!     row += e.value / area;
//! }
//! assert!((row - 1.0).abs() < 1e-6);
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! ## 4. Asking for an accuracy: the tolerance mode
//!
//! The fixed-order methods are exponentially accurate on smooth pairs but cannot tell you
//! their error where a shadow or a back-face cut crosses a patch. The tolerance mode
//! ([`adaptive_exchange`](crate::adaptive_exchange), or [`Method::Tolerance`](crate::Method)
//! over grids) raises the order and splits the pair until its error estimate meets the
//! relative tolerance, and says whether it did: check `converged`; `error` is an estimate of
//! the absolute error meant never to be below it.
//!
//! ```
//! use pdm_kernel::{surface_exchange, vec3, Adaptive, Disk, Method, PatchGrid};
//! // A disk of radius 1 and a coaxial one of radius 0.5 facing it from 0.5 above, cut 1 × 4
//! // and 2 × 2, each pair to a relative tolerance of 1e-9. Closed form (parallel coaxial
//! // disks, catalogue): F = ½ (X − √(X² − 4 (R₂/R₁)²)), X = 1 + (1 + R₂²)/R₁², Rᵢ = rᵢ/h.
//! let lower = Disk::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 0.0, 1.0), 1.0)?;
//! let upper = Disk::new(vec3(0.0, 0.0, 0.5), vec3(0.0, 0.0, -1.0), 0.5)?;
//! let (a, b) = (PatchGrid::new(&lower, 1, 4)?, PatchGrid::new(&upper, 2, 2)?);
//! let (r1, r2) = (1.0 / 0.5, 0.5 / 0.5);
//! let x: f64 = 1.0 + (1.0 + r2 * r2) / (r1 * r1);
//! let exact = 0.5 * (x - (x * x - 4.0 * (r2 / r1) * (r2 / r1)).sqrt());
//! let method = Method::Tolerance(Adaptive::new(1e-9)); // max order 12: capacity 144
//! let e = surface_exchange::<f64, _, _, _, 144>(a.clone(), b, method, &())?;
//! assert!(e.converged, "the tolerance was not met");
//! let area = a.area(16)?; // π, exact to rounding
//! let (f, error) = (e.value / area, e.error.unwrap_or(f64::INFINITY) / area);
//! assert!(error <= 1e-9 * f);
//! assert!((f - exact).abs() <= error);
//! # Ok::<(), pdm_kernel::PdmError>(())
//! ```
//!
//! ## 5. The sample capacity, chosen at run time
//!
//! `CAP`, the samples one patch may hold, is a compile-time constant so that nothing is
//! allocated: [`Method::capacity`](crate::Method::capacity) says what a method needs, and
//! [`with_capacity`](crate::with_capacity) runs a computation generic over `CAP` with the
//! smallest of a few fixed capacities that holds it (see its example). On a microcontroller,
//! pick the capacity by hand (25 for the paper's order 5) and consider the compile-time-order
//! entry points of [`fixed`](crate::fixed); the crate README gives the measured stack and
//! flash.
//!
//! ## 6. Where to look next
//!
//! - Accuracy of each method, and the cases where a fixed order is only algebraically
//!   accurate: [`pair_exchange`](crate::pair_exchange)'s documentation.
//! - The tolerance mode's estimates and limits: [`adaptive`](crate::adaptive).
//! - Visibility (the facing tests of section 3.2 and occluders):
//!   [`visibility`](crate::visibility).
