//! Large structures for `ivt.hb` (issue 28): the frequency response and the
//! single orbit of a sparse `M, C, K` with `g` on a few DOFs, condensed onto
//! those DOFs ([`ivt_condense`]), any DOF recovered per point, and the
//! cantilever model. The public wrappers in `ivt/hb.py` convert
//! `scipy.sparse`/dense matrices to COO triplets and `f` to load vectors.

use crate::hb_shared::{finite, run_user};
use crate::user_problem::{user_problem, PyProblem};
use ivt_condense::{
    condensed_response, CondensedBranch, CondensedFrc, CondensedFrcOptions, CondensedPoint,
    Structure,
};
use ivt_hb::{HbError, HbOptions};
use ivt_jobs::{pairs, Steps};
use ivt_kin::params::Typed;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

/// COO triplets `(rows, cols, values)` of one matrix.
type Coo = (Vec<usize>, Vec<usize>, Vec<f64>);

fn triplets(name: &str, coo: &Coo) -> PyResult<Vec<(usize, usize, f64)>> {
    let (r, c, v) = coo;
    if r.len() != c.len() || r.len() != v.len() {
        return Err(PyValueError::new_err(format!(
            "argument `{name}`: rows, cols and values must have one length"
        )));
    }
    Ok(r.iter()
        .zip(c)
        .zip(v)
        .map(|((&i, &j), &x)| (i, j, x))
        .collect())
}

/// The settings shared by `frc` and `solve` on a large structure.
struct Large<'py> {
    n_dof: usize,
    m: Coo,
    c: Coo,
    k: Coo,
    g: Bound<'py, PyAny>,
    jac: Option<Bound<'py, PyAny>>,
    load: (Vec<f64>, Vec<f64>),
    dofs: Vec<usize>,
    hb: HbOptions,
    velocity_dependent: bool,
    vectorized: bool,
}

impl<'py> Large<'py> {
    /// The settings of one call: matrices, `g` with its optional Jacobian,
    /// the loads, the nonlinear DOFs, HB sizes, `[velocity_dependent,
    /// vectorized]`.
    fn new(
        n_dof: usize,
        (m, c, k): (Coo, Coo, Coo),
        (g, jac): (Bound<'py, PyAny>, Option<Bound<'py, PyAny>>),
        load: (Vec<f64>, Vec<f64>),
        dofs: Vec<usize>,
        hb: HbOptions,
        [velocity_dependent, vectorized]: [bool; 2],
    ) -> Self {
        Self {
            n_dof,
            m,
            c,
            k,
            g,
            jac,
            load,
            dofs,
            hb,
            velocity_dependent,
            vectorized,
        }
    }

    /// The local problem (zero matrices on the nonlinear DOFs, `g`, no `f`)
    /// and the structure, or a Python error.
    fn build(&self, py: Python<'py>) -> PyResult<(Structure, PyProblem)> {
        let s = self.dofs.len();
        let structure = Structure::from_triplets(
            self.n_dof,
            &triplets("m", &self.m)?,
            &triplets("c", &self.c)?,
            &triplets("k", &self.k)?,
        )
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let flags = [self.velocity_dependent, self.vectorized];
        let local = local_problem(py, s, &self.g, self.jac.as_ref(), flags)?;
        Ok((structure, local))
    }

    /// Runs `solve` on the condensed branch of this structure with the GIL
    /// released ([`run_user`]: a callback's exception is the error).
    fn run<T: Send>(
        &self,
        py: Python<'py>,
        solve: impl FnOnce(&mut CondensedBranch<&PyProblem>) -> Result<T, HbError> + Send,
    ) -> PyResult<T> {
        let (structure, local) = self.build(py)?;
        let (dofs, load, hb) = (self.dofs.clone(), self.load.clone(), self.hb.clone());
        run_user(py, &local, move |p| {
            let mut branch = CondensedBranch::new(structure, dofs, &load.0, &load.1, p, &hb)?;
            solve(&mut branch)
        })
    }
}

