"""Tests of the CCSDS OEM reader (tqdyn.readers.oem), the states from it (tqdyn.astro.oem_states) and the
writer (tqdyn.formats.oem).

Input: ESA's LISA science orbits shipped in tqdyn/data/esa-lisa-orbits (CReMA 2.0,
TDB files and the copies with TCB time tags; data/SOURCES.md), and OEM files
written here (temporary directories).

References:
(1) the raw text of ESA's files (split here with str.split, independently of the
    ``oem`` package and of the reader);
(2) the ``oem`` package (PyPI, 0.4.x): its parsed epochs (astropy Time), states
    and its own Hermite interpolation (monomial basis, velocity from the
    accelerations when the file has them);
(3) the IAU 2006 frame bias (IERS Conventions 2010, TN36 eq. 5.21 with
    xi0 = -16.617 mas, eta0 = -6.8192 mas, da0 = -14.6 mas);
(4) IAU 2006 Resolution B3 (TDB - TCB) and ERFA's ``tcbtdb``;
(5) an exact circular Kepler orbit sampled at ESA's epochs (numpy, this file),
    for the interpolation error free of the files' own noise.
Bounds are 3-10x above the values measured (stated with each test).
"""

from __future__ import annotations

import os

import erfa
import numpy as np
import pytest

from tqdyn.astro import oem_states as st
from tqdyn.astro import timescales as ts
from tqdyn.astro.constants import AU_M, L_B
from tqdyn.formats import oem as fo
from tqdyn.formats.trajectory import OutputError
from tqdyn.readers import oem as ro

MAS = np.pi / 648000.0 / 1000.0  # one milliarcsecond [rad]
TDB_FILES = ro.esa_lisa_orbit_files("TDB")
TCB_FILES = ro.esa_lisa_orbit_files("TCB")
N_RECORDS = 1169  # data lines of each ESA file (1)


def _records(path):
    """(epoch text, 9 floats) of every data line of an ESA file, from the raw text (1)."""
    out = []
    with open(path, encoding="ascii") as fh:
        lines = fh.read().splitlines()
    stop = lines.index("META_STOP")
    for line in lines[stop + 1:]:
        parts = line.split()
        if len(parts) == 10:
            out.append((parts[0], [float(x) for x in parts[1:]]))
    return out


@pytest.fixture(scope="module")
def esa():
    return [ro.read_oem(p) for p in TDB_FILES]


@pytest.fixture(scope="module")
def esa_tcb():
    return [ro.read_oem(p) for p in TCB_FILES]


def _sec(a1, a2, b1, b2):
    return ((np.asarray(a1) - b1) + (np.asarray(a2) - b2)) * 86400.0


# ------------------------------------------------------------------ reader vs the text

def _file_id(path):
    return os.path.basename(os.path.dirname(path)) + "/" + os.path.basename(path)[-9:]


@pytest.mark.parametrize("path", TDB_FILES + TCB_FILES, ids=_file_id)
def test_reader_matches_the_text_of_esa_files(path):
    """Reference (1): first and last records, count, units (km -> m, km/s -> m/s, km/s^2 -> m/s^2)."""
    rec = _records(path)
    tr = ro.read_oem(path)
    assert len(rec) == len(tr) == N_RECORDS
    assert (tr.object_name, tr.object_id, tr.center_name, tr.ref_frame) == ("LISA", "-1000", "SUN", "EME2000")
    assert tr.time_system == ("TCB" if os.sep + "tcb" + os.sep in path else "TDB")
    assert (tr.interpolation, tr.interpolation_degree) == ("HERMITE", 7)
    assert tr.a is not None
    for k in (0, -1):
        text, vals = rec[k]
        # positions/velocities: float(text) * 1000, at most 1 rounding of the product
        np.testing.assert_allclose(tr.r[k], np.array(vals[0:3]) * 1e3, rtol=2.3e-16, atol=0)
        np.testing.assert_allclose(tr.v[k], np.array(vals[3:6]) * 1e3, rtol=2.3e-16, atol=0)
        np.testing.assert_allclose(tr.a[k], np.array(vals[6:9]) * 1e3, rtol=2.3e-16, atol=0)
        # epoch: ERFA's dtf2d of the same text (its seconds as a float64) -> within 1e-10 s
        date, time = text.split("T")
        y, mo, d = (int(x) for x in date.split("-"))
        h, mi, s = time.split(":")
        j1, j2 = erfa.dtf2d(tr.time_system, y, mo, d, int(h), int(mi), float(s))
        assert abs(_sec(tr.jd1[k], tr.jd2[k], j1, j2)) < 1e-10
    assert rec[0][0] in ("2036-12-09T00:00:00.00000094", "2036-12-09T00:00:29.327664")


