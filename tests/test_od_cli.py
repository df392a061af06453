"""``tqdyn od simulate | fit | covariance`` (tqdyn.cli.od, tqdyn.workflows.od; docs/commands.md).

The orbit-determination problem (tqdyn.od.problem) is replaced by the linear stand-in
tests/od_fake_problem.py, which has its interface: these tests check the command line and the files,
not the physics.  References: the weighted least-squares solution of the stand-in's linear model by
numpy's lstsq (independent of tqdyn's estimator) for the printed summary lines; the command-line
contract (one line on stderr and exit status 2 for bad input, 130 for Ctrl-C, nothing written then).
The run is tianqin-kepler, 1 day at 600 s (a few seconds).
"""

from __future__ import annotations

import numpy as np
import pytest

import od_fake_problem as fake
from od_fake_problem import fake_problem  # noqa: F401  (autouse: the stand-in replaces tqdyn.od.problem)
from cli_support import run_cli


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    import tqdyn

    d = tmp_path_factory.mktemp("od-run")
    tqdyn.run("tianqin-kepler", {"run.duration": "1d", "integrator.step": 600}, output=str(d / "run.h5"))
    return d / "run.h5"


def _simulate(run_file, out, capsys, *extra):
    return run_cli(["od", "simulate", str(run_file), "--tracking", "gnss,slr,isr,dsn", "--arc", "12h", "--seed", "3",
                    "--output", str(out), *extra], capsys)


def _lstsq(meas, scen_names):
    """Weighted least squares of the stand-in's linear model by numpy: (x, sigma, chi2)."""
    scen = type("S", (), {"satellites": [type("Sat", (), {"name": n}) for n in scen_names]})
    jac = fake.design(scen, meas) / meas.sigma[:, None]
    y = meas.value / meas.sigma
    x, *_ = np.linalg.lstsq(jac, y, rcond=None)
    cov = np.linalg.inv(jac.T @ jac)
    r = y - jac @ x
    return x, np.sqrt(np.diag(cov)), float(r @ r)


def test_simulate_then_fit_prints_the_least_squares_solution(run_file, tmp_path, capsys):
    """simulate writes the TDM; fit prints one line per parameter (value +- 1-sigma, unit) and chi^2/dof
    equal to numpy's weighted least squares of the same measurements; EST.h5 holds them."""
    from tqdyn.formats.od_estimate import read_estimate_file
    from tqdyn.formats.od_tdm import read_measurements_tdm

    tdm, est = tmp_path / "m.tdm", tmp_path / "est.h5"
    status, out, err = _simulate(run_file, tdm, capsys)
    assert status in (0, None), err
    assert out.splitlines()[0] == ("measurements: 1095 (219 gnss_pseudorange, 219 slr_range, 219 isr_range, "
                                   "219 dsn_range, 219 dsn_range_rate) over 43200 s, seed 3")
    status, out, err = run_cli(["od", "fit", str(run_file), str(tdm), "--output", str(est)], capsys)
    assert status in (0, None), err
    fields, info = read_measurements_tdm(tdm, grid_s=1.0)  # two-way rows back on the whole seconds
    assert info["seed"] == "3" and info["run_file"] == "run.h5"
    meas = fake.Measurements(**fields)
    names = ["Sat1", "Sat2", "Sat3"]
    x, sig, chi2 = _lstsq(meas, names)
    lines = out.splitlines()
    units = ["m", "m/s^2"] * 3
    pnames = [f"{s}/{p}" for s in names for p in ("x", "s_x")]
    for i, (line, n) in enumerate(zip(lines, pnames)):
        assert line == f"  {n:<8} = {x[i]: .9e} +- {sig[i]:.3e} {units[i]}"
    assert lines[6].startswith(f"chi2/dof = {chi2:.6g}/{1095 - 6} = {chi2 / 1089:.4g} (p = ")
    f = read_estimate_file(est)
    np.testing.assert_allclose(f.parameters["values"], x, rtol=1e-9)
    np.testing.assert_allclose(f.parameters["sigma"], sig, rtol=1e-9)
    assert np.array_equal(f.measurements["value"], meas.value)
    import hashlib

    assert f.attrs["tdm_sha256"] == hashlib.sha256(tdm.read_bytes()).hexdigest()
    assert "[scenario]" in f.attrs["scenario"] and f.attrs["scenario_name"] == "tianqin-kepler"


