"""The paper's studies on LISA (and Taiji): the catalogue of ``tqdyn report --studies --mission lisa``.

The same machinery as the TianQin set (:mod:`tqdyn.workflows.studies`:
:class:`~tqdyn.workflows.studies.RunSpec`, :class:`~tqdyn.workflows.studies.Study`,
:func:`~tqdyn.workflows.studies.plan_studies`,
:func:`~tqdyn.workflows.studies.run_studies`), with the heliocentric
built-in scenarios as bases and overrides only:

* ``lisa`` -- coupled LISA: ESA's CReMA 2.0 initial states (2036-12-09 TDB),
  ESA's Newtonian force model, the LISA architecture (one TM per MOSA at
  ``tm_distance`` = 0.30 m on its optical axis, an assumption) and drag-free
  scheme, iterative (light-time-solved) pointing, ESA's -2..+2 nm/s^2 ramp
  as a common TM self-gravity along +X_S;
* ``lisa-gravity`` -- the same initial states and forces, point masses, no
  self-gravity; ``lisa-esa`` -- ESA's point-mass model with the ramp toward
  the centroid; ``lisa-kepler`` -- the equal-arm Keplerian design under the
  Sun alone (the geometry of the analytic estimate); ``taiji`` -- the
  Keplerian Taiji design (3e9 m arms).

Every run is one year (365 d; ESA's whole file span, 3926.5 d, for the
``esa-ramp-span`` study) at the scenarios' 6 h step with a row at every step
(1461 rows per year), integrated with DP87 as the TianQin set
(:data:`~tqdyn.workflows.studies.STUDY_INTEGRATOR`).  The "no self-gravity" coupled
runs switch ESA's ramp off with ``spacecraft.self_gravity_center=[0, 0]``
(the scenario key has no "off" value; zero adds nothing).

The S frame of a LISA satellite rotates once a year relative to the orbital
(radial / along-track / normal) frame (the cartwheel): no axis of S is the
flight direction, unlike TianQin's -Y_S (:data:`tqdyn.workflows.studies.FLIGHT_DIRECTION_S`).
The six common self-gravity runs push along +-X_S (toward / away from the
incentre: ESA's ramp direction), +-Y_S (in the plane, along the triangle's
rotation or against it) and +-Z_S (the constellation normal).

Units: durations in days (TDB, the heliocentric runs' time scale) since each
scenario's epoch; accelerations m/s^2 (in S for the self-gravity
overrides); everything else SI.
"""

from __future__ import annotations

from .studies import COMMON_SG, SG_DIRECTIONS, RunSpec, Study, _common

__all__ = [
    "ESA_SPAN_DAYS",
    "MISSION",
    "NO_RAMP",
    "QUICK_SCALE",
    "RUNS",
    "SG_DIRECTIONS",
    "STUDIES",
    "YEAR_DAYS",
]

#: Name of this study set (``tqdyn report --studies --mission lisa``).
MISSION = "lisa"
#: Span of one study run [days].
YEAR_DAYS = 365.0
#: ESA's CReMA 2.0 files' common span, rounded down to whole 6 h steps [days] (tests/test_esa_lisa.py).
ESA_SPAN_DAYS = 3926.5
#: Duration scale of ``--quick``: 365 d -> 4 d (16 rows at 6 h), 3926.5 d -> 43.6 d.
QUICK_SCALE = 1.0 / 90.0
#: The override that switches ESA's self-gravity ramp off in the coupled ``lisa`` scenario.
NO_RAMP = "spacecraft.self_gravity_center=[0, 0]"
#: Output decimation: a row at every 6 h step.
_EVERY = 1

_KEPLER_COUPLED = ("spacecraft.architecture=lisa", "spacecraft.self_gravity=off", "constellation.pointing=iterative",
                   "constellation.control=on")
_SUN_ONLY = ("forces.third_bodies=[]", "forces.relativity=false")

_AXIS_TEXT = {"+x": "+X_S (toward the incentre)", "-x": "-X_S (away from the incentre)",
              "+y": "+Y_S (in the plane)", "-y": "-Y_S (in the plane)",
              "+z": "+Z_S (the constellation normal)", "-z": "-Z_S"}