def test_esa_first_records_differ_between_spacecraft(esa):
    """Reference (1): the three files hold three spacecraft although all say OBJECT_NAME = LISA, OBJECT_ID = -1000."""
    assert {t.object_name for t in esa} == {"LISA"}
    d12 = np.linalg.norm(esa[0].r[0] - esa[1].r[0])
    # the LISA arms: 2.5e9 m +- 1 %
    assert 2.4e9 < d12 < 2.6e9


def test_epochs_kept_at_full_precision(esa):
    """Epochs from the text with exact decimal arithmetic: |jd2| <= 0.5, jd1 integral; the oem package's
    astropy epochs (2) agree within 9.6e-12 s (measured) -> bound 5e-11 s; the 8 decimals survive
    (2036-12-09T00:00:00.00000094: 0.94 us after midnight, to 1e-12 s)."""
    from oem import OrbitEphemerisMessage

    tr = esa[0]
    assert np.all(tr.jd1 == np.round(tr.jd1)) and np.all(np.abs(tr.jd2) <= 0.5)
    assert abs(_sec(tr.jd1[0], tr.jd2[0], 2465036.5, 0.0) - 0.94e-6) < 1e-12
    seg = OrbitEphemerisMessage.open(TDB_FILES[0]).segments[0]
    ep = seg._state_data[0]
    d = np.array([_sec(e.jd1, e.jd2, a, b) for e, a, b in zip(ep, tr.jd1, tr.jd2)])
    assert np.abs(d).max() < 5e-11
    # sampling as stated in data/SOURCES.md: steps 2.30 .. 3.40 d, median 3.37 d
    h = np.diff(_sec(tr.jd1, tr.jd2, tr.jd1[0], tr.jd2[0])) / 86400.0
    assert 2.30 < h.min() < 2.31 and 3.40 < h.max() < 3.41 and abs(np.median(h) - 3.37) < 0.01


def test_shipped_files_match_sources_md():
    """src/tqdyn/data/SOURCES.md: bytes and sha256 of every shipped esa-lisa-orbits file (copied unchanged
    from esa/lisa-orbit-files), and its parse check (lisa1: first record x, vx, ax; last epoch)."""
    import hashlib
    import re

    data = os.path.dirname(os.path.dirname(TDB_FILES[0]))
    table = open(os.path.join(data, "SOURCES.md"), encoding="utf-8").read()
    rows = re.findall(r"^\| (esa-lisa-orbits/\S+) \| (\d+) \| ([0-9a-f]{64}) \|$", table, flags=re.M)
    assert len(rows) == 8
    for name, size, sha in rows:
        blob = open(os.path.join(data, name), "rb").read()
        assert len(blob) == int(size) and hashlib.sha256(blob).hexdigest() == sha, name
    tr = ro.read_oem(TDB_FILES[0])
    rec = _records(TDB_FILES[0])
    assert rec[0][0] == "2036-12-09T00:00:00.00000094" and rec[-1][0] == "2047-09-09T13:04:48.00000111"
    assert (rec[0][1][0], rec[0][1][3], rec[0][1][6]) == (80831155.766481, -25.1637279, -0.000003230390)
    assert abs(tr.r[0, 0] - 80831155766.481) < 2e-5 and abs(tr.v[0, 0] + 25163.7279) < 4e-12


# ------------------------------------------------------------------ frame bias

def test_frame_bias_is_the_iau2006_rotation():
    """Reference (3): B = R1(-eta0) R2(xi0) R3(da0) (TN36 eq. 5.21) against erfa.bp06's rb: they differ by
    9.8e-13 rad = 0.2 uas (measured; bp06 takes the bias from the Fukushima-Williams angles at J2000,
    eta0 = phib - eps0 = -6.819 mas instead of -6.8192 mas) -> bound 5e-12; rotation angle 23.147 mas
    (sqrt(xi0^2 + eta0^2 + da0^2)); the rotation vector of B is (-eta0, xi0, da0) (sign: r_EME = B r_ICRS)."""
    xi0, eta0, da0 = -16.617 * MAS, -6.8192 * MAS, -14.6 * MAS
    b_ref = erfa.rx(-eta0, erfa.ry(xi0, erfa.rz(da0, np.eye(3))))
    B = st.frame_bias_matrix()
    assert np.abs(B - b_ref).max() < 5e-12
    np.testing.assert_allclose(B @ B.T, np.eye(3), atol=1e-15)
    w = np.array([B[1, 2] - B[2, 1], B[2, 0] - B[0, 2], B[0, 1] - B[1, 0]]) / 2
    np.testing.assert_allclose(w / MAS, [-eta0 / MAS, xi0 / MAS, da0 / MAS], atol=1e-3)
    angle = np.linalg.norm(w) / MAS
    assert abs(angle - np.sqrt(16.617**2 + 6.8192**2 + 14.6**2)) < 1e-3
    assert abs(angle - 23.147) < 1e-3


