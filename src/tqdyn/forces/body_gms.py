"""The GMs of the point-mass bodies a run uses, as its scenario gives them.

Every GM of a body other than the geocentric central body (``forces.gm_earth``)
enters a run from the scenario keys of :data:`BODY_GM_KEYS` (TDB-compatible,
m^3/s^2; their defaults are the DE430/DE431 values of ``data/gm_de431.tpc``),
so that a run is reproduced from its resolved scenario alone.
"""

from __future__ import annotations

__all__ = ["BODY_GM_KEYS", "body_gms", "default_body_gm"]

#: The scenario key ([forces], an attribute of the scenario's ``ForcesConfig``) of each point-mass body's
#: GM [m^3/s^2], TDB-compatible (the ephemerides' values; default ``data/gm_de431.tpc``, DE430/DE431):
#: the Sun's wherever it enters (heliocentric central body, third body, tides, relativity, J2), the
#: Earth's as a heliocentric third body (the geocentric model's own GM is ``forces.gm_earth``, EGM2008,
#: TT-compatible), the Moon's and the planetary systems'.
BODY_GM_KEYS = {"sun": "gm_sun", "earth": "gm_earth_tdb", "moon": "gm_moon", "mercury": "gm_mercury",
                "venus": "gm_venus", "mars": "gm_mars", "jupiter": "gm_jupiter", "saturn": "gm_saturn",
                "uranus": "gm_uranus", "neptune": "gm_neptune"}


def body_gms(forces) -> dict[str, float]:
    """{body: GM [m^3/s^2]} of the point-mass bodies of :data:`BODY_GM_KEYS`
    as ``forces`` (a scenario's ``ForcesConfig``) gives them, float64 (one
    rounding of the exact decimal), TDB-compatible.  Every GM a run uses
    comes from here, so that a run is reproduced from its resolved scenario
    alone; a ``forces`` object without a key falls back to
    :func:`tqdyn.astro.ephemeris.planetary_gm` for it."""
    out, defaults = {}, None
    for body, key in BODY_GM_KEYS.items():
        value = getattr(forces, key, None)
        if value is None:
            if defaults is None:
                from ..astro.ephemeris import planetary_gm

                defaults = planetary_gm()
            out[body] = float(defaults[body])
        else:
            out[body] = float(value)
    return out


def default_body_gm(body: str):
    """The exact (``Decimal``) DE430/DE431 GM [m^3/s^2] of ``body`` in the
    shipped ``data/gm_de431.tpc`` (km^3/s^2 times 1e9), in its shortest
    decimal form: the default of the body's key in :data:`BODY_GM_KEYS`."""
    from ..astro.ephemeris import NAIF_ID
    from ..readers import pck

    return pck.shipped_gm(exact=True)[NAIF_ID[body]].normalize()
