"""The arithmetic core (tqdyn.numerics.dd) against exact references.

References: exact rational arithmetic (fractions.Fraction) for the
error-free transformations; mpmath at 60 significant digits (~200 bits,
exact or within 1e-60 relative for the operations on dd inputs of <= 107
bits) for the dd operations, with the relative error bounds stated in the
module docstring (u = 2**-53): add dd+dd 3u^2, dd+float64 2u^2, mul dd*dd
4u^2, dd*float64 2u^2, div 15u^2, sqrt 4u^2.  The published bounds carry
O(u^3) terms (e.g. 3u^2/(1-4u)); a slack factor (1 + 2**-40) covers them.
The float64 mode is checked bit for bit against numpy (IEEE float64).

The operations are called from small @njit wrappers, as in the hot path.
"""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

import mpmath
import numpy as np
from mpmath import mpf
from numba import njit

from tqdyn.numerics import dd as P
from tqdyn.numerics.dd import add, div, fast_two_sum, ld, mul, sqrt, st, sub, two_prod, two_sum

U = 2.0 ** -53
SLACK = 1 + 2.0 ** -40
BOUND = {"add": 3 * U * U, "sub": 3 * U * U, "mul": 4 * U * U, "div": 15 * U * U, "sqrt": 4 * U * U,
         "add_f": 2 * U * U, "sub_f": 2 * U * U, "f_add": 2 * U * U, "f_sub": 2 * U * U,
         "mul_f": 2 * U * U, "f_mul": 2 * U * U, "div_f": 15 * U * U, "f_div": 15 * U * U}
N = 3000
DPS = 60


# --------------------------------------------------------------------------
# compiled wrappers


@njit(cache=False)
def _eft_kernel(a, b, out):
    """out[k] = (two_sum s, e, two_prod p, e, fast_two_sum s, e) of a[k], b[k]."""
    for k in range(a.shape[0]):
        s, e = two_sum(a[k], b[k])
        p, f = two_prod(a[k], b[k])
        if abs(a[k]) >= abs(b[k]):
            fs, fe = fast_two_sum(a[k], b[k])
        else:
            fs, fe = fast_two_sum(b[k], a[k])
        out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5] = s, e, p, f, fs, fe


@njit(cache=False)
def _ops_kernel(x, y, z, out):
    """Generic: x, y, z (n[, 2]); out (5, n[, 2]) = x+y, x-y, x*y, x/y, sqrt(z)."""
    for k in range(x.shape[0]):
        a = ld(x, k)
        b = ld(y, k)
        st(out, add(a, b), 0, k)
        st(out, sub(a, b), 1, k)
        st(out, mul(a, b), 2, k)
        st(out, div(a, b), 3, k)
        st(out, sqrt(ld(z, k)), 4, k)


@njit(cache=False)
def _mixed_kernel(x, f, out):
    """x: (n, 2) dd, f: (n,) float64; out (8, n, 2) = x+f, x-f, f+x, f-x, x*f, f*x, x/f, f/x."""
    for k in range(x.shape[0]):
        a = ld(x, k)
        b = f[k]
        st(out, add(a, b), 0, k)
        st(out, sub(a, b), 1, k)
        st(out, add(b, a), 2, k)
        st(out, sub(b, a), 3, k)
        st(out, mul(a, b), 4, k)
        st(out, mul(b, a), 5, k)
        st(out, div(a, b), 6, k)
        st(out, div(b, a), 7, k)


# --------------------------------------------------------------------------
# random operands


def random_f64(rng, n, lo_exp=-10, hi_exp=10):
    """n float64 log-uniform in magnitude over 10**[lo_exp, hi_exp], random signs."""
    return rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(lo_exp, hi_exp, n)


def random_dd(rng, n, lo_exp=-10, hi_exp=10, min_gap_bits=53, max_gap_bits=60):
    """(n, 2) normalized dd numbers: hi log-uniform over 10**[lo_exp, hi_exp]
    with random signs, lo = hi * r * 2**-gap with r in (-1, 1) and gap bits
    uniform in [min_gap, max_gap], then renormalized (|lo| <= ulp(hi)/2)."""
    hi = random_f64(rng, n, lo_exp, hi_exp)
    gap = rng.uniform(min_gap_bits, max_gap_bits, n)
    lo = hi * rng.uniform(-1, 1, n) * 2.0 ** -gap
    out = np.empty((n, 2))
    for k in range(n):
        s = hi[k] + lo[k]  # fast_two_sum in Python float64 arithmetic (exact, |hi| >= |lo|)
        out[k] = s, lo[k] - (s - hi[k])
    return out


def is_normalized(d) -> np.ndarray:
    return np.abs(d[..., 1]) <= np.spacing(np.abs(d[..., 0])) / 2


