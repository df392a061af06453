"""Lagrange interpolation on a uniform grid, for slowly varying tabulated quantities.

Slow, expensive series (precession-nutation X, Y, s; TDB - TT; the sub-daily
EOP terms) are evaluated at the nodes of a uniform grid and interpolated to
the many instants of a propagation chunk: :func:`grid_interp` uses the
:data:`POINTS` nodes floor(u) - 3 .. floor(u) + 4 around u (u in units of
the grid step), i.e. a degree-7 polynomial; for a quantity with frequencies
below f the error is ~ (2 pi f h)^8 / 8! of its amplitude (h the step).

:func:`weights` gives the Lagrange weights (and their derivatives) of any
set of nodes for vectorised numpy use (fractional delays, tabulated orbits).
"""

from __future__ import annotations

import math

import numpy as np

from . import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)

__all__ = ["MARGIN", "POINTS", "grid_interp", "weights"]

#: Number of nodes of the interpolation (degree POINTS - 1).
POINTS = 8
_HALF = POINTS // 2  # nodes k-3 .. k+4 around the interval [k, k+1)
#: Nodes needed beyond the first and last interval of a request, on each side.
MARGIN = _HALF + 1


def _denominators() -> np.ndarray:
    offs = np.arange(-_HALF + 1, _HALF + 1, dtype=np.float64)  # -3..4
    return np.array([math.prod(float(offs[j] - offs[m]) for m in range(POINTS) if m != j)
                     for j in range(POINTS)])


_DENOM = _denominators()


def grid_interp(u: np.ndarray, k0: int, vals: np.ndarray, out: np.ndarray) -> None:
    """out[i, c] = the 8-point Lagrange interpolant of vals[:, c] at u[i].

    u : (n,) positions in units of the grid step; vals : (m_nodes, n_cols)
    values at the nodes k0, k0 + 1, ... (it must hold floor(u) - 3 ..
    floor(u) + 4 for every u); out : (n, n_cols), written.  Vectorised over
    the instants (numpy: nothing to compile); each weight is the product
    over the other nodes in node order, divided by its denominator, and the
    sum runs over the nodes in order."""
    u = np.asarray(u, dtype=np.float64)
    vals = np.asarray(vals, dtype=np.float64)
    kq = np.floor(u)
    x = u - kq
    b = kq.astype(np.int64) - (_HALF - 1) - int(k0)
    acc = np.zeros(out.shape)
    for j in range(POINTS):
        p = np.ones_like(x)
        for q in range(POINTS):
            if q != j:
                p *= x - float(q - _HALF + 1)
        acc += (p / _DENOM[j])[:, None] * vals[b + j]
    out[...] = acc


def weights(x, offsets, derivative: bool = False):
    """Lagrange weights of the nodes ``offsets`` (p,) at x (n,) (both in grid steps):
    w (n, p) with sum_j w_j(x) f(o_j) the degree p - 1 interpolant of f at x, each
    w_j = prod_{q != j} (x - o_q) / (o_j - o_q); with ``derivative`` also dw/dx (n, p)
    [per grid step].  Returns w, or (w, dw).  Memory O(n p)."""
    o = [float(v) for v in offsets]
    p = len(o)
    d = np.asarray(x, dtype=np.float64)[:, None] - np.asarray(o)[None, :]         # (n, p)
    w = np.empty(d.shape)
    dw = np.zeros(d.shape) if derivative else None
    for j in range(p):
        others = [m for m in range(p) if m != j]
        denom = math.prod(o[j] - o[m] for m in others)
        w[:, j] = np.prod(d[:, others], axis=1) / denom
        if derivative:       # dw_j/dx = sum over k != j of prod over m != j, k of (x - o_m), over denom
            for k in others:
                dw[:, j] += np.prod(d[:, [m for m in others if m != k]], axis=1)
            dw[:, j] /= denom
    return (w, dw) if derivative else w
