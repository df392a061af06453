"""Reader of the IERS Rapid Service / Prediction Center ``finals2000A``
file (Bulletin A measured values and predictions, IAU 2000A dX, dY): the
file's Bulletin A columns in SI as an :class:`~tqdyn.readers.eop_c04.EopSeries`
with a per-row ``predicted`` flag.

File read: ``astropy_iers_data/data/finals2000A.all`` (PyPI
``astropy-iers-data``, released weekly; ``ReadMe.finals2000A`` beside it
describes the columns).  Fixed-width columns (1-based bytes)::

     1-  6  year (2 digits), month, day       8- 15  MJD (UTC)
        17  polar-motion flag I / P          19- 27  x [arcsec]   38- 46  y [arcsec]
        58  UT1-UTC flag I / P               59- 68  UT1-UTC [s]
     80- 86 LOD [ms] (not always filled)        96  nutation flag I / P
     98-106 dX [mas]                        117-125  dY [mas]

"I" = IERS (measured, Bulletin A rapid solution), "P" = prediction.  A row
is *predicted* if its polar motion or its UT1-UTC is flagged "P" (the
nutation flag alone is "P" for the first years of the file and for the
last few measured days; dX, dY are < 1 mas).  The rows after the last
prediction hold only a date and are not read.  Where LOD is blank
(predictions) it is derived from the UT1-TAI of the neighbouring days
(central differences; one-sided at the ends): LOD = -d(UT1-TAI)/dt [s per
day]; where dX, dY are blank (predictions beyond ~3 months) they are 0.
The Bulletin B columns (135-185) are not used.
"""

from __future__ import annotations

import functools
import os
import warnings

import erfa
import numpy as np

from ..astro.constants import ARCSEC_RAD, MJD_JD0
from .eop_c04 import IERS_DATA_PACKAGE, EopSeries, iers_data_file, iers_data_version

__all__ = ["parse_finals2000a", "read_finals2000a"]

_FINALS_FILE = "finals2000A.all"
_MAS_RAD = ARCSEC_RAD * 1e-3


def _field(line: str, a: int, b: int) -> str:
    """Bytes a..b (1-based, inclusive) of a fixed-width row, stripped."""
    return line[a - 1:b].strip()


def parse_finals2000a(text: str, source: str = "text") -> EopSeries:
    """Parse the text of an IERS ``finals2000A`` file (``.all``, ``.data`` or
    ``.daily``) into an :class:`~tqdyn.readers.eop_c04.EopSeries` (x, y, dX,
    dY in rad; UT1-UTC, LOD in s; MJD in UTC) with ``predicted`` flags.

    Reads every row with a polar motion and a UT1-UTC value; stops at the
    first row without them (the date-only rows at the end).  Checks each
    row's MJD against its (two-digit-year) date and that the days are
    consecutive.  Raises ``ValueError`` naming the source and line.
    """
    mjd, xp, yp, dut1, lod, dx, dy, pred = [], [], [], [], [], [], [], []
    dates = []
    for lineno, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        if len(line) < 68 or not _field(line, 19, 27) or not _field(line, 59, 68):
            if mjd:
                break  # date-only rows after the predictions
            raise ValueError(f"{source}:{lineno}: finals2000A row without polar motion / UT1-UTC")
        try:
            m = float(_field(line, 8, 15))
            yy, mo, d = int(line[0:2]), int(line[2:4]), int(line[4:6])
            x, y = float(_field(line, 19, 27)), float(_field(line, 38, 46))
            u = float(_field(line, 59, 68))
            lod_ms = _field(line, 80, 86)
            sx, sy = _field(line, 98, 106), _field(line, 117, 125)
            flags = (_field(line, 17, 17), _field(line, 58, 58))
        except ValueError:
            raise ValueError(f"{source}:{lineno}: cannot parse finals2000A row {line.rstrip()!r}") from None
        if any(f not in ("I", "P") for f in flags):
            raise ValueError(f"{source}:{lineno}: finals2000A flags {flags!r}; expected 'I' or 'P'")
        mjd.append(m)
        dates.append(((1900 if m <= 51543 else 2000) + yy, mo, d))
        xp.append(x)
        yp.append(y)
        dut1.append(u)
        lod.append(float(lod_ms) * 1e-3 if lod_ms else np.nan)
        dx.append(float(sx) if sx else 0.0)
        dy.append(float(sy) if sy else 0.0)
        pred.append("P" in flags)
    if not mjd:
        raise ValueError(f"{source}: no finals2000A data rows found")
    mjd_a = np.array(mjd)
    dd = np.array(dates)
    jd1, jd2 = erfa.cal2jd(dd[:, 0], dd[:, 1], dd[:, 2])
    bad = np.nonzero(jd1 + jd2 - MJD_JD0 != mjd_a)[0]
    if bad.size:
        raise ValueError(f"{source}: row of MJD {mjd_a[bad[0]]:.2f}: MJD does not match the date {tuple(dd[bad[0]])}")
    if np.any(np.diff(mjd_a) != 1.0):
        i = int(np.nonzero(np.diff(mjd_a) != 1.0)[0][0])
        raise ValueError(f"{source}: days not consecutive after MJD {mjd_a[i]:.2f}")
    dut1_a = np.array(dut1)
    lod_a = np.array(lod)
    if np.any(np.isnan(lod_a)):
        # LOD = -d(UT1-TAI)/dt from the series itself (TAI-UTC of each day from ERFA)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", category=erfa.ErfaWarning)
            dat = np.asarray(erfa.dat(dd[:, 0], dd[:, 1], dd[:, 2], 0.0), dtype=np.float64)
        ut1_tai = dut1_a - dat
        slope = np.gradient(ut1_tai) if ut1_tai.size > 1 else np.zeros(1)
        lod_a = np.where(np.isnan(lod_a), -slope, lod_a)
    return EopSeries(mjd=mjd_a, xp=np.array(xp) * ARCSEC_RAD, yp=np.array(yp) * ARCSEC_RAD, dut1=dut1_a,
                     lod=lod_a, dx=np.array(dx) * _MAS_RAD, dy=np.array(dy) * _MAS_RAD, source=source,
                     predicted=np.array(pred, dtype=bool))


@functools.lru_cache(maxsize=1)
def _package_finals() -> EopSeries:
    res = iers_data_file(_FINALS_FILE)
    return parse_finals2000a(res.read_text(encoding="ascii", errors="replace"),
                             source=f"{IERS_DATA_PACKAGE}/data/{_FINALS_FILE} (IERS finals2000A, Bulletin A, "
                                    f"astropy-iers-data {iers_data_version()})")


def read_finals2000a(path=None) -> EopSeries:
    """Read a ``finals2000A`` file into an :class:`~tqdyn.readers.eop_c04.EopSeries` with ``predicted`` flags.

    ``path=None``: the ``finals2000A.all`` of the installed ``astropy-iers-data``
    package (measured values from 1973 and Bulletin A predictions about a
    year ahead of its release), parsed once and cached.  Otherwise a path.
    Raises ``FileNotFoundError`` / ``ValueError``.
    """
    if path is None:
        return _package_finals()
    p = os.fspath(path)
    if not os.path.isfile(p):
        raise FileNotFoundError(f"finals2000A file not found: {p}")
    with open(p, encoding="ascii", errors="replace") as fh:
        return parse_finals2000a(fh.read(), source=p)
