//! `ivt.hb.cycle_branch` (issue 27, item 2): the Hopf points of an
//! autonomous user family and the limit-cycle branch born at the first
//! (the job [`ivt_hb::jobs::cycle_branch()`] of `ivt hb cycle-branch`);
//! `ivt.hb.neimark_sacker_points`, the sampled Neimark–Sacker boundary of a forced family
//! ([`ivt_hb::neimark_sacker_points`]); and [`PyFamily`], a Python `family(p)` as the
//! fallible Rust family of ivt-hb's two-parameter functions.

use ivt_hb::jobs::{self, CycleBranchRequest};
use ivt_hb::{HbError, HbOptions};
use numpy::IntoPyArray;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::Mutex;

use crate::args::count;
use crate::hb_shared::{finite, run_user, UserArgs};
use crate::to_python::to_dict;
use crate::user_problem::{user_problem, PyProblem};
use ivt_hb::jobs::pairs;

/// The user system `family(p)` returns: a tuple (m, c, k, g, f).
pub(crate) fn family_system<'py>(
    family: &Bound<'py, PyAny>,
    p: f64,
) -> PyResult<[Bound<'py, PyAny>; 5]> {
    let wrong = || PyTypeError::new_err("argument `family` must return a tuple (m, c, k, g, f)");
    let parts: Vec<Bound<'py, PyAny>> = family.call1((p,))?.extract().map_err(|_| wrong())?;
    parts.try_into().map_err(|_| wrong())
}

/// A Python `family(p)` → (m, c, k, g, f) as a fallible family of user
/// systems; the first exception it raised is kept ([`Self::take_error`]).
pub(crate) struct PyFamily {
    family: Py<PyAny>,
    velocity_dependent: bool,
    vectorized: bool,
    failure: Mutex<Option<PyErr>>,
}

impl PyFamily {
    pub(crate) fn new(
        family: &Bound<'_, PyAny>,
        velocity_dependent: bool,
        vectorized: bool,
    ) -> Self {
        Self {
            family: family.clone().unbind(),
            velocity_dependent,
            vectorized,
            failure: Mutex::new(None),
        }
    }

    /// The user system at `p` (`f` None: unforced).
    pub(crate) fn build(&self, p: f64) -> Result<PyProblem, HbError> {
        Python::attach(|py| {
            let [m, c, k, g, f] = family_system(self.family.bind(py), p)?;
            let f = (!f.is_none()).then_some(&f);
            user_problem(
                &m,
                &c,
                &k,
                &g,
                f,
                None,
                self.velocity_dependent,
                self.vectorized,
            )
        })
        .map_err(|e| {
            let message = e.to_string();
            self.keep_error(e);
            HbError::InvalidInput(format!("family(p) failed: {message}"))
        })
    }

    /// Keep `e` as the family's exception unless one is kept already.
    pub(crate) fn keep_error(&self, e: PyErr) {
        if let Ok(mut slot) = self.failure.lock() {
            slot.get_or_insert(e);
        }
    }

    /// This family, taken as `family(mu, p)`, with its first argument fixed
    /// at `mu` by `partial` (`functools.partial`): a one-parameter family
    /// with the same flags and an error slot of its own.
    pub(crate) fn with_first(&self, partial: &Bound<'_, PyAny>, mu: f64) -> PyResult<PyFamily> {
        let one = partial.call1((self.family.bind(partial.py()), mu))?;
        Ok(Self::new(&one, self.velocity_dependent, self.vectorized))
    }

    /// The first exception `family` raised, if any.
    pub(crate) fn take_error(&self) -> Option<PyErr> {
        self.failure.lock().ok().and_then(|mut s| s.take())
    }

    /// Run `job` with the HB options of `first` (from [`Self::first`]) with
    /// the GIL released, as [`run_user`] on the first user system; then the
    /// first exception `family` raised, if any, is the error (it caused the
    /// job's failure), else the job's own result.
    pub(crate) fn run<T: Send>(
        &self,
        py: Python<'_>,
        first: (PyProblem, HbOptions),
        job: impl FnOnce(&HbOptions) -> Result<T, HbError> + Send,
    ) -> PyResult<T> {
        let (problem, hb) = first;
        let result = run_user(py, &problem, |_| job(&hb));
        if let Some(e) = self.take_error() {
            return Err(e);
        }
        result
    }

