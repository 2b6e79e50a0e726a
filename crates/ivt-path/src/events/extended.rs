//! The Newton iteration every event locator runs: on a minimally extended
//! system `[R(q, λ) + Σⱼ μⱼ bⱼ; ψ(q, λ)] = 0` (Govaerts' bordering: `ψ` the
//! test functions of a bordered matrix that turns singular at the event, `μ`
//! unfoldings that make the system square) through [`ivt_num::newton()`],
//! stopped by one [`StepRule`], with the small pieces the locators share
//! (borders from inverse iteration, the `[R_q, R_λ]` blocks, the result).

use super::detector::{Bifurcation, BifurcationKind, LocateOptions};
use crate::branch::{full_newton_steps, residual_lambda_difference, Branch};
use crate::error::PathError;
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::SolveError;
use ivt_num::{
    newton, BorderedError, BorderedLu, LuWorkspace, NewtonOptions, NewtonSystem, NewtonWorkspace,
    StepCheck,
};
use std::convert::Infallible;

/// The error of a singular matrix before the first Newton step.
pub fn singular_at_start() -> SolveError {
    SolveError::SingularJacobian {
        iteration: 0,
        history: Vec::new(),
    }
}

/// Refuses a start `(q0, λ0)` of the wrong size, of an empty branch, or not
/// finite.
///
/// # Errors
/// [`PathError::InvalidInput`] for sizes, [`SolveError::NonFinite`] for NaN or ∞.
pub fn check_start<B: Branch>(branch: &B, q0: &[f64], lambda0: f64) -> Result<(), PathError> {
    if q0.len() != branch.len() || q0.is_empty() {
        return Err(PathError::InvalidInput(format!(
            "start must have {} entries (at least one), got {}",
            branch.len(),
            q0.len()
        )));
    }
    if !(lambda0.is_finite() && q0.iter().all(|v| v.is_finite())) {
        return Err(PathError::Solve(SolveError::NonFinite {
            iteration: 0,
            history: Vec::new(),
        }));
    }
    Ok(())
}

/// The located bifurcation with its residual norm ‖R(q, λ)‖₂.
pub fn finish<B: Branch>(
    branch: &mut B,
    kind: BifurcationKind,
    (q, lambda): (Vec<f64>, f64),
    multipliers: Vec<c64>,
    null_vectors: Vec<Vec<f64>>,
    iterations: usize,
) -> Bifurcation {
    let mut r = vec![0.0; q.len()];
    branch.residual(&q, lambda, &mut r);
    Bifurcation {
        kind,
        q,
        lambda,
        multipliers,
        null_vectors,
        iterations,
        residual_norm: norm2(&r),
    }
}

/// Two steps of inverse iteration with the factored `J` (or `Jᵀ`) from `v`,
/// normalised; `false` if the iterate vanishes or is not finite.
pub fn null_vector(lu: &mut LuWorkspace, v: &mut [f64], transpose: bool) -> bool {
    inverse_iteration(v, |v| {
        if transpose {
            lu.solve_transpose(v);
        } else {
            lu.solve(v);
        }
        true
    })
}

/// Two steps of inverse iteration from `v` with `solve` (`v ← A⁻¹v`,
/// `false` if the solve is refused), normalised each time; `false` if the
/// iterate vanishes or is not finite.
fn inverse_iteration(v: &mut [f64], mut solve: impl FnMut(&mut [f64]) -> bool) -> bool {
    for _ in 0..2 {
        if !solve(v) {
            return false;
        }
        let n = norm2(v);
        if n == 0.0 || !n.is_finite() {
            return false;
        }
        v.iter_mut().for_each(|x| *x /= n);
    }
    true
}

/// A unit null vector of the near-singular row-major `m×m` matrix `jac`: two
/// steps of inverse iteration ([`null_vector`]) from the uniform seed; `None`
/// if they break down. A factor singular to rounding still serves (the solve
/// is checked instead).
pub fn unit_null_vector(jac: &[f64], m: usize) -> Option<Vec<f64>> {
    let mut lu = LuWorkspace::new(m);
    let mut v = vec![1.0 / (m as f64).sqrt(); m];
    lu.factor_row_major(jac);
    null_vector(&mut lu, &mut v, false).then_some(v)
}

