"""Multi-segment CCSDS OEM files: reading (tqdyn.readers.oem.read_oem), interpolation across segments and
their continuity (tqdyn.astro.oem_states), the writer's files read back, and the scenario key ``initial.oem``.

Input: ESA's CReMA 2.0 LISA orbits for a November launch (leading, +20 deg), whose files hold two segments:
1169 records to 2048-03-04T23:11:53.47537616 TDB, then 6 records (1.3-d steps) from that epoch to
2048-03-11T13:04:47.99999985 TDB (tests/fixtures/esa-lisa-nov-launch, README.md there: source, commits,
licence); files made from them here (edited text, or written by tqdyn.formats.oem).

References:
(1) the raw text of the files (split here with str.split, independently of the reader and of the ``oem``
    package): record counts, epochs, the two states at the shared epoch (2.1 cm apart in position, equal in
    velocity), the printed digits (6 decimals of km: 1 mm; 7 of km/s: 0.1 mm/s);
(2) the ``oem`` package (PyPI), which reads both segments too;
(3) the accuracy of the interpolation elsewhere in the file: each record left out and interpolated from
    the others (Hermite 7, as the files say), measured over segment 1 away from the boundary;
(4) the single-segment reading of the same records (a file split into segments must give the states of
    the unsplit one).
Bounds are 3-10x above the values measured (stated with each test).
"""

from __future__ import annotations

import dataclasses
import pathlib

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn.astro import oem_states as st
from tqdyn.formats import oem as fo
from tqdyn.readers import oem as ro

FIX = pathlib.Path(__file__).parent / "fixtures" / "esa-lisa-nov-launch"
TDB = [str(FIX / "tdb" / f"trajectory_out_mida+20deg_cw_sg-2nmss_nov_launch_lisa{i}.oem") for i in (1, 2, 3)]
TCB1 = str(FIX / "tcb" / "trajectory_out_mida+20deg_cw_sg-2nmss_nov_launch_lisa1.oem")
N1, N2 = 1169, 6
T_SHARED = "2048-03-04T23:11:53.47537616"
SPAN1 = f"2037-06-11T00:00:00.00000000 .. {T_SHARED} TDB"
SPAN2 = f"{T_SHARED} .. 2048-03-11T13:04:47.99999985 TDB"


def _segments_text(path):
    """[(epoch text, 9 floats), ...] per segment, from the raw text (1)."""
    segs = []
    for line in open(path, encoding="ascii").read().splitlines():
        if line.startswith("META_START"):
            segs.append([])
        parts = line.split()
        if segs and len(parts) == 10 and line[:2] == "20":
            segs[-1].append((parts[0], [float(x) for x in parts[1:]]))
    return segs


def _sec(a1, a2, b1, b2):
    return ((np.asarray(a1) - b1) + (np.asarray(a2) - b2)) * 86400.0


def _one_line(exc_info, path):
    msg = str(exc_info.value)
    assert "\n" not in msg and str(path) in msg and "()" not in msg, msg
    return msg


def _edited(tmp_path, name, edit, src=TDB[0]):
    """A copy of ``src`` whose data/metadata lines of segment 2 pass through ``edit(line) -> line``."""
    out, seg = [], 0
    for line in open(src, encoding="ascii").read().split("\n"):
        seg += line.startswith("META_START")
        out.append(edit(line) if seg == 2 else line)
    p = tmp_path / name
    p.write_text("\n".join(out), encoding="ascii")
    return p


def _shift_x_km(dx_km):
    def edit(line):
        parts = line.split()
        if len(parts) == 10 and line[:2] == "20":
            return line.replace(parts[1], f"{float(parts[1]) + dx_km:.6f}", 1)
        return line
    return edit


@pytest.fixture(scope="module")
def nov():
    return [ro.read_oem(p) for p in TDB]


# ------------------------------------------------------------------ reading

