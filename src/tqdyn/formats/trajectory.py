"""Trajectory files: the public HDF5 output format of tqdyn (I/O only).

This module writes and reads the ``tqdyn-trajectory`` HDF5 format, version
:data:`FORMAT_VERSION`.  It is pure I/O: it imports no physics module and no
physics module imports it.  The format is documented field by field in
``docs/trajectory-format.md``; :data:`FIELDS` is its machine-readable form.

Conventions (for every field, see :data:`FIELDS` for each one's unit/frame)
--------------------------------------------------------------------------
* Units: SI (m, m/s, m/s^2, rad, rad/s, rad/s^2, s).
* Time scale: TDB.  Times ``t`` are seconds since the root attribute
  ``epoch_utc`` (the epoch is *labelled* in UTC, ISO 8601; elapsed time is TDB).
* Frame: GCRS for inertial vectors; body frame S for the angular velocity;
  the optical-assembly frame OA_l for test-mass quantities.
* Shapes: ``[time, satellite, tm, component]``; the satellite axis has length
  ``n_sat`` in 1..3, the test-mass (= MOSA) axis length 2, components x, y, z.
* Double-double ("dd") fields are HDF5 groups holding two float64 datasets
  ``hi`` and ``lo`` of equal shape; the value is the unevaluated sum
  ``hi + lo``.  "f8" fields are a single float64 dataset.

Writing is atomic: :class:`TrajectoryWriter` writes to a hidden temporary file
in the destination directory and renames it into place on :meth:`close`; on any
failure (including ``KeyboardInterrupt``) the temporary file is removed and the
destination is left untouched.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
import pathlib
import secrets
import weakref
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import h5py
import numpy as np

from .. import __version__ as _TQDYN_VERSION
from ..numerics.dd import np_two_sum

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "FieldSpec",
    "FIELDS",
    "ROOT_ATTRS",
    "OutputError",
    "TrajectoryFormatError",
    "check_writable",
    "TrajectoryWriter",
    "Trajectory",
    "read_trajectory",
]

FORMAT = "tqdyn-trajectory"
"""Value of the root attribute ``format``."""

FORMAT_VERSION = 1
"""Format version written by this module; readers accept any version <= this."""

_DEFAULT_CHUNK_ROWS = 4096

# ---------------------------------------------------------------------------
# field catalogue
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class FieldSpec:
    """Description of one trajectory field (one HDF5 path).

    Attributes
    ----------
    kind : str
        ``"dd"`` (group with float64 datasets ``hi``/``lo``, value = hi + lo)
        or ``"f8"`` (one float64 dataset).
    shape : tuple of (str | int)
        Trailing shape *without* the time axis; ``"sat"`` stands for the
        satellite axis (length n_sat, 1..3), ``"tm"`` for the test-mass / MOSA
        axis (length 2).  ``()`` for a scalar per time row.
    unit : str
        SI unit (``"1"`` for dimensionless).
    frame : str
        Frame the components are expressed in (or what the quantity refers to).
    description : str
        One-line meaning.
    time_dependent : bool
        True: stored with a leading time axis of length N (same N for every
        time-dependent field).  False: static, stored with ``shape`` only.
    dims : tuple of str
        xarray dimension names for ``shape`` (``"sat"``, ``"tm"``, ``"comp"``,
        ``"row"``, ``"col"``); the time axis (``"time"``) is not included.
    """

    kind: str
    shape: tuple
    unit: str
    frame: str
    description: str
    time_dependent: bool
    dims: tuple

    def resolved_shape(self, n_sat: int) -> tuple[int, ...]:
        """Trailing shape (no time axis) with ``sat`` -> n_sat and ``tm`` -> 2."""
        return tuple(n_sat if a == "sat" else 2 if a == "tm" else int(a) for a in self.shape)


def _f(kind, shape, dims, unit, frame, description, time_dependent=True):
    return FieldSpec(kind, tuple(shape), unit, frame, description, time_dependent, tuple(dims))


FIELDS: dict[str, FieldSpec] = {
    "t": _f("dd", (), (), "s", "TDB",
            "time since epoch_utc, TDB seconds"),
    "sat/r": _f("dd", ("sat", 3), ("sat", "comp"), "m", "GCRS",
                "satellite centre-of-mass position"),
    "sat/v": _f("dd", ("sat", 3), ("sat", "comp"), "m/s", "GCRS",
                "satellite centre-of-mass velocity"),
    "sat/a_gravity": _f("f8", ("sat", 3), ("sat", "comp"), "m/s^2", "GCRS",
                        "satellite gravitational acceleration, all gravitational terms"),
    "sat/a_dragfree": _f("f8", ("sat", 3), ("sat", "comp"), "m/s^2", "GCRS",
                         "drag-free control acceleration G_i of the satellite"),
    "sat/T_S_I": _f("f8", ("sat", 3, 3), ("sat", "row", "col"), "1", "GCRS -> S",
                    "rotation matrix inertial (GCRS) -> body frame S; rows are X_S, Y_S, Z_S "
                    "in GCRS components"),
    "sat/omega": _f("f8", ("sat", 3), ("sat", "comp"), "rad/s", "S",
                    "angular velocity of S relative to GCRS, components in S"),
    "sat/omega_dot": _f("f8", ("sat", 3), ("sat", "comp"), "rad/s^2", "S",
                        "angular acceleration of S relative to GCRS, components in S"),
    "sat/breathing_angle": _f("f8", ("sat",), ("sat",), "rad", "constellation",
                              "breathing angle alpha_i: angle at satellite i between its two arms"),
    "mosa/angle": _f("f8", ("sat", "tm"), ("sat", "tm"), "rad", "S",
                     "angle of X_OA_l from X_S about Z_S (MOSA l = 1, 2)"),
    "tm/r": _f("dd", ("sat", "tm", 3), ("sat", "tm", "comp"), "m", "GCRS",
               "test-mass centre-of-mass position"),
    "tm/v": _f("dd", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s", "GCRS",
               "test-mass centre-of-mass velocity (extension of format version 1)"),
    "tm/a": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "GCRS",
               "test-mass total acceleration: gravity + self-gravity + suspension "
               "(extension of format version 1)"),
    "tm/housing_offset": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m", "GCRS",
                            "free-TM verification mode: TM position minus its housing centre "
                            "(extension of format version 1)"),
    "tm/a_suspension": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "OA_l",
                          "test-mass suspension (actuation) acceleration"),
    "tm/alpha_suspension": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "rad/s^2", "OA_l",
                              "angular acceleration the test mass needs (suspension)"),
    "tm/self_gravity": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "OA_l",
                          "spacecraft self-gravity acceleration at the test mass (static)",
                          time_dependent=False),
}
"""Every field of format version 1, keyed by HDF5 path, in canonical order."""

ROOT_ATTRS: dict[str, str] = {
    "format": f'str, always "{FORMAT}"',
    "format_version": f"int, {FORMAT_VERSION}",
    "tqdyn_version": "str, version of tqdyn that wrote the file",
    "scenario": "str, the resolved scenario as TOML text",
    "epoch_utc": "str, ISO 8601 UTC label of t = 0",
    "time_scale": 'str, always "TDB"',
    "frame": 'str, always "GCRS"',
    "precision": 'str, "dd" | "float64"',
    "step_s": "float, integrator / output step in s",
    "integrator": "str, integrator name",
    "pointing": 'str, "global" | "taylor1" | "taylor2" | "iterative" | "none"',
    "control": 'str, "on" | "off"',
}
"""Root attributes of format version 1 and their type / allowed values."""

_REQUIRED_USER_ATTRS = ("scenario", "epoch_utc", "precision", "step_s", "integrator",
                        "pointing", "control")
_CHOICES = {
    "precision": ("dd", "float64"),
    "pointing": ("global", "taylor1", "taylor2", "iterative", "none"),
    "control": ("on", "off"),
    "time_scale": ("TDB",),
    "frame": ("GCRS",),
}
_COORDS = {
    "tm": [1, 2],
    "comp": ["x", "y", "z"],
    "row": ["X_S", "Y_S", "Z_S"],
    "col": ["x", "y", "z"],
}


class OutputError(OSError):
    """The output path cannot be written (one-line message naming the path)."""


class TrajectoryFormatError(ValueError):
    """A file is not a readable tqdyn trajectory (one-line message naming the file)."""


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def _fmt_shape(shape) -> str:
    return "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def _symbolic(spec: FieldSpec) -> str:
    names = {"sat": "n_sat", "tm": "tm"}
    return _fmt_shape(("rows",) + tuple(names.get(a, a) for a in spec.shape))


def _spec(path: str, where: str) -> FieldSpec:
    try:
        return FIELDS[path]
    except KeyError:
        raise ValueError(f"{where}: unknown field {path!r}; allowed: {', '.join(FIELDS)}") from None


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


def _check_attrs(attrs: Mapping[str, Any]) -> dict[str, Any]:
    """Validate the caller's root attributes and return the full attribute dict."""
    if not isinstance(attrs, Mapping):
        raise TypeError(f"attrs must be a mapping, got {type(attrs).__name__}")
    missing = [k for k in _REQUIRED_USER_ATTRS if k not in attrs]
    if missing:
        raise ValueError(f"attrs: missing required root attribute(s) {', '.join(missing)}")
    out: dict[str, Any] = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "tqdyn_version": _TQDYN_VERSION,
        "time_scale": "TDB",
        "frame": "GCRS",
    }
    for key, val in attrs.items():
        if not isinstance(key, str) or not key:
            raise ValueError(f"attrs: attribute names must be non-empty str, got {key!r}")
        if isinstance(val, (bool, np.bool_)):
            raise ValueError(f"attrs[{key!r}]: bool is not allowed; use a str (e.g. \"on\"/\"off\")")
        if isinstance(val, np.generic):
            val = val.item()
        if not isinstance(val, (str, int, float)):
            raise ValueError(f"attrs[{key!r}]: must be str, int or float, got {type(val).__name__}")
        out[key] = val
    if out["format"] != FORMAT or out["format_version"] != FORMAT_VERSION:
        raise ValueError(f"attrs: format/format_version are set by the writer and must be "
                         f"{FORMAT!r}/{FORMAT_VERSION}, got {out['format']!r}/{out['format_version']!r}")
    out["format"], out["format_version"] = FORMAT, FORMAT_VERSION  # exact types (str, int)
    for key, allowed in _CHOICES.items():
        if out[key] not in allowed:
            raise ValueError(f"attrs[{key!r}] = {out[key]!r}; allowed: {' | '.join(allowed)}")
    for key in ("scenario", "epoch_utc", "integrator", "tqdyn_version"):
        if not isinstance(out[key], str):
            raise ValueError(f"attrs[{key!r}]: must be str, got {type(out[key]).__name__}")
    try:
        _dt.datetime.fromisoformat(out["epoch_utc"])
    except ValueError:
        raise ValueError(f"attrs['epoch_utc'] = {out['epoch_utc']!r} is not an ISO 8601 "
                         "date-time (e.g. 2034-01-01T00:00:00)") from None
    step = out["step_s"]
    if isinstance(step, str) or not math.isfinite(step):
        raise ValueError(f"attrs['step_s'] = {step!r}; must be a finite number of seconds")
    out["step_s"] = float(step)
    return out


