"""GNSS transmitters from SP3 files (tqdyn.readers.sp3, tqdyn.od.gnss_sp3, ``--sp3`` of ``tqdyn od``).

The reference files are written here, by hand, in the fixed-width SP3-d / SP3-c layout of the format
documents (S. Hilla, NGS/NOAA, SP3-c 2010, SP3-d 2016): the nominal Walker GPS constellation
(tqdyn.od.measurements_gnss.GPS, analytic circular orbits in the GCRS) sampled every 900 s and
rotated into the ITRS with pyerfa directly (``erfa.c2t06a``, IAU 2006/2000A, with zero polar
motion and UT1 = UTC, i.e. no EOP -- the reader's constellation is then built with ``use_eop=False``),
epochs labelled in GPS time (TT - 51.184 s, calendar by ``erfa.d2dtf``).  Reading them back must give
the Walker states again: the differences are the interpolation error plus the files' 1 mm rounding.
"""

from __future__ import annotations

import erfa
import numpy as np
import pytest
from scipy import stats

from cli_support import run_cli

EPOCH_ISO = "2024-03-01T00:00:00"
STEP = 900.0


def _calendar(jd1, jd2):
    y, mo, d, (h, mi, s, frac) = erfa.d2dtf("TT", 8, jd1, jd2)
    return int(y), int(mo), int(d), int(h), int(mi), s + frac * 1e-8


def write_walker_sp3(path, const, epoch, t0, t1, *, step=STEP, prefix="G", time_system="GPS", missing=()):
    """An SP3-d file of ``const`` sampled at t0..t1 [s TT since ``epoch``], ITRS by erfa.c2t06a
    without EOP; ``missing``: (epoch index, satellite index) written as 0.000000.  Returns t."""
    t = np.arange(t0, t1 + 0.5 * step, step)
    pos, _ = const.states(t)                                   # (n, K, 3) GCRS [m]
    jd1, jd2 = epoch.tt
    tt2 = jd2 + t / 86400.0
    tai1, tai2 = erfa.tttai(np.full_like(t, jd1), tt2)
    utc1, utc2 = erfa.taiutc(tai1, tai2)
    off = {"GPS": 51.184, "BDT": 65.184}[time_system] / 86400.0
    ids = [f"{prefix}{k + 1:02d}" for k in range(pos.shape[1])]
    y, mo, d, h, mi, s = _calendar(jd1, tt2[0] - off)
    lines = [f"#dP{y:4d} {mo:2d} {d:2d} {h:2d} {mi:2d} {s:11.8f} {t.size:7d} ORBIT IGS20 FIT  TST",
             f"## 2300      0.00000000 {step:14.8f} 60370 0.0000000000000"]
    slots = ids + ["  0"] * (85 - len(ids))
    for j in range(0, 85, 17):
        lines.append((f"+  {len(ids):3d}   " if j == 0 else "+        ") + "".join(slots[j:j + 17]))
    lines += [f"%c {prefix}  cc {time_system} ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
              "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
              "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000",
              "%f  0.0000000  0.000000000  0.00000000000  0.000000000000000",
              "%i    0    0    0    0      0      0      0      0         0",
              "%i    0    0    0    0      0      0      0      0         0",
              "/* Walker GPS written by tests/test_od_sp3.py"]
    for i in range(t.size):
        itrs = pos[i] @ erfa.c2t06a(jd1, tt2[i], utc1[i], utc2[i], 0.0, 0.0).T / 1e3   # (K, 3) [km]
        y, mo, d, h, mi, s = _calendar(jd1, tt2[i] - off)
        lines.append(f"*  {y:4d} {mo:2d} {d:2d} {h:2d} {mi:2d} {s:11.8f}")
        for k, sid in enumerate(ids):
            x = (0.0, 0.0, 0.0) if (i, k) in missing else itrs[k]
            lines.append(f"P{sid}{x[0]:14.6f}{x[1]:14.6f}{x[2]:14.6f}{12.345678:14.6f}")
    lines.append("EOF")
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return t


@pytest.fixture(scope="module")
def epoch():
    from tqdyn.astro.timescales import Epoch

    return Epoch.from_utc(EPOCH_ISO)