def test_both_segments_are_read(nov):
    """Reference (1), (2): 1169 + 6 records; the joined trajectory holds every record in file order, with
    each segment's rows, span (as the file writes it), interpolation and printed digits; the two states at
    the shared epoch 2.1 cm apart (text: 1, 19, 9 mm per component) and equal in velocity."""
    from oem import OrbitEphemerisMessage

    for path, tr in zip(TDB, nov):
        text = _segments_text(path)
        assert [len(s) for s in text] == [N1, N2]
        assert len(OrbitEphemerisMessage.open(path).segments) == 2
        parts = ro.read_oem_segments(path)
        assert [len(s) for s in parts] == [N1, N2] and all(s.segments == () for s in parts)
        assert len(tr) == N1 + N2 and [s.rows for s in tr.segments] == [(0, N1), (N1, N1 + N2)]
        assert [s.label for s in tr.segments] == [SPAN1, SPAN2]
        assert (tr.interpolation, tr.interpolation_degree) == ("HERMITE", 7) and tr.a is not None
        assert (tr.start, tr.stop) == (parts[0].start, parts[1].stop)
        for s in tr.segments:
            assert s.r_unit == pytest.approx(1e-3, rel=1e-12) and s.v_unit == pytest.approx(1e-4, rel=1e-12)
        np.testing.assert_array_equal(tr.r, np.concatenate([parts[0].r, parts[1].r]))
        (t1, x1), (t2, x2) = text[0][-1], text[1][0]
        assert t1 == t2 == T_SHARED and x1[3:] == x2[3:]
        assert 0.0205 < np.linalg.norm(np.subtract(x1[:3], x2[:3])) * 1e3 < 0.0211
        # the reader's SI values: the same 2.1 cm within float64 at 1.5e11 m (ulp 3e-5 m)
        assert abs(np.linalg.norm(tr.r[N1] - tr.r[N1 - 1]) - np.linalg.norm(np.subtract(x1[:3], x2[:3])) * 1e3) < 1e-4


def test_states_in_each_segment_and_at_the_boundary(nov):
    """At every record epoch the record itself; at the shared epoch segment 2's record (a later segment takes
    over from its start); between records the state of the segment alone (4): windows never mix segments;
    just before the boundary segment 1's last record (the 1-ms left limit, moved back by v dt, agrees to
    0.1 mm (measured) -> bound 1 mm; segment 2's record is 2.1 cm away)."""
    for path, tr in zip(TDB, nov):
        one, two = ro.read_oem_segments(path)
        r, v = st.states_at(tr, tr.jd1, tr.jd2)
        keep = np.r_[0:N1 - 1, N1:N1 + N2]  # the shared epoch gives segment 2's record
        np.testing.assert_array_equal(r[keep], tr.r[keep])
        np.testing.assert_array_equal(v[keep], tr.v[keep])
        np.testing.assert_array_equal(r[N1 - 1], tr.r[N1])
        for seg, rows in ((one, np.arange(N1 - 8, N1 - 1)), (two, np.arange(0, N2 - 1))):
            j1, j2 = seg.jd1[rows], seg.jd2[rows] + 0.37 * np.diff(_sec(seg.jd1, seg.jd2, 0, 0))[rows] / 86400.0
            ra, va = st.states_at(tr, j1, j2)
            rb, vb = st.states_at(seg, j1, j2)
            np.testing.assert_array_equal(ra, rb)
            np.testing.assert_array_equal(va, vb)
        dt = 1e-3
        rl, vl = st.states_at(tr, tr.jd1[N1], tr.jd2[N1] - dt / 86400.0)
        assert np.linalg.norm(rl + vl * dt - tr.r[N1 - 1]) < 1e-3
        assert np.linalg.norm(rl + vl * dt - tr.r[N1]) > 0.02


