"""`ivt.foxglove_layout()` names the layout file the installed package ships
(the wheel's copy of crates/ivt-py/python/ivt/foxglove/ivt-layout.json, whose
panels tests/foxglove_layout.rs checks against real MCAP files)."""

import json
import pathlib

import ivt

REPO = pathlib.Path(__file__).resolve().parents[3]


def test_layout_is_shipped_and_identical_to_the_repository_copy() -> None:
    path = ivt.foxglove_layout()
    assert path.is_file(), path
    shipped = json.loads(path.read_text(encoding="utf-8"))
    source = REPO / "crates" / "ivt-py" / "python" / "ivt" / "foxglove" / "ivt-layout.json"
    assert shipped == json.loads(source.read_text(encoding="utf-8"))
    assert "/control.omega" in path.read_text(encoding="utf-8")