def _cleanup(state: dict) -> None:
    """Close the HDF5 handle and delete the temporary file (idempotent)."""
    h5 = state.pop("h5", None)
    if h5 is not None:
        try:
            h5.close()
        except Exception:  # pragma: no cover - best effort
            pass
    tmp = state.pop("tmp", None)
    if tmp is not None:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass


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
        ``tqdyn_version``, ``time_scale`` ("TDB") and ``frame`` ("GCRS") are
        filled in (a given ``tqdyn_version`` is kept; the others must match).
        Extra str/int/float attributes are stored as given.
    fields : sequence of str
        Paths from :data:`FIELDS` this file will contain; must include ``"t"``
        if any other time-dependent field is listed.  Static fields listed here
        must be given with :meth:`set_static` before :meth:`close`.
    n_sat : int
        Length of the satellite axis, 1..3.
    expected_rows : int, optional
        Hint only: number of time rows expected.  Datasets are pre-allocated to
        it (and trimmed to :attr:`rows_written` on close) and the chunk size is
        ``min(expected_rows, 4096)`` rows.  Writing more or fewer rows is fine.
    compression : str, optional
        h5py compression filter for time-dependent datasets (default None:
        off, for speed).

    Data are float64 (SI units, TDB seconds, frames as in :data:`FIELDS`); each
    :meth:`append` adds ``rows`` time rows to every time-dependent field.
    """

    def __init__(self, path, attrs: Mapping[str, Any], fields: Sequence[str], n_sat: int,
                 expected_rows: int | None = None, *, compression: str | None = None):
        self._path = check_writable(path)
        if isinstance(n_sat, bool) or not isinstance(n_sat, (int, np.integer)) or not 1 <= n_sat <= 3:
            raise ValueError(f"n_sat = {n_sat!r}; allowed: 1, 2 or 3")
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
            h5 = h5py.File(tmp, "w")
            self._state["h5"] = h5
            for k, v in full_attrs.items():
                h5.attrs[k] = v
            self._dsets: dict[str, tuple] = {}
            for f in self._tfields:
                spec = FIELDS[f]
                trail = spec.resolved_shape(self._n_sat)
                kw = dict(shape=(self._expected,) + trail, maxshape=(None,) + trail,
                          dtype=np.float64, chunks=(self._chunk_rows,) + trail,
                          compression=compression)
                if spec.kind == "dd":
                    g = h5.create_group(f)
                    self._field_attrs(g, spec)
                    self._dsets[f] = (g.create_dataset("hi", **kw), g.create_dataset("lo", **kw))
                else:
                    ds = h5.create_dataset(f, **kw)
                    self._field_attrs(ds, spec)
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

    @staticmethod
    def _field_attrs(obj, spec: FieldSpec) -> None:
        obj.attrs["units"] = spec.unit
        obj.attrs["frame"] = spec.frame
        obj.attrs["description"] = spec.description

    def _require_open(self, what: str) -> h5py.File:
        if self._status != "open":
            raise ValueError(f"{what}: writer for {str(self._path)!r} is already {self._status}")
        return self._state["h5"]

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
        """Length of the satellite axis (1..3)."""
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
        ``(rows,)`` in TDB seconds since the epoch).  All fields must have the
        same number of rows.  Everything is validated before anything is
        stored, so a rejected call (ValueError naming the field) changes
        nothing.  The data are copied; small appends are buffered in memory
        and written in blocks of the chunk size (4096 rows by default), so
        appending one row per step is fine.
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
        except BaseException:
            self.abort()
            raise
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
                self._field_attrs(g, spec)
                g.create_dataset("hi", data=arrays[0])
                g.create_dataset("lo", data=arrays[1])
            else:
                ds = h5.create_dataset(path, data=arrays[0])
                self._field_attrs(ds, spec)
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
        h5 = self._require_open("close")
        try:
            if self._static_pending:
                raise ValueError(f"close: declared static field(s) {', '.join(sorted(self._static_pending))} "
                                 "never set with set_static()")
            self._flush()
            for dsets in self._dsets.values():
                for ds in dsets:
                    if ds.shape[0] != self._rows:
                        ds.resize(self._rows, axis=0)
            h5.close()
            self._state.pop("h5", None)
            tmp = self._state["tmp"]
            _fsync_path(tmp)
            try:
                os.replace(tmp, self._path)
            except OSError as exc:
                raise OutputError(f"cannot move finished trajectory into place at {str(self._path)!r}: "
                                  f"{exc.strerror or exc}") from None
            self._state.pop("tmp", None)
            _fsync_path(self._path.parent, directory=True)
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
        h5.flush()
        _fsync_path(self._state["tmp"])
        return self._state["tmp"]

    def keep_partial(self) -> str | None:
        """Close the temporary file WITHOUT deleting it (a run interrupted
        after a checkpoint keeps its partial trajectory for ``--resume``);
        :attr:`path` is untouched.  Returns the partial file's path."""
        if self._status != "open":
            return None
        tmp = self._state.get("tmp")
        h5 = self._state.pop("h5", None)
        if h5 is not None:
            try:
                h5.close()
            except Exception:  # pragma: no cover - best effort
                pass
        self._state.pop("tmp", None)
        self._finalizer.detach()
        self._status = "aborted"
        return tmp

    @classmethod
    def reopen(cls, partial, path, rows: int) -> "TrajectoryWriter":
        """Continue a partial trajectory written by an interrupted run: the
        temporary file ``partial`` is truncated to its first ``rows`` time
        rows (those covered by the checkpoint) and appended to; close()
        renames it to ``path`` as usual."""
        self = cls.__new__(cls)
        self._path = check_writable(path)
        if not os.path.isfile(partial):
            raise OutputError(f"partial trajectory {str(partial)!r} of the checkpoint is missing; cannot resume")
        self._state = {"tmp": str(partial)}
        self._finalizer = weakref.finalize(self, _cleanup, self._state)
        try:
            h5 = h5py.File(partial, "r+")
        except OSError as exc:
            self._finalizer.detach()
            raise OutputError(f"cannot reopen partial trajectory {str(partial)!r}: {exc}") from None
        self._state["h5"] = h5
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
        self._status = "open"
        return self

    def abort(self) -> None:
        """Discard everything: close and delete the temporary file; :attr:`path` is untouched."""
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
        if self._status == "open":
            self.close()
        return False

    def __repr__(self) -> str:
        return (f"TrajectoryWriter({str(self._path)!r}, n_sat={self._n_sat}, "
                f"rows_written={self._rows}, status={self._status!r})")


