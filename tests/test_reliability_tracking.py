"""Reliability of the tracking input, CCSDS TDM and SP3 files (issue 34, item 3; docs/reliability.md).

Every fault is one edit of a valid file; each case checks the promise of docs/reliability.md: one
line naming the file, the line, the field and what is allowed (readers in-process), and for
``tqdyn od fit`` exit status 2, one ``tqdyn: error:`` line, no output file, and no propagation at all
(``tqdyn.dynamics.propagate`` is replaced by a function that fails the test if called).
References: the Gregorian calendar (30 days in June, 2005 not a leap year); IERS Bulletin C 52 (a
leap second at the end of 2016-12-31, none at the end of 2016-12-30); the measurement file layout of
docs/orbit-determination.md (TT epochs = UTC + 64.184 s in 2004: TAI - UTC = 32 s, TT - TAI =
32.184 s); the columns of the SP3-c format document.
"""

from __future__ import annotations

import re
import types

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn.astro.timescales import Epoch
from tqdyn.formats.od_tdm import measurements_to_tdm, read_measurements_tdm
from tqdyn.formats.tdm import format_tdm, parse_tdm, read_tdm
from tqdyn.readers.sp3 import read_sp3

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")      # tianqin-kepler's
T0 = "2004-06-06T00:01:04.184000000"               # t = 0 s in TT
T1 = "2004-06-06T00:11:04.184000000"               # t = 600 s


def _table(t, typ="slr_range", peer="Yarragadee"):
    t = np.asarray(t, np.float64)
    n = t.size
    return types.SimpleNamespace(t=t, type=np.array([typ] * n), sat=np.zeros(n, int),
                                 peer=np.array([peer] * n), value=np.linspace(1e8, 1.1e8, n),
                                 sigma=np.full(n, 0.01))


def _text(m=6):
    info = {"tracking": "slr", "arc_s": "43200.0", "interval_s": "600.0"}
    # a one-way type: its tags are the table's t (two-way rows are tagged at the station's reception)
    return format_tdm(measurements_to_tdm(_table(np.arange(m) * 600.0, "gnss_pseudorange", "G07"), epoch=EPOCH,
                                          time_scale="TT",
                                          satellite_names=["Sat1", "Sat2", "Sat3"], info=info,
                                          creation_date="2026-01-01T00:00:00"))


def _line_of(text, needle):
    return next(i for i, ln in enumerate(text.splitlines(), 1) if needle in ln)


def _refusal(path):
    with pytest.raises(ValueError) as info:
        read_measurements_tdm(path, epoch=EPOCH, time_scale="TT")
    msg = str(info.value)
    assert "\n" not in msg and len(msg) <= 220, msg
    return msg


@pytest.mark.parametrize("old, new, field, why", [
    (f"RANGE = {T1}", "RANGE = 2004-13-06T00:11:04.184000000", "RANGE", "month 13 is not allowed; allowed: 01-12"),
    (f"RANGE = {T1}", "RANGE = 2004-06-06T25:11:04.184000000", "RANGE", "hour 25 is not allowed; allowed: 00-23"),
    (f"RANGE = {T1}", "RANGE = 2004-06-06T00:60:04.184000000", "RANGE", "minute 60 is not allowed; allowed: 00-59"),
    (f"RANGE = {T1}", "RANGE = 2004-06-31T00:11:04.184000000", "RANGE",
     "day 31 is not allowed; allowed: 01-30 in 2004-06"),
    (f"RANGE = {T1}", "RANGE = 2004-000T00:11:04.184000000", "RANGE",
     "day of year 000 is not allowed; allowed: 001-366 in 2004"),
    (f"RANGE = {T1}", "RANGE = 2005-366T00:11:04.184000000", "RANGE",
     "day of year 366 is not allowed; allowed: 001-365 in 2005"),
    (f"RANGE = {T1}", "RANGE = 2004-06-06T23:59:60.500000000", "RANGE",
     "second 60.5 is not allowed; allowed: 0 <= second < 60 (TT has no leap seconds)"),
    (f"START_TIME = {T0}", "START_TIME = 2004-13-06T00:01:04.184000000", "START_TIME",
     "month 13 is not allowed; allowed: 01-12"),
    (f"STOP_TIME = {T1.replace('00:11', '00:51')}", "STOP_TIME = 2004-06-06T00:51:04.184000000Q", "STOP_TIME",
     "is not YYYY-MM-DDThh:mm:ss[.d] or YYYY-DDDThh:mm:ss[.d]"),
    (f"START_TIME = {T0}", "START_TIME = 2004-06-07T00:01:04.184000000", "STOP_TIME",
     "is before START_TIME '2004-06-07T00:01:04.184000000'; allowed: STOP_TIME >= START_TIME"),
    ("CREATION_DATE = 2026-01-01T00:00:00", "CREATION_DATE = 2026-02-30T00:00:00", "CREATION_DATE",
     "day 30 is not allowed; allowed: 01-28 in 2026-02"),
])
def test_tdm_calendar_and_syntax_refusals(tmp_path, old, new, field, why):
    """An epoch that does not exist (month, day, day of year, hour, minute, a second 60 in TT), a
    reversed START/STOP, a malformed epoch: one line '<file>, line <n>: <field>: ...' at the edited
    line (STOP_TIME's for the reversed span)."""
    text = _text()
    assert old in text
    bad = text.replace(old, new, 1)
    n = _line_of(bad, "STOP_TIME =") if field == "STOP_TIME" else _line_of(bad, new)
    p = tmp_path / "bad.tdm"
    p.write_text(bad)
    msg = _refusal(p)
    assert msg.startswith(f"{p}, line {n}: {field}: "), msg
    assert msg.endswith(why), msg


