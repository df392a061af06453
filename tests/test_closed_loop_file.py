"""The closed-loop file (tqdyn.formats.closed_loop; docs/closed-loop-file.md).

References: what tqdyn.analysis.closed_loop computes in memory for the same model (the file must hand
back the same float64 bits: it stores and reads, nothing else); h5py's own view of the datasets'
filters (Fletcher-32); the file system (nothing at the output path after a failure).
"""

from __future__ import annotations

import json
import os

import h5py
import numpy as np
import pytest

from tqdyn.formats.closed_loop import FORMAT, FORMAT_VERSION, ClosedLoopFormatError, ClosedLoopWriter, read_closed_loop

F = np.logspace(-4, 0, 8)


@pytest.fixture(scope="module")
def model_and_budget():
    import tqdyn
    from tqdyn.analysis.closed_loop import closed_loop_budget
    from tqdyn.closedloop.model import closed_loop_model

    traj = tqdyn.propagate("tianqin", {"run.duration": "2h", "integrator.step": 600})
    model = closed_loop_model(traj)
    return model, closed_loop_budget(model, f=F)


def _write(path, model, budget, duration=300.0, fs=2.0, seed=3, block_size=256, wrap=None):
    from tqdyn.analysis.closed_loop import closed_loop_timeseries
    from tqdyn.closedloop.loop import OUTPUTS

    attrs = {"mission": model.mission, "seed": seed, "fs": fs, "duration_s": duration,
             "n_samples": int(round(duration * fs)), "t0": model.t_span[0],
             "satellite_names": json.dumps(list(model.satellite_names)), "source_file": "run.h5"}
    with ClosedLoopWriter(path, attrs, units=OUTPUTS) as w:
        w.write_budget(budget)
        closed_loop_timeseries(model, duration_s=duration, fs=fs, seed=seed, block_size=block_size,
                               sink=w if wrap is None else wrap(w))
    return path


def test_round_trip_is_bit_equal_to_the_in_memory_results(tmp_path, model_and_budget):
    """What the reader returns equals closed_loop_budget / closed_loop_timeseries in memory, bit for
    bit (the file stores float64 as computed), with the same dims, coordinates and units."""
    from tqdyn.analysis.closed_loop import closed_loop_timeseries

    model, budget = model_and_budget
    path = _write(tmp_path / "cl.h5", model, budget)
    f = read_closed_loop(path)
    mem = closed_loop_timeseries(model, duration_s=300.0, fs=2.0, seed=3, block_size=256)   # the same blocks
    ts = f.timeseries()
    assert ts["values"].dims == mem["values"].dims
    assert np.array_equal(ts["values"].values, mem["values"].values)
    assert np.array_equal(ts["time"].values, mem["time"].values)
    for c in ("output", "unit", "frame", "sat_name"):
        assert list(ts[c].values) == list(mem[c].values)
    assert list(f.budget.data_vars) == list(budget.data_vars)
    for name in list(budget.data_vars) + list(budget.coords):
        assert f.budget[name].dims == budget[name].dims, name
        a, b = f.budget[name].values, budget[name].values
        assert (np.array_equal(a, b) if a.dtype.kind == "f" else list(a.ravel()) == list(b.ravel())), name
    assert f.budget.attrs == budget.attrs
    part = f.timeseries(outputs=["tm1_acceleration"], start=10, stop=20)
    assert np.array_equal(part["values"].values[:, :, 0], mem["values"].sel(output="tm1_acceleration").values[10:20])


def test_every_dataset_is_chunked_with_fletcher32(tmp_path, model_and_budget):
    path = _write(tmp_path / "cl.h5", *model_and_budget)
    seen = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            seen.append(name)
            assert obj.fletcher32 and obj.chunks is not None, name

    with h5py.File(path, "r") as h5:
        h5.visititems(visit)
        assert h5.attrs["format"] == FORMAT and h5.attrs["format_version"] == FORMAT_VERSION
        assert h5["timeseries/tm1_acceleration"].attrs["units"] == "m/s^2"
    assert "timeseries/t" in seen and "budget/asd" in seen and "budget/dominant" in seen


class _Failing:
    def __init__(self, sink, exc, after=2):
        self.sink, self.exc, self.after, self.n = sink, exc, after, 0

    def start(self, meta):
        self.sink.start(meta)

    def write(self, block):
        self.n += 1
        if self.n == self.after:
            raise self.exc
        self.sink.write(block)

    def close(self):
        self.sink.close()


@pytest.mark.parametrize("exc", [KeyboardInterrupt(), OSError(28, "No space left on device")])
def test_a_failed_or_interrupted_write_leaves_no_file(tmp_path, model_and_budget, exc):
    """Ctrl-C or a write error in the middle of the stream: no file at the output path, no temporary
    file left, an existing file there unchanged."""
    out = tmp_path / "cl.h5"
    with pytest.raises(type(exc)):
        _write(out, *model_and_budget, wrap=lambda w: _Failing(w, exc))
    assert not out.exists() and os.listdir(tmp_path) == []
    out.write_bytes(b"old")
    with pytest.raises(type(exc)):
        _write(out, *model_and_budget, wrap=lambda w: _Failing(w, exc))
    assert out.read_bytes() == b"old" and os.listdir(tmp_path) == ["cl.h5"]


def test_foreign_and_newer_files_are_refused_in_one_line(tmp_path, model_and_budget):
    import tqdyn

    run = tmp_path / "run.h5"
    tqdyn.run("tianqin-kepler", {"run.duration": "600", "integrator.step": 300}, output=str(run))
    text = tmp_path / "notes.h5"
    text.write_text("not hdf5")
    newer = _write(tmp_path / "cl.h5", *model_and_budget)
    with h5py.File(newer, "r+") as h5:
        h5.attrs["format_version"] = 99
    for path, pat in ((run, "format = 'tqdyn-trajectory'"), (text, "not a readable HDF5 file"),
                      (newer, "newer than this tqdyn")):
        with pytest.raises(ClosedLoopFormatError, match=pat) as e:
            read_closed_loop(path)
        assert "\n" not in str(e.value)
    with pytest.raises(FileNotFoundError):
        read_closed_loop(tmp_path / "missing.h5")


def test_a_corrupted_chunk_fails_its_checksum_in_one_line(tmp_path, model_and_budget):
    """A flipped byte inside a time-series chunk: Fletcher-32 catches it on reading."""
    path = _write(tmp_path / "cl.h5", *model_and_budget)
    with h5py.File(path, "r") as h5:
        off = h5["timeseries/tm1_acceleration"].id.get_chunk_info(0).byte_offset
    data = bytearray(path.read_bytes())
    data[off + 100] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(ClosedLoopFormatError, match="Fletcher-32") as e:
        read_closed_loop(path).timeseries(outputs=["tm1_acceleration"])
    assert "\n" not in str(e.value)
