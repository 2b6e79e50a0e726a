//! Period doubling, Neimark–Sacker and branch points of a periodic-orbit branch
//! `R(q, λ) = 0` (the HB residual Eq. 61 of a [`Family`]), each located by Newton's
//! method on a minimally extended system, and branch switching at them.
//!
//! A bifurcation is a common zero of `R` and of bordered test functions
//! (Govaerts' bordering, as [`crate::fold`] does for folds): for a matrix `A(q, λ)`
//! that turns singular there, `[[A, b], [cᵀ, 0]] [v; g] = [0; 1]` gives a smooth `g`
//! that vanishes exactly where `A` is singular while the bordered matrix stays
//! regular (`b`, `c` near its left and right null vectors at the start).
//!
//! - **Period doubling**: `A = Φ + I`, `Φ` the monodromy matrix of the orbit
//!   (Hsu's method, Eq. 80): a multiplier −1.
//! - **Neimark–Sacker**: `A = Φ⊙Φ − I`, `Φ⊙Φ` the second compound (bialternate
//!   product) of `Φ`, whose eigenvalues are the products `μᵢμⱼ`, `i < j`: a complex
//!   pair on the unit circle (`μμ̄ = 1`). A real pair `μ, 1/μ` (neutral saddle)
//!   is also a zero and is reported as an error.
//! - **Branch point** (simple, located in [`crate::branch_point`]): `[∂R/∂q, ∂R/∂λ]` (m × (m+1)) loses rank; two
//!   test functions from the two-column bordering `[[R_x, b], [Cᵀ, 0]]`, and an
//!   unfolding `R + μ b = 0` with μ unknown make the system square and regular.
//!
//! `∂R/∂q` is the exact Galerkin Jacobian (Eq. 56); `∂R/∂λ` and the derivatives of
//! the test functions are central differences. Branch switching at the located
//! points is in [`crate::switching`].

use crate::broyden::SolveError;
use crate::family::{Family, FamilyBranch};
use crate::floquet::{eigenvalues, monodromy_uniform, HsuRule};
use crate::fold::{
    extended_step_check, null_vector, residual_lambda_difference as residual_lambda, Branch,
};
use crate::ihb::HbError;
use crate::stability::StabilityAnalyzer;
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::{
    newton, BorderedError, BorderedLu, LuWorkspace, NewtonOptions, NewtonSystem, NewtonWorkspace,
    StepCheck,
};
use std::convert::Infallible;
use thiserror::Error;

/// The kind of a located bifurcation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BifurcationKind {
    /// A turning point in λ (a real multiplier through +1), located by
    /// [`crate::fold::locate_fold`].
    Fold,
    /// A real Floquet multiplier through −1.
    PeriodDoubling,
    /// A complex pair of multipliers through the unit circle.
    NeimarkSacker,
    /// Two branches cross (rank loss of `[∂R/∂q, ∂R/∂λ]`).
    BranchPoint,
}

/// Options of the extended-system Newton iterations.
#[derive(Debug, Clone, PartialEq)]
pub struct BifurcationOptions {
    /// Hsu sub-intervals of the monodromy matrix (Magnus4; > harmonics).
    pub stability_steps: usize,
    /// Stop when the Newton step is below this, relative to ‖q‖∞ and |λ|.
    pub step_tol: f64,
    /// Also stop when the step is below this (relative) and the residual no
    /// longer falls by 4× per step (the noise floor of the differences).
    pub noise_tol: f64,
    /// Maximum Newton steps.
    pub max_iter: usize,
    /// Relative central-difference step for `∂R/∂λ` and the test functions.
    pub fd_step: f64,
}

impl Default for BifurcationOptions {
    fn default() -> Self {
        Self {
            stability_steps: 2048,
            step_tol: 1e-11,
            noise_tol: 1e-8,
            max_iter: 30,
            fd_step: 1e-6,
        }
    }
}

