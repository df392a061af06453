"""Acceleration of a fully-normalised spherical-harmonic gravity field (compiled, float64).

The potential of a body of gravitational parameter GM [m^3/s^2] and reference
radius R [m], at body-fixed position r = (x, y, z) [m] (geocentric latitude
phi, longitude lambda), is

    U = GM/r  sum_{n=nmin}^{N} (R/r)^n  sum_{m=0}^{n}
              Pbar_nm(sin phi) (C_nm cos(m lambda) + S_nm sin(m lambda))

with the fully-normalised ("4 pi", geodesy) associated Legendre functions
Pbar_nm = sqrt((2 - delta_m0) (2n + 1) (n - m)! / (n + m)!) P_nm, P_nm without
the Condon-Shortley phase.  The acceleration is a = grad U, in the same
body-fixed frame as r.  C_00 = 1 gives the monopole; tqdyn evaluates the
monopole separately in extended precision (:mod:`tqdyn.forces.central`), so
the kernels default to ``nmin = 2`` (degree 1 vanishes for a field referred
to the center of mass).

Algorithm: Cunningham's solid harmonics in Cartesian form, fully normalised
(O. Montenbruck & E. Gill, *Satellite Orbits*, Springer 2000, sec. 3.2.4,
eqs. 3.27-3.33, with the normalisation carried into every recursion and
acceleration factor):

    Vbar_nm + i Wbar_nm = (R/r)^(n+1) Pbar_nm(sin phi) exp(i m lambda)

    Vbar_00 = R/r,  Vbar_mm = c_m (x R/r^2 Vbar_{m-1,m-1} - y R/r^2 Wbar_{m-1,m-1})
    Vbar_nm = a_nm z R/r^2 Vbar_{n-1,m} - b_nm R^2/r^2 Vbar_{n-2,m}      (n > m)

    c_1 = sqrt(3), c_m = sqrt((2m + 1) / (2m)),
    a_nm = sqrt((2n - 1)(2n + 1) / ((n - m)(n + m))),
    b_nm = sqrt((2n + 1)(n + m - 1)(n - m - 1) / ((2n - 3)(n + m)(n - m))),

(the same for Wbar) -- the standard forward-column recursion of Pbar_nm,
stable for all degrees used here (underflow of the sectoral terms starts
beyond degree ~1500).  The gradient of degree n is a combination of the
degree-(n+1) harmonics of orders m-1, m, m+1, so the kernels walk the
harmonics column by column (order k, degree j = k .. N+1) keeping only the
last two values of the current column, and add the contribution of each
(j, k) to the coefficients (j-1, k-1), (j-1, k), (j-1, k+1) as it is formed:
no scratch arrays, no allocation, no singularity at the poles (Cartesian
form).  The recursion factors a_nm, b_nm, c_m and the three acceleration
factors of each (j, k) are read from module constants tabulated to degree
64 (86 kB; products of sqrt(i), 1/sqrt(i)) and formed on the fly, as the
same products, above it; the loops over the degrees are split so that the
rows where all three coefficients exist run without tests, and all array
indices are unsigned (no negative-index wrap-around code).

Time-variable corrections (tides): :func:`sh_accel_delta` evaluates the
static field C, S (a 2-D (N+1, N+1) array) plus corrections dC, dS given as
flat 1-D arrays -- either a (nt+1, nt+1) array flattened row-major
(dC_nm = dC[n (nt + 1) + m], the tide models' output) or packed lower
triangles (dC_nm = dC[n (n + 1)/2 + m], (nt+1)(nt+2)/2 values, the layout
of the Earth term's time-only inputs) -- summed on the fly; :func:`sh_accel_corrections`
evaluates the corrections alone (force budgets of the tides);
:func:`sh_accel_flat` is the common core on flat arrays with explicit
leading dimensions, for kernels that take coefficients from a flat
parameter vector (:mod:`tqdyn.forces.earth`).

All kernels: float64 scalars in and out, m, m^3/s^2, m/s^2, compiled with
numba (no fastmath), no allocation.  Round-off: ~1e-16 .. 1e-15 of the
perturbation's magnitude (measured against a 60-digit, at degree 90
150-digit, mpmath evaluation of the defining series in
tests/test_spherical_harmonics.py; the test bound is 1e-14).  Cost per
evaluation of :func:`sh_accel` at N = 12 and 90: measured by ``tqdyn bench
--model kernels``; the tables and the split loops made the kernels faster
with bit-for-bit the same results.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..numerics.jit import dynamic  # (importing numerics.jit registers the package-wide kernel cache)
from ..numerics.jit import inner_kernel

__all__ = [
    "NMAX_SH",
    "sh_accel",
    "sh_accel_delta",
    "sh_accel_corrections",
    "sh_accel_flat",
]

#: Highest degree the kernels accept (size of the square-root tables).
NMAX_SH = 360

_NTAB = 2 * NMAX_SH + 6
_SQ = np.sqrt(np.arange(_NTAB, dtype=np.float64))  # sqrt(i)
_ISQ = np.zeros(_NTAB)
_ISQ[1:] = 1.0 / np.sqrt(np.arange(1, _NTAB, dtype=np.float64))  # 1/sqrt(i), 0 at i = 0
_SQ.setflags(write=False)
_ISQ.setflags(write=False)
_SQRT2 = math.sqrt(2.0)


def _factor_tables(jtop, nmax):
    """Recursion and acceleration factors of every harmonic (j, k), 0 <= k <= j
    <= jtop, in packed lower-triangle order (index j(j + 1)/2 + k):
    a_jk, b_jk (recursion, see the module docstring; a_{k+1,k} = sqrt(2k + 3),
    b_{k+1,k} = 0), and the acceleration factors f_z, f_-, f_+ of the
    coefficients (j-1, k), (j-1, k-1), (j-1, k+1) (0 where the coefficient
    does not exist), with the normalisation ratio g_n = sqrt((2n + 1)/(2n + 3))
    of degree n = j - 1 and the sqrt(2) of the orders 0:

        f_z = g_n sqrt((j + k)(j - k)),
        f_- = g_n sqrt((j + k - 1)(j + k)) / 2    (x sqrt 2 at k = 1),
        f_+ = g_n sqrt((j - k - 1)(j - k)) / 2    (x sqrt 2 at k = 0);

    and the sectoral factors c_k (k = 1 .. nmax + 1; c_0 = 0 unused).  Each
    is formed as the same product of the tabulated sqrt(i), 1/sqrt(i), in
    the same order, as the loops formed them before the tables existed, so
    the kernels' results are bit-for-bit those of that version
    (independently rounded factors sqrt(ratio) were measured to be no more
    accurate on average, but moved single points of the degree >= 3 field by
    up to 1e-14)."""
    sq, isq = _SQ, _ISQ
    j = np.concatenate([np.full(i + 1, i) for i in range(jtop + 1)])
    k = np.concatenate([np.arange(i + 1) for i in range(jtop + 1)])
    n = j - 1
    a, b, fz, fm, fp = (np.zeros(j.size) for _ in range(5))
    s1 = j == k + 1
    a[s1] = sq[2 * j[s1] + 1]
    s = j > k + 1
    js, ks = j[s], k[s]
    a[s] = sq[2 * js - 1] * sq[2 * js + 1] * isq[js - ks] * isq[js + ks]
    b[s] = sq[2 * js + 1] * sq[js + ks - 1] * sq[js - ks - 1] * isq[2 * js - 3] * isq[js + ks] * isq[js - ks]
    g = np.zeros(j.size)
    s = n >= 0
    g[s] = sq[2 * n[s] + 1] * isq[2 * n[s] + 3]
    s = n >= k
    fz[s] = g[s] * sq[j[s] + k[s]] * sq[j[s] - k[s]]
    s = (k >= 1) & (n >= 0)
    fm[s] = 0.5 * g[s] * sq[j[s] + k[s] - 1] * sq[j[s] + k[s]]
    s = n >= k + 1
    fp[s] = 0.5 * g[s] * sq[np.maximum(j[s] - k[s] - 1, 0)] * sq[j[s] - k[s]]
    fm[k == 1] *= _SQRT2
    fp[k == 0] *= _SQRT2
    ck = np.zeros(nmax + 2)
    kk = np.arange(2, nmax + 2)
    ck[2:] = sq[2 * kk + 1] * isq[2 * kk]
    ck[1] = math.sqrt(3.0)
    return a, b, fz, fm, fp, ck


# read-only module constants, frozen into the compiled kernels -- and into
# the cache file of every kernel calling them, hence tabulated only to
# harmonic degree j <= _JT (86 kB); above it the kernels form the same products on the fly
# (_factors), with bit-for-bit the same values
_JT = 64
_A, _B, _FZ, _FM, _FP, _CK = _factor_tables(_JT, NMAX_SH)
for _t in (_A, _B, _FZ, _FM, _FP, _CK):
    _t.setflags(write=False)
del _t

@inner_kernel
def _factors(j, k):
    """(a, b, f_z, f_-, f_+) of harmonic (j, k), j >= 1, as in _factor_tables
    (same products, same order); for the degrees above the tables."""
    sq, isq = _SQ, _ISQ
    n = j - 1
    a, b, fz, fm, fp = 0.0, 0.0, 0.0, 0.0, 0.0
    if j == k + 1:
        a = sq[2 * j + 1]
    elif j > k + 1:
        a = sq[2 * j - 1] * sq[2 * j + 1] * isq[j - k] * isq[j + k]
        b = sq[2 * j + 1] * sq[j + k - 1] * sq[j - k - 1] * isq[2 * j - 3] * isq[j + k] * isq[j - k]
    g = sq[2 * n + 1] * isq[2 * n + 3]
    if n >= k:
        fz = g * sq[j + k] * sq[j - k]
    if k >= 1:
        fm = 0.5 * g * sq[j + k - 1] * sq[j + k]
        if k == 1:
            fm *= _SQRT2
    if n >= k + 1:
        fp = 0.5 * g * sq[j - k - 1] * sq[j - k]
        if k == 0:
            fp *= _SQRT2
    return a, b, fz, fm, fp


@njit(cache=True, inline="always")
def _advance(j, k, ib, zr, rr, v1, w1, v, w, ta, tb, tz, tm, tp):
    """One step (j - 1, k) -> (j, k) of the column recursion for j >= k + 2
    (ib: the table index of (j, k)): (f_z, f_-, f_+) of (j, k) and the new
    (Vbar, Wbar) of degrees j - 1 and j.  Inlined into the kernel's loops."""
    if j <= _JT:
        u = np.uint64(ib)
        fa, fb, fz, fm, fp = ta[u], tb[u], tz[u], tm[u], tp[u]
    else:
        fa, fb, fz, fm, fp = _factors(j, k)
    a = fa * zr
    b = fb * rr
    return fz, fm, fp, v, w, a * v - b * v1, a * w - b * w1


