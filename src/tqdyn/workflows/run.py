"""Run a scenario to a trajectory file: the job behind ``tqdyn run`` and ``tqdyn sweep``.

This module composes the library: it chooses the fields and root attributes
of the output file from the scenario, streams the propagator's rows into
:class:`tqdyn.formats.trajectory.TrajectoryWriter` (atomic: no file, or a
complete one), writes resumable checkpoints (file format:
:mod:`tqdyn.formats.checkpoint`) and resumes from them.  It prints nothing;
the CLI and the sweep driver report.

Errors: bad input (scenario, output path, data limits, a checkpoint of
another run) raises ``ValueError`` /
:class:`tqdyn.formats.trajectory.OutputError` before anything is written.
Any exception during the propagation (including ``KeyboardInterrupt``) is
re-raised after clean-up; its attribute ``tqdyn_checkpoint`` is the
checkpoint path if the run can be resumed (``--resume``), else None.  A
state that stops being finite (:class:`tqdyn.dynamics.NonFiniteStateError`) leaves no file and no
checkpoint (resuming would meet it again).  A
failed write (disk full, file-size limit) is an
:class:`tqdyn.formats.trajectory.OutputIOError`; the last checkpoint (if
any) and its partial trajectory stay valid for ``--resume``.
:func:`check_checkpoint` checks the checkpoint side of a run before any
work starts (the CLI calls it before its banner).
"""

from __future__ import annotations

import os
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..formats import trajectory as io
from .. import dynamics
from ..dynamics import Checkpoint, RunResult, row_names
from ..formats.atomic import same_file
from ..formats.checkpoint import read_checkpoint, write_checkpoint
from .heap import bound_heap_retention

__all__ = ["RunSummary", "run_to_file", "run_scenario_text", "one_line", "output_fields", "output_attrs",
           "spacecraft_attrs", "checkpoint_path", "check_checkpoint", "eop_attrs", "eop_warning", "load_run_scenario",
           "scenario_inputs", "scenario_of_trajectory"]


@dataclass(frozen=True)
class RunSummary:
    """What :func:`run_to_file` did.

    result : the propagator's :class:`~tqdyn.dynamics.RunResult`;
    path : the trajectory file; rows : time rows written;
    compile_s : JIT compilation / warm-up time [s] (0 when cached in-process).
    """

    result: RunResult
    path: Path
    rows: int
    compile_s: float

    @property
    def size_mb(self) -> float:
        """Size of the trajectory file in MB."""
        return self.path.stat().st_size / 1e6


def output_fields(scen) -> tuple[str, ...]:
    """Trajectory fields a run of ``scen`` writes (see :data:`tqdyn.formats.trajectory.FIELDS`)."""
    c = scen.constellation
    fields = [io.field_path(name) for name in row_names(c.coupled, c.free_tms)]
    return tuple(fields + (["tm/self_gravity"] if c.coupled else []))


def _eop_of(scen, model):
    """(table, source name) of the Earth orientation a run of ``scen`` uses
    (None, "off" without EOP or without an Earth field)."""
    if model is not None:
        return getattr(model, "eop", None), getattr(model, "eop_source", "off")
    if not scen.forces.earth_degree:
        return None, "off"
    from ..astro.eop_sources import eop_table

    eop = eop_table(scen.forces.eop)
    return eop, scen.forces.eop if eop is not None else "off"


def _run_span(scen):
    from ..astro.eop_sources import run_span_mjd

    return run_span_mjd(scen.epoch, float(scen.run.duration_s))


def eop_attrs(scen, model=None) -> dict:
    """The Earth-orientation root attributes of a run of ``scen`` (with
    ``model``'s table if given): ``eop`` (the source name), ``eop_sources``
    (which source covered which days of the run, the long-term model with
    its parameters) and ``eop_data`` (the files and the leap-second table)."""
    from ..astro.eop_sources import data_note, describe_coverage

    eop, source = _eop_of(scen, model)
    if eop is None and not scen.forces.earth_degree:
        return {"eop": "off", "eop_sources": "not used (forces.earth_degree = 0: no Earth field)",
                "eop_data": data_note(None)}
    return {"eop": source, "eop_sources": describe_coverage(eop, *_run_span(scen)), "eop_data": data_note(eop)}


def eop_warning(scen, model=None) -> str | None:
    """One line if a run of ``scen`` uses the long-term EOP model (beyond the
    IERS measurements and predictions), else None: for the CLI to print."""
    from ..astro.eop_sources import long_term_warning

    eop, _ = _eop_of(scen, model)
    return None if eop is None else long_term_warning(eop, *_run_span(scen))


