"""Tidal arguments: Delaunay (fundamental) arguments, Greenwich mean sidereal
time, Doodson arguments and the phase theta_f of a tidal constituent
(IERS Conventions 2010 = TN36, sec. 5.7 eq. 5.43, sec. 6.2 eq. 6.8, sec. 6.3).

Conventions (TN36 sec. 6.2.1, after eq. 6.8e; the same arguments serve the
solid-tide step 2 and the ocean tides of sec. 6.3):

* Delaunay arguments F = (l, l', F, D, Omega) [rad] at TT (IERS 2003/2010
  eq. 5.43, Simon et al. 1994): the pyerfa routines ``fal03``, ``falp03``,
  ``faf03``, ``fad03``, ``faom03``, argument t = TT Julian centuries since
  J2000.0.  TDB may be passed instead of TT: |TDB - TT| < 2 ms moves the
  fastest argument (l, 2.6e-6 rad/s) by < 6e-9 rad.
* theta_g: Greenwich mean sidereal time as an angle (IAU 2006,
  ``erfa.gmst06``: UT1 and TT) [rad].
* Doodson arguments beta = (tau, s, h, p, N', p_s) [rad]:

      s   = F + Omega                  Moon's mean longitude
      h   = s - D                      Sun's mean longitude
      p   = s - l                      longitude of the Moon's mean perigee
      N'  = -Omega                     minus the longitude of the Moon's node
      p_s = s - D - l'                 longitude of the Sun's mean perigee
      tau = theta_g + pi - s           mean lunar time (from lower transit)

* A constituent f with Doodson number ``A B C . D E F`` has multipliers
  n = (A, B-5, C-5, D-5, E-5, F-5) and phase

      theta_f = n . beta = n_1 (theta_g + pi) - N . F           (TN36 eq. 6.8d/e)

  with Delaunay multipliers N = (n_4, n_6, n_1 - n_2 - n_3 - n_4 - n_6,
  n_3 + n_6, n_1 - n_2 - n_3 - n_4 + n_5 - n_6)
  (:func:`delaunay_multipliers`; the columns "l l' F D Omega" of TN36
  Tables 6.5a-c).

All angles are radians; they are *not* reduced to [0, 2 pi) unless stated
(the phases are only ever used through cos and sin).  Everything is
vectorised over leading array axes.

Speed: :func:`tidal_cos_sin` gives cos and sin of many phases at many
instants from 12 trigonometric calls per instant (the six exp(i beta_k) and
their integer powers, multiplied together in a compiled loop) instead of two
per (instant, constituent): faster than numpy's cos/sin for the 71
step-2 constituents, and exact to ~1e-15 (a few ulp per multiplication).
"""

from __future__ import annotations

import math

import erfa
import numpy as np
from numba import njit

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..readers.doodson import delaunay_multipliers, doodson_multipliers
from .constants import J2000_JD

__all__ = [
    "DAYS_PER_JULIAN_CENTURY",
    "delaunay_arguments",
    "delaunay_multipliers",
    "doodson_arguments",
    "doodson_multipliers",
    "greenwich_mean_sidereal_time",
    "julian_centuries",
    "tidal_cos_sin",
    "tidal_harmonic_sum",
    "tidal_phase",
]

#: Days per Julian century [d] (exact, IAU).
DAYS_PER_JULIAN_CENTURY = 36525.0



def julian_centuries(jd1, jd2) -> np.ndarray:
    """Julian centuries since J2000.0 of the two-part Julian date (jd1, jd2)
    [d] (any time scale; TT or TDB for the tidal arguments).  Returns float64
    with the broadcast shape of jd1, jd2.  The large part is differenced
    first: ((jd1 - 2451545) + jd2) / 36525."""
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    return ((jd1 - float(J2000_JD)) + jd2) / DAYS_PER_JULIAN_CENTURY


def delaunay_arguments(tt1, tt2) -> np.ndarray:
    """The five fundamental (Delaunay) arguments of nutation theory.

    tt1, tt2: two-part TT Julian date [d] (TDB is as good, see the module
    docstring), arrays broadcast to shape S.
    Returns float64 S + (5,): (l, l', F, D, Omega) [rad], IERS 2010 eq. 5.43
    (pyerfa ``fal03``, ``falp03``, ``faf03``, ``fad03``, ``faom03``; each
    reduced to (-2 pi, 2 pi) by ERFA).
    """
    t = julian_centuries(tt1, tt2)
    out = np.empty(t.shape + (5,))
    out[..., 0] = erfa.fal03(t)
    out[..., 1] = erfa.falp03(t)
    out[..., 2] = erfa.faf03(t)
    out[..., 3] = erfa.fad03(t)
    out[..., 4] = erfa.faom03(t)
    return out


