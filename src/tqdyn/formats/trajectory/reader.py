"""Reading trajectory files: :func:`read_trajectory` and :class:`Trajectory` (with ``to_xarray``)."""

from __future__ import annotations

import os
import pathlib
from typing import Any, Mapping

import h5py
import numpy as np

from ... import __version__ as _TQDYN_VERSION
from ...numerics.dd import np_two_sum
from ...astro.reference import GEOCENTRIC, GEOCENTRIC_V1, REFERENCE_SYSTEMS, ReferenceSystem
from .schema import (field_frame, _COORDS, FIELDS, FORMAT, FORMAT_VERSION, TrajectoryFormatError, _check_attrs, _fmt_shape, _spec,
                     _symbolic, row_fields)

__all__ = ["Trajectory", "read_trajectory"]

# ---------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------


def _frozen(a) -> np.ndarray:
    """A read-only float64 copy (the arrays of a :class:`Trajectory` are read-only)."""
    out = np.array(a, dtype=np.float64)
    out.setflags(write=False)
    return out


def _native_attr(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.generic):
        return value.item()
    return value


class Trajectory:
    """A trajectory file read fully into memory (numpy arrays, file closed).

    Create with :func:`read_trajectory` (or in memory with :meth:`from_rows`).  Arrays are float64 and read-only,
    shaped ``(N, *trailing)`` for time-dependent fields (``N`` time rows) and
    ``trailing`` for static ones; units, frames and trailing shapes are those of
    :data:`FIELDS` (SI; GCRS / S / OA_l; times in TT seconds since
    ``attrs["epoch_utc"]``).

    Attributes
    ----------
    path : pathlib.Path or None
        File that was read (None for an in-memory trajectory, :meth:`from_rows`).
    attrs : dict
        Root attributes as native Python str / int / float.
    format_version : int
        Format version of the file (<= :data:`FORMAT_VERSION`).
    scenario_toml : str
        The resolved scenario as TOML text (``""`` if the file has none).
    """

    def __init__(self, path: pathlib.Path | None, attrs: dict, data: dict[str, tuple[np.ndarray, ...]],
                 n_sat: int):
        self.path = None if path is None else pathlib.Path(path)
        self.attrs = attrs
        self.format_version = int(attrs["format_version"])
        self.scenario_toml = str(attrs.get("scenario", ""))
        self._data = data
        self._n_sat = n_sat

    @classmethod
    def from_rows(cls, rows, attrs: Mapping[str, Any], static: Mapping[str, np.ndarray] | None = None) -> "Trajectory":
        """An in-memory trajectory (no file, :attr:`path` None) of a propagation's
        output rows (:class:`tqdyn.dynamics.Rows`, all rows in one block) with
        the root attributes a file of it would have (validated as the writer
        validates them) and its static fields (e.g. ``tm/self_gravity``)."""
        data = {}
        for path, value in row_fields(rows).items():
            arrays = value if isinstance(value, tuple) else (value,)
            data[path] = tuple(_frozen(a) for a in arrays)
        for path, value in (static or {}).items():
            _spec(path, "static")
            data[path] = (_frozen(value),)
        return cls(None, _check_attrs(attrs), data, int(np.shape(rows.sat_r[0])[1]))

    @property
    def _where(self) -> str:
        return "the in-memory trajectory" if self.path is None else repr(str(self.path))

    @property
    def reference(self) -> ReferenceSystem:
        """Origin, frame and time scale of the file's vectors and times
        (root attributes ``origin``, ``frame``, ``time_scale``).  Files of
        format version 1 (tqdyn 0.1) are geocentric with t TT-elapsed seconds
        labelled TDB: :data:`tqdyn.astro.reference.GEOCENTRIC_V1`, whose
        description says so."""
        key = (self.attrs.get("origin", GEOCENTRIC.origin), self.attrs.get("frame", GEOCENTRIC.frame),
               self.attrs.get("time_scale", GEOCENTRIC.time_scale))
        if self.format_version == 1:
            return GEOCENTRIC_V1
        for r in REFERENCE_SYSTEMS:
            if (r.origin, r.frame, r.time_scale) == key:
                return r
        return ReferenceSystem(*key, description="as recorded in the file")

    @property
    def epoch(self):
        """The epoch of t = 0 as a :class:`tqdyn.astro.timescales.Epoch`:
        from the root attribute ``epoch_tdb`` when present (exact), else
        from ``epoch_utc``."""
        from ...astro.timescales import Epoch

        tdb = self.attrs.get("epoch_tdb")
        return Epoch.from_tdb(str(tdb)) if tdb else Epoch.from_utc(str(self.attrs["epoch_utc"]))

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
                msg = f"{self._where} has no field {path!r}; it has: {', '.join(self.fields)}"
            else:
                msg = f"unknown field {path!r}; fields of {self._where}: {', '.join(self.fields)}"
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

        Dimensions ``time`` (coordinate: float64 TT seconds since epoch,
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
            coords["time"] = ("time", t, {"units": "s", "frame": self.reference.time_scale,
                                          "description": spec.description + " (float64 hi + lo)"})
            variables["t_lo"] = ("time", t_lo, {"units": "s", "frame": self.reference.time_scale,
                                                "description": "residual of time: exact t = time + t_lo"})
        if self._n_sat:
            coords["sat"] = ("sat", np.arange(1, self._n_sat + 1))
        for f in self.fields:
            if f == "t":
                continue
            spec = FIELDS[f]
            dims = (("time",) if spec.time_dependent else ()) + spec.dims
            name = f.replace("/", "_")
            attrs = {"units": spec.unit, "frame": field_frame(spec, self.reference.time_scale, self.reference.frame),
                     "description": spec.description}
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
        return (f"Trajectory({self._where}, n_rows={self.n_rows}, n_sat={self._n_sat}, "
                f"fields={self.fields})")


def _read_array(obj, path: str, fname: str) -> np.ndarray:
    if not isinstance(obj, h5py.Dataset):
        raise TrajectoryFormatError(f"{fname}: {path!r} is not a dataset")
    if obj.dtype != np.float64:
        raise TrajectoryFormatError(f"{fname}: {path!r} has dtype {obj.dtype}, expected float64")
    try:
        raw = obj[()]
    except (OSError, RuntimeError) as exc:  # Fletcher-32 mismatch, damaged chunk index, I/O error
        text = " ".join(str(exc).split())
        low = text.lower()
        if "checksum" in low or "fletcher" in low or ("filter" in low and obj.fletcher32):
            what = "fails its Fletcher-32 checksum: the file is corrupted"
        else:
            what = f"cannot be read, the file is damaged ({text[:160]})"
        raise TrajectoryFormatError(f"{fname}: dataset {path!r} {what}; re-create it (run again)") from None
    arr = np.ascontiguousarray(raw, dtype=np.float64)
    arr.setflags(write=False)
    return arr


def read_trajectory(path) -> Trajectory:
    """Read a tqdyn trajectory file completely into memory and close it.

    Accepts ``format == "tqdyn-trajectory"`` with ``format_version`` <=
    :data:`FORMAT_VERSION`; anything else raises :class:`TrajectoryFormatError`
    naming the file, the value found and what is supported.  Shapes are checked
    against :data:`FIELDS` (all time-dependent fields share N rows with ``t``;
    one n_sat throughout).  HDF5 objects that are not fields of the format are
    ignored.  Returns a :class:`Trajectory` (float64 arrays, SI units, the file's time scale).
    """
    p = pathlib.Path(os.path.abspath(os.path.expanduser(os.fspath(path))))
    fname = str(p)
    if not p.is_file():
        raise FileNotFoundError(f"trajectory file {fname!r} does not exist or is not a file")
    try:
        h5 = h5py.File(p, "r")
    except OSError as exc:
        raise TrajectoryFormatError(f"{fname}: not a readable HDF5 file ({exc})") from None
    try:
        return _read_open(h5, p, fname)
    except (OSError, RuntimeError, KeyError) as exc:  # damaged object headers / B-trees
        raise TrajectoryFormatError(f"{fname}: the file is damaged ({' '.join(str(exc).split())[:160]}); "
                                    f"re-create it (run again)") from None


def _read_open(h5, p, fname) -> Trajectory:
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