def spacecraft_attrs(scen) -> dict:
    """The spacecraft root attributes of a coupled run of ``scen``
    (:data:`tqdyn.formats.trajectory.schema.SPACECRAFT_ATTRS`; ``{}`` for
    point-mass runs): the architecture, the drag-free scheme, the EH centres
    and MOSA pivots at the nominal opening angle (m, body frame S) and the
    TMs' sensitive axes (unit vectors, each in its OA_l) as JSON (2, 3)
    arrays, the nominal opening angle (rad)."""
    import json

    if not scen.constellation.coupled:
        return {}
    craft = scen.spacecraft.craft()

    def vectors(a):
        return json.dumps([[float(x) + 0.0 for x in row] for row in a])  # + 0.0: no negative zeros

    return {"spacecraft_architecture": craft.architecture, "dragfree_scheme": craft.scheme,
            "spacecraft_housing_centers": vectors(craft.nominal_housing_centers),
            "spacecraft_pivots": vectors(craft.pivots),
            "spacecraft_sensitive_axes": vectors(craft.sensitive_axes_array),
            "spacecraft_theta_nominal": float(craft.theta_nominal),
            "spacecraft_units": io.schema.SPACECRAFT_UNITS}


def integrator_label(integ) -> str:
    """The trajectory file's ``integrator`` attribute: "dp87-<mode>-<tableau>",
    or for the multistep method "multistep-<order>-<corrector>-dp87-<tableau>"
    (order, step stages, the DP87 tableau of its start-up)."""
    if integ.method == "multistep":
        return f"multistep-{integ.order}-{integ.corrector}-dp87-{integ.tableau}"
    return f"dp87-{integ.mode}-{integ.tableau}"


def output_attrs(scen, model=None) -> dict:
    """Root attributes of the trajectory file of ``scen`` (the EOP attributes
    from ``model``'s table if given, see :func:`eop_attrs`; the spacecraft
    attributes of a coupled run, see :func:`spacecraft_attrs`; the constants
    record of :mod:`tqdyn.scenario.record`)."""
    from ..scenario.record import constants_json, run_constants

    integ = scen.integrator
    c = scen.constellation
    ref = scen.reference
    return {
        "scenario": scen.to_toml(),
        "epoch_utc": scen.epoch_utc,
        **({"epoch_tdb": scen.epoch_tdb} if scen.epoch_tdb else {}),
        "origin": ref.origin,
        "frame": ref.frame,
        "time_scale": ref.time_scale,
        "precision": scen.run.precision,
        "step_s": float(integ.step_s),
        "integrator": integrator_label(integ),
        "pointing": c.pointing,
        "control": c.control,
        "free_tms": int(c.free_tms),
        **spacecraft_attrs(scen),
        **eop_attrs(scen, model),
        "constants": constants_json(run_constants(scen, model)),
    }


def scenario_of_trajectory(path, overrides=(), *, writes: bool = False):
    """(scenario, warnings) to run again what the trajectory file ``path``
    records: its resolved scenario (root attribute ``scenario``) with
    ``overrides`` (``"section.key=value"``, as ``--set``), and one line per
    thing this tqdyn would do differently from the file's run, compared with
    the file's constants record (root attribute ``constants``,
    :func:`tqdyn.scenario.record.compare_constants`, for the scenario without
    the overrides): none means the run reproduces the file bit for bit.
    A file written before ``forces.eop_interpolation`` existed (its resolved
    [forces] lacks the key) ran with the IERS 4-point scheme: it is re-run
    with "lagrange4", not with today's default.
    ``writes``: the run will write ``run.output``, which must not be ``path``.
    Raises FileNotFoundError, ValueError (one line: not a trajectory, no
    scenario, the output would replace ``path``) or ScenarioError."""
    from ..scenario import loads_scenario
    from ..scenario.record import compare_constants, run_constants

    attrs = io.read_attributes(path)
    text = attrs.get("scenario")
    src = f"{path} (attribute scenario)"
    if not isinstance(text, str) or not text.strip():
        raise ValueError(f"{path}: the trajectory records no scenario; allowed: a trajectory file written by tqdyn run")
    import tomllib

    try:
        old = "eop_interpolation" not in tomllib.loads(text).get("forces", {})
    except tomllib.TOMLDecodeError:
        old = False  # loads_scenario reports it
    legacy = ["forces.eop_interpolation=lagrange4"] if old else []
    scen = loads_scenario(text, legacy, source=src)
    notes = []
    recorded = attrs.get("constants")
    if recorded is None:
        notes.append(f"{path} records no constants (written by tqdyn {attrs.get('tqdyn_version', '?')}): the run "
                     "uses this tqdyn's constants and data files, and its defaults of keys the scenario lacks")
    else:
        diffs = compare_constants(recorded, run_constants(scen))
        if diffs:
            more = f" (and {len(diffs) - 1} more)" if len(diffs) > 1 else ""
            notes.append(f"{path}: this tqdyn will not reproduce the file's run: {diffs[0]}{more}")
    if overrides:
        scen = loads_scenario(text, [*legacy, *overrides], source=src)
    if writes and os.path.exists(os.path.expanduser(scen.run.output)) and same_file(scen.run.output, path):
        raise ValueError(f"run.output: {scen.run.output!r} is the trajectory the scenario is read from; allowed: "
                         "another file (-o OUT.h5, or --set run.output=OUT.h5)")
    return scen, notes


