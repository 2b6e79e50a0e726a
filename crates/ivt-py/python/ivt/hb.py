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
    "max_amplitude", "newton_steps", "exhausted", "failures_per_start",
    "copies_merged", "bound"} ("bound" states in words what "exhausted"
    refers to)."""

    def __init__(self, solutions: list, search: dict) -> None:  # type: ignore[type-arg]
        super().__init__(solutions)
        self.search = search


def all_solutions(
    m, c, k, g, f, omega, n=20, samples=None, max_amplitude=10.0, amplitudes=6,
    newton_steps=60, tol=0.0, velocity_dependent=True, vectorized=False,
    rtol=1e-9, max_iter=100, jac=None,
):  # type: ignore[no-untyped-def]
    """Every period-one solution at ``omega`` that deflated Newton finds
    within bounded starts (see ``ivt._ivt.hb._all_solutions``): a list of
    {"coeffs", "amplitude", "multipliers", "stable", "stability"} by
    increasing size, with ``.search`` = {"starts", "runs", "max_amplitude",
    "newton_steps", "exhausted", "failures_per_start", "copies_merged",
    "bound"}. Time-shifted copies of an autonomous problem's orbits are
    merged; an undamped linear resonance with nothing found raises
    ValueError naming the harmonic."""
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
import os as _os
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

_LARGE_KEYS = ("nonlinear_dofs", "amplitude_dof", "record_dofs", "reduction", "reduction_tol",
               "reduction_samples")

# The exact condensed path keeps narrow-banded structures (half-bandwidth at most
# this: the beams) and small ones (below _REDUCE_FROM DOFs); "auto" reduces the rest.
_BAND = 16
_REDUCE_FROM = 1000
# From this many DOFs on, "krylov" checks at 2 sampled frequencies, not 3.
_FEWER_CHECKS = 50_000


def _matrix(name, a):
    """`a`, or the matrix in the Matrix Market file `a` names (str or path)."""
    if isinstance(a, (str, _os.PathLike)):
        import scipy.io

        try:
            return scipy.io.mmread(_os.fspath(a))
        except (OSError, ValueError) as e:
            raise ValueError(f"argument `{name}`: cannot read Matrix Market file {a!r}: {e}") from None
    return a


def _coo_arrays(name, a):
    """n and the COO arrays (rows, cols, values: int64, int64, float64) of a
    scipy.sparse or dense matrix or a Matrix Market file; complex entries
    (structural damping K(1 + iη)) are refused."""
    a = _matrix(name, a)
    if hasattr(a, "tocoo"):
        c = a.tocoo()
        rows, cols, vals = c.row, c.col, c.data
        shape = c.shape
    else:
        arr = _np.atleast_2d(_np.asarray(a))
        shape = arr.shape
        if arr.ndim != 2:
            raise ValueError(f"argument `{name}` must be square, got shape {shape}")
        rows, cols = _np.nonzero(arr)
        vals = arr[rows, cols]
    if len(shape) != 2 or shape[0] != shape[1]:
        raise ValueError(f"argument `{name}` must be square, got shape {shape}")
    if _np.iscomplexobj(vals):
        raise ValueError(
            f"argument `{name}` is complex: its imaginary part would be dropped. Complex inputs are "
            "refused (structural damping K(1 + iη) included: give a real damping matrix c, e.g. "
            "c = η·k/ω at one frequency ω, or Rayleigh c = α·m + β·k)"
        )
    return shape[0], (
        _np.ascontiguousarray(rows, dtype=_np.int64),
        _np.ascontiguousarray(cols, dtype=_np.int64),
        _np.ascontiguousarray(vals, dtype=_np.float64),
    )


def _coo(name, a):
    """COO triplets (rows, cols, values) as lists, for the exact path."""
    n, (rows, cols, vals) = _coo_arrays(name, a)
    return n, (rows.tolist(), cols.tolist(), vals.tolist())


def _half_bandwidth(coo):
    rows, cols, _ = coo
    return int(_np.max(_np.abs(rows - cols))) if len(rows) else 0


def _loads(f, n):
    """(F_cos, F_sin) from an array F (F cos θ) or a pair (F_cos, F_sin)."""
    parts = f if isinstance(f, (tuple, list)) and len(f) == 2 and _np.ndim(f[0]) == 1 else (f,)
    if any(_np.iscomplexobj(v) for v in parts):
        raise ValueError("argument `f` is complex: its imaginary part would be dropped; give real load vectors "
                         "(F_cos, F_sin) for a phase")
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
    files = isinstance(m, (str, _os.PathLike))
    return hasattr(m, "tocoo") or files or loads or extra.get("nonlinear_dofs") is not None


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


# The keywords the condensed (large-model) path reads; any other keyword is
# refused there, not ignored (issue 41).
_LARGE_PATH_KEYS = {
    "solve": {"m", "c", "k", "g", "omega_f", "f", "n", "samples", "velocity_dependent", "vectorized",
              "jac", "stability", "rtol"},
    "frc": {"m", "c", "k", "g", "f", "omega_from", "omega_to", "n", "samples", "velocity_dependent",
            "vectorized", "jac", "stability", "rtol", "ds", "ds_min", "ds_max", "max_points", "truncation_estimate"},
}


def _refuse_keys(native_name, given, sig):
    """TypeError for a keyword neither function knows (a misspelling), ValueError
    for one of the dense path's that the large-model path does not read."""
    allowed = _LARGE_PATH_KEYS[native_name]
    unknown = sorted(k for k in given if k not in allowed and k not in sig.parameters)
    if unknown:
        raise TypeError(f"{native_name}() got unexpected keyword argument(s) {', '.join(map(repr, unknown))}")
    inapplicable = sorted(k for k in given if k not in allowed)
    if inapplicable:
        raise ValueError(
            f"{native_name}: {', '.join(map(repr, inapplicable))} do(es) not apply to a large model "
            f"(sparse m/c/k, load-vector f or nonlinear_dofs: the condensed path); it reads "
            f"{', '.join(sorted(allowed - {'m', 'c', 'k', 'g', 'f'}))}"
        )


