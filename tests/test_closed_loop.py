"""The closed-loop model (tqdyn.closedloop, tqdyn.analysis.closed_loop; docs/closed-loop.md).

References: the analytic closed-loop transfer functions of a one-degree-of-freedom loop
(S = 1/(1 + L), T = L/(1 + L), evaluated directly from C(s) and P(s) = 1/(s^2 + k)); the Welch
estimate's own statistics (chi^2 with the segments' degrees of freedom); the nominal control of real
coupled runs (tqdyn.propagate: the drag-free and suspension accelerations the compiled kernel
computes from the three control conditions); the published ASD shapes of the requirements.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from tqdyn.closedloop.budget import DesignError, check_stable, closed_loop_response, loop_margins, noise_budget
from tqdyn.closedloop.controllers import Controller, lead_lag_pid
from tqdyn.closedloop.loop import SOURCES, build_closed_loop, output_names
from tqdyn.closedloop.missions import (CONSTELLATION_MISSIONS, default_controllers, default_noise, default_plant,
                                      requirement)
from tqdyn.closedloop.noise import AsdModel, shaping_error
from tqdyn.closedloop.one_dof import one_dof_loop
from tqdyn.closedloop.plant import PlantParameters, WorkingPoint
from tqdyn.closedloop.simulate import simulate
from tqdyn.constellation.spacecraft import Spacecraft
from tqdyn.scenario import ScenarioError, load_scenario


def _model(mission, wp=None, **plant):
    sc = Spacecraft.preset(mission)
    d = {**default_plant(mission), **plant}
    p = PlantParameters(sc_mass=d["sc_mass"], sc_inertia=d["sc_inertia"], tm_mass=d["tm_mass"], tm_side=d["tm_side"],
                        mosa_inertia=d["mosa_inertia"], mosa_stiffness=d["mosa_stiffness"],
                        stiffness=np.tile(d["stiffness"], (2, 1)),
                        rotational_stiffness=np.tile(d["rotational_stiffness"], (2, 1)), crosstalk=d["crosstalk"],
                        housing_centers=sc.housing_centers(math.pi / 3), lever_arms=sc.lever_arms(math.pi / 3),
                        sensitive_axes=sc.sensitive_axes_array)
    if wp is None:
        n2 = 4e-10 if mission == "tianqin" else 4e-14
        wp = WorkingPoint(gamma=np.diag([2 * n2, -n2, -n2]), omega=np.array([0.0, 0.0, math.sqrt(n2)]),
                          omega_dot=np.zeros(3), theta=math.pi / 3, theta_dot=0.0,
                          a_suspension=np.array([[0.0, 1e-10, 5e-11], [0.0, -1e-10, -5e-11]]),
                          alpha_suspension=np.full((2, 3), 1e-13), a_dragfree=np.array([1e-11, 2e-11, 3e-11]),
                          self_gravity=np.full((2, 3), 5e-11))
    return p, wp


def test_one_dof_reproduces_the_analytic_sensitivity_and_complementary_sensitivity():
    """x/n_thr = -(1/M) P/(1 + L), x/n_s = -L/(1 + L) with L = C P, P = 1/(s^2 + k) (module docstring of
    tqdyn.closedloop.one_dof): the interconnected loop agrees to round-off (measured ~1e-15; bound 1e-6)."""
    c = lead_lag_pid(0.05)
    M, k = 2000.0, -1e-6
    cl = one_dof_loop(c, M, k)
    f = np.logspace(-6, 1, 200)
    s = 2j * math.pi * f
    L = c.tf()(s) / (s ** 2 + k)
    G = closed_loop_response(cl, f, ["x"], ["thruster_force[0]", "interferometer[0]"])
    assert np.max(np.abs(G[0, 0] / (-(1 / M) / (s ** 2 + k) / (1 + L)) - 1)) < 1e-6
    assert np.max(np.abs(G[0, 1] / (-L / (1 + L)) - 1)) < 1e-6
    m = loop_margins(cl)[0]
    # the design's crossover and its phase margin: arcsin((a-1)/(a+1)) - atan(1/r) = 54.9 - 5.7 deg
    assert m.f_phase_margin == pytest.approx(0.05, rel=1e-3)
    assert 45 < m.phase_margin < 52


def test_one_dof_time_domain_asd_agrees_with_the_budget_within_welch_statistics():
    """White thruster noise (1e-7 N/Hz^1/2) through the discretised loop, one day at 4 Hz: the Welch ASD over
    the discretised loop's predicted ASD has mean 1 within 4 of its standard errors (Hann, 50 % overlap)."""
    cl = one_dof_loop(lead_lag_pid(0.05), 2000.0, -1e-6)
    fs, n, nper = 4.0, 4 * 86400, 2 ** 14
    snk = simulate([[(0.0, cl)]], {"thruster_force": AsdModel(1e-7, (), "N", "n")}, fs, n, seed=3)
    f, pxx = signal.welch(snk.values[:, 0, 0], fs=fs, nperseg=nper)
    G = closed_loop_response(cl, f[1:], ["x"], ["thruster_force[0]"], dt=1 / fs)
    r = pxx[1:] / (np.abs(G[0, 0]) * 1e-7) ** 2
    band = f[1:] > 10 * fs / nper
    k = 2 * n / nper - 1                                 # segments (50 % overlap)
    sigma = math.sqrt(1.0 / (0.5 * k)) / math.sqrt(band.sum())   # Hann's effective dof ~ k (overlap)
    assert abs(np.mean(r[band]) - 1) < 4 * sigma + 0.01


