"""The long references of issue 45, by scipy alone, beside ivt's answers.

Run by hand (not in CI; about four minutes):  .venv/bin/python bench/qp_references.py

1. The forced Van der Pol oscillator x″ − μ(1 − x²)x′ + x = F cos ωt
   (μ = F = 0.2) at ω = 0.93 and 0.90, below its Neimark–Sacker point:
   DOP853 (rtol 1e-12) over 300 periods of transient and 1500 measured; the
   rotation number of the stroboscopic (Poincaré) map from the angles of its
   points about their centre, the mean of |x| over time and its maximum,
   each average weighted by exp(−1/(s(1 − s))) (the weighted Birkhoff
   average of Das, Sander & Yorke, super-polynomially convergent), |x|
   integrated by Gauss–Legendre between its zeros. Beside them: the torus of
   `ivt.hb.torus_branch` from the located Neimark–Sacker point.
   crates/ivt-jobs/tests/torus.rs computes the same reference with RK6 in CI;
   crates/ivt-py/tests/test_hb_qp.py holds these numbers.
2. The wall time of `ivt.hb.event_sensitivity` on the thesis Duffing's folds
   against one `frc` that locates them (measured, not asserted).
"""

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from ivt import hb

MU = F = 0.2


def bump(s):
    s = np.asarray(s, dtype=float)
    out = np.zeros_like(s)
    inside = (s > 0) & (s < 1)
    out[inside] = np.exp(-1.0 / (s[inside] * (1.0 - s[inside])))
    return out


def reference(omega, transient=300, periods=1500, pieces=64):
    def rhs(t, y):
        return [y[1], MU * (1 - y[0] ** 2) * y[1] - y[0] + F * math.cos(omega * t)]

    period = 2 * math.pi / omega
    y = solve_ivp(rhs, (0, transient * period), [0.5, 0.0], method="DOP853", rtol=1e-12, atol=1e-13).y[:, -1]
    run = solve_ivp(rhs, (0, periods * period), y, method="DOP853", rtol=1e-12, atol=1e-13, dense_output=True)
    section = run.sol(np.arange(periods + 1) * period).T
    w = bump((np.arange(periods) + 0.5) / periods)
    w /= w.sum()
    centre = (w[:, None] * section[:-1]).sum(0)
    angle = np.unwrap(np.arctan2(section[:, 1] - centre[1], section[:, 0] - centre[0]))
    rho = abs(np.sum(w * np.diff(angle))) / (2 * math.pi)
    nodes, weights = np.polynomial.legendre.leggauss(12)
    total = periods * period
    t = np.linspace(0, total, periods * pieces + 1)
    x, v = run.sol(t)
    num = den = top = 0.0

    def bisect(a, b, component):
        f0 = run.sol(a)[component]
        for _ in range(60):
            mid = 0.5 * (a + b)
            if run.sol(mid)[component] * f0 > 0:
                a = mid
            else:
                b = mid
        return 0.5 * (a + b)

    for k in range(len(t) - 1):
        a, b = t[k], t[k + 1]
        cuts = [a, bisect(a, b, 0), b] if x[k] * x[k + 1] < 0 else [a, b]
        for p, q in zip(cuts[:-1], cuts[1:]):
            s = 0.5 * (p + q) + 0.5 * (q - p) * nodes
            ws = bump(s / total)
            num += np.sum(weights * ws * np.abs(run.sol(s)[0])) * 0.5 * (q - p)
            den += np.sum(weights * ws) * 0.5 * (q - p)
        if v[k] * v[k + 1] < 0:
            top = max(top, abs(run.sol(bisect(a, b, 1))[0]))
    return rho, num / den, top


def main():
    g = lambda x, v, th: MU * x**2 * v  # noqa: E731
    f = lambda th: F * np.cos(th)  # noqa: E731
    frc = hb.frc(1.0, -MU, 1.0, g, f, 0.6, 1.6, n=12, samples=32, vectorized=True)
    [ns] = [b for b in frc["bifurcations"] if b["kind"] == "neimark_sacker"]
    t0 = time.perf_counter()
    tor = hb.torus_branch(1.0, -MU, 1.0, g, f, ns, 0.89, at=[0.93, 0.90], n=12, samples=32, vectorized=True)
    print(f"torus branch from ω = {ns['omega']:.8f}: {len(tor['points'])} points, "
          f"{time.perf_counter() - t0:.1f} s")
    print("| ω | | rotation number | mean abs x | max abs x |")
    print("|---|---|---|---|---|")
    for p in tor["at"]:
        rho, mean, top = reference(p["omega"])
        print(f"| {p['omega']} | scipy | {rho:.10f} | {mean:.10f} | {top:.10f} |")
        print(f"| | ivt ({p['truncation']}) | {p['rotation_number']:.10f} | {p['amplitude_mean']:.10f} | "
              f"{p['amplitude_max']:.10f} |")
        print(f"| | estimates | {p['errors']['rotation_number']:.1e} | {p['errors']['amplitude_mean']:.1e} | "
              f"{p['errors']['amplitude_max']:.1e} |")

    duffing = lambda force: (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0),  # noqa: E731
                             lambda th: force * np.cos(th))
    t0 = time.perf_counter()
    curve = hb.frc(*duffing(0.1), 0.5, 2.5, n=20, events=False)
    t_frc = time.perf_counter() - t0
    for fold in curve["folds"]:
        t0 = time.perf_counter()
        s = hb.event_sensitivity(duffing, fold, 0.1, n=20)
        print(f"fold at {s['omega']:.8f}: dω/dF {s['d_omega_dp']:.10f} in {1e3 * (time.perf_counter() - t0):.2f} ms "
              f"(the whole frc with its two folds: {1e3 * t_frc:.1f} ms)")


if __name__ == "__main__":
    main()
