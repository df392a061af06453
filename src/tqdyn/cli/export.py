"""Command line: ``tqdyn export RUN.h5 --format lisa OUT.h5``.

A click command registered by :mod:`tqdyn.cli` (``cli.add_command(export)``).
It only composes library calls (:func:`tqdyn.workflows.export.export_lisa`).  As
everywhere in the CLI, bad input exits with status 2 and one line
``tqdyn: error: ...`` on stderr, and no output file is left behind.
"""

from __future__ import annotations


import click

from ._common import EXIT_INTERRUPTED as _EXIT_INTERRUPTED, fail as _fail

__all__ = ["FORMATS", "export"]

FORMATS = ("lisa",)
"""Export formats: ``lisa`` = LISA orbit file (lisaorbits layout 2.x)."""


@click.command("export")
@click.argument("run_file", metavar="RUN.h5")
@click.argument("out_file", metavar="OUT.h5")
@click.option("--format", "fmt", metavar="FORMAT", help="Output format (required); allowed: lisa.")
@click.option("--shapiro", is_flag=True, help="Include the Earth's Shapiro delay in the light travel times.")
def export(run_file, out_file, fmt, shapiro):
    """Export the trajectory RUN.h5 to OUT.h5 in another tool's format.

    --format lisa writes a LISA orbit file (lisaorbits layout 2.x, read by
    lisainstrument and pytdi): satellite states, light travel times between
    the test masses (satellite centres for runs without test masses),
    proper times and proper pseudoranges.  The frame stays tqdyn's GCRS and
    the time TT seconds since the epoch; the file's attributes say how each
    quantity is defined.
    """
    if fmt is None:
        _fail(f"--format is required; allowed: {', '.join(FORMATS)}")
    if fmt not in FORMATS:
        _fail(f"--format: {fmt!r} is not allowed; allowed: {', '.join(FORMATS)}")
    from ..formats import trajectory as io
    from ..workflows.export import export_lisa

    try:
        summary = export_lisa(run_file, out_file, shapiro=shapiro)
    except (FileNotFoundError, ValueError, io.OutputError) as exc:
        _fail(str(exc))
    except KeyboardInterrupt:
        _fail("interrupted; no output file written", _EXIT_INTERRUPTED)
    head = (f"LISA orbit file {summary.path}: {summary.size} samples from t0 = {summary.t0:g} s every "
            f"{summary.dt:g} s (TT since the epoch, GCRS)")
    click.echo("\n".join([
        head,
        f"light travel times: {summary.note}; {summary.ltt_range[0]:.9f} .. {summary.ltt_range[1]:.9f} s"
        + ("; Earth Shapiro delay included" if summary.shapiro else ""),
        f"dropped {summary.dropped_rows} leading row(s) whose emission time precedes the trajectory",
    ]))
