"""Composition of the force model: which terms are on, their parameters and
their time-only inputs, and the one compiled function that sums them.

Each force term is a small object (one per module of :mod:`tqdyn.forces`)
with the same interface:

* ``name``, ``description``, ``source`` -- for ``tqdyn info`` and the docs;
* ``params()`` -> float64 array of its constant parameters;
* a compiled kernel ``(rx, ry, rz, vx, vy, vz, tdat, params) -> (ax, ay, az)``
  (float64, m and m/s in, m/s^2 out, GCRS) reading its own slices of the
  time-only inputs and parameters -- only the central monopole, large enough
  to need it, is evaluated in the propagation's extended precision;
* ``n_tdat`` and ``precompute(epoch, t_hi, t_lo)`` -> float64 array
  (..., n_tdat) of its *time-only* inputs (ephemeris positions, rotation
  matrices, tidal corrections ...) at propagation times t = t_hi + t_lo
  [s of TT since the epoch].  The propagator calls it once per chunk of
  steps for all stage times (the DP87 nodes t_n + c_i h are known in
  advance), so no Python runs inside the compiled loop.

The compiled side is :func:`gravity`: a fixed list of slots, one per term
kind, each switched on by the ``layout`` table built here.  Adding a term
means adding its module, a slot constant and one branch in
:func:`gravity_split` or, for a float64 term evaluated at the point alone,
in :func:`float64_terms` (the one list of those, which the test masses'
differential gravity differences too); a float64 kernel is called through
:func:`term_gate`, so that a propagation (which passes
:attr:`ForceModel.kernel_layout`) compiles it only if its model enables it.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

from ..astro.ephemeris import ephemeris_named
from ..astro.reference import GEOCENTRIC, ReferenceSystem
from ..numerics.dd import add, const, mul, to_f64
from ..numerics.jit import INLINED_OVERLOAD_OPTIONS, OVERLOAD_OPTIONS, dynamic, inner_kernel
from .body_gms import body_gms
from .central import EarthMonopole, monopole
from .earth import PARAM_HEADER as _EF_HEADER
from .earth import EarthField, degree2_accel_ext, earth_field_accel
from .earth_indirect import EarthFieldIndirect, earth_field_indirect_accel
from .eih import HeliocentricEIH, heliocentric_eih_accel
from .eih_gcrs import GeocentricEIH, geocentric_eih_accel
from .heliocentric import CentralJ2, SunMonopole, central_j2_accel
from .moon import MoonField, moon_field_accel, moon_field_direct
from .relativity import Relativity, relativity_accel
from .sun import SunJ2, sun_j2_accel
from .third_body import ThirdBodies, third_bodies_accel, third_body_accel_ext

__all__ = ["ForceModel", "build_force_model", "describe_terms", "float64_terms", "gravity",
           "gravity_split", "slot_table", "SLOTS", "term_gate"]

#: Slot of each term kind in the compiled dispatcher (row of ``layout``).
SLOT_EARTH_MONOPOLE = 0
SLOT_THIRD_BODY = 1
SLOT_RELATIVITY = 2
SLOT_MOON_FIELD = 3
SLOT_SUN_J2 = 4
SLOT_EARTH_FIELD = 5
SLOT_EARTH_FIELD_INDIRECT = 6
SLOT_CENTRAL_J2 = 7
SLOT_EIH = 8
SLOT_EIH_GCRS = 9
#: The central body's monopole (the Earth's or, heliocentric, the Sun's) uses the first slot.
SLOT_CENTRAL_MONOPOLE = SLOT_EARTH_MONOPOLE
SLOTS = {"earth_monopole": SLOT_EARTH_MONOPOLE, "central_j2": SLOT_CENTRAL_J2, "third_body": SLOT_THIRD_BODY,
         "relativity": SLOT_RELATIVITY,
         "moon_field": SLOT_MOON_FIELD, "sun_j2": SLOT_SUN_J2, "earth_field": SLOT_EARTH_FIELD,
         "earth_field_indirect": SLOT_EARTH_FIELD_INDIRECT, "relativity_eih": SLOT_EIH,
         "relativity_eih_gcrs": SLOT_EIH_GCRS}
_TERM_SLOT = {EarthMonopole: SLOT_EARTH_MONOPOLE, ThirdBodies: SLOT_THIRD_BODY, Relativity: SLOT_RELATIVITY,
              MoonField: SLOT_MOON_FIELD, SunJ2: SLOT_SUN_J2, EarthField: SLOT_EARTH_FIELD,
              EarthFieldIndirect: SLOT_EARTH_FIELD_INDIRECT, SunMonopole: SLOT_CENTRAL_MONOPOLE,
              CentralJ2: SLOT_CENTRAL_J2, HeliocentricEIH: SLOT_EIH, GeocentricEIH: SLOT_EIH_GCRS}


class ForceModel:
    """The set of enabled force terms, flattened for the compiled loop.

    Attributes
    ----------
    reference: the :class:`~tqdyn.astro.reference.ReferenceSystem` of the
        positions and accelerations (origin, frame, time scale of t).
    terms: tuple of term objects, in slot order.
    params: (n_params,) float64, the terms' parameters concatenated.
    layout: (n_slots, 3) int64; row s = (enabled, parameter offset, tdat
        column offset) of slot s.
    kernel_layout: the ``layout`` the propagation passes to the compiled
        functions: (layout, on), on[s] True for an enabled slot s and None
        for one that is off, so that only the enabled terms are compiled
        (:func:`term_gate`); the table alone compiles every term.
    n_tdat: total number of time-only input columns.
    eop: the :class:`~tqdyn.astro.eop.EOP` table the Earth's orientation
        uses (None: no EOP); eop_source: its name ("auto", "c04-14", ...,
        "off", or "custom" for a table passed to :func:`build_force_model`).
    """

    def __init__(self, terms, reference: ReferenceSystem = GEOCENTRIC, eop=None, eop_source: str = "off"):
        self.reference = reference
        self.eop = eop
        self.eop_source = eop_source
        terms = tuple(sorted(terms, key=lambda t: _TERM_SLOT[type(t)]))
        slots = [_TERM_SLOT[type(t)] for t in terms]
        if len(set(slots)) != len(slots):
            raise ValueError("forces: a force term is listed twice")
        self.terms = terms
        self.layout = np.zeros((len(SLOTS), 3), dtype=np.int64)
        params, p_off, t_off = [], 0, 0
        for term, slot in zip(terms, slots):
            p = np.asarray(term.params(), dtype=np.float64)
            self.layout[slot] = (1, p_off, t_off)
            params.append(p)
            p_off += p.size
            t_off += term.n_tdat
        self.params = np.concatenate(params) if params else np.zeros(0)
        self.n_tdat = t_off
        self.kernel_layout = (self.layout, tuple(True if row[0] else None for row in self.layout))

    @property
    def time_dependent(self) -> bool:
        """True if any term needs time-only inputs."""
        return self.n_tdat > 0

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Time-only inputs of every enabled term at times t_hi + t_lo [s TT
        since epoch]; returns float64 (*shape(t_hi), n_tdat)."""
        cols = [term.precompute(epoch, t_hi, t_lo) for term in self.terms]
        return np.concatenate(cols, axis=-1) if cols else np.zeros(np.shape(t_hi) + (0,))

    def describe(self) -> list[tuple[str, str, str]]:
        """(name, description, source) of each enabled term."""
        return [(t.name, t.description, t.source) for t in self.terms]


