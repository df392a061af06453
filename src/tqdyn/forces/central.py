"""Point-mass (monopole) gravity of the central body, in extended precision.

The monopole is the one force term large enough (~4e-2 m/s^2 at 1e5 km)
that float64 round-off (4e-18 m/s^2) would show in the propagated orbits, so
it is evaluated in the propagation's own number type (double-double in dd
mode) -- see :mod:`tqdyn.precision`.  Every other term is a small
perturbation evaluated in float64 and added to it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..numerics.dd import add, dd_from_mp, div, mul, neg, sqrt

__all__ = ["monopole", "EarthMonopole"]


@njit(cache=True)
def monopole(x, y, z, gm):
    """Acceleration -gm r / |r|^3 [m/s^2] at r = (x, y, z) [m] relative to the
    body's center, in the frame of r.  Generic: dd tuples or float64 scalars.
    gm [m^3/s^2] in the same number type (or float64).  Returns (ax, ay, az)."""
    r2 = add(add(mul(x, x), mul(y, y)), mul(z, z))
    f = div(gm, mul(r2, sqrt(r2)))
    return neg(mul(f, x)), neg(mul(f, y)), neg(mul(f, z))


@dataclass(frozen=True)
class EarthMonopole:
    """The Earth's point-mass term, GCRS, geocentric.

    gm: gravitational parameter [m^3/s^2] as an exact decimal (str/Decimal);
    default EGM2008's 3.986004415e14.  Parameters handed to the compiled
    model: [gm_hi, gm_lo] (dd pair of the exact value).
    """

    gm: object = "3.986004415e14"
    name: str = field(default="earth_monopole", init=False)
    description: str = field(default="Earth point mass, -GM r/|r|^3 (extended precision)", init=False)
    source: str = field(default="GM of EGM2008 (Pavlis et al. 2012)", init=False)
    n_tdat: int = field(default=0, init=False)

    def params(self) -> np.ndarray:
        """[gm_hi, gm_lo] float64 (value gm_hi + gm_lo, m^3/s^2)."""
        return np.array(dd_from_mp(self.gm), dtype=np.float64)

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """No time-only inputs: an (..., 0) array."""
        return np.zeros(np.shape(t_hi) + (0,))
