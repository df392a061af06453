"""Defining properties of the Gauss-Jackson / summed Adams coefficients in ``_multistep_coefficients``.

Reference: exact polynomial solutions.  For order K the formulas interpolate
the accelerations by a polynomial of degree K (Berry & Healy 2004, J.
Astronaut. Sci. 52, 331; Henrici 1962, ch. 5), so a motion r(t) that is a
polynomial of degree <= K + 2 (r'' of degree <= K) is integrated *exactly*:
started from its exact values at t_0 .. t_K (the sums fixed by the corrector
at t_K, as the propagator does after its start-up), every predicted and
corrected position and velocity of the following steps must equal r(t_n),
r'(t_n) exactly.  The test steps the summed form here in exact rational
arithmetic (``fractions.Fraction``), independently of the compiled kernels
and of the generating script; a motion of degree K + 3 must not be exact
(the order is not higher than stated).  The leading error constants are
checked against the one-step error on t^(K+3).
"""

from __future__ import annotations

import importlib.util
import pathlib
import random
from fractions import Fraction
from math import comb, factorial

import pytest

from tqdyn.numerics import _multistep_coefficients as tab
from tqdyn.numerics import multistep as ms

ROOT = pathlib.Path(__file__).resolve().parent.parent


def _poly(coefs):
    """r(t), r'(t), r''(t) of the polynomial sum_i c_i t^i (exact Fractions)."""
    def r(t):
        return sum(c * t ** i for i, c in enumerate(coefs))

    def v(t):
        return sum(i * c * t ** (i - 1) for i, c in enumerate(coefs) if i >= 1)

    def a(t):
        return sum(i * (i - 1) * c * t ** (i - 2) for i, c in enumerate(coefs) if i >= 2)

    return r, v, a


def _run(order, coefs, h, corrector, steps):
    """Step the summed form of ``order`` on the polynomial motion ``coefs``
    (exact data at t_0 .. t_K, then ``steps`` steps of ``corrector`` =
    (corrections, evaluated)); returns the largest |error| of the returned
    positions and velocities."""
    c = ms.load_coefficients(order)
    pp, pv, cp, cv = c.rows
    r, v, a = _poly(coefs)
    t0 = Fraction(1, 3)
    F = [a(t0 + j * h) for j in range(order + 1)]  # oldest first; F[-1] = f_K
    tK = t0 + order * h
    # sums at t_K from the corrector at t_K
    s_prev = v(tK) / h - sum(cv[j] * F[-1 - j] for j in range(order + 1))
    S_prev = r(tK) / h ** 2 - sum(cp[j] * F[-1 - j] for j in range(order + 1))
    s = s_prev + F[-1]
    S = S_prev + s
    n_corr, evaluated = corrector
    worst = Fraction(0)
    for n in range(steps):
        t1 = tK + (n + 1) * h
        rp = h ** 2 * (S + sum(pp[j] * F[-1 - j] for j in range(order + 1)))
        vp = h * (s + sum(pv[j] * F[-1 - j] for j in range(order + 1)))
        y = (rp, vp)
        f = a(t1)  # the acceleration is a function of time: evaluating gives the exact value
        for it in range(n_corr):
            rc = h ** 2 * (S + cp[0] * f + sum(cp[j] * F[-j] for j in range(1, order + 1)))
            vc = h * (s + cv[0] * f + sum(cv[j] * F[-j] for j in range(1, order + 1)))
            y = (rc, vc)
        worst = max(worst, abs(y[0] - r(t1)), abs(y[1] - v(t1)))
        F = F[1:] + [f]
        s += f
        S += s
    return worst


@pytest.mark.parametrize("order", ms.ORDERS)
def test_exact_on_polynomials_of_the_orders_degree(order):
    rng = random.Random(order)
    h = Fraction(3, 2)
    for degree in (order + 2, order + 1, 3):
        coefs = [Fraction(rng.randint(-9, 9), rng.randint(1, 5)) for _ in range(degree + 1)]
        for corrector in ((0, True), (1, False), (1, True), (2, True)):
            assert _run(order, coefs, h, corrector, steps=order + 3) == 0, (degree, corrector)
    coefs = [Fraction(0)] * (order + 3) + [Fraction(1)]  # t^(K+3): one degree too many
    assert _run(order, coefs, h, (1, True), steps=2) != 0


@pytest.mark.parametrize("order", (4, 8, 10, 16))
def test_error_constants(order):
    """One step from exact sums on r = t^(K+3) (r'' = (K+3)(K+2) t^(K+1),
    nabla^(K+1) r'' = (K+3)! h^(K+1)): the position errors of the predictor
    and corrector are ERROR_* h^2 nabla^(K+1) f, exactly (the next term,
    nabla^(K+2) f, vanishes)."""
    c = ms.load_coefficients(order)
    pp, _, cp, _ = c.rows
    h = Fraction(1)
    K = order
    r, _, a = _poly([Fraction(0)] * (K + 3) + [Fraction(1)])
    # the exact second sum S_n: from the full series, which terminates for this motion
    # (nabla^(K+2) f = 0): r_{n+1} = h^2 (S_n + sum_{k=0}^{K+1} P_{k+2} nabla^k f_n)
    series = _generator().difference_series(K + 6)
    n = Fraction(K + 5)
    f = [a(n - j) for j in range(K + 3)]  # f_n, f_{n-1}, ...

    def nabla(k):  # nabla^k f_n
        return sum((-1) ** j * comb(k, j) * f[j] for j in range(k + 1))

    S = r(n + 1) / h ** 2 - sum(series["P"][k + 2] * nabla(k) for k in range(K + 2))
    pred = h ** 2 * (S + sum(pp[j] * f[j] for j in range(K + 1)))
    lead = Fraction(factorial(K + 3)) * h ** (K + 1)  # nabla^(K+1) f for f = (K+3)(K+2) t^(K+1)
    assert r(n + 1) - pred == c.errors["PREDICTOR_POSITION"] * h ** 2 * lead
    f1 = a(n + 1)
    g = [f1] + f  # f_{n+1}, f_n, ...
    corr = h ** 2 * (S + sum(cp[j] * g[j] for j in range(K + 1)))
    assert r(n + 1) - corr == c.errors["CORRECTOR_POSITION"] * h ** 2 * lead


