"""Scaling of large solids (issue 42): the steel cantilever plate of scikit-fem
tetrahedra (1 × 0.2 × 0.02 m, E = 210 GPa, ν = 0.3, ρ = 7800 kg/m³, clamped at
x = 0, C = 2·0.005·ω₁·M, cubic spring k3 = 1.5e-4·k_tip³ to ground at the tip
corner's vertical DOF, unit force there, ω 0.8–1.3 ω₁, n = 7) at about 3 k,
30 k and 100 k DOFs, and a second geometry (an L-bracket, scikit-fem mesh with
elements removed): time to reduce, the curve with stability at every point,
per point, peak memory, the reduction's certificate; the exact condensed path
beside it as far as it goes (the whole 3 k curve, one 30 k point).

    .venv/bin/python bench/large_fe.py [--out bench/large_fe.md] [--png bench/large_fe.png] [--sizes 40 125 235]

Each case runs in a child process (its peak RSS is its own). Measured, not
asserted: CPU time of the child (process_time) and wall time on a shared
2-core machine; the load average is printed with each row."""

import argparse
import datetime
import multiprocessing as mp
import os
import resource
import time

import numpy as np
import scipy.sparse.linalg as spla

ZETA = 0.005


def first_frequency(m, k):
    return float(np.sqrt(spla.eigsh(k.tocsc(), 1, m.tocsc(), sigma=0.0, which="LM")[0][0]))


def k3_for(k, tip):
    e = np.zeros(k.shape[0])
    e[tip] = 1.0
    return 1.5e-4 / spla.spsolve(k.tocsc(), e)[tip] ** 3


def bracket(n):
    """An L-bracket: 0.3 × 0.3 m legs 0.1 m wide, 0.02 m thick, clamped at the
    end y = 0.3 of one leg; tip: the vertical DOF at (0.3, 0, 0.02)."""
    import skfem

    import ivt

    mesh = skfem.MeshTet.init_tensor(np.linspace(0, 0.3, n + 1), np.linspace(0, 0.3, n + 1),
                                     np.linspace(0, 0.02, 3))
    centre = mesh.p[:, mesh.t].mean(axis=1)
    mesh = mesh.remove_elements(np.nonzero((centre[0] > 0.1) & (centre[1] > 0.1))[0])
    m, k, _, dof = ivt.hb.models.solid(mesh, lambda x: np.isclose(x[1], 0.3))
    corner = int(np.argmin(np.sum((mesh.p.T - np.array([0.3, 0.0, 0.02])) ** 2, axis=1)))
    return m, k, dof(corner, 2)


def case(kind, size, exact, queue):
    import ivt

    t0 = time.perf_counter()
    m, k, tip = ivt.hb.models.plate(size) if kind == "plate" else bracket(size)
    w1 = first_frequency(m, k)
    k3 = k3_for(k, tip)
    c = (2.0 * ZETA * w1) * m
    f = np.zeros(m.shape[0])
    f[tip] = 1.0
    setup = time.perf_counter() - t0
    rss_model = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    spring = ivt.hb.elements.cubic_spring(k3, dof=tip)
    cpu, wall = time.process_time(), time.perf_counter()
    out = ivt.hb.frc(m, c, k, spring, f, 0.8 * w1, 1.3 * w1, nonlinear_dofs=[tip], reduction="krylov")
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    r = out["reduction"]
    pts = out["points"]
    row = dict(kind=kind, n_dof=m.shape[0], w1=w1, k3=k3, setup=setup, cpu=cpu, wall=wall,
               reduce_wall=r["seconds"], points=len(pts), basis=r["basis"], modes=r["modes"],
               error=r["error_estimate"], sampled=[s["error"] for s in r["sampled"]],
               folds=[fd["omega"] / w1 for fd in out["folds"]],
               located=[fd["located"] for fd in out["folds"]],
               mu=max(p["multiplier_error"] for p in pts),
               uncertain=sum(p["stability"] == "uncertain" for p in pts),
               flips=sum(a["stability"] != b["stability"] for a, b in zip(pts, pts[1:])),
               rss_model=rss_model, rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
               load=os.getloadavg()[0])
    if exact == "curve":
        cpu = time.process_time()
        ex = ivt.hb.frc(m, c, k, spring, f, 0.8 * w1, 1.3 * w1, nonlinear_dofs=[tip], reduction="exact",
                        stability=False)
        row["exact_cpu"] = time.process_time() - cpu
        row["exact_points"] = len(ex["points"])
        row["exact_folds"] = [fd["omega"] / w1 for fd in ex["folds"]]
    elif exact == "point":
        cpu = time.process_time()
        ivt.hb.solve(m, c, k, spring, w1, f, nonlinear_dofs=[tip], stability=False)
        row["exact_point_cpu"] = time.process_time() - cpu
    queue.put(row)


