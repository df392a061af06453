"""JPL ephemeris access (tqdyn.astro.ephemeris) and the ephemeris-driven third-body
term (tqdyn.forces.third_body_ephemeris).

References, each independent of tqdyn's Chebyshev code:
* jplephem's own segment evaluation (``SPK[center, target].compute_and_differentiate``,
  numpy Clenshaw recurrence), chained by hand in the test: km -> m, km/day -> m/s;
* finite differences of tqdyn's own positions for the velocities;
* order-of-magnitude facts: the Moon's geocentric distance stays within
  356,000-407,000 km (perigee/apogee extremes), the Sun's within
  1.471e11-1.521e11 m (perihelion/aphelion);
* the DE430/DE431 GMs as published by Folkner et al. (2014), "The Planetary
  and Lunar Ephemerides DE430 and DE431", IPN Progress Report 42-196, Table 8
  (km^3/s^2).
"""

from __future__ import annotations

import math
import pathlib
import pickle

import numpy as np
import pytest
from jplephem.spk import SPK

from tqdyn.astro.ephemeris import BODIES, Ephemeris, default_ephemeris, default_ephemeris_path, planetary_gm
from tqdyn.forces.third_body import ThirdBodies, third_body_accel
from tqdyn.forces.third_body_ephemeris import third_bodies
from tqdyn.astro.timescales import Epoch, tdb_jd
from tqdyn.readers.pck import parse_gm_tpc

JD_EPOCH = 2453162.5  # 2004-06-06 00:00 (TDB here)
BARY = {"mercury": 1, "venus": 2, "mars": 4, "jupiter": 5, "saturn": 6, "uranus": 7, "neptune": 8}


def _chain(body):
    """(center, target, sign) chain of the geocentric state, written out here."""
    if body == "moon":
        return [(3, 301, 1.0), (3, 399, -1.0)]
    target = 10 if body == "sun" else BARY[body]
    return [(0, target, 1.0), (0, 3, -1.0), (3, 399, -1.0)]


def _jplephem_state(kernel, body, jd1, jd2):
    """Geocentric state from jplephem's own evaluation: (n, 3) m, (n, 3) m/s."""
    pos = np.zeros((np.size(jd2), 3))
    vel = np.zeros((np.size(jd2), 3))
    for c, t, sign in _chain(body):
        p, v = kernel[c, t].compute_and_differentiate(jd1, jd2)  # km, km/day
        pos += sign * np.asarray(p).T * 1e3
        vel += sign * np.asarray(v).T * 1e3 / 86400.0
    return pos, vel


@pytest.fixture(scope="module")
def eph():
    return default_ephemeris()


@pytest.fixture(scope="module")
def kernel(eph):
    k = SPK.open(eph.path)
    yield k
    k.close()


def test_default_file_and_span(eph):
    assert eph.name == "DE421"
    assert pathlib.Path(eph.path).name == "de421.bsp"
    # DE421 covers 1899-07-29 .. 2053-10-09 (JD 2414864.5 .. 2471184.5, TDB)
    assert eph.span_jd == (2414864.5, 2471184.5)
    assert set(BODIES) <= set(eph.bodies)


@pytest.mark.parametrize("body", BODIES)
def test_positions_and_velocities_match_jplephem_chain(eph, kernel, body):
    """tqdyn's compiled Chebyshev evaluation vs jplephem's, over 1950-2050:
    agreement at float64 round-off (measured <= 6e-16 |r| and <= 3e-15 |v|)."""
    rng = np.random.default_rng(7)
    jd1 = np.full(400, 2451545.0)
    jd2 = rng.uniform(-18262.0, 18262.0, 400)
    pos, vel = eph.geocentric(body, jd1, jd2)
    ref_p, ref_v = _jplephem_state(kernel, body, jd1, jd2)
    assert pos.shape == vel.shape == (400, 3)
    dp = np.linalg.norm(pos - ref_p, axis=1)
    dv = np.linalg.norm(vel - ref_v, axis=1)
    assert np.all(dp <= 2e-15 * np.linalg.norm(ref_p, axis=1)), dp.max()  # Sun: 0.3 mm, Moon: 1 um
    assert np.all(dv <= 1e-14 * np.linalg.norm(ref_v, axis=1) + 1e-12), dv.max()


