"""Orbit determination in memory: the jobs of ``tqdyn.od_simulate | od_fit | od_covariance``.

* :func:`od_simulate`: a run (a trajectory in memory, a run file, or a scenario: its
  ``[accelerations]`` and initial states are the truth) and a tracking plan -> seeded measurements,
  an ``xarray.Dataset`` (:func:`measurements_dataset`; no file);
* :func:`od_fit`: a scenario, measurements (that Dataset, or :func:`open_measurements` of a TDM)
  and the tracking -> the batch least-squares estimate, an ``xarray.Dataset``
  (:func:`estimate_dataset`);
* :func:`od_covariance`: a scenario and a tracking plan -> the predicted covariance, an
  ``xarray.Dataset`` (:func:`covariance_dataset`).

Their keyword arguments are typed and checked: an unknown keyword is a ``TypeError``, a bad value a
``ValueError``, each one line naming the argument and what is allowed (:func:`checked_keywords`).
The file commands (:mod:`tqdyn.workflows.od`: ``tqdyn od simulate | fit | covariance``) are the
cores :func:`simulate`, :func:`fit` and :func:`covariance` with a file read before and written after
(``cli=True`` names the arguments as command-line options in the error lines).

Measurements Dataset (dimension ``row``, one scalar measurement each, ordered by time): coordinates
``t`` [s since the scenario epoch, the run's time scale: TT geocentric, TDB heliocentric], ``type``,
``sat`` (the satellite's index), ``peer`` (station, GNSS transmitter or the other satellite's index);
variables ``value`` and ``sigma`` [m, m/s for range rates]; attributes ``epoch`` (t = 0, with its
scale), ``time_scale``, ``satellite_names`` (comma-separated) and the plan as the TDM header records
it (``tracking``, ``arc_s``, ``interval_s``, ``seed``, ``scenario``, and ``bias``, ``stations``,
``sp3`` when given).  Units SI throughout.
"""

from __future__ import annotations

import functools
import inspect
import json
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._choices import unknown
from . import od as _od

__all__ = ["Fitted", "Simulated", "checked_keywords", "covariance", "covariance_dataset", "estimate_dataset", "estimate_file_of",
           "fit",
           "measurements_dataset", "measurements_fields", "od_covariance", "od_fit", "od_simulate",
           "open_measurements", "simulate"]

_FIELDS = ("t", "type", "sat", "peer", "value", "sigma")
#: Options of :func:`tqdyn.od.estimator.estimate` that :func:`od_fit` passes on, with their checks.
ESTIMATOR_OPTIONS = {"step_tol": "a number > 0", "max_iterations": "an integer >= 1",
                     "max_condition": "a number > 1", "min_kept_fraction": "a number in (0, 1]",
                     "max_edit_passes": "an integer >= 0"}


def checked_keywords(func):
    """``func`` refusing an unknown keyword argument in one line (``TypeError`` naming it, the
    closest keyword and the allowed ones) instead of Python's bare message."""
    sig = inspect.signature(func)
    names = [p.name for p in sig.parameters.values()
             if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and not p.name.startswith("_")]

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        for key in kwargs:
            if key not in names:
                raise TypeError(unknown(f"{func.__name__}()", key, names, "docs/python.md",
                                        problem="is not a keyword argument", noun="keywords", quote=repr))
        return func(*args, **kwargs)

    return wrapper


def _opt(name: str, cli: bool) -> str:
    """The name of an argument in an error line: ``--a-priori`` on the command line, ``a_priori`` here."""
    return "--" + name.replace("_", "-") if cli else name


def _problem():
    return _od._problem()


def _seed(seed, cli: bool) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"{_opt('seed', cli)}: {seed!r} is not allowed; allowed: an integer >= 0")
    return int(seed)


def _override_list(overrides) -> list[str]:
    """``{"run.duration": "2d"}``, ``["run.duration=2d"]`` or one string -> ``["run.duration=2d", ...]``."""
    from collections.abc import Mapping

    from ..scenario.toml_text import toml_value

    if isinstance(overrides, str):
        return [overrides]
    if isinstance(overrides, Mapping):
        return [f"{key}={toml_value(value)}" for key, value in overrides.items()]
    return list(overrides or ())


