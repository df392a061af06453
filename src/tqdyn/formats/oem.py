"""CCSDS Orbit Ephemeris Message (OEM 2.0, KVN) writer (I/O only).

Writes the states of tqdyn runs as OEM files (CCSDS 502.0-B-2, "Orbit Data
Messages", section 5), readable by :func:`tqdyn.readers.oem.read_oem`, by the
PyPI package ``oem`` and by any OEM reader (Orekit, GMAT, STK, lisaorbits'
``OEMOrbits``).  tqdyn's systems (:class:`OemSegment` helpers):

* heliocentric runs: ``CENTER_NAME = SUN``, ``REF_FRAME = ICRF``,
  ``TIME_SYSTEM = TDB`` (ICRF axes, TDB-compatible coordinates);
* geocentric runs: ``CENTER_NAME = EARTH``, ``REF_FRAME = GCRF``,
  ``TIME_SYSTEM = TT`` (the GCRS, TT-compatible coordinates).

Layout: header (``CCSDS_OEM_VERS = 2.0``, ``CREATION_DATE`` UTC,
``ORIGINATOR``, comments), then per segment ``META_START`` .. ``META_STOP``
(OBJECT_NAME, OBJECT_ID, CENTER_NAME, REF_FRAME, TIME_SYSTEM, START_TIME,
STOP_TIME, INTERPOLATION, INTERPOLATION_DEGREE, in the order of the
standard's table 5-3) and one line per state: epoch
``YYYY-MM-DDThh:mm:ss.sssssssss`` (9 decimals: 1 ns, 30 um at 30 km/s),
x y z [km] vx vy vz [km/s] (and ax ay az [km/s^2] if given), each with 16
significant digits (``% .15e``; the standard's limit; < 1e-4 m at 1 au).

The ``oem`` package's own writer is not used: its epochs have 6 decimals
(1 us = 30 mm along a heliocentric orbit) and its numbers 15 significant
digits or 6 decimals of km/s (1 mm/s).  Its reader is the check that the
files written here are valid (tests/test_oem.py).

An OEM holds "orbit data for a single object" (CCSDS 502.0-B-2, 5.1.3; the
``oem`` package enforces it): several segments in one file must share
OBJECT_NAME, OBJECT_ID and TIME_SYSTEM and follow each other in time.
:func:`tqdyn.readers.oem.read_oem` reads them back as one trajectory when
each starts where the previous one stops (same centre and frame, states
agreeing there: :func:`tqdyn.astro.oem_states.require_continuous`), else
:func:`tqdyn.readers.oem.read_oem_segments` one by one.  A constellation is
written one file per satellite (:func:`write_oem_files`).

Writing is atomic: a hidden temporary file in the destination directory is
renamed into place when complete; on any error it is removed and an existing
file at the destination is left untouched.  Every input is checked (shapes,
finite values, increasing epochs, allowed names) before anything is written.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import os
import pathlib
from collections.abc import Sequence

import erfa
import numpy as np

from .._choices import allowed, did_you_mean
from .._version import __version__

from ..astro.oem_states import GEOCENTRIC, HELIOCENTRIC, INTERPOLATIONS
from ..readers.oem import REF_FRAMES, TIME_SYSTEMS
from . import trajectory as _io
from .atomic import replacing

__all__ = ["OEM_VERSION", "OemSegment", "write_oem", "write_oem_files"]

OEM_VERSION = "2.0"
"""The CCSDS_OEM_VERS written."""

_EPOCH_DECIMALS = 9
_NUMBER = "{: .15e}"  # 16 significant digits
_KM = 1000.0


@dataclasses.dataclass(frozen=True, eq=False)
class OemSegment:
    """One ephemeris segment to write.

    object_name : str; jd1, jd2 : (N,) -- epochs, two-part JD [d] in
    ``time_system``, strictly increasing; r : (N, 3) [m]; v : (N, 3) [m/s];
    a : (N, 3) [m/s^2] or None; center_name, ref_frame, time_system : str
    (default: tqdyn's heliocentric SUN / ICRF / TDB); object_id : str or None
    (None: the object name); interpolation, interpolation_degree: the
    recommended interpolation (default HERMITE 7: 4 records with position and
    velocity); comments : lines written after META_STOP.
    """

    object_name: str
    jd1: np.ndarray
    jd2: np.ndarray
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray | None = None
    center_name: str = HELIOCENTRIC[0]
    ref_frame: str = HELIOCENTRIC[1]
    time_system: str = HELIOCENTRIC[2]
    object_id: str | None = None
    interpolation: str | None = "HERMITE"
    interpolation_degree: int | None = 7
    comments: tuple[str, ...] = ()

    @classmethod
    def heliocentric(cls, object_name, jd1, jd2, r, v, **kw) -> OemSegment:
        """A segment of tqdyn's heliocentric system (SUN, ICRF axes, TDB)."""
        c, f, t = HELIOCENTRIC
        return cls(object_name, jd1, jd2, r, v, center_name=c, ref_frame=f, time_system=t, **kw)

    @classmethod
    def geocentric(cls, object_name, jd1, jd2, r, v, **kw) -> OemSegment:
        """A segment of tqdyn's geocentric system (EARTH, GCRF, TT)."""
        c, f, t = GEOCENTRIC
        return cls(object_name, jd1, jd2, r, v, center_name=c, ref_frame=f, time_system=t, **kw)


# ------------------------------------------------------------------ checks

def _text(value, name: str, *, upper: bool = False) -> str:
    if not isinstance(value, str):
        raise ValueError(f"{name}: must be str, got {type(value).__name__}")
    s = value.strip()
    if not s or not s.isascii() or not s.isprintable():
        raise ValueError(f"{name} = {value!r}: must be non-empty printable ASCII on one line")
    return s.upper() if upper else s


def _array(val, name: str, shape: tuple) -> np.ndarray:
    arr = np.asarray(val)
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"{name}: dtype {arr.dtype} is not real numeric (float64 expected)")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    if arr.shape != shape:
        raise ValueError(f"{name}: shape {arr.shape}, expected {shape}")
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"{name}: non-finite value at index {tuple(int(i) for i in bad[0])}; "
                         "OEM states must be finite")
    return arr


