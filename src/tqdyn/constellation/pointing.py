"""Beam directions and the satellite pointing frame under four pointing laws.

For satellite i (even permutation (i, j, k), see
:mod:`tqdyn.constellation.indices`) the two incoming beams come from the
positions of the remote satellites j and k at their emission times.  This
module returns, for every satellite and MOSA, the unit vector from the
receiver's position r_i(t0) towards the emitter's position (GCRS, SI,
coordinate time TDB; no aberration by the receiver's own velocity, as in the
paper), under one of the laws

* ``global``    -- instantaneous positions (paper eq. geometrypointing):
  n = (r_j(t0) - r_i(t0)) / |...|;
* ``taylor1``   -- first-order Taylor expansion of r_j(t0 - tau) with
  tau ~ L/c (eq. pointing2): n' = n_ij - v_j(t0)/c;
* ``taylor2``   -- second order (eqs. pointing1 + pointing2, i.e.
  realpointingapproximation): n' = n_ij - v_j/c + a_j L / (2 c^2);
* ``iterative`` -- the light-travel-time equation (eq. lightTravelTime)
  tau = |r_j(t0 - tau) - r_i(t0)| / c solved in double-double with a
  caller-supplied position interpolator of the emitter, then
  n = (r_j(t0 - tau) - r_i(t0)) / (c tau).

The Taylor vectors n' are *not* unit vectors (their norm differs from 1 by
~|v|/c ~ 1e-5); they are normalised here before anything else (DESIGN 4b:
forming the bisector from unnormalised vectors costs ~2e-6 rad).

Array layout: beams are (..., 3, 2, 3) = (time..., satellite i, MOSA l,
component); MOSA 1 receives from satellite k, MOSA 2 from satellite j.

Cost of tau ~ L/c: the exact tau differs from L/c by about
-(n_ij . v_j) L / c^2 (the emitter's velocity along the arm): for TianQin
this reaches ~2e-6 s (measured by ``tests/test_pointing.py``), not the
~1e-7 s the paper quotes.  In the Taylor laws it enters the beam direction
only through the emitter's displacement v_perp * dtau ~ 4e-3 m, i.e.
~2e-11 rad -- the level of the paper's Fig. 5.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..astro.constants import C_LIGHT
from ..numerics.dd import np_dd_add, np_dd_div_d, np_dd_sqr, np_dd_sqrt
from .geometry import _f64, _split_positions, arms, by_mosa
from .indices import EMITTER_OF_MOSA

__all__ = [
    "LAWS",
    "Beams",
    "PointingFrame",
    "angle_between",
    "beam_directions",
    "pointing_frames",
    "solve_light_travel_time",
]

LAWS = ("global", "taylor1", "taylor2", "iterative")

# per (sat, mosa): 0-based index of the emitter (MOSA 1 <- k, MOSA 2 <- j)
_EMITTER = EMITTER_OF_MOSA
_RECEIVER = np.array([[s, s] for s in range(3)], dtype=np.intp)


def angle_between(u, v) -> np.ndarray:
    """Angle [rad] between vectors u and v (..., 3), any norms, computed as
    atan2(|u x v|, u . v) (accurate for tiny angles).  Shape (...)."""
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.einsum("...k,...k->...", u, v))


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


# ------------------------------------------------------------------ dd numpy helpers

def _as_dd_times(t):
    if isinstance(t, tuple):
        hi, lo = t
    else:
        t = np.asarray(t, np.float64)
        hi, lo = (t[:, 0], t[:, 1]) if t.ndim == 2 else (t, np.zeros_like(t))
    return np.asarray(hi, np.float64), np.asarray(lo, np.float64)


# ------------------------------------------------------------------ iterative light travel time

def solve_light_travel_time(t, R, position_at: Callable, *, tol: float = 1e-20, max_iter: int = 12):
    """Solve tau = |r_j(t0 - tau) - r_i(t0)| / c for every beam (eq. lightTravelTime).

    t: reception times t0, TDB seconds since the epoch, (N,) dd as an (N, 2)
    array or a (hi, lo) tuple; R: receiver positions r_i(t0) [m] GCRS,
    (N, 3, 3) dd (trailing 2 or (hi, lo) tuple; float64 accepted);
    position_at(sat, t_hi, t_lo) -> (M, 3, 2) dd GCRS positions [m] of
    satellite ``sat`` (a :class:`~tqdyn.constellation.indices.Sat`, 1-based)
    at the TDB times t_hi + t_lo (each (M,) float64) -- e.g. a wrapper of
    :func:`tqdyn.integrators.hermite.interpolate_states`.

    Fixed-point iteration in numpy double-double starting from tau = L/c
    (contraction factor |n . v_j|/c ~ 1e-5, so ~4 iterations); stops when the
    last correction |tau_{n+1} - tau_n| (= the equation's residual at tau_n)
    is below ``tol`` [s] for all beams; the returned tau_{n+1} then has a
    residual ~1e-5 times smaller.  Raises RuntimeError if not converged in
    ``max_iter`` iterations.

    Returns (tau, r_emit, last_step): tau (N, 3, 2, 2) dd [s]; r_emit
    (N, 3, 2, 3, 2) dd [m], emitter positions at t0 - tau (consistent with
    the returned tau to the interpolator's precision); last_step (N, 3, 2)
    float64 [s], the last correction.  Beam layout (N, 3, 2) = (receiver i,
    MOSA l), MOSA 1 <- satellite k, MOSA 2 <- satellite j.
    """
    from .indices import Sat

    t_hi, t_lo = _as_dd_times(t)
    r_hi, r_lo = _split_positions(R)
    if r_lo is None:
        r_lo = np.zeros_like(r_hi)
    N = t_hi.shape[0]
    ri_hi = r_hi[:, _RECEIVER, :]  # (N, 3, 2, 3)
    ri_lo = r_lo[:, _RECEIVER, :]
    L = by_mosa(arms((r_hi, r_lo)).length, axis=-1)  # (N, 3, 2)
    tau_hi, tau_lo = L / C_LIGHT, np.zeros_like(L)
    re_hi = np.empty((N, 3, 2, 3))
    re_lo = np.empty((N, 3, 2, 3))
    sel = [np.nonzero(_EMITTER == e) for e in range(3)]  # beams emitted by satellite e
    last = None
    for _ in range(max_iter):
        te_hi, te_lo = np_dd_add(t_hi[:, None, None], t_lo[:, None, None], -tau_hi, -tau_lo)
        for e in range(3):
            si, mi = sel[e]
            th = te_hi[:, si, mi].reshape(-1)  # (N * 2,), time-major
            tl = te_lo[:, si, mi].reshape(-1)
            p = np.asarray(position_at(Sat(e + 1), th, tl), np.float64).reshape(N, len(si), 3, 2)
            re_hi[:, si, mi, :] = p[..., 0]
            re_lo[:, si, mi, :] = p[..., 1]
        dh, dl = np_dd_add(re_hi, re_lo, -ri_hi, -ri_lo)
        s2h, s2l = np_dd_sqr(dh[..., 0], dl[..., 0])
        for q in (1, 2):
            qh, ql = np_dd_sqr(dh[..., q], dl[..., q])
            s2h, s2l = np_dd_add(s2h, s2l, qh, ql)
        nh, nl = np_dd_sqrt(s2h, s2l)
        new_hi, new_lo = np_dd_div_d(nh, nl, C_LIGHT)
        sh, sl = np_dd_add(new_hi, new_lo, -tau_hi, -tau_lo)
        last = sh + sl
        tau_hi, tau_lo = new_hi, new_lo
        if np.all(np.abs(last) < tol):
            break
    else:
        raise RuntimeError(f"light travel time not converged: max correction {np.max(np.abs(last)):.3e} s")
    # emitter positions at the returned tau (one more interpolation)
    te_hi, te_lo = np_dd_add(t_hi[:, None, None], t_lo[:, None, None], -tau_hi, -tau_lo)
    for e in range(3):
        si, mi = sel[e]
        p = np.asarray(position_at(Sat(e + 1), te_hi[:, si, mi].reshape(-1), te_lo[:, si, mi].reshape(-1)),
                       np.float64).reshape(N, len(si), 3, 2)
        re_hi[:, si, mi, :] = p[..., 0]
        re_lo[:, si, mi, :] = p[..., 1]
    tau = np.stack([tau_hi, tau_lo], axis=-1)
    r_emit = np.stack([re_hi, re_lo], axis=-1)
    return tau, r_emit, last


# ------------------------------------------------------------------ beams

@dataclass(frozen=True)
class Beams:
    """Incoming-beam directions of one pointing law.

    law: the law's name; n: (..., 3, 2, 3) unit vectors [GCRS] from the
    receiver at t0 towards the emitter (MOSA 1 <- k, MOSA 2 <- j);
    tau: (..., 3, 2) [s] light travel time used (L/c for global / taylor*,
    the solved value for iterative, float64 hi + lo); tau_dd: (..., 3, 2, 2)
    dd tau (iterative only, else None); last_step: (..., 3, 2) [s] last
    correction of the iteration (iterative only)."""

    law: str
    n: np.ndarray
    tau: np.ndarray
    tau_dd: np.ndarray | None = None
    last_step: np.ndarray | None = None


def beam_directions(law: str, R, V=None, A=None, *, t=None, position_at: Callable | None = None,
                    tol: float = 1e-20, max_iter: int = 12) -> Beams:
    """Incoming-beam unit vectors for every satellite and MOSA under ``law``.

    law: one of :data:`LAWS`; R: positions (N, 3, 3) [m] GCRS (float64, dd
    (N, 3, 3, 2) or (hi, lo)); V: velocities [m/s] (needed by taylor1,
    taylor2); A: accelerations [m/s^2], float64 (N, 3, 3) (taylor2; these are
    the satellites' total accelerations, gravity plus drag-free control if
    any); t, position_at: reception times and emitter interpolator for
    ``iterative`` (see :func:`solve_light_travel_time`).  Times are TDB.
    Returns :class:`Beams` with n (N, 3, 2, 3).
    """
    if law not in LAWS:
        raise ValueError(f"pointing law {law!r} is not allowed; allowed: {', '.join(LAWS)}")
    if law == "iterative":
        if t is None or position_at is None:
            raise ValueError("the iterative law needs t and position_at")
        tau, r_emit, last = solve_light_travel_time(t, R, position_at, tol=tol, max_iter=max_iter)
        r_hi, r_lo = _split_positions(R)
        if r_lo is None:
            r_lo = np.zeros_like(r_hi)
        d = (r_emit[..., 0] - r_hi[:, _RECEIVER, :]) + (r_emit[..., 1] - r_lo[:, _RECEIVER, :])
        return Beams(law, _unit(d), tau[..., 0] + tau[..., 1], tau, last)
    a = arms(R)
    n = by_mosa(a.n)  # (N, 3, 2, 3)
    L = by_mosa(a.length, axis=-1)
    tau = L / C_LIGHT
    if law == "global":
        return Beams(law, n, tau)
    if V is None:
        raise ValueError(f"the {law} law needs velocities")
    v_emit = _f64(V)[..., _EMITTER, :]
    nprime = n - v_emit / C_LIGHT
    if law == "taylor2":
        if A is None:
            raise ValueError("the taylor2 law needs accelerations")
        a_emit = np.asarray(_f64(A))[..., _EMITTER, :]
        nprime = nprime + a_emit * (L / (2.0 * C_LIGHT ** 2))[..., None]
    return Beams(law, _unit(nprime), tau)


@dataclass(frozen=True)
class PointingFrame:
    """Satellite frame S and MOSA angle from two incoming beams.

    X_S, Y_S, Z_S: (..., 3, 3) [GCRS] unit axes per satellite (X_S the
    bisector of the two beams, Z_S = n_ij x n_ik / sin(theta), Y_S = Z_S x X_S);
    T_S_I: (..., 3, 3, 3) rotation inertial -> S (rows X_S, Y_S, Z_S);
    theta: (..., 3) [rad] angle between the two beams (the breathing angle
    alpha_i for the global law); the MOSA angle of OA_l is +theta/2 (l = 1,
    towards k) or -theta/2 (l = 2, towards j) about Z_S."""

    X_S: np.ndarray
    Y_S: np.ndarray
    Z_S: np.ndarray
    theta: np.ndarray

    @property
    def T_S_I(self) -> np.ndarray:
        return np.stack([self.X_S, self.Y_S, self.Z_S], axis=-2)


def pointing_frames(n) -> PointingFrame:
    """S frames and beam angles from beam vectors n (..., 3, 2, 3) [GCRS]
    (MOSA 1 <- k, MOSA 2 <- j; any norms: each beam is normalised first)."""
    n = _unit(np.asarray(n, np.float64))
    nk, nj = n[..., 0, :], n[..., 1, :]
    c = np.cross(nj, nk)
    sc = np.linalg.norm(c, axis=-1)
    Z = c / sc[..., None]
    X = _unit(nj + nk)
    Y = np.cross(Z, X)
    theta = np.arctan2(sc, np.einsum("...k,...k->...", nj, nk))
    return PointingFrame(X, Y, Z, theta)