def _load(source, overrides):
    """(scenario, notes, label) of a trajectory in memory (its recorded scenario), a Scenario, a run
    file, a built-in name or a TOML path, with ``overrides`` (:func:`_override_list`)."""
    from ..scenario import Scenario, loads_scenario

    over = _override_list(overrides)
    if isinstance(source, Scenario):
        scen = loads_scenario(source.to_toml(), over, source=f"scenario {source.name!r}") if over else source
        return scen, (), source.name
    text = getattr(source, "scenario_toml", None)
    if text is not None and getattr(source, "path", None) is None:   # a trajectory propagated in memory
        return loads_scenario(text, over, source="trajectory"), (), "trajectory"
    if getattr(source, "path", None) is not None:                    # a trajectory read from its file
        source = source.path
    return _od._scenario(source, over)


def _groups(estimate, consider, a_priori, groups, cli: bool) -> tuple:
    """(estimated groups, considered groups, {group: a priori sigma}) of the arguments, each falling back to
    ``groups`` (a Tracking's ``(estimate, consider, a_priori_sigma)``, or None) when not given; ValueError
    (one line) for a considered group without an a priori sigma."""
    from ..od.tracking import check_consider

    est_names = _od.parse_names(estimate, _opt("estimate", cli))
    con_names = _od.parse_names(consider, _opt("consider", cli))
    sig = _od.parse_a_priori(a_priori, _opt("a_priori", cli))
    if groups is not None:
        est_names, con_names = est_names or tuple(groups[0] or ()), con_names or tuple(groups[1])
        sig = sig or dict(groups[2] or {})
    check_consider(con_names, sig, _opt("consider", cli), _opt("a_priori", cli) + " {g}=SIGMA")
    return est_names, con_names, sig


def _plan(tracking, arc, interval, stations, cli: bool):
    """(kinds, arc_s, interval_s, stations, groups) of ``tracking``: kinds (``"gnss,slr"`` or a
    sequence) with ``arc`` [s or "7d"], or a ``tqdyn.od.problem.Tracking`` (then without arc,
    interval, stations); groups: the plan's (estimate, consider, a_priori_sigma) or None."""
    p = _problem()
    if isinstance(tracking, p.Tracking):
        for name, v in (("arc", arc), ("interval", interval), ("stations", stations)):
            if v is not None:
                raise ValueError(f"{_opt(name, cli)}: {v!r} is given with a Tracking plan, which has its own; "
                                 f"allowed: one of the two")
        groups = (tracking.estimate, tracking.consider, tracking.a_priori_sigma)
        return tuple(tracking.kinds), float(tracking.arc_s), float(tracking.interval_s), tracking.stations, groups
    kinds = _od.parse_tracking(tracking, _opt("tracking", cli))
    if arc is None:
        raise ValueError(f"{_opt('arc', cli)}: missing; allowed: seconds, or with a unit (7d, 12h, 30min), or a "
                         "tqdyn.od.problem.Tracking as tracking")
    interval_s = None if interval is None else _od.parse_arc(interval, _opt("interval", cli))
    names = _od.parse_names(stations, _opt("stations", cli))
    return kinds, _od.parse_arc(arc, _opt("arc", cli)), interval_s, (names or None), None


@dataclass(frozen=True)
class Simulated:
    """What :func:`simulate` made: ``meas`` (``tqdyn.od.problem.Measurements``), the scenario, the
    tracking plan, ``info`` (the TDM header's keys, in order) and notes (a run file's warnings)."""

    meas: object
    scenario: object
    tracking: object
    info: dict
    notes: tuple


