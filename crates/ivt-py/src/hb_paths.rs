//! `ivt.hb.frc` and `ivt.hb.backbone`: branches of periodic orbits of a user
//! system followed by pseudo-arclength continuation (Eq. 68–77), the jobs
//! [`ivt_jobs::frc`] (Floquet multipliers at every point; folds, period
//! doublings, Neimark–Sacker points and branch points each located on its
//! extended system) and [`ivt_jobs::backbone`].

use ivt_hb::BackboneOptions;
use ivt_jobs::{self as jobs, BackboneRequest, FrcRequest};
use ivt_kin::params::Typed;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::hb_shared::{finite, run_user, user_system_fn, UserArgs};
use crate::to_python::to_dict;

user_system_fn! {
/// Frequency-response curve of a user system `M x'' + C x' + K x + g(x, v, θ)
/// = f(θ)` (θ = ω_f t) by pseudo-arclength continuation in ω_f from
/// `omega_from` to `omega_to`, Floquet multipliers (Hsu) at every point, and
/// its events each located by Newton on its extended system (not bracketed).
///
/// m, c, k, g, f, velocity_dependent, jac as in `solve` (f may be None; g may
/// be an `ivt.hb.elements` composition); `vectorized=True`: g(x, v, theta) gets
/// x, v of shape (N, n_dof) and theta of shape (N,) (all 2·samples AFT
/// samples at once, or another grid, see `solve`) and returns (N, n_dof).
/// A `g` or `f` with a parameter named `omega` (`g(x, v, theta, omega)`,
/// `f(theta, omega)`: a rotating unbalance, a frequency-dependent load) gets
/// ω_f as that keyword, and the path's ∂R/∂ω_f includes its ω-dependence
/// (`jac` must then be None).
/// Returns the job's [`ivt_jobs::FrcCurve`]: {"points": [{"omega",
/// "coeffs", "amplitude", "multipliers", "multiplier_error", "stable",
/// "stability", "kind"}...], "folds": [{"omega",
/// "amplitude", "coeffs", "located", "index" (path point before the
/// turn)}...], "bifurcations":
/// [{"kind" ("fold", "period_doubling", "neimark_sacker", "branch_point"),
/// "omega", "located", "multipliers", "coeffs", "index", "error"}...] in path
/// order, "termination", "time_s"} and the arrays omega, amplitude, stable. amplitude
/// is max |x_0| over the AFT samples (DOF 0). Each point's Hsu sub-intervals
/// are doubled until the Richardson estimate of its multipliers' error
/// ("multiplier_error", relative to max(1, |μ|)) is ≤ 1e-6; the events'
/// multipliers come from 2048 fixed steps. `events=False` locates the folds
/// only by `ivt_hb::frequency_response` (no period-doubling,
/// Neimark–Sacker or branch-point test per point: cheaper per
/// point, see docs/guide/src/accuracy-speed.md). `ds`, `ds_min`, `ds_max`,
/// `max_points`: the path's steps in (coefficients, ω_f) and most points
/// (None: Δη from 0.05 up to 0.08, ds_min 1e-7, 5000 points; on the
/// condensed path, in its scaled unknowns). GIL released between callbacks.
fn frc<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    omega_from: f64,
    omega_to: f64;
    tol: f64 = 0.0,
    events: bool = true,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let (from, to) = (finite("omega_from", omega_from)?, finite("omega_to", omega_to)?);
    if !(from > 0.0 && to > 0.0 && from != to) {
        return Err(PyValueError::new_err(format!(
            "arguments `omega_from` = {}, `omega_to` = {} must be > 0 and distinct",
            Typed(from),
            Typed(to)
        )));
    }
    // The Newton–chord corrector: one Galerkin Jacobian and ~3 residuals per
    // point, the user's `g` called about a sixth as often as by Broyden.
    let steps = crate::steps::steps(ds, ds_min, ds_max, max_points)?;
    let req = FrcRequest { options: crate::steps::sweep(from, to, &steps)?, events };
    let curve = run_user(py, &problem, |p| jobs::frc(p, &opts, &req))?;
    to_dict(py, &curve)
}
}

user_system_fn! {
/// Backbone curve (nonlinear normal mode) of the undamped, unforced system
/// `M x'' + K x + g(x, v) = 0` (`c` must be zero) followed in amplitude from
/// the linear mode of frequency `omega0` and shape `mode` (K·mode = ω₀² M·mode).
///
/// The frequency ω is an unknown, with the phase condition b1 = 0 on DOF `dof`
/// and its first cosine coefficient a1 prescribed: `amplitude` is a1 of DOF
/// `dof`, traced from `amplitude_from` to `amplitude_to` (ivt_hb::branches::backbone, a
/// fictitious damping κ unfolds the family and is ~0 on the result).
/// g, velocity_dependent, vectorized and jac as in `solve`: the curve is
/// followed with the Newton–chord corrector on the exact Jacobian of
/// {q, ω, κ} (the Galerkin Jacobian, with ∂g from `jac`, the elements, or
/// differences of `g`).
/// Returns {"amplitude", "omega", "kappa" (arrays), "points": [{"amplitude",
/// "omega", "kappa", "peak" (max |x| of DOF `dof`), "coeffs"}...],
/// "termination"}. `ds`, `ds_min`, `ds_max`, `max_points`: the path's
/// steps (None: Δη from 0.02 up to 0.2, 5000 points). GIL released between
/// callbacks.
fn backbone<'py>(py, user, jac;
    omega0: f64,
    mode: Vec<f64>,
    amplitude_from: f64 = 0.01,
    amplitude_to: f64 = 1.0;
    #[pyo3(from_py_with = crate::args::int64)] dof: i64 = 0,
    tol: f64 = 0.0,
    ds: Option<f64> = None,
    ds_min: Option<f64> = None,
    ds_max: Option<f64> = None,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None,
) {
    let (problem, opts) = user.setup(None, 1, tol)?;
    crate::hb_shared::without_omega(&problem, "backbone")?;
    // The request's Newton–chord corrector, with the keywords' steps.
    let own = BackboneRequest::default().options.continuation;
    let steps = crate::steps::steps(ds, ds_min, ds_max, max_points)?;
    let req = BackboneRequest {
        omega0: finite("omega0", omega0)?,
        mode,
        options: BackboneOptions {
            dof: crate::args::count("dof", dof)?,
            amplitude_from: finite("amplitude_from", amplitude_from)?,
            amplitude_to: finite("amplitude_to", amplitude_to)?,
            continuation: crate::steps::on(&steps, own)?,
        },
    };
    let curve = run_user(py, &problem, |p| jobs::backbone(p, &opts, &req))?;
    to_dict(py, &curve)
}
}

/// Add `frc` and `backbone` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [frc, backbone]);
    Ok(())
}
