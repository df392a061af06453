"""Gauss-Jackson / summed Adams multistep integration: coefficients and compiled generic steps.

The method integrates r'' = f(t, r, r') on a fixed grid t_n = n h from the
first and second sums of the accelerations,

    s_n = s_{n-1} + f_n,    S_n = S_{n-1} + s_n,

positions by the summed Stormer-Cowell (Gauss-Jackson) formulas and
velocities by the summed Adams formulas (Berry & Healy 2004, "Implementation
of Gauss-Jackson integration for orbit propagation", J. Astronaut. Sci. 52,
331), in ordinate form, with K + 1 accelerations for order K:

    predictor  r_{n+1} = h^2 (S_n + sum_j PP_j f_{n-j}),    r'_{n+1} = h (s_n + sum_j PV_j f_{n-j})
    corrector  r_{n+1} = h^2 (S_n + sum_j CP_j f_{n+1-j}),  r'_{n+1} = h (s_n + sum_j CV_j f_{n+1-j})

(j = 0 .. K; derivation and the rationals: ``tools/gen_multistep_coefficients.py``,
:mod:`._multistep_coefficients`).  Order K interpolates the accelerations by
a polynomial of degree K: positions that are polynomials of degree <= K + 2
in t are integrated exactly.  A step is P(EC)^k E: predict, evaluate, k
times (correct, evaluate); k = 0 is the explicit method (predictor only),
k = 1 the usual PECE.  Every step ends with an evaluation at the state it
returns, so the table holds f(t_n, r_n, r'_n) exactly.

The sums are the integrator's state: the positions and velocities are
formed from them afresh at every step (nothing is accumulated in r), and
the sums are updated with a compensated (Kahan) addition, so their rounding
does not grow with the number of steps (3e6 for five years at 50 s).

As in :mod:`.dp87`, the compiled functions are generic over the number type
(:mod:`tqdyn.numerics.dd`): arrays with a trailing dd axis give
double-double, plain float64 arrays float64.  Shapes: the acceleration
table F (K + 1, n_body, 3[, 2]) is a ring (``head`` = index of the newest
value f_n, f_{n-j} at (head - j) mod (K + 1)); the sums S, cS, s, cs
(n_body, 3[, 2]) (cS, cs: the compensations); states y and derivatives k
(n_body, 6[, 2]) with rows (x, y, z, vx, vy, vz) [m, m/s]; coefficient rows
coef (4, K + 1[, 2]) in the order PP, PV, CP, CV; hh (2[, 2]) = (h, h^2).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from . import _multistep_coefficients as _tab
from .dd import add, dd_from_mp, div, ld, mp_exact, mul, st, sub, to_f64
from .jit import dynamic, inner_kernel, kernel

__all__ = ["ORDERS", "CORRECTORS", "DEFAULT_ORDER", "DEFAULT_CORRECTOR", "Coefficients", "load_coefficients",
           "StepCoefficients", "step_coefficients", "predict", "correct", "commit", "start", "max_change", "ROW_NAMES"]

#: Orders (degree K of the acceleration interpolant, K + 1 back values) the generated table holds:
#: the allowed values of ``integrator.order``.
ORDERS = tuple(_tab.ORDERS)
#: The stages of a step (``integrator.corrector``): P(redict), E(valuate), C(orrect); one evaluation
#: of the right-hand side per "e" ("pe": the explicit method; "pec": its prediction corrected, the
#: correction not evaluated; "pece": the usual predictor-corrector).
CORRECTORS = ("pe", "pec", "pece", "pecec", "pecece")
#: Defaults of ``integrator.order`` and ``integrator.corrector``: docs/precision.md ("Multistep
#: integration") gives the measurements behind them.
DEFAULT_ORDER = 10
DEFAULT_CORRECTOR = "pece"
#: Rows of ``coef``: position predictor, velocity predictor, position corrector, velocity corrector.
ROW_NAMES = ("PREDICTOR_POSITION", "PREDICTOR_VELOCITY", "CORRECTOR_POSITION", "CORRECTOR_VELOCITY")
_PP, _PV, _CP, _CV = 0, 1, 2, 3


@dataclass(frozen=True)
class Coefficients:
    """The four ordinate rows of order K as exact Fractions (K + 1 each,
    in :data:`ROW_NAMES` order) and the leading error constants (dict by row
    name, :mod:`._multistep_coefficients`)."""

    order: int
    rows: tuple
    errors: dict


def load_coefficients(order: int) -> Coefficients:
    """The exact coefficients of ``order`` (one of :data:`ORDERS`)."""
    if order not in ORDERS:
        raise ValueError(f"integrator.order: {order!r} is not available; allowed: {ORDERS[0]}..{ORDERS[-1]}")
    rows = tuple(tuple(Fraction(x) for x in getattr(_tab, name)[order]) for name in ROW_NAMES)
    errors = {name: Fraction(getattr(_tab, "ERROR_" + name)[order]) for name in ROW_NAMES}
    return Coefficients(order=order, rows=rows, errors=errors)


@dataclass(frozen=True)
class StepCoefficients:
    """Coefficients for the compiled loop in the working precision.

    coef: (4, K + 1[, 2]) the rows of :class:`Coefficients` rounded once to
    dd (or float64); hh: (2[, 2]) the step h [s] and h^2 [s^2], each the
    exact value rounded once; h: the step as a (hi, lo) pair; order: K.
    """

    coef: np.ndarray
    hh: np.ndarray
    h: tuple[float, float]
    order: int


def step_coefficients(order: int, h, precision: str) -> StepCoefficients:
    """The coefficients of ``order`` and the step ``h`` [s] (exact number:
    Decimal, Fraction, str or int; a float at its exact binary value) for
    ``precision`` "dd" or "float64"."""
    import mpmath

    c = load_coefficients(order)
    coef = np.array([[dd_from_mp(x) for x in row] for row in c.rows])  # (4, K + 1, 2)
    with mpmath.workdps(60):
        hm = mp_exact(h)
        hh = np.array([dd_from_mp(hm), dd_from_mp(hm * hm)])
    h_pair = (float(hh[0, 0]), float(hh[0, 1]))
    if precision != "dd":
        coef = coef[..., 0] + coef[..., 1]
        hh = np.array([float(mp_exact(h)), float(mp_exact(h) ** 2)])
    return StepCoefficients(coef=np.ascontiguousarray(coef), hh=np.ascontiguousarray(hh), h=h_pair, order=order)


# --------------------------------------------------------------------------
# compiled building blocks (generic over dd / float64)


@inner_kernel
def _weighted(F, head, row, coef, b, q, acc, first, k, shift):
    """acc + sum_j coef[row, j] f_{m-j}[b, q] over the table (j = 0 .. K).

    The newest value f_m is ``k[b, 3 + q]`` if ``first`` (the corrector's
    f_{n+1}, not yet in the table; then f_{m-j} = F[head - j + 1] for j >= 1),
    else F[head] (the predictor's f_n).  ``shift`` = 1 with ``first``, 0 without."""
    nk = F.shape[0]
    for j in range(nk):
        if first and j == 0:
            x = ld(k, b, 3 + q)
        else:
            x = ld(F, (head - j + shift) % nk, b, q)
        acc = add(acc, mul(ld(coef, row, j), x))
    return acc


@inner_kernel
def predict(S, cS, s, cs, F, head, coef, hh, out):
    """out = the predicted state at t_{n+1}: r = h^2 (S_n + sum_j PP_j f_{n-j}),
    r' = h (s_n + sum_j PV_j f_{n-j}) (the sums' compensations included)."""
    h, h2 = ld(hh, 0), ld(hh, 1)
    for b in range(S.shape[0]):
        for q in range(3):
            accr = _weighted(F, head, dynamic(_PP), coef, b, q, ld(cS, b, q), dynamic(False), out, dynamic(0))
            accv = _weighted(F, head, dynamic(_PV), coef, b, q, ld(cs, b, q), dynamic(False), out, dynamic(0))
            st(out, mul(add(ld(S, b, q), accr), h2), b, q)
            st(out, mul(add(ld(s, b, q), accv), h), b, q + 3)


@inner_kernel
def correct(S, cS, s, cs, F, head, k, coef, hh, out):
    """out = the corrected state at t_{n+1} from the derivative k (n_body,
    6[, 2]) evaluated at the previous iterate: r = h^2 (S_n + sum_j CP_j
    f_{n+1-j}), r' = h (s_n + sum_j CV_j f_{n+1-j}), f_{n+1} = k[:, 3:6]."""
    h, h2 = ld(hh, 0), ld(hh, 1)
    for b in range(S.shape[0]):
        for q in range(3):
            accr = _weighted(F, head, dynamic(_CP), coef, b, q, ld(cS, b, q), dynamic(True), k, dynamic(1))
            accv = _weighted(F, head, dynamic(_CV), coef, b, q, ld(cs, b, q), dynamic(True), k, dynamic(1))
            st(out, mul(add(ld(S, b, q), accr), h2), b, q)
            st(out, mul(add(ld(s, b, q), accv), h), b, q + 3)


@inner_kernel
def commit(S, cS, s, cs, F, head, k):
    """Enter f_{n+1} = k[:, 3:6] (the evaluation at the returned state):
    s_{n+1} = s_n + f_{n+1}, S_{n+1} = S_n + s_{n+1}, each a compensated
    (Kahan) addition whose rounding error is carried in cs / cS into the
    next one, and f_{n+1} into the table.  Returns the new head index."""
    nk = F.shape[0]
    new = (head + 1) % nk
    for b in range(S.shape[0]):
        for q in range(3):
            f = ld(k, b, 3 + q)
            st(F, f, new, b, q)
            s0 = ld(s, b, q)
            inc = add(f, ld(cs, b, q))
            s1 = add(s0, inc)
            st(cs, add(sub(s0, s1), inc), b, q)
            st(s, s1, b, q)
            S0 = ld(S, b, q)
            inc = add(add(s1, ld(cs, b, q)), ld(cS, b, q))
            S1 = add(S0, inc)
            st(cS, add(sub(S0, S1), inc), b, q)
            st(S, S1, b, q)
    return new


@kernel
def start(y, F, head, coef, hh, S, cS, s, cs):
    """Sums at t_N from the state y_N (n_body, 6[, 2]) and the table
    f_{N-K} .. f_N (newest at ``head``), by the corrector at N:
    S_{N-1} = r_N / h^2 - sum_j CP_j f_{N-j}, s_{N-1} = r'_N / h - sum_j CV_j f_{N-j},
    then s_N = s_{N-1} + f_N and S_N = S_{N-1} + s_N (compensations zero)."""
    h, h2 = ld(hh, 0), ld(hh, 1)
    nk = F.shape[0]
    for b in range(S.shape[0]):
        for q in range(3):
            zero = mul(ld(y, b, q), 0.0)
            accr = zero
            accv = zero
            for j in range(nk):
                x = ld(F, (head - j) % nk, b, q)
                accr = add(accr, mul(ld(coef, _CP, j), x))
                accv = add(accv, mul(ld(coef, _CV, j), x))
            s_prev = sub(div(ld(y, b, q + 3), h), accv)
            s_now = add(s_prev, ld(F, head, b, q))
            st(s, s_now, b, q)
            st(S, add(sub(div(ld(y, b, q), h2), accr), s_now), b, q)
            st(cs, zero, b, q)
            st(cS, zero, b, q)


@inner_kernel
def max_change(a, b, out):
    """out[0] = max(out[0], max |r_a - r_b|) [m], out[1] likewise for the
    velocities [m/s] (largest component, float64); a, b: (n_body, 6[, 2])."""
    for i in range(a.shape[0]):
        for q in range(6):
            d = abs(to_f64(sub(ld(a, i, q), ld(b, i, q))))
            if d > out[q // 3]:
                out[q // 3] = d
