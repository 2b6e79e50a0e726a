//! `ivt.hb.torus_branch` and `ivt.hb.diagram` (issue 45 items 1 and 2): the
//! quasi-periodic response born at a Neimark–Sacker point of
//! `frc(..., events=True)` (the job [`ivt_jobs::torus()`], the CLI's
//! `ivt hb torus`) and the automatic bifurcation diagram (the job
//! [`ivt_jobs::diagram()`], the CLI's `ivt hb diagram`), on a user
//! system.

use ivt_hb::branches::torus::{TorusOptions, Truncation};
use ivt_hb::c64;
use ivt_jobs::{self as jobs, DiagramRequest, TorusRequest};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::count;
use crate::hb_shared::{dict_item, given_point, run_user, user_system_fn, UserArgs};
use crate::to_python::to_dict;

/// The truncation argument `name`: an int `h` (the diamond |k₁| + |k₂| ≤ h)
/// or a pair `(h1, h2)` (the box |k₁| ≤ h1, |k₂| ≤ h2).
fn truncation(name: &str, value: &Bound<'_, PyAny>) -> PyResult<Truncation> {
    if let Ok(h) = value.extract::<i64>() {
        return Ok(Truncation::Diamond { h: count(name, h)? });
    }
    let (h1, h2): (i64, i64) = value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "argument `{name}` must be an int h (|k1| + |k2| <= h) or a pair (h1, h2) (|k1| <= h1, |k2| <= h2)"
        ))
    })?;
    Ok(Truncation::Box {
        h1: count(name, h1)?,
        h2: count(name, h2)?,
    })
}

/// The Neimark–Sacker point `start` (an entry of
/// `frc(..., events=True)["bifurcations"]`): ω_f, coefficients, multipliers.
fn neimark_sacker(start: &Bound<'_, PyDict>) -> PyResult<(f64, Vec<f64>, Vec<c64>)> {
    let kind: String = dict_item(start, "start", "kind")?.extract()?;
    if kind != "neimark_sacker" {
        return Err(PyValueError::new_err(format!(
            "argument `start` must be a neimark_sacker event of frc(..., events=True), not {kind:?}"
        )));
    }
    let located: Option<bool> = start
        .get_item("located")?
        .map(|v| v.extract())
        .transpose()?;
    if located == Some(false) {
        return Err(PyValueError::new_err(
            "argument `start` (neimark_sacker) was not located",
        ));
    }
    let (omega, coeffs) = given_point(start, "start")?;
    let pairs: Vec<[f64; 2]> = dict_item(start, "start", "multipliers")?
        .extract()
        .map_err(|_| {
            PyTypeError::new_err("argument `start[\"multipliers\"]` must be [[re, im], ...]")
        })?;
    Ok((
        omega,
        coeffs,
        pairs.iter().map(|p| c64::new(p[0], p[1])).collect(),
    ))
}

user_system_fn! {
/// The quasi-periodic response born at a Neimark–Sacker point: the torus
/// branch x(t) = X(θ₁, θ₂), θ₁ = ω_f t, θ₂ = Ω t (two-frequency harmonic
/// balance, Ω unknown with a phase condition, the harmonics k = (k₁, k₂) of
/// `truncation`: a pair (h1, h2) keeps |k₁| ≤ h1, |k₂| ≤ h2, an int h keeps
/// |k₁| + |k₂| ≤ h), started from `start` (a "neimark_sacker" entry of
/// `frc(..., events=True)["bifurcations"]` with the same n, samples) and
/// continued in ω_f to `omega_to` (on the side where the torus leaves the
/// point, else a ValueError). Each point: "omega", "rotation_number"
/// (Ω/ω_f reduced to [0, 1/2]: the turn of the stroboscopic map per forcing
/// period), "second_frequency" (Ω), "amplitude_mean" and "amplitude_max"
/// (mean and max of |x_d| over the torus, d = `amplitude_dof`),
/// "error_estimate" (the largest of "errors": twice each quantity's change
/// to a truncation 4 orders wider; path points only with
/// `estimate_points=True`), "normal_exponent" and "stable" (one DOF: the
/// normal Lyapunov exponent; None otherwise), "coeffs", "truncation". Each ω_f
/// of `at` crossed by the branch is solved there and refined in wider
/// truncations until its estimate is ≤ `estimate_tol` (or its estimate's truncation
/// would exceed `max_unknowns`), with its Poincaré section θ₁ = 0
/// ("section": {"x", "v"}) and its "harmonics" [[k₁, k₂], ...]. Returns
/// {"start_omega", "angle", "start_second_frequency", "truncation",
/// "harmonics", "samples", "points", "at", "termination", "time_s"}.
/// `ds`, `ds_min`, `ds_max`, `max_points`: the path's steps (None: Δη from
/// 0.01 up to 0.05, 400 points). A
/// hysteretic element (Jenkins) is a ValueError. GIL released between
/// callbacks.
fn torus_branch<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    start: &Bound<'py, PyDict>,
    omega_to: f64,
    at: Vec<f64> = (Vec::new());
    truncation: Option<&Bound<'py, PyAny>> = None,
    step: f64 = 0.02,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
    estimate_tol: f64 = 1e-7,
    #[pyo3(from_py_with = crate::args::int64)] max_unknowns: i64 = 3000,
    #[pyo3(from_py_with = crate::args::int64)] amplitude_dof: i64 = 0,
    estimate_points: bool = false,
    #[pyo3(from_py_with = crate::args::int64)] section_points: i64 = 200,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let (omega, coeffs, multipliers) = neimark_sacker(start)?;
    let torus = TorusOptions {
        truncation: match truncation {
            Some(t) => self::truncation("truncation", t)?,
            None => TorusOptions::default().truncation,
        },
        ..TorusOptions::default()
    };
    let req = TorusRequest {
        omega,
        coeffs,
        multipliers,
        omega_to,
        at,
        torus,
        step,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
        amplitude_dof: count("amplitude_dof", amplitude_dof)?,
        estimate_points,
        tol: estimate_tol,
        max_unknowns: count("max_unknowns", max_unknowns)?,
        section_points: count("section_points", section_points)?,
    };
    let curve = run_user(py, &problem, |p| jobs::torus(p, &opts, &req))?;
    to_dict(py, &curve)
}
}