@pytest.fixture(scope="module")
def walker_file(tmp_path_factory, epoch):
    from tqdyn.od.measurements_gnss import GPS

    path = tmp_path_factory.mktemp("sp3") / "walker.sp3"
    write_walker_sp3(path, GPS, epoch, -2 * 3600.0, 2 * 86400.0)
    return path


def test_walker_sp3_read_back_gives_the_walker_states(walker_file, epoch, record_number):
    """Positions and velocities interpolated from the SP3-d file at 3000 random times against the
    analytic Walker states (module docstring).  Measured: max position error 0.93 mm (the files'
    1 mm rounding; the 10-point interpolation of unrounded samples alone: 9.7e-6 m, 3.5e-8 m/s),
    max velocity error 1.9e-6 m/s.  Bounds: 5 mm, 1e-5 m/s."""
    from tqdyn.od.gnss_sp3 import sp3_constellation
    from tqdyn.od.measurements_gnss import GPS

    c = sp3_constellation(walker_file, epoch, use_eop=False)
    assert c.ids == tuple(f"G{k:02d}" for k in range(1, 25))
    t = np.random.default_rng(1).uniform(c.span[0], c.span[1], 3000)
    r, v = c.states(t)
    r0, v0 = GPS.states(t)
    dr = float(np.max(np.linalg.norm(r - r0, axis=-1)))
    dv = float(np.max(np.linalg.norm(v - v0, axis=-1)))
    record_number("od_sp3.walker_position_error_max_m", dr, "m")
    record_number("od_sp3.walker_velocity_error_max_m_s", dv, "m/s")
    assert dr < 5e-3, dr
    assert dv < 1e-5, dv


def test_consecutive_files_are_joined(tmp_path, walker_file, epoch):
    """The same samples split into two consecutive files (sharing the midnight epoch, as some
    analysis centres' daily files do) and given together give the constellation of the single file
    exactly (the same samples, the same interpolation); BeiDou satellites in a third file stay a
    constellation of their own; a second file that disagrees at the shared epoch by 1 m is refused
    in one line, and a missing day (a gap in the epochs) too."""
    from tqdyn.od.gnss_sp3 import sp3_constellation, sp3_constellations
    from tqdyn.od.measurements_gnss import BEIDOU_MEO, GPS

    day1, day2, bds = tmp_path / "d1.sp3", tmp_path / "d2.sp3", tmp_path / "c.sp3"
    write_walker_sp3(day1, GPS, epoch, -2 * 3600.0, 86400.0)
    write_walker_sp3(day2, GPS, epoch, 86400.0, 2 * 86400.0)
    write_walker_sp3(bds, BEIDOU_MEO, epoch, -2 * 3600.0, 2 * 86400.0, prefix="C")
    one = sp3_constellation(walker_file, epoch, use_eop=False)
    joined, cbd = sp3_constellations([day2, bds, day1], epoch, use_eop=False)      # order: of the first file
    assert joined.ids == one.ids and joined.name == "d1.sp3+d2.sp3" and cbd.ids[0] == "C01"
    assert joined.span == one.span
    t = np.linspace(one.span[0], one.span[1], 500)
    assert np.array_equal(joined.states(t)[0], one.states(t)[0])
    text = day2.read_text().splitlines()
    k = next(i for i, line in enumerate(text) if line.startswith("PG01"))
    text[k] = text[k][:4] + f"{float(text[k][4:18]) + 1e-3:14.6f}" + text[k][18:]      # +1 m in x
    bad = tmp_path / "d2bad.sp3"
    bad.write_text("\n".join(text) + "\n")
    with pytest.raises(ValueError, match=r"^d2bad.sp3: satellite G01 at MJD \d+ \+ \d+ s is 1 m from the earlier "
                                         r"file's position; allowed: files that agree where they overlap$"):
        sp3_constellations([day1, bad], epoch, use_eop=False)
    day3 = tmp_path / "d3.sp3"
    write_walker_sp3(day3, GPS, epoch, 3 * 86400.0, 4 * 86400.0)
    with pytest.raises(ValueError, match=r"^d1.sp3\+d3.sp3: epoch \d+ is 172800 s after the previous one"):
        sp3_constellations([day1, day3], epoch, use_eop=False)


