"""pyHarm (pyharm-os) on issue 28's cantilever "as far as it gets": the same
beam (dense M, C, K of ivt.hb.models.cantilever), cubic spring 200 x³ and
force 0.005 cos ωt at the tip, n = 7 harmonics, its arc-length FRF over
0.7–1.3 ω₁ (no stability: pyHarm's FRF has none by default), CPU time per
curve against n_dof, each size in a child process with a time budget.

    .venv/bin/python bench/large_pyharm.py [--budget 120] [--sizes 5 25 50 100]

Measured, not asserted (CPU time on a shared 2-core machine)."""

import argparse
import multiprocessing as mp
import time

import numpy as np

import ivt
from periodic_common import hb_samples, pyharm_input

W1 = 3.516015268066119
N_HARM = 7


def run(n_elements, queue):
    from pyHarm.Maestro import Maestro

    m, c, k, tip = ivt.hb.models.cantilever(n_elements)
    m, c, k = (a.toarray() for a in (m, c, k))
    inp = pyharm_input(m, c, k, 200.0, 0.005, N_HARM, 2 * hb_samples(N_HARM), 0.7 * W1, 1.3 * W1,
                       1e-10, dict(ds_max=0.05, ds0=0.01))
    inp["substructures"]["sub"]["ndofs"] = 1
    for name in ("cubic", "force"):
        inp["connectors"][name]["connect"] = {"sub": [tip]}
    t0 = time.process_time()
    mae = Maestro(inp)
    frf = mae.nls["frf"]
    frf.Solve()
    cpu = time.process_time() - t0
    pts = [s.x for s in frf.SolList if s.flag_accepted]
    omegas = np.array([x[-1] for x in pts])
    turns = omegas[1:-1][np.diff(np.sign(np.diff(omegas))) != 0].tolist()
    queue.put(dict(cpu=cpu, points=len(pts), last=float(omegas[-1]) if len(pts) else float("nan"),
                   folds=turns))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--budget", type=float, default=120.0)
    ap.add_argument("--sizes", type=int, nargs="+", default=[5, 25, 50, 100])
    args = ap.parse_args()
    print("| n_dof | pyHarm curve CPU (s) | points | per point (ms) | reached ω (rad/s) | ω turns |")
    print("| ---: | ---: | ---: | ---: | ---: | --- |")
    for n_el in args.sizes:
        queue = mp.Queue()
        proc = mp.Process(target=run, args=(n_el, queue))
        proc.start()
        proc.join(args.budget)
        if proc.is_alive():
            proc.terminate()
            proc.join()
            print(f"| {2 * n_el} | > {args.budget:.0f} (stopped) | – | – | – | – |", flush=True)
            break
        r = queue.get() if not queue.empty() else None
        if r is None:
            print(f"| {2 * n_el} | failed | – | – | – | – |", flush=True)
            break
        per = 1e3 * r["cpu"] / max(r["points"], 1)
        turns = ", ".join(f"{w:.6f}" for w in r["folds"])
        print(f"| {2 * n_el} | {r['cpu']:.2f} | {r['points']} | {per:.1f} | {r['last']:.4f} | {turns} |",
              flush=True)


if __name__ == "__main__":
    main()
