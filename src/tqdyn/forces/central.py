"""Point-mass (monopole) gravity of the central body, in extended precision.

The monopole is the one force term large enough (~4e-2 m/s^2 at 1e5 km)
that float64 round-off (4e-18 m/s^2) would show in the propagated orbits, so
it is evaluated in the propagation's own number type (double-double in dd
mode) -- see :mod:`tqdyn.numerics.dd`.  Every other term is a small
perturbation evaluated in float64 and added to it.

Its time derivatives, the jerk and the snap, are here too: the local
pointing laws need the remote satellite's jerk (omega_dot contains jerk / c)
and snap (taylor2, the iterative law's Taylor model of the remote orbit).
For a body at r moving with v and accelerating with a::

    J = -gm [v/r^3 - 3 (r.v) r/r^5]
    S = -gm [a/r^3 - 6 (r.v) v/r^5 - 3 (v.v + r.a) r/r^5 + 15 (r.v)^2 r/r^7]

(the snap with the *given* total acceleration a, in which it is linear).
:func:`monopole_jerk_snap` is the compiled version on 3-tuples,
:func:`central_jerk_snap` the vectorised numpy one; tests/test_jerks.py
checks both against finite differences of :func:`monopole` along a Kepler
orbit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..numerics.dd import add, dd_from_mp, div, mul, neg, sqrt
from ..numerics.vec3 import axpy, dot, scale
from ..numerics.jit import inner_kernel

__all__ = ["monopole", "monopole_jerk_snap", "central_jerk_snap", "EarthMonopole"]


@inner_kernel
def monopole(x, y, z, gm):
    """Acceleration -gm r / |r|^3 [m/s^2] at r = (x, y, z) [m] relative to the
    body's center, in the frame of r.  Generic: dd tuples or float64 scalars.
    gm [m^3/s^2] in the same number type (or float64).  Returns (ax, ay, az)."""
    r2 = add(add(mul(x, x), mul(y, y)), mul(z, z))
    f = div(gm, mul(r2, sqrt(r2)))
    return neg(mul(f, x)), neg(mul(f, y)), neg(mul(f, z))


@inner_kernel
def monopole_jerk_snap(r, v, a, gm):
    """Jerk [m/s^3] and snap [m/s^4] of -gm r/|r|^3 (snap with the given a).

    r [m], v [m/s], a [m/s^2]: float64 3-tuples in one inertial frame, at one
    instant; gm [m^3/s^2].  Returns (jerk, snap) as 3-tuples in that frame."""
    r2 = dot(r, r)
    rn = math.sqrt(r2)
    ir3 = 1.0 / (r2 * rn)
    ir5 = ir3 / r2
    ir7 = ir5 / r2
    rv = dot(r, v)
    jerk = scale(-gm, axpy(-3.0 * rv * ir5, r, scale(ir3, v)))
    cr = -3.0 * (dot(v, v) + dot(r, a)) * ir5 + 15.0 * rv * rv * ir7
    snap = scale(-gm, axpy(cr, r, axpy(-6.0 * rv * ir5, v, scale(ir3, a))))
    return jerk, snap


def central_jerk_snap(r, v, gm, a=None):
    """Jerk and snap of the point-mass (monopole) acceleration a = -gm r / |r|^3.

    Parameters
    ----------
    r : (..., 3) m, v : (..., 3) m/s -- state relative to the body, one
        inertial frame (float64 or a (hi, lo) pair); gm : float, m^3/s^2.
    a : (..., 3) m/s^2, optional -- the actual acceleration to use in the snap
        (default: the monopole's); the snap is linear in it.

    Returns
    -------
    jerk (..., 3) m/s^3 and snap (..., 3) m/s^4, same frame and epochs (the
    formulas of the module docstring).
    """
    r = _plain(r)
    v = _plain(v)
    gm = float(gm)
    rn = np.sqrt(np.sum(r * r, axis=-1))[..., None]
    rv = np.sum(r * v, axis=-1)[..., None]
    if a is None:
        a = -gm * r / rn**3
    else:
        a = _plain(a)
    jerk = -gm * (v / rn**3 - 3.0 * rv * r / rn**5)
    vv = np.sum(v * v, axis=-1)[..., None]
    ra = np.sum(r * a, axis=-1)[..., None]
    snap = -gm * (a / rn**3 - 6.0 * rv * v / rn**5 - 3.0 * (vv + ra) * r / rn**5 + 15.0 * rv**2 * r / rn**7)
    return jerk, snap


def _plain(x):
    """float64 array from an array or a (hi, lo) pair (hi + lo)."""
    if isinstance(x, tuple):
        return np.asarray(x[0], dtype=np.float64) + np.asarray(x[1], dtype=np.float64)
    return np.asarray(x, dtype=np.float64)


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