@pytest.mark.parametrize("mission", CONSTELLATION_MISSIONS)
def test_default_designs_are_stable_with_margins_and_name_their_dominant_sources(mission):
    """Every loop channel of the default design: phase margin 40..60 deg near its design crossover (the
    lead-lag design gives 49 deg on 1/s^2); the budget names a largest source for every output and band."""
    p, wp = _model(mission)
    cl = build_closed_loop(p, wp, default_controllers(mission))
    check_stable(cl)
    for m in loop_margins(cl):
        assert 40 < m.phase_margin < 60, m
    f = np.logspace(-4, 0, 60)
    b, sources = noise_budget(cl, default_noise(mission), f)
    assert b.shape == (len(output_names()), len(sources), len(f))
    assert np.all(np.isfinite(b)) and np.all(b >= 0)
    i = output_names().index("tm1_acceleration")
    low = f < 3e-4
    # below the loops' bandwidths the residual acceleration is the TM force noise input
    assert sources[int(np.argmax(np.mean(b[i][:, low] ** 2, axis=1)))] == "tm_force"


def _margins_agree(cl, rel=1e-9):
    """Windowed loop_margins against python-control's stability_margins on the whole 1500-point grid
    (method="full"): every channel's margins and crossover frequencies, relative difference <= ``rel``
    (measured <= 6.2e-16 on the default designs and on a coupled run's working points: the interpolating
    spline of the FRD forgets points 16 grid points away by 0.27^16 = 1e-9 of its local error)."""
    full, win = loop_margins(cl, method="full"), loop_margins(cl)
    assert [m.channel for m in full] == [m.channel for m in win]
    for a, b in zip(full, win):
        for name in ("gain_margin", "phase_margin", "f_gain_margin", "f_phase_margin"):
            u, v = getattr(a, name), getattr(b, name)
            assert (math.isnan(u) and math.isnan(v)) or u == v or abs(u - v) <= rel * abs(u), (a, b, name)
        assert math.isfinite(a.phase_margin) and math.isfinite(a.f_phase_margin), a


@pytest.mark.parametrize("mission", CONSTELLATION_MISSIONS)
def test_windowed_margins_equal_the_full_grid_at_the_representative_working_point(mission):
    """tqdyn.closedloop.missions.representative_working_point (the first-principles working point) and the
    default design of each mission."""
    from tqdyn.closedloop.missions import representative_plant, representative_working_point

    _margins_agree(build_closed_loop(representative_plant(mission), representative_working_point(mission),
                                     default_controllers(mission)))


@pytest.mark.parametrize("mission", CONSTELLATION_MISSIONS)
def test_frequency_response_equals_python_control(mission):
    """closed_loop_response's batched solve against python-control's frequency_response (per-frequency
    solve, without slycot) on every output and input of the default design, continuous and zero-order-hold
    discretised (dt 0.25 s): difference <= 1e-10 of each transfer function's largest modulus (measured
    0: the same LAPACK gesv per frequency)."""
    import control

    from tqdyn.closedloop.budget import frequency_response

    p, wp = _model(mission)
    cl = build_closed_loop(p, wp, default_controllers(mission))
    sys = cl.system
    w = 2 * math.pi * np.logspace(-6, 0.3, 60)
    for s in (sys, control.c2d(sys, 0.25, method="zoh")):
        ref = np.asarray(control.frequency_response(s, w).complex)
        new = frequency_response(s, w)
        scale = np.max(np.abs(ref), axis=2, keepdims=True)
        assert np.all(np.abs(new - ref) <= 1e-10 * scale)
    with pytest.raises(ValueError, match="allowed: 'window', 'full'"):
        loop_margins(cl, method="spline")


