//! The fold locator on a parabola.

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
    let f = locate_fold(&mut Parabola, &q0, 1.09, &LocateOptions::fold()).unwrap();
    assert!((f.lambda - 1.0).abs() < 1e-13, "{f:?}");
    // The extended system is regular at the fold: q converges as fast as λ.
    assert!(
        (f.q[0] - 1.0).abs() < 1e-12 && (f.q[1] - 1.0).abs() < 1e-12,
        "{f:?}"
    );
    assert!(f.residual_norm < 1e-12 && f.iterations <= 8, "{f:?}");
}
