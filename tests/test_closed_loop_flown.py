"""LISA Pathfinder and TianQin-1 as closed-loop configurations, against what flew
(docs/closed-loop-validation.md, sections 4-6).

References (typed from the papers' abstracts into src/tqdyn/data/flight_results.toml, each with its paper):

* LISA Pathfinder's Delta g: the Brownian floor 1.74 fm s^-2/Hz^1/2 above 2 mHz (Armano et al. 2018, PRL 120,
  061101), the sub-mHz tail 1.1 fm s^-2/Hz^1/2 x (1 mHz/f) (Armano et al. 2024, arXiv:2405.05207), the readout
  34.8 fm/Hz^1/2 (Armano et al. 2016, PRL 116, 231101), combined in quadrature as the papers' noise model.
* LISA Pathfinder's stability near 1 mHz in six degrees of freedom and the star tracker's effect below
  (Armano et al. 2019, PRD 99, 082001).
* TianQin-1: 5e-11 m s^-2/Hz^1/2 at 10 mHz against 2e-9 thruster noise (Xiao et al. 2022, CQG 39, 155001);
  3e-9 m s^-2/Hz^1/2 at 0.1 Hz with drag-free control, thrust noise 0.3 uN/Hz^1/2 at 0.1 Hz (Luo et al. 2020, CQG
  37, 185013).

The other references are analytic (the loop formulas named in each test).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tqdyn.closedloop.budget import check_stable, loop_margins
from tqdyn.closedloop.flight_observables import (STABILITY_DOF, delta_g_budget, residual_acceleration_budget,
                                                 stability_budget)
from tqdyn.closedloop.flown import published_delta_g, published_flight_results
from tqdyn.closedloop.model import ClosedLoopError, static_closed_loop_model

PUB = published_flight_results()


@pytest.fixture(scope="module")
def lpf():
    m = static_closed_loop_model("lpf")
    return m, m.loops[0][0][1], m.parts[0][0][0]


@pytest.fixture(scope="module")
def tq1():
    m = static_closed_loop_model("tianqin-1")
    return m, m.loops[0][0][1]


def test_lpf_is_stable_with_its_loops_at_their_design_crossovers(lpf):
    """The collinear geometry (two TMs on X_S, 376 mm apart) is controlled: every pole in the left half plane
    (but the orbit displacement), every channel's phase margin that of the lead-lag design on 1/s^2
    (49.2 deg, controllers.py) within 3 deg, at a crossover within 5 % of its design frequency."""
    from tqdyn.closedloop.flown import FLOWN_CROSSOVER_HZ, flown_plant, flown_noise, lpf_design

    m, cl, _p = lpf
    check_stable(cl)
    design = {**FLOWN_CROSSOVER_HZ["lpf"], **lpf_design(flown_noise("lpf"), flown_plant("lpf"))}
    for mg in loop_margins(cl):
        assert abs(mg.phase_margin - 49.2) < 3.0, mg
        assert mg.f_phase_margin == pytest.approx(design[mg.channel.split("[")[0]], rel=0.05), mg


def test_lpf_delta_g_reproduces_the_published_curve_over_1_to_30_mhz(lpf, record_number):
    """Delta g of the full six-DOF loop (the flight estimator o12'' + k2 o12 + (k2 - k1) o1 - g2) against the
    published curve: within 2 % over 1-30 mHz (acceptance: 10 %; measured 0.7 %).  The TM force noise and the
    readout are the published terms themselves (inputs); what the loop adds (the other sources: star tracker
    through the guidance forces and the cross-talk, capacitive sensing, thrusters) is below 3 % of the power
    (measured 1.4 %)."""
    m, cl, p = lpf
    f = np.logspace(-3, math.log10(3e-2), 60)
    b, sources = delta_g_budget(cl, p, m.noise, f)
    total = np.sqrt(np.sum(b ** 2, axis=0))
    ref = published_delta_g(f, PUB)
    dev = np.abs(total / ref - 1)
    own = np.array([j for j, s in enumerate(sources) if s not in ("tm_force", "interferometer")])
    share = np.sum(b[own] ** 2, axis=0) / total ** 2
    assert np.max(dev) < 0.02
    assert np.max(share) < 0.03
    fq = np.array([1e-3, 3e-3, 1e-2, 3e-2])
    bq = np.sqrt(np.sum(delta_g_budget(cl, p, m.noise, fq)[0] ** 2, axis=0))
    record_number("closed_loop_flown.lpf_dg_max_rel_dev", float(np.max(dev)), "")
    record_number("closed_loop_flown.lpf_dg_model", bq.tolist(), "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.lpf_dg_published", published_delta_g(fq, PUB).tolist(), "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.lpf_dg_loop_share_max", float(np.max(share)), "")
    record_number("closed_loop_flown.lpf_dg_loop_largest", sources[int(own[np.argmax(np.max(b[own], axis=1))])], "")


def test_lpf_stability_in_six_dof_near_1_mhz(lpf, record_number):
    """The spacecraft's acceleration w.r.t. its geodesic at 1 mHz against PRD 99, 082001: Y, Z, Theta, Eta within
    a factor 2 (measured 1.17, 1.75, 1.61, 1.23: the capacitive readout through the drag-free and attitude loops,
    the spacecraft following the TMs).  Two are derived instead, each within 10 %, and lie outside the factor 2
    (docs derive why):

    * X, where the spacecraft follows TM 1: sqrt(2) x TM 1's own acceleration noise (the drag-free design rule
      puts the thrusters' share equal to it), 2.1e-15 against the published 5.0e-15 (ratio 0.44);
    * Phi: with the DFACS ICD's inertia (Z the smallest, 191.7 kg m^2) Z is the attitude design rule's most
      demanding axis, so at 1 mHz the thrusters' and the star tracker's shares about Z both equal the readout's,
      w^2 sqrt(2) n_cap / L (w = 2 pi 1 mHz, n_cap the capacitive readout at 1 mHz, L the separation): sqrt(3) x
      that, 6.2e-13 against the published 3e-13 (ratio 2.1).

    With the project's generic crossovers instead (50 / 20 mHz) the thrusters set X, Eta and Phi (the loop gain
    at 1 mHz is too low)."""
    m, cl, _p = lpf
    f = np.array([1e-3])
    st, _s = stability_budget(cl, m.noise, f)
    pub = PUB["lpf"]["stability"]
    model = {d: float(np.sqrt(np.sum(st[d] ** 2))) for d in STABILITY_DOF}
    ratio = {d: model[d] / pub[d] for d in STABILITY_DOF}
    for d in ("Y", "Z", "Theta", "Eta"):
        assert 0.5 < ratio[d] < 2.0, (d, ratio[d])
    a_tm1 = float(m.noise["tm_force"].asd(1e-3))
    assert model["X"] == pytest.approx(math.sqrt(2) * a_tm1, rel=0.10)
    readout = (2 * math.pi * 1e-3) ** 2 * math.sqrt(2) * float(m.noise["capacitive_translation"].asd(1e-3)) / 0.376
    assert model["Phi"] == pytest.approx(math.sqrt(3) * readout, rel=0.10)
    record_number("closed_loop_flown.lpf_stability_model", [model[d] for d in STABILITY_DOF], "SI/Hz^1/2")
    record_number("closed_loop_flown.lpf_stability_published", [pub[d] for d in STABILITY_DOF], "SI/Hz^1/2")
    record_number("closed_loop_flown.lpf_stability_ratio", [ratio[d] for d in STABILITY_DOF], "")
    record_number("closed_loop_flown.lpf_x_tm1_force_noise", a_tm1, "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.lpf_attitude_readout_1mhz", readout, "rad s^-2/Hz^1/2")
    # the same loop with the project's generic crossovers (drag-free 50 mHz, attitude 20 mHz) instead of the
    # design rule: the thrusters then set every DOF at 1 mHz (the loop gain there is too low)
    from tqdyn.closedloop.controllers import lead_lag_pid
    from tqdyn.closedloop.loop import build_closed_loop

    p, wp = m.parts[0][0]
    ctl = {**m.controllers, "dragfree": lead_lag_pid(0.05, name="dragfree"), "attitude": lead_lag_pid(0.02, name="a")}
    gen, gs = stability_budget(build_closed_loop(p, wp, ctl, scheme="collinear"), m.noise, f)
    record_number("closed_loop_flown.lpf_stability_generic_design",
                  [float(np.sqrt(np.sum(gen[d] ** 2))) for d in STABILITY_DOF], "SI/Hz^1/2")
    assert all(gs[int(np.argmax(gen[d][:, 0]))] in ("thruster_force", "thruster_torque") for d in ("X", "Eta", "Phi"))


def test_lpf_star_tracker_limits_the_attitude_below_1_mhz(lpf, record_number):
    """Below 1 mHz the star tracker, through the guidance loop, is the largest source of the stability about Y
    and Z (Eta, Phi) at every frequency from 0.05 to 0.7 mHz, and the totals there exceed the TMs' sensing
    contribution alone (the flight floor's continuation) by a factor >= 1.4 (measured: the star tracker's
    term is flat in acceleration, (2 pi f)^2 |T_g| n_st with |T_g| ~ f^-2, while the sensing falls as f)."""
    m, cl, _p = lpf
    f = np.logspace(math.log10(5e-5), math.log10(7e-4), 12)
    st, sources = stability_budget(cl, m.noise, f)
    i_st = sources.index("star_tracker")
    rise = {}
    for d in ("Eta", "Phi"):
        b = st[d]
        assert np.all(np.argmax(b, axis=0) == i_st), d
        sensing = np.hypot(b[sources.index("capacitive_translation")], b[sources.index("capacitive_rotation")])
        rise[d] = np.sqrt(np.sum(b ** 2, axis=0)) / sensing
        assert np.min(rise[d]) > 1.4, d
    fq = np.array([1e-4, 3e-4, 1e-3])
    sq, _ = stability_budget(cl, m.noise, fq)
    record_number("closed_loop_flown.lpf_phi_model_0p1_0p3_1mhz", np.sqrt(np.sum(sq["Phi"] ** 2, axis=0)).tolist(),
                  "rad s^-2/Hz^1/2")
    record_number("closed_loop_flown.lpf_eta_model_0p1_0p3_1mhz", np.sqrt(np.sum(sq["Eta"] ** 2, axis=0)).tolist(),
                  "rad s^-2/Hz^1/2")
    record_number("closed_loop_flown.lpf_star_tracker_rise_at_0p05mhz", [float(rise["Eta"][0]), float(rise["Phi"][0])],
                  "")


def test_lpf_guidance_design_rule_holds_at_1_mhz(lpf, record_number):
    """The guidance crossover is chosen so that the star tracker's share of the attitude about Z at 1 mHz equals
    the TMs' sensing share (flown.lpf_design, on the pure 1/s^2 plant): in the full loop the two agree within
    20 % (measured ratio, star tracker over sensing)."""
    m, cl, _p = lpf
    st, sources = stability_budget(cl, m.noise, np.array([1e-3]))
    b = st["Phi"][:, 0]
    r = float(b[sources.index("star_tracker")] / b[sources.index("capacitive_translation")])
    assert 0.8 < r < 1.25
    record_number("closed_loop_flown.lpf_guidance_share_ratio", r, "")
    record_number("closed_loop_flown.lpf_design_crossovers_hz",
                  [_crossover(m.controllers[k]) for k in ("dragfree", "attitude", "guidance")],
                  "Hz")


def _crossover(c):
    """|C(i w)| / w^2 = 1 (the design's crossover on 1/s^2) [Hz], by bisection on log f."""
    lo, hi = -9.0, 2.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        s = 2j * math.pi * 10 ** mid
        L = c.gain * np.prod(s - np.array(c.zeros)) / np.prod(s - np.array(c.poles)) / s ** 2
        lo, hi = (mid, hi) if abs(L) > 1 else (lo, mid)
    return 10 ** lo


def test_lpf_orbit_around_l1_does_not_reach_the_loop(lpf, record_number):
    """The static working point against one without the tide (Sun 4.1e-14, Earth 1.2e-13 s^-2) and one without
    the yearly turn (2e-7 rad/s): Delta g and the six stabilities at 0.1, 1, 10 mHz change by less than 1e-5
    (tide: second order, Gamma/(2 pi f)^2 <= 8e-7 at 0.1 mHz; measured 1.2e-6) and 1e-4 (rotation: first
    order through the Coriolis and gyroscopic terms, Omega/(2 pi f) <= 3.2e-4 at 0.1 mHz; measured 3.2e-5)."""
    import dataclasses

    from tqdyn.closedloop.loop import build_closed_loop

    m, cl, p = lpf
    wp = m.parts[0][0][1]
    f = np.array([1e-4, 1e-3, 1e-2])

    def totals(c):
        out = [np.sqrt(np.sum(delta_g_budget(c, p, m.noise, f)[0] ** 2, axis=0))]
        st = stability_budget(c, m.noise, f)[0]
        return np.array(out + [np.sqrt(np.sum(st[d] ** 2, axis=0)) for d in STABILITY_DOF])

    ref = totals(cl)
    worst = {}
    for name, w in (("tide", dataclasses.replace(wp, gamma=np.zeros((3, 3)))),
                    ("rotation", dataclasses.replace(wp, omega=np.zeros(3)))):
        other = totals(build_closed_loop(p, w, m.controllers, scheme="collinear"))
        worst[name] = float(np.max(np.abs(ref / other - 1)))
    assert worst["tide"] < 1e-5 and worst["rotation"] < 1e-4, worst
    record_number("closed_loop_flown.lpf_orbit_effect_max_rel", [worst["tide"], worst["rotation"]], "")
    record_number("closed_loop_flown.lpf_tide_s2", float(np.max(np.abs(np.linalg.eigvalsh(wp.gamma)))), "s^-2")


def test_tianqin1_residual_acceleration_at_10_mhz(tq1, record_number):
    """TianQin-1's measured acceleration (the servo's command) along X at 10 mHz: the thruster noise times the
    drag-free PI loop's sensitivity |1/(1 + C(i w))| (flat plant: the servo's bandwidth is 10x higher) within
    2 %, and that against the published 5e-11 m s^-2/Hz^1/2 (Xiao et al. 2022): the default loop (50 mHz, the
    project's drag-free crossover) gives 9.7e-10, 19x the published (outside the factor 2; the published ratio
    to the thruster noise, 1/40, is the flight loop's sensitivity, not in the sources used; docs derive it)."""
    m, cl = tq1
    check_stable(cl)
    pub = PUB["tianqin-1"]["residual_acceleration"]
    f = np.array([pub["f_hz"]])
    b, sources = residual_acceleration_budget(cl, m.noise, f)
    total = float(np.sqrt(np.sum(b ** 2)))
    c = m.controllers["dragfree"]
    s = 2j * math.pi * f[0]
    C = c.gain * np.prod(s - np.array(c.zeros)) / np.prod(s - np.array(c.poles))
    thr = float(m.noise["thruster_force"].asd(f[0])) / m.parts[0][0][0].sc_mass
    assert thr == pytest.approx(pub["thruster_noise"], rel=1e-12)
    assert total == pytest.approx(abs(1 / (1 + C)) * thr, rel=0.02)
    assert sources[int(np.argmax(b[:, 0]))] == "thruster_force"
    record_number("closed_loop_flown.tq1_residual_10mhz", total, "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.tq1_ratio_to_published", total / pub["value"], "")
    record_number("closed_loop_flown.tq1_sensitivity_10mhz", float(abs(1 / (1 + C))), "")
    record_number("closed_loop_flown.tq1_published_sensitivity", pub["value"] / pub["thruster_noise"], "")
    # for scale: the crossover of an integrator-dominated PI (zero at its crossover) with the published |S|
    from scipy.optimize import brentq

    from tqdyn.closedloop.controllers import pi_controller

    def excess(lf):
        c = pi_controller(10 ** lf, integrator_ratio=1.0)
        return abs(1 / (1 + c.gain * (s - c.zeros[0]) / s)) - pub["value"] / pub["thruster_noise"]

    fc = 10 ** brentq(excess, -2.5, 1.0)
    record_number("closed_loop_flown.tq1_implied_crossover_hz", fc, "Hz")
    # the same loop at 0.1 Hz (Luo et al. 2020's point): |S| there, for the docs' comparison of loop types
    c = pi_controller(fc, integrator_ratio=1.0)
    s1 = 2j * math.pi * 0.1
    record_number("closed_loop_flown.tq1_implied_sensitivity_0p1hz", float(abs(1 / (1 + c.gain * (s1 - c.zeros[0]) / s1))),
                  "")


def test_tianqin1_residual_acceleration_at_0_1_hz(tq1, record_number):
    """TianQin-1's measured acceleration along X at 0.1 Hz against the first round's residual with drag-free
    control, 3e-9 m s^-2/Hz^1/2 at 0.1 Hz (Luo et al. 2020, CQG 37, 185013): the model is the thruster noise
    (2e-9, Xiao et al. 2022) times the PI loop's |1/(1 + C(i w))| = 0.50 within 10 % (the flat-plant formula
    neglects the 0.5 Hz servo, a few % at 0.1 Hz; measured 1.05), i.e. 1.0e-9, 0.35 of the published value:
    below it by more than the factor 2 (the published residual exceeds the quoted thruster noise, which a loop
    with |S| = 0.5 cannot give; docs derive it).  Also recorded: the same loop with the first round's thrust noise,
    0.3 uN/Hz^1/2 over the configuration's 35 kg (the thruster term scales with the thrust noise)."""
    m, cl = tq1
    fr = PUB["tianqin-1"]["first_round"]
    f = np.array([0.1])
    b, sources = residual_acceleration_budget(cl, m.noise, f)
    total = float(np.sqrt(np.sum(b ** 2)))
    c = m.controllers["dragfree"]
    s = 2j * math.pi * f[0]
    sens = float(abs(1 / (1 + c.gain * np.prod(s - np.array(c.zeros)) / np.prod(s - np.array(c.poles)))))
    sc_mass = m.parts[0][0][0].sc_mass
    thr = float(m.noise["thruster_force"].asd(f[0])) / sc_mass
    assert total == pytest.approx(sens * thr, rel=0.10)
    assert sources[int(np.argmax(b[:, 0]))] == "thruster_force"
    ratio = total / fr["with_dfc_at_0p1hz"]
    assert 0.25 < ratio < 0.5
    record_number("closed_loop_flown.tq1_residual_0p1hz", total, "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.tq1_ratio_to_published_0p1hz", ratio, "")
    record_number("closed_loop_flown.tq1_sensitivity_0p1hz", sens, "")
    with_luo = total * (fr["thrust_noise_at_0p1hz"] / sc_mass) / thr
    record_number("closed_loop_flown.tq1_residual_0p1hz_luo_thrust", with_luo, "m s^-2/Hz^1/2")
    record_number("closed_loop_flown.tq1_ratio_0p1hz_luo_thrust", with_luo / fr["with_dfc_at_0p1hz"], "")


def test_a_geometry_the_scheme_cannot_control_is_refused_in_one_line():
    """The constellation scheme (DWS pitches of two MOSAs) on LISA Pathfinder's collinear TMs, and the collinear
    scheme on LISA's 60-degree axes: one line naming closed_loop.scheme and what is allowed (before: a bare
    LinAlgError from the constellation's geometry solve); a single-spacecraft geometry key on a constellation
    mission likewise (closed_loop.plant.tm_separation)."""
    from tqdyn.scenario.loader import closed_loop_config

    for table in ({"mission": "lpf", "scheme": "constellation"}, {"mission": "lisa", "scheme": "collinear"},
                  {"mission": "tianqin-1", "scheme": "collinear"}):
        with pytest.raises(ClosedLoopError) as exc:
            static_closed_loop_model(closed_loop_config(table))
        text = str(exc.value)
        assert text.startswith("closed_loop.scheme:") and "allowed:" in text and "\n" not in text, text
        assert len(text) < 300
    with pytest.raises(ClosedLoopError, match=r"^closed_loop.plant.tm_separation: .* allowed: the single-spacecraft"):
        static_closed_loop_model(closed_loop_config({"mission": "lisa", "plant": {"tm_separation": 0.3}}))


def test_the_command_writes_a_missions_static_working_point_and_refuses_bad_input(tmp_path, capsys):
    """``tqdyn closed-loop --mission lpf``: a closed-loop file of one spacecraft whose budget's channels are the
    collinear scheme's (15) and whose source attributes are empty; bad input (a controller missing its gain, a
    loop the scheme does not have, both or neither of RUN.h5 and --mission, an unknown mission, a --set mission
    other than --mission) exits 2 with one line naming the key, and writes nothing."""
    from cli_support import run_cli

    from tqdyn.formats.closed_loop import read_closed_loop

    out = tmp_path / "lpf.h5"
    small = ["--set", "closed_loop.n_freq=8", "--duration", "60", "--fs", "1", "-q"]
    status, _o, err = run_cli(["closed-loop", "--mission", "lpf", "--output", str(out), *small], capsys)
    assert status == 0, err
    f = read_closed_loop(out)
    assert f.attrs["mission"] == "lpf" and f.attrs["source_file"] == "" and f.configuration["working_point"] == "static"
    assert len(f.budget["channel"]) == 15 and f.budget["total"].shape[:2] == (1, 1)
    bad = [["--mission", "lpf", "--set", "closed_loop.controllers.guidance.zeros=[-1e-5]",
            "--set", "closed_loop.controllers.guidance.poles=[0, -1e-4]"],
           ["--mission", "lpf", "--set", "closed_loop.controllers.mosa.gain=1"],
           ["--mission", "tianqin-1", "--set", "closed_loop.scheme=constellation"],
           [str(out), "--mission", "lpf"], [], ["--mission", "lpf-2"],
           ["--mission", "lpf", "--set", "closed_loop.mission=lisa"]]
    keys = ["closed_loop.controllers.guidance.gain", "closed_loop.controllers.mosa", "closed_loop.scheme", "RUN.h5",
            "RUN.h5", "--mission", "closed_loop.mission"]
    for argv, key in zip(bad, keys):
        target = tmp_path / "bad.h5"
        status, _o, err = run_cli(["closed-loop", *argv, "--output", str(target), *small], capsys)
        lines = err.strip().splitlines()
        assert status == 2 and len(lines) == 1 and key in lines[0] and "allowed" in lines[0], (argv, err)
        assert not target.exists()
