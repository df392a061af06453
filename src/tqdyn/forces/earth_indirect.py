"""Indirect effect of the Earth's non-central field: the Moon and the Sun
pull on the Earth's bulge, which accelerates the geocentre itself.

By Newton's third law the Moon's attraction on the Earth's non-central mass
(degrees >= 2) equals minus the Earth field's attraction on the Moon, so the
geocentre moves with a_E = -(GM_b / GM_E) g(s_b), g the Earth's non-central
field (degrees 2..N) at the body's geocentric position s_b.  In the
geocentric frame every satellite therefore feels

    a = + sum_b (GM_b / GM_E) g(s_b),

the same vector for all of them (it does not depend on the satellite's
position: time-only).  At the Moon's distance the J2 field is ~1.2e-9
m/s^2, so the Moon's share is ~1.5e-11 m/s^2 (comparable to the relativistic
terms); the Sun's is ~1e-14 m/s^2.  It is common to the three satellites and
so does not change inter-satellite ranges, but it moves the orbits at the
metre level over weeks.  Table II of the paper does not list it; tqdyn keeps
it as its own switchable term.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..astro.timescales import tdb_jd
from .earth import EarthField, earth_field_accel_batch
from ..numerics.jit import inner_kernel

__all__ = ["EarthFieldIndirect", "earth_field_indirect_accel"]


@inner_kernel
def earth_field_indirect_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """The geocentre's acceleration reversed [m/s^2, GCRS]: tdat[0:3]
    (precomputed; independent of the satellite's state)."""
    return tdat[0], tdat[1], tdat[2]


@dataclass(frozen=True)
class EarthFieldIndirect:
    """Indirect term of the Earth's non-central field (see module docstring).

    field: the Earth's static field (degrees 2..N, its own rotation
    provider); bodies: names of the attracting bodies; gms: their GM
    [m^3/s^2]; gm_earth [m^3/s^2]; ephemeris: object with
    ``geocentric_states(bodies, jd1, jd2, velocity=False)``.
    Time-only inputs: the acceleration (3) at each instant; no parameters.
    """

    field: EarthField
    bodies: tuple[str, ...]
    gms: tuple[float, ...]
    gm_earth: float
    ephemeris: object
    name: str = field(default="earth_field_indirect", init=False)
    description: str = field(
        default="geocentre acceleration by Moon/Sun on the Earth's non-central field (indirect term)", init=False)
    source: str = field(default="Newton's third law with the Earth field and the JPL ephemeris", init=False)
    n_tdat: int = field(default=3, init=False)

    def params(self) -> np.ndarray:
        """No parameters: an empty float64 array."""
        return np.zeros(0)

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """sum_b (GM_b / GM_E) g(s_b) at t = t_hi + t_lo [s TT since
        epoch]: float64 (*shape(t_hi), 3) [m/s^2, GCRS]."""
        shape = np.broadcast_shapes(np.shape(t_hi), np.shape(t_lo))
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        pos, _ = self.ephemeris.geocentric_states(self.bodies, jd1, jd2, velocity=False)  # (*shape, nb, 3)
        tdat = self.field.precompute(epoch, t_hi, t_lo).reshape(-1, self.field.n_tdat)
        params = self.field.params()
        out = np.zeros((tdat.shape[0], 3))
        pos = pos.reshape(-1, len(self.bodies), 3)
        for k, gm in enumerate(self.gms):
            g = earth_field_accel_batch(pos[:, k, :], tdat, params, part="static")
            out += (gm / self.gm_earth) * g
        return out.reshape(shape + (3,))
