"""Deep-space ground stations: two-way range and range rate (Doppler).

For the heliocentric constellations (LISA, Taiji: Sun-centred BCRS, t in
TDB seconds since the epoch) and, as well, for geocentric runs (GCRS, TT).

Stations (:data:`DEEP_SPACE_STATIONS`), ITRF positions [m]:

* NASA DSN 70 m antennas DSS-14 (Goldstone), DSS-43 (Canberra), DSS-63
  (Madrid): Cartesian ITRF93 coordinates at epoch 2003.0 of JPL section 335,
  as listed in NAIF's frame kernel ``earth_topo_050714.tf`` (W. M. Folkner,
  TDA Progress Report 42-128, 1996, for their uncertainties: ~4 cm).
  Plate motion since 2003 (~2-5 cm/yr) is not applied (< 1.5 m by 2030).
* ESA ESTRACK 35 m antennas Cebreros (DSA 2), Malargue (DSA 3), New Norcia
  (DSA 1): geodetic longitude and latitude of ESA's SPICE frame kernel
  ``estrack_v04.tf`` (ESAC, 2021, "in accordance with the public
  information provided by ESTRACK"), heights 794 m (Cebreros), 1550 m
  (Malargue), 252 m (New Norcia) on the WGS84 ellipsoid (``erfa.gd2gc``):
  an assumption, approximate values not checked against a primary
  source (the kernel gives no heights).  Accuracy: ~10 m; fine for
  simulations and covariance studies, not for real data.

Model (:func:`dsn_tracking`): the two-way light time of
:func:`tqdyn.od.measurements.two_way`, satellite state at the bounce time.
Heliocentric: the station's barycentric position is the Earth's (the
project's JPL ephemeris, :func:`tqdyn.lightpath.heliocentric.body_states`)
plus its GCRS position (project's ITRS -> GCRS with EOP, evaluated at the TT
instant of the TDB time), both at the transmit / receive instants, expressed
relative to the Sun's position at the time tag (the Sun moves V_sun tau,
~2 km during a 170 s leg, along its barycentric velocity); the Sun's
Shapiro delay is added to each leg (~10-50 m).  Not modelled: the
GCRS -> BCRS Lorentz contraction of the station vector (~6 cm), the Earth's
Shapiro delay (~cm), troposphere, ionosphere and the solar corona
(calibrated for real data), the antennas' axis offsets.
Visibility: elevation >= the mask (default 10 deg) at the time tag.
Range rate: the exact time derivative of the two-way range (instantaneous
Doppler, in m/s); the integrated (count) Doppler of real data is its mean
over the count interval.  Noise (:data:`DSN_RANGE_SIGMA_M`,
:data:`DSN_DOPPLER_SIGMA_M_S`): m-level range, mm/s Doppler (60 s X band:
~0.1 mm/s; 1 mm/s a conservative default).
"""

from __future__ import annotations

import erfa
import numpy as np

from .._choices import unknown
from ..astro.ephemeris import default_ephemeris, planetary_gm
from ..astro.reference import HELIOCENTRIC
from ..astro.timescales import tdb_minus_tt
from ..lightpath.heliocentric import body_states, sun_barycentric_motion
from ..lightpath.shapiro import shapiro_delay
from .measurements import Observable, geocentric_two_way, sin_elevation, station_states_gcrs, two_way

__all__ = ["DEEP_SPACE_STATIONS", "DSN_DOPPLER_SIGMA_M_S", "DSN_RANGE_SIGMA_M", "dsn_tracking",
           "station_itrs"]

_ESTRACK_GEODETIC = {   # name: (east longitude [deg], latitude [deg], height [m])
    "Cebreros": (-4.3675499, 40.4526901, 794.0),
    "Malargue": (-69.3981934, -35.7760086, 1550.0),
    "New Norcia": (116.1914978, -31.0482254, 252.0),
}

#: Deep-space stations: name -> ITRF position (3,) [m] (see the module docstring).
DEEP_SPACE_STATIONS = {
    "DSS-14 Goldstone": np.array([-2353621.4197, -4641341.4717, 3677052.3178]),
    "DSS-43 Canberra": np.array([-4460894.9170, 2682361.5070, -3674748.1517]),
    "DSS-63 Madrid": np.array([4849092.5175, -360180.3480, 4115109.2506]),
    **{name: np.asarray(erfa.gd2gc(1, np.radians(lon), np.radians(lat), h), np.float64)
       for name, (lon, lat, h) in _ESTRACK_GEODETIC.items()},
}
#: Default noise of two-way range [m] and range rate [m/s].
DSN_RANGE_SIGMA_M = 1.0
DSN_DOPPLER_SIGMA_M_S = 1e-3


