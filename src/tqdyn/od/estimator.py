"""Batch weighted least squares (Gauss-Newton) with a priori information, consider parameters,
outlier editing and covariance analysis, on a generic measurement model.

Problem.  Parameters x (n,) are estimated (initial states, acceleration parameters, biases: any unit,
each parameter in its own); parameters c (n_c,) are *considered*: held at their nominal values c0 and
not estimated, but their a priori uncertainty P_cc enters the covariance.  A model callable maps the
full vector q = (x, c) (n + n_c,) to the computed measurements h(q) (m,) and the Jacobian
H = dh/dq (m, n + n_c) = [H_x | H_c].  The measurements y (m,) have a noise covariance R (m, m):
diagonal from sigmas (m,), or a full (block) matrix.  An a priori estimate x0 with covariance P0 may
be given (a parameter without a priori information has an infinite sigma).  The estimate minimises

    J(x) = (y - h(x, c0))^T R^-1 (y - h(x, c0)) + (x - x0)^T P0^-1 (x - x0).

Whitening.  R = L L^T (Cholesky; L = diag(sigma) for sigmas) and P0^-1 = S0^T S0 (S0 = L0^-1,
P0 = L0 L0^T) turn J into ||b - A dx||^2 with, at the iterate x_k,

    A = [L^-1 H_x ; S0],   b = [L^-1 (y - h(x_k, c0)) ; S0 (x0 - x_k)].

Solution (Gauss-Newton).  The columns of A are scaled to unit norm (D = diag(1 / ||A_j||)), the
scaled matrix is factorised by its singular value decomposition A D = U S V^T, and the step is
dx = D V S^-1 U^T b; the normal equations are never formed, so the accuracy is governed by the
condition number kappa = s_max / s_min of A D (reported), not by its square.  A problem with
kappa above ``max_condition`` is refused as unobservable, naming the parameters with components
>= 0.1 on the singular vectors of the small singular values (the null space).  The iteration stops
when max_j |dx_j| / sigma_j < ``step_tol`` (sigma from the current linearisation); the converged
estimate includes that last step and the post-fit residuals are updated linearly with it
(r = r_k - H_x dx, an O(dx^2) approximation, the same order as the step itself).

Covariance.  P_xx = (H_x^T R^-1 H_x + P0^-1)^-1 = D V S^-2 V^T D (Tapley, Schutz & Born,
"Statistical Orbit Determination", 2004, section 4.3: the covariance of the batch estimate with a
priori information); correlation rho_ij = P_ij / sqrt(P_ii P_jj).

Consider parameters (Tapley, Schutz & Born 2004, section 6.3, "consider covariance analysis", with
the a priori cross-covariance P_xc = 0 of that section).  With M_xc = H_x^T R^-1 H_c the sensitivity
matrix is

    S_xc = -P_xx M_xc                                     (n, n_c),

the consider covariance of the estimate and its cross-covariance with c are

    P_c,xx = P_xx + S_xc P_cc S_xc^T,      P_c,xc = S_xc P_cc,

and an error dc = c_true - c0 of the consider parameters moves the estimate by -S_xc dc
(x_hat - x_true = P_xx H_x^T R^-1 (H_c dc + noise) for a linear model).  Computed stably as
S_xc = -D V S^-1 U_d^T (L^-1 H_c), U_d the data rows of U.

Outlier editing (optional, ``edit_sigma`` = k).  After convergence every measurement gets its
normalised residual z_i = r_i / sqrt(v_i) with the post-fit residual variance v_i = R_ii - (H_x P_xx
H_x^T)_ii for a measurement used in the fit and R_ii + (H_x P_xx H_x^T)_ii for one left out (its
prediction error); measurements with |z_i| > k are left out and the fit is repeated (from the last
estimate) until the set no longer changes.  Edited measurements can be readmitted.  Fewer kept than
``min_kept_fraction`` of the measurements is refused.

Statistics.  chi^2 = (whitened post-fit data residuals)^2 summed over the kept measurements plus the
a priori term ||S0 (x_hat - x0)||^2; degrees of freedom m_kept + (number of a priori rows) - n;
p-value = P(chi^2_dof >= chi^2) (scipy.stats.chi2.sf).  Editing removes the largest residuals, so
the p-value after editing is biased high.  Per group of measurements (e.g. a measurement type or
station): count, rms residual (measurement unit), rms of r_i / sqrt(R_ii) and of z_i.

Covariance analysis (:func:`covariance_analysis`): the same covariance, consider covariance,
sensitivity and condition number from H at the nominal parameters and R alone, without data.

Units: whatever the model uses, consistently: y, h, sigma in the measurement's unit (a mix of
units is fine: each row is whitened by its own sigma), x in each parameter's unit, H in
measurement unit per parameter unit.  Every array is float64.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy import linalg, stats

__all__ = ["Covariance", "Estimate", "GroupStatistics", "Parameters", "Problem", "correlation",
           "covariance_analysis", "estimate"]

#: Components of a null-space singular vector at or above this magnitude name their parameter.
NULL_COMPONENT = 0.1


def _one_line(msg: str) -> str:
    return " ".join(msg.split())


@dataclass(frozen=True)
class Parameters:
    """Named parameters with a priori values and an optional a priori covariance.

    names: (n,) distinct strings; values: (n,) a priori (estimated parameters: the first
    linearisation point) or nominal (consider parameters) values, each in its own unit;
    covariance: None (no a priori information), (n,) a priori sigmas (``inf``: none for that
    parameter) or a symmetric positive definite (n, n) matrix, in the parameters' units squared."""

    names: tuple
    values: np.ndarray
    covariance: np.ndarray | None = None

    def __post_init__(self):
        names = tuple(str(v) for v in self.names)
        if len(set(names)) != len(names):
            raise ValueError(f"parameter names = {names!r}: must be distinct")
        values = np.array(self.values, dtype=np.float64).reshape(-1)
        if values.size != len(names):
            raise ValueError(f"parameter values: {values.size} given for {len(names)} names")
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise ValueError(f"parameter {names[bad[0]]!r} = {values[bad[0]]}: a priori value must be finite")
        cov = self.covariance
        if cov is not None:
            cov = np.array(cov, dtype=np.float64)
            n = len(names)
            if cov.shape == (n,):
                bad = np.flatnonzero(~(cov > 0) | np.isnan(cov))
                if bad.size:
                    raise ValueError(f"a priori sigma of {names[bad[0]]!r} = {cov[bad[0]]}: must be > 0 (inf: none)")
            elif cov.shape == (n, n):
                if not np.all(np.isfinite(cov)) or not np.allclose(cov, cov.T, rtol=1e-12, atol=0):
                    raise ValueError("a priori covariance: must be a finite symmetric (n, n) matrix")
            else:
                raise ValueError(f"a priori covariance: shape {cov.shape}, expected ({n},) sigmas or ({n}, {n})")
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "covariance", cov)

    @property
    def size(self) -> int:
        return len(self.names)

    def information_root(self) -> np.ndarray:
        """S0 (k, n) with S0^T S0 = P0^-1 (k = n for a matrix, the number of finite sigmas for
        sigmas, 0 without a priori information); unit 1 / parameter unit."""
        n, cov = self.size, self.covariance
        if cov is None:
            return np.zeros((0, n))
        if cov.ndim == 1:
            rows = np.flatnonzero(np.isfinite(cov))
            s0 = np.zeros((rows.size, n))
            s0[np.arange(rows.size), rows] = 1.0 / cov[rows]
            return s0
        try:
            low = linalg.cholesky(cov, lower=True)
        except linalg.LinAlgError:
            raise ValueError("a priori covariance: not positive definite") from None
        return linalg.solve_triangular(low, np.eye(n), lower=True)

    def full_covariance(self) -> np.ndarray:
        """The a priori covariance as an (n, n) matrix (consider parameters: all sigmas finite)."""
        cov = self.covariance
        if cov is None or (cov.ndim == 1 and not np.all(np.isfinite(cov))):
            raise ValueError(f"consider parameters {self.names}: need a finite a priori covariance")
        if cov.ndim == 1:
            return np.diag(cov ** 2)
        self.information_root()  # positive definiteness
        return cov


