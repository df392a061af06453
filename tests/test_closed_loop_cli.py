"""``tqdyn closed-loop RUN.h5 --output CL.h5`` (tqdyn.cli.closed_loop; docs/commands.md).

References: the in-memory entry points (tqdyn.analysis.closed_loop) for what the file holds; the
command-line contract (one line on stderr, exit status 2 for bad input, 3 for a failed write, 130 for
Ctrl-C; nothing at the output path then).  The runs are 2 h at 600 s (a few seconds each); the budget
of the failure tests is computed once (monkeypatched in) to keep them fast.
"""

from __future__ import annotations

import functools
import os

import numpy as np
import pytest

from cli_support import run_cli

SMALL = ["--set", "closed_loop.n_freq=8", "--duration", "600", "--fs", "1"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    import tqdyn

    d = tmp_path_factory.mktemp("cl-runs")
    over = {"run.duration": "2h", "integrator.step": 600}
    tqdyn.run("tianqin", over, output=str(d / "tq.h5"))
    tqdyn.run("tianqin-gravity", over, output=str(d / "gravity.h5"))
    tqdyn.run("tianqin-kepler", over, output=str(d / "kepler.h5"))
    return d


@pytest.fixture(scope="module")
def made(runs, tmp_path_factory):
    """One closed-loop file made by the command (and its output)."""
    import contextlib
    import io

    from tqdyn import cli

    out = tmp_path_factory.mktemp("cl-out") / "cl.h5"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = cli.main(["closed-loop", str(runs / "tq.h5"), "--output", str(out), "--seed", "5", "--per-source",
                               *SMALL])
        except SystemExit as exc:
            status = exc.code
    return status, out, err.getvalue()


def test_the_command_writes_what_the_entry_points_compute(runs, made):
    """The file's budget and series equal closed_loop_budget / closed_loop_timeseries of the same run,
    configuration, duration, rate and seed, bit for bit; the source run is identified."""
    import hashlib

    import tqdyn
    from tqdyn.analysis.closed_loop import closed_loop_budget, closed_loop_timeseries
    from tqdyn.closedloop.model import closed_loop_model
    from tqdyn.formats.closed_loop import read_closed_loop
    from tqdyn.scenario import loads_scenario

    status, out, err = made
    assert status in (0, None), err
    f = read_closed_loop(out)
    traj = tqdyn.open_trajectory(runs / "tq.h5")
    cfg = loads_scenario(traj.scenario_toml, ["closed_loop.n_freq=8"]).closed_loop
    model = closed_loop_model(traj, cfg)
    ts = closed_loop_timeseries(model, duration_s=600.0, fs=1.0, seed=5)
    assert np.array_equal(f.timeseries()["values"].values, ts["values"].values)
    b = closed_loop_budget(model)
    for name in ("asd", "total", "gain_margin", "gain_margin_lower", "gain_margin_upper", "phase_margin", "frequency"):
        assert np.array_equal(f.budget[name].values, b[name].values, equal_nan=True), name
    assert f.attrs["source_file"] == "tq.h5" and f.attrs["seed"] == 5 and f.attrs["fs"] == 1.0
    assert f.attrs["source_sha256"] == hashlib.sha256((runs / "tq.h5").read_bytes()).hexdigest()
    assert f.configuration["settings"]["n_freq"] == 8 and f.configuration["mission"] == "tianqin"
    assert set(f.configuration["controllers"]) == {"dragfree", "suspension", "attitude", "attitude_z", "mosa",
                                                   "tm_rotation"}


@pytest.mark.parametrize("args, pattern", [
    (["--set", "closed_loop.controllers.nonsense.gain=1"], "is not a loop"),
    (["--set", "closed_loop.noise.nonsense.level=1"], "is not a noise source"),
    (["--set", "closed_loop.noise.thruster_force.level=-1"], "negative ASD"),
    (["--set", "closed_loop.noise.thruster_force.level=inf"], "not a finite number"),
    (["--set", "closed_loop.controllers.suspension.zeros=[-6.2e-7]", "--set",
      "closed_loop.controllers.suspension.poles=[0,0,-6e-5]", "--set", "closed_loop.controllers.suspension.gain=1e-12"],
     r"closed_loop\.controllers\.suspension: the closed loop is unstable .*phase margin"),
    (["--duration", "-3d"], "--duration"), (["--duration", "nan"], "--duration"), (["--duration", "0"], "--duration"),
    (["--fs", "0"], "--fs"), (["--fs", "-4"], "--fs"), (["--seed", "-1"], "--seed"),
    (["--set", "run.duration=1d"], "not a closed-loop key"),
])
def test_bad_input_is_one_line_exit_2_and_nothing_written(runs, tmp_path, capsys, args, pattern):
    out = tmp_path / "cl.h5"
    status, stdout, err = run_cli(["closed-loop", str(runs / "tq.h5"), "--output", str(out), *args], capsys)
    assert status == 2 and err.count("\n") == 1 and err.startswith("tqdyn: error: "), err
    assert __import__("re").search(pattern, err), err
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("run, pattern", [("gravity.h5", "missing"), ("kepler.h5", "missing"),
                                          ("absent.h5", "does not exist"), ("text.h5", "not a readable HDF5")])
def test_runs_without_test_masses_and_unreadable_runs_are_refused(runs, tmp_path, capsys, run, pattern):
    """A pure-gravity run (no attitude, no control), a point-mass run (no test masses), a missing file
    and a file that is not HDF5: one line, exit 2, nothing written."""
    (runs / "text.h5").write_text("not a run")
    out = tmp_path / "cl.h5"
    status, _o, err = run_cli(["closed-loop", str(runs / run), "--output", str(out)], capsys)
    assert status == 2 and err.count("\n") == 1 and pattern in err, err
    assert os.listdir(tmp_path) == []


def test_output_may_not_be_the_run_and_an_existing_output_is_replaced_only_when_complete(runs, made, tmp_path,
                                                                                         capsys):
    """As tqdyn run: the output replaces an existing file on success (atomically), never the input."""
    status, _o, err = run_cli(["closed-loop", str(runs / "tq.h5"), "--output", str(runs / "tq.h5")], capsys)
    assert status == 2 and "is the input RUN.h5" in err and err.count("\n") == 1
    out = tmp_path / "cl.h5"
    out.write_bytes(b"old")
    status, stdout, err = run_cli(["closed-loop", str(runs / "tq.h5"), "-o", str(out), "--seed", "5", "--per-source",
                                   *SMALL], capsys)
    assert status in (0, None) and "output:" in stdout
    assert out.read_bytes() == made[1].read_bytes()          # the same bytes as the first file (deterministic)


@pytest.mark.parametrize("exc, code", [(KeyboardInterrupt(), 130), (OSError(28, "No space left on device"), 3)])
def test_interrupt_or_write_error_leaves_no_file(runs, made, tmp_path, capsys, monkeypatch, exc, code):
    """Ctrl-C or a disk-full error after the first block: one line, exit 130 / 3, no file at the output
    path and no temporary file; an existing output untouched."""
    from tqdyn.analysis import closed_loop as acl
    from tqdyn.formats.closed_loop import read_closed_loop
    from tqdyn.workflows import closed_loop as wf

    budget = read_closed_loop(made[1]).budget
    monkeypatch.setattr(acl, "closed_loop_budget", lambda model, **kw: budget)

    class Failing:
        def __init__(self, sink):
            self.sink, self.n = sink, 0

        def start(self, meta):
            self.sink.start(meta)

        def write(self, block):
            self.n += 1
            if self.n == 2:
                raise exc
            self.sink.write(block)

        def close(self):
            self.sink.close()

    monkeypatch.setattr(wf, "closed_loop_to_file",
                        functools.partial(wf.closed_loop_to_file, block_size=100, wrap=Failing))
    for existing in (False, True):
        out = tmp_path / "cl.h5"
        if existing:
            out.write_bytes(b"old")
        status, _o, err = run_cli(["closed-loop", str(runs / "tq.h5"), "-o", str(out), *SMALL], capsys)
        assert status == code and err.strip().splitlines()[-1].startswith("tqdyn: error: "), err
        assert "no output file written" in err
        assert (out.read_bytes() == b"old") if existing else not out.exists()
        assert os.listdir(tmp_path) == (["cl.h5"] if existing else [])


def test_the_progress_bars_follow_the_budget_then_the_samples():
    """tqdyn.cli.closed_loop._Bars: a bar over the segment x spacecraft loops, closed when the last loop
    is done; then a bar over the samples."""
    from tqdyn.cli.closed_loop import _Bars

    made = []

    class Bar:
        def __init__(self, total, unit, desc):
            self.total, self.unit, self.n, self.closed = total, unit, 0, False
            made.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True

    bars = _Bars(Bar, 6, 1000)
    for _ in range(6):
        bars.loops(1)
    bars.samples(400)
    bars.samples(600)
    bars.close()
    assert [(b.unit, b.total, b.n, b.closed) for b in made] == [("loop", 6, 6, True), ("sample", 1000, 1000, True)]