def test_frame_bias_moves_esa_positions_by_up_to_17_km(esa):
    """EME2000 -> ICRF on ESA's lisa1: |r_ICRF - r_EME2000| <= angle |r| (23.147 mas = 16.79 km at 1 au);
    measured 5.0 .. 16.84 km over the 10.75 years (|r| up to 1.007 au); |r| unchanged to 1e-4 m."""
    tr = esa[0]
    h = st.to_heliocentric(tr)
    assert h.ref_frame == "ICRF" and h.time_system == "TDB" and h.center_name == "SUN"
    dr = np.linalg.norm(h.r - tr.r, axis=1)
    rn = np.linalg.norm(tr.r, axis=1)
    assert np.all(dr <= 23.148 * MAS * rn)
    assert 16.7e3 < dr.max() < 16.9e3 and 4.9e3 < dr.min() < 5.1e3
    assert abs(23.147 * MAS * AU_M - 16.79e3) < 10
    assert np.abs(np.linalg.norm(h.r, axis=1) - rn).max() < 1e-4
    np.testing.assert_allclose(h.r, tr.r @ st.frame_bias_matrix(), rtol=0, atol=1e-4)  # r_ICRS = B^T r


# ------------------------------------------------------------------ interpolation

def _circular(t):
    """Exact circular heliocentric orbit at 1 au: r, v at the times t [s] (reference (5))."""
    gm = 1.32712440041e20
    n = np.sqrt(gm / AU_M**3)
    th = n * t + 0.3
    c, s = np.cos(th), np.sin(th)
    z = np.zeros_like(t)
    return (np.stack([AU_M * c, AU_M * s, z], -1), np.stack([-AU_M * n * s, AU_M * n * c, z], -1))


def _leave_one_out(tr, ks):
    err_r, err_v = [], []
    for k in ks:
        keep = np.r_[0:k, k + 1:len(tr)]
        sub = tr.replace(jd1=tr.jd1[keep], jd2=tr.jd2[keep], r=tr.r[keep], v=tr.v[keep], a=None)
        r, v = st.states_at(sub, tr.jd1[k], tr.jd2[k])
        err_r.append(np.linalg.norm(r - tr.r[k]))
        err_v.append(np.linalg.norm(v - tr.v[k]))
    return np.array(err_r), np.array(err_v)


def test_interpolation_returns_the_records_at_their_epochs(esa):
    """At a record's epoch, the record itself (exactly), first and last included; array shapes."""
    tr = esa[0]
    r, v = st.states_at(tr, tr.jd1, tr.jd2)
    assert r.shape == v.shape == (N_RECORDS, 3)
    assert np.array_equal(r, tr.r) and np.array_equal(v, tr.v)
    r1, v1 = st.states_at(tr, tr.jd1[5], tr.jd2[5])
    assert r1.shape == v1.shape == (3,)
    r2, _ = st.states_at(tr, np.full((2, 3), tr.jd1[7]), tr.jd2[7])
    assert r2.shape == (2, 3, 3) and np.array_equal(r2[1, 2], tr.r[7])


