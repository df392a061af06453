"""Reliability of `tqdyn run` and of the trajectory files (issue 14, items 1, 2, 3, 5, 8).

The faults are made by the tests themselves: a file-size limit
(RLIMIT_FSIZE, i.e. `ulimit -f`, with SIGXFSZ ignored) in a child process,
SIGTERM / SIGHUP sent to a child `tqdyn run`, truncated and corrupted
checkpoints and SPK files, and bytes flipped inside a trajectory dataset's
chunk.  Each case checks the promise of docs/reliability.md: the exit
status, exactly one `tqdyn: error:` line on stderr and no traceback, no
file at the output path, and that the checkpoint still continues with
`--resume` to the same trajectory as an uninterrupted run.
"""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from tqdyn.astro.ephemeris import default_ephemeris_path
from tqdyn.formats import trajectory as io
from cli_support import run_cli as _run
from cli_support import run_cli_interrupted

SRC = str(Path(__file__).resolve().parents[1] / "src")
KEPLER = ["run", "tianqin-kepler", "-q"]


def _child(args, limit: int | None = None, **kw) -> subprocess.Popen:
    """`tqdyn ARGS` in a child process (this tree's sources), optionally
    under a file-size limit of ``limit`` bytes (SIGXFSZ ignored, so writes
    fail with EFBIG as on a full disk)."""
    def pre():
        if limit is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    env = dict(os.environ, PYTHONPATH=SRC)
    return subprocess.Popen([sys.executable, "-c", "from tqdyn.cli import main; main()", *args],
                            preexec_fn=pre, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def _finish(p: subprocess.Popen, timeout=300):
    out, err = p.communicate(timeout=timeout)
    return p.returncode, out, err


@pytest.fixture(scope="module", autouse=True)
def _warm_jit_cache(tmp_path_factory):
    """Compile (and cache) the kernels once without a limit: a size-limited
    child must fail on the trajectory, not on numba's cache files."""
    out = tmp_path_factory.mktemp("warm") / "w.h5"
    status, _, err = _finish(_child(KEPLER + ["--duration", "1h", "--checkpoint-every", "10", "-o", str(out)]))
    assert status == 0, err


def _here(args) -> tuple[int, str]:
    """`tqdyn ARGS` in this process (where the test is not about the process): (exit status, stderr)."""
    import contextlib
    import io as text_io

    from tqdyn import cli

    err = text_io.StringIO()
    with contextlib.redirect_stdout(text_io.StringIO()), contextlib.redirect_stderr(err):
        try:
            status = cli.main(list(args))
        except SystemExit as exc:
            status = exc.code
    return status, err.getvalue()


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    """uninterrupted(args, path): the file of an uninterrupted `tqdyn ARGS` run (in this process, once per
    module for each ``args``: the tests that interrupt the same run compare with one reference) copied to
    ``path``."""
    done: dict = {}

    def copy_to(args, path: Path):
        key = tuple(args)
        if key not in done:
            ref = tmp_path_factory.mktemp("reference") / "ref.h5"
            status, err = _here([*args, "-o", str(ref)])
            assert status == 0, err
            done[key] = ref
        shutil.copyfile(done[key], path)

    return copy_to


def _one_error_line(err: str) -> str:
    """The only `tqdyn: error:` line of stderr (besides the banner / warnings); no traceback."""
    assert "Traceback" not in err, err
    errors = [ln for ln in err.splitlines() if ln.startswith("tqdyn: error:")]
    assert len(errors) == 1, err
    return errors[0]


def _listing(d) -> list[str]:
    return sorted(os.listdir(d))


def _same_data(a_path, b_path):
    a, b = io.read_trajectory(a_path), io.read_trajectory(b_path)
    assert a.fields == b.fields and a.n_rows == b.n_rows
    for f in a.fields:
        for x, y in zip(a._data[f], b._data[f]):
            np.testing.assert_array_equal(x, y)


# ---------------------------------------------------------------------------
# 1. full disk / file-size limit
# ---------------------------------------------------------------------------


def test_file_size_limit_without_checkpoint(tmp_path):
    """The first block of rows does not fit: exit 3, one line naming the
    file and the cause, no output and no temporary file; an existing file
    at the output path is untouched."""
    out = tmp_path / "out.h5"
    out.write_bytes(b"previous result")
    status, _, err = _finish(_child(KEPLER + ["--duration", "1d", "-o", str(out)], limit=200_000))
    line = _one_error_line(err)
    assert status == 3, err
    assert "File too large" in line and str(out) in line and "no output file written" in line
    assert _listing(tmp_path) == ["out.h5"] and out.read_bytes() == b"previous result"


def test_file_size_limit_checkpoint_resumes(tmp_path, uninterrupted):
    """The limit is hit after a checkpoint: exit 3, the checkpoint and its
    partial trajectory are kept, a `--resume` under the same limit fails the
    same way, and once the limit is lifted `--resume` finishes to the same
    data as an uninterrupted run."""
    args = KEPLER + ["--duration", "6d", "--checkpoint-every", "1000"]
    ref, out = tmp_path / "ref.h5", tmp_path / "out.h5"
    status, _, err = _finish(_child(args + ["-o", str(out)], limit=2_500_000))
    line = _one_error_line(err)
    assert status == 3 and "--resume" in line and "out.h5.checkpoint" in line, err
    left = _listing(tmp_path)
    assert "out.h5" not in left and "out.h5.checkpoint" in left
    assert len([n for n in left if n.startswith(".out.h5.") and n.endswith(".tmp")]) == 1
    status, _, err = _finish(_child(args + ["-o", str(out), "--resume"], limit=2_500_000))
    assert status == 3 and "--resume" in _one_error_line(err)
    status, err = _here(args + ["-o", str(out), "--resume"])  # the limit lifted
    assert status == 0, err
    uninterrupted(args, ref)
    _same_data(ref, out)
    assert _listing(tmp_path) == ["out.h5", "ref.h5"]


@pytest.mark.skipif(os.environ.get("TQDYN_TEST_TMPFS") != "1",
                    reason="mounts a small tmpfs (root); set TQDYN_TEST_TMPFS=1")
def test_full_disk_tmpfs_checkpoint_resumes(tmp_path):
    """A real full file system (ENOSPC): a 2.6 MB tmpfs, enlarged after the
    failure ("free space"), then `--resume`."""
    small = tmp_path / "small"
    small.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2600k", "tmpfs", str(small)], check=True)
    try:
        args = KEPLER + ["--duration", "6d", "--checkpoint-every", "1000"]
        ref, out = tmp_path / "ref.h5", small / "out.h5"
        status, _, err = _finish(_child(args + ["-o", str(ref)]))
        assert status == 0, err
        status, _, err = _finish(_child(args + ["-o", str(out)]))
        line = _one_error_line(err)
        assert status == 3 and "No space left on device" in line and "--resume" in line, err
        status, _, err = _finish(_child(KEPLER + ["--duration", "6d", "--checkpoint-every", "0",
                                                  "-o", str(small / "other.h5")]))
        assert status == 3 and "no output file written" in _one_error_line(err), err
        assert "out.h5" not in _listing(small) and "out.h5.checkpoint" in _listing(small)
        subprocess.run(["mount", "-o", "remount,size=20m", str(small)], check=True)
        status, _, err = _finish(_child(args + ["-o", str(out), "--resume"]))
        assert status == 0, err
        _same_data(ref, out)
        assert _listing(small) == ["out.h5"]
    finally:
        subprocess.run(["umount", str(small)], check=False)


def test_writer_failed_write_closes_safely(tmp_path):
    """A TrajectoryWriter whose write fails (EFBIG) raises OutputIOError and
    the process exits normally (HDF5 used to crash on closing such a file)."""
    code = f"""
import numpy as np
from tqdyn.formats import trajectory as io
attrs = dict(scenario="x", epoch_utc="2004-06-06T00:00:00", precision="float64", step_s=1.0,
             integrator="dp87-fixed-x", pointing="none", control="off")
try:
    with io.TrajectoryWriter({str(tmp_path / 'w.h5')!r}, attrs, ["t", "sat/r"], n_sat=3, expected_rows=100000) as w:
        for i in range(10):
            w.append({{"t": (np.arange(10000.) + i, np.zeros(10000)), "sat/r": (np.ones((10000, 3, 3)), np.zeros((10000, 3, 3)))}})
except io.OutputIOError as exc:
    print("OutputIOError", exc)
"""
    def pre():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (300_000, 300_000))

    p = subprocess.run([sys.executable, "-c", code], preexec_fn=pre, env=dict(os.environ, PYTHONPATH=SRC),
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("OutputIOError") and "File too large" in p.stdout
    assert _listing(tmp_path) == []


# ---------------------------------------------------------------------------
# 2. SIGTERM and SIGHUP
# ---------------------------------------------------------------------------


def _wait_for(path: Path, p: subprocess.Popen, timeout=120):
    t0 = time.monotonic()
    while not path.exists():
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < timeout, "no checkpoint appeared"
        time.sleep(0.05)


def _resume_matches_uninterrupted(tmp_path, args, out, ref, uninterrupted):
    """`--resume` of the interrupted run finishes; its data equal an uninterrupted run's; nothing else left.
    Neither is about the process: both run in this one (the reference once per ``args``)."""
    code, err = _here(args + ["-o", str(out), "--resume"])
    assert code == 0, err
    uninterrupted(args, ref)
    _same_data(ref, out)
    assert _listing(tmp_path) == ["out.h5", "ref.h5"]


@pytest.mark.parametrize("sig, status", [(signal.SIGTERM, 143), (signal.SIGHUP, 129)], ids=["SIGTERM", "SIGHUP"])
def test_signal_keeps_checkpoint_and_resumes(tmp_path, uninterrupted, sig, status):
    """SIGTERM / SIGHUP after a checkpoint: like Ctrl-C (checkpoint and its
    partial file kept, no output file), exit 128 + signal, one line;
    `--resume` finishes to the data of an uninterrupted run."""
    args = KEPLER + ["--duration", "12d", "--checkpoint-every", "500"]
    ref, out = tmp_path / "ref.h5", tmp_path / "out.h5"
    p = _child(args + ["-o", str(out)])
    _wait_for(tmp_path / "out.h5.checkpoint", p)
    p.send_signal(sig)
    code, _, err = _finish(p)
    line = _one_error_line(err)
    assert code == status, err
    assert signal.Signals(sig).name in line and "--resume" in line
    left = _listing(tmp_path)
    assert "out.h5" not in left and "out.h5.checkpoint" in left
    assert len([n for n in left if n.endswith(".tmp")]) == 1  # the partial trajectory, as after Ctrl-C
    _resume_matches_uninterrupted(tmp_path, args, out, ref, uninterrupted)


@pytest.mark.parametrize("options", [
    ["--duration", "12d", "--checkpoint-every", "500"],
    # --checkpoint-interval alone: a checkpoint at the first chunk boundary (4096 steps) after the wall-clock
    # interval; where it falls does not change the steps
    ["--duration", "40d", "--checkpoint-every", "0", "--checkpoint-interval", "0.001"],
], ids=["every-500-steps", "wall-clock-interval"])
def test_kill_9_after_a_checkpoint_resumes(tmp_path, uninterrupted, options):
    """kill -9 (no handler can run): the last checkpoint and its partial file
    are what is left, nothing at the output path; `--resume` finishes to the
    data of an uninterrupted run."""
    args = KEPLER + options
    ref, out = tmp_path / "ref.h5", tmp_path / "out.h5"
    p = _child(args + ["-o", str(out)])
    _wait_for(tmp_path / "out.h5.checkpoint", p)
    p.send_signal(signal.SIGKILL)
    code, _, _ = _finish(p)
    assert code == -signal.SIGKILL
    left = _listing(tmp_path)
    assert "out.h5" not in left and "out.h5.checkpoint" in left
    _resume_matches_uninterrupted(tmp_path, args, out, ref, uninterrupted)


def test_sigterm_without_checkpoint_leaves_nothing(tmp_path):
    out = tmp_path / "out.h5"
    p = _child(KEPLER + ["--duration", "200d", "--checkpoint-every", "0", "-o", str(out)])
    t0 = time.monotonic()
    while not any(n.endswith(".tmp") for n in os.listdir(tmp_path)):  # the writer has started
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < 120
        time.sleep(0.05)
    p.send_signal(signal.SIGTERM)
    code, _, err = _finish(p)
    line = _one_error_line(err)
    assert code == 143 and "SIGTERM" in line and "no output file written" in line, err
    assert _listing(tmp_path) == []


# ---------------------------------------------------------------------------
# 3 + 5. damaged checkpoints, truncated SPK: one line, before the banner
# ---------------------------------------------------------------------------


@pytest.fixture
def interrupted_run(tmp_path, capsys, monkeypatch):
    """An interrupted run (Ctrl-C after its checkpoints): (args, output path, checkpoint path)."""
    args = KEPLER + ["--duration", "1d", "--checkpoint-every", "200"]
    out = tmp_path / "run.h5"
    status, _, err = run_cli_interrupted(args + ["-o", str(out)], capsys, monkeypatch)
    assert status == 130, err
    ckpt = tmp_path / "run.h5.checkpoint"
    assert ckpt.exists()
    return args, out, ckpt


def _damage(ckpt: Path, how: str):
    raw = ckpt.read_bytes()
    if how == "truncated":
        ckpt.write_bytes(raw[: len(raw) // 2])
    elif how == "garbage":
        ckpt.write_bytes(b"\x00junk" * 100)
    elif how == "object":  # what numpy would only load "unsafely"
        with open(ckpt, "wb") as fh:
            np.savez(fh, scenario=np.array([{"a": 1}], dtype=object), precision=np.array("dd"))
    elif how == "flipped":
        b = bytearray(raw)
        for i in range(40, 60):
            b[i] ^= 0xFF
        ckpt.write_bytes(bytes(b))


@pytest.mark.parametrize("how", ["truncated", "garbage", "object", "flipped"])
def test_damaged_checkpoint_one_line(interrupted_run, capsys, how):
    args, out, ckpt = interrupted_run
    _damage(ckpt, how)
    status, _, err = _run(args + ["-o", str(out), "--resume"], capsys)
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1, err  # no banner before it
    assert err.startswith("tqdyn: error:") and str(ckpt) in err and "remove it" in err
    assert "unsafely" not in err and "allow_pickle" not in err


def test_resume_errors_before_the_banner(interrupted_run, capsys, tmp_path):
    args, out, ckpt = interrupted_run
    # another scenario
    status, _, err = _run(args + ["-o", str(out), "--resume", "--step", "25"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "different scenario" in err
    # a checkpoint and no --resume
    status, _, err = _run(args + ["-o", str(out)], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "--resume" in err
    # the partial trajectory is damaged
    partial = [tmp_path / n for n in os.listdir(tmp_path) if n.endswith(".tmp")]
    assert len(partial) == 1
    saved = partial[0].read_bytes()
    partial[0].write_bytes(saved[:1000])
    status, _, err = _run(args + ["-o", str(out), "--resume"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "cannot be read" in err, err
    partial[0].write_bytes(saved)
    # the partial trajectory is gone
    for n in os.listdir(tmp_path):
        if n.endswith(".tmp"):
            os.unlink(tmp_path / n)
    status, _, err = _run(args + ["-o", str(out), "--resume"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "partial trajectory" in err
    assert "missing" in err and "remove the checkpoint" in err
    # no checkpoint
    ckpt.unlink()
    status, _, err = _run(args + ["-o", str(out), "--resume"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "no checkpoint" in err


@pytest.mark.parametrize("size", [100, 5000, 5_000_000])
def test_truncated_spk_one_line(tmp_path, capsys, size):
    bsp = tmp_path / "trunc.bsp"
    with open(default_ephemeris_path(), "rb") as fh:
        bsp.write_bytes(fh.read(size))
    status, _, err = _run(["run", "--duration", "1h", "-q", "--set", f"forces.ephemeris={bsp}",
                           "-o", str(tmp_path / "x.h5")], capsys)
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1 and str(bsp) in err, err
    assert _listing(tmp_path) == ["trunc.bsp"]


def test_checkpoint_holds_plain_arrays(interrupted_run):
    _, _, ckpt = interrupted_run
    with np.load(ckpt, allow_pickle=False) as data:
        for key in data.files:
            assert data[key].dtype.kind in "Uifb", (key, data[key].dtype)


# ---------------------------------------------------------------------------
# 8. integrity: Fletcher-32 checksums
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("small")
    path = d / "k.h5"
    p = _child(KEPLER + ["--duration", "2h", "-o", str(path)])
    status, _, err = _finish(p)
    assert status == 0, err
    return path


def _flip_in_chunk(path: Path, dataset: str):
    with h5py.File(path, "r") as h5:
        ds = h5[dataset]
        info = ds.id.get_chunk_info(0)
        offset, size = info.byte_offset, info.size
    with open(path, "r+b") as fh:
        fh.seek(offset + size // 2)
        b = fh.read(4)
        fh.seek(offset + size // 2)
        fh.write(bytes(x ^ 0x5A for x in b))


def test_datasets_carry_fletcher32(small_run):
    with h5py.File(small_run, "r") as h5:
        names = []
        h5.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for n in names:
            assert h5[n].fletcher32, n


def test_old_file_without_checksums_reads():
    traj = io.read_trajectory(Path(__file__).parent / "fixtures" / "trajectory-v1-tianqin.h5")
    assert traj.n_rows > 0


@pytest.mark.parametrize("dataset", ["sat/r/hi", "t/lo"])
def test_corrupted_dataset_is_refused(small_run, tmp_path, capsys, dataset):
    bad = tmp_path / "bad.h5"
    shutil.copy(small_run, bad)
    _flip_in_chunk(bad, dataset)
    with pytest.raises(io.TrajectoryFormatError, match="checksum"):
        io.read_trajectory(bad)
    status, _, err = _run(["export", str(bad), str(tmp_path / "x.oem"), "--format", "oem"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and str(bad) in err and "checksum" in err, err
    status, _, err = _run(["report", str(bad), "-o", str(tmp_path / "rep"), "-q"], capsys)
    assert status == 2 and len(err.strip().splitlines()) == 1 and "checksum" in err, err
    assert _listing(tmp_path) == ["bad.h5"]
