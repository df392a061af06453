"""Orbit determination from files: the jobs behind ``tqdyn od simulate | fit | covariance``.

* :func:`simulate_to_tdm`: the scenario of a run file (its ``[accelerations]`` and initial states are
  the injected truth), a tracking plan, seeded measurements (``tqdyn.od``'s ``problem.simulate``) written
  as a CCSDS TDM (:mod:`tqdyn.formats.od_tdm`) whose header records the plan;
* :func:`fit_to_file`: a scenario and a TDM, the batch least-squares fit
  (``tqdyn.od``'s ``problem.fit``) written as the estimate file (:mod:`tqdyn.formats.od_estimate`);
* :func:`covariance_of`: the predicted covariance of a tracking plan
  (``tqdyn.od``'s ``problem.covariance``), optionally written as JSON.

Every input is checked before any work and nothing is written on bad input (a ``ValueError`` /
``FileNotFoundError`` / :class:`tqdyn.formats.trajectory.OutputError` with one line); files are
written atomically.  ``progress`` callbacks receive the name of the stage that starts.  Nothing is
printed here; the CLI reports.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._choices import allowed as allowed_names, did_you_mean, unknown
from ..formats import trajectory as io
from ..formats.atomic import check_output, replacing, same_file
from ..formats.od_estimate import estimate_contents, write_estimate_file
from ..formats.od_tdm import read_measurements_tdm, write_measurements_tdm
from .closed_loop import file_sha256
from .run import load_run_scenario

__all__ = ["KIND_OF_TYPE", "SimulateSummary", "covariance_of", "fit_to_file", "parameter_unit", "parse_arc",
           "parse_names", "parse_tracking", "simulate_to_tdm"]

#: measurement type -> the tracking kind that produces it
KIND_OF_TYPE = {"gnss_pseudorange": "gnss", "slr_range": "slr", "isr_range": "isr", "dsn_range": "dsn",
                "dsn_range_rate": "dsn"}


def _problem():
    from ..od import problem

    return problem


def parse_tracking(text, option: str = "--tracking") -> tuple[str, ...]:
    """``"gnss,slr,isr"`` (or a sequence) -> the kinds, checked against
    ``tqdyn.od``'s ``problem.TRACKING_KINDS``; ValueError (one line) otherwise."""
    allowed = _problem().TRACKING_KINDS
    kinds = tuple(k.strip() for k in (text.split(",") if isinstance(text, str) else text))
    if not kinds or any(not k for k in kinds):
        raise ValueError(f"{option}: {text!r} is empty; allowed: a comma-separated list of {allowed_names(allowed)}")
    for k in kinds:
        if k not in allowed:
            raise ValueError(unknown(option, k, allowed, problem="is not a tracking type"))
    if len(set(kinds)) != len(kinds):
        raise ValueError(f"{option}: {text!r} names a tracking type twice")
    return kinds


def parse_names(text, option: str) -> tuple[str, ...]:
    """``"state,s_frame"`` (or a sequence; None or "" -> ()) -> a tuple of names."""
    if text is None:
        return ()
    items = text.split(",") if isinstance(text, str) else list(text)
    return tuple(s.strip() for s in items if s.strip())


def _key_values(items, option: str, what: str):
    """``KEY=VALUE`` strings (or a mapping) -> [(key, value text)]; ValueError (one line) otherwise."""
    if isinstance(items, dict):
        return [(str(k), v) for k, v in items.items()]
    out = []
    for item in ([items] if isinstance(items, str) else list(items or ())):
        key, sep, value = str(item).rpartition("=")
        if not sep or not key.strip() or not value.strip():
            raise ValueError(f"{option}: {item!r} is not allowed; allowed: {what}")
        out.append((key.strip(), value.strip()))
    return out


def _number(text, option: str, key: str, positive: bool) -> float:
    try:
        v = float(text)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(text, bool) or not math.isfinite(v) or (positive and v <= 0):
        raise ValueError(f"{option}: {key} = {text!r} is not allowed; allowed: a finite number"
                         + (" > 0" if positive else ""))
    return v


