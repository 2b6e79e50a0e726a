//! [`GeneralProblem`]: a problem built from matrices, a [`Nonlinearity`] `g` (a
//! closure, or a type evaluating all AFT samples at once, with or without an
//! analytic Jacobian) and an excitation; either may read the excitation
//! frequency ω_f ([`super::omega`]).

use super::omega::Excitation;
use super::{
    central_difference_samples, central_differences, matrix_getters, per_sample,
    zero_velocity_blocks, PeriodicProblem,
};

/// The force `g(x, v, θ)` of a [`GeneralProblem`]: any closure
/// `Fn(&[f64], &[f64], f64, &mut [f64])` (one sample per call), or a type that
/// also evaluates all AFT samples in one call (e.g. one call into an interpreter),
/// and optionally its analytic Jacobian ([`Self::jacobian_samples`];
/// [`WithJacobian`] pairs a closure with one).
pub trait Nonlinearity {
    /// `g` at one sample (see [`PeriodicProblem::nonlinear`]).
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]);
    /// `g` at `theta.len()` samples, sample-major (see
    /// [`PeriodicProblem::nonlinear_samples`]). Default: [`Self::eval`] per sample.
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        let n = x.len() / theta.len().max(1);
        per_sample(n, x, v, theta, out, |x, v, th, out| {
            self.eval(x, v, th, out)
        });
    }
    /// The analytic `∂g/∂x`, `∂g/∂v` at `theta.len()` samples into `dg` (layout of
    /// [`PeriodicProblem::nonlinear_jacobian_samples`]: per sample the row-major
    /// blocks `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`); returns whether it wrote them.
    /// Default: `false`, and [`GeneralProblem`] differences [`Self::eval_samples`]
    /// ([`central_difference_samples`]: one call per Jacobian on the 2·n_dof
    /// perturbed copies of the samples, 4·n_dof with velocity dependence)
    /// instead.
    fn jacobian_samples(&self, _x: &[f64], _v: &[f64], _theta: &[f64], _dg: &mut [f64]) -> bool {
        false
    }
    /// Whether `g` reads ω_f ([`PeriodicProblem::frequency_dependent`]).
    /// Default: `false`.
    fn frequency_dependent(&self) -> bool {
        false
    }
    /// `g(x, v, θ, ω_f)` at all samples. Default: [`Self::eval_samples`].
    fn eval_samples_at(&self, x: &[f64], v: &[f64], theta: &[f64], _w: f64, out: &mut [f64]) {
        self.eval_samples(x, v, theta, out)
    }
    /// Whether `g` has a memory ([`PeriodicProblem::hysteretic`]). Default:
    /// `false`.
    fn hysteretic(&self) -> bool {
        false
    }
}

/// A [`Nonlinearity`] `g` with its analytic Jacobian `jacobian(x, v, θ, dg)`
/// at one sample (`dg`: the blocks `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`), so that the
/// Galerkin Jacobian (Eq. 56) and the stability matrix (Eq. 79) call no
/// differences of `g` ([`GeneralProblem::with_jacobian`]).
pub struct WithJacobian<G, J> {
    g: G,
    jacobian: J,
}

impl<G, J> Nonlinearity for WithJacobian<G, J>
where
    G: Nonlinearity,
    J: Fn(&[f64], &[f64], f64, &mut [f64]),
{
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.g.eval(x, v, theta, out)
    }
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g.eval_samples(x, v, theta, out)
    }
    fn jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) -> bool {
        let n = x.len() / theta.len().max(1);
        per_sample(n, x, v, theta, dg, &self.jacobian);
        true
    }
    fn frequency_dependent(&self) -> bool {
        self.g.frequency_dependent()
    }
    fn eval_samples_at(&self, x: &[f64], v: &[f64], theta: &[f64], w: f64, out: &mut [f64]) {
        self.g.eval_samples_at(x, v, theta, w, out)
    }
    fn hysteretic(&self) -> bool {
        self.g.hysteretic()
    }
}

impl<G: Fn(&[f64], &[f64], f64, &mut [f64])> Nonlinearity for G {
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self(x, v, theta, out)
    }
}

/// A general multi-DOF problem built from matrices, a [`Nonlinearity`] (e.g. a
/// closure) and an excitation closure, for users who do not want to implement the
/// trait. Its `∂g` are the nonlinearity's analytic Jacobian when it has one
/// ([`Nonlinearity::jacobian_samples`], [`Self::with_jacobian`]), else central
/// differences over all samples at once with steps relative to the orbit
/// ([`central_difference_samples`]).
pub struct GeneralProblem<G, F> {
    n: usize,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    g: G,
    f: F,
    velocity_dependent: bool,
}

