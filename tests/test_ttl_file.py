"""Time-varying TTL coefficients (tqdyn.ttl.coupling), LISA Instrument's TTL coefficient file
(tqdyn.formats.ttl) and ``tqdyn export CL.h5 --format ttl OUT.h5`` (docs/tilt-to-length.md).

References: LISA Instrument 2.3's own reader and writer (``lisainstrument.ttl``); analytic sines with
linearly drifting coefficients; LISA Instrument 2.3 itself run with a file written by tqdyn (its stored
angular jitters and its science carrier with and without TTL).
"""

from __future__ import annotations

import json
import math
import os
import warnings

import numpy as np
import pytest

from cli_support import run_cli
from tqdyn.ttl.coupling import (LINEAR_FIELDS, LPF_DRIFT_M_PER_RAD_PER_S, MOSAS, TimeVaryingTTLCoefficients,
                                  TTLCoefficients, distant_mosa, ttl_terms)

C_SI = 299792458.0


def _values(t, seed=1):
    """Per-MOSA coefficient series (m/rad) at t: c0 + r t + a sin(w t), distinct per MOSA and field."""
    rng = np.random.default_rng(seed)
    return {f: {m: rng.uniform(-2e-3, 2e-3) + rng.uniform(-1e-6, 1e-6) * t + 1e-4 * np.sin(t / 300.0 + rng.uniform())
                for m in MOSAS} for f in LINEAR_FIELDS}


# ---------------------------------------------------------------------------
# the file
# ---------------------------------------------------------------------------


def test_round_trip_through_lisa_instruments_reader(tmp_path):
    """A file written by tqdyn reads back bit for bit with LISA Instrument 2.3's ``load_ttl_file`` (and
    tqdyn's reader); a file written by LISA Instrument's ``create_ttl_file`` reads back bit for bit with
    tqdyn's reader.  The layout (attribute, dataset names) is therefore LISA Instrument's."""
    pytest.importorskip("lisainstrument")
    from lisainstrument.orbiting.constellation_enums import MosaID
    from lisainstrument.ttl.ttl_file_reader import load_ttl_file
    from lisainstrument.ttl.ttl_file_writer import create_ttl_file
    from lisainstrument.ttl.ttl_source_interp import TTLCoefficients as LiCoefficients

    from tqdyn.formats.ttl import read_ttl_file, write_ttl_file

    t = 1e5 + 7.3 * np.arange(257) + 1e-3 * np.sin(np.arange(257))
    v = _values(t)
    out = write_ttl_file(tmp_path / "ttl.h5", t, v, order=3, attrs={"source_file": "cl.h5"})
    li = load_ttl_file(out)
    assert li.order == 3 and np.array_equal(li.t_sample, t)
    for f, d in (("local_phi", li.c_ij_phi_rx), ("distant_phi", li.c_ij_phi_tx), ("local_eta", li.c_ij_eta_rx),
                 ("distant_eta", li.c_ij_eta_tx)):
        for m in MOSAS:
            assert np.array_equal(d[MosaID(m)], v[f][m]), (f, m)
    back = read_ttl_file(out)
    assert back.attrs["source_file"] == "cl.h5" and back.attrs["tqdyn_version"]
    assert all(np.array_equal(back.coefficients[f][m], v[f][m]) for f in LINEAR_FIELDS for m in MOSAS)

    create_ttl_file(LiCoefficients(t_sample=t, order=5, c_ij_phi_rx={MosaID(m): v["local_phi"][m] for m in MOSAS},
                                   c_ij_phi_tx={MosaID(m): v["distant_phi"][m] for m in MOSAS},
                                   c_ij_eta_rx={MosaID(m): v["local_eta"][m] for m in MOSAS},
                                   c_ij_eta_tx={MosaID(m): v["distant_eta"][m] for m in MOSAS}), tmp_path / "li.h5")
    theirs = read_ttl_file(tmp_path / "li.h5")
    assert theirs.order == 5 and np.array_equal(theirs.t, t)
    assert all(np.array_equal(theirs.coefficients[f][m], v[f][m]) for f in LINEAR_FIELDS for m in MOSAS)