    /// The user system at `p` and HB options from the shared keywords.
    pub(crate) fn first(
        &self,
        py: Python<'_>,
        p: f64,
        n: i64,
        samples: i64,
        rtol: f64,
        max_iter: i64,
    ) -> PyResult<(PyProblem, HbOptions)> {
        let [m, c, k, g, f] = family_system(self.family.bind(py), p)?;
        let user = UserArgs {
            system: [&m, &c, &k, &g],
            n,
            samples,
            velocity_dependent: self.velocity_dependent,
            vectorized: self.vectorized,
            rtol,
            max_iter: crate::args::count("max_iter", max_iter)?,
            jac: None,
        };
        user.setup((!f.is_none()).then_some(&f), 1, 0.0)
    }
}

/// Hopf points and the limit-cycle branch of the autonomous family
/// `family(p)` → (m, c, k, g, f) (f None) for p in [p_from, p_to]
/// (ivt_hb::cycle_branch): the equilibria (from x = 0) are followed on
/// `grid` intervals of p, a Hopf point is where two complex eigenvalues
/// cross the imaginary axis (bisection), with its first Lyapunov coefficient
/// ("lyapunov" > 0: subcritical, the cycles born there are unstable). The
/// cycle branch starts from the first Hopf point's normal form at a distance
/// `offset`·|p_to − p_from| and is followed (HB with ω unknown,
/// pseudo-arclength) with Floquet stability at every point; its folds are
/// located on the fold system; the cycles at each p of `at` are solved
/// exactly. Returns {"hopf": [{"p", "omega", "lyapunov", "subcritical"}...],
/// "points": [{"p", "omega", "period", "amplitude", "stable", "stability",
/// "multipliers", "coeffs"}...], "bifurcations": [{"kind": "fold", "p",
/// "omega", "amplitude", "coeffs"}...], "at": [cycles as in points],
/// "termination" (None when there is no Hopf point)}.
#[pyfunction]
#[pyo3(signature = (
    family, p_from, p_to, at = Vec::new(), n = 20, samples = 64,
    velocity_dependent = true, vectorized = false, grid = 100, rtol = 1e-9, max_iter = 100,
    ds = 0.02, ds_max = 0.05, max_points = 2000, offset = 1e-2
))]
#[allow(clippy::too_many_arguments)]
fn cycle_branch<'py>(
    py: Python<'py>,
    family: &Bound<'py, PyAny>,
    p_from: f64,
    p_to: f64,
    at: Vec<f64>,
    #[pyo3(from_py_with = crate::args::int64)] n: i64,
    #[pyo3(from_py_with = crate::args::int64)] samples: i64,
    velocity_dependent: bool,
    vectorized: bool,
    #[pyo3(from_py_with = crate::args::int64)] grid: i64,
    rtol: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_iter: i64,
    ds: f64,
    ds_max: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_points: i64,
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
        ds,
        ds_max,
        max_points: count("max_points", max_points)?,
        offset,
    };
    let fam = PyFamily::new(family, velocity_dependent, vectorized);
    let first = fam.first(py, p_from, n, samples, rtol, max_iter)?;
    let branch = fam.run(py, first, |hb| {
        jobs::cycle_branch(|p| fam.build(p), hb, &req)
    })?;
    to_dict(py, &branch)
}

/// The Neimark–Sacker boundary of the forced family `family(p)` → (m, c, k,
/// g, f) in (omega, p), sampled (ivt_hb::neimark_sacker_points): at each p of
/// `ps` the frequency response from `omega_from` to `omega_to` is traced
/// with its events, and each Neimark–Sacker point located on its extended
/// system. Not a continuation: a turn of the boundary in p between samples is
/// not followed. Returns [{"p", "omega", "coeffs", "multipliers"}...] in
/// order of `ps`.
#[pyfunction]
#[pyo3(signature = (
    family, ps, omega_from, omega_to, n = 20, samples = 64, rtol = 1e-9, max_iter = 100,
    velocity_dependent = true, vectorized = false
))]
#[allow(clippy::too_many_arguments)]
fn neimark_sacker_points<'py>(
    py: Python<'py>,
    family: &Bound<'py, PyAny>,
    ps: Vec<f64>,
    omega_from: f64,
    omega_to: f64,
    #[pyo3(from_py_with = crate::args::int64)] n: i64,
    #[pyo3(from_py_with = crate::args::int64)] samples: i64,
    rtol: f64,
    #[pyo3(from_py_with = crate::args::int64)] max_iter: i64,
    velocity_dependent: bool,
    vectorized: bool,
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
    let fam = PyFamily::new(family, velocity_dependent, vectorized);
    let first = fam.first(py, finite("ps[0]", p0)?, n, samples, rtol, max_iter)?;
    let points = fam.run(py, first, |hb| {
        ivt_hb::neimark_sacker_points(|p| fam.build(p), hb, from, to, &ps)
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
