"""scipy side of the work–precision study (see bench/work_precision.sh).

Same problem as `ivt bench work-precision` (crates/ivt-sim/src/work_precision.rs):
Eq. 151 of the printed plant in the angle domain (θ independent, state [t, ω]),
V_m = 8.6 V, T_U = 6 N·m, r = 6 mm, ω(0) = 8 rad/s; the quantity is
ω_a = 2π/(t(Θ) − t(Θ − 2π)) at Θ = 100 rad. Each solver integrates to Θ − 2π
and then on to Θ (two solve_ivp calls, both endpoints exact, both timed), as the
Rust integrator does. scipy does not know the corners of f(θ) at π/4 + kπ/2;
its error control has to find them.
"""
import json
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

A = math.pi / (2 * math.sqrt(2))  # Eq. 43 amplitude


def make_rhs(pl, pr):
    ja, jb, jc, jd = pl["j_a"], pl["j_b"], pl["j_c"], pl["j_d"]
    g, cd, cv, cl = pl["g"], pl["motor_damping"], pl["motor_gain"], pl["load_gain"]
    r, vm, tu = pr["r"], pr["v_m"], pr["t_u"]

    def rhs(theta, z):
        w = z[1]
        phi = (theta + math.pi / 4) % (math.pi / 2) - math.pi / 4  # Eq. 139
        f, ft = A * math.cos(phi), -A * math.sin(phi)
        j = ja + jb * r * r + jc * r * r * f * f + jd * f * f
        jt = 2 * (jc * r * r + jd) * f * ft
        gam = g * (math.sin(theta) + math.cos(theta)) * r + cv * f * vm - cl * f * tu * r
        acc = (gam - 0.5 * jt * w * w - cd * f * f * w) / j
        return [1.0 / w, acc / w]

    return rhs


def omega_a(rhs, pr, method, tol):
    th1 = pr["theta_end"] - 2 * math.pi
    a = solve_ivp(rhs, (0.0, th1), [0.0, pr["omega_start"]], method=method, rtol=tol, atol=tol)
    b = solve_ivp(rhs, (th1, pr["theta_end"]), a.y[:, -1], method=method, rtol=tol, atol=tol)
    if not (a.success and b.success):
        return float("nan"), 0
    return 2 * math.pi / (b.y[0, -1] - a.y[0, -1]), a.nfev + b.nfev


def timed(fn, budget=1.0):
    best, spent, n, out = float("inf"), 0.0, 0, None
    while n < 1 or (spent < budget and n < 5):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        best, spent, n = min(best, dt), spent + dt, n + 1
    return out, best


def main():
    study = json.load(open(sys.argv[1]))
    png = sys.argv[2] if len(sys.argv) > 2 else None
    pr, ref = study["problem"], study["reference"]
    rhs = make_rhs(study["plant"], pr)
    rows = [dict(method=r["method"], tol=r["tolerance"], time=r["run_time_s"], err=r["error"]) for r in study["rows"]]
    for method in ["RK45", "DOP853", "LSODA"]:
        for e in range(3, 13):
            tol = 10.0 ** -e
            (w, nfev), t = timed(lambda: omega_a(rhs, pr, method, tol))
            rows.append(dict(method=method, tol=tol, time=t, err=abs(w - ref)))
            print(f"{method:7s} tol {tol:.0e}: {t:.3e} s, err {abs(w - ref):.2e}, nfev {nfev}", file=sys.stderr)
    print(f"reference ω_a = {ref:.15f} rad/s (check {study['reference_check']:.1e})\n")
    print("| method | tol / h | run time [s] | error in ω_a [rad/s] |")
    print("|---|---|---|---|")
    for r in rows:
        print(f"| {r['method']} | {r['tol']:.1e} | {r['time']:.3e} | {r['err']:.2e} |")
    # speed-up at equal error ≤ 1e-8: fastest run of each family reaching it
    def fastest(pred):
        c = [r["time"] for r in rows if pred(r) and r["err"] <= 1e-8]
        return min(c) if c else float("inf")
    ours = fastest(lambda r: r["method"] in ("dp5", "rk4"))
    theirs = {m: fastest(lambda r, m=m: r["method"] == m) for m in ["RK45", "DOP853", "LSODA"]}
    best = min(theirs.values())
    print(f"\nfastest run with error ≤ 1e-8: ivt-sim {ours:.3e} s; scipy "
          + ", ".join(f"{m} {t:.3e} s" for m, t in theirs.items())
          + f"; speed-up vs the fastest scipy method: {best / ours:.0f}×")
    if png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 5))
        for m in ["dp5", "rk4", "RK45", "DOP853", "LSODA"]:
            pts = sorted((r["err"], r["time"]) for r in rows if r["method"] == m and r["err"] > 0)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=("ivt-sim " if m in ("dp5", "rk4") else "scipy ") + m)
        ax.set_xlabel("error in ω_a after ≈ 10 s [rad/s]")
        ax.set_ylabel("run time [s]")
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        ax.set_title("Work–precision, printed plant Eq. 151 (angle domain)")
        fig.tight_layout()
        fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