def test_the_writer_is_atomic(tmp_path, monkeypatch):
    """An error or Ctrl-C in the middle of writing (the 7th dataset) leaves an existing file unchanged and
    no temporary file; an OSError (a full disk) becomes one-line OutputError; bad input is refused before
    anything is written."""
    import h5py

    from tqdyn.formats.trajectory import OutputError
    from tqdyn.formats.ttl import write_ttl_file

    t = np.arange(10.0)
    v = _values(t)
    out = tmp_path / "ttl.h5"
    out.write_bytes(b"old")
    real = h5py.Group.create_dataset
    for exc in (KeyboardInterrupt(), OSError(28, "No space left on device")):
        calls = {"n": 0}

        def failing(self, *a, _exc=exc, **k):
            calls["n"] += 1
            if calls["n"] == 7:
                raise _exc
            return real(self, *a, **k)

        monkeypatch.setattr(h5py.Group, "create_dataset", failing)
        with pytest.raises(KeyboardInterrupt if isinstance(exc, KeyboardInterrupt) else OutputError) as info:
            write_ttl_file(out, t, v)
        monkeypatch.setattr(h5py.Group, "create_dataset", real)
        assert out.read_bytes() == b"old" and sorted(os.listdir(tmp_path)) == ["ttl.h5"]
        if isinstance(exc, OSError):
            assert "No space left" in str(info.value) and "\n" not in str(info.value)
    bad = dict(v, local_phi=dict(v["local_phi"], **{"12": np.where(t > 5, np.nan, 0.0)}))
    with pytest.raises(ValueError, match=r"coefficients.local_phi\['12'\].*non-finite"):
        write_ttl_file(out, t, bad)
    with pytest.raises(ValueError, match="interpolation_order = 4"):
        write_ttl_file(out, t, v, order=4)
    assert out.read_bytes() == b"old"


# ---------------------------------------------------------------------------
# time-varying coefficients in ttl_terms
# ---------------------------------------------------------------------------


def test_drifting_coefficients_against_the_analytic_sine():
    """phi_m(t) = A sin(w t + p_m) with c(t) = c0 + r (t - t_ref): the local term equals c_ij(t) phi_ij(t)
    and the distant term c_ji(t - tau) phi_ji(t - tau) -- the distant coefficient at the emission time, as
    LISA Instrument 2.3 -- to round-off (the order-7 Lagrange error, (w dt)^8/8! ~ 1e-21 relative, is far
    below the reference's own: sin of a phase w t ~ 2e4 rad carries ~4e-12 relative, 4e-23 m here).
    The drift is 1e4 times LISA Pathfinder's so that c(t) and c(t - tau) differ (by r tau = 1e-8 m/rad,
    ~1e-5 relative): taking the distant coefficient at the reception time would fail the bound."""
    n, dt, t0, tau = 4000, 0.5, 1.2e6, 8.3
    t = t0 + dt * np.arange(n)
    w, amp = 2 * math.pi * 3e-3, 1e-8
    ph = {m: amp * np.sin(w * t + 0.3 * k) for k, m in enumerate(MOSAS)}
    et = {m: amp * np.cos(w * t + 0.7 * k) for k, m in enumerate(MOSAS)}
    base = TTLCoefficients.random(seed=4)
    r = 1e4 * LPF_DRIFT_M_PER_RAD_PER_S
    rate = {"local_phi": r, "local_eta": -r, "distant_phi": r, "distant_eta": -0.5 * r}
    c = TimeVaryingTTLCoefficients.drifting(base, rate, t_ref=t0 + 100.0)
    local, distant = ttl_terms(ph, et, c, dt, {m: tau for m in MOSAS}, t0=t0)
    coef = lambda f, m, tt: getattr(base, f)[m] + rate[f] * (tt - (t0 + 100.0))  # noqa: E731
    for k, m in enumerate(MOSAS):
        want = coef("local_phi", m, t) * ph[m] + coef("local_eta", m, t) * et[m]
        assert np.max(np.abs(local[m] - want)) < 1e-25                      # measured ~4e-27 m
        j, te = MOSAS.index(distant_mosa(m)), t - tau
        want_d = (coef("distant_phi", distant_mosa(m), te) * amp * np.sin(w * te + 0.3 * j)
                  + coef("distant_eta", distant_mosa(m), te) * amp * np.cos(w * te + 0.7 * j))
        ok = np.isfinite(distant[m])
        assert ok.sum() == n - 20 and np.max(np.abs(distant[m][ok] - want_d[ok])) < 2e-22    # measured 4e-23 m
        at_reception = (coef("distant_phi", distant_mosa(m), t) * amp * np.sin(w * te + 0.3 * j)
                        + coef("distant_eta", distant_mosa(m), t) * amp * np.cos(w * te + 0.7 * j))
        assert np.max(np.abs(at_reception[ok] - want_d[ok])) > 1e-17         # r tau phi: measured >= 4e-17 m


