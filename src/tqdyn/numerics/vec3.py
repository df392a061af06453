"""3-vectors as float64 tuples, for compiled (numba) kernels.

The kernels of the right-hand side work on 3-tuples rather than arrays: a
tuple lives in registers, an array slice is a heap object with a reference
count.  These helpers are the one implementation of the elementary vector
operations for those kernels; the numpy modules use numpy's own operations.
IEEE order of operations, no fastmath: ``cross(a, b)`` is always
``(a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0)``.
"""

from __future__ import annotations

from .jit import inner_kernel

__all__ = ["add", "axpy", "cross", "dot", "row", "scale", "sub"]


@inner_kernel
def add(a, b):
    """a + b."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@inner_kernel
def sub(a, b):
    """a - b."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@inner_kernel
def scale(s, a):
    """s * a (s a scalar)."""
    return (s * a[0], s * a[1], s * a[2])


@inner_kernel
def axpy(s, a, b):
    """s * a + b (s a scalar)."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


@inner_kernel
def dot(a, b):
    """a . b."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@inner_kernel
def cross(a, b):
    """a x b."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@inner_kernel
def row(x, m):
    """Row m of a (n, 3) array as a tuple."""
    return (x[m, 0], x[m, 1], x[m, 2])
