"""Measurement models of orbit determination (tqdyn.od.measurements*).

References: central finite differences of the models' own values for the
partials (step sizes chosen so that truncation and rounding are both
< 1e-7 of the partials); pyerfa (``erfa.c2t06a``, ``erfa.gd2gc``) for the
station's GCRS position in an independent two-way light-time solution;
the finite difference of the two-way range in time for the range rate;
geometry with a known answer for the GNSS visibility; the published numbers
of GPS signals tracked above the GPS constellation by NASA's MMS mission
(Winternitz et al. 2017, NAVIGATION 64(2), "GPS navigation above 76,000 km
for the MMS mission": a handful of signals on average between 12 and 25
Earth radii with side-lobe reception, fewer at the larger distance; the
bound below is that order, not a fitted value) for the count at TianQin's
1e5 km (15.7 Earth radii).
"""

from __future__ import annotations

import erfa
import numpy as np
import pytest

from tqdyn.astro.constants import C_LIGHT, GM_EARTH_EGM2008
from tqdyn.astro.timescales import Epoch
from tqdyn.od.measurements import Observable, simulate
from tqdyn.od.measurements_dsn import dsn_tracking
from tqdyn.od.measurements_gnss import GPS, BEIDOU_MEO, gnss_visibility, pseudorange
from tqdyn.od.measurements_isr import isr_range
from tqdyn.od.measurements_slr import slr_range, slr_station_positions

EPOCH = Epoch.from_utc("2020-06-01T00:00:00")
GM = float(GM_EARTH_EGM2008)


def _orbit(t, radius=1e8, inc=1.6):
    n = np.sqrt(GM / radius ** 3)
    c, s = np.cos(n * t), np.sin(n * t)
    r = radius * np.stack([c, s * np.cos(inc), s * np.sin(inc)], -1)
    v = radius * n * np.stack([-s, c * np.cos(inc), c * np.sin(inc)], -1)
    return r, v


def _fd(f, x, h):
    """Central differences of f (returns (N, S)) w.r.t. x (N, 3): (N, S, 3)."""
    cols = []
    for i in range(3):
        d = np.zeros_like(x)
        d[:, i] = h
        cols.append((f(x + d) - f(x - d)) / (2 * h))
    return np.stack(cols, -1)


def test_slr_partials_match_finite_differences():
    t = np.array([0.0, 7200.0, 30000.0])
    r, v = _orbit(t)
    obs = slr_range(EPOCH, t, r, v)
    num = _fd(lambda x: slr_range(EPOCH, t, x, v).value, r, 10.0)
    assert np.max(np.abs(obs.d_r - num)) < 1e-8      # measured 1.9e-9
    assert np.max(np.abs(np.linalg.norm(obs.d_r, axis=-1) - 1)) < 1e-5


def test_slr_range_against_pyerfa_station_positions():
    """Two-way range without EOP (UT1 = UTC, no polar motion) against an
    independent solution: the station's GCRS position from erfa.c2t06a at
    the transmit and receive instants, fixed-point light times, the same
    Shapiro formula (2 GM/c^3 ln((a+b+L)/(a+b-L)))."""
    t = np.array([1000.0, 20000.0])
    r, v = _orbit(t)
    obs = slr_range(EPOCH, t, r, v, ["Graz", "Yarragadee"], use_eop=False)
    _, itrs = slr_station_positions(EPOCH, ["Graz", "Yarragadee"])

    def station(tt_s, x):
        tt1, tt2 = EPOCH.tt[0], EPOCH.tt[1] + tt_s / 86400.0
        u1, u2 = erfa.taiutc(*erfa.tttai(tt1, tt2))          # UT1 = UTC
        return erfa.c2t06a(tt1, tt2, u1, u2, 0.0, 0.0).T @ x

    def shap(a, b):
        na, nb, L = np.linalg.norm(a), np.linalg.norm(b), np.linalg.norm(a - b)
        return 2 * GM / C_LIGHT ** 3 * np.log((na + nb + L) / (na + nb - L))

    for n in range(t.size):
        for s in range(2):
            legs = []
            for sign in (-1, 1):
                tau = 0.0
                for _ in range(6):
                    R = station(t[n] + sign * tau, itrs[s])
                    tau = np.linalg.norm(r[n] - R) / C_LIGHT + shap(R, r[n])
                legs.append(tau)
            ref = 0.5 * C_LIGHT * sum(legs)
            assert abs(obs.value[n, s] - ref) < 3e-7, (n, s, obs.value[n, s] - ref)   # measured 3e-8 m


