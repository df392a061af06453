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

Version 0.2 has one: :data:`GEOCENTRIC`.  Its time axis is the one version
0.1 used -- TT-elapsed seconds labelled TDB, the JPL ephemerides read at
TDB(epoch) + t (docs/design.md, "Time axis").
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CENTRAL_BODIES", "GEOCENTRIC", "REFERENCE_SYSTEMS", "ReferenceSystem", "reference_system"]


@dataclass(frozen=True)
class ReferenceSystem:
    """Origin, axes and coordinate time of a propagation.

    central_body : the origin of the coordinates (and of the elements of
        the initial states), a name of :data:`CENTRAL_BODIES`;
    frame : the axes and reference system, ``"GCRS"`` (geocentric celestial
        reference system: ICRF axes, origin at the geocentre);
    time_scale : the time scale of t (seconds since the scenario epoch);
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


#: The geocentric system of TianQin: GCRS, Earth-centred, ICRF axes.
GEOCENTRIC = ReferenceSystem(
    central_body="earth", frame="GCRS", time_scale="TDB",
    description="geocentric GCRS (origin the geocentre, ICRF axes); t in seconds since the epoch, labelled TDB")

#: Every reference system tqdyn propagates in.
REFERENCE_SYSTEMS = (GEOCENTRIC,)
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
