"""The quantities of a BCRS / TCB LISA orbit file (physics): :func:`lisa_orbit_quantities_bcrs`.

LISA's tools take orbit files in the barycentric BCRS (origin the
solar-system barycentre) with TCB as coordinate time, in TCB-compatible
units.  From a tqdyn trajectory (heliocentric: Sun-centred BCRS, TDB;
geocentric: TT-compatible GCRS, TT):

* time: TCB - TCB_epoch = S (TDB - TDB_epoch), S = 1/(1 - L_B)
  (:func:`tqdyn.astro.timescales.tdb_to_tcb`); geocentric runs go TT -> TDB
  at the geocentre first, on a uniform TDB (hence TCB) grid to which their
  states are interpolated (:func:`tqdyn.astro.timescales.geocentre_tdb_grid`);
  then counted from the time origin
  (:func:`tqdyn.astro.timescales.tcb_origin_offset`);
* lengths x_TCB = S x_TDB, velocities unchanged, accelerations / S, light
  travel times S ltt_TDB, rates (d_ltt, d_ppr) unchanged, GMs S GM_TDB;
* origin: heliocentric states + the Sun's barycentric motion at the same
  TDB (:func:`tqdyn.lightpath.heliocentric.ssb_states`); geocentric: the
  Earth's barycentric state at TDB(TT) + the 1PN GCRS -> BCRS
  transformation (:func:`tqdyn.astro.geocentric.gcrs_to_bcrs_states`);
* light travel times solved again in the BCRS (the lightpath solver on the
  barycentric states, TDB units), plus, with ``shapiro``, the Sun's Shapiro
  delay (and the Earth's for geocentric runs) from the bodies' ephemeris
  centres (:func:`tqdyn.lightpath.shapiro.add_shapiro_delays`);
* clocks against TCB: heliocentric runs
  :func:`tqdyn.lightpath.proper_time_bcrs.proper_time_deviation_of`
  (``against="TCB"``), geocentric runs
  :func:`tqdyn.lightpath.proper_time_bcrs.proper_time_deviation_geocentric_tcb`;
  zero at the trajectory's first sample; ppr, d_ppr and the tps group as
  :func:`tqdyn.lightpath.proper_time.pseudorange_quantities` forms them;
* axes: ICRF, or the IAU 2006 mean ecliptic and equinox of J2000
  (``erfa.ecm06`` at J2000 TT: x_ecl = R x_ICRF), the axes of lisaorbits'
  files.
"""

from __future__ import annotations

from typing import Any

import erfa
import numpy as np

from .._choices import unknown
from ..astro.constants import J2000_JD
from ..astro.geocentric import TDB_TO_TT_SCALE, gcrs_to_bcrs_states
from ..astro.timescales import TCB_SCALE, tcb_origin_offset, tdb_jd, tdb_to_tcb
from ..numerics.dd import np_dd_add_d
from .heliocentric import ephemeris_of, gm_of, ssb_states
from .light_time import _layout_of, _trajectory_arrays, light_travel_times, satellite_states
from .proper_time import pseudorange_quantities, scenario_gm_earth
from .proper_time_bcrs import proper_time_deviation_geocentric_tcb, proper_time_deviation_of
from .shapiro import add_shapiro_delays

__all__ = ["BCRS_AXES", "lisa_orbit_quantities_bcrs"]

#: Axes of the BCRS vectors: "icrf" (the BCRS's own) or "ecliptic" (IAU 2006 mean ecliptic and equinox of J2000,
#: erfa.ecm06 at J2000 TT: the axes of lisaorbits' files and of lisagwresponse's ecliptic source coordinates).
BCRS_AXES = ("icrf", "ecliptic")


