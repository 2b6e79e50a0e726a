"""Many nonlinear DOFs on a large solid (issue 42, item 4): a patch of Jenkins
elements on the steel cantilever plate of `large_fe.py` (scikit-fem
tetrahedra, 1 × 0.2 × 0.02 m, clamped at x = 0, C = 2·0.005·ω₁·M, unit force
at the tip corner's vertical DOF, ω 0.8–1.3 ω₁). Each element (stiffness
0.01·k_tip, k_tip the tip's static stiffness, slip force 0.02 N) joins the
axial (x) DOF of one top-face node to the ground; the patch is the top-face
nodes nearest the free end. `ivt.hb.frc` with its defaults (the reduced path,
n = 7), with and without stability at every point.

    .venv/bin/python bench/large_patch.py [--out bench/large_patch.md] [--nx 40] \
        [--elements 5 10 20 40] [--timeout 600]

Each case runs in a child process (its CPU time and peak RSS are its own); a
case that does not finish within the timeout is recorded as such. Measured,
not asserted; the load average is printed with each row."""

import argparse
import datetime
import multiprocessing as mp
import os
import resource
import time

import numpy as np
import scipy.sparse.linalg as spla

LENGTH, WIDTH, HEIGHT = 1.0, 0.2, 0.02


def plate_with_nodes(nx):
    """The plate of `ivt.hb.models.plate(nx)` with its mesh: (m, k, tip, mesh, dof)."""
    import skfem

    import ivt

    ny = max(1, nx // 5)
    mesh = skfem.MeshTet.init_tensor(np.linspace(0, LENGTH, nx + 1), np.linspace(0, WIDTH, ny + 1),
                                     np.linspace(0, HEIGHT, 3))
    m, k, _, dof = ivt.hb.models.solid(mesh, lambda x: np.isclose(x[0], 0.0))
    corner = int(np.argmin(np.sum((mesh.p.T - np.array([LENGTH, WIDTH, HEIGHT])) ** 2, axis=1)))
    return m, k, dof(corner, 2), mesh, dof


def case(nx, elements, stability, queue):
    import ivt

    m, k, tip, mesh, dof = plate_with_nodes(nx)
    w1 = float(np.sqrt(spla.eigsh(k.tocsc(), 1, m.tocsc(), sigma=0.0, which="LM")[0][0]))
    e = np.zeros(m.shape[0])
    e[tip] = 1.0
    k_tip = 1.0 / spla.spsolve(k.tocsc(), e)[tip]
    top = np.nonzero(np.isclose(mesh.p[2], HEIGHT) & ~np.isclose(mesh.p[0], 0.0))[0]
    top = top[np.argsort(-mesh.p[0, top], kind="stable")][:elements]
    patch = None
    for node in top:
        j = ivt.hb.elements.jenkins(0.01 * k_tip, 0.02, dof=dof(int(node), 0))
        patch = j if patch is None else patch + j
    c = (2.0 * 0.005 * w1) * m
    f = np.zeros(m.shape[0])
    f[tip] = 1.0
    cpu, wall = time.process_time(), time.perf_counter()
    out = ivt.hb.frc(m, c, k, patch, f, 0.8 * w1, 1.3 * w1, stability=stability)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    pts = out["points"]
    row = dict(n_dof=m.shape[0], elements=len(top), stability=stability, cpu=cpu, wall=wall,
               points=len(pts), method=out.get("method"), basis=out.get("reduction", {}).get("basis"),
               folds=len(out["folds"]),
               mu=max(p["multiplier_error"] for p in pts) if stability else None,
               uncertain=sum(p["stability"] == "uncertain" for p in pts) if stability else None,
               rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, load=os.getloadavg()[0])
    queue.put(row)


def run(nx, elements, stability, timeout):
    queue = mp.Queue()
    proc = mp.Process(target=case, args=(nx, elements, stability, queue))
    proc.start()
    proc.join(timeout)
    if proc.is_alive():
        proc.kill()
        proc.join()
        row = dict(elements=elements, stability=stability, timeout=timeout, load=os.getloadavg()[0])
    else:
        row = queue.get() if not queue.empty() else dict(elements=elements, stability=stability,
                                                         failed=proc.exitcode)
    print(row, flush=True)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench/large_patch.md")
    ap.add_argument("--nx", type=int, default=40)
    ap.add_argument("--elements", type=int, nargs="+", default=[5, 10, 20, 40])
    ap.add_argument("--timeout", type=float, default=600.0)
    args = ap.parse_args()
    rows = [run(args.nx, n, stability, args.timeout) for n in args.elements for stability in (False, True)]
    lines = [
        f"A patch of Jenkins elements on the plate (issue 42, item 4), measured "
        f"{datetime.date.today().isoformat()} on the shared 2-core machine (not asserted; "
        f"`bench/large_patch.py --nx {args.nx}`).",
        "",
        "| DOFs | elements | stability | curve (s CPU / wall) | points | method | basis | folds | "
        "max multiplier error | uncertain | peak RSS (MB) | load |",
        "| ---: | ---: | --- | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        if "cpu" not in r:
            why = f"not finished in {r['timeout']:.0f} s" if "timeout" in r else f"failed ({r['failed']})"
            lines.append(f"| | {r['elements']} | {r['stability']} | {why} | | | | | | | | {r['load']:.1f} |")
            continue
        mu = "" if r["mu"] is None else f"{r['mu']:.1e}"
        unc = "" if r["uncertain"] is None else str(r["uncertain"])
        lines.append(
            f"| {r['n_dof']} | {r['elements']} | {r['stability']} | {r['cpu']:.2f} / {r['wall']:.2f} | "
            f"{r['points']} | {r['method']} | {r['basis']} | {r['folds']} | {mu} | {unc} | {r['rss']:.0f} | "
            f"{r['load']:.1f} |"
        )
    with open(args.out + ".tmp", "w") as fh:
        fh.write("\n".join(lines) + "\n")
    os.replace(args.out + ".tmp", args.out)


if __name__ == "__main__":
    main()