def test_hermite_on_an_exact_orbit_at_esa_epochs(esa):
    """Reference (5): the degree-7 Hermite (4 records) of an exact circular orbit at ESA's epochs.
    Leave-one-out (record k from k-2, k-1, k+1, k+2): measured max 8.4 mm -> bound 5 cm; between records
    (mid-interval, all records): measured 0.4 mm, 2.5e-9 m/s -> bounds 3 mm, 2e-8 m/s.  Rounded to the
    files' digits (1e-6 km, 1e-7 km/s): leave-one-out max 17 m, mid-interval max 6.4 m -> bounds 100 m, 30 m
    (the 0.1 mm/s of the velocities dominates)."""
    tr = esa[0]
    t = _sec(tr.jd1, tr.jd2, tr.jd1[0], tr.jd2[0])
    r, v = _circular(t)
    exact = tr.replace(r=r, v=v, a=None)
    ks = np.arange(3, len(tr) - 3, 3)
    er, _ = _leave_one_out(exact, ks)
    assert er.max() < 0.05
    tm = 0.5 * (t[:-1] + t[1:])
    rm, vm = st.states_at(exact, tr.jd1[:-1], tr.jd2[:-1] + 0.5 * np.diff(t) / 86400.0)
    rt, vt = _circular(tm)
    assert np.linalg.norm(rm - rt, axis=1).max() < 3e-3
    assert np.linalg.norm(vm - vt, axis=1).max() < 2e-8
    rounded = tr.replace(r=np.round(r / 1e3, 6) * 1e3, v=np.round(v / 1e3, 7) * 1e3, a=None)
    er2, _ = _leave_one_out(rounded, ks)
    assert 1.0 < er2.max() < 100.0
    rm2, _ = st.states_at(rounded, tr.jd1[:-1], tr.jd2[:-1] + 0.5 * np.diff(t) / 86400.0)
    assert np.linalg.norm(rm2 - rt, axis=1).max() < 30.0


def test_leave_one_out_on_esa_files(esa):
    """ESA's records interpolated from their neighbours (each k, Hermite 7 from k-2, k-1, k+1, k+2):
    measured max 189 m, median ~38 m (lisa1), ~150 m at the 2nd and 3rd dense-output records of each
    integrator step, 15-25 m at the others; velocity max 4.3e-4 m/s -> bounds 1 km, 3e-3 m/s.  The
    records agree with each other to ~100 m (ESA's tolerance 1e-9), far above the 8 mm of the
    interpolation itself (test above)."""
    tr = esa[0]
    ks = np.arange(3, len(tr) - 3)
    er, ev = _leave_one_out(tr, ks)
    assert er.max() < 1000.0 and 10.0 < np.median(er) < 200.0
    assert ev.max() < 3e-3
    by_phase = [np.median(er[ks % 4 == j]) for j in range(4)]
    assert max(by_phase[2], by_phase[3]) > 3 * max(by_phase[0], by_phase[1])


def test_interpolation_agrees_with_the_oem_package(esa):
    """Reference (2): oem's EphemerisSegment(epoch) at 32 mid-intervals of lisa1: positions agree to
    0.12 mm (measured; oem solves a monomial Vandermonde system) -> bound 1 mm; velocities to 1.4e-3 m/s
    (oem's velocity is the Hermite of velocity + acceleration, ours the derivative of the position
    polynomial) -> bound 1e-2 m/s.  oem refuses the last record: its STOP_TIME is truncated to the
    microsecond (2047-09-09T13:04:48.000001 < 13:04:48.00000111)."""
    from astropy.time import Time
    from oem import OrbitEphemerisMessage

    tr = esa[0]
    seg = OrbitEphemerisMessage.open(TDB_FILES[0]).segments[0]
    dr, dv = [], []
    for k in range(5, len(tr) - 5, 37):
        j1 = tr.jd1[k]
        j2 = tr.jd2[k] + 0.5 * ((tr.jd1[k + 1] - tr.jd1[k]) + (tr.jd2[k + 1] - tr.jd2[k]))
        r, v = st.states_at(tr, j1, j2)
        s = seg(Time(j1, j2, format="jd", scale="tdb"))
        dr.append(np.linalg.norm(s.position * 1e3 - r))
        dv.append(np.linalg.norm(s.velocity * 1e3 - v))
    assert len(dr) == 32 and max(dr) < 1e-3 and max(dv) < 1e-2
    last = seg._state_data[0][-1]
    with pytest.raises(ValueError):
        seg(last)
    r, v = st.states_at(tr, tr.jd1[-1], tr.jd2[-1])
    assert np.array_equal(r, tr.r[-1])


def test_lagrange_and_linear(esa):
    """LAGRANGE of degree n-1 through n records reproduces a polynomial of that degree exactly
    (to rounding: < 1e-6 m on 1e11 m); LINEAR at mid-interval = the mean of the two records."""
    tr = esa[0]
    t = _sec(tr.jd1, tr.jd2, tr.jd1[0], tr.jd2[0])
    tt = t / 1e6
    poly = np.stack([1e11 + 3e9 * tt - 2e7 * tt**2 + 1e5 * tt**3 - 40 * tt**4 + 0.1 * tt**5] * 3, -1)
    lag = tr.replace(r=poly, v=poly * 1e-7, a=None)
    j2 = tr.jd2[10:20] + 0.37 * np.diff(t)[10:20] / 86400.0
    r, _ = st.states_at(lag, tr.jd1[10:20], j2, method="LAGRANGE", degree=5)
    ts = _sec(tr.jd1[10:20], j2, tr.jd1[0], tr.jd2[0]) / 1e6
    ref = 1e11 + 3e9 * ts - 2e7 * ts**2 + 1e5 * ts**3 - 40 * ts**4 + 0.1 * ts**5
    assert np.abs(r[:, 0] - ref).max() < 1e-6 * 1e3  # 1 mm on 1e11 m (measured ~1e-5 m)
    r, v = st.states_at(tr, tr.jd1[3], tr.jd2[3] + 0.5 * np.diff(t)[3] / 86400.0, method="LINEAR")
    np.testing.assert_allclose(r, 0.5 * (tr.r[3] + tr.r[4]), rtol=1e-15)


