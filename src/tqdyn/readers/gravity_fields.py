"""Readers of spherical-harmonic gravity-field coefficient files.

Readers (file -> :class:`GravityModel`) are separate from the evaluation
(:mod:`tqdyn.forces.spherical_harmonics`, which takes arrays, not paths).

Formats
-------
* ICGEM ``.gfc`` (:func:`read_icgem_gfc`): header keywords
  ``earth_gravity_constant`` [m^3/s^2], ``radius`` [m], ``max_degree``,
  ``norm``, ``tide_system``, ``modelname``, then ``end_of_head`` and rows
  ``gfc n m C S sigmaC sigmaS`` (static models only: ``gfct``/``trnd``/
  ``acos``/``asin`` rows of time-variable models are rejected).
* PDS SHADR ASCII (:func:`read_shadr`): a comma-separated header line
  ``R_ref [km], GM [km^3/s^2], sigma(GM), degree, order, normalization flag,
  reference longitude, reference latitude``, then lines ``n, m, C, S, sigmaC,
  sigmaS``; converted to SI (m, m^3/s^2).  There is no C_00 line; C_00 = 1.

Shipped models (``tqdyn/data``, provenance in ``data/SOURCES.md``):

* :func:`egm2008` -- EGM2008 (Pavlis et al. 2012) to degree and order 90,
  GM = 3.986004415e14 m^3/s^2, R = 6378136.3 m, fully normalised,
  **tide-free** as shipped (body-fixed frame: ITRS).
* :func:`gl0660b` -- the GRAIL lunar field GL0660B (Konopliv et al. 2013) to
  degree 20, GM = 4.9028003055554e12 m^3/s^2, R = 1.738e6 m, fully
  normalised, tide-free C20/C22 (frame: lunar principal axes of DE421).

Permanent tide (IERS Conventions 2010, TN36 sec. 6.2.2)
-------------------------------------------------------
The Sun's and Moon's tide-generating potential has a non-zero time average
(the permanent tide), which deforms the Earth permanently and changes C20.
A "tide-free" C20 excludes both the direct permanent potential and the
permanent deformation; a "zero-tide" C20 includes the permanent
deformation.  For EGM2008 the two differ by

    C20(zero-tide) - C20(tide-free) = -0.484169317366974e-3 - (-0.484165143790815e-3)
                                    = -4.173576159e-9,

(NGA's published zero-tide value; IERS TN36 eq. 6.13 gives A0 H0 k20 =
4.4228e-8 x (-0.31460) x 0.30190 = -4.2007e-9 with the IERS 2010 k20 --
EGM2008's conversion used k20 = 0.3).  The IERS 2010 solid-tide model
(TN36 sec. 6.2, step 1 with the nominal Love numbers) evaluated with the
Sun and Moon ephemerides produces the permanent part too: its dC20 has the
time average A0 H0 k20.  Two consistent combinations exist:

1. **tide-free static C20 + solid tides INCLUDING their permanent part**
   (step 1 as computed, the mean not removed) -- tqdyn's default
   (``egm2008(tide_system="tide_free")``, :class:`tqdyn.forces.earth.EarthField`);
2. zero-tide static C20 (``egm2008(tide_system="zero_tide")``) + solid tides
   with the permanent part removed (TN36 eq. 6.14: dC20 - A0 H0 k20).

Mixing them (tide-free + mean removed, or zero-tide + mean kept) counts the
permanent deformation zero or two times: an error of ~4.2e-9 in C20, i.e.
~2.6e-12 m/s^2 at r = 1e8 m.  Combinations 1 and 2 differ by (0.30190 - 0.3)
x 4.4228e-8 x 0.3146 = 2.6e-11 in C20 (~1.6e-14 m/s^2 at 1e8 m), the
difference between the k20 of IERS 2010 and of the EGM2008 release.
"""

from __future__ import annotations

import functools
import importlib.resources
import math
import os
from dataclasses import dataclass, field, replace

import numpy as np

from .._choices import unknown

__all__ = [
    "EGM2008_FILE",
    "GL0660B_FILE",
    "GravityModel",
    "read_icgem_gfc",
    "read_shadr",
    "egm2008",
    "gl0660b",
    "EGM2008_C20_ZERO_TIDE",
    "TIDE_SYSTEMS",
]

#: EGM2008 zero-tide C20 (fully normalised), NGA's published value
#: (the EGM2008 zero-tide coefficient release; data/SOURCES.md).
EGM2008_C20_ZERO_TIDE = -0.484169317366974e-03