def _without(tr, i):
    """The joined trajectory without record i (its segments' rows moved up)."""
    keep = np.r_[0:i, i + 1:len(tr)]
    spans = tuple(dataclasses.replace(s, rows=(s.rows[0] - (s.rows[0] > i), s.rows[1] - (s.rows[1] > i)))
                  for s in tr.segments)
    return tr.replace(jd1=tr.jd1[keep], jd2=tr.jd2[keep], r=tr.r[keep], v=tr.v[keep], a=None, segments=spans)


def _leave_one_out(tr, rows):
    out = []
    for i in rows:
        r, v = st.states_at(_without(tr, i), tr.jd1[i], tr.jd2[i])
        out.append((np.linalg.norm(r - tr.r[i]), np.linalg.norm(v - tr.v[i])))
    return np.array(out)


def test_interpolation_near_the_boundary_as_accurate_as_elsewhere(nov, record_number):
    """Reference (3).  The 4 records on each side of the boundary, each left out and interpolated from the
    joined file (the windows then end at the boundary), miss by at most 171 / 163 / 208 m and 1.5e-3 /
    1.5e-3 / 1.7e-3 m/s (lisa1/2/3, measured; the worst: segment 1's second-to-last record, one of the
    dense-output records that miss by ~150 m anywhere, with a window of 3 records before it and 1 after),
    while every 7th record elsewhere in segment 1 misses by up to 178-182 m (median 106-125 m) and 6.4e-4 m/s:
    bounds 1.5x the elsewhere maximum in position, 5e-3 m/s.  Segment 2's records (1.3-d steps) miss by <= 30 m.
    A window crossing the boundary (segment 1's records but its last, then segment 2's) would move the
    states of segment 1's last interval by <= 27 m and 3.8e-4 m/s (measured), inside the 182 m / 6.4e-4
    m/s, so windows inside one segment lose nothing visible."""
    seen = {k: [] for k in ("near_r_max", "near_v_max", "far_r_max", "far_r_median", "far_v_max", "crossing_r_max",
                            "crossing_v_max")}
    for tr in nov:
        near = _leave_one_out(tr, list(range(N1 - 5, N1 - 1)) + list(range(N1 + 1, N1 + 5)))
        far = _leave_one_out(tr, range(1, N1 - 5, 7))
        assert near[:, 0].max() < 1.5 * far[:, 0].max() and far[:, 0].max() < 250.0
        assert near[:, 1].max() < 5e-3 and near[4:, 0].max() < 100.0
        crossing = tr.replace(jd1=np.delete(tr.jd1, N1 - 1), jd2=np.delete(tr.jd2, N1 - 1),
                              r=np.delete(tr.r, N1 - 1, 0), v=np.delete(tr.v, N1 - 1, 0), a=None, segments=())
        frac = np.linspace(0.05, 0.95, 19)
        j2 = tr.jd2[N1 - 2] + frac * _sec(tr.jd1[N1 - 1], tr.jd2[N1 - 1], tr.jd1[N1 - 2], tr.jd2[N1 - 2]) / 86400.0
        ra, va = st.states_at(tr, np.full(19, tr.jd1[N1 - 2]), j2)
        rb, vb = st.states_at(crossing, np.full(19, tr.jd1[N1 - 2]), j2)
        assert np.linalg.norm(ra - rb, axis=1).max() < 100.0 and np.linalg.norm(va - vb, axis=1).max() < 2e-3
        for key, x in (("near_r_max", near[:, 0].max()), ("near_v_max", near[:, 1].max()),
                       ("far_r_max", far[:, 0].max()), ("far_r_median", np.median(far[:, 0])),
                       ("far_v_max", far[:, 1].max()), ("crossing_r_max", np.linalg.norm(ra - rb, axis=1).max()),
                       ("crossing_v_max", np.linalg.norm(va - vb, axis=1).max())):
            seen[key].append(float(x))
    for key, xs in seen.items():  # per file (lisa1, lisa2, lisa3)
        record_number(f"oem_segments.{key}", xs, "m/s" if "_v_" in key else "m")


