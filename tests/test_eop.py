"""Tests for tqdyn.astro.eop (IERS 14 C04 / 20 C04 / finals2000A readers, interpolation, sub-daily EOP terms).

Independent references used here:
* The parse check of ``src/tqdyn/data/SOURCES.md`` (2004-06-06, MJD 53162:
  x = -0.074487", y = 0.475665", UT1-UTC = -0.4704721 s, LOD = -0.0002408 s,
  dX = 0.000116", dY = 0.000096"), read off the file by hand.
* Rows of astropy-iers-data 0.2026.11.2's ``eopc04.1962-now`` (IERS EOP 20
  C04) and ``finals2000A.all`` copied verbatim into this file, with their
  values read off by hand (the installed files change weekly, so the parse
  checks use the copies; the installed files are checked for structure and
  against the 14 C04 series).
* A slow exact-rational (``fractions.Fraction``) 4-point Lagrange interpolant
  written here, with its own node selection and TAI-UTC from ``erfa.dat``
  called per calendar date (so the leap-second handling is checked against
  ERFA's table, not against the module's own bookkeeping).
* ERFA's ``erfa.taiutc`` (TAI -> UTC quasi-JD) for the UTC abscissa.
* IERS Conventions software test cases: PMSDNUT2 (libration in polar motion,
  TN36 Table 5.1a): MJD 54335 -> dx = 24.83144238273364834 uas,
  dy = -14.09240692041837661 uas (header of PMSDNUT2.F, 2011-10-13); and
  ORTHO_EOP (Ray ocean-tide model as orthoweights, a different realisation
  of the same ocean-tide model as TN36 Tables 8.2/8.3): MJD 47100 ->
  dx = -162.8386373279636530 uas, dy = 117.7907525842668974 uas,
  dUT1 = -23.39092370609808214 us (header of ORTHO_EOP.F).  The argument
  conventions of those routines (1982 GMST polynomial of an MJD, IERS 2003
  Delaunay arguments = ``erfa.fal03`` etc.) are written out here.
* The period column of the IERS tables vs the periods implied by the parsed
  argument multipliers and the IERS argument rates.
"""

from __future__ import annotations

import math
import warnings
from fractions import Fraction

import erfa
import numpy as np
import pytest

from tqdyn.astro.eop import ARCSEC, EOP, tidal_arguments, tidal_eop_corrections
from tqdyn.astro.eop import load_eop
from tqdyn.readers.eop_c04 import parse_eop_c04, read_eop_c04_20
from tqdyn.readers.eop_finals import parse_finals2000a, read_finals2000a
from tqdyn.readers.iers_tables import load_tidal_eop_terms

UAS = ARCSEC * 1e-6


@pytest.fixture(scope="module")
def eop() -> EOP:
    return load_eop()


def _dat(mjd_day: int, fd: float = 0.0) -> float:
    y, m, d, _ = erfa.jd2cal(2400000.5, float(mjd_day))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        return float(erfa.dat(int(y), int(m), int(d), fd))


# ----------------------------------------------------------------------
# reader


def test_parse_check_from_sources_md(eop):
    i = int(np.nonzero(eop.mjd == 53162)[0][0])
    assert eop.xp[i] == -0.074487 * ARCSEC
    assert eop.yp[i] == 0.475665 * ARCSEC
    assert eop.dut1[i] == -0.4704721
    assert eop.lod[i] == -0.0002408
    assert eop.dx[i] == 0.000116 * ARCSEC
    assert eop.dy[i] == 0.000096 * ARCSEC
    # SOURCES.md: 1962-01-01 .. 2024-09-03, one row per day
    assert eop.span_mjd == (37665.0, 60556.0)
    assert eop.mjd.size == 60556 - 37665 + 1
    # arrays are read-only (shared, cached table)
    with pytest.raises(ValueError):
        eop.xp[0] = 0.0


def test_load_eop_is_cached(eop):
    assert load_eop() is eop