# ------------------------------------------------------------------ TDB vs TCB

def test_tcb_files_are_the_tdb_orbits_with_tcb_tags(esa, esa_tcb):
    """Reference (1), (4): every state of the TCB files equals the TDB file's, digit for digit: positions
    are NOT scaled to TCB-compatible coordinates (x (1 + L_B) would move them by 2.3 km); the TCB tags
    converted by IAU 2006 B3 equal the TDB tags within 5.0e-7 s (measured: the 6 decimals of the TCB tags;
    mean 4e-9 s) -> bound 1.5e-6 s, while +TDB0 instead of -6.55e-5 s would leave 1.31e-4 s; the TDB
    file interpolated at the converted tags gives the TCB records within 15 mm (measured, 30 km/s x 0.5 us)
    -> bound 5 cm."""
    for a, b in zip(esa, esa_tcb):
        assert b.time_system == "TCB" and len(a) == len(b)
        assert np.array_equal(a.r, b.r) and np.array_equal(a.v, b.v) and np.array_equal(a.a, b.a)
        assert 2.2e3 < L_B * np.linalg.norm(a.r, axis=1).max() < 2.4e3
        raw = _sec(b.jd1, b.jd2, a.jd1, a.jd2)
        assert 29.3 < raw[0] < 29.4 and 34.5 < raw[-1] < 34.6  # TCB - TDB grows by L_B ~ 0.49 s/yr
        h = st.to_heliocentric(b)
        assert h.time_system == "TDB" and h.ref_frame == "ICRF"
        d = _sec(h.jd1, h.jd2, a.jd1, a.jd2)
        assert np.abs(d).max() < 1.5e-6
        assert np.abs(d - 2 * ts.TDB0_S).max() > 1e-4
        r, _ = st.states_at(a, h.jd1[1:-1], h.jd2[1:-1])
        assert np.linalg.norm(r - b.r[1:-1], axis=1).max() < 0.05
        # scaled conversion, if asked for: r (1 - L_B)
        hs = st.to_heliocentric(b, tcb_scaled_coordinates=True)
        np.testing.assert_allclose(hs.r, h.r * (1 - L_B), rtol=1e-15)


def test_tcb_to_tdb_against_erfa(esa_tcb):
    """Reference (4): erfa.tcbtdb at the 1169 TCB tags: measured 4.8e-12 s -> bound 5e-11 s."""
    b = esa_tcb[0]
    j1, j2 = ts.tcb_to_tdb(b.jd1, b.jd2)
    e1, e2 = erfa.tcbtdb(b.jd1, b.jd2)
    assert np.abs(_sec(j1, j2, e1, e2)).max() < 5e-11


# ------------------------------------------------------------------ writer

