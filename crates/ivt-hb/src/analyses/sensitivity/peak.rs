//! The amplitude peak of a response curve as a located point and its
//! sensitivities: its test `∇A·t_q` (zero at the peak), located by Newton
//! on the curve, and its adjoint derivatives.

use super::*;

/// The peak's test: `∇A(q)·t_q` with `t` the curve's tangent from the
/// bordered solve `[[J, R_ω], [cᵀ]] t = e` (`c` fixed).
fn peak_test<B: Branch>(
    branch: &mut B,
    (q, omega): (&[f64], f64),
    c: &[f64],
    n: usize,
    dof: usize,
) -> f64 {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    branch.jacobian(q, omega, &mut jac);
    let mut r_omega = vec![0.0; m];
    branch.residual_lambda(q, omega, path_lambda_step(omega), &mut r_omega);
    let (corner, row) = match c.split_last() {
        Some((l, r)) => (*l, r),
        None => return f64::NAN,
    };
    let mut lu = BorderedLu::new(m, 1);
    if !factored(lu.factor(&jac, &r_omega, row, &[corner])) {
        return f64::NAN;
    }
    let mut tangent = vec![0.0; m + 1];
    if let Some(e) = tangent.last_mut() {
        *e = 1.0;
    }
    if lu.solve(&mut tangent).is_err() {
        return f64::NAN;
    }
    match amplitude_gradient(q, n, dof) {
        Ok((_, grad)) => grad.iter().zip(&tangent).map(|(a, b)| a * b).sum(),
        Err(_) => f64::NAN,
    }
}

/// The unit tangent `[−J⁻¹R_ω; 1]/‖·‖` at `(q, ω)` (the peak test's border).
fn tangent_at<B: Branch>(branch: &mut B, q: &[f64], omega: f64) -> Result<Vec<f64>, HbError> {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    branch.jacobian(q, omega, &mut jac);
    let mut r_omega = vec![0.0; m];
    branch.residual_lambda(q, omega, path_lambda_step(omega), &mut r_omega);
    let mut lu = LuWorkspace::new(m);
    if !lu.factor_row_major(&jac) {
        return Err(HbError::InvalidInput(
            "the amplitude peak lies on a fold (∂R/∂q singular): locate the fold instead".into(),
        ));
    }
    lu.solve(&mut r_omega);
    let mut t: Vec<f64> = r_omega.iter().map(|v| -v).collect();
    t.push(1.0);
    let norm = ivt_num::vector::norm2(&t);
    t.iter_mut().for_each(|v| *v /= norm);
    Ok(t)
}

/// Locates the amplitude peak near `(q0, ω0)`: Newton on `[R; ∇A·t] = 0`
/// ([`extended_newton`]).
pub(super) fn locate_peak<B: Branch>(
    branch: &mut B,
    (q0, omega0): (&[f64], f64),
    n: usize,
    dof: usize,
    opts: &LocateOptions,
) -> Result<(Vec<f64>, f64, usize), HbError> {
    let c = tangent_at(branch, q0, omega0)?;
    let (q, omega, its) = extended_newton(
        branch,
        (q0, omega0),
        &[],
        |br: &mut B, q: &[f64], l: f64, out: &mut [f64]| {
            if let Some(o) = out.first_mut() {
                *o = peak_test(br, (q, l), &c, n, dof);
            }
        },
        opts,
    )?;
    Ok((q, omega, its))
}

/// The peak's adjoint (the test of [`peak_test`]).
pub(super) fn peak<F: Family>(
    t: &mut Triple<F>,
    (q, omega): (&[f64], f64),
    n: usize,
    dof: usize,
    grad_a: &[f64],
    opts: &LocateOptions,
) -> Result<(f64, f64), HbError> {
    let c = tangent_at(&mut t.at, q, omega)?;
    let psi_p = (peak_test(&mut t.plus, (q, omega), &c, n, dof)
        - peak_test(&mut t.minus, (q, omega), &c, n, dof))
        / (2.0 * t.h);
    let mut test =
        move |br: &mut FamilyBranch<F>, q: &[f64], l: f64| peak_test(br, (q, l), &c, n, dof);
    scalar_adjoint(t, (q, omega), &mut test, psi_p, grad_a, opts)
}
