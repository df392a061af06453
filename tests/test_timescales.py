"""Tests for tqdyn.astro.timescales (UTC -> TAI -> TT -> TDB at the geocenter).

References used here, independent of the code under test:
* JD of a calendar date from Python's proleptic Gregorian ``datetime.date``
  ordinal: JD(2000-01-01 0h) = 2451544.5 (J2000.0 = 2451545.0 is 12h TT).
* TAI-UTC = 32 s from 1999-01-01 to 2006-01-01 and 37 s since 2017-01-01
  (IERS Bulletin C); TT-TAI = 32.184 s exactly (IAU 1991 Resolution A4).
* TDB-TT approximation 0.001657 sin g + 0.000014 sin 2g s with
  g = 357.53 deg + 0.98560028 deg * (JD - 2451545.0)
  (USNO Circular 179, Kaplan 2005, eq. 2.6; accurate to about 10-30 us).
* pyerfa's own routines called directly in the test (forward chain and the
  inverse routines erfa.taiutc, erfa.tttai, erfa.tdbtt, erfa.d2dtf).
All comparisons are differences of two-part JDs done in exact rational
arithmetic (fractions.Fraction) and expressed in seconds.
"""

from __future__ import annotations

import datetime as dt
import math
import warnings
from fractions import Fraction

import erfa
import numpy as np
import pytest

from tqdyn.astro.timescales import Epoch, parse_utc, tdb_jd, tt_jd

DAY = 86400
EPOCH_ISO = "2004-06-06T00:00:00"


def _jd(pair) -> Fraction:
    return Fraction(float(pair[0])) + Fraction(float(pair[1]))


def _dsec(p, q) -> float:
    """(p - q) in seconds, exactly from the two float pairs, rounded once at the end."""
    return float((_jd(p) - _jd(q)) * DAY)


@pytest.fixture(scope="module")
def ep() -> Epoch:
    return Epoch.from_utc(EPOCH_ISO)


def test_utc_jd_from_calendar(ep):
    # JD at 0h of the date: days since 2000-01-01 (Python ordinal) + 2451544.5
    jd0 = (dt.date(2004, 6, 6) - dt.date(2000, 1, 1)).days + 2451544.5
    assert _jd(ep.utc) == Fraction(jd0)
    assert ep.utc_iso == EPOCH_ISO
    # jd1 is shared by all scales (ERFA convention: large part first)
    assert ep.utc[0] == ep.tai[0] == ep.tt[0] == ep.tdb[0] == jd0


def test_tai_minus_utc_is_32s(ep):
    # IERS Bulletin C: TAI-UTC = 32 s on 2004-06-06; erfa's table agrees exactly
    assert erfa.dat(2004, 6, 6, 0.0) == 32.0
    # the float JD pair represents 32 s to its rounding: |err| < ulp(3.7e-4 d) * 86400 ~ 5e-15 s
    assert abs(_dsec(ep.tai, ep.utc) - 32.0) < 1e-12


def test_tt_minus_tai_is_32_184s(ep):
    assert abs(_dsec(ep.tt, ep.tai) - 32.184) < 1e-12


def test_tdb_minus_tt(ep):
    dtdb = _dsec(ep.tdb, ep.tt)
    assert abs(dtdb) < 2e-3  # the periodic TDB-TT terms are below 1.7 ms
    # equal to erfa.dtdb at that instant (geocentric: elong = u = v = 0; ut then irrelevant)
    ref = erfa.dtdb(ep.tt[0], ep.tt[1], 0.0, 0.0, 0.0, 0.0)
    assert abs(dtdb - ref) < 1e-12
    ref_ut_other = erfa.dtdb(ep.tt[0], ep.tt[1], 0.37, 0.0, 0.0, 0.0)
    assert ref_ut_other == ref  # the UT argument only enters the topocentric terms
    # USNO Circular 179 eq. 2.6 (first-principles approximation, ~10-30 us accuracy)
    g = math.radians(357.53 + 0.98560028 * (float(_jd(ep.tt)) - 2451545.0))
    approx = 0.001657 * math.sin(g) + 0.000014 * math.sin(2 * g)
    assert abs(dtdb - approx) < 50e-6


