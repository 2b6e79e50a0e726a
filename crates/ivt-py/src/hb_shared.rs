//! Helpers shared by the `ivt.hb` bindings (hb.rs, hb_paths.rs,
//! hb_string.rs), kept here so that none of those modules imports another:
//! the `ConvergenceError` exception and the mapping of ivt-hb errors onto
//! Python exceptions by [`ivt_hb::HbError::kind`], the GIL-released runs that
//! re-raise a callback's exception (the error slot of the user problem), the
//! argument checks that name the Python argument (and the point dicts a
//! continuation starts from), and the `user_system_fn!` signature of every
//! user-system function, written once with `hb_family::family_fn!` as
//! `hb_keywords_fn!` (the keywords both share).

use ivt_hb::{HbError, HbOptions};
use ivt_kin::params::Typed;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::count;
use crate::interrupt::detach_interruptible;
use crate::user_problem::{callback_error, user_problem, with_tolerances, PyProblem};

create_exception!(
    ivt,
    ConvergenceError,
    PyRuntimeError,
    "A harmonic-balance solve that did not converge; `.history` holds ‖r‖ per iteration."
);

/// Map an ivt-hb error to Python by its [`HbError::kind`]: `"input"` →
/// ValueError, `"failed"` → ConvergenceError carrying the residual history
/// (`.history`, empty when the failure had none).
pub(crate) fn hb_err(py: Python<'_>, e: HbError) -> PyErr {
    if e.kind() == "input" {
        return PyValueError::new_err(e.to_string());
    }
    let err = ConvergenceError::new_err(e.to_string());
    if let Ok(list) = PyList::new(py, e.history()) {
        let _ = err.value(py).setattr("history", list);
    }
    err
}

/// Run `solve` with the GIL released, interruptible by Ctrl-C
/// ([`detach_interruptible`]); its error mapped by [`hb_err`].
pub(crate) fn run<T: Send>(
    py: Python<'_>,
    solve: impl FnOnce() -> Result<T, HbError> + Send,
) -> PyResult<T> {
    detach_interruptible(py, solve)?.map_err(|e| hb_err(py, e))
}

/// Run `solve` on a user system with the GIL released (its callbacks take it
/// back), interruptible by Ctrl-C ([`detach_interruptible`]), then re-raise the first exception a callback raised (it aborted the
/// run) or map the ivt-hb error with [`hb_err`].
pub(crate) fn run_user<T: Send>(
    py: Python<'_>,
    problem: &PyProblem,
    solve: impl FnOnce(&PyProblem) -> Result<T, HbError> + Send,
) -> PyResult<T> {
    let result = detach_interruptible(py, || solve(problem))?;
    // The callback's exception, not the failure it caused, is the error.
    if let Some(e) = callback_error(problem) {
        return Err(e);
    }
    result.map_err(|e| hb_err(py, e))
}

/// ValueError when the user system's `g` or `f` reads `omega`: `what` has no
/// excitation frequency to give it, its ω is an unknown of the orbit (only
/// `frc` and `solve` pass ω).
pub(crate) fn without_omega(problem: &PyProblem, what: &str) -> PyResult<()> {
    if ivt_hb::PeriodicProblem::frequency_dependent(problem) {
        return Err(PyValueError::new_err(format!(
            "`g` or `f` reads `omega`, but {what} has no excitation frequency to pass: its ω \
             is an unknown of the orbit (only `frc` and `solve` pass omega)"
        )));
    }
    Ok(())
}

/// `samples` = N (2N AFT samples) when the caller gives none: 64, the
/// default for n ≤ 20 (Fig. 28's 2N = 128), and the same proportion, 3.2·n
/// rounded up, above (`n = 80` → 256), so that every n works without it.
pub(crate) fn default_samples(n: usize) -> usize {
    (16 * n).div_ceil(5).max(64)
}

/// Options from the Python keywords: n harmonics, `samples` = N (2N AFT
/// samples; None: [`default_samples`]).
pub(crate) fn options(
    n: i64,
    samples: Option<i64>,
    subharmonic: i64,
    tol: f64,
) -> PyResult<HbOptions> {
    let n: usize = count("n", n)?;
    let samples: usize = match samples {
        Some(s) => count("samples", s)?,
        None => default_samples(n),
    };
    let subharmonic: usize = count("subharmonic", subharmonic)?;
    if n == 0 {
        return Err(PyValueError::new_err(
            "argument `n` (harmonics) must be >= 1",
        ));
    }
    if let Some(why) = ivt_hb::limits::unknowns_error(1, n) {
        return Err(PyValueError::new_err(format!("argument `n` = {n}: {why}")));
    }
    if let Some(why) = ivt_hb::limits::samples_error(samples) {
        return Err(PyValueError::new_err(format!(
            "argument `samples` = {samples}: {why}"
        )));
    }
    if samples <= n {
        return Err(PyValueError::new_err(format!(
            "argument `samples` = {samples} must exceed `n` = {n} (2N > 2n AFT samples)"
        )));
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(PyValueError::new_err(format!(
            "argument `tol` = {} must be finite and > 0",
            Typed(tol)
        )));
    }
    Ok(HbOptions::new(n, samples)
        .with_subharmonic(subharmonic)
        .with_tol(tol))
}

