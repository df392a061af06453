"""The ``[closed_loop]`` section of a scenario: the closed-loop model's settings (docs/scenarios.md).

Every key is optional; what is not given takes the mission's default
(:mod:`tqdyn.closedloop.missions`), the mission being ``closed_loop.mission`` or, by default, the
run's ``spacecraft.architecture``.  Layout (SI units; ASDs one-sided)::

    [closed_loop]
    mission = "lisa"              # "tianqin" | "lisa" | "taiji" (default: spacecraft.architecture)
    fs = 4.0                      # Hz, time-domain sample rate
    duration = "3d"               # time-domain length (default: the run's span)
    seed = 0                      # root seed of the noise realisations
    segment = "1d"                # frozen-coefficient segment length
    f_min = 1e-5                  # Hz, budget grid
    f_max = 1.0                   # Hz
    n_freq = 300
    attitude_z_sensor = "dws"     # "dws" | "star_tracker"
    [closed_loop.plant]           # sc_mass [kg], sc_inertia [kg m^2] (3), tm_mass [kg], tm_side [m],
                                  # mosa_inertia [kg m^2], mosa_stiffness [N m/rad], stiffness [s^-2] (3),
                                  # rotational_stiffness [s^-2] (3), crosstalk [1]
    [closed_loop.controllers.<loop>]   # zeros, poles [rad/s; [re, im] for a conjugate pair], gain
    [closed_loop.noise.<source>]       # level [unit/Hz^1/2], knees [[f Hz, slope], ...]

The configuration is kept as given (sparse): :meth:`ClosedLoopConfig.to_toml_lines` writes back only the
keys that were set, so scenarios without the section resolve to the same text as before it existed.
Errors are :class:`~tqdyn.scenario.values.ScenarioError` naming the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any

from .toml_text import toml_str, toml_value
from .values import ScenarioError, _require, _require_choice, _unknown_key

__all__ = ["CLOSED_LOOP_KEYS", "LOOP_NAMES", "MISSIONS", "PLANT_KEYS", "SOURCE_UNITS", "ClosedLoopConfig",
           "check_asd", "check_controller"]

#: Missions with a default closed-loop design (tqdyn.closedloop.missions).
MISSIONS = ("tianqin", "lisa", "taiji")
#: Control loops (tqdyn.closedloop.controllers.LOOPS describes their channels).
LOOP_NAMES = ("dragfree", "suspension", "attitude", "attitude_z", "mosa", "tm_rotation")
#: Noise sources and the unit of their ASD (tqdyn.closedloop.loop.SOURCES: components, where they enter).
SOURCE_UNITS = {"thruster_force": "N", "thruster_gain": "1", "thruster_torque": "N m", "tm_force": "m/s^2",
                "tm_torque": "rad/s^2", "actuation_force": "1", "actuation_torque": "1",
                "capacitive_translation": "m", "capacitive_rotation": "rad", "interferometer": "m", "dws": "rad",
                "star_tracker": "rad", "mosa_encoder": "rad", "mosa_actuator": "N m"}

#: Top-level keys of [closed_loop] and their kind.
CLOSED_LOOP_KEYS = {"mission": "string", "fs": "number", "duration": "duration", "seed": "integer",
                    "segment": "duration", "f_min": "number", "f_max": "number", "n_freq": "integer",
                    "attitude_z_sensor": "string"}
#: Keys of [closed_loop.plant]: name -> number of values (1: a number).
PLANT_KEYS = {"sc_mass": 1, "sc_inertia": 3, "tm_mass": 1, "tm_side": 1, "mosa_inertia": 1, "mosa_stiffness": 1,
              "stiffness": 3, "rotational_stiffness": 3, "crosstalk": 1}
_POSITIVE = ("sc_mass", "sc_inertia", "tm_mass", "tm_side", "mosa_inertia")
#: Where the keys, loops and noise sources are listed.
_DOC = "docs/scenarios.md#closed_loop"


def _num(v) -> bool:
    return isinstance(v, (int, float, Decimal)) and not isinstance(v, bool) and math.isfinite(float(v))


@dataclass(frozen=True)
class ClosedLoopConfig:
    """The validated ``[closed_loop]`` table (module docstring); ``raw`` the given keys as nested dicts."""

    raw: Any = field(default_factory=dict)

    def __post_init__(self):
        LOOPS, SOURCES = LOOP_NAMES, SOURCE_UNITS
        raw = self.raw if self.raw is not None else {}
        _require(isinstance(raw, dict), "closed_loop", raw, "is not a table", "a [closed_loop] table")
        allowed = tuple(CLOSED_LOOP_KEYS) + ("plant", "controllers", "noise")
        for key, v in raw.items():
            name = f"closed_loop.{key}"
            if key not in allowed:
                raise _unknown_key(name, allowed, _DOC)
            if key == "mission":
                _require_choice(v, name, MISSIONS, problem="is not a mission")
            elif key == "attitude_z_sensor":
                _require_choice(v, name, ("dws", "star_tracker"), problem="is not a sensor")
            elif key in ("fs", "f_min", "f_max"):
                _require(_num(v) and float(v) > 0, name, v, "is not a positive number", "a frequency > 0 Hz")
            elif key in ("seed", "n_freq"):
                _require(isinstance(v, int) and not isinstance(v, bool) and v >= (0 if key == "seed" else 2),
                         name, v, "is not an allowed integer", "an integer >= 0 (seed), >= 2 (n_freq)")
            elif key in ("duration", "segment"):
                _require(_num(v) and float(v) > 0, name, v, "is not a positive duration", "a duration > 0 s")
            elif key == "plant":
                _require(isinstance(v, dict), name, v, "is not a table", "[closed_loop.plant]")
                for pk, pv in v.items():
                    pname = f"{name}.{pk}"
                    if pk not in PLANT_KEYS:
                        raise _unknown_key(pname, tuple(PLANT_KEYS), _DOC, "is not a plant key")
                    n = PLANT_KEYS[pk]
                    ok = _num(pv) if n == 1 else (isinstance(pv, list) and len(pv) == n and all(_num(x) for x in pv))
                    _require(ok, pname, pv, "is not valid", "a number" if n == 1 else f"{n} numbers")
                    vals = [pv] if n == 1 else pv
                    if pk in _POSITIVE:
                        _require(all(float(x) > 0 for x in vals), pname, pv, "is not positive", "> 0")
                    if pk == "crosstalk":
                        _require(0 <= float(pv) < 1, pname, pv, "is out of range", "0 <= crosstalk < 1")
            elif key == "controllers":
                _require(isinstance(v, dict), name, v, "is not a table", "[closed_loop.controllers.<loop>]")
                for loop, spec in v.items():
                    lname = f"{name}.{loop}"
                    if loop not in LOOPS:
                        raise _unknown_key(lname, LOOPS, _DOC, "is not a loop")
                    _require(isinstance(spec, dict) and set(spec) <= {"zeros", "poles", "gain"}, lname, spec,
                             "is not a controller table", "zeros, poles, gain")
                    self._controller(loop, spec)
            elif key == "noise":
                _require(isinstance(v, dict), name, v, "is not a table", "[closed_loop.noise.<source>]")
                for src, spec in v.items():
                    sname = f"{name}.{src}"
                    if src not in SOURCES:
                        raise _unknown_key(sname, tuple(SOURCES), _DOC, "is not a noise source", noun="sources")
                    _require(isinstance(spec, dict) and set(spec) <= {"level", "knees"}, sname, spec,
                             "is not a noise table", "level, knees")
                    self._asd(src, spec)

    @staticmethod
    def _controller(loop: str, spec: dict):
        for k in ("zeros", "poles", "gain"):
            _require(k in spec, f"closed_loop.controllers.{loop}.{k}", None, "is missing",
                     "zeros, poles (rad/s) and gain, all three")
        check_controller(loop, spec["zeros"], spec["poles"], spec["gain"])

    @staticmethod
    def _asd(src: str, spec: dict):
        check_asd(f"closed_loop.noise.{src}", spec.get("level", 0.0), spec.get("knees", []))

    def __hash__(self) -> int:  # the raw tables are dicts; the scenario is hashable
        return hash(repr(self.raw))

    def mission(self, architecture: str) -> str:
        """The mission whose defaults apply: ``mission`` or the spacecraft architecture."""
        return str(self.raw.get("mission", architecture))

    def value(self, key: str, default):
        """A top-level value as float/int/str (durations in s), or ``default``."""
        v = self.raw.get(key)
        if v is None:
            return default
        if isinstance(v, (Decimal, float)):
            return float(v)
        return v

    def to_toml_lines(self) -> list[str]:
        """The given keys as TOML lines (nothing when the section is empty)."""
        raw = self.raw or {}
        if not raw:
            return []
        out = ["[closed_loop]"]
        for k in CLOSED_LOOP_KEYS:
            if k in raw:
                v = raw[k]
                out.append(f"{k} = {toml_str(v) if isinstance(v, str) else toml_value(v)}")
        out.append("")
        if raw.get("plant"):
            out += ["[closed_loop.plant]"] + [f"{k} = {toml_value(v)}" for k, v in raw["plant"].items()] + [""]
        for group in ("controllers", "noise"):
            for name, spec in raw.get(group, {}).items():
                out += [f"[closed_loop.{group}.{name}]"] + [f"{k} = {toml_value(v)}" for k, v in spec.items()] + [""]
        return out


def _roots(values, name: str) -> list:
    ok = isinstance(values, (list, tuple)) and all(
        _num(v) or (isinstance(v, (list, tuple)) and len(v) == 2 and all(_num(x) for x in v)) for v in values)
    _require(ok, name, values, "is not a list of roots", "real numbers (rad/s) or [re, im] pairs (conjugate pairs)")
    out = []
    for v in values:
        if isinstance(v, (list, tuple)):
            re, im = float(v[0]), float(v[1])
            out += [complex(re, im), complex(re, -im)] if im != 0 else [complex(re, 0.0)]
        else:
            out.append(complex(float(v), 0.0))
    return out


def check_controller(loop: str, zeros, poles, gain) -> tuple[list, list, float]:
    """The rules of a controller C(s) = gain prod(s - z)/prod(s - p) (tqdyn.closedloop.controllers): roots
    real or [re, im] pairs [rad/s], finite; at most as many zeros as poles (proper); poles with Re <= 0;
    gain > 0.  Returns (zeros, poles, gain) as complex lists and a float; ScenarioError naming the key."""
    name = f"closed_loop.controllers.{loop}"
    z = _roots(zeros, f"{name}.zeros")
    p = _roots(poles, f"{name}.poles")
    _require(_num(gain) and float(gain) > 0, f"{name}.gain", gain, "is not a positive number",
             "gain > 0 (negative feedback is built into the loop)")
    _require(len(z) <= len(p), name, f"{len(z)} zeros, {len(p)} poles", "is improper",
             "at most as many zeros as poles")
    _require(all(r.real <= 0 for r in p), f"{name}.poles", poles, "has an unstable pole",
             "poles with Re <= 0 (an integrator at 0 is allowed)")
    return z, p, float(gain)


def check_asd(name: str, level, knees) -> tuple[float, tuple]:
    """The rules of an ASD model (tqdyn.closedloop.noise.AsdModel): level finite and >= 0 (a negative ASD
    is refused), knees pairs [f > 0 Hz, slope != 0].  Returns (level, knees) as floats."""
    _require(_num(level), f"{name}.level", level, "is not a finite number", "a level >= 0 (unit/Hz^1/2)")
    _require(float(level) >= 0, f"{name}.level", level, "is a negative ASD", "a level >= 0 (unit/Hz^1/2)")
    ok = isinstance(knees, (list, tuple)) and all(
        isinstance(k, (list, tuple)) and len(k) == 2 and all(_num(x) for x in k) and float(k[0]) > 0
        and float(k[1]) != 0 for k in knees)
    _require(ok, f"{name}.knees", knees, "has an invalid knee", "pairs [frequency Hz > 0, slope != 0]")
    return float(level), tuple((float(a), float(b)) for a, b in knees)
