"""Tests of tqdyn.forces.atmospheric_tides and tqdyn.readers.bb2006 (S1/S2
atmospheric tides, Biancale & Bode 2006).

References (independent of the module):
* Parse check: the numbers of src/tqdyn/data/atm_tides_bb2006_S1S2.txt
  (S2 2 2 0.545 hPa 148.8 deg; S1 1 1 0.220 hPa 73.2 deg; S2 8 5 0.005 74.9).
* The conversion: Newton's integral of the surface load sigma = p / g over
  the sphere of radius a (Gauss-Legendre x uniform quadrature), the pressure
  synthesised here from the file's amplitudes and phases with scipy's
  Legendre functions, times (1 + k'_n) per degree (k'_n typed in from TN36
  sec. 6.3.1 and Gegout), against the potential of the module's dC, dS.
* TN36 eq. 6.15 in complex form with the eq. 6.21 amplitude/phase
  coefficients C+ = F A sin eps, S+ = F A cos eps (Python complex numbers).
* The physical phase check: the barometric S2 maximum at ~10:00 and ~22:00
  local solar time (Haurwitz & Cowley 1973: 09:45 / 21:45), local solar time
  from the Sun's hour angle (DE421 read with jplephem, Earth orientation
  from pyerfa: tests/tide_support.py).
* Magnitude: a first-principles bound derived in the test.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from tide_support import DirectDE421, _pbar, max_accel, potential, standin_orientation

from tqdyn.astro.tidal_arguments import delaunay_arguments, doodson_arguments, tidal_phase
from tqdyn.astro.timescales import Epoch, tdb_jd
from tqdyn.forces.atmospheric_tides import (
    AtmosphericTides,
    atmospheric_tide_coefficients,
    pressure_coefficients,
    stokes_factor,
)
from tqdyn.readers.bb2006 import parse_bb2006, read_bb2006

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")
GM = 3.986004415e14        # m^3/s^2, EGM2008
A_REF = 6378136.3          # m, EGM2008 reference radius
G = 6.67430e-11            # m^3/(kg s^2), CODATA 2018
G0 = 9.80665               # m/s^2, standard gravity
#: load Love numbers: TN36 sec. 6.3.1 (n = 2..6), Gegout (n = 7, 8)
K_LOAD = {2: -0.3075, 3: -0.195, 4: -0.132, 5: -0.1032, 6: -0.0892, 7: -0.0821, 8: -0.0767}


def _beta(t):
    eo = standin_orientation(EPOCH, np.asarray(t, dtype=float))
    return eo, doodson_arguments(eo.gmst, delaunay_arguments(*eo.tt))


# ---------------------------------------------------------------- reader


def test_parse_check():
    model = read_bb2006()
    assert model.waves == ("S2", "S1")
    assert len(model.wave) == 48 and model.wave.count("S1") == model.wave.count("S2") == 24
    assert model.nmax == 8 and model.m.max() == 5
    i = [k for k in range(48) if model.wave[k] == "S2" and model.n[k] == 2 and model.m[k] == 2][0]
    assert model.amplitude[i] == pytest.approx(54.5, rel=1e-14)                # 0.545 hPa
    assert model.phase[i] == pytest.approx(math.radians(148.8), rel=1e-14)
    assert model.doodson_number[i] == "273.555" and list(model.doodson[i]) == [2, 2, -2, 0, 0, 0]
    s1 = model.select(wave="S1", n=1, m=1)
    assert s1.amplitude[0] == pytest.approx(22.0, rel=1e-14) and s1.phase[0] == pytest.approx(math.radians(73.2))
    assert s1.doodson_number[0] == "164.556" and list(s1.doodson[0]) == [1, 1, -1, 0, 0, 1]
    last = model.select(wave="S2", n=8, m=5)
    assert last.amplitude[0] == pytest.approx(0.5) and last.phase[0] == pytest.approx(math.radians(74.9))
    # the first and last rows of the file
    assert (model.wave[0], model.n[0], model.m[0]) == ("S2", 0, 0) and model.amplitude[0] == pytest.approx(0.5)
    assert (model.wave[-1], model.n[-1], model.m[-1]) == ("S1", 8, 5)
    assert model.phase[-1] == pytest.approx(math.radians(266.1))


def test_reader_bad_input():
    with pytest.raises(ValueError, match="expected 5 columns"):
        parse_bb2006(["S2 2 2 0.545"])
    with pytest.raises(ValueError, match="order m = 3 outside 0..2"):
        parse_bb2006(["S2 2 3 0.5 10.0"])
    with pytest.raises(ValueError, match="duplicate"):
        parse_bb2006(["S2 2 2 0.5 10.0", "S2 2 2 0.5 10.0"])
    with pytest.raises(ValueError, match="no Doodson number"):
        parse_bb2006(["M2 2 2 0.5 10.0"])
    with pytest.raises(ValueError, match="no coefficient rows"):
        parse_bb2006(["# header only"])
    with pytest.raises(FileNotFoundError, match="not found"):
        read_bb2006("/nonexistent/atm.txt")
    # a Doodson number declared in the header is used
    m = parse_bb2006(["# X: K2 (Doodson 275.555)", "K2 2 2 0.1 0.0"])
    assert list(m.doodson[0]) == [2, 2, 0, 0, 0, 0]


# ---------------------------------------------------------------- conversion


def test_stokes_factor_value():
    # F_2 = 4 pi G a^2 (1 + k'_2) / (GM g 5), typed in; = 3 (1 + k'_2) / (rho_E a g 5)
    f2 = 4 * math.pi * G * A_REF ** 2 * (1 - 0.3075) / (GM * G0 * 5)
    assert stokes_factor(2) == pytest.approx(f2, rel=1e-14)
    rho_e = 3 * GM / (4 * math.pi * G * A_REF ** 3)
    assert f2 == pytest.approx(3 * (1 - 0.3075) / (rho_e * A_REF * G0 * 5), rel=1e-14)
    assert 1.2e-12 < f2 < 1.22e-12                       # 1.209e-12 per Pa
    with pytest.raises(ValueError, match="outside 2..8"):
        stokes_factor(9)


def test_matches_eq_6_15_complex_form():
    """TN36 eq. 6.15 with the eq. 6.21 coefficients C+ = F A sin eps,
    S+ = F A cos eps (prograde only): dC - i dS = sum (C+ - i S+) e^{i theta}."""
    model = read_bb2006()
    rng = np.random.default_rng(3)
    beta = doodson_arguments(rng.uniform(0, 2 * math.pi, 3), rng.uniform(-6, 6, (3, 5)))
    dc, ds = atmospheric_tide_coefficients(beta, model)
    theta = tidal_phase(beta, model.doodson)                      # (3, 48)
    for i in range(3):
        z = np.zeros((9, 9), dtype=complex)
        for k in range(48):
            n, m = model.n[k], model.m[k]
            if n < 2:
                continue
            f = 4 * math.pi * G * A_REF ** 2 * (1 + K_LOAD[n]) / (GM * G0 * (2 * n + 1))
            cp, sp = f * model.amplitude[k] * math.sin(model.phase[k]), f * model.amplitude[k] * math.cos(model.phase[k])
            z[n, m] += complex(cp, -sp) * cmath.exp(1j * theta[i, k])
        np.testing.assert_allclose(dc[i], z.real, rtol=0, atol=1e-24)
        np.testing.assert_allclose(ds[i][:, 1:], -z.imag[:, 1:], rtol=0, atol=1e-24)
    assert np.all(ds[..., 0] == 0) and np.all(dc[..., :2, :] == 0)


def _newton_potential(points, t_beta, nmax=8, n_lat=64, n_lon=128):
    """Potential [m^2/s^2] at ITRS points (P, 3) of the surface load sigma =
    p / g on the sphere r = a, by quadrature of Newton's integral per degree
    times (1 + k'_n).  p from the file's amplitudes and phases:
    p = sum A Pbar_nm(sin phi) sin(theta_f + m lambda + eps).  Returns
    (degrees 2..nmax, P)."""
    model = read_bb2006()
    mu, w_mu = np.polynomial.legendre.leggauss(n_lat)           # mu = sin(phi)
    lam = 2 * math.pi * np.arange(n_lon) / n_lon
    w = np.outer(w_mu, np.full(n_lon, 2 * math.pi / n_lon))      # dOmega weights
    cosphi = np.sqrt(1 - mu * mu)
    src = A_REF * np.stack([np.outer(cosphi, np.cos(lam)), np.outer(cosphi, np.sin(lam)),
                            np.outer(mu, np.ones(n_lon))], axis=-1)  # (n_lat, n_lon, 3)
    theta = tidal_phase(t_beta, model.doodson)                   # (48,)
    dist = np.linalg.norm(points[:, None, None, :] - src[None], axis=-1)  # (P, n_lat, n_lon)
    out = []
    for n in range(2, nmax + 1):
        p = np.zeros((n_lat, n_lon))
        for k in np.flatnonzero(model.n == n):
            m = model.m[k]
            p += model.amplitude[k] * _pbar(n, m, mu)[:, None] * np.sin(theta[k] + m * lam + model.phase[k])[None]
        sigma = p / G0                                            # kg/m^2
        v = G * A_REF ** 2 * np.sum(w * sigma / dist, axis=(1, 2))
        out.append((1 + K_LOAD[n]) * v)
    return np.array(out)


def test_conversion_against_newton_quadrature(record_number):
    """dC, dS of the S1/S2 load against Newton's integral of sigma = p / g over the sphere (Gauss-Legendre x uniform
    quadrature, independent of the Stokes conversion).  Measured: <= 5.8e-15 relative per degree at r = 1.3 a (the
    quadrature's and float64's rounding), 4.4e-13 for the sum at r = 1e8 m (cancellation of the degrees in float64);
    bounds 5x.  docs/force-model.md quotes the per-degree agreement."""
    t = np.array([5 * 3600.0 + 17.0])
    _, beta = _beta(t)
    dc, ds = AtmosphericTides(orientation=standin_orientation)(EPOCH, t)
    rng = np.random.default_rng(11)
    dirs = rng.normal(size=(6, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    worst = 0.0
    # per degree close to the load (r = 1.3 a), where every degree matters
    pts = 1.3 * A_REF * dirs
    quad = _newton_potential(pts, beta[0])
    for n in range(2, 9):
        mask = (np.arange(9) == n)[:, None]
        ref = potential(pts, np.where(mask, dc, 0.0), np.where(mask, ds, 0.0), GM, A_REF)[0]
        scale = np.max(np.abs(ref))
        err = np.max(np.abs(quad[n - 2] - ref)) / scale
        worst = max(worst, err)
        assert err < 3e-14, (n, err)
    # the total at the TianQin distance
    pts = 1.0e8 * dirs
    quad = _newton_potential(pts, beta[0]).sum(axis=0)
    ref = potential(pts, dc, ds, GM, A_REF)[0]
    err_total = np.max(np.abs(quad - ref)) / np.max(np.abs(ref))
    print(f"\natmospheric tides, dC/dS vs Newton quadrature of sigma = p/g: worst degree (r = 1.3 a) "
          f"{worst:.1e}, total at r = 1e8 m {err_total:.1e} (potential ~{np.max(np.abs(ref)):.1e} m^2/s^2)")
    assert err_total < 2e-12
    record_number("atmospheric_tides.newton_worst_degree_rel", worst)
    record_number("atmospheric_tides.newton_total_1e8m_rel", err_total)


# ---------------------------------------------------------------- physical checks


def _local_solar_times_of_maximum(dc_nm, ds_nm, m, eo, t):
    """Local apparent solar times [h] of the maxima over longitude of
    dC_nm cos(m lambda) + dS_nm sin(m lambda) (the order-m pressure pattern
    along a parallel; F_n > 0), from the Sun's ITRS longitude (hour angle at
    lambda = lambda - lambda_sun, LST = 12 h + hour angle / 15 deg)."""
    jd1, jd2 = tdb_jd(EPOCH, t, 0.0)
    sun, _ = DirectDE421().geocentric("sun", jd1, jd2)
    sun_itrs = np.einsum("...ij,...j->...i", eo.T_ITRS_GCRS, sun)
    lam_sun = np.arctan2(sun_itrs[..., 1], sun_itrs[..., 0])
    lam0 = np.arctan2(ds_nm, dc_nm) / m                           # a maximum of cos(m (lambda - lam0))
    out = []
    for j in range(m):
        lam = lam0 + 2 * math.pi * j / m
        out.append(np.mod(12.0 + np.degrees(lam - lam_sun) / 15.0, 24.0))
    return np.sort(np.stack(out, axis=-1), axis=-1)


def test_s2_pressure_maximum_near_10_and_22_local_solar_time(record_number):
    """The S2 (2,2) term of the model as used in the dynamics (its dC22,
    dS22 = F_2 (Pc22, Ps22)) puts the pressure maximum at ~10:00 and ~22:00
    local solar time, on every day of a 3-month span."""
    assert stokes_factor(2) > 0
    t = np.arange(0.0, 90 * 86400.0, 86400.0 * 7 + 3 * 3600.0 + 11.0)   # different days and UT hours
    eo, _ = _beta(t)
    s2 = AtmosphericTides(waves=("S2",), degree=2, orientation=standin_orientation)
    dc, ds = s2.evaluate(eo)
    lst = _local_solar_times_of_maximum(dc[:, 2, 2], ds[:, 2, 2], 2, eo, t)
    print(f"\nS2 (2,2) pressure maxima at local solar time {lst[:, 0].min():.3f}..{lst[:, 0].max():.3f} h and "
          f"{lst[:, 1].min():.3f}..{lst[:, 1].max():.3f} h")
    # measured 09:56-10:04 and 21:56-22:04 (the spread is the equation of time)
    assert np.all(np.abs(lst[:, 0] - 10.0) < 1.0) and np.all(np.abs(lst[:, 1] - 22.0) < 1.0)
    # the other reading of the file's note, p = Ccos cos(theta + m lambda) + Csin sin(theta + m lambda)
    # = A cos(theta + m lambda - eps), puts the maximum ~5 h earlier: rejected
    model = read_bb2006().select(wave="S2", n=2, m=2)
    theta = tidal_phase(doodson_arguments(eo.gmst, delaunay_arguments(*eo.tt)), model.doodson[0])
    amp, eps = model.amplitude[0], model.phase[0]
    # A cos(theta - eps + m lambda) = A cos(theta - eps) cos(m lambda) - A sin(theta - eps) sin(m lambda)
    alt = _local_solar_times_of_maximum(amp * np.cos(theta - eps), -amp * np.sin(theta - eps), 2, eo, t)
    print(f"rejected reading: maxima at {alt[:, 0].mean():.3f} h and {alt[:, 1].mean():.3f} h")
    assert np.all(np.abs(alt[:, 0] - 10.0) > 4.0)
    record_number("atmospheric_tides.s2_max_local_time_h", [lst[:, 0].min(), lst[:, 0].max(), lst[:, 1].min(),
                                                            lst[:, 1].max()], "h")
    record_number("atmospheric_tides.s2_rejected_reading_h", [alt[:, 0].mean(), alt[:, 1].mean()], "h")


def test_s1_pressure_maximum_in_the_morning():
    """Secondary check of the S1 argument (Doodson 164.556, with p_s): the
    tropical barogram's 10:00 maximum is higher than its 22:00 one and its
    16:00 minimum deeper than its 04:00 one, which needs the diurnal maximum
    T1 with cos((10 - T1) 15 deg) > 0 > cos((22 - T1) 15 deg) and
    cos((16 - T1) 15 deg) < 0 < cos((4 - T1) 15 deg): 04:00 < T1 < 10:00.
    The migrating S1 (1,1) term peaks at ~06:17 (164.555 would give ~01:10)."""
    t = np.arange(0.0, 60 * 86400.0, 86400.0 * 5 + 7 * 3600.0)
    eo, _ = _beta(t)
    dc, ds = AtmosphericTides(waves=("S1",), degree=2, orientation=standin_orientation).evaluate(eo)
    # degree 1 is not part of the Stokes corrections: the (1,1) pressure from the file's numbers
    model = read_bb2006().select(wave="S1", nmax=1)
    beta = doodson_arguments(eo.gmst, delaunay_arguments(*eo.tt))
    theta = tidal_phase(beta, model.doodson)
    k = [i for i in range(len(model.wave)) if model.n[i] == 1 and model.m[i] == 1][0]
    pc = model.amplitude[k] * np.sin(theta[:, k] + model.phase[k])
    ps = model.amplitude[k] * np.cos(theta[:, k] + model.phase[k])
    lst = _local_solar_times_of_maximum(pc, ps, 1, eo, t)[:, 0]
    print(f"\nS1 (1,1) pressure maximum at local solar time {lst.min():.3f}..{lst.max():.3f} h")
    assert np.all((lst > 4.0) & (lst < 10.0))
    # the module's convention for the degree-2 S1 terms is the same as used here
    pc2, ps2 = pressure_coefficients(beta, read_bb2006().select(wave="S1"), degree=2)
    np.testing.assert_allclose(dc[:, 2, 2], stokes_factor(2) * pc2[:, 2, 2], rtol=1e-13, atol=0)
    np.testing.assert_allclose(ds[:, 2, 2], stokes_factor(2) * ps2[:, 2, 2], rtol=1e-13, atol=0)


def test_magnitude_at_tianqin_distance(record_number):
    """Max |a| over a day and over directions at r = 1e8 m against the
    first-principles bound of the dominant term: a (2,2) coefficient of
    amplitude D accelerates by at most 3 max|Pbar_22| GM/r^2 (a/r)^2 D
    (radial part at the equator; the horizontal parts are in quadrature),
    D = F_2 A_S2,22 (A = 54.5 Pa, F_2 typed in): 6.2e-14 m/s^2."""
    t = np.arange(24) * 3600.0
    prov = AtmosphericTides(orientation=standin_orientation)
    dc, ds = prov(EPOCH, t)
    f2 = 4 * math.pi * G * A_REF ** 2 * (1 - 0.3075) / (GM * G0 * 5)
    r = 1.0e8
    estimate = 3 * (math.sqrt(15) / 2) * GM / r ** 2 * (A_REF / r) ** 2 * f2 * 54.5
    total = max_accel(dc, ds, r=r)
    deg2 = (np.arange(9) == 2)[:, None]
    dc1, ds1 = AtmosphericTides(waves=("S1",), orientation=standin_orientation)(EPOCH, t)
    dc2, ds2 = AtmosphericTides(waves=("S2",), orientation=standin_orientation)(EPOCH, t)
    s1 = max_accel(np.where(deg2, dc1, 0), np.where(deg2, ds1, 0), r=r)
    s2 = max_accel(np.where(deg2, dc2, 0), np.where(deg2, ds2, 0), r=r)
    high = max_accel(np.where(np.arange(9)[:, None] >= 3, dc, 0), np.where(np.arange(9)[:, None] >= 3, ds, 0), r=r)
    amp22 = np.hypot(dc2[:, 2, 2], ds2[:, 2, 2]).max()
    print(f"\natmospheric tides at r = 1e8 m: total {total:.2e} m/s^2 (estimate {estimate:.2e}), degree 2: "
          f"S2 {s2:.2e}, S1 {s1:.2e}; degrees 3-8 {high:.2e}; S2 |dC22, dS22| = {amp22:.2e}")
    assert amp22 == pytest.approx(f2 * 54.5, rel=1e-12)
    assert estimate / 3 < total < 3 * estimate                   # measured 7.6e-14: 1.2x (S2 (2,0), (2,1), S1 add)
    assert total < 2e-13                                         # "of order 1e-13 or below"
    assert s1 < s2 / 3                                           # measured S1/S2 = 0.14 at degree 2
    assert high < total / 10                                     # measured 1.5e-15: a/r = 0.064 per degree
    amp1 = np.hypot(dc1[:, 2, :], ds1[:, 2, :]).max()
    record_number("atmospheric_tides.at_1e8m", {"total": total, "s2_degree2": s2, "s1_degree2": s1,
                                                "s2_dc22": amp22, "s1_degree2_coefficient": amp1}, "m/s^2")


def test_provider_interface():
    """The provider's shapes, degree, the real Earth orientation against the pyerfa stand-in, bad arguments.
    Its cost per chunk is measured by ``tqdyn bench --model kernels``."""
    prov = AtmosphericTides()
    assert prov.degree == 8 and prov.name == "atmospheric_tides" and "Biancale" in prov.source
    t = np.array([[0.0, 600.0], [86400.0, 86400.0 * 45]])
    dc, ds = AtmosphericTides(orientation=standin_orientation)(EPOCH, t, 0.0)
    assert dc.shape == ds.shape == (2, 2, 9, 9)
    assert np.all(dc[..., :2, :] == 0) and np.all(ds[..., 0] == 0) and np.all(np.triu(dc[0, 0], 1) == 0)
    # real Earth orientation vs the pyerfa stand-in: same GMST up to EOP differences
    a = AtmosphericTides()(EPOCH, t.ravel())
    b = AtmosphericTides(orientation=standin_orientation)(EPOCH, t.ravel())
    # (constant UT1-UTC in the stand-in: GMST drifts by ~2e-6 rad over 45 days)
    np.testing.assert_allclose(a[0], b[0], rtol=0, atol=1e-5 * np.max(np.abs(b[0])))
    with pytest.raises(ValueError, match="degree 9"):
        AtmosphericTides(degree=9)
    with pytest.raises(ValueError, match="subset"):
        AtmosphericTides(waves=("K1",))


# ---------------------------------------------------------------- wiring


def test_scenario_switch_and_force_model():
    from tqdyn.forces.model import build_force_model, describe_terms
    from tqdyn.scenario import load_scenario, loads_scenario
    from tqdyn.scenario.config import ForcesConfig

    assert ForcesConfig().atmospheric_tides is False              # off unless switched on
    on = load_scenario("tianqin")
    assert on.forces.atmospheric_tides is True                     # Table II has it
    off = load_scenario("tianqin", ["forces.atmospheric_tides=false"])
    assert "atmospheric_tides = true" in on.to_toml() and "atmospheric_tides = false" in off.to_toml()
    assert loads_scenario(on.to_toml()) == on

    def tide_names(scen):
        field = [t for t in build_force_model(scen.forces).terms if t.name == "earth_field"][0]
        return [getattr(p, "name", "") for p in field.tides], field

    names_on, field = tide_names(on)
    names_off, _ = tide_names(off)
    assert "atmospheric_tides" in names_on and "atmospheric_tides" not in names_off
    assert field.tide_degree == 10                                 # ocean tides (10) > atmospheric (8)
    only, field = tide_names(load_scenario("tianqin", ["forces.ocean_tides_degree=0", "forces.solid_tides=false",
                                                       "forces.pole_tides=false"]))
    assert only == ["atmospheric_tides"] and field.tide_degree == 8
    assert "atmospheric_tides" in [name for name, _, _ in describe_terms()]
    with pytest.raises(Exception, match="atmospheric_tides"):
        load_scenario("tianqin", ["forces.atmospheric_tides=3"])


def test_budget_term_at_tianqin_states():
    """The force budget reports the term by name, of the measured size."""
    from tqdyn.analysis.budget import force_budget
    from tqdyn.forces.model import build_force_model
    from tqdyn.scenario import load_scenario

    scen = load_scenario("tianqin", ["forces.eop=false"])
    model = build_force_model(scen.forces)
    t = np.arange(0.0, 86400.0, 3600.0)
    ang = 2 * math.pi * t / 86400.0 / 3.65                       # ~1 revolution per 3.65 d
    r = 1.0e8 * np.stack([np.cos(ang), np.sin(ang) * 0.27, np.sin(ang) * 0.96], axis=-1)[:, None, :]
    v = np.zeros_like(r)
    budget = {b.name: b for b in force_budget(model, EPOCH, t, np.zeros_like(t), r, v)}
    a = budget["atmospheric_tides"]
    print(f"\nbudget at r = 1e8 m: atmospheric_tides max {a.max:.2e}, ocean_tides max {budget['ocean_tides'].max:.2e}")
    assert "Biancale" in a.source
    assert 1e-14 < a.max < 2e-13                                   # measured 4.5e-14; <= 7.6e-14 (max over directions)


def test_cli_forces_lists_the_term(capsys):
    from tqdyn import cli

    sets = ["forces.third_bodies=sun,moon", "forces.solid_tides=false", "forces.ocean_tides_degree=0",
            "forces.pole_tides=false", "forces.moon_degree=0", "forces.sun_j2=false", "forces.relativity=false",
            "forces.earth_field_indirect=false", "constellation.pointing=none", "constellation.control=off"]
    argv = ["forces", "--duration", "6h", "--every", "3600"] + [x for s in sets for x in ("--set", s)]
    try:
        status = cli.main(argv)
    except SystemExit as exc:
        status = exc.code
    out = capsys.readouterr().out
    assert status == 0
    rows = {p[0]: float(p[1]) for p in (line.split() for line in out.splitlines())
            if len(p) >= 3 and p[1][0].isdigit()}
    assert 1e-14 < rows["atmospheric_tides"] < 2e-13                # 6.7e-14 over 10 days of the full model (docs)
    assert "NOT modelled" not in out