def scenario_inputs(scenario, scen) -> dict:
    """The files a run of ``scen`` reads, {label: path}: the scenario argument ``scenario`` when it is
    a file (a TOML file or a run file), ``forces.ephemeris`` when it is a path, ``initial.oem.N``; an
    output must be none of them (:func:`tqdyn.formats.atomic.check_output`)."""
    files = {}
    if scenario is not None and os.path.isfile(os.fspath(scenario)):
        files["SCENARIO"] = scenario
    if scen.forces.ephemeris != "de421":
        files["forces.ephemeris"] = scen.forces.ephemeris
    for k, path in enumerate(scen.initial.oem, start=1):
        files[f"initial.oem.{k}"] = path
    return files


def load_run_scenario(scenario=None, overrides=(), *, writes: bool = False):
    """(scenario, warnings) of ``scenario``: a trajectory file (HDF5: its
    recorded run, :func:`scenario_of_trajectory`; ``writes`` as there), else
    a built-in name or a TOML path (:func:`tqdyn.scenario.load_scenario`, no
    warnings)."""
    from ..scenario import load_scenario

    if scenario is not None and io.is_trajectory_file(scenario):
        return scenario_of_trajectory(scenario, overrides, writes=writes)
    return load_scenario(scenario, overrides), []


def checkpoint_path(output) -> Path:
    """Checkpoint file of a run writing ``output``: ``<output>.checkpoint``."""
    p = Path(output)
    return p.with_name(p.name + ".checkpoint")


def check_checkpoint(scen, resume: bool) -> None:
    """Check, before any work, what the checkpoint of a run of ``scen``
    needs: without ``resume`` there must be no checkpoint (it would be
    lost); with it, the checkpoint must be readable, belong to the same
    scenario and precision, and its partial trajectory must exist.
    Raises ``ValueError`` (one line naming the file) otherwise."""
    out_path = io.check_writable(scen.run.output)
    ckpt = checkpoint_path(out_path)
    if resume:
        data = _read_own_checkpoint(ckpt, scen)
        try:
            io.TrajectoryWriter.check_partial(data.partial, data.rows)
        except io.OutputError as exc:
            raise ValueError(f"--resume: {exc}; remove the checkpoint {ckpt} to start again") from None
    elif ckpt.exists():
        raise ValueError(f"{ckpt} holds the checkpoint of an interrupted run: continue it with "
                         f"--resume, or delete it to start again")


