"""Outputs of LISA / Taiji / TianQin coupled runs: the spacecraft attributes of the trajectory file
(docs/trajectory-format.md, "Spacecraft attributes") and ``tqdyn report`` on a heliocentric run
(docs/report.md, "LISA and Taiji runs").

References:
* the attribute values: the architecture presets of tqdyn.constellation.spacecraft (``Spacecraft.preset``,
  an independent construction of the same geometry) and the documented defaults of older files;
* the LISA arm length: ESA's design value 2.5e9 m (2.5e6 km; Martens & Joffre 2021, "Trajectory design for
  the ESA LISA mission", arXiv:2101.03040) for the mean, and ESA's CReMA 2.0 orbit files shipped in
  tqdyn/data/esa-lisa-orbits (the `lisa` scenario's initial states; read by tqdyn.readers.oem and
  interpolated as the files say by tqdyn.astro.oem_states) for the arm lengths, their rates and the
  breathing angles on the run's grid;
* the drag-free acceleration: the scenario's input, ESA's self-gravity ramp -2e-9 -> +2e-9 m/s^2 along +X_S,
  linear over the files' span 2036-12-09 .. 2047-09-09T13:04:48 TDB, which the satellite must follow;
* the suspension along the sensitive axes: zero by the LISA scheme's condition e_l . A_l = 0 (round-off).
Bounds are 3-10x the values measured here (stated with each assertion).  The 1-year `lisa` run takes ~1.5 s
after the JIT compilation (cached on disk; ~35 s once), its report ~5 s.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import shutil

import h5py
import numpy as np
import pytest

from tqdyn import cli
from tqdyn.astro.oem_states import states_at, to_heliocentric
from tqdyn.cli.report import report as report_command
from tqdyn.constellation import geometry
from tqdyn.constellation.spacecraft import Spacecraft
from tqdyn.formats import trajectory as io
from tqdyn.readers.oem import esa_lisa_orbit_files, read_oem
from tqdyn.scenario import load_scenario
from tqdyn.workflows import report as rp
from tqdyn.workflows.run import run_to_file

cli.cli.add_command(report_command)

SPACECRAFT_KEYS = ("spacecraft_architecture", "dragfree_scheme", "spacecraft_housing_centers", "spacecraft_pivots",
                   "spacecraft_sensitive_axes", "spacecraft_theta_nominal", "spacecraft_units")
#: tests/test_report.py's cheap geocentric force model (a short TianQin run in a few seconds)
CHEAP = ["forces.earth_degree=2", "forces.third_bodies=sun,moon", "forces.solid_tides=false",
         "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.atmospheric_tides=false",
         "forces.moon_degree=0", "forces.sun_j2=false", "forces.relativity=false", "forces.earth_field_indirect=false"]


@pytest.fixture(scope="module")
def lisa_year(tmp_path_factory):
    """The built-in `lisa` scenario over one year (1461 rows at 6 h)."""
    path = tmp_path_factory.mktemp("lisa") / "lisa.h5"
    return run_to_file(load_scenario("lisa", ["run.duration=365d", f"run.output={path}"])).path


@pytest.fixture(scope="module")
def tianqin_short(tmp_path_factory):
    """The built-in `tianqin` scenario (coupled, Table IV self-gravity), 1 h at 50 s, cheap forces."""
    path = tmp_path_factory.mktemp("tq") / "tianqin.h5"
    return run_to_file(load_scenario("tianqin", ["run.duration=1h", f"run.output={path}", *CHEAP])).path


def _copy_without_spacecraft(src, dst, scenario_edit=None):
    """A copy of ``src`` as a file written before the spacecraft attributes: no spacecraft_* / dragfree_scheme
    root attributes, no components / dragfree_scheme / sensitive_axes on the datasets; ``scenario_edit``
    rewrites the scenario text."""
    shutil.copyfile(src, dst)
    with h5py.File(dst, "r+") as f:
        for key in SPACECRAFT_KEYS:
            del f.attrs[key]
        for path in io.FIELDS:
            if path in f:
                for key in ("components", "dragfree_scheme", "sensitive_axes"):
                    if key in f[path].attrs:
                        del f[path].attrs[key]
        if scenario_edit is not None:
            f.attrs["scenario"] = scenario_edit(f.attrs["scenario"])
    return dst


# ---------------------------------------------------------------- the attributes


def test_lisa_file_records_its_spacecraft(lisa_year):
    preset = Spacecraft.preset("lisa", tm_distance=0.30)  # the scenario's tm_distance; an independent construction
    with h5py.File(lisa_year, "r") as f:
        a = dict(f.attrs)
        assert a["format_version"] == 2  # new attributes, no new format version
        assert a["spacecraft_architecture"] == "lisa" and a["dragfree_scheme"] == "lisa"
        np.testing.assert_array_equal(json.loads(a["spacecraft_housing_centers"]), preset.nominal_housing_centers)
        np.testing.assert_array_equal(json.loads(a["spacecraft_pivots"]), np.zeros((2, 3)))
        np.testing.assert_array_equal(json.loads(a["spacecraft_sensitive_axes"]), [[1, 0, 0], [1, 0, 0]])
        assert a["spacecraft_theta_nominal"] == math.pi / 3
        assert "m, in the body frame S" in a["spacecraft_units"] and "row l in OA_l" in a["spacecraft_units"]
        # the housing centres: 0.30 m from the CoM along X_OA_l at +-30 deg from X_S
        np.testing.assert_allclose(json.loads(a["spacecraft_housing_centers"]),
                                   0.3 * np.array([[math.sqrt(3) / 2, 0.5, 0], [math.sqrt(3) / 2, -0.5, 0]]),
                                   rtol=0, atol=1e-16)
        s = f["tm/a_suspension"].attrs
        assert s["frame"] == "OA_l" and s["dragfree_scheme"] == "lisa"
        assert s["components"].startswith("x = X_OA_l (the optical axis of MOSA l")
        assert s["sensitive_axes"].startswith("TM 1: [1, 0, 0] in OA_1 = X_OA_1 (the optical axis); TM 2: [1, 0, 0]")
        g = f["sat/a_dragfree"].attrs
        assert g["frame"] == "BCRS" and g["dragfree_scheme"] == "lisa" and "the file's frame BCRS" in g["components"]
        assert f["sat/omega"].attrs["components"].startswith("x = X_S")
        assert "components" not in f["t"].attrs and "components" not in f["sat/breathing_angle"].attrs
    sc = io.read_trajectory(lisa_year).spacecraft
    assert sc.recorded and (sc.architecture, sc.dragfree_scheme) == ("lisa", "lisa")
    np.testing.assert_array_equal(sc.housing_centers, preset.nominal_housing_centers)
    np.testing.assert_array_equal(sc.sensitive_axes, preset.sensitive_axes_array)
    ds = io.read_trajectory(lisa_year).to_xarray()
    assert ds.attrs["spacecraft_architecture"] == "lisa" and ds["tm_a_suspension"].attrs["dragfree_scheme"] == "lisa"


def test_tianqin_file_records_tianqin(tianqin_short):
    tr = io.read_trajectory(tianqin_short)
    assert (tr.attrs["spacecraft_architecture"], tr.attrs["dragfree_scheme"]) == ("tianqin", "tianqin")
    sc = tr.spacecraft
    # Table III of the paper: TM_1 at +0.20 m, TM_2 at -0.20 m along Y_S, pivots at the EH centres, X_OA_l
    np.testing.assert_array_equal(sc.housing_centers, [[0, 0.2, 0], [0, -0.2, 0]])
    np.testing.assert_array_equal(sc.pivots, sc.housing_centers)
    np.testing.assert_array_equal(sc.sensitive_axes, [[1, 0, 0], [1, 0, 0]])
    assert "-0.0" not in tr.attrs["spacecraft_housing_centers"]
    with h5py.File(tianqin_short, "r") as f:
        assert f["sat/a_dragfree"].attrs["dragfree_scheme"] == "tianqin"
        assert "GCRS" in f["sat/a_dragfree"].attrs["components"]


def test_older_files_read_as_documented(lisa_year, tianqin_short, tmp_path):
    # format version 1 (tests/fixtures, tqdyn 0.1, coupled tianqin): the TianQin defaults, not recorded
    import pathlib

    v1 = io.read_trajectory(pathlib.Path(__file__).parent / "fixtures" / "trajectory-v1-tianqin.h5").spacecraft
    assert not v1.recorded and (v1.architecture, v1.dragfree_scheme) == ("tianqin", "tianqin")
    np.testing.assert_array_equal(v1.housing_centers, [[0, 0.2, 0], [0, -0.2, 0]])
    np.testing.assert_array_equal(v1.sensitive_axes, [[1, 0, 0], [1, 0, 0]])
    assert v1.theta_nominal == math.pi / 3

    # a version-2 file from before the architecture keys, with another line layout: the scenario's d_tm, d_p, tm_axis
    def old_scenario(text):
        new = {"d_tm": "d_tm = 0.5", "d_p": "d_p = 0.1", "tm_axis": 'tm_axis = "z"'}
        lines = [new.get(ln.split(" =")[0], ln) for ln in text.splitlines()
                 if not ln.startswith(("architecture =", "dragfree ="))]
        return "\n".join(lines)

    old = io.read_trajectory(_copy_without_spacecraft(tianqin_short, tmp_path / "old.h5", old_scenario))
    assert "architecture" not in old.scenario_toml and "\nd_tm = 0.5\nd_p = 0.1\n" in old.scenario_toml
    sc = old.spacecraft
    ref = Spacecraft.preset("tianqin", d_tm=0.5, d_p=0.1, tm_axis="z")
    assert not sc.recorded and (sc.architecture, sc.dragfree_scheme) == ("tianqin", "tianqin")
    np.testing.assert_allclose(sc.housing_centers, ref.nominal_housing_centers, rtol=0, atol=1e-16)
    np.testing.assert_allclose(sc.pivots, ref.pivots, rtol=0, atol=1e-16)
    with h5py.File(tmp_path / "old.h5", "r") as f:
        assert "components" not in f["tm/a_suspension"].attrs
    assert "sensitive_axes" not in old.to_xarray()["tm_a_suspension"].attrs

    # a LISA file without the attributes (written between the architecture and these attributes): its scenario
    sc = io.read_trajectory(_copy_without_spacecraft(lisa_year, tmp_path / "lisa-old.h5")).spacecraft
    rec = io.read_trajectory(lisa_year).spacecraft
    assert not sc.recorded and (sc.architecture, sc.dragfree_scheme) == ("lisa", "lisa")
    np.testing.assert_allclose(sc.housing_centers, rec.housing_centers, rtol=0, atol=1e-16)
    np.testing.assert_array_equal(sc.pivots, rec.pivots)


def test_point_mass_files_have_no_spacecraft(tmp_path):
    attrs = dict(scenario="", epoch_utc="2034-01-01T00:00:00", precision="dd", step_s=50.0, integrator="dp87",
                 pointing="none", control="off")
    with io.TrajectoryWriter(tmp_path / "pm.h5", attrs, ["t", "sat/r"], n_sat=1) as w:
        w.append({"t": (np.zeros(2), np.zeros(2)), "sat/r": (np.ones((2, 1, 3)), np.zeros((2, 1, 3)))})
    assert io.read_trajectory(tmp_path / "pm.h5").spacecraft is None


@pytest.mark.parametrize("key, value, match", [
    ("spacecraft_housing_centers", "[[0, 0.2, 0]]", "JSON"),
    ("spacecraft_sensitive_axes", "not json", "JSON"),
    ("spacecraft_theta_nominal", 4.0, "angle"),
    ("dragfree_scheme", "", "non-empty"),
])
def test_bad_spacecraft_attrs_one_line(tmp_path, key, value, match):
    attrs = dict(scenario="", epoch_utc="2034-01-01T00:00:00", precision="dd", step_s=50.0, integrator="dp87",
                 pointing="global", control="on", **{key: value})
    with pytest.raises(ValueError, match=match) as exc:
        io.TrajectoryWriter(tmp_path / "x.h5", attrs, ["t"], n_sat=3)
    assert "\n" not in str(exc.value) and key in str(exc.value)
    assert not list(tmp_path.iterdir())


# ---------------------------------------------------------------- tqdyn report on the LISA year


def _esa_on_grid(tr):
    """ESA's three orbits interpolated at the trajectory's instants: arms (geometry.Arms) and breathing angles."""
    ep = tr.epoch.tdb
    t = tr["t"]
    orbits = [to_heliocentric(read_oem(p), eme2000_frame_bias=False) for p in esa_lisa_orbit_files("TDB")]
    states = [states_at(o, ep[0], ep[1] + t / 86400.0) for o in orbits]
    a = geometry.arms(np.stack([s[0] for s in states], 1), np.stack([s[1] for s in states], 1))
    return a, geometry.breathing_angles(a)[0]


def test_cli_report_lisa_year(lisa_year, tmp_path, capsys, monkeypatch, record_number):
    captured = {}
    real = rp.report_runs

    def keep(*args, **kw):
        captured["rep"] = rep = real(*args, **kw)
        return rep

    monkeypatch.setattr(rp, "report_runs", keep)
    out = tmp_path / "rep"
    with pytest.raises(SystemExit) as exc:
        cli.main(["report", str(lisa_year), "--out", str(out), "-q"])
        raise SystemExit(0)
    text = capsys.readouterr().out
    assert exc.value.code == 0
    rep = captured["rep"]
    for stem in ("lisa-arms", "lisa-breathing", "lisa-actuation", "lisa-control", "lisa-pointing"):
        for ext in ("png", "pdf"):
            assert (out / f"{stem}.{ext}").stat().st_size > 10_000, stem
    summary = (out / "summary.md").read_text()
    assert "| lisa: spacecraft | - | architecture lisa, drag-free scheme lisa |" in summary and "recorded in the file" in summary
    assert "origin sun, frame BCRS, time scale TDB" in summary
    assert "60 +- 1 deg (requirement, LISA)" in summary and "2.500e+09 m (LISA)" in summary
    # a TianQin comparison would be wrong here: no paper values, no TianQin flight axis, no range ASD on the 6 h grid
    assert "Fig. " not in summary and "flight direction" not in summary and "0.3 pm" not in summary
    assert "no range ASD: the grid's Nyquist frequency 2.31e-05 Hz" in summary
    assert summary.rstrip() in text  # the table on stdout

    tr = io.read_trajectory(lisa_year)
    esa, esa_alpha = _esa_on_grid(tr)
    arms = rep.values["lisa/arms"]
    # the mean arm over the year: -0.30 % of ESA's design 2.5e9 m (measured; ESA's files over the same rows the same
    # to 1.5 km): within 1 % (3x)
    assert abs(arms["mean"] / 2.5e9 - 1) < 0.01
    # against ESA's files on the run's grid (measured: mean -1.5 km, min 0, max -0.34 km; rates +8e-5 / +2e-5 m/s;
    # breathing angles -7e-6 / -1.5e-6 deg): 4-7x
    L = esa.length[:, :3]
    assert abs(arms["mean"] - L.mean()) < 6e3 and abs(arms["min"] - L.min()) < 6e3 and abs(arms["max"] - L.max()) < 6e3
    Ld = esa.length_dot[:, :3]
    assert abs(arms["rate_max"] - Ld.max()) < 5e-4 and abs(arms["rate_min"] - Ld.min()) < 5e-4
    lo, hi = rep.values["lisa/breathing_deg"]
    assert abs(lo - np.degrees(esa_alpha.min())) < 5e-5 and abs(hi - np.degrees(esa_alpha.max())) < 5e-5
    # and ESA's own ranges: corner angles 59.07 .. 61.00 deg, |dL/dt| up to 10.05 m/s in this first year
    assert 58.9 < lo < 59.2 and 60.9 < hi < 61.1 and 9.9 < arms["rate_max"] < 10.2

    act = rep.values["lisa/actuation"]
    # the drag-free G follows ESA's ramp along +X_S: mean over the 6 h rows -2e-9 + 4e-9 (T_run / 2) / T_span
    # (measured to 1e-8 relative: 1e-7 bound, 10x)
    span_d = (_dt.datetime(2047, 9, 9, 13, 4, 48) - _dt.datetime(2036, 12, 9)).total_seconds() / 86400.0
    ramp_mean = -2e-9 + 4e-9 * (365 / 2) / span_d
    np.testing.assert_allclose(act["G_mean_S"][:, 0], ramp_mean, rtol=1e-7)
    np.testing.assert_allclose(act["G_max"], 2e-9, rtol=1e-6)  # at t = 0 (measured 1.5e-7 relative)
    # nothing along the sensitive axes X_OA_l but round-off: measured 2.9e-16 of |G| (3e-15: 10x)
    assert np.all(act["A_sensitive"] < 3e-15 * 2e-9)
    # the suspension across them: measured 6.4e-16 m/s^2 at most (3e-15: 5x), and not zero
    assert 1e-16 < act["A_max"].max() < 3e-15
    # docs/report.md, "A year of lisa": the report's numbers and their differences to ESA's files
    values = {}
    for key, v in rep.values.items():
        if key.startswith("lisa/") and key != "lisa/spacecraft":
            *path, last = key.split("/")[1:]
            node = values
            for p in path:
                node = node.setdefault(p, {})
            node[last] = v
    record_number("report.lisa_year", {
        **values, "A_per_tm_axis": act["A_axis"].max(axis=0),
        "vs_esa": {"mean_m": arms["mean"] - L.mean(), "min_m": arms["min"] - L.min(), "max_m": arms["max"] - L.max(),
                   "rate_min": arms["rate_min"] - Ld.min(), "rate_max": arms["rate_max"] - Ld.max(),
                   "angle_lo_deg": lo - np.degrees(esa_alpha.min()), "angle_hi_deg": hi - np.degrees(esa_alpha.max())},
        "mean_over_design": arms["mean"] / 2.5e9 - 1, "A_sensitive_over_G": float(act["A_sensitive"].max() / 2e-9),
        "G_mean_rel_error": float(np.max(np.abs(act["G_mean_S"][:, 0] / ramp_mean - 1))),
        "G_across_max": float(np.max(act["G_axis_S"][:, 1:]))})


def test_taiji_and_tianqin_references(tmp_path, tianqin_short, record_number):
    """The constellation a report compares with: Taiji's 3e9 m design for the taiji architecture (mean arm over a
    year measured -0.17 % of it: 1 % bound, 6x), TianQin's sqrt(3) x 1e5 km for geocentric files (the mean
    over this hour of the cheap model measured +1.5e-5 of it: 1e-4 bound, 7x)."""
    from tqdyn.analysis import metrics
    from tqdyn.workflows.report.generic import constellation_reference

    out = tmp_path / "taiji.h5"
    tr = io.read_trajectory(run_to_file(load_scenario("taiji", ["run.duration=365d", f"run.output={out}"])).path)
    ref = constellation_reference(tr)
    assert ref is metrics.TAIJI and ref.arm_m == 3e9 and ref.breathing_band_deg is None
    assert tr.spacecraft.architecture == "taiji" and tr.spacecraft.dragfree_scheme == "lisa"
    L, rate = metrics.arm_lengths_of(tr)
    assert abs(L.mean() / 3e9 - 1) < 0.01
    # the rates are dL/dt: against a centred difference of the lengths on the 6 h grid (measured 2.1e-5 m/s, the
    # difference's truncation; 1e-4: 5x)
    dt = 21600.0
    assert np.max(np.abs((L[2:] - L[:-2]) / (2 * dt) - rate[1:-1])) < 1e-4
    alpha = np.degrees(metrics.breathing_angles_of(tr))
    record_number("report.taiji_year", {"arm_min_m": float(L.min()), "arm_max_m": float(L.max()),
                                        "mean_over_design": float(L.mean() / 3e9 - 1), "rate_min": float(rate.min()),
                                        "rate_max": float(rate.max()), "angle_min_deg": float(alpha.min()),
                                        "angle_max_deg": float(alpha.max()),
                                        "G_max": float(np.linalg.norm(tr["sat/a_dragfree"], axis=-1).max())})

    tq = io.read_trajectory(tianqin_short)
    assert constellation_reference(tq) is metrics.TIANQIN
    assert abs(metrics.arm_lengths_of(tq)[0].mean() / (math.sqrt(3) * 1e8) - 1) < 1e-4
