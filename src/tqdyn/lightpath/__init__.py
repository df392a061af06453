"""Light paths of the constellation (physics): light travel times, Shapiro delay, ranges, proper times.

Modules: :mod:`~tqdyn.lightpath.light_time` (the light-time solver,
:func:`light_travel_times`, :func:`light_travel_times_of`,
:func:`link_bodies`; geocentric GCRS and heliocentric BCRS),
:mod:`~tqdyn.lightpath.results` (:class:`LightTravelTimes`),
:mod:`~tqdyn.lightpath.shapiro` (:func:`shapiro_delay`),
:mod:`~tqdyn.lightpath.ranges` (:func:`instantaneous_ranges`),
:mod:`~tqdyn.lightpath.proper_time` (proper times of the satellites' clocks
in the GCRS and the LISA orbit-file quantities),
:mod:`~tqdyn.lightpath.proper_time_bcrs` (proper times of heliocentric
clocks against TDB or TCB, and of geocentric ones against TCB),
:mod:`~tqdyn.lightpath.heliocentric` (the Sun's barycentric motion and the
bodies' states from the ephemeris) and :mod:`~tqdyn.lightpath.lisa_bcrs`
(the quantities of a BCRS / TCB LISA orbit file).
The public names of the first four are re-exported here.
"""

from .light_time import BODY_LAYOUTS, light_travel_times, light_travel_times_of, link_bodies
from .ranges import instantaneous_ranges
from .results import LightTravelTimes
from .shapiro import shapiro_delay

__all__ = [
    "BODY_LAYOUTS",
    "LightTravelTimes",
    "instantaneous_ranges",
    "light_travel_times",
    "light_travel_times_of",
    "link_bodies",
    "shapiro_delay",
]
