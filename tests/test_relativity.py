"""Post-Newtonian correction, IERS Conventions 2010 (TN36) eq. (10.12):
tqdyn.forces.relativity.

References:
* each of the three terms typed again here from TN36 eq. (10.12) in mpmath
  (50 digits), vector by vector, with R = Earth relative to the Sun;
* the circular-orbit closed form of the Schwarzschild term,
  3 (GM)^2 / (c^2 r^3) radially outward (r.v = 0, v^2 = GM/r);
* the geodetic (de Sitter) precession of the geocentric frame, 1.92"/century
  (e.g. TN36 ch. 10; Brumberg, Essential Relativistic Celestial Mechanics,
  1991): the de Sitter term is the Coriolis acceleration Omega x v with
  Omega = 2 x (geodetic precession);
* pyerfa's composite ``erfa.pnm06a`` (its third row is the CIP unit vector
  in the GCRS) for the direction of J.

Magnitudes on the TianQin orbit from first principles (r = 1e8 m,
v = sqrt(GM/r) = 1996 m/s, GM = 3.986e14, c = 2.998e8, GM_S = 1.327e20,
R = 1.5e11 m, |Rdot| = 2.98e4 m/s, |J| = 9.8e8 m^2/s):
* Schwarzschild: 3 GM^2/(c^2 r^3) = 3 (3.986e14)^2 / (8.988e16 * 1e24) = 5.3e-12 m/s^2;
* Lense-Thirring: 2 GM v |J| / (c^2 r^3) = 2 * 3.986e14 * 1996 * 9.8e8 / 8.988e40
  = 1.7e-14 m/s^2 (the (r x v)(r.J) term adds up to 3x that);
* de Sitter: 3 GM_S |Rdot| v / (c^2 R^2) = 3 * 1.327e20 * 2.98e4 * 1996 / (8.988e16 * 2.24e22)
  = 1.2e-11 m/s^2 -- larger than Schwarzschild at this radius.
Measured over 10 days from 2004-06-06: Schwarzschild 5.30e-12 (constant),
Lense-Thirring 4.6e-15 .. 3.4e-14, de Sitter 9e-13 .. 1.13e-11 m/s^2.
"""

from __future__ import annotations

import math

import erfa
import mpmath
import numpy as np
import pytest

from tqdyn.astro.ephemeris import default_ephemeris, planetary_gm
from tqdyn.forces.relativity import (N_TDAT, Relativity, cip_direction, de_sitter_accel, lense_thirring_accel,
                                     relativity_accel, schwarzschild_accel)
from tqdyn.astro.timescales import Epoch, tdb_jd

GM = 3.986004415e14  # m^3/s^2, EGM2008
C = 299792458.0  # m/s
GM_SUN = 1.3271244004193938e20  # m^3/s^2, gm_de431.tpc BODY10_GM
J = 9.8e8  # m^2/s, TN36 sec. 10.3
EPOCH = Epoch.from_utc("2004-06-06T00:00:00")


# --- mpmath references, TN36 eq. (10.12) -----------------------------------

def _mv(x):
    return [mpmath.mpf(float(c)) for c in x]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _mp_schwarzschild(r, v, beta=1, gamma=1):
    with mpmath.workdps(50):
        r, v = _mv(r), _mv(v)
        gm, c = mpmath.mpf(GM), mpmath.mpf(C)
        rn = mpmath.sqrt(_dot(r, r))
        a = (2 * (beta + gamma) * gm / rn - gamma * _dot(v, v))
        b = 2 * (1 + gamma) * _dot(r, v)
        return [float(gm / (c**2 * rn**3) * (a * ri + b * vi)) for ri, vi in zip(r, v)]


def _mp_lense_thirring(r, v, jvec, gamma=1):
    with mpmath.workdps(50):
        r, v, jv = _mv(r), _mv(v), _mv(jvec)
        gm, c = mpmath.mpf(GM), mpmath.mpf(C)
        rn = mpmath.sqrt(_dot(r, r))
        rxv, vxj = _cross(r, v), _cross(v, jv)
        rj = _dot(r, jv)
        return [float((1 + gamma) * gm / (c**2 * rn**3) * (3 / rn**2 * h * rj + w)) for h, w in zip(rxv, vxj)]