#: Tide systems a model can declare.
TIDE_SYSTEMS = ("tide_free", "zero_tide", "mean_tide", "unknown")

#: The shipped coefficient files (in ``tqdyn/data``): EGM2008 to degree 90 and the lunar GL0660B.
EGM2008_FILE = "EGM2008_90.gfc"
GL0660B_FILE = "jggrx_0660b_sha_deg20.tab"


@dataclass(frozen=True, eq=False)
class GravityModel:
    """A spherical-harmonic gravity field (static coefficients).

    Attributes
    ----------
    name : str
        Model name (e.g. ``"EGM2008"``).
    gm : float
        Gravitational parameter [m^3/s^2] the coefficients refer to.
    radius : float
        Reference radius [m].
    C, S : np.ndarray
        (nmax+1, nmax+1) float64, read-only: C[n, m], S[n, m] (zero for
        m > n and for rows absent from the file; C[0, 0] = 1).
    nmax : int
        Highest degree held (orders up to nmax).
    normalization : str
        ``"full"``: fully normalised (4 pi) coefficients (the only kind
        stored; unnormalised files are converted on reading).
    tide_system : str
        One of :data:`TIDE_SYSTEMS` (C20's permanent-tide convention).
    source : str
        Provenance (file name, header degree, ...).

    Frame: the body-fixed frame of the model (ITRS for the Earth, lunar
    principal axes for GL0660B).
    """

    name: str
    gm: float
    radius: float
    C: np.ndarray = field(repr=False)
    S: np.ndarray = field(repr=False)
    nmax: int
    normalization: str = "full"
    tide_system: str = "unknown"
    source: str = ""

    def __post_init__(self):
        C = np.array(self.C, dtype=np.float64, order="C")
        S = np.array(self.S, dtype=np.float64, order="C")
        n1 = int(self.nmax) + 1
        if C.shape != (n1, n1) or S.shape != (n1, n1):
            raise ValueError(f"{self.name}: C, S must have shape ({n1}, {n1}) for nmax = {self.nmax}, "
                             f"got {C.shape} and {S.shape}")
        if self.normalization != "full":
            raise ValueError(f"{self.name}: normalization {self.normalization!r}; only 'full' is stored")
        if self.tide_system not in TIDE_SYSTEMS:
            raise ValueError(unknown(f"{self.name}: tide_system", self.tide_system, TIDE_SYSTEMS))
        C.setflags(write=False)
        S.setflags(write=False)
        object.__setattr__(self, "C", C)
        object.__setattr__(self, "S", S)
        object.__setattr__(self, "nmax", int(self.nmax))
        object.__setattr__(self, "gm", float(self.gm))
        object.__setattr__(self, "radius", float(self.radius))

    def truncated(self, nmax: int) -> "GravityModel":
        """The same model truncated to degree (and order) ``nmax``.

        Raises ValueError if nmax exceeds the degree held or is negative."""
        nmax = _check_degree(self.name, nmax, self.nmax)
        if nmax == self.nmax:
            return self
        return replace(self, C=self.C[: nmax + 1, : nmax + 1], S=self.S[: nmax + 1, : nmax + 1], nmax=nmax)


def _check_degree(name: str, nmax, limit: int) -> int:
    if isinstance(nmax, bool) or not isinstance(nmax, (int, np.integer)):
        raise ValueError(f"{name}: degree must be an integer, got {nmax!r}")
    nmax = int(nmax)
    if nmax < 0:
        raise ValueError(f"{name}: degree {nmax} is negative")
    if nmax > limit:
        raise ValueError(f"{name}: degree {nmax} requested, but the model holds degrees up to {limit} only")
    return nmax


def _float(text: str) -> float:
    return float(text.replace("D", "E").replace("d", "e"))


def _fill(name, rows, nmax_wanted, path):
    """(n, m, C, S) rows -> (C, S) arrays of degree nmax (rows above skipped)."""
    C = np.zeros((nmax_wanted + 1, nmax_wanted + 1))
    S = np.zeros((nmax_wanted + 1, nmax_wanted + 1))
    for n, m, c, s in rows:
        if m > n or n < 0 or m < 0:
            raise ValueError(f"{path}: invalid degree/order ({n}, {m})")
        if n <= nmax_wanted:
            C[n, m] = c
            S[n, m] = s
    return C, S


