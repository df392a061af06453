"""HDF5 file handles that survive a full disk: the low-level helpers of
:class:`~tqdyn.formats.trajectory.TrajectoryWriter` (I/O only).

HDF5 (2.0) crashes (SIGSEGV) when it closes a file whose pending writes keep
failing (ENOSPC, EFBIG), and again at interpreter exit.  After a failed
write the writer points the file's descriptor at /dev/null
(:func:`_neutralize`): HDF5 then closes it without error and the file on
disk stays as it was.
"""

from __future__ import annotations

import errno
import os
import re

import h5py

from .schema import OutputError

__all__: list[str] = []

#: True once an HDF5 file failed to close in this process.  HDF5 (2.0) then
#: crashes (SIGSEGV) on any later close, including at interpreter exit; a
#: command line that sees it set ends with ``os._exit`` after its message.
#: The writer avoids it: after a failed write or flush it points the file's
#: descriptor at /dev/null (:func:`_neutralize`) so that closing succeeds.
HDF5_POISONED = False

def _vfd(h5) -> int | None:
    """The POSIX file descriptor of an open h5py file (sec2 driver), or None."""
    try:
        fd = h5.id.get_vfd_handle()
    except Exception:  # pragma: no cover - other drivers
        return None
    return fd if isinstance(fd, int) and fd >= 0 else None


def _neutralize(state: dict) -> None:
    """Point the HDF5 file's descriptor at /dev/null: nothing more reaches the
    file on disk and HDF5's own later writes (on close) cannot fail.  HDF5
    crashes when it closes a file whose pending writes keep failing (disk
    full, EFBIG); after this the file on disk stays as it was."""
    fd = state.get("fd")
    if fd is None or state.get("neutralized"):
        return
    try:
        nul = os.open(os.devnull, os.O_RDWR)
        try:
            os.dup2(nul, fd)
        finally:
            os.close(nul)
        state["neutralized"] = True
    except OSError:  # pragma: no cover - best effort
        pass


def _close_h5(state: dict, keep: bool) -> None:
    """Close the HDF5 handle (idempotent).  ``keep``: the file must stay
    readable (flush first; if that fails, leave it as it is on disk)."""
    global HDF5_POISONED
    h5 = state.pop("h5", None)
    if h5 is None:
        return
    if keep and not state.get("neutralized"):
        try:
            h5.flush()
        except Exception:  # noqa: BLE001 - disk full etc.: keep what is on disk
            _neutralize(state)
    else:
        _neutralize(state)
    try:
        h5.close()
    except Exception:  # pragma: no cover - best effort
        HDF5_POISONED = True
    state.pop("fd", None)


def _cleanup(state: dict) -> None:
    """Close the HDF5 handle and delete the temporary file (idempotent)."""
    _close_h5(state, keep=False)
    tmp = state.pop("tmp", None)
    if tmp is not None:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass


def _io_reason(exc: BaseException) -> str:
    """The cause of an HDF5 / OS write failure in a few words (strerror)."""
    num = getattr(exc, "errno", None)
    if not isinstance(num, int):
        m = re.search(r"errno = (\d+)", str(exc))
        num = int(m.group(1)) if m else None
    if num:
        return f"{os.strerror(num)} (errno {num})"
    text = " ".join(str(exc).split())
    return text[:200] or type(exc).__name__


def _fsize_limit() -> int | None:
    """The soft RLIMIT_FSIZE of this process in bytes (None: unlimited / unknown)."""
    try:
        import resource
    except ImportError:  # pragma: no cover - Windows
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return None if soft == resource.RLIM_INFINITY or soft < 0 else int(soft)


def _fsync_strict(path, writer) -> None:
    """fsync a file; a failure (EIO, ENOSPC on network file systems) is an
    :class:`OutputIOError` of ``writer``."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError as exc:
        raise writer._io_failed(exc) from None
    try:
        os.fsync(fd)
    except OSError as exc:
        raise writer._io_failed(exc) from None
    finally:
        os.close(fd)


def headroom_errno(tmp, last_size, chunk_bytes: int) -> tuple[int | None, int]:
    """(errno or None, size of ``tmp``): ENOSPC / EFBIG if the file cannot grow
    by what the next checkpoint interval needs -- twice its growth since
    ``last_size``, at least two chunks of every dataset (``chunk_bytes``), plus
    1 MiB -- on its file system (free space) or under the file-size limit
    (RLIMIT_FSIZE).  A write failing in the middle of HDF5's bookkeeping
    leaves a file HDF5 cannot reopen; stopping before keeps it consistent.
    A check, not a reservation: another writer filling the disk meanwhile is
    not covered."""
    size = os.path.getsize(tmp)
    grown = size - (size if last_size is None else last_size)
    need = max(2 * grown, 2 * chunk_bytes) + (1 << 20)
    limit = _fsize_limit()
    if limit is not None and size + need > limit:
        return errno.EFBIG, size
    try:
        st = os.statvfs(tmp)
    except (OSError, AttributeError):  # pragma: no cover
        return None, size
    return (errno.ENOSPC if st.f_bavail * st.f_frsize < need else None), size


def check_partial(partial, rows: int) -> None:
    """Check, read-only and before any work, that the partial trajectory
    ``partial`` of a checkpoint can be continued (:meth:`reopen`): it
    exists, HDF5 opens it and its time field holds at least ``rows``
    rows.  Raises :class:`OutputError` (one line) otherwise."""
    name = os.path.basename(partial)
    if not os.path.isfile(partial):
        raise OutputError(f"partial trajectory {name!r} is missing")
    try:
        with h5py.File(partial, "r") as h5:
            t = h5["t"] if "t" in h5 else None
            n = rows if t is None else (t.shape[0] if isinstance(t, h5py.Dataset) else t["hi"].shape[0])
    except Exception as exc:  # noqa: BLE001 - damaged by a crash in the middle of a write
        reason = re.sub(r"^[^(]*\((.*)\)$", r"\1", _io_reason(exc)).split(",")[0]
        raise OutputError(f"partial trajectory {name!r} cannot be read ({reason})") from None
    if n < rows:
        raise OutputError(f"partial trajectory {name!r} holds {n} rows, the checkpoint needs {rows}")
