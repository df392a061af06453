"""Output files: the check every writing command makes before any work (:func:`check_output`) and the
one mechanism behind the writers that replace a file atomically (:func:`replacing`, and
:func:`replacing_h5` for HDF5 files) (I/O only).

A file is written to a hidden temporary file ``.OUT.<random>.tmp`` next to the output and renamed
over it only when complete.  Any failure (an error, a full disk, Ctrl-C, a stop signal) removes the
temporary file and leaves the output path as it was.  A write that fails at run time (disk full,
file-size limit, I/O error) raises :class:`tqdyn.formats.trajectory.OutputIOError` (one line naming
the file and the cause; the command line exits with status 3).  HDF5 (2.0) crashes the process when
it flushes or closes a file whose writes failed: :func:`replacing_h5` builds the file in memory and
writes its image with ordinary file writes, so HDF5 never sees the full disk.
"""

from __future__ import annotations

import contextlib
import errno
import os
import pathlib
import secrets

from . import trajectory as _io
from .stop import check_stop
from .trajectory._h5safe import _fsize_limit, _io_reason

__all__ = ["NO_SPACE", "check_directory", "check_output", "file_size_limit", "replacing", "replacing_directory",
           "replacing_h5", "same_file", "write_failure"]


def _abs(path) -> pathlib.Path:
    return pathlib.Path(os.path.abspath(os.path.expanduser(os.fspath(path))))


def file_size_limit() -> int | None:
    """The process's file-size limit in bytes (RLIMIT_FSIZE, ``ulimit -f``; None: unlimited)."""
    return _fsize_limit()


def same_file(a, b) -> bool:
    """True when the paths ``a`` and ``b`` name the same file: by path, by symbolic link or by hard
    link (``os.path.samefile``: the same device and inode) when both exist; by absolute path otherwise."""
    pa, pb = _abs(a), _abs(b)
    if pa.exists() and pb.exists():
        return os.path.samefile(pa, pb)
    return pa == pb


def check_output(path, option: str, inputs) -> pathlib.Path:
    """Check, before any work, that an output can be written at ``path``
    (:func:`tqdyn.formats.trajectory.check_writable`) and that it is none of the command's
    ``inputs`` ({label: path}, None entries skipped; or an iterable of (label, path)): the same
    file by path, symbolic link or hard link.  Returns the absolute path; raises
    :class:`~tqdyn.formats.trajectory.OutputError` or ValueError ``"<option>: '<path>' is the input
    <label>; allowed: another file"`` (one line) otherwise."""
    out = _io.check_writable(path)
    for label, src in (inputs.items() if isinstance(inputs, dict) else inputs):
        if src is not None and os.path.exists(os.fspath(src)) and same_file(out, src):
            raise ValueError(f"{option}: {str(out)!r} is the input {label}"
                             + ("" if _abs(src) == out else f" ({str(_abs(src))!r}, the same file)")
                             + "; allowed: another file")
    return out


#: the errno values of a full disk: no space, the file-size limit, the disk quota
NO_SPACE = frozenset({errno.ENOSPC, errno.EFBIG, getattr(errno, "EDQUOT", errno.ENOSPC)})


def write_failure(exc: BaseException, writes_only: bool = True) -> OSError | None:
    """The OSError of ``exc`` if it is a failed write: ``exc`` itself when ``writes_only`` (the
    failing block only writes), or a full-disk error (:data:`NO_SPACE`: ENOSPC, EFBIG, EDQUOT) --
    ``exc`` or the error it was raised while handling, for a library whose clean-up fails in turn after
    a write failed (matplotlib's PDF writer).  None otherwise."""
    if writes_only and isinstance(exc, OSError):
        return exc
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in NO_SPACE:
            return exc
        exc = exc.__cause__ or exc.__context__
    return None


