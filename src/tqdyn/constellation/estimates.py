"""First-order analytic estimates of the constellations' control and orbits: the heliocentric
constellations (LISA, Taiji) and the linear (Hill, Clohessy-Wiltshire) response of near-circular
orbits to small accelerations.  The studies set these models against the coupled runs
(:mod:`tqdyn.workflows.report`); the analysis only measures the runs.

Derivations in ``docs/lisa-coupled.md``; ``tools/derive_lisa_estimates.py``
redoes them in sympy and checks every step.  Everything here is numpy; no I/O.

Conventions: SI units (m, s, m/s^2, rad); ``alpha = L / (2 a)`` (L the arm
length, a the semi-major axis), ``n^2 = GM / a^3``, d the distance of each
test mass (TM) from the satellite's centre of mass along its optical axis;
tau = n t.  The *cartwheel frame* is the Hill (Clohessy-Wiltshire) frame of
the constellation's centre: x radial (away from the Sun), y along-track, z
along the orbital angular momentum.  In it the clockwise LISA design is, to
first order in alpha, the rigid circle rho_i = R0 (cos psi_i u0 + sin psi_i
w0), R0 = L / sqrt(3), u0 = (1/2, 0, sqrt(3)/2), w0 = (0, -1, 0), psi_i = n t
+ phi_i, turning at +n about N = u0 x w0 = (sqrt(3)/2, 0, -1/2); with
tqdyn's labels (1, 2, 3 counterclockwise seen from the ecliptic pole),
Z_S = n_ij x n_ik / sin(alpha_i) = -N, X_S = -rho_hat_i (toward the centre)
and Y_S = Z_S x X_S = d rho_hat_i / d psi (along the cartwheel's rotation).

1. Nominal control of the Keplerian design
------------------------------------------
A TM on its optical axis sits at d u_l, u_l the unit vector of the arm it
faces; with the pivot at the CoM its relative acceleration is d u_l'' and the
bracket of eq:TMforce is exactly g_l = d (T(r_i) u_l - u_l''), T the Sun's
tidal tensor at the satellite.  Expanding the Keplerian design
(:mod:`tqdyn.astro.constellation_design`, tilt pi/3 + 5/8 alpha) to second
order in alpha, the zeroth order of g_l vanishes (every point of the rigidly
turning plane is a free CW orbit) and the first order is, in S, with tau the
satellite's mean anomaly, unit alpha n^2 d, components in OA_l (x along
the arm, y = Z_S x x, z = Z_S)::

    g_1 = ( -13/8 r3 cos tau - 21/16 sin tau + 3/32 r3 cos 3tau + 15/32 sin 3tau,
            3/4 cos tau - 7/16 r3 sin tau - 15/32 cos 3tau - 1/32 r3 sin 3tau,
            r3/64 (36 - 39 cos 2tau + 3/2 cos 4tau) - 81/64 sin 2tau + 3/128 sin 4tau )

(r3 = sqrt(3); g_2: the same with the sin terms of x and z and the cos terms
of y of opposite sign), and the LISA drag-free scheme (G . u_l = g_l . u_l,
G . Z = mean g . Z) gives, in S,

    G_X = -13/4 cos tau + 3/16 cos 3 tau
    G_Y = -21/8 sin tau + 15/16 sin 3 tau
    G_Z = sqrt(3)/64 (36 - 39 cos 2 tau + 3/2 cos 4 tau)
    A_1y = 7/8 (cos tau - sqrt(3) sin tau) + 3/8 cos 3 tau + sqrt(3)/2 sin 3 tau
    A_2y = -7/8 (cos tau + sqrt(3) sin tau) - 3/8 cos 3 tau + sqrt(3)/2 sin 3 tau
    A_1z = -A_2z = 81/64 sin 2 tau - 3/128 sin 4 tau,   A_lx = 0,

so max |G| = 4.1204 alpha n^2 d and max |A component| = 2.3849 alpha n^2 d
(:data:`KEPLER_MAX_G`, :data:`KEPLER_MAX_SUSPENSION`).  In the cartwheel frame
G has the mean (-37/16, 0, -2.0568) alpha n^2 d (radial, along-track, normal).

2. The exact identity on any orbit
----------------------------------
:func:`arm_identity_control` evaluates g_l = d (T u_l - u_l'') from the
satellites' positions, velocities and accelerations (e.g. ESA's orbit files)
and solves the drag-free scheme: an estimate of the coupled run that needs
no attitude or control code.

3. Common self-gravity on the cartwheel
---------------------------------------
A constant acceleration f along X_S, Y_S or Z_S of every satellite drives the
CW equations at the orbital frequency (X_S, Y_S turn once a year in the
cartwheel frame).  :func:`cartwheel_sg_displacement` is the closed-form
response (zero initial state) and :func:`common_sg_arm_response` the first-
order arm-length, arm-length-rate and corner-angle changes; along Z_S (the
same direction for all three) the first-order change is zero.

4. Small differential accelerations
-----------------------------------
:func:`cw_response`: the linear (Clohessy-Wiltshire) response of each
satellite to a small acceleration history, in its own orbital frame;
:func:`ramp_difference_response` splits the push between ESA's ramp toward
the centroid and the coupled run's through the TMs into its parts.
:func:`secular_along_track_drift`: the secular part of the along-track
response on a near-circular (TianQin) orbit of mean motion n, from the
averaged Hill equations with zero initial relative state,

    delta_t(T) = -3 int_0^T (T - s) f_t(s) ds - (2 / n) int_0^T f_r(s) ds,

for a constant f_t -3/2 f_t T^2 (a forward push makes the satellite fall
behind).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008

__all__ = [
    "KEPLER_MAX_G",
    "KEPLER_MAX_SUSPENSION",
    "KEPLER_MEAN_G_HILL",
    "ControlEstimate",
    "arm_identity_control",
    "bisector_median_angle",
    "cartwheel_phase_series",
    "cartwheel_phases",
    "cartwheel_sg_displacement",
    "common_sg_arm_response",
    "cw_response",
    "kepler_control",
    "kepler_control_estimate",
    "lisa_scheme_constant",
    "pointing_law_bounds",
    "ramp_difference_response",
    "secular_along_track_drift",
]

_S3 = math.sqrt(3.0)

#: max over tau of |G| of the Keplerian design, unit alpha n^2 d (module docstring, section 1).
KEPLER_MAX_G = 4.120403156
#: max over tau, both TMs and all components of the suspension A_l, unit alpha n^2 d.
KEPLER_MAX_SUSPENSION = 2.384898671
#: mean of G over a year in the cartwheel frame (radial, along-track, normal), unit alpha n^2 d.
KEPLER_MEAN_G_HILL = (-37.0 / 16.0, 0.0, -2.056810334)

_U0 = np.array([0.5, 0.0, _S3 / 2])
_W0 = np.array([0.0, -1.0, 0.0])
_N = np.cross(_U0, _W0)


def kepler_control(tau) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First-order g_l, G and A_l of the Keplerian design at the satellite's mean anomaly ``tau`` [rad].

    tau : array (...).  Returns (g (..., 2, 3) with ``g[..., l, :]`` in OA_l,
    G (..., 3) in S, A (..., 2, 3) with ``A[..., l, :]`` in OA_l), all in units of
    alpha n^2 d [m/s^2 per (alpha n^2 d)] (module docstring, section 1;
    MOSA 1 faces satellite k, MOSA 2 satellite j).  Frame-independent of the
    time scale (tau = n t).
    """
    t = np.asarray(tau, dtype=np.float64)
    c1, s1, c3, s3 = np.cos(t), np.sin(t), np.cos(3 * t), np.sin(3 * t)
    c2, s2, c4, s4 = np.cos(2 * t), np.sin(2 * t), np.cos(4 * t), np.sin(4 * t)
    gz_even = _S3 / 64 * (36 - 39 * c2 + 1.5 * c4)
    gz_odd = 81 / 64 * s2 - 3 / 128 * s4
    g1 = np.stack([-13 / 8 * _S3 * c1 - 21 / 16 * s1 + 3 / 32 * _S3 * c3 + 15 / 32 * s3,
                   3 / 4 * c1 - 7 / 16 * _S3 * s1 - 15 / 32 * c3 - 1 / 32 * _S3 * s3,
                   gz_even - gz_odd], -1)
    g2 = np.stack([-13 / 8 * _S3 * c1 + 21 / 16 * s1 + 3 / 32 * _S3 * c3 - 15 / 32 * s3,
                   -3 / 4 * c1 - 7 / 16 * _S3 * s1 + 15 / 32 * c3 - 1 / 32 * _S3 * s3,
                   gz_even + gz_odd], -1)
    G = np.stack([-13 / 4 * c1 + 3 / 16 * c3, -21 / 8 * s1 + 15 / 16 * s3, gz_even], -1)
    a1y = 7 / 8 * (c1 - _S3 * s1) + 3 / 8 * c3 + _S3 / 2 * s3
    a2y = -7 / 8 * (c1 + _S3 * s1) - 3 / 8 * c3 + _S3 / 2 * s3
    z = np.zeros_like(t)
    A = np.stack([np.stack([z, a1y, gz_odd], -1), np.stack([z, a2y, -gz_odd], -1)], -2)
    return np.stack([g1, g2], -2), G, A


