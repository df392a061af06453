"""Earth orientation for any epoch: the EOP sources, their combination into
one daily table, and the long-term model beyond the IERS data.

Sources (the scenario key ``forces.eop``)
-----------------------------------------
======================  ==================================================================
``"auto"`` (default;    IERS EOP 20 C04 (measured), then IERS finals2000A: Bulletin A
``true``)               measured values after the C04's last day, then its predictions
                        (about a year ahead of the data release), then the long-term model
                        (below) to 2099-12-31
``"finals"``            the same without the long-term model (measured + predicted only)
``"c04-20"``            IERS EOP 20 C04 only (measured)
``"c04-14"``            the shipped IERS EOP 14 C04, 1962-01-01..2024-09-03 (measured; the
                        series of the paper's era, kept to reproduce it bit for bit)
``"off"`` (``false``)   no EOP: x_p = y_p = dX = dY = 0, UT1 = UTC
======================  ==================================================================

EOP 20 C04, finals2000A and the leap-second table come from the PyPI package
``astropy-iers-data`` (released weekly; nothing is downloaded at run time;
:mod:`tqdyn.readers.eop_c04`, :mod:`tqdyn.readers.eop_finals`).  With the
version 0.2026.11.2 of that package: C04 to 2026-09-29, finals measured to
2026-10-22, predicted to 2027-10-29.  A table built here is one
:class:`~tqdyn.astro.eop.EOP` whose :attr:`~tqdyn.astro.eop.EOP.segments`
say which source gave which days ("c04-20", "finals-measured",
"finals-predicted", "long-term", "c04-14").

The long-term model (after the last measured or predicted day)
---------------------------------------------------------------
* Polar motion: the IERS 2010 conventional mean pole (TN36 eq. 7.25, linear
  after 2010; :func:`tqdyn.astro.eop.mean_pole_iers2010`, the pole the pole
  tides refer to, so their wobble is zero there).  It leaves out the
  Chandler (433 d) and annual wobbles: the 20 C04 pole differs from it by
  0.12" rms, 0.25" at most over 2010-2026 (6e-7 / 1.2e-6 rad; measured in
  tests/test_eop_sources.py); this error does not grow with time beyond the
  mean pole's own drift (the 2010 model's linear drift is itself off by
  ~0.1" in 2026).
* UT1-UTC: UT1-TAI extrapolated linearly from the last day with the mean
  LOD of the table's last 365 days (the slope of UT1-TAI over that year,
  free of the annual and semi-annual terms); TAI-UTC held at its last
  value (no leap second is announced; the CGPM stops them by 2035).  Why
  extrapolate rather than hold UT1-UTC (LOD = 0): over 1975-2026, for
  start dates one month apart, the extrapolation errs by 0.09 / 0.40 /
  0.90 / 2.3 s rms (0.27 / 1.0 / 2.0 / 5.2 s max) after 1 / 3 / 5 / 10 years,
  holding by 0.56 / 1.6 / 2.7 / 5.0 s rms (tests/test_eop_sources.py).
  1 s of UT1 is 7.3e-5 rad of Earth rotation.
* dX = dY = 0 (the free core nutation is not predictable; |dX|, |dY| <
  ~0.5 mas = 2.4e-9 rad).
* The sub-daily ocean-tide and libration terms are added as everywhere.

Junctions: the combined table is one daily series interpolated as any
other (4-point Lagrange, :mod:`tqdyn.astro.eop`): the interpolant is
continuous everywhere and reproduces each day's value.  The values of two
sources differ where they meet: C04 -> finals measured by the sources'
difference (last year: 45 uas rms in x, 25 us in UT1-UTC); predicted ->
long-term by the wobble the mean pole leaves out (~0.1" in polar motion,
taken within one day), while UT1-TAI is continuous (only its slope
changes).  Measured in tests/test_eop_sources.py.
"""

from __future__ import annotations

import functools
import warnings

import erfa
import numpy as np

