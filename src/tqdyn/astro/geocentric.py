"""Positions of the Sun, the Moon and the planets in the TT-compatible GCRS, from a BCRS ephemeris.

A JPL ephemeris gives barycentric (BCRS) positions in TDB-compatible units at
TDB; tqdyn's geocentric dynamics live in the TT-compatible GCRS.  The
first-order (1PN) transformation of an external body's position to the
geocentre (IAU 2000 Resolution B1.3; IERS Conventions 2010 sec. 10.2 and
11.1; Soffel et al. 2003, AJ 126, 2687), at the GCRS coordinate time T of the
satellite instant:

1. **Simultaneity.**  TCB - TCG = c^-2 [A(t) + v_E . r_E] (+ O(c^-4)), r_E = x -
   x_E: the body's event simultaneous in the GCRS with the geocentre's event
   at T happens at the barycentric time t_E(T) + (v_E . r_E)/c^2, where
   t_E(T) is the geocentre's TDB at TT = T (``tdb_jd``).  The geocentric
   vector then moves by (v_B - v_E)(v_E . r_E)/c^2.
2. **The coordinate transformation** (TCB/TCG units)::

       X = r_E + c^-2 [ (v_E . r_E) v_E / 2 + U_ext(x_E) r_E + (a_E . r_E) r_E - a_E |r_E|^2 / 2 ]

   with v_E, a_E the Earth's barycentric velocity and acceleration and
   U_ext(x_E) = sum_j GM_j / |x_j - x_E| the potential of the other bodies
   at the geocentre.
3. **Units.**  x_TDB = (1 - L_B) x_TCB and X_TT = (1 - L_G) X_TCG, so
   X_TT = K X with K = (1 - L_G) / (1 - L_B) = 1 + 1.48e-8; the bodies' GMs
   scale the same way (GM_TT = K GM_TDB, the masses being SI in both).

Magnitudes, relative to |r_E|: K - 1 = 1.48e-8; U_ext/c^2 = 9.9e-9 (the
Sun; the Moon and the planets add < 3e-12, Jupiter 2.2e-12); the Lorentz term <= v_E^2/(2c^2)
= 4.8e-9; for the Sun (a_E . r_E) r_E - a_E r_E^2/2 = 4.9e-9 (for the Moon
a_E r_E/c^2 = 2.5e-11); the simultaneity shift 3e-10 (Moon) and 2e-10 (Sun).
On the point-mass accelerations at the TianQin orbit (1e5 km) the transform
acts like moving each body to lambda X, lambda = K (1 + f U_sun/c^2), f = 1
(3/2 for the Sun, its own acceleration term), plus the direction-dependent
velocity terms: the Moon's 1.2e-5 m/s^2 change by 5.2e-8 .. 8.7e-8 of
themselves (up to 8.1e-13 m/s^2) and the Sun's 6.0e-6 m/s^2 by 7.3e-8 (up to
4.4e-13 m/s^2) (tests/test_geocentric.py).
The 1PN corrections of the tidal field itself, of the same relative order
(v^2/c^2 ~ 1e-8 of the tidal acceleration; IERS 2010 eq. 10.12 leaves them
out too), are the force term :mod:`tqdyn.forces.eih_gcrs` (optional);
O(c^-4) is not modelled.
"""

from __future__ import annotations

import numpy as np

from .constants import C_LIGHT, L_B, L_G

__all__ = ["TDB_TO_TT_SCALE", "bcrs_to_gcrs", "gcrs_to_bcrs_offsets"]

#: K = (1 - L_G) / (1 - L_B): TDB-compatible -> TT-compatible lengths and GMs [1].
TDB_TO_TT_SCALE = 1.0 + (L_B - L_G) / (1.0 - L_B)  # written so that only the last rounding is left