def test_temperature_and_series_models():
    """c(t) = c0 + k_T (T(t) - T_ref) with a temperature linear in t, and a sampled series that is a
    polynomial of degree <= the spline's: both are reproduced exactly by the splines (round-off: the
    spline through T ~ 293 K, ulp 6e-14 K, times 8e-6 m/rad/K gives a few 1e-19 m/rad per ulp); a
    temperature or series that does not cover the angles' span is refused in one line."""
    base = TTLCoefficients.constant(1e-3, -2e-3, 5e-4, 0.0)
    ts = np.linspace(0.0, 1e4, 41)
    c = TimeVaryingTTLCoefficients.thermal(base, 8e-6, ts, 293.0 + 2e-4 * ts)
    t = np.linspace(0.0, 1e4, 777)
    assert np.max(np.abs(c.coefficient("local_phi", "23", t) - (1e-3 + 8e-6 * 2e-4 * t))) < 1e-17   # measured 2.8e-18
    poly = {f: {m: 1e-3 + 1e-7 * ts - 3e-15 * ts ** 3 for m in MOSAS} for f in LINEAR_FIELDS}
    s = TimeVaryingTTLCoefficients.from_series(ts, poly, order=3)
    assert np.max(np.abs(s.coefficient("distant_eta", "21", t) - (1e-3 + 1e-7 * t - 3e-15 * t ** 3))) < 1e-15
    with pytest.raises(ValueError, match=r"ttl.temperature: covers t = 0.0 .. 10000.0 s; needed"):
        c.coefficient("local_phi", "12", np.array([2e4]))
    with pytest.raises(ValueError, match=r"ttl.series: 'local_psi' is not a key \(did you mean 'local_phi'\?\)"):
        TimeVaryingTTLCoefficients.from_series(ts, {"local_psi": {}})
    with pytest.raises(ValueError, match=r"ttl.rate\['12'\] = nan"):
        TimeVaryingTTLCoefficients.drifting(base, {m: (math.nan if m == "12" else 0.0) for m in MOSAS})
    with pytest.raises(ValueError, match="ttl.order = 4"):
        TimeVaryingTTLCoefficients(base=base, order=4)


# ---------------------------------------------------------------------------
# LISA Instrument 2.3 with a file written by tqdyn
# ---------------------------------------------------------------------------