@pytest.mark.parametrize("value, why", [
    ("1e999", "value '1e999' is not finite; allowed: a number within float64's range (|x| < 1.8e308)"),
    ("nan", "value 'nan' is not a number"),
    ("1e306", "value '1e306' (km) is inf in m; allowed: |value| <= 1.7e305 (km)"),
])
def test_tdm_non_finite_value_refused_at_its_line(tmp_path, value, why):
    """1e999 (inf as a float), nan, and a km value whose metres overflow (1e306 km = 1e309 m >
    1.8e308): refused at the line they are on, not later as an unnamed array element."""
    text = _text()
    lines = text.splitlines()
    n = next(i for i, ln in enumerate(lines, 1) if ln.strip().startswith("RANGE = 2004-06-06T00:21"))
    lines[n - 1] = lines[n - 1].rsplit(" ", 1)[0] + " " + value
    p = tmp_path / "bad.tdm"
    p.write_text("\n".join(lines) + "\n")
    msg = _refusal(p)
    assert msg == f"{p}, line {n}: RANGE: {why}", msg


def test_utc_leap_second_only_where_the_table_has_one():
    """TIME_SYSTEM = UTC: 23:59:60.5 on 2016-12-31 is read (IERS Bulletin C 52); the same on
    2016-12-30, or 23:58:60 on 2016-12-31, is refused naming the rule."""
    from test_tdm import ANNEX_E1

    def with_epoch(e):
        return ANNEX_E1.replace("RECEIVE_FREQ_1 = 2005-159T17:41:01", f"RECEIVE_FREQ_1 = {e}")

    tdm = parse_tdm(with_epoch("2016-12-31T23:59:60.5"), "leap")
    assert tdm.segments[0].data[-1][1] == "2016-12-31T23:59:60.5"
    assert parse_tdm(with_epoch("2016-366T23:59:60.999"), "leap").segments[0].data[-1][1] == "2016-366T23:59:60.999"
    for e in ("2016-12-30T23:59:60.5", "2016-12-31T23:58:60.0", "2016-12-31T23:59:61.0"):
        with pytest.raises(ValueError, match=r"^leap, line 25: RECEIVE_FREQ_1: epoch '.*': second 6\d.* is not allowed; "
                                             r"allowed: 0 <= second < 60 \(60.x only at 23:59 of a UTC day that ends "
                                             r"with a leap second\)$"):
            parse_tdm(with_epoch(e), "leap")


def test_tdm_rows_keep_their_lines(tmp_path):
    """read_measurements_tdm(..., with_lines=True) gives each row the line it came from (the data lines
    of the text); without it the fields are the six of the measurement table."""
    p = tmp_path / "m.tdm"
    text = _text()
    p.write_text(text)
    fields, _ = read_measurements_tdm(p, epoch=EPOCH, time_scale="TT", with_lines=True)
    want = [i for i, ln in enumerate(text.splitlines(), 1) if ln.strip().startswith("RANGE =")]
    assert fields["line"].tolist() == want
    assert "line" not in read_measurements_tdm(p, epoch=EPOCH, time_scale="TT")[0]
    assert read_tdm(p).segments[0].lines == want


# ------------------------------------------------------------------ od fit: epochs against the run


class _Propagated(Exception):
    pass


@pytest.fixture
def no_propagation(monkeypatch):
    """tqdyn.dynamics.propagate replaced: calling it raises _Propagated."""
    from tqdyn import dynamics

    def boom(*a, **k):
        raise _Propagated

    monkeypatch.setattr(dynamics, "propagate", boom)


FIT = ["--set", "run.duration=1d", "--set", "integrator.step=600", "-q"]


def _fit(tmp_path, capsys, t, sat=None, arc="43200.0"):
    meas = _table(t)
    if sat is not None:
        meas.sat = np.asarray(sat)
    info = {"tracking": "slr", "interval_s": "600.0", **({"arc_s": arc} if arc else {})}
    tdm = tmp_path / "m.tdm"
    tdm.write_text(format_tdm(measurements_to_tdm(meas, epoch=EPOCH, time_scale="TT", info=info,
                                                  satellite_names=["Sat1", "Sat2", "Sat3"])))
    out = tmp_path / "est.h5"
    return run_cli(["od", "fit", "tianqin-kepler", str(tdm), "-o", str(out), *FIT], capsys), tdm, out


