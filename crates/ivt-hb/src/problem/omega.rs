//! Models that read the excitation frequency (issue 27, item 7): a rotating
//! unbalance `m e ω_f² cos θ`, a frequency-dependent load, a law written in
//! τ-derivatives. Such a problem says so
//! ([`PeriodicProblem::frequency_dependent`]) and gives `g(x, v, θ, ω_f)` and
//! `f(θ, ω_f)` through the `_at` hooks; every solver sees it bound to one ω_f
//! as [`AtFrequency`], an ordinary [`PeriodicProblem`].
//!
//! The HB residual Eq. 61 projects the excitation once, when it is planned,
//! and the frequency family ([`crate::Frequency`]) keeps that projection for
//! all ω_f. So [`AtFrequency`] hands the solver the excitation at the fixed
//! [`REFERENCE_FREQUENCY`] ω_r and moves the rest into `g`:
//!
//! `g̃(x, v, θ) = g(x, v, θ, ω_f) − [f(θ, ω_f) − f(θ, ω_r)]`,  `f̃(θ) = f(θ, ω_r)`,
//!
//! so that `g̃ − f̃ = g − f` at every AFT sample: the residual is that of the
//! model at ω_f (the same Galerkin projection on the same grid), its
//! ω_f-derivative `∂R/∂ω_f` includes the ω-dependence of `g` and `f`, and the
//! force scale of the tolerance is that of `f(·, ω_r)`.

use super::{forward_matrices, PeriodicProblem};

/// ω_r of [`AtFrequency`]: the frequency whose excitation `f(θ, ω_r)` is
/// projected once (the rest of `f(θ, ω_f)` enters with `g`).
pub const REFERENCE_FREQUENCY: f64 = 1.0;

/// A problem at one excitation frequency ω_f: for a
/// [`PeriodicProblem::frequency_dependent`] model the `_at` hooks at ω_f
/// (see the module docs); for any other problem the problem itself.
#[derive(Debug, Clone, Copy)]
pub struct AtFrequency<'a, P: ?Sized> {
    problem: &'a P,
    omega_f: f64,
    dependent: bool,
}

impl<'a, P: PeriodicProblem + ?Sized> AtFrequency<'a, P> {
    /// `problem` at ω_f.
    pub fn new(problem: &'a P, omega_f: f64) -> Self {
        Self {
            problem,
            omega_f,
            dependent: problem.frequency_dependent(),
        }
    }

    /// The excitation frequency ω_f.
    pub fn omega_f(&self) -> f64 {
        self.omega_f
    }

    /// `out −= f(θ, ω_f) − f(θ, ω_r)` at each sample (`out` sample-major).
    fn move_excitation(&self, theta: &[f64], out: &mut [f64]) {
        let n = self.problem.n_dof();
        let (mut at, mut reference) = (vec![0.0; n], vec![0.0; n]);
        for (&th, g) in theta.iter().zip(out.chunks_mut(n)) {
            self.problem.excitation_at(th, self.omega_f, &mut at);
            self.problem
                .excitation_at(th, REFERENCE_FREQUENCY, &mut reference);
            for ((g, a), r) in g.iter_mut().zip(&at).zip(&reference) {
                *g -= a - r;
            }
        }
    }
}

impl<P: PeriodicProblem + ?Sized> PeriodicProblem for AtFrequency<'_, P> {
    forward_matrices!(|s| s.problem);
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        if self.dependent {
            self.nonlinear_samples(x, v, &[theta], out)
        } else {
            self.problem.nonlinear(x, v, theta, out)
        }
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        if self.dependent {
            self.problem
                .nonlinear_samples_at(x, v, theta, self.omega_f, out);
            self.move_excitation(theta, out);
        } else {
            self.problem.nonlinear_samples(x, v, theta, out)
        }
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        if self.dependent {
            self.problem.excitation_at(theta, REFERENCE_FREQUENCY, out)
        } else {
            self.problem.excitation(theta, out)
        }
    }
    /// The moved excitation does not depend on `x`, `v`: `∂g̃ = ∂g(·, ω_f)`.
    fn nonlinear_jacobian(&self, x: &[f64], v: &[f64], theta: f64, dg: &mut [f64]) {
        if self.dependent {
            self.nonlinear_jacobian_samples(x, v, &[theta], dg)
        } else {
            self.problem.nonlinear_jacobian(x, v, theta, dg)
        }
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.problem
            .nonlinear_jacobian_samples_at(x, v, theta, self.omega_f, dg)
    }
}