@dataclass(frozen=True)
class Problem:
    """A least-squares problem: model, measurements, noise and parameters.

    model: callable q -> (h, H): q (n + n_c,) the estimated then the considered parameters'
    values; h (m,) computed measurements; H (m, n + n_c) their partial derivatives.
    estimated, consider: :class:`Parameters` (consider: None or with a finite covariance).
    y: (m,) measurements (None for :func:`covariance_analysis`); sigma: (m,) noise sigmas, or
    noise_covariance: (m, m) symmetric positive definite (one of the two), measurement units.
    groups: optional (m,) labels (e.g. measurement type or station) for per-group statistics."""

    model: Callable
    estimated: Parameters
    y: np.ndarray | None = None
    sigma: np.ndarray | None = None
    noise_covariance: np.ndarray | None = None
    consider: Parameters | None = None
    groups: tuple | None = None

    def __post_init__(self):
        if (self.sigma is None) == (self.noise_covariance is None):
            raise ValueError("sigma, noise_covariance: give exactly one of them")
        if self.sigma is not None:
            sig = np.array(self.sigma, dtype=np.float64).reshape(-1)
            bad = np.flatnonzero(~(np.isfinite(sig) & (sig > 0)))
            if bad.size:
                raise ValueError(f"sigma[{bad[0]}] = {sig[bad[0]]}: measurement sigmas must be finite and > 0")
            object.__setattr__(self, "sigma", sig)
            m = sig.size
        else:
            cov = np.array(self.noise_covariance, dtype=np.float64)
            if cov.ndim != 2 or cov.shape[0] != cov.shape[1]:
                raise ValueError(f"noise_covariance: shape {cov.shape}, expected (m, m)")
            if not np.all(np.isfinite(cov)) or not np.allclose(cov, cov.T, rtol=1e-12, atol=0):
                raise ValueError("noise_covariance: must be a finite symmetric matrix")
            d = np.diag(cov)
            bad = np.flatnonzero(~(d > 0))
            if bad.size:
                raise ValueError(f"noise_covariance[{bad[0]}, {bad[0]}] = {d[bad[0]]}: variances must be > 0")
            object.__setattr__(self, "noise_covariance", cov)
            m = cov.shape[0]
        if self.y is not None:
            y = np.array(self.y, dtype=np.float64).reshape(-1)
            if y.size != m:
                raise ValueError(f"y: {y.size} measurements, {m} sigmas")
            bad = np.flatnonzero(~np.isfinite(y))
            if bad.size:
                raise ValueError(f"y[{bad[0]}] = {y[bad[0]]}: measurements must be finite")
            object.__setattr__(self, "y", y)
        if self.groups is not None:
            groups = tuple(self.groups)
            if len(groups) != m:
                raise ValueError(f"groups: {len(groups)} labels for {m} measurements")
            object.__setattr__(self, "groups", groups)
        if self.consider is not None:
            self.consider.full_covariance()
            clash = set(self.consider.names) & set(self.estimated.names)
            if clash:
                raise ValueError(f"parameters {sorted(clash)}: both estimated and considered")

    @property
    def size(self) -> int:
        """Number of measurements m."""
        return self.sigma.size if self.sigma is not None else self.noise_covariance.shape[0]

    @property
    def variances(self) -> np.ndarray:
        """R_ii (m,), measurement units squared."""
        return self.sigma ** 2 if self.sigma is not None else np.diag(self.noise_covariance).copy()

    def whitener(self, kept: np.ndarray) -> Callable:
        """Function X[kept] -> L_k^-1 X[kept] for the kept measurements (bool (m,)); X (m,) or (m, k)."""
        if self.sigma is not None:
            s = self.sigma[kept]
            return lambda x: (x[kept].T / s).T
        sub = self.noise_covariance[np.ix_(kept, kept)]
        try:
            low = linalg.cholesky(sub, lower=True)
        except linalg.LinAlgError:
            raise ValueError("noise_covariance: not positive definite") from None
        return lambda x: linalg.solve_triangular(low, x[kept], lower=True)


