"""Tests of the trajectory file format (tqdyn.formats.trajectory): writer, reader, xarray view."""

import os
import pathlib

import h5py
import numpy as np
import pytest

from tqdyn.formats import trajectory as io
from tqdyn.formats.trajectory import (
    FIELDS,
    FORMAT,
    FORMAT_VERSION,
    OutputError,
    Trajectory,
    TrajectoryFormatError,
    TrajectoryWriter,
    check_writable,
    read_trajectory,
)

ALL = list(FIELDS)
TIME_FIELDS = [f for f in ALL if FIELDS[f].time_dependent]
TWO_BODY = ["t", "sat/r", "sat/v", "sat/a_gravity"]


def make_attrs(**over):
    attrs = {
        "scenario": '[constellation]\nname = "tianqin"\n',
        "epoch_utc": "2034-01-01T00:00:00",
        "precision": "dd",
        "step_s": 50.0,
        "integrator": "rk8_dd",
        "pointing": "taylor2",
        "control": "on",
    }
    attrs.update(over)
    return attrs


def make_data(n, n_sat=3, fields=ALL, seed=0):
    """Synthetic arrays: dd fields as (hi, lo) with genuinely non-trivial lo."""
    rng = np.random.default_rng(seed)
    out = {}
    for f in fields:
        spec = FIELDS[f]
        shape = ((n,) if spec.time_dependent else ()) + spec.resolved_shape(n_sat)
        hi = rng.standard_normal(shape) * 1e8
        if spec.kind == "dd":
            lo = hi * np.finfo(float).eps * (rng.random(shape) - 0.5)  # |lo| < ulp(hi)/2
            out[f] = (hi, lo)
        else:
            out[f] = hi
    if "t" in out:
        hi = 50.0 * np.arange(n) + 1e-3
        out["t"] = (hi, hi * 1e-17)
    return out


def rows_slice(data, a, b):
    out = {}
    for f, v in data.items():
        if not FIELDS[f].time_dependent:
            continue
        out[f] = (v[0][a:b], v[1][a:b]) if isinstance(v, tuple) else v[a:b]
    return out


def write(path, data, n_sat=3, fields=None, chunks=(None,), **kw):
    fields = list(data) if fields is None else fields
    n = data["t"][0].shape[0]
    with TrajectoryWriter(path, make_attrs(), fields, n_sat, **kw) as w:
        bounds = [0] + [c for c in chunks if c is not None] + [n]
        for a, b in zip(bounds[:-1], bounds[1:]):
            w.append(rows_slice(data, a, b))
        for f in fields:
            if not FIELDS[f].time_dependent:
                w.set_static(f, data[f])
    assert w.rows_written == n
    return w


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def dir_listing(d):
    return sorted(p.name for p in pathlib.Path(d).iterdir())


# ---------------------------------------------------------------------------
# catalogue
# ---------------------------------------------------------------------------


def test_fields_catalogue_matches_contract():
    expected = {
        "t": ("dd", ()),
        "sat/r": ("dd", ("sat", 3)),
        "sat/v": ("dd", ("sat", 3)),
        "sat/a_gravity": ("f8", ("sat", 3)),
        "sat/a_dragfree": ("f8", ("sat", 3)),
        "sat/T_S_I": ("f8", ("sat", 3, 3)),
        "sat/omega": ("f8", ("sat", 3)),
        "sat/omega_dot": ("f8", ("sat", 3)),
        "sat/breathing_angle": ("f8", ("sat",)),
        "mosa/angle": ("f8", ("sat", "tm")),
        "tm/r": ("dd", ("sat", "tm", 3)),
        "tm/a_suspension": ("f8", ("sat", "tm", 3)),
        "tm/alpha_suspension": ("f8", ("sat", "tm", 3)),
        "tm/self_gravity": ("f8", ("sat", "tm", 3)),
    }
    # docs/trajectory-format.md: every contract field exactly as specified; the rest
    # are documented extensions (never renames or reshapes)
    extensions = {
        "tm/v": ("dd", ("sat", "tm", 3)),
        "tm/a": ("f8", ("sat", "tm", 3)),
        "tm/housing_offset": ("f8", ("sat", "tm", 3)),
    }
    assert {f: (s.kind, s.shape) for f, s in FIELDS.items()} == {**expected, **extensions}
    assert [f for f in FIELDS if f in expected] == list(expected)  # contract order kept
    assert [f for f, s in FIELDS.items() if not s.time_dependent] == ["tm/self_gravity"]
    for f, s in FIELDS.items():
        assert s.unit and s.frame and s.description, f
        assert len(s.dims) == len(s.shape), f
    assert FIELDS["sat/r"].resolved_shape(1) == (1, 3)
    assert FIELDS["tm/r"].resolved_shape(3) == (3, 2, 3)
    assert FORMAT == "tqdyn-trajectory" and FORMAT_VERSION == 2
    assert set(io.__all__) >= {"FIELDS", "FieldSpec", "OutputError", "check_writable",
                               "TrajectoryWriter", "Trajectory", "read_trajectory"}