def _runs() -> dict[str, RunSpec]:
    y = YEAR_DAYS
    runs = [
        RunSpec("gravity-1y", "LISA pure gravity (point masses, ESA's initial states and forces, no self-gravity), "
                "1 yr at 6 h", (), y, _EVERY, "lisa-gravity"),
        RunSpec("dragfree-1y", "coupled LISA, iterative pointing, no self-gravity (ESA's ramp off), 1 yr at 6 h",
                (NO_RAMP,), y, _EVERY, "lisa"),
        RunSpec("dragfree-global-1y", "coupled LISA as dragfree-1y but global (instantaneous) pointing in the loop, "
                "1 yr at 6 h", (NO_RAMP, "constellation.pointing=global"), y, _EVERY, "lisa"),
        RunSpec("kepler-gravity-1y", "LISA Keplerian design (L = 2.5e9 m), Sun only, pure gravity, 1 yr at 6 h", (),
                y, _EVERY, "lisa-kepler"),
        RunSpec("kepler-dragfree-1y", "LISA Keplerian design, Sun only, coupled (architecture lisa, iterative "
                "pointing, no self-gravity), 1 yr at 6 h", _KEPLER_COUPLED, y, _EVERY, "lisa-kepler"),
        RunSpec("taiji-kepler-dragfree-1y", "Taiji Keplerian design (L = 3e9 m), Sun only, coupled, no self-gravity, "
                "1 yr at 6 h", _SUN_ONLY, y, _EVERY, "taiji"),
        RunSpec("taiji-dragfree-1y", "Taiji (built-in: Sun, planets, relativity), coupled, no self-gravity, "
                "1 yr at 6 h", (), y, _EVERY, "taiji"),
        RunSpec("table-iv-1y", "coupled LISA with the paper's Table IV per-TM self-gravity (TianQin's values, in "
                "OA_l), ramp off, 1 yr at 6 h", (NO_RAMP, "spacecraft.self_gravity=table-iv"), y, _EVERY, "lisa"),
        RunSpec("ramp-1y", "coupled LISA with ESA's -2..+2 nm/s^2 ramp as a common TM self-gravity along +X_S "
                "(the built-in lisa), 1 yr at 6 h", (), y, _EVERY, "lisa"),
        RunSpec("esa-1y", "ESA's point-mass model: the ramp toward the centroid (built-in lisa-esa), 1 yr at 6 h", (),
                y, _EVERY, "lisa-esa"),
        RunSpec("ramp-span", "coupled LISA with ESA's ramp (built-in lisa) over ESA's whole span, 3926.5 d at 6 h",
                (), ESA_SPAN_DAYS, _EVERY, "lisa"),
        RunSpec("esa-span", "ESA's point-mass model (lisa-esa) over ESA's whole span, 3926.5 d at 6 h", (),
                ESA_SPAN_DAYS, _EVERY, "lisa-esa"),
    ]
    for label, d in SG_DIRECTIONS.items():
        runs.append(RunSpec(f"sg{label}-1y", f"coupled LISA, common self-gravity {COMMON_SG:g} m/s^2 along "
                            f"{_AXIS_TEXT[label]}, ramp off, 1 yr at 6 h", (NO_RAMP, _common(d)), y, _EVERY, "lisa"))
    return {r.name: r for r in runs}


#: Every LISA study run by name.
RUNS: dict[str, RunSpec] = _runs()

_SG_RUNS = tuple(f"sg{label}-1y" for label in SG_DIRECTIONS)

#: The LISA studies by name (in report order); ``paper`` names the TianQin paper's counterpart.
STUDIES: dict[str, Study] = {s.name: s for s in [
    Study("estimate", "Nominal drag-free and suspension accelerations vs the first-order analytic estimate",
          "Sec. V.A / Fig. 7 (TianQin)",
          ("kepler-dragfree-1y", "taiji-kepler-dragfree-1y", "taiji-dragfree-1y", "dragfree-1y"),
          "max |G| and max suspension component of the Keplerian designs (Sun only) against "
          "alpha n^2 d x (4.12, 2.38) (docs/lisa-coupled.md); ESA's orbit and Taiji's full model for comparison"),
    Study("dragfree-deviation", "Drag-free vs pure-gravity orbits over one year", "Sec. V.A (TianQin)",
          ("gravity-1y", "dragfree-1y", "kepler-gravity-1y", "kepler-dragfree-1y"),
          "orbit deviation (radial / along-track / cross-track) and its secular prediction from G"),
    Study("control", "Nominal suspension and drag-free accelerations without and with self-gravity",
          "Figs. 7, 8 (TianQin)", ("dragfree-1y", "table-iv-1y", "ramp-1y"),
          "no self-gravity; the paper's Table IV per-TM values (TianQin's, as a stand-in); ESA's ramp through the TMs"),
    Study("common-self-gravity", "Common self-gravity 1e-9 m/s^2 along +-x, +-y, +-z of S over one year",
          "Sec. V.B.2 (TianQin)", ("dragfree-1y", *_SG_RUNS),
          "arm lengths, arm-length rates and corner angles vs the no-self-gravity run, with the Hill estimate"),
    Study("pointing", "Pointing laws at LISA's 8.3 s light time: global and Taylor vs iterative",
          "Fig. 5 (TianQin)", ("dragfree-1y", "dragfree-global-1y"),
          "beam direction and MOSA angle errors along the 1-year orbit; global pointing in the loop"),
    Study("esa-ramp", "ESA's self-gravity ramp: through the TMs (coupled) vs toward the centroid vs ESA's files",
          "docs/lisa-orbits.md", ("ramp-1y", "esa-1y", "dragfree-1y"),
          "the bisector (incentre) vs the centroid direction, the nominal G, the beams' aberration"),
    Study("esa-ramp-span", "ESA's ramp over ESA's whole span (10.75 yr)", "docs/lisa-orbits.md",
          ("ramp-span", "esa-span"), "coupled lisa vs lisa-esa vs ESA's files over 3926.5 d"),
]}
