//! The crate's error type. The outcome of a failed solve ([`SolveError`])
//! and the path engine's errors ([`PathError`]) nest in it by `#[from]`, so
//! a failed path or solve keeps its residual history.

use ivt_num::SolveError;
use ivt_path::PathError;
use thiserror::Error;

/// Errors of the harmonic-balance engine, its AFT, Hill's method and STHB.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum HbError {
    /// Invalid sizes or parameters.
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// An array does not have the size the problem asks for.
    #[error("invalid input: {what} has {got} entries, expected {expected}")]
    Size {
        /// Which array.
        what: &'static str,
        /// The entries it must hold.
        expected: usize,
        /// The entries it holds.
        got: usize,
    },
    /// Eq. 62 needs `N > n` (2N samples resolve harmonics below N without
    /// aliasing of the linear terms).
    #[error("AFT needs N > n (got N = {n_half}, n = {harmonics})")]
    AftTooFewSamples {
        /// Harmonics n.
        harmonics: usize,
        /// Half the number of samples, N.
        n_half: usize,
    },
    /// More than [`crate::limits::MAX_SAMPLES`] AFT samples (2N ≤ 2^22: 32 MiB
    /// per buffer).
    #[error("AFT needs 2N ≤ 2^22 samples (got N = {n_half})")]
    AftTooManySamples {
        /// Half the number of samples, N.
        n_half: usize,
    },
    /// The iteration did not converge (carries the residual history).
    #[error("harmonic balance did not converge: {0}; ‖r‖ history {history:?}", history = .0.history())]
    Solve(#[from] SolveError),
    /// A limit-cycle iteration collapsed onto the equilibrium `x = 0`.
    #[error("the iteration collapsed onto the equilibrium x = 0 (no limit cycle near the guess)")]
    Equilibrium,
    /// A failure of the path engine (a path that cannot start, a locator
    /// that cannot converge, sizes), with its residual history.
    #[error(transparent)]
    Path(#[from] PathError),
    /// A Newton iteration at a fixed frequency did not reach the tolerance.
    #[error("{method} did not converge at omega = {omega}: residual norms {history:?}")]
    NoConvergence {
        /// Which solver.
        method: &'static str,
        /// Excitation frequency.
        omega: f64,
        /// Residual norm at each iteration.
        history: Vec<f64>,
    },
    /// The Jacobian at a fixed frequency is singular.
    #[error("singular Jacobian at omega = {omega:?}")]
    Singular {
        /// Excitation frequency.
        omega: f64,
    },
    /// The residual at a fixed frequency became NaN or infinite.
    #[error("non-finite residual at omega = {omega:?}")]
    NonFinite {
        /// Excitation frequency.
        omega: f64,
    },
    /// A path could not step on (step below its minimum).
    #[error("continuation stalled at omega = {omega} (step {step:e}): {cause}")]
    Stalled {
        /// Last converged frequency.
        omega: f64,
        /// Step length at the failure.
        step: f64,
        /// The last corrector failure.
        cause: Box<HbError>,
    },
    /// A curve's first point, solved from rest (a = 0), did not converge: near a
    /// resonance the start lies outside Newton's basin.
    #[error("the curve starts from rest at omega = {omega:?} and that solve failed ({cause}); start below the resonance (e.g. at half its frequency) and continue through it")]
    ColdStart {
        /// Start frequency.
        omega: f64,
        /// The start solve's failure (with its residual history).
        cause: Box<HbError>,
    },
    /// A transient integration (limit cycle from a state) ended without
    /// settling onto a periodic attractor.
    #[error(
        "the transient from the given state did not reach a limit cycle (t = {time:?}): {reason}"
    )]
    Transient {
        /// Time integrated.
        time: f64,
        /// What stopped it.
        reason: &'static str,
    },
    /// An eigenvalue computation (Hill matrix, monodromy matrix) failed.
    #[error("eigenvalue computation failed: {0}")]
    Eigen(String),
    /// Hsu's monodromy matrix of a converged orbit has non-finite multipliers,
    /// so its stability is unknown (e.g. ω_f so small that one period spans
    /// far more time than the steps resolve).
    #[error(
        "the Floquet multipliers at ω_f = {omega:?} are not finite (Hsu's method over at most \
         {steps} steps of one period 2π/ω_f); the stability of this solution is unknown"
    )]
    NonFiniteMultipliers {
        /// Excitation frequency.
        omega: f64,
        /// Hsu sub-intervals of the period (the cap, for adaptive Hsu).
        steps: usize,
    },
    /// The caller cancelled the computation ([`ivt_num::cancel`]).
    #[error("{}", ivt_num::cancel::CANCELLED)]
    Interrupted,
}

impl HbError {
    /// A stable snake_case word for the class of the error, the `kind` of the
    /// CLI's `{"error", "kind"}` object (SPEC §6) and the Python exception
    /// (`ValueError` for `"input"`, `ivt.hb.ConvergenceError` for
    /// `"failed"`): `"input"` when the arguments are invalid (sizes,
    /// parameters, the AFT's sample count), `"failed"` when a solve, a path,
    /// a stability or eigenvalue computation failed on valid arguments.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::InvalidInput(_)
            | Self::Size { .. }
            | Self::AftTooFewSamples { .. }
            | Self::AftTooManySamples { .. } => "input",
            Self::Path(e) => e.kind(),
            Self::Solve(_)
            | Self::Equilibrium
            | Self::NoConvergence { .. }
            | Self::Singular { .. }
            | Self::NonFinite { .. }
            | Self::Stalled { .. }
            | Self::ColdStart { .. }
            | Self::Eigen(_)
            | Self::Transient { .. }
            | Self::NonFiniteMultipliers { .. }
            | Self::Interrupted => "failed",
        }
    }

    /// The residual norm per iteration of a failed Broyden or Newton solve
    /// (empty for the other errors).
    pub fn history(&self) -> &[f64] {
        match self {
            Self::Solve(s) => s.history(),
            Self::Path(e) => e.history(),
            Self::NoConvergence { history, .. } => history,
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_split_bad_arguments_from_failed_computations() {
        let input = HbError::AftTooFewSamples {
            harmonics: 20,
            n_half: 10,
        };
        assert_eq!(input.kind(), "input");
        assert_eq!(HbError::InvalidInput("n".into()).kind(), "input");
        let failed = HbError::NoConvergence {
            method: "classic IHB",
            omega: 1.0,
            history: vec![1.0, 0.5],
        };
        assert_eq!(failed.kind(), "failed");
        assert_eq!(failed.history(), [1.0, 0.5]);
        assert_eq!(HbError::Equilibrium.kind(), "failed");
        assert!(HbError::Equilibrium.history().is_empty());
    }
}
