#![doc = include_str!("../README.md")]
//! The harmonic-balance jobs run by the command line (`ivt hb ...`) and by
//! Python (`ivt.hb.*`): each takes a typed request (with `Default` and
//! `validate`) and returns a [`serde::Serialize`] result whose field names
//! are the JSON keys of SPEC §6 and the keys of the Python dicts. Neither
//! front end assembles a job or classifies its errors
//! ([`ivt_hb::HbError::kind`]); they parse arguments and serialize results.
//!
//! | job | request | result | CLI | Python |
//! |---|---|---|---|---|
//! | orbit + stability (Eq. 56–67, 78) | [`OrbitRequest`] | [`Orbit`] | `hb duffing` | `duffing`, `mathieu_duffing`, `solve` |
//! | FRC, with or without events (Eq. 68–77) | [`FrcRequest`] | [`FrcCurve`] | `hb duffing-frc [--events]` | `duffing_frc`, `frc` |
//! | fold, period-doubling and Neimark–Sacker curves in (ω, p) (Eq. 56, 61, 68–80) | [`FoldCurveRequest`] | [`FoldCurveResult`] | `hb duffing-folds`, `hb vdp-torus` | `duffing_folds`, `continue_bifurcation` |
//! | limit cycle (ω unknown) | [`LimitCycleRequest`] | [`Cycle`] | `hb limit-cycle` | `limit_cycle` |
//! | backbone | [`BackboneRequest`] | [`BackboneCurve`] | `hb duffing-backbone` | `backbone` |
//! | Mathieu–Duffing cascade (Eq. 81–85) | [`CascadeRequest`] | [`Cascade`] | `hb mathieu-duffing` | `mathieu_cascade` |
//! | STHB string curve (Eq. 103–136) | [`StringRequest`] | [`StringCurve`] | `hb string` | `string` |
//! | Hopf points and the cycle branch (issue 27) | [`CycleBranchRequest`] | [`CycleBranchResult`] | `hb cycle-branch` | `cycle_branch` |
//! | every solution at one ω_f by deflation (issue 27) | [`AllSolutionsRequest`] | [`AllSolutionsResult`] | `hb all-solutions` | `all_solutions` |
//! | branch switching at a period doubling or branch point (Eq. 56, 61, 68–77) | [`SwitchRequest`] | [`SwitchedBranch`] | `hb switch` | `switch_branch` |
//! | the torus branch from a Neimark–Sacker point (issue 45) | [`TorusRequest`] | [`TorusCurve`] | `hb torus` | `torus_branch` |
//! | `dω/dp`, `dA/dp` of a located feature by its adjoint (issue 45) | [`SensitivityRequest`] | [`SensitivityResult`] | — | `event_sensitivity` |
//! | the automatic bifurcation diagram (issue 45) | [`DiagramRequest`] | [`Diagram`] | `hb diagram` | `diagram` |
//!

pub mod all_solutions;
mod array;
pub mod backbone;
pub mod cascade;
pub mod cycle_branch;
pub mod cycle_fold;
pub mod diagram;
pub mod fold_curve;
pub mod frc;
pub mod limit_cycle;
pub mod ns_points;
pub mod orbit;
pub mod sensitivity;
pub mod string;
pub mod switch;
pub mod torus;