/// A located bifurcation.
#[derive(Debug, Clone, PartialEq)]
pub struct Bifurcation {
    /// What it is.
    pub kind: BifurcationKind,
    /// The orbit at the bifurcation.
    pub q: Vec<f64>,
    /// The parameter at the bifurcation.
    pub lambda: f64,
    /// Floquet multipliers there (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Branch point only: an orthonormal basis of the null space of
    /// `[∂R/∂q, ∂R/∂λ]` (two vectors of `m + 1` entries); empty otherwise.
    pub null_vectors: Vec<Vec<f64>>,
    /// Newton steps taken.
    pub iterations: usize,
    /// ‖R(q, λ)‖₂ at the result.
    pub residual_norm: f64,
}

impl Bifurcation {
    /// Branch point: the unit direction of the null space orthogonal to
    /// `tangent` (the tangent of the branch that was followed, `m + 1`
    /// entries): the initial direction of the other branch. `None` for other
    /// kinds.
    pub fn second_direction(&self, tangent: &[f64]) -> Option<Vec<f64>> {
        let [v1, v2] = self.null_vectors.as_slice() else {
            return None;
        };
        let (a, b) = (dot(tangent, v1), dot(tangent, v2));
        // In span{v1, v2} the direction orthogonal to (a, b) is (−b, a).
        let mut d: Vec<f64> = v1.iter().zip(v2).map(|(x, y)| -b * x + a * y).collect();
        let n = norm2(&d);
        if n == 0.0 || !n.is_finite() {
            return None;
        }
        d.iter_mut().for_each(|x| *x /= n);
        Some(d)
    }
}

/// Errors of bifurcation location.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum BifurcationError {
    /// Sizes, solves or Newton failures (with the residual history).
    #[error(transparent)]
    Hb(#[from] HbError),
    /// The Neimark–Sacker test converged to a real pair `μ, 1/μ`.
    #[error(
        "neutral saddle at λ = {lambda} (real multipliers μ and 1/μ), not a Neimark–Sacker point"
    )]
    NeutralSaddle {
        /// Where.
        lambda: f64,
    },
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn solve_error(e: SolveError) -> BifurcationError {
    BifurcationError::Hb(HbError::Solve(e))
}

/// The monodromy matrix Φ of the orbit `q` at λ (Hsu, Magnus4, `steps` steps).
pub(crate) struct Monodromy {
    analyzer: StabilityAnalyzer,
    steps: usize,
    dim: usize,
    phi: Vec<f64>,
}

impl Monodromy {
    pub(crate) fn new<F: Family>(
        branch: &FamilyBranch<F>,
        lambda: f64,
        steps: usize,
    ) -> Result<Self, HbError> {
        let problem = branch.family().at(lambda).0;
        let analyzer = StabilityAnalyzer::new(&problem, branch.options().harmonics, steps)?;
        let dim = 2 * crate::PeriodicProblem::n_dof(&problem);
        Ok(Self {
            analyzer,
            steps,
            dim,
            phi: vec![0.0; dim * dim],
        })
    }

    fn eval<F: Family>(&mut self, branch: &FamilyBranch<F>, q: &[f64], lambda: f64) -> &[f64] {
        let (problem, sol) = branch.solution(q, lambda);
        let theta = self.analyzer.theta_samples(&problem, &sol);
        let period = 2.0 * std::f64::consts::PI;
        monodromy_uniform(
            self.dim,
            theta,
            self.steps,
            period,
            HsuRule::Magnus4,
            &mut self.phi,
        );
        &self.phi
    }

    pub(crate) fn multipliers<F: Family>(
        &mut self,
        branch: &FamilyBranch<F>,
        q: &[f64],
        lambda: f64,
    ) -> Vec<c64> {
        let dim = self.dim;
        eigenvalues(self.eval(branch, q, lambda), dim)
    }
}

