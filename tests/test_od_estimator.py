"""Batch least-squares estimator of orbit determination (tqdyn.od.estimator).

References: (a) the closed-form solution of the linearised Hill / Clohessy-Wiltshire relative motion
with a constant along-track acceleration (derived in :func:`_cw_partials`, checked against a
numerical integration of the equations of motion), whose normal matrix is summed and inverted in
mpmath at 50 digits, independently of the estimator's scaled SVD; (b) the chi-square distribution
of normalised errors over seeds for the estimator's own covariance; (c) Monte Carlo over the
consider parameter's distribution for the consider covariance of Tapley, Schutz & Born (2004),
section 6.3; (d) exact answers of noise-free problems (injected parameters, a point ranged from
known stations).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy import integrate, stats

from tqdyn.od import estimator as od

N_RAD_S = math.sqrt(3.986004418e14 / 1.0e8 ** 3)
"""Mean motion of a circular geocentric orbit of radius 1e5 km (TianQin's), rad/s (GM_Earth of
IERS 2010)."""
SIGMA_M = 1.0  # m, position-fix noise
NAMES = ("a_t", "x0", "y0", "vx0", "vy0")
TRUE = np.array([2e-9, 3.0, -5.0, 1e-3, -2e-3])
"""Along-track acceleration (m/s^2), initial radial and along-track offsets (m) and rates (m/s)."""


def _cw_partials(t, n, lib=np):
    """Rows of the fixes (x(t), y(t)) in the parameters NAMES: (2, 5) per time t (s).

    Hill / Clohessy-Wiltshire equations (x radial, y along-track, mean motion n):
    x'' - 2 n y' - 3 n^2 x = 0, y'' + 2 n x' = a.  Homogeneous solution (c = cos nt, s = sin nt):
    x = (4 - 3c) x0 + s/n vx0 + 2 (1 - c)/n vy0, y = 6 (s - nt) x0 + y0 - 2 (1 - c)/n vx0 +
    (4 s - 3 nt)/n vy0; particular solution from rest for constant a: x_p = 2 a (nt - s)/n^2,
    y_p = a (4 (1 - c) - 3/2 n^2 t^2)/n^2 (substitution: x_p'' - 2n y_p' - 3n^2 x_p = 2as - 8as +
    6ant - 6ant + 6as = 0; y_p'' + 2n x_p' = 4ac - 3a + 4a - 4ac = a)."""
    nt = n * t
    c, s = lib.cos(nt), lib.sin(nt)
    return [[2 * (nt - s) / n ** 2, 4 - 3 * c, 0, s / n, 2 * (1 - c) / n],
            [(4 * (1 - c) - 1.5 * nt ** 2) / n ** 2, 6 * (s - nt), 1, -2 * (1 - c) / n, (4 * s - 3 * nt) / n]]


def _times(count, span_s=2 * 86400.0):
    return np.arange(count) * (span_s / count)


def _cw_jacobian(times):
    """(2 N, 5) float64: fixes ordered x(t_0), y(t_0), x(t_1), ..."""
    return np.array([row for t in times for row in _cw_partials(t, N_RAD_S)], dtype=np.float64)


def _cw_problem(times, y=None, *, sigma=SIGMA_M, apriori=None, consider=False, **kw):
    jac = _cw_jacobian(times)
    if consider:  # estimate the initial state, consider the acceleration
        est = od.Parameters(NAMES[1:], np.zeros(4))
        con = od.Parameters(NAMES[:1], [0.0], np.array([consider]))
        jac = np.concatenate([jac[:, 1:], jac[:, :1]], axis=1)
    else:
        est, con = od.Parameters(NAMES, np.zeros(5), apriori), None
    model = lambda q: (jac @ q, jac)  # noqa: E731 (linear model)
    groups = ("x", "y") * len(times)
    sig = np.full(2 * len(times), sigma) if np.ndim(sigma) == 0 else sigma
    if np.ndim(sig) == 2:
        return od.Problem(model, est, y=y, noise_covariance=sig, consider=con, groups=groups, **kw)
    return od.Problem(model, est, y=y, sigma=sig, consider=con, groups=groups, **kw)


def _mp_covariance(times, prior_info=None, blocks=None):
    """(H^T R^-1 H + P0^-1)^-1 in mpmath at 50 digits (list of lists): H from _cw_partials evaluated
    in mpmath, R^-1 = 1/sigma^2 or the inverse of each epoch's 2x2 block."""
    with mpmath.workdps(50):
        n = mpmath.sqrt(mpmath.mpf("3.986004418e14") / mpmath.mpf("1e8") ** 3)
        nmat = mpmath.zeros(5, 5)
        if blocks is None:
            winv = mpmath.eye(2) / mpmath.mpf(SIGMA_M) ** 2
        else:
            winv = mpmath.inverse(mpmath.matrix(blocks))
        for t in times:
            h = mpmath.matrix(_cw_partials(mpmath.mpf(float(t)), n, mpmath))
            nmat += h.T * winv * h
        if prior_info is not None:
            for i, v in enumerate(prior_info):
                nmat[i, i] += mpmath.mpf(v)
        return mpmath.inverse(nmat)


def _relative_error(p, ref):
    """max over (i, j) of |P_ij - ref_ij| / sqrt(ref_ii ref_jj)."""
    ref = np.array(ref.tolist(), dtype=np.float64)
    s = np.sqrt(np.diag(ref))
    return float(np.max(np.abs(p - ref) / np.outer(s, s)))


def test_cw_closed_form_solves_the_equations_of_motion():
    """The closed form of _cw_partials against DOP853 integration of the Hill equations over 2 days
    (rtol 1e-12): agreement to 5e-9 m on positions of up to 790 m (measured 7.3e-10 m)."""
    n = N_RAD_S

    def rhs(_, s):
        x, y, vx, vy = s
        return [vx, vy, 2 * n * vy + 3 * n * n * x, -2 * n * vx + TRUE[0]]

    times = _times(40)
    sol = integrate.solve_ivp(rhs, (0, times[-1]), TRUE[1:], method="DOP853", rtol=1e-12, atol=1e-12,
                              t_eval=times)
    closed = (_cw_jacobian(times) @ TRUE).reshape(-1, 2)
    assert np.max(np.abs(closed - sol.y[:2].T)) < 5e-9


@pytest.mark.parametrize("prior", [None, "state"])
def test_cw_covariance_matches_mpmath_normal_matrix(prior):
    """40 fixes of (x, y) over 2 days, sigma 1 m: the estimator's covariance of (a_t, x0, y0, vx0, vy0)
    and the covariance analysis (no data) against the mpmath inverse of the analytic normal matrix,
    relative to sqrt(P_ii P_jj): < 1e-9 (measured 8.6e-15); with an a priori of 10 m, 10 m, 1 cm/s,
    1 cm/s on the initial state (none on a_t) likewise (measured 6.3e-15).  A linear problem converges
    in 2 evaluations; the scaled condition number is 76 (bound 1e3)."""
    times = _times(40)
    sig0 = np.array([np.inf, 10.0, 10.0, 0.01, 0.01]) if prior else None
    rng = np.random.default_rng(7)
    jac = _cw_jacobian(times)
    y = jac @ TRUE + SIGMA_M * rng.standard_normal(jac.shape[0])
    problem = _cw_problem(times, y, apriori=sig0)
    fit = od.estimate(problem)
    ref = _mp_covariance(times, None if sig0 is None else [0.0] + [1 / s ** 2 for s in sig0[1:]])
    assert _relative_error(fit.covariance, ref) < 1e-9
    assert _relative_error(od.covariance_analysis(problem).covariance, ref) < 1e-9
    assert fit.iterations == 2 and fit.condition_number < 1e3
    np.testing.assert_allclose(fit.correlation, od.correlation(np.array(ref.tolist(), dtype=float)), atol=1e-9)


def test_cw_block_noise_covariance_matches_mpmath():
    """Per-fix 2x2 noise blocks (sigma_x 1 m, sigma_y 2 m, correlation 0.6) as a full (m, m)
    noise_covariance: covariance against mpmath's sum of H_k^T R_k^-1 H_k, < 1e-9 relative (measured
    2.6e-15); and a diagonal noise_covariance gives the same estimate as sigmas (to 1e-12 sigma)."""
    times = _times(30)
    blk = np.array([[1.0, 0.6 * 2.0], [0.6 * 2.0, 4.0]])
    cov = np.kron(np.eye(times.size), blk)
    jac = _cw_jacobian(times)
    y = jac @ TRUE + np.random.default_rng(3).multivariate_normal(np.zeros(2 * times.size), cov)
    fit = od.estimate(_cw_problem(times, y, sigma=cov))
    assert _relative_error(fit.covariance, _mp_covariance(times, blocks=blk.tolist())) < 1e-9
    diag_fit = od.estimate(_cw_problem(times, y, sigma=np.diag(np.diag(cov))))
    sig_fit = od.estimate(_cw_problem(times, y, sigma=np.sqrt(np.diag(cov))))
    assert np.max(np.abs(diag_fit.values - sig_fit.values) / sig_fit.sigma) < 1e-12


def test_cw_recovery_consistent_with_covariance_over_seeds():
    """25 seeds: the normalised errors e^T P^-1 e summed over seeds follow chi^2 with 25 x 5 = 125
    degrees of freedom, and the post-fit chi^2 summed over seeds chi^2 with 25 x (80 - 5); both are
    accepted within the 1e-4 and 1 - 1e-4 quantiles (two-sided 2e-4 false-alarm rate); each seed's
    chi^2 p-value lies in (1e-4, 1 - 1e-4)."""
    times = _times(40)
    jac = _cw_jacobian(times)
    q_err, q_res, dof = 0.0, 0.0, 0
    for seed in range(25):
        y = jac @ TRUE + SIGMA_M * np.random.default_rng(100 + seed).standard_normal(jac.shape[0])
        fit = od.estimate(_cw_problem(times, y))
        e = fit.values - TRUE
        q_err += float(e @ np.linalg.solve(fit.covariance, e))
        q_res += fit.chi2
        dof += fit.chi2_dof
        assert 1e-4 < fit.chi2_pvalue < 1 - 1e-4
        assert fit.groups["x"].count == 40 and fit.groups["y"].edited == 0
    assert dof == 25 * 75
    for q, k in ((q_err, 125), (q_res, dof)):
        assert stats.chi2.ppf(1e-4, k) < q < stats.chi2.ppf(1 - 1e-4, k), (q, k)


def test_consider_sensitivity_analytic():
    """Noise-free fixes made with a_t = 2e-9 m/s^2, fitted with a_t considered at 0: the state error
    equals -S_xc da (linear model, module docstring) to 1e-9 of the state sigmas (measured 2.2e-13),
    and S_xc equals -P_xx H_x^T R^-1 H_c from the mpmath normal matrix (< 1e-9 relative; measured
    3.8e-14); the covariance analysis' consider covariance P_xx + S_xc P_cc S_xc^T (sigma_a = 1e-9
    m/s^2) equals mpmath's, < 1e-9 relative to sqrt(P_ii P_jj)."""
    times = _times(40)
    jac = _cw_jacobian(times)
    problem = _cw_problem(times, jac @ TRUE, consider=1e-9)
    fit = od.estimate(problem)
    err = fit.values - TRUE[1:]
    np.testing.assert_array_less(np.abs(err + fit.sensitivity[:, 0] * TRUE[0]), 1e-9 * fit.sigma)
    with mpmath.workdps(50):
        n = mpmath.sqrt(mpmath.mpf("3.986004418e14") / mpmath.mpf("1e8") ** 3)
        m_xx, m_xc = mpmath.zeros(4, 4), mpmath.zeros(4, 1)
        for t in times:
            h = mpmath.matrix(_cw_partials(mpmath.mpf(float(t)), n, mpmath))
            hx, hc = h[:, 1:5], h[:, 0]
            m_xx += hx.T * hx
            m_xc += hx.T * hc
        p_xx = mpmath.inverse(m_xx)
        sxc = -(p_xx * m_xc)
        ref = np.array([float(v) for v in sxc])
        p_c = p_xx + sxc * mpmath.mpf("1e-18") * sxc.T
    assert np.max(np.abs(fit.sensitivity[:, 0] - ref) / np.abs(ref)) < 1e-9
    assert _relative_error(od.covariance_analysis(problem).consider_covariance, p_c) < 1e-9


def test_consider_covariance_matches_monte_carlo():
    """Initial state estimated, a_t considered with sigma 1e-9 m/s^2: over 1000 draws of a_t and of
    the noise, e^T P_c^-1 e summed follows chi^2 with 4000 degrees of freedom (accepted within the 1e-4
    and 1 - 1e-4 quantiles); the noise-only P_xx fails the same test (the consider term dominates:
    the sigma of y0 grows by a factor 19, bound > 3), so the test can fail."""
    times = _times(40)
    jac = _cw_jacobian(times)
    sig_a = 1e-9
    analysis = od.covariance_analysis(_cw_problem(times, consider=sig_a))
    assert np.max(analysis.consider_sigma / analysis.sigma) > 3
    rng = np.random.default_rng(11)
    q_c = q_x = 0.0
    trials = 1000
    for _ in range(trials):
        a = sig_a * rng.standard_normal()
        truth = np.concatenate([[a], TRUE[1:]])
        y = jac @ truth + SIGMA_M * rng.standard_normal(jac.shape[0])
        fit = od.estimate(_cw_problem(times, y, consider=sig_a))
        e = fit.values - TRUE[1:]
        q_c += float(e @ np.linalg.solve(fit.consider_covariance, e))
        q_x += float(e @ np.linalg.solve(fit.covariance, e))
    lo, hi = stats.chi2.ppf(1e-4, 4 * trials), stats.chi2.ppf(1 - 1e-4, 4 * trials)
    assert lo < q_c < hi, q_c
    assert q_x > hi, q_x
    np.testing.assert_allclose(fit.consider_covariance, analysis.consider_covariance, rtol=1e-9, atol=0)


def test_outliers_are_edited_and_the_rest_kept():
    """100 fixes (200 measurements) with 20-sigma errors added to 5 of them; 5-sigma editing removes
    exactly those 5 and the estimate equals a fit to the other 195 (to 1e-10 sigma); the normalised
    residuals equal those of the hat matrix formed with the normal equations (to 2e-12; measured
    2.1e-13); a kept fraction required above 195/200 is refused in one line."""
    times = _times(100)
    jac = _cw_jacobian(times)
    y = jac @ TRUE + SIGMA_M * np.random.default_rng(5).standard_normal(jac.shape[0])
    bad = np.array([7, 50, 123, 188, 199])
    y[bad] += 20 * SIGMA_M * np.array([1, -1, 1, -1, 1])
    fit = od.estimate(_cw_problem(times, y), edit_sigma=5.0)
    np.testing.assert_array_equal(np.flatnonzero(fit.edited), bad)
    assert np.all(np.abs(fit.normalised_residuals[bad]) > 15)
    assert fit.groups["x"].edited + fit.groups["y"].edited == 5 and fit.chi2_dof == 195 - 5
    keep = np.setdiff1d(np.arange(y.size), bad)
    sub = od.Problem(lambda q: (jac[keep] @ q, jac[keep]), od.Parameters(NAMES, np.zeros(5)), y=y[keep],
                     sigma=np.full(keep.size, SIGMA_M))
    ref = od.estimate(sub)
    assert np.max(np.abs(fit.values - ref.values) / ref.sigma) < 1e-10
    # normalised residuals from the hat matrix of the kept rows, by the normal equations:
    # kept r_i / (sigma sqrt(1 - h_i P h_i^T / sigma^2)), edited r_i / sqrt(sigma^2 + h_i P h_i^T)
    p = np.linalg.inv(jac[keep].T @ jac[keep]) * SIGMA_M ** 2
    r = y - jac @ ref.values
    hph = np.einsum("ij,jk,ik->i", jac, p, jac)
    z = np.where(fit.edited, r / np.sqrt(SIGMA_M ** 2 + hph), r / np.sqrt(SIGMA_M ** 2 - hph))
    assert np.max(np.abs(fit.normalised_residuals - z)) < 2e-12
    with pytest.raises(ValueError, match="min_kept_fraction") as err:
        od.estimate(_cw_problem(times, y), edit_sigma=5.0, min_kept_fraction=0.99)
    assert "\n" not in str(err.value)


STATIONS = np.array([[6.4e6, 0, 0], [0, 6.4e6, 0], [0, 0, 6.4e6], [-4.0e6, -4.0e6, 3.0e6],
                     [3.0e6, -5.0e6, -2.0e6], [-2.0e6, 4.0e6, -4.5e6]])
"""Known station positions (m), on the Earth's surface roughly."""
POINT = np.array([1.5e7, -2.0e7, 8.0e6])  # m
BIAS = 12.5  # m, common range bias


def _ranging_problem(start, y=None, sigma=0.01):
    def model(q):
        d = q[:3] - STATIONS
        rho = np.linalg.norm(d, axis=1)
        return rho + q[3], np.concatenate([d / rho[:, None], np.ones((len(STATIONS), 1))], axis=1)

    if y is None:
        y = np.linalg.norm(POINT - STATIONS, axis=1) + BIAS
    return od.Problem(model, od.Parameters(("x", "y", "z", "bias"), start), y=y, sigma=np.full(len(STATIONS), sigma))


def test_nonlinear_ranging_converges_from_a_poor_start():
    """Noise-free ranges (plus a common bias) from 6 known stations to a point at ~26,000 km, start
    ~6,000 km and 1 km off: converges in <= 8 model evaluations (measured 7) to the exact point and
    bias within 3e-7 m (measured 4.3e-8 m); max_iterations = 2 is refused in one line naming the last step."""
    start = np.concatenate([POINT + np.array([5.0e6, -3.0e6, 2.0e6]), [1000.0]])
    fit = od.estimate(_ranging_problem(start))
    assert fit.iterations <= 8
    assert np.max(np.abs(fit.values - np.concatenate([POINT, [BIAS]]))) < 3e-7
    with pytest.raises(ValueError, match="no convergence in max_iterations = 2: the last step was") as err:
        od.estimate(_ranging_problem(start), max_iterations=2)
    assert "\n" not in str(err.value)


def _sum_problem(y=None):
    t = np.linspace(0.0, 10.0, 20)
    jac = np.stack([t, t, t * t], axis=1)  # h = (a + b) t + c t^2: only a + b is determined
    return od.Problem(lambda q: (jac @ q, jac), od.Parameters(("a", "b", "c"), np.zeros(3)),
                      y=np.zeros(t.size) if y is None else y, sigma=np.ones(t.size))


def test_refusals_are_one_line():
    """Unobservable parameters named (a, b, not c), a non-finite measurement, non-positive sigmas, a
    priori covariance not positive definite: each a ValueError of one line naming the field."""
    cases = [
        (lambda: od.estimate(_sum_problem()), r"unobservable: .* determine a, b \("),
        (lambda: od.covariance_analysis(_sum_problem()), r"unobservable: .* determine a, b \("),
        (lambda: _sum_problem(np.where(np.arange(20) == 3, np.nan, 0.0)), r"^y\[3\] = nan: measurements must be finite"),
        (lambda: od.Problem(lambda q: q, od.Parameters(("a",), [0.0]), y=[1.0, 2.0], sigma=[1.0, 0.0]),
         r"^sigma\[1\] = 0.0: measurement sigmas must be finite and > 0"),
        (lambda: od.Problem(lambda q: q, od.Parameters(("a",), [0.0]), y=[1.0], sigma=[-2.0]), r"^sigma\[0\] = -2.0"),
        (lambda: od.Parameters(("a", "b"), [0.0, 0.0], [[1.0, 2.0], [2.0, 1.0]]).information_root(),
         "not positive definite"),
        (lambda: od.estimate(od.Problem(lambda q: (np.array([np.nan]), np.ones((1, 1))), od.Parameters(("a",), [0.0]),
                                        y=[1.0], sigma=[1.0])), "model: non-finite h or H at measurement 0"),
    ]
    for call, pattern in cases:
        with pytest.raises(ValueError, match=pattern) as err:
            call()
        assert "\n" not in str(err.value), str(err.value)
    with pytest.raises(ValueError) as err:
        od.estimate(_sum_problem())
    assert "c" not in str(err.value).split("determine ")[1].split(" (")[0]


def test_a_priori_makes_the_problem_observable():
    """The same degenerate problem with an a priori sigma of 1 on b: accepted; the estimate of a + b
    from data y = 3 t is 3 (to 1e-12) and the a priori holds b at its a priori value 0 in the limit of
    exact data (the data leave b - a free, a priori b = 0 decides)."""
    t = np.linspace(0.0, 10.0, 20)
    jac = np.stack([t, t, t * t], axis=1)
    prob = od.Problem(lambda q: (jac @ q, jac), od.Parameters(("a", "b", "c"), np.zeros(3), [np.inf, 1.0, np.inf]),
                      y=3.0 * t, sigma=np.full(t.size, 1e-6))
    fit = od.estimate(prob)
    assert abs(fit.value("a") + fit.value("b") - 3.0) < 1e-12
    assert abs(fit.value("b")) < 1e-9 and abs(fit.value("c")) < 1e-12