def run_to_file(scen, *, model=None, progress: Callable[[int], None] | None = None,
                checkpoint_every: int = 0, resume: bool = False, checkpoint_interval_s: float = 0.0) -> RunSummary:
    """Propagate ``scen`` and write its trajectory to ``scen.run.output``.

    Parameters
    ----------
    scen : :class:`tqdyn.scenario.Scenario`.
    model : the force model (built from ``scen.forces`` if None).
    progress : called with the number of steps done since the last call
        (fixed mode) or the seconds advanced (adaptive mode).
    checkpoint_every : write a checkpoint ``<output>.checkpoint`` every that
        many steps (fixed mode; 0 = never).  An interrupted run keeps it and
        its partial trajectory; ``resume=True`` continues it to the same file
        bit for bit.
    checkpoint_interval_s : also write one at the first chunk boundary after
        this many seconds of wall-clock time since the last (fixed mode; 0 =
        never).
    resume : continue from the checkpoint (it must belong to the same
        resolved scenario and precision).
    """
    out_path = io.check_writable(scen.run.output)
    bound_heap_retention()
    if model is None:
        model = dynamics.check_inputs(scen)
    fixed = scen.integrator.mode == "fixed"
    if not fixed:
        checkpoint_every, checkpoint_interval_s = 0, 0.0
    ckpt = checkpoint_path(out_path)
    if resume:
        start, writer_factory = _resume(ckpt, scen, out_path)
    else:
        if ckpt.exists():
            raise ValueError(f"{ckpt} holds the checkpoint of an interrupted run: continue it with "
                             f"--resume, or delete it to start again")
        start = None
        writer_factory = None
    t0 = time.perf_counter()
    try:
        dynamics.warm_up(scen.run.precision, scen.integrator.method, dynamics.build_system(scen, model).cpar,
                         model=model)
    except OSError as exc:  # numba could not write its cache (disk full, file-size limit)
        raise io.OutputIOError(f"JIT compilation could not write numba's cache: {exc.strerror or exc}; free "
                               f"space, or set NUMBA_CACHE_DIR to a writable directory") from None
    compile_s = time.perf_counter() - t0
    if writer_factory is not None:
        writer = writer_factory()
        try:
            writer.check_headroom()
        except io.OutputIOError as exc:
            writer.keep_partial()
            exc.tqdyn_checkpoint = ckpt
            raise
    else:
        writer = io.TrajectoryWriter(out_path, output_attrs(scen, model), output_fields(scen),
                                     n_sat=len(scen.satellites),
                                     expected_rows=scen.n_steps // scen.run.output_every + 1)
        if scen.constellation.coupled:
            writer.set_static("tm/self_gravity", dynamics.self_gravity_oa(scen))

    def save_checkpoint(c: Checkpoint):
        partial = writer.sync()
        try:
            write_checkpoint(ckpt, scenario=scen.to_toml(), precision=scen.run.precision, n=c.n, y=c.y,
                             comp=c.comp, partial=partial, rows=writer.rows_written, table=c.table)
        except OSError as exc:  # disk full: the previous checkpoint (if any) stays valid
            raise io.OutputIOError(f"cannot write the checkpoint {str(ckpt)!r}: "
                                   f"{exc.strerror or exc}") from None
        # stop here, with a consistent partial file, rather than in the middle of a write
        writer.check_headroom()

    try:
        result = dynamics.propagate(scen, sink=lambda rows: writer.append(io.row_fields(rows)), progress=progress, model=model, start=start,
                                      checkpoint=save_checkpoint, checkpoint_every=checkpoint_every,
                                      checkpoint_interval_s=checkpoint_interval_s)
        rows = writer.rows_written
        writer.close()
    except BaseException as exc:
        # keep the partial trajectory while a checkpoint refers to it; else discard it.  A state that is
        # not finite would come back on resuming: nothing is kept (no file, no checkpoint).
        if isinstance(exc, dynamics.NonFiniteStateError):
            ckpt.unlink(missing_ok=True)
        resumable = ckpt.exists()
        writer.keep_partial() if resumable else writer.abort()
        try:
            exc.tqdyn_checkpoint = ckpt if resumable else None
        except AttributeError:  # pragma: no cover - exceptions without a __dict__
            pass
        raise
    ckpt.unlink(missing_ok=True)
    return RunSummary(result=result, path=out_path, rows=rows, compile_s=compile_s)


def one_line(exc: BaseException) -> str:
    """``"<ExceptionType>: <message>"`` on one line (white space folded)."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def run_scenario_text(scenario_toml: str, source: str = "scenario") -> dict:
    """Run one resolved scenario (its TOML text) to its file, as a worker
    task does: never raises.  Returns ``{"ok": True, "rows", "wall_s",
    "compile_s"}`` (rows written, propagation and JIT seconds) or ``{"ok":
    False, "error": one line, "traceback": text}``.  ``source`` names the
    scenario in error messages."""
    from ..scenario import loads_scenario

    try:
        summary = run_to_file(loads_scenario(scenario_toml, source=source))
    except Exception as exc:  # noqa: BLE001 - reported per task; the others go on
        return {"ok": False, "error": one_line(exc), "traceback": traceback.format_exc()}
    return {"ok": True, "rows": int(summary.rows), "wall_s": float(summary.result.wall_s),
            "compile_s": float(summary.compile_s)}


def _read_own_checkpoint(ckpt_path, scen):
    """The checkpoint of a run of ``scen`` (ValueError if missing, damaged or another run's)."""
    if not ckpt_path.exists():
        raise ValueError(f"--resume: no checkpoint {ckpt_path} to continue from")
    data = read_checkpoint(ckpt_path)
    if data.scenario != scen.to_toml() or data.precision != scen.run.precision:
        raise ValueError(f"--resume: the checkpoint {ckpt_path} belongs to a different scenario or "
                         f"precision; give the same arguments as the interrupted run")
    return data


def _resume(ckpt_path, scen, out_path):
    """(Checkpoint, writer factory) of an interrupted run; ValueError if
    there is none or it belongs to another scenario."""
    data = _read_own_checkpoint(ckpt_path, scen)
    start = Checkpoint(data.n, data.y, data.comp, data.table)
    partial, rows = data.partial, data.rows
    return start, lambda: io.TrajectoryWriter.reopen(partial, out_path, rows)
