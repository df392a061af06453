"""Tests of tqdyn.forces.tidal_arguments (Delaunay, Doodson arguments, phases).

References:
* Delaunay arguments: IERS Conventions 2010 (TN36) eq. 5.43 (Simon et al.
  1994), typed in below and evaluated in mpmath at 40 digits -- independent
  of pyerfa's fal03 .. faom03 used by the module.
* Mean longitudes of the Moon, Sun, lunar perigee, node and solar perigee:
  J. Meeus, Astronomical Algorithms (2nd ed. 1998), eqs. 47.1-47.7 and 25.2-25.4
  (ELP-2000/82 and Newcomb-type fits, *not* the Simon et al. fits):
  independent series that must agree with the Doodson arguments to ~1e-5 rad.
* Tidal frequencies: TN36 Tables 6.5a-c (deg/hr column).
* Phases by definition: K1 = theta_g + pi; M2 = 2 (theta_g + pi - s);
  S2 = 2 (theta_g + pi - h) = 2 x (UT1 angle of the mean Sun) = 4 pi UT1-fraction.
"""

from __future__ import annotations

import math

import erfa
import mpmath
import numpy as np
import pytest

from tqdyn.astro.tidal_arguments import (
    delaunay_arguments,
    delaunay_multipliers,
    doodson_arguments,
    doodson_multipliers,
    greenwich_mean_sidereal_time,
    julian_centuries,
    tidal_phase,
)

DEG = math.pi / 180.0
TWO_PI = 2.0 * math.pi


def _wrap(x):
    """x mod 2 pi into (-pi, pi]."""
    return (np.asarray(x) + math.pi) % TWO_PI - math.pi


# TT Julian dates: 2004-06-06T00:01:04.184 TT (= 0 h UTC) plus a spread of
# dates 1990..2030
DATES = [(2453162.5, 64.184 / 86400), (2447892.5, 0.3), (2451545.0, 0.0), (2453200.5, 0.71),
         (2458849.5, 0.123), (2462502.5, 0.9)]


@mpmath.workdps(40)
def _delaunay_mp(t):
    """TN36 eq. 5.43 in mpmath; t in Julian centuries TT; returns radians mod 2 pi."""
    t = mpmath.mpf(t)
    arcsec = mpmath.pi / 648000
    series = [
        (mpmath.mpf("134.96340251") * 3600, "1717915923.2178", "31.8792", "0.051635", "-0.00024470"),
        (mpmath.mpf("357.52910918") * 3600, "129596581.0481", "-0.5532", "0.000136", "-0.00001149"),
        (mpmath.mpf("93.27209062") * 3600, "1739527262.8478", "-12.7512", "-0.001037", "0.00000417"),
        (mpmath.mpf("297.85019547") * 3600, "1602961601.2090", "-6.3706", "0.006593", "-0.00003169"),
        (mpmath.mpf("125.04455501") * 3600, "-6962890.5431", "7.4722", "0.007702", "-0.00005939"),
    ]
    out = []
    for c0, c1, c2, c3, c4 in series:
        v = c0 + t * (mpmath.mpf(c1) + t * (mpmath.mpf(c2) + t * (mpmath.mpf(c3) + t * mpmath.mpf(c4))))
        out.append(float(mpmath.fmod(v * arcsec, 2 * mpmath.pi)))
    return np.array(out)


@pytest.mark.parametrize("jd", DATES)
def test_delaunay_arguments_match_iers_series(jd):
    got = delaunay_arguments(*jd)
    ref = _delaunay_mp(float(julian_centuries(*jd)))
    # pyerfa reduces mod 2 pi in float64 from ~1e9 arcsec: ~1e-13 rad
    np.testing.assert_allclose(_wrap(got - ref), 0.0, atol=1e-12)


