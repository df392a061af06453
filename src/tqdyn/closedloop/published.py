"""The ``"published"`` closed-loop defaults of TianQin, LISA and Taiji: the numbers of the v0.3 defaults replaced
where a published design or flight paper gives one, each with its source (``closed_loop.defaults``).

Every entry of :data:`PUBLISHED` is (value, source); the sources were read at the level the text says (for most,
the abstract: the papers' bodies, tables and figures were not available), and src/tqdyn/data/SOURCES.md
("Closed-loop defaults") lists the same table.  What no source read here gives stays at the v0.3 value
(:mod:`tqdyn.closedloop.missions`, marked *assumption* there); no value is chosen to make a budget pass.
docs/closed-loop-validation.md (section 7) evaluates both presets against the requirements.

Units: SI; ASDs one-sided, ``(level [unit/Hz^1/2], knees ((f [Hz], slope), ...))`` as
:class:`tqdyn.closedloop.noise.AsdModel`.
"""

from __future__ import annotations

import math

__all__ = ["LPF_DG_FLOOR", "LPF_DG_TAIL_1MHZ", "PUBLISHED", "PUBLISHED_PLANT", "THRUSTER_LEVER_M",
           "published_noise_levels", "published_plant_values"]

#: LISA Pathfinder's differential acceleration Delta g: the Brownian floor [m s^-2/Hz^1/2] (Armano et al. 2018,
#: PRL 120, 061101, abstract: 1.74 fm s^-2/Hz^1/2 above 2 mHz) and the 1/f tail at 1 mHz (Armano et al. 2024,
#: arXiv:2405.05207, abstract: 1.1 fm s^-2/Hz^1/2 at 1 mHz rising as 1/f).
LPF_DG_FLOOR = 1.74e-15
LPF_DG_TAIL_1MHZ = 1.1e-15
#: The lever arm [m] that turns a thrust noise into a torque noise (v0.3's rule; no spacecraft thruster
#: layout was found: an assumption, stated in SOURCES.md).
THRUSTER_LEVER_M = 1.0

_TM_FORCE = ((LPF_DG_FLOOR / math.sqrt(2.0), ((1e-3 * LPF_DG_TAIL_1MHZ / LPF_DG_FLOOR, -1.0),)),
             "LISA Pathfinder in flight, per test mass: Delta g's floor 1.74 fm s^-2/Hz^1/2 (Armano et al. 2018, PRL "
             "120, 061101, abstract) and its 1.1 fm s^-2/Hz^1/2 (1 mHz/f) tail (Armano et al. 2024, arXiv:2405.05207, "
             "abstract) split equally between the two TMs: 1.23 fm s^-2/Hz^1/2, knee 0.63 mHz, slope -1.  The "
             "flight-demonstrated level, used as the TM force-noise allocation (no mission's own allocation table "
             "was readable)")
_LPF_THRUST = (0.17e-6, "LISA Pathfinder cold-gas thrusters in flight, ~0.17 uN/Hz^1/2 flat, 'compatible with the "
                        "noise budget for the upcoming LISA' (Armano et al. 2019, PRD 99, 122003, abstract)")
_TQ1_THRUST = (0.3e-6, "TianQin-1's micro-Newton thrusters in orbit, 0.3 uN/Hz^1/2 at 0.1 Hz (Luo et al. 2020, CQG 37, "
                       "185013, abstract); taken flat (the spectrum is not in the abstract)")

_DWS = ((7e-8 / 335.0, ()),
        "the LISA consortium's instrument simulator, lisainstrument 2.3.0 (PyPI), Instrument default dws_asds = "
        "7e-8/335 = 2.09e-10 rad/Hz^1/2, flat ('DWS measurement noise'; the simulator's defaults follow the LISA "
        "performance model); TianQin and Taiji: LISA's, as v0.3 applied LISA's order to them (no value of their own "
        "was found)")
_CROSSTALK = (1.1e-3, "LISA Pathfinder's design value, the capacitive actuation cross-talk translation -> "
                      "translation (worst case) of the LPF DFACS External ICD (S2-ASD-ICD-2011 Iss14), as typed in "
                      "the LPF data-analysis toolbox LTPDA (GitHub gulbrillo/LTPDA, matlab/classes/@plist/"
                      "ltp_parameters.m; a secondary source quoting the ICD); the flown mission's design value, used "
                      "for lack of a LISA, TianQin or Taiji value")

#: mission -> {noise source: ((level, knees), source text)} for the sources whose published value replaces v0.3's
#: (``thruster_force`` as a level only; ``thruster_torque`` and ``tm_torque`` follow from these,
#: :func:`published_noise_levels`).
PUBLISHED = {
    "tianqin": {"tm_force": _TM_FORCE, "thruster_force": _TQ1_THRUST, "dws": _DWS},
    "lisa": {"tm_force": _TM_FORCE, "thruster_force": _LPF_THRUST, "dws": _DWS},
    "taiji": {"tm_force": _TM_FORCE,
              "thruster_force": (_LPF_THRUST[0], _LPF_THRUST[1] + "; Taiji: LISA's (no Taiji thrust-noise value "
                                                                   "was found)"),
              "dws": _DWS},
}
#: mission -> {[closed_loop.plant] key: (value, source text)} for the plant values whose published value replaces
#: v0.3's (the same for the three missions).
PUBLISHED_PLANT = {m: {"crosstalk": _CROSSTALK} for m in ("tianqin", "lisa", "taiji")}


def published_noise_levels(mission: str) -> dict:
    """{source: (level, knees)} of the published preset that differ from v0.3 for a constellation ``mission``:
    ``tm_force`` [m/s^2], ``thruster_force`` [N], the derived ``thruster_torque`` [N m] (the thrust noise at
    :data:`THRUSTER_LEVER_M`) and ``dws`` [rad].  ``tm_torque`` follows ``tm_force`` by the v0.3 rule (missions.py)."""
    p = PUBLISHED[mission]
    (a_level, a_knees), _ = p["tm_force"]
    thrust, _ = p["thruster_force"]
    return {"tm_force": (a_level, a_knees), "thruster_force": (thrust, ()),
            "thruster_torque": (thrust * THRUSTER_LEVER_M, ()), "dws": p["dws"][0]}


def published_plant_values(mission: str) -> dict:
    """{[closed_loop.plant] key: value} of the published preset that differ from v0.3 for a constellation
    ``mission``: ``crosstalk`` [1]."""
    return {k: v for k, (v, _src) in PUBLISHED_PLANT[mission].items()}
