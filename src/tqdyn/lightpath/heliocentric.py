"""The solar system around heliocentric light paths and clocks (physics, no I/O).

Heliocentric trajectories (:data:`tqdyn.astro.reference.HELIOCENTRIC`) are
Sun-centred coordinates of the TDB-compatible BCRS, t in TDB seconds since
the epoch.  Their light-time equation and their clocks' proper times hold
in the barycentric coordinates, in which the Sun moves; this module gives
what they need from the JPL ephemeris, at the ephemeris dates
:meth:`tqdyn.astro.reference.ReferenceSystem.ephemeris_jd` of the grid:

* :func:`sun_barycentric_motion`: the Sun's barycentric position S [m],
  velocity dS/dt [m/s] (~10-15 m/s, dominated by Jupiter and Saturn) and
  acceleration [m/s^2] (~2e-7 m/s^2), ICRF axes.  S and dS/dt are the
  barycentric minus the heliocentric state of the Earth (the public
  :meth:`~tqdyn.astro.ephemeris.Ephemeris.earth_barycentric` and
  :meth:`~tqdyn.astro.ephemeris.Ephemeris.heliocentric_states`; rounding
  ~3e-5 m and ~4e-12 m/s), the acceleration the central difference of
  dS/dt over +-300 s (truncation ~1e-16 m/s^2, rounding ~1e-14 m/s^2);
* :func:`ssb_states`: Sun-centred states moved to the solar-system
  barycentre (+ the Sun's barycentric motion);
* :func:`body_states`: Sun-centred positions and velocities of the Earth,
  the Moon and the planets (system barycentres);
* :func:`ephemeris_of`, :func:`run_third_bodies`, :func:`resolve_bodies`:
  the run's ephemeris and third bodies from the trajectory's scenario, and
  the body lists that the light-time and proper-time options accept.
"""

from __future__ import annotations

import tomllib

import numpy as np

from .._choices import allowed, did_you_mean
from ..forces.body_gms import BODY_GM_KEYS
from ..astro.ephemeris import HELIOCENTRIC_BODIES, Ephemeris, default_ephemeris, planetary_gm
from ..astro.reference import HELIOCENTRIC
from ..numerics.dd import np_dd_add_d

__all__ = ["BODY_SETS", "body_states", "ephemeris_of", "gm_of", "resolve_bodies", "run_third_bodies",
           "ssb_states", "sun_barycentric_motion"]

#: Named body lists: ``"third_bodies"`` = the run's ``forces.third_bodies``
#: (the heliocentric ones), ``"all"`` = every body of
#: :data:`tqdyn.astro.ephemeris.HELIOCENTRIC_BODIES` (Earth, Moon, Mercury .. Neptune).
BODY_SETS = ("third_bodies", "all")

_FD_STEP = 300.0  # s, central difference of the Sun's barycentric velocity


def _scenario(trajectory) -> dict:
    text = str(getattr(trajectory, "scenario_toml", "") or "")
    try:
        return tomllib.loads(text) if text else {}
    except tomllib.TOMLDecodeError:
        return {}


def ephemeris_of(trajectory) -> Ephemeris:
    """The JPL ephemeris of the run that wrote ``trajectory``: its scenario's
    ``forces.ephemeris`` ("de421", the shipped default, or a .bsp path);
    the shipped DE421 when the trajectory has no scenario."""
    name = str(_scenario(trajectory).get("forces", {}).get("ephemeris", "de421"))
    return default_ephemeris() if name.lower() == "de421" else Ephemeris(name)


def run_third_bodies(trajectory) -> tuple[str, ...]:
    """The run's third bodies (scenario ``forces.third_bodies``) that the
    ephemeris gives heliocentrically (the Sun, the central body, excluded); () without a scenario."""
    names = _scenario(trajectory).get("forces", {}).get("third_bodies", ())
    return tuple(str(b).lower() for b in names if str(b).lower() in HELIOCENTRIC_BODIES)


def resolve_bodies(spec, trajectory=None) -> tuple[str, ...]:
    """Body names from ``spec``: None or () -> (); ``"third_bodies"`` -> the
    run's (:func:`run_third_bodies`); ``"all"`` -> :data:`HELIOCENTRIC_BODIES`;
    a sequence of names -> those (lower case, checked).  ValueError for an
    unknown name (the Sun, the origin, is not a deflector: its terms are
    always the central body's)."""
    if spec is None:
        return ()
    if isinstance(spec, str):
        if spec == "third_bodies":
            return run_third_bodies(trajectory) if trajectory is not None else ()
        if spec == "all":
            return HELIOCENTRIC_BODIES
        spec = (spec,)
    out = []
    for b in spec:
        key = str(b).lower()
        if key not in HELIOCENTRIC_BODIES:
            raise ValueError(f"body {b!r} is not allowed{did_you_mean(key, HELIOCENTRIC_BODIES)}; allowed: "
                             f"{allowed(HELIOCENTRIC_BODIES)}, or "
                             f"{' / '.join(repr(s) for s in BODY_SETS)} (the Sun is the central body)")
        if key not in out:
            out.append(key)
    return tuple(out)


