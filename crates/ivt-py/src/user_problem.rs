//! User systems for `ivt.hb`: `M x'' + C x' + K x + g(x, v, θ) = f(θ)` with `g`
//! and `f` Python callables (per sample, or vectorized over all AFT samples).
//! `g` may instead be a composition of ivt-hb's Rust elements
//! ([`crate::hb_elements::Elements`]): then no Python runs in the loop. The
//! system is an ivt-hb [`GeneralProblem`]; this module adds the Python calls
//! and the capture of the first exception a callback raised. An optional
//! Python `jac` ([`PyJacobian`]) replaces the differences of a Python `g`;
//! elements bring their own analytic Jacobian. `g` and `f` may read the
//! excitation frequency: a parameter named `omega` in their signature gets ω_f
//! as a keyword (ivt-hb's frequency-dependent models, [`reads_omega`]).

use crate::callback_arrays::{float_array, SampleArrays};
use crate::error_slot::{failed, record, ErrorSlot};
use crate::hb_elements::Elements;
use crate::user_jacobian::PyJacobian;
use ivt_hb::problem::{per_sample, Nonlinearity};
use ivt_hb::{ElementProblem, Excitation, GeneralProblem, HbOptions, PeriodicProblem};
use numpy::{IntoPyArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::Arc;

/// The excitation `f(θ)` or `f(θ, omega=ω_f)` of a user system (a Python
/// callable or none) and the error slot.
pub(crate) struct PyExcitation {
    f: Option<Py<PyAny>>,
    omega: bool,
    error: ErrorSlot,
}

impl Excitation for PyExcitation {
    fn eval(&self, theta: f64, out: &mut [f64]) {
        self.eval_with(theta, None, out)
    }
    fn eval_at(&self, theta: f64, omega_f: f64, out: &mut [f64]) {
        self.eval_with(theta, Some(omega_f), out)
    }
    fn frequency_dependent(&self) -> bool {
        self.omega
    }
}

impl PyExcitation {
    /// `f(θ)`, with `omega=ω_f` when `f` reads it (NaN and an error without ω_f).
    fn eval_with(&self, theta: f64, omega_f: Option<f64>, out: &mut [f64]) {
        let Some(f) = &self.f else {
            return out.fill(0.0);
        };
        let omega = self.omega.then_some(omega_f);
        call_into(
            "the value of `f`",
            &self.error,
            f,
            |py| pyo3::types::PyTuple::new(py, [theta]),
            omega,
            out,
        )
    }
}

/// The excitation frequency a callback that reads `omega` is given:
/// `None` when it does not read it, `Some(None)` when it does but the caller
/// has no ω_f (an error: only `frc` and `solve` pass it).
type OmegaArg = Option<Option<f64>>;

/// Whether the callable has a parameter named `omega` (then it is called with
/// `omega=ω_f`); `false` when its signature cannot be read.
fn reads_omega(func: &Bound<'_, PyAny>) -> bool {
    let py = func.py();
    py.import("inspect")
        .and_then(|m| m.call_method1("signature", (func,)))
        .and_then(|sig| sig.getattr("parameters"))
        .and_then(|params| params.contains("omega"))
        .unwrap_or(false)
}

/// `omega=ω_f` as keywords, or the error of a callback that reads `omega`
/// called where there is no excitation frequency.
fn omega_kwargs(
    py: Python<'_>,
    omega: OmegaArg,
) -> PyResult<Option<Bound<'_, pyo3::types::PyDict>>> {
    match omega {
        None => Ok(None),
        Some(None) => Err(PyValueError::new_err(
            "a callback reads `omega`, but this function has no excitation frequency \
             (only `frc` and `solve` pass omega)",
        )),
        Some(Some(w)) => {
            let kw = pyo3::types::PyDict::new(py);
            kw.set_item("omega", w)?;
            Ok(Some(kw))
        }
    }
}

/// The nonlinearity of a user system: a Python callable (with its Python
/// Jacobian, if given), or Rust elements (an [`ElementProblem`] without
/// forcing, evaluated with no Python call, with its analytic Jacobian), and the
/// slot of the first exception raised by `g`, `jac` or `f`.
pub(crate) struct UserG {
    law: UserLaw,
    error: ErrorSlot,
}

