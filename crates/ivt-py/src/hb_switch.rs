//! `ivt.hb.switch_branch` (issue 27 item 2): from a period doubling or a
//! branch point of `frc(..., events=True)` onto the new branch, continued in
//! ω_f — the job [`ivt_jobs::switch()`] (the CLI's `ivt hb switch`).

use ivt_hb::{BifurcationKind, Corrector};
use ivt_jobs::{self as jobs, SwitchRequest, SwitchStart};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::hb_shared::{dict_item, given_point, run_user, user_system_fn, UserArgs};
use crate::to_python::to_dict;

/// The event `at` (an entry of `frc(..., events=True)["bifurcations"]`) as
/// the job's start: its kind, ω_f and coefficients; an event whose location
/// failed is refused with its reason.
fn given_event(at: &Bound<'_, PyDict>) -> PyResult<SwitchStart> {
    let name: String = dict_item(at, "at", "kind")?.extract()?;
    let kind = match name.as_str() {
        "period_doubling" => BifurcationKind::PeriodDoubling,
        "branch_point" => BifurcationKind::BranchPoint,
        "fold" => BifurcationKind::Fold,
        "neimark_sacker" => BifurcationKind::NeimarkSacker,
        other => {
            return Err(PyValueError::new_err(format!(
                "argument `at` has kind {other:?}: not an event of `frc`"
            )))
        }
    };
    let located: Option<bool> = at.get_item("located")?.map(|v| v.extract()).transpose()?;
    if located == Some(false) {
        let why: Option<String> = at.get_item("error")?.and_then(|v| v.extract().ok());
        return Err(PyValueError::new_err(format!(
            "argument `at` ({name}) was not located: {}",
            why.unwrap_or_default()
        )));
    }
    let (omega, coeffs) = given_point(at, "at")?;
    Ok(SwitchStart::Given {
        kind,
        omega,
        coeffs,
    })
}

user_system_fn! {
/// Branch switching on the frequency response of a user system `M x'' + C x'
/// + K x + g(x, v, θ) = f(θ)`: `at` is a period doubling or a branch point of
/// `frc(m, c, k, g, f, ..., events=True)["bifurcations"]` (same n, samples,
/// tol; a fold or a Neimark–Sacker point is a ValueError naming it). At a
/// period doubling the period-2 branch starts from the odd-harmonic null
/// vector of the period-2 Galerkin Jacobian (its coeffs then have 2n
/// harmonics of ω_f/2); at a branch point the branch nearer ω_f = const of
/// the two through it (the symmetry-breaking branch of a pitchfork). Its
/// first point is `step`·‖coeffs‖ away; it is then continued to `to` (on the
/// side where it leaves, else a ValueError) with its own events, as `frc`.
/// Returns the job's [`ivt_jobs::SwitchedBranch`]: the keys of `frc`
/// ("points", "folds", "bifurcations", "termination", "omega", "amplitude",
/// "stable", "time_s") and "kind" (of `at`), "start_omega", "harmonics",
/// "subharmonic" (2 after a period doubling). `ds`, `ds_min`, `ds_max`,
/// `max_points`: the new branch's steps (None: those of `frc`, Δη from 0.05
/// up to 0.08, 5000 points). GIL released between callbacks.
fn switch_branch<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    at: &Bound<'py, PyDict>,
    to: f64;
    step: f64 = 0.05,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let req = SwitchRequest {
        start: given_event(at)?,
        to,
        step,
        corrector: Corrector::Newton,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
    };
    let branch = run_user(py, &problem, |p| jobs::switch(p, &opts, &req))?;
    to_dict(py, &branch)
}
}

/// Add `switch_branch` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [switch_branch]);
    Ok(())
}
