"""Command line: ``tqdyn report RUN.h5 [RUN.h5 ...]`` and ``tqdyn report --studies``.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(report)``.  It only
composes :mod:`tqdyn.workflows.report` and :mod:`tqdyn.workflows.studies`:

* ``tqdyn report RUN.h5 [...] [--out DIR]``: figures (PNG and PDF) of what
  the runs contain, ``DIR/summary.md`` and ``DIR/summary.json`` (every
  number of the table, machine-readable, with its provenance);
* ``tqdyn report --studies [--mission tianqin|lisa] [--runs-dir DIR] [--out DIR]
  [--quick | --duration-scale X] [--study NAME ...] [--set KEY=VALUE ...]
  [--workers N]``: runs (or reuses) the study runs of the paper's section V
  and regenerates its figures and the summary table (paper value vs tqdyn
  value); with ``--mission lisa`` the same studies on LISA and Taiji
  (:mod:`tqdyn.workflows.studies_lisa`, :mod:`tqdyn.workflows.report.lisa`:
  one-year runs, reference = first-order estimates and ESA's files);
* ``tqdyn report --closed-loop [--out DIR]``: the default closed-loop designs of TianQin, LISA and
  Taiji at the working points of short coupled runs (:mod:`tqdyn.workflows.report.closed_loop`):
  ``DIR/closed-loop/*.png|pdf`` (budget stacks, loop gains with margins, residual TM acceleration
  against the requirement, the single-link TTL budget of the six links and the worst link's TTL by
  source), ``DIR/summary.md`` and ``DIR/summary.json``.

Bad input (a missing file, a file that is not a tqdyn trajectory, an unknown
study, bad overrides, conflicting options, an input that the report would
replace) exits with status 2 and one line ``tqdyn: error: ...`` on stderr,
before anything is run or written.  The report's files are written into a
hidden temporary directory and moved into DIR when complete
(:func:`tqdyn.formats.atomic.replacing_directory`): a full disk (status 3),
Ctrl-C (130) or SIGTERM (143) leave DIR as it was (:func:`._common.guarded`).
Progress goes to stderr, the summary table to stdout.  Exit status 1 if a
study run failed (the report of the others is still written).
"""

from __future__ import annotations

import sys

import click

from .._version import __version__
from ._common import EXIT_FAILED as _EXIT_RUN_FAILED
from ._common import Choice, fail as _fail, guarded

__all__ = ["report"]


@click.command("report", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("runs", nargs=-1, metavar="[RUN.h5 ...]")
@click.option("--out", "-o", "out", metavar="DIR",
              help="Output directory of the figures and summary.md (default: tqdyn-report; with --studies: "
                   "tqdyn-studies).")
@click.option("--studies", is_flag=True,
              help="Run (or reuse) the study runs of the paper's section V and regenerate its figures and table.")
@click.option("--closed-loop", "closed_loop", is_flag=True,
              help="The default closed-loop designs of the three missions at the working points of short coupled "
                   "runs: budget stacks, loop gains with margins, residual TM acceleration (docs/closed-loop.md), "
                   "single-link TTL budgets (docs/tilt-to-length.md).")
@click.option("--mission", type=Choice(["tianqin", "lisa"]), default=None,
              help="With --studies: the study set, tianqin (the paper's section V, default) or lisa (the same "
                   "studies on LISA and Taiji, one-year runs).")
@click.option("--runs-dir", metavar="DIR", help="With --studies: directory of the study runs (default: OUT/runs).")
@click.option("--quick", is_flag=True, help="With --studies: durations scaled by 1/90 (90 d -> 1 d, 30 d -> 8 h; "
                                            "lisa: 365 d -> 4 d).")
@click.option("--duration-scale", type=float, metavar="X",
              help="With --studies: factor on the paper's spans (default 1: 90 d and 30 d; lisa: 365 d).")
@click.option("--study", "only", multiple=True, metavar="NAME",
              help="With --studies: only this study (repeatable); default all.")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="With --studies: override applied to every study run (repeatable), e.g. forces.earth_degree=2.")
@click.option("--workers", type=int, metavar="N",
              help="With --studies: worker processes for the runs (default: the CPU cores; 1 = in this process).")