def _epoch_texts(jd1, jd2, scale: str, name: str) -> list[str]:
    try:
        iy, im, iday, ihmsf = erfa.d2dtf(scale, _EPOCH_DECIMALS, jd1, jd2)
    except (erfa.ErfaError, ValueError) as exc:
        raise ValueError(f"{name}: epochs cannot be written as calendar dates ({exc})") from None
    if np.any(iy < 0) or np.any(iy > 9999):
        raise ValueError(f"{name}: epochs outside the years 0000 .. 9999 of CCSDS dates")
    return [f"{y:04d}-{m:02d}-{d:02d}T{h:02d}:{mi:02d}:{s:02d}.{f:0{_EPOCH_DECIMALS}d}"
            for y, m, d, (h, mi, s, f) in zip(iy.tolist(), im.tolist(), iday.tolist(), ihmsf.tolist())]


def _prepare(seg: OemSegment, k: int) -> dict:
    if not isinstance(seg, OemSegment):
        raise ValueError(f"segments[{k}]: must be an OemSegment, got {type(seg).__name__}")
    p = f"segments[{k}]"
    name = _text(seg.object_name, f"{p}.object_name")
    oid = name if seg.object_id is None else _text(seg.object_id, f"{p}.object_id")
    center = _text(seg.center_name, f"{p}.center_name", upper=True)
    frame = _text(seg.ref_frame, f"{p}.ref_frame", upper=True)
    if frame not in REF_FRAMES:
        raise ValueError(f"{p}.ref_frame = {frame!r} is not supported{did_you_mean(frame, REF_FRAMES)} "
                         f"(allowed: {allowed(REF_FRAMES)})")
    tsys = _text(seg.time_system, f"{p}.time_system", upper=True)
    if tsys not in TIME_SYSTEMS:
        raise ValueError(f"{p}.time_system = {tsys!r} is not supported{did_you_mean(tsys, TIME_SYSTEMS)} "
                         f"(allowed: {allowed(TIME_SYSTEMS)})")
    jd1 = np.asarray(seg.jd1)
    if jd1.ndim != 1 or jd1.shape[0] < 1:
        raise ValueError(f"{p}.jd1: shape {jd1.shape}, expected (N,) with N >= 1 epochs")
    N = jd1.shape[0]
    jd1 = _array(jd1, f"{p}.jd1", (N,))
    jd2 = _array(np.broadcast_to(np.asarray(seg.jd2), (N,)) if np.ndim(seg.jd2) == 0 else seg.jd2,
                 f"{p}.jd2", (N,))
    step = ((jd1[1:] - jd1[:-1]) + (jd2[1:] - jd2[:-1])) * 86400.0
    bad = np.flatnonzero(~(step > 0))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{p}: epochs must increase strictly; epoch {i + 1} is {step[i]!r} s after epoch {i}")
    cols = [_array(seg.r, f"{p}.r", (N, 3)), _array(seg.v, f"{p}.v", (N, 3))]
    if seg.a is not None:
        cols.append(_array(seg.a, f"{p}.a", (N, 3)))
    epochs = _epoch_texts(jd1, jd2, tsys, p)
    dup = [i for i in range(1, N) if epochs[i] <= epochs[i - 1]]
    if dup:
        raise ValueError(f"{p}: epochs {dup[0] - 1} and {dup[0]} are closer than the 1 ns written "
                         f"({epochs[dup[0]]})")
    meta = {"OBJECT_NAME": name, "OBJECT_ID": oid, "CENTER_NAME": center, "REF_FRAME": frame,
            "TIME_SYSTEM": tsys, "START_TIME": epochs[0], "STOP_TIME": epochs[-1]}
    if seg.interpolation is not None:
        method = _text(seg.interpolation, f"{p}.interpolation", upper=True)
        if method not in INTERPOLATIONS:
            raise ValueError(f"{p}.interpolation = {method!r} is not supported{did_you_mean(method, INTERPOLATIONS)} "
                             f"(allowed: {allowed(INTERPOLATIONS)})")
        deg = seg.interpolation_degree
        if not isinstance(deg, (int, np.integer)) or isinstance(deg, bool) or deg < 1:
            raise ValueError(f"{p}.interpolation_degree = {deg!r}: must be an int >= 1")
        if method == "HERMITE" and deg % 2 == 0:
            raise ValueError(f"{p}.interpolation_degree = {deg} for HERMITE must be odd (2n - 1 for n records)")
        if method == "LINEAR" and deg != 1:
            raise ValueError(f"{p}.interpolation_degree = {deg} for LINEAR must be 1")
        meta["INTERPOLATION"] = method
        meta["INTERPOLATION_DEGREE"] = str(int(deg))
    lines = (seg.comments,) if isinstance(seg.comments, str) else tuple(seg.comments)
    comments = [_text(c, f"{p}.comments[{i}]") for i, c in enumerate(lines)]
    values = np.concatenate(cols, axis=1) / _KM
    return {"meta": meta, "epochs": epochs, "values": values, "comments": comments,
            "span": (jd1[0], jd2[0], jd1[-1], jd2[-1])}


