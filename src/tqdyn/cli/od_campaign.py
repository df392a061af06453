"""Command line: ``tqdyn od campaign recovery | covariance SCENARIO ...`` -- orbit-determination
campaigns on Dask (:mod:`tqdyn.workflows.od_campaign`).

Registered on the ``tqdyn od`` group (:mod:`.od`).  Bad input (no seeds, an unknown tracking kind,
an arc outside the run, an output that is an input, an unreachable scheduler) exits with status 2
and one line, nothing written; members that failed are reported on stderr and make the exit status 1
after the others are gathered; Ctrl-C exits with 130, SIGTERM with 143, a member or the gathered file
that cannot be written (full disk) with 3 (:func:`._common.guarded`; the local cluster closed, the
members that finished are kept and skipped when the campaign is run again, no output file).
Progress: a bar over the members on stderr.
"""

from __future__ import annotations

import sys

import click

from ._common import EXIT_FAILED, guarded

__all__ = ["campaign"]


@click.command("campaign")
@click.argument("kind", type=click.Choice(["recovery", "covariance"]), metavar="recovery|covariance")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--tracking", "tracking", multiple=True, required=True,
              help="A tracking plan, comma-separated kinds (gnss, slr, isr, dsn); repeat for several plans.")
@click.option("--arc", "arcs", multiple=True, required=True,
              help="An arc from the epoch: seconds or with a unit (1d, 12h); repeat for several arcs.")
@click.option("--epoch", "epochs", multiple=True, metavar="UTC",
              help="An epoch (scenario.epoch_utc, e.g. 2030-01-01T00:00:00); repeatable [default: the scenario's].")
@click.option("--seeds", help="Recovery: the noise seeds, a count N (0..N-1), a range A-B or a list 1,5,7.")
@click.option("--truth", "truth", multiple=True, metavar="KEY=VALUE",
              help="Recovery: a scenario value of the truth the measurements are simulated on (e.g. "
                   "accelerations.s_frame=[[0,1e-10,0],[0,1e-10,0],[0,1e-10,0]]); the fit uses SCENARIO.")
@click.option("--interval", help="Measurement interval: seconds or with a unit [default: 600 s].")
@click.option("--estimate", help="Parameter groups to estimate, comma-separated [default: the plan's].")
@click.option("--consider", help="Parameter groups to consider (not estimated, their uncertainty kept).")
@click.option("--a-priori", "a_priori", multiple=True, metavar="GROUP=SIGMA",
              help="A priori 1-sigma of a parameter group (as tqdyn od fit); repeatable.")
@click.option("--stations", help="Ground stations (SLR, deep-space), comma-separated [default: the plan's].")
@click.option("--output", "-o", required=True, help="Output netCDF file; the members' results go to OUTPUT.parts/.")
@click.option("--scheduler", metavar="ADDRESS", help="Address of a running Dask scheduler [default: a local cluster].")
@click.option("--workers", type=int, metavar="N", help="Worker processes of the local cluster [default: the cores].")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help="Override a scenario value (repeatable).")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
def campaign(kind, scenario, tracking, arcs, epochs, seeds, truth, interval, estimate, consider, a_priori, stations,
             output, scheduler, workers, sets, quiet):
    """Run an orbit-determination campaign on Dask: a recovery Monte Carlo over noise seeds (simulate on
    the truth, fit SCENARIO; the chi-square of the estimates' errors) or the predicted covariance, over
    every tracking plan x arc x epoch; gathered into one netCDF file.  Members already done are
    skipped."""
    from tqdm import tqdm

    from ..workflows import od_campaign as oc

    if workers is not None and workers < 1:
        raise click.UsageError(f"--workers: {workers} is not a number of workers; allowed: an integer >= 1")
    if workers is not None and scheduler is not None:
        raise click.UsageError("--workers: applies to the local cluster only; the cluster at --scheduler has its own")
    bar = None
    failed = [0]

    def started(client):
        nonlocal bar
        bar = tqdm(total=len(pending), disable=True if quiet or not pending else None, unit="member",
                   file=sys.stderr, dynamic_ncols=True, desc=f"od campaign {kind}")

    def progress(member, res):
        failed[0] += not res["ok"]
        if failed[0]:
            bar.set_postfix(failed=failed[0], refresh=False)
        bar.update(1)

    def close():
        if bar is not None:
            bar.close()

    with guarded(lambda exc: "the members that finished are kept and skipped when the campaign is run again",
                 bad_input=(ValueError, FileNotFoundError, ImportError), cleanup=close):
        spec = oc.plan_campaign(kind, scenario, tracking=tracking, arc=arcs, epoch=epochs, seeds=seeds, truth=truth,
                                overrides=sets, interval=interval, estimate=estimate, consider=consider,
                                a_priori=a_priori, stations=stations, output=output)
        from ..workflows.sweep import netcdf_engine

        netcdf_engine()
        pending = [m for m in spec.members if not spec.done(m)]
        result = oc.run_campaign(spec, scheduler=scheduler, n_workers=workers, progress=progress, started=started)
    close()
    ran = result.n_ran
    rate = f", {ran / result.wall_s * 60:.1f} members/min" if ran and result.wall_s > 0 else ""
    lines = [f"campaign {kind}: {len(spec.members)} members: {result.n_skipped} already done, {ran} ran, "
             f"{len(result.failures)} failed ({result.wall_s:.1f} s{rate})"
             + (f"; {len(result.rerun)} re-run after a worker was lost" if result.rerun else "")]
    ds = result.dataset
    if ds is not None and kind == "recovery":
        for i, plan in enumerate(ds.plan.values):
            for j, arc_s in enumerate(ds.arc_s.values):
                for k, epoch in enumerate(ds.epoch.values):
                    chi, dof = float(ds.error_chi2_sum[i, j, k]), int(ds.error_chi2_dof[i, j, k])
                    lines.append(f"  {plan} over {arc_s:g} s{' at ' + epoch if epoch else ''}: chi2 of the estimates' "
                                 f"errors = {chi:.6g} for {dof} dof (p = {float(ds.error_chi2_pvalue[i, j, k]):.3g})")
    lines.append(f"output: {result.output}" if result.output is not None else "output: none (no member succeeded)")
    click.echo("\n".join(lines))
    for m, err in result.failures:
        click.echo(f"tqdyn: {m.label} failed: {err}", err=True)
    if result.failures:
        sys.exit(EXIT_FAILED)