@click.option("--quiet", "-q", is_flag=True, help="No progress on stderr.")
def report(runs, out, studies, closed_loop, mission, runs_dir, quick, duration_scale, only, sets, workers, quiet):
    """Figures and a summary table of trajectory files RUN.h5, or (--studies)
    of the paper's section V: pointing laws (Fig. 5), range ASDs (Figs. 6,
    10, 11), electrostatic control (Figs. 7, 8), drag-free and self-gravity
    orbit deviations and breathing angles (Fig. 9); with --mission lisa the
    same studies on LISA and Taiji (one year) against first-order estimates
    and ESA's orbit files."""
    def say(msg):
        if not quiet:
            click.echo(msg, err=True)

    if closed_loop:
        if runs:
            _fail(f"RUN.h5: {runs[0]!r} given with --closed-loop; allowed: either trajectory files or --closed-loop")
        if studies:
            _fail("--closed-loop: conflicts with --studies; allowed: one of them")
        for name, given in (("--mission", mission is not None), ("--runs-dir", runs_dir is not None),
                            ("--quick", quick), ("--duration-scale", duration_scale is not None),
                            ("--study", bool(only)), ("--set", bool(sets)), ("--workers", workers is not None)):
            if given:
                _fail(f"{name}: only applies with --studies")
        _run_closed_loop(out or "tqdyn-closed-loop", say)
        return
    if studies:
        if runs:
            _fail(f"RUN.h5: {runs[0]!r} given with --studies; allowed: either trajectory files or --studies")
        _run_studies(out or "tqdyn-studies", runs_dir, quick, duration_scale, only, sets, workers, quiet, say,
                     mission or "tianqin")
        return
    for name, given in (("--mission", mission is not None), ("--runs-dir", runs_dir is not None), ("--quick", quick),
                        ("--duration-scale", duration_scale is not None), ("--study", bool(only)),
                        ("--set", bool(sets)), ("--workers", workers is not None)):
        if given:
            _fail(f"{name}: only applies with --studies")
    if not runs:
        _fail("RUN.h5: no trajectory file given; allowed: one or more tqdyn trajectory files, or --studies")
    from ..formats import trajectory as io
    from ..workflows import report as rp

    def make(stage):
        rep = rp.report_runs(runs, stage, progress=say)
        rp.write_summary_json(rep, " ".join(["tqdyn report", *runs] + (["--out", out] if out else [])),
                              runs={str(r): _file_facts(r) for r in runs})
        return rep

    with guarded(bad_input=(FileNotFoundError, io.TrajectoryFormatError, ValueError, ImportError)):
        _check_report_inputs(runs, out or "tqdyn-report")
        rep = _staged(out or "tqdyn-report", make)
    _print_report(rep)


#: the names of the files a report writes besides its figures (*.png, *.pdf)
_REPORT_FILES = ("summary.md", "summary.json")


def _check_report_inputs(runs, out) -> None:
    """Refuse (ValueError, one line) an input RUN.h5 that a report into ``out`` would replace: a file of
    ``out`` named as a report file (summary.md, summary.json, *.png, *.pdf)."""
    import os

    from ..formats.atomic import same_file

    for r in runs:
        parent, name = os.path.dirname(os.path.abspath(r)), os.path.basename(r)
        if (os.path.isdir(out) and same_file(parent, out)
                and (name in _REPORT_FILES or name.lower().endswith((".png", ".pdf")))):
            raise ValueError(f"--out: {out!r} would replace the input RUN.h5 {r!r} (a report writes "
                             f"{', '.join(_REPORT_FILES)} and *.png, *.pdf there); allowed: another directory")


def _staged(out, make):
    """The report ``make(directory)`` written into a hidden temporary directory and moved into ``out`` when
    complete (:func:`tqdyn.formats.atomic.replacing_directory`: a fault leaves ``out`` as it was); its
    paths point into ``out``."""
    from ..formats.atomic import check_directory, replacing_directory

    final = check_directory(out, "--out")
    with replacing_directory(final, "--out") as stage:
        rep = make(stage)

    def moved(p):
        return None if p is None else final / p.relative_to(stage)

    rep.out_dir, rep.summary_path = final, moved(rep.summary_path)
    rep.figures = [moved(p) for p in rep.figures]
    return rep


def _run_closed_loop(out, say):
    from ..workflows import report as rp
    from ..workflows.report.closed_loop import RUNS, report_closed_loop

    def make(stage):
        rep = report_closed_loop(stage, progress=say)
        rp.write_summary_json(rep, f"tqdyn report --closed-loop --out {out}",
                              runs={m: {"scenario": r[0], "overrides": list(r[1]), "description": r[2]}
                                    for m, r in RUNS.items()})
        return rep

    with guarded(bad_input=(ValueError,)):
        rep = _staged(out, make)
    _print_report(rep)


def _file_facts(path, rows=None, wall_s=None) -> dict:
    """Size [MB] (and rows, wall time [s] when known) of a trajectory file."""
    import os

    size = os.path.getsize(path) / 1e6 if path is not None and os.path.exists(path) else None
    return {"file_mb": size, "rows": rows, "wall_s": wall_s}


def _print_report(rep) -> None:
    click.echo(rep.summary_path.read_text(encoding="utf-8").rstrip())
    pngs = sorted(p.name for p in rep.figures if p.suffix == ".png")
    click.echo(f"\nfigures ({len(rep.figures)} files, PNG and PDF) in {rep.out_dir}: " + ", ".join(pngs))
    click.echo(f"summary: {rep.summary_path}")


