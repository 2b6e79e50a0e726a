//! Folds (turning points) of a solution branch `R(q, λ) = 0`, located by Newton's
//! method on the minimally extended system (Govaerts' bordering)
//!
//! `R(q, λ) = 0`,  `g(q, λ) = 0`,  where  `[[J, b], [cᵀ, 0]] [v; g] = [0; 1]`,
//!
//! `J = ∂R/∂q`. `g` vanishes exactly where `J` is singular, and for borders `b`, `c`
//! near the left and right null vectors the bordered matrix stays regular there, so
//! Newton on `{q, λ}` converges quadratically to the fold itself (not to a bracket
//! between two path points). `∂g/∂(q, λ) = −wᵀ J_(q, λ) v` with `w` from the
//! transposed bordered system ([`Branch::jacobian_gradient`], and a central
//! difference of [`Branch::bilinear`] in λ); `∂R/∂λ` by central differences. One
//! Jacobian per Newton step.
//!
//! On a traced path ([`Fold`]) the test function is the λ component of the
//! secant into each point (pseudo-arclength, Eq. 68–77): it changes sign where
//! the path turns in λ, and the locator starts from the point nearest the turn.

use super::detector::{
    Bifurcation, BifurcationKind, Detector, LocateOptions, PathSoFar, Start, FOLD_STEP_TOL,
};
use super::extended::{check_start, finish, null_vector, singular_at_start, Ruled, StepRule};
use crate::branch::Branch;
use crate::continuation::turn;
use crate::error::PathError;
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::{newton, BorderedLu, LuWorkspace, NewtonSystem, NewtonWorkspace};
use std::convert::Infallible;

/// A located fold.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldLocation {
    /// The solution at the fold.
    pub q: Vec<f64>,
    /// The parameter at the fold.
    pub lambda: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// ‖R(q, λ)‖₂ at the fold.
    pub residual_norm: f64,
}

/// Scratch of the bordered solves: one LU of the bordered matrix serves both
/// the plain and the transposed system.
struct Bordered {
    jac: Vec<f64>,
    lu: BorderedLu,
    rhs: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
}

impl Bordered {
    /// `rhs = [0; 1]` solved with the bordered matrix (or its transpose)
    /// into `out` (`m`); returns the last entry (NaN if singular).
    fn solve_unit(&mut self, transpose: bool, out: &mut [f64]) -> f64 {
        self.rhs.fill(0.0);
        if let Some(last) = self.rhs.last_mut() {
            *last = 1.0;
        }
        let solved = if transpose {
            self.lu.solve_transpose(&mut self.rhs)
        } else {
            self.lu.solve(&mut self.rhs)
        };
        match (solved, self.rhs.split_last()) {
            (Ok(()), Some((g, head))) if head.len() == out.len() => {
                out.copy_from_slice(head);
                *g
            }
            _ => f64::NAN,
        }
    }

    /// Assembles `J` at `(q, λ)` (unless `self.jac` already holds it) and solves
    /// `[[J, b], [cᵀ, 0]] [v; g] = e` and `[[Jᵀ, c], [bᵀ, 0]] [w; g] = e`;
    /// returns `g` (NaN if singular), `J` stays in `self.jac`.
    fn solve_pair<B: Branch>(
        &mut self,
        branch: &mut B,
        (q, lambda): (&[f64], f64),
        jac_current: bool,
        v: &mut [f64],
        w: &mut [f64],
    ) -> f64 {
        if !jac_current {
            branch.jacobian(q, lambda, &mut self.jac);
        }
        if self.lu.factor(&self.jac, &self.b, &self.c, &[0.0]).is_err() {
            return f64::NAN;
        }
        let g = self.solve_unit(false, v);
        let g_t = self.solve_unit(true, w);
        if g_t.is_finite() && v.iter().chain(w.iter()).all(|x| x.is_finite()) {
            g
        } else {
            f64::NAN
        }
    }
}

