"""Stop requests: a stop signal (SIGTERM, SIGHUP) received by a command, as every output writer
sees it (no I/O, no imports).

The command line (:func:`tqdyn.cli._common.guarded`) records the signal here with
:func:`request_stop` and raises :class:`Stopped` where the command is (or, for ``tqdyn run``, at
the next chunk of steps).  Every writer that renames a finished temporary file into place
(:func:`tqdyn.formats.atomic.replacing`, :class:`tqdyn.formats.trajectory.TrajectoryWriter`,
:class:`tqdyn.formats.closed_loop.ClosedLoopWriter`) calls :func:`check_stop` just before the
rename: a signal whose exception was lost (Python prints an exception raised by a signal handler
inside a garbage-collector callback and drops it) still stops the command before its output appears.
"""

from __future__ import annotations

import signal

__all__ = ["Stopped", "check_stop", "clear_stop", "request_stop", "stop_requested"]

_STATE: dict = {}


class Stopped(KeyboardInterrupt):
    """A stop signal (``signum``: SIGTERM, SIGHUP), handled as Ctrl-C is (a KeyboardInterrupt: every
    writer removes its temporary file, ``tqdyn run`` keeps its checkpoint)."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


def request_stop(signum: int) -> None:
    """Record that the stop signal ``signum`` arrived (the first one counts)."""
    _STATE.setdefault("signum", int(signum))


def stop_requested() -> int | None:
    """The signal number recorded by :func:`request_stop` (None: none)."""
    return _STATE.get("signum")


def check_stop() -> None:
    """Raise :class:`Stopped` if a stop signal was recorded."""
    if "signum" in _STATE:
        raise Stopped(_STATE["signum"])


def clear_stop() -> None:
    """Forget a recorded stop signal (the command line, when it ends)."""
    _STATE.pop("signum", None)
