//! The start of an exact-Jacobian path: Newton at fixed λ.

use faer::Mat;
use ivt_num::LuWorkspace;

use super::{ContinuationOptions, PathSystem, SolveError};
use crate::error::HbError;

/// Newton on `R(u, λ) = 0` at the λ of `x` (`u` then λ, corrected in place) to
/// `opts.broyden.tol` within `opts.broyden.max_iter` steps, for any
/// [`PathSystem`] (the first point of [`super::pseudo_arclength_exact`] must
/// be converged). The Jacobian is assembled only when the residual misses the
/// tolerance. Returns the steps taken.
///
/// # Errors
/// [`HbError::ContinuationStart`] with the residual history when Newton does
/// not converge; [`HbError::SingularStart`] for a singular Jacobian.
pub fn correct_at_fixed_lambda<S: PathSystem>(
    system: &mut S,
    x: &mut [f64],
    opts: &ContinuationOptions,
) -> Result<usize, HbError> {
    let m = system.dim();
    let lambda = x[m];
    let mut r = vec![0.0; m];
    let mut jac = Mat::zeros(m, m);
    let mut lu = LuWorkspace::new(m);
    let mut history = Vec::new();
    loop {
        let it = history.len();
        system.residual(&x[..m], lambda, &mut r);
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        history.push(norm);
        if norm <= opts.broyden.tol {
            return Ok(it);
        }
        if !norm.is_finite() || it == opts.broyden.max_iter {
            return Err(HbError::ContinuationStart {
                lambda,
                cause: SolveError::NonConvergence {
                    iterations: it,
                    history,
                },
            });
        }
        system.residual_jacobian(&x[..m], lambda, &mut r, &mut jac);
        lu.mat.copy_from(&jac);
        if !lu.factor() {
            return Err(HbError::SingularStart { lambda });
        }
        lu.solve(&mut r);
        for (u, d) in x.iter_mut().zip(&r) {
            *u -= d;
        }
    }
}