def mp_of(d) -> mpf:
    return mpf(float(d[0])) + mpf(float(d[1]))


def rel_err(computed_dd, exact: mpf) -> float:
    with mpmath.workdps(DPS):
        if exact == 0:
            return 0.0 if computed_dd[0] == 0 and computed_dd[1] == 0 else float("inf")
        return float(abs(mp_of(computed_dd) - exact) / abs(exact))


# --------------------------------------------------------------------------
# error-free transformations


def test_two_sum_two_prod_are_error_free():
    rng = np.random.default_rng(20240601)
    n = 4000
    # sums: magnitudes 1e-300 .. 1e300, including wildly different ones
    a = random_f64(rng, n, -300, 300)
    b = np.concatenate([random_f64(rng, n // 2, -300, 300), a[: n // 2] * (1 + rng.uniform(-1e-8, 1e-8, n // 2))])
    b[n // 2: 3 * n // 4] *= -1  # near-cancellation
    out = np.empty((n, 6))
    _eft_kernel(a, b, out)
    for k in range(n):
        s, e = out[k, 0], out[k, 1]
        assert s == a[k] + b[k]
        assert Fraction(s) + Fraction(e) == Fraction(a[k]) + Fraction(b[k]), (a[k], b[k])
        assert Fraction(out[k, 4]) + Fraction(out[k, 5]) == Fraction(a[k]) + Fraction(b[k]), (a[k], b[k])
    # products: factors 1e-140 .. 1e140 (product and its error term in the normal/subnormal-exact range)
    a = random_f64(rng, n, -140, 140)
    b = random_f64(rng, n, -140, 140)
    out = np.empty((n, 6))
    _eft_kernel(a, b, out)
    for k in range(n):
        p, e = out[k, 2], out[k, 3]
        assert p == a[k] * b[k]
        assert Fraction(p) + Fraction(e) == Fraction(a[k]) * Fraction(b[k]), (a[k], b[k])
    # the classic examples
    out = np.empty((2, 6))
    _eft_kernel(np.array([1.0, 1e16]), np.array([2.0 ** -60, 1.0 + 2.0 ** -52]), out)
    assert tuple(out[0, :2]) == (1.0, 2.0 ** -60)
    assert Fraction(out[1, 0]) + Fraction(out[1, 1]) == Fraction(10 ** 16) + 1 + Fraction(1, 2 ** 52)


# --------------------------------------------------------------------------
# dd arithmetic vs mpmath


def _operands(rng):
    x = random_dd(rng, N)
    y = random_dd(rng, N)
    m = N // 6
    # near-cancellation: y_hi = -x_hi (first sixth, for x + y) or y_hi = x_hi (second sixth, for x - y),
    # with a fresh lo (|lo| < |hi| 2**-54 <= ulp(hi)/2, so y stays normalized)
    y[:m, 0] = -x[:m, 0]
    y[m:2 * m, 0] = x[m:2 * m, 0]
    y[:2 * m, 1] = x[:2 * m, 0] * rng.uniform(-1, 1, 2 * m) * 2.0 ** -54
    z = np.abs(random_dd(rng, N))
    return x, y, z


def test_dd_operations_within_docstring_bounds():
    rng = np.random.default_rng(7)
    x, y, z = _operands(rng)
    assert is_normalized(x).all() and is_normalized(y).all() and is_normalized(z).all()
    out = np.empty((5, N, 2))
    _ops_kernel(x, y, z, out)
    assert is_normalized(out).all()
    worst = dict.fromkeys(("add", "sub", "mul", "div", "sqrt"), 0.0)
    with mpmath.workdps(DPS):
        for k in range(N):
            a, b, c = mp_of(x[k]), mp_of(y[k]), mp_of(z[k])
            exact = {"add": a + b, "sub": a - b, "mul": a * b, "div": a / b, "sqrt": mpmath.sqrt(c)}
            for i, op in enumerate(("add", "sub", "mul", "div", "sqrt")):
                worst[op] = max(worst[op], rel_err(out[i, k], exact[op]))
    print("\ndd ops, max relative error / u^2: " + ", ".join(f"{op} {w / U**2:.3f}" for op, w in worst.items()))
    for op, w in worst.items():
        assert w <= BOUND[op] * SLACK, op


def test_mixed_dd_float64_operations_within_bounds():
    rng = np.random.default_rng(11)
    x = random_dd(rng, N)
    f = random_f64(rng, N)
    f[: N // 6] = -x[: N // 6, 0]  # exact cancellation of the hi parts
    out = np.empty((8, N, 2))
    _mixed_kernel(x, f, out)
    assert is_normalized(out).all()
    names = ("add_f", "sub_f", "f_add", "f_sub", "mul_f", "f_mul", "div_f", "f_div")
    worst = dict.fromkeys(names, 0.0)
    with mpmath.workdps(DPS):
        for k in range(N):
            a, b = mp_of(x[k]), mpf(float(f[k]))
            exact = (a + b, a - b, b + a, b - a, a * b, b * a, a / b, b / a)
            for i, op in enumerate(names):
                worst[op] = max(worst[op], rel_err(out[i, k], exact[i]))
    print("\ndd-float64 ops, max relative error / u^2: " + ", ".join(f"{op} {w / U**2:.3f}" for op, w in worst.items()))
    for op, w in worst.items():
        assert w <= BOUND[op] * SLACK, op


def test_float64_mode_is_ieee():
    rng = np.random.default_rng(3)
    x = random_f64(rng, N)
    y = random_f64(rng, N)
    y[: N // 6] = -x[: N // 6] * (1 + 2.0 ** -52)
    z = np.abs(random_f64(rng, N))
    out = np.empty((5, N))
    _ops_kernel(x, y, z, out)
    with np.errstate(all="raise"):
        ref = (x + y, x - y, x * y, x / y, np.sqrt(z))
    for i in range(5):
        assert np.array_equal(out[i], ref[i]), i


# --------------------------------------------------------------------------
# conversions


def test_dd_from_mp_is_correctly_rounded_and_round_trips():
    rng = np.random.default_rng(5)
    with mpmath.workdps(DPS):
        values = [(mpmath.rand() - mpf("0.5")) * mpf(10) ** int(rng.integers(-30, 30)) for _ in range(1000)]
        values += [mpf(1) + mpf(2) ** -53 + mpf(2) ** -80, -(mpf(1) + mpf(2) ** -53 + mpf(2) ** -80), mpf(0),
                   mpf(2) ** 60 + 1, mpmath.pi * 1e8]
        for x in values:
            hi, lo = P.dd_from_mp(x)
            # hi is the nearest float64 of x; lo the nearest float64 of x - hi
            assert Fraction(hi) == _nearest_fraction(x)
            assert abs(x - (mpf(hi) + mpf(lo))) <= mpf(2) ** -106 * abs(x)
            assert abs(lo) <= np.spacing(abs(hi)) / 2
            back = P.mp_from_dd(np.array([hi, lo]))[()]
            assert back == mpmath.fadd(mpf(hi), mpf(lo), exact=True)
            assert P.dd_from_mp(back) == (hi, lo)
    # other exact inputs
    assert P.dd_from_mp(Fraction(1, 3)) == P.dd_from_mp("0.33333333333333333333333333333333333333333333333333333333333")
    assert P.dd_from_mp(Decimal("0.1")) == P.dd_from_mp("0.1")
    hi, lo = P.dd_from_mp("0.1")
    assert hi == 0.1 and abs(Fraction(hi) + Fraction(lo) - Fraction(1, 10)) <= Fraction(1, 10) * Fraction(1, 2 ** 106)
    assert P.dd_from_mp(398600441500000) == (398600441500000.0, 0.0)


def _nearest_fraction(x: mpf) -> Fraction:
    """Nearest float64 of x as a Fraction (Python's int / int division is correctly rounded)."""
    sign, man, exp, _ = x._mpf_
    exact = (-1) ** sign * Fraction(int(man)) * Fraction(2) ** int(exp)
    return Fraction(exact.numerator / exact.denominator)


def test_dd_array_round_trip_exact_and_split_join():
    rng = np.random.default_rng(9)
    # |lo| / |hi| from 2**-53 down to 2**-500: mpf inputs are converted at
    # their own precision, so every valid dd survives dd -> mp -> dd bit for bit.
    d = random_dd(rng, 300, -20, 20, 53, 500).reshape(100, 3, 2)
    assert is_normalized(d).all()
    vals = P.mp_from_dd(d)
    assert vals.shape == (100, 3) and vals.dtype == object
    for idx in np.ndindex(vals.shape):
        assert vals[idx] == mpmath.fadd(mpf(d[idx][0]), mpf(d[idx][1]), exact=True)
    back = P.dd_array_from_mp(vals)
    assert back.shape == d.shape and np.array_equal(back, d)  # bit-identical
    hi, lo = P.split_dd(d)
    assert np.shares_memory(hi, d) and np.array_equal(hi, d[..., 0]) and np.array_equal(lo, d[..., 1])
    j = P.join_dd(hi, lo)
    assert j.shape == d.shape and j.dtype == np.float64 and np.array_equal(j, d)
    assert P.is_dd_array(d, 2) and not P.is_dd_array(d[..., 0], 2)
