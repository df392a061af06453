"""Lagrange interpolation on a uniform grid (compiled), for slowly varying tabulated quantities.

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
from numba import njit

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


@njit(cache=True)
def _interp(u, k0, vals, denom, out):
    npts = denom.size
    half = npts // 2
    m = vals.shape[1]
    w = np.empty(npts)
    for i in range(u.size):
        kq = math.floor(u[i])
        x = u[i] - kq
        for j in range(npts):
            p = 1.0
            for q in range(npts):
                if q != j:
                    p *= x - (q - half + 1)
            w[j] = p / denom[j]
        b = int(kq) - (half - 1) - k0
        for c in range(m):
            acc = 0.0
            for j in range(npts):
                acc += w[j] * vals[b + j, c]
            out[i, c] = acc


def grid_interp(u: np.ndarray, k0: int, vals: np.ndarray, out: np.ndarray) -> None:
    """out[i, c] = the 8-point Lagrange interpolant of vals[:, c] at u[i].

    u : (n,) positions in units of the grid step; vals : (m_nodes, n_cols)
    values at the nodes k0, k0 + 1, ... (it must hold floor(u) - 3 ..
    floor(u) + 4 for every u); out : (n, n_cols), written."""
    _interp(np.ascontiguousarray(u, dtype=np.float64), int(k0), np.ascontiguousarray(vals), _DENOM, out)


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
