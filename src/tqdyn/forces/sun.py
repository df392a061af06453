"""The Sun's oblateness (J2) acting on a geocentric orbit, with the Sun's IAU
orientation.

Orientation: the IAU WGCCRE 2009 rotational elements of the Sun (Archinal
et al. 2011, Celest. Mech. Dyn. Astr. 109, 101), as in NAIF's
``pck00010.tpc``: north pole alpha0 = 286.13 deg, delta0 = 63.87 deg (ICRF,
constant), prime meridian W = 84.176 deg + 14.1844 deg/d * d (d: days of TDB
since J2000).  The J2 term is zonal, so only the pole enters it; the prime
meridian is used by :func:`solar_iau_rotation` only.  The elements are read
by :func:`tqdyn.readers.pck.read_iau_sun_elements`.

Field: the zonal degree-2 term with the unnormalised J2 = -C20_unnorm; in
fully normalised form C20 = -J2 / sqrt(5).  Default J2 = 2.1106088532726840e-7
at R = 696000 km (the DE430/DE431 ephemeris header value, as quoted in
mockingbirdnest/Principia ``astronomy/sol_gravity_model.proto.txt``; the
IAU text PCK has no solar J2), with GM of the Sun from
``tqdyn.astro.ephemeris.planetary_gm()["sun"]``, the DE430/DE431 value
1.32712440041939400e20 m^3/s^2 (NAIF gm_de431.tpc, BODY10_GM).

For a body-centred position d and the unit pole vector p (|d| = r, z = d.p)

    g(d) = -(3/2) GM J2 R^2 / r^5 [ (1 - 5 z^2/r^2) d + 2 z p ],

the gradient g = grad U of the J2 part U = -(GM/r) J2 (R/r)^2 P2(z/r) of
the potential GM/r [1 - J2 (R/r)^2 P2(z/r)] (acceleration = +grad of the
potential; P2(t) = (3t^2 - 1)/2).  The geocentric term is the
field on the satellite minus the field on the Earth (the geocentric frame
falls towards the Sun's figure too):

    a = g(r - s) - g(-s),   s: the Sun's geocentric GCRS position.

Along a TianQin orbit (r ~ 1e8 m) g itself is ~4e-14 m/s^2 and the
difference (a tidal term, ~ g * 4 r/|s|) is ~1e-16 m/s^2 (measured along
three TianQin-like orbits over 10 days: 6e-17 .. 8e-17 m/s^2).  The float64
evaluation loses ~2.5 digits to that cancellation and rounds r - s at 1 au
to ~3e-5 m: absolute error ~3e-29 m/s^2.  GCRS axes are ICRF axes (the pole is used as
given in ICRF).  Not included: the Sun's monopole acting on the Earth's
figure (the reaction on the geocentre, ~GM_sun 3 J2_E R_E^2 / (2 |s|^4) =
1.5e-14 m/s^2, two orders above this term), which belongs with the
Earth-field term.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..astro.constants import J2000_JD
from ..astro.timescales import tdb_jd
from ..numerics.jit import inner_kernel
from ..readers.pck import IauSunElements, read_iau_sun_elements

__all__ = [
    "GM_SUN_DE430",
    "J2_SUN_DE430",
    "R_SUN_IAU_M",
    "SunJ2",
    "solar_iau_rotation",
    "sun_j2_accel",
    "sun_pole",
    "zonal_j2_accel",
]

#: Unnormalised J2 of the Sun [1], DE430/DE431 header value (with R = 696000 km).
J2_SUN_DE430 = 2.1106088532726840e-7

#: Reference radius of the Sun's J2 [m]: 696000 km (IAU nominal radius used
#: with the DE430 J2; pck00010.tpc BODY10_RADII).
R_SUN_IAU_M = 696000e3

#: GM of the Sun [m^3/s^2], DE430/DE431 (NAIF gm_de431.tpc BODY10_GM =
#: 1.3271244004193938e11 km^3/s^2), as ``tqdyn.astro.ephemeris.planetary_gm()["sun"]``.
GM_SUN_DE430 = 1.32712440041939400e20


def sun_pole(elements: IauSunElements | None = None) -> np.ndarray:
    """Unit vector (3,) of the Sun's north pole in ICRF (= GCRS axes),
    (cos dec cos ra, cos dec sin ra, sin dec) from the IAU elements (None:
    pck00010.tpc).  The pole must be constant (zero rates, as in IAU 2009);
    ValueError otherwise."""
    el = read_iau_sun_elements() if elements is None else elements
    if np.any(el.ra[1:] != 0.0) or np.any(el.dec[1:] != 0.0):
        raise ValueError(f"Sun pole: time-dependent pole (ra {el.ra}, dec {el.dec} deg) is not supported; "
                         "the J2 term assumes a constant pole")
    ra, dec = np.deg2rad(el.ra[0]), np.deg2rad(el.dec[0])
    return np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])


def solar_iau_rotation(jd1, jd2, elements: IauSunElements | None = None) -> np.ndarray:
    """T_SUN_ICRF: ICRF -> the Sun's IAU body-fixed frame at two-part TDB
    Julian dates jd1 + jd2 [d] (arrays, broadcast):
    R3(W) R1(90 deg - dec) R3(90 deg + ra).  Returns (..., 3, 3) float64;
    its third row is :func:`sun_pole` (for a constant pole)."""
    el = read_iau_sun_elements() if elements is None else elements
    jd1, jd2 = np.broadcast_arrays(np.asarray(jd1, dtype=np.float64), np.asarray(jd2, dtype=np.float64))
    d = (jd1 - J2000_JD) + jd2
    t = d / 36525.0
    ra = np.deg2rad(el.ra[0] + t * (el.ra[1] + t * el.ra[2]))
    dec = np.deg2rad(el.dec[0] + t * (el.dec[1] + t * el.dec[2]))
    w = np.deg2rad(np.mod(el.pm[0] + d * (el.pm[1] + d * el.pm[2]), 360.0))
    phi, theta = 0.5 * np.pi + ra, 0.5 * np.pi - dec
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(w), np.sin(w)
    rows = (
        cp * cf - sp * ct * sf, cp * sf + sp * ct * cf, sp * st,
        -sp * cf - cp * ct * sf, -sp * sf + cp * ct * cf, cp * st,
        st * sf, -st * cf, ct,
    )
    return np.stack(rows, axis=-1).reshape(np.shape(d) + (3, 3))


@inner_kernel
def zonal_j2_accel(dx, dy, dz, gm, j2r2, px, py, pz):
    """Acceleration [m/s^2] of the zonal J2 term of a body at the body-centred
    position d = (dx, dy, dz) [m] (any inertial axes), pole unit vector
    p = (px, py, pz) in the same axes, gm [m^3/s^2], j2r2 = J2 R^2 [m^2].
    float64 scalars; returns (ax, ay, az)."""
    r2 = dx * dx + dy * dy + dz * dz
    z = dx * px + dy * py + dz * pz
    k = -1.5 * gm * j2r2 / (r2 * r2 * math.sqrt(r2))
    u = 1.0 - 5.0 * z * z / r2
    return k * (u * dx + 2.0 * z * px), k * (u * dy + 2.0 * z * py), k * (u * dz + 2.0 * z * pz)


@inner_kernel
def sun_j2_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Geocentric acceleration [m/s^2, GCRS] of a satellite at (rx, ry, rz)
    [m, GCRS] from the Sun's J2: field on the satellite minus field on the
    Earth (the velocity is not used).  float64 scalars.

    tdat (3,): the Sun's geocentric GCRS position [m].  params (5,):
    [gm (m^3/s^2), J2 R^2 (m^2), pole_x, pole_y, pole_z (unit, GCRS)].
    """
    sx, sy, sz = tdat[0], tdat[1], tdat[2]
    gm, j2r2, px, py, pz = params[0], params[1], params[2], params[3], params[4]
    ax, ay, az = zonal_j2_accel(rx - sx, ry - sy, rz - sz, gm, j2r2, px, py, pz)
    bx, by, bz = zonal_j2_accel(-sx, -sy, -sz, gm, j2r2, px, py, pz)
    return ax - bx, ay - by, az - bz