def simulate(source, tracking, arc=None, *, seed: int = 0, interval=None, stations=None, bias=None, sp3=None,
             overrides=(), progress: Callable[[str], None] | None = None, ready: Callable[[], None] | None = None,
             cli: bool = False) -> Simulated:
    """Simulate the measurements of ``tracking`` over ``arc`` on ``source``'s scenario with noise seed
    ``seed`` (:func:`od_simulate`'s arguments).  ``ready`` is called once the arguments are checked,
    before the scenario is loaded (the file command checks its files there)."""
    say = progress or (lambda stage: None)
    kinds, arc_s, interval_s, station_names, _ = _plan(tracking, arc, interval, stations, cli)
    biases = _od.parse_biases(bias, _opt("bias", cli))
    sp3_paths = _od._sp3_paths(sp3, kinds)
    seed = _seed(seed, cli)
    if ready is not None:
        ready()
    scen, notes, label = _load(source, overrides)
    _od._check_arc(scen, arc_s, label)
    p = _problem()
    plan = _od._tracking(kinds, arc_s, interval_s, **({"stations": station_names} if station_names else {}),
                         **_od._sp3_orbits(sp3_paths, scen, arc_s))
    say("scheduling")
    p.schedule(scen, plan)  # visibility refusals (a station below the horizon) before the simulation
    say("simulating")
    meas = p.simulate(scen, plan, None, seed, bias=biases)
    info = {"tracking": ",".join(kinds), "arc_s": repr(arc_s), "interval_s": repr(float(plan.interval_s)),
            "seed": str(seed), "scenario": scen.name}
    if biases:
        info["bias"] = json.dumps(biases)
    if plan.stations is not None:
        info["stations"] = ",".join(plan.stations)
    if sp3_paths:
        info["sp3"] = json.dumps(_od._sp3_record(sp3_paths))
    return Simulated(meas, scen, plan, info, tuple(notes))


def measurements_dataset(meas, *, epoch: str, time_scale: str, satellite_names=None, info: dict):
    """The measurements Dataset (module docstring) of a measurement table (attributes t, type, sat,
    peer, value, sigma, or a dict of them); epoch: t = 0 as text with its scale (``Epoch.iso``);
    time_scale: "TT" or "TDB"; satellite_names: the scenario's (None: not recorded); info: the
    plan's keys (the TDM header's)."""
    import xarray as xr

    cols = {f: np.asarray(getattr(meas, f) if not isinstance(meas, dict) else meas[f]) for f in _FIELDS}
    coords = {"t": ("row", cols["t"].astype(np.float64), {"units": "s", "description": "time tag since the epoch"}),
              "type": ("row", cols["type"].astype(str)), "sat": ("row", cols["sat"].astype(np.int64)),
              "peer": ("row", cols["peer"].astype(str))}
    data = {"value": ("row", cols["value"].astype(np.float64), {"units": "m or m/s (range rates)"}),
            "sigma": ("row", cols["sigma"].astype(np.float64), {"units": "m or m/s (range rates)"})}
    tau = meas.get("tau_down") if isinstance(meas, dict) else getattr(meas, "tau_down", None)
    if tau is not None:   # two-way rows: the downlink light time the TDM's tags are formed with
        data["tau_down"] = ("row", np.asarray(tau, np.float64), {"units": "s"})
    attrs = {"epoch": epoch, "time_scale": time_scale,
             **({"satellite_names": ",".join(satellite_names)} if satellite_names else {}), **info}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def measurements_fields(ds, name: str = "measurements") -> tuple[dict, dict]:
    """(fields, info) of a measurements Dataset, as :func:`tqdyn.formats.od_tdm.read_measurements_tdm`
    gives them for a file (fields: t, type, sat, peer, value, sigma and line, the row's index)."""
    missing = [f for f in _FIELDS if f not in getattr(ds, "variables", {})]
    if missing:
        raise ValueError(f"{name}: no {missing[0]!r}; allowed: a Dataset of tqdyn.od_simulate or "
                         "tqdyn.open_measurements (row: t, type, sat, peer, value, sigma)")
    fields = {f: np.asarray(ds[f].values) for f in _FIELDS}
    fields["type"], fields["peer"] = fields["type"].astype(str), fields["peer"].astype(str)
    fields["sat"] = fields["sat"].astype(np.int64)
    fields["line"] = np.arange(fields["t"].size, dtype=np.int64)
    return fields, {str(k): str(v) for k, v in ds.attrs.items()}


