"""The right-hand side of the propagated system.

State layout: y (n_body, 6[, 2]) with rows (x, y, z, vx, vy, vz) [m, m/s],
GCRS, geocentric; trailing axis 2 in dd mode (see :mod:`tqdyn.precision`).
Each body moves under the force model of :mod:`tqdyn.forces.model`.
"""

from __future__ import annotations

from numba import njit

from .forces.model import gravity
from .precision import ld, st

__all__ = ["system_rhs"]


@njit(cache=True)
def system_rhs(y, tdat, params, layout, k):
    """dy/dt for every body: k[b, 0:3] = v_b, k[b, 3:6] = a(r_b).

    y, k: (n_body, 6[, 2]); tdat: (n_tdat,) float64 time-only inputs at the
    instant of y; params, layout: the force model's.  Units m/s and m/s^2.
    """
    for b in range(y.shape[0]):
        ax, ay, az = gravity(ld(y, b, 0), ld(y, b, 1), ld(y, b, 2), ld(y, b, 3), ld(y, b, 4), ld(y, b, 5),
                             tdat, params, layout)
        for q in range(3):
            st(k, ld(y, b, q + 3), b, q)
        st(k, ax, b, 3)
        st(k, ay, b, 4)
        st(k, az, b, 5)
