"""Calling overhead of ivt.hb.duffing against the Rust benchmark.

    .venv/bin/python crates/ivt-py/benches/bench_duffing.py [--rust]

Times `ivt.hb.duffing(n=20, samples=64, omega_f=0.4)` (Fig. 28 point) with and
without the Floquet multipliers, the general solver with a Python callback,
and — with --rust — runs `cargo bench -p ivt-hb --bench hb` for the Rust
medians (divan) to compare. Medians of many calls; the machine may be loaded.
"""

import statistics
import subprocess
import sys
import time
from typing import Callable

import numpy as np

import ivt


def median_us(fn: Callable[[], object], repeat: int = 200) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e6


def main() -> None:
    rows = [
        ("duffing(stability=False)", lambda: ivt.hb.duffing(stability=False)),
        ("duffing() incl. Hsu 256", lambda: ivt.hb.duffing()),
        ("solve_time_s reported inside", None),
        (
            "solve(g=Python callable)",
            lambda: ivt.hb.solve(
                1.0, 0.04, 1.0, lambda x, v, t: x**3, 0.4,
                f=lambda t: 0.1 * np.cos(t), velocity_dependent=False, stability=False,
            ),
        ),
    ]
    inner = statistics.median(
        ivt.hb.duffing(stability=False)["solve_time_s"] for _ in range(200)
    ) * 1e6
    print(f"{'call':36s} {'median µs':>10s}")
    for name, fn in rows:
        if fn is None:
            print(f"{name:36s} {inner:10.1f}")
            continue
        reps = 20 if "callable" in name else 300
        print(f"{name:36s} {median_us(fn, reps):10.1f}")
    if "--rust" in sys.argv:
        out = subprocess.run(
            ["cargo", "bench", "-p", "ivt-hb", "--bench", "hb", "--", "duffing"],
            capture_output=True, text=True,
        )
        print(out.stdout)


if __name__ == "__main__":
    main()