def describe_terms() -> list[tuple[str, str, str]]:
    """(name, description, source) of every force term tqdyn can evaluate,
    including the tide models summed into the Earth field."""
    from .atmospheric_tides import AtmosphericTides
    from .ocean_tides import OceanTides
    from .pole_tides import OceanPoleTide, SolidPoleTide
    from .solid_tides import SolidTides

    classes = list(dict.fromkeys(_TERM_SLOT)) + [SolidTides, OceanTides, SolidPoleTide, OceanPoleTide, AtmosphericTides]
    return [(cls.name, cls.description, cls.source) for cls in classes]


class _Orientation:
    """Earth orientation with one EOP table (None: no EOP), as a picklable
    callable (epoch, t_hi, t_lo) -> EarthOrientation; ``.rotation`` gives
    the T_ITRS_GCRS provider of the Earth field."""

    def __init__(self, eop):
        self.eop = eop

    def __call__(self, epoch, t_hi, t_lo):
        from ..astro.earth_orientation import earth_orientation

        return earth_orientation(epoch, t_hi, t_lo, self.eop, use_eop=self.eop is not None)

    def rotation(self, epoch, t_hi, t_lo):
        return self(epoch, t_hi, t_lo).T_ITRS_GCRS


def _tide_models(forces, eph, orientation, gms) -> tuple:
    """The tide providers switched on in ``forces`` (coefficient corrections
    summed into the Earth field); gms: :func:`body_gms`."""
    tides = []
    if forces.solid_tides:
        from .solid_tides import SolidTides

        tides.append(SolidTides(orientation=orientation, ephemeris=eph, gm_earth=float(forces.gm_earth),
                                gm_moon=gms["moon"], gm_sun=gms["sun"]))
    if forces.ocean_tides_degree:
        from .ocean_tides import OceanTides

        tides.append(OceanTides(nmax=forces.ocean_tides_degree, orientation=orientation))
    if forces.pole_tides:
        from .pole_tides import OceanPoleTide, SolidPoleTide

        tides += [SolidPoleTide(orientation=orientation), OceanPoleTide(orientation=orientation)]
    if forces.atmospheric_tides:
        from .atmospheric_tides import AtmosphericTides

        # all of the file (degree 8), referred to the static field's GM and radius (EGM2008)
        tides.append(AtmosphericTides(orientation=orientation))
    return tuple(tides)


