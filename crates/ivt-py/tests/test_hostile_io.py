"""Issue #43, part A, from Python: every path-taking function opens its file
through the one Rust opener (`ivt_sim::input`): a FIFO without a writer, a
device or a directory is refused at once saying what it is (a FIFO blocked
forever, a directory or /dev/zero was reported as a missing file); plant
files hold their `[plant]` table alone; a scene's outputs never replace the
scene; a set speed no rig can hold is refused with its range; and the
command line run with `stdout=subprocess.DEVNULL` does its work (it was
taken for a closed stdout and did nothing)."""

import json
import os
import pathlib
import subprocess
import time
from typing import Any, Callable, List

import pytest

import ivt
from ivt import ctrl, design, kin

from conftest import _ivt_bin

SCENE = "duration_s = 0.5\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n"


def quickly(call: Callable[[], Any], error: Any) -> str:
    """`call` raises `error` within 5 s (a FIFO used to block forever)."""
    t0 = time.monotonic()
    with pytest.raises(error) as info:
        call()
    assert time.monotonic() - t0 < 5.0
    return str(info.value)


def path_readers(path: pathlib.Path, tmp: pathlib.Path) -> List[Callable[[], Any]]:
    """Every Python function that reads the file at `path`."""
    scene = tmp / "with_plant_file.toml"
    scene.write_text(SCENE + f"[plant]\nfile = {json.dumps(str(path))}\n")
    return [
        lambda: kin.Plant.from_file(path),
        lambda: kin.Plant.from_file(str(path)),
        lambda: design.ol_solve(8.0, 4.0, plant=path),
        lambda: ivt.sim.run(path),
        lambda: ivt.sim.run(str(path)),
        lambda: ivt.sim.check_scene(path),
        lambda: ivt.sim.scene_dict(path),
        lambda: ivt.sim.run(scene),
        lambda: ivt.sim.check_scene(scene),
    ]


def test_fifo_device_and_directory_are_refused_saying_what_they_are(
    tmp_path: pathlib.Path,
) -> None:
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    directory = tmp_path / "a-directory"
    directory.mkdir()
    for path, what in [
        (fifo, "a FIFO (named pipe)"),
        (pathlib.Path("/dev/zero"), "a character device"),
        (directory, "a directory"),
    ]:
        for call in path_readers(path, tmp_path):
            message = quickly(call, ValueError)
            assert what in message and str(path) in message, message
            assert "does not exist" not in message, message


def test_a_missing_plant_file_is_file_not_found(tmp_path: pathlib.Path) -> None:
    message = quickly(lambda: kin.Plant.from_file(tmp_path / "missing.toml"), FileNotFoundError)
    assert "missing.toml" in message, message


def test_plant_files_hold_the_plant_table_alone(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "p.toml"
    for text, needle in [
        ("k_t = 0.1\n[plant]\npreset = \"printed\"\n", "k_t"),
        ("[plant]\n[controller]\nk_prop_deg_per_rpm = 5.0\n", "controller"),
        ("[plant]\nk_t = 1e-300\n", "`plant.k_t` = 1e-300 N·m/A is outside"),
    ]:
        path.write_text(text)
        for call in [
            lambda: kin.Plant.from_file(path),
            lambda: design.ol_solve(8.0, 4.0, plant=str(path)),
        ]:
            message = quickly(call, ValueError)
            assert "p.toml" in message and needle in message, message


def test_a_scene_output_never_replaces_the_scene(tmp_path: pathlib.Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    scene = out / "s_summary.json"
    text = 'name = "s"\n' + SCENE + "[outputs]\nsummary = true\n"
    scene.write_text(text)
    message = quickly(lambda: ivt.sim.run(scene, out=out), RuntimeError)
    assert "is an input of this run" in message, message
    assert scene.read_text() == text
    assert sorted(p.name for p in out.iterdir()) == ["s_summary.json"]


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: ctrl.Controller(omega0=1e-31), "omega0"),
        (lambda: ctrl.Controller(omega0_rpm=1e-30), "omega0_rpm"),
        (lambda: design.ol_solve(8.0, 4.0, omega0_rpm=0.05), "omega0_rpm"),
    ],
)
def test_a_set_speed_no_rig_holds_is_refused_with_its_range(
    call: Callable[[], Any], name: str
) -> None:
    message = quickly(call, ValueError)
    assert message.startswith(f"argument `{name}` = "), message
    assert "is outside [0.1, 10000) rpm" in message or "is outside [0.01, 1000) rad/s" in message


def test_the_cli_writes_to_devnull(tmp_path: pathlib.Path) -> None:
    """`subprocess.run([... "--json" ...], stdout=subprocess.DEVNULL)`: the
    command runs (exit 0) and writes its files."""
    scene = tmp_path / "s.toml"
    scene.write_text('name = "s"\n' + SCENE + "[outputs]\nsummary = true\n")
    out = tmp_path / "out"
    run = subprocess.run(
        [str(_ivt_bin()), "--json", "sim", str(scene), "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert (out / "s_summary.json").is_file()
