//! `ivt.hb`: the harmonic-balance engine of ivt-hb (modified/classic IHB, limit
//! cycles, Floquet stability by Hsu's method, frequency-response curves with
//! located folds) for Duffing, Mathieu–Duffing and user systems
//! `M x'' + C x' + K x + g(x, x', θ) = f(θ)`. Each function parses its
//! arguments, runs an `ivt_jobs` job and returns its result as a dict
//! (the keys of the CLI's JSON, [`crate::to_python`]).

use ivt_hb::{AtFrequency, Duffing, MathieuDuffing};
use ivt_jobs::{self as jobs, CascadeRequest, FrcRequest, LimitCycleRequest, OrbitRequest};
use numpy::PyArrayLike1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::args::{count, int64};
use crate::hb_shared::{
    finite, guess_vec, hb_err, options, run, run_user, user_system_fn, ConvergenceError, UserArgs,
};
use crate::to_python::to_dict;

/// The orbit job's request from the keywords (`method` by name).
fn orbit_request(
    py: Python<'_>,
    omega_f: f64,
    method: &str,
    guess: Option<&Bound<'_, PyAny>>,
    stability: bool,
) -> PyResult<OrbitRequest> {
    Ok(OrbitRequest {
        omega_f,
        method: method.parse().map_err(|e| hb_err(py, e))?,
        guess: guess_vec(guess)?,
        stability,
    })
}

/// Duffing's equation Eq. 49 from the keywords (each must be finite).
fn duffing_problem(xi: f64, alpha: f64, eps: f64, force: f64) -> PyResult<Duffing> {
    Ok(Duffing::new(
        finite("xi", xi)?,
        finite("alpha", alpha)?,
        finite("eps", eps)?,
        finite("force", force)?,
    ))
}

