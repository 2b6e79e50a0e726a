//! The exact corrector (§3.2.3 with Newton in place of Broyden): the
//! tangent solves `[J R_λ; t_prevᵀ] t = e_{m+1}` (oriented along the previous
//! one), and the correction of `[R(u); tᵀ(u − u_pred)] = 0` is first the
//! chord iteration on the tangent's LU ([`super::chord`]), then Newton
//! ([`ivt_num::newton()`], full steps) on the exact bordered Jacobian. With
//! [`ContinuationOptions::second_order_predictor`] the chord's matrix is
//! assembled and factored at the prediction, and that LU (bordered by the
//! tangent) gives the next point's tangent.

use std::convert::Infallible;

use super::{Corrected, Correction, DirectionError, Found, PathCorrector, Prediction, Retry};
use crate::branch::{full_newton_steps, path_lambda_step, Branch};
use crate::continuation::ContinuationOptions;
use crate::error::PathError;
use ivt_num::iteration::Stopping;
use ivt_num::vector::norm2;
use ivt_num::SolveError;
use ivt_num::{
    chord, newton_bordered, Border, BorderedLu, NewtonSystem, NewtonWorkspace, StepCheck,
};

/// Corrector iterations counted as this many chord iterations per full Newton
/// step (a Newton step assembles and factors the Jacobian).
const NEWTON_WEIGHT: usize = 2;

/// The chord–Newton corrector on the exact Jacobian; `aug` holds the LU of
/// the last bordered matrix `[J R_λ; rowᵀ]`.
pub struct NewtonCorrector {
    m: usize,
    aug: BorderedLu,
    /// `∂R/∂u`, row-major `m × m`.
    jac: Vec<f64>,
    r: Vec<f64>,
    r_lambda: Vec<f64>,
    rhs: Vec<f64>,
    /// The corrected point.
    u: Vec<f64>,
    /// `jac` was assembled at `u` as Newton converged there: the tangent at
    /// that point reuses it instead of assembling it again.
    jac_at_u: bool,
    /// Buffers of the Newton corrector.
    newton: NewtonWorkspace,
    tol: f64,
    max_newton: usize,
    second_order: bool,
    /// The chord has not failed on this step.
    chord_ok: bool,
    /// `aug` holds the prediction's LU of the chord that reached the last
    /// point, bordered by the tangent: the next tangent comes from it.
    factored_near_x: bool,
}

impl NewtonCorrector {
    /// The corrector of a branch of `m` unknowns: `opts.broyden.tol` is the
    /// absolute tolerance on `‖[R; constraint]‖₂`, `opts.broyden.max_iter` the
    /// Newton iteration limit (the chord may take three times as many while
    /// it contracts by ½ or better).
    pub fn new(m: usize, opts: &ContinuationOptions) -> Self {
        Self {
            m,
            aug: BorderedLu::new(m, 1),
            jac: vec![0.0; m * m],
            r: vec![0.0; m],
            r_lambda: vec![0.0; m],
            rhs: vec![0.0; m + 1],
            u: vec![0.0; m + 1],
            jac_at_u: false,
            newton: NewtonWorkspace::bordered(m + 1, 1),
            tol: opts.broyden.tol,
            max_newton: opts.broyden.max_iter,
            second_order: opts.second_order_predictor,
            chord_ok: true,
            factored_near_x: false,
        }
    }

    /// Factors `[J R_λ; rowᵀ]` with the `J` in `jac`, assembled at `x`;
    /// `false` if singular.
    fn factor<B: Branch>(&mut self, branch: &mut B, x: &[f64], row: &[f64]) -> bool {
        let Some(((&lambda, u), (corner, row))) = x.split_last().zip(row.split_last()) else {
            return false;
        };
        branch.residual_lambda(u, lambda, path_lambda_step(lambda), &mut self.r_lambda);
        self.aug
            .factor(&self.jac, &self.r_lambda, row, std::slice::from_ref(corner))
            .is_ok()
    }

    /// The unit tangent at `x`, oriented along the previous `tangent` (which
    /// also borders the matrix); leaves its LU in `aug` for the chord.
    fn tangent<B: Branch>(&mut self, branch: &mut B, x: &[f64], tangent: &mut [f64]) -> bool {
        // After Newton converged, `jac` is already the Jacobian at `x`.
        let reuse = self.jac_at_u && self.u == x;
        if !reuse {
            if let Some((&lambda, u)) = x.split_last() {
                branch.jacobian(u, lambda, &mut self.jac);
            }
        }
        self.jac_at_u = false;
        self.factor(branch, x, tangent) && self.solve_tangent(tangent)
    }

