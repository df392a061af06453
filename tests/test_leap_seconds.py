"""Leap seconds: the IERS table of astropy-iers-data, ERFA, tqdyn's time scales and the EOP series agree.

References: the IERS ``Leap_Second.dat`` file itself (its rows and its expiry
line, read by a regular expression written here, independently of the
reader); ERFA's built-in pre-1972 UTC (TAI-UTC = 3.5401300 s on
1965-01-01, the drift term of ``eraDat``); and the physics of a leap second
in the EOP series: UTC is held back by 1 s, so UT1-UTC jumps by +1 s minus
the day's LOD from one daily row to the next, and UT1-TAI stays smooth.
"""

from __future__ import annotations

import datetime as dt
import re
import warnings

import erfa
import numpy as np
import pytest

from tqdyn.astro import timescales
from tqdyn.astro.eop import EOP
from tqdyn.astro.eop_sources import eop_table
from tqdyn.astro.timescales import Epoch
from tqdyn.readers.eop_c04 import iers_data_file, read_eop_c04_20
from tqdyn.readers.eop_finals import read_finals2000a
from tqdyn.readers.leap_seconds import parse_leap_seconds, read_leap_seconds

DAY = 86400.0


def _file_rows():
    """(MJD, day, month, year, TAI-UTC) and the expiry date, read from the file with a regex of this test."""
    text = iers_data_file("Leap_Second.dat").read_text()
    rows = [tuple(float(x) for x in m.groups()) for m in
            re.finditer(r"^\s*(\d{5})\.0\s+(\d+)\s+(\d+)\s+(\d{4})\s+(\d+)\s*$", text, re.M)]
    exp = re.search(r"File expires on (\d+) (\w+) (\d{4})", text)
    return rows, dt.datetime.strptime(" ".join(exp.groups()), "%d %B %Y")


def _tai_minus_utc(iso: str) -> float:
    e = Epoch.from_utc(iso)
    return ((e.tai[0] - e.utc[0]) + (e.tai[1] - e.utc[1])) * DAY


def test_reader_matches_file():
    rows, expires = _file_rows()
    table = read_leap_seconds()
    assert len(rows) == table.mjd.size >= 28  # 28 changes from 1972-01-01 to 2017-01-01
    for (mjd, day, month, year, dat), m, y, mo, d in zip(rows, table.mjd, table.year, table.month, table.tai_utc):
        assert (mjd, year, month, dat) == (m, y, mo, d) and day == 1
    assert table.expires == expires.date()
    assert table.tai_utc[0] == 10.0 and table.year[0] == 1972


def test_erfa_uses_the_newest_table():
    rows, expires = _file_rows()
    ls = erfa.leap_seconds.get()
    have = {(int(r["year"]), int(r["month"])): float(r["tai_utc"]) for r in ls}
    for _, _, month, year, dat in rows:
        assert have[(int(year), int(month))] == dat
    assert erfa.leap_seconds.expires >= expires  # the file's expiry, not 180 days after 2017-01-01
    assert timescales.installed_leap_seconds() is not None
    # ERFA's pre-1972 drifting UTC is kept by the merge
    assert erfa.dat(1965, 1, 1, 0.0) == pytest.approx(3.5401300, abs=1e-12)
    note = timescales.leap_seconds_note()
    assert "Leap_Second.dat" in note and f"{expires:%Y-%m-%d}" in note


def test_time_scales_tai_utc_at_every_leap_second():
    """TAI-UTC of tqdyn's Epoch (erfa.dtf2d -> utctai) equals the file's value at 0 h of each date (and
    of the day before: the previous value); from 23:59:59 UTC of the day before to 0 h, 2 s of TAI pass
    (the leap second 23:59:60 exists), 1 s elsewhere."""
    rows, _ = _file_rows()

    def tai_s(iso):  # TAI as seconds relative to the epoch's jd1 (two-part JD: ~1e-11 s resolution)
        e = Epoch.from_utc(iso)
        return e.tai[0], e.tai[1] * DAY

    for k, (_, _, month, year, dat) in enumerate(rows):
        day = f"{int(year):04d}-{int(month):02d}-01"
        assert _tai_minus_utc(day + "T00:00:00") == pytest.approx(dat, abs=1e-9)
        if k:
            prev = dt.date(int(year), int(month), 1) - dt.timedelta(days=1)
            assert _tai_minus_utc(f"{prev}T00:00:00") == pytest.approx(rows[k - 1][4], abs=1e-9)
            (j0, s0), (j1, s1) = tai_s(f"{prev}T23:59:59"), tai_s(day + "T00:00:00")
            assert (j1 - j0) * DAY + (s1 - s0) == pytest.approx(2.0, abs=1e-6)
            Epoch.from_utc(f"{prev}T23:59:60.5")  # the leap second exists in UTC
    (j0, s0), (j1, s1) = tai_s("2019-12-31T23:59:59"), tai_s("2020-01-01T00:00:00")
    assert (j1 - j0) * DAY + (s1 - s0) == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(ValueError):
        Epoch.from_utc("2019-12-31T23:59:60.5")  # no leap second there
    # after the last leap second: held (37 s), also past the expiry date
    assert _tai_minus_utc("2035-06-01T00:00:00") == rows[-1][4]