def parse_biases(items, option: str = "--bias") -> dict:
    """``TYPE=VALUE`` or ``TYPE/PEER=VALUE`` (repeated; or a mapping) -> {key: value [m, m/s for
    dsn_range_rate]}, the measurement biases of ``tqdyn.od``'s ``problem.simulate``."""
    allowed = _problem().BIAS_TYPES
    out = {}
    for key, value in _key_values(items, option, "TYPE=VALUE or TYPE/STATION=VALUE"):
        typ = key.removeprefix("bias/").split("/")[0]
        if typ not in allowed:
            raise ValueError(f"{option}: {key!r} is not allowed{did_you_mean(typ, allowed)}; allowed: "
                             f"{', '.join(allowed)} (or TYPE/STATION, TYPE/EMITTER->RECEIVER)")
        out[key] = _number(value, option, key, positive=False)
    return out


def parse_a_priori(items, option: str = "--a-priori") -> dict:
    """``GROUP=SIGMA`` (``state=SIGMA_R,SIGMA_V``, ``bias=SIGMA`` or ``bias/TYPE=SIGMA``; repeated, or a
    mapping such as {"state": (100.0, 0.01), "bias": {"slr_range": 0.02}}) -> ``Tracking.a_priori_sigma``
    {group: sigma} [m, m/s, m/s^2]."""
    groups = _problem().GROUPS
    pairs = []
    for key, value in _key_values(items, option, "GROUP=SIGMA (state=SIGMA_R,SIGMA_V)"):
        if key == "bias" and isinstance(value, dict):
            pairs += [(f"bias/{t}", v) for t, v in value.items()]
        else:
            pairs.append((key, ",".join(str(v) for v in value) if isinstance(value, (list, tuple)) else value))
    out: dict = {}
    for key, value in pairs:
        group, _, typ = key.partition("/")
        if group not in groups:
            raise ValueError(unknown(option, key, groups) + " (or bias/TYPE)")
        if typ and (group != "bias" or typ not in _problem().BIAS_TYPES):
            raise ValueError(unknown(option, key, [f"bias/{t}" for t in _problem().BIAS_TYPES]))
        parts = value.split(",") if isinstance(value, str) else [value]
        if len(parts) != (2 if group == "state" else 1):
            raise ValueError(f"{option}: {key} = {value!r} is not allowed; allowed: "
                             + ("SIGMA_R,SIGMA_V (m, m/s)" if group == "state" else "one number"))
        sig = [_number(x, option, key, positive=True) for x in parts]
        if group == "bias" and "bias" in out and bool(typ) != isinstance(out["bias"], dict):
            raise ValueError(f"{option}: bias is given with and without a type; allowed: one of the two")
        if typ:
            out.setdefault("bias", {})[typ] = sig[0]
        else:
            out[group] = tuple(sig) if group == "state" else sig[0]
    return out


def _check_consider(con_names, a_priori: dict) -> None:
    for g in con_names:
        if g not in a_priori:
            raise ValueError(f"--consider: {g!r} needs an a priori sigma; allowed: with --a-priori {g}=SIGMA")


