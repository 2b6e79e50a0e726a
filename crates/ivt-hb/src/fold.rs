//! Folds (turning points) of a solution branch `R(q, λ) = 0`, located by Newton's
//! method on the minimally extended system (Govaerts' bordering)
//!
//! `R(q, λ) = 0`,  `g(q, λ) = 0`,  where  `[[J, b], [cᵀ, 0]] [v; g] = [0; 1]`,
//!
//! `J = ∂R/∂q`. `g` vanishes exactly where `J` is singular, and for borders `b`, `c`
//! near the left and right null vectors the bordered matrix stays regular there, so
//! Newton on `{q, λ}` converges quadratically to the fold itself (not to a bracket
//! between two path points). `∂g/∂(q, λ)` is taken by central differences of `g`
//! with steps relative to the solution's scale; `∂R/∂λ` likewise.
//!
//! [`HbBranch`] is the harmonic-balance residual (Eq. 61) in λ = ω_f with the exact
//! Galerkin Jacobian (Eq. 56), the branch of a frequency-response curve.

use crate::broyden::SolveError;
use crate::dense::{norm2, solve_dense};
use crate::ihb::{GalerkinJacobian, HbError, HbOptions, HbResidual};
use crate::problem::PeriodicProblem;

/// A one-parameter family of square systems `R(q, λ) = 0` with `∂R/∂q`.
pub trait Branch {
    /// Number of unknowns `m` (λ excluded).
    fn len(&self) -> usize;
    /// True for a branch without unknowns.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `R(q, λ)` into `r` (`m`).
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]);
    /// `∂R/∂q` at `(q, λ)`, row-major `m×m`, into `jac`.
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]);
}

/// The HB residual Eq. 61 of `problem` as a branch in the excitation frequency ω_f.
pub struct HbBranch<'a, P> {
    problem: &'a P,
    res: HbResidual,
    galerkin: GalerkinJacobian,
}

impl<'a, P: PeriodicProblem> HbBranch<'a, P> {
    /// Plans the residual and the Galerkin quadrature.
    ///
    /// # Errors
    /// As [`HbResidual::new`].
    pub fn new(problem: &'a P, opts: &HbOptions) -> Result<Self, HbError> {
        let res = HbResidual::new(problem, opts)?;
        let galerkin = GalerkinJacobian::new(&res);
        Ok(Self {
            problem,
            res,
            galerkin,
        })
    }
}

impl<P: PeriodicProblem> Branch for HbBranch<'_, P> {
    fn len(&self) -> usize {
        self.res.len()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        self.res.eval(self.problem, q, lambda, 1.0, r);
    }
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        self.galerkin
            .assemble(&mut self.res, self.problem, q, lambda, 1.0, jac);
    }
}

/// Options of the fold Newton iteration.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldOptions {
    /// Stop when the Newton step is below `step_tol` relative to the scale of `q`
    /// (‖q‖∞) and of λ.
    pub step_tol: f64,
    /// Maximum Newton steps.
    pub max_iter: usize,
    /// Relative central-difference step for `∂g/∂(q, λ)` and `∂R/∂λ`.
    pub fd_step: f64,
}

