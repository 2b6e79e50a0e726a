//! `ivt.design`: the controller-design tools of ivt-hb (§4.2–4.3): IHB steady
//! state, open-loop table and refit, delay-loop stability at a point and over a grid.
//! Keys follow `ivt ol solve`, `ivt ol table`, `ivt ol fit`, `ivt stability` and
//! `ivt stability-map` (`--json`).

use crate::args::{check_arg, count, int};
use crate::kin::Plant;
use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
use ivt_design::fit::{LawError, PolyForm};
use ivt_design::gains::grid_stability_map;
use ivt_design::open_loop::fit_law;
use ivt_design::polish::{accurate_r, SolveMethod};
use ivt_design::steady::IhbOptions;
use ivt_design::sweep::{self, Grid};
use ivt_design::{rpm_to_rad_s, IvtError, OperatingPoint, Verdict};
use ivt_kin::plant::{PlantParams, PlantPreset};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::time::Instant;

/// The plant of a `plant=` argument: a preset name (`"printed"`,
/// `"thesis-ch4"`), the path of a plant file (`*.toml` or an `os.PathLike`;
/// [`crate::kin::plant_from_file`]), an `ivt.kin.Plant`, or None (printed),
/// with the name the result echoes (the path for a file, `"custom"` for a
/// Plant matching no preset).
fn plant_of(plant: Option<&Bound<'_, PyAny>>) -> PyResult<(PlantParams, String)> {
    let Some(obj) = plant else {
        return Ok((PlantParams::printed(), PlantPreset::Printed.name().into()));
    };
    if let Ok(name) = obj.extract::<String>() {
        if let Some(preset) = PlantPreset::from_name(&name) {
            return Ok((preset.params(), preset.name().into()));
        }
        if !name.ends_with(".toml") {
            let names: Vec<_> = PlantPreset::ALL.iter().map(|p| p.name()).collect();
            return Err(PyValueError::new_err(format!(
                "argument `plant` = \"{name}\" must be one of {} or a plant file (*.toml)",
                names.join(", ")
            )));
        }
    }
    if let Ok(path) = obj.extract::<std::path::PathBuf>() {
        let params = crate::kin::plant_from_file(&path)?;
        return Ok((params, path.display().to_string()));
    }
    let params = obj.extract::<PyRef<'_, Plant>>()?.params;
    let name = PlantPreset::ALL
        .into_iter()
        .find(|p| p.params() == params)
        .map_or("custom", PlantPreset::name);
    Ok((params, name.into()))
}

/// One operating point, each argument checked through its key.
fn operating_point(v_m: f64, t_u: f64, omega0_rpm: f64) -> PyResult<OperatingPoint> {
    check_arg("v_m", "inputs.v_m[]", v_m)?;
    check_arg("t_u", "inputs.t_u[]", t_u)?;
    check_arg("omega0_rpm", "controller.omega0_rpm", omega0_rpm)?;
    let op = OperatingPoint {
        v_m,
        t_u,
        omega0: rpm_to_rad_s(omega0_rpm),
    };
    op.validate().map_err(design_err)?;
    Ok(op)
}

/// The (V_m, T_U) grid of `(from, step, to)` axes at ω0, validated (the
/// axes' ends and ω0 through their keys, each axis at most
/// `MAX_AXIS_POINTS` values, checked before allocation).
fn grid_of(v_m: (f64, f64, f64), t_u: (f64, f64, f64), omega0_rpm: f64) -> PyResult<Grid> {
    check_arg("omega0_rpm", "controller.omega0_rpm", omega0_rpm)?;
    for v in [v_m.0, v_m.2] {
        check_arg("v_m", "inputs.v_m[]", v)?;
    }
    for v in [t_u.0, t_u.2] {
        check_arg("t_u", "inputs.t_u[]", v)?;
    }
    let grid = Grid {
        v_m: sweep::axis("v_m", v_m.0, v_m.1, v_m.2).map_err(design_err)?,
        t_u: sweep::axis("t_u", t_u.0, t_u.1, t_u.2).map_err(design_err)?,
        omega0: rpm_to_rad_s(omega0_rpm),
    };
    grid.validate().map_err(design_err)?;
    Ok(grid)
}