def test_covariance_prints_sigmas_and_writes_json(run_file, tmp_path, capsys):
    """covariance prints each parameter's 1-sigma (numpy's inverse normal matrix of the scheduled
    measurements) and writes them as JSON; a run file works as SCENARIO."""
    import json

    out_json = tmp_path / "cov.json"
    status, out, err = run_cli(["od", "covariance", str(run_file), "--tracking", "slr", "--arc", "12h",
                                "--json", str(out_json)], capsys)
    assert status in (0, None), err
    scen = type("S", (), {"satellites": [type("Sat", (), {"name": n}) for n in ("Sat1", "Sat2", "Sat3")]})
    meas = fake.schedule(scen, fake.Tracking(("slr",), 43200.0))
    meas.value = np.ones(len(meas.t))
    _, sig, _ = _lstsq(meas, ("Sat1", "Sat2", "Sat3"))
    rec = json.loads(out_json.read_text())
    np.testing.assert_allclose(rec["sigma"], sig, rtol=1e-9)
    assert rec["tracking"]["kinds"] == ["slr"] and rec["units"][:2] == ["m", "m/s^2"]
    assert out.splitlines()[1] == f"  Sat1/s_x   sigma = {sig[1]:.3e} m/s^2"


def _bad_tdm(tmp_path):
    p = tmp_path / "bad.tdm"
    p.write_text("CCSDS_TDM_VERS = 2.0\nCREATION_DATE = 2026-01-01T00:00:00\nORIGINATOR = x\nMETA_START\n"
                 "  TIME_SYSTEM = TT\n  FOO = 1\n")
    return p


