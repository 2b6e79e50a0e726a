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
//! - [`iteration`]: the iteration core (argmin's `Solver::next_iter` and
//!   executor): a [`iteration::Solver`] takes one step, [`iteration::execute`]
//!   owns the loop, the ‖F‖₂ history and the stopping rule; every solver
//!   below fails with its one error, [`SolveError`];
//! - [`newton`](mod@newton): the one damped Newton method (dense Jacobian, optional
//!   linear border rows, through [`bordered::BorderedLu`], backtracking,
//!   residual and step tests);
//! - [`chord`](mod@chord): the chord iteration on a factorization the
//!   caller has, with Broyden's updates (Kelley's `brsol`): the first try
//!   of the exact-Jacobian path corrector;
//! - [`deflation`]: deflated Newton, the roots of `F` other than the known
//!   ones (the HB solutions at one frequency of `ivt_hb::all_solutions`);
//! - [`broyden`]: Broyden's quasi-Newton method (the thesis's Eq. 66–67)
//!   with its line search and Jacobian refreshes, on caller-owned
//!   `B` and `H = B⁻¹`.
//!
//! The rule for linear algebra: faer for dense LU and eigenvalues
//! (workspace-based, no allocation in loops); nalgebra only for small
//! fixed-size algebra and `expm`.

pub mod bordered;
pub mod broyden;
pub mod cancel;
pub mod chord;
pub mod deflation;
pub mod iteration;
pub mod lu;
pub mod newton;
pub mod rk;
pub mod small;
pub mod tableau;
#[cfg(test)]
mod test_rng;
pub mod vector;

pub use bordered::{BorderedError, BorderedLu};
pub use broyden::{
    broyden_solve, BlockDiagonal, BroydenOptions, BroydenStats, BroydenWorkspace, System,
};
pub use chord::chord;
pub use deflation::{deflated_newton, Deflation};
pub use iteration::{SolveError, StepCheck};
pub use lu::LuWorkspace;
pub use newton::{
    newton, newton_bordered, Border, NewtonOptions, NewtonStats, NewtonSystem, NewtonWorkspace,
};
pub use rk::{ExplicitRk, Tolerance};
pub use tableau::{Tableau, DP5, RK4, RK6};