impl<G, F> GeneralProblem<G, F>
where
    G: Nonlinearity,
    F: Fn(f64, &mut [f64]),
{
    /// `M`, `C`, `K` row-major `n×n`; `g(x, v, θ, out)`, `f(θ, out)` (an
    /// [`Excitation`] that reads ω_f: [`Self::with_excitation`]). The sizes are
    /// checked where the problem is solved: a matrix that is not `n×n` is an
    /// [`crate::HbError::InvalidInput`] of the solver (e.g. `"M must be 2×2"`).
    pub fn new(n: usize, m: Vec<f64>, c: Vec<f64>, k: Vec<f64>, g: G, f: F) -> Self {
        Self {
            n,
            m,
            c,
            k,
            g,
            f,
            velocity_dependent: true,
        }
    }
}

impl<G, F> GeneralProblem<G, F> {
    /// The same problem with the excitation `f` (e.g. one that reads ω_f).
    pub fn with_excitation<E: Excitation>(self, f: E) -> GeneralProblem<G, E> {
        GeneralProblem {
            n: self.n,
            m: self.m,
            c: self.c,
            k: self.k,
            g: self.g,
            f,
            velocity_dependent: self.velocity_dependent,
        }
    }

    /// Declares whether `g` reads `v` (default `true`; `false` saves an inverse FFT
    /// per DOF in the residual and the `v` differences of the Jacobian).
    pub fn with_velocity_dependent(mut self, velocity_dependent: bool) -> Self {
        self.velocity_dependent = velocity_dependent;
        self
    }

    /// The nonlinearity `g`.
    pub fn nonlinearity(&self) -> &G {
        &self.g
    }

    /// The same problem with the analytic Jacobian `jacobian(x, v, θ, dg)` of `g`
    /// at one sample (`dg`: row-major `[∂g/∂x | ∂g/∂v]`, `2·n_dof²`; the `∂g/∂v`
    /// block is ignored, taken as zero, when `g` is declared velocity
    /// independent): every Jacobian assembly then calls it instead of
    /// differencing `g`.
    pub fn with_jacobian<J>(self, jacobian: J) -> GeneralProblem<WithJacobian<G, J>, F>
    where
        J: Fn(&[f64], &[f64], f64, &mut [f64]),
    {
        GeneralProblem {
            n: self.n,
            m: self.m,
            c: self.c,
            k: self.k,
            g: WithJacobian {
                g: self.g,
                jacobian,
            },
            f: self.f,
            velocity_dependent: self.velocity_dependent,
        }
    }
}

