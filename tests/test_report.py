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
         "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.moon_degree=0", "forces.sun_j2=false",
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
    # the paper's Fig. 5: ~1e-6 rad global, ~1e-11 rad Taylor (orders of magnitude)
    assert 1e-6 < m["global"]["per_beam"] < 1e-5
    assert abs(m["global"]["per_beam"] / global_ref - 1) < 0.01
    assert 1e-12 < m["taylor1"]["per_beam"] < 1e-10
    assert abs(m["taylor2"]["per_beam"] / taylor2_ref - 1) < 0.05
    for law in ("taylor1", "taylor2"):  # docs/design.md, Traps: cancel in X_S, add in theta
        assert m[law]["x_s"] < 1e-13 < m[law]["per_beam"] < m[law]["theta"]
    # tau ~ L/c costs (n . v) L / c^2 ~ 2e-6 s, not the paper's 1e-7 s
    L = geometry.by_mosa(a.length, axis=-1)[1:]
    assert abs(np.max(st.tau_error) / np.max(np.abs(nv) * L / C_LIGHT ** 2) - 1) < 0.02
    assert st.ltt_residual < 1e-20


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
    # the +flight self-gravity of tqdyn.studies is [0, -1e-9, 0] in S: check the sign on a run
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
    assert 1e-14 < c["max_A"] < 1e-12 and 1e-14 < c["max_G"] < 1e-12 and 1e-14 < c["max_alpha"] < 1e-12


def test_cli_report_runs(runs, tmp_path, capsys):
    code, out, err = _cli(["report", str(runs["dragfree"]), "--out", str(tmp_path / "o"), "-q"], capsys)
    assert code == 0, err
    assert "| quantity | paper | tqdyn | agreement / notes |" in out
    assert (tmp_path / "o" / "summary.md").is_file() and (tmp_path / "o" / "dragfree-control.pdf").is_file()
    assert err == ""


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
    code, out, err = _cli(args, capsys)
    assert code == 0 and "2 reused, 0 to run" in err


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
