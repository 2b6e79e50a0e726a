"""Shared by the periodic-orbit benchmarks (periodic_work_precision.py and
periodic_frc.py): the thesis Duffing's parameters, best-of timing, the AFT
sample count, and the translation to and from pyHarm's input and unknowns."""

import time

import numpy as np

XI, ALPHA, EPS, FORCE = 0.02, 1.0, 1.0, 0.1
GRID = 256  # reference grid points over one period


# ---------------------------------------------------------------------------
# Timing


def timed(fn, budget=0.5, max_runs=5):
    """Best-of wall time: repeat fn until `budget` seconds or `max_runs` calls."""
    best, spent, n, out = float("inf"), 0.0, 0, None
    while n < 1 or (spent < budget and n < max_runs):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        best, spent, n = min(best, dt), spent + dt, n + 1
    return out, best


def hb_samples(n):
    """N of the AFT (2N time points): 2N > 4n keeps the cubic term alias-free."""
    return 2 * n + 2


# ---------------------------------------------------------------------------
# pyHarm (pyharm-os): the same systems through its input dictionary. pyHarm's
# unknowns per harmonic block are all DOFs of [mean, cos 1, sin 1, cos 2, ...],
# x = c0 + Σ c_k cos kωt + s_k sin kωt (its own DFT operator), ω last.


# pyHarm's nonlinear solvers (its `solver` keyword) and the options that set
# each one's tolerance to `tol`.
PYHARM_SOLVERS = {
    "scipyroot": lambda tol: {"root": {"options": {"xtol": tol}}},
    "NewtonRaphson": lambda tol: {"tol_residual": tol, "tol_delta_x": tol},
    "MoorePenrose": lambda tol: {"tol_residual": tol, "tol_delta_x": tol},
}


def pyharm_input(m, c, k, cubic, force, n, nti, omega_from, omega_to, xtol, frc_options=None,
                 solver="scipyroot"):
    """Maestro input: one linear substructure (M, C, K), a cubic spring on DOF 0 to
    ground, a cosine force on DOF 0; an 'frf' analysis (arc-length continuation,
    tangent predictor) whose corrector iterations use `solver` at tolerance xtol
    (default scipy root/hybr)."""
    analysis = {"study": "frf", "puls_inf": omega_from, "puls_sup": omega_to, "verbose": False,
                "solver": solver, "solver_options": PYHARM_SOLVERS[solver](xtol)}
    analysis.update(frc_options or {})
    return {
        "system": {"type": "Base", "nh": n, "nti": nti},
        "substructures": {"sub": {"type": "substructure", "ndofs": 1,
                                  "matrix": {"M": np.atleast_2d(m), "C": np.atleast_2d(c), "K": np.atleast_2d(k)}}},
        "connectors": {
            "cubic": {"type": "CubicSpring", "connect": {"sub": [0]}, "dirs": [0], "k": cubic},
            "force": {"type": "CosinusForcing", "connect": {"sub": [0]}, "dirs": [0], "amp": force},
        },
        "analysis": {"frf": analysis},
    }


def pyharm_to_ivt(x, n, n_dof, dof=0):
    """pyHarm unknowns (ω dropped) → ivt's [a0, a1..an, b1..bn] of one DOF."""
    blocks = np.asarray(x[: n_dof * (2 * n + 1)]).reshape(2 * n + 1, n_dof)[:, dof]
    return np.concatenate([[2 * blocks[0]], blocks[1::2], blocks[2::2]])


def ivt_to_pyharm(q, n):
    out = np.empty(2 * n + 1)
    out[0], out[1::2], out[2::2] = q[0] / 2, q[1:n + 1], q[n + 1:]
    return out
