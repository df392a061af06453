"""The single-link TTL budget from the closed loop (tqdyn.ttl.budget, tqdyn.analysis.ttl_budget).

References: LISA Instrument 2.3's MOSA angle formulas (tqdyn.ttl.coupling.mosa_angles, itself checked
against LISA Instrument in tests/test_ttl.py) under the frame identification x_sc = X_S, z_sc = -Z_S; the
analytic ASD of a static single-input transfer (|sum_k c_k g_k| x ASD); the Welch estimate's own
statistics on a seeded closed-loop time series passed through tqdyn.ttl.coupling.link_ttl.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy import signal

from tqdyn.closedloop.loop import ClosedLoop, build_closed_loop, source_inputs
from tqdyn.closedloop.missions import default_controllers, default_noise, default_plant
from tqdyn.closedloop.noise import AsdModel
from tqdyn.closedloop.plant import PlantParameters, WorkingPoint
from tqdyn.closedloop.simulate import simulate
from tqdyn.ttl.coupling import MOSAS, TTLCoefficients, link_ttl, mosa_angles
from tqdyn.ttl.budget import ANGLE_OUTPUTS, angle_map, link_ttl_asd, mosa_angles_from_outputs
from tqdyn.constellation.spacecraft import Spacecraft


def test_angle_map_is_lisa_instruments_mosa_angles_with_the_s_frame_turned_about_x():
    """Random spacecraft and MOSA angle jitter at theta = 60 deg: the geometric map (optical axes from
    oa_rotation, z_m = -Z_S) equals ttl.mosa_angles (LISA Instrument's formulas, opening angles +-30 deg)
    fed roll = phi_x, pitch = -phi_y, yaw = -phi_z, MOSA yaw = -dth_l (module docstring); round-off."""
    rng = np.random.default_rng(1)
    out = {n: rng.normal(size=(7, 3)) for n in ANGLE_OUTPUTS}
    phi, eta = mosa_angles_from_outputs(out, math.pi / 3)
    sats = ("1", "2", "3")
    mosa_of = {"13": (0, 1), "12": (0, 2), "21": (1, 1), "23": (1, 2), "32": (2, 1), "31": (2, 2)}
    ref_phi, ref_eta = mosa_angles(
        {s: -out["sc_attitude_z"][:, i] for i, s in enumerate(sats)},
        {s: -out["sc_attitude_y"][:, i] for i, s in enumerate(sats)},
        {s: out["sc_attitude_x"][:, i] for i, s in enumerate(sats)},
        {m: -out[f"mosa_angle_{l}"][:, i] for m, (i, l) in mosa_of.items()},
        {m: np.zeros(7) for m in MOSAS})
    for m in MOSAS:
        assert np.max(np.abs(phi[m] - ref_phi[m])) < 1e-14
        assert np.max(np.abs(eta[m] - ref_eta[m])) < 1e-14
    # a rotation about MOSA 12's own optical axis (X_S turned by -30 deg) leaves its yaw and pitch at 0
    M = angle_map(math.pi / 3)
    axis = np.array([math.cos(-math.pi / 6), math.sin(-math.pi / 6), 0.0, 0.0, 0.0])
    assert abs(M[1, 0] @ axis) < 1e-15 and abs(M[1, 1] @ axis) < 1e-15


def _static_loop(gains: dict) -> ClosedLoop:
    """A ClosedLoop whose angle outputs are static gains of the star tracker's three inputs."""
    ins = source_inputs("star_tracker")
    D = np.zeros((len(ANGLE_OUTPUTS), 3))
    for (o, q), g in gains.items():
        D[ANGLE_OUTPUTS.index(o), q] = g
    sys = control.ss(np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((5, 0)), D, inputs=ins, outputs=list(ANGLE_OUTPUTS))
    return ClosedLoop(system=sys, channel_names=(), dc_force={})


def test_single_source_single_axis_is_the_coefficient_times_the_angle_asd():
    """Static transfers (analytic): yaw phi_12 = -phi_z, pitch eta_12 = sin(-30 deg) phi_x; ASD_12 =
    |c| ASD for yaw alone, |c|/2 for pitch alone, local and distant (other spacecraft) in quadrature, and
    phi and eta of one input add coherently: c_eta = -2 c_phi cancels (bound 1e-12 relative)."""
    f = np.logspace(-4, -1, 5)
    st = {"star_tracker": AsdModel(3e-6, ((1e-3, -1.0),), "rad", "st")}
    asd = st["star_tracker"].asd(f)
    yaw = [_static_loop({("sc_attitude_z", 2): 1.0})] * 3
    pitch = [_static_loop({("sc_attitude_x", 0): 1.0})] * 3
    both = [_static_loop({("sc_attitude_z", 0): 1.0, ("sc_attitude_x", 0): 1.0})] * 3
    c = 2.2e-3
    a, _ = link_ttl_asd(yaw, st, f, TTLCoefficients.constant(c, 0, 0, 0), math.pi / 3)
    np.testing.assert_allclose(a[0, 0], c * asd, rtol=1e-12)
    a, _ = link_ttl_asd(pitch, st, f, TTLCoefficients.constant(0, c, 0, 0), math.pi / 3)
    np.testing.assert_allclose(a[0, 0], 0.5 * c * asd, rtol=1e-12)
    a, _ = link_ttl_asd(yaw, st, f, TTLCoefficients.constant(c, 0, 2 * c, 0), math.pi / 3)
    np.testing.assert_allclose(a[0, 0], math.sqrt(5) * c * asd, rtol=1e-12)
    a, _ = link_ttl_asd(both, st, f, TTLCoefficients.constant(c, -2 * c, 0, 0), math.pi / 3)
    assert np.max(a[MOSAS.index("12"), 0]) < 1e-12 * c * np.max(asd)
    with pytest.raises(ValueError, match="quadratic") as e:
        q = TTLCoefficients(*({m: c for m in MOSAS} for _ in range(4)), local_phiphi={m: 1.0 for m in MOSAS})
        link_ttl_asd(yaw, st, f, q, math.pi / 3)
    assert "\n" not in str(e.value)


class _WPHolder:
    theta = math.pi / 3


_WP = _WPHolder()


def _lisa_loop():
    sc = Spacecraft.preset("lisa")
    d = default_plant("lisa")
    p = PlantParameters(sc_mass=d["sc_mass"], sc_inertia=d["sc_inertia"], tm_mass=d["tm_mass"], tm_side=d["tm_side"],
                        mosa_inertia=d["mosa_inertia"], mosa_stiffness=d["mosa_stiffness"],
                        stiffness=np.tile(d["stiffness"], (2, 1)),
                        rotational_stiffness=np.tile(d["rotational_stiffness"], (2, 1)), crosstalk=d["crosstalk"],
                        housing_centers=sc.housing_centers(math.pi / 3), lever_arms=sc.lever_arms(math.pi / 3),
                        sensitive_axes=sc.sensitive_axes_array)
    n2 = 4e-14
    wp = WorkingPoint(gamma=np.diag([2 * n2, -n2, -n2]), omega=np.array([0.0, 0.0, math.sqrt(n2)]),
                      omega_dot=np.zeros(3), theta=math.pi / 3, theta_dot=0.0,
                      a_suspension=np.array([[0.0, 1e-10, 5e-11], [0.0, -1e-10, -5e-11]]),
                      alpha_suspension=np.full((2, 3), 1e-13), a_dragfree=np.array([1e-11, 2e-11, 3e-11]),
                      self_gravity=np.full((2, 3), 5e-11))
    return build_closed_loop(p, wp, default_controllers("lisa"))


def test_link_ttl_of_a_closed_loop_time_series_agrees_with_the_budget_within_welch_statistics():
    """LISA's closed loop (three spacecraft, independent seeded noise, default sources), 1 Hz for 2^16 s;
    MOSA angles (mosa_angles_from_outputs) through ttl.link_ttl with random coefficients (seed 4) and
    tau = 8.3 s; the Welch ASD of link 12 over the continuous budget (link_ttl_asd; the series realise it
    band-limited to fs/2, cross-spectra included: docs/closed-loop.md) has mean 1 within 4 of its standard
    errors (Hann, 50 % overlap) from 10 Welch bins to 0.1 fs (above it the distant term's Lagrange delay,
    relative error (2 pi f dt)^8 / 8!, is not in the budget: 0.25 at 0.4 Hz).
    Measured: |mean - 1| = 0.036 (seeds 8-12: 0.0006-0.022), bound 0.061."""
    cl = _lisa_loop()
    noise = default_noise("lisa")
    fs, n, nper = 1.0, 2 ** 16, 2 ** 11
    snk = simulate([[(0.0, cl)]] * 3, noise, fs, n, seed=7)
    outs = list(snk.meta["outputs"])
    vals = {o: snk.values[:, :, outs.index(o)] for o in ANGLE_OUTPUTS}
    phi, eta = mosa_angles_from_outputs(vals, math.pi / 3)
    coeffs = TTLCoefficients.random(4)
    s = link_ttl(phi, eta, coeffs, 1 / fs, {m: 8.3 for m in MOSAS})["12"]
    s = s[np.isfinite(s)]
    f, pxx = signal.welch(s, fs=fs, nperseg=nper)
    a, _ = link_ttl_asd([cl] * 3, noise, f[1:], coeffs, math.pi / 3)
    pred = np.sum(a[0] ** 2, axis=0)
    band = (f[1:] > 10 * fs / nper) & (f[1:] < 0.1 * fs)
    r = pxx[1:][band] / pred[band]
    k = 2 * s.size / nper - 1
    sigma = math.sqrt(1.0 / (0.5 * k)) / math.sqrt(band.sum())
    assert abs(np.mean(r) - 1) < 4 * sigma + 0.01


def test_single_link_budget_dataset_and_its_tm_term():
    """single_link_budget on LISA's loop with version 0.3's noise (``defaults="v0.3"``): the TM term of a link at
    1 mHz is the two TMs' stray acceleration (LISA's requirement shape, 3e-15 sqrt(1 + (0.4 mHz/f)^2) sqrt(1 + (f/8 mHz)^4) each, drag-free
    suppresses the rest) in quadrature over (2 pi f)^2 (within 10 %); the requirement is LISA's 15 pm
    sqrt(1 + (2 mHz/f)^4); total = power sum of TTL, TM and readout (round-off)."""
    from tqdyn.closedloop.model import ClosedLoopModel
    from tqdyn.analysis.ttl_budget import single_link_budget

    cl = _lisa_loop()
    model = ClosedLoopModel(loops=[[(0.0, cl)]] * 3, noise=default_noise("lisa", "v0.3"), mission="lisa",
                            settings={"f_min": 1e-4, "f_max": 1.0, "n_freq": 41}, satellite_names=("1", "2", "3"),
                            t_span=(0.0, 1.0), parts=[[(None, cl_wp)] for cl_wp in [_WP] * 3])
    ds = single_link_budget(model)
    assert ds["ttl"].dims == ("link", "source", "frequency") and list(ds["link"].values) == list(MOSAS)
    f = ds["frequency"].values
    k = int(np.argmin(np.abs(f - 1e-3)))
    a = 3e-15 * math.sqrt(1 + (0.4e-3 / f[k]) ** 2) * math.sqrt(1 + (f[k] / 8e-3) ** 4)
    assert ds["tm_acceleration_total"].values[0, k] == pytest.approx(math.sqrt(2) * a / (2 * math.pi * f[k]) ** 2,
                                                                     rel=0.1)
    assert ds["requirement"].values[k] == pytest.approx(15e-12 * math.sqrt(1 + (2e-3 / f[k]) ** 4), rel=1e-12)
    tot = np.sqrt(ds["ttl_total"] ** 2 + ds["tm_acceleration_total"] ** 2 + ds["readout"] ** 2)
    np.testing.assert_allclose(ds["total"].values, tot.values, rtol=1e-12)


def test_link_ttl_asd_of_a_dynamic_loop_is_the_coefficients_times_python_controls_transfer():
    """LISA's closed loop (dynamic, all loops closed), DWS alone (4 inputs), random coefficients (seed 2):
    links 12 and 13 against the transfers evaluated by python-control's own ``frequency_response`` and
    the MOSA angles written out by hand (module docstring: phi = -(phi_z + dth_l), eta = sin(s_l theta/2)
    phi_x - cos(s_l theta/2) phi_y, s_1 = +1, s_2 = -1; link 12 = MOSA 2 of spacecraft 1 + MOSA 1 of
    spacecraft 2, link 13 = MOSA 1 of spacecraft 1 + MOSA 2 of spacecraft 3), |H_local|^2 + |H_distant|^2
    summed over the inputs, times the DWS ASD.  Relative agreement 1e-9 (measured: 0, python-control's LU
    solve per frequency is the one budget.frequency_response batches; the angle map and sums are independent)."""
    cl = _lisa_loop()
    noise = {"dws": default_noise("lisa")["dws"]}
    f = np.array([1e-4, 1e-3, 3e-3, 1e-2, 1e-1])
    theta = math.pi / 3
    coeffs = TTLCoefficients.random(2)
    a, sources = link_ttl_asd([cl] * 3, noise, f, coeffs, theta)
    assert sources == ["dws"]
    sys = cl.system
    oi = [sys.output_labels.index(o) for o in ANGLE_OUTPUTS]
    ii = [sys.input_labels.index(q) for q in source_inputs("dws")]
    sub = control.ss(sys.A, sys.B[:, ii], sys.C[oi, :], sys.D[np.ix_(oi, ii)])
    G = np.asarray(control.frequency_response(sub, 2 * math.pi * f).complex).reshape(5, 4, len(f))
    gx, gy, gz = G[0], G[1], G[2]

    def angles(l):                                        # (phi, eta) of MOSA l of any spacecraft: (4, n_f)
        s = 1.0 if l == 1 else -1.0
        return -(gz + G[2 + l]), math.sin(s * theta / 2) * gx - math.cos(s * theta / 2) * gy

    for link, (l_local, distant, l_distant) in {"12": (2, "21", 1), "13": (1, "31", 2)}.items():
        pl, el = angles(l_local)
        pd, ed = angles(l_distant)
        h_loc = coeffs.local_phi[link] * pl + coeffs.local_eta[link] * el
        h_dis = coeffs.distant_phi[distant] * pd + coeffs.distant_eta[distant] * ed
        ref = np.sqrt(np.sum(np.abs(h_loc) ** 2 + np.abs(h_dis) ** 2, axis=0)) * noise["dws"].asd(f)
        np.testing.assert_allclose(a[MOSAS.index(link), 0], ref, rtol=1e-9)


def test_link_budget_summary_against_an_analytic_budget():
    """A budget built by hand: link TTL 1e-13 (1 mHz / f) m/Hz^1/2 from one source (a second source at a
    tenth of it), readout flat 1e-12, no TM term, requirement flat 2e-12.  Analytic: the TTL exceeds the
    readout below 1e-4 sqrt(1.01) Hz (from the band's edge, 0.01 mHz, to the last grid point below it), the
    worst margin is at the band's lowest frequency, TTL / requirement there (1e-13 sqrt(1.01) x 100 / 2e-12
    = 5.02 at 0.01 mHz), the dominant source holds 100/101 of the TTL power, the allocation ratio is the
    largest TTL over 0.3 pm (bounds: exact grid points, 1e-12 relative)."""
    import xarray as xr

    from tqdyn.analysis.ttl_budget import link_budget_summary

    def budget(f):
        t = 1e-13 * (1e-3 / f)
        ttl = np.stack([t, 0.1 * t])[None].repeat(6, axis=0)
        tt = np.sqrt(np.sum(ttl ** 2, axis=1))
        ro = np.full((6, f.size), 1e-12)
        tot = np.sqrt(tt ** 2 + ro ** 2)
        S, F = ("link", "source", "frequency"), ("link", "frequency")
        return xr.Dataset({"ttl": (S, ttl), "ttl_total": (F, tt), "tm_acceleration_total": (F, np.zeros_like(tt)),
                           "readout": (F, ro), "total": (F, tot),
                           "requirement": (("frequency",), np.full(f.size, 2e-12)),
                           "margin": (F, 2e-12 / tot)},
                          coords={"link": list(MOSAS), "source": ["a", "b"], "frequency": f})

    f = np.logspace(-6, 0, 121)
    s = link_budget_summary(budget(f), budget(np.array([1e-3])), band=(0.99e-5, 1.0), allocation=0.3e-12)
    v = s["links"]["23"]
    f_cross = 1e-4 * math.sqrt(1.01)                       # 1e-13 sqrt(1.01) (1 mHz / f) = 1e-12
    lo, hi = f[f >= 0.99e-5][0], f[f < f_cross][-1]
    assert v["ttl_exceeds_readout_hz"] == [lo, hi] and lo == pytest.approx(1e-5) and hi == pytest.approx(1e-4)
    assert v["ttl_exceeds_readout_throughout"]
    assert v["worst_margin_f_hz"] == lo and v["worst_margin_limited_by"] == "ttl"
    t_max = 1e-13 * (1e-3 / lo) * math.sqrt(1.01)
    assert v["ttl_over_requirement_max"] == pytest.approx(t_max / 2e-12, rel=1e-12)
    assert v["ttl_over_allocation_max"] == pytest.approx(t_max / 0.3e-12, rel=1e-12)
    assert v["dominant_source"] == "a" and v["dominant_source_share"] == pytest.approx(100 / 101, rel=1e-12)
    assert v["ttl"] == [pytest.approx(1e-13 * math.sqrt(1.01), rel=1e-12)]
    assert s["frequencies_hz"] == [1e-3] and s["requirement"] == [2e-12]


def test_summary_refuses_a_band_outside_the_grid_and_bad_frequencies_in_one_line():
    from tqdyn.closedloop.model import ClosedLoopModel
    from tqdyn.analysis.ttl_budget import link_budget_summary, single_link_budget, ttl_budget_values

    cl = _lisa_loop()
    model = ClosedLoopModel(loops=[[(0.0, cl)]] * 3, noise=default_noise("lisa"), mission="lisa",
                            settings={"f_min": 1e-4, "f_max": 1.0, "n_freq": 11}, satellite_names=("1", "2", "3"),
                            t_span=(0.0, 1.0), parts=[[(None, w)] for w in [_WP] * 3])
    ds = single_link_budget(model)
    for call, match in ((lambda: link_budget_summary(ds, ds, band=(2.0, 3.0)), "band = "),
                        (lambda: link_budget_summary(ds, ds, allocation=-1.0), "allocation = "),
                        (lambda: ttl_budget_values(model, frequencies=(1e-3, 0.0)), "frequencies = ")):
        with pytest.raises(ValueError, match=match) as e:
            call()
        assert "\n" not in str(e.value)
