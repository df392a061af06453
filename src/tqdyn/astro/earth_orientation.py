"""Earth orientation: GCRS <-> ITRS with IAU 2006/2000A (CIO based) and IERS EOP.

The transformation (IERS Conventions 2010, TN36 ch. 5, eq. 5.1)::

    [GCRS] = Q(t) R(t) W(t) [ITRS]
    T_ITRS_GCRS = W^T R^T Q^T = R1(-y_p) R2(-x_p) R3(s') R3(ERA) R3(-s) M^T

with, in TN36's notation,

* Q = M(X, Y) R3(s): the CIP coordinates X, Y in the GCRS from the IAU 2006/2000A
  precession-nutation series (``erfa.xys06a``), plus the IERS celestial pole
  offsets dX, dY of the EOP series, and the CIO locator s (``erfa.xys06a``);
  M = [[1-aX^2, -aXY, X], [-aXY, 1-aY^2, Y], [-X, -Y, 1-a(X^2+Y^2)]],
  a = 1/(1 + sqrt(1 - X^2 - Y^2)) (TN36 eq. 5.10);
* R = R3(-ERA): Earth rotation angle of UT1 (IAU 2000, ``erfa.era00``);
* W = R3(-s') R2(x_p) R1(y_p): polar motion (C04 x_p, y_p plus, by default,
  the IERS sub-daily ocean-tide and libration terms, see :mod:`tqdyn.astro.eop`)
  and the TIO locator s' = -47 uas t (TN36 eq. 5.13, as ``erfa.sp00``).

R1, R2, R3 are the usual frame rotations (R3(a) = [[cos a, sin a, 0],
[-sin a, cos a, 0], [0, 0, 1]]), as in SOFA/ERFA, so the product equals
``erfa.c2tcio(erfa.c2ixys(X + dX, Y + dY, s), era, erfa.pom00(xp, yp, sp))``.
Here the closed form above, the ERA (TN36 eq. 5.15) and the IAU 2006 GMST
(TN36 eq. 5.32) are evaluated in one compiled loop; ``tests/test_frames.py``
compares them with that ERFA composition, with ``erfa.c2t06a``,
``erfa.era00`` and ``erfa.gmst06`` evaluated independently at every instant.

Time scales (input: t = t_hi + t_lo s of TT after a scenario :class:`Epoch`,
the geocentric time axis of tqdyn): TT = TT(epoch) + t; TAI = TT - 32.184 s;
UT1 = TAI + (UT1-TAI) with UT1-TAI interpolated from the EOP table
(:mod:`tqdyn.astro.eop`, sources :mod:`tqdyn.astro.eop_sources`) at the instant's UTC (TAI - (TAI-UTC) from ERFA's
leap-second table, ERFA's quasi-JD on leap-second days) -- the same UT1 as
ERFA's chain ``tttai`` -> ``taiutc`` -> ``utcut1`` with the interpolated
UT1-UTC (checked in the tests).  Two-part Julian dates keep jd1 on the half
day (the epoch's jd1 plus whole days) and jd2 within half a day (ulp 2.4 ps).

Speed: the slow series (``erfa.xys06a``: X, Y, s; the sub-daily EOP terms) are evaluated on a uniform grid of step 1 h in t (nodes
t = k h, anchored at the epoch, covering the request plus 5 h margins) and
interpolated to the instants with 8-point (degree-7) Lagrange interpolation;
everything else (EOP interpolation, ERA, GMST, s', the matrix) is evaluated
at every instant.  Interpolation error against direct ERFA evaluation at every
instant (measured over 2004-2006): < 4e-16 rad in X, Y, s (ERFA's own
evaluation noise); the whole matrix agrees with the
ERFA composition to < 1e-12 rad.  Cost per chunk of 53,248 instants:
measured by ``tqdyn bench --model kernels``.  The last few results are memoised
(keyed by the epoch, the options and the exact bytes of t_hi, t_lo), because
several force terms ask for the same chunk; returned arrays are read-only.
"""

from __future__ import annotations

import math
import threading
import warnings
from collections import OrderedDict
from dataclasses import dataclass