def _run_studies(out, runs_dir, quick, duration_scale, only, sets, workers, quiet, say, mission="tianqin"):
    from pathlib import Path

    from tqdm import tqdm

    from ..formats.atomic import check_directory
    from ..workflows import studies as st
    from ..workflows import report as rp
    from ..workflows.sweep.execute import default_workers

    if quick and duration_scale is not None:
        _fail("--quick: conflicts with --duration-scale; allowed: one of them")
    if workers is not None and workers < 1:
        _fail(f"--workers: {workers} is not a number of workers; allowed: an integer >= 1")
    if mission == "lisa":
        from ..workflows import studies_lisa as sl
        from ..workflows.report.lisa import report_lisa_studies

        catalogue = {"catalogue": sl.STUDIES, "runs": sl.RUNS}
        quick_scale = sl.QUICK_SCALE
    else:
        catalogue = {}
        quick_scale = st.QUICK_SCALE
    scale = quick_scale if quick else (1.0 if duration_scale is None else duration_scale)
    runs_dir = runs_dir or str(Path(out) / "runs")
    names = tuple(only) or None
    try:
        if duration_scale is not None:
            st.scaled_duration_s(1.0, duration_scale, 50.0)  # validates the scale
        plan = st.plan_studies(runs_dir, studies=names, duration_scale=scale, extra_overrides=sets, **catalogue)
        check_directory(out, "--out")
    except (ValueError, FileNotFoundError) as exc:
        _fail(str(exc))
    pending = [p for p in plan if not p.done]
    n = min(workers or default_workers(), max(len(pending), 1))
    say(f"tqdyn {__version__}: {len(plan)} study runs (duration scale {scale:g}) in {Path(runs_dir).resolve()}: "
        f"{len(plan) - len(pending)} reused, {len(pending)} to run"
        + (f" on {n} worker process{'es' if n != 1 else ''}" if pending else ""))
    bar = tqdm(total=len(pending), disable=True if quiet or not pending else None, unit="run", file=sys.stderr,
               dynamic_ncols=True, desc="study runs")

    def progress(o):
        if o.status == "reused":
            return
        bar.update(1)
        if o.status == "failed":
            bar.write(f"tqdyn: study run {o.run.name} failed: {o.error}", file=sys.stderr)
        elif not quiet:
            bar.write(f"  {o.run.name}: {o.rows} rows in {o.wall_s:.1f} s", file=sys.stderr)

    import time

    t0 = time.perf_counter()
    with guarded(lambda exc: "finished runs are kept and reused next time", bad_input=(ValueError, FileNotFoundError),
                 cleanup=bar.close):
        result = st.run_studies(runs_dir, studies=names, duration_scale=scale, extra_overrides=sets,
                                workers=workers, progress=progress, plan=plan, **catalogue)
    bar.close()
    paths = {name: result.path(name) for name in result.outcomes}
    scaled = "" if scale == 1.0 else f" (durations x {scale:.4g})"
    t_runs = time.perf_counter()
    command = " ".join(["tqdyn report --studies"] + (["--mission", mission] if mission != "tianqin" else [])
                       + (["--quick"] if quick else []) + ([f"--duration-scale {duration_scale:g}"]
                                                           if duration_scale is not None else [])
                       + [f"--study {s}" for s in only] + [f"--set {s}" for s in sets]
                       + ([f"--workers {workers}"] if workers is not None else []) + ["--out", out])
    runs_info = {}
    for name, o in result.outcomes.items():
        facts = _file_facts(o.run.path if o.ok else None, o.rows or None, o.wall_s if o.status == "ran" else None)
        days = o.run.duration_s / 86400.0
        runs_info[name] = {"status": o.status, "duration_s": o.run.duration_s, **facts,
                           "file_mb_per_day": facts["file_mb"] / days if facts["file_mb"] and days else None}
    sizes = [r["file_mb"] for r in runs_info.values() if r["file_mb"] is not None]

    def make(stage):
        if mission == "lisa":
            rep = report_lisa_studies(paths, stage, studies=names, progress=say,
                                      title="tqdyn: the paper's studies on LISA and Taiji" + scaled)
        else:
            rep = rp.report_studies(paths, stage, studies=names, progress=say,
                                    title="tqdyn: the paper's section V reproduced" + scaled)
        t_end = time.perf_counter()
        rp.write_summary_json(rep, command, mission=mission, duration_scale=scale, studies=list(result.studies),
                              timing={"workers": n, "runs_wall_s": t_runs - t0, "report_wall_s": t_end - t_runs,
                                      "total_wall_s": t_end - t0, "n_runs": len(plan), "n_ran": len(pending)},
                              runs=runs_info, runs_total_file_mb=sum(sizes) if sizes else None)
        return rep

    with guarded(lambda exc: "the study runs are kept and reused next time",
                 bad_input=(ImportError,)):  # matplotlib missing: the runs are kept
        rep = _staged(out, make)
    _print_report(rep)
    if result.failures:
        for o in result.failures:
            click.echo(f"tqdyn: study run {o.run.name} failed: {o.error}", err=True)
        sys.exit(_EXIT_RUN_FAILED)
