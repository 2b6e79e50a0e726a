//! `ivt.hb.all_solutions` and `ivt.hb.damped_modes` (issue 27): every periodic
//! solution at one frequency by deflated Newton (the job
//! [`ivt_jobs::all_solutions()`] of `ivt hb all-solutions`),
//! and damped nonlinear modes by the extended periodic motion concept
//! ([`ivt_hb::damped_modes`]), on a user system. Fold curves are in
//! `hb_folds.rs`. The limit cycle from a state is `limit_cycle(..., x0=)`
//! (`ivt_jobs::limit_cycle`).

use ivt_hb::{BackboneOptions, ContinuationOptions, Corrector, DampedModes};
use ivt_jobs::{self as jobs, AllSolutionsRequest};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::args::count;
use crate::hb_shared::{finite, run_user, user_system_fn, UserArgs};
use crate::to_python::to_dict;

user_system_fn! {
/// Every period-one solution of `M x'' + C x' + K x + g(x, v, θ) = f(θ)` at
/// the excitation frequency `omega` that deflated Newton finds (Farrell et
/// al. 2015, as BifurcationKit): after each root the residual is deflated by
/// it, and Newton on the Galerkin Jacobian is restarted. The search is
/// bounded: starts are the linear solution and its shape scaled to
/// `amplitudes` amplitudes from max_amplitude/100 to max_amplitude/2 at four
/// phases; `newton_steps` steps per run; iterates leaving the box
/// max|coefficient| ≤ `max_amplitude` are abandoned.
/// Returns {"solutions", "search"}; `ivt.hb.all_solutions` returns
/// `ivt.hb.AllSolutions`: a list of {"coeffs", "amplitude" (max |x|
/// of DOF 0), "multipliers" ([[re, im], ...], Hsu), "stable", "stability"}
/// by increasing size, whose `search` attribute is {"starts", "runs",
/// "max_amplitude", "newton_steps", "exhausted", "failures_per_start",
/// "copies_merged", "bound"} ("exhausted": every start's last run found
/// nothing new within the bounds, stated in "bound"). Time-shifted copies of
/// an autonomous problem's orbits are merged; an undamped linear resonance
/// where nothing is found raises ValueError naming the harmonic. g, f, jac
/// as in `solve`.
fn _all_solutions<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    omega: f64;
    max_amplitude: f64 = 10.0,
    #[pyo3(from_py_with = crate::args::int64)] amplitudes: i64 = 6,
    #[pyo3(from_py_with = crate::args::int64)] newton_steps: i64 = 60,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let req = AllSolutionsRequest {
        omega,
        max_amplitude,
        amplitudes: count("amplitudes", amplitudes)?,
        newton_steps: count("newton_steps", newton_steps)?,
    };
    // `ivt.hb.all_solutions` makes this an `AllSolutions` (a list with a
    // `search` attribute).
    let all = run_user(py, &problem, |p| jobs::all_solutions(p, &opts, &req))?;
    to_dict(py, &all)
}
}

/// The damped modes as `{"points": [{"amplitude", "omega", "damping_ratio",
/// "peak", "coeffs"}...], "linear_omega", "linear_mode", "termination"}`.
fn damped_dict<'py>(py: Python<'py>, dm: &DampedModes) -> PyResult<Bound<'py, PyDict>> {
    let points = PyList::empty(py);
    for p in &dm.points {
        let e = PyDict::new(py);
        e.set_item("amplitude", p.amplitude)?;
        e.set_item("omega", p.omega)?;
        e.set_item("damping_ratio", p.damping_ratio)?;
        e.set_item("peak", p.peak)?;
        e.set_item("coeffs", p.coeffs.clone().into_pyarray(py))?;
        points.append(e)?;
    }
    let d = PyDict::new(py);
    d.set_item("points", points)?;
    d.set_item("linear_omega", dm.linear_omega)?;
    d.set_item("linear_mode", PyTuple::new(py, &dm.linear_mode)?)?;
    d.set_item("termination", dm.termination.as_str())?;
    Ok(d)
}

user_system_fn! {
/// Damped nonlinear mode `mode` (0: lowest linear frequency) of the free
/// system `M x'' + C x' + K x + g(x, v) = 0` by the extended periodic motion
/// concept (Krack 2015, NLvib's EPMC): a negative mass-proportional damping
/// κ M x' makes the orbit periodic; the modal damping ratio is
/// ζ = −κ/(2ω). `amplitude` is a1 (first cosine coefficient) of DOF `dof`,
/// whose b1 is held at 0, traced from `amplitude_from` to `amplitude_to`
/// (Newton–chord on the exact Jacobian). At vanishing amplitude the point is
/// the linear mode (ω₀ and, for proportional damping, its ζ); for C = 0 the
/// curve is `backbone`'s.
/// Returns {"points": [{"amplitude", "omega", "damping_ratio", "peak" (max |x|
/// of DOF `dof`), "coeffs"}...],
/// "linear_omega", "linear_mode", "termination"}. `ds`, `ds_min`, `ds_max`,
/// `max_points`: the path's steps (None: Δη from 0.02 up to 0.2, 5000
/// points).
fn damped_modes<'py>(py, user, jac;
    amplitude_from: f64,
    amplitude_to: f64;
    #[pyo3(from_py_with = crate::args::int64)] mode: i64 = 0,
    #[pyo3(from_py_with = crate::args::int64)] dof: i64 = 0,
    tol: f64 = 0.0,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
) {
    let (problem, opts) = user.setup(None, 1, tol)?;
    crate::hb_shared::without_omega(&problem, "damped_modes")?;
    let steps = crate::steps::steps(ds, ds_min, ds_max, max_points)?;
    let bopts = BackboneOptions {
        dof: count("dof", dof)?,
        amplitude_from: finite("amplitude_from", amplitude_from)?,
        amplitude_to: finite("amplitude_to", amplitude_to)?,
        continuation: crate::steps::on(
            &steps,
            ContinuationOptions {
                corrector: Corrector::Newton,
                ..ContinuationOptions::default()
            },
        )?,
    };
    let mode = count("mode", mode)?;
    let dm = run_user(py, &problem, |p| ivt_hb::damped_modes(p, &opts, mode, &bopts))?;
    damped_dict(py, &dm)
}
}

/// Add `_all_solutions` and `damped_modes` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [_all_solutions, damped_modes]);
    Ok(())
}