/// `Φ + I` (period doubling) or `Φ⊙Φ − I` (Neimark–Sacker) into `a`; returns its size.
fn test_matrix(kind: BifurcationKind, phi: &[f64], dim: usize, a: &mut Vec<f64>) -> usize {
    a.clear();
    if kind == BifurcationKind::PeriodDoubling {
        a.extend_from_slice(phi);
        for i in 0..dim {
            a[i * dim + i] += 1.0;
        }
        return dim;
    }
    // Second compound: rows/columns are the pairs i < j, entries the 2×2 minors.
    let pairs: Vec<(usize, usize)> = (0..dim)
        .flat_map(|i| (i + 1..dim).map(move |j| (i, j)))
        .collect();
    let s = pairs.len();
    for &(i, j) in &pairs {
        for &(k, l) in &pairs {
            a.push(phi[i * dim + k] * phi[j * dim + l] - phi[i * dim + l] * phi[j * dim + k]);
        }
    }
    for d in 0..s {
        a[d * s + d] -= 1.0;
    }
    s
}

/// `g` of `[[A, b], [cᵀ, 0]] [v; g] = [0; 1]` for fixed borders `b`, `c`: the
/// bordered LU and the right-hand side are kept across the calls of the
/// finite-difference loop of [`extended_newton`].
struct BorderedScalar {
    b: Vec<f64>,
    c: Vec<f64>,
    lu: BorderedLu,
    rhs: Vec<f64>,
}

impl BorderedScalar {
    fn new(b: Vec<f64>, c: Vec<f64>) -> Self {
        let s = b.len();
        Self {
            b,
            c,
            lu: BorderedLu::new(s, 1),
            rhs: vec![0.0; s + 1],
        }
    }

    /// `g` for the `s×s` row-major `a` (NaN if singular).
    fn eval(&mut self, a: &[f64]) -> f64 {
        let s = self.b.len();
        // Near-singular pivots are accepted (the solve is checked instead).
        if !factored(self.lu.factor(a, &self.b, &self.c, &[0.0])) {
            return f64::NAN;
        }
        self.rhs.fill(0.0);
        self.rhs[s] = 1.0;
        if self.lu.solve(&mut self.rhs).is_ok() && self.rhs.iter().all(|v| v.is_finite()) {
            self.rhs[s]
        } else {
            f64::NAN
        }
    }
}

/// A factorization usable for solves: regular, or singular to rounding
/// (inverse iteration and test functions at a bifurcation accept it and
/// check the solution); not one refused for its sizes.
pub(crate) fn factored(result: Result<(), BorderedError>) -> bool {
    matches!(result, Ok(()) | Err(BorderedError::Singular))
}

/// Writes `[J | R_λ]` (`m` rows) into the first `m + 1` columns of the row-major
/// matrix `dst` with row stride `stride`.
pub(crate) fn put_jacobian(dst: &mut [f64], stride: usize, jac: &[f64], r_lambda: &[f64]) {
    let m = r_lambda.len();
    for i in 0..m {
        dst[i * stride..i * stride + m].copy_from_slice(&jac[i * m..(i + 1) * m]);
        dst[i * stride + m] = r_lambda[i];
    }
}

pub(crate) fn lambda_step(opts: &BifurcationOptions, lambda: f64) -> f64 {
    opts.fd_step * lambda.abs().max(1e-3)
}

/// The blocks `R_q` (row-major `m×m`) and `R_λ` of `[R_q, R_λ]` at `(q, λ)`,
/// `R_λ` by a central difference with [`lambda_step`].
pub(crate) fn jacobian_blocks<B: Branch>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    opts: &BifurcationOptions,
) -> (Vec<f64>, Vec<f64>) {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    let mut r_lambda = vec![0.0; m];
    branch.jacobian(q, lambda, &mut jac);
    residual_lambda(branch, q, lambda, lambda_step(opts, lambda), &mut r_lambda);
    (jac, r_lambda)
}

/// Right and left near-null vectors of the near-singular square row-major `a`,
/// refined in place from their seeds; only a non-finite factor is refused.
pub(crate) fn border_null_vectors(
    a: &[f64],
    right: &mut [f64],
    left: &mut [f64],
) -> Result<(), BifurcationError> {
    let mut lu = LuWorkspace::new(right.len());
    lu.factor_row_major(a);
    if !null_vector(&mut lu, right, false) || !null_vector(&mut lu, left, true) {
        return Err(solve_error(SolveError::SingularJacobian {
            iteration: 0,
            history: Vec::new(),
        }));
    }
    Ok(())
}

/// Result of [`extended_newton`]: `(q, λ, iterations)`.
pub(crate) type Converged = (Vec<f64>, f64, usize);