def test_span_end_points_and_broadcasting(eph, kernel):
    lo, hi = eph.span_jd
    for jd in (lo, hi):  # both end points are inside (last record includes its end)
        p, v = eph.geocentric("moon", jd, 0.0)
        rp, rv = _jplephem_state(kernel, "moon", jd, 0.0)
        assert np.linalg.norm(p - rp[0]) < 1e-6 and np.linalg.norm(v - rv[0]) < 1e-9
    # any shape, jd1 and jd2 broadcast
    jd2 = np.linspace(0.0, 1.0, 12).reshape(3, 4)
    p, v = eph.geocentric("sun", JD_EPOCH, jd2)
    assert p.shape == (3, 4, 3) and v.shape == (3, 4, 3)
    p1, _ = eph.geocentric("sun", np.full(12, JD_EPOCH), jd2.reshape(-1))
    np.testing.assert_array_equal(p.reshape(-1, 3), p1)
    ps, vs = eph.geocentric_states(("moon", "sun"), JD_EPOCH, jd2, velocity=False)
    assert ps.shape == (3, 4, 2, 3) and vs is None
    np.testing.assert_array_equal(ps[..., 1, :], p)


def test_known_magnitudes_at_epoch(eph):
    """Moon 356,000-407,000 km (lunar perigee/apogee extremes); Sun within
    perihelion/aphelion 1.471e11-1.521e11 m, and in early June near aphelion
    (> 1.51e11 m); the Moon's speed about the Earth ~1.0 km/s, the Sun's
    apparent speed ~29-30 km/s."""
    pm, vm = eph.geocentric("moon", JD_EPOCH, 0.0)
    ps, vs = eph.geocentric("sun", JD_EPOCH, 0.0)
    assert 3.56e8 < np.linalg.norm(pm) < 4.07e8
    assert 1.51e11 < np.linalg.norm(ps) < 1.521e11
    assert 0.9e3 < np.linalg.norm(vm) < 1.1e3
    assert 2.9e4 < np.linalg.norm(vs) < 3.05e4


@pytest.mark.parametrize("body", ["moon", "sun", "venus", "jupiter"])
def test_velocity_is_derivative_of_position(eph, body):
    """4th-order central difference of positions, h = 300 s, two-part time:
    truncation h^4 |x^(5)|/30 < 1e-9 m/s, round-off ~ulp(|r|)/h: 1e-7 m/s
    for the Sun, 3e-6 m/s for Jupiter; tolerance 1e-5 m/s."""
    h = 300.0 / 86400.0
    jd2 = np.linspace(0.0, 90.0, 37)
    p = {k: eph.geocentric(body, JD_EPOCH, jd2 + k * h)[0] for k in (-2, -1, 1, 2)}
    _, v = eph.geocentric(body, JD_EPOCH, jd2)
    fd = (8.0 * (p[1] - p[-1]) - (p[2] - p[-2])) / (12.0 * 300.0)
    assert np.max(np.abs(fd - v)) < 1e-5


def test_out_of_span_raises_naming_date_and_span(eph):
    with pytest.raises(ValueError, match=r"2060-01-01T00:00:00 TDB.*outside its span 1899-07-29.*2053-10-09"):
        eph.geocentric("moon", 2473459.5, 0.0)  # 2060-01-01
    with pytest.raises(ValueError, match=r"1890-.*outside its span"):
        eph.geocentric_states(BODIES, 2411368.5, np.array([0.0, 1.0]))  # 1890
    with pytest.raises(ValueError, match="not finite"):
        eph.geocentric("sun", JD_EPOCH, np.nan)
    # from a propagation's point of view: epoch 2053-09-01 + 60 days
    ep = Epoch.from_utc("2053-09-01T00:00:00")
    with pytest.raises(ValueError, match="outside its span"):
        third_bodies(eph).precompute(ep, np.array([0.0, 60 * 86400.0]), 0.0)


def test_bad_bodies_and_files(eph, tmp_path):
    with pytest.raises(ValueError, match="'pluto2' is not a body \\(did you mean 'pluto'\\?\\)"):
        eph.geocentric("pluto2", JD_EPOCH, 0.0)
    missing = tmp_path / "de440.bsp"
    with pytest.raises(FileNotFoundError, match=str(missing)):
        Ephemeris(missing)
    junk = tmp_path / "junk.bsp"
    junk.write_bytes(b"not a DAF file" * 100)
    with pytest.raises(ValueError, match="junk.bsp"):
        Ephemeris(junk)
    with pytest.raises(ValueError, match="listed twice"):
        third_bodies(eph, ("moon", "moon"))


