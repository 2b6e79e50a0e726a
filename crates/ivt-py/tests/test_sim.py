"""ivt.sim.run against `ivt sim SCENE --json` (same scene, same seed: the
summaries must be identical apart from wall-clock fields) and physical
consistency of the returned channels."""

import json
import pathlib

import numpy as np
import pytest

import ivt
from conftest import REPO

SCENE = REPO / "scenes" / "load_step_delay.toml"
WALL_CLOCK = {"wall_time_s", "realtime_factor"}


def short_scene(duration_s: float = 4.0) -> dict:  # type: ignore[type-arg]
    d = ivt.sim.scene_dict(SCENE)
    d["duration_s"] = duration_s
    d["inputs"]["t_u"] = [[0.0, 6.0], [1.0, 6.0], [1.01, 8.0]]
    d["metrics"]["from_s"] = 1.0
    d["metrics"]["static_window_s"] = 1.0
    return d


def test_run_path_equals_cli(cli, tmp_path: pathlib.Path) -> None:  # type: ignore[no-untyped-def]
    ref = cli("sim", str(SCENE), "--out", str(tmp_path / "cli"))
    got = ivt.sim.run(SCENE, out=tmp_path / "py")
    assert set(got["summary"]) == set(ref["summary"])
    for key, value in ref["summary"].items():
        if key not in WALL_CLOCK:
            assert got["summary"][key] == value, key
    assert [pathlib.Path(p).name for p in got["outputs"]] == [
        pathlib.Path(p).name for p in ref["outputs"]
    ]
    written = json.loads((tmp_path / "py" / "load_step_delay_summary.json").read_text())
    assert written["pulses"] == ref["summary"]["pulses"]


def test_dict_text_and_path_forms_agree() -> None:
    d = short_scene()
    a = ivt.sim.run(d)
    text = SCENE.read_text().replace("duration_s = 30.0", "duration_s = 4.0")
    text = text.replace("[10.0, 6.0], [10.01, 8.0]", "[1.0, 6.0], [1.01, 8.0]")
    text = text.replace("from_s = 10.0", "from_s = 1.0").replace("static_window_s = 5.0", "static_window_s = 1.0")
    b = ivt.sim.run(text)
    for key in a["summary"]:
        if key not in WALL_CLOCK:
            assert a["summary"][key] == b["summary"][key], key
    np.testing.assert_array_equal(a["channels"]["control"]["r"], b["channels"]["control"]["r"])
    assert a["outputs"] == []  # nothing written without `out`


def test_channels_are_consistent_arrays() -> None:
    res = ivt.sim.run(short_scene())
    plant, control = res["channels"]["plant"], res["channels"]["control"]
    for key in ["t", "theta", "omega", "omega_a", "r", "v_m", "t_u"]:
        assert plant[key].dtype == np.float64 and plant[key].shape == plant["t"].shape
    assert control["ticks"].dtype == np.int64 and control["saturated"].dtype == np.bool_
    # Logged every 12th of 1200 pulses: θ advances by exactly 2π/100 between rows.
    np.testing.assert_allclose(np.diff(plant["theta"]), 2 * np.pi / 100, rtol=1e-9)
    # ω = dθ/dt: mean speed over each logged interval lies between its end-point speeds
    # (ω is monotone over a 3.6° interval except at the gear corners, hence the 0.5 %).
    mean = np.diff(plant["theta"]) / np.diff(plant["t"])
    lo = np.minimum(plant["omega"][1:], plant["omega"][:-1])
    hi = np.maximum(plant["omega"][1:], plant["omega"][:-1])
    assert np.all(mean >= lo * 0.995) and np.all(mean <= hi * 1.005)
    assert np.all((plant["r"] >= 0) & (plant["r"] <= 0.012))
    assert res["summary"]["pulses"] > 0 and res["summary"]["ppr"] == 1200


def test_scene_errors() -> None:
    d = short_scene()
    d["controller"]["law"] = "pid"
    with pytest.raises(ValueError, match="law"):
        ivt.sim.run(d)
    d = short_scene()
    d["bogus"] = 1
    with pytest.raises(ValueError, match="bogus"):
        ivt.sim.run(d)
    d = short_scene()
    d["plant"] = {"r_u": -1.0}
    with pytest.raises(ValueError, match="plant.r_u"):
        ivt.sim.check_scene(d)
    with pytest.raises(ValueError, match="no_such.toml"):
        ivt.sim.run("no_such.toml")
    with pytest.raises(TypeError, match="`scene`"):
        ivt.sim.run(42)  # type: ignore[arg-type]
    assert ivt.sim.check_scene(SCENE)["name"] == "load_step_delay"
    assert 1200 in ivt.sim.SUPPORTED_PPR


def test_steady_state_scene_takes_the_ihb_route() -> None:
    scene = REPO / "scenes" / "steady_state.toml"
    ihb = ivt.sim.run(scene)["summary"]
    assert ihb["route"] == "ihb_steady_state"
    assert ihb["steady_state"]["verdict"] == "feasible"
    time = ivt.sim.run(scene, route="time_integration")["summary"]
    assert time["route"] == "time_integration"
    # crates/ivt-sim/tests/steady_route.rs derives these bounds: the loop
    # dithers over ±1 stepper step (≈ 1.6e-4 rad/s in ω_a) around r̄.
    a, b = ihb["steady_state"], time["steady_state"]
    assert abs(a["omega_a_rad_s"] - b["omega_a_rad_s"]) < 2e-4
    assert abs(a["omega_max_rad_s"] / b["omega_max_rad_s"] - 1.0) < 1e-4
    with pytest.raises(RuntimeError, match="route"):
        ivt.sim.run(REPO / "scenes" / "load_step_delay.toml", route="ihb_steady_state")
    with pytest.raises(ValueError, match="route"):
        ivt.sim.run(scene, route="fast")
