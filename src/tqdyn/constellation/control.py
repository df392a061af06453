"""Nominal suspension (electrostatic) and drag-free control of one satellite.

All functions are vectorised numpy: leading axes ``(...)`` are free (in tqdyn
``(N, 3)`` = time, satellite), then ``2`` = TM / MOSA l, then ``3`` =
component.  Units SI (m/s^2, rad/s, rad/s^2, rad); time scale irrelevant
(instantaneous relations; tqdyn uses TT).  Frames: S = nominal satellite
frame, OA_l = MOSA/TM frame (X_S rotated by +theta/2 for l = 1, -theta/2 for
l = 2 about Z_S, see :mod:`tqdyn.constellation.spacecraft`), GCRS inertial.

Derivation (replaces the paper's eq:TMforce, eq:E1, eq:E2, eq:Greal)
--------------------------------------------------------------------
Let R be the satellite CoM, T = T_S_I, and let the TM nominal point be the EH
center r_0 = r_p + rho (S coordinates), where the pivot r_p is fixed in S and
the lever arm rho = r_0 - r_p turns with the MOSA at the relative angular
velocity w_oa = +/- alpha_dot/2 Z_S:  rho' = w_oa x rho,
rho'' = w_oa' x rho + w_oa x (w_oa x rho)  (' = derivative of S coordinates).
The inertial acceleration of that point, expressed in S, is

    R'' + rho'' + 2 w_S x rho' + w_S' x r_0 + w_S x (w_S x r_0).

A TM that stays on it obeys a_grav,TM + sg_l + A_l = a_grav,S + G + (the
terms above), with G the satellite's control (drag-free) acceleration and
sg_l the self-gravity.  Hence  G = A_l + g_l  (eq:TMforcesimple) with

    g_l = (a_grav,TM_l - a_grav,S) + sg_l
          - 2 w_S x (w_oa x rho) - w_oa' x rho - w_oa x (w_oa x rho)
          - w_S x (w_S x r_0) - w_S' x r_0.

This is exactly the curly bracket of eq:TMforce (plus the self-gravity, which
the paper includes in g_l only in words, Fig. 2 caption).  No discrepancy in
the bracket; the paper's symbol ``omega_OA`` must be read as the MOSA rate
*relative to S* (+/- alpha_dot/2 Z_S), not its inertial angular velocity.

Three conditions: (a) G_1 = A_1 + g_1 = A_2 + g_2 = G, (b) A_l . X_OA_l = 0,
(c) A_1 . Z = -A_2 . Z.  With s = sin(theta/2), c = cos(theta/2),
Y_OA_1 = (-s, c, 0), Y_OA_2 = (s, c, 0), A_l = a_l Y_OA_l + b_l Z, and
dg = g_2 - g_1, (a) reads A_1 - A_2 = dg:

    -s (a_1 + a_2) = dg_x,  c (a_1 - a_2) = dg_y,  b_1 - b_2 = dg_z,  b_2 = -b_1

    a_1 = (dg_y s - dg_x c) / sin(theta),  a_2 = (-dg_y s - dg_x c) / sin(theta),
    b_1 = dg_z / 2,  b_2 = -dg_z / 2                      (= eq:E1, eq:E2 as printed)

    G = A_1 + g_1 = ( (g_1x + g_2x)/2 - tan(theta/2) dg_y / 2,
                      (g_1y + g_2y)/2 - cot(theta/2) dg_x / 2,
                      (g_1z + g_2z)/2 ).

The printed eq:Greal has tan(theta), cot(theta) instead: that violates (a)
(:func:`dragfree_as_printed` reproduces it for comparison; the tests measure
the violation).

General scheme (``scheme = "lisa"``; any sensitive axes)
-------------------------------------------------------
The same kind of conditions for sensitive axes e_l (unit vectors fixed in
OA_l, in S: e_l = T_S_OA_l s_l) and the out-of-plane direction n = Z_S:
(a) G = A_l + g_l (l = 1, 2), (b) e_l . A_l = 0 (the spacecraft follows TM l
along its own sensitive axis: no electrostatic actuation there), (c)
n . A_1 = -n . A_2 (equal and opposite out-of-plane actuation).  Nine linear
equations for the nine unknowns G, A_1, A_2.  Dotting (a) with e_l and using
(b): e_l . G = e_l . g_l; adding the two n-components of (a) and using (c):
n . G = n . (g_1 + g_2) / 2.  With M = (e_1; e_2; n) (rows) and det M =
e_1 . (e_2 x n) != 0, Cramer's rule (M^-1 has the columns e_2 x n, n x e_1,
e_1 x e_2 over det M) gives

    G = [ (e_1.g_1) (e_2 x n) + (e_2.g_2) (n x e_1) + (n.(g_1+g_2)/2) (e_1 x e_2) ] / det M,
    A_l = G - g_l.

For e_l = X_OA_l this is the closed form above (tests/test_control.py checks
both, and a sympy solution of the nine equations, to round-off).  det M = 0
(parallel sensitive axes, or both in a plane containing n) leaves G
undetermined: :class:`~tqdyn.constellation.spacecraft.Spacecraft` refuses it.

TM attitude: each TM is kept aligned with OA_l, whose inertial angular
velocity is W = w_S + w_oa (in S).  Its inertial angular acceleration, in S,
is dW/dt = w_S' + w_oa' + w_S x w_oa; expressed in OA_l it is the angular
acceleration the TM needs (Euler's equations for a cubic TM, isotropic inertia,
have no W x (I W) term).  The gravity-gradient torque on a cube vanishes to
first order by symmetry (its inertia tensor is isotropic); an external
angular acceleration (torque / moment of inertia) can be passed and is
subtracted.

Precision: g_l is a sum of ~1e-10 m/s^2 terms cancelling to ~1e-13 m/s^2;
in float64 that costs ~1e-26 m/s^2.  The gravitational difference
a_grav,TM - a_grav,S (two ~4e-2 m/s^2 numbers) must NOT be formed here: the
caller forms it in double-double (or a cancellation-free formula) and passes
the float64 difference.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .attitude import T_OA_S_of
from .indices import MOSA_SIGN
from .spacecraft import Spacecraft

__all__ = [
    "NominalControl",
    "dragfree_acceleration",
    "dragfree_as_printed",
    "dragfree_general",
    "mosa_angular_rates",
    "nominal_control",
    "oa_rotation",
    "suspension_acceleration",
    "tm_angular_acceleration",
    "tm_relative_acceleration",
]


def _f64(x, name: str, tail: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.shape[a.ndim - len(tail):] != tail or a.ndim < len(tail):
        raise ValueError(f"{name} has shape {a.shape}; allowed: (..., {', '.join(map(str, tail))})")
    return a


def oa_rotation(theta) -> np.ndarray:
    """T_OA_S for both MOSAs: rows X_OA_l, Y_OA_l, Z_OA_l in S coordinates.

    ``theta``: MOSA opening angle alpha_i, rad, shape (...).  Returns shape
    (..., 2, 3, 3); ``[..., l-1, :, :]`` maps S vectors into OA_l.  OA_1 is
    X_S rotated by +theta/2 about Z_S, OA_2 by -theta/2.
    """
    half = 0.5 * np.asarray(theta, dtype=np.float64)
    return T_OA_S_of(half[..., None] * MOSA_SIGN)


def mosa_angular_rates(alpha_dot, alpha_ddot) -> tuple[np.ndarray, np.ndarray]:
    """MOSA angular velocity and acceleration relative to S, in S.

    ``alpha_dot`` [rad/s], ``alpha_ddot`` [rad/s^2]: breathing-angle rates,
    shape (...).  Returns (omega_mosa, omega_dot_mosa), each (..., 2, 3):
    (0, 0, +alpha_dot/2) for l = 1 and (0, 0, -alpha_dot/2) for l = 2
    (likewise with alpha_ddot).
    """
    ad = np.asarray(alpha_dot, dtype=np.float64)
    add = np.asarray(alpha_ddot, dtype=np.float64)
    w = np.zeros(np.broadcast_shapes(ad.shape, add.shape) + (2, 3))
    wd = np.zeros_like(w)
    w[..., 2] = 0.5 * ad[..., None] * MOSA_SIGN
    wd[..., 2] = 0.5 * add[..., None] * MOSA_SIGN
    return w, wd


def tm_relative_acceleration(dg_gravity_S, omega_S, omega_dot_S, omega_mosa, omega_dot_mosa,
                             r0, rho, self_gravity_S=None) -> np.ndarray:
    """g_l, the bracket of eq:TMforce (derivation in the module docstring), in S.

    Parameters (all in the S frame)
    ----------
    dg_gravity_S : (..., 2, 3) m/s^2, a_grav(TM_l) - a_grav(satellite CoM).
    omega_S, omega_dot_S : (..., 3) rad/s, rad/s^2, satellite angular velocity
        and acceleration w.r.t. the inertial frame.
    omega_mosa, omega_dot_mosa : (..., 2, 3) MOSA rates relative to S.
    r0 : (..., 2, 3) m, EH centers; rho : (..., 2, 3) m, r0 - pivot.
    self_gravity_S : (..., 2, 3) m/s^2 or None.

    Returns (..., 2, 3) m/s^2 in S.
    """
    dg = _f64(dg_gravity_S, "dg_gravity_S", (2, 3))
    w = _f64(omega_S, "omega_S", (3,))[..., None, :]
    wd = _f64(omega_dot_S, "omega_dot_S", (3,))[..., None, :]
    wm = _f64(omega_mosa, "omega_mosa", (2, 3))
    wmd = _f64(omega_dot_mosa, "omega_dot_mosa", (2, 3))
    r0 = _f64(r0, "r0", (2, 3))
    rho = _f64(rho, "rho", (2, 3))
    cr = np.cross
    g = (dg
         - 2.0 * cr(w, cr(wm, rho)) - cr(wmd, rho) - cr(wm, cr(wm, rho))
         - cr(w, cr(w, r0)) - cr(wd, r0))
    if self_gravity_S is not None:
        g = g + _f64(self_gravity_S, "self_gravity_S", (2, 3))
    return g


def suspension_acceleration(g, theta) -> np.ndarray:
    """Suspension control A_c,l of both TMs in their OA_l frames (eq:E1, eq:E2).

    ``g``: (..., 2, 3) m/s^2, g_l in S; ``theta``: (...) rad.  Returns
    (..., 2, 3) m/s^2, component ``[..., l-1, :]`` in OA_l (x component is 0).
    """
    g = _f64(g, "g", (2, 3))
    th = np.asarray(theta, dtype=np.float64)
    dg = g[..., 1, :] - g[..., 0, :]
    s, c, sn = np.sin(0.5 * th), np.cos(0.5 * th), np.sin(th)
    out = np.zeros(np.broadcast_shapes(dg.shape[:-1], th.shape) + (2, 3))
    out[..., 0, 1] = (dg[..., 1] * s - dg[..., 0] * c) / sn
    out[..., 1, 1] = (-dg[..., 1] * s - dg[..., 0] * c) / sn
    out[..., 0, 2] = 0.5 * dg[..., 2]
    out[..., 1, 2] = -0.5 * dg[..., 2]
    return out


def dragfree_acceleration(g, theta) -> np.ndarray:
    """Drag-free acceleration G of the satellite, in S, derived from the conditions.

    G = ((g1x+g2x)/2 - tan(theta/2) dg_y/2, (g1y+g2y)/2 - cot(theta/2) dg_x/2,
    (g1z+g2z)/2), dg = g_2 - g_1.  ``g``: (..., 2, 3) m/s^2 in S; ``theta``:
    (...) rad.  Returns (..., 3) m/s^2 in S.
    """
    g = _f64(g, "g", (2, 3))
    th = np.asarray(theta, dtype=np.float64)
    dg = g[..., 1, :] - g[..., 0, :]
    mean = 0.5 * (g[..., 0, :] + g[..., 1, :])
    t = np.tan(0.5 * th)
    out = np.array(np.broadcast_to(mean, np.broadcast_shapes(mean.shape, th.shape + (3,))))
    out[..., 0] -= 0.5 * t * dg[..., 1]
    out[..., 1] -= 0.5 * dg[..., 0] / t
    return out


def dragfree_general(g, theta, sensitive_axes=None) -> tuple[np.ndarray, np.ndarray]:
    """Drag-free G and suspensions A_l of the general scheme (module docstring).

    ``g``: (..., 2, 3) m/s^2, g_l in S; ``theta``: (...) rad;
    ``sensitive_axes``: (2, 3) unit vectors in OA_l (None: X_OA_l).  Returns
    (G_S (..., 3) m/s^2 in S, A (..., 2, 3) m/s^2 with ``A[..., l, :]`` in OA_l).
    """
    g = _f64(g, "g", (2, 3))
    th = np.asarray(theta, dtype=np.float64)
    sens = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]) if sensitive_axes is None else \
        _f64(sensitive_axes, "sensitive_axes", (2, 3))
    T = oa_rotation(th)                                   # (..., 2, 3, 3): S -> OA_l
    e = np.einsum("...lji,lj->...li", T, sens)            # e_l in S
    n = np.array([0.0, 0.0, 1.0])
    e1, e2 = e[..., 0, :], e[..., 1, :]
    det = np.einsum("...i,...i->...", e1, np.cross(e2, n))
    b1 = np.einsum("...i,...i->...", e1, g[..., 0, :])
    b2 = np.einsum("...i,...i->...", e2, g[..., 1, :])
    b3 = 0.5 * (g[..., 0, 2] + g[..., 1, 2])
    G = (b1[..., None] * np.cross(e2, n) + b2[..., None] * np.cross(n, e1)
         + b3[..., None] * np.cross(e1, e2)) / det[..., None]
    A_S = G[..., None, :] - g
    return G, np.einsum("...lij,...lj->...li", T, A_S)


def dragfree_as_printed(g, theta) -> np.ndarray:
    """eq:Greal exactly as printed (tan(theta), cot(theta)) -- WRONG, for comparison only.

    Same shapes and units as :func:`dragfree_acceleration`.  It violates
    condition (a) (equal TM accelerations in S) by
    |dg| * |tan(theta) - tan(theta/2)| / 2 (x) and |cot(theta) - cot(theta/2)| / 2 (y).
    """
    g = _f64(g, "g", (2, 3))
    th = np.asarray(theta, dtype=np.float64)
    dg = g[..., 1, :] - g[..., 0, :]
    out = 0.5 * (g[..., 0, :] + g[..., 1, :])
    out[..., 0] -= 0.5 * np.tan(th) * dg[..., 1]
    out[..., 1] -= 0.5 * dg[..., 0] / np.tan(th)
    return out


def tm_angular_acceleration(omega_S, omega_dot_S, omega_mosa, omega_dot_mosa, theta,
                            external=None) -> np.ndarray:
    """Angular acceleration the suspension must give each TM, in OA_l (``tm/alpha_suspension``).

    The inertial angular acceleration of OA_l, T_OA_S (w_S' + w_oa' + w_S x w_oa),
    minus ``external`` (an external torque / moment of inertia acting on the TM,
    rad/s^2, in OA_l, e.g. a gravity-gradient torque; zero for a cube).
    Inputs in S: omega_S, omega_dot_S (..., 3); omega_mosa, omega_dot_mosa
    (..., 2, 3); theta (...) rad.  Returns (..., 2, 3) rad/s^2 in OA_l.
    """
    w = _f64(omega_S, "omega_S", (3,))[..., None, :]
    wd = _f64(omega_dot_S, "omega_dot_S", (3,))[..., None, :]
    wm = _f64(omega_mosa, "omega_mosa", (2, 3))
    wmd = _f64(omega_dot_mosa, "omega_dot_mosa", (2, 3))
    a_S = wd + wmd + np.cross(w, wm)
    out = np.einsum("...ij,...j->...i", oa_rotation(theta), a_S)
    if external is not None:
        out = out - _f64(external, "external", (2, 3))
    return out


@dataclass(frozen=True)
class NominalControl:
    """Outputs of :func:`nominal_control` (shapes for inputs with leading axes (N, 3)).

    g : (N, 3, 2, 3) m/s^2, g_l in S (differential gravity + inertial + self-gravity).
    a_suspension : (N, 3, 2, 3) m/s^2, A_c,l in OA_l (``tm/a_suspension``).
    a_dragfree_S : (N, 3, 3) m/s^2, G in S.
    a_dragfree : (N, 3, 3) m/s^2, G in GCRS (``sat/a_dragfree``).
    alpha_suspension : (N, 3, 2, 3) rad/s^2 in OA_l (``tm/alpha_suspension``).
    """

    g: np.ndarray
    a_suspension: np.ndarray
    a_dragfree_S: np.ndarray
    a_dragfree: np.ndarray
    alpha_suspension: np.ndarray


def nominal_control(T_S_I, omega_S, omega_dot_S, theta, omega_mosa, omega_dot_mosa,
                    dg_gravity, spacecraft: Spacecraft | None = None, tm_torque=None) -> NominalControl:
    """Nominal suspension and drag-free control of all satellites at all times.

    Parameters
    ----------
    T_S_I : (N, 3, 3, 3) rotation GCRS -> S (rows X_S, Y_S, Z_S).
    omega_S, omega_dot_S : (N, 3, 3) rad/s, rad/s^2, in S (w.r.t. GCRS).
    theta : (N, 3) rad, MOSA opening angle = breathing angle alpha_i.
    omega_mosa, omega_dot_mosa : (N, 3, 2, 3) rad/s, rad/s^2 in S, MOSA rates
        relative to S (see :func:`mosa_angular_rates`).
    dg_gravity : (N, 3, 2, 3) m/s^2, GCRS, a_grav(TM_l) - a_grav(satellite),
        formed by the caller without cancellation (double-double).  Gravity at
        the actual TM positions (the EH centers in the nominal state).
    spacecraft : architecture and drag-free scheme (default ``Spacecraft()``:
        the ``tianqin`` preset with Table IV self-gravity).
    tm_torque : (N, 3, 2, 3) rad/s^2 in OA_l or None, external angular
        acceleration on the TMs.

    Any leading axes (...) instead of (N, 3) work the same way (the
    satellite axis must be present, length 3, for the per-satellite
    self-gravity).  Time scale: instantaneous (TT in tqdyn).
    """
    sc = Spacecraft() if spacecraft is None else spacecraft
    T = _f64(T_S_I, "T_S_I", (3, 3))
    th = np.asarray(theta, dtype=np.float64)
    dg_I = _f64(dg_gravity, "dg_gravity", (2, 3))
    dg_S = np.einsum("...ij,...lj->...li", T, dg_I)
    T_OA_S = oa_rotation(th)
    sg_S = np.einsum("...lji,...lj->...li", T_OA_S, sc.self_gravity_array)  # T_S_OA sg
    r0 = sc.housing_centers(th)
    rho = sc.lever_arms(th)
    g = tm_relative_acceleration(dg_S, omega_S, omega_dot_S, omega_mosa, omega_dot_mosa, r0, rho, sg_S)
    if sc.scheme == "tianqin":
        A = suspension_acceleration(g, th)
        G_S = dragfree_acceleration(g, th)
    else:
        G_S, A = dragfree_general(g, th, sc.sensitive_axes_array)
    G_I = np.einsum("...ji,...j->...i", T, G_S)
    alpha = tm_angular_acceleration(omega_S, omega_dot_S, omega_mosa, omega_dot_mosa, th, tm_torque)
    return NominalControl(g=g, a_suspension=A, a_dragfree_S=G_S, a_dragfree=G_I, alpha_suspension=alpha)