def test_chain_matches_erfa_forward_and_inverse(ep):
    # forward chain evaluated independently here
    u1, u2 = erfa.dtf2d("UTC", 2004, 6, 6, 0, 0, 0.0)
    a1, a2 = erfa.utctai(u1, u2)
    t1, t2 = erfa.taitt(a1, a2)
    b1, b2 = erfa.tttdb(t1, t2, erfa.dtdb(t1, t2, 0.0, 0.0, 0.0, 0.0))
    for mine, ref in ((ep.utc, (u1, u2)), (ep.tai, (a1, a2)), (ep.tt, (t1, t2)), (ep.tdb, (b1, b2))):
        assert abs(_dsec(mine, ref)) < 1e-12
    # inverse routines take us back to UTC
    dtr = erfa.dtdb(ep.tt[0], ep.tt[1], 0.0, 0.0, 0.0, 0.0)
    tt_back = erfa.tdbtt(ep.tdb[0], ep.tdb[1], dtr)
    tai_back = erfa.tttai(*tt_back)
    utc_back = erfa.taiutc(*tai_back)
    assert abs(_dsec(tt_back, ep.tt)) < 1e-9
    assert abs(_dsec(tai_back, ep.tai)) < 1e-9
    assert abs(_dsec(utc_back, ep.utc)) < 1e-9
    iy, im, id_, ihmsf = erfa.d2dtf("UTC", 3, *ep.utc)
    assert (int(iy), int(im), int(id_)) == (2004, 6, 6)
    assert tuple(int(x) for x in ihmsf.tolist()) == (0, 0, 0, 0)


def test_after_last_leap_second_and_leap_second_day():
    # 37 s since 2017-01-01 (IERS Bulletin C)
    e = Epoch.from_utc("2017-01-01T00:00:00")
    assert abs(_dsec(e.tai, e.utc) - 37.0) < 1e-12
    # 2016-12-31 had a leap second: 23:59:60.5 exists
    e = Epoch.from_utc("2016-12-31T23:59:60.5")
    assert e.utc_iso == "2016-12-31T23:59:60.5"
    with pytest.raises(ValueError, match="2016-12-30T23:59:60"):
        Epoch.from_utc("2016-12-30T23:59:60")


def test_no_erfa_warning_leaks():
    # 2004 (inside the table) and 2035 (TianQin era, after the last leap second:
    # erfa flags it "dubious" and keeps TAI-UTC = 37 s)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Epoch.from_utc(EPOCH_ISO)
        e = Epoch.from_utc("2035-01-01T00:00:00")
    assert abs(_dsec(e.tai, e.utc) - 37.0) < 1e-12


def test_normalisation():
    assert Epoch.from_utc("2004-06-06 00:00Z").utc_iso == "2004-06-06T00:00:00"
    assert Epoch.from_utc("2004-06-06").utc_iso == "2004-06-06T00:00:00"
    e = Epoch.from_utc("2004-06-06T12:34:56.789")
    assert e.utc_iso == "2004-06-06T12:34:56.789"
    assert abs(float(_jd(e.utc) - _jd(Epoch.from_utc("2004-06-06").utc)) * DAY - (12 * 3600 + 34 * 60 + 56.789)) < 1e-9
    f = parse_utc("2004-06-06T01:02:03")
    assert (f.year, f.month, f.day, f.hour, f.minute, f.second) == (2004, 6, 6, 1, 2, 3.0)


@pytest.mark.parametrize(
    "bad",
    ["06/06/2004", "2004-6-6T00:00:00", "2004-13-01T00:00:00", "2004-02-30T00:00:00",
     "2004-06-06T24:00:00", "2004-06-06T00:61:00", "1950-01-01T00:00:00", "", "yesterday"],
)
def test_bad_strings(bad):
    with pytest.raises(ValueError) as info:
        Epoch.from_utc(bad)
    msg = str(info.value)
    assert repr(bad) in msg
    assert "YYYY-MM-DDTHH:MM:SS" in msg


def test_non_string_rejected():
    with pytest.raises(ValueError, match="must be a string"):
        Epoch.from_utc(20040606)


