"""The heliocentric force model of LISA- and Taiji-like constellations.

Coordinates: Sun-centred, ICRF axes, TDB-compatible BCRS (a Newtonian
translation of the barycentric coordinates of the JPL ephemerides to the
Sun's centre); t in TDB seconds since the epoch
(:data:`tqdyn.astro.reference.HELIOCENTRIC`).  GMs: the TDB-compatible
values of the ephemerides (``data/gm_de431.tpc``, DE430/DE431).

Terms (each switchable in ``[forces]``):

* the Sun's point mass, -GM_S r/|r|^3, in the propagation's extended
  precision (:class:`SunMonopole`; ~6e-3 m/s^2 at 1 au: float64 round-off,
  ~1e-18 m/s^2, moves a one-year orbit by ~1e-4 m, measured);
* the Earth, the Moon and the planets (system barycentres) as point-mass
  third bodies in the heliocentric form, direct minus indirect term
  (:func:`heliocentric_third_bodies`: the same Battin cancellation-free
  kernel as the geocentric third bodies, with heliocentric positions; the
  indirect term is the Sun's own acceleration by the body);
* the Sun's J2 with its IAU pole, on the satellite only (the Sun is the
  origin; :class:`CentralJ2`; ~4e-14 m/s^2 at 1 au);
* relativity: the Sun's post-Newtonian (Schwarzschild, PPN beta = gamma =
  1) term of IERS 2010 eq. (10.12) with GM_S (:func:`sun_schwarzschild`;
  ~2e-10 m/s^2 at 1 au, 30 km/s), or with ``relativity_model = "eih"`` the
  full 1PN n-body acceleration, the Sun's motion and the planets' terms
  included (:class:`tqdyn.forces.eih.HeliocentricEIH`).  The Sun's
  Lense-Thirring term is not modelled: its size is measured in
  tests/test_heliocentric.py and stated in docs/force-model.md.

Which terms need extended precision at 1 au is measured in
tests/test_heliocentric.py: only the Sun's monopole (the planets' terms,
<= 1.8e-7 m/s^2 for the Earth near LISA, have float64 round-off of
<= 6e-23 m/s^2, i.e. ~1e-9 m in a year).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..astro.ephemeris import HELIOCENTRIC_BODIES, Ephemeris, default_ephemeris, planetary_gm
from ..astro.reference import HELIOCENTRIC
from .central import EarthMonopole
from .relativity import Relativity
from .sun import J2_SUN_DE430, R_SUN_IAU_M, sun_pole, zonal_j2_accel
from .third_body import ThirdBodies

__all__ = ["CentralJ2", "HeliocentricPositions", "SunMonopole", "central_j2_accel", "heliocentric_third_bodies",
           "sun_schwarzschild"]


def _gm_sun_decimal() -> str:
    """GM of the Sun [m^3/s^2] as the exact decimal of the shipped GM file (DE430/DE431:
    BODY10_GM = 1.3271244004193938E+11 km^3/s^2), for the dd monopole."""
    from ..readers.pck import shipped_gm

    return str(shipped_gm(exact=True)[10])


@dataclass(frozen=True)
class SunMonopole(EarthMonopole):
    """The Sun's point-mass term, heliocentric (the central monopole slot).

    gm: exact decimal [m^3/s^2]; default the DE430/DE431 value
    1.3271244004193938e20 (TDB-compatible; a run passes its scenario's
    ``forces.gm_sun``).  Parameters: [gm_hi, gm_lo]."""

    gm: object = field(default_factory=_gm_sun_decimal)
    name: str = field(default="sun_monopole", init=False)
    description: str = field(default="Sun point mass, -GM r/|r|^3 (extended precision)", init=False)
    source: str = field(default="GM of the Sun: the scenario's forces.gm_sun (default DE430/DE431, "
                                "tqdyn/data/gm_de431.tpc, TDB-compatible)", init=False)


@dataclass(frozen=True)
class HeliocentricPositions:
    """Position provider of :class:`~tqdyn.forces.third_body.ThirdBodies`
    for a heliocentric run: a picklable callable (epoch, t_hi, t_lo) ->
    (*shape(t_hi), n_bodies, 3) float64 Sun-centred BCRS positions [m]
    (ICRF axes) of ``names`` at t = t_hi + t_lo [s TDB since the epoch's
    TDB]: :meth:`tqdyn.astro.ephemeris.Ephemeris.heliocentric_states` at
    :meth:`tqdyn.astro.reference.ReferenceSystem.ephemeris_jd`."""

    ephemeris: Ephemeris
    names: tuple[str, ...]

    def __call__(self, epoch, t_hi, t_lo=0.0) -> np.ndarray:
        jd1, jd2 = HELIOCENTRIC.ephemeris_jd(epoch, t_hi, t_lo)
        return self.ephemeris.heliocentric_states(self.names, jd1, jd2, velocity=False)[0]


def heliocentric_third_bodies(ephemeris: Ephemeris | None, names, extended=(), gms=None) -> ThirdBodies:
    """Point-mass third bodies of a heliocentric run (names from
    :data:`tqdyn.astro.ephemeris.HELIOCENTRIC_BODIES`), GMs [m^3/s^2] from
    ``gms`` ({body: GM}, the scenario's ``forces.gm_*``; None: those of
    ``data/gm_de431.tpc``) as given (TDB-compatible; planets as systems at
    their barycentres, the Earth and the Moon separately).  ValueError for
    an unknown name, a name listed twice or an empty list."""
    eph = default_ephemeris() if ephemeris is None else ephemeris
    names = tuple(str(n).lower() for n in ((names,) if isinstance(names, str) else names))
    if not names:
        raise ValueError("third bodies: empty list of bodies")
    if len(set(names)) != len(names):
        raise ValueError(f"third bodies: a body is listed twice in {names}")
    for n in names:
        if n not in HELIOCENTRIC_BODIES:
            raise ValueError(f"third bodies: {n!r} is not a heliocentric third body; allowed: "
                             f"{', '.join(HELIOCENTRIC_BODIES)}")
    gm = planetary_gm() if gms is None else dict(gms)
    return ThirdBodies(
        names=names, gms=tuple(gm[n] for n in names), position=HeliocentricPositions(eph, names),
        source=(f"JPL {eph.name} ({eph.path}) via jplephem, heliocentric (body minus Sun, BCRS, TDB); GM: "
                + ("tqdyn/data/gm_de431.tpc" if gms is None else "the scenario's forces.gm_* (default gm_de431.tpc)")
                + " (DE430/DE431; planets as systems at their barycentres)"),
        extended=tuple(n for n in names if n in extended))


@njit(cache=True)
def central_j2_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Acceleration [m/s^2] of the central body's zonal J2 at the
    body-centred position r [m] (ICRF axes); the velocity and tdat are not
    used.  params (5,): [gm (m^3/s^2), J2 R^2 (m^2), pole_x, pole_y, pole_z
    (unit vector, ICRF)].  float64 scalars."""
    return zonal_j2_accel(rx, ry, rz, params[0], params[1], params[2], params[3], params[4])


