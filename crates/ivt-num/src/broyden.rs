//! Generic Broyden ("good" update, Eq. 66–67) solver for `F(x) = 0`, `x ∈ R^m`.
//!
//! The solver iterates with the inverse `H = B⁻¹` of the approximate Jacobian `B`;
//! each update is rank one, so `H` follows by Sherman–Morrison and an iteration costs
//! O(m²) with no allocation: everything lives in the caller-owned
//! [`BroydenWorkspace`]. Rows listed in [`BroydenWorkspace::exact_rows`] are never
//! changed by the update (the exact augmenting row of the arc-length method, Eq. 77).
//!
//! `B` itself is updated alongside `H` only when the caller reads it between solves
//! ([`BroydenWorkspace::track_jacobian`], on by default, as continuation does). A
//! one-shot solve turns tracking off: the update then uses `B s = −t r` (the step is
//! `s = −t H r`), which is exact for `B = H⁻¹`, and a full step lets the next
//! direction follow from the update's `H u` without another product. `B` is then
//! recovered by inverting `H` only if someone asks for it.
//!
//! Untracked, `H` is also kept factored: its base plus the updates as pairs,
//! `H = H₀ + Σ p_j q_jᵀ` (`broyden/inverse.rs`). Seeded with a
//! [`BlockDiagonal`] `H₀` (the inverse of the linear Jacobian Eq. 60, by
//! harmonic), an iteration then costs O(rank·m) instead of three O(m²) passes:
//! Fig. 28's orbit (n = 20, m = 41, five iterations) went from 23 µs to 18 µs
//! per Python call (measured, not asserted: `bench/python_orbit.py`).
//!
//! Safeguards: a backtracking line search on ‖F‖ and, when the iteration stalls or
//! the line search fails, a refresh of `B` by the system's Jacobian (or by forward
//! finite differences when the system has none).
//!
//! The workspace and its O(m²) kernels are in `broyden/workspace.rs`, the factored
//! `H` in `broyden/inverse.rs`, the block-diagonal `H₀` in `broyden/blocks.rs`, the
//! driver (line search, refresh policy, a [`crate::iteration::Solver`] of the
//! iteration core) in `broyden/solve.rs`; a failed solve is a
//! [`crate::SolveError`].

mod blocks;
mod inverse;
mod solve;
mod workspace;
pub use blocks::BlockDiagonal;
pub use solve::broyden_solve;
pub use workspace::BroydenWorkspace;

/// A nonlinear system `F(x) = 0` with as many equations as unknowns.
///
/// Any closure `FnMut(&[f64], &mut [f64])` is a system (Jacobian by finite
/// differences); implement the trait to supply an analytic Jacobian.
pub trait System {
    /// Writes `F(x)` into `r` (`r.len() == x.len()`).
    fn residual(&mut self, x: &[f64], r: &mut [f64]);
    /// Writes the Jacobian `∂F/∂x` (row-major `m×m`) into `jac`; returns `false`
    /// when not available (the solver then uses finite differences).
    fn jacobian(&mut self, _x: &[f64], _jac: &mut [f64]) -> bool {
        false
    }
}

impl<F: FnMut(&[f64], &mut [f64])> System for F {
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        self(x, r)
    }
}

/// Options of the Broyden solver.
#[derive(Debug, Clone, PartialEq)]
pub struct BroydenOptions {
    /// Convergence when ‖F(x)‖₂ ≤ `tol`.
    pub tol: f64,
    /// Maximum number of (quasi-)Newton steps.
    pub max_iter: usize,
    /// Maximum step halvings in the backtracking line search.
    pub max_backtracks: usize,
    /// Allow refreshing `B` by the exact/finite-difference Jacobian on stalls.
    pub jacobian_refresh: bool,
    /// Maximum number of Jacobian refreshes in one solve.
    pub max_refreshes: usize,
    /// A step that reduces ‖F‖ by less than this factor counts as a stall
    /// (e.g. 0.9: less than 10 % reduction).
    pub stall_ratio: f64,
    /// Consecutive stalled steps before the Jacobian is refreshed.
    pub stall_iters: usize,
    /// Relative forward-difference step for the finite-difference Jacobian.
    pub fd_step: f64,
}

impl Default for BroydenOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            max_iter: 100,
            max_backtracks: 8,
            jacobian_refresh: true,
            max_refreshes: 5,
            stall_ratio: 0.9,
            stall_iters: 4,
            fd_step: 1e-7,
        }
    }
}

impl BroydenOptions {
    /// Same options with another tolerance.
    pub fn with_tol(mut self, tol: f64) -> Self {
        self.tol = tol;
        self
    }
    /// Same options with another iteration limit.
    pub fn with_max_iter(mut self, max_iter: usize) -> Self {
        self.max_iter = max_iter;
        self
    }
}

/// Statistics of a converged solve (`Default`: no work done, for orbits built
/// from given coefficients).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BroydenStats {
    /// Quasi-Newton steps taken.
    pub iterations: usize,
    /// Residual evaluations (including line search and finite differences).
    pub residual_evals: usize,
    /// Times the Jacobian was refreshed (exact or finite differences).
    pub jacobian_refreshes: usize,
    /// Final ‖F(x)‖₂.
    pub residual_norm: f64,
}

#[cfg(test)]
mod tests;
