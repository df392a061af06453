"""Time scales for tqdyn: UTC -> TAI -> TT -> TDB at the geocenter (pyerfa/SOFA), and TCB -> TDB.

Conventions
-----------
* Dates are two-part Julian dates ``(jd1, jd2)`` in days, following the
  ERFA/SOFA convention: ``jd1`` holds the large part (``JD0 = ... .5`` at 0 h),
  ``jd2`` the small part.  UTC uses ERFA's quasi-JD convention (a UTC day with
  a leap second is 86401 s long but still one "day" of JD).
* Time scales: UTC (civil input), TAI = UTC + (TAI-UTC) from ERFA's leap-second
  table (``erfa.dat``), TT = TAI + 32.184 s (exact, IAU 1991), TDB = TT +
  (TDB-TT) from ERFA's Fairhead & Bretagnon series ``erfa.dtdb`` evaluated at
  the geocenter (observer longitude and distances from the spin axis and the
  equator all zero).  At the geocenter the topocentric terms of ``dtdb`` are
  multiplied by those distances and vanish, so the UT1 argument ``ut`` has no
  effect; UTC's fraction of the day is passed for it.
* The geocentric time axis: t is SI seconds of TT after the scenario epoch's
  TT (TT is the coordinate time of the TT-compatible GCRS, in which the
  geocentric equations of motion and EGM2008's GM hold); the JPL ephemerides
  are read at TDB(TT) (:func:`tdb_jd`).  Version 0.1 read them at
  TDB(epoch) + t instead (25 us/day off near 2004).
* TCB (the BCRS's coordinate time, that of LISA orbit files): TDB = TCB -
  L_B (JD_TCB - T0) 86400 s + TDB0 (IAU 2006 Resolution B3) is linear, so
  TCB intervals, lengths and GMs are S = 1/(1 - L_B) times the
  TDB-compatible ones (:data:`TCB_PER_TDB`, :func:`tdb_to_tcb`) and only
  the epoch's TCB date needs ``erfa.tdbtcb`` (:func:`tcb_jd_of_epoch`).
  TT -> TCB is not linear (TDB - TT is periodic, 1.7 ms): a geocentric TT
  grid goes to TDB at the geocentre first (:func:`geocentre_tdb_grid`).

Leap seconds: on import this module merges the IERS leap-second table
``Leap_Second.dat`` of the installed ``astropy-iers-data`` package (released
weekly, with the date until which it guarantees no further leap second)
into ERFA's table (:func:`install_leap_seconds`, ``erfa.leap_seconds.update``:
the union of both, so ERFA's pre-1972 UTC drifts stay), so that TAI-UTC
here, in ERFA and in the EOP series (whose UT1-UTC jumps by +1 s at each
leap second) agree, whichever is newer (tests/test_leap_seconds.py).  For
dates after the last leap second (2017-01-01, TAI-UTC = 37 s) TAI-UTC is
held at its last value: past the table's expiry date that is an assumption
(:func:`leap_seconds_note`; the CGPM decided in 2022 to stop leap seconds by
2035) and ERFA flags the year as "dubious"; tqdyn suppresses ERFA's "dubious
year" warning.  Dates before 1960-01-01, where UTC is not defined, are
rejected.
"""

from __future__ import annotations

import datetime as _dt
import math
import re
import warnings
from dataclasses import dataclass
from decimal import Decimal, localcontext
from typing import NamedTuple

import erfa
import numpy as np

from .._choices import allowed, did_you_mean
from ..numerics.dd import np_dd_add_d, np_fast_two_sum, np_two_prod, np_two_sum
from ..numerics.lagrange import MARGIN, grid_interp
from ..readers.leap_seconds import LeapSeconds, read_leap_seconds
from .constants import DAY_S, J2000_JD, L_B

__all__ = ["TCB_ORIGINS", "TCB_PER_TDB", "TCB_SCALE", "TCB_SCALE_MINUS_1", "TCB_T0_JD", "TDB0_S", "Epoch", "UTCFields",
           "geocentre_tdb_grid", "install_leap_seconds", "installed_leap_seconds", "leap_seconds_note", "parse_utc",
           "tcb_jd_of_epoch", "tcb_origin_offset", "tcb_to_tdb", "tdb_after", "tdb_jd", "tdb_minus_tt", "tdb_to_tcb",
           "tt_jd", "unix_of_tcb"]

