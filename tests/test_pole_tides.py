"""Tests of tqdyn.forces.pole_tides (IERS 2010 = TN36 eq. 6.22, 6.24, 7.24, 7.25).

References:
* Mean pole: TN36 Table 7.7 coefficients typed in below (mas, years since
  2000.0), evaluated in mpmath; the cubic and linear branches must join at
  2010.0 (to the rounding of the published coefficients, ~1 uas).
* Polar motion of 2004-06-06: EOP 14 C04, MJD 53162 (x = -0.074487",
  y = 0.475665"; parse check in src/tqdyn/data/SOURCES.md).
* Pole-tide formulas: TN36 eq. 6.22 and 6.24 typed in (arcsec in, Stokes out).
"""

from __future__ import annotations


import mpmath
import numpy as np
import pytest
from tide_support import XP_2004, YP_2004, max_accel, standin_orientation

from tqdyn.forces.pole_tides import (
    ARCSEC,
    OceanPoleTide,
    SolidPoleTide,
    mean_pole_iers2010,
    ocean_pole_tide,
    solid_pole_tide,
    wobble,
)
from tqdyn.astro.timescales import Epoch

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")
MAS = ARCSEC / 1000.0


@mpmath.workdps(30)
def _mean_pole_mp(t):
    """TN36 Table 7.7, t = years since 2000.0; returns (x, y) in mas."""
    t = mpmath.mpf(t)
    if t < 10:
        x = mpmath.mpf("55.974") + mpmath.mpf("1.8243") * t + mpmath.mpf("0.18413") * t**2 \
            + mpmath.mpf("0.007024") * t**3
        y = mpmath.mpf("346.346") + mpmath.mpf("1.7896") * t - mpmath.mpf("0.10729") * t**2 \
            - mpmath.mpf("0.000908") * t**3
    else:
        x = mpmath.mpf("23.513") + mpmath.mpf("7.6141") * t
        y = mpmath.mpf("358.891") - mpmath.mpf("0.6287") * t
    return float(x), float(y)


@pytest.mark.parametrize("years", [0.0, 4.4305, 4.68, 9.99, 10.0, 15.3, 24.9])
def test_mean_pole(years):
    jd = 2451545.0 + years * 365.25
    x, y = mean_pole_iers2010((np.array(jd), np.array(0.0)))
    rx, ry = _mean_pole_mp(years)
    assert x / MAS == pytest.approx(rx, abs=1e-9)   # mas
    assert y / MAS == pytest.approx(ry, abs=1e-9)


def test_mean_pole_branches_join_at_2010():
    eps = 1e-6  # days
    a = mean_pole_iers2010((np.array(2451545.0 + 3652.5 - eps), np.array(0.0)))
    b = mean_pole_iers2010((np.array(2451545.0 + 3652.5), np.array(0.0)))
    assert abs(a[0] - b[0]) < 2e-3 * MAS and abs(a[1] - b[1]) < 2e-3 * MAS


def test_pole_tides_2004():
    tt = (np.array(2453162.5), np.array(64.184 / 86400))
    m1, m2 = wobble(XP_2004, YP_2004, tt)
    xbar, ybar = _mean_pole_mp((2453162.5 + 64.184 / 86400 - 2451545.0) / 365.25)
    rm1 = -0.074487 - xbar / 1000.0                       # arcsec, TN36 eq. 7.24
    rm2 = -(0.475665 - ybar / 1000.0)
    assert m1 / ARCSEC == pytest.approx(rm1, abs=1e-12)
    assert m2 / ARCSEC == pytest.approx(rm2, abs=1e-12)
    c, s = solid_pole_tide(m1, m2)
    assert c == pytest.approx(-1.333e-9 * (rm1 + 0.0115 * rm2), rel=1e-12)
    assert s == pytest.approx(-1.333e-9 * (rm2 - 0.0115 * rm1), rel=1e-12)
    oc, os_ = ocean_pole_tide(m1, m2)
    assert oc == pytest.approx(-2.1778e-10 * (rm1 - 0.01724 * rm2), rel=1e-12)
    assert os_ == pytest.approx(-1.7232e-10 * (rm2 - 0.03365 * rm1), rel=1e-12)
    print(f"\n2004-06-06: m1 = {rm1:.4f}\", m2 = {rm2:.4f}\"; solid dC21 = {c:.3e}, dS21 = {s:.3e}; "
          f"ocean dC21 = {oc:.3e}, dS21 = {os_:.3e}")
    # wobble ~0.1-0.2 arcsec -> solid ~2e-10, ocean ~3e-11
    assert 0.05 < abs(rm1) < 0.3 and 0.05 < abs(rm2) < 0.3
    assert 1e-10 < abs(c) < 4e-10 and 1e-10 < abs(s) < 4e-10
    assert 1e-11 < abs(oc) < 6e-11 and 1e-11 < abs(os_) < 6e-11


def test_providers_with_standin():
    t = np.array([[0.0, 3600.0], [86400.0 * 10, 86400.0 * 90]])
    for cls, fn in ((SolidPoleTide, solid_pole_tide), (OceanPoleTide, ocean_pole_tide)):
        prov = cls(orientation=standin_orientation)
        dc, ds = prov(EPOCH, t, 0.0)
        assert dc.shape == ds.shape == (2, 2, 3, 3) and prov.nmax == 2
        eo = standin_orientation(EPOCH, t, 0.0)
        rc, rs = fn(*wobble(eo.xp, eo.yp, eo.tt))
        np.testing.assert_array_equal(dc[..., 2, 1], rc)
        np.testing.assert_array_equal(ds[..., 2, 1], rs)
        mask = np.ones((3, 3), bool)
        mask[2, 1] = False
        assert np.all(dc[..., mask] == 0) and np.all(ds[..., mask] == 0)
        assert prov.name in ("solid_pole_tide", "ocean_pole_tide")


def test_providers_with_real_earth_orientation():

    t = np.linspace(0.0, 86400.0 * 90, 10)
    dc, ds = SolidPoleTide()(EPOCH, t)
    ref = SolidPoleTide(orientation=standin_orientation)(EPOCH, t[:1])
    # day 0 with C04 polar motion (+ any sub-daily terms, < 1 mas) vs the constant stand-in
    assert dc[0, 2, 1] == pytest.approx(ref[0][0, 2, 1], rel=1e-2)
    print(f"\nsolid pole tide over 90 days (real EOP): dC21 {dc[:, 2, 1].min():.3e} .. {dc[:, 2, 1].max():.3e}, "
          f"dS21 {ds[:, 2, 1].min():.3e} .. {ds[:, 2, 1].max():.3e}")


def test_magnitudes_at_tianqin_distance():
    t = np.zeros(1)
    sc, ss = SolidPoleTide(orientation=standin_orientation)(EPOCH, t)
    oc, os_ = OceanPoleTide(orientation=standin_orientation)(EPOCH, t)
    a_solid, a_ocean = max_accel(sc, ss), max_accel(oc, os_)
    print(f"\npole tides at r = 1e8 m (2004-06-06): solid {a_solid:.2e}, ocean (degree 2) {a_ocean:.2e} m/s^2")
    assert 1e-14 < a_solid < 1e-12
    assert 1e-15 < a_ocean < a_solid