def _check_single_object(parts: list[dict]) -> None:
    first = parts[0]["meta"]
    for k, part in enumerate(parts[1:], 1):
        meta = part["meta"]
        for key in ("OBJECT_NAME", "OBJECT_ID", "TIME_SYSTEM"):
            if meta[key] != first[key]:
                raise ValueError(f"segments[{k}]: {key} = {meta[key]!r} differs from segments[0]'s {first[key]!r}; "
                                 "an OEM holds a single object in one time system (CCSDS 502.0-B-2, 5.1.3): "
                                 "write one file per object")
        a1, a2, _, _ = part["span"]
        _, _, b1, b2 = parts[k - 1]["span"]
        if ((a1 - b1) + (a2 - b2)) < 0:
            raise ValueError(f"segments[{k}]: starts at {part['epochs'][0]}, before segments[{k - 1}] ends "
                             f"({parts[k - 1]['epochs'][-1]}); segments must follow each other in time")


def _kvn(parts: list[dict], originator: str, creation_date: str, comments: list[str]) -> str:
    out = [f"CCSDS_OEM_VERS = {OEM_VERSION}"]
    out += [f"COMMENT {c}" for c in comments]
    out += [f"CREATION_DATE = {creation_date}", f"ORIGINATOR = {originator}", ""]
    for part in parts:
        out.append("META_START")
        out += [f"{key} = {val}" for key, val in part["meta"].items()]
        out.append("META_STOP")
        out.append("")
        out += [f"COMMENT {c}" for c in part["comments"]]
        for epoch, row in zip(part["epochs"], part["values"].tolist()):
            out.append(epoch + " " + " ".join(_NUMBER.format(x) for x in row))
        out.append("")
    return "\n".join(out) + "\n"


