"""The single-spacecraft missions that flew, as closed-loop configurations: LISA Pathfinder (``lpf``, two test
masses on one axis) and TianQin-1 (``tianqin-1``, one inertial sensor).

Every number has its source in src/tqdyn/data/SOURCES.md (section "Closed-loop defaults: LISA Pathfinder and
TianQin-1"): a flight or design paper where one was found, *assumption* (with the reason) where none was.
None is fitted to the flight results the configurations are compared with (docs/closed-loop-validation.md).
Units: SI; ASDs one-sided (:mod:`tqdyn.closedloop.noise`).

**Static working points.**  The loop of a single spacecraft is built at a documented static working point,
without a trajectory file.  What the orbit contributes to the loop is the gravity-gradient tensor Gamma, the
body rate omega and the DC forces; Gamma and omega^2 enter beside the test-mass stiffness (~1e-6 s^-2):

* LISA Pathfinder near Sun-Earth L1 (1.5e9 m sunward of the Earth): the Sun's tide GM_S/r^3 = 4.1e-14 s^-2,
  the Earth's GM_E/d^3 = 1.2e-13 s^-2, the body turning once a year to keep the Sun in view
  (omega^2 = 4e-14 s^-2): together ~3e-13 s^-2, seven orders below the stiffness.  The Lissajous orbit
  around L1 changes these by factors of order one over months; the loop cannot see them.  A static point
  with the two tides along the Sun line (Z_S) serves.
* TianQin-1 in a 620-642 km orbit (r = 7.009e6 m): n^2 = GM_E/r^3 = 1.16e-6 s^-2, the order of the
  stiffness, in a frame turning at the orbital rate n (Earth-pointing).  For a circular orbit the tide in
  that frame is constant: a static point is exact up to the eccentricity (~1.6e-3, a relative change of
  5e-3 of Gamma).
"""

from __future__ import annotations

import math

import numpy as np

from .controllers import lead_lag_pid, pi_controller
from .noise import AsdModel
from .plant import PlantParameters, WorkingPoint, tm_stiffness

__all__ = ["FLOWN_CROSSOVER_HZ", "LPF_BAND_LOW_HZ", "flown_controllers", "flown_noise", "flown_plant",
           "flown_plant_parameters", "flown_requirement", "flown_working_point", "lpf_design", "published_delta_g",
           "published_flight_results", "rule_crossover"]

_GM_SUN, _GM_EARTH = 1.32712440041e20, 3.986004415e14      # m^3/s^2 (DE440 / EGM2008, as the force model)
_AU = 1.495978707e11                                        # m
_L1_FROM_EARTH = 1.5e9                                      # m, Sun-Earth L1 (ESA: 1.5 million km)
_TQ1_RADIUS = 6378137.0 + 631e3                             # m, mean of the 620 / 642 km perigee / apogee
_YEAR = 365.25 * 86400.0                                    # s

#: Plant values (scenario keys of [closed_loop.plant]; SOURCES.md).
_PLANT = {
    # inertia about X_S (the TM line), Y_S, Z_S (the Sun line) and the actuation cross-talk (worst case): the LPF
    # DFACS External ICD (S2-ASD-ICD-2011 Iss14) as typed in the LTPDA toolbox's ltp_parameters.m
    "lpf": dict(sc_mass=422.7, sc_inertia=(202.5, 209.7, 191.7), tm_mass=1.928, tm_side=0.046, mosa_inertia=1.0,
                mosa_stiffness=0.0, stiffness=(-1.3e-6, -1.3e-6, -1.3e-6), tm2_stiffness=(-2.0e-6, -2.0e-6, -2.0e-6),
                rotational_stiffness=(-1e-6, -1e-6, -1e-6), crosstalk=1.1e-3, tm_separation=0.376),
    "tianqin-1": dict(sc_mass=35.0, sc_inertia=(1.266, 1.240, 1.427), tm_mass=0.1, tm_side=0.03, mosa_inertia=1.0,
                      mosa_stiffness=0.0, stiffness=(-1e-6, -1e-6, -1e-6), rotational_stiffness=(-1e-6, -1e-6, -1e-6),
                      crosstalk=1e-3, tm_separation=0.0),
}
#: Crossover frequencies [Hz] of the default controllers (the project's lead-lag crossovers, CROSSOVER_HZ of
#: tqdyn.closedloop.missions; LISA Pathfinder's drag-free, attitude and guidance loops by :func:`lpf_design`;
#: TianQin-1's servo 10x its drag-free loop, which is a PI on the measured acceleration).
FLOWN_CROSSOVER_HZ = {
    "lpf": {"suspension": 0.005, "tm_rotation": 0.005},
    "tianqin-1": {"suspension": 0.5, "dragfree": 0.05, "attitude": 0.02, "tm_rotation": 0.5},
}
#: The lower edge of LISA Pathfinder's measurement band [Hz] (1-30 mHz), the guidance design's reference.
LPF_BAND_LOW_HZ = 1e-3