@dataclass(frozen=True)
class ControlEstimate:
    """The first-order nominal control of an equal-arm Keplerian design.

    alpha = L / (2 a) [-]; n2 = GM / a^3 [s^-2]; scale = alpha n2 d
    [m/s^2]; max_G [m/s^2]; max_suspension [m/s^2] (largest component of
    either TM's suspension, OA_l); mean_G_hill (3,) [m/s^2] (radial,
    along-track, normal); drift_along_1yr [m]: the along-track drift
    -(2/n) mean_G_r T after T = one orbital period (the mean along-track
    component is zero)."""

    alpha: float
    n2: float
    scale: float
    max_G: float
    max_suspension: float
    mean_G_hill: tuple
    drift_along_1yr: float


def kepler_control_estimate(arm_length: float, d: float = 0.30, a: float = 149597870700.0,
                            gm: float = 1.3271244004193938e20) -> ControlEstimate:
    """:class:`ControlEstimate` for arm length ``arm_length`` [m], TM distance ``d`` [m],
    semi-major axis ``a`` [m] and GM of the Sun ``gm`` [m^3/s^2] (DE430)."""
    alpha = float(arm_length) / (2.0 * float(a))
    n2 = float(gm) / float(a) ** 3
    scale = alpha * n2 * float(d)
    n = math.sqrt(n2)
    mean = tuple(m * scale for m in KEPLER_MEAN_G_HILL)
    return ControlEstimate(alpha=alpha, n2=n2, scale=scale, max_G=KEPLER_MAX_G * scale,
                           max_suspension=KEPLER_MAX_SUSPENSION * scale, mean_G_hill=mean,
                           drift_along_1yr=-2.0 / n * mean[0] * (2 * math.pi / n))


