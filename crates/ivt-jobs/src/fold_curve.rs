//! Bifurcation curves (codimension 2) of a model family `family(p)` in
//! (ω, p): a fold of the frequency response followed through its cusps
//! ([`ivt_hb::fold_curve`]: the extended system `R = 0`, `Φ_q v = 0`,
//! `|v| = 1` of Eq. 56/61 continued by Eq. 68–77 in `p`), or a period
//! doubling or Neimark–Sacker point to the ends of its curve with the strong
//! resonances on it ([`ivt_hb::branches::codim2::bifurcation_curve`]: `R = 0` with the
//! critical eigenvector of the monodromy matrix, Eq. 80). The start is a
//! given point, or the point of that kind of largest ω_f located on the FRC
//! of `family(p_start)` over an interval.

use super::{all_finite, finite, finite_list, path_steps, Array, FrcRequest, Steps};
use ivt_hb::branches::codim2::{bifurcation_curve, CurvePoint, CurveStart};
use ivt_hb::branches::events::BifurcationKind;
use ivt_hb::branches::events::Unlocated;
use ivt_hb::branches::frc::{frequency_response, FrcOptions};
use ivt_hb::orbit::ihb::{HbOptions, HbSolution};
use ivt_hb::problem::{boxed_family, BoxedFamily, PeriodicProblem};
use ivt_hb::HbError;
use ivt_path::continuation::{ContinuationOptions, Corrector, Termination};
use serde::Serialize;
use std::time::Instant;

/// Where the curve starts.
#[derive(Debug, Clone, PartialEq)]
pub enum FoldStart {
    /// A located point of the request's kind on the FRC of
    /// `family(p_start)` (with the same harmonics and samples): its ω_f and
    /// coefficients.
    Given {
        /// ω_f of the point.
        omega: f64,
        /// Its coefficients.
        coeffs: Vec<f64>,
    },
    /// The located point of the request's kind of largest ω_f on the FRC of
    /// `family(p_start)` traced from `from` to `to` (with its events unless
    /// the kind is a fold).
    Search {
        /// Start of the FRC.
        from: f64,
        /// End of the FRC.
        to: f64,
    },
}

/// The kind, the start, the interval of `p` and the path's steps.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldCurveRequest {
    /// What is followed: a fold, a period doubling or a Neimark–Sacker
    /// point (not a branch point).
    pub kind: BifurcationKind,
    /// The start point.
    pub start: FoldStart,
    /// `p` of the start.
    pub p_start: f64,
    /// The curve goes first towards this `p`, then from the start the other
    /// way …
    pub p_from: f64,
    /// … and ends where `p` leaves `[p_from, p_to]`.
    pub p_to: f64,
    /// `p` at which the folds are located exactly (each crossing).
    pub at: Vec<f64>,
    /// The path's steps and most points (by default Δη from 0.02 up to
    /// 0.05, 5000 points: [`FOLD_CURVE_STEPS`]).
    pub steps: Steps,
}

/// The curve's own first step, largest step and most points.
pub const FOLD_CURVE_STEPS: (f64, f64, usize) = (0.02, 0.05, 5000);

impl Default for FoldCurveRequest {
    /// The thesis Duffing's upper fold searched on ω_f ∈ [0.5, 2.5] at
    /// p = 0.1, followed from p = 0 to 0.3 in steps up to 0.05.
    fn default() -> Self {
        Self {
            kind: BifurcationKind::Fold,
            start: FoldStart::Search { from: 0.5, to: 2.5 },
            p_start: 0.1,
            p_from: 0.0,
            p_to: 0.3,
            at: Vec::new(),
            steps: Steps::default(),
        }
    }
}

impl FoldCurveRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite number or no path point
    /// (the interval and the start fold are checked by
    /// [`ivt_hb::fold_curve`]).
    pub fn validate(&self) -> Result<(), HbError> {
        if self.kind == BifurcationKind::BranchPoint {
            return Err(HbError::InvalidInput(
                "branch points are not continued in two parameters".into(),
            ));
        }
        match &self.start {
            FoldStart::Given { omega, coeffs } => {
                finite("omega", *omega)?;
                if coeffs.iter().any(|c| !c.is_finite()) {
                    return Err(HbError::InvalidInput(
                        "the start point's coefficients must be finite".into(),
                    ));
                }
            }
            FoldStart::Search { from, to } => {
                finite("from", *from)?;
                finite("to", *to)?;
            }
        }
        all_finite(&[
            ("p_start", self.p_start),
            ("p_from", self.p_from),
            ("p_to", self.p_to),
        ])?;
        finite_list("at", &self.at)?;
        self.path().map(|_| ())
    }

    /// [`FOLD_CURVE_STEPS`] with the request's `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn path(&self) -> Result<ContinuationOptions, HbError> {
        path_steps(&self.steps, FOLD_CURVE_STEPS)
    }
}