enum UserLaw {
    Python(PyNonlinearity, Option<PyJacobian>),
    Elements(ElementProblem),
}

impl Nonlinearity for UserG {
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        match &self.law {
            UserLaw::Python(g, _) => g.eval(x, v, theta, out),
            UserLaw::Elements(e) => e.nonlinear(x, v, theta, out),
        }
    }
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        match &self.law {
            UserLaw::Python(g, _) => g.eval_samples(x, v, theta, out),
            UserLaw::Elements(e) => e.nonlinear_samples(x, v, theta, out),
        }
    }
    fn jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) -> bool {
        match &self.law {
            UserLaw::Python(_, Some(jac)) => jac.eval_samples(x, v, theta, dg),
            UserLaw::Python(_, None) => return false,
            UserLaw::Elements(e) => e.nonlinear_jacobian_samples(x, v, theta, dg),
        }
        true
    }
    fn frequency_dependent(&self) -> bool {
        matches!(&self.law, UserLaw::Python(g, _) if g.omega)
    }
    fn hysteretic(&self) -> bool {
        matches!(&self.law, UserLaw::Elements(e) if e.hysteretic())
    }
    fn eval_samples_at(&self, x: &[f64], v: &[f64], theta: &[f64], w: f64, out: &mut [f64]) {
        match &self.law {
            UserLaw::Python(g, _) => g.eval_with(x, v, theta, Some(w), out),
            UserLaw::Elements(e) => e.nonlinear_samples(x, v, theta, out),
        }
    }
}

/// A user system: the ivt-hb general problem (∂g from `jac` or the elements,
/// else by central differences over all samples at once, steps relative to the
/// orbit) with `g` a Python callable or Rust elements and `f` a Python callable.
pub(crate) type PyProblem = GeneralProblem<UserG, PyExcitation>;

/// The Python `g(x, v, theta)`: per sample, or (`vectorized`) once for all
/// samples with (N, n_dof) arrays and a (N,) phase array, returning (N, n_dof).
pub(crate) struct PyNonlinearity {
    g: Py<PyAny>,
    n: usize,
    vectorized: bool,
    /// `g` reads `omega` ([`reads_omega`]).
    omega: bool,
    arrays: SampleArrays,
    error: ErrorSlot,
}

