"""Writing trajectory files: :func:`check_writable` and :class:`TrajectoryWriter`.

Writing is atomic: :class:`TrajectoryWriter` writes to a hidden temporary file
in the destination directory and renames it into place on
:meth:`~TrajectoryWriter.close`; on any failure (including
``KeyboardInterrupt``) the temporary file is removed and the destination is
left untouched.  For checkpoints, :meth:`~TrajectoryWriter.sync`,
:meth:`~TrajectoryWriter.keep_partial` and :meth:`~TrajectoryWriter.reopen`
keep and continue a partial file.
"""

from __future__ import annotations

import os
import pathlib
import secrets
import weakref
from typing import Any, Mapping, Sequence

import h5py
import numpy as np

from . import _h5safe
from ._h5safe import _cleanup, _close_h5, _fsync_strict, _io_reason, _neutralize, _vfd, check_partial, headroom_errno
from .schema import FIELDS, FieldSpec, OutputError, OutputIOError, _check_attrs, _fmt_shape, _spec, _symbolic, dataset_attrs
from ..stop import check_stop

__all__ = ["check_writable", "hdf5_poisoned", "TrajectoryWriter"]

_DEFAULT_CHUNK_ROWS = 1024  # rows per chunk: also the rows buffered in memory (~2 MB for a coupled run)
# The rows are buffered here and written a whole chunk at a time, so HDF5's
# chunk cache would only keep written chunks resident (up to 1 MB per
# dataset, ~20 MB for a coupled run, growing with the run): no chunk cache.
_RDCC_NBYTES = 0

# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def _as_f8(value, name: str) -> np.ndarray:
    arr = np.asarray(value)
    if arr.dtype.kind not in "fiub":
        raise ValueError(f"field {name!r}: dtype {arr.dtype} is not real numeric (float64 expected)")
    return np.ascontiguousarray(arr, dtype=np.float64)