def test_pseudoranges_from_the_sp3_file_match_the_nominal_ones(walker_file, epoch):
    """Pseudoranges at a receiver on a 1e5 km circular orbit (TianQin's radius) over a day from the
    SP3 constellation against the analytic Walker one: same visibility, values equal to < 1 cm
    (measured: 0.79 mm max, the position error above)."""
    from tqdyn.od.gnss_sp3 import sp3_constellation
    from tqdyn.od.measurements_gnss import GPS, pseudorange

    c = sp3_constellation(walker_file, epoch, use_eop=False)
    t = np.arange(0.0, 86400.0, 600.0)
    a, n = 1e8, np.sqrt(3.986004418e14 / 1e8 ** 3)
    r = a * np.stack([np.cos(n * t), 0.6 * np.sin(n * t), 0.8 * np.sin(n * t)], -1)
    v = a * n * np.stack([-np.sin(n * t), 0.6 * np.cos(n * t), 0.8 * np.cos(n * t)], -1)
    o_sp3, o_nom = pseudorange(t, r, v, c), pseudorange(t, r, v, GPS)
    assert np.array_equal(o_sp3.visible, o_nom.visible) and o_nom.visible.sum() > 50
    d = np.abs(o_sp3.value - o_nom.value)[o_nom.visible]
    assert d.max() < 1e-2, d.max()


SP3C = """\
#cP2024  3  1  0  0  0.00000000       3 ORBIT IGS14 HLM  IGS
## 2303 432000.00000000   300.00000000 60370 0.0000000000000
+    3   G01C23  5  0  0  0  0  0  0  0  0  0  0  0  0  0  0
+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         2  2  2  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
%c M  cc GPS ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%f  1.2500000  1.025000000  0.00000000000  0.000000000000000
%f  0.0000000  0.000000000  0.00000000000  0.000000000000000
%i    0    0    0    0      0      0      0      0         0
%i    0    0    0    0      0      0      0      0         0
/* hand-made SP3-c example
/* with absent values
/*
/*
*  2024  3  1  0  0  0.00000000
PG01 -11044.805800 -10475.672350  21929.418200    189.163300 18 18 18 219
PC23  13165.300146  19862.451378 -14418.813690 999999.999999
PG05      0.000000      0.000000      0.000000    -12.000000
VG01   2755.123456  -1234.567890    111.111111      0.000000
*  2024  3  1  0  5  0.00000000
PG01 -11044.700000 999999.999999  21929.400000    189.163400
PC23  13165.400000  19862.500000 -14418.900000    -45.678900
PG05  20000.000000 -10000.000000   5000.000000      0.000000
*  2024  3  1  0 10  0.00000000
PG01 -11044.600000 -10475.600000  21929.300000    189.163500
PC23  13165.500000  19862.600000 -14419.000000    -45.679000
EOF
"""


def test_sp3c_fields_and_absent_values(tmp_path):
    """A hand-made SP3-c file (the format document's layout, values typed here): header fields,
    positions km -> m and clocks microseconds -> s as typed; 0.000000 and 999999.999999 (position
    or clock) and a record that is not there read as NaN; a blank system letter (`` 5``) is GPS."""
    from tqdyn.readers.sp3 import read_sp3

    path = tmp_path / "hand.sp3"
    path.write_text(SP3C, encoding="ascii")
    o = read_sp3(path)
    assert (o.version, o.coordinate_system, o.orbit_type, o.agency, o.time_system) == ("c", "IGS14", "HLM", "IGS",
                                                                                       "GPS")
    assert o.satellites == ("G01", "C23", "G05") and o.interval_s == 300.0
    assert o.mjd.tolist() == [60370] * 3 and o.sod.tolist() == [0.0, 300.0, 600.0]
    assert o.positions.shape == (3, 3, 3) and o.clocks.shape == (3, 3)
    assert o.positions[0, 0] == pytest.approx([-11044805.8, -10475672.35, 21929418.2], abs=1e-6)
    assert o.clocks[0, 0] == pytest.approx(189.1633e-6, rel=1e-12)
    assert np.isnan(o.clocks[0, 1]) and not np.isnan(o.positions[0, 1]).any()      # 999999.999999 clock
    assert np.isnan(o.positions[0, 2]).all() and o.clocks[0, 2] == -12e-6           # 0.000000 position
    assert np.isnan(o.positions[1, 0]).all() and o.clocks[1, 0] == pytest.approx(189.1634e-6, rel=1e-12)
    assert np.isnan(o.clocks[1, 2])                                                  # 0.000000 clock
    assert np.isnan(o.positions[2, 2]).all() and np.isnan(o.clocks[2, 2])           # no record


