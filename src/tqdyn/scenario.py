"""Scenarios: TOML files -> validated, frozen configuration dataclasses.

A scenario fixes everything a tqdyn run needs: the epoch, the initial
Keplerian elements of the satellites, the force model switches, the
integrator and the run length.  Numbers are read with
``tomllib.loads(..., parse_float=decimal.Decimal)`` and kept as ``Decimal``
so that decimal inputs such as ``raan_deg = 211.6`` stay exact until they are
converted at extended precision (see :mod:`tqdyn.elements`).

Conventions
-----------
* Units: SI (m, s, m^3/s^2) unless the TOML key carries a unit suffix
  (``a_km``, ``*_deg``); the dataclasses store SI values with a unit suffix
  in the field name (``a_m``, ``step_s``, ``duration_s``, ``d_tm_m``).
* Frame: satellite elements are osculating two-body elements in the GCRS
  (geocentric, ICRF axes), referred to the scenario epoch.
* Time: ``scenario.epoch_utc`` is a UTC calendar date-time; run durations and
  steps are TDB seconds after that epoch (see :mod:`tqdyn.timescales`).

TOML layout (every section and key optional except at least one
``[[satellites]]`` entry with ``a_km``)::

    [scenario]      name, description, epoch_utc, extends (a built-in scenario
                    whose tables this file updates key by key)
    [run]           duration ("10d", "12h", "30min", "3600s" or seconds),
                    precision ("dd" | "float64"), output, output_every
    [integrator]    method ("dp87"), mode ("fixed" | "adaptive"), step [s],
                    tableau ("corrected" | "published"), rtol
    [forces]        earth_monopole, gm_earth [m^3/s^2]
    [constellation] pointing ("none" | "global" | "taylor1" | "taylor2" |
                    "iterative"), control ("on" | "off"), free_tms (bool)
    [spacecraft]    d_tm [m], d_p [m], tm_axis ("x" | "y" | "z"),
                    self_gravity ("table-iv" | "off" | array (2, 3) or
                    (3, 2, 3) [m/s^2] in OA_l), self_gravity_common (array
                    (3,) or (3, 3) [m/s^2] in S, on both TMs of a satellite)
    [[satellites]]  name, a_km, e, i_deg, raan_deg, argp_deg, nu_deg

Errors are :class:`ScenarioError` (a ``ValueError``) with one line
``"<field>: <value> <problem>; allowed: <what is allowed>"``.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation, localcontext
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

from .astro.constants import GM_EARTH_EGM2008
from .astro.timescales import Epoch

__all__ = [
    "SatelliteConfig",
    "IntegratorConfig",
    "RunConfig",
    "ForcesConfig",
    "SpacecraftConfig",
    "ConstellationConfig",
    "POINTING_LAWS",
    "Scenario",
    "ScenarioError",
    "builtin_scenarios",
    "load_scenario",
    "loads_scenario",
    "parse_duration",
    "DEFAULT_SCENARIO",
    "DEFAULT_EPOCH_UTC",
]

DEFAULT_SCENARIO = "tianqin"
#: Epoch used when a scenario file has no ``scenario.epoch_utc`` (UTC): the
#: epoch of the TianQin Table I elements.
DEFAULT_EPOCH_UTC = "2004-06-06T00:00:00"

_PRECISIONS = ("dd", "float64")
_METHODS = ("dp87",)
_MODES = ("fixed", "adaptive")
_TABLEAUS = ("corrected", "published")
_RTOL_MAX = 1e-3
_EXACT = 200  # Decimal working precision for exact unit conversions

_NOVALUE = object()


# --------------------------------------------------------------------------- errors


def _fmt(value: Any) -> str:
    if isinstance(value, Decimal):
        return str(value)
    if isinstance(value, Path):
        return repr(str(value))
    return repr(value)


class ScenarioError(ValueError):
    """Invalid scenario: one line ``"<field>: <value> <problem>; allowed: <allowed>"``.

    Attributes ``field`` (dotted TOML path such as ``"satellites.2.e"``),
    ``value`` (the offending value, or ``None``), ``problem`` and ``allowed``.
    """

    def __init__(self, field: str, value: Any = _NOVALUE, problem: str = "", allowed: str | None = None):
        self.field = field
        self.value = None if value is _NOVALUE else value
        self.problem = problem
        self.allowed = allowed
        parts = [f"{field}:"]
        if value is not _NOVALUE:
            parts.append(_fmt(value))
        if problem:
            parts.append(problem)
        msg = " ".join(parts)
        if allowed:
            msg += f"; allowed: {allowed}"
        super().__init__(msg.replace("\n", " "))


def _one_of(options: Sequence[str]) -> str:
    return ", ".join(repr(o) for o in options)


# --------------------------------------------------------------------------- value helpers


def _to_decimal(value: Any, name: str) -> Decimal:
    """Coerce int/Decimal/str/float to a finite Decimal (for direct Python construction)."""
    if isinstance(value, bool):
        raise ScenarioError(name, value, "is a boolean", "a finite number")
    if isinstance(value, Decimal):
        d = value
    elif isinstance(value, int):
        d = Decimal(value)
    elif isinstance(value, float):
        d = Decimal(repr(value))
    elif isinstance(value, str):
        try:
            d = Decimal(value.strip())
        except InvalidOperation:
            raise ScenarioError(name, value, "is not a number", "a finite number") from None
    else:
        raise ScenarioError(name, value, f"has type {type(value).__name__}", "a finite number")
    if not d.is_finite():
        raise ScenarioError(name, value, "is not finite", "a finite number")
    return d


def _require(cond: bool, name: str, value: Any, problem: str, allowed: str) -> None:
    if not cond:
        raise ScenarioError(name, value, problem, allowed)


def _require_choice(value: Any, name: str, options: Sequence[str]) -> None:
    _require(isinstance(value, str) and value in options, name, value, "is not a valid choice", _one_of(options))


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


_UNITS = {"s": Decimal(1), "min": Decimal(60), "h": Decimal(3600), "d": Decimal(86400)}
_DURATION_RE = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(s|min|h|d)?\s*$")
_DURATION_FORMS = 'a number of seconds or a string "<number><unit>" with unit s, min, h or d (e.g. "90d", "1.5d", "12h", "30min", "3600s")'


def _parse_duration(value: Any, name: str) -> Decimal:
    if isinstance(value, bool):
        raise ScenarioError(name, value, "is a boolean", _DURATION_FORMS)
    if isinstance(value, str):
        m = _DURATION_RE.match(value)
        if m is None:
            raise ScenarioError(name, value, "is not a duration", _DURATION_FORMS)
        with localcontext() as ctx:
            ctx.prec = _EXACT
            return Decimal(m[1]) * _UNITS[m[2] or "s"]
    if isinstance(value, (int, Decimal, float)):
        d = _to_decimal(value, name)
        return d
    raise ScenarioError(name, value, f"has type {type(value).__name__}", _DURATION_FORMS)


def parse_duration(value: Any) -> Decimal:
    """Parse a duration into seconds (``Decimal``, exact).

    Accepts numbers (seconds: int, Decimal, float) and strings
    ``"<number><unit>"`` with unit ``s``, ``min``, ``h`` or ``d`` (1 d =
    86400 s), e.g. ``"90d"`` -> 7776000, ``"1.5d"`` -> 129600.0, ``"12h"``,
    ``"30min"``, ``"3600s"``; a bare numeric string means seconds.  The sign
    is not checked here.  Raises :class:`ScenarioError` (a ``ValueError``).
    """
    return _parse_duration(value, "duration")


# --------------------------------------------------------------------------- dataclasses


@dataclass(frozen=True)
class SatelliteConfig:
    """Initial osculating Keplerian elements of one satellite (GCRS, at the scenario epoch).

    ``a_m`` semi-major axis [m] (> 0), ``e`` eccentricity [-] (0 <= e < 1),
    ``i_deg``, ``raan_deg``, ``argp_deg``, ``nu_deg``: inclination, right
    ascension of the ascending node, argument of pericenter, true anomaly
    [deg], finite.  All numbers are exact ``Decimal``.
    """

    name: str
    a_m: Decimal
    e: Decimal
    i_deg: Decimal
    raan_deg: Decimal
    argp_deg: Decimal
    nu_deg: Decimal

    def __post_init__(self) -> None:
        _require(isinstance(self.name, str) and self.name.strip() != "", "satellite.name", self.name, "is not a non-empty string", "a non-empty string")
        for f in ("a_m", "e", "i_deg", "raan_deg", "argp_deg", "nu_deg"):
            _set(self, f, _to_decimal(getattr(self, f), f"satellite.{f}"))
        _require(self.a_m > 0, "satellite.a_m", self.a_m, "is not positive", "a > 0 m")
        _require(0 <= self.e < 1, "satellite.e", self.e, "is not an elliptic eccentricity", "0 <= e < 1")


@dataclass(frozen=True)
class IntegratorConfig:
    """Integrator choice.

    ``method``: ``"dp87"`` (Dormand-Prince 8(7)); ``mode``: ``"fixed"`` or
    ``"adaptive"``; ``step_s`` [s] (> 0): the fixed step, or in adaptive mode
    the output interval; ``tableau``: ``"corrected"`` or ``"published"``
    coefficients; ``rtol``: adaptive-mode relative local error tolerance
    (0 < rtol < 1e-3).
    """

    method: str = "dp87"
    mode: str = "fixed"
    step_s: Decimal = Decimal(50)
    tableau: str = "corrected"
    rtol: float = 1e-22

    def __post_init__(self) -> None:
        _require_choice(self.method, "integrator.method", _METHODS)
        _require_choice(self.mode, "integrator.mode", _MODES)
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

    ``duration_s`` [s of TDB] (> 0); ``precision``: ``"dd"`` (double-double)
    or ``"float64"``; ``output``: HDF5 file name (non-empty); ``output_every``:
    write every N-th step (integer >= 1).
    """

    duration_s: Decimal = Decimal(864000)
    precision: str = "dd"
    output: str = "tqdyn-run.h5"
    output_every: int = 1

    def __post_init__(self) -> None:
        _set(self, "duration_s", _to_decimal(self.duration_s, "run.duration_s"))
        _require(self.duration_s > 0, "run.duration_s", self.duration_s, "is not positive", "duration > 0 s")
        _require_choice(self.precision, "run.precision", _PRECISIONS)
        _require(isinstance(self.output, str) and self.output.strip() != "", "run.output", self.output, "is not a non-empty string", "a file name")
        oe = self.output_every
        _require(isinstance(oe, int) and not isinstance(oe, bool) and oe >= 1, "run.output_every", oe, "is not an integer >= 1", "an integer >= 1")