    /// The unit solution of `aug · z = e_{m+1}` (the tangent of the factored
    /// bordered matrix), oriented along the previous `tangent`, into it.
    fn solve_tangent(&mut self, tangent: &mut [f64]) -> bool {
        let z = &mut self.rhs;
        z.fill(0.0);
        if let Some(last) = z.last_mut() {
            *last = 1.0;
        }
        let solved = self.aug.solve(z).is_ok();
        let norm = norm2(z);
        let along: f64 = z.iter().zip(tangent.iter()).map(|(a, b)| a * b).sum();
        let sign = if along < 0.0 { -1.0 } else { 1.0 };
        for (t, v) in tangent.iter_mut().zip(z.iter()) {
            *t = sign * v / norm;
        }
        solved && norm.is_finite()
    }

    /// `R` and `J` at the corrector's start (the prediction) and the LU of
    /// `[J R_λ; rowᵀ]` there, `row` the constraint's gradient: the chord's
    /// matrix of the second-order predictor. `false` if singular.
    fn factor_at_start<B: Branch>(&mut self, branch: &mut B, pred: &Prediction<'_>) -> bool {
        let u = std::mem::take(&mut self.u);
        if let Some((&lambda, q)) = u.split_last() {
            branch.residual_jacobian(q, lambda, &mut self.r, &mut self.jac);
        }
        self.jac_at_u = false;
        let factored = self.factor(branch, &u, &pred.row());
        self.u = u;
        factored
    }

    /// Newton on `[R(u); constraint] = 0` from `u`; diverged once ‖F‖ grows
    /// after the second step. Leaves `jac` at the solution for the tangent.
    fn newton<B: Branch>(
        &mut self,
        branch: &mut B,
        pred: &Prediction<'_>,
    ) -> Result<usize, SolveError> {
        let nopts = full_newton_steps(self.tol, self.max_newton);
        let mut corrected = ExactNewton {
            branch,
            jac: &mut self.jac,
            r_lambda: &mut self.r_lambda,
        };
        // The constraint row about the prediction (`λ = fix` when landing).
        let row = pred.row();
        let (values, origin) = match pred.fix {
            Some(l) => ([l], &[][..]),
            None => ([0.0], pred.u_pred),
        };
        let border = Border {
            rows: &row,
            values: &values,
            origin,
        };
        let result = newton_bordered(
            &mut corrected,
            border,
            &mut self.u,
            &mut self.newton,
            &nopts,
        );
        // The last residual evaluation assembled `jac` at `u`.
        self.jac_at_u = result.is_ok();
        if let Some(r) = self.newton.residual().get(..self.m) {
            self.r.copy_from_slice(r);
        }
        result.map(|stats| stats.iterations)
    }
}

impl<B: Branch> PathCorrector<B> for NewtonCorrector {
    /// The start must be converged ([`super::super::correct_at_fixed_lambda`]).
    fn start(&mut self, branch: &mut B, x: &mut [f64], dir: &mut [f64]) -> Result<(), PathError> {
        let sign = dir.last().copied().unwrap_or(1.0);
        let direction = dir;
        direction.fill(0.0);
        if let Some(last) = direction.last_mut() {
            *last = if sign >= 0.0 { 1.0 } else { -1.0 };
        }
        if self.tangent(branch, x, direction) {
            Ok(())
        } else {
            Err(PathError::SingularStart {
                lambda: x.last().copied().unwrap_or(f64::NAN),
            })
        }
    }

