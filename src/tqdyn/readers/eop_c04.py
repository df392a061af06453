"""Reader of the IERS EOP (14 or 20) C04 daily series into an
:class:`tqdyn.astro.eop.EOP` table (the interpolation lives there).

Shipped: ``data/eopc04_14_IAU2000.62-now.txt`` (IERS EOP 14 C04,
1962-01-01 .. 2024-09-03; see ``data/SOURCES.md``).  Angles are converted
from arcsec to rad, times stay in s, MJD in days of UTC.
"""

from __future__ import annotations

import functools
import importlib.resources
import os
import re

import erfa
import numpy as np

from ..astro.eop import _MJD_JD0, ARCSEC, EOP

__all__ = ["load_eop", "parse_eop_c04"]

_EOP_FILE = "eopc04_14_IAU2000.62-now.txt"

_C04_ROW = re.compile(r"^\s*(\d{4})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{5})\s")


def parse_eop_c04(text: str, source: str = "text") -> EOP:
    """Parse the text of an IERS EOP (14 or 20) C04 file into an :class:`~tqdyn.astro.eop.EOP`.

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
    bad = np.nonzero(jd1 + jd2 - _MJD_JD0 != a[:, 3])[0]
    if bad.size:
        r = rows[bad[0]]
        raise ValueError(f"{source}: row {r[:4]}: MJD does not match the calendar date")
    return EOP(mjd=a[:, 3], xp=a[:, 4] * ARCSEC, yp=a[:, 5] * ARCSEC, dut1=a[:, 6], lod=a[:, 7],
               dx=a[:, 8] * ARCSEC, dy=a[:, 9] * ARCSEC, source=source)


@functools.lru_cache(maxsize=1)
def _default_eop() -> EOP:
    res = importlib.resources.files("tqdyn") / "data" / _EOP_FILE
    return parse_eop_c04(res.read_text(encoding="ascii"), source=f"tqdyn/data/{_EOP_FILE} (IERS EOP 14 C04)")


def load_eop(path=None) -> EOP:
    """Read an IERS C04 EOP file into an :class:`~tqdyn.astro.eop.EOP` (x, y, dX, dY in rad; s).

    ``path=None``: the shipped IERS EOP 14 C04 series
    (``tqdyn/data/eopc04_14_IAU2000.62-now.txt``, 1962-01-01 .. 2024-09-03),
    parsed once and cached.  Otherwise a path to a file of the same format.
    Raises ``FileNotFoundError`` for a missing file and ``ValueError`` for a
    malformed one.
    """
    if path is None:
        return _default_eop()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise FileNotFoundError(f"EOP file not found: {p}")
    with open(p, encoding="ascii", errors="replace") as fh:
        return parse_eop_c04(fh.read(), source=p)
