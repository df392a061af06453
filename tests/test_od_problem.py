"""Orbit determination put together (tqdyn.od.problem): tracking plans, simulated measurements,
the measurement partials chained with the variational equations, the recovery of an injected
self-gravity, refusals.

References: central differences of the computed measurements between double-double
propagations (for the partials); the chi-square distribution of the normalised estimation
errors of a linear(ised) least-squares estimate with Gaussian noise (Tapley, Schutz & Born,
"Statistical Orbit Determination", 2004, section 4.3: x_hat - x ~ N(0, P)), for the recovery.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from scipy import stats

from tqdyn.od import estimator, problem as odp
from tqdyn.od.parameters import OrbitParameters
from tqdyn.scenario import load_scenario

DAY = 86400.0
SCEN = "tianqin-gravity"
#: The injected DC self-gravity per S axis [m/s^2] (the order of the paper's Table IV).
INJECTED = 1e-10
#: Chi-square acceptance quantiles of the recovery tests.
Q_LOW, Q_HIGH = 1e-3, 1.0 - 1e-3


def _truth():
    acc = np.zeros((3, 12))
    acc[:, :3] = INJECTED
    return OrbitParameters(accelerations=acc)


@pytest.fixture(scope="module")
def recovery():
    """The truth run and the nominal partials, shared by the seeds: GNSS + SLR + ISR on
    tianqin-gravity over 2 days every 1800 s, state and S-frame accelerations estimated."""
    tr = odp.Tracking(("gnss", "slr", "isr"), 2 * DAY, 1800.0)
    clean = odp.simulate(SCEN, tr, _truth(), noise=False)
    prob = odp.build_problem(SCEN, odp.simulate(SCEN, tr, _truth(), seed=0), tr)
    q0 = prob.estimated.values.copy()
    x_true = q0.copy()
    for k, n in enumerate(prob.estimated.names):
        if n.split("/")[1] in ("s_x", "s_y", "s_z"):
            x_true[k] = INJECTED
    return tr, clean, prob, q0, x_true


def _draw(clean, seed):
    """Measurement values of one seed: white noise of each row's sigma and a receiver clock
    bias per GNSS epoch and satellite (1 km), independent of the package's simulate()."""
    rng = np.random.default_rng(1000 + seed)
    y = clean.value + clean.sigma * rng.standard_normal(len(clean))
    g = clean.type == "gnss_pseudorange"
    keys = {k: rng.normal(0.0, 1e3) for k in set(zip(clean.t[g].tolist(), clean.sat[g].tolist()))}
    y[g] += [keys[k] for k in zip(clean.t[g].tolist(), clean.sat[g].tolist())]
    return y


def _chi2(fits, x_true, s_only):
    total, dof, z = 0.0, 0, []
    for f in fits:
        idx = [k for k, n in enumerate(f.names) if not s_only or n.split("/")[1].startswith("s_")]
        e = (f.values - x_true)[idx]
        P = f.covariance[np.ix_(idx, idx)]
        total += float(e @ np.linalg.solve(P, e))
        dof += len(idx)
        z.append(e / f.sigma[idx])
    return total, dof, np.array(z)


def _check_recovery(record_number, fits, x_true, tag):
    chi_all, dof_all, _ = _chi2(fits, x_true, False)
    chi_s, dof_s, z = _chi2(fits, x_true, True)
    s_sigma = fits[0].sigma[[k for k, n in enumerate(fits[0].names) if "/s_" in n]]
    record_number(f"od.recovery_{tag}_seeds", len(fits))
    record_number(f"od.recovery_{tag}_chi2_all", [chi_all, dof_all])
    record_number(f"od.recovery_{tag}_chi2_s", [chi_s, dof_s])
    record_number(f"od.recovery_{tag}_chi2_s_pvalue", float(stats.chi2.sf(chi_s, dof_s)))
    record_number(f"od.recovery_{tag}_s_sigma_max", float(s_sigma.max()), "m/s^2")
    record_number(f"od.recovery_{tag}_s_sigma_min", float(s_sigma.min()), "m/s^2")
    for chi, dof in ((chi_all, dof_all), (chi_s, dof_s)):
        assert stats.chi2.ppf(Q_LOW, dof) < chi < stats.chi2.ppf(Q_HIGH, dof), (chi, dof)
    # the injected 1e-10 m/s^2 is determined: every S-axis sigma well below it
    assert s_sigma.max() < INJECTED / 2
    # the mean error over the seeds is consistent with zero (4 sigma of the mean)
    assert np.all(np.abs(z.mean(axis=0)) < 4.0 / np.sqrt(len(fits)))


