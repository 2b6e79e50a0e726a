//! The frequency-response curve of the nonlinear string by space–time
//! harmonic balance (STHB, §3.3, Eq. 103; Figs. 34–36): Newton arclength on
//! the exact (Tau) Jacobian for both boundaries, stability by monodromy,
//! confirmed by Hill's method near |μ| = 1 (Eq. 130–131).

use ivt_hb::branches::frc::Frc;
use ivt_hb::stability::StabilityKind;
use ivt_hb::HbError;
use ivt_path::continuation::{Steps, Termination};
use ivt_sthb::frc::{frequency_response, StringFrcOptions};
use ivt_sthb::stability::StabilityMethod;
use ivt_sthb::{Boundary, StringHb, StringParams};
use serde::Serialize;
use std::time::Instant;

/// Largest |k_d| accepted: from k_d ≈ 1e9 on the trace ends in an error
/// after seconds, growing to ~12 s at 1e17 (measured with `ivt hb string`,
/// not asserted; the thesis uses 10 and 30).
pub const MAX_KD: f64 = 1e9;

/// The string, the interval in ω and the path's steps.
#[derive(Debug, Clone, PartialEq)]
pub struct StringRequest {
    /// The model and its discretization.
    pub params: StringParams,
    /// Start frequency (> 0).
    pub from: f64,
    /// End frequency (> `from`, finite).
    pub to: f64,
    /// The path's steps and most points (by default those of
    /// [`StringFrcOptions`]: Δη from 0.02 up to 0.05, 2000 points).
    pub steps: Steps,
}

impl Default for StringRequest {
    /// k_d = 10, N = 5, M = 19, fixed–fixed, ω from 1 to 6, steps ≤ 0.05.
    fn default() -> Self {
        Self {
            params: StringParams::default(),
            from: 1.0,
            to: 6.0,
            steps: Steps::default(),
        }
    }
}

impl StringRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for |k_d| > [`MAX_KD`], invalid
    /// [`StringParams`], unless 0 < from < to (finite), or for steps
    /// [`Steps::on`] refuses.
    pub fn validate(&self) -> Result<(), HbError> {
        let kd = self.params.kd;
        if !(kd.is_finite() && kd.abs() <= MAX_KD) {
            return Err(HbError::InvalidInput(format!(
                "`kd` = {kd:?} must be finite with |kd| <= {MAX_KD:e}"
            )));
        }
        self.params.validate()?;
        let (from, to) = (self.from, self.to);
        if !(from > 0.0 && to > from && to.is_finite()) {
            return Err(HbError::InvalidInput(format!(
                "need 0 < `from` < `to` (finite), got {from:?} .. {to:?}"
            )));
        }
        self.options().map(|_| ())
    }

    /// The default [`StringFrcOptions`] with the request's steps.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn options(&self) -> Result<StringFrcOptions, HbError> {
        let mut opts = StringFrcOptions::default();
        opts.continuation = self
            .steps
            .on(opts.continuation)
            .map_err(HbError::InvalidInput)?;
        Ok(opts)
    }
}

/// One point of the string's curve.
#[derive(Debug, Clone, Serialize)]
pub struct StringPoint {
    /// ω.
    pub omega: f64,
    /// ‖a‖ (Eq. 114).
    pub norm: f64,
    /// The verdict.
    pub stable: bool,
    /// The leading multiplier's class.
    pub kind: StabilityKind,
    /// |μ| of the leading multiplier.
    pub max_multiplier: Option<f64>,
    /// Hill or monodromy.
    pub method: StabilityMethod,
}

/// A fold of the string's curve.
#[derive(Debug, Clone, Serialize)]
pub struct StringFold {
    /// ω at the turn.
    pub omega: f64,
    /// ‖a‖ there.
    pub norm: f64,
    /// Converged on the extended system (else the path's turning point).
    pub located: bool,
    /// Path point before the turn.
    pub index: usize,
}

/// The curve: the keys of `ivt hb string --json` and `ivt.hb.string`.
#[derive(Debug, Clone, Serialize)]
pub struct StringCurve {
    /// Points in path order.
    pub points: Vec<StringPoint>,
    /// Folds in path order.
    pub folds: Vec<StringFold>,
    /// Exact Jacobians assembled.
    pub jacobians: usize,
    /// Hill's method calls.
    pub hill_calls: usize,
    /// Why the path stopped.
    pub stop: Termination,
    /// Wall time of the whole job.
    pub solve_time_s: f64,
    /// For a spring of k0 > 1 (Eq. 132 as printed is a negative spring):
    /// what `stable` means there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub boundary_note: Option<String>,
    /// The traced curve (for plots; not serialized).
    #[serde(skip)]
    pub frc: Frc,
}

/// Trace the string's curve of `req`.
///
/// # Errors
/// [`StringRequest::validate`]'s; the trace's (cold start, stalled step,
/// Hill's method) are numerical failures.
pub fn string(req: &StringRequest) -> Result<StringCurve, HbError> {
    req.validate()?;
    let opts = req.options()?;
    let t0 = Instant::now();
    // Newton arclength with the exact (Tau) Jacobian for both boundaries: the
    // engine's Broyden continuation (`spring_frequency_response`, §3.3.5)
    // gives the same spring curve ~50× slower (docs/guide/src/model/string.md).
    let mut hb = StringHb::new(req.params.clone())?;
    let curve = frequency_response(&mut hb, req.from, req.to, &opts)?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    let points = curve
        .frc
        .points
        .iter()
        .zip(&curve.methods)
        .map(|(p, &method)| StringPoint {
            omega: p.omega_f,
            norm: p.amplitude,
            stable: p.stable(),
            kind: p.kind,
            max_multiplier: p.multipliers.first().map(|m| m.norm()),
            method,
        })
        .collect();
    let boundary_note = match req.params.boundary {
        Boundary::Spring { k0 } if k0 > 1.0 => Some(format!(
            "Eq. 132 as printed (k0 w = +w_x) is a negative spring: for k0 > 1 the continuous \
             string has a growing mode (tanh γ = γ/k0). `stable` is the verdict of the \
             {}-mode Tau model, which resolves that mode only when N > (k0 − 1)/2; \
             a restoring spring of stiffness k is --k0=-k",
            req.params.modes
        )),
        _ => None,
    };
    let folds = curve
        .frc
        .events
        .iter()
        .map(|f| StringFold {
            omega: f.omega_f,
            norm: f.amplitude,
            located: f.located,
            index: f.index,
        })
        .collect();
    Ok(StringCurve {
        points,
        folds,
        jacobians: curve.jacobians,
        hill_calls: curve.hill_calls,
        stop: curve.frc.termination.clone(),
        solve_time_s,
        boundary_note,
        frc: curve.frc,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_kd_and_reversed_interval_are_input_errors() {
        let mut req = StringRequest::default();
        req.params.kd = 2f64.powi(63);
        assert!(string(&req).unwrap_err().to_string().contains("`kd`"));
        let req = StringRequest {
            from: 3.0,
            to: 1.0,
            ..StringRequest::default()
        };
        assert_eq!(req.validate().unwrap_err().kind(), "input");
    }
}
