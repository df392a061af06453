"""What every ``tqdyn`` command shares: exit statuses and the one-line error."""

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
