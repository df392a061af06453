"""The BCRS physics of the LISA export at its home: barycentric states, Shapiro delays of bodies away from the
origin, and the TCB clocks of a geocentric run (tqdyn.lightpath.heliocentric.ssb_states,
tqdyn.lightpath.shapiro.add_shapiro_delays, tqdyn.lightpath.proper_time_bcrs.proper_time_deviation_geocentric_tcb).

References, independent of the code under test:
* the ephemeris's barycentric Earth (segments 0 -> 3 -> 399) against the Sun-centred Earth moved by
  ssb_states (segments 0 -> 10);
* the light-time solver's own Shapiro term (solved iteratively in its equation, heliocentric, Sun at rest)
  against the first-order addition to the geometric light times;
* the BCRS metric: d tau/dTCB = 1 - (U + v^2/2)/c^2 with U the Earth's monopole plus the potential of the Sun,
  the Moon and the planets at the satellite (ephemeris positions, DE430 GMs) and v the barycentric velocity,
  for circular geocentric orbits of radius 1e8 m written out here.
Measured values are quoted with each test; bounds are 3-10x them.
"""

from __future__ import annotations

import numpy as np

from tqdyn.astro.constants import C_LIGHT, GM_EARTH_EGM2008, L_B
from tqdyn.astro.ephemeris import default_ephemeris, planetary_gm
from tqdyn.astro.geocentric import EXTERNAL_BODIES, TDB_TO_TT_SCALE, gcrs_to_bcrs_states
from tqdyn.astro.reference import HELIOCENTRIC
from tqdyn.astro.timescales import Epoch, tdb_after
from tqdyn.lightpath import light_travel_times
from tqdyn.lightpath.heliocentric import ssb_states
from tqdyn.lightpath.proper_time_bcrs import proper_time_deviation_geocentric_tcb
from tqdyn.lightpath.shapiro import add_shapiro_delays

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")
AU = 149597870700.0
GM_SUN = planetary_gm()["sun"]


def test_ssb_states_give_the_ephemeris_barycentric_earth():
    # measured: 3.1e-5 m (the rounding of 1.5e11 m positions), 9.1e-13 m/s
    eph = default_ephemeris()
    t = np.arange(0.0, 30 * 86400.0, 3600.0)
    jd1, jd2 = tdb_after(EPOCH, t)
    pos, vel = eph.heliocentric_states(("earth",), jd1, jd2)
    zero = np.zeros_like(pos)
    st = ssb_states(eph, EPOCH, t, {"earth": ((pos, zero), (vel, zero), zero)})
    (xh, xl), (vh, vl), a = st["bodies"]["earth"]
    x, v = eph.earth_barycentric(jd1, jd2)
    assert np.abs((xh + xl)[:, 0] - x).max() < 3e-4
    assert np.abs((vh + vl)[:, 0] - v).max() < 1e-11
    assert np.array_equal(a[:, 0], st["a_sun"]) and 1e-7 < np.linalg.norm(st["a_sun"], axis=-1).max() < 1e-6


def _triangle(t, L=2.5e9):
    """A rigid triangle of side L turning once a year about a point on a circular 1 au orbit (plane tilted by
    60 deg): Sun-centred positions, velocities, accelerations (N, 3, 3), exact."""
    n = np.sqrt(GM_SUN / AU ** 3)
    c = AU * np.stack([np.cos(n * t), np.sin(n * t), 0 * t], -1)
    cv = AU * n * np.stack([-np.sin(n * t), np.cos(n * t), 0 * t], -1)
    e1, e2 = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.5, np.sqrt(3) / 2])
    r, v, a = [], [], []
    for i in range(3):
        ph = (-n * t + 2 * np.pi * i / 3)[:, None]
        d = L / np.sqrt(3) * (np.cos(ph) * e1 + np.sin(ph) * e2)
        dv = L / np.sqrt(3) * n * (np.sin(ph) * e1 - np.cos(ph) * e2)
        r.append(c + d), v.append(cv + dv), a.append(-n * n * (c + d))
    return np.stack(r, 1), np.stack(v, 1), np.stack(a, 1)


