"""One validated boundary (issue 30 item 2) from Python: every argument that
`ivt_kin::params::ALIASES` lists for Python is refused out of range with
`argument `name` <refusal>`, the value as typed, where <refusal> is the very
text a scene prints after the key of the same quantity (`ivt.sim.check_scene`)
or the CLI after the flag (`--k` under `--si`, `--stall-timeout`,
`kin direction --r-sun`).

The aliases are read from the table's source, so an argument added there
without a call here fails `test_every_python_alias_has_a_call`. (The CLI and
scene sides: tests/boundary.rs.)"""

import json
import math
import os
import pathlib
import re
import subprocess
from typing import Callable, Dict, List, Optional, Tuple

import pytest

import ivt
from ivt import ctrl, design, kin

REPO = pathlib.Path(__file__).resolve().parents[3]
PARAMS = REPO / "crates" / "ivt-kin" / "src" / "params.rs"

# Out of every key's range (all ranges are finite): the f32 refusal for the
# controller's numbers, the range refusal for the others, and NaN.
VALUES = [1e300, -1e300, math.nan]


def python_aliases() -> List[Tuple[str, str]]:
    """`py("name", "key")` rows of ALIASES, in table order."""
    rows = re.findall(r'py\("([a-z_0-9]+)", "([^"]+)"\)', PARAMS.read_text())
    assert len(rows) > 20, "the table's rows were not found"
    return rows


PLANT_FIELDS = [
    "r_a", "k_e", "k_t", "l_a", "j_n1", "j_n2", "j_inshaft", "j_carrier", "j_ring",
    "j_crk", "m_r", "m_dr", "j_u", "r_u", "g", "sun_to_planet", "r_max",
]

Call = Callable[[float], object]

# Every (argument, key) of the table: the calls that take it.
CALLS: Dict[Tuple[str, str], List[Call]] = {
    ("r_sun", "kin.r_sun"): [lambda v: kin.direction(r_sun=v)],
    ("r_planet", "kin.r_planet"): [lambda v: kin.direction(r_planet=v)],
    ("v_m", "inputs.v_m[]"): [
        lambda v: design.ol_solve(v, 6.0),
        lambda v: design.stability(v, 6.0),
        lambda v: design.ol_table(v_m=(v, 0.4, 12.0)),
    ],
    ("t_u", "inputs.t_u[]"): [
        lambda v: design.ol_solve(8.0, v),
        lambda v: design.stability_map(t_u=(1.5, 0.5, v)),
    ],
    ("omega0_rpm", "controller.omega0_rpm"): [
        lambda v: design.ol_solve(8.0, 6.0, omega0_rpm=v),
        lambda v: design.ol_fit(omega0_rpm=v),
        lambda v: ctrl.Controller(omega0_rpm=v),
    ],
    ("k", "controller.k_mm_per_rad"): [lambda v: design.stability(8.0, 6.0, k=v)],
    ("k2", "controller.k2_mm_per_rad"): [lambda v: design.stability_map(k2=v)],
    ("k", "controller.k_si"): [
        lambda v: design.stability(8.0, 6.0, k=v, si=True),
        lambda v: ctrl.Controller(k=v),
    ],
    ("k2", "controller.k2_si"): [lambda v: ctrl.Controller(k2=v)],
    ("f_timer_hz", "encoder.f_timer_hz"): [lambda v: ctrl.Controller(f_timer_hz=v)],
    ("omega0", "controller.omega0"): [lambda v: ctrl.Controller(omega0=v)],
    ("k_prop", "controller.k_prop_si"): [lambda v: ctrl.Controller(k_prop=v)],
    ("prop_period_s", "controller.prop_period_s"): [
        lambda v: ctrl.Controller(prop_period_s=v)
    ],
    ("stepper_max_speed", "stepper.max_speed"): [
        lambda v: ctrl.Controller(stepper_max_speed=v)
    ],
    ("stepper_accel", "stepper.accel"): [lambda v: ctrl.Controller(stepper_accel=v)],
    ("stall_timeout_s", "controller.stall_timeout_s"): [
        lambda v: ctrl.Controller(stall_timeout_s=v)
    ],
}
for _field in PLANT_FIELDS:
    CALLS[(_field, f"plant.{_field}")] = [
        lambda v, f=_field: kin.Plant(**{f: v}),
        lambda v, f=_field: kin.Plant().replace(**{f: v}),
    ]