/// A `#[pyfunction]` on Duffing's equation Eq. 49 returning a dict. Python
/// parameters: the `head` ones (`name: type [= default]`), then Duffing's
/// keywords `n=20, samples=None, xi=0.02, alpha=1.0, eps=1.0, force=0.1`
/// (declared here once for every Duffing function), then the `tail` ones.
/// The body gets the equation ([`duffing_problem`]) and the two counts under
/// the names the caller gives.
macro_rules! duffing_fn {
    (
        $(#[$doc:meta])*
        fn $name:ident<$lt:lifetime>($py:ident, $problem:ident, $n:ident, $samples:ident;
            head [$( $arg:ident: $ty:ty $(= $default:tt)? ),*];
            tail [$( $(#[$pb:ident($($pb_args:tt)*)])* $brg:ident: $bty:ty $(= $bdefault:tt)? ),*];
        ) $body:block
    ) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (
            $($arg $(= $default)?,)* $n = 20, $samples = None, xi = 0.02, alpha = 1.0, eps = 1.0,
            force = 0.1 $(, $brg $(= $bdefault)?)*
        ))]
        #[allow(clippy::too_many_arguments)]
        fn $name<$lt>(
            $py: Python<$lt>,
            $( $arg: $ty, )*
            #[pyo3(from_py_with = int64)] $n: i64,
            #[pyo3(from_py_with = crate::args::opt_int64)] $samples: Option<i64>,
            xi: f64, alpha: f64, eps: f64, force: f64,
            $( $(#[$pb($($pb_args)*)])* $brg: $bty, )*
        ) -> PyResult<Bound<$lt, PyDict>> {
            let $problem = duffing_problem(xi, alpha, eps, force)?;
            $body
        }
    };
}

duffing_fn! {
/// Periodic solution of Duffing's equation Eq. 49,
/// `u'' + 2ξu' + αu + εu³ = F cos(ω_f t)`, by harmonic balance.
///
/// n harmonics, 2·samples AFT samples (samples = N > n), method "modified"
/// (AFT residual + Broyden, §3.2.2) or "classic" (Newton with the Galerkin
/// Jacobian, §3.2.1). Returns the dict of `ivt hb duffing --json`: coeffs
/// [a0, a1..an, b1..bn] (u = a0/2 + Σ a_k cos kτ + b_k sin kτ, τ = ω_f t),
/// iterations, residual_norm, solve_time_s (the solve alone), floquet
/// multipliers [[re, im], ...] by Hsu's method (Magnus-4 steps doubled from
/// max(2(n + 1), 32) until their Richardson estimate multiplier_error, relative
/// to max(1, |μ|), is at most 1e-6, at most 4096; as the CLI and the FRC
/// points), stable.
/// `stability=False` skips the multipliers (floquet = [], stable = None,
/// multiplier_error = None).
/// The GIL is released while solving.
fn duffing<'py>(py, problem, n, samples;
    head [];
    tail [
        omega_f: f64 = 0.4,
        method: &str = "modified",
        guess: Option<&Bound<'py, PyAny>> = None,
        tol: f64 = 1e-10,
        stability: bool = true
    ];
) {
    let opts = options(n, samples, 1, tol)?;
    let req = orbit_request(py, omega_f, method, guess, stability)?;
    let orbit = run(py, || jobs::orbit(&problem, &opts, &req))?;
    to_dict(py, &orbit)
}
}

/// Periodic solution of the Mathieu–Duffing equation Eq. 81,
/// `u'' + 2ξ̂u' − (α̂ + β sin Ωt)u + γu³ = 0`, of period p·2π/Ω
/// (`subharmonic=p`; p = 2 after the first period doubling). A nonzero
/// `guess` is needed to leave the trivial solution u = 0. Same dict as
/// `duffing`.
#[pyfunction]
#[pyo3(signature = (
    beta, n = 20, samples = None, xi = 0.125, alpha = 1.0, gamma = 1.0, omega = 2.0,
    subharmonic = 1, guess = None, tol = 1e-10, stability = true
))]
#[allow(clippy::too_many_arguments)]
fn mathieu_duffing<'py>(
    py: Python<'py>,
    beta: f64,
    #[pyo3(from_py_with = int64)] n: i64,
    #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
    xi: f64,
    alpha: f64,
    gamma: f64,
    omega: f64,
    #[pyo3(from_py_with = int64)] subharmonic: i64,
    guess: Option<&Bound<'py, PyAny>>,
    tol: f64,
    stability: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let opts = options(n, samples, subharmonic, tol)?;
    let problem = MathieuDuffing::new(
        finite("xi", xi)?,
        finite("alpha", alpha)?,
        finite("beta", beta)?,
        finite("gamma", gamma)?,
    );
    let req = orbit_request(py, omega, "modified", guess, stability)?;
    let orbit = run(py, || jobs::orbit(&problem, &opts, &req))?;
    to_dict(py, &orbit)
}

/// The period-doubling cascade of the Mathieu–Duffing equation Eq. 81
/// (§3.2.5): β at the first three period doublings, located by Floquet
/// multipliers crossing −1 along the branch, with `n` harmonics per period
/// and `samples` = N (2N AFT samples; None: 4n) on the period-1 orbit, both
/// doubled with each period. `ds`, `ds_min`, `ds_max`, `max_points`: the
/// steps of every leg (None: the period-1 branch in β from Δη = 0.02 up to
/// 0.05, each period-2^k branch in its amplitude a₁ from 0.01·A up to 0.02·A,
/// A the largest coefficient of the orbit that doubled; 4000 points per leg).
/// Returns the dict of `ivt hb mathieu-duffing --json`:
/// period_doubling_beta, periods, multipliers ([[re, im]...] at each
/// doubling), thesis ([4.825, 5.194, 5.253]), time_s. GIL released.
#[pyfunction]
#[pyo3(signature = (xi = 0.125, alpha = 1.0, omega = 2.0, gamma = 1.0, n = 12, samples = None,
                    ds = None, ds_min = None, ds_max = None, max_points = None))]
