//! `ivt.hb.frc` and `ivt.hb.backbone`: branches of periodic orbits of a user
//! system followed by pseudo-arclength continuation (Eq. 68–77). The FRC is
//! ivt-hb's event tracer ([`ivt_hb::trace`]) on the frequency family: Floquet
//! multipliers (Hsu) at every point, folds, period doublings, Neimark–Sacker
//! points and branch points each located on its extended system.

use ivt_hb::{
    frequency_response, trace, Backbone, BackboneOptions, BifurcationKind, Corrector, Event,
    FamilyBranch, Frc, FrcFold, FrcOptions, Frequency, HbError, HbOptions, ModifiedIhb,
    PeriodicProblem, Trace, TraceOptions,
};
use numpy::ndarray::Array1;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::hb::{finite, frc_dict, pairs, run_user, user_system_fn, UserArgs};

/// The FRC of `problem` from `from` to `to`, followed with the Newton–chord
/// corrector and `FrcOptions::default()`'s second-order predictor (one
/// Galerkin Jacobian and ~3 residuals per point: the user's `g` is called
/// about a sixth as often as by Broyden's many iterations). With `events`,
/// the start is solved by the modified IHB and the branch traced in ω_f by
/// [`ivt_hb::trace`], every event located (the trace's events are returned);
/// without, [`ivt_hb::frequency_response`] traces it and locates the folds
/// only (no branch-point test per point).
fn traced_frc<P: PeriodicProblem>(
    problem: &P,
    opts: &HbOptions,
    from: f64,
    to: f64,
    events: bool,
) -> Result<(Option<Trace>, Frc), HbError> {
    if !events {
        let frc_opts = FrcOptions {
            from,
            to,
            corrector: Corrector::Newton,
            ..FrcOptions::default()
        };
        return Ok((None, frequency_response(problem, opts, &frc_opts)?));
    }
    let start = ModifiedIhb::new(problem, opts.clone())?.solve(from, None)?;
    let frc_opts = FrcOptions::default();
    let trace_opts = TraceOptions {
        lambda_to: to,
        continuation: frc_opts.continuation,
        corrector: Corrector::Newton,
        ..TraceOptions::default()
    };
    let mut branch = FamilyBranch::new(Frequency(problem), opts, from)?;
    let traced = trace(&mut branch, &start.coeffs, from, &trace_opts).map_err(|e| match e {
        ivt_hb::BifurcationError::Hb(h) => h,
        other => HbError::InvalidInput(other.to_string()),
    })?;
    let frc = Frc::from_trace(&traced, opts)?;
    Ok((Some(traced), frc))
}

/// The Python name of an event kind.
fn kind_name(kind: BifurcationKind) -> &'static str {
    match kind {
        BifurcationKind::Fold => "fold",
        BifurcationKind::PeriodDoubling => "period_doubling",
        BifurcationKind::NeimarkSacker => "neimark_sacker",
        BifurcationKind::BranchPoint => "branch_point",
    }
}

/// One event as a dict: kind, omega (located, else that of the point before
/// it), located, multipliers at the located point (else those of the point
/// before), index, and for a failed location the reason.
fn event_dict<'py>(py: Python<'py>, e: &Event, frc: &Frc) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("kind", kind_name(e.kind))?;
    d.set_item("index", e.index)?;
    let near = frc.points.get(e.index);
    match &e.location {
        Ok(b) => {
            d.set_item("omega", b.lambda)?;
            d.set_item("located", true)?;
            d.set_item("multipliers", pairs(&b.multipliers))?;
            d.set_item("coeffs", b.q.clone().into_pyarray(py))?;
            d.set_item("error", py.None())?;
        }
        Err(why) => {
            d.set_item("omega", near.map(|p| p.omega_f))?;
            d.set_item("located", false)?;
            d.set_item("multipliers", near.map(|p| pairs(&p.multipliers)))?;
            d.set_item("coeffs", near.map(|p| p.coeffs.clone().into_pyarray(py)))?;
            d.set_item("error", why.to_string())?;
        }
    }
    Ok(d)
}