/// One point of the curve.
#[derive(Debug, Clone, Serialize)]
pub struct CurveFoldPoint {
    /// ω_f of the point.
    pub omega: f64,
    /// The second parameter.
    pub p: f64,
    /// max |x_0| over one period (DOF 0).
    pub amplitude: f64,
    /// Coefficients of the orbit there.
    pub coeffs: Array<f64>,
    /// Angle θ of the critical multipliers `e^{±iθ}` (π on a
    /// period-doubling curve); absent on a fold curve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
}

/// What a special point of a curve is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpecialKind {
    /// Two folds merge (a turning point of the curve in `p`).
    Cusp,
    /// A Neimark–Sacker curve ends on a fold curve (θ = 0).
    #[serde(rename = "resonance_1_1")]
    Resonance1To1,
    /// A Neimark–Sacker curve ends on a period-doubling curve (θ = π).
    #[serde(rename = "resonance_1_2")]
    Resonance1To2,
    /// θ = 2π/3 on a Neimark–Sacker curve.
    #[serde(rename = "resonance_1_3")]
    Resonance1To3,
    /// θ = π/2 on a Neimark–Sacker curve.
    #[serde(rename = "resonance_1_4")]
    Resonance1To4,
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

/// A point the curve passed but could not locate (`ivt_hb`'s
/// `Unlocated`): what was sought, the path point the locator started from,
/// and why it failed.
#[derive(Debug, Clone, Serialize)]
pub struct UnlocatedPoint {
    /// `"at"`, `"cusp"` or `"resonance_1_1"` … `"resonance_1_4"`.
    pub what: &'static str,
    /// The requested `p` of an `at` point (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// The locator's failure in words (at an `at` value where the family
    /// itself fails, followed by its error).
    pub reason: String,
    /// The path point the locator started from.
    pub near: CurveFoldPoint,
}

/// A bifurcation curve: the keys of `ivt hb duffing-folds --json`,
/// `ivt hb vdp-torus --json` and of the dicts of `ivt.hb.duffing_folds` and
/// `ivt.hb.continue_bifurcation`.
#[derive(Debug, Clone, Serialize)]
pub struct FoldCurveResult {
    /// The bifurcation followed.
    pub kind: BifurcationKind,
    /// The start point's ω_f.
    pub start_omega: f64,
    /// Points in path order.
    pub points: Vec<CurveFoldPoint>,
    /// The fold at each requested `p`, each crossing, in path order.
    pub at: Vec<CurveFoldPoint>,
    /// Cusps in path order (fold curves); resonances 1:1, 1:2, 1:3, 1:4
    /// in that order (Neimark–Sacker curves); none on period-doubling
    /// curves.
    pub special: Vec<SpecialPoint>,
    /// The `at` points, cusps and resonances the path passed but whose
    /// location failed, in path order (none is dropped silently).
    pub unlocated: Vec<UnlocatedPoint>,
    /// Why the path stopped.
    pub termination: Termination,
    /// Wall time of the whole job (the start's FRC included).
    pub time_s: f64,
}

/// The curve of `req.kind` of `family` from `req`'s start.
///
/// # Errors
/// [`FoldCurveRequest::validate`]'s; `family(p_start)`'s; with
/// [`FoldStart::Search`], the FRC's and [`HbError::InvalidInput`] when it has
/// no located point of the kind; [`ivt_hb::fold_curve`]'s or
/// [`ivt_hb::branches::codim2::bifurcation_curve`]'s.
pub fn fold_curve<'p, P, F>(
    family: F,
    hb: &HbOptions,
    req: &FoldCurveRequest,
) -> Result<FoldCurveResult, HbError>
where
    P: PeriodicProblem + 'p,
    F: Fn(f64) -> Result<P, HbError>,
{
    fold_curve_of(&boxed_family(family), hb, req)
}