def test_dsn_range_rate_is_the_time_derivative_and_partials_match():
    """Heliocentric: the range rate against the central difference of the
    range for a satellite on a straight line, and the partials of both."""
    ep = Epoch.from_tdb("2035-03-01T00:00:00")
    from tqdyn.astro.ephemeris import default_ephemeris
    from tqdyn.astro.reference import HELIOCENTRIC
    from tqdyn.lightpath.heliocentric import body_states
    t = np.array([0.0, 40000.0])
    pe, ve = body_states(default_ephemeris(), ep, t, ("earth",), HELIOCENTRIC)
    r = pe[:, 0] + np.array([2e10, -4e10, 1e10])
    v = ve[:, 0] + np.array([3.0, -5.0, 2.0])
    rng, rate = dsn_tracking(ep, t, r, v)
    h = 5.0
    plus, _ = dsn_tracking(ep, t + h, r + v * h, v)
    minus, _ = dsn_tracking(ep, t - h, r - v * h, v)
    fd = (plus.value - minus.value) / (2 * h)
    # float64 ranges of 5e10 m carry 8e-6 m ulps: the difference quotient is good to ~1e-5 m/s
    assert np.max(np.abs(rate.value - fd)) < 1e-4          # m/s (noise: 1e-3); measured 3.5e-5
    num = _fd(lambda x: dsn_tracking(ep, t, x, v)[0].value, r, 100.0)
    assert np.max(np.abs(rng.d_r - num)) < 1e-6
    num = _fd(lambda x: dsn_tracking(ep, t, x, v)[1].value, r, 1e4)
    assert np.max(np.abs(rate.d_r - num)) < 1e-11 + 1e-4 * np.max(np.abs(rate.d_r))
    num = _fd(lambda x: dsn_tracking(ep, t, r, x)[1].value, v, 1.0)
    assert np.max(np.abs(rate.d_v - num)) < 1e-8


def test_isr_range_solves_the_light_time_equation_and_partials():
    t = np.array([0.0, 100.0])
    r0, v0 = _orbit(t)
    rot = [np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]) for a in (0, 2.1, 4.2)]
    r = np.stack([r0 @ m.T for m in rot], 1)
    v = np.stack([v0 @ m.T for m in rot], 1)
    a = np.zeros_like(r)
    obs = isr_range(t, r, v, a)
    from tqdyn.constellation.indices import LINK_EMITTER, LINK_RECEIVER
    tau = obs.extra["tau"]
    xe = r[:, LINK_EMITTER] - v[:, LINK_EMITTER] * tau[..., None]
    assert np.max(np.abs(np.linalg.norm(r[:, LINK_RECEIVER] - xe, axis=-1) - obs.value)) < 1e-6
    for side, sat in ((0, LINK_RECEIVER), (1, LINK_EMITTER)):
        for link in range(6):
            k = sat[link]

            def f(x, k=k):
                rr = r.copy()
                rr[:, k] = x
                return isr_range(t, rr, v, a).value[:, link:link + 1]
            num = _fd(f, r[:, k], 10.0)[:, 0]
            assert np.max(np.abs(obs.d_r[:, link, side] - num)) < 1e-6


