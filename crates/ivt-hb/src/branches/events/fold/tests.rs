//! The fold test function's gradient of a family branch against
//! differences of the assembled Jacobian.

use crate::orbit::ihb::HbOptions;
use crate::problem::PeriodicProblem;
use ivt_path::branch::fd_jacobian_gradient;
use ivt_path::Branch;

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
