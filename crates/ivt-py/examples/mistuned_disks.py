"""Mistuned bladed disks on a Dask cluster: the distribution of the peak
amplification (issue 46).

pyHarm's 24-sector lumped bladed disk (``ivt.hb.models.bladed_disk``, tutorial
006) with the cubic spring 5e10·x³ and the force F = 1 at sector 0's blade
tip, its frequency response through the blade-mode resonance (1150–1260
rad/s) on the exact condensed path. Each disk's 24 blade stiffnesses are drawn
uniformly within ±SPREAD of nominal (``ivt.sweep.draws``, seeded); the peak
amplification is the peak tip amplitude of the mistuned disk over the tuned
disk's. The disks run on a dask process ``LocalCluster`` of WORKERS workers
(``--workers 0``: one local thread, the serial baseline).

    python crates/ivt-py/examples/mistuned_disks.py                # 200 disks, 2 workers
    python crates/ivt-py/examples/mistuned_disks.py --disks 20 --plot amplification.png
"""

import argparse
import time
from typing import Any, Dict, List, Tuple

import numpy as np
import numpy.typing as npt

import ivt

FloatArray = npt.NDArray[np.float64]
# The tutorial's frequency band (the blade-dominated modes of the tuned disk
# lie at 1189–1230 rad/s), the condensed path's defaults (n = 7, samples = 32),
# folds located, no Floquet multipliers (the peak does not need them), steps of
# at most 2 % of the band: the peaks are sharp (ζ ≈ 0.12 %), and a hardening
# peak next to its fold is left as sampled; at the default 15 % every curve
# still reaches its peak (the stepper rejects a step that jumps across one),
# within 2.3e-3 on 40 disks (tests/test_sweep_hb.py, measured).
OPTIONS: Dict[str, Any] = dict(
    omega_from=1150.0, omega_to=1260.0, vectorized=True, stability=False, ds_max=0.02
)


def tip_spring(x: FloatArray, v: FloatArray, theta: FloatArray) -> FloatArray:
    """The cubic spring 5e10·x³ at the blade tip (g sees the tip DOF only)."""
    return 5e10 * x**3


def disk(blade_stiffness: FloatArray) -> Tuple[Any, Any, Any, Any, FloatArray, int]:
    """A disk of the given blade stiffness factors: (m, c, k, g, F, tip)."""
    m, c, k, tip = ivt.hb.models.bladed_disk(blade_stiffness)
    f = np.zeros(m.shape[0])
    f[tip] = 1.0
    return m, c, k, tip_spring, f, tip


def peak(result: Dict[str, Any]) -> float:
    """The curve's largest tip amplitude: its points' and its located folds'."""
    folds = [float(e["amplitude"]) for e in result["folds"]]
    return max([float(np.max(result["amplitude"]))] + folds)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--disks", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2,
                        help="dask worker processes (0: one local thread)")
    parser.add_argument("--spread", type=float, default=0.03, help="blade stiffness ±spread (uniform)")
    parser.add_argument("--seed", type=int, default=46)
    parser.add_argument("--plot", help="write a histogram of the amplification to this PNG")
    args = parser.parse_args()

    m, c, k, g, f, tip = disk(np.ones(24))
    options = dict(OPTIONS, nonlinear_dofs=[tip], amplitude_dof=tip)
    tuned = peak(ivt.hb.frc(m, c, k, g, f, **options))
    sets = ivt.sweep.draws({"blade_stiffness": np.ones(24)}, {"blade_stiffness": args.spread},
                           n=args.disks, seed=args.seed)
    models: List[Tuple[Any, ...]] = [disk(s["blade_stiffness"])[:5] for s in sets]

    start = time.perf_counter()
    if args.workers > 0:
        import distributed

        cluster = distributed.LocalCluster(  # type: ignore[no-untyped-call]
            n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
        with cluster, distributed.Client(cluster) as client:  # type: ignore[no-untyped-call]
            setup = time.perf_counter() - start
            start = time.perf_counter()
            results = ivt.sweep.hb("frc", models, client=client, progress="disks", **options)
    else:
        setup = 0.0
        results = ivt.sweep.hb("frc", models, max_workers=1, progress="disks", **options)
    elapsed = time.perf_counter() - start

    # A curve that reversed before the band's end missed part of it: left out.
    crossed = [r for r in results if r["omega"][-1] == OPTIONS["omega_to"]]
    amplification = np.array([peak(r) for r in crossed]) / tuned
    q = np.percentile(amplification, [0, 5, 50, 95, 100])
    print(f"tuned peak tip amplitude {tuned:.6e} m")
    print(f"{len(crossed)} of {args.disks} disks crossed the band "
          f"({args.disks - len(crossed)} curves reversed early, left out)")
    print(f"blade stiffness ±{args.spread:.0%}: peak amplification "
          f"min {q[0]:.4f}, 5 % {q[1]:.4f}, median {q[2]:.4f}, 95 % {q[3]:.4f}, max {q[4]:.4f}")
    print(f"{args.workers or 'local'} worker(s): {elapsed:.2f} s for the sweep "
          f"({elapsed / args.disks * 1e3:.0f} ms per disk), {setup:.2f} s to start the cluster")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.hist(amplification, bins=20)
        ax.set_xlabel("peak amplification (mistuned / tuned peak tip amplitude)")
        ax.set_ylabel("disks")
        fig.tight_layout()
        fig.savefig(args.plot)


if __name__ == "__main__":
    main()