/// Locates the fold of `branch` nearest the converged point `(q0, λ0)`
/// (`opts.stability_steps` unused: no multipliers).
///
/// # Errors
/// [`PathError::InvalidInput`] for sizes; [`PathError::Solve`]:
/// [`ivt_num::SolveError::SingularJacobian`] if the bordered or extended matrix is
/// singular (e.g. a branch point rather than a fold),
/// [`ivt_num::SolveError::NonConvergence`] (with the ‖(R, g)‖ history) when
/// Newton does not settle within `max_iter` steps,
/// [`ivt_num::SolveError::NonFinite`] for NaN.
pub fn locate_fold<B: Branch>(
    branch: &mut B,
    q0: &[f64],
    lambda0: f64,
    opts: &LocateOptions,
) -> Result<FoldLocation, PathError> {
    check_start(branch, q0, lambda0)?;
    let m = branch.len();
    let n1 = m + 1;
    let mut bd = Bordered {
        jac: vec![0.0; m * m],
        lu: BorderedLu::new(m, 1),
        rhs: vec![0.0; n1],
        b: vec![1.0 / (m as f64).sqrt(); m],
        c: vec![1.0 / (m as f64).sqrt(); m],
    };
    // Borders: the approximate left/right null vectors of J at the start.
    branch.jacobian(q0, lambda0, &mut bd.jac);
    let mut lu = LuWorkspace::new(m);
    // J is near-singular at a fold: only a non-finite factor is refused.
    lu.factor_row_major(&bd.jac);
    if !null_vector(&mut lu, &mut bd.c, false) || !null_vector(&mut lu, &mut bd.b, true) {
        return Err(PathError::Solve(singular_at_start()));
    }
    let mut x = q0.to_vec();
    x.push(lambda0);
    let mut system = Ruled {
        system: FoldSystem {
            branch,
            bd,
            jac_current: true,
            fd_step: opts.fd_step,
            r_lambda: vec![0.0; m],
            v: vec![0.0; m],
            w: vec![0.0; m],
            grad: vec![0.0; m],
        },
        rule: StepRule {
            m,
            step_tol: opts.step_tol,
            noise_tol: opts.noise_tol,
            lambda_floor: f64::MIN_POSITIVE,
        },
    };
    let nopts = StepRule::newton_options(opts.max_iter, false);
    let mut ws = NewtonWorkspace::new(n1);
    let stats = newton(&mut system, &mut x, &mut ws, &nopts)?;
    let residual_norm = norm2(ws.residual().get(..m).unwrap_or_default());
    let lambda = x.pop().unwrap_or(lambda0);
    Ok(FoldLocation {
        q: x,
        lambda,
        iterations: stats.iterations,
        residual_norm,
    })
}

/// The minimally extended system `[R(q, λ); g(q, λ)] = 0` in `x = (q, λ)`
/// for [`ivt_num::newton()`]: the residual solves the bordered pair (so the
/// Jacobian reuses `J`, `v` and `w` of the same point), the Jacobian is
/// `[[J, R_λ], [g_q, g_λ]]` with `g_(q, λ) = −wᵀ J_(q, λ) v` (Govaerts).
struct FoldSystem<'a, B> {
    branch: &'a mut B,
    bd: Bordered,
    /// `bd.jac` already holds `J` at the next residual point (the start).
    jac_current: bool,
    fd_step: f64,
    r_lambda: Vec<f64>,
    v: Vec<f64>,
    w: Vec<f64>,
    grad: Vec<f64>,
}

