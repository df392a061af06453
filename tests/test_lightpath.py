"""Tests of tqdyn.lightpath (iterative light travel times, ranges).

References (independent of the code under test):
(1) analytic two-body Kepler orbits evaluated in mpmath at 40 digits (the
    Kepler equation solved by Newton's method in this file): exact positions,
    velocities and accelerations at the grid times (the input) and exact
    positions at the emission times (the reference for the Hermite dense
    output);
(2) mpmath.findroot of the light-time equation c tau = |r_e(t - tau) - r_r(t)|
    on those exact orbits (the reference for tau);
(3) the light-time residual recomputed in mpmath from the returned dd values;
(4) the Earth Shapiro formula 2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L))
    evaluated in mpmath;
(5) tqdyn's DP87 propagator run directly to the emission instant (a separate
    integration whose step is chosen so that it lands there) as the reference
    for the dense output on a real trajectory.
Bounds are in physical units: 1e-13 m for positions, 1e-13 m / c for tau,
1e-20 s for residuals.  Measured values are printed (pytest -s).
"""

from __future__ import annotations

from decimal import Decimal, localcontext

import mpmath
import numpy as np
import pytest

from tqdyn import lightpath as LP
from tqdyn.astro.constants import C_LIGHT
from tqdyn.constellation.indices import LINKS, Link, Sat
from tqdyn.numerics.dd import mp_from_pair

DPS = 40
GM = "3.986004418e14"  # m^3/s^2, the value the task prescribes for the analytic orbits
STEP = 50  # s
N_ROWS = 145  # 2 hours at 50 s
ROWS = (1, 2, 71, 144)  # rows checked against mpmath (0 has no emission time in the grid)


# ------------------------------------------------------------------ mpmath Kepler reference

def _kepler(el, t):
    """Exact two-body state at time t [s] (mpmath): r [m], v [m/s], a [m/s^2] in
    the inertial frame; el = (a [m], e, i, raan, argp, M0 [rad])."""
    a, e, inc, raan, argp, m0 = el
    gm = mpmath.mpf(GM)
    n = mpmath.sqrt(gm / a ** 3)
    M = m0 + n * t
    E = M
    for _ in range(60):
        dE = (E - e * mpmath.sin(E) - M) / (1 - e * mpmath.cos(E))
        E -= dE
        if abs(dE) < mpmath.mpf(10) ** (-DPS - 5):
            break
    cE, sE = mpmath.cos(E), mpmath.sin(E)
    b = mpmath.sqrt(1 - e * e)
    den = 1 - e * cE
    p = [a * (cE - e), a * b * sE, 0]
    w = [-a * n * sE / den, a * n * b * cE / den, 0]
    cO, sO, ci, si, cw, sw = (mpmath.cos(raan), mpmath.sin(raan), mpmath.cos(inc), mpmath.sin(inc),
                              mpmath.cos(argp), mpmath.sin(argp))
    R = [[cO * cw - sO * sw * ci, -cO * sw - sO * cw * ci, sO * si],
         [sO * cw + cO * sw * ci, -sO * sw + cO * cw * ci, -cO * si],
         [sw * si, cw * si, ci]]
    r = [R[q][0] * p[0] + R[q][1] * p[1] for q in range(3)]
    v = [R[q][0] * w[0] + R[q][1] * w[1] for q in range(3)]
    rn = mpmath.sqrt(sum(x * x for x in r))
    acc = [-gm * x / rn ** 3 for x in r]
    return r, v, acc


def _dd(x):
    hi = float(x)
    return hi, float(x - hi)


