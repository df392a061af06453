"""Smooth time-only inputs: the third bodies' positions in double-double
(tqdyn.astro.ephemeris_dd), the first-order effect of their low parts in the
float64 third-body kernel, and the CIP direction on a fixed grid.

References:
* mpmath (40 digits): the same SPK Chebyshev coefficients (exact float64
  numbers, read here with jplephem) summed by the definition
  T_j(s) = cos(j arccos s) at the exact dd time, the segments chained by hand
  (Sun = (0->10) - (0->3) - (3->399), Moon = (3->301) - (3->399));
* jplephem's float64 evaluation (agreement to its own rounding);
* mpmath evaluation of the point-mass acceleration gm [(s - r)/|s - r|^3 -
  s/|s|^3] at the displaced body position (the Jacobian correction);
* ``erfa.xy06`` at every instant (the CIP interpolation).
The smoothness measure: eighth differences on a 50 s grid, summed exactly
(fractions); for a smooth orbit they are h^8 x^(8) ~ 1e-22 m (the Moon's
(50 s x 2.7e-6 /s)^8 x 3.8e8 m), for white noise of rms e they are ~113 e.
"""

from __future__ import annotations

from fractions import Fraction

import erfa
import mpmath
import numpy as np
import pytest
from jplephem.spk import SPK

from tqdyn.astro.ephemeris import default_ephemeris, default_ephemeris_path
from tqdyn.astro.timescales import tt_jd
from tqdyn.forces.relativity import cip_direction
from tqdyn.forces.third_body import third_body_position_jacobian_times
from tqdyn.forces.third_body_ephemeris import third_bodies

CHAINS = {"sun": [(0, 10, 1), (0, 3, -1), (3, 399, -1)], "moon": [(3, 301, 1), (3, 399, -1)]}


def _epoch():
    from tqdyn.scenario import load_scenario

    return load_scenario("tianqin", []).epoch


def _raw(seg):
    """(init [s], intlen [s], coef (3, n_rec, n_coef)) of a type-2 segment, from the file."""
    init, intlen, rsize, n = seg.daf.read_array(seg.end_i - 3, seg.end_i)
    raw = seg.daf.map_array(seg.start_i, seg.end_i - 4).reshape(int(n), int(rsize))
    n_coef = (int(rsize) - 2) // 3
    return float(init), float(intlen), np.array(raw[:, 2:].reshape(int(n), 3, n_coef).transpose(1, 0, 2))


@mpmath.workdps(40)
def test_dd_positions_against_mpmath(record_number):
    """Sun and Moon geocentric positions (DE421) from the dd evaluation vs
    the mpmath sum of the same coefficients at the same dd instants, 40
    instants over 90 days: measured 5.2e-30 (Sun) and 6.8e-29 (Moon)
    relative, 7e-19 / 3e-20 m (the dd time argument, 1e-23 s at 1e9 s past
    J2000, times the speeds); bound 5e-28 relative (the float64 evaluation
    errs by ~1e-16)."""
    spk = SPK.open(default_ephemeris_path())
    try:
        raw = {key: _raw(spk[key]) for chain in CHAINS.values() for key in [(c, t) for c, t, _ in chain]}
        rng = np.random.default_rng(5)
        th = 1.1e9 + np.sort(rng.uniform(0.0, 90 * 86400.0, 40))
        tl = rng.uniform(-1e-7, 1e-7, 40) * np.spacing(th)
        hi, lo = default_ephemeris().geocentric_positions_dd(("sun", "moon"), th, tl)
        worst = {}
        for b, (name, chain) in enumerate(CHAINS.items()):
            rel = 0.0
            for i in range(th.size):
                t = mpmath.mpf(float(th[i])) + mpmath.mpf(float(tl[i]))
                ref = [mpmath.mpf(0)] * 3
                for center, target, sign in chain:
                    init, intlen, coef = raw[center, target]
                    k = min(int(mpmath.floor((t - init) / intlen)), coef.shape[1] - 1)
                    s = 2 * (t - init - k * intlen) / intlen - 1
                    ang = mpmath.acos(s)
                    for c in range(3):
                        ref[c] += sign * 1000 * mpmath.fsum(mpmath.mpf(float(coef[c, k, j])) * mpmath.cos(j * ang)
                                                            for j in range(coef.shape[2]))
                err = mpmath.sqrt(mpmath.fsum((ref[c] - mpmath.mpf(float(hi[i, b, c])) - mpmath.mpf(float(lo[i, b, c])))
                                              ** 2 for c in range(3)))
                rel = max(rel, float(err / mpmath.sqrt(mpmath.fsum(x * x for x in ref))))
            worst[name] = rel
    finally:
        spk.close()
    print(f"\ndd ephemeris vs mpmath, relative: {worst}")
    record_number("smooth.dd_ephemeris_vs_mpmath_rel", max(worst.values()))
    assert max(worst.values()) < 5e-28


def _eighth_differences(hi, lo):
    """Exact eighth differences (rms over windows, per body) [m] of dd positions (n, n_bodies, 3)."""
    w = [(-1) ** (8 - i) * int(mpmath.binomial(8, i)) for i in range(9)]
    out = []
    for j in range(0, hi.shape[0] - 8, 5):
        out.append([[float(sum((Fraction(float(hi[j + i, b, c])) + Fraction(float(lo[j + i, b, c]))) * w[i]
                               for i in range(9))) for c in range(3)] for b in range(hi.shape[1])])
    return np.sqrt((np.asarray(out) ** 2).mean(axis=(0, 2)))


