"""Scenarios: TOML files -> validated, frozen configuration dataclasses.

A scenario fixes everything a tqdyn run needs: the epoch, the initial
Keplerian elements of the satellites, the force model switches, the
integrator and the run length.  Numbers are read with
``tomllib.loads(..., parse_float=decimal.Decimal)`` and kept as ``Decimal``
so that decimal inputs such as ``raan_deg = 211.6`` stay exact until they are
converted at extended precision (see :mod:`tqdyn.astro.elements`).

Conventions
-----------
* Units: SI (m, s, m^3/s^2) unless the TOML key carries a unit suffix
  (``a_km``, ``*_deg``); the dataclasses store SI values with a unit suffix
  in the field name (``a_m``, ``step_s``, ``duration_s``, ``d_tm_m``).
* Frame: satellite elements are osculating two-body elements in the GCRS
  (geocentric, ICRF axes), referred to the scenario epoch.
* Time: ``scenario.epoch_utc`` is a UTC calendar date-time; run durations and
  steps are TT seconds after that epoch (see :mod:`tqdyn.astro.timescales`).

TOML layout (every section and key optional except at least one
``[[satellites]]`` entry with ``a_km``)::

    [scenario]      name, description, epoch_utc, central_body ("earth"), extends (a built-in scenario
                    whose tables this file updates key by key), allow_below_surface
                    (false: every satellite starts outside the central body)
    [run]           duration ("10d", "12h", "30min", "3600s" or seconds),
                    precision ("dd" | "float64"), output, output_every,
                    max_steps (default 1e9: the most steps a run may have)
    [integrator]    method ("multistep" | "dp87"; not given: DEFAULT_METHOD with mode = "fixed",
                    "dp87" adaptive), mode ("fixed" | "adaptive"), step [s],
                    tableau ("corrected" | "published"), rtol; multistep: order,
                    corrector ("pe" | "pec" | "pece" | "pecec" | "pecece")
    [forces]        earth_monopole, gm_earth [m^3/s^2], the force-model switches,
                    gm_sun, gm_earth_tdb, gm_moon, gm_mercury .. gm_neptune
                    [m^3/s^2, TDB-compatible; default DE430/DE431]
    [constellation] pointing ("none" | "global" | "taylor1" | "taylor2" |
                    "iterative"), control ("on" | "off"), free_tms (bool),
                    tm_gravity ("differential" | "direct")
    [spacecraft]    d_tm [m], d_p [m], tm_axis ("x" | "y" | "z"),
                    self_gravity ("table-iv" | "off" | array (2, 3) or
                    (3, 2, 3) [m/s^2] in OA_l), self_gravity_common (array
                    (3,) or (3, 3) [m/s^2] in S, on both TMs of a satellite)
    [[satellites]]  name, a_km, e, i_deg, raan_deg, argp_deg, nu_deg (any number
                    for point masses, exactly 3 for a coupled constellation)

Errors are :class:`ScenarioError` (a ``ValueError``) with one line
``"<field>: <value> <problem>; allowed: <what is allowed>"``.

Modules: :mod:`tqdyn.scenario.config` (the dataclasses, their validation,
:meth:`Scenario.to_toml`), :mod:`tqdyn.scenario.loader` (TOML schema,
overrides, ``extends``, built-in scenarios in ``tqdyn/scenario/builtin/``),
:mod:`tqdyn.scenario.record` (the constants a run uses besides its keys, as
a trajectory file records them).
"""

from __future__ import annotations

from . import config, loader
from .config import *  # noqa: F401,F403
from .loader import *  # noqa: F401,F403

__all__ = config.__all__ + loader.__all__
