//! `ivt.hb.string`: the frequency-response curve of the nonlinear string by
//! space–time harmonic balance (STHB, thesis §3.3, Eq. 103; Figs. 34–36), the
//! job [`ivt_jobs::string`] of `ivt hb string --json`.

use ivt_jobs::{self as jobs, StringRequest};
use ivt_sthb::{Boundary, StringParams};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{count, int64};
use crate::hb_shared::run;
use crate::to_python::to_dict;

/// Frequency-response curve of the string with geometric nonlinearity,
/// `ω² w_tt + ω c_d w_t − w_xx − k_d w_x² w_xx − y0 sin(πx) cos t = 0`
/// (Eq. 103, t the phase), by STHB: `modes` sine trial functions N,
/// `harmonics` M, grids `ns` × `ms`, traced in ω from `from_` to `to` by
/// Newton arclength (`ds`, `ds_min`, `ds_max`, `max_points`: its steps and
/// most points, None: Δη from 0.02 up to 0.05, ds_min 1e-6, 2000 points);
/// stability by monodromy,
/// confirmed by Hill's method near |μ| = 1. `boundary` "fixed" (Eq. 104) or
/// "spring" (k0 w(1) = w_x(1), Eq. 132, Tau method).
/// Returns the dict of `ivt hb string --json`: points [{"omega", "norm" (‖a‖,
/// Eq. 114), "stable", "kind", "max_multiplier", "method"}...], folds
/// [{"omega", "norm", "located", "index"}...], jacobians, hill_calls, stop,
/// solve_time_s ([`ivt_jobs::StringCurve`]; a spring
/// of k0 > 1 adds boundary_note). A trace that fails numerically raises
/// `ConvergenceError`. |kd| is limited to 1e9
/// ([`ivt_jobs::string::MAX_KD`]: larger values only make the trace slow
/// before it fails). GIL released.
#[pyfunction]
#[pyo3(signature = (
    kd = 10.0, modes = 5, harmonics = 19, from_ = 1.0, to = 6.0, cd = 0.8, y0 = 0.5, ns = 64,
    ms = 128, boundary = "fixed", k0 = 10.0, ds = None, ds_min = None, ds_max = None,
    max_points = None
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
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
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
    if !(from_ > 0.0 && to > from_ && to.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "need 0 < `from_` < `to` (finite), got {from_} .. {to}"
        )));
    }
    let req = StringRequest {
        params,
        from: from_,
        to,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
    };
    let curve = run(py, || jobs::string(&req))?;
    to_dict(py, &curve)
}

/// Add `string` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [string]);
    Ok(())
}
