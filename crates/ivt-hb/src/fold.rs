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
//! [`crate::FamilyBranch`] is the harmonic-balance residual (Eq. 61) in any
//! parameter λ (e.g. `|w| (&problem, w)` for λ = ω_f, the branch of a
//! frequency-response curve) with the exact Galerkin Jacobian (Eq. 56).

use crate::broyden::SolveError;
use crate::ihb::HbError;
use ivt_num::vector::norm2;
use ivt_num::StepCheck;
use ivt_num::{newton, BorderedLu, LuWorkspace, NewtonOptions, NewtonSystem, NewtonWorkspace};
use std::convert::Infallible;

pub use crate::branch::{
    bilinear_lambda_difference, fd_jacobian_gradient, residual_lambda_difference, Branch,
};

/// Options of the fold Newton iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldOptions {
    /// Stop when the Newton step is below `step_tol` relative to the scale of `q`
    /// (‖q‖∞) and of λ.
    pub step_tol: f64,
    /// Also stop when the step is below `noise_tol` (relative) and ‖(R, g)‖ no
    /// longer falls by 4× per step: the noise floor of a finite-difference `∂g`
    /// (a user `g` without analytic Jacobian) is reached.
    pub noise_tol: f64,
    /// Maximum Newton steps.
    pub max_iter: usize,
    /// Relative central-difference step for `∂g/∂λ` and `∂R/∂λ`.
    pub fd_step: f64,
}

impl Default for FoldOptions {
    fn default() -> Self {
        Self {
            step_tol: 1e-12,
            noise_tol: 1e-8,
            max_iter: 25,
            fd_step: 1e-6,
        }
    }
}

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
    m: usize,
    jac: Vec<f64>,
    lu: BorderedLu,
    rhs: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
}

impl Bordered {
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
        let m = self.m;
        if !jac_current {
            branch.jacobian(q, lambda, &mut self.jac);
        }
        if self.lu.factor(&self.jac, &self.b, &self.c, &[0.0]).is_err() {
            return f64::NAN;
        }
        self.rhs.fill(0.0);
        self.rhs[m] = 1.0;
        if self.lu.solve(&mut self.rhs).is_err() {
            return f64::NAN;
        }
        v.copy_from_slice(&self.rhs[..m]);
        let g = self.rhs[m];
        self.rhs.fill(0.0);
        self.rhs[m] = 1.0;
        if self.lu.solve_transpose(&mut self.rhs).is_err() {
            return f64::NAN;
        }
        w.copy_from_slice(&self.rhs[..m]);
        if v.iter().chain(w.iter()).all(|x| x.is_finite()) {
            g
        } else {
            f64::NAN
        }
    }
}

/// Two steps of inverse iteration with the factored `J` (or `Jᵀ`) from `v`,
/// normalised.
pub(crate) fn null_vector(lu: &mut LuWorkspace, v: &mut [f64], transpose: bool) -> bool {
    for _ in 0..2 {
        if transpose {
            lu.solve_transpose(v);
        } else {
            lu.solve(v);
        }
        let n = norm2(v);
        if n == 0.0 || !n.is_finite() {
            return false;
        }
        v.iter_mut().for_each(|x| *x /= n);
    }
    true
}

