"""The working point of the closed loop from a coupled run's arrays: gravity gradient, rates, DC actuation.

Gravity-gradient tensor at the spacecraft (S frame) [s^-2]: the point-mass tidal tensors of the
central body and of the run's third bodies,

    Gamma = sum_b GM_b / |d_b|^3 (3 d_b d_b^T / |d_b|^2 - I),   d_b = r_sat - r_b,

rotated into S (T_S_I Gamma T_S_I^T).  TianQin (1e8 m from the Earth): the Earth's monopole
GM/r^3 = 4e-10 s^-2; the Moon 1e-13, the Sun 4e-14; the Earth's J2 changes the Earth's tidal tensor by
~(3/2) J2 (R/r)^2 ~ 7e-6 of itself (3e-15 s^-2), left out.  LISA / Taiji (1 au from the Sun): the Sun's
GM/r^3 = 4e-14 s^-2 (1e4 times less than TianQin's); the Earth at ~5e10 m 3e-18, the planets less.  In
the loop Gamma multiplies displacements of nm (1e-19 m/s^2 at TianQin): nothing beyond point masses
can matter.

The other coefficients come from the trajectory's fields (one row per time, per satellite): ``sat/omega``,
``sat/omega_dot`` (S), ``mosa/angle`` (the opening angle theta = angle_1 - angle_2, its rate by
central differences), ``tm/a_suspension`` and ``tm/alpha_suspension`` (OA_l), ``sat/a_dragfree``
(rotated into S), ``tm/self_gravity`` (OA_l).
"""

from __future__ import annotations

import math

import numpy as np

from .plant import WorkingPoint

__all__ = ["gravity_gradient", "segment_rows", "third_body_positions", "working_points"]


def gravity_gradient(r, bodies, gms) -> np.ndarray:
    """Tidal tensor [s^-2] at positions ``r`` (..., 3) [m] of point masses at ``bodies`` (..., n_b, 3) [m]
    with ``gms`` (n_b,) [m^3/s^2], same frame as the inputs (the central body: a position of zeros).
    Returns (..., 3, 3)."""
    d = np.asarray(r, dtype=np.float64)[..., None, :] - np.asarray(bodies, dtype=np.float64)   # (..., n_b, 3)
    dn = np.linalg.norm(d, axis=-1)
    u = d / dn[..., None]
    k = np.asarray(gms, dtype=np.float64) / dn ** 3
    eye = np.eye(3)
    return np.sum(k[..., None, None] * (3.0 * u[..., :, None] * u[..., None, :] - eye), axis=-3)


def third_body_positions(reference, epoch, t, bodies, ephemeris) -> np.ndarray:
    """Positions (N, n_b, 3) [m] of ``bodies`` relative to the central body of ``reference``
    (:class:`tqdyn.astro.reference.ReferenceSystem`) at the run times ``t`` (N,) [s since ``epoch``];
    ``ephemeris`` an :class:`tqdyn.astro.ephemeris.Ephemeris`.  Newtonian (the 1PN corrections change
    the tide by ~1e-8 of itself)."""
    if not bodies:
        return np.zeros((len(t), 0, 3))
    jd1, jd2 = reference.ephemeris_jd(epoch, np.asarray(t, dtype=np.float64))
    if reference.central_body == "sun":
        pos, _ = ephemeris.heliocentric_states(tuple(bodies), jd1, jd2, velocity=False)
    else:
        pos, _ = ephemeris.geocentric_states(tuple(bodies), jd1, jd2, velocity=False)
    return pos


def segment_rows(t, segment_s: float) -> list[tuple[int, int, int]]:
    """Split the rows of the run's time axis ``t`` (N,) [s] into consecutive segments of ``segment_s`` [s] from
    t[0]: ceil(span / segment_s) of them (a run of exactly n segments' length gives n; at least one), the last
    one holding the final row; each (first row, last row + 1, row of the working point (the one nearest the
    segment's middle))."""
    t = np.asarray(t, dtype=np.float64)
    span = float(t[-1] - t[0])
    n = max(1, math.ceil(span / segment_s - 1e-9))
    out = []
    for k in range(n):
        a = t[0] + k * segment_s
        i0 = int(np.searchsorted(t, a - 1e-9))
        i1 = len(t) if k == n - 1 else int(np.searchsorted(t, a + segment_s - 1e-9))
        if i1 <= i0:
            continue
        mid = int(np.argmin(np.abs(t[i0:i1] - (a + 0.5 * segment_s)))) + i0
        out.append((i0, i1, mid))
    return out or [(0, len(t), len(t) // 2)]


def working_points(t, r, T_S_I, omega, omega_dot, mosa_angle, a_suspension, alpha_suspension, a_dragfree,
                   self_gravity, central_gm, bodies_pos=None, bodies_gm=()) -> list[list[WorkingPoint]]:
    """:class:`~tqdyn.closedloop.plant.WorkingPoint` per row and satellite: a list over rows of lists over
    satellites.  Arrays as the trajectory stores them: t (N,) [s], r (N, n, 3) [m, inertial], T_S_I
    (N, n, 3, 3), omega / omega_dot (N, n, 3) [S], mosa_angle (N, n, 2) [rad], a_suspension /
    alpha_suspension (N, n, 2, 3) [OA_l], a_dragfree (N, n, 3) [inertial], self_gravity (n, 2, 3)
    [OA_l]; central_gm [m^3/s^2]; bodies_pos (N, n_b, 3) [m] and bodies_gm (n_b,) of the third bodies."""
    t = np.asarray(t, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    N, n = r.shape[:2]
    pos = np.zeros((N, 1, 3))
    gms = [central_gm]
    if bodies_pos is not None and len(bodies_gm):
        pos = np.concatenate([pos, np.asarray(bodies_pos, dtype=np.float64)], axis=1)
        gms = gms + list(bodies_gm)
    gam_I = gravity_gradient(r, pos[:, None, :, :], gms)                       # (N, n, 3, 3)
    T = np.asarray(T_S_I, dtype=np.float64)
    gam_S = np.einsum("...ij,...jk,...lk->...il", T, gam_I, T)
    theta = np.asarray(mosa_angle[..., 0] - mosa_angle[..., 1], dtype=np.float64)
    theta_dot = np.gradient(theta, t, axis=0) if N > 1 else np.zeros_like(theta)
    G_S = np.einsum("...ij,...j->...i", T, np.asarray(a_dragfree, dtype=np.float64))
    sg = np.asarray(self_gravity, dtype=np.float64)
    return [[WorkingPoint(gamma=gam_S[k, i], omega=np.asarray(omega[k, i], dtype=np.float64),
                          omega_dot=np.asarray(omega_dot[k, i], dtype=np.float64), theta=float(theta[k, i]),
                          theta_dot=float(theta_dot[k, i]), a_suspension=np.asarray(a_suspension[k, i]),
                          alpha_suspension=np.asarray(alpha_suspension[k, i]), a_dragfree=G_S[k, i],
                          self_gravity=sg[i], t=float(t[k]))
             for i in range(n)] for k in range(N)]