def test_missing_and_malformed_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.txt"):
        load_eop(tmp_path / "nope.txt")
    empty = tmp_path / "empty.txt"
    empty.write_text("header only\n")
    with pytest.raises(ValueError, match="no EOP C04 data rows"):
        load_eop(empty)
    row = "2004   6   {d:d}  {mjd:d}  -0.074487   0.475665  -0.4704721  -0.0002408   0.000116   0.000096\n"
    gap = tmp_path / "gap.txt"
    gap.write_text("".join(row.format(d=d, mjd=53156 + d) for d in (1, 2, 3, 5, 6)))
    with pytest.raises(ValueError, match="consecutive"):
        load_eop(gap)
    badmjd = tmp_path / "badmjd.txt"
    badmjd.write_text("".join(row.format(d=d, mjd=53157 + d) for d in (1, 2, 3, 4)))
    with pytest.raises(ValueError, match="MJD does not match"):
        load_eop(badmjd)
    text = "".join(row.format(d=d, mjd=53156 + d) for d in (1, 2, 3, 4, 5))
    ok = tmp_path / "ok.txt"
    ok.write_text(text)
    e = load_eop(ok)
    assert e.span_mjd == (53157.0, 53161.0)
    assert e.source == str(ok)
    e2 = parse_eop_c04(text)
    assert np.array_equal(e2.dut1, e.dut1) and e2.source == "text"


#: Verbatim rows of IERS EOP 20 C04 (astropy-iers-data 0.2026.11.2, eopc04.1962-now) with its column header;
#: the last two rows straddle the leap second at the end of 2005-12-31.
C04_20_TEXT = """\
# YR  MM  DD  HH       MJD        x(")        y(")  UT1-UTC(s)       dX(")       dY(")  xrt("/day)  yrt("/day)      LOD(s)        x Er        y Er  UT1-UTC Er       dX Er       dY Er      xrt Er      yrt Er      LOD Er
2004   6   6   0  53162.00   -0.074500    0.475660  -0.4704630    0.000048    0.000116    0.001231    0.001632  -0.0002172    0.000067    0.000057   0.0000091    0.000067    0.000070    0.000121    0.000172   0.0000228
2004   6   7   0  53163.00   -0.073352    0.477179  -0.4703245   -0.000002    0.000118    0.001327    0.001267  -0.0000516    0.000066    0.000056   0.0000091    0.000068    0.000070    0.000120    0.000170   0.0000228
2005  12  31   0  53735.00    0.053717    0.384262  -0.6611412    0.000273   -0.000282   -0.001078   -0.000758   0.0000237    0.000068    0.000058   0.0000084    0.000075    0.000076    0.000124    0.000162   0.0000388
2006   1   1   0  53736.00    0.052632    0.383697   0.3387931    0.000307   -0.000233   -0.000928   -0.000502   0.0001379    0.000070    0.000058   0.0000083    0.000073    0.000076    0.000119    0.000147   0.0000483
"""

#: Verbatim rows of finals2000A.all (astropy-iers-data 0.2026.11.2): the last measured day, the first two
#: predictions (with dX, dY), the last prediction (without), the first date-only row.
FINALS_TEXT = (
    "261022 61335.00 I  0.149159 0.000041  0.317685 0.000041  I-0.0428601 0.0000203                 P     0.271"
    "    0.127     0.162    0.159" + " " * 53 + "\n"
    "261023 61336.00 P  0.148194 0.000600  0.317462 0.000400  P-0.0444801 0.0000297                 P     0.268"
    "    0.127     0.172    0.159" + " " * 53 + "\n"
    "261024 61337.00 P  0.147163 0.000891  0.317408 0.000659  P-0.0461706 0.0000359                 P     0.264"
    "    0.128     0.181    0.160" + " " * 53 + "\n"
)
FINALS_TAIL = ("271029 61707.00 P  0.179319 0.017516  0.276208 0.028383  P-0.2081431 0.0254096" + " " * 108 + "\n"
               "271030 61708.00" + " " * 172 + "\n")
#: A measured row with LOD and the Bulletin B columns (2004-06-06).
FINALS_2004 = (" 4 6 6 53162.00 I -0.074537 0.000053  0.475644 0.000057  I-0.4704398 0.0000064 -0.2254 0.0044  I"
               "     0.082    0.150    -0.099    0.145 -0.074410  0.475460 -0.4705960    -0.150     0.168  \n")


