"""Controller design from the model (``ivt-hb``'s IVT tools, thesis §4.2–4.3):
the IHB steady state r̄(V_m, T_U), the open-loop table over a grid and its
refit to the Eq. 158–159 law, and the stability of the integral time-delay
loop at a point and over a grid. Dict keys follow ``ivt ol solve``,
``ivt ol table``, ``ivt ol fit``, ``ivt stability`` and ``ivt stability-map``
(``--json``).

Every function takes ``plant="printed"`` (Table 1, the default),
``plant="thesis-ch4"`` (Table 1 with k_t and k_e divided by 10, the
calibration Chapter 4's computations reproduce on) or an ``ivt.kin.Plant``;
the result's ``"plant"`` names it (``"custom"`` for a Plant matching no preset)."""

from . import _ivt
from ._reexport import reexport


__all__ = ["ol_solve", "ol_table", "ol_fit", "stability", "stability_map"]

reexport(globals(), _ivt.design, __all__)
