"""A seeded fuzz of the public Python functions: each call gets hostile values
(negative, huge and non-finite numbers, strings, None, lists) for one to
three of its parameters. Every call must return or raise ValueError,
TypeError or RuntimeError (ivt.hb.ConvergenceError is one) — never a pyo3
PanicException, never an abort (which would end this process), and within
the time a real call takes. `IVT_PY_FUZZ_CASES` sets the number of calls
(default 400, about 10 s); `IVT_PY_FUZZ_SEED` the seed."""

import inspect
import os
import random
import time
from typing import Any, Callable, Dict, List, Tuple

import pytest

from ivt import ctrl, design, hb, kin

FLOATS: List[Any] = [-1.0, 0.0, 0.5, 2.0, float("nan"), float("inf"), float("-inf"), 1e308, 1e-300]
INTS: List[Any] = [-1, 0, 1, 2, 3, 7, 2**32, 2**63 - 1, 2**64]
OTHERS: List[Any] = [None, "abc", "", [1.0, 2.0], (1.0, 1e-300, 1e308), (2.0, 0.0, 12.0)]
POOL = FLOATS + INTS + OTHERS

#: The functions fuzzed: every public function of ivt.kin, ivt.hb, ivt.ctrl
#: and ivt.design that computes from numbers alone (ivt.sim and ivt.sweep
#: read scenes, covered by the scene proptest of tests/hardening.rs; the
#: user-system solvers of ivt.hb need callables and get them here as junk).
MODULES = [kin, hb, ctrl, design]

#: Slowest legitimate call seen in this pool is ol_table on the default grid
#: (~1 s on a loaded machine); anything beyond this is a runaway.
PER_CALL_LIMIT_S = 30.0


def _functions() -> List[Tuple[str, Callable[..., Any]]]:
    out = []
    for m in MODULES:
        for name in getattr(m, "__all__", dir(m)):
            obj = getattr(m, name)
            if callable(obj) and not inspect.isclass(obj) and not name.startswith("_"):
                try:
                    inspect.signature(obj)
                except (TypeError, ValueError):
                    continue
                out.append((f"{m.__name__}.{name}", obj))
    # The classes' constructors take keyword overrides.
    out += [("ivt.ctrl.Controller", ctrl.Controller), ("ivt.kin.Plant", kin.Plant),
            ("ivt.kin.Givt", kin.Givt)]
    return sorted(out, key=lambda t: t[0])


def _call(rng: random.Random, fn: Callable[..., Any]) -> Tuple[List[Any], Dict[str, Any]]:
    """Arguments: required positionals drawn from the pool, one to three
    optional parameters overridden by hostile values."""
    params = list(inspect.signature(fn).parameters.values())
    args: List[Any] = []
    kwargs: Dict[str, Any] = {}
    optional = []
    for p in params:
        if p.kind in (p.VAR_POSITIONAL,):
            continue
        if p.kind is p.VAR_KEYWORD:
            optional.append(rng.choice(["k", "r_max", "f_timer_hz", "k_t", "omega0_rpm", "bogus"]))
            continue
        if p.default is p.empty:
            args.append(rng.choice(FLOATS + INTS[:5]))
        else:
            optional.append(p.name)
    for name in rng.sample(optional, min(len(optional), rng.randint(1, 3))):
        kwargs[name] = rng.choice(POOL)
    return args, kwargs


def test_public_functions_never_panic_or_abort() -> None:
    cases = int(os.environ.get("IVT_PY_FUZZ_CASES", "400"))
    rng = random.Random(int(os.environ.get("IVT_PY_FUZZ_SEED", "20261123")))
    functions = _functions()
    assert len(functions) >= 30, [n for n, _ in functions]
    counts = {"ok": 0, "refused": 0}
    for _ in range(cases):
        name, fn = rng.choice(functions)
        args, kwargs = _call(rng, fn)
        t0 = time.perf_counter()
        try:
            fn(*args, **kwargs)
            counts["ok"] += 1
        except (ValueError, TypeError, RuntimeError) as e:
            assert str(e), f"{name}(*{args}, **{kwargs}): {type(e).__name__} without a message"
            counts["refused"] += 1
        except BaseException as e:  # PanicException derives from BaseException
            pytest.fail(f"{name}(*{args!r}, **{kwargs!r}) raised {type(e).__name__}: {e}")
        dt = time.perf_counter() - t0
        assert dt < PER_CALL_LIMIT_S, f"{name}(*{args!r}, **{kwargs!r}) took {dt:.1f} s"
    # Both outcomes occur: the pool reaches the numerics, not only the checks.
    assert counts["ok"] > cases // 10 and counts["refused"] > cases // 10, counts