/// Newton ([`ivt_num::newton()`]) on `[R(q, λ) + Σⱼ μⱼ bⱼ; ψ(q, λ)] = 0`,
/// unknowns `{q, λ, μ}` with `k = unfold.len() + 1` test functions `ψ` (the
/// unfoldings `μ` make it square). Full steps; stops by
/// [`crate::fold::extended_step_check`].
pub(crate) fn extended_newton<B, T>(
    branch: &mut B,
    q0: &[f64],
    lambda0: f64,
    unfold: &[Vec<f64>],
    tests: T,
    opts: &BifurcationOptions,
) -> Result<Converged, BifurcationError>
where
    B: Branch,
    T: FnMut(&mut B, &[f64], f64, &mut [f64]),
{
    let m = branch.len();
    let k = unfold.len() + 1;
    let mut x = q0.to_vec();
    x.push(lambda0);
    x.resize(m + k, 0.0);
    let mut system = Extended {
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
    let nopts = NewtonOptions {
        ftol: 0.0,
        max_iter: opts.max_iter,
        max_halvings: 0,
        accept_no_descent: true,
        accept_near_singular: true,
        ..NewtonOptions::default()
    };
    let stats = newton(
        &mut system,
        &mut x,
        &mut NewtonWorkspace::new(m + k),
        &nopts,
    )
    .map_err(|e| solve_error(SolveError::from(e)))?;
    let lambda = x.get(m).copied().unwrap_or(lambda0);
    x.truncate(m);
    Ok((x, lambda, stats.iterations))
}

/// The extended system of [`extended_newton`] as a [`NewtonSystem`]:
/// `[J, R_λ, b]` analytic in `q` with `R_λ` by [`lambda_step`], the
/// test-function rows by central differences in `q` and λ.
struct Extended<'a, B, T> {
    branch: &'a mut B,
    unfold: &'a [Vec<f64>],
    tests: T,
    opts: &'a BifurcationOptions,
    m: usize,
    jac: Vec<f64>,
    r_lambda: Vec<f64>,
    psi: (Vec<f64>, Vec<f64>),
    qt: Vec<f64>,
}

impl<B, T> NewtonSystem for Extended<'_, B, T>
where
    B: Branch,
    T: FnMut(&mut B, &[f64], f64, &mut [f64]),
{
    type Error = Infallible;

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        let m = self.m;
        let (q, rest) = x.split_at(m);
        let (lambda, mu) = (rest[0], &rest[1..]);
        let (r, psi) = out.split_at_mut(m);
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
        let (q, lambda) = (&x[..m], x[m]);
        self.branch.jacobian(q, lambda, &mut self.jac);
        let h_lambda = lambda_step(self.opts, lambda);
        residual_lambda(self.branch, q, lambda, h_lambda, &mut self.r_lambda);
        newton.fill(0.0);
        put_jacobian(newton, n, &self.jac, &self.r_lambda);
        for (i, row) in newton.chunks_exact_mut(n).take(m).enumerate() {
            for (j, b) in self.unfold.iter().enumerate() {
                row[m + 1 + j] = b[i];
            }
        }
        // Test-function rows by central differences in q and λ.
        let q_scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        self.qt.copy_from_slice(q);
        let (psi_p, psi_m) = (&mut self.psi.0, &mut self.psi.1);
        for col in 0..=m {
            let h = if col < m {
                self.opts.fd_step * q[col].abs().max(q_scale).max(f64::MIN_POSITIVE)
            } else {
                h_lambda
            };
            if col < m {
                self.qt[col] = q[col] + h;
                (self.tests)(self.branch, &self.qt, lambda, psi_p);
                self.qt[col] = q[col] - h;
                (self.tests)(self.branch, &self.qt, lambda, psi_m);
                self.qt[col] = q[col];
            } else {
                (self.tests)(self.branch, q, lambda + h, psi_p);
                (self.tests)(self.branch, q, lambda - h, psi_m);
            }
            for (t, (p, mi)) in psi_p.iter().zip(psi_m.iter()).enumerate() {
                newton[(m + t) * n + col] = (p - mi) / (2.0 * h);
            }
        }
        Ok(())
    }

    fn check_step(
        &mut self,
        x: &[f64],
        step: &[f64],
        history: &[f64],
    ) -> Result<StepCheck, Infallible> {
        Ok(extended_step_check(
            (x, step, self.m),
            history,
            (self.opts.step_tol, self.opts.noise_tol),
            1e-3,
        ))
    }
}

