"""Time-only inputs evaluated with numpy instead of compiled loops (a first run compiles less):
each must give, to the bit, what the per-instant loop it replaced gave.

The references below are those loops (the compiled kernels of tqdyn 0.3.0.dev0 before the change),
run here as plain Python: Python floats are IEEE doubles like numba's (no fast-math, no fused
multiply-add), so the same operations in the same order give the same bits.
"""

import math

import numpy as np

from tqdyn.astro import eop as _eop
from tqdyn.forces import earth as _earth
from tqdyn.forces import solid_tides as _solid
from tqdyn.numerics import lagrange as _lagrange

RNG = np.random.default_rng(20261208)


def test_grid_interp_is_the_scalar_loop():
    """8-point Lagrange interpolation: the per-instant weights (product over the other nodes,
    over the denominator) and the sum over the nodes in order, as the compiled loop did."""
    u = RNG.uniform(10.0, 40.0, 57)
    vals = RNG.normal(size=(60, 3))
    out = np.empty((u.size, 3))
    _lagrange.grid_interp(u, 3, vals, out)
    half, npts = _lagrange.POINTS // 2, _lagrange.POINTS
    for i in range(u.size):
        kq = math.floor(u[i])
        x = float(u[i]) - kq
        w = []
        for j in range(npts):
            p = 1.0
            for q in range(npts):
                if q != j:
                    p *= x - (q - half + 1)
            w.append(p / float(_lagrange._DENOM[j]))
        b = kq - (half - 1) - 3
        for c in range(3):
            acc = 0.0
            for j in range(npts):
                acc += w[j] * float(vals[b + j, c])
            assert out[i, c] == acc


def test_eop_spline_and_utc_are_the_scalar_loops():
    """EOP spline (Horner in s = x - k, k clamped) and UTC from TAI (the day before or after when
    the instant is outside the day's TAI span): the compiled loops' per-instant arithmetic."""
    x = np.concatenate([RNG.uniform(-2.0, 22.0, 60), [0.0, 5.0, 19.999]])
    coef = RNG.normal(size=(20, 4, 6))
    out = np.empty((x.size, 6))
    _eop._cubic_table(x, coef, out)
    for i in range(x.size):
        k = min(max(math.floor(x[i]), 0), 19)
        s = float(x[i]) - k
        for c in range(6):
            ref = ((coef[k, 0, c] * s + coef[k, 1, c]) * s + coef[k, 2, c]) * s + coef[k, 3, c]
            assert out[i, c] == ref
    dat0 = np.where(np.arange(30) < 15, 32.0, 33.0)
    daylen = np.full(30, 86400.0)
    daylen[14] = 86401.0  # a leap second at the end of day 14
    tai = np.concatenate([RNG.uniform(-1.0, 31.0, 80), np.arange(30) + 31.9 / 86400, [15 + 32.5 / 86400]])
    got = np.empty(tai.size)
    _eop._utc_from_tai(tai, dat0, daylen, got)
    n_back = n_ahead = 0
    for q in range(tai.size):
        t = float(tai[q])
        i = min(max(math.floor(t), 0), 29)
        sec = (t - i) * 86400.0 - dat0[i]
        if sec < 0.0 and i > 0:
            i -= 1
            n_back += 1
            sec = (t - i) * 86400.0 - dat0[i]
        elif sec >= daylen[i] and i < 29:
            i += 1
            n_ahead += 1
            sec = (t - i) * 86400.0 - dat0[i]
        assert got[q] == i + sec / daylen[i]
    assert n_back > 0  # both corrections were exercised


def test_tide_packing_is_the_scalar_loop():
    """Packed lower triangles of the tide corrections: the first provider stored (the rest of the
    block zeroed), later ones added up to the degree already held."""
    for filled in (-1, 1, 3):
        out = RNG.normal(size=(4, 30))
        ref = out.copy()
        c = RNG.normal(size=(4, 4, 4))
        _earth._pack(out, 5, c, filled, 15)
        f = (filled + 1) * (filled + 2) // 2
        for i in range(4):
            j = 5
            for n in range(4):
                for m in range(n + 1):
                    ref[i, j] = ref[i, j] + c[i, n, m] if j - 5 < f else c[i, n, m]
                    j += 1
            if filled < 0:
                ref[i, j:20] = 0.0
        assert np.array_equal(out, ref)


def test_step1_solid_tides_are_the_scalar_loop():
    """IERS 2010 eq. 6.6/6.7 per instant and body, in the compiled loop's order of operations."""
    pos = RNG.normal(size=(9, 2, 3)) * np.array([3.8e8, 1.5e11])[None, :, None]
    ratio = np.array([0.0123, 332946.0])
    kre, kim, kplus = RNG.normal(size=(4, 4)), RNG.normal(size=(4, 4)) * 0.01, RNG.normal(size=3) * 0.01
    dc, ds = np.empty((9, 5, 5)), np.empty((9, 5, 5))
    _solid._step1_kernel(pos, ratio, 6378136.3, kre, kim, kplus, True, dc, ds)
    nf = _solid._N
    for i in range(9):
        tr, ti = np.zeros((4, 4)), np.zeros((4, 4))
        for j in range(2):
            x, y, z = (float(v) for v in pos[i, j])
            r = math.sqrt(x * x + y * y + z * z)
            u, w1r, w1i = z / r, x / r, -y / r
            w2r, w2i = w1r * w1r - w1i * w1i, 2.0 * w1r * w1i
            w3r, w3i = w2r * w1r - w2i * w1i, w2r * w1i + w2i * w1r
            q = 6378136.3 / r
            rho2 = ratio[j] * q * q * q
            rho3, u2 = rho2 * q, u * u
            tr[2, 0] += rho2 * nf[2, 0] * 0.5 * (3.0 * u2 - 1.0)
            a = rho2 * nf[2, 1] * 3.0 * u
            tr[2, 1] += a * w1r
            ti[2, 1] += a * w1i
            a = rho2 * nf[2, 2] * 3.0
            tr[2, 2] += a * w2r
            ti[2, 2] += a * w2i
            tr[3, 0] += rho3 * nf[3, 0] * 0.5 * (5.0 * u2 - 3.0) * u
            a = rho3 * nf[3, 1] * 1.5 * (5.0 * u2 - 1.0)
            tr[3, 1] += a * w1r
            ti[3, 1] += a * w1i
            a = rho3 * nf[3, 2] * 15.0 * u
            tr[3, 2] += a * w2r
            ti[3, 2] += a * w2i
            a = rho3 * nf[3, 3] * 15.0
            tr[3, 3] += a * w3r
            ti[3, 3] += a * w3i
        for nn in (2, 3):
            f = 1.0 / (2 * nn + 1)
            for m in range(nn + 1):
                assert dc[i, nn, m] == f * (kre[nn, m] * tr[nn, m] - kim[nn, m] * ti[nn, m])
                assert ds[i, nn, m] == -f * (kre[nn, m] * ti[nn, m] + kim[nn, m] * tr[nn, m])
        for m in range(3):
            assert dc[i, 4, m] == 0.2 * kplus[m] * tr[2, m]
            assert ds[i, 4, m] == -0.2 * kplus[m] * ti[2, m]
        assert dc[i, 4, 3] == 0.0 and dc[i, 0, 0] == 0.0