    fn correct(&mut self, branch: &mut B, pred: &Prediction<'_>, x: &mut [f64]) -> Correction {
        self.u.copy_from_slice(pred.u_pred);
        // A fresh LU at the predictor (its residual is the chord's first).
        let fresh = self.chord_ok && self.second_order;
        if fresh && !self.factor_at_start(branch, pred) {
            self.chord_ok = false;
        }
        let chord = if self.chord_ok {
            if fresh {
                if let Some((c, r)) = self.rhs.split_last_mut() {
                    r.copy_from_slice(&self.r);
                    *c = pred.constraint(&self.u);
                }
            }
            let mut residual = |x: &[f64], r: &mut [f64]| {
                if let (Some((&lambda, u)), Some((c, r))) = (x.split_last(), r.split_last_mut()) {
                    branch.residual(u, lambda, r);
                    *c = pred.constraint(x);
                }
            };
            let stopping = Stopping {
                ftol: self.tol,
                max_iter: 3 * self.max_newton,
            };
            chord(
                &mut residual,
                &mut self.aug,
                &mut self.u,
                &mut self.rhs,
                fresh,
                stopping,
            )
        } else {
            Err(SolveError::NonConvergence {
                iterations: 0,
                history: Vec::new(),
            })
        };
        let weighted = match chord {
            Ok(its) => its,
            // From the chord's best iterate (the predictor at worst).
            Err(_) => {
                self.chord_ok = false;
                self.newton(branch, pred)? * NEWTON_WEIGHT
            }
        };
        // Not after landing: bordered by e_{m+1}, the LU's determinant is
        // det J, not the branch-point test's.
        self.factored_near_x = fresh && self.chord_ok && pred.fix.is_none();
        x.copy_from_slice(&self.u);
        let iterations = if self.chord_ok {
            weighted
        } else {
            weighted / NEWTON_WEIGHT
        };
        Ok(Corrected {
            iterations,
            effort: weighted,
        })
    }

    /// The tangent at `x` (from the prediction's LU where the chord left it).
    fn direction(&mut self, branch: &mut B, _x_prev: &[f64], x: &[f64], dir: &mut [f64]) -> Found {
        let direction = dir;
        self.chord_ok = true;
        let found = if self.factored_near_x {
            self.solve_tangent(direction)
        } else {
            self.tangent(branch, x, direction)
        };
        found.then_some(()).ok_or(DirectionError::Singular)
    }

    /// The chord stays off for the rest of the step once it failed, and
    /// after [`Retry::Turned`] unless it factors afresh at each prediction
    /// (the tangent's LU is the rejected point's).
    fn retry(&mut self, _branch: &mut B, _x_prev: &[f64], why: Retry) {
        if why == Retry::Turned && !self.second_order {
            self.chord_ok = false;
        }
    }

    fn bordered_sign(&self) -> Option<f64> {
        Some(self.aug.det_sign())
    }

    /// At `target_iter` already: a chord that needs that many iterations
    /// (or Newton half as many) is far from its two-iteration regime.
    fn shrink_at(&self, target_iter: usize) -> usize {
        target_iter
    }

    fn second_order(&self) -> bool {
        self.second_order
    }
}

/// `R(u, λ) = 0` in `x = (u, λ)` as the [`NewtonSystem`] that the
/// constraint row closes ([`newton_bordered`]): each residual assembles `J`
/// with it ([`Branch::residual_jacobian`]); the Jacobian is `[J, R_λ]`
/// row-major.
struct ExactNewton<'a, B> {
    branch: &'a mut B,
    /// `∂R/∂u` of the last residual, row-major `m × m`.
    jac: &'a mut [f64],
    r_lambda: &'a mut [f64],
}

impl<B: Branch> NewtonSystem for ExactNewton<'_, B> {
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        match x.split_last() {
            Some((&lambda, u)) => self.branch.residual_jacobian(u, lambda, r, self.jac),
            None => r.fill(f64::NAN),
        }
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        let m = self.r_lambda.len();
        if let Some((&lambda, u)) = x.split_last() {
            let h = path_lambda_step(lambda);
            self.branch.residual_lambda(u, lambda, h, self.r_lambda);
        }
        let jac_rows = self.jac.chunks_exact(m.max(1));
        for ((r_l, jac_row), out_row) in self
            .r_lambda
            .iter()
            .zip(jac_rows)
            .zip(out.chunks_exact_mut(m + 1))
        {
            if let Some((left, last)) = out_row.split_at_mut_checked(m) {
                left.copy_from_slice(jac_row);
                last.fill(*r_l);
            }
        }
        Ok(())
    }

    /// Diverged when ‖F‖ rises after the second step (the corrector halves
    /// the path step instead).
    fn check_step(
        &mut self,
        _x: &[f64],
        _step: &[f64],
        history: &[f64],
    ) -> Result<StepCheck, Infallible> {
        Ok(match history {
            [_, .., before, now] if now > before => StepCheck::Diverged,
            _ => StepCheck::Continue,
        })
    }
}