def parse_arc(value, option: str = "--arc") -> float:
    """A duration (seconds, or ``7d``, ``12h``, ``30min`` as ``--duration`` takes it) -> seconds > 0."""
    from ..scenario import ScenarioError
    from ..scenario.loader import parse_duration

    try:
        v = float(parse_duration(value))
    except (ScenarioError, ValueError, ArithmeticError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{option}: {value!r} is not a duration > 0; allowed: seconds, or with a unit (7d, 12h, "
                         "30min, 3600s)")
    return v


def parameter_unit(name: str) -> str:
    """The unit of an estimated parameter from its name ``"<sat>/<component>"``: the initial state's
    x, y, z [m] and vx, vy, vz [m/s], the acceleration parameters and a coupled run's common
    self-gravity [m/s^2], the measurement biases ``"bias/<type>/..."`` [m, m/s for range rates];
    "" otherwise."""
    from ..od.coupled import COMMON_NAMES
    from ..od.parameters import PARAMETER_NAMES, STATE_NAMES

    if name.startswith("bias/"):
        return "m/s" if name.split("/")[1] == "dsn_range_rate" else "m"
    last = name.rsplit("/", 1)[-1]
    if last in STATE_NAMES:
        return "m" if last in STATE_NAMES[:3] else "m/s"
    return "m/s^2" if last in PARAMETER_NAMES or last in COMMON_NAMES else ""


def _check_arc(scen, arc_s: float, source: str) -> None:
    span = float(scen.run.duration_s)
    if arc_s > span:
        raise ValueError(f"--arc: {arc_s:g} s is outside the run {source} ({span:g} s from its epoch); allowed: "
                         f"0 < arc <= {span:g} s (or --set run.duration=...)")


def _check_rows(scen, fields, arc_s: float, tdm) -> None:
    """Every measurement row against the run, before any propagation: its satellite is one of the
    scenario's, its epoch t [s] lies in [0, arc] (the header's ``tqdyn arc_s``, at most the run's
    span) and on the run's step grid (``integrator.step``).  One line naming the file's line."""
    from ..od.variational import off_grid

    t, sat, line = fields["t"], fields["sat"], fields["line"]
    n_sat, span, step = len(scen.satellites), float(scen.run.duration_s), float(scen.integrator.step_s)
    end = min(arc_s, span)

    def first(mask):
        i = np.flatnonzero(mask)
        return int(i[np.argmin(line[i])]) if i.size else None

    i = first(sat >= n_sat)
    if i is not None:
        raise ValueError(f"{tdm}, line {line[i]}: tqdyn sat = {sat[i]}; allowed: 0..{n_sat - 1} (the scenario's "
                         f"{n_sat} satellites)")
    i = first(~((t >= 0) & (t <= end + 1e-9 * max(1.0, end))))
    if i is not None:
        what = (f"the arc 0..{end:g} s (header tqdyn arc_s; the run spans {span:g} s)" if arc_s <= span
                else f"the run, 0..{span:g} s")
        raise ValueError(f"{tdm}, line {line[i]}: epoch at t = {t[i]:.12g} s (from the scenario epoch) is outside "
                         f"{what}; allowed: epochs in it")
    i = first(off_grid(t, step))
    if i is not None:
        d = t[i] - round(t[i] / step) * step
        raise ValueError(f"{tdm}, line {line[i]}: epoch at t = {t[i]:.12g} s (from the scenario epoch) is {d:+.3g} s "
                         f"off the step grid (integrator.step = {step:g} s); allowed: multiples of {step:g} s")


def _scenario(scenario, overrides):
    """(scenario, notes, label) of a name, TOML path or run file (as ``tqdyn run``)."""
    scen, notes = load_run_scenario(scenario, list(overrides))
    return scen, notes, (str(scenario) if scenario is not None else scen.name)


@dataclass(frozen=True)
class SimulateSummary:
    """What :func:`simulate_to_tdm` wrote: path, measurement count per type, the tracking plan."""

    path: pathlib.Path
    counts: dict
    tracking: object
    notes: tuple


def _tracking(kinds, arc_s, interval_s, estimate=None, consider=None, **kw):
    p = _problem()
    extra = {}
    if interval_s is not None:
        extra["interval_s"] = float(interval_s)
    if estimate:
        extra["estimate"] = tuple(estimate)
    if consider:
        extra["consider"] = tuple(consider)
    return p.Tracking(kinds=tuple(kinds), arc_s=float(arc_s), **extra, **kw)


def _stations(value) -> dict:
    names = parse_names(value, "--stations")
    return {"stations": names} if names else {}


def _interval(value) -> float | None:
    return None if value is None else parse_arc(value, "--interval")


def _sp3_paths(sp3, kinds) -> list:
    """The ``--sp3`` files (a path or a sequence; None: none), checked to exist and to go with GNSS
    tracking; ValueError / FileNotFoundError (one line) otherwise."""
    paths = [sp3] if isinstance(sp3, (str, os.PathLike)) else list(sp3 or ())
    if paths and "gnss" not in kinds:
        raise ValueError(f"--sp3: the tracking ({','.join(kinds)}) has no gnss; allowed: --sp3 with gnss tracking")
    for path in paths:
        if not os.path.isfile(os.fspath(path)):
            raise FileNotFoundError(f"--sp3: SP3 file {str(path)!r} does not exist or is not a file")
    return paths


def _sp3_inputs(sp3) -> dict:
    """{"--sp3 FILE": path} of the ``--sp3`` files (inputs an output must not be)."""
    paths = [sp3] if isinstance(sp3, (str, os.PathLike)) else list(sp3 or ())
    return {f"--sp3 {os.fspath(p)}": p for p in paths}


def _sp3_orbits(paths, scen, arc_s: float) -> dict:
    """{"gnss_orbits": the SP3 constellations of ``paths`` on the scenario's epoch} (no files: {}),
    each checked to cover the arc (and the second before it: the signals' emission times)."""
    if not paths:
        return {}
    from ..od.gnss_sp3 import sp3_constellations

    orbits = sp3_constellations(paths, scen.epoch)
    for o in orbits:
        lo, hi = o.span
        if lo > -1.0 or hi < arc_s:
            raise ValueError(f"--sp3: {o.name} covers t = {lo:.6g} to {hi:.6g} s TT since the epoch (its epochs "
                             f"less {o.points // 2 - 1} samples at each end); allowed: a file covering the arc, "
                             f"-1 to {arc_s:g} s")
    return {"gnss_orbits": orbits}


def _sp3_record(paths) -> list:
    """[[file name, SHA-256], ...] of the SP3 files (the TDM header's ``sp3``)."""
    return [[pathlib.Path(path).name, file_sha256(path)] for path in paths]


def _check_sp3_against(info: dict, paths, tdm) -> list:
    """Refuse (one line) SP3 files other than those the TDM was simulated with (SHA-256); else
    their :func:`_sp3_record`."""
    try:
        used = [tuple(x) for x in json.loads(info["sp3"])] if info.get("sp3") else []
    except (ValueError, TypeError):
        raise ValueError(f"{tdm}: header: tqdyn sp3 = {info['sp3']!r}; allowed: a JSON list of [file, sha256]") \
            from None
    record = _sp3_record(paths)
    given = [tuple(x) for x in record]
    if not used and given:
        raise ValueError(f"--sp3: {tdm} was simulated with the nominal GNSS constellations (no SP3 file); allowed: "
                         "no --sp3")
    if used and not given:
        raise ValueError(f"--sp3: {tdm} was simulated with the SP3 file(s) {', '.join(n for n, _ in used)}; "
                         "allowed: --sp3 with the same file(s)")
    if sorted(h for _, h in used) != sorted(h for _, h in given):
        other = [n for n, h in given if h not in {u for _, u in used}]
        raise ValueError(f"--sp3: {', '.join(other) or 'the files given'} (by SHA-256) "
                         f"{'is' if len(other) == 1 else 'are'} not the SP3 file(s) {tdm} was simulated with "
                         f"({', '.join(n for n, _ in used)}); allowed: the same file(s)")
    return record


def simulate_to_tdm(run_file, tracking, arc, *, output, seed: int = 0, interval=None, stations=None, bias=None,
                    sp3=None, overrides=(), progress: Callable[[str], None] | None = None) -> SimulateSummary:
    """Simulate the measurements of ``tracking`` (kinds) over ``arc`` from the run file's scenario (its
    ``[accelerations]`` are the truth) with noise seed ``seed``, and write them as a TDM to ``output``.
    stations: ground-station names (None: the plan's defaults); bias: constant measurement biases
    (:func:`parse_biases`; None: none), recorded in the TDM's header; sp3: SP3 files of the GNSS
    transmitters (a path or a sequence; None: the nominal constellations), their names and SHA-256
    recorded in the header."""
    say = progress or (lambda stage: None)
    kinds = parse_tracking(tracking)
    biases = parse_biases(bias)
    arc_s = parse_arc(arc)
    interval_s = _interval(interval)
    sp3_paths = _sp3_paths(sp3, kinds)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"--seed: {seed!r} is not allowed; allowed: an integer >= 0")
    if not io.is_trajectory_file(run_file):
        raise (FileNotFoundError(f"RUN.h5: trajectory file {str(run_file)!r} does not exist or is not a file")
               if not os.path.isfile(os.fspath(run_file)) else
               ValueError(f"RUN.h5: {str(run_file)!r} is not a trajectory file; allowed: a file written by tqdyn run"))
    out = check_output(output, "--output", {"RUN.h5": run_file, **_sp3_inputs(sp3_paths)})
    scen, notes, label = _scenario(run_file, overrides)
    _check_arc(scen, arc_s, label)
    p = _problem()
    plan = _tracking(kinds, arc_s, interval_s, **_stations(stations), **_sp3_orbits(sp3_paths, scen, arc_s))
    say("scheduling")
    p.schedule(scen, plan)  # visibility refusals (a station below the horizon) before the simulation
    say("simulating")
    meas = p.simulate(scen, plan, None, seed, bias=biases)
    info = {"tracking": ",".join(kinds), "arc_s": repr(arc_s), "interval_s": repr(float(plan.interval_s)),
            "seed": str(seed), "scenario": scen.name, "run_file": pathlib.Path(run_file).name,
            "run_sha256": file_sha256(run_file)}
    if biases:
        info["bias"] = json.dumps(biases)
    if plan.stations is not None:
        info["stations"] = ",".join(plan.stations)
    if sp3_paths:
        info["sp3"] = json.dumps(_sp3_record(sp3_paths))
    say("writing")
    path = write_measurements_tdm(out, meas, epoch=scen.epoch, time_scale=scen.reference.time_scale,
                                  satellite_names=[s.name for s in scen.satellites], info=info)
    counts: dict = {}
    for typ in np.asarray(meas.type).tolist():
        counts[typ] = counts.get(typ, 0) + 1
    return SimulateSummary(path, counts, plan, tuple(notes))


