//! `ivt.hb.string`: the frequency-response curve of the nonlinear string by
//! space–time harmonic balance (STHB, thesis §3.3, Eq. 103; Figs. 34–36), the
//! computation of `ivt hb string --json` with its defaults and keys.

use ivt_hb::sthb::frc::{frequency_response, StringFrcOptions};
use ivt_hb::sthb::{Boundary, StringHb, StringParams};
use ivt_hb::HbError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::time::Instant;

use crate::args::{count, int64};
use crate::hb::{hb_err, ConvergenceError};

/// Frequency-response curve of the string with geometric nonlinearity,
/// `ω² w_tt + ω c_d w_t − w_xx − k_d w_x² w_xx − y0 sin(πx) cos t = 0`
/// (Eq. 103, t the phase), by STHB: `modes` sine trial functions N,
/// `harmonics` M, grids `ns` × `ms`, traced in ω from `from_` to `to` by
/// Newton arclength with steps up to `step_max`; stability by monodromy,
/// confirmed by Hill's method near |μ| = 1. `boundary` "fixed" (Eq. 104) or
/// "spring" (k0 w(1) = w_x(1), Eq. 132, Tau method).
/// Returns the dict of `ivt hb string --json`: points [{"omega", "norm" (‖a‖,
/// Eq. 114), "stable", "kind", "max_multiplier", "method"}...], jacobians,
/// hill_calls, stop, solve_time_s. A trace that fails numerically raises
/// `ConvergenceError`. |kd| is limited to 1e9 (larger values
/// only make the trace slow before it fails). GIL released.
/// Largest |k_d| accepted (see [`string`]).
const MAX_KD: f64 = 1e9;

#[pyfunction]
#[pyo3(signature = (
    kd = 10.0, modes = 5, harmonics = 19, from_ = 1.0, to = 6.0, cd = 0.8, y0 = 0.5, ns = 64,
    ms = 128, boundary = "fixed", k0 = 10.0, step_max = 0.05
))]
#[allow(clippy::too_many_arguments)]
fn string<'py>(
    py: Python<'py>,
    kd: f64,
    #[pyo3(from_py_with = int64)] modes: i64,
    #[pyo3(from_py_with = int64)] harmonics: i64,
    from_: f64,
    to: f64,
    cd: f64,
    y0: f64,
    #[pyo3(from_py_with = int64)] ns: i64,
    #[pyo3(from_py_with = int64)] ms: i64,
    boundary: &str,
    k0: f64,
    step_max: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let boundary = match boundary {
        "fixed" => Boundary::Fixed,
        "spring" => Boundary::Spring { k0 },
        other => {
            return Err(PyValueError::new_err(format!(
                "argument `boundary` = {other:?} must be 'fixed' or 'spring'"
            )))
        }
    };
    // Measured with `ivt hb string`: from k_d ≈ 1e9 on the trace ends in an
    // error after seconds, growing to ~12 s at 1e17 (the thesis uses 10 and 30).
    if !(kd.is_finite() && kd.abs() <= MAX_KD) {
        return Err(PyValueError::new_err(format!(
            "argument `kd` = {kd} must be finite with |kd| <= {MAX_KD:e}"
        )));
    }
    let params = StringParams {
        kd,
        cd,
        y0,
        modes: count("modes", modes)?,
        harmonics: count("harmonics", harmonics)?,
        ns: count("ns", ns)?,
        ms: count("ms", ms)?,
        boundary,
    };
    params.validate().map_err(|e| hb_err(py, e))?;
    if !(from_ > 0.0 && to > from_ && to.is_finite() && step_max > 0.0 && step_max.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "need 0 < `from_` < `to` (finite) and `step_max` > 0, got {from_} .. {to}, {step_max}"
        )));
    }
    let mut opts = StringFrcOptions::default();
    opts.continuation.ds_max = step_max;
    let t0 = Instant::now();
    let mut hb = StringHb::new(params).map_err(|e| hb_err(py, e))?;
    // The inputs are valid here: a failure of the trace (cold start, stalled
    // step, Hill's method) is numerical, a ConvergenceError.
    let curve = py
        .detach(|| frequency_response(&mut hb, from_, to, &opts))
        .map_err(|e| match e {
            HbError::InvalidInput(_) => hb_err(py, e),
            other => ConvergenceError::new_err(other.to_string()),
        })?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    let points = PyList::empty(py);
    for (p, method) in curve.frc.points.iter().zip(&curve.methods) {
        let e = PyDict::new(py);
        e.set_item("omega", p.omega_f)?;
        e.set_item("norm", p.amplitude)?;
        e.set_item("stable", p.stable())?;
        e.set_item("kind", format!("{:?}", p.kind))?;
        e.set_item("max_multiplier", p.multipliers.first().map(|m| m.norm()))?;
        e.set_item("method", format!("{method:?}"))?;
        points.append(e)?;
    }
    let d = PyDict::new(py);
    d.set_item("points", points)?;
    d.set_item("solve_time_s", solve_time_s)?;
    d.set_item("jacobians", curve.jacobians)?;
    d.set_item("hill_calls", curve.hill_calls)?;
    d.set_item("stop", format!("{:?}", curve.frc.termination))?;
    Ok(d)
}

/// Add `string` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [string]);
    Ok(())
}