/// `v` unless it is NaN or infinite (ValueError naming the argument).
pub(crate) fn finite(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(PyValueError::new_err(format!(
            "argument `{name}` = {} must be finite",
            Typed(v)
        )))
    }
}

/// The `guess` keyword: a 1-D array-like of floats, or None.
pub(crate) fn guess_vec(guess: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<f64>>> {
    guess.map(|g| float_vec(g, "argument `guess`")).transpose()
}

/// A 1-D array-like of floats as a vector; `what` names it in the TypeError.
fn float_vec(v: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    v.extract::<numpy::PyArrayLike1<'_, f64, numpy::AllowTypeChange>>()
        .map(|a| a.as_array().to_vec())
        .map_err(|_| PyTypeError::new_err(format!("{what} must be a 1-D array of floats")))
}

/// The entry `key` of the dict argument `arg`; a missing one is a
/// ValueError naming both.
pub(crate) fn dict_item<'py>(
    dict: &Bound<'py, PyDict>,
    arg: &str,
    key: &str,
) -> PyResult<Bound<'py, PyAny>> {
    dict.get_item(key)?
        .ok_or_else(|| PyValueError::new_err(format!("argument `{arg}` needs \"{key}\"")))
}

/// ω and the coefficients of the point given as the dict argument `arg`
/// (an entry of `frc(...)["folds"]` or `["bifurcations"]`): its finite
/// "omega" and its "coeffs", a 1-D array of floats.
pub(crate) fn given_point(dict: &Bound<'_, PyDict>, arg: &str) -> PyResult<(f64, Vec<f64>)> {
    let omega = dict_item(dict, arg, "omega")?.extract()?;
    let omega = finite(&format!("{arg}[\"omega\"]"), omega)?;
    let coeffs = float_vec(
        &dict_item(dict, arg, "coeffs")?,
        &format!("{arg}[\"coeffs\"]"),
    )?;
    Ok((omega, coeffs))
}

/// The harmonic-balance keywords every user-system and family function
/// shares: `n`, `samples`, `velocity_dependent`, `vectorized`, `rtol` and
/// `max_iter` (checked).
#[derive(Clone, Copy)]
pub(crate) struct HbKeys {
    pub(crate) n: i64,
    pub(crate) samples: Option<i64>,
    pub(crate) velocity_dependent: bool,
    pub(crate) vectorized: bool,
    pub(crate) rtol: f64,
    pub(crate) max_iter: usize,
}

impl HbKeys {
    /// The keywords as given; `max_iter` must be ≥ 0.
    pub(crate) fn new(
        n: i64,
        samples: Option<i64>,
        velocity_dependent: bool,
        vectorized: bool,
        rtol: f64,
        max_iter: i64,
    ) -> PyResult<Self> {
        Ok(Self {
            n,
            samples,
            velocity_dependent,
            vectorized,
            rtol,
            max_iter: count("max_iter", max_iter)?,
        })
    }
}

