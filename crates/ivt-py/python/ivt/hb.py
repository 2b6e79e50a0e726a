"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability and
frequency-response curves, for Duffing, Mathieu–Duffing and user systems.

Coefficient convention (as ``ivt hb ... --json``): ``[a0, a1..an, b1..bn]``
per DOF with ``u(τ) = a0/2 + Σ a_k cos kτ + b_k sin kτ``, τ = ω t.
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
eval_series = _native.eval_series
ConvergenceError = _native.ConvergenceError

__all__ = [
    "ConvergenceError",
    "duffing",
    "duffing_frc",
    "eval_series",
    "mathieu_duffing",
    "solve",
]
