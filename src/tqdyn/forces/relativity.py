"""Post-Newtonian (relativistic) correction to the geocentric acceleration of
an Earth satellite: IERS Conventions (2010), IERS Technical Note 36, ch. 10,
sec. 10.3, eq. (10.12):

    Delta a = GM_E/(c^2 r^3) { [2(beta+gamma) GM_E/r - gamma v.v] r
                               + 2(1+gamma) (r.v) v }                       Schwarzschild
            + (1+gamma) GM_E/(c^2 r^3) [ (3/r^2)(r x v)(r.J) + v x J ]       Lense-Thirring
            + (1+2 gamma) [ Rdot x ( -GM_S R / (c^2 R^3) ) ] x v             de Sitter

r, v: geocentric position and velocity of the satellite (GCRS); R, Rdot:
position and velocity of the Earth with respect to the Sun (here minus the
Sun's geocentric state from the ephemeris); J: the Earth's angular momentum
per unit mass, |J| ~ 9.8e8 m^2/s (TN36 sec. 10.3); GM_E, GM_S: geocentric
and heliocentric gravitational constants; beta = gamma = 1 (general
relativity).

Choices (each a field of :class:`Relativity`):

* GM_E = 3.986004415e14 m^3/s^2 (EGM2008, TT-compatible, the value of the
  central term); GM_S from the ephemeris' GM file (DE430/431,
  TDB-compatible); c = 299792458 m/s.  Eq. (10.12) belongs to the GCRS,
  whose time coordinate is TCG; tqdyn integrates in TT (the TT-compatible
  GCRS) with TT- and TDB-compatible GMs, which rescales the correction by
  relative amounts of order L_G ~ 7e-10 or L_B ~ 1.6e-8, i.e. < 1e-18 m/s^2
  here.
* Direction of J (``j_axis``): ``"cip"`` (default) -- the Celestial
  Intermediate Pole, i.e. the Earth's rotation axis, in the GCRS
  (IAU 2006/2000A via ``erfa.xy06``, without the EOP celestial-pole offsets
  dX, dY ~ 0.1 mas), or ``"gcrs_z"`` -- the GCRS z axis.  In 2004 the two
  differ by ~4.1e-4 rad (precession since J2000), which changes the
  Lense-Thirring term by ~4e-4 of its ~6e-14 m/s^2 (~2e-17 m/s^2, measured
  in the tests).  Polar motion (CIP vs ITRS pole, ~2e-6 rad) and the
  difference between the angular-momentum and rotation axes are far below that.
* The CIP is evaluated with ERFA on a fixed grid of nodes 0.5 d apart
  (counted from the epoch, whatever instants are requested together, so
  that the force is one function of time) and interpolated by the 8-point
  Lagrange polynomial (error < 1e-14 rad against ``erfa.xy06``, measured in
  the tests; the shortest significant nutation term has a 13.66 d period),
  so precompute stays fast.

Magnitudes on a TianQin orbit (r = 1e8 m, v = 1996 m/s): Schwarzschild
3 GM_E^2/(c^2 r^3) = 5.3e-12 m/s^2; de Sitter <= 3 GM_S |Rdot| v/(c^2 R^2) =
1.2e-11 m/s^2 (a Coriolis term of twice the geodetic precession, 19 mas/yr;
larger than Schwarzschild at this radius); Lense-Thirring ~
2 GM_E v |J|/(c^2 r^3) = 1.7e-14 m/s^2, up to ~6e-14 m/s^2.  All evaluated in
float64 (relative round-off ~1e-16, i.e. < 1e-26 m/s^2).

Term interface (see :mod:`tqdyn.forces.model`): parameters
``[gm_e, c, beta, gamma, gm_s, |J|, on_schwarzschild, on_lense_thirring,
on_de_sitter]``; time-only inputs (9 per instant) ``[s_x, s_y, s_z, sv_x,
sv_y, sv_z, j_x, j_y, j_z]``: geocentric GCRS position [m] and velocity [m/s]
of the Sun (zeros if de Sitter is off) and the unit vector of J in the GCRS
(zeros if Lense-Thirring is off).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import erfa
import numpy as np

from .._choices import unknown
from ..astro.constants import C_LIGHT, DAY_S, GM_EARTH_EGM2008, J_EARTH_IERS2010
from ..astro.ephemeris import Ephemeris, default_ephemeris, planetary_gm
from ..astro.timescales import tdb_jd, tt_jd
from ..numerics.lagrange import MARGIN, grid_interp
from ..numerics.jit import inner_kernel

__all__ = [
    "Relativity",
    "schwarzschild_accel",
    "lense_thirring_accel",
    "de_sitter_accel",
    "relativity_accel",
    "cip_direction",
    "N_TDAT",
]

#: Time-only inputs per instant: Sun position (3), Sun velocity (3), J unit vector (3).
N_TDAT = 9

_J_AXES = ("cip", "gcrs_z")
_CIP_NODE_SPACING = 0.5 * DAY_S  # s between ERFA evaluations of the CIP


@inner_kernel
def schwarzschild_accel(rx, ry, rz, vx, vy, vz, gm, c, beta, gamma):
    """Schwarzschild term of IERS 2010 eq. (10.12) [m/s^2], GCRS:
    GM/(c^2 r^3) {[2(beta+gamma) GM/r - gamma v.v] r + 2(1+gamma)(r.v) v}.
    r [m], v [m/s]: geocentric GCRS state; gm [m^3/s^2]; c [m/s].
    float64 scalars; returns (ax, ay, az)."""
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    v2 = vx * vx + vy * vy + vz * vz
    rv = rx * vx + ry * vy + rz * vz
    k = gm / (c * c * r2 * r)
    f = k * (2.0 * (beta + gamma) * gm / r - gamma * v2)
    g = k * (2.0 * (1.0 + gamma) * rv)
    return f * rx + g * vx, f * ry + g * vy, f * rz + g * vz


@inner_kernel
def schwarzschild_jerk(rx, ry, rz, vx, vy, vz, gm, c, beta, gamma):
    """Time derivative [m/s^3] of :func:`schwarzschild_accel` along the
    Kepler motion (r' = v, v' = -gm r/r^3; the post-Newtonian part of v'
    changes it by ~1e-8 relative): with k = gm/(c^2 r^3), s = r.v,
    P = 2(beta+gamma) gm/r - gamma v.v, Q = 2(1+gamma) s, a0 = -gm r/r^3:
    k' = -3 k s/r^2, P' = -2 beta gm s/r^3, Q' = 2(1+gamma)(v.v - gm/r),
    jerk = k' (P r + Q v) + k (P' r + (P + Q') v + Q a0).
    Same frame and units as the acceleration; float64 scalars."""
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    v2 = vx * vx + vy * vy + vz * vz
    s = rx * vx + ry * vy + rz * vz
    k = gm / (c * c * r2 * r)
    kd = -3.0 * k * s / r2
    p = 2.0 * (beta + gamma) * gm / r - gamma * v2
    q = 2.0 * (1.0 + gamma) * s
    pd = -2.0 * beta * gm * s / (r2 * r)
    qd = 2.0 * (1.0 + gamma) * (v2 - gm / r)
    m = -gm / (r2 * r)
    return (kd * (p * rx + q * vx) + k * (pd * rx + (p + qd) * vx + q * m * rx),
            kd * (p * ry + q * vy) + k * (pd * ry + (p + qd) * vy + q * m * ry),
            kd * (p * rz + q * vz) + k * (pd * rz + (p + qd) * vz + q * m * rz))


@inner_kernel
def lense_thirring_accel(rx, ry, rz, vx, vy, vz, jx, jy, jz, gm, c, gamma):
    """Lense-Thirring term of IERS 2010 eq. (10.12) [m/s^2], GCRS:
    (1+gamma) GM/(c^2 r^3) [(3/r^2)(r x v)(r.J) + v x J].
    r [m], v [m/s]; J = (jx, jy, jz) the Earth's angular momentum per unit
    mass [m^2/s] in the GCRS.  float64 scalars; returns (ax, ay, az)."""
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    k = (1.0 + gamma) * gm / (c * c * r2 * r)
    q = 3.0 * (rx * jx + ry * jy + rz * jz) / r2
    hx, hy, hz = ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx  # r x v
    wx, wy, wz = vy * jz - vz * jy, vz * jx - vx * jz, vx * jy - vy * jx  # v x J
    return k * (q * hx + wx), k * (q * hy + wy), k * (q * hz + wz)


@inner_kernel
def de_sitter_accel(vx, vy, vz, sx, sy, sz, svx, svy, svz, gm_sun, c, gamma):
    """De Sitter (geodesic precession) term of IERS 2010 eq. (10.12) [m/s^2],
    GCRS: (1+2 gamma) [Rdot x (-GM_S R/(c^2 R^3))] x v, with R = -s, Rdot = -sv
    the Earth's position [m] and velocity [m/s] relative to the Sun (s, sv:
    geocentric GCRS state of the Sun); v [m/s] the satellite's geocentric
    velocity; gm_sun [m^3/s^2].  float64 scalars; returns (ax, ay, az)."""
    Rx, Ry, Rz = -sx, -sy, -sz
    Ux, Uy, Uz = -svx, -svy, -svz
    R2 = Rx * Rx + Ry * Ry + Rz * Rz
    k = -gm_sun / (c * c * R2 * math.sqrt(R2))
    wx, wy, wz = k * Rx, k * Ry, k * Rz  # -GM_S R / (c^2 R^3)
    f = 1.0 + 2.0 * gamma
    ox = f * (Uy * wz - Uz * wy)  # Omega = (1+2 gamma) Rdot x w
    oy = f * (Uz * wx - Ux * wz)
    oz = f * (Ux * wy - Uy * wx)
    return oy * vz - oz * vy, oz * vx - ox * vz, ox * vy - oy * vx


@inner_kernel
def relativity_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Sum of the enabled terms of IERS 2010 eq. (10.12) [m/s^2], GCRS (the
    perturbation-kernel signature of :mod:`tqdyn.forces.model`).

    rx..vz: geocentric GCRS position [m] and velocity [m/s] (float64);
    tdat: this instant's time-only inputs (>= 9: Sun position [m], Sun
    velocity [m/s], unit vector of J); params: [gm_e, c, beta, gamma, gm_s,
    |J|, on_schwarzschild, on_lense_thirring, on_de_sitter].
    """
    gm, c, beta, gamma = params[0], params[1], params[2], params[3]
    ax, ay, az = 0.0, 0.0, 0.0
    if params[6] != 0.0:
        gx, gy, gz = schwarzschild_accel(rx, ry, rz, vx, vy, vz, gm, c, beta, gamma)
        ax, ay, az = ax + gx, ay + gy, az + gz
    if params[7] != 0.0:
        jm = params[5]
        gx, gy, gz = lense_thirring_accel(rx, ry, rz, vx, vy, vz, jm * tdat[6], jm * tdat[7], jm * tdat[8],
                                          gm, c, gamma)
        ax, ay, az = ax + gx, ay + gy, az + gz
    if params[8] != 0.0:
        gx, gy, gz = de_sitter_accel(vx, vy, vz, tdat[0], tdat[1], tdat[2], tdat[3], tdat[4], tdat[5],
                                     params[4], c, gamma)
        ax, ay, az = ax + gx, ay + gy, az + gz
    return ax, ay, az