import erfa
import numpy as np
from numba import njit

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache, before any @njit)
from ..numerics.dd import add, mul, to_f64, two_prod
from ..numerics.lagrange import MARGIN, POINTS, grid_interp
from ..readers.iers_tables import load_tidal_eop_terms
from .eop import EOP, tidal_arguments, tidal_eop_corrections
from .eop_sources import DEFAULT_EOP_SOURCE, eop_table
from .timescales import Epoch, tt_jd

__all__ = ["GRID_POINTS", "GRID_STEP_S", "EarthOrientation", "earth_orientation", "gcrs_to_itrs", "itrs_to_gcrs"]

#: Grid step [s] of the tabulated slow quantities (X, Y, s, sub-daily EOP terms).
GRID_STEP_S = 3600.0
#: Number of points of the Lagrange interpolation on that grid (degree 7).
GRID_POINTS = POINTS

_TT_TAI_S = 32.184
_DAY = 86400.0
_MJD0 = 2400000.5
_MEMO_SIZE = 4


@dataclass(frozen=True, eq=False)
class EarthOrientation:
    """Earth orientation at a set of instants (arrays of the request's shape ``...``).

    T_ITRS_GCRS : (..., 3, 3) float64
        Rotation GCRS -> ITRS: ``v_itrs = T_ITRS_GCRS @ v_gcrs``
        (= W^T R3(ERA) Q^T, IAU 2006/2000A, CIO based, X, Y + dX, dY).
        Its transpose maps ITRS into GCRS (:attr:`T_GCRS_ITRS`).
    era : (...) rad -- Earth rotation angle (IAU 2000) of UT1, in [0, 2 pi).
    gmst : (...) rad -- Greenwich mean sidereal time, IAU 2006 (``erfa.gmst06``), [0, 2 pi).
    tt, ut1 : tuple (jd1, jd2) of (...) float64 -- two-part Julian dates [d] of TT and UT1.
    xp, yp : (...) rad -- polar motion used (C04 interpolated, plus the
        sub-daily terms if requested; zero without EOP).
    dut1 : (...) s -- UT1-UTC used.
    All arrays are read-only.
    """

    T_ITRS_GCRS: np.ndarray
    era: np.ndarray
    gmst: np.ndarray
    tt: tuple
    ut1: tuple
    xp: np.ndarray
    yp: np.ndarray
    dut1: np.ndarray

    @property
    def T_GCRS_ITRS(self) -> np.ndarray:
        """(..., 3, 3) rotation ITRS -> GCRS (transpose of :attr:`T_ITRS_GCRS`)."""
        return np.swapaxes(self.T_ITRS_GCRS, -1, -2)


# ----------------------------------------------------------------------
# the slow quantities on a uniform grid


def _grid_nodes(epoch: Epoch, k: np.ndarray, eop: EOP | None, tides) -> np.ndarray:
    """Slow quantities at grid nodes t = k h [s TT since the epoch]: columns
    X, Y, s [rad] and, with tides, dx_p, dy_p [rad], dUT1 [s] of the sub-daily
    EOP terms."""
    t = k.astype(np.float64) * GRID_STEP_S
    d1, tt2 = tt_jd(epoch, t, 0.0)
    x, y, s = erfa.xys06a(d1, tt2)
    cols = [x, y, s]
    if tides is not None and eop is not None:
        # UT1 at the nodes for GMST (nodes in the margins may lie just outside
        # the EOP span: clamped there, which moves gamma by < 1e-6 rad)
        mjd_tai = (d1 - _MJD0) + (tt2 - _TT_TAI_S / _DAY)
        lo, hi = eop.span_mjd
        mjd_utc = np.clip(eop.mjd_utc_from_tai(mjd_tai), lo, hi)
        ut1_tai = eop._interp_columns(mjd_utc, check=False)[:, 2]
        ut2 = tt2 + (ut1_tai - _TT_TAI_S) / _DAY
        args = tidal_arguments((d1, ut2), (d1, tt2))
        cols.extend(tidal_eop_corrections(args, tides))
    return np.ascontiguousarray(np.stack(cols, axis=1))


