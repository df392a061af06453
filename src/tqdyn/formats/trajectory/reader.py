"""Reading trajectory files: :func:`read_trajectory` and :class:`Trajectory` (with ``to_xarray``)."""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass
from typing import Any, Mapping

import h5py
import numpy as np

from ..._choices import allowed, did_you_mean
from ..._version import __version__ as _TQDYN_VERSION
from ...numerics.dd import np_two_sum
from ...astro.reference import GEOCENTRIC, GEOCENTRIC_V1, REFERENCE_SYSTEMS, ReferenceSystem
from .schema import (_COORDS, FIELDS, FORMAT, FORMAT_VERSION, TrajectoryFormatError, _check_attrs, _fmt_shape, _spec,
                     _symbolic, dataset_attrs, parse_vectors, row_fields)

__all__ = ["DAMAGED", "SpacecraftRecord", "Trajectory", "damaged_message", "is_trajectory_file", "native_attr",
           "open_for_reading", "read_dataset", "text_array",
           "read_attributes", "read_trajectory", "run_is_complete"]


@dataclass(frozen=True)
class SpacecraftRecord:
    """The spacecraft of a coupled trajectory (:attr:`Trajectory.spacecraft`),
    the same for the three satellites.

    architecture : str
        ``"tianqin"``, ``"lisa"`` or ``"taiji"`` (root attribute ``spacecraft_architecture``).
    dragfree_scheme : str
        ``"tianqin"`` or ``"lisa"`` (root attribute ``dragfree_scheme``).
    housing_centers : ndarray (2, 3)
        EH centres r_0,l of TM 1, TM 2 at ``theta_nominal``, m, in the body
        frame S (origin the satellite's centre of mass).
    pivots : ndarray (2, 3)
        MOSA pivots (fixed in S), m, in S.
    sensitive_axes : ndarray (2, 3)
        Unit sensitive axis of TM l in its frame OA_l (row l - 1).
    theta_nominal : float
        Nominal MOSA opening angle, rad.
    recorded : bool
        True when the file records these values (root attributes of
        :data:`~tqdyn.formats.trajectory.schema.SPACECRAFT_ATTRS`); False for a
        coupled file written before them (format version 1, or 2 before the
        spacecraft architecture became configuration): then every such run
        used the TianQin architecture and scheme, and the values are its
        defaults -- the line layout of the file's scenario (``[spacecraft]
        d_tm``, ``d_p``, ``tm_axis``; 0.40 m, 0 m, ``"y"`` when absent),
        sensitive axes X_OA_l, theta_nominal pi/3.
    """

    architecture: str
    dragfree_scheme: str
    housing_centers: np.ndarray
    pivots: np.ndarray
    sensitive_axes: np.ndarray
    theta_nominal: float
    recorded: bool


