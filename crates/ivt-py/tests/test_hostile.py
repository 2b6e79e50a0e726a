"""Issue #30's hostile scenes from Python: `ivt.sim.run` raises ValueError (a
scene refused by its validated boundary) or RuntimeError (a run refused by its
work budget), never PanicException, never a result computed from nonsense,
and never after unbounded work (each within 20 s, as tests/hostile.rs asks of
the command line)."""

import time
from typing import Any, Callable, Dict, Type

import pytest

import ivt

BASE = "duration_s = 2.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n"

CASES: Dict[str, Any] = {
    # former panics in profile.rs ("min > max")
    "rtol": (BASE + "[integrator]\nrtol = 1e-300\natol = 1e-300\n", "`integrator.rtol` = 1e-300"),
    "t_u": (BASE.replace("t_u = [[0.0, 4.0]]", "t_u = [[0, 1e300]]"), "value = 1e300"),
    # spun forever
    "period": (BASE + "[sensors]\nperiod_s = 1e-300\n", "`sensors.period_s` = 1e-300 s"),
    # ran with the controller faulted on every pulse, exit 0
    "k_f32": (BASE + "[controller]\nk_mm_per_rad = 1e300\n", "does not fit the controller's f32"),
    # the third value was dropped
    "knot3": (BASE.replace("v_m = [[0.0, 8.0]]", "v_m = [[0.0, 8.6, 1.0]]"), "knot 0 has 3 numbers"),
}


def timed(call: Callable[[], Any], error: Type[Exception]) -> str:
    t0 = time.monotonic()
    with pytest.raises(error) as info:
        call()
    assert time.monotonic() - t0 < 20.0
    return str(info.value)


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_scene_text_raises_value_error(name: str) -> None:
    text, needle = CASES[name]
    message = timed(lambda: ivt.sim.run(text), ValueError)
    assert needle in message, message


@pytest.mark.parametrize("name", sorted(CASES))
def test_hostile_scene_file_raises_value_error(name: str, tmp_path: Any) -> None:
    text, needle = CASES[name]
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    message = timed(lambda: ivt.sim.run(path, out=tmp_path / "out"), ValueError)
    assert needle in message, message
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("read", [ivt.sim.run, ivt.sim.scene_dict])
def test_endless_file_is_read_no_further_than_its_limit(
    read: Callable[[Any], Any], tmp_path: Any
) -> None:
    # issue 43: inputs are regular files; a device is refused at once
    # (ivt.sweep starts from scene_dict: the same opener as ivt.sim.run)
    message = timed(lambda: read("/dev/zero"), ValueError)
    assert "a character device" in message, message
    # a regular file over the budget (sparse: nothing written) by its size
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate((1 << 20) + 1)
    message = timed(lambda: read(big), ValueError)
    assert "1048577 bytes: more than the 1048576" in message, message


def test_work_beyond_the_budget_raises_runtime_error() -> None:
    # 1e6 s at 100 rpm, 4096 pulses/rev: 6.827e9 pulses + 1e8 readings
    text = BASE.replace("2.0", "1e6") + "[encoder]\nppr = 4096\n"
    message = timed(lambda: ivt.sim.run(text), RuntimeError)
    assert "about 6.927e9" in message, message
