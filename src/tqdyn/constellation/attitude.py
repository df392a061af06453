"""Nominal attitude of the three satellites and six MOSAs; angular velocity and acceleration.

What this module computes (paper sec. III.A and appendix A, re-derived; the
derivation is written out below because the paper has errors)
---------------------------------------------------------------------------------
For satellite i with the even permutation (i, j, k) and the two *beam* unit
vectors b_ij, b_ik (from i towards j and k; which vectors depends on the
pointing law, see below):

* ``X_S = (b_ij + b_ik) / |b_ij + b_ik|`` -- the bisector.  For the global law
  this *is* the direction to the incenter: r_inc - R_i = L_ij L_ik (n_ij + n_ik) / P
  with P the perimeter, so the paper's two definitions coincide;
* ``Z_S = b_ij x b_ik / sin(theta_i)``, ``sin(theta_i) = |b_ij x b_ik|``;
* ``Y_S = Z_S x X_S``;  ``T_S_I`` has rows X_S, Y_S, Z_S (GCRS components).
* theta_i = angle between the two beams = atan2(|b_ij x b_ik|, b_ij . b_ik)
  (the breathing angle alpha_i for the global law).
* OA_1 = S rotated by +theta/2 about Z_S, so X_OA1 = cos(theta/2) X_S +
  sin(theta/2) Y_S = b_ik (faces satellite k); OA_2 = S rotated by -theta/2
  (X_OA2 = b_ij, faces j).  ``T_OA_S = [[c, s, 0], [-s, c, 0], [0, 0, 1]]`` with
  (c, s) = (cos, sin) of the MOSA angle phi_l = +/- theta/2; MOSA rates
  +/- theta_dot/2, accelerations +/- theta_ddot/2.

Angular velocity and acceleration (both expressed in S).  From the Poisson
relation ``T_S_I dT_I_S/dt = [omega_S x]`` (columns of T_I_S are X, Y, Z)::

    omega_S = (Z . dY/dt,  X . dZ/dt,  Y . dX/dt)
    omega_dot_S = d/dt omega_S  (component-wise; the derivative of the S
                  components equals the inertial angular acceleration expressed
                  in S, because d/dt(T w) = T w_dot - omega x omega = T w_dot)
                = (Z'.Y' + Z.Y'',  X'.Z' + X.Z'',  Y'.X' + Y.X'')

The derivatives of the unit vectors follow from u = w/|w| (L = |w|):
``u' = (w' - L' u)/L``, ``L' = u.w'``; ``u'' = (w'' - L'' u - 2 L' u')/L``,
``L'' = u'.w' + u.w''``.  So omega needs the beams' first derivatives and
omega_dot their second derivatives: for the global law the velocities and
accelerations of the three satellites (no jerk); for the Taylor laws the beam
contains -v_j/c, so omega_dot needs the remote satellite's *jerk* (and taylor2
its snap, whose contribution is <= |a| L n^2 / (2 c^2) ~ 2e-20 rad/s^2; it is
optional).  :func:`tqdyn.forces.central.central_jerk_snap` gives the monopole jerk/snap; the
perturbations (< 1e-5 m/s^2) change the jerk by < 1e-5 n ~ 2e-10 m/s^3, i.e.
omega_dot by < 1e-18 rad/s^2 through the 1/c factor.

The accelerations passed in are whatever the caller integrates: if they
include the drag-free acceleration G_i, omega_dot includes that feedback
(~1e-18 m/s^2 / L, negligible); the module does not add anything itself.

Two methods are implemented for the global law:

* ``method="direct"`` -- the Poisson relation above with the frame vectors
  differentiated analytically (also used for the Taylor laws);
* ``method="p-frame"`` -- the appendix: an auxiliary frame p with z_p = Z_S,
  x_p along the projection of the inertial Z_I on the constellation plane.
  The paper prints ``x_p = (cos(beta) z_p - Z_I)/sin(beta)``, which points
  *opposite* to the projection its text describes; we use the text's choice
  ``x_p = (Z_I - cos(beta) z_p)/sin(beta)`` (omega_S does not depend on it).
  Then with rho = T_p_I (R_i - r_inc) (p coordinates of satellite i relative to
  the incenter; it lies in the plane, rho_z = 0)::

      rho'  = T_p_I d(R_i - r_inc)/dt + T_p_I' (R_i - r_inc)
      rho'' = T_p_I d2(...)/dt2 + 2 T_p_I' d(...)/dt + T_p_I'' (R_i - r_inc)

  -- the time derivatives of the *p-frame coordinates*, not inertial velocities
  rotated into p (that mistake gives ~3e-9 rad/s errors).  With x = -rho/|rho|::

      omega_i/p     = rho' x x / |rho|
      omega_dot_i/p = (2 (x . rho') omega_i/p - x x rho'') / |rho|
      omega_S     = T_S_p (omega_p + omega_i/p)
      omega_dot_S = T_S_p (omega_dot_p + omega_dot_i/p + omega_p x omega_i/p)

  The last term is the paper's ``T_S_p' (omega_p + omega_i/p)`` written out
  (T_S_p' Omega = T_S_p (Omega x omega_i/p)).

Pointing laws (beam vectors b_ij, with tau = L_ij / c as in eq. pointing2):

* ``"global"``  -- b_ij = n_ij (instantaneous positions, eq. geometrypointing);
* ``"taylor1"`` -- b_ij = unit(n_ij - v_j / c)   (first-order Taylor of the
  emission position r_j(t - tau) = r_j - v_j tau, divided by c tau);
* ``"taylor2"`` -- b_ij = unit(n_ij - v_j / c + a_j L_ij / (2 c^2)).
  The beam vectors are normalised *before* forming the bisector and normal
  (docs/design.md, Traps).  Their derivatives are taken analytically from the same
  expressions, so the rates are consistent with the attitude they produce
  (tested against finite differences of the frames).

Inputs and shapes
-----------------
All functions are vectorised over any leading shape ``...`` (typically time,
N): positions ``r`` (..., 3, 3) = (..., satellite 1..3, xyz) in m, GCRS; or a
pair ``(hi, lo)`` of such float64 arrays (double-double; the satellite
differences are then formed with the low parts, so arm vectors keep full
float64 precision).  ``v`` (m/s), ``a`` (m/s^2), ``jerk`` (m/s^3), ``snap``
(m/s^4) likewise, GCRS.  All at the same epochs (TT seconds; the time scale
only matters through the caller's epochs).  Outputs are float64: frames are
unit vectors, float64 is at the 1e-16 rad level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._choices import unknown
from ..astro.constants import C_LIGHT
from .indices import MOSA_SIGN, PARTNERS, Mosa, Sat

__all__ = [
    "LAWS",
    "METHODS",
    "Attitude",
    "attitude",
    "beam_vectors",
    "T_OA_S_of",
    "Sat",
    "Mosa",
]

#: Pointing laws understood by :func:`attitude`.
LAWS = ("global", "taylor1", "taylor2")
#: Methods for omega / omega_dot understood by :func:`attitude`.
METHODS = ("direct", "p-frame")

_I = np.arange(3)
_J = PARTNERS[:, 0]   # j of the even permutation (i, j, k)
_K = PARTNERS[:, 1]   # k


# --------------------------------------------------------------------------
# small jet helpers: a "jet" is a tuple (x, x', x'') with trailing entries None
# when not available; vectors have a trailing axis of length 3.


def _as_f64_parts(x):
    """(hi, lo) pair or plain array -> (hi, lo) float64 arrays (lo may be zeros)."""
    if isinstance(x, tuple):
        hi, lo = x
        return np.asarray(hi, dtype=np.float64), np.asarray(lo, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    return x, None


def _diff(x, idx_to, idx_from):
    """x[..., to, :] - x[..., from, :] for (..., 3, 3) input (hi/lo aware), float64."""
    if x is None:
        return None
    hi, lo = _as_f64_parts(x)
    d = hi[..., idx_to, :] - hi[..., idx_from, :]
    if lo is not None:
        d = d + (lo[..., idx_to, :] - lo[..., idx_from, :])
    return d


def _pick(x, idx):
    """x[..., idx, :] as float64 (hi + lo if a pair)."""
    if x is None:
        return None
    hi, lo = _as_f64_parts(x)
    out = hi[..., idx, :]
    if lo is not None:
        out = out + lo[..., idx, :]
    return out


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _cross(a, b):
    return np.cross(a, b)


def _unit_jet(w):
    """Unit vector u = w/|w| and its derivatives, with |w| and its derivatives.

    w = (w0, w1, w2) with w1/w2 possibly None.  Returns (u-jet, L-jet).
    """
    w0, w1, w2 = w
    L = np.sqrt(_dot(w0, w0))
    u = w0 / L[..., None]
    u1 = u2 = L1 = L2 = None
    if w1 is not None:
        L1 = _dot(u, w1)
        u1 = (w1 - L1[..., None] * u) / L[..., None]
        if w2 is not None:
            L2 = _dot(u1, w1) + _dot(u, w2)
            u2 = (w2 - L2[..., None] * u - 2.0 * L1[..., None] * u1) / L[..., None]
    return (u, u1, u2), (L, L1, L2)


def _cross_jet(a, b):
    c0 = _cross(a[0], b[0])
    c1 = c2 = None
    if a[1] is not None and b[1] is not None:
        c1 = _cross(a[1], b[0]) + _cross(a[0], b[1])
        if a[2] is not None and b[2] is not None:
            c2 = _cross(a[2], b[0]) + 2.0 * _cross(a[1], b[1]) + _cross(a[0], b[2])
    return (c0, c1, c2)


def _dot_jet(a, b):
    c0 = _dot(a[0], b[0])
    c1 = c2 = None
    if a[1] is not None and b[1] is not None:
        c1 = _dot(a[1], b[0]) + _dot(a[0], b[1])
        if a[2] is not None and b[2] is not None:
            c2 = _dot(a[2], b[0]) + 2.0 * _dot(a[1], b[1]) + _dot(a[0], b[2])
    return (c0, c1, c2)


def _add_jet(a, b, sb=1.0):
    return tuple(None if (x is None or y is None) else x + sb * y for x, y in zip(a, b))


def _scale_jet(s, a):
    """scalar-jet * vector-jet (product rule)."""
    c0 = s[0][..., None] * a[0]
    c1 = c2 = None
    if s[1] is not None and a[1] is not None:
        c1 = s[1][..., None] * a[0] + s[0][..., None] * a[1]
        if s[2] is not None and a[2] is not None:
            c2 = s[2][..., None] * a[0] + 2.0 * s[1][..., None] * a[1] + s[0][..., None] * a[2]
    return (c0, c1, c2)


# --------------------------------------------------------------------------
# public helpers


def _arm_jet(r, v, a, idx_to):
    """Inertial arm vector R_to - R_i for every satellite i, with derivatives."""
    return (_diff(r, idx_to, _I), _diff(v, idx_to, _I), _diff(a, idx_to, _I))


def beam_vectors(r, v=None, a=None, *, law="global", jerk=None, snap=None, c=C_LIGHT):
    """Unit beam vectors b_ij, b_ik of the pointing law and their time derivatives.

    Parameters
    ----------
    r, v, a : (..., 3, 3) positions [m], velocities [m/s], accelerations
        [m/s^2] of satellites 1..3, GCRS, at the same epochs (TT).  Each may be
        a (hi, lo) pair.  ``v`` / ``a`` may be None (fewer derivatives).
    law : "global" | "taylor1" | "taylor2" (see module docstring).
    jerk, snap : (..., 3, 3) m/s^3, m/s^4, GCRS -- needed for the second
        derivative under the Taylor laws (jerk for taylor1/2; snap optional for
        taylor2, taken as zero if None: error <= |a| L n^2/(2c^2) ~ 2e-20).
    c : speed of light, m/s.

    Returns
    -------
    (b_ij, b_ij', b_ij''), (b_ik, b_ik', b_ik'') : each (..., 3, 3) =
        (..., satellite i, xyz), dimensionless, 1/s, 1/s^2, GCRS; derivatives
        that cannot be formed from the inputs are None.
    """
    if law not in LAWS:
        raise ValueError(unknown("pointing law", law, LAWS))
    beams = []
    for idx in (_J, _K):
        d = _arm_jet(r, v, a, idx)
        n, L = _unit_jet(d)
        if law == "global":
            beams.append(n)
            continue
        if v is None:
            raise ValueError(f"law {law!r} needs the velocities v")
        vr = (_pick(v, idx), _pick(a, idx), _pick(jerk, idx))
        w = _add_jet(n, vr, -1.0 / c)   # n_ij - v_j/c and derivatives (a_j, jerk_j)
        if law == "taylor2":
            if a is None:
                raise ValueError("law 'taylor2' needs the accelerations a")
            sn = _pick(snap, idx) if snap is not None else np.zeros_like(vr[0])
            half = 1.0 / (2.0 * c * c)
            # + a_j L_ij / (2 c^2): product rule with the jets of L_ij and (a_j, jerk_j, snap_j)
            term = _scale_jet(tuple(None if x is None else x * half for x in L), (vr[1], vr[2], sn))
            w = _add_jet(w, term)
        beams.append(_unit_jet(w)[0])
    return beams[0], beams[1]


def T_OA_S_of(phi):
    """Rotation matrices S -> OA for MOSA angles ``phi`` (rad, about Z_S).

    Parameters
    ----------
    phi : (...,) rad, angle of X_OA from X_S about Z_S (+theta/2 for OA_1,
        -theta/2 for OA_2).

    Returns
    -------
    (..., 3, 3) rows X_OA, Y_OA, Z_OA expressed in S.
    """
    phi = np.asarray(phi, dtype=np.float64)
    cp, sp = np.cos(phi), np.sin(phi)
    out = np.zeros(phi.shape + (3, 3))
    out[..., 0, 0] = cp
    out[..., 0, 1] = sp
    out[..., 1, 0] = -sp
    out[..., 1, 1] = cp
    out[..., 2, 2] = 1.0
    return out


@dataclass
class Attitude:
    """Nominal attitude of satellites and MOSAs at N epochs (leading shape ``...``).

    All float64.  Satellite axis: Sat.index (0, 1, 2 = Sat 1, 2, 3); MOSA axis:
    Mosa.index (0 = OA_1 facing k, 1 = OA_2 facing j).  Fields that need inputs
    not given (v, a, jerk) are None.

    Attributes
    ----------
    T_S_I : (..., 3, 3, 3) rotation GCRS -> S (rows X_S, Y_S, Z_S).
    theta, theta_dot, theta_ddot : (..., 3) rad, rad/s, rad/s^2 -- angle between
        the two beams (= breathing angle alpha_i for the global law) and rates.
    omega, omega_dot : (..., 3, 3) rad/s, rad/s^2 -- inertial angular velocity
        and angular acceleration of S, expressed in S.
    mosa_angle, mosa_rate, mosa_accel : (..., 3, 2) rad, rad/s, rad/s^2 --
        angle of X_OA_l from X_S about Z_S (+theta/2, -theta/2) and rates.
    T_OA_S : (..., 3, 2, 3, 3) rotation S -> OA_l.
    omega_oa, omega_dot_oa : (..., 3, 2, 3) rad/s, rad/s^2 -- inertial angular
        velocity / acceleration of OA_l, expressed in OA_l:
        T_OA_S (omega_S + phi' e_z) and T_OA_S (omega_dot_S + phi'' e_z +
        omega_S x phi' e_z).  The latter is the angular acceleration a TM kept
        aligned with OA_l needs (docs/design.md, Conventions; ``tm/alpha_suspension``).
    law, method : str.
    """

    T_S_I: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray | None
    theta_ddot: np.ndarray | None
    omega: np.ndarray | None
    omega_dot: np.ndarray | None
    mosa_angle: np.ndarray
    mosa_rate: np.ndarray | None
    mosa_accel: np.ndarray | None
    T_OA_S: np.ndarray
    omega_oa: np.ndarray | None
    omega_dot_oa: np.ndarray | None
    law: str
    method: str

    @property
    def T_OA_I(self) -> np.ndarray:
        """(..., 3, 2, 3, 3) rotation GCRS -> OA_l (= T_OA_S @ T_S_I)."""
        return self.T_OA_S @ self.T_S_I[..., None, :, :]

    def axis(self, sat: Sat, which: str = "X") -> np.ndarray:
        """(..., 3) GCRS unit vector X_S, Y_S or Z_S of satellite ``sat``."""
        return self.T_S_I[..., Sat(sat).index, "XYZ".index(which), :]


def _frames_from_beams(bj, bk):
    """S-frame axes jets and theta jet from the two beam jets."""
    s = _add_jet(bj, bk)
    X, _ = _unit_jet(s)
    Z, sin_jet = _unit_jet(_cross_jet(bj, bk))
    Y = _cross_jet(Z, X)
    cos_jet = _dot_jet(bj, bk)
    theta = np.arctan2(sin_jet[0], cos_jet[0])
    th1 = th2 = None
    if cos_jet[1] is not None:
        th1 = -cos_jet[1] / sin_jet[0]
        if cos_jet[2] is not None:
            th2 = -(cos_jet[2] + th1**2 * cos_jet[0]) / sin_jet[0]
    return X, Y, Z, (theta, th1, th2)


def _omega_poisson(X, Y, Z):
    """omega, omega_dot in the frame (rows X, Y, Z) from the axis jets (Poisson)."""
    if X[1] is None:
        return None, None
    om = np.stack([_dot(Z[0], Y[1]), _dot(X[0], Z[1]), _dot(Y[0], X[1])], axis=-1)
    if X[2] is None:
        return om, None
    omd = np.stack([_dot(Z[1], Y[1]) + _dot(Z[0], Y[2]),
                    _dot(X[1], Z[1]) + _dot(X[0], Z[2]),
                    _dot(Y[1], X[1]) + _dot(Y[0], X[2])], axis=-1)
    return om, omd


def _matvec(T, x):
    return np.einsum("...ab,...b->...a", T, x)


def _p_frame_omega(r, v, a, Z):
    """omega_S, omega_dot_S and T_S_I (global law) by the appendix p-frame method."""
    # incenter offset R_i - r_inc = -(L_ik d_ij + L_ij d_ik) / P (P = perimeter),
    # formed from arm differences only (no large-number cancellation).
    dj = _arm_jet(r, v, a, _J)
    dk = _arm_jet(r, v, a, _K)
    _, Lj = _unit_jet(dj)   # L_ij for every i
    _, Lk = _unit_jet(dk)   # L_ik for every i
    # perimeter = L_12 + L_23 + L_31 = sum over i of L_ij
    P = tuple(None if x is None else np.sum(x, axis=-1, keepdims=True) * np.ones_like(x) for x in Lj)
    num = _add_jet(_scale_jet(Lk, dj), _scale_jet(Lj, dk))
    inv_P0 = 1.0 / P[0]
    invP = (inv_P0,
            None if P[1] is None else -P[1] * inv_P0**2,
            None if P[2] is None else (2.0 * P[1]**2 * inv_P0 - P[2]) * inv_P0**2)
    rho_I = _scale_jet(invP, num)
    rho_I = tuple(None if x is None else -x for x in rho_I)

    # p axes: z_p = Z_S, x_p along the projection of Z_I on the plane (text's sign).
    ZI = np.array([0.0, 0.0, 1.0])
    zi = tuple(None if x is None else x[..., 2] for x in Z)   # Z_I . z_p and derivatives
    w = _scale_jet(zi, Z)
    w = (ZI - w[0],) + tuple(None if x is None else -x for x in w[1:])
    xp, _ = _unit_jet(w)
    yp = _cross_jet(Z, xp)
    zp = Z
    om_p, omd_p = _omega_poisson(xp, yp, zp)

    T = np.stack([xp[0], yp[0], zp[0]], axis=-2)          # T_p_I
    T1 = np.stack([xp[1], yp[1], zp[1]], axis=-2)
    T2 = np.stack([xp[2], yp[2], zp[2]], axis=-2)
    rho = _matvec(T, rho_I[0])
    # time derivatives of the p-frame coordinates (not rotated inertial velocities)
    rho1 = _matvec(T, rho_I[1]) + _matvec(T1, rho_I[0])
    rho2 = _matvec(T, rho_I[2]) + 2.0 * _matvec(T1, rho_I[1]) + _matvec(T2, rho_I[0])
    rn = np.sqrt(_dot(rho, rho))[..., None]
    x = -rho / rn
    om_ip = _cross(rho1, x) / rn
    omd_ip = (2.0 * _dot(x, rho1)[..., None] * om_ip - _cross(x, rho2)) / rn
    ez = np.zeros_like(x)
    ez[..., 2] = 1.0
    y = _cross(ez, x)
    T_S_p = np.stack([x, y, ez], axis=-2)
    omega = _matvec(T_S_p, om_p + om_ip)
    omega_dot = _matvec(T_S_p, omd_p + omd_ip + _cross(om_p, om_ip))
    T_S_I = T_S_p @ T
    return omega, omega_dot, T_S_I


def attitude(r, v=None, a=None, *, law="global", method="direct", jerk=None, snap=None, c=C_LIGHT):
    """Nominal S and OA frames, their angular velocities and accelerations.

    Parameters
    ----------
    r : (..., 3, 3) m, GCRS -- satellite positions (satellite axis = Sat.index),
        float64 or a (hi, lo) pair of float64 arrays.  Leading axes ``...``
        (e.g. N epochs, TT) are broadcast through.
    v : (..., 3, 3) m/s, GCRS, optional -- needed for omega (all laws) and for
        the frames themselves under the Taylor laws.
    a : (..., 3, 3) m/s^2, GCRS, optional -- needed for omega_dot (global law),
        omega (Taylor laws) and the frames of taylor2.  Pass the total
        acceleration the orbit follows (gravity + drag-free G if modelled).
    law : "global" (default), "taylor1" or "taylor2" -- see the module docstring.
    method : "direct" (Poisson relation, analytic frame derivatives; all laws)
        or "p-frame" (the appendix method; global law only).
    jerk : (..., 3, 3) m/s^3, GCRS, optional -- d a / dt of each satellite; needed
        for omega_dot under the Taylor laws (see :func:`tqdyn.forces.central.central_jerk_snap`).
    snap : (..., 3, 3) m/s^4, optional -- taylor2 only, zero if None.
    c : m/s.

    Returns
    -------
    :class:`Attitude` (fields and shapes documented there).
    """
    if method not in METHODS:
        raise ValueError(unknown("method", method, METHODS))
    if method == "p-frame" and law != "global":
        raise ValueError("the p-frame method is defined for the global law only (one common plane)")
    if law != "global" and v is None:
        raise ValueError(f"law {law!r} needs the velocities v")
    if law == "taylor2" and a is None:
        raise ValueError("law 'taylor2' needs the accelerations a")
    bj, bk = beam_vectors(r, v, a, law=law, jerk=jerk, snap=snap, c=c)
    X, Y, Z, th = _frames_from_beams(bj, bk)
    T_S_I = np.stack([X[0], Y[0], Z[0]], axis=-2)
    if method == "direct":
        omega, omega_dot = _omega_poisson(X, Y, Z)
    else:
        if v is None or a is None:
            raise ValueError("method 'p-frame' needs velocities and accelerations")
        omega, omega_dot, T_S_I = _p_frame_omega(r, v, a, Z)

    half = lambda x: None if x is None else 0.5 * x[..., None] * MOSA_SIGN  # noqa: E731  (OA_1 +theta/2, OA_2 -theta/2)
    phi, phi1, phi2 = half(th[0]), half(th[1]), half(th[2])
    T_OA_S = T_OA_S_of(phi)
    omega_oa = omega_dot_oa = None
    if omega is not None and phi1 is not None:
        ez = np.array([0.0, 0.0, 1.0])
        w_tot = omega[..., None, :] + phi1[..., None] * ez
        omega_oa = _matvec(T_OA_S, w_tot)
        if omega_dot is not None and phi2 is not None:
            wd = omega_dot[..., None, :] + phi2[..., None] * ez + _cross(omega[..., None, :], phi1[..., None] * ez)
            omega_dot_oa = _matvec(T_OA_S, wd)
    return Attitude(T_S_I=T_S_I, theta=th[0], theta_dot=th[1], theta_ddot=th[2],
                    omega=omega, omega_dot=omega_dot,
                    mosa_angle=phi, mosa_rate=phi1, mosa_accel=phi2, T_OA_S=T_OA_S,
                    omega_oa=omega_oa, omega_dot_oa=omega_dot_oa, law=law, method=method)
