//! `ivt.sim`: run ivt-sim scenes (TOML path, TOML text or a dict) and get
//! the recorded channels as numpy arrays plus the summary of `ivt sim --json`.

use ivt_sim::output::write_outputs;
use ivt_sim::record::Channel;
use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::steady::Route;
use numpy::ndarray::{Array1, Array2};
use numpy::IntoPyArray;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use serde::Serialize;
use serde_json::Value;
use std::path::PathBuf;

/// A JSON value (from serde) as Python objects, through the `json` module.
fn json_to_py<'py>(py: Python<'py>, value: &impl Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| PyRuntimeError::new_err(format!("serializing result: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Parse a scene given as a dict, a path (str or os.PathLike) or TOML text.
///
/// A `str` is TOML text when it contains a newline or `=`, else a path.
/// Dicts go through TOML so that they get exactly the file's validation.
pub fn scene_from_py(ob: &Bound<'_, PyAny>) -> PyResult<Scene> {
    let py = ob.py();
    let bad = |e: ivt_sim::scene::SceneError| PyValueError::new_err(e.to_string());
    if ob.cast::<PyDict>().is_ok() {
        let text: String = py
            .import("json")?
            .call_method1("dumps", (ob,))
            .map_err(|e| {
                PyTypeError::new_err(format!("argument `scene`: dict is not JSON-like: {e}"))
            })?
            .extract()?;
        let value: Value = serde_json::from_str(&text)
            .map_err(|e| PyValueError::new_err(format!("argument `scene`: {e}")))?;
        let toml_text = toml::to_string(&value).map_err(|e| {
            PyValueError::new_err(format!("argument `scene`: not representable as TOML: {e}"))
        })?;
        return Scene::parse(&toml_text, "<dict>").map_err(bad);
    }
    if ob.cast::<PyString>().is_ok() {
        let s: String = ob.extract()?;
        let s = s.as_str();
        if s.contains('\n') || s.contains('=') {
            return Scene::parse(s, "<string>").map_err(bad);
        }
        return Scene::load(&PathBuf::from(s)).map_err(bad);
    }
    if ob.hasattr("__fspath__")? {
        let path: PathBuf = ob.extract()?;
        return Scene::load(&path).map_err(bad);
    }
    Err(PyTypeError::new_err(
        "argument `scene` must be a dict, a path or TOML text",
    ))
}

/// One channel (its samples as JSON objects) as a dict of column arrays:
/// numbers → float64, integers → int64, booleans → bool.
fn columns<'py>(
    py: Python<'py>,
    rows: Result<Vec<Value>, serde_json::Error>,
) -> PyResult<Bound<'py, PyDict>> {
    let rows = rows.map_err(|e| PyRuntimeError::new_err(format!("serializing channel: {e}")))?;
    let out = PyDict::new(py);
    let Some(Value::Object(first)) = rows.first() else {
        return Ok(out);
    };
    for (key, v0) in first {
        let col = rows.iter().map(|r| r.get(key));
        if v0.is_boolean() {
            let a: Array1<bool> = col
                .map(|v| v.and_then(Value::as_bool).unwrap_or(false))
                .collect();
            out.set_item(key, a.into_pyarray(py))?;
        } else if v0.is_i64() || v0.is_u64() {
            let a: Array1<i64> = col
                .map(|v| {
                    v.and_then(|v| v.as_i64().or_else(|| v.as_u64().map(|u| u as i64)))
                        .unwrap_or(0)
                })
                .collect();
            out.set_item(key, a.into_pyarray(py))?;
        } else {
            let a: Array1<f64> = col
                .map(|v| v.and_then(Value::as_f64).unwrap_or(f64::NAN))
                .collect();
            out.set_item(key, a.into_pyarray(py))?;
        }
    }
    Ok(out)
}