def flown_plant(mission: str) -> dict:
    """The [closed_loop.plant] values of ``lpf`` or ``tianqin-1`` (a copy)."""
    return dict(_PLANT[mission])


def _m(name, level, knees=(), unit=""):
    return AsdModel(level, knees, unit, f"closed_loop.noise.{name}")


def flown_noise(mission: str) -> dict:
    """{source: AsdModel} of ``lpf`` or ``tianqin-1`` (every source of :data:`tqdyn.closedloop.loop.SOURCES`;
    level 0 where the spacecraft has no such element)."""
    if mission == "lpf":
        dg_floor, tail = 1.74e-15, 1.1e-15            # Delta g: Brownian floor; 1/f tail at 1 mHz (per Delta g)
        a_tm = dg_floor / math.sqrt(2.0)              # split equally between the two TMs
        cap_x = math.sqrt(1.2e-9 * 2.4e-9)            # flight range 1.2-2.4 nm, 83-170 nrad: geometric means
        cap_r = math.sqrt(83e-9 * 170e-9)
        thr = 0.17e-6
        return {
            "thruster_force": _m("thruster_force", thr, (), "N"),
            "thruster_gain": _m("thruster_gain", 1e-3, (), "1"),
            "thruster_torque": _m("thruster_torque", thr * 1.0, (), "N m"),
            "tm_force": _m("tm_force", a_tm, ((1e-3 * tail / dg_floor, -1.0),), "m/s^2"),
            "tm_torque": _m("tm_torque", 3.0 * a_tm / 0.046, ((1e-3 * tail / dg_floor, -1.0),), "rad/s^2"),
            "actuation_force": _m("actuation_force", 1e-6, (), "1"),
            "actuation_torque": _m("actuation_torque", 1e-6, (), "1"),
            "capacitive_translation": _m("capacitive_translation", cap_x, ((1e-3, -1.0),), "m"),
            "capacitive_rotation": _m("capacitive_rotation", cap_r, ((1e-3, -1.0),), "rad"),
            "interferometer": _m("interferometer", 34.8e-15, (), "m"),
            "dws": _m("dws", 0.0, (), "rad"),
            "star_tracker": _m("star_tracker", 32.0 * math.pi / (180 * 3600), (), "rad"),
            "mosa_encoder": _m("mosa_encoder", 0.0, (), "rad"),
            "mosa_actuator": _m("mosa_actuator", 0.0, (), "N m"),
        }
    m_sc = _PLANT["tianqin-1"]["sc_mass"]
    return {
        "thruster_force": _m("thruster_force", 2e-9 * m_sc, (), "N"),
        "thruster_gain": _m("thruster_gain", 1e-3, (), "1"),
        "thruster_torque": _m("thruster_torque", 2e-9 * m_sc * 0.25, (), "N m"),
        "tm_force": _m("tm_force", 0.0, (), "m/s^2"),
        "tm_torque": _m("tm_torque", 0.0, (), "rad/s^2"),
        "actuation_force": _m("actuation_force", 1e-6, (), "1"),
        "actuation_torque": _m("actuation_torque", 1e-6, (), "1"),
        # the inertial sensor's 5e-12 m s^-2/Hz^1/2 at 0.1 Hz read as a displacement noise n: (2 pi f)^2 n
        "capacitive_translation": _m("capacitive_translation", 5e-12 / (2 * math.pi * 0.1) ** 2, (), "m"),
        "capacitive_rotation": _m("capacitive_rotation", 1.7e-7, ((1e-3, -1.0),), "rad"),
        "interferometer": _m("interferometer", 30e-12, (), "m"),
        "dws": _m("dws", 0.0, (), "rad"),
        "star_tracker": _m("star_tracker", 1e-5, (), "rad"),
        "mosa_encoder": _m("mosa_encoder", 0.0, (), "rad"),
        "mosa_actuator": _m("mosa_actuator", 0.0, (), "N m"),
    }


