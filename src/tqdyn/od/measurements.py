"""Measurement models of orbit determination: the common parts.

Every model is a function of the satellites' states at the measurements' time
tags -- positions r [m] and velocities v [m/s], GCRS for geocentric runs
(time tags t in TT seconds since the scenario epoch), Sun-centred BCRS for
heliocentric ones (TDB seconds) -- and returns an :class:`Observable`: the
computed observable, its partial derivatives with respect to the
satellite's position and velocity at the time tag (the estimator chains them
with the state transition matrix), and a visibility mask.  :func:`simulate`
adds seeded white noise and biases to a computed observable.

This module also holds the ground-station geometry shared by satellite laser
ranging (:mod:`.measurements_slr`) and the deep-space stations
(:mod:`.measurements_dsn`):

* :func:`station_states_gcrs`: a station's ITRS position rotated into the
  GCRS with the project's IAU 2006/2000A transformation and EOP
  (:func:`tqdyn.astro.earth_orientation.earth_orientation`), its velocity
  omega x R and acceleration omega x (omega x R) about the CIP (the rates of
  precession-nutation, ~1e-11 rad/s, change the velocity by < 1e-4 m/s and
  are left out);
* :func:`sin_elevation`: elevation above the WGS84 ellipsoid's horizon
  (the geodetic normal, ``erfa.gc2gd``);
* :func:`two_way`: the two-way light time of a signal sent by a station at
  t - tau_up, reflected or transponded by the satellite at the time tag t
  (the *bounce* time) and received by the same station at t + tau_down,
  solved by fixed-point iteration with the station *moving* (its position
  re-evaluated at the shifted instants), with the two-way range
  c (tau_up + tau_down) / 2, the two-way range rate (its time derivative),
  and their exact partials.

Time tags: the satellite's state is the one at the bounce time t.  A
station's data are usually tagged at transmission (laser ranging normal
points: the fire time) or reception (deep-space tracking): those are
``t - tau_up`` and ``t + tau_down``, returned with the observable
(``extra["t_transmit"]``, ``extra["t_receive"]``), so that either convention
can be matched.

Derivation of the partials (R(t'), V(t'), A(t'): the station's position,
velocity and acceleration; s = -1 for the up leg, +1 for the down leg;
D = r - R(t + s tau), L = |D|, u = D / L):

* light time: c tau = L, hence c d tau = u . (dr - s V d tau), i.e.
  d tau / dr = u / (c + s u . V);
* its rate: c tau' = u . (v - V (1 + s tau')), i.e.
  tau' = u . (v - V) / (c + s u . V); differentiating N = u . (v - V) and
  Dn = c + s u . V through du = (I - u u^T) / L dD,
  dD = (I - s V g^T) dr, dV = s A g^T dr (g = d tau / dr) gives
  d tau' / dr = (dN - tau' dDn) / Dn and d tau' / dv = u / Dn.

Neglected, with their sizes: the troposphere and the ionosphere (to be
modelled as corrections, as they are for real data), the relativistic
delays apart from the Shapiro delay of the central body where noted, the
station's tidal and loading displacements (cm), the antenna or retroreflector
offsets from the centre of mass (cm-m: calibrated as biases).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import erfa
import numpy as np

from ..astro.constants import C_LIGHT
from ..astro.earth_orientation import earth_orientation
from ..lightpath.shapiro import shapiro_delay

__all__ = ["EARTH_ROTATION_RATE", "Observable", "geocentric_two_way", "simulate", "sin_elevation", "station_states_gcrs",
           "two_way"]

#: Earth rotation rate d(ERA)/d(UT1) [rad/s]: 2 pi x 1.00273781191135448 / 86400
#: (IERS Conventions 2010, TN36 eq. 5.15); UT1 runs at TT's rate to ~1e-8 (LOD).
EARTH_ROTATION_RATE = 2.0 * np.pi * 1.00273781191135448 / 86400.0


@dataclass(frozen=True)
class Observable:
    """A computed observable, its partials and its visibility.

    value : (N, ...) float64 -- the observable [m for ranges, m/s for range
        rates]; NaN where it cannot be computed.
    d_r, d_v : (N, ..., 3) float64 -- partial derivatives of ``value`` with
        respect to the satellite's position [m/m] and velocity [m/(m/s)] at
        the time tag, in the frame of the input states (for the
        inter-satellite links: (N, L, 2, 3), receiver then emitter).
    visible : (N, ...) bool -- whether the measurement exists (elevation
        mask, occultation, link budget, ...).
    kind, unit : str -- e.g. "two-way range", "m".
    extra : dict -- model-specific arrays (light times, partial with respect
        to a clock bias, station instants, ...), documented by each model.
    """

    value: np.ndarray
    d_r: np.ndarray
    d_v: np.ndarray
    visible: np.ndarray
    kind: str
    unit: str
    extra: dict = field(default_factory=dict)


def simulate(obs: Observable, sigma, *, bias=0.0, seed: int = 0) -> np.ndarray:
    """Simulated measurements: ``obs.value + bias + sigma * n`` with n
    standard normal from ``numpy.random.default_rng(seed)``, NaN where the
    measurement is not visible.

    sigma, bias : float or arrays broadcasting with ``obs.value`` [unit of
    the observable] (a bias per station: shape (S,) for values (N, S)).
    Returns a new float64 array of ``obs.value``'s shape; the same seed
    gives the same numbers."""
    sigma = np.asarray(sigma, np.float64)
    if np.any(sigma < 0) or not np.all(np.isfinite(sigma)):
        raise ValueError(f"sigma: {sigma!r} is not allowed; expected finite values >= 0")
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal(obs.value.shape)
    out = obs.value + np.asarray(bias, np.float64) + sigma * noise
    return np.where(obs.visible, out, np.nan)


def _itrs_vectors(itrs) -> np.ndarray:
    x = np.asarray(itrs, np.float64)
    if x.ndim == 1:
        x = x[None, :]
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"station positions: shape {x.shape} is not allowed; expected (S, 3) [m, ITRS]")
    return x


def station_states_gcrs(epoch, t, itrs, *, dt=0.0, eop=None, use_eop: bool = True):
    """GCRS position, velocity and acceleration of ground stations.

    epoch : :class:`tqdyn.astro.timescales.Epoch`; t : (N,) [s TT since the
    epoch]; dt : (N, S) or scalar [s] added to t for each station (the
    light-time shifts); itrs : (S, 3) [m] station positions in the ITRS
    (Earth-fixed: plate motion is applied by the caller).
    eop, use_eop : as :func:`tqdyn.astro.earth_orientation.earth_orientation`.

    Returns R, V, A: (N, S, 3) [m, m/s, m/s^2], GCRS; V = omega x R and
    A = omega x V with omega = EARTH_ROTATION_RATE times the CIP
    (ITRS direction (x_p, -y_p, 1), to first order in polar motion).
    """
    x = _itrs_vectors(itrs)
    t = np.asarray(t, np.float64)
    tt = np.broadcast_to(t[:, None], (t.size, x.shape[0]))
    dts = np.broadcast_to(np.asarray(dt, np.float64), tt.shape)
    eo = earth_orientation(epoch, tt, dts, eop, use_eop=use_eop)
    T = eo.T_GCRS_ITRS                                              # (N, S, 3, 3)
    w = np.stack([eo.xp, -eo.yp, np.ones_like(eo.xp)], axis=-1) * EARTH_ROTATION_RATE   # (N, S, 3) ITRS
    vx = np.cross(w, x)                                             # (N, S, 3)
    ax = np.cross(w, vx)
    R = np.einsum("nsij,sj->nsi", T, x)
    V = np.einsum("nsij,nsj->nsi", T, vx)
    A = np.einsum("nsij,nsj->nsi", T, ax)
    return R, V, A


def geodetic_up(itrs) -> np.ndarray:
    """(S, 3) unit normals of the WGS84 ellipsoid at the stations (ITRS), from
    ``erfa.gc2gd(1, x)`` (geodetic longitude and latitude)."""
    x = _itrs_vectors(itrs)
    lon, lat, _h = erfa.gc2gd(1, x)
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)


def sin_elevation(epoch, t, itrs, r, *, eop=None, use_eop: bool = True) -> np.ndarray:
    """Sine of the elevation of satellites seen from ground stations.

    t : (N,) [s TT since the epoch]; itrs : (S, 3) [m, ITRS]; r : (N, 3)
    satellite positions [m, GCRS].  Elevation above the station's geodetic
    horizon (WGS84 normal), geometric (no refraction, no light time: the
    satellite moves < 0.01 deg during the light time at 1e5 km).
    Returns (N, S)."""
    x = _itrs_vectors(itrs)
    t = np.asarray(t, np.float64)
    tt = np.broadcast_to(t[:, None], (t.size, x.shape[0]))
    T = earth_orientation(epoch, tt, 0.0, eop, use_eop=use_eop).T_GCRS_ITRS
    up = np.einsum("nsij,sj->nsi", T, geodetic_up(x))
    R = np.einsum("nsij,sj->nsi", T, x)
    d = np.asarray(r, np.float64)[:, None, :] - R
    return np.einsum("nsi,nsi->ns", d, up) / np.linalg.norm(d, axis=-1)


def _leg(r, v, states, s: int, delay):
    """One leg: light time tau (fixed point of c tau = |r - R(t + s tau)| + c delay(.)),
    its gradient g = d tau/dr and the rate tau' with its partials."""
    tau = None
    R = V = A = None
    for _ in range(4):     # |V|/c ~ 1e-6 (1e-4 heliocentric): 4 iterations reach < 1e-20 s relative
        shift = 0.0 if tau is None else s * tau
        R, V, A = states(shift)
        D = r[:, None, :] - R
        L = np.linalg.norm(D, axis=-1)
        if delay is None:
            extra = 0.0
        else:   # the delay diverges on rays through the body's centre (hidden rays): 0 there
            with np.errstate(divide="ignore", invalid="ignore"):
                extra = np.nan_to_num(delay(R, r), nan=0.0, posinf=0.0)
        tau = L / C_LIGHT + extra
    u = D / L[..., None]
    uV = np.einsum("nsi,nsi->ns", u, V)
    Dn = C_LIGHT + s * uV
    g = u / Dn[..., None]                                   # d tau / dr
    w = v[:, None, :] - V
    N = np.einsum("nsi,nsi->ns", u, w)
    rate = N / Dn                                           # d tau / dt
    # d u / dr = P / L (I - s V g^T); dN/dr, dDn/dr
    P = np.eye(3) - u[..., :, None] * u[..., None, :]
    M = (np.eye(3) - s * V[..., :, None] * g[..., None, :])
    PM = np.einsum("nsij,nsjk->nsik", P, M) / L[..., None, None]
    uA = np.einsum("nsi,nsi->ns", u, A)
    dN = np.einsum("nsi,nsik->nsk", w, PM) - s * uA[..., None] * g
    dDn = s * (np.einsum("nsi,nsik->nsk", V, PM) + s * uA[..., None] * g)
    d_rate_dr = (dN - rate[..., None] * dDn) / Dn[..., None]
    d_rate_dv = g
    return tau, g, rate, d_rate_dr, d_rate_dv, R