@pytest.mark.parametrize("series", ["c04-20", "finals"])
def test_eop_series_jump_by_one_second_at_each_leap_second(series):
    """UT1-UTC of the daily series jumps by +1 s (less the day's LOD) at each leap second of the table
    inside the series, and nowhere else; the EOP table (which checks UT1-TAI for smoothness on
    construction) interpolates UT1-TAI continuously across each."""
    s = read_eop_c04_20() if series == "c04-20" else read_finals2000a()
    rows, _ = _file_rows()
    leaps = [r[0] for r in rows[1:] if s.mjd[0] < r[0] <= s.mjd[-1]]
    assert len(leaps) >= (27 if series == "c04-20" else 22)
    jumps = np.diff(s.dut1)
    big = s.mjd[1:][np.abs(jumps) > 0.5]
    assert list(big) == leaps
    for mjd in leaps:
        i = int(np.searchsorted(s.mjd, mjd))
        lod = 0.5 * (s.lod[i] + s.lod[i - 1])
        assert abs(jumps[i - 1] - (1.0 - lod)) < 1e-3, (mjd, jumps[i - 1], lod)
    e = EOP.from_series(s)
    for mjd in leaps:
        u = e.ut1_minus_tai(np.array([mjd - 1e-6, mjd]))
        assert abs(u[1] - u[0]) < 1e-8
        assert e.tai_minus_utc(mjd) - e.tai_minus_utc(mjd - 1e-6) == pytest.approx(1.0, abs=1e-9)


def test_eop_refuses_a_leap_second_erfa_does_not_know():
    """A series whose UT1-UTC jumps by 1 s on a day without a leap second (as a newer EOP file would
    next to an older leap-second table) is refused with a message naming the date."""
    good = eop_table("c04-20")
    sel = (good.mjd >= 60000) & (good.mjd < 60020)
    dut1 = good.dut1[sel].copy()
    dut1[10:] += 1.0  # a "leap second" at the end of MJD 60009
    with pytest.raises(ValueError, match=r"UT1-TAI changes by \+(0\.99|1\.00)\d* s from MJD 60009 to 60010.*leap-second"):
        EOP(good.mjd[sel], good.xp[sel], good.yp[sel], dut1, good.lod[sel], good.dx[sel], good.dy[sel], "test")


def test_install_merges_and_validates():
    """A newer table (here: an invented leap second on 2031-01-01) is merged into ERFA's; a table that
    contradicts ERFA's is refused; the original table is restored afterwards."""
    saved, saved_exp = erfa.leap_seconds.get().copy(), erfa.leap_seconds.expires
    base = read_leap_seconds()
    head = "#  File expires on 28 June 2032\n" + "".join(
        f"    {m:.1f}    1  {mo}  {y}       {d:g}\n" for m, y, mo, d in zip(base.mjd, base.year, base.month,
                                                                           base.tai_utc))

    def row(y, mo, dat):
        return f"    {erfa.cal2jd(y, mo, 1)[1]:.1f}    1  {mo}  {y}       {dat}\n"

    try:
        timescales.install_leap_seconds(parse_leap_seconds(head + row(2031, 1, 38), "invented"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", erfa.ErfaWarning)
            assert erfa.dat(2031, 1, 1, 0.0) == 38.0 and erfa.dat(2030, 12, 31, 0.0) == 37.0
        assert erfa.leap_seconds.expires == dt.datetime(2032, 6, 28)
        assert _tai_minus_utc("2031-06-01T00:00:00") == 38.0
        # a table that puts that leap second half a year later contradicts ERFA's (now merged) table
        with pytest.raises(ValueError):
            timescales.install_leap_seconds(parse_leap_seconds(head + row(2031, 7, 38), "contradicting"))
    finally:
        erfa.leap_seconds.set(saved)
        erfa.leap_seconds._expires = saved_exp
        timescales._LEAP["table"] = read_leap_seconds()
    assert erfa.leap_seconds.get().size == saved.size and _tai_minus_utc("2031-06-01T00:00:00") == 37.0