def _measurements(fields):
    return _problem().Measurements(**{k: fields[k] for k in ("t", "type", "sat", "peer", "value", "sigma")})


def _header_number(info: dict, key: str, tdm) -> float:
    try:
        v = float(info[key])
    except ValueError:
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{tdm}: header: tqdyn {key} = {info[key]!r}; allowed: a number of seconds > 0")
    return v


def fit_to_file(scenario, tdm, *, output=None, estimate=None, consider=None, a_priori=None, edit_sigma=None,
                sp3=None, overrides=(), figure=None, progress: Callable[[str], None] | None = None, **options):
    """Fit the scenario's parameters (``estimate``, ``consider``: names of parameter groups, default
    the plan's) to the measurements of the TDM ``tdm``; write the estimate file ``output`` (None: no
    file) and the residuals' figure ``figure`` (None: none; PNG or PDF by its suffix,
    :func:`tqdyn.analysis.figures_od.plot_od_residuals`, checked before the fit).  a_priori: a
    priori sigmas per group (:func:`parse_a_priori`), needed for each considered group.  sp3: the
    SP3 files the TDM was simulated with (its header names them; refused when they differ, by
    SHA-256; None: none, the nominal constellations).  Returns
    (:class:`tqdyn.od.estimator.Estimate`, the scenario, notes).  ``options`` go to
    :func:`tqdyn.od.estimator.estimate` with ``edit_sigma``."""
    say = progress or (lambda stage: None)
    est_names, con_names = parse_names(estimate, "--estimate"), parse_names(consider, "--consider")
    sig = parse_a_priori(a_priori)
    _check_consider(con_names, sig)
    if edit_sigma is not None and not (isinstance(edit_sigma, (int, float)) and edit_sigma > 0):
        raise ValueError(f"--edit-sigma: {edit_sigma!r} is not allowed; allowed: a number > 0")
    if not os.path.isfile(os.fspath(tdm)):
        raise FileNotFoundError(f"MEAS.tdm: measurement file {str(tdm)!r} does not exist or is not a file")
    inputs = {"MEAS.tdm": tdm, "SCENARIO": scenario if scenario and os.path.isfile(str(scenario)) else None,
              **_sp3_inputs(sp3)}
    out = check_output(output, "--output", inputs) if output is not None else None
    if figure is not None:
        from ..analysis.figures_od import check_residual_figure_path

        try:
            check_residual_figure_path(figure)
        except ImportError as exc:
            raise ValueError(f"--figure: {str(figure)!r} cannot be drawn ({exc}); allowed: no --figure, or install "
                             "matplotlib") from None
        if out is not None and same_file(out, figure):
            raise ValueError(f"--figure: {str(figure)!r} is the output EST.h5; allowed: another file")
        check_output(figure, "--figure", inputs)
    scen, notes, label = _scenario(scenario, overrides)
    say("reading")
    fields, info = read_measurements_tdm(tdm, epoch=scen.epoch, time_scale=scen.reference.time_scale,
                                         with_lines=True)
    kinds = tuple(info["tracking"].split(",")) if info.get("tracking") else \
        tuple(dict.fromkeys(KIND_OF_TYPE[t] for t in fields["type"]))
    parse_tracking(kinds, f"{tdm}: header tqdyn tracking")
    sp3_paths = _sp3_paths(sp3, kinds)
    sp3_record = _check_sp3_against(info, sp3_paths, tdm)
    arc_s = _header_number(info, "arc_s", tdm) if "arc_s" in info else float(np.max(fields["t"]))
    _check_rows(scen, fields, arc_s, tdm)
    _check_arc(scen, arc_s, label)
    interval_s = _header_number(info, "interval_s", tdm) if "interval_s" in info else None
    plan = _tracking(kinds, arc_s, interval_s, est_names, con_names, a_priori_sigma=sig or None,
                     **_stations(info.get("stations")), **_sp3_orbits(sp3_paths, scen, arc_s))
    meas = _measurements(fields)
    say("fitting")
    if edit_sigma is not None:
        options["edit_sigma"] = float(edit_sigma)
    fit = _problem().fit(scen, meas, plan, **options)
    rows = _problem().residual_rows(meas)
    units = [parameter_unit(n) for n in fit.names]
    attrs = {"scenario": scen.to_toml(), "scenario_name": scen.name, "epoch": scen.epoch.iso,
             "time_scale": scen.reference.time_scale, "tdm_file": pathlib.Path(tdm).name,
             "tdm_sha256": file_sha256(tdm), "edit_sigma": math.nan if edit_sigma is None else float(edit_sigma),
             "tracking": json.dumps({"kinds": list(kinds), "arc_s": arc_s, "interval_s": float(plan.interval_s),
                                     "estimate": list(_problem().estimated_groups(scen, plan)),
                                     "consider": list(plan.consider),
                                     "a_priori_sigma": plan.a_priori_sigma or {},
                                     **({"sp3": sp3_record} if sp3_record else {})})}
    if out is not None:
        say("writing")
        write_estimate_file(out, fit, meas, attrs=attrs, units=units, residual_rows=rows)
    if figure is not None:
        from ..analysis.figures_od import plot_od_residuals

        say("plotting")
        try:
            plot_od_residuals(estimate_contents(fit, meas, attrs=attrs, units=units, residual_rows=rows), figure)
        except io.OutputIOError as exc:  # a full disk: status 3, the estimate file stays
            err = io.OutputIOError(f"--figure: {exc}")
            err.tqdyn_note = ("the figure was not written" + (f", the estimate file {str(out)!r} was"
                                                              if out is not None else ""))
            raise err from None
        except (OSError, RuntimeError) as exc:  # a directory removed since the check, a missing LaTeX
            raise ValueError(f"--figure: {str(figure)!r} could not be written ({exc}); nothing was written there"
                             + (f", the estimate file {str(out)!r} was" if out is not None else "")
                             + "; allowed: a writable file with space for the figure") from None
    return fit, scen, tuple(notes)