/// Right and left near-null vectors of the near-singular square row-major `a`,
/// refined in place from their seeds; only a non-finite factor is refused.
///
/// # Errors
/// [`SolveError::SingularJacobian`] when inverse iteration breaks down.
pub fn border_null_vectors(
    a: &[f64],
    right: &mut [f64],
    left: &mut [f64],
) -> Result<(), SolveError> {
    let mut lu = LuWorkspace::new(right.len());
    // `a` is near-singular at an event: only a non-finite factor is refused.
    lu.factor_row_major(a);
    if !null_vector(&mut lu, right, false) || !null_vector(&mut lu, left, true) {
        return Err(singular_at_start());
    }
    Ok(())
}

/// Right and left near-null vectors of the bordered matrix `[[J, b], [cᵀ, d]]`
/// (`b = r_lambda`, `[cᵀ, d] = row`: the augmented Jacobian
/// `[[R_q, R_λ], [uᵀ]]` of a branch point), factored once by `lu`
/// ([`BorderedLu`], `m` and one border) and refined in place from their
/// seeds by inverse iteration; only a non-finite factor is refused.
///
/// # Errors
/// [`SolveError::SingularJacobian`] when inverse iteration breaks down.
pub fn augmented_null_vectors(
    lu: &mut BorderedLu,
    (jac, r_lambda, row): (&[f64], &[f64], &[f64]),
    right: &mut [f64],
    left: &mut [f64],
) -> Result<(), SolveError> {
    let Some((corner, c)) = row.split_last() else {
        return Err(singular_at_start());
    };
    // Near-singular at the event: only sizes that do not fit are refused.
    let usable = factored(lu.factor(jac, r_lambda, c, std::slice::from_ref(corner)));
    if !usable
        || !inverse_iteration(right, |v| lu.solve(v).is_ok())
        || !inverse_iteration(left, |v| lu.solve_transpose(v).is_ok())
    {
        return Err(singular_at_start());
    }
    Ok(())
}

/// A factorization usable for solves: regular, or singular to rounding
/// (inverse iteration and test functions at a bifurcation accept it and
/// check the solution); not one refused for its sizes.
pub fn factored(result: Result<(), BorderedError>) -> bool {
    matches!(result, Ok(()) | Err(BorderedError::Singular))
}

/// Writes `[J | R_λ]` (`m` rows) into the first `m + 1` columns of the row-major
/// matrix `dst` with row stride `stride` (> `m`).
pub fn put_jacobian(dst: &mut [f64], stride: usize, jac: &[f64], r_lambda: &[f64]) {
    let m = r_lambda.len();
    if m == 0 || stride <= m {
        return;
    }
    for ((row, j_row), r_l) in dst
        .chunks_exact_mut(stride)
        .zip(jac.chunks_exact(m))
        .zip(r_lambda)
    {
        if let Some((head, rest)) = row.split_at_mut_checked(m) {
            head.copy_from_slice(j_row);
            if let Some(c) = rest.first_mut() {
                *c = *r_l;
            }
        }
    }
}

/// The central-difference step in λ of the locators' `∂R/∂λ` and test
/// functions: `fd_step·max(|λ|, 1e-3)`.
pub fn lambda_step(opts: &LocateOptions, lambda: f64) -> f64 {
    opts.fd_step * lambda.abs().max(1e-3)
}

/// `R(q, λ)` of a [`Branch`] as a system in the unknowns `x = {q, λ}` (one
/// row fewer than unknowns, closed by the caller's border rows through
/// [`ivt_num::newton_bordered`]: a step off a bifurcation, a fixed
/// component), with the Jacobian `[R_q, R_λ]` (`R_λ` by the central
/// difference of [`lambda_step`]).
pub struct BranchWithLambda<'a, B> {
    branch: &'a mut B,
    opts: &'a LocateOptions,
    jac: Vec<f64>,
    r_lambda: Vec<f64>,
}