def _elements(eccentric: bool, tm: bool):
    """Body elements: 3 satellites 120 deg apart on a = 1e8 m, i = 74.5 deg
    (satellite 2 with e = 0.005 if ``eccentric``); with ``tm`` two bodies per
    satellite displaced +-0.2 m along the track (MOSA 1: +, MOSA 2: -)."""
    a = mpmath.mpf(10) ** 8
    inc, raan = mpmath.radians(mpmath.mpf("74.5")), mpmath.radians(mpmath.mpf("211.6"))
    out = []
    for s in range(3):
        e = mpmath.mpf("0.005") if (eccentric and s == 1) else mpmath.mpf(0)
        m0 = 2 * mpmath.pi * s / 3 + mpmath.radians(30)
        if tm:
            out.append([(a, e, inc, raan, mpmath.mpf(0), m0 + sgn * mpmath.mpf("0.2") / a) for sgn in (1, -1)])
        else:
            out.append((a, e, inc, raan, mpmath.mpf(0), m0))
    return out


def _sample(elements, tm: bool):
    """Grid (N_ROWS at STEP s) with exact states rounded to dd; a as float64."""
    shape = (N_ROWS, 3, 2, 3) if tm else (N_ROWS, 3, 3)
    R, V = np.empty(shape + (2,)), np.empty(shape + (2,))
    A = np.empty(shape)
    for k in range(N_ROWS):
        t = mpmath.mpf(STEP * k)
        for s in range(3):
            for m, el in (enumerate(elements[s]) if tm else [(None, elements[s])]):
                r, v, acc = _kepler(el, t)
                idx = (k, s, m) if tm else (k, s)
                for q in range(3):
                    R[idx + (q,)] = _dd(r[q])
                    V[idx + (q,)] = _dd(v[q])
                    A[idx + (q,)] = float(acc[q])
    t = np.stack([np.arange(N_ROWS) * float(STEP), np.zeros(N_ROWS)], -1)
    return t, R, V, A


def _body(elements, tm, sat: Sat, remote: Sat):
    """Elements of the body of ``sat`` on the link with ``remote``."""
    if not tm:
        return elements[sat.index]
    return elements[sat.index][sat.mosa_facing(remote).index]


@pytest.fixture(scope="module", params=[(False, False), (True, True)], ids=["circular-sats", "eccentric-tms"])
def case(request):
    eccentric, tm = request.param
    with mpmath.workdps(DPS):
        elements = _elements(eccentric, tm)
        t, R, V, A = _sample(elements, tm)
    res = LP.light_travel_times(t, R, V, A)
    return elements, tm, t, R, res


def test_layout_and_nan_rows(case):
    _, tm, _, R, res = case
    assert res.source == ("tm" if tm else "sat")
    assert res.tau[0].shape == (N_ROWS, 6) and res.r_emit[0].shape == (N_ROWS, 6, 3)
    # row 0: the emission time precedes the first sample -> NaN (documented)
    assert np.all(np.isnan(res.tau[0][0])) and np.all(np.isnan(res.r_emit[0][0]))
    assert np.all(np.isfinite(res.tau[0][1:])) and np.all(np.isfinite(res.residual[1:]))
    assert np.all(res.iterations[1:] <= 5)
    # receiver = grid value of the body facing the emitter, exactly (no interpolation)
    for ln in LINKS:
        idx = (ln.receiver.index, ln.mosa.index) if tm else (ln.receiver.index,)
        assert np.array_equal(res.r_receive[0][:, ln.index], R[(slice(None),) + idx + (slice(None), 0)])
        assert np.array_equal(res.r_receive[1][:, ln.index], R[(slice(None),) + idx + (slice(None), 1)])
    # tau ~ sqrt(3) a / c for the triangle on a = 1e8 m
    assert np.all(np.abs(res.tau_f64[1:] - np.sqrt(3) * 1e8 / C_LIGHT) < 5e-3)  # e = 0.005: +-5e5 m


