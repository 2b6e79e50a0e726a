//! The fold locator on a parabola, and the fold test function's gradient
//! against differences of the assembled Jacobian.

use super::*;
use crate::branch::fd_jacobian_gradient;
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
    let f = locate_fold(&mut Parabola, &q0, 1.09, &LocateOptions::fold()).unwrap();
    assert!((f.lambda - 1.0).abs() < 1e-13, "{f:?}");
    // The extended system is regular at the fold: q converges as fast as λ.
    assert!(
        (f.q[0] - 1.0).abs() < 1e-12 && (f.q[1] - 1.0).abs() < 1e-12,
        "{f:?}"
    );
    assert!(f.residual_norm < 1e-12 && f.iterations <= 8, "{f:?}");
}