from .._choices import did_you_mean
from ..readers.eop_c04 import EopSeries, iers_data_version, read_eop_c04, read_eop_c04_20
from ..readers.eop_finals import read_finals2000a
from .constants import MJD_JD0
from .eop import DEFAULT_EOP_INTERPOLATION, EOP, EOP_INTERPOLATIONS, EopSegment, EopSpanError, mean_pole_iers2010
from .timescales import Epoch, leap_seconds_note, tt_jd

__all__ = ["DEFAULT_EOP_INTERPOLATION", "DEFAULT_EOP_SOURCE", "EOP_INTERPOLATIONS", "EOP_SOURCES", "EOP_SOURCES_ALLOWED", "LONG_TERM_LAST_MJD", "LOD_WINDOW_DAYS",
           "check_coverage", "coverage", "data_note", "describe_coverage", "describe_sources", "eop_table",
           "long_term_warning", "normalize_eop_source", "run_span_mjd", "truncate", "with_long_term"]

#: The values of ``forces.eop`` and what each means.
EOP_SOURCES: dict[str, str] = {
    "auto": "measured (IERS EOP 20 C04, then finals2000A Bulletin A), then Bulletin A predictions, "
            "then the long-term model",
    "finals": "IERS EOP 20 C04, then finals2000A Bulletin A measured and predicted values (no long-term model)",
    "c04-20": "IERS EOP 20 C04, measured only",
    "c04-14": "IERS EOP 14 C04 (shipped, the paper's era), measured only",
    "off": "no EOP: x_p = y_p = dX = dY = 0, UT1 = UTC",
}
#: ``forces.eop = true`` means this source.
DEFAULT_EOP_SOURCE = "auto"
#: What ``forces.eop`` accepts (for one-line errors).
EOP_SOURCES_ALLOWED = 'true (= "auto"), false (= "off"), ' + ", ".join(f'"{k}"' for k in EOP_SOURCES)
#: Last day of the long-term model: 2099-12-31 [MJD, UTC].
LONG_TERM_LAST_MJD = 88068.0
#: Days over which the long-term model's LOD is averaged.
LOD_WINDOW_DAYS = 365

_DAY = 86400.0
_TT_TAI = 32.184


def normalize_eop_source(value) -> str:
    """The source name of a ``forces.eop`` value: True -> "auto", False -> "off",
    a name of :data:`EOP_SOURCES` (case and surrounding blanks ignored) -> itself.
    Raises ValueError otherwise."""
    if value is True:
        return DEFAULT_EOP_SOURCE
    if value is False:
        return "off"
    if isinstance(value, str) and value.strip().lower() in EOP_SOURCES:
        return value.strip().lower()
    raise ValueError(f"{value!r} is not an EOP source{did_you_mean(value, EOP_SOURCES)}; allowed: {EOP_SOURCES_ALLOWED}")


def _iso(mjd: float) -> str:
    y, m, d, _ = erfa.jd2cal(MJD_JD0, float(np.floor(mjd)))
    return f"{int(y):04d}-{int(m):02d}-{int(d):02d}"


def _quiet_dat(mjd: np.ndarray) -> np.ndarray:
    y, m, d, _ = erfa.jd2cal(MJD_JD0, mjd)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=erfa.ErfaWarning, message=".*dubious year.*")
        return np.asarray(erfa.dat(y, m, d, 0.0), dtype=np.float64)


# --------------------------------------------------------------------------- building tables

_COLS = ("mjd", "xp", "yp", "dut1", "lod", "dx", "dy")


def _table(parts: list[tuple[EopSeries, np.ndarray, list[EopSegment]]], source: str,
           interpolation: str = DEFAULT_EOP_INTERPOLATION) -> EOP:
    """One EOP table from (series, row selection, segments) parts, in order."""
    cols = {c: np.concatenate([getattr(s, c)[sel] for s, sel, _ in parts]) for c in _COLS}
    pred = np.concatenate([np.zeros(int(sel.sum()), bool) if s.predicted is None else np.asarray(s.predicted)[sel]
                           for s, sel, _ in parts])
    segs = tuple(g for _, _, segs in parts for g in segs)
    return EOP(*(cols[c] for c in _COLS), source=source, predicted=pred, segments=segs, interpolation=interpolation)