/// Locates the fold of `branch` nearest the converged point `(q0, λ0)`.
///
/// # Errors
/// [`HbError::Solve`]: [`SolveError::SingularJacobian`] if the bordered or extended
/// matrix is singular (e.g. a branch point rather than a fold),
/// [`SolveError::NonConvergence`] (with the ‖(R, g)‖ history) when Newton does
/// not settle within `max_iter` steps, [`SolveError::NonFinite`] for NaN.
pub fn locate_fold<B: Branch>(
    branch: &mut B,
    q0: &[f64],
    lambda0: f64,
    opts: &FoldOptions,
) -> Result<FoldLocation, HbError> {
    let m = branch.len();
    if q0.len() != m {
        return Err(HbError::InvalidInput(format!(
            "fold start must have {m} entries, got {}",
            q0.len()
        )));
    }
    if !(lambda0.is_finite() && q0.iter().all(|v| v.is_finite())) {
        return Err(HbError::Solve(SolveError::NonFinite {
            iteration: 0,
            history: Vec::new(),
        }));
    }
    let n1 = m + 1;
    let mut bd = Bordered {
        m,
        jac: vec![0.0; m * m],
        lu: BorderedLu::new(m, 1),
        rhs: vec![0.0; n1],
        b: vec![1.0 / (m as f64).sqrt(); m],
        c: vec![1.0 / (m as f64).sqrt(); m],
    };
    // Borders: the approximate left/right null vectors of J at the start.
    branch.jacobian(q0, lambda0, &mut bd.jac);
    let mut lu = LuWorkspace::new(m);
    // J is near-singular at a fold: only a non-finite factor is refused here.
    lu.factor_row_major(&bd.jac);
    if !null_vector(&mut lu, &mut bd.c, false) || !null_vector(&mut lu, &mut bd.b, true) {
        return Err(HbError::Solve(SolveError::SingularJacobian {
            iteration: 0,
            history: Vec::new(),
        }));
    }
    let mut x = q0.to_vec();
    x.push(lambda0);
    let mut system = FoldSystem {
        branch,
        bd,
        jac_current: true,
        fd_step: opts.fd_step,
        r_lambda: vec![0.0; m],
        v: vec![0.0; m],
        w: vec![0.0; m],
        grad: vec![0.0; m],
        step_tol: opts.step_tol,
        noise_tol: opts.noise_tol,
    };
    let nopts = NewtonOptions {
        ftol: 0.0,
        max_iter: opts.max_iter,
        max_halvings: 0,
        accept_no_descent: true,
        ..NewtonOptions::default()
    };
    let mut ws = NewtonWorkspace::new(n1);
    let stats = newton(&mut system, &mut x, &mut ws, &nopts).map_err(SolveError::from)?;
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
    step_tol: f64,
    noise_tol: f64,
}

impl<B: Branch> NewtonSystem for FoldSystem<'_, B> {
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        let m = self.bd.m;
        let (q, lambda) = (&x[..m], x[m]);
        self.branch.residual(q, lambda, &mut r[..m]);
        let current = std::mem::replace(&mut self.jac_current, false);
        r[m] = self
            .bd
            .solve_pair(self.branch, (q, lambda), current, &mut self.v, &mut self.w);
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        let m = self.bd.m;
        let (q, lambda) = (&x[..m], x[m]);
        let h_lambda = self.fd_step * lambda.abs().max(f64::MIN_POSITIVE);
        let branch = &mut *self.branch;
        branch.residual_lambda(q, lambda, h_lambda, &mut self.r_lambda);
        let g_lambda = -branch.bilinear_lambda(q, lambda, h_lambda, &self.w, &self.v);
        branch.jacobian_gradient(q, lambda, &self.w, &self.v, &mut self.grad);
        let n1 = m + 1;
        for ((row, j_row), r_l) in jac
            .chunks_exact_mut(n1)
            .zip(self.bd.jac.chunks_exact(m))
            .zip(&self.r_lambda)
        {
            row[..m].copy_from_slice(j_row);
            row[m] = *r_l;
        }
        let last = &mut jac[m * n1..];
        last.iter_mut().zip(&self.grad).for_each(|(o, g)| *o = -g);
        last[m] = g_lambda;
        Ok(())
    }

    fn check_step(
        &mut self,
        x: &[f64],
        step: &[f64],
        history: &[f64],
    ) -> Result<StepCheck, Infallible> {
        Ok(extended_step_check(
            (x, step, self.bd.m),
            history,
            (self.step_tol, self.noise_tol),
            f64::MIN_POSITIVE,
        ))
    }
}

