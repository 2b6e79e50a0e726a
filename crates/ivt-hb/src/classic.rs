//! Classic IHB (§3.2.1, Eq. 53–57): Newton's method with the exact Galerkin
//! Jacobian Φ_q, the nonlinear part integrated by quadrature on the 2N grid
//! (O(N·m²) per iteration plus an LU) — the baseline the modified IHB is timed
//! against (thesis: 0.25 s vs 0.003 s).

use crate::broyden::{BroydenStats, SolveError};
use crate::ihb::{validate_omega, GalerkinJacobian, HbError, HbOptions, HbResidual, HbSolution};
use crate::linalg::{lu_factor, lu_solve, matvec, norm2};
use crate::problem::PeriodicProblem;

/// Newton–Galerkin solver with reusable buffers.
#[derive(Debug)]
pub struct ClassicIhb<P> {
    problem: P,
    opts: HbOptions,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    jac: Vec<f64>,
    h0: Vec<f64>,
    piv: Vec<usize>,
    r: Vec<f64>,
    r_trial: Vec<f64>,
    q_trial: Vec<f64>,
    dq: Vec<f64>,
    history: Vec<f64>,
}

impl<P: PeriodicProblem> ClassicIhb<P> {
    /// Prepares the solver.
    ///
    /// # Errors
    /// As [`crate::ModifiedIhb::new`].
    pub fn new(problem: P, opts: HbOptions) -> Result<Self, HbError> {
        let res = HbResidual::new(&problem, &opts)?;
        let m = res.len();
        let galerkin = GalerkinJacobian::new(&res);
        Ok(Self {
            problem,
            opts,
            res,
            galerkin,
            jac: vec![0.0; m * m],
            h0: vec![0.0; m * m],
            piv: vec![0; m],
            r: vec![0.0; m],
            r_trial: vec![0.0; m],
            q_trial: vec![0.0; m],
            dq: vec![0.0; m],
            history: Vec::with_capacity(64),
        })
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// Solves by Newton from the linear solution or from `guess`.
    ///
    /// # Errors
    /// [`HbError::Solve`] with the residual history when Newton fails.
    pub fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError> {
        validate_omega(omega_f)?;
        let m = self.res.len();
        let omega = omega_f / self.opts.subharmonic as f64;
        let mut q = vec![0.0; m];
        match guess {
            Some(g) if g.len() == m && g.iter().all(|v| v.is_finite()) => q.copy_from_slice(g),
            Some(_) => {
                return Err(HbError::InvalidInput(format!(
                    "guess must have {m} finite entries"
                )))
            }
            None => {
                if self
                    .res
                    .linear_jacobian(&self.problem, omega, &mut self.jac, &mut self.h0)
                {
                    matvec(&self.h0, m, m, self.res.excitation(), &mut q);
                }
            }
        }
        self.history.clear();
        let scale = self
            .res
            .force_scale(&self.problem, &q, omega, &mut self.r_trial);
        let tol = self.opts.residual_tol(scale);
        self.res.eval(&self.problem, &q, omega_f, 1.0, &mut self.r);
        let mut norm = norm2(&self.r);
        self.history.push(norm);
        let mut stats = BroydenStats {
            iterations: 0,
            residual_evals: 1,
            jacobian_refreshes: 0,
            residual_norm: norm,
        };
        let fail = |h: &Vec<f64>, it| {
            HbError::Solve(SolveError::NonConvergence {
                iterations: it,
                history: h.clone(),
            })
        };
        if !norm.is_finite() {
            return Err(HbError::Solve(SolveError::NonFinite {
                iteration: 0,
                history: self.history.clone(),
            }));
        }
        while norm > tol {
            if stats.iterations >= self.opts.broyden.max_iter {
                return Err(fail(&self.history, stats.iterations));
            }
            stats.iterations += 1;
            // Φ_q = L(ω) + (1/π)∫ C_s (G_x C_sᵀ + ω G_v C_s'ᵀ) dτ (Eq. 56).
            self.galerkin.assemble(
                &mut self.res,
                &self.problem,
                &q,
                omega_f,
                1.0,
                &mut self.jac,
            );
            stats.jacobian_refreshes += 1;
            if lu_factor(&mut self.jac, m, &mut self.piv).is_err() {
                return Err(HbError::Solve(SolveError::SingularJacobian {
                    iteration: stats.iterations,
                    history: self.history.clone(),
                }));
            }
            self.dq.iter_mut().zip(&self.r).for_each(|(d, r)| *d = -r);
            lu_solve(&self.jac, m, &self.piv, &mut self.dq);
            // Newton step (Eq. 57) with step halving if ‖r‖ grows.
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..=self.opts.broyden.max_backtracks {
                for i in 0..m {
                    self.q_trial[i] = q[i] + t * self.dq[i];
                }
                self.res.eval(
                    &self.problem,
                    &self.q_trial,
                    omega_f,
                    1.0,
                    &mut self.r_trial,
                );
                stats.residual_evals += 1;
                let nt = norm2(&self.r_trial);
                if nt.is_finite() && nt < norm {
                    norm = nt;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                return Err(fail(&self.history, stats.iterations));
            }
            q.copy_from_slice(&self.q_trial);
            std::mem::swap(&mut self.r, &mut self.r_trial);
            self.history.push(norm);
        }
        stats.residual_norm = norm;
        Ok(HbSolution {
            coeffs: q,
            omega_f,
            harmonics: self.opts.harmonics,
            subharmonic: self.opts.subharmonic,
            stats,
        })
    }
}

impl<P: PeriodicProblem> crate::ihb::HbSolver for ClassicIhb<P> {
    fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError> {
        ClassicIhb::solve(self, omega_f, guess)
    }
    fn options(&self) -> &HbOptions {
        &self.opts
    }
}