# ---------------------------------------------------------------------------
# round trip
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n_sat", [3, 1, 2, 6])
def test_round_trip_every_field_bit_exact(tmp_path, n_sat):
    n = 37
    data = make_data(n, n_sat)
    path = tmp_path / "traj.h5"
    w = write(path, data, n_sat)
    assert w.path == path
    assert dir_listing(tmp_path) == ["traj.h5"]

    tr = read_trajectory(path)
    assert isinstance(tr, Trajectory)
    assert tr.fields == tuple(FIELDS)
    assert tr.n_sat == n_sat and tr.n_rows == n == len(tr)
    for f in ALL:
        spec = FIELDS[f]
        if spec.kind == "dd":
            hi, lo = tr.dd(f)
            assert np.array_equal(bits(hi), bits(data[f][0])), f
            assert np.array_equal(bits(lo), bits(data[f][1])), f
            assert np.array_equal(tr[f], data[f][0] + data[f][1]), f
        else:
            assert tr[f].dtype == np.float64
            assert np.array_equal(bits(tr[f]), bits(data[f])), f
            with pytest.raises(ValueError, match=f):
                tr.dd(f)
    assert tr["tm/self_gravity"].shape == (n_sat, 2, 3)
    assert tr["sat/T_S_I"].shape == (n, n_sat, 3, 3)


def test_root_attributes_native_types(tmp_path):
    path = tmp_path / "a.h5"
    write(path, make_data(4, fields=TWO_BODY))
    with h5py.File(path, "r") as h5:
        a = h5.attrs
        assert a["format"] == FORMAT and isinstance(a["format"], str)
        assert a["format_version"] == 2 and np.issubdtype(type(a["format_version"]), np.integer)
        assert isinstance(a["step_s"], (float, np.floating)) and a["step_s"] == 50.0
        for k in ("tqdyn_version", "scenario", "epoch_utc", "time_scale", "frame", "precision",
                  "integrator", "pointing", "control"):
            assert isinstance(a[k], str), k
        assert a["time_scale"] == "TT" and a["frame"] == "GCRS" and a["origin"] == "earth"
        assert h5["t"].attrs["frame"] == "TT"   # the time field names the file's time scale
        # dd layout: a group with float64 hi/lo; resizable chunked datasets
        assert isinstance(h5["sat/r"], h5py.Group)
        assert h5["sat/r/hi"].dtype == np.float64 and h5["sat/r/lo"].shape == (4, 3, 3)
        assert h5["sat/a_gravity"].maxshape == (None, 3, 3)
        assert h5["sat/a_gravity"].chunks is not None and h5["sat/a_gravity"].compression is None
        assert h5["sat/a_gravity"].attrs["units"] == "m/s^2"
    tr = read_trajectory(path)
    assert tr.format_version == 2
    assert tr.scenario_toml == make_attrs()["scenario"]
    assert tr.attrs["pointing"] == "taylor2" and type(tr.attrs["format_version"]) is int
    assert tr.fields == tuple(TWO_BODY)
    import tqdyn
    assert tr.attrs["tqdyn_version"] == tqdyn.__version__


