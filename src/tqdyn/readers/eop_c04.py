"""Reader of the IERS EOP (14 or 20) C04 daily series: the file's columns
in SI as an :class:`EopSeries` (the interpolation, and the :class:`tqdyn.astro.eop.EOP`
table built from a series, live in :mod:`tqdyn.astro.eop`).

Shipped: ``data/eopc04_14_IAU2000.62-now.txt`` (IERS EOP 14 C04,
1962-01-01 .. 2024-09-03; see ``data/SOURCES.md``).  Angles are converted
from arcsec to rad, times stay in s, MJD in days of UTC.
"""

from __future__ import annotations

import functools
import importlib.resources
import os
import re
from dataclasses import dataclass

import erfa
import numpy as np

from ..astro.constants import ARCSEC_RAD, MJD_JD0

__all__ = ["EopSeries", "parse_eop_c04", "read_eop_c04"]

_EOP_FILE = "eopc04_14_IAU2000.62-now.txt"

_C04_ROW = re.compile(r"^\s*(\d{4})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{5})\s")


@dataclass(frozen=True, eq=False)
class EopSeries:
    """Daily Earth orientation parameters as a file gives them, in SI.

    mjd : MJD of the node [d, UTC]; xp, yp : polar motion [rad]; dut1 :
    UT1-UTC [s]; lod : excess length of day [s]; dx, dy : celestial pole
    offsets dX, dY w.r.t. IAU 2006/2000A [rad] (1-D float64 arrays of one
    length); source : where the series came from.
    """

    mjd: np.ndarray
    xp: np.ndarray
    yp: np.ndarray
    dut1: np.ndarray
    lod: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    source: str


def parse_eop_c04(text: str, source: str = "text") -> EopSeries:
    """Parse the text of an IERS EOP (14 or 20) C04 file into an :class:`EopSeries`.

    Data rows are ``Y M D MJD x y UT1-UTC LOD dX dY`` followed by their
    errors (x, y, dX, dY in arcsec; UT1-UTC, LOD in s); header lines are
    skipped.  Each row's MJD is checked against its calendar date.
    Angles are converted to rad.  Raises ``ValueError`` for a file without
    data rows, a malformed row, or non-consecutive days.
    """
    rows = []
    for lineno, line in enumerate(text.splitlines(), 1):
        m = _C04_ROW.match(line)
        if m is None:
            continue
        tok = line.split()
        if len(tok) < 10:
            raise ValueError(f"{source}:{lineno}: EOP C04 row has {len(tok)} fields, expected >= 10")
        try:
            y, mo, d, mjd = (int(t) for t in tok[:4])
            vals = [float(t) for t in tok[4:10]]
        except ValueError:
            raise ValueError(f"{source}:{lineno}: cannot parse EOP C04 row {line.strip()!r}") from None
        rows.append((y, mo, d, mjd, *vals))
    if not rows:
        raise ValueError(f"{source}: no EOP C04 data rows found")
    a = np.array(rows, dtype=np.float64)
    jd1, jd2 = erfa.cal2jd(a[:, 0].astype(int), a[:, 1].astype(int), a[:, 2].astype(int))
    bad = np.nonzero(jd1 + jd2 - MJD_JD0 != a[:, 3])[0]
    if bad.size:
        r = rows[bad[0]]
        raise ValueError(f"{source}: row {r[:4]}: MJD does not match the calendar date")
    return EopSeries(mjd=a[:, 3], xp=a[:, 4] * ARCSEC_RAD, yp=a[:, 5] * ARCSEC_RAD, dut1=a[:, 6], lod=a[:, 7],
                     dx=a[:, 8] * ARCSEC_RAD, dy=a[:, 9] * ARCSEC_RAD, source=source)


@functools.lru_cache(maxsize=1)
def _shipped() -> EopSeries:
    res = importlib.resources.files("tqdyn") / "data" / _EOP_FILE
    return parse_eop_c04(res.read_text(encoding="ascii"), source=f"tqdyn/data/{_EOP_FILE} (IERS EOP 14 C04)")


def read_eop_c04(path=None) -> EopSeries:
    """Read an IERS C04 EOP file into an :class:`EopSeries` (x, y, dX, dY in rad; s).

    ``path=None``: the shipped IERS EOP 14 C04 series
    (``tqdyn/data/eopc04_14_IAU2000.62-now.txt``, 1962-01-01 .. 2024-09-03),
    parsed once and cached.  Otherwise a path to a file of the same format.
    Raises ``FileNotFoundError`` for a missing file and ``ValueError`` for a
    malformed one.
    """
    if path is None:
        return _shipped()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise FileNotFoundError(f"EOP file not found: {p}")
    with open(p, encoding="ascii", errors="replace") as fh:
        return parse_eop_c04(fh.read(), source=p)
