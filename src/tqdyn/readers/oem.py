"""Reader of CCSDS Orbit Ephemeris Messages (OEM 1.0 / 2.0, KVN or XML) and
their interpolation (CCSDS 502.0-B-2, "Orbit Data Messages", section 5).

Parsing is done by the PyPI package ``oem`` (``OrbitEphemerisMessage.open``
checks the file against the standard; ``oem.parsers`` gives the text of
every field); this module turns one ephemeris segment into arrays in SI
units, interpolates them as the file says (:func:`states_at`) and converts
them to tqdyn's systems (:func:`to_heliocentric`, :func:`to_geocentric`).

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
equinox), ICRF, GCRF; TIME_SYSTEM TDB, TCB, TT.  EME2000 -> ICRF axes: the
IAU 2006 frame bias, r_ICRS = B^T r_EME2000 with B = ``erfa.bp06(...)[0]``
(the bias matrix rb: ICRS -> mean J2000; a rotation by 23.1 mas, i.e. up
to 16.8 km at 1 au).  TCB -> TDB (IAU 2006 Resolution B3):
TDB = TCB - L_B (JD_TCB - T0) 86400 s + TDB0, T0 = 2443144.5003725,
TDB0 = -6.55e-5 s.  ESA's TCB LISA files (``data/esa-lisa-orbits/tcb``) carry
the same numbers as their TDB files, only the time tags differ: their
coordinates are TDB-compatible (not scaled by 1 + L_B), which is the default
of :func:`to_heliocentric` (``tcb_scaled_coordinates=False``).

Errors: one-line ``ValueError`` messages naming the file, the field and the
value (malformed file, unsupported frame or time system, non-monotonic
epochs, epoch outside the span); no exception of the ``oem`` package leaks.
This layer imports nothing of tqdyn but :mod:`tqdyn.astro.constants`.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import re
import warnings
from fractions import Fraction

import erfa
import numpy as np

from ..astro.constants import DAY_S, L_B

__all__ = [
    "GEOCENTRIC",
    "HELIOCENTRIC",
    "INTERPOLATIONS",
    "REF_FRAMES",
    "TCB_T0_JD",
    "TDB0_S",
    "TIME_SYSTEMS",
    "OemTrajectory",
    "esa_lisa_orbit_files",
    "frame_bias_matrix",
    "read_oem",
    "read_oem_segments",
    "require_center",
    "states_at",
    "tcb_to_tdb",
    "to_geocentric",
    "to_heliocentric",
]

REF_FRAMES = ("EME2000", "ICRF", "GCRF")
"""REF_FRAME values read (EME2000 is rotated to ICRF / GCRF axes by the frame bias)."""
TIME_SYSTEMS = ("TDB", "TCB", "TT")
"""TIME_SYSTEM values read."""
INTERPOLATIONS = ("HERMITE", "LAGRANGE", "LINEAR")
"""INTERPOLATION methods that :func:`states_at` implements."""

HELIOCENTRIC = ("SUN", "ICRF", "TDB")
"""(CENTER_NAME, REF_FRAME, TIME_SYSTEM) of tqdyn's heliocentric system: Sun-centred, ICRF axes, TDB."""
GEOCENTRIC = ("EARTH", "GCRF", "TT")
"""(CENTER_NAME, REF_FRAME, TIME_SYSTEM) of tqdyn's geocentric system: the GCRS (ICRF axes), TT."""

#: T0 of IAU 2006 Resolution B3: 1977-01-01T00:00:32.184 TAI as a JD in TCB (and TDB, TT) [d].
TCB_T0_JD = 2443144.5003725
#: TDB0 of IAU 2006 Resolution B3 [s]: TDB = TCB - L_B (JD_TCB - T0) 86400 + TDB0.
TDB0_S = -6.55e-5

_DAY = float(DAY_S)
_EPOCH = re.compile(r"^(\d{4})-(?:(\d{2})-(\d{2})|(\d{3}))T(\d{2}):(\d{2}):(\d{2}(?:\.\d*)?)Z?$")
_KM = 1000.0