def read_icgem_gfc(path, nmax: int | None = None) -> GravityModel:
    """Read a static ICGEM ``.gfc`` gravity-field file.

    Parameters
    ----------
    path : str or path-like (or a ``importlib.resources`` Traversable)
    nmax : int, optional
        Keep degrees <= nmax (default: all the file holds).  A degree above
        what the file holds raises ValueError naming the limit.

    Returns a :class:`GravityModel` (SI: gm [m^3/s^2], radius [m]; C, S fully
    normalised; tide system from the header, ``unknown`` if absent).
    Raises FileNotFoundError for a missing file and ValueError for a file
    that is not a static, fully normalised ICGEM model.
    """
    text = _read_text(path)
    header, rows, in_head = {}, [], True
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if in_head:
            if parts[0] == "end_of_head":
                in_head = False
            elif len(parts) >= 2:
                header.setdefault(parts[0].lower(), parts[1])
            continue
        key = parts[0].lower()
        if key == "gfc":
            try:
                n, m = int(parts[1]), int(parts[2])
                c = _float(parts[3])
                s = _float(parts[4]) if len(parts) > 4 else 0.0
            except (IndexError, ValueError):
                raise ValueError(f"{path}:{lineno}: bad gfc row {line.strip()!r}") from None
            rows.append((n, m, c, s))
        elif key in ("gfct", "trnd", "acos", "asin", "dot"):
            raise ValueError(f"{path}:{lineno}: time-variable ICGEM rows ({key!r}) are not supported")
        else:
            raise ValueError(f"{path}:{lineno}: unknown row key {parts[0]!r}")
    if in_head:
        raise ValueError(f"{path}: no 'end_of_head' line: not an ICGEM .gfc file")
    try:
        gm = _float(header["earth_gravity_constant"])
        radius = _float(header["radius"])
    except KeyError as exc:
        raise ValueError(f"{path}: header keyword {exc.args[0]!r} missing") from None
    norm = header.get("norm", "fully_normalized").lower()
    if not rows:
        raise ValueError(f"{path}: no gfc rows")
    n_file = max(r[0] for r in rows)
    nmax = n_file if nmax is None else _check_degree(str(path), nmax, n_file)
    C, S = _fill(str(path), rows, nmax, path)
    if norm == "unnormalized":
        C, S = _normalize(C, S)
    elif norm != "fully_normalized":
        raise ValueError(f"{path}: normalization {norm!r} not supported")
    tide = header.get("tide_system", "unknown").lower()
    tide = {"tide_free": "tide_free", "zero_tide": "zero_tide", "mean_tide": "mean_tide"}.get(tide, "unknown")
    name = header.get("modelname", os.path.basename(str(path)))
    hdr_deg = header.get("max_degree", "?")
    return GravityModel(name=name, gm=gm, radius=radius, C=C, S=S, nmax=nmax, tide_system=tide,
                        source=f"{os.path.basename(str(path))} (ICGEM, header max_degree {hdr_deg}, "
                               f"file degree {n_file}, read to {nmax})")


def read_shadr(path, nmax: int | None = None, *, name: str | None = None,
               tide_system: str = "unknown") -> GravityModel:
    """Read a PDS SHADR ASCII spherical-harmonic file (comma-separated).

    Parameters
    ----------
    path : str or path-like
    nmax : int, optional
        Keep degrees <= nmax (default: all the file holds -- which may be
        less than the header's degree, e.g. a truncated copy); a degree
        above the file's raises ValueError naming the limit.
    name : str, optional
        Model name (default: the file name).
    tide_system : str
        SHADR headers do not state it; one of :data:`TIDE_SYSTEMS`.

    Returns a :class:`GravityModel` in SI (R_ref km -> m, GM km^3/s^2 ->
    m^3/s^2), fully normalised (normalization flag 0 files are converted),
    C_00 = 1.
    """
    text = _read_text(path)
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise ValueError(f"{path}: empty SHADR file")
    try:
        head = [p.strip() for p in lines[0].split(",")]
        r_km, gm_km3 = _float(head[0]), _float(head[1])
        hdr_deg, norm_flag = int(head[3]), int(head[5])
    except (IndexError, ValueError):
        raise ValueError(f"{path}: bad SHADR header line {lines[0].strip()!r}") from None
    rows = []
    for lineno, line in enumerate(lines[1:], 2):
        parts = [p.strip() for p in line.split(",")]
        try:
            rows.append((int(parts[0]), int(parts[1]), _float(parts[2]), _float(parts[3])))
        except (IndexError, ValueError):
            raise ValueError(f"{path}:{lineno}: bad SHADR coefficient line {line.strip()!r}") from None
    if not rows:
        raise ValueError(f"{path}: no coefficient lines")
    n_file = max(r[0] for r in rows)
    nmax = n_file if nmax is None else _check_degree(str(path), nmax, n_file)
    C, S = _fill(str(path), rows, nmax, path)
    C[0, 0], S[0, 0] = 1.0, 0.0
    if norm_flag == 0:
        C, S = _normalize(C, S)
    elif norm_flag != 1:
        raise ValueError(f"{path}: SHADR normalization flag {norm_flag} not supported (0 or 1)")
    return GravityModel(name=name or os.path.basename(str(path)), gm=gm_km3 * 1e9, radius=r_km * 1e3,
                        C=C, S=S, nmax=nmax, tide_system=tide_system,
                        source=f"{os.path.basename(str(path))} (PDS SHADR, header degree {hdr_deg}, "
                               f"file degree {n_file}, read to {nmax})")