def open_measurements(path, scenario=None):
    """The measurements Dataset of a measurement file (CCSDS TDM written by ``tqdyn od simulate`` or
    :func:`tqdyn.formats.od_tdm.write_measurements_tdm`), t from the file's epoch, or from
    ``scenario``'s (a name, TOML, run file or Scenario; then checked to agree).  Two-way rows are
    tagged at reception in the file; their bounce instants are moved back onto the grid of the
    scenario's ``integrator.step`` (no scenario: the header's ``tqdyn interval_s``) as ``tqdyn od
    fit`` reads them."""
    from ..formats.od_tdm import tdm_to_measurements
    from ..formats.tdm import read_tdm

    scen = None if scenario is None else _load(scenario, ())[0]
    tdm = read_tdm(path)
    kw = {"epoch": None if scen is None else scen.epoch,
          "time_scale": None if scen is None else scen.reference.time_scale, "name": str(path)}
    fields, info = tdm_to_measurements(tdm, **kw, grid_s=None if scen is None else float(scen.integrator.step_s))
    if scen is None and "interval_s" in info:
        fields, info = tdm_to_measurements(tdm, **kw, grid_s=_od._header_number(info, "interval_s", str(path)))
    epoch, time_scale = info.pop("epoch"), info.pop("time_scale")
    names = [s.name for s in scen.satellites] if scen is not None else None
    return measurements_dataset(fields, epoch=epoch, time_scale=time_scale, satellite_names=names, info=info)


@dataclass(frozen=True)
class Fitted:
    """What :func:`fit` made: the :class:`tqdyn.od.estimator.Estimate`, the fitted measurement table,
    the scenario, the plan, the estimate file's attributes (no file's name), units, residual rows,
    notes."""

    estimate: object
    meas: object
    scenario: object
    tracking: object
    attrs: dict
    units: list
    residual_rows: np.ndarray
    notes: tuple


def _number_options(options: dict, cli: bool) -> dict:
    out = {}
    for key, v in options.items():
        if v is None:
            continue
        is_int = key in ("max_iterations", "max_edit_passes")
        good = (not isinstance(v, bool) and isinstance(v, (int, np.integer) if is_int else (int, float, np.number))
                and math.isfinite(float(v)))
        if good:
            good = {"step_tol": v > 0, "max_iterations": v >= 1, "max_condition": v > 1,
                    "min_kept_fraction": 0 < v <= 1, "max_edit_passes": v >= 0}[key]
        if not good:
            raise ValueError(f"{_opt(key, cli)}: {v!r} is not allowed; allowed: {ESTIMATOR_OPTIONS[key]}")
        out[key] = v
    return out