def test_writer_round_trip_heliocentric(esa, tmp_path):
    """ESA's lisa1 in tqdyn's heliocentric system (ICRF, TDB) written and read back (by the reader and by
    the oem package (2)): epochs exact (8 decimals fit the 9 written), positions within 7.6e-5 m (measured:
    16 digits of km) -> bound 5e-4 m, velocities 5.5e-12 m/s -> 5e-11 m/s, accelerations 1.3e-18 m/s^2 ->
    1e-17 m/s^2; metadata as written."""
    from oem import OrbitEphemerisMessage

    h = st.to_heliocentric(esa[0])
    seg = fo.OemSegment.heliocentric("LISA1", h.jd1, h.jd2, h.r, h.v, a=h.a)
    p = fo.write_oem(tmp_path / "lisa1.oem", seg, creation_date="2025-01-01T00:00:00")
    back = ro.read_oem(p)
    assert (back.object_name, back.object_id, back.center_name, back.ref_frame, back.time_system) == (
        "LISA1", "LISA1", "SUN", "ICRF", "TDB")
    assert (back.interpolation, back.interpolation_degree) == ("HERMITE", 7)
    assert np.abs(_sec(back.jd1, back.jd2, h.jd1, h.jd2)).max() < 1e-12
    assert np.abs(back.r - h.r).max() < 5e-4
    assert np.abs(back.v - h.v).max() < 5e-11
    assert np.abs(back.a - h.a).max() < 1e-17
    text = p.read_text()
    assert text.startswith("CCSDS_OEM_VERS = 2.0\n")
    first = text.split("META_STOP\n")[1].splitlines()[1]
    assert first.split()[0] == "2036-12-09T00:00:00.000000940"
    assert all(len(x.lstrip("-").split("e")[0].replace(".", "")) == 16 for x in first.split()[1:])
    msg = OrbitEphemerisMessage.open(p)
    states = list(msg.segments[0].states)
    assert len(states) == N_RECORDS
    assert np.abs(np.array([s.position for s in states]) * 1e3 - h.r).max() < 5e-4
    ep = msg.segments[0]._state_data[0]
    assert max(abs(_sec(e.jd1, e.jd2, a, b)) for e, a, b in zip(ep, h.jd1, h.jd2)) < 1e-10
    # our interpolation of the written file = of the original
    r0, v0 = st.states_at(h, h.jd1[100], h.jd2[100] + 1.1)
    r1, v1 = st.states_at(back, h.jd1[100], h.jd2[100] + 1.1)
    assert np.abs(r1 - r0).max() < 1e-3 and np.abs(v1 - v0).max() < 1e-8


def test_writer_round_trip_geocentric_and_epoch_rounding(tmp_path):
    """A geocentric segment (EARTH, GCRF, TT) at epochs that are not whole nanoseconds: read back within
    the 0.5 ns of the 9 decimals written (+ the 2.4 ps of jd2) -> bound 6e-10 s; states to 16 digits."""
    rng = np.random.default_rng(1)
    n = 50
    jd1 = np.full(n, 2460000.0)
    jd2 = np.sort(rng.uniform(-0.5, 0.5, n))
    r = rng.normal(0, 1e8, (n, 3))
    v = rng.normal(0, 1e3, (n, 3))
    seg = fo.OemSegment.geocentric("TQ1", jd1, jd2, r, v)
    p = fo.write_oem(tmp_path / "tq1.oem", seg)
    back = ro.read_oem(p)
    assert (back.center_name, back.ref_frame, back.time_system) == ("EARTH", "GCRF", "TT")
    d = _sec(back.jd1, back.jd2, jd1, jd2)
    assert np.abs(d).max() < 6e-10 and np.abs(d).max() > 1e-11
    np.testing.assert_allclose(back.r, r, rtol=1e-15, atol=1e-9)
    np.testing.assert_allclose(back.v, v, rtol=1e-15, atol=1e-12)
    assert st.to_geocentric(back).ref_frame == "GCRF"
    with pytest.raises(ValueError, match="CENTER_NAME = 'EARTH'"):
        st.to_heliocentric(back)


def test_reader_reads_xml_and_compressed_files(esa, tmp_path):
    """The reader takes what the oem package parses: ESA's lisa1 gzip-compressed (identical arrays), and
    converted to XML by the oem package (2) (its writer keeps 6 decimals of a second and 15 digits:
    epochs within 0.5 us (measured) -> bound 1 us, positions within 1e-14 relative)."""
    import gzip

    from oem import OrbitEphemerisMessage

    gz = tmp_path / "lisa1.oem.gz"
    gz.write_bytes(gzip.compress(open(TDB_FILES[0], "rb").read()))
    t = ro.read_oem(gz)
    assert np.array_equal(t.r, esa[0].r) and np.array_equal(t.jd2, esa[0].jd2)
    xml = tmp_path / "lisa1.xml"
    OrbitEphemerisMessage.convert(TDB_FILES[0], xml, "xml")
    x = ro.read_oem(xml)
    assert (x.ref_frame, x.time_system, x.interpolation, x.interpolation_degree) == ("EME2000", "TDB", "HERMITE", 7)
    assert np.abs(_sec(x.jd1, x.jd2, esa[0].jd1, esa[0].jd2)).max() < 1e-6  # measured 5.0e-7 s
    np.testing.assert_allclose(x.r, esa[0].r, rtol=1e-14)


