"""Every `ivt_jobs` job that has a command line gives Python the CLI's
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
    # The points run from the far end of the first leg (towards F = 0, through
    # the cusp, up to 0.3) to that of the second: the start is inside.
    (first,) = [p for p in got["points"] if p["omega"] == got["start_omega"]]
    start = {"kind": "fold", "omega": got["start_omega"], "coeffs": first["coeffs"]}
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


# --- user models from the command line (issue 46): `ivt hb frc|solve MODEL.toml`

#: Two masses in a chain (m = 1, k = 2/-1, light proportional damping) with
#: a hardening spring from DOF 0 to the ground and a cubic damper between the
#: masses, driven at DOF 0. K comes from a Matrix Market file written by
#: scipy (an independent writer of the format).
_M = [[1.0, 0.0], [0.0, 1.0]]
_C = [[0.04, -0.02], [-0.02, 0.04]]
_K = [[2.0, -1.0], [-1.0, 2.0]]
_MODEL = """
[model]
m = [[1.0, 0.0], [0.0, 1.0]]
c = [[0.04, -0.02], [-0.02, 0.04]]
k = "k.mtx"

[[element]]
law = "cubic_spring"
k3 = 0.5
dof = 0

[[element]]
law = "cubic_damper"
c3 = 0.01
dof = 1
to = 0

[forcing]
amplitude = [0.1, 0.0]

[range]
from = 0.5
to = 2.5

[options]
n = 12
samples = 32
"""


def _model_files(tmp_path: Any) -> Any:
    import scipy.io
    import scipy.sparse

    scipy.io.mmwrite(str(tmp_path / "k.mtx"), scipy.sparse.coo_matrix(np.array(_K)))
    path = tmp_path / "model.toml"
    path.write_text(_MODEL)
    return path


def _g() -> Any:
    return hb.elements.cubic_spring(0.5, dof=0) + hb.elements.cubic_damper(0.01, dof=1, to=0)


def _f(theta: float) -> list:  # type: ignore[type-arg]
    return [0.1 * math.cos(theta), 0.0]


def test_model_file_frc_equals_python_frc(cli: Callable[..., Dict[str, Any]], tmp_path: Any) -> None:
    path = _model_files(tmp_path)
    ref = cli("hb", "frc", str(path))
    got = hb.frc(np.array(_M), np.array(_C), np.array(_K), _g(), _f, 0.5, 2.5, n=12, samples=32)
    same(got, ref)
    # A curve with its folds (the hardening peak near the first mode, ω ≈ 1)
    # and a point count that a wrong model would not reproduce.
    assert len(ref["folds"]) == 2 and len(ref["points"]) > 50
    assert all(0.9 < f["omega"] < 2.0 for f in ref["folds"])
    # --from/--to override [range].
    part = cli("hb", "frc", str(path), "--from", "2.5", "--to", "1.5")
    same(hb.frc(_M, _C, _K, _g(), _f, 2.5, 1.5, n=12, samples=32), part)


def test_model_file_solve_equals_python_solve(cli: Callable[..., Dict[str, Any]], tmp_path: Any) -> None:
    path = _model_files(tmp_path)
    ref = cli("hb", "solve", str(path), "--omega", "1.3")
    same(hb.solve(_M, _C, _K, _g(), 1.3, _f, n=12, samples=32), ref)
    # The orbit balances the equations: the first harmonic of DOF 0 is far
    # from the linear response alone would give at this ω (cubic spring on).
    assert ref["residual_norm"] < 1e-9 and ref["stability"] in ("stable", "unstable")


def _cli_error(tmp_path: Any, text: str, *args: str) -> Dict[str, Any]:
    """The one JSON error object of `ivt --json hb frc BAD.toml` (exit 2)."""
    import json
    import subprocess

    from conftest import _ivt_bin

    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    out = subprocess.run(
        [str(_ivt_bin()), "--json", "hb", *(args or ("frc",)), str(bad)],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 2, (out.returncode, out.stdout, out.stderr)
    lines = out.stdout.strip().splitlines()
    assert len(lines) == 1, out.stdout
    obj: Dict[str, Any] = json.loads(lines[0])
    assert set(obj) == {"error", "kind"}, obj
    return obj


_BASE = "[model]\nm = 1.0\nc = 0.1\nk = 1.0\n[range]\nfrom = 0.5\nto = 2.0\n"


def test_bad_model_files_give_one_error_naming_the_key(tmp_path: Any) -> None:
    cases = [
        (_BASE + "[options]\nharmonics = 3\n", "input", ["options.harmonics"]),
        (_BASE + "[options]\nn = 0\n", "input", ["options.n", "0"]),
        (_BASE + "[options]\nn = 10\nsamples = 8\n", "input", ["options.samples", "8"]),
        (_BASE + "[[element]]\nlaw = 'cubic'\nk3 = 1.0\ndof = 0\n", "input", ["element[0].law", "cubic"]),
        (_BASE + "[[element]]\nlaw = 'cubic_spring'\nk3 = 1.0\ndof = 1\n", "input", ["element[0].dof", "1"]),
        (_BASE + "[[element]]\nlaw = 'cubic_spring'\ndof = 0\n", "input", ["element[0]", "k3"]),
        (_BASE + "[[element]]\nlaw = 'cubic_spring'\nk3 = 1.0\ngap = 0.1\ndof = 0\n", "input",
         ["element[0].gap", "0.1"]),
        (_BASE + "[[element]]\nlaw = 'coulomb'\nforce = 1.0\nv_reg = -1.0\ndof = 0\n", "input",
         ["element[0].v_reg", "-1"]),
        (_BASE + "[forcing]\namplitude = [1.0, 2.0]\n", "input", ["forcing.amplitude", "2 entries"]),
        (_BASE + "[forcing]\namplitude = [nan]\n", "input", ["forcing.amplitude[0]", "NaN"]),
        ("[model]\nm = [[1.0, 0.0], [0.0]]\nc = 0.1\nk = 1.0\n", "input", ["model.m", "row 1"]),
        ("[model]\nm = true\nc = 0.1\nk = 1.0\n", "input", ["model.m", "true"]),
        ("[model]\nm = 1.0\nc = 0.1\n", "input", ["model", "k"]),
        ("[model]\nm = 'missing.mtx'\nc = 0.1\nk = 1.0\n", "io", ["model.m", "missing.mtx"]),
        (_BASE.replace("from = 0.5", "from = -0.5"), "input", ["range.from", "-0.5"]),
        ("[model]\nm = 1.0\nc = 0.1\nk = 1.0\n", "input", ["range.from", "--from"]),
    ]
    for text, kind, words in cases:
        err = _cli_error(tmp_path, text)
        assert err["kind"] == kind, (text, err)
        for w in words:
            assert w in err["error"], (text, w, err)
    (tmp_path / "c.mtx").write_text("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1.0 0.5\n")
    err = _cli_error(tmp_path, "[model]\nm = 1.0\nc = 'c.mtx'\nk = 1.0\n")
    assert err["kind"] == "input" and "model.c" in err["error"] and "complex" in err["error"], err
    err = _cli_error(tmp_path, _BASE, "solve", "--omega", "0")
    assert err["kind"] == "input" and "--omega" in err["error"], err