#: T0 of IAU 2006 Resolution B3: 1977-01-01T00:00:32.184 TAI as a JD in TCB (and TDB, TT) [d].
TCB_T0_JD = 2443144.5003725
#: TDB0 of IAU 2006 Resolution B3 [s]: TDB = TCB - L_B (JD_TCB - T0) 86400 + TDB0.
TDB0_S = -6.55e-5

_ISO_FORMAT = "YYYY-MM-DDTHH:MM:SS[.fff] (UTC; 'T' or a space between date and time; optional trailing 'Z')"

_ISO_RE = re.compile(
    r"^\s*(?P<y>\d{4})-(?P<mo>\d{2})-(?P<d>\d{2})"
    r"(?:[T ](?P<h>\d{2}):(?P<mi>\d{2})(?::(?P<s>\d{2})(?P<frac>\.\d+)?)?)?"
    r"\s*Z?\s*$"
)

_FIRST_UTC_YEAR = 1960  # UTC (and erfa.dat) start on 1960-01-01


# --------------------------------------------------------------------------- leap seconds

_LEAP: dict = {"table": None, "error": None}


class _Expiring(np.ndarray):
    """A structured leap-second array with the ``expires`` attribute erfa.leap_seconds reads."""


def install_leap_seconds(table: LeapSeconds | None = None) -> LeapSeconds:
    """Merge a leap-second table into ERFA's (``erfa.leap_seconds.update``).

    ``table=None``: the ``Leap_Second.dat`` of the installed astropy-iers-data
    package (:func:`tqdyn.readers.leap_seconds.read_leap_seconds`); done once
    on import of this module.  ERFA keeps the union of its own table and
    ``table`` (leap seconds only ever get added) and the later of the two
    expiry dates.  Returns the table; raises ``ValueError`` if it
    contradicts ERFA's (a TAI-UTC step other than 1 s).
    """
    if table is None:
        table = read_leap_seconds()
    arr = np.zeros(table.mjd.size, dtype=erfa.dt_eraLEAPSECOND)
    arr["year"], arr["month"], arr["tai_utc"] = table.year, table.month, table.tai_utc
    arr = arr.view(_Expiring)
    if table.expires is not None:
        arr.expires = _dt.datetime.combine(table.expires, _dt.time())
    erfa.leap_seconds.update(arr)
    _LEAP["table"], _LEAP["error"] = table, None
    return table


def installed_leap_seconds() -> LeapSeconds | None:
    """The leap-second table installed into ERFA (None: ERFA's own table,
    because the package file could not be read)."""
    return _LEAP["table"]


def leap_seconds_note() -> str:
    """One line: where TAI-UTC comes from, its last step and until when it is known."""
    table = _LEAP["table"]
    last = erfa.leap_seconds.get()[-1]
    step = f"last leap second {int(last['year']):04d}-{int(last['month']):02d}-01 (TAI-UTC = {last['tai_utc']:g} s)"
    if table is None:
        return f"leap seconds: ERFA's built-in table, {step} ({_LEAP['error'] or 'no IERS file installed'})"
    exp = erfa.leap_seconds.expires
    return f"leap seconds: {table.source}, {step}, valid until {exp:%Y-%m-%d} (TAI-UTC held after it)"


try:
    install_leap_seconds()
except (FileNotFoundError, ValueError) as _exc:  # pragma: no cover - package missing or corrupt
    _LEAP["error"] = str(_exc)


class UTCFields(NamedTuple):
    """Calendar fields of a UTC instant as parsed by :func:`parse_utc`.

    ``second`` is in seconds (float, may be in [60, 61) on a leap-second day);
    ``iso`` is the normalised string ``YYYY-MM-DDTHH:MM:SS[.fff]`` (the fraction
    digits as given).
    """

    year: int
    month: int
    day: int
    hour: int
    minute: int
    second: float
    iso: str


def _bad(iso: object, why: str, scale: str = "UTC") -> ValueError:
    fmt = _ISO_FORMAT.replace("(UTC;", f"({scale};")
    exc = ValueError(f"{scale} epoch {iso!r}: {why}; expected format {fmt}")
    exc.reason = why  # short reason, for callers that format their own message
    return exc


