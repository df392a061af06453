"""Measurement biases in orbit determination (group "bias" of tqdyn.od.problem): one constant per
ground station and type, and per one-way inter-satellite link, estimated or considered.

References: the normal distribution of the errors of a least-squares estimate with Gaussian noise
(Tapley, Schutz & Born, "Statistical Orbit Determination", 2004, section 4.3: x_hat - x ~ N(0, P));
for the a priori and consider cases, the covariance of generalised least squares with the
bias folded into the noise, computed here with numpy from the same Jacobian of the orbit
parameters: a bias b ~ N(0, s_b^2) on the rows B makes the noise covariance R + s_b^2 B B^T, so
estimating b with that a priori gives the orbit covariance (H^T (R + s_b^2 B B^T)^-1 H)^-1, and
ignoring b (considering it) gives the sandwich P H^T R^-1 (R + s_b^2 B B^T) R^-1 H P with
P = (H^T R^-1 H)^-1 (TSB section 6.3).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import stats

from tqdyn.od import estimator, problem as odp

DAY = 86400.0
SCEN = "tianqin-gravity"
#: Injected biases [m]: every SLR station 3 cm, Graz -10 cm; every link 0.5 m, Sat2->Sat1 -2 m.
BIAS = {"slr_range": 0.03, "slr_range/Graz": -0.10, "isr_range": 0.5, "isr_range/Sat2->Sat1": -2.0}


def _truth_of(name: str) -> float:
    key = name.removeprefix("bias/")
    return BIAS.get(key, BIAS.get(key.split("/")[0], 0.0))


@pytest.fixture(scope="module")
def plan():
    return odp.Tracking(("slr", "isr"), 2 * DAY, 1800.0, estimate=("state", "s_frame", "bias"))


def test_biases_recovered_20_seeds(plan, record_number):
    """SLR + ISR on tianqin-gravity over 2 days with the biases of BIAS: 20 noise draws fitted
    (the linearised problem at the nominal point: the model is linear in the biases, and the
    orbit's nonlinearity over 2 days is ~1e-8 m).  chi^2 of the 14 bias errors against their
    covariance, summed over the seeds, lies within the 1e-3 quantiles of chi^2(280); against
    biases of the opposite sign it does not (a sign error in the bias partials would be seen)."""
    clean = odp.simulate(SCEN, plan, noise=False, bias=BIAS)
    prob = odp.build_problem(SCEN, clean, plan)
    q0 = prob.estimated.values.copy()
    h0, H0 = prob.model(q0)

    def linear(q):
        return h0 + H0 @ (np.asarray(q) - q0), H0

    linear.transform = prob.model.transform
    lin = dataclasses.replace(prob, model=linear)
    names = list(prob.estimated.names)
    ib = [k for k, n in enumerate(names) if n.startswith("bias/")]
    assert len(ib) == 8 + 6
    truth = np.array([_truth_of(names[k]) for k in ib])
    chi, chi_flip = 0.0, 0.0
    for seed in range(20):
        rng = np.random.default_rng(500 + seed)
        f = estimator.estimate(odp.with_measurements(lin, clean.value + clean.sigma * rng.standard_normal(len(clean))))
        P = f.covariance[np.ix_(ib, ib)]
        e = f.values[ib] - truth
        chi += float(e @ np.linalg.solve(P, e))
        e_flip = f.values[ib] + truth
        chi_flip += float(e_flip @ np.linalg.solve(P, e_flip))
    dof = 20 * len(ib)
    record_number("od.bias_recovery_chi2", [chi, dof])
    assert stats.chi2.ppf(1e-3, dof) < chi < stats.chi2.ppf(1 - 1e-3, dof), (chi, dof)
    assert chi_flip > stats.chi2.ppf(1 - 1e-3, dof), chi_flip


def _orbit_jacobian_and_bias_rows(plan_):
    """The Jacobian of the orbit parameters (state, s_frame) of the plan's schedule, the rows'
    sigmas and the bias incidence built here from the rows' types and peers (numpy only)."""
    meas = odp.schedule(SCEN, plan_)
    prob = odp.build_problem(SCEN, meas, dataclasses.replace(plan_, estimate=("state", "s_frame")))
    H = prob.model(prob.estimated.values)[1]
    sats = ["Sat1", "Sat2", "Sat3"]
    keys = [f"{t}/{p}" if t == "slr_range" else f"{t}/{sats[int(p)]}->{sats[s]}"
            for t, s, p in zip(meas.type, meas.sat, meas.peer)]
    uniq = sorted(set(keys))
    B = np.array([[1.0 if k == u else 0.0 for u in uniq] for k in keys])
    return meas, H, B


def test_a_priori_and_consider_biases_match_generalised_least_squares(plan, record_number):
    """Covariance analysis (1 day, SLR + ISR) with the biases estimated under an a priori sigma
    of 5 cm, and considered with that sigma: the orbit parameters' covariance equals the GLS
    forms of the module docstring (numpy QR of the whitened, column-scaled orbit Jacobian) to
    1e-12 of the product of the two sigmas (measured 1.6e-13 estimated, 4.5e-14 considered)."""
    s_b = 0.05
    short = dataclasses.replace(plan, arc_s=DAY)
    meas, H, B = _orbit_jacobian_and_bias_rows(short)
    C = np.diag(meas.sigma ** 2) + s_b ** 2 * B @ B.T
    # whitened, column-scaled QR (the normal matrices are too ill-conditioned to invert as they are)
    D = np.diag(1.0 / np.linalg.norm(H / meas.sigma[:, None], axis=0))
    L = np.linalg.cholesky(C)
    Q, Rq = np.linalg.qr(np.linalg.solve(L, H) @ D)
    Ri = np.linalg.inv(Rq)
    P_gls = D @ Ri @ Ri.T @ D
    Q, Rq = np.linalg.qr((H / meas.sigma[:, None]) @ D)
    K = D @ np.linalg.inv(Rq) @ Q.T / meas.sigma[None, :]         # P H^T R^-1
    P = K @ np.diag(meas.sigma ** 2) @ K.T
    P_consider = K @ C @ K.T

    est = odp.covariance(SCEN, dataclasses.replace(short, a_priori_sigma={"bias": s_b}))
    n = H.shape[1]
    assert all(not x.startswith("bias/") for x in est.names[:n]) and est.names[n].startswith("bias/")
    con = odp.covariance(SCEN, dataclasses.replace(short, estimate=("state", "s_frame"), consider=("bias",),
                                                   a_priori_sigma={"bias": s_b}))

    def rel(a, b):
        sa, sb = np.sqrt(np.diag(a)), np.sqrt(np.diag(b))
        return float(np.max(np.abs(a - b) / np.outer(sb, sb)))

    r_est = rel(est.covariance[:n, :n], P_gls)
    r_con = rel(con.consider_covariance, P_consider)
    record_number("od.bias_a_priori_vs_gls", r_est)
    record_number("od.bias_consider_vs_gls", r_con)
    assert r_est < 1e-12 and r_con < 1e-12, (r_est, r_con)
    # the biases matter: the considered sigmas are larger than the noise-only ones
    assert np.max(np.sqrt(np.diag(P_consider)) / np.sqrt(np.diag(P))) > 2.0