def test_doodson_arguments_against_meeus_mean_longitudes():
    """s, h, p, N', p_s from the Delaunay combinations vs Meeus' series."""
    worst = 0.0
    for jd in DATES:
        t = float(julian_centuries(*jd))
        beta = doodson_arguments(0.0, delaunay_arguments(*jd))
        s = 218.3164477 + 481267.88123421 * t - 0.0015786 * t * t        # Meeus 47.1
        mm = 134.9633964 + 477198.8675055 * t + 0.0087414 * t * t        # 47.4, Moon's mean anomaly
        om = 125.0445479 - 1934.1362891 * t + 0.0020754 * t * t          # 47.7
        h = 280.46646 + 36000.76983 * t + 0.0003032 * t * t              # 25.2
        ms = 357.52911 + 35999.05029 * t - 0.0001537 * t * t             # 25.3
        ref = np.array([s, h, s - mm, -om, h - ms]) * DEG
        diff = _wrap(beta[1:] - ref)
        worst = max(worst, float(np.max(np.abs(diff))))
    print(f"\nDoodson arguments vs Meeus' series: max difference {worst:.2e} rad")
    assert worst < 3e-5


def test_tau_is_mean_lunar_time():
    jd = DATES[0]
    theta_g = 1.2345
    beta = doodson_arguments(theta_g, delaunay_arguments(*jd))
    assert abs(_wrap(beta[0] - (theta_g + math.pi - beta[1]))) < 1e-15


def _gmst(tt, ut1):
    return greenwich_mean_sidereal_time(ut1, tt)


@pytest.mark.parametrize("jd", DATES)
def test_k1_m2_s2_phases_by_definition(jd):
    tt = (np.array(jd[0]), np.array(jd[1]))
    ut1 = (tt[0], tt[1] - 64.6544721 / 86400)
    theta_g = _gmst(tt, ut1)
    assert abs(theta_g - erfa.gmst06(ut1[0], ut1[1], tt[0], tt[1])) == 0.0
    beta = doodson_arguments(theta_g, delaunay_arguments(*tt))
    k1 = tidal_phase(beta, doodson_multipliers("165.555"))
    m2 = tidal_phase(beta, doodson_multipliers("255.555"))
    s2 = tidal_phase(beta, doodson_multipliers("273.555"))
    # K1: theta_g + pi exactly
    assert abs(_wrap(k1 - (theta_g + math.pi))) < 1e-12
    # M2: twice the Greenwich hour angle of the mean Moon (+ 2 pi), Moon from Meeus 47.1
    t = float(julian_centuries(*tt))
    s_meeus = (218.3164477 + 481267.88123421 * t - 0.0015786 * t * t) * DEG
    assert abs(_wrap(m2 - 2.0 * (theta_g - s_meeus))) < 6e-5
    # S2: twice the UT1 angle of the mean Sun = 4 pi x (UT1 fraction of day)
    frac = ((ut1[0] - 0.5) % 1.0 + ut1[1]) % 1.0
    err = abs(_wrap(s2 - 2.0 * TWO_PI * frac))
    assert err < 5e-4, err  # GMST vs mean-longitude-of-the-Sun definitions: ~2e-4 rad


@pytest.mark.parametrize("number, freq_deg_hr", [
    ("255.555", 28.98410), ("165.555", 15.04107), ("273.555", 30.00000), ("145.555", 13.94303),
    ("163.555", 14.95893), ("245.655", 28.43973), ("75.555", 1.09804), ("55.565", 0.00221),
])
def test_phase_rates_match_tabulated_frequencies(number, freq_deg_hr):
    """d theta_f/dt by finite differences over 1 day vs TN36's deg/hr column."""
    tt0 = (2453162.5, 0.0)
    dt = 1.0  # day
    ph = []
    for d in (0.0, dt):
        tt = (np.array(tt0[0]), np.array(tt0[1] + d))
        ut1 = (tt[0], tt[1] - 64.6544721 / 86400)
        beta = doodson_arguments(_gmst(tt, ut1), delaunay_arguments(*tt))
        ph.append(float(tidal_phase(beta, doodson_multipliers(number))))
    n = doodson_multipliers(number)
    cycles = round((n[0] * 360.9856 * dt - (ph[1] - ph[0]) / DEG) / 360.0)  # whole turns of the tau/s part
    rate = ((ph[1] - ph[0]) / DEG + 360.0 * cycles) / (24.0 * dt)
    assert abs(rate - freq_deg_hr) < 2e-5, (rate, freq_deg_hr)


