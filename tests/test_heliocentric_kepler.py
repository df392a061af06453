"""The heliocentric propagation against the exact two-body solution: the
built-in ``lisa-kepler`` scenario (LISA's equal-arm Keplerian design under
the Sun's point mass, GM of DE430) over one year.

Reference: each satellite's initial dd state, converted exactly to mpmath,
turned into osculating elements and propagated analytically with
:func:`tqdyn.astro.elements.kepler_state_at` (Kepler's equation solved by
Newton in mpmath at 50 digits) -- the exact solution of the Sun-only
problem, so the difference is the total numerical error of the run.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from tqdyn import dynamics as prop
from tqdyn.astro import elements as el
from tqdyn.astro.reference import HELIOCENTRIC
from tqdyn.dynamics.initial import central_gm, initial_state
from tqdyn.numerics import dd as P
from tqdyn.scenario import load_scenario

YEAR_S = 365 * 86400


def _final_errors(scen, precision):
    """|r_final - r_kepler| [m] per satellite after the run, and the result."""
    y0 = initial_state(scen)
    result = prop.propagate(scen, precision=precision)
    gm = central_gm(scen)
    errs = []
    with mpmath.workdps(50):
        t = el.from_dd(*result.t_final)
        for b in range(len(scen.satellites)):
            r0 = P.mp_from_dd(y0[b, 0:3])
            v0 = P.mp_from_dd(y0[b, 3:6])
            k = el.state_to_elements(list(r0), list(v0), gm)
            r_ref, _ = el.kepler_state_at(k["a"], k["e"], k["i"], k["raan"], k["argp"], k["nu"], gm, t)
            r = P.mp_from_dd(result.y_final[b, 0:3])
            errs.append(float(mpmath.sqrt(sum((mpmath.mpf(x) - y) ** 2 for x, y in zip(r, r_ref)))))
    return np.array(errs), result


def test_lisa_kepler_one_year_vs_two_body(record_number):
    """Issue acceptance: one year, dd error < 1e-6 m, float64 visibly worse (values in docs/precision.md): DP87
    (the multistep method on these orbits: tests/test_multistep.py)."""
    scen = load_scenario("lisa-kepler", ["integrator.method=dp87"])
    assert scen.reference is HELIOCENTRIC and float(scen.run.duration_s) == YEAR_S
    assert float(scen.integrator.step_s) == 21600.0
    dd, res = _final_errors(scen, "dd")
    f64, _ = _final_errors(scen, "float64")
    print(f"\n[lisa-kepler] 1 year, 6 h steps: dd {dd} m, float64 {f64} m; energy drift {res.energy_rel_drift}")
    # measured (6 h steps, 1460 steps): dd 1.3e-14 .. 2.6e-14 m (the issue asks < 1e-6 m), float64
    # 5.5e-5 .. 1.3e-4 m (round-off of a 1.5e11 m state, ulp 3e-5 m); bounds ~4x either side
    assert 3e-15 < dd.max() < 1e-13
    assert 1.5e-5 < f64.min() and f64.max() < 6e-4
    # energy: the relative drift of the two-body energy, measured -1.45e-26
    assert np.all(np.abs(res.energy_rel_drift) < 6e-26)
    record_number("precision.lisa_kepler_1y_dd_m", [dd.min(), dd.max()], "m")
    record_number("precision.lisa_kepler_1y_float64_m", [f64.min(), f64.max()], "m")
    record_number("precision.lisa_kepler_1y_energy_drift", float(np.max(np.abs(res.energy_rel_drift))))


def test_lisa_kepler_against_lisaorbits_keplerian_orbits():
    """Issue acceptance: the ``lisa-kepler`` run against lisaorbits' ``KeplerianOrbits`` with the same
    parameters (L, a, lambda1, m_init1 of the design), positions monthly over the year.

    Conventions: tqdyn integrates in TDB with DE430's TDB-compatible GM_S = 1.32712440041939e20 m^3/s^2, ICRF
    axes; KeplerianOrbits is an exact Kepler ellipse in ecliptic axes (erfa.ecm06 at J2000) with
    lisaconstants' GM_SUN = 1.3271244e20 (IAU 2015 nominal) and elapsed time t - t_init (its t is TCB; only
    differences enter).  The difference is the GM: 3.16e-10 relative, pi a dGM/GM = 148.5 m along-track after
    a year (growing linearly).  With KeplerianOrbits' mean motion set to DE430's (its only GM dependence,
    ``n``) what remains is float64 rounding on lisaorbits' side (~1e-4 m).
    """
    import warnings

    import erfa

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lisaorbits = pytest.importorskip("lisaorbits")
        from lisaconstants import GM_SUN
    from tqdyn.astro.constellation_design import keplerian_constellation

    scen = load_scenario("lisa-kepler", ["run.output_every=120"])  # every 30 days
    i = scen.initial
    d = keplerian_constellation(i.arm_length_m, i.displacement_deg, i.rotation, scen.epoch.tdb,
                                a=i.semi_major_axis_m, gm=central_gm(scen))
    chunks = []
    prop.propagate(scen, sink=chunks.append)
    rows = prop.Rows.concatenate(chunks)
    t = rows.t[0] + rows.t[1]
    r = rows.sat_r[0] + rows.sat_r[1]
    ecm = np.array(erfa.ecm06(2451545.0, 0.0))
    orb = lisaorbits.KeplerianOrbits(L=float(d.L), a=float(d.a), lambda1=float(d.lambda1), m_init1=float(d.m_init1))
    ref_nominal = orb.compute_position(orb.t_init + t)
    orb.n = np.sqrt(float(central_gm(scen)) / float(d.a) ** 3)
    ref_same_gm = orb.compute_position(orb.t_init + t)
    ours = r @ ecm.T
    diff_nominal = np.linalg.norm(ours - ref_nominal, axis=-1)
    diff_same = np.linalg.norm(ours - ref_same_gm, axis=-1)
    rel = (float(central_gm(scen)) - GM_SUN) / GM_SUN
    predicted = np.pi * float(d.a) * rel * t[-1] / (2 * np.pi * np.sqrt(float(d.a) ** 3 / GM_SUN))
    print(f"\n[lisa-kepler vs KeplerianOrbits] same GM: max {diff_same.max():.2e} m; nominal GM: after a year "
          f"{diff_nominal[-1]} m (predicted {predicted:.1f} m)")
    # measured: same GM 1.1e-4 m (float64 rounding of lisaorbits' 1.5e11 m positions); nominal GM 145.7 .. 146.9 m
    # after 365 d against 146.4 m predicted (pi a dGM/GM per orbital period, times 365 d / period)
    assert diff_same.max() < 1e-3
    assert np.all(np.abs(diff_nominal[-1] - predicted) < 3.0)


def test_lisa_kepler_adaptive_mode():
    """Adaptive DP87 on the heliocentric Kepler case (output every day, rtol 1e-20): one year against the
    analytic solution; measured 4.1e-17 .. 7.3e-17 m (the local error per step is held below 1e-20 |r| =
    1.5e-9 m; the actual error of the 8th-order steps is far below that bound); bound 3e-16 m."""
    scen = load_scenario("lisa-kepler", ["integrator.mode=adaptive", "integrator.rtol=1e-20", "integrator.step=86400"])
    err, res = _final_errors(scen, "dd")
    print(f"\n[lisa-kepler adaptive] 1 year, rtol 1e-20: {err} m")
    assert err.max() < 3e-16