def fit(scenario, fields: dict, info: dict, tracking=None, *, estimate=None, consider=None, a_priori=None,
        edit_sigma=None, sp3=None, overrides=(), options: dict | None = None, name: str = "measurements",
        progress: Callable[[str], None] | None = None, cli: bool = False, scen=None) -> Fitted:
    """Fit ``scenario`` to the measurements ``fields`` with header ``info`` (:func:`od_fit`'s
    arguments; ``name`` names the measurements in error lines; ``scen``: the scenario already
    loaded)."""
    say = progress or (lambda stage: None)
    groups = None
    if tracking is not None:
        if isinstance(tracking, _problem().Tracking):
            groups = (tracking.estimate, tracking.consider, tracking.a_priori_sigma)
            kinds = tuple(tracking.kinds)
        else:
            kinds = _od.parse_tracking(tracking, _opt("tracking", cli))
    est_names, con_names, sig = _groups(estimate, consider, a_priori, groups, cli)
    if edit_sigma is not None and (isinstance(edit_sigma, bool) or not isinstance(edit_sigma, (int, float))
                                   or not edit_sigma > 0):
        raise ValueError(f"{_opt('edit_sigma', cli)}: {edit_sigma!r} is not allowed; allowed: a number > 0")
    opts = _number_options(dict(options or {}), cli)
    if scen is None:
        scen, notes, label = _load(scenario, overrides)
    else:
        notes, label = (), str(scenario) if scenario is not None else scen.name
    for key, mine in (("epoch", scen.epoch.iso), ("time_scale", scen.reference.time_scale)):
        if key in info and info[key] != mine:
            raise ValueError(f"{name}: {key} {info[key]}, the scenario's is {mine}; allowed: measurements of "
                             "this scenario")
    header = tuple(info["tracking"].split(",")) if info.get("tracking") else \
        tuple(dict.fromkeys(_od._registry().kind_of(t) for t in fields["type"]))
    _od.parse_tracking(header, f"{name}: header tqdyn tracking")
    if tracking is None:
        kinds = header
    sp3_paths = _od._sp3_paths(sp3, kinds)
    sp3_record = _od._check_sp3_against(info, sp3_paths, name)
    arc_s = _od._header_number(info, "arc_s", name) if "arc_s" in info else float(np.max(fields["t"]))
    _od._check_rows(scen, fields, arc_s, name)
    _od._check_arc(scen, arc_s, label)
    interval_s = _od._header_number(info, "interval_s", name) if "interval_s" in info else None
    plan = _od._tracking(kinds, arc_s, interval_s, est_names, con_names, a_priori_sigma=sig or None,
                         **_od._stations(info.get("stations")), **_od._sp3_orbits(sp3_paths, scen, arc_s))
    meas = _od._measurements(fields)
    say("fitting")
    if edit_sigma is not None:
        opts["edit_sigma"] = float(edit_sigma)
    p = _problem()
    result = p.fit(scen, meas, plan, **opts)
    rows = p.residual_rows(meas)
    units = [_od._unit(n) for n in result.names]
    attrs = {"scenario": scen.to_toml(), "scenario_name": scen.name, "epoch": scen.epoch.iso,
             "time_scale": scen.reference.time_scale,
             "edit_sigma": math.nan if edit_sigma is None else float(edit_sigma),
             "tracking": json.dumps({"kinds": list(kinds), "arc_s": arc_s, "interval_s": float(plan.interval_s),
                                     "estimate": list(p.estimated_groups(scen, plan)),
                                     "consider": list(plan.consider),
                                     "a_priori_sigma": plan.a_priori_sigma or {},
                                     **({"sp3": sp3_record} if sp3_record else {})})}
    return Fitted(result, meas, scen, plan, attrs, units, rows, tuple(notes))


def estimate_dataset(fitted: Fitted, attrs: dict | None = None):
    """The estimate as an ``xarray.Dataset``: what the estimate file holds
    (:mod:`tqdyn.formats.od_estimate`), with dimensions ``parameter`` (and ``parameter_j`` for the
    matrices; coordinate ``unit``), ``consider``, ``row`` (the measurements) and ``fit_row`` (the
    rows of the fit); variables ``estimate``, ``sigma``, ``covariance``, ``correlation``,
    ``consider_sigma``, ``consider_covariance``, ``sensitivity``, the measurements' ``value`` and
    ``sigma_measurement`` with coordinates t, type, sat, peer, and ``residual``,
    ``normalised_residual``, ``edited``, ``residual_row``; attributes: the file's root attributes
    (chi2, chi2_dof, chi2_pvalue, iterations, condition_number, scenario, tracking, groups, ...)."""
    import xarray as xr

    from ..formats.od_estimate import estimate_contents

    c = estimate_contents(fitted.estimate, fitted.meas, attrs=attrs or fitted.attrs, units=fitted.units,
                          residual_rows=fitted.residual_rows)
    p, m = c.parameters, c.measurements
    pj = ("parameter", "parameter_j")
    data = {"estimate": ("parameter", p["values"]), "sigma": ("parameter", p["sigma"]),
            "covariance": (pj, p["covariance"]), "correlation": (pj, p["correlation"]),
            "consider_sigma": ("parameter", p["consider_sigma"]), "consider_covariance": (pj, p["consider_covariance"]),
            "sensitivity": (("parameter", "consider"), np.asarray(p["sensitivity"]).reshape(len(p["names"]), -1)),
            "value": ("row", m["value"]), "sigma_measurement": ("row", m["sigma"]),
            "residual": ("fit_row", m["residual"]), "normalised_residual": ("fit_row", m["normalised_residual"]),
            "edited": ("fit_row", m["edited"]), "residual_row": ("fit_row", m["residual_row"])}
    coords = {"parameter": p["names"], "parameter_j": p["names"], "unit": ("parameter", p["units"]),
              "consider": p["consider_names"], "t": ("row", m["t"]), "type": ("row", m["type"]),
              "sat": ("row", m["sat"]), "peer": ("row", m["peer"])}
    return xr.Dataset(data, coords=coords, attrs=dict(c.attrs))


