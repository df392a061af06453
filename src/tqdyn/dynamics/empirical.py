"""Acceleration parameters of point-mass satellites: a constant acceleration in the
constellation's S frame and empirical constant and once-per-revolution accelerations in RTN.

Per satellite b the propagation can carry :data:`N_PAR` = 12 parameters p [m/s^2]
(names :data:`PARAMETER_NAMES`, in this order), and adds

    a_b = T_I_S (p0, p1, p2) + (R T N) (p3, p4, p5)
          + cos(u) (R T N) (p6, p7, p8) + sin(u) (R T N) (p9, p10, p11)

to the satellite's acceleration, i.e. a_b = B_b p with the (3, 12) basis B_b of
:func:`empirical_basis` (the partial derivative of a_b with respect to p).

* S frame: the frame of the global pointing law (:mod:`tqdyn.constellation._kinematics_jit`)
  at the instantaneous positions of the three satellites: for satellite i (0-based) with
  j = (i + 1) % 3, k = (i + 2) % 3 and n_ij = unit(r_j - r_i),
  X_S = unit(n_ij + n_ik) (the bisector, toward the incentre), Z_S = unit(n_ij x n_ik)
  (normal to the constellation plane), Y_S = Z_S x X_S.  It needs exactly three satellites
  (bodies 0..2).  This is the direction of the DC self-gravity of the test masses, which a
  drag-free satellite follows.
* RTN: R = r / |r|, N = (r x v) / |r x v|, T = N x R from the satellite's own position r
  and velocity v relative to the central body (the run's frame).
* u: argument of latitude, the angle in the orbit plane from the ascending node on the
  frame's xy plane (GCRS or ICRF equator) to r: cos u = (R_y N_x - R_x N_y) / sin i,
  sin u = R_z / sin i (undefined for an orbit in the xy plane, sin i = 0).

Everything is formed in float64 from the (dd or float64) state; the arm differences
r_j - r_i from both parts of a dd position, as :func:`tqdyn.dynamics.rhs.toward_centre`
does.  The accelerations are SI [m/s^2] in the run's frame (GCRS or BCRS axes).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..numerics.dd import add, ld, st, sub, to_f64

__all__ = ["N_PAR", "PARAMETER_NAMES", "add_empirical", "empirical_basis", "s_frame_rows"]

#: Names of the per-satellite parameters, in the order of the basis columns.
PARAMETER_NAMES = ("s_x", "s_y", "s_z", "rtn_r", "rtn_t", "rtn_n",
                   "cos_r", "cos_t", "cos_n", "sin_r", "sin_t", "sin_n")
N_PAR = len(PARAMETER_NAMES)


@njit(cache=True)
def _unit(x, y, z):
    n = np.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@njit(cache=True)
def s_frame_rows(y, i, out):
    """Rows X_S, Y_S, Z_S (out (3, 3), float64, unit vectors in the run's frame) of
    satellite i (0..2) from the positions of bodies 0..2 of y (n_body, 6[, 2])."""
    j, k = (i + 1) % 3, (i + 2) % 3
    ax, ay, az = _unit(to_f64(sub(ld(y, j, 0), ld(y, i, 0))), to_f64(sub(ld(y, j, 1), ld(y, i, 1))),
                       to_f64(sub(ld(y, j, 2), ld(y, i, 2))))
    bx, by, bz = _unit(to_f64(sub(ld(y, k, 0), ld(y, i, 0))), to_f64(sub(ld(y, k, 1), ld(y, i, 1))),
                       to_f64(sub(ld(y, k, 2), ld(y, i, 2))))
    xx, xy, xz = _unit(ax + bx, ay + by, az + bz)
    zx, zy, zz = _unit(ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)
    out[0, 0], out[0, 1], out[0, 2] = xx, xy, xz
    out[2, 0], out[2, 1], out[2, 2] = zx, zy, zz
    out[1, 0], out[1, 1], out[1, 2] = zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx


@njit(cache=True)
def empirical_basis(y, b, with_s, B):
    """B (3, N_PAR) float64 <- the basis of satellite b's parameter accelerations
    (module docstring) at the state y (n_body, 6[, 2]) [m, m/s]; with_s: fill the S-frame
    columns (three satellites), else leave them zero."""
    rx, ry, rz = to_f64(ld(y, b, 0)), to_f64(ld(y, b, 1)), to_f64(ld(y, b, 2))
    vx, vy, vz = to_f64(ld(y, b, 3)), to_f64(ld(y, b, 4)), to_f64(ld(y, b, 5))
    Rx, Ry, Rz = _unit(rx, ry, rz)
    Nx, Ny, Nz = _unit(ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx)
    Tx, Ty, Tz = Ny * Rz - Nz * Ry, Nz * Rx - Nx * Rz, Nx * Ry - Ny * Rx
    c, s = Ry * Nx - Rx * Ny, Rz
    rho = np.sqrt(c * c + s * s)
    cu, su = c / rho, s / rho
    for m in range(12):
        B[0, m], B[1, m], B[2, m] = 0.0, 0.0, 0.0
    if with_s:
        S = np.empty((3, 3))
        s_frame_rows(y, b, S)
        for m in range(3):
            B[0, m], B[1, m], B[2, m] = S[m, 0], S[m, 1], S[m, 2]
    for g, f in ((1, 1.0), (2, cu), (3, su)):
        o = 3 * g
        B[0, o], B[1, o], B[2, o] = f * Rx, f * Ry, f * Rz
        B[0, o + 1], B[1, o + 1], B[2, o + 1] = f * Tx, f * Ty, f * Tz
        B[0, o + 2], B[1, o + 2], B[2, o + 2] = f * Nx, f * Ny, f * Nz


@njit(cache=True)
def add_empirical(y, p, k):
    """Add the parameter accelerations of every satellite to k (n_body, 6[, 2]).

    p: (n_sat, N_PAR) float64 parameters [m/s^2] of bodies 0..n_sat-1 (S-frame columns
    only used, and only allowed, with three satellites).  The sum B p is float64 and
    added to the dd acceleration with one dd addition per component."""
    B = np.empty((3, 12))
    n = p.shape[0]
    for b in range(n):
        with_s = n == 3 and (p[b, 0] != 0.0 or p[b, 1] != 0.0 or p[b, 2] != 0.0)
        empirical_basis(y, b, with_s, B)
        for q in range(3):
            acc = 0.0
            for m in range(12):
                acc += B[q, m] * p[b, m]
            st(k, add(ld(k, b, q + 3), acc), b, q + 3)