/// The local problem of `s` nonlinear DOFs: zero matrices, `g` (with its
/// optional Jacobian `jac`), no `f`; `[velocity_dependent, vectorized]`.
pub(crate) fn local_problem<'py>(
    py: Python<'py>,
    s: usize,
    g: &Bound<'py, PyAny>,
    jac: Option<&Bound<'py, PyAny>>,
    [velocity_dependent, vectorized]: [bool; 2],
) -> PyResult<PyProblem> {
    let zeros = PyArray2::<f64>::zeros(py, [s, s], false).into_any();
    user_problem(
        &zeros,
        &zeros,
        &zeros,
        g,
        None,
        jac,
        velocity_dependent,
        vectorized,
    )
}

/// `n` harmonics, `samples` = N, relative tolerance `rtol`.
pub(crate) fn hb_options(n: usize, samples: usize) -> PyResult<HbOptions> {
    if n == 0 || samples <= n {
        return Err(PyValueError::new_err(format!(
            "need n ≥ 1 harmonics and samples > n, got n = {n}, samples = {samples}"
        )));
    }
    Ok(HbOptions::new(n, samples))
}

pub(crate) fn point_dict<'py>(py: Python<'py>, p: &CondensedPoint) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("omega", p.omega_f)?;
    d.set_item("amplitude", p.amplitude)?;
    d.set_item("coeffs", p.coeffs.clone().into_pyarray(py))?;
    let dofs = PyDict::new(py);
    for (j, c) in &p.dof_coeffs {
        dofs.set_item(j, c.clone().into_pyarray(py))?;
    }
    d.set_item("dof_coeffs", dofs)?;
    d.set_item("solve_error", p.solve_error)?;
    d.set_item("data_error", p.data_error)?;
    d.set_item("orbit_error", p.orbit_error)?;
    d.set_item("truncation_error", p.truncation_error)?;
    // Without the truncation estimate there is no whole estimate: None, not
    // the orbit error alone.
    d.set_item(
        "error_estimate",
        p.truncation_error.map(|t| p.orbit_error + t),
    )?;
    match &p.floquet {
        Some(f) => {
            d.set_item("multipliers", pairs(&f.floquet.multipliers))?;
            d.set_item("stable", f.floquet.stable())?;
            d.set_item("stability", f.floquet.kind.name())?;
            d.set_item("multiplier_error", f.error_estimate())?;
            d.set_item("stability_basis", f.basis)?;
        }
        None => {
            for key in ["multipliers", "stable", "stability", "multiplier_error"] {
                d.set_item(key, py.None())?;
            }
        }
    }
    Ok(d)
}

pub(crate) fn frc_dict<'py>(py: Python<'py>, frc: &CondensedFrc) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let points = PyList::empty(py);
    for p in &frc.points {
        points.append(point_dict(py, p)?)?;
    }
    let folds = PyList::empty(py);
    for f in &frc.events {
        let e = PyDict::new(py);
        e.set_item("omega", f.omega_f)?;
        e.set_item("amplitude", f.amplitude)?;
        e.set_item("coeffs", f.coeffs.clone().into_pyarray(py))?;
        e.set_item("located", f.located)?;
        e.set_item("index", f.index)?;
        folds.append(e)?;
    }
    d.set_item("points", points)?;
    d.set_item("folds", folds)?;
    d.set_item("termination", frc.termination.as_str())?;
    let omega: Vec<f64> = frc.points.iter().map(|p| p.omega_f).collect();
    let amplitude: Vec<f64> = frc.points.iter().map(|p| p.amplitude).collect();
    d.set_item("omega", omega.into_pyarray(py))?;
    d.set_item("amplitude", amplitude.into_pyarray(py))?;
    Ok(d)
}