def test_an_unstable_design_is_refused_naming_the_loop():
    """A suspension crossover far below the stiffness's unstable pole (sqrt(1e-6) rad/s = 0.16 mHz) cannot
    hold the TM: refused with the loop's name and its margins."""
    p, wp = _model("lisa")
    ctl = default_controllers("lisa")
    ctl["suspension"] = lead_lag_pid(1e-6, name="suspension")
    with pytest.raises(DesignError, match=r"^closed_loop\.controllers\.\w+: the closed loop is unstable") as e:
        check_stable(build_closed_loop(p, wp, ctl))
    assert "\n" not in str(e.value)


def test_improper_and_bad_controllers_and_noise_are_refused_in_one_line():
    for kw, pat in ((dict(zeros=(-1.0, -2.0), poles=(-1.0,), gain=1.0), "improper"),
                    (dict(zeros=(), poles=(1.0,), gain=1.0), "unstable pole"),
                    (dict(zeros=(), poles=(-1.0,), gain=-1.0), "positive")):
        with pytest.raises(ScenarioError, match=pat):
            Controller(name="dragfree", **kw)
    with pytest.raises(ScenarioError, match="negative ASD"):
        AsdModel(-1.0, (), "N", "closed_loop.noise.thruster_force")
    for over, pat in (("closed_loop.noise.thruster_force.level=-1", "negative ASD"),
                      ("closed_loop.noise.nonsense.level=1", "not a noise source"),
                      ("closed_loop.controllers.nonsense.gain=1", "not a loop"),
                      ("closed_loop.mission=hubble", "not a mission")):
        with pytest.raises(ScenarioError, match=pat) as e:
            load_scenario("tianqin", [over])
        assert "\n" not in str(e.value)


@pytest.mark.parametrize("model", [AsdModel(3e-15, ((4e-4, -1.0), (8e-3, 2.0))), AsdModel(1e-15, ((1e-4, -0.5),)),
                                   AsdModel(2.4e-9, ((1e-3, -1.0),))])
def test_shaping_filters_follow_the_asd_models(model):
    """The rational shaping filters of the published shapes (LISA's knees, TianQin's sqrt(1 + 0.1 mHz/f)):
    within 1 % of the model over [1e-6, 2] Hz (measured <= 0.44 %)."""
    assert shaping_error(model, 1e-6, 2.0) < 1e-2


def test_requirements_are_the_published_curves():
    """LISA 3e-15 sqrt(1 + (0.4 mHz/f)^2) sqrt(1 + (f/8 mHz)^4); TianQin 1e-15 sqrt(1 + 0.1 mHz/f)."""
    f = np.array([1e-4, 1e-3, 1e-2])
    assert np.allclose(requirement("lisa").asd(f), 3e-15 * np.sqrt(1 + (4e-4 / f) ** 2) * np.sqrt(1 + (f / 8e-3) ** 4))
    assert np.allclose(requirement("tianqin").asd(f), 1e-15 * np.sqrt(1 + 1e-4 / f))


def test_adding_a_source_leaves_the_other_realisations_unchanged():
    """One SeedSequence per (satellite, source): the interferometer-driven output is the same with or
    without thruster noise switched on, to round-off of the linear superposition."""
    cl = one_dof_loop(lead_lag_pid(0.05), 2000.0, 0.0)
    ifo = {"interferometer": AsdModel(1e-12, (), "m", "n")}
    a = simulate([[(0.0, cl)]], ifo, 4.0, 4000, seed=7).values
    both = simulate([[(0.0, cl)]], {**ifo, "thruster_force": AsdModel(1e-7, (), "N", "n")}, 4.0, 4000, seed=7).values
    thr = simulate([[(0.0, cl)]], {"thruster_force": AsdModel(1e-7, (), "N", "n")}, 4.0, 4000, seed=7).values
    assert np.max(np.abs(both - (a + thr))) <= 1e-9 * np.max(np.abs(both))


def test_streaming_blocks_equal_one_block():
    """The state carries across blocks: blocks of 1000 samples give the same series as one block."""
    p, wp = _model("tianqin")
    cl = build_closed_loop(p, wp, default_controllers("tianqin"))
    noise = default_noise("tianqin")
    a = simulate([[(0.0, cl)]], noise, 4.0, 3000, seed=1, block_size=1000).values
    b = simulate([[(0.0, cl)]], noise, 4.0, 3000, seed=1, block_size=3000).values
    assert np.max(np.abs(a - b)) <= 1e-9 * np.max(np.abs(b), axis=0).max()


