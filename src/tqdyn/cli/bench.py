"""Command line: ``tqdyn bench [--model NAME ...] [--duration D] [--step S] [--no-heyoka] [--json PATH]``.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(bench)``.  It only
composes :mod:`tqdyn.workflows.bench` (and :mod:`.bench_kernels`,
:mod:`.bench_mission`) and prints their tables; ``--json PATH`` also writes
every result into a record (:mod:`tqdyn.workflows.numbers`), one entry per
model with its own command, date, machine and library versions, updating
the entries of the models that ran and keeping the others.  Bad input exits
with status 2 and one line on stderr, before anything runs.
"""

from __future__ import annotations

import os
from pathlib import Path

import click

from ._common import Choice, fail as _fail, guarded

__all__ = ["bench", "MODELS", "ALL_MODELS"]

#: Every model, in the order they run.
MODELS = ("kepler", "full", "coupled", "lisa", "lisa-coupled", "kernels", "default-run", "startup", "tianqin-5y",
          "tianqin-5y-multistep", "lisa-10y", "closed-loop", "closed-loop-budget-90d", "closed-loop-budget-lisa-1y",
          "od-coupled-30d")
#: What ``--model all`` runs (the mission-length commands are asked for by name).
ALL_MODELS = ("kepler", "full", "coupled", "lisa", "lisa-coupled", "kernels")


def _check_json_path(path) -> Path:
    from ..workflows.numbers import read_record

    p = Path(os.path.abspath(os.path.expanduser(path)))
    if p.is_dir():
        _fail(f"--json: {str(p)!r} is a directory; allowed: a JSON file path")
    if not p.parent.is_dir():
        _fail(f"--json: the directory of {str(p)!r} does not exist; allowed: a path in an existing directory")
    if not os.access(p.parent, os.W_OK):
        _fail(f"--json: the directory of {str(p)!r} is not writable; allowed: a writable directory")
    try:
        data = read_record(p)
    except ValueError as exc:
        _fail(f"--json: {exc}")
    if data and data.get("written_by") != "tqdyn bench":
        _fail(f"--json: {str(p)!r} was not written by tqdyn bench; allowed: a bench record, or a new path")
    return p


@click.command("bench")
@click.option("--duration", default=None,
              help="Propagated span [default: 90d; lisa: 3652.5d = 10 years; lisa-coupled: 365d; rounded up to "
                   "whole 6 h steps; default-run: the scenario's 10 d; tianqin-5y(-multistep): 1826d; lisa-10y: 3653d; "
                   "closed-loop: the time series, 3d; closed-loop-budget-90d: 90d; closed-loop-budget-lisa-1y: "
                   "365d; od-coupled-30d: 30d].")
@click.option("--step", default="50", show_default=True, help="Step / output grid [s] of the kepler model.")
@click.option("--no-heyoka", is_flag=True, help="Skip the heyoka real128 peer even if installed.")
@click.option("--model", "which", type=Choice(MODELS + ("all",), doc="docs/commands.md#tqdyn-bench"), multiple=True,
              help="kepler: monopole only; full: the full force model, pure gravity (and the reduced model vs "
                   "heyoka); coupled: the full coupled run (attitude + drag-free control); lisa: the heliocentric "
                   "lisa-esa scenario (ESA's orbits and force model, point masses); lisa-coupled: the coupled "
                   "lisa scenario (LISA architecture and drag-free scheme, one year); kernels: the time-only inputs "
                   "of one chunk, term by term, and the compiled kernels per evaluation; default-run: the command "
                   "`tqdyn run` (10 days); startup: `tqdyn run --duration 1h` with each integrator (DP87, "
                   "multistep), first with an empty kernel cache (compilation clocked), then with it filled; tianqin-5y: `tqdyn run tianqin` for five years with DP87; "
                   "tianqin-5y-multistep: the same "
                   "with the multistep method; lisa-10y: `tqdyn run "
                   "lisa` for ten years; closed-loop: the closed-loop time series of 3 TianQin spacecraft, "
                   "3 days at 4 Hz, streamed to a file; closed-loop-budget-90d / closed-loop-budget-lisa-1y: "
                   "tqdyn closed-loop's model, budget and file of a 90-day TianQin / one-year LISA run (made "
                   "first, not timed), time and peak memory; od-coupled-30d: a 30-day coupled TianQin recovery (GNSS + SLR + "
                   "ISR) fitted with the variational equations and with central differences, against the 30-day "
                   "run; all: " + ", ".join(ALL_MODELS) + " [default]. Repeatable.")
