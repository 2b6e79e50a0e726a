//! The continuation keywords of every Python function that follows a path:
//! `ds`, `ds_min`, `ds_max`, `max_points`, each `None` by default (the
//! path's own, tuned value, named in the function's docstring), collected
//! into the engine's one [`Steps`] and merged with the path's options there.

use ivt_hb::{ContinuationOptions, Corrector, FrcOptions};
use ivt_jobs::Steps;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The keywords as [`Steps`] (`max_points` ≥ 0 fits `usize`, else a
/// ValueError naming it; the steps are checked where they are merged).
///
/// # Errors
/// `ValueError` for a `max_points` outside `usize`.
pub(crate) fn steps(
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    max_points: Option<i64>,
) -> PyResult<Steps> {
    Ok(Steps {
        ds,
        ds_min,
        ds_max,
        max_points: max_points
            .map(|v| crate::args::count("max_points", v))
            .transpose()?,
    })
}

/// `base` with the keywords' overrides ([`Steps::on`]).
///
/// # Errors
/// `ValueError` with [`Steps::on`]'s reason, as "argument ...".
pub(crate) fn on(steps: &Steps, base: ContinuationOptions) -> PyResult<ContinuationOptions> {
    steps.on(base).map_err(refused)
}

/// [`Steps::on`]'s reason as the ValueError "argument ...".
fn refused(why: String) -> PyErr {
    PyValueError::new_err(format!("argument {why}"))
}

/// The default frequency sweep from `from` to `to` (the Newton–chord
/// corrector, [`FrcOptions::stepped_sweep`]) with the keywords' steps.
///
/// # Errors
/// As [`on`].
pub(crate) fn sweep(from: f64, to: f64, steps: &Steps) -> PyResult<FrcOptions> {
    FrcOptions::stepped_sweep(from, to, Corrector::Newton, steps).map_err(refused)
}
