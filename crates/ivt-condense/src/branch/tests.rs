//! Tests of the condensed branch: its Jacobians against differences.

use super::*;
use crate::models::{cantilever, BeamProperties};
use ivt_hb::GeneralProblem;
use ivt_path::branch::bilinear_lambda_difference;

/// With three nonlinear DOFs of which two are joined by an element and
/// the third acts alone (so four of the nine blocks of `∂G/∂q` are
/// zero), the condensed Jacobian equals central differences of the
/// condensed residual, column by column.
#[test]
fn jacobian_with_uncoupled_dofs_equals_differences_of_the_residual() {
    let beam = cantilever(30, &BeamProperties::default()).unwrap();
    let s = &beam.model;
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
    let dofs = vec![beam.tip, beam.tip - 2, beam.tip - 10];
    let mut load = vec![0.0; s.n_dof()];
    load[beam.tip] = 0.005;
    let law = |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
        let joint = 50.0 * (x[0] - x[1]).powi(3);
        g[0] = 200.0 * x[0].powi(3) + joint;
        g[1] = -joint;
        g[2] = 80.0 * x[2].powi(3);
    };
    let unforced = |_t: f64, f: &mut [f64]| f.fill(0.0);
    let zeros = vec![0.0; 9];
    let local = GeneralProblem::new(3, zeros.clone(), zeros.clone(), zeros, law, unforced)
        .with_velocity_dependent(false);
    let hb = HbOptions::new(5, 32);
    let mut branch = CondensedBranch::new(structure, dofs, &load, &[], local, &hb).unwrap();
    let omega = 3.6;
    let mut q = branch.linear_guess(omega).unwrap();
    let m = q.len();
    q.iter_mut()
        .enumerate()
        .for_each(|(i, x)| *x = 5.0 * *x + 1e-3 * ((i % 7) as f64 - 3.0));
    let mut jac = vec![0.0; m * m];
    branch.jacobian(&q, omega, &mut jac);
    let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
    let mut worst = 0.0f64;
    let scale = jac.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for c in 0..m {
        let h = 1e-6;
        let mut x = q.clone();
        x[c] += h;
        branch.residual(&x, omega, &mut plus);
        x[c] -= 2.0 * h;
        branch.residual(&x, omega, &mut minus);
        for r in 0..m {
            let fd = (plus[r] - minus[r]) / (2.0 * h);
            worst = worst.max((fd - jac[r * m + c]).abs() / scale);
        }
    }
    // Measured 4.4e-11 (the difference's rounding and O(h²) error); with
    // the coupled block (0, 1) skipped, 2.3e-3.
    assert!(worst < 1e-7, "{worst:e}");
    // Not vacuous: the DOF acting alone is coupled to the others
    // through the structure's receptances, not through ∂G/∂q.
    let l = 2 * 5 + 1;
    assert!(jac[(2 * l + 1) * m + 1].abs() > 1e-6 * scale);
}

/// The exact `∂(wᵀJv)/∂ω_f` equals the central difference of two
/// Jacobians (each from its own factorizations) at ω_f ± h to its
/// O(h²) error, on the N = 50 beam near its first resonance with the
/// tip spring well into its nonlinear range.
#[test]
fn exact_bilinear_lambda_equals_the_difference_of_jacobians() {
    let beam = cantilever(50, &BeamProperties::default()).unwrap();
    let s = &beam.model;
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
    let mut load = vec![0.0; s.n_dof()];
    load[beam.tip] = 0.005;
    let spring = |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = 200.0 * x[0].powi(3);
    let unforced = |_t: f64, f: &mut [f64]| f[0] = 0.0;
    let local = GeneralProblem::new(1, vec![0.0], vec![0.0], vec![0.0], spring, unforced)
        .with_velocity_dependent(false);
    let hb = HbOptions::new(7, 32);
    let mut branch =
        CondensedBranch::new(structure, vec![beam.tip], &load, &[], local, &hb).unwrap();
    let omega = 3.6;
    // Five times the linear response, a second harmonic and a cubic one.
    let mut q = branch.linear_guess(omega).unwrap();
    q.iter_mut().for_each(|x| *x *= 5.0);
    q[3] = 0.004;
    q[7 + 3] = -0.002;
    let m = q.len();
    let w: Vec<f64> = (0..m).map(|i| ((i * 7 % 5) as f64 - 2.0) * 0.3).collect();
    let v: Vec<f64> = (0..m).map(|i| 1.0 / (1.0 + i as f64)).collect();
    let exact = Branch::bilinear_lambda(&mut branch, &q, omega, 0.0, &w, &v);
    let errors: Vec<f64> = [1e-4, 1e-5]
        .iter()
        .map(|&h| {
            let d = bilinear_lambda_difference(&mut branch, &q, omega, h, &w, &v);
            (d - exact).abs() / exact.abs()
        })
        .collect();
    // O(h²): the error falls by about 100 from h = 1e-4 to 1e-5
    // (measured 1.7e-6 at h = 1e-4, 1.7e-4 at h = 1e-3).
    assert!(errors[1] < 1e-7, "{errors:?}");
    assert!(errors[0] > 30.0 * errors[1], "{errors:?}");
    assert!(exact.abs() > 1e-3, "{exact}");
}
