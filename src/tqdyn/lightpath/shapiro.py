"""Shapiro delay of the body at the coordinate origin on a light path.

2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) with r_e = |r_e(t - tau)|,
r_r = |r_r(t)|, L = |D|.  Geocentric (GCRS, the Earth): about 7.8e-11 s
(2.3 cm) for TianQin, nearly constant (it varies with the arm lengths
only); GM defaults to :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`.
Heliocentric (Sun-centred BCRS, the Sun, ``gm`` = the Sun's): ~1.65e-7 s
(49 m) on LISA's 2.5e9 m arms.  The light-time solver
(:func:`tqdyn.lightpath.light_time.light_travel_times`, ``shapiro``)
includes the same term in its equation (and, heliocentric, those of other
bodies); :func:`add_shapiro_delays` adds delays of bodies anywhere to light
times solved without them (the BCRS light times of the LISA export, whose
deflectors -- the Sun, the Earth -- are not at the origin).
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008
from ..numerics.dd import np_dd_add_d

__all__ = ["add_shapiro_delays", "shapiro_delay"]


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


def add_shapiro_delays(lp, deflectors) -> tuple[tuple[np.ndarray, np.ndarray], np.ndarray]:
    """Geometric light travel times plus the Shapiro delays of deflecting bodies, to first order.

    lp: a :class:`~tqdyn.lightpath.results.LightTravelTimes` solved without
    any Shapiro term (c tau = |x_r(t) - x_e(t - tau)|) on the grid lp.t;
    deflectors: (center, gm) pairs, center (N, 3) [m] the body's position
    at the grid times in lp's coordinates, gm [m^3/s^2] in the same units
    (e.g. TDB-compatible GMs for TDB-compatible BCRS coordinates).

    The delay s = sum of :func:`shapiro_delay` with r_e, r_r from each
    body's centre enters the light-time equation c (tau - s) = |x_r(t) -
    x_e(t - tau)|, whose first-order solution about the geometric tau is
    tau + s / (1 - n.v_e/c) (n the link's unit vector, v_e the emitter's
    velocity); its rate gets d/dt of that term by second-order finite
    differences along the grid (rows without a light time: NaN).

    Returns (tau dd (hi, lo), tau_rate), each (N, 6) [s, s/s]; lp's own
    values when ``deflectors`` is empty.
    """
    if not deflectors:
        return lp.tau, lp.tau_rate
    re = lp.r_emit[0] + lp.r_emit[1]
    rr = lp.r_receive[0] + lp.r_receive[1]
    s = np.zeros_like(lp.tau[0])
    for center, gm in deflectors:
        s = s + shapiro_delay(re - center[:, None, :], rr - center[:, None, :], gm)
    nve = np.einsum("...k,...k->...", lp.unit_vectors, lp.v_emit)
    add = s * (1.0 / (1.0 - nve / C_LIGHT))
    tgrid = lp.t[0] + lp.t[1]
    ok = np.all(np.isfinite(add), axis=1)
    s_dot = np.full_like(add, np.nan)
    s_dot[ok] = np.gradient(add[ok], tgrid[ok], axis=0, edge_order=2)
    return np_dd_add_d(*lp.tau, add), lp.tau_rate + s_dot
