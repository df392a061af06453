"""Compiled nominal control of one satellite (the integrator's inner loop).

Scalar numba versions of :func:`tqdyn.constellation.control.nominal_control`
and :meth:`tqdyn.constellation.spacecraft.Spacecraft.housing_centers` for one
satellite at one instant; the derivations (eq:TMforce bracket, eq:E1, eq:E2
and G from the three control conditions with tan(theta/2), cot(theta/2); the
general scheme for any sensitive axes by Cramer's rule) are in
:mod:`tqdyn.constellation.control`.  The numpy module is the reference
the tests compare these kernels with.

Frames: S (satellite), OA_l (MOSA/TM l: X_S rotated by +theta/2 for l = 1,
-theta/2 for l = 2 about Z_S), GCRS.  Units SI.  Time scale: instantaneous
(TT in tqdyn).
"""

from __future__ import annotations

import math


from ..numerics.vec3 import cross
from .indices import MOSA_SIGN
from ..numerics.jit import inner_kernel

__all__ = ["housing_geometry", "satellite_control"]


@inner_kernel
def housing_geometry(i, theta, theta_dot, r0_nom, piv, theta_nom, w, r0, rho, vel):
    """EH centers of satellite ``i`` and their velocity relative to the CoM, in S.

    theta, theta_dot : MOSA opening angle [rad] and its rate [rad/s].
    r0_nom : (2, 3) EH centers at theta_nom [m, S]; piv : (2, 3) MOSA pivots
    [m, S, fixed in S]; theta_nom : nominal opening angle [rad].
    w : (n, 3) satellite angular velocities [rad/s, S] (row i is used).
    Outputs (in place, S frame, rows [i] of (n, 2, 3) arrays): rho lever arms
    R_z(+/-(theta - theta_nom)/2) (r0_nom - piv) [m]; r0 = piv + rho EH
    centers [m]; vel inertial velocity of the EH center relative to the CoM,
    expressed in S: w x r0 + w_oa x rho [m/s], with the MOSA rate w_oa =
    (0, 0, +/-theta_dot/2).  (Arrays are indexed, not sliced, so the hot
    path creates no array views.)
    """
    for l in range(2):
        s = MOSA_SIGN[l]
        d = s * 0.5 * (theta - theta_nom)
        c, sn = math.cos(d), math.sin(d)
        px, py, pz = r0_nom[l, 0] - piv[l, 0], r0_nom[l, 1] - piv[l, 1], r0_nom[l, 2] - piv[l, 2]
        rx, ry = c * px - sn * py, sn * px + c * py
        rho[i, l, 0], rho[i, l, 1], rho[i, l, 2] = rx, ry, pz
        r0[i, l, 0] = piv[l, 0] + rx
        r0[i, l, 1] = piv[l, 1] + ry
        r0[i, l, 2] = piv[l, 2] + pz
        cx, cy, cz = cross((w[i, 0], w[i, 1], w[i, 2]), (r0[i, l, 0], r0[i, l, 1], r0[i, l, 2]))
        wm = s * 0.5 * theta_dot
        vel[i, l, 0] = cx - wm * ry
        vel[i, l, 1] = cy + wm * rx
        vel[i, l, 2] = cz


