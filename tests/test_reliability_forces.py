"""`tqdyn forces` under bad input: exit status 2, exactly one line
``tqdyn: error: <field>: <value> <problem>; allowed: <what>`` on stderr, no
traceback, no file created, an existing file at the ``--plot`` path untouched,
and every check made before the propagation starts (no banner).

Reference: the README's promise for bad input and issue 14 (items 3 and 5).
The faults are made by the tests themselves (bad option values, a missing
directory, a failing figure writer via monkeypatch).  All cases but two are
refused before any computation (milliseconds); the two that propagate use
short Kepler runs (a few seconds).
"""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest

from cli_support import run_cli

#: The content of a file that must survive a refused or failed ``--plot``.
KEEP = b"an existing figure the user cares about\n"


def _refused(argv, capsys, field):
    """Run ``tqdyn forces ARGV``; assert exit 2, one stderr line naming ``field``, an "allowed:" part, no banner,
    nothing on stdout; returns the line."""
    status, out, err = run_cli(["forces", *argv], capsys)
    lines = err.splitlines()
    assert status == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith(f"tqdyn: error: {field}: "), lines[0]
    assert "; allowed: " in lines[0], lines[0]
    assert "Traceback" not in err and "propagating" not in err
    assert out == ""
    return lines[0]


def _files(directory):
    return sorted(os.listdir(directory))