def _erfa_reason(msg: str) -> str:
    m = re.search(r'ERFA function "(\w+)" yielded \d+ of "([^"]*)"', msg)
    return f"{m[2]} (erfa.{m[1]})" if m else msg


def parse_utc(iso: str, scale: str = "UTC") -> UTCFields:
    """Parse an ISO 8601 UTC date-time string (calendar form, no time zone).

    Accepts ``YYYY-MM-DDTHH:MM:SS[.fff]``, ``YYYY-MM-DD HH:MM[:SS[.fff]]``,
    ``YYYY-MM-DD`` (midnight) and an optional trailing ``Z``.  Years before
    1960 are rejected (UTC undefined).  Calendar validity (month, day, hour,
    minute, second <= 60.999... only on a leap-second day) is checked by
    ``erfa.dtf2d``.

    Returns a :class:`UTCFields` (time scale UTC, or ``scale`` -- "TDB" --
    whose days all have 86400 s); raises ``ValueError`` naming the string
    and the expected format.
    """
    if not isinstance(iso, str):
        raise _bad(iso, f"must be a string, got {type(iso).__name__}", scale)
    m = _ISO_RE.match(iso)
    if m is None:
        raise _bad(iso, "not an ISO 8601 calendar date-time", scale)
    y, mo, d = int(m["y"]), int(m["mo"]), int(m["d"])
    h = int(m["h"] or 0)
    mi = int(m["mi"] or 0)
    s_int = m["s"] or "00"
    frac = m["frac"] or ""
    sec = float(s_int + frac)
    if y < _FIRST_UTC_YEAR:
        raise _bad(iso, f"year {y} is before {_FIRST_UTC_YEAR}, where UTC is not defined", scale)
    norm = f"{y:04d}-{mo:02d}-{d:02d}T{h:02d}:{mi:02d}:{s_int}{frac}"
    fields = UTCFields(y, mo, d, h, mi, sec, norm)
    if scale == "UTC":
        _utc_jd(fields, iso)  # calendar validation
    else:
        _erfa_quiet(erfa.dtf2d, scale, y, mo, d, h, mi, sec, iso=iso, scale=scale)
    return fields


