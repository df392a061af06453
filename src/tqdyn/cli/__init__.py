"""Command line: ``tqdyn run | info | forces | bench | export | sweep | report | closed-loop | od``.

The click group and the entry point :func:`main`; every command lives in its
own module (:mod:`.run`, :mod:`.forces`, :mod:`.info`, :mod:`.bench`,
:mod:`.export`, :mod:`.sweep`, :mod:`.report`, :mod:`.closed_loop`, :mod:`.od`) and only composes library
calls.  Bad input exits with status 2 and one line on stderr (no traceback,
no partial output file); every command runs in :func:`._common.guarded` (Ctrl-C, SIGTERM, SIGHUP,
a full disk: docs/reliability.md, "Fault classes").
"""

from __future__ import annotations

import click

from .._version import __version__
from ..workflows.heap import bound_heap_retention
from ._common import EXIT_INTERRUPTED as _EXIT_INTERRUPTED, fail as _fail, guarded as _guarded
from .bench import bench as _bench_command
from .closed_loop import closed_loop as _closed_loop_command
from .export import export as _export_command
from .forces import forces as _forces_command
from .info import info as _info_command
from .od import od as _od_command
from .report import report as _report_command
from .run import run as _run_command
from .sweep import sweep as _sweep_command

__all__ = ["main"]


class _GuardedGroup(click.Group):
    """The command group; every command runs in :func:`._common.guarded` (inside click's own
    handling, which would print an empty line for a KeyboardInterrupt reaching it)."""

    def invoke(self, ctx):
        with _guarded():
            return super().invoke(ctx)


@click.group(cls=_GuardedGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="tqdyn")
def cli():
    """tqdyn -- coupled dynamics of drag-free gravitational-wave constellations
    (TianQin by default) in double-double precision."""


cli.add_command(_run_command)
cli.add_command(_forces_command)
cli.add_command(_info_command)
cli.add_command(_bench_command)
cli.add_command(_export_command)
cli.add_command(_sweep_command)
cli.add_command(_report_command)
cli.add_command(_closed_loop_command)
cli.add_command(_od_command)


def main(argv=None):
    """Entry point: click in non-standalone mode so usage errors are one line.
    Large freed blocks go back to the system (:mod:`tqdyn.workflows.heap`)."""
    bound_heap_retention()
    try:
        cli.main(args=argv, prog_name="tqdyn", standalone_mode=False)
    except click.exceptions.Abort:
        _fail("interrupted", _EXIT_INTERRUPTED)
    except click.exceptions.ClickException as exc:
        _fail(exc.format_message())
    except KeyboardInterrupt:
        _fail("interrupted", _EXIT_INTERRUPTED)
    return 0


if __name__ == "__main__":  # pragma: no cover
    main()
