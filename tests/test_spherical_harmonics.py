"""Spherical-harmonic gravity kernels (tqdyn.forces.spherical_harmonics).

References, all independent of the kernels' recursion:

* ``_mp_accel``: the gradient of the defining series
  U = GM/r sum_n (R/r)^n sum_m Pbar_nm(sin phi) (C_nm cos m lambda + S_nm sin m lambda),
  differentiated analytically in spherical coordinates and evaluated in
  mpmath at >= 60 digits.  The Legendre functions come from their definition:
  P_n from the explicit sum 2^-n sum_k (-1)^k C(n,k) C(2n-2k,n) t^(n-2k)
  (exact integers), P_nm = (1 - t^2)^(m/2) d^m P_n/dt^m (no Condon-Shortley
  phase), Pbar_nm = sqrt((2 - delta_m0)(2n+1)(n-m)!/(n+m)!) P_nm.  These are
  themselves checked against closed forms and against mpmath's
  hypergeometric ``legenp``.
* heyoka's ``model.egm2008_acc`` (its own EGM2008 table, compiled Taylor
  expression system), evaluated in real128.

Tolerances are in m/s^2, stated per check; the kernels round like float64
arithmetic on the perturbation, so they are set at 1e-14 of the perturbation
magnitude at each point.
"""

from __future__ import annotations

import functools
import math

import mpmath
import numpy as np
import pytest

from tqdyn.readers.gravity_fields import egm2008
from tqdyn.forces.spherical_harmonics import (
    NMAX_SH,
    sh_accel,
    sh_accel_corrections,
    sh_accel_delta,
    sh_accel_flat,
)

GM = 3.986004415e14  # m^3/s^2, EGM2008
RE = 6378136.3  # m, EGM2008
REL_TOL = 1e-14  # of |a| at each point


# --------------------------------------------------------------------------
# mpmath reference: the defining formula