def test_two_body_subset_and_missing_fields(tmp_path):
    path = tmp_path / "kepler.h5"
    write(path, make_data(5, fields=TWO_BODY))
    tr = read_trajectory(path)
    assert tr.fields == tuple(TWO_BODY)
    assert "tm/r" not in tr
    with pytest.raises(KeyError, match="tm/r"):
        tr["tm/r"]
    with pytest.raises(KeyError, match="bogus"):
        tr["bogus"]


def test_chunked_appends_equal_single_write(tmp_path):
    n = 101
    data = make_data(n)
    one, many = tmp_path / "one.h5", tmp_path / "many.h5"
    write(one, data)
    write(many, data, chunks=(1, 2, 40, 40, 100), expected_rows=60)
    a, b = read_trajectory(one), read_trajectory(many)
    assert a.fields == b.fields
    for f in ALL:
        for x, y in zip(a._get(f), b._get(f)):
            assert np.array_equal(bits(x), bits(y)), f


@pytest.mark.parametrize("expected_rows", [None, 3, 10, 10_000])
def test_expected_rows_is_only_a_hint(tmp_path, expected_rows):
    data = make_data(10, fields=TWO_BODY)
    path = tmp_path / "e.h5"
    write(path, data, chunks=(4,), expected_rows=expected_rows)
    tr = read_trajectory(path)
    assert tr.n_rows == 10
    assert np.array_equal(tr.dd("t")[0], data["t"][0])


def test_dd_as_trailing_axis_of_two(tmp_path):
    data = make_data(6, fields=TWO_BODY)
    packed = {f: (np.stack(v, axis=-1) if isinstance(v, tuple) else v) for f, v in data.items()}
    assert packed["sat/r"].shape == (6, 3, 3, 2) and packed["t"].shape == (6, 2)
    path = tmp_path / "p.h5"
    with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3) as w:
        w.append(packed)
    tr = read_trajectory(path)
    for f in ("t", "sat/r", "sat/v"):
        hi, lo = tr.dd(f)
        assert np.array_equal(bits(hi), bits(data[f][0]))
        assert np.array_equal(bits(lo), bits(data[f][1]))


def test_append_copies_caller_buffers(tmp_path):
    """Rows may be buffered; reusing the caller's arrays afterwards must not change the file."""
    data = make_data(4, fields=TWO_BODY)
    path = tmp_path / "c.h5"
    with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3) as w:
        for i in range(4):
            row = {f: tuple(np.array(x[i:i + 1]) for x in v) if isinstance(v, tuple)
                   else np.array(v[i:i + 1]) for f, v in data.items()}
            w.append(row)
            row["sat/a_gravity"][...] = np.nan
            row["sat/r"][0][...] = np.nan
        assert w.rows_written == 4
    tr = read_trajectory(path)
    assert np.array_equal(tr["sat/a_gravity"], data["sat/a_gravity"])
    assert np.array_equal(tr.dd("sat/r")[0], data["sat/r"][0])


def test_zero_rows_file(tmp_path):
    path = tmp_path / "z.h5"
    with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3):
        pass
    tr = read_trajectory(path)
    assert tr.n_rows == 0 and tr["sat/r"].shape == (0, 3, 3)
    ds = tr.to_xarray()
    assert ds.sizes["time"] == 0


def test_readback_arrays_are_read_only(tmp_path):
    path = tmp_path / "r.h5"
    write(path, make_data(3, fields=TWO_BODY))
    tr = read_trajectory(path)
    with pytest.raises(ValueError):
        tr["sat/a_gravity"][0, 0, 0] = 1.0