def greenwich_mean_sidereal_time(ut1, tt) -> np.ndarray:
    """theta_g: Greenwich mean sidereal time (IAU 2006, ``erfa.gmst06``) [rad]
    in [0, 2 pi).  ut1, tt: two-part Julian dates (jd1, jd2) [d] in UT1 and TT
    (arrays broadcast to shape S); returns float64 S."""
    return np.asarray(erfa.gmst06(ut1[0], ut1[1], tt[0], tt[1]), dtype=np.float64)


def doodson_arguments(theta_g, delaunay) -> np.ndarray:
    """Doodson arguments beta = (tau, s, h, p, N', p_s) [rad] (TN36 sec. 6.2).

    theta_g: Greenwich mean sidereal time [rad], shape S; delaunay: S + (5,)
    (l, l', F, D, Omega) [rad] from :func:`delaunay_arguments` at the same
    instants.  Returns float64 S + (6,).
    """
    theta_g = np.asarray(theta_g, dtype=np.float64)
    fa = np.asarray(delaunay, dtype=np.float64)
    l, lp, f, d, om = fa[..., 0], fa[..., 1], fa[..., 2], fa[..., 3], fa[..., 4]
    out = np.empty(np.broadcast_shapes(theta_g.shape, l.shape) + (6,))
    s = f + om
    out[..., 1] = s
    out[..., 0] = (theta_g + math.pi) - s
    out[..., 2] = s - d
    out[..., 3] = s - l
    out[..., 4] = -om
    out[..., 5] = (s - d) - lp
    return out


def tidal_phase(beta, multipliers) -> np.ndarray:
    """Phases theta_f = n_f . beta [rad] of tidal constituents.

    beta: S + (6,) Doodson arguments [rad] (:func:`doodson_arguments`);
    multipliers: (6,) or (n_f, 6) integer Doodson multipliers, or a Doodson
    number (str, e.g. ``"255.555"``) or a list of them.
    Returns float64 S (one constituent) or S + (n_f,); not reduced mod 2 pi.
    """
    beta = np.asarray(beta, dtype=np.float64)
    if isinstance(multipliers, str):
        multipliers = doodson_multipliers(multipliers)
    elif len(multipliers) and isinstance(multipliers[0], str):
        multipliers = [doodson_multipliers(x) for x in multipliers]
    mult = np.asarray(multipliers, dtype=np.float64)
    if mult.ndim == 1:
        return beta @ mult
    return beta @ mult.T


@njit(cache=True)
def _exp_powers(beta_row, pmax, pr, pi_):
    """pr[k, pmax + p] + i pi_[k, pmax + p] = exp(i p beta_row[k]) for
    p = -pmax..pmax (by repeated multiplication; negative p by conjugation)."""
    for k in range(6):
        c = math.cos(beta_row[k])
        s = math.sin(beta_row[k])
        pr[k, pmax] = 1.0
        pi_[k, pmax] = 0.0
        for p in range(1, pmax + 1):
            a, b = pr[k, pmax + p - 1], pi_[k, pmax + p - 1]
            pr[k, pmax + p] = a * c - b * s
            pi_[k, pmax + p] = a * s + b * c
            pr[k, pmax - p] = pr[k, pmax + p]  # exp(-i p beta) = conj(exp(i p beta))
            pi_[k, pmax - p] = -pi_[k, pmax + p]


@njit(cache=True)
def _phase(pr, pi_, pmax, mult, f):
    """(cos, sin) of theta_f = sum_k mult[f, k] beta_k from the powers of
    exp(i beta_k) tabulated by :func:`_exp_powers`."""
    re, im = 1.0, 0.0
    for k in range(6):
        m = mult[f, k]
        if m != 0:
            a, b = pr[k, pmax + m], pi_[k, pmax + m]
            re, im = re * a - im * b, re * b + im * a
    return re, im


