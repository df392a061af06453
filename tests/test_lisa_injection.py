"""The closed loop's tilt-to-length as a LISA Instrument injection file (``tqdyn export CL.h5 --format
lisa-injection OUT.h5 --run RUN.h5``; docs/lisa-ttl.md).

The chain (tools/lisa_ttl_chain.py): a 2-hour TianQin run, a 1800 s closed-loop series at 4 Hz, its LISA orbit
file and its injection file; LISA Instrument 2.3 (dt = 0.25 s, 3000 samples) and PyTDI 2.2 on them.
References: LISA Instrument's own readouts (difference of runs with and without the file) against tqdyn's
link TTL recomputed here from the closed-loop file, the trajectory's opening angles and the *orbit file's*
light travel times, converted by g = -(nu0/c) ds/dt with a degree-7 spline derivative (not the writer's
finite difference); PyTDI's linearity.  A few seconds per LISA Instrument run.
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

pytest.importorskip("lisainstrument")
pytest.importorskip("pytdi")
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tools"))

from lisa_ttl_chain import LINKS, make_files, simulate, x2_of  # noqa: E402

BAND = (0.01, 0.4)   # Hz: above 1/100 of the 750 s simulated, below fs/10 of the 4 Hz closed loop
NU0 = 2.816e14       # Hz: LISA Instrument 2.3's default central_freq
C = 299792458.0


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    import warnings

    warnings.filterwarnings("ignore")
    files = make_files(tmp_path_factory.mktemp("lisa-ttl"))
    runs = {(inj, laser): simulate(files["orbits"], files["injection"] if inj else None, laser=laser)
            for inj in (False, True) for laser in (False, True)}
    return files, runs


def _bandpass(x, band=BAND):
    """x (4 Hz) without its first 200 samples (LISA Instrument's start: filters and delays warming up),
    band-passed (8th-order Butterworth, forward and backward), without 400 samples at each end."""
    from scipy.signal import butter, sosfiltfilt

    return sosfiltfilt(butter(8, band, btype="bandpass", fs=4.0, output="sos"), np.asarray(x)[200:])[400:-400]


def _reference(files, times):
    """-(nu0/c) ds_ij/dt at ``times`` [Hz], s_ij from link_ttl on the closed-loop file's angles with the
    orbit file's light travel times."""
    import h5py
    from scipy.interpolate import make_interp_spline

    import tqdyn
    from tqdyn.analysis.ttl_budget import worst_case_coefficients
    from tqdyn.ttl.coupling import link_ttl
    from tqdyn.ttl.budget import ANGLE_OUTPUTS, mosa_angles_from_outputs
    from tqdyn.formats.closed_loop import read_closed_loop

    ts = read_closed_loop(files["closed_loop"]).timeseries(list(ANGLE_OUTPUTS))
    t = ts["time"].values
    outputs = {o: ts["values"].sel(output=o).values for o in ANGLE_OUTPUTS}
    traj = tqdyn.open_trajectory(files["run"])
    ang = np.asarray(traj["mosa/angle"])
    mid = int(np.argmin(np.abs(np.asarray(traj["t"]) - t.mean())))
    phi, eta = mosa_angles_from_outputs(outputs, ang[mid, :, 0] - ang[mid, :, 1])
    with h5py.File(files["orbits"]) as f:
        to = f.attrs["t0"] + f.attrs["dt"] * np.arange(f.attrs["size"])
        ltt = f["tcb/ltt"][:]
    delays = {m: np.interp(t, to, ltt[:, k]) for k, m in enumerate(LINKS)}
    s = link_ttl(phi, eta, worst_case_coefficients(), t[1] - t[0], delays)
    out = {}
    for m in LINKS:
        ok = np.isfinite(s[m])
        out[m] = -(NU0 / C) * make_interp_spline(t[ok], s[m][ok], k=7).derivative()(times)
    return out


def test_lisa_instrument_readouts_reproduce_the_ttl(chain, record_number):
    """LISA Instrument's science carrier readouts with the injection file minus without (every noise off)
    equal -(nu0/c) ds_ij/dt of tqdyn's link TTL delayed by the anti-aliasing filter's group delay, in
    0.01-0.4 Hz, to < 1e-3 relative (RMS of the difference over RMS of the reference, band-passed alike).
    Measured 4.2e-4, of which up to 3.4e-4 is the disagreement of the two derivative estimators of the
    4 Hz series (the reference's spline, the writer's 9-point difference) in this metric; the readouts
    match the file's own samples to 5.5e-5 (the spline interpolation to the 16 Hz physics grid, the filters).
    Also: the signal is there (the TTL's RMS is > 1e-7 Hz) and a sign flip or a one-sample shift fails."""
    files, runs = chain
    t, sci1, _, gd = runs[(True, False)]
    _, sci0, _, _ = runs[(False, False)]
    ref = _reference(files, t - gd)
    cut = slice(None)
    worst = 0.0
    for m in LINKS:
        a, b = _bandpass(sci1[m] - sci0[m])[cut], _bandpass(ref[m])[cut]
        assert np.std(b) > 1e-7
        rel = float(np.std(a - b) / np.std(b))
        worst = max(worst, rel)
        assert np.std(a + b) / np.std(b) > 1.9                           # the sign matters
        assert np.std(_bandpass(np.roll(sci1[m] - sci0[m], 1))[cut] - b) / np.std(b) > 1e-2   # and the time
    record_number("lisa_injection.readout_rel_error", worst)
    assert worst < 1e-3
    # docs/lisa-ttl.md's recipe (the same make_files and simulate calls; tests/test_docs_examples.py, slow): with
    # every noise off, X2 is zero without the injection file and not with it (only the TTL in X2)
    x2_1, x2_0 = runs[(True, False)][2], runs[(False, False)][2]
    ok = np.isfinite(x2_1) & np.isfinite(x2_0)
    ok[:100] = False
    assert np.std(x2_0[ok]) == 0 < np.std(x2_1[ok])


def test_x2_with_ttl_minus_without_is_the_x2_of_the_ttl(chain, record_number):
    """With laser noise on (same seed), X2 with the injection minus X2 without equals PyTDI's X2 of the
    injected TTL alone (the readouts' difference), to < 1e-6 of its RMS (float rounding of the laser noise,
    ~1e2 Hz in the raw beatnotes); and that X2 of the TTL equals PyTDI's X2 of tqdyn's reference TTL
    (readouts replaced by -(nu0/c) ds/dt) in band to < 3e-3 relative (measured 1.0e-3: the readout comparison's
    derivative-estimator difference, through the linear X2)."""
    files, runs = chain
    t, sci1, x2_1, gd = runs[(True, True)]
    _, sci0, x2_0, _ = runs[(False, True)]
    zeros = np.zeros_like(t)
    meas = {f"{k}_{m}": zeros for k in ("ref", "tmi") for m in LINKS}
    x2_ttl = x2_of(files["orbits"], {**meas, **{f"sci_{m}": sci1[m] - sci0[m] for m in LINKS}}, t[0] - gd)
    ok = np.isfinite(x2_ttl) & np.isfinite(x2_1) & np.isfinite(x2_0)
    ok[:100] = False
    lin = float(np.max(np.abs((x2_1 - x2_0 - x2_ttl)[ok])) / np.std(x2_ttl[ok]))
    assert np.std(x2_ttl[ok]) > 1e-8
    assert lin < 1e-6
    ref = _reference(files, t - gd)
    x2_ref = x2_of(files["orbits"], {**meas, **{f"sci_{m}": ref[m] for m in LINKS}}, t[0] - gd)
    cut = slice(None)
    a, b = _bandpass(np.nan_to_num(x2_ttl))[cut], _bandpass(np.nan_to_num(x2_ref))[cut]
    rel = float(np.std(a - b) / np.std(b))
    record_number("lisa_injection.x2_rel_error", rel)
    assert rel < 3e-3


def test_injection_enters_like_lisa_instruments_own_ttl(chain, tmp_path, record_number):
    """The derivation (tqdyn.ttl.injection): LISA Instrument with its own TTL (random coefficients,
    different for every MOSA; its angular jitters the only noise) and LISA Instrument with no jitter but the
    file -(nu0/c) link_ttl(its jitter velocities) at the readout_isi_carrier / _usb points (16 Hz, its physics
    grid; tqdyn's delays from the orbit file's light travel times) give the same science readouts: carrier and
    sideband, in 0.01-1 Hz to < 3e-5 relative (measured 9.6e-6: the omitted carrier offsets ~1e-7, the Lagrange
    delays, the spline of the file); the reference and test-mass interferometers see no TTL in either run.
    (link_ttl is linear with constant delays, so it maps velocities to ds/dt; the derivative is the other
    tests'.)"""
    import warnings

    import h5py
    from lisainstrument import Instrument

    from tqdyn.ttl.coupling import TTLCoefficients, link_ttl
    from tqdyn.formats.lisa_injection import write_lisa_injection

    files, _ = chain
    c = TTLCoefficients.random(7)
    kw = dict(orbits=str(files["orbits"]), size=3000, dt=0.25, lock="six", seed=3, telemetry_downsampling=100,
              delay_isc_min=0.5 * 0.578, delay_isc_max=1.5 * 0.578)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        own = Instrument(ttl_coeffs=(c.local_phi, c.distant_phi, c.local_eta, c.distant_eta), **kw)
        own.disable_all_noises(excluding="angular-jitters")
        ra = own.export_numpy_full()
        tp = np.asarray(ra.physics_t)
        with h5py.File(files["orbits"]) as f:
            to = f.attrs["t0"] + f.attrs["dt"] * np.arange(f.attrs["size"])
            ltt = f["tcb/ltt"][:]
        vel = {q: {m: np.asarray(getattr(ra.mosa_data, f"mosa_total_jitter_{q}s")[m]) for m in LINKS}
               for q in ("phi", "eta")}
        sd = link_ttl(vel["phi"], vel["eta"], c, tp[1] - tp[0],
                      {m: np.interp(tp, to, ltt[:, k]) for k, m in enumerate(LINKS)})
        g = {m: np.nan_to_num(-(NU0 / C) * sd[m]) for m in LINKS}
        path = write_lisa_injection(tmp_path / "own.h5", tp[0], tp[1] - tp[0],
                                    {f"{p}_{m}": g[m] for m in LINKS for p in ("readout_isi_carrier", "readout_isi_usb")})
        inj = Instrument(glitches=str(path), **kw)
        inj.disable_all_noises()
        rb = inj.export_numpy_full()
    worst = 0.0
    for kind in ("sci_carrier_fluctuations", "sci_usb_fluctuations"):
        for m in LINKS:
            a = _bandpass(getattr(ra.mosa_data, kind)[m], (0.01, 1.0))
            b = _bandpass(getattr(rb.mosa_data, kind)[m], (0.01, 1.0))
            assert np.std(a) > 1e-6
            worst = max(worst, float(np.std(a - b) / np.std(a)))
    for r in (ra, rb):
        for kind in ("ref_carrier_fluctuations", "tmi_carrier_fluctuations"):
            assert all(np.max(np.abs(getattr(r.mosa_data, kind)[m])) == 0.0 for m in LINKS)
    record_number("lisa_injection.own_ttl_rel_error", worst)
    assert worst < 3e-5


def test_tm_injection_enters_like_lisa_instruments_test_mass_noise(chain, tmp_path, record_number):
    """The test-mass point (tqdyn.ttl.injection): LISA Instrument with its own test-mass noise (the
    only noise) and LISA Instrument with no noise but that velocity (m/s, 16 Hz) at ``tm_ij`` give the same
    test-mass interferometer readouts, carrier and sideband (< 1e-12 relative RMS, full band; measured 4e-16:
    the spline of the file is exact at its samples), and the science interferometers see nothing of it."""
    import warnings

    from lisainstrument import Instrument

    from tqdyn.formats.lisa_injection import write_lisa_injection

    files, _ = chain
    kw = dict(orbits=str(files["orbits"]), size=3000, dt=0.25, lock="six", seed=4, telemetry_downsampling=100,
              delay_isc_min=0.5 * 0.578, delay_isc_max=1.5 * 0.578)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        own = Instrument(**kw)
        own.disable_all_noises(excluding="test-mass")
        ra = own.export_numpy_full()
        tp = np.asarray(ra.physics_t)
        v = {m: np.asarray(ra.mosa_data.testmass_noises[m]) for m in LINKS}
        path = write_lisa_injection(tmp_path / "tm.h5", tp[0], tp[1] - tp[0], {f"tm_{m}": v[m] for m in LINKS})
        inj = Instrument(glitches=str(path), **kw)
        inj.disable_all_noises()
        rb = inj.export_numpy_full()
    worst = 0.0
    for kind in ("tmi_carrier_fluctuations", "tmi_usb_fluctuations"):
        for m in LINKS:
            a = np.asarray(getattr(ra.mosa_data, kind)[m])[200:]
            b = np.asarray(getattr(rb.mosa_data, kind)[m])[200:]
            assert np.std(a) > 0
            worst = max(worst, float(np.std(a - b) / np.std(a)))
    for m in LINKS:
        assert np.max(np.abs(rb.mosa_data.sci_carrier_fluctuations[m])) == 0.0
    record_number("lisa_injection.tm_rel_error", worst)
    assert worst < 1e-12
