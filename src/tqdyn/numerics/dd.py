"""Extended-precision arithmetic: compiled double-double (dd) and its float64 twin.

tqdyn's hot path (force model + integrator) is written once against the
generic operations of this module and compiled by numba for two number types:

* **dd mode** -- a number is a pair ``(hi, lo)`` of float64 with value
  ``hi + lo`` and ``|lo| <= ulp(hi)/2`` (about 32 significant digits,
  unit roundoff u_dd = 2**-106 ~ 1.2e-32);
* **float64 mode** -- a number is a plain float64 (u = 2**-53 ~ 1.1e-16).

The operations (``add``, ``sub``, ``mul``, ``div``, ``sqrt``, ``neg``,
``ld``/``st`` for array access, ...) are numba overloads that choose their
implementation from the argument *types* at compile time, so the float64 mode
is the same source code compiled to plain float64 instructions, not dd code
with zero low parts.  Arrays of dd numbers carry a trailing axis of length 2
(``[..., 0]`` = hi, ``[..., 1]`` = lo); float64 arrays have no such axis.

Error model (dd mode), with u = 2**-53 and all products formed with a
hardware fused multiply-add (no ``fastmath``, so the compiler never
re-associates the error-free transformations):

* ``two_sum`` / ``two_prod`` are error-free: a + b = s + e, a*b = p + e exactly.
* ``add`` (dd + dd, "AccurateDWPlusDW"): relative error <= 3 u^2.
* ``add`` (dd + float64, "DWPlusFP"): relative error <= 2 u^2.
* ``mul`` (dd * dd, "DWTimesDW3" with FMA): relative error <= 4 u^2.
* ``mul`` (dd * float64, "DWTimesFP3" with FMA): relative error <= 2 u^2.
* ``div`` (dd / dd, "DWDivDW2"): relative error <= 15 u^2.
* ``sqrt`` (one Newton correction of the float64 root): relative error <= 4 u^2.

Bounds from M. Joldes, J.-M. Muller, V. Popescu, "Tight and rigorous error
bounds for basic building blocks of double-word arithmetic", ACM TOMS 44
(2017).  u^2 = 1.2e-32, so a 1e8 m coordinate is held to about 1e-24 m and
every operation adds at most a few 1e-24 m of rounding; the tests measure the
accumulated rounding of whole propagations against mpmath.

Python-side helpers convert between dd arrays and exact rationals / mpmath
numbers for tests and I/O.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from numba import njit, types

from . import jit as _jit  # noqa: F401  (registers the package-wide kernel cache before any @njit)
from numba.extending import intrinsic, overload

__all__ = [
    "add", "add_acc", "sub", "mul", "div", "sqrt", "neg", "fma_", "to_f64",
    "ld", "st", "const", "lo_part", "copy_columns",
    "two_sum", "two_prod", "fast_two_sum",
    "dd_from_mp", "dd_array_from_mp", "mp_from_dd", "mp_from_pair", "split_dd", "join_dd",
    "np_two_sum", "np_two_prod", "mp_exact", "np_fast_two_sum", "np_dd_add", "np_dd_sqr",
    "np_dd_sqrt", "np_dd_div_d", "np_dd_add_d",
    "is_dd_array",
]

_DD = types.UniTuple(types.float64, 2)


# --------------------------------------------------------------------------
# error-free transformations


@intrinsic
def _fma(typingctx, a, b, c):
    """Hardware fused multiply-add a*b + c with one rounding (llvm.fma.f64)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


@njit(inline="always")
def fma_(a, b, c):
    """a*b + c rounded once (float64 scalars)."""
    return _fma(a, b, c)


@njit(inline="always")
def two_sum(a, b):
    """Error-free sum: returns (s, e) with s = fl(a + b) and a + b = s + e exactly."""
    s = a + b
    bb = s - a
    e = (a - (s - bb)) + (b - bb)
    return s, e


@njit(inline="always")
def fast_two_sum(a, b):
    """Error-free sum for |a| >= |b| (or a = 0): a + b = s + e exactly."""
    s = a + b
    e = b - (s - a)
    return s, e


@njit(inline="always")
def two_prod(a, b):
    """Error-free product with FMA: a*b = p + e exactly (barring under/overflow)."""
    p = a * b
    e = _fma(a, b, -p)
    return p, e


# --------------------------------------------------------------------------
# dd kernels (tuples (hi, lo))


@njit(inline="always")
def _dd_add(xh, xl, yh, yl):
    sh, sl = two_sum(xh, yh)
    th, tl = two_sum(xl, yl)
    c = sl + th
    vh, vl = fast_two_sum(sh, c)
    w = tl + vl
    return fast_two_sum(vh, w)