def run(kind, size, exact):
    queue = mp.Queue()
    proc = mp.Process(target=case, args=(kind, size, exact, queue))
    proc.start()
    proc.join()
    row = queue.get() if not queue.empty() else None
    if row is not None:
        print(row, flush=True)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/large_fe.md")
    ap.add_argument("--png", default="bench/large_fe.png")
    ap.add_argument("--sizes", type=int, nargs="+", default=[40, 125, 235])
    ap.add_argument("--bracket", type=int, default=60)
    args = ap.parse_args()
    exact = {40: "curve", 125: "point"}
    rows = [run("plate", s, exact.get(s)) for s in args.sizes]
    rows.append(run("bracket", args.bracket, None))
    rows = [r for r in rows if r is not None]
    today = datetime.date.today().isoformat()
    lines = [
        f"Large solids (issue 42), measured {today} on the shared 2-core machine (not asserted).",
        "",
        "| model | DOFs | ω₁ (rad/s) | k3 (N/m³) | reduce (s wall) | reduce + curve (s CPU / wall) | points | "
        "(reduce + curve) / points (ms CPU) | basis | modes | receptance error est. | sampled errors | folds / ω₁ | "
        "max multiplier error | uncertain | stability flips | peak RSS (MB) | load |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        per = 1e3 * r["cpu"] / max(r["points"], 1)
        folds = ", ".join(f"{w:.6f}" + ("" if ok else " (not located)") for w, ok in zip(r["folds"], r["located"]))
        sampled = ", ".join(f"{e:.1e}" for e in r["sampled"])
        lines.append(
            f"| {r['kind']} | {r['n_dof']} | {r['w1']:.3f} | {r['k3']:.3e} | {r['reduce_wall']:.2f} | "
            f"{r['cpu']:.2f} / {r['wall']:.2f} | {r['points']} | {per:.1f} | {r['basis']} | {r['modes']} | "
            f"{r['error']:.1e} | {sampled} | {folds} | {r['mu']:.1e} | {r['uncertain']} | {r['flips']} | "
            f"{r['rss']:.0f} | {r['load']:.1f} |"
        )
    lines.append("")
    for r in rows:
        if "exact_cpu" in r:
            folds = ", ".join(f"{w:.8f}" for w in r["exact_folds"])
            lines.append(f"Exact condensed path, {r['n_dof']} DOFs: whole curve without stability "
                         f"{r['exact_cpu']:.1f} s CPU, {r['exact_points']} points "
                         f"({1e3 * r['exact_cpu'] / r['exact_points']:.0f} ms per point), folds / ω₁ {folds}.")
        if "exact_point_cpu" in r:
            lines.append(f"Exact condensed path, {r['n_dof']} DOFs: one orbit at ω₁ without stability "
                         f"{r['exact_point_cpu']:.1f} s CPU.")
    lines.append("")
    lines.append("Peak RSS includes scikit-fem's assembly and scipy's eigsh for ω₁ (setup, not timed).")
    text = "\n".join(lines) + "\n"
    with open(args.out, "w") as fh:
        fh.write(text)
    print(text)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    plates = [r for r in rows if r["kind"] == "plate"]
    fig, ax = plt.subplots(figsize=(5, 3.6))
    n = [r["n_dof"] for r in plates]
    ax.loglog(n, [r["reduce_wall"] for r in plates], "o-", label="reduce (wall)")
    ax.loglog(n, [r["cpu"] for r in plates], "s-", label="reduce + curve (CPU)")
    ax.loglog(n, [r["cpu"] / r["points"] for r in plates], "^-", label="(reduce + curve) / points (CPU)")
    ax.set_xlabel("DOFs")
    ax.set_ylabel("s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.png, dpi=100)


if __name__ == "__main__":
    main()
