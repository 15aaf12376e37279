//! Independent reference values: closed forms from the configuration-factor catalogue and
//! computations that share no code with the kernel's quadrature.