def test_tt_jd_zero_and_shapes(ep):
    jd1, jd2 = tt_jd(ep, 0.0)
    assert jd1 == ep.tt[0] and jd2 == ep.tt[1]
    jd1, jd2 = tt_jd(ep, np.arange(5.0) * 50.0)
    assert jd1.shape == jd2.shape == (5,) and np.all(jd1 == ep.tt[0])
    jd1, jd2 = tt_jd(ep, np.arange(3.0), np.zeros((2, 1)))
    assert jd1.shape == jd2.shape == (2, 3)
    jd1, _ = tt_jd(ep, np.array([0.0, 86400.0 * 3650.5]))
    assert jd1[1] - jd1[0] in (3650.0, 3651.0) and jd1[1] % 1 == 0.5   # whole days move into jd1


@pytest.mark.parametrize("t_hi, t_lo", [(7.776e6, 0.0), (7.776e6, 3.1e-10), (12345.678901234, -1.7e-13),
                                        (1.5778e8, 0.0), (3.1557600e8 + 0.123456789, 4e-12)])
def test_tt_jd_exact_to_picoseconds(ep, t_hi, t_lo):
    # Reference: exact rational arithmetic.  jd1 takes the whole days, so jd2 stays within
    # ~half a day and its rounding (half an ulp, <= 2^-54 d = 4.8 ps) is the only error,
    # whatever the span (10 years here).
    jd1, jd2 = tt_jd(ep, t_hi, t_lo)
    exact = Fraction(ep.tt[0]) + Fraction(ep.tt[1]) + (Fraction(t_hi) + Fraction(t_lo)) / DAY
    err_s = abs(float((Fraction(float(jd1)) + Fraction(float(jd2)) - exact) * DAY))
    assert abs(float(jd2)) < 0.51
    assert err_s <= abs(float(np.spacing(jd2))) / 2 * DAY * 1.000001
    assert err_s < 5e-12


def test_tdb_jd_against_pyerfa_over_ten_years(ep):
    # Reference: pyerfa at every instant: TT = TT(epoch) + t, TDB = tttdb(TT, dtdb(TT)) at the
    # geocentre.  tqdyn interpolates an hourly table of dtdb (8-point Lagrange): measured
    # 5e-17 s; the comparison of two-part dates adds their rounding (~5 ps).
    t = np.linspace(0.0, 10 * 365.25 * 86400.0, 2001) + 1234.5678
    jd1, jd2 = tdb_jd(ep, t)
    tt1, tt2 = tt_jd(ep, t)
    ref1, ref2 = erfa.tttdb(tt1, tt2, erfa.dtdb(tt1, tt2, 0.0, 0.0, 0.0, 0.0))
    err = ((jd1 - ref1) + (jd2 - ref2)) * DAY
    assert np.max(np.abs(err)) < 2e-11
    # TDB - TT is the 1.66 ms annual term and its companions, not a constant
    dt = (jd2 - tt2) * DAY
    assert 1.5e-3 < dt.max() - dt.min() < 3.5e-3
    b1, b2 = tdb_jd(ep, 0.0)
    assert abs(((b1 - ep.tdb[0]) + (b2 - ep.tdb[1])) * DAY) < 1e-11


# --------------------------------------------------------------------------- TCB


def test_tdb_to_tcb_against_mpmath():
    # Reference: S = 1 / (1 - L_B) with L_B = 1.550519768e-8 exactly (IAU 2006 Resolution B3), mpmath at 50
    # digits, applied to the exact dd inputs.  tdb_to_tcb forms (S - 1) x in float64: measured 3.0e-24 of |x|
    # over times to 10 years, lengths to 2e11 m and light times.
    import mpmath as mp

    from tqdyn.astro.timescales import TCB_PER_TDB, TCB_SCALE, TCB_SCALE_MINUS_1, tdb_to_tcb

    rng = np.random.default_rng(1)
    hi = np.concatenate([rng.uniform(-3.2e8, 3.2e8, 200), rng.uniform(-2e11, 2e11, 200), rng.uniform(0, 20, 200)])
    lo = rng.uniform(-0.5, 0.5, hi.size) * np.spacing(hi)
    h, l = tdb_to_tcb(hi, lo)
    with mp.workdps(50):
        S = 1 / (1 - mp.mpf("1.550519768e-8"))
        assert abs(mp.mpf(TCB_PER_TDB[0]) + mp.mpf(TCB_PER_TDB[1]) - S) < mp.mpf("1e-32")
        assert TCB_SCALE == float(S) and TCB_SCALE_MINUS_1 == float(S - 1)
        worst = max(abs(mp.mpf(a) + mp.mpf(b) - S * (mp.mpf(x) + mp.mpf(y))) / abs(mp.mpf(x))
                    for a, b, x, y in zip(h, l, hi, lo))
    assert worst < 1e-23