def test_the_tolerance_at_the_boundary(nov, record_number):
    """The continuity tolerance (astro.oem_states module docstring): sqrt(3)/2 (1 mm + 1 mm) of the digits
    plus the largest leave-one-out miss of the 4 records of each segment nearest the boundary: 171 / 163 /
    208 m and 1.6e-3 / 1.7e-3 / 1.9e-3 m/s (measured), 8000 times the 2.1-cm jump; a 1-km shift of segment
    2 is 5-6 times the tolerance."""
    tols = []
    for tr in nov:
        (j, k, p, text), = list(st._takeovers(tr))
        assert (j, k, text) == (0, 1, f"{T_SHARED} TDB") and p == tr.segments[1].start
        miss = [st._leave_one_out(tr, s, p, "HERMITE", 4) for s in (0, 1)]
        tol_r = np.sqrt(3) * 1e-3 + max(m[0] for m in miss)
        assert 100.0 < tol_r < 250.0
        assert st.require_continuous(tr) is tr
        tols.append([float(tol_r), float(np.sqrt(3) * 1e-4 + max(m[1] for m in miss))])
    record_number("oem_segments.boundary_tolerance_r", [t[0] for t in tols], "m")  # per file (lisa1, lisa2, lisa3)
    record_number("oem_segments.boundary_tolerance_v", [t[1] for t in tols], "m/s")


# ------------------------------------------------------------------ refused

def test_a_shifted_segment_is_refused(tmp_path):
    """Segment 2 moved by 1 km (x + 1.000000 km in the text) or after an impulse of 1 cm/s at its start
    (vx + 0.0000100 km/s, x + 1e-5 km/s (t - T)): one line naming the file, both segments, the epoch, the
    difference and the tolerance; read_oem still reads it (the reader does not judge states), every use of it as one
    trajectory refuses it; each segment alone still works."""
    p = _edited(tmp_path, "shift.oem", _shift_x_km(1.0))
    tr = ro.read_oem(p)
    for use in (lambda: st.states_at(tr, tr.jd1[5], tr.jd2[5]), lambda: st.to_heliocentric(tr),
                lambda: st.require_continuous(tr)):
        with pytest.raises(ValueError) as ei:
            use()
        msg = _one_line(ei, p)
        assert (f"segments 1 and 2 differ where they meet ({T_SHARED} TDB): positions by 1000 m; "
                "allowed: <= 170.6 m") in msg
    one, two = ro.read_oem_segments(p)
    assert np.array_equal(st.states_at(two, two.jd1[2], two.jd2[2])[0], two.r[2])

    import datetime as dt

    t0 = dt.datetime.fromisoformat(T_SHARED[:26])

    def manoeuvre(line):  # segment 2 after an impulse of 1 cm/s along x at its start: x + dv (t - T), vx + dv
        parts = line.split()
        if len(parts) == 10 and line[:2] == "20":
            t = (dt.datetime.fromisoformat(parts[0][:26]) - t0).total_seconds()
            line = line.replace(parts[1], f"{float(parts[1]) + 1e-5 * t:.6f}", 1)
            return line.replace(parts[4], f"{float(parts[4]) + 1e-5:.7f}", 1)
        return line

    p = _edited(tmp_path, "dv.oem", manoeuvre)
    with pytest.raises(ValueError) as ei:
        st.states_at(ro.read_oem(p), 2465221.0, 0.0)
    assert "velocities by 0.01 m/s; allowed: <= 0.001637 m/s" in _one_line(ei, p)