/// Calls `func(*args)` (with `omega=ω_f`, see [`OmegaArg`]) and writes its `out.len()` floats into `out` (NaN and the
/// exception recorded on error).
fn call_into(
    what: &str,
    slot: &ErrorSlot,
    func: &Py<PyAny>,
    args: impl FnOnce(Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyTuple>>,
    omega: OmegaArg,
    out: &mut [f64],
) {
    if failed(slot) {
        out.fill(f64::NAN);
        return;
    }
    let n = out.len();
    let r = Python::attach(|py| -> PyResult<()> {
        let res = func
            .bind(py)
            .call(args(py)?, omega_kwargs(py, omega)?.as_ref())?;
        if !res.is_exact_instance_of::<pyo3::types::PyFloat>() {
            crate::callback_arrays::refuse_complex(what, &res)?;
        }
        let v: Vec<f64> = if let Ok(x) = res.extract::<f64>() {
            vec![x]
        } else {
            res.extract()?
        };
        if v.len() != n {
            return Err(PyValueError::new_err(format!(
                "callback returned {} values for n_dof = {n}",
                v.len()
            )));
        }
        out.copy_from_slice(&v);
        Ok(())
    });
    if let Err(e) = r {
        record(slot, e);
        out.fill(f64::NAN);
    }
}

impl PyNonlinearity {
    /// One call of a vectorized `g` on `theta.len()` samples (sample-major).
    fn call_vectorized(
        &self,
        x: &[f64],
        v: &[f64],
        theta: &[f64],
        omega: OmegaArg,
        out: &mut [f64],
    ) {
        if failed(&self.error) {
            out.fill(f64::NAN);
            return;
        }
        let (n, ns) = (self.n, theta.len());
        let r = Python::attach(|py| -> PyResult<()> {
            let [xs, vs, ths] = self.arrays.args(py, n, x, v, theta)?;
            let kw = omega_kwargs(py, omega)?;
            let res = self.g.bind(py).call((xs, vs, ths), kw.as_ref())?;
            crate::callback_arrays::refuse_complex("the value of vectorized `g`", &res)?;
            let (shape, values) = float_array(&res).ok_or_else(|| {
                PyTypeError::new_err("vectorized `g` must return an array of floats")
            })?;
            if values.len() != ns * n || (shape.len() == 2 && shape != [ns, n]) {
                return Err(PyValueError::new_err(format!(
                    "vectorized `g` returned shape {shape:?}, expected ({ns}, {n})"
                )));
            }
            out.copy_from_slice(&values);
            Ok(())
        });
        if let Err(e) = r {
            record(&self.error, e);
            out.fill(f64::NAN);
        }
    }
}

impl PyNonlinearity {
    /// `g` on all samples, with `omega=ω_f` when it reads it (`omega_f`:
    /// the caller's excitation frequency, if it has one).
    fn eval_with(
        &self,
        x: &[f64],
        v: &[f64],
        theta: &[f64],
        omega_f: Option<f64>,
        out: &mut [f64],
    ) {
        let omega = self.omega.then_some(omega_f);
        if self.vectorized {
            self.call_vectorized(x, v, theta, omega, out);
        } else {
            per_sample(self.n, x, v, theta, out, |x, v, th, out| {
                self.call_one(x, v, th, omega, out)
            });
        }
    }

    /// One call of a per-sample `g`.
    fn call_one(&self, x: &[f64], v: &[f64], theta: f64, omega: OmegaArg, out: &mut [f64]) {
        call_into(
            "the value of `g`",
            &self.error,
            &self.g,
            |py| {
                pyo3::types::PyTuple::new(
                    py,
                    [
                        x.to_vec().into_pyarray(py).into_any(),
                        v.to_vec().into_pyarray(py).into_any(),
                        pyo3::types::PyFloat::new(py, theta).into_any(),
                    ],
                )
            },
            omega,
            out,
        );
    }
}

impl Nonlinearity for PyNonlinearity {
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.eval_with(x, v, &[theta], None, out)
    }
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        self.eval_with(x, v, theta, None, out)
    }
}

/// An n×n float64 matrix (array-like) as row-major data.
fn matrix(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<(usize, Vec<f64>)> {
    crate::callback_arrays::refuse_complex(&format!("argument `{name}`"), ob)?;
    // A scalar is a 1×1 matrix (single DOF).
    let (n, data) = if let Ok(x) = ob.extract::<f64>() {
        (1, vec![x])
    } else {
        let a = ob
            .extract::<numpy::PyArrayLike2<'_, f64, numpy::AllowTypeChange>>()
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "argument `{name}` must be a square matrix of floats"
                ))
            })?;
        let shape = a.shape().to_vec();
        match shape.as_slice() {
            &[rows, cols] if rows == cols && rows > 0 => {
                (rows, a.as_array().iter().copied().collect())
            }
            _ => {
                return Err(PyValueError::new_err(format!(
                    "argument `{name}` must be square and non-empty, got shape {shape:?}"
                )))
            }
        }
    };
    if let Some(bad) = data.iter().find(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "argument `{name}` has a non-finite entry ({bad})"
        )));
    }
    Ok((n, data))
}

