"""Shapiro delay of the body at the coordinate origin on a light path.

2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) with r_e = |r_e(t - tau)|,
r_r = |r_r(t)|, L = |D|.  Geocentric (GCRS, the Earth): about 7.8e-11 s
(2.3 cm) for TianQin, nearly constant (it varies with the arm lengths
only); GM defaults to :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`.
Heliocentric (Sun-centred BCRS, the Sun, ``gm`` = the Sun's): ~1.65e-7 s
(49 m) on LISA's 2.5e9 m arms.  The light-time solver
(:func:`tqdyn.lightpath.light_time.light_travel_times`, ``shapiro``)
includes the same term in its equation (and, heliocentric, those of other
bodies).
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008

__all__ = ["shapiro_delay"]


def _default_gm() -> float:
    return float(GM_EARTH_EGM2008)


def shapiro_delay(r_emit, r_receive, gm: float | None = None) -> np.ndarray:
    """Shapiro delay of the body at the origin 2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) [s].

    r_emit, r_receive: (..., 3) positions [m] of the emitter (at emission)
    and the receiver (at reception) relative to the deflecting body at the
    origin (geocentric GCRS: the Earth; Sun-centred BCRS: the Sun), float64;
    L = |r_e - r_r|.  gm: [m^3/s^2], default
    :data:`tqdyn.astro.constants.GM_EARTH_EGM2008` (pass the Sun's for
    heliocentric positions).  Returns (...) float64."""
    gm = _default_gm() if gm is None else float(gm)
    re = np.asarray(r_emit, np.float64)
    rr = np.asarray(r_receive, np.float64)
    a, b = np.linalg.norm(re, axis=-1), np.linalg.norm(rr, axis=-1)
    L = np.linalg.norm(re - rr, axis=-1)
    return 2.0 * gm / C_LIGHT ** 3 * np.log((a + b + L) / (a + b - L))