@pytest.mark.parametrize("name, edit, why", [
    ("gap.oem", lambda line: "" if line.startswith(T_SHARED) else line,
     "segments 1 and 2 are not continuous: a gap of 113674.905 s (1.31568 d) between them"),
    ("frame.oem", lambda line: line.replace("EME2000", "ICRF"), "REF_FRAME = 'EME2000' and 'ICRF' differ"),
    ("centre.oem", lambda line: line.replace("= SUN", "= EARTH"), "CENTER_NAME = 'SUN' and 'EARTH' differ"),
])
def test_segments_that_cannot_be_one_trajectory(tmp_path, name, edit, why):
    """A gap (segment 2's first record removed), another frame or centre (a valid OEM still): read_oem
    refuses in one line naming the file, both segments and what is allowed; read_oem_segments reads them."""
    p = _edited(tmp_path, name, edit)
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    msg = _one_line(ei, p)
    assert why in msg and "; allowed: segments that join (docs/scenarios.md#oem-files)" in msg
    assert len(ro.read_oem_segments(p)) == 2


@pytest.mark.parametrize("name, edit, why", [
    ("object.oem", lambda line: line.replace("-1000", "-1001"), "differ in OBJECT_ID ('-1000', '-1001')"),
    ("time.oem", lambda line: line.replace("TIME_SYSTEM          = TDB", "TIME_SYSTEM          = TT"),
     "differ in TIME_SYSTEM ('TDB', 'TT')"),
])
def test_segments_of_an_invalid_oem(tmp_path, name, edit, why):
    """Another object or time system in segment 2: not a valid OEM (CCSDS 502.0-B-2 5.1.3; the oem package
    (2) refuses it too): both readers refuse it in one line naming both segments."""
    p = _edited(tmp_path, name, edit)
    for read in (ro.read_oem, ro.read_oem_segments):
        with pytest.raises(ValueError) as ei:
            read(p)
        msg = _one_line(ei, p)
        assert why in msg and "segments 1 and 2 differ in" in msg and "allowed: one object" in msg


@pytest.mark.parametrize("text, ok", [("2048-03-04T23:11:53.475376", True), ("2048-03-04T23:11:53.475377", False)])
def test_the_shared_epoch_written_with_other_digits(tmp_path, text, ok):
    """Segment 2's start (its first record and START_TIME) written with 6 decimals: correctly rounded
    (0.16 us before segment 1's stop, within the 0.5 us of the digits) it is the same epoch and the file
    is joined, segment 1's stop moved to it; 0.84 us after it is a gap."""
    p = _edited(tmp_path, "digits.oem", lambda line: line.replace(T_SHARED, text))
    if ok:
        tr = ro.read_oem(p)
        assert tr.segments[0].stop == tr.segments[1].start and tr.segments[0].stop_text == f"{T_SHARED} TDB"
        st.require_continuous(tr)
    else:
        with pytest.raises(ValueError) as ei:
            ro.read_oem(p)
        assert "are not continuous: a gap of 8.4" in _one_line(ei, p)


def test_segments_out_of_order(tmp_path):
    text = open(TDB[0], encoding="ascii").read()
    i = text.index("META_START", text.index("META_STOP"))
    head = text[:text.index("META_START")]
    p = tmp_path / "swapped.oem"
    p.write_text(head + text[i:] + "\n" + text[text.index("META_START"):i], encoding="ascii")
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    assert (f"segments 1 and 2 overlap: segment 2 starts ({SPAN1.split(' .. ')[0]} TDB) before segment 1 stops "
            f"({SPAN2.split(' .. ')[1]}); allowed: usable spans in time order" in _one_line(ei, p))


# ------------------------------------------------------------------ overlaps, short segments, the writer

def _write(tmp_path, name, tr, parts):
    """Write rows ``parts`` (list of (a, b)) of ``tr`` as segments of one file (16 digits)."""
    segs = [fo.OemSegment("LISA", tr.jd1[a:b], tr.jd2[a:b], tr.r[a:b], tr.v[a:b], center_name="SUN",
                          ref_frame=tr.ref_frame, time_system=tr.time_system) for a, b in parts]
    return fo.write_oem(tmp_path / name, segs, creation_date="2025-01-01T00:00:00")


