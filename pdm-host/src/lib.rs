//! Host-side (std) tools around `pdm-kernel`: the `pdm-ff` command line, independent reference
//! values, the Gauss–Legendre table generator, validation and sweeps.

pub mod csv_num;
pub mod gauss_gen;
pub mod reference;
pub mod scene;
pub mod tradeoff;
pub mod validate;