/// Locates the period doubling (multiplier −1) or Neimark–Sacker point (complex
/// pair on the unit circle) nearest the converged orbit `(q0, λ0)` of `branch`.
///
/// # Errors
/// [`BifurcationError::Hb`] for sizes, a singular bordered or extended system
/// (with the history), non-convergence; [`BifurcationError::NeutralSaddle`] when
/// a Neimark–Sacker search ends on a real pair `μ, 1/μ`.
pub fn locate_multiplier_crossing<F: Family>(
    branch: &mut FamilyBranch<F>,
    kind: BifurcationKind,
    q0: &[f64],
    lambda0: f64,
    opts: &BifurcationOptions,
) -> Result<Bifurcation, BifurcationError> {
    if !matches!(
        kind,
        BifurcationKind::PeriodDoubling | BifurcationKind::NeimarkSacker
    ) {
        return Err(HbError::InvalidInput(
            "locate_multiplier_crossing takes period doubling or Neimark–Sacker".into(),
        )
        .into());
    }
    check_start(branch, q0, lambda0)?;
    let mut mono = Monodromy::new(branch, lambda0, opts.stability_steps)?;
    let dim = mono.dim;
    let mut a = Vec::new();
    let s = test_matrix(kind, mono.eval(branch, q0, lambda0), dim, &mut a);
    let (mut b, mut c) = (
        vec![1.0 / (s as f64).sqrt(); s],
        vec![1.0 / (s as f64).sqrt(); s],
    );
    border_null_vectors(&a, &mut c, &mut b)?;
    let mut bordered = BorderedScalar::new(b, c);
    let (q, lambda, iterations) = extended_newton(
        branch,
        q0,
        lambda0,
        &[],
        |br: &mut FamilyBranch<F>, q: &[f64], l: f64, out: &mut [f64]| {
            test_matrix(kind, mono.eval(br, q, l), dim, &mut a);
            out[0] = bordered.eval(&a);
        },
        opts,
    )?;
    let mut mono = Monodromy::new(branch, lambda, opts.stability_steps)?;
    let multipliers = mono.multipliers(branch, &q, lambda);
    if kind == BifurcationKind::NeimarkSacker {
        let on_circle = multipliers
            .iter()
            .any(|z| (z.norm() - 1.0).abs() < 1e-6 && z.im.abs() > 1e-6);
        if !on_circle {
            return Err(BifurcationError::NeutralSaddle { lambda });
        }
    }
    finish(branch, kind, q, lambda, multipliers, Vec::new(), iterations)
}

pub(crate) fn check_start<B: Branch>(branch: &B, q0: &[f64], lambda0: f64) -> Result<(), HbError> {
    if q0.len() != branch.len() {
        return Err(HbError::InvalidInput(format!(
            "start must have {} entries, got {}",
            branch.len(),
            q0.len()
        )));
    }
    if !(lambda0.is_finite() && q0.iter().all(|v| v.is_finite())) {
        return Err(HbError::Solve(SolveError::NonFinite {
            iteration: 0,
            history: Vec::new(),
        }));
    }
    Ok(())
}

pub(crate) fn finish<B: Branch>(
    branch: &mut B,
    kind: BifurcationKind,
    q: Vec<f64>,
    lambda: f64,
    multipliers: Vec<c64>,
    null_vectors: Vec<Vec<f64>>,
    iterations: usize,
) -> Result<Bifurcation, BifurcationError> {
    let mut r = vec![0.0; q.len()];
    branch.residual(&q, lambda, &mut r);
    Ok(Bifurcation {
        kind,
        q,
        lambda,
        multipliers,
        null_vectors,
        iterations,
        residual_norm: norm2(&r),
    })
}
