"""Reference systems: the origin, the axes and the coordinate time of a propagation.

Every state tqdyn propagates, every force it evaluates and every trajectory
file it writes is relative to one :class:`ReferenceSystem`: a central body
(the origin of the coordinates and the body whose point mass is the leading
term), a frame (the axes and the relativistic reference system whose
coordinate time the equations of motion use) and a time scale (what the
independent variable t measures, in seconds since the scenario epoch).  The
scenario names the central body (``scenario.central_body``); the reference
system follows from it, the force model carries it and the trajectory file
records it (root attributes ``origin``, ``frame``, ``time_scale``).

Version 0.2 has two:

* :data:`GEOCENTRIC` (TianQin), whose coordinate time is TT (the geocentric
  equations of motion and EGM2008's GM are TT-compatible): t is seconds of
  TT since the epoch's TT, the JPL ephemerides are read at TDB(TT)
  (:func:`tqdyn.astro.timescales.tdb_jd`);
* :data:`HELIOCENTRIC` (LISA, Taiji): Sun-centred coordinates of the
  TDB-compatible BCRS with ICRF axes, t in TDB seconds since the epoch's
  TDB; the JPL ephemerides (and their GMs) are TDB-compatible already and
  are read at TDB(epoch) + t.

:meth:`ReferenceSystem.ephemeris_jd` is the one place where t becomes the
ephemerides' TDB argument.  Trajectory files of format version
1 (tqdyn 0.1) are geocentric with ``time_scale = "TDB"``: their t is
TT-elapsed seconds labelled TDB, and the ephemerides of that version were
read at TDB(epoch) + t (:data:`GEOCENTRIC_V1`, docs/design.md).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CENTRAL_BODIES", "GEOCENTRIC", "GEOCENTRIC_V1", "HELIOCENTRIC", "REFERENCE_SYSTEMS", "ReferenceSystem", "reference_system"]


@dataclass(frozen=True)
class ReferenceSystem:
    """Origin, axes and coordinate time of a propagation.

    central_body : the origin of the coordinates (and of the elements of
        the initial states), a name of :data:`CENTRAL_BODIES`;
    frame : the axes and reference system, ``"GCRS"`` (geocentric celestial
        reference system: ICRF axes, origin at the geocentre) or ``"BCRS"``
        (barycentric celestial reference system: ICRF axes; here with the
        origin moved to the Sun's centre, a Newtonian translation);
    time_scale : the time scale of t (seconds since the scenario epoch),
        ``"TT"`` or ``"TDB"``;
    description : one line for ``tqdyn info`` and the docs.
    """

    central_body: str
    frame: str
    time_scale: str
    description: str

    @property
    def origin(self) -> str:
        """The origin of the coordinates (the central body's name), as the trajectory file records it."""
        return self.central_body

    def ephemeris_jd(self, epoch, t_hi, t_lo=0.0):
        """Two-part TDB Julian date [d] (jd1, jd2) at which the JPL
        ephemerides are read for t = t_hi + t_lo [s of :attr:`time_scale`
        since ``epoch``, a :class:`tqdyn.astro.timescales.Epoch`]: TDB(TT)
        for a TT axis (:func:`tqdyn.astro.timescales.tdb_jd`), the epoch's
        TDB plus t for a TDB axis (:func:`tqdyn.astro.timescales.tdb_after`).
        Arrays of the broadcast shape of t_hi and t_lo, ps resolution."""
        from .timescales import tdb_after, tdb_jd

        if self.time_scale == "TDB":
            return tdb_after(epoch, t_hi, t_lo)
        return tdb_jd(epoch, t_hi, t_lo)


#: The geocentric system of TianQin: GCRS, Earth-centred, ICRF axes, TT.
GEOCENTRIC = ReferenceSystem(
    central_body="earth", frame="GCRS", time_scale="TT",
    description="geocentric GCRS (origin the geocentre, ICRF axes, TT-compatible); t in TT seconds since the "
                "epoch, the JPL ephemerides at TDB(TT)")
#: The heliocentric system of LISA and Taiji: Sun-centred BCRS, ICRF axes, TDB.
HELIOCENTRIC = ReferenceSystem(
    central_body="sun", frame="BCRS", time_scale="TDB",
    description="heliocentric BCRS (origin the Sun's centre, ICRF axes, TDB-compatible); t in TDB seconds since "
                "the epoch, the JPL ephemerides at TDB(epoch) + t")
#: What a trajectory file of format version 1 (tqdyn 0.1) is relative to.
GEOCENTRIC_V1 = ReferenceSystem(
    central_body="earth", frame="GCRS", time_scale="TDB",
    description="format version 1 (tqdyn 0.1): geocentric GCRS; t is TT-elapsed seconds since the epoch labelled "
                "TDB, the ephemerides were read at TDB(epoch) + t (25 us/day off near 2004)")

#: Every reference system tqdyn propagates in.
REFERENCE_SYSTEMS = (GEOCENTRIC, HELIOCENTRIC)
_SYSTEMS = {r.central_body: r for r in REFERENCE_SYSTEMS}
#: Central bodies a scenario may name.
CENTRAL_BODIES = tuple(_SYSTEMS)


def reference_system(central_body: str) -> ReferenceSystem:
    """The reference system of a central body (ValueError naming the allowed ones otherwise)."""
    try:
        return _SYSTEMS[central_body]
    except (KeyError, TypeError):
        raise ValueError(f"central body {central_body!r} is not supported; allowed: "
                         f"{', '.join(repr(b) for b in CENTRAL_BODIES)}") from None
