"""Orbit determination: the checks and parsers of the inputs of ``tqdyn od`` and of
``tqdyn.od_simulate | od_fit | od_covariance`` (tracking kinds, arcs, biases, a priori sigmas, SP3
files, a measurement table's rows against a run) and the covariance's JSON record.

The jobs are :mod:`tqdyn.workflows.od_memory` (in memory: simulate, fit, covariance) and
:mod:`tqdyn.workflows.od_files` (``tqdyn od simulate | fit | covariance``: a file read, the
in-memory job, a file written).  Every check raises a ``ValueError`` / ``FileNotFoundError`` with
one line naming the option or field, the value and what is allowed.
"""

from __future__ import annotations

import json
import math
import os
import pathlib

import numpy as np

from .._choices import allowed as allowed_names, did_you_mean, unknown
from .closed_loop import file_sha256
from .run import load_run_scenario

__all__ = ["KIND_OF_TYPE", "covariance_record", "parameter_unit", "parse_arc", "parse_names",  # noqa: F822
           "parse_tracking"]


def _problem():
    from ..od import problem

    return problem


def _registry():
    from ..od import registry

    return registry


def _unit(name: str) -> str:
    from ..od.tracking import parameter_unit

    return parameter_unit(name)


def __getattr__(name):
    """The names this module had before the measurement registry (:mod:`tqdyn.od.registry`):
    ``KIND_OF_TYPE`` {type: kind} and ``parameter_unit``, re-exported from it."""
    if name == "KIND_OF_TYPE":
        return {n: x.kind for n, x in _registry().TYPES.items()}
    if name == "parameter_unit":
        return _unit
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
    """``TYPE=VALUE`` or ``TYPE/PEER=VALUE`` (repeated; or a mapping) -> {key: value [the type's
    unit, m or m/s]}, the measurement biases of ``tqdyn.od``'s ``problem.simulate``."""
    allowed = _problem().BIAS_TYPES
    out = {}
    for key, value in _key_values(items, option, "TYPE=VALUE or TYPE/STATION=VALUE"):
        typ = key.removeprefix("bias/").split("/")[0]
        if typ not in allowed:
            raise ValueError(f"{option}: {key!r} is not allowed{did_you_mean(typ, allowed)}; allowed: "
                             f"{', '.join(allowed)}, or TYPE/PEER")
        out[key] = _number(value, option, key, positive=False)
    return out


def parse_a_priori(items, option: str = "--a-priori") -> dict:
    """``GROUP=SIGMA`` (``state=SIGMA_R,SIGMA_V``, ``bias=SIGMA`` or ``bias/TYPE=SIGMA``; repeated, or a
    mapping such as {"state": (100.0, 0.01), "bias": {TYPE: 0.02}}) -> ``Tracking.a_priori_sigma``
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
    from ..od.tracking import check_consider

    check_consider(con_names, a_priori, "--consider", "--a-priori {g}=SIGMA")


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
    from ..od.measurement_type import scenario_eop

    orbits = sp3_constellations(paths, scen.epoch, **scenario_eop(scen))
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
            "names": list(cov.names), "units": [_unit(n) for n in cov.names], "values": arr(cov.values),
            "sigma": arr(cov.sigma), "covariance": arr(cov.covariance), "correlation": arr(cov.correlation),
            "consider_names": list(cov.consider_names), "consider_sigma": arr(cov.consider_sigma),
            "condition_number": float(cov.condition_number)}