def two_way(t, r, v, states, *, delay=None):
    """Two-way light times, range and range rate between stations and a satellite.

    t : (N,) time tags = bounce times [s since the epoch, the run's time
    scale]; r, v : (N, 3) satellite position [m] and velocity [m/s] at t
    (GCRS or Sun-centred BCRS); states : callable ``states(dt)`` with dt a
    scalar or (N, S) array [s] returning the stations' (R, V, A) (N, S, 3)
    at t + dt in the same frame [m, m/s, m/s^2]; delay : optional callable
    ``delay(R, r)`` -> (N, S) [s], an extra one-way delay (e.g. the Shapiro
    delay of the central body), whose own partials are neglected.

    Returns a dict of (N, S) arrays: ``tau_up``, ``tau_down`` [s];
    ``range`` = c (tau_up + tau_down) / 2 [m] with ``range_dr`` (N, S, 3);
    ``range_rate`` = d range / dt [m/s] with ``range_rate_dr``,
    ``range_rate_dv`` (N, S, 3); ``R_transmit``, ``R_receive`` (N, S, 3) the
    station positions at t - tau_up and t + tau_down [m].
    """
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    tu, gu, ru, dru, dvu, Ru = _leg(r, v, states, -1, delay)
    td, gd, rd, drd, dvd, Rd = _leg(r, v, states, +1, delay)
    half_c = 0.5 * C_LIGHT
    return {"tau_up": tu, "tau_down": td,
            "range": half_c * (tu + td), "range_dr": half_c * (gu + gd),
            "range_rate": half_c * (ru + rd), "range_rate_dr": half_c * (dru + drd),
            "range_rate_dv": half_c * (dvu + dvd),
            "R_transmit": Ru, "R_receive": Rd}


def geocentric_two_way(epoch, t, r, v, itrs, *, eop=None, use_eop: bool = True, shapiro: bool = True):
    """Two-way light time between ground stations and a satellite of a geocentric run.

    t : (N,) bounce times [s TT since the epoch]; r, v : (N, 3) satellite GCRS position [m] and
    velocity [m/s] at t; itrs : (S, 3) station ITRS positions [m]; ``shapiro``: add the Earth's
    Shapiro delay on each leg.  Returns (the dict of :func:`two_way`, sin_elevation (N, S))."""
    def states(dt):
        return station_states_gcrs(epoch, t, itrs, dt=dt, eop=eop, use_eop=use_eop)

    delay = (lambda R, rr: shapiro_delay(R, rr[:, None, :])) if shapiro else None
    return two_way(t, r, v, states, delay=delay), sin_elevation(epoch, t, itrs, r, eop=eop, use_eop=use_eop)