def bcrs_to_gcrs(r, v, v_earth, gms) -> np.ndarray:
    """TT-compatible GCRS positions of bodies from their BCRS geocentric states.

    r, v : (..., n, 3) [m, m/s] -- x_B - x_E and v_B - v_E of n bodies from a
        TDB-compatible BCRS ephemeris at the geocentre's TDB (ICRF axes);
    v_earth : (..., 3) [m/s] -- the Earth's barycentric velocity there;
    gms : (n,) [m^3/s^2] -- the bodies' TDB-compatible GMs (their potential
        and attraction at the geocentre give U_ext and a_E; a body of GM 0
        contributes nothing).

    Returns X (..., n, 3) [m]: the positions at the same GCRS coordinate time,
    TT-compatible (the module docstring), ICRF axes.
    """
    r = np.asarray(r, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    ve = np.asarray(v_earth, dtype=np.float64)[..., None, :]
    gm = np.asarray(gms, dtype=np.float64)
    d = np.linalg.norm(r, axis=-1)                                  # (..., n)
    u_ext = np.sum(gm / d, axis=-1)[..., None, None]                # (..., 1, 1)
    a_e = np.sum((gm / d ** 3)[..., None] * r, axis=-2)[..., None, :]   # (..., 1, 3)
    c2 = C_LIGHT * C_LIGHT
    ve_r = np.sum(ve * r, axis=-1)[..., None]                       # (..., n, 1)
    ae_r = np.sum(a_e * r, axis=-1)[..., None]
    x = r + v * (ve_r / c2)                                         # simultaneity
    x = x + (0.5 * ve_r * ve + u_ext * r + ae_r * r - 0.5 * a_e * (d ** 2)[..., None]) / c2
    return TDB_TO_TT_SCALE * x


def _vdot(a, b):
    """Dot product over the last axis, kept as (..., 1) for broadcasting."""
    return np.sum(a * b, axis=-1, keepdims=True)


def gcrs_to_bcrs_offsets(y, w, acc, v_e, a_e, u_ext):
    """The 1PN GCRS -> BCRS terms of positions and velocities: the inverse of
    :func:`bcrs_to_gcrs` to O(c^-2).

    y, w, acc : (..., 3) [m, m/s, m/s^2] -- geocentric positions,
        velocities and accelerations in TDB-compatible units (the
        TT-compatible GCRS values divided by K = (1 - L_G)/(1 - L_B)) at one
        GCRS time T;
    v_e, a_e : (..., 3) -- the Earth's barycentric velocity and acceleration
        at TDB(T); u_ext : (..., 1) -- the potential of the other bodies at
        the geocentre [m^2/s^2] (all broadcast against y).

    Returns (dr, dw) (..., 3) [m, m/s]: the position relative to the
    geocentre at the barycentric time of the geocentre's event is r = y + dr,
    with

        dr = -[ (v_E.y) v_E / 2 + U_ext y + (a_E.y) y - a_E |y|^2 / 2 + w (v_E.y) ] / c^2

    (the first four terms invert the coordinate transformation of
    bcrs_to_gcrs, the last its simultaneity shift v (v_E.r)/c^2), and dw =
    d(dr)/dT along y' = w, w' = acc, v_E' = a_E (U_ext and a_E held
    constant: their rates contribute < 1e-8 m/s at 1e8 m).  Neglected:
    O(c^-4), ~1e-16 of |y|.
    """
    c2 = C_LIGHT * C_LIGHT
    vy, wy, ay = _vdot(v_e, y), _vdot(w, y), _vdot(a_e, y)
    vw, aw = _vdot(v_e, w), _vdot(a_e, w)
    yy = _vdot(y, y)
    dr = -(0.5 * vy * v_e + u_ext * y + ay * y - 0.5 * a_e * yy + w * vy) / c2
    dw = -(0.5 * (ay + vw) * v_e + 0.5 * vy * a_e + u_ext * w + aw * y + ay * w - a_e * wy
           + acc * vy + w * (ay + vw)) / c2
    return dr, dw