def _erfa_quiet(func, *args, iso: object, scale: str = "UTC"):
    """Call an erfa routine; drop 'dubious year' warnings, turn others into ValueError."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", erfa.ErfaWarning)
        try:
            out = func(*args)
        except erfa.ErfaError as exc:
            raise _bad(iso, _erfa_reason(str(exc)), scale) from None
    for w in caught:
        msg = str(w.message)
        if issubclass(w.category, erfa.ErfaWarning) and "dubious year" in msg:
            continue
        if issubclass(w.category, erfa.ErfaWarning):
            raise _bad(iso, _erfa_reason(msg), scale)
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return out


def _utc_jd(f: UTCFields, iso: object) -> tuple[float, float]:
    u1, u2 = _erfa_quiet(erfa.dtf2d, "UTC", f.year, f.month, f.day, f.hour, f.minute, f.second, iso=iso)
    return float(u1), float(u2)


@dataclass(frozen=True)
class Epoch:
    """An instant given in UTC, with its two-part Julian dates in UTC, TAI, TT and TDB.

    Attributes
    ----------
    utc_iso : str
        Normalised ``YYYY-MM-DDTHH:MM:SS[.fff]`` (UTC).
    utc, tai, tt, tdb : tuple[float, float]
        Two-part Julian dates ``(jd1, jd2)`` in days in each time scale.  ``jd1``
        is the same in all four (``JD at 0 h UTC of the date``, ending in .5);
        ``jd2`` carries the fraction and the offsets (TAI-UTC, 32.184 s,
        TDB-TT).  UTC uses ERFA's quasi-JD convention.  TDB is geocentric.
    """

    utc_iso: str
    utc: tuple[float, float]
    tai: tuple[float, float]
    tt: tuple[float, float]
    tdb: tuple[float, float]
    tdb_iso: str = ""

    @classmethod
    def from_utc(cls, iso: str) -> "Epoch":
        """Build an :class:`Epoch` from a UTC ISO string (see :func:`parse_utc`).

        Chain: ``erfa.dtf2d('UTC')`` -> ``erfa.utctai`` -> ``erfa.taitt`` ->
        ``erfa.tttdb`` with ``dtr = erfa.dtdb(tt1, tt2, ut, 0, 0, 0)``
        (geocentric; TT is used for dtdb's TDB argument, the difference of
        < 2 ms changes dtr by < 1e-15 s).  Raises ``ValueError`` for a bad string.
        """
        f = parse_utc(iso)
        utc = _utc_jd(f, iso)
        tai = _erfa_quiet(erfa.utctai, *utc, iso=iso)
        tt = erfa.taitt(*tai)
        # UT fraction of the day: only used by the topocentric terms of dtdb,
        # which vanish at the geocenter (elong = u = v = 0).
        ut = (f.hour * 3600 + f.minute * 60 + f.second) / DAY_S
        dtr = erfa.dtdb(tt[0], tt[1], ut, 0.0, 0.0, 0.0)
        tdb = erfa.tttdb(tt[0], tt[1], dtr)
        return cls(f.iso, _pair(utc), _pair(tai), _pair(tt), _pair(tdb))

    @classmethod
    def from_tdb(cls, iso: str) -> "Epoch":
        """Build an :class:`Epoch` from a TDB ISO string (same calendar
        forms as :func:`parse_utc`; a TDB day has 86400 s).

        Chain: ``erfa.dtf2d('TDB')`` (exact to the digits given, ps) ->
        ``erfa.tdbtt`` with ``dtr = erfa.dtdb`` at the geocentre ->
        ``erfa.tttai`` -> ``erfa.taiutc``; ``utc_iso`` is the UTC label
        rounded to 1 us (``erfa.d2dtf``).  Raises ``ValueError`` for a bad
        string or a date whose UTC is before 1960.
        """
        f = parse_utc(iso, scale="TDB")
        tdb = _erfa_quiet(erfa.dtf2d, "TDB", f.year, f.month, f.day, f.hour, f.minute, f.second, iso=iso,
                          scale="TDB")
        dtr = erfa.dtdb(tdb[0], tdb[1], 0.0, 0.0, 0.0, 0.0)
        tt = erfa.tdbtt(tdb[0], tdb[1], dtr)
        tai = erfa.tttai(*tt)
        utc = _erfa_quiet(erfa.taiutc, *tai, iso=iso)
        y, mo, d, hmsf = _erfa_quiet(erfa.d2dtf, "UTC", 6, *utc, iso=iso)
        if int(y) < _FIRST_UTC_YEAR:
            raise _bad(iso, f"its UTC year {int(y)} is before {_FIRST_UTC_YEAR}, where UTC is not defined", "TDB")
        label = (f"{int(y):04d}-{int(mo):02d}-{int(d):02d}T{int(hmsf['h']):02d}:{int(hmsf['m']):02d}:"
                 f"{int(hmsf['s']):02d}.{int(hmsf['f']):06d}")
        return cls(label, _pair(utc), _pair(tai), _pair(tt), _pair(tdb), f.iso)

    @property
    def iso(self) -> str:
        """The epoch as given: ``tdb_iso + " TDB"`` for :meth:`from_tdb`, else ``utc_iso + " UTC"``."""
        return f"{self.tdb_iso} TDB" if self.tdb_iso else f"{self.utc_iso} UTC"


def _pair(p) -> tuple[float, float]:
    return float(p[0]), float(p[1])


def _after(pair, t_hi, t_lo) -> tuple[np.ndarray, np.ndarray]:
    """Two-part JD of ``t = t_hi + t_lo`` seconds after the JD ``pair`` (same
    time scale): jd1 = pair[0] + whole days (exact), |jd2| <= 0.5 + |pair[1]|."""
    t_hi = np.asarray(t_hi, dtype=np.float64)
    t_lo = np.asarray(t_lo, dtype=np.float64)
    t_hi, t_lo = np.broadcast_arrays(t_hi, t_lo)
    day = float(DAY_S)
    q_hi = t_hi / day
    p, pe = np_two_prod(q_hi, day)  # p + pe == q_hi * 86400 exactly
    rem = ((t_hi - p) - pe) + t_lo  # t_hi - p is exact (Sterbenz)
    q_lo = rem / day
    s, se = np_two_sum(np.float64(pair[1]), q_hi)
    n = np.floor(s + 0.5)  # whole days, moved into jd1
    jd2 = (s - n) + (se + q_lo)  # s - n is exact (|s - n| <= 0.5)
    jd1 = np.float64(pair[0]) + n  # exact: (half-)integers far below 2**52
    return np.asarray(jd1, dtype=np.float64), np.asarray(jd2, dtype=np.float64)


def tdb_after(epoch: Epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two-part TDB Julian date of the instant ``t = t_hi + t_lo`` seconds of TDB after ``epoch``'s TDB.

    The heliocentric time axis of tqdyn (t is TDB, the coordinate time of
    the TDB-compatible BCRS, the JPL ephemerides' own argument).  Returns
    (jd1, jd2) [d] as :func:`tt_jd` (same error-free construction, 2.4 ps).
    """
    return _after(epoch.tdb, t_hi, t_lo)


