"""The measurement interface (tqdyn.od.registry, tqdyn.od.measurement_type), the TT&C stations
(tqdyn.od.measurements_ttc), the scenario's Earth orientation in the station models, and the TDM
conventions read by another tool (ccsds-ndm).

References: the CCSDS TDM standard (503.0-B-2) for the meaning of TIMETAG_REF = RECEIVE,
PATH = 1,2,1 and RANGE_UNITS = s (the round-trip light time); the light-time equations solved
here by fixed point from the truth trajectory (straight lines at c, the Earth's Shapiro delay
2 GM/c^3 ln((r1 + r2 + rho)/(r1 + r2 - rho)), Moyer 2000, eq. 8-38); for the EOP test the first-
order change of a distance |r - R| under a small move dR of one end, -u . dR (u the unit vector
from R to r), with the stations' GCRS positions under the two EOP tables.
"""

from __future__ import annotations

import pathlib
from decimal import Decimal

import erfa
import numpy as np
import pytest

from tqdyn.astro.eop_sources import eop_table
from tqdyn.formats.od_tdm import write_measurements_tdm
from tqdyn.od import problem as odp
from tqdyn.od import registry
from tqdyn.od.measurements import station_states_gcrs
from tqdyn.od.measurements_slr import slr_station_positions
from tqdyn.od.measurements_ttc import ttc_stations, use_ttc_stations
from tqdyn.od.tracking import evaluate, row_order
from tqdyn.od.variational import propagate_dd
from tqdyn.scenario import load_scenario

DAY = 86400.0
SCEN = "tianqin-gravity"
C = 299792458.0           # m/s
GM_EARTH = 3.986004418e14  # m^3/s^2 (IERS 2010)


def _shapiro(R, r):
    r1, r2, rho = np.linalg.norm(R), np.linalg.norm(r), np.linalg.norm(r - R)
    return 2.0 * GM_EARTH / C ** 3 * np.log((r1 + r2 + rho) / (r1 + r2 - rho))


def _tt_seconds(text: str) -> Decimal:
    """Seconds [TT] of a TDM epoch text since MJD 0, as an exact decimal."""
    ymd, hms = text.split("T")
    y, m, d = (int(x) for x in ymd.split("-"))
    h, mi, sec = hms.split(":")
    return Decimal(int(erfa.cal2jd(y, m, d)[1])) * 86400 + int(h) * 3600 + int(mi) * 60 + Decimal(sec)


def test_every_user_reads_the_registry():
    """The tracking kinds, the bias types, the TDM types and the workflow's old names are the
    registry's (one list), and each type's keyword and path are the standard's for its signal."""
    from tqdyn.formats import od_tdm
    from tqdyn.workflows import od as wf

    assert odp.MEASUREMENT_TYPES == tuple(registry.TYPES) == tuple(od_tdm.TYPES)
    assert wf.KIND_OF_TYPE == {n: x.kind for n, x in registry.TYPES.items()}
    assert set(odp.TRACKING_KINDS) == {"gnss", "slr", "isr", "dsn", "ttc"}
    for n, x in registry.TYPES.items():
        assert x.path == ("1,2,1" if x.stations_label else "1,2"), n
        assert x.tdm_keyword == ("DOPPLER_INSTANTANEOUS" if x.unit == "m/s" else "RANGE"), n
    assert wf.parameter_unit("bias/ttc_range_rate/Kashi") == "m/s" and wf.parameter_unit("TQ1/vx") == "m/s"


def test_ttc_stations_file_is_the_users(tmp_path):
    """A replaced stations file gives the stations and types it lists (one station, range only:
    rows of ttc_range from it, no Doppler); the shipped file's Kashi is at the latitude it gives
    (geocentric latitude of 38.4214 deg geodetic: within 0.2 deg)."""
    kashi = ttc_stations()["Kashi"][0]
    assert abs(np.degrees(np.arcsin(kashi[2] / np.linalg.norm(kashi))) - 38.4214) < 0.2
    p = tmp_path / "stations.toml"
    p.write_text('[[station]]\nname = "Here"\ntypes = ["ttc_range"]\nitrf = [%r, %r, %r]\n' % tuple(map(float, kashi)))
    try:
        use_ttc_stations(p)
        meas = odp.schedule(SCEN, odp.Tracking(("ttc",), DAY, 3600.0))
    finally:
        use_ttc_stations(None)
    assert len(meas) > 0 and set(meas.type) == {"ttc_range"} and set(meas.peer) == {"Here"}


