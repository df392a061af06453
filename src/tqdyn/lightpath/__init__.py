"""Light paths of the constellation (physics): light travel times, Shapiro delay, ranges, proper times.

Modules: :mod:`~tqdyn.lightpath.light_time` (the light-time solver,
:func:`light_travel_times`, :func:`light_travel_times_of`,
:class:`LightTravelTimes`, :func:`link_bodies`), :mod:`~tqdyn.lightpath.shapiro`
(:func:`shapiro_delay`), :mod:`~tqdyn.lightpath.ranges`
(:func:`instantaneous_ranges`) and :mod:`~tqdyn.lightpath.proper_time`
(proper times of the satellites' clocks and the LISA orbit-file quantities).
The public names of the first three are re-exported here.
"""

from .light_time import BODY_LAYOUTS, LightTravelTimes, light_travel_times, light_travel_times_of, link_bodies
from .ranges import instantaneous_ranges
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