/// Run a scene (ivt-sim, software in the loop with the ivt-ctrl controller)
/// with the GIL released.
///
/// scene: a dict (the TOML structure), a path to a .toml file, or TOML text
/// (a str containing a newline or `=`). out: directory for the files the
/// scene's [outputs] asks for (MCAP, CSV, summary JSON, PNG), or None to write
/// nothing. Returns a dict with "summary" (the keys of `ivt sim --json`),
/// "channels" (each logged channel as a dict of numpy arrays: plant, control,
/// stepper, sensors; "plot" as an n×6 array) and "outputs" (written paths).
/// The summary names the route taken ("ihb_steady_state" for a scene that
/// asks only for steady-state metrics at constant inputs, else
/// "time_integration"; `route=` forces one) and carries "steady_state" when
/// the scene asks for it.
/// Scene errors raise ValueError with ivt-sim's one-line message; a failed
/// integration or controller backend raises RuntimeError.
#[pyfunction]
#[pyo3(signature = (scene, out = None, route = None))]
fn run<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    out: Option<PathBuf>,
    route: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = scene_from_py(scene)?;
    let force = match route.as_deref() {
        None => None,
        Some(name) => Some(Route::from_name(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "argument `route` = {name:?}: must be 'ihb_steady_state' or 'time_integration'"
            ))
        })?),
    };
    let (answer, paths) = py
        .detach(|| -> Result<_, String> {
            let answer = Simulation::new(&scene)
                .route(force)
                .answer()
                .map_err(|e| e.to_string())?;
            let paths = match &out {
                Some(dir) => write_outputs(dir, &scene, &answer).map_err(|e| e.to_string())?,
                None => vec![],
            };
            Ok((answer, paths))
        })
        .map_err(PyRuntimeError::new_err)?;
    let d = PyDict::new(py);
    d.set_item("summary", json_to_py(py, &answer.summary_json(&scene))?)?;
    let ch = PyDict::new(py);
    let empty = ivt_sim::run::Channels::default();
    let c = answer.run.as_ref().map_or(&empty, |r| &r.channels);
    for &channel in Channel::ALL {
        if let Some(rows) = c.json_rows(channel) {
            ch.set_item(channel.name(), columns(py, rows)?)?;
        }
    }
    if let Some(v) = &c.plot {
        // (t, ω, ω_a, r, V_m, T_U) per row
        let flat: Vec<f64> = v
            .iter()
            .flat_map(|s| [s.t, s.omega, s.omega_a, s.r, s.v_m, s.t_u])
            .collect();
        let a = Array2::from_shape_vec((v.len(), 6), flat)
            .map_err(|e| PyRuntimeError::new_err(format!("plot channel: {e}")))?;
        ch.set_item("plot", a.into_pyarray(py))?;
    }
    d.set_item("channels", ch)?;
    let outputs: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    d.set_item("outputs", PyList::new(py, outputs)?)?;
    Ok(d)
}

/// Parse and validate a scene without running it; returns its name,
/// duration_s, seed and ppr (a cheap check of a dict before a sweep).
#[pyfunction]
fn check_scene<'py>(py: Python<'py>, scene: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let s = scene_from_py(scene)?;
    s.plant_params()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("name", &s.name)?;
    d.set_item("duration_s", s.duration_s)?;
    d.set_item("seed", s.seed)?;
    d.set_item("ppr", s.encoder.ppr)?;
    Ok(d)
}

/// A scene as a plain dict (the TOML structure), after validating it: the
/// form `ivt.sweep` edits with dotted keys. Accepts what `run` accepts.
#[pyfunction]
fn scene_dict<'py>(py: Python<'py>, scene: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    scene_from_py(scene)?;
    if scene.cast::<PyDict>().is_ok() {
        return py.import("copy")?.call_method1("deepcopy", (scene,));
    }
    let text = if scene.cast::<PyString>().is_ok()
        && scene
            .extract::<String>()
            .is_ok_and(|s| s.contains('\n') || s.contains('='))
    {
        scene.extract::<String>()?
    } else {
        let path: PathBuf = scene.extract()?;
        ivt_sim::input::read_text_bounded(&path, ivt_sim::input::MAX_SCENE_BYTES)
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", path.display())))?
    };
    let table: toml::Table = toml::from_str(&text)
        .map_err(|e| PyValueError::new_err(format!("argument `scene`: {e}")))?;
    json_to_py(py, &table)
}

/// Register `ivt._ivt.sim`.
pub fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let m = PyModule::new(parent.py(), "sim")?;
    add_functions!(&m, [run, check_scene, scene_dict]);
    m.add("SUPPORTED_PPR", ivt_ctrl::SUPPORTED_PPR.to_vec())?;
    parent.add_submodule(&m)
}