def lisa_orbit_quantities_bcrs(trajectory, *, shapiro: bool | None = None, gm_earth: float | None = None,
                               axes: str = "icrf", time_origin: str = "epoch", ephemeris=None) -> dict[str, Any]:
    """All datasets of a BCRS / TCB LISA orbit file from a tqdyn trajectory (the module docstring).

    trajectory: duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`
    (``t``, ``sat/r``, ``sat/v``, ``sat/a_gravity`` (+ ``sat/a_dragfree``),
    the ``tm/*`` states if any; ``reference``, ``epoch``,
    ``scenario_toml``), heliocentric (Sun-centred BCRS, TDB) or geocentric
    (GCRS, TT) with 3 satellites.  Light paths run test mass to test mass
    when the trajectory has ``tm/r``, ``tm/v``, ``tm/a``, else between the
    satellites' centres.  shapiro: add the Sun's Shapiro delay (and the
    Earth's, geocentric runs); None: on for heliocentric runs, off for
    geocentric ones.  gm_earth: the Earth's TT-compatible GM [m^3/s^2] of
    a geocentric run's clocks and Shapiro delay (default: the scenario's
    ``forces.gm_earth``, else GM_EARTH_EGM2008).  axes: one of
    :data:`BCRS_AXES`; time_origin: one of
    :data:`tqdyn.astro.timescales.TCB_ORIGINS`; ephemeris: an
    :class:`tqdyn.astro.ephemeris.Ephemeris` (default the run's,
    ``forces.ephemeris``).  The Sun's GM (Shapiro delay) is the run's
    ``forces.gm_sun``, the other bodies' (proper times) their ``forces.gm_*``.

    Returns a dict, all arrays for the N rows of the trajectory's grid (rows
    whose emission time precedes the first sample have NaN light times):
    ``t`` dd (hi, lo) (N,) [s TCB from the time origin] of the uniform TCB
    grid; the datasets of :mod:`tqdyn.formats.lisa` (keys ``"tcb/x"`` ...;
    x [m] TCB-compatible, v [m/s], a [m/s^2], n, ltt [s TCB], ...) and
    ``ltt_lo`` (dd remainder of tcb/ltt); ``t_init`` [s] (the first sample,
    where delta_tau = 0); ``source`` ("tm" | "sat"), ``note`` (the light
    paths' endpoints), ``shapiro_bodies`` (names of the bodies whose delay
    is included), ``gm_sun`` (TDB-compatible) and ``gm_earth``
    (TT-compatible; None for heliocentric runs) [m^3/s^2].
    """
    if axes not in BCRS_AXES:
        raise ValueError(unknown("axes", axes, BCRS_AXES))
    ref = trajectory.reference
    helio = ref.origin == "sun"
    shapiro = helio if shapiro is None else bool(shapiro)
    eph = ephemeris_of(trajectory) if ephemeris is None else ephemeris
    epoch = trajectory.epoch
    gm_sun = float(gm_of(("sun",), trajectory)[0])  # TDB-compatible, the run's (forces.gm_sun)
    t, lr, lv, la, _ = _trajectory_arrays(trajectory)
    layout = _layout_of(np.shape(lr[0]), "tm/r")
    sat = satellite_states(trajectory)
    bodies = {"sat": sat} if layout == "sat" else {"sat": sat, "light": (lr, lv, la)}
    if helio:
        gm_e = None
        st = ssb_states(eph, epoch, t, bodies, ref)
        # tau - TCB, rates per TCB second: the Sun's and the planets' potentials, the barycentric velocity
        dtau, rate, rate_dot = proper_time_deviation_of(trajectory, against="TCB", ephemeris=eph)
        deflectors = {"the Sun": (st["x_sun"], gm_sun)}
    else:
        gm_e = scenario_gm_earth(trajectory) if gm_earth is None else float(gm_earth)
        st = gcrs_to_bcrs_states(epoch, t, bodies, eph)
        r, v, a = sat
        dtau, rate, rate_dot = proper_time_deviation_geocentric_tcb(t, r[0] + r[1], v[0] + v[1], a, st, gm_e)
        deflectors = {"the Sun": (eph.sun_barycentric(*tdb_jd(epoch, *st["T"]))[0], gm_sun),
                      "the Earth": (st["x_e"], gm_e / float(TDB_TO_TT_SCALE))}
    if not shapiro:
        deflectors = {}
    tb = st["t"]
    xr, xv, xa = st["bodies"]["light" if layout == "tm" else "sat"]
    note = ("test mass to test mass: receiver = TM of satellite a facing b, emitter = TM of satellite b facing a"
            if layout == "tm" else "satellite centre of mass to satellite centre of mass")
    lp = light_travel_times(tb, xr, xv, xa, note=note + " (solved in the BCRS)")
    ltt, d_ltt = add_shapiro_delays(lp, list(deflectors.values()))
    # TCB: t_c = S t, x_c = S x, v unchanged, a / S, ltt S ltt; rates against the first sample with a light time
    valid = np.all(np.isfinite(ltt[0]), axis=1)
    i0 = int(np.argmax(valid)) if valid.any() else 0
    tch, tcl = tdb_to_tcb(*tb)
    t_off = tcb_origin_offset(time_origin, epoch, float(tch[i0] + tcl[i0]))
    q = pseudorange_quantities((tch - tch[i0]) + (tcl - tcl[i0]), tdb_to_tcb(*ltt), d_ltt, dtau, rate, rate_dot)
    (sxh, sxl), (svh, svl), sa = st["bodies"]["sat"]
    xh, xl = tdb_to_tcb(sxh, sxl)
    x, v, a, n = xh + xl, svh + svl, sa / TCB_SCALE, lp.unit_vectors
    if axes == "ecliptic":
        rot = erfa.ecm06(J2000_JD, 0.0)  # ICRS -> mean ecliptic and equinox of J2000 (IAU 2006, frame bias)
        x, v, a, n = (z @ rot.T for z in (x, v, a, n))
    t_out = np_dd_add_d(tch, tcl, t_off)
    return {"t": t_out, "t_init": float(t_out[0][0] + t_out[1][0]), "tcb/x": x, "tcb/v": v, "tcb/a": a, "tcb/n": n,
            **q, "source": layout, "note": lp.note, "shapiro_bodies": tuple(deflectors), "gm_sun": gm_sun,
            "gm_earth": gm_e}
