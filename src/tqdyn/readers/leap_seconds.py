"""Reader of the IERS leap-second file ``Leap_Second.dat`` (IERS Bulletin C):
the dates at which TAI-UTC changed since 1972 and the file's expiry date.

File read: ``astropy_iers_data/data/Leap_Second.dat`` (PyPI
``astropy-iers-data``, released weekly).  Rows ``MJD day month year
TAI-UTC`` after a ``#`` header that says until when the table is valid
("File expires on 28 June 2027").  The table is installed into ERFA by
:func:`tqdyn.astro.timescales.install_leap_seconds`.
"""

from __future__ import annotations

import datetime as _dt
import functools
import os
import re
from typing import NamedTuple

import numpy as np

from .eop_c04 import IERS_DATA_PACKAGE, iers_data_file, iers_data_version

__all__ = ["LeapSeconds", "parse_leap_seconds", "read_leap_seconds"]

_LEAP_FILE = "Leap_Second.dat"
_EXPIRES = re.compile(r"File expires on\s+(\d{1,2})\s+([A-Za-z]+)\s+(\d{4})")
_ROW = re.compile(r"^\s*(\d{5})(?:\.\d*)?\s+(\d{1,2})\s+(\d{1,2})\s+(\d{4})\s+(\d+(?:\.\d*)?)\s*$")


class LeapSeconds(NamedTuple):
    """A leap-second table.

    mjd : (n,) float64 -- MJD (UTC) of 0 h of the day from which TAI-UTC holds;
    year, month : (n,) int64 -- that date (day 1 of January or July);
    tai_utc : (n,) float64 -- TAI-UTC [s] from that date on;
    expires : ``datetime.date`` or None -- the date until which the file
    guarantees that no further leap second is introduced; source : text.
    """

    mjd: np.ndarray
    year: np.ndarray
    month: np.ndarray
    tai_utc: np.ndarray
    expires: _dt.date | None
    source: str


def parse_leap_seconds(text: str, source: str = "text") -> LeapSeconds:
    """Parse the text of an IERS ``Leap_Second.dat`` file.

    Checks that every change is on the 1st of January or July, that TAI-UTC
    rises by 1 s at each row and that the MJDs increase.  Raises
    ``ValueError`` naming the source and line.
    """
    rows = []
    expires = None
    for lineno, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("#"):
            m = _EXPIRES.search(line)
            if m:
                try:
                    expires = _dt.datetime.strptime(f"{m[1]} {m[2]} {m[3]}", "%d %B %Y").date()
                except ValueError:
                    raise ValueError(f"{source}:{lineno}: cannot read the expiry date {m[0]!r}") from None
            continue
        if not line.strip():
            continue
        m = _ROW.match(line)
        if m is None:
            raise ValueError(f"{source}:{lineno}: cannot parse leap-second row {line.strip()!r}")
        mjd, day, month, year, dat = int(m[1]), int(m[2]), int(m[3]), int(m[4]), float(m[5])
        if day != 1 or month not in (1, 7):
            raise ValueError(f"{source}:{lineno}: leap second on {year}-{month:02d}-{day:02d}; "
                             f"expected the 1st of January or July")
        rows.append((mjd, year, month, dat))
    if not rows:
        raise ValueError(f"{source}: no leap-second rows found")
    a = np.array(rows, dtype=np.float64)
    if np.any(np.diff(a[:, 0]) <= 0) or np.any(np.diff(a[:, 3]) != 1.0):
        raise ValueError(f"{source}: leap-second rows must increase in date and by 1 s in TAI-UTC")
    return LeapSeconds(mjd=a[:, 0], year=a[:, 1].astype(np.int64), month=a[:, 2].astype(np.int64),
                       tai_utc=a[:, 3], expires=expires, source=source)


@functools.lru_cache(maxsize=1)
def _package_table() -> LeapSeconds:
    res = iers_data_file(_LEAP_FILE)
    return parse_leap_seconds(res.read_text(encoding="ascii", errors="replace"),
                              source=f"{IERS_DATA_PACKAGE}/data/{_LEAP_FILE} "
                                     f"(astropy-iers-data {iers_data_version()})")


def read_leap_seconds(path=None) -> LeapSeconds:
    """The leap-second table of ``path``, or (``None``) the ``Leap_Second.dat``
    of the installed ``astropy-iers-data`` package (parsed once, cached).
    Raises ``FileNotFoundError`` / ``ValueError``."""
    if path is None:
        return _package_table()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise FileNotFoundError(f"leap-second file not found: {p}")
    with open(p, encoding="ascii", errors="replace") as fh:
        return parse_leap_seconds(fh.read(), source=p)