@pytest.mark.parametrize("text, pattern", [
    ('[[station]]\nname = "X"\ntypes = ["ttc_phase"]\nitrf = [1.0, 2.0, 3.0]\n',
     r"station 'X': types: 'ttc_phase' is not allowed.*allowed: ttc_range, ttc_range_rate"),
    ('[[station]]\nname = "X"\ngeodetic = [10.0, 95.0, 0.0]\n', r"station 'X': geodetic = \[10.0, 95.0, 0.0\]; allowed"),
    ('[[station]]\nname = "X"\n', r"station 'X': position missing; allowed: one of geodetic"),
])
def test_bad_stations_file_is_one_line(tmp_path, text, pattern):
    """A stations file with an unknown measurement type, a latitude beyond 90 deg or no position is
    refused in one line naming the file, the station, the field and what is allowed."""
    p = tmp_path / "s.toml"
    p.write_text(text)
    with pytest.raises(ValueError, match=pattern) as info:
        use_ttc_stations(p)
    use_ttc_stations(None)
    assert "\n" not in str(info.value) and p.name in str(info.value) and len(str(info.value)) <= 200


def test_eop_of_the_scenario_moves_the_slr_ranges_as_the_stations():
    """forces.eop = "c04-14" against the default ("auto"): on the same satellite states the SLR
    ranges move by the stations' GCRS displacement projected on the line of sight, -u . dR, at
    the bounce time (first order; the light-time legs differ by ~0.3 s of Earth rotation)."""
    base = load_scenario(SCEN)
    other = load_scenario(SCEN, ['forces.eop="c04-14"'])
    tr = odp.Tracking(("slr",), DAY, 3600.0)
    t, y = propagate_dd(base, None, tr.times())
    states = y[..., 0] + y[..., 1]
    rows_a = evaluate(base, tr, t, states, ("slr_range",))
    rows_b = evaluate(other, tr, t, states, ("slr_range",))
    names, itrs = slr_station_positions(base.epoch)
    Ra = station_states_gcrs(base.epoch, t, itrs, eop=eop_table("auto", base.forces.eop_interpolation))[0]
    Rb = station_states_gcrs(base.epoch, t, itrs, eop=eop_table("c04-14", base.forces.eop_interpolation))[0]
    moved, want, disp = [], [], []
    for a, b in zip(rows_a, rows_b):
        vis = a.visible
        s = np.array([names.index(p) for p in a.peer])
        r = states[a.t_idx, a.sat, :3]
        R = Ra[a.t_idx, s]
        u = (r - R) / np.linalg.norm(r - R, axis=1)[:, None]
        dR = Rb[a.t_idx, s] - R
        moved.append((b.value - a.value)[vis])
        want.append(-np.einsum("ij,ij->i", u, dR)[vis])
        disp.append(np.linalg.norm(dR, axis=1)[vis])
    moved, want, disp = map(np.concatenate, (moved, want, disp))
    print(f"stations moved {np.sqrt(np.mean(disp ** 2)) * 1e3:.2f} mm rms ({disp.max() * 1e3:.2f} max); ranges "
          f"{np.sqrt(np.mean(moved ** 2)) * 1e3:.2f} mm rms; range - projection {np.abs(moved - want).max() * 1e6:.3f} um max "
          f"over {moved.size} ranges")
    assert np.sqrt(np.mean(moved ** 2)) > 1e-3               # the ranges do move (mm level)
    # the legs see the stations ~0.3 s apart: dR turns by omega tau ~ 2e-5 rad, ~2e-7 m of a cm move
    assert np.max(np.abs(moved - want)) <= 3e-7


@pytest.fixture(scope="module")
def tdm_file(tmp_path_factory):
    """Noise-free SLR and TT&C measurements of tianqin-gravity over a day every hour, written as a
    TDM, with the truth states on the grid."""
    scen = load_scenario(SCEN)
    tr = odp.Tracking(("slr", "ttc"), DAY, 3600.0)
    meas = odp.simulate(scen, tr, None, noise=False)
    path = tmp_path_factory.mktemp("tdm") / "m.tdm"
    write_measurements_tdm(path, meas, epoch=scen.epoch, time_scale="TT",
                           satellite_names=[s.name for s in scen.satellites])
    t, y = propagate_dd(scen, None, tr.times())
    return scen, meas, path, t, y[..., 0] + y[..., 1]


