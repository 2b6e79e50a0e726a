//! The Broyden corrector (thesis Eq. 68–77): Broyden's method on the
//! augmented system `[R(x); x_dᵀ(x − x_p) − Δη] = 0` with the approximate
//! Jacobian `B_x = [[B_q, B_λ], [x_dᵀ]]` (Eq. 72). `B_q` is carried over from
//! the previous point, `B_λ` is refreshed by one finite difference at each
//! prediction, and the last row is kept exact through every update
//! ([`BroydenWorkspace::exact_rows`], Eq. 77). The direction at a point is the
//! secant from its predecessor (Eq. 71). The branch is seen through its
//! residual alone (the adapter `residual_of`): no Jacobian is assembled.

use super::{Corrected, Correction, DirectionError, Found, PathCorrector, Prediction, Retry};
use crate::branch::Branch;
use crate::continuation::predictor::distance;
use crate::error::PathError;
use ivt_num::vector::{dot, norm2};
use ivt_num::LuWorkspace;
use ivt_num::{broyden_solve, BroydenOptions, BroydenWorkspace, SolveError};

/// `R(x)` of `branch` at `x = (u, λ)` into `r` (NaN for an empty `x`): the
/// branch as the residual [`broyden_solve`] iterates on.
fn residual_of<B: Branch>(branch: &mut B, x: &[f64], r: &mut [f64]) {
    match x.split_last() {
        Some((&lambda, u)) => branch.residual(u, lambda, r),
        None => r.fill(f64::NAN),
    }
}

/// Broyden's corrector and its Jacobian estimate.
#[derive(Debug, Clone)]
pub struct BroydenCorrector {
    m: usize,
    opts: BroydenOptions,
    /// The estimate `[B_q, B_λ]`, row-major `m × (m+1)`.
    jac: Vec<f64>,
    /// The start's Jacobian estimate, if given.
    jac0: Option<Vec<f64>>,
    ws: BroydenWorkspace,
    /// `B_x` of a fresh factorization.
    b: Vec<f64>,
    /// `B_x` must be set afresh (not updated by its changed column and row).
    fresh: bool,
    /// Scratch of the differences.
    r0: Vec<f64>,
    r1: Vec<f64>,
    xt: Vec<f64>,
    e_lambda: Vec<f64>,
    /// The iterations of the last correction.
    iterations: usize,
}

impl BroydenCorrector {
    /// The corrector of a branch of `m` unknowns; `jac0`, if given, is a
    /// row-major `m×(m+1)` Jacobian estimate at the start (otherwise forward
    /// differences of step `opts.fd_step`).
    pub fn new(m: usize, opts: &BroydenOptions, jac0: Option<&[f64]>) -> Self {
        let n1 = m + 1;
        let mut ws = BroydenWorkspace::new(n1);
        ws.exact_rows = m..n1;
        // Only H = B_x⁻¹ is updated in the iterations (three O(m²) passes
        // each, not six); the λ column and the arc-length row that change
        // between points stay known, and B_x is rebuilt from H only when a
        // rejected point needs B_q.
        ws.track_jacobian = false;
        ws.tracked_column = Some(m);
        let mut e_lambda = vec![0.0; n1];
        if let Some(last) = e_lambda.last_mut() {
            *last = 1.0;
        }
        Self {
            m,
            opts: opts.clone(),
            jac: vec![0.0; m * n1],
            jac0: jac0.map(<[f64]>::to_vec),
            ws,
            b: vec![0.0; n1 * n1],
            fresh: true,
            r0: vec![0.0; m],
            r1: vec![0.0; m],
            xt: vec![0.0; n1],
            e_lambda,
            iterations: 0,
        }
    }

    /// Forward-difference Jacobian `[R_u, R_λ]` at `x` into `self.jac`.
    fn difference_jacobian<B: Branch>(&mut self, branch: &mut B, x: &[f64]) {
        let n1 = self.m + 1;
        self.xt.copy_from_slice(x);
        residual_of(branch, x, &mut self.r0);
        for (j, &xj) in x.iter().enumerate() {
            let h = self.opts.fd_step * xj.abs().max(1.0);
            set(&mut self.xt, j, xj + h);
            residual_of(branch, &self.xt, &mut self.r1);
            for ((row, a), b) in self.jac.chunks_exact_mut(n1).zip(&self.r1).zip(&self.r0) {
                set(row, j, (a - b) / h);
            }
            set(&mut self.xt, j, xj);
        }
    }

