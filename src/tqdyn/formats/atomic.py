"""Atomic replacement of an output file: the one mechanism behind the OEM and
LISA orbit writers (I/O only)."""

from __future__ import annotations

import contextlib
import os
import pathlib
import secrets

from . import trajectory as _io

__all__ = ["replacing"]


@contextlib.contextmanager
def replacing(out: pathlib.Path, what: str):
    """Yield a new hidden temporary path ``.OUT.<random>.tmp`` next to
    ``out`` for the caller to write; when the block ends normally the file
    is synced to disk and renamed over ``out``.  On any failure (including
    KeyboardInterrupt) the temporary file is removed and ``out`` is left as
    it was; an ``OSError`` becomes :class:`tqdyn.formats.trajectory.OutputError`
    ``"cannot write <what> '<out>': ..."`` (one line)."""
    tmp = out.parent / f".{out.name}.{secrets.token_hex(6)}.tmp"
    try:
        yield tmp
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
        if isinstance(exc, OSError) and not isinstance(exc, _io.OutputError):
            raise _io.OutputError(f"cannot write {what} {str(out)!r}: {exc}") from None
        raise
