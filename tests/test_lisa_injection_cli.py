"""``tqdyn export CL.h5 --format lisa-injection OUT.h5 --run RUN.h5`` on the command line: what it writes
(read back by LISA Instrument's own glitch-file reader) and its refusals (one line on stderr, exit status 2,
nothing at the output path).  Runs of 2 h at 600 s and a 300 s closed-loop series at 4 Hz: a few seconds."""

from __future__ import annotations

import numpy as np
import pytest

from cli_support import run_cli


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    import tqdyn
    from tqdyn import cli

    d = tmp_path_factory.mktemp("inj-cli")
    over = {"run.duration": "2h", "integrator.step": 600}
    tqdyn.run("tianqin", over, output=str(d / "tq.h5"))
    tqdyn.run("tianqin", {**over, "run.duration": "3h"}, output=str(d / "other.h5"))
    try:
        cli.main(["closed-loop", str(d / "tq.h5"), "-o", str(d / "cl.h5"), "--duration", "300", "--fs", "4",
                  "--set", "closed_loop.n_freq=8", "-q"])
    except SystemExit as exc:
        assert exc.code in (0, None)
    return d


def test_the_file_is_a_lisa_instrument_glitch_file(files, capsys, tmp_path):
    """LISA Instrument's reader (glitch_file) opens it; the 12 readout datasets (carrier and sideband of the six
    links) are finite, equal, of the file's size, in Hz of the expected order (-(nu0/c) ds/dt with s ~ 1e-11 m
    at ~0.1 Hz: ~1e-5 Hz); the random coefficients of two seeds give different files."""
    gf = pytest.importorskip("lisainstrument.glitches.glitch_file")
    from lisainstrument.orbiting.constellation_enums import MosaID

    out = tmp_path / "ttl.h5"
    status, so, err = run_cli(["export", str(files / "cl.h5"), "--format", "lisa-injection", str(out), "--run",
                               str(files / "tq.h5"), "--coefficients", "random", "--seed", "1"], capsys)
    assert status in (0, None), err
    assert "LISA Instrument injection file" in so
    f = gf.glitch_file(out)
    assert str(f.format_version) == "2.0.0"
    for mosa in MosaID:
        assert f.has_readout_sci_carrier(mosa) and f.has_readout_sci_usbs(mosa) and not f.has_test_mass(mosa)
        a = f.load_segment_readout_sci_carrier(f.start_time, f.end_time, mosa, 0).values
        b = f.load_segment_readout_sci_usbs(f.start_time, f.end_time, mosa, 0).values
        assert np.array_equal(a, b) and np.all(np.isfinite(a)) and 1e-8 < np.std(a) < 1e-3
    out2 = tmp_path / "ttl2.h5"
    run_cli(["export", str(files / "cl.h5"), "--format", "lisa-injection", str(out2), "--run", str(files / "tq.h5"),
             "--coefficients", "random", "--seed", "2"], capsys)
    g = gf.glitch_file(out2)
    assert not np.array_equal(g.load_segment_readout_sci_carrier(g.start_time, g.end_time, MosaID("12"), 0).values,
                              f.load_segment_readout_sci_carrier(f.start_time, f.end_time, MosaID("12"), 0).values)


