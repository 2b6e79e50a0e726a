"""Scaling of the condensed frequency response (issue 28): CPU time of the
cantilever's whole curve 0.7–1.3 ω₁ (tip cubic spring k3 = 200, F = 0.005,
folds located, per-point error estimates, Floquet multipliers at every
point) and per point, against n_dof = 100 … 2000 (n = 7 harmonics) and
against the harmonics n = 3 … 15 (n_dof = 1000), with the fitted exponents
of time per point, and a PNG of both.

    .venv/bin/python bench/large_scaling.py [--out bench/large_scaling.md] [--png bench/large_scaling.png]

Measured, not asserted (CPU time of this process: the machine is shared)."""

import argparse
import time

import numpy as np

import ivt

W1 = 3.516015268066119


def curve(n_elements, n=7, stability=True):
    m, c, k, tip = ivt.hb.models.cantilever(n_elements)
    f = np.zeros(m.shape[0])
    f[tip] = 0.005

    # The tip spring as a Rust element at the tip (a model DOF, the condensed
    # path's nonlinear DOF): no Python call per sample (a per-sample Python g with its jac
    # adds about a fifth on the 1000-DOF curve; test_hb_large.py checks that
    # both give the same curve).
    spring = ivt.hb.elements.cubic_spring(200.0, dof=tip)

    best = float("inf")
    for _ in range(2):  # the best of two: the first call also plans the FFTs
        t0 = time.process_time()
        out = ivt.hb.frc(m, c, k, spring, f, 0.7 * W1, 1.3 * W1, nonlinear_dofs=[tip],
                         n=n, samples=max(32, 4 * n + 4), stability=stability)
        best = min(best, time.process_time() - t0)
    return best, out


def row(label, cpu, out):
    pts = len(out["points"])
    folds = [f["omega"] for f in out["folds"] if f["located"]]
    err = max(p["error_estimate"] for p in out["points"])
    mu = [p["multiplier_error"] for p in out["points"] if p["multiplier_error"] is not None]
    print(label, f"{cpu:.3f} s", pts, f"{1e3 * cpu / pts:.2f} ms/pt", folds, flush=True)
    return dict(label=label, cpu=cpu, pts=pts, per=cpu / pts, folds=folds, err=err,
                mu=max(mu) if mu else float("nan"))


def table(rows, head):
    lines = [
        f"| {head} | curve CPU (s) | points | per point (ms) | folds (rad/s) | max point error est. | max multiplier error est. |",
        "| ---: | ---: | ---: | ---: | --- | ---: | ---: |",
    ]
    for r in rows:
        folds = ", ".join(f"{w:.10f}" for w in r["folds"])
        lines.append(f"| {r['label']} | {r['cpu']:.2f} | {r['pts']} | {1e3 * r['per']:.1f} | {folds} | "
                     f"{r['err']:.1e} | {r['mu']:.1e} |")
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/large_scaling.md")
    ap.add_argument("--png", default="bench/large_scaling.png")
    args = ap.parse_args()
    dofs = [row(n_dof, *curve(n_dof // 2)) for n_dof in (100, 200, 500, 1000, 2000)]
    harm = [row(n, *curve(500, n=n)) for n in (3, 5, 7, 11, 15)]
    nostab = row(1000, *curve(500, stability=False))
    slope_dof = np.polyfit(np.log([r["label"] for r in dofs]), np.log([r["per"] for r in dofs]), 1)[0]
    slope_n = np.polyfit(np.log([r["label"] for r in harm]), np.log([r["per"] for r in harm]), 1)[0]
    lines = ["Against n_dof (n = 7 harmonics, stability at every point):", ""]
    lines += table(dofs, "n_dof")
    lines += ["", f"Fitted exponent of time per point in n_dof (100–2000): {slope_dof:.2f}.", ""]
    lines += ["Against the harmonics n (n_dof = 1000, samples = max(32, 4n + 4)):", ""]
    lines += table(harm, "n")
    lines += ["", f"Fitted exponent of time per point in n (3–15): {slope_n:.2f}.", ""]
    lines += [f"n_dof = 1000, n = 7 without stability (`stability=False`): {nostab['cpu']:.2f} s CPU, "
              f"{nostab['pts']} points ({1e3 * nostab['per']:.1f} ms per point).", ""]
    lines += ["Measured, not asserted (CPU time of one Python process on a shared 2-core machine).", ""]
    text = "\n".join(lines)
    with open(args.out, "w") as fh:
        fh.write(text)
    print(text)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no PNG")
        return
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.loglog([r["label"] for r in dofs], [1e3 * r["per"] for r in dofs], "o-")
    a.set_xlabel("n_dof")
    a.set_ylabel("CPU per point (ms)")
    a.set_title(f"n = 7: exponent {slope_dof:.2f}")
    b.loglog([r["label"] for r in harm], [1e3 * r["per"] for r in harm], "s-")
    b.set_xlabel("harmonics n")
    b.set_title(f"n_dof = 1000: exponent {slope_n:.2f}")
    for ax in (a, b):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)


if __name__ == "__main__":
    main()
