//! A Python `family(p)` → (m, c, k, g, f) (or (m, c, k, g), unforced) as the fallible Rust family of
//! ivt-hb's two-parameter functions ([`PyFamily`]), and the `family_fn!`
//! signature of the continuation functions on such a family (the keywords
//! they share reach the body as one [`FamilyArgs`]).

use ivt_hb::{HbError, HbOptions};
use ivt_jobs::Steps;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use std::sync::Mutex;

use crate::hb_shared::{run_user, HbKeys, UserArgs};
use crate::user_problem::{user_problem, PyProblem};

/// The user system `family(p)` returns: a tuple (m, c, k, g, f), or
/// (m, c, k, g) for an unforced (autonomous) system (f None).
pub(crate) fn family_system<'py>(
    family: &Bound<'py, PyAny>,
    p: f64,
) -> PyResult<[Bound<'py, PyAny>; 5]> {
    let wrong = || {
        PyTypeError::new_err(
            "argument `family` must return a tuple (m, c, k, g, f) or, unforced, (m, c, k, g)",
        )
    };
    let mut parts: Vec<Bound<'py, PyAny>> = family.call1((p,))?.extract().map_err(|_| wrong())?;
    if parts.len() == 4 {
        parts.push(family.py().None().into_bound(family.py()));
    }
    parts.try_into().map_err(|_| wrong())
}

/// A Python `family(p)` → (m, c, k, g, f) as a fallible family of user
/// systems; the first exception it raised is kept ([`Self::take_error`]).
pub(crate) struct PyFamily {
    family: Py<PyAny>,
    keys: HbKeys,
    failure: Mutex<Option<PyErr>>,
}

impl PyFamily {
    /// `family` with the HB keywords of its systems and their options.
    pub(crate) fn new(family: &Bound<'_, PyAny>, keys: HbKeys) -> Self {
        Self {
            family: family.clone().unbind(),
            keys,
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
                self.keys.velocity_dependent,
                self.keys.vectorized,
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
    /// with the same keywords and an error slot of its own.
    pub(crate) fn with_first(&self, partial: &Bound<'_, PyAny>, mu: f64) -> PyResult<PyFamily> {
        let one = partial.call1((self.family.bind(partial.py()), mu))?;
        Ok(Self::new(&one, self.keys))
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

    /// The user system at `p` and HB options from the family's keywords.
    pub(crate) fn first(&self, py: Python<'_>, p: f64) -> PyResult<(PyProblem, HbOptions)> {
        let [m, c, k, g, f] = family_system(self.family.bind(py), p)?;
        let user = UserArgs {
            system: [&m, &c, &k, &g],
            keys: self.keys,
            jac: None,
        };
        user.setup((!f.is_none()).then_some(&f), 1, 0.0)
    }
}

/// What a [`family_fn!`] function's shared keywords give its body: the
/// family with its HB keywords, and the continuation keywords.
pub(crate) struct FamilyArgs {
    /// `family` with `n`, `samples`, `velocity_dependent`, `vectorized`,
    /// `rtol`, `max_iter`.
    pub family: PyFamily,
    /// `ds`, `ds_min`, `ds_max`, `max_points` (None: the path's own).
    pub steps: Steps,
}

/// A `#[pyfunction]` continuing a solution of a Python family, returning a
/// dict: `fn name<'py>(py, args) [own parameters] { body }`. Python
/// parameters: `family`, the function's own (`name: type [= default]`, in
/// brackets), then `n=20, samples=None, velocity_dependent=True,
/// vectorized=False, rtol=1e-9, max_iter=100, ds=None, ds_min=None,
/// ds_max=None, max_points=None`; those reach the body as the [`FamilyArgs`]
/// named by the caller.
macro_rules! family_fn {
    ($(#[$doc:meta])* fn $name:ident<$lt:lifetime>($py:ident, $args:ident) $own:tt $body:block) => {
        $crate::hb_shared::hb_keywords_fn! {
            $(#[$doc])*
            fn $name<$lt>($py, keys);
            head [family,] [family: &Bound<$lt, PyAny>,];
            own $own;
            mid [];
            tail [, ds = None, ds_min = None, ds_max = None, max_points = None] [
                ds: Option<f64>, ds_min: Option<f64>, ds_max: Option<f64>,
                #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
            ];
            {
                let $args = $crate::hb_family::FamilyArgs {
                    family: $crate::hb_family::PyFamily::new(family, keys),
                    steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
                };
                $body
            }
        }
    };
}
pub(crate) use family_fn;
