"""Beam directions and the satellite pointing frame under four pointing laws.

For satellite i (even permutation (i, j, k), see
:mod:`tqdyn.constellation.indices`) the two incoming beams come from the
positions of the remote satellites j and k at their emission times.  This
module returns, for every satellite and MOSA, the unit vector from the
receiver's position r_i(t0) towards the emitter's position (GCRS, SI,
coordinate time TT; no aberration by the receiver's own velocity, as in the
paper), under one of the laws

* ``global``    -- instantaneous positions (paper eq. geometrypointing):
  n = (r_j(t0) - r_i(t0)) / |...|;
* ``taylor1``   -- first-order Taylor expansion of r_j(t0 - tau) with
  tau ~ L/c (eq. pointing2): n' = n_ij - v_j(t0)/c;
* ``taylor2``   -- second order (eqs. pointing1 + pointing2, i.e.
  realpointingapproximation): n' = n_ij - v_j/c + a_j L / (2 c^2);
* ``iterative`` -- the light-travel-time equation (eq. lightTravelTime)
  tau = |r_j(t0 - tau) - r_i(t0)| / c, then n = (r_j(t0 - tau) - r_i(t0)) /
  |...|.  The equation is solved by tqdyn's one post-processing light-time
  solver, :func:`tqdyn.lightpath.light_travel_times` (double-double, on the
  Hermite dense output of the trajectory); this module takes its result
  (``light_times``) and only re-indexes it by satellite and MOSA.  (The
  other solver, inside the compiled right-hand side, works on a Taylor model
  of the remote orbit because the trajectory does not exist yet there:
  :mod:`tqdyn.constellation._kinematics_jit`.)

The Taylor vectors n' are *not* unit vectors (their norm differs from 1 by
~|v|/c ~ 1e-5); they are normalised here before anything else (docs/design.md, Traps:
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

from dataclasses import dataclass

import numpy as np

from .._choices import unknown
from ..astro.constants import C_LIGHT
from .geometry import _f64, arms, by_mosa
from .indices import EMITTER_OF_MOSA, LINK_OF_MOSA

__all__ = [
    "LAWS",
    "Beams",
    "PointingFrame",
    "angle_between",
    "beam_directions",
    "pointing_frames",
]

LAWS = ("global", "taylor1", "taylor2", "iterative")

# per (sat, mosa): 0-based index of the emitter (MOSA 1 <- k, MOSA 2 <- j)
_EMITTER = EMITTER_OF_MOSA


def angle_between(u, v) -> np.ndarray:
    """Angle [rad] between vectors u and v (..., 3), any norms, computed as
    atan2(|u x v|, u . v) (accurate for tiny angles).  Shape (...)."""
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.einsum("...k,...k->...", u, v))


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


# ------------------------------------------------------------------ beams

@dataclass(frozen=True)
class Beams:
    """Incoming-beam directions of one pointing law.

    law: the law's name; n: (..., 3, 2, 3) unit vectors [GCRS] from the
    receiver at t0 towards the emitter (MOSA 1 <- k, MOSA 2 <- j);
    tau: (..., 3, 2) [s] light travel time used (L/c for global / taylor*,
    the solved value for iterative, float64 hi + lo); tau_dd: (..., 3, 2, 2)
    dd tau (iterative only, else None); last_step: (..., 3, 2) [s] residual
    of the light-time equation at the returned tau (iterative only)."""

    law: str
    n: np.ndarray
    tau: np.ndarray
    tau_dd: np.ndarray | None = None
    last_step: np.ndarray | None = None


def beam_directions(law: str, R, V=None, A=None, *, light_times=None) -> Beams:
    """Incoming-beam unit vectors for every satellite and MOSA under ``law``.

    law: one of :data:`LAWS`; R: positions (N, 3, 3) [m] GCRS (float64, dd
    (N, 3, 3, 2) or (hi, lo)); V: velocities [m/s] (needed by taylor1,
    taylor2); A: accelerations [m/s^2], float64 (N, 3, 3) (taylor2; these are
    the satellites' total accelerations, gravity plus drag-free control if
    any).  ``iterative`` takes instead ``light_times``, the solved light
    travel times of the satellite centres on the same N times
    (:func:`tqdyn.lightpath.light_travel_times` of (t, R, V, A), a
    :class:`~tqdyn.lightpath.LightTravelTimes`; rows whose emission precedes
    the grid are NaN).  Times are TT.  Returns :class:`Beams` with n (N, 3, 2, 3).
    """
    if law not in LAWS:
        raise ValueError(unknown("pointing law", law, LAWS))
    if law == "iterative":
        if light_times is None:
            raise ValueError("the iterative law needs light_times: tqdyn.lightpath.light_travel_times(t, R, V, A) "
                             "of the satellite centres")
        if getattr(light_times, "source", "sat") != "sat":
            raise ValueError(f"light_times: solved between {light_times.source!r} bodies; the pointing laws "
                             "need the satellite centres (source 'sat')")
        per_beam = lambda x: x[:, LINK_OF_MOSA]  # noqa: E731  (link axis -> (satellite, MOSA))
        rh, rl = light_times.r_receive
        eh, el = light_times.r_emit
        d = (per_beam(eh) - per_beam(rh)) + (per_beam(el) - per_beam(rl))
        tau = np.stack([per_beam(light_times.tau[0]), per_beam(light_times.tau[1])], axis=-1)
        return Beams(law, _unit(d), tau[..., 0] + tau[..., 1], tau, per_beam(np.asarray(light_times.residual)))
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