@dataclass(frozen=True)
class GroupStatistics:
    """Post-fit residual statistics of one group of measurements: count (kept), edited (left out),
    rms (measurement unit, kept), weighted_rms (of r_i / sqrt(R_ii), kept) and normalised_rms (of
    the normalised residuals z_i, kept)."""

    count: int
    edited: int
    rms: float
    weighted_rms: float
    normalised_rms: float


@dataclass(frozen=True)
class Covariance:
    """Covariance of the estimated parameters.

    names: (n,); values: (n,) estimate (or the nominal values of a covariance analysis);
    covariance: P_xx (n, n), measurement noise (and a priori) only; sigma: sqrt(diag P_xx) (n,);
    correlation: (n, n); consider_names: (n_c,); sensitivity: S_xc (n, n_c) (module docstring);
    consider_covariance: P_c,xx (n, n) (= P_xx without consider parameters); consider_sigma (n,);
    condition_number: kappa of the column-scaled whitened Jacobian (a priori rows included).
    Units: each parameter's own."""

    names: tuple
    values: np.ndarray
    covariance: np.ndarray
    sigma: np.ndarray
    correlation: np.ndarray
    consider_names: tuple
    sensitivity: np.ndarray
    consider_covariance: np.ndarray
    consider_sigma: np.ndarray
    condition_number: float

    def value(self, name: str) -> float:
        """The estimate of parameter ``name``."""
        return float(self.values[self.names.index(name)])


