//! `ivt.hb.event_sensitivity` (issue 45 item 3): how a located feature of a
//! frequency response moves with the parameter of a Python family
//! `family(p) -> (m, c, k, g, f)`, the job
//! [`ivt_jobs::event_sensitivity()`].

use ivt_hb::analyses::sensitivity::Feature;
use ivt_jobs::{self as jobs, SensitivityRequest};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::count;
use crate::hb_family::PyFamily;
use crate::hb_shared::hb_keywords_fn;
use crate::hb_shared::{finite, given_point};
use crate::to_python::to_dict;

hb_keywords_fn! {
/// dω_f/dp and dA/dp (A = max |x_d| of the orbit, d = `amplitude_dof`) of a
/// located feature of the frequency response of `family(p)` → (m, c, k, g,
/// f), by the adjoint of the feature's extended system: one transposed
/// solve per feature on its bordered LU, ∂/∂p of the residual and the test
/// by central differences. `event` is an entry of `frc(..., events=True)
/// ["bifurcations"]` or `frc(...)["folds"]` computed at `p` (same n,
/// samples): "kind" "fold" (the default), "period_doubling",
/// "neimark_sacker", "branch_point" (a symmetric pitchfork: taken as given)
/// or "peak" (any point near an amplitude peak away from folds, e.g. the
/// highest point of `frc(...)["points"]`); the feature is located again at
/// `p` from it. Returns {"kind", "p", "omega", "amplitude", "d_omega_dp",
/// "d_amplitude_dp", "coeffs", "iterations", "time_s"}. An exception in
/// `family` is re-raised. GIL released between callbacks.
/// (Not a path: no continuation keywords.)
fn event_sensitivity<'py>(py, keys);
head [family,] [family: &Bound<'py, PyAny>,];
own [
    event: &Bound<'py, PyDict>,
    p: f64,
    #[pyo3(from_py_with = crate::args::int64)] amplitude_dof: i64 = 0
];
mid [];
tail [] [];
{
    let p = finite("p", p)?;
    let kind: Option<String> = event.get_item("kind")?.map(|k| k.extract()).transpose()?;
    let feature = Feature::from_name(kind.as_deref().unwrap_or("fold"))
        .map_err(|e| PyValueError::new_err(format!("argument `event`: {e}")))?;
    let located: Option<bool> = event.get_item("located")?.map(|v| v.extract()).transpose()?;
    if located == Some(false) {
        return Err(PyValueError::new_err("argument `event` was not located"));
    }
    let (omega, coeffs) = given_point(event, "event")?;
    let req = SensitivityRequest {
        feature,
        omega,
        coeffs,
        p,
        amplitude_dof: count("amplitude_dof", amplitude_dof)?,
    };
    let fam = &PyFamily::new(family, keys);
    let first = fam.first(py, p)?;
    let s = fam.run(py, first, |hb| jobs::event_sensitivity(|x| fam.build(x), hb, &req))?;
    to_dict(py, &s)
}
}

/// Add `event_sensitivity` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [event_sensitivity]);
    Ok(())
}
