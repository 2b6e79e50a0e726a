"""FRC comparisons of the periodic-orbit benchmark (periodic_work_precision.py
runs them unless --quick): the thesis Duffing FRC and the 2-DOF cubic chain,
ivt's continuation (Hsu stability at every point) beside pyHarm's arc-length
continuation (no stability)."""

import math
import sys
import time

import numpy as np

import ivt
from periodic_common import ALPHA, EPS, FORCE, PYHARM_SOLVERS, XI, hb_samples, pyharm_input, pyharm_to_ivt, timed


def pyharm_curve(m, c, k, cubic, n, omega_from, omega_to, ds_max, solver="scipyroot"):
    """pyHarm FRC by its arc-length continuation (tangent predictor; corrector
    iterations by `solver` at tolerance 1e-10, default root/hybr), ds0 = ds_max / 5.
    Returns time, accepted points as (ω, unknowns) and the number of ω turns (folds)."""
    from pyHarm.Maestro import Maestro

    n_dof = np.atleast_2d(m).shape[0]
    mae = Maestro(pyharm_input(m, c, k, cubic, FORCE, n, 2 * hb_samples(n), omega_from, omega_to, 1e-10,
                               dict(ds_max=ds_max, ds0=ds_max / 5), solver=solver))
    frf = mae.nls["frf"]
    t0 = time.perf_counter()
    frf.Solve()
    elapsed = time.perf_counter() - t0
    pts = [s.x for s in frf.SolList if s.flag_accepted]
    omegas = np.array([x[-1] for x in pts])
    amps = [math.hypot(*pyharm_to_ivt(x, n, n_dof)[[1, n + 1]]) for x in pts]
    turns = omegas[1:-1][np.diff(np.sign(np.diff(omegas))) != 0].tolist()
    return dict(time=elapsed, points=len(pts), omegas=omegas, xs=pts, peak=max(amps), folds=turns)


# ---------------------------------------------------------------------------
# FRC comparisons


def fold_omegas(folds):
    """ω of each fold: plain floats (duffing_frc) or dicts with "omega" (SPEC §6 frc)."""
    return [float(f["omega"]) if isinstance(f, dict) else float(f) for f in folds]


def duffing_frc_rows(n, ds_max):
    """Thesis Duffing 0.2–3.0: ivt.hb.duffing_frc (its own step control, Hsu
    stability at every point) against pyHarm's continuation (no stability) with
    each of its nonlinear solvers; `pyharm` is the default (scipy root/hybr),
    `pyharm_solvers` every solver, timed right after an ivt run of its own."""
    def ivt_curve():
        return timed(lambda: ivt.hb.duffing_frc(from_=0.2, to=3.0, n=n, samples=hb_samples(n), xi=XI,
                                                alpha=ALPHA, eps=EPS, force=FORCE), budget=1.0)

    out, t_ivt = ivt_curve()
    solvers = {}
    for solver in PYHARM_SOLVERS:
        _, t_mine = ivt_curve()
        try:
            ph = pyharm_curve(1.0, 2 * XI, ALPHA, EPS, n, 0.2, 3.0, ds_max, solver=solver)
        except Exception as e:  # a solver that fails on this curve: say so, time the others
            solvers[solver] = dict(error=f"{type(e).__name__}: {e}")
            continue
        solvers[solver] = dict(time=ph["time"], points=ph["points"], folds=ph["folds"], peak=ph["peak"],
                               ivt_time=t_mine, ratio=ph["time"] / t_mine)
    ph = solvers["scipyroot"]
    return dict(problem="Duffing FRC 0.2–3.0", n=n, samples=hb_samples(n),
                ivt=dict(time=t_ivt, points=len(out["points"]), folds=fold_omegas(out["folds"]),
                         peak=max(p["amplitude"] for p in out["points"]), stability=True),
                pyharm=dict(time=ph.get("time"), points=ph.get("points"), folds=ph.get("folds"),
                            peak=ph.get("peak"), ds_max=ds_max, stability=False),
                pyharm_solvers=solvers)


CHAIN_M = np.eye(2)
CHAIN_C = 0.02 * np.eye(2)
CHAIN_K = np.array([[2.0, -1.0], [-1.0, 2.0]])


def chain_g(x, v, theta):
    return [0.5 * x[0] ** 3, 0.0]


def chain_g_vec(x, v, t):
    out = np.zeros_like(x)
    out[:, 0] = 0.5 * x[:, 0] ** 3
    return out


def chain_jac_vec(x, v, t):
    """(∂g/∂x, ∂g/∂v) of chain_g_vec at the N samples: (N, 2, 2) and None."""
    dg_dx = np.zeros((x.shape[0], 2, 2))
    dg_dx[:, 0, 0] = 1.5 * x[:, 0] ** 2
    return dg_dx, None