/// The frequency response of a large structure condensed onto
/// `nonlinear_dofs` (private: `ivt.hb.frc` calls it for sparse matrices,
/// load-vector forcing, `nonlinear_dofs`, `amplitude_dof` or `record_dofs`).
/// `m, c, k`: `(rows, cols, values)` triplets of `n_dof × n_dof`; `f`:
/// `(F_cos, F_sin)`; `g(x, v, theta)` sees the nonlinear DOFs only.
#[pyfunction]
#[pyo3(signature = (
    n_dof, m, c, k, g, f, omega_from, omega_to, nonlinear_dofs, amplitude_dof = None,
    record_dofs = Vec::new(), n = 7, samples = 32, velocity_dependent = true,
    vectorized = false, rtol = 1e-12, jac = None, ds = None, ds_min = None, ds_max = None,
    max_points = None, truncation_estimate = true, stability = true
))]
#[allow(clippy::too_many_arguments)]
fn frc_large<'py>(
    py: Python<'py>,
    n_dof: usize,
    m: Coo,
    c: Coo,
    k: Coo,
    g: Bound<'py, PyAny>,
    f: (Vec<f64>, Vec<f64>),
    omega_from: f64,
    omega_to: f64,
    nonlinear_dofs: Vec<usize>,
    amplitude_dof: Option<usize>,
    record_dofs: Vec<usize>,
    n: usize,
    samples: usize,
    velocity_dependent: bool,
    vectorized: bool,
    rtol: f64,
    jac: Option<Bound<'py, PyAny>>,
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    max_points: Option<usize>,
    truncation_estimate: bool,
    stability: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (hb, flags) = (hb_options(n, samples)?, [velocity_dependent, vectorized]);
    let large = Large::new(n_dof, (m, c, k), (g, jac), f, nonlinear_dofs, hb, flags);
    let opts = frc_options(
        (omega_from, omega_to, rtol),
        (amplitude_dof, record_dofs),
        [truncation_estimate, stability],
        &Steps {
            ds,
            ds_min,
            ds_max,
            max_points,
        },
    )?;
    let frc = large.run(py, move |branch| condensed_response(branch, &opts))?;
    frc_dict(py, &frc)
}

/// The condensed sweep's options from the keywords of `frc`: `(from, to,
/// rtol)`, `(amplitude_dof, record_dofs)`, `[truncation_estimate,
/// stability]` and the continuation keywords.
pub(crate) fn frc_options(
    (omega_from, omega_to, rtol): (f64, f64, f64),
    (amplitude_dof, record_dofs): (Option<usize>, Vec<usize>),
    [truncation_estimate, stability]: [bool; 2],
    steps: &Steps,
) -> PyResult<CondensedFrcOptions> {
    let mut opts = CondensedFrcOptions {
        from: finite("omega_from", omega_from)?,
        to: finite("omega_to", omega_to)?,
        rtol: finite("rtol", rtol)?,
        amplitude_dof,
        record_dofs,
        truncation_estimate,
        stability_blocks: stability.then_some(ivt_condense::DEFAULT_BLOCKS),
        ..CondensedFrcOptions::default()
    };
    opts.continuation = crate::steps::on(steps, opts.continuation)?;
    Ok(opts)
}

pub(crate) fn positive(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "argument `{name}` must be > 0, got {}",
            Typed(v)
        )))
    }
}

/// One orbit of a large structure at `omega` (private: `ivt.hb.solve` calls
/// it as [`frc_large`]): Newton on the condensed system from the linear
/// response. Returns the point dict of [`frc_large`] ({"coeffs", "omega",
/// "amplitude", "dof_coeffs", "solve_error", "data_error", "orbit_error", "truncation_error",
/// "error_estimate", "multipliers", "stable", "stability",
/// "multiplier_error"}).
#[pyfunction]
#[pyo3(signature = (
    n_dof, m, c, k, g, f, omega, nonlinear_dofs, stability = true, rtol = 1e-12,
    jac = None, record_dofs = Vec::new(), amplitude_dof = None, vectorized = false,
    velocity_dependent = true, samples = 32, n = 7
))]
#[allow(clippy::too_many_arguments)]
fn solve_large<'py>(
    n_dof: usize,
    m: Coo,
    c: Coo,
    py: Python<'py>,
    k: Coo,
    g: Bound<'py, PyAny>,
    f: (Vec<f64>, Vec<f64>),
    omega: f64,
    nonlinear_dofs: Vec<usize>,
    stability: bool,
    rtol: f64,
    jac: Option<Bound<'py, PyAny>>,
    record_dofs: Vec<usize>,
    amplitude_dof: Option<usize>,
    vectorized: bool,
    velocity_dependent: bool,
    samples: usize,
    n: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let (hb, flags) = (hb_options(n, samples)?, [velocity_dependent, vectorized]);
    let large = Large::new(n_dof, (m, c, k), (g, jac), f, nonlinear_dofs, hb, flags);
    let omega = positive("omega", finite("omega", omega)?)?;
    let rtol = positive("rtol", rtol)?;
    let point = large.run(py, move |branch| {
        // A curve of one point: the start at ω, corrected at fixed ω.
        let opts = CondensedFrcOptions {
            from: omega,
            to: omega * (1.0 + 1e-9),
            rtol,
            amplitude_dof,
            record_dofs,
            truncation_estimate: true,
            stability_blocks: stability.then_some(ivt_condense::DEFAULT_BLOCKS),
            stability_tol: ivt_condense::DEFAULT_BASIS_TOL,
            continuation: ivt_hb::ContinuationOptions {
                max_points: 1,
                ..CondensedFrcOptions::default().continuation
            },
        };
        let frc = condensed_response(branch, &opts)?;
        frc.points
            .into_iter()
            .next()
            .ok_or_else(|| HbError::InvalidInput("no orbit".into()))
    })?;
    point_dict(py, &point)
}

