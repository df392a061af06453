"""The closed-loop file: the ``tqdyn-closed-loop`` HDF5 format (I/O only; docs/closed-loop-file.md).

One file holds the closed loop of one coupled run (``tqdyn closed-loop RUN.h5 --output CL.h5``):

* root attributes: :data:`FORMAT`, :data:`FORMAT_VERSION`, the writing tqdyn, the source run's
  identity (``source_*``), the resolved closed-loop configuration (``configuration``, JSON), the
  time-domain ``seed``, ``fs`` [Hz], ``duration_s`` [s], ``n_samples``, ``t0`` [s] and the mission;
* ``/timeseries``: ``t`` (N,) [s, the run's time axis since its epoch] and one dataset per
  time-domain output, (N, n_sat) in the output's unit (attributes ``units``, ``frame``,
  ``description``), written block by block as :func:`tqdyn.closedloop.simulate.simulate` streams;
* ``/budget``: every variable and coordinate of :func:`tqdyn.analysis.closed_loop.closed_loop_budget`'s
  Dataset (frequency grid x output x source ASDs, total, requirement, margins, dominant source per
  output and band), each with its dimension names (attribute ``dims``) and units.

Every dataset is chunked and carries a Fletcher-32 checksum.  Writing is atomic:
:class:`ClosedLoopWriter` writes to a hidden temporary file beside the output and renames it into
place on :meth:`~ClosedLoopWriter.close`; a failure or an interrupt (with-block, :meth:`abort`)
removes the temporary file and leaves the output path as it was.  Strings are stored as fixed-length
UTF-8 strings (HDF5 character set UTF-8); the budget's datasets are compressed (byte shuffle + gzip).  Version 1
files (ASCII strings, ``gain_margin`` python-control's choice) are read into version 2's layout.  Units SI.
"""

from __future__ import annotations

import json
import os
import pathlib
import secrets
import weakref

import h5py
import numpy as np

from .._version import __version__ as _TQDYN_VERSION
from ..closedloop.simulate import Block, Sink
from .trajectory import OutputError, OutputIOError, check_writable
from .stop import check_stop
from .trajectory._h5safe import _cleanup, _close_h5, _io_reason, _vfd
from .trajectory.reader import DAMAGED, damaged_message, native_attr, open_for_reading, read_dataset, text_array

__all__ = ["FORMAT", "FORMAT_VERSION", "ClosedLoopFile", "ClosedLoopFormatError", "ClosedLoopWriter",
           "ROOT_ATTRS", "read_closed_loop"]

FORMAT = "tqdyn-closed-loop"
"""Value of the root attribute ``format``."""
FORMAT_VERSION = 2
"""Format version written; readers accept any version <= this (docs/closed-loop-file.md#older-versions)."""

#: Root attributes and their meaning (docs/closed-loop-file.md).
ROOT_ATTRS = {
    "format": f'str, always "{FORMAT}"',
    "format_version": f"int, {FORMAT_VERSION}",
    "tqdyn_version": "str, version of tqdyn that wrote the file",
    "mission": 'str, the mission whose defaults apply: "tianqin" | "lisa" | "taiji" | "lpf" | "tianqin-1"',
    "source_file": "str, file name (no directory) of the coupled run (trajectory file) the loops linearise; "
                   "the source_* attributes are empty (0) for a mission's static working point (--mission)",
    "source_path": "str, absolute path of that file when the closed loop was computed",
    "source_sha256": "str, SHA-256 of the trajectory file's bytes",
    "source_scenario_sha256": "str, SHA-256 of the run's resolved scenario (its root attribute scenario, UTF-8)",
    "source_format_version": "int, format_version of the trajectory file",
    "source_tqdyn_version": "str, tqdyn_version of the trajectory file",
    "source_epoch_utc": "str, epoch_utc of the run (t = 0)",
    "source_time_scale": "str, time_scale of the run's t (and of this file's t)",
    "configuration": "str, JSON: the resolved closed-loop configuration (settings, plant, controllers, noise)",
    "closed_loop_toml": "str, the [closed_loop] section as given (scenario and --set overrides; may be empty)",
    "seed": "int, root seed of the noise realisations",
    "fs": "float, Hz, sample rate of the time series",
    "duration_s": "float, s, length of the time series (n_samples / fs)",
    "n_samples": "int, number of time samples N",
    "t0": "float, s, first time (the run's first row) on the run's time axis",
    "satellite_names": "str, JSON list of the satellites' names (the sat axis)",
}

