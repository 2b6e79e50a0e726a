//! The path of a system given by its residual alone ([`ResidualBranch`]: a
//! subproblem assembled by the caller, e.g. an extended or phase-conditioned
//! system), followed by the one [`Stepper`] with the thesis's Broyden
//! corrector (Eq. 72–77, [`BroydenCorrector`]).

use super::{BroydenCorrector, ContinuationOptions, Path, PathPoint, Stepper};
use crate::branch::ResidualBranch;
use crate::error::PathError;

/// Follows `residual(x, r)` (`x = (u, λ)`, `start.len() = m + 1` entries,
/// `r` of `m`) from `start` in the direction of increasing λ if
/// `direction > 0`, with the Broyden corrector (`jac0`: an optional row-major
/// `m×(m+1)` Jacobian estimate at the start, otherwise forward differences),
/// handing each point to `on_point` until it returns `false`
/// ([`Stepper::run`]).
///
/// # Errors
/// As [`Stepper::new`]: a start of the wrong size or non-finite entries or
/// steps, or a start the corrector cannot converge.
pub fn follow_residual<F: FnMut(&[f64], &mut [f64])>(
    residual: F,
    start: &[f64],
    jac0: Option<&[f64]>,
    direction: f64,
    opts: &ContinuationOptions,
    mut on_point: impl FnMut(&PathPoint) -> bool,
) -> Result<Path, PathError> {
    let m = start.len().saturating_sub(1);
    let mut branch = ResidualBranch::new(m, residual);
    let corrector = Box::new(BroydenCorrector::new(m, &opts.broyden, jac0));
    let mut stepper = Stepper::new(&mut branch, corrector, start, 0, direction, opts)?;
    Ok(stepper.run(|_, p| on_point(p)))
}