#[allow(clippy::too_many_arguments)]
fn mathieu_cascade<'py>(
    py: Python<'py>,
    xi: f64,
    alpha: f64,
    omega: f64,
    gamma: f64,
    #[pyo3(from_py_with = int64)] n: i64,
    #[pyo3(from_py_with = crate::args::opt_int64)] samples: Option<i64>,
    ds: Option<f64>,
    ds_min: Option<f64>,
    ds_max: Option<f64>,
    #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let req = CascadeRequest {
        xi: finite("xi", xi)?,
        alpha: finite("alpha", alpha)?,
        omega: finite("omega", omega)?,
        gamma: finite("gamma", gamma)?,
        harmonics: count("n", n)?,
        samples: samples.map(|s| count("samples", s)).transpose()?,
        steps: crate::steps::steps(ds, ds_min, ds_max, max_points)?,
        ..CascadeRequest::default()
    };
    let cascade = run(py, || jobs::cascade(&req))?;
    to_dict(py, &cascade)
}

duffing_fn! {
/// Frequency-response curve of Duffing's equation by pseudo-arclength
/// continuation in ω_f from `from_` to `to` (Fig. 29), with the Floquet
/// verdict at every point: the dict of `ivt hb duffing-frc --json`
/// ([`ivt_jobs::FrcCurve`]): {"points": [{"omega", "amplitude",
/// "stable", "stability", "kind", "coeffs", "multipliers",
/// "multiplier_error"}...], "folds": [ω_f at each turning point],
/// "bifurcations", "termination", "time_s"} and the arrays omega,
/// amplitude, stable for plotting. `events=True` (`--events`) also locates
/// period doublings, Neimark–Sacker and branch points. `ds`, `ds_min`,
/// `ds_max`, `max_points`: the path's steps (None: Δη from 0.05 up to 0.08,
/// 5000 points). GIL released.
fn duffing_frc<'py>(py, problem, n, samples;
    head [from_: f64 = 0.2, to: f64 = 3.0];
    tail [
        events: bool = false,
        ds: Option<f64> = None,
        ds_min: Option<f64> = None,
        ds_max: Option<f64> = None,
        #[pyo3(from_py_with = crate::args::opt_int64)] max_points: Option<i64> = None
    ];
) {
    let opts = options(n, samples, 1, 1e-10)?;
    let steps = crate::steps::steps(ds, ds_min, ds_max, max_points)?;
    let req = FrcRequest {
        options: crate::steps::sweep(finite("from_", from_)?, finite("to", to)?, &steps)?,
        events,
    };
    let curve = run(py, || jobs::frc(&problem, &opts, &req))?;
    to_dict(py, &curve.with_fold_omegas())
}
}

