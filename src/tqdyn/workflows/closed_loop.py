"""The closed loop of a run file to a closed-loop file (``tqdyn closed-loop``; docs/closed-loop-file.md).

:func:`check_closed_loop_inputs` resolves everything a run needs and refuses bad input in one line
before anything is written; :func:`closed_loop_to_file` then computes the budget, streams the time
series into a :class:`~tqdyn.formats.closed_loop.ClosedLoopWriter` and renames the file into place
(nothing at the output path after a failure or an interrupt).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import dataclass

from ..formats import trajectory as io
from ..formats.atomic import check_output
from ..formats.closed_loop import ClosedLoopWriter

__all__ = ["ClosedLoopJob", "ClosedLoopSummary", "check_closed_loop_inputs", "closed_loop_to_file",
           "resolved_configuration"]


@dataclass
class ClosedLoopJob:
    """What :func:`check_closed_loop_inputs` resolved: the trajectory (None for a mission's static working
    point), the model, the output path and the time-domain settings (duration [s], fs [Hz], seed), the
    configuration and the root attributes."""

    traj: object
    model: object
    output: object
    duration_s: float
    fs: float
    seed: int
    attrs: dict
    per_source: bool = False


@dataclass(frozen=True)
class ClosedLoopSummary:
    """The result of :func:`closed_loop_to_file`: the file, its size [bytes], the samples written,
    the wall times [s] of the budget and of the streamed time series."""

    path: object
    size_bytes: int
    n_samples: int
    n_sat: int
    budget_s: float
    timeseries_s: float


def _positive(name: str, text, parse) -> float:
    try:
        v = float(parse(text))
    except Exception:  # noqa: BLE001 - any unparsable value
        v = float("nan")
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name}: {text!r} is not allowed; allowed: a finite number > 0"
                         + (" (seconds, or with a unit: 3d, 6h, 30min, 3600s)" if name == "--duration" else " (Hz)"))
    return v


def resolved_configuration(config, architecture: str, settings: dict, hinf=()) -> dict:
    """The resolved closed-loop configuration as plain JSON types: settings, plant, controllers
    (zeros, poles [rad/s] as [re, im], gain) and noise (level [unit/Hz^1/2], knees [[Hz, slope]], unit); with
    ``closed_loop.design = "hinf"`` (``hinf``: the model's synthesised controllers, one per satellite) also
    ``hinf``, per satellite the controller's ``order``, ``gamma``, ``bandwidth_hz`` and ``shift`` [rad/s]
    (``controllers`` then holds the per-loop design it replaces)."""
    from ..closedloop.missions import resolve

    mission, plant, ctl, noise = resolve(config, architecture)
    extra = {"hinf": [{"order": k.order, "gamma": float(k.gamma), "bandwidth_hz": [float(f) for f in k.bandwidth_hz],
                       "shift": float(k.shift)} for k in hinf]} if hinf else {}
    return {"mission": mission, "settings": dict(settings), **extra,
            "plant": {k: (list(v) if isinstance(v, (tuple, list)) else float(v)) for k, v in plant.items()},
            "controllers": {k: {"zeros": [[complex(z).real, complex(z).imag] for z in c.zeros],
                                "poles": [[complex(p).real, complex(p).imag] for p in c.poles], "gain": float(c.gain)}
                            for k, c in ctl.items()},
            "noise": {k: {"level": float(a.level), "knees": [list(x) for x in a.knees], "unit": a.unit}
                      for k, a in noise.items()}}


def file_sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 22), b""):
            h.update(chunk)
    return h.hexdigest()


def _series(model, dur, rate, seed) -> tuple:
    """(duration [s], fs [Hz], seed, n_samples) of the time series: the options given, else the model's
    settings (the duration: ``closed_loop.duration``, else :func:`tqdyn.analysis.closed_loop.default_series_s`);
    ValueError (one line) for less than one sample."""
    from ..analysis.closed_loop import default_series_s

    s = model.settings
    dur = dur if dur is not None else (s["duration"] or default_series_s(model))
    rate = rate if rate is not None else s["fs"]
    seed = seed if seed is not None else s["seed"]
    n = int(round(float(dur) * rate))
    if n < 1:
        raise ValueError(f"--duration: {dur!r} s at {rate!r} Hz is less than one sample; allowed: duration x fs >= 1")
    return dur, rate, seed, n


def _static_job(mission, out, dur, rate, seed, overrides, per_source: bool) -> ClosedLoopJob:
    """The job of a mission's static working point (no run file): the source_* attributes are empty."""
    from ..closedloop.model import static_closed_loop_model
    from ..scenario.loader import closed_loop_config

    cfg = closed_loop_config({"mission": mission}, overrides)
    if cfg.raw.get("mission") != mission:
        raise ValueError(f"--set closed_loop.mission={cfg.raw.get('mission')!r}: conflicts with --mission {mission!r}; "
                         "allowed: the mission in --mission only")
    model = static_closed_loop_model(cfg, validate=True)
    s = model.settings
    dur, rate, seed, n = _series(model, dur, rate, seed)
    _check_size(model, n, out)
    conf = resolved_configuration(cfg, mission, {**s, "fs": rate, "duration": float(dur), "seed": int(seed)},
                                  model.hinf)
    conf["working_point"] = "static"
    attrs = {"mission": model.mission, "source_file": "", "source_path": "", "source_sha256": "",
             "source_scenario_sha256": "", "source_format_version": 0, "source_tqdyn_version": "",
             "source_epoch_utc": "", "source_time_scale": "", "configuration": json.dumps(conf),
             "closed_loop_toml": "\n".join(cfg.to_toml_lines()), "seed": int(seed), "fs": float(rate),
             "duration_s": n / rate, "n_samples": n, "t0": 0.0,
             "satellite_names": json.dumps(list(model.satellite_names))}
    return ClosedLoopJob(traj=None, model=model, output=out, duration_s=n / rate, fs=float(rate), seed=int(seed),
                         attrs=attrs, per_source=bool(per_source))


def check_closed_loop_inputs(run_file, output, duration=None, fs=None, seed=None, overrides=(),
                             per_source: bool = False, mission=None) -> ClosedLoopJob:
    """Resolve a ``tqdyn closed-loop`` job; raise (one line) FileNotFoundError, ValueError
    (TrajectoryFormatError, ScenarioError, ClosedLoopError, DesignError: a bad option, a run without
    test masses or a pure-gravity run, an unknown loop or source, a bad ASD, an unstable design naming
    the loop and its margin) or OutputError (the output path) before anything is written.
    ``overrides``: ``closed_loop.KEY=VALUE`` strings, as the scenario's ``--set``; ``per_source``: also write
    the ASD of every output from every source (``/budget/asd``, n_segment x n_sat x 46 x n_source x n_freq).
    ``mission`` (instead of ``run_file``): the mission's static working point
    (:func:`tqdyn.closedloop.model.static_closed_loop_model`; the file's source_* attributes are then empty,
    its configuration says ``"working_point": "static"``)."""
    from ..closedloop.model import closed_loop_model
    from ..scenario import loads_scenario
    from ..scenario.closed_loop import MISSIONS
    from ..scenario.loader import parse_duration

    if (run_file is None) == (mission is None):
        raise ValueError("RUN.h5: give either a run file or --mission (not both, not neither); allowed: "
                         "tqdyn closed-loop RUN.h5 --output CL.h5, or tqdyn closed-loop --mission NAME --output CL.h5")
    if mission is not None and mission not in MISSIONS:
        raise ValueError(f"--mission: {mission!r} is not a mission; allowed: {', '.join(MISSIONS)}")
    dur = None if duration is None else _positive("--duration", duration, parse_duration)
    rate = None if fs is None else _positive("--fs", fs, float)
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise ValueError(f"--seed: {seed!r} is not allowed; allowed: an integer >= 0")
    for o in overrides:
        if not str(o).startswith("closed_loop."):
            raise ValueError(f"--set: {o!r} is not a closed-loop key; allowed: closed_loop.KEY=VALUE "
                             "(docs/scenarios.md#closed-loop)")
    if mission is not None:
        return _static_job(mission, check_output(output, "--output", {}), dur, rate, seed, overrides,
                           per_source)
    src = os.path.abspath(os.path.expanduser(os.fspath(run_file)))
    if not os.path.isfile(src):
        raise FileNotFoundError(f"RUN.h5: trajectory file {src!r} does not exist or is not a file")
    out = check_output(output, "--output", {"RUN.h5": src})
    traj = io.read_trajectory(src)
    scen = loads_scenario(traj.scenario_toml, list(overrides), source=f"{src} (attribute scenario) and --set")
    model = closed_loop_model(traj, scen.closed_loop, validate=True)
    s = model.settings
    dur, rate, seed, n = _series(model, dur, rate, seed)
    _check_size(model, n, out)
    settings = {**s, "fs": rate, "duration": float(dur), "seed": int(seed)}
    conf = resolved_configuration(scen.closed_loop, traj.spacecraft.architecture, settings, model.hinf)
    ta = traj.attrs
    attrs = {"mission": model.mission, "source_file": os.path.basename(src), "source_path": src,
             "source_sha256": file_sha256(src),
             "source_scenario_sha256": hashlib.sha256(traj.scenario_toml.encode("utf-8")).hexdigest(),
             "source_format_version": int(ta.get("format_version", 0)),
             "source_tqdyn_version": str(ta.get("tqdyn_version", "")),
             "source_epoch_utc": str(ta.get("epoch_utc", "")), "source_time_scale": str(ta.get("time_scale", "")),
             "configuration": json.dumps(conf), "closed_loop_toml": "\n".join(scen.closed_loop.to_toml_lines()),
             "seed": int(seed), "fs": float(rate), "duration_s": n / rate, "n_samples": n,
             "t0": float(model.t_span[0]), "satellite_names": json.dumps(list(model.satellite_names))}
    return ClosedLoopJob(traj=traj, model=model, output=out, duration_s=n / rate, fs=float(rate), seed=int(seed),
                         attrs=attrs, per_source=bool(per_source))


#: Memory of the budget per (segment, spacecraft, output, source, frequency) [bytes]: 3.3 float64
#: measured at the peak (the ASDs, the responses they come from); 4 with a margin.
BUDGET_BYTES_PER_POINT = 4 * 8


def _check_size(model, n_samples: int, out) -> None:
    """Refuse, before any work, a closed loop whose budget needs more memory than the machine has
    (ValueError naming closed_loop.n_freq) or whose time series -- streamed, so bounded by the disk,
    not the memory -- is larger than the free space where it goes (OutputIOError naming --duration
    and --fs; a lower bound: n_samples x (outputs x spacecraft + 1) float64)."""
    from ..closedloop.loop import output_names
    from .memory import check_memory, check_space, human_bytes

    n_freq = int(model.settings["n_freq"])
    per_freq = len(model.loops) * len(model.loops[0]) * len(output_names()) * max(len(model.noise), 1) \
        * BUDGET_BYTES_PER_POINT
    check_memory(n_freq * per_freq, f"closed_loop.n_freq = {n_freq}: the budget",
                 lambda budget: f"closed_loop.n_freq <= {int(budget // per_freq)}")
    row = (len(output_names(time_domain=True)) * len(model.loops) + 1) * 8
    check_space(n_samples * row, out, "the closed-loop file",
                f"a shorter --duration or a lower --fs (the file holds {human_bytes(row)} per sample)")


class _Counting:
    """A sink forwarding to ``sink`` and calling ``progress(n_rows)`` after each block."""

    def __init__(self, sink, progress):
        self.sink, self.progress = sink, progress

    def start(self, meta):
        self.sink.start(meta)

    def write(self, block):
        self.sink.write(block)
        if self.progress is not None:
            self.progress(len(block.t))

    def close(self):
        return self.sink.close()


def closed_loop_to_file(job: ClosedLoopJob, progress=None, block_size: int = 65536, budget=None,
                        wrap=None, budget_progress=None) -> ClosedLoopSummary:
    """Write the closed-loop file of ``job`` (:func:`check_closed_loop_inputs`): the budget
    (:func:`~tqdyn.analysis.closed_loop.closed_loop_budget`, per source when the job asks; or ``budget`` if
    given), then the time
    series streamed block by block (``progress(n)`` after each block of n samples; ``budget_progress(1)``
    after each of the budget's segment x spacecraft loops).  ``wrap``: a
    function of the writer returning the sink the simulation writes to (tests inject failures).
    On any failure or interrupt no file is left at the output path (the writer's temporary file
    exists from the start: an interrupt during the budget removes it too)."""
    from ..analysis.closed_loop import closed_loop_budget, closed_loop_timeseries
    from ..closedloop.loop import OUTPUTS

    try:
        with ClosedLoopWriter(job.output, job.attrs, units=OUTPUTS) as writer:
            t0 = time.perf_counter()
            ds = closed_loop_budget(job.model, progress=budget_progress, per_source=job.per_source) if budget is None \
                else budget
            t1 = time.perf_counter()
            writer.write_budget(ds)
            sink = _Counting(writer if wrap is None else wrap(writer), progress)
            closed_loop_timeseries(job.model, duration_s=job.duration_s, fs=job.fs, seed=job.seed, sink=sink,
                                   block_size=block_size)
    except OSError as exc:                 # the writer removed its temporary file (with-block)
        if isinstance(exc, io.OutputError):
            raise
        raise io.OutputIOError(f"cannot write the closed-loop file {str(job.output)!r}: "
                               f"{exc.strerror or exc}") from None
    t2 = time.perf_counter()
    path = writer.path
    return ClosedLoopSummary(path=path, size_bytes=os.path.getsize(path), n_samples=job.attrs["n_samples"],
                             n_sat=len(job.model.loops), budget_s=t1 - t0, timeseries_s=t2 - t1)