def test_de_file_by_path_and_pickling(eph):
    """Any DE .bsp by path: the shipped DE421 opened by its path gives the
    same numbers; an Ephemeris pickles (reopened by path, for parallel runs)."""
    jd2 = np.linspace(0.0, 10.0, 50)
    with Ephemeris(pathlib.Path(default_ephemeris_path())) as other:
        assert other is not eph and other.name == "DE421"
        for body in ("moon", "sun", "mars"):
            np.testing.assert_array_equal(other.geocentric(body, JD_EPOCH, jd2)[0],
                                          eph.geocentric(body, JD_EPOCH, jd2)[0])
        clone = pickle.loads(pickle.dumps(other))
        np.testing.assert_array_equal(clone.geocentric("moon", JD_EPOCH, jd2)[1],
                                      other.geocentric("moon", JD_EPOCH, jd2)[1])
        clone.close()
        tb = pickle.loads(pickle.dumps(third_bodies(other, ("moon",))))
        assert tb.precompute(Epoch.from_utc("2004-06-06T00:00:00"), 0.0, 0.0).shape == (6,)  # scalar time: hi, lo
        tb.position.ephemeris.close()
    # after close: segments already read still work, unread ones raise
    other.geocentric("moon", JD_EPOCH, jd2)
    with pytest.raises(ValueError, match="closed"):
        other.geocentric("saturn", JD_EPOCH, jd2)


def test_split_segments_are_stitched(eph, kernel):
    """Files such as DE431/DE441 split a pair into segments covering
    different times.  Emulate it with two copies of DE421's Moon segment
    restricted to the two halves of the span: every instant is evaluated
    in one of them and the result is unchanged."""
    from tqdyn.astro import ephemeris as mod

    split = Ephemeris(eph.path)
    pair = split._pairs[(3, 301)]
    a, b = mod._Segment(pair.segments[0].seg), mod._Segment(pair.segments[0].seg)
    mid = 2440000.5
    a.end_jd, b.start_jd = mid, mid
    split._pairs[(3, 301)] = mod._Pair([b, a])
    assert split._pairs[(3, 301)].start_jd == eph.span_jd[0] and split._pairs[(3, 301)].end_jd == eph.span_jd[1]
    jd2 = np.linspace(-20000.0, 18000.0, 501)  # both sides of mid
    p, v = split.geocentric("moon", 2451545.0, jd2)
    rp, rv = _jplephem_state(kernel, "moon", np.full(501, 2451545.0), jd2)
    assert np.max(np.linalg.norm(p - rp, axis=1)) < 1e-6
    assert np.max(np.linalg.norm(v - rv, axis=1)) < 1e-9
    split.close()


def test_planetary_gm_published_values():
    """Folkner et al. (2014) Table 8 (DE430), km^3/s^2 -> m^3/s^2; the Earth
    from GM_EMB and EMRAT = 81.3005690741906200: GM_E = GM_EMB EMRAT/(1+EMRAT)."""
    gm = planetary_gm()
    published = {
        "sun": 132712440041.939400, "mercury": 22031.780000, "venus": 324858.592000, "mars": 42828.375214,
        "jupiter": 126712764.800000, "saturn": 37940585.200000, "uranus": 5794548.600000,
        "neptune": 6836527.100580, "pluto": 977.000000,
    }
    for name, value in published.items():  # the file prints 17 digits (e.g. 1.2671276480000021E+08)
        assert gm[name] == pytest.approx(value * 1e9, rel=5e-15), name
    emrat, gm_emb = 81.3005690741906200, 403503.235502259800e9
    assert gm["earth"] == pytest.approx(gm_emb * emrat / (1 + emrat), rel=1e-15)
    assert gm["moon"] == pytest.approx(gm_emb / (1 + emrat), rel=1e-15)
    assert set(BODIES) <= set(gm)


