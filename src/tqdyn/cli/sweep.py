"""Command line: ``tqdyn sweep SWEEP.toml [--scheduler ADDRESS] [--workers N] [--dashboard HOST:PORT|off]
[--tls-ca-file PEM --tls-cert PEM [--tls-key PEM]] [--connect-timeout S]``.

Registered in :mod:`tqdyn.cli` with ``cli.add_command(sweep)``.  It only
composes :mod:`tqdyn.workflows.sweep`: validate the whole sweep (bad input: exit
status 2, one line ``tqdyn: error: ...`` on stderr, nothing run or written),
run the members not yet done on Dask with a progress bar on stderr, gather
them into ``<output_dir>/<name>.nc`` and print a summary on stdout.  Members
that failed are reported on stderr (their parameters and one-line error)
and make the exit status 1, after everything that succeeded is written.
The sweep file format is documented in ``docs/sweeps.md``.
"""

from __future__ import annotations

import sys

import click

from .._version import __version__
from ._common import EXIT_FAILED as _EXIT_MEMBER_FAILED
from ._common import fail as _fail, guarded

__all__ = ["sweep"]


def _describe(spec) -> str:
    """``product over direction[6] x a_km[3]`` / ``zip over direction, a_km [6]``."""
    if spec.mode == "product":
        return "product over " + " x ".join(f"{p.dim}[{len(p.values)}]" for p in spec.parameters)
    return "zip over " + ", ".join(p.dim for p in spec.parameters) + f" [{spec.shape[0]}]"


def _table(rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]


def _member_rows(plan, outcomes=None) -> list[str]:
    spec = plan.spec
    head = ["member", *(p.dim for p in spec.parameters), "status"] + (["time [s]"] if outcomes else []) + ["file"]
    rows = [head]
    for k, m in enumerate(plan.members):
        values = [v for _, v in m.params]
        if outcomes is None:
            status, extra = ("done" if plan.done[k] else "to run"), []
        else:
            o = outcomes[k]
            status = o.status
            extra = [f"{o.wall_s + o.compile_s:.2f}" if o.status == "ran" else "-"]
        rows.append([str(m.index + 1), *values, status, *extra, m.path.name])
    return _table(rows)