def _mp_de_sitter(v, sun_pos, sun_vel, gamma=1):
    with mpmath.workdps(50):
        v = _mv(v)
        R = [-x for x in _mv(sun_pos)]  # Earth w.r.t. the Sun
        Rdot = [-x for x in _mv(sun_vel)]
        c, gms = mpmath.mpf(C), mpmath.mpf(GM_SUN)
        Rn = mpmath.sqrt(_dot(R, R))
        inner = [-gms * x / (c**2 * Rn**3) for x in R]
        omega = [(1 + 2 * gamma) * x for x in _cross(Rdot, inner)]
        return [float(x) for x in _cross(omega, v)]


def _states(n, seed, r_scale=1.0e8):
    rng = np.random.default_rng(seed)
    r = rng.normal(size=(n, 3))
    r *= r_scale * rng.uniform(0.7, 1.3, (n, 1)) / np.linalg.norm(r, axis=1, keepdims=True)
    v = rng.normal(size=(n, 3)) * math.sqrt(GM / r_scale) / math.sqrt(3)
    return r, v


def _sun(jd2=0.0):
    p, v = default_ephemeris().geocentric("sun", EPOCH.tdb[0], EPOCH.tdb[1] + jd2)
    return p, v


# --- each term against mpmath ----------------------------------------------

@pytest.mark.parametrize("r_scale", [1.0e8, 7.0e6])  # TianQin and LEO
def test_schwarzschild_vs_mpmath(r_scale):
    """|a| ~ 5e-12 m/s^2 (TianQin) / ~1e-8 (LEO); agreement <= 1e-14 |a|
    (float64 round-off of a few operations: ~5e-26 m/s^2 at TianQin)."""
    r, v = _states(20, 1, r_scale)
    for ri, vi in zip(r, v):
        ref = np.array(_mp_schwarzschild(ri, vi))
        got = np.array(schwarzschild_accel(*ri, *vi, GM, C, 1.0, 1.0))
        assert np.linalg.norm(got - ref) <= 1e-14 * np.linalg.norm(ref)
    # PPN parameters enter where eq. (10.12) puts them
    ref = np.array(_mp_schwarzschild(r[0], v[0], beta=0.5, gamma=0.75))
    got = np.array(schwarzschild_accel(*r[0], *v[0], GM, C, 0.5, 0.75))
    assert np.linalg.norm(got - ref) <= 1e-14 * np.linalg.norm(ref)


def test_schwarzschild_circular_closed_form():
    """r.v = 0, v^2 = GM/r: a = 3 GM^2/(c^2 r^3) r_hat (outward), 5.30e-12 m/s^2 at 1e8 m."""
    r = np.array([1.0e8, 0.0, 0.0])
    v = np.array([0.0, math.sqrt(GM / 1.0e8), 0.0])
    a = np.array(schwarzschild_accel(*r, *v, GM, C, 1.0, 1.0))
    expected = 3.0 * GM**2 / (C**2 * 1.0e24)
    assert expected == pytest.approx(5.3034e-12, rel=1e-4)
    assert a[0] == pytest.approx(expected, rel=1e-14) and a[1] == 0.0 and a[2] == 0.0


@pytest.mark.parametrize("r_scale", [1.0e8, 7.0e6])
def test_lense_thirring_vs_mpmath(r_scale):
    """J = 9.8e8 m^2/s along a (slightly tilted) pole; |a| ~ 2e-14 m/s^2 at
    TianQin; agreement <= 1e-14 |a| (~1e-28 m/s^2)."""
    r, v = _states(20, 2, r_scale)
    jdir = np.array([4.1e-4, 3.1e-5, 1.0])
    jdir /= np.linalg.norm(jdir)
    jvec = J * jdir
    for ri, vi in zip(r, v):
        ref = np.array(_mp_lense_thirring(ri, vi, jvec))
        got = np.array(lense_thirring_accel(*ri, *vi, *jvec, GM, C, 1.0))
        assert np.linalg.norm(got - ref) <= 1e-14 * np.linalg.norm(ref)