@njit(inline="always")
def _dd_add_sloppy(xh, xl, yh, yl):
    sh, sl = two_sum(xh, yh)
    sl += xl + yl
    return fast_two_sum(sh, sl)


@njit(inline="always")
def _dd_add_d(xh, xl, y):
    sh, sl = two_sum(xh, y)
    v = xl + sl
    return fast_two_sum(sh, v)


@njit(inline="always")
def _dd_mul(xh, xl, yh, yl):
    ch, cl1 = two_prod(xh, yh)
    tl0 = xl * yl
    tl1 = _fma(xh, yl, tl0)
    cl2 = _fma(xl, yh, tl1)
    cl3 = cl1 + cl2
    return fast_two_sum(ch, cl3)


@njit(inline="always")
def _dd_mul_d(xh, xl, y):
    ch, cl1 = two_prod(xh, y)
    cl3 = _fma(xl, y, cl1)
    return fast_two_sum(ch, cl3)


@njit(inline="always")
def _dd_div(xh, xl, yh, yl):
    th = xh / yh
    rh, rl = _dd_mul_d(yh, yl, th)
    pih = xh - rh
    dl = xl - rl
    d = pih + dl
    tl = d / yh
    return fast_two_sum(th, tl)


@njit(inline="always")
def _dd_sqrt(xh, xl):
    if xh <= 0.0:
        return (math.sqrt(xh), 0.0)
    q = math.sqrt(xh)
    ph, pl = two_prod(q, q)
    r = ((xh - ph) - pl + xl) / (2.0 * q)
    return fast_two_sum(q, r)


# --------------------------------------------------------------------------
# generic operations: dispatch on float64 / dd tuple at compile time


def _is_dd(t):
    return isinstance(t, types.UniTuple) and t.count == 2 and isinstance(t.dtype, types.Float)


def _is_f(t):
    return isinstance(t, (types.Float, types.Integer))


def add(a, b):
    """a + b (generic: float64 or dd)."""


def sub(a, b):
    """a - b (generic: float64 or dd)."""


def add_acc(a, b):
    """a + b for accumulating sums whose terms do not cancel the
    accumulator a (generic).  dd: the cheaper "sloppy" sum (error <= ~2u^2
    (|a| + |b|) instead of 3u^2 |a + b|); float64: plain +."""


def mul(a, b):
    """a * b (generic: float64 or dd)."""


def div(a, b):
    """a / b (generic: float64 or dd)."""


def sqrt(a):
    """Square root (generic: float64 or dd)."""


def neg(a):
    """-a (generic: float64 or dd)."""


def to_f64(a):
    """Nearest float64 of a (hi part of a dd; the value itself for float64)."""


def const(hi, lo, like):
    """A constant (hi + lo) in the number type of ``like`` (dd or float64)."""


def lo_part(a):
    """Low part of a dd number (0.0 for float64): a = to_f64(a) + lo_part(a)."""