def test_positions_are_smooth_on_a_50s_grid(record_number):
    """Eighth differences of the GCRS positions of the model's third-body
    term on a 50 s grid (the first 6 hours): with the dd inputs (measured Sun
    2e-11 m, Moon 1e-13 m rms: the TDB - TT time argument's float64
    interpolation, ~3e-16 s, times the bodies' geocentric speeds) against
    the float64 positions (Sun 1e-3 m, Moon 3e-6 m: their rounding, ~113
    times the rms of white noise).  Bounds: dd < 2e-10 m (Sun), 2e-12 m (Moon);
    float64 > 1e-4, 1e-7 m."""
    tb = third_bodies(None, ("sun", "moon"))
    t = np.arange(0.0, 6 * 3600.0, 50.0)
    hi, lo = tb.position.position_dd(_epoch(), t, 0.0)
    f = tb.position(_epoch(), t, 0.0)
    dd = _eighth_differences(hi, lo)
    f64 = _eighth_differences(f, np.zeros_like(f))
    print(f"\neighth differences on 50 s [m]: dd {dd}, float64 {f64}")
    record_number("smooth.eighth_diff_dd_m", [float(x) for x in dd], "m")
    record_number("smooth.eighth_diff_float64_m", [float(x) for x in f64], "m")
    assert dd[0] < 2e-10 and dd[1] < 2e-12
    assert f64[0] > 1e-4 and f64[1] > 1e-7
    # the hi parts are the float64 evaluation to its own rounding (~1e-16 relative)
    assert np.all(np.abs(hi - f) < 1e-15 * np.linalg.norm(f, axis=-1, keepdims=True))


@pytest.mark.parametrize("body, gm, s", [
    ("venus", 3.2485859e14, (2.9e10, -2.1e10, -0.9e10)),
    ("sun", 1.32712440041e20, (1.2e11, -7.9e10, -3.4e10)),
    ("moon", 4.9028e12, (-2.1e8, 2.8e8, 1.2e8)),
])
@mpmath.workdps(50)
def test_jacobian_correction_against_mpmath(body, gm, s, record_number):
    """J(r, s) e against the mpmath difference a(r, s + e) - a(r, s) of the
    point-mass acceleration: for |e| = ulp(|s|) / 2 (the size of a low part)
    and |e| = 1e3 m.  The residual is second order, ~(|e| / |s - r|) |J e|,
    plus J's float64 rounding (the two terms of J cancel to ~|r| / |s|:
    measured <= 2e-13 relative for the Sun); bound 1e-11 |J e| + 3 (|e| /
    |s - r|) |J e|."""
    r = (6.1e7, -7.3e7, 2.2e7)

    def mp_acc(sv):
        d = [mpmath.mpf(sv[c]) - mpmath.mpf(r[c]) for c in range(3)]
        sm = [mpmath.mpf(sv[c]) for c in range(3)]
        nd = mpmath.sqrt(mpmath.fsum(x * x for x in d)) ** 3
        ns = mpmath.sqrt(mpmath.fsum(x * x for x in sm)) ** 3
        return [gm * (d[c] / nd - sm[c] / ns) for c in range(3)]

    a_s = mp_acc(s)
    dist = float(np.linalg.norm(np.subtract(s, r)))
    worst = 0.0
    for size in (0.5 * np.spacing(np.linalg.norm(s)), 1e3):
        e = tuple(size * np.array([0.6, -0.48, 0.64]))
        a_e = mp_acc([mpmath.mpf(s[c]) + mpmath.mpf(e[c]) for c in range(3)])
        ref = np.array([float(a_e[c] - a_s[c]) for c in range(3)])
        j = np.array(third_body_position_jacobian_times(*r, *s, gm, *e))
        err = np.linalg.norm(j - ref) / np.linalg.norm(ref)
        print(f"\n{body}: |e| = {size:.1e} m: |J e| = {np.linalg.norm(j):.2e} m/s^2, relative error {err:.1e} "
              f"(second order {size / dist:.1e})")
        if size < 1.0:
            worst = max(worst, err)
        assert err < 1e-11 + 3 * size / dist
    record_number(f"smooth.jacobian_rel_err_{body}", worst)


def test_cip_direction_fixed_grid():
    """The CIP direction is one function of time, whatever instants are
    requested together (bit for bit), and matches erfa.xy06 at every instant
    to < 3e-13 rad over 90 days (measured 1.0e-13 rad; 8-point Lagrange on
    0.5 d nodes)."""
    ep = _epoch()
    t = np.linspace(0.0, 90 * 86400.0, 3001) + 13.25
    u = cip_direction(ep, t)
    x, y = erfa.xy06(*tt_jd(ep, t))
    err = max(np.abs(u[:, 0] - x).max(), np.abs(u[:, 1] - y).max())
    print(f"\nCIP interpolation vs erfa.xy06: {err:.2e} rad")
    assert err < 3e-13
    np.testing.assert_array_equal(cip_direction(ep, t[1000:1013]), u[1000:1013])
    np.testing.assert_array_equal(cip_direction(ep, t[1500]), u[1500])
