"""Tests of tqdyn.forces.ocean_tides (FES2004, IERS 2010 = TN36 eq. 6.15).

References:
* Parse check: M2, l = m = 2 of the shipped file (SOURCES.md and the task's
  values): DelC+ = -39.36214, DelS+ = 46.75729, DelC- = 9.57270,
  DelS- = 5.24459 (x 1e-11).
* TN36 eq. 6.15 in its complex form, sum_f sum_+- (C+- -/+ i S+-) exp(+- i
  theta_f), evaluated with Python complex numbers in the test (the module
  uses the expanded real form and compiled phase products).
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from tide_support import max_accel, standin_orientation

from tqdyn.forces.ocean_tides import OceanTides, ocean_tide_coefficients
from tqdyn.readers.fes2004 import FES2004_MAX_DEGREE, parse_fes2004, read_fes2004
from tqdyn.astro.tidal_arguments import delaunay_arguments, doodson_arguments, tidal_phase
from tqdyn.astro.timescales import Epoch

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")


def test_parse_check_m2():
    model = read_fes2004(nmax=10)
    i = model.names.index("M2")
    assert list(model.doodson[i]) == [2, 0, 0, 0, 0, 0]
    assert model.c_plus[i, 2, 2] == pytest.approx(-39.36214e-11, rel=1e-14)
    assert model.s_plus[i, 2, 2] == pytest.approx(46.75729e-11, rel=1e-14)
    assert model.c_minus[i, 2, 2] == pytest.approx(9.57270e-11, rel=1e-14)
    assert model.s_minus[i, 2, 2] == pytest.approx(5.24459e-11, rel=1e-14)


def test_wave_list_and_truncation():
    model = read_fes2004(nmax=10)
    assert sorted(model.names) == sorted(
        ["2N2", "K1", "K2", "M2", "M4", "Mf", "Mm", "Msq", "Mtm", "N2", "O1", "Om1", "Om2", "P1", "Q1", "S2", "Sa", "Ssa"])
    assert model.c_plus.shape == (18, 11, 11)
    # nothing above the diagonal, nothing below degree 2
    for arr in (model.c_plus, model.s_plus, model.c_minus, model.s_minus):
        assert np.all(np.triu(arr, 1) == 0)
        assert np.all(arr[:, :2] == 0)
    # equilibrium long-period waves only in C20 (TN36 sec. 6.3.2)
    om1 = model.names.index("Om1")
    assert model.c_plus[om1, 2, 0] == pytest.approx(-6.58128e-11)
    assert np.count_nonzero(model.c_plus[om1]) == 1
    # K1, S2 multipliers
    assert list(model.doodson[model.names.index("K1")]) == [1, 1, 0, 0, 0, 0]
    assert list(model.doodson[model.names.index("S2")]) == [2, 2, -2, 0, 0, 0]


def test_bad_input():
    with pytest.raises(ValueError, match="nmax = 101 is outside 0..100"):
        read_fes2004(nmax=FES2004_MAX_DEGREE + 1)
    with pytest.raises(FileNotFoundError, match="not found"):
        read_fes2004("/nonexistent/fes.dat")
    header = ["h1", "h2", "h3", "h4"]
    with pytest.raises(ValueError, match="expected 8 columns"):
        parse_fes2004(header + [" 255.555 M2    2   2 -39.36214  46.75729     9.57270"])
    with pytest.raises(ValueError, match="duplicate"):
        parse_fes2004(header + [" 255.555 M2    2   2 1 2 3 4"] * 2)


def _eq615_complex(model, theta, n, m):
    """TN36 eq. 6.15 for one (n, m) at one instant: (dC, dS)."""
    z = 0j
    for f in range(len(model.names)):
        th = theta[f]
        z += complex(model.c_plus[f, n, m], -model.s_plus[f, n, m]) * cmath.exp(1j * th)
        z += complex(model.c_minus[f, n, m], model.s_minus[f, n, m]) * cmath.exp(-1j * th)
    return z.real, -z.imag


def test_matches_eq_6_15_complex_form():
    model = read_fes2004(nmax=6)
    rng = np.random.default_rng(5)
    beta = doodson_arguments(rng.uniform(0, 2 * math.pi, 4), rng.uniform(-6, 6, (4, 5)))
    dc, ds = ocean_tide_coefficients(beta, model)
    assert dc.shape == ds.shape == (4, 7, 7)
    theta = tidal_phase(beta, model.doodson)
    for i in range(4):
        for n in range(2, 7):
            for m in range(n + 1):
                rc, rs = _eq615_complex(model, theta[i], n, m)
                assert dc[i, n, m] == pytest.approx(rc, abs=1e-22)
                if m > 0:  # S_n0 multiplies sin(0) = 0: the module sets it to 0
                    assert ds[i, n, m] == pytest.approx(rs, abs=1e-22)
    assert np.all(ds[..., 0] == 0)


def test_provider_with_standin():
    t = np.array([[0.0, 600.0, 1200.0], [86400.0, 86400.0 * 45, 86400.0 * 90]])
    prov = OceanTides(nmax=10, orientation=standin_orientation)
    dc, ds = prov(EPOCH, t, 0.0)
    assert dc.shape == ds.shape == (2, 3, 11, 11) and prov.nmax == 10
    eo = standin_orientation(EPOCH, t, 0.0)
    rc, rs = ocean_tide_coefficients(doodson_arguments(eo.gmst, delaunay_arguments(*eo.tt)), read_fes2004(nmax=10))
    np.testing.assert_allclose(dc, rc, rtol=0, atol=1e-25)
    np.testing.assert_allclose(ds, rs, rtol=0, atol=1e-25)


def test_provider_with_real_earth_orientation():

    t = np.linspace(0.0, 86400.0, 5)
    a = OceanTides()(EPOCH, t)
    b = OceanTides(orientation=standin_orientation)(EPOCH, t)
    # same GMST up to the EOP difference (constant UT1-UTC in the stand-in): ~1e-8 rad
    np.testing.assert_allclose(a[0], b[0], rtol=0, atol=1e-6 * np.max(np.abs(b[0])))


def test_magnitude_at_tianqin_distance():
    t = np.arange(24) * 3600.0
    dc, ds = OceanTides(nmax=10, orientation=standin_orientation)(EPOCH, t)
    total = max_accel(dc, ds)
    deg2 = max_accel(np.where(np.arange(11)[:, None] == 2, dc, 0), np.where(np.arange(11)[:, None] == 2, ds, 0))
    deg3 = max_accel(np.where(np.arange(11)[:, None] == 3, dc, 0), np.where(np.arange(11)[:, None] == 3, ds, 0))
    high = max_accel(np.where(np.arange(11)[:, None] >= 5, dc, 0), np.where(np.arange(11)[:, None] >= 5, ds, 0))
    print(f"\nocean tides at r = 1e8 m: total {total:.2e}, degree 2 {deg2:.2e}, degree 3 {deg3:.2e}, "
          f"degrees 5-10 {high:.2e} m/s^2")
    assert 1e-14 < total < 1e-11
    assert high < 1e-15