#: Bodies available as point-mass third bodies (JPL DE ephemerides).
THIRD_BODIES = ("sun", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")
#: Largest degrees the shipped coefficient files hold.
MAX_EARTH_DEGREE = 90  # EGM2008_90.gfc
MAX_MOON_DEGREE = 20  # jggrx_0660b_sha_deg20.tab
MAX_OCEAN_TIDE_DEGREE = 100  # fes2004_Cnm-Snm.dat
LIBRATION_MODELS = ("de421", "iau")


@dataclass(frozen=True)
class ForcesConfig:
    """Force-model switches.  Every perturbation is off unless switched on
    (the built-in ``tianqin`` scenario switches on the paper's full model).

    ``earth_monopole``: Earth point mass; ``gm_earth`` [m^3/s^2] (> 0),
    default EGM2008 3.986004415e14.
    ``earth_degree``: degree and order of the Earth's static field EGM2008
    (0 = off, 2..90); ``earth_degree2_extended``: its degree-2 part (J2,
    ~5e-7 m/s^2, with the degree-2 tides) in extended precision.
    ``ephemeris``: "de421" (shipped) or the path of a JPL DE .bsp file.
    ``third_bodies``: point-mass bodies, a subset of THIRD_BODIES;
    ``third_bodies_extended``: those of them evaluated in the propagation's
    extended precision (default Moon and Sun: their float64 round-off,
    ~1e-21 m/s^2, would move the orbits by ~1e-12 m per day).
    ``solid_tides``: IERS 2010 solid Earth tides (steps 1 and 2).
    ``ocean_tides_degree``: FES2004 ocean tides to this degree (0 = off).
    ``pole_tides``: solid Earth and ocean pole tides.
    ``moon_degree``: GL0660B lunar field degree (0 = off, 2..20);
    ``moon_libration``: lunar orientation "de421" (PA kernel) | "iau".
    ``sun_j2``: the Sun's J2 with its IAU pole.
    ``relativity``: IERS 2010 eq. 10.12 (Schwarzschild, Lense-Thirring, de Sitter).
    ``earth_field_indirect``: the geocentre's acceleration by the Moon and
    Sun (those listed in third_bodies) acting on the Earth's non-central
    field (needs earth_degree >= 2).
    ``eop``: polar motion, UT1-UTC and celestial-pole offsets from EOP 14 C04
    (false: zero -- for tests and comparisons only).
    """

    earth_monopole: bool = True
    gm_earth: Decimal = Decimal(GM_EARTH_EGM2008)
    earth_degree: int = 0
    earth_degree2_extended: bool = True
    ephemeris: str = "de421"
    third_bodies: tuple[str, ...] = ()
    third_bodies_extended: tuple[str, ...] = ("moon", "sun")
    solid_tides: bool = False
    ocean_tides_degree: int = 0
    pole_tides: bool = False
    moon_degree: int = 0
    moon_libration: str = "de421"
    sun_j2: bool = False
    relativity: bool = False
    earth_field_indirect: bool = False
    eop: bool = True

    def __post_init__(self) -> None:
        for key in ("earth_monopole", "earth_degree2_extended", "solid_tides", "pole_tides", "sun_j2", "relativity",
                    "earth_field_indirect", "eop"):
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
            _require(body in THIRD_BODIES, "forces.third_bodies", body, "is not a known body", _one_of(THIRD_BODIES))
        _require(len(set(bodies)) == len(bodies), "forces.third_bodies", list(bodies), "lists a body twice", "each body once")
        ext = tuple(self.third_bodies_extended)
        _set(self, "third_bodies_extended", ext)
        for body in ext:
            _require(body in THIRD_BODIES, "forces.third_bodies_extended", body, "is not a known body", _one_of(THIRD_BODIES))
        _require_choice(self.moon_libration, "forces.moon_libration", LIBRATION_MODELS)
        _require(not self.earth_field_indirect or self.earth_degree >= 2, "forces.earth_field_indirect", True,
                 "needs the Earth's non-central field", "false, or earth_degree >= 2")


SELF_GRAVITY_MODELS = ("table-iv", "off")
TM_AXES = ("x", "y", "z")


def _num_array(value: Any, name: str, shapes: Sequence[tuple[int, ...]], unit: str) -> tuple:
    """Nested tuples of Decimal with one of ``shapes`` (ScenarioError otherwise)."""
    allowed = " or ".join(str(tuple(s)) for s in shapes)
    allowed = f"an array of shape {allowed} of finite numbers [{unit}]"

    def conv(x, depth):
        if isinstance(x, (list, tuple)):
            return tuple(conv(e, depth + 1) for e in x)
        if isinstance(x, bool) or not isinstance(x, (int, float, Decimal)):
            raise ScenarioError(name, value, f"contains {_a(_toml_type(x))}", allowed)
        d = Decimal(str(x)) if isinstance(x, float) else Decimal(x)
        _require(d.is_finite(), name, value, "is not finite", allowed)
        return d

    arr = conv(value, 0)

    def shape(x):
        if not isinstance(x, tuple):
            return ()
        inner = {shape(e) for e in x}
        return (len(x),) + inner.pop() if len(inner) == 1 else (len(x), -1)

    _require(isinstance(arr, tuple) and shape(arr) in [tuple(s) for s in shapes], name,
             value, "has the wrong shape", allowed)
    return arr


@dataclass(frozen=True)
class SpacecraftConfig:
    """Spacecraft architecture (the same for the three satellites).

    ``d_tm_m`` [m] (> 0): distance between the two test masses;
    ``d_p_m`` [m] (>= 0): distance of the MOSA pivots from the
    electrode-housing centers; ``tm_axis``: S-frame axis along which the two
    TMs lie (TM_1 at +d_tm/2);  ``self_gravity``: DC self-gravity of each TM
    in its OA_l frame, "table-iv" (the paper's Table IV), "off", or an array
    of shape (2, 3) (both satellites alike) or (3, 2, 3) [m/s^2];
    ``self_gravity_common``: an extra DC acceleration on both TMs of a
    satellite, fixed in the satellite frame S, shape (3,) (all satellites)
    or (3, 3) [m/s^2] (the paper's common self-gravity studies).
    """

    d_tm_m: Decimal = Decimal("0.40")
    d_p_m: Decimal = Decimal("0")
    tm_axis: str = "y"
    self_gravity: Any = "table-iv"
    self_gravity_common: Any = (Decimal(0), Decimal(0), Decimal(0))

    def __post_init__(self) -> None:
        _set(self, "d_tm_m", _to_decimal(self.d_tm_m, "spacecraft.d_tm_m"))
        _set(self, "d_p_m", _to_decimal(self.d_p_m, "spacecraft.d_p_m"))
        _require(self.d_tm_m > 0, "spacecraft.d_tm_m", self.d_tm_m, "is not positive", "d_tm > 0 m")
        _require(self.d_p_m >= 0, "spacecraft.d_p_m", self.d_p_m, "is negative", "d_p >= 0 m")
        _require_choice(self.tm_axis, "spacecraft.tm_axis", TM_AXES)
        if isinstance(self.self_gravity, str):
            _require_choice(self.self_gravity, "spacecraft.self_gravity", SELF_GRAVITY_MODELS)
        else:
            _set(self, "self_gravity", _num_array(self.self_gravity, "spacecraft.self_gravity",
                                                  ((2, 3), (3, 2, 3)), "m/s^2 in OA_l"))
        _set(self, "self_gravity_common", _num_array(self.self_gravity_common, "spacecraft.self_gravity_common",
                                                     ((3,), (3, 3)), "m/s^2 in S"))

    def self_gravity_values(self):
        """(oa, common): float64 arrays (3, 2, 3) [m/s^2, OA_l] and (3, 3) [m/s^2, S]."""
        import numpy as np

        if self.self_gravity == "off":
            oa = np.zeros((3, 2, 3))
        elif self.self_gravity == "table-iv":
            oa = None
        else:
            oa = np.broadcast_to(np.array(self.self_gravity, dtype=np.float64), (3, 2, 3)).copy()
        common = np.broadcast_to(np.array(self.self_gravity_common, dtype=np.float64), (3, 3)).copy()
        return oa, common


POINTING_LAWS = ("none", "global", "taylor1", "taylor2", "iterative")
CONTROL_MODES = ("on", "off")


@dataclass(frozen=True)
class ConstellationConfig:
    """Attitude and control of a three-satellite constellation.

    ``pointing``: "none" (satellites are independent point masses, no
    attitude) or the pointing law of the attitude (see
    :mod:`tqdyn.constellation.pointing`); ``control``: "on" applies the
    drag-free acceleration G_i to the satellites' orbits, "off" propagates
    the pure-gravity constellation (attitude and the control that would be
    needed are still output); ``free_tms``: verification mode that also
    propagates the six TMs as free bodies.
    """

    pointing: str = "none"
    control: str = "off"
    free_tms: bool = False

    def __post_init__(self) -> None:
        _require_choice(self.pointing, "constellation.pointing", POINTING_LAWS)
        _require_choice(self.control, "constellation.control", CONTROL_MODES)
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
    :class:`SatelliteConfig` (GCRS elements), at least one, unique names.
    In fixed mode ``run.duration_s`` is an exact multiple of
    ``integrator.step_s``.
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

    def __post_init__(self) -> None:
        _require(isinstance(self.name, str) and self.name.strip() != "", "scenario.name", self.name, "is not a non-empty string", "a non-empty string")
        _require(isinstance(self.description, str), "scenario.description", self.description, "is not a string", "a string")
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
        sats = tuple(self.satellites)
        _require(len(sats) >= 1, "satellites", list(sats), "is empty", "at least one satellite")
        seen: dict[str, int] = {}
        for k, sat in enumerate(sats, start=1):
            _require(isinstance(sat, SatelliteConfig), f"satellites.{k}", sat, "is not a SatelliteConfig", "SatelliteConfig")
            if sat.name in seen:
                raise ScenarioError(f"satellites.{k}.name", sat.name, f"duplicates satellites.{seen[sat.name]}.name", "unique satellite names")
            seen[sat.name] = k
        _set(self, "satellites", sats)
        if self.constellation.coupled:
            _require(len(sats) == 3, "constellation.pointing", self.constellation.pointing,
                     f"needs exactly 3 satellites (the scenario has {len(sats)})",
                     '"none" for other constellations')
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

    @property
    def epoch(self) -> Epoch:
        """The scenario epoch as a :class:`tqdyn.timescales.Epoch` (UTC/TAI/TT/TDB two-part JDs)."""
        return Epoch.from_utc(self.epoch_utc)

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
        """The resolved scenario as TOML text; :func:`loads_scenario` / :func:`load_scenario`
        read it back to an equal :class:`Scenario`.  Numbers are written in
        their exact decimal form (durations and steps in s)."""
        out: list[str] = ["# tqdyn scenario (resolved). Units: SI unless the key name says otherwise.", ""]
        out += ["[scenario]", f"name = {_toml_str(self.name)}", f"description = {_toml_str(self.description)}",
                f"epoch_utc = {_toml_str(self.epoch_utc)}  # UTC", ""]
        r = self.run
        out += ["[run]", f"duration = {_toml_dec(r.duration_s)}  # s (TDB)", f"precision = {_toml_str(r.precision)}",
                f"output = {_toml_str(r.output)}", f"output_every = {r.output_every}", ""]
        g = self.integrator
        out += ["[integrator]", f"method = {_toml_str(g.method)}", f"mode = {_toml_str(g.mode)}",
                f"step = {_toml_dec(g.step_s)}  # s", f"tableau = {_toml_str(g.tableau)}", f"rtol = {g.rtol!r}", ""]
        f = self.forces
        b = lambda x: "true" if x else "false"  # noqa: E731
        out += ["[forces]", f"earth_monopole = {b(f.earth_monopole)}",
                f"gm_earth = {_toml_dec(f.gm_earth)}  # m^3/s^2", f"earth_degree = {f.earth_degree}",
                f"earth_degree2_extended = {b(f.earth_degree2_extended)}",
                f"ephemeris = {_toml_str(f.ephemeris)}",
                "third_bodies = [" + ", ".join(_toml_str(x) for x in f.third_bodies) + "]",
                "third_bodies_extended = [" + ", ".join(_toml_str(x) for x in f.third_bodies_extended) + "]",
                f"solid_tides = {b(f.solid_tides)}", f"ocean_tides_degree = {f.ocean_tides_degree}",
                f"pole_tides = {b(f.pole_tides)}", f"moon_degree = {f.moon_degree}",
                f"moon_libration = {_toml_str(f.moon_libration)}", f"sun_j2 = {b(f.sun_j2)}",
                f"relativity = {b(f.relativity)}", f"earth_field_indirect = {b(f.earth_field_indirect)}",
                f"eop = {b(f.eop)}", ""]
        s = self.spacecraft
        out += ["[spacecraft]", f"d_tm = {_toml_dec(s.d_tm_m)}  # m", f"d_p = {_toml_dec(s.d_p_m)}  # m",
                f"tm_axis = {_toml_str(s.tm_axis)}",
                f"self_gravity = {_toml_value(s.self_gravity)}  # m/s^2 in OA_l",
                f"self_gravity_common = {_toml_value(s.self_gravity_common)}  # m/s^2 in S", ""]
        c = self.constellation
        out += ["[constellation]", f"pointing = {_toml_str(c.pointing)}", f"control = {_toml_str(c.control)}",
                f"free_tms = {b(c.free_tms)}", ""]
        for sat in self.satellites:
            with localcontext() as ctx:
                ctx.prec = _EXACT
                a_km = sat.a_m / 1000
            out += ["[[satellites]]", f"name = {_toml_str(sat.name)}", f"a_km = {_toml_dec(a_km)}", f"e = {_toml_dec(sat.e)}",
                    f"i_deg = {_toml_dec(sat.i_deg)}", f"raan_deg = {_toml_dec(sat.raan_deg)}",
                    f"argp_deg = {_toml_dec(sat.argp_deg)}", f"nu_deg = {_toml_dec(sat.nu_deg)}", ""]
        return "\n".join(out)


def _toml_value(x: Any) -> str:
    """A string or a nested tuple of Decimals as TOML."""
    if isinstance(x, str):
        return _toml_str(x)
    if isinstance(x, tuple):
        return "[" + ", ".join(_toml_value(e) for e in x) + "]"
    return _toml_dec(x)


def _toml_dec(d: Decimal) -> str:
    # str(Decimal) of a finite value is always a valid TOML integer or float
    # ("100009.5", "1E+5", "3.986004415E+14", "0E-7").
    return str(d)


_TOML_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _toml_str(s: str) -> str:
    out = []
    for ch in s:
        if ch in _TOML_ESCAPES:
            out.append(_TOML_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


# --------------------------------------------------------------------------- raw table -> Scenario

_STR, _NUM, _INT, _BOOL, _DUR, _EPOCH = "string", "number", "integer", "boolean", "duration", "epoch"
_STRLIST = "list of strings"
_ANY = "any"  # validated by the dataclass itself

_SCHEMA: dict[str, dict[str, str]] = {
    "scenario": {"name": _STR, "description": _STR, "epoch_utc": _EPOCH, "extends": _STR},
    "run": {"duration": _DUR, "precision": _STR, "output": _STR, "output_every": _INT},
    "integrator": {"method": _STR, "mode": _STR, "step": _NUM, "tableau": _STR, "rtol": _NUM},
    "forces": {"earth_monopole": _BOOL, "gm_earth": _NUM, "earth_degree": _INT, "earth_degree2_extended": _BOOL, "ephemeris": _STR,
               "third_bodies": _STRLIST, "third_bodies_extended": _STRLIST, "solid_tides": _BOOL, "ocean_tides_degree": _INT, "pole_tides": _BOOL,
               "moon_degree": _INT, "moon_libration": _STR, "sun_j2": _BOOL, "relativity": _BOOL,
               "earth_field_indirect": _BOOL, "eop": _BOOL},
    "spacecraft": {"d_tm": _NUM, "d_p": _NUM, "tm_axis": _STR, "self_gravity": _ANY, "self_gravity_common": _ANY},
    "constellation": {"pointing": _STR, "control": _STR, "free_tms": _BOOL},
}
_SAT_SCHEMA: dict[str, str] = {
    "name": _STR, "a_km": _NUM, "e": _NUM, "i_deg": _NUM, "raan_deg": _NUM, "argp_deg": _NUM, "nu_deg": _NUM,
}
_TOP_KEYS = tuple(_SCHEMA) + ("satellites",)
# TOML key -> dataclass field, where they differ
_FIELD_OF = {"step": "step_s", "duration": "duration_s", "d_tm": "d_tm_m", "d_p": "d_p_m"}


def _typed(value: Any, kind: str, name: str) -> Any:
    """Check the TOML type of a raw value and convert it (no range checks)."""
    if kind == _STR:
        _require(isinstance(value, str), name, value, f"is {_a(_toml_type(value))}", "a string")
        return value
    if kind == _BOOL:
        _require(isinstance(value, bool), name, value, f"is {_a(_toml_type(value))}", "true or false")
        return value
    if kind == _INT:
        _require(isinstance(value, int) and not isinstance(value, bool), name, value, f"is {_a(_toml_type(value))}", "an integer")
        return value
    if kind == _NUM:
        ok = isinstance(value, (int, Decimal)) and not isinstance(value, bool)
        _require(ok, name, value, f"is {_a(_toml_type(value))}", "a number")
        _require(Decimal(value).is_finite(), name, value, "is not finite", "a finite number")
        return Decimal(value)
    if kind == _STRLIST:
        ok = isinstance(value, list) and all(isinstance(x, str) for x in value)
        _require(ok, name, value, f"is {_a(_toml_type(value))}", "a list of strings")
        return tuple(value)
    if kind == _ANY:
        return value
    if kind == _DUR:
        d = _parse_duration(value, name)
        return d
    if kind == _EPOCH:
        if isinstance(value, str):
            return value
        if isinstance(value, _dt.datetime):
            off = value.utcoffset()
            _require(off is None or off == _dt.timedelta(0), name, value.isoformat(), "has a non-zero UTC offset", "a UTC date-time")
            return value.replace(tzinfo=None).isoformat()
        if isinstance(value, _dt.date):
            return value.isoformat()
        raise ScenarioError(name, value, f"is {_a(_toml_type(value))}", "a UTC date-time string YYYY-MM-DDTHH:MM:SS[.fff]")
    raise AssertionError(kind)  # pragma: no cover


def _a(noun: str) -> str:
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def _toml_type(value: Any) -> str:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, (Decimal, float)):
        return "float"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    if isinstance(value, dict):
        return "table"
    if isinstance(value, (_dt.date, _dt.time)):
        return "date-time"
    return type(value).__name__


def _check_table(table: Any, name: str, allowed: Sequence[str]) -> dict:
    _require(isinstance(table, dict), name, table, f"is {_a(_toml_type(table))}", "a table")
    for key in table:
        if key not in allowed:
            raise ScenarioError(f"{name}.{key}" if name else key, problem="is not a known key", allowed=", ".join(allowed))
    return table


def _build(cls, prefix: str, raw: Mapping[str, Any], schema: Mapping[str, str]):
    """Type-check raw TOML values, construct ``cls`` and map its errors back to TOML names."""
    kwargs: dict[str, Any] = {}
    for key, kind in schema.items():
        if key in raw:
            kwargs[_FIELD_OF.get(key, key)] = _typed(raw[key], kind, f"{prefix}.{key}")
    try:
        return cls(**kwargs)
    except ScenarioError as err:
        key = err.field.rsplit(".", 1)[-1]
        toml_key = {v: k for k, v in _FIELD_OF.items()}.get(key, key)
        value = raw.get(toml_key, err.value)
        raise ScenarioError(f"{prefix}.{toml_key}", value, err.problem, err.allowed) from None


def _build_satellite(raw: Any, k: int) -> SatelliteConfig:
    prefix = f"satellites.{k}"
    _check_table(raw, prefix, tuple(_SAT_SCHEMA))
    _require("a_km" in raw, f"{prefix}.a_km", _NOVALUE, "is missing", "a semi-major axis in km (> 0)")
    vals = {key: _typed(raw[key], kind, f"{prefix}.{key}") for key, kind in _SAT_SCHEMA.items() if key in raw}
    a_km = vals.pop("a_km")
    with localcontext() as ctx:
        ctx.prec = _EXACT
        a_m = a_km * 1000
    _require(a_km > 0, f"{prefix}.a_km", a_km, "is not positive", "a_km > 0 km")
    kwargs = {"name": vals.pop("name", f"Sat{k}"), "a_m": a_m, "e": Decimal(0), "i_deg": Decimal(0),
              "raan_deg": Decimal(0), "argp_deg": Decimal(0), "nu_deg": Decimal(0)}
    kwargs.update(vals)
    try:
        return SatelliteConfig(**kwargs)
    except ScenarioError as err:
        key = err.field.rsplit(".", 1)[-1]
        key = "a_km" if key == "a_m" else key
        raise ScenarioError(f"{prefix}.{key}", raw.get(key, err.value), err.problem, err.allowed) from None


def _scenario_from_raw(raw: dict, default_name: str) -> Scenario:
    _check_table(raw, "", _TOP_KEYS)
    for sec in _SCHEMA:
        _check_table(raw.get(sec, {}), sec, tuple(_SCHEMA[sec]))
    meta = raw.get("scenario", {})
    run = _build(RunConfig, "run", raw.get("run", {}), _SCHEMA["run"])
    integ = _build(IntegratorConfig, "integrator", raw.get("integrator", {}), _SCHEMA["integrator"])
    forces = _build(ForcesConfig, "forces", raw.get("forces", {}), _SCHEMA["forces"])
    craft = _build(SpacecraftConfig, "spacecraft", raw.get("spacecraft", {}), _SCHEMA["spacecraft"])
    const = _build(ConstellationConfig, "constellation", raw.get("constellation", {}), _SCHEMA["constellation"])
    sats_raw = raw.get("satellites")
    _require(sats_raw is not None, "satellites", _NOVALUE, "is missing", "at least one [[satellites]] table")
    _require(isinstance(sats_raw, list) and len(sats_raw) >= 1, "satellites", sats_raw, "is not a non-empty array of tables",
             "at least one [[satellites]] table")
    sats = tuple(_build_satellite(s, k) for k, s in enumerate(sats_raw, start=1))
    name = _typed(meta.get("name", default_name), _STR, "scenario.name")
    desc = _typed(meta.get("description", ""), _STR, "scenario.description")
    epoch = _typed(meta.get("epoch_utc", DEFAULT_EPOCH_UTC), _EPOCH, "scenario.epoch_utc")
    return Scenario(name=name, description=desc, epoch_utc=epoch, run=run, integrator=integ, forces=forces,
                    spacecraft=craft, constellation=const, satellites=sats)


# --------------------------------------------------------------------------- overrides


def _parse_override_value(text: str, kind: str) -> Any:
    try:
        value = tomllib.loads("v = " + text, parse_float=Decimal)["v"]
    except tomllib.TOMLDecodeError:
        if kind == _STRLIST:  # --set forces.third_bodies=sun,moon
            return [x.strip() for x in text.split(",") if x.strip()]
        return text.strip()
    if kind in (_STR, _EPOCH) and not isinstance(value, str) and not (kind == _EPOCH and isinstance(value, _dt.date)):
        return text.strip()  # e.g. --set scenario.name=123 means the string "123"
    return value


def _apply_overrides(raw: dict, overrides: Sequence[str]) -> None:
    for item in overrides:
        if not isinstance(item, str) or "=" not in item:
            raise ScenarioError("override", item, "is not of the form key=value",
                                '"section.key=value" or "satellites.N.key=value"')
        key, text = item.split("=", 1)
        key = key.strip()
        parts = key.split(".")
        if parts[0] == "satellites":
            sats = raw.get("satellites")
            n = len(sats) if isinstance(sats, list) else 0
            if len(parts) != 3:
                raise ScenarioError(f"override {key}", problem="is not of the form satellites.N.key",
                                    allowed=f"satellites.N.key with N in 1..{n} and key in {', '.join(_SAT_SCHEMA)}")
            idx_text, sat_key = parts[1], parts[2]
            if not idx_text.isdigit() or not 1 <= int(idx_text) <= n:
                raise ScenarioError(f"override {key}", idx_text, "is not a satellite index",
                                    f"1..{n} (1-based)" if n else "no satellites defined")
            if sat_key not in _SAT_SCHEMA:
                raise ScenarioError(f"override {key}", sat_key, "is not a satellite key", ", ".join(_SAT_SCHEMA))
            sat = sats[int(idx_text) - 1]
            _require(isinstance(sat, dict), f"satellites.{idx_text}", sat, "is not a table", "a [[satellites]] table")
            sat[sat_key] = _parse_override_value(text, _SAT_SCHEMA[sat_key])
            continue
        if len(parts) != 2 or parts[0] not in _SCHEMA:
            allowed = ", ".join(f"{s}.<key>" for s in _SCHEMA) + ", satellites.N.<key>"
            raise ScenarioError(f"override {key}", problem="is not a known section.key", allowed=allowed)
        sec, sub = parts
        if sub not in _SCHEMA[sec]:
            raise ScenarioError(f"override {key}", sub, f"is not a key of [{sec}]", ", ".join(_SCHEMA[sec]))
        table = raw.setdefault(sec, {})
        _require(isinstance(table, dict), sec, table, "is not a table", "a table")
        table[sub] = _parse_override_value(text, _SCHEMA[sec][sub])


# --------------------------------------------------------------------------- public loaders


def _builtin_dir():
    return resources.files("tqdyn") / "scenarios"


def builtin_scenarios() -> tuple[str, ...]:
    """Names of the built-in scenarios (package data ``tqdyn/scenarios/*.toml``), sorted."""
    return tuple(sorted(p.name[: -len(".toml")] for p in _builtin_dir().iterdir() if p.name.endswith(".toml")))


def loads_scenario(text: str, overrides: Sequence[str] = (), *, source: str = "<string>", default_name: str = "scenario") -> Scenario:
    """Build a :class:`Scenario` from TOML ``text`` (see :func:`load_scenario` for overrides).

    ``source`` names the text in error messages; ``default_name`` is used when
    the text has no ``scenario.name``.
    """
    try:
        raw = tomllib.loads(text, parse_float=Decimal)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, problem=f"invalid TOML: {exc}", allowed="a TOML document (https://toml.io)") from None
    raw = _resolve_extends(raw, source, ())
    if isinstance(overrides, str):
        overrides = (overrides,)
    _apply_overrides(raw, overrides)
    return _scenario_from_raw(raw, default_name)


