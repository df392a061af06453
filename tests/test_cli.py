"""The command line: `tqdyn run` end to end, bad input, interruption, info, bench.

Reference values: the analytic two-body solution (mpmath, 50 digits) of the
tianqin-kepler elements (Table I of the TianQin paper) -- independent of the
integrator -- and the trajectory-file contract of docs/design.md, Contracts (docs/trajectory-format.md).
"""

from __future__ import annotations

import os

import mpmath
import numpy as np
import pytest

from tqdyn.astro import elements
from tqdyn.formats import trajectory as io
from tqdyn import dynamics
from tqdyn.numerics.dd import mp_from_dd
from tqdyn.scenario import load_scenario, loads_scenario
from cli_support import run_cli as _run
from cli_support import run_cli_interrupted




def _no_files(directory) -> list[str]:
    return sorted(os.listdir(directory))


def test_run_default_scenario_writes_valid_file(default_run):
    """`tqdyn run` with no scenario argument: the built-in tianqin scenario
    (full force model), 10 days at 50 s, written to the default file name in
    the working directory (the session fixture ``default_run``, conftest.py)."""
    status, out, err, path = default_run
    assert status == 0, err
    assert path.exists() and path.name == "tqdyn-run.h5"
    assert "wall time" in out and "Sat3" in out
    tr = io.read_trajectory(path)
    scen = load_scenario("tianqin")
    assert tr.attrs["format"] == "tqdyn-trajectory" and tr.attrs["format_version"] == 2
    assert tr.attrs["time_scale"] == "TT" and tr.attrs["frame"] == "GCRS" and tr.attrs["origin"] == "earth"
    assert tr.attrs["precision"] == "dd" and tr.attrs["epoch_utc"] == "2004-06-06T00:00:00"
    assert tr.attrs["step_s"] == 50.0
    assert loads_scenario(tr.scenario_toml) == scen  # the resolved scenario is in the file
    t_hi, t_lo = tr.dd("t")
    n = scen.n_steps
    assert t_hi.shape == (n + 1,) and t_hi[-1] + t_lo[-1] == float(scen.run.duration_s)
    np.testing.assert_array_equal(np.diff(t_hi), 50.0)
    r_hi, r_lo = tr.dd("sat/r")
    assert r_hi.shape == (n + 1, 3, 3) and tr["sat/a_gravity"].shape == (n + 1, 3, 3)
    # a_gravity: the monopole GM/r^2 plus perturbations (Moon ~2e-5 m/s^2, J2 ~5e-7 m/s^2
    # against 4e-2 m/s^2): within 1e-3 relative of GM/r^2
    a = np.linalg.norm(tr["sat/a_gravity"], axis=-1)
    r = np.linalg.norm(r_hi + r_lo, axis=-1)
    np.testing.assert_allclose(a, float(scen.forces.gm_earth) / r**2, rtol=1e-3)


def test_run_default_scenario_printed_numbers(default_run):
    """The README's `tqdyn run` transcript (the multistep method, order 10, PECE): 17280 steps, 34671
    right-hand-side evaluations (the 10 DP87 start-up steps, 13 each and one at their end, then 2 per step),
    17281 rows, and the control maxima it prints, which must be those of the file.  The magnitudes themselves
    are bounded in tests/test_coupled.py::test_default_run_control_maxima."""
    status, out, err, path = default_run
    assert status == 0, err
    assert "steps: 17280 accepted, 34671 right-hand-side evaluations" in out
    assert "(17281 rows," in out
    printed = {}
    for line in out.splitlines():
        for key in ("max |G_i| (drag-free)", "max |A_c,l| component (suspension)",
                    "max |alpha_l| component (TM angular)"):
            if line.startswith(key + ":"):
                printed[key] = float(line.split(":")[1].split()[0])
    tr = io.read_trajectory(path)
    file_values = {"max |G_i| (drag-free)": np.linalg.norm(tr["sat/a_dragfree"], axis=-1).max(),
                   "max |A_c,l| component (suspension)": np.abs(tr["tm/a_suspension"]).max(),
                   "max |alpha_l| component (TM angular)": np.abs(tr["tm/alpha_suspension"]).max()}
    print(f"\nprinted {printed}; file {file_values}")
    assert set(printed) == set(file_values), out
    for key, value in file_values.items():
        # the run's maxima cover the evaluations of the rows, which are the file's rows; 4 digits printed
        assert abs(printed[key] / value - 1) < 1e-3, (key, printed[key], value)


