"""Default closed-loop parameters, noise models and controllers of TianQin, LISA and Taiji, and (through
:mod:`tqdyn.closedloop.flown`) of the single-spacecraft missions LISA Pathfinder (``lpf``) and TianQin-1.

Every number has its source in src/tqdyn/data/SOURCES.md (section "Closed-loop defaults"); the ones
marked *assumption* are tqdyn's choices where no public document gives a value, stated with the
reason.  Two presets (``closed_loop.defaults``, :data:`tqdyn.scenario.closed_loop.DEFAULTS`): ``"published"``
(the default) replaces v0.3's values where a published design or flight paper gives one
(:mod:`tqdyn.closedloop.published`); ``"v0.3"`` keeps version 0.3's lead-lag design and assumed values as
they were.  Units: SI; ASDs one-sided (:mod:`tqdyn.closedloop.noise`).
"""

from __future__ import annotations

import math

import numpy as np

from .._choices import unknown

from ..scenario.closed_loop import (CONSTELLATION_MISSIONS, DEFAULTS, MISSIONS, PLANT_KEYS, SCHEME_LOOPS,
                                    SINGLE_SPACECRAFT_MISSIONS)
from .controllers import Controller, lead_lag_pid
from .flown import (flown_controllers, flown_noise, flown_plant, flown_plant_parameters, flown_requirement,
                    flown_working_point)
from .noise import AsdModel
from .plant import PlantParameters, WorkingPoint, plant_parameters
from .published import published_noise_levels, published_plant_values

__all__ = ["CONSTELLATION_MISSIONS", "MISSIONS", "SINGLE_SPACECRAFT_MISSIONS", "controller_from_keys",
           "default_controllers", "default_noise", "default_plant", "representative_plant",
           "representative_working_point", "requirement", "resolve"]


#: Plant defaults per mission (scenario keys of [closed_loop.plant]).
_PLANT = {
    # TM: 2.45 kg, 50 mm cube (TianQin test-mass design); spacecraft 600 kg (assumption), inertias of a
    # 1 m-radius, 0.8 m-high cylinder of that mass (assumption)
    "tianqin": dict(sc_mass=600.0, sc_inertia=(182.0, 182.0, 300.0), tm_mass=2.45, tm_side=0.050),
    # TM: 1.96 kg, 46 mm Au-Pt cube (LISA Pathfinder / LISA); spacecraft ~2000 kg, inertias of a 1.5 m-radius,
    # 0.8 m-high cylinder (assumption)
    "lisa": dict(sc_mass=2000.0, sc_inertia=(1232.0, 1232.0, 2250.0), tm_mass=1.96, tm_side=0.046),
    # Taiji: LISA-like (assumption: no public mass budget); TM as LISA's
    "taiji": dict(sc_mass=2000.0, sc_inertia=(1232.0, 1232.0, 2250.0), tm_mass=1.96, tm_side=0.046),
}
_COMMON_PLANT = dict(mosa_inertia=10.0, mosa_stiffness=0.0, stiffness=(-1e-6, -1e-6, -1e-6),
                     rotational_stiffness=(-1e-6, -1e-6, -1e-6), crosstalk=1e-3)

#: Crossover frequencies of the default controllers [Hz] (docs/closed-loop.md derives them).
CROSSOVER_HZ = {"dragfree": 0.05, "suspension": 0.005, "attitude": 0.02, "attitude_z": 0.02, "mosa": 0.01,
                "tm_rotation": 0.005}


def _check(mission: str, defaults: str = DEFAULTS[0]) -> None:
    if mission not in MISSIONS:
        raise ValueError(unknown("closed_loop.mission", mission, MISSIONS, problem="is not a mission"))
    if defaults not in DEFAULTS:
        raise ValueError(unknown("closed_loop.defaults", defaults, DEFAULTS, problem="is not a defaults preset"))


def default_plant(mission: str, defaults: str = DEFAULTS[0]) -> dict:
    """The [closed_loop.plant] defaults of ``mission`` (keys of :class:`tqdyn.closedloop.plant.PlantParameters`
    that are not geometry): masses [kg], inertias [kg m^2], tm_side [m], stiffness [s^-2], crosstalk [1]; the
    single-spacecraft missions also tm2_stiffness [s^-2] and tm_separation [m] (their geometry).  ``defaults``:
    a preset of :data:`~tqdyn.scenario.closed_loop.DEFAULTS`; ``"published"`` differs from ``"v0.3"`` only in the
    actuation cross-talk (LISA Pathfinder's design value, :func:`tqdyn.closedloop.published.published_plant_values`;
    no published stiffness or spacecraft inertia of these missions was found, SOURCES.md)."""
    _check(mission, defaults)
    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_plant(mission)
    out = {**_COMMON_PLANT, **_PLANT[mission]}
    if defaults == "published":
        out.update(published_plant_values(mission))
    return out