def estimate_file_of(ds):
    """The :class:`tqdyn.formats.od_estimate.EstimateFile` (path None) of an :func:`estimate_dataset`,
    as :func:`tqdyn.formats.od_estimate.read_estimate_file` gives a file (for the residuals' figure)."""
    from ..formats.od_estimate import EstimateFile

    params = {"names": ds["parameter"].values.astype(str), "units": ds["unit"].values.astype(str),
              "values": ds["estimate"].values, "consider_names": ds["consider"].values.astype(str),
              **{k: ds[k].values for k in ("sigma", "covariance", "correlation", "sensitivity", "consider_covariance",
                                           "consider_sigma")}}
    meas = {"t": ds["t"].values, "type": ds["type"].values.astype(str), "sat": ds["sat"].values,
            "peer": ds["peer"].values.astype(str), "value": ds["value"].values,
            "sigma": ds["sigma_measurement"].values,
            **{k: ds[k].values for k in ("residual", "normalised_residual", "edited", "residual_row")}}
    return EstimateFile(None, dict(ds.attrs), params, meas)


def covariance(scenario, tracking, arc=None, *, interval=None, estimate=None, consider=None, a_priori=None,
               stations=None, sp3=None, overrides=(), ready: Callable[[], None] | None = None,
               progress: Callable[[str], None] | None = None, cli: bool = False):
    """(covariance, scenario, plan, sp3 paths, notes) of a tracking plan on a scenario
    (:func:`od_covariance`'s arguments; ``ready`` as :func:`simulate`'s)."""
    say = progress or (lambda stage: None)
    kinds, arc_s, interval_s, station_names, groups = _plan(tracking, arc, interval, stations, cli)
    sp3_paths = _od._sp3_paths(sp3, kinds)
    est_names, con_names, sig = _groups(estimate, consider, a_priori, groups, cli)
    if ready is not None:
        ready()
    scen, notes, label = _load(scenario, overrides)
    _od._check_arc(scen, arc_s, label)
    plan = _od._tracking(kinds, arc_s, interval_s, est_names, con_names, a_priori_sigma=sig or None,
                         **({"stations": station_names} if station_names else {}),
                         **_od._sp3_orbits(sp3_paths, scen, arc_s))
    say("covariance")
    return _problem().covariance(scen, plan), scen, plan, sp3_paths, tuple(notes)


def covariance_dataset(cov, scen, plan, sp3_paths=()):
    """The predicted covariance as an ``xarray.Dataset``: the JSON record of ``tqdyn od covariance
    --json`` (:func:`tqdyn.workflows.od.covariance_record`) with dimensions ``parameter``,
    ``parameter_j`` (coordinate ``unit``) and ``consider``; variables ``nominal`` (the parameters'
    values), ``sigma``, ``covariance``, ``correlation``, ``consider_sigma``; attributes scenario,
    epoch, time_scale, tracking (JSON), condition_number."""
    import xarray as xr

    rec = _od.covariance_record(cov, scen, plan, sp3_paths)
    pj = ("parameter", "parameter_j")
    data = {"nominal": ("parameter", np.asarray(rec["values"])), "sigma": ("parameter", np.asarray(rec["sigma"])),
            "covariance": (pj, np.asarray(rec["covariance"]).reshape(len(rec["names"]), -1)),
            "correlation": (pj, np.asarray(rec["correlation"]).reshape(len(rec["names"]), -1)),
            "consider_sigma": ("parameter", np.asarray(rec["consider_sigma"]))}
    coords = {"parameter": list(rec["names"]), "parameter_j": list(rec["names"]), "unit": ("parameter", rec["units"]),
              "consider": list(rec["consider_names"])}
    attrs = {"scenario": rec["scenario"], "epoch": rec["epoch"], "time_scale": rec["time_scale"],
             "tracking": json.dumps(rec["tracking"]), "condition_number": rec["condition_number"]}
    return xr.Dataset(data, coords=coords, attrs=attrs)


