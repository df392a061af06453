"""Parameter sweeps on Dask: tqdyn.workflows.sweep and the `tqdyn sweep` command.

Reference values, independent of the sweep code:
* the analytic effect of a constant common self-gravity a = 1e-9 m/s^2 on a
  drag-free satellite: the satellites follow their TMs, so over t = 1 h the
  members "+x" and "-x" differ by 2 * a t^2 / 2 = a t^2 = 1.296e-2 m
  (docs/design.md scales the same effect to ~100 km in 3 months).
  Corrections: the gravity gradient (n^2 t^2 ~ 5e-3 relative, n^2 =
  GM/r^3 = 4e-10 s^-2) and the turn of the S frame (orbital rate 2e-5
  rad/s, 0.07 rad in 1 h: < 0.3 %), hence a 1 % tolerance;
* a circular orbit (e = 0) starts at |r| = a: the a_km values typed in the
  sweep files below (Table I: Sat1 a = 100000 km);
* the member files read with h5py directly (hi + lo), not through
  tqdyn.formats.trajectory, for the gathered values;
* TOML itself (tomllib) for the override text of the swept values.
Members run the built-in "tianqin" scenario (coupled: attitude + drag-free
control) with a cheap force model (Earth monopole, Moon at most) for 1 h at
50 s, so each member takes well under a second once the kernels are cached.
"""

from __future__ import annotations

import os
import shutil
import tomllib
from decimal import Decimal

import dask
import h5py
import numpy as np
import pytest
import xarray as xr
from click.testing import CliRunner

from tqdyn.workflows import sweep as sw
from tqdyn.scenario.toml_text import toml_str, toml_value
from tqdyn.cli.sweep import sweep as sweep_command
from tqdyn.scenario import loads_scenario

# the paper's full force model switched off but for the Earth monopole (cheap, 1 h)
_CHEAP = ["run.duration=1h", "forces.earth_degree=0", "forces.earth_field_indirect=false", "forces.third_bodies=[]",
          "forces.solid_tides=false", "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.atmospheric_tides=false",
          "forces.moon_degree=0", "forces.sun_j2=false", "forces.relativity=false"]


def _toml_list(items) -> str:
    return "[" + ", ".join(toml_str(s) for s in items) + "]"


SIX_DIRECTIONS = f"""
[sweep]
name = "self-gravity-directions"
scenario = "tianqin"
output_dir = "sg-out"
set = {_toml_list(_CHEAP)}
mode = "product"

[[sweep.parameter]]
key = "spacecraft.self_gravity_common"
values = [[1e-9, 0, 0], [-1e-9, 0, 0], [0, 1e-9, 0], [0, -1e-9, 0], [0, 0, 1e-9], [0, 0, -1e-9]]
labels = ["+x", "-x", "+y", "-y", "+z", "-z"]
name = "direction"
"""


