//! The two path correctors of `frequency_response` on the 2-DOF cubic chain of
//! issue 17: the same located folds, and the Newton–chord corrector calls `g`
//! about a third as often per point as Broyden's (the reason user systems use it).

mod common;

use ivt_hb::{
    frequency_response, Corrector, ElementProblem, FrcOptions, HbOptions, PeriodicProblem,
};
use std::cell::Cell;

/// The chain with counters of `g` and `∂g` evaluations (all samples at once).
struct Counted {
    chain: ElementProblem,
    g_calls: Cell<usize>,
    jacobian_calls: Cell<usize>,
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

fn chain() -> Counted {
    Counted {
        chain: common::chain::cubic_chain(),
        g_calls: Cell::new(0),
        jacobian_calls: Cell::new(0),
    }
}

/// `(fold ω's, g calls per point, ∂g calls per point)` of the curve 0.2 → 3.0.
fn curve(corrector: Corrector) -> (Vec<f64>, f64, f64) {
    let p = chain();
    let opts = FrcOptions {
        corrector,
        ..FrcOptions::default()
    };
    let frc = frequency_response(&p, &HbOptions::new(20, 84), &opts).unwrap();
    assert!(frc.folds.iter().all(|f| f.located), "{corrector:?}");
    let n = frc.points.len() as f64;
    (
        frc.folds.iter().map(|f| f.omega_f).collect(),
        p.g_calls.get() as f64 / n,
        p.jacobian_calls.get() as f64 / n,
    )
}

#[test]
fn newton_corrector_finds_the_same_folds_with_a_third_of_the_g_calls() {
    let (broyden, g_b, j_b) = curve(Corrector::Broyden);
    let (newton, g_n, j_n) = curve(Corrector::Newton);
    eprintln!("per point: Broyden g {g_b:.1}, ∂g {j_b:.2}; Newton g {g_n:.1}, ∂g {j_n:.2}");
    // Both curves locate the four folds of the two resonances on the same
    // extended system (Newton to ~1e-12): equal to 1e-9.
    assert_eq!(broyden.len(), 4, "{broyden:?}");
    assert_eq!(newton.len(), 4, "{newton:?}");
    for (a, b) in broyden.iter().zip(&newton) {
        assert!((a - b).abs() < 1e-9, "{broyden:?} vs {newton:?}");
    }
    // Measured 22.5 and 8.0 g calls per point (1.5 and 3.0 ∂g calls): the
    // Newton path's chord is Broyden-accelerated, and its tangent reuses the
    // Jacobian Newton converged with.
    assert!(g_n < 0.4 * g_b, "g per point: Newton {g_n}, Broyden {g_b}");
}