_FROM_CONFIG = object()


def build_force_model(forces, reference: ReferenceSystem = GEOCENTRIC, eop=_FROM_CONFIG) -> ForceModel:
    """ForceModel from a scenario's ``ForcesConfig`` (one shared ephemeris)
    in the reference system of the scenario's central body (the terms of
    this module are the geocentric ones).  ``eop``: the EOP table of
    ``forces.eop``, interpolated as ``forces.eop_interpolation``
    (:func:`tqdyn.astro.eop_sources.eop_table`) unless an
    :class:`~tqdyn.astro.eop.EOP` table (or None: no EOP) is given, e.g. to
    compare sources."""
    if reference.central_body == "sun":
        return _heliocentric_model(forces, reference)
    if reference.central_body != "earth":
        raise ValueError(f"scenario.central_body: {reference.central_body!r} has no force model; "
                         "allowed: 'earth', 'sun'")
    terms = []
    gms = body_gms(forces)
    if forces.earth_monopole:
        terms.append(EarthMonopole(gm=forces.gm_earth))
    needs_ephemeris = (forces.third_bodies or forces.relativity or forces.moon_degree or forces.sun_j2
                       or forces.solid_tides or forces.earth_field_indirect)
    eph = ephemeris_named(forces.ephemeris) if needs_ephemeris else None
    if eop is _FROM_CONFIG:
        from ..astro.eop_sources import eop_table

        source = forces.eop
        eop = eop_table(source, forces.eop_interpolation) if forces.earth_degree else None
    else:
        source = "custom" if eop is not None else "off"
    orientation = _Orientation(eop)
    rotation = orientation.rotation
    if forces.earth_degree:
        terms.append(EarthField(degree=forces.earth_degree, tides=_tide_models(forces, eph, orientation, gms),
                                rotation=rotation, extended_degree2=forces.earth_degree2_extended))
    if forces.earth_field_indirect:
        bodies = tuple(b for b in ("moon", "sun") if b in forces.third_bodies)
        terms.append(EarthFieldIndirect(field=EarthField(degree=forces.earth_degree, rotation=rotation),
                                        bodies=bodies, gms=tuple(gms[b] for b in bodies),
                                        gm_earth=float(forces.gm_earth), ephemeris=eph))
    if forces.third_bodies:
        from .third_body_ephemeris import third_bodies

        terms.append(third_bodies(eph, forces.third_bodies, extended=forces.third_bodies_extended,
                                  gcrs=forces.third_bodies_gcrs, gms=gms))
    if forces.moon_degree:
        terms.append(MoonField(degree=forces.moon_degree, libration=forces.moon_libration, ephemeris=eph))
    if forces.sun_j2:
        terms.append(SunJ2(ephemeris=eph, gm=gms["sun"]))
    if forces.relativity:
        terms.append(Relativity(ephemeris=eph, gm_earth=float(forces.gm_earth), gm_sun=gms["sun"]))
        if forces.relativity_model == "eih":
            terms.append(GeocentricEIH(names=forces.third_bodies, ephemeris=eph, gm_earth=float(forces.gm_earth),
                                       gms=tuple(gms.items())))
    return ForceModel(terms, reference, eop=eop, eop_source=source if eop is not None else "off")