def _instrument(ttl, n, dt, seed):
    from lisainstrument import Instrument

    zero3 = {s: 0.0 for s in "123"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ins = Instrument(orbits="static", t0=0.0, size=n, dt=dt, physics_upsampling=1, aafilter=None, lock="six",
                         seed=seed, ttl_coeffs=ttl, interpolation=("lagrange", 7), clock_freqoffsets=zero3,
                         clock_freqlindrifts=zero3, clock_freqquaddrifts=zero3)
        ins.disable_all_noises(excluding="angular-jitters")
        return ins.export_numpy_full()


def test_lisa_instrument_applies_tqdyns_file_as_tqdyn_does(tmp_path, record_number):
    """LISA Instrument 2.3 (static orbits, every noise off but its angular jitters, six lasers on
    cavities, no filter, order-7 Lagrange delays; 4000 samples at 4 Hz) run with a TTL file written by
    tqdyn whose coefficients drift across zero (c = c0 + r (t - 500 s), r = 2e-6 m/rad/s per MOSA
    and field: far larger than a real drift, so that the time of each coefficient matters).

    Reference: the TTL in its science carrier, (its sci carrier with that file - with zero coefficients)
    x -c / (nu0 + the emitting laser's offset) (both TTL terms of link ij ride on laser ji's carrier,
    ``instru_formulas.carrier_fluctuations`` / ``distant_carrier_fluctuations``), against tqdyn's
    ``ttl_terms`` with the same TimeVaryingTTLCoefficients applied to its stored MOSA angular jitters
    (``mosa_total_jitter_phis``/``_etas``).  LISA Instrument's jitters are angular velocities (rad/s) and
    its TTL a velocity c(t) dphi/dt; ``ttl_terms`` is linear in the angles, so fed with them it gives
    c(t) dphi/dt, LISA Instrument's quantity (tqdyn's displacement c phi differs from its integral by the
    integral of dc/dt phi, docs/tilt-to-length.md).  Compared in band 0.01-0.5 Hz (relative rms of the
    difference of the Hann-windowed DFTs in the band, worst link): measured 3.4e-15, bound 3e-14 (the
    requirement was 1e-3).  The same with the distant coefficient taken at the reception time is off by
    2.0e-2 (asserted > 1e-3): the file's coefficients are applied at the emission time."""
    pytest.importorskip("lisainstrument")
    from tqdyn.formats.ttl import write_ttl_file

    n, dt, seed = 4000, 0.25, 7
    tg = dt * np.arange(-1200, n + 1200)                           # LISA Instrument reads ~60 s either side
    base = TTLCoefficients.random(seed=11)
    c = TimeVaryingTTLCoefficients.drifting(base, 2e-6, t_ref=500.0)
    path = write_ttl_file(tmp_path / "ttl.h5", tg, {f: {m: c.coefficient(f, m, tg) for m in MOSAS}
                                                    for f in LINEAR_FIELDS})
    on = _instrument(("file", str(path)), n, dt, seed)
    zero = {m: 0.0 for m in MOSAS}
    off = _instrument((zero, zero, zero, zero), n, dt, seed)
    md = on.mosa_data
    nu0 = on.meta_data.central_freq
    phidot = {m: np.asarray(md.mosa_total_jitter_phis[m]) for m in MOSAS}
    etadot = {m: np.asarray(md.mosa_total_jitter_etas[m]) for m in MOSAS}
    tau = {m: float(np.mean(md.pprs[m])) for m in MOSAS}
    assert all(np.ptp(md.pprs[m]) == 0 for m in MOSAS)
    local, distant = ttl_terms(phidot, etadot, c, dt, tau, t0=0.0)
    # the wrong convention, for contrast: the distant coefficient taken at the reception time
    t = dt * np.arange(n)
    from tqdyn.ttl.coupling import _delay
    wrong = {m: c.coefficient("distant_phi", distant_mosa(m), t) * _delay(phidot[distant_mosa(m)], dt, tau[m])
             + c.coefficient("distant_eta", distant_mosa(m), t) * _delay(etadot[distant_mosa(m)], dt, tau[m])
             for m in MOSAS}
    skip = 200                                                      # the distant term's first ~tau/dt + 4 samples
    win = np.hanning(n - skip)
    f = np.fft.rfftfreq(n - skip, dt)
    band = (f > 0.01) & (f < 0.5)
    worst, worst_wrong = 0.0, 0.0
    for m in MOSAS:
        theirs = -(np.asarray(md.sci_carrier_fluctuations[m]) - np.asarray(off.mosa_data.sci_carrier_fluctuations[m]))
        theirs = theirs * C_SI / (nu0 + on.meta_data.offset_freqs[distant_mosa(m)])     # m/s
        ours = local[m] + distant[m]
        a, b = np.fft.rfft(win * theirs[skip:]), np.fft.rfft(win * ours[skip:])
        bw = np.fft.rfft(win * (local[m] + wrong[m])[skip:])
        ref = np.sqrt(np.sum(np.abs(a[band]) ** 2))
        worst = max(worst, float(np.sqrt(np.sum(np.abs(a[band] - b[band]) ** 2)) / ref))
        worst_wrong = max(worst_wrong, float(np.sqrt(np.sum(np.abs(a[band] - bw[band]) ** 2)) / ref))
        # its stored local TTL is tqdyn's local term bit for bit up to round-off
        assert np.max(np.abs(np.asarray(md.local_ttls[m]) - local[m])) < 1e-12 * np.max(np.abs(local[m]))
    record_number("ttl_file.lisainstrument_rel_diff_in_band", worst, "relative rms, 0.01-0.5 Hz")
    record_number("ttl_file.lisainstrument_rel_diff_reception_time", worst_wrong, "relative rms, 0.01-0.5 Hz")
    assert worst < 3e-14
    assert worst_wrong > 1e-3


# ---------------------------------------------------------------------------
# tqdyn export CL.h5 --format ttl OUT.h5
# ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def closed_loop_file(tmp_path_factory):
    """A small closed-loop file (synthetic series, 50 samples at 0.5 Hz from t0 = 3600 s; an empty-ish
    budget) written by tqdyn's ClosedLoopWriter: the export reads only its time grid and identity."""
    import xarray as xr

    from tqdyn.closedloop.simulate import Block
    from tqdyn.formats.closed_loop import ClosedLoopWriter

    p = tmp_path_factory.mktemp("ttl-cl") / "cl.h5"
    n = 50
    t = 3600.0 + 2.0 * np.arange(n)
    attrs = {"mission": "lisa", "source_file": "run.h5", "source_epoch_utc": "2035-01-01T00:00:00",
             "source_time_scale": "TT", "seed": 1, "fs": 0.5, "duration_s": 100.0, "n_samples": n, "t0": 3600.0,
             "satellite_names": json.dumps(["sc1", "sc2", "sc3"]), "configuration": "{}"}
    with ClosedLoopWriter(p, attrs) as w:
        w.start({"outputs": ["sc_attitude_x"], "n_sat": 3, "fs": 0.5, "n_samples": n, "t0": 3600.0, "units": {}})
        w.write(Block(t, np.zeros((n, 3, 1)), ("sc_attitude_x",)))
        w.write_budget(xr.Dataset({"total": (("frequency",), np.ones(3))}, coords={"frequency": [1e-3, 1e-2, 1e-1]}))
        w.close()
    return p


def test_export_ttl_writes_the_file(closed_loop_file, tmp_path, capsys):
    """The command samples the coefficients on the closed-loop file's grid (or --step over its span):
    worst-case coefficients are LISA Instrument's half-widths; --drift 1e-8 (m/rad per day) adds
    1e-8/86400 m/rad/s from the first sample; --coefficients FILE reads per-MOSA values; the root
    attributes identify the closed-loop file (its SHA-256)."""
    import hashlib

    from tqdyn.formats.ttl import read_ttl_file

    out = tmp_path / "ttl.h5"
    status, so, err = run_cli(["export", str(closed_loop_file), "--format", "ttl", str(out), "--drift", "lpf"], capsys)
    assert status in (0, None), err
    assert "50 samples from t = 3600 s to 3698 s" in so and "drifting 1e-08 m/rad per day" in so
    f = read_ttl_file(out)
    assert np.array_equal(f.t, 3600.0 + 2.0 * np.arange(50)) and f.order == 5
    want = 2.2e-3 + 1e-8 / 86400 * (f.t - 3600.0)
    assert np.max(np.abs(f.coefficients["local_eta"]["31"] - want)) < 1e-18
    assert np.max(np.abs(f.coefficients["distant_phi"]["12"] - (2.4e-3 + 1e-8 / 86400 * (f.t - 3600.0)))) < 1e-18
    assert f.attrs["source_sha256"] == hashlib.sha256(closed_loop_file.read_bytes()).hexdigest()
    model = json.loads(f.attrs["coefficient_model"])
    assert model["kind"] == "worst-case" and model["drift_m_per_rad_per_s"] == 1e-8 / 86400

    toml = tmp_path / "c.toml"
    toml.write_text("\n".join(f"[{k}]\n" + "\n".join(f'"{m}" = {1e-4 * (i + 1) * (j + 1)}' for j, m in enumerate(MOSAS))
                              for i, k in enumerate(LINEAR_FIELDS)))
    status, so, err = run_cli(["export", str(closed_loop_file), "--format", "ttl", str(out), "--coefficients",
                               str(toml), "--step", "20"], capsys)
    assert status in (0, None), err
    f = read_ttl_file(out)
    assert np.array_equal(f.t, [3600.0, 3620.0, 3640.0, 3660.0, 3680.0, 3698.0])
    assert np.all(f.coefficients["distant_phi"]["21"] == 1e-4 * 3 * 6)


@pytest.mark.parametrize("args, pattern", [
    (["--coefficients", "BAD.toml"], r"c.toml: 'local_psi' is not a key \(did you mean 'local_phi'\?\)"),
    (["--coefficients", "NAN.json"], r"ttl.local_phi\['13'\] = nan: must be a finite number"),
    (["--coefficients", "KEY.json"], r"ttl.distant_eta: '14' is not a key"),
    (["--coefficients", "random"], r"--seed: required with --coefficients random"),
    (["--seed", "3"], r"--seed: applies to --coefficients random only"),
    (["--drift", "fast"], r"--drift = 'fast': must be a finite number \(m/rad per day\) or lpf"),
    (["--step", "-1"], r"--step = -1.0: must be a finite number > 0"),
    (["--step", "30"], r"--step = 30.0: gives 5 samples over 3600 .. 3698 s; the spline of degree 5 needs more"),
    (["--frame", "gcrs"], r"--frame: does not apply to --format ttl"),
    (["TRAJ"], r"format = 'tqdyn-trajectory'.*expected format 'tqdyn-closed-loop'"),
    (["LISA"], r"format = 'tqdyn-closed-loop'.*expected format 'tqdyn-trajectory'"),
])
def test_export_ttl_refuses_bad_input(closed_loop_file, tmp_path, capsys, args, pattern):
    """Bad input: exit status 2, one line ``tqdyn: error: ...`` naming the field and value, and no file:
    an unknown MOSA or table, a non-finite coefficient, --seed without random, a bad drift or step, an
    option of another format, a trajectory file given to --format ttl, a closed-loop file to --format lisa."""
    import re

    from pathlib import Path

    (tmp_path / "c.toml").write_text('[local_psi]\n"12" = 1e-3\n')
    vals = {f: {m: 1e-3 for m in MOSAS} for f in LINEAR_FIELDS}
    (tmp_path / "nan.json").write_text(json.dumps(dict(vals, local_phi=dict(vals["local_phi"], **{"13": float("nan")}))))
    (tmp_path / "key.json").write_text(json.dumps(dict(vals, distant_eta=dict(vals["distant_eta"], **{"14": 0.0}))))
    files = {"BAD.toml": tmp_path / "c.toml", "NAN.json": tmp_path / "nan.json", "KEY.json": tmp_path / "key.json"}
    args = [str(files.get(a, a)) for a in args]
    src, fmt = str(closed_loop_file), "ttl"
    if args == ["TRAJ"]:
        src, args = str(Path(__file__).parent / "fixtures" / "trajectory-v1-tianqin.h5"), []
    elif args == ["LISA"]:
        fmt, args = "lisa", []
    out = tmp_path / "out.h5"
    status, so, err = run_cli(["export", src, "--format", fmt, str(out), *args], capsys)
    assert status == 2 and so == ""
    assert err.startswith("tqdyn: error: ") and err.count("\n") == 1, err
    assert re.search(pattern, err), err
    assert not out.exists() and not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]