def _from_scenario_text(scenario_toml: str) -> SpacecraftRecord:
    """The spacecraft of a coupled file without spacecraft attributes
    (:class:`SpacecraftRecord`, ``recorded`` False), from the ``[spacecraft]``
    table of its scenario text (TOML): ``architecture`` (default
    ``"tianqin"``), ``dragfree`` (default the architecture's: ``"tianqin"``
    for tianqin, else ``"lisa"``), the line layout of tianqin (TM_1 at
    +d_tm/2, TM_2 at -d_tm/2 along ``tm_axis`` of S, pivots d_p behind the EH
    centres along the nominal X_OA_l; 0.40 m, 0 m, "y" by default) or the
    optical-axis layout of lisa / taiji (EH centres ``tm_distance``, default
    0.30 m, along the nominal X_OA_l, pivots at the CoM), ``housing_centers``
    / ``pivots`` / ``sensitive_axes`` where given, theta_nominal pi/3.  The
    scenario text of a file written before the architectures were
    configurable names none of these keys: the TianQin defaults."""
    import math
    import tomllib

    try:
        sc = tomllib.loads(scenario_toml).get("spacecraft", {})
        if not isinstance(sc, dict):
            sc = {}
    except (tomllib.TOMLDecodeError, TypeError):
        sc = {}
    theta = math.pi / 3
    h = 0.5 * theta
    u = np.array([[math.cos(h), math.sin(h), 0.0], [math.cos(h), -math.sin(h), 0.0]])
    arch = str(sc.get("architecture", "tianqin"))
    scheme = str(sc.get("dragfree", "tianqin" if arch == "tianqin" else "lisa"))
    try:
        if arch == "tianqin":
            d_tm, d_p = float(sc.get("d_tm", 0.40)), float(sc.get("d_p", 0.0))
            e = np.zeros(3)
            e[{"x": 0, "y": 1, "z": 2}.get(str(sc.get("tm_axis", "y")), 1)] = 1.0
            r0 = np.array([0.5 * d_tm * e, -0.5 * d_tm * e])
            piv = r0 - d_p * u
        else:
            r0 = float(sc.get("tm_distance", 0.30)) * u
            piv = np.zeros((2, 3))
        if "housing_centers" in sc or "pivots" in sc:
            r0 = np.array(sc.get("housing_centers", r0), dtype=np.float64)
            piv = np.array(sc.get("pivots", r0), dtype=np.float64)
        sens = np.array(sc.get("sensitive_axes", [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), dtype=np.float64)
        sens = sens / np.linalg.norm(sens, axis=-1, keepdims=True)
        if r0.shape != (2, 3) or piv.shape != (2, 3) or sens.shape != (2, 3):
            raise ValueError("not (2, 3)")
    except (TypeError, ValueError):  # a damaged scenario text: the TianQin defaults
        return _from_scenario_text("")
    # + 0.0: no negative zeros
    return SpacecraftRecord(arch, scheme, _frozen(r0 + 0.0), _frozen(piv + 0.0), _frozen(sens + 0.0), theta, False)


def _frozen(a) -> np.ndarray:
    """A read-only float64 copy (the arrays of a :class:`Trajectory` are read-only)."""
    out = np.array(a, dtype=np.float64)
    out.setflags(write=False)
    return out


def native_attr(value):
    """An HDF5 attribute value as a Python value: bytes decoded as UTF-8, numpy scalars as Python scalars."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.generic):
        return value.item()
    return value


def text_array(a) -> np.ndarray:
    """A string array as fixed-length UTF-8 bytes (HDF5 filters need fixed-size elements); same shape."""
    enc = [str(x).encode("utf-8") for x in np.asarray(a, dtype=object).ravel()]
    width = max([len(e) for e in enc] + [1])
    return np.array(enc, dtype=f"S{width}").reshape(np.shape(a))


def read_dataset(ds, fname: str, error: type, remedy: str, sel=()):
    """The values of the HDF5 dataset ``ds`` (``sel`` a selection, or all) of file ``fname``; text
    datasets (attribute ``kind = "text"``) decoded to str.  A dataset that fails its Fletcher-32 checksum
    or cannot be read raises ``error`` (one line naming the file, the dataset and ``remedy``, the command
    that re-creates it)."""
    try:
        raw = ds[sel] if sel != () else ds[()]
    except OSError as exc:
        low = str(exc).lower()
        what = ("fails its Fletcher-32 checksum: the file is corrupted" if ("checksum" in low or "fletcher" in low
                or "filter" in low) else "cannot be read, the file is damaged")
        raise error(f"{fname}: dataset {ds.name!r} {what}; re-create it ({remedy})") from None
    if ds.attrs.get("kind") == "text":
        return np.char.decode(np.asarray(raw), "utf-8")
    return raw


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
    def spacecraft(self) -> SpacecraftRecord | None:
        """The spacecraft architecture and drag-free scheme of a coupled run
        (root attribute ``pointing`` != ``"none"``): a
        :class:`SpacecraftRecord` from the root attributes
        ``spacecraft_architecture``, ``dragfree_scheme``,
        ``spacecraft_housing_centers``, ``spacecraft_pivots``,
        ``spacecraft_sensitive_axes``, ``spacecraft_theta_nominal``; for a
        coupled file written before them (``recorded`` False) what its
        scenario text says, the TianQin defaults when it says nothing
        (format version 1 and early version-2 files).  None for point-mass runs (no attitude, no test masses)."""
        import math

        a = self.attrs
        if a.get("pointing", "none") == "none":
            return None
        if "spacecraft_architecture" not in a:
            return _from_scenario_text(self.scenario_toml)
        vec = {k: _frozen(parse_vectors(a[f"spacecraft_{k}"], f"spacecraft_{k}"))
               for k in ("housing_centers", "pivots", "sensitive_axes")}
        return SpacecraftRecord(str(a["spacecraft_architecture"]), str(a.get("dragfree_scheme", "tianqin")),
                                theta_nominal=float(a.get("spacecraft_theta_nominal", math.pi / 3)), recorded=True,
                                **vec)

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
        """Length of the satellite axis (>= 1; 0 if the file has no satellite field)."""
        return self._n_sat

    @property
    def satellite_names(self) -> tuple[str, ...]:
        """The satellites' names in satellite-axis order: the ``name`` of each
        ``[[satellites]]`` table of the file's resolved scenario (root attribute
        ``scenario``), or ``Sat1``, ``Sat2``, ... when the scenario does not
        name exactly :attr:`n_sat` satellites (no scenario, or a damaged one)."""
        import tomllib

        try:
            sats = tomllib.loads(self.scenario_toml).get("satellites", [])
            names = tuple(str(s["name"]) for s in sats)
        except (tomllib.TOMLDecodeError, AttributeError, TypeError, KeyError):
            names = ()
        return names if len(names) == self._n_sat else tuple(f"Sat{k}" for k in range(1, self._n_sat + 1))

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
                msg = f"{self._where} has no field {path!r}; it has: {allowed(self.fields, noun='fields')}"
            else:
                msg = (f"unknown field {path!r}{did_you_mean(path, self.fields)}; fields of {self._where}: "
                       f"{allowed(self.fields, noun='fields')}")
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
        hi + lo), ``sat`` (1..n_sat; the non-index coordinate ``sat_name``
        along it holds :attr:`satellite_names`), ``tm`` (1, 2), ``comp`` ("x", "y", "z"),
        ``row`` ("X_S", "Y_S", "Z_S") and ``col`` ("x", "y", "z") for
        ``sat_T_S_I``.  Variables are named by path with "/" -> "_" (e.g.
        ``sat_r``); a dd field gives the float64 ``hi + lo`` in ``<name>`` and
        the exact residual in ``<name>_lo`` (``<name> + <name>_lo`` == hi + lo
        exactly); the time field gives the ``time`` coordinate and ``t_lo``.
        Variable attrs: ``units``, ``frame``, ``description``, and as in the
        file ``components`` (what x, y, z are) for vectors and, for a coupled
        run that records its spacecraft, ``dragfree_scheme`` /
        ``sensitive_axes`` on the actuation fields
        (:func:`~tqdyn.formats.trajectory.schema.dataset_attrs`); dataset
        attrs: the root attributes.
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
            coords["sat_name"] = ("sat", np.array(self.satellite_names, dtype=str),
                                  {"description": "satellite name (the scenario's [[satellites]] name)"})
        for f in self.fields:
            if f == "t":
                continue
            spec = FIELDS[f]
            dims = (("time",) if spec.time_dependent else ()) + spec.dims
            name = f.replace("/", "_")
            attrs = dataset_attrs(f, {**self.attrs, "time_scale": self.reference.time_scale,
                                      "frame": self.reference.frame})
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


#: What h5py raises on a damaged file (object headers, B-trees, checksums).
DAMAGED = (OSError, RuntimeError, KeyError)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:160]


def open_for_reading(path, noun: str, error: type) -> tuple[pathlib.Path, str, "h5py.File"]:
    """(absolute path, its name, the open HDF5 file) of ``path`` for reading; FileNotFoundError
    ("``noun`` '...' does not exist or is not a file") for a missing file, ``error`` (one line
    naming the file) for one that HDF5 cannot open."""
    p = pathlib.Path(os.path.abspath(os.path.expanduser(os.fspath(path))))
    fname = str(p)
    if not p.is_file():
        raise FileNotFoundError(f"{noun} {fname!r} does not exist or is not a file")
    try:
        return p, fname, h5py.File(p, "r")
    except OSError as exc:
        raise error(f"{fname}: not a readable HDF5 file ({_one_line(exc)})") from None


def damaged_message(fname: str, exc: BaseException, remedy: str) -> str:
    """The one-line message of a file whose HDF5 structures fail to read (``exc``, one of
    :data:`DAMAGED`); ``remedy`` names the command that re-creates it."""
    return f"{fname}: the file is damaged ({_one_line(exc)}); re-create it ({remedy})"


def read_trajectory(path) -> Trajectory:
    """Read a tqdyn trajectory file completely into memory and close it.

    Accepts ``format == "tqdyn-trajectory"`` with ``format_version`` <=
    :data:`FORMAT_VERSION`; anything else raises :class:`TrajectoryFormatError`
    naming the file, the value found and what is supported.  Shapes are checked
    against :data:`FIELDS` (all time-dependent fields share N rows with ``t``;
    one n_sat throughout).  HDF5 objects that are not fields of the format are
    ignored.  Returns a :class:`Trajectory` (float64 arrays, SI units, the file's time scale).
    """
    p, fname, h5 = open_for_reading(path, "trajectory file", TrajectoryFormatError)
    try:
        return _read_open(h5, p, fname)
    except DAMAGED as exc:  # damaged object headers / B-trees
        raise TrajectoryFormatError(damaged_message(fname, exc, "run again")) from None


_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def is_trajectory_file(path) -> bool:
    """True when ``path`` is an existing file that starts with the HDF5 signature
    (a trajectory file, or another HDF5 file that :func:`read_attributes` refuses)."""
    try:
        with open(os.fspath(path), "rb") as fh:
            return fh.read(8) == _HDF5_SIGNATURE
    except (OSError, TypeError, ValueError):
        return False


def read_attributes(path) -> dict:
    """The root attributes of a trajectory file (native str / int / float),
    without reading its datasets; the same format and version checks as
    :func:`read_trajectory` (FileNotFoundError, or a one-line
    :class:`TrajectoryFormatError` naming the file)."""
    _, fname, h5 = open_for_reading(path, "trajectory file", TrajectoryFormatError)
    try:
        with h5:
            return _checked_attrs(h5, fname)
    except DAMAGED as exc:
        raise TrajectoryFormatError(damaged_message(fname, exc, "run again")) from None


def _checked_attrs(h5, fname) -> dict:
    """The root attributes of an open file, after the format and version checks."""
    attrs = {k: native_attr(v) for k, v in h5.attrs.items()}
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
    return attrs


def _read_open(h5, p, fname) -> Trajectory:
    with h5:
        attrs = _checked_attrs(h5, fname)
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
            if ns < 1 or (n_sat and ns != n_sat):
                raise TrajectoryFormatError(f"{fname}: {f!r} has satellite axis length {ns}, expected "
                                            f"{n_sat if n_sat else '>= 1'}")
            n_sat = ns
        expected = shape[:lead] + spec.resolved_shape(n_sat)
        if shape != expected:
            raise TrajectoryFormatError(f"{fname}: {f!r} has shape {_fmt_shape(shape)}, expected "
                                        f"{_fmt_shape(expected)}")
    return Trajectory(p, attrs, data, n_sat)


def run_is_complete(path, canonical_toml: str, output_placeholder: str) -> bool:
    """True if ``path`` is a complete run of the scenario ``canonical_toml``.

    Complete means: a readable tqdyn trajectory whose stored resolved
    scenario, with ``run.output`` set to ``output_placeholder``, is
    ``canonical_toml`` (which must have been resolved with the same
    placeholder, so that a moved output folder still counts), and whose last
    time row is ``run.duration`` (within 1e-6 of the step [s], at least 1e-6 s).
    Anything else -- missing, unreadable, another scenario, cut short -- is
    False: the caller runs it (again).  Used by the studies and the sweeps.
    """
    from ...scenario import ScenarioError, loads_scenario

    try:
        with h5py.File(path, "r") as h5:
            if h5.attrs.get("format") != FORMAT:
                return False
            stored = h5.attrs.get("scenario", "")
            stored = stored.decode("utf-8") if isinstance(stored, bytes) else str(stored)
            t_hi, t_lo = h5["t/hi"], h5["t/lo"]
            n = t_hi.shape[0]
            if n == 0:
                return False
            t_end = float(t_hi[n - 1]) + float(t_lo[n - 1])
    except (OSError, KeyError, ValueError, TypeError):
        return False
    try:
        scen = loads_scenario(stored, [f"run.output={output_placeholder}"])
    except ScenarioError:
        return False
    if scen.to_toml() != canonical_toml:
        return False
    return abs(t_end - float(scen.run.duration_s)) <= 1e-6 * max(1.0, float(scen.integrator.step_s))
