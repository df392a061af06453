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

The other way, GCRS -> BCRS (the LISA export of geocentric runs):
:func:`gcrs_to_bcrs_offsets` inverts the transformation to O(c^-2) and
:func:`gcrs_to_bcrs_states` moves a geocentric trajectory's states to the
solar-system barycentre on a uniform TDB grid, with the Earth's
barycentric state and the external field U_ext, a_E at the geocentre from
:func:`earth_barycentric_field` (:func:`external_field`, the same sums as
:func:`bcrs_to_gcrs`).
"""

from __future__ import annotations

import numpy as np

from ..numerics.dd import np_dd_add, np_dd_add_d, np_dd_div_d, np_two_sum
from ..numerics.hermite import interpolate_states
from .constants import C_LIGHT, L_B, L_G
from .timescales import geocentre_tdb_grid, tdb_jd

__all__ = ["EXTERNAL_BODIES", "TDB_TO_TT_SCALE", "bcrs_to_gcrs", "earth_barycentric_field", "external_field",
           "gcrs_to_bcrs_offsets", "gcrs_to_bcrs_states",
           "bcrs_to_gcrs_offsets"]

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
    t1, t2 = _pn_terms(r, v, v_earth, gms)
    return TDB_TO_TT_SCALE * ((r + t1) + t2)


def bcrs_to_gcrs_offsets(r, v, v_earth, gms) -> np.ndarray:
    """delta = X / K - r [m] (..., n, 3) of :func:`bcrs_to_gcrs` (same
    arguments), formed without r, so without r's rounding: the 1PN part of
    the transformation (<= 1.5e-8 |r|), a smooth function of the states."""
    t1, t2 = _pn_terms(r, v, v_earth, gms)
    return t1 + t2


def _pn_terms(r, v, v_earth, gms):
    """The two 1PN terms of :func:`bcrs_to_gcrs`: X / K = (r + t1) + t2."""
    r = np.asarray(r, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    ve = np.asarray(v_earth, dtype=np.float64)[..., None, :]
    d = np.linalg.norm(r, axis=-1)                                  # (..., n)
    u_ext, a_e = external_field(r, gms)
    u_ext, a_e = u_ext[..., None, None], a_e[..., None, :]          # (..., 1, 1), (..., 1, 3)
    c2 = C_LIGHT * C_LIGHT
    ve_r = np.sum(ve * r, axis=-1)[..., None]                       # (..., n, 1)
    ae_r = np.sum(a_e * r, axis=-1)[..., None]
    t1 = v * (ve_r / c2)                                            # simultaneity
    t2 = (0.5 * ve_r * ve + u_ext * r + ae_r * r - 0.5 * a_e * (d ** 2)[..., None]) / c2
    return t1, t2


def external_field(r, gms) -> tuple[np.ndarray, np.ndarray]:
    """The other bodies' Newtonian potential and attraction at the geocentre.

    r: (..., n, 3) [m] geocentric positions of n bodies (BCRS, TDB-compatible,
    ICRF axes); gms: (n,) [m^3/s^2] their TDB-compatible GMs.  Returns
    U_ext = sum_j GM_j / |r_j| (...) [m^2/s^2] and a_E = sum_j GM_j r_j /
    |r_j|^3 (..., 3) [m/s^2] (the Earth's barycentric acceleration due to
    them), TDB-compatible.
    """
    r = np.asarray(r, dtype=np.float64)
    gm = np.asarray(gms, dtype=np.float64)
    d = np.linalg.norm(r, axis=-1)
    return np.sum(gm / d, axis=-1), np.sum((gm / d ** 3)[..., None] * r, axis=-2)


#: Bodies whose potential and attraction at the geocentre enter the GCRS -> BCRS transformation (those of them
#: that the ephemeris holds): the Sun, the Moon and the planets' systems.
EXTERNAL_BODIES = ("sun", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")


def earth_barycentric_field(ephemeris, jd1, jd2):
    """The Earth's barycentric state and the external field at the geocentre at TDB dates.

    ephemeris: an :class:`tqdyn.astro.ephemeris.Ephemeris`; jd1, jd2: (N,)
    two-part TDB Julian dates [d].  Returns (x_E, v_E, a_E, U_ext, bodies):
    the Earth's barycentric position [m] and velocity [m/s] (N, 3), its
    acceleration a_E (N, 3) [m/s^2] and the potential U_ext (N, 1)
    [m^2/s^2] of the :data:`EXTERNAL_BODIES` the ephemeris holds
    (:func:`external_field`, DE430/DE431 GMs), and the names of those
    bodies; BCRS, TDB-compatible, ICRF axes.
    """
    from .ephemeris import planetary_gm

    x_e, v_e = ephemeris.earth_barycentric(jd1, jd2)
    names = tuple(b for b in EXTERNAL_BODIES if b in ephemeris.bodies)
    rel, _ = ephemeris.geocentric_states(names, jd1, jd2, velocity=False)
    gms = planetary_gm()
    u_ext, a_e = external_field(rel, np.array([gms[b] for b in names]))
    return x_e, v_e, a_e, u_ext[:, None], names


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


def _bc(x, ndim: int):
    """(N, k) -> (N, 1, ..., 1, k) with ndim dimensions (broadcast over the bodies' axes)."""
    return x.reshape(x.shape[:1] + (1,) * (ndim - 2) + x.shape[-1:])


def gcrs_to_bcrs_states(epoch, t, bodies, ephemeris) -> dict:
    """Geocentric states (TT-compatible GCRS, TT) -> barycentric ones (BCRS: origin the solar-system barycentre,
    ICRF axes, TDB-compatible) on the uniform TDB grid that spans the TT grid.

    epoch: the :class:`tqdyn.astro.timescales.Epoch` of t; t: dd (hi, lo)
    (N,) [s TT since the epoch]; bodies: name -> (r, v, a) with r, v dd
    (hi, lo) pairs of (N, ..., 3) [m, m/s] and a float64 (N, ..., 3)
    [m/s^2] (e.g. (N, 3, 3) satellites or (N, 3, 2, 3) test masses), GCRS
    on the grid t; ephemeris: an :class:`tqdyn.astro.ephemeris.Ephemeris`.

    The grid t_k and the geocentre's TT instants T_k are those of
    :func:`tqdyn.astro.timescales.geocentre_tdb_grid`; the states at T_k come
    from the quintic Hermite dense output of the grid
    (:func:`tqdyn.numerics.hermite.interpolate_states`; accelerations:
    linear between rows).  Then y = X / K, w = V / K (K =
    :data:`TDB_TO_TT_SCALE`), r = y + dr (:func:`gcrs_to_bcrs_offsets`), x_B
    = x_E(TDB(T_k)) + r, v_B = v_E + (w + dw) dT/dt, a_B = a_E + (acc/K)
    (dT/dt)^2 (the 1PN terms of a, < 1e-9 m/s^2, are not applied), with x_E,
    v_E, a_E, U_ext from :func:`earth_barycentric_field`.

    Returns a dict: ``t`` (hi, lo) [s TDB since the epoch's TDB], ``T``
    (hi, lo) [s TT since the epoch], ``x_e``, ``v_e``, ``a_e`` (N, 3),
    ``u_ext`` (N, 1), ``dT_dt_m1`` (N,) (dT/dt - 1), ``u_ext_bodies``
    (names), ``bodies``: name -> ((hi, lo) positions [m], (hi, lo)
    velocities [m/s], float64 accelerations [m/s^2]) in the BCRS, and
    ``y``: name -> (y, w), the geocentric positions and velocities at T_k in
    TDB-compatible units (float64).
    """
    th, tl = (np.asarray(p, np.float64) for p in t)
    N = th.size
    (bh, bl), (Th, Tl), dT_dt_m1 = geocentre_tdb_grid(epoch, (th, tl))
    jd1, jd2 = tdb_jd(epoch, Th, Tl)
    x_e, v_e, a_e, u_ext, names = earth_barycentric_field(ephemeris, jd1, jd2)
    K = float(TDB_TO_TT_SCALE)
    nodes = np.ascontiguousarray(np.stack([th, tl], -1))
    query = np.ascontiguousarray(np.stack([Th, Tl], -1))
    jn = np.clip(np.searchsorted(th + tl, Th + Tl, side="right") - 1, 0, N - 2)
    frac = ((Th - th[jn]) + (Tl - tl[jn])) / ((th[jn + 1] - th[jn]) + (tl[jn + 1] - tl[jn]))
    out, ys = {}, {}
    for name, (r, v, a) in bodies.items():
        r = np.ascontiguousarray(np.stack([np.asarray(p, np.float64) for p in r], -1))
        v = np.ascontiguousarray(np.stack([np.asarray(p, np.float64) for p in v], -1))
        a = np.ascontiguousarray(np.asarray(a, np.float64))
        rq, vq = interpolate_states(nodes, r, v, a, query)
        fr = frac.reshape((-1,) + (1,) * (a.ndim - 1))
        acc = (a[jn] * (1 - fr) + a[jn + 1] * fr) / K
        yh, yl = np_dd_div_d(rq[..., 0], rq[..., 1], K)
        y = yh + yl
        w = (vq[..., 0] + vq[..., 1]) / K
        nd = y.ndim
        ve, ae = _bc(v_e, nd), _bc(a_e, nd)
        dr, dw = gcrs_to_bcrs_offsets(y, w, acc, ve, ae, _bc(u_ext, nd))
        xh, xl = np_dd_add_d(yh, yl, dr)
        xh, xl = np_dd_add(xh, xl, *np_two_sum(_bc(x_e, nd) + 0.0 * y, np.zeros_like(y)))
        rate = 1.0 + _bc(dT_dt_m1[:, None], nd)
        vh, vl = np_two_sum(ve + 0.0 * w, (w + dw) * rate)
        out[name] = ((xh, xl), (vh, vl), ae + acc * rate * rate)
        ys[name] = (y, w)
    return {"t": (bh, bl), "T": (Th, Tl), "x_e": x_e, "v_e": v_e, "a_e": a_e, "u_ext": u_ext, "dT_dt_m1": dT_dt_m1,
            "bodies": out, "y": ys, "u_ext_bodies": names}