# --------------------------------------------------------------------------- the exact identity

_PERM = ((0, 1, 2), (1, 2, 0), (2, 0, 1))  # (i, j, k) even permutations


def _lisa_scheme(e1, e2, Z, g1, g2) -> np.ndarray:
    """G of the LISA drag-free scheme, G . e_l = g_l . e_l and G . Z = Z . (g_1 + g_2) / 2, by Cramer's rule:
    e_l the sensitive axes, Z the normal, g_l the TMs' relative accelerations, all (..., 3) in one frame;
    returns G (..., 3) in that frame."""
    det = np.sum(e1 * np.cross(e2, Z), -1)[..., None]
    b1 = np.sum(e1 * g1, -1)[..., None]
    b2 = np.sum(e2 * g2, -1)[..., None]
    b3 = 0.5 * np.sum(Z * (g1 + g2), -1)[..., None]
    return (b1 * np.cross(e2, Z) + b2 * np.cross(Z, e1) + b3 * np.cross(e1, e2)) / det


def lisa_scheme_constant(sg_oa, theta: float = math.pi / 3) -> tuple[np.ndarray, np.ndarray]:
    """G (3,) in S and A (2, 3) in OA_l [m/s^2] of the LISA drag-free scheme when the TMs' relative
    accelerations are constant vectors sg_oa (2, 3) [m/s^2] given in OA_l (e.g. a per-TM self-gravity), at
    the opening angle theta [rad]: OA_l is X_S turned by +-theta/2 about Z_S (MOSA 1 +, facing k), the
    sensitive axes X_OA_l; Cramer's rule, written out independently of :mod:`tqdyn.constellation.control`."""
    h = 0.5 * theta
    e = np.array([[math.cos(h), math.sin(h), 0.0], [math.cos(h), -math.sin(h), 0.0]])
    y = np.array([[-math.sin(h), math.cos(h), 0.0], [math.sin(h), math.cos(h), 0.0]])
    z = np.array([0.0, 0.0, 1.0])
    g = np.array([sg_oa[l, 0] * e[l] + sg_oa[l, 1] * y[l] + sg_oa[l, 2] * z for l in range(2)])
    G = _lisa_scheme(e[0], e[1], z, g[0], g[1])
    A = np.array([[(G - g[l]) @ e[l], (G - g[l]) @ y[l], (G - g[l]) @ z] for l in range(2)])
    return G, A


