//! `ivt.hb.cycle_fold_curve` (issue 27, item 1): a fold of limit cycles of an
//! autonomous user family `family(mu, nu)` followed in ν, started from the
//! first fold of the cycle branch in μ at ν = `nu_from`: the job
//! [`ivt_jobs::cycle_fold_curve`] on the Python family.

use ivt_hb::branches::codim2::CycleFoldPoint;
use ivt_hb::{HbError, HbSolution};
use ivt_jobs::CycleFoldRequest;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::hb_family::{family_fn, PyFamily};
use crate::hb_shared::hb_err;

/// `family(mu, nu)` as the one-parameter [`PyFamily`] `partial(family, mu)`
/// of ν; the first exception it raised is kept in the slot of `family`.
struct PyFamily2<'a> {
    family: &'a PyFamily,
    partial: Py<PyAny>,
}

impl PyFamily2<'_> {
    fn at_mu(&self, py: Python<'_>, mu: f64) -> PyResult<PyFamily> {
        self.family.with_first(self.partial.bind(py), mu)
    }

    fn build(&self, mu: f64, nu: f64) -> Result<crate::user_problem::PyProblem, HbError> {
        let fam = Python::attach(|py| self.at_mu(py, mu))
            .map_err(|e| HbError::InvalidInput(format!("family failed: {e}")))?;
        fam.build(nu).inspect_err(|_| {
            if let Some(e) = fam.take_error() {
                self.family.keep_error(e);
            }
        })
    }
}

/// One fold as {"mu", "nu", "omega", "amplitude", "coeffs"} (`n` harmonics).
fn point_dict<'py>(py: Python<'py>, pt: &CycleFoldPoint, n: usize) -> PyResult<Bound<'py, PyDict>> {
    let orbit = HbSolution {
        coeffs: pt.fold.coeffs.clone(),
        omega_f: pt.fold.omega,
        harmonics: n,
        subharmonic: 1,
        stats: Default::default(),
    };
    let d = PyDict::new(py);
    d.set_item("mu", pt.mu)?;
    d.set_item("nu", pt.fold.p)?;
    d.set_item("omega", pt.fold.omega)?;
    d.set_item("amplitude", orbit.amplitude(0))?;
    d.set_item("coeffs", pt.fold.coeffs.clone().into_pyarray(py))?;
    Ok(d)
}

family_fn! {
/// The fold of limit cycles of the autonomous family `family(mu, nu)` →
/// (m, c, k, g, None) followed in ν from `nu_from` towards `nu_to`
/// (ivt_hb::branches::codim2::cycle_fold_curve: the cycle equations with ω unknown and
/// the phase condition, plus a unit null vector of their Jacobian in (q, ω),
/// pseudo-arclength in ν, μ solved along). The start is the first fold of
/// the cycle branch of `family(mu, nu_from)` for mu in [mu_from, mu_to]
/// (as `cycle_branch`). The folds at each ν of `at` are solved exactly.
/// Returns {"points": [{"mu", "nu", "omega", "amplitude", "coeffs"}...],
/// "at": [...], "special": [{"kind": "cusp", ...}...] (turning points in
/// ν, located as the fold of the curve), "unlocated": [{"what": "at" |
/// "cusp", "value" (an `at` ν), "reason", "near": the path point}...] (points
/// the curve passed whose location failed), "termination"}.
fn cycle_fold_curve<'py>(py, args) [
    nu_from: f64,
    nu_to: f64,
    mu_from: f64,
    mu_to: f64,
    at: Vec<f64> = (Vec::new())
] {
    let req = CycleFoldRequest {
        nu_from,
        nu_to,
        mu_from,
        mu_to,
        at,
        steps: args.steps,
    };
    req.validate().map_err(|e| hb_err(py, e))?;
    let fam = PyFamily2 {
        family: &args.family,
        partial: py.import("functools")?.getattr("partial")?.unbind(),
    };
    // The user system at (mu_from, nu_from) sets the HB options.
    let first = fam.at_mu(py, mu_from)?.first(py, nu_from)?;
    let harmonics = first.1.harmonics;
    let curve = fam.family.run(py, first, |hb| {
        ivt_jobs::cycle_fold_curve(|mu: f64, nu: f64| fam.build(mu, nu), hb, &req)
    })?;
    let list = |pts: &[CycleFoldPoint]| -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for pt in pts {
            list.append(point_dict(py, pt, harmonics)?)?;
        }
        Ok(list)
    };
    let special = list(&curve.cusps)?;
    for d in special.iter() {
        d.set_item("kind", "cusp")?;
    }
    let out = PyDict::new(py);
    out.set_item("points", list(&curve.points)?)?;
    out.set_item("at", list(&curve.at)?)?;
    out.set_item("special", special)?;
    let unlocated = PyList::empty(py);
    for u in &curve.unlocated {
        let d = PyDict::new(py);
        d.set_item("what", u.what)?;
        if let Some(v) = u.value {
            d.set_item("value", v)?;
        }
        d.set_item("reason", &u.reason)?;
        d.set_item("near", point_dict(py, &u.near, harmonics)?)?;
        unlocated.append(d)?;
    }
    out.set_item("unlocated", unlocated)?;
    out.set_item("termination", curve.termination.as_str())?;
    Ok(out)
}
}

/// Add `cycle_fold_curve` to the `hb` module.
pub fn register(hb: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(hb, [cycle_fold_curve]);
    Ok(())
}