def _heliocentric_model(forces, reference: ReferenceSystem) -> ForceModel:
    """The heliocentric terms of :mod:`tqdyn.forces.heliocentric` switched on in ``forces``."""
    from .heliocentric import heliocentric_third_bodies, sun_schwarzschild

    terms = []
    gms = body_gms(forces)
    if forces.sun_monopole:
        gm_sun = getattr(forces, "gm_sun", None)  # the exact decimal for the extended-precision monopole
        terms.append(SunMonopole() if gm_sun is None else SunMonopole(gm=str(gm_sun)))
    eih = forces.relativity and forces.relativity_model == "eih"
    eph = ephemeris_named(forces.ephemeris) if forces.third_bodies or eih else None
    if forces.third_bodies:
        terms.append(heliocentric_third_bodies(eph, forces.third_bodies, extended=forces.third_bodies_extended,
                                               gms=gms))
    if forces.sun_j2:
        terms.append(CentralJ2(gm=gms["sun"]))
    if eih:  # the full 1PN acceleration, which contains the Sun's Schwarzschild term
        terms.append(HeliocentricEIH(names=forces.third_bodies, ephemeris=eph, gms=tuple(gms.items())))
    elif forces.relativity:
        terms.append(sun_schwarzschild(gm=gms["sun"]))
    return ForceModel(terms, reference)


def slot_table(layout):
    """The (n_slots, 3) int64 table of ``layout``: :attr:`ForceModel.layout`
    itself or the table of :attr:`ForceModel.kernel_layout` (compiled code only)."""


@overload(slot_table, jit_options=OVERLOAD_OPTIONS)
def _ov_slot_table(layout):
    if isinstance(layout, types.Array):
        return lambda layout: layout
    return lambda layout: layout[0]


def term_gate(slot: int, kernel):
    """``gate(layout, args)``: ``kernel(*args)`` (args a tuple), the float64
    acceleration (ax, ay, az) [m/s^2] of the term in slot ``slot``, compiled
    only if the term can be on: given the :attr:`ForceModel.kernel_layout`
    of a model without it, ``kernel`` is not compiled and the gate gives
    (0.0, 0.0, 0.0) (the caller checks the table at run time, as for a
    layout table alone, with which ``kernel`` is compiled).  Compiled code
    only; inlined into the caller (numba still compiles each gate once, to type it, with
    :data:`tqdyn.numerics.jit.INLINED_OVERLOAD_OPTIONS`: the term's kernel is not optimised again there)."""
    def gate(layout, args):
        raise TypeError("a force-term gate is called from compiled code only")

    @overload(gate, jit_options=INLINED_OVERLOAD_OPTIONS, inline="always")
    def _gate(layout, args):
        if isinstance(layout, types.BaseTuple) and isinstance(layout.types[1].types[slot], types.NoneType):
            return lambda layout, args: (0.0, 0.0, 0.0)
        return lambda layout, args: kernel(*args)

    gate.__name__ = gate.__qualname__ = f"{kernel.__name__}_gate"
    gate.__doc__ = f":func:`term_gate` of ``{kernel.__name__}`` (slot {slot})."
    return gate