pub use all_solutions::{
    all_solutions, AllSolutionsRequest, AllSolutionsResult, FoundOrbit, SearchBounds,
};
pub use array::{check_finite, finite_pairs, pairs, Array, ARRAY_NAME};
pub use backbone::{backbone, free_duffing, BackboneCurve, BackboneRequest, BackboneSample};
pub use cascade::{cascade, Cascade, CascadeRequest, THESIS_BETAS};
pub use cycle_branch::{
    cycle_branch, CycleBranchRequest, CycleBranchResult, CycleFold, CycleRecord, HopfRecord,
};
pub use cycle_fold::{cycle_fold_curve, CycleFoldRequest, CYCLE_FOLD_STEPS};
pub use diagram::{
    diagram, BranchKind, Diagram, DiagramBranch, DiagramPoint, DiagramRequest, DiagramSearch,
    Origin,
};
pub use fold_curve::{
    fold_curve, CurveFoldPoint, FoldCurveRequest, FoldCurveResult, FoldStart, SpecialKind,
    SpecialPoint, UnlocatedPoint,
};
pub use frc::{frc, CurvePoint, EventRecord, FoldPoint, FrcCurve, FrcRequest};
pub use limit_cycle::{limit_cycle, Cycle, LimitCycleRequest, DEFAULT_TOL, MAX_HARMONICS};
pub use ns_points::{neimark_sacker_points, NeimarkSackerPoint};
pub use orbit::{orbit, Method, Orbit, OrbitRequest};
pub use sensitivity::{event_sensitivity, SensitivityRequest, SensitivityResult};
pub use string::{string, StringCurve, StringFold, StringPoint, StringRequest};
pub use switch::{switch, SwitchRequest, SwitchStart, SwitchedBranch};
pub use torus::{torus, Section, TorusCurve, TorusPoint, TorusRequest};

use ivt_hb::HbError;
use ivt_path::continuation::ContinuationOptions;
pub use ivt_path::continuation::Steps;

/// Hsu sub-intervals per period for `harmonics` harmonics: max(8n, 256)
/// (Eq. 78; 256 resolve the stability flags of the thesis's examples, 8n
/// the fastest harmonic's period with 8 Magnus-4 steps).
pub fn stability_steps(harmonics: usize) -> usize {
    harmonics.saturating_mul(8).max(256)
}

/// The value of the two `choices` whose name is `value` (the `FromStr` of
/// the jobs' enums); otherwise `Err(InvalidInput)` naming the argument
/// `what` and both names.
pub(crate) fn one_of<T: Copy>(
    what: &str,
    value: &str,
    choices: [(&str, T); 2],
) -> Result<T, HbError> {
    let [(a, x), (b, y)] = choices;
    match value {
        v if v == a => Ok(x),
        v if v == b => Ok(y),
        other => Err(HbError::InvalidInput(format!(
            "`{what}` = {other:?} must be '{a}' or '{b}'"
        ))),
    }
}

/// `Err(InvalidInput)` unless `v` is finite, naming the argument.
pub(crate) fn finite(name: &str, v: f64) -> Result<f64, HbError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(HbError::InvalidInput(format!(
            "`{name}` = {v:?} must be finite"
        )))
    }
}

/// `v` if it is finite and positive; otherwise `Err(InvalidInput)` naming
/// `name`.
pub(crate) fn positive(name: &str, v: f64) -> Result<f64, HbError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(HbError::InvalidInput(format!(
            "`{name}` = {v:?} must be finite and > 0"
        )))
    }
}

/// [`finite`] of each named value, the first failure returned.
pub(crate) fn all_finite(values: &[(&str, f64)]) -> Result<(), HbError> {
    values
        .iter()
        .try_for_each(|&(name, v)| finite(name, v).map(|_| ()))
}

/// [`finite`] of each entry of the list `name`, the first failure returned.
pub(crate) fn finite_list(name: &str, values: &[f64]) -> Result<(), HbError> {
    values.iter().try_for_each(|&v| finite(name, v).map(|_| ()))
}

/// The default path with a job's own `(ds, ds_max, max_points)` (its
/// `*_STEPS` constant), overridden by the request's `steps`.
///
/// # Errors
/// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
pub(crate) fn path_steps(
    steps: &Steps,
    (ds, ds_max, max_points): (f64, f64, usize),
) -> Result<ContinuationOptions, HbError> {
    let own = ContinuationOptions {
        ds,
        ds_max,
        max_points,
        ..ContinuationOptions::default()
    };
    steps.on(own).map_err(HbError::InvalidInput)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hsu_steps_are_eight_per_harmonic_and_at_least_256() {
        assert_eq!(stability_steps(20), 256);
        assert_eq!(stability_steps(32), 256);
        assert_eq!(stability_steps(40), 320);
        assert_eq!(stability_steps(usize::MAX), usize::MAX);
    }
}
