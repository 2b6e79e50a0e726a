//! `ivt.hb.continue_bifurcation` and `ivt.hb.duffing_folds`: a fold of the
//! frequency response followed in a second parameter p through its cusps, the
//! job [`ivt_jobs::fold_curve`] (the CLI's `ivt hb duffing-folds`), on a
//! user family `family(p) -> (m, c, k, g, f)` or on Duffing's equation in F.

use ivt_hb::{BifurcationKind, Duffing};
use ivt_jobs::{self as jobs, FoldCurveRequest, FoldStart};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::int64;
use crate::hb_family::family_fn;
use crate::hb_shared::{finite, given_point, options, run};
use crate::to_python::to_dict;

/// The kind and start point of `continue_bifurcation`: ω and coefficients of
/// a fold, period-doubling or Neimark–Sacker dict (`kind` "fold" when
/// absent).
fn given_start(start: &Bound<'_, PyDict>) -> PyResult<(BifurcationKind, FoldStart)> {
    let kind: Option<String> = start.get_item("kind")?.map(|k| k.extract()).transpose()?;
    let kind = match kind.as_deref() {
        None | Some("fold") => BifurcationKind::Fold,
        Some("period_doubling") => BifurcationKind::PeriodDoubling,
        Some("neimark_sacker") => BifurcationKind::NeimarkSacker,
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "argument `start` must be a fold, period_doubling or neimark_sacker point, not {other:?}"
            )))
        }
    };
    let (omega, coeffs) = given_point(start, "start")?;
    Ok((kind, FoldStart::Given { omega, coeffs }))
}

family_fn! {
/// Two-parameter continuation of a fold, period doubling or Neimark–Sacker
/// point of the frequency response of `family(p)` → (m, c, k, g, f) in
/// (omega, p), the job [`ivt_jobs::fold_curve`]. `start` is an entry of
/// `frc(..., events=True)["bifurcations"]` (or of `frc(...)["folds"]`)
/// computed at p = `p_start`, with the same `n` and `samples`; its "kind"
/// says what is followed. Folds (ivt_hb::fold_curve: R = 0, Φ_q v = 0,
/// |v| = 1 followed in p from the start first towards `p_from`, then the
/// other way, each until p leaves [p_from, p_to]): cusps (where two folds merge and the jump disappears)
/// are located as turning points of the curve in p. Period doublings and
/// Neimark–Sacker points (ivt_hb::branches::codim2::bifurcation_curve: R = 0 with the
/// critical eigenvector of the monodromy matrix, followed both ways from the
/// start): each point carries the angle θ of its critical multipliers
/// e^{±iθ}, and on an NS curve the resonances 1:1 and 1:2 (its ends on a fold
/// or PD curve) and 1:3, 1:4 are located. The point at each p of `at` is
/// solved exactly (each crossing). An exception in `family` is re-raised;
/// one in the `g` or `f` it returns for p ≠ p_start makes that point fail
/// (the curve stops there). Returns the job's
/// [`ivt_jobs::FoldCurveResult`]: {"kind", "start_omega", "points":
/// [{"omega", "p", "amplitude", "coeffs", "angle" (not on folds)}...],
/// "at": [...], "special": [{"kind": "cusp" | "resonance_1_1" | ...,
/// "omega", "p", "amplitude", "coeffs"}...], "unlocated": [{"what": "at" |
/// "cusp" | "resonance_1_1" | ..., "value" (an `at` p), "reason", "near":
/// the path point}...] (points the curve passed whose location failed),
/// "termination", "time_s"}.
fn continue_bifurcation<'py>(py, args) [
    start: &Bound<'py, PyDict>,
    p_from: f64,
    p_to: f64,
    at: Vec<f64> = (Vec::new()),
    p_start: Option<f64> = None
] {
    let p_start = finite(
        "p_start",
        p_start.ok_or_else(|| PyValueError::new_err("argument `p_start` is required"))?,
    )?;
    let (kind, start) = given_start(start)?;
    let req = FoldCurveRequest {
        kind,
        start,
        p_start,
        p_from,
        p_to,
        at,
        steps: args.steps,
    };
    let fam = &args.family;
    let first = fam.first(py, p_start)?;
    crate::hb_shared::without_omega(&first.0, "continue_bifurcation")?;
    let curve = fam.run(py, first, |hb| jobs::fold_curve(|p| fam.build(p), hb, &req))?;
    to_dict(py, &curve)
}
}

/// The folds of the frequency response of the thesis Duffing (Eq. 49, ξ =
/// 0.02, α = ε = 1) followed in the force F (p = F) through the cusp where
/// the jump disappears: the dict of `ivt hb duffing-folds --json` (the same
/// job, defaults and tolerance 1e-10). The start is the fold of largest ω_f
/// on the FRC from `from_` to `to` at `force`; the curve goes from it first
/// towards `force_from`, then from it towards `force_to`, each leg until F
/// leaves [force_from, force_to]; the folds at each F of `at` are located
/// exactly, on every fold the curve crosses there. GIL released.
#[pyfunction]
#[pyo3(signature = (
    force = 0.1, force_from = 0.0, force_to = 0.3, at = vec![0.1, 0.2, 0.3], from_ = 0.5,
    to = 2.5, n = 20, samples = None, ds = None, ds_min = None, ds_max = None, max_points = None
))]
#[allow(clippy::too_many_arguments)]
fn duffing_folds<'py>(
    py: Python<'py>,
    force: f64,
    force_from: f64,
    force_to: f64,
    at: Vec<f64>,
    from_: f64,
    to: f64,
    #[pyo3(from_py_with = int64)] n: i64,
    #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = options(n, samples, 1, 1e-10)?;
    let req = FoldCurveRequest {
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
        start: FoldStart::Search { from: from_, to },
        p_start: finite("force", force)?,
        p_from: force_from,
        p_to: force_to,
        at,
        ..FoldCurveRequest::default()
    };
    let family = |f: f64| Ok(Duffing::new(0.02, 1.0, 1.0, f));
    let curve = run(py, || jobs::fold_curve(family, &opts, &req))?;
    to_dict(py, &curve)
}

/// Add `continue_bifurcation` and `duffing_folds` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [continue_bifurcation, duffing_folds]);
    Ok(())
}