/// The delay loop of `stability` and `stability_map`: the plant (and the
/// name the result echoes), the feedback gains (thesis mm·rad⁻¹, or SI with
/// `si`; each checked through its key) and the Chebyshev Tau discretization
/// of order `n` (validated; the message names `n` and `chebyshev_order`).
fn delay_loop<'py>(
    plant: Option<&Bound<'py, PyAny>>,
    k: f64,
    k2: f64,
    si: bool,
    n: i128,
) -> PyResult<(PlantParams, String, FeedbackGains, DelayOptions)> {
    let (params, plant_name) = plant_of(plant)?;
    let keys = if si {
        ["controller.k_si", "controller.k2_si"]
    } else {
        ["controller.k_mm_per_rad", "controller.k2_mm_per_rad"]
    };
    for ((name, v), key) in [("k", k), ("k2", k2)].into_iter().zip(keys) {
        check_arg(name, key, v)?;
    }
    let gains = if si {
        FeedbackGains { k, k2 }
    } else {
        FeedbackGains::from_thesis_mm_per_rad(k, k2)
    };
    let opts = DelayOptions {
        chebyshev_order: count("n", n)?,
        ..Default::default()
    };
    opts.validate()
        .map_err(|e| PyValueError::new_err(format!("argument `n`: {e}")))?;
    Ok((params, plant_name, gains, opts))
}

/// What `ol_table` and `ol_fit` share: the plant (and its echoed name), the
/// IHB options and the grid, each validated.
fn grid_job(
    plant: Option<&Bound<'_, PyAny>>,
    harmonics: i128,
    v_m: (f64, f64, f64),
    t_u: (f64, f64, f64),
    omega0_rpm: f64,
) -> PyResult<(PlantParams, String, IhbOptions, Grid)> {
    let (params, plant_name) = plant_of(plant)?;
    let opts = ihb_options(harmonics)?;
    Ok((params, plant_name, opts, grid_of(v_m, t_u, omega0_rpm)?))
}

fn ihb_options(harmonics: i128) -> PyResult<IhbOptions> {
    Ok(IhbOptions {
        harmonics: count("harmonics", harmonics)?,
        ..Default::default()
    })
}

/// A design-crate error: bad inputs → `ValueError`, solver failures (stall,
/// no convergence) → `RuntimeError` (the CLI's `input` and `failed`).
fn design_err(e: IvtError) -> PyErr {
    match e {
        IvtError::Input { .. } | IvtError::Plant(_) | IvtError::EmptyGrid(_) => {
            PyValueError::new_err(e.to_string())
        }
        IvtError::Stall { .. } | IvtError::NoConvergence { .. } | IvtError::AllFailed { .. } => {
            PyRuntimeError::new_err(e.to_string())
        }
    }
}

/// IVT steady state at one operating point (§4.2.1): the mean eccentricity r̄
/// that holds the mean speed ω0 at (V_m, T_U), accurate by default.
///
/// `method="polish"` (default) refines the n-harmonic IHB by θ-shooting
/// (≤ 1e-9 relative); `method="ihb"` reports the IHB alone (n = 7, the
/// thesis's choice, is ~3 % off r̄), with |r̄(n) − r̄(2n+1)| as its error
/// estimate. Returns the dict of `ivt ol solve --json`: r, feasible, verdict
/// ("feasible", "under-drive", "over-drive"), q, omega_min, omega_max,
/// solve_time_s, iterations, residual_norm, harmonics, r_max, omega0, method
/// ("ihb+shooting" or "ihb"), r_ihb, error_estimate {r_abs, r_rel, how},
/// thesis_choice, plant. `plant`: "printed" (default), "thesis-ch4" or an
/// ivt.kin.Plant.
#[pyfunction]
#[pyo3(signature = (v_m, t_u, omega0_rpm = 100.0, harmonics = 7, plant = None, method = "polish"))]
fn ol_solve<'py>(
    py: Python<'py>,
    v_m: f64,
    t_u: f64,
    omega0_rpm: f64,
    #[pyo3(from_py_with = int)] harmonics: i128,
    plant: Option<&Bound<'py, PyAny>>,
    method: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let (params, plant_name) = plant_of(plant)?;
    let op = operating_point(v_m, t_u, omega0_rpm)?;
    let opts = ihb_options(harmonics)?;
    let method = match method {
        "polish" => SolveMethod::Polish,
        "ihb" => SolveMethod::Ihb,
        other => {
            return Err(PyValueError::new_err(format!(
                "argument `method` = {other:?} must be 'polish' or 'ihb'"
            )))
        }
    };
    let t0 = Instant::now();
    let acc = py
        .detach(|| accurate_r(&params, &op, opts, method))
        .map_err(design_err)?;
    let dt = t0.elapsed().as_secs_f64();
    let s = &acc.ihb;
    let verdict = Verdict::classify(acc.r, params.r_max);
    let d = PyDict::new(py);
    d.set_item("r", acc.r)?;
    d.set_item("feasible", verdict == Verdict::Feasible)?;
    d.set_item("verdict", verdict.as_str())?;
    d.set_item("q", s.q.clone().into_pyarray(py))?;
    d.set_item("omega_min", acc.omega_min)?;
    d.set_item("omega_max", acc.omega_max)?;
    d.set_item("solve_time_s", dt)?;
    d.set_item("iterations", s.iterations)?;
    d.set_item("residual_norm", s.residual_norm)?;
    d.set_item("harmonics", opts.harmonics)?;
    d.set_item("r_max", params.r_max)?;
    d.set_item("omega0", op.omega0)?;
    d.set_item("method", method.label())?;
    d.set_item("r_ihb", s.r)?;
    let e = PyDict::new(py);
    e.set_item("r_abs", acc.error_abs)?;
    e.set_item("r_rel", acc.error_abs / acc.r.abs())?;
    e.set_item("how", acc.how)?;
    d.set_item("error_estimate", e)?;
    d.set_item(
        "thesis_choice",
        method == SolveMethod::Ihb && opts.harmonics == 7,
    )?;
    d.set_item("plant", plant_name)?;
    Ok(d)
}

