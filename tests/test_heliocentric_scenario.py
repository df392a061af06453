"""Heliocentric scenarios: keys, initial states (Cartesian, ecliptic elements,
the Keplerian design, OEM files), the epoch in TDB, the self-gravity ramp
toward the centre, the file's reference system, and bad input (one line,
exit 2, no file)."""

from __future__ import annotations

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn.astro.oem_states import to_heliocentric
from tqdyn.astro.reference import HELIOCENTRIC
from tqdyn.astro.timescales import Epoch
from tqdyn.dynamics.initial import initial_state, satellite_states
from tqdyn.readers.oem import esa_lisa_orbit_files, read_oem
from tqdyn.scenario import load_scenario, loads_scenario

BASE = """
[scenario]
name = "h"
central_body = "sun"
epoch_tdb = "2035-01-01T00:00:00"
[run]
duration = "2d"
[integrator]
step = 21600
"""


def test_builtins_resolve_and_round_trip():
    for name in ("lisa", "lisa-esa", "lisa-gravity", "lisa-kepler", "taiji"):
        scen = load_scenario(name)
        assert scen.reference is HELIOCENTRIC and len(scen.satellites) == 3
        again = loads_scenario(scen.to_toml())
        assert again == scen, name
    lisa = load_scenario("lisa")
    assert lisa.constellation.coupled and lisa.spacecraft.architecture == "lisa"
    assert not load_scenario("lisa-gravity").constellation.coupled
    assert load_scenario("lisa-gravity").spacecraft.self_gravity_center is None
    # the default epoch of initial.oem: the files' first common record (ESA's 2036-12-09T00:00:00.00000094 TDB)
    assert lisa.epoch_tdb == "2036-12-09T00:00:00.000000940"
    assert lisa.spacecraft.self_gravity_center_span == ("2036-12-09T00:00:00.000000940 TDB",
                                                       "2047-09-09T13:04:48.000001110 TDB")


def test_oem_initial_states_are_the_files_records():
    # reference: the files' first records (km, km/s), their "EME2000" read as ICRF axes (initial.oem_eme2000)
    scen = load_scenario("lisa-esa")
    y0 = initial_state(scen)
    for k, path in enumerate(esa_lisa_orbit_files("TDB")):
        traj = to_heliocentric(read_oem(path), eme2000_frame_bias=False)
        assert np.max(np.abs(y0[k, 0:3, 0] - traj.r[0])) < 1e-5  # m: the record itself (rounded to 16 digits)
        assert np.max(np.abs(y0[k, 3:6, 0] - traj.v[0])) < 1e-12


def test_epoch_tdb_exact_and_its_utc_label():
    # reference: pyerfa's TDB -> TT -> TAI -> UTC chain at the geocentre
    e = Epoch.from_tdb("2036-12-09T00:00:00.00000094")
    assert e.tdb == (2465036.5, pytest.approx(0.94e-6 / 86400, abs=1e-20))
    assert e.utc_iso == "2036-12-08T23:58:50.816709" and e.iso.endswith(" TDB")
    back = Epoch.from_utc(e.utc_iso)
    assert abs(((back.tdb[0] - e.tdb[0]) + (back.tdb[1] - e.tdb[1])) * 86400) < 1e-6  # s: the 1-us label


def test_cartesian_and_ecliptic_elements():
    # an ecliptic circular orbit in the ecliptic plane: its ICRF state lies in the plane tilted by the
    # obliquity (84381.406" + the frame bias): the angular momentum is ecm06's third row (erfa)
    import erfa

    text = BASE + """
[initial]
axes = "ecliptic"
[[satellites]]
a_km = 149597870.7
i_deg = 0
nu_deg = 40
[[satellites]]
r_km = [1.5e8, 0, 0]
v_kmps = [0, 29.7, 0]
"""
    scen = loads_scenario(text)
    (r1, v1), (r2, v2) = satellite_states(scen)
    h = np.cross([float(x) for x in r1], [float(x) for x in v1])
    pole = np.array(erfa.ecm06(2451545.0, 0.0))[2]
    assert np.linalg.norm(h / np.linalg.norm(h) - pole) < 1e-15
    # the Cartesian state: r_ICRF = ecm06^T r_ecliptic (float64 matrix: 1e-16 * 1.5e11 m)
    ecm = np.array(erfa.ecm06(2451545.0, 0.0))
    assert np.max(np.abs(np.array([float(x) for x in r2]) - ecm.T @ [1.5e11, 0, 0])) < 1e-4
    assert np.max(np.abs(np.array([float(x) for x in v2]) - ecm.T @ [0, 29.7e3, 0])) < 1e-11
    assert loads_scenario(scen.to_toml()) == scen


