"""Command line: ``tqdyn run [SCENARIO] [--duration ...] [--set KEY=VALUE ...] [--resume]``.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(run)``.  It only
composes library calls: it resolves the scenario, checks the output path,
runs the propagator (:func:`tqdyn.workflows.run.run_to_file`) with a
progress bar, streams the rows into the HDF5 writer and prints a short
summary.  Bad input exits with status 2 and one line on stderr (no
traceback, no partial output file), checked before the banner; a failed
write (disk full, file-size limit) exits with status 3, one line; Ctrl-C
(130), SIGTERM (143) and SIGHUP (129) keep the last checkpoint for
``--resume``.  See docs/reliability.md.
"""

from __future__ import annotations

import sys

import click

from .._version import __version__
from ._common import Choice, _overrides, fail as _fail, guarded

__all__ = ["run"]


def _format_state_table(scenario, y_dd) -> list[str]:
    import numpy as np

    lines = []
    for sat, row in zip(scenario.satellites, y_dd):
        r = row[0:3, 0] + row[0:3, 1]
        v = row[3:6, 0] + row[3:6, 1]
        lines.append(f"  {sat.name:<6} r = [{r[0]: .9e}, {r[1]: .9e}, {r[2]: .9e}] m"
                     f"  |r| = {np.linalg.norm(r):.6f} m  |v| = {np.linalg.norm(v):.9f} m/s")
    return lines


def _checkpoint_interval(text) -> float:
    """``--checkpoint-interval`` in seconds (>= 0, finite); ValueError naming the option."""
    import math

    from ..scenario import ScenarioError
    from ..scenario.loader import parse_duration

    try:
        v = float(parse_duration(text))
    except (ScenarioError, ValueError, ArithmeticError):
        v = float("nan")
    if not (math.isfinite(v) and v >= 0):
        raise ValueError(f"--checkpoint-interval: {text!r} is not a duration; allowed: >= 0 seconds, or with a unit "
                         "(30min, 2h, 1d); 0 = never")
    return v


@click.command("run")
@click.argument("scenario", required=False)
@click.option("--duration", help="Propagation span: seconds, or with a unit: 90d, 12h, 30min, 3600s.")
@click.option("--step", help="Integrator step [s] (fixed mode) or output interval (adaptive mode).")
@click.option("--output", "-o", help="Output HDF5 trajectory file.")
@click.option("--precision", type=Choice(["dd", "float64"]), help="Arithmetic of the propagation.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override a scenario value, e.g. --set integrator.mode=adaptive or "
                   "--set satellites.2.nu_deg=151 (repeatable).")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@click.option("--checkpoint-every", type=click.IntRange(min=0), default=20000, show_default=True,
              help="Write a resumable checkpoint every N steps (fixed mode; 0 = never).")
@click.option("--checkpoint-interval", default="0", show_default=True, metavar="DURATION",
              help="Also write a checkpoint after this much wall-clock time since the last one, at the next chunk "
                   "of steps (fixed mode): seconds or 30min, 2h; 0 = never.")
