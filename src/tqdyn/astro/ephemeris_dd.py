"""Geocentric positions from a JPL ephemeris in double-double: smooth
functions of time.

The float64 evaluation of :mod:`tqdyn.astro.ephemeris` rounds the time
argument (the normalised Chebyshev time s ~ 1e-16 of a 4 .. 32 day record:
~1e-10 s, i.e. ~1e-6 m of the Earth-Moon barycentre moving at 3e4 m/s), the
recurrence, the sums and the final positions (ulp 3e-5 m at the Sun's 1.4e11
m, 6e-8 m at the Moon's 3.8e8 m).  None of these roundings is a smooth
function of time: a force that takes such positions as inputs carries a
white noise of their size times the tidal gradient (~2e-21 m/s^2 per
evaluation for a TianQin orbit, docs/precision.md), and two integrators that
sample it at other instants drift apart.

Here the same SPK coefficients (exact float64 numbers) are summed by
Clenshaw's recurrence in double-double (:mod:`tqdyn.numerics.dd`, relative
error ~1e-31 of the sum of the terms' magnitudes) at a double-double time
argument (TDB seconds past J2000), and the segment states are summed in
double-double: a 1.4e11 m position is held to ~1e-20 m.  Positions only
(the third-body terms need no velocity).  Compiled with numba, vectorised
over instants; about 10x the float64 evaluation's cost per segment.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..numerics.dd import add, div, mul, np_dd_add, np_dd_add_d, np_two_prod, sub
from .constants import DAY_S, J2000_JD

__all__ = ["chain_positions_dd", "tdb_seconds_dd"]

_KM = 1000.0
_J2000 = float(J2000_JD)
_DAY = float(DAY_S)


@njit(cache=True)
def _cheb_pos_dd(coef, init, intlen, th, tl, sel, out, ob, base, bb, bsign):
    """Positions of one SPK Chebyshev segment at many dd instants, plus a base.

    coef: (n_rec, n_comp, n_coef) float64 coefficients [km] (components 0..2:
    position); init [s TDB past J2000], intlen [s]; th, tl: (n,) TDB seconds
    past J2000, hi and lo of a dd number, inside the segment (checked by the
    caller); sel: (m,) int64 instants to evaluate (empty: all n).  For each
    selected instant i and component c, as a dd number stored in [..., 0]
    (hi) and [..., 1] (lo):

        out[i, ob, c] = position [m] + bsign * base[i, bb, c]

    out, base: (n, *, 3, 2) float64; bsign: +1, -1 or 0 (no base).
    """
    n_rec, _, n_coef = coef.shape
    use_sel = sel.shape[0] > 0
    n = sel.shape[0] if use_sel else th.shape[0]
    for m in range(n):
        i = sel[m] if use_sel else m
        a = sub((th[i], tl[i]), init)
        k = int(math.floor((a[0] + a[1]) / intlen))
        if k >= n_rec:  # the end point belongs to the last record
            k = n_rec - 1
        if k < 0:
            k = 0
        off = sub(a, k * intlen)  # k intlen: exact (integer seconds)
        s = sub(mul(div(off, intlen), 2.0), 1.0)
        s2 = mul(s, 2.0)
        for c in range(3):
            # Clenshaw: b_j = 2 s b_{j+1} - b_{j+2} + c_j; sum = s b_1 - b_2 + c_0
            b1 = (0.0, 0.0)
            b2 = (0.0, 0.0)
            for j in range(n_coef - 1, 0, -1):
                b0 = add(sub(mul(s2, b1), b2), coef[k, c, j])
                b2 = b1
                b1 = b0
            p = mul(add(sub(mul(s, b1), b2), coef[k, c, 0]), _KM)
            if bsign != 0.0:
                p = add(p, (bsign * base[i, bb, c, 0], bsign * base[i, bb, c, 1]))
            out[i, ob, c, 0] = p[0]
            out[i, ob, c, 1] = p[1]


_ALL = np.zeros(0, dtype=np.int64)


def _pair_eval(pair, th, tl, out, ob, base, bb, bsign) -> None:
    """Evaluate every instant in the segment of ``pair`` (an ephemeris
    ``_Pair``) that covers it (the last listed wins on overlaps)."""
    if len(pair.segments) == 1:
        coef, init, intlen = pair.segments[0].load()
        _cheb_pos_dd(coef, init, intlen, th, tl, _ALL, out, ob, base, bb, bsign)
        return
    t = (th + tl) / _DAY  # days past J2000 (segment choice only)
    todo = np.ones(th.shape[0], dtype=bool)
    for seg in reversed(pair.segments):
        m = todo & (t >= seg.start_jd - _J2000) & (t <= seg.end_jd - _J2000)
        sel = np.flatnonzero(m).astype(np.int64)
        if sel.size:
            coef, init, intlen = seg.load()
            _cheb_pos_dd(coef, init, intlen, th, tl, sel, out, ob, base, bb, bsign)
            todo &= ~m


def chain_positions_dd(base_ops, ops, th, tl):
    """Sums of segment positions in dd at the dd instants th + tl ((n,)
    float64 each, TDB seconds past J2000, inside the segments' span).

    base_ops, ops: sequences of (pair, row, base_row, sign) with ``pair`` an
    ephemeris ``_Pair`` (its ``segments`` with ``load()``, ``start_jd``,
    ``end_jd``): base_ops fill the scratch rows base[:, row] (2 rows) in
    order, ops the output rows out[:, row] = pair + sign * base[:, base_row]
    (the chains of :class:`tqdyn.astro.ephemeris.Ephemeris`).  Returns (hi,
    lo), each (n, len(ops), 3) float64 [m]."""
    n = th.shape[0]
    out = np.empty((n, len(ops), 3, 2))
    base = np.zeros((n, 2, 3, 2))
    for pair, row, brow, sign in base_ops:
        _pair_eval(pair, th, tl, base, row, base, brow, sign)
    for pair, row, brow, sign in ops:
        _pair_eval(pair, th, tl, out, row, base, brow, sign)
    return out[..., 0], out[..., 1]


def tdb_seconds_dd(epoch, t_hi, t_lo, tdb_minus_tt):
    """TDB seconds past J2000 (JD 2451545.0 TDB) of the TT instants t_hi +
    t_lo [s since ``epoch``'s TT] as a dd pair (hi, lo) of float64 arrays
    (broadcast shape): the epoch's two-part TT date times 86400 (exact
    products), plus t, plus ``tdb_minus_tt`` [s] (float64 array of that
    shape: TDB - TT at the geocentre, a smooth function of time), summed in
    dd.  Resolution ~1e-23 s on a 1e9 s argument."""
    e1, e2 = (float(x) for x in epoch.tt)
    a, ae = np_two_prod(np.float64(e1 - _J2000), np.float64(_DAY))  # e1 - J2000 is exact
    b, be = np_two_prod(np.float64(e2), np.float64(_DAY))
    h, lo = np_dd_add(a, ae, b, be)
    t_hi = np.asarray(t_hi, dtype=np.float64)
    t_lo = np.asarray(t_lo, dtype=np.float64)
    t_hi, t_lo = np.broadcast_arrays(t_hi, t_lo)
    h, lo = np_dd_add(np.full(t_hi.shape, h), np.full(t_hi.shape, lo), t_hi, t_lo)
    return np_dd_add_d(h, lo, np.asarray(tdb_minus_tt, dtype=np.float64))
