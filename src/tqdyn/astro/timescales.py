"""Time scales for tqdyn: UTC -> TAI -> TT -> TDB at the geocenter (pyerfa/SOFA).

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
* Durations are SI seconds of TDB after the scenario epoch; tqdyn's dynamics
  is geocentric (GCRS position, ICRF axes) and uses TDB as its time argument.

Leap seconds: ERFA's table is used as shipped with pyerfa.  For dates after
the last tabulated leap second (2017-01-01, TAI-UTC = 37 s) ERFA holds
TAI-UTC at its last value and flags the year as "dubious"; tqdyn accepts that
(no further leap second has been announced; the CGPM decided in 2022 to
abolish them by 2035) and suppresses ERFA's "dubious year" warning.  Dates
before 1960-01-01, where UTC is not defined, are rejected.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import erfa
import numpy as np

from .constants import DAY_S
from ..numerics.dd import np_two_prod, np_two_sum

__all__ = ["Epoch", "UTCFields", "parse_utc", "tdb_jd"]

_ISO_FORMAT = "YYYY-MM-DDTHH:MM:SS[.fff] (UTC; 'T' or a space between date and time; optional trailing 'Z')"

_ISO_RE = re.compile(
    r"^\s*(?P<y>\d{4})-(?P<mo>\d{2})-(?P<d>\d{2})"
    r"(?:[T ](?P<h>\d{2}):(?P<mi>\d{2})(?::(?P<s>\d{2})(?P<frac>\.\d+)?)?)?"
    r"\s*Z?\s*$"
)

_FIRST_UTC_YEAR = 1960  # UTC (and erfa.dat) start on 1960-01-01


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


def _bad(iso: object, why: str) -> ValueError:
    exc = ValueError(f"UTC epoch {iso!r}: {why}; expected format {_ISO_FORMAT}")
    exc.reason = why  # short reason, for callers that format their own message
    return exc


def _erfa_reason(msg: str) -> str:
    m = re.search(r'ERFA function "(\w+)" yielded \d+ of "([^"]*)"', msg)
    return f"{m[2]} (erfa.{m[1]})" if m else msg


def parse_utc(iso: str) -> UTCFields:
    """Parse an ISO 8601 UTC date-time string (calendar form, no time zone).

    Accepts ``YYYY-MM-DDTHH:MM:SS[.fff]``, ``YYYY-MM-DD HH:MM[:SS[.fff]]``,
    ``YYYY-MM-DD`` (midnight) and an optional trailing ``Z``.  Years before
    1960 are rejected (UTC undefined).  Calendar validity (month, day, hour,
    minute, second <= 60.999... only on a leap-second day) is checked by
    ``erfa.dtf2d``.

    Returns a :class:`UTCFields` (time scale UTC); raises ``ValueError``
    naming the string and the expected format.
    """
    if not isinstance(iso, str):
        raise _bad(iso, f"must be a string, got {type(iso).__name__}")
    m = _ISO_RE.match(iso)
    if m is None:
        raise _bad(iso, "not an ISO 8601 calendar date-time")
    y, mo, d = int(m["y"]), int(m["mo"]), int(m["d"])
    h = int(m["h"] or 0)
    mi = int(m["mi"] or 0)
    s_int = m["s"] or "00"
    frac = m["frac"] or ""
    sec = float(s_int + frac)
    if y < _FIRST_UTC_YEAR:
        raise _bad(iso, f"year {y} is before {_FIRST_UTC_YEAR}, where UTC is not defined")
    norm = f"{y:04d}-{mo:02d}-{d:02d}T{h:02d}:{mi:02d}:{s_int}{frac}"
    fields = UTCFields(y, mo, d, h, mi, sec, norm)
    _utc_jd(fields, iso)  # calendar validation
    return fields


def _erfa_quiet(func, *args, iso: object):
    """Call an erfa routine; drop 'dubious year' warnings, turn others into ValueError."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", erfa.ErfaWarning)
        try:
            out = func(*args)
        except erfa.ErfaError as exc:
            raise _bad(iso, _erfa_reason(str(exc))) from None
    for w in caught:
        msg = str(w.message)
        if issubclass(w.category, erfa.ErfaWarning) and "dubious year" in msg:
            continue
        if issubclass(w.category, erfa.ErfaWarning):
            raise _bad(iso, _erfa_reason(msg))
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
        as_pair = lambda p: (float(p[0]), float(p[1]))  # noqa: E731
        return cls(f.iso, as_pair(utc), as_pair(tai), as_pair(tt), as_pair(tdb))


def tdb_jd(epoch: Epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two-part TDB Julian date of ``t = t_hi + t_lo`` seconds of TDB after ``epoch``.

    Parameters
    ----------
    epoch : Epoch
        Reference instant (its ``tdb`` pair is used).
    t_hi, t_lo : float or array_like
        Elapsed TDB time in s as a double-double (``t_lo`` may be 0); arrays
        broadcast against each other.

    Returns
    -------
    jd1, jd2 : np.ndarray (float64, broadcast shape of t_hi and t_lo)
        ``jd1 = epoch.tdb[0]`` exactly; ``jd2 = epoch.tdb[1] + (t_hi + t_lo)/86400``
        in days, formed with error-free transformations (no large float such
        as the full JD is ever formed) so that the only error is the final
        rounding of ``jd2``: at most half an ulp of ``jd2``.

    Resolution: ulp(jd2) * 86400 s, i.e. 19 ps for |jd2| < 2 d, 1.2 ns near
    90 d (|jd2| in [64, 128) d: ulp = 2**-46 d), 4.9 ns near one year and 20 ns
    at 5 years.  This is for ephemeris/time-scale arguments only; tqdyn's
    integrators carry t itself in double-double.
    """
    t_hi = np.asarray(t_hi, dtype=np.float64)
    t_lo = np.asarray(t_lo, dtype=np.float64)
    t_hi, t_lo = np.broadcast_arrays(t_hi, t_lo)
    day = float(DAY_S)
    q_hi = t_hi / day
    p, pe = np_two_prod(q_hi, day)  # p + pe == q_hi * 86400 exactly
    rem = ((t_hi - p) - pe) + t_lo  # t_hi - p is exact (Sterbenz)
    q_lo = rem / day
    s, se = np_two_sum(np.float64(epoch.tdb[1]), q_hi)
    jd2 = s + (se + q_lo)
    jd1 = np.full(jd2.shape, epoch.tdb[0], dtype=np.float64)
    return jd1, np.asarray(jd2, dtype=np.float64)