@overload(add, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_add(a, b):
    if _is_dd(a) and _is_dd(b):
        return lambda a, b: _dd_add(a[0], a[1], b[0], b[1])
    if _is_dd(a) and _is_f(b):
        return lambda a, b: _dd_add_d(a[0], a[1], b)
    if _is_f(a) and _is_dd(b):
        return lambda a, b: _dd_add_d(b[0], b[1], a)
    if _is_f(a) and _is_f(b):
        return lambda a, b: a + b


@overload(add_acc, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_add_acc(a, b):
    if _is_dd(a) and _is_dd(b):
        return lambda a, b: _dd_add_sloppy(a[0], a[1], b[0], b[1])
    return _ov_add(a, b)


@overload(sub, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_sub(a, b):
    if _is_dd(a) and _is_dd(b):
        return lambda a, b: _dd_add(a[0], a[1], -b[0], -b[1])
    if _is_dd(a) and _is_f(b):
        return lambda a, b: _dd_add_d(a[0], a[1], -b)
    if _is_f(a) and _is_dd(b):
        return lambda a, b: _dd_add_d(-b[0], -b[1], a)
    if _is_f(a) and _is_f(b):
        return lambda a, b: a - b


@overload(mul, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_mul(a, b):
    if _is_dd(a) and _is_dd(b):
        return lambda a, b: _dd_mul(a[0], a[1], b[0], b[1])
    if _is_dd(a) and _is_f(b):
        return lambda a, b: _dd_mul_d(a[0], a[1], b)
    if _is_f(a) and _is_dd(b):
        return lambda a, b: _dd_mul_d(b[0], b[1], a)
    if _is_f(a) and _is_f(b):
        return lambda a, b: a * b


@overload(div, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_div(a, b):
    if _is_dd(a) and _is_dd(b):
        return lambda a, b: _dd_div(a[0], a[1], b[0], b[1])
    if _is_dd(a) and _is_f(b):
        return lambda a, b: _dd_div(a[0], a[1], b, 0.0)
    if _is_f(a) and _is_dd(b):
        return lambda a, b: _dd_div(a, 0.0, b[0], b[1])
    if _is_f(a) and _is_f(b):
        return lambda a, b: a / b


@overload(sqrt, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_sqrt(a):
    if _is_dd(a):
        return lambda a: _dd_sqrt(a[0], a[1])
    if _is_f(a):
        return lambda a: math.sqrt(a)


@overload(neg, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_neg(a):
    if _is_dd(a):
        return lambda a: (-a[0], -a[1])
    if _is_f(a):
        return lambda a: -a


@overload(to_f64, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_to_f64(a):
    if _is_dd(a):
        return lambda a: a[0]
    if _is_f(a):
        return lambda a: float(a)


@overload(lo_part, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_lo_part(a):
    if _is_dd(a):
        return lambda a: a[1]
    if _is_f(a):
        return lambda a: 0.0


@overload(const, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_const(hi, lo, like):
    if _is_dd(like):
        return lambda hi, lo, like: (float(hi), float(lo))
    if _is_f(like):
        return lambda hi, lo, like: float(hi)


# --------------------------------------------------------------------------
# array access: dd arrays have a trailing axis of length 2


def ld(arr, *idx):
    """Load element ``arr[idx]`` as a generic number (dd tuple if the array
    carries the dd axis, i.e. has one more dimension than indices)."""


def st(arr, value, *idx):
    """Store a generic number into ``arr[idx]`` (both parts for dd arrays)."""


@overload(ld, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_ld(arr, *idx):
    nidx = len(idx)
    if arr.ndim == nidx + 1:
        def impl(arr, *idx):
            return (arr[idx + (0,)], arr[idx + (1,)])
        return impl
    if arr.ndim == nidx:
        def impl(arr, *idx):
            return arr[idx]
        return impl


@overload(st, jit_options=_jit.OVERLOAD_OPTIONS)
def _ov_st(arr, value, *idx):
    nidx = len(idx)
    if arr.ndim == nidx + 1 and _is_dd(value):
        def impl(arr, value, *idx):
            arr[idx + (0,)] = value[0]
            arr[idx + (1,)] = value[1]
        return impl
    if arr.ndim == nidx + 1 and _is_f(value):
        def impl(arr, value, *idx):
            arr[idx + (0,)] = value
            arr[idx + (1,)] = 0.0
        return impl
    if arr.ndim == nidx and _is_f(value):
        def impl(arr, value, *idx):
            arr[idx] = value
        return impl
    if arr.ndim == nidx and _is_dd(value):
        def impl(arr, value, *idx):
            arr[idx] = value[0]
        return impl


@njit(inline="always")
def copy_columns(src, dst, q0, n):
    """dst[b, q] = src[b, q0 + q] for every row b and q < n (generic: both
    parts of dd arrays).  An element loop: numpy's array assignment would
    also compile its shape checks and their error messages into the kernel."""
    for b in range(src.shape[0]):
        for q in range(n):
            st(dst, ld(src, b, q0 + q), b, q)


# --------------------------------------------------------------------------
# Python-side conversions (tests, I/O, set-up; not for the hot path)


def is_dd_array(arr: np.ndarray, ndim_value: int) -> bool:
    """True if ``arr`` holds dd numbers for values of ``ndim_value`` dimensions."""
    return arr.ndim == ndim_value + 1 and arr.shape[-1] == 2


def mp_exact(x):
    """An exact number (mpf, Fraction, int, float, str, Decimal) as mpf at
    the current working precision (decimal strings converted by mpmath)."""
    import mpmath

    if isinstance(x, mpmath.mpf):
        return x  # as is: no rounding to the working precision
    if isinstance(x, Fraction):
        return mpmath.mpf(x.numerator) / x.denominator
    if isinstance(x, (int, float)):
        return mpmath.mpf(x)
    return mpmath.mpf(str(x))


def dd_from_mp(x) -> tuple[float, float]:
    """Round an exact number (mpmath mpf, Fraction, int, float, str, Decimal) to dd.

    Returns (hi, lo): hi = nearest float64 of x (ties to even), lo = nearest
    float64 of the exact difference x - hi; so |x - (hi + lo)| <= 2**-106 |x|
    (normal range) and |lo| <= ulp(hi)/2.  mpf inputs are used exactly at
    their own precision; Fractions, decimal strings and Decimals are
    converted at 60 digits first (exact enough for any dd).
    """
    import mpmath
    from mpmath.libmp import round_nearest, to_float

    with mpmath.workdps(60):
        v = mp_exact(x)
        hi = to_float(v._mpf_, rnd=round_nearest)
        lo = to_float(mpmath.fsub(v, mpmath.mpf(hi), exact=True)._mpf_, rnd=round_nearest)
    return hi, lo


def np_fast_two_sum(a, b):
    """Vectorised error-free sum for |a| >= |b| (numpy): a + b = s + e."""
    s = a + b
    return s, b - (s - a)


def np_dd_add(ah, al, bh, bl):
    """Vectorised dd + dd (numpy; hi/lo arrays): (sh, sl) ~ (ah + al) + (bh + bl)."""
    s, e = np_two_sum(ah, bh)
    t, f = np_two_sum(al, bl)
    e = e + t
    s, e = np_fast_two_sum(s, e)
    e = e + f
    return np_fast_two_sum(s, e)


def np_dd_add_d(ah, al, b):
    """Vectorised dd + float64 (numpy): (ah + al) + b as a dd pair.

    two_sum of the high parts, then a fast renormalisation: exact as long as
    ah + b does not cancel below al (|ah + b| >= |al|), e.g. a small
    correction b to a dd coordinate or time."""
    s, e = np_two_sum(np.asarray(ah, np.float64), np.asarray(b, np.float64))
    return np_fast_two_sum(s, e + al)


def np_dd_sqr(ah, al):
    """Vectorised dd square (numpy): (ah + al)^2 as a dd pair."""
    p, e = np_two_prod(ah, ah)
    e = e + 2.0 * ah * al + al * al
    return np_fast_two_sum(p, e)


def np_dd_sqrt(ah, al):
    """Vectorised dd square root (numpy), one Newton correction of the float64 root."""
    q = np.sqrt(ah)
    p, e = np_two_prod(q, q)
    r = ((ah - p) - e + al) / (2.0 * q)
    return np_fast_two_sum(q, r)


def np_dd_div_d(ah, al, b):
    """Vectorised dd / float64 (numpy): (ah + al) / b as a dd pair."""
    q = ah / b
    p, e = np_two_prod(q, b)
    r = ((ah - p) - e + al) / b
    return np_fast_two_sum(q, r)


def mp_from_pair(hi: float, lo: float):
    """dd pair -> mpmath mpf hi + lo, exactly (no rounding)."""
    import mpmath

    return mpmath.fadd(mpmath.mpf(float(hi)), mpmath.mpf(float(lo)), exact=True)


def np_two_sum(a, b):
    """Vectorised error-free sum (numpy): a + b = s + e exactly, elementwise."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def np_two_prod(a, b):
    """Vectorised error-free product (numpy, Veltkamp-Dekker splitting, no
    FMA needed): a * b = p + e exactly, elementwise, barring overflow."""

    def split(x):
        c = 134217729.0 * x  # 2**27 + 1
        hi = c - (c - x)
        return hi, x - hi

    p = a * b
    ah, al = split(a)
    bh, bl = split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def dd_array_from_mp(values, shape=None) -> np.ndarray:
    """Array of exact numbers -> dd array with trailing axis 2 (float64)."""
    flat = [dd_from_mp(v) for v in np.asarray(values, dtype=object).ravel()]
    out = np.array(flat, dtype=np.float64).reshape(
        (np.shape(values) if shape is None else tuple(shape)) + (2,))
    return out


def mp_from_dd(arr: np.ndarray):
    """dd array (trailing axis 2) -> numpy object array of exact mpmath values hi + lo."""
    arr = np.asarray(arr, dtype=np.float64)
    out = np.empty(arr.shape[:-1], dtype=object)
    for idx in np.ndindex(out.shape):
        out[idx] = mp_from_pair(arr[idx + (0,)], arr[idx + (1,)])
    return out


def split_dd(arr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dd array (trailing axis 2) -> (hi, lo) pair of float64 arrays (views)."""
    return arr[..., 0], arr[..., 1]


def join_dd(hi: np.ndarray, lo: np.ndarray) -> np.ndarray:
    """(hi, lo) float64 arrays -> dd array with trailing axis 2."""
    return np.stack([np.asarray(hi, np.float64), np.asarray(lo, np.float64)], axis=-1)
