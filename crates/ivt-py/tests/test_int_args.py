"""Every integer argument of ivt.ctrl, ivt.kin (gears) and ivt.design refuses
a value outside its range (2**63, 2**64, -1, ...) with a `ValueError` whose
message names the argument, and a float or a bool with a `TypeError`: never
pyo3's bare `OverflowError: Python int too large to convert to C long`.
Beyond ±2**127 and for a wrong type the name is in the exception's note
("while processing 'ppr'", added by pyo3, shown in the traceback). ivt.sim
takes no integer argument (scenes are dicts or TOML, checked by the scene
parser)."""

from typing import Any, Callable, List, Tuple

import numpy as np
import pytest

from ivt import ctrl, design, kin

# (label, call with the value, argument name, out-of-range values)
OUT_OF_RANGE = [2**63, 2**64, -1, -(2**63) - 1, 2**200]
CASES: List[Tuple[str, Callable[[Any], Any], str, List[int]]] = [
    ("Controller(ppr)", lambda v: ctrl.Controller(v), "ppr", OUT_OF_RANGE),
    ("Controller(decimation)", lambda v: ctrl.Controller(decimation=v), "decimation", OUT_OF_RANGE + [2**16]),
    # i32: -1 is a valid offset
    ("Controller(offset_steps)", lambda v: ctrl.Controller(offset_steps=v), "offset_steps",
     [2**31, -(2**31) - 1, 2**63, 2**64]),
    ("Controller.on_pulse(ticks)", lambda v: ctrl.Controller().on_pulse(v), "ticks", OUT_OF_RANGE + [2**32]),
    ("Controller.step_tick(now)", lambda v: ctrl.Controller().step_tick(v), "now", OUT_OF_RANGE + [2**32]),
    ("Controller.on_pulses([ticks])", lambda v: ctrl.Controller().on_pulses([v]), "ticks",
     OUT_OF_RANGE + [2**32]),
    ("pitch_profile(points)", lambda v: kin.pitch_profile(points=v), "points", OUT_OF_RANGE),
    ("fourier_coefficient_eq38(k)", lambda v: kin.fourier_coefficient_eq38(v), "k", OUT_OF_RANGE + [2**32]),
    ("ol_solve(harmonics)", lambda v: design.ol_solve(8.0, 6.0, harmonics=v), "harmonics", OUT_OF_RANGE),
    ("ol_table(harmonics)", lambda v: design.ol_table((8.0, 1.0, 8.0), (6.0, 1.0, 6.0), harmonics=v),
     "harmonics", OUT_OF_RANGE),
    ("stability(n)", lambda v: design.stability(8.6, 6.0, n=v), "n", OUT_OF_RANGE),
    ("stability_map(n)", lambda v: design.stability_map((8.0, 1.0, 8.0), (6.0, 1.0, 6.0), n=v), "n",
     OUT_OF_RANGE),
]


@pytest.mark.parametrize("label,call,name,values", CASES, ids=[c[0] for c in CASES])
def test_out_of_range_integer_is_a_named_value_error(
    label: str, call: Callable[[Any], Any], name: str, values: List[int]
) -> None:
    for v in values:
        with pytest.raises(ValueError) as e:
            call(v)
        assert not isinstance(e.value, OverflowError), f"{label} = {v}: {e.value!r}"
        if abs(v) < 2**127:
            assert f"`{name}`" in str(e.value), f"{label} = {v}: {e.value!r} does not name `{name}`"
        else:
            text = str(e.value) + " ".join(getattr(e.value, "__notes__", []))
            assert f"'{name}'" in text or f"`{name}`" in text, f"{label} = {v}: {text!r}"


@pytest.mark.parametrize("label,call,name,values", CASES, ids=[c[0] for c in CASES])
def test_float_or_bool_for_an_integer_is_a_named_type_error(
    label: str, call: Callable[[Any], Any], name: str, values: List[int]
) -> None:
    for v in [7.0, 7.5, True, "7"]:
        with pytest.raises(TypeError) as e:
            call(v)
        text = str(e.value) + " ".join(getattr(e.value, "__notes__", []))
        assert f"'{name}'" in text or f"`{name}`" in text, f"{label} = {v!r}: {text!r}"


def test_in_range_integers_still_work() -> None:
    """The checks refuse only what does not fit: numpy integers and the
    extremes of each range are accepted."""
    c = ctrl.Controller(np.int64(1200), decimation=np.uint16(5), offset_steps=-(2**31))
    assert c.on_pulse(2**32 - 1)["fault_name"] is not None
    assert c.step_tick(0)["fault_name"] is not None
    assert kin.fourier_coefficient_eq38(np.int32(1)) == pytest.approx(2.0 / 15.0)