_CHUNK_ROWS = 65536          # time rows per chunk of the time series (a 3-satellite output: 1.5 MB)
_RDCC_NBYTES = 0             # blocks are whole chunks: no chunk cache (memory stays bounded)


class ClosedLoopFormatError(ValueError):
    """A file that is not a readable closed-loop file: one line naming the file and what was found."""


#: Largest chunk of a budget dataset [bytes] (the leading axes, e.g. the segments, are split first).
_BUDGET_CHUNK_BYTES = 1 << 21
#: Compression of the budget's datasets (h5py: byte shuffle, then gzip at this level).
_GZIP_LEVEL = 4


def _chunks(shape, itemsize: int = 8) -> tuple | None:
    """Chunks of at most :data:`_BUDGET_CHUNK_BYTES` (and 65,536 per axis): whole trailing axes, the leading
    ones cut first."""
    if not shape or not all(int(n) > 0 for n in shape):
        return None
    ch = [max(1, min(int(n), 65536)) for n in shape]
    for k in range(len(ch)):
        rest = itemsize * int(np.prod(ch[k + 1:], dtype=np.int64))
        if rest * ch[k] <= _BUDGET_CHUNK_BYTES:
            break
        ch[k] = max(1, _BUDGET_CHUNK_BYTES // max(1, rest))
    return tuple(ch)


def _put(group, name: str, value, dims=(), attrs=None):
    arr = np.asarray(value)
    text = arr.dtype.kind in "USO"
    if text:
        arr = text_array(arr)                      # fixed-length UTF-8 bytes, stored with the UTF-8 character set
    ch = _chunks(arr.shape, arr.dtype.itemsize)
    extra = {"compression": "gzip", "compression_opts": _GZIP_LEVEL, "shuffle": True} if ch is not None else {}
    if text:                                       # HDF5 converts no ASCII to UTF-8: the UTF-8 type in file and memory
        tid = h5py.h5t.C_S1.copy()
        tid.set_size(arr.dtype.itemsize)
        tid.set_cset(h5py.h5t.CSET_UTF8)
        ds = group.create_dataset(name, shape=arr.shape, dtype=h5py.Datatype(tid), chunks=ch,
                                  fletcher32=ch is not None, **extra)
        if arr.size:
            ds.id.write(h5py.h5s.ALL, h5py.h5s.ALL, np.ascontiguousarray(arr), mtype=tid)
    else:
        ds = group.create_dataset(name, data=arr, chunks=ch, fletcher32=ch is not None, **extra)
    ds.attrs["dims"] = ",".join(dims)
    ds.attrs["kind"] = "text" if arr.dtype.kind == "S" else "number"
    for k, v in (attrs or {}).items():
        ds.attrs[k] = v if not isinstance(v, (list, tuple, dict)) else json.dumps(v)
    return ds


class ClosedLoopWriter(Sink):
    """Write a closed-loop file (module docstring) at ``path``: a :class:`~tqdyn.closedloop.simulate.Sink`
    for the time series (``start``, ``write`` per block, ``close``) plus :meth:`write_budget`.

    path : the destination (checked with :func:`tqdyn.formats.trajectory.check_writable`; an existing
        file there is replaced only by a complete file).
    attrs : root attributes (:data:`ROOT_ATTRS`; ``format``, ``format_version`` and ``tqdyn_version``
        are filled in); str, int, float values.
    units : {output: (unit, frame, description)} of the time-domain outputs.

    Use it in a with-block: any exception (including KeyboardInterrupt) removes the temporary file.
    A write that fails (disk full) raises :class:`~tqdyn.formats.trajectory.OutputIOError` (one line).
    """

    def __init__(self, path, attrs: dict, units: dict | None = None):
        self._path = check_writable(path)
        self._units = dict(units or {})
        self._status = "open"
        self._state: dict = {}
        self._meta: dict = {}
        self._row = 0
        self._budget = False
        tmp = str(self._path.parent / f".{self._path.name}.{secrets.token_hex(6)}.tmp")
        self._state["tmp"] = tmp
        self._finalizer = weakref.finalize(self, _cleanup, self._state)
        try:
            h5 = h5py.File(tmp, "w", rdcc_nbytes=_RDCC_NBYTES)
            self._state["h5"] = h5
            self._state["fd"] = _vfd(h5)
            for k, v in {"format": FORMAT, "format_version": FORMAT_VERSION, "tqdyn_version": _TQDYN_VERSION,
                         **{k: v for k, v in attrs.items() if k not in ("format", "format_version")}}.items():
                h5.attrs[k] = v
        except BaseException as exc:
            self.abort()
            if isinstance(exc, OSError) and not isinstance(exc, OutputError):
                raise OutputError(f"cannot create the closed-loop file {str(self._path)!r}: {_io_reason(exc)}") from None
            raise

    @property
    def path(self) -> pathlib.Path:
        """The destination path (absolute)."""
        return self._path

    def _h5(self, what: str):
        if self._status != "open":
            raise ValueError(f"{what}: the closed-loop writer for {str(self._path)!r} is already {self._status}")
        return self._state["h5"]

    def _failed(self, exc) -> OutputIOError:
        self._status = "failed"
        return OutputIOError(f"cannot write the closed-loop file {str(self._path)!r}: {_io_reason(exc)}")

    def write_budget(self, ds) -> None:
        """Store the budget Dataset of :func:`tqdyn.analysis.closed_loop.closed_loop_budget` under
        ``/budget``: every data variable and coordinate (with its dims and attrs) and the Dataset's
        attributes as the group's."""
        h5 = self._h5("write_budget")
        try:
            g = h5.create_group("budget")
            for k, v in ds.attrs.items():
                g.attrs[k] = v
            g.attrs["variables"] = json.dumps([str(k) for k in ds.data_vars])
            g.attrs["coordinates"] = json.dumps([str(k) for k in ds.coords])
            for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
                _put(g, name, var.values, var.dims, dict(var.attrs, role="coord" if name in ds.coords else "data"))
        except OSError as exc:
            raise self._failed(exc) from None
        self._budget = True

    # -- the Sink interface --------------------------------------------------
    def start(self, meta: dict) -> None:
        """Create ``/timeseries`` for ``meta`` (:func:`tqdyn.closedloop.simulate.simulate`): ``outputs``,
        ``n_sat``, ``fs``, ``n_samples``, ``t0``, ``units``."""
        h5 = self._h5("start")
        self._meta = dict(meta)
        n, n_sat = int(meta["n_samples"]), int(meta["n_sat"])
        rows = max(1, min(_CHUNK_ROWS, n))
        try:
            g = h5.create_group("timeseries")
            t = g.create_dataset("t", shape=(n,), dtype=np.float64, chunks=(rows,), fletcher32=True)
            t.attrs.update({"dims": "time", "kind": "number", "units": "s",
                            "description": "time on the run's time axis (its time_scale) since its epoch"})
            self._dsets = [t]
            for o in meta["outputs"]:
                unit, frame, desc = self._units.get(o, (meta.get("units", {}).get(o, ""), "", ""))
                ds = g.create_dataset(o, shape=(n, n_sat), dtype=np.float64, chunks=(rows, n_sat), fletcher32=True)
                ds.attrs.update({"dims": "time,sat", "kind": "number", "units": unit, "frame": frame,
                                 "description": desc})
                self._dsets.append(ds)
            g.attrs["outputs"] = json.dumps(list(meta["outputs"]))
        except OSError as exc:
            raise self._failed(exc) from None

    def write(self, block: Block) -> None:
        """Store one block of rows (``block.t`` (m,), ``block.values`` (m, n_sat, n_out))."""
        self._h5("write")
        m = len(block.t)
        r0, r1 = self._row, self._row + m
        try:
            self._dsets[0][r0:r1] = block.t
            for k, ds in enumerate(self._dsets[1:]):
                ds[r0:r1] = block.values[:, :, k]
        except OSError as exc:
            raise self._failed(exc) from None
        self._row = r1

    def close(self) -> pathlib.Path:
        """Finish the file (every sample written, the budget stored) and rename it into place; returns
        the path.  ValueError (and the temporary file removed) if the file is incomplete."""
        if self._status == "closed":
            return self._path
        h5 = self._h5("close")
        try:
            check_stop()  # a stop signal that arrived: no file is renamed into place
            if not self._meta or self._row != int(self._meta["n_samples"]) or not self._budget:
                raise ValueError(f"close: the closed-loop file {str(self._path)!r} is incomplete ({self._row} of "
                                 f"{self._meta.get('n_samples', '?')} samples, budget "
                                 f"{'stored' if self._budget else 'missing'})")
            try:
                h5.flush()
            except OSError as exc:
                raise self._failed(exc) from None
            _close_h5(self._state, keep=True)
            tmp = self._state["tmp"]
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
            os.replace(tmp, self._path)
            self._state.pop("tmp", None)
        except BaseException:
            self.abort()
            raise
        self._status = "closed"
        self._finalizer.detach()
        return self._path

    def abort(self) -> None:
        """Discard the temporary file; the output path is left as it was."""
        if self._status == "closed":
            return
        _cleanup(self._state)
        self._status = "aborted"

    def __enter__(self) -> "ClosedLoopWriter":
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is not None or self._status != "closed":
            self.abort()
        return False


# ---------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------


def _values(ds, fname: str, sel=()):
    return read_dataset(ds, fname, ClosedLoopFormatError, "tqdyn closed-loop", sel)


class ClosedLoopFile:
    """An open-and-closed view of a closed-loop file (:func:`read_closed_loop`): ``attrs`` (root
    attributes, native types), ``configuration`` (the parsed JSON), ``budget`` (xarray.Dataset, as
    :func:`~tqdyn.analysis.closed_loop.closed_loop_budget` returned it) and :meth:`timeseries`."""

    def __init__(self, path: pathlib.Path, attrs: dict, budget):
        self.path = path
        self.attrs = attrs
        self.budget = budget
        self.configuration = json.loads(attrs.get("configuration", "{}") or "{}")

    def _open(self):
        try:
            return h5py.File(self.path, "r")
        except OSError as exc:
            raise ClosedLoopFormatError(f"{self.path}: not a readable HDF5 file ({exc})") from None

    def timeseries(self, outputs=None, start: int = 0, stop: int | None = None):
        """The time series as an ``xarray.Dataset`` ``values`` (time, sat, output) [output units] with
        coordinates time [s], sat, sat_name, output, unit, frame -- the layout of
        :func:`~tqdyn.analysis.closed_loop.closed_loop_timeseries`.  ``outputs``: a subset of names
        (default all); ``start``/``stop``: a row range (the file is read only there)."""
        import xarray as xr

        fname = str(self.path)
        with self._open() as h5:
            g = h5["timeseries"]
            names = json.loads(native_attr(g.attrs["outputs"]))
            if outputs is not None:
                bad = [o for o in outputs if o not in names]
                if bad:
                    raise ValueError(f"outputs: {bad[0]!r} is not a time-domain output of {fname}; allowed: "
                                     + ", ".join(names))
                names = [o for o in names if o in outputs]
            sel = slice(start, stop)
            t = _values(g["t"], fname, sel)
            vals = np.stack([_values(g[o], fname, sel) for o in names], axis=-1) if names else \
                np.zeros((len(t), 0, 0))
            units = [native_attr(g[o].attrs.get("units", "")) for o in names]
            frames = [native_attr(g[o].attrs.get("frame", "")) for o in names]
        sat_names = json.loads(self.attrs.get("satellite_names", "[]"))
        return xr.Dataset({"values": (("time", "sat", "output"), vals)},
                          coords={"time": t, "sat": np.arange(1, vals.shape[1] + 1), "sat_name": ("sat", sat_names),
                                  "output": names, "unit": ("output", units), "frame": ("output", frames)},
                          attrs={"mission": self.attrs.get("mission", ""), "fs": float(self.attrs["fs"]),
                                 "seed": int(self.attrs["seed"]),
                                 "time_unit": "s on the run's time axis since the epoch"})


def _upgrade_v1(data: dict) -> None:
    """A version-1 budget in version 2's layout: version 1's ``gain_margin`` is python-control's choice (the
    margin closest to 1 in dB, the upper one when a loop has both); ``gain_margin_lower`` and
    ``gain_margin_upper`` are what it tells (inf: no phase crossover, so none of either; NaN: not recorded) and
    ``gain_margin`` becomes the lower one."""
    import xarray as xr

    gm = data.get("gain_margin")
    if gm is None or "gain_margin_lower" in data:
        return
    v = np.asarray(gm.values, dtype=np.float64)
    lower = np.where(np.isinf(v), 0.0, np.where(v < 1, v, np.nan))
    upper = np.where(np.isinf(v), np.inf, np.where(v > 1, v, np.nan))
    attrs = dict(gm.attrs, units="1")
    data["gain_margin"] = xr.Variable(gm.dims, lower, attrs=attrs)
    data["gain_margin_lower"] = xr.Variable(gm.dims, lower, attrs=attrs)
    data["gain_margin_upper"] = xr.Variable(gm.dims, upper, attrs=attrs)


def _read_budget(h5, fname: str, version: int = FORMAT_VERSION):
    import xarray as xr

    g = h5["budget"]
    coords, data = {}, {}
    order = (json.loads(native_attr(g.attrs.get("coordinates", "[]")))
             + json.loads(native_attr(g.attrs.get("variables", "[]"))))
    for name in order + sorted(k for k in g if k not in order):
        ds = g[name]
        dims = tuple(d for d in native_attr(ds.attrs.get("dims", "")).split(",") if d)
        attrs = {k: native_attr(v) for k, v in ds.attrs.items() if k not in ("dims", "kind", "role")}
        var = xr.Variable(dims, _values(ds, fname), attrs=attrs)
        (coords if native_attr(ds.attrs.get("role")) == "coord" else data)[name] = var
    if version < 2:
        _upgrade_v1(data)
    return xr.Dataset(data, coords=coords, attrs={k: native_attr(v) for k, v in g.attrs.items()
                                                  if k not in ("variables", "coordinates")})


def read_closed_loop(path) -> ClosedLoopFile:
    """Open a closed-loop file: root attributes and budget read, time series on demand
    (:meth:`ClosedLoopFile.timeseries`).  FileNotFoundError for a missing file; a one-line
    :class:`ClosedLoopFormatError` for anything that is not a ``tqdyn-closed-loop`` file of version
    <= :data:`FORMAT_VERSION` (a trajectory file, another HDF5 file, a damaged file)."""
    p, fname, h5 = open_for_reading(path, "closed-loop file", ClosedLoopFormatError)
    try:
        with h5:
            attrs = {k: native_attr(v) for k, v in h5.attrs.items()}
            fmt, ver = attrs.get("format"), attrs.get("format_version")
            if fmt != FORMAT:
                raise ClosedLoopFormatError(
                    f"{fname}: format = {fmt!r} (format_version = {ver!r}); expected format {FORMAT!r} "
                    "(written by tqdyn closed-loop)")
            if isinstance(ver, bool) or not isinstance(ver, int) or ver < 1:
                raise ClosedLoopFormatError(f"{fname}: format = {fmt!r} with invalid format_version = {ver!r}; "
                                            f"expected an int 1..{FORMAT_VERSION}")
            if ver > FORMAT_VERSION:
                raise ClosedLoopFormatError(
                    f"{fname}: format = {fmt!r} format_version = {ver} is newer than this tqdyn ({_TQDYN_VERSION}) "
                    f"reads (format_version <= {FORMAT_VERSION}); upgrade tqdyn")
            if "budget" not in h5 or "timeseries" not in h5:
                raise ClosedLoopFormatError(f"{fname}: the group '/budget' or '/timeseries' is missing; re-create "
                                            "it (tqdyn closed-loop)")
            budget = _read_budget(h5, fname, ver)
    except DAMAGED as exc:
        raise ClosedLoopFormatError(damaged_message(fname, exc, "tqdyn closed-loop")) from None
    return ClosedLoopFile(p, attrs, budget)