def test_against_mpmath(case):
    # references (1)-(3): exact Kepler position at t - tau, mpmath root of the
    # light-time equation on the exact orbits, residual recomputed in mpmath
    elements, tm, t, _, res = case
    worst_pos = worst_tau = worst_res = 0.0
    with mpmath.workdps(DPS):
        c = mpmath.mpf(C_LIGHT)
        for k in ROWS:
            tk = mp_from_pair(*t[k])
            for ln in LINKS:
                el_e = _body(elements, tm, ln.emitter, ln.receiver)
                el_r = _body(elements, tm, ln.receiver, ln.emitter)
                tau = mp_from_pair(res.tau[0][k, ln.index], res.tau[1][k, ln.index])
                re_dd = [mp_from_pair(res.r_emit[0][k, ln.index, q], res.r_emit[1][k, ln.index, q]) for q in range(3)]
                rr_dd = [mp_from_pair(res.r_receive[0][k, ln.index, q], res.r_receive[1][k, ln.index, q])
                         for q in range(3)]
                exact_e, _, _ = _kepler(el_e, tk - tau)
                worst_pos = max(worst_pos, float(mpmath.sqrt(sum((x - y) ** 2 for x, y in zip(re_dd, exact_e)))))
                rr, _, _ = _kepler(el_r, tk)

                def f(x, rr=rr, el_e=el_e, tk=tk):
                    re = _kepler(el_e, tk - x)[0]
                    return mpmath.sqrt(sum((p - q) ** 2 for p, q in zip(re, rr))) / c - x

                root = mpmath.findroot(f, tau)
                worst_tau = max(worst_tau, float(abs(root - tau)))
                resid = tau - mpmath.sqrt(sum((x - y) ** 2 for x, y in zip(re_dd, rr_dd))) / c
                worst_res = max(worst_res, float(abs(resid)))
    print(f"\nHermite position at t - tau vs exact Kepler: {worst_pos:.2e} m; tau vs mpmath root: "
          f"{worst_tau:.2e} s ({worst_tau * C_LIGHT:.2e} m); residual (mpmath) {worst_res:.2e} s, "
          f"(solver) {np.nanmax(np.abs(res.residual)):.2e} s")
    assert worst_pos < 1e-13
    assert worst_tau < 1e-13 / C_LIGHT
    assert worst_res < 1e-20
    assert np.nanmax(np.abs(res.residual)) < 1e-20


def test_range_is_c_tau(case):
    _, _, _, _, res = case
    with mpmath.workdps(DPS):
        for k in ROWS:
            for j in range(6):
                tau = mp_from_pair(res.tau[0][k, j], res.tau[1][k, j])
                rng = mp_from_pair(res.range[0][k, j], res.range[1][k, j])
                assert abs(float(rng - tau * C_LIGHT)) < 1e-22  # m: dd rounding of c * tau


def test_rate_matches_finite_difference(case):
    # reference: central finite difference of tau along the grid (error ~ h^2 tau''' / 6)
    _, _, _, _, res = case
    tau = res.tau_f64
    fd = (tau[3:] - tau[1:-2]) / (2 * STEP)
    rate = res.tau_rate[2:-1]
    assert np.max(np.abs(fd - rate)) < 1e-14  # s/s; |rate| ~ 1e-5


def test_instantaneous_ranges(case):
    # reference: |r_e(t) - r_r(t)| of the exact orbits in mpmath
    elements, tm, t, R, res = case
    rh, rl = LP.instantaneous_ranges((R[..., 0], R[..., 1]))
    worst = 0.0
    with mpmath.workdps(DPS):
        for k in (0, 144):
            tk = mp_from_pair(*t[k])
            for ln in LINKS:
                re = _kepler(_body(elements, tm, ln.emitter, ln.receiver), tk)[0]
                rr = _kepler(_body(elements, tm, ln.receiver, ln.emitter), tk)[0]
                exact = mpmath.sqrt(sum((x - y) ** 2 for x, y in zip(re, rr)))
                worst = max(worst, float(abs(mp_from_pair(rh[k, ln.index], rl[k, ln.index]) - exact)))
    print(f"\ninstantaneous range vs mpmath: {worst:.2e} m")
    assert worst < 1e-15  # m: dd rounding of the positions (~1e-24 m each) and of the norm
    # the light-path range differs from the instantaneous one by ~ n . v_e tau ~ km
    assert np.all(np.abs(rh[1:] - res.range[0][1:]) < 2e3)
    assert np.array_equal(rh[:, Link.L12.index], rh[:, Link.L21.index])