/// The `#[pyfunction]` behind [`user_system_fn!`] and
/// `hb_family::family_fn!`, returning a dict. Python parameters: the
/// `head` ones, the function's own (`name: type [= default]`), `n=20,
/// samples=None`, its own again (`mid`), `velocity_dependent=True,
/// vectorized=False, rtol=1e-9, max_iter=100`, then the `tail` ones. Those
/// six reach the body as the [`HbKeys`] named `$keys`; the head and tail
/// parameters are named (for the body) by the calling macro. A default is
/// one token tree (a literal, `None`, or an expression in parentheses), so
/// that pyo3 still shows literal defaults in the Python signature.
macro_rules! hb_keywords_fn {
    (
        $(#[$doc:meta])*
        fn $name:ident<$lt:lifetime>($py:ident, $keys:ident);
        head [$($head_sig:tt)*] [$($head_param:tt)*];
        own [$( $(#[$pa:ident($($pa_args:tt)*)])* $arg:ident: $ty:ty $(= $default:tt)? ),*];
        mid [$( $(#[$pb:ident($($pb_args:tt)*)])* $brg:ident: $bty:ty $(= $bdefault:tt)? ),*];
        tail [$($tail_sig:tt)*] [$($tail_param:tt)*];
        $body:block
    ) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (
            $($head_sig)* $($arg $(= $default)?,)* n = 20, samples = None, $($brg $(= $bdefault)?,)*
            velocity_dependent = true, vectorized = false, rtol = 1e-9, max_iter = 100
            $($tail_sig)*
        ))]
        #[allow(clippy::too_many_arguments, clippy::field_reassign_with_default)]
        fn $name<$lt>(
            $py: Python<$lt>,
            $($head_param)*
            $( $(#[$pa($($pa_args)*)])* $arg: $ty, )*
            #[pyo3(from_py_with = crate::args::int64)] n: i64,
            #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
            $( $(#[$pb($($pb_args)*)])* $brg: $bty, )*
            velocity_dependent: bool, vectorized: bool, rtol: f64,
            #[pyo3(from_py_with = crate::args::int64)] max_iter: i64,
            $($tail_param)*
        ) -> PyResult<Bound<$lt, PyDict>> {
            let $keys = $crate::hb_shared::HbKeys::new(
                n, samples, velocity_dependent, vectorized, rtol, max_iter,
            )?;
            $body
        }
    };
}
pub(crate) use hb_keywords_fn;

/// A `#[pyfunction]` on a user system `M x'' + C x' + K x + g(x, v, θ) =
/// f(θ)` returning a dict. Python parameters: `m, c, k, g`, the function's
/// own (`name: type [= default]`), `n=20, samples=None`, its own again, then
/// `velocity_dependent=True, vectorized=False, rtol=1e-9, max_iter=100`, and
/// `jac=None` when the caller names it after the `UserArgs` binding (a
/// function whose solver assembles the Galerkin Jacobian). The
/// shared ones reach the body as the [`UserArgs`] named by the caller.
macro_rules! user_system_fn {
    (
        $(#[$doc:meta])*
        fn $name:ident<$lt:lifetime>($py:ident, $user:ident $(, $jac:ident)?;
            $( $(#[$pa:ident($($pa_args:tt)*)])* $arg:ident: $ty:ty $(= $default:tt)? ),+;
            $( $(#[$pb:ident($($pb_args:tt)*)])* $brg:ident: $bty:ty $(= $bdefault:tt)? ),+ $(,)?
        ) $body:block
    ) => {
        $crate::hb_shared::hb_keywords_fn! {
            $(#[$doc])*
            fn $name<$lt>($py, keys);
            head [m, c, k, g,] [
                m: &Bound<$lt, PyAny>, c: &Bound<$lt, PyAny>, k: &Bound<$lt, PyAny>,
                g: &Bound<$lt, PyAny>,
            ];
            own [$( $(#[$pa($($pa_args)*)])* $arg: $ty $(= $default)? ),+];
            mid [$( $(#[$pb($($pb_args)*)])* $brg: $bty $(= $bdefault)? ),+];
            tail [$(, $jac = None)?] [$( $jac: Option<&Bound<$lt, PyAny>>, )?];
            {
                let $user = UserArgs { system: [m, c, k, g], keys, jac: None $( .or($jac) )? };
                $body
            }
        }
    };
}
pub(crate) use user_system_fn;

/// The arguments every user-system function shares: the system `[m, c, k, g]`,
/// `g`'s optional Jacobian `jac` (always None where the keyword is not offered)
/// and the harmonic-balance keywords.
pub(crate) struct UserArgs<'a, 'py> {
    pub(crate) system: [&'a Bound<'py, PyAny>; 4],
    pub(crate) keys: HbKeys,
    pub(crate) jac: Option<&'a Bound<'py, PyAny>>,
}

impl UserArgs<'_, '_> {
    /// The user problem forced by `f` and its options (`subharmonic`, absolute
    /// tolerance `tol`, see [`with_tolerances`]).
    pub(crate) fn setup(
        &self,
        f: Option<&Bound<'_, PyAny>>,
        subharmonic: i64,
        tol: f64,
    ) -> PyResult<(PyProblem, HbOptions)> {
        let [m, c, k, g] = self.system;
        let problem = user_problem(
            m,
            c,
            k,
            g,
            f,
            self.jac,
            self.keys.velocity_dependent,
            self.keys.vectorized,
        )?;
        let k = &self.keys;
        let opts = options(k.n, k.samples, subharmonic, 1.0)?;
        Ok((problem, with_tolerances(opts, tol, k.rtol, k.max_iter)?))
    }
}