@njit(cache=True)
def _cos_sin_kernel(beta, mult, pmax, cos_out, sin_out):
    """cos/sin of theta[i, f] = sum_k mult[f, k] beta[i, k] via powers of
    exp(i beta[i, k]).  beta (n, 6), mult (n_f, 6) int64 with |entries| <=
    pmax; cos_out, sin_out (n, n_f)."""
    n = beta.shape[0]
    nf = mult.shape[0]
    width = 2 * pmax + 1
    pr = np.empty((6, width))
    pi_ = np.empty((6, width))
    for i in range(n):
        _exp_powers(beta[i], pmax, pr, pi_)
        for f in range(nf):
            re, im = _phase(pr, pi_, pmax, mult, f)
            cos_out[i, f] = re
            sin_out[i, f] = im


def tidal_cos_sin(beta, multipliers) -> tuple[np.ndarray, np.ndarray]:
    """cos(theta_f) and sin(theta_f) of tidal phases theta_f = n_f . beta.

    beta: S + (6,) Doodson arguments [rad]; multipliers: (n_f, 6) integer
    Doodson multipliers.  Returns (cos, sin), float64 S + (n_f,) each; equal
    to ``np.cos(tidal_phase(beta, multipliers))`` (and sin) to ~1e-15
    absolute (compiled products of powers of exp(i beta_k); see the module
    docstring).
    """
    beta = np.asarray(beta, dtype=np.float64)
    mult = np.ascontiguousarray(np.asarray(multipliers, dtype=np.int64).reshape(-1, 6))
    shape = beta.shape[:-1]
    flat = np.ascontiguousarray(beta.reshape(-1, 6))
    nf = mult.shape[0]
    c = np.empty((flat.shape[0], nf))
    s = np.empty((flat.shape[0], nf))
    pmax = int(np.max(np.abs(mult))) if mult.size else 0
    _cos_sin_kernel(flat, mult, pmax, c, s)
    return c.reshape(shape + (nf,)), s.reshape(shape + (nf,))


@njit(cache=True)
def _harmonic_sum_kernel(beta, mult, pmax, wc, ws, out):
    """out[i, q] = sum_f cos(theta[i, f]) wc[f, q] + sin(theta[i, f]) ws[f, q]
    with the phases of :func:`_cos_sin_kernel`; out (n, K) is overwritten."""
    n = beta.shape[0]
    nf = mult.shape[0]
    nq = wc.shape[1]
    width = 2 * pmax + 1
    pr = np.empty((6, width))
    pi_ = np.empty((6, width))
    for i in range(n):
        _exp_powers(beta[i], pmax, pr, pi_)
        for q in range(nq):
            out[i, q] = 0.0
        for f in range(nf):
            re, im = _phase(pr, pi_, pmax, mult, f)
            for q in range(nq):
                out[i, q] += re * wc[f, q] + im * ws[f, q]


_FUSED_MAX_OUTPUTS = 16  # above this many outputs, BLAS (cos @ wc) beats the fused loop


def tidal_harmonic_sum(beta, multipliers, w_cos, w_sin) -> np.ndarray:
    """Linear combinations of the cos and sin of tidal phases:
    out[..., q] = sum_f cos(theta_f) w_cos[f, q] + sin(theta_f) w_sin[f, q],
    theta_f = n_f . beta.

    beta: S + (6,) Doodson arguments [rad]; multipliers: (n_f, 6) int;
    w_cos, w_sin: (n_f, K) float64 weights.  Returns float64 S + (K,).
    Fused compiled loop for K <= 16 (no (n, n_f) temporaries), else
    :func:`tidal_cos_sin` and two matrix products.
    """
    wc = np.ascontiguousarray(w_cos, dtype=np.float64)
    ws = np.ascontiguousarray(w_sin, dtype=np.float64)
    beta = np.asarray(beta, dtype=np.float64)
    shape = beta.shape[:-1]
    if wc.shape[1] > _FUSED_MAX_OUTPUTS:
        c, s = tidal_cos_sin(beta, multipliers)
        return c @ wc + s @ ws
    mult = np.ascontiguousarray(np.asarray(multipliers, dtype=np.int64).reshape(-1, 6))
    flat = np.ascontiguousarray(beta.reshape(-1, 6))
    out = np.empty((flat.shape[0], wc.shape[1]))
    pmax = int(np.max(np.abs(mult))) if mult.size else 0
    _harmonic_sum_kernel(flat, mult, pmax, wc, ws, out)
    return out.reshape(shape + (wc.shape[1],))