def test_shapiro():
    # reference (4): Shapiro formula s in mpmath at the solved geometry; to first
    # order in s the term shifts tau by s / (1 + n.v_e / c) (n from receiver to
    # emitter), from differentiating c tau = |r_e(t - tau) - r_r(t)| + c s
    with mpmath.workdps(DPS):
        elements = _elements(False, False)
        t, R, V, A = _sample(elements, False)
    off = LP.light_travel_times(t, R, V, A)
    on = LP.light_travel_times(t, R, V, A, shapiro=True)
    assert np.all(off.shapiro[1:] == 0.0)
    worst = 0.0
    with mpmath.workdps(DPS):
        gm = mpmath.mpf("3.986004415e14")  # default: constants.GM_EARTH_EGM2008
        c = mpmath.mpf(C_LIGHT)
        for k in ROWS:
            for j in range(6):
                re = [mp_from_pair(on.r_emit[0][k, j, q], on.r_emit[1][k, j, q]) for q in range(3)]
                rr = [mp_from_pair(on.r_receive[0][k, j, q], on.r_receive[1][k, j, q]) for q in range(3)]
                a, b = (mpmath.sqrt(sum(x * x for x in p)) for p in (re, rr))
                L = mpmath.sqrt(sum((x - y) ** 2 for x, y in zip(re, rr)))
                s = 2 * gm / c ** 3 * mpmath.log((a + b + L) / (a + b - L))
                d = mp_from_pair(on.tau[0][k, j], on.tau[1][k, j]) - mp_from_pair(off.tau[0][k, j], off.tau[1][k, j])
                nve = sum((x - y) * mpmath.mpf(float(w)) for x, y, w in zip(re, rr, on.v_emit[k, j])) / L
                worst = max(worst, float(abs(d - s / (1 + nve / c))))
                assert abs(on.shapiro[k, j] - float(s)) < 1e-25
    print(f"\nShapiro: tau(on) - tau(off) vs formula: {worst:.2e} s (delay {np.nanmax(on.shapiro):.2e} s)")
    assert 5e-11 < np.nanmax(on.shapiro) < 1e-10  # ~2.3 cm for TianQin
    assert worst < 1e-20
    assert np.allclose(LP.shapiro_delay(on.r_emit[0][1:], on.r_receive[0][1:]), on.shapiro[1:], rtol=1e-12, atol=0)
    assert np.nanmax(np.abs(on.residual)) < 1e-20
    # rate with the Shapiro term vs fourth-order finite differences of tau (dd)
    tau = on.tau[0] + on.tau[1]
    fd = (-tau[5:] + 8 * tau[4:-1] - 8 * tau[2:-3] + tau[1:-4]) / (12 * STEP)
    assert np.max(np.abs(fd - on.tau_rate[3:-2])) < 1e-16


