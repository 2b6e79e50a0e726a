//! `ivt.hb.cycle_branch` (issue 27, item 2): the Hopf points of an
//! autonomous user family and the limit-cycle branch born at the first
//! (the job [`ivt_jobs::cycle_branch()`] of `ivt hb cycle-branch`);
//! `ivt.hb.neimark_sacker_points`, the sampled Neimark–Sacker boundary of a forced family
//! ([`ivt_jobs::neimark_sacker_points`]), on a Python `family(p)` ([`PyFamily`]).

use ivt_jobs::{self as jobs, pairs, CycleBranchRequest};
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::count;
use crate::hb_family::PyFamily;
use crate::hb_shared::{finite, HbKeys};
use crate::to_python::to_dict;

/// Hopf points and the limit-cycle branch of the autonomous family
/// `family(p)` → (m, c, k, g, f) (f None) for p in [p_from, p_to]
/// (ivt_hb::branches::cycle_branch): the equilibria (from x = 0) are followed on
/// `grid` intervals of p, a Hopf point is where two complex eigenvalues
/// cross the imaginary axis (bisection), with its first Lyapunov coefficient
/// ("lyapunov" > 0: subcritical, the cycles born there are unstable). The
/// cycle branch starts from the first Hopf point's normal form at a distance
/// `offset`·|p_to − p_from| and is followed (HB with ω unknown,
/// pseudo-arclength) with Floquet stability at every point; its folds are
/// located on the fold system; the cycles at each p of `at` are solved
/// exactly. A Hopf point is only where a complex pair crosses (a pair turning
/// real is none); stretches the search could not decide are in
/// "hopf_undecided" ([{"p_from", "p_to", "reason"}]). A forced family (f
/// not zero, or g depending on θ) raises ValueError, as does a member that
/// fails along the branch (the family's exception, another size, g NaN).
/// Returns {"hopf": [{"p", "omega", "lyapunov", "subcritical"}...], "hopf_undecided",
/// "points": [{"p", "omega", "period", "amplitude", "stable", "stability",
/// "multipliers", "coeffs"}...], "bifurcations": [{"kind": "fold", "p",
/// "omega", "amplitude", "coeffs"}...], "at": [cycles as in points],
/// "unlocated": [{"what" ("fold" or "at"), "value" (an at value), "reason",
/// "near": {"omega", "p", "amplitude", "coeffs"}}...] (a fold or at cycle the
/// branch passed but that could not be located, with the path point the
/// solve started from; none is dropped), "termination" (None when there is
/// no Hopf point)}.
#[pyfunction]
#[pyo3(signature = (
    family, p_from, p_to, at = Vec::new(), n = 20, samples = None,
    velocity_dependent = true, vectorized = false, grid = 100, rtol = 1e-9, max_iter = 100,
    ds = None, ds_min = None, ds_max = None, max_points = None, offset = 1e-2
))]
#[allow(clippy::too_many_arguments)]
fn cycle_branch<'py>(
    py: Python<'py>,
    family: &Bound<'py, PyAny>,
    p_from: f64,
    p_to: f64,
    at: Vec<f64>,
    #[pyo3(from_py_with = crate::args::int64)] n: i64,
    #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
    velocity_dependent: bool,
    vectorized: bool,
    #[pyo3(from_py_with = crate::args::int64)] grid: i64,
    rtol: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_iter: i64,
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
    offset: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (p_from, p_to) = (finite("p_from", p_from)?, finite("p_to", p_to)?);
    if p_from == p_to {
        return Err(PyValueError::new_err(
            "arguments `p_from` and `p_to` must differ",
        ));
    }
    let req = CycleBranchRequest {
        p_from,
        p_to,
        at,
        grid: count("grid", grid)?,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
        offset,
    };
    let keys = HbKeys::new(n, samples, velocity_dependent, vectorized, rtol, max_iter)?;
    let fam = PyFamily::new(family, keys);
    let first = fam.first(py, p_from)?;
    crate::hb_shared::without_omega(&first.0, "cycle_branch")?;
    let branch = fam.run(py, first, |hb| {
        jobs::cycle_branch(|p| fam.build(p), hb, &req)
    })?;
    to_dict(py, &branch)
}

/// The Neimark–Sacker boundary of the forced family `family(p)` → (m, c, k,
/// g, f) in (omega, p), sampled (ivt_jobs::neimark_sacker_points): at each p of
/// `ps` the frequency response from `omega_from` to `omega_to` is traced
/// with its events, and each Neimark–Sacker point located on its extended
/// system. Not a continuation: a turn of the boundary in p between samples is
/// not followed. `ds`, `ds_min`, `ds_max`, `max_points`: each response's
/// steps (None: those of `frc`). Returns [{"p", "omega", "coeffs",
/// "multipliers"}...] in order of `ps`.
#[pyfunction]
#[pyo3(signature = (
    family, ps, omega_from, omega_to, n = 20, samples = None, rtol = 1e-9, max_iter = 100,
    velocity_dependent = true, vectorized = false, ds = None, ds_min = None, ds_max = None,
    max_points = None
))]
#[allow(clippy::too_many_arguments)]
fn neimark_sacker_points<'py>(
    py: Python<'py>,
    family: &Bound<'py, PyAny>,
    ps: Vec<f64>,
    omega_from: f64,
    omega_to: f64,
    #[pyo3(from_py_with = crate::args::int64)] n: i64,
    #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
    rtol: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_iter: i64,
    velocity_dependent: bool,
    vectorized: bool,
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
) -> PyResult<Bound<'py, PyList>> {
    let (from, to) = (
        finite("omega_from", omega_from)?,
        finite("omega_to", omega_to)?,
    );
    let first_p = ps.first().copied();
    let (Some(p0), true) = (first_p, from > 0.0 && to > 0.0 && from != to) else {
        return Err(PyValueError::new_err(
            "arguments `omega_from`, `omega_to` must be > 0 and distinct, `ps` not empty",
        ));
    };
    let steps = crate::steps::steps(ds, ds_min, ds_max, max_points)?;
    let sweep = crate::steps::sweep(from, to, &steps)?;
    let keys = HbKeys::new(n, samples, velocity_dependent, vectorized, rtol, max_iter)?;
    let fam = PyFamily::new(family, keys);
    let first = fam.first(py, finite("ps[0]", p0)?)?;
    let points = fam.run(py, first, |hb| {
        ivt_jobs::neimark_sacker_points(|p| fam.build(p), hb, &sweep, &ps)
    })?;
    let list = PyList::empty(py);
    for pt in points {
        let d = PyDict::new(py);
        d.set_item("p", pt.p)?;
        d.set_item("omega", pt.omega)?;
        d.set_item("coeffs", pt.coeffs.into_pyarray(py))?;
        d.set_item("multipliers", pairs(&pt.multipliers))?;
        list.append(d)?;
    }
    Ok(list)
}

/// Add `cycle_branch` and `neimark_sacker_points` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [cycle_branch, neimark_sacker_points]);
    Ok(())
}