/// Open-loop table: the IHB steady state over a grid (rows of fixed T_U run
/// in parallel on Rust threads, warm starts along V_m), GIL released.
///
/// v_m, t_u: (from, step, to) as in `ivt ol table` (thesis grid
/// 2:0.4:12 V × 1.5:0.5:9 N·m). Returns {"v_m", "t_u", "omega0",
/// "points": [{"vm", "tu", "r", "verdict", ...} or {"vm", "tu", "error"}]}
/// and "plant" like the CLI, plus "r": an array of shape (len(t_u), len(v_m)) with NaN
/// where a point failed.
#[pyfunction]
#[pyo3(signature = (
    v_m = (2.0, 0.4, 12.0), t_u = (1.5, 0.5, 9.0), omega0_rpm = 100.0, harmonics = 7,
    plant = None
))]
fn ol_table<'py>(
    py: Python<'py>,
    v_m: (f64, f64, f64),
    t_u: (f64, f64, f64),
    omega0_rpm: f64,
    #[pyo3(from_py_with = int)] harmonics: i128,
    plant: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (params, plant_name, opts, grid) = grid_job(plant, harmonics, v_m, t_u, omega0_rpm)?;
    let pts = crate::interrupt::detach_interruptible_threaded(py, || {
        sweep::sweep(&params, &grid, opts, || ())
    })?
    .map_err(design_err)?;
    let points = PyList::empty(py);
    let mut r = Array2::<f64>::from_elem((grid.t_u.len(), grid.v_m.len()), f64::NAN);
    for (i, p) in pts.iter().enumerate() {
        let e = PyDict::new(py);
        e.set_item("vm", p.op.v_m)?;
        e.set_item("tu", p.op.t_u)?;
        match &p.result {
            Ok(s) => {
                e.set_item("r", s.r)?;
                e.set_item("verdict", s.verdict.as_str())?;
                e.set_item("omega_min", s.omega_min)?;
                e.set_item("omega_max", s.omega_max)?;
                if let Some(slot) = r.get_mut((i / grid.v_m.len(), i % grid.v_m.len())) {
                    *slot = s.r;
                }
            }
            Err(msg) => e.set_item("error", msg)?,
        }
        points.append(e)?;
    }
    let d = PyDict::new(py);
    d.set_item("v_m", grid.v_m.clone())?;
    d.set_item("t_u", grid.t_u.clone())?;
    d.set_item("omega0", grid.omega0)?;
    d.set_item("points", points)?;
    d.set_item("r", r.into_pyarray(py))?;
    d.set_item("plant", plant_name)?;
    Ok(d)
}

