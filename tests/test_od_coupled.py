"""Orbit determination of coupled runs (tqdyn.od.coupled through tqdyn.od.problem): the common
self-gravity of each satellite's test masses estimated from tracking, its partials by the coupled
variational equations (tqdyn.od.coupled_variational) or central differences of double-double
coupled runs.

References: the point-mass variational equations of tqdyn.od.variational (float64, checked there
against dd differences) on tianqin-gravity, for the sensitivity of a drag-free orbit to its TMs'
DC acceleration; the normal distribution of the estimation errors of a least-squares estimate with
Gaussian noise (Tapley, Schutz & Born, "Statistical Orbit Determination", 2004, section 4.3:
x_hat - x ~ N(0, P)), for the recovery; the differences themselves at half the steps, for the
steps; the central differences of dd runs (an independent method: perturbed runs of the whole
coupled propagation, no Jacobian), for the variational equations.
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn.od import coupled, problem as odp
from tqdyn.od.parameters import OrbitParameters
from tqdyn.od.variational import propagate_with_partials
from tqdyn.scenario import load_scenario

DAY = 86400.0
SCEN = "tianqin"
#: Injected common self-gravity [m/s^2 in S] on each satellite (flight direction Y_S; the
#: order of the paper's Table IV).
INJECTED = (0.0, 1e-10, 0.0)


@pytest.fixture(scope="module")
def coupled_partials():
    """The coupled tianqin partials by central differences over 12 h (every 3 h, difference runs at
    600 s steps, the default difference steps): (times [s], coupled.propagate_with_partials result),
    shared by three tests."""
    t = np.arange(0.0, DAY / 2 + 1.0, 10800.0)
    return t, coupled.propagate_with_partials(load_scenario(SCEN), None, t, step=600.0, method="differences")


@pytest.mark.slow  # ~100 coupled one-day runs for the differences: ~10 s
def test_recovery_of_common_self_gravity(record_number):
    """GNSS + SLR + ISR on the coupled tianqin run over 1 day every 1800 s, 1e-10 m/s^2 along
    Y_S injected on each satellite; state and common self-gravity estimated: every estimated
    value within 4.5 sigma of the truth (N(0, 1) errors: a 4.5-sigma miss among 27 has a chance
    ~2e-4).  Sat1's Y_S sigma (measured 8.5e-12 m/s^2; 12 h give ~9e-11, too little to see
    1e-10, hence one day) is bounded at 3e-11 m/s^2.  The default suite checks the same recovery
    and bound through the command line (tests/test_od_chain.py::test_coupled_run_simulate_then_fit:
    the same plan and injection, another noise seed)."""
    scen = load_scenario(SCEN)
    tr = odp.Tracking(("gnss", "slr", "isr"), DAY, 1800.0, estimate=("state", "self_gravity_common"))
    nom = odp.nominal_parameters(scen)
    truth = OrbitParameters(nom.accelerations, nom.y0, np.tile(INJECTED, (3, 1)))
    est = odp.fit(scen, odp.simulate(scen, tr, truth, seed=0), tr)
    x_true = odp._values(truth)
    z = (est.values - x_true) / est.sigma
    names = list(est.names)
    assert names[18:] == coupled.parameter_names(scen)
    record_number("od.coupled_recovery_max_z", float(np.max(np.abs(z))))
    sig_y = float(est.sigma[names.index("Sat1/sgc_y")])
    record_number("od.coupled_recovery_sat1_sigma_y", sig_y, "m/s^2")
    assert np.max(np.abs(z)) < 4.5, dict(zip(names, z))
    assert sig_y < 3e-11


def test_coupled_sensitivity_matches_point_mass_s_frame(coupled_partials, record_number):
    """The position sensitivity of the coupled (drag-free, global pointing) tianqin orbits to
    their TMs' common self-gravity equals the point-mass sensitivity of tianqin-gravity (same
    initial states) to the S-frame constant acceleration: the drag-free control hands the TMs'
    DC acceleration on to the orbit.  Largest difference over the 9 x 9 position blocks at 3, 6,
    9, 12 h relative to the largest point-mass sensitivity at that time: measured 1.5e-9 (the
    coupled run's Table IV self-gravity and attitude), bounded at 1e-8."""
    nom = odp.nominal_parameters(load_scenario(SCEN))
    t, pc = coupled_partials
    pp = propagate_with_partials(load_scenario("tianqin-gravity"), OrbitParameters(y0=nom.y0), t, step=600.0)
    sp = np.concatenate([pp.sensitivities_full[:, :, 12 * b:12 * b + 3] for b in range(3)], axis=2)
    pos = [6 * b + i for b in range(3) for i in range(3)]
    rel = max(float(np.max(np.abs(pc.sensitivities_full[k][pos] - sp[k][pos])) / np.max(np.abs(sp[k][pos])))
              for k in range(1, t.size))
    record_number("od.coupled_vs_point_mass_rel", rel)
    assert np.max(np.abs(sp[-1][pos])) > 1e8         # s^2: ~ t^2 / 2 at 12 h
    assert rel < 1e-8


def test_difference_steps(coupled_partials, record_number):
    """Halving every difference step (1 m, 2^-13 m/s, 2^-30 m/s^2) changes the coupled partials
    over 12 h (every 3 h) by less than 1e-15 of each column's largest value (measured 2.2e-16:
    truncation and round-off both at the float64 level)."""
    t, a = coupled_partials
    b = coupled.propagate_with_partials(load_scenario(SCEN), None, t, step=600.0,
                                        steps=(coupled.STEP_POSITION / 2, coupled.STEP_VELOCITY / 2,
                                               coupled.STEP_COMMON / 2), method="differences")
    fa = np.concatenate([a.stm_full, a.sensitivities_full], axis=2)
    fb = np.concatenate([b.stm_full, b.sensitivities_full], axis=2)
    rel = float(np.max(np.max(np.abs(fa - fb), axis=(0, 1)) / np.max(np.abs(fa), axis=(0, 1))))
    record_number("od.coupled_fd_halving_rel", rel)
    assert rel < 1e-15


def test_default_groups_follow_the_run():
    """A plan that names no groups estimates state + S-frame constants on a point-mass run and
    state + common self-gravity on a coupled one; a considered default group leaves the estimate."""
    tr = odp.Tracking(("slr",), DAY)
    assert odp.estimated_groups("tianqin-gravity", tr) == ("state", "s_frame")
    assert odp.estimated_groups(SCEN, tr) == ("state", "self_gravity_common")
    tr_c = odp.Tracking(("slr",), DAY, consider=("self_gravity_common",),
                        a_priori_sigma={"self_gravity_common": 1e-9})
    assert odp.estimated_groups(SCEN, tr_c) == ("state",)


def _variational_vs_differences(v, d) -> dict:
    """Largest difference of the variational partials v from the central differences d, relative to
    each column's largest value (over the times and the 18 rows), per parameter class: initial
    positions, initial velocities, common self-gravity; and ``cross``: the blocks of one satellite's
    state against another satellite's parameters (the coupling through the beam directions),
    relative to each such block's own largest value."""
    def rel(a, b, cols):
        return float(np.max(np.max(np.abs(a[:, :, cols] - b[:, :, cols]), axis=(0, 1))
                            / np.max(np.abs(b[:, :, cols]), axis=(0, 1))))

    pos = [6 * b + i for b in range(3) for i in range(3)]
    vel = [6 * b + 3 + i for b in range(3) for i in range(3)]
    out = {"position": rel(v.stm_full, d.stm_full, pos), "velocity": rel(v.stm_full, d.stm_full, vel),
           "self_gravity_common": rel(v.sensitivities_full, d.sensitivities_full, list(range(9)))}
    cross = 0.0
    for a, b, n in ((v.stm_full, d.stm_full, 6), (v.sensitivities_full, d.sensitivities_full, 3)):
        for r in range(3):
            for c in range(3):
                if r != c:
                    x, y = a[:, 6 * r:6 * r + 6, n * c:n * c + n], b[:, 6 * r:6 * r + 6, n * c:n * c + n]
                    cross = max(cross, float(np.max(np.abs(x - y)) / np.max(np.abs(y))))
    out["cross"] = cross
    return out


def test_variational_equations_match_differences_half_day(coupled_partials, record_number):
    """The coupled variational partials (Jacobians of the dd coupled right-hand side every 3600 s,
    the default node spacing over 12 h, so that 12 nodes interpolate; DP87 at 600 s) against the central differences of dd runs over 12 h every 3 h: largest
    difference per parameter class relative to each column's largest value, measured 2.2e-11
    (states) and 6e-12 (common self-gravity), bounded at 1e-10; the blocks that couple the
    satellites (one satellite's state against another's parameters, ~1e-4 m/m and ~4 s^2 after
    12 h) relative to their own size measured 5.2e-8, bounded at 2e-7."""
    t, d = coupled_partials
    v = coupled.propagate_with_partials(load_scenario(SCEN), None, t, step=600.0)
    assert np.array_equal(v.states_dd, d.states_dd)
    rel = _variational_vs_differences(v, d)
    record_number("od.coupled_variational_rel_12h", rel)
    assert max(rel["position"], rel["velocity"], rel["self_gravity_common"]) < 1e-10, rel
    assert rel["cross"] < 2e-7, rel


@pytest.mark.slow  # 54 ten-day coupled runs for the differences: ~1 min
def test_variational_equations_match_differences_ten_days(record_number):
    """Acceptance: the coupled variational partials against the central differences of dd runs over
    10 days every 3 h (both integrated at 600 s): largest difference per parameter class relative
    to each column's largest value at most 1e-6 (measured 9e-10 for the states, 2e-9 for the common
    self-gravity, with Jacobian nodes every 5400 s interpolated through 12 of them), and the
    satellites' coupling blocks (0.5 m/m and 1.3e5 s^2 after 10 days) to 1e-6 of their own size
    (measured 2.5e-10)."""
    scen = load_scenario(SCEN)
    t = np.arange(0.0, 10 * DAY + 1.0, 10800.0)
    d = coupled.propagate_with_partials(scen, None, t, step=600.0, method="differences")
    v = coupled.propagate_with_partials(scen, None, t, step=600.0)
    rel = _variational_vs_differences(v, d)
    record_number("od.coupled_variational_rel_10d", rel)
    assert max(rel.values()) < 1e-6, rel
    assert max(rel["position"], rel["velocity"], rel["self_gravity_common"]) < 1e-8, rel


def test_partials_method_is_checked():
    """An unknown method of the coupled partials is refused in one line naming the allowed ones,
    both as an argument and as the block's method; so is a node spacing off the partials' step."""
    scen = load_scenario(SCEN)
    for call in (lambda: coupled.propagate_with_partials(scen, None, [0.0], method="taylor"),
                 lambda: coupled.method("taylor").__enter__()):
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == "method: 'taylor'; allowed: variational, differences"
    with pytest.raises(ValueError, match="node_step: 700.0 s is not a multiple"):
        coupled.propagate_with_partials(scen, None, [600.0], step=600.0, node_step=700.0)