@pytest.mark.parametrize("t, sat, pattern", [
    ([0, 600, 601, 1200], None, r"line 28: epoch at t = 601 s \(from the scenario epoch\) is \+1 s off the step grid "
                                r"\(integrator.step = 600 s\); allowed: multiples of 600 s$"),
    ([0, 600, 1200, 86400 + 600], None, r"line 29: epoch at t = 87000 s \(from the scenario epoch\) is outside the arc "
                                        r"0..43200 s \(header tqdyn arc_s; the run spans 86400 s\); allowed: epochs in it$"),
    ([-600, 0, 600], None, r"line 26: epoch at t = -600 s \(from the scenario epoch\) is outside the arc 0..43200 s"),
    ([0, 600, 1200], [0, 0, 3], r"line 46: tqdyn sat = 3; allowed: 0..2 \(the scenario's 3 satellites\)$"),
])
def test_fit_refuses_epochs_off_the_run_before_propagating(tmp_path, capsys, no_propagation, t, sat, pattern):
    """An epoch 1 s off the 600 s grid, one beyond the arc (a day after the run's start: today it made
    od fit propagate for minutes), one before the epoch, a satellite the scenario does not have:
    exit 2, one line naming the file's line, no file, and nothing propagated."""
    (status, _, err), tdm, out = _fit(tmp_path, capsys, t, sat)
    assert status == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"tqdyn: error: {tdm}, "), err
    assert re.search(pattern, lines[0]), lines[0]
    assert len(lines[0].replace(str(tdm), "")) <= 170, lines[0]
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["m.tdm"]


def test_fit_without_an_arc_refuses_an_epoch_beyond_the_run(tmp_path, capsys, no_propagation):
    """A file without 'tqdyn arc_s' (its arc is its last epoch): an epoch after the run's 86400 s is
    refused naming the run's span, before any propagation."""
    (status, _, err), tdm, out = _fit(tmp_path, capsys, [0, 600, 86400 + 1200], arc=None)
    assert status == 2
    assert err.strip() == (f"tqdyn: error: {tdm}, line 27: epoch at t = 87600 s (from the scenario epoch) is outside "
                           "the run, 0..86400 s; allowed: epochs in it")
    assert not out.exists()


def test_fit_of_good_epochs_reaches_the_propagation(tmp_path, capsys, no_propagation):
    """The control case: epochs on the grid, inside the arc, of the scenario's satellites pass every
    check, and the fit goes on to propagate (here: the stand-in raises)."""
    with pytest.raises(_Propagated):
        _fit(tmp_path, capsys, [0, 600, 1200, 43200])


# ------------------------------------------------------------------ SP3

def _sp3(tmp_path, old, new):
    from test_od_sp3 import SP3C

    assert old in SP3C
    p = tmp_path / "bad.sp3"
    p.write_text(SP3C.replace(old, new, 1))
    with pytest.raises(ValueError) as info:
        read_sp3(p)
    msg = str(info.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("old, new, expect", [
    ("*  2024  3  1  0  5  0.00000000", "*  2024 13  1  0  5  0.00000000",
     "bad.sp3: line 28: epoch '2024 13  1  0  5  0.00000000': month 13 is not allowed; allowed: 01-12"),
    ("*  2024  3  1  0  5  0.00000000", "*  2024  2 30  0  5  0.00000000",
     "bad.sp3: line 28: epoch '2024  2 30  0  5  0.00000000': day 30 is not allowed; allowed: 01-29 in 2024-02"),
    ("*  2024  3  1  0  5  0.00000000", "*  2024  3  1 24  5  0.00000000",
     "bad.sp3: line 28: epoch '2024  3  1 24  5  0.00000000': hour 24 is not allowed; allowed: 00-23"),
    ("*  2024  3  1  0  5  0.00000000", "*  2024  3  1  0  4 60.00000000",
     "bad.sp3: line 28: epoch '2024  3  1  0  4 60.00000000': second 60 is not allowed; allowed: 0 <= second < 60 "
     "(GPS has no leap seconds)"),
    ("*  2024  3  1  0  5  0.00000000", "*  2024  3  1  0  0  0.00000000",
     "bad.sp3: line 28: epoch '2024  3  1  0  0  0.00000000' is not after the previous epoch; allowed: epochs in "
     "increasing time order"),
    ("## 2303 432000.00000000   300.00000000", "## 2303 432000.00000000     0.00000000",
     "bad.sp3: line 2: epoch interval (columns 25-38) = 0 s is not allowed; allowed: a number of seconds > 0"),
    ("+    3   G01C23  5", "+    0   G01C23  5",
     "bad.sp3: line 3: number of satellites (columns 4-6) = 0 is not allowed; allowed: an integer >= 1"),
    ("PC23  13165.400000", "PC23        nan    ",
     "bad.sp3: line 30: C23 x (columns 5-18) = 'nan' is not a number; allowed: a decimal number in those columns"),
])
def test_sp3_refusals_name_the_line_and_the_field(tmp_path, old, new, expect):
    """SP3 epochs are calendar dates (GPS time: no second 60), in increasing order; the header's
    interval and satellite count are positive; a non-finite coordinate is refused at its line."""
    assert _sp3(tmp_path, old, new) == expect