def arm_identity_control(R, V, A, gm: float = 1.3271244004193938e20, d: float = 0.30) -> tuple[np.ndarray, np.ndarray]:
    """G and A_l of TMs at ``d`` [m] on the optical axes, from the exact identity g_l = d (T u_l - u_l'').

    R, V, A : (N, 3, 3) heliocentric positions [m], velocities [m/s] and
    accelerations [m/s^2] of the three satellites (ICRF axes; any common
    time scale); T is the Sun's point-mass tidal tensor (``gm`` [m^3/s^2]) at
    each satellite (the planets' tides at LISA are < 1e-4 of it).  u_l are
    the instantaneous arm directions (the beams' light-time aberration,
    ~1e-4 rad, is left out).  Returns (G (N, 3, 3) in S, A (N, 3, 2, 3) in
    OA_l), S and OA_l as in tqdyn (MOSA 1 faces k, MOSA 2 faces j, Z_S =
    n_ij x n_ik / sin(alpha_i)), the LISA drag-free scheme (sensitive axes
    X_OA_l).
    """
    R, V, A = (np.asarray(x, dtype=np.float64) for x in (R, V, A))
    G_out = np.zeros(R.shape)
    A_out = np.zeros(R.shape[:2] + (2, 3))
    for i, j, k in _PERM:
        us, gs = [], []
        for far in (k, j):
            D, Dd, Ddd = R[:, far] - R[:, i], V[:, far] - V[:, i], A[:, far] - A[:, i]
            L = np.linalg.norm(D, axis=-1)[:, None]
            u = D / L
            Ld = np.sum(u * Dd, -1)[:, None]
            ud = (Dd - u * Ld) / L
            Ldd = np.sum(u * Ddd, -1)[:, None] + np.sum(Dd * ud, -1)[:, None]
            udd = (Ddd - u * Ldd - 2 * Ld * ud) / L
            ri = R[:, i]
            rn = np.linalg.norm(ri, axis=-1)[:, None]
            rh = ri / rn
            Tu = gm / rn ** 3 * (3 * rh * np.sum(rh * u, -1)[:, None] - u)
            us.append(u)
            gs.append(d * (Tu - udd))
        e1, e2 = us
        Z = np.cross(e2, e1)
        Z /= np.linalg.norm(Z, axis=-1)[:, None]
        X = e1 + e2
        X /= np.linalg.norm(X, axis=-1)[:, None]
        Y = np.cross(Z, X)
        G = _lisa_scheme(e1, e2, Z, gs[0], gs[1])
        G_out[:, i] = np.stack([np.sum(G * X, -1), np.sum(G * Y, -1), np.sum(G * Z, -1)], -1)
        for l, (e, g) in enumerate(zip(us, gs)):
            a = G - g
            A_out[:, i, l] = np.stack([np.sum(a * e, -1), np.sum(a * np.cross(Z, e), -1), np.sum(a * Z, -1)], -1)
    return G_out, A_out