def test_ccsds_ndm_reads_the_ranges_at_their_tags(tdm_file):
    """ccsds-ndm parses the file; each two-way range (RANGE in s, TIMETAG_REF = RECEIVE, PATH
    1,2,1) is recomputed from the truth: reception at the station at the tag, the bounce solved
    back on the downleg, the transmission on the upleg; c (round trip) / 2 agrees to 1 mm (to the
    um the tags' 1-ns digits allow)."""
    ndm_io = pytest.importorskip("ccsds_ndm.ndm_io")
    scen, _, path, t_grid, states = tdm_file
    segs = ndm_io.NdmIo().from_path(pathlib.Path(path)).body.segment
    tt0 = scen.epoch.tt
    eop = eop_table(scen.forces.eop, scen.forces.eop_interpolation)      # the scenario's, as the models
    positions = {**dict(zip(*slr_station_positions(scen.epoch))), **{k: v[0] for k, v in ttc_stations().items()}}
    names = [s.name for s in scen.satellites]
    worst, n = 0.0, 0
    y, m, d, hmsf = erfa.d2dtf("TT", 9, *tt0)                      # the epoch (t = 0) in TT, to 1 ns
    t0 = _tt_seconds("%04d-%02d-%02dT%02d:%02d:%02d.%09d" % (y, m, d, *hmsf))
    for seg in segs:
        md = seg.metadata
        if str(getattr(md.timetag_ref, "value", md.timetag_ref)) != "RECEIVE" or md.path != "1,2,1" or \
                md.range_units is None:
            continue
        assert str(getattr(md.range_units, "value", md.range_units)) == "s"
        sat_i = names.index(md.participant_2)
        itrs = positions[md.participant_1][None, :]
        for o in seg.data.observation:
            off_r = float(_tt_seconds(o.epoch) - t0)       # the tag [s since the epoch, TT], exact
            k = int(np.argmin(np.abs(t_grid - off_r)))
            off_r -= t_grid[k]                             # from the grid instant: no cancellation

            def station(dt, k=k, itrs=itrs):
                return station_states_gcrs(scen.epoch, t_grid[k:k + 1], itrs, dt=np.array([[dt]]), eop=eop)[0][0, 0]

            def sat(dt, k=k, sat_i=sat_i):
                return states[k, sat_i, :3] + states[k, sat_i, 3:] * dt

            R_r, off_b = station(off_r), off_r
            for _ in range(5):      # downleg: t_b + |R(t_r) - r(t_b)| / c + shapiro = t_r
                off_b = off_r - np.linalg.norm(R_r - sat(off_b)) / C - _shapiro(R_r, sat(off_b))
            r_b, off_t = sat(off_b), off_b
            for _ in range(5):      # upleg: t_t + |r(t_b) - R(t_t)| / c + shapiro = t_b
                R_t = station(off_t)
                off_t = off_b - np.linalg.norm(r_b - R_t) / C - _shapiro(R_t, r_b)
            err = abs(C * (off_r - off_t) / 2.0 - C * float(o.range) / 2.0)
            assert abs(off_b) < 1e-6          # the bounce is the model's grid instant
            worst, n = max(worst, err), n + 1
    print(f"{n} two-way ranges recomputed at their tags: worst {worst * 1e3:.4f} mm")
    assert n > 20 and worst <= 2e-6      # within 1 mm; the bound: the 1-ns tag digits times ~2 km/s


def test_tqdyn_reads_ccsds_ndm_and_old_files(tdm_file, tmp_path):
    """The file written back by ccsds-ndm reads as the measurements written (tags back on the
    grid, values to 1e-15), and the same rows in the 0.3 layout (two-way rows at the bounce, no
    TIMETAG_REF, km) read as before."""
    pytest.importorskip("ccsds_ndm")
    from ccsds_ndm.mapping import NDMFileFormats
    from ccsds_ndm.ndm_io import NdmIo

    from tqdyn.formats.od_tdm import read_measurements_tdm

    scen, meas, path, _, _ = tdm_file
    other = tmp_path / "ndm.tdm"
    NdmIo().to_file(NdmIo().from_path(path), NDMFileFormats.KVN, other)
    fields, _ = read_measurements_tdm(other, epoch=scen.epoch, time_scale="TT", grid_s=60.0)
    k = row_order(fields["t"], fields["type"], fields["sat"], fields["peer"])     # the table's row order
    for f in ("t", "type", "sat", "peer", "sigma"):
        assert np.array_equal(fields[f][k], getattr(meas, f)), f
    rel = np.abs(fields["value"][k] / meas.value - 1.0)
    print(f"ccsds-ndm's file read back: values within {rel.max():.2e} relative, tags on the grid exactly")
    assert rel.max() <= 1e-15
    old = pathlib.Path(__file__).parent / "fixtures" / "od_tdm_0.3.tdm"
    fields, _ = read_measurements_tdm(old, epoch=scen.epoch, time_scale="TT")
    assert fields["t"][0] == 0.0 and set(fields["type"]) == {"slr_range", "dsn_range_rate"}
    assert fields["value"].tolist()[:2] == [101234567.891, 0.125]


def test_ttc_stations_option_of_the_commands(tmp_path, capsys):
    """``--ttc-stations FILE`` (tqdyn od simulate | fit | covariance): a file with an unknown measurement type
    is refused in one line naming the station, the field and what is allowed (exit 2, nothing written), and
    the choice ends with the command (the shipped stations again afterwards)."""
    from cli_support import run_cli

    bad = tmp_path / "bad.toml"
    bad.write_text('[[station]]\nname = "X"\ntypes = ["ttc_phase"]\nitrf = [1.0, 2.0, 3.0]\n')
    out_json = tmp_path / "cov.json"
    status, out, err = run_cli(["od", "covariance", "tianqin-kepler", "--tracking", "ttc", "--arc", "12h",
                                "--ttc-stations", str(bad), "--json", str(out_json)], capsys)
    assert status == 2 and not out_json.exists()
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "'ttc_phase' is not allowed" in lines[0] and "ttc_range" in lines[0], err
    assert "Kashi" in ttc_stations()