def _normalize(C, S):
    """Unnormalised -> fully normalised: Cbar = C / N_nm,
    N_nm = sqrt((2 - delta_m0)(2n + 1)(n - m)!/(n + m)!)."""
    n1 = C.shape[0]
    C, S = C.copy(), S.copy()
    for n in range(n1):
        for m in range(n + 1):
            lnn = 0.5 * (math.log((2 - (m == 0)) * (2 * n + 1)) + math.lgamma(n - m + 1) - math.lgamma(n + m + 1))
            C[n, m] /= math.exp(lnn)
            S[n, m] /= math.exp(lnn)
    return C, S


def _read_text(path) -> str:
    try:
        if hasattr(path, "read_text"):
            return path.read_text(encoding="utf-8")
        with open(path, encoding="utf-8") as fh:
            return fh.read()
    except FileNotFoundError:
        raise FileNotFoundError(f"gravity-field file not found: {path}") from None


def _data(name: str):
    return importlib.resources.files("tqdyn") / "data" / name


@functools.lru_cache(maxsize=None)
def _egm2008_full() -> GravityModel:
    return read_icgem_gfc(_data(EGM2008_FILE))


@functools.lru_cache(maxsize=None)
def egm2008(nmax: int = 12, tide_system: str = "tide_free") -> GravityModel:
    """EGM2008 truncated to degree and order ``nmax`` (<= 90, the shipped file).

    tide_system: ``"tide_free"`` (as shipped) or ``"zero_tide"`` (C20
    replaced by NGA's zero-tide value :data:`EGM2008_C20_ZERO_TIDE`; every
    other coefficient is the same in both releases).  See the module
    docstring for which one goes with which solid-tide treatment; tqdyn's
    Earth term uses tide-free + solid tides including the permanent part.

    Cached (the same read-only object for equal arguments).  Body-fixed
    frame: ITRS; gm = 3.986004415e14 m^3/s^2, radius = 6378136.3 m.
    Raises ValueError for nmax > 90 or an unknown tide system.
    """
    full = _egm2008_full()
    model = full.truncated(_check_degree("EGM2008", nmax, full.nmax))
    if tide_system == "tide_free":
        return model
    if tide_system == "zero_tide":
        if model.nmax < 2:
            return replace(model, tide_system="zero_tide")
        C = model.C.copy()
        C[2, 0] = EGM2008_C20_ZERO_TIDE
        return replace(model, C=C, tide_system="zero_tide",
                       source=model.source + "; C20 = zero-tide -0.484169317366974e-3 (NGA)")
    raise ValueError(f"EGM2008: tide_system {tide_system!r}; expected 'tide_free' or 'zero_tide'")


@functools.lru_cache(maxsize=None)
def gl0660b(nmax: int = 7) -> GravityModel:
    """GL0660B lunar gravity field truncated to degree and order ``nmax``
    (<= 20, the shipped file; the header's 660 is the original product's).

    Tide-free C20, C22 (data/SOURCES.md).  Body-fixed frame: lunar principal
    axes (DE421); gm = 4.9028003055554e12 m^3/s^2, radius = 1.738e6 m.
    Cached.  Raises ValueError for nmax > 20.
    """
    full = _gl0660b_full()
    return full.truncated(_check_degree("GL0660B", nmax, full.nmax))


@functools.lru_cache(maxsize=None)
def _gl0660b_full() -> GravityModel:
    return read_shadr(_data(GL0660B_FILE), name="GL0660B", tide_system="tide_free")