def _sun_gm() -> float:
    """GM of the Sun [m^3/s^2]: ``tqdyn.astro.ephemeris.planetary_gm()["sun"]``
    (the DE430/DE431 value, which GM_SUN_DE430 repeats)."""
    from ..astro.ephemeris import planetary_gm

    return float(planetary_gm()["sun"])


def _positions(eph, body, jd1, jd2) -> np.ndarray:
    """Geocentric GCRS position [m] of ``body`` from an ephemeris object,
    (*shape(jd1), 3); positions only when the object can skip velocities."""
    if hasattr(eph, "geocentric_states"):
        return np.asarray(eph.geocentric_states((body,), jd1, jd2, velocity=False)[0][..., 0, :], dtype=np.float64)
    return np.asarray(eph.geocentric(body, jd1, jd2)[0], dtype=np.float64)


def _default_ephemeris():
    from ..astro.ephemeris import default_ephemeris

    return default_ephemeris()


@dataclass(frozen=True)
class SunJ2:
    """The Sun's J2 (zonal, IAU pole) on the geocentric orbit: satellite
    minus Earth.

    j2: unnormalised J2 [1]; radius: its reference radius [m]; gm: GM of
    the Sun [m^3/s^2] (None: ``tqdyn.astro.ephemeris.planetary_gm()["sun"]``,
    DE430); ephemeris: an object with ``geocentric(body, jd1, jd2) ->
    (pos [m], vel [m/s])`` (GCRS, TDB two-part JD), None for
    :func:`tqdyn.astro.ephemeris.default_ephemeris`.

    Parameters handed to the compiled model: [gm, J2 R^2, pole (3)];
    time-only inputs: the Sun's geocentric GCRS position [m] (3 columns).
    """

    j2: float = J2_SUN_DE430
    radius: float = R_SUN_IAU_M
    gm: float | None = None
    ephemeris: object = None
    name: str = field(default="sun_j2", init=False)
    description: str = field(default="Sun's J2 (zonal, IAU 2009 pole), satellite minus Earth", init=False)
    source: str = field(
        default="J2 = 2.1106088532726840e-7 at R = 696000 km (DE430/431 header); pole "
                "286.13/63.87 deg (IAU WGCCRE 2009, NAIF pck00010.tpc)", init=False)
    n_tdat: int = field(default=3, init=False)

    def __post_init__(self):
        if not (np.isfinite(self.j2) and np.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"SunJ2: j2 {self.j2!r} must be finite and radius {self.radius!r} m positive")
        if self.gm is not None and not (np.isfinite(self.gm) and self.gm > 0):
            raise ValueError(f"SunJ2: gm {self.gm!r} m^3/s^2 must be positive")

    def params(self) -> np.ndarray:
        """[gm, J2 R^2, pole_x, pole_y, pole_z] float64 (SI, GCRS)."""
        gm = _sun_gm() if self.gm is None else float(self.gm)
        return np.concatenate([[gm, float(self.j2) * float(self.radius) ** 2], sun_pole()])

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """The Sun's geocentric GCRS position [m] at t = t_hi + t_lo [s TT
        since epoch]: float64 (*shape(t_hi), 3)."""
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        eph = _default_ephemeris() if self.ephemeris is None else self.ephemeris
        pos = _positions(eph, "sun", jd1, jd2)
        if pos.shape != jd1.shape + (3,):
            raise ValueError(f"SunJ2: ephemeris returned Sun positions of shape {pos.shape}, expected {jd1.shape + (3,)}")
        return pos
