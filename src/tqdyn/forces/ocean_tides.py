"""Ocean tides (FES2004) as corrections to the Earth's Stokes coefficients
(IERS Conventions 2010 = TN36, sec. 6.3, eq. 6.15).

Model: FES2004 (Lyard et al. 2006) in the spherical-harmonic form distributed
with TN36, ``data/fes2004_Cnm-Snm.dat`` (see SOURCES.md): 18 waves (2N2 K1 K2
M2 M4 Mf Mm Msq Mtm N2 O1 Om1 Om2 P1 Q1 S2 Sa Ssa), degree and order <= 100,
coefficients DelC+-, DelS+- of the fully normalised Stokes coefficients in
units of 1e-11 (the unit fixed by the TN36 update of 23 Sep 2011).  The
paper's model is the same FES2004 to n = 10 (its Table II).

TN36 eq. 6.15:

    dC_nm - i dS_nm = sum_f sum_(+,-) (C^+-_f,nm -/+ i S^+-_f,nm) exp(+- i theta_f)

i.e., expanded (TN36's own real form; Orekit ``OceanTidesWave`` uses the same):

    dC_nm = sum_f [(C+ + C-) cos theta_f + (S+ + S-) sin theta_f]
    dS_nm = sum_f [(S+ - S-) cos theta_f - (C+ - C-) sin theta_f]

with theta_f = n_f . beta the Doodson phase of the wave (TN36 sec. 6.2/6.3,
tau = theta_g + pi - s; :mod:`tqdyn.forces.tidal_arguments`).  The file's
coefficients are used as given (its header states no other phase
convention).  Known caveat (TN36 chapter 6 updates of 23 Sep and 14 Oct
2011): the phase of the C20 term of the very long-period equilibrium waves
Om1/Om2 (first two data lines) was set to pi/2 with "an ongoing discussion"
whether it should be -pi/2, i.e. the sign of their dC20 (Om1: 6.6e-11,
18.6-year period, ~7e-14 m/s^2 at r = 1e8 m, nearly constant over a 90-day
run) is uncertain.

Not done: (1) admittance for the secondary waves (TN36 sec. 6.3.2 allows
interpolating minor lines from the main ones; they are each at most a few %
of the main waves -- an estimate, not measured here -- i.e. ~1e-15 m/s^2 at
r = 1e8 m); (2) the degree-1 terms: tqdyn's origin is the center of mass
of the whole Earth including its oceans, and a mass redistribution inside
the system does not move that origin, so it exerts no degree-1 force in
this frame; degrees < ``min_degree`` = 2 are zeroed (the file's n = 1 rows
are zero anyway);
(3) the atmospheric tides (S1, S2; "atmospheric tide NOT included" in the
file header): see :mod:`tqdyn.forces.atmospheric_tides`.

Magnitude at r = 1e8 m (max over a day and over directions, measured in
tests/test_ocean_tides.py): 1.4e-12 m/s^2 in total, degree 2 1.3e-12,
degree 3 1.5e-13, degrees 5-10 together 8e-16; each degree is attenuated by
a further R/r = 0.064.
"""

from __future__ import annotations

import functools
import importlib.resources
import os
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..astro.tidal_arguments import delaunay_arguments, doodson_arguments, doodson_multipliers, tidal_cos_sin

__all__ = [
    "FES2004_FILE",
    "FES2004_MAX_DEGREE",
    "OceanTideModel",
    "OceanTides",
    "ocean_tide_coefficients",
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
    left zero (2: no degree-1 terms, see the module docstring).
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


def ocean_tide_coefficients(beta, model: OceanTideModel):
    """Ocean-tide corrections (TN36 eq. 6.15) at given Doodson arguments.

    beta: S + (6,) Doodson arguments [rad] (tau, s, h, p, N', p_s) at the
    instants; model: :class:`OceanTideModel`.
    Returns (dC, dS), float64 S + (nmax+1, nmax+1) indexed [n, m],
    dimensionless, fully normalised, ITRS (two views of one S + (2, nmax+1,
    nmax+1) array, from one matrix product; dS_n0 = 0).
    """
    c, s = tidal_cos_sin(beta, model.doodson)                           # S + (n_w,) each
    shape = c.shape[:-1]
    k = model.nmax + 1
    out = np.concatenate([c, s], axis=-1) @ model._weights                # S + (2 k^2,)
    out = out.reshape(shape + (2, k, k))
    return out[..., 0, :, :], out[..., 1, :, :]


@dataclass(frozen=True, eq=False)
class OceanTides:
    """FES2004 ocean tides (TN36 sec. 6.3) as a Stokes-coefficient provider.

    ``provider(epoch, t_hi, t_lo)`` (t = t_hi + t_lo [s TDB since epoch],
    shape S) returns (dC, dS), float64 S + (nmax+1, nmax+1) [n, m]:
    dimensionless corrections to the fully normalised Stokes coefficients
    (ITRS; FES2004 is normalised like EGM2008 and independent of the field's
    GM and radius at this level).

    Parameters
    ----------
    nmax : maximum degree and order (default 10, as in the paper; <= 100).
    orientation : callable (epoch, t_hi, t_lo) -> object with gmst [rad] S
        and tt (jd1, jd2); None -> :func:`tqdyn.frames.earth_orientation`.
    path : FES2004 file; None -> the shipped one.
    """

    nmax: int = 10
    orientation: Callable | None = None
    path: str | None = None
    name: str = field(default="ocean_tides", init=False)
    description: str = field(default="ocean tides FES2004 (18 waves, no admittance), eq. 6.15", init=False)
    source: str = field(default="FES2004 (Lyard et al. 2006) as distributed with IERS Conventions 2010, "
                                "sec. 6.3", init=False)

    def __post_init__(self):
        object.__setattr__(self, "nmax", int(self.nmax))
        self.model  # read (and validate nmax) now, not in the middle of a run  # noqa: B018

    @property
    def model(self) -> OceanTideModel:
        """The FES2004 waves up to ``nmax`` (read once per process)."""
        return read_fes2004(self.path, self.nmax)

    def evaluate(self, eo, tdb=None) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS) S + (nmax+1, nmax+1) from an Earth orientation eo (gmst
        [rad] S, tt (jd1, jd2)); ``tdb`` is unused (same signature as the
        other providers)."""
        from .solid_tides import _tt_pair

        beta = doodson_arguments(eo.gmst, delaunay_arguments(*_tt_pair(eo)))
        return ocean_tide_coefficients(beta, self.model)

    def __call__(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), float64 S + (nmax+1, nmax+1), at t = t_hi + t_lo [s TDB
        since epoch]."""
        from .solid_tides import _resolve_orientation

        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, np.float64), np.asarray(t_lo, np.float64))
        eo = _resolve_orientation(self.orientation)(epoch, t_hi, t_lo)
        return self.evaluate(eo)