def _generator():
    spec = importlib.util.spec_from_file_location("gen_ms", ROOT / "tools" / "gen_multistep_coefficients.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_shipped_table_is_the_scripts_output():
    """The generated module holds what tools/gen_multistep_coefficients.py computes (no hand edits)."""
    gen = _generator()
    assert tuple(gen.ORDERS) == tuple(tab.ORDERS)
    for K in tab.ORDERS:
        rows = gen.coefficients(K)
        for name in ms.ROW_NAMES:
            assert tuple(str(x) for x in rows[name]) == getattr(tab, name)[K]
            assert str(rows["ERROR_" + name]) == getattr(tab, "ERROR_" + name)[K]


def test_known_low_order_values():
    """Classical values (Henrici 1962, tables 5.3, 5.4): the difference-form
    Stormer (1, 0, 1/12, 1/12, 19/240, 3/40), Cowell (1, -1, 1/12, 0, -1/240,
    -1/240), Adams-Bashforth (1, 1/2, 5/12, 3/8, 251/720) and Adams-Moulton
    (1, -1/2, -1/12, -1/24, -19/720) series."""
    s = _generator().difference_series(6)
    assert s["P"][:6] == [1, 0, Fraction(1, 12), Fraction(1, 12), Fraction(19, 240), Fraction(3, 40)]
    assert s["G"][:6] == [1, -1, Fraction(1, 12), 0, Fraction(-1, 240), Fraction(-1, 240)]
    assert s["Q"][:5] == [1, Fraction(1, 2), Fraction(5, 12), Fraction(3, 8), Fraction(251, 720)]
    assert s["A"][:5] == [1, Fraction(-1, 2), Fraction(-1, 12), Fraction(-1, 24), Fraction(-19, 720)]


def test_unknown_order_is_one_line():
    with pytest.raises(ValueError, match=r"^integrator.order: 3 is not available; allowed: 4..16$"):
        ms.load_coefficients(3)


def _step_matrix(order, corrector, z):
    """The linear map of one step on (S, s, f_n .. f_{n-K}) for r'' = z r (h = 1, float64)."""
    import numpy as np

    c = ms.load_coefficients(order)
    pp = np.array([float(x) for x in c.rows[0]])
    cp = np.array([float(x) for x in c.rows[2]])
    n_corr, evaluated = corrector
    n = order + 3
    M = np.zeros((n, n))
    for col in range(n):
        state = np.zeros(n)
        state[col] = 1.0
        S, s, F = state[0], state[1], state[2:]
        f = z * (S + pp @ F)
        for it in range(n_corr):
            r = S + cp[0] * f + cp[1:] @ F[:-1]
            if evaluated or it < n_corr - 1:
                f = z * r
        s1 = s + f
        M[:, col] = np.concatenate([[S + s1, s1, f], F[:-1]])
    return M


def stability_limit(order, corrector):
    """Largest h w (to 1e-3) for which no eigenvalue of the step map on
    r'' = -w^2 r exceeds 1 + 1e-9 in modulus (scanned from 0)."""
    import numpy as np

    w = 1e-3
    while w < 2.0:
        if np.max(np.abs(np.linalg.eigvals(_step_matrix(order, corrector, -w * w)))) > 1 + 1e-9:
            return w - 1e-3
        w += 1e-3
    return w


@pytest.mark.parametrize("order", (8, 10, 12, 16))
def test_stability_intervals(order, record_number):
    """Stability on r'' = -w^2 r (no root of the step's companion matrix
    above 1 + 1e-9 in modulus): every scheme is stable at h w = 0.01, more
    than twice LISA's h n = 4.3e-3 at 6 h steps (TianQin: 1.0e-3), and the
    corrector widens the interval (the predictor alone, and PEC, whose table
    holds the predicted accelerations, have the smaller one).  Measured h w
    limits: 0.175 / 0.090 / 0.046 / 0.012 (PE) and 0.355 / 0.402 / 0.316 /
    0.086 (PECE) for K = 8 / 10 / 12 / 16."""
    import numpy as np

    for corrector in ((0, True), (1, True), (2, True)):
        assert np.max(np.abs(np.linalg.eigvals(_step_matrix(order, corrector, -1e-4)))) <= 1 + 1e-9
    got_pe = stability_limit(order, (0, True))
    got_pece = stability_limit(order, (1, True))
    print(f"\nK = {order}: h w <= {got_pe:.3f} (PE), {got_pece:.3f} (PECE)")
    record_number(f"multistep.stability.K{order}", {"pe": got_pe, "pece": got_pece}, "h w")
    assert 0.01 <= got_pe < got_pece < 2.0
