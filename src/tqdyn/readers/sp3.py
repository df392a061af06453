"""Reader of GNSS precise orbits in the SP3-c and SP3-d formats (S. Hilla, "The Extended Standard
Product 3 Orbit Format (SP3-c)", NGS/NOAA, 2010, and "(SP3-d)", 2016; files of the IGS and its
analysis centres).

What is read (columns are 1-based, as in the format documents):

* line 1 ``#c`` / ``#d``: position/velocity flag (col 3), start epoch (cols 4-31), number of
  epochs (cols 33-39, I7), data used (41-45), coordinate system (47-51, e.g. ``IGS20``,
  ``ITRF``: a terrestrial frame), orbit type (53-55), agency (57-60);
* line 2 ``##``: epoch interval [s] (cols 25-38);
* ``+`` lines: the number of satellites (cols 4-6) and their ids, 17 per line from col 10, 3
  characters each (``G07``, ``C23``; a blank system letter is GPS, as in SP3-a);
* the first ``%c`` line: the time system (cols 10-12): ``GPS``, ``GAL``, ``QZS`` (GPS time
  scales), ``BDT``, ``TAI``; others (``UTC``, ``GLO``) are refused;
* epoch lines ``*  YYYY MM DD hh mm ss.ssssssss`` (year 4-7, month 9-10, day 12-13, hour 15-16,
  minute 18-19, second 21-31);
* position and clock records ``P``: satellite id (cols 2-4), x, y, z [km] (5-18, 19-32, 33-46,
  F14.6) and clock [microseconds] (47-60, F14.6).  A coordinate 0.000000 or 999999.999999 is a
  bad or absent position (the three become NaN), a clock 999999.999999 (or 0.000000, absent) is
  NaN.  Velocity records ``V``, correlation records ``EP``/``EV``, ``%f``, ``%i``, ``++`` and
  comment lines are skipped.

Returned in SI: positions [m] in the file's terrestrial frame, clocks [s], epochs as modified
Julian day numbers and seconds of the day in the file's time system (:data:`TT_MINUS`: its offset
to TT).  Malformed lines raise a one-line ``ValueError`` naming the file, the line and the field:
a number that is not one or not finite, an epoch that is not a calendar date and time
(:func:`tqdyn.readers.dates.calendar_problem`; the allowed time systems have no leap seconds, so
second < 60), epochs not in increasing order, an epoch interval <= 0, a satellite count < 1.

Consecutive files of the same satellites (the daily files of an analysis centre) are joined in
time by :func:`merge_sp3`.
"""

from __future__ import annotations

import datetime
import math
import os
from dataclasses import dataclass

import numpy as np

from .dates import calendar_problem

__all__ = ["SP3Orbits", "TT_MINUS", "merge_sp3", "read_sp3"]

#: TT minus the file's time system [s] (constant offsets): GPS time (and Galileo's, QZSS's,
#: aligned with it) = TAI - 19 s, so TT = GPST + 51.184 s; BeiDou time BDT = GPST - 14 s;
#: TT = TAI + 32.184 s.
TT_MINUS = {"GPS": 51.184, "GAL": 51.184, "QZS": 51.184, "BDT": 65.184, "TAI": 32.184}
_MISSING = 999999.999999
_MJD_ORDINAL = datetime.date(1858, 11, 17).toordinal()


@dataclass(frozen=True, eq=False)
class SP3Orbits:
    """The contents of an SP3 file (module docstring).

    path : the file's path (str); version : "c" or "d"; coordinate_system, orbit_type, agency,
    time_system : header fields (str); interval_s : header epoch interval [s]; satellites : ids
    (K,) ("G07"); mjd : (N,) int64 modified Julian day of each epoch and sod : (N,) float64
    seconds of that day [s], in the file's time system; positions : (N, K, 3) [m] in the file's
    terrestrial frame (NaN: absent); clocks : (N, K) [s] (NaN: absent)."""

    path: str
    version: str
    coordinate_system: str
    orbit_type: str
    agency: str
    time_system: str
    interval_s: float
    satellites: tuple
    mjd: np.ndarray
    sod: np.ndarray
    positions: np.ndarray
    clocks: np.ndarray


def _field(line: str, lo: int, hi: int, kind, where: str, name: str):
    """Columns lo..hi (1-based, inclusive) of ``line`` as int or float; ValueError naming them."""
    text = line[lo - 1:hi]
    try:
        v = kind(text)
    except ValueError:
        v = None
    if v is None or (kind is float and not math.isfinite(v)):
        raise ValueError(f"{where}: {name} (columns {lo}-{hi}) = {text.strip()!r} is not a number; allowed: "
                         f"{'an integer' if kind is int else 'a decimal number'} in those columns")
    return v


