"""The first post-Newtonian (1PN) n-body terms that IERS 2010 eq. (10.12) leaves out, in the GCRS:
the Einstein-Infeld-Hoffmann (EIH) equations of a satellite transformed to the geocentric frame.

**What the geocentric model has.**  tqdyn's geocentric acceleration is the Earth's field, the
point masses of the Sun, the Moon and the planets at their positions in the TT-compatible GCRS
(:func:`tqdyn.astro.geocentric.bcrs_to_gcrs`, the 1PN transformation of IAU 2000 B1.3) with the
Newtonian direct-minus-indirect formula, and eq. (10.12): the Earth's Schwarzschild and
Lense-Thirring terms and the Sun's de Sitter (geodetic precession) term.  In the GCRS metric of
Damour, Soffel & Xu (Soffel et al. 2003, AJ 126, 2687, the IAU 2000 B1.3 frame),
g_00 = -1 + 2W/c^2 - 2W^2/c^4, g_0a = -4 W^a/c^3, g_ab = (1 + 2W/c^2) delta_ab with
W = W_E + W_tidal, W^a = W^a_E + W^a_tidal + W^a_iner, a satellite's 1PN acceleration also has

* the 1PN part of the electric tidal field: the tidal moments at 1PN differ from the Newtonian
  tidal field of the body's GCRS position by relative O(GM_S/(c^2 R), v_E^2/c^2) ~ 1e-8.  For the
  Sun on a circular orbit the tidal acceleration G X in the Earth's frame, from the Riemann tensor
  of the Sun's field boosted to v_E (areal radius R + GM_S/c^2), is G = GM_S/R^3 diag(2 - 6 U + 3 b^2,
  -(1 - 3 U), -(1 - 3 U + 3 b^2)) along (n, v_E, normal), U = GM_S/(c^2 R), b^2 = v_E^2/c^2 = U;
  the Newtonian tide of the GCRS position (moved outward by 3/2 U) is GM_S/R^3 (1 - 9 U/2) diag(2, -1,
  -1): they differ by GM_S/R^3 U diag(6, -3/2, -9/2), 2.3e-13 m/s^2 along n at 1e5 km;
* the cross terms of the Earth's and the tidal potential, -4 (W_E grad W_tidal + W_tidal grad
  W_E)/c^2: estimated (4 GM_E/r)(2 GM_M r/D^3)/c^2 = 3e-15 m/s^2 for the Moon at 1e5 km;
* the velocity-dependent tidal terms, (V^2 grad W_tidal - 4 (V.grad W_tidal) V - 3 V dW_tidal/dT)/c^2:
  estimated <= 4 V^2 |grad W_tidal| / c^2 = 3e-15 m/s^2 (V = 2 km/s, the Moon's 1.7e-5 m/s^2 tide);
* the gravitomagnetic tidal terms: the Sun's velocity relative to the Earth (30 km/s) makes a
  gravitomagnetic field whose uniform part is the de Sitter precession of eq. (10.12) and whose
  gradient across the orbit is r/R = 7e-4 of it: estimated 4 V (v_E GM_S r/R^3)/c^2 ~ 8e-15 m/s^2;
  and the geodetic precession by the Moon and the planets, which eq. (10.12) leaves out: estimated
  3 v_rel (GM_M/D^2) V/c^2 ~ 2e-15 m/s^2 for the Moon (v_rel = 1 km/s).

Measured (tests/test_eih.py): their sum is 4.0e-14 .. 1.8e-13 m/s^2 at 1e5 km (random states, 2004 and
2035; 1.4e-13 .. 1.8e-13 on TianQin's orbits over one orbit from 2004-06-06), nearly all of it the
Sun's; the Moon's part 2.4e-15 .. 1.6e-14, the planets' ~1e-16 m/s^2.

**Evaluation: the EIH equations transformed.**  Rather than expanding W_tidal and W^a_tidal in
multipoles (the Moon at r/D = 0.26 would need many), this term evaluates the exact 1PN point-mass
problem and subtracts what the model already has.  The satellite's barycentric motion obeys the EIH
equations of a massless particle among the Earth and the third bodies
(:func:`tqdyn.forces.eih.eih_1pn_kernel`); the GCRS coordinates (T, X) follow from the barycentric
(t, x) by the IAU 2000 transformation (Soffel et al. 2003; IERS 2010 ch. 10)::

    T = t - c^-2 [A(t) + v_E . r],      dA/dt = v_E^2/2 + W0,
    X = r + c^-2 Phi,  Phi = v_E (v_E . r)/2 + W0 r + r (a_E . r) - a_E r^2/2,

with r = x - x_E(t), v_E, a_E, j_E = da_E/dt the Earth's barycentric velocity, Newtonian
acceleration and jerk, W0 = sum_j mu_j / |x_j - x_E| the potential of the other bodies at the
geocentre.  With u = dr/dt, b = du/dt and dT/dt = 1 - S/c^2, S = v_E^2/2 + W0 + a_E . r + v_E . u::

    d^2X/dT^2 = b + c^-2 [ D^2 Phi + 2 b S + u DS ],
    DS     = v_E . a_E + W0' + j_E . r + 2 a_E . u + v_E . b,
    D^2 Phi = j_E (v_E . r)/2 + a_E (a_E . r + v_E . u) + v_E (j_E . r + 2 a_E . u + v_E . b)/2
            + W0'' r + 2 W0' u + W0 b + b (a_E . r) + 2 u (j_E . r + a_E . u)
            + r (2 j_E . u + a_E . b) - 2 j_E (r . u) - a_E (u . u + r . b)

(D = d/dt; the Earth's snap d^2 a_E/dt^2 ~ 2e-16 m/s^4 would add r^2 |a_E''| / c^2 ~ 3e-23 m/s^2
and is left out).  Here b = x'' - x_E'' is the EIH acceleration of the satellite minus that of the
Earth (Newtonian + 1PN); in the c^-2 bracket its Newtonian value, r and u may be replaced by X and
V (the error is O(c^-4)).  Given the GCRS state (T, X, V), the barycentric r, u follow by inverting
the transformation to O(c^-2) (r = X - Phi(X)/c^2, u = V - [D Phi + V S]/c^2), and the satellite's
event is at the barycentric time t_E(T) + (v_E . r)/c^2, where t_E(T) is the geocentre's (TDB(TT),
where the ephemeris is read): the bodies' Newtonian terms are taken at positions moved by
(v_j - v_E)(v_E . r)/c^2 (<= 3 cm for the Moon, 1 m for the Sun).

The term is then

    d^2X/dT^2 - [ Newtonian Earth and third bodies at their GCRS positions + Schwarzschild + de Sitter ]

with the model's own positions, GMs and formulas.  The Newtonian parts (4e-2 m/s^2, moved by ~1e-8)
are differenced without cancellation (:func:`tqdyn.forces.third_body.pm_difference`), so the term's
float64 round-off is that of its largest pieces: the bracket's 2 b S / c^2 (1.2e-9 m/s^2) and the
Earth's EIH terms on the satellite, sums of barycentric velocities of 30 km/s (4e-10 m/s^2): ~1e-24
m/s^2.  Its 1PN truncation -- terms O(c^-4), which the 1PN transformation leaves undetermined, e.g.
3 b S^2/c^4 = 2.5e-17 m/s^2 -- separates it from the transformed EIH equations differentiated exactly:
by 3.5e-17 .. 5.1e-17 m/s^2 (tests/test_eih.py).

**Units.**  The dynamics are TT-compatible (positions and GMs of the model times K = (1 - L_G)/(1 -
L_B)); this term is evaluated in TDB-compatible units at X/K (GMs divided by K), and the result
divided by K.  The Earth's GM is the model's (``forces.gm_earth``) divided by K.

**Time-only and satellite-dependent parts.**  Per instant (:meth:`GeocentricEIH.precompute`): the
bodies' rows of :func:`tqdyn.forces.eih.eih_1pn_kernel` with the Earth first (geocentric BCRS
positions, barycentric velocities, Newtonian barycentric accelerations, potentials), the bodies'
1PN position corrections Delta_j of :func:`~tqdyn.astro.geocentric.bcrs_to_gcrs` (X_j = K (d_j +
Delta_j)), and j_E, W0', W0'', EIH_1PN(Earth); the satellite-dependent rest is the compiled
float64 kernel :func:`geocentric_eih_accel`.  The bodies are the run's third bodies (which must
include the Sun and the Moon, with ``third_bodies_gcrs``), point masses; the Earth is a point mass
here (its Lense-Thirring term stays that of eq. 10.12; the 1PN terms of its J2, ~J2 (R_E/r)^2 times
Schwarzschild, are ~2e-17 m/s^2).

Term interface (:mod:`tqdyn.forces.model`): parameters ``[K, c, gm_earth (TT), n, index of the Sun
among the bodies, mu_E, mu_1 .. mu_n]`` (mu TDB-compatible); time-only inputs per instant
``10 (n + 1) + 3 n + 8``: the rows (Earth, then the bodies), Delta_j (3 n), j_E (3), W0', W0'',
EIH_1PN(Earth) (3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008
from ..astro.ephemeris import Ephemeris, default_ephemeris, planetary_gm
from ..astro.geocentric import TDB_TO_TT_SCALE, bcrs_to_gcrs
from ..astro.timescales import tdb_jd
from .eih import N_BODY_COLUMNS, eih_1pn_kernel, newtonian_bodies
from .relativity import de_sitter_accel, schwarzschild_accel
from .third_body import pm_difference

__all__ = ["GeocentricEIH", "geocentric_eih_accel"]

_NB = N_BODY_COLUMNS


@njit(cache=True, inline="always")
def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@njit(cache=True, inline="always")
def _phi(x, y, z, vex, vey, vez, aex, aey, aez, w0):
    """Phi(r) of the transformation X = r + Phi/c^2 (module docstring) [m^3/s^2]."""
    ve_x, ae_x, xx = _dot(vex, vey, vez, x, y, z), _dot(aex, aey, aez, x, y, z), _dot(x, y, z, x, y, z)
    return (0.5 * vex * ve_x + w0 * x + x * ae_x - 0.5 * aex * xx,
            0.5 * vey * ve_x + w0 * y + y * ae_x - 0.5 * aey * xx,
            0.5 * vez * ve_x + w0 * z + z * ae_x - 0.5 * aez * xx)


@njit(cache=True, inline="always")
def _dphi_s(x, y, z, ux, uy, uz, vex, vey, vez, aex, aey, aez, jex, jey, jez, w0, w0d):
    """(D Phi (3) [m^3/s^3], S [m^2/s^2]) at r, u (module docstring)."""
    ve_x, ae_x, je_x = _dot(vex, vey, vez, x, y, z), _dot(aex, aey, aez, x, y, z), _dot(jex, jey, jez, x, y, z)
    ve_u, ae_u = _dot(vex, vey, vez, ux, uy, uz), _dot(aex, aey, aez, ux, uy, uz)
    xx, xu = _dot(x, y, z, x, y, z), _dot(x, y, z, ux, uy, uz)
    s = 0.5 * _dot(vex, vey, vez, vex, vey, vez) + w0 + ae_x + ve_u
    f, g = je_x + ae_u, ae_x + ve_u
    return (0.5 * aex * ve_x + 0.5 * vex * g + w0d * x + w0 * ux + ux * ae_x + x * f - 0.5 * jex * xx - aex * xu,
            0.5 * aey * ve_x + 0.5 * vey * g + w0d * y + w0 * uy + uy * ae_x + y * f - 0.5 * jey * xx - aey * xu,
            0.5 * aez * ve_x + 0.5 * vez * g + w0d * z + w0 * uz + uz * ae_x + z * f - 0.5 * jez * xx - aez * xu,
            s)


@njit(cache=True, inline="always")
def _bracket(x, y, z, ux, uy, uz, bx, by, bz, vex, vey, vez, aex, aey, aez, jex, jey, jez, w0, w0d, w0dd):
    """D^2 Phi + 2 b S + u DS [m^3/s^4] at r, u, b (module docstring)."""
    ve_x, ae_x, je_x = _dot(vex, vey, vez, x, y, z), _dot(aex, aey, aez, x, y, z), _dot(jex, jey, jez, x, y, z)
    ve_u, ae_u, je_u = _dot(vex, vey, vez, ux, uy, uz), _dot(aex, aey, aez, ux, uy, uz), _dot(jex, jey, jez, ux, uy, uz)
    ve_b, ae_b = _dot(vex, vey, vez, bx, by, bz), _dot(aex, aey, aez, bx, by, bz)
    xu, uu, xb = _dot(x, y, z, ux, uy, uz), _dot(ux, uy, uz, ux, uy, uz), _dot(x, y, z, bx, by, bz)
    s = 0.5 * _dot(vex, vey, vez, vex, vey, vez) + w0 + ae_x + ve_u
    ds = _dot(vex, vey, vez, aex, aey, aez) + w0d + je_x + 2.0 * ae_u + ve_b
    f0, f1, f2 = ae_x + ve_u, je_x + 2.0 * ae_u + ve_b, 2.0 * (je_x + ae_u)
    f3, f4, g = 2.0 * je_u + ae_b, uu + xb, w0 + ae_x + 2.0 * s
    return (0.5 * jex * ve_x + aex * f0 + 0.5 * vex * f1 + w0dd * x + 2.0 * w0d * ux + g * bx + ux * f2 + x * f3
            - 2.0 * jex * xu - aex * f4 + ux * ds,
            0.5 * jey * ve_x + aey * f0 + 0.5 * vey * f1 + w0dd * y + 2.0 * w0d * uy + g * by + uy * f2 + y * f3
            - 2.0 * jey * xu - aey * f4 + uy * ds,
            0.5 * jez * ve_x + aez * f0 + 0.5 * vez * f1 + w0dd * z + 2.0 * w0d * uz + g * bz + uz * f2 + z * f3
            - 2.0 * jez * xu - aez * f4 + uz * ds)


@njit(cache=True)
def geocentric_eih_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """The 1PN n-body terms beyond IERS 2010 eq. (10.12) [m/s^2] at the geocentric position r [m] and
    velocity v [m/s] (TT-compatible GCRS; the perturbation-kernel signature of
    :mod:`tqdyn.forces.model`).  tdat, params: the module docstring.  float64 scalars; returns
    (ax, ay, az)."""
    k_tt, c = params[0], params[1]
    c2 = c * c
    n = int(params[3])
    isun = int(params[4])
    mu = params[5:6 + n]
    mu_e = mu[0]
    x, y, z = rx / k_tt, ry / k_tt, rz / k_tt  # X in TDB-compatible units
    vex, vey, vez = tdat[3], tdat[4], tdat[5]
    aex, aey, aez = tdat[6], tdat[7], tdat[8]
    w0 = tdat[9]
    od = _NB * (n + 1)  # Delta_j
    oj = od + 3 * n
    jex, jey, jez = tdat[oj], tdat[oj + 1], tdat[oj + 2]
    w0d, w0dd = tdat[oj + 3], tdat[oj + 4]
    # barycentric r, u to O(c^-2): X = r + Phi/c^2, V = u + (D Phi + u S)/c^2
    px, py, pz = _phi(x, y, z, vex, vey, vez, aex, aey, aez, w0)
    e0x, e0y, e0z = -px / c2, -py / c2, -pz / c2  # r - X
    qx, qy, qz = x + e0x, y + e0y, z + e0z
    dx, dy, dz, s = _dphi_s(x, y, z, vx, vy, vz, vex, vey, vez, aex, aey, aez, jex, jey, jez, w0, w0d)
    ux, uy, uz = vx - (dx + vx * s) / c2, vy - (dy + vy * s) / c2, vz - (dz + vz * s) / c2
    dt = _dot(vex, vey, vez, qx, qy, qz) / c2  # the satellite's event after the geocentre's [s]
    # Newtonian b minus the model's Newtonian terms (exact differences), and the model's at X
    gx, gy, gz = pm_difference(mu_e, x, y, z, e0x, e0y, e0z)
    dbx, dby, dbz = -gx, -gy, -gz
    r2 = _dot(x, y, z, x, y, z)
    kr = -mu_e / (r2 * math.sqrt(r2))
    mx, my, mz = kr * x, kr * y, kr * z
    for j in range(n):
        o, od_j = _NB * (j + 1), od + 3 * j
        # body j moved to the satellite's event, relative to the model's GCRS position d_j + Delta_j
        sx = (tdat[o + 3] - vex) * dt - tdat[od_j]
        sy = (tdat[o + 4] - vey) * dt - tdat[od_j + 1]
        sz = (tdat[o + 5] - vez) * dt - tdat[od_j + 2]
        bx, by, bz = tdat[o] + tdat[od_j], tdat[o + 1] + tdat[od_j + 1], tdat[o + 2] + tdat[od_j + 2]
        m = mu[j + 1]
        gx, gy, gz = pm_difference(m, bx - x, by - y, bz - z, sx - e0x, sy - e0y, sz - e0z)
        hx, hy, hz = pm_difference(m, bx, by, bz, sx, sy, sz)
        dbx, dby, dbz = dbx + (gx - hx), dby + (gy - hy), dbz + (gz - hz)
        dx, dy, dz = bx - x, by - y, bz - z
        d2, p2 = _dot(dx, dy, dz, dx, dy, dz), _dot(bx, by, bz, bx, by, bz)
        kd, kp = m / (d2 * math.sqrt(d2)), m / (p2 * math.sqrt(p2))
        mx, my, mz = mx + (kd * dx - kp * bx), my + (kd * dy - kp * by), mz + (kd * dz - kp * bz)
    # the EIH 1PN accelerations: satellite (bodies unshifted: the shift is O(c^-4) here) minus Earth
    fx, fy, fz = eih_1pn_kernel(qx, qy, qz, vex + ux, vey + uy, vez + uz, tdat, mu, -1, c)
    fx, fy, fz = fx - tdat[oj + 5], fy - tdat[oj + 6], fz - tdat[oj + 7]
    # the c^-2 bracket with r, u, b -> X, V and the Newtonian terms at X (the error is O(c^-4))
    cx, cy, cz = _bracket(x, y, z, vx, vy, vz, mx, my, mz, vex, vey, vez, aex, aey, aez, jex, jey, jez, w0, w0d,
                          w0dd)
    # the model's Schwarzschild (TT units, its own GM) and de Sitter (the Sun's geocentric BCRS state)
    hx, hy, hz = schwarzschild_accel(rx, ry, rz, vx, vy, vz, params[2], c, 1.0, 1.0)
    o = _NB * (isun + 1)
    wx, wy, wz = de_sitter_accel(vx, vy, vz, tdat[o], tdat[o + 1], tdat[o + 2], tdat[o + 3] - vex,
                                 tdat[o + 4] - vey, tdat[o + 5] - vez, mu[isun + 1], c, 1.0)
    return ((dbx + fx + cx / c2) / k_tt - hx - wx, (dby + fy + cy / c2) / k_tt - hy - wy,
            (dbz + fz + cz / c2) / k_tt - hz - wz)


@njit(cache=True)
def _fill_geocentric(pos, vel, v_earth, delta, mu, c, out):
    """Time-only inputs (m, 10 (n + 1) + 3 n + 8) from the bodies' geocentric BCRS positions pos and
    velocities vel (m, n, 3) [m, m/s], the Earth's barycentric velocity v_earth (m, 3), the 1PN
    position corrections delta (m, n, 3) [m] and the GMs mu (n + 1,) (the Earth first)."""
    n = mu.shape[0] - 1
    od = _NB * (n + 1)
    oj = od + 3 * n
    for t in range(out.shape[0]):
        row = out[t]
        for q in range(3):
            row[q] = 0.0
            row[3 + q] = v_earth[t, q]
        for j in range(n):
            o = _NB * (j + 1)
            for q in range(3):
                row[o + q] = pos[t, j, q]
                row[o + 3 + q] = vel[t, j, q] + v_earth[t, q]
                row[od + 3 * j + q] = delta[t, j, q]
        newtonian_bodies(row, mu)
        jx, jy, jz, w1, w2 = 0.0, 0.0, 0.0, 0.0, 0.0
        for j in range(n):
            o = _NB * (j + 1)
            dx, dy, dz = row[o], row[o + 1], row[o + 2]
            wx, wy, wz = vel[t, j, 0], vel[t, j, 1], vel[t, j, 2]
            d2 = dx * dx + dy * dy + dz * dz
            d3 = d2 * math.sqrt(d2)
            dw = dx * wx + dy * wy + dz * wz
            m = mu[j + 1]
            jx += m * (wx / d3 - 3.0 * dw * dx / (d3 * d2))
            jy += m * (wy / d3 - 3.0 * dw * dy / (d3 * d2))
            jz += m * (wz / d3 - 3.0 * dw * dz / (d3 * d2))
            w1 -= m * dw / d3
            da = dx * (row[o + 6] - row[6]) + dy * (row[o + 7] - row[7]) + dz * (row[o + 8] - row[8])
            w2 += m * (-(wx * wx + wy * wy + wz * wz + da) / d3 + 3.0 * dw * dw / (d3 * d2))
        row[oj], row[oj + 1], row[oj + 2], row[oj + 3], row[oj + 4] = jx, jy, jz, w1, w2
        row[oj + 5], row[oj + 6], row[oj + 7] = eih_1pn_kernel(0.0, 0.0, 0.0, row[3], row[4], row[5], row, mu, 0, c)


@dataclass(frozen=True)
class GeocentricEIH:
    """The 1PN n-body terms beyond IERS 2010 eq. (10.12) in the TT-compatible GCRS (module
    docstring): to be used with the third bodies ``names`` in the GCRS (which must include the Sun
    and the Moon) and :class:`~tqdyn.forces.relativity.Relativity` (Schwarzschild, de Sitter).

    names: the third bodies (:data:`tqdyn.astro.ephemeris.BODIES`); ephemeris: their source (None:
    the shipped DE421); gm_earth [m^3/s^2]: the model's TT-compatible GM of the Earth; gms: ((body,
    GM [m^3/s^2, TDB-compatible]), ...) of the bodies, the scenario's ``forces.gm_*`` (empty: DE430/DE431,
    ``data/gm_de431.tpc``)."""

    names: tuple[str, ...] = ("sun", "moon")
    ephemeris: Ephemeris | None = None
    gm_earth: float = float(GM_EARTH_EGM2008)
    gms: tuple = ()
    name: str = field(default="relativity_eih_gcrs", init=False)
    description: str = field(
        default="1PN n-body terms beyond IERS 2010 eq. 10.12 in the GCRS: 1PN tidal field, velocity-dependent and "
                "gravitomagnetic tidal terms of the third bodies, their geodetic precession beyond the Sun's "
                "(EIH equations transformed to the GCRS; forces.relativity_model = \"eih\")", init=False)
    source: str = field(
        default="EIH equations (Standish & Williams, Explanatory Supplement ch. 8 eq. 8.1) transformed by the IAU "
                "2000 B1.3 BCRS -> GCRS transformation (Soffel et al. 2003, AJ 126, 2687), minus the Newtonian "
                "third bodies in the GCRS and IERS 2010 eq. 10.12; bodies from a JPL ephemeris", init=False)
    n_tdat: int = field(default=0, init=False)

    def __post_init__(self):
        names = tuple(str(b).lower() for b in self.names)
        object.__setattr__(self, "names", names)
        for body in ("sun", "moon"):
            if body not in names:
                raise ValueError(f"relativity_eih_gcrs: the third bodies {names} lack {body!r}, which the GCRS "
                                 "transformation of the model needs")
        object.__setattr__(self, "n_tdat", _NB * (len(names) + 1) + 3 * len(names) + 8)

    def _ephemeris(self) -> Ephemeris:
        return default_ephemeris() if self.ephemeris is None else self.ephemeris

    def _gms(self) -> np.ndarray:
        """[mu_E, mu_1 .. mu_n] TDB-compatible [m^3/s^2]."""
        gm = dict(self.gms) if self.gms else planetary_gm()
        return np.array([self.gm_earth / TDB_TO_TT_SCALE] + [gm[b] for b in self.names], dtype=np.float64)

    def params(self) -> np.ndarray:
        """[K, c, gm_earth (TT), n, index of the Sun, mu_E, mu_1 .. mu_n] float64 (SI)."""
        return np.concatenate([[TDB_TO_TT_SCALE, C_LIGHT, self.gm_earth, len(self.names), self.names.index("sun")],
                               self._gms()])

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Time-only inputs at t = t_hi + t_lo [s TT since ``epoch``], the ephemeris read at the
        geocentre's TDB: float64 (*broadcast shape of t_hi, t_lo, n_tdat) (module docstring)."""
        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, dtype=np.float64), np.asarray(t_lo, dtype=np.float64))
        shape = t_hi.shape
        jd1, jd2 = tdb_jd(epoch, t_hi.reshape(-1), t_lo.reshape(-1))
        eph = self._ephemeris()
        pos, vel = eph.geocentric_states(self.names, jd1, jd2, velocity=True)
        _, v_earth = eph.earth_barycentric(jd1, jd2)
        mu = self._gms()
        # the model's 1PN position corrections (tqdyn.forces.third_body_ephemeris.EphemerisPositions.correction)
        delta = bcrs_to_gcrs(pos, vel, v_earth, mu[1:]) / TDB_TO_TT_SCALE - pos
        out = np.empty((jd1.size, self.n_tdat))
        _fill_geocentric(np.ascontiguousarray(pos), np.ascontiguousarray(vel), np.ascontiguousarray(v_earth),
                         np.ascontiguousarray(delta), mu, C_LIGHT, out)
        return out.reshape(shape + (self.n_tdat,))