def test_writer_round_trip_of_both_segments(nov, tmp_path):
    """ESA's two segments written by tqdyn's writer (one file, two segments) and read back: the same spans
    (epochs to the 9 decimals written), the states to 16 digits (<= 1e-4 m, measured 7e-5 m), the same
    interpolated states at 100 epochs across the whole span (<= 1e-3 m)."""
    tr = nov[0]
    p = _write(tmp_path, "both.oem", tr, [(0, N1), (N1, N1 + N2)])
    back = ro.read_oem(p)
    assert [s.rows for s in back.segments] == [(0, N1), (N1, N1 + N2)]
    assert [s.label for s in back.segments] == [f"2037-06-11T00:00:00.000000000 .. {T_SHARED}0 TDB",
                                                f"{T_SHARED}0 .. 2048-03-11T13:04:47.999999850 TDB"]
    assert np.abs(back.r - tr.r).max() < 1e-4 and np.abs(_sec(back.jd1, back.jd2, tr.jd1, tr.jd2)).max() < 1e-12
    span = _sec(*tr.stop, *tr.start)
    j2 = tr.start[1] + np.linspace(0.0, span, 100) / 86400.0
    ra, va = st.states_at(tr, tr.start[0], j2)
    rb, vb = st.states_at(back, tr.start[0], j2)
    assert np.abs(rb - ra).max() < 1e-3 and np.abs(vb - va).max() < 1e-8


def _spliced(tmp_path, seg_a, seg_b, switch):
    """One file of the segments seg_a, seg_b (OemSegment, written by tqdyn's writer) whose records overlap,
    seg_a usable until and seg_b from the epoch text ``switch`` (USEABLE_STOP_TIME, USEABLE_START_TIME)."""
    import re

    ta, tb = (fo.write_oem(tmp_path / f"{x}.part", seg, creation_date="2025-01-01T00:00:00").read_text()
              for x, seg in (("a", seg_a), ("b", seg_b)))
    (a0, a1), (b0, b1) = (re.search(r"START_TIME = (\S+)\nSTOP_TIME = (\S+)", t).groups() for t in (ta, tb))
    ta = ta.replace("\nSTOP_TIME", f"\nUSEABLE_START_TIME = {a0}\nUSEABLE_STOP_TIME = {switch}\nSTOP_TIME", 1)
    tb = tb.replace("\nSTOP_TIME", f"\nUSEABLE_START_TIME = {switch}\nUSEABLE_STOP_TIME = {b1}\nSTOP_TIME", 1)
    p = tmp_path / "spliced.oem"
    p.write_text(ta + tb[tb.index("META_START"):], encoding="ascii")
    return p


def _seg(tr, rows, dx=0.0, jd2=None, r=None, v=None):
    return fo.OemSegment("LISA", tr.jd1[rows], tr.jd2[rows] if jd2 is None else jd2,
                         (tr.r[rows] if r is None else r) + [dx, 0.0, 0.0], tr.v[rows] if v is None else v,
                         ref_frame="EME2000")


