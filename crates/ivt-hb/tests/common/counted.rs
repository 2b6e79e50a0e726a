//! The 2-DOF cubic chain with counters of its batched `g` and `∂g`
//! evaluations: the work counts of the corrector and stability tests.

use ivt_hb::{ElementProblem, PeriodicProblem};
use std::cell::Cell;

/// The chain with counters of `g` and `∂g` evaluations (all samples at once).
pub struct Counted {
    chain: ElementProblem,
    /// `nonlinear_samples` calls.
    pub g_calls: Cell<usize>,
    /// `nonlinear_jacobian_samples` calls.
    pub jacobian_calls: Cell<usize>,
}

impl PeriodicProblem for Counted {
    fn n_dof(&self) -> usize {
        self.chain.n_dof()
    }
    fn mass(&self) -> &[f64] {
        self.chain.mass()
    }
    fn damping(&self) -> &[f64] {
        self.chain.damping()
    }
    fn stiffness(&self) -> &[f64] {
        self.chain.stiffness()
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.chain.nonlinear(x, v, theta, out)
    }
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.g_calls.set(self.g_calls.get() + 1);
        self.chain.nonlinear_samples(x, v, theta, out)
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        self.chain.excitation(theta, out)
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        self.jacobian_calls.set(self.jacobian_calls.get() + 1);
        self.chain.nonlinear_jacobian_samples(x, v, theta, dg)
    }
}

impl Counted {
    /// The chain of [`super::chain::cubic_chain`], no calls counted yet.
    pub fn chain() -> Self {
        Self {
            chain: super::chain::cubic_chain(),
            g_calls: Cell::new(0),
            jacobian_calls: Cell::new(0),
        }
    }
}
