"""The ``[closed_loop]`` section of a scenario: the closed-loop model's settings (docs/scenarios.md).

Every key is optional; what is not given takes the mission's default
(:mod:`tqdyn.closedloop.missions`), the mission being ``closed_loop.mission`` or, by default, the
run's ``spacecraft.architecture``, and the settings' defaults of :data:`CLOSED_LOOP_KEYS`.  Layout
(SI units; ASDs one-sided)::

    [closed_loop]
    mission                       # one of MISSIONS: "tianqin" | "lisa" | "taiji" | "lpf" | "tianqin-1"
    defaults                      # one of DEFAULTS: "published" (default) | "v0.3" (the constellation missions'
                                  # preset of default values: tqdyn.closedloop.missions)
    scheme                        # one of SCHEMES (default: the mission's, MISSION_SCHEME)
    fs                            # Hz, time-domain sample rate
    duration                      # time-domain length ("3d" or s; default: the first day, or the run's span)
    seed                          # root seed of the noise realisations
    segment                       # frozen-coefficient segment length ("1d" or s)
    f_min, f_max, n_freq          # the budget's log frequency grid [Hz]
    attitude_z_sensor             # one of ATTITUDE_Z_SENSORS
    design                        # one of DESIGNS: "per_loop" (default) | "hinf"
    hinf_peak_sensitivity         # "hinf": the weights' peak sensitivity M_s (> 1; default 2)
    hinf_authority_ratio          # "hinf": the actuators' bandwidth ratio r (> 0; default 30)
    [closed_loop.plant]           # sc_mass [kg], sc_inertia [kg m^2] (3), tm_mass [kg], tm_side [m],
                                  # mosa_inertia [kg m^2], mosa_stiffness [N m/rad], stiffness [s^-2] (3),
                                  # rotational_stiffness [s^-2] (3), crosstalk [1], tm2_stiffness,
                                  # tm2_rotational_stiffness [s^-2] (3, TM 2's when it differs),
                                  # tm_separation [m] (single-spacecraft missions: the housings' distance)
    [closed_loop.controllers.<loop>]   # zeros, poles [rad/s; [re, im] for a conjugate pair], gain
                                       # (the loops of the scheme: SCHEME_LOOPS)
    [closed_loop.noise.<source>]       # level [unit/Hz^1/2], knees [[f Hz, slope], ...] (SOURCES)

The loop and noise-source tables (:data:`LOOPS`, :data:`SCHEME_LOOPS`, :data:`SOURCES`) live here, the
lowest layer that names them; :mod:`tqdyn.closedloop` builds the loops from them.

The configuration is kept as given (sparse): :meth:`ClosedLoopConfig.to_toml_lines` writes back only the
keys that were set, so scenarios without the section resolve to the same text as before it existed.
Errors are :class:`~tqdyn.scenario.values.ScenarioError` naming the key.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any

from ..numerics.finite import finite_number
from .toml_text import toml_str, toml_value
from .values import ScenarioError, _require, _require_choice, _unknown_key

__all__ = ["ATTITUDE_Z_SENSORS", "CLOSED_LOOP_KEYS", "COLLINEAR_LOOPS", "CONSTELLATION_MISSIONS", "DEFAULTS",
           "DEFAULT_SERIES_S", "DESIGNS",
           "LOOPS", "MISSIONS", "MISSION_SCHEME", "PLANT_KEYS", "SCHEMES", "SCHEME_LOOPS", "SINGLE_SPACECRAFT_MISSIONS",
           "SINGLE_TM_LOOPS", "SOURCES", "ClosedLoopConfig", "check_asd", "check_controller"]

#: Missions of a constellation (three spacecraft, a coupled run's working point).
CONSTELLATION_MISSIONS = ("tianqin", "lisa", "taiji")
#: Single-spacecraft missions that flew: LISA Pathfinder (two test masses on one axis) and TianQin-1 (one
#: inertial sensor); their loops are built at a documented static working point (no run needed).
SINGLE_SPACECRAFT_MISSIONS = ("lpf", "tianqin-1")
#: Missions with a default closed-loop design (tqdyn.closedloop.missions).
MISSIONS = CONSTELLATION_MISSIONS + SINGLE_SPACECRAFT_MISSIONS
#: Control schemes (which sensor drives which actuator): "constellation" (a MOSA per TM, DWS attitude: the
#: three constellation missions), "collinear" (two TMs on one axis, LISA Pathfinder's modes), "single_tm"
#: (one inertial sensor in accelerometer mode, TianQin-1's).
SCHEMES = ("constellation", "collinear", "single_tm")
#: The scheme of each mission.
MISSION_SCHEME = {"tianqin": "constellation", "lisa": "constellation", "taiji": "constellation",
                  "lpf": "collinear", "tianqin-1": "single_tm"}
#: Control loops of the "constellation" scheme: name -> (channels, what is sensed, sensor, actuator).  Each
#: channel's controller (tqdyn.closedloop.controllers) turns the sensed coordinate into an acceleration command.
LOOPS = {
    "dragfree": (("tm1 sensitive axis", "tm2 sensitive axis", "mean z of the TMs"), "m",
                 "interferometer (sensitive axes), capacitive (z)", "thrusters (force)"),
    "suspension": (("tm1 p axis (Z x e_1)", "tm2 p axis (Z x e_2)", "half the z difference"), "m",
                   "capacitive", "electrostatic force"),
    "attitude": (("x", "y"), "rad", "DWS (the pitches of both MOSAs)", "thrusters (torque)"),
    "attitude_z": (("z",), "rad", "mean DWS yaw minus mean MOSA encoder angle (or the star tracker)",
                   "thrusters (torque)"),
    "mosa": (("MOSA 1", "MOSA 2"), "rad", "DWS yaw of the MOSA (spacecraft yaw + MOSA angle)", "MOSA actuator"),
    "tm_rotation": (("tm1 x", "tm1 y", "tm1 z", "tm2 x", "tm2 y", "tm2 z"), "rad", "capacitive", "electrostatic torque"),
}
#: Loops of the "collinear" scheme (LISA Pathfinder's science mode; TM 1 at +tm_separation/2 on X_S, TM 2 at
#: -tm_separation/2, both sensitive axes X_S; docs/closed-loop-validation.md).
COLLINEAR_LOOPS = {
    "dragfree": (("x: tm1 (o1)", "y: mean of the TMs", "z: mean of the TMs"), "m",
                 "interferometer o1 (x), capacitive (y, z)", "thrusters (force)"),
    "suspension": (("x: tm2 on o12",), "m", "interferometer o12 = x2 - x1", "electrostatic force on TM 2"),
    "attitude": (("x: mean TM rotation about X", "y: (z1 - z2)/separation", "z: -(y1 - y2)/separation"), "rad",
                 "capacitive (the TMs: the spacecraft follows them)", "thrusters (torque)"),
    "tm_rotation": (("tm1 y", "tm1 z", "tm2 y", "tm2 z", "tm2 - tm1 x"), "rad", "capacitive", "electrostatic torque"),
    "guidance": (("x", "y", "z"), "rad", "star tracker (the spacecraft's inertial attitude)",
                 "electrostatic torque about X on both TMs (x), differential force along Z (y) and Y (z)"),
}
#: Loops of the "single_tm" scheme (TianQin-1: the inertial sensor as an accelerometer, drag-free on its
#: measured acceleration, attitude on the star tracker).
SINGLE_TM_LOOPS = {
    "suspension": (("tm1 x", "tm1 y", "tm1 z"), "m", "capacitive", "electrostatic force (the accelerometer's servo)"),
    "dragfree": (("x", "y", "z"), "m/s^2", "the suspension's command (the measured acceleration)",
                 "thrusters (force)"),
    "attitude": (("x", "y", "z"), "rad", "star tracker", "thrusters (torque)"),
    "tm_rotation": (("tm1 x", "tm1 y", "tm1 z"), "rad", "capacitive", "electrostatic torque"),
}
#: The loop table of each scheme.
SCHEME_LOOPS = {"constellation": LOOPS, "collinear": COLLINEAR_LOOPS, "single_tm": SINGLE_TM_LOOPS}
#: Noise sources: name -> (components, unit of the ASD, where it enters the loop, tqdyn.closedloop.loop).
SOURCES = {
    "thruster_force": (3, "N", "thrust, S axes"),
    "thruster_gain": (3, "1", "fractional thrust noise times the DC thrust M |G| per S axis"),
    "thruster_torque": (3, "N m", "thruster torque, S axes"),
    "tm_force": (6, "m/s^2", "stray acceleration of TM 1, TM 2 (OA_l axes)"),
    "tm_torque": (6, "rad/s^2", "stray angular acceleration of TM 1, TM 2 (OA_l)"),
    "actuation_force": (6, "1", "fractional electrostatic force noise times the DC force m |A| per OA_l axis"),
    "actuation_torque": (6, "1", "fractional electrostatic torque noise times the DC torque I |alpha| per OA_l axis"),
    "capacitive_translation": (6, "m", "capacitive readout of x_1, x_2 (OA_l)"),
    "capacitive_rotation": (6, "rad", "capacitive readout of eta_1, eta_2 (OA_l)"),
    "interferometer": (2, "m", "TM interferometer along each sensitive axis"),
    "dws": (4, "rad", "DWS pitch and yaw of MOSA 1, then MOSA 2"),
    "star_tracker": (3, "rad", "star tracker, S axes"),
    "mosa_encoder": (2, "rad", "MOSA angle encoder (the angle of the MOSA relative to the spacecraft)"),
    "mosa_actuator": (2, "N m", "MOSA actuator torque"),
}
#: Sensors of the attitude about Z_S: the mean DWS yaw minus the mean MOSA encoder angle (default), or
#: the star tracker (as LISA Pathfinder, which had no DWS).
ATTITUDE_Z_SENSORS = ("dws", "star_tracker")

#: Controller designs: "per_loop" (one controller per channel: the mission's or [closed_loop.controllers]) and
#: "hinf" (an H-infinity mixed-sensitivity controller over each spacecraft's whole plant, tqdyn.closedloop.hinf;
#: the "constellation" scheme).
DESIGNS = ("per_loop", "hinf")
#: Presets of the constellation missions' default values (``closed_loop.defaults``): "published" replaces version
#: 0.3's values where a published design or flight paper gives one (tqdyn.closedloop.published, cited in
#: SOURCES.md), "v0.3" keeps version 0.3's lead-lag design and assumed values.  The first is the default.
DEFAULTS = ("published", "v0.3")

#: Length [s] of the time series when ``duration`` is not given: the run's first day (its span if shorter).
DEFAULT_SERIES_S = 86400.0
#: Top-level keys of [closed_loop]: name -> (kind, default).  Defaults: ``mission`` None = the spacecraft
#: architecture; ``scheme`` None = the mission's (:data:`MISSION_SCHEME`); ``fs`` [Hz]; ``duration`` [s] None =
#: :data:`DEFAULT_SERIES_S` or the run's span if shorter; ``segment`` [s]; ``f_min``, ``f_max``
#: [Hz] and ``n_freq`` the budget's log grid; ``attitude_z_sensor`` one of :data:`ATTITUDE_Z_SENSORS`;
#: ``defaults`` one of :data:`DEFAULTS`.
CLOSED_LOOP_KEYS = {"mission": ("string", None), "scheme": ("string", None), "fs": ("number", 4.0),
                    "duration": ("duration", None), "seed": ("integer", 0), "segment": ("duration", 86400.0),
                    "f_min": ("number", 1e-5), "f_max": ("number", 1.0), "n_freq": ("integer", 300),
                    "attitude_z_sensor": ("string", ATTITUDE_Z_SENSORS[0]), "defaults": ("string", DEFAULTS[0]),
                    "design": ("string", DESIGNS[0]), "hinf_peak_sensitivity": ("number", 2.0),
                    "hinf_authority_ratio": ("number", 30.0)}
#: Keys of [closed_loop.plant]: name -> number of values (1: a number).
PLANT_KEYS = {"sc_mass": 1, "sc_inertia": 3, "tm_mass": 1, "tm_side": 1, "mosa_inertia": 1, "mosa_stiffness": 1,
              "stiffness": 3, "rotational_stiffness": 3, "crosstalk": 1, "tm2_stiffness": 3,
              "tm2_rotational_stiffness": 3, "tm_separation": 1}
_POSITIVE = ("sc_mass", "sc_inertia", "tm_mass", "tm_side", "mosa_inertia", "tm_separation")
#: Where the keys, loops and noise sources are listed.
_DOC = "docs/scenarios.md#closed_loop"


def _num(v) -> bool:
    return finite_number(v) is not None


@dataclass(frozen=True)
class ClosedLoopConfig:
    """The validated ``[closed_loop]`` table (module docstring); ``raw`` the given keys as nested dicts."""

    raw: Any = field(default_factory=dict)

    def __post_init__(self):
        raw = self.raw if self.raw is not None else {}
        _require(isinstance(raw, dict), "closed_loop", raw, "is not a table", "a [closed_loop] table")
        allowed = tuple(CLOSED_LOOP_KEYS) + ("plant", "controllers", "noise")
        for key, v in raw.items():
            name = f"closed_loop.{key}"
            if key not in allowed:
                raise _unknown_key(name, allowed, _DOC)
            if key == "mission":
                _require_choice(v, name, MISSIONS, problem="is not a mission")
            elif key == "scheme":
                _require_choice(v, name, SCHEMES, problem="is not a control scheme")
            elif key == "attitude_z_sensor":
                _require_choice(v, name, ATTITUDE_Z_SENSORS, problem="is not a sensor")
            elif key == "design":
                _require_choice(v, name, DESIGNS, problem="is not a controller design")
            elif key == "hinf_peak_sensitivity":
                _require(_num(v) and float(v) > 1, name, v, "is not allowed", "a peak sensitivity > 1")
            elif key == "hinf_authority_ratio":
                _require(_num(v) and float(v) > 0, name, v, "is not allowed", "a bandwidth ratio > 0")
            elif key == "defaults":
                _require_choice(v, name, DEFAULTS, problem="is not a defaults preset")
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
                loops = SCHEME_LOOPS[self.scheme()]
                for loop, spec in v.items():
                    lname = f"{name}.{loop}"
                    if loop not in loops:
                        raise _unknown_key(lname, loops, _DOC, f"is not a loop of the {self.scheme()!r} scheme")
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
        lo, hi = (float(raw.get(k, CLOSED_LOOP_KEYS[k][1])) for k in ("f_min", "f_max"))
        if not lo < hi:
            given = "f_min" if "f_min" in raw else "f_max"
            _require(False, f"closed_loop.{given}", raw[given],
                     f"leaves no band: f_min = {lo:g} Hz, f_max = {hi:g} Hz" + ("" if {"f_min", "f_max"} <= set(raw)
                                                                               else " (the other one's default)"),
                     "f_min < f_max [Hz]")

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

    def scheme(self, architecture: str = "tianqin") -> str:
        """The control scheme: ``scheme`` or the mission's (:data:`MISSION_SCHEME`; a constellation run's
        architecture by default)."""
        raw = self.raw or {}
        if raw.get("scheme") in SCHEMES:
            return str(raw["scheme"])
        return MISSION_SCHEME.get(str(raw.get("mission", architecture)), "constellation")

    def value(self, key: str, default):
        """A top-level value as float/int/str (durations in s), or ``default``."""
        v = self.raw.get(key)
        if v is None:
            return default
        if isinstance(v, (Decimal, float)):
            return float(v)
        return v

    def settings(self) -> dict:
        """The top-level settings but ``mission`` with the defaults of :data:`CLOSED_LOOP_KEYS` filled in:
        fs [Hz], duration [s] (None: the run's span), seed, segment [s], f_min, f_max [Hz], n_freq,
        attitude_z_sensor, defaults; numbers as float, integers as int."""
        cast = {"number": float, "integer": int, "duration": float, "string": str}
        out = {}
        for key, (kind, default) in CLOSED_LOOP_KEYS.items():
            if key != "mission":
                v = self.value(key, default)
                out[key] = None if v is None else cast[kind](v)
        return out

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
