"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability,
frequency-response curves with located folds, period doublings,
Neimark–Sacker and branch points (:func:`frc`), the quasi-periodic torus born
at a Neimark–Sacker point (:func:`torus_branch`), automatic bifurcation
diagrams (:func:`diagram`), sensitivities of located features to a model
parameter (:func:`event_sensitivity`), and limit cycles, for Duffing,
Mathieu–Duffing, the STHB string (:func:`string`) and user systems; backbone
curves (:func:`backbone`) of conservative ones. ``g`` may be a Python callable
or a sum of Rust elements from :mod:`ivt.hb.elements` (e.g.
``elements.cubic_spring(0.5, dof=0) + elements.coulomb(0.1, 1e-3, dof=1)``),
evaluated with no Python in the loop.

Coefficient convention (as ``ivt hb ... --json``): ``[a0, a1..an, b1..bn]``
per DOF with ``u(τ) = a0/2 + Σ a_k cos kτ + b_k sin kτ``, τ = ω t; a
multi-DOF vector is the DOF blocks one after the other (``eval_series(...,
n_dof=)`` evaluates it). User callbacks: ``g(x, v, theta)`` with v = dx/dt and
theta = ω_f t; with ``vectorized=True`` x, v have shape (N, n_dof) and theta
shape (N,) for all N samples of a grid (the AFT's, Hsu's, or the 2·n_dof
perturbed copies of one stacked to difference ∂g), and g returns (N, n_dof)
acting row by row.
All solvers release the GIL; :func:`solve` re-acquires it only to call the
user's Python callbacks. Non-convergence raises :class:`ConvergenceError`
whose ``history`` attribute is the residual norm per iteration.
"""

from . import _ivt
from ._reexport import reexport


__all__ = [
    "AllSolutions",
    "ConvergenceError",
    "all_solutions",
    "backbone",
    "continue_bifurcation",
    "cycle_branch",
    "cycle_fold_curve",
    "damped_modes",
    "diagram",
    "duffing",
    "duffing_folds",
    "duffing_frc",
    "eval_series",
    "event_sensitivity",
    "frc",
    "limit_cycle",
    "mathieu_cascade",
    "mathieu_duffing",
    "neimark_sacker_points",
    "solve",
    "string",
    "switch_branch",
    "torus_branch",
]

_NATIVE = [name for name in __all__ if name not in ("AllSolutions", "all_solutions")]
reexport(globals(), _ivt.hb, _NATIVE)
elements = _ivt.hb.elements
Elements = _ivt.hb.elements.Elements


class AllSolutions(list):  # type: ignore[type-arg]
    """The orbits found by :func:`all_solutions` (a list of dicts), with the
    search's bounds and outcome in ``search``: {"starts", "runs",
    "max_amplitude", "newton_steps", "exhausted"}."""

    def __init__(self, solutions: list, search: dict) -> None:  # type: ignore[type-arg]
        super().__init__(solutions)
        self.search = search


def all_solutions(
    m, c, k, g, f, omega, n=20, samples=64, max_amplitude=10.0, amplitudes=6,
    newton_steps=60, tol=0.0, velocity_dependent=True, vectorized=False,
    rtol=1e-9, max_iter=100, jac=None,
):  # type: ignore[no-untyped-def]
    """Every period-one solution at ``omega`` that deflated Newton finds
    within bounded starts (see ``ivt._ivt.hb._all_solutions``): a list of
    {"coeffs", "amplitude", "multipliers", "stable", "stability"} by
    increasing size, with ``.search`` = {"starts", "runs", "max_amplitude",
    "newton_steps", "exhausted"}."""
    found = _ivt.hb._all_solutions(
        m, c, k, g, f, omega, n=n, samples=samples, max_amplitude=max_amplitude,
        amplitudes=amplitudes, newton_steps=newton_steps, tol=tol,
        velocity_dependent=velocity_dependent, vectorized=vectorized, rtol=rtol,
        max_iter=max_iter, jac=jac,
    )
    return AllSolutions(found["solutions"], found["search"])
# --- large structures (issue 28): condensation onto the nonlinear DOFs -------

import inspect as _inspect
import operator as _operator
from types import SimpleNamespace as _Namespace

import numpy as _np


def _index(name, value):
    """A count or DOF index as the native functions take it: an int or a numpy
    integer, not a bool and not a float (TypeError), not negative (ValueError),
    the error naming the argument."""
    if isinstance(value, bool):
        raise TypeError(f"argument `{name}` must be an integer, not bool")
    try:
        index = _operator.index(value)
    except TypeError:
        raise TypeError(f"argument `{name}` must be an integer, got {value!r}") from None
    if index < 0:
        raise ValueError(f"argument `{name}` must be >= 0, got {index}")
    return index

_LARGE_KEYS = ("nonlinear_dofs", "amplitude_dof", "record_dofs")


def _coo(name, a):
    """COO triplets (rows, cols, values) of a scipy.sparse or dense matrix."""
    if hasattr(a, "tocoo"):
        c = a.tocoo()
        rows, cols, vals = c.row, c.col, c.data
        n = c.shape[0]
        if c.shape[0] != c.shape[1]:
            raise ValueError(f"argument `{name}` must be square, got shape {c.shape}")
    else:
        arr = _np.atleast_2d(_np.asarray(a, dtype=float))
        if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
            raise ValueError(f"argument `{name}` must be square, got shape {arr.shape}")
        rows, cols = _np.nonzero(arr)
        vals = arr[rows, cols]
        n = arr.shape[0]
    return n, ([int(i) for i in rows], [int(j) for j in cols], [float(v) for v in vals])


def _loads(f, n):
    """(F_cos, F_sin) from an array F (F cos θ) or a pair (F_cos, F_sin)."""
    if isinstance(f, (tuple, list)) and len(f) == 2 and _np.ndim(f[0]) == 1:
        fc, fs = (_np.asarray(v, dtype=float).ravel() for v in f)
    else:
        fc = _np.asarray(f, dtype=float).ravel()
        fs = _np.zeros(n)
    if fc.shape != (n,) or fs.shape != (n,):
        raise ValueError(f"load vectors of `f` must have n_dof = {n} entries")
    return [float(v) for v in fc], [float(v) for v in fs]


def _is_large(m, f, extra):
    loads = f is not None and not callable(f)
    return hasattr(m, "tocoo") or loads or extra.get("nonlinear_dofs") is not None


def _series_max(coeffs):
    """max_τ |x(τ)| of one series: a 4096-point grid refined by Newton."""
    tau = _np.linspace(0.0, 2.0 * _np.pi, 4096, endpoint=False)
    x = _np.abs(_ivt.hb.eval_series(coeffs, tau))
    t = float(tau[int(_np.argmax(x))])
    for _ in range(8):
        d1 = float(_ivt.hb.eval_series(coeffs, t, 1))
        d2 = float(_ivt.hb.eval_series(coeffs, t, 2))
        if d2 == 0.0:
            break
        t -= d1 / d2
    return max(float(x.max()), abs(float(_ivt.hb.eval_series(coeffs, t))))


def _dense_dofs(entry, n_dof, amplitude_dof, record_dofs):
    """dof_coeffs / amplitude of a dense solution's point (all DOFs known)."""
    coeffs = _np.asarray(entry["coeffs"])
    blocks = coeffs.reshape(n_dof, -1)
    record_dofs = [_index("record_dofs", j) for j in (record_dofs or ())]
    if amplitude_dof is not None:
        amplitude_dof = _index("amplitude_dof", amplitude_dof)
    for j in record_dofs + ([] if amplitude_dof is None else [amplitude_dof]):
        if not 0 <= j < n_dof:
            raise ValueError(f"DOF {j} is out of range for {n_dof} DOFs")
    entry["dof_coeffs"] = {int(j): blocks[j].copy() for j in (record_dofs or ())}
    if amplitude_dof is not None:
        entry["amplitude"] = _series_max(blocks[amplitude_dof])