impl Default for FoldOptions {
    fn default() -> Self {
        Self {
            step_tol: 1e-12,
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

/// Scratch of the bordered solves.
struct Bordered {
    m: usize,
    jac: Vec<f64>,
    big: Vec<f64>,
    rhs: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
}

impl Bordered {
    /// `g` of the bordered system at `(q, λ)` (and `J` left in `self.jac`).
    fn test_function<B: Branch>(&mut self, branch: &mut B, q: &[f64], lambda: f64) -> f64 {
        let m = self.m;
        let n1 = m + 1;
        branch.jacobian(q, lambda, &mut self.jac);
        for i in 0..m {
            self.big[i * n1..i * n1 + m].copy_from_slice(&self.jac[i * m..(i + 1) * m]);
            self.big[i * n1 + m] = self.b[i];
        }
        self.big[m * n1..m * n1 + m].copy_from_slice(&self.c);
        self.big[m * n1 + m] = 0.0;
        self.rhs.fill(0.0);
        self.rhs[m] = 1.0;
        if solve_dense(&self.big, n1, &mut self.rhs, false) {
            self.rhs[m]
        } else {
            f64::NAN
        }
    }
}

/// Two steps of inverse iteration with `J` (or `Jᵀ`) from `v`, normalised.
fn null_vector(jac: &[f64], m: usize, v: &mut [f64], transpose: bool) -> bool {
    for _ in 0..2 {
        if !solve_dense(jac, m, v, transpose) {
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
        big: vec![0.0; n1 * n1],
        rhs: vec![0.0; n1],
        b: vec![1.0 / (m as f64).sqrt(); m],
        c: vec![1.0 / (m as f64).sqrt(); m],
    };
    let singular = |iteration, history: &[f64]| {
        HbError::Solve(SolveError::SingularJacobian {
            iteration,
            history: history.to_vec(),
        })
    };
    // Borders: the approximate left/right null vectors of J at the start.
    branch.jacobian(q0, lambda0, &mut bd.jac);
    if !null_vector(&bd.jac, m, &mut bd.c, false) || !null_vector(&bd.jac, m, &mut bd.b, true) {
        return Err(singular(0, &[]));
    }
    let mut q = q0.to_vec();
    let mut lambda = lambda0;
    let mut r = vec![0.0; m];
    let mut rp = vec![0.0; m];
    let mut rm = vec![0.0; m];
    let mut xt = vec![0.0; m];
    let mut newton = vec![0.0; n1 * n1];
    let mut step = vec![0.0; n1];
    let mut history = Vec::with_capacity(opts.max_iter + 1);
    for it in 0..=opts.max_iter {
        branch.residual(&q, lambda, &mut r);
        let g = bd.test_function(branch, &q, lambda);
        let norm = (norm2(&r).powi(2) + g * g).sqrt();
        history.push(norm);
        if !norm.is_finite() {
            return Err(HbError::Solve(SolveError::NonFinite {
                iteration: it,
                history,
            }));
        }
        if it == opts.max_iter {
            break;
        }
        // Newton matrix [[J, R_λ], [g_q, g_λ]] with J from the test-function call.
        for i in 0..m {
            newton[i * n1..i * n1 + m].copy_from_slice(&bd.jac[i * m..(i + 1) * m]);
        }
        let q_scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let h_lambda = opts.fd_step * lambda.abs().max(f64::MIN_POSITIVE);
        branch.residual(&q, lambda + h_lambda, &mut rp);
        branch.residual(&q, lambda - h_lambda, &mut rm);
        for i in 0..m {
            newton[i * n1 + m] = (rp[i] - rm[i]) / (2.0 * h_lambda);
        }
        let gp = bd.test_function(branch, &q, lambda + h_lambda);
        let gm = bd.test_function(branch, &q, lambda - h_lambda);
        newton[m * n1 + m] = (gp - gm) / (2.0 * h_lambda);
        xt.copy_from_slice(&q);
        for k in 0..m {
            let h = opts.fd_step * q[k].abs().max(q_scale).max(f64::MIN_POSITIVE);
            xt[k] = q[k] + h;
            let gp = bd.test_function(branch, &xt, lambda);
            xt[k] = q[k] - h;
            let gm = bd.test_function(branch, &xt, lambda);
            xt[k] = q[k];
            newton[m * n1 + k] = (gp - gm) / (2.0 * h);
        }
        for i in 0..m {
            step[i] = -r[i];
        }
        step[m] = -g;
        if !solve_dense(&newton, n1, &mut step, false) {
            return Err(singular(it, &history));
        }
        for i in 0..m {
            q[i] += step[i];
        }
        lambda += step[m];
        let dq = step[..m].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if dq <= opts.step_tol * q_scale.max(f64::MIN_POSITIVE)
            && step[m].abs() <= opts.step_tol * lambda.abs()
        {
            branch.residual(&q, lambda, &mut r);
            return Ok(FoldLocation {
                q,
                lambda,
                iterations: it + 1,
                residual_norm: norm2(&r),
            });
        }
    }
    Err(HbError::Solve(SolveError::NonConvergence {
        iterations: opts.max_iter,
        history,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

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