@pytest.mark.parametrize("every, problem", [
    ("nan", "is not finite"), ("NaN", "is not finite"), ("inf", "is not finite"), ("-inf", "is not finite"),
    ("snan", "is not finite"), ("0", "is not positive"), ("-600", "is not positive"),
    ("abc", "is not a number"), ("", "is not a number"), ("10min", "is not a number"),
    ("55", "is not a multiple of the step 50 s"), ("1e-400", "is not a multiple of the step"),
    ("1e400", "is longer than the duration"), ("90000", "is longer than the duration 86400 s"),
])
def test_every_bad_values(every, problem, tmp_path, capsys, monkeypatch):
    """--every must be a positive, finite multiple of the step at most the duration; an existing --plot file is
    left as it was."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "budget.png").write_bytes(KEEP)
    line = _refused(["tianqin-kepler", "--duration", "1d", "--every", every, "--plot", "budget.png"], capsys, "--every")
    assert problem in line
    assert _files(tmp_path) == ["budget.png"] and (tmp_path / "budget.png").read_bytes() == KEEP


def test_every_too_many_samples(tmp_path, capsys, monkeypatch):
    """A sampling that would hold more than MAX_SAMPLES states in memory is refused up front."""
    monkeypatch.chdir(tmp_path)
    # 4e10 s at 50 s steps is 8e8 steps (within run.max_steps), every 1000 s 4e7 samples
    line = _refused(["tianqin-kepler", "--duration", "4e10s", "--every", "1000"], capsys, "--every")
    assert "samples" in line and "at most 10000000" in line
    assert _files(tmp_path) == []


def test_duration_too_many_samples_at_default_every(tmp_path, capsys, monkeypatch):
    """The same with the default --every: the duration is named (a duration beyond run.max_steps is refused by
    the scenario first, naming run.duration: it used to fail in ERFA's taiutc)."""
    monkeypatch.chdir(tmp_path)
    line = _refused(["tianqin-kepler", "--duration", "4e10s"], capsys, "--duration")
    assert "default --every 600 s" in line
    line = _refused(["tianqin-kepler", "--duration", "1e12d"], capsys, "run.duration")
    assert "run.max_steps" in line


@pytest.mark.parametrize("name, problem", [
    ("budget.txt", "has an unsupported extension .txt"),
    ("budget.h5", "has an unsupported extension .h5"),
    ("budget", "has no file extension"),
])
def test_plot_unsupported_format(name, problem, tmp_path, capsys, monkeypatch):
    """--plot with a format matplotlib cannot write: refused before computing, with the allowed extensions (from
    matplotlib's FigureCanvasBase.get_supported_filetypes); an existing file of that name untouched."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / name).write_bytes(KEEP)
    line = _refused(["--duration", "1d", "--plot", name], capsys, "--plot")
    assert f"'{name}' {problem}" in line
    for ext in (".png", ".pdf", ".svg"):
        assert ext in line.split("allowed:")[1]
    assert _files(tmp_path) == [name] and (tmp_path / name).read_bytes() == KEEP


def test_plot_missing_directory(tmp_path, capsys, monkeypatch):
    """--plot into a directory that does not exist: refused before the computation (it used to run it first)."""
    monkeypatch.chdir(tmp_path)
    line = _refused(["--duration", "1d", "--plot", "missing_dir/x.png"], capsys, "--plot")
    assert "does not exist" in line
    assert _files(tmp_path) == []


def test_plot_parent_is_a_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "f").write_bytes(KEEP)
    line = _refused(["--duration", "1d", "--plot", "f/x.png"], capsys, "--plot")
    assert "not a directory" in line
    assert _files(tmp_path) == ["f"] and (tmp_path / "f").read_bytes() == KEEP


@pytest.mark.parametrize("which", ["dir", "dir/", "dir.png", ""])
def test_plot_path_is_a_directory(which, tmp_path, capsys, monkeypatch):
    """--plot naming a directory (with or without a figure extension, or empty = the working directory)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "dir").mkdir()
    (tmp_path / "dir.png").mkdir()
    line = _refused(["--duration", "1d", "--plot", which], capsys, "--plot")
    assert "is a directory" in line
    assert _files(tmp_path) == ["dir", "dir.png"] and _files(tmp_path / "dir") == []


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root writes into read-only directories")
def test_plot_unwritable_directory(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        line = _refused(["--duration", "1d", "--plot", "ro/x.png"], capsys, "--plot")
        assert "cannot be written" in line
        assert _files(ro) == []
    finally:
        ro.chmod(0o755)


@pytest.mark.parametrize("argv, field", [
    (["no-such-scenario"], "scenario"),
    (["--set", "nokeyvalue"], "override"),
    (["--set", "integrator.step=nan"], "integrator.step"),
    (["--duration", "xyz"], "run.duration"),
    (["--duration", "nan"], "run.duration"),
    (["--duration", "-1d"], "run.duration"),
])
def test_other_bad_options(argv, field, tmp_path, capsys, monkeypatch):
    """Scenario, --set and --duration errors: one line naming the field, nothing written (the --plot file kept)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "budget.png").write_bytes(KEEP)
    _refused([*argv, "--plot", "budget.png"], capsys, field)
    assert _files(tmp_path) == ["budget.png"] and (tmp_path / "budget.png").read_bytes() == KEEP


def test_heliocentric_default_every(tmp_path, capsys, monkeypatch):
    """lisa-kepler (central_body = "sun", step 6 h): the default --every is the smallest multiple of the step
    >= 600 s, so `tqdyn forces lisa-kepler` works; 600 s is refused in one line."""
    monkeypatch.chdir(tmp_path)
    status, out, err = run_cli(["forces", "lisa-kepler", "--duration", "10d", "--plot", "lisa.svg"], capsys)
    assert status == 0, err
    assert "sampling every 21600 s" in err and "41 samples" in out and "sun_monopole" in out
    assert _files(tmp_path) == ["lisa.svg"] and (tmp_path / "lisa.svg").read_bytes().lstrip().startswith(b"<?xml")
    line = _refused(["lisa-kepler", "--every", "600"], capsys, "--every")
    assert "multiple of the step 21600 s" in line


def test_plot_write_failure_is_atomic(tmp_path, capsys, monkeypatch):
    """A failure while the figure is written (a full disk, simulated: savefig writes part of the file and raises
    ENOSPC) leaves the existing file untouched and no temporary file; one line, exit 3 (a failed write,
    docs/reliability.md)."""
    import matplotlib.figure

    monkeypatch.chdir(tmp_path)
    (tmp_path / "budget.png").write_bytes(KEEP)

    def full_disk(self, fname, *args, **kwargs):
        with open(fname, "wb") as fh:
            fh.write(b"\x89PNG partial")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full_disk)
    status, out, err = run_cli(["forces", "tianqin-kepler", "--duration", "1h", "--plot", "budget.png"], capsys)
    lines = err.splitlines()
    assert status == 3
    assert lines[-1].startswith("tqdyn: error: --plot: cannot write the figure") and "budget.png" in lines[-1]
    assert "No space left" in lines[-1] and "nothing was written there" in lines[-1] and "Traceback" not in err
    assert _files(tmp_path) == ["budget.png"] and (tmp_path / "budget.png").read_bytes() == KEEP


def test_plot_force_budget_replaces_atomically(tmp_path):
    """The library call: a new figure replaces an existing file in one rename; no temporary file is left."""
    from tqdyn.analysis.budget import TermBudget
    from tqdyn.analysis.figures import plot_force_budget

    t = np.linspace(0.0, 86400.0, 5)
    budget = [TermBudget("earth", "", "", 1.0, 1.0, np.ones((5, 3)))]
    path = tmp_path / "b.pdf"
    path.write_bytes(KEEP)
    plot_force_budget(budget, t, path)
    assert path.read_bytes().startswith(b"%PDF") and _files(tmp_path) == ["b.pdf"]
    with pytest.raises(ValueError, match="unsupported extension"):
        plot_force_budget(budget, t, tmp_path / "b.txt")
    assert _files(tmp_path) == ["b.pdf"]