/// [`fold_curve`] on the boxed family.
fn fold_curve_of(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    req: &FoldCurveRequest,
) -> Result<FoldCurveResult, HbError> {
    req.validate()?;
    let t0 = Instant::now();
    let (omega, coeffs) = match &req.start {
        FoldStart::Given { omega, coeffs } => (*omega, coeffs.clone()),
        FoldStart::Search { from, to } => search_start(&family, hb, req, *from, *to)?,
    };
    let copts = req.path()?;
    let h = hb.harmonics;
    let (points, at, special, unlocated, termination) = if req.kind == BifurcationKind::Fold {
        let curve = ivt_hb::fold_curve(
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
        let fold = |f: &ivt_hb::FoldPoint| sample(f.omega, f.p, &f.coeffs, None, h);
        let cusps = curve.cusps.iter().map(|c| SpecialPoint {
            kind: SpecialKind::Cusp,
            point: fold(c),
        });
        (
            curve.points.iter().map(fold).collect(),
            curve.at.iter().map(fold).collect(),
            cusps.collect(),
            unlocated_points(&curve.unlocated, fold),
            curve.termination,
        )
    } else {
        let start = CurveStart {
            kind: req.kind,
            coeffs,
            omega,
            p: req.p_start,
        };
        let curve = bifurcation_curve(family, hb, &start, req.p_from, req.p_to, &req.at, &copts)?;
        let point = |c: &CurvePoint| sample(c.omega, c.p, &c.coeffs, Some(c.angle), h);
        let special = curve.resonances.iter().filter_map(|(order, c)| {
            let kind = match order {
                1 => SpecialKind::Resonance1To1,
                2 => SpecialKind::Resonance1To2,
                3 => SpecialKind::Resonance1To3,
                4 => SpecialKind::Resonance1To4,
                _ => return None,
            };
            Some(SpecialPoint {
                kind,
                point: point(c),
            })
        });
        (
            curve.points.iter().map(point).collect(),
            curve.at.iter().map(point).collect(),
            special.collect(),
            unlocated_points(&curve.unlocated, point),
            curve.termination,
        )
    };
    Ok(FoldCurveResult {
        kind: req.kind,
        start_omega: omega,
        points,
        at,
        special,
        unlocated,
        termination,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

/// The curve's unlocated points with `point` (its sample of a curve point)
/// as their `near`.
pub(crate) fn unlocated_points<T>(
    unlocated: &[Unlocated<T>],
    point: impl Fn(&T) -> CurveFoldPoint,
) -> Vec<UnlocatedPoint> {
    (unlocated.iter())
        .map(|u| UnlocatedPoint {
            what: u.what,
            value: u.value,
            reason: u.reason.clone(),
            near: point(&u.near),
        })
        .collect()
}

/// The located point of `req.kind` of largest ω_f on the FRC of
/// `family(req.p_start)` from `from` to `to`: its ω_f and coefficients.
fn search_start<P, F>(
    family: &F,
    hb: &HbOptions,
    req: &FoldCurveRequest,
    from: f64,
    to: f64,
) -> Result<(f64, Vec<f64>), HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let problem = family(req.p_start)?;
    let best = if req.kind == BifurcationKind::Fold {
        let opts = FrcOptions {
            from,
            to,
            ..FrcOptions::default()
        };
        frequency_response(&problem, hb, &opts)?
            .events
            .into_iter()
            .filter(|f| f.located)
            .map(|f| (f.omega_f, f.coeffs))
            .max_by(|x, y| x.0.total_cmp(&y.0))
    } else {
        let frc = FrcRequest {
            options: FrcOptions::sweep(from, to, Corrector::Newton),
            events: true,
        };
        super::frc(&problem, hb, &frc)?
            .bifurcations
            .into_iter()
            .filter(|e| e.kind == req.kind && e.located)
            .filter_map(|e| Some((e.omega?, e.coeffs?.0)))
            .max_by(|x, y| x.0.total_cmp(&y.0))
    };
    best.ok_or_else(|| {
        HbError::InvalidInput(format!(
            "the FRC from ω_f = {from:?} to {to:?} at p = {:?} has no located {} to start from",
            req.p_start,
            req.kind.words()
        ))
    })
}

/// A point of the curve with its amplitude ([`HbSolution::amplitude`]).
fn sample(
    omega: f64,
    p: f64,
    coeffs: &[f64],
    angle: Option<f64>,
    harmonics: usize,
) -> CurveFoldPoint {
    let orbit = HbSolution {
        coeffs: coeffs.to_vec(),
        omega_f: omega,
        harmonics,
        subharmonic: 1,
        stats: Default::default(),
    };
    CurveFoldPoint {
        omega,
        p,
        amplitude: orbit.amplitude(0),
        coeffs: Array(orbit.coeffs),
        angle,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_hb::Duffing;

    #[test]
    fn duffing_folds_through_the_cusp_are_the_shooting_folds() {
        // The thesis Duffing in F from the F = 0.1 upper fold down to the
        // cusp and up the lower fold, then up the upper fold: by shooting
        // (tests/fold_curve.rs) the folds at F = 0.2 are at ω = 1.2589591460
        // and 2.2115927040, at F = 0.3 at 1.3297591465 and 2.6572119678, the
        // cusp at F = 0.0120510724.
        let family = |f: f64| Ok(Duffing::new(0.02, 1.0, 1.0, f));
        let hb = HbOptions::new(15, 64).with_tol(1e-10);
        let req = FoldCurveRequest {
            at: vec![0.2, 0.3],
            ..FoldCurveRequest::default()
        };
        let c = fold_curve(family, &hb, &req).unwrap();
        assert_eq!(c.termination, Termination::LeftInterval);
        let mut found: Vec<(f64, f64)> = c.at.iter().map(|p| (p.p, p.omega)).collect();
        found.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert_eq!(found.len(), 4, "{found:?}");
        let want = [
            (0.2, 1.2589591460),
            (0.2, 2.2115927040),
            (0.3, 1.3297591465),
            (0.3, 2.6572119678),
        ];
        for (got, want) in found.iter().zip(want) {
            assert!(
                got.0 == want.0 && (got.1 - want.1).abs() < 1e-7,
                "{got:?} vs {want:?}"
            );
        }
        assert_eq!(c.special.len(), 1);
        assert!((c.special[0].point.p / 0.0120510724 - 1.0).abs() < 1e-6);
    }

    #[test]
    fn van_der_pol_torus_curve_ends_at_the_shooting_resonance() {
        // ẍ − 0.2(1 − x²)ẋ + x = F cos ω_f t from its Neimark–Sacker point at
        // F = 0.2: by shooting (tests/ns_curve.rs) the NS point at F = 0.3 is
        // at ω_f = 0.8980504973 and the 1:1 end at F = 0.1924005859.
        let family = |f: f64| {
            Ok(ivt_hb::GeneralProblem::new(
                1,
                vec![1.0],
                vec![-0.2],
                vec![1.0],
                |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = 0.2 * x[0] * x[0] * v[0],
                move |t: f64, out: &mut [f64]| out[0] = f * t.cos(),
            ))
        };
        let req = FoldCurveRequest {
            kind: BifurcationKind::NeimarkSacker,
            start: FoldStart::Search { from: 0.5, to: 1.6 },
            p_start: 0.2,
            p_from: 0.0,
            p_to: 0.3,
            at: vec![0.3],
            steps: Steps {
                ds: Some(0.01),
                ds_max: Some(0.02),
                max_points: Some(400),
                ds_min: None,
            },
        };
        let c = fold_curve(family, &HbOptions::new(9, 32), &req).unwrap();
        assert_eq!(c.kind, BifurcationKind::NeimarkSacker);
        assert!((c.start_omega - 0.94525643).abs() < 1e-8);
        assert_eq!(c.termination, Termination::LeftInterval);
        assert_eq!(c.at.len(), 1);
        assert!((c.at[0].omega - 0.8980504973).abs() < 1e-7);
        assert!(c.points.iter().all(|p| p.angle.is_some_and(|a| a > 0.0)));
        let [r] = c.special.as_slice() else {
            panic!("{:?}", c.special)
        };
        assert_eq!(r.kind, SpecialKind::Resonance1To1);
        assert!((r.point.p - 0.1924005859).abs() < 1e-7);
    }

    #[test]
    fn a_branch_point_curve_is_an_input_error() {
        let family = |f: f64| Ok(Duffing::new(0.02, 1.0, 1.0, f));
        let req = FoldCurveRequest {
            kind: BifurcationKind::BranchPoint,
            ..FoldCurveRequest::default()
        };
        let e = fold_curve(family, &HbOptions::new(10, 32), &req).unwrap_err();
        assert!(e.to_string().contains("branch points"), "{e}");
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