def covariance_of(scenario, tracking, arc, *, interval=None, estimate=None, consider=None, a_priori=None,
                  stations=None, sp3=None, overrides=(), json_out=None, progress: Callable[[str], None] | None = None):
    """The predicted covariance (:class:`tqdyn.od.estimator.Covariance`) of the tracking plan on the
    scenario (a_priori, sp3: as :func:`simulate_to_tdm`'s), and (optionally) its JSON file ``json_out``.
    Returns (covariance, scenario, notes)."""
    say = progress or (lambda stage: None)
    kinds = parse_tracking(tracking)
    arc_s = parse_arc(arc)
    interval_s = _interval(interval)
    sp3_paths = _sp3_paths(sp3, kinds)
    est_names, con_names = parse_names(estimate, "--estimate"), parse_names(consider, "--consider")
    sig = parse_a_priori(a_priori)
    _check_consider(con_names, sig)
    inputs = {"SCENARIO": scenario if scenario and os.path.isfile(str(scenario)) else None, **_sp3_inputs(sp3_paths)}
    out = check_output(json_out, "--json", inputs) if json_out is not None else None
    scen, notes, label = _scenario(scenario, overrides)
    _check_arc(scen, arc_s, label)
    plan = _tracking(kinds, arc_s, interval_s, est_names, con_names, a_priori_sigma=sig or None,
                     **_stations(stations), **_sp3_orbits(sp3_paths, scen, arc_s))
    say("covariance")
    cov = _problem().covariance(scen, plan)
    if out is not None:
        say("writing")
        rec = covariance_record(cov, scen, plan, sp3_paths)
        with replacing(out, "the covariance JSON") as tmp:
            tmp.write_text(json.dumps(rec, indent=1) + "\n", encoding="utf-8")
    return cov, scen, tuple(notes)


