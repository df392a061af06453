"""Robustness of a closed-loop design: its plant's uncertain parameters drawn at random, the design kept
(docs/closed-loop.md#robustness-monte-carlo).

:data:`UNCERTAINTY` lists the parameters drawn, their distributions and spreads; :func:`draw` draws them,
:func:`evaluate` builds the closed loop of one draw with the nominal design's controllers (the per-loop ones
or a :class:`tqdyn.closedloop.hinf.HinfController`) and returns its stability, its loop-at-a-time margins and
its requirement ratio.  The campaign (many draws on Dask, the xarray dataset) is
:mod:`tqdyn.workflows.closed_loop_mc`; this module is physics only.

Units: SI; stiffness in s^-2 (x'' = -k x), housing offsets in m (S frame), gains and ratios dimensionless,
margins in degrees (phase) and factors (gain).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .budget import grid_margins, loop_gains, noise_budget
from .loop import build_closed_loop
from .plant import PlantParameters, WorkingPoint

__all__ = ["ACTUATOR_INPUTS", "MC_BAND_HZ", "UNCERTAINTY", "draw", "evaluate", "perturbed_plant"]

#: The plant inputs whose actuator gain is drawn (thrust, thruster torque, electrostatic force and torque on
#: both TMs, MOSA actuators), names of :mod:`tqdyn.closedloop.plant`.
ACTUATOR_INPUTS = tuple([f"F[{i}]" for i in range(3)] + [f"T[{i}]" for i in range(3)]
                        + [f"f{l}[{i}]" for l in (1, 2) for i in range(3)]
                        + [f"t{l}[{i}]" for l in (1, 2) for i in range(3)] + ["tm[0]", "tm[1]"])

#: The uncertain parameters: name -> (distribution, spread, source).  Every spread is an assumption of tqdyn
#: (no public budget gives the missions' tolerances), chosen as an order of magnitude and stated here and in
#: docs/closed-loop.md: the Monte Carlo measures how a design degrades over such a spread, not a mission's odds.
UNCERTAINTY = {
    "stiffness": ("normal, relative", 0.3,
                  "each TM and axis: k (1 + 0.3 n); the TM's electrostatic and gravitational stiffness is known to a "
                  "few tens of percent before flight (assumption)"),
    "rotational_stiffness": ("normal, relative", 0.3, "each TM and axis, as the stiffness (assumption)"),
    "crosstalk": ("log-normal", math.log(3.0),
                  "the actuation cross-talk c exp(ln 3 n): within a factor 3 (one sigma) of the nominal (assumption)"),
    "housing_offset": ("normal, absolute [m]", 1e-3,
                       "each housing's centre, each S axis: 1 mm (integration tolerance; assumption)"),
    "actuator_gain": ("normal, relative", 0.05,
                      "each actuator axis of ACTUATOR_INPUTS: 1 + 0.05 n, an uncalibrated scale factor (assumption)"),
}
#: The band of the requirement ratio [Hz] (the report's, tqdyn.workflows.report.closed_loop) and its grid points.
MC_BAND_HZ = (1e-4, 1.0)
_N_BAND = 60
#: The loop-gain grid of the margins: [Hz], [Hz], points.
_MARGIN_GRID = (1e-6, 10.0, 600)


def draw(rng: np.random.Generator, n: int) -> dict:
    """``n`` draws of the standard variates of :data:`UNCERTAINTY` (unit normals): {name: array}, shapes
    stiffness, rotational_stiffness, housing_offset (n, 2, 3); crosstalk (n,); actuator_gain (n, 20)."""
    return {"stiffness": rng.standard_normal((n, 2, 3)), "rotational_stiffness": rng.standard_normal((n, 2, 3)),
            "crosstalk": rng.standard_normal(n), "housing_offset": rng.standard_normal((n, 2, 3)),
            "actuator_gain": rng.standard_normal((n, len(ACTUATOR_INPUTS)))}


def perturbed_plant(p: PlantParameters, z: dict, k: int) -> tuple[PlantParameters, dict, dict]:
    """(plant, actuator gains {input: factor}, the drawn values) of draw ``k`` of the variates ``z``
    (:func:`draw`) around the nominal plant ``p``.  The values: stiffness, rotational_stiffness (2, 3)
    [s^-2], crosstalk [1], housing_offset (2, 3) [m], actuator_gain (20,) [1]."""
    s = UNCERTAINTY
    vals = {"stiffness": np.asarray(p.stiffness) * (1.0 + s["stiffness"][1] * z["stiffness"][k]),
            "rotational_stiffness": np.asarray(p.rotational_stiffness)
            * (1.0 + s["rotational_stiffness"][1] * z["rotational_stiffness"][k]),
            "crosstalk": float(p.crosstalk * math.exp(s["crosstalk"][1] * z["crosstalk"][k])),
            "housing_offset": s["housing_offset"][1] * z["housing_offset"][k],
            "actuator_gain": 1.0 + s["actuator_gain"][1] * z["actuator_gain"][k]}
    q = dataclasses.replace(p, stiffness=vals["stiffness"], rotational_stiffness=vals["rotational_stiffness"],
                            crosstalk=min(vals["crosstalk"], 0.5),
                            housing_centers=np.asarray(p.housing_centers) + vals["housing_offset"],
                            lever_arms=np.asarray(p.lever_arms) + vals["housing_offset"])
    return q, dict(zip(ACTUATOR_INPUTS, vals["actuator_gain"])), vals


def evaluate(p: PlantParameters, wp: WorkingPoint, controllers, noise: dict, requirement,
             attitude_z_sensor: str = "dws", scheme: str = "constellation", actuator_gain: dict | None = None) -> dict:
    """The closed loop of ``p`` at ``wp`` with the design ``controllers`` ({loop: Controller} or a
    multivariable controller), under the ``noise`` ({source: AsdModel}): ``stable`` (every pole but the orbit
    displacement's with Re <= 1e-9 x max(1, |poles|)), ``max_pole_re`` [1/s] (of those), ``phase_margin_min``
    [deg], ``gain_margin_lower_max`` (the largest factor by which some channel's gain may fall; 0: none),
    ``gain_margin_upper_min`` (the smallest by which one may rise; inf: none) over the channels
    (:func:`tqdyn.closedloop.budget.grid_margins`), and ``requirement_ratio`` (the largest ratio of either TM's
    residual acceleration to the ``requirement`` (AsdModel) over :data:`MC_BAND_HZ`) with its frequency
    ``ratio_f_hz`` [Hz].  Margins and ratio are nan for an unstable loop."""
    cl = build_closed_loop(p, wp, controllers, attitude_z_sensor, scheme, actuator_gain)
    sys = cl.system
    keep = [k for k, s in enumerate(sys.state_labels) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
    ev = np.linalg.eigvals(sys.A[np.ix_(keep, keep)])
    re = float(np.max(ev.real))
    out = {"stable": bool(re <= 1e-9 * max(1.0, float(np.max(np.abs(ev))))), "max_pole_re": re,
           "phase_margin_min": math.nan, "gain_margin_lower_max": math.nan, "gain_margin_upper_min": math.nan,
           "requirement_ratio": math.nan, "ratio_f_hz": math.nan}
    if not out["stable"]:
        return out
    fm = np.logspace(math.log10(_MARGIN_GRID[0]), math.log10(_MARGIN_GRID[1]), _MARGIN_GRID[2])
    m = grid_margins(loop_gains(cl, fm)[1], fm)
    f = np.logspace(math.log10(MC_BAND_HZ[0]), math.log10(MC_BAND_HZ[1]), _N_BAND)
    b, _src = noise_budget(cl, noise, f, outputs=["tm1_acceleration", "tm2_acceleration"])
    ratio = np.max(np.sqrt(np.sum(b ** 2, axis=1)), axis=0) / requirement.asd(f)
    k = int(np.argmax(ratio))
    out.update(phase_margin_min=float(np.min(m["phase_margin"])),
               gain_margin_lower_max=float(np.max(m["gain_margin_lower"])),
               gain_margin_upper_min=float(np.min(m["gain_margin_upper"])),
               requirement_ratio=float(ratio[k]), ratio_f_hz=float(f[k]))
    return out
