//! A member of a family that may fail: the problem at p, or where the family
//! fails a problem of the same size that is NaN everywhere, so that the path
//! follower rejects the step (as the fold curve's NaN residual,
//! [`crate::branches::codim2`]). With a [`Failures`] slot the cause is kept — the
//! family's error, a member of another size, a `g` that returns NaN or ±∞
//! for a finite state — so that a curve that stalls there ends with that
//! error, not as a normal `step_too_small` termination.

use crate::error::HbError;
use crate::problem::PeriodicProblem;
use std::sync::Mutex;

/// The latest cause of a failed member since the slot was last cleared.
#[derive(Debug, Default)]
pub(crate) struct Failures(Mutex<Option<HbError>>);

impl Failures {
    fn record(&self, e: HbError) {
        if let Ok(mut slot) = self.0.lock() {
            *slot = Some(e);
        }
    }

    /// Forget the causes so far (a point was accepted after them).
    pub(crate) fn clear(&self) {
        if let Ok(mut slot) = self.0.lock() {
            *slot = None;
        }
    }

    /// The latest cause, if any.
    pub(crate) fn take(&self) -> Option<HbError> {
        self.0.lock().ok().and_then(|mut s| s.take())
    }
}

/// `family(p)`, or NaN of `n` DOFs where it failed.
pub(crate) struct Member<'s, P> {
    problem: Option<P>,
    n: usize,
    nan: Vec<f64>,
    p: f64,
    failures: Option<&'s Failures>,
}

impl<'s, P: PeriodicProblem> Member<'s, P> {
    /// The member `built` = `family(p)` of a family of `n` DOFs; its failure
    /// (an error, or another size) kept in `failures` if given.
    pub(crate) fn new(
        built: Result<P, HbError>,
        n: usize,
        p: f64,
        failures: Option<&'s Failures>,
    ) -> Self {
        let problem = match built {
            Ok(problem) if problem.n_dof() == n => Some(problem),
            Ok(problem) => {
                if let Some(f) = failures {
                    f.record(HbError::InvalidInput(format!(
                        "the family changes size along the curve: at p = {p} it has {} DOFs, \
                         at the start {n}",
                        problem.n_dof()
                    )));
                }
                None
            }
            Err(e) => {
                if let Some(f) = failures {
                    f.record(e);
                }
                None
            }
        };
        let nan = match problem {
            Some(_) => Vec::new(),
            None => vec![f64::NAN; n * n],
        };
        Self {
            problem,
            n,
            nan,
            p,
            failures,
        }
    }

    /// `eval(problem, out)` at the member, or NaN where the family failed.
    fn or_nan(&self, out: &mut [f64], eval: impl FnOnce(&P, &mut [f64])) {
        match &self.problem {
            Some(p) => eval(p, out),
            None => out.fill(f64::NAN),
        }
    }

    /// Keep "g is not finite at a finite state" as the cause.
    fn check_finite(&self, x: &[f64], v: &[f64], out: &[f64]) {
        let Some(failures) = self.failures else {
            return;
        };
        let finite = |a: &[f64]| a.iter().all(|s| s.is_finite());
        if self.problem.is_some() && finite(x) && finite(v) && !finite(out) {
            failures.record(HbError::InvalidInput(format!(
                "g returned NaN or ±∞ for a finite state at p = {}",
                self.p
            )));
        }
    }
}

impl<P: PeriodicProblem> PeriodicProblem for Member<'_, P> {
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
        self.or_nan(out, |p, out| p.nonlinear(x, v, theta, out));
        self.check_finite(x, v, out);
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.or_nan(out, |p, out| p.nonlinear_samples(x, v, theta, out));
        self.check_finite(x, v, out);
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