/// The stopping rule of the extended-system Newton iterations (folds,
/// bifurcations): the step `(Δq, Δλ)` below `step_tol` relative to ‖q‖∞
/// (before the step) and to `max(|λ|, lambda_floor)`, or below `noise_tol`
/// once ‖F‖ no longer falls by 4× per step — the noise floor of the
/// finite differences in their Jacobians (a user `g` without an analytic
/// Jacobian). `x` is `(q, λ, …)` after the step with `q` of `m` entries,
/// `history` the ‖F‖ history up to the point after the step.
pub(crate) fn extended_step_check(
    (x, step, m): (&[f64], &[f64], usize),
    history: &[f64],
    (step_tol, noise_tol): (f64, f64),
    lambda_floor: f64,
) -> StepCheck {
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
            && d_lambda.abs() <= tol * lambda.abs().max(lambda_floor)
    };
    // ‖F‖ at the point the step left, against the one before it.
    let stalled = match history {
        [.., before, left, _] => *left > 0.25 * before,
        _ => false,
    };
    if below(step_tol) || (stalled && below(noise_tol)) {
        StepCheck::Converged
    } else {
        StepCheck::Continue
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ihb::HbOptions;
    use crate::problem::PeriodicProblem;

    /// `R = (q₀² − 2q₀ + 2 − λ, q₁ − q₀³)`: along the branch `λ = (q₀ − 1)² + 1`,
    /// a fold at `q = (1, 1)`, `λ = 1`.
    struct Parabola;

    impl Branch for Parabola {
        fn len(&self) -> usize {
            2
        }
        fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
            r[0] = q[0] * q[0] - 2.0 * q[0] + 2.0 - lambda;
            r[1] = q[1] - q[0] * q[0] * q[0];
        }
        fn jacobian(&mut self, q: &[f64], _lambda: f64, jac: &mut [f64]) {
            jac.copy_from_slice(&[2.0 * q[0] - 2.0, 0.0, -3.0 * q[0] * q[0], 1.0]);
        }
    }

    /// `g = [0.5x₀³ + 0.1x₀²v₁ + 0.2 sin θ x₁, 0.3v₁²x₁]`, `f = [cos θ, 0]`.
    struct Coupled;

    impl PeriodicProblem for Coupled {
        fn n_dof(&self) -> usize {
            2
        }
        fn mass(&self) -> &[f64] {
            &[1.0, 0.0, 0.0, 1.0]
        }
        fn damping(&self) -> &[f64] {
            &[0.05, 0.0, 0.0, 0.05]
        }
        fn stiffness(&self) -> &[f64] {
            &[2.0, -1.0, -1.0, 2.0]
        }
        fn nonlinear(&self, x: &[f64], v: &[f64], th: f64, g: &mut [f64]) {
            g[0] = 0.5 * x[0].powi(3) + 0.1 * x[0] * x[0] * v[1] + 0.2 * th.sin() * x[1];
            g[1] = 0.3 * v[1] * v[1] * x[1];
        }
        fn excitation(&self, th: f64, f: &mut [f64]) {
            f[0] = th.cos();
            f[1] = 0.0;
        }
        fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], th: f64, dg: &mut [f64]) {
            let (dg_dx, dg_dv) = dg.split_at_mut(4);
            dg_dx.copy_from_slice(&[
                1.5 * x[0] * x[0] + 0.2 * x[0] * v[1],
                0.2 * th.sin(),
                0.0,
                0.3 * v[1] * v[1],
            ]);
            dg_dv.copy_from_slice(&[0.0, 0.1 * x[0] * x[0], 0.0, 0.6 * v[1] * x[1]]);
        }
    }

    #[test]
    fn hb_gradient_matches_differences_of_the_assembled_jacobian() {
        // 2 DOF, cubic and velocity-dependent coupling, θ-dependent term, with
        // analytic ∂g: the quadrature form of ∂(wᵀJv)/∂q against 2m assembled
        // Jacobians (central differences, error ~1e-10 relative).
        let problem = Coupled;
        let opts = HbOptions::new(4, 16);
        let mut branch = crate::FamilyBranch::new(|w: f64| (&problem, w), &opts, 1.2).unwrap();
        let m = branch.len();
        let pattern = |k: usize, a: f64| (a * (k as f64 + 1.0)).sin() / (1.0 + k as f64);
        let q: Vec<f64> = (0..m).map(|k| pattern(k, 1.3)).collect();
        let w: Vec<f64> = (0..m).map(|k| pattern(k, 0.7)).collect();
        let v: Vec<f64> = (0..m).map(|k| pattern(k, 2.1)).collect();
        let (mut fast, mut slow) = (vec![0.0; m], vec![0.0; m]);
        branch.jacobian_gradient(&q, 1.2, &w, &v, &mut fast);
        fd_jacobian_gradient(&mut branch, &q, 1.2, &w, &v, 1e-5, &mut slow);
        let scale = slow.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        assert!(scale > 0.01, "{slow:?}");
        for (a, b) in fast.iter().zip(&slow) {
            assert!((a - b).abs() < 1e-7 * scale, "{fast:?}\n{slow:?}");
        }
    }

    #[test]
    fn newton_lands_on_the_turning_point_of_a_parabola() {
        // Start on the branch at q₀ = 1.3 (λ = 1.09): the fold is 0.3 away.
        let q0 = [1.3, 1.3f64.powi(3)];
        let f = locate_fold(&mut Parabola, &q0, 1.09, &FoldOptions::default()).unwrap();
        assert!((f.lambda - 1.0).abs() < 1e-13, "{f:?}");
        // The extended system is regular at the fold: q converges as fast as λ.
        assert!(
            (f.q[0] - 1.0).abs() < 1e-12 && (f.q[1] - 1.0).abs() < 1e-12,
            "{f:?}"
        );
        assert!(f.residual_norm < 1e-12 && f.iterations <= 8, "{f:?}");
    }
}
