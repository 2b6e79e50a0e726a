//! Fold curve (codimension 2): a fold of the frequency response of a model
//! family `family(p)` followed in (ω, p) through its cusps
//! ([`crate::fold_curve`]: the extended system `R = 0`, `Φ_q v = 0`,
//! `|v| = 1` of Eq. 56/61 continued by Eq. 68–77 in `p`). The start is a
//! given fold, or the fold of largest ω_f located on the FRC of
//! `family(p_start)` over an interval.

use super::{finite, Array};
use crate::codim2::FoldPoint as CurveFold;
use crate::continuation::{ContinuationOptions, Termination};
use crate::error::HbError;
use crate::events::BifurcationKind;
use crate::frc::{frequency_response, FrcOptions};
use crate::ihb::{HbOptions, HbSolution};
use crate::problem::PeriodicProblem;
use serde::Serialize;
use std::time::Instant;

/// Where the fold curve starts.
#[derive(Debug, Clone, PartialEq)]
pub enum FoldStart {
    /// A located fold of the FRC of `family(p_start)` (with the same
    /// harmonics and samples): its ω_f and coefficients.
    Given {
        /// ω_f of the fold.
        omega: f64,
        /// Its coefficients.
        coeffs: Vec<f64>,
    },
    /// The located fold of largest ω_f on the FRC of `family(p_start)`
    /// traced from `from` to `to`.
    Search {
        /// Start of the FRC.
        from: f64,
        /// End of the FRC.
        to: f64,
    },
}

/// The start, the interval of `p` and the path's steps.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldCurveRequest {
    /// The start fold.
    pub start: FoldStart,
    /// `p` of the start.
    pub p_start: f64,
    /// The curve goes first towards this `p` …
    pub p_from: f64,
    /// … and ends where `p` leaves `[p_from, p_to]`.
    pub p_to: f64,
    /// `p` at which the folds are located exactly (each crossing).
    pub at: Vec<f64>,
    /// First arclength step.
    pub ds: f64,
    /// Largest arclength step.
    pub ds_max: f64,
    /// Most path points.
    pub max_points: usize,
}

impl Default for FoldCurveRequest {
    /// The thesis Duffing's upper fold searched on ω_f ∈ [0.5, 2.5] at
    /// p = 0.1, followed from p = 0 to 0.3 in steps up to 0.05.
    fn default() -> Self {
        Self {
            start: FoldStart::Search { from: 0.5, to: 2.5 },
            p_start: 0.1,
            p_from: 0.0,
            p_to: 0.3,
            at: Vec::new(),
            ds: 0.02,
            ds_max: 0.05,
            max_points: 5000,
        }
    }
}

impl FoldCurveRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite number or no path point
    /// (the interval and the start fold are checked by
    /// [`crate::fold_curve`]).
    pub fn validate(&self) -> Result<(), HbError> {
        match &self.start {
            FoldStart::Given { omega, coeffs } => {
                finite("omega", *omega)?;
                if coeffs.iter().any(|c| !c.is_finite()) {
                    return Err(HbError::InvalidInput(
                        "the start fold's coefficients must be finite".into(),
                    ));
                }
            }
            FoldStart::Search { from, to } => {
                finite("from", *from)?;
                finite("to", *to)?;
            }
        }
        for (name, v) in [
            ("p_start", self.p_start),
            ("p_from", self.p_from),
            ("p_to", self.p_to),
            ("ds", self.ds),
            ("ds_max", self.ds_max),
        ] {
            finite(name, v)?;
        }
        if let Some(p) = self.at.iter().find(|p| !p.is_finite()) {
            return Err(HbError::InvalidInput(format!("`at` = {p} must be finite")));
        }
        if self.max_points == 0 {
            return Err(HbError::InvalidInput("`max_points` must be ≥ 1".into()));
        }
        Ok(())
    }
}

/// One fold on the curve.
#[derive(Debug, Clone, Serialize)]
pub struct CurveFoldPoint {
    /// ω_f of the fold.
    pub omega: f64,
    /// The second parameter.
    pub p: f64,
    /// max |x_0| over one period (DOF 0).
    pub amplitude: f64,
    /// Coefficients of the orbit there.
    pub coeffs: Array<f64>,
}

/// What a special point of a fold curve is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpecialKind {
    /// Two folds merge (a turning point of the curve in `p`).
    Cusp,
}

/// A special point of the curve.
#[derive(Debug, Clone, Serialize)]
pub struct SpecialPoint {
    /// What it is.
    pub kind: SpecialKind,
    /// Where.
    #[serde(flatten)]
    pub point: CurveFoldPoint,
}