def chain_f(theta):
    return [FORCE * math.cos(theta), 0.0]


def chain_diff(coeffs, x, n):
    """Max coefficient difference between an ivt orbit (DOF-major [a0, a.., b..]
    per DOF) and a pyHarm one."""
    q = np.asarray(coeffs).reshape(2, 2 * n + 1)
    return max(float(np.max(np.abs(q[d] - pyharm_to_ivt(x, n, 2, d)))) for d in range(2))


def chain_rows(n, ds_max, omega_from, omega_to):
    """2-DOF cubic chain. With ivt.hb.frc: whole curves side by side. Without it:
    ivt.hb.solve (Python per-sample g) at every ω of pyHarm's path, in path order,
    warm-started from the previous ivt orbit, and compared with pyHarm's orbit."""
    ph = pyharm_curve(CHAIN_M, CHAIN_C, CHAIN_K, 0.5, n, omega_from, omega_to, ds_max)
    row = dict(problem=f"2-DOF chain {omega_from}–{omega_to}", n=n, samples=hb_samples(n),
               pyharm=dict(time=ph["time"], points=ph["points"], folds=ph["folds"], peak=ph["peak"],
                           ds_max=ds_max, stability=False))
    why = "no ivt.hb.frc on this build"
    if hasattr(ivt.hb, "frc"):
        try:
            # events=False: folds only, the work of duffing_frc; events=True adds the
            # period-doubling, Neimark–Sacker and branch-point tests at every point.
            # jac: the user's ∂g/∂x (vectorized), used by every Jacobian assembly
            # in place of differencing g.
            for key, events, jac in (("ivt", False, None), ("ivt_events", True, None),
                                     ("ivt_jac", False, chain_jac_vec), ("ivt_jac_events", True, chain_jac_vec)):
                out, t = timed(lambda: ivt.hb.frc(CHAIN_M, CHAIN_C, CHAIN_K, chain_g_vec, chain_f, omega_from,
                                                  omega_to, n=n, samples=hb_samples(n), velocity_dependent=False,
                                                  vectorized=True, events=events, jac=jac),
                               budget=1.0)
                with_jac = ", vectorized jac" if jac is not None else ""
                row[key] = dict(mode=f"ivt.hb.frc, vectorized g{with_jac}, events={events}", time=t,
                                points=len(out["points"]), folds=fold_omegas(out["folds"]),
                                peak=max(p["amplitude"] for p in out["points"]), stability=True)
            return row
        except Exception as e:  # an API this script does not know: say so, measure per-ω solves
            why = f"ivt.hb.frc failed: {type(e).__name__}: {e}"
            print(why, file=sys.stderr)
    guess, diffs, t_total, solved, other_branch = None, [], 0.0, 0, []
    for omega, x in zip(ph["omegas"], ph["xs"]):
        t0 = time.perf_counter()
        try:
            sol = ivt.hb.solve(CHAIN_M, CHAIN_C, CHAIN_K, chain_g, float(omega), f=chain_f, n=n,
                               samples=hb_samples(n), guess=guess, stability=False, velocity_dependent=False)
        except ivt.hb.ConvergenceError:
            t_total += time.perf_counter() - t0
            guess = None
            continue
        t_total += time.perf_counter() - t0
        solved += 1
        guess = sol["coeffs"]
        diffs.append(chain_diff(sol["coeffs"], x, n))
        if diffs[-1] >= 1e-6:
            other_branch.append((float(omega), x))
    # Where the warm-started sweep landed elsewhere, is pyHarm's orbit an ivt orbit too?
    # Untimed: solve again from pyHarm's orbit and compare.
    same_when_seeded = 0
    for omega, x in other_branch:
        seed = np.concatenate([pyharm_to_ivt(x, n, 2, d) for d in range(2)])
        try:
            sol = ivt.hb.solve(CHAIN_M, CHAIN_C, CHAIN_K, chain_g, omega, f=chain_f, n=n, samples=hb_samples(n),
                               guess=seed, stability=False, velocity_dependent=False)
        except ivt.hb.ConvergenceError:
            continue
        same_when_seeded += chain_diff(sol["coeffs"], x, n) < 1e-6
    row["ivt"] = dict(mode=f"ivt.hb.solve per ω ({why}), Python per-sample g", time=t_total,
                      points=solved, folds=[], peak=None, stability=False,
                      max_coeff_diff_vs_pyharm=max(diffs) if diffs else None,
                      agree_1e6=sum(d < 1e-6 for d in diffs), agree_when_seeded=int(same_when_seeded))
    return row
