"""Tests for tqdyn.astro.earth_orientation (GCRS -> ITRS, IAU 2006/2000A CIO based, IERS EOP).

Independent references used here:
* pyerfa's composite routines evaluated directly at every instant:
  ``erfa.c2tcio(erfa.c2ixys(X + dX, Y + dY, s), erfa.era00(UT1),
  erfa.pom00(xp, yp, erfa.sp00(TT)))`` with X, Y, s from ``erfa.xys06a`` (no
  grid, no interpolation), ``erfa.c2t06a`` (its own precession-nutation path
  via ``pnm06a``) for zero pole offsets, ``erfa.era00`` and ``erfa.gmst06``.
  The time chain of the reference is ERFA's own: TDB -> TT with ``erfa.dtdb``
  and ``erfa.tdbtt``, TT -> TAI -> UTC with ``erfa.tttai``/``erfa.taiutc``,
  UT1 with ``erfa.utcut1`` and UT1-UTC, xp, yp, dX, dY from ``EOP.at`` (whose
  interpolation is tested against an exact-rational reference in test_eop.py).
* The SOFA cookbook example ("SOFA Tools for Earth Attitude", IAU 2006/2000A,
  CIO based, using the X, Y series): UTC 2007-04-05 12:00:00,
  UT1-UTC = -0.072073685 s, xp = 0.0349282", yp = 0.4833163",
  dX = 0.1750 mas, dY = -0.2259 mas, published GCRS -> ITRS matrix
  (quoted to 16 digits, e.g. in tudat's unit test of its SOFA interface):
  [[+0.973104317697536, +0.2303638262391256, -0.0007031634821983242],
   [-0.2303638004560344, +0.9731045706328012, +0.000118545366624876],
   [+0.000711560162667892, +4.662640399540082e-05, +0.9999997457540244]].
"""

from __future__ import annotations

import warnings

import erfa
import mpmath
import numpy as np
import pytest

from tqdyn.astro.eop import ARCSEC, EOP, tidal_arguments, tidal_eop_corrections
from tqdyn.astro.eop import load_eop
from tqdyn.readers.iers_tables import load_tidal_eop_terms
from tqdyn.astro.earth_orientation import earth_orientation, gcrs_to_itrs, itrs_to_gcrs
from tqdyn.astro.timescales import Epoch, tdb_jd

DAY = 86400.0


@pytest.fixture(scope="module")
def ep() -> Epoch:
    return Epoch.from_utc("2004-06-06T00:00:00")


@pytest.fixture(scope="module")
def eop() -> EOP:
    return load_eop()


def _erfa_chain(ep, t, eop):
    """TT, UT1 (two-part) and EOP values at t [s TDB since ep], all by ERFA's own routines."""
    d1, d2 = tdb_jd(ep, t, 0.0)
    dtr = erfa.dtdb(d1, d2, 0.0, 0.0, 0.0, 0.0)
    tt = erfa.tdbtt(d1, d2, dtr)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        utc = erfa.taiutc(*erfa.tttai(*tt))
        v = eop.at((utc[0] - 2400000.5) + utc[1])
        ut1 = erfa.utcut1(utc[0], utc[1], v.dut1)
    return tt, ut1, v


def _angle_diff(a, b):
    return np.abs(np.remainder(a - b + np.pi, 2 * np.pi) - np.pi)