impl<'a, B: Branch> BranchWithLambda<'a, B> {
    /// The system of `branch`, `R_λ` with the step of `opts`.
    pub fn new(branch: &'a mut B, opts: &'a LocateOptions) -> Self {
        let m = branch.len();
        Self {
            branch,
            opts,
            jac: vec![0.0; m * m],
            r_lambda: vec![0.0; m],
        }
    }
}

impl<B: Branch> NewtonSystem for BranchWithLambda<'_, B> {
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        if let Some((&lambda, q)) = x.split_last() {
            self.branch.residual(q, lambda, r);
        }
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        let Some((&lambda, q)) = x.split_last() else {
            return Ok(());
        };
        self.branch.jacobian(q, lambda, &mut self.jac);
        let h = lambda_step(self.opts, lambda);
        residual_lambda_difference(self.branch, q, lambda, h, &mut self.r_lambda);
        put_jacobian(jac, q.len() + 1, &self.jac, &self.r_lambda);
        Ok(())
    }
}

/// The blocks `R_q` (row-major `m×m`) and `R_λ` of `[R_q, R_λ]` at `(q, λ)`,
/// `R_λ` by a central difference with [`lambda_step`].
pub fn jacobian_blocks<B: Branch>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    opts: &LocateOptions,
) -> (Vec<f64>, Vec<f64>) {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    let mut r_lambda = vec![0.0; m];
    branch.jacobian(q, lambda, &mut jac);
    residual_lambda_difference(branch, q, lambda, lambda_step(opts, lambda), &mut r_lambda);
    (jac, r_lambda)
}

/// The stopping rule of every extended-system Newton iteration (folds and
/// bifurcations): the step `(Δq, Δλ)` below `step_tol` relative to ‖q‖∞
/// (before the step) and to `max(|λ|, lambda_floor)`, or below `noise_tol`
/// once ‖F‖ no longer falls by 4× per step — the noise floor of the finite
/// differences in their Jacobians (a user `g` without an analytic
/// Jacobian). Full Newton steps, no residual test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRule {
    /// Unknowns `q` (the entries before λ).
    pub m: usize,
    /// See [`LocateOptions::step_tol`].
    pub step_tol: f64,
    /// See [`LocateOptions::noise_tol`].
    pub noise_tol: f64,
    /// Smallest |λ| the λ step is taken relative to.
    pub lambda_floor: f64,
}

impl StepRule {
    /// The options of [`ivt_num::newton()`] under this rule: full steps, at
    /// most `max_iter`, stopped by [`Self::check`] only.
    pub fn newton_options(max_iter: usize, accept_near_singular: bool) -> NewtonOptions {
        NewtonOptions {
            accept_near_singular,
            ..full_newton_steps(0.0, max_iter)
        }
    }

    /// The verdict after a step: `x` is `(q, λ, …)` after the step with `q`
    /// of `m` entries, `history` the ‖F‖ history up to the point after it.
    pub fn check(&self, x: &[f64], step: &[f64], history: &[f64]) -> StepCheck {
        let m = self.m;
        let (Some(q), Some(dq), Some(lambda), Some(d_lambda)) =
            (x.get(..m), step.get(..m), x.get(m), step.get(m))
        else {
            return StepCheck::Continue;
        };
        let q_scale = q
            .iter()
            .zip(dq)
            .fold(0.0f64, |a, (qi, d)| a.max((qi - d).abs()));
        let dq = dq.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let below = |tol: f64| {
            dq <= tol * q_scale.max(f64::MIN_POSITIVE)
                && d_lambda.abs() <= tol * lambda.abs().max(self.lambda_floor)
        };
        // ‖F‖ at the point the step left, against the one before it.
        let stalled = match history {
            [.., before, left, _] => *left > 0.25 * before,
            _ => false,
        };
        if below(self.step_tol) || (stalled && below(self.noise_tol)) {
            StepCheck::Converged
        } else {
            StepCheck::Continue
        }
    }
}