/// Open-loop refit (thesis §4.2.1, `ivt ol fit`, same defaults): the IHB r̄
/// over the grid, the Eq. 158 polynomial (all 15 terms V^0..2 T^0..4 with
/// `full=True`) through the feasible points, the Eq. 159 over-drive boundary
/// (r̄ = r_max) and the under-drive one (r̄ = 0), and the ω_a error of the
/// refitted law and of the thesis's printed law. Axes `(from, step, to)` at
/// `omega0_rpm`, as in `ol_table`. Returns the dict of `ivt ol fit --json`:
/// poly [[V^i T^j]], boundary, r_max, form ("eq158" or "full"), points,
/// plant, rms_r, max_r, omega_a_error_rpm {max_abs, rms},
/// thesis_omega_a_error_rpm {max_abs, rms}, boundary_max_dev_v,
/// underdrive_boundary {alpha, beta}, emitted (None: no Rust file is
/// written). `RuntimeError` when every point or a boundary solve fails. GIL
/// released.
#[pyfunction]
#[pyo3(signature = (
    v_m = (2.0, 0.4, 12.0), t_u = (1.5, 0.5, 9.0), omega0_rpm = 100.0, harmonics = 7,
    plant = None, full = false
))]
fn ol_fit<'py>(
    v_m: (f64, f64, f64),
    t_u: (f64, f64, f64),
    omega0_rpm: f64,
    #[pyo3(from_py_with = int)] harmonics: i128,
    plant: Option<&Bound<'py, PyAny>>,
    full: bool,
    py: Python<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let (params, plant_name, opts, grid) = grid_job(plant, harmonics, v_m, t_u, omega0_rpm)?;
    let form = if full {
        PolyForm::Full
    } else {
        PolyForm::Eq158
    };
    let rep = crate::interrupt::detach_interruptible_threaded(py, || {
        fit_law(&params, &grid, form, opts, || ())
    })?
    .map_err(design_err)?;
    let error_dict = |e: &LawError| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("max_abs", e.max_abs_rpm)?;
        d.set_item("rms", e.rms_rpm)?;
        Ok(d)
    };
    let d = PyDict::new(py);
    d.set_item("poly", rep.law.poly)?;
    d.set_item("boundary", rep.law.boundary)?;
    d.set_item("r_max", rep.law.r_max)?;
    d.set_item("form", if full { "full" } else { "eq158" })?;
    d.set_item("points", rep.fit.points)?;
    d.set_item("plant", plant_name)?;
    d.set_item("rms_r", rep.fit.rms_r)?;
    d.set_item("max_r", rep.fit.max_r)?;
    d.set_item("omega_a_error_rpm", error_dict(&rep.law_error)?)?;
    d.set_item("thesis_omega_a_error_rpm", error_dict(&rep.thesis_error)?)?;
    d.set_item("boundary_max_dev_v", rep.overdrive.max_dev_v)?;
    let under = PyDict::new(py);
    under.set_item("alpha", rep.underdrive.alpha)?;
    under.set_item("beta", rep.underdrive.beta)?;
    d.set_item("underdrive_boundary", under)?;
    d.set_item("emitted", py.None())?;
    Ok(d)
}

/// Local stability of the integral time-delay loop (Eq. 174–179, Chebyshev
/// spectral Tau of order `n`, monodromy over θ ∈ [0, 2π]) at (V_m, T_U).
///
/// k, k2: gains in the thesis's mm·rad⁻¹ unless `si=True` (m·s/rad²).
/// Returns the dict of `ivt stability --json` (without "design"):
/// max_abs_multiplier (excluding the structural unit one), structural,
/// multipliers [[re, im]...], r_bar, k_si, k2_si, chebyshev_order, stable,
/// solve_time_s, plant. GIL released.
#[pyfunction]
#[pyo3(signature = (
    v_m, t_u, k = 0.01, k2 = 0.02, si = false, n = 16, omega0_rpm = 100.0, plant = None
))]
#[allow(clippy::too_many_arguments)]
fn stability<'py>(
    py: Python<'py>,
    v_m: f64,
    t_u: f64,
    k: f64,
    k2: f64,
    si: bool,
    #[pyo3(from_py_with = int)] n: i128,
    omega0_rpm: f64,
    plant: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let op = operating_point(v_m, t_u, omega0_rpm)?;
    let (params, plant_name, gains, opts) = delay_loop(plant, k, k2, si, n)?;
    let t0 = Instant::now();
    let s = py
        .detach(|| delay_stability(&params, &op, gains, &opts))
        .map_err(design_err)?;
    let dt = t0.elapsed().as_secs_f64();
    let d = PyDict::new(py);
    d.set_item("max_abs_multiplier", s.max_abs_multiplier)?;
    d.set_item("structural", [s.structural.0, s.structural.1])?;
    let mult: Vec<[f64; 2]> = s.multipliers.iter().map(|m| [m.0, m.1]).collect();
    d.set_item("multipliers", mult)?;
    d.set_item("r_bar", s.orbit.r)?;
    d.set_item("k_si", gains.k)?;
    d.set_item("k2_si", gains.k2)?;
    d.set_item("chebyshev_order", opts.chebyshev_order)?;
    d.set_item("stable", s.max_abs_multiplier < 1.0)?;
    d.set_item("solve_time_s", dt)?;
    d.set_item("plant", plant_name)?;
    Ok(d)
}

