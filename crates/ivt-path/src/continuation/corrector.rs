//! The corrector of a continuation step: from the prediction back onto the
//! branch, closing `R(u, λ) = 0` by the arclength constraint (Eq. 72) or,
//! landing on a bound, by `λ = bound`. One trait, [`PathCorrector`], one
//! file per method: Broyden on the secant model (`broyden.rs`, Eq. 68–77),
//! chord iterations on the tangent's factorization (`chord.rs`) and Newton on
//! the exact bordered Jacobian (`newton.rs`, the chord's fallback).

use std::borrow::Cow;

use crate::branch::Branch;
use crate::error::PathError;
use ivt_num::SolveError;

mod broyden;
mod newton;
pub use broyden::BroydenCorrector;
pub use newton::NewtonCorrector;

/// One step's prediction and the constraint that closes the corrector's
/// system.
#[derive(Debug, Clone, Copy)]
pub struct Prediction<'a> {
    /// The last point on the path (`u` then λ).
    pub x_prev: &'a [f64],
    /// The unit direction at it (secant or tangent): the constraint's gradient.
    pub direction: &'a [f64],
    /// The predicted point.
    pub u_pred: &'a [f64],
    /// The arclength step Δη.
    pub step: f64,
    /// Correct on `λ = fix` (landing on a bound) instead of the arclength
    /// constraint.
    pub fix: Option<f64>,
}

impl Prediction<'_> {
    /// The constraint's gradient: the direction (borrowed, no copy per
    /// point), or `e_{m+1}` on `λ = fix`.
    pub fn row(&self) -> Cow<'_, [f64]> {
        match self.fix {
            Some(_) => {
                let mut row = vec![0.0; self.direction.len()];
                if let Some(last) = row.last_mut() {
                    *last = 1.0;
                }
                Cow::Owned(row)
            }
            None => Cow::Borrowed(self.direction),
        }
    }

    /// The constraint `dᵀ(u − u_pred)`, or `λ − λ_fix`. Evaluated as a
    /// difference of points, not as `dᵀu − dᵀu_pred`, which would lose its
    /// last digits to cancellation when λ is large.
    pub fn constraint(&self, u: &[f64]) -> f64 {
        match self.fix {
            Some(l) => u.last().map_or(f64::NAN, |v| v - l),
            None => self
                .direction
                .iter()
                .zip(u.iter().zip(self.u_pred))
                .map(|(t, (a, b))| t * (a - b))
                .sum(),
        }
    }
}

/// A converged correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Corrected {
    /// Iterations reported with the point ([`super::PathPoint::iterations`]).
    pub iterations: usize,
    /// The effort the step rule reads (a Newton iteration counts as two
    /// chord iterations).
    pub effort: usize,
}

/// The outcome of [`PathCorrector::correct`].
pub type Correction = Result<Corrected, SolveError>;

/// The outcome of [`PathCorrector::direction`].
pub type Found = Result<(), DirectionError>;

/// Why the direction at an accepted point is not available.
#[derive(Debug, Clone, PartialEq)]
pub enum DirectionError {
    /// The corrector went backwards along the path: the step is redone
    /// shorter, and the error ends the path if it cannot be.
    Backwards(SolveError),
    /// The bordered matrix of the tangent is singular: the path ends.
    Singular,
}

/// Why a step is redone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Retry {
    /// The corrector failed: the step is halved.
    Failed,
    /// The point was rejected (outside the interval, backwards, or too far
    /// from the prediction): the step is redone without the corrector's
    /// state of the rejected attempt.
    Rejected,
    /// The direction at the point turned too much
    /// ([`super::ContinuationOptions::max_turn`]): as [`Retry::Rejected`],
    /// after [`PathCorrector::direction`] ran at the rejected point.
    Turned,
}

/// A corrector of the continuation stepper ([`super::Stepper`]): the start's
/// direction, the correction of each prediction, and the direction at each
/// accepted point.
pub trait PathCorrector<B: Branch> {
    /// Prepares the path at its start `x` (`u` then λ; a corrector that needs
    /// a converged start corrects it here at fixed λ) and writes the unit
    /// direction there into `dir`, whose λ component gives its sign on entry.
    ///
    /// # Errors
    /// [`PathError::ContinuationStart`] if the start cannot be converged,
    /// [`PathError::SingularStart`] if it has no tangent.
    fn start(&mut self, branch: &mut B, x: &mut [f64], dir: &mut [f64]) -> Result<(), PathError>;

    /// Corrects the prediction `pred` into `x` (`u` then λ).
    ///
    /// # Errors
    /// The corrector's failure (the step is then halved).
    fn correct(&mut self, branch: &mut B, pred: &Prediction<'_>, x: &mut [f64]) -> Correction;

    /// The unit direction at the accepted point `x` (reached from `x_prev`)
    /// into `dir`, which holds the previous direction on entry.
    ///
    /// # Errors
    /// [`DirectionError`].
    fn direction(&mut self, branch: &mut B, x_prev: &[f64], x: &[f64], dir: &mut [f64]) -> Found;

    /// The step from `x_prev` is redone ([`Retry`]).
    fn retry(&mut self, branch: &mut B, x_prev: &[f64], why: Retry);

    /// The sign of `det [[R_q, R_λ], [tᵀ]]` at the last accepted point when
    /// the corrector factored that matrix ([`super::PathPoint::bordered_sign`]).
    fn bordered_sign(&self) -> Option<f64> {
        None
    }

    /// The effort ([`Corrected::effort`]) from which the step rule shrinks
    /// the step: above `target_iter` (Broyden's many cheap iterations).
    fn shrink_at(&self, target_iter: usize) -> usize {
        target_iter + 1
    }

    /// Whether the predictor adds the curvature term
    /// ([`super::ContinuationOptions::second_order_predictor`]).
    fn second_order(&self) -> bool {
        false
    }
}