@inner_kernel
def satellite_control(i, scheme, sens, dg_S, sg_S, w, wd, theta, theta_dot, theta_ddot, r0, rho, g, A, G_S,
                      alpha):
    """g_l, suspension A_c,l, drag-free G and TM angular acceleration of satellite ``i``.

    scheme : 0 = the "tianqin" closed form (sensitive axes X_OA_l), 1 = the
    general "lisa" solution with the sensitive axes ``sens`` (2, 3) [unit
    vectors in OA_l] (derivations in :mod:`tqdyn.constellation.control`).
    Every other array has a leading satellite axis; row i is read / written.
    Inputs (S frame): dg_S (n, 2, 3) a_grav(TM_l) - a_grav(CoM) [m/s^2];
    sg_S (n, 2, 3) self-gravity of TM l [m/s^2]; w, wd (n, 3) satellite
    angular velocity [rad/s] and acceleration [rad/s^2]; theta, theta_dot,
    theta_ddot: MOSA opening angle and rates [rad, rad/s, rad/s^2]; r0, rho
    (n, 2, 3) EH centers and lever arms [m].
    Outputs (in place): g (n, 2, 3) [m/s^2, S]; A (n, 2, 3) [m/s^2, OA_l];
    G_S (n, 3) [m/s^2, S]; alpha (n, 2, 3) [rad/s^2, OA_l] (cube TM: no
    gravity-gradient torque).
    """
    for l in range(2):
        s = MOSA_SIGN[l]
        wm = s * 0.5 * theta_dot
        wmd = s * 0.5 * theta_ddot
        px, py = rho[i, l, 0], rho[i, l, 1]
        qx, qy, qz = r0[i, l, 0], r0[i, l, 1], r0[i, l, 2]
        # w_oa x rho, w_oa x (w_oa x rho), w_oa' x rho with w_oa = (0, 0, wm); rho_z = 0
        mx, my = -wm * py, wm * px
        mmx, mmy = -wm * my, wm * mx
        mdx, mdy = -wmd * py, wmd * px
        c1 = cross((w[i, 0], w[i, 1], w[i, 2]), (mx, my, 0.0))
        wr = cross((w[i, 0], w[i, 1], w[i, 2]), (qx, qy, qz))
        c2 = cross((w[i, 0], w[i, 1], w[i, 2]), wr)
        c3 = cross((wd[i, 0], wd[i, 1], wd[i, 2]), (qx, qy, qz))
        g[i, l, 0] = dg_S[i, l, 0] + sg_S[i, l, 0] - 2.0 * c1[0] - mdx - mmx - c2[0] - c3[0]
        g[i, l, 1] = dg_S[i, l, 1] + sg_S[i, l, 1] - 2.0 * c1[1] - mdy - mmy - c2[1] - c3[1]
        g[i, l, 2] = dg_S[i, l, 2] + sg_S[i, l, 2] - 2.0 * c1[2] - c2[2] - c3[2]
    h = 0.5 * theta
    if scheme == 0:
        sh, ch, sn = math.sin(h), math.cos(h), math.sin(theta)
        dx, dy, dz = g[i, 1, 0] - g[i, 0, 0], g[i, 1, 1] - g[i, 0, 1], g[i, 1, 2] - g[i, 0, 2]
        A[i, 0, 0] = 0.0
        A[i, 0, 1] = (dy * sh - dx * ch) / sn
        A[i, 0, 2] = 0.5 * dz
        A[i, 1, 0] = 0.0
        A[i, 1, 1] = (-dy * sh - dx * ch) / sn
        A[i, 1, 2] = -0.5 * dz
        t = sh / ch
        G_S[i, 0] = 0.5 * (g[i, 0, 0] + g[i, 1, 0]) - 0.5 * t * dy
        G_S[i, 1] = 0.5 * (g[i, 0, 1] + g[i, 1, 1]) - 0.5 * dx / t
        G_S[i, 2] = 0.5 * (g[i, 0, 2] + g[i, 1, 2])
    else:
        # e_l = T_S_OA_l s_l; G = [b1 (e2 x n) + b2 (n x e1) + b3 (e1 x e2)] / (e1 . (e2 x n)), n = Z_S
        c1_, s1_ = math.cos(h), math.sin(h)
        c2_, s2_ = math.cos(-h), math.sin(-h)
        e1x, e1y, e1z = c1_ * sens[0, 0] - s1_ * sens[0, 1], s1_ * sens[0, 0] + c1_ * sens[0, 1], sens[0, 2]
        e2x, e2y, e2z = c2_ * sens[1, 0] - s2_ * sens[1, 1], s2_ * sens[1, 0] + c2_ * sens[1, 1], sens[1, 2]
        b1 = e1x * g[i, 0, 0] + e1y * g[i, 0, 1] + e1z * g[i, 0, 2]
        b2 = e2x * g[i, 1, 0] + e2y * g[i, 1, 1] + e2z * g[i, 1, 2]
        b3 = 0.5 * (g[i, 0, 2] + g[i, 1, 2])
        # e2 x n = (e2y, -e2x, 0), n x e1 = (-e1y, e1x, 0), det = e1 . (e2 x n) = e1x e2y - e1y e2x
        ux, uy, uz = cross((e1x, e1y, e1z), (e2x, e2y, e2z))
        det = e1x * e2y - e1y * e2x
        G_S[i, 0] = (b1 * e2y - b2 * e1y + b3 * ux) / det
        G_S[i, 1] = (-b1 * e2x + b2 * e1x + b3 * uy) / det
        G_S[i, 2] = b3 * uz / det
        for l in range(2):
            c, sp = math.cos(MOSA_SIGN[l] * h), math.sin(MOSA_SIGN[l] * h)
            ax, ay, az = G_S[i, 0] - g[i, l, 0], G_S[i, 1] - g[i, l, 1], G_S[i, 2] - g[i, l, 2]
            A[i, l, 0] = c * ax + sp * ay
            A[i, l, 1] = -sp * ax + c * ay
            A[i, l, 2] = az
    # TM angular acceleration: T_OA_S (w' + w_oa' + w x w_oa)
    for l in range(2):
        s = MOSA_SIGN[l]
        wm = s * 0.5 * theta_dot
        ax = wd[i, 0] + w[i, 1] * wm
        ay = wd[i, 1] - w[i, 0] * wm
        az = wd[i, 2] + s * 0.5 * theta_ddot
        c, sp = math.cos(s * h), math.sin(s * h)
        alpha[i, l, 0] = c * ax + sp * ay
        alpha[i, l, 1] = -sp * ax + c * ay
        alpha[i, l, 2] = az