/// The excitation `f` of a [`super::GeneralProblem`]: any closure
/// `Fn(θ, out)`, or a type whose `f` reads ω_f ([`Self::frequency_dependent`]).
pub trait Excitation {
    /// `f(θ)` (see [`PeriodicProblem::excitation`]).
    fn eval(&self, theta: f64, out: &mut [f64]);
    /// `f(θ, ω_f)`. Default: [`Self::eval`].
    fn eval_at(&self, theta: f64, _omega_f: f64, out: &mut [f64]) {
        self.eval(theta, out)
    }
    /// Whether `f` reads ω_f. Default: `false`.
    fn frequency_dependent(&self) -> bool {
        false
    }
}

impl<F: Fn(f64, &mut [f64])> Excitation for F {
    fn eval(&self, theta: f64, out: &mut [f64]) {
        self(theta, out)
    }
}

/// An [`Excitation`] `f(θ, ω_f, out)` that reads ω_f, given as a closure
/// (e.g. the rotating unbalance `|th, w, f| f[0] = m_e * w * w * th.cos()`).
/// Without an ω_f ([`Excitation::eval`]) it is NaN: a solver that does not
/// bind the problem to its ω_f ([`AtFrequency`]) fails on a non-finite
/// excitation instead of solving another model.
pub struct FrequencyExcitation<F>(pub F);

impl<F: Fn(f64, f64, &mut [f64])> Excitation for FrequencyExcitation<F> {
    fn eval(&self, _theta: f64, out: &mut [f64]) {
        out.fill(f64::NAN);
    }
    fn eval_at(&self, theta: f64, omega_f: f64, out: &mut [f64]) {
        (self.0)(theta, omega_f, out)
    }
    fn frequency_dependent(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Duffing, GeneralProblem, Nonlinearity};

    /// `g = ε x³ + 0.1 ω_f x`, `f = F ω_f² cos θ` as hooks of a general problem.
    struct OmegaCubic;
    impl Nonlinearity for OmegaCubic {
        fn eval(&self, _x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
            out.fill(f64::NAN);
        }
        fn frequency_dependent(&self) -> bool {
            true
        }
        fn eval_samples_at(&self, x: &[f64], _v: &[f64], _th: &[f64], w: f64, out: &mut [f64]) {
            for (o, x) in out.iter_mut().zip(x) {
                *o = x * x * x + 0.1 * w * x;
            }
        }
    }

    #[test]
    fn bound_model_is_g_minus_f_at_its_frequency() {
        let p = GeneralProblem::new(1, vec![1.0], vec![0.04], vec![1.0], OmegaCubic, |_, o| {
            o.fill(0.0)
        })
        .with_excitation(FrequencyExcitation(|th: f64, w: f64, f: &mut [f64]| {
            f[0] = 0.03 * w * w * th.cos()
        }))
        .with_velocity_dependent(false);
        assert!(p.frequency_dependent());
        let w = 1.7;
        let bound = AtFrequency::new(&p, w);
        let (x, th) = (0.4, 0.9);
        let (mut g, mut f) = ([0.0], [0.0]);
        bound.nonlinear(&[x], &[0.0], th, &mut g);
        bound.excitation(th, &mut f);
        let expected = x * x * x + 0.1 * w * x - 0.03 * w * w * th.cos();
        assert!(
            (g[0] - f[0] - expected).abs() < 1e-15,
            "{} vs {expected}",
            g[0] - f[0]
        );
        // The reference excitation is that at ω_r, for every ω_f.
        assert_eq!(f[0], 0.03 * th.cos());
        // ∂g̃/∂x = 3x² + 0.1 ω_f (differences of g at ω_f).
        let mut dg = [0.0; 2];
        bound.nonlinear_jacobian(&[x], &[0.0], th, &mut dg);
        assert!((dg[0] - (3.0 * x * x + 0.1 * w)).abs() < 1e-9, "{dg:?}");
        assert_eq!(dg[1], 0.0);
    }

    #[test]
    fn other_problems_pass_through() {
        let d = Duffing::fig28();
        let bound = AtFrequency::new(&d, 1.3);
        let (mut a, mut b) = ([0.0], [0.0]);
        bound.nonlinear(&[0.5], &[0.0], 0.2, &mut a);
        d.nonlinear(&[0.5], &[0.0], 0.2, &mut b);
        assert_eq!(a, b);
        bound.excitation(0.2, &mut a);
        d.excitation(0.2, &mut b);
        assert_eq!(a, b);
    }
}