/// A fold curve: the keys of `ivt hb duffing-folds --json` and of the dicts
/// of `ivt.hb.duffing_folds` and `ivt.hb.continue_bifurcation`.
#[derive(Debug, Clone, Serialize)]
pub struct FoldCurveResult {
    /// The bifurcation followed (a fold).
    pub kind: BifurcationKind,
    /// The start fold's ω_f.
    pub start_omega: f64,
    /// Points in path order.
    pub points: Vec<CurveFoldPoint>,
    /// The fold at each requested `p`, each crossing, in path order.
    pub at: Vec<CurveFoldPoint>,
    /// Cusps in path order.
    pub special: Vec<SpecialPoint>,
    /// Why the path stopped.
    pub termination: Termination,
    /// Wall time of the whole job (the start's FRC included).
    pub time_s: f64,
}

/// The fold curve of `family` from `req`'s start.
///
/// # Errors
/// [`FoldCurveRequest::validate`]'s; `family(p_start)`'s; with
/// [`FoldStart::Search`], the FRC's and [`HbError::InvalidInput`] when it has
/// no located fold; [`crate::fold_curve`]'s.
pub fn fold_curve<P, F>(
    family: F,
    hb: &HbOptions,
    req: &FoldCurveRequest,
) -> Result<FoldCurveResult, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    req.validate()?;
    let t0 = Instant::now();
    let (omega, coeffs) = match &req.start {
        FoldStart::Given { omega, coeffs } => (*omega, coeffs.clone()),
        FoldStart::Search { from, to } => {
            let opts = FrcOptions {
                from: *from,
                to: *to,
                ..FrcOptions::default()
            };
            let frc = frequency_response(&family(req.p_start)?, hb, &opts)?;
            let fold = frc
                .folds
                .iter()
                .filter(|f| f.located)
                .max_by(|x, y| x.omega_f.total_cmp(&y.omega_f))
                .ok_or_else(|| {
                    HbError::InvalidInput(format!(
                        "the FRC from ω_f = {from} to {to} at p = {} has no located fold to start from",
                        req.p_start
                    ))
                })?;
            (fold.omega_f, fold.coeffs.clone())
        }
    };
    let copts = ContinuationOptions {
        ds: req.ds,
        ds_max: req.ds_max,
        max_points: req.max_points,
        ..ContinuationOptions::default()
    };
    let curve = crate::fold_curve(
        family,
        hb,
        &coeffs,
        omega,
        req.p_start,
        req.p_from,
        req.p_to,
        &req.at,
        &copts,
    )?;
    let sample = |f: &CurveFold| sample(f, hb.harmonics);
    Ok(FoldCurveResult {
        kind: BifurcationKind::Fold,
        start_omega: omega,
        points: curve.points.iter().map(sample).collect(),
        at: curve.at.iter().map(sample).collect(),
        special: curve
            .cusps
            .iter()
            .map(|c| SpecialPoint {
                kind: SpecialKind::Cusp,
                point: sample(c),
            })
            .collect(),
        termination: curve.termination,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// A fold of the curve with its amplitude ([`HbSolution::amplitude`]).
fn sample(f: &CurveFold, harmonics: usize) -> CurveFoldPoint {
    let orbit = HbSolution {
        coeffs: f.coeffs.clone(),
        omega_f: f.omega,
        harmonics,
        subharmonic: 1,
        stats: Default::default(),
    };
    CurveFoldPoint {
        omega: f.omega,
        p: f.p,
        amplitude: orbit.amplitude(0),
        coeffs: Array(orbit.coeffs),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Duffing;

    #[test]
    fn duffing_folds_through_the_cusp_are_the_shooting_folds() {
        // The thesis Duffing in F from the F = 0.1 upper fold down to the
        // cusp and up the lower fold: by shooting (tests/fold_curve.rs) the
        // folds at F = 0.2 and 0.3 are at ω = 1.2589591460 and 1.3297591465,
        // the cusp at F = 0.0120510724.
        let family = |f: f64| Ok(Duffing::new(0.02, 1.0, 1.0, f));
        let hb = HbOptions::new(15, 64).with_tol(1e-10);
        let req = FoldCurveRequest {
            at: vec![0.2, 0.3],
            ..FoldCurveRequest::default()
        };
        let c = fold_curve(family, &hb, &req).unwrap();
        assert_eq!(c.termination, Termination::LeftInterval);
        let omegas: Vec<f64> = c.at.iter().map(|p| p.omega).collect();
        assert_eq!(omegas.len(), 2, "{omegas:?}");
        for (got, want) in omegas.iter().zip([1.2589591460, 1.3297591465]) {
            assert!((got - want).abs() < 1e-7, "{got} vs {want}");
        }
        assert_eq!(c.special.len(), 1);
        assert!((c.special[0].point.p / 0.0120510724 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn an_frc_without_a_fold_is_an_input_error() {
        let family = |f: f64| Ok(Duffing::new(0.02, 1.0, 1.0, f));
        let req = FoldCurveRequest {
            p_start: 0.001,
            ..FoldCurveRequest::default()
        };
        let e = fold_curve(family, &HbOptions::new(10, 32), &req).unwrap_err();
        assert!(e.to_string().contains("no located fold"), "{e}");
    }
}