def test_bdt_and_gps_labels(tmp_path, epoch):
    """The same calendar labels in BDT lie 14 s later in TT than in GPS time (BDT = GPST - 14 s,
    TT = GPST + 51.184 s: the systems' definitions); the GPS-labelled 2024-03-01 00:00:00 is
    51.184 s - (TAI - UTC = 37 s) - 32.184 s = -18 s in TT after the UTC epoch of that label."""
    from tqdyn.od.gnss_sp3 import SP3Constellation
    from tqdyn.readers.sp3 import read_sp3

    text = SP3C.replace("G05", "G06")
    rows = [line for line in text.splitlines() if not line.startswith(("*", "P", "V", "EOF"))]
    body = []
    for i in range(12):
        body.append(f"*  2024  3  1 {i // 12:2d} {5 * i:2d}  0.00000000")
        body.append(f"PG01{20000.0 + i:14.6f}{10000.0:14.6f}{5000.0:14.6f}{0.0:14.6f}")
    head = "\n".join(rows).replace("       3 ORBIT", "      12 ORBIT") + "\n"
    for ts in ("GPS", "BDT"):
        (tmp_path / f"{ts}.sp3").write_text(head.replace("cc GPS ccc", f"cc {ts} ccc") + "\n".join(body) + "\nEOF\n")
    g = SP3Constellation(read_sp3(tmp_path / "GPS.sp3"), epoch, use_eop=False, points=4)
    b = SP3Constellation(read_sp3(tmp_path / "BDT.sp3"), epoch, use_eop=False, points=4)
    assert g.t[0] == pytest.approx(-18.0, abs=1e-6)
    assert b.t - g.t == pytest.approx(np.full(12, 14.0), abs=1e-6)


def _one_line_error(func, *args, **kw) -> str:
    with pytest.raises(ValueError) as exc:
        func(*args, **kw)
    msg = str(exc.value)
    assert "\n" not in msg
    return msg


def test_refusals_name_the_file_line_and_field(tmp_path, walker_file, epoch):
    """Malformed position record, a time system that is not allowed, a time outside the span: one
    line each, naming the file, the line number and the field."""
    from tqdyn.od.gnss_sp3 import sp3_constellation
    from tqdyn.readers.sp3 import read_sp3

    lines = SP3C.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("PC23"))
    bad = lines.copy()
    bad[k] = bad[k][:20] + "x" + bad[k][21:]
    (tmp_path / "bad.sp3").write_text("\n".join(bad) + "\n")
    msg = _one_line_error(read_sp3, tmp_path / "bad.sp3")
    assert msg.startswith(f"bad.sp3: line {k + 1}: C23 y (columns 19-32)"), msg
    (tmp_path / "utc.sp3").write_text(SP3C.replace("cc GPS ccc", "cc UTC ccc"))
    msg = _one_line_error(read_sp3, tmp_path / "utc.sp3")
    assert msg.startswith("utc.sp3: line 13: time system (columns 10-12) 'UTC' is not allowed; allowed: GPS"), msg
    c = sp3_constellation(walker_file, epoch, use_eop=False)
    assert c.span == pytest.approx((-7200.0 + 4 * STEP, 2 * 86400.0 - 4 * STEP), abs=1e-6)
    msg = _one_line_error(c.states, [0.0, c.span[1] + 1.0])
    assert msg.startswith("walker.sp3: t = ") and "outside the span" in msg, msg


def test_absent_samples_make_the_transmitter_invisible(tmp_path, epoch):
    """A satellite written as 0.000000 at one epoch: NaN states for the times whose 10-point window
    holds that sample (and only there), and its pseudoranges are not visible there."""
    from tqdyn.od.gnss_sp3 import sp3_constellation
    from tqdyn.od.measurements_gnss import GPS, pseudorange

    path = tmp_path / "gap.sp3"
    t = write_walker_sp3(path, GPS, epoch, 0.0, 86400.0, missing={(40, 3)})
    c = sp3_constellation(path, epoch, use_eop=False)
    tq = np.arange(c.span[0] + 60.0, c.span[1], 300.0)   # + 60 s: the emission times stay in the span
    r, _ = c.states(tq)
    gap = np.isnan(r[:, 3, 0])
    # the window of nodes floor(u) - 4 .. floor(u) + 5 holds node 40 for u in [35, 45)
    assert np.array_equal(gap, (tq >= t[35]) & (tq < t[45]))
    assert not np.isnan(np.delete(r, 3, axis=1)).any()
    rec = 1e8 * np.array([[1.0, 0.0, 0.0]]) * np.ones((tq.size, 1))
    o = pseudorange(tq, rec, np.zeros_like(rec), c)
    assert not o.visible[gap, 3].any()