def test_vs_erfa_composition(ep, eop):
    rng = np.random.default_rng(11)
    t = rng.uniform(-157 * DAY, 938 * DAY, 2000)  # 2004-01-01 .. 2006-12-31
    res = earth_orientation(ep, t, 0.0, eop, tidal_eop=False)
    tt, ut1, v = _erfa_chain(ep, t, eop)
    X, Y, s = erfa.xys06a(*tt)
    ref = erfa.c2tcio(erfa.c2ixys(X + v.dx, Y + v.dy, s), erfa.era00(*ut1), erfa.pom00(v.xp, v.yp, erfa.sp00(*tt)))
    err = np.abs(res.T_ITRS_GCRS - ref).max()
    print(f"\nT_ITRS_GCRS vs erfa.c2tcio composition, 2000 instants 2004-2006: max |dT| = {err:.1e} rad")
    assert err < 1e-11
    # time scales: same jd1, so the jd2 difference is exact; tolerance = rounding of jd2
    ulp = np.spacing(np.abs(res.tt[1])).max() * DAY
    assert np.array_equal(res.tt[0], tt[0])
    assert np.abs(res.tt[1] - tt[1]).max() * DAY <= 2 * ulp
    dut = ((res.ut1[0] - ut1[0]) + (res.ut1[1] - ut1[1])) * DAY
    assert np.abs(dut).max() <= 2e-8  # s: the reference's own jd2 rounding (ulp 9.8e-9 s at ~900 d)
    assert np.abs(res.dut1 - v.dut1).max() < 1e-12
    # same interpolant; abscissae differ by the float64 MJD rounding (~1e-6 s)
    assert np.abs(res.xp - v.xp).max() < 1e-18 and np.abs(res.yp - v.yp).max() < 1e-18
    # angles from the compiled kernel vs ERFA at the module's own UT1/TT
    # ERA: ERFA's float64 sum rounds to ~1e-14 rad here (the module sums the turns in dd);
    # against TN36 eq. 5.15 in mpmath (the IAU decimals, the exact two-part UT1 date): the final rounding
    assert _angle_diff(res.era, erfa.era00(*res.ut1)).max() < 5e-14
    with mpmath.workdps(40):
        for i in range(0, t.size, 97):
            tu = (mpmath.mpf(float(res.ut1[0][i])) - 2451545) + mpmath.mpf(float(res.ut1[1][i]))
            turns = mpmath.mpf("0.7790572732640") + mpmath.mpf("1.00273781191135448") * tu
            exact = 2 * mpmath.pi * (turns - mpmath.floor(turns))
            d = mpmath.mpf(float(res.era[i])) - exact
            assert abs(float(d - 2 * mpmath.pi * mpmath.nint(d / (2 * mpmath.pi)))) < 2e-15  # measured <= 4.4e-16
    # GMST = ERA + polynomial: ERFA's ERA rounding again
    assert _angle_diff(res.gmst, erfa.gmst06(res.ut1[0], res.ut1[1], res.tt[0], res.tt[1])).max() < 5e-14


def test_vs_c2t06a_without_pole_offsets(ep, eop):
    # same EOP but dX = dY = 0: then erfa.c2t06a is the complete reference
    e0 = EOP(eop.mjd, eop.xp, eop.yp, eop.dut1, eop.lod, np.zeros_like(eop.dx), np.zeros_like(eop.dy))
    rng = np.random.default_rng(12)
    t = rng.uniform(-157 * DAY, 938 * DAY, 500)
    res = earth_orientation(ep, t, 0.0, e0, tidal_eop=False)
    tt, ut1, v = _erfa_chain(ep, t, e0)
    ref = erfa.c2t06a(tt[0], tt[1], ut1[0], ut1[1], v.xp, v.yp)
    err = np.abs(res.T_ITRS_GCRS - ref).max()
    print(f"\nT_ITRS_GCRS vs erfa.c2t06a (dX = dY = 0): max |dT| = {err:.1e} rad")
    assert err < 1e-11


def test_sofa_cookbook_example():
    # constant EOP of the cookbook example on a few daily nodes around 2007-04-05
    mjd = np.arange(54190.0, 54201.0)
    one = np.ones_like(mjd)
    e = EOP(mjd, 0.0349282 * ARCSEC * one, 0.4833163 * ARCSEC * one, -0.072073685 * one, 0.0 * one,
            0.1750e-3 * ARCSEC * one, -0.2259e-3 * ARCSEC * one)
    ep07 = Epoch.from_utc("2007-04-05T12:00:00")
    T = earth_orientation(ep07, 0.0, 0.0, e, tidal_eop=False).T_ITRS_GCRS
    ref = np.array([[+0.973104317697536, +0.2303638262391256, -0.0007031634821983242],
                    [-0.2303638004560344, +0.9731045706328012, +0.000118545366624876],
                    [+0.000711560162667892, +4.662640399540082e-05, +0.9999997457540244]])
    err = np.abs(T - ref).max()
    print(f"\nSOFA cookbook GCRS->ITRS example: max |dT| = {err:.1e}")
    assert T.shape == (3, 3)
    assert err < 1e-12