def test_gm_reader():
    text = ("junk BODY10_GM = ( 9 )\n\\begindata\n BODY10_GM = ( 1.5E+02 )\n BODY301_GM=(2.0D0)\n"
            "\\begintext\n BODY5_GM = ( 7 )")
    assert parse_gm_tpc(text) == {10: 1.5e11, 301: 2.0e9}
    with pytest.raises(ValueError, match="no BODYnnn_GM"):
        parse_gm_tpc("nothing here")


def _tianqin_orbit(t):
    """Circular TianQin-like orbit (Table I of the paper, Sat1: a = 1e5 km,
    i = 74.5 deg, Omega = 211.6 deg, nu0 = 30 deg), GCRS, at t [s]: (n, 3) m."""
    gm, a = 3.986004415e14, 1.0e8
    n = math.sqrt(gm / a**3)
    inc, raan = math.radians(74.5), math.radians(211.6)
    p = np.array([math.cos(raan), math.sin(raan), 0.0])
    q = np.array([-math.sin(raan) * math.cos(inc), math.cos(raan) * math.cos(inc), math.sin(inc)])
    u = math.radians(30.0) + n * np.asarray(t)
    return a * (np.cos(u)[:, None] * p + np.sin(u)[:, None] * q)


def test_third_bodies_factory_and_magnitudes_along_tianqin_orbit(eph):
    """Third-body accelerations over 10 days from 2004-06-06 on the TianQin
    orbit (600 s sampling).  Tidal estimate 2 GM r / d^3 (max) and GM r / d^3:
    Moon (d = 3.6e8 m): 1e-5..2.1e-5; Sun: 3.9e-6..7.9e-6; Venus, at inferior
    conjunction on 2004-06-08 (transit of Venus, d = 0.289 au = 4.3e10 m):
    GM r/d^3 = 4e-10 .. 8e-10; Jupiter (d ~ 5.6 au): 2e-11..4e-11 m/s^2.
    Measured maxima: Moon 2.2e-5, Sun 5.9e-6, Venus 6.3e-10, Jupiter 3.5e-11
    m/s^2.  Assert each within a factor 10 of the estimate GM r/d^3.
    (The ephemeris's own BCRS differences and GMs; the default GCRS
    transform, 1.5e-8 relative, is tests/test_geocentric.py's.)"""
    tb = third_bodies(eph, gcrs=False)
    assert isinstance(tb, ThirdBodies)
    assert tb.names == BODIES and tb.n_tdat == 54  # 27 coordinates and their low parts (dd)
    assert "DE421" in tb.source and "gm_de431.tpc" in tb.source
    np.testing.assert_array_equal(tb.params(), [9.0, *[planetary_gm()[b] for b in BODIES], *[0.0] * 9])  # + flags
    ep = Epoch.from_utc("2004-06-06T00:00:00")
    t = np.arange(0.0, 10 * 86400.0 + 1.0, 600.0)
    tdat = tb.precompute(ep, t, 0.0)
    assert tdat.shape == (t.size, 54)
    # positions are the ephemeris' at tdb_jd (the float64 evaluation: to its rounding, a few 1e-8 m
    # for the Moon's sums of segments), the dd low parts below half an ulp of the high parts
    jd1, jd2 = tdb_jd(ep, t, 0.0)
    assert np.abs(tdat[:, 3:6] - eph.geocentric("moon", jd1, jd2)[0]).max() < 1e-6
    assert np.all(np.abs(tdat[:, 27:]) <= 0.5 * np.spacing(np.abs(tdat[:, :27])))
    r = _tianqin_orbit(t)
    maxima = {}
    for k, name in enumerate(BODIES):
        acc = np.array([third_body_accel(*r[i], *tdat[i, 3 * k:3 * k + 3], tb.gms[k]) for i in range(t.size)])
        maxima[name] = float(np.max(np.linalg.norm(acc, axis=1)))
        d = float(np.min(np.linalg.norm(tdat[:, 3 * k:3 * k + 3], axis=1)))
        estimate = tb.gms[k] * 1.0e8 / d**3
        assert estimate / 10 < maxima[name] < 10 * estimate, (name, maxima[name], estimate)
    assert 1e-5 < maxima["moon"] < 3e-5
    assert 3e-6 < maxima["sun"] < 8e-6
    assert 1e-11 < maxima["jupiter"] < 1e-10
    assert 1e-10 < maxima["venus"] < 1e-9  # inferior conjunction (2004 transit)