def _runs(series: EopSeries, sel: np.ndarray, labels: tuple[str, str]) -> list[EopSegment]:
    """Segments of the selected rows of a series: runs of measured / predicted rows."""
    mjd = series.mjd[sel]
    if mjd.size == 0:
        return []
    flags = np.zeros(mjd.size, bool) if series.predicted is None else np.asarray(series.predicted)[sel]
    cut = np.nonzero(np.diff(flags.astype(np.int8)))[0] + 1
    out = []
    for a, b in zip(np.concatenate([[0], cut]), np.concatenate([cut - 1, [mjd.size - 1]])):
        p = bool(flags[a])
        out.append(EopSegment(labels[p], float(mjd[a]), float(mjd[b]), "predicted" if p else "measured",
                              series.source))
    return out


def _single(series: EopSeries, label: str, source: str) -> EOP:
    sel = np.ones(series.mjd.size, bool)
    return _table([(series, sel, _runs(series, sel, (label, label + "-predicted")))], source)


def _c04_then_finals(source: str) -> EOP:
    c04 = read_eop_c04_20()
    fin = read_finals2000a()
    after = fin.mjd > c04.mjd[-1]
    if after.any() and fin.mjd[after][0] != c04.mjd[-1] + 1.0:
        raise ValueError(f"EOP: finals2000A starts after the C04's last day {_iso(c04.mjd[-1])}: a gap")
    allc = np.ones(c04.mjd.size, bool)
    return _table([(c04, allc, _runs(c04, allc, ("c04-20", "c04-20"))),
                   (fin, after, _runs(fin, after, ("finals-measured", "finals-predicted")))], source)


def with_long_term(eop: EOP, last_mjd: float = LONG_TERM_LAST_MJD, lod_window: int = LOD_WINDOW_DAYS,
                   source: str | None = None) -> EOP:
    """``eop`` extended day by day with the long-term model from its last node + 1 to ``last_mjd``.

    Polar motion: the IERS 2010 mean pole at each day's 0 h UTC (as TT);
    UT1-TAI: the last node's value extrapolated linearly with LOD_bar =
    -(UT1-TAI change over the last ``lod_window`` days) / ``lod_window``;
    UT1-UTC = UT1-TAI + TAI-UTC (ERFA's table, held after the last leap
    second); LOD = LOD_bar; dX = dY = 0.  The new rows form one "long-term"
    segment (kind "model") whose description states LOD_bar.  Returns
    ``eop`` itself if it already reaches ``last_mjd``.
    """
    last = float(eop.mjd[-1])
    if last >= last_mjd:
        return eop
    u = eop._table[:, 2]  # UT1-TAI at the nodes [s]
    w = int(min(lod_window, eop.mjd.size - 1))
    lod_bar = -(u[-1] - u[-1 - w]) / w
    m = np.arange(last + 1.0, last_mjd + 1.0)
    dat = _quiet_dat(m)
    xp, yp = mean_pole_iers2010((np.full(m.size, MJD_JD0) + m, (dat + _TT_TAI) / _DAY))
    ut1_tai = u[-1] - lod_bar * (m - last)
    desc = (f"IERS 2010 mean pole; UT1-TAI extrapolated from {_iso(last)} at LOD = {lod_bar * 1e3:.3f} ms "
            f"(mean of the last {w} days); dX = dY = 0")
    seg = EopSegment("long-term", float(m[0]), float(m[-1]), "model", desc)
    model = EopSeries(m, xp, yp, ut1_tai + dat, np.full(m.size, lod_bar), np.zeros(m.size), np.zeros(m.size),
                      "long-term model", np.ones(m.size, bool))
    base = EopSeries(eop.mjd, eop.xp, eop.yp, eop.dut1, eop.lod, eop.dx, eop.dy, eop.source,
                     np.zeros(eop.mjd.size, bool) if eop.predicted is None else eop.predicted)
    return _table([(base, np.ones(eop.mjd.size, bool), list(eop.segments)),
                   (model, np.ones(m.size, bool), [seg])], source or eop.source, eop.interpolation)