def test_parse_c04_20_layout():
    s = parse_eop_c04(C04_20_TEXT, source="c04-20 rows")
    assert np.array_equal(s.mjd, [53162.0, 53163.0, 53735.0, 53736.0])
    assert s.xp[0] == -0.074500 * ARCSEC and s.yp[0] == 0.475660 * ARCSEC
    assert s.dut1[0] == -0.4704630 and s.lod[0] == -0.0002172  # LOD is column 13 in 20 C04, not 8
    assert s.dx[0] == 0.000048 * ARCSEC and s.dy[0] == 0.000116 * ARCSEC
    assert s.dut1[3] == 0.3387931 and s.lod[3] == 0.0001379 and s.predicted is None
    # the two C04 series agree on 2004-06-06 to their stated errors (ITRF 2014 vs 2020 alignment)
    assert abs(s.xp[0] - (-0.074487 * ARCSEC)) < 100 * UAS and abs(s.dut1[0] - (-0.4704721)) < 20e-6
    with pytest.raises(ValueError, match="0 h"):
        parse_eop_c04(C04_20_TEXT.replace("2004   6   7   0  53163.00", "2004   6   7  12  53163.00"))
    with pytest.raises(ValueError, match="MJD does not match"):
        parse_eop_c04(C04_20_TEXT.replace("53163.00", "53164.00"))


def test_installed_c04_20():
    s = read_eop_c04_20()
    assert s.mjd[0] == 37665.0 and np.all(np.diff(s.mjd) == 1.0)  # 1962-01-01, daily
    assert s.mjd[-1] >= 61312.0  # 2026-09-29 in the 0.2026.11.2 release; later releases extend it
    assert "EOP 20 C04" in s.source and "astropy-iers-data" in s.source
    c14 = load_eop()
    i, k = np.searchsorted(s.mjd, 53162.0), np.searchsorted(c14.mjd, 53162.0)
    assert abs(s.xp[i] - c14.xp[k]) < 100 * UAS and abs(s.dut1[i] - c14.dut1[k]) < 20e-6


def test_parse_finals2000a_rows():
    s = parse_finals2000a(FINALS_TEXT, source="finals rows")
    assert np.array_equal(s.mjd, [61335.0, 61336.0, 61337.0])
    assert list(s.predicted) == [False, True, True]
    assert s.xp[0] == 0.149159 * ARCSEC and s.yp[1] == 0.317462 * ARCSEC
    assert s.dut1[1] == -0.0444801 and s.dut1[2] == -0.0461706
    assert s.dx[1] == pytest.approx(0.268e-3 * ARCSEC, rel=1e-15) and s.dy[2] == pytest.approx(0.181e-3 * ARCSEC, rel=1e-15)
    # LOD is blank in these rows: -d(UT1-TAI)/dt from the neighbours (TAI-UTC = 37 s throughout)
    assert abs(s.lod[1] - (0.0461706 - 0.0428601) / 2) < 1e-14  # (UT1-UTC - 37 s rounds to ~7e-15 s)
    assert abs(s.lod[0] - (0.0444801 - 0.0428601)) < 1e-14
    m = parse_finals2000a(FINALS_2004)
    assert m.mjd[0] == 53162.0 and m.xp[0] == -0.074537 * ARCSEC and m.dut1[0] == -0.4704398
    assert m.lod[0] == -0.2254e-3 and m.dx[0] == pytest.approx(0.082e-3 * ARCSEC, rel=1e-15) and not m.predicted[0]
    # the date-only rows after the predictions end the series; dX, dY blank -> 0
    t = parse_finals2000a(FINALS_TAIL)
    assert t.mjd.size == 1 and t.dx[0] == 0.0 and t.predicted[0] and t.yp[0] == 0.276208 * ARCSEC
    with pytest.raises(ValueError, match="consecutive"):
        parse_finals2000a(FINALS_TEXT.splitlines(True)[0] + FINALS_TEXT.splitlines(True)[2])
    with pytest.raises(ValueError, match="MJD does not match"):
        parse_finals2000a(FINALS_TEXT.replace("261023 61336", "261024 61336"))
    with pytest.raises(ValueError, match="flags"):
        parse_finals2000a(FINALS_TEXT.replace("61336.00 P", "61336.00 X"))