def test_orthonormal_and_shapes(ep):
    t = np.linspace(0.0, 90 * DAY, 4001).reshape(1, 4001)
    T = gcrs_to_itrs(ep, t, 0.0)
    assert T.shape == (1, 4001, 3, 3)
    eye = np.einsum("...ij,...kj->...ik", T, T)
    assert np.abs(eye - np.eye(3)).max() < 1e-15
    assert np.abs(np.linalg.det(T) - 1.0).max() < 1e-15
    assert np.array_equal(itrs_to_gcrs(ep, t, 0.0), np.swapaxes(T, -1, -2))
    # scalar and broadcast (t_hi array, t_lo scalar) requests
    r = earth_orientation(ep, 123.0, 0.25)
    assert r.T_ITRS_GCRS.shape == (3, 3) and r.era.shape == () and r.tt[1].shape == ()
    r2 = earth_orientation(ep, np.array([123.0, 456.0]), 0.25)
    assert np.allclose(r2.T_ITRS_GCRS[0], r.T_ITRS_GCRS, rtol=0, atol=1e-15)


def test_double_double_time_is_used(ep):
    # t_lo shifts the instant: 1e-3 s is 7.3e-8 rad of Earth rotation
    a = earth_orientation(ep, 1000.0, 0.0, tidal_eop=False)
    b = earth_orientation(ep, 1000.0, 1e-3, tidal_eop=False)
    omega = 7.292115e-5
    assert abs(_angle_diff(b.era, a.era) - omega * 1e-3) < 1e-12


def test_earth_rotation_rate(ep, eop):
    # finite-difference angular velocity of the ITRS about its z axis: the ERA
    # rate 2 pi * 1.00273781191135448 / 86400 rad/s of UT1, times dUT1/dTT = 1 - LOD/86400
    t = np.array([10 * DAY, 10 * DAY + 10.0])
    r = earth_orientation(ep, t, 0.0, tidal_eop=False)
    W = r.T_ITRS_GCRS[1] @ r.T_ITRS_GCRS[0].T  # rotation over 10 s, ITRS axes
    sk = np.array([W[1, 2] - W[2, 1], W[2, 0] - W[0, 2], W[0, 1] - W[1, 0]]) / 2  # axis * sin(angle)
    angle = np.arctan2(np.linalg.norm(sk), (np.trace(W) - 1) / 2)
    w = sk / np.linalg.norm(sk) * angle / 10.0
    lod = eop.at(53172.0).lod
    expect = 2 * np.pi * 1.00273781191135448 / DAY * (1 - lod / DAY)
    # CIO-based: no rotation of the CIRS about the CIP, so w_z is the ERA rate;
    # 1e-9 relative covers TDB-TT and C04 LOD vs interpolated-UT1 rate differences
    assert abs(w[2] - expect) < 1e-9 * expect
    # the rotation axis is the CIP, which sits at (x_p, -y_p) in the ITRS (TN36
    # sec. 5.4.1): w_xy = w_E (x_p, -y_p) ~ 1.7e-10 rad/s, up to the CIP's own
    # motion in the GCRS (precession-nutation, < 1e-11 rad/s)
    assert abs(w[0] - expect * r.xp[0]) < 1e-11
    assert abs(w[1] + expect * r.yp[0]) < 1e-11