def test_added_shapiro_delay_is_the_solvers():
    # The solver with the Sun's Shapiro term in its equation vs the geometric solution plus s / (1 - n.v_e/c):
    # measured 1.7e-19 s on delays of 1.64e-7 .. 1.65e-7 s, rates 2.2e-20 on a Shapiro rate of 2.4e-16
    # (LISA-like triangle at 1 au, 10 days at 600 s).
    t = np.arange(0.0, 10 * 86400.0, 600.0)
    r, v, a = _triangle(t)
    still = np.zeros((t.size, 3))
    lp0 = light_travel_times(t, r, v, a, reference=HELIOCENTRIC, origin_velocity=still, shapiro=False)
    lp1 = light_travel_times(t, r, v, a, reference=HELIOCENTRIC, origin_velocity=still, shapiro=True)
    tau, rate = add_shapiro_delays(lp0, [(still, GM_SUN)])
    s = (lp1.tau[0] - lp0.tau[0]) + (lp1.tau[1] - lp0.tau[1])
    assert 1.6e-7 < np.nanmin(s) and np.nanmax(s) < 1.7e-7
    assert np.nanmax(np.abs((tau[0] - lp1.tau[0]) + (tau[1] - lp1.tau[1]))) < 1e-18
    assert np.nanmax(np.abs(rate - lp1.tau_rate)) < 2e-19
    assert np.all(np.isnan(tau[0][0])) and np.all(np.isfinite(tau[0][1:]))   # the first row has no emission time
    assert add_shapiro_delays(lp0, [])[0] is lp0.tau


def test_geocentric_clocks_against_tcb_follow_the_bcrs_metric():
    # Circular geocentric orbits of radius 1e8 m (TianQin's), 2 days at 300 s: the rate per TCB second against
    # -(GM_E/r + U_ext(x_B) + v_B^2/2)/c^2 from the BCRS states: measured 5.2e-15 (mean 1.0e-15) on rates of
    # -1.52e-8 .. -1.40e-8 (the tidal quadrupole of U_ext at 1e8 m, ~4e-15, is not in the clock model), and
    # delta_tau against the integral of that rate: 3.7e-10 s of 2.6e-3 s; the rates' derivatives against that
    # rate's finite differences: 2.5e-19 of 1.3e-14 /s.
    eph = default_ephemeris()
    gm = float(GM_EARTH_EGM2008)
    R = 1e8
    n = np.sqrt(gm / R ** 3)
    t = np.arange(0.0, 2 * 86400.0 + 1.0, 300.0)
    e1, e2 = np.array([1.0, 0.0, 0.0]), np.array([0.0, np.cos(1.6), np.sin(1.6)])
    ph = [(n * t + 2 * np.pi * i / 3)[:, None] for i in range(3)]
    r = np.stack([R * (np.cos(p) * e1 + np.sin(p) * e2) for p in ph], 1)
    v = np.stack([R * n * (-np.sin(p) * e1 + np.cos(p) * e2) for p in ph], 1)
    a = -gm * r / R ** 3
    zero, tt = np.zeros_like(r), (t, np.zeros_like(t))
    st = gcrs_to_bcrs_states(EPOCH, tt, {"sat": ((r, zero), (v, zero), a)}, eph)
    dtau, rate, rate_dot = proper_time_deviation_geocentric_tcb(tt, r, v, a, st, gm)
    (xh, xl), (vh, vl), _ = st["bodies"]["sat"]
    xb, vb = xh + xl, vh + vl
    jd1, jd2 = tdb_after(EPOCH, *st["t"])
    names = tuple(b for b in EXTERNAL_BODIES if b in eph.bodies)
    rel, _ = eph.geocentric_states(names, jd1, jd2, velocity=False)
    bodies = eph.earth_barycentric(jd1, jd2)[0][:, None, :] + rel
    gms = np.array([planetary_gm()[b] for b in names])
    u_ext = np.sum(gms / np.linalg.norm(xb[:, :, None, :] - bodies[:, None], axis=-1), axis=-1)
    u_earth = gm / TDB_TO_TT_SCALE / np.linalg.norm(st["y"]["sat"][0], axis=-1)
    ref = -(u_earth + u_ext + 0.5 * np.sum(vb * vb, -1)) / C_LIGHT ** 2
    assert -1.6e-8 < rate.min() and rate.max() < -1.3e-8
    assert np.abs(rate - ref).max() < 2e-14
    t_c = (st["t"][0] + st["t"][1]) / (1 - L_B)
    integral = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * np.diff(t_c)[:, None] * (ref[1:] + ref[:-1]), 0)])
    assert np.all(dtau[0] == 0.0) and np.abs(dtau - integral).max() < 2e-9
    assert np.abs(rate_dot - np.gradient(ref, t_c, axis=0, edge_order=2)).max() < 2e-18
