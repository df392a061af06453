"""Earth orientation parameters (EOP): daily tables and their interpolation.

What this module provides
-------------------------
* :class:`EOP` -- a daily EOP table ready to interpolate, built from one
  series or from several combined (:mod:`tqdyn.astro.eop_sources`: IERS EOP
  20 C04, finals2000A measured and predicted values, the long-term model);
  :attr:`EOP.segments` says which source gave which rows.
* :func:`load_eop` -- the shipped IERS EOP 14 C04 daily series
  (``data/eopc04_14_IAU2000.62-now.txt``, shipped; see ``data/SOURCES.md``;
  read by :func:`tqdyn.readers.eop_c04.read_eop_c04`) as an :class:`EOP` table: polar motion x_p, y_p and celestial pole
  offsets dX, dY in **rad**, UT1-UTC and LOD in **s**, one row per day at
  0 h UTC (MJD in UTC).
* :meth:`EOP.at` -- interpolation to any instants (arrays of any shape).
* :func:`tqdyn.readers.iers_tables.load_tidal_eop_terms` / :func:`tidal_eop_corrections` -- the IERS
  2010 diurnal and semidiurnal corrections to polar motion and UT1 that the
  C04 series does not contain (ocean tides: TN36 Tables 8.2 and 8.3, as in
  the IERS routine ``interp.f``/PMUT1_OCEANS; libration in polar motion:
  TN36 Table 5.1a, as in PMSDNUT2).  They are optional
  (:func:`tqdyn.astro.earth_orientation.earth_orientation` ``tidal_eop=``).

Interpolation
-------------
Two interpolants of the same daily nodes in MJD(UTC), both exact at every
node (:attr:`EOP.interpolation`, scenario key ``forces.eop_interpolation``):

* ``"spline"`` (the default): the C2 cubic spline through all the nodes
  (``scipy.interpolate.CubicSpline``, not-a-knot ends), its coefficients
  computed once per table (24 numbers per day: ~10 MB for 1962-2099) and
  evaluated by a small kernel.  Its value, slope and curvature are
  continuous at the nodes, so the force model that rotates the Earth's field
  with it is smooth in time: an integrator of order > 2 keeps its order
  across the daily nodes (docs/precision.md, "The force model's own
  noise").  Not-a-knot rather than natural ends: a natural spline forces
  zero curvature at the table's two ends, an O(h^2) error there, where
  not-a-knot keeps the O(h^4) of a cubic (the ends are the first days of
  1962 and the long-term model's last days, far from any run; a node's
  influence on the spline decays by 2 - sqrt(3) ~ 0.27 per day away from it).
* ``"lagrange4"``: four-point (cubic) Lagrange interpolation, the scheme of
  the IERS routine ``interp.f`` (IERS Gazette No. 13, "Interpolating IERS
  Earth orientation data", McCarthy, Gambis & Bizouard) recommended for the
  C04 series: for x in [MJD_i, MJD_i+1) the nodes i-1, i, i+1, i+2 are used
  (the first / last four nodes at the two ends of the table).  It is
  continuous, but its slope jumps at every node.

UT1-UTC jumps by +1 s at every leap second.  It is therefore interpolated as
UT1-TAI, which is smooth: the node values enter as
``UT1-UTC_j + (TAI-UTC(x) - TAI-UTC_j)`` with TAI-UTC from ERFA's leap-second
table (``erfa.dat``, which also carries the pre-1972 linear drifts), i.e. the
interpolated quantity is UT1-TAI and TAI-UTC of the requested instant is
added back.  For a query at a node the correction is zero and the tabulated
UT1-UTC is returned exactly (either interpolant).  :meth:`EOP.ut1_minus_tai` gives UT1-TAI
directly (what :mod:`tqdyn.astro.earth_orientation` uses: UT1 = TAI + (UT1-TAI), no UTC
needed).

How much the interpolation scheme matters (measured in ``tests/test_eop.py``,
2004-2006): 4-point Lagrange and 8-point Lagrange interpolants of the same
C04 nodes differ by up to ~7 us (rms ~2 us) in UT1 (5e-10 rad of Earth
rotation angle) and ~2e-10 rad (45 uas) in polar motion at mid-day -- the
day-to-day scatter of the series itself, below the C04's own stated errors
(e.g. 2004-06-06: 14 us in UT1-UTC, 68 uas in x).  The spline and the
4-point interpolant differ by as much (every 0.05 d, 2004-2006): up to
8.3 us (rms 1.4 us) in UT1 and 2.3e-10 rad (rms 6e-11 rad) in polar
motion (``test_spline_vs_lagrange4_spread``).  The IERS also recommends
removing the zonal tides from UT1 (TN36 Table 8.1, routine RG_ZONT2) before
interpolating; that table is not shipped and this is not done (the cubic
interpolation error of the largest zonal term, 13.66 d, ~0.4 ms, is < 0.4 us).
For tqdyn's use (rotating the Earth's gravity field seen from 1e8 m) any of
these is far below what matters: 1e-9 rad of orientation changes the
acceleration of the Earth's non-central field at 1e8 m by < 1e-15 m/s^2.

Leap seconds: TAI-UTC comes from ERFA's table, into which
:mod:`tqdyn.astro.timescales` installs the current IERS table on import.
Each table checks on construction that UT1-TAI is smooth (|change| < 0.1 s
per day; the series' UT1-UTC jumps by +1 s at each leap second, less the
day's LOD): a leap second missing from ERFA's table would show as a 1 s
jump and is refused.

Units: angles in rad (the file's arcsec times pi/648000), times in s, MJD in
days of UTC (ERFA quasi-JD convention on leap-second days).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from dataclasses import dataclass, field
from typing import NamedTuple

import erfa
import numpy as np

from numba import njit

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache, before any @njit)
from ..readers.eop_c04 import EopSeries, read_eop_c04
from ..readers.iers_tables import TidalEOPTerms
from . import timescales as _timescales  # noqa: F401  (installs the current leap-second table in ERFA)
from .constants import ARCSEC_RAD, J2000_JD, MJD_JD0

__all__ = [
    "load_eop",
    "ARCSEC",
    "DEFAULT_EOP_INTERPOLATION",
    "EOP",
    "EOP_INTERPOLATIONS",
    "EOPValues",
    "EopSegment",
    "EopSpanError",
    "mean_pole_iers2010",
    "tidal_arguments",
    "tidal_eop_corrections",
]

#: One arcsecond in radians (pi / 648000).
ARCSEC = ARCSEC_RAD  # rad per arcsec (astro.constants)

_MJD_JD0 = MJD_JD0
_DAY = 86400.0

#: Interpolants of an :class:`EOP` table between its daily nodes (module docstring, "Interpolation").
EOP_INTERPOLATIONS = ("spline", "lagrange4")
#: The default: the C2 cubic spline (smooth force model in time).
DEFAULT_EOP_INTERPOLATION = "spline"


class EOPValues(NamedTuple):
    """Interpolated Earth orientation parameters (arrays of the query's shape).

    xp, yp : rad -- polar motion (CIP in the ITRS), IERS C04.
    dut1 : s -- UT1-UTC.
    lod : s -- excess length of day.
    dx, dy : rad -- celestial pole offsets dX, dY w.r.t. IAU 2006/2000A.
    """

    xp: np.ndarray
    yp: np.ndarray
    dut1: np.ndarray
    lod: np.ndarray
    dx: np.ndarray
    dy: np.ndarray


class EopSegment(NamedTuple):
    """The rows of an :class:`EOP` table that came from one source.

    label : short name ("c04-20", "finals-measured", "finals-predicted",
        "long-term", "c04-14", or the table's source for a single series);
    first, last : MJD [d, UTC] of its first and last daily node;
    kind : "measured" | "predicted" | "model";
    description : one line (the file, or the model and its parameters).
    """

    label: str
    first: float
    last: float
    kind: str
    description: str


class EopSpanError(ValueError):
    """A date outside an EOP table's span: attributes ``mjd`` (the first
    offending MJD, UTC), ``span`` (first, last node MJD) and ``table``."""

    def __init__(self, message: str, mjd: float, span: tuple[float, float], table: "EOP"):
        super().__init__(message)
        self.mjd = mjd
        self.span = span
        self.table = table


# IERS 2010 conventional mean pole: TN36 Table 7.7 [mas yr^-k], k = 0..3
_MP_CUBIC_X = (55.974, 1.8243, 0.18413, 0.007024)
_MP_CUBIC_Y = (346.346, 1.7896, -0.10729, -0.000908)
_MP_LINEAR_X = (23.513, 7.6141)
_MP_LINEAR_Y = (358.891, -0.6287)
_MP_SWITCH_YEARS = 10.0  # 2010.0 - 2000.0
_JULIAN_YEAR_D = 365.25


def mean_pole_iers2010(tt) -> tuple[np.ndarray, np.ndarray]:
    """IERS 2010 conventional mean pole (TN36 eq. 7.25, Table 7.7).

    tt: two-part TT Julian date (jd1, jd2) [d], arrays of shape S.
    Returns (x_bar, y_bar) [rad], float64 S: cubic model before 2010.0,
    linear from 2010.0 on (the branches join to 1 uas).  Used by the pole
    tides (:mod:`tqdyn.forces.pole_tides`) and as the polar motion of the
    long-term EOP model (:mod:`tqdyn.astro.eop_sources`).  Raises
    ValueError for non-finite dates.
    """
    t = ((np.asarray(tt[0], dtype=np.float64) - float(J2000_JD)) + np.asarray(tt[1], dtype=np.float64)) \
        / _JULIAN_YEAR_D
    if not np.all(np.isfinite(t)):
        raise ValueError("mean pole: non-finite date")
    cubic = t < _MP_SWITCH_YEARS
    xc = _MP_CUBIC_X[0] + t * (_MP_CUBIC_X[1] + t * (_MP_CUBIC_X[2] + t * _MP_CUBIC_X[3]))
    yc = _MP_CUBIC_Y[0] + t * (_MP_CUBIC_Y[1] + t * (_MP_CUBIC_Y[2] + t * _MP_CUBIC_Y[3]))
    xl = _MP_LINEAR_X[0] + _MP_LINEAR_X[1] * t
    yl = _MP_LINEAR_Y[0] + _MP_LINEAR_Y[1] * t
    mas = ARCSEC_RAD / 1000.0
    return np.where(cubic, xc, xl) * mas, np.where(cubic, yc, yl) * mas


@functools.lru_cache(maxsize=1)
def _shipped_eop() -> "EOP":
    return EOP.from_series(read_eop_c04())


def load_eop(path=None) -> "EOP":
    """The EOP table of an IERS C04 file (x, y, dX, dY in rad; s).

    ``path=None``: the shipped IERS EOP 14 C04 series
    (``tqdyn/data/eopc04_14_IAU2000.62-now.txt``, 1962-01-01 .. 2024-09-03),
    read once and cached.  Otherwise a path to a file of the same format.
    Raises ``FileNotFoundError`` for a missing file and ``ValueError`` for a
    malformed one (:func:`tqdyn.readers.eop_c04.read_eop_c04`).
    """
    return _shipped_eop() if path is None else EOP.from_series(read_eop_c04(path))


def _quiet_dat(y, m, d, fd):
    """erfa.dat without the 'dubious year' warning (years past ERFA's table)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=erfa.ErfaWarning, message=".*dubious year.*")
        return np.asarray(erfa.dat(y, m, d, fd), dtype=np.float64)


@dataclass(frozen=True, eq=False)
class EOP(EopSeries):
    """IERS C04 Earth orientation parameters at daily nodes (0 h UTC), ready to interpolate.

    Attributes (1-D float64 arrays, one element per day, equally spaced)
    ----------
    mjd : MJD of the node [d, UTC].
    xp, yp : polar motion [rad].
    dut1 : UT1-UTC [s].
    lod : excess length of day [s].
    dx, dy : celestial pole offsets dX, dY w.r.t. IAU 2006/2000A [rad].
    source : where the table came from (file path, the shipped file, or "arrays").
    predicted : None, or a bool array: True where the row is a prediction.
    segments : tuple of :class:`EopSegment` (which source gave which rows, in
        order, covering every node); default: one "measured" segment named
        after ``source`` (or, with ``predicted``, its measured and predicted runs).
    interpolation : one of :data:`EOP_INTERPOLATIONS` (default "spline"; the
        IERS scheme is "lagrange4"); :meth:`with_interpolation` gives the
        same table with the other one.

    TAI-UTC at the nodes (from ``erfa.dat``) is computed on construction and
    kept privately (it is what removes the leap-second jumps of UT1-UTC).
    Construct with :func:`load_eop` (or :meth:`from_series`, or directly from arrays, e.g. in tests).
    """

    source: str = "arrays"
    predicted: np.ndarray | None = None
    segments: tuple = ()
    interpolation: str = DEFAULT_EOP_INTERPOLATION
    _dat0: np.ndarray = field(init=False, repr=False)
    _dlod: np.ndarray = field(init=False, repr=False)
    _daylen: np.ndarray = field(init=False, repr=False)
    _table: np.ndarray = field(init=False, repr=False)

    @classmethod
    def from_series(cls, series) -> "EOP":
        """The table of a daily series read from a file (:class:`tqdyn.readers.eop_c04.EopSeries`)."""
        return cls(series.mjd, series.xp, series.yp, series.dut1, series.lod, series.dx, series.dy, series.source,
                   getattr(series, "predicted", None))

    def __post_init__(self):
        if self.interpolation not in EOP_INTERPOLATIONS:
            raise ValueError(f"EOP.interpolation: {self.interpolation!r} is not an interpolant; allowed: "
                             + ", ".join(f'"{k}"' for k in EOP_INTERPOLATIONS))
        cols = {}
        for name in ("mjd", "xp", "yp", "dut1", "lod", "dx", "dy"):
            a = np.array(getattr(self, name), dtype=np.float64)  # own copy
            if a.ndim != 1:
                raise ValueError(f"EOP.{name}: expected a 1-D array, got shape {a.shape}")
            a.setflags(write=False)
            cols[name] = a
            object.__setattr__(self, name, a)
        n = cols["mjd"].size
        if n < 4:
            raise ValueError(f"EOP: need at least 4 daily nodes for 4-point interpolation, got {n}")
        for name, a in cols.items():
            if a.size != n:
                raise ValueError(f"EOP.{name}: {a.size} values, expected {n} (one per node)")
            if not np.all(np.isfinite(a)):
                raise ValueError(f"EOP.{name}: non-finite values")
        mjd = cols["mjd"]
        if np.any(mjd != np.round(mjd)) or np.any(np.diff(mjd) != 1.0):
            raise ValueError("EOP.mjd: nodes must be consecutive integer MJDs (one per day at 0 h UTC)")
        # TAI-UTC from ERFA's table, as erfa.utctai splits it: dat0 at 0 h of
        # each node day, the drift over the day dlod (pre-1972 UTC only) and
        # the step at its end dleap (leap second); the UTC day then lasts
        # daylen = (86400 + dleap)(86400 + dlod)/86400 s of TAI.
        days = np.append(mjd, mjd[-1] + 1.0)
        y, m, d, _ = erfa.jd2cal(_MJD_JD0, days)
        dat0 = _quiet_dat(y, m, d, 0.0)
        dlod = 2.0 * (_quiet_dat(y, m, d, 0.5) - dat0)
        dleap = dat0[1:] - (dat0[:-1] + dlod[:-1])
        daylen = (_DAY + dleap) * (_DAY + dlod[:-1]) / _DAY
        for name, a in (("_dat0", dat0[:-1]), ("_dlod", dlod[:-1]), ("_daylen", daylen)):
            a = np.ascontiguousarray(a)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        # leap seconds: UT1-TAI must be smooth (ERFA's table and the series agree)
        ut1_tai = cols["dut1"] - dat0[:-1]
        jump = np.abs(np.diff(ut1_tai))
        if jump.size and jump.max() > 0.1:
            i = int(np.argmax(jump))
            raise ValueError(
                f"EOP {self.source}: UT1-TAI changes by {ut1_tai[i + 1] - ut1_tai[i]:+.4f} s from MJD "
                f"{mjd[i]:.0f} to {mjd[i + 1]:.0f} ({_mjd_iso(mjd[i + 1])}): the series' leap seconds "
                f"disagree with ERFA's leap-second table (TAI-UTC {dat0[i]:.0f} -> {dat0[i + 1]:.0f} s)")
        self._init_segments(mjd)
        # columns interpolated together: xp, yp, UT1-TAI, lod, dx, dy
        tab = np.stack([cols["xp"], cols["yp"], cols["dut1"] - dat0[:-1], cols["lod"], cols["dx"], cols["dy"]],
                       axis=1)
        tab.setflags(write=False)
        object.__setattr__(self, "_table", tab)

    def _init_segments(self, mjd: np.ndarray) -> None:
        pred = self.predicted
        if pred is not None:
            pred = np.array(pred, dtype=bool)
            if pred.shape != mjd.shape:
                raise ValueError(f"EOP.predicted: shape {pred.shape}, expected {mjd.shape}")
            pred.setflags(write=False)
            object.__setattr__(self, "predicted", pred)
        segs = tuple(EopSegment(*s) for s in self.segments)
        if not segs:
            flags = np.zeros(mjd.size, dtype=bool) if pred is None else pred
            cut = np.nonzero(np.diff(flags.astype(np.int8)))[0] + 1
            starts = np.concatenate([[0], cut])
            ends = np.concatenate([cut - 1, [mjd.size - 1]])
            segs = tuple(EopSegment(self.source + (" (predicted)" if flags[a] else ""), float(mjd[a]),
                                    float(mjd[b]), "predicted" if flags[a] else "measured", self.source)
                         for a, b in zip(starts, ends))
        ok = (segs[0].first == mjd[0] and segs[-1].last == mjd[-1]
              and all(b.first == a.last + 1.0 for a, b in zip(segs, segs[1:])))
        if not ok:
            raise ValueError("EOP.segments: must cover the nodes in order, without gaps or overlaps")
        object.__setattr__(self, "segments", segs)

    def with_interpolation(self, interpolation: str) -> "EOP":
        """This table interpolated with ``interpolation`` (one of
        :data:`EOP_INTERPOLATIONS`): ``self`` if it already is, else a copy
        made once and kept (the same object on every call)."""
        if interpolation == self.interpolation:
            return self
        variants = self.__dict__.setdefault("_variants", {})
        if interpolation not in variants:
            variants[interpolation] = dataclasses.replace(self, interpolation=interpolation)
        return variants[interpolation]

    @functools.cached_property
    def _spline(self) -> np.ndarray:
        """(n, 4, 6) float64: the not-a-knot cubic spline of the six columns of
        ``_table`` on the unit-spaced nodes, row k = the cubic of [k, k+1) as
        Horner coefficients in s = x - k (c0 s^3 + c1 s^2 + c2 s + c3, c3 the
        node value itself); the last row re-expands the last cubic about the
        last node (value exact there)."""
        from scipy.interpolate import CubicSpline

        n = self.mjd.size
        sp = CubicSpline(np.arange(n, dtype=np.float64), self._table, axis=0, bc_type="not-a-knot")
        c = np.empty((n, 4, self._table.shape[1]))
        c[:-1] = np.moveaxis(sp.c, 0, 1)
        c[-1] = [sp.c[0, -1], 0.5 * sp(n - 1.0, 2), sp(n - 1.0, 1), self._table[-1]]
        c.setflags(write=False)
        return c

    # ------------------------------------------------------------------
    @property
    def span_mjd(self) -> tuple[float, float]:
        """(first, last) node MJD [d, UTC]; :meth:`at` accepts first <= mjd <= last."""
        return float(self.mjd[0]), float(self.mjd[-1])

    def _check_span(self, mjd: np.ndarray) -> None:
        lo, hi = self.span_mjd
        if mjd.size == 0:
            return
        ok = (mjd >= lo) & (mjd <= hi)
        if not np.all(ok):
            v = float(mjd[~ok].flat[0])
            raise EopSpanError(
                f"EOP: date MJD {v:.6f} (UTC, {_mjd_iso(v)}) is outside the EOP table span "
                f"MJD {lo:.0f}..{hi:.0f} ({_mjd_iso(lo)} .. {_mjd_iso(hi)}) of {self.source}; allowed: "
                f"dates in that span (scenario: forces.eop = \"auto\" extends the measured series with "
                f"predictions and a long-term model; false runs without EOP)", v, (lo, hi), self)

    def _day_index(self, mjd: np.ndarray) -> np.ndarray:
        return np.clip(np.floor(mjd - self.mjd[0]).astype(np.int64), 0, self.mjd.size - 1)

    def _tai_utc(self, mjd: np.ndarray, day: np.ndarray) -> np.ndarray:
        """TAI-UTC [s] at mjd (UTC quasi-MJD) in the node day of index ``day``."""
        return self._dat0[day] + (mjd - self.mjd[day]) * self._dlod[day]

    def at(self, mjd_utc) -> EOPValues:
        """Interpolated EOP at ``mjd_utc`` [d, MJD in UTC], any shape.

        Interpolated with :attr:`interpolation` (see the module docstring); UT1-UTC
        is interpolated as UT1-TAI (leap-second jumps removed) and TAI-UTC of
        the query instant is added back.  At a node the tabulated values are
        returned exactly.  Returns an :class:`EOPValues` of float64 arrays of
        the shape of ``mjd_utc`` (xp, yp, dx, dy in rad; dut1, lod in s).
        Raises ``ValueError`` outside :attr:`span_mjd`.
        """
        mjd = np.asarray(mjd_utc, dtype=np.float64)
        shape = mjd.shape
        mjd = mjd.ravel()
        cols = self._interp_columns(mjd)
        day = self._day_index(mjd)
        dat_q = self._tai_utc(mjd, day)
        if self.interpolation == "spline":
            # UT1-UTC_day + (UT1-TAI(q) - UT1-TAI_day) + (TAI-UTC(q) - TAI-UTC_day): exact at nodes
            dut1 = self.dut1[day] + (cols[:, 2] - self._table[day, 2]) + (dat_q - self._dat0[day])
            c = [cols[:, 0], cols[:, 1], dut1, cols[:, 3], cols[:, 4], cols[:, 5]]
            return EOPValues(*(a.reshape(shape) for a in c))
        # UT1-UTC = sum_j w_j (UT1-UTC_j + (TAI-UTC(q) - TAI-UTC_j)): exact at nodes
        vals = np.stack([self.dut1, self._dat0], axis=1)
        adj = np.empty((mjd.size, 4))
        k = np.empty(mjd.size, dtype=np.int64)
        _lagrange4_window(mjd - self.mjd[0], self.mjd.size, k, adj)
        dut1 = np.zeros(mjd.size)
        for j in range(4):
            dut1 += adj[:, j] * (vals[k + j, 0] + (dat_q - vals[k + j, 1]))
        c = [cols[:, 0], cols[:, 1], dut1, cols[:, 3], cols[:, 4], cols[:, 5]]
        return EOPValues(*(a.reshape(shape) for a in c))

    def tai_minus_utc(self, mjd_utc) -> np.ndarray:
        """TAI-UTC [s] at ``mjd_utc`` [d, UTC quasi-MJD] (ERFA's table, within the EOP span)."""
        mjd = np.asarray(mjd_utc, dtype=np.float64)
        self._check_span(mjd)
        return self._tai_utc(mjd, self._day_index(mjd))

    def ut1_minus_tai(self, mjd_utc) -> np.ndarray:
        """UT1-TAI [s] at ``mjd_utc`` [d, UTC], :attr:`interpolation` (smooth across leap seconds)."""
        mjd = np.asarray(mjd_utc, dtype=np.float64)
        return self._interp_columns(mjd.ravel())[:, 2].reshape(mjd.shape)

    def _interp_columns(self, mjd: np.ndarray, check: bool = True) -> np.ndarray:
        """(n, 6) interpolated [xp, yp, UT1-TAI, lod, dx, dy] (rad, s) at 1-D mjd (UTC)."""
        if check:
            self._check_span(mjd)
        out = np.empty((mjd.size, 6))
        x = np.ascontiguousarray(mjd - self.mjd[0])
        if self.interpolation == "spline":
            _cubic_table(x, self._spline, out)
        else:
            _lagrange4_table(x, self._table, out)
        return out

    def mjd_utc_from_tai(self, mjd_tai) -> np.ndarray:
        """MJD(UTC) [d] of instants given as MJD(TAI) [d] (float64 arrays of any shape).

        Uses ERFA's leap-second table as ``erfa.taiutc`` does, including
        ERFA's UTC quasi-JD convention on leap-second days (the fraction of a
        day with a leap second is seconds/86401).  Instants outside the table
        span are mapped with the first / last day's TAI-UTC (the span is
        checked where EOP values are interpolated).
        """
        tai = np.asarray(mjd_tai, dtype=np.float64)
        out = np.empty(tai.size)
        _utc_from_tai(np.ascontiguousarray(tai.ravel() - self.mjd[0]), self._dat0, self._daylen, out)
        return (out + self.mjd[0]).reshape(tai.shape)


@njit(cache=True)
def _lagrange4(xi, n_nodes):
    """Window start k (nodes k..k+3, clamped at the ends) and the 4-point
    Lagrange weights at abscissa xi on unit-spaced nodes 0..n_nodes-1."""
    k = int(math.floor(xi)) - 1
    if k < 0:
        k = 0
    if k > n_nodes - 4:
        k = n_nodes - 4
    s = xi - k
    s1, s2, s3 = s - 1.0, s - 2.0, s - 3.0
    return k, -(s1 * s2 * s3) / 6.0, (s * s2 * s3) * 0.5, -(s * s1 * s3) * 0.5, (s * s1 * s2) / 6.0


@njit(cache=True)
def _lagrange4_window(x, n_nodes, k_out, w_out):
    """Window start (nodes k..k+3) and 4-point Lagrange weights at abscissae x
    [d] relative to the first of n_nodes unit-spaced nodes."""
    for i in range(x.size):
        k, w0, w1, w2, w3 = _lagrange4(x[i], n_nodes)
        k_out[i] = k
        w_out[i, 0], w_out[i, 1], w_out[i, 2], w_out[i, 3] = w0, w1, w2, w3


@njit(cache=True)
def _lagrange4_table(x, table, out):
    """out[i, c] = 4-point Lagrange interpolant of table[:, c] (unit-spaced
    nodes 0, 1, ...) at x[i]; window i-1..i+2, clamped at the ends."""
    n_nodes, m = table.shape
    for i in range(x.size):
        k, w0, w1, w2, w3 = _lagrange4(x[i], n_nodes)
        for c in range(m):
            out[i, c] = w0 * table[k, c] + w1 * table[k + 1, c] + w2 * table[k + 2, c] + w3 * table[k + 3, c]


def _cubic_table(x, coef, out):
    """out[i, c] = the piecewise cubic of coef (n, 4, m) (row k: Horner
    coefficients in s = x - k on [k, k+1)) at x[i], k clamped to 0..n-1
    (vectorised: numpy, nothing to compile)."""
    k = np.clip(np.floor(x), 0, coef.shape[0] - 1).astype(np.int64)
    s = (x - k)[:, None]
    c = coef[k]
    out[...] = ((c[:, 0] * s + c[:, 1]) * s + c[:, 2]) * s + c[:, 3]


def _utc_from_tai(tai, dat0, daylen, out):
    """UTC quasi-MJD (relative to the first node) of TAI MJDs (same origin):
    day i starts at TAI i + dat0[i]/86400 and lasts daylen[i] s of TAI
    (vectorised: numpy, nothing to compile)."""
    n = dat0.size
    i = np.clip(np.floor(tai), 0, n - 1).astype(np.int64)
    sec = (tai - i) * 86400.0 - dat0[i]
    back = (sec < 0.0) & (i > 0)  # before the day's start: the day before
    ahead = ~back & (sec >= daylen[i]) & (i < n - 1)  # past its end: the next day
    i = i - back + ahead
    out[...] = i + np.where(back | ahead, (tai - i) * 86400.0 - dat0[i], sec) / daylen[i]


def _mjd_iso(mjd: float) -> str:
    """Calendar date YYYY-MM-DD of an MJD (for error messages)."""
    try:
        y, m, d, _ = erfa.jd2cal(_MJD_JD0, float(mjd))
        return f"{int(y):04d}-{int(m):02d}-{int(d):02d}"
    except Exception:
        return "?"


# ----------------------------------------------------------------------
# diurnal / semidiurnal corrections (ocean tides, libration)


def tidal_arguments(ut1, tt) -> np.ndarray:
    """The six arguments (gamma, l, l', F, D, Omega) [rad] of the sub-daily EOP terms.

    ut1, tt : two-part Julian dates (jd1, jd2) of UT1 and TT (arrays, same shape).
    gamma = GMST + pi with the IAU 2006 GMST (``erfa.gmst06``); the Delaunay
    arguments are the IERS 2003 expressions (TN36 eq. 5.43, ``erfa.fal03``,
    ``falp03``, ``faf03``, ``fad03``, ``faom03``) of TT Julian centuries since
    J2000.  (``interp.f`` and PMSDNUT2 use the 1982 GMST of an MJD taken as
    both UT1 and TT; the difference, < 0.01 rad in gamma, changes the
    corrections by < 1e-11 rad.)  Returns float64 (..., 6).
    """
    t = ((np.asarray(tt[0]) - 2451545.0) + np.asarray(tt[1])) / 36525.0
    gmst = erfa.gmst06(ut1[0], ut1[1], tt[0], tt[1])
    return np.stack([gmst + math.pi, erfa.fal03(t), erfa.falp03(t), erfa.faf03(t),
                     erfa.fad03(t), erfa.faom03(t)], axis=-1)


def tidal_eop_corrections(args, terms: TidalEOPTerms):
    """Sub-daily corrections (dx_p, dy_p [rad], dUT1 [s]) to add to interpolated C04 EOP.

    args : (..., 6) float64 [rad], the arguments (gamma = GMST + pi, l, l', F,
        D, Omega), e.g. from :func:`tidal_arguments`.
    terms : :class:`tqdyn.readers.iers_tables.TidalEOPTerms`.
    Each term contributes s * sin(a) + c * cos(a) with a = mult . args
    (the convention of interp.f and PMSDNUT2).  Returns three float64 arrays
    of shape args.shape[:-1].
    """
    args = np.asarray(args, dtype=np.float64)
    a_pm = args @ terms.pm_mult.T.astype(np.float64)
    s_pm, c_pm = np.sin(a_pm), np.cos(a_pm)
    dxp = s_pm @ terms.pm_coef[:, 0] + c_pm @ terms.pm_coef[:, 1]
    dyp = s_pm @ terms.pm_coef[:, 2] + c_pm @ terms.pm_coef[:, 3]
    a_ut = args @ terms.ut1_mult.T.astype(np.float64)
    dut = np.sin(a_ut) @ terms.ut1_coef[:, 0] + np.cos(a_ut) @ terms.ut1_coef[:, 1]
    return dxp, dyp, dut
