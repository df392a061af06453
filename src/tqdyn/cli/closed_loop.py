"""Command line: ``tqdyn closed-loop RUN.h5 --output CL.h5 [--duration D] [--fs HZ] [--seed N] [--set ...]
[--per-source]``, or ``tqdyn closed-loop --mission NAME --output CL.h5 [...]`` (a mission's static working
point, no run).

Registered in :mod:`tqdyn.cli`.  It only composes :mod:`tqdyn.workflows.closed_loop`: the inputs are
resolved and checked first (bad input: status 2, one line, nothing written), then the budget and the
time series are written to the closed-loop file (docs/closed-loop-file.md) with progress bars (the
budget's loops, then the samples); a failed write exits with status 3, Ctrl-C with 130, SIGTERM with
143 (:func:`._common.guarded`), and none leaves a file at the output path (an existing file there is
replaced only by a complete one, as ``tqdyn run`` does).
"""

from __future__ import annotations

import sys

import click

from ._common import guarded

__all__ = ["closed_loop"]


class _Bars:
    """Two progress bars one after the other: the budget's loops (segment x spacecraft), then the time
    series' samples (opened when the budget's last loop is done, so that its rate counts samples only)."""

    def __init__(self, make, n_loops: int, n_samples: int):
        self.make, self.n_loops, self.n_samples = make, n_loops, n_samples
        self.bar = make(n_loops, "loop", "budget")
        self.done = 0

    def loops(self, k: int) -> None:
        self.bar.update(k)
        self.done += k
        if self.done >= self.n_loops:
            self.bar.close()
            self.bar = self.make(self.n_samples, "sample", "closed loop")

    def samples(self, k: int) -> None:
        self.bar.update(k)

    def close(self) -> None:
        self.bar.close()


@click.command("closed-loop")
@click.argument("run_file", metavar="[RUN.h5]", required=False)
@click.option("--mission", help="Instead of RUN.h5: the mission's static working point (lpf, tianqin-1, or a "
                                "constellation mission's representative point; docs/closed-loop.md).")
@click.option("--output", "-o", required=True, help="Output closed-loop HDF5 file (replaced only by a complete one).")
@click.option("--duration", help="Length of the time series: seconds, or with a unit: 3d, 6h, 30min, 3600s "
                                 "[default: closed_loop.duration, else the run's first day (its span if shorter)].")
@click.option("--fs", help="Sample rate of the time series [Hz; default: closed_loop.fs, docs/scenarios.md].")
@click.option("--seed", type=int, help="Root seed of the noise realisations [default: closed_loop.seed].")
@click.option("--set", "sets", multiple=True, metavar="closed_loop.KEY=VALUE",
              help="Override a closed-loop key of the run's scenario, e.g. --set closed_loop.n_freq=100 or "
                   "--set closed_loop.noise.thruster_force.level=1e-7 (repeatable; docs/scenarios.md).")
@click.option("--per-source", is_flag=True, help="Also write the ASD of every output from every noise source "
                                                "(/budget/asd; the totals and dominant sources are always written).")
@click.option("--monte-carlo", "monte_carlo", type=int, metavar="N",
              help="With --mission: instead of the budget and series, N draws of the plant's uncertain parameters "
                   "evaluated with both designs (per_loop, hinf); writes a netCDF dataset (docs/closed-loop.md).")
@click.option("--scheduler", metavar="ADDRESS", help="With --monte-carlo: a Dask scheduler to run the draws on "
                                                     "[default: a local cluster].")
@click.option("--workers", type=int, help="With --monte-carlo: the local cluster's workers [default: the usable "
                                          "cores]; 0: in this process.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bars.")