def _split_dd(value, name: str, shape: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(hi, lo) from a (hi, lo) pair, an object with .hi/.lo, or an array [..., 2]."""
    if isinstance(value, (tuple, list)):
        if len(value) != 2:
            raise ValueError(f"field {name!r}: double-double value must be a (hi, lo) pair, "
                             f"got a sequence of length {len(value)}")
        hi, lo = _as_f8(value[0], name + " hi"), _as_f8(value[1], name + " lo")
    elif hasattr(value, "hi") and hasattr(value, "lo") and not isinstance(value, np.ndarray):
        hi, lo = _as_f8(value.hi, name + " hi"), _as_f8(value.lo, name + " lo")
    else:
        arr = _as_f8(value, name)
        if arr.ndim != len(shape) + 1 or arr.shape[-1] != 2:
            raise ValueError(
                f"field {name!r}: double-double value must be a (hi, lo) tuple or an array of shape "
                f"{_fmt_shape(tuple(shape) + (2,))}, got array of shape {_fmt_shape(arr.shape)}")
        hi, lo = np.ascontiguousarray(arr[..., 0]), np.ascontiguousarray(arr[..., 1])
    if hi.shape != lo.shape:
        raise ValueError(f"field {name!r}: hi shape {_fmt_shape(hi.shape)} != lo shape "
                         f"{_fmt_shape(lo.shape)}")
    return hi, lo


def _fsync_path(path, directory: bool = False) -> None:
    flags = os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0)
    try:
        fd = os.open(path, flags)
    except OSError:  # pragma: no cover - e.g. directories on Windows
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


# ---------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------


def check_writable(path) -> pathlib.Path:
    """Check, before any propagation, that a trajectory can be written at ``path``.

    The parent directory must exist and be writable (probed by creating and
    removing a hidden file there) and ``path`` must not be a directory.  An
    existing regular file at ``path`` is fine (it will be replaced on success).

    Returns the absolute path (``pathlib.Path``); raises :class:`OutputError`
    with a one-line message naming the path otherwise.
    """
    raw = os.fspath(path)
    if raw == "" or raw.endswith(("/", os.sep)):
        raise OutputError(f"output path {raw!r} names a directory, not a file")
    p = pathlib.Path(os.path.abspath(os.path.expanduser(raw)))
    if p.is_dir():
        raise OutputError(f"output path {str(p)!r} is a directory, not a file")
    if p.exists() and not p.is_file():
        raise OutputError(f"output path {str(p)!r} exists and is not a regular file")
    parent = p.parent
    if not parent.exists():
        raise OutputError(f"output directory {str(parent)!r} does not exist (for {str(p)!r})")
    if not parent.is_dir():
        raise OutputError(f"output directory {str(parent)!r} is not a directory (for {str(p)!r})")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"output directory {str(parent)!r} is not writable (for {str(p)!r})")
    probe = parent / f".{p.name}.{secrets.token_hex(6)}.probe"
    try:
        fd = os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputError(f"output directory {str(parent)!r} is not writable (for {str(p)!r}): "
                          f"{exc.strerror or exc}") from None
    return p


def hdf5_poisoned() -> bool:
    """True once an HDF5 file failed to close in this process (HDF5 then
    crashes on any later close: a command line ends with ``os._exit``)."""
    return _h5safe.HDF5_POISONED


class TrajectoryWriter:
    """Write a trajectory incrementally to a temporary file next to `path`
    (same directory, hidden name) and rename it into place atomically on close().
    If the with-block raises (including KeyboardInterrupt), the temporary file is removed
    and no file appears at `path` (an existing file at `path` is left untouched).

    Parameters
    ----------
    path : str or os.PathLike
        Destination file (checked with :func:`check_writable`).
    attrs : mapping
        Root attributes.  Required: ``scenario`` (TOML text), ``epoch_utc``
        (ISO 8601), ``precision`` ("dd" | "float64"), ``step_s`` (float, s),
        ``integrator``, ``pointing`` (global | taylor1 | taylor2 | iterative |
        none), ``control`` (on | off).  ``format``, ``format_version``,
        ``tqdyn_version``, ``origin`` ("earth"), ``frame`` ("GCRS") and ``time_scale`` ("TT") are
        filled in (a given ``tqdyn_version`` is kept; the others must match).
        Extra str/int/float attributes are stored as given; the spacecraft
        attributes of a coupled run (:data:`SPACECRAFT_ATTRS
        <tqdyn.formats.trajectory.schema.SPACECRAFT_ATTRS>`) are checked
        (JSON (2, 3) vectors, theta in (0, pi) rad) and also state the
        drag-free scheme and the TMs' sensitive axes on the actuation datasets
        (:func:`~tqdyn.formats.trajectory.schema.dataset_attrs`).
    fields : sequence of str
        Paths from :data:`FIELDS` this file will contain; must include ``"t"``
        if any other time-dependent field is listed.  Static fields listed here
        must be given with :meth:`set_static` before :meth:`close`.
    n_sat : int
        Length of the satellite axis (>= 1; 3 for coupled runs).
    expected_rows : int, optional
        Hint only: number of time rows expected.  Datasets are pre-allocated to
        it (and trimmed to :attr:`rows_written` on close) and the chunk size is
        ``min(expected_rows, _DEFAULT_CHUNK_ROWS)`` rows.  Writing more or fewer rows is fine.
    compression : str, optional
        h5py compression filter for time-dependent datasets (default None:
        off, for speed).

    Data are float64 (SI units, TT seconds since the epoch, frames as in :data:`FIELDS`); each
    :meth:`append` adds ``rows`` time rows to every time-dependent field.
    Every dataset carries a Fletcher-32 checksum.

    A write that fails at run time (disk full, file-size limit) raises
    :class:`OutputIOError`; the writer then writes nothing more to the
    temporary file, and :meth:`abort` (as the with-block does) removes it or
    :meth:`keep_partial` keeps it for a checkpoint.
    """

    def __init__(self, path, attrs: Mapping[str, Any], fields: Sequence[str], n_sat: int,
                 expected_rows: int | None = None, *, compression: str | None = None):
        self._path = check_writable(path)
        if isinstance(n_sat, bool) or not isinstance(n_sat, (int, np.integer)) or not n_sat >= 1:
            raise ValueError(f"n_sat = {n_sat!r}; allowed: an integer >= 1 (the number of satellites)")
        self._n_sat = int(n_sat)
        if isinstance(fields, str):
            raise ValueError("fields: must be a sequence of field paths, not a single str")
        fields = list(fields)
        for f in fields:
            _spec(f, "fields")
        dup = sorted({f for f in fields if fields.count(f) > 1})
        if dup:
            raise ValueError(f"fields: duplicate field(s) {', '.join(dup)}")
        self._fields = tuple(f for f in FIELDS if f in fields)  # canonical order
        self._tfields = tuple(f for f in self._fields if FIELDS[f].time_dependent)
        if self._tfields and "t" not in self._tfields:
            raise ValueError("fields: time-dependent fields need the time field 't'")
        self._static_pending = {f for f in self._fields if not FIELDS[f].time_dependent}
        if expected_rows is not None and (isinstance(expected_rows, bool)
                                          or not isinstance(expected_rows, (int, np.integer))
                                          or expected_rows < 0):
            raise ValueError(f"expected_rows = {expected_rows!r}; must be a non-negative int or None")
        self._expected = int(expected_rows) if expected_rows is not None else 0
        self._chunk_rows = max(1, min(_DEFAULT_CHUNK_ROWS, self._expected or _DEFAULT_CHUNK_ROWS))
        full_attrs = _check_attrs(attrs)
        self._attrs = full_attrs

        self._rows = 0  # rows appended (on disk + buffered)
        self._rows_on_disk = 0
        self._buf: dict[str, list] = {f: [] for f in self._tfields}
        self._buf_rows = 0
        self._status = "open"
        self._state: dict = {}
        tmp = self._make_tmp()
        self._state["tmp"] = tmp
        self._finalizer = weakref.finalize(self, _cleanup, self._state)
        try:
            h5 = h5py.File(tmp, "w", rdcc_nbytes=_RDCC_NBYTES)
            self._state["h5"] = h5
            self._state["fd"] = _vfd(h5)
            for k, v in full_attrs.items():
                h5.attrs[k] = v
            self._dsets: dict[str, tuple] = {}
            for f in self._tfields:
                spec = FIELDS[f]
                trail = spec.resolved_shape(self._n_sat)
                kw = dict(shape=(self._expected,) + trail, maxshape=(None,) + trail,
                          dtype=np.float64, chunks=(self._chunk_rows,) + trail,
                          compression=compression, fletcher32=True)
                if spec.kind == "dd":
                    g = h5.create_group(f)
                    self._field_attrs(g, f)
                    self._dsets[f] = (g.create_dataset("hi", **kw), g.create_dataset("lo", **kw))
                else:
                    ds = h5.create_dataset(f, **kw)
                    self._field_attrs(ds, f)
                    self._dsets[f] = (ds,)
        except BaseException as exc:
            self.abort()
            if isinstance(exc, OSError) and not isinstance(exc, OutputError):
                raise OutputError(f"cannot create temporary file {tmp!r} for {str(self._path)!r}: "
                                  f"{exc}") from exc
            raise

    # -- helpers -------------------------------------------------------------
    def _make_tmp(self) -> str:
        for _ in range(100):
            tmp = str(self._path.parent / f".{self._path.name}.{secrets.token_hex(6)}.tmp")
            try:
                fd = os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666)  # honours umask
            except FileExistsError:  # pragma: no cover - astronomically unlikely
                continue
            except OSError as exc:
                raise OutputError(f"cannot create temporary file in {str(self._path.parent)!r} "
                                  f"for {str(self._path)!r}: {exc.strerror or exc}") from None
            os.close(fd)
            return tmp
        raise OutputError(f"cannot create a unique temporary file for {str(self._path)!r}")  # pragma: no cover

    def _field_attrs(self, obj, path: str) -> None:
        # units, frame (the time field's is the file's time scale, the vectors' the file's frame),
        # description, components and, for the actuation fields, the drag-free scheme and sensitive axes
        for key, value in dataset_attrs(path, self._attrs).items():
            obj.attrs[key] = value

    def _require_open(self, what: str) -> h5py.File:
        if self._status != "open":
            raise ValueError(f"{what}: writer for {str(self._path)!r} is already {self._status}")
        return self._state["h5"]

    def _io_failed(self, exc: BaseException) -> OutputIOError:
        """A write to the temporary file failed: stop writing to it (its
        descriptor now points at /dev/null, see :func:`_neutralize`) and
        return the one-line error.  The caller decides whether the partial
        file is kept (:meth:`keep_partial`, for a checkpoint) or removed
        (:meth:`abort`, as on any failure in a with-block)."""
        _neutralize(self._state)
        self._status = "failed"
        err = OutputIOError(f"cannot write the trajectory {str(self._path)!r} (temporary file "
                            f"{self._state.get('tmp')!r}): {_io_reason(exc)}")
        self._failure = err
        return err

    def _coerce(self, name: str, spec: FieldSpec, value, static: bool) -> tuple[np.ndarray, ...]:
        trail = spec.resolved_shape(self._n_sat)
        if spec.kind == "dd":
            arrays = _split_dd(value, name, trail if static else ("rows",) + trail)
        else:
            arrays = (_as_f8(value, name),)
        for a in arrays:
            if static:
                if a.shape != trail:
                    raise ValueError(f"field {name!r}: shape {_fmt_shape(a.shape)}, expected "
                                     f"{_fmt_shape(trail)} (static, n_sat={self._n_sat})")
            elif a.ndim != len(trail) + 1 or a.shape[1:] != trail:
                raise ValueError(f"field {name!r}: shape {_fmt_shape(a.shape)}, expected "
                                 f"{_fmt_shape(('rows',) + trail)} = {_symbolic(spec)} with "
                                 f"n_sat={self._n_sat}")
        return arrays

    # -- public API ----------------------------------------------------------
    @property
    def path(self) -> pathlib.Path:
        """Final destination path (absolute)."""
        return self._path

    @property
    def fields(self) -> tuple[str, ...]:
        """Declared fields, in canonical :data:`FIELDS` order."""
        return self._fields

    @property
    def n_sat(self) -> int:
        """Length of the satellite axis (>= 1)."""
        return self._n_sat

    @property
    def rows_written(self) -> int:
        """Number of time rows appended so far (including rows still buffered in memory)."""
        return self._rows

    def append(self, rows: Mapping[str, np.ndarray | tuple[np.ndarray, np.ndarray]]) -> None:
        """Append one chunk of time rows.

        ``rows`` maps *every* declared time-dependent field to its new rows:
        f8 fields as float64 arrays of shape ``(rows, *trailing)``; dd fields as
        a ``(hi, lo)`` tuple of two such arrays, or one array of shape
        ``(rows, *trailing, 2)`` with ``[..., 0] = hi`` and ``[..., 1] = lo``.
        Trailing shapes are those of :data:`FIELDS` with ``sat`` = n_sat and
        ``tm`` = 2 (e.g. ``sat/r``: ``(rows, n_sat, 3)`` in m, GCRS; ``t``:
        ``(rows,)`` in TT seconds since the epoch).  All fields must have the
        same number of rows.  Everything is validated before anything is
        stored, so a rejected call (ValueError naming the field) changes
        nothing.  The data are copied; small appends are buffered in memory
        and written in blocks of the chunk size (``_DEFAULT_CHUNK_ROWS`` rows by
        default), so appending one row per step is fine.
        """
        self._require_open("append")
        if not isinstance(rows, Mapping):
            raise TypeError(f"append: rows must be a mapping field -> array, got {type(rows).__name__}")
        for name in rows:
            spec = _spec(name, "append")
            if name not in self._fields:
                raise ValueError(f"append: field {name!r} was not declared in fields "
                                 f"({', '.join(self._fields)})")
            if not spec.time_dependent:
                raise ValueError(f"append: field {name!r} is static; use set_static()")
        missing = [f for f in self._tfields if f not in rows]
        if missing:
            raise ValueError(f"append: missing field(s) {', '.join(missing)} (every declared "
                             "time-dependent field needs rows in each append)")
        data = {f: self._coerce(f, FIELDS[f], rows[f], static=False) for f in self._tfields}
        counts = {f: a[0].shape[0] for f, a in data.items()}
        n = counts.get("t", 0)
        bad = [f for f, c in counts.items() if c != n]
        if bad:
            raise ValueError(f"append: field {bad[0]!r} has {counts[bad[0]]} rows but 't' has {n}; "
                             "all fields need the same number of rows")
        if n == 0:
            return
        # buffer small appends (copied: callers may reuse their arrays) and
        # write whole blocks, so per-step appends stay cheap
        for f, arrays in data.items():
            self._buf[f].append(tuple(np.array(a, dtype=np.float64, copy=True) for a in arrays))
        self._buf_rows += n
        self._rows += n
        if self._buf_rows >= self._chunk_rows:
            self._flush()

    def _flush(self) -> None:
        """Write the buffered rows to the datasets."""
        if not self._buf_rows:
            return
        r1 = self._rows_on_disk + self._buf_rows
        r0 = self._rows_on_disk
        try:
            for f, parts in self._buf.items():
                for k, ds in enumerate(self._dsets[f]):
                    block = parts[0][k] if len(parts) == 1 else np.concatenate([p[k] for p in parts])
                    if ds.shape[0] < r1:
                        ds.resize(r1, axis=0)
                    ds[r0:r1] = block
                parts.clear()
        except (OSError, RuntimeError) as exc:
            raise self._io_failed(exc) from None
        self._buf_rows = 0
        self._rows_on_disk = r1

    def set_static(self, path: str, value: np.ndarray) -> None:
        """Store a static (no time axis) field, e.g. ``tm/self_gravity``.

        ``value`` has the field's trailing shape (``tm/self_gravity``:
        ``(n_sat, 2, 3)`` in m/s^2, frame OA_l).  The field need not be listed
        in ``fields``; setting it again replaces the previous value.
        """
        h5 = self._require_open("set_static")
        spec = _spec(path, "set_static")
        if spec.time_dependent:
            raise ValueError(f"set_static: field {path!r} is time-dependent; use append()")
        arrays = self._coerce(path, spec, value, static=True)
        try:
            if path in h5:
                del h5[path]
            if spec.kind == "dd":
                g = h5.create_group(path)
                self._field_attrs(g, path)
                g.create_dataset("hi", data=arrays[0], fletcher32=True)
                g.create_dataset("lo", data=arrays[1], fletcher32=True)
            else:
                ds = h5.create_dataset(path, data=arrays[0], fletcher32=True)
                self._field_attrs(ds, path)
        except (OSError, RuntimeError) as exc:
            raise self._io_failed(exc) from None
        except BaseException:
            self.abort()
            raise
        self._static_pending.discard(path)
        if path not in self._fields:
            self._fields = tuple(f for f in FIELDS if f in self._fields or f == path)

    def close(self) -> pathlib.Path:
        """Finish the file and atomically rename it to :attr:`path`; return that path.

        Raises ValueError if a declared static field was never set (the
        temporary file is then removed).  Calling close() again returns the path.
        """
        if self._status == "closed":
            return self._path
        if self._status == "failed":
            raise self._failure
        h5 = self._require_open("close")
        check_stop()  # a stop signal that arrived: the partial file stays as it is (a checkpoint may need it)
        try:
            if self._static_pending:
                raise ValueError(f"close: declared static field(s) {', '.join(sorted(self._static_pending))} "
                                 "never set with set_static()")
            self._flush()
            try:
                for dsets in self._dsets.values():
                    for ds in dsets:
                        if ds.shape[0] != self._rows:
                            ds.resize(self._rows, axis=0)
                h5.flush()  # a failure here is caught while HDF5 can still close safely
            except (OSError, RuntimeError) as exc:
                raise self._io_failed(exc) from None
            _close_h5(self._state, keep=True)
            if self._state.get("neutralized"):  # pragma: no cover - the flush above succeeded
                raise self._io_failed(OSError("closing failed"))
            tmp = self._state["tmp"]
            _fsync_strict(tmp, self)
            try:
                os.replace(tmp, self._path)
            except OSError as exc:
                raise OutputError(f"cannot move finished trajectory into place at {str(self._path)!r}: "
                                  f"{exc.strerror or exc}") from None
            self._state.pop("tmp", None)
            _fsync_path(self._path.parent, directory=True)
        except OutputIOError:
            # a failed write: the caller keeps the partial file for a checkpoint
            # (keep_partial) or removes it (abort; a with-block does)
            raise
        except BaseException:
            self.abort()
            raise
        self._status = "closed"
        self._finalizer.detach()
        return self._path

    # -- checkpoints ---------------------------------------------------------
    def sync(self) -> str:
        """Write every buffered row to the temporary file and flush it to
        disk, so that its first :attr:`rows_written` rows survive a crash;
        returns the temporary file's path (for a checkpoint)."""
        h5 = self._require_open("sync")
        self._flush()
        try:
            h5.flush()
        except (OSError, RuntimeError) as exc:
            raise self._io_failed(exc) from None
        _fsync_strict(self._state["tmp"], self)
        return self._state["tmp"]

    def check_headroom(self) -> None:
        """After a sync and its checkpoint (or a :meth:`reopen`): check that
        the file can grow by what the next checkpoint interval needs (see
        :func:`._h5safe.headroom_errno`); if not, stop now with an
        :class:`OutputIOError`, while the partial file is consistent and the
        checkpoint written for it valid for ``--resume``."""
        chunk_bytes = sum(ds.chunks and int(np.prod(ds.chunks)) * 8 + 64
                          for dsets in self._dsets.values() for ds in dsets)
        num, self._synced_size = headroom_errno(self._state["tmp"], getattr(self, "_synced_size", None), chunk_bytes)
        if num:
            raise self._io_failed(OSError(num, os.strerror(num)))

    def keep_partial(self) -> str | None:
        """Close the temporary file WITHOUT deleting it (a run interrupted
        after a checkpoint keeps its partial trajectory for ``--resume``);
        :attr:`path` is untouched.  Returns the partial file's path."""
        if self._status not in ("open", "failed"):
            return None
        tmp = self._state.get("tmp")
        _close_h5(self._state, keep=True)
        self._state.pop("tmp", None)
        self._finalizer.detach()
        self._status = "aborted"
        return tmp

    check_partial = staticmethod(check_partial)

    @classmethod
    def reopen(cls, partial, path, rows: int) -> "TrajectoryWriter":
        """Continue a partial trajectory written by an interrupted run: the
        temporary file ``partial`` is truncated to its first ``rows`` time
        rows (those covered by the checkpoint) and appended to; close()
        renames it to ``path`` as usual."""
        self = cls.__new__(cls)
        self._path = check_writable(path)
        if not os.path.isfile(partial):
            raise OutputError(f"partial trajectory {os.path.basename(partial)!r} is missing")
        self._state = {"tmp": str(partial)}
        self._finalizer = weakref.finalize(self, _cleanup, self._state)
        try:
            h5 = h5py.File(partial, "r+", rdcc_nbytes=_RDCC_NBYTES)
        except OSError as exc:
            self._finalizer.detach()
            raise OutputError(f"cannot reopen partial trajectory {str(partial)!r}: {exc}") from None
        self._state["h5"] = h5
        self._state["fd"] = _vfd(h5)
        try:
            self._reopen_datasets(h5, partial, rows)
        except OutputError:
            _close_h5(self._state, keep=True)
            self._finalizer.detach()
            raise
        except Exception as exc:  # noqa: BLE001 - a damaged partial file
            _close_h5(self._state, keep=True)
            self._finalizer.detach()
            raise OutputError(f"cannot continue partial trajectory {str(partial)!r}: {_io_reason(exc)}") from None
        self._status = "open"
        return self

    def _reopen_datasets(self, h5, partial, rows: int) -> None:
        self._attrs = {k: (v.decode() if isinstance(v, bytes) else v.item() if isinstance(v, np.generic) else v)
                       for k, v in h5.attrs.items()}
        self._fields = tuple(f for f in FIELDS if f in h5)
        self._tfields = tuple(f for f in self._fields if FIELDS[f].time_dependent)
        self._static_pending = set()
        self._dsets = {f: ((h5[f]["hi"], h5[f]["lo"]) if FIELDS[f].kind == "dd" else (h5[f],))
                       for f in self._tfields}
        self._n_sat = int(self._dsets["sat/r"][0].shape[1]) if "sat/r" in self._dsets else 1
        for dsets in self._dsets.values():
            for ds in dsets:
                if ds.shape[0] < rows:
                    raise OutputError(f"partial trajectory {str(partial)!r} holds {ds.shape[0]} rows, "
                                      f"the checkpoint needs {rows}; cannot resume")
                ds.resize(rows, axis=0)
        self._expected = rows
        self._chunk_rows = self._dsets["t"][0].chunks[0] if "t" in self._dsets else _DEFAULT_CHUNK_ROWS
        self._rows = self._rows_on_disk = rows
        self._buf = {f: [] for f in self._tfields}
        self._buf_rows = 0

    def abort(self) -> None:
        """Discard everything: close and delete the temporary file; :attr:`path` is untouched.
        (Also after a failed write: the file is closed without writing more.)"""
        if self._status == "closed":
            return
        for parts in getattr(self, "_buf", {}).values():
            parts.clear()
        self._buf_rows = 0
        _cleanup(self._state)
        self._status = "aborted"

    def __enter__(self) -> "TrajectoryWriter":
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is not None:
            self.abort()
            return False
        if self._status in ("open", "failed"):
            try:
                self.close()
            except BaseException:
                self.abort()
                raise
        return False

    def __repr__(self) -> str:
        return (f"TrajectoryWriter({str(self._path)!r}, n_sat={self._n_sat}, "
                f"rows_written={self._rows}, status={self._status!r})")