def gm_of(bodies, trajectory=None) -> np.ndarray:
    """(K,) GMs [m^3/s^2] of ``bodies``, TDB-compatible, planets as systems:
    the run's own (its scenario's ``forces.gm_sun``, ``gm_earth_tdb``,
    ``gm_moon``, ``gm_<planet>``; :data:`tqdyn.forces.body_gms.BODY_GM_KEYS`)
    when ``trajectory`` has them, else the DE430/DE431 values of
    :func:`tqdyn.astro.ephemeris.planetary_gm` (the keys' defaults)."""
    gm = planetary_gm()
    forces = _scenario(trajectory).get("forces", {}) if trajectory is not None else {}
    out = []
    for b in bodies:
        value = forces.get(BODY_GM_KEYS.get(b, ""))
        try:
            out.append(float(value) if value is not None else float(gm[b]))
        except (TypeError, ValueError):
            out.append(float(gm[b]))
    return np.array(out, dtype=np.float64)


def _times(t) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(t, tuple):
        return tuple(np.asarray(p, np.float64) for p in t)
    th = np.asarray(t, np.float64)
    return th, np.zeros_like(th)


def sun_barycentric_motion(ephemeris: Ephemeris, epoch, t, reference=HELIOCENTRIC):
    """The Sun's barycentric position [m], velocity [m/s] and acceleration
    [m/s^2] at t (dd (hi, lo) or float64 (N,) seconds of the reference's
    time scale since ``epoch``, a :class:`tqdyn.astro.timescales.Epoch`),
    BCRS (TDB-compatible), ICRF axes: three float64 arrays (N, 3)."""
    th, tl = _times(t)

    def state(dt):  # the ephemeris's segment 0 -> 10
        return ephemeris.sun_barycentric(*reference.ephemeris_jd(epoch, th, tl + dt))

    s, v = state(0.0)
    _, vp = state(_FD_STEP)
    _, vm = state(-_FD_STEP)
    return s, v, (vp - vm) / (2.0 * _FD_STEP)


def ssb_states(ephemeris: Ephemeris, epoch, t, bodies, reference=HELIOCENTRIC) -> dict:
    """Sun-centred states -> BCRS states with the origin at the solar-system barycentre.

    t as :func:`sun_barycentric_motion` (N,) [s TDB since ``epoch``];
    bodies: name -> (r, v, a), r and v dd (hi, lo) pairs of (N, ..., 3) [m,
    m/s] and a float64 (N, ..., 3) [m/s^2], Sun-centred BCRS
    (TDB-compatible, ICRF axes).  Each state gets the Sun's barycentric
    position, velocity and acceleration S, dS/dt, d2S/dt2 at the same TDB
    (x + S, v + dS/dt in dd; a + d2S/dt2).  Returns a dict: ``t`` (hi,
    lo), ``x_sun``, ``v_sun``, ``a_sun`` (N, 3) and ``bodies``: name ->
    ((hi, lo) positions [m], (hi, lo) velocities [m/s], float64
    accelerations [m/s^2]).
    """
    th, tl = _times(t)
    x_s, v_s, a_s = sun_barycentric_motion(ephemeris, epoch, (th, tl), reference)
    out = {}
    for name, (r, v, a) in bodies.items():
        rh, rl = (np.asarray(p, np.float64) for p in r)
        vh, vl = (np.asarray(p, np.float64) for p in v)
        shape = (-1,) + (1,) * (rh.ndim - 2) + (3,)  # broadcast over the bodies' axes
        out[name] = (np_dd_add_d(rh, rl, x_s.reshape(shape) + 0.0 * rh),
                     np_dd_add_d(vh, vl, v_s.reshape(shape) + 0.0 * vh),
                     np.asarray(a, np.float64) + a_s.reshape(shape))
    return {"t": (th, tl), "x_sun": x_s, "v_sun": v_s, "a_sun": a_s, "bodies": out}


def body_states(ephemeris: Ephemeris, epoch, t, bodies, reference=HELIOCENTRIC, *, velocity: bool = True):
    """Sun-centred positions [m] and velocities [m/s] (or None) of ``bodies``
    (names of :data:`HELIOCENTRIC_BODIES`) at t (as
    :func:`sun_barycentric_motion`): float64 arrays (N, K, 3), BCRS
    (TDB-compatible), ICRF axes."""
    th, tl = _times(t)
    if not bodies:
        z = np.zeros(th.shape + (0, 3))
        return z, (z.copy() if velocity else None)
    jd1, jd2 = reference.ephemeris_jd(epoch, th, tl)
    return ephemeris.heliocentric_states(tuple(bodies), jd1, jd2, velocity=velocity)
