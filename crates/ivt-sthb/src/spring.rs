//! Frequency–response of the string with the spring boundary (§3.3.5, Fig. 36)
//! by the spectral Tau method, solved with Broyden's method as in the thesis.
//!
//! The residual is [`StringHb`] with [`super::Boundary::Spring`] (Tau rows
//! Eq. 134–136); the path follower is the engine's
//! [`ivt_path::continuation::Stepper`] with [`ivt_path::continuation::BroydenCorrector`]: Broyden's
//! method (Eq. 66–67) with the exact augmenting row. It is seeded once with the
//! exact STHB Jacobian `[J | ∂R/∂ω]` at the start point; afterwards only
//! rank-one updates (and the engine's Jacobian refresh if Broyden stalls).

use faer::Mat;

use ivt_path::continuation::{follow_residual, ContinuationOptions, Termination};

use super::{StringHb, StringParams};
use ivt_hb::HbError;

/// One point `(ω, ‖a‖)` of a spring-boundary curve, with the solution.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringPoint {
    /// Excitation frequency.
    pub omega: f64,
    /// `‖a‖` over all `N + 1` coordinates (complex coefficients, Fig. 36).
    pub norm: f64,
    /// Broyden corrector iterations.
    pub iterations: usize,
}

/// Trace ‖a‖(ω) from `omega_from` to `omega_to` (`omega_from < omega_to`).
///
/// # Errors
/// [`HbError::InvalidInput`] for bad parameters, [`HbError::NoConvergence`] if
/// the start does not converge, [`HbError::Stalled`] if the path stops short.
pub fn spring_frequency_response(
    params: StringParams,
    omega_from: f64,
    omega_to: f64,
    step_max: f64,
) -> Result<Vec<SpringPoint>, HbError> {
    if !(omega_from > 0.0 && omega_to > omega_from && omega_to.is_finite()) {
        return Err(HbError::InvalidInput(format!(
            "need 0 < from < to, got {omega_from:?} .. {omega_to:?}"
        )));
    }
    let mut hb = StringHb::new(params)?;
    let n = hb.dim();
    // Start: Newton with the exact Jacobian, then the seed Jacobian [J | R_ω].
    let mut a = vec![0.0; n];
    hb.solve(omega_from, &mut a, 1e-12, 50)?;
    let (mut r, mut r_w, mut jac) = (vec![0.0; n], vec![0.0; n], Mat::<f64>::zeros(n, n));
    hb.residual_jacobian(&a, omega_from, &mut r, &mut jac);
    hb.d_residual_d_omega(&a, omega_from, &mut r_w);
    // Row i of [J | R_ω].
    let mut jac0 = vec![0.0; n * (n + 1)];
    for ((i, row), rw) in jac0.chunks_exact_mut(n + 1).enumerate().zip(&r_w) {
        let (row_j, row_w) = row.split_at_mut(n);
        for (j, x) in row_j.iter_mut().enumerate() {
            *x = jac[(i, j)];
        }
        row_w.fill(*rw);
    }
    let mut start = a.clone();
    start.push(omega_from);
    let opts = ContinuationOptions {
        ds: 0.5 * step_max,
        ds_max: step_max,
        lambda_min: omega_from,
        lambda_max: omega_to,
        target_iter: 10,
        ..Default::default()
    };
    // x = [a, ω].
    let residual = |x: &[f64], out: &mut [f64]| match x.split_last() {
        Some((&omega, a)) => hb.residual(a, omega, out),
        None => out.fill(f64::NAN),
    };
    let path = follow_residual(residual, &start, Some(&jac0), 1.0, &opts, |p| {
        if std::env::var_os("IVT_STHB_TRACE").is_some() {
            eprintln!("spring point ω = {:.5} its {}", p.lambda(), p.iterations);
        }
        true
    })?;
    let points = path
        .points
        .iter()
        .map(|p| {
            Ok(SpringPoint {
                omega: p.lambda(),
                norm: hb.complex_norm(super::frc::coefficients(p, n)?),
                iterations: p.iterations,
            })
        })
        .collect::<Result<Vec<_>, HbError>>()?;
    if let Termination::StepTooSmall(e) = path.termination {
        let last = points.last().map_or(omega_from, |p| p.omega);
        return Err(HbError::Stalled {
            omega: last,
            step: opts.ds_min,
            cause: Box::new(HbError::Solve(e)),
        });
    }
    Ok(points)
}