def _epoch(line: str, where: str, what: str) -> tuple[int, float]:
    y, mo, d = (_field(line, lo, hi, int, where, f"{what} {n}")
                for lo, hi, n in ((4, 7, "year"), (9, 10, "month"), (12, 13, "day")))
    h, mi = _field(line, 15, 16, int, where, f"{what} hour"), _field(line, 18, 19, int, where, f"{what} minute")
    s = _field(line, 21, 31, float, where, f"{what} second")
    if not 1 <= y <= 9999:
        raise ValueError(f"{where}: {what} year {y} is not allowed; allowed: 0001-9999")
    why = calendar_problem(y, mo, d, h, mi, s, scale="GPS")  # the allowed time systems have no leap seconds
    if why is not None:
        raise ValueError(f"{where}: {what} {line[3:31].strip()!r}: {why}")
    return datetime.date(y, mo, d).toordinal() - _MJD_ORDINAL, h * 3600.0 + mi * 60.0 + s


def _sat_id(text: str) -> str:
    return ("G" + text[1:] if text[0] == " " else text).replace(" ", "0")


def read_sp3(path) -> SP3Orbits:
    """Read the SP3-c or SP3-d file ``path`` (module docstring).  FileNotFoundError if it does
    not exist; ValueError (one line: the file, the line number, the field) if it is malformed or
    its time system is not one of :data:`TT_MINUS`."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"SP3 file {path!r} does not exist or is not a file")
    with open(path, encoding="ascii", errors="replace") as f:
        lines = f.read().splitlines()
    name = os.path.basename(path)
    if not lines or not lines[0].startswith(("#c", "#d")):
        head = lines[0][:3] if lines else ""
        raise ValueError(f"{name}: line 1: version {head!r} is not allowed; allowed: an SP3-c or SP3-d file "
                         "(first line '#c' or '#d')")
    first = lines[0].ljust(60)
    where = f"{name}: line 1"
    version = first[1]
    if first[2] not in "PV":
        raise ValueError(f"{where}: position/velocity flag (column 3) = {first[2]!r}; allowed: 'P' or 'V'")
    _epoch(first, where, "start epoch")
    n_epochs = _field(first, 33, 39, int, where, "number of epochs")
    coord, orbit_type, agency = first[46:51].strip(), first[52:55].strip(), first[56:60].strip()
    if len(lines) < 2 or not lines[1].startswith("##"):
        raise ValueError(f"{name}: line 2: missing the '##' line; allowed: an SP3-c or SP3-d header")
    interval = _field(lines[1].ljust(60), 25, 38, float, f"{name}: line 2", "epoch interval")
    if not interval > 0:
        raise ValueError(f"{name}: line 2: epoch interval (columns 25-38) = {interval:g} s is not allowed; allowed: "
                         "a number of seconds > 0")
    sats: list[str] = []
    n_sats = None
    time_system = None
    epochs: list[tuple[int, float]] = []
    rows: dict[tuple[int, str], tuple] = {}
    i = 2
    for i in range(2, len(lines)):
        line = lines[i]
        where = f"{name}: line {i + 1}"
        if line.startswith("+ "):
            if n_sats is None:
                n_sats = _field(line.ljust(60), 4, 6, int, where, "number of satellites")
                if n_sats < 1:
                    raise ValueError(f"{where}: number of satellites (columns 4-6) = {n_sats} is not allowed; "
                                     "allowed: an integer >= 1")
            body = line[9:60]
            sats += [_sat_id(body[j:j + 3]) for j in range(0, len(body) - 2, 3)
                     if body[j:j + 3].strip() not in ("0", "00", "")]
        elif line.startswith("%c") and time_system is None:
            time_system = line[9:12].strip()
            if time_system not in TT_MINUS:
                raise ValueError(f"{where}: time system (columns 10-12) {time_system!r} is not allowed; allowed: "
                                 f"{', '.join(TT_MINUS)}")
        elif line.startswith("*"):
            epochs.append(_epoch(line.ljust(31), where, "epoch"))
            if len(epochs) > 1 and epochs[-1] <= epochs[-2]:
                raise ValueError(f"{where}: epoch {line[3:31].strip()!r} is not after the previous epoch; allowed: "
                                 "epochs in increasing time order")
        elif line.startswith("P"):
            if not epochs:
                raise ValueError(f"{where}: a position record before the first epoch line; allowed: '*' epoch first")
            rec = line.ljust(60)
            sid = _sat_id(rec[1:4])
            vals = tuple(_field(rec, lo, lo + 13, float, where, f"{sid} {c}")
                         for lo, c in ((5, "x"), (19, "y"), (33, "z"), (47, "clock")))
            rows[(len(epochs) - 1, sid)] = vals
        elif line.startswith("EOF"):
            break
    where = f"{name}: header"
    if time_system is None:
        raise ValueError(f"{where}: no '%c' line with the time system; allowed: an SP3-c or SP3-d header")
    if n_sats is None or len(sats) < n_sats:
        raise ValueError(f"{where}: the '+' lines list {len(sats)} satellite ids for {n_sats} satellites; allowed: "
                         "one id per satellite")
    sats = sats[:n_sats]
    if len(set(sats)) != len(sats):
        raise ValueError(f"{where}: a satellite id is listed twice in the '+' lines; allowed: distinct ids")
    if len(epochs) != n_epochs:
        raise ValueError(f"{where}: line 1 announces {n_epochs} epochs, the file has {len(epochs)}; allowed: a "
                         "complete file")
    col = {s: k for k, s in enumerate(sats)}
    pos = np.full((len(epochs), len(sats), 3), np.nan)
    clk = np.full((len(epochs), len(sats)), np.nan)
    for (e, sid), (x, y, z, c) in rows.items():
        k = col.get(sid)
        if k is None:
            raise ValueError(f"{name}: epoch {e + 1}: satellite {sid!r} is not in the header's '+' lines; allowed: "
                             f"{', '.join(sats)}")
        if not any(v == 0.0 or abs(v - _MISSING) < 5e-7 for v in (x, y, z)):
            pos[e, k] = (x * 1e3, y * 1e3, z * 1e3)
        if c != 0.0 and abs(c - _MISSING) >= 5e-7:
            clk[e, k] = c * 1e-6
    mjd = np.array([e[0] for e in epochs], np.int64)
    sod = np.array([e[1] for e in epochs], np.float64)
    return SP3Orbits(path, version, coord, orbit_type, agency, time_system, float(interval), tuple(sats), mjd, sod,
                     pos, clk)


#: Largest difference [m] between two files' positions of a satellite at the same epoch for
#: :func:`merge_sp3` to take them as one (the files' 1 mm resolution, with margin).
MERGE_TOLERANCE_M = 0.01


def merge_sp3(parts) -> SP3Orbits:
    """One :class:`SP3Orbits` from several files of one time system and epoch interval (e.g.
    consecutive daily files): the union of their epochs (in time order) and satellites (in order
    of first appearance); a satellite absent from a file is NaN at that file's epochs.  An epoch
    in two files (the shared midnight) keeps the first file's value and is refused (one-line
    ValueError) when the two positions of a satellite differ by more than
    :data:`MERGE_TOLERANCE_M`.  ``path`` joins the files' paths with ``"+"``."""
    parts = sorted(parts, key=lambda o: (int(o.mjd[0]), float(o.sod[0])))
    first = parts[0]
    names = "+".join(os.path.basename(o.path) for o in parts)
    for o in parts[1:]:
        for field in ("time_system", "interval_s"):
            if getattr(o, field) != getattr(first, field):
                raise ValueError(f"{os.path.basename(o.path)}: {field} = {getattr(o, field)!r}, "
                                 f"{os.path.basename(first.path)} has {getattr(first, field)!r}; allowed: files of "
                                 f"one {field.replace('_s', '')} to join")
    sats = list(dict.fromkeys(s for o in parts for s in o.satellites))
    col = {s: k for k, s in enumerate(sats)}
    keys = sorted({(int(m), float(d)) for o in parts for m, d in zip(o.mjd, o.sod)})
    row = {k: i for i, k in enumerate(keys)}
    pos = np.full((len(keys), len(sats), 3), np.nan)
    clk = np.full((len(keys), len(sats)), np.nan)
    for o in parts:
        for e, key in enumerate(zip(o.mjd.tolist(), o.sod.tolist())):
            i = row[(int(key[0]), float(key[1]))]
            for k, s in enumerate(o.satellites):
                new = o.positions[e, k]
                old = pos[i, col[s]]
                if np.all(np.isfinite(old)):
                    if np.all(np.isfinite(new)) and np.max(np.abs(new - old)) > MERGE_TOLERANCE_M:
                        raise ValueError(f"{os.path.basename(o.path)}: satellite {s} at MJD {key[0]} + {key[1]:g} s "
                                         f"is {np.max(np.abs(new - old)):.3g} m from the earlier file's position; "
                                         f"allowed: files that agree where they overlap")
                    continue
                pos[i, col[s]] = new
                clk[i, col[s]] = o.clocks[e, k]
    mjd = np.array([k[0] for k in keys], np.int64)
    sod = np.array([k[1] for k in keys], np.float64)
    return SP3Orbits(names, first.version, first.coordinate_system, first.orbit_type, first.agency,
                     first.time_system, first.interval_s, tuple(sats), mjd, sod, pos, clk)