def _default_comments(parts: list[dict]) -> list[str]:
    lines = [f"written by tqdyn {__version__}",
             "units: positions km, velocities km/s" + (", accelerations km/s**2" if any(
                 p["values"].shape[1] == 9 for p in parts) else "")]
    systems = {(p["meta"]["CENTER_NAME"], p["meta"]["REF_FRAME"], p["meta"]["TIME_SYSTEM"]) for p in parts}
    if HELIOCENTRIC in systems:
        lines.append("SUN / ICRF / TDB: heliocentric, ICRF axes, TDB-compatible coordinates (tqdyn heliocentric)")
    if GEOCENTRIC in systems:
        lines.append("EARTH / GCRF / TT: the GCRS, ICRF axes, TT-compatible coordinates (tqdyn geocentric)")
    return lines


def _write_atomic(out: pathlib.Path, text: str) -> None:
    with replacing(out, "OEM file") as tmp, open(tmp, "x", encoding="ascii", newline="\n") as fh:
        fh.write(text)


def _header_args(originator, creation_date):
    orig = _text(originator, "originator")
    if creation_date is None:
        creation_date = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S")
    return orig, _text(creation_date, "creation_date")


def write_oem(path, segments: OemSegment | Sequence[OemSegment], *, originator: str = "tqdyn",
              creation_date: str | None = None, comments: Sequence[str] = ()) -> pathlib.Path:
    """Write the segment(s) of one object as a CCSDS OEM 2.0 file (KVN), atomically.

    path : destination (checked with :func:`tqdyn.formats.trajectory.check_writable`;
    an existing file is replaced only when the new one is complete);
    segments : an :class:`OemSegment` or a sequence of them, of one object
    (same OBJECT_NAME, OBJECT_ID, TIME_SYSTEM) in time order;
    originator : ORIGINATOR; creation_date : CREATION_DATE (UTC
    ``YYYY-MM-DDThh:mm:ss``; default now); comments : header COMMENT lines
    (default: tqdyn version, units, frames).

    Returns the absolute path written.  Raises ValueError (bad input, naming
    the field) or :class:`tqdyn.formats.trajectory.OutputError` (path not
    writable); nothing is written then.
    """
    segs = [segments] if isinstance(segments, OemSegment) else list(segments)
    if not segs:
        raise ValueError("segments: at least one OemSegment is needed")
    parts = [_prepare(s, k) for k, s in enumerate(segs)]
    _check_single_object(parts)
    orig, created = _header_args(originator, creation_date)
    comments = (comments,) if isinstance(comments, str) else tuple(comments)
    lines = [_text(c, f"comments[{i}]") for i, c in enumerate(comments)] or _default_comments(parts)
    out = _io.check_writable(path)
    _write_atomic(out, _kvn(parts, orig, created, lines))
    return out


def write_oem_files(directory, segments: Sequence[OemSegment], *, name: str = "{object_name}.oem",
                    originator: str = "tqdyn", creation_date: str | None = None,
                    comments: Sequence[str] = ()) -> list[pathlib.Path]:
    """Write one OEM file per object (e.g. per satellite of a constellation)
    into ``directory``: the segments of each OBJECT_NAME, in the order given,
    go to ``name.format(object_name=..., index=...)`` (index: 1, 2, ... in
    order of first appearance).  Everything is checked before the first file
    is written; each file is written atomically (:func:`write_oem`).
    Returns the paths written."""
    segs = list(segments)
    if not segs:
        raise ValueError("segments: at least one OemSegment is needed")
    groups: dict[str, list[OemSegment]] = {}
    for k, s in enumerate(segs):
        _prepare(s, k)
        groups.setdefault(_text(s.object_name, f"segments[{k}].object_name"), []).append(s)
    targets = []
    for i, (obj, group) in enumerate(groups.items(), 1):
        fname = name.format(object_name=obj, index=i)
        if not fname or "/" in fname or os.sep in fname or fname in (".", ".."):
            raise ValueError(f"name = {name!r} gives the file name {fname!r} for {obj!r}: must be a plain file name")
        targets.append((pathlib.Path(directory) / fname, group))
    if len({p for p, _ in targets}) != len(targets):
        raise ValueError(f"name = {name!r} gives the same file name to two objects; use {{object_name}} or {{index}}")
    for k, (p, group) in enumerate(targets):
        parts = [_prepare(s, j) for j, s in enumerate(group)]
        _check_single_object(parts)
        _io.check_writable(p)
    _header_args(originator, creation_date)
    return [write_oem(p, group, originator=originator, creation_date=creation_date, comments=comments)
            for p, group in targets]