/// A fold of the fast path (`events=False`) as an event dict (multipliers:
/// those of the path point nearest the turn).
fn fold_event<'py>(py: Python<'py>, fold: &FrcFold, frc: &Frc) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("kind", "fold")?;
    d.set_item("index", fold.index)?;
    d.set_item("omega", fold.omega_f)?;
    d.set_item("located", fold.located)?;
    let near = frc.points.get(fold.index);
    d.set_item("multipliers", near.map(|p| pairs(&p.multipliers)))?;
    d.set_item("coeffs", fold.coeffs.clone().into_pyarray(py))?;
    d.set_item("error", py.None())?;
    Ok(d)
}

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
/// Returns {"points": [{"omega", "coeffs", "amplitude", "multipliers",
/// "multiplier_error", "stable", "stability"}...], "folds": [{"omega",
/// "amplitude", "coeffs", "located", "index" (path point before the
/// turn)}...], "bifurcations":
/// [{"kind" ("fold", "period_doubling", "neimark_sacker", "branch_point"),
/// "omega", "located", "multipliers", "coeffs", "index", "error"}...] in path
/// order, "termination"} and the arrays omega, amplitude, stable. amplitude
/// is max |x_0| over the AFT samples (DOF 0). Each point's Hsu sub-intervals
/// are doubled until the Richardson estimate of its multipliers' error
/// ("multiplier_error", relative to max(1, |μ|)) is ≤ 1e-6; the events'
/// multipliers come from 2048 fixed steps. `events=False` locates the folds
/// only by `ivt_hb::frequency_response` (no period-doubling,
/// Neimark–Sacker or branch-point test per point: cheaper per
/// point, see the ivt-py README). GIL released between callbacks.
fn frc<'py>(py, user, jac;
    f: Option<&Bound<'py, PyAny>>,
    omega_from: f64,
    omega_to: f64;
    tol: f64 = 0.0,
    events: bool = true,
) {
    let (problem, opts) = user.setup(f, 1, tol)?;
    let (from, to) = (finite("omega_from", omega_from)?, finite("omega_to", omega_to)?);
    if !(from > 0.0 && to > 0.0 && from != to) {
        return Err(PyValueError::new_err(format!(
            "arguments `omega_from` = {from}, `omega_to` = {to} must be > 0 and distinct"
        )));
    }
    let (traced, frc) = run_user(py, &problem, |p| traced_frc(p, &opts, from, to, events))?;
    let d = frc_dict(py, &frc)?;
    let folds = PyList::empty(py);
    for fold in &frc.folds {
        let e = PyDict::new(py);
        e.set_item("omega", fold.omega_f)?;
        e.set_item("amplitude", fold.amplitude)?;
        e.set_item("coeffs", fold.coeffs.clone().into_pyarray(py))?;
        e.set_item("located", fold.located)?;
        e.set_item("index", fold.index)?;
        folds.append(e)?;
    }
    let bifurcations = PyList::empty(py);
    match &traced {
        Some(t) => {
            for e in &t.events {
                bifurcations.append(event_dict(py, e, &frc)?)?;
            }
        }
        None => {
            for fold in &frc.folds {
                bifurcations.append(fold_event(py, fold, &frc)?)?;
            }
        }
    }
    d.set_item("folds", folds)?;
    d.set_item("bifurcations", bifurcations)?;
    Ok(d)
}
}

/// The backbone as a dict of arrays and points.
fn backbone_dict<'py>(py: Python<'py>, bb: &Backbone) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: fn(&ivt_hb::BackbonePoint) -> f64| Array1::from_iter(bb.points.iter().map(f));
    d.set_item("amplitude", col(|p| p.amplitude).into_pyarray(py))?;
    d.set_item("omega", col(|p| p.omega).into_pyarray(py))?;
    d.set_item("kappa", col(|p| p.kappa).into_pyarray(py))?;
    let points = PyList::empty(py);
    for p in &bb.points {
        let e = PyDict::new(py);
        e.set_item("amplitude", p.amplitude)?;
        e.set_item("omega", p.omega)?;
        e.set_item("kappa", p.kappa)?;
        e.set_item("coeffs", p.coeffs.clone().into_pyarray(py))?;
        points.append(e)?;
    }
    d.set_item("points", points)?;
    d.set_item("termination", format!("{:?}", bb.termination))?;
    Ok(d)
}

user_system_fn! {
/// Backbone curve (nonlinear normal mode) of the undamped, unforced system
/// `M x'' + K x + g(x, v) = 0` (`c` must be zero) followed in amplitude from
/// the linear mode of frequency `omega0` and shape `mode` (K·mode = ω₀² M·mode).
///
/// The frequency ω is an unknown, with the phase condition b1 = 0 on DOF `dof`
/// and its first cosine coefficient a1 prescribed: `amplitude` is a1 of DOF
/// `dof`, traced from `amplitude_from` to `amplitude_to` (ivt_hb::backbone, a
/// fictitious damping κ unfolds the family and is ~0 on the result).
/// g, velocity_dependent, vectorized and jac as in `solve`: the curve is
/// followed with the Newton–chord corrector on the exact Jacobian of
/// {q, ω, κ} (the Galerkin Jacobian, with ∂g from `jac`, the elements, or
/// differences of `g`).
/// Returns {"amplitude", "omega", "kappa" (arrays), "points": [{"amplitude",
/// "omega", "kappa", "coeffs"}...], "termination"}. GIL released between
/// callbacks.
fn backbone<'py>(py, user, jac;
    omega0: f64,
    mode: Vec<f64>,
    amplitude_from: f64 = 0.01,
    amplitude_to: f64 = 1.0;
    #[pyo3(from_py_with = crate::args::int64)] dof: i64 = 0,
    tol: f64 = 0.0,
) {
    let (problem, opts) = user.setup(None, 1, tol)?;
    let bopts = BackboneOptions {
        dof: crate::args::count("dof", dof)?,
        amplitude_from: finite("amplitude_from", amplitude_from)?,
        amplitude_to: finite("amplitude_to", amplitude_to)?,
        corrector: Corrector::Newton,
        ..BackboneOptions::default()
    };
    let omega0 = finite("omega0", omega0)?;
    let bb = run_user(py, &problem, |p| ivt_hb::backbone(p, &opts, omega0, &mode, &bopts))?;
    backbone_dict(py, &bb)
}
}

/// Add `frc` and `backbone` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [frc, backbone]);
    Ok(())
}
