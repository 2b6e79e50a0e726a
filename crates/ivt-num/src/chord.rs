//! The chord corrector: iterations on the factorization `A₀` of the
//! bordered matrix `[[J, R_λ], [tᵀ]]` the tangent left (no new
//! factorization), accelerated by Broyden's updates of it (Kelley's `brsol`:
//! the update of `A₀⁻¹` applied through the stored steps by
//! Sherman–Morrison), superlinear where the plain chord contracts linearly.
//! The first attempt of [`super::NewtonCorrector`], whose Newton takes over
//! where the chord does not contract.

use super::Prediction;
use crate::branch::Branch;
use ivt_num::vector::{dot, norm2};
use ivt_num::BorderedLu;
use ivt_num::SolveError;

/// The chord's state: the factored matrix, the iterate and the residual.
pub(super) struct Chord<'a> {
    /// The LU of `[[J, R_λ], [rowᵀ]]`.
    pub(super) aug: &'a mut BorderedLu,
    /// The iterate (`u` then λ), from the prediction; left at the best
    /// iterate on failure, for Newton to start from.
    pub(super) u: &'a mut [f64],
    /// `[R; constraint]` scratch; on entry with `start_residual_known`, its
    /// first `m` entries hold `R` at the start.
    pub(super) rhs: &'a mut [f64],
    /// Absolute tolerance on `‖[R; constraint]‖₂`.
    pub(super) tol: f64,
    /// Up to `3·max_newton` iterations while the chord contracts.
    pub(super) max_newton: usize,
}

impl Chord<'_> {
    /// Chord iterations from `u`: fails fast when the residual does not fall
    /// by ½ per iteration (over two) or grows. Returns the iteration count.
    pub(super) fn run<B: Branch>(
        &mut self,
        branch: &mut B,
        pred: &Prediction<'_>,
        start_residual_known: bool,
    ) -> Result<usize, SolveError> {
        let mut history: Vec<f64> = Vec::new();
        let mut steps: Vec<Vec<f64>> = Vec::new();
        let mut best = (f64::INFINITY, self.u.to_vec());
        for it in 0..=3 * self.max_newton {
            if it > 0 || !start_residual_known {
                if let (Some((&lambda, u)), Some((_, r))) =
                    (self.u.split_last(), self.rhs.split_last_mut())
                {
                    branch.residual(u, lambda, r);
                }
            }
            let constraint = pred.constraint(self.u);
            if let Some(c) = self.rhs.last_mut() {
                *c = constraint;
            }
            if let Some(done) = settle(&mut history, norm2(self.rhs), self.tol) {
                return done;
            }
            let now = history.last().copied().unwrap_or(f64::INFINITY);
            if now < best.0 {
                best.0 = now;
                best.1.copy_from_slice(self.u);
            }
            let before = |k: usize| {
                history
                    .len()
                    .checked_sub(k + 1)
                    .and_then(|i| history.get(i))
            };
            let grew = before(1).is_some_and(|b| now >= *b);
            if grew || before(2).is_some_and(|b| now > 0.25 * b) {
                break;
            }
            // z = −A₀⁻¹F, then the updates s_{j+1} s_jᵀ z / ‖s_j‖² in order.
            let mut z = self.rhs.to_vec();
            if self.aug.solve(&mut z).is_err() {
                break;
            }
            z.iter_mut().for_each(|v| *v = -*v);
            for pair in steps.windows(2) {
                if let [s0, s1] = pair {
                    let c = dot(s0, &z) / dot(s0, s0);
                    z.iter_mut().zip(s1).for_each(|(v, s)| *v += c * s);
                }
            }
            if let Some(last) = steps.last() {
                let denom = 1.0 - dot(last, &z) / dot(last, last);
                z.iter_mut().for_each(|v| *v /= denom);
            }
            for (x, d) in self.u.iter_mut().zip(&z) {
                *x += d;
            }
            steps.push(z);
        }
        self.u.copy_from_slice(&best.1);
        Err(SolveError::NonConvergence {
            iterations: history.len().saturating_sub(1),
            history,
        })
    }
}

/// Records a corrector's residual norm; `Some` once it is done: converged
/// (the iteration count) or non-finite (the error with the history).
fn settle(history: &mut Vec<f64>, norm: f64, tol: f64) -> Option<Result<usize, SolveError>> {
    let iteration = history.len();
    history.push(norm);
    if !norm.is_finite() {
        let history = std::mem::take(history);
        return Some(Err(SolveError::NonFinite { iteration, history }));
    }
    (norm <= tol).then_some(Ok(iteration))
}
