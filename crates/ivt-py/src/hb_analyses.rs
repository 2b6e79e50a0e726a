//! `ivt.hb.all_solutions` and `ivt.hb.damped_modes` (issue 27): every periodic
//! solution at one frequency by deflated Newton ([`ivt_hb::all_solutions`]),
//! and damped nonlinear modes by the extended periodic motion concept
//! ([`ivt_hb::damped_modes`]), on a user system; `ivt.hb.continue_bifurcation`,
//! the fold curve of a model family in two parameters ([`ivt_hb::fold_curve`]).
//! The limit cycle from a state is `limit_cycle(..., x0=)`
//! (`ivt_hb::jobs::limit_cycle`).

use ivt_hb::{
    AllSolutions, BackboneOptions, BroydenStats, ContinuationOptions, Corrector, DampedModes,
    HbSolution, SearchOptions,
};
use numpy::IntoPyArray;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::args::count;
use crate::hb_bifurcation::PyFamily;
use crate::hb_shared::{finite, run_user, user_system_fn, UserArgs};
use ivt_hb::jobs::{pairs, stability_steps};

/// One orbit of [`AllSolutions`] as `{"coeffs", "amplitude", "multipliers",
/// "stable", "stability"}` (amplitude: max |x| of DOF 0).
fn solutions_list<'py>(py: Python<'py>, all: &AllSolutions) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for s in &all.solutions {
        let d = PyDict::new(py);
        d.set_item("coeffs", s.solution.coeffs.clone().into_pyarray(py))?;
        d.set_item("amplitude", s.solution.amplitude(0))?;
        d.set_item("multipliers", pairs(&s.multipliers))?;
        d.set_item("stable", s.kind == ivt_hb::StabilityKind::Stable)?;
        d.set_item("stability", s.kind.name())?;
        list.append(d)?;
    }
    Ok(list)
}

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
/// "max_amplitude", "newton_steps", "exhausted"} ("exhausted": every start's
/// last run found nothing new within the bounds). g, f, jac as in `solve`.
fn _all_solutions<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    omega: f64;
    max_amplitude: f64 = 10.0,
    #[pyo3(from_py_with = crate::args::int64)] amplitudes: i64 = 6,
    #[pyo3(from_py_with = crate::args::int64)] newton_steps: i64 = 60,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let search = SearchOptions {
        max_amplitude: finite("max_amplitude", max_amplitude)?,
        amplitudes: count("amplitudes", amplitudes)?,
        max_iter: count("newton_steps", newton_steps)?,
        stability_steps: stability_steps(opts.harmonics),
        ..SearchOptions::default()
    };
    let omega = finite("omega", omega)?;
    let all = run_user(py, &problem, |p| ivt_hb::all_solutions(p, &opts, omega, &search))?;
    let report = PyDict::new(py);
    report.set_item("starts", all.report.starts)?;
    report.set_item("runs", all.report.runs)?;
    report.set_item("max_amplitude", all.report.max_amplitude)?;
    report.set_item("newton_steps", all.report.max_iter)?;
    report.set_item("exhausted", all.report.exhausted)?;
    // `ivt.hb.all_solutions` makes this an `AllSolutions` (a list with a
    // `search` attribute).
    let out = PyDict::new(py);
    out.set_item("solutions", solutions_list(py, &all)?)?;
    out.set_item("search", report)?;
    Ok(out)
}
}

/// The damped modes as `{"points": [{"amplitude", "omega", "damping_ratio",
/// "coeffs"}...], "linear_omega", "linear_mode", "termination"}`.
fn damped_dict<'py>(py: Python<'py>, dm: &DampedModes) -> PyResult<Bound<'py, PyDict>> {
    let points = PyList::empty(py);
    for p in &dm.points {
        let e = PyDict::new(py);
        e.set_item("amplitude", p.amplitude)?;
        e.set_item("omega", p.omega)?;
        e.set_item("damping_ratio", p.damping_ratio)?;
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
/// Returns {"points": [{"amplitude", "omega", "damping_ratio", "coeffs"}...],
/// "linear_omega", "linear_mode", "termination"}.
fn damped_modes<'py>(py, user, jac;
    amplitude_from: f64,
    amplitude_to: f64;
    #[pyo3(from_py_with = crate::args::int64)] mode: i64 = 0,
    #[pyo3(from_py_with = crate::args::int64)] dof: i64 = 0,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(None, 1, tol)?;
    let bopts = BackboneOptions {
        dof: count("dof", dof)?,
        amplitude_from: finite("amplitude_from", amplitude_from)?,
        amplitude_to: finite("amplitude_to", amplitude_to)?,
        corrector: Corrector::Newton,
        ..BackboneOptions::default()
    };
    let mode = count("mode", mode)?;
    let dm = run_user(py, &problem, |p| ivt_hb::damped_modes(p, &opts, mode, &bopts))?;
    damped_dict(py, &dm)
}
}