def test_installed_finals2000a():
    s = read_finals2000a()
    assert s.mjd[0] == 41684.0 and np.all(np.diff(s.mjd) == 1.0)  # 1973-01-02, daily
    pred = s.predicted
    first_p = int(np.argmax(pred))
    assert not pred[:first_p].any() and pred[first_p:].all()  # measured, then predicted
    assert 300 <= pred.sum() <= 400  # about a year of Bulletin A predictions
    assert np.all(np.isfinite(s.lod)) and np.all(np.abs(s.lod) < 5e-3)
    assert "finals2000A" in s.source


# ----------------------------------------------------------------------
# interpolation


@pytest.mark.parametrize("kind", ["spline", "lagrange4"])
def test_nodes_reproduced_exactly(eop, kind):
    tab = eop.with_interpolation(kind)
    v = tab.at(tab.mjd)
    for name in ("xp", "yp", "dut1", "lod", "dx", "dy"):
        assert np.array_equal(getattr(v, name), getattr(tab, name)), name
    assert np.array_equal(tab.ut1_minus_tai(tab.mjd), tab._table[:, 2])


def _ref_interp(eop: EOP, x: float):
    """Exact-rational 4-point Lagrange at MJD(UTC) x; UT1-UTC via UT1-TAI with erfa.dat per date."""
    n = eop.mjd.size
    i = int(math.floor(x - eop.mjd[0]))
    k = min(max(i - 1, 0), n - 4)
    X = Fraction(x)
    nodes = [Fraction(float(eop.mjd[k + j])) for j in range(4)]

    def lag(vals):
        tot = Fraction(0)
        for j in range(4):
            w = Fraction(1)
            for m in range(4):
                if m != j:
                    w *= (X - nodes[m]) / (nodes[j] - nodes[m])
            tot += w * vals[j]
        return tot

    out = {}
    for name in ("xp", "yp", "lod", "dx", "dy"):
        out[name] = float(lag([Fraction(float(getattr(eop, name)[k + j])) for j in range(4)]))
    ut1_tai = lag([Fraction(float(eop.dut1[k + j])) - Fraction(_dat(int(eop.mjd[k + j]))) for j in range(4)])
    day = math.floor(x)
    dat_q = Fraction(_dat(day, x - day))
    out["dut1"] = float(ut1_tai + dat_q)
    out["ut1_tai"] = float(ut1_tai)
    return out


def test_interpolation_vs_exact_lagrange(eop):
    """The "lagrange4" interpolant (IERS interp.f) against exact rational 4-point Lagrange."""
    eop = eop.with_interpolation("lagrange4")
    rng = np.random.default_rng(3)
    lo, hi = eop.span_mjd
    xs = list(rng.uniform(lo, hi, 60))
    xs += [lo, lo + 0.3, hi - 0.7, hi]  # clamped windows at both ends
    # around leap seconds (UTC days ending with a leap: 2005-12-31, 2008-12-31,
    # 2012-06-30, 2015-06-30, 2016-12-31) and a pre-1972 date with a drifting TAI-UTC
    for day in (53736, 54832, 56109, 57204, 57754):
        xs += [day - 1.5, day - 0.25, day - 1e-6, float(day), day + 1e-6, day + 0.75]
    xs += [39000.3, 40000.9]
    x = np.array(xs)
    v = eop.at(x)
    u = eop.ut1_minus_tai(x)
    for q, xq in enumerate(xs):
        r = _ref_interp(eop, xq)
        for name, tol in (("xp", 1e-20), ("yp", 1e-20), ("dx", 1e-20), ("dy", 1e-20), ("lod", 1e-17),
                          ("dut1", 1e-13)):
            assert abs(getattr(v, name)[q] - r[name]) <= tol, (name, xq)
        assert abs(u[q] - r["ut1_tai"]) <= 2e-14, xq