def rule_crossover(ratio: float, part: str, f_band: float = LPF_BAND_LOW_HZ) -> float:
    """The crossover f_c [Hz] of the project's lead-lag design (:func:`~tqdyn.closedloop.controllers.lead_lag_pid`)
    on the pure 1/s^2 plant at which |S(f_band)| (``part`` "S": a loop suppressing an actuator's noise) or
    |T(f_band)| (``part`` "T": a loop passing a sensor's noise) equals ``ratio`` (S = 1/(1 + L), T = L/(1 + L));
    scipy's brentq on log f_c."""
    from scipy.optimize import brentq

    s = 2j * math.pi * f_band

    def excess(log_fc):
        c = lead_lag_pid(10.0 ** log_fc)
        z, pl = np.array(c.zeros, dtype=complex), np.array(c.poles, dtype=complex)
        L = c.gain * np.prod(s - z) / np.prod(s - pl) / s ** 2
        return math.log(abs((1.0 if part == "S" else L) / (1.0 + L)) / ratio)

    lo, hi = (math.log10(f_band), math.log10(f_band) + 4.0) if part == "S" else (math.log10(f_band) - 6.0,
                                                                               math.log10(f_band))
    return 10.0 ** brentq(excess, lo, hi)


def lpf_design(noise: dict, plant: dict, f_band: float = LPF_BAND_LOW_HZ) -> dict:
    """Crossovers [Hz] of LISA Pathfinder's drag-free, attitude and guidance loops by one design rule (LISA
    Pathfinder's DFACS shields the drag-free TM over the measurement band from 1 mHz: ESA's DFACS page): at the
    band's lower edge ``f_band`` each actuator's or attitude sensor's noise through its loop equals the floor
    the loop cannot go below, the most demanding axis setting the loop's single controller:

    * drag-free: the thrusters' acceleration noise F/M through |S| equals, along X, TM 1's own acceleration
      noise (the spacecraft follows it), along Y and Z (2 pi f)^2 x the capacitive readout of the TMs' mean;
    * attitude: the thrusters' angular acceleration noise T/J_ii through |S| equals (2 pi f)^2 x the TMs'
      attitude readout (about X the mean rotation readout, about Y and Z sqrt(2) x the capacitive readout over
      the separation);
    * guidance: the star tracker's noise through |T| equals that attitude readout.

    ``noise`` {source: AsdModel}, ``plant`` the [closed_loop.plant] values.  The flight controllers are not in
    the sources used (SOURCES.md); this rule is tqdyn's, stated before any comparison."""
    w2 = (2 * math.pi * f_band) ** 2
    L = float(plant["tm_separation"])
    cap = float(noise["capacitive_translation"].asd(f_band))
    att = np.array([noise["capacitive_rotation"].asd(f_band) / math.sqrt(2.0),
                    math.sqrt(2.0) * cap / L, math.sqrt(2.0) * cap / L])
    a_thr = float(noise["thruster_force"].asd(f_band)) / float(plant["sc_mass"])
    floor_df = np.array([noise["tm_force"].asd(f_band), w2 * cap / math.sqrt(2.0), w2 * cap / math.sqrt(2.0)])
    a_tor = float(noise["thruster_torque"].asd(f_band)) / np.asarray(plant["sc_inertia"], dtype=np.float64)
    st = float(noise["star_tracker"].asd(f_band))
    return {"dragfree": rule_crossover(float(np.min(floor_df)) / a_thr, "S", f_band),
            "attitude": rule_crossover(float(np.min(w2 * att / a_tor)), "S", f_band),
            "guidance": rule_crossover(float(np.min(att)) / st, "T", f_band)}


def flown_controllers(mission: str) -> dict:
    """{loop: Controller} of ``lpf`` (lead-lag: suspension and TM rotation at :data:`FLOWN_CROSSOVER_HZ`, the
    drag-free, attitude and guidance loops at :func:`lpf_design` of the default noise and plant) or
    ``tianqin-1`` (lead-lag at :data:`FLOWN_CROSSOVER_HZ`; the drag-free loop a PI on the measured acceleration)."""
    cross = dict(FLOWN_CROSSOVER_HZ[mission])
    if mission == "lpf":
        cross.update(lpf_design(flown_noise("lpf"), _PLANT["lpf"]))
    out = {loop: lead_lag_pid(f, name=loop) for loop, f in cross.items()}
    if mission == "tianqin-1":
        out["dragfree"] = pi_controller(cross["dragfree"], name="dragfree")
    return out