def _utc_minus_tai(jd1: np.ndarray, tt2: np.ndarray) -> np.ndarray:
    """UTC - TAI [s] at TT instants (jd1, tt2), ERFA's leap-second table (no EOP)."""
    tai1, tai2 = erfa.tttai(jd1, tt2)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=erfa.ErfaWarning, message=".*dubious year.*")
        u1, u2 = erfa.taiutc(tai1, tai2)
    return ((u1 - tai1) + (u2 - tai2)) * _DAY


def _interp_grid(t_hi: np.ndarray, t_lo: np.ndarray, epoch, eop, tides) -> np.ndarray:
    """Slow quantities of :func:`_grid_nodes` interpolated to t = t_hi + t_lo (1-D)."""
    u = t_hi / GRID_STEP_S + t_lo / GRID_STEP_S
    k0 = int(math.floor(u.min())) - MARGIN
    k1 = int(math.floor(u.max())) + MARGIN + 1
    vals = _grid_nodes(epoch, np.arange(k0, k1, dtype=np.int64), eop, tides)
    out = np.empty((u.size, vals.shape[1]))
    grid_interp(u, k0, vals, out)
    return out


# ----------------------------------------------------------------------
# the rotation matrix and the angles

_D2PI = 2.0 * math.pi
_D2PI_LO = 2.4492935982947064e-16  # 2 pi - _D2PI
#: TN36 eq. 5.15's decimals 0.00273781191135448 and 0.7790572732640 as dd pairs (hi + lo).
_ERA_RATE = (0.00273781191135448, 1.1969606404306886e-19)
_ERA_0 = (0.779057273264, 1.6884986507648136e-17)
_DJ00 = 2451545.0
_DAS2R = math.pi / 648000.0


@njit(cache=True)
def _anp(a):
    w = np.fmod(a, _D2PI)
    if w < 0.0:
        w += _D2PI
    return w


@njit(cache=True)
def _orientation_kernel(jd1, ut2, tt2, X, Y, s, xp, yp, T, era_out, gmst_out):
    """Per instant: ERA (IAU 2000), GMST (IAU 2006), s' (IAU 2000) and
    T_ITRS_GCRS = R1(-yp) R2(-xp) R3(ERA + s' - s) M(X, Y)^T (TN36 eqs 5.1, 5.10)."""
    for i in range(X.size):
        # Earth rotation angle, IAU 2000 (TN36 eq. 5.15), in turns summed in dd: ERFA's float64
        # sum (~34 turns in 2034, tu rounded to 1.6e-7 s) rounds to ~4e-14 rad, a non-smooth
        # function of time; here only the final rounding of the angle (< 4.4e-16 rad) is left
        d1, d2 = ut2[i], jd1[i]
        if d1 > d2:
            d1, d2 = d2, d1
        a = d2 - _DJ00  # exact (half-integer days)
        p, pe = two_prod(_ERA_RATE[0], a)
        p -= math.floor(p)  # exact
        q, qe = two_prod(_ERA_RATE[0], d1)
        turns = add(add(add((p, pe + _ERA_RATE[1] * a), (q, qe + _ERA_RATE[1] * d1)), np.fmod(d1, 1.0)),
                    np.fmod(d2, 1.0))
        turns = add(turns, _ERA_0)
        w = math.floor(turns[0])
        turns = add((turns[0] - w, 0.0), turns[1])  # turns[0] - w: exact
        era = _anp(to_f64(mul(turns, (_D2PI, _D2PI_LO))))
        # GMST, IAU 2006 (TN36 eq. 5.32), t in TT Julian centuries
        t = ((jd1[i] - _DJ00) + tt2[i]) / 36525.0
        poly = -0.000029956 + (-0.0000000368) * t
        poly = 0.014506 + (4612.156534 + (1.3915817 + (-0.00000044 + poly * t) * t) * t) * t
        gm = era + poly * _DAS2R
        era_out[i] = era
        gmst_out[i] = _anp(gm)
        sp = -47e-6 * t * _DAS2R  # TIO locator s' (TN36 eq. 5.13)
        x, y = X[i], Y[i]
        x2, y2 = x * x, y * y
        a = 1.0 / (1.0 + math.sqrt(1.0 - x2 - y2))
        axy = -a * x * y
        m00, m01, m02 = 1.0 - a * x2, axy, -x
        m10, m11, m12 = axy, 1.0 - a * y2, -y
        m20, m21, m22 = x, y, 1.0 - a * (x2 + y2)
        phi = era + (sp - s[i])
        c, sn = math.cos(phi), math.sin(phi)
        a00, a01, a02 = c * m00 + sn * m10, c * m01 + sn * m11, c * m02 + sn * m12
        a10, a11, a12 = c * m10 - sn * m00, c * m11 - sn * m01, c * m12 - sn * m02
        cx, sx = math.cos(xp[i]), math.sin(xp[i])
        cy, sy = math.cos(yp[i]), math.sin(yp[i])
        b20, b21, b22 = cx * m20 - sx * a00, cx * m21 - sx * a01, cx * m22 - sx * a02
        T[i, 0, 0] = cx * a00 + sx * m20
        T[i, 0, 1] = cx * a01 + sx * m21
        T[i, 0, 2] = cx * a02 + sx * m22
        T[i, 1, 0] = cy * a10 - sy * b20
        T[i, 1, 1] = cy * a11 - sy * b21
        T[i, 1, 2] = cy * a12 - sy * b22
        T[i, 2, 0] = sy * a10 + cy * b20
        T[i, 2, 1] = sy * a11 + cy * b21
        T[i, 2, 2] = sy * a12 + cy * b22