def covariance_record(cov, scen, plan, sp3_paths=()) -> dict:
    """The JSON record of a predicted covariance: scenario, tracking plan, parameter names and units,
    nominal values, sigmas, covariance, correlation, consider names and sigmas, condition number (and the
    names and SHA-256 of the SP3 files ``sp3_paths``, when given)."""
    def arr(a):
        return np.asarray(a, np.float64).tolist()

    return {"scenario": scen.name, "epoch": scen.epoch.iso, "time_scale": scen.reference.time_scale,
            "tracking": {"kinds": list(plan.kinds), "arc_s": float(plan.arc_s), "interval_s": float(plan.interval_s),
                         "estimate": list(_problem().estimated_groups(scen, plan)),
                         "consider": list(plan.consider), "a_priori_sigma": plan.a_priori_sigma or {},
                         **({"sp3": _sp3_record(sp3_paths)} if sp3_paths else {})},
            "names": list(cov.names), "units": [parameter_unit(n) for n in cov.names], "values": arr(cov.values),
            "sigma": arr(cov.sigma), "covariance": arr(cov.covariance), "correlation": arr(cov.correlation),
            "consider_names": list(cov.consider_names), "consider_sigma": arr(cov.consider_sigma),
            "condition_number": float(cov.condition_number)}