CALLS[("r_u", "plant.r_u")].append(lambda v: kin.output_speed(0.1, 1.0, 0.001, r_u=v))


def toml_number(v: float) -> str:
    return "nan" if math.isnan(v) else repr(v)


def scene_refusal(key: str, v: float) -> str:
    """What a scene prints after the key (or knot) when `key` = v."""
    inputs = {"v_m": "[[0.0, 8.0]]", "t_u": "[[0.0, 6.0]]"}
    extra, at, words = "", key, ""
    if key in ("inputs.v_m[]", "inputs.t_u[]"):
        name = key[len("inputs."):-2]
        inputs[name] = f"[[0.0, {toml_number(v)}]]"
        at, words = f"inputs.{name}[0]", "knot 0: value "
    else:
        section, field = key.split(".", 1)
        extra = f"[{section}]\n{field} = {toml_number(v)}\n"
    text = (
        f"duration_s = 1.0\n[inputs]\nv_m = {inputs['v_m']}\nt_u = {inputs['t_u']}\n{extra}"
    )
    with pytest.raises(ValueError) as info:
        ivt.sim.check_scene(text)
    message = str(info.value)
    head = f"`{at}` {words}"
    assert head in message, message
    return message.split(head, 1)[1]


def cli_refusal(argv: List[str], flag: str) -> str:
    """What the CLI prints after `flag` (exit 2, kind input)."""
    exe = os.environ.get("IVT_BIN") or str(REPO / "target" / "release" / "ivt")
    out = subprocess.run([exe, "--json", *argv], capture_output=True, text=True)
    assert out.returncode == 2, out.stdout
    obj = json.loads(out.stdout)
    assert obj["kind"] == "input", obj
    error: str = obj["error"]
    assert error.startswith(flag + " "), error
    return error[len(flag) + 1:]


def reference(key: str, v: float, tmp: pathlib.Path) -> Optional[str]:
    """The refusal of another boundary for the same quantity (None: no other
    boundary sets it — `omega0` in rad/s and the SI `k_prop` are Python's own)."""
    shown = ivt_typed(v)
    if key in ("controller.k_si", "controller.k2_si"):
        flag = "--k" if key == "controller.k_si" else "--k2"
        return cli_refusal(["stability", "--vm=8", "--tu=6", "--si", f"{flag}={shown}"], flag)
    if key == "controller.stall_timeout_s":
        log = tmp / "log.csv"
        log.write_text("ticks\n" + "".join(f"{1000 + 500 * k}\n" for k in range(50)))
        return cli_refusal(["ctrl", "replay", str(log), f"--stall-timeout={shown}"],
                           "--stall-timeout")
    if key in ("kin.r_sun", "kin.r_planet"):
        flag = "--r-sun" if key == "kin.r_sun" else "--r-planet"
        return cli_refusal(["kin", "direction", f"{flag}={shown}"], flag)
    if key in ("controller.omega0", "controller.k_prop_si"):
        return None
    return scene_refusal(key, v)


def ivt_typed(v: float) -> str:
    """A value as the CLI's parser reads it (the refusal shows it as typed)."""
    return "NaN" if math.isnan(v) else repr(v)


def test_every_python_alias_has_a_call() -> None:
    rows = python_aliases()
    missing = [row for row in rows if not CALLS.get(row)]
    assert not missing, f"aliases without a call in test_boundary.py: {missing}"
    assert sorted(CALLS) == sorted(set(rows)), "calls for aliases the table does not list"


@pytest.mark.parametrize("alias", python_aliases(), ids=lambda a: f"{a[0]}->{a[1]}")
def test_every_argument_is_refused_with_the_boundarys_text(
    alias: Tuple[str, str], tmp_path: pathlib.Path
) -> None:
    name, key = alias
    for v in VALUES:
        want = reference(key, v, tmp_path)
        for call in CALLS[alias]:
            with pytest.raises(ValueError) as info:
                call(v)
            message = str(info.value)
            head = f"argument `{name}` = "
            assert message.startswith(head), message
            if want is not None:
                assert message == f"argument `{name}` {want}", (message, want)
            else:
                shown = "NaN" if math.isnan(v) else ("1e300" if v > 0 else "-1e300")
                assert message.startswith(head + shown + " "), message
                assert "f32" in message, message  # both are controller f32 numbers