def test_overlapping_records_and_a_short_segment(tmp_path):
    """Reference (4): segment 1 of ESA's lisa1 cut into two segments whose records overlap (rows 0-1100 and
    1096-1168, usable until / from record 1098) and into rows 0-1166 and 1166-1168 (a last segment of 3
    records, fewer than the 4 of a Hermite-7 window: its windows take the records of segment 1 before
    it): the states at 200 epochs equal those of the unsplit segment within the 16 digits written
    (measured 3e-5 m) -> 1e-3 m; the oem package (2) reads the overlapping file too."""
    from oem import OrbitEphemerisMessage

    one = ro.read_oem_segments(TDB[0])[0]
    j2 = one.start[1] + np.linspace(0.0, _sec(*one.stop, *one.start), 200) / 86400.0
    ref_r, ref_v = st.states_at(one, one.start[0], j2)
    p = _spliced(tmp_path, _seg(one, np.arange(0, 1101)), _seg(one, np.arange(1096, N1)),
                 ro.epoch_text(one.jd1[1098], one.jd2[1098]))
    assert len(OrbitEphemerisMessage.open(p).segments) == 2
    short = _write(tmp_path, "short.oem", one, [(0, 1167), (1166, N1)])
    for path, sizes in ((p, [1101, 73]), (short, [1167, 3])):
        tr = ro.read_oem(path)
        assert [s.rows[1] - s.rows[0] for s in tr.segments] == sizes
        r, v = st.states_at(tr, one.start[0], j2)
        assert np.abs(r - ref_r).max() < 1e-3 and np.abs(v - ref_v).max() < 1e-8


def test_overlap_without_shared_records(tmp_path):
    """A second segment sampled at segment 1's mid-intervals from record 1100 on (its states: segment 1
    interpolated there), usable from its first record, where segment 1's usable span ends (its records go
    on): the check interpolates segment 1 there (agreement 2e-5 m, measured) and passes; the same second
    segment moved by 1 km is refused there."""
    one = ro.read_oem_segments(TDB[0])[0]
    rows = np.arange(1100, N1 - 1)
    mid2 = one.jd2[rows] + 0.5 * np.diff(_sec(one.jd1, one.jd2, 0, 0))[rows] / 86400.0
    r2, v2 = st.states_at(one, one.jd1[rows], mid2)
    switch = ro.epoch_text(one.jd1[1100], mid2[0])
    for dx, ok in ((0.0, True), (1000.0, False)):
        p = _spliced(tmp_path, _seg(one, np.arange(N1)), _seg(one, rows, dx, jd2=mid2, r=r2, v=v2), switch)
        tr = ro.read_oem(p)
        assert tr.segments[0].stop_text == tr.segments[1].start_text == f"{switch} TDB"
        if ok:
            st.require_continuous(tr)
            q1, q2 = one.jd1[1105], mid2[5] + 0.1  # segment 2's: equal to it alone
            alone = ro.read_oem_segments(p)[1]
            np.testing.assert_array_equal(st.states_at(tr, q1, q2)[0], st.states_at(alone, q1, q2)[0])
        else:
            with pytest.raises(ValueError) as ei:
                st.require_continuous(tr)
            assert f"meet ({switch} TDB): positions by 1000 m" in _one_line(ei, p)


def test_tcb_file_of_two_segments(nov):
    """The TCB copy (1): to TDB, both segments' spans move with the time tags (within the 1-us rounding of
    the TCB text of the TDB file's spans, measured 4e-7 s -> bound 1.5e-6 s) and keep the file's text; the
    state at the shared epoch equals the TDB file's (the records are the same numbers)."""
    h = st.to_heliocentric(ro.read_oem(TCB1), eme2000_frame_bias=False)
    t = nov[0]
    assert h.time_system == "TDB" and h.segments[0].label.endswith("2048-03-04T23:12:28.300914 TCB")
    for a, b in zip(h.segments, t.segments):
        assert abs(_sec(*a.start, *b.start)) < 1.5e-6 and abs(_sec(*a.stop, *b.stop)) < 1.5e-6
    r, _ = st.states_at(h, *h.segments[1].start)
    np.testing.assert_array_equal(r, t.r[N1])