@dataclass(frozen=True)
class CentralJ2:
    """The Sun's J2 on a heliocentric orbit (the Sun is the origin: no
    indirect term).  j2 [1], radius [m] (DE430 header J2 at R = 696000 km),
    pole from the IAU elements (pck00010.tpc, constant), gm [m^3/s^2]
    (None: DE430).  Parameters: [gm, J2 R^2, pole (3)]; no time-only inputs."""

    j2: float = J2_SUN_DE430
    radius: float = R_SUN_IAU_M
    gm: float | None = None
    name: str = field(default="sun_j2", init=False)
    description: str = field(default="Sun's J2 (zonal, IAU 2009 pole), heliocentric", init=False)
    source: str = field(
        default="J2 = 2.1106088532726840e-7 at R = 696000 km (DE430/431 header); pole "
                "286.13/63.87 deg (IAU WGCCRE 2009, NAIF pck00010.tpc)", init=False)
    n_tdat: int = field(default=0, init=False)

    def params(self) -> np.ndarray:
        """[gm, J2 R^2, pole_x, pole_y, pole_z] float64 (SI, ICRF axes)."""
        gm = float(planetary_gm()["sun"]) if self.gm is None else float(self.gm)
        return np.concatenate([[gm, float(self.j2) * float(self.radius) ** 2], sun_pole()])

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """No time-only inputs: an (..., 0) array."""
        return np.zeros(np.shape(t_hi) + (0,))


def sun_schwarzschild(gm: float | None = None) -> Relativity:
    """The Sun's post-Newtonian term on a heliocentric orbit: the
    Schwarzschild part of IERS 2010 eq. (10.12) with GM_S [m^3/s^2] (``gm``,
    the scenario's ``forces.gm_sun``; None: DE430) in place of GM_E, beta =
    gamma = 1 (:class:`tqdyn.forces.relativity.Relativity` with
    Lense-Thirring and de Sitter off: the Sun's Lense-Thirring acceleration
    at 1 au is 2.5e-15 m/s^2, 0.8 m after a year, not modelled; de Sitter
    is a geocentric-frame term)."""
    gm = float(planetary_gm()["sun"]) if gm is None else float(gm)
    rel = Relativity(schwarzschild=True, lense_thirring=False, de_sitter=False, gm_earth=gm, gm_sun=gm)
    object.__setattr__(rel, "description", "post-Newtonian correction of the Sun (Schwarzschild, IERS 2010 eq. 10.12 "
                                           "with GM_S)")
    object.__setattr__(rel, "source", "IERS Conventions 2010 (TN36) ch. 10 eq. (10.12), first term, GM_S of DE430")
    return rel