def test_shapes(eop):
    x = np.full((2, 3), 53162.25)
    v = eop.at(x)
    assert all(a.shape == (2, 3) for a in v)
    assert eop.at(53162.25).xp.shape == ()
    assert eop.ut1_minus_tai(x).shape == (2, 3)


def test_ut1_across_leap_second(eop):
    # 2006-01-01 0h UTC (MJD 53736): leap second, TAI-UTC 32 -> 33 s
    eps = 1e-7  # d
    before, after = eop.at(np.array([53736 - eps, 53736.0]))[2]
    assert abs((after - before) - 1.0) < 1e-6  # UT1-UTC jumps by +1 s (UT1 itself is smooth)
    u0, u1 = eop.ut1_minus_tai(np.array([53736 - eps, 53736.0]))
    assert abs(u1 - u0) < 1e-9  # UT1-TAI continuous
    assert eop.tai_minus_utc(53736 - eps) == 32.0 and eop.tai_minus_utc(53736.0) == 33.0


def test_mjd_utc_from_tai_matches_erfa(eop):
    rng = np.random.default_rng(5)
    tai = list(rng.uniform(41400.0, 60550.0, 2000))  # 1972 .. 2024
    # inside and around the leap second at the end of 2005-12-31 (TAI = UTC + 32 s)
    t0 = 53736.0 + 32.0 / 86400
    tai += [t0 - 2.0 / 86400, t0 - 0.5 / 86400, t0 + 0.3 / 86400, t0 + 1.5 / 86400]
    tai = np.array(tai)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        u1, u2 = erfa.taiutc(2400000.5, tai)
    ref = (u1 - 2400000.5) + u2
    got = eop.mjd_utc_from_tai(tai)
    assert np.abs(got - ref).max() * 86400 < 1e-5  # s (float64 MJD resolution ~1e-6 s)


def test_out_of_span(eop):
    for bad in (37664.5, 60556.01):
        with pytest.raises(ValueError, match=r"outside the EOP table span MJD 37665\.\.60556") as exc:
            eop.at(np.array([53162.0, bad]))
        assert "1962-01-01" in str(exc.value) and "2024-09-03" in str(exc.value)
    with pytest.raises(ValueError, match="2025-01-01"):
        eop.ut1_minus_tai(60676.0)


def test_interpolation_scheme_spread(eop):
    """How much the choice of interpolant matters (printed; documented in the
    module docstring): 4-point (IERS) vs 8-point Lagrange at mid-day, 2004-2006."""
    i0 = int(53005 - eop.mjd[0])
    i1 = int(54101 - eop.mjd[0])
    q = eop.mjd[i0:i1] + 0.5
    four = eop.with_interpolation("lagrange4")._interp_columns(q)
    k = np.arange(i0, i1)[:, None] + np.arange(-3, 5)[None, :]  # 8 nodes around each mid-day
    s = 0.5
    offs = np.arange(-3, 5, dtype=float)
    w = np.array([np.prod([(s - offs[m]) / (offs[j] - offs[m]) for m in range(8) if m != j]) for j in range(8)])
    eight = np.einsum("j,njc->nc", w, eop._table[k])
    d_ut1 = np.abs(four[:, 2] - eight[:, 2]).max()
    d_pm = np.abs(four[:, :2] - eight[:, :2]).max()
    print(f"\n4- vs 8-point interpolation 2004-2006: UT1 {d_ut1 * 1e6:.2f} us (ERA {d_ut1 * 7.29e-5:.1e} rad), "
          f"polar motion {d_pm:.1e} rad")
    # below the C04's own stated errors (2004-06-06: 14 us in UT1, 68 uas = 3.3e-10 rad in x)
    assert d_ut1 < 14e-6 and d_pm < 3.3e-10