def test_self_gravity_ramp_shortens_the_arms():
    # first principles: a constant g toward the centroid moves each satellite toward it by g T^2 / 2,
    # so an arm (sqrt(3) times the centroid distance) shortens by sqrt(3) g T^2 / 2 = 646 m after 10 days
    # for g = 1e-9 m/s^2; the orbital dynamics change it by < 1 % over 10 days (measured 643.7 m)
    from tqdyn.dynamics import propagate

    over = ["run.duration=10d"]
    ramp = over + ["spacecraft.self_gravity_center=[1e-9, 1e-9]",
                   'spacecraft.self_gravity_center_span=["2035-01-01 TDB", "2036-01-01 TDB"]']
    a = propagate(load_scenario("lisa-kepler", over))
    b = propagate(load_scenario("lisa-kepler", ramp))

    def arm(y):
        return np.linalg.norm((y[0, 0:3, 0] - y[1, 0:3, 0]) + (y[0, 0:3, 1] - y[1, 0:3, 1]))

    shrink = arm(a.y_final) - arm(b.y_final)
    print(f"\narm shortening by 1 nm/s^2 toward the centre over 10 d: {shrink:.2f} m (first order 646.5 m)")
    assert abs(shrink - np.sqrt(3) * 0.5e-9 * 864000.0 ** 2) < 10.0


@pytest.mark.parametrize("override, field", [
    (["scenario.central_body=jupiter"], "scenario.central_body"),
    (["scenario.epoch_tdb=2050-01-01"], "initial.oem.1"),
    (['forces.third_bodies=["sun"]'], "forces.third_bodies"),
    (["forces.earth_degree=4"], "forces.earth_degree"),
    (["spacecraft.architecture=lisa", "spacecraft.d_tm=0.4"], "spacecraft.d_tm"),
    (["initial.rotation=sideways"], "initial.rotation"),
    (["initial.axes=galactic"], "initial.axes"),
])
def test_bad_heliocentric_input_one_line(tmp_path, capsys, override, field):
    out = tmp_path / "x.h5"
    args = ["run", "lisa-esa", "--set", "run.duration=1d", "--output", str(out)]
    for o in override:
        args += ["--set", o]
    status, _, err = run_cli(args, capsys)
    assert status == 2 and err.count("\n") == 1 and field in err, err
    assert not out.exists()


@pytest.mark.parametrize("edit, what", [
    (lambda t: t[:3000], "not a readable CCSDS OEM file"),
    (lambda t: t.replace("EME2000", "ITRF"), "REF_FRAME = 'ITRF'"),
    (lambda t: t.replace("TIME_SYSTEM          = TDB", "TIME_SYSTEM          = UTC"), "TIME_SYSTEM = 'UTC'"),
    (lambda t: "garbage\n", "not a readable CCSDS OEM file"),
    (lambda t: t.replace("CENTER_NAME          = SUN", "CENTER_NAME          = EARTH"), "CENTER_NAME"),
])
def test_bad_oem_files_one_line(tmp_path, capsys, edit, what):
    files = esa_lisa_orbit_files("TDB")
    bad = tmp_path / "bad.oem"
    bad.write_text(edit(open(files[0], encoding="utf-8").read()), encoding="utf-8")
    out = tmp_path / "x.h5"
    status, _, err = run_cli(["run", "lisa-esa", "--set", f'initial.oem=["{bad}", "{files[1]}", "{files[2]}"]',
                              "--set", "run.duration=1d", "--output", str(out)], capsys)
    assert status == 2 and err.count("\n") == 1 and "initial.oem.1" in err and what in err, err
    assert not out.exists()


def test_set_initial_oem_relative_to_cwd(tmp_path, monkeypatch, capsys):
    import shutil

    files = esa_lisa_orbit_files("TCB")
    for k, f in enumerate(files):
        shutil.copy(f, tmp_path / f"sc{k + 1}.oem")
    monkeypatch.chdir(tmp_path)
    scen = load_scenario("lisa-esa", ['initial.oem=["sc1.oem", "sc2.oem", "sc3.oem"]'])
    # TCB time tags: the first common record converted to TDB (IAU 2006 B3) is ESA's TDB first record
    # within the TCB files' 1-us tag rounding
    e = scen.epoch
    ref = load_scenario("lisa-esa").epoch
    assert abs(((e.tdb[0] - ref.tdb[0]) + (e.tdb[1] - ref.tdb[1])) * 86400) < 2e-6
    assert all(str(tmp_path) in p for p in scen.initial.oem)


def test_trajectory_file_records_the_heliocentric_system(tmp_path):
    from tqdyn.formats.trajectory import read_trajectory
    from tqdyn.workflows.run import run_to_file

    out = tmp_path / "h.h5"
    run_to_file(load_scenario("lisa-kepler", ["run.duration=1d", f"run.output={out}"]))
    tr = read_trajectory(out)
    assert (tr.attrs["origin"], tr.attrs["frame"], tr.attrs["time_scale"]) == ("sun", "BCRS", "TDB")
    assert tr.reference is HELIOCENTRIC and tr.attrs["epoch_tdb"] == "2035-01-01T00:00:00"
    assert tr.epoch.tdb == (2464328.5, 0.0)
    ds = tr.to_xarray()
    assert ds["sat_r"].attrs["frame"] == "BCRS" and ds["time"].attrs["frame"] == "TDB"