    /// The `B_q` block of the row-major `rows` (`m` rows of `stride`) into
    /// `self.jac`.
    fn carry_bq(&mut self, rows: &[f64], stride: usize) {
        let m = self.m;
        for (to, from) in self.jac.chunks_exact_mut(m + 1).zip(rows.chunks(stride)) {
            if let (Some(to), Some(from)) = (to.get_mut(..m), from.get(..m)) {
                to.copy_from_slice(from);
            }
        }
    }
}

impl<B: Branch> PathCorrector<B> for BroydenCorrector {
    fn start(&mut self, branch: &mut B, x: &mut [f64], dir: &mut [f64]) -> Result<(), PathError> {
        let sign = dir.last().copied().unwrap_or(1.0);
        let direction = dir;
        let (m, n1) = (self.m, self.m + 1);
        match self.jac0.take() {
            Some(j) if j.len() == m * n1 => self.jac.copy_from_slice(&j),
            Some(_) => {
                return Err(PathError::InvalidInput(
                    "continuation: jac0 must be m×(m+1)".into(),
                ))
            }
            None => self.difference_jacobian(branch, x),
        }
        // Correct the start at fixed λ.
        let Some((lam0, q)) = x.split_last_mut() else {
            return Err(PathError::InvalidInput("continuation: empty start".into()));
        };
        let lam0 = *lam0;
        let mut wsq = BroydenWorkspace::new(m);
        let bq: Vec<f64> = self
            .jac
            .chunks_exact(n1)
            .flat_map(|row| row.iter().take(m).copied())
            .collect();
        if wsq.set_jacobian(&bq).is_err() {
            wsq.clear_jacobian();
        }
        let mut fixed = |qv: &[f64], r: &mut [f64]| branch.residual(qv, lam0, r);
        broyden_solve(&mut fixed, q, &mut wsq, &self.opts).map_err(|cause| {
            PathError::ContinuationStart {
                lambda: lam0,
                cause,
            }
        })?;
        self.carry_bq(wsq.jacobian(), m);
        // Tangent at the start: B_q z = B_λ, t = [−z; 1].
        let mut lu = LuWorkspace::new(m);
        for (i, row) in self.jac.chunks_exact(n1).enumerate() {
            for (j, v) in row.iter().take(m).enumerate() {
                lu.mat[(i, j)] = *v;
            }
        }
        // A start near a fold has an ill-conditioned B_q and still a tangent:
        // only a non-finite solution (an exactly singular B_q) is refused.
        lu.factor();
        let mut z: Vec<f64> = self
            .jac
            .chunks_exact(n1)
            .map(|row| row.last().copied().unwrap_or(f64::NAN))
            .collect();
        lu.solve(&mut z);
        if !z.iter().all(|v| v.is_finite()) {
            return Err(PathError::SingularStart { lambda: lam0 });
        }
        let mut xd: Vec<f64> = z.iter().map(|v| -v).chain(std::iter::once(1.0)).collect();
        let nt = norm2(&xd);
        let sign = if sign >= 0.0 { 1.0 } else { -1.0 };
        xd.iter_mut().for_each(|v| *v *= sign / nt);
        direction.copy_from_slice(&xd);
        Ok(())
    }

