#![doc = include_str!("../README.md")]
//! The numerics layer shared by ivt-hb, ivt-design and the `ivt` binary.
//!
//! The rule: every Runge–Kutta integration in the workspace — the
//! steady-state shooting, the delay-loop simulation, the Floquet and
//! monodromy integrations and every time-domain reference check in the
//! tests — goes through the one explicit stepper [`rk::ExplicitRk`], driven
//! by a [`tableau::Tableau`] given as data ([`tableau::RK4`],
//! [`tableau::RK6`], [`tableau::DP5`]). A new method is a new tableau, not a
//! new kernel. The simulator's plant integrator (`ivt_sim::integrate`) uses
//! it too, on the fixed-size state `[f64; 3]`: the stepping methods are
//! `#[inline(always)]`, so the stages and the right-hand side compile into
//! one loop without heap or dynamic dispatch, and the logs are bit-identical
//! to the hand-written kernels it replaced.
//!
//! One job per module:
//! - [`tableau`]: the Butcher tableaux (nodes, weights, embedded error
//!   weights, dense-output weights);
//! - [`rk`]: the stepper — fixed steps, tentative steps with an embedded
//!   error estimate and the step-size controller, dense output;
//! - [`lu`]: dense LU on faer with caller-owned scratch, factor once per
//!   Jacobian refresh and solve many without allocating;
//! - [`small`]: products of small row-major matrices on nalgebra;
//! - [`vector`]: dot, norm, axpy and the row-major matrix–vector product
//!   on slices for the quasi-Newton loops;
//! - [`bordered`]: the bordered matrix `[[J, B], [Cᵀ, D]]` factored once
//!   (solve, transposed solve, determinant sign): every extended system of
//!   the path engine;
//! - [`newton`](mod@newton): the one damped Newton method (dense Jacobian, optional
//!   linear border rows, through [`bordered::BorderedLu`], backtracking,
//!   residual and step tests).
//!
//! The rule for linear algebra: faer for dense LU and eigenvalues
//! (workspace-based, no allocation in loops); nalgebra only for small
//! fixed-size algebra and `expm`.

pub mod bordered;
pub mod cancel;
pub mod lu;
pub mod newton;
pub mod rk;
pub mod small;
pub mod tableau;
#[cfg(test)]
mod test_rng;
pub mod vector;

pub use bordered::{BorderedError, BorderedLu};
pub use lu::LuWorkspace;
pub use newton::{
    newton, newton_bordered, Border, NewtonError, NewtonOptions, NewtonStats, NewtonSystem,
    NewtonWorkspace, StepCheck,
};
pub use rk::{ExplicitRk, Tolerance};
pub use tableau::{Tableau, DP5, RK4, RK6};