@click.option("--resume", is_flag=True, help="Continue an interrupted run from its checkpoint (same arguments).")
def run(scenario, duration, step, output, precision, sets, quiet, checkpoint_every, checkpoint_interval, resume):
    """Propagate SCENARIO (a built-in name or a TOML file; default: tianqin)
    and write the trajectory file.  SCENARIO may also be a trajectory file
    RUN.h5: its recorded scenario runs again (give another -o), reproducing
    the file bit for bit unless a warning says what differs.  Interrupted
    runs (Ctrl-C, a crash) keep their last checkpoint; `--resume` continues
    them to a bit-identical file."""
    from tqdm import tqdm

    from ..formats import trajectory as io
    from ..formats.atomic import check_output
    from ..formats.stop import check_stop
    from .. import dynamics
    from ..workflows import run as runner
    from ..scenario import ScenarioError

    try:
        interval_s = _checkpoint_interval(checkpoint_interval)
        scen, notes = runner.load_run_scenario(scenario, _overrides(sets, duration, step, output, precision),
                                               writes=True)
        check_output(scen.run.output, "run.output", runner.scenario_inputs(scenario, scen))
        runner.check_checkpoint(scen, resume)
        model = dynamics.check_inputs(scen)
    except (ScenarioError, io.OutputError, ValueError, FileNotFoundError) as exc:
        _fail(str(exc))
    integ = scen.integrator
    fixed = integ.mode == "fixed"
    n_total = scen.n_steps
    c = scen.constellation
    click.echo(f"tqdyn {__version__}: scenario {scen.name!r}, {len(scen.satellites)} satellite(s), "
               f"{scen.run.precision} precision, "
               + (f"multistep order {integ.order} {integ.corrector.upper()} (DP87 start-up) "
                  if integ.method == "multistep" else f"DP87 {integ.mode} ")
               + (f"{integ.step_s} s x {n_total} steps" if fixed else f"rtol {integ.rtol}, output every {integ.step_s} s")
               + f", {scen.run.duration_s} s from {scen.epoch.iso}"
               + (f"; pointing {c.pointing}, control {c.control}" + (", free TMs" if c.free_tms else "")
                  if c.coupled else ""), err=True)
    for note in notes + [runner.eop_warning(scen, model)]:
        if note:
            click.echo(f"tqdyn: warning: {note}", err=True)
    state = {"bar": None}

    def progress(n):
        check_stop()  # SIGTERM / SIGHUP: stop here, between two chunks of steps
        if state["bar"] is None:
            state["bar"] = tqdm(total=n_total if fixed else float(scen.run.duration_s),
                                disable=True if quiet else None, unit="step" if fixed else "s",
                                unit_scale=not fixed, file=sys.stderr, dynamic_ncols=True, desc="propagating")
        state["bar"].update(n)

    def close_bar():
        if state["bar"] is not None:
            state["bar"].close()

    def note(exc) -> str:
        ckpt = getattr(exc, "tqdyn_checkpoint", None)
        if not ckpt:
            return "no output file written"
        if isinstance(exc, io.OutputIOError):
            return f"the checkpoint {ckpt} is kept: free space, then continue with the same command and --resume"
        return f"continue with the same command and --resume (checkpoint {ckpt})"

    with guarded(note, cleanup=close_bar, deferred=True):
        try:
            summary = runner.run_to_file(scen, model=model, progress=progress,
                                         checkpoint_every=checkpoint_every if fixed else 0, resume=resume,
                                         checkpoint_interval_s=interval_s if fixed else 0.0)
        except io.OutputIOError:
            raise
        except (ValueError, io.OutputError) as exc:
            close_bar()
            if isinstance(exc, dynamics.NonFiniteStateError):
                _fail(f"{exc}; no output file written")
            if hasattr(exc, "tqdyn_checkpoint") and not isinstance(exc, io.OutputError):
                raise  # a failure inside the propagation, not bad input
            _fail(str(exc))
    close_bar()
    result = summary.result
    lines = [
        f"steps: {result.n_steps} accepted" + (f", {result.n_rejected} rejected" if not fixed else "")
        + f", {result.n_rhs} right-hand-side evaluations",
        f"wall time: {result.wall_s:.2f} s propagation (+ {summary.compile_s:.2f} s JIT compilation)",
        f"final states ({result.reference.frame}, t = {result.t_final[0] + result.t_final[1]:.3f} s "
        f"{result.reference.time_scale} after the epoch):",
        *_format_state_table(scen, result.y_final),
    ]
    if result.energy_rel_drift is not None:
        lines.append("two-body energy drift (relative): "
                     + ", ".join(f"{s.name} {d:.2e}" for s, d in zip(scen.satellites, result.energy_rel_drift)))
    for key, text in result.extra.items():
        lines.append(f"{key}: {text}")
    lines.append(f"output: {summary.path} ({summary.rows} rows, {summary.size_mb:.1f} MB)")
    click.echo("\n".join(lines))
