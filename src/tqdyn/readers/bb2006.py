"""Reader of the Biancale & Bode (2006) atmospheric-tide file,
``data/atm_tides_bb2006_S1S2.txt`` (see SOURCES.md): the mean-annual
prograde S1 and S2 surface-pressure tides as spherical-harmonic amplitudes
[hPa] and phases [deg], degrees n <= 8, orders m <= 5, 24 terms per wave.

File layout: ``#`` comment lines (the header names each wave's Doodson
number as ``S1 (Doodson 164.556)``), then rows ``wave n m amplitude_hPa
phase_deg``.  Gives an :class:`AtmosphericTideModel` (one entry per row,
amplitudes converted to Pa and phases to rad, numbers otherwise as in the
file); the pressure convention and the conversion to Stokes coefficients
are theory: :mod:`tqdyn.forces.atmospheric_tides`.
"""

from __future__ import annotations

import functools
import importlib.resources
import math
import os
import re
from dataclasses import dataclass

import numpy as np

from .._choices import allowed, did_you_mean
from .doodson import doodson_multipliers

__all__ = [
    "BB2006_FILE",
    "BB2006_MAX_DEGREE",
    "DOODSON_NUMBERS",
    "AtmosphericTideModel",
    "parse_bb2006",
    "read_bb2006",
]

#: Shipped coefficient file (``tqdyn/data``).
BB2006_FILE = "atm_tides_bb2006_S1S2.txt"
#: Highest degree in the shipped file.
BB2006_MAX_DEGREE = 8
#: Doodson numbers of the radiational solar waves (Cartwright & Tayler
#: notation, as in the file header and TN36 Table 6.5b for S1): used for a
#: wave whose number the file header does not state.
DOODSON_NUMBERS = {"S1": "164.556", "S2": "273.555"}
_HPA = 100.0  # Pa per hPa (1 hPa = 1 mbar = 100 Pa, exact)
_HEADER_DOODSON = re.compile(r"\b([A-Za-z][A-Za-z0-9]*)\s*\(\s*Doodson\s+(\d{1,3}\.\d{3})\s*\)")


@dataclass(frozen=True, eq=False)
class AtmosphericTideModel:
    """Surface-pressure tide terms, one entry per file row (file order).

    wave: (k,) wave names ("S1", "S2"); doodson_number: (k,) Doodson numbers
    (str, e.g. "273.555"); doodson: (k, 6) int Doodson multipliers; n, m:
    (k,) int degree and order; amplitude: (k,) float64 [Pa]; phase: (k,)
    float64 [rad].  ``waves``: the distinct wave names in file order.
    """

    wave: tuple[str, ...]
    doodson_number: tuple[str, ...]
    doodson: np.ndarray
    n: np.ndarray
    m: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray

    @property
    def waves(self) -> tuple[str, ...]:
        """Distinct wave names, in file order."""
        return tuple(dict.fromkeys(self.wave))

    @property
    def nmax(self) -> int:
        """Highest degree present."""
        return int(self.n.max())

    def select(self, wave: str | None = None, nmax: int | None = None, n: int | None = None,
               m: int | None = None) -> AtmosphericTideModel:
        """The entries of one wave and/or degree <= nmax and/or one (n, m)."""
        keep = np.ones(len(self.wave), dtype=bool)
        if wave is not None:
            keep &= np.array([w == wave for w in self.wave])
        if nmax is not None:
            keep &= self.n <= nmax
        if n is not None:
            keep &= self.n == n
        if m is not None:
            keep &= self.m == m
        idx = np.flatnonzero(keep)
        if idx.size == 0:
            raise ValueError(f"atmospheric tides: no terms with wave={wave}, nmax={nmax}, n={n}, m={m}")
        return AtmosphericTideModel(wave=tuple(self.wave[i] for i in idx),
                                    doodson_number=tuple(self.doodson_number[i] for i in idx),
                                    doodson=self.doodson[idx], n=self.n[idx], m=self.m[idx],
                                    amplitude=self.amplitude[idx], phase=self.phase[idx])