# ---------------------------------------------------------------------------
# atomicity
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_failure_in_with_block_leaves_nothing(tmp_path, exc):
    data = make_data(20)
    path = tmp_path / "fail.h5"
    with pytest.raises(exc):
        with TrajectoryWriter(path, make_attrs(), ALL, 3) as w:
            w.append(rows_slice(data, 0, 10))
            assert len(dir_listing(tmp_path)) == 1  # the hidden temporary file
            assert dir_listing(tmp_path)[0].startswith(".fail.h5.")
            raise exc("boom")
    assert not path.exists()
    assert dir_listing(tmp_path) == []


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_existing_file_survives_failed_write(tmp_path, exc):
    path = tmp_path / "keep.h5"
    path.write_bytes(b"precious old result")
    before = os.stat(path)
    with pytest.raises(exc):
        with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3) as w:
            w.append(rows_slice(make_data(5, fields=TWO_BODY), 0, 5))
            raise exc()
    assert path.read_bytes() == b"precious old result"
    assert os.stat(path).st_mtime_ns == before.st_mtime_ns
    assert dir_listing(tmp_path) == ["keep.h5"]


def test_existing_file_replaced_on_success(tmp_path):
    path = tmp_path / "out.h5"
    path.write_bytes(b"old")
    write(path, make_data(3, fields=TWO_BODY))
    assert read_trajectory(path).n_rows == 3
    assert dir_listing(tmp_path) == ["out.h5"]


def test_bad_append_inside_with_block_leaves_nothing(tmp_path):
    path = tmp_path / "bad.h5"
    with pytest.raises(ValueError, match="sat/v"):
        with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3) as w:
            rows = rows_slice(make_data(5, fields=TWO_BODY), 0, 5)
            del rows["sat/v"]
            w.append(rows)
    assert dir_listing(tmp_path) == []


def test_abort_and_use_after_close(tmp_path):
    path = tmp_path / "ab.h5"
    w = TrajectoryWriter(path, make_attrs(), TWO_BODY, 3)
    w.append(rows_slice(make_data(2, fields=TWO_BODY), 0, 2))
    w.abort()
    w.abort()  # idempotent
    assert dir_listing(tmp_path) == []
    with pytest.raises(ValueError, match="aborted"):
        w.append(rows_slice(make_data(2, fields=TWO_BODY), 0, 2))

    w = TrajectoryWriter(path, make_attrs(), TWO_BODY, 3)
    assert w.close() == path and w.close() == path
    with pytest.raises(ValueError, match="closed"):
        w.append(rows_slice(make_data(2, fields=TWO_BODY), 0, 2))


def test_unclosed_writer_temp_removed_on_garbage_collection(tmp_path):
    import gc

    w = TrajectoryWriter(tmp_path / "gc.h5", make_attrs(), TWO_BODY, 3)
    assert len(dir_listing(tmp_path)) == 1
    del w
    gc.collect()
    assert dir_listing(tmp_path) == []


def test_declared_static_field_must_be_set(tmp_path):
    path = tmp_path / "s.h5"
    fields = TWO_BODY + ["tm/self_gravity"]
    with pytest.raises(ValueError, match="tm/self_gravity"):
        with TrajectoryWriter(path, make_attrs(), fields, 3) as w:
            w.append(rows_slice(make_data(2, fields=TWO_BODY), 0, 2))
    assert dir_listing(tmp_path) == []


def test_set_static_without_declaring(tmp_path):
    path = tmp_path / "s2.h5"
    sg = np.arange(18.0).reshape(3, 2, 3)
    with TrajectoryWriter(path, make_attrs(), TWO_BODY, 3) as w:
        w.set_static("tm/self_gravity", sg)
    tr = read_trajectory(path)
    assert "tm/self_gravity" in tr.fields
    assert np.array_equal(tr["tm/self_gravity"], sg)


# ---------------------------------------------------------------------------
# validation errors
# ---------------------------------------------------------------------------


@pytest.fixture
def writer(tmp_path):
    w = TrajectoryWriter(tmp_path / "v.h5", make_attrs(), ALL, 3)
    yield w
    w.abort()


def test_append_missing_field_named(writer):
    rows = rows_slice(make_data(4), 0, 4)
    del rows["tm/a_suspension"]
    with pytest.raises(ValueError, match="missing field.*tm/a_suspension"):
        writer.append(rows)
    assert writer.rows_written == 0