def cip_direction(epoch, t_hi, t_lo=0.0) -> np.ndarray:
    """Unit vector of the Celestial Intermediate Pole in the GCRS,
    (X, Y, sqrt(1 - X^2 - Y^2)) with X, Y from ``erfa.xy06`` (IAU 2006
    precession + IAU 2000A nutation; no EOP dX, dY), at t = t_hi + t_lo
    [s TT since ``epoch``].

    Evaluated on the nodes k 0.5 d (k integer, t counted from the epoch)
    and interpolated by the 8-point Lagrange polynomial (module docstring).
    Returns float64 (*broadcast shape of t_hi, t_lo, 3).
    """
    t = np.add(np.asarray(t_hi, dtype=np.float64), np.asarray(t_lo, dtype=np.float64))
    shape = t.shape
    flat = t.reshape(-1)
    out = np.empty((flat.size, 3))
    if flat.size == 0:
        return out.reshape(shape + (3,))
    if not np.all(np.isfinite(flat)):
        raise ValueError("relativity: CIP direction requested at a non-finite time")
    u = flat / _CIP_NODE_SPACING
    k0 = int(math.floor(u.min())) - MARGIN
    k1 = int(math.floor(u.max())) + MARGIN + 1
    x, y = erfa.xy06(*tt_jd(epoch, np.arange(k0, k1, dtype=np.float64) * _CIP_NODE_SPACING))
    xy = np.empty((flat.size, 2))
    grid_interp(u, k0, np.stack((x, y), axis=-1), xy)
    out[:, :2] = xy
    out[:, 2] = np.sqrt(1.0 - out[:, 0] ** 2 - out[:, 1] ** 2)
    return out.reshape(shape + (3,))


