//! Large solids for `ivt.hb.frc` (issue 42): the structure reduced once onto
//! a certified basis ([`ivt_condense::reduce`]), the condensed path run
//! on the reduced model, the stability decided with the reduction's effect
//! on the multipliers. The wrapper in `ivt/hb.py` chooses this path or the
//! exact one of `hb_large.rs` (`reduction=`) and passes the matrices as
//! numpy COO arrays.

use crate::hb_large::{frc_dict, frc_options, hb_options, local_problem, positive};
use crate::hb_shared::{finite, run_user};
use crate::to_python::to_dict;
use faer::sparse::{SparseColMat, Triplet};
use ivt_condense::reduce::basis::Operators;
use ivt_condense::reduce::{reduced_response, ReducedModel, ReductionOptions};
use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// One matrix as numpy COO arrays `(rows, cols, values)`.
type CooArrays<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

/// The sparse `n×n` matrix `name` of COO arrays (duplicates summed).
fn sparse(name: &str, n: usize, coo: &CooArrays<'_>) -> PyResult<SparseColMat<usize, f64>> {
    let (rows, cols, vals) = (coo.0.as_array(), coo.1.as_array(), coo.2.as_array());
    if rows.len() != cols.len() || rows.len() != vals.len() {
        return Err(PyValueError::new_err(format!(
            "argument `{name}`: rows, cols and values must have one length"
        )));
    }
    let index = |i: i64| usize::try_from(i).ok().filter(|&i| i < n);
    let mut triplets = Vec::with_capacity(rows.len());
    for ((&i, &j), &v) in rows.iter().zip(cols.iter()).zip(vals.iter()) {
        match (index(i), index(j)) {
            (Some(row), Some(col)) if v.is_finite() => triplets.push(Triplet { row, col, val: v }),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "argument `{name}`: entry ({i}, {j}) = {v} is out of range for {n} DOFs or not finite"
                )))
            }
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| PyValueError::new_err(format!("argument `{name}`: {e:?}")))
}

/// The frequency response of a large solid reduced onto a certified basis
/// (private: `ivt.hb.frc` calls it for `reduction="krylov"`, or "auto" on a
/// model that is not narrow-banded). Returns the dict of the exact path
/// with, per point, "multiplier_error" (the reduced model's estimate plus the
/// reduction's effect on max |μ|, "reduction_multiplier_error"), "stability"
/// ("uncertain" where max |μ| lies within it of 1; "stable" then None), and
/// "method": "reduced", "reduction": {method, n_dof, basis, blocks, modes,
/// cutoff, first_frequency, error_estimate, nested_change, sampled}.
#[pyfunction]
#[pyo3(signature = (
    n_dof, m, c, k, g, f, omega_from, omega_to, nonlinear_dofs, amplitude_dof = None,
    record_dofs = Vec::new(), n = 7, samples = 32, velocity_dependent = true,
    vectorized = false, rtol = 1e-12, jac = None, ds = None, ds_min = None, ds_max = None,
    max_points = None, truncation_estimate = true, stability = true, reduction_tol = 1e-8,
    reduction_samples = 3
))]
#[allow(clippy::too_many_arguments)]
fn frc_reduced<'py>(
    py: Python<'py>,
    n_dof: usize,
    m: CooArrays<'py>,
    c: CooArrays<'py>,
    k: CooArrays<'py>,
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
    reduction_tol: f64,
    reduction_samples: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let hb = hb_options(n, samples)?;
    let opts = frc_options(
        (omega_from, omega_to, rtol),
        (amplitude_dof, record_dofs),
        [truncation_estimate, stability],
        &ivt_jobs::Steps {
            ds,
            ds_min,
            ds_max,
            max_points,
        },
    )?;
    let matrices = (
        sparse("m", n_dof, &m)?,
        sparse("c", n_dof, &c)?,
        sparse("k", n_dof, &k)?,
    );
    let flags = [velocity_dependent, vectorized];
    let local = local_problem(py, nonlinear_dofs.len(), &g, jac.as_ref(), flags)?;
    let reduction = ReductionOptions {
        band: (opts.from, opts.to),
        harmonics: n,
        subharmonic: 1,
        tol: positive("reduction_tol", finite("reduction_tol", reduction_tol)?)?,
        samples: reduction_samples,
        ..ReductionOptions::default()
    };
    let (load_cos, load_sin) = f;
    let (frc, report) = run_user(py, &local, move |p| {
        let (mm, cc, kk) = &matrices;
        let ops = Operators {
            m: mm.as_ref(),
            c: cc.as_ref(),
            k: kk.as_ref(),
        };
        let model = ReducedModel::new(ops, &nonlinear_dofs, &load_cos, &load_sin, &reduction)?;
        let frc = reduced_response(&model, p, &hb, &opts)?;
        Ok((frc, model.report().clone()))
    })?;
    let d = frc_dict(py, &frc.frc)?;
    if let Some(points) = d.get_item("points")? {
        let points = points.cast_into::<PyList>()?;
        for (point, st) in points.iter().zip(&frc.stability) {
            let (Ok(point), Some(st)) = (point.cast_into::<PyDict>(), st) else {
                continue;
            };
            point.set_item("multiplier_error", st.multiplier_error)?;
            point.set_item("reduction_multiplier_error", st.reduction_error)?;
            point.set_item("stability", st.verdict.name())?;
            point.set_item("stable", st.verdict.stable())?;
        }
    }
    d.set_item("method", "reduced")?;
    d.set_item("reduction", to_dict(py, &report)?)?;
    Ok(d)
}

/// Register the reduced large-structure path on `ivt._ivt.hb`.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    hb.add_function(wrap_pyfunction!(frc_reduced, hb)?)
}