/// A fold of the curve as `{"omega", "p", "amplitude" (max |x| of DOF 0),
/// "coeffs"}`.
fn fold_point_dict<'py>(
    py: Python<'py>,
    fp: &ivt_hb::FoldPoint,
    harmonics: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let orbit = HbSolution {
        coeffs: fp.coeffs.clone(),
        omega_f: fp.omega,
        harmonics,
        subharmonic: 1,
        stats: BroydenStats::default(),
    };
    let d = PyDict::new(py);
    d.set_item("omega", fp.omega)?;
    d.set_item("p", fp.p)?;
    d.set_item("amplitude", orbit.amplitude(0))?;
    d.set_item("coeffs", orbit.coeffs.into_pyarray(py))?;
    Ok(d)
}

/// Two-parameter continuation of a fold of the frequency response of
/// `family(p)` → (m, c, k, g, f) in (omega, p) (ivt_hb::fold_curve: the
/// extended system R = 0, Φ_q v = 0, |v| = 1 followed in p, first towards
/// `p_from`, until p leaves [p_from, p_to]). `start` is a fold of
/// `frc(..., events=True)["bifurcations"]` (or `frc(...)["folds"]`) computed
/// at p = `p_start`, with the same `n` and `samples`. Cusps (where two folds
/// merge and the jump disappears) are located as turning points of the curve
/// in p; the fold at each p of `at` is solved exactly (each crossing).
/// Only folds this round (period-doubling and Neimark–Sacker curves are not
/// built). An exception in `family` is re-raised; one in the `g` or `f` it
/// returns for p ≠ p_start makes that point fail (the curve stops there).
/// Returns {"kind": "fold", "points": [{"omega", "p", "amplitude",
/// "coeffs"}...], "at": [...], "special": [{"kind": "cusp", "omega", "p",
/// "amplitude", "coeffs"}...], "termination"}.
#[pyfunction]
#[pyo3(signature = (
    family, start, p_from, p_to, at = Vec::new(), p_start = None, n = 20, samples = 64,
    velocity_dependent = true, vectorized = false, rtol = 1e-9, max_iter = 100,
    ds = 0.02, ds_max = 0.05, max_points = 2000
))]
#[allow(clippy::too_many_arguments)]
fn continue_bifurcation<'py>(
    py: Python<'py>,
    family: &Bound<'py, PyAny>,
    start: &Bound<'py, PyDict>,
    p_from: f64,
    p_to: f64,
    at: Vec<f64>,
    p_start: Option<f64>,
    #[pyo3(from_py_with = crate::args::int64)] n: i64,
    #[pyo3(from_py_with = crate::args::int64)] samples: i64,
    velocity_dependent: bool,
    vectorized: bool,
    rtol: f64,
    max_iter: usize,
    ds: f64,
    ds_max: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_points: i64,
) -> PyResult<Bound<'py, PyDict>> {
    let p_start = finite(
        "p_start",
        p_start.ok_or_else(|| PyValueError::new_err("argument `p_start` is required"))?,
    )?;
    let kind: Option<String> = start.get_item("kind")?.map(|k| k.extract()).transpose()?;
    if kind.as_deref().is_some_and(|k| k != "fold") {
        return Err(PyValueError::new_err(
            "argument `start` must be a fold: only fold curves are continued this round",
        ));
    }
    let item = |key: &str| {
        start
            .get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("argument `start` needs \"{key}\"")))
    };
    let omega = finite("start[\"omega\"]", item("omega")?.extract()?)?;
    let coeffs: Vec<f64> = item("coeffs")?
        .extract::<numpy::PyArrayLike1<'_, f64, numpy::AllowTypeChange>>()
        .map_err(|_| PyTypeError::new_err("start[\"coeffs\"] must be a 1-D array of floats"))?
        .as_array()
        .to_vec();
    let fam = PyFamily::new(family, velocity_dependent, vectorized);
    let (first, opts) = fam.first(py, p_start, n, samples, rtol, max_iter)?;
    let copts = ContinuationOptions {
        ds: finite("ds", ds)?,
        ds_max: finite("ds_max", ds_max)?,
        max_points: count("max_points", max_points)?,
        ..ContinuationOptions::default()
    };
    let curve = run_user(py, &first, |_| {
        ivt_hb::fold_curve(
            |p| fam.build(p),
            &opts,
            &coeffs,
            omega,
            p_start,
            p_from,
            p_to,
            &at,
            &copts,
        )
    });
    if let Some(e) = fam.take_error() {
        return Err(e);
    }
    let curve = curve?;
    let list = |points: &[ivt_hb::FoldPoint]| -> PyResult<Bound<'py, PyList>> {
        let l = PyList::empty(py);
        for fp in points {
            l.append(fold_point_dict(py, fp, opts.harmonics)?)?;
        }
        Ok(l)
    };
    let special = PyList::empty(py);
    for cusp in &curve.cusps {
        let d = fold_point_dict(py, cusp, opts.harmonics)?;
        d.set_item("kind", "cusp")?;
        special.append(d)?;
    }
    let d = PyDict::new(py);
    d.set_item("kind", "fold")?;
    d.set_item("points", list(&curve.points)?)?;
    d.set_item("at", list(&curve.at)?)?;
    d.set_item("special", special)?;
    d.set_item("termination", curve.termination.as_str())?;
    Ok(d)
}

/// Add `_all_solutions`, `damped_modes` and `continue_bifurcation` to the
/// `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [_all_solutions, damped_modes, continue_bifurcation]);
    Ok(())
}
