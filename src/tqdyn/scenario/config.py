"""Scenario configuration: the frozen, validated dataclasses of a tqdyn run
(:class:`Scenario` and its sections) and :class:`ScenarioError`.

TOML files are read into these by :mod:`tqdyn.scenario.loader`;
:meth:`Scenario.to_toml` writes a resolved scenario back as TOML.  Units,
frames and the TOML layout: see :mod:`tqdyn.scenario`.

Errors are :class:`ScenarioError` (a ``ValueError``) with one line
``"<field>: <value> <problem>; allowed: <what is allowed>"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from decimal import Decimal, localcontext

from ..astro.reference import CENTRAL_BODIES, ReferenceSystem, reference_system
from ..astro.constants import GM_EARTH_EGM2008
from ..astro.eop_sources import (DEFAULT_EOP_INTERPOLATION, DEFAULT_EOP_SOURCE, EOP_INTERPOLATIONS, EOP_SOURCES,
                                  EOP_SOURCES_ALLOWED, normalize_eop_source)
from ..astro.timescales import Epoch
from ..forces.body_gms import BODY_GM_KEYS, default_body_gm
from ..numerics import multistep as _ms
from .toml_text import toml_str, toml_value

__all__ = [
    "SatelliteConfig", "IntegratorConfig", "RunConfig", "ForcesConfig", "SpacecraftConfig",
    "ConstellationConfig", "POINTING_LAWS", "Scenario", "ScenarioError", "CONTROL_MODES", "LIBRATION_MODELS",
    "MAX_EARTH_DEGREE", "MAX_MOON_DEGREE", "MAX_OCEAN_TIDE_DEGREE", "SELF_GRAVITY_MODELS", "THIRD_BODIES",
    "TM_AXES", "MAX_STEPS", "BODY_RADII_M", "ClosedLoopConfig", "DEFAULT_METHOD",
]

_PRECISIONS, _METHODS, _MODES, _TABLEAUS = ("dd", "float64"), ("dp87", "multistep"), ("fixed", "adaptive"), ("corrected", "published")
_RTOL_MAX = 1e-3
DEFAULT_METHOD = "multistep"  #: ``integrator.method`` of a fixed-step run naming none (adaptive: ``"dp87"``, the only one)
#: Default of ``run.max_steps``: the most integration steps (fixed mode) or output intervals (adaptive mode) a run
#: may have.  The longest real runs are ~3e6 steps (TianQin, 5 years at 50 s); at ``tqdyn bench``'s rates
#: (docs/scenarios.md) 1e9 steps take hours (Kepler) to days (full TianQin model) and write ~1e11 bytes per
#: satellite (output_every = 1): a count above is a mistyped duration or step; raise run.max_steps to override.
MAX_STEPS = 1_000_000_000
from .spacecraft import SELF_GRAVITY_MODELS, TM_AXES, SpacecraftConfig  # noqa: F401  (re-exported)
from .closed_loop import ClosedLoopConfig  # noqa: F401  ([closed_loop]; re-exported)
from .accelerations import AccelerationsConfig  # noqa: F401  ([accelerations]; re-exported)
from .initial import AU_M, BODY_RADII_M, check_above_surface, INITIAL_AXES, INITIAL_DESIGNS, ROTATIONS, InitialConfig, SatelliteConfig, epoch_from_label  # noqa: F401
from .values import (_EXACT, _NOVALUE, ScenarioError, _a, _fmt, _num_array, _one_of, _require,  # noqa: F401  (re-exported)
                     _did_you_mean, _require_choice, _set, _to_decimal, _toml_type)


@dataclass(frozen=True)
class IntegratorConfig:
    """Integrator choice.

    ``method``: ``"dp87"`` (Dormand-Prince 8(7)) or ``"multistep"`` (fixed step; :mod:`tqdyn.numerics.multistep`);
    None (not given): :data:`DEFAULT_METHOD` in fixed mode, ``"dp87"`` in adaptive mode; ``mode``: ``"fixed"`` or
    ``"adaptive"`` (DP87 only); ``step_s`` [s] (> 0): the fixed step, or in adaptive mode
    the output interval; ``tableau``: ``"corrected"`` or ``"published"``
    coefficients (also of the multistep start-up); ``rtol``: adaptive-mode relative local error tolerance
    (0 < rtol < 1e-3).  Multistep: ``order`` and ``corrector`` (:mod:`tqdyn.numerics.multistep`).
    """

    method: str | None = None
    mode: str = "fixed"
    step_s: Decimal = Decimal(50)
    tableau: str = "corrected"
    rtol: float = 1e-22
    order: int = _ms.DEFAULT_ORDER
    corrector: str = _ms.DEFAULT_CORRECTOR

    def __post_init__(self) -> None:
        _require_choice(self.mode, "integrator.mode", _MODES)
        _set(self, "method", (DEFAULT_METHOD if self.mode == "fixed" else "dp87") if self.method is None else self.method)
        _require_choice(self.method, "integrator.method", _METHODS)
        _require(self.method != "multistep" or self.mode == "fixed", "integrator.mode", self.mode,
                 'has no multistep form (integrator.method = "multistep")', '"fixed", or method = "dp87"')
        o = self.order
        _require(isinstance(o, int) and not isinstance(o, bool) and o in _ms.ORDERS, "integrator.order", o,
                 "is not an available order", f"an integer {_ms.ORDERS[0]}..{_ms.ORDERS[-1]}")
        _require_choice(self.corrector, "integrator.corrector", _ms.CORRECTORS)
        _require_choice(self.tableau, "integrator.tableau", _TABLEAUS)
        _set(self, "step_s", _to_decimal(self.step_s, "integrator.step_s"))
        _require(self.step_s > 0, "integrator.step_s", self.step_s, "is not positive", "step > 0 s")
        rtol = self.rtol
        if isinstance(rtol, bool) or not isinstance(rtol, (int, float, Decimal)):
            raise ScenarioError("integrator.rtol", rtol, "is not a number", f"0 < rtol < {_RTOL_MAX:g}")
        rtol = float(rtol)
        _require(math.isfinite(rtol) and 0 < rtol < _RTOL_MAX, "integrator.rtol", self.rtol, "is out of range", f"0 < rtol < {_RTOL_MAX:g}")
        _set(self, "rtol", rtol)


@dataclass(frozen=True)
class RunConfig:
    """Run length and output.

    ``duration_s`` [s] (> 0); ``precision``: ``"dd"`` (double-double)
    or ``"float64"``; ``output``: HDF5 file name (non-empty); ``output_every``:
    write every N-th step (integer >= 1); ``max_steps``: the most steps
    (fixed mode) or output intervals (adaptive mode) the run may have,
    default :data:`MAX_STEPS` = 1e9 (integer >= 1; checked by
    :class:`Scenario`: a larger count cannot finish).
    """

    duration_s: Decimal = Decimal(864000)
    precision: str = "dd"
    output: str = "tqdyn-run.h5"
    output_every: int = 1
    max_steps: int = MAX_STEPS

    def __post_init__(self) -> None:
        _set(self, "duration_s", _to_decimal(self.duration_s, "run.duration_s"))
        _require(self.duration_s > 0, "run.duration_s", self.duration_s, "is not positive", "duration > 0 s")
        _require_choice(self.precision, "run.precision", _PRECISIONS)
        _require(isinstance(self.output, str) and self.output.strip() != "", "run.output", self.output, "is not a non-empty string", "a file name")
        oe = self.output_every
        _require(isinstance(oe, int) and not isinstance(oe, bool) and oe >= 1, "run.output_every", oe, "is not an integer >= 1", "an integer >= 1")
        ms = self.max_steps
        _require(isinstance(ms, int) and not isinstance(ms, bool) and ms >= 1, "run.max_steps", ms,
                 "is not an integer >= 1", f"an integer >= 1 (default {MAX_STEPS})")


#: Bodies available as point-mass third bodies (JPL DE ephemerides): all but
#: the central body itself ("sun" for geocentric runs, "earth" for heliocentric ones).
THIRD_BODIES = ("sun", "earth", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")
_BODIES_DOC = "docs/scenarios.md#forces"
#: Keys of [forces] that belong to the geocentric model only.
GEOCENTRIC_ONLY_FORCES = ("earth_degree", "solid_tides", "ocean_tides_degree", "pole_tides", "atmospheric_tides",
                          "moon_degree", "earth_field_indirect")
#: Largest degrees the shipped coefficient files hold.
MAX_EARTH_DEGREE = 90  # EGM2008_90.gfc
MAX_MOON_DEGREE = 20  # jggrx_0660b_sha_deg20.tab
MAX_OCEAN_TIDE_DEGREE = 100  # fes2004_Cnm-Snm.dat
LIBRATION_MODELS = ("de421", "iau")
#: Values of forces.relativity_model: IERS 2010 eq. 10.12 alone, or with the 1PN n-body (EIH) terms.
RELATIVITY_MODELS = ("iers2010", "eih")


def _gm_field(body: str):
    """A [forces] GM key (:data:`BODY_GM_KEYS`), default the shipped DE430/DE431 value."""
    return field(default_factory=lambda: default_body_gm(body))


@dataclass(frozen=True)
class ForcesConfig:
    """Force-model switches.  Every perturbation is off unless switched on
    (the built-in ``tianqin`` scenario switches on the paper's full model).

    ``earth_monopole``: Earth point mass (geocentric runs); ``gm_earth``
    [m^3/s^2] (> 0), default EGM2008 3.986004415e14.
    ``sun_monopole``: Sun point mass (heliocentric runs; GM of DE430).
    ``earth_degree``: degree and order of the Earth's static field EGM2008
    (0 = off, 2..90); ``earth_degree2_extended``: its degree-2 part (J2,
    ~5e-7 m/s^2, with the degree-2 tides) in extended precision.
    ``ephemeris``: "de421" (shipped) or the path of a JPL DE .bsp file.
    ``third_bodies``: point-mass bodies, a subset of THIRD_BODIES;
    ``third_bodies_extended``: those of them evaluated in the propagation's
    extended precision (default Moon and Sun: their float64 round-off,
    ~1e-21 m/s^2, would move the orbits by ~1e-12 m per day);
    ``third_bodies_gcrs``: their positions and GMs transformed from the
    ephemeris's TDB-compatible BCRS to the TT-compatible GCRS (1PN,
    :mod:`tqdyn.astro.geocentric`; false: the BCRS differences, as tqdyn 0.1).
    ``solid_tides``: IERS 2010 solid Earth tides (steps 1 and 2).
    ``ocean_tides_degree``: FES2004 ocean tides to this degree (0 = off).
    ``pole_tides``: solid Earth and ocean pole tides; ``atmospheric_tides``: S1, S2 (Biancale & Bode 2006).
    ``moon_degree``: GL0660B lunar field degree (0 = off, 2..20);
    ``moon_libration``: lunar orientation "de421" (PA kernel) | "iau".
    ``sun_j2``: the Sun's J2 with its IAU pole.
    ``relativity``: IERS 2010 eq. 10.12 (geocentric: Schwarzschild,
    Lense-Thirring, de Sitter; heliocentric: the Sun's Schwarzschild term).
    ``relativity_model``: what ``relativity = true`` applies: "iers2010"
    (that alone, the default) or "eih": the first post-Newtonian n-body
    (Einstein-Infeld-Hoffmann) terms of the Sun and the third bodies too
    (heliocentric: the full 1PN acceleration in place of the Sun's
    Schwarzschild term; geocentric: the 1PN terms of the third bodies in
    the GCRS that eq. 10.12 leaves out, which need the Sun and the Moon
    among the third bodies, in the GCRS).
    ``earth_field_indirect``: the geocentre's acceleration by the Moon and
    Sun (those listed in third_bodies) acting on the Earth's non-central
    field (needs earth_degree >= 2).
    ``gm_sun``, ``gm_earth_tdb``, ``gm_moon``, ``gm_mercury`` .. ``gm_neptune``
    [m^3/s^2] (> 0): the GMs of the point-mass bodies, TDB-compatible (the
    ephemerides'; default the exact DE430/DE431 values of
    ``data/gm_de431.tpc``; planets as systems): every GM of a run but the
    geocentric central body's comes from them (:mod:`tqdyn.forces.body_gms`);
    ``gm_earth_tdb`` is the Earth's as a heliocentric third body.
    ``eop``: the source of polar motion, UT1-UTC and celestial-pole offsets,
    one of :data:`tqdyn.astro.eop_sources.EOP_SOURCES` (default "auto":
    measured, predicted, then the long-term model; true = "auto", false =
    "off": none, for tests and comparisons); stored as the name.  ``eop_interpolation``: "spline" (C2 cubic
    spline of the daily values, the default: smooth in time) or "lagrange4" (IERS 4-point); :mod:`tqdyn.astro.eop`.
    """

    earth_monopole: bool = True
    sun_monopole: bool = True
    gm_earth: Decimal = Decimal(GM_EARTH_EGM2008)
    earth_degree: int = 0
    earth_degree2_extended: bool = True
    ephemeris: str = "de421"
    third_bodies: tuple[str, ...] = ()
    third_bodies_extended: tuple[str, ...] = ("moon", "sun")
    third_bodies_gcrs: bool = True
    solid_tides: bool = False
    ocean_tides_degree: int = 0
    pole_tides: bool = False
    atmospheric_tides: bool = False
    moon_degree: int = 0
    moon_libration: str = "de421"
    sun_j2: bool = False
    relativity: bool = False
    earth_field_indirect: bool = False
    eop: str = DEFAULT_EOP_SOURCE
    eop_interpolation: str = DEFAULT_EOP_INTERPOLATION
    # GMs of the point-mass bodies (BODY_GM_KEYS), TDB-compatible
    gm_sun: Decimal = _gm_field("sun")
    gm_earth_tdb: Decimal = _gm_field("earth")
    gm_moon: Decimal = _gm_field("moon")
    gm_mercury: Decimal = _gm_field("mercury")
    gm_venus: Decimal = _gm_field("venus")
    gm_mars: Decimal = _gm_field("mars")
    gm_jupiter: Decimal = _gm_field("jupiter")
    gm_saturn: Decimal = _gm_field("saturn")
    gm_uranus: Decimal = _gm_field("uranus")
    gm_neptune: Decimal = _gm_field("neptune")
    relativity_model: str = "iers2010"

    def __post_init__(self) -> None:
        ok = isinstance(self.eop, bool) or (isinstance(self.eop, str) and self.eop.strip().lower() in EOP_SOURCES)
        _require(ok, "forces.eop", self.eop, "is not an EOP source" + _did_you_mean(self.eop, EOP_SOURCES), EOP_SOURCES_ALLOWED)
        _set(self, "eop", normalize_eop_source(self.eop))
        for key in ("earth_monopole", "sun_monopole", "earth_degree2_extended", "third_bodies_gcrs", "solid_tides", "pole_tides",
                    "atmospheric_tides", "sun_j2", "relativity", "earth_field_indirect"):
            _require(isinstance(getattr(self, key), bool), f"forces.{key}", getattr(self, key), "is not a boolean", "true or false")
        _set(self, "gm_earth", _to_decimal(self.gm_earth, "forces.gm_earth"))
        _require(self.gm_earth > 0, "forces.gm_earth", self.gm_earth, "is not positive", "gm_earth > 0 m^3/s^2")
        for key, top in (("earth_degree", MAX_EARTH_DEGREE), ("moon_degree", MAX_MOON_DEGREE),
                         ("ocean_tides_degree", MAX_OCEAN_TIDE_DEGREE)):
            v = getattr(self, key)
            ok = isinstance(v, int) and not isinstance(v, bool) and (v == 0 or 2 <= v <= top)
            _require(ok, f"forces.{key}", v, "is not an allowed degree", f"0 (off) or 2..{top} (the data file's limit)")
        _require(isinstance(self.ephemeris, str) and self.ephemeris.strip() != "", "forces.ephemeris", self.ephemeris,
                 "is not a name or path", '"de421" or the path of a JPL .bsp file')
        bodies = tuple(self.third_bodies)
        _set(self, "third_bodies", bodies)
        for body in bodies:
            _require_choice(body, "forces.third_bodies", THIRD_BODIES, _BODIES_DOC, "is not a known body")
        _require(len(set(bodies)) == len(bodies), "forces.third_bodies", list(bodies), "lists a body twice", "each body once")
        ext = tuple(self.third_bodies_extended)
        _set(self, "third_bodies_extended", ext)
        for body in ext:
            _require_choice(body, "forces.third_bodies_extended", THIRD_BODIES, _BODIES_DOC, "is not a known body")
        _require_choice(self.moon_libration, "forces.moon_libration", LIBRATION_MODELS)
        _require(not self.earth_field_indirect or self.earth_degree >= 2, "forces.earth_field_indirect", True,
                 "needs the Earth's non-central field", "false, or earth_degree >= 2")
        for key in BODY_GM_KEYS.values():
            _set(self, key, _to_decimal(getattr(self, key), f"forces.{key}"))
            _require(getattr(self, key) > 0, f"forces.{key}", getattr(self, key), "is not positive",
                     f"{key} > 0 m^3/s^2 (default: DE430/DE431, data/gm_de431.tpc)")
        _require_choice(self.relativity_model, "forces.relativity_model", RELATIVITY_MODELS)
        _require_choice(self.eop_interpolation, "forces.eop_interpolation", EOP_INTERPOLATIONS)


POINTING_LAWS = ("none", "global", "taylor1", "taylor2", "iterative")
CONTROL_MODES = ("on", "off")
TM_GRAVITY_METHODS = ("differential", "direct")


@dataclass(frozen=True)
class ConstellationConfig:
    """Attitude and control of a three-satellite constellation.

    ``pointing``: "none" (satellites are independent point masses, no
    attitude) or the pointing law of the attitude (see
    :mod:`tqdyn.constellation.pointing`); ``control``: "on" applies the
    drag-free acceleration G_i to the satellites' orbits, "off" propagates
    the pure-gravity constellation (attitude and the control that would be
    needed are still output); ``free_tms``: verification mode that also
    propagates the six TMs as free bodies; ``tm_gravity``: how the TMs'
    differential gravity a(EH centre) - a(satellite) is formed,
    "differential" (term by term without cancellation,
    :mod:`tqdyn.forces.differential`) or "direct" (the whole force model
    evaluated again at each EH centre in the run's precision: six more
    full evaluations per right-hand side, ~15% slower for TianQin; the same
    result to ~5e-25 m/s^2 geocentric, ~1e-22 heliocentric).
    """

    pointing: str = "none"
    control: str = "off"
    free_tms: bool = False
    tm_gravity: str = "differential"

    def __post_init__(self) -> None:
        _require_choice(self.pointing, "constellation.pointing", POINTING_LAWS)
        _require_choice(self.control, "constellation.control", CONTROL_MODES)
        _require_choice(self.tm_gravity, "constellation.tm_gravity", TM_GRAVITY_METHODS)
        _require(isinstance(self.free_tms, bool), "constellation.free_tms", self.free_tms, "is not a boolean",
                 "true or false")
        _require(self.pointing != "none" or self.control == "off", "constellation.control", self.control,
                 'needs an attitude, but constellation.pointing = "none"',
                 'control = "off" (the pure-gravity constellation), or a pointing law')
        _require(self.pointing != "none" or not self.free_tms, "constellation.free_tms", True,
                 'needs an attitude, but constellation.pointing = "none"', "false, or a pointing law")

    @property
    def coupled(self) -> bool:
        """True when the run has attitudes, TMs and control (pointing != "none")."""
        return self.pointing != "none"


@dataclass(frozen=True)
class Scenario:
    """A complete, validated scenario.

    ``epoch_utc``: normalised UTC ``YYYY-MM-DDTHH:MM:SS[.fff]`` (the epoch of
    the satellite elements and t = 0 of the run); ``satellites``: tuple of
    :class:`SatelliteConfig` (elements relative to the central body, in the
    frame of :attr:`reference`), at least one, unique names: any number for
    point-mass runs, exactly 3 when the run is coupled
    (``constellation.pointing`` != "none") or pulls them toward their centre
    (``spacecraft.self_gravity_center``);
    ``central_body``: the origin of the propagation (one of
    :data:`tqdyn.astro.reference.CENTRAL_BODIES`).
    In fixed mode ``run.duration_s`` is an exact multiple of
    ``integrator.step_s``; ``integrator.step_s`` is at most
    ``run.duration_s``, and the number of steps :attr:`n_steps` at most
    ``run.max_steps``.
    Every satellite starts outside the central body: pericentre
    a (1 - e) (Cartesian states: |r|) at least :data:`BODY_RADII_M` (the
    Earth's equatorial radius 6378137 m, the Sun's radius 696000 km),
    unless ``allow_below_surface`` (TOML ``[scenario] allow_below_surface
    = true``, for tests of the dynamics with point masses).
    """

    name: str
    description: str
    epoch_utc: str
    run: RunConfig = field(default_factory=RunConfig)
    integrator: IntegratorConfig = field(default_factory=IntegratorConfig)
    forces: ForcesConfig = field(default_factory=ForcesConfig)
    spacecraft: SpacecraftConfig = field(default_factory=SpacecraftConfig)
    constellation: ConstellationConfig = field(default_factory=ConstellationConfig)
    satellites: tuple[SatelliteConfig, ...] = ()
    central_body: str = "earth"
    epoch_tdb: str = ""
    initial: InitialConfig = field(default_factory=InitialConfig)
    allow_below_surface: bool = False
    # ---- [closed_loop] (tqdyn.scenario.closed_loop): the closed-loop model's settings, sparse
    closed_loop: ClosedLoopConfig = field(default_factory=ClosedLoopConfig)
    accelerations: AccelerationsConfig = field(default_factory=AccelerationsConfig)  # [accelerations], sparse

    def __post_init__(self) -> None:
        _require_choice(self.central_body, "scenario.central_body", CENTRAL_BODIES)
        _require(isinstance(self.initial, InitialConfig), "initial", self.initial, "is not an InitialConfig",
                 "InitialConfig")
        _require(isinstance(self.name, str) and self.name.strip() != "", "scenario.name", self.name, "is not a non-empty string", "a non-empty string")
        _require(isinstance(self.description, str), "scenario.description", self.description, "is not a string", "a string")
        _require(isinstance(self.allow_below_surface, bool), "scenario.allow_below_surface", self.allow_below_surface,
                 "is not a boolean", "true or false")
        if self.epoch_tdb:
            try:
                epoch = Epoch.from_tdb(self.epoch_tdb)
            except ValueError as exc:
                reason = getattr(exc, "reason", str(exc))
                raise ScenarioError("scenario.epoch_tdb", self.epoch_tdb, f"is not a valid TDB epoch ({reason})",
                                    "a TDB date-time YYYY-MM-DDTHH:MM:SS[.fff] from 1960 on") from None
            _set(self, "epoch_tdb", epoch.tdb_iso)
        else:
            try:
                epoch = Epoch.from_utc(self.epoch_utc)
            except ValueError as exc:
                reason = getattr(exc, "reason", str(exc))
                raise ScenarioError("scenario.epoch_utc", self.epoch_utc, f"is not a valid UTC epoch ({reason})",
                                    "a UTC date-time YYYY-MM-DDTHH:MM:SS[.fff] from 1960 on") from None
        _set(self, "epoch_utc", epoch.utc_iso)
        for name, cls in (("run", RunConfig), ("integrator", IntegratorConfig), ("forces", ForcesConfig),
                          ("spacecraft", SpacecraftConfig), ("constellation", ConstellationConfig)):
            _require(isinstance(getattr(self, name), cls), name, getattr(self, name), f"is not a {cls.__name__}", cls.__name__)
        self._check_central_body()
        sats = tuple(self.satellites)
        if self.initial.derived and not sats:
            from .initial import derived_satellites

            sats = derived_satellites(self.initial, epoch, self.central_body, self.forces.gm_sun)
        _require(len(sats) >= 1, "satellites", list(sats), "is empty", "at least one satellite")
        seen: dict[str, int] = {}
        for k, sat in enumerate(sats, start=1):
            _require(isinstance(sat, SatelliteConfig), f"satellites.{k}", sat, "is not a SatelliteConfig", "SatelliteConfig")
            if sat.name in seen:
                raise ScenarioError(f"satellites.{k}.name", sat.name, f"duplicates satellites.{seen[sat.name]}.name", "unique satellite names")
            seen[sat.name] = k
        _set(self, "satellites", sats)
        self._check_satellite_count()
        self.accelerations.check(len(sats), self.constellation.coupled)
        if not self.allow_below_surface:
            check_above_surface(self.satellites, self.initial, self.central_body)
        if self.integrator.step_s > self.run.duration_s:
            raise ScenarioError("integrator.step", self.integrator.step_s,
                                f"s is longer than run.duration = {self.run.duration_s} s",
                                "0 < step <= run.duration")
        if self.integrator.mode == "fixed":
            with localcontext() as ctx:
                ctx.prec = _EXACT
                rem = self.run.duration_s % self.integrator.step_s
            if rem != 0:
                raise ScenarioError(
                    "run.duration",
                    self.run.duration_s,
                    f"s is not an integer multiple of integrator.step = {self.integrator.step_s} s (fixed mode)",
                    "a duration that is a whole number of steps",
                )
        self._check_steps()

    def _check_satellite_count(self) -> None:
        """Point-mass runs take any number of satellites; what couples them
        (attitudes locked to the beams, TMs, drag-free control; the
        self-gravity toward the constellation's centre) is defined for a
        triangle of exactly 3."""
        n = len(self.satellites)
        if n == 3:
            return
        c = self.constellation
        given = "satellite given" if n == 1 else "satellites given"
        if c.coupled:
            raise ScenarioError("satellites", n, f"{given}; a coupled run (pointing {c.pointing!r}) needs exactly 3",
                                '3 satellites, or constellation.pointing = "none" and control = "off" (any number)')
        if self.spacecraft.self_gravity_center is not None:
            raise ScenarioError("satellites", n, f"{given}; spacecraft.self_gravity_center (the pull "
                                "toward the centre of a triangle) needs exactly 3",
                                "3 satellites, or no spacecraft.self_gravity_center (point masses: any number)")

    def _check_steps(self) -> None:
        """At most ``run.max_steps`` steps; the error names the step when it is
        below 1 s while the duration would fit at 1 s steps, else the duration."""
        n, top = self.n_steps, self.run.max_steps
        if n <= top:
            return
        d, h = self.run.duration_s, self.integrator.step_s
        what = "steps" if self.integrator.mode == "fixed" else "output intervals"
        allowed = f"at most run.max_steps = {top} {what} (raise it to run more)"
        if h < 1 and d <= top:
            raise ScenarioError("integrator.step", h, f"s makes run.duration = {d} s {n:.3g} {what}",
                                f"a step >= {d / top:.3g} s, {allowed}")
        raise ScenarioError("run.duration", d, f"s is {n:.3g} {what} of integrator.step = {h} s", allowed)

    def _check_central_body(self) -> None:
        """The force model, the initial states and the coupled dynamics against the central body."""
        f, body = self.forces, self.central_body
        for b in f.third_bodies:
            _require(b != body, "forces.third_bodies", b, f"is the central body (scenario.central_body = {body!r})",
                     _one_of([x for x in THIRD_BODIES if x != body], _BODIES_DOC))
        if body == "sun":
            for key in GEOCENTRIC_ONLY_FORCES:
                v = getattr(f, key)
                _require(not v, f"forces.{key}", v, 'belongs to the geocentric model (scenario.central_body = "sun")',
                         "0 / false for a heliocentric run")
        elif f.relativity and f.relativity_model == "eih":  # the GCRS terms subtract the model's GCRS third bodies
            need = [b for b in ("sun", "moon") if b not in f.third_bodies]
            _require(not need and f.third_bodies_gcrs, "forces.relativity_model", f.relativity_model,
                     f"needs the Sun and the Moon as third bodies in the GCRS (third_bodies lacks {need})" if need
                     else "needs the third bodies in the GCRS (third_bodies_gcrs = false)",
                     '"iers2010", or "sun" and "moon" in third_bodies with third_bodies_gcrs = true')
        if body != "sun":
            _require(self.initial.design == "none", "initial.design", self.initial.design,
                     "is a heliocentric constellation design", '"none" for a geocentric run')
            _require(not self.initial.oem, "initial.oem", list(self.initial.oem),
                     "gives heliocentric (Sun-centred) states", 'central_body = "sun"')
            _require(self.spacecraft.self_gravity_center is None, "spacecraft.self_gravity_center",
                     self.spacecraft.self_gravity_center, "is the heliocentric constellations' model",
                     'central_body = "sun"')
        if self.initial.design != "none":
            _require(body == "sun", "initial.design", self.initial.design, "is heliocentric", 'central_body = "sun"')
        sc = self.spacecraft
        if sc.self_gravity_center is not None and sc.self_gravity_center_span is None:
            _require(bool(self.initial.oem), "spacecraft.self_gravity_center_span", None, "is missing",
                     '["START", "END"] dates (the default, the span of initial.oem, needs OEM files)')
            from .initial import oem_common_span

            _set(sc, "self_gravity_center_span", oem_common_span(self.initial.oem, self.initial.oem_eme2000))

    def self_gravity_centre_ramp(self) -> tuple[float, float, float, float] | None:
        """(g_start, g_end, t_start, t_end) of ``spacecraft.self_gravity_center``:
        magnitudes [m/s^2, positive toward the constellation centre] and
        the span in s since the epoch on the run's time axis (TDB); None if off."""
        sc = self.spacecraft
        if sc.self_gravity_center is None:
            return None
        ep = self.epoch
        ts = []
        for text in sc.self_gravity_center_span:
            e = epoch_from_label(text, "spacecraft.self_gravity_center_span")
            ts.append(((e.tdb[0] - ep.tdb[0]) + (e.tdb[1] - ep.tdb[1])) * 86400.0)
        return float(sc.self_gravity_center[0]), float(sc.self_gravity_center[1]), ts[0], ts[1]

    @property
    def reference(self) -> ReferenceSystem:
        """Origin, frame and time scale of the states (:mod:`tqdyn.astro.reference`), from ``central_body``."""
        return reference_system(self.central_body)

    @property
    def epoch(self) -> Epoch:
        """The scenario epoch as a :class:`tqdyn.astro.timescales.Epoch`
        (UTC/TAI/TT/TDB two-part JDs): from ``epoch_tdb`` when given, else
        from ``epoch_utc``."""
        return Epoch.from_tdb(self.epoch_tdb) if self.epoch_tdb else Epoch.from_utc(self.epoch_utc)

    @property
    def n_steps(self) -> int:
        """Number of integration steps: ``duration_s / step_s``.

        Exact in fixed mode (validated).  In adaptive mode ``step_s`` is the
        output interval and this is the number of output intervals,
        ``ceil(duration_s / step_s)`` (the last one may be shorter).
        """
        with localcontext() as ctx:
            ctx.prec = _EXACT
            q = self.run.duration_s / self.integrator.step_s
            return int(q.to_integral_value(rounding="ROUND_CEILING"))

    def to_toml(self) -> str:
        """The resolved scenario as TOML text; :func:`~tqdyn.scenario.loader.loads_scenario` / :func:`~tqdyn.scenario.loader.load_scenario`
        read it back to an equal :class:`Scenario`.  Numbers are written in
        their exact decimal form (durations and steps in s)."""
        out: list[str] = ["# tqdyn scenario (resolved). Units: SI unless the key name says otherwise.", ""]
        out += ["[scenario]", f"name = {toml_str(self.name)}", f"description = {toml_str(self.description)}",
                (f"epoch_tdb = {toml_str(self.epoch_tdb)}  # TDB (UTC {self.epoch_utc})" if self.epoch_tdb
                 else f"epoch_utc = {toml_str(self.epoch_utc)}  # UTC"),
                f"central_body = {toml_str(self.central_body)}",
                f"allow_below_surface = {'true' if self.allow_below_surface else 'false'}", ""]
        r = self.run
        out += ["[run]", f"duration = {toml_value(r.duration_s)}  # s", f"precision = {toml_str(r.precision)}",
                f"output = {toml_str(r.output)}", f"output_every = {r.output_every}",
                f"max_steps = {r.max_steps}", ""]
        g = self.integrator
        out += ["[integrator]", f"method = {toml_str(g.method)}", f"mode = {toml_str(g.mode)}",
                f"step = {toml_value(g.step_s)}  # s", f"tableau = {toml_str(g.tableau)}", f"rtol = {g.rtol!r}"]
        if g.method != "dp87" or (g.order, g.corrector) != (_ms.DEFAULT_ORDER, _ms.DEFAULT_CORRECTOR):
            out += [f"order = {g.order}", f"corrector = {toml_str(g.corrector)}"]  # DP87 runs: left implicit
        out += [""]
        f = self.forces
        b = lambda x: "true" if x else "false"  # noqa: E731
        out += ["[forces]", f"earth_monopole = {b(f.earth_monopole)}", f"sun_monopole = {b(f.sun_monopole)}",
                f"gm_earth = {toml_value(f.gm_earth)}  # m^3/s^2", f"earth_degree = {f.earth_degree}",
                f"earth_degree2_extended = {b(f.earth_degree2_extended)}",
                f"ephemeris = {toml_str(f.ephemeris)}",
                "third_bodies = [" + ", ".join(toml_str(x) for x in f.third_bodies) + "]",
                "third_bodies_extended = [" + ", ".join(toml_str(x) for x in f.third_bodies_extended) + "]",
                f"third_bodies_gcrs = {b(f.third_bodies_gcrs)}",
                f"solid_tides = {b(f.solid_tides)}", f"ocean_tides_degree = {f.ocean_tides_degree}",
                f"pole_tides = {b(f.pole_tides)}", f"atmospheric_tides = {b(f.atmospheric_tides)}",
                f"moon_degree = {f.moon_degree}", f"moon_libration = {toml_str(f.moon_libration)}", f"sun_j2 = {b(f.sun_j2)}",
                f"relativity = {b(f.relativity)}", f"earth_field_indirect = {b(f.earth_field_indirect)}",
                f"eop = {toml_str(f.eop)}", f"eop_interpolation = {toml_str(f.eop_interpolation)}",
                *(f"{key} = {toml_value(getattr(f, key))}  # m^3/s^2, TDB-compatible" for key in BODY_GM_KEYS.values())]
        if f.relativity_model != "iers2010":  # the default is left implicit
            out += [f"relativity_model = {toml_str(f.relativity_model)}"]
        out += [""]
        s = self.spacecraft
        out += ["[spacecraft]", f"architecture = {toml_str(s.architecture)}", f"dragfree = {toml_str(s.dragfree)}"]
        if s.architecture == "tianqin":
            out += [f"d_tm = {toml_value(s.d_tm_m)}  # m", f"d_p = {toml_value(s.d_p_m)}  # m",
                    f"tm_axis = {toml_str(s.tm_axis)}"]
        else:
            out += [f"tm_distance = {toml_value(s.tm_distance_m)}  # m"]
        for key in ("housing_centers", "pivots", "sensitive_axes"):
            if getattr(s, key) is not None:
                out += [f"{key} = {toml_value(getattr(s, key))}"]
        out += [f"envelope_radius = {toml_value(s.envelope_radius_m)}  # m",
                f"self_gravity = {toml_value(s.self_gravity)}  # m/s^2 in OA_l",
                f"self_gravity_common = {toml_value(s.self_gravity_common)}  # m/s^2 in S"]
        if s.self_gravity_center is not None:
            out += [f"self_gravity_center = {toml_value(s.self_gravity_center)}  # m/s^2 toward the centre"]
        if s.self_gravity_center_span is not None:
            out += ["self_gravity_center_span = [" + ", ".join(toml_str(x) for x in s.self_gravity_center_span) + "]"]
        out += [""]
        i = self.initial
        out += ["[initial]", f"axes = {toml_str(i.axes)}", f"design = {toml_str(i.design)}",
                f"arm_length = {toml_value(i.arm_length_m)}  # m", f"displacement_deg = {toml_value(i.displacement_deg)}",
                f"rotation = {toml_str(i.rotation)}", f"semi_major_axis = {toml_value(i.semi_major_axis_m)}  # m",
                "oem = [" + ", ".join(toml_str(x) for x in i.oem) + "]",
                f"oem_eme2000 = {toml_str(i.oem_eme2000)}", ""]
        c = self.constellation
        out += ["[constellation]", f"pointing = {toml_str(c.pointing)}", f"control = {toml_str(c.control)}",
                f"free_tms = {b(c.free_tms)}", f"tm_gravity = {toml_str(c.tm_gravity)}", ""]
        out += self.closed_loop.to_toml_lines() + self.accelerations.to_toml_lines()  # only keys given / non-zero
        for sat in self.satellites:
            out += ["[[satellites]]", f"name = {toml_str(sat.name)}"]
            if i.derived:  # the states follow from [initial]
                out += [""]
                continue
            with localcontext() as ctx:
                ctx.prec = _EXACT
                if sat.cartesian:
                    r_km = tuple(x / 1000 for x in sat.r_m)
                    v_kmps = tuple(x / 1000 for x in sat.v_mps)
                    out += [f"r_km = {toml_value(r_km)}", f"v_kmps = {toml_value(v_kmps)}", ""]
                    continue
                a_km = sat.a_m / 1000
            out += [f"a_km = {toml_value(a_km)}", f"e = {toml_value(sat.e)}",
                    f"i_deg = {toml_value(sat.i_deg)}", f"raan_deg = {toml_value(sat.raan_deg)}",
                    f"argp_deg = {toml_value(sat.argp_deg)}", f"nu_deg = {toml_value(sat.nu_deg)}", ""]
        return "\n".join(out)
