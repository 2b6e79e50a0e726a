//! Modified IHB (§3.2.2): AFT residual (Eq. 61–65) and Broyden's method (Eq. 66–67)
//! seeded with the linear Jacobian Eq. 60 and the linear solution `q₀ = B₀⁻¹ r_F`;
//! parameter stepping in the nonlinearity (ε from 0 in steps, reusing the last
//! Broyden matrix) when the direct iteration fails, and pseudo-arclength in the
//! stepping parameter when that path folds.

use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{validate_omega, HbError, HbOptions, HbResidual, HbSolution, HbSolver};
use crate::problem::PeriodicProblem;
use ivt_num::{broyden_solve, BlockDiagonal, BroydenStats, BroydenWorkspace, System};
use ivt_path::continuation::{follow_residual, ContinuationOptions};

/// The modified IHB solver for one problem and one size (plans and buffers reused
/// across solves; nothing is allocated inside the iteration, except the Galerkin
/// Jacobian's scratch, built once on the solver's first stalled-Broyden refresh).
#[derive(Debug)]
pub struct ModifiedIhb<P> {
    problem: P,
    opts: HbOptions,
    res: HbResidual,
    /// Built on the first Broyden refresh (most solves never need it).
    galerkin: Option<GalerkinJacobian>,
    ws: BroydenWorkspace,
    /// `H₀`, the inverse of the linear Jacobian Eq. 60, by blocks.
    h0: BlockDiagonal,
    /// Scratch of `m` entries (the forcing scale).
    scratch: Vec<f64>,
    q: Vec<f64>,
}

impl<P: PeriodicProblem> ModifiedIhb<P> {
    /// Prepares the solver.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`]/[`HbError::AftTooFewSamples`] for bad sizes (N ≤ n, p = 0,
    /// non-finite matrices or excitation).
    pub fn new(problem: P, opts: HbOptions) -> Result<Self, HbError> {
        let res = HbResidual::new(&problem, &opts)?;
        let m = res.len();
        Ok(Self {
            problem,
            opts,
            galerkin: None,
            res,
            ws: {
                // One-shot solves never read B: iterate on H alone.
                let mut ws = BroydenWorkspace::new(m);
                ws.track_jacobian = false;
                ws
            },
            h0: BlockDiagonal::default(),
            scratch: vec![0.0; m],
            q: vec![0.0; m],
        })
    }

    /// The problem.
    pub fn problem(&self) -> &P {
        &self.problem
    }

    /// The problem, mutable (e.g. to change a parameter between solves).
    pub fn problem_mut(&mut self) -> &mut P {
        &mut self.problem
    }

    /// The options.
    pub fn options(&self) -> &HbOptions {
        &self.opts
    }

    /// The residual evaluator (for continuation or custom drivers).
    pub fn residual_evaluator(&mut self) -> &mut HbResidual {
        &mut self.res
    }

    /// Residual Eq. 61 of `q` at `omega_f` (full nonlinearity) into `r`.
    pub fn residual(&mut self, q: &[f64], omega_f: f64, r: &mut [f64]) {
        self.res.eval(&self.problem, q, omega_f, 1.0, r);
    }

    /// Solves from the linear solution (Eq. 59) or from `guess`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a bad frequency or guess;
    /// [`HbError::Solve`] with the residual history when no attempt converges.
    pub fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError> {
        let mut q = std::mem::take(&mut self.q);
        let out = self.solve_into(omega_f, guess.is_some(), guess, &mut q);
        let sol = out.map(|stats| HbSolution {
            coeffs: q.clone(),
            omega_f,
            harmonics: self.opts.harmonics,
            subharmonic: self.opts.subharmonic,
            stats,
        });
        self.q = q;
        sol
    }

