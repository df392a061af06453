"""Force-model composition and the time-only-input mechanism, exercised with
the point-mass third-body term and a prescribed (analytic) body orbit.

References: the third-body acceleration written literally in mpmath (50
digits) and as the finite-difference gradient of its potential
Phi = GM (1/|r - s| - r.s/|s|^3); for the mechanism, the convergence order
of the integrator (a time-only input evaluated at wrong stage times makes
the method first order in that term) and the independent time path of the
adaptive mode.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from tqdyn import dynamics
from tqdyn.forces.central import EarthMonopole
from tqdyn.forces.model import ForceModel, gravity
from tqdyn.forces.third_body import ThirdBodies, third_body_accel
from tqdyn.numerics.dd import mp_from_dd
from tqdyn.scenario import load_scenario

from mp_reference import third_body_literal

GM_MOON = 4.9028000661637961e12  # m^3/s^2 (DE430, gm_de431.tpc)
GM_SUN = 1.32712440041939400e20  # m^3/s^2 (DE430)
R_MOON = 3.844e8  # m, mean Earth-Moon distance
W_MOON = 2.6617e-6  # rad/s, mean sidereal motion of the Moon


def _moon_position(epoch, t_hi, t_lo):
    """A test Moon on a circular orbit inclined 20 deg: (..., 1, 3) [m]."""
    t = np.asarray(t_hi) + np.asarray(t_lo)
    c, s = np.cos(W_MOON * t), np.sin(W_MOON * t)
    inc = math.radians(20.0)
    pos = np.stack([R_MOON * c, R_MOON * s * math.cos(inc), R_MOON * s * math.sin(inc)], axis=-1)
    return pos[..., None, :]


def _mp_gradient(r, s, gm, h=mpmath.mpf("1e-3")):
    """4th-order central-difference gradient of Phi = GM (1/|r-s| - r.s/|s|^3)
    at 50 digits; step 1 mm, truncation ~ h^4 |Phi^(5)| ~ 1e-40 relative."""
    with mpmath.workdps(50):
        s = [mpmath.mpf(x) for x in s]
        ns3 = mpmath.sqrt(sum(x * x for x in s)) ** 3

        def phi(p):
            d = mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(p, s)))
            return gm * (1 / d - sum(a * b for a, b in zip(p, s)) / ns3)

        grad = []
        for q in range(3):
            up = [mpmath.mpf(x) for x in r]
            dn = [mpmath.mpf(x) for x in r]
            up[q] += h
            dn[q] -= h
            # 4th-order central difference
            up2 = [mpmath.mpf(x) for x in r]
            dn2 = [mpmath.mpf(x) for x in r]
            up2[q] += 2 * h
            dn2[q] -= 2 * h
            grad.append((8 * (phi(up) - phi(dn)) - (phi(up2) - phi(dn2))) / (12 * h))
        return grad


@pytest.mark.parametrize("gm, s", [
    (GM_MOON, (3.0e8, -2.0e8, 1.0e8)),
    (GM_SUN, (1.2e11, 8.0e10, 3.0e10)),
])
def test_third_body_accel_vs_mpmath(gm, s):
    rng = np.random.default_rng(1)
    for _ in range(20):
        r = rng.normal(size=3)
        r *= 1.0e8 / np.linalg.norm(r)
        got = third_body_accel(*r, *s, gm)
        ref = third_body_literal(r, s, gm)
        grad = _mp_gradient(r, s, gm)
        scale = float(mpmath.sqrt(sum(x * x for x in ref)))
        for q in range(3):
            # float64 evaluation: a few ulps of the result (Moon: ~1e-20 m/s^2),
            # no cancellation loss
            assert abs(got[q] - float(ref[q])) < 2e-15 * scale
            assert abs(float(grad[q] - ref[q])) < 1e-12 * scale  # the potential's gradient is the force


def test_literal_formula_loses_digits_for_the_sun():
    """Why the Battin form: the literal direct-minus-indirect difference
    loses ~3 digits for the Sun at 1e5 km; the Battin form does not."""
    r = np.array([6.0e7, -5.0e7, 6.0e7])
    s = np.array([1.2e11, 8.0e10, 3.0e10])
    ref = np.array([float(x) for x in third_body_literal(r, s, GM_SUN)])
    d = r - s
    naive = -GM_SUN * (d / np.linalg.norm(d) ** 3 + s / np.linalg.norm(s) ** 3)
    battin = np.array(third_body_accel(*r, *s, GM_SUN))
    assert np.max(np.abs(battin - ref)) < 0.1 * np.max(np.abs(naive - ref))


def _model():
    moon = ThirdBodies(names=("Moon",), gms=(GM_MOON,), position=_moon_position, source="test orbit")
    return ForceModel([EarthMonopole(), moon])


def test_composition_sums_terms():
    """gravity() = monopole (dd) + third body (float64), layout from ForceModel."""
    model = _model()
    assert model.n_tdat == 6 and model.time_dependent  # 3 coordinates and their low parts (zero here)
    assert [t.name for t in model.terms] == ["earth_monopole", "third_body"]
    r = (7.0e7, 2.0e7, -6.0e7)
    s = _moon_position(None, np.array(1234.0), np.array(0.0))[0]
    tdat = model.precompute(None, np.array(1234.0), np.array(0.0))
    np.testing.assert_array_equal(tdat, np.concatenate((s, np.zeros(3))))  # a plain callable: no low parts
    dd = [(x, 0.0) for x in r]  # dd inputs: the monopole is evaluated in dd
    total = gravity(*dd, *dd, tdat, model.params, model.layout)
    mono_only = ForceModel([EarthMonopole()])
    mono = gravity(*dd, *dd, np.zeros(0), mono_only.params, mono_only.layout)
    tb = third_body_accel(*r, *s, GM_MOON)
    for q in range(3):
        diff = (Fraction(total[q][0]) + Fraction(total[q][1])) - (Fraction(mono[q][0]) + Fraction(mono[q][1]))
        assert abs(float(diff) - tb[q]) < 1e-30  # the float64 term is added to the dd sum (dd rounding ~1e-33)


def test_kernel_layout_compiles_the_enabled_terms_alone():
    """A model without the Sun's J2 and relativity, given as its kernel_layout, compiles neither kernel
    into the force sum (the LLVM code of the same function given the layout table alone, which compiles
    every term, is the reference: it calls both), gives the table's acceleration to the bit, and stays
    cacheable (no dynamic globals: a term's kernel is no run-time value)."""
    from numba import njit

    from tqdyn.forces.model import float64_terms

    model = _model()

    @njit
    def terms(r, tdat, params, layout):
        return float64_terms(0.0, 0.0, 0.0, r[0], r[1], r[2], 0.0, 0.0, 0.0, tdat, params, layout, -1)

    r = np.array((7.0e7, 2.0e7, -6.0e7))
    tdat = model.precompute(None, np.array(1234.0), np.array(0.0))
    assert terms(r, tdat, model.params, model.kernel_layout) == terms(r, tdat, model.params, model.layout)
    by_layout = {type(sig[-1]).__name__: terms.inspect_llvm(sig) for sig in terms.signatures}
    code_table, code_gated = by_layout["Array"], by_layout["Tuple"]
    for kernel in ("sun_j2_accel", "relativity_accel"):
        assert kernel in code_table and kernel not in code_gated
    assert all(not cres.library._dynamic_globals for cres in terms.overloads.values())


def _final(scen, model, **kw):
    res = dynamics.propagate(scen, model=model, **kw)
    return mp_from_dd(res.y_final[:, 0:3, :]), res


def test_time_only_inputs_reach_every_stage_at_its_time():
    """One day with a moving third body: halving the step changes the result
    by < 1e-10 m.  If the time-only inputs were evaluated at the wrong stage
    times (e.g. all at the step start) the ~6e-10 m/s^2 change of the lunar
    tidal term over a step would be integrated to first order only and the
    two runs would differ by ~1 m.  What remains (~2e-12 m, the same with a
    static Moon, and proportional to GM) is the float64 round-off of the
    perturbation (~1e-21 m/s^2) accumulated over the day; the DP87
    truncation error itself is ~1e-22 m here.
    """
    over = ["run.duration=1d", "satellites.1.e=0.05", "integrator.method=dp87"]  # the stages of DP87
    scen50 = load_scenario("tianqin-kepler", over + ["integrator.step=50"])
    scen25 = load_scenario("tianqin-kepler", over + ["integrator.step=25"])
    model = _model()
    r50, _ = _final(scen50, model, chunk=100)  # several chunks: precompute per chunk
    r25, _ = _final(scen25, model)
    diff = max(float(mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(x, y)))) for x, y in zip(r50, r25))
    print(f"third body, 1 day, |r(50 s) - r(25 s)| = {diff:.2e} m")
    assert diff < 1e-10
    # the Moon's effect itself is large: it is really in the run
    r0, _ = _final(scen50, ForceModel([EarthMonopole()]))
    effect = max(float(mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(x, y)))) for x, y in zip(r50, r0))
    assert effect > 1.0


def test_adaptive_path_agrees_with_fixed():
    """The adaptive driver computes its own stage times (exact rationals);
    with a time-dependent force it agrees with the fixed-step run."""
    over = ["run.duration=6h"]
    fixed = load_scenario("tianqin-kepler", over)
    adaptive = load_scenario("tianqin-kepler", over + ["integrator.mode=adaptive", "integrator.rtol=1e-20"])
    model = _model()
    rf, _ = _final(fixed, model)
    ra, res = _final(adaptive, model)
    assert res.n_steps > 1
    diff = max(float(mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(x, y)))) for x, y in zip(rf, ra))
    print(f"third body, 6 h, |fixed - adaptive(rtol 1e-20)| = {diff:.2e} m")
    assert diff < 1e-9
