"""Every `ivt_hb::jobs` job that has a command line gives Python the CLI's
result: the dict of `ivt.hb.X(...)` and the object of `ivt hb X --json` on
the same input hold the same keys and the same values (wall times aside).
Both serialize one Rust result type, so any difference is a front end that
assembles or renames on its own. Enum values are snake_case words, never
the Debug text of a Rust type (SPEC §6)."""

import math
import re
from typing import Any, Callable, Dict

import numpy as np

from ivt import hb

#: Wall-clock keys: measured per run, never equal.
TIMES = {"solve_time_s", "time_s"}

#: A snake_case word (termination, stability kind, event kind, method).
WORD = re.compile(r"[a-z]+(_[a-z]+)*")


def same(got: Any, ref: Any, where: str = "") -> None:
    """`got` (Python) equals `ref` (parsed JSON): dicts with the same keys,
    lists of the same length, floats to 1e-12 relative (JSON prints the
    shortest repr that round-trips, so only the last bit may differ), NaN
    where JSON has null."""
    if isinstance(got, np.ndarray):
        got = got.tolist()
    if isinstance(got, dict):
        assert isinstance(ref, dict), where
        assert set(got) == set(ref), (where, sorted(set(got) ^ set(ref)))
        for key in got:
            if key not in TIMES:
                same(got[key], ref[key], f"{where}.{key}")
    elif isinstance(got, (list, tuple)):
        assert isinstance(ref, list) and len(got) == len(ref), (where, len(got), ref)
        for i, (a, b) in enumerate(zip(got, ref)):
            same(a, b, f"{where}[{i}]")
    elif isinstance(got, bool) or got is None or isinstance(got, str):
        assert got == ref, (where, got, ref)
    elif isinstance(got, float) and math.isnan(got):
        assert ref is None, (where, ref)
    else:
        assert isinstance(ref, (int, float)) and not isinstance(ref, bool), (where, ref)
        assert abs(got - ref) <= 1e-12 * max(1.0, abs(ref)), (where, got, ref)


def test_orbit_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    for method in ("modified", "classic"):
        # Below the folds (1.17, 1.65): one orbit, a stable one.
        got = hb.duffing(omega_f=0.8, method=method)  # type: ignore[arg-type]
        ref = cli("hb", "duffing", "--omega-f", "0.8", "--method", method)
        same(got, ref, method)
        assert got["stability"] == "stable" and got["stable"] is True
        assert len(got["floquet"]) == 2 and got["harmonics"] == 20


def test_frc_without_events_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.duffing_frc(0.5, 2.0, n=10, samples=32)
    ref = cli("hb", "duffing-frc", "--from", "0.5", "--to", "2", "--n", "10", "--samples", "32")
    same(got, ref)
    assert got["termination"] == "left_interval"
    assert len(got["folds"]) == 2 and [b["kind"] for b in got["bifurcations"]] == ["fold"] * 2
    assert all(WORD.fullmatch(p["kind"]) for p in got["points"])


def test_frc_with_events_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.duffing_frc(0.5, 2.0, n=10, samples=32, events=True)
    ref = cli("hb", "duffing-frc", "--from", "0.5", "--to", "2", "--n", "10", "--samples", "32",
              "--events")
    same(got, ref)
    # The same two folds as the folds-only path, here located as events.
    fast = hb.duffing_frc(0.5, 2.0, n=10, samples=32)
    np.testing.assert_allclose(got["folds"], fast["folds"], rtol=0, atol=1e-8)
    assert [b["kind"] for b in got["bifurcations"]] == ["fold", "fold"]
    assert all(b["located"] for b in got["bifurcations"])


def test_cascade_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.mathieu_cascade()
    ref = cli("hb", "mathieu-duffing")
    same(got, ref)
    assert got["periods"] == [1, 2, 4]