/// An extended system stopped by its [`StepRule`]: the one
/// [`NewtonSystem::check_step`] of the locators.
pub struct Ruled<S> {
    /// The extended system.
    pub system: S,
    /// Its stopping rule.
    pub rule: StepRule,
}

impl<S: NewtonSystem> NewtonSystem for Ruled<S> {
    type Error = S::Error;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), S::Error> {
        self.system.residual(x, r)
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), S::Error> {
        self.system.jacobian(x, jac)
    }

    fn check_step(&mut self, x: &[f64], step: &[f64], h: &[f64]) -> Result<StepCheck, S::Error> {
        Ok(self.rule.check(x, step, h))
    }
}

/// Result of [`extended_newton`]: `(q, λ, iterations)`.
pub type Converged = (Vec<f64>, f64, usize);

/// Newton ([`ivt_num::newton()`]) on `[R(q, λ) + Σⱼ μⱼ bⱼ; ψ(q, λ)] = 0`,
/// unknowns `{q, λ, μ}` with `k = unfold.len() + 1` test functions `ψ` (the
/// unfoldings `μ` make it square). Full steps; stops by [`StepRule`].
///
/// # Errors
/// [`PathError::Solve`] with the ‖F‖ history for a singular extended
/// matrix, non-finite values or no convergence within `max_iter` steps.
pub fn extended_newton<B, T>(
    branch: &mut B,
    (q0, lambda0): (&[f64], f64),
    unfold: &[Vec<f64>],
    tests: T,
    opts: &LocateOptions,
) -> Result<Converged, PathError>
where
    B: Branch,
    T: FnMut(&mut B, &[f64], f64, &mut [f64]),
{
    let (extended, mut x) = Extended::at(branch, (q0, lambda0), unfold, tests, opts);
    let (m, n) = (extended.m, x.len());
    let mut system = Ruled {
        system: extended,
        rule: StepRule {
            m,
            step_tol: opts.step_tol,
            noise_tol: opts.noise_tol,
            lambda_floor: 1e-3,
        },
    };
    let nopts = StepRule::newton_options(opts.max_iter, true);
    let stats = newton(&mut system, &mut x, &mut NewtonWorkspace::new(n), &nopts)?;
    let lambda = x.get(m).copied().unwrap_or(lambda0);
    x.truncate(m);
    Ok((x, lambda, stats.iterations))
}

/// The Newton matrix of [`extended_newton`]'s system at `(q, λ)` with the
/// unfoldings `μ = 0` (row-major, `m + k` square, `k = unfold.len() + 1`):
/// `[[J, R_λ, b], [ψ_q, ψ_λ, 0]]`, the test rows by the same central
/// differences. The matrix whose transpose gives the adjoint of a located
/// event (ivt-hb's `analyses::sensitivity`).
pub fn extended_matrix<B, T>(
    branch: &mut B,
    (q, lambda): (&[f64], f64),
    unfold: &[Vec<f64>],
    tests: T,
    opts: &LocateOptions,
) -> Vec<f64>
where
    B: Branch,
    T: FnMut(&mut B, &[f64], f64, &mut [f64]),
{
    let (mut system, x) = Extended::at(branch, (q, lambda), unfold, tests, opts);
    let mut out = vec![0.0; x.len() * x.len()];
    let Ok(()) = system.jacobian(&x, &mut out);
    out
}

/// The extended system of [`extended_newton`] as a [`NewtonSystem`]:
/// `[J, R_λ, b]` analytic in `q` with `R_λ` by [`lambda_step`], the
/// test-function rows by central differences in `q` and λ.
struct Extended<'a, B, T> {
    branch: &'a mut B,
    unfold: &'a [Vec<f64>],
    tests: T,
    opts: &'a LocateOptions,
    m: usize,
    jac: Vec<f64>,
    r_lambda: Vec<f64>,
    psi: (Vec<f64>, Vec<f64>),
    qt: Vec<f64>,
}

