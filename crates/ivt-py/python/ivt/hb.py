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

_native = _ivt.hb

duffing = _native.duffing
duffing_frc = _native.duffing_frc
mathieu_duffing = _native.mathieu_duffing
solve = _native.solve
frc = _native.frc
limit_cycle = _native.limit_cycle
eval_series = _native.eval_series
ConvergenceError = _native.ConvergenceError

__all__ = [
    "ConvergenceError",
    "duffing",
    "duffing_frc",
    "eval_series",
    "frc",
    "limit_cycle",
    "mathieu_duffing",
    "solve",
]