def _large_samples(given):  # type: ignore[no-untyped-def]
    """The large-model path's N: as given, or 32 (its default for n ≤ 7)
    and the same proportion, 32/7·n rounded up, above, so that every n works
    without ``samples``."""
    samples = given.get("samples")
    if samples is not None:
        return _index("samples", samples)
    n = _index("n", given.get("n", 7))
    return max(32, -(-32 * n // 7))


def _large_call(native_name, sig, args, kwargs, extra):
    known = {k: v for k, v in kwargs.items() if k in sig.parameters}
    try:
        bound = sig.bind(*args, **known)
    except TypeError as e:
        raise TypeError(f"{native_name}: {e}") from None
    # What the caller gave (the condensed path's own defaults apply to the
    # rest), including the path keywords the native signature lacks.
    given = {**bound.arguments, **{k: v for k, v in kwargs.items() if k not in known}}
    _refuse_keys(native_name, given, sig)
    bound.apply_defaults()
    a = _Namespace(**bound.arguments)
    dofs = extra.get("nonlinear_dofs")
    g = a.g
    if isinstance(g, Elements):
        # An element's dof/to name model DOFs on every path (issue 46): the
        # condensed path takes its nonlinear DOFs from the elements and sees
        # them at their positions in that list.
        if dofs is None:
            dofs = g.dofs
        g = g.restricted([_index("nonlinear_dofs", j) for j in dofs])
    elif dofs is None:
        raise ValueError(
            "a large model (sparse m/c/k or load-vector f) with a Python g needs nonlinear_dofs=[...]: "
            "the DOFs g acts on (g then sees x, v of those DOFs only); ivt.hb.elements name "
            "their model DOFs themselves"
        )
    n, m = _coo_arrays("m", a.m)
    nc, c = _coo_arrays("c", a.c)
    nk, k = _coo_arrays("k", a.k)
    if not n == nc == nk:
        raise ValueError(f"`m`, `c`, `k` must have one size, got {n}, {nc}, {nk}")
    reduction = extra.get("reduction") or "auto"
    if reduction not in ("auto", "exact", "krylov"):
        raise ValueError(f"argument `reduction` must be 'auto', 'exact' or 'krylov', got {reduction!r}")
    if reduction == "auto":
        banded = _half_bandwidth(k) <= _BAND
        reduce = native_name == "frc" and not banded and n >= _REDUCE_FROM
        reduction = "krylov" if reduce else "exact"
    if reduction == "krylov" and native_name != "frc":
        raise ValueError("reduction='krylov' is available for frc; solve runs the exact condensed path")
    kw = dict(
        amplitude_dof=(
            None if extra.get("amplitude_dof") is None else _index("amplitude_dof", extra["amplitude_dof"])
        ),
        record_dofs=[_index("record_dofs", j) for j in (extra.get("record_dofs") or ())],
        n=_index("n", given.get("n", 7)),
        samples=_large_samples(given),
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
        if given.get("max_points") is not None:
            kw["max_points"] = _index("max_points", given["max_points"])
    if reduction == "krylov":
        if extra.get("reduction_tol") is not None:
            kw["reduction_tol"] = float(extra["reduction_tol"])
        samples = extra.get("reduction_samples")
        # An exact check is a complex sparse LU of the whole structure: about
        # 9 s CPU at 100 k DOFs, three quarters of the reduction there.
        kw["reduction_samples"] = (
            _index("reduction_samples", samples) if samples is not None else (3 if n < _FEWER_CHECKS else 2)
        )
        return _ivt.hb.frc_reduced(n, m, c, k, g, f, a.omega_from, a.omega_to, dofs, **kw)
    m, c, k = ((r.tolist(), cc.tolist(), v.tolist()) for r, cc, v in (m, c, k))
    if native_name == "frc":
        kw["truncation_estimate"] = bool(given.get("truncation_estimate", True))
        out = _ivt.hb.frc_large(n, m, c, k, g, f, a.omega_from, a.omega_to, dofs, **kw)
    else:
        out = _ivt.hb.solve_large(n, m, c, k, g, f, a.omega_f, dofs, **kw)
    out["method"] = "exact"
    out["reduction"] = None
    return out


def _with_large(native):
    """`native` (ivt.hb.frc or solve) extended by the keywords of issue 28:
    `nonlinear_dofs`, `amplitude_dof`, `record_dofs`; sparse m, c, k and
    load-vector `f` route to the condensed solver."""
    sig = _inspect.signature(native)

    def call(*args, nonlinear_dofs=None, amplitude_dof=None, record_dofs=None, reduction=None,
             reduction_tol=None, reduction_samples=None, **kwargs):
        extra = dict(nonlinear_dofs=nonlinear_dofs, amplitude_dof=amplitude_dof, record_dofs=record_dofs,
                     reduction=reduction, reduction_tol=reduction_tol, reduction_samples=reduction_samples)
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
                # the folds and events are measured as the points are
                for e in [*out.get("folds", []), *out.get("bifurcations", [])]:
                    if isinstance(e, dict) and e.get("coeffs") is not None:
                        blocks = _np.asarray(e["coeffs"]).reshape(n_dof, -1)
                        e["amplitude"] = _series_max(blocks[_index("amplitude_dof", amplitude_dof)])
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
refinement in double-double residuals) and a Python `g(x, v, theta)` sees x, v
of those DOFs only. With `ivt.hb.elements` as `g`, each element's `dof`/`to`
names a model DOF, as on a dense model, and the nonlinear DOFs are the
elements' own (`g.dofs`); `nonlinear_dofs`, if given, must hold them all. Defaults there: n = 7, samples = 32, rtol = 1e-12 (on the
receptance-form residual, relative to the larger of the start's linear
response and the point's own size). Each point then
carries "solve_error" (the refined solves'), "orbit_error" (the orbit's error
from the corrector residual and the refined solves), "data_error" (the first-order effect of storing M and C in
double precision), "truncation_error" and "error_estimate" (orbit_error +
truncation_error, a relative error; a curve's `truncation_estimate=False`
skips the truncation estimate, most of a curve's cost without stability,
and leaves both None). `amplitude_dof=j`: "amplitude" is max |x_j(τ)|;
`record_dofs=[...]`: each point carries "dof_coeffs": {j: [a0, a1..an,
b1..bn]} (any model). With `amplitude_dof` the folds' and events'
"amplitude" is that DOF's too. Stability (default on; `stability=False` skips it,
folds are located either way): Floquet multipliers of the whole structure's
variational equation on the Ritz vectors of the nonlinear DOFs (Krylov
blocks of K⁻¹M from the static modes, grown per point until the multipliers
move ≤ 1e-4 with the last block or the basis closes an invariant subspace; at
most 64 blocks; for proportional damping and a position-only g, Hsu by a
modal splitting): "multipliers", "stable",
"stability" and "multiplier_error" (basis truncation + Hsu estimates) per
point.

Keywords of the dense path that the condensed path does not read
(`subharmonic`, `guess`, `method`, `tol`, `max_iter`, `events`) raise
ValueError there, unknown ones TypeError; complex m, c, k or loads raise
ValueError.

Large solids (issue 42): m, c, k may also be Matrix Market files (paths), as
FE codes export them (real entries; complex structural damping is refused).
`reduction="auto"` (the default) keeps the exact condensed path for
narrow-banded structures (half-bandwidth ≤ 16, e.g. beams), for models below
1000 DOFs and for `solve`, and otherwise reduces once (`"krylov"`): block
Lanczos in shift-invert mode at σ = 0 (one sparse Cholesky factorization of
K, which must be positive definite: a clamped structure) from the static modes
of the nonlinear DOFs and the load, grown until its Ritz values pass
1.5·n·ω_max and the receptances at the nonlinear DOFs change by less than
`reduction_tol`/10 (default tol 1e-8) from one block fewer over every harmonic
band, then checked by exact sparse solves at `reduction_samples` frequencies
(default 3, or 2 from 50 000 DOFs on); the curve runs on the reduced model. The result carries "method"
("exact" or "reduced") and "reduction" (None, or {"method", "n_dof", "basis",
"blocks", "modes", "cutoff", "first_frequency", "error_estimate",
"nested_change", "sampled": [{"omega", "harmonic", "omega_f", "error",
"solve_error"}]}); each point's "error_estimate" includes the reduction's
receptance error, "multiplier_error" its effect on max |μ|
("reduction_multiplier_error"), and "stability" is "uncertain" (and "stable"
None) where max |μ| lies within "multiplier_error" of 1.
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


def _scikit_fem():
    """The scikit-fem module, or an ImportError saying how to install it."""
    try:
        import skfem
    except ImportError as e:
        raise ImportError(
            "ivt.hb.models.plate and solid assemble with scikit-fem, an optional extra: "
            "pip install 'ivt[fe]' (or pip install scikit-fem)"
        ) from e
    return skfem


def _solid(mesh, clamped, young=210e9, poisson=0.3, density=7800.0):
    """Linear elasticity with the consistent mass on a scikit-fem tetrahedral
    (or any 3-D) mesh, P1 vector elements, SI units: returns (m, k, xyz, dof)
    with scipy.sparse CSR m and k of the free DOFs (those not at the nodes
    where ``clamped(x)`` holds, x of shape (3, N)), xyz (n_dof, 3) the node
    coordinates of each free DOF and dof(node, direction) its index (-1 if
    clamped). Needs scikit-fem (``pip install 'ivt[fe]'``)."""
    import numpy as np

    skfem = _scikit_fem()
    from skfem.helpers import dot
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    element = {4: skfem.ElementTetP1, 8: skfem.ElementHex1}.get(mesh.t.shape[0], skfem.ElementTetP1)
    basis = skfem.Basis(mesh, skfem.ElementVector(element()))
    k = linear_elasticity(*lame_parameters(young, poisson)).assemble(basis)

    @skfem.BilinearForm
    def mass(u, v, w):
        return density * dot(u, v)

    m = mass.assemble(basis)
    fixed = basis.get_dofs(clamped).all()
    free = np.setdiff1d(np.arange(basis.N), fixed)
    index = -np.ones(basis.N, dtype=np.int64)
    index[free] = np.arange(free.size)
    nodal = basis.nodal_dofs  # (3, n_nodes)
    xyz = np.zeros((basis.N, 3))
    for d in range(3):
        xyz[nodal[d]] = mesh.p.T
    m, k = (a.tocsr()[free][:, free].tocsr() for a in (m, k))

    def dof(node, direction):
        return int(index[nodal[direction, node]])

    return m, k, xyz[free], dof


def _plate(nx, ny=None, nz=2, size=(1.0, 0.2, 0.02), young=210e9, poisson=0.3, density=7800.0):
    """Issue 42's steel cantilever plate (1 × 0.2 × 0.02 m, E = 210 GPa,
    ν = 0.3, ρ = 7800 kg/m³) of nx × ny × nz hexahedra split into six
    tetrahedra each (scikit-fem's ``MeshTet.init_tensor``), clamped at x = 0:
    returns (m, k, tip), tip the vertical DOF of the corner (L, W, H).
    ny defaults to nx // 5. Needs scikit-fem (``pip install 'ivt[fe]'``)."""
    import numpy as np

    skfem = _scikit_fem()

    ny = max(1, nx // 5) if ny is None else ny
    lx, ly, lz = size
    mesh = skfem.MeshTet.init_tensor(
        np.linspace(0.0, lx, nx + 1), np.linspace(0.0, ly, ny + 1), np.linspace(0.0, lz, nz + 1)
    )
    m, k, _, dof = _solid(mesh, lambda x: np.isclose(x[0], 0.0), young, poisson, density)
    corner = int(np.argmin(np.sum((mesh.p.T - np.array([lx, ly, lz])) ** 2, axis=1)))
    return m, k, dof(corner, 2)


def _bladed_disk(blade_stiffness=None):
    """pyHarm's 24-sector lumped bladed disk of issue 28 (tutorial 006):
    sectors of three DOFs [disk, blade root, blade tip], M = diag(1.2, 0.35,
    0.25), disk-to-ground 6e5, disk-root 1e6, root-tip 2e6, neighbouring
    disks joined by 5e7 (cyclically), C = 2e-6 K. ``blade_stiffness``: 24
    factors scaling each sector's blade springs (stiffness mistuning; None or
    all ones: the tuned disk). Returns (m, c, k, tip) with scipy.sparse CSR
    matrices and the index of sector 0's blade tip (DOF 2), where the
    tutorial's force and cubic spring 5e10·x³ act."""
    import scipy.sparse as sp

    factors = None if blade_stiffness is None else [float(v) for v in _np.ravel(blade_stiffness)]
    n, mats, tip = _ivt.hb.bladed_disk_coo(factors)
    m, c, k = (sp.csr_matrix((v, (r, cc)), shape=(n, n)) for r, cc, v in mats)
    return m, c, k, tip


models = _Namespace(cantilever=_cantilever, solid=_solid, plate=_plate, bladed_disk=_bladed_disk)


# --- pickling of element sums (dask ships models to worker processes) --------

import copyreg as _copyreg


def _elements_from_state(state):
    """The sum of elements that ``Elements._state()`` lists, rebuilt by the
    constructors (the inverse of the pickling below)."""
    out = None
    for name, params, dof, to in state:
        e = getattr(elements, name)(*params, dof=dof, to=to)
        out = e if out is None else out + e
    return out


_copyreg.pickle(Elements, lambda e: (_elements_from_state, (e._state(),)))