    /// Allocation-free core of [`Self::solve`]: the solution is written to `q`.
    /// With `use_guess`, `guess` (or `q` itself when `guess` is `None`) is the start;
    /// otherwise the linear solution.
    ///
    /// # Errors
    /// As [`Self::solve`].
    pub fn solve_into(
        &mut self,
        omega_f: f64,
        use_guess: bool,
        guess: Option<&[f64]>,
        q: &mut [f64],
    ) -> Result<BroydenStats, HbError> {
        validate_omega(omega_f)?;
        let m = self.res.len();
        if q.len() != m {
            return Err(HbError::InvalidInput(format!(
                "coefficient vector must have {m} entries"
            )));
        }
        if let Some(g) = guess {
            if g.len() != m || !g.iter().all(|v| v.is_finite()) {
                return Err(HbError::InvalidInput(format!(
                    "guess must have {m} finite entries"
                )));
            }
            q.copy_from_slice(g);
        }
        let omega = omega_f / self.opts.subharmonic as f64;
        let invertible = self.res.linear_inverse(&self.problem, omega, &mut self.h0);
        let seed = |ws: &mut BroydenWorkspace, h0: &BlockDiagonal| {
            if invertible {
                ws.set_inverse_jacobian_blocks(h0)
            } else {
                ws.clear_jacobian();
                Ok(())
            }
        };
        if !use_guess {
            if invertible {
                self.h0.mul(self.res.excitation(), q);
            } else {
                q.fill(0.0);
            }
        }
        // Tolerance atol + rtol·S (HbOptions), S from the forcing or the start.
        let scale = self
            .res
            .force_scale(&self.problem, q, omega, &mut self.scratch);
        let broyden = crate::BroydenOptions {
            tol: self.opts.residual_tol(scale),
            ..self.opts.broyden.clone()
        };
        let start: Vec<f64> = if self.opts.homotopy_steps == 0 {
            Vec::new()
        } else {
            q.to_vec()
        };
        let (problem, ws, opts) = (&self.problem, &mut self.ws, &self.opts);
        let mut sys = HbSystem {
            problem,
            res: &mut self.res,
            galerkin: &mut self.galerkin,
            omega_f,
            s: 1.0,
        };
        let mut last_err = None;
        if opts.homotopy_steps == 0 {
            seed(ws, &self.h0)?;
            match broyden_solve(&mut sys, q, ws, &broyden) {
                Ok(stats) => return Ok(stats),
                Err(e) => last_err = Some(e),
            }
        }
        // Parameter stepping s = h/steps (ε^{(h)} = hΔε), warm Broyden matrix.
        let start = if start.is_empty() {
            // Restart from the linear solution (or the guess).
            let mut s = vec![0.0; m];
            match guess {
                Some(g) => s.copy_from_slice(g),
                None if invertible => self.h0.mul(sys.res.excitation(), &mut s),
                None => {}
            }
            s
        } else {
            start
        };
        // Adaptive parameter stepping: s grows by Δs (initially 1/steps), which is
        // halved on failure (Broyden matrix refreshed) and grown by 1.5 on success.
        let mut ds = 1.0 / opts.homotopy_steps.max(8) as f64;
        let mut s_done = 0.0;
        q.copy_from_slice(&start);
        seed(ws, &self.h0)?;
        let mut q_ok = start;
        let mut total = BroydenStats::default();
        while s_done < 1.0 {
            let s = (s_done + ds).min(1.0);
            sys.s = s;
            match broyden_solve(&mut sys, q, ws, &broyden) {
                Ok(st) => {
                    total.iterations += st.iterations;
                    total.residual_evals += st.residual_evals;
                    total.jacobian_refreshes += st.jacobian_refreshes;
                    total.residual_norm = st.residual_norm;
                    s_done = s;
                    q_ok.copy_from_slice(q);
                    ds *= 1.5;
                }
                Err(e) => {
                    last_err = Some(e);
                    ds *= 0.5;
                    q.copy_from_slice(&q_ok);
                    ws.clear_jacobian();
                    if ds < 1e-5 {
                        break;
                    }
                }
            }
        }
        if s_done >= 1.0 {
            return Ok(total);
        }
        // Last resort: the solution path in s may turn back (a fold in s), which
        // plain stepping cannot pass; follow it by pseudo-arclength in s from the
        // last converged point and solve at s = 1 from the point that crosses it.
        let mut x0 = q_ok.clone();
        x0.push(s_done);
        let copts = ContinuationOptions {
            ds: 0.05,
            ds_max: 0.5,
            lambda_min: -1.0,
            lambda_max: 1.0,
            max_points: 2000,
            broyden: broyden.clone(),
            ..ContinuationOptions::default()
        };
        let mut crossing: Option<(Vec<f64>, Vec<f64>)> = None;
        let mut prev: Option<Vec<f64>> = None;
        let res = &mut *sys.res;
        // x = [q, s]: the coefficients and the stepping parameter.
        let residual = |x: &[f64], r: &mut [f64]| match x.split_last() {
            Some((&s, q)) => res.eval(problem, q, omega_f, s, r),
            None => r.fill(f64::NAN),
        };
        let traced = follow_residual(residual, &x0, None, 1.0, &copts, |pt| {
            if pt.lambda() >= 1.0 {
                crossing = Some((prev.take().unwrap_or_else(|| pt.x.clone()), pt.x.clone()));
                return false;
            }
            prev = Some(pt.x.clone());
            true
        });
        let crossing = crossing
            .as_ref()
            .map(|(a, b)| (a.split_last(), b.split_last()));
        if let (Ok(_), Some((Some((&sa, qa)), Some((&sb, qb))))) = (traced, crossing) {
            let t = if sb != sa {
                (1.0 - sa) / (sb - sa)
            } else {
                1.0
            };
            for ((qi, &ai), &bi) in q.iter_mut().zip(qa).zip(qb) {
                *qi = ai + t * (bi - ai);
            }
            ws.clear_jacobian();
            sys.s = 1.0;
            match broyden_solve(&mut sys, q, ws, &broyden) {
                Ok(st) => return Ok(st),
                Err(e) => last_err = Some(e),
            }
        }
        // Every path to here ran at least one failed attempt.
        Err(last_err.map_or_else(
            || HbError::NoConvergence {
                method: "modified IHB",
                omega: omega_f,
                history: Vec::new(),
            },
            HbError::Solve,
        ))
    }
}

/// The residual Eq. 61 at nonlinearity scale `s` as a Broyden [`System`] whose
/// Jacobian (used when Broyden stalls or starts cold) is the exact Galerkin one,
/// Eq. 56: O(N·m²) instead of the m residual evaluations of finite differences,
/// and exact, so the refreshed step is a Newton step.
struct HbSystem<'a, P> {
    problem: &'a P,
    res: &'a mut HbResidual,
    galerkin: &'a mut Option<GalerkinJacobian>,
    omega_f: f64,
    s: f64,
}

impl<P: PeriodicProblem> System for HbSystem<'_, P> {
    fn residual(&mut self, q: &[f64], r: &mut [f64]) {
        self.res.eval(self.problem, q, self.omega_f, self.s, r);
    }

    fn jacobian(&mut self, q: &[f64], jac: &mut [f64]) -> bool {
        let res = &mut *self.res;
        self.galerkin
            .get_or_insert_with(|| GalerkinJacobian::new(res))
            .assemble(res, self.problem, q, self.omega_f, self.s, jac);
        jac.iter().all(|v| v.is_finite())
    }
}
impl<P: PeriodicProblem> HbSolver for ModifiedIhb<P> {
    fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError> {
        ModifiedIhb::solve(self, omega_f, guess)
    }
    fn options(&self) -> &HbOptions {
        &self.opts
    }
}