def closed_loop(run_file, mission, output, duration, fs, seed, sets, per_source, quiet, monte_carlo=None,
                scheduler=None, workers=None):
    """The closed loop of the coupled run RUN.h5 (any mission), or of a mission's static working point
    (--mission, e.g. lpf or tianqin-1): the drag-free, suspension, attitude and MOSA loops linearised
    around the working point (docs/closed-loop.md), their noise budget, margins and dominant sources,
    and seeded time series of every output per spacecraft, streamed to the closed-loop file CL.h5
    (docs/closed-loop-file.md)."""
    from tqdm import tqdm

    from ..formats import trajectory as io
    from ..workflows import closed_loop as wf

    if monte_carlo is not None or scheduler is not None or workers is not None:
        _monte_carlo(run_file, mission, output, monte_carlo, seed, sets, scheduler, workers, quiet)
        return
    with guarded(bad_input=(ValueError, FileNotFoundError, io.OutputError)):
        job = wf.check_closed_loop_inputs(run_file, output, duration=duration, fs=fs, seed=seed, overrides=sets,
                                          per_source=per_source, mission=mission)
    n = job.attrs["n_samples"]
    where = job.attrs["source_file"] or "static working point"
    click.echo(f"tqdyn closed-loop: {where}, mission {job.model.mission}, "
               f"{len(job.model.loops)} spacecraft x {len(job.model.loops[0])} segment(s); time series "
               f"{job.duration_s:g} s at {job.fs:g} Hz ({n} samples), seed {job.seed}", err=True)
    n_loops = len(job.model.loops) * len(job.model.loops[0])
    bars = _Bars(lambda total, unit, desc: tqdm(total=total, disable=True if quiet else None, unit=unit,
                                                unit_scale=unit == "sample", file=sys.stderr, dynamic_ncols=True,
                                                desc=desc), n_loops, n)
    with guarded(bad_input=(ValueError, io.OutputError), cleanup=bars.close):
        summary = wf.closed_loop_to_file(job, progress=bars.samples, budget_progress=bars.loops)
    bars.close()
    click.echo(f"budget: {summary.budget_s:.2f} s; time series: {summary.n_samples} samples x {summary.n_sat} "
               f"spacecraft in {summary.timeseries_s:.2f} s")
    click.echo(f"output: {summary.path} ({summary.size_bytes / 1e6:.1f} MB)")


def _monte_carlo(run_file, mission, output, n, seed, sets, scheduler, workers, quiet) -> None:
    """``--monte-carlo N``: the robustness Monte Carlo (:mod:`tqdyn.workflows.closed_loop_mc`) to a netCDF file."""
    from tqdm import tqdm

    from ..formats import trajectory as io
    from ..formats.atomic import check_output
    from ..formats.netcdf import write_netcdf
    from ..workflows import closed_loop_mc as mc

    with guarded(bad_input=(ValueError, io.OutputError)):
        if n is None:
            raise ValueError("--scheduler/--workers: only with --monte-carlo N; allowed: tqdyn closed-loop --mission "
                             "NAME --monte-carlo N [--scheduler ADDRESS | --workers N] --output MC.nc")
        if run_file is not None:
            raise ValueError("RUN.h5: not with --monte-carlo; allowed: --mission NAME (the static working point)")
        mc.check_monte_carlo(mission, n, sets, workers)
        out = check_output(output, "--output", {})
    click.echo(f"tqdyn closed-loop: Monte Carlo of {mission}, {n} draws x 2 designs (per_loop, hinf), seed "
               f"{seed or 0}, on {scheduler or ('this process' if workers == 0 else 'a local cluster')}", err=True)
    bar = tqdm(total=2 * n, disable=True if quiet else None, unit="draw", file=sys.stderr, dynamic_ncols=True,
               desc="monte carlo")
    with guarded(bad_input=(ValueError, io.OutputError), cleanup=bar.close):
        ds = mc.monte_carlo(mission, n, seed or 0, sets, scheduler, workers, progress=bar.update)
        bar.close()
        path = write_netcdf(ds, out, what="the Monte Carlo file")
    for d, row in mc.summarise(ds).items():
        r = row["requirement_ratio"]
        ratio = "no stable draw" if r is None else f"{r['median']:.3g} [{r['p05']:.3g}, {r['p95']:.3g}]"
        click.echo(f"{d}: stable {row['stable_fraction']:.0%}, requirement ratio median [5 %, 95 %] {ratio}")
    click.echo(f"output: {path}")