@pytest.fixture(scope="module")
def tianqin_runs():
    import tqdyn

    over = {"run.duration": "2h", "integrator.step": 600}
    return (tqdyn.propagate("tianqin", over),
            tqdyn.propagate("tianqin", {**over, "spacecraft.self_gravity": "off"}))


def test_dc_limit_reproduces_the_nominal_split_of_a_coupled_run(tianqin_runs):
    """DC self-gravity (Table IV, the file's tm/self_gravity) injected as TM force noise at 1e-9 Hz: the
    loop's thrust / M and suspension / m equal the difference of the nominal control of two coupled runs
    (Table IV minus no self-gravity; compiled kernel, three control conditions) -- the signs and the
    split.  Difference: the loop includes the reaction of the suspension on the spacecraft (m/M =
    4e-3 of A), the nominal control does not; the bound is 2 m/M of |A|."""
    from tqdyn.closedloop.model import closed_loop_model

    with_sg, without = tianqin_runs
    model = closed_loop_model(with_sg)
    row = len(with_sg["t"]) // 2
    cl = model.loops[0][0][1]
    sg = with_sg["tm/self_gravity"][0]                              # (2, 3) OA_l
    G = closed_loop_response(cl, [1e-9], ["thrust_force_x", "thrust_force_y", "thrust_force_z"]
                             + [f"tm{l}_es_force_{a}" for l in (1, 2) for a in "xyz"],
                             [f"tm_force[{k}]" for k in range(6)])[:, :, 0].real
    out = G @ sg.reshape(6)
    T = with_sg["sat/T_S_I"][row, 0]
    dG = T @ (with_sg["sat/a_dragfree"][row, 0] - without["sat/a_dragfree"][row, 0])
    dA = with_sg["tm/a_suspension"][row, 0] - without["tm/a_suspension"][row, 0]
    M, m = default_plant("tianqin")["sc_mass"], default_plant("tianqin")["tm_mass"]
    tol = 2 * m / M * np.max(np.abs(dA))
    assert np.max(np.abs(out[:3] / M - dG)) < tol
    assert np.max(np.abs(out[3:].reshape(2, 3) / m - dA)) < tol


@pytest.mark.parametrize("sat", [0, 1, 2])
def test_windowed_margins_equal_the_full_grid_at_a_coupled_runs_working_point(tianqin_runs, sat):
    """The working points of a coupled TianQin run (tqdyn.propagate, Table IV self-gravity)."""
    from tqdyn.closedloop.model import closed_loop_model

    _margins_agree(closed_loop_model(tianqin_runs[0]).loops[sat][0][1])


def test_entry_point_refuses_a_pure_gravity_run():
    import tqdyn
    from tqdyn.closedloop.model import ClosedLoopError, closed_loop_model

    tr = tqdyn.propagate("tianqin-gravity", {"run.duration": "1h", "integrator.step": 600})
    with pytest.raises(ClosedLoopError, match="missing") as e:
        closed_loop_model(tr)
    assert "\n" not in str(e.value)


def _with_scenario(traj, text):
    """A shallow copy of the trajectory ``traj`` whose recorded scenario is ``text``."""
    import copy

    out = copy.copy(traj)
    out.scenario_toml = text
    return out


@pytest.mark.parametrize("config", [None, "given"])
def test_a_recorded_scenario_that_does_not_load_is_refused_in_one_line(tianqin_runs, config):
    """A run whose recorded scenario does not load (here an unknown key under [forces]) is refused in one
    line naming the trajectory and the key, whether the [closed_loop] settings come from that scenario
    (config None: they were replaced by the defaults) or are given (the gravity gradient was set to
    zero).  Reference: the key written into the text here."""
    from tqdyn.closedloop.model import ClosedLoopError, closed_loop_model
    from tqdyn.scenario.closed_loop import ClosedLoopConfig

    traj = tianqin_runs[0]
    assert "\n[forces]\n" in traj.scenario_toml
    bad = _with_scenario(traj, traj.scenario_toml.replace("\n[forces]\n", "\n[forces]\nnot_a_key = 1\n", 1))
    with pytest.raises(ClosedLoopError) as e:
        closed_loop_model(bad, None if config is None else ClosedLoopConfig())
    msg = str(e.value)
    assert msg.startswith("the in-memory trajectory: its recorded scenario does not load (forces.not_a_key)")
    assert "\n" not in msg and len(msg) <= 200