@pytest.mark.parametrize("case, pattern", [
    ("tracking", r"--tracking: 'radar' is not a tracking type; allowed: gnss, slr, isr, dsn"),
    ("arc", r"--arc: 2.592e\+06 s is outside the run .*run.h5 \(86400 s from its epoch\)"),
    ("horizon", "tracking.stations: 'Nowhere' is below the 20 deg elevation mask for the whole arc"),
    ("sim-output-is-input", r"--output: .*run.h5' is the input RUN.h5"),
    ("fit-output-is-input", r"--output: .*good.tdm' is the input MEAS.tdm"),
    ("malformed", r"bad.tdm, line 6: FOO: not a TDM metadata keyword"),
    ("foreign", r"good.tdm: header: no 'COMMENT tqdyn epoch'"),
    ("estimate", r"tracking.estimate: 'bogus' is not a parameter group"),
    ("header", r"good.tdm: header: tqdyn arc_s = 'long'; allowed: a number of seconds > 0"),
    ("arc-format", r"--arc: 'week' is not a duration"),
    ("bias-type", r"--bias: 'gnss_pseudorange' is not allowed; allowed: slr_range, isr_range, dsn_range, "
                  r"dsn_range_rate"),
    ("bias-value", r"--bias: slr_range = 'abc' is not allowed; allowed: a finite number"),
    ("bias-form", r"--bias: 'slr_range' is not allowed; allowed: TYPE=VALUE or TYPE/STATION=VALUE"),
    ("consider", r"--consider: 's_frame' needs an a priori sigma; allowed: with --a-priori s_frame=SIGMA"),
    ("a-priori-group", r"--a-priori: 'j2' is not allowed; allowed: state, s_frame"),
    ("a-priori-state", r"--a-priori: state = '1' is not allowed; allowed: SIGMA_R,SIGMA_V \(m, m/s\)"),
    ("a-priori-value", r"--a-priori: bias = '-1' is not allowed; allowed: a finite number > 0"),
])
def test_refusals_are_one_line_and_write_nothing(run_file, tmp_path, capsys, case, pattern):
    """Bad input: exit status 2, one line on stderr, no file at the output path (nor a temporary one)."""
    good = tmp_path / "good.tdm"
    status, _, err = _simulate(run_file, good, capsys)
    assert status in (0, None), err
    out = tmp_path / "out"
    sim = ["od", "simulate", str(run_file), "--tracking", "gnss", "--arc", "12h", "--output", str(out)]
    fit = ["od", "fit", str(run_file), str(good), "--output", str(out)]
    if case == "foreign":
        good.write_text(good.read_text().replace("COMMENT tqdyn epoch", "COMMENT epoch"))
    if case == "header":
        good.write_text(good.read_text().replace("tqdyn arc_s = 43200.0", "tqdyn arc_s = long"))
    argv = {"tracking": sim[:4] + ["gnss,radar"] + sim[5:], "arc": sim[:6] + ["30d"] + sim[7:],
            "horizon": sim + ["--tracking", "slr", "--stations", "Yarragadee,Nowhere"],
            "sim-output-is-input": sim[:-1] + [str(run_file)], "fit-output-is-input": fit[:-1] + [str(good)],
            "malformed": ["od", "fit", str(run_file), str(_bad_tdm(tmp_path)), "--output", str(out)],
            "foreign": fit, "header": fit, "estimate": fit + ["--estimate", "state,bogus"],
            "arc-format": sim[:6] + ["week"] + sim[7:], "bias-type": sim + ["--bias", "gnss_pseudorange=1"],
            "bias-value": sim + ["--bias", "slr_range=abc"], "bias-form": sim + ["--bias", "slr_range"],
            "consider": fit + ["--estimate", "state", "--consider", "s_frame"],
            "a-priori-group": fit + ["--a-priori", "j2=1"], "a-priori-state": fit + ["--a-priori", "state=1"],
            "a-priori-value": fit + ["--a-priori", "bias=-1"]}[case]
    before = sorted(p.name for p in tmp_path.iterdir())
    status, _, err = run_cli(argv, capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error: "), err
    import re

    assert re.search(pattern, lines[0]), lines[0]
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("command", ["simulate", "fit"])
def test_ctrl_c_exits_130_without_a_file(run_file, tmp_path, capsys, monkeypatch, command):
    """Ctrl-C during the work: exit status 130, one line, no output file."""
    good = tmp_path / "good.tdm"
    if command == "fit":
        assert _simulate(run_file, good, capsys)[0] in (0, None)

    def stop(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(fake, command, stop)
    out = tmp_path / "out"
    argv = (["od", "simulate", str(run_file), "--tracking", "gnss", "--arc", "1h", "--output", str(out)]
            if command == "simulate" else ["od", "fit", str(run_file), str(good), "--output", str(out)])
    status, _, err = run_cli(argv, capsys)
    assert status == 130 and err.strip() == "tqdyn: error: interrupted; no output file written"
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_front_door_in_memory_matches_the_command(run_file, tmp_path, capsys):
    """tqdyn.od_simulate / od_fit / od_covariance (in memory) give what the commands write: the TDM's
    rows, the estimate file's values and sigmas, the covariance JSON's sigmas (reference: the files the
    commands wrote, read back with their readers and the open_* names)."""
    import json

    import tqdyn

    a, e = tmp_path / "a.tdm", tmp_path / "e.h5"
    assert _simulate(run_file, a, capsys)[0] in (0, None)
    ds = tqdyn.od_simulate(run_file, ["gnss", "slr", "isr", "dsn"], 43200, seed=3)
    on_file = tqdyn.open_measurements(a)
    assert int((ds.type == "slr_range").sum()) == 219
    for name in ("t", "value", "sigma", "sat"):
        assert np.array_equal(ds[name].values, on_file[name].values), name
    assert list(ds.type.values) == list(on_file.type.values) and list(ds.peer.values) == list(on_file.peer.values)
    status, _, err = run_cli(["od", "fit", str(run_file), str(a), "--output", str(e), "--edit-sigma", "6"], capsys)
    assert status in (0, None), err
    est = tqdyn.od_fit(str(run_file), ds, edit_sigma=6.0)
    f = tqdyn.open_od_estimate(e)
    assert tqdyn.read_od_estimate is tqdyn.open_od_estimate and tqdyn.read_closed_loop is tqdyn.open_closed_loop
    assert np.array_equal(f.parameters["values"], est.estimate.values)
    assert np.array_equal(f.parameters["sigma"], est.sigma.values) and est.attrs["edit_sigma"] == 6.0
    assert est.attrs["chi2"] == f.attrs["chi2"] and list(est.parameter.values) == list(f.parameters["names"])
    assert np.array_equal(tqdyn.od_fit(str(run_file), on_file, edit_sigma=6.0).estimate.values, est.estimate.values)
    cov = tqdyn.od_covariance("tianqin-kepler", "slr", "12h", estimate="s_frame")
    assert list(cov.parameter.values) == ["Sat1/s_x", "Sat2/s_x", "Sat3/s_x"]
    js = tmp_path / "c.json"
    assert run_cli(["od", "covariance", "tianqin-kepler", "--tracking", "slr", "--arc", "12h", "--estimate", "s_frame",
                    "--json", str(js)], capsys)[0] in (0, None)
    assert np.array_equal(json.loads(js.read_text())["sigma"], cov.sigma.values)