def truncate(eop: EOP, last_mjd: float, source: str | None = None) -> EOP:
    """The rows of ``eop`` up to ``last_mjd`` [MJD, UTC] (segments cut there):
    e.g. to see what the long-term model (:func:`with_long_term`) would have
    given over a span that is measured."""
    sel = eop.mjd <= last_mjd
    if sel.sum() < 4:
        raise ValueError(f"EOP: truncating at MJD {last_mjd} leaves fewer than 4 rows")
    segs = [g._replace(last=min(g.last, float(last_mjd))) for g in eop.segments if g.first <= last_mjd]
    base = EopSeries(eop.mjd, eop.xp, eop.yp, eop.dut1, eop.lod, eop.dx, eop.dy, eop.source,
                     np.zeros(eop.mjd.size, bool) if eop.predicted is None else eop.predicted)
    return _table([(base, sel, segs)], source or eop.source, eop.interpolation)


def eop_table(source: str | bool = DEFAULT_EOP_SOURCE, interpolation: str = DEFAULT_EOP_INTERPOLATION) -> EOP | None:
    """The EOP table of a source name (or True / False), built once and cached,
    interpolated with ``interpolation`` (:data:`tqdyn.astro.eop.EOP_INTERPOLATIONS`).

    "auto": 20 C04 + finals2000A (measured, predicted) + the long-term model
    to 2099-12-31; "finals": without the long-term model; "c04-20"; "c04-14"
    (the shipped file); "off": None.  Raises ValueError for an unknown
    name, FileNotFoundError if astropy-iers-data is missing.
    """
    eop = _eop_table(normalize_eop_source(source))
    return None if eop is None else eop.with_interpolation(interpolation)


@functools.lru_cache(maxsize=None)
def _eop_table(name: str) -> EOP | None:
    if name == "off":
        return None
    if name == "c04-14":
        return _single(read_eop_c04(), "c04-14", 'source "c04-14"')
    if name == "c04-20":
        return _single(read_eop_c04_20(), "c04-20", 'source "c04-20"')
    finals = _c04_then_finals('source "finals"')
    return finals if name == "finals" else with_long_term(finals, source='source "auto"')


# --------------------------------------------------------------------------- which source covers a run

def run_span_mjd(epoch: Epoch, duration_s: float) -> tuple[float, float]:
    """(first, last) MJD [d, UTC] of a run of ``duration_s`` s of TT from ``epoch``."""
    t = np.array([0.0, float(duration_s)])
    jd1, jd2 = tt_jd(epoch, t, 0.0)
    tai1, tai2 = erfa.tttai(jd1, jd2)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=erfa.ErfaWarning, message=".*dubious year.*")
        u1, u2 = erfa.taiutc(tai1, tai2)
    mjd = (u1 - MJD_JD0) + u2
    return float(mjd.min()), float(mjd.max())


def coverage(eop: EOP, mjd0: float, mjd1: float) -> list[tuple[EopSegment, float, float]]:
    """(segment, first, last MJD [UTC]) of each segment of ``eop`` that the
    span mjd0..mjd1 touches; a segment owns the days from its first node to
    the next segment's first node (the last one to its last node)."""
    segs = eop.segments
    out = []
    for k, s in enumerate(segs):
        end = segs[k + 1].first if k + 1 < len(segs) else s.last
        a, b = max(mjd0, s.first), min(mjd1, end)
        if a < b or (a == b and (k + 1 == len(segs) or a < end)):
            out.append((s, a, b if k + 1 == len(segs) or b < end else np.nextafter(end, -np.inf)))
    return out


