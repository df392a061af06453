"""Satellite laser ranging (SLR): two-way ranges from ILRS stations.

Stations: ITRF2020 positions and velocities of the ILRS SLR reference frame
SLRF2020 (file ``SLRF2020_POS+VEL_2023.10.02.snx``, version 231001, shipped
in ``tqdyn/data``, provenance in data/SOURCES.md; read by
:mod:`tqdyn.readers.sinex`), propagated linearly from their 2015.0
reference epoch to the scenario epoch, using the station's solution valid
then.  :data:`ILRS_STATIONS` names a handful of them (ILRS code, point
code); any other code of the file can be given.

Model (:func:`slr_range`): the two-way range c (tau_up + tau_down) / 2 of
:func:`tqdyn.od.measurements.two_way` -- the station moving in the GCRS
along the project's ITRS -> GCRS transformation with EOP, re-evaluated at
the transmit and receive instants -- plus the Earth's Shapiro delay on each
leg (:func:`tqdyn.lightpath.shapiro.shapiro_delay`: ~2.5 cm one way at
1e5 km).  Satellite state at the bounce time (the time tag); the fire
time is ``extra["t_transmit"]``.  Visibility: elevation above the geodetic
horizon >= the mask (default 20 deg, a common SLR tracking limit).  Not
modelled: the troposphere (Mendes-Pavlis: ~2.4 m at zenith, a correction
applied to real data), the retroreflector's offset from the centre of mass,
station eccentricities (ILRS ``ecc_xyz.snx``), tides and loading.
Noise: cm level (:data:`SLR_SIGMA_M`) with :func:`tqdyn.od.measurements.simulate`.
"""

from __future__ import annotations

import numpy as np

from .._choices import allowed, did_you_mean
from ..astro.constants import J2000_JD
from ..readers.sinex import shipped_slrf, station_position
from .measurements import Observable, geocentric_two_way

__all__ = ["ILRS_STATIONS", "SLR_SIGMA_M", "slr_range", "slr_station_positions"]

#: A handful of ILRS stations: name -> (ILRS 4-digit code, SINEX point code).
#: Where the stations are listed.
_DOC = "docs/od-measurements.md#measurement-models"
ILRS_STATIONS = {
    "Yarragadee": ("7090", "A"),
    "Monument Peak": ("7110", "A"),
    "Changchun": ("7237", "A"),
    "Zimmerwald": ("7810", "B"),
    "Graz": ("7839", "A"),
    "Herstmonceux": ("7840", "A"),
    "Matera": ("7941", "A"),
    "Wettzell": ("8834", "A"),
}
#: Single-shot-to-normal-point noise of SLR ranges [m]: "cm level" (normal
#: points of modern stations reach mm; 1 cm is a conservative default).
SLR_SIGMA_M = 0.01


def _decimal_year(epoch) -> float:
    jd = epoch.tt[0] + epoch.tt[1]
    return 2000.0 + (jd - J2000_JD) / 365.25


def slr_station_positions(epoch, stations=None) -> tuple[list[str], np.ndarray]:
    """Names and ITRF positions (S, 3) [m] of SLR stations at the scenario epoch.

    stations: names of :data:`ILRS_STATIONS` or (code, point) tuples
    (default: all of :data:`ILRS_STATIONS`).  Each station's SLRF2020
    solution whose span holds the epoch (else its latest one), propagated
    linearly.  ValueError (one line) for an unknown station."""
    catalogue = shipped_slrf()
    year = _decimal_year(epoch)
    names = list(ILRS_STATIONS) if stations is None else list(stations)
    out, labels = [], []
    for s in names:
        code, pt = ILRS_STATIONS[s] if isinstance(s, str) and s in ILRS_STATIONS else (s if isinstance(s, tuple) else (None, None))
        sols = [x for x in catalogue if x.code == code and x.point == pt]
        if not sols:
            raise ValueError(f"SLR station {s!r} is not allowed: not in SLRF2020{did_you_mean(s, ILRS_STATIONS)}; "
                             f"allowed: {allowed(ILRS_STATIONS, _DOC, noun='stations')} or an (ILRS code, point) pair")
        valid = [x for x in sols if x.start <= year <= x.end] or sorted(sols, key=lambda x: x.soln)[-1:]
        out.append(station_position(valid[0], year))
        labels.append(s if isinstance(s, str) else f"{code} {pt}")
    return labels, np.array(out)


def slr_range(epoch, t, r, v, stations=None, *, elevation_mask_deg: float = 20.0, eop=None,
              use_eop: bool = True, shapiro: bool = True) -> Observable:
    """Two-way SLR ranges from ground stations to a satellite (geocentric runs).

    epoch : scenario :class:`~tqdyn.astro.timescales.Epoch`; t : (N,) bounce
    times [s TT since the epoch]; r, v : (N, 3) satellite GCRS position [m]
    and velocity [m/s] at t; stations : as :func:`slr_station_positions`.

    Returns an :class:`~tqdyn.od.measurements.Observable` with value (N, S)
    [m], d_r (N, S, 3), d_v (N, S, 3) (zero: the range depends on the
    state at the bounce time through the position only), visible (N, S);
    extra: ``stations`` (names), ``tau_up``, ``tau_down`` [s],
    ``t_transmit``, ``t_receive`` (N, S) [s TT since the epoch],
    ``sin_elevation`` (N, S).
    """
    t = np.asarray(t, np.float64)
    names, itrs = slr_station_positions(epoch, stations)
    res, sel = geocentric_two_way(epoch, t, r, v, itrs, eop=eop, use_eop=use_eop, shapiro=shapiro)
    visible = sel >= np.sin(np.radians(elevation_mask_deg))
    return Observable(res["range"], res["range_dr"], np.zeros_like(res["range_dr"]), visible,
                      "two-way range", "m",
                      {"stations": names, "tau_up": res["tau_up"], "tau_down": res["tau_down"],
                       "t_transmit": t[:, None] - res["tau_up"], "t_receive": t[:, None] + res["tau_down"],
                       "sin_elevation": sel})
