//! A member of a family that may fail: the problem at p, or where the family
//! fails a problem of the same size that is NaN everywhere, so that the path
//! follower rejects the step (as the fold curve's NaN residual,
//! [`crate::branches::codim2`]).

use crate::problem::PeriodicProblem;

/// `family(p)`, or NaN of `n` DOFs where it failed.
pub(crate) struct Member<P> {
    problem: Option<P>,
    n: usize,
    nan: Vec<f64>,
}

impl<P: PeriodicProblem> Member<P> {
    pub(crate) fn new(problem: Option<P>, n: usize) -> Self {
        let nan = match problem {
            Some(_) => Vec::new(),
            None => vec![f64::NAN; n * n],
        };
        Self { problem, n, nan }
    }

    /// `eval(problem, out)` at the member, or NaN where the family failed.
    fn or_nan(&self, out: &mut [f64], eval: impl FnOnce(&P, &mut [f64])) {
        match &self.problem {
            Some(p) => eval(p, out),
            None => out.fill(f64::NAN),
        }
    }
}

impl<P: PeriodicProblem> PeriodicProblem for Member<P> {
    fn n_dof(&self) -> usize {
        self.problem.as_ref().map_or(self.n, P::n_dof)
    }
    fn mass(&self) -> &[f64] {
        self.problem.as_ref().map_or(&self.nan, P::mass)
    }
    fn damping(&self) -> &[f64] {
        self.problem.as_ref().map_or(&self.nan, P::damping)
    }
    fn stiffness(&self) -> &[f64] {
        self.problem.as_ref().map_or(&self.nan, P::stiffness)
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.or_nan(out, |p, out| p.nonlinear(x, v, theta, out))
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.or_nan(out, |p, out| p.nonlinear_samples(x, v, theta, out))
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        self.or_nan(out, |p, out| p.excitation(theta, out))
    }
    fn velocity_dependent(&self) -> bool {
        self.problem.as_ref().is_none_or(P::velocity_dependent)
    }
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        self.or_nan(dg, |p, dg| p.nonlinear_jacobian(x, v, theta, dg))
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.or_nan(dg, |p, dg| p.nonlinear_jacobian_samples(x, v, theta, dg))
    }
}