def test_run_kepler_matches_analytic(tmp_path, capsys):
    """tianqin-kepler through the CLI: the file's final positions against the
    analytic two-body solution (mpmath, 50 digits)."""
    out_file = tmp_path / "kepler.h5"
    status, out, err = _run(["run", "tianqin-kepler", "--duration", "1d", "-o", str(out_file), "-q"], capsys)
    assert status == 0, err
    assert "energy drift" in out
    tr = io.read_trajectory(out_file)
    scen = load_scenario("tianqin-kepler", ["run.duration=1d"])
    r_hi, r_lo = tr.dd("sat/r")
    got = mp_from_dd(np.stack([r_hi[-1], r_lo[-1]], axis=-1))
    with mpmath.workdps(50):
        for sat, row in zip(scen.satellites, got):
            ref, _ = elements.kepler_state_at(sat.a_m, sat.e, elements.deg(sat.i_deg), elements.deg(sat.raan_deg),
                                              elements.deg(sat.argp_deg), elements.deg(sat.nu_deg),
                                              scen.forces.gm_earth, scen.run.duration_s)
            err = float(mpmath.sqrt(sum((a - b) ** 2 for a, b in zip(row, ref))))
            assert err < 1e-12, (sat.name, err)
    a = tr["sat/a_gravity"][-1]
    r = r_hi[-1] + r_lo[-1]
    gm = float(scen.forces.gm_earth)
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), gm / np.linalg.norm(r, axis=1) ** 2, rtol=1e-14)


def test_run_options_and_overrides(tmp_path, capsys):
    out_file = tmp_path / "short.h5"
    status, out, err = _run(["run", "tianqin-kepler", "--duration", "2h", "--step", "25", "--precision", "float64",
                             "--set", "run.output_every=4", "-o", str(out_file), "-q"], capsys)
    assert status == 0, err
    tr = io.read_trajectory(out_file)
    assert tr.attrs["precision"] == "float64" and tr.attrs["step_s"] == 25.0
    t = tr["t"]
    assert t[0] == 0.0 and t[-1] == 7200.0 and np.all(np.diff(t) == 100.0)
    assert np.all(tr.dd("sat/r")[1] == 0.0)  # float64 run: lo parts are zero


def test_adaptive_run(tmp_path, capsys):
    out_file = tmp_path / "adaptive.h5"
    status, out, err = _run(["run", "tianqin-kepler", "--duration", "1d", "--set", "integrator.mode=adaptive",
                             "--set", "integrator.rtol=1e-16", "-o", str(out_file), "-q"], capsys)
    assert status == 0, err
    assert "rejected" in out
    tr = io.read_trajectory(out_file)
    np.testing.assert_array_equal(np.diff(tr["t"]), 50.0)  # sampled on the output grid