earth_field_term = term_gate(SLOT_EARTH_FIELD, earth_field_accel)
_indirect_term = term_gate(SLOT_EARTH_FIELD_INDIRECT, earth_field_indirect_accel)
_moon_term = term_gate(SLOT_MOON_FIELD, moon_field_accel)
_moon_direct_term = term_gate(SLOT_MOON_FIELD, moon_field_direct)
_sun_j2_term = term_gate(SLOT_SUN_J2, sun_j2_accel)
_relativity_term = term_gate(SLOT_RELATIVITY, relativity_accel)
_central_j2_term = term_gate(SLOT_CENTRAL_J2, central_j2_accel)
_eih_term = term_gate(SLOT_EIH, heliocentric_eih_accel)
_eih_gcrs_term = term_gate(SLOT_EIH_GCRS, geocentric_eih_accel)


@njit(cache=True, inline="always")
def gravity(x, y, z, vx, vy, vz, tdat, params, layout):
    """Total gravitational acceleration [m/s^2] at the position (x, y, z) [m]
    and velocity (vx, vy, vz) [m/s] relative to the central body, in the
    force model's reference system (see :func:`gravity_split`, whose first
    three values this returns).  Returns (ax, ay, az) in the number type of x.
    """
    ax, ay, az, _, _, _ = gravity_split(x, y, z, vx, vy, vz, tdat, params, layout)
    return ax, ay, az