def _resolve_extends(raw: dict, source: str, chain: tuple[str, ...]) -> dict:
    """``[scenario] extends = "<built-in>"``: the built-in scenario's tables,
    each updated key by key with this file's (``[[satellites]]``, if given,
    replaces the base's list); ``name`` and ``description`` are this file's."""
    meta = raw.get("scenario", {})
    if not isinstance(meta, dict) or "extends" not in meta:
        return raw
    base_name = meta["extends"]
    builtins = builtin_scenarios()
    _require(isinstance(base_name, str) and base_name in builtins, "scenario.extends", base_name,
             "is not a built-in scenario", ", ".join(builtins))
    _require(base_name not in chain, "scenario.extends", base_name, f"extends itself ({' -> '.join(chain)})",
             "a chain of built-in scenarios without cycles")
    text = (_builtin_dir() / f"{base_name}.toml").read_text(encoding="utf-8")
    base = _resolve_extends(tomllib.loads(text, parse_float=Decimal), base_name, chain + (base_name,))
    merged = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    for key, value in raw.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key].update(value)
        else:
            merged[key] = value
    merged["scenario"] = {k: v for k, v in merged["scenario"].items() if k != "extends"}
    merged["scenario"].setdefault("description", "")
    for k in ("name", "description"):
        if k not in meta:
            merged["scenario"].pop(k, None)
    return merged