def test_writer_segments_one_object_per_file(esa, tmp_path):
    """CCSDS 502.0-B-2 5.1.3: one object per OEM.  Two consecutive segments of one object -> one file of 2
    segments (read by both readers); three spacecraft in one file -> ValueError; write_oem_files -> one
    file each."""
    from oem import OrbitEphemerisMessage

    h = st.to_heliocentric(esa[0])
    s1 = fo.OemSegment.heliocentric("LISA1", h.jd1[:600], h.jd2[:600], h.r[:600], h.v[:600])
    s2 = fo.OemSegment.heliocentric("LISA1", h.jd1[600:], h.jd2[600:], h.r[600:], h.v[600:])
    p = fo.write_oem(tmp_path / "two.oem", [s1, s2])
    segs = ro.read_oem_segments(p)
    assert [len(s) for s in segs] == [600, N_RECORDS - 600]
    assert len(OrbitEphemerisMessage.open(p).segments) == 2
    with pytest.raises(ValueError) as ei:  # record 600 follows record 599 a step later: a gap, not one trajectory
        ro.read_oem(p)
    assert "segments 1 and 2 are not continuous: a gap of 291188.098 s (3.37023 d)" in _one_line_error(ei, p)
    with pytest.raises(ValueError, match="segments must follow each other"):
        fo.write_oem(tmp_path / "x.oem", [s2, s1])
    sats = [fo.OemSegment.heliocentric(f"LISA{i + 1}", t.jd1, t.jd2, t.r, t.v) for i, t in enumerate(esa)]
    with pytest.raises(ValueError, match=r"5\.1\.3"):
        fo.write_oem(tmp_path / "all.oem", sats)
    assert not (tmp_path / "all.oem").exists()
    paths = fo.write_oem_files(tmp_path, sats)
    assert [q.name for q in paths] == ["LISA1.oem", "LISA2.oem", "LISA3.oem"]
    for q, t in zip(paths, esa):
        assert np.abs(ro.read_oem(q).r - t.r).max() < 5e-4


def test_writer_is_atomic(esa, tmp_path, monkeypatch):
    """A NaN position raises before anything is written; an existing file stays untouched; a failure
    mid-write (fsync raising) leaves neither a partial file nor the temporary file."""
    h = st.to_heliocentric(esa[0])
    r = h.r.copy()
    r[17, 1] = np.nan
    bad = fo.OemSegment.heliocentric("LISA1", h.jd1, h.jd2, r, h.v)
    dest = tmp_path / "lisa1.oem"
    with pytest.raises(ValueError, match=r"r: non-finite value at index \(17, 1\)"):
        fo.write_oem(dest, bad)
    assert not dest.exists() and list(tmp_path.iterdir()) == []
    dest.write_text("previous content\n")
    with pytest.raises(ValueError):
        fo.write_oem(dest, bad)
    assert dest.read_text() == "previous content\n"
    good = fo.OemSegment.heliocentric("LISA1", h.jd1, h.jd2, h.r, h.v)

    def boom(fd):
        raise OSError("disk full (simulated)")

    monkeypatch.setattr(fo.os, "fsync", boom)
    with pytest.raises(OutputError, match="disk full"):
        fo.write_oem(dest, good)
    assert dest.read_text() == "previous content\n"
    assert sorted(q.name for q in tmp_path.iterdir()) == ["lisa1.oem"]
    monkeypatch.undo()
    fo.write_oem(dest, good)
    assert len(ro.read_oem(dest)) == N_RECORDS


@pytest.mark.parametrize("kw, match", [
    (dict(ref_frame="ITRF"), "ref_frame = 'ITRF' is not supported"),
    (dict(time_system="UTC"), "time_system = 'UTC' is not supported"),
    (dict(interpolation_degree=6), "must be odd"),
    (dict(object_name="a\nb"), "printable ASCII"),
])
def test_writer_rejects_bad_segments(tmp_path, kw, match):
    base = dict(object_name="S", jd1=np.full(4, 2460000.0), jd2=np.arange(4) * 0.1, r=np.ones((4, 3)),
                v=np.ones((4, 3)))
    base.update(kw)
    with pytest.raises(ValueError, match=match):
        fo.write_oem(tmp_path / "s.oem", fo.OemSegment(**base))
    with pytest.raises(ValueError, match="increase strictly"):
        fo.write_oem(tmp_path / "s.oem", fo.OemSegment("S", np.full(3, 2460000.0), np.array([0, 0.2, 0.1]),
                                                       np.ones((3, 3)), np.ones((3, 3))))
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ bad input

def _one_line_error(exc_info, path):
    msg = str(exc_info.value)
    assert "\n" not in msg and str(path) in msg
    assert exc_info.value.__suppress_context__ or exc_info.value.__context__ is None
    return msg


