"""The orbit-determination files: measurements as CCSDS TDM (tqdyn.formats.od_tdm) and the estimate
file EST.h5 (tqdyn.formats.od_estimate); docs/od-files.md.

References: exact decimal arithmetic (Python's decimal module) for the m -> km conversion of the
values; the IERS offsets TAI - UTC = 32 s (1999-2006, IERS Bulletin C) and TT - TAI = 32.184 s for
the epochs of a geocentric run; bit equality for the round trips.
"""

from __future__ import annotations

import datetime
import types
from decimal import Decimal

import h5py
import numpy as np
import pytest

from tqdyn.astro.timescales import Epoch
from tqdyn.formats.od_estimate import EstimateFormatError, read_estimate_file, write_estimate_file
from tqdyn.formats.od_tdm import measurements_to_tdm, read_measurements_tdm, tdm_to_measurements, write_measurements_tdm
from tqdyn.formats.tdm import format_tdm, parse_tdm, read_tdm

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")
C = 299792458.0   # m/s, the SI definition
FIELDS = ("t", "type", "sat", "peer", "value", "sigma")


def _table(m=60, seed=1):
    """A table of every type, satellite and a few peers, in time order; values of every magnitude
    from 1e-13 m (sub-pm) to 1e11 m with random mantissas, and some random float64 bit patterns
    (one-way rows)."""
    rng = np.random.default_rng(seed)
    kinds = [("gnss_pseudorange", "G07", 3.0), ("slr_range", "Monument Peak", 0.01), ("isr_range", "0", 0.5),
             ("dsn_range", "DSS-14", 1.0), ("dsn_range_rate", "DSS-14", 1e-3), ("gnss_pseudorange", "C12", 2.5)]
    t = np.repeat(np.arange(m // 6) * 600.0, 6)
    typ = np.array([k[0] for k in kinds] * (m // 6))
    peer = np.array([k[1] for k in kinds] * (m // 6))
    sigma = np.array([k[2] for k in kinds] * (m // 6))
    sat = np.array([0, 1, 2, 0, 1, 2] * (m // 6))
    value = rng.uniform(-1, 1, m) * 10.0 ** rng.uniform(-13, 11, m)
    one_way = np.flatnonzero(np.isin(typ, ["gnss_pseudorange", "isr_range"]))[:10]
    bits = rng.integers(0, 2 ** 62, one_way.size - 1, dtype=np.int64).view(np.float64)
    value[one_way[:-1]] = np.where(np.isfinite(bits), bits, 1.0)
    value[one_way[-1]] = 1e-12  # 1 pm
    # downlink light times [s] of the two-way rows: a range's half round trip (what a reader takes
    # back), a range rate's a few 10 ms (its range row is of another satellite here)
    tau = np.where(typ == "dsn_range_rate", rng.uniform(0.01, 0.05, m), np.nan)
    rng_rows = np.isin(typ, ["slr_range", "dsn_range"])
    tau[rng_rows] = value[rng_rows] / C
    return types.SimpleNamespace(t=t, type=typ, sat=sat, peer=peer, value=value, sigma=sigma, tau_down=tau)


def _seconds_after(text: str, t0: datetime.datetime) -> float:
    """Seconds from t0 to an epoch text YYYY-MM-DDThh:mm:ss.fffffffff (its ns digits kept)."""
    return (datetime.datetime.fromisoformat(text[:26]) - t0).total_seconds() + float("0." + text[26:]) * 1e-6


def test_tdm_round_trip_is_exact():
    """Measurements -> TDM text -> Measurements gives every field back bit for bit (geocentric run, UTC
    epoch: TT of the epoch is whole ns, t on a 600 s grid); the km texts are exactly value / 1000."""
    meas = _table()
    tdm = measurements_to_tdm(meas, epoch=EPOCH, time_scale="TT", satellite_names=["TQ1", "TQ2", "TQ3"],
                              info={"tracking": "gnss,slr,isr,dsn"}, creation_date="2026-01-01T00:00:00")
    text = format_tdm(tdm)
    fields, info = tdm_to_measurements(parse_tdm(text), epoch=EPOCH, time_scale="TT", grid_s=600.0)
    for f in FIELDS:
        assert np.array_equal(fields[f], getattr(meas, f)), f
    assert fields["value"].view(np.int64).tolist() == meas.value.view(np.int64).tolist()
    assert info["tracking"] == "gnss,slr,isr,dsn" and info["time_scale"] == "TT"
    for seg in tdm.segments:
        for kw, _, v in seg.data:
            assert kw == ("DOPPLER_INSTANTANEOUS" if "rate" in seg.meta_comments[0] else "RANGE")
    # each one-way km text is the shortest decimal of the value (repr) divided by 1000 exactly
    one_way = {v for seg in tdm.segments if seg.metadata["PATH"] == "1,2" for _, _, v in seg.data}
    for x in meas.value[np.isin(meas.type, ["gnss_pseudorange", "isr_range"])]:
        assert str(Decimal(repr(float(x))).scaleb(-3)) in one_way
    texts = one_way
    for v in texts:
        assert Decimal(repr(float(Decimal(v) * 1000))) == Decimal(v) * 1000


def test_tdm_epochs_and_keywords():
    """TT = UTC + 32 s + 32.184 s in 2004 (IERS); the standard's keywords per type; the ISR peer by
    name; sigma and type in tqdyn's comments."""
    meas = _table(12)
    tdm = measurements_to_tdm(meas, epoch=EPOCH, time_scale="TT", satellite_names=["TQ1", "TQ2", "TQ3"])
    seg = {s.meta_comments[0]: s for s in tdm.segments[:5]}
    gnss = seg["tqdyn type = gnss_pseudorange"]
    assert gnss.data[0][1] == "2004-06-06T00:01:04.184000000"
    assert gnss.metadata == {"TIME_SYSTEM": "TT", "PARTICIPANT_1": "G07", "PARTICIPANT_2": "TQ1", "MODE": "SEQUENTIAL",
                             "PATH": "1,2", "TIMETAG_REF": "RECEIVE", "RANGE_UNITS": "km",
                             "START_TIME": "2004-06-06T00:01:04.184000000",
                             "STOP_TIME": "2004-06-06T00:11:04.184000000"}
    isr = seg["tqdyn type = isr_range"]
    assert isr.metadata["PARTICIPANT_1"] == "TQ1" and isr.metadata["PARTICIPANT_2"] == "TQ3"
    assert "tqdyn peer = 0" in isr.meta_comments
    rr = seg["tqdyn type = dsn_range_rate"]
    assert rr.metadata["PATH"] == "1,2,1" and "RANGE_UNITS" not in rr.metadata and rr.metadata["TIMETAG_REF"] == "RECEIVE"
    slr = seg["tqdyn type = slr_range"]
    assert slr.metadata["RANGE_UNITS"] == "s" and slr.metadata["TIMETAG_REF"] == "RECEIVE"
    # tagged at reception: the bounce (t = 0 at the UTC epoch, TT 00:01:04.184) plus the downlink light time
    assert abs(_seconds_after(slr.data[0][1], datetime.datetime(2004, 6, 6, 0, 1, 4, 184000))
               - meas.tau_down[1]) <= 1e-9
    assert "tqdyn sigma = 0.001 m/s" in rr.meta_comments
    assert seg["tqdyn type = slr_range"].metadata["PARTICIPANT_1"] == "Monument Peak"


def test_tdm_heliocentric_times_within_a_nanosecond(tmp_path):
    """A TDB epoch that is not whole nanoseconds: t comes back within 1 ns (the epoch digits); the file
    is written atomically and read back through the TDM reader."""
    epoch = Epoch.from_tdb("2035-03-01T12:00:00.123456789123")
    meas = _table(24)
    meas.t = meas.t + np.linspace(0.0, 1.0, meas.t.size) * 1e-3
    path = write_measurements_tdm(tmp_path / "m.tdm", meas, epoch=epoch, time_scale="TDB")
    fields, _ = read_measurements_tdm(path, epoch=epoch, time_scale="TDB")
    one = np.isin(fields["type"], ["gnss_pseudorange", "isr_range"])
    fields = {k: v[one] for k, v in fields.items()}
    meas = types.SimpleNamespace(**{k: getattr(meas, k)[np.isin(meas.type, ["gnss_pseudorange", "isr_range"])]
                                    for k in FIELDS})
    err = np.max(np.abs(fields["t"] - meas.t))
    assert err <= 1.0e-9, err
    assert np.array_equal(fields["value"], meas.value)
    assert read_tdm(path).segments[0].metadata["TIME_SYSTEM"] == "TDB"


@pytest.mark.parametrize("edit, pattern", [
    (lambda s: s.replace("COMMENT tqdyn epoch", "COMMENT epoch"), r"header: no 'COMMENT tqdyn epoch'"),
    (lambda s: s.replace("  COMMENT tqdyn type = slr_range\n", ""), r"segment 2: metadata: no 'COMMENT tqdyn type'"),
    (lambda s: s.replace("RANGE_UNITS = km", "RANGE_UNITS = s", 1), r"segment 1: RANGE_UNITS = 's'; allowed: km"),
    (lambda s: s.replace("TIMETAG_REF = RECEIVE", "TIMETAG_REF = BOUNCE", 1),
     r"segment 1: TIMETAG_REF: 'BOUNCE' is not allowed; allowed: TRANSMIT, RECEIVE"),
    (lambda s: s.replace("tqdyn sigma = 3.0 m", "tqdyn sigma = -3.0 m"), r"segment 1: tqdyn sigma = '-3.0 m'"),
    (lambda s: s.replace("TIME_SYSTEM = TT", "TIME_SYSTEM = UTC", 1), r"segment 1: TIME_SYSTEM = 'UTC'"),
    (lambda s: s.replace("DATA_STOP", "", 1), r"line \d+: META_START: unexpected here"),
])
def test_tdm_refusals_are_one_line(tmp_path, edit, pattern):
    """A damaged or foreign measurement file is refused in one line naming the file and the field."""
    meas = _table(12)
    text = edit(format_tdm(measurements_to_tdm(meas, epoch=EPOCH, time_scale="TT")))
    p = tmp_path / "bad.tdm"
    p.write_text(text)
    with pytest.raises(ValueError, match=pattern) as info:
        read_measurements_tdm(p, epoch=EPOCH, time_scale="TT")
    assert "\n" not in str(info.value) and str(p) in str(info.value)


def test_tdm_of_another_scenario_is_refused(tmp_path):
    p = write_measurements_tdm(tmp_path / "m.tdm", _table(12), epoch=EPOCH, time_scale="TT")
    with pytest.raises(ValueError, match=r"header: epoch 2004-06-06T00:00:00 UTC, the scenario's is 2004-06-07"):
        read_measurements_tdm(p, epoch=Epoch.from_utc("2004-06-07T00:00:00"), time_scale="TT")
    with pytest.raises(ValueError, match=r"time scale TT, the scenario's is TDB"):
        read_measurements_tdm(p, epoch=EPOCH, time_scale="TDB")


def _estimate():
    """A real Estimate of a small linear problem with a consider parameter and editing."""
    from tqdyn.od.estimator import Parameters, Problem, estimate

    t = np.linspace(0.0, 86400.0, 40)
    jac = np.stack([np.ones_like(t), t, 0.5 * t * t], 1)
    y = jac[:, :2] @ [3.0, 1e-3] + 0.5 * np.random.default_rng(2).standard_normal(t.size)
    y[7] += 30.0
    prob = Problem(lambda q: (jac @ q, jac), Parameters(("Sat1/x", "Sat1/vx"), np.zeros(2)), y=y,
                   sigma=np.full(t.size, 0.5), consider=Parameters(("Sat1/s_x",), np.zeros(1), np.array([1e-12])),
                   groups=tuple(["slr_range"] * t.size))
    meas = types.SimpleNamespace(t=t, type=np.array(["slr_range"] * t.size), sat=np.zeros(t.size, np.int64),
                                 peer=np.array(["Yarragadee"] * t.size), value=y, sigma=np.full(t.size, 0.5))
    return estimate(prob, edit_sigma=5.0), meas


def test_estimate_file_round_trip_is_bit_equal(tmp_path):
    """Every field written is read back bit for bit; the statistics are the Estimate's."""
    est, meas = _estimate()
    assert est.edited[7] and est.edited.sum() == 1
    attrs = {"scenario": "[scenario]\nname = \"x\"\n", "scenario_name": "x", "epoch": EPOCH.iso, "time_scale": "TT",
             "tdm_file": "m.tdm", "tdm_sha256": "ab" * 32, "edit_sigma": 5.0, "tracking": "{}"}
    path = write_estimate_file(tmp_path / "est.h5", est, meas, attrs=attrs, units=["m", "m/s"])
    f = read_estimate_file(path)
    p, m = f.parameters, f.measurements
    assert list(p["names"]) == ["Sat1/x", "Sat1/vx"] and list(p["units"]) == ["m", "m/s"]
    assert list(p["consider_names"]) == ["Sat1/s_x"]
    for k in ("values", "sigma", "covariance", "correlation", "sensitivity", "consider_covariance", "consider_sigma"):
        assert np.array_equal(p[k], getattr(est, k)) and p[k].dtype == np.float64, k
    for k, ref in (("t", meas.t), ("value", meas.value), ("sigma", meas.sigma), ("sat", meas.sat),
                   ("residual", est.residuals), ("normalised_residual", est.normalised_residuals),
                   ("edited", est.edited), ("type", meas.type), ("peer", meas.peer)):
        assert np.array_equal(m[k], ref), k
    assert m["edited"].dtype == bool
    for k in ("chi2", "chi2_dof", "chi2_pvalue", "iterations", "last_step", "condition_number"):
        assert f.attrs[k] == getattr(est, k), k
    for k, v in attrs.items():
        assert f.attrs[k] == v, k
    assert f.attrs["format"] == "tqdyn-od-estimate" and f.attrs["format_version"] == 1
    assert f.sigma_of("Sat1/vx") == est.sigma[1]


def test_estimate_file_refusals(tmp_path):
    """A foreign HDF5 file, a damaged (truncated) one and a missing dataset are refused in one line; an
    interrupted write leaves no file."""
    est, meas = _estimate()
    attrs = {"scenario": "", "tdm_sha256": ""}
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5.attrs["format"] = "tqdyn-trajectory"
    with pytest.raises(EstimateFormatError, match=r"format = 'tqdyn-trajectory'; expected format 'tqdyn-od-estimate'"):
        read_estimate_file(foreign)
    good = write_estimate_file(tmp_path / "est.h5", est, meas, attrs=attrs)
    data = good.read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(EstimateFormatError) as info:
        read_estimate_file(cut)
    assert str(cut) in str(info.value) and "\n" not in str(info.value)
    with h5py.File(good, "a") as h5:
        del h5["measurements/residual"]
    with pytest.raises(EstimateFormatError, match=r"'/measurements/residual' is missing"):
        read_estimate_file(good)
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    with pytest.raises(EstimateFormatError, match=r"not a readable HDF5 file"):
        read_estimate_file(text)


def test_interrupted_estimate_write_leaves_nothing(tmp_path, monkeypatch):
    est, meas = _estimate()
    import tqdyn.formats.od_estimate as mod

    def stop(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(mod, "_put", stop)
    with pytest.raises(KeyboardInterrupt):
        write_estimate_file(tmp_path / "est.h5", est, meas, attrs={})
    assert list(tmp_path.iterdir()) == []


def _ccsds_ndm_segments(path):
    """The segments of a TDM as the PyPI package ccsds-ndm (an independent reader generated from the
    CCSDS schemas) parses them."""
    ndm_io = pytest.importorskip("ccsds_ndm.ndm_io")
    import pathlib

    return ndm_io.NdmIo().from_path(pathlib.Path(path)).body.segment


def _text(v) -> str:
    """An enumeration member's value or a plain string (ccsds-ndm returns either)."""
    return str(getattr(v, "value", v))


def test_tdm_read_by_ccsds_ndm(tmp_path):
    """A measurement file of tqdyn parsed by ccsds-ndm 3.1 (its KVN reader): one segment per
    (type, satellite, peer, sigma); TIME_SYSTEM, the participants, PATH, MODE, RANGE_UNITS (of the
    ranges) and TIMETAG_REF as the table of docs/od-files.md says; every epoch as written and every
    value (km, km/s) equal to the table's m, m/s / 1000 to the float64 rounding of ccsds-ndm's parse
    of the decimal (1 ulp), every epoch the TT of the UTC epoch + t (TT - UTC = 64.184 s in 2004)."""
    meas = _table()
    names = ["TQ1", "TQ2", "TQ3"]
    path = write_measurements_tdm(tmp_path / "m.tdm", meas, epoch=EPOCH, time_scale="TT", satellite_names=names)
    segs = _ccsds_ndm_segments(path)
    keys = list(dict.fromkeys(zip(meas.type.tolist(), meas.sat.tolist(), meas.peer.tolist(), meas.sigma.tolist())))
    assert len(segs) == len(keys)
    paths = {"gnss_pseudorange": "1,2", "isr_range": "1,2", "slr_range": "1,2,1", "dsn_range": "1,2,1",
             "dsn_range_rate": "1,2,1"}
    for seg, (typ, sat, peer, sig) in zip(segs, keys):
        md = seg.metadata
        rows = (meas.type == typ) & (meas.sat == sat) & (meas.peer == peer)
        assert _text(md.time_system) == "TT" and _text(md.mode) == "SEQUENTIAL"
        assert md.participant_2 == names[sat]
        assert md.participant_1 == (names[int(peer)] if typ == "isr_range" else peer)
        assert md.path == paths[typ]
        two = paths[typ] == "1,2,1"
        assert _text(md.range_units) == ("None" if typ == "dsn_range_rate" else "s" if two else "km")
        assert _text(md.timetag_ref) == "RECEIVE"
        obs = seg.data.observation
        v = meas.value[rows]
        if typ == "dsn_range_rate":   # d/dt_receive = (d/dt_bounce) / (1 + v / c)
            value, want_v = np.array([o.doppler_instantaneous for o in obs]) * 1e3, v * C / (C + v)
        elif two:                     # the round-trip light time 2 v / c
            value, want_v = np.array([o.range for o in obs]), 2.0 * v / C
        else:
            value, want_v = np.array([o.range for o in obs]) * 1e3, v
        assert np.allclose(value, want_v, rtol=1.5e-15, atol=0), typ
        tt0 = datetime.datetime(2004, 6, 6, 0, 1, 4, 184000)     # the UTC epoch + 32 s + 32.184 s
        tag = meas.t[rows] + (meas.tau_down[rows] if two else 0.0)   # two-way: at reception
        got = np.array([_seconds_after(o.epoch, tt0) for o in obs])
        assert np.max(np.abs(got - tag)) <= 1e-9, typ


def test_tdm_written_by_ccsds_ndm_is_read(tmp_path):
    """The same file written back by ccsds-ndm (its own KVN layout: aligned keywords, blank lines,
    its float formatting) is read by tqdyn: types, satellites, peers, sigmas and time tags exactly,
    values to the 1-ulp rounding of ccsds-ndm's km floats."""
    pytest.importorskip("ccsds_ndm")
    from ccsds_ndm.mapping import NDMFileFormats
    from ccsds_ndm.ndm_io import NdmIo

    meas = _table()
    path = write_measurements_tdm(tmp_path / "m.tdm", meas, epoch=EPOCH, time_scale="TT",
                                  satellite_names=["TQ1", "TQ2", "TQ3"])
    other = tmp_path / "ndm.tdm"
    NdmIo().to_file(NdmIo().from_path(path), NDMFileFormats.KVN, other)
    assert other.read_text() != path.read_text()
    fields, _ = read_measurements_tdm(other, epoch=EPOCH, time_scale="TT", grid_s=600.0)
    for f in ("t", "type", "sat", "peer", "sigma"):
        assert np.array_equal(fields[f], getattr(meas, f)), f
    assert np.allclose(fields["value"], meas.value, rtol=1.5e-15, atol=0)