def flown_requirement(mission: str) -> AsdModel:
    """LISA Pathfinder's requirement on Delta g, 3e-14 m s^-2/Hz^1/2 (1 + (f/3 mHz)^2) in 1-30 mHz (two knees
    of slope 1 make the factor exactly); TianQin-1: none found in the sources used (level 0)."""
    if mission == "lpf":
        return AsdModel(3e-14, ((3e-3, 1.0), (3e-3, 1.0)), "m/s^2", "requirement")
    return AsdModel(0.0, (), "m/s^2", "requirement")


def flown_working_point(mission: str) -> WorkingPoint:
    """The static working point (module docstring), S frame, SI: LISA Pathfinder with the Sun along +Z_S, the
    Earth along -Z_S, the body turning about Y_S once a year, the solar radiation force (19 uN, ESA) as the
    DC drag-free acceleration along -Z_S; TianQin-1 with Z_S radial, turning at the orbital rate about -Y_S."""
    if mission == "lpf":
        k = _GM_SUN / (_AU - _L1_FROM_EARTH) ** 3 + _GM_EARTH / _L1_FROM_EARTH ** 3
        omega = np.array([0.0, 2 * math.pi / _YEAR, 0.0])
        g = np.array([0.0, 0.0, -19e-6 / _PLANT["lpf"]["sc_mass"]])
    else:
        k = _GM_EARTH / _TQ1_RADIUS ** 3
        omega = np.array([0.0, -math.sqrt(k), 0.0])
        g = np.zeros(3)
    return WorkingPoint(gamma=k * np.diag([-1.0, -1.0, 2.0]), omega=omega, omega_dot=np.zeros(3), theta=0.0,
                        theta_dot=0.0, a_suspension=np.zeros((2, 3)), alpha_suspension=np.zeros((2, 3)), a_dragfree=g,
                        self_gravity=np.zeros((2, 3)))


def flown_plant_parameters(mission: str, plant: dict | None = None) -> PlantParameters:
    """The :class:`PlantParameters` of ``lpf`` (TM 1 at +tm_separation/2 X_S, TM 2 at -tm_separation/2, both
    sensitive axes X_S, housings fixed) or ``tianqin-1`` (one TM at the centre of mass) from the plant values
    ``plant`` (default :func:`flown_plant`)."""
    v = flown_plant(mission) if plant is None else plant
    half = 0.5 * float(v["tm_separation"])
    centres = np.array([[half, 0.0, 0.0], [-half, 0.0, 0.0]])
    return PlantParameters(sc_mass=float(v["sc_mass"]), sc_inertia=tuple(v["sc_inertia"]), tm_mass=float(v["tm_mass"]),
                           tm_side=float(v["tm_side"]), mosa_inertia=float(v["mosa_inertia"]),
                           mosa_stiffness=float(v["mosa_stiffness"]), stiffness=tm_stiffness(v),
                           rotational_stiffness=tm_stiffness(v, "rotational_stiffness"),
                           crosstalk=float(v["crosstalk"]), housing_centers=centres, lever_arms=np.zeros((2, 3)),
                           sensitive_axes=np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]),
                           n_tm=2 if mission == "lpf" else 1, mosa=False)


def published_flight_results() -> dict:
    """The published flight results typed from the papers (package data ``tqdyn/data/flight_results.toml``:
    every value with its paper and how it was read), as nested dicts."""
    import tomllib
    from importlib import resources

    return tomllib.loads((resources.files("tqdyn") / "data" / "flight_results.toml").read_text(encoding="utf-8"))


def published_delta_g(f, results: dict | None = None) -> np.ndarray:
    """LISA Pathfinder's published Delta g ASD [m s^-2/Hz^1/2] at ``f`` [Hz]: the quadrature sum of the
    published terms (:func:`published_flight_results` ``lpf.delta_g``): the Brownian floor (2018), the sub-mHz
    tail floor x (1 mHz/f) (2024) and the readout (2 pi f)^2 n (2016)."""
    d = (published_flight_results() if results is None else results)["lpf"]["delta_g"]
    f = np.asarray(f, dtype=np.float64)
    return np.sqrt(d["floor"] ** 2 + (d["tail_at_1mhz"] * 1e-3 / f) ** 2 + ((2 * math.pi * f) ** 2 * d["readout"]) ** 2)