@njit(cache=True, inline="always")
def _accumulate(ax, ay, az, fz, fm, fp, v, w, cm, sm, c0, s0, cp, sp):
    """Add harmonic (j, k)'s contribution through the coefficients (n, k - 1)
    (cm, sm), (n, k) (c0, s0), (n, k + 1) (cp, sp), n = j - 1, with factors
    f_-, f_z, f_+ (the rows of the branch-free loops, where all three orders exist)."""
    az -= fz * (c0 * v + s0 * w)
    ax -= fm * (cm * v + sm * w)
    ay -= fm * (cm * w - sm * v)
    ax += fp * (cp * v + sp * w)
    ay += fp * (sp * v - cp * w)
    return ax, ay, az


@inner_kernel
def sh_accel_flat(x, y, z, gm, radius, C, S, ldc, nmax, mmax, dC, dS, ldt, nt, nmin):
    """Acceleration [m/s^2] of a fully-normalised spherical-harmonic field,
    degrees nmin .. max(nmax, nt), at body-fixed position (x, y, z) [m]; the
    result is in the same body-fixed frame.  Core of the other kernels.

    Parameters
    ----------
    x, y, z : float64, body-fixed position [m] (r >= radius for the series
        to converge; r > 0 required).
    gm : float64, gravitational parameter [m^3/s^2]; radius : float64,
        reference radius [m].
    C, S : 1-D float64, static coefficients, flat row-major views of
        (ldc, ldc) arrays: C_nm = C[n ldc + m].
    ldc : int, leading dimension of C, S (>= nmax + 1).
    nmax, mmax : int, highest degree and order of the static part used
        (nmax < 0: no static part; mmax is clipped to nmax).
    dC, dS : 1-D float64, corrections added to the static coefficients:
        flat row-major (ldt, ldt) arrays, dC_nm = dC[n ldt + m] (ldt > 0),
        or packed lower triangles, dC_nm = dC[n (n + 1)/2 + m] (ldt = 0).
    ldt : int, leading dimension of dC, dS (>= nt + 1), or 0 for the
        packed triangular layout.
    nt : int, highest degree of the corrections (nt < 0: none).
    nmin : int, lowest degree evaluated (0 includes the monopole C_00).

    Returns (ax, ay, az) float64 [m/s^2].  Raises ValueError if
    max(nmax, nt) > NMAX_SH.
    """
    if mmax > nmax:
        mmax = nmax
    ntot = nmax if nmax > nt else nt
    if ntot > NMAX_SH:
        raise ValueError("sh_accel: degree above NMAX_SH = 360")
    if nmin < 0:
        nmin = 0
    if ntot < nmin:
        return 0.0, 0.0, 0.0
    r2 = x * x + y * y + z * z
    rho = radius / r2  # R / r^2
    xr, yr, zr = x * rho, y * rho, z * rho
    rr = radius * rho  # R^2 / r^2
    # columns needed: order k of the harmonics runs to (highest order of a
    # non-zero coefficient) + 1; column k is needed up to degree jmax(k)
    kmax_static = mmax + 1 if nmax >= 0 else -1
    kmax_tide = nt + 1 if nt >= 0 else -1
    kmax = kmax_static if kmax_static > kmax_tide else kmax_tide
    ta, tb, tz, tm, tp, ck = _A, _B, _FZ, _FM, _FP, _CK
    ax, ay, az = 0.0, 0.0, 0.0
    vkk = radius / math.sqrt(r2)  # Vbar_00 = R / r
    wkk = 0.0
    for k in range(kmax + 1):
        if k >= 1:
            t = ck[np.uint64(k)]
            vkk, wkk = t * (xr * vkk - yr * wkk), t * (xr * wkk + yr * vkk)
        jmax = -1
        if k <= kmax_static:
            jmax = nmax + 1
        if k <= kmax_tide and nt + 1 > jmax:
            jmax = nt + 1
        if jmax > ntot + 1:
            jmax = ntot + 1
        # static coefficients of the orders k - 1, k, k + 1 present (degree permitting)
        st_m = k >= 1 and k - 1 <= mmax
        st_0 = k <= mmax
        st_p = k + 1 <= mmax
        v1, w1 = 0.0, 0.0  # Vbar, Wbar of degree j - 1 (order k)
        v, w = vkk, wkk  # degree j
        ib = (k * (k + 1)) // 2 + k  # index of (j, k) in the factor tables
        # rows j = k, k + 1 (not all three coefficients exist), the column
        # k = 1 (order-0 x, y terms) and the columns with only part of the
        # static orders k - 1 .. k + 1: general loop with every test; the
        # other rows: branch-free loops over the degree ranges with static +
        # correction, static only, correction only.  The order of the
        # operations is the same in all (results independent of the split).
        partial = k == 1 or (nmax >= 0 and (k == mmax or k == mmax + 1))
        jg = jmax + 1 if partial else k + 2
        if jg > jmax + 1:
            jg = jmax + 1
        for j in range(k, jg):
            if j > k:
                ib += j  # (j - 1, k) -> (j, k)
            if j <= _JT:
                u = np.uint64(ib)
                fa, fb, fz, fm, fp = ta[u], tb[u], tz[u], tm[u], tp[u]
            else:
                fa, fb, fz, fm, fp = _factors(j, k)
            if j > k:
                a = fa * zr
                b = fb * rr  # 0 at j = k + 1 (and v1 = w1 = 0)
                v1, w1, v, w = v, w, a * v - b * v1, a * w - b * w1
            n = j - 1
            if n < nmin:
                continue
            # coefficients (n, k - 1), (n, k), (n, k + 1) = static (n <= nmax,
            # m <= mmax) + correction (n <= nt), fetched inline: a helper
            # taking the arrays would increment/decrement their reference
            # counts on every call (8x slower); absent ones are 0 (as are
            # their factors in the tables)
            cm, sm, c0, s0, cp, sp = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            if n <= nmax:
                o = n * ldc + k
                if st_m:
                    cm, sm = C[np.uint64(o - 1)], S[np.uint64(o - 1)]
                if st_0 and n >= k:
                    c0, s0 = C[np.uint64(o)], S[np.uint64(o)]
                if st_p and n > k:
                    cp, sp = C[np.uint64(o + 1)], S[np.uint64(o + 1)]
            if n <= nt:
                o = (n * ldt if ldt > 0 else (n * (n + 1)) // 2) + k
                if k >= 1:
                    cm, sm = cm + dC[np.uint64(o - 1)], sm + dS[np.uint64(o - 1)]
                if n >= k:
                    c0, s0 = c0 + dC[np.uint64(o)], s0 + dS[np.uint64(o)]
                if n > k:
                    cp, sp = cp + dC[np.uint64(o + 1)], sp + dS[np.uint64(o + 1)]
            # (n, k): z component; (n, k - 1): the V_{n+1, m+1} terms of x and
            # y (order 0: no sine part); (n, k + 1): the V_{n+1, m-1} terms of
            # x and y.  Absent terms add exact zeros.
            az -= fz * (c0 * v + s0 * w)
            if k == 1:
                ax -= fm * cm * v
                ay -= fm * cm * w
            else:
                ax -= fm * (cm * v + sm * w)
                ay -= fm * (cm * w - sm * v)
            ax += fp * (cp * v + sp * w)
            ay += fp * (sp * v - cp * w)
        if partial:
            continue
        # rows j >= k + 2: all three orders exist; static rows n <= ns.
        # (All indices are >= 0; as unsigned integers they need no
        # negative-index wrap-around code: a quarter of the time at N = 12.)
        ns = nmax if st_p else -1
        # (1) below nmin: recursion only
        j0 = jg
        j1 = nmin + 1 if nmin + 1 < jmax + 1 else jmax + 1
        for j in range(j0, j1):
            ib += j
            fz, fm, fp, v1, w1, v, w = _advance(j, k, ib, zr, rr, v1, w1, v, w, ta, tb, tz, tm, tp)
        j0 = j1 if j1 > j0 else j0
        # (2) static + correction: n <= min(ns, nt)
        j1 = (ns if ns < nt else nt) + 2
        if j1 > jmax + 1:
            j1 = jmax + 1
        for j in range(j0, j1):
            ib += j
            fz, fm, fp, v1, w1, v, w = _advance(j, k, ib, zr, rr, v1, w1, v, w, ta, tb, tz, tm, tp)
            n = j - 1
            o = n * ldc + k
            to = (n * ldt if ldt > 0 else (n * (n + 1)) // 2) + k
            cm, sm = C[np.uint64(o - 1)] + dC[np.uint64(to - 1)], (S[np.uint64(o - 1)] + dS[np.uint64(to - 1)])
            c0, s0 = C[np.uint64(o)] + dC[np.uint64(to)], S[np.uint64(o)] + dS[np.uint64(to)]
            cp, sp = C[np.uint64(o + 1)] + dC[np.uint64(to + 1)], S[np.uint64(o + 1)] + dS[np.uint64(to + 1)]
            ax, ay, az = _accumulate(ax, ay, az, fz, fm, fp, v, w, cm, sm, c0, s0, cp, sp)
        j0 = j1 if j1 > j0 else j0
        # (3) the rest up to jmax: static only (ns > nt) or correction only
        if ns > nt:
            for j in range(j0, jmax + 1):
                ib += j
                fz, fm, fp, v1, w1, v, w = _advance(j, k, ib, zr, rr, v1, w1, v, w, ta, tb, tz, tm, tp)
                o = (j - 1) * ldc + k
                cm, sm = C[np.uint64(o - 1)], S[np.uint64(o - 1)]
                c0, s0 = C[np.uint64(o)], S[np.uint64(o)]
                cp, sp = C[np.uint64(o + 1)], S[np.uint64(o + 1)]
                ax, ay, az = _accumulate(ax, ay, az, fz, fm, fp, v, w, cm, sm, c0, s0, cp, sp)
        else:
            for j in range(j0, jmax + 1):
                ib += j
                fz, fm, fp, v1, w1, v, w = _advance(j, k, ib, zr, rr, v1, w1, v, w, ta, tb, tz, tm, tp)
                n = j - 1
                to = (n * ldt if ldt > 0 else (n * (n + 1)) // 2) + k
                cm, sm = dC[np.uint64(to - 1)], dS[np.uint64(to - 1)]
                c0, s0 = dC[np.uint64(to)], dS[np.uint64(to)]
                cp, sp = dC[np.uint64(to + 1)], dS[np.uint64(to + 1)]
                ax, ay, az = _accumulate(ax, ay, az, fz, fm, fp, v, w, cm, sm, c0, s0, cp, sp)
    scale = gm / (radius * radius)
    return scale * ax, scale * ay, scale * az


@inner_kernel
def sh_accel(x, y, z, gm, radius, C, S, nmax, nmin=2, mmax=-1):
    """Acceleration [m/s^2] of a fully-normalised spherical-harmonic field,
    degrees nmin .. nmax, orders 0 .. mmax, at body-fixed position (x, y, z)
    [m]; result in the same body-fixed frame.

    gm [m^3/s^2], radius [m] float64; C, S: (L, L) float64 C-contiguous
    arrays of the fully-normalised coefficients C[n, m], S[n, m] with
    L >= nmax + 1; nmax: highest degree; nmin: lowest degree (default 2:
    without the monopole; 0 includes it); mmax: highest order (-1 or
    >= nmax: all orders).  Returns (ax, ay, az) float64 [m/s^2].
    Raises ValueError if nmax >= L.
    """
    L = C.shape[0]
    if nmax >= L or C.shape[1] != L or S.shape[0] != L or S.shape[1] != L:
        raise ValueError("sh_accel: nmax above the degree of the coefficient arrays (or C, S not square)")
    if mmax < 0 or mmax > nmax:
        mmax = nmax
    Cf, Sf = C.reshape(L * L), S.reshape(L * L)
    # no corrections: empty views (not constant arrays, not constant sizes: the
    # types of the other kernels' calls, so that all share one compiled core)
    return sh_accel_flat(x, y, z, gm, radius, Cf, Sf, L, nmax, mmax, Cf[:0], Sf[:0], dynamic(1), dynamic(-1), nmin)


@njit(cache=True)
def sh_accel_delta(x, y, z, gm, radius, C, S, nmax, dC, dS, nt, nmin=2, mmax=-1, packed=False):
    """Acceleration [m/s^2] of the static field C, S (degrees nmin .. nmax,
    orders 0 .. mmax) plus time-variable corrections dC, dS (degrees
    nmin .. nt, all orders), at body-fixed position (x, y, z) [m]; result in
    the same body-fixed frame.

    C, S: (L, L) float64 as in :func:`sh_accel`; dC, dS: 1-D float64,
    fully-normalised corrections added to C, S without copying: views of
    (nt+1, nt+1) row-major arrays (dC_nm = dC[n (nt + 1) + m], e.g.
    ``dC2d.ravel()``) or, with packed=True, packed lower triangles
    (dC_nm = dC[n (n + 1)/2 + m]); nt: their degree (< 0: none).
    Returns (ax, ay, az) float64 [m/s^2].
    """
    L = C.shape[0]
    if nmax >= L or C.shape[1] != L or S.shape[0] != L or S.shape[1] != L:
        raise ValueError("sh_accel_delta: nmax above the degree of the coefficient arrays (or C, S not square)")
    size = (nt + 1) * (nt + 2) // 2 if packed else (nt + 1) * (nt + 1)
    if nt >= 0 and (dC.shape[0] < size or dS.shape[0] < size):
        raise ValueError("sh_accel_delta: dC, dS shorter than their degree nt needs")
    if mmax < 0 or mmax > nmax:
        mmax = nmax
    return sh_accel_flat(x, y, z, gm, radius, C.reshape(L * L), S.reshape(L * L), L, nmax, mmax,
                         dC, dS, 0 if packed else nt + 1, nt, nmin)


@njit(cache=True)
def sh_accel_corrections(x, y, z, gm, radius, dC, dS, nt, nmin=2, packed=False):
    """Acceleration [m/s^2] of the coefficient corrections alone (degrees
    nmin .. nt, all orders; e.g. one tide model's dC, dS) at body-fixed
    position (x, y, z) [m]; result in the same body-fixed frame.

    gm [m^3/s^2], radius [m]; dC, dS: 1-D float64 fully-normalised
    corrections, (nt+1, nt+1) row-major or (packed=True) packed lower
    triangles, as in :func:`sh_accel_delta`.  Returns (ax, ay, az).
    """
    size = (nt + 1) * (nt + 2) // 2 if packed else (nt + 1) * (nt + 1)
    if nt >= 0 and (dC.shape[0] < size or dS.shape[0] < size):
        raise ValueError("sh_accel_corrections: dC, dS shorter than their degree nt needs")
    return sh_accel_flat(x, y, z, gm, radius, dC[:0], dS[:0], dynamic(1), dynamic(-1), dynamic(-1), dC, dS,
                         0 if packed else nt + 1, nt, nmin)