@pytest.mark.parametrize("field,shape", [
    ("sat/a_gravity", (4, 3)),
    ("sat/a_gravity", (4, 2, 3)),
    ("sat/T_S_I", (4, 3, 3)),
    ("mosa/angle", (4, 3, 3)),
    ("sat/breathing_angle", (4, 3, 1)),
])
def test_append_wrong_shape_named(writer, field, shape):
    rows = rows_slice(make_data(4), 0, 4)
    rows[field] = np.zeros(shape)
    with pytest.raises(ValueError, match=f"field '{field}'.*shape"):
        writer.append(rows)
    assert writer.rows_written == 0


def test_append_dd_errors_named(writer):
    good = rows_slice(make_data(4), 0, 4)
    rows = dict(good, **{"sat/r": (good["sat/r"][0], good["sat/r"][1][:, :2])})
    with pytest.raises(ValueError, match="sat/r"):
        writer.append(rows)
    rows = dict(good, **{"tm/r": good["tm/r"][0]})  # plain array, no lo
    with pytest.raises(ValueError, match="tm/r"):
        writer.append(rows)
    rows = dict(good, **{"sat/v": (good["sat/v"][0],)})
    with pytest.raises(ValueError, match="sat/v"):
        writer.append(rows)
    assert writer.rows_written == 0


def test_append_row_count_mismatch_named(writer):
    rows = rows_slice(make_data(4), 0, 4)
    rows["sat/omega"] = rows["sat/omega"][:3]
    with pytest.raises(ValueError, match="sat/omega.*rows"):
        writer.append(rows)


def test_append_unknown_undeclared_and_static_fields(tmp_path, writer):
    rows = rows_slice(make_data(4), 0, 4)
    with pytest.raises(ValueError, match="bogus"):
        writer.append(dict(rows, bogus=np.zeros(4)))
    with pytest.raises(ValueError, match="tm/self_gravity.*static"):
        writer.append(dict(rows, **{"tm/self_gravity": np.zeros((3, 2, 3))}))
    with TrajectoryWriter(tmp_path / "u.h5", make_attrs(), TWO_BODY, 3) as w2:
        with pytest.raises(ValueError, match="tm/r.*not declared"):
            w2.append(dict(rows_slice(make_data(4, fields=TWO_BODY), 0, 4), **{"tm/r": rows["tm/r"]}))
    with pytest.raises(ValueError, match="tm/self_gravity.*shape"):
        writer.set_static("tm/self_gravity", np.zeros((3, 3)))
    with pytest.raises(ValueError, match="sat/r.*time-dependent"):
        writer.set_static("sat/r", np.zeros((3, 3)))


def test_writer_argument_errors(tmp_path):
    p = tmp_path / "x.h5"
    with pytest.raises(ValueError, match="n_sat"):
        TrajectoryWriter(p, make_attrs(), TWO_BODY, 0)
    with pytest.raises(ValueError, match="n_sat"):
        TrajectoryWriter(p, make_attrs(), TWO_BODY, 2.0)
    with pytest.raises(ValueError, match="bogus"):
        TrajectoryWriter(p, make_attrs(), TWO_BODY + ["bogus"], 3)
    with pytest.raises(ValueError, match="'t'"):
        TrajectoryWriter(p, make_attrs(), ["sat/r"], 3)
    with pytest.raises(ValueError, match="pointing.*global"):
        TrajectoryWriter(p, make_attrs(pointing="sideways"), TWO_BODY, 3)
    with pytest.raises(ValueError, match="control"):
        TrajectoryWriter(p, make_attrs(control=True), TWO_BODY, 3)
    with pytest.raises(ValueError, match="precision"):
        TrajectoryWriter(p, make_attrs(precision="quad"), TWO_BODY, 3)
    with pytest.raises(ValueError, match="epoch_utc"):
        TrajectoryWriter(p, make_attrs(epoch_utc="yesterday"), TWO_BODY, 3)
    with pytest.raises(ValueError, match="time_scale"):
        TrajectoryWriter(p, make_attrs(time_scale="UTC"), TWO_BODY, 3)
    attrs = make_attrs()
    del attrs["scenario"]
    with pytest.raises(ValueError, match="scenario"):
        TrajectoryWriter(p, attrs, TWO_BODY, 3)
    assert dir_listing(tmp_path) == []