def test_tm_injection_is_the_integral_of_the_tm_acceleration(files, capsys, tmp_path):
    """--tm-acceleration: d tm_ij/dt (first differences over dt) equals the mean of consecutive samples of the
    closed-loop file's tm{l}_acceleration of the TM on MOSA ij (MOSA l = 1 of spacecraft i faces k, l = 2 faces
    j, (i, j, k) even: 13, 12 / 21, 23 / 32, 31), to < 1e-13 of its RMS (the trapezoidal rule exactly;
    measured ~2e-14); its mean is zero; without the flag there is no tm dataset."""
    import h5py

    from tqdyn.formats.closed_loop import read_closed_loop

    out = tmp_path / "tm.h5"
    status, _, err = run_cli(["export", str(files / "cl.h5"), "--format", "lisa-injection", str(out), "--run",
                              str(files / "tq.h5"), "--tm-acceleration"], capsys)
    assert status in (0, None), err
    ts = read_closed_loop(files / "cl.h5").timeseries(["tm1_acceleration", "tm2_acceleration"])
    t = ts["time"].values
    where = {"13": (0, "tm1"), "12": (0, "tm2"), "21": (1, "tm1"), "23": (1, "tm2"), "32": (2, "tm1"), "31": (2, "tm2")}
    with h5py.File(out) as f:
        dt, t0 = f.attrs["dt"], f.attrs["t0"]
        i0 = int(np.argmin(np.abs(t - t0)))
        for m, (i, tm) in where.items():
            v = f[f"tm_{m}"][:]
            a = ts["values"].sel(output=f"{tm}_acceleration").values[i0:i0 + v.size, i]
            am = 0.5 * (a[1:] + a[:-1])
            assert np.max(np.abs(np.diff(v) / dt - am)) < 1e-13 * np.std(am)
            assert abs(v.mean()) < 1e-12 * np.std(v)
    run_cli(["export", str(files / "cl.h5"), "--format", "lisa-injection", str(tmp_path / "no.h5"), "--run",
             str(files / "tq.h5")], capsys)
    with h5py.File(tmp_path / "no.h5") as f:
        assert not [k for k in f if k.startswith("tm_")]


@pytest.mark.parametrize("case, pattern", [
    ("other-run", "closed loop of another run"),
    ("trajectory-as-cl", "expected format 'tqdyn-closed-loop'"),
    ("no-run", "--run RUN.h5 is required"),
    ("nan", "local_eta['12'] = nan: must be a finite number"),
    ("bad-spec", "allowed: worst-case, random, or a .toml or .json file"),
    ("step-with-injection", "--step: does not apply to --format lisa-injection"),
    ("run-with-lisa", "--run: does not apply to --format lisa"),
    ("frame-with-injection", "--frame: does not apply to --format lisa-injection"),
    ("tm-with-lisa", "--tm-acceleration: does not apply to --format lisa"),
])
def test_refusals(files, capsys, tmp_path, case, pattern):
    """Each refusal: exit status 2, one line on stderr naming the problem (the other run: both files),
    no file at the output path (an existing one unchanged)."""
    out = tmp_path / "out.h5"
    out.write_bytes(b"keep")
    cl, run = str(files / "cl.h5"), str(files / "tq.h5")
    nan_file = tmp_path / "nan.toml"
    nan_file.write_text("\n".join(f"[{f}]\n" + "\n".join(f'"{m}" = {"nan" if f == "local_eta" else 1e-3}'
                                                            for m in ("12", "23", "31", "13", "32", "21"))
                                  for f in ("local_phi", "local_eta", "distant_phi", "distant_eta")))
    argv = {
        "other-run": [cl, "--format", "lisa-injection", str(out), "--run", str(files / "other.h5")],
        "trajectory-as-cl": [run, "--format", "lisa-injection", str(out), "--run", run],
        "no-run": [cl, "--format", "lisa-injection", str(out)],
        "nan": [cl, "--format", "lisa-injection", str(out), "--run", run, "--coefficients", str(nan_file)],
        "bad-spec": [cl, "--format", "lisa-injection", str(out), "--run", run, "--coefficients", "best-case"],
        "step-with-injection": [cl, "--format", "lisa-injection", str(out), "--run", run, "--step", "10"],
        "run-with-lisa": [run, "--format", "lisa", str(out), "--run", run],
        "frame-with-injection": [cl, "--format", "lisa-injection", str(out), "--run", run, "--frame", "gcrs"],
        "tm-with-lisa": [run, "--format", "lisa", str(out), "--tm-acceleration"],
    }[case]
    status, _, err = run_cli(["export", *argv], capsys)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and pattern in lines[0], err
    if case == "other-run":
        assert "cl.h5" in lines[0] and "other.h5" in lines[0]
    assert out.read_bytes() == b"keep"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
