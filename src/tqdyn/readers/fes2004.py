"""Reader of the FES2004 ocean-tide coefficient file distributed with the
IERS Conventions 2010 (TN36 sec. 6.3), ``data/fes2004_Cnm-Snm.dat`` (see
SOURCES.md): 18 waves, degree and order <= 100, coefficients DelC+-, DelS+-
of the fully normalised Stokes coefficients in units of 1e-11.

Gives an :class:`OceanTideModel` (arrays per wave, degree and order); the
corrections of TN36 eq. 6.15 are evaluated by
:mod:`tqdyn.forces.ocean_tides`.  Doodson numbers are decoded with
:func:`tqdyn.astro.tidal_arguments.doodson_multipliers`.
"""

from __future__ import annotations

import functools
import importlib.resources
import os
from dataclasses import dataclass

import numpy as np

from .doodson import doodson_multipliers

__all__ = [
    "FES2004_FILE",
    "FES2004_MAX_DEGREE",
    "OceanTideModel",
    "parse_fes2004",
    "read_fes2004",
]

#: Shipped FES2004 coefficient file (``tqdyn/data``).
FES2004_FILE = "fes2004_Cnm-Snm.dat"
#: Highest degree (and order) in the shipped file.
FES2004_MAX_DEGREE = 100
_UNIT = 1e-11  # unit of the file's coefficients (TN36 update of 23 Sep 2011)
_HEADER_LINES = 4


@dataclass(frozen=True, eq=False)
class OceanTideModel:
    """Spherical-harmonic ocean-tide waves, truncated at degree ``nmax``.

    names: (n_w,) Darwin names; doodson: (n_w, 6) int Doodson multipliers;
    c_plus, s_plus, c_minus, s_minus: (n_w, nmax+1, nmax+1) float64
    [wave, n, m] dimensionless (file units 1e-11 applied), zero for m > n and
    for degrees below ``min_degree``.
    """

    names: tuple[str, ...]
    doodson: np.ndarray
    c_plus: np.ndarray
    s_plus: np.ndarray
    c_minus: np.ndarray
    s_minus: np.ndarray
    nmax: int
    min_degree: int = 2

    @functools.cached_property
    def _weights(self) -> np.ndarray:
        """W (2 n_w, 2 (nmax+1)^2): [cos theta, sin theta] @ W gives, per
        instant, dC then dS flattened row-major over (n, m) (TN36 eq. 6.15
        real form; dS_n0 columns zero)."""
        k = self.nmax + 1
        nw = len(self.names)
        cp, sp = self.c_plus.reshape(nw, k * k), self.s_plus.reshape(nw, k * k)
        cm, sm = self.c_minus.reshape(nw, k * k), self.s_minus.reshape(nw, k * k)
        w = np.zeros((2 * nw, 2, k * k))
        w[:nw, 0] = cp + cm          # dC: cos
        w[nw:, 0] = sp + sm          # dC: sin
        w[:nw, 1] = sp - sm          # dS: cos
        w[nw:, 1] = -(cp - cm)       # dS: sin
        w[:, 1, ::k] = 0.0           # dS_n0 multiplies sin(0 lambda) = 0
        return w.reshape(2 * nw, 2 * k * k)


def parse_fes2004(lines, nmax: int = 10, min_degree: int = 2) -> OceanTideModel:
    """Parse the TN36 FES2004 coefficient file.

    lines: iterable of the file's text lines (4 header lines, then
    ``Doodson Darwin l m DelC+ DelS+ DelC- DelS-``, coefficients in 1e-11);
    nmax: keep degrees <= nmax (<= 100); min_degree: degrees below it are
    left zero (2: no degree-1 terms, see :mod:`tqdyn.forces.ocean_tides`).
    Returns :class:`OceanTideModel` with waves in file order.  Raises
    ValueError for a malformed row, a duplicated (wave, n, m), or nmax out of
    range.
    """
    if not (0 <= nmax <= FES2004_MAX_DEGREE):
        raise ValueError(f"FES2004: nmax = {nmax} is outside 0..{FES2004_MAX_DEGREE} (the file's maximum degree)")
    waves: dict[str, int] = {}
    names: list[str] = []
    mults: list[np.ndarray] = []
    rows: list[tuple[int, int, int, float, float, float, float]] = []
    for lineno, line in enumerate(lines, 1):
        if lineno <= _HEADER_LINES:
            continue
        parts = line.split()
        if not parts:
            continue
        if len(parts) != 8:
            raise ValueError(f"FES2004 line {lineno}: expected 8 columns "
                             f"(Doodson Darwin l m DelC+ DelS+ DelC- DelS-), got {line.rstrip()!r}")
        try:
            n, m = int(parts[2]), int(parts[3])
            vals = [float(x) for x in parts[4:]]
        except ValueError:
            raise ValueError(f"FES2004 line {lineno}: cannot parse {line.rstrip()!r}") from None
        if n > nmax or n < min_degree:
            continue
        if not 0 <= m <= n:
            raise ValueError(f"FES2004 line {lineno}: order m = {m} outside 0..{n}")
        key = f"{parts[0]} {parts[1]}"
        if key not in waves:
            waves[key] = len(names)
            names.append(parts[1])
            mults.append(doodson_multipliers(parts[0]))
        rows.append((waves[key], n, m, *vals))
    if not names:
        raise ValueError(f"FES2004: no coefficient rows with {min_degree} <= degree <= {nmax}")
    shape = (len(names), nmax + 1, nmax + 1)
    coef = np.zeros((4,) + shape)
    seen = np.zeros(shape, dtype=bool)
    for w, n, m, cp, sp, cm, sm in rows:
        if seen[w, n, m]:
            raise ValueError(f"FES2004: duplicate coefficients for wave {names[w]}, n = {n}, m = {m}")
        seen[w, n, m] = True
        coef[:, w, n, m] = (cp, sp, cm, sm)
    coef *= _UNIT
    return OceanTideModel(names=tuple(names), doodson=np.array(mults, dtype=np.int64), c_plus=coef[0],
                          s_plus=coef[1], c_minus=coef[2], s_minus=coef[3], nmax=nmax, min_degree=min_degree)


@functools.lru_cache(maxsize=4)
def _read_cached(path: str | None, nmax: int, min_degree: int) -> OceanTideModel:
    if path is None:
        res = importlib.resources.files("tqdyn") / "data" / FES2004_FILE
        if not res.is_file():
            raise FileNotFoundError(f"tqdyn data file not found: {res}")
        with res.open("r", encoding="ascii") as fh:
            return parse_fes2004(fh, nmax, min_degree)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"FES2004 coefficient file not found: {path}")
    with open(path, encoding="ascii") as fh:
        return parse_fes2004(fh, nmax, min_degree)


def read_fes2004(path=None, nmax: int = 10, min_degree: int = 2) -> OceanTideModel:
    """Read a FES2004 coefficient file (None -> the shipped
    ``data/fes2004_Cnm-Snm.dat``) up to degree ``nmax`` (cached per
    arguments).  See :func:`parse_fes2004`."""
    if not (0 <= int(nmax) <= FES2004_MAX_DEGREE):
        raise ValueError(f"FES2004: nmax = {nmax} is outside 0..{FES2004_MAX_DEGREE} (the file's maximum degree)")
    return _read_cached(None if path is None else os.fspath(path), int(nmax), int(min_degree))
