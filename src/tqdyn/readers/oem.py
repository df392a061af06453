"""Reader of CCSDS Orbit Ephemeris Messages (OEM 1.0 / 2.0, KVN or XML):
text -> arrays in SI units, segments and metadata (CCSDS 502.0-B-2, "Orbit
Data Messages", section 5).  Nothing else: the interpolation of the states,
the continuity of several segments, the EME2000 frame bias, TCB -> TDB and
tqdyn's heliocentric / geocentric systems are :mod:`tqdyn.astro.oem_states`.

Parsing is done by the PyPI package ``oem`` (``OrbitEphemerisMessage.open``
checks the file against the standard; ``oem.parsers`` gives the text of
every field); this module turns the ephemeris segments into arrays.
:func:`read_oem_segments` gives every segment as it is; :func:`read_oem`
gives the file as one :class:`OemTrajectory`: its only segment, or its
segments joined (every record, in file order, with :class:`SegmentSpan`
saying which rows are which segment) when they can be one trajectory.  A
valid OEM already holds one object (OBJECT_NAME, OBJECT_ID) in one
TIME_SYSTEM, with the segments' usable spans (USEABLE_START_TIME ..
USEABLE_STOP_TIME, else their records) in time order and not overlapping --
their records may overlap outside them (CCSDS 502.0-B-2; the ``oem``
package checks it, this module first, for messages naming the segments);
joined, they must also share CENTER_NAME and REF_FRAME and leave no gap:
each starts where the previous one stops.  Whether the states agree there
needs the interpolation, hence :func:`tqdyn.astro.oem_states.require_continuous`.

Epochs: kept as two-part Julian dates (jd1, jd2) [d] in the file's
TIME_SYSTEM, converted from the epoch *text* with exact decimal arithmetic:
jd1 = the integral JD nearest the instant (noon), jd2 in [-0.5, 0.5] the
correctly rounded remainder, so the only error is that one rounding: <= 2.8e-17
d = 2.4 ps, whatever the number of decimals in the file (ESA's LISA files give
10 ns).  The ``oem`` package's own epochs (astropy ``Time`` from the same
text) agree within 1e-11 s; its metadata times (START_TIME, ...) are
truncated to microseconds (``datetime``), so the package's own span check
puts the last record of ESA's LISA files, 1.1e-7 s after the truncated
STOP_TIME, outside the segment: this module uses the full-precision text.

Frames and time systems accepted: REF_FRAME EME2000 (J2000 mean equator and
equinox), ICRF, GCRF; TIME_SYSTEM TDB, TCB, TT.

Errors: one-line ``ValueError`` messages naming the file, the field and the
value (malformed file, unsupported frame or time system, non-monotonic
epochs, segments that cannot be one trajectory); no exception of the ``oem``
package leaks, and no message names a Python function.  This layer imports
nothing of tqdyn but :mod:`tqdyn.astro.constants`.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import re
import warnings
from fractions import Fraction

import erfa
import numpy as np

from .._choices import allowed, did_you_mean
from ..astro.constants import DAY_S

__all__ = [
    "JOIN_RULE",
    "REF_FRAMES",
    "TIME_SYSTEMS",
    "OemTrajectory",
    "SegmentSpan",
    "epoch_text",
    "esa_lisa_orbit_files",
    "read_oem",
    "read_oem_segments",
    "require_center",
]

REF_FRAMES = ("EME2000", "ICRF", "GCRF")
"""REF_FRAME values read (EME2000: see :func:`tqdyn.astro.oem_states.to_heliocentric`)."""
TIME_SYSTEMS = ("TDB", "TCB", "TT")
"""TIME_SYSTEM values read."""

_DAY = float(DAY_S)
_EPOCH = re.compile(r"^(\d{4})-(?:(\d{2})-(\d{2})|(\d{3}))T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")
_KM = 1000.0


@dataclasses.dataclass(frozen=True)
class SegmentSpan:
    """One segment of a joined multi-segment :class:`OemTrajectory`.

    rows : (first, end) -- its records are rows first .. end - 1 of the
    trajectory's arrays (end exclusive); start, stop : (jd1, jd2) [d] -- its
    usable span (USEABLE_START/STOP_TIME if given, else its first and last
    records; a stop from which the next segment's start differs by no more
    than half a unit of the two epochs' last printed decimal -- the same
    epoch written with other digits -- is moved to that start),
    in the trajectory's ``time_system``; start_text, stop_text :
    str -- the same two epochs as the file writes them, with the file's
    TIME_SYSTEM (e.g. ``"2048-03-04T23:11:53.47537616 TDB"``: for messages,
    unchanged by time-scale conversions); interpolation, interpolation_degree
    -- its INTERPOLATION (upper case) and INTERPOLATION_DEGREE, or None;
    r_unit [m], v_unit [m/s] -- one unit of the last digit the file prints
    for its positions and velocities (the largest over its records: the
    digits' rounding is at most half of it per component).
    """

    rows: tuple[int, int]
    start: tuple[float, float]
    stop: tuple[float, float]
    start_text: str
    stop_text: str
    interpolation: str | None
    interpolation_degree: int | None
    r_unit: float
    v_unit: float

    @property
    def label(self) -> str:
        """``"start .. stop TS"`` as in the file (for messages)."""
        return _label((self.start_text, self.stop_text))


@dataclasses.dataclass(frozen=True, eq=False)
class OemTrajectory:
    """The states of an OEM file (one segment, or several joined), in SI units.

    source : str -- the file (for messages); object_name, object_id,
    center_name, ref_frame, time_system : str -- the metadata (upper case for
    the last three); jd1, jd2 : (N,) float64 -- epochs, two-part JD [d] in
    ``time_system`` (strictly increasing within each segment); r : (N, 3)
    [m], v : (N, 3) [m/s], a : (N, 3) [m/s^2] or None (None also when a
    segment has none) -- the states; interpolation : str or None and
    interpolation_degree : int or None -- as the file says (a joined file:
    the segments' common value, None if they differ); start, stop :
    (jd1, jd2) -- the usable span (USEABLE_START/STOP_TIME if given, else the
    first and last records; a joined file: its segments' union); header :
    dict of the header's text fields; segments : () for one segment (the
    whole arrays), else one :class:`SegmentSpan` per segment of the file, in
    file order (:func:`read_oem`).
    """

    source: str
    object_name: str
    object_id: str
    center_name: str
    ref_frame: str
    time_system: str
    jd1: np.ndarray
    jd2: np.ndarray
    r: np.ndarray
    v: np.ndarray
    a: np.ndarray | None
    interpolation: str | None
    interpolation_degree: int | None
    start: tuple[float, float]
    stop: tuple[float, float]
    header: dict = dataclasses.field(default_factory=dict)
    segments: tuple[SegmentSpan, ...] = ()

    def __len__(self) -> int:
        return int(self.jd1.shape[0])

    def replace(self, **changes) -> OemTrajectory:
        """A copy with some fields changed."""
        return dataclasses.replace(self, **changes)


# ------------------------------------------------------------------ epochs

def _epoch_jd(text: str, source: str, field: str) -> tuple[float, float]:
    """Exact two-part JD (jd1 integral, |jd2| <= 0.5) of a CCSDS epoch text
    ``YYYY-MM-DDThh:mm:ss[.d...]`` or ``YYYY-DDDThh:mm:ss[.d...]``."""
    m = _EPOCH.match(text.strip())
    if m is None:
        raise ValueError(f"{source}: {field} = {text.strip()!r} is not a CCSDS epoch "
                         "(allowed: YYYY-MM-DDThh:mm:ss[.d...] or YYYY-DDDThh:mm:ss[.d...])")
    year = int(m[1])
    hour, minute, sec = int(m[5]), int(m[6]), Fraction(m[7])
    if hour > 23 or minute > 59 or sec >= 60:
        raise ValueError(f"{source}: {field} = {text.strip()!r} has a time of day out of range "
                         "(hh <= 23, mm <= 59, ss < 60; leap seconds are UTC only)")
    jd_noon = _noon_jd(year, m[2], m[3], m[4])
    if jd_noon is None:
        raise ValueError(f"{source}: {field} = {text.strip()!r} is not a valid calendar date")
    frac = (Fraction(hour * 3600 + minute * 60) + sec) / DAY_S - Fraction(1, 2)
    if frac > Fraction(1, 2):
        jd_noon += 1.0
        frac -= 1
    return jd_noon, float(frac)


@functools.lru_cache(maxsize=4096)
def _noon_jd(year: int, month: str | None, day: str | None, doy: str | None) -> float | None:
    """JD of noon of a calendar date (month-day or day-of-year), None if invalid."""
    try:
        if doy is not None:
            leap = (year % 4 == 0 and year % 100 != 0) or year % 400 == 0
            if not 1 <= int(doy) <= 365 + leap:
                return None
            djm0, djm = erfa.cal2jd(year, 1, 1)
            djm = djm + int(doy) - 1
        else:
            djm0, djm = erfa.cal2jd(year, int(month), int(day))
    except (erfa.ErfaError, ValueError):
        return None
    # JD of 0 h = djm0 + djm (2400000.5 + MJD); noon is half a day later (exact in float64)
    return float(djm0) + float(djm) + 0.5


def _dsec(a1, a2, b1, b2):
    """(a1 + a2) - (b1 + b2) in seconds, for JD pairs within days of each other."""
    return ((a1 - b1) + (a2 - b2)) * _DAY


def epoch_text(jd1, jd2) -> str:
    """A two-part JD [d] as a CCSDS epoch text with 9 decimals (1 ns), in the
    time scale of the JD (for messages)."""
    iy, im, iday, ihmsf = erfa.d2dtf("TT", 9, jd1, jd2)
    h, mi, s, f = (int(ihmsf[key]) for key in "hmsf")
    return f"{int(iy):04d}-{int(im):02d}-{int(iday):02d}T{h:02d}:{mi:02d}:{s:02d}.{f:09d}"


# ------------------------------------------------------------------ reading

def _one_line(exc: BaseException) -> str:
    """The exception in one line: its text (a ValueError's alone), after its type."""
    text = " ".join(str(exc).split())
    if text and isinstance(exc, ValueError):
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _raw(path: str):
    """(header, segments) as the ``oem`` package's parsers give them (text)."""
    # imported here: ``oem`` imports astropy (~0.5 s), which only the OEM reader needs
    from oem import parsers, tools

    if tools.is_kvn(path):
        with tools._open(path, "rt") as fh:
            return parsers.parse_kvn_oem(fh)
    with tools._open(path, "rt") as fh:
        return parsers.parse_xml_oem(fh)


def _open(path: str):
    from oem import OrbitEphemerisMessage

    return OrbitEphemerisMessage.open(path)


def _metadata(src: str, k: int, nseg: int, meta: dict, rows) -> dict:
    """The checked metadata and epochs of one raw segment (before the ``oem`` package validates the file)."""
    where = src if nseg == 1 else f"{src} (segment {k + 1})"

    def field(key, required=True):
        val = meta.get(key)
        if val is None or not str(val).strip():
            if required:
                raise ValueError(f"{where}: metadata field {key} is missing (required by CCSDS 502.0-B-2)")
            return None
        return str(val).strip()

    frame = field("REF_FRAME").upper()
    if frame not in REF_FRAMES:
        raise ValueError(f"{where}: REF_FRAME = {frame!r} is not supported{did_you_mean(frame, REF_FRAMES)} "
                         f"(allowed: {allowed(REF_FRAMES)})")
    tsys = field("TIME_SYSTEM").upper()
    if tsys not in TIME_SYSTEMS:
        raise ValueError(f"{where}: TIME_SYSTEM = {tsys!r} is not supported{did_you_mean(tsys, TIME_SYSTEMS)} "
                         f"(allowed: {allowed(TIME_SYSTEMS)})")
    if not rows:
        raise ValueError(f"{where}: the data section has no state vectors (truncated file?)")
    jd = np.array([_epoch_jd(str(row[0]), where, f"epoch of record {i + 1}") for i, row in enumerate(rows)],
                  dtype=np.float64).reshape(-1, 2)
    jd1, jd2 = jd[:, 0].copy(), jd[:, 1].copy()
    step = _dsec(jd1[1:], jd2[1:], jd1[:-1], jd2[:-1])
    bad = np.flatnonzero(~(step > 0))
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{where}: epochs not strictly increasing: record {i + 2} epoch = {str(rows[i + 1][0])!r} "
                         f"follows record {i + 1} epoch = {str(rows[i][0])!r}")
    interp = field("INTERPOLATION", required=False)
    degree = field("INTERPOLATION_DEGREE", required=False)
    if degree is not None:
        try:
            degree = int(degree)
        except ValueError:
            raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree!r} is not an integer") from None
    start = (float(jd1[0]), float(jd2[0]))
    stop = (float(jd1[-1]), float(jd2[-1]))
    texts = [str(rows[0][0]).strip(), str(rows[-1][0]).strip()]
    for key in ("USEABLE_START_TIME", "USEABLE_STOP_TIME"):
        val = field(key, required=False)
        if val is not None:
            u = _epoch_jd(val, where, key)
            if key == "USEABLE_START_TIME" and _dsec(*u, *start) > 0:
                start, texts[0] = u, val
            elif key == "USEABLE_STOP_TIME" and _dsec(*u, *stop) < 0:
                stop, texts[1] = u, val
    if not _dsec(*stop, *start) >= 0:
        raise ValueError(f"{where}: USEABLE_START_TIME .. USEABLE_STOP_TIME leave no usable span")
    return dict(where=where, rows=rows, source=src, object_name=field("OBJECT_NAME"), object_id=field("OBJECT_ID"),
                center_name=field("CENTER_NAME").upper(), ref_frame=frame, time_system=tsys, jd1=jd1, jd2=jd2,
                interpolation=interp.upper() if interp else None, interpolation_degree=degree,
                start=start, stop=stop, texts=(f"{texts[0]} {tsys}", f"{texts[1]} {tsys}"))


def _significant_digits(x: float) -> int:
    """Significant digits of the shortest decimal that gives the float ``x`` back (trailing zeros dropped)."""
    return len(repr(x).split("e")[0].replace(".", "").lstrip("-0").rstrip("0"))


def _last_digit_unit(x: np.ndarray) -> float:
    """One unit of the last digit printed for the values ``x`` (parsed from the text, any shape), in
    their unit: 10**(e - S + 1), e the decimal exponent of the largest |x|, S the most significant
    digits of any value.  Exact for fixed decimals ("%.6f": 1e-6); for a fixed number of significant
    digits ("%.15e") the unit of the largest value, the coarsest; 0 if every value is 0."""
    mag = np.abs(np.asarray(x, dtype=np.float64)).ravel()
    mag = mag[mag > 0]
    if not mag.size:
        return 0.0
    digits = max(_significant_digits(float(m)) for m in mag.tolist())
    return 10.0 ** (math.floor(math.log10(float(mag.max()))) - digits + 1)


def _segment(md: dict, states, header: dict) -> tuple[OemTrajectory, dict]:
    """One segment as an :class:`OemTrajectory` (SI), and what joining segments needs (texts, digits)."""
    md = dict(md)
    where, rows, jd1, texts = md.pop("where"), md.pop("rows"), md["jd1"], md.pop("texts")
    vals = np.array([s.vector for s in states], dtype=np.float64)
    if vals.shape[0] != jd1.shape[0] or vals.shape[1] not in (6, 9):
        raise ValueError(f"{where}: the oem package read {vals.shape[0]} states of {vals.shape[1:]} values, "
                         f"the text has {jd1.shape[0]} records")
    if not np.all(np.isfinite(vals)):
        i = int(np.argwhere(~np.isfinite(vals))[0, 0])
        raise ValueError(f"{where}: record {i + 1} (epoch {str(rows[i][0])!r}) has a non-finite value")
    extra = dict(texts=texts, r_unit=_last_digit_unit(vals[:, 0:3]) * _KM, v_unit=_last_digit_unit(vals[:, 3:6]) * _KM)
    vals = vals * _KM
    traj = OemTrajectory(r=np.ascontiguousarray(vals[:, 0:3]), v=np.ascontiguousarray(vals[:, 3:6]),
                         a=np.ascontiguousarray(vals[:, 6:9]) if vals.shape[1] == 9 else None,
                         header=dict(header), **md)
    return traj, extra


def _read(path) -> list[tuple[OemTrajectory, dict]]:
    """Every segment of the file, with its texts and digits (:func:`_segment`)."""
    src = os.fspath(path)
    if not os.path.isfile(src):
        raise FileNotFoundError(f"OEM file not found: {src}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            raw_header, raw_segments = _raw(src)
        except Exception as exc:  # the oem package's parser: any failure means a malformed file
            raise ValueError(f"{src}: not a readable CCSDS OEM file ({_one_line(exc)})") from None
        if not raw_segments:
            raise ValueError(f"{src}: not a readable CCSDS OEM file (no META_START .. META_STOP segment)")
        # our checks first (metadata, frame, time system, epochs), for precise messages
        metas = [_metadata(src, k, len(raw_segments), seg.get("header") or {}, seg.get("data") or [])
                 for k, seg in enumerate(raw_segments)]
        names = list(dict.fromkeys(md["object_name"] for md in metas))
        if len(names) > 1:
            raise ValueError(f"{src}: segments of {len(names)} objects (OBJECT_NAME = "
                             f"{', '.join(repr(n) for n in names)}); an OEM holds a single object "
                             "(CCSDS 502.0-B-2, 5.1.3)")
        _check_order(src, metas)
        try:
            message = _open(src)
            segments = list(message.segments)
        except Exception as exc:
            raise ValueError(f"{src}: not a valid CCSDS OEM file ({_one_line(exc)})") from None
    if len(segments) != len(raw_segments):
        raise ValueError(f"{src}: the oem package read {len(segments)} segments, the text has {len(raw_segments)}")
    header = {str(k): str(v).strip() for k, v in raw_header.items()}
    out = []
    for md, seg in zip(metas, segments):
        try:
            states = list(seg.states)
        except Exception as exc:
            raise ValueError(f"{src}: not a valid CCSDS OEM file ({_one_line(exc)})") from None
        out.append(_segment(md, states, header))
    return out


def _same_epoch(a: str, b: str) -> float:
    """How far apart [s] two epoch texts may be and still write one epoch: half a unit of the coarser last
    decimal (``"...:53.47537616 TDB"``: 1e-8 s, ``"...:53.475376 TCB"``: 1e-6 s)."""
    def unit(text):
        sec = text.split()[0].rsplit(":", 1)[-1]
        return 10.0 ** -(len(sec.split(".")[1]) if "." in sec else 0)
    return 0.5 * max(unit(a), unit(b))


def _label(texts) -> str:
    """``"start .. stop TS"`` from the (start, stop) texts with their time system."""
    return f"{texts[0].rsplit(' ', 1)[0]} .. {texts[1]}"


def _check_order(src: str, metas: list[dict]) -> None:
    """What CCSDS 502.0-B-2 asks of the segments of one OEM (and the ``oem`` package checks): one OBJECT_ID
    and TIME_SYSTEM, usable spans in time order, not overlapping; one line naming both segments' spans."""
    for k in range(1, len(metas)):
        a, b = metas[k - 1], metas[k]
        where = f"{src}: segments {k} and {k + 1}"
        for key in ("object_id", "time_system"):
            if a[key] != b[key]:
                raise ValueError(f"{where} differ in {key.upper()} ({a[key]!r}, {b[key]!r}); allowed: one object in "
                                 "one time system per file (CCSDS 502.0-B-2 5.1.3)")
        if _dsec(*b["start"], *a["stop"]) < -_same_epoch(a["texts"][1], b["texts"][0]):
            raise ValueError(f"{where} overlap: segment {k + 1} starts ({b['texts'][0]}) before segment {k} stops "
                             f"({a['texts'][1]}); allowed: usable spans in time order")


def read_oem_segments(path) -> list[OemTrajectory]:
    """Every ephemeris segment of the OEM file ``path`` (KVN or XML, optionally
    gzip/bz2/xz-compressed), as :class:`OemTrajectory` in SI units, each on
    its own (``segments == ()``), in file order, whether or not they could be
    one trajectory.

    Raises ``FileNotFoundError`` (no such file) or a one-line ``ValueError``
    naming the file (and the segment, the field and its value).
    """
    return [traj for traj, _ in _read(path)]


#: What :func:`read_oem` joins (the "allowed" of its messages): segments of one CENTER_NAME and
#: REF_FRAME, each starting where the previous one stops (records may overlap outside
#: USEABLE_START_TIME .. USEABLE_STOP_TIME), whose states agree there.
JOIN_RULE = "segments that join (docs/scenarios.md#oem-files)"


def _join(src: str, parts: list[tuple[OemTrajectory, dict]]) -> OemTrajectory:
    """The segments as one trajectory (every record, file order), or a one-line ValueError.  A segment
    that starts before or after the previous one stops by no more than half a unit of the coarser of
    the two epochs' last printed decimals (the same epoch, written with other digits) starts where it
    stops (the previous segment's stop moves there)."""
    segs = [t for t, _ in parts]
    spans, row = [], 0
    for t, x in parts:
        spans.append(SegmentSpan(rows=(row, row + len(t)), start=t.start, stop=t.stop, start_text=x["texts"][0],
                                 stop_text=x["texts"][1], interpolation=t.interpolation,
                                 interpolation_degree=t.interpolation_degree, r_unit=x["r_unit"], v_unit=x["v_unit"]))
        row += len(t)
    for k in range(1, len(segs)):
        a, b = spans[k - 1], spans[k]
        why = None
        for key in ("center_name", "ref_frame"):
            if getattr(segs[k], key) != getattr(segs[k - 1], key):
                why = f"{key.upper()} = {getattr(segs[k - 1], key)!r} and {getattr(segs[k], key)!r} differ"
        gap = _dsec(*b.start, *a.stop)  # >= -_same_epoch: _check_order
        if why is None and gap > _same_epoch(a.stop_text, b.start_text):
            why = f"a gap of {gap:.9g} s ({gap / _DAY:.6g} d) between them"
        if why is not None:
            raise ValueError(f"{src}: segments {k} and {k + 1} are not continuous: {why}; allowed: {JOIN_RULE}")
        if gap != 0:
            spans[k - 1] = dataclasses.replace(a, stop=b.start)
    first, last = segs[0], segs[-1]
    methods = {(t.interpolation, t.interpolation_degree) for t in segs}
    interp, degree = methods.pop() if len(methods) == 1 else (None, None)
    cat = np.concatenate
    return OemTrajectory(source=src, object_name=first.object_name, object_id=first.object_id,
                         center_name=first.center_name, ref_frame=first.ref_frame, time_system=first.time_system,
                         jd1=cat([t.jd1 for t in segs]), jd2=cat([t.jd2 for t in segs]), r=cat([t.r for t in segs]),
                         v=cat([t.v for t in segs]),
                         a=None if any(t.a is None for t in segs) else cat([t.a for t in segs]),
                         interpolation=interp, interpolation_degree=degree, start=first.start, stop=last.stop,
                         header=dict(first.header), segments=tuple(spans))


def read_oem(path, object_name: str | None = None) -> OemTrajectory:
    """The OEM file ``path`` as one trajectory: its only segment, or its
    segments joined (:class:`SegmentSpan`; every record in file order) when
    they can be one trajectory: one CENTER_NAME and REF_FRAME (one object
    and time system, usable spans in order and not overlapping: any valid
    OEM), each segment's usable span starting where the previous one stops
    (to the digits of the two epochs: they may differ by half a unit of the
    coarser last decimal).  The agreement of the states there needs the
    interpolation (:func:`tqdyn.astro.oem_states.require_continuous`).
    ``object_name``: the OBJECT_NAME required (an OEM holds one object).
    Errors: see :func:`read_oem_segments`, and one line naming the file, the
    two segments' spans (as the file writes them) and what is allowed.
    """
    parts = _read(path)
    if object_name is not None and parts[0][0].object_name != object_name:
        raise ValueError(f"{os.fspath(path)}: OBJECT_NAME = {object_name!r} not in the file "
                         f"(it has: {parts[0][0].object_name!r})")
    if len(parts) == 1:
        return parts[0][0]
    return _join(os.fspath(path), parts)


def esa_lisa_orbit_files(time_system: str = "TDB") -> tuple[str, str, str]:
    """Paths of ESA's LISA science orbits shipped in ``tqdyn/data/esa-lisa-orbits``
    (CReMA 2.0, trailing, May launch; see data/SOURCES.md), spacecraft 1, 2, 3:
    ``"TDB"`` the TDB files, ``"TCB"`` the ones with TCB time tags."""
    import importlib.resources

    ts = str(time_system).upper()
    if ts not in ("TDB", "TCB"):
        raise ValueError(f"time_system = {time_system!r}: ESA's LISA orbits ship in TDB and TCB (allowed: TDB, TCB)")
    base = importlib.resources.files("tqdyn") / "data" / "esa-lisa-orbits"
    if ts == "TCB":
        base = base / "tcb"
    out = []
    for i in (1, 2, 3):
        res = base / f"trajectory_out_mida-20deg_cw_sg-2nmss_may_launch_lisa{i}.oem"
        if not res.is_file():
            raise FileNotFoundError(f"ESA LISA orbit file not found: {res}")
        out.append(os.fspath(res))
    return tuple(out)


def require_center(traj: OemTrajectory, center: str = "SUN") -> OemTrajectory:
    """``traj`` if its CENTER_NAME is ``center``, else a one-line ValueError
    naming the file (for the caller that needs e.g. heliocentric states)."""
    if traj.center_name != center.upper():
        raise ValueError(f"{traj.source}: CENTER_NAME = {traj.center_name!r}, but {center.upper()!r} is required "
                         f"here (object {traj.object_name!r})")
    return traj
