"""A fork server for tests/test_reliability_faults.py: real `tqdyn` processes without paying the
imports of each one.

Started once (``python fault_server.py``, this tree's sources on PYTHONPATH), it imports the command
line and the libraries every command loads (and runs the Monte Carlo's cached H-infinity synthesis),
then reads one JSON request per line on stdin and, for each, forks a child that runs ``tqdyn ARGV``
as the console script does (``sys.exit(main(argv))``; a library crashing at exit shows as a killed
child, :func:`_child`).  It answers
``{"pid": PID}`` when the child starts (the leader of a new process group) and ``{"status": S}``
when it ends (S: the exit status, or
-signal for a child killed by a signal), one child at a time.

A request: ``argv`` (the arguments after ``tqdyn``), ``cwd``, ``stdout`` and ``stderr`` (files the
child's are written to), ``limit`` (bytes: RLIMIT_FSIZE as ``ulimit -f``, with SIGXFSZ ignored so that
writes fail with EFBIG as on a full disk; null: none) and ``block`` (null, or ``{"target":
"module:attr.attr", "under": DIR or null, "ready": FILE, "go": FILE}``: the first call of that
function -- of ``os:replace``, the first whose destination is under DIR -- creates FILE ``ready`` and
waits until FILE ``go`` exists before it goes on, so that a test can send a signal while the command
is at work; a signal handler that raises ends the wait at once).
"""

from __future__ import annotations

import atexit
import ctypes
import gc
import importlib
import json
import os
import resource
import signal
import sys
import time


def _warm() -> None:
    """Import what the commands import (the children inherit it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401
    import tqdyn.cli  # noqa: F401
    for name in ("tqdyn.workflows.run", "tqdyn.workflows.export", "tqdyn.workflows.export_oem",
                 "tqdyn.workflows.export_ttl", "tqdyn.workflows.export_injection", "tqdyn.workflows.closed_loop",
                 "tqdyn.workflows.od", "tqdyn.workflows.od_files", "tqdyn.workflows.report", "tqdyn.workflows.sweep", "tqdyn.workflows.bench",
                 "tqdyn.workflows.od_campaign", "tqdyn.workflows.closed_loop_mc", "distributed",
                 "tqdyn.analysis.closed_loop", "tqdyn.analysis.figures", "tqdyn.analysis.figures_od",
                 "tqdyn.analysis.budget", "tqdyn.od.problem", "xarray", "h5netcdf", "control", "tqdm"):
        importlib.import_module(name)
    import warnings

    from tqdyn.workflows.closed_loop_mc import _designs

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _designs("tianqin", ())  # the H-infinity synthesis of `closed-loop --monte-carlo` (cached; 6 s)


def _resolve(target: str):
    """(owner, attribute name) of ``"module:attr.attr"``."""
    module, _, path = target.partition(":")
    owner = importlib.import_module(module)
    parts = path.split(".")
    for p in parts[:-1]:
        owner = getattr(owner, p)
    return owner, parts[-1]


def _install_block(block: dict) -> None:
    owner, name = _resolve(block["target"])
    original = getattr(owner, name)
    under = block.get("under")
    state = {"done": False}

    def blocking(*args, **kwargs):
        if not state["done"] and (under is None or str(args[1]).startswith(under)):
            state["done"] = True
            with open(block["ready"], "w"):
                pass
            t0 = time.monotonic()
            while not os.path.exists(block["go"]) and time.monotonic() - t0 < 120:
                time.sleep(0.01)
        return original(*args, **kwargs)

    setattr(owner, name, blocking)


def _child(req: dict):
    """In the forked child: set up the process as requested, run the command line, and end as the
    console script does except for Python's own teardown of its modules (slow in a child of a large
    process, and not where the faults are): the atexit functions, then the C library's ``exit``,
    which runs the C libraries' exit handlers -- HDF5 closes its open files there, where a file
    left after a failed write crashes it."""
    os.setpgid(0, 0)  # a process group of its own (and its children's), as a terminal's foreground job
    os.chdir(req["cwd"])
    for fd, path, flags in ((0, os.devnull, os.O_RDONLY),
                            (1, req["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC),
                            (2, req["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC)):
        new = os.open(path, flags, 0o644)
        os.dup2(new, fd)
        os.close(new)
    if req.get("limit") is not None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (req["limit"], req["limit"]))
    if req.get("block"):
        _install_block(req["block"])
    from tqdyn.cli import main

    try:
        code = main(list(req["argv"]))
    except SystemExit as exc:
        code = exc.code
    code = 0 if code is None else code if isinstance(code, int) else 1
    sys.stdout.flush()
    sys.stderr.flush()
    atexit._run_exitfuncs()
    ctypes.CDLL(None).exit(code)  # the C library's exit: its atexit handlers (HDF5 closes its files there)


def _reply(obj: dict) -> None:
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def serve() -> None:
    _warm()
    gc.freeze()  # the children's collections leave the server's objects alone (no copy of their pages)
    _reply({"ready": True})
    for line in sys.stdin:
        req = json.loads(line)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            _child(req)
        try:
            os.setpgid(pid, pid)  # as the child does: before the client may signal the group
        except OSError:
            pass
        _reply({"pid": pid})
        _, wstatus = os.waitpid(pid, 0)
        _reply({"status": os.waitstatus_to_exitcode(wstatus)})


if __name__ == "__main__":
    serve()
