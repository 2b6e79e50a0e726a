//! Backbone curve (nonlinear normal mode) of an undamped, unforced system,
//! followed in amplitude from a linear mode with ω unknown (phase condition
//! b1 = 0, a fictitious damping κ unfolding the family: [`ivt_hb::backbone()`]).

use super::{finite, Array};
use ivt_hb::branches::backbone::{BackboneOptions, BackbonePoint};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{GeneralProblem, PeriodicProblem};
use ivt_hb::HbError;
use ivt_path::continuation::{Corrector, Termination};
use serde::Serialize;

/// The undamped, unforced Duffing oscillator `u'' + αu + εu³ = 0` as the
/// general problem `M = 1, C = 0, K = α, g = εu³` (velocity independent):
/// the system of `ivt hb duffing-backbone`, built as Python builds it from
/// `m, c, k, g`, so that both run the same arithmetic.
pub fn free_duffing(alpha: f64, eps: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![0.0],
        vec![alpha],
        move |x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]| {
            if let (Some(g), Some(&x)) = (out.first_mut(), x.first()) {
                *g = eps * x * x * x;
            }
        },
        |_theta: f64, out: &mut [f64]| out.fill(0.0),
    )
    .with_velocity_dependent(false)
}

/// The linear mode to start from and the backbone's options.
#[derive(Debug, Clone, PartialEq)]
pub struct BackboneRequest {
    /// Linear frequency ω₀ of the mode (K·mode = ω₀² M·mode).
    pub omega0: f64,
    /// Mode shape (n_dof entries).
    pub mode: Vec<f64>,
    /// The reference DOF, the amplitude interval and the path.
    pub options: BackboneOptions,
}

impl Default for BackboneRequest {
    /// One DOF of unit frequency, a1 from 0.01 to 1, Newton–chord corrector.
    fn default() -> Self {
        let mut options = BackboneOptions::default();
        options.continuation.corrector = Corrector::Newton;
        Self {
            omega0: 1.0,
            mode: vec![1.0],
            options,
        }
    }
}

impl BackboneRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite frequency or amplitude (the
    /// mode and the system are checked by [`ivt_hb::backbone()`]).
    pub fn validate(&self) -> Result<(), HbError> {
        finite("omega0", self.omega0)?;
        finite("amplitude_from", self.options.amplitude_from)?;
        finite("amplitude_to", self.options.amplitude_to)?;
        Ok(())
    }
}

/// One point of the backbone.
#[derive(Debug, Clone, Serialize)]
pub struct BackboneSample {
    /// a1 of the amplitude DOF.
    pub amplitude: f64,
    /// Frequency ω.
    pub omega: f64,
    /// Fictitious damping κ (~0 on the result).
    pub kappa: f64,
    /// max |x| of the amplitude DOF over one period (the ordinate of a
    /// response curve's `amplitude`).
    pub peak: f64,
    /// Coefficients.
    pub coeffs: Array<f64>,
}

/// A backbone: the keys of `ivt.hb.backbone`.
#[derive(Debug, Clone, Serialize)]
pub struct BackboneCurve {
    /// a1 of every point (a column).
    pub amplitude: Array<f64>,
    /// ω of every point.
    pub omega: Array<f64>,
    /// κ of every point.
    pub kappa: Array<f64>,
    /// The points.
    pub points: Vec<BackboneSample>,
    /// Why the path stopped.
    pub termination: Termination,
}

/// The backbone of `problem` from `req`'s mode.
///
/// # Errors
/// [`BackboneRequest::validate`]'s and [`ivt_hb::backbone()`]'s.
pub fn backbone(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &BackboneRequest,
) -> Result<BackboneCurve, HbError> {
    req.validate()?;
    let bb = ivt_hb::backbone(problem, hb, req.omega0, &req.mode, &req.options)?;
    let col = |f: fn(&BackbonePoint) -> f64| bb.points.iter().map(f).collect();
    Ok(BackboneCurve {
        amplitude: col(|p| p.amplitude),
        omega: col(|p| p.omega),
        kappa: col(|p| p.kappa),
        points: bb
            .points
            .iter()
            .map(|p| BackboneSample {
                amplitude: p.amplitude,
                omega: p.omega,
                kappa: p.kappa,
                peak: p.peak,
                coeffs: Array(p.coeffs.clone()),
            })
            .collect(),
        termination: bb.termination,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_hb::Duffing;

    #[test]
    fn duffing_backbone_follows_the_first_order_frequency_law() {
        // u'' + u + u³ = 0: ω² ≈ 1 + 3a²/4 for small a (Lindstedt); at
        // a1 = 0.1 the O(a⁴) rest is below 1e-5.
        let d = Duffing::new(0.0, 1.0, 1.0, 0.0);
        let hb = HbOptions::new(10, 32);
        let mut req = BackboneRequest::default();
        req.options.amplitude_to = 0.1;
        let bb = backbone(&d, &hb, &req).unwrap();
        assert_eq!(bb.termination, Termination::LeftInterval);
        let last = bb.points.last().unwrap();
        let a = last.amplitude;
        let law = (1.0 + 0.75 * a * a).sqrt();
        assert!((last.omega - law).abs() < 1e-5, "{} vs {law}", last.omega);
        assert!(bb.kappa.0.iter().all(|k| k.abs() < 1e-8));
    }
}