@dataclasses.dataclass(frozen=True, eq=False)
class OemTrajectory:
    """One ephemeris segment of an OEM file, in SI units.

    source : str -- the file (for messages); object_name, object_id,
    center_name, ref_frame, time_system : str -- the metadata (upper case for
    the last three); jd1, jd2 : (N,) float64 -- epochs, two-part JD [d] in
    ``time_system`` (strictly increasing); r : (N, 3) [m], v : (N, 3) [m/s],
    a : (N, 3) [m/s^2] or None -- the states; interpolation : str or None and
    interpolation_degree : int or None -- as the file says; start, stop :
    (jd1, jd2) -- the usable span (USEABLE_START/STOP_TIME if given, else the
    first and last records); header : dict of the header's text fields.
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


def _jd_text(jd1, jd2) -> str:
    iy, im, iday, ihmsf = erfa.d2dtf("TT", 9, jd1, jd2)
    h, mi, s, f = (int(ihmsf[key]) for key in "hmsf")
    return f"{int(iy):04d}-{int(im):02d}-{int(iday):02d}T{h:02d}:{mi:02d}:{s:02d}.{f:09d}"


# ------------------------------------------------------------------ reading

def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
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
        raise ValueError(f"{where}: REF_FRAME = {frame!r} is not supported (allowed: {', '.join(REF_FRAMES)})")
    tsys = field("TIME_SYSTEM").upper()
    if tsys not in TIME_SYSTEMS:
        raise ValueError(f"{where}: TIME_SYSTEM = {tsys!r} is not supported (allowed: {', '.join(TIME_SYSTEMS)})")
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
    for key in ("USEABLE_START_TIME", "USEABLE_STOP_TIME"):
        val = field(key, required=False)
        if val is not None:
            u = _epoch_jd(val, where, key)
            if key == "USEABLE_START_TIME":
                start = u if _dsec(*u, *start) > 0 else start
            else:
                stop = u if _dsec(*u, *stop) < 0 else stop
    if not _dsec(*stop, *start) >= 0:
        raise ValueError(f"{where}: USEABLE_START_TIME .. USEABLE_STOP_TIME leave no usable span")
    return dict(where=where, rows=rows, source=src, object_name=field("OBJECT_NAME"), object_id=field("OBJECT_ID"),
                center_name=field("CENTER_NAME").upper(), ref_frame=frame, time_system=tsys, jd1=jd1, jd2=jd2,
                interpolation=interp.upper() if interp else None, interpolation_degree=degree,
                start=start, stop=stop)


def _segment(md: dict, states, header: dict) -> OemTrajectory:
    md = dict(md)
    where, rows, jd1 = md.pop("where"), md.pop("rows"), md["jd1"]
    vals = np.array([s.vector for s in states], dtype=np.float64)
    if vals.shape[0] != jd1.shape[0] or vals.shape[1] not in (6, 9):
        raise ValueError(f"{where}: the oem package read {vals.shape[0]} states of {vals.shape[1:]} values, "
                         f"the text has {jd1.shape[0]} records")
    if not np.all(np.isfinite(vals)):
        i = int(np.argwhere(~np.isfinite(vals))[0, 0])
        raise ValueError(f"{where}: record {i + 1} (epoch {str(rows[i][0])!r}) has a non-finite value")
    vals = vals * _KM
    return OemTrajectory(r=np.ascontiguousarray(vals[:, 0:3]), v=np.ascontiguousarray(vals[:, 3:6]),
                         a=np.ascontiguousarray(vals[:, 6:9]) if vals.shape[1] == 9 else None,
                         header=dict(header), **md)


def read_oem_segments(path) -> list[OemTrajectory]:
    """Every ephemeris segment of the OEM file ``path`` (KVN or XML, optionally
    gzip/bz2/xz-compressed), as :class:`OemTrajectory` in SI units.

    Raises ``FileNotFoundError`` (no such file) or a one-line ``ValueError``
    naming the file (and the segment, the field and its value).
    """
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


def read_oem(path, object_name: str | None = None) -> OemTrajectory:
    """The ephemeris segment of the OEM file ``path``: the only one, or (a
    file of several segments) the one of ``object_name``, which must be
    unique.  See :func:`read_oem_segments` for the errors."""
    every = read_oem_segments(path)
    segs = every
    if object_name is not None:
        segs = [s for s in every if s.object_name == object_name]
        if not segs:
            names = sorted({s.object_name for s in every})
            raise ValueError(f"{os.fspath(path)}: OBJECT_NAME = {object_name!r} not in the file "
                             f"(it has: {', '.join(repr(n) for n in names)})")
    if len(segs) != 1:
        raise ValueError(f"{os.fspath(path)}: {len(segs)} ephemeris segments"
                         + (f" of OBJECT_NAME = {object_name!r}" if object_name else "")
                         + "; use read_oem_segments() to read them all")
    return segs[0]


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


# ------------------------------------------------------------------ interpolation

def _nodes(method: str, degree: int, where: str) -> int:
    if method == "HERMITE":
        if degree < 1 or degree % 2 == 0:
            raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for HERMITE must be odd and >= 1 "
                             "(n records with position and velocity give degree 2n - 1)")
        return (degree + 1) // 2
    if method == "LINEAR":
        if degree not in (None, 1):
            raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for LINEAR must be 1")
        return 2
    if degree < 1:
        raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for LAGRANGE must be >= 1")
    return degree + 1


def _lagrange_basis(tau, d):
    """l_i(t) and l_i'(t) for nodes t_i: tau (M, n) = t - t_i [s], d (M, n, n) = t_i - t_j."""
    n = tau.shape[1]
    l = np.ones_like(tau)
    dl = np.zeros_like(tau)
    for i in range(n):
        others = [j for j in range(n) if j != i]
        for j in others:
            l[:, i] *= tau[:, j] / d[:, i, j]
        for k in others:
            term = 1.0 / d[:, i, k]
            for j in others:
                if j != k:
                    term = term * tau[:, j] / d[:, i, j]
            dl[:, i] += term
    return l, dl