def _one_sided_derivatives(tab: EOP, nodes: np.ndarray) -> np.ndarray:
    """(2 sides, 2 orders, n nodes, 6 columns): the first and second
    derivatives [unit/d, unit/d^2] of the six interpolated columns at the node
    MJDs from the left and from the right: from the exact cubic through the
    interpolant's values at 4 points inside the day before / after each node
    (each day's piece is a cubic, for both interpolants; the points are
    multiples of 1/8 d, exact in float64 MJDs)."""
    s = np.array([0.125, 0.375, 0.625, 0.875])
    V = np.vander(s, 4)  # columns s^3, s^2, s, 1
    out = []
    for side in (-1.0, 0.0):
        v = tab._interp_columns((nodes[:, None] + side + s[None, :]).ravel()).reshape(nodes.size, 4, 6)
        c = np.linalg.solve(V, v.transpose(1, 0, 2).reshape(4, -1)).reshape(4, nodes.size, 6)
        t0 = -side  # the node's offset in that day
        out.append([3.0 * c[0] * t0**2 + 2.0 * c[1] * t0 + c[2], 6.0 * c[0] * t0 + 2.0 * c[1]])
    return np.array(out)


def test_spline_c2_at_nodes(eop):
    """The spline's slope and curvature are continuous at the nodes: the
    one-sided values differ by the round-off of the cubic fits (~1e3 eps of
    the column's values per d, per d^2: ~1e-14 s/d^2 in UT1-TAI ~ -30 s); the
    4-point Lagrange interpolant's slope jumps (by ~1/6 of the series' third
    difference: >= 1e-3 of the slope itself; its curvature at a node is the
    second central difference from either side)."""
    nodes = eop.mjd[np.arange(15400, 16500, 7)]  # 2004..2007
    scale = np.abs(eop._table[15400:16500]).max(axis=0)  # per column [rad, s]
    left, right = _one_sided_derivatives(eop.with_interpolation("spline"), nodes)
    spline = (np.abs(left - right).max(axis=1) / scale).max()
    left, right = _one_sided_derivatives(eop.with_interpolation("lagrange4"), nodes)
    l4_slope = (np.abs(left[0] - right[0]).max(axis=0) / np.abs(left[0]).max(axis=0)).min()
    print(f"\nslope and curvature jumps at nodes: spline {spline:.1e} of the values (/d, /d^2), "
          f"lagrange4 slope jump >= {l4_slope:.1e} of the slope")
    assert spline < 1e-12
    assert l4_slope > 1e-3


def test_spline_vs_make_interp_spline(eop):
    """The spline against an independent one: scipy's make_interp_spline
    (B-spline basis, k = 3, not-a-knot) through the same 60 000 nodes; they
    agree to the round-off of the two solves (~1e-15 relative)."""
    from scipy.interpolate import make_interp_spline

    tab = eop.with_interpolation("spline")
    ref = make_interp_spline(tab.mjd, tab._table, k=3, axis=0)
    rng = np.random.default_rng(11)
    lo, hi = tab.span_mjd
    x = np.concatenate([rng.uniform(lo, hi, 5000), [lo, lo + 0.3, hi - 0.7, hi]])
    scale = np.abs(tab._table).max(axis=0)
    dev = (np.abs(tab._interp_columns(x) - ref(x)) / scale).max()
    assert dev < 1e-13, dev


def test_spline_vs_lagrange4_spread(eop, record_number):
    """The two interpolants between the nodes, 2004-2006 (every 0.05 d; C04 14):
    they differ by the series' day-to-day scatter, as 4- vs 8-point Lagrange
    (test_interpolation_scheme_spread), below the C04's own stated errors
    (2004-06-06: 14 us in UT1-UTC, 68 uas = 3.3e-10 rad in x)."""
    q = np.arange(53005.0, 54101.0, 0.05)
    d = eop.with_interpolation("spline")._interp_columns(q) - eop.with_interpolation("lagrange4")._interp_columns(q)
    ut1, pm = d[:, 2], np.hypot(d[:, 0], d[:, 1])
    res = {"ut1_max_s": float(np.abs(ut1).max()), "ut1_rms_s": float(np.sqrt(np.mean(ut1**2))),
           "pm_max_rad": float(pm.max()), "pm_rms_rad": float(np.sqrt(np.mean(pm**2)))}
    print(f"\nspline vs lagrange4 2004-2006: {res}")
    record_number("eop.spline_vs_lagrange4", res)
    assert res["ut1_max_s"] < 14e-6 and res["pm_max_rad"] < 3.3e-10