@dataclass(frozen=True)
class Estimate(Covariance):
    """A batch least-squares estimate (:func:`estimate`): the :class:`Covariance` fields and

    residuals: y - h(x_hat) (m,) (linearised at the last iterate, module docstring), measurement
    units; normalised_residuals: z (m,) with the post-fit residual variances; edited: (m,) bool,
    True for the measurements left out; chi2, chi2_dof, chi2_pvalue: module docstring; iterations:
    model evaluations; last_step: max |dx_j / sigma_j| of the last step; groups: dict label ->
    :class:`GroupStatistics` (empty without groups)."""

    residuals: np.ndarray = field(default=None)
    normalised_residuals: np.ndarray = field(default=None)
    edited: np.ndarray = field(default=None)
    chi2: float = math.nan
    chi2_dof: int = 0
    chi2_pvalue: float = math.nan
    iterations: int = 0
    last_step: float = math.nan
    groups: dict = field(default_factory=dict)


def correlation(cov: np.ndarray) -> np.ndarray:
    """Correlation matrix P_ij / sqrt(P_ii P_jj) of a covariance (n, n)."""
    s = np.sqrt(np.diag(cov))
    return cov / np.outer(s, s)


class _Linearised:
    """The column-scaled SVD of A = [L^-1 H_x ; S0] (module docstring): A D = U S V^T."""

    def __init__(self, a: np.ndarray, n_data: int, names: tuple, max_condition: float):
        if a.shape[0] < a.shape[1]:  # fewer equations than parameters: the zero rows expose the null space
            a = np.vstack([a, np.zeros((a.shape[1] - a.shape[0], a.shape[1]))])
        norms = np.sqrt(np.sum(a * a, axis=0))
        self.scale = np.where(norms > 0, norms, 1.0)  # D = diag(1 / scale)
        u, s, vt = np.linalg.svd(a / self.scale, full_matrices=False)
        self.condition = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
        if not self.condition <= max_condition:
            small = s < s[0] / max_condition
            comp = np.max(np.abs(vt[small]), axis=0)
            null = [nm for nm, v in zip(names, comp) if v >= NULL_COMPONENT]
            raise ValueError(_one_line(
                f"unobservable: the measurements and a priori information do not determine {', '.join(null)} "
                f"(null-space direction of the scaled normal matrix; condition number {self.condition:.3g} > "
                f"max_condition = {max_condition:.3g})"))
        self.u, self.s, self.vt, self.n_data = u, s, vt, n_data
        self.g = (vt.T / s) / self.scale[:, None]  # D V S^-1 (n, n)

    def step(self, b: np.ndarray) -> np.ndarray:
        return self.g @ (self.u.T @ b)

    def covariance(self) -> np.ndarray:
        p = self.g @ self.g.T
        return 0.5 * (p + p.T)

    def sensitivity(self, whitened_hc: np.ndarray) -> np.ndarray:
        """S_xc = -D V S^-1 U_d^T (L^-1 H_c) (n, n_c)."""
        return -self.g @ (self.u[: self.n_data].T @ whitened_hc)