def station_itrs(stations=None) -> tuple[list[str], np.ndarray]:
    """Names and ITRF positions (S, 3) [m] of deep-space stations (default all)."""
    names = list(DEEP_SPACE_STATIONS) if stations is None else list(stations)
    bad = [s for s in names if s not in DEEP_SPACE_STATIONS]
    if bad:
        raise ValueError(unknown("deep-space station", bad[0], DEEP_SPACE_STATIONS,
                                 "docs/od-measurements.md#measurement-models", noun="stations"))
    return names, np.array([DEEP_SPACE_STATIONS[s] for s in names])


def dsn_tracking(epoch, t, r, v, stations=None, *, heliocentric: bool = True, ephemeris=None,
                 elevation_mask_deg: float = 10.0, shapiro: bool = True, eop=None,
                 use_eop: bool = True) -> tuple[Observable, Observable]:
    """Two-way range and range rate from deep-space stations.

    epoch : scenario :class:`~tqdyn.astro.timescales.Epoch`; t : (N,) bounce
    times [s since the epoch: TDB heliocentric, TT geocentric]; r, v : (N, 3)
    satellite position [m] and velocity [m/s] at t (Sun-centred BCRS, or
    GCRS when ``heliocentric`` is False); stations : names of
    :data:`DEEP_SPACE_STATIONS` (default all); ephemeris : the run's
    :class:`~tqdyn.astro.ephemeris.Ephemeris` (default the project's).

    Returns (range, range_rate) :class:`~tqdyn.od.measurements.Observable`:
    values (N, S) [m], [m/s]; d_r, d_v (N, S, 3); visible (N, S); extra
    ``stations``, ``tau_up``, ``tau_down`` [s], ``t_transmit``,
    ``t_receive`` [s since the epoch, the run's scale].
    """
    t = np.asarray(t, np.float64)
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    names, itrs = station_itrs(stations)
    S = itrs.shape[0]
    if heliocentric:
        eph = default_ephemeris() if ephemeris is None else ephemeris
        tdb1, tdb2 = epoch.tdb
        # TT seconds since the epoch of the TDB instants t (TDB - TT varies by < 1.7 ms)
        t_tt = t - (tdb_minus_tt(tdb1, tdb2 + t / 86400.0) - (tdb2 - epoch.tt[1]) * 86400.0
                    - (tdb1 - epoch.tt[0]) * 86400.0)
        _xs, v_sun, _as = sun_barycentric_motion(eph, epoch, t, HELIOCENTRIC)        # (N, 3)
        gm_sun = planetary_gm()["sun"]

        def states(dt):
            dt = np.broadcast_to(np.asarray(dt, np.float64), (t.size, S))
            th = np.broadcast_to(t[:, None], dt.shape).ravel()
            pe, ve = body_states(eph, epoch, (th, dt.ravel()), ("earth",), HELIOCENTRIC)
            R, V, A = station_states_gcrs(epoch, t_tt, itrs, dt=dt, eop=eop, use_eop=use_eop)
            R = R + pe[:, 0].reshape(R.shape) + v_sun[:, None, :] * dt[..., None]
            V = V + ve[:, 0].reshape(V.shape) + v_sun[:, None, :]
            return R, V, A

        delay = (lambda R, rr: shapiro_delay(R, rr[:, None, :], gm_sun)) if shapiro else None
        res = two_way(t, r, v + v_sun, states, delay=delay)
        pe0, _ = body_states(eph, epoch, t, ("earth",), HELIOCENTRIC, velocity=False)
        sel = sin_elevation(epoch, t_tt, itrs, r - pe0[:, 0], eop=eop, use_eop=use_eop)
    else:
        res, sel = geocentric_two_way(epoch, t, r, v, itrs, eop=eop, use_eop=use_eop, shapiro=shapiro)
    visible = sel >= np.sin(np.radians(elevation_mask_deg))
    extra = {"stations": names, "tau_up": res["tau_up"], "tau_down": res["tau_down"],
             "t_transmit": t[:, None] - res["tau_up"], "t_receive": t[:, None] + res["tau_down"],
             "sin_elevation": sel}
    rng = Observable(res["range"], res["range_dr"], np.zeros_like(res["range_dr"]), visible,
                     "two-way range", "m", extra)
    rate = Observable(res["range_rate"], res["range_rate_dr"], res["range_rate_dv"], visible,
                      "two-way range rate", "m/s", extra)
    return rng, rate
