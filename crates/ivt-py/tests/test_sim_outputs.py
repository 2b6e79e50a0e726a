"""`ivt.sim.run(scene, out=dir)` through the one output writer: concurrent
runs into the same directory never collide on a temporary name (issue #30:
four threads, 20 runs, 11 used to fail), every run's set is complete and
nothing temporary is left; a target that is not a regular file is refused."""

import json
import os
import pathlib
import threading
from typing import Any, Dict, List

import pytest

import ivt
from conftest import REPO

SCENE = REPO / "scenes" / "load_step_delay.toml"


def short_scene() -> Dict[str, Any]:
    d: Dict[str, Any] = ivt.sim.scene_dict(SCENE)
    d["duration_s"] = 0.5
    d["metrics"]["from_s"] = 0.0
    d["metrics"]["static_window_s"] = 0.2
    d["outputs"]["mcap"] = True
    d["outputs"]["csv"] = True
    d["outputs"]["summary"] = True
    return d


def test_four_threads_into_one_directory(tmp_path: pathlib.Path) -> None:
    scene = short_scene()
    out = tmp_path / "shared" / "out"  # created by the runs themselves
    errors: List[BaseException] = []
    results: List[Dict[str, Any]] = []
    lock = threading.Lock()

    def worker(runs: int) -> None:
        for _ in range(runs):
            try:
                r = ivt.sim.run(scene, out=out)
                with lock:
                    results.append(r)
            except BaseException as e:  # noqa: BLE001 - collected and asserted below
                with lock:
                    errors.append(e)

    threads = [threading.Thread(target=worker, args=(5,)) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert len(results) == 20
    names = sorted(p.name for p in out.iterdir())
    expected = sorted(pathlib.Path(p).name for p in results[0]["outputs"])
    assert names == expected, names  # the set, and no temporary file
    assert not any(n.startswith(".tmp-") for n in names)
    assert any(n.endswith(".mcap") for n in names) and any(n.endswith(".csv") for n in names)
    summary = json.loads((out / f"{scene['name']}_summary.json").read_text())
    assert summary["pulses"] == results[0]["summary"]["pulses"]


@pytest.mark.skipif(os.name != "posix", reason="symlinks and /dev/null")
def test_symlinked_output_is_refused(tmp_path: pathlib.Path) -> None:
    scene = short_scene()
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.json"
    victim.write_text("keep")
    (out / f"{scene['name']}_summary.json").symlink_to(victim)
    with pytest.raises(RuntimeError, match="symbolic link"):
        ivt.sim.run(scene, out=out)
    assert victim.read_text() == "keep"
    # nothing of the set was written: only the symlink is there
    assert [p.name for p in out.iterdir()] == [f"{scene['name']}_summary.json"]


@pytest.mark.skipif(not os.path.exists("/dev/null"), reason="needs /dev/null")
def test_device_as_output_is_a_runtime_error() -> None:
    before = os.stat("/dev/null")
    with pytest.raises(RuntimeError, match="/dev/null"):
        ivt.sim.run(short_scene(), out="/dev/null")
    after = os.stat("/dev/null")
    assert (after.st_mode, after.st_rdev) == (before.st_mode, before.st_rdev)