@dataclass(frozen=True)
class Relativity:
    """Post-Newtonian correction, IERS Conventions 2010 eq. (10.12), geocentric GCRS.

    Fields
    ------
    schwarzschild, lense_thirring, de_sitter : bool
        Switch each of the three terms.
    ephemeris : Ephemeris or None
        Source of the Sun's geocentric state for de Sitter (``None``: the
        shipped DE421, :func:`tqdyn.astro.ephemeris.default_ephemeris`).
    j_axis : str
        Direction of J: ``"cip"`` (rotation axis, default) or ``"gcrs_z"``.
    gm_earth : float
        GM_E [m^3/s^2], default EGM2008's 3.986004415e14.
    gm_sun : float or None
        GM_S [m^3/s^2] of the de Sitter term (None: DE430/431 of
        :func:`tqdyn.astro.ephemeris.planetary_gm`; a run passes its
        scenario's ``forces.gm_sun``).
    j_earth : float
        |J| [m^2/s], default 9.8e8 (TN36 sec. 10.3).
    beta, gamma : float
        PPN parameters, 1 in general relativity.

    c is exact (299792458 m/s).
    """

    schwarzschild: bool = True
    lense_thirring: bool = True
    de_sitter: bool = True
    ephemeris: Ephemeris | None = None
    j_axis: str = "cip"
    gm_earth: float = float(GM_EARTH_EGM2008)
    j_earth: float = J_EARTH_IERS2010
    gm_sun: float | None = None
    beta: float = 1.0
    gamma: float = 1.0
    name: str = field(default="relativity", init=False)
    description: str = field(
        default="post-Newtonian correction (IERS 2010 eq. 10.12): Schwarzschild, Lense-Thirring, de Sitter",
        init=False)
    source: str = field(
        default="IERS Conventions 2010 (TN36) ch. 10 eq. (10.12); Sun from a JPL ephemeris; CIP from ERFA xy06",
        init=False)
    n_tdat: int = field(default=N_TDAT, init=False)

    def __post_init__(self):
        if self.j_axis not in _J_AXES:
            raise ValueError(unknown("relativity: j_axis", self.j_axis, _J_AXES))
        for label, value in (("gm_earth", self.gm_earth), ("j_earth", self.j_earth)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"relativity: {label} = {value!r}; expected a positive finite number")
        if self.de_sitter:
            eph = self._ephemeris()
            object.__setattr__(self, "source", (
                f"IERS Conventions 2010 (TN36) ch. 10 eq. (10.12); Sun: JPL {eph.name} ({eph.path}), "
                f"GM_S from gm_de431.tpc; J along the {'CIP (ERFA xy06)' if self.j_axis == 'cip' else 'GCRS z axis'}"))

    def _ephemeris(self) -> Ephemeris:
        return default_ephemeris() if self.ephemeris is None else self.ephemeris

    def params(self) -> np.ndarray:
        """[gm_e, c, beta, gamma, gm_s, |J|, on_s, on_lt, on_ds] float64 (SI)."""
        gm_sun = planetary_gm()["sun"] if self.gm_sun is None else float(self.gm_sun)
        return np.array([self.gm_earth, C_LIGHT, self.beta, self.gamma, gm_sun, self.j_earth,
                         float(self.schwarzschild), float(self.lense_thirring), float(self.de_sitter)],
                        dtype=np.float64)

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Time-only inputs at t = t_hi + t_lo [s TT since ``epoch``]:
        float64 (*broadcast shape of t_hi, t_lo, 9) = Sun's geocentric GCRS
        position [m] and velocity [m/s] (zeros if de Sitter is off), unit
        vector of J in the GCRS (zeros if Lense-Thirring is off)."""
        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, dtype=np.float64), np.asarray(t_lo, dtype=np.float64))
        out = np.zeros(t_hi.shape + (N_TDAT,))
        if self.de_sitter:
            jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
            pos, vel = self._ephemeris().geocentric_states(("sun",), jd1, jd2, velocity=True)
            out[..., 0:3] = pos[..., 0, :]
            out[..., 3:6] = vel[..., 0, :]
        if self.lense_thirring:
            if self.j_axis == "cip":
                out[..., 6:9] = cip_direction(epoch, t_hi, t_lo)
            else:
                out[..., 8] = 1.0
        return out