# ---------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------


def _native_attr(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.generic):
        return value.item()
    return value


class Trajectory:
    """A trajectory file read fully into memory (numpy arrays, file closed).

    Create with :func:`read_trajectory`.  Arrays are float64 and read-only,
    shaped ``(N, *trailing)`` for time-dependent fields (``N`` time rows) and
    ``trailing`` for static ones; units, frames and trailing shapes are those of
    :data:`FIELDS` (SI; GCRS / S / OA_l; times in TDB seconds since
    ``attrs["epoch_utc"]``).

    Attributes
    ----------
    path : pathlib.Path
        File that was read.
    attrs : dict
        Root attributes as native Python str / int / float.
    format_version : int
        Format version of the file (<= :data:`FORMAT_VERSION`).
    scenario_toml : str
        The resolved scenario as TOML text (``""`` if the file has none).
    """

    def __init__(self, path: pathlib.Path, attrs: dict, data: dict[str, tuple[np.ndarray, ...]],
                 n_sat: int):
        self.path = pathlib.Path(path)
        self.attrs = attrs
        self.format_version = int(attrs["format_version"])
        self.scenario_toml = str(attrs.get("scenario", ""))
        self._data = data
        self._n_sat = n_sat

    @property
    def fields(self) -> tuple[str, ...]:
        """Fields present in the file, in canonical :data:`FIELDS` order."""
        return tuple(f for f in FIELDS if f in self._data)

    @property
    def n_sat(self) -> int:
        """Length of the satellite axis (1..3; 0 if the file has no satellite field)."""
        return self._n_sat

    @property
    def n_rows(self) -> int:
        """Number of time rows N (0 if the file has no time field)."""
        return self._data["t"][0].shape[0] if "t" in self._data else 0

    def __len__(self) -> int:
        return self.n_rows

    def __contains__(self, path) -> bool:
        return path in self._data

    def _get(self, path: str) -> tuple[np.ndarray, ...]:
        try:
            return self._data[path]
        except KeyError:
            if path in FIELDS:
                msg = f"{str(self.path)!r} has no field {path!r}; it has: {', '.join(self.fields)}"
            else:
                msg = f"unknown field {path!r}; fields of {str(self.path)!r}: {', '.join(self.fields)}"
            raise KeyError(msg) from None

    def __getitem__(self, path: str) -> np.ndarray:
        """Field ``path`` as a float64 array.

        f8 fields are returned as stored.  dd fields are returned as the
        float64 sum ``hi + lo`` -- a convenience that LOSES the extra precision
        of ``lo`` (only ~16 significant digits remain); use :meth:`dd` for the
        exact pair.
        """
        arrays = self._get(path)
        if len(arrays) == 1:
            return arrays[0]
        return arrays[0] + arrays[1]

    def dd(self, path: str) -> tuple[np.ndarray, np.ndarray]:
        """Exact double-double pair ``(hi, lo)`` of dd field ``path`` (value = hi + lo)."""
        arrays = self._get(path)
        if len(arrays) != 2:
            raise ValueError(f"field {path!r} is stored as float64, not double-double; use traj[{path!r}]")
        return arrays[0], arrays[1]

    def to_xarray(self):
        """The trajectory as an ``xarray.Dataset``.

        Dimensions ``time`` (coordinate: float64 TDB seconds since epoch,
        hi + lo), ``sat`` (1..n_sat), ``tm`` (1, 2), ``comp`` ("x", "y", "z"),
        ``row`` ("X_S", "Y_S", "Z_S") and ``col`` ("x", "y", "z") for
        ``sat_T_S_I``.  Variables are named by path with "/" -> "_" (e.g.
        ``sat_r``); a dd field gives the float64 ``hi + lo`` in ``<name>`` and
        the exact residual in ``<name>_lo`` (``<name> + <name>_lo`` == hi + lo
        exactly); the time field gives the ``time`` coordinate and ``t_lo``.
        Variable attrs: ``units``, ``frame``, ``description``; dataset attrs:
        the root attributes.
        """
        import xarray as xr

        coords: dict[str, Any] = {}
        variables: dict[str, Any] = {}
        if "t" in self._data:
            t, t_lo = np_two_sum(*self._data["t"])
            spec = FIELDS["t"]
            coords["time"] = ("time", t, {"units": "s", "frame": spec.frame,
                                          "description": spec.description + " (float64 hi + lo)"})
            variables["t_lo"] = ("time", t_lo, {"units": "s", "frame": spec.frame,
                                                "description": "residual of time: exact t = time + t_lo"})
        if self._n_sat:
            coords["sat"] = ("sat", np.arange(1, self._n_sat + 1))
        for f in self.fields:
            if f == "t":
                continue
            spec = FIELDS[f]
            dims = (("time",) if spec.time_dependent else ()) + spec.dims
            name = f.replace("/", "_")
            attrs = {"units": spec.unit, "frame": spec.frame, "description": spec.description}
            arrays = self._data[f]
            if len(arrays) == 2:
                val, res = np_two_sum(*arrays)
                variables[name] = (dims, val, dict(attrs, description=attrs["description"] + " (float64 hi + lo)"))
                variables[name + "_lo"] = (dims, res, dict(
                    attrs, description=f"residual of {name}: exact value = {name} + {name}_lo"))
            else:
                variables[name] = (dims, arrays[0], attrs)
            for d in spec.dims:
                if d in _COORDS and d not in coords:
                    coords[d] = (d, np.array(_COORDS[d]))
        return xr.Dataset(variables, coords=coords, attrs=dict(self.attrs))

    def __repr__(self) -> str:
        return (f"Trajectory({str(self.path)!r}, n_rows={self.n_rows}, n_sat={self._n_sat}, "
                f"fields={self.fields})")