def load_scenario(name_or_path: str | os.PathLike | None = None, overrides: Sequence[str] = ()) -> Scenario:
    """Load a scenario by built-in name or from a ``.toml`` file, apply overrides, validate.

    Parameters
    ----------
    name_or_path : str, path or None
        ``None`` -> ``"tianqin"``.  A built-in name (see
        :func:`builtin_scenarios`) or a path to a TOML file.  A string that
        ends in ``.toml`` or contains a path separator is always a path.
    overrides : sequence of str
        ``"section.key=value"`` or ``"satellites.N.key=value"`` (N 1-based).
        ``value`` is read as a TOML value (``50.0``, ``true``, ``"x"``) and
        otherwise taken as a plain string (``integrator.mode=adaptive``,
        ``run.duration=90d``).  Applied to the raw table before validation.

    Returns a validated :class:`Scenario`; raises :class:`ScenarioError`.
    """
    if name_or_path is None:
        name_or_path = DEFAULT_SCENARIO
    builtins = builtin_scenarios()
    text_name = os.fspath(name_or_path)
    looks_like_path = (
        not isinstance(name_or_path, str)
        or text_name.endswith(".toml")
        or os.sep in text_name
        or (os.altsep is not None and os.altsep in text_name)
    )
    if not looks_like_path and text_name in builtins:
        text = (_builtin_dir() / f"{text_name}.toml").read_text(encoding="utf-8")
        return loads_scenario(text, overrides, source=f"built-in scenario {text_name!r}", default_name=text_name)
    path = Path(text_name)
    if not path.is_file():
        what = "is not a file" if path.exists() else ("does not exist" if looks_like_path else "is neither a built-in scenario nor a file")
        raise ScenarioError("scenario", text_name, what, f"a path to a .toml file or a built-in scenario: {', '.join(builtins)}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError("scenario", text_name, f"cannot be read ({exc})", "a readable UTF-8 .toml file") from None
    return loads_scenario(text, overrides, source=str(path), default_name=path.stem)
