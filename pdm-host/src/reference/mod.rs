//! Independent reference values: closed forms from the configuration-factor catalogue and
//! computations that share no code with the kernel's quadrature.
//!
//! Nothing here uses `pdm_kernel`: plain `f64`, own vector helpers ([`vector`]) and own
//! quadrature rules ([`quadrature`]: Gauss–Legendre nodes and weights from the `gauss-quad`
//! crate, the graded and adaptive rules written here).
//! * [`closed_form`]: catalogue entries C-11, C-14, C-41, sphere identities.
//! * [`contour`]: planar polygon → planar polygon by the contour (Stokes) form.
//! * [`monte_carlo`]: seeded, multithreaded ray estimator for the paper's cube-and-sphere scene.
//! * [`raytrace`]: seeded ray estimator for general patches (parallelogram, disk/annulus,
//!   cylinder, cone, sphere) with exact intersections and occluders.
//! * [`direct`]: deterministic 4-D Gauss–Legendre integration for unoccluded separate smooth
//!   pairs of any parametric patches (including Bézier patches and user maps).
//! * [`cube`]: deterministic high-accuracy face → face factors of that scene with the sphere as
//!   occluder (visibility boundaries put into the rule).

pub mod closed_form;
pub mod contour;
pub mod cube;
pub mod direct;
pub mod monte_carlo;
pub mod quadrature;
pub mod raytrace;
pub mod vector;