def requirement(mission: str) -> AsdModel:
    """The mission's TM acceleration-noise requirement [m/s^2/Hz^1/2] (one-sided):
    TianQin 1e-15 sqrt(1 + 0.1 mHz/f); LISA 3e-15 sqrt(1 + (0.4 mHz/f)^2) sqrt(1 + (f/8 mHz)^4);
    Taiji 3e-15 with LISA's knees; LISA Pathfinder's on Delta g and TianQin-1's (none):
    :func:`tqdyn.closedloop.flown.flown_requirement`."""
    _check(mission)
    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_requirement(mission)
    if mission == "tianqin":
        return AsdModel(1e-15, ((1e-4, -0.5),), "m/s^2", "requirement")
    return AsdModel(3e-15, ((4e-4, -1.0), (8e-3, 2.0)), "m/s^2", "requirement")


def default_noise(mission: str, defaults: str = DEFAULTS[0]) -> dict:
    """{source: AsdModel} defaults of ``mission`` (one-sided ASDs; units of :data:`tqdyn.closedloop.loop.SOURCES`).
    ``defaults="published"``: the TM force noise, thrust, thruster-torque and DWS noise of
    :func:`tqdyn.closedloop.published.published_noise_levels` over v0.3's; ``"v0.3"``: version 0.3's values
    (the TM force noise equal to the requirement)."""
    _check(mission, defaults)
    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_noise(mission)
    out = _v03_noise(mission)
    if defaults == "published":
        a = _PLANT[mission]["tm_side"]
        for src, (level, knees) in published_noise_levels(mission).items():
            out[src] = AsdModel(level, knees, out[src].unit, out[src].name)
        tm = out["tm_force"]
        out["tm_torque"] = AsdModel(3.0 * tm.level / a, tm.knees, "rad/s^2", out["tm_torque"].name)
    return out


def _v03_noise(mission: str) -> dict:
    """Version 0.3's noise defaults of a constellation mission (SOURCES.md)."""
    req = requirement(mission)
    a = _PLANT[mission]["tm_side"]

    def m(name, level, knees=(), unit=""):
        return AsdModel(level, knees, unit, f"closed_loop.noise.{name}")

    return {
        "thruster_force": m("thruster_force", 1e-7, (), "N"),
        "thruster_gain": m("thruster_gain", 1e-3, (), "1"),
        "thruster_torque": m("thruster_torque", 1e-7, (), "N m"),
        "tm_force": m("tm_force", req.level, req.knees, "m/s^2"),
        # a force noise f on one face of a cube, lever a/2, inertia m a^2/6: angular 3 f/(m a)
        "tm_torque": m("tm_torque", 3.0 * req.level / a, req.knees, "rad/s^2"),
        "actuation_force": m("actuation_force", 1e-6, (), "1"),
        "actuation_torque": m("actuation_torque", 1e-6, (), "1"),
        "capacitive_translation": m("capacitive_translation", 2.4e-9, ((1e-3, -1.0),), "m"),
        "capacitive_rotation": m("capacitive_rotation", 1.7e-7, ((1e-3, -1.0),), "rad"),
        "interferometer": m("interferometer", 1e-12 if mission == "tianqin" else 3.5e-14,
                            ((2e-3, -2.0),), "m"),
        "dws": m("dws", 2e-10, ((2e-3, -2.0),), "rad"),
        "star_tracker": m("star_tracker", 1e-5, (), "rad"),
        "mosa_encoder": m("mosa_encoder", 1e-9, ((1e-3, -1.0),), "rad"),
        "mosa_actuator": m("mosa_actuator", 1e-9, (), "N m"),
    }


def default_controllers(mission: str, defaults: str = DEFAULTS[0]) -> dict:
    """{loop: Controller}: :func:`tqdyn.closedloop.controllers.lead_lag_pid` at :data:`CROSSOVER_HZ`
    (the same crossovers for the three constellation missions; the plants differ in masses and inertias only
    by the actuator conversion, which the controllers' acceleration commands absorb); the single-spacecraft
    missions' loops: :func:`tqdyn.closedloop.flown.flown_controllers`.  Both presets of ``defaults`` use
    these crossovers: no published bandwidth of a TianQin, LISA or Taiji loop was readable (SOURCES.md)."""
    _check(mission, defaults)
    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_controllers(mission)
    return {loop: lead_lag_pid(f, name=loop) for loop, f in CROSSOVER_HZ.items()}


def controller_from_keys(loop: str, zeros, poles, gain) -> Controller:
    """A :class:`Controller` of ``loop`` from scenario keys (zeros, poles in rad/s; gain)."""
    def flat(x):
        return tuple(tuple(float(a) for a in r) if isinstance(r, (list, tuple)) else float(r) for r in x)

    return Controller(zeros=flat(zeros), poles=flat(poles), gain=float(gain), name=loop)