user_system_fn! {
/// Periodic solution of a user system `M x'' + C x' + K x + g(x, v, θ) = f(θ)`
/// (θ = ω_f t, v = dx/dt) by the modified IHB (or classic), with Floquet
/// multipliers.
///
/// m, c, k: n_dof×n_dof matrices (a float for one DOF). g(x, v, theta) →
/// n_dof floats (x, v numpy arrays of n_dof); f(theta) → n_dof floats (None:
/// unforced). `velocity_dependent=False` when g ignores v (saves work).
/// `vectorized=True`: g(x, v, theta) is called once per residual with x, v of
/// shape (N, n_dof) and theta of shape (N,) for all N = 2·samples AFT
/// samples, and returns (N, n_dof); g must act row by row (other grids
/// come: Hsu's stability grid, and differencing ∂g stacks its 2·n_dof
/// perturbed copies of a grid into one call).
/// Convergence: ‖r‖₂ ≤ tol + rtol·S, r the Galerkin residual (a force), S
/// the norm of the forcing's projection (for f = None: of the guess's linear
/// force): `tol` is absolute (default 0), `rtol` relative (default 1e-9), so
/// by default a change of length unit changes nothing. `max_iter` caps the
/// iterations. ∂g (stability, Jacobian refreshes) is differenced over all
/// samples at once with steps relative to the orbit's amplitude, unless
/// `jac` is given: jac(x, v, theta) → (dg_dx, dg_dv), per sample two
/// (n_dof, n_dof) arrays (row i, column j: ∂g_i/∂x_j); with `vectorized=True`
/// for (N, n_dof) inputs two (N, n_dof, n_dof) arrays. dg_dv may be None
/// (zero; it is taken as zero anyway when velocity_dependent=False). A wrong
/// shape or a non-finite entry raises ValueError naming `jac`; `jac` with
/// ivt.hb.elements as g is a TypeError (elements have their own Jacobian).
/// Speed cost: a per-sample g is called once per AFT sample and residual
/// evaluation (2·samples calls per iteration), each costing ~1–3 µs of
/// interpreter time against ~10 ns for a Rust g; with `vectorized=True` it is
/// one call per residual and one per ∂g (none with `jac`: one `jac` call per
/// Jacobian assembly instead).
/// The GIL is released between callbacks, so other Python threads run. An
/// exception in a callback aborts the solve and is re-raised. Same dict as
/// `duffing`.
fn solve<'py>(py, user, jac;
    omega_f: f64,
    f: Option<&Bound<'py, PyAny>> = None;
    #[pyo3(from_py_with = int64)] subharmonic: i64 = 1,
    method: &str = "modified",
    guess: Option<&Bound<'py, PyAny>> = None,
    tol: f64 = 0.0,
    stability: bool = true,
) {
    let (problem, opts) = user.setup(f, subharmonic, tol)?;
    let req = orbit_request(py, omega_f, method, guess, stability)?;
    // Bound to ω_f: a `g` or `f` that reads `omega` gets it.
    let orbit = run_user(py, &problem, |p| {
        jobs::orbit(&AtFrequency::new(p, req.omega_f), &opts, &req)
    })?;
    to_dict(py, &orbit)
}
}

user_system_fn! {
/// Limit cycle of an autonomous user system `M x'' + C x' + K x + g(x, v) = 0`
/// by harmonic balance with the response frequency ω as an unknown and the
/// phase condition b1 = 0 on DOF 0 (Newton with the Galerkin Jacobian).
///
/// The start is `guess` (coefficients, n_dof blocks of [a0, a1..an, b1..bn])
/// at `omega_guess`, or else the transient from the state `x0` = [x..., v...]
/// (default: x = (`amplitude`, 0, ...), v = 0) integrated until it settles
/// onto the attractor (Dormand–Prince 5(4); settled when a section crossing
/// returns within 1e-6), then refined by HB (ivt_hb::limit_cycle_from_state;
/// a transient that comes to rest raises ivt.hb.ConvergenceError naming the equilibrium).
/// g(x, v, theta): theta is the phase ω t (an autonomous g ignores it);
/// `vectorized` and `jac` as in `solve`.
/// Accuracy (issue 41): `tol` (default 1e-8) is the relative accuracy asked
/// of ω and the coefficients. The cycle is solved again at 1.5·n (samples in
/// proportion) from its own coefficients; "error_estimate" is twice the
/// largest relative change of ω or a coefficient (at least 1e-11, the solves'
/// floor); while it exceeds `tol`, n
/// grows by half (up to 160) and "accuracy" says "met" or "not met" (with
/// the estimate); `tol=0` keeps n as given ("not asked", the estimate still
/// reported). `n` is the first n; `samples` ≤ n is raised to the default.
/// Returns {"omega", "period", "coeffs", "multipliers" ([[re, im], ...],
/// the trivial +1 included), "stable" (all others inside the unit circle),
/// "stability", "iterations", "residual_norm", "harmonics", "samples",
/// "error_estimate", "tol", "accuracy"}.
fn limit_cycle<'py>(py, user, jac;
    omega_guess: f64,
    amplitude: f64 = 1.0,
    guess: Option<&Bound<'py, PyAny>> = None;
    tol: f64 = 1e-8,
    x0: Option<Vec<f64>> = None,
) {
    if !(omega_guess.is_finite() && omega_guess > 0.0) {
        return Err(PyValueError::new_err(format!(
            "argument `omega_guess` = {omega_guess} must be finite and > 0 (a cycle's frequency)"
        )));
    }
    let mut user = user;
    // `samples` ≤ n: the default (as the job).
    if user.keys.samples.is_some_and(|s| s <= user.keys.n) {
        user.keys.samples = None;
    }
    let (problem, opts) = user.setup(None, 1, 0.0)?;
    crate::hb_shared::without_omega(&problem, "limit_cycle")?;
    let req = LimitCycleRequest {
        omega_guess,
        guess: guess_vec(guess)?,
        x0,
        amplitude: finite("amplitude", amplitude)?,
        tol,
    };
    let cycle = run_user(py, &problem, |p| jobs::limit_cycle(p, &opts, &req))?;
    to_dict(py, &cycle)
}
}