@pytest.mark.parametrize("argv, needle", [
    (["run", "no-such-scenario"], "no-such-scenario"),
    (["run", "--set", "integrator.bogus=1"], "integrator.bogus"),
    (["run", "--set", "nonsense"], "nonsense"),
    (["run", "--step", "-50"], "-50"),
    (["run", "--step", "0"], "step"),
    (["run", "--duration", "1000", "--step", "300"], "1000"),
    (["run", "--duration", "ten days"], "ten days"),
    (["run", "--precision", "quad"], "quad"),
    (["run", "--set", "satellites.7.e=0.1"], "satellites.7"),
    (["run", "--set", "satellites.1.e=1.5"], "1.5"),
    (["frobnicate"], "frobnicate"),
])
def test_bad_input_one_line_exit_2(tmp_path, capsys, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    status, out, err = _run(argv, capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error:"), err
    assert needle in lines[0]
    assert "Traceback" not in err
    assert _no_files(tmp_path) == []


def test_malformed_toml_and_missing_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bad = tmp_path / "bad.toml"
    bad.write_text("[run\nduration = 5\n")
    status, _, err = _run(["run", str(bad)], capsys)
    assert status == 2 and "bad.toml" in err and len(err.strip().splitlines()) == 1
    status, _, err = _run(["run", str(tmp_path / "missing.toml")], capsys)
    assert status == 2 and "missing.toml" in err
    assert _no_files(tmp_path) == ["bad.toml"]


def test_unwritable_output(tmp_path, capsys):
    target = tmp_path / "no" / "such" / "dir" / "x.h5"
    status, _, err = _run(["run", "-o", str(target)], capsys)
    assert status == 2 and str(target.parent) in err
    status, _, err = _run(["run", "-o", str(tmp_path)], capsys)  # a directory
    assert status == 2 and len(err.strip().splitlines()) == 1


def test_interrupt_leaves_no_file(tmp_path, capsys, monkeypatch):
    """Ctrl-C during the propagation: exit 130, no output, no temporary file,
    an existing output file untouched."""
    out_file = tmp_path / "run.h5"
    out_file.write_bytes(b"previous")
    real = dynamics.propagate

    def interrupted(scen, sink=None, progress=None, **kw):
        def sink_then_stop(rows):
            sink(rows)
            raise KeyboardInterrupt
        return real(scen, sink=sink_then_stop, progress=progress, chunk=64, **kw)

    monkeypatch.setattr(dynamics, "propagate", interrupted)
    status, _, err = _run(["run", "tianqin-kepler", "--duration", "1d", "-o", str(out_file), "-q"], capsys)
    assert status == 130 and "interrupted" in err
    assert _no_files(tmp_path) == ["run.h5"] and out_file.read_bytes() == b"previous"


def test_info(capsys):
    status, out, _ = _run(["info"], capsys)
    assert status == 0
    for needle in ("tqdyn", "numba", "tianqin-kepler", "earth_monopole", "RK8(7)13M", "corrected"):
        assert needle in out


def test_bench_short(capsys):
    """The benchmark command runs (short span; the numbers of the full spans are in docs/data/bench.json).  The
    kernels model is left out here (tests/test_numbers_records.py and `tqdyn bench --model kernels`)."""
    models = [a for m in ("kepler", "full", "coupled", "lisa", "lisa-coupled") for a in ("--model", m)]
    status, out, err = _run(["bench", *models, "--duration", "1h", "--no-heyoka"], capsys)
    assert status == 0, err
    assert "tqdyn dd" in out and "tqdyn float64" in out and "dd / float64" in out


def test_forces_budget_orders(tmp_path, capsys, record_number):
    """`tqdyn forces` on the full model over 10 days (every 600 s): every term present, with the known orders at
    r ~ 1e8 m (first principles: GM/r^2 = 4.0e-2; lunar tidal 2 GM_m r/d^3 ~ 1e-5; solar ~ 2 GM_s r/AU^3 ~ 6e-6;
    J2: 1.5 J2 GM R^2/r^4 ~ 5e-7; Schwarzschild 3 GM^2/(c^2 r^3) = 5.3e-12 ...), RMS <= max, and the plot.  The
    table is docs/force-model.md's budget (recorded)."""
    png = tmp_path / "budget.png"
    status, out, err = _run(["forces", "--duration", "10d", "--every", "600", "--plot", str(png)], capsys)
    assert status == 0, err
    rows = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[1][0].isdigit():
            rows[parts[0]] = (float(parts[1]), float(parts[2]))
    print(f"\nforce budget, 10 days: {rows}")
    expected = {  # max |a| [m/s^2]: (low, high), factor-3 brackets around the first-principles orders
        "earth_monopole": (3.9e-2, 4.1e-2), "third_body:moon": (3e-6, 3e-5), "third_body:sun": (2e-6, 2e-5),
        "earth_field": (2e-7, 1e-6), "relativity": (3e-12, 5e-11), "solid_tides": (1e-12, 3e-11),
        "ocean_tides": (1e-13, 1e-11), "moon_field": (3e-14, 3e-12), "solid_pole_tide": (3e-14, 3e-12),
        "ocean_pole_tide": (3e-15, 3e-13), "sun_j2": (1e-18, 1e-15), "earth_field_indirect": (3e-12, 5e-11),
        "atmospheric_tides": (1e-14, 2e-13),
    }
    for name, (low, high) in expected.items():
        assert low <= rows[name][0] <= high, (name, rows[name])
    assert set(expected) <= set(rows), sorted(set(expected) - set(rows))
    assert {"third_body:venus", "third_body:jupiter", "third_body:neptune"} <= set(rows)
    for name, (mx, rms) in rows.items():
        assert 0 < rms <= mx, name
    record_number("forces.budget_tianqin_10d", rows, "m/s^2 (max, RMS)")
    assert "NOT modelled" not in out
    assert png.exists() and png.stat().st_size > 10_000


def test_data_limits_are_bad_input(tmp_path, capsys):
    """A date outside the lunar kernel / ephemeris span, a missing ephemeris
    file: exit 2 with a line naming the limit, before any output."""
    status, _, err = _run(["run", "--set", "scenario.epoch_utc=2052-06-01T00:00:00", "-o", str(tmp_path / "x.h5")],
                          capsys)
    assert status == 2 and "span" in err and len(err.strip().splitlines()) == 1
    status, _, err = _run(["run", "--set", "forces.ephemeris=/nope/de440.bsp", "-o", str(tmp_path / "x.h5")], capsys)
    assert status == 2 and "/nope/de440.bsp" in err
    assert _no_files(tmp_path) == []


@pytest.mark.parametrize("extra", [[], ["--set", "constellation.free_tms=true"]], ids=["coupled", "free-tms"])
def test_checkpoint_resume_bit_identical(tmp_path, capsys, monkeypatch, extra):
    """Ctrl-C after a checkpoint: exit 130, no output file, a checkpoint;
    `--resume` with the same arguments finishes to a file identical bit for
    bit to the uninterrupted run (full force model and coupled attitude /
    control, 1 day; with free TMs the checkpoint carries the TM states)."""
    args = ["run", "tianqin", "--duration", "1d", "--checkpoint-every", "500", "-q", *extra]
    ref = tmp_path / "ref.h5"
    status, _, err = _run(args + ["-o", str(ref)], capsys)
    assert status == 0, err
    assert not (tmp_path / "ref.h5.checkpoint").exists()
    if extra:
        # the free TMs stay at their EH centres (full model, global pointing, 1 day): measured 2.4e-16 m, bounds
        # ~5x either side (tests/test_coupled.py::test_free_tms_ten_days_full_model, slow: 2.0e-15 m in 10 days)
        off = np.linalg.norm(io.read_trajectory(ref)["tm/housing_offset"], axis=-1).max()
        assert 5e-17 < off < 1e-15, off

    out = tmp_path / "run.h5"
    # Ctrl-C after the third chunk of rows, i.e. after the checkpoints at steps 500 and 1000
    status, _, err = run_cli_interrupted(args + ["-o", str(out)], capsys, monkeypatch)
    assert status == 130 and "--resume" in err
    assert not out.exists() and (tmp_path / "run.h5.checkpoint").exists()
    status, _, err = _run(args + ["-o", str(out)], capsys)  # without --resume: refused, nothing lost
    assert status == 2 and "--resume" in err
    status, _, err = _run(args + ["-o", str(out), "--resume"], capsys)
    assert status == 0, err
    assert not (tmp_path / "run.h5.checkpoint").exists()
    a, b = io.read_trajectory(ref), io.read_trajectory(out)
    assert a.fields == b.fields
    for f in a.fields:
        if io.FIELDS[f].kind == "dd":
            for x, y in zip(a.dd(f), b.dd(f)):
                np.testing.assert_array_equal(x, y)
        else:
            np.testing.assert_array_equal(a[f], b[f])
    assert sorted(os.listdir(tmp_path)) == ["ref.h5", "run.h5"]  # no partial or temporary file left


def test_resume_without_checkpoint_is_bad_input(tmp_path, capsys):
    status, _, err = _run(["run", "--duration", "1h", "-o", str(tmp_path / "x.h5"), "--resume"], capsys)
    assert status == 2 and "no checkpoint" in err
