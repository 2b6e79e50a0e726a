//! How a located feature of a frequency response moves with a parameter of
//! its model family (issue 45 item 3): [`ivt_hb::analyses::sensitivity`] on a fold,
//! period doubling, Neimark–Sacker point, branch point or amplitude peak
//! given by its ω_f and orbit (an entry of `frc(..., events=True)`'s
//! `bifurcations` or `folds`, or a point near the peak).

use super::{finite, Array};
use ivt_hb::analyses::sensitivity::{sensitivity, Feature};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{boxed_family, BoxedFamily, PeriodicProblem};
use ivt_hb::HbError;
use serde::Serialize;
use std::time::Instant;

/// The feature and the parameter value it was computed at.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityRequest {
    /// What it is.
    pub feature: Feature,
    /// ω_f of the feature (or near the peak).
    pub omega: f64,
    /// Its orbit (the HB options' harmonics).
    pub coeffs: Vec<f64>,
    /// The family's parameter there.
    pub p: f64,
    /// The DOF whose amplitude `A` is differentiated.
    pub amplitude_dof: usize,
}

/// The keys of `ivt.hb.event_sensitivity`.
#[derive(Debug, Clone, Serialize)]
pub struct SensitivityResult {
    /// The feature (`fold`, `period_doubling`, `neimark_sacker`,
    /// `branch_point`, `peak`).
    pub kind: &'static str,
    /// The parameter.
    pub p: f64,
    /// ω_f of the feature, located again at `p`.
    pub omega: f64,
    /// max |x_d| of its orbit.
    pub amplitude: f64,
    /// `dω_f/dp`.
    pub d_omega_dp: f64,
    /// `dA/dp`.
    pub d_amplitude_dp: f64,
    /// The orbit.
    pub coeffs: Array<f64>,
    /// Newton steps of the location.
    pub iterations: usize,
    /// Wall time.
    pub time_s: f64,
}

/// The sensitivity of `req`'s feature of `family(p)`'s frequency response.
///
/// # Errors
/// [`HbError::InvalidInput`] for a non-finite ω_f, p or coefficients;
/// [`ivt_hb::analyses::sensitivity::sensitivity`]'s.
pub fn event_sensitivity<'p, P, F>(
    family: F,
    hb: &HbOptions,
    req: &SensitivityRequest,
) -> Result<SensitivityResult, HbError>
where
    P: PeriodicProblem + 'p,
    F: Fn(f64) -> Result<P, HbError>,
{
    event_sensitivity_of(&boxed_family(family), hb, req)
}

/// [`event_sensitivity`] on the boxed family.
fn event_sensitivity_of(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    req: &SensitivityRequest,
) -> Result<SensitivityResult, HbError> {
    let t0 = Instant::now();
    let (omega, p) = (finite("omega", req.omega)?, finite("p", req.p)?);
    super::finite_list("coeffs", &req.coeffs)?;
    let s = sensitivity(
        family,
        hb,
        req.feature,
        (&req.coeffs, omega),
        p,
        req.amplitude_dof,
    )?;
    Ok(SensitivityResult {
        kind: s.feature.name(),
        p,
        omega: s.omega,
        amplitude: s.amplitude,
        d_omega_dp: s.d_omega_dp,
        d_amplitude_dp: s.d_amplitude_dp,
        coeffs: Array(s.coeffs),
        iterations: s.iterations,
        time_s: t0.elapsed().as_secs_f64(),
    })
}