# ---------------------------------------------------------------------------
# check_writable
# ---------------------------------------------------------------------------


def test_check_writable_ok(tmp_path):
    p = check_writable(tmp_path / "ok.h5")
    assert p == tmp_path / "ok.h5" and p.is_absolute()
    assert dir_listing(tmp_path) == []


def test_check_writable_missing_dir(tmp_path):
    p = tmp_path / "nope" / "x.h5"
    with pytest.raises(OutputError, match="nope.*does not exist"):
        check_writable(p)
    with pytest.raises(OutputError, match="nope"):
        TrajectoryWriter(p, make_attrs(), TWO_BODY, 3)


def test_check_writable_path_is_dir(tmp_path):
    d = tmp_path / "adir"
    d.mkdir()
    with pytest.raises(OutputError, match="adir.*is a directory"):
        check_writable(d)
    with pytest.raises(OutputError, match="directory"):
        check_writable(str(tmp_path) + os.sep)


def test_check_writable_unwritable_dir(tmp_path):
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o500)
    try:
        if os.access(d, os.W_OK):
            pytest.skip("running as root (or similar): read-only directory is still writable")
        with pytest.raises(OutputError, match="ro.*not writable"):
            check_writable(d / "x.h5")
    finally:
        d.chmod(0o700)


def test_check_writable_probe_failure(tmp_path, monkeypatch):
    """The directory is probed by creating a file (catches e.g. read-only mounts, ACLs)."""
    real_open = os.open

    def fake_open(path, flags, *a, **k):
        if str(path).endswith(".probe"):
            raise PermissionError(13, "Permission denied")
        return real_open(path, flags, *a, **k)

    monkeypatch.setattr(os, "open", fake_open)
    with pytest.raises(OutputError, match="not writable.*Permission denied"):
        check_writable(tmp_path / "x.h5")


def test_output_error_is_oserror():
    assert issubclass(OutputError, OSError)


# ---------------------------------------------------------------------------
# reader format checks
# ---------------------------------------------------------------------------


def _retag(path, **attrs):
    with h5py.File(path, "r+") as h5:
        for k, v in attrs.items():
            h5.attrs[k] = v


def test_reader_rejects_wrong_format(tmp_path):
    path = tmp_path / "f.h5"
    write(path, make_data(2, fields=TWO_BODY))
    _retag(path, format="something-else")
    with pytest.raises(TrajectoryFormatError) as ei:
        read_trajectory(path)
    msg = str(ei.value)
    assert "something-else" in msg and "tqdyn-trajectory" in msg and "f.h5" in msg
    assert "format_version" in msg and "\n" not in msg


def test_reader_rejects_newer_version(tmp_path):
    path = tmp_path / "v.h5"
    write(path, make_data(2, fields=TWO_BODY))
    _retag(path, format_version=FORMAT_VERSION + 1)
    with pytest.raises(TrajectoryFormatError) as ei:
        read_trajectory(path)
    msg = str(ei.value)
    assert "tqdyn-trajectory" in msg and f"format_version = {FORMAT_VERSION + 1}" in msg
    assert f"<= {FORMAT_VERSION}" in msg and "\n" not in msg


def test_reader_other_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.h5"):
        read_trajectory(tmp_path / "missing.h5")
    junk = tmp_path / "junk.h5"
    junk.write_bytes(b"not hdf5 at all")
    with pytest.raises(TrajectoryFormatError, match="junk.h5"):
        read_trajectory(junk)
    path = tmp_path / "m.h5"
    write(path, make_data(4, fields=TWO_BODY))
    with h5py.File(path, "r+") as h5:
        del h5["sat/a_gravity"]
        h5.create_dataset("sat/a_gravity", data=np.zeros((3, 3, 3)))
    with pytest.raises(TrajectoryFormatError, match="sat/a_gravity.*rows"):
        read_trajectory(path)