def _large_call(native_name, sig, args, kwargs, extra):
    known = {k: v for k, v in kwargs.items() if k in sig.parameters}
    try:
        bound = sig.bind(*args, **known)
    except TypeError as e:
        raise TypeError(f"{native_name}: {e}") from None
    # What the caller gave (the condensed path's own defaults apply to the
    # rest), including the path keywords the native signature lacks.
    given = {**bound.arguments, **{k: v for k, v in kwargs.items() if k not in known}}
    bound.apply_defaults()
    a = _Namespace(**bound.arguments)
    dofs = extra.get("nonlinear_dofs")
    if dofs is None:
        raise ValueError(
            "a large model (sparse m/c/k or load-vector f) needs nonlinear_dofs=[...]: "
            "the DOFs g acts on (g then sees x, v of those DOFs only)"
        )
    n, m = _coo("m", a.m)
    nc, c = _coo("c", a.c)
    nk, k = _coo("k", a.k)
    if not n == nc == nk:
        raise ValueError(f"`m`, `c`, `k` must have one size, got {n}, {nc}, {nk}")
    kw = dict(
        amplitude_dof=(
            None if extra.get("amplitude_dof") is None else _index("amplitude_dof", extra["amplitude_dof"])
        ),
        record_dofs=[_index("record_dofs", j) for j in (extra.get("record_dofs") or ())],
        n=_index("n", given.get("n", 7)),
        samples=_index("samples", given.get("samples", 32)),
        velocity_dependent=bool(given.get("velocity_dependent", True)),
        vectorized=bool(given.get("vectorized", False)),
        jac=given.get("jac"),
        stability=bool(given.get("stability", True)),
    )
    if "rtol" in given:
        kw["rtol"] = float(given["rtol"])
    f = _loads(a.f, n) if a.f is not None else ([0.0] * n, [0.0] * n)
    dofs = [_index("nonlinear_dofs", j) for j in dofs]
    if native_name == "frc":
        for key in ("ds", "ds_min", "ds_max"):
            if given.get(key) is not None:
                kw[key] = float(given[key])
        return _ivt.hb.frc_large(n, m, c, k, a.g, f, a.omega_from, a.omega_to, dofs, **kw)
    return _ivt.hb.solve_large(n, m, c, k, a.g, f, a.omega_f, dofs, **kw)