# ----------------------------------------------------------------------
# sub-daily terms


def _iers_args(rmjd: float) -> np.ndarray:
    """(GMST + pi, l, l', F, D, Omega) as PMSDNUT2 / ORTHO-style routines form them:
    1982 GMST polynomial of T = (MJD - 51544.5)/36525 (seconds of time), and the
    IERS 2003 Delaunay arguments (FUNDARG = erfa.fal03 ... faom03)."""
    t = (rmjd - 51544.5) / 36525.0
    gmst_s = math.fmod(67310.54841 + t * ((8640184.812866 + 3155760000.0) + t * (0.093104 + t * (-0.0000062))),
                       86400.0)
    gamma = gmst_s * (2 * math.pi / 86400.0) + math.pi
    return np.array([gamma, erfa.fal03(t), erfa.falp03(t), erfa.faf03(t), erfa.fad03(t), erfa.faom03(t)])


def test_libration_vs_pmsdnut2_test_case():
    terms = load_tidal_eop_terms(ocean=False, libration=True)
    assert terms.pm_mult.shape == (10, 6) and terms.ut1_mult.shape == (0, 6)
    dx, dy, dut = tidal_eop_corrections(_iers_args(54335.0), terms)
    assert abs(dx / UAS - 24.83144238273364834) < 1e-5
    assert abs(dy / UAS - -14.09240692041837661) < 1e-5
    assert dut == 0.0


def test_ocean_tides_vs_ortho_eop_test_case():
    terms = load_tidal_eop_terms(ocean=True, libration=False)
    assert terms.pm_mult.shape == (71, 6) and terms.ut1_mult.shape == (71, 6)
    dx, dy, dut = tidal_eop_corrections(_iers_args(47100.0), terms)
    print(f"\nocean tides at MJD 47100 minus ORTHO_EOP: dx {dx / UAS + 162.8386373279636530:+.3f} uas, "
          f"dy {dy / UAS - 117.7907525842668974:+.3f} uas, dUT1 {dut * 1e6 + 23.39092370609808214:+.4f} us")
    # two realisations of Ray's model: agree to < 1 uas and < 0.1 us (total ~200 uas, 23 us)
    assert abs(dx / UAS - -162.8386373279636530) < 1.0
    assert abs(dy / UAS - 117.7907525842668974) < 1.0
    assert abs(dut * 1e6 - -23.39092370609808214) < 0.1


def test_tidal_multipliers_match_period_column():
    # IERS argument rates at J2000 [arcsec per Julian century] (TN36 eqs 5.43 and
    # the 1982 GMST: (876600 h + 8640184.812866 s) * 15 arcsec/s)
    rates = np.array([(876600 * 3600 + 8640184.812866) * 15, 1717915923.2178, 129596581.0481,
                      1739527262.8478, 1602961601.2090, -6962890.2665])
    terms = load_tidal_eop_terms()
    for mult, period in ((terms.pm_mult, terms.periods_pm), (terms.ut1_mult, terms.periods_ut1)):
        implied = 1296000.0 * 36525.0 / np.abs(mult @ rates)
        assert np.abs(implied - period).max() < 2e-7  # d (tables give 7-8 digits)


def test_tidal_arguments_vectorised_and_consistent():
    # erfa-based arguments at the PMSDNUT2 test date with UT1 = TT: gamma from
    # gmst06 differs from the 1982 polynomial by < 1e-6 rad, the rest is identical
    mjd = np.array([54335.0, 54335.25])
    jd = (np.full(2, 2400000.5), mjd)
    a = tidal_arguments(jd, jd)
    assert a.shape == (2, 6)
    ref = _iers_args(54335.0)
    assert abs(math.remainder(a[0, 0] - ref[0], 2 * math.pi)) < 1e-6
    assert np.abs(a[0, 1:] - ref[1:]).max() < 1e-12
    dx, _, dut = tidal_eop_corrections(a, load_tidal_eop_terms())
    assert dx.shape == (2,) and np.all(np.abs(dx) < 2e-9) and np.all(np.abs(dut) < 1e-4)