/// Stability of the time-delay loop over a (V_m, T_U) grid for fixed gains
/// (thesis Fig. 42; `ivt stability-map`, same defaults). Axes are
/// `(from, step, to)` at `omega0_rpm`, as in `ol_table`; k, k2, si, n, plant
/// as in `stability`; `feasible_only` maps only the points whose IHB r̄ lies
/// in [0, r_max]. Returns the dict of `ivt stability-map --json`: "points"
/// [{"vm", "tu", "max_abs_multiplier"} or {"vm", "tu", "error"}], "worst",
/// "failed", "k_si", "k2_si", "solve_time_s", "plant"; plus "v_m", "t_u" (the
/// axes) and "max_abs_multiplier": an array of shape (len(t_u), len(v_m)),
/// NaN where a point failed or was skipped. `RuntimeError` when every point
/// fails. GIL released.
#[pyfunction]
#[pyo3(signature = (
    v_m = (2.0, 0.4, 12.0), t_u = (1.5, 0.5, 9.0), omega0_rpm = 100.0, k = 0.01, k2 = 0.02,
    si = false, n = 16, plant = None, feasible_only = false
))]
#[allow(clippy::too_many_arguments)]
fn stability_map<'py>(
    py: Python<'py>,
    v_m: (f64, f64, f64),
    t_u: (f64, f64, f64),
    omega0_rpm: f64,
    k: f64,
    k2: f64,
    si: bool,
    #[pyo3(from_py_with = int)] n: i128,
    plant: Option<&Bound<'py, PyAny>>,
    feasible_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let grid = grid_of(v_m, t_u, omega0_rpm)?;
    let (params, plant_name, gains, opts) = delay_loop(plant, k, k2, si, n)?;
    let t0 = Instant::now();
    let map = crate::interrupt::detach_interruptible_threaded(py, || {
        grid_stability_map(&params, &grid, feasible_only, gains, &opts)
    })?
    .map_err(design_err)?;
    let dt = t0.elapsed().as_secs_f64();
    let points = PyList::empty(py);
    for (op, r) in &map.entries {
        let e = PyDict::new(py);
        e.set_item("vm", op.v_m)?;
        e.set_item("tu", op.t_u)?;
        match r {
            Ok(m) => e.set_item("max_abs_multiplier", m)?,
            Err(msg) => e.set_item("error", msg)?,
        }
        points.append(e)?;
    }
    let values = Array2::from_shape_vec((grid.t_u.len(), grid.v_m.len()), map.values(&grid))
        .map_err(|e| PyRuntimeError::new_err(format!("stability map layout: {e}")))?;
    let d = PyDict::new(py);
    d.set_item("points", points)?;
    d.set_item("worst", map.worst)?;
    d.set_item("failed", map.failed)?;
    d.set_item("k_si", gains.k)?;
    d.set_item("k2_si", gains.k2)?;
    d.set_item("solve_time_s", dt)?;
    d.set_item("plant", plant_name)?;
    d.set_item("v_m", grid.v_m.clone())?;
    d.set_item("t_u", grid.t_u.clone())?;
    d.set_item("max_abs_multiplier", values.into_pyarray(py))?;
    Ok(d)
}

/// Register `ivt._ivt.design`.
pub fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let m = PyModule::new(parent.py(), "design")?;
    add_functions!(&m, [ol_solve, ol_fit, ol_table, stability, stability_map]);
    parent.add_submodule(&m)
}
