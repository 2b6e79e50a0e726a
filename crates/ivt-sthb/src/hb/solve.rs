//! The string's Newton–Raphson solve at fixed ω (step a6 of §3.3,
//! [`ivt_num::newton()`] on the STHB residual and exact Jacobian).

use super::StringHb;
use faer::Mat;
use ivt_hb::HbError;
use ivt_num::{newton, NewtonOptions, NewtonSystem, NewtonWorkspace, SolveError};
use std::convert::Infallible;

/// Newton–Raphson statistics of one converged solve.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveStats {
    /// Newton iterations (Jacobian factorizations).
    pub iterations: usize,
    /// Residual norm at each iteration, the last one converged.
    pub history: Vec<f64>,
}

impl StringHb {
    /// Newton–Raphson (step a6, [`ivt_num::newton()`]) with step halving on
    /// `‖R‖` (the full step is kept if no halving helps; the history shows
    /// it), from the guess in `a`, overwritten by the solution.
    /// Converged when `‖R‖ ≤ tol (1 + y0)`; [`Self::s_spectrum`] is then
    /// that of the solution.
    ///
    /// # Errors
    /// [`HbError::NoConvergence`] with the residual history after `max_iter`
    /// iterations, [`HbError::Singular`] or [`HbError::NonFinite`].
    pub fn solve(
        &mut self,
        omega: f64,
        a: &mut [f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<SolveStats, HbError> {
        let dim = self.dim();
        let opts = NewtonOptions {
            ftol: tol * (1.0 + self.p.y0.abs()),
            max_iter,
            max_halvings: 7,
            accept_no_descent: true,
            full_step_without_descent: true,
            ..NewtonOptions::default()
        };
        let mut ws = std::mem::replace(&mut self.newton, NewtonWorkspace::new(0));
        let mut jac = std::mem::replace(&mut self.jac, Mat::zeros(0, 0));
        if jac.nrows() != dim {
            jac = Mat::zeros(dim, dim);
        }
        let mut system = FixedOmega {
            hb: self,
            omega,
            jac: &mut jac,
        };
        let result = newton(&mut system, a, &mut ws, &opts);
        let history = ws.history().to_vec();
        self.newton = ws;
        self.jac = jac;
        match result {
            Ok(stats) => {
                // Leave Ŝ_p at the solution (the last residual was a trial's,
                // without it): the stability functions read it.
                self.balance(a, true);
                Ok(SolveStats {
                    iterations: stats.iterations,
                    history,
                })
            }
            Err(
                SolveError::SingularJacobian { .. }
                | SolveError::BorderSize { .. }
                | SolveError::Dimension { .. },
            ) => Err(HbError::Singular { omega }),
            Err(SolveError::NonFinite { .. }) => Err(HbError::NonFinite { omega }),
            Err(SolveError::NonConvergence { .. } | SolveError::NoDescent { .. }) => {
                Err(HbError::NoConvergence {
                    method: "Newton",
                    omega,
                    history,
                })
            }
            Err(SolveError::Eval(never)) => match never {},
        }
    }
}

/// The string's residual at fixed ω as a [`NewtonSystem`]: trial residuals
/// skip the Jacobian's spectrum; the Jacobian re-balances with it at the
/// accepted point (`J = J_lin − S_𝒯`, Eq. 115–125).
struct FixedOmega<'a> {
    hb: &'a mut StringHb,
    omega: f64,
    jac: &'a mut Mat<f64>,
}

impl NewtonSystem for FixedOmega<'_> {
    type Error = Infallible;

    fn residual(&mut self, a: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        self.hb.balance(a, false);
        self.hb.finish_residual(a, self.omega, r);
        Ok(())
    }

    fn jacobian(&mut self, a: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        self.hb.balance(a, true);
        self.hb.fill_jacobian(self.omega, self.jac);
        // `fill_jacobian` made `jac` `dim × dim`; `out` is row-major `dim × dim`.
        let dim = self.jac.ncols();
        for (i, row) in out
            .chunks_exact_mut(dim.max(1))
            .take(self.jac.nrows())
            .enumerate()
        {
            for (v, j) in row.iter_mut().zip(self.jac.row(i).iter()) {
                *v = *j;
            }
        }
        Ok(())
    }
}