@inner_kernel
def gravity_split(x, y, z, vx, vy, vz, tdat, params, layout):
    """Total gravitational acceleration [m/s^2] at the position (x, y, z) [m]
    and velocity (vx, vy, vz) [m/s] relative to the central body, in the
    force model's reference system (geocentric GCRS or heliocentric BCRS) (generic dd / float64; the
    velocity enters the relativistic terms only), from the enabled terms.

    tdat: (n_tdat,) float64 time-only inputs at this instant; params, layout:
    from :class:`ForceModel`.  Returns (ax, ay, az, ex, ey, ez): the total
    in the number type of x and, float64, the part of it from the Earth
    field's float64 kernel (zero without that term), which the differential
    gravity of the test masses reuses (:mod:`tqdyn.forces.differential`).
    """
    tab = slot_table(layout)
    zero = mul(x, 0.0)
    ax, ay, az = zero, zero, zero
    if tab[SLOT_EARTH_MONOPOLE, 0]:
        o = tab[SLOT_EARTH_MONOPOLE, 1]
        gx, gy, gz = monopole(x, y, z, const(params[o], params[o + 1], x))
        ax, ay, az = add(ax, gx), add(ay, gy), add(az, gz)
    if tab[SLOT_THIRD_BODY, 0]:
        o, c = tab[SLOT_THIRD_BODY, 1], tab[SLOT_THIRD_BODY, 2]
        n = int(params[o])
        for k in range(n):
            if params[o + 1 + n + k] != 0.0:  # this body in extended precision
                gx, gy, gz = third_body_accel_ext(x, y, z, tdat[c + 3 * k], tdat[c + 3 * k + 1],
                                                  tdat[c + 3 * k + 2], params[o + 1 + k], tdat[c + 3 * (n + k)],
                                                  tdat[c + 3 * (n + k) + 1], tdat[c + 3 * (n + k) + 2])
                ax, ay, az = add(ax, gx), add(ay, gy), add(az, gz)
    if tab[SLOT_EARTH_FIELD, 0]:
        o, c = tab[SLOT_EARTH_FIELD, 1], tab[SLOT_EARTH_FIELD, 2]
        ld = int(params[o + 2]) + 1
        if params[o + _EF_HEADER + 2 * ld * ld] != 0.0:  # degree 2 in extended precision
            gx, gy, gz = degree2_accel_ext(x, y, z, tdat[c:], params[o:])
            ax, ay, az = add(ax, gx), add(ay, gy), add(az, gz)
    # perturbations: float64 kernels at the float64-rounded state (~1e-16
    # relative); each has the signature (rx, ry, rz, vx, vy, vz, tdat, params)
    # -> (ax, ay, az) on its own slices of tdat and params; those after the
    # Earth-field indirect term are the list of float64_terms
    rx, ry, rz = to_f64(x), to_f64(y), to_f64(z)
    ux, uy, uz = to_f64(vx), to_f64(vy), to_f64(vz)
    px, py, pz = 0.0, 0.0, 0.0
    ex, ey, ez = 0.0, 0.0, 0.0
    if tab[SLOT_THIRD_BODY, 0]:
        o, c = tab[SLOT_THIRD_BODY, 1], tab[SLOT_THIRD_BODY, 2]
        gx, gy, gz = third_bodies_accel(rx, ry, rz, ux, uy, uz, tdat[c:], params[o:])
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_EARTH_FIELD, 0]:
        o, c = tab[SLOT_EARTH_FIELD, 1], tab[SLOT_EARTH_FIELD, 2]
        ex, ey, ez = earth_field_term(layout, (rx, ry, rz, ux, uy, uz, tdat[c:], params[o:]))
        px, py, pz = px + ex, py + ey, pz + ez
    if tab[SLOT_EARTH_FIELD_INDIRECT, 0]:
        o, c = tab[SLOT_EARTH_FIELD_INDIRECT, 1], tab[SLOT_EARTH_FIELD_INDIRECT, 2]
        gx, gy, gz = _indirect_term(layout, (rx, ry, rz, ux, uy, uz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    px, py, pz = float64_terms(px, py, pz, rx, ry, rz, ux, uy, uz, tdat, params, layout, dynamic(-1))
    return add(ax, px), add(ay, py), add(az, pz), ex, ey, ez


@inner_kernel
def float64_terms(px, py, pz, rx, ry, rz, vx, vy, vz, tdat, params, layout, moon_degree):
    """(px, py, pz) plus the force terms evaluated in float64 at the point itself [m/s^2], in this
    order: the Moon's field, the Sun's J2, relativity (IERS 2010 eq. 10.12), the central body's J2,
    the heliocentric EIH term, the GCRS EIH terms -- the one list of these terms, for the
    satellites' acceleration (:func:`gravity_split`) and for the test masses' differential gravity
    (:func:`tqdyn.forces.differential.direct_terms`, which differences them between two points).

    r [m], v [m/s]: float64 position and velocity in the force model's frame; tdat, params, layout:
    the model's.  moon_degree < 0: the Moon's whole field on the satellite minus that on the Earth
    (:func:`~tqdyn.forces.moon.moon_field_accel`); >= 0: its degrees 2 .. moon_degree on the point
    alone (:func:`~tqdyn.forces.moon.moon_field_direct`; the Earth's term drops out of a
    difference).  float64; returns (x, y, z)."""
    tab = slot_table(layout)
    if tab[SLOT_MOON_FIELD, 0]:
        o, c = tab[SLOT_MOON_FIELD, 1], tab[SLOT_MOON_FIELD, 2]
        if moon_degree < 0:
            gx, gy, gz = _moon_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        else:
            gx, gy, gz = _moon_direct_term(layout, (rx, ry, rz, tdat[c:], params[o:], moon_degree))
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_SUN_J2, 0]:
        o, c = tab[SLOT_SUN_J2, 1], tab[SLOT_SUN_J2, 2]
        gx, gy, gz = _sun_j2_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_RELATIVITY, 0]:
        o, c = tab[SLOT_RELATIVITY, 1], tab[SLOT_RELATIVITY, 2]
        gx, gy, gz = _relativity_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_CENTRAL_J2, 0]:
        o, c = tab[SLOT_CENTRAL_J2, 1], tab[SLOT_CENTRAL_J2, 2]
        gx, gy, gz = _central_j2_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_EIH, 0]:
        o, c = tab[SLOT_EIH, 1], tab[SLOT_EIH, 2]
        gx, gy, gz = _eih_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    if tab[SLOT_EIH_GCRS, 0]:
        o, c = tab[SLOT_EIH_GCRS, 1], tab[SLOT_EIH_GCRS, 2]
        gx, gy, gz = _eih_gcrs_term(layout, (rx, ry, rz, vx, vy, vz, tdat[c:], params[o:]))
        px, py, pz = px + gx, py + gy, pz + gz
    return px, py, pz