@contextlib.contextmanager
def replacing(out: pathlib.Path, what: str):
    """Yield a new hidden temporary path ``.OUT.<random>.tmp`` next to ``out`` for the caller to
    write; when the block ends normally the file is synced to disk and renamed over ``out`` (unless
    a stop signal arrived meanwhile: :func:`tqdyn.formats.stop.check_stop`).  On any failure
    (including KeyboardInterrupt) the temporary file is removed and ``out`` is left as it was; an
    ``OSError`` becomes :class:`tqdyn.formats.trajectory.OutputIOError` ``"cannot write <what>
    '<out>': <cause> (errno N)"`` (one line)."""
    out = pathlib.Path(out)
    tmp = out.parent / f".{out.name}.{secrets.token_hex(6)}.tmp"
    try:
        yield tmp
        check_stop()
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, out)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        failed = write_failure(exc)
        if failed is not None and not isinstance(failed, _io.OutputError):
            raise _io.OutputIOError(f"cannot write {what} {str(out)!r}: {_io_reason(failed)}") from None
        raise


@contextlib.contextmanager
def replacing_h5(out: pathlib.Path, what: str):
    """:func:`replacing` for an HDF5 file: yield an ``h5py.File`` built in memory (HDF5's core
    driver, no backing store); when the block ends normally its image is written to the temporary
    file with ordinary file writes and renamed over ``out``.  HDF5 itself never writes to the disk,
    so a full disk is an ordinary ``OSError`` of that write --
    :class:`~tqdyn.formats.trajectory.OutputIOError`, the temporary file removed -- instead of a
    failure inside HDF5 (which crashes HDF5 2.0 when it later flushes or closes the file).  The
    file is held in memory twice at the end (its pages and its image): for files of the size of
    the arrays written, not for streamed ones (:class:`~tqdyn.formats.trajectory.TrajectoryWriter`,
    :class:`~tqdyn.formats.closed_loop.ClosedLoopWriter` write to disk and handle a full disk
    themselves)."""
    import h5py

    with replacing(out, what) as tmp:
        h5 = h5py.File(tmp, "w", driver="core", backing_store=False)
        try:
            yield h5
            h5.flush()
            image = h5.id.get_file_image()
        finally:
            h5.close()
        with open(tmp, "xb") as f:
            f.write(image)
        del image


def _nearest_existing(path: pathlib.Path) -> pathlib.Path:
    while not path.exists():
        path = path.parent
    return path


def check_directory(out_dir, option: str) -> pathlib.Path:
    """Check, creating nothing, that ``out_dir`` is a directory, or can be created as one, that can be
    written.  Returns its absolute path; ValueError ``"<option>: ..."`` (one line) otherwise."""
    out = _abs(out_dir)
    base = _nearest_existing(out)
    if not base.is_dir():
        raise ValueError(f"{option}: {str(out)!r} " + ("is not a directory" if base == out else
                                                        f"cannot be created: {str(base)!r} is not a directory")
                         + "; allowed: a writable directory")
    if not os.access(base, os.W_OK | os.X_OK):
        raise ValueError(f"{option}: {str(out)!r} " + ("is not writable" if base == out else
                                                        f"cannot be created in {str(base)!r}, not writable")
                         + "; allowed: a writable directory")
    return out


@contextlib.contextmanager
def replacing_directory(out_dir, option: str = "--out"):
    """:func:`replacing` for the files of a directory: yield a new hidden temporary directory
    (``.tqdyn.<random>.tmp`` in ``out_dir``, or in its nearest existing parent if it does not exist)
    for the caller to write files into; when the block ends normally ``out_dir`` is created if needed
    and every file is renamed into it (other files there stay; files of the same names are replaced),
    then the temporary directory is removed.  On any failure (including KeyboardInterrupt) the
    temporary directory is removed and ``out_dir`` is left as it was (not even created); a full disk
    (:func:`write_failure`) becomes :class:`~tqdyn.formats.trajectory.OutputIOError` (one line).
    ``out_dir`` is checked first (:func:`check_directory`)."""
    import shutil

    out = check_directory(out_dir, option)
    stage = _nearest_existing(out) / f".tqdyn.{secrets.token_hex(6)}.tmp"
    try:
        stage.mkdir()
        yield stage
        check_stop()
        files = sorted(p for p in stage.rglob("*") if p.is_file())
        for p in files:
            dest = out / p.relative_to(stage)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(p, dest)
    except BaseException as exc:
        shutil.rmtree(stage, ignore_errors=True)
        failed = write_failure(exc, writes_only=False)  # the block reads its inputs too
        if failed is not None and not isinstance(failed, _io.OutputError):
            raise _io.OutputIOError(f"cannot write the files of {str(out)!r}: {_io_reason(failed)}") from None
        raise
    shutil.rmtree(stage, ignore_errors=True)