@functools.lru_cache(maxsize=None)
def _dm_legendre(n: int, m: int) -> tuple:
    """((power, integer coefficient), ...) of 2^n d^m P_n / dt^m (exact)."""
    out = []
    for k in range(n // 2 + 1):
        p = n - 2 * k
        if p < m:
            continue
        c = (-1) ** k * math.comb(n, k) * math.comb(2 * n - 2 * k, n) * math.perm(p, m)
        out.append((p - m, c))
    return tuple(out)


def _poly(n, m, tpow):
    return sum((c * tpow[q] for q, c in _dm_legendre(n, m)), mpmath.mpf(0)) / mpmath.mpf(2) ** n


def _norm(n, m):
    return mpmath.sqrt(mpmath.mpf((2 - (m == 0)) * (2 * n + 1) * math.factorial(n - m)) / math.factorial(n + m))


def _mp_pbar(n, m, t):
    """Fully-normalised associated Legendre function from its definition."""
    t = mpmath.mpf(t)
    tpow = [t**q for q in range(n + 1)]
    return _norm(n, m) * (1 - t * t) ** (mpmath.mpf(m) / 2) * _poly(n, m, tpow)


def _mp_accel(r, gm, radius, C, S, nmax, nmin=2, dps=60):
    """Gradient of the defining series at the body-fixed point r [m]
    (floats, taken exactly), in mpmath; returns 3 mpf [m/s^2]."""
    with mpmath.workdps(dps):
        x, y, z = (mpmath.mpf(float(v)) for v in r)
        gm, radius = mpmath.mpf(float(gm)), mpmath.mpf(float(radius))
        rn = mpmath.sqrt(x * x + y * y + z * z)
        t = z / rn  # sin(phi)
        c = mpmath.sqrt(x * x + y * y) / rn  # cos(phi)
        lam = mpmath.atan2(y, x)
        tpow = [t**q for q in range(nmax + 2)]
        cpow = [c**q for q in range(nmax + 2)]
        ar = aphi = alam = mpmath.mpf(0)
        for n in range(nmin, nmax + 1):
            rho = (radius / rn) ** n
            for m in range(n + 1):
                cnm, snm = float(C[n, m]), float(S[n, m])
                if cnm == 0.0 and snm == 0.0:
                    continue
                N = _norm(n, m)
                q0 = _poly(n, m, tpow)
                q1 = _poly(n, m + 1, tpow) if m < n else mpmath.mpf(0)
                cm, sm = mpmath.cos(m * lam), mpmath.sin(m * lam)
                A = cnm * cm + snm * sm
                B = -cnm * sm + snm * cm
                P = N * cpow[m] * q0
                dP = N * (cpow[m + 1] * q1 - (m * cpow[m - 1] * t * q0 if m > 0 else 0))
                ar += -(n + 1) * rho * P * A
                aphi += rho * dP * A
                if m > 0:
                    alam += rho * N * cpow[m - 1] * q0 * m * B
        k = gm / (rn * rn)
        cl, sl = mpmath.cos(lam), mpmath.sin(lam)
        er = (c * cl, c * sl, t)
        ephi = (-t * cl, -t * sl, c)
        elam = (-sl, cl, mpmath.mpf(0))
        return [k * (ar * er[i] + aphi * ephi[i] + alam * elam[i]) for i in range(3)]


def _cart(r, lat_deg, lon_deg):
    la, lo = math.radians(lat_deg), math.radians(lon_deg)
    return (r * math.cos(la) * math.cos(lo), r * math.cos(la) * math.sin(lo), r * math.sin(la))


POINTS = {
    "r=7e6 mid-latitude": _cart(7e6, 35.0, 20.0),
    "r=7e6 near north pole": _cart(7e6, 89.9999, 123.0),
    "r=7e6 south pole": (0.0, 0.0, -7e6),
    "r=R (surface), lat 10": _cart(RE, 10.0, 200.0),
    "r=1e8 lat -50": _cart(1e8, -50.0, 250.0),
    "r=1e8 equator": _cart(1e8, 0.0, 77.0),
}


def _check(a, ref, what):
    a = np.asarray(a)
    ref = np.array([float(v) for v in ref])
    err = np.abs(a - ref).max()
    tol = REL_TOL * np.linalg.norm(ref)
    assert err <= tol, f"{what}: |a - a_ref| = {err:.3e} m/s^2 > {tol:.3e} m/s^2 (|a_ref| = {np.linalg.norm(ref):.3e})"
    return err, tol


# --------------------------------------------------------------------------
# the reference's Legendre functions


def test_reference_legendre_functions():
    """Closed forms (Pbar_20 = sqrt5 (3t^2-1)/2, Pbar_22 = sqrt(15)/2 (1-t^2),
    Pbar_33 = sqrt(35/8) (1-t^2)^(3/2)) and mpmath's hypergeometric legenp,
    which carries the Condon-Shortley phase (-1)^m: agreement to 1e-40."""
    with mpmath.workdps(60):
        t = mpmath.mpf("0.3")
        assert abs(_mp_pbar(2, 0, t) - mpmath.sqrt(5) * (3 * t * t - 1) / 2) < 1e-50
        assert abs(_mp_pbar(2, 2, t) - mpmath.sqrt(15) / 2 * (1 - t * t)) < 1e-50
        assert abs(_mp_pbar(3, 3, t) - mpmath.sqrt(mpmath.mpf(35) / 8) * (1 - t * t) ** 1.5) < 1e-50
    for n, m in [(7, 3), (12, 12), (40, 17), (90, 0), (90, 45), (90, 60)]:
        with mpmath.workdps(50):
            ref = (-1) ** m * _norm(n, m) * mpmath.legenp(n, m, mpmath.mpf("0.61"), type=2)
        with mpmath.workdps(150):  # the explicit sums cancel ~20 digits at degree 90
            got = _mp_pbar(n, m, mpmath.mpf("0.61"))
        assert abs(got - ref) <= 1e-40 * max(1, abs(ref)), (n, m)


# --------------------------------------------------------------------------
# kernel vs the defining formula


@pytest.mark.parametrize("where", list(POINTS))
def test_egm2008_degree12_vs_mpmath(where):
    """EGM2008 degrees 2..12 (the paper's field) vs the 60-digit reference;
    tolerance 1e-14 |a| [m/s^2] (|a| ~ 1e-2 at 7e6 m, 3e-7 at 1e8 m)."""
    m = egm2008(12)
    r = POINTS[where]
    a = sh_accel(*r, m.gm, m.radius, m.C, m.S, 12)
    _check(a, _mp_accel(r, m.gm, m.radius, m.C, m.S, 12), where)


@pytest.mark.parametrize("where", ["r=7e6 mid-latitude", "r=7e6 near north pole", "r=R (surface), lat 10"])
def test_egm2008_degree90_vs_mpmath(where):
    """EGM2008 degrees 2..90 (the whole shipped file) vs the reference at
    150 digits (the explicit Legendre sums cancel ~20 digits at degree 90);
    tolerance 1e-14 |a| [m/s^2].  Measured: 1.0e-15 |a| at 7e6 m, 8e-16
    near the pole, 6.2e-15 |a| = 9.7e-17 m/s^2 at r = R (all 89 degrees
    unattenuated: the worst case)."""
    m = egm2008(90)
    r = POINTS[where]
    a = sh_accel(*r, m.gm, m.radius, m.C, m.S, 90)
    _check(a, _mp_accel(r, m.gm, m.radius, m.C, m.S, 90, dps=150), where)


def _random_field(n, seed):
    """A field whose every coefficient matters: C_nm, S_nm ~ N(0, 1) / n^2
    (EGM2008's high-degree terms are too small at 1e8 m to test them)."""
    rng = np.random.default_rng(seed)
    C = np.tril(rng.normal(size=(n + 1, n + 1))) / np.maximum(np.arange(n + 1), 1)[:, None] ** 2
    S = np.tril(rng.normal(size=(n + 1, n + 1))) / np.maximum(np.arange(n + 1), 1)[:, None] ** 2
    S[:, 0] = 0.0
    return C, S


@pytest.mark.parametrize("where", ["r=7e6 mid-latitude", "r=7e6 near north pole", "r=7e6 south pole", "r=1e8 lat -50"])
def test_random_field_vs_mpmath(where):
    """O(1) random coefficients to degree 20, including the monopole
    (nmin = 0) and degree 1: tolerance 1e-14 |a| [m/s^2]."""
    C, S = _random_field(20, 7)
    r = POINTS[where]
    for nmin in (0, 2):
        a = sh_accel(*r, GM, RE, C, S, 20, nmin)
        _check(a, _mp_accel(r, GM, RE, C, S, 20, nmin), f"{where}, nmin={nmin}")


def test_monopole_and_degree_selection():
    """nmin = 0 with C00 = 1 adds exactly -GM r/r^3 (to float64 rounding of
    the monopole, 1e-16 |a|); nmin/mmax select degrees and orders like
    zeroing the other coefficients (exact up to 1e-16 |a|)."""
    m = egm2008(12)
    r = np.array(POINTS["r=7e6 mid-latitude"])
    a0 = np.array(sh_accel(*r, m.gm, m.radius, m.C, m.S, 12, 0))
    a2 = np.array(sh_accel(*r, m.gm, m.radius, m.C, m.S, 12))
    mono = -m.gm * r / np.linalg.norm(r) ** 3
    assert np.abs(a0 - a2 - mono).max() < 1e-15 * np.linalg.norm(mono)
    C, S = m.C.copy(), m.S.copy()
    C[:, 5:], S[:, 5:] = 0.0, 0.0
    C[:4], S[:4] = 0.0, 0.0
    ref = np.array(sh_accel(*r, m.gm, m.radius, C, S, 12))
    got = np.array(sh_accel(*r, m.gm, m.radius, m.C, m.S, 12, 4, 4))
    assert np.abs(got - ref).max() <= 1e-16 * np.linalg.norm(ref) + 1e-30


# --------------------------------------------------------------------------
# corrections (tides)


def test_corrections_vs_summed_coefficients_and_mpmath():
    """sh_accel_delta(C, S, dC, dS) equals sh_accel(C + dC, S + dS) and
    sh_accel_corrections(dC, dS) equals the reference of the corrections
    alone, for square (nt+1, nt+1) and packed-triangle layouts; corrections
    of degree 10 (above the static degree 4 here, to test that case too)
    and 4.  Tolerance 1e-14 |a| [m/s^2]."""
    m = egm2008(12)
    r = POINTS["r=7e6 mid-latitude"]
    rng = np.random.default_rng(3)
    rows, cols = np.tril_indices(11)
    for nmax, nt in [(12, 4), (4, 10)]:
        dC = np.tril(rng.normal(size=(nt + 1, nt + 1))) * 1e-8
        dS = np.tril(rng.normal(size=(nt + 1, nt + 1))) * 1e-8
        dS[:, 0] = 0.0
        n1 = max(nmax, nt) + 1
        Ct, St = np.zeros((n1, n1)), np.zeros((n1, n1))
        Ct[: nmax + 1, : nmax + 1] += m.C[: nmax + 1, : nmax + 1]
        St[: nmax + 1, : nmax + 1] += m.S[: nmax + 1, : nmax + 1]
        Ct[: nt + 1, : nt + 1] += dC
        St[: nt + 1, : nt + 1] += dS
        ref_total = sh_accel(*r, m.gm, m.radius, Ct, St, n1 - 1)
        got = sh_accel_delta(*r, m.gm, m.radius, m.C, m.S, nmax, dC.ravel(), dS.ravel(), nt)
        _check(got, ref_total, f"static {nmax} + corrections {nt}")
        k = (nt + 1) * (nt + 2) // 2
        got_p = sh_accel_delta(*r, m.gm, m.radius, m.C, m.S, nmax, dC[rows[:k], cols[:k]].copy(),
                               dS[rows[:k], cols[:k]].copy(), nt, 2, -1, True)
        assert np.array_equal(np.array(got_p), np.array(got))
        ref_corr = _mp_accel(r, m.gm, m.radius, dC, dS, nt)
        _check(sh_accel_corrections(*r, m.gm, m.radius, dC.ravel(), dS.ravel(), nt), ref_corr, f"corrections {nt}")
        _check(sh_accel_corrections(*r, m.gm, m.radius, dC[rows[:k], cols[:k]].copy(),
                                    dS[rows[:k], cols[:k]].copy(), nt, 2, True), ref_corr, f"packed corrections {nt}")


def test_bad_degrees_raise():
    m = egm2008(12)
    with pytest.raises(ValueError, match="nmax above"):
        sh_accel(7e6, 0.0, 0.0, m.gm, m.radius, m.C, m.S, 13)
    big = np.zeros(NMAX_SH + 2)
    with pytest.raises(ValueError, match="NMAX_SH"):
        sh_accel_flat(7e6, 0.0, 0.0, GM, RE, big, big, 1, -1, -1, big, big, 0, NMAX_SH + 1, 2)
    with pytest.raises(ValueError, match="shorter"):
        sh_accel_corrections(7e6, 0.0, 0.0, GM, RE, np.zeros(10), np.zeros(10), 4)


# --------------------------------------------------------------------------
# second library: heyoka


@pytest.mark.heyoka
def test_vs_heyoka_egm2008_degree12():
    """heyoka.model.egm2008_acc(n = m = 12) minus its degree <= 1 part, in
    real128 (heyoka ships its own EGM2008 table; its C20 is the tide-free
    -4.84165143790815e-4 like ours): agreement 1e-14 |a| [m/s^2] at 1e8 m
    and 7e6 m; the coefficient tables agree to their printed digits."""
    hy = pytest.importorskip("heyoka")
    x, y, z = hy.make_vars("x", "y", "z")
    acc = hy.model.egm2008_acc([x, y, z], 12, 12)
    acc1 = hy.model.egm2008_acc([x, y, z], 1, 1)
    f = hy.cfunc([a - b for a, b in zip(acc, acc1)], [x, y, z], fp_type=hy.real128)
    assert float(hy.model.get_egm2008_mu()) == GM and float(hy.model.get_egm2008_a()) == RE
    m = egm2008(12)
    for where, r in POINTS.items():
        ref = f(np.array([hy.real128(v) for v in r]))
        ref = [mpmath.mpf(str(v)) for v in ref]
        _check(sh_accel(*r, m.gm, m.radius, m.C, m.S, 12), ref, f"heyoka, {where}")


# --------------------------------------------------------------------------
# magnitudes along a TianQin orbit and timing (reported)


def _tianqin_circle(n=400, r=1e8, inc=74.5, raan=211.6):
    u = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    i, o = np.radians(inc), np.radians(raan)
    p = np.stack([np.cos(u), np.sin(u) * np.cos(i), np.sin(u) * np.sin(i)], axis=1) * r
    Rz = np.array([[np.cos(o), -np.sin(o), 0.0], [np.sin(o), np.cos(o), 0.0], [0.0, 0.0, 1.0]])
    return p @ Rz.T


def test_magnitudes_along_tianqin_orbit(capsys):
    """Per-degree acceleration of EGM2008 along a circle r = 1e8 m,
    i = 74.5 deg (GCRS = ITRS here: the magnitudes do not depend on the
    Earth's rotation angle beyond a factor ~2).  Expected: C20 ~ 3e-7 m/s^2
    (3/2 J2 GM R^2/r^4 = 2.6e-7 times a latitude factor of 1..2), degree n
    falling roughly like (R/r)^n ~ 0.064^n."""
    m = egm2008(12)
    pts = _tianqin_circle()
    rows = []
    for n in range(2, 13):
        C, S = np.zeros_like(m.C), np.zeros_like(m.S)
        C[n], S[n] = m.C[n], m.S[n]
        a = np.array([sh_accel(*p, m.gm, m.radius, C, S, 12) for p in pts])
        rows.append((n, np.linalg.norm(a, axis=1).max()))
    with capsys.disabled():
        print("\nEGM2008 per-degree max |a| along r = 1e8 m, i = 74.5 deg [m/s^2]: "
              + ", ".join(f"n={n}: {v:.2e}" for n, v in rows))
    mags = dict(rows)
    assert 2e-7 < mags[2] < 6e-7
    assert 1e-10 < mags[3] < 1e-9
    assert 1e-12 < mags[4] < 1e-10
    for n in range(3, 12):
        assert mags[n + 1] < 0.3 * mags[n]
