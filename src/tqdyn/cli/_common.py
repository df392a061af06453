"""What the ``tqdyn`` commands share: exit statuses, the one-line error, the
choice option type whose refusal suggests the closest choice, and the
overrides of the scenario shortcut options (``run``, ``forces``)."""

from __future__ import annotations

import sys

import click

from .._choices import allowed, did_you_mean

__all__ = ["EXIT_FAILED", "EXIT_BAD_INPUT", "EXIT_IO", "EXIT_INTERRUPTED", "EXIT_SIGHUP", "EXIT_SIGTERM", "Choice",
           "fail"]

#: some work failed (a sweep member, a study run) after the rest was written
EXIT_FAILED = 1
#: bad input: one line on stderr, nothing written
EXIT_BAD_INPUT = 2
#: the output could not be written at run time (disk full, file-size limit,
#: I/O error): one line on stderr, no file at the output path, the last
#: checkpoint (if any) kept for --resume
EXIT_IO = 3
#: interrupted (Ctrl-C, SIGINT)
EXIT_INTERRUPTED = 130
#: stopped by SIGHUP (128 + 1), handled like Ctrl-C
EXIT_SIGHUP = 129
#: stopped by SIGTERM (128 + 15), handled like Ctrl-C
EXIT_SIGTERM = 143


def fail(message: str, status: int = EXIT_BAD_INPUT):
    """Print ``tqdyn: error: <message>`` on stderr and exit with ``status``."""
    click.echo(f"tqdyn: error: {message}", err=True)
    sys.exit(status)


class Choice(click.Choice):
    """``click.Choice`` whose refusal is one short line (:mod:`tqdyn._choices`):
    the closest choices and, for a long list, the page ``doc`` that lists them."""

    def __init__(self, choices, doc: str | None = None, **kwargs):
        super().__init__(choices, **kwargs)
        self.doc = doc

    def get_invalid_choice_message(self, value, ctx) -> str:
        names = list(self._normalized_mapping(ctx=ctx).values())
        return f"{value!r} is not allowed{did_you_mean(value, names)}; allowed: {allowed(names, self.doc, quote=repr)}"


def _overrides(sets, duration, step, output, precision) -> list[str]:
    """The ``--set`` overrides of a command followed by those of its shortcut options
    (``--duration``, ``--step``, ``--output``, ``--precision``) that were given."""
    over = list(sets)
    for key, value in (("run.duration", duration), ("integrator.step", step),
                       ("run.output", output), ("run.precision", precision)):
        if value is not None:
            over.append(f"{key}={value}")
    return over