    fn correct(&mut self, branch: &mut B, pred: &Prediction<'_>, x: &mut [f64]) -> Correction {
        let (m, n1) = (self.m, self.m + 1);
        x.copy_from_slice(pred.u_pred);
        // B_λ by one finite difference at the prediction.
        let Some(lambda) = x.last_mut() else {
            return Err(SolveError::NonConvergence {
                iterations: 0,
                history: Vec::new(),
            });
        };
        let h = self.opts.fd_step * lambda.abs().max(1.0);
        residual_of(branch, x, &mut self.r0);
        if let Some(l) = x.last_mut() {
            *l += h;
        }
        residual_of(branch, x, &mut self.r1);
        if let Some(l) = x.last_mut() {
            *l -= h;
        }
        for ((row, a), b) in self.jac.chunks_exact_mut(n1).zip(&self.r1).zip(&self.r0) {
            set(row, m, (a - b) / h);
        }
        // B_x = [[B_q, B_λ], [x_dᵀ]] (Eq. 72). After a successful step only the
        // λ column and the augmenting row change: two Sherman–Morrison updates.
        // The constraint row: the secant, or e_λ when landing.
        let row = if pred.fix.is_some() {
            &self.e_lambda
        } else {
            pred.direction
        };
        let set_b = if self.fresh {
            if let Some((top, bottom)) = self.b.split_at_mut_checked(m * n1) {
                top.copy_from_slice(&self.jac);
                bottom.copy_from_slice(row);
            }
            self.ws.set_jacobian(&self.b)
        } else {
            let corner = self.ws.jacobian_entry(m, m);
            let col: Vec<f64> = self
                .jac
                .chunks_exact(n1)
                .map(|r| r.last().copied().unwrap_or(f64::NAN))
                .chain(corner)
                .collect();
            self.ws
                .replace_col(m, &col)
                .and_then(|()| self.ws.replace_row(m, row))
        };
        self.fresh = false;
        let (xp, xd, step) = (pred.x_prev, pred.direction, pred.step);
        let mut aug = |xv: &[f64], r: &mut [f64]| {
            if let Some((r_u, [r_c])) = r.split_at_mut_checked(m) {
                residual_of(branch, xv, r_u);
                *r_c = match pred.fix {
                    Some(l) => xv.last().map_or(f64::NAN, |v| v - l),
                    None => {
                        let mut g = 0.0;
                        for ((d, a), b) in xd.iter().zip(xv).zip(xp) {
                            g += d * (a - b);
                        }
                        g - step
                    }
                };
            }
        };
        let outcome = set_b.and_then(|()| broyden_solve(&mut aug, x, &mut self.ws, &self.opts));
        let dist = distance(x, xp);
        match outcome {
            Ok(stats) if dist <= 3.0 * step => {
                self.iterations = stats.iterations;
                Ok(Corrected {
                    iterations: stats.iterations,
                    effort: stats.iterations,
                })
            }
            Ok(_) => Err(SolveError::NonConvergence {
                iterations: 0,
                history: self.ws.history().to_vec(),
            }),
            Err(e) => Err(e),
        }
    }

    /// The secant from `x_prev` (Eq. 71); a secant against the previous one
    /// is a corrector that went backwards.
    fn direction(&mut self, _branch: &mut B, x_prev: &[f64], x: &[f64], dir: &mut [f64]) -> Found {
        let direction = dir;
        let mut new_xd: Vec<f64> = x.iter().zip(x_prev).map(|(a, b)| a - b).collect();
        let nn = norm2(&new_xd);
        new_xd.iter_mut().for_each(|v| *v /= nn);
        if dot(&new_xd, direction) < 0.0 {
            return Err(DirectionError::Backwards(SolveError::NonConvergence {
                iterations: self.iterations,
                history: self.ws.history().to_vec(),
            }));
        }
        direction.copy_from_slice(&new_xd);
        Ok(())
    }

    /// A failed corrector restarts from forward differences at `x_prev`; a
    /// rejected point only from a fresh factorization of the current `B_q`.
    fn retry(&mut self, branch: &mut B, x_prev: &[f64], why: Retry) {
        if why == Retry::Failed {
            self.difference_jacobian(branch, x_prev);
        } else {
            let n1 = self.m + 1;
            let rows = self.ws.jacobian().to_vec();
            self.carry_bq(&rows, n1);
        }
        self.fresh = true;
    }
}

/// `x[k] = v` (nothing for `k` out of range).
fn set(x: &mut [f64], k: usize, v: f64) {
    if let Some(e) = x.get_mut(k) {
        *e = v;
    }
}
