"""Reader of the IERS EOP C04 daily series, in both layouts (14 C04 and 20
C04): the file's columns in SI as an :class:`EopSeries` (the interpolation,
and the :class:`tqdyn.astro.eop.EOP` table built from a series, live in
:mod:`tqdyn.astro.eop`; the combination of sources in
:mod:`tqdyn.astro.eop_sources`).

Files read
----------
* ``tqdyn/data/eopc04_14_IAU2000.62-now.txt`` (shipped, frozen): IERS EOP 14
  C04, 1962-01-01 .. 2024-09-03 (``data/SOURCES.md``), rows
  ``Y M D MJD x y UT1-UTC LOD dX dY`` + errors.
* ``astropy_iers_data/data/eopc04.1962-now`` (PyPI ``astropy-iers-data``,
  released weekly; a runtime dependency): IERS EOP 20 C04 (consistent with
  ITRF 2020), rows ``Y M D HH MJD x y UT1-UTC dX dY xrt yrt LOD`` + errors
  (``ReadMe.eopc04`` beside it).  Located with :mod:`importlib.resources`;
  nothing is downloaded.

Angles are converted from arcsec to rad, times stay in s, MJD in days of UTC.
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

__all__ = ["EopSeries", "IERS_DATA_PACKAGE", "iers_data_file", "iers_data_version", "parse_eop_c04",
           "read_eop_c04", "read_eop_c04_20"]

_EOP_FILE = "eopc04_14_IAU2000.62-now.txt"
#: The PyPI package that ships the current IERS files (EOP 20 C04, finals2000A, leap seconds).
IERS_DATA_PACKAGE = "astropy_iers_data"
_C04_20_FILE = "eopc04.1962-now"

# 14 C04: "YYYY MM DD MJD x ..." (MJD an integer); 20 C04: "YYYY MM DD HH MJD.xx x ..."
_C04_14_ROW = re.compile(r"^\s*(\d{4})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{5})\s")
_C04_20_ROW = re.compile(r"^\s*(\d{4})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{1,2})\s+(\d{5}\.\d*)\s")
# token index of x, y, UT1-UTC, LOD, dX, dY and the number of tokens needed
_COLUMNS = {"14": ((4, 5, 6, 7, 8, 9), 10), "20": ((5, 6, 7, 12, 8, 9), 13)}


@dataclass(frozen=True, eq=False)
class EopSeries:
    """Daily Earth orientation parameters as a file gives them, in SI.

    mjd : MJD of the node [d, UTC]; xp, yp : polar motion [rad]; dut1 :
    UT1-UTC [s]; lod : excess length of day [s]; dx, dy : celestial pole
    offsets dX, dY w.r.t. IAU 2006/2000A [rad] (1-D float64 arrays of one
    length); source : where the series came from; predicted : None (every
    row measured, as in the C04 series) or a bool array, True where the
    file flags the row as a prediction (finals2000A's "P" flags).
    """

    mjd: np.ndarray
    xp: np.ndarray
    yp: np.ndarray
    dut1: np.ndarray
    lod: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    source: str
    predicted: np.ndarray | None = None


def iers_data_file(name: str):
    """The file ``name`` of the ``astropy-iers-data`` package (an
    :mod:`importlib.resources` Traversable); FileNotFoundError naming the
    package if it is not installed or lacks the file."""
    try:
        res = importlib.resources.files(IERS_DATA_PACKAGE) / "data" / name
    except ModuleNotFoundError:
        raise FileNotFoundError(f"IERS data file {name}: the package astropy-iers-data is not installed "
                                f"(pip install astropy-iers-data)") from None
    if not res.is_file():
        raise FileNotFoundError(f"IERS data file not found: {IERS_DATA_PACKAGE}/data/{name}")
    return res


def iers_data_version() -> str:
    """Version of the installed ``astropy-iers-data`` package ("not installed" if absent)."""
    try:
        from importlib.metadata import version

        return version("astropy-iers-data")
    except Exception:  # noqa: BLE001 - metadata missing or package absent
        return "not installed"


def parse_eop_c04(text: str, source: str = "text") -> EopSeries:
    """Parse the text of an IERS EOP C04 file (14 C04 or 20 C04 layout) into an :class:`EopSeries`.

    14 C04 rows are ``Y M D MJD x y UT1-UTC LOD dX dY`` + errors; 20 C04 rows
    ``Y M D HH MJD x y UT1-UTC dX dY xrt yrt LOD`` + errors (HH must be 0;
    the layout is recognised from the first data row).  x, y, dX, dY in
    arcsec, UT1-UTC and LOD in s; header and comment lines are skipped.
    Each row's MJD is checked against its calendar date.  Angles are
    converted to rad.  Raises ``ValueError`` for a file without data rows, a
    malformed row, or non-consecutive days (the latter in :class:`tqdyn.astro.eop.EOP`).
    """
    rows = []
    layout = None
    for lineno, line in enumerate(text.splitlines(), 1):
        if layout != "20" and _C04_14_ROW.match(line):
            layout = layout or "14"
        elif layout != "14" and _C04_20_ROW.match(line):
            layout = layout or "20"
        else:
            continue
        cols, need = _COLUMNS[layout]
        tok = line.split()
        if len(tok) < need:
            raise ValueError(f"{source}:{lineno}: EOP C04 row has {len(tok)} fields, expected >= {need}")
        try:
            y, mo, d = (int(t) for t in tok[:3])
            mjd = float(tok[4] if layout == "20" else tok[3])
            vals = [float(tok[c]) for c in cols]
        except ValueError:
            raise ValueError(f"{source}:{lineno}: cannot parse EOP C04 row {line.strip()!r}") from None
        if layout == "20" and int(tok[3]) != 0:
            raise ValueError(f"{source}:{lineno}: EOP C04 row at {tok[3]} h UTC; expected daily rows at 0 h")
        rows.append((y, mo, d, mjd, *vals))
    if not rows:
        raise ValueError(f"{source}: no EOP C04 data rows found")
    a = np.array(rows, dtype=np.float64)
    jd1, jd2 = erfa.cal2jd(a[:, 0].astype(int), a[:, 1].astype(int), a[:, 2].astype(int))
    bad = np.nonzero(jd1 + jd2 - MJD_JD0 != a[:, 3])[0]
    if bad.size:
        r = rows[bad[0]]
        raise ValueError(f"{source}: row {tuple(int(v) for v in r[:4])}: MJD does not match the calendar date")
    # columns: x, y, UT1-UTC, LOD, dX, dY
    return EopSeries(mjd=a[:, 3], xp=a[:, 4] * ARCSEC_RAD, yp=a[:, 5] * ARCSEC_RAD, dut1=a[:, 6], lod=a[:, 7],
                     dx=a[:, 8] * ARCSEC_RAD, dy=a[:, 9] * ARCSEC_RAD, source=source)


@functools.lru_cache(maxsize=1)
def _shipped() -> EopSeries:
    res = importlib.resources.files("tqdyn") / "data" / _EOP_FILE
    return parse_eop_c04(res.read_text(encoding="ascii"), source=f"tqdyn/data/{_EOP_FILE} (IERS EOP 14 C04)")


def read_eop_c04(path=None) -> EopSeries:
    """Read an IERS C04 EOP file (14 or 20 C04 layout) into an :class:`EopSeries` (x, y, dX, dY in rad; s).

    ``path=None``: the shipped IERS EOP 14 C04 series
    (``tqdyn/data/eopc04_14_IAU2000.62-now.txt``, 1962-01-01 .. 2024-09-03),
    parsed once and cached.  Otherwise a path to a file of either layout.
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


@functools.lru_cache(maxsize=1)
def read_eop_c04_20() -> EopSeries:
    """The IERS EOP 20 C04 series of the installed ``astropy-iers-data``
    package (``eopc04.1962-now``, 1962-01-01 to about a month before the
    package's release), parsed once and cached.  FileNotFoundError if the
    package is missing."""
    res = iers_data_file(_C04_20_FILE)
    return parse_eop_c04(res.read_text(encoding="ascii", errors="replace"),
                         source=f"{IERS_DATA_PACKAGE}/data/{_C04_20_FILE} (IERS EOP 20 C04, "
                                f"astropy-iers-data {iers_data_version()})")