# --------------------------------------------------------------------------- the front door


@checked_keywords
def od_simulate(run, tracking, arc=None, *, seed: int = 0, interval=None, stations=None, bias=None, sp3=None,
                overrides=()):
    """Measurements Dataset (module docstring) of ``tracking`` simulated on ``run``: a trajectory
    (``tqdyn.propagate``'s or ``tqdyn.open_trajectory``'s), a run file, or a scenario (name, TOML,
    Scenario); its ``[accelerations]`` and initial states are the truth.  tracking: ``"gnss,slr,isr"``
    or a sequence of kinds with ``arc`` (seconds or ``"7d"``), or a ``tqdyn.od.problem.Tracking``;
    seed: of the noise; bias: constant measurement biases {type or type/peer: value [m, m/s]};
    sp3: SP3 files of the GNSS transmitters; overrides: scenario keys."""
    s = simulate(run, tracking, arc, seed=seed, interval=interval, stations=stations, bias=bias, sp3=sp3,
                 overrides=overrides)
    scen = s.scenario
    return measurements_dataset(s.meas, epoch=scen.epoch.iso, time_scale=scen.reference.time_scale,
                                satellite_names=[x.name for x in scen.satellites], info=s.info)


@checked_keywords
def od_fit(scenario, measurements, tracking=None, *, estimate=None, consider=None, a_priori=None,
           edit_sigma: float | None = None, sp3=None, overrides=(), step_tol: float | None = None,
           max_iterations: int | None = None, max_condition: float | None = None,
           min_kept_fraction: float | None = None, max_edit_passes: int | None = None):
    """The batch least-squares estimate (:func:`estimate_dataset`) of ``scenario`` (a name, TOML,
    run file, trajectory or Scenario) from ``measurements`` (:func:`od_simulate`'s or
    :func:`open_measurements`'s Dataset); tracking: the kinds (None: the measurements' own) or a
    ``tqdyn.od.problem.Tracking``; estimate, consider: parameter groups; a_priori: {group: sigma};
    edit_sigma: k-sigma outlier editing; the estimator's step_tol, max_iterations, max_condition,
    min_kept_fraction, max_edit_passes (None: its defaults; :func:`tqdyn.od.estimator.estimate`)."""
    fields, info = measurements_fields(measurements)
    options = {"step_tol": step_tol, "max_iterations": max_iterations, "max_condition": max_condition,
               "min_kept_fraction": min_kept_fraction, "max_edit_passes": max_edit_passes}
    f = fit(scenario, fields, info, tracking, estimate=estimate, consider=consider, a_priori=a_priori,
            edit_sigma=edit_sigma, sp3=sp3, overrides=overrides, options=options)
    return estimate_dataset(f)


@checked_keywords
def od_covariance(scenario, tracking, arc=None, *, interval=None, estimate=None, consider=None, a_priori=None,
                  stations=None, sp3=None, overrides=()):
    """The predicted covariance (:func:`covariance_dataset`) of ``tracking`` (kinds with ``arc``, or a
    ``tqdyn.od.problem.Tracking``) on ``scenario``, without measurements."""
    cov, scen, plan, sp3_paths, _ = covariance(scenario, tracking, arc, interval=interval, estimate=estimate,
                                               consider=consider, a_priori=a_priori, stations=stations, sp3=sp3,
                                               overrides=overrides)
    return covariance_dataset(cov, scen, plan, sp3_paths)