def _with_large(native):
    """`native` (ivt.hb.frc or solve) extended by the keywords of issue 28:
    `nonlinear_dofs`, `amplitude_dof`, `record_dofs`; sparse m, c, k and
    load-vector `f` route to the condensed solver."""
    sig = _inspect.signature(native)

    def call(*args, nonlinear_dofs=None, amplitude_dof=None, record_dofs=None, **kwargs):
        extra = dict(nonlinear_dofs=nonlinear_dofs, amplitude_dof=amplitude_dof, record_dofs=record_dofs)
        bound = sig.bind_partial(*args, **{k: v for k, v in kwargs.items() if k in sig.parameters})
        m, f = bound.arguments.get("m"), bound.arguments.get("f")
        if _is_large(m, f, extra):
            return _large_call(native.__name__, sig, args, kwargs, extra)
        out = native(*args, **kwargs)
        if amplitude_dof is not None or record_dofs is not None:
            n_dof = _np.atleast_2d(_np.asarray(m, dtype=float)).shape[0]
            entries = out["points"] if "points" in out else [out]
            for e in entries:
                _dense_dofs(e, n_dof, amplitude_dof, record_dofs)
            if "points" in out and amplitude_dof is not None:
                out["amplitude"] = _np.array([e["amplitude"] for e in entries])
        return out

    params = list(sig.parameters.values()) + [
        _inspect.Parameter(name, _inspect.Parameter.KEYWORD_ONLY, default=None) for name in _LARGE_KEYS
    ]
    call.__signature__ = sig.replace(parameters=params)
    call.__name__ = native.__name__
    call.__qualname__ = native.__name__
    call.__doc__ = (native.__doc__ or "") + _LARGE_DOC
    return call


_LARGE_DOC = """

Large models (issue 28): `m`, `c`, `k` may be scipy.sparse matrices and `f`
an array F (F cos θ) or a pair (F_cos, F_sin) of load vectors; with
`nonlinear_dofs=[...]` the problem is condensed onto those DOFs (per harmonic
the linear DOFs decouple exactly; sparse LU of the dynamic stiffness with
refinement in double-double residuals) and `g(x, v, theta)` sees x, v of those
DOFs only. Defaults there: n = 7, samples = 32, rtol = 1e-12 (on the
receptance-form residual, relative to the larger of the start's linear
response and the point's own size). Each point then
carries "solve_error" (the refined solves'), "orbit_error" (the orbit's error
from the corrector residual and the refined solves), "data_error" (the first-order effect of storing M and C in
double precision), "truncation_error" and "error_estimate" (orbit_error +
truncation_error, a relative error). `amplitude_dof=j`: "amplitude" is max |x_j(τ)|;
`record_dofs=[...]`: each point carries "dof_coeffs": {j: [a0, a1..an,
b1..bn]} (any model). Stability (default on; `stability=False` skips it,
folds are located either way): Floquet multipliers of the whole structure's
variational equation on the Ritz vectors of the nonlinear DOFs (Krylov
blocks of K⁻¹M from the static modes, grown per point until the multipliers
move ≤ 1e-4 with the last block or the basis closes an invariant subspace; at
most 64 blocks; for proportional damping and a position-only g, Hsu by a
modal splitting): "multipliers", "stable",
"stability" and "multiplier_error" (basis truncation + Hsu estimates) per
point.
"""

frc = _with_large(_ivt.hb.frc)
solve = _with_large(_ivt.hb.solve)


def _cantilever(n_elements, length=1.0, ei=1.0, rho_a=1.0, alpha=0.07, beta=2e-4):
    """The Euler–Bernoulli cantilever of issue 28 (Hermite-cubic elements,
    consistent mass, clamped at x = 0, DOFs [w1, θ1, …, wN, θN],
    C = alpha·M + beta·K): returns (m, c, k, tip) with scipy.sparse CSR
    matrices and the index of the tip displacement."""
    import scipy.sparse as sp

    n, mats, tip = _ivt.hb.cantilever_coo(n_elements, length, ei, rho_a, alpha, beta)
    m, c, k = (sp.csr_matrix((v, (r, cc)), shape=(n, n)) for r, cc, v in mats)
    return m, c, k, tip


models = _Namespace(cantilever=_cantilever)