def describe_coverage(eop: EOP | None, mjd0: float, mjd1: float) -> str:
    """Which source covered which days of mjd0..mjd1, one line:
    ``"c04-20 2026-09-20..2026-09-29; finals-measured 2026-09-30..2026-10-01"``
    (the long-term model with its parameters in parentheses)."""
    if eop is None:
        return "off (no EOP: x_p = y_p = dX = dY = 0, UT1 = UTC)"
    parts = []
    for s, a, b in coverage(eop, mjd0, mjd1):
        parts.append(f"{s.label} {_iso(a)}..{_iso(b)}" + (f" ({s.description})" if s.kind == "model" else ""))
    return "; ".join(parts) if parts else "none (outside the table)"


def data_note(eop: EOP | None) -> str:
    """The files behind a table and the leap-second table, one line."""
    if eop is None:
        return "none; " + leap_seconds_note()
    files = []
    for s in eop.segments:
        if s.kind != "model" and s.description not in files:
            files.append(s.description)
    return "; ".join(files) + "; " + leap_seconds_note()


def check_coverage(eop: EOP | None, source: str, mjd0: float, mjd1: float, field: str = "forces.eop") -> None:
    """ValueError (one line naming ``field``, the source and what is allowed)
    unless the table covers mjd0..mjd1 [MJD, UTC]."""
    if eop is None:
        return
    lo, hi = eop.span_mjd
    if lo <= mjd0 and mjd1 <= hi:
        return
    bad = mjd0 if mjd0 < lo else mjd1
    kinds = sorted({s.kind for s in eop.segments}, key=("measured", "predicted", "model").index)
    model = "model" in kinds
    kinds = [k if k != "model" else "the long-term model" for k in kinds]
    what = (", ".join(kinds[:-1]) + " and " if len(kinds) > 1 else "") + kinds[-1] + ("" if model else " only")
    if model:
        allowed = f"a run within {_iso(lo)}..{_iso(hi)}, or false (no EOP)"
    else:
        allowed = f'a run within that span, or "auto" (up to {_iso(LONG_TERM_LAST_MJD)})'
    where = "start" if bad == mjd0 else "end"
    raise EopSpanError(f'{field}: "{source}" covers {_iso(lo)}..{_iso(hi)} ({what}), not {_iso(bad)} '
                       f"(the run's {where}, UTC); allowed: {allowed}", bad, (lo, hi), eop)


def long_term_warning(eop: EOP | None, mjd0: float, mjd1: float) -> str | None:
    """One line when the span mjd0..mjd1 uses the long-term model, else None."""
    if eop is None:
        return None
    model = [(s, a) for s, a, _ in coverage(eop, mjd0, mjd1) if s.kind == "model"]
    if not model:
        return None
    s, a = model[0]
    line = (f"EOP: the IERS measurements and predictions end {_iso(s.first - 1)}; from {_iso(a)} the run uses the "
            f"long-term model ({s.description}; expected error: polar motion ~0.1\", UT1 ~0.1 s after 1 year, "
            f"~2 s after 10 years)")
    exp = erfa.leap_seconds.expires
    exp_mjd = float(erfa.cal2jd(exp.year, exp.month, exp.day)[1])
    if mjd1 > exp_mjd:
        line += f"; TAI-UTC held at {erfa.leap_seconds.get()[-1]['tai_utc']:g} s after {exp:%Y-%m-%d}"
    return line


def describe_sources() -> list[str]:
    """Lines for ``tqdyn info``: each source, its segments and their spans."""
    lines = [f"Earth orientation (forces.eop; IERS data of astropy-iers-data {iers_data_version()}):"]
    pad = " " * 26
    for name, what in EOP_SOURCES.items():
        tag = name + (' (default, = true)' if name == DEFAULT_EOP_SOURCE else ' (= false)' if name == "off" else "")
        lines.append(f"  {tag:<24}{what}")
        if name == "off":
            continue
        try:
            eop = eop_table(name)
        except (FileNotFoundError, ValueError) as exc:
            lines.append(f"{pad}unavailable: {exc}")
            continue
        lines.append(pad + "; ".join(f"{s.label} {_iso(s.first)}..{_iso(s.last)}" for s in eop.segments))
        lines += [f"{pad}long-term: {s.description}" for s in eop.segments if s.kind == "model"]
    lines.append("  " + leap_seconds_note())
    return lines
