"""`ivt.hb.duffing()` against a scipy-written harmonic balance, in one process.

    python bench/python_orbit.py [--calls 2000] [--rounds 5]

Both solve Fig. 28's orbit (Eq. 49 at ω_f = 0.4, ξ = 0.02, α = ε = 1, F = 0.1) with
n = 20 harmonics on 2N = 128 AFT samples from the one-harmonic guess: ivt with its
defaults (modified IHB + Broyden, then Floquet multipliers by Hsu's method; and
`stability=False`), scipy with `root`/hybr (MINPACK, difference Jacobian, xtol
1e-10) on a numpy AFT residual (`scipy_hb` of bench/periodic_work_precision.py).
Each round times `--calls` calls of each in turn and keeps the median; the rounds
alternate so that load changes hit both sides. Prints the medians and the ratio
per round. The numbers quoted in the guide were measured with this script and
are not asserted."""

import argparse
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import ivt  # noqa: E402
from periodic_work_precision import one_term_guess, scipy_hb  # noqa: E402

OMEGA, N, SAMPLES = 0.4, 20, 64


def median_call(fn, calls):
    times = []
    for _ in range(calls):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--calls", type=int, default=2000)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()

    a, b, _ = one_term_guess(OMEGA, "lower")
    q0 = np.zeros(2 * N + 1)
    q0[1], q0[N + 1] = a, b
    ours = ivt.hb.duffing()["coeffs"]
    theirs = scipy_hb(OMEGA, N, SAMPLES, q0, 1e-10)
    diff = float(np.max(np.abs(np.asarray(ours) - theirs)))
    print(f"max |coefficient difference| ivt vs scipy HB: {diff:.1e}")

    calls = {
        "ivt.hb.duffing()": lambda: ivt.hb.duffing(),
        "ivt.hb.duffing(stability=False)": lambda: ivt.hb.duffing(stability=False),
        "scipy HB (root/hybr)": lambda: scipy_hb(OMEGA, N, SAMPLES, q0, 1e-10),
    }
    for fn in calls.values():  # warm-up
        for _ in range(50):
            fn()
    print("round | " + " | ".join(calls) + " | scipy / ivt.hb.duffing()")
    for r in range(args.rounds):
        med = {name: median_call(fn, args.calls if "scipy" not in name else max(args.calls // 20, 50))
               for name, fn in calls.items()}
        cells = " | ".join(f"{1e6 * t:.1f} µs" for t in med.values())
        ratio = med["scipy HB (root/hybr)"] / med["ivt.hb.duffing()"]
        print(f"{r + 1} | {cells} | {ratio:.0f}×", flush=True)


if __name__ == "__main__":
    main()