def _edit(tmp_path, old, new, name="edited.oem"):
    text = open(TDB_FILES[0], encoding="ascii").read()
    assert old in text
    p = tmp_path / name
    p.write_text(text.replace(old, new, 1))
    return p


def test_malformed_files(tmp_path):
    """Truncated (mid-line, before META_STOP), garbage text, binary bytes, empty: one-line ValueError naming
    the file, nothing of the oem package's traceback."""
    text = open(TDB_FILES[0], encoding="ascii").read()
    cases = {
        "cut_midline.oem": text[: len(text) // 2],
        "cut_header.oem": text[: text.index("INTERPOLATION ")],
        "garbage.oem": "hello world\nthis is not an OEM\n",
        "empty.oem": "",
    }
    for name, content in cases.items():
        p = tmp_path / name
        p.write_text(content)
        with pytest.raises(ValueError) as ei:
            ro.read_oem(p)
        _one_line_error(ei, p)
    p = tmp_path / "binary.oem"
    p.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    _one_line_error(ei, p)
    # two objects in one file (ESA's lisa1 + lisa2 renamed): not an OEM (CCSDS 502.0-B-2, 5.1.3)
    other = open(TDB_FILES[1], encoding="ascii").read().replace("OBJECT_NAME          = LISA ",
                                                                  "OBJECT_NAME          = LISA2", 1)
    p = tmp_path / "two_objects.oem"
    p.write_text(text + other[other.index("META_START"):])
    with pytest.raises(ValueError) as ei:
        ro.read_oem_segments(p)
    assert "OBJECT_NAME = 'LISA', 'LISA2'); an OEM holds a single object" in _one_line_error(ei, p)
    with pytest.raises(FileNotFoundError, match="OEM file not found"):
        ro.read_oem(tmp_path / "missing.oem")


def test_unsupported_frame_and_time_system(tmp_path):
    p = _edit(tmp_path, "REF_FRAME            = EME2000", "REF_FRAME            = ITRF", "itrf.oem")
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    msg = _one_line_error(ei, p)
    assert "REF_FRAME = 'ITRF' is not supported (did you mean 'ICRF'?) (allowed: EME2000, ICRF, GCRF)" in msg
    p = _edit(tmp_path, "TIME_SYSTEM          = TDB", "TIME_SYSTEM          = UTC", "utc.oem")
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    msg = _one_line_error(ei, p)
    assert "TIME_SYSTEM = 'UTC' is not supported (allowed: TDB, TCB, TT)" in msg  # no name is close to it


def test_non_monotonic_epochs(tmp_path):
    text = open(TDB_FILES[0], encoding="ascii").read().splitlines(keepends=True)
    i = text.index("META_STOP\n") + 10
    text[i], text[i + 1] = text[i + 1], text[i]
    p = tmp_path / "swapped.oem"
    p.write_text("".join(text))
    with pytest.raises(ValueError) as ei:
        ro.read_oem(p)
    msg = _one_line_error(ei, p)
    assert ("epochs not strictly increasing: record 10 epoch = '2037-01-02T16:39:52.48589817' follows record 9 "
            "epoch = '2037-01-06T01:28:05.06634710'") in msg


def test_epoch_outside_span_and_other_caller_errors(esa, tmp_path):
    tr = esa[0]
    with pytest.raises(ValueError) as ei:
        st.states_at(tr, tr.jd1[0], tr.jd2[0] - 1e-6)
    msg = _one_line_error(ei, tr.source)
    assert "is outside the span 2036-12-09T00:00:00.000000940 .. 2047-09-09T13:04:48.000001110 TDB" in msg
    with pytest.raises(ValueError, match="outside the span"):
        st.states_at(tr, tr.jd1[-1] + 1.0, tr.jd2[-1])
    with pytest.raises(ValueError, match="CENTER_NAME = 'SUN', but 'EARTH' is required"):
        ro.require_center(tr, "EARTH")
    assert ro.require_center(tr) is tr
    with pytest.raises(ValueError, match="OBJECT_NAME = 'LISA2' not in the file"):
        ro.read_oem(TDB_FILES[0], object_name="LISA2")
    p = _edit(tmp_path, "INTERPOLATION_DEGREE = 7", "INTERPOLATION_DEGREE = 6", "deg6.oem")
    with pytest.raises(ValueError, match="INTERPOLATION_DEGREE = 6 for HERMITE must be odd"):
        st.states_at(ro.read_oem(p), tr.jd1[5], tr.jd2[5])