def test_self_gravity_recovered_linearised_20_seeds(recovery, record_number):
    """Self-gravity of 1e-10 m/s^2 per S axis injected into the truth run is estimated back
    from 20 noise draws, with the shared nominal partials (one Gauss-Newton step from the
    a priori point is the exact least-squares solution of the linearised problem; the
    nonlinearity of 1e-10 m/s^2 over 2 days, displacements ~2 m on 1e8 m ranges, is ~1e-8 m):
    the normalised errors x_hat - x_true against the covariance follow chi-square with
    20 x 27 (all) and 20 x 9 (S axes) degrees of freedom within the 1e-3 and 1 - 1e-3
    quantiles; the GNSS clocks (1 km per epoch) are eliminated."""
    tr, clean, prob, q0, x_true = recovery
    h0, H0 = prob.model(q0)

    def linear(q):
        return h0 + H0 @ (np.asarray(q) - q0), H0

    linear.transform = prob.model.transform
    lin = dataclasses.replace(prob, model=linear)
    fits = [estimator.estimate(odp.with_measurements(lin, _draw(clean, s))) for s in range(20)]
    _check_recovery(record_number, fits, x_true, "linear")


def test_self_gravity_recovered_gauss_newton(recovery):
    """The full Gauss-Newton fit (a new dd propagation with partials per iteration) of two
    seeds converges and agrees with the linearised estimate to 1e-2 of a sigma, within
    5 sigma of the injected values."""
    tr, clean, prob, q0, x_true = recovery
    h0, H0 = prob.model(q0)
    for seed in range(2):
        y = _draw(clean, seed)
        f = estimator.estimate(odp.with_measurements(prob, y))

        def linear(q):
            return h0 + H0 @ (np.asarray(q) - q0), H0

        linear.transform = prob.model.transform
        g = estimator.estimate(odp.with_measurements(dataclasses.replace(prob, model=linear), y))
        assert f.iterations <= 3
        assert np.max(np.abs(f.values - g.values) / f.sigma) < 1e-2
        s = [k for k, n in enumerate(f.names) if "/s_" in n]
        assert np.max(np.abs(f.values[s] - INJECTED) / f.sigma[s]) < 5.0


@pytest.mark.slow
def test_self_gravity_recovered_gauss_newton_20_seeds(recovery, record_number):
    """As the linearised test, with the full Gauss-Newton fit of each of 20 seeds."""
    tr, clean, prob, q0, x_true = recovery
    fits = [estimator.estimate(odp.with_measurements(prob, _draw(clean, s))) for s in range(20)]
    _check_recovery(record_number, fits, x_true, "gauss_newton")