def test_no_oem_message_names_a_python_function(nov, tmp_path):
    """Every refusal of an OEM file, through the reader, the states and the writer, in words: no "()"."""
    msgs = []
    cases = [lambda: ro.read_oem(_edited(tmp_path, "f.oem", lambda s: s.replace("EME2000", "ICRF"))),
             lambda: st.states_at(ro.read_oem(_edited(tmp_path, "s.oem", _shift_x_km(1.0))), 2465221.0, 0.0),
             lambda: st.states_at(nov[0], 2400000.0, 0.0),
             lambda: st.states_at(nov[0].replace(interpolation=None, segments=()), 2465221.0),
             lambda: st.states_at(nov[0].replace(interpolation_degree=None, segments=()), 2465221.0),
             lambda: st.states_at(nov[0], 2465221.0, method="SPLINE"),
             lambda: ro.read_oem(tmp_path / "missing.oem"),
             lambda: fo.write_oem(tmp_path / "x.oem", [fo.OemSegment("A", [2460000.0], [0.0], [[1, 2, 3]],
                                                                     [[1, 2, 3]]),
                                                        fo.OemSegment("B", [2460001.0], [0.0], [[1, 2, 3]],
                                                                      [[1, 2, 3]])])]
    for case in cases:
        with pytest.raises((ValueError, OSError)) as ei:
            case()
        msgs.append(str(ei.value))
    assert len(msgs) == len(cases) and not [m for m in msgs if "()" in m or "\n" in m], msgs


# ------------------------------------------------------------------ the scenario key initial.oem

def _oem_list(files):
    return "initial.oem=[" + ", ".join(f'"{f}"' for f in files) + "]"


@pytest.mark.parametrize("epoch, segment", [(None, 0), ("2048-03-07T12:00:00", 1), ("2048-03-04T23:11:53.5", 1),
                                            ("2048-03-04T23:11:53", 0)])
def test_cli_runs_from_any_epoch_of_both_segments(tmp_path, capsys, epoch, segment):
    """``tqdyn run lisa-esa --duration 30d --set 'initial.oem=[...]'`` with the three two-segment files:
    the default epoch (their first record), inside segment 2, 25 ms after and 0.48 s before the shared
    epoch (the runs go past the files' end); the initial states are the files' states at the epoch
    (the files' "EME2000" read as ICRF, as lisa-esa reads them; 16 digits: 1e-5 m, 1e-12 m/s): the first
    record, and otherwise the segment's own interpolation (4), and the self-gravity ramp spans both
    segments."""
    from tqdyn.formats.trajectory import read_trajectory
    from tqdyn.scenario import load_scenario

    out = tmp_path / "run.h5"
    over = [_oem_list(TDB)] + ([f"scenario.epoch_tdb={epoch}"] if epoch else [])
    args = ["run", "lisa-esa", "--duration", "30d", "--output", str(out)]
    for o in over:
        args += ["--set", o]
    status, _, err = run_cli(args, capsys)
    assert status == 0, err
    tr = read_trajectory(out)
    scen = load_scenario("lisa-esa", over)
    for k, path in enumerate(TDB):
        seg = st.to_heliocentric(ro.read_oem_segments(path)[segment], eme2000_frame_bias=False)
        r, v = (seg.r[0], seg.v[0]) if epoch is None else st.states_at(seg, *scen.epoch.tdb)
        assert np.abs(tr["sat/r"][0, k] - r).max() < 1e-5
        assert np.abs(tr["sat/v"][0, k] - v).max() < 1e-12
    assert scen.spacecraft.self_gravity_center_span == ("2037-06-11T00:00:00.000000000 TDB",
                                                       "2048-03-11T13:04:47.999999850 TDB")


def test_cli_refuses_a_discontinuous_file_in_one_line(tmp_path, capsys):
    bad = _edited(tmp_path, "shift.oem", _shift_x_km(1.0))
    out = tmp_path / "x.h5"
    status, _, err = run_cli(["run", "lisa-esa", "--duration", "30d", "--set", _oem_list([bad] + TDB[1:]),
                              "--output", str(out)], capsys)
    assert status == 2 and err.count("\n") == 1 and err.startswith("tqdyn: error: initial.oem.1: "), err
    assert str(bad) in err and T_SHARED in err and "differ where they meet" in err and "()" not in err
    assert not out.exists()
