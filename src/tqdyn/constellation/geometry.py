"""Constellation geometry: arm vectors, unit vectors, breathing angles, incenter,
and their first and second time derivatives (paper: eqs. OAinput1-3, the
breathing-angle equations of the appendix and the incenter of section III).

Conventions (see :mod:`tqdyn.constellation.indices`): positions R_i of the
three satellites, GCRS [m], time axis first; arrays are ``(..., 3, 3)`` =
(time..., satellite 1..3, component).  Per-link quantities use the LISA link
order 12, 23, 31, 13, 32, 21 (axis of length 6, ``Link.index``); link ab
(receiver a, emitter b) carries the arm vector r_ab = R_b - R_a pointing
from the receiver to the emitter, i.e. the direction the receiving telescope
faces in the instantaneous ("global") geometry.  All quantities are at one
common coordinate time t (TT) -- no light travel time here (see
:mod:`tqdyn.constellation.pointing`).

Precision: positions may be given in double-double (trailing axis of length
2, or a ``(hi, lo)`` tuple as in the propagator's rows); the arm vector
R_b - R_a is formed from both parts (error ~1e-16 of the ~1.7e8 m arm, i.e.
~2e-8 m, instead of the ~3e-8 m of rounding each absolute position to
float64 first) and returned as float64: every output here is a direction,
an angle or a rate, for which float64 (1e-16 relative) is ample.  Ranges at
the pm level are the business of :mod:`tqdyn.lightpath`.

Derivatives (derived here; the paper's appendix writes |r_ij|-dot as
``|\\dot r_ij|`` and the second derivative as ``|\\ddot r_ij|``, which are
*not* the norms of the relative velocity / acceleration but the time
derivatives of the arm length L = |r_ij|):

* L' = r' . n,                 n' = (r' - L' n) / L,
* L'' = r'' . n + r' . n',     n'' = (r'' - L'' n - 2 L' n') / L,
* cos(alpha_i) = n_ij . n_ik,
  alpha_i' = -(n_ij' . n_ik + n_ij . n_ik') / sin(alpha_i),
  alpha_i'' = -(n_ij'' . n_ik + n_ij . n_ik'' + 2 n_ij' . n_ik'
               + alpha_i'^2 cos(alpha_i)) / sin(alpha_i).

These agree with the printed appendix formulas once |r|-dot is read as L'.
``tests/test_geometry.py`` checks them against finite differences along a
real trajectory and against a rigidly rotating equilateral triangle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .indices import LINK_EMITTER, LINK_IJ, LINK_IK, LINK_OF_MOSA, LINK_RECEIVER

__all__ = [
    "Arms",
    "Geometry",
    "Incenter",
    "arms",
    "breathing_angles",
    "by_mosa",
    "centroid_directions",
    "constellation_geometry",
    "incenter",
    "link_pairs",
]

_RECV, _EMIT = LINK_RECEIVER, LINK_EMITTER
# per satellite i: link index of (i -> j) and (i -> k)
_IJ, _IK = LINK_IJ, LINK_IK


def link_pairs() -> tuple[np.ndarray, np.ndarray]:
    """Index arrays (3,), (3,) of the links i->j and i->k for satellites
    i = 1, 2, 3 (positions along a link axis in LISA order)."""
    return _IJ.copy(), _IK.copy()


def by_mosa(x: np.ndarray, axis: int = -2) -> np.ndarray:
    """Re-index a per-link array (link axis of length 6 at ``axis``) per MOSA:
    the link axis becomes two axes (3, 2) = (satellite i, MOSA l), where MOSA
    1 receives from satellite k and MOSA 2 from satellite j.  Default axis -2
    suits vector arrays (..., 6, 3); use axis=-1 for scalars (..., 6)."""
    x = np.asarray(x)
    return np.take(x, LINK_OF_MOSA, axis=axis % x.ndim)


def _split_positions(R):
    """(hi, lo) float64 arrays (..., 3, 3) from float64, dd (..., 3, 3, 2) or a (hi, lo) tuple."""
    if isinstance(R, tuple):
        hi, lo = R
        return np.asarray(hi, np.float64), np.asarray(lo, np.float64)
    R = np.asarray(R, np.float64)
    if R.shape[-1] == 2 and R.ndim >= 3 and R.shape[-2] == 3:
        return R[..., 0], R[..., 1]
    if R.shape[-1] != 3 or R.ndim < 2 or R.shape[-2] != 3:
        raise ValueError(f"positions: expected shape (..., 3, 3) or (..., 3, 3, 2), got {R.shape}")
    return R, None


def _f64(x):
    """float64 value of float64 / dd (trailing 2) / (hi, lo) input; None passes."""
    if x is None:
        return None
    hi, lo = _split_positions(x)
    return hi if lo is None else hi + lo


def _dot(a, b):
    return np.einsum("...k,...k->...", a, b)


@dataclass(frozen=True)
class Arms:
    """Arm vectors of the six links (LISA order) and their time derivatives.

    Shapes (... = leading time axes): vectors (..., 6, 3), scalars (..., 6);
    GCRS components, SI units, all at the same coordinate time (TT).
    Derivative fields are None when the corresponding input was not given.

    r [m]: R_emitter - R_receiver;  length [m]: L = |r|;  n: r / L (unit);
    r_dot [m/s], length_dot [m/s] (L'), n_dot [1/s];
    r_ddot [m/s^2], length_ddot [m/s^2] (L''), n_ddot [1/s^2].
    """

    r: np.ndarray
    length: np.ndarray
    n: np.ndarray
    r_dot: np.ndarray | None = None
    length_dot: np.ndarray | None = None
    n_dot: np.ndarray | None = None
    r_ddot: np.ndarray | None = None
    length_ddot: np.ndarray | None = None
    n_ddot: np.ndarray | None = None


def _differences(x_hi, x_lo):
    """x[emitter] - x[receiver] for the six links, using both dd parts."""
    a_hi, b_hi = x_hi[..., _EMIT, :], x_hi[..., _RECV, :]
    s = a_hi - b_hi  # two_sum of a_hi and -b_hi
    bb = s - a_hi
    e = (a_hi - (s - bb)) + (-b_hi - bb)
    if x_lo is not None:
        e = e + (x_lo[..., _EMIT, :] - x_lo[..., _RECV, :])
    return s + e


def arms(R, V=None, A=None) -> Arms:
    """Arm vectors, lengths, unit vectors and their derivatives (eqs. OAinput1-3).

    R: positions (..., 3, 3) [m], GCRS, float64, dd (..., 3, 3, 2) or a
    (hi, lo) tuple; V: velocities [m/s] (same forms, optional); A:
    accelerations [m/s^2] (float64 (..., 3, 3) or dd, optional, needs V).
    Axis -2 is the satellite (1, 2, 3), the last the component; all at one
    coordinate time (TT).  Returns :class:`Arms` with per-link arrays
    (..., 6, 3) / (..., 6) in LISA link order.
    """
    r = _differences(*_split_positions(R))
    L = np.sqrt(_dot(r, r))
    n = r / L[..., None]
    if V is None:
        if A is not None:
            raise ValueError("accelerations need velocities")
        return Arms(r, L, n)
    rd = _differences(*_split_positions(V))
    Ld = _dot(rd, n)
    nd = (rd - Ld[..., None] * n) / L[..., None]
    if A is None:
        return Arms(r, L, n, rd, Ld, nd)
    rdd = _differences(*_split_positions(A))
    Ldd = _dot(rdd, n) + _dot(rd, nd)
    ndd = (rdd - Ldd[..., None] * n - 2.0 * Ld[..., None] * nd) / L[..., None]
    return Arms(r, L, n, rd, Ld, nd, rdd, Ldd, ndd)


def breathing_angles(a: Arms):
    """Breathing angles alpha_i (angle at satellite i between n_ij and n_ik)
    and their first and second time derivatives.

    a: :class:`Arms`.  Returns (alpha [rad], alpha_dot [rad/s], alpha_ddot
    [rad/s^2]), each (..., 3) over satellites 1..3; the derivatives are None
    if ``a`` has no velocity / acceleration parts.  alpha is computed as
    atan2(|n_ij x n_ik|, n_ij . n_ik) (accurate at any angle); the three
    angles sum to pi up to round-off.
    """
    nj, nk = a.n[..., _IJ, :], a.n[..., _IK, :]
    c = _dot(nj, nk)
    s = np.linalg.norm(np.cross(nj, nk), axis=-1)
    alpha = np.arctan2(s, c)
    if a.n_dot is None:
        return alpha, None, None
    ndj, ndk = a.n_dot[..., _IJ, :], a.n_dot[..., _IK, :]
    cd = _dot(ndj, nk) + _dot(nj, ndk)
    alpha_dot = -cd / s
    if a.n_ddot is None:
        return alpha, alpha_dot, None
    nddj, nddk = a.n_ddot[..., _IJ, :], a.n_ddot[..., _IK, :]
    cdd = _dot(nddj, nk) + _dot(nj, nddk) + 2.0 * _dot(ndj, ndk)
    alpha_ddot = -(cdd + alpha_dot ** 2 * c) / s
    return alpha, alpha_dot, alpha_ddot


def centroid_directions(R) -> np.ndarray:
    """Unit vectors (..., 3, 3) from each satellite toward the centroid (R_1 + R_2 + R_3) / 3 of the three.

    R: positions (..., 3, 3) [m] as for :func:`arms` (float64, dd or (hi,
    lo)); formed from the arm vectors, centroid - R_i = (r_ij + r_ik) / 3,
    so free of the cancellation of the absolute positions.  Same axes as R.
    The incenter's direction (:class:`Incenter`, X_S of the global law)
    differs from it by the first-order angle (L_ik - L_ij) / (2 sqrt(3) L)
    (:func:`tqdyn.constellation.estimates.bisector_median_angle`).
    """
    a = arms(R)
    c = a.r[..., _IJ, :] + a.r[..., _IK, :]
    return c / np.linalg.norm(c, axis=-1, keepdims=True)


@dataclass(frozen=True)
class Incenter:
    """Incenter of the triangle of the three satellites (instantaneous).

    position: (..., 3) [m] GCRS, in the precision of the input positions
    (dd (..., 3, 2) if R was dd or a (hi, lo) tuple, else float64);
    velocity (..., 3) [m/s] and acceleration (..., 3) [m/s^2], float64 GCRS
    (None without V / A);
    offset (..., 3, 3) [m]: r_inc - R_i for each satellite i (float64, formed
    from arm vectors, so free of the 1e8 m cancellation); offset_dot [m/s],
    offset_ddot [m/s^2]: its time derivatives (None without V / A).
    X_S of satellite i in the global law is offset_i / |offset_i|.
    """

    position: np.ndarray
    offset: np.ndarray
    velocity: np.ndarray | None = None
    acceleration: np.ndarray | None = None
    offset_dot: np.ndarray | None = None
    offset_ddot: np.ndarray | None = None


def incenter(R, a: Arms, V=None, A=None) -> Incenter:
    """Incenter r_inc = (r23 R1 + r31 R2 + r12 R3) / (r12 + r23 + r31) and its
    derivatives.

    R, V, A: positions [m], velocities [m/s], accelerations [m/s^2] as for
    :func:`arms` (GCRS, (..., 3, 3), R float64 / dd / (hi, lo)); a: the
    :class:`Arms` of the same states (with derivatives if V / A are wanted).
    Computed per satellite i as the offset d_i = (w_j r_ij + w_k r_ik) / W,
    with w_j = |r_ki| (side opposite j), w_k = |r_ij|, W = perimeter, and
    d_i' = (P' - d_i W') / W, d_i'' = (P'' - 2 d_i' W' - d_i W'') / W for
    P = w_j r_ij + w_k r_ik.  Returns :class:`Incenter`.
    """
    L = a.length  # (..., 6)
    # satellite i: w_j = |r_ki| = L[i->k], w_k = |r_ij| = L[i->j]
    lij, lik = _IJ, _IK
    wj, wk = L[..., lik], L[..., lij]
    W = L[..., _IJ].sum(axis=-1)[..., None]  # perimeter: links 12, 23, 31
    P = wj[..., None] * a.r[..., lij, :] + wk[..., None] * a.r[..., lik, :]
    d = P / W[..., None]
    hi, lo = _split_positions(R)
    if lo is None:
        pos = hi[..., 0, :] + d[..., 0, :]
    else:
        s = hi[..., 0, :] + d[..., 0, :]
        bb = s - hi[..., 0, :]
        e = (hi[..., 0, :] - (s - bb)) + (d[..., 0, :] - bb) + lo[..., 0, :]
        s2 = s + e
        pos = np.stack([s2, e - (s2 - s)], axis=-1)
    if V is None or a.length_dot is None:
        return Incenter(pos, d)
    Ld = a.length_dot
    wjd, wkd = Ld[..., lik], Ld[..., lij]
    Wd = Ld[..., _IJ].sum(axis=-1)[..., None]
    Pd = (wjd[..., None] * a.r[..., lij, :] + wj[..., None] * a.r_dot[..., lij, :]
          + wkd[..., None] * a.r[..., lik, :] + wk[..., None] * a.r_dot[..., lik, :])
    dd_ = (Pd - d * Wd[..., None]) / W[..., None]
    vel = _f64(V)[..., 0, :] + dd_[..., 0, :]
    if A is None or a.length_ddot is None:
        return Incenter(pos, d, vel, None, dd_, None)
    Ldd = a.length_ddot
    wjdd, wkdd = Ldd[..., lik], Ldd[..., lij]
    Wdd = Ldd[..., _IJ].sum(axis=-1)[..., None]
    Pdd = (wjdd[..., None] * a.r[..., lij, :] + 2.0 * wjd[..., None] * a.r_dot[..., lij, :]
           + wj[..., None] * a.r_ddot[..., lij, :]
           + wkdd[..., None] * a.r[..., lik, :] + 2.0 * wkd[..., None] * a.r_dot[..., lik, :]
           + wk[..., None] * a.r_ddot[..., lik, :])
    ddd = (Pdd - 2.0 * dd_ * Wd[..., None] - d * Wdd[..., None]) / W[..., None]
    acc = _f64(A)[..., 0, :] + ddd[..., 0, :]
    return Incenter(pos, d, vel, acc, dd_, ddd)


@dataclass(frozen=True)
class Geometry:
    """Everything :func:`constellation_geometry` computes (see :class:`Arms`,
    :func:`breathing_angles`, :class:`Incenter`): ``arms``; ``alpha``,
    ``alpha_dot``, ``alpha_ddot`` (..., 3) [rad, rad/s, rad/s^2];
    ``incenter``."""

    arms: Arms
    alpha: np.ndarray
    alpha_dot: np.ndarray | None
    alpha_ddot: np.ndarray | None
    incenter: Incenter


def constellation_geometry(R, V=None, A=None) -> Geometry:
    """Arms, breathing angles and incenter (with derivatives as far as V, A
    allow) of the states R [m], V [m/s], A [m/s^2], GCRS, shapes (..., 3, 3)
    (R, V may be dd), all at one coordinate time (TT)."""
    a = arms(R, V, A)
    alpha, ad, add = breathing_angles(a)
    return Geometry(a, alpha, ad, add, incenter(R, a, V, A))