def resolve(config, architecture: str) -> tuple[str, dict, dict, dict]:
    """(mission, plant dict, {loop: Controller}, {source: AsdModel}) of a
    :class:`tqdyn.scenario.closed_loop.ClosedLoopConfig` over the mission's defaults (the mission:
    ``closed_loop.mission`` or the spacecraft ``architecture``; the preset ``closed_loop.defaults``); a given noise ``level`` or ``knees``
    replaces that part of the default.  A ``closed_loop.scheme`` other than the mission's takes the
    project's lead-lag design for its loops (:data:`CROSSOVER_HZ`; 20 mHz for a loop it does not name).
    ValueError (one line) for ``tm_separation`` on a constellation mission."""
    mission = config.mission(architecture)
    raw = config.raw or {}
    defaults = str(raw.get("defaults", DEFAULTS[0]))
    plant = default_plant(mission, defaults)
    for k, v in raw.get("plant", {}).items():
        if k == "tm_separation" and mission not in SINGLE_SPACECRAFT_MISSIONS:
            raise ValueError(f"closed_loop.plant.tm_separation: {v!r} is not allowed for {mission!r}; allowed: "
                             f"the single-spacecraft missions ({', '.join(SINGLE_SPACECRAFT_MISSIONS)}) only (a "
                             "run's geometry comes from its spacecraft)")
        plant[k] = float(v) if PLANT_KEYS[k] == 1 else tuple(float(x) for x in v)
    scheme = config.scheme(architecture)
    ctl = default_controllers(mission, defaults)
    if set(ctl) != set(SCHEME_LOOPS[scheme]):       # another scheme than the mission's: its loops' defaults
        ctl = {loop: lead_lag_pid(CROSSOVER_HZ.get(loop, CROSSOVER_HZ["attitude"]), name=loop)
               for loop in SCHEME_LOOPS[scheme]}
    for loop, spec in raw.get("controllers", {}).items():
        ctl[loop] = controller_from_keys(loop, spec["zeros"], spec["poles"], float(spec["gain"]))
    noise = default_noise(mission, defaults)
    for src, spec in raw.get("noise", {}).items():
        base = noise[src]
        noise[src] = AsdModel(float(spec.get("level", base.level)),
                              tuple(tuple(float(x) for x in k) for k in spec.get("knees", base.knees)),
                              base.unit, base.name)
    return mission, plant, ctl, noise


def representative_working_point(mission: str, self_gravity=None) -> WorkingPoint:
    """A working point of ``mission`` from first principles: the central body's tide at the orbit
    (TianQin: GM_E/r^3 at r = 1e8 m; LISA/Taiji: GM_S/(1 au)^3) in a frame turning at the orbital rate
    about Z_S, theta = 60 deg, DC suspension from the self-gravity (default Table IV; the nominal
    scheme puts the differences dg_y, dg_z on the TMs: A_1 = -A_2 = (0, dg_y/(2 cos 30), dg_z/2)
    along Y_OA, Z), no drag-free DC acceleration along the sensitive axes.  SI units, S / OA_l frames.
    The single-spacecraft missions: :func:`tqdyn.closedloop.flown.flown_working_point` (``self_gravity``
    unused)."""
    from ..constellation.control import dragfree_general, oa_rotation
    from ..constellation.spacecraft import TABLE_IV_SELF_GRAVITY

    _check(mission)
    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_working_point(mission)
    gm, r = (3.986004415e14, 1e8) if mission == "tianqin" else (1.32712440041e20, 1.495978707e11)
    n2 = gm / r ** 3
    sg = TABLE_IV_SELF_GRAVITY if self_gravity is None else np.asarray(self_gravity)
    T = oa_rotation(math.pi / 3)
    g_S = np.einsum("lji,lj->li", T, sg)
    G, A = dragfree_general(g_S, math.pi / 3)
    return WorkingPoint(gamma=np.diag([2 * n2, -n2, -n2]), omega=np.array([0.0, 0.0, math.sqrt(n2)]),
                        omega_dot=np.zeros(3), theta=math.pi / 3, theta_dot=0.0, a_suspension=A,
                        alpha_suspension=np.zeros((2, 3)), a_dragfree=G, self_gravity=sg)


def representative_plant(mission: str, **over) -> PlantParameters:
    """The :class:`~tqdyn.closedloop.plant.PlantParameters` of ``mission``'s preset spacecraft at theta =
    60 deg with the mission's default plant values, ``over`` replacing some of them (keys of
    :func:`default_plant`, e.g. ``crosstalk=0.0``); a single-spacecraft mission's own geometry
    (:func:`tqdyn.closedloop.flown.flown_plant_parameters`)."""
    from ..constellation.spacecraft import Spacecraft

    if mission in SINGLE_SPACECRAFT_MISSIONS:
        return flown_plant_parameters(mission, {**default_plant(mission), **over})
    return plant_parameters({**default_plant(mission), **over}, Spacecraft.preset(mission), math.pi / 3)