def _evaluate(problem: Problem, q: np.ndarray, n_total: int):
    out = problem.model(q.copy())
    try:
        h, jac = out
    except (TypeError, ValueError):
        raise ValueError("model: must return (h, H)") from None
    h = np.asarray(h, dtype=np.float64).reshape(-1)
    jac = np.asarray(jac, dtype=np.float64)
    m = problem.size
    if h.shape != (m,) or jac.shape != (m, n_total):
        raise ValueError(f"model: returned h {h.shape} and H {jac.shape}, expected ({m},) and ({m}, {n_total})")
    if not (np.all(np.isfinite(h)) and np.all(np.isfinite(jac))):
        i = int(np.flatnonzero(~(np.isfinite(h) & np.all(np.isfinite(jac), axis=1)))[0])
        raise ValueError(f"model: non-finite h or H at measurement {i} (h = {h[i]}) at the current parameters")
    return h, jac


def _consider_parts(problem: Problem):
    if problem.consider is None:
        return (), np.zeros(0), np.zeros((0, 0))
    return problem.consider.names, problem.consider.values, problem.consider.full_covariance()


def _covariance_fields(lin: _Linearised, whitened_hc: np.ndarray, pcc: np.ndarray, names, cnames,
                       values) -> dict:
    p = lin.covariance()
    sxc = lin.sensitivity(whitened_hc)
    pc = p + sxc @ pcc @ sxc.T
    pc = 0.5 * (pc + pc.T)
    return dict(names=names, values=values, covariance=p, sigma=np.sqrt(np.diag(p)), correlation=correlation(p),
                consider_names=cnames, sensitivity=sxc, consider_covariance=pc,
                consider_sigma=np.sqrt(np.diag(pc)), condition_number=lin.condition)


def covariance_analysis(problem: Problem, *, max_condition: float = 1e10) -> Covariance:
    """Predicted covariance without data: H at the a priori / nominal parameter values, the noise
    covariance and the a priori information (module docstring).  ``problem.y`` is not used.
    Refuses an unobservable problem (condition number above ``max_condition``) in one line."""
    est = problem.estimated
    cnames, c0, pcc = _consider_parts(problem)
    n = est.size
    _, jac = _evaluate(problem, np.concatenate([est.values, c0]), n + c0.size)
    kept = np.ones(problem.size, dtype=bool)
    white = problem.whitener(kept)
    s0 = est.information_root()
    lin = _Linearised(np.vstack([white(jac[:, :n]), s0]), int(kept.sum()), est.names, max_condition)
    return Covariance(**_covariance_fields(lin, white(jac[:, n:]), pcc, est.names, cnames, est.values.copy()))


def _gauss_newton(problem, x, c0, kept, step_tol, max_iterations, max_condition):
    """Iterate to convergence on the kept measurements; returns (x, lin, r_post, jac, white, iterations, ratio)."""
    est = problem.estimated
    n = est.size
    s0 = est.information_root()
    white = problem.whitener(kept)
    ratio, worst = math.inf, est.names[0] if n else ""
    for it in range(1, max_iterations + 1):
        h, jac = _evaluate(problem, np.concatenate([x, c0]), n + c0.size)
        r = problem.y - h
        lin = _Linearised(np.vstack([white(jac[:, :n]), s0]), int(kept.sum()), est.names, max_condition)
        dx = lin.step(np.concatenate([white(r), s0 @ (est.values - x)]))
        z = np.abs(dx) / np.sqrt(np.diag(lin.covariance()))
        k = int(np.argmax(z))
        ratio, worst = float(z[k]), est.names[k]
        x = x + dx
        if ratio < step_tol:
            return x, lin, r - jac[:, :n] @ dx, jac, white, it, ratio
    raise ValueError(_one_line(
        f"no convergence in max_iterations = {max_iterations}: the last step was {ratio:.3g} sigma "
        f"(parameter {worst}), step_tol = {step_tol:.3g}"))