impl<B: Branch> NewtonSystem for FoldSystem<'_, B> {
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        let (Some((&lambda, q)), Some((g, r))) = (x.split_last(), r.split_last_mut()) else {
            return Ok(());
        };
        self.branch.residual(q, lambda, r);
        let current = std::mem::replace(&mut self.jac_current, false);
        *g = self
            .bd
            .solve_pair(self.branch, (q, lambda), current, &mut self.v, &mut self.w);
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        let Some((&lambda, q)) = x.split_last() else {
            return Ok(());
        };
        let m = q.len();
        let h_lambda = self.fd_step * lambda.abs().max(f64::MIN_POSITIVE);
        let branch = &mut *self.branch;
        branch.residual_lambda(q, lambda, h_lambda, &mut self.r_lambda);
        let g_lambda = -branch.bilinear_lambda(q, lambda, h_lambda, &self.w, &self.v);
        branch.jacobian_gradient(q, lambda, &self.w, &self.v, &mut self.grad);
        super::extended::put_jacobian(jac, m + 1, &self.bd.jac, &self.r_lambda);
        if let Some(last) = jac.get_mut(m * (m + 1)..) {
            for (o, g) in last
                .iter_mut()
                .zip(self.grad.iter().map(|g| -g).chain([g_lambda]))
            {
                *o = g;
            }
        }
        Ok(())
    }
}

/// The fold event of a path on any [`Branch`]: the λ component of the secant
/// into each point ([`crate::PathPoint::dlambda`]) changes sign; the locator
/// ([`locate_fold`], step tolerance at most 1e-12) starts from the point
/// nearest the turn of the parabola through the three points around it
/// ([`crate::continuation::turn_estimate`]). A located fold is its orbit and
/// λ alone; [`Fold::locate_with`] adds the multipliers there (ivt-hb's
/// `FamilyFold`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Fold;

impl Fold {
    /// [`locate_fold`] from the start point of `at` (step tolerance at most
    /// 1e-12), as a [`Bifurcation`] with `multipliers`' of the located
    /// orbit.
    ///
    /// # Errors
    /// As [`locate_fold`]; the error of `multipliers`.
    pub fn locate_with<B: Branch, E: From<PathError>>(
        at: Start<'_, B>,
        multipliers: impl FnOnce(&mut B, &[f64], f64, &LocateOptions) -> Result<Vec<c64>, E>,
    ) -> Result<Bifurcation, E> {
        let (q, lambda) = at.point()?;
        let (branch, opts) = (at.branch, at.opts);
        let fold_opts = LocateOptions {
            step_tol: opts.step_tol.min(FOLD_STEP_TOL),
            ..opts.clone()
        };
        let f = locate_fold(branch, q, lambda, &fold_opts)?;
        let multipliers = multipliers(branch, &f.q, f.lambda, opts)?;
        Ok(finish(
            branch,
            BifurcationKind::Fold,
            (f.q, f.lambda),
            multipliers,
            Vec::new(),
            f.iterations,
        ))
    }

    /// The start of the locator: the point nearest the turn of the parabola
    /// through the three newest points, once their secants turned.
    pub fn start(path: &PathSoFar) -> Option<usize> {
        let k = path.len().checked_sub(3)?;
        let [a, b, c] = path.points.get(k..)? else {
            return None;
        };
        Some(k + turn(a, b, c).1)
    }

    /// The test function at point `k`: the λ component of the secant into
    /// it.
    pub fn test(path: &PathSoFar, k: usize) -> f64 {
        path.points.get(k).map_or(f64::NAN, |p| p.dlambda)
    }
}

impl<B: Branch, E: From<PathError>> Detector<B, E> for Fold {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::Fold
    }

    fn start(&self, path: &PathSoFar) -> Option<usize> {
        Fold::start(path)
    }

    fn test(&mut self, _branch: &mut B, path: &PathSoFar, k: usize) -> f64 {
        Fold::test(path, k)
    }

    /// [`locate_fold`] with a step tolerance of at most 1e-12.
    fn locate(&mut self, at: Start<'_, B>) -> Result<Bifurcation, E> {
        Self::locate_with(at, |_, _, _, _| Ok(Vec::new()))
    }
}

#[cfg(test)]
mod tests;
