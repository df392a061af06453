"""Independent, slow Prince-Dormand RK8(7)13M in mpmath for the two-body
problem: the reference that measures the arithmetic rounding of tqdyn's
compiled dd integrator (tests/test_propagation.py and
benchmarks/bench_rounding.py).  Nothing here comes from tqdyn's integrator:
the tableau strings are read from ``_dp87_tableau`` and every operation is
mpmath at DPS digits.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
from mpmath import mpf

from tqdyn.numerics import _dp87_tableau as tab

GM = "3.986004415e14"  # m^3/s^2
DPS = 50  # mpmath digits


def _tableau_entry(text: str) -> mpf:
    """Exact tableau string ("p/q", "0", "1" or a decimal) -> mpf at the working precision."""
    if "/" in text:
        f = Fraction(text)
        return mpf(f.numerator) / f.denominator
    return mpf(text)


def _round_dd(x: mpf) -> tuple[float, float]:
    """Nearest double-double of x: hi = nearest float64, lo = nearest float64 of x - hi."""
    hi = float(x)  # mpmath rounds to nearest (context rounding 'n')
    with mpmath.workdps(80):
        lo = float(x - mpf(hi))
    return hi, lo


def mp_dp87(y0: list, h: str, n_steps: int, *, a_rows=tab.A_CORRECTED, b_row=tab.B_CORRECTED, coef=None):
    """Independent RK8(7)13M in mpmath (DPS digits) for y' = (v, -GM r/|r|^3).

    The stage matrix and weights enter as h*a_ij and h*b_j, each formed at 60
    digits and rounded to dd exactly as the compiled code's coefficients (and,
    if ``coef`` is given, checked to be bit-identical to them); the stages
    are y + sum_j (h a_ij) k_j, the update y + sum_j (h b_j) k_j, all at DPS digits.
    """
    with mpmath.workdps(60):
        hm = mpf(h)
        ha = [[(j, _round_dd(_tableau_entry(x) * hm)) for j, x in enumerate(row) if x != "0"] for row in a_rows]
        hb = [(j, _round_dd(_tableau_entry(x) * hm)) for j, x in enumerate(b_row) if x != "0"]
    if coef is not None:  # the compiled run uses exactly these numbers
        for i, row in enumerate(ha):
            assert coef.nnz[i] == len(row)
            for j, pair in row:
                assert tuple(coef.ha[i, j]) == pair, (i, j)
        assert [int(j) for j in coef.nzb] == [j for j, _ in hb]
        for j, pair in hb:
            assert tuple(coef.hb[j]) == pair, j
    with mpmath.workdps(DPS):
        ha = [[(j, mpf(p[0]) + mpf(p[1])) for j, p in row] for row in ha]
        hb = [(j, mpf(p[0]) + mpf(p[1])) for j, p in hb]
        gm = mpf(GM)

        def f(y):
            r2 = y[0] * y[0] + y[1] * y[1] + y[2] * y[2]
            k = -gm / (r2 * mpmath.sqrt(r2))
            return [y[3], y[4], y[5], k * y[0], k * y[1], k * y[2]]

        y = [mpf(x) for x in y0]
        for _ in range(n_steps):
            K = [f(y)]
            for i in range(1, 13):
                K.append(f([y[q] + mpmath.fsum(c * K[j][q] for j, c in ha[i]) for q in range(6)]))
            y = [y[q] + mpmath.fsum(c * K[j][q] for j, c in hb) for q in range(6)]
        return y


def third_body_literal(r, s, gm, dps: int = 50) -> list:
    """Geocentric third-body acceleration written literally, -GM (d/|d|^3 +
    s/|s|^3) with d = r - s, in mpmath at ``dps`` digits [m/s^2]."""
    with mpmath.workdps(dps):
        r = [mpf(x) for x in r]
        s = [mpf(x) for x in s]
        d = [a - b for a, b in zip(r, s)]
        nd = mpmath.sqrt(sum(x * x for x in d))
        ns = mpmath.sqrt(sum(x * x for x in s))
        return [-gm * (dd / nd**3 + ss / ns**3) for dd, ss in zip(d, s)]
