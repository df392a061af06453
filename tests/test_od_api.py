"""Orbit determination in memory (tqdyn.od_simulate / od_fit / od_covariance, tqdyn.workflows.od_memory):
no file between a propagation, its simulated tracking and the fit; typed, checked keyword arguments.

References: the layer below called directly (tqdyn.od.problem.simulate / fit / covariance on the same
scenario, plan and seed: the front door must hand back exactly its numbers); the truth the measurements
are simulated from (the fit must find it within its own sigmas); the chi-square law of the post-fit
residuals of a correct model.  The run is tianqin-kepler (point masses, Kepler), 1 day at 600 s.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

import tqdyn
from tqdyn.od import problem as odp

SCEN = {"run.duration": "1d", "integrator.step": 600}


@pytest.fixture(scope="module")
def traj():
    """A one-day tianqin-kepler run propagated in memory (no file)."""
    return tqdyn.propagate("tianqin-kepler", SCEN)


def test_fit_of_simulated_tracking_without_a_file(traj, tmp_path, monkeypatch):
    """The acceptance line: tqdyn.od_fit(scenario, tqdyn.od_simulate(run, tracking), tracking) with the run
    in memory; nothing is written (the working directory stays empty); the values are those of
    tqdyn.od.problem's simulate and fit with the same plan and seed; the estimate is within 5 sigma of the
    truth (the run's own initial states and zero accelerations) and chi^2 within its 1e-3 quantiles."""
    monkeypatch.chdir(tmp_path)
    tracking = "slr,isr"
    meas = tqdyn.od_simulate(traj, tracking, "12h", seed=4)
    est = tqdyn.od_fit(tqdyn.load_scenario("tianqin-kepler", SCEN), meas, tracking)
    assert list(tmp_path.iterdir()) == []
    scen = tqdyn.load_scenario("tianqin-kepler", SCEN)
    plan = odp.Tracking(("slr", "isr"), 43200.0)
    ref_meas = odp.simulate(scen, plan, None, 4)
    ref = odp.fit(scen, ref_meas, plan)
    assert np.array_equal(meas.value.values, ref_meas.value) and np.array_equal(meas.t.values, ref_meas.t)
    assert list(meas.type.values) == list(ref_meas.type) and meas.attrs["seed"] == "4"
    assert list(est.parameter.values) == list(ref.names)
    assert np.array_equal(est.estimate.values, ref.values) and np.array_equal(est.covariance.values, ref.covariance)
    truth = odp.build_problem(scen, ref_meas, plan).estimated.values
    assert np.max(np.abs(est.estimate.values - truth) / est.sigma.values) < 5.0
    dof = int(est.attrs["chi2_dof"])
    assert stats.chi2.ppf(1e-3, dof) < est.attrs["chi2"] < stats.chi2.ppf(1 - 1e-3, dof)
    assert set(est.unit.values) == {"m", "m/s", "m/s^2"} and est.residual.size == est.normalised_residual.size


def test_a_tracking_plan_object_and_the_covariance(traj):
    """A tqdyn.od.problem.Tracking as the tracking (its arc and interval); od_covariance's sigmas are
    tqdyn.od.problem.covariance's of the same plan, bit for bit; od_fit's estimator options reach the
    estimator (max_iterations=1 stops after one model evaluation)."""
    plan = odp.Tracking(("slr",), 43200.0, 1800.0, estimate=("state",))
    meas = tqdyn.od_simulate(traj, plan, seed=1)
    assert meas.attrs["interval_s"] == "1800.0" and meas.sizes["row"] > 0
    cov = tqdyn.od_covariance("tianqin-kepler", plan, overrides=SCEN)
    ref = odp.covariance(tqdyn.load_scenario("tianqin-kepler", SCEN), plan)
    assert np.array_equal(cov.sigma.values, ref.sigma) and list(cov.parameter.values) == list(ref.names)
    one = tqdyn.od_fit("tianqin-kepler", meas, plan, overrides=SCEN, max_iterations=1, step_tol=1e3)
    assert one.attrs["iterations"] == 1


@pytest.mark.parametrize("call, pattern", [
    (lambda t: tqdyn.od_fit("tianqin-kepler", None, "slr", edit_sigm=3.0),
     r"^od_fit\(\): 'edit_sigm' is not a keyword argument \(did you mean 'edit_sigma'\?\); allowed: one of the "
     r"14 keywords in docs/python.md$"),
    (lambda t: tqdyn.od_simulate(t, "slr", "1d", output="m.tdm"),
     r"^od_simulate\(\): 'output' is not a keyword argument; allowed: one of the 9 keywords in docs/python.md"),
    (lambda t: tqdyn.od_simulate(t, "slrr", "1d"), r"^tracking: 'slrr' is not a tracking type \(did you mean 'slr'"),
    (lambda t: tqdyn.od_simulate(t, "slr"), r"^arc: missing; allowed: seconds"),
    (lambda t: tqdyn.od_simulate(t, "slr", "-2h"), r"^arc: '-2h' is not a duration > 0"),
    (lambda t: tqdyn.od_simulate(t, "slr", "1d", seed=-1), r"^seed: -1 is not allowed; allowed: an integer >= 0"),
    (lambda t: tqdyn.od_simulate(t, "slr", "1d", bias={"slr_rang": 1.0}), r"^bias: 'slr_rang' is not allowed"),
    (lambda t: tqdyn.od_simulate(t, odp.Tracking(("slr",), 3600.0), "1d"), r"^arc: '1d' is given with a Tracking"),
    (lambda t: tqdyn.od_covariance("tianqin-kepler", "slr", "1h", consider="s_frame"),
     r"^consider: 's_frame' needs an a priori sigma; allowed: with a_priori s_frame=SIGMA"),
    (lambda t: tqdyn.od_covariance("tianqin-kepler", "slr", "1h", a_priori={"stat": 1.0}),
     r"^a_priori: 'stat' is not allowed \(did you mean 'state'\?\)"),
])
def test_bad_arguments_are_one_line_naming_the_argument(traj, call, pattern):
    """An unknown keyword (TypeError) or a bad value (ValueError): one line of at most 200 characters
    naming the argument as the Python call spells it and what is allowed (the patterns: the messages
    the checks are written to give)."""
    with pytest.raises((TypeError, ValueError)) as info:
        call(traj)
    msg = str(info.value)
    assert "\n" not in msg and len(msg) <= 200, msg
    assert __import__("re").search(pattern, msg), msg


def test_bad_estimator_options_and_measurements(traj):
    """The estimator's options are checked by value (one line naming the option and the allowed range), and
    measurements of another epoch are refused (the Dataset's epoch against the scenario's)."""
    meas = tqdyn.od_simulate(traj, "slr", "6h", seed=0)
    for key, value, allowed in (("max_iterations", 0, "an integer >= 1"), ("step_tol", -1.0, "a number > 0"),
                                ("min_kept_fraction", 2.0, r"a number in \(0, 1\]"), ("edit_sigma", "3", "a number > 0")):
        with pytest.raises(ValueError, match=rf"^{key}: .* is not allowed; allowed: {allowed}$"):
            tqdyn.od_fit("tianqin-kepler", meas, overrides=SCEN, **{key: value})
    moved = meas.assign_attrs(epoch="2004-06-07T00:00:00 UTC")
    with pytest.raises(ValueError, match=r"^measurements: epoch 2004-06-07T.*; allowed: measurements of this"):
        tqdyn.od_fit("tianqin-kepler", moved, overrides=SCEN)
    with pytest.raises(ValueError, match=r"^measurements: no 't'; allowed: a Dataset of tqdyn.od_simulate"):
        tqdyn.od_fit("tianqin-kepler", meas.drop_vars("t"), overrides=SCEN)