/// Evaluate the Fourier series u(τ) = a0/2 + Σ a_k cos kτ + b_k sin kτ of
/// coefficients [a0, a1..an, b1..bn] at τ (array-like), or its `order`-th
/// τ-derivative. With `n_dof` > 1, `coeffs` holds n_dof such blocks (the
/// layout of every multi-DOF result) and the result gains a last axis of
/// length n_dof (u_d(τ) for each DOF).
#[pyfunction]
#[pyo3(signature = (coeffs, tau, order = 0, n_dof = 1))]
fn eval_series<'py>(
    py: Python<'py>,
    coeffs: PyArrayLike1<'py, f64, numpy::AllowTypeChange>,
    tau: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = int64)] order: i64,
    #[pyo3(from_py_with = int64)] n_dof: i64,
) -> PyResult<Bound<'py, PyAny>> {
    let n_dof: usize = count("n_dof", n_dof)?;
    let order: u32 = count("order", order)?;
    let q = coeffs.as_array().to_vec();
    if n_dof == 0 || !q.len().is_multiple_of(n_dof) || (q.len() / n_dof).is_multiple_of(2) {
        return Err(PyValueError::new_err(format!(
            "argument `coeffs` must have n_dof·(2n+1) entries for n_dof = {n_dof}, got {}",
            q.len()
        )));
    }
    if n_dof == 1 {
        return crate::vectorize::map1(py, [("tau", tau)], |[t]| {
            ivt_hb::orbit::aft::eval_series(&q, t, order)
        });
    }
    let per_dof = q
        .chunks_exact(q.len() / n_dof)
        .map(|block| {
            crate::vectorize::map1(py, [("tau", tau)], |[t]| {
                ivt_hb::orbit::aft::eval_series(block, t, order)
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let np = py.import("numpy")?;
    np.call_method1("stack", (per_dof, -1))
}

/// Register `ivt._ivt.hb`.
pub fn register(parent: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = parent.py();
    let m = PyModule::new(py, "hb")?;
    add_functions!(
        &m,
        [
            duffing,
            duffing_frc,
            mathieu_duffing,
            mathieu_cascade,
            solve,
            limit_cycle,
            eval_series
        ]
    );
    crate::hb_paths::register(&m)?;
    crate::hb_analyses::register(&m)?;
    crate::hb_folds::register(&m)?;
    crate::hb_bifurcation::register(&m)?;
    crate::hb_cycle_fold::register(&m)?;
    crate::hb_large::register(&m)?;
    crate::hb_reduced::register(&m)?;
    crate::hb_string::register(&m)?;
    crate::hb_switch::register(&m)?;
    crate::hb_torus::register(&m)?;
    crate::hb_sensitivity::register(&m)?;
    crate::hb_elements::register(&m)?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    parent.add_submodule(&m)
}
