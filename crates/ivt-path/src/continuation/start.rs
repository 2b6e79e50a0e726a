//! The start of an exact-Jacobian path: Newton at fixed λ ([`ivt_num::newton()`]).

use crate::branch::{full_newton_steps, Branch};
use ivt_num::{newton, NewtonSystem, NewtonWorkspace, SolveError};
use std::convert::Infallible;

use super::ContinuationOptions;
use crate::error::PathError;

/// A [`Branch`] at fixed λ as a square [`NewtonSystem`] in `u`.
struct FixedLambda<'a, S> {
    system: &'a mut S,
    lambda: f64,
}

impl<S: Branch> NewtonSystem for FixedLambda<'_, S> {
    type Error = Infallible;

    fn residual(&mut self, u: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        self.system.residual(u, self.lambda, r);
        Ok(())
    }

    fn jacobian(&mut self, u: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        self.system.jacobian(u, self.lambda, jac);
        Ok(())
    }
}

/// Newton on `R(u, λ) = 0` at the λ of `x` (`u` then λ, corrected in place) to
/// `opts.broyden.tol` within `opts.broyden.max_iter` steps, for any
/// [`Branch`] (the start of a [`super::NewtonCorrector`] path must
/// be converged). The Jacobian is assembled only when the residual misses the
/// tolerance; every step is taken in full (no line search: the start is a
/// converged orbit of another method, already close). Returns the steps taken.
///
/// # Errors
/// [`PathError::ContinuationStart`] with the residual history when Newton does
/// not converge; [`PathError::SingularStart`] for a singular Jacobian;
/// [`PathError::InvalidInput`] when `x` has not `m + 1` entries.
pub fn correct_at_fixed_lambda<S: Branch>(
    system: &mut S,
    x: &mut [f64],
    opts: &ContinuationOptions,
) -> Result<usize, PathError> {
    let m = system.len();
    let Some((&mut lambda, u)) = x.split_last_mut().filter(|(_, u)| u.len() == m) else {
        return Err(PathError::InvalidInput(
            "continuation start must hold m unknowns and λ".into(),
        ));
    };
    let mut fixed = FixedLambda { system, lambda };
    let nopts = full_newton_steps(opts.broyden.tol, opts.broyden.max_iter);
    match newton(&mut fixed, u, &mut NewtonWorkspace::new(m), &nopts) {
        Ok(stats) => Ok(stats.iterations),
        Err(SolveError::SingularJacobian { .. }) => Err(PathError::SingularStart { lambda }),
        Err(e) => Err(PathError::ContinuationStart { lambda, cause: e }),
    }
}
