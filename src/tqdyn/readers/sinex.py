"""Reader of station positions and velocities from SINEX solution files
(SINEX 2.02: the ILRS SLRF2020 file shipped in ``tqdyn/data``, see
data/SOURCES.md): blocks SITE/ID, SOLUTION/EPOCHS and SOLUTION/ESTIMATE.

Each (site code, point code, solution number) gets its reference epoch, its
position STAX/STAY/STAZ [m] and velocity VELX/VELY/VELZ [m/yr] (ITRF axes)
and its validity span (SOLUTION/EPOCHS data start and end; ``00:000:00000``
= open end).  SINEX epochs ``YY:DDD:SSSSS`` are years 1950-2049 (YY < 50
is 20YY), day of year, seconds of day; they are returned as decimal years
(year + (day - 1 + s/86400) / days-in-year), which is how the velocities'
"per year" is meant only to ~1e-3 (a 365.25-day year is used for the
propagation, :func:`station_position`: the difference is < 0.1 mm).

Malformed lines raise a one-line ``ValueError`` naming the file and line.
"""

from __future__ import annotations

import importlib.resources
from dataclasses import dataclass

import numpy as np

__all__ = ["SinexStation", "read_sinex_stations", "shipped_slrf", "station_position", "SLRF_FILE"]

#: The shipped ILRS SLR reference frame file (ITRF2020 realisation, version 231001).
SLRF_FILE = "SLRF2020_POS+VEL_2023.10.02.snx"
_YEAR_DAYS = 365.25


@dataclass(frozen=True)
class SinexStation:
    """One solution of one station: code (4 digits, str), point code, solution
    number, name (SITE/ID description), reference epoch, position (3,) [m],
    velocity (3,) [m/yr] (ITRF), validity start and end (decimal years;
    end = inf when open)."""

    code: str
    point: str
    soln: int
    name: str
    ref_epoch: float
    position: np.ndarray
    velocity: np.ndarray
    start: float
    end: float


def _year(text: str, where: str) -> float:
    try:
        yy, ddd, sss = (int(p) for p in text.split(":"))
    except ValueError:
        raise ValueError(f"{where}: SINEX epoch {text!r} is not YY:DDD:SSSSS") from None
    if yy == 0 and ddd == 0 and sss == 0:
        return float("inf")
    year = 2000 + yy if yy < 50 else 1900 + yy
    days = 366.0 if (year % 4 == 0 and (year % 100 != 0 or year % 400 == 0)) else 365.0
    return year + (ddd - 1 + sss / 86400.0) / days


def read_sinex_stations(text: str, name: str = "<sinex>") -> list[SinexStation]:
    """Stations of a SINEX text (``name`` only labels error messages)."""
    block = None
    names: dict[tuple[str, str], str] = {}
    spans: dict[tuple[str, str, int], tuple[float, float]] = {}
    est: dict[tuple[str, str, int], dict] = {}
    for k, line in enumerate(text.splitlines(), start=1):
        where = f"{name}, line {k}"
        if line.startswith("+"):
            block = line[1:].strip()
            continue
        if line.startswith("-"):
            block = None
            continue
        if not line.startswith(" ") or block is None:
            continue
        f = line.split()
        try:
            if block == "SITE/ID":
                names[(f[0], f[1])] = line[21:44].strip()
            elif block == "SOLUTION/EPOCHS":
                spans[(f[0], f[1], int(f[2]))] = (_year(f[4], where), _year(f[5], where))
            elif block == "SOLUTION/ESTIMATE":
                typ, code, pt, soln, ref, val = f[1], f[2], f[3], int(f[4]), f[5], float(f[8])
                if typ[:3] in ("STA", "VEL"):
                    d = est.setdefault((code, pt, soln), {"ref": _year(ref, where)})
                    d[typ] = val
        except (IndexError, ValueError) as exc:
            if isinstance(exc, ValueError) and str(exc).startswith(name):
                raise
            raise ValueError(f"{where}: malformed {block} line: {line.strip()!r}") from None
    out = []
    for key, d in est.items():
        if not all(c in d for c in ("STAX", "STAY", "STAZ")):
            raise ValueError(f"{name}: station {key[0]} {key[1]} solution {key[2]} lacks STAX/STAY/STAZ")
        start, end = spans.get(key, (-np.inf, np.inf))
        out.append(SinexStation(key[0], key[1], key[2], names.get(key[:2], ""), d["ref"],
                                np.array([d["STAX"], d["STAY"], d["STAZ"]]),
                                np.array([d.get("VELX", 0.0), d.get("VELY", 0.0), d.get("VELZ", 0.0)]),
                                start, end))
    return out


def shipped_slrf() -> list[SinexStation]:
    """The stations of the shipped SLRF2020 file (:data:`SLRF_FILE`)."""
    res = importlib.resources.files("tqdyn") / "data" / SLRF_FILE
    return read_sinex_stations(res.read_text(encoding="utf-8", errors="replace"), f"tqdyn/data/{SLRF_FILE}")


def station_position(station: SinexStation, year: float) -> np.ndarray:
    """ITRF position [m] (3,) at the decimal year ``year``: position +
    velocity (year - ref_epoch) (linear; the post-seismic deformation models
    that a few SLRF sites need are not applied)."""
    return station.position + station.velocity * (year - station.ref_epoch)
