//! Classic IHB (§3.2.1, Eq. 53–57): damped Newton with the exact Galerkin
//! Jacobian Φ_q, the nonlinear part summed on the 2N grid by FFT
//! ([`crate::orbit::galerkin`]; plus an LU per iteration) — the baseline the modified IHB is timed
//! against (thesis: 0.25 s vs 0.003 s).

use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{validate_omega, HbError, HbOptions, HbResidual, HbSolution};
use crate::problem::PeriodicProblem;
use ivt_num::{newton, BlockDiagonal, BroydenStats, NewtonOptions, NewtonSystem, NewtonWorkspace};
use std::convert::Infallible;

/// Newton–Galerkin solver with reusable buffers.
#[derive(Debug)]
pub struct ClassicIhb<P> {
    problem: P,
    opts: HbOptions,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    /// `H₀`, the inverse of the linear Jacobian Eq. 60, by blocks.
    h0: BlockDiagonal,
    /// Scratch for the force scale of the tolerance.
    scratch: Vec<f64>,
    newton: NewtonWorkspace,
}

/// The HB residual (Eq. 61) at fixed ω_f with its Galerkin Jacobian Φ_q
/// (Eq. 56) as a Newton system (also the deflated search's, analyses/deflation.rs).
pub(crate) struct Galerkin<'a, P> {
    pub(crate) problem: &'a P,
    pub(crate) res: &'a mut HbResidual,
    pub(crate) galerkin: &'a mut GalerkinJacobian,
    pub(crate) omega_f: f64,
}

impl<P: PeriodicProblem> NewtonSystem for Galerkin<'_, P> {
    type Error = Infallible;
    fn residual(&mut self, q: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        self.res.eval(self.problem, q, self.omega_f, 1.0, r);
        Ok(())
    }
    /// Φ_q = L(ω) + (1/π)∫ C_s (G_x C_sᵀ + ω G_v C_s'ᵀ) dτ (Eq. 56).
    fn jacobian(&mut self, q: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        self.galerkin
            .assemble(self.res, self.problem, q, self.omega_f, 1.0, jac);
        Ok(())
    }
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
            h0: BlockDiagonal::default(),
            scratch: vec![0.0; m],
            newton: NewtonWorkspace::new(m),
        })
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// Solves by damped Newton (Eq. 57, [`ivt_num::newton()`]: step halving while
    /// ‖R‖ does not fall) from the linear solution or from `guess`.
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
                if self.res.linear_inverse(&self.problem, omega, &mut self.h0) {
                    self.h0.mul(self.res.excitation(), &mut q);
                }
            }
        }
        let scale = self
            .res
            .force_scale(&self.problem, &q, omega, &mut self.scratch);
        let b = &self.opts.broyden;
        let opts = NewtonOptions {
            ftol: self.opts.residual_tol(scale),
            max_iter: b.max_iter,
            max_halvings: b.max_backtracks,
            ..NewtonOptions::default()
        };
        let mut sys = Galerkin {
            problem: &self.problem,
            res: &mut self.res,
            galerkin: &mut self.galerkin,
            omega_f,
        };
        let stats = newton(&mut sys, &mut q, &mut self.newton, &opts)?;
        Ok(HbSolution {
            coeffs: q,
            omega_f,
            harmonics: self.opts.harmonics,
            subharmonic: self.opts.subharmonic,
            stats: BroydenStats {
                iterations: stats.iterations,
                residual_evals: stats.residual_evals,
                jacobian_refreshes: stats.jacobian_evals,
                residual_norm: stats.residual_norm,
            },
        })
    }
}

impl<P: PeriodicProblem> crate::orbit::ihb::HbSolver for ClassicIhb<P> {
    fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError> {
        ClassicIhb::solve(self, omega_f, guess)
    }
    fn options(&self) -> &HbOptions {
        &self.opts
    }
}
