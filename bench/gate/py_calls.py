"""The Python calls of the benchmark gate (scripts/bench-gate): each is what a
user types, at a size that keeps the gate's step short. Run by gate.py under
callgrind as `python py_calls.py REGION_SO NAME...`; each named call is made
once as a warm-up (one-time costs: numpy's C API import, pyo3's interned
names) and once inside `ivt_bench_measure` (bench/gate/region.c), after a
full garbage collection, whose dump holds that call's instructions alone
(gate.py names one call per process). Without valgrind it just runs them."""

import ctypes
import gc
import math
import sys

import numpy as np

import ivt
from ivt import hb

# The 2-DOF cubic chain of bench/periodic_frc.py.
CHAIN_M, CHAIN_C, CHAIN_K = np.eye(2), 0.02 * np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]])


def chain_g_vec(x, v, t):
    out = np.zeros_like(x)
    out[:, 0] = 0.5 * x[:, 0] ** 3
    return out


def chain_f(theta):
    return [0.1 * math.cos(theta), 0.0]


def van_der_pol_g(x, v, th):
    return x**2 * v


def condensed_beam():
    m, c, k, tip = hb.models.cantilever(4)
    f = np.zeros(m.shape[0])
    f[tip] = 0.005
    w1 = 3.516015268066119
    return hb.frc(m, c, k, hb.elements.cubic_spring(200.0, dof=tip), f, 1.05 * w1, 1.2 * w1, n=5, samples=16,
                  nonlinear_dofs=[tip])


CALLS = {
    # The orbit at the defaults (Fig. 28: n = 20, 2N = 128, ω_f = 0.4, with stability).
    "py duffing": lambda: hb.duffing(),
    # Fig. 29's FRC with Hsu stability at every point, n = 8.
    "py duffing_frc": lambda: hb.duffing_frc(n=8, samples=32),
    # The chain FRC 0.2–3.0, n = 8: a vectorized Python g, then the same spring as a Rust element.
    "py frc chain vectorized g": lambda: hb.frc(CHAIN_M, CHAIN_C, CHAIN_K, chain_g_vec, chain_f, 0.5, 2.5, n=5,
                                                samples=16, events=False, velocity_dependent=False,
                                                vectorized=True),
    "py frc chain rust element": lambda: hb.frc(CHAIN_M, CHAIN_C, CHAIN_K, hb.elements.cubic_spring(0.5, dof=0),
                                                chain_f, 0.5, 2.5, n=5, samples=16, events=False),
    # Van der Pol, μ = 1 (vectorized g).
    "py limit_cycle": lambda: hb.limit_cycle(1.0, -1.0, 1.0, van_der_pol_g, 1.0, amplitude=2.0, n=10, samples=32,
                                             vectorized=True),
    # The 4-element cantilever condensed onto its tip (a Rust cubic spring), FRC above its first
    # mode with stability.
    "py frc condensed beam": condensed_beam,
    # The fold curve of Duffing's FRC in (ω, F), n = 8.
    "py duffing_folds": lambda: hb.duffing_folds(n=5, samples=16, force_to=0.15, at=[0.1]),
    # Every orbit of the thesis Duffing at ω = 1.4 (three), n = 8.
    "py all_solutions": lambda: hb.all_solutions(1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0),
                                                 lambda th: 0.1 * np.cos(th), 1.4, n=8, samples=32),
}


def main(region_so, names):
    region = ctypes.CDLL(region_so)
    callback = ctypes.CFUNCTYPE(ctypes.c_int)
    region.ivt_bench_measure.argtypes = [callback, ctypes.c_char_p]
    for name in names:  # warm-up: every call once before instrumentation starts
        CALLS[name]()
    region.ivt_bench_start()
    for name in names:
        call = CALLS[name]
        # A full collection first: the cyclic collector's counters start at
        # zero, so whether a collection falls inside the call depends on the
        # call's own allocations, not on what the import or the previous call
        # left (without it `py duffing`, 260 k instructions, moved by 8 % when
        # a line was added to hb.py).
        gc.collect()
        # a ctypes callback must return its declared int; the result is dropped
        # inside the region, as a user's `ivt.hb.duffing()` statement drops it
        region.ivt_bench_measure(callback(lambda: call() and 0), name.encode())


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:] or list(CALLS))
    print(ivt.__name__, "calls done", file=sys.stderr)