def _normalised(problem, lin, jac_x, r, kept):
    """z_i = r_i / sqrt(R_ii -+ (H P H^T)_ii) (module docstring), (m,)."""
    hph = np.sum((jac_x @ lin.g) ** 2, axis=1)
    rii = problem.variances
    var = np.where(kept, rii - hph, rii + hph)
    tiny = 1e-14 * rii
    return np.where(var > tiny, r / np.sqrt(np.maximum(var, tiny)), 0.0)


def _group_statistics(problem, r, z, kept) -> dict:
    if problem.groups is None:
        return {}
    labels = np.empty(len(problem.groups), dtype=object)
    labels[:] = problem.groups
    w = r / np.sqrt(problem.variances)
    out = {}
    for g in dict.fromkeys(problem.groups):
        sel = labels == g
        k = sel & kept
        nk = int(k.sum())

        def rms(v):
            return float(np.sqrt(np.mean(v[k] ** 2))) if nk else math.nan

        out[g] = GroupStatistics(count=nk, edited=int((sel & ~kept).sum()), rms=rms(r), weighted_rms=rms(w),
                                 normalised_rms=rms(z))
    return out


def estimate(problem: Problem, *, step_tol: float = 1e-4, max_iterations: int = 20,
             max_condition: float = 1e10, edit_sigma: float | None = None, min_kept_fraction: float = 0.5,
             max_edit_passes: int = 10) -> Estimate:
    """Batch weighted least squares by Gauss-Newton (module docstring), starting from the a priori
    values of ``problem.estimated`` with the consider parameters at their nominal values.

    step_tol: convergence when max_j |dx_j / sigma_j| < step_tol; max_iterations: model evaluations
    per editing pass; max_condition: refusal threshold of the scaled condition number; edit_sigma:
    k of the k-sigma editing (None: no editing); min_kept_fraction: refusal below this kept
    fraction; max_edit_passes: refusal when the edited set still changes after this many passes.
    Every refusal is a ValueError with one line."""
    if problem.y is None:
        raise ValueError("y: no measurements (use covariance_analysis for a prediction without data)")
    if not (step_tol > 0 and max_iterations >= 1):
        raise ValueError(f"step_tol = {step_tol}, max_iterations = {max_iterations}: need > 0 and >= 1")
    if edit_sigma is not None and not edit_sigma > 0:
        raise ValueError(f"edit_sigma = {edit_sigma}: must be > 0 (or None: no editing)")
    est = problem.estimated
    if est.size == 0:
        raise ValueError("estimated: no parameters")
    cnames, c0, pcc = _consider_parts(problem)
    n, m = est.size, problem.size
    kept = np.ones(m, dtype=bool)
    x = est.values.copy()
    iterations = 0
    for npass in range(max_edit_passes + 1):
        x, lin, r, jac, white, it, ratio = _gauss_newton(problem, x, c0, kept, step_tol, max_iterations,
                                                         max_condition)
        iterations += it
        z = _normalised(problem, lin, jac[:, :n], r, kept)
        if edit_sigma is None:
            break
        new = np.abs(z) <= edit_sigma
        if new.sum() < min_kept_fraction * m:
            raise ValueError(_one_line(
                f"outlier editing: {int(new.sum())} of {m} measurements within {edit_sigma:g} sigma, fewer than "
                f"min_kept_fraction = {min_kept_fraction:g} (check the model or the sigmas)"))
        if np.array_equal(new, kept):
            break
        if npass == max_edit_passes:
            raise ValueError(_one_line(
                f"outlier editing: the edited set still changes after max_edit_passes = {max_edit_passes}"))
        kept = new
    s0 = est.information_root()
    rw = white(r)
    chi2_data = float(rw @ rw)
    pr = s0 @ (x - est.values)
    chi2 = chi2_data + float(pr @ pr)
    dof = int(kept.sum()) + s0.shape[0] - n
    pval = float(stats.chi2.sf(chi2, dof)) if dof > 0 else math.nan
    cov = _covariance_fields(lin, white(jac[:, n:]), pcc, est.names, cnames, x)
    return Estimate(**cov, residuals=r, normalised_residuals=z, edited=~kept, chi2=chi2, chi2_dof=dof,
                    chi2_pvalue=pval, iterations=iterations, last_step=ratio,
                    groups=_group_statistics(problem, r, z, kept))