def test_de_sitter_vs_mpmath():
    """Sun's geocentric state from DE421 at several dates; |a| up to
    1.2e-11 m/s^2 at TianQin speeds; agreement <= 1e-14 |a|."""
    _, v = _states(20, 3)
    for k, vi in enumerate(v):
        sp, sv = _sun(jd2=18.0 * k)
        ref = np.array(_mp_de_sitter(vi, sp, sv))
        got = np.array(de_sitter_accel(*vi, *sp, *sv, GM_SUN, C, 1.0))
        assert np.linalg.norm(got - ref) <= 1e-14 * np.linalg.norm(ref)


def test_de_sitter_is_twice_the_geodetic_precession():
    """a = Omega x v, Omega = 3 GM_S/(c^2 R^3) R x Rdot (gamma = 1): twice the
    geodetic precession of the GCRS, whose yearly mean is 1.92"/century."""
    jd2 = np.linspace(0.0, 365.25, 367)
    sp, sv = default_ephemeris().geocentric("sun", EPOCH.tdb[0], EPOCH.tdb[1] + jd2)
    omega = []
    for p, u in zip(sp, sv):
        # Omega from the kernel itself: a(v = e_x), a(v = e_y) give the columns of [Omega x]
        ax = np.array(de_sitter_accel(1.0, 0.0, 0.0, *p, *u, GM_SUN, C, 1.0))  # = (0, Oz, -Oy)
        ay = np.array(de_sitter_accel(0.0, 1.0, 0.0, *p, *u, GM_SUN, C, 1.0))  # = (-Oz, 0, Ox)
        omega.append([ay[2], -ax[2], ax[1]])
    rate = np.linalg.norm(omega, axis=1).mean() / 2.0  # rad/s
    arcsec_per_century = rate * 86400 * 36525 * 180 / math.pi * 3600
    assert arcsec_per_century == pytest.approx(1.92, abs=0.01)


def test_kernel_sums_enabled_terms():
    r, v = _states(5, 4)
    term = Relativity()
    t = np.array([0.0, 3600.0, 86400.0, 5 * 86400.0, 9 * 86400.0])
    tdat = term.precompute(EPOCH, t, 0.0)
    p = term.params()
    assert p.shape == (9,) and list(p[[0, 1, 2, 3, 5]]) == [GM, C, 1.0, 1.0, J]
    assert p[4] == planetary_gm()["sun"] == GM_SUN
    for i in range(5):
        s = np.array(schwarzschild_accel(*r[i], *v[i], GM, C, 1.0, 1.0))
        lt = np.array(lense_thirring_accel(*r[i], *v[i], *(J * tdat[i, 6:9]), GM, C, 1.0))
        ds = np.array(de_sitter_accel(*v[i], *tdat[i, 0:6], GM_SUN, C, 1.0))
        np.testing.assert_allclose(relativity_accel(*r[i], *v[i], tdat[i], p), s + lt + ds, rtol=1e-15, atol=1e-30)
        for flags, expected in (((1, 0, 0), s), ((0, 1, 0), lt), ((0, 0, 1), ds), ((0, 0, 0), 0 * s)):
            q = p.copy()
            q[6:9] = flags
            np.testing.assert_array_equal(relativity_accel(*r[i], *v[i], tdat[i], q), expected + 0.0)


# --- time-only inputs ----------------------------------------------------------

def test_precompute_columns():
    t_hi = np.linspace(0.0, 10 * 86400.0, 41).reshape(41, 1) + np.zeros((1, 2))
    t_lo = np.array([0.0, 1e-7])
    term = Relativity()
    tdat = term.precompute(EPOCH, t_hi, t_lo)
    assert tdat.shape == (41, 2, N_TDAT) and term.n_tdat == N_TDAT
    jd1, jd2 = tdb_jd(EPOCH, t_hi, t_lo)
    sp, sv = default_ephemeris().geocentric("sun", jd1, jd2)
    np.testing.assert_array_equal(tdat[..., 0:3], sp)
    np.testing.assert_array_equal(tdat[..., 3:6], sv)
    # CIP from ERFA's composite NPB matrix (third row), TT ~ TDB
    npb = erfa.pnm06a(np.full(41, EPOCH.tt[0]), EPOCH.tt[1] + t_hi[:, 0] / 86400.0)
    err = np.linalg.norm(tdat[:, 0, 6:9] - npb[:, 2, :], axis=1)
    assert err.max() < 1e-8  # rad; linear interpolation on 0.5-day nodes
    assert np.linalg.norm(tdat[..., 6:9], axis=-1) == pytest.approx(1.0, abs=1e-15)
    # switched-off terms: zeros, and no ephemeris needed
    off = Relativity(de_sitter=False, lense_thirring=False).precompute(EPOCH, t_hi, t_lo)
    assert not off.any()
    # a scalar time (the propagator's final evaluation) gives one row
    one = term.precompute(EPOCH, t_hi[3, 0], 0.0)
    np.testing.assert_array_equal(one[:6], tdat[3, 0, :6])
    assert np.linalg.norm(one[6:] - tdat[3, 0, 6:]) < 1e-8  # CIP: exact vs interpolated (rad)
    z = Relativity(j_axis="gcrs_z").precompute(EPOCH, t_hi[:, 0], 0.0)
    np.testing.assert_array_equal(z[:, 6:9], np.tile([0.0, 0.0, 1.0], (41, 1)))