def test_tidal_eop_terms(ep, eop):
    t = np.linspace(0.0, 2 * DAY, 577)
    a = earth_orientation(ep, t, 0.0, tidal_eop=False)
    b = earth_orientation(ep, t, 0.0)  # default: with the sub-daily terms
    dxp, dyp = b.xp - a.xp, b.yp - a.yp
    dut = b.dut1 - a.dut1
    # direct evaluation at every instant (no grid) with the module's UT1/TT
    args = tidal_arguments(b.ut1, b.tt)
    rx, ry, ru = tidal_eop_corrections(args, load_tidal_eop_terms())
    # grid (1 h, 8-point) interpolation of the 12 h / 24 h terms: < 1e-13 rad, < 2e-10 s
    assert np.abs(dxp - rx).max() < 1e-13 and np.abs(dyp - ry).max() < 1e-13
    assert np.abs(dut - ru).max() < 2e-10  # s, i.e. < 1.5e-14 rad of ERA
    dT = np.abs(b.T_ITRS_GCRS - a.T_ITRS_GCRS).max()
    dpm = max(np.abs(dxp).max(), np.abs(dyp).max())
    print(f"\nsub-daily EOP terms (2004-06-06..08): |dxp|,|dyp| <= {dpm:.1e} rad, "
          f"|dUT1| <= {np.abs(dut).max() * 1e6:.1f} us, |dT| <= {dT:.1e} rad")
    assert 1e-10 < dT < 1e-8


def test_without_eop(ep):
    t = np.linspace(0.0, 3 * DAY, 50)
    r = earth_orientation(ep, t, 0.0, use_eop=False)
    d1, d2 = tdb_jd(ep, t, 0.0)
    tt = erfa.tdbtt(d1, d2, erfa.dtdb(d1, d2, 0.0, 0.0, 0.0, 0.0))
    utc = erfa.taiutc(*erfa.tttai(*tt))
    ref = erfa.c2t06a(tt[0], tt[1], utc[0], utc[1], 0.0, 0.0)  # UT1 = UTC, no polar motion
    assert np.abs(r.T_ITRS_GCRS - ref).max() < 1e-11
    assert np.all(r.xp == 0.0) and np.all(r.dut1 == 0.0)
    # usable outside the EOP table
    late = Epoch.from_utc("2030-01-01T00:00:00")
    assert earth_orientation(late, t, 0.0, use_eop=False).T_ITRS_GCRS.shape == (50, 3, 3)


def test_out_of_eop_span(eop):
    late = Epoch.from_utc("2024-09-01T00:00:00")
    with pytest.raises(ValueError, match=r"outside the EOP table span MJD 37665\.\.60556.*2024-09-03"):
        earth_orientation(late, np.array([0.0, 5 * DAY]), 0.0, eop)  # the shipped 14 C04 series
    # the default table ("auto": measured, predicted, long-term model) ends 2099-12-31
    assert earth_orientation(late, np.array([0.0, 5 * DAY]), 0.0).T_ITRS_GCRS.shape == (2, 3, 3)
    with pytest.raises(ValueError, match=r"2100-01-0.*outside the EOP table span.*2099-12-31"):
        earth_orientation(Epoch.from_utc("2099-12-31T00:00:00"), np.array([0.0, 2 * DAY]), 0.0)
    early = Epoch.from_utc("1961-06-01T00:00:00")
    with pytest.raises(ValueError, match="1962-01-01"):
        earth_orientation(early, 0.0, 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        earth_orientation(Epoch.from_utc("2004-06-06T00:00:00"), np.array([0.0, np.nan]), 0.0)


def test_memo_and_read_only(ep):
    t = np.linspace(0.0, 1000.0, 101)
    a = earth_orientation(ep, t, 0.0)
    b = earth_orientation(ep, t.copy(), 0.0)
    assert a is b  # same values -> memoised result
    c = earth_orientation(ep, t + 1e-9, 0.0)
    assert c is not a
    d = earth_orientation(ep, t, 0.0, tidal_eop=False)
    assert d is not a
    with pytest.raises(ValueError):
        a.T_ITRS_GCRS[0, 0, 0] = 1.0