def test_gnss_visibility_known_geometry():
    """A GPS satellite directly behind the Earth is occulted; one between
    the Earth and the receiver points its antenna away (180 deg off
    boresight) and is not received; one far across, just outside the
    Earth's limb, is in the main lobe."""
    r = np.array([[1e8, 0.0, 0.0]])
    g = np.array([[[-26.56e6, 0.0, 0.0], [26.56e6, 0.0, 0.0], [-26.56e6, 9.0e6, 0.0]]])
    vis, theta, _cn0, occ = gnss_visibility(r, g)
    assert occ[0].tolist() == [True, False, False]
    assert vis[0].tolist() == [False, False, True]
    assert np.degrees(theta[0, 1]) == pytest.approx(180.0)


def test_visible_gnss_count_over_a_day_at_1e5_km():
    """Mean number of GPS signals received over a day at 1e5 km with
    side-lobe reception is of the order MMS tracked between 12 and 25
    Earth radii (a handful of signals); main-lobe reception alone gives
    fewer."""
    t = np.arange(0.0, 86400.0, 600.0)
    r, v = _orbit(t)
    side = pseudorange(t, r, v, GPS).visible.sum(1).mean()
    main = pseudorange(t, r, v, GPS, mode="main").visible.sum(1).mean()
    assert 2.0 <= side <= 10.0, side          # measured 4.1
    assert main < side
    assert pseudorange(t, r, v, BEIDOU_MEO).visible.sum(1).mean() > main


def test_pseudorange_partials_and_light_time():
    t = np.array([0.0, 5000.0])
    r, v = _orbit(t)
    obs = pseudorange(t, r, v, GPS)
    num = _fd(lambda x: pseudorange(t, x, v, GPS).value, r, 10.0)
    # the Shapiro delay's own gradient is left out: ~2GM/c^2 / (a + b - L), < 1e-9 for the
    # visible rays (> 100 km above the surface); it grows for rays grazing the Earth
    assert np.max(np.abs(obs.d_r - num)[obs.visible]) < 1e-8   # measured 2.0e-9
    g = obs.extra["r_emit"]
    geo = np.linalg.norm(r[:, None] - g, axis=-1)
    shap = (obs.value - geo)[obs.visible]
    assert np.all((shap > 0.005) & (shap < 0.1))     # the Earth's Shapiro delay: cm


def test_simulate_is_seeded_and_masked():
    val = np.zeros((20000, 2))
    vis = np.ones_like(val, bool)
    vis[0, 0] = False
    obs = Observable(val, np.zeros(val.shape + (3,)), np.zeros(val.shape + (3,)), vis, "x", "m")
    a = simulate(obs, 0.01, bias=[0.0, 1.0], seed=3)
    b = simulate(obs, 0.01, bias=[0.0, 1.0], seed=3)
    assert np.array_equal(a, b, equal_nan=True) and np.isnan(a[0, 0])
    assert abs(np.nanstd(a[:, 0]) - 0.01) < 5e-4 and abs(np.nanmean(a[:, 1]) - 1.0) < 5e-4
    with pytest.raises(ValueError, match="sigma"):
        simulate(obs, -1.0)


def test_arm_length_changes_agree_with_absolute_ranging():
    """The light-path ranges of tqdyn.lightpath (double-double, Hermite
    dense output) against the independent float64 Taylor solution of
    isr_range on Kepler orbits, and the double-double difference."""
    from tqdyn.od.measurements_isr import arm_length_changes
    t = np.arange(0.0, 2000.0, 50.0)
    rot = [np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]) for a in (0, 2.1, 4.2)]
    r0, v0 = _orbit(t)
    r = np.stack([r0 @ m.T for m in rot], 1)
    v = np.stack([v0 @ m.T for m in rot], 1)
    a = -GM * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3
    arm = arm_length_changes(t, r, v, a)
    absolute = isr_range(t, r, v, a)
    k = arm.extra["reference_row"]
    assert k == 1 and not arm.visible[0].any() and arm.visible[1:].all()
    total = arm.value[1:] + arm.extra["reference_range"]
    assert np.max(np.abs(total - absolute.value[1:])) < 3e-7       # m; measured 6e-8 (float64 ulp of 1.7e8 m: 3e-8)
    assert np.all(arm.value[k] == 0.0)