def test_partials_against_central_differences(record_number):
    """compute()'s H against central differences of compute()'s h between dd propagations
    (tianqin-gravity, 1 day every 3 h, GNSS + SLR + ISR + DSN + TT&C): the columns of Sat1's x
    (steps +-1 m) and Sat2's s_y (+-1e-9 m/s^2).  Expected: the float64 variational equations
    (~1e-10 relative, docs/orbit-determination.md) and the differences' round-off (~1e-8 m
    on 1e8 m ranges over ~1-4 m of change, ~1e-8)."""
    tr = odp.Tracking(("gnss", "slr", "isr", "dsn", "ttc"), DAY, 3 * 3600.0)
    meas = odp.schedule(SCEN, tr)
    assert np.all(np.diff(meas.t) >= 0) and np.all(np.isnan(meas.value))
    assert set(meas.type) == set(odp.MEASUREMENT_TYPES)
    nominal = odp.nominal_parameters(SCEN)
    h, H, names = odp.compute(SCEN, nominal, meas)
    assert H.shape == (len(meas), 54) and len(names) == 54
    worst = {}
    for name, delta in (("Sat1/x", 1.0), ("Sat2/s_y", 1e-9)):
        j = names.index(name)
        out = []
        for sign in (1.0, -1.0):
            par = OrbitParameters(accelerations=np.array(nominal.accelerations), y0=nominal.y0_dd().copy())
            if j < 18:
                par.y0[j // 6, j % 6, 0] += sign * delta
            else:
                par.accelerations.flat[j - 18] += sign * delta
            out.append(odp.compute(SCEN, par, meas)[0])
        fd = (out[0] - out[1]) / (2 * delta)
        for mtype in odp.MEASUREMENT_TYPES:
            k = meas.type == mtype
            ref = np.max(np.abs(fd[k]))
            if ref > 0:
                worst[(name, mtype)] = float(np.max(np.abs(H[k, j] - fd[k])) / ref)
    rel = max(worst.values())
    record_number("od.problem_partials_fd_rel", rel)
    # measured 2.1e-8
    assert rel < 1e-7, worst


def test_lisa_dsn_and_isr_covariance():
    """Heliocentric: DSN + ISR on lisa-gravity (10 days, every 6 h) determine the states and
    the S-frame accelerations (the problem is observable; sigmas finite and positive)."""
    c = odp.covariance("lisa-gravity", odp.Tracking(("dsn", "isr"), 10 * DAY, 21600.0))
    s = [k for k, n in enumerate(c.names) if "/s_" in n]
    assert len(s) == 9 and np.all(np.isfinite(c.sigma)) and np.all(c.sigma[s] > 0)
    # DSN ranges of 1 m and range rates of 1 mm/s: the S axes to ~1e-9 m/s^2 in 10 days
    assert np.all(c.sigma[s] < 1e-8)


@pytest.mark.parametrize("make, match", [
    (lambda: odp.Tracking(("gps",), DAY), "tracking.kinds: 'gps' is not allowed"),
    (lambda: odp.Tracking(("slr",), DAY, estimate=("state", "j2")), "tracking.estimate: 'j2'"),
    (lambda: odp.Tracking(("slr",), DAY, consider=("rtn",)), "tracking.consider: 'rtn' needs an a priori sigma"),
    (lambda: odp.schedule(SCEN, odp.Tracking(("slr",), 60 * 365.25 * DAY, DAY)),
     "tracking.arc_s: .* ends beyond the span of the ephemeris"),
    (lambda: odp.schedule(SCEN, odp.Tracking(("slr",), DAY, 625.0)),
     "tracking.interval_s: 625.0 s is not a multiple of integrator.step = 50.0 s"),
    (lambda: odp.schedule("lisa-gravity", odp.Tracking(("dsn",), DAY / 2, 21600.0,
                                                         stations=("DSS-14 Goldstone", "DSS-63 Madrid"))),
     "tracking.stations: 'DSS-63 Madrid' is below its elevation mask for the whole arc"),
    (lambda: odp.schedule("lisa-gravity", odp.Tracking(("gnss", "isr"), DAY, 21600.0)),
     "tracking.kinds: 'gnss' is not allowed for the heliocentric scenario 'lisa-gravity'; allowed: dsn, isr"),
    (lambda: odp.schedule("tianqin", odp.Tracking(("slr",), DAY, estimate=("state", "s_frame"))),
     "tracking: group 's_frame' is not allowed for the coupled scenario 'tianqin'; "
     "allowed: state, self_gravity_common"),
    (lambda: odp.schedule(SCEN, odp.Tracking(("slr",), DAY, estimate=("state", "self_gravity_common"))),
     "tracking: group 'self_gravity_common' needs a coupled scenario"),
    (lambda: odp.covariance(SCEN, odp.Tracking(("gnss",), DAY / 2, 3600.0, estimate=("state", "s_frame", "bias"))),
     "tracking: group 'bias' but no measurement of slr_range, isr_range, dsn_range, dsn_range_rate"),
    (lambda: odp.covariance(SCEN, odp.Tracking(("slr", "isr"), DAY / 2, 3600.0, consider=("bias",),
                                               a_priori_sigma={"bias": {"slr_range": 0.02}})),
     re.escape("tracking.a_priori_sigma['bias']: no sigma for 'isr_range', whose biases are considered")),
    (lambda: odp.simulate(SCEN, odp.Tracking(("slr",), DAY / 2, 3600.0), bias={"slr_range/Nowhere": 1.0}),
     "bias: 'slr_range/Nowhere' is not a bias of these measurements; allowed: a type of"),
    (lambda: odp.Tracking(("slr",), DAY, a_priori_sigma={"bias": {"gnss_pseudorange": 1.0}}),
     re.escape("tracking.a_priori_sigma['bias']: 'gnss_pseudorange' is not allowed")),
    (lambda: odp.nominal_parameters(load_scenario("tianqin", ["constellation.free_tms=true"])),
     "constellation.free_tms = true propagates the test masses"),
    (lambda: odp.fit(SCEN, odp.schedule(SCEN, odp.Tracking(("isr",), 3600.0, 600.0)),
                     odp.Tracking(("isr",), 3600.0, 600.0)), "measurements: every value is NaN"),
])
def test_refusals(make, match):
    """Bad tracking plans and scenarios are refused in one line naming the field and value
    (the horizon case: on lisa-gravity Madrid sees no satellite at 0, 6 and 12 h, measured)."""
    with pytest.raises(ValueError, match=match) as exc:
        make()
    assert "\n" not in str(exc.value)


def test_consider_and_a_priori():
    """Consider parameters and a priori sigmas reach the estimator: considering the RTN
    constants (1e-11 m/s^2) can only widen the S-axis sigmas (P_c = P + S P_cc S^T), and a
    tight a priori sigma (1e-15 m/s^2) on the S-frame constants bounds their sigmas by it."""
    base = odp.Tracking(("slr",), DAY, 3600.0)
    c0 = odp.covariance(SCEN, base)
    cc = odp.covariance(SCEN, dataclasses.replace(base, consider=("rtn",), a_priori_sigma={"rtn": 1e-11}))
    s = [k for k, n in enumerate(c0.names) if "/s_" in n]
    assert cc.consider_names and len(cc.consider_names) == 9
    assert np.allclose(cc.sigma, c0.sigma, rtol=1e-9)
    assert np.all(cc.consider_sigma[s] >= c0.sigma[s] * (1 - 1e-9))
    assert np.any(cc.consider_sigma[s] > 1.01 * c0.sigma[s])
    ca = odp.covariance(SCEN, dataclasses.replace(base, a_priori_sigma={"s_frame": 1e-15}))
    assert np.all(ca.sigma[s] <= 1e-15 * (1 + 1e-9))
