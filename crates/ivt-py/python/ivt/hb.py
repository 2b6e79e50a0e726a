"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability,
frequency-response curves with located folds, period doublings,
Neimark–Sacker and branch points (:func:`frc`), and limit cycles, for Duffing,
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
    "damped_modes",
    "duffing",
    "duffing_frc",
    "eval_series",
    "frc",
    "limit_cycle",
    "mathieu_cascade",
    "mathieu_duffing",
    "solve",
    "string",
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
