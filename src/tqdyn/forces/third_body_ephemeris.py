"""Point-mass third bodies whose positions come from a JPL ephemeris.

:func:`third_bodies` builds a :class:`tqdyn.forces.third_body.ThirdBodies`
term (Battin's cancellation-free direct-minus-indirect acceleration) for a
list of bodies of :data:`tqdyn.ephemeris.BODIES`: positions from
:meth:`tqdyn.ephemeris.Ephemeris.geocentric_states` (geocentric, ICRF axes =
GCRS, TDB), GMs from :func:`tqdyn.ephemeris.planetary_gm` (DE430/DE431
values; the planets as whole systems at their barycenters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..astro.ephemeris import BODIES, Ephemeris, default_ephemeris, planetary_gm
from ..astro.timescales import tdb_jd
from .third_body import ThirdBodies

__all__ = ["EphemerisPositions", "third_bodies"]


@dataclass(frozen=True)
class EphemerisPositions:
    """Position provider of :class:`ThirdBodies`: a picklable callable
    (epoch, t_hi, t_lo) -> (*shape(t_hi), n_bodies, 3) float64 geocentric
    GCRS positions [m] of ``names`` at t = t_hi + t_lo [s TDB since epoch]
    (:func:`tqdyn.timescales.tdb_jd`, then the ephemeris)."""

    ephemeris: Ephemeris
    names: tuple[str, ...]

    def __call__(self, epoch, t_hi, t_lo=0.0) -> np.ndarray:
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        pos, _ = self.ephemeris.geocentric_states(self.names, jd1, jd2, velocity=False)
        return pos


def third_bodies(ephemeris: Ephemeris | None = None, names=BODIES, extended=()) -> ThirdBodies:
    """Third-body term for ``names`` (default: all of
    :data:`tqdyn.ephemeris.BODIES`) with positions from ``ephemeris``
    (``None``: the shipped DE421, :func:`tqdyn.ephemeris.default_ephemeris`)
    and GMs [m^3/s^2] from ``data/gm_de431.tpc``; the bodies named in
    ``extended`` (and in ``names``) are evaluated in extended precision.

    Returns a ThirdBodies (parameters [n, gm_1..gm_n]; time-only inputs: the
    3 n geocentric GCRS coordinates [m] per instant).  Raises ValueError for
    an unknown name, a name listed twice or a body the ephemeris lacks.
    """
    eph = default_ephemeris() if ephemeris is None else ephemeris
    if isinstance(names, str):
        names = (names,)
    names = tuple(str(n).lower() for n in names)
    if not names:
        raise ValueError("third bodies: empty list of bodies")
    if len(set(names)) != len(names):
        raise ValueError(f"third bodies: a body is listed twice in {names}")
    eph.validate_bodies(names)
    gm = planetary_gm()
    return ThirdBodies(
        names=names,
        gms=tuple(gm[n] for n in names),
        position=EphemerisPositions(eph, names),
        source=(f"JPL {eph.name} ({eph.path}) via jplephem; GM: tqdyn/data/gm_de431.tpc "
                f"(DE430/DE431; planets as systems at their barycenters)"),
        extended=tuple(n for n in names if n in extended),
    )
