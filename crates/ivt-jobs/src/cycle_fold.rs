//! A fold of limit cycles of an autonomous family `family(μ, ν)` followed in
//! ν ([`ivt_hb::branches::codim2::cycle_fold_curve`]), started from the first
//! fold of the cycle branch in μ at ν = `nu_from`
//! ([`ivt_hb::branches::cycle_branch`]): the job behind
//! `ivt.hb.cycle_fold_curve`.

use super::{all_finite, finite_list, path_steps, Steps};
use ivt_hb::branches::codim2::{cycle_fold_curve as follow, CycleFoldCurve};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{BoxedProblem, PeriodicProblem};
use ivt_hb::{cycle_branch, CycleBranchOptions, HbError};
use ivt_path::continuation::ContinuationOptions;

/// The curve's own `(ds, ds_max, max_points)` in (q, ω, μ, ν): Δ from 0.02
/// up to 0.05, 2000 points (those of the cycle branch,
/// [`crate::cycle_branch::CYCLE_BRANCH_STEPS`], which the curve starts from).
pub const CYCLE_FOLD_STEPS: (f64, f64, usize) = crate::cycle_branch::CYCLE_BRANCH_STEPS;

/// A cycle-fold curve to follow.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CycleFoldRequest {
    /// The second parameter ν: the curve starts at `nu_from` and is followed
    /// both ways within [`nu_from`, `nu_to`]'s span.
    pub nu_from: f64,
    /// The other end of ν.
    pub nu_to: f64,
    /// The interval of μ in which the start's cycle branch is searched for
    /// its first fold.
    pub mu_from: f64,
    /// The other end of μ.
    pub mu_to: f64,
    /// ν values at which the folds are solved exactly.
    pub at: Vec<f64>,
    /// Overrides of [`CYCLE_FOLD_STEPS`].
    pub steps: Steps,
}

impl CycleFoldRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for non-finite ends or `at` values, equal
    /// ends, or steps [`Steps::on`] refuses.
    pub fn validate(&self) -> Result<(), HbError> {
        all_finite(&[
            ("nu_from", self.nu_from),
            ("nu_to", self.nu_to),
            ("mu_from", self.mu_from),
            ("mu_to", self.mu_to),
        ])?;
        if self.nu_from == self.nu_to || self.mu_from == self.mu_to {
            return Err(HbError::InvalidInput(
                "`nu_from`, `nu_to` must differ, and `mu_from`, `mu_to`".into(),
            ));
        }
        finite_list("at", &self.at)?;
        self.path().map(|_| ())
    }

    /// [`CYCLE_FOLD_STEPS`] with the request's `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn path(&self) -> Result<ContinuationOptions, HbError> {
        path_steps(&self.steps, CYCLE_FOLD_STEPS)
    }
}

/// The cycle-fold curve of `family(μ, ν)` (module docs).
///
/// # Errors
/// The request's refusals ([`CycleFoldRequest::validate`]);
/// [`HbError::InvalidInput`] when the cycle branch at `nu_from` has no fold
/// in [`mu_from`, `mu_to`]; the failures of the branch and of the curve.
pub fn cycle_fold_curve<'p, P, F>(
    family: F,
    hb: &HbOptions,
    req: &CycleFoldRequest,
) -> Result<CycleFoldCurve, HbError>
where
    P: PeriodicProblem + 'p,
    F: Fn(f64, f64) -> Result<P, HbError>,
{
    cycle_fold_curve_of(
        &move |mu: f64, nu: f64| family(mu, nu).map(|m| Box::new(m) as BoxedProblem<'p>),
        hb,
        req,
    )
}

/// [`cycle_fold_curve`] on the boxed family.
fn cycle_fold_curve_of<'p>(
    family: &dyn Fn(f64, f64) -> Result<BoxedProblem<'p>, HbError>,
    hb: &HbOptions,
    req: &CycleFoldRequest,
) -> Result<CycleFoldCurve, HbError> {
    req.validate()?;
    let branch = cycle_branch(
        &|mu| family(mu, req.nu_from),
        hb,
        req.mu_from,
        req.mu_to,
        &CycleBranchOptions::default(),
    )?;
    let Some((mu, start)) = branch.folds.first() else {
        return Err(HbError::InvalidInput(
            "the cycle branch at nu_from has no fold in [mu_from, mu_to]".into(),
        ));
    };
    // The path goes first towards the first of the pair: nu_to.
    follow(
        family,
        hb,
        start,
        (*mu, req.nu_from),
        (req.nu_to, req.nu_from),
        &req.at,
        &req.path()?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ẍ − (μ + νx² − x⁴)ẋ + x = 0` (ivt-hb's tests/cycle_fold.rs checks
    /// its curve against shooting).
    fn family(mu: f64, nu: f64) -> Result<impl PeriodicProblem, HbError> {
        Ok(ivt_hb::problem::bautin(mu, nu))
    }

    fn request() -> CycleFoldRequest {
        CycleFoldRequest {
            nu_from: 1.0,
            nu_to: 0.6,
            mu_from: -0.2,
            mu_to: 0.1,
            at: vec![0.8],
            steps: Steps::default(),
        }
    }

    #[test]
    fn the_job_starts_at_the_branch_fold_and_solves_the_at_values() {
        let hb = HbOptions::new(15, 64);
        let curve = cycle_fold_curve(family, &hb, &request()).unwrap();
        // Averaging: the fold lies near μ = −ν²/8 (−0.125 at ν = 1, −0.08 at 0.8).
        let [at] = curve.at.as_slice() else {
            panic!("{:?}", curve.at.len())
        };
        assert!((at.fold.p - 0.8).abs() < 1e-12, "{}", at.fold.p);
        assert!((at.mu + 0.08).abs() < 0.01, "{}", at.mu);
        assert!(curve.points.len() > 3);
        let max_points = Steps {
            max_points: Some(2),
            ..Steps::default()
        };
        let short = CycleFoldRequest {
            steps: max_points,
            ..request()
        };
        let cut = cycle_fold_curve(family, &hb, &short).unwrap();
        assert!(cut.points.len() < curve.points.len());
    }

    #[test]
    fn refusals_name_the_input() {
        let hb = HbOptions::new(15, 64);
        let refused =
            |req: CycleFoldRequest| cycle_fold_curve(family, &hb, &req).unwrap_err().to_string();
        let same = refused(CycleFoldRequest {
            nu_to: 1.0,
            ..request()
        });
        assert!(same.contains("must differ"), "{same}");
        let nan = refused(CycleFoldRequest {
            mu_to: f64::NAN,
            ..request()
        });
        assert!(nan.contains("mu_to"), "{nan}");
        let bad_at = refused(CycleFoldRequest {
            at: vec![f64::INFINITY],
            ..request()
        });
        assert!(bad_at.contains("at"), "{bad_at}");
        let ds = refused(CycleFoldRequest {
            steps: Steps {
                ds: Some(-1.0),
                ..Steps::default()
            },
            ..request()
        });
        assert!(ds.contains("`ds`"), "{ds}");
        // No fold of cycles for μ in [0.2, 0.5] at ν = 1 (the fold is at −0.125).
        let none = refused(CycleFoldRequest {
            mu_from: 0.2,
            mu_to: 0.5,
            ..request()
        });
        assert!(none.contains("no fold"), "{none}");
    }
}
