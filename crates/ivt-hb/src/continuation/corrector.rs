//! The corrector's system of the exact-Jacobian path: the predicted point
//! and its constraint ([`Prediction`]), and `[R(u, λ); constraint] = 0` as a
//! bordered [`NewtonSystem`] ([`ExactNewton`]) for the Newton corrector of
//! [`super::exact`] (thesis Eq. 72 with the exact Jacobian).

use faer::Mat;
use ivt_num::{NewtonSystem, StepCheck};
use std::borrow::Cow;
use std::convert::Infallible;

use super::PathSystem;

/// `[R(u, λ); constraint] = 0` in `x = (u, λ)` as a square
/// [`NewtonSystem`]: each residual assembles `J` with it (the string's
/// Jacobian costs little beyond its residual); the Jacobian is
/// `[[J, R_λ], [rowᵀ]]` row-major. The constraint is evaluated as
/// `tᵀ(u − u_pred)`, not as `tᵀu − tᵀu_pred`, which would lose its last
/// digits to cancellation when λ is large.
pub(super) struct ExactNewton<'a, S> {
    pub(super) system: &'a mut S,
    pub(super) jac: &'a mut Mat<f64>,
    pub(super) r_lambda: &'a mut [f64],
    pub(super) pred: &'a Prediction<'a>,
}

impl<S: PathSystem> NewtonSystem for ExactNewton<'_, S> {
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        let m = self.r_lambda.len();
        match (x.split_at_checked(m), r.split_at_mut_checked(m)) {
            (Some((u, &[lambda])), Some((r_u, [r_c]))) => {
                self.system.residual_jacobian(u, lambda, r_u, self.jac);
                *r_c = self.pred.constraint(x);
            }
            _ => r.fill(f64::NAN),
        }
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        let m = self.r_lambda.len();
        if let Some((u, &[lambda])) = x.split_at_checked(m) {
            self.system.d_residual_d_lambda(u, lambda, self.r_lambda);
        }
        let row = self.pred.row();
        let mut rows = out.chunks_exact_mut(m + 1);
        // r_lambda first: zip must not pull (and drop) the constraint row.
        for (i, (r_l, out_row)) in self.r_lambda.iter().zip(rows.by_ref()).enumerate() {
            for (j, v) in out_row.iter_mut().take(m).enumerate() {
                *v = self.jac[(i, j)];
            }
            if let Some(last) = out_row.last_mut() {
                *last = *r_l;
            }
        }
        if let Some(last_row) = rows.next() {
            last_row.copy_from_slice(&row);
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

/// A predicted point and the constraint that closes the corrector's system.
pub(super) struct Prediction<'a> {
    pub(super) u_pred: &'a [f64],
    pub(super) tangent: &'a [f64],
    /// Correct on `λ = fix` (landing on a bound) instead of `tᵀ(u − u_pred) = 0`.
    pub(super) fix: Option<f64>,
}

impl Prediction<'_> {
    /// The constraint's gradient: the tangent (borrowed, no copy per point),
    /// or `e_{m+1}` on `λ = fix`.
    pub(super) fn row(&self) -> Cow<'_, [f64]> {
        match self.fix {
            Some(_) => {
                let mut row = vec![0.0; self.tangent.len()];
                row[self.tangent.len() - 1] = 1.0;
                Cow::Owned(row)
            }
            None => Cow::Borrowed(self.tangent),
        }
    }

    /// The constraint `tᵀ(u − u_pred)`, or `λ − λ_fix`.
    pub(super) fn constraint(&self, u: &[f64]) -> f64 {
        match self.fix {
            Some(l) => u[u.len() - 1] - l,
            None => self
                .tangent
                .iter()
                .zip(u.iter().zip(self.u_pred))
                .map(|(t, (a, b))| t * (a - b))
                .sum(),
        }
    }
}