# (shares the propagator kernels compiled for the other tests; ~0.2 s when they are cached)
def test_propagator_dense_output_vs_direct_propagation():
    # reference (5): propagate the built-in Kepler scenario directly to the emission
    # instant t_k - tau and compare with the dense-output emitter position
    from tqdyn.dynamics import Rows, propagate
    from tqdyn.scenario import load_scenario

    blocks = []
    dp87 = "integrator.method=dp87"  # DP87 rows and reference (tests/test_multistep.py: the multistep rows)
    propagate(load_scenario("tianqin-kepler", ["run.duration=2h", dp87]), sink=blocks.append)
    rows = Rows.concatenate(blocks)
    t, R, V, A = rows.t, rows.sat_r, rows.sat_v, rows.sat_a_gravity
    res = LP.light_travel_times(t, R, V, A)
    assert res.source == "sat" and np.nanmax(np.abs(res.residual)) < 1e-20
    k, ln, m = 72, Link.L12, 72  # t_k = 3600 s; emitter = satellite 2
    with mpmath.workdps(DPS), localcontext() as ctx:
        ctx.prec = 45
        te = mp_from_pair(t[0][k], t[1][k]) - mp_from_pair(res.tau[0][k, ln.index], res.tau[1][k, ln.index])
        step = (Decimal(mpmath.nstr(te, 40, min_fixed=-1, max_fixed=50)) / m).quantize(Decimal("1e-28"))
        duration = step * m  # exact in Decimal; |duration - te| <= m * 5e-29 s
        gap = float(mpmath.mpf(str(duration)) - te)
    direct = propagate(load_scenario("tianqin-kepler", [f"run.duration={duration}", f"integrator.step={step}", dp87]))
    y = direct.y_final[ln.emitter.index]  # (6, 2) dd
    worst = 0.0
    with mpmath.workdps(DPS):
        for q in range(3):
            d = mp_from_pair(*y[q]) - mp_from_pair(res.r_emit[0][k, ln.index, q], res.r_emit[1][k, ln.index, q])
            worst = max(worst, float(abs(d)))
    print(f"\ndense output at t - tau vs direct propagation ({m} steps of {float(step):.6f} s): {worst:.2e} m "
          f"(time gap {gap:.1e} s)")
    assert abs(gap) < 1e-26  # s: moves the emitter by < 1e-22 m
    assert worst < 1e-13


class _FakeTrajectory:
    """Duck-typed stand-in for tqdyn.formats.trajectory.Trajectory (dict of arrays)."""

    def __init__(self, fields):
        self._f = fields
        self.n_sat = 3

    def __contains__(self, name):
        return name in self._f

    def dd(self, name):
        return self._f[name]

    def __getitem__(self, name):
        v = self._f[name]
        return v[0] + v[1] if isinstance(v, tuple) else v


def test_trajectory_adapter_fallback():
    with mpmath.workdps(DPS):
        t, R, V, A = _sample(_elements(False, False), False)
    fields = {"t": (t[:, 0], t[:, 1]), "sat/r": (R[..., 0], R[..., 1]), "sat/v": (V[..., 0], V[..., 1]),
              "sat/a_gravity": A}
    res = LP.light_travel_times_of(_FakeTrajectory(fields))
    assert res.source == "sat" and "no test-mass fields" in res.note
    ref = LP.light_travel_times(t, R, V, A)
    assert np.array_equal(res.tau[0][1:], ref.tau[0][1:])
    fields["tm/r"] = (np.zeros((N_ROWS, 3, 2, 3)),) * 2
    with pytest.raises(ValueError, match="tm/v, tm/a"):
        LP.light_travel_times_of(_FakeTrajectory(fields))


def test_bad_inputs():
    t = np.arange(4) * 50.0
    r = np.ones((4, 3, 3)) * 1e8
    with pytest.raises(ValueError, match=r"r: shape \(4, 3, 4\)"):
        LP.light_travel_times(t, np.ones((4, 3, 4)), r, r)
    with pytest.raises(ValueError, match="v: shape"):
        LP.light_travel_times(t, r, np.ones((4, 3, 2, 3)), r)
    with pytest.raises(ValueError, match="strictly increasing"):
        LP.light_travel_times(np.array([0.0, 50.0, 50.0, 100.0]), r, r, r)
    with pytest.raises(ValueError, match="at least 2"):
        LP.light_travel_times(t[:1], r[:1], r[:1], r[:1])
    with pytest.raises(ValueError, match="r: 4 rows but t has 3"):
        LP.light_travel_times(t[:3], r, r, r)
    bad = r.copy()
    bad[2, 1, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        LP.light_travel_times(t, bad, r, r)
    with pytest.raises(ValueError, match="max_iter"):
        LP.light_travel_times(t, r, r, r, max_iter=0)
    with pytest.raises(ValueError, match="layout"):
        LP.link_bodies(r, "mosa")
