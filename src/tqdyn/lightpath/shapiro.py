"""Shapiro delay of the Earth on a light path (geocentric, GCRS).

2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) with r_e = |r_e(t - tau)|,
r_r = |r_r(t)|, L = |D|; about 7.8e-11 s (2.3 cm) for TianQin, nearly
constant (it varies with the arm lengths only).  GM defaults to
:data:`tqdyn.astro.constants.GM_EARTH_EGM2008`.  The light-time solver
(:func:`tqdyn.lightpath.light_time.light_travel_times`, ``shapiro=True``)
includes the same term in its equation.
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008

__all__ = ["shapiro_delay"]


def _default_gm() -> float:
    return float(GM_EARTH_EGM2008)


def shapiro_delay(r_emit, r_receive, gm: float | None = None) -> np.ndarray:
    """Shapiro delay of the Earth 2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) [s].

    r_emit, r_receive: (..., 3) geocentric GCRS positions [m] of the emitter
    (at emission) and the receiver (at reception), float64; L = |r_e - r_r|.
    gm: [m^3/s^2], default :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`.
    Returns (...) float64."""
    gm = _default_gm() if gm is None else float(gm)
    re = np.asarray(r_emit, np.float64)
    rr = np.asarray(r_receive, np.float64)
    a, b = np.linalg.norm(re, axis=-1), np.linalg.norm(rr, axis=-1)
    L = np.linalg.norm(re - rr, axis=-1)
    return 2.0 * gm / C_LIGHT ** 3 * np.log((a + b + L) / (a + b - L))
