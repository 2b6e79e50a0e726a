"""Plant files (a `[plant]` table: preset + overrides, as written by
`ivt rig identify --out`): `ivt.kin.Plant.from_file` and `plant=` in
ivt.design read them with the same parser as scenes and `--plant-file`."""

import pathlib

import pytest

from ivt import design, kin


def _write(tmp_path: pathlib.Path, text: str) -> pathlib.Path:
    path = tmp_path / "rig.toml"
    path.write_text(text)
    return path


def test_from_file_is_the_preset_with_overrides(tmp_path: pathlib.Path) -> None:
    path = _write(tmp_path, '[plant]\npreset = "thesis-ch4"\nk_t = 0.08\nr_u = 0.0381\n')
    p = kin.Plant.from_file(path)
    want = kin.Plant(k_t=0.08, k_e=0.075, r_u=0.0381)  # thesis-ch4: k_e = 0.075
    assert p.params() == want.params()
    assert kin.Plant.from_file(str(path)).summary() == want.summary()


def test_design_plant_file_equals_cli(tmp_path: pathlib.Path, cli) -> None:  # type: ignore[no-untyped-def]
    path = _write(tmp_path, '[plant]\npreset = "printed"\nk_t = 0.7\nj_ring = 0.008\n')
    ref = cli("ol", "solve", "--plant-file", str(path), "--vm", "9", "--tu", "4", "--method", "ihb")
    got = design.ol_solve(9.0, 4.0, plant=path, method="ihb")
    assert got["r"] == ref["r"]
    assert got["plant"] == str(path) == ref["plant"]
    assert design.ol_solve(9.0, 4.0, plant=str(path), method="ihb")["r"] == ref["r"]


def test_plant_file_errors(tmp_path: pathlib.Path) -> None:
    with pytest.raises(FileNotFoundError):
        kin.Plant.from_file(tmp_path / "missing.toml")
    bad = _write(tmp_path, "[plant]\nk_t = -1.0\n")
    with pytest.raises(ValueError, match=r"rig\.toml:2:1: `plant\.k_t`"):
        kin.Plant.from_file(bad)
    with pytest.raises(ValueError, match="plant file"):
        design.ol_solve(9.0, 4.0, plant="no-such-preset")