def test_tcb_origins_against_astropy(ep):
    # Reference: astropy.time's own TDB -> TCB and TCB -> UTC chains (what lisaorbits dates its files with):
    # the epoch's TCB date, the TCB seconds from J2000.0 TCB, and Unix times.  Measured: 4.8e-12 s (the epoch's
    # TCB date: the rounding of two-part dates); the offsets agree to the last bit, bounded here by a few ulps of
    # their float64 values (~1e9 s: 2.4e-7 s).
    from astropy.time import Time

    from tqdyn.astro.timescales import tcb_jd_of_epoch, tcb_origin_offset

    c1, c2 = tcb_jd_of_epoch(ep)
    ref = Time(ep.tdb[0], ep.tdb[1], format="jd", scale="tdb").tcb
    assert abs(((c1 - ref.jd1) + (c2 - ref.jd2)) * DAY) < 3e-11
    j2000 = (Time(c1, c2, format="jd", scale="tcb") - Time(2451545.0, 0.0, format="jd", scale="tcb")).to_value("s")
    assert abs(tcb_origin_offset("j2000", ep, 0.0) - j2000) < 1e-6
    assert tcb_origin_offset("epoch", ep, 1234.5) == 0.0
    for t_first in (0.0, 1234.5, DAY * 365.0):
        unix = Time(c1, c2 + t_first / DAY, format="jd", scale="tcb").unix
        assert abs(tcb_origin_offset("unix", ep, t_first) + t_first - unix) < 1e-6
    with pytest.raises(ValueError, match="time origin 'gps' is not allowed; allowed: epoch, j2000, unix"):
        tcb_origin_offset("gps", ep, 0.0)


def test_geocentre_tdb_grid_against_erfa(ep):
    # Reference: erfa.dtdb at each instant (not tqdyn's interpolated table), dates compared in exact rationals.
    # The grid t_k is uniform (measured: exactly), each T_k has TDB(T_k) - TDB(epoch) = t_k (measured 4.6e-12 s:
    # the rounding of the two-part dates), and dT/dt - 1 is -d(TDB - TT)/dTDB (central differences of erfa.dtdb
    # over +-60 s; measured 5.4e-19 of a 3.0e-10 rate), over 10 days at 600 s.
    from tqdyn.astro.timescales import geocentre_tdb_grid

    N = 1441
    th = np.arange(N) * 600.0
    (bh, bl), (Th, Tl), rate_m1 = geocentre_tdb_grid(ep, (th, np.zeros(N)))
    b = bh + bl
    assert np.abs((bh - bh[0]) + (bl - bl[0]) - np.arange(N) * ((b[-1] - b[0]) / (N - 1))).max() < 1e-12
    assert Th[0] + Tl[0] == th[0] and Th[-1] + Tl[-1] == th[-1]
    t1, t2 = tt_jd(ep, Th, Tl)
    b1, b2 = erfa.tttdb(t1, t2, erfa.dtdb(t1, t2, 0.0, 0.0, 0.0, 0.0))
    err = max(abs(float(((Fraction(x) - Fraction(ep.tdb[0])) + (Fraction(y) - Fraction(ep.tdb[1]))) * DAY
                        - (Fraction(p) + Fraction(q)))) for x, y, p, q in zip(b1, b2, bh, bl))
    assert err < 3e-11
    h = 60.0
    d = (erfa.dtdb(t1, t2 + h / DAY, 0, 0, 0, 0) - erfa.dtdb(t1, t2 - h / DAY, 0, 0, 0, 0)) / (2 * h)
    assert np.abs(rate_m1 - (-d / (1 + d))).max() < 5e-18
    assert 1e-10 < np.abs(rate_m1).max() < 4e-10