def test_reader_ignores_unknown_objects(tmp_path):
    path = tmp_path / "extra.h5"
    write(path, make_data(2, fields=TWO_BODY))
    with h5py.File(path, "r+") as h5:
        h5.create_dataset("notes/something", data=np.zeros(5))
    assert read_trajectory(path).fields == tuple(TWO_BODY)


# ---------------------------------------------------------------------------
# xarray
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("n_sat", [3, 1, 6])
def test_xarray_view(tmp_path, n_sat):
    xr = pytest.importorskip("xarray")
    n = 7
    data = make_data(n, n_sat)
    path = tmp_path / "x.h5"
    write(path, data, n_sat)
    tr = read_trajectory(path)
    ds = tr.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert dict(ds.sizes) == {"time": n, "sat": n_sat, "tm": 2, "comp": 3, "row": 3, "col": 3}
    assert list(ds["sat"].values) == list(range(1, n_sat + 1))
    assert list(ds["tm"].values) == [1, 2]
    assert list(ds["comp"].values) == ["x", "y", "z"]
    assert ds["time"].dtype == np.float64
    assert np.array_equal(ds["time"].values, data["t"][0] + data["t"][1])
    assert ds["sat_r"].dims == ("time", "sat", "comp")
    assert ds["sat_T_S_I"].dims == ("time", "sat", "row", "col")
    assert ds["mosa_angle"].dims == ("time", "sat", "tm")
    assert ds["sat_breathing_angle"].dims == ("time", "sat")
    assert ds["tm_r"].dims == ("time", "sat", "tm", "comp")
    assert ds["tm_self_gravity"].dims == ("sat", "tm", "comp")
    assert "sat_a_gravity_lo" not in ds and "t" not in ds
    for name in ("sat_r", "sat_v", "tm_r"):
        hi, lo = data[name.replace("_", "/", 1)]
        assert np.array_equal(ds[name].values, hi + lo)
        # value + residual reproduces hi + lo exactly (two-sum)
        s, r = ds[name].values, ds[name + "_lo"].values
        assert np.array_equal(s, hi + lo)
        assert np.all((s - hi) - lo == -r)
    assert ds["sat_r"].attrs["units"] == "m" and ds["sat_r"].attrs["frame"] == "GCRS"
    assert ds["tm_a_suspension"].attrs["frame"] == "OA_l"
    for v in ds.data_vars.values():
        assert {"units", "frame", "description"} <= set(v.attrs)
    for k, v in tr.attrs.items():
        assert ds.attrs[k] == v
    assert ds.attrs["format"] == FORMAT


def test_xarray_two_body_only(tmp_path):
    pytest.importorskip("xarray")
    path = tmp_path / "k.h5"
    write(path, make_data(3, n_sat=1, fields=TWO_BODY), n_sat=1)
    ds = read_trajectory(path).to_xarray()
    assert set(ds.data_vars) == {"t_lo", "sat_r", "sat_r_lo", "sat_v", "sat_v_lo", "sat_a_gravity"}
    assert dict(ds.sizes) == {"time": 3, "sat": 1, "comp": 3}


def test_reads_format_version_1_files():
    """A file written by tqdyn 0.1 (tests/fixtures/trajectory-v1-tianqin.h5: the coupled
    tianqin scenario, 10 minutes, made with the 0.1 release) reads with every field, and its
    reference system says what its t meant (TT-elapsed seconds labelled TDB)."""
    from tqdyn.astro.reference import GEOCENTRIC_V1

    path = pathlib.Path(__file__).parent / "fixtures" / "trajectory-v1-tianqin.h5"
    tr = read_trajectory(path)
    assert tr.format_version == 1 and tr.attrs["tqdyn_version"] == "0.1.0" and tr.attrs["time_scale"] == "TDB"
    assert tr.reference is GEOCENTRIC_V1 and "labelled TDB" in tr.reference.description
    assert tr.n_rows == 13 and tr.n_sat == 3 and "tm/alpha_suspension" in tr.fields
    assert np.array_equal(tr["t"], np.arange(13) * 50.0)
    ds = tr.to_xarray()
    assert ds.time.attrs["frame"] == "TDB" and ds.sat_r.shape == (13, 3, 3)
