"""What the ``tqdyn`` commands share: exit statuses, the one-line error and
the overrides of the scenario shortcut options (``run``, ``forces``)."""

from __future__ import annotations

import sys

import click

__all__ = ["EXIT_FAILED", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED", "fail"]

#: some work failed (a sweep member, a study run) after the rest was written
EXIT_FAILED = 1
#: bad input: one line on stderr, nothing written
EXIT_BAD_INPUT = 2
#: interrupted (Ctrl-C)
EXIT_INTERRUPTED = 130


def fail(message: str, status: int = EXIT_BAD_INPUT):
    """Print ``tqdyn: error: <message>`` on stderr and exit with ``status``."""
    click.echo(f"tqdyn: error: {message}", err=True)
    sys.exit(status)


def _overrides(sets, duration, step, output, precision) -> list[str]:
    """The ``--set`` overrides of a command followed by those of its shortcut options
    (``--duration``, ``--step``, ``--output``, ``--precision``) that were given."""
    over = list(sets)
    for key, value in (("run.duration", duration), ("integrator.step", step),
                       ("run.output", output), ("run.precision", precision)):
        if value is not None:
            over.append(f"{key}={value}")
    return over