def _compute(epoch: Epoch, t_hi: np.ndarray, t_lo: np.ndarray, eop: EOP | None, tides) -> EarthOrientation:
    shape = t_hi.shape
    th, tl = t_hi.ravel(), t_lo.ravel()
    n = th.size
    if n == 0:
        z = np.zeros(shape)
        return EarthOrientation(np.zeros(shape + (3, 3)), z, z, (z, z), (z, z), z, z, z)
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(tl))):
        raise ValueError("earth_orientation: non-finite time in t_hi/t_lo")
    jd1, tt2 = tt_jd(epoch, th, tl)
    if eop is not None:
        # span check first, before any grid work
        mjd_tai = (jd1 - _MJD0) + (tt2 - _TT_TAI_S / _DAY)
        eop._check_span(eop.mjd_utc_from_tai(np.array([mjd_tai.min(), mjd_tai.max()])))
    if eop is None:
        tides = None
    g = _interp_grid(th, tl, epoch, eop, tides)
    X, Y, s = g[:, 0], g[:, 1], g[:, 2]
    if eop is not None:
        mjd_tai = (jd1 - _MJD0) + (tt2 - _TT_TAI_S / _DAY)
        mjd_utc = eop.mjd_utc_from_tai(mjd_tai)
        e = eop._interp_columns(mjd_utc)  # xp, yp, UT1-TAI, lod, dx, dy; checks the span
        xp, yp, ut1_tai = e[:, 0].copy(), e[:, 1].copy(), e[:, 2].copy()
        X = X + e[:, 4]
        Y = Y + e[:, 5]
        utc_tai = -eop.tai_minus_utc(mjd_utc)
    else:
        xp = np.zeros(n)
        yp = np.zeros(n)
        utc_tai = _utc_minus_tai(jd1, tt2)
        ut1_tai = utc_tai.copy()  # UT1 = UTC
    if tides is not None:
        xp += g[:, 3]
        yp += g[:, 4]
        ut1_tai += g[:, 5]
    ut2 = tt2 + (ut1_tai - _TT_TAI_S) / _DAY
    T = np.empty((n, 3, 3))
    era = np.empty(n)
    gmst = np.empty(n)
    _orientation_kernel(jd1, ut2, tt2, np.ascontiguousarray(X), np.ascontiguousarray(Y), np.ascontiguousarray(s),
                        xp, yp, T, era, gmst)
    dut1 = ut1_tai - utc_tai

    def ro(a, extra=()):
        a = a.reshape(shape + extra)
        a.setflags(write=False)
        return a

    return EarthOrientation(ro(T, (3, 3)), ro(era), ro(gmst), (ro(jd1), ro(tt2)), (ro(jd1.copy()), ro(ut2)),
                            ro(xp), ro(yp), ro(dut1))


_memo: OrderedDict = OrderedDict()
_memo_lock = threading.Lock()