@pytest.fixture(scope="module")
def client():
    """One local Dask cluster (2 worker processes, 1 thread each) for the library tests."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=40) as cluster, Client(cluster) as c:
        yield c


def _write(tmp_path, text, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _h5_value(path, field):
    """hi + lo of a dd field of a trajectory file, read with h5py (not tqdyn.formats.trajectory)."""
    with h5py.File(path, "r") as h5:
        return h5[field]["hi"][()] + h5[field]["lo"][()]


# --------------------------------------------------------------------------- (1) six self-gravity directions


def test_six_self_gravity_directions_on_local_cluster(tmp_path):
    """`tqdyn sweep` on a new LocalCluster with 2 workers: six members, one
    `direction` dimension with the six labels, the trajectory variables, and
    the physics of a common self-gravity (a t^2 between +x and -x)."""
    path = _write(tmp_path, SIX_DIRECTIONS)
    res = CliRunner().invoke(sweep_command, [str(path), "--workers", "2", "-q"])
    assert res.exit_code == 0, res.output + res.stderr
    assert "local cluster of 2 worker processes" in res.stderr
    assert "6 members: 0 already done, 6 ran, 0 failed" in res.stdout
    nc = tmp_path / "sg-out" / "self-gravity-directions.nc"
    assert nc.is_file() and str(nc) in res.stdout
    with xr.open_dataset(nc, engine=sw.netcdf_engine()) as ds:
        ds = ds.load()
    labels = ["+x", "-x", "+y", "-y", "+z", "-z"]
    assert list(ds["direction"].values) == labels
    assert ds["sat_r"].dims == ("direction", "time", "sat", "comp") and ds.sizes["time"] == 73  # 3600 s / 50 s + 1
    for var in ("sat_v", "sat_a_gravity", "sat_a_dragfree", "sat_T_S_I", "mosa_angle", "tm_r", "tm_a_suspension"):
        assert var in ds and ds[var].dims[0] == "direction"
    assert ds["ok"].dtype == bool and bool(ds["ok"].all()) and list(ds["error"].values) == [""] * 6
    assert ds.attrs["sweep_name"] == "self-gravity-directions" and ds.attrs["frame"] == "GCRS"
    # the value coordinate holds the swept vectors (values typed in SIX_DIRECTIONS)
    expected = np.array([[1e-9, 0, 0], [-1e-9, 0, 0], [0, 1e-9, 0], [0, -1e-9, 0], [0, 0, 1e-9], [0, 0, -1e-9]])
    np.testing.assert_array_equal(ds["direction_value"].values, expected)
    # each member's resolved scenario carries its value
    for k, lab in enumerate(labels):
        scen = loads_scenario(str(ds["scenario"].sel(direction=lab).values))
        assert [float(x) for x in scen.spacecraft.self_gravity_common] == list(expected[k])
        # gathered values == the member file read with h5py
        member = tmp_path / "sg-out" / str(ds["member_file"].sel(direction=lab).values)
        r = ds["sat_r"].sel(direction=lab).values + ds["sat_r_lo"].sel(direction=lab).values
        np.testing.assert_array_equal(r, _h5_value(member, "sat/r"))
    # analytic: +x and -x differ by a t^2 = 1e-9 * 3600^2 m at t = 1 h (1 % tolerance, see module doc)
    end = ds.isel(time=-1)
    d = (end["sat_r"].sel(direction="+x") - end["sat_r"].sel(direction="-x")).values
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1e-9 * 3600.0**2, rtol=1e-2)
    # orthogonal directions: sqrt(2) * a t^2 / 2
    d = (end["sat_r"].sel(direction="+x") - end["sat_r"].sel(direction="+z")).values
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), np.sqrt(2) * 0.5e-9 * 3600.0**2, rtol=1e-2)


# --------------------------------------------------------------------------- (2) a failing member


FAILING = f"""
[sweep]
scenario = "tianqin"
set = {_toml_list([*_CHEAP[:3], 'forces.third_bodies=["moon"]', *_CHEAP[4:]])}
mode = "zip"

[[sweep.parameter]]
key = "satellites.1.a_km"
values = [100000.0, 100001.0, 100002.0]

[[sweep.parameter]]
key = "forces.ephemeris"
values = ["de421", "/nonexistent/de999.bsp", "de421"]
"""


def test_failing_member_is_reported_and_the_others_complete(tmp_path, client):
    """Member 2 names a missing ephemeris file: it fails in its task, is
    reported with its parameters, is NaN in the dataset; members 1 and 3
    complete and are written."""
    path = _write(tmp_path, FAILING, "failing.toml")
    seen = []
    result = sw.run_sweep(path, scheduler=client, progress=seen.append)
    assert len(seen) == 3
    assert [o.status for o in result.outcomes] == ["ran", "failed", "ran"]
    (bad,) = result.failures
    assert bad.member.params == (("a_km", "100001.0"), ("ephemeris", "/nonexistent/de999.bsp"))
    assert bad.error.startswith("FileNotFoundError") and "/nonexistent/de999.bsp" in bad.error
    assert "\n" not in bad.error and "Traceback" in bad.traceback
    assert "member 2 (a_km=100001.0, ephemeris=/nonexistent/de999.bsp)" == bad.member.label
    assert [p.name for p in result.files] == [result.outcomes[0].member.path.name,
                                              result.outcomes[2].member.path.name]
    assert all(p.is_file() for p in result.files) and not bad.member.path.exists()
    assert result.output == tmp_path / "failing-out" / "failing.nc" and result.output.is_file()
    with xr.open_dataset(result.output, engine=sw.netcdf_engine()) as ds:
        ds = ds.load()
    assert ds["sat_r"].dims[:2] == ("member", "time")
    assert list(ds["ok"].values) == [True, False, True]
    assert "FileNotFoundError" in str(ds["error"].values[1])
    np.testing.assert_array_equal(ds["a_km"].values, [100000.0, 100001.0, 100002.0])
    assert list(ds["ephemeris"].values) == ["de421", "/nonexistent/de999.bsp", "de421"]
    assert np.isnan(ds["sat_r"].values[1]).all() and np.isfinite(ds["sat_r"].values[[0, 2]]).all()
    # circular orbits start at |r| = a (the a_km values typed above)
    r0 = ds["sat_r"].isel(time=0, sat=0).values + ds["sat_r_lo"].isel(time=0, sat=0).values
    np.testing.assert_allclose(np.linalg.norm(r0[[0, 2]], axis=-1), [100000.0e3, 100002.0e3], rtol=0, atol=1e-6)


# --------------------------------------------------------------------------- (3) re-running skips what is done


TWO = f"""
[sweep]
name = "two"
scenario = "tianqin"
set = {_toml_list(_CHEAP)}