impl<'a, B: Branch, T> Extended<'a, B, T> {
    /// The system of `branch` with `unfold` and `tests`, and its unknowns at
    /// `(q, λ)` with the unfoldings `μ = 0`: `[q, λ, 0, …]`.
    fn at(
        branch: &'a mut B,
        (q, lambda): (&[f64], f64),
        unfold: &'a [Vec<f64>],
        tests: T,
        opts: &'a LocateOptions,
    ) -> (Self, Vec<f64>) {
        let m = branch.len();
        let k = unfold.len() + 1;
        let mut x = q.to_vec();
        x.push(lambda);
        x.resize(m + k, 0.0);
        let system = Self {
            branch,
            unfold,
            tests,
            opts,
            m,
            jac: vec![0.0; m * m],
            r_lambda: vec![0.0; m],
            psi: (vec![0.0; k], vec![0.0; k]),
            qt: vec![0.0; m],
        };
        (system, x)
    }
}

impl<B, T> NewtonSystem for Extended<'_, B, T>
where
    B: Branch,
    T: FnMut(&mut B, &[f64], f64, &mut [f64]),
{
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        let m = self.m;
        let (Some((q, rest)), Some((r, psi))) =
            (x.split_at_checked(m), out.split_at_mut_checked(m))
        else {
            out.fill(f64::NAN);
            return Ok(());
        };
        let Some((&lambda, mu)) = rest.split_first() else {
            out.fill(f64::NAN);
            return Ok(());
        };
        self.branch.residual(q, lambda, r);
        for (b, mu_j) in self.unfold.iter().zip(mu) {
            r.iter_mut().zip(b).for_each(|(ri, bi)| *ri += mu_j * bi);
        }
        (self.tests)(self.branch, q, lambda, psi);
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], newton: &mut [f64]) -> Result<(), Infallible> {
        let m = self.m;
        let n = x.len();
        let (Some(q), Some(&lambda)) = (x.get(..m), x.get(m)) else {
            newton.fill(f64::NAN);
            return Ok(());
        };
        self.branch.jacobian(q, lambda, &mut self.jac);
        let h_lambda = lambda_step(self.opts, lambda);
        residual_lambda_difference(self.branch, q, lambda, h_lambda, &mut self.r_lambda);
        newton.fill(0.0);
        put_jacobian(newton, n, &self.jac, &self.r_lambda);
        for (i, row) in newton.chunks_exact_mut(n).take(m).enumerate() {
            let unfold_cols = row.iter_mut().skip(m + 1);
            for (entry, b) in unfold_cols.zip(self.unfold) {
                *entry = b.get(i).copied().unwrap_or(f64::NAN);
            }
        }
        // Test-function rows by central differences in q and λ.
        let q_scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        self.qt.copy_from_slice(q);
        let (psi_p, psi_m) = (&mut self.psi.0, &mut self.psi.1);
        for col in 0..=m {
            let h = match (q.get(col), self.qt.get_mut(col)) {
                (Some(&qc), Some(slot)) => {
                    let h = self.opts.fd_step * qc.abs().max(q_scale).max(f64::MIN_POSITIVE);
                    *slot = qc + h;
                    (self.tests)(self.branch, &self.qt, lambda, psi_p);
                    if let Some(slot) = self.qt.get_mut(col) {
                        *slot = qc - h;
                    }
                    (self.tests)(self.branch, &self.qt, lambda, psi_m);
                    if let Some(slot) = self.qt.get_mut(col) {
                        *slot = qc;
                    }
                    h
                }
                _ => {
                    (self.tests)(self.branch, q, lambda + h_lambda, psi_p);
                    (self.tests)(self.branch, q, lambda - h_lambda, psi_m);
                    h_lambda
                }
            };
            let rows = newton.chunks_exact_mut(n).skip(m);
            for (row, (p, mi)) in rows.zip(psi_p.iter().zip(psi_m.iter())) {
                if let Some(entry) = row.get_mut(col) {
                    *entry = (p - mi) / (2.0 * h);
                }
            }
        }
        Ok(())
    }
}