def _read_array(obj, path: str, fname: str) -> np.ndarray:
    if not isinstance(obj, h5py.Dataset):
        raise TrajectoryFormatError(f"{fname}: {path!r} is not a dataset")
    if obj.dtype != np.float64:
        raise TrajectoryFormatError(f"{fname}: {path!r} has dtype {obj.dtype}, expected float64")
    arr = np.ascontiguousarray(obj[()], dtype=np.float64)
    arr.setflags(write=False)
    return arr


def read_trajectory(path) -> Trajectory:
    """Read a tqdyn trajectory file completely into memory and close it.

    Accepts ``format == "tqdyn-trajectory"`` with ``format_version`` <=
    :data:`FORMAT_VERSION`; anything else raises :class:`TrajectoryFormatError`
    naming the file, the value found and what is supported.  Shapes are checked
    against :data:`FIELDS` (all time-dependent fields share N rows with ``t``;
    one n_sat throughout).  HDF5 objects that are not fields of the format are
    ignored.  Returns a :class:`Trajectory` (float64 arrays, SI units, TDB).
    """
    p = pathlib.Path(os.path.abspath(os.path.expanduser(os.fspath(path))))
    fname = str(p)
    if not p.is_file():
        raise FileNotFoundError(f"trajectory file {fname!r} does not exist or is not a file")
    try:
        h5 = h5py.File(p, "r")
    except OSError as exc:
        raise TrajectoryFormatError(f"{fname}: not a readable HDF5 file ({exc})") from None
    with h5:
        attrs = {k: _native_attr(v) for k, v in h5.attrs.items()}
        fmt = attrs.get("format")
        ver = attrs.get("format_version")
        if fmt != FORMAT:
            raise TrajectoryFormatError(
                f"{fname}: format = {fmt!r} (format_version = {ver!r}); expected format "
                f"{FORMAT!r} with format_version <= {FORMAT_VERSION}")
        if isinstance(ver, bool) or not isinstance(ver, int) or ver < 1:
            raise TrajectoryFormatError(
                f"{fname}: format = {fmt!r} with invalid format_version = {ver!r}; expected an "
                f"int 1..{FORMAT_VERSION}")
        if ver > FORMAT_VERSION:
            raise TrajectoryFormatError(
                f"{fname}: format = {fmt!r} format_version = {ver} is newer than this tqdyn "
                f"({_TQDYN_VERSION}) supports (format_version <= {FORMAT_VERSION}); upgrade tqdyn")
        data: dict[str, tuple[np.ndarray, ...]] = {}
        for f, spec in FIELDS.items():
            if f not in h5:
                continue
            obj = h5[f]
            if spec.kind == "dd":
                if not isinstance(obj, h5py.Group) or "hi" not in obj or "lo" not in obj:
                    raise TrajectoryFormatError(f"{fname}: {f!r} must be a group with datasets 'hi' and 'lo'")
                hi = _read_array(obj["hi"], f + "/hi", fname)
                lo = _read_array(obj["lo"], f + "/lo", fname)
                if hi.shape != lo.shape:
                    raise TrajectoryFormatError(f"{fname}: {f!r} hi shape {_fmt_shape(hi.shape)} != "
                                                f"lo shape {_fmt_shape(lo.shape)}")
                data[f] = (hi, lo)
            else:
                data[f] = (_read_array(obj, f, fname),)
    n_rows = data["t"][0].shape[0] if "t" in data else None
    n_sat = 0
    for f, arrays in data.items():
        spec = FIELDS[f]
        shape = arrays[0].shape
        lead = 1 if spec.time_dependent else 0
        if len(shape) != lead + len(spec.shape):
            raise TrajectoryFormatError(f"{fname}: {f!r} has shape {_fmt_shape(shape)}, expected "
                                        f"{_symbolic(spec) if lead else _fmt_shape(spec.shape)}")
        if spec.time_dependent:
            if n_rows is None:
                raise TrajectoryFormatError(f"{fname}: has time-dependent field {f!r} but no time field 't'")
            if shape[0] != n_rows:
                raise TrajectoryFormatError(f"{fname}: {f!r} has {shape[0]} rows but 't' has {n_rows}")
        if "sat" in spec.shape:
            ns = shape[lead + spec.shape.index("sat")]
            if not 1 <= ns <= 3 or (n_sat and ns != n_sat):
                raise TrajectoryFormatError(f"{fname}: {f!r} has satellite axis length {ns}, expected "
                                            f"{n_sat if n_sat else '1..3'}")
            n_sat = ns
        expected = shape[:lead] + spec.resolved_shape(n_sat)
        if shape != expected:
            raise TrajectoryFormatError(f"{fname}: {f!r} has shape {_fmt_shape(shape)}, expected "
                                        f"{_fmt_shape(expected)}")
    return Trajectory(p, attrs, data, n_sat)