def test_doodson_number_parsing():
    assert list(doodson_multipliers("255.555")) == [2, 0, 0, 0, 0, 0]
    assert list(doodson_multipliers("55.565")) == [0, 0, 0, 0, 1, 0]
    assert list(doodson_multipliers("056.554")) == [0, 0, 1, 0, 0, -1]
    assert list(doodson_multipliers("165,555")) == [1, 1, 0, 0, 0, 0]
    assert list(doodson_multipliers(135.655)) == [1, -2, 0, 1, 0, 0]
    for bad in ("2555.55", "M2", "255.5555", ""):
        with pytest.raises(ValueError, match="Doodson number"):
            doodson_multipliers(bad)


def test_delaunay_multipliers_of_known_waves():
    """Against the 'l l' F D Omega' columns printed in TN36 Tables 6.5a-c."""
    cases = {"145.555": (1, [0, 0, 2, 0, 2]),        # O1
             "165.555": (1, [0, 0, 0, 0, 0]),        # K1
             "163.555": (1, [0, 0, 2, -2, 2]),       # P1
             "255.555": (2, [0, 0, 2, 0, 2]),        # M2
             "57.555": (0, [0, 0, -2, 2, -2]),       # Ssa
             "56.554": (0, [0, -1, 0, 0, 0])}        # Sa
    for number, (order, big) in cases.items():
        n1, got = delaunay_multipliers(doodson_multipliers(number))
        assert n1 == order and list(got) == big, number


def test_phase_from_doodson_equals_phase_from_delaunay():
    """theta_f = n . beta = n1 (theta_g + pi) - N . F for arbitrary arguments."""
    rng = np.random.default_rng(1)
    fa = rng.uniform(-7, 7, size=(10, 5))
    theta_g = rng.uniform(0, TWO_PI, size=10)
    beta = doodson_arguments(theta_g, fa)
    for number in ("125.755", "165.565", "275.555", "93.555", "455.555", "235.755"):
        n = doodson_multipliers(number)
        n1, big = delaunay_multipliers(n)
        alt = n1 * (theta_g + math.pi) - fa @ big
        np.testing.assert_allclose(_wrap(tidal_phase(beta, n) - alt), 0.0, atol=1e-12)


def test_vectorised_shapes():
    jd1 = np.full((3, 4), 2453162.5)
    jd2 = np.linspace(0, 1, 12).reshape(3, 4)
    fa = delaunay_arguments(jd1, jd2)
    assert fa.shape == (3, 4, 5)
    beta = doodson_arguments(np.zeros((3, 4)), fa)
    assert beta.shape == (3, 4, 6)
    ph = tidal_phase(beta, np.array([doodson_multipliers("255.555"), doodson_multipliers("165.555")]))
    assert ph.shape == (3, 4, 2)
    np.testing.assert_array_equal(tidal_phase(beta, ["255.555", "165.555"]), ph)
    np.testing.assert_array_equal(tidal_phase(beta, "255.555"), ph[..., 0])


def test_compiled_cos_sin_and_sums_match_numpy():
    """tidal_cos_sin / tidal_harmonic_sum (products of powers of exp(i beta_k))
    against numpy's cos/sin of the explicit phases."""
    from tqdyn.astro.tidal_arguments import tidal_cos_sin, tidal_harmonic_sum

    rng = np.random.default_rng(11)
    beta = rng.uniform(-15, 15, size=(2, 50, 6))
    mult = np.array([doodson_multipliers(x) for x in
                     ("255.555", "165.555", "455.555", "195.465", "57.555", "162.556", "127.555", "55.575")])
    c, s = tidal_cos_sin(beta, mult)
    theta = tidal_phase(beta, mult)
    assert c.shape == s.shape == (2, 50, 8)
    np.testing.assert_allclose(c, np.cos(theta), rtol=0, atol=1e-13)
    np.testing.assert_allclose(s, np.sin(theta), rtol=0, atol=1e-13)
    for k in (3, 40):  # fused kernel and the BLAS path
        wc, ws = rng.normal(size=(8, k)), rng.normal(size=(8, k))
        out = tidal_harmonic_sum(beta, mult, wc, ws)
        assert out.shape == (2, 50, k)
        np.testing.assert_allclose(out, np.cos(theta) @ wc + np.sin(theta) @ ws, rtol=0, atol=1e-12)
