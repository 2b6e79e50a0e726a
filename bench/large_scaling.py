"""Scaling of the condensed frequency response (issue 28): CPU time of the
cantilever's whole curve 0.7–1.3 ω₁ (tip cubic spring k3 = 200, F = 0.005,
n = 7 harmonics, folds located, per-point error estimates) and per point,
against n_dof = 100 … 2000, with the fitted exponent of time per point.

    .venv/bin/python bench/large_scaling.py [--out bench/large_scaling.md]

Measured, not asserted (CPU time of this process: the machine is shared)."""

import argparse
import time

import numpy as np

import ivt

W1 = 3.516015268066119


def curve(n_elements):
    m, c, k, tip = ivt.hb.models.cantilever(n_elements)
    f = np.zeros(m.shape[0])
    f[tip] = 0.005

    def g(x, v, t):
        return 200.0 * x**3

    def jac(x, v, t):
        return np.array([[600.0 * x[0] ** 2]]), np.zeros((1, 1))

    t0 = time.process_time()
    out = ivt.hb.frc(m, c, k, g, f, 0.7 * W1, 1.3 * W1, jac=jac, nonlinear_dofs=[tip])
    return time.process_time() - t0, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/large_scaling.md")
    args = ap.parse_args()
    rows = []
    for n_dof in (100, 200, 500, 1000, 2000):
        cpu, out = curve(n_dof // 2)
        pts = len(out["points"])
        folds = [f["omega"] for f in out["folds"] if f["located"]]
        rows.append((n_dof, cpu, pts, cpu / pts, folds))
        print(n_dof, f"{cpu:.3f} s", pts, f"{1e3 * cpu / pts:.2f} ms/pt", folds, flush=True)
    x = np.log([r[0] for r in rows])
    y = np.log([r[3] for r in rows])
    slope = np.polyfit(x, y, 1)[0]
    lines = [
        "| n_dof | curve CPU (s) | points | per point (ms) | folds (rad/s) |",
        "| ---: | ---: | ---: | ---: | --- |",
    ]
    for n_dof, cpu, pts, per, folds in rows:
        lines.append(f"| {n_dof} | {cpu:.2f} | {pts} | {1e3 * per:.1f} | {', '.join(f'{w:.10f}' for w in folds)} |")
    lines.append("")
    lines.append(f"Fitted exponent of time per point in n_dof (100–2000): {slope:.2f}.")
    text = "\n".join(lines) + "\n"
    with open(args.out, "w") as fh:
        fh.write(text)
    print(text)


if __name__ == "__main__":
    main()