[[sweep.parameter]]
key = "satellites.2.nu_deg"
values = [150.0, 150.5]
"""


def test_rerun_skips_done_members_and_redoes_stale_files(tmp_path, client):
    path = _write(tmp_path, TWO)
    first = sw.run_sweep(path, scheduler=client)
    assert [o.status for o in first.outcomes] == ["ran", "ran"] and not first.failures
    files = [o.member.path for o in first.outcomes]
    mtimes = [os.stat(f).st_mtime_ns for f in files]
    # all done: nothing is submitted -- a scheduler address nobody listens at is never contacted
    again = sw.run_sweep(path, scheduler="tcp://127.0.0.1:1")
    assert [o.status for o in again.outcomes] == ["done", "done"] and again.n_skipped == 2
    assert [os.stat(f).st_mtime_ns for f in files] == mtimes
    xr.testing.assert_identical(again.dataset, first.dataset)
    # a moved output directory still counts as done (run.output is not part of the identity)
    moved = tmp_path / "moved"
    shutil.copytree(tmp_path / "sweep-out", moved)  # default output_dir: <file stem>-out
    spec = sw.load_sweep(path)
    plan = sw.plan_sweep(sw.SweepSpec(name=spec.name, parameters=spec.parameters, scenario=spec.scenario,
                                      output_dir=moved, common=spec.common))
    assert plan.done == (True, True)
    # a truncated (partial) file and a file of another member are redone
    data = files[0].read_bytes()
    files[0].write_bytes(data[: len(data) // 2])
    shutil.copyfile(moved / files[0].name, files[1])
    assert sw.plan_sweep(path).done == (False, False)
    third = sw.run_sweep(path, scheduler=client)
    assert [o.status for o in third.outcomes] == ["ran", "ran"]
    assert sw.plan_sweep(path).done == (True, True)
    np.testing.assert_array_equal(third.dataset["sat_r"].values, first.dataset["sat_r"].values)
    # the CLI reports the skipped members
    res = CliRunner().invoke(sweep_command, [str(path), "--scheduler", "tcp://127.0.0.1:1"])
    assert res.exit_code == 0, res.stderr
    assert "2 already done, 0 to run" in res.stderr and "2 already done, 0 ran, 0 failed" in res.stdout


# --------------------------------------------------------------------------- (4) bad input: one line, exit 2


_HEAD = '[sweep]\nscenario = "tianqin-kepler"\nset = ["run.duration=1h"]\n'
_P = '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [100000.0, 100001.0]\n'


@pytest.mark.parametrize("text, fragment", [
    (_HEAD + "colour = 1\n" + _P, "sweep.colour: is not a known key; allowed: name, scenario"),
    ("[sweep\n", "is not valid TOML"),
    ('[other]\nx = 1\n', "other: is not a known key"),
    (_HEAD, "sweep.parameter: is missing"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = []\n',
     "sweep.parameter.1.values: [] is empty; allowed: a non-empty array"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\n', "sweep.parameter.1.values: is missing"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [1.0]\nunit = "km"\n',
     "sweep.parameter.1.unit: is not a known key"),
    (_HEAD + 'mode = "zip"\n' + _P + '[[sweep.parameter]]\nkey = "satellites.2.nu_deg"\nvalues = [1.0, 2.0, 3.0]\n',
     "sweep.parameter.2.values: has 3 values, sweep.parameter.1 has 2 (zip mode)"),
    (_HEAD + 'mode = "grid"\n' + _P, "sweep.mode: 'grid' is not a valid choice; allowed: 'product', 'zip'"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.e"\nvalues = [0.0, 1.5]\n',
     "sweep member 2 (e=1.5): satellites.1.e: 1.5 is not an elliptic eccentricity; allowed: 0 <= e < 1"),
    (_HEAD + '[[sweep.parameter]]\nkey = "forces.colour"\nvalues = [1, 2]\n',
     "sweep.parameter.1.key: override forces.colour: 'colour' is not a key of [forces]"),
    (_HEAD + '[[sweep.parameter]]\nkey = "spacecraft.self_gravity_common"\nvalues = [[1e-9, 0, 0], [0, 1e-9, 0]]\n',
     "sweep.parameter.1.labels: are missing: the values are not all scalars"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [1.0, 2.0]\nlabels = ["a"]\n',
     "sweep.parameter.1.labels: ['a'] has 1 labels for 2 values"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [100000.0, 100000.0]\n',
     "sweep.parameter.1.values: 100000.0 is repeated"),
    (_HEAD + '[[sweep.parameter]]\nkey = "run.duration"\nvalues = ["1h", "2h"]\n',
     "sweep.parameter.1.key: 'run.duration' is also set in sweep.set"),
    ('[sweep]\nscenario = "tianqin-kepler"\n[[sweep.parameter]]\nkey = "run.duration"\nvalues = ["1h", "2h"]\n',
     "sweep member 2 (duration=2h): has another time grid"),
    (_HEAD.replace('"]', '", "run.output=x.h5"]') + _P, "sweep.set.2: 'run.output=x.h5' sets run.output"),
    ('[sweep]\nscenario = "nowhere.toml"\n' + _P, "sweep.scenario: 'nowhere.toml' is neither a built-in scenario nor"),
    (_HEAD + _P + '[[sweep.parameter]]\nkey = "satellites.2.a_km"\nvalues = [1.0, 2.0]\n',
     "sweep.parameter.2.name: 'a_km' clashes with the name of sweep.parameter.1"),
    (_HEAD + '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [1.0, 2.0]\nname = "time"\n',
     "sweep.parameter.1.name: 'time' is a name the gathered dataset already uses"),
])
def test_bad_sweep_files_exit_2_with_one_line(tmp_path, text, fragment):
    path = _write(tmp_path, text, "bad.toml")
    res = CliRunner().invoke(sweep_command, [str(path)])
    assert res.exit_code == 2, (res.stdout, res.stderr)
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error: "), res.stderr
    assert fragment in lines[0], lines[0]
    assert res.stdout == "" and sorted(os.listdir(tmp_path)) == ["bad.toml"]  # nothing run, nothing written


def test_bad_command_line_exit_2_with_one_line(tmp_path):
    ok = _write(tmp_path, _HEAD + _P)
    cases = [([str(tmp_path / "missing.toml")], "sweep file"),
             ([str(ok), "--workers", "0"], "--workers: 0 is not a number of workers; allowed: an integer >= 1"),
             ([str(ok), "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers: applies to the local"),
             ]
    for argv, fragment in cases:
        res = CliRunner().invoke(sweep_command, argv)
        lines = res.stderr.splitlines()
        assert res.exit_code == 2 and len(lines) == 1 and fragment in lines[0], (argv, res.stderr)
    # an unreachable scheduler: one line, nothing written (connect timeout shortened for the test)
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        res = CliRunner().invoke(sweep_command, [str(ok), "--scheduler", "tcp://127.0.0.1:1"])
    lines = res.stderr.splitlines()
    assert res.exit_code == 2 and lines[-1].startswith("tqdyn: error: scheduler: 'tcp://127.0.0.1:1' cannot be")
    assert not (tmp_path / "sweep-out" / "sweep.nc").exists()


# --------------------------------------------------------------------------- members and values (no cluster)


def test_dry_run_lists_the_product_grid_in_c_order(tmp_path):
    text = _HEAD + _P + '[[sweep.parameter]]\nkey = "constellation.pointing"\nvalues = ["global", "taylor1"]\n'
    text = text.replace('"tianqin-kepler"', '"tianqin"')
    res = CliRunner().invoke(sweep_command, [str(_write(tmp_path, text)), "--dry-run"])
    assert res.exit_code == 0, res.stderr
    rows = [line.split() for line in res.stdout.splitlines()[2:]]
    assert [r[:4] for r in rows] == [["1", "100000.0", "global", "to"], ["2", "100000.0", "taylor1", "to"],
                                     ["3", "100001.0", "global", "to"], ["4", "100001.0", "taylor1", "to"]]
    assert "4 members (product over a_km[2] x pointing[2])" in res.stderr
    assert not (tmp_path / "sweep-out").exists()


@pytest.mark.parametrize("value", [Decimal("1E-9"), Decimal("-0.5"), 3, True, "off", "a \"quoted\" \\ path\n",
                                   (Decimal("1E-9"), 0, Decimal("-2.5")), ((1, 2), (3, 4))])
def test_override_text_is_toml_of_the_value(value):
    """The override text of a value parses back (tomllib) to the same value."""
    parsed = tomllib.loads("v = " + toml_value(value), parse_float=Decimal)["v"]

    def norm(x):
        return tuple(norm(e) for e in x) if isinstance(x, (list, tuple)) else x
    assert norm(parsed) == norm(value) and type(parsed) is type(value) or isinstance(value, tuple)


def test_members_carry_their_values_and_distinct_files(tmp_path):
    """Each member's resolved scenario has the base + common set + its values;
    file names are hashes of the resolved scenario (stable, distinct)."""
    text = ('[sweep]\nscenario = "tianqin-kepler"\nset = ["run.duration=2h", "satellites.3.nu_deg=271"]\n'
            'output_dir = "out"\nmode = "zip"\n'
            '[[sweep.parameter]]\nkey = "satellites.1.a_km"\nvalues = [100000.0, 100001.0, 100001.0]\n'
            '[[sweep.parameter]]\nkey = "satellites.2.nu_deg"\nvalues = [150, 150, 151]\n')
    path = _write(tmp_path, text)
    plan = sw.plan_sweep(path)
    assert plan.spec.output_dir == tmp_path / "out" and plan.spec.name == "sweep"
    assert plan.done == (False, False, False)
    expect = [("100000.0", "150"), ("100001.0", "150"), ("100001.0", "151")]
    for m, (a_km, nu) in zip(plan.members, expect):
        scen = loads_scenario(m.scenario_toml)
        assert scen.satellites[0].a_m == Decimal(a_km) * 1000 and scen.satellites[1].nu_deg == Decimal(nu)
        assert scen.satellites[2].nu_deg == 271 and scen.run.duration_s == 7200
        assert scen.run.output == str(m.path) and m.path.parent == tmp_path / "out"
    assert len({m.path for m in plan.members}) == 3
    assert [m.path for m in sw.plan_sweep(path).members] == [m.path for m in plan.members]  # stable
    # the sweep's TOML reads back to the same sweep
    again = sw.loads_sweep(plan.spec.to_toml(), base_dir=tmp_path)
    assert again.parameters == plan.spec.parameters and again.common == plan.spec.common


def test_members_with_different_fields_merge_nan_filled(tmp_path, client):
    """A zip sweep over the attitude: member 1 (pointing "none") has no
    attitude / TM fields, member 2 ("global", control on) has them; the
    gathered dataset holds the union, NaN where a member has no such field,
    and each member's values as in its own file (read with h5py)."""
    text = (f'[sweep]\nscenario = "tianqin"\nset = {_toml_list(_CHEAP)}\nmode = "zip"\n'
            '[[sweep.parameter]]\nkey = "constellation.pointing"\nvalues = ["none", "global"]\n'
            '[[sweep.parameter]]\nkey = "constellation.control"\nvalues = ["off", "on"]\n')
    result = sw.run_sweep(_write(tmp_path, text), scheduler=client)
    assert not result.failures
    ds = result.dataset
    assert list(ds["pointing"].values) == ["none", "global"] and list(ds["control"].values) == ["off", "on"]
    assert {"tm", "row", "col"} <= set(ds.coords)
    assert np.isnan(ds["tm_r"].values[0]).all() and np.isfinite(ds["tm_r"].values[1]).all()
    assert "pointing" not in ds.attrs and ds.attrs["precision"] == "dd"  # only attributes common to all members
    for k, o in enumerate(result.outcomes):
        np.testing.assert_array_equal(ds["sat_r"].values[k] + ds["sat_r_lo"].values[k], _h5_value(o.member.path, "sat/r"))
    with h5py.File(result.outcomes[1].member.path, "r") as h5:
        np.testing.assert_array_equal(ds["sat_T_S_I"].values[1], h5["sat/T_S_I"][()])