/// The cantilever of issue 28 as COO triplets: `(n_dof, (m, c, k), tip)`
/// with each matrix `(rows, cols, values)` (private: `ivt.hb.models.cantilever`
/// builds scipy.sparse matrices from it).
#[pyfunction]
#[pyo3(signature = (n_elements, length = 1.0, ei = 1.0, rho_a = 1.0, alpha = 0.07, beta = 2e-4))]
fn cantilever_coo<'py>(
    py: Python<'py>,
    n_elements: usize,
    length: f64,
    ei: f64,
    rho_a: f64,
    alpha: f64,
    beta: f64,
) -> PyResult<Bound<'py, PyTuple>> {
    let props = ivt_condense::models::BeamProperties {
        length,
        ei,
        rho_a,
        alpha,
        beta,
    };
    let beam = ivt_condense::models::cantilever(n_elements, &props)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    model_coo(py, &beam.model, beam.tip)
}

/// pyHarm's 24-sector bladed disk of issue 28 as COO triplets, `(n_dof,
/// (m, c, k), tip)` as [`cantilever_coo`]; `blade_stiffness` (24 factors, one
/// per sector's blade springs; None: the tuned disk) mistunes it (private:
/// `ivt.hb.models.bladed_disk`).
#[pyfunction]
#[pyo3(signature = (blade_stiffness = None))]
fn bladed_disk_coo<'py>(
    py: Python<'py>,
    blade_stiffness: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let disk = match blade_stiffness {
        Some(factors) => ivt_condense::models::bladed_disk_mistuned(&factors),
        None => ivt_condense::models::bladed_disk(),
    }
    .map_err(|e| PyValueError::new_err(e.to_string()))?;
    model_coo(py, &disk.model, disk.tip)
}

/// `(n_dof, (m, c, k), dof)` with each matrix `(rows, cols, values)` arrays.
fn model_coo<'py>(
    py: Python<'py>,
    model: &ivt_condense::models::SparseModel,
    dof: usize,
) -> PyResult<Bound<'py, PyTuple>> {
    let mats = model.triplets().map(|t| {
        let rows: Vec<usize> = t.iter().map(|e| e.0).collect();
        let cols: Vec<usize> = t.iter().map(|e| e.1).collect();
        let vals: Vec<f64> = t.iter().map(|e| e.2).collect();
        (
            rows.into_pyarray(py),
            cols.into_pyarray(py),
            vals.into_pyarray(py),
        )
    });
    (model.n_dof(), mats, dof).into_pyobject(py)
}

/// Register the large-structure functions on `ivt._ivt.hb`.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    hb.add_function(wrap_pyfunction!(frc_large, hb)?)?;
    hb.add_function(wrap_pyfunction!(solve_large, hb)?)?;
    hb.add_function(wrap_pyfunction!(cantilever_coo, hb)?)?;
    hb.add_function(wrap_pyfunction!(bladed_disk_coo, hb)?)?;
    Ok(())
}
