//! The Broyden solve's error: why it failed, with the residual history.

use thiserror::Error;

/// Why a solve failed; every variant carries the residual-norm history.
///
/// Kept apart from [`crate::HbError`] (which nests it as `HbError::Solve` by
/// `#[from]`) because it is also a record, not only an error: a path that ends
/// because its step fell below the minimum keeps the last corrector failure in
/// [`crate::Termination::StepTooSmall`], and the Broyden and fold iterations
/// report it without a frequency or problem to attach.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum SolveError {
    /// The tolerance was not reached within `max_iter` steps or after the
    /// allowed Jacobian refreshes.
    #[error("no convergence after {iterations} iterations: ‖F‖ went {first:.3e} → {last:.3e}", first = history.first().copied().unwrap_or(f64::NAN), last = history.last().copied().unwrap_or(f64::NAN))]
    NonConvergence {
        /// Steps taken.
        iterations: usize,
        /// ‖F‖₂ after each accepted step (first entry: initial guess).
        history: Vec<f64>,
    },
    /// `F` returned NaN/inf at the initial guess, or the inputs were not finite.
    #[error("non-finite residual or input (iteration {iteration})")]
    NonFinite {
        /// Step at which it happened.
        iteration: usize,
        /// ‖F‖₂ history so far.
        history: Vec<f64>,
    },
    /// The (approximate) Jacobian became singular and could not be refreshed.
    #[error("singular Jacobian at iteration {iteration}")]
    SingularJacobian {
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
}

impl SolveError {
    /// The ‖F‖₂ history carried by the error (empty for [`SolveError::Dimension`]).
    pub fn history(&self) -> &[f64] {
        match self {
            Self::NonConvergence { history, .. }
            | Self::NonFinite { history, .. }
            | Self::SingularJacobian { history, .. } => history,
            Self::Dimension { .. } => &[],
        }
    }
}

impl SolveError {
    /// A failed [`ivt_num::newton()`] in this crate's terms (a line search
    /// without descent is a non-convergence), or the system's own error
    /// ([`ivt_num::NewtonError::Eval`]) as `Err`.
    ///
    /// # Errors
    /// The system's own error, unchanged.
    pub fn from_newton<E>(e: ivt_num::NewtonError<E>) -> Result<Self, E> {
        use ivt_num::NewtonError as N;
        Ok(match e {
            N::NonConvergence {
                iterations,
                history,
            }
            | N::NoDescent {
                iteration: iterations,
                history,
            } => Self::NonConvergence {
                iterations,
                history,
            },
            N::SingularJacobian { iteration, history } => {
                Self::SingularJacobian { iteration, history }
            }
            N::NonFinite { iteration, history } => Self::NonFinite { iteration, history },
            N::BorderSize {
                rows,
                values,
                unknowns,
            } => Self::Dimension {
                expected: values * unknowns,
                got: rows,
            },
            N::Eval(e) => return Err(e),
        })
    }
}

/// A failed [`ivt_num::newton()`] on an infallible system ([`SolveError::from_newton`]).
impl From<ivt_num::NewtonError<std::convert::Infallible>> for SolveError {
    fn from(e: ivt_num::NewtonError<std::convert::Infallible>) -> Self {
        Self::from_newton(e).unwrap_or_else(|never| match never {})
    }
}
