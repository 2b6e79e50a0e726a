"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability,
frequency-response curves with located folds, and limit cycles, for Duffing,
Mathieu–Duffing and user systems.

Coefficient convention (as ``ivt hb ... --json``): ``[a0, a1..an, b1..bn]``
per DOF with ``u(τ) = a0/2 + Σ a_k cos kτ + b_k sin kτ``, τ = ω t; a
multi-DOF vector is the DOF blocks one after the other (``eval_series(...,
n_dof=)`` evaluates it). User callbacks: ``g(x, v, theta)`` with v = dx/dt and
theta = ω_f t; with ``vectorized=True`` x, v have shape (N, n_dof) and theta
shape (N,) for all N AFT samples, and g returns (N, n_dof).
All solvers release the GIL; :func:`solve` re-acquires it only to call the
user's Python callbacks. Non-convergence raises :class:`ConvergenceError`
whose ``history`` attribute is the residual norm per iteration.
"""

from . import _ivt
from ._reexport import reexport


__all__ = [
    "ConvergenceError",
    "duffing",
    "duffing_frc",
    "eval_series",
    "frc",
    "limit_cycle",
    "mathieu_cascade",
    "mathieu_duffing",
    "solve",
]

reexport(globals(), _ivt.hb, __all__)