def test_cip_direction_single_instant_and_validation():
    u = cip_direction(EPOCH, 0.0)
    x, y = erfa.xy06(EPOCH.tt[0], EPOCH.tt[1])
    assert u.shape == (3,)
    assert abs(u[0] - x) < 1e-15 and abs(u[1] - y) < 1e-15
    # precession since J2000: ~4.1e-4 rad between CIP and GCRS z in 2004
    assert math.acos(u[2]) == pytest.approx(4.1e-4, rel=0.05)
    with pytest.raises(ValueError, match="j_axis"):
        Relativity(j_axis="itrs")
    with pytest.raises(ValueError, match="j_earth"):
        Relativity(j_earth=-1.0)
    assert "DE421" in Relativity().source


# --- along the TianQin orbit ---------------------------------------------------

def _tianqin(t):
    """Circular TianQin orbit (Sat1 of the paper's Table I), GCRS: r [m], v [m/s]."""
    a = 1.0e8
    n = math.sqrt(GM / a**3)
    inc, raan = math.radians(74.5), math.radians(211.6)
    p = np.array([math.cos(raan), math.sin(raan), 0.0])
    q = np.array([-math.sin(raan) * math.cos(inc), math.cos(raan) * math.cos(inc), math.sin(inc)])
    u = math.radians(30.0) + n * t
    r = a * (np.cos(u)[:, None] * p + np.sin(u)[:, None] * q)
    v = a * n * (-np.sin(u)[:, None] * p + np.cos(u)[:, None] * q)
    return r, v


def test_magnitudes_along_tianqin_orbit():
    """Orders of magnitude (module docstring): maxima within a factor 10 of
    5.3e-12 (Schwarzschild), 1.7e-14 (Lense-Thirring), 1.2e-11 (de Sitter)
    m/s^2 over 10 days.  The J-axis choice (CIP vs GCRS z, 4.1e-4 rad apart)
    changes the total by <= 4.1e-4 x 6e-14 ~ 2.5e-17 m/s^2."""
    t = np.arange(0.0, 10 * 86400.0 + 1.0, 900.0)
    r, v = _tianqin(t)
    term = Relativity()
    tdat = term.precompute(EPOCH, t, 0.0)
    tdat_z = Relativity(j_axis="gcrs_z").precompute(EPOCH, t, 0.0)
    p = term.params()
    mags = {}
    for k, name in ((6, "schwarzschild"), (7, "lense_thirring"), (8, "de_sitter")):
        q = p.copy()
        q[6:9] = 0.0
        q[k] = 1.0
        acc = np.array([relativity_accel(*r[i], *v[i], tdat[i], q) for i in range(t.size)])
        mags[name] = float(np.linalg.norm(acc, axis=1).max())
    for name, estimate in (("schwarzschild", 5.3e-12), ("lense_thirring", 1.7e-14), ("de_sitter", 1.2e-11)):
        assert estimate / 10 < mags[name] < estimate * 10, (name, mags[name])
    d = np.array([np.subtract(relativity_accel(*r[i], *v[i], tdat[i], p), relativity_accel(*r[i], *v[i], tdat_z[i], p))
                  for i in range(t.size)])
    assert 1e-18 < np.linalg.norm(d, axis=1).max() < 1e-16