/// The user system of `solve`, `frc`, `limit_cycle` and `backbone` from its
/// Python arguments. `g` is a callable or an [`Elements`] composition (then
/// `velocity_dependent` and `vectorized` are the elements' own, and `jac`
/// must be None); `jac` is `g`'s Jacobian ([`PyJacobian`]) or None.
#[allow(clippy::too_many_arguments)]
pub(crate) fn user_problem(
    m: &Bound<'_, PyAny>,
    c: &Bound<'_, PyAny>,
    k: &Bound<'_, PyAny>,
    g: &Bound<'_, PyAny>,
    f: Option<&Bound<'_, PyAny>>,
    jac: Option<&Bound<'_, PyAny>>,
    velocity_dependent: bool,
    vectorized: bool,
) -> PyResult<PyProblem> {
    let (nm, m) = matrix("m", m)?;
    let (nc, c) = matrix("c", c)?;
    let (nk, k) = matrix("k", k)?;
    if nm != nc || nm != nk {
        return Err(PyValueError::new_err(format!(
            "`m`, `c`, `k` must have the same size, got {nm}, {nc}, {nk}"
        )));
    }
    let elements = g
        .cast::<Elements>()
        .ok()
        .map(|e| e.borrow().list().to_vec());
    if elements.is_none() && !g.is_callable() {
        return Err(PyTypeError::new_err(
            "argument `g` must be callable g(x, v, theta) or ivt.hb.elements",
        ));
    }
    match (jac, &elements) {
        (Some(_), Some(_)) => {
            return Err(PyTypeError::new_err(
                "argument `jac` must be None when `g` is ivt.hb.elements (they have their own Jacobian)",
            ))
        }
        (Some(j), None) if !j.is_callable() => {
            return Err(PyTypeError::new_err(
                "argument `jac` must be callable jac(x, v, theta) -> (dg_dx, dg_dv) or None",
            ))
        }
        _ => {}
    }
    if let Some(f) = f {
        if !f.is_callable() {
            return Err(PyTypeError::new_err(
                "argument `f` must be callable f(theta) or None",
            ));
        }
    }
    let error = ErrorSlot::default();
    let g_omega = elements.is_none() && reads_omega(g);
    if g_omega && jac.is_some() {
        return Err(PyTypeError::new_err(
            "argument `jac` must be None when `g` reads `omega` (its differences are taken at each omega)",
        ));
    }
    let excitation = PyExcitation {
        f: f.map(|f| f.clone().unbind()),
        omega: f.is_some_and(reads_omega),
        error: Arc::clone(&error),
    };
    let (g, velocity_dependent) = match elements {
        Some(list) => {
            let problem = ElementProblem::new(nm, [m.clone(), c.clone(), k.clone()], list, vec![])
                .map_err(|e| PyValueError::new_err(format!("argument `g`: {e}")))?;
            let dependent = problem.velocity_dependent();
            (UserLaw::Elements(problem), dependent)
        }
        None => (
            UserLaw::Python(
                PyNonlinearity {
                    g: g.clone().unbind(),
                    n: nm,
                    vectorized,
                    omega: g_omega,
                    arrays: SampleArrays::default(),
                    error: Arc::clone(&error),
                },
                jac.map(|j| {
                    PyJacobian::new(j.clone().unbind(), nm, vectorized, Arc::clone(&error))
                }),
            ),
            velocity_dependent,
        ),
    };
    let g = UserG { law: g, error };
    let unforced = |_: f64, out: &mut [f64]| out.fill(0.0);
    Ok(GeneralProblem::new(nm, m, c, k, g, unforced)
        .with_excitation(excitation)
        .with_velocity_dependent(velocity_dependent))
}

/// The first exception a callback raised during a run, if any.
pub(crate) fn callback_error(problem: &PyProblem) -> Option<PyErr> {
    problem
        .nonlinearity()
        .error
        .lock()
        .ok()
        .and_then(|mut s| s.take())
}

/// The tolerance keywords of `solve`, `frc` and `limit_cycle` applied to `opts`:
/// ‖r‖₂ ≤ `tol + rtol·S` (`tol` absolute, S the force scale of ivt-hb's
/// `HbOptions`); `max_iter` caps the iterations of one solve.
pub(crate) fn with_tolerances(
    opts: HbOptions,
    tol: f64,
    rtol: f64,
    max_iter: usize,
) -> PyResult<HbOptions> {
    if !(rtol.is_finite() && tol.is_finite() && rtol >= 0.0 && tol >= 0.0 && rtol + tol > 0.0) {
        return Err(PyValueError::new_err(format!(
            "tolerances must be finite, >= 0 and not both 0, got tol = {tol}, rtol = {rtol}"
        )));
    }
    if max_iter == 0 {
        return Err(PyValueError::new_err("argument `max_iter` must be >= 1"));
    }
    Ok(opts.with_tolerances(rtol, tol).with_max_iter(max_iter))
}
