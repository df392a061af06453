"""The closed loop of a coupled run (physics, no I/O): each spacecraft's drag-free, suspension, attitude,
MOSA and TM-rotation loops linearised around the run's working point, their noise budget and their
time series (docs/closed-loop.md).

Modules: :mod:`~tqdyn.closedloop.model` (:func:`closed_loop_model`: the loops of a run, per satellite
and frozen-coefficient segment), :mod:`~tqdyn.closedloop.plant` (the linearised plant),
:mod:`~tqdyn.closedloop.working_point` (its frozen coefficients from a run's arrays),
:mod:`~tqdyn.closedloop.controllers`, :mod:`~tqdyn.closedloop.noise` (one-sided ASD models),
:mod:`~tqdyn.closedloop.loop` (the named interconnection), :mod:`~tqdyn.closedloop.missions` (the
defaults of TianQin, LISA and Taiji), :mod:`~tqdyn.closedloop.budget` (frequency domain: budgets,
margins), :mod:`~tqdyn.closedloop.simulate` (time domain), :mod:`~tqdyn.closedloop.synthesis` (how
the time series realise the budget), :mod:`~tqdyn.closedloop.one_dof` (the
one-axis reference loop), :mod:`~tqdyn.closedloop.schemes` (the single-spacecraft control schemes),
:mod:`~tqdyn.closedloop.flown` (LISA Pathfinder and TianQin-1 as configurations, their static working
points), :mod:`~tqdyn.closedloop.flight_observables` (Delta g, the six-DOF stability, the measured
residual acceleration), :mod:`~tqdyn.closedloop.hinf` (the H-infinity design over a spacecraft's whole
plant, ``closed_loop.design = "hinf"``) and :mod:`~tqdyn.closedloop.robust` (a design's robustness over the
plant's uncertain parameters).  The loop and noise-source tables are the scenario's
(:data:`tqdyn.scenario.closed_loop.LOOPS`, :data:`tqdyn.scenario.closed_loop.SOURCES`).

The public names below are imported from their modules on first use (python-control is slow to
import), so that ``import tqdyn.closedloop.noise`` stays cheap.
"""

import importlib

#: Public name -> the module that defines it.
_HOME = {
    "ClosedLoopError": "model", "ClosedLoopModel": "model", "closed_loop_model": "model",
    "static_closed_loop_model": "model",
    "delta_g_budget": "flight_observables", "stability_budget": "flight_observables",
    "residual_acceleration_budget": "flight_observables",
    "ClosedLoop": "loop", "OUTPUTS": "loop", "SOURCES": "loop", "build_closed_loop": "loop", "output_names": "loop",
    "DesignError": "budget", "check_stable": "budget", "closed_loop_response": "budget", "loop_margins": "budget",
    "noise_budget": "budget",
    "Controller": "controllers", "LOOPS": "controllers", "lead_lag_pid": "controllers",
    "AsdModel": "noise",
    "PlantParameters": "plant", "WorkingPoint": "plant", "plant_parameters": "plant",
    "MISSIONS": "missions", "CONSTELLATION_MISSIONS": "missions", "SINGLE_SPACECRAFT_MISSIONS": "missions",
    "default_controllers": "missions", "default_noise": "missions", "default_plant": "missions",
    "representative_plant": "missions", "representative_working_point": "missions", "requirement": "missions",
    "working_points": "working_point",
    "series_psd": "synthesis",
    "HinfController": "hinf", "synthesise": "hinf", "UNCERTAINTY": "robust",
}

__all__ = sorted(_HOME)


def __getattr__(name):
    if name in _HOME:
        return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
