"""Tests of tqdyn.analysis.metrics, tqdyn.analysis.pointing_study, tqdyn.workflows.studies,
tqdyn.workflows.report and the ``tqdyn report`` command.

References:
* pointing (Fig. 5): first-order aberration estimates written here from the
  trajectory's own velocities -- the global law misses the emitter's
  velocity perpendicular to the arm, |v_perp| / c; taylor2 keeps only the
  error of tau ~ L/c, (n . v) |v_perp| / c^2 (derived in docs/report.md);
* the secular along-track drift: the closed form -3/2 f T^2 for a constant
  tangential acceleration on a circular orbit (Hill / Clohessy-Wiltshire);
* the range ASD: the analytic one-sided ASD sqrt(2 / fs) sigma of white noise;
* the flight direction: Y_S . v / |v| computed from the stored frames;
* files and exit codes of the command line (expected names, one stderr line).
Short runs use a cheap force model (Earth degree 2, Sun and Moon) so the file
stays well under a minute; the full study set is exercised with --quick
(slow).
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn import cli
from tqdyn.formats import trajectory as io
from tqdyn.workflows import run as runner
from tqdyn.workflows import report as rp
from tqdyn.workflows import studies
from tqdyn.analysis import metrics
from tqdyn.analysis.pointing_study import compare_pointing_laws, pointing_study_of
from tqdyn.cli.report import report as report_command
from tqdyn.astro.constants import C_LIGHT
from tqdyn.constellation import geometry
from tqdyn.constellation.indices import Sat
from tqdyn.scenario import load_scenario

cli.cli.add_command(report_command)  # what tqdyn.cli does once the command is registered there

CHEAP = ["forces.earth_degree=2", "forces.third_bodies=sun,moon", "forces.solid_tides=false",
         "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.atmospheric_tides=false",
         "forces.moon_degree=0", "forces.sun_j2=false",
         "forces.relativity=false", "forces.earth_field_indirect=false"]


def _run(path, overrides, duration="6h", scenario="tianqin"):
    scen = load_scenario(scenario, [f"run.duration={duration}", f"run.output={path}", *CHEAP, *overrides])
    return runner.run_to_file(scen).path


def _study_run(path, name):
    spec = studies.RUNS[name]
    return _run(path, list(spec.overrides), scenario=spec.scenario)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("runs")
    return {"gravity": _study_run(d / "gravity.h5", "gravity-90d"),
            "dragfree": _run(d / "dragfree.h5", ["spacecraft.self_gravity=off"]),
            "flight": _study_run(d / "flight.h5", "sg-y-90d")}


def _cli(args, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(args)
        raise SystemExit(0)
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


# ---------------------------------------------------------------- pointing study


def test_pointing_study_orders_and_analytic_estimates(runs):
    tr = io.read_trajectory(runs["dragfree"])
    st = pointing_study_of(tr)
    m = st.maxima()
    # reference: aberration estimates from the stored velocities (no pointing code involved)
    a = geometry.arms(tr.dd("sat/r"))
    n = geometry.by_mosa(a.n)[1:]  # (N, 3, 2, 3) receiver -> emitter
    emitter = np.array([[s.k.index, s.j.index] for s in Sat])  # MOSA 1 <- k, MOSA 2 <- j
    v = tr["sat/v"][1:][:, emitter, :]
    nv = np.einsum("...k,...k->...", n, v)
    v_perp = np.linalg.norm(v - nv[..., None] * n, axis=-1)
    global_ref = np.max(v_perp) / C_LIGHT
    taylor2_ref = np.max(np.abs(nv) * v_perp) / C_LIGHT ** 2
    print(f"pointing maxima {m}; estimates global {global_ref:.3e}, taylor2 {taylor2_ref:.3e} rad")
    # the paper's Fig. 5: ~1e-6 rad global, ~1e-11 rad Taylor; README / docs/report.md: 5.77e-6, 3.85e-11,
    # 1.93e-11 rad (measured on this 6 h run: 5.77e-6, 3.84e-11, 1.92e-11 rad): ~3x either side, plus the estimates
    assert 2e-6 < m["global"]["per_beam"] < 2e-5
    assert abs(m["global"]["per_beam"] / global_ref - 1) < 0.01
    assert 1.2e-11 < m["taylor1"]["per_beam"] < 1.2e-10
    assert abs(m["taylor1"]["per_beam"] / (2 * taylor2_ref) - 1) < 0.05   # docs/report.md point 4: twice taylor2
    assert abs(m["taylor2"]["per_beam"] / taylor2_ref - 1) < 0.05
    for law in ("taylor1", "taylor2"):  # docs/design.md, Traps: cancel in X_S (measured 9.3e-15 / 5.1e-15 rad), add in theta
        assert m[law]["x_s"] < 5e-14 < m[law]["per_beam"] < m[law]["theta"]
    # tau ~ L/c costs (n . v) L / c^2 ~ 2e-6 s, not the paper's 1e-7 s
    L = geometry.by_mosa(a.length, axis=-1)[1:]
    assert abs(np.max(st.tau_error) / np.max(np.abs(nv) * L / C_LIGHT ** 2) - 1) < 0.02
    assert st.ltt_residual < 3e-31   # s; dd rounding of the light time (measured ~4e-32 s)


def test_pointing_study_bad_input():
    t = np.arange(10) * 50.0
    R = np.zeros((10, 3, 3))
    with pytest.raises(ValueError, match="laws"):
        compare_pointing_laws(t, R, R, R, laws=("local",))
    with pytest.raises(ValueError, match="stride"):
        compare_pointing_laws(t, R, R, R, stride=0)
    with pytest.raises(ValueError, match="A: shape"):
        compare_pointing_laws(t, R, R, R[:, :2])


# ---------------------------------------------------------------- analysis helpers


def test_secular_drift_constant_tangential_push():
    # reference: -3/2 f T^2 (Hill) for a constant along-track push on a circular orbit
    gm, a, f = 3.986004415e14, 1.0e8, 1e-9
    nn = np.sqrt(gm / a ** 3)
    t = np.linspace(0.0, 90 * 86400.0, 20001)
    ph = nn * t
    r = a * np.stack([np.cos(ph), np.sin(ph), 0 * ph], -1)[:, None, :]
    v = a * nn * np.stack([-np.sin(ph), np.cos(ph), 0 * ph], -1)[:, None, :]
    acc = f * v / np.linalg.norm(v, axis=-1, keepdims=True)
    drift = metrics.secular_along_track_drift(t, r, v, acc)
    assert abs(drift[-1, 0] / (-1.5 * f * t[-1] ** 2) - 1) < 1e-6


def test_range_asd_white_noise_level():
    # reference: white noise of standard deviation sigma sampled at fs has the
    # one-sided ASD sqrt(2 / fs) * sigma; here 0.3 pm/Hz^1/2 on top of 1.7e8 m
    rng = np.random.default_rng(1)
    dt, n = 50.0, 40000
    level = 0.3e-12
    sigma = level * np.sqrt(0.5 / dt)
    t = np.arange(n) * dt
    res = metrics.range_asd_in_band(t, np.full(n, 1.7e8), rng.normal(0.0, sigma, n))
    sel = (res.f > 2e-3) & (res.f < 9e-3)
    assert abs(np.median(res.asd[sel]) / level - 1) < 0.05
    assert res.band[1] == pytest.approx(0.01)
    # the requirement is 0.3 pm/Hz^1/2 * sqrt(1 + (7 mHz / f)^4) >= the noise: ratio <~ 1 near Nyquist
    assert 0.7 < res.max_ratio < 1.3 and res.f_at_max > 5e-3


def test_flight_direction_is_minus_y_s(runs):
    # the +flight self-gravity of tqdyn.workflows.studies is [0, -1e-9, 0] in S: check the sign on a run
    y = metrics.flight_axis_check(io.read_trajectory(runs["dragfree"]))
    assert np.max(y) < -0.9999
    assert studies.FLIGHT_DIRECTION_S == (0.0, -1.0, 0.0)


def test_flight_push_moves_the_orbit_along_track(runs):
    # reference: Hill / Clohessy-Wiltshire along-track response to a constant push f
    # along the velocity, zero initial offset: y(T) = f (4 (1 - cos nT) / n^2 - 3/2 T^2)
    # (forward first, then behind: -3/2 f T^2 dominates after a few orbits)
    grav = io.read_trajectory(runs["gravity"])
    dev = metrics.orbit_deviation(io.read_trajectory(runs["flight"]), grav)
    n = np.sqrt(3.986004415e14 / np.mean(np.linalg.norm(grav["sat/r"], axis=-1), axis=0) ** 3)
    T, f = dev.t[-1], 1e-9
    expected = f * (4 * (1 - np.cos(n * T)) / n ** 2 - 1.5 * T ** 2)
    print(f"+flight push: along-track {dev.along[-1]} m, Hill {expected} m")
    assert np.all(np.abs(dev.along[-1] / expected - 1) < 0.05)


def test_catalogue():
    for s in studies.STUDIES.values():
        assert s.runs and all(r in studies.RUNS for r in s.runs)
    # the extreme case (built-in scenario tianqin-extreme): Sat1 +flight, Sat2 -flight, Sat3 +flight
    ex = studies.RUNS["sg-extreme-90d"].scenario_for().spacecraft.self_gravity_values()[1]
    flight = np.array(studies.FLIGHT_DIRECTION_S)
    np.testing.assert_array_equal(ex, 1e-9 * np.array([flight, -flight, flight]))
    assert studies.scaled_duration_s(90, studies.QUICK_SCALE, 600.0) == 86400
    assert studies.scaled_duration_s(30, studies.QUICK_SCALE, 50.0) == 28800
    with pytest.raises(ValueError, match="duration scale"):
        studies.scaled_duration_s(90, 0.0, 50.0)
    plan = studies.plan_studies("/nonexistent/runs", studies=["extreme"], duration_scale=studies.QUICK_SCALE,
                                check_data=False)
    assert [p.name for p in plan] == ["gravity-90d", "sg-extreme-90d"] and not any(p.done for p in plan)
    with pytest.raises(ValueError, match="study"):
        studies.plan_studies("x", studies=["fig5"])


# ---------------------------------------------------------------- report of given runs


def test_report_runs_files_and_rows(runs, tmp_path):
    out = tmp_path / "rep"
    rep = rp.report_runs([runs["gravity"], runs["dragfree"]], out)
    names = {p.name for p in rep.figures}
    for stem in ("dragfree-control", "dragfree-breathing", "dragfree-range-asd", "dragfree-pointing",
                 "gravity-breathing", "gravity-range-asd", "gravity-pointing", "deviations"):
        for ext in ("png", "pdf"):
            assert f"{stem}.{ext}" in names
            assert (out / f"{stem}.{ext}").stat().st_size > 1000
    text = rep.summary_path.read_text()
    assert text.startswith("# tqdyn report") and "| quantity | paper | tqdyn | agreement / notes |" in text
    quantities = [r.quantity for r in rep.rows]
    for q in ("dragfree: max |A| TM suspension", "dragfree: max |alpha| TM angular", "dragfree: max |G| drag-free",
              "dragfree: flight direction in S", "dragfree: breathing angles", "dragfree: TM-TM light-path range ASD",
              "gravity: Sat-Sat light-path range ASD", "dragfree: pointing error global",
              "dragfree: max orbit deviation from gravity"):
        assert any(x.startswith(q) for x in quantities), q
    # no self-gravity: the controls are at the paper's ~1e-13 level (Fig. 7)
    c = rep.values["dragfree/control"]
    print(f"\n6 h, cheap model, no self-gravity: max |A| {c['max_A']:.2e} m/s^2, |G| {c['max_G']:.2e} m/s^2, "
          f"|alpha| {c['max_alpha']:.2e} rad/s^2")
    # the paper's ~1e-13 (Fig. 7); measured on these 6 h 9.15e-14 m/s^2, 5.31e-14 m/s^2, 1.29e-13 rad/s^2 (the
    # README's first-day values: 1.4e-13, 1.1e-13, 3.1e-13): ~3x either side
    assert 3e-14 < c["max_A"] < 3e-13 and 1.5e-14 < c["max_G"] < 2e-13 and 4e-14 < c["max_alpha"] < 4e-13


def test_cli_report_runs(runs, tmp_path, capsys):
    code, out, err = _cli(["report", str(runs["dragfree"]), "--out", str(tmp_path / "o"), "-q"], capsys)
    assert code == 0, err
    assert "| quantity | paper | tqdyn | agreement / notes |" in out
    assert (tmp_path / "o" / "summary.md").is_file() and (tmp_path / "o" / "dragfree-control.pdf").is_file()
    assert err == ""
    import json

    rec = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert rec["written_by"] == "tqdyn report" and rec["rows"] and "dragfree/control" in rec["values"]
    assert rec["runs"][str(runs["dragfree"])]["file_mb"] > 0


@pytest.mark.parametrize("args, match", [
    (["report"], "no trajectory file"),
    (["report", "/nonexistent/run.h5"], "does not exist"),
    (["report", "NOTATRAJ"], "not a readable HDF5"),
    (["report", "--quick", "x.h5"], "--quick: only applies with --studies"),
    (["report", "--studies", "x.h5"], "either trajectory files or --studies"),
    (["report", "--studies", "--study", "fig5"], "study: 'fig5' is not a study"),
    (["report", "--studies", "--quick", "--duration-scale", "0.5"], "conflicts"),
    (["report", "--studies", "--duration-scale", "-1"], "duration scale"),
    (["report", "--studies", "--set", "forces.earth_degree=500"], "forces.earth_degree"),
])
def test_cli_bad_input(args, match, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "NOTATRAJ").write_text("hello")
    code, out, err = _cli(args, capsys)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("tqdyn: error: ") and match in err, err
    assert out == ""
    assert not (tmp_path / "tqdyn-report").exists() and not (tmp_path / "tqdyn-studies" / "runs").exists()


def test_cli_not_a_trajectory_hdf5(tmp_path, capsys):
    import h5py

    with h5py.File(tmp_path / "other.h5", "w") as h5:
        h5["x"] = np.zeros(3)
    code, _out, err = _cli(["report", str(tmp_path / "other.h5"), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and err.count("\n") == 1 and "format" in err


# ---------------------------------------------------------------- the studies end to end


def test_cli_one_study_quick_in_process(tmp_path, capsys):
    # one study (Fig. 9) at 1/90 of its span, cheap forces, in this process; the second call reuses both runs
    args = ["report", "--studies", "--study", "extreme", "--quick", "--workers", "1", "--out", str(tmp_path / "s"),
            *[a for s in CHEAP for a in ("--set", s)]]
    code, out, err = _cli(args, capsys)
    assert code == 0, err
    assert "0 reused, 2 to run" in err
    assert "\n| Fig. 9: extreme case, breathing angles over 1 d" in out
    assert {p.name for p in (tmp_path / "s").glob("fig9*")} == {"fig9-extreme-breathing.png",
                                                               "fig9-extreme-breathing.pdf"}
    # summary.json: every number of the table with its provenance, the runs with their size and wall time
    import json

    rec = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert rec["written_by"] == "tqdyn report" and rec["command"].startswith("tqdyn report --studies --quick")
    assert rec["machine"]["cores"] >= 1 and rec["libraries"]["numpy"] and rec["date"].endswith("Z")
    assert rec["mission"] == "tianqin" and rec["duration_scale"] == pytest.approx(1 / 90)
    assert [r["quantity"] for r in rec["rows"]][0].startswith("Fig. 9: extreme case, breathing angles over 1 d")
    assert rec["values"]["extreme"]["range"][0] < 60 < rec["values"]["extreme"]["range"][1]
    assert set(rec["runs"]) == {"gravity-90d", "sg-extreme-90d"}
    assert all(r["status"] == "ran" and r["file_mb"] > 0 and r["wall_s"] > 0 and r["rows"] > 1
               for r in rec["runs"].values())
    assert rec["timing"]["n_runs"] == 2 and rec["timing"]["total_wall_s"] > 0
    code, out, err = _cli(args, capsys)
    assert code == 0 and "2 reused, 0 to run" in err
    rec = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert all(r["status"] == "reused" and r["wall_s"] is None for r in rec["runs"].values())


@pytest.mark.slow
def test_cli_studies_quick(tmp_path, capsys):
    # every study run at 1/90 of its span with the cheap force model, then the report; a second call reuses the runs
    args = ["report", "--studies", "--quick", "--out", str(tmp_path / "s"), "--workers", "2",
            *[a for s in CHEAP for a in ("--set", s)]]
    code, out, err = _cli(args, capsys)
    assert code == 0, err
    for stem in ("fig5-pointing", "fig6-range-asd", "fig7-control-no-self-gravity", "fig8-control-table-iv",
                 "dragfree-deviation", "common-self-gravity", "fig9-extreme-breathing",
                 "fig10-lightpath-vs-instantaneous", "fig11-sat-vs-tm"):
        for ext in ("png", "pdf"):
            assert (tmp_path / "s" / f"{stem}.{ext}").is_file(), stem
    for q in ("Fig. 5: global pointing", "Fig. 6: ASD(drag-free - gravity", "Fig. 7: max", "Fig. 8: max",
              "Sec. V.A: drag-free", "Sec. V.B.2: +flight", "Fig. 9: extreme case", "Fig. 10: light-path range ASD",
              "Fig. 11: ASD(TM-TM - Sat-Sat"):
        assert f"\n| {q}" in out, q
    assert "skipped" not in out
    code, out, err = _cli(args + ["-q"], capsys)
    assert code == 0 and "reused" not in err  # quiet
    assert len(list((tmp_path / "s" / "runs").glob("*.h5"))) == len(
        {r for s in studies.STUDIES.values() for r in s.runs})


def _band(value, quoted, factor=3.0):
    """value within a factor ``factor`` of the quoted (README / docs) number, same sign (both sides)."""
    value, quoted = np.asarray(value, dtype=float), np.asarray(quoted, dtype=float)
    return bool(np.all(np.sign(value) == np.sign(quoted)) and np.all(np.abs(value) > np.abs(quoted) / factor)
                and np.all(np.abs(value) < np.abs(quoted) * factor))


@pytest.mark.slow
def test_paper_studies_full_spans(tmp_path):
    """The numbers of docs/report.md ("Summary (full spans)" and "Where tqdyn differs") and of the README's
    "Reproducing the paper" table, from the 14 study runs at full spans (``tqdyn report --studies``: 10 min
    with one worker on the 2-core test machine, the report itself 20 s).  Each quoted number is bounded within a factor 3 either
    side (a zero would be wrong for every one of them), and where docs/report.md derives a value the
    derivation is the reference: Hill's equations for the common self-gravity pushes, the secular along-track
    drift of the stored G, the tidal model of the local-vs-global G, the aberration estimates of the pointing
    laws.  TQDYN_STUDIES_RUNS_DIR keeps the runs between sessions (complete runs are reused);
    TQDYN_STUDIES_WORKERS sets the number of worker processes (default: one per core)."""
    import json
    import math
    import os

    runs_dir = os.environ.get("TQDYN_STUDIES_RUNS_DIR") or tmp_path / "runs"
    workers = int(os.environ.get("TQDYN_STUDIES_WORKERS", "0")) or None
    res = studies.run_studies(runs_dir, workers=workers)
    assert not res.failures, [(o.run.name, o.error) for o in res.failures]
    rep = rp.report_studies({n: res.path(n) for n in res.outcomes}, tmp_path / "out")
    v = rep.values
    print("\nstudy values: " + json.dumps(v, default=lambda x: np.asarray(x).tolist(), indent=1))

    # Fig. 5 (30 d): per beam 5.77e-6 / 3.85e-11 / 1.93e-11 rad; global X_S 5.8e-6, theta 1.0e-8; taylor1 X_S
    # 4.6e-14, theta 7.7e-11; 2nd / 1st order 0.50; tau - L/c 1.93e-6 s (s. tests/test_pointing.py for the
    # aberration estimates as references)
    p = v["pointing"]
    assert _band(p["global"]["per_beam"], 5.77e-6) and _band(p["global"]["x_s"], 5.8e-6)
    assert _band(p["global"]["theta"], 1.0e-8)
    assert _band(p["taylor1"]["per_beam"], 3.85e-11) and _band(p["taylor1"]["x_s"], 4.6e-14)
    assert _band(p["taylor1"]["theta"], 7.7e-11) and _band(p["taylor2"]["per_beam"], 1.93e-11)
    assert 0.4 < p["taylor2"]["per_beam"] / p["taylor1"]["per_beam"] < 0.6
    assert _band(v["pointing/tau_error_max"], 1.93e-6)
    # Fig. 6 / Fig. 10: range ASD / requirement (max in 0.1 .. 10 mHz): the gravity orbits' own signal 2.43 (the
    # same 2.43 on the Table IV TM-TM light path: the control adds nothing there), differences 1.65e-5
    # (drag-free - gravity), 1.84e-5 (global - local), 6.76e-4 (light path - instantaneous), 9.17e-4 (TM - Sat)
    # (tqdyn 0.1's time axis and force model: 2.42, 1.57e-5, 1.80e-5, 6.76e-4, 9.34e-4; docs/report.md)
    assert _band(v["asd/gravity"], 2.43) and _band(v["asd/light_path"], 2.43)
    assert abs(v["asd/light_path"] / v["asd/gravity"] - 1) < 0.05
    assert _band(v["asd/dragfree_minus_gravity"], 1.65e-5) and _band(v["asd/global_minus_local"], 1.84e-5)
    assert _band(v["asd/lp_minus_inst"], 6.76e-4) and _band(v["asd/tm_minus_sat"], 9.17e-4)
    # light-time residual (iterative, dd): 2.77e-23 m
    assert v["lightpath/residual_max"] * C_LIGHT < 3 * 2.77e-23
    # Fig. 7 (30 d, no self-gravity): |A| 6.56e-13 (first day 1.4e-13) m/s^2, |alpha| 7.44e-13 (3.1e-13) rad/s^2,
    # |G| 3.52 / 4.40 / 5.22e-13 (first day 1.1e-13) m/s^2; the flight direction is -Y_S on every row
    c = v["control_no_sg"]
    assert _band(c["max_A"], 6.56e-13) and _band(c["max_A_day1"], 1.4e-13)
    assert _band(c["max_alpha"], 7.44e-13) and _band(c["max_alpha_day1"], 3.1e-13)
    assert _band(c["max_G_per_sat"], [3.52e-13, 4.40e-13, 5.22e-13]) and _band(c["max_G_day1"], 1.1e-13)
    assert v["flight_axis"][1] < -0.99999
    # Fig. 8 (30 d, Table IV): |A| per TM 9.20e-11 (< 1e-10, as the paper says), |A_1 - A_2| 1.75e-10 m/s^2
    # (Table IV's own z difference is 1.67e-10)
    c = v["control_table_iv"]
    assert _band(c["max_A"], 9.20e-11) and c["max_A"] < 1e-10
    assert 1.67e-10 - 1e-12 < c["max_dA"] < 3 * 1.75e-10
    # Sec. V.A (90 d): drag-free vs gravity max |dr| 1.47 / 0.70 / 0.90 m, along-track at 90 d 1.47 / -0.66 /
    # -0.74 m measured vs 1.36 / -0.59 / -0.66 m predicted (reference: the secular drift of the stored G,
    # within the ~10 % first-order theory leaves), max |G| first day 1.0e-13 / 1.2e-14 / 1.1e-13 -> 90 d 4.2e-13 /
    # 4.4e-13 / 5.5e-13 m/s^2; local (taylor2) pointing 1.68 / 0.51 / 0.68 m
    d = v["deviation/dragfree-global-90d"]
    assert _band(d["max"], [1.47, 0.70, 0.90]) and _band(d["end_along"], [1.47, -0.66, -0.74])
    assert _band(d["pred_end"], [1.36, -0.59, -0.66])
    np.testing.assert_allclose(d["end_along"], d["pred_end"], rtol=0.2)
    assert _band(d["G_first_day"], [1.0e-13, 1.2e-14, 1.1e-13]) and _band(d["G_max"], [4.2e-13, 4.4e-13, 5.5e-13])
    assert _band(v["deviation/dragfree-local-90d"]["max"], [1.68, 0.51, 0.68])
    # local vs global: 0.217 m per satellite in 90 d; dG along Y_S 2.39e-15 m/s^2 (X_S 4e-18, Z_S 2e-21) =
    # 3 n^2 (d_TM/2) delta cot(theta/2) with delta = 5.77e-6 rad (reference: that model, and 3/2 dG T^2)
    lg = v["deviation/local_vs_global"]
    T = 90 * 86400.0
    assert _band(lg["max"], [0.217] * 3)
    np.testing.assert_allclose(lg["max"], 1.5 * lg["model"] * T ** 2, rtol=0.05)
    assert _band(lg["dG_max"][:, 1], [2.39e-15] * 3)
    np.testing.assert_allclose(lg["dG_max"][:, 1], lg["model"], rtol=0.01)
    assert np.all(lg["dG_max"][:, 0] < 3 * 4e-18) and np.all(lg["dG_max"][:, 2] < 3 * 2e-21)
    assert _band(lg["delta_max"], [5.77e-6] * 3)
    # Sec. V.B.2 (90 d): 1e-9 m/s^2 common self-gravity: +flight (-y) 90.67 / 90.68 / 90.67 km, along-track
    # -90.66 .. -90.68 km (falls behind); per direction (max over satellites) +-x 0.784 / 0.786 km, +-y 90.7 km,
    # +-z 3.32 / 3.39 m.  References (Hill): along-track push 3/2 f T^2 - 4 f (1 - cos nT) / n^2 = 90.69 km,
    # radial push 2 f T / n = 0.779 km, normal push bounded by 2 f / n^2 = 5 m
    sg = v["common_sg"]
    f, n = 1e-9, math.sqrt(3.986004415e14 / 1e8 ** 3)
    assert _band(sg["-y"]["dev_end"], [90.67e3, 90.68e3, 90.67e3]) and _band(sg["+y"]["dev_end"].max(), 90.7e3)
    assert _band(sg["-y"]["along_end"], [-90.66e3, -90.68e3, -90.67e3])
    for label in ("-y", "+y"):
        np.testing.assert_allclose(sg[label]["dev_end"], f * (1.5 * T ** 2 - 4 * (1 - math.cos(n * T)) / n ** 2),
                                   rtol=0.01)
    for label, quoted in (("+x", 784.0), ("-x", 786.0)):
        assert _band(sg[label]["dev_end"].max(), quoted)
        np.testing.assert_allclose(sg[label]["dev_end"].max(), 2 * f * T / n, rtol=0.05)
    for label, quoted in (("+z", 3.32), ("-z", 3.39)):
        # the normal push does not drift: its 90-day maximum stays at the Hill amplitude 2 f / n^2 = 5.0 m (measured
        # 5.25 m, 5 % above the first-order value docs/report.md calls a bound)
        assert _band(sg[label]["dev_end"].max(), quoted) and sg[label]["dev_max"].max() < 1.2 * 2 * f / n ** 2
    # breathing angles: change < 1e-4 deg ("max 0.0001 deg") in the six runs; the angles 59.9369 .. 60.0659 deg
    # (the excursions from 60 deg bounded within 3x)
    assert max(sg[label]["dalpha_max"] for label in sg) < 3e-4
    lo = min(sg[label]["alpha_range"][0] for label in sg)
    hi = max(sg[label]["alpha_range"][1] for label in sg)
    assert _band(lo - 60, 59.9369 - 60) and _band(hi - 60, 60.0659 - 60)
    # Fig. 9 (90 d): extreme case 59.8953 .. 60.1074 deg, first outside 60 +- 0.1 deg at day 86.0 ("near the end
    # of 3 months"); change vs gravity 0.0522 / 0.0005 / 0.0517 deg; deviation 90.7 km per satellite; the
    # gravity orbit alone 59.9369 .. 60.0659 deg
    ex = v["extreme"]
    assert _band(ex["range"][0] - 60, 59.8953 - 60) and _band(ex["range"][1] - 60, 60.1074 - 60)
    assert ex["first_exit_day"] is not None and 80 < ex["first_exit_day"] < 90
    assert _band(ex["change_max"], [0.0522, 0.0005, 0.0517]) and _band(ex["dev_end"], [90.7e3] * 3)
    assert _band(ex["gravity_range"][0] - 60, 59.9369 - 60) and _band(ex["gravity_range"][1] - 60, 60.0659 - 60)


@pytest.mark.slow
def test_gravity_orbit_range_asd_is_the_earth_field(record_number):
    """docs/report.md point 6: the Sat1-Sat3 light-path range ASD of the 30-day gravity orbits is 2.4 times the
    requirement at 0.100 mHz and below it from 0.104 mHz on; it is the orbits' response to the Earth's field:
    only the Earth's field (static field and tides) gives the same ratio (2.41), only the Moon and the Sun
    0.011, Kepler alone 1e-9 (at the band's lower edge); the static field truncated at degree 6 0.19, at 8 and
    12 2.24; Welch segments of 6.3, 12.5 and 25 days give 2.4, 1.9, 2.5 (not window leakage).  Bounds 3x
    either side; 30-day pure-gravity runs at 50 s through the public API (~80 s in all)."""
    import tqdyn
    from tqdyn.analysis import spectra
    from tqdyn.constellation.indices import Link

    no_bodies = ["forces.third_bodies=[]", "forces.third_bodies_extended=[]", "forces.moon_degree=0",
                 "forces.sun_j2=false", "forces.relativity=false", "forces.earth_field_indirect=false"]
    no_tides = ["forces.solid_tides=false", "forces.ocean_tides_degree=0", "forces.pole_tides=false"]
    cases = {"full": [], "earth": no_bodies,
             "moon+sun": [*no_tides, "forces.earth_degree=0", "forces.third_bodies=sun,moon", "forces.moon_degree=0",
                          "forces.sun_j2=false", "forces.relativity=false", "forces.earth_field_indirect=false"],
             "kepler": [*no_bodies, *no_tides, "forces.earth_degree=0"],
             **{f"static-{n}": [*no_bodies, *no_tides, f"forces.earth_degree={n}"] for n in (6, 8, 12)}}
    asd, lts = {}, {}
    for name, overrides in cases.items():
        lts[name] = tqdyn.light_travel_times(tqdyn.propagate("tianqin-gravity", ["run.duration=30d", *overrides]))
        asd[name] = tqdyn.range_asd(lts[name], "13")
    print("\n30-day gravity orbits, link 13, ASD / requirement in 0.1 .. 10 mHz: " + ", ".join(
        f"{k} {a.max_ratio:.3g} at {a.f_at_max:.3g} Hz" for k, a in asd.items()) + f"; full: >= 1 up to "
        f"{asd['full'].f_above} Hz")
    full = asd["full"]
    assert full.band[0] == pytest.approx(1e-4) and _band(full.max_ratio, 2.42) and full.max_ratio > 1
    assert full.f_at_max == pytest.approx(1e-4) and 1e-4 <= full.f_above < 2e-4   # measured 1.037e-4 Hz
    assert _band(asd["earth"].max_ratio, 2.41) and abs(asd["earth"].max_ratio / full.max_ratio - 1) < 0.05
    assert _band(asd["moon+sun"].max_ratio, 0.011)
    # Kepler: the ratio at the band's lower edge (docs "1e-9"; measured 1.5e-9); its band maximum is the numerical
    # floor near Nyquist (measured 8.7e-6 at 8.8 mHz)
    k = asd["kepler"]
    sel = (k.f >= k.band[0]) & (k.f <= k.band[1])
    assert _band(k.asd[sel][0] / spectra.requirement_asd(k.f[sel][0]), 1e-9) and k.max_ratio < 3e-5
    assert _band(asd["static-6"].max_ratio, 0.19)
    assert _band(asd["static-8"].max_ratio, 2.24) and _band(asd["static-12"].max_ratio, 2.24)
    # Welch segments of 6.25 (the default, 10800 samples), 12.5 and 25 days: 2.42, 1.94, 2.55 measured
    lt = lts["full"]
    i = Link(13).index
    hi, lo = lt.range[0][:, i], lt.range[1][:, i]
    ok = np.isfinite(hi)
    t = (lt.t[0] + lt.t[1])[ok]
    ratios = []
    for nperseg, quoted in ((10800, 2.4), (21600, 1.9), (43200, 2.5)):
        f, a = spectra.range_asd(t, hi[ok], lo[ok], nperseg=nperseg)
        ratios.append(spectra.band_limited_max_ratio(f, a, 50.0, band=(1e-4, 1e-2))[0])
        assert _band(ratios[-1], quoted), (nperseg, ratios[-1])
    assert ratios[0] == pytest.approx(full.max_ratio, rel=1e-9) and max(ratios) / min(ratios) < 1.5
    record_number("report.gravity_asd", {**{name: a.max_ratio for name, a in asd.items()}, "welch": ratios,
                                         "kepler_at_0.1mHz": float(k.asd[sel][0] / spectra.requirement_asd(k.f[sel][0])),
                                         "f_above_full": full.f_above})