def states_at(traj: OemTrajectory, jd1, jd2=0.0, *, method: str | None = None,
              degree: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Interpolated position [m] and velocity [m/s] at the epochs jd1 + jd2
    [d] (in ``traj.time_system``; arrays, broadcast to shape S) -> r, v of
    shape S + (3,).

    Method and degree: the file's INTERPOLATION / INTERPOLATION_DEGREE unless
    given.  HERMITE of degree 2n - 1: the polynomial through the positions and
    velocities of n records (degree 7: 4 records), velocity its derivative;
    LAGRANGE of degree n - 1 (and LINEAR, n = 2): positions and velocities
    interpolated separately through n records.  The records: n consecutive
    ones with as many on each side of the epoch as possible (n // 2 at or
    before it), shifted inwards at the ends; at a record's epoch the record
    itself is returned.  Epochs outside the usable span (``traj.start``
    .. ``traj.stop``, ends included): one-line ValueError naming the file.
    """
    where = traj.source
    m = (method or traj.interpolation or "").upper()
    if not m:
        raise ValueError(f"{where}: the file gives no INTERPOLATION; pass method= "
                         f"(allowed: {', '.join(INTERPOLATIONS)})")
    if m not in INTERPOLATIONS:
        raise ValueError(f"{where}: INTERPOLATION = {m!r} is not supported (allowed: {', '.join(INTERPOLATIONS)})")
    deg = degree if degree is not None else (traj.interpolation_degree if method is None or m == traj.interpolation
                                             else None)
    if deg is None:
        if m != "LINEAR":
            raise ValueError(f"{where}: no INTERPOLATION_DEGREE for {m}; pass degree=")
        deg = 1
    n = _nodes(m, int(deg), where)
    N = len(traj)
    if N < n:
        raise ValueError(f"{where}: {m} of degree {deg} needs {n} records, the segment has {N}")
    q1, q2 = np.broadcast_arrays(np.asarray(jd1, dtype=np.float64), np.asarray(jd2, dtype=np.float64))
    shape = q1.shape
    q1, q2 = q1.ravel(), q2.ravel()
    if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(q2))):
        raise ValueError(f"{where}: epoch must be finite")
    before = _dsec(q1, q2, *traj.start) < 0
    after = _dsec(q1, q2, *traj.stop) > 0
    if np.any(before | after):
        i = int(np.flatnonzero(before | after)[0])
        raise ValueError(f"{where}: epoch {_jd_text(q1[i], q2[i])} {traj.time_system} "
                         f"(JD {float(q1[i])!r} + {float(q2[i])!r}) is outside the span "
                         f"{_jd_text(*traj.start)} .. {_jd_text(*traj.stop)} {traj.time_system} of the file")
    # window: records k - n//2 .. k - n//2 + n - 1, k = records at or before the epoch
    t_rec = _dsec(traj.jd1, traj.jd2, traj.jd1[0], traj.jd2[0])
    t_q = _dsec(q1, q2, traj.jd1[0], traj.jd2[0])
    k = np.searchsorted(t_rec, t_q, side="right")
    first = np.clip(k - n // 2, 0, N - n)
    idx = first[:, None] + np.arange(n)[None, :]                     # (M, n)
    n1, n2 = traj.jd1[idx], traj.jd2[idx]
    tau = _dsec(q1[:, None], q2[:, None], n1, n2)                    # t - t_i [s]
    d = _dsec(n1[:, :, None], n2[:, :, None], n1[:, None, :], n2[:, None, :])  # t_i - t_j [s]
    np.einsum("mii->mi", d)[...] = 1.0                               # unused diagonal
    x, xd = traj.r[idx], traj.v[idx]                                 # (M, n, 3)
    l, dl = _lagrange_basis(tau, d)
    if m == "HERMITE":
        inv = 1.0 / d
        np.einsum("mii->mi", inv)[...] = 0.0
        c = inv.sum(axis=2)                                          # l_i'(t_i)
        g = 1.0 - 2.0 * tau * c
        H = g * l * l
        K = tau * l * l
        dH = -2.0 * c * l * l + 2.0 * g * l * dl
        dK = l * l + 2.0 * tau * l * dl
        r = np.einsum("mi,mik->mk", H, x) + np.einsum("mi,mik->mk", K, xd)
        v = np.einsum("mi,mik->mk", dH, x) + np.einsum("mi,mik->mk", dK, xd)
    else:
        r = np.einsum("mi,mik->mk", l, x)
        v = np.einsum("mi,mik->mk", l, xd)
    hit_m, hit_i = np.nonzero(tau == 0.0)
    r[hit_m] = x[hit_m, hit_i]
    v[hit_m] = xd[hit_m, hit_i]
    return r.reshape(shape + (3,)), v.reshape(shape + (3,))


# ------------------------------------------------------------------ conversions

@functools.lru_cache(maxsize=1)
def frame_bias_matrix() -> np.ndarray:
    """The IAU 2006 frame-bias matrix B (ICRS -> mean equator and equinox of
    J2000, "EME2000"): r_EME2000 = B r_ICRS, r_ICRS = B^T r_EME2000.
    ``erfa.bp06(2451545, 0)[0]`` (the bias does not depend on the date)."""
    rb = np.array(erfa.bp06(2451545.0, 0.0)[0], dtype=np.float64)
    rb.setflags(write=False)
    return rb


def tcb_to_tdb(jd1, jd2) -> tuple[np.ndarray, np.ndarray]:
    """TDB (jd1, jd2) of TCB instants (jd1, jd2) [d] (IAU 2006 Resolution B3):
    TDB = TCB - L_B ((jd1 - T0) + jd2) 86400 s + TDB0; jd1 kept, the
    correction (~ -30 s in 2037) added to jd2 (error ~1e-17 d)."""
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    corr = (-L_B * ((jd1 - TCB_T0_JD) + jd2) * _DAY + TDB0_S) / _DAY
    return jd1.copy(), jd2 + corr


def _to_icrf_axes(traj: OemTrajectory, name: str, frame_bias: bool = True) -> OemTrajectory:
    if traj.ref_frame == "EME2000" and frame_bias:
        bt = frame_bias_matrix().T
        return traj.replace(r=traj.r @ bt.T, v=traj.v @ bt.T, a=None if traj.a is None else traj.a @ bt.T,
                            ref_frame=name)
    return traj.replace(ref_frame=name)


def to_heliocentric(traj: OemTrajectory, *, tcb_scaled_coordinates: bool = False,
                    eme2000_frame_bias: bool = True) -> OemTrajectory:
    """``traj`` in tqdyn's heliocentric system: CENTER_NAME SUN, ICRF axes, TDB.

    REF_FRAME EME2000 is rotated by the frame bias (ICRF kept) -- unless
    ``eme2000_frame_bias`` is False: then EME2000 is taken as a label of
    ICRF axes (ESA's CReMA 2.0 LISA files, whose "EME2000" states fit
    ICRF-axes dynamics: tests/test_esa_lisa.py, docs/lisa-orbits.md); TIME_SYSTEM
    TCB tags become TDB (:func:`tcb_to_tdb`; TDB kept).  With
    ``tcb_scaled_coordinates`` the file's coordinates are taken as
    TCB-compatible and scaled to TDB-compatible ones: r (1 - L_B), a / (1 - L_B)
    (v unchanged); ESA's TCB LISA files are not scaled (their states equal
    those of the TDB files), hence the default False.  Raises ValueError
    (naming the file) for another centre, GCRF or TT.
    """
    require_center(traj, "SUN")
    if traj.ref_frame not in ("EME2000", "ICRF"):
        raise ValueError(f"{traj.source}: REF_FRAME = {traj.ref_frame!r} is not heliocentric "
                         "(allowed here: EME2000, ICRF)")
    if traj.time_system not in ("TDB", "TCB"):
        raise ValueError(f"{traj.source}: TIME_SYSTEM = {traj.time_system!r} for a heliocentric trajectory "
                         "(allowed here: TDB, TCB)")
    out = _to_icrf_axes(traj, "ICRF", eme2000_frame_bias)
    if traj.time_system == "TCB":
        j1, j2 = tcb_to_tdb(traj.jd1, traj.jd2)
        (s1,), (s2,) = tcb_to_tdb([traj.start[0]], [traj.start[1]])
        (e1,), (e2,) = tcb_to_tdb([traj.stop[0]], [traj.stop[1]])
        out = out.replace(jd1=j1, jd2=j2, start=(float(s1), float(s2)), stop=(float(e1), float(e2)),
                          time_system="TDB")
        if tcb_scaled_coordinates:
            out = out.replace(r=out.r * (1.0 - L_B), a=None if out.a is None else out.a / (1.0 - L_B))
    return out


def to_geocentric(traj: OemTrajectory) -> OemTrajectory:
    """``traj`` in tqdyn's geocentric system: CENTER_NAME EARTH, GCRF (ICRF
    axes; EME2000 rotated by the frame bias), TT.  Raises ValueError (naming
    the file) for another centre, ICRF or a time system other than TT."""
    require_center(traj, "EARTH")
    if traj.ref_frame not in ("EME2000", "GCRF"):
        raise ValueError(f"{traj.source}: REF_FRAME = {traj.ref_frame!r} is not geocentric "
                         "(allowed here: EME2000, GCRF)")
    if traj.time_system != "TT":
        raise ValueError(f"{traj.source}: TIME_SYSTEM = {traj.time_system!r} for a geocentric trajectory "
                         "(allowed here: TT)")
    return _to_icrf_axes(traj, "GCRF")
