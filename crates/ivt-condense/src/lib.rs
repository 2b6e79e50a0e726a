#![doc = include_str!("../README.md")]
//! Large structures with local nonlinearity (issue 28): harmonic balance
//! condensed onto the nonlinear DOFs.
//!
//! For `M x″ + C x′ + K x + g(x_S, ẋ_S, θ) = F_c cos θ + F_s sin θ` with sparse
//! `M`, `C`, `K` and `g` acting on a few DOFs `S`, harmonic balance decouples
//! the linear DOFs exactly, harmonic by harmonic: the unknowns are the
//! harmonics of `x_S` alone, the linear part is the dynamic stiffness
//! `D_h = K − (hω)²M + ihωC` condensed onto `S` (Krack & Gross, *Harmonic
//! Balance for Nonlinear Vibration Problems*, ch. 3; NLvib `HB_residual.m`).
//!
//! - [`Structure`]: sparse `M`, `C`, `K` on one pattern; `D_h` factored by
//!   faer's sparse LU (the choice: sparse factorization, exact for any
//!   damping, rather than a truncated modal basis), solved with iterative
//!   refinement in double-double residuals so the fine mesh's κ ~ N⁴ costs no
//!   accuracy ([`dynamic`]).
//! - [`Receptances`]: `D̃_h`, the condensed load and their ω-derivatives.
//! - [`CondensedBranch`]: the condensed residual as a [`ivt_hb::Branch`];
//!   any DOF recovered on request.
//! - [`condensed_response`]: the frequency-response curve with folds located
//!   and per point the estimated solve and truncation errors.
//! - [`ReducedStability`]: Floquet multipliers of the whole structure's
//!   variational equation on a reduced basis (the Ritz vectors of `S`,
//!   load-dependent) grown per orbit until the basis truncation's estimated error
//!   meets a tolerance.
//! - [`reduce`]: a large solid projected once onto a certified basis
//!   (issue 42), the condensed path then run on the small reduced model.

mod band;
mod branch;
mod double_double;
pub mod dynamic;
mod estimate;
mod frc;
mod modal_hsu;
pub mod models;
mod peak;
mod receptance;
pub mod reduce;
mod ritz;
mod scaled;
mod stability;

pub use branch::CondensedBranch;
pub use dynamic::{Factored, Structure};
pub use estimate::truncation_error;
pub use frc::{
    condensed_response, correct_condensed, CondensedFold, CondensedFrc, CondensedFrcOptions,
    CondensedPoint,
};
pub use receptance::{Coupling, Receptances};
pub use stability::{
    multiplier_distance, BasisGrowth, CondensedFloquet, ReducedStability, DEFAULT_BASIS_TOL,
    DEFAULT_BLOCKS,
};
