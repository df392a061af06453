"""What a job may hold, checked before it starts: the memory of the machine (the exports that build
their arrays whole) and the free space of a file system (the closed-loop file, streamed to disk).

A job whose estimate exceeds :data:`MEMORY_FRACTION` of the memory available now (psutil's
``virtual_memory().available``: Linux's MemAvailable, the memory that can be given to a process
without swapping) is refused in one line naming the size and the option that bounds it, before any
array is allocated -- not after minutes of work, with a MemoryError or the system's out-of-memory
killer.  The estimates are bytes per sample measured with the process's peak resident size
(docs/reliability.md, "Memory and disk").
"""

from __future__ import annotations

import os

from ..formats import trajectory as io

__all__ = ["MEMORY_FRACTION", "available_memory", "check_memory", "check_space", "human_bytes"]

#: The fraction of the available memory a job may plan to use (the rest: the interpreter and
#: libraries, other processes, the estimates' margin).
MEMORY_FRACTION = 0.5


def human_bytes(n: float) -> str:
    """``n`` bytes as ``"3.2 GB"`` (powers of 1000)."""
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if abs(n) < 1000 or unit == "PB":
            return f"{n:.3g} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1000.0
    return f"{n:.3g} PB"  # pragma: no cover


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation now (None: unknown)."""
    try:
        import psutil

        return int(psutil.virtual_memory().available)
    except Exception:  # noqa: BLE001 - no psutil, no /proc: no check
        return None


def check_memory(nbytes: float, what: str, allowed) -> None:
    """ValueError (one line) when ``what`` needs ``nbytes`` of memory, more than
    :data:`MEMORY_FRACTION` of :func:`available_memory`: ``"<what> needs ~N of memory, over 50% of the
    M available; allowed: <allowed>"``.  ``allowed`` names the option that bounds it: a
    str, or a function of the bytes the job may use returning one."""
    avail = available_memory()
    if avail is not None and nbytes > MEMORY_FRACTION * avail:
        text = allowed(MEMORY_FRACTION * avail) if callable(allowed) else allowed
        raise ValueError(f"{what} needs ~{human_bytes(nbytes)} of memory, over {MEMORY_FRACTION:.0%} of the "
                         f"{human_bytes(avail)} available; allowed: {text}")


def check_space(nbytes: float, path, what: str, allowed: str) -> None:
    """:class:`~tqdyn.formats.trajectory.OutputIOError` (one line, exit status 3: nothing written) when
    the file ``what`` at ``path``, at least ``nbytes`` long, cannot fit: more than the free space of
    the file system of its directory, or than the process's file-size limit (RLIMIT_FSIZE,
    ``ulimit -f``)."""
    from ..formats.atomic import file_size_limit

    try:
        st = os.statvfs(os.path.dirname(os.path.abspath(os.fspath(path))))
        free = st.f_bavail * st.f_frsize
    except (OSError, AttributeError):  # pragma: no cover - no statvfs
        free = None
    limit = file_size_limit()
    if free is not None and nbytes > free:
        why = f"{human_bytes(free)} are free there"
    elif limit is not None and nbytes > limit:
        why = f"the file-size limit is {human_bytes(limit)}"
    else:
        return
    raise io.OutputIOError(f"cannot write {what} {str(path)!r}: it needs at least {human_bytes(nbytes)}, {why}; "
                           f"allowed: {allowed}")