# --------------------------------------------------------------------------------------------
# the command line, end to end

@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """A tianqin-gravity run of 2 days and the Walker SP3 file over its first day (with margins)."""
    import tqdyn
    from tqdyn.api import load_scenario
    from tqdyn.od.measurements_gnss import GPS

    d = tmp_path_factory.mktemp("sp3-chain")
    tqdyn.run("tianqin-gravity", {"run.duration": "2d"}, output=str(d / "tg.h5"))
    write_walker_sp3(d / "gps.sp3", GPS, load_scenario("tianqin-gravity").epoch, -3 * 3600.0, 86400.0 + 3 * 3600.0)
    return d


def test_simulate_then_fit_with_an_sp3_file(chain, tmp_path, capsys):
    """``od simulate --sp3`` then ``od fit --sp3`` with the real problem: the TDM's peers are the
    file's ids, its header names the file and its SHA-256 (hashlib), and chi^2 of the fit lies
    within its 1e-4 .. 1 - 1e-4 quantiles (the chi-square law of a correct model)."""
    import hashlib
    import json

    from tqdyn.formats.od_estimate import read_estimate_file
    from tqdyn.formats.od_tdm import read_measurements_tdm

    sp3, tdm, est = chain / "gps.sp3", tmp_path / "m.tdm", tmp_path / "est.h5"
    status, out, err = run_cli(["od", "simulate", str(chain / "tg.h5"), "--tracking", "gnss,slr", "--arc", "1d",
                                "--interval", "1800", "--sp3", str(sp3), "--output", str(tdm), "--quiet"], capsys)
    assert status in (0, None), err
    fields, info = read_measurements_tdm(tdm)
    assert json.loads(info["sp3"]) == [["gps.sp3", hashlib.sha256(sp3.read_bytes()).hexdigest()]]
    peers = set(fields["peer"][fields["type"] == "gnss_pseudorange"])
    assert peers and peers <= {f"G{k:02d}" for k in range(1, 25)}
    status, out, err = run_cli(["od", "fit", "tianqin-gravity", str(tdm), "--sp3", str(sp3), "--output", str(est),
                                "--quiet"], capsys)
    assert status in (0, None), err
    e = read_estimate_file(est)
    chi2, dof = float(e.attrs["chi2"]), int(e.attrs["chi2_dof"])
    assert stats.chi2.ppf(1e-4, dof) < chi2 < stats.chi2.ppf(1 - 1e-4, dof), (chi2, dof)
    # another file (one comment changed), or none: refused in one line, nothing written
    other = tmp_path / "other.sp3"
    other.write_text(sp3.read_text().replace("/* Walker GPS", "/* Walker gps"))
    for extra, expect in ((["--sp3", str(other)], "--sp3: other.sp3 (by SHA-256) is not the SP3 file(s)"),
                          ([], "--sp3: ")):
        out_file = tmp_path / "refused.h5"
        status, out, err = run_cli(["od", "fit", "tianqin-gravity", str(tdm), *extra, "--output", str(out_file),
                                    "--quiet"], capsys)
        assert status == 2 and len(err.strip().splitlines()) == 1 and expect in err, err
        assert not out_file.exists()


def test_cli_refuses_a_missing_or_short_sp3_file(chain, tmp_path, capsys):
    """``--sp3`` naming a file that does not exist, or one that does not cover the arc: exit 2, one
    line, no output file."""
    out_file = tmp_path / "m.tdm"
    for sp3, expect in ((tmp_path / "nope.sp3", "does not exist"), (chain / "gps.sp3", "covers t = ")):
        status, out, err = run_cli(["od", "simulate", str(chain / "tg.h5"), "--tracking", "gnss", "--arc", "2d",
                                    "--sp3", str(sp3), "--output", str(out_file), "--quiet"], capsys)
        assert status == 2 and len(err.strip().splitlines()) == 1 and expect in err, err
        assert not out_file.exists()