@click.option("--json", "json_path", metavar="PATH",
              help="Also write the results to this JSON record: the entries of the models run are replaced, "
                   "the others kept (docs/numbers.md).")
def bench(duration, step, no_heyoka, which, json_path):
    """Benchmarks: Kepler (3 TianQin satellites, Earth monopole: tqdyn dd vs
    float64 vs heyoka real128 on the same grid), the force model (full
    model dd / float64, reduced model dd vs heyoka real128), the coupled
    constellation (dd / float64), LISA (heliocentric point masses, 10
    years, dd / float64), the coupled LISA constellation (one year), the
    kernels, and whole `tqdyn run` commands (default run, five years of
    TianQin, ten years of LISA)."""
    from ..scenario import ScenarioError
    from ..workflows import bench as _bench
    from ..workflows import bench_closed_loop as _closed_loop
    from ..workflows import bench_kernels as _kernels
    from ..workflows import bench_mission as _mission
    from ..workflows import bench_od as _od
    from ..workflows import numbers as _numbers

    chosen = set()
    for w in which or ("all",):
        chosen.update(ALL_MODELS if w == "all" else (w,))
    models = [m for m in MODELS if m in chosen]
    path = _check_json_path(json_path) if json_path else None
    if duration is not None:
        from ..scenario.loader import parse_duration

        try:
            if not parse_duration(duration) > 0:
                raise ValueError
        except (ScenarioError, ValueError, ArithmeticError):
            _fail(f"--duration: {duration!r} is not a duration; allowed: seconds or a number with s, min, h, d "
                  "(e.g. 90d), greater than 0")

    def command(model):
        return ("tqdyn bench --model " + model + (f" --duration {duration}" if duration else "")
                + (f" --step {step}" if step != "50" and model == "kepler" else "")
                + (" --no-heyoka" if no_heyoka and model in ("kepler", "full") else "")
                + (f" --json {json_path}" if json_path else ""))

    span = duration or "90d"
    runners = {
        "kepler": lambda: (_bench.kepler_benchmark(duration=span, step=step, heyoka=not no_heyoka),
                           _bench.format_report),
        "full": lambda: (_bench.force_model_benchmark(duration=span, heyoka=not no_heyoka), _bench.format_force_report),
        "coupled": lambda: (_bench.coupled_benchmark(duration=span), _bench.format_coupled_report),
        "lisa": lambda: (_bench.lisa_benchmark(duration=duration or _bench.LISA_DURATION), _bench.format_lisa_report),
        "lisa-coupled": lambda: (_bench.lisa_benchmark(duration=duration or _bench.LISA_COUPLED_DURATION,
                                                       scenario="lisa"), _bench.format_lisa_report),
        "kernels": lambda: (_kernels.kernels_benchmark(), _kernels.format_kernels_report),
    }
    runners["closed-loop"] = lambda: (_closed_loop.closed_loop_benchmark(duration),
                                      _closed_loop.format_closed_loop_report)
    for name in _closed_loop.BUDGET_RUNS:
        runners[name] = lambda name=name: (_closed_loop.closed_loop_budget_benchmark(name, duration),
                                           _closed_loop.format_budget_report)
    runners["od-coupled-30d"] = lambda: (_od.od_coupled_benchmark(duration), _od.format_od_coupled_report)
    runners["startup"] = lambda: (_mission.startup_benchmark(duration), _mission.format_startup_report)
    for name in _mission.MISSION_RUNS:
        runners[name] = lambda name=name: (_mission.mission_benchmark(name, duration), _mission.format_mission_report)
    done: list[str] = []

    def note(exc) -> str:
        if path is None:
            return "no output file written"
        return (f"the record {path} holds the models that finished ({', '.join(done)})" if done else
                f"the record {path} is as it was")

    for model in models:
        prov = _numbers.provenance("tqdyn bench", command(model))
        with guarded(note, bad_input=(ScenarioError, ValueError)):
            try:
                result, fmt = runners[model]()
            except RuntimeError as exc:
                _fail(str(exc), 1)
            click.echo(fmt(result))
            if path is not None:
                entry = {**prov, "model": model, "result": result}
                entry.pop("written_by")
                _numbers.merge_section(path, "models", {model: entry},
                                       {"written_by": "tqdyn bench",
                                        "description": "results of tqdyn bench --json, one entry per model, each "
                                                       "with the command, date, machine and library versions of its "
                                                       "run"})
        done.append(model)