def test_a_file_whose_scenario_does_not_load_is_named(tianqin_runs, tmp_path):
    """The refusal names the file a trajectory was read from (its path); the error of the scenario's
    loader is one of TOML here (a truncated text)."""
    from tqdyn.closedloop.model import ClosedLoopError, closed_loop_model

    bad = _with_scenario(tianqin_runs[0], "[scenario\n")
    bad.path = tmp_path / "run.h5"
    with pytest.raises(ClosedLoopError, match=r"^'.*run\.h5': its recorded scenario does not load; allowed: "):
        closed_loop_model(bad)


def test_the_recorded_gravity_gradient_enters_the_working_point(tianqin_runs):
    """The working point's gravity gradient is the run's (Earth GM/r^3 ~ 4e-10 s^-2 at TianQin's 1e8 m,
    the largest eigenvalue 2 GM/r^3 of the point-mass tide), not zero."""
    from tqdyn.closedloop.model import closed_loop_model

    wp = closed_loop_model(tianqin_runs[0]).parts[0][0][1]
    ev = np.linalg.eigvalsh(0.5 * (wp.gamma + wp.gamma.T))
    assert ev[-1] == pytest.approx(2 * 3.986004415e14 / 1e8 ** 3, rel=0.01)


def test_the_closed_loop_settings_defaults_are_the_scenarios_table():
    """The model's settings without a [closed_loop] section are tqdyn.scenario.closed_loop.CLOSED_LOOP_KEYS'
    defaults, and docs/scenarios.md's table states the same values (the reference: the page)."""
    import pathlib
    import re

    from tqdyn.scenario.closed_loop import CLOSED_LOOP_KEYS, ClosedLoopConfig

    s = ClosedLoopConfig().settings()
    assert s == {k: d for k, (_kind, d) in CLOSED_LOOP_KEYS.items() if k != "mission"}
    page = (pathlib.Path(__file__).resolve().parent.parent / "docs" / "scenarios.md").read_text(encoding="utf-8")
    rows = dict(re.findall(r"^\| (`[^|]+`) \| ([^|]+) \|", page, flags=re.M))
    assert float(rows["`fs`"]) == s["fs"] and int(rows["`seed`"]) == s["seed"]
    assert [float(x) for x in rows["`f_min`, `f_max`, `n_freq`"].split(",")] == [s["f_min"], s["f_max"], s["n_freq"]]
    assert rows["`segment`"].strip() == '`"1d"`' and s["segment"] == 86400.0
    assert rows["`attitude_z_sensor`"].strip() == f'`"{s["attitude_z_sensor"]}"`'


@pytest.mark.parametrize("sensor", ["dws", "star_tracker"])
def test_the_interconnection_leaves_no_signal_unconnected(sensor):
    """python-control's own check of the named interconnection (unused_signals: every block input fed,
    every block output used) finds nothing, for both attitude-z sensors: no misnamed signal."""
    p, wp = _model("lisa")
    cl = build_closed_loop(p, wp, default_controllers("lisa"), sensor)
    assert cl.system.unused_signals() == ({}, {})


def test_entry_point_budget_and_series_are_xarray(tianqin_runs):
    from tqdyn.analysis.closed_loop import closed_loop_budget, closed_loop_timeseries
    from tqdyn.closedloop.model import closed_loop_model

    model = closed_loop_model(tianqin_runs[0])
    calls = []
    ds = closed_loop_budget(model, f=np.logspace(-4, 0, 20), progress=calls.append)
    assert calls == [1] * (len(model.loops) * len(model.loops[0]))
    assert ds["asd"].dims == ("segment", "sat", "output", "source", "frequency")
    assert set(ds["source"].values) == set(SOURCES)
    ts = closed_loop_timeseries(model, duration_s=600.0, fs=2.0)
    assert ts["values"].dims == ("time", "sat", "output") and ts["values"].shape[:2] == (1200, 3)


def test_design_numbers_dc_path_is_far_below_the_requirement():
    """tqdyn.analysis.closed_loop_paths.design_numbers() at the first-principles working points (Table IV
    self-gravity, DC suspension 8.4e-11 m/s^2): the DC self-gravity's path (1e-6 actuation noise x
    the DC force x 1e-3 cross-talk, ~1e-19 m/s^2/Hz^1/2 by that product) is below 1e-3 of the
    requirement at 1 mHz for every mission; the stiffness path is |K| x jitter."""
    from tqdyn.analysis.closed_loop_paths import design_numbers

    fresh = design_numbers()
    for m, v in fresh["missions"].items():
        assert v["actuation_force"][0] < 1e-3 * requirement(m).asd(1e-3)
        assert 1e-20 < v["actuation_force"][0] < 1e-18            # 1e-6 x 8.4e-11 x 1e-3 = 8.4e-20

