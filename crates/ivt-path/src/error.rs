//! The crate's error type. A failed solve ([`SolveError`], with its residual
//! history) nests in it by `#[from]`; ivt-hb's `HbError` nests this one the
//! same way.

use ivt_num::SolveError;
use thiserror::Error;

/// Errors of the path engine: a path that cannot start, a locator that
/// cannot converge, arguments of the wrong size.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum PathError {
    /// Invalid sizes or parameters.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// An iteration (a locator's extended system, a start) did not converge
    /// (carries the residual history).
    #[error("the iteration did not converge: {0}; ‖r‖ history {history:?}", history = .0.history())]
    Solve(#[from] SolveError),
    /// A path's first point did not converge at its fixed parameter.
    #[error("continuation start at λ = {lambda:?} does not converge: {cause}")]
    ContinuationStart {
        /// Path parameter of the start.
        lambda: f64,
        /// The corrector's failure (with its residual history).
        cause: SolveError,
    },
    /// A path has no tangent at its start (singular `∂R/∂u` there).
    #[error("continuation start at λ = {lambda:?}: singular Jacobian, no tangent")]
    SingularStart {
        /// Path parameter of the start.
        lambda: f64,
    },
}

impl PathError {
    /// A stable snake_case word for the class of the error: `"input"` when
    /// the arguments are invalid, `"failed"` when a computation failed on
    /// valid ones (the `kind` of the CLI's `{"error", "kind"}` object).
    pub fn kind(&self) -> &'static str {
        match self {
            Self::InvalidInput(_) => "input",
            Self::Solve(_) | Self::ContinuationStart { .. } | Self::SingularStart { .. } => {
                "failed"
            }
        }
    }

    /// The residual norm per iteration of a failed solve (empty for the
    /// other errors).
    pub fn history(&self) -> &[f64] {
        match self {
            Self::Solve(s) | Self::ContinuationStart { cause: s, .. } => s.history(),
            Self::InvalidInput(_) | Self::SingularStart { .. } => &[],
        }
    }
}