# --------------------------------------------------------------------------- common self-gravity


def cartwheel_phases(R0, V0) -> tuple[np.ndarray, float, np.ndarray]:
    """Phases phi_i [rad] of the three satellites on the cartwheel at one instant.

    R0, V0 : (3, 3) heliocentric positions [m] and velocities [m/s].
    Returns (phi (3,), R0 = mean distance from the centroid [m], H (3, 3)
    rows: the cartwheel frame's x, y, z axes in the input axes).  ValueError
    unless the constellation is the clockwise cartwheel (the satellites'
    offsets from the centroid within 0.05 of the plane spanned by u0, w0 and
    Z_S of satellite 1 along -N), the case the closed forms are derived for.
    """
    R0, V0 = np.asarray(R0, np.float64), np.asarray(V0, np.float64)
    c, cv = R0.mean(axis=0), V0.mean(axis=0)
    x = c / np.linalg.norm(c)
    z = np.cross(c, cv)
    z /= np.linalg.norm(z)
    H = np.stack([x, np.cross(z, x), z])
    rho = (R0 - c) @ H.T
    rn = np.linalg.norm(rho, axis=-1)
    rh = rho / rn[:, None]
    zs = np.cross(rh[1] - rh[0], rh[2] - rh[0])
    zs /= np.linalg.norm(zs)
    if np.max(np.abs(rh @ _N)) > 0.05 or zs @ _N > -0.95:
        raise ValueError("constellation: not the clockwise cartwheel of the closed forms (its plane or its "
                         "labels differ); allowed: LISA's / Taiji's clockwise design")
    return np.arctan2(rh @ _W0, rh @ _U0), float(rn.mean()), H


def cartwheel_phase_series(R, V) -> np.ndarray:
    """Cartwheel phases psi_i(t) [rad] of the satellites along a trajectory.

    R, V : (N, 3, 3) heliocentric positions [m] and velocities [m/s].  At
    each row: the satellite's offset from the centroid in the centroid's
    Hill frame, psi = atan2(rho_hat . w0, rho_hat . u0) (module docstring).
    To first order in alpha, psi_i - pi is satellite i's mean anomaly tau
    of :func:`kepler_control` (for the Keplerian design).  Returns (N, 3).
    """
    R, V = np.asarray(R, np.float64), np.asarray(V, np.float64)
    c, cv = R.mean(axis=1), V.mean(axis=1)
    x = c / np.linalg.norm(c, axis=-1, keepdims=True)
    z = np.cross(c, cv)
    z /= np.linalg.norm(z, axis=-1, keepdims=True)
    y = np.cross(z, x)
    rho = R - c[:, None, :]
    hx, hy, hz = (np.einsum("nsk,nk->ns", rho, e) for e in (x, y, z))
    return np.arctan2(-hy, 0.5 * hx + 0.5 * _S3 * hz)


