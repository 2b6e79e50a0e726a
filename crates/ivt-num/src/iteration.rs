//! The iteration core of every nonlinear solver of the workspace, after
//! argmin's `Solver::next_iter` and `Executor`: a [`Solver`] knows how to
//! evaluate its start and take one step from the current iterate; the
//! executor ([`execute`]) owns the loop — the ‖F‖₂ history, the iteration
//! count, the residual test `‖F‖₂ ≤ ftol` and the limit `max_iter` ([`Stopping`])
//! — and every failure is the one error type [`SolveError`], carrying that
//! history.
//!
//! Its solvers: damped Newton ([`crate::newton()`], [`crate::newton_bordered`]),
//! Broyden ([`crate::broyden_solve`]), the chord iteration on a given
//! factorization ([`crate::chord()`]) and deflated Newton
//! ([`crate::deflated_newton`]). Stopping is not failing: a converged solve
//! returns its iteration count, a verdict of the solver's own (a step test,
//! a divergence rule) is a [`StepCheck`].

use std::convert::Infallible;
use thiserror::Error;

/// Why a solve failed; the iteration variants carry the `‖F‖₂` history
/// (first entry: the initial guess; one per accepted step). `E` is the
/// system's own evaluation error ([`SolveError::Eval`]); the solvers of an
/// infallible system (Broyden's [`crate::System`]) fail with
/// `SolveError` (`E = Infallible`).
#[derive(Debug, Clone, Error, PartialEq)]
pub enum SolveError<E = Infallible> {
    /// The tolerance was not reached within `max_iter` steps, after the
    /// allowed Jacobian refreshes, or the solver's own rule declared the
    /// iteration diverging.
    #[error("no convergence after {iterations} iterations: ‖F‖ went {first:.3e} → {last:.3e}", first = history.first().copied().unwrap_or(f64::NAN), last = history.last().copied().unwrap_or(f64::NAN))]
    NonConvergence {
        /// Steps taken.
        iterations: usize,
        /// ‖F‖₂ history.
        history: Vec<f64>,
    },
    /// No step length in Newton's line search reduced `‖F‖₂`.
    #[error("no descent along the Newton step at step {iteration}")]
    NoDescent {
        /// Step at which it happened.
        iteration: usize,
        /// ‖F‖₂ history.
        history: Vec<f64>,
    },
    /// The (approximate) Jacobian is numerically singular and could not be
    /// refreshed, or the step is not finite.
    #[error("singular Jacobian at iteration {iteration}")]
    SingularJacobian {
        /// Step at which it happened.
        iteration: usize,
        /// ‖F‖₂ history so far.
        history: Vec<f64>,
    },
    /// A non-finite start, residual or step.
    #[error("non-finite residual or input (iteration {iteration})")]
    NonFinite {
        /// Step at which it happened.
        iteration: usize,
        /// ‖F‖₂ history so far.
        history: Vec<f64>,
    },
    /// Workspace and vector sizes disagree.
    #[error("dimension mismatch: workspace for {expected} unknowns, got {got}")]
    Dimension {
        /// Workspace size.
        expected: usize,
        /// Length of the given vector.
        got: usize,
    },
    /// The border rows, their right-hand side and the unknowns disagree in
    /// size (`rows` must be `k × n`, `values` `k`, `k ≤ n`).
    #[error("border of {rows} entries and {values} values does not fit {unknowns} unknowns")]
    BorderSize {
        /// Entries of the border rows.
        rows: usize,
        /// Entries of the right-hand side.
        values: usize,
        /// Unknowns `n`.
        unknowns: usize,
    },
    /// The system's evaluation failed.
    #[error("evaluation failed")]
    Eval(E),
}

impl<E> SolveError<E> {
    /// The ‖F‖₂ history carried by the error (empty for the size errors and
    /// [`SolveError::Eval`]).
    pub fn history(&self) -> &[f64] {
        match self {
            Self::NonConvergence { history, .. }
            | Self::NoDescent { history, .. }
            | Self::SingularJacobian { history, .. }
            | Self::NonFinite { history, .. } => history,
            Self::Dimension { .. } | Self::BorderSize { .. } | Self::Eval(_) => &[],
        }
    }

    /// The error of an infallible system, or the system's own error
    /// ([`SolveError::Eval`]) as `Err`.
    ///
    /// # Errors
    /// The system's own error, unchanged.
    pub fn infallible(self) -> Result<SolveError, E> {
        Ok(match self {
            Self::NonConvergence {
                iterations,
                history,
            } => SolveError::NonConvergence {
                iterations,
                history,
            },
            Self::NoDescent { iteration, history } => SolveError::NoDescent { iteration, history },
            Self::SingularJacobian { iteration, history } => {
                SolveError::SingularJacobian { iteration, history }
            }
            Self::NonFinite { iteration, history } => SolveError::NonFinite { iteration, history },
            Self::Dimension { expected, got } => SolveError::Dimension { expected, got },
            Self::BorderSize {
                rows,
                values,
                unknowns,
            } => SolveError::BorderSize {
                rows,
                values,
                unknowns,
            },
            Self::Eval(e) => return Err(e),
        })
    }
}

/// The solver's verdict on an accepted step ([`Solver::check`],
/// [`crate::NewtonSystem::check_step`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepCheck {
    /// Iterate on.
    Continue,
    /// Stop: the point is the solution.
    Converged,
    /// Stop: the iteration diverges ([`SolveError::NonConvergence`]).
    Diverged,
}

/// The executor's stopping rule: converged at `‖F‖₂ ≤ ftol`, failed after
/// `max_iter` steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stopping {
    /// Residual tolerance.
    pub ftol: f64,
    /// Most steps.
    pub max_iter: usize,
}

