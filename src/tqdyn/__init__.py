"""tqdyn: coupled orbit-attitude dynamics of drag-free gravitational-wave
constellations (TianQin by default) in extended (double-double) precision.

The front door (:mod:`tqdyn.api`)::

    import tqdyn
    traj = tqdyn.propagate("tianqin", {"run.duration": "2d"})   # in memory
    ds = traj.to_xarray()
    asd = tqdyn.range_asd(tqdyn.light_travel_times(traj), "13")

:func:`load_scenario`, :func:`builtin_scenarios`, :func:`propagate`,
:func:`run`, :func:`open_trajectory`, :func:`light_travel_times`,
:func:`range_asd`, :func:`requirement_asd`, :func:`breathing_angles`, the closed loop
(:func:`closed_loop_model`, :func:`closed_loop_budget`, :func:`closed_loop_timeseries`,
:func:`open_closed_loop`), orbit determination in memory (:func:`od_simulate`, :func:`od_fit`,
:func:`od_covariance`, :func:`open_measurements`, :func:`open_od_estimate`, :func:`plot_od_residuals`) and the
classes :class:`Scenario`, :class:`Trajectory`, :class:`LightTravelTimes`.
The readers are named ``open_*``; their former names ``read_closed_loop`` and
``read_od_estimate`` are kept as aliases.  They are imported on first use, so ``import tqdyn`` stays cheap.
"""

from ._version import __version__

__all__ = ["__version__", "LightTravelTimes", "RunSummary", "Scenario", "ScenarioError", "Trajectory",
           "breathing_angles", "builtin_scenarios", "closed_loop_budget", "closed_loop_model", "closed_loop_timeseries",
           "light_travel_times", "load_scenario", "od_covariance", "od_fit", "od_simulate", "open_closed_loop",
           "open_measurements", "open_od_estimate", "open_trajectory", "plot_od_residuals", "propagate", "range_asd",
           "read_closed_loop", "read_od_estimate", "requirement_asd", "run"]


def __getattr__(name):
    if name in __all__:
        from . import api

        return getattr(api, name)
    raise AttributeError(f"module 'tqdyn' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
