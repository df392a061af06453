"""Point-mass third bodies whose positions come from a JPL ephemeris.

:func:`third_bodies` builds a :class:`tqdyn.forces.third_body.ThirdBodies`
term (Battin's cancellation-free direct-minus-indirect acceleration) for a
list of bodies of :data:`tqdyn.astro.ephemeris.BODIES`: positions from
:meth:`tqdyn.astro.ephemeris.Ephemeris.geocentric_states` at the geocentre's
TDB (:func:`tqdyn.astro.timescales.tdb_jd`), GMs from
:func:`tqdyn.astro.ephemeris.planetary_gm` (DE430/DE431 values; the planets
as whole systems at their barycenters).  By default (``gcrs``) both are
transformed from the ephemeris's TDB-compatible BCRS to the TT-compatible
GCRS of the dynamics (:func:`tqdyn.astro.geocentric.bcrs_to_gcrs`,
1.5e-8 relative; the Sun and the Moon always enter the Earth's barycentric
acceleration and potential there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..astro.ephemeris import BODIES, Ephemeris, default_ephemeris, planetary_gm
from ..astro.geocentric import TDB_TO_TT_SCALE, bcrs_to_gcrs_offsets
from ..astro.ephemeris_dd import tdb_seconds_dd
from ..astro import timescales
from ..astro.timescales import tdb_jd, tt_jd
from ..numerics.dd import np_dd_add_d, np_fast_two_sum, np_two_prod
from ..numerics.lagrange import MARGIN, grid_interp
from .third_body import ThirdBodies

__all__ = ["EphemerisPositions", "third_bodies"]


@dataclass(frozen=True)
class EphemerisPositions:
    """Position provider of :class:`ThirdBodies`: a picklable callable
    (epoch, t_hi, t_lo) -> (*shape(t_hi), n_bodies, 3) float64 geocentric
    positions [m] of ``names`` at t = t_hi + t_lo [s TT since epoch]: the
    ephemeris at the geocentre's TDB (:func:`tqdyn.astro.timescales.tdb_jd`),
    transformed to the TT-compatible GCRS when ``gcrs`` (else the BCRS
    differences, TDB-compatible, as in tqdyn 0.1).  ``gms``: ((body, GM
    [m^3/s^2], TDB-compatible), ...) of the bodies whose potential enters
    the transformation (the Sun, the Moon and ``names``; empty: the shipped
    DE430/DE431 values of :func:`tqdyn.astro.ephemeris.planetary_gm`)."""

    ephemeris: Ephemeris
    names: tuple[str, ...]
    gcrs: bool = True
    gms: tuple = ()

    def __call__(self, epoch, t_hi, t_lo=0.0) -> np.ndarray:
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        pos, _ = self.ephemeris.geocentric_states(self.names, jd1, jd2, velocity=False)
        if not self.gcrs:
            return pos
        return TDB_TO_TT_SCALE * (pos + self._delta(epoch, t_hi, t_lo, pos.shape))

    def position_dd(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """The positions of ``__call__`` as smooth functions of time: (hi,
        lo), each (*shape(t_hi), n_bodies, 3) float64 [m], a dd pair.  The
        ephemeris in dd at a dd TDB argument
        (:meth:`tqdyn.astro.ephemeris.Ephemeris.geocentric_positions_dd`), the
        1PN part delta (float64, interpolated: smooth) added and K applied in
        dd."""
        jd1, jd2 = tt_jd(epoch, t_hi, t_lo)
        th, tl = tdb_seconds_dd(epoch, t_hi, t_lo, timescales.tdb_minus_tt(jd1, jd2))  # as tdb_jd looks it up
        hi, lo = self.ephemeris.geocentric_positions_dd(self.names, th, tl)
        if not self.gcrs:
            return hi, lo
        hi, lo = np_dd_add_d(hi, lo, self._delta(epoch, t_hi, t_lo, hi.shape))  # |delta| <= 1.5e-8 |pos|
        p, e = np_two_prod(hi, np.float64(TDB_TO_TT_SCALE))
        return np_fast_two_sum(p, e + lo * TDB_TO_TT_SCALE)

    def _delta(self, epoch, t_hi, t_lo, shape) -> np.ndarray:
        """The 1PN part delta [m] (shape) of X = K (r + delta) at t_hi + t_lo:
        (<= 1.5e-8 r; periods >= 27 d) on an hourly TT grid, interpolated
        (error ~ (2 pi h / 27 d)^8 / 8! delta < 1e-19 m)."""
        u = (np.asarray(t_hi, dtype=np.float64) + np.asarray(t_lo, dtype=np.float64)) / _GRID_S
        u = np.broadcast_to(u, shape[:-2]).ravel()
        if u.size == 0:
            return np.zeros(shape)
        k0 = int(math.floor(u.min())) - MARGIN
        k1 = int(math.floor(u.max())) + MARGIN + 1
        delta = self.correction(epoch, np.arange(k0, k1, dtype=np.float64) * _GRID_S)
        out = np.empty((u.size, delta.shape[1] * 3))
        grid_interp(u, k0, delta.reshape(delta.shape[0], -1), out)
        return out.reshape(shape)

    def correction(self, epoch, t) -> np.ndarray:
        """delta = X / K - r [m] (m, n_bodies, 3) at t (m,) [s TT since epoch]:
        the 1PN terms of :func:`tqdyn.astro.geocentric.bcrs_to_gcrs` (the Sun
        and the Moon always enter the Earth's potential and acceleration)."""
        jd1, jd2 = tdb_jd(epoch, t)
        bodies = self.names + tuple(b for b in ("sun", "moon") if b not in self.names)
        pos, vel = self.ephemeris.geocentric_states(bodies, jd1, jd2, velocity=True)
        _, v_earth = self.ephemeris.earth_barycentric(jd1, jd2)
        gm = dict(self.gms) if self.gms else planetary_gm()
        # formed without pos (X / K - pos would carry pos's rounding, ~3e-5 m for the Sun, into the
        # nodes, and the interpolant would jump by that much from one grid interval to the next)
        n = len(self.names)
        return bcrs_to_gcrs_offsets(pos, vel, v_earth, np.array([gm[b] for b in bodies]))[:, :n]


#: Step [s] of the grid of the 1PN correction.
_GRID_S = 3600.0


def third_bodies(ephemeris: Ephemeris | None = None, names=BODIES, extended=(), gcrs: bool = True,
                 gms=None) -> ThirdBodies:
    """Third-body term for ``names`` (default: all of
    :data:`tqdyn.astro.ephemeris.BODIES`) with positions from ``ephemeris``
    (``None``: the shipped DE421, :func:`tqdyn.astro.ephemeris.default_ephemeris`)
    and GMs [m^3/s^2, TDB-compatible] from ``gms`` ({body: GM}, the
    scenario's ``forces.gm_*``; None: ``data/gm_de431.tpc``); the bodies named in
    ``extended`` (and in ``names``) are evaluated in extended precision.
    ``gcrs``: positions and GMs in the TT-compatible GCRS (the GMs times
    :data:`tqdyn.astro.geocentric.TDB_TO_TT_SCALE`); False: as the ephemeris
    gives them.

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
    gm = planetary_gm() if gms is None else dict(gms)
    used = names + tuple(b for b in ("sun", "moon") if b not in names)
    return ThirdBodies(
        names=names,
        gms=tuple(gm[n] * (TDB_TO_TT_SCALE if gcrs else 1.0) for n in names),
        position=EphemerisPositions(eph, names, gcrs, tuple((b, float(gm[b])) for b in used)),
        source=(f"JPL {eph.name} ({eph.path}) via jplephem; GM: "
                + ("tqdyn/data/gm_de431.tpc" if gms is None else "the scenario's forces.gm_* (default gm_de431.tpc)")
                + " (DE430/DE431; planets as systems at their barycenters)"
                + ("; BCRS -> TT-compatible GCRS (1PN)" if gcrs else "; BCRS differences, TDB-compatible")),
        extended=tuple(n for n in names if n in extended),
    )