impl<G, F> PeriodicProblem for GeneralProblem<G, F>
where
    G: Nonlinearity,
    F: Excitation,
{
    matrix_getters!();
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.g.eval(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g.eval_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        self.f.eval(theta, out)
    }
    fn velocity_dependent(&self) -> bool {
        self.velocity_dependent
    }
    fn hysteretic(&self) -> bool {
        self.g.hysteretic()
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        if !self.g.jacobian_samples(x, v, theta, dg) {
            return central_difference_samples(self, x, v, theta, dg);
        }
        if !self.velocity_dependent {
            zero_velocity_blocks(self.n, dg);
        }
    }
    fn frequency_dependent(&self) -> bool {
        self.g.frequency_dependent() || self.f.frequency_dependent()
    }
    fn nonlinear_samples_at(&self, x: &[f64], v: &[f64], th: &[f64], w: f64, out: &mut [f64]) {
        self.g.eval_samples_at(x, v, th, w, out)
    }
    /// A `g` that reads ω_f is differenced at ω_f (its analytic Jacobian,
    /// if any, does not see ω_f).
    fn nonlinear_jacobian_samples_at(
        &self,
        x: &[f64],
        v: &[f64],
        t: &[f64],
        w: f64,
        dg: &mut [f64],
    ) {
        if !self.g.frequency_dependent() {
            return self.nonlinear_jacobian_samples(x, v, t, dg);
        }
        let eval =
            |x: &[f64], v: &[f64], t: &[f64], g: &mut [f64]| self.g.eval_samples_at(x, v, t, w, g);
        central_differences(self.n, self.velocity_dependent, eval, x, v, t, dg)
    }
    fn excitation_at(&self, theta: f64, omega_f: f64, out: &mut [f64]) {
        self.f.eval_at(theta, omega_f, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GalerkinJacobian, HbOptions, HbResidual};
    use std::cell::Cell;

    /// A 2-DOF chain with a coupled, velocity-dependent `g`:
    /// g₀ = ½x₀³ + 0.1x₀²v₁, g₁ = 0.2(x₁ − x₀)³.
    fn chain_g(x: &[f64], v: &[f64], out: &mut [f64]) {
        out[0] = 0.5 * x[0].powi(3) + 0.1 * x[0] * x[0] * v[1];
        out[1] = 0.2 * (x[1] - x[0]).powi(3);
    }

    /// Its `[∂g/∂x | ∂g/∂v]`, row-major 2×2 blocks.
    fn chain_jacobian(x: &[f64], v: &[f64], dg: &mut [f64]) {
        let d = 0.6 * (x[1] - x[0]).powi(2);
        let dx = [1.5 * x[0] * x[0] + 0.2 * x[0] * v[1], 0.0, -d, d];
        let dv = [0.0, 0.1 * x[0] * x[0], 0.0, 0.0];
        dg[..4].copy_from_slice(&dx);
        dg[4..].copy_from_slice(&dv);
    }

    /// The Galerkin Jacobian Φ_q (Eq. 56) of `problem` at a two-harmonic orbit,
    /// and the number of one-sample `g` calls `calls` counted while assembling it.
    fn galerkin<P: PeriodicProblem>(problem: &P, calls: &Cell<usize>) -> (Vec<f64>, usize) {
        let opts = HbOptions::new(5, 16);
        let mut res = HbResidual::new(problem, &opts).unwrap();
        let l = 2 * 5 + 1;
        let mut q = vec![0.0; 2 * l];
        // DOF 0: 0.8cos τ + 0.3 sin 2τ + 0.1; DOF 1: 0.5 sin τ − 0.2cos 3τ.
        (q[0], q[1], q[5 + 2]) = (0.2, 0.8, 0.3);
        (q[l + 5 + 1], q[l + 3]) = (0.5, -0.2);
        let mut jac = vec![0.0; q.len() * q.len()];
        calls.set(0);
        GalerkinJacobian::new(&res).assemble(&mut res, problem, &q, 1.3, 1.0, &mut jac);
        (jac, calls.get())
    }

    #[test]
    fn analytic_jacobian_gives_the_differenced_galerkin_jacobian_without_calling_g() {
        let calls = Cell::new(0);
        let g = |x: &[f64], v: &[f64], _th: f64, out: &mut [f64]| {
            calls.set(calls.get() + 1);
            chain_g(x, v, out);
        };
        let mck = || {
            (
                vec![1.0, 0.0, 0.0, 1.0],
                vec![0.02, 0.0, 0.0, 0.02],
                vec![2.0, -1.0, -1.0, 2.0],
            )
        };
        let (m, c, k) = mck();
        let differenced =
            GeneralProblem::new(2, m, c, k, g, |_: f64, out: &mut [f64]| out.fill(0.0));
        let (m, c, k) = mck();
        let analytic = GeneralProblem::new(2, m, c, k, g, |_: f64, out: &mut [f64]| out.fill(0.0))
            .with_jacobian(|x: &[f64], v: &[f64], _th: f64, dg: &mut [f64]| {
                chain_jacobian(x, v, dg)
            });
        let (jac_fd, calls_fd) = galerkin(&differenced, &calls);
        let (jac_an, calls_an) = galerkin(&analytic, &calls);
        // Central differences with steps 1e-6 of the orbit's scale err by
        // ~1e-10 relative (FD_STEP): 1e-8 of the largest entry bounds it.
        let scale = jac_an.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let err = jac_fd
            .iter()
            .zip(&jac_an)
            .fold(0.0f64, |a, (f, e)| a.max((f - e).abs()));
        assert!(
            err <= 1e-8 * scale,
            "max |Φ_fd − Φ_analytic| = {err:e}, scale {scale}"
        );
        // The 2N = 32 samples, differenced in 4·n_dof = 8 evaluations of all samples.
        assert_eq!(calls_fd, 8 * 32);
        assert_eq!(calls_an, 0);
    }

    #[test]
    fn analytic_velocity_block_is_ignored_for_a_velocity_independent_g() {
        let g = |x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| chain_g(x, &[0.0; 2], out);
        let problem = GeneralProblem::new(
            2,
            vec![1.0, 0.0, 0.0, 1.0],
            vec![0.0; 4],
            vec![0.0; 4],
            g,
            |_: f64, out: &mut [f64]| out.fill(0.0),
        )
        .with_velocity_dependent(false)
        .with_jacobian(|x: &[f64], _v: &[f64], _th: f64, dg: &mut [f64]| dg.fill(x[0]));
        let (x, v) = ([0.5, 1.0, -2.0, 3.0], [7.0; 4]);
        let mut dg = [f64::NAN; 16];
        problem.nonlinear_jacobian_samples(&x, &v, &[0.0, 1.0], &mut dg);
        assert_eq!(&dg[..8], &[0.5, 0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!(&dg[8..], &[-2.0, -2.0, -2.0, -2.0, 0.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn a_matrix_that_is_not_n_by_n_is_the_solvers_input_error() {
        let g = |_x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| out.fill(0.0);
        let f = |_: f64, out: &mut [f64]| out.fill(0.0);
        let problem = GeneralProblem::new(2, vec![1.0; 3], vec![0.0; 4], vec![1.0; 4], g, f);
        let err = HbResidual::new(&problem, &HbOptions::new(3, 8)).unwrap_err();
        assert_eq!(err, crate::HbError::InvalidInput("M must be 2×2".into()));
    }
}