/// What a solver sees of the run: the step it takes (1 for the first) and
/// the ‖F‖₂ history so far (its last entry at the current iterate).
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    /// The step being taken (or just taken, in [`Solver::check`]).
    pub iteration: usize,
    /// ‖F‖₂ at the start and after each accepted step.
    pub history: &'a [f64],
}

impl Progress<'_> {
    /// ‖F‖₂ at the current iterate.
    pub fn norm(&self) -> f64 {
        self.history.last().copied().unwrap_or(f64::NAN)
    }

    /// [`SolveError::NonConvergence`] at this step with the history.
    pub fn non_convergence<E>(&self) -> SolveError<E> {
        SolveError::NonConvergence {
            iterations: self.iteration,
            history: self.history.to_vec(),
        }
    }

    /// [`SolveError::SingularJacobian`] at this step with the history.
    pub fn singular<E>(&self) -> SolveError<E> {
        SolveError::SingularJacobian {
            iteration: self.iteration,
            history: self.history.to_vec(),
        }
    }

    /// [`SolveError::NonFinite`] at this step with the history.
    pub fn non_finite<E>(&self) -> SolveError<E> {
        SolveError::NonFinite {
            iteration: self.iteration,
            history: self.history.to_vec(),
        }
    }
}

/// The outcome of one [`Solver::next_iter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// The iterate moved; `norm` is ‖F‖₂ there. `converged`: the solver's
    /// own test (e.g. Newton's small step) says it is the solution.
    Moved {
        /// ‖F‖₂ at the new iterate.
        norm: f64,
        /// The solver stops here whatever `ftol` says.
        converged: bool,
    },
    /// The iterate did not move, the solver's state did (e.g. Broyden's
    /// refreshed Jacobian after a failed line search): the step counts, no
    /// history entry is added.
    Restarted,
}

/// One iterative method for `F(x) = 0` (argmin's `Solver`): the executor
/// ([`execute`]) calls [`Solver::start`] once, [`Solver::init`] once the
/// start is recorded and finite, then [`Solver::next_iter`] until
/// `‖F‖₂ ≤ ftol`, [`Step::Moved`] with `converged`, or a verdict of
/// [`Solver::check`] ends the run.
pub trait Solver {
    /// The system's evaluation error.
    type Error;

    /// Evaluates `F` at the start `x`; returns `‖F(x)‖₂`.
    ///
    /// # Errors
    /// A start that cannot be evaluated (not finite, the wrong size, the
    /// system's error).
    fn start(&mut self, x: &mut [f64]) -> Result<f64, SolveError<Self::Error>>;

    /// Prepares the first step once the start is recorded and finite (e.g.
    /// Broyden's first Jacobian). Default: nothing.
    ///
    /// # Errors
    /// As [`Solver::next_iter`].
    fn init(&mut self, _x: &[f64], _at: Progress<'_>) -> Result<(), SolveError<Self::Error>> {
        Ok(())
    }

    /// One step from `x` (updated in place).
    ///
    /// # Errors
    /// The method's failure at this step (with `at`'s history).
    fn next_iter(
        &mut self,
        x: &mut [f64],
        at: Progress<'_>,
    ) -> Result<Step, SolveError<Self::Error>>;

    /// The verdict on the step just taken, asked when it left
    /// `‖F‖₂ > ftol` (`at.history` ends with ‖F‖₂ at `x`). Default:
    /// [`StepCheck::Continue`].
    ///
    /// # Errors
    /// The method's failure at this step.
    fn check(
        &mut self,
        _x: &[f64],
        _at: Progress<'_>,
    ) -> Result<StepCheck, SolveError<Self::Error>> {
        Ok(StepCheck::Continue)
    }
}

/// The run at step `iteration` with `history`.
fn at(iteration: usize, history: &[f64]) -> Progress<'_> {
    Progress { iteration, history }
}

/// Runs `solver` from `x` (overwritten by the last iterate) under
/// `stopping`, recording ‖F‖₂ in `history` (cleared first; its capacity is
/// reused). Returns the steps taken.
///
/// # Errors
/// The solver's errors; [`SolveError::NonFinite`] for a non-finite ‖F‖₂;
/// [`SolveError::NonConvergence`] after `max_iter` steps or on a
/// [`StepCheck::Diverged`] verdict.
pub fn execute<S: Solver + ?Sized>(
    solver: &mut S,
    x: &mut [f64],
    stopping: Stopping,
    history: &mut Vec<f64>,
) -> Result<usize, SolveError<S::Error>> {
    history.clear();
    let start = solver.start(x)?;
    history.push(start);
    let mut norm = start;
    if !norm.is_finite() {
        return Err(at(0, history).non_finite());
    }
    solver.init(x, at(0, history))?;
    let mut iterations = 0;
    loop {
        if norm <= stopping.ftol {
            return Ok(iterations);
        }
        if iterations >= stopping.max_iter {
            return Err(at(iterations, history).non_convergence());
        }
        iterations += 1;
        let Step::Moved {
            norm: next,
            converged,
        } = solver.next_iter(x, at(iterations, history))?
        else {
            continue;
        };
        norm = next;
        history.push(norm);
        if !norm.is_finite() {
            return Err(at(iterations, history).non_finite());
        }
        if converged {
            return Ok(iterations);
        }
        if norm > stopping.ftol {
            match solver.check(x, at(iterations, history))? {
                StepCheck::Continue => {}
                StepCheck::Converged => return Ok(iterations),
                StepCheck::Diverged => return Err(at(iterations, history).non_convergence()),
            }
        }
    }
}
