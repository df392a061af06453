"""What the ``tqdyn`` commands share: exit statuses, the one-line error, the one mechanism every
writing command runs its work in (:func:`guarded`: signals, a full disk), the choice option type whose
refusal suggests the closest choice, and the overrides of the scenario shortcut options (``run``, ``forces``)."""

from __future__ import annotations

import contextlib
import os
import signal
import sys

import click

from .._choices import allowed, did_you_mean

__all__ = ["EXIT_FAILED", "EXIT_BAD_INPUT", "EXIT_IO", "EXIT_INTERRUPTED", "EXIT_SIGHUP", "EXIT_SIGTERM", "Choice",
           "fail", "fail_io", "guarded"]

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


def fail_io(message: str):
    """One line, exit status 3 (a failed write); if HDF5 could not close a file, end without the
    interpreter's exit handlers (HDF5 would crash in them)."""
    from ..formats.trajectory import hdf5_poisoned

    if hdf5_poisoned():  # pragma: no cover - the writers avoid it
        click.echo(f"tqdyn: error: {message}", err=True)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(EXIT_IO)
    fail(message, EXIT_IO)


#: the stop signals and the exit status of each (128 + the signal number, as a shell reports a process
#: killed by it); Ctrl-C (SIGINT) is Python's KeyboardInterrupt, status 130
_SIGNAL_EXIT = {signal.SIGTERM: EXIT_SIGTERM, **({signal.SIGHUP: EXIT_SIGHUP} if hasattr(signal, "SIGHUP") else {})}


def _no_note(exc) -> str:
    """What is left after the fault ``exc``: its attribute ``tqdyn_note`` if it has one, else
    "no output file written"."""
    return getattr(exc, "tqdyn_note", None) or "no output file written"


@contextlib.contextmanager
def guarded(note=_no_note, *, bad_input=(), cleanup=None, deferred: bool = False):
    """The work of a writing command, with its faults turned into one line and the documented exit
    status (docs/reliability.md, "Fault classes"): a failed write (disk full, file-size limit:
    :class:`~tqdyn.formats.trajectory.OutputIOError`) exits with 3, Ctrl-C with 130, SIGTERM with 143
    and SIGHUP with 129; ``note(exc)`` ends the line (default "no output file written": the writers
    have removed their temporary files, :mod:`tqdyn.formats.atomic`); an exception of the classes
    ``bad_input`` exits with 2, its message on one line.  ``cleanup()`` runs first (closing progress
    bars).  :func:`tqdyn.cli.main` runs every command in one, so a command nests its own only for
    its notes, bad-input classes and clean-up.

    SIGTERM and SIGHUP are recorded (:func:`tqdyn.formats.stop.request_stop`) and raise
    :class:`~tqdyn.formats.stop.Stopped` (a KeyboardInterrupt) where the command is, as Ctrl-C does;
    with ``deferred`` they are only recorded and the work calls
    :func:`~tqdyn.formats.stop.check_stop` at points where it can stop cleanly (``tqdyn run``: between
    two chunks of steps).  Either way every writer checks again before it renames its file into
    place, so a signal whose exception was lost still leaves no output.  A second signal is ignored.
    Handlers are installed in the main thread only; the previous ones come back at the end."""
    from ..formats import trajectory as io
    from ..formats.atomic import NO_SPACE
    from ..formats.stop import Stopped, clear_stop, request_stop

    def handler(signum, frame):
        for s in _SIGNAL_EXIT:
            signal.signal(s, signal.SIG_IGN)
        request_stop(signum)
        if not deferred:
            raise Stopped(signum)

    try:
        old = {s: signal.signal(s, handler) for s in _SIGNAL_EXIT}
    except ValueError:  # not the main thread
        old = {}
    try:
        yield
    except io.OutputIOError as exc:
        if cleanup is not None:
            cleanup()
        fail_io(f"{exc}; {note(exc)}")
    except bad_input as exc:
        if cleanup is not None:
            cleanup()
        fail(" ".join(str(exc).split()))
    except OSError as exc:
        if exc.errno not in NO_SPACE:
            raise
        if cleanup is not None:  # a full disk outside the output (numba's cache, a library's file)
            cleanup()
        where = f" to {str(exc.filename)!r}" if exc.filename else ""
        fail_io(f"a write{where} failed: {exc.strerror} (errno {exc.errno}); {note(exc)}")
    except KeyboardInterrupt as exc:
        if cleanup is not None:
            cleanup()
        if isinstance(exc, Stopped) and exc.signum in _SIGNAL_EXIT:
            fail(f"stopped by {signal.Signals(exc.signum).name}; {note(exc)}", _SIGNAL_EXIT[exc.signum])
        fail(f"interrupted; {note(exc)}", EXIT_INTERRUPTED)
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        clear_stop()


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