def parse_bb2006(lines) -> AtmosphericTideModel:
    """Parse the Biancale & Bode S1/S2 file.

    lines: iterable of text lines (``#`` comments; rows ``wave n m
    amplitude_hPa phase_deg``).  Returns :class:`AtmosphericTideModel`
    (amplitudes in Pa, phases in rad).  Raises ValueError for a malformed
    row, an order outside 0..n, a negative amplitude, a duplicated (wave,
    n, m), a wave without a Doodson number, or a file without rows.
    """
    declared: dict[str, str] = {}
    rows: list[tuple[str, int, int, float, float]] = []
    seen: set[tuple[str, int, int]] = set()
    for lineno, line in enumerate(lines, 1):
        text = line.strip()
        if not text:
            continue
        if text.startswith("#"):
            for wave, number in _HEADER_DOODSON.findall(text):
                declared[wave] = number
            continue
        parts = text.split()
        if len(parts) != 5:
            raise ValueError(f"atmospheric-tide file line {lineno}: expected 5 columns "
                             f"(wave n m amplitude_hPa phase_deg), got {line.rstrip()!r}")
        try:
            n, m = int(parts[1]), int(parts[2])
            amp, pha = float(parts[3]), float(parts[4])
        except ValueError:
            raise ValueError(f"atmospheric-tide file line {lineno}: cannot parse {line.rstrip()!r}") from None
        if not 0 <= m <= n:
            raise ValueError(f"atmospheric-tide file line {lineno}: order m = {m} outside 0..{n}")
        if not amp >= 0.0:
            raise ValueError(f"atmospheric-tide file line {lineno}: amplitude {amp} hPa is negative")
        key = (parts[0], n, m)
        if key in seen:
            raise ValueError(f"atmospheric-tide file: duplicate term wave {parts[0]}, n = {n}, m = {m}")
        seen.add(key)
        rows.append((parts[0], n, m, amp, pha))
    if not rows:
        raise ValueError("atmospheric-tide file: no coefficient rows")
    numbers = {}
    for wave in dict.fromkeys(r[0] for r in rows):
        number = declared.get(wave, DOODSON_NUMBERS.get(wave))
        if number is None:
            raise ValueError(f"atmospheric-tide file: wave {wave!r} has no Doodson number"
                             f"{did_you_mean(wave, DOODSON_NUMBERS)}; allowed: a header 'NAME (Doodson ABC.DEF)' "
                             f"or {allowed(sorted(DOODSON_NUMBERS), noun='waves')}")
        numbers[wave] = number
    return AtmosphericTideModel(
        wave=tuple(r[0] for r in rows),
        doodson_number=tuple(numbers[r[0]] for r in rows),
        doodson=np.array([doodson_multipliers(numbers[r[0]]) for r in rows], dtype=np.int64),
        n=np.array([r[1] for r in rows], dtype=np.int64),
        m=np.array([r[2] for r in rows], dtype=np.int64),
        amplitude=np.array([r[3] * _HPA for r in rows], dtype=np.float64),
        phase=np.array([math.radians(r[4]) for r in rows], dtype=np.float64))


@functools.lru_cache(maxsize=4)
def _read_cached(path: str | None) -> AtmosphericTideModel:
    if path is None:
        res = importlib.resources.files("tqdyn") / "data" / BB2006_FILE
        if not res.is_file():
            raise FileNotFoundError(f"tqdyn data file not found: {res}")
        with res.open("r", encoding="utf-8") as fh:
            return parse_bb2006(fh)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"atmospheric-tide coefficient file not found: {path}")
    with open(path, encoding="utf-8") as fh:
        return parse_bb2006(fh)


def read_bb2006(path=None) -> AtmosphericTideModel:
    """Read a Biancale & Bode S1/S2 file (None -> the shipped
    ``data/atm_tides_bb2006_S1S2.txt``; cached per path).  See
    :func:`parse_bb2006`."""
    return _read_cached(None if path is None else os.fspath(path))