user_system_fn! {
/// The automatic bifurcation diagram of `M x'' + C x' + K x + g(x, v, θ) =
/// f(θ)` over ω_f from `omega_from` to `omega_to`: the primary response
/// curve with its events, then to `depth` levels both halves of the branch
/// through each branch point, the period-2 branch at each period doubling
/// and (`tori`) the torus branch at each Neimark–Sacker point (`torus`: the
/// truncation as in `torus_branch`, `torus_points` points); and branches no
/// event leads to (isolas): every fold followed in the forcing scale
/// f → s f over `fold_scale` (None: not), and every orbit deflated Newton
/// finds at `deflation_omegas` frequencies spread over the interval (box
/// `max_amplitude`, `amplitudes` start amplitudes). A start on a known branch
/// is not traced again; a branch stops where it closes on its start
/// ("termination" "stopped"). Every branch is solved exactly at each ω_f of
/// `at` (points with "at": True). Returns {"branches": [{"kind" ("primary",
/// "branch_point", "period_doubling", "torus", "fold_curve", "deflation"),
/// "parent", "origin" {"kind", "omega", "event"}, "level", "harmonics",
/// "subharmonic", "torus_harmonics", "points": [{"omega", "amplitude",
/// "coeffs", "stable", "stability", "multipliers", "rotation_number",
/// "at"}...], "events", "termination"}...], "search": {"interval", "depth",
/// "deepest", "events_beyond_depth", "max_branches", "branch_limit_reached",
/// "duplicates", "failures", "fold_curves", "fold_scale",
/// "deflation_omegas", "deflation_solutions", "deflation_exhausted",
/// "truncated_branches"}, "time_s"}. `ds`, `ds_min`, `ds_max`, `max_points`:
/// every branch's steps (None: Δη from 0.02 up to 0.05, 2000 points).
/// GIL released between callbacks.
fn diagram<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    omega_from: f64,
    omega_to: f64,
    at: Vec<f64> = (Vec::new());
    #[pyo3(from_py_with = crate::args::int64)] depth: i64 = 2,
    #[pyo3(from_py_with = crate::args::int64)] max_branches: i64 = 24,
    tori: bool = true,
    torus: Option<&Bound<'py, PyAny>> = None,
    #[pyo3(from_py_with = crate::args::int64)] torus_points: i64 = 60,
    fold_scale: Option<(f64, f64)> = (Some((0.25, 4.0))),
    #[pyo3(from_py_with = crate::args::int64)] deflation_omegas: i64 = 6,
    max_amplitude: f64 = 10.0,
    #[pyo3(from_py_with = crate::args::int64)] amplitudes: i64 = 6,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
    step: f64 = 0.05,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let defaults = DiagramRequest::default();
    let req = DiagramRequest {
        from: omega_from,
        to: omega_to,
        depth: count("depth", depth)?,
        max_branches: count("max_branches", max_branches)?,
        tori,
        torus: TorusOptions {
            truncation: match torus {
                Some(t) => truncation("torus", t)?,
                None => defaults.torus.truncation,
            },
            ..defaults.torus
        },
        torus_points: count("torus_points", torus_points)?,
        fold_scale,
        samples: count("deflation_omegas", deflation_omegas)?,
        max_amplitude,
        amplitudes: count("amplitudes", amplitudes)?,
        at,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
        step,
    };
    let d = run_user(py, &problem, |p| jobs::diagram(p, &opts, &req))?;
    to_dict(py, &d)
}
}

/// Add `torus_branch` and `diagram` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [torus_branch, diagram]);
    Ok(())
}