def test_string_curve_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.string(modes=3, harmonics=7, ns=32, ms=64, from_=1.0, to=3.0)
    ref = cli("hb", "string", "--modes", "3", "--harmonics", "7", "--ns", "32", "--ms", "64",
              "--from", "1", "--to", "3")
    same(got, ref)
    assert got["stop"] == "left_interval"
    assert {p["method"] for p in got["points"]} <= {"hill", "monodromy"}
    assert all(WORD.fullmatch(p["kind"]) for p in got["points"])
    # A spring of k0 > 1 carries its note in both.
    args = dict(modes=3, harmonics=7, ns=32, ms=64, from_=1.0, to=1.5, boundary="spring", k0=1e4)
    got = hb.string(**args)  # type: ignore[arg-type]
    ref = cli("hb", "string", "--modes", "3", "--harmonics", "7", "--ns", "32", "--ms", "64",
              "--from", "1", "--to", "1.5", "--boundary", "spring", "--k0", "10000")
    same(got, ref)
    assert "negative spring" in got["boundary_note"]


def test_fold_curve_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.duffing_folds(n=15, at=[0.2, 0.3])
    ref = cli("hb", "duffing-folds", "--n", "15", "--at", "0.2,0.3")
    same(got, ref)
    assert got["kind"] == "fold" and got["termination"] == "left_interval"
    assert [s["kind"] for s in got["special"]] == ["cusp"]
    # continue_bifurcation runs the same job on a user family: from the same
    # start fold, the same curve to the solver's tolerance (another problem
    # type, so not to the last bit).
    family = lambda F: (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0),
                        lambda th: F * np.cos(th))
    start = {"kind": "fold", "omega": got["start_omega"], "coeffs": got["points"][0]["coeffs"]}
    user = hb.continue_bifurcation(family, start, 0.0, 0.3, at=[0.2, 0.3], p_start=0.1, n=15,
                                   max_points=5000)
    assert set(user) == set(got)
    np.testing.assert_allclose([a["omega"] for a in user["at"]], [a["omega"] for a in got["at"]],
                               rtol=0, atol=1e-8)


def test_limit_cycle_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    """`ivt hb limit-cycle` builds M = 1, C = −μ, K = 1 and g as Python does
    from (m, c, k, g): the same problem, the same arithmetic."""
    mu = 1.0
    got = hb.limit_cycle(1.0, -mu, 1.0, lambda x, v, th: mu * x * x * v, 1.0)
    ref = cli("hb", "limit-cycle", "--mu", "1")
    same(got, ref)
    assert got["stability"] == "stable" and abs(got["period"] - 6.6632868593) < 1e-9
    # Weak Van der Pol (μ = 0.1): ω within 1e-2 of 1 (averaging).
    lc = hb.limit_cycle(1.0, -0.1, 1.0, lambda x, v, th: 0.1 * x**2 * v, 1.0, amplitude=2.0)
    assert lc["stability"] == "stable" and abs(lc["omega"] - 1.0) < 1e-2
    mu = 2.0
    got = hb.limit_cycle(1.0, -mu, 1.0, lambda x, v, th: mu * v * v * v / 3.0, 1.0,
                         n=40, samples=128, amplitude=0.5)
    ref = cli("hb", "limit-cycle", "--model", "rayleigh", "--mu", "2", "--n", "40",
              "--samples", "128", "--amplitude", "0.5")
    same(got, ref)


def test_backbone_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    got = hb.backbone(1.0, 0.0, 1.0, lambda x, v, th: 1.0 * x * x * x, 1.0, [1.0], 0.01, 0.5,
                      velocity_dependent=False)
    ref = cli("hb", "duffing-backbone", "--to", "0.5")
    same(got, ref)
    assert got["termination"] == "left_interval"
    assert isinstance(got["amplitude"], np.ndarray)
    assert isinstance(got["points"][0]["coeffs"], np.ndarray)


def test_elements_repr_is_the_python_call_not_debug_text() -> None:
    el = hb.elements.cubic_spring(0.5) + hb.elements.coulomb(0.02, 0.05, dof=0, to=1)
    assert repr(el) == ("Elements([cubic_spring(k3=0.5, dof=0, to=None), "
                        "coulomb(force=0.02, v_reg=0.05, dof=0, to=1)])")