@click.command("sweep", context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("sweep_file", metavar="SWEEP.toml")
@click.option("--scheduler", metavar="ADDRESS",
              help="Address of a running Dask scheduler, e.g. tcp://host:8786 or tls://host:8786 (its workers need "
                   "tqdyn and the output directory at the same path). Default: a new local cluster.")
@click.option("--workers", type=int, metavar="N",
              help="Worker processes of the local cluster (1 thread each). Default: the CPU cores.")
@click.option("--dashboard", metavar="HOST:PORT|off", default=None,
              help="Where the local cluster's Dask dashboard listens. Default: 127.0.0.1:0 (this machine only, "
                   "any free port); 'off': no dashboard. E.g. 0.0.0.0:8787 exposes it to the network.")
@click.option("--tls-ca-file", metavar="PEM", help="TLS: CA certificate for a tls:// --scheduler.")
@click.option("--tls-cert", metavar="PEM", help="TLS: this client's certificate (may hold the key too).")
@click.option("--tls-key", metavar="PEM", help="TLS: this client's private key.")
@click.option("--connect-timeout", type=float, metavar="SECONDS", default=None,
              help="How long to wait for --scheduler before giving up (exit 2, nothing written). Default: 10.")
@click.option("--dry-run", is_flag=True, help="Validate the sweep and list its members; run nothing.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
def sweep(sweep_file, scheduler, workers, dashboard, tls_ca_file, tls_cert, tls_key, connect_timeout, dry_run, quiet):
    """Run the parameter sweep SWEEP.toml on Dask: every member (base scenario
    + common overrides + its parameter values) is one task; members whose
    trajectory file is already complete are skipped; the results are
    gathered into one netCDF file <output_dir>/<name>.nc.  Exit status 1 if
    a member failed (the others are kept), 2 on bad input (nothing written,
    also when --scheduler cannot be reached)."""
    import math

    from tqdm import tqdm

    from ..workflows import sweep as sw

    if workers is not None and workers < 1:
        _fail(f"--workers: {workers} is not a number of workers; allowed: an integer >= 1")
    if workers is not None and scheduler is not None:
        _fail("--workers: applies to the local cluster only; the cluster at --scheduler has its own workers")
    if dashboard is not None and scheduler is not None:
        _fail("--dashboard: applies to the local cluster only; the cluster at --scheduler has its own dashboard")
    if scheduler is None and any(v is not None for v in (tls_ca_file, tls_cert, tls_key, connect_timeout)):
        _fail("--tls-ca-file/--tls-cert/--tls-key/--connect-timeout: apply to a remote --scheduler only")
    if connect_timeout is not None and not (math.isfinite(connect_timeout) and connect_timeout > 0):
        _fail(f"--connect-timeout: {connect_timeout} is not a duration; allowed: seconds > 0")
    if dashboard is None or dashboard.strip().lower() in ("off", "none", "no", "false"):
        dash = None if dashboard is not None else sw.DEFAULT_DASHBOARD
    else:
        dash = dashboard
    try:
        security = sw.make_security(tls_ca_file, tls_cert, tls_key)
        if dash is not None:
            sw.check_dashboard(dash)
        plan = sw.plan_sweep(sweep_file)
        if not dry_run:
            sw.netcdf_engine()
            sw.check_output_dir(plan)
    except (ValueError, FileNotFoundError, ImportError) as exc:
        _fail(str(exc))
    spec = plan.spec
    pending = plan.pending
    n_done = len(plan.members) - len(pending)
    if scheduler is not None:
        where = f"on the Dask cluster at {scheduler}"
    else:
        n = min(workers or sw.default_workers(), max(len(pending), 1))
        where = f"on a local cluster of {n} worker process{'es' if n != 1 else ''}"

    def banner(client=None):
        extra = ""
        if client is not None and scheduler is None:
            link = client.dashboard_link if dash is not None else None
            extra = f" (dashboard {link})" if link else ""
        click.echo(f"tqdyn {__version__}: sweep {spec.name!r}: {len(plan.members)} members ({_describe(spec)}), "
                   f"{n_done} already done, {len(pending)} to run"
                   + (f" {where}{extra}" if pending and not dry_run else ""), err=True)

    if dry_run:
        banner()
        click.echo("\n".join([f"sweep {spec.name!r}: base scenario {spec.scenario}, output {spec.output}",
                              *_member_rows(plan)]))
        return
    bar = None
    n_failed = 0

    def started(client):
        nonlocal bar
        banner(client)
        bar = tqdm(total=len(pending), disable=True if quiet or not pending else None, unit="member",
                   file=sys.stderr, dynamic_ncols=True, desc="members")

    def progress(outcome):
        nonlocal n_failed
        n_failed += not outcome.ok
        if n_failed:
            bar.set_postfix(failed=n_failed, refresh=False)
        bar.update(1)

    def close_bar():
        if bar is not None:
            bar.close()

    options = {"dashboard": dash, "security": security}
    if connect_timeout is not None:
        options["timeout"] = connect_timeout
    with guarded(lambda exc: "the members that finished are kept and skipped when the sweep is run again",
                 bad_input=(ValueError, FileNotFoundError, ImportError), cleanup=close_bar):
        result = sw.run_sweep(plan, scheduler=scheduler, n_workers=workers, progress=progress, started=started,
                              **options)
    close_bar()
    failures = result.failures
    rerun = result.rerun
    lines = [(f"sweep {spec.name!r}: {len(result.outcomes)} members: {result.n_skipped} already done, "
              f"{result.n_ran} ran, {len(failures)} failed ({result.wall_s:.1f} s)"
              + (f"; {len(rerun)} re-run after a worker was lost" if rerun else "")),
             *_member_rows(plan, result.outcomes)]
    if result.output is not None:
        ds = result.dataset
        dims = ", ".join(f"{d}: {n}" for d, n in ds.sizes.items())
        lines.append(f"output: {result.output} ({result.output.stat().st_size / 1e6:.1f} MB; {dims}"
                     + ("; failed members NaN-filled, see variables ok and error" if failures else "") + ")")
    else:
        lines.append("output: none (no member succeeded)")
    click.echo("\n".join(lines))
    for o in rerun:
        click.echo(f"tqdyn: note: {o.member.label} was re-run after its Dask worker was lost "
                   f"({o.lost_workers} time{'s' if o.lost_workers != 1 else ''}); its file is that of the complete "
                   "re-run", err=True)
    if result.stale_temporaries:
        click.echo(f"tqdyn: note: removed {result.stale_temporaries} temporary file(s) left by lost workers", err=True)
    for o in failures:
        click.echo(f"tqdyn: {o.member.label} failed: {o.error}", err=True)
    if failures:
        sys.exit(_EXIT_MEMBER_FAILED)
