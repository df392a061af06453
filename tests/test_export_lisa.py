"""Tests of the LISA orbit-file export (tqdyn.workflows.export, tqdyn.formats.lisa, `tqdyn export`).

Input: a trajectory file written with tqdyn.formats.trajectory.TrajectoryWriter from
analytic two-body Kepler orbits (numpy, this file): 3 satellites on
a = 1e8 m, i = 74.5 deg, 120 deg apart, satellite 3 with e = 0.01, 4 hours
at 50 s, with test masses +-0.2 m along the track (their own Kepler orbits).

References:
(1) the analytic proper time of a Kepler orbit: with vis-viva,
    (GM/r + v^2/2)/c^2 = (2 GM/r - GM/(2a))/c^2 and int dt/r = (E - E0)/(n a)
    (E the eccentric anomaly); against the coordinate time TT, d tau/dTT =
    (1 - (GM/r + v^2/2)/c^2)/(1 - L_G) (TT = (1 - L_G) TCG), so delta_tau(t) =
    [L_G (t - t0) - (2 GM (E - E0)/(n a) - GM (t - t0)/(2 a))/c^2]/(1 - L_G) --
    for a circular orbit (L_G - 1.5 GM/(a c^2)) t/(1 - L_G);
(2) finite differences of the exported ltt / ppr for their rates;
(3) lisaorbits' own iterative light travel time (InterpolatedOrbits,
    Shapiro off) on the same satellite positions;
(4) lisainstrument (Instrument reading the file, a 400-sample simulation)
    and pytdi (Data.from_orbits) -- the readers the format is for.
(3) and (4) are skipped when the optional packages are not installed.
"""

from __future__ import annotations

import os
import warnings

import h5py
import numpy as np
import pytest

from tqdyn.astro.constants import L_G
from tqdyn.formats import trajectory as io
from tqdyn import lightpath as LP
from tqdyn.cli.export import export
from tqdyn.astro.constants import C_LIGHT
from tqdyn.constellation.indices import LINKS, Link
from tqdyn.formats.lisa import LISA_LINK_ORDER, write_lisa_orbits
from tqdyn.workflows.export import export_lisa

GM = 3.986004415e14  # m^3/s^2 (written into the scenario attribute, read back by the export)
A_M = 1e8
ECC = (0.0, 0.0, 0.01)
STEP = 50.0
N = 289  # 4 hours at 50 s
LINK_NAMES = ("12", "23", "31", "13", "32", "21")