def cartwheel_sg_displacement(axis: str, f: float, n: float, t, phi) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form CW response to a constant ``f`` [m/s^2] along an S axis of a cartwheel satellite.

    axis : "x" (X_S = -rho_hat, toward the centre), "y" (Y_S, along the
    cartwheel's rotation) or "z" (Z_S = -N, the same for all satellites);
    n : mean motion [rad/s]; t : (N,) [s] since the start (zero relative
    state there); phi : the satellite's phase (psi = n t + phi).  Returns
    (dr (N, 3) [m], dv (N, 3) [m/s]) in the cartwheel frame (x radial, y
    along-track, z normal; dv relative to that rotating frame).
    """
    t = np.asarray(t, dtype=np.float64)
    nt = n * t
    ps = nt + phi
    cp, sp_ = math.cos(phi), math.sin(phi)
    if axis == "x":
        x = (16 * cp - 3 * np.cos(nt - phi) - 13 * np.cos(ps) - 10 * nt * np.sin(ps)) / (8 * n ** 2)
        y = (-16 * sp_ + 3 * np.sin(nt - phi) + 19 * np.sin(ps) - 10 * nt * np.cos(ps) - 12 * nt * cp) / (4 * n ** 2)
        z = _S3 * (sp_ * np.sin(nt) - nt * np.sin(ps)) / (4 * n ** 2)
        vx = (-10 * nt * np.cos(ps) + 6 * np.sin(nt) * cp) / (8 * n)
        vy = (10 * nt * np.sin(ps) - 12 * cp + 3 * np.cos(nt - phi) + 9 * np.cos(ps)) / (4 * n)
        vz = -_S3 * (nt * np.cos(ps) + np.sin(nt) * cp) / (4 * n)
    elif axis == "y":
        x = (16 * sp_ + 3 * np.sin(nt - phi) - 13 * np.sin(ps) + 10 * nt * np.cos(ps)) / (8 * n ** 2)
        y = (16 * cp + 3 * np.cos(nt - phi) - 19 * np.cos(ps) - 10 * nt * np.sin(ps) - 12 * nt * sp_) / (4 * n ** 2)
        z = _S3 * (nt * np.cos(ps) - cp * np.sin(nt)) / (4 * n ** 2)
        vx = (-10 * nt * np.sin(ps) + 6 * sp_ * np.sin(nt)) / (8 * n)
        vy = (-10 * nt * np.cos(ps) - 12 * sp_ - 3 * np.sin(nt - phi) + 9 * np.sin(ps)) / (4 * n)
        vz = -_S3 * (nt * np.sin(ps) + sp_ * np.sin(nt)) / (4 * n)
    elif axis == "z":
        x = _S3 * (np.cos(nt) - 1) / (2 * n ** 2)
        y = _S3 * (nt - np.sin(nt)) / n ** 2
        z = (1 - np.cos(nt)) / (2 * n ** 2)
        vx = -_S3 * np.sin(nt) / (2 * n)
        vy = _S3 * (1 - np.cos(nt)) / n
        vz = np.sin(nt) / (2 * n)
    else:
        raise ValueError(f"axis: {axis!r} is not an axis of S; allowed: x, y, z")
    return f * np.stack([x, y, z], -1), f * np.stack([vx, vy, vz], -1)


def common_sg_arm_response(axis: str, f: float, t, R0, V0, gm: float = 1.3271244004193938e20):
    """First-order arm-length, arm-length-rate and corner-angle changes of a common self-gravity.

    axis, f : as :func:`cartwheel_sg_displacement` (a negative ``f`` is the
    opposite direction); t : (N,) [s] since the instant of ``R0``, ``V0``
    ((3, 3) heliocentric states [m, m/s]) where the perturbation starts;
    gm [m^3/s^2] sets n from the centroid's distance.  Returns (dL (N, 3)
    [m], dLdot (N, 3) [m/s] for the arms 12, 23, 31; dalpha (N, 3) [rad] for
    the corners 1, 2, 3), on the rigid cartwheel (first order in f and zeroth
    in alpha).
    """
    t = np.asarray(t, dtype=np.float64)
    phi, R, _ = cartwheel_phases(R0, V0)
    n = math.sqrt(gm / np.linalg.norm(np.asarray(R0, np.float64).mean(axis=0)) ** 3)
    rho, rhod, dr, dv = [], [], [], []
    for p in phi:
        ps = n * t + p
        rho.append(R * (np.cos(ps)[:, None] * _U0 + np.sin(ps)[:, None] * _W0))
        rhod.append(R * n * (-np.sin(ps)[:, None] * _U0 + np.cos(ps)[:, None] * _W0))
        a, b = cartwheel_sg_displacement(axis, f, n, t, p)
        dr.append(a)
        dv.append(b)
    L0 = _S3 * R
    dL, dLd = [], []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        D, Dd = rho[j] - rho[i], rhod[j] - rhod[i]
        u = D / L0
        dD, dDd = dr[j] - dr[i], dv[j] - dv[i]
        du = (dD - u * np.sum(u * dD, -1)[:, None]) / L0
        dL.append(np.sum(u * dD, -1))
        dLd.append(np.sum(du * Dd, -1) + np.sum(u * dDd, -1))
    dal = []
    for i, j, k in _PERM:
        uij, uik = (rho[j] - rho[i]) / L0, (rho[k] - rho[i]) / L0
        d1, d2 = dr[j] - dr[i], dr[k] - dr[i]
        du1 = (d1 - uij * np.sum(uij * d1, -1)[:, None]) / L0
        du2 = (d2 - uik * np.sum(uik * d2, -1)[:, None]) / L0
        dal.append(-(np.sum(du1 * uik, -1) + np.sum(uij * du2, -1)) / (_S3 / 2))
    return np.stack(dL, -1), np.stack(dLd, -1), np.stack(dal, -1)


# --------------------------------------------------------------------------- linear response


def cw_response(t, r, v, f, gm: float = 1.3271244004193938e20) -> np.ndarray:
    """Clohessy-Wiltshire response of each satellite to a small acceleration history.

    t : (N,) [s] increasing (the response starts from a zero relative state
    at t[0]); r, v : (N, S, 3) heliocentric positions [m] and velocities [m/s]
    of the reference orbits (defining each satellite's radial, along-track
    and normal axes; the perturbed orbit is fine); f : (N, S, 3) [m/s^2],
    same axes.  n = sqrt(gm / mean|r|^3) per satellite.  Returns (N, S, 3)
    [m]: radial, along-track, normal displacement, the exact solution of the
    CW equations with that forcing (trapezoidal quadrature of the
    convolution with the CW state-transition matrix).
    """
    from scipy.integrate import cumulative_trapezoid

    t = np.asarray(t, np.float64) - float(np.asarray(t)[0])
    r, v, f = (np.asarray(x, np.float64) for x in (r, v, f))
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    rh = r / rn
    h = np.cross(r, v)
    hh = h / np.linalg.norm(h, axis=-1, keepdims=True)
    th = np.cross(hh, rh)
    fx, fy, fz = (np.einsum("...k,...k->...", f, e) for e in (rh, th, hh))
    n = np.sqrt(gm / np.mean(rn[..., 0], axis=0) ** 3)
    nt = n * t[:, None]
    c, s = np.cos(nt), np.sin(nt)

    def I(g):
        return cumulative_trapezoid(g, t, axis=0, initial=0.0)

    def conv(g, kind):  # int_0^t K(t - s) g(s) ds
        if kind == "one":
            return I(g)
        if kind == "tau":
            return t[:, None] * I(g) - I(t[:, None] * g)
        ic, is_ = I(c * g), I(s * g)
        return c * ic + s * is_ if kind == "cos" else s * ic - c * is_

    x = conv(fx, "sin") / n + 2 * (conv(fy, "one") - conv(fy, "cos")) / n
    y = -2 * (conv(fx, "one") - conv(fx, "cos")) / n + (4 * conv(fy, "sin") - 3 * n * conv(fy, "tau")) / n
    z = conv(fz, "sin") / n
    return np.stack([x, y, z], -1)


def ramp_difference_response(t, r, v, G, g, X, bisector, centroid, gm: float = 1.3271244004193938e20) -> dict:
    """The CW response (:func:`cw_response`) of each satellite to the difference G - g(t) c_hat between the
    coupled run's drag-free push G (ESA's ramp g(t) applied through the TMs, along X_S) and ESA's ramp
    toward the centroid c_hat, in its three parts: ``geometric`` g (b_hat - c_hat) (X_S's nominal
    direction, the beams' bisector b_hat toward the incentre, against the centroid), ``aberration``
    g (X_S - b_hat) (the beams' aberration) and ``nominal`` G - g X_S (the drag-free push without the ramp).

    t (N,) [s]; r, v (N, S, 3) [m, m/s] the reference orbits (:func:`cw_response`); G (N, S, 3) [m/s^2];
    g (N,) [m/s^2] the ramp's magnitude (positive toward the centre); X, bisector, centroid (N, S, 3)
    unit vectors (the same inertial frame).  Returns {part: (N, S, 3) [m] radial, along-track, normal}; the
    parts sum to the response to G - g c_hat."""
    gs = g[:, None, None]
    parts = {"geometric": gs * (bisector - centroid), "aberration": gs * (X - bisector), "nominal": G - gs * X}
    return {k: cw_response(t, r, v, f, gm=gm) for k, f in parts.items()}


def secular_along_track_drift(t, r, v, f) -> np.ndarray:
    """Secular along-track drift [m] caused by a small acceleration f on a near-circular orbit.

    t : (N,) [s] increasing; r, v : (N, n_sat, 3) [m, m/s] GCRS (the
    perturbed orbit is fine: f is small); f : (N, n_sat, 3) [m/s^2] GCRS.
    Returns (N, n_sat): -3 int_0^t (t - s) f_t ds - (2/n) int_0^t f_r ds
    (module docstring), f_t = f . t_hat, f_r = f . r_hat, n = sqrt(GM / a^3)
    with a the mean |r| (GM: EGM2008), integrals by the trapezoidal rule.
    """
    from scipy.integrate import cumulative_trapezoid

    t = np.asarray(t, np.float64)
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    f = np.asarray(f, np.float64)
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    rh = r / rn
    h = np.cross(r, v)
    th = np.cross(h / np.linalg.norm(h, axis=-1, keepdims=True), rh)
    ft = np.einsum("...k,...k->...", f, th)
    fr = np.einsum("...k,...k->...", f, rh)
    n = np.sqrt(float(GM_EARTH_EGM2008) / np.mean(rn[..., 0], axis=0) ** 3)  # (n_sat,)
    Ft = cumulative_trapezoid(ft, t, axis=0, initial=0.0)
    FFt = cumulative_trapezoid(Ft, t, axis=0, initial=0.0)
    Fr = cumulative_trapezoid(fr, t, axis=0, initial=0.0)
    return -3.0 * FFt - 2.0 / n * Fr


# --------------------------------------------------------------------------- geometry, pointing


def bisector_median_angle(L_ij, L_ik, L=None) -> np.ndarray:
    """First-order angle [rad] at satellite i from the bisector of its corner (toward the
    incentre: tqdyn's X_S, the direction of the coupled ramp) to the median (toward the
    centroid: ESA's ramp), positive toward arm ik: (L_ik - L_ij) / (2 sqrt(3) L).

    L_ij, L_ik [m] (any shape, the arms to j and to k), L the mean arm length [m]
    (default their mean).  For equal adjacent arms the two directions coincide whatever
    the corner angle (docs/lisa-coupled.md)."""
    L_ij, L_ik = np.asarray(L_ij, np.float64), np.asarray(L_ik, np.float64)
    L = 0.5 * (L_ij + L_ik) if L is None else L
    return (L_ik - L_ij) / (2 * _S3 * L)


def pointing_law_bounds(v: float, L: float) -> dict[str, float]:
    """First-order bounds of the pointing-law errors for a remote satellite moving at ``v`` [m/s]
    (its speed in the frame of the light propagation, BCRS) on an arm of length ``L`` [m]:
    ``global`` v/c [rad] (the emitter moves by v tau during the light time tau = L/c),
    ``taylor`` v^2 / (2 c^2) [rad] (tau = L/c misses L (n.v)/c^2; the emission point
    then moves by |n x v| L (n.v)/c^2, at most L v^2 / (2 c^2)), ``tau`` L v / c^2 [s]."""
    c = C_LIGHT
    return {"global": v / c, "taylor": v * v / (2 * c * c), "tau": L * v / (c * c)}