def earth_orientation(epoch: Epoch, t_hi, t_lo=0.0, eop: EOP | None = None, *, use_eop: bool = True,
                      tidal_eop: bool = True) -> EarthOrientation:
    """GCRS -> ITRS rotation and Earth rotation angles at t = t_hi + t_lo s of TT after ``epoch``.

    Parameters
    ----------
    epoch : :class:`tqdyn.astro.timescales.Epoch` -- the scenario epoch.
    t_hi, t_lo : float or array_like [s] -- TT seconds since the epoch as a
        double-double (broadcast together; ``t_lo`` may be 0).
    eop : :class:`tqdyn.astro.eop.EOP` or None -- EOP table (default: the
        table of the default source "auto", :func:`tqdyn.astro.eop_sources.eop_table`:
        IERS EOP 20 C04, finals2000A measured and predicted values, then the
        long-term model; the shipped 14 C04 series is ``eop_table("c04-14")``).
    use_eop : bool -- False: no EOP at all (x_p = y_p = dX = dY = 0, UT1 =
        UTC); for quick looks and for dates outside the EOP table.
    tidal_eop : bool -- add the IERS 2010 sub-daily ocean-tide terms
        (x_p, y_p, UT1; TN36 Tables 8.2, 8.3, as in interp.f) and the
        polar-motion libration terms (Table 5.1a, as in PMSDNUT2) to the
        interpolated C04 values, as the IERS Conventions prescribe (default
        True; they change T_ITRS_GCRS by up to ~5e-9 rad; tested against the
        IERS test cases in tests/test_eop.py).  Ignored when use_eop is False.

    Returns
    -------
    :class:`EarthOrientation` with arrays of the broadcast shape of t_hi, t_lo
    (``T_ITRS_GCRS`` (..., 3, 3)).  Results for the last few distinct
    requests are memoised; the arrays are read-only.

    Raises ``ValueError`` if an instant falls outside the EOP table's span
    (message names the date and the span) or a time is not finite.
    """
    th = np.asarray(t_hi, dtype=np.float64)
    tl = np.asarray(t_lo, dtype=np.float64)
    th, tl = np.broadcast_arrays(th, tl)
    th = np.array(th, dtype=np.float64, order="C")  # own contiguous copies (keeps 0-d shape)
    tl = np.array(tl, dtype=np.float64, order="C")
    if use_eop and eop is None:
        eop = eop_table(DEFAULT_EOP_SOURCE)
    if not use_eop:
        eop = None
    tidal_eop = bool(tidal_eop) and eop is not None
    key = (epoch, id(eop), bool(use_eop), tidal_eop, th.shape, hash(th.tobytes()), hash(tl.tobytes()))
    with _memo_lock:
        hit = _memo.get(key)
        if hit is not None and hit[0] is eop and np.array_equal(hit[1], th) and np.array_equal(hit[2], tl):
            _memo.move_to_end(key)
            return hit[3]
    tides = load_tidal_eop_terms() if (tidal_eop and eop is not None) else None
    res = _compute(epoch, th, tl, eop, tides)
    with _memo_lock:
        _memo[key] = (eop, th.copy(), tl.copy(), res)
        while len(_memo) > _MEMO_SIZE:
            _memo.popitem(last=False)
    return res


def gcrs_to_itrs(epoch: Epoch, t_hi, t_lo=0.0, eop: EOP | None = None, *, use_eop: bool = True,
                 tidal_eop: bool = True) -> np.ndarray:
    """T_ITRS_GCRS (..., 3, 3): rotation of GCRS vectors into the ITRS at t = t_hi + t_lo
    [s TT since ``epoch``]; see :func:`earth_orientation` (same options, read-only array)."""
    return earth_orientation(epoch, t_hi, t_lo, eop, use_eop=use_eop, tidal_eop=tidal_eop).T_ITRS_GCRS


def itrs_to_gcrs(epoch: Epoch, t_hi, t_lo=0.0, eop: EOP | None = None, *, use_eop: bool = True,
                 tidal_eop: bool = True) -> np.ndarray:
    """T_GCRS_ITRS (..., 3, 3): rotation of ITRS vectors into the GCRS (transpose of
    :func:`gcrs_to_itrs`)."""
    return earth_orientation(epoch, t_hi, t_lo, eop, use_eop=use_eop, tidal_eop=tidal_eop).T_GCRS_ITRS