def _kepler(e, m0, t):
    """Analytic two-body orbit (numpy float64): r, v, a (N, 3) and eccentric anomaly E (N,)."""
    inc, raan = np.radians(74.5), np.radians(211.6)
    n = np.sqrt(GM / A_M ** 3)
    M = m0 + n * t
    E = M.copy()
    for _ in range(30):
        E = E - (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
    cE, sE, b = np.cos(E), np.sin(E), np.sqrt(1 - e * e)
    den = 1 - e * cE
    p = np.stack([A_M * (cE - e), A_M * b * sE, 0 * E], -1)
    w = np.stack([-A_M * n * sE / den, A_M * n * b * cE / den, 0 * E], -1)
    cO, sO, ci, si = np.cos(raan), np.sin(raan), np.cos(inc), np.sin(inc)
    R = np.array([[cO, -sO * ci, sO * si], [sO, cO * ci, -cO * si], [0.0, si, ci]])  # argp = 0
    r, v = p @ R.T, w @ R.T
    return r, v, -GM * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3, E


def _m0(s):
    return 2 * np.pi * s / 3 + np.radians(30)


def _analytic_delta_tau(s, t):
    """Reference (1): delta_tau of satellite s (0-based) at times t, zero at t = 0."""
    n = np.sqrt(GM / A_M ** 3)
    E = _kepler(ECC[s], _m0(s), np.asarray(t, float))[3]
    E0 = _kepler(ECC[s], _m0(s), np.zeros(1))[3][0]
    t = np.asarray(t, float)
    return (L_G * t - (2 * GM * (E - E0) / (n * A_M) - GM * t / (2 * A_M)) / C_LIGHT ** 2) / (1 - L_G)


_ATTRS = {"scenario": f"[forces]\ngm_earth = {GM!r}\n", "epoch_utc": "2004-06-06T00:00:00", "precision": "dd",
          "step_s": STEP, "integrator": "analytic Kepler (test)", "pointing": "none", "control": "off"}


def _write_run(path, tms=True, n_sat=3):
    t = np.arange(N) * STEP
    R, V, A = (np.empty((N, n_sat, 3)) for _ in range(3))
    TR, TV, TA = (np.empty((N, n_sat, 2, 3)) for _ in range(3))
    for s in range(n_sat):
        R[:, s], V[:, s], A[:, s], _ = _kepler(ECC[s], _m0(s), t)
        for m, sgn in enumerate((1, -1)):
            TR[:, s, m], TV[:, s, m], TA[:, s, m], _ = _kepler(ECC[s], _m0(s) + sgn * 0.2 / A_M, t)
    z = np.zeros_like
    fields = ["t", "sat/r", "sat/v", "sat/a_gravity"] + (["tm/r", "tm/v", "tm/a"] if tms else [])
    rows = {"t": (t, z(t)), "sat/r": (R, z(R)), "sat/v": (V, z(V)), "sat/a_gravity": A}
    if tms:
        rows.update({"tm/r": (TR, z(TR)), "tm/v": (TV, z(TV)), "tm/a": TA})
    with io.TrajectoryWriter(path, _ATTRS, fields, n_sat=n_sat) as w:
        w.append(rows)
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("lisa")
    run_tm = _write_run(d / "run_tm.h5")
    run_sat = _write_run(d / "run_sat.h5", tms=False)
    s_tm = export_lisa(run_tm, d / "orbits_tm.h5")
    s_sat = export_lisa(run_sat, d / "orbits_sat.h5")
    return d, run_tm, run_sat, s_tm, s_sat


def _read(path):
    with h5py.File(path, "r") as f:
        return dict(f.attrs), {k: f[k][()] for k in ("tcb/x", "tcb/v", "tcb/a", "tcb/delta_tau", "tcb/n", "tcb/ltt",
                                                    "tcb/d_ltt", "tcb/ppr", "tcb/d_ppr", "tps/delta_t", "tps/ppr",
                                                    "tps/d_ppr", "tqdyn/ltt_lo")}


def test_layout(files):
    _, run_tm, _, s_tm, s_sat = files
    attrs, data = _read(s_tm.path)
    size = N - 1  # the first row has no emission time inside the trajectory: dropped
    assert s_tm.dropped_rows == 1 and s_tm.size == size and s_tm.source == "tm" and s_sat.source == "sat"
    assert attrs["version"] == "2.3" and isinstance(attrs["version"], str)
    assert attrs["t0"] == STEP and attrs["dt"] == STEP and attrs["size"] == size
    assert isinstance(attrs["t0"], np.floating) and isinstance(attrs["size"], np.integer)  # pytdi asserts np.number
    assert "GCRS" in attrs["frame"] and "TT seconds" in attrs["time_scale"] and attrs["gm_earth"] == GM
    assert "test masses" in attrs["ltt_endpoints"] and bool(attrs["ignore_shapiro"])
    assert "satellite centres" in _read(s_sat.path)[0]["ltt_endpoints"]
    for name, shape in (("tcb/x", (3, 3)), ("tcb/n", (6, 3)), ("tcb/ltt", (6,)), ("tcb/delta_tau", (3,)),
                        ("tps/ppr", (6,)), ("tps/delta_t", (3,))):
        assert data[name].shape == (size,) + shape
    assert all(np.all(np.isfinite(v)) for v in data.values())
    # link columns: LISA order "ij" = received by i from j, = tqdyn's Link order; the value
    # of column j is the light travel time of Link with that index, TM to TM
    assert tuple(int(ln) for ln in LINKS) == LISA_LINK_ORDER
    tr = io.read_trajectory(run_tm)
    lp = LP.light_travel_times(tr.dd("t"), tr.dd("tm/r"), tr.dd("tm/v"), tr["tm/a"])
    for ln in LINKS:
        j = LINK_NAMES.index(str(int(ln)))
        np.testing.assert_array_equal(data["tcb/ltt"][:, j], (lp.tau[0] + lp.tau[1])[1:, ln.index])
        # n points from the emitter (satellite ln.emitter) to the receiver
        d_er = data["tcb/x"][:, ln.receiver.index] - data["tcb/x"][:, ln.emitter.index]
        cos = np.einsum("ij,ij->i", data["tcb/n"][:, j], d_er) / np.linalg.norm(d_er, axis=-1)
        assert np.all(cos > 1 - 1e-9)
    np.testing.assert_allclose(np.linalg.norm(data["tcb/n"], axis=-1), 1.0, rtol=0, atol=1e-15)
    # TM to TM vs centre to centre: the TMs sit +-0.2 m along the track -> ~0.1-0.4 m / c
    diff = np.abs(data["tcb/ltt"] - _read(s_sat.path)[1]["tcb/ltt"]) * C_LIGHT
    assert 0.01 < diff.max() < 0.5


def test_proper_time_vs_analytic(files):
    # reference (1)
    _, _, _, s_tm, _ = files
    attrs, data = _read(s_tm.path)
    t = attrs["t0"] + np.arange(attrs["size"]) * attrs["dt"]
    assert attrs["t_init"] == 0.0
    worst = max(np.max(np.abs(data["tcb/delta_tau"][:, s] - _analytic_delta_tau(s, t))) for s in range(3))
    print(f"\nproper time vs analytic Kepler: {worst:.2e} s (|delta_tau| up to "
          f"{np.max(np.abs(data['tcb/delta_tau'])):.2e} s)")
    assert worst < 1e-19
    np.testing.assert_allclose(data["tcb/delta_tau"][:, 0], (L_G - 1.5 * GM / (A_M * C_LIGHT ** 2)) * t / (1 - L_G),
                               rtol=1e-12)
    # ppr = ltt + delta_tau_recv(t) - delta_tau_emit(t - ltt), emitter clock from the analytic formula
    ltt = data["tcb/ltt"] + data["tqdyn/ltt_lo"]
    worst = 0.0
    for j, name in enumerate(LINK_NAMES):
        rcv, emt = int(name[0]) - 1, int(name[1]) - 1
        ref = _analytic_delta_tau(rcv, t) - _analytic_delta_tau(emt, t - ltt[:, j])
        worst = max(worst, np.max(np.abs((data["tcb/ppr"][:, j] - data["tcb/ltt"][:, j]) - ref)))
    print(f"ppr - ltt vs analytic clocks: {worst:.2e} s")
    assert worst < 3e-16  # s: float64 rounding of ppr ~ 0.58 s (ulp 1.1e-16 s)


def test_rates_vs_finite_differences(files):
    # reference (2): fourth-order central differences (truncation h^4 x^(5) / 30, rounding
    # ~3e-18 s/s from the float64 samples)
    _, _, _, s_tm, _ = files
    _, data = _read(s_tm.path)

    def fd(x):
        return (-x[4:] + 8 * x[3:-1] - 8 * x[1:-3] + x[:-4]) / (12 * STEP)

    err_ltt = np.max(np.abs(fd(data["tcb/ltt"]) - data["tcb/d_ltt"][2:-2]))
    # d_ppr is per unit receiver proper time: d ppr/dt = d_ppr (1 + d delta_tau_recv/dt)
    rate_r = np.gradient(data["tcb/delta_tau"], STEP, axis=0)[:, [int(n[0]) - 1 for n in LINK_NAMES]]
    err_ppr = np.max(np.abs(fd(data["tcb/ppr"]) - (data["tcb/d_ppr"] * (1 + rate_r))[2:-2]))
    print(f"\nd_ltt vs FD: {err_ltt:.2e} s/s; d_ppr vs FD: {err_ppr:.2e} s/s "
          f"(rates up to {np.max(np.abs(data['tcb/d_ltt'])):.1e} s/s)")
    assert err_ltt < 1e-16 and err_ppr < 1e-16
    # the clocks make the PPR rate differ from the LTT rate (~1e-14 s/s here)
    assert np.max(np.abs(data["tcb/d_ppr"] - data["tcb/d_ltt"])) > 1e-15


def test_tps_sampling(files):
    # coordinate time t of proper time tau = t_k: for the circular satellites delta_tau = -K t
    # (K = (1.5 GM/(a c^2) - L_G)/(1 - L_G), reference (1)), so t = t_k / (1 - K) and
    # delta_t = K t_k / (1 - K);
    # the PPR there is ppr(t_k) + delta_t * dppr/dt, dppr/dt from finite differences of tcb/ppr
    _, _, _, s_tm, _ = files
    attrs, data = _read(s_tm.path)
    t = attrs["t0"] + np.arange(attrs["size"]) * attrs["dt"]
    K = (1.5 * GM / (A_M * C_LIGHT ** 2) - L_G) / (1 - L_G)
    for s in (0, 1):
        np.testing.assert_allclose(data["tps/delta_t"][:, s], K * t / (1 - K), rtol=1e-9, atol=1e-22)
    shift = data["tps/ppr"] - data["tcb/ppr"]
    fdp = np.gradient(data["tcb/ppr"], STEP, axis=0, edge_order=2)
    worst = 0.0
    for j, name in enumerate(LINK_NAMES):
        rcv = int(name[0]) - 1
        if rcv == 2:
            continue
        worst = max(worst, np.max(np.abs(shift[:, j] - K * t / (1 - K) * fdp[:, j])))
    print(f"\ntps/ppr shift vs reference: {worst:.2e} s (shift up to {np.max(np.abs(shift)):.2e} s)")
    assert worst < 3e-16


def test_ltt_vs_lisaorbits(files):
    # reference (3): lisaorbits' iterative light travel time on the same satellite states
    lisaorbits = pytest.importorskip("lisaorbits")
    _, _, run_sat, _, s_sat = files
    attrs, data = _read(s_sat.path)
    tr = io.read_trajectory(run_sat)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        orb = lisaorbits.InterpolatedOrbits(tr["t"], tr["sat/r"], tr["sat/v"], tt_method="iterative", tt_niter=6,
                                            ignore_shapiro=True)
        t = attrs["t0"] + np.arange(attrs["size"]) * attrs["dt"]
        ltt = orb.compute_ltt(t)
    worst = np.max(np.abs(ltt - data["tcb/ltt"]))
    print(f"\nltt vs lisaorbits InterpolatedOrbits (iterative, float64): {worst:.2e} s")
    assert worst < 2e-15  # s: float64 arithmetic and spline interpolation in lisaorbits


def test_lisainstrument_reads_and_simulates(files):
    # reference (4): lisainstrument reads the file (both datasets) and runs 400 samples;
    # the PPRs it integrates from d_ppr match a spline of the exported samples
    pytest.importorskip("lisainstrument")
    from lisainstrument import Instrument
    from scipy.interpolate import make_interp_spline

    _, _, _, s_tm, _ = files
    attrs, data = _read(s_tm.path)
    t = attrs["t0"] + np.arange(attrs["size"]) * attrs["dt"]
    for dataset, values in (("tps/ppr", data["tps/ppr"]), ("tcb/ltt", data["tcb/ltt"])):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            instru = Instrument(orbits=str(s_tm.path), orbit_dataset=dataset, size=400, dt=0.25,
                                physics_upsampling=1, aafilter=None, lock="six", telemetry_downsampling=400,
                                delay_isc_min=0.3, delay_isc_max=1.0)  # TianQin: ~0.58 s, not LISA's ~8.3 s
            res = instru.export_numpy_full()
        assert res.t.shape == (400,) and res.t[0] == attrs["t0"] + 75.0  # lisainstrument's default t0 margin
        worst = 0.0
        for j, name in enumerate(LINK_NAMES):
            ref = make_interp_spline(t, values[:, j], 5)(res.t)
            worst = max(worst, np.max(np.abs(res.mosa_data.pprs[name] - ref)))
        print(f"\nlisainstrument ({dataset}): PPR vs exported samples {worst:.2e} s")
        assert worst < 1e-14
        for name in LINK_NAMES:
            assert np.all(np.isfinite(res.mosa_data.sci_carrier_fluctuations[name]))


def test_pytdi_reads_delays(files):
    pytest.importorskip("pytdi")
    from pytdi import Data
    from scipy.interpolate import make_interp_spline

    _, _, _, s_tm, _ = files
    attrs, data = _read(s_tm.path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = Data.from_orbits(str(s_tm.path), fs=4.0, t0=200.0, sci_12=np.zeros(100))
    t = attrs["t0"] + np.arange(attrs["size"]) * attrs["dt"]
    tq = 200.0 + np.arange(100) / 4.0
    for j, name in enumerate(LINK_NAMES):
        np.testing.assert_allclose(d.delays[f"d_{name}"], make_interp_spline(t, data["tps/ppr"][:, j], 5)(tq),
                                   rtol=0, atol=1e-15)


# ------------------------------------------------------------------ writer

def _minimal(n=5):
    t = np.arange(n) * 10.0
    z3, z6 = np.zeros((n, 3)), np.full((n, 6), 0.5)
    ones = np.ones((n, 3, 3))
    return {"t": t, "x": ones, "v": ones, "a": ones, "ltt": z6, "d_ltt": z6 * 0, "n": np.ones((n, 6, 3)) / np.sqrt(3),
            "ppr": z6, "d_ppr": z6 * 0, "delta_tau": z3, "tps_ppr": z6, "tps_d_ppr": z6 * 0, "tps_delta_t": z3}


def test_writer_validation(tmp_path):
    out = tmp_path / "o.h5"
    kw = _minimal()
    bad = dict(kw, ltt=np.zeros((5, 5)))
    with pytest.raises(ValueError, match=r"tcb/ltt: shape \(5, 5\), expected \(5, 6\)"):
        write_lisa_orbits(out, **bad)
    nan = kw["ppr"].copy()
    nan[3, 2] = np.nan
    with pytest.raises(ValueError, match=r"tcb/ppr: non-finite value at index \(3, 2\)"):
        write_lisa_orbits(out, **dict(kw, ppr=nan))
    t = kw["t"].copy()
    t[2] += 0.01
    with pytest.raises(ValueError, match="uniform grid"):
        write_lisa_orbits(out, **dict(kw, t=t))
    with pytest.raises(ValueError, match="reserved"):
        write_lisa_orbits(out, **kw, attrs={"t0": 1.0})
    with pytest.raises(io.OutputError, match="does not exist"):
        write_lisa_orbits(tmp_path / "nope" / "o.h5", **kw)
    assert os.listdir(tmp_path) == []
    path = write_lisa_orbits(out, **kw, attrs={"note": "x", "flag": True})
    with h5py.File(path) as f:
        assert f.attrs["version"] == "2.3" and f.attrs["size"] == 5 and f.attrs["dt"] == 10.0
        assert f["tcb/ltt"].attrs["units"] == "s"


def test_writer_is_atomic(tmp_path, monkeypatch):
    out = tmp_path / "o.h5"
    out.write_bytes(b"previous content")
    calls = []
    real = h5py.Group.create_dataset

    def failing(self, name, *a, **k):
        calls.append(name)
        if len(calls) == 3:
            raise RuntimeError("disk full (simulated)")
        return real(self, name, *a, **k)

    monkeypatch.setattr(h5py.Group, "create_dataset", failing)
    with pytest.raises(RuntimeError, match="simulated"):
        write_lisa_orbits(out, **_minimal())
    assert out.read_bytes() == b"previous content"  # untouched
    assert sorted(os.listdir(tmp_path)) == ["o.h5"]  # no temporary file left


# ------------------------------------------------------------------ command line

def _cli(argv, capsys):
    """`tqdyn export ...` in-process: through tqdyn.cli once the command is registered there,
    else the click command itself (same error convention).  Returns (status, stdout, stderr)."""
    from tqdyn import cli

    try:
        if "export" in getattr(cli.cli, "commands", {}):
            status = cli.main(["export", *argv])
        else:
            export.main(args=list(argv), prog_name="tqdyn export", standalone_mode=False)
            status = 0
    except SystemExit as exc:
        status = exc.code
    out = capsys.readouterr()
    return status, out.out, out.err


def test_cli_export(files, tmp_path, capsys):
    _, run_tm, _, _, _ = files
    out = tmp_path / "cli.h5"
    status, stdout, err = _cli([str(run_tm), "--format", "lisa", str(out)], capsys)
    assert status == 0, err
    assert "288 samples" in stdout and "test mass" in stdout
    with h5py.File(out) as f:
        assert f.attrs["version"] == "2.3" and f["tcb/ltt"].shape == (288, 6)


def _one_line_error(status, err, *words):
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("tqdyn: error: "), err
    for w in words:
        assert w in lines[0], lines[0]


def test_cli_bad_input(files, tmp_path, capsys):
    _, run_tm, _, _, _ = files
    out = tmp_path / "o.h5"
    _one_line_error(*_cli([str(run_tm), "--format", "csv", str(out)], capsys)[::2], "--format", "'csv'", "lisa")
    _one_line_error(*_cli([str(run_tm), str(out)], capsys)[::2], "--format is required", "lisa")
    _one_line_error(*_cli([str(tmp_path / "missing.h5"), "--format", "lisa", str(out)], capsys)[::2],
                    "missing.h5", "does not exist")
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    _one_line_error(*_cli([str(junk), "--format", "lisa", str(out)], capsys)[::2], "junk.h5")
    one = _write_run(tmp_path / "one.h5", tms=False, n_sat=1)
    _one_line_error(*_cli([str(one), "--format", "lisa", str(out)], capsys)[::2], "n_sat = 1", "3 satellites")
    _one_line_error(*_cli([str(run_tm), "--format", "lisa", str(tmp_path / "no" / "o.h5")], capsys)[::2],
                    "does not exist")
    _one_line_error(*_cli([str(one), "--format", "lisa", str(one)], capsys)[::2], "input")
    assert not out.exists()
    assert sorted(os.listdir(tmp_path)) == ["junk.h5", "one.h5"]


def test_link_enum_matches_lisa_convention():
    # LISA: link "12" is received by spacecraft 1 from spacecraft 2 (lisaorbits.utils.receiver/emitter)
    assert Link.L12.receiver == 1 and Link.L12.emitter == 2
    assert [str(int(ln)) for ln in LINKS] == list(LINK_NAMES)