def tt_jd(epoch: Epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two-part TT Julian date of the instant ``t = t_hi + t_lo`` seconds of TT after ``epoch``.

    The geocentric time axis of tqdyn: t is TT (the coordinate time of the
    TT-compatible GCRS) counted from the epoch's TT.  Returns (jd1, jd2) [d],
    float64 arrays of the broadcast shape of t_hi and t_lo: jd1 the epoch's
    jd1 plus whole days (exact), jd2 within about half a day, formed with
    error-free transformations, so the only error is the final rounding of
    jd2: <= 2.8e-17 d = 2.4 ps whatever the span.
    """
    return _after(epoch.tt, t_hi, t_lo)


#: Step [h] of the tabulated TDB - TT (its shortest periods, lunar terms of
#: ~14 d, are interpolated by the 8-point Lagrange polynomial to < 1e-18 s).
_DTDB_STEP_H = 1.0
_J2000_TT = 2451545.0


def tdb_minus_tt(jd1, jd2) -> np.ndarray:
    """TDB - TT [s] at the geocentre at TT instants (jd1, jd2) (any shape).

    ``erfa.dtdb`` (Fairhead & Bretagnon 1990, the series of SOFA/ERFA;
    geocentric: the topocentric terms vanish) evaluated on an hourly grid of
    TT and interpolated (:func:`tqdyn.numerics.lagrange.grid_interp`; error
    < 1e-18 s against ``erfa.dtdb`` at every instant, which is much slower).  ERFA's date argument is TDB; evaluating it at TT (< 2 ms off)
    changes the result by < 1e-15 s.
    """
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    jd1, jd2 = np.broadcast_arrays(jd1, jd2)
    shape = jd1.shape
    if jd1.size == 0:
        return np.zeros(shape)
    u = (((jd1 - _J2000_TT) + jd2) * (24.0 / _DTDB_STEP_H)).ravel()
    k0 = int(math.floor(u.min())) - MARGIN
    k1 = int(math.floor(u.max())) + MARGIN + 1
    k = np.arange(k0, k1, dtype=np.int64)
    hours = k * _DTDB_STEP_H
    node1 = _J2000_TT + np.floor(hours / 24.0)
    node2 = (hours - 24.0 * np.floor(hours / 24.0)) / 24.0
    vals = np.asarray(erfa.dtdb(node1, node2, 0.0, 0.0, 0.0, 0.0), dtype=np.float64)[:, None]
    out = np.empty((u.size, 1))
    grid_interp(u, k0, vals, out)
    return out[:, 0].reshape(shape)


def tdb_jd(epoch: Epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two-part TDB Julian date of the instant ``t = t_hi + t_lo`` seconds of TT after ``epoch``.

    The argument of the JPL ephemerides for the geocentric time axis: the
    TT instant :func:`tt_jd` plus (TDB - TT) at the geocentre
    (:func:`tdb_minus_tt`).  Returns (jd1, jd2) [d] of the broadcast shape
    of t_hi and t_lo (jd1 as :func:`tt_jd`'s; resolution 2.4 ps).  Against
    pyerfa's ``tttdb(tt1, tt2, dtdb(tt1, tt2, ...))`` at every instant:
    < 1e-12 s (tests/test_timescales.py).
    """
    jd1, jd2 = tt_jd(epoch, t_hi, t_lo)
    return jd1, jd2 + tdb_minus_tt(jd1, jd2) / float(DAY_S)


# --------------------------------------------------------------------------- TCB and the geocentre's TDB grid

def _tcb_per_tdb() -> tuple[float, float]:
    with localcontext() as ctx:
        ctx.prec = 40
        k = 1 / (1 - Decimal(repr(L_B)))  # L_B = 1.550519768e-8 exactly (IAU 2006 Resolution B3)
        hi = float(k)
        return hi, float(k - Decimal(hi))


#: S = dTCB / dTDB = 1 / (1 - L_B) as a dd pair (hi, lo) [1] (IAU 2006 Resolution B3: TDB = TCB - L_B (JD_TCB -
#: T0) 86400 s + TDB0 is linear in TCB, so TCB intervals are S times TDB intervals, and TCB-compatible lengths
#: and GMs S times the TDB-compatible ones; velocities are the same in both).
TCB_PER_TDB = _tcb_per_tdb()
#: S rounded to float64 (= 1 + L_B / (1 - L_B) to the last bit).
TCB_SCALE = TCB_PER_TDB[0]
#: S - 1 = L_B / (1 - L_B) [1], correctly rounded (for the small TCB - TDB terms).
TCB_SCALE_MINUS_1 = (TCB_PER_TDB[0] - 1.0) + TCB_PER_TDB[1]

#: Origins of a TCB time axis (:func:`tcb_origin_offset`).
TCB_ORIGINS = ("epoch", "j2000", "unix")
_UNIX_EPOCH_JD = 2440587.5  # 1970-01-01T00:00:00 UTC (ERFA quasi-JD)


def tdb_to_tcb(hi, lo) -> tuple[np.ndarray, np.ndarray]:
    """TDB-compatible -> TCB-compatible: S (hi + lo) = (hi + lo) + (S - 1)(hi + lo) as a dd pair.

    hi, lo: float64 arrays (any shape) of a dd TDB interval [s since an
    instant, e.g. the epoch's TDB] or a TDB-compatible length [m] (light
    travel time, BCRS coordinate).  Returns the TCB seconds since the same
    instant's TCB, or the TCB-compatible length, (hi, lo) of the same shape.
    The correction (S - 1)(hi + lo) ~ 1.55e-8 (hi + lo) is formed in float64,
    so the result holds ~3e-24 of |hi + lo| (1e-15 s on 10 years, 5e-13 m at
    1.5e11 m; tests/test_timescales.py).
    """
    hi = np.asarray(hi, np.float64)
    d = (hi + np.asarray(lo, np.float64)) * TCB_SCALE_MINUS_1
    s, e = np_two_sum(hi, d)
    return np_fast_two_sum(s, e + lo)


def tcb_jd_of_epoch(epoch: Epoch) -> tuple[float, float]:
    """Two-part TCB Julian date [d] of ``epoch`` (``erfa.tdbtcb`` of its TDB: IAU 2006 B3)."""
    c1, c2 = erfa.tdbtcb(*epoch.tdb)
    return float(c1), float(c2)


def unix_of_tcb(jd1: float, jd2: float) -> float:
    """Unix time [s] of a TCB instant (two-part JD), as astropy's ``Time(..., scale="tcb").unix``: TCB -> TDB
    (IAU 2006 B3) -> TT (erfa.dtdb at the geocentre) -> TAI -> UTC, then (JD_UTC - 2440587.5) * 86400 (ERFA's
    quasi-JD: 86400 s a day; leap seconds are not counted)."""
    b1, b2 = erfa.tcbtdb(jd1, jd2)
    dtr = erfa.dtdb(b1, b2, 0.0, 0.0, 0.0, 0.0)
    t1, t2 = erfa.tdbtt(b1, b2, dtr)
    a1, a2 = erfa.tttai(t1, t2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        u1, u2 = erfa.taiutc(a1, a2)
    return float(((u1 - _UNIX_EPOCH_JD) + u2) * DAY_S)


def tcb_origin_offset(origin: str, epoch: Epoch, t_first: float) -> float:
    """Seconds [s] to add to "TCB seconds since ``epoch``'s TCB instant" to count from ``origin``.

    ``"epoch"``: 0; ``"j2000"``: the TCB seconds from J2000.0 TCB (JD
    2451545.0 TCB) to the epoch's TCB; ``"unix"``: such that the instant
    ``t_first`` [s TCB since the epoch's TCB] gets its Unix time
    (:func:`unix_of_tcb`), the following ones TCB seconds after it.
    """
    if origin not in TCB_ORIGINS:
        raise ValueError(f"time origin {origin!r} is not allowed{did_you_mean(origin, TCB_ORIGINS)}; "
                         f"allowed: {allowed(TCB_ORIGINS)}")
    if origin == "epoch":
        return 0.0
    c1, c2 = tcb_jd_of_epoch(epoch)
    if origin == "j2000":
        return float((c1 - J2000_JD) * DAY_S + c2 * DAY_S)
    return unix_of_tcb(c1, c2 + t_first / DAY_S) - t_first


_DIFF_S = 300.0  # s: half-step of the central differences of TDB - TT


def geocentre_tdb_grid(epoch: Epoch, t) -> tuple[tuple, tuple, np.ndarray]:
    """The uniform TDB grid spanning a geocentric TT grid, and the geocentre's TT on it.

    t: dd (hi, lo) (N,), N >= 2: TT seconds since ``epoch`` (the
    geocentric time axis).  The grid t_k (TDB seconds since the epoch's
    TDB) runs from TDB(T_0) to TDB(T_{N-1}) in N - 1 equal steps, formed
    in dd as t_0 + k (t_{N-1} - t_0)/(N - 1); the geocentre's event at t_k
    has the TT instant T_k = t_k - (TDB - TT)(T_k) (:func:`tdb_minus_tt`
    relative to the epoch's; fixed point, 3 iterations, held inside [T_0,
    T_{N-1}] against the last rounding), and dT/dt = 1 / (1 + d(TDB -
    TT)/dT) (central differences over +-300 s; |dT/dt - 1| < 4e-10).

    Returns (t_k dd, T_k dd, dT/dt - 1): two (hi, lo) pairs and an array,
    each (N,), [s, s TT since the epoch, 1].
    """
    th, tl = (np.asarray(p, np.float64) for p in t)
    N = th.size
    d0 = float(tdb_minus_tt(*epoch.tt))

    def dtdb(hi, lo):  # (TDB - TT)(T) - (TDB - TT)(epoch) [s]
        return np.asarray(tdb_minus_tt(*tt_jd(epoch, hi, lo)), np.float64) - d0

    b0 = np_dd_add_d(th[0], tl[0], float(dtdb(th[0], tl[0])))
    b1 = np_dd_add_d(th[-1], tl[-1], float(dtdb(th[-1], tl[-1])))
    span = (b1[0] - b0[0]) + (b1[1] - b0[1])
    kdt_h, kdt_l = np_two_prod(np.arange(N, dtype=np.float64), span / (N - 1))
    bh, bl = np_two_sum(np.full(N, b0[0]), kdt_h)
    bh, bl = np_fast_two_sum(bh, bl + (kdt_l + b0[1]))
    Th, Tl = np_dd_add_d(bh, bl, -dtdb(th, tl))
    for _ in range(3):
        Th, Tl = np_dd_add_d(bh, bl, -dtdb(Th, Tl))
    lo_t, hi_t = th[0] + tl[0], th[-1] + tl[-1]  # rounding at the ends must not leave the grid
    Tl = np.where(Th + Tl < lo_t, lo_t - Th, np.where(Th + Tl > hi_t, hi_t - Th, Tl))
    ddt = (dtdb(Th + _DIFF_S, Tl) - dtdb(Th - _DIFF_S, Tl)) / (2 * _DIFF_S)
    return (bh, bl), (Th, Tl), -ddt / (1.0 + ddt)


def tcb_to_tdb(jd1, jd2) -> tuple[np.ndarray, np.ndarray]:
    """TDB (jd1, jd2) of TCB instants (jd1, jd2) [d] (IAU 2006 Resolution B3):
    TDB = TCB - L_B ((jd1 - T0) + jd2) 86400 s + TDB0; jd1 kept, the
    correction (~ -30 s in 2037) added to jd2 (error ~1e-17 d; against
    ``erfa.tcbtdb``: 4.8e-12 s, tests/test_oem.py)."""
    day = float(DAY_S)
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    corr = (-L_B * ((jd1 - TCB_T0_JD) + jd2) * day + TDB0_S) / day
    return jd1.copy(), jd2 + corr
