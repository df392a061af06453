"""Export a tqdyn trajectory to another tool's file format: the job behind ``tqdyn export``.

:func:`export_lisa` writes a LISA orbit file (lisaorbits layout 2.x, see
:mod:`tqdyn.formats.lisa`): it reads the trajectory
(:mod:`tqdyn.formats.trajectory`), has :mod:`tqdyn.lightpath` compute every
dataset and writes the file (:func:`tqdyn.formats.lisa.write_lisa_orbits`)
with attributes that say how each quantity is defined.  It prints nothing;
the CLI reports.

Two frames (``frame``):

* ``"gcrs"`` (default for geocentric runs, tqdyn 0.2's file): the
  trajectory's own GCRS with TT as coordinate time: light travel times of
  :func:`tqdyn.lightpath.light_travel_times_of`, clocks and pseudoranges of
  :func:`tqdyn.lightpath.proper_time.lisa_orbit_quantities`;
* ``"bcrs"`` (default and only choice for heliocentric runs; an option for
  geocentric ones): the barycentric BCRS (origin the solar-system
  barycentre, ICRF or ecliptic axes) with TCB as coordinate time, in
  TCB-compatible units, as lisaorbits' files (``tcb/...``) mean it:
  :func:`tqdyn.lightpath.lisa_bcrs.lisa_orbit_quantities_bcrs`, whose
  module docstring lists the conversions (docs/lisa-export.md).
"""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass

import numpy as np

from .._choices import unknown
from .._version import __version__ as _TQDYN_VERSION
from ..formats import trajectory as _io
from ..formats.atomic import check_output
from ..formats.lisa import (AXES, FRAMES, TIME_ORIGINS, GCRS_FRAME_NOTE, GCRS_TIME_NOTE, GCRS_TPS_DEFINITION, uniform_grid, tcb_jd_of_epoch,
                            time_convention, write_lisa_orbits)
from ..lightpath import light_travel_times_of
from ..lightpath.light_time import satellite_states
from ..lightpath.lisa_bcrs import lisa_orbit_quantities_bcrs
from ..lightpath.proper_time import lisa_orbit_quantities, scenario_gm_earth

__all__ = ["AXES", "FRAMES", "TIME_ORIGINS", "LisaExport", "export_lisa"]


@dataclass(frozen=True)
class LisaExport:
    """Summary of one export: ``path`` written; ``size`` samples from ``t0``
    every ``dt`` [s, TT since ``epoch_utc``]; ``dropped_rows`` leading rows
    without an emission time inside the trajectory; ``source`` "tm" | "sat"
    and ``note`` (light-path endpoints); ``ltt_range`` (min, max) [s];
    ``shapiro`` whether the Shapiro delay is included; ``frame`` "gcrs" |
    "bcrs", ``time_scale`` "TT" | "TCB" of t0 and dt."""

    path: pathlib.Path
    size: int
    t0: float
    dt: float
    dropped_rows: int
    source: str
    note: str
    ltt_range: tuple[float, float]
    shapiro: bool
    frame: str = "gcrs"
    time_scale: str = "TT"
    shapiro_bodies: str = "the Earth"


def _resolve_frame(traj, frame, axes, time_origin, src) -> str:
    ref = traj.reference
    helio = ref.origin == "sun"
    if frame is None:
        frame = "bcrs" if helio else "gcrs"
    if frame not in FRAMES:
        raise ValueError(unknown("frame", frame, FRAMES))
    if axes not in AXES:
        raise ValueError(unknown("axes", axes, AXES))
    if time_origin not in TIME_ORIGINS:
        raise ValueError(unknown("time_origin", time_origin, TIME_ORIGINS))
    if helio and frame == "gcrs":
        raise ValueError(f"{src}: a heliocentric trajectory (origin 'sun', BCRS, TDB) exports with frame = 'bcrs' "
                         "only (origin the solar-system barycentre, TCB)")
    if frame == "bcrs" and (ref.origin, ref.time_scale) not in (("sun", "TDB"), ("earth", "TT")):
        raise ValueError(f"{src}: origin / time scale {ref.origin!r} / {ref.time_scale!r} cannot be exported to the "
                         "BCRS (needs a geocentric TT trajectory of format version 2 or a heliocentric TDB one)")
    if frame == "gcrs" and (axes != "icrf" or time_origin != "epoch"):
        raise ValueError("axes and time_origin apply to frame = 'bcrs' only; the GCRS file keeps ICRF axes and "
                         "TT seconds since the epoch")
    return frame


def _first_valid_row(ltt, src) -> int:
    valid = np.all(np.isfinite(ltt), axis=1)
    i0 = int(np.argmax(valid)) if valid.any() else len(valid)
    if i0 >= len(valid) - 1 or not valid[i0:].all():
        raise ValueError(f"{src}: light travel times undefined beyond the leading rows; cannot export")
    return i0


def _rows(q: dict, i0: int) -> dict:
    """The arrays of ``q`` (and its times ``t``, float64 or a dd pair) from row i0 on; other entries as they are."""
    sl = slice(i0, None)
    out = {k: v[sl] if isinstance(v, np.ndarray) else v for k, v in q.items()}
    if isinstance(q["t"], tuple):
        out["t"] = (q["t"][0][sl], q["t"][1][sl])
    return out


def _write(out, q: dict, meta: dict, **kw):
    return write_lisa_orbits(
        out, q["t"], q["tcb/x"], q["tcb/v"], q["tcb/a"], q["tcb/ltt"], q["tcb/d_ltt"], q["tcb/n"], q["tcb/ppr"],
        q["tcb/d_ppr"], delta_tau=q["tcb/delta_tau"], tps_ppr=q["tps/ppr"], tps_d_ppr=q["tps/d_ppr"],
        tps_delta_t=q["tps/delta_t"], attrs=meta, extra={"tqdyn/ltt_lo": q["ltt_lo"]}, **kw)


def _endpoints(source: str) -> str:
    return ("test masses (TM of satellite i facing j <- TM of satellite j facing i)" if source == "tm"
            else "satellite centres of mass (the trajectory has no test-mass fields)")


def export_lisa(trajectory, out_path, *, shapiro: bool | None = None, gm: float | None = None, frame: str | None = None,
                axes: str = "icrf", time_origin: str = "epoch") -> LisaExport:
    """Export a tqdyn trajectory (file path or :class:`tqdyn.formats.trajectory.Trajectory`) to a LISA orbit file.

    Light travel times come from :func:`tqdyn.lightpath.light_travel_times_of`
    (test mass to test mass if the trajectory has ``tm/r``, ``tm/v``,
    ``tm/a``; satellite centres otherwise); satellite states from ``sat/r``,
    ``sat/v``, ``sat/a_gravity`` (+ ``sat/a_dragfree``); proper times with
    the Earth GM ``gm`` (default: the trajectory scenario's
    ``forces.gm_earth``, else :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`).
    The grid must be uniform and hold 3 satellites.  Leading rows whose
    emission time precedes the first sample are dropped (normally one).
    ``shapiro``: include the Shapiro delay in ltt (GCRS: the Earth's; BCRS:
    the Sun's, plus the Earth's for a geocentric run); None (default): on
    for heliocentric runs, off for geocentric ones.

    ``frame``: "gcrs" (geocentric runs only; their default: the GCRS and TT
    of the trajectory) or "bcrs" (heliocentric runs' default: barycentric,
    TCB; see the module docstring); ``axes`` ("icrf" | "ecliptic") and
    ``time_origin`` ("epoch" | "j2000" | "unix") choose the axes and the
    origin of t of a BCRS file.

    Returns a :class:`LisaExport`.  Raises FileNotFoundError (no input
    file), ValueError (:class:`tqdyn.formats.trajectory.TrajectoryFormatError` or unusable
    content, naming the field) or :class:`tqdyn.formats.trajectory.OutputError`.
    """
    if isinstance(trajectory, (str, os.PathLike)):
        traj = _io.read_trajectory(trajectory)
        src = str(traj.path)
    else:
        traj = trajectory
        src = str(getattr(trajectory, "path", ""))
    out = check_output(out_path, "OUT", {"RUN.h5": src or None})
    if traj.n_sat != 3:
        raise ValueError(f"{src}: n_sat = {traj.n_sat}; a LISA orbit file needs 3 satellites (its six links); "
                         f"allowed: a trajectory of 3 satellites (--format oem takes any number)")
    for f in ("t", "sat/r", "sat/v", "sat/a_gravity"):
        if f not in traj:
            raise ValueError(f"{src}: has no field {f!r} (needed for the LISA export)")
    if len(traj) < 3:
        raise ValueError(f"{src}: {len(traj)} time rows; the LISA export needs at least 3")
    uniform_grid(traj.dd("t"), f"{src}: t")
    frame = _resolve_frame(traj, frame, axes, time_origin, src)
    attrs = dict(getattr(traj, "attrs", {}) or {})
    if frame == "bcrs":
        return _export_bcrs(traj, out, src, attrs, shapiro=shapiro, gm=gm, axes=axes, time_origin=time_origin)
    shapiro = bool(shapiro)
    gm_v = scenario_gm_earth(traj) if gm is None else float(gm)
    lp = light_travel_times_of(traj, shapiro=shapiro, gm=gm_v)
    q = lisa_orbit_quantities(traj.dd("t"), *satellite_states(traj), lp, gm_v)
    i0 = _first_valid_row(q["tcb/ltt"], src)
    q = _rows(q, i0)
    meta = {
        "generator": "tqdyn export --format lisa",
        "tqdyn_version": _TQDYN_VERSION,
        "frame": GCRS_FRAME_NOTE,
        "time_scale": GCRS_TIME_NOTE + ("" if getattr(traj, "format_version", 2) >= 2 else
                               "; the source trajectory is of format version 1: its t is TT-elapsed seconds labelled "
                               "TDB"),
        "epoch_utc": str(attrs.get("epoch_utc", "")),
        "t_init": q["t_init"],
        "tt_method": "iterative (Newton, double-double, quintic Hermite dense output of the emitter)",
        "ignore_shapiro": not shapiro,
        "ltt_endpoints": _endpoints(lp.source),
        "ltt_note": lp.note,
        "link_order": "12, 23, 31, 13, 32, 21 (ij: received by spacecraft i, emitted by spacecraft j)",
        "tps_definition": GCRS_TPS_DEFINITION,
        "gm_earth": gm_v,
        "dropped_rows": i0,
        "precision_note": "float64 datasets; dd remainder of tcb/ltt in tqdyn/ltt_lo (ltt = tcb/ltt + tqdyn/ltt_lo)",
        "source_trajectory": src,
        "tqdyn_scenario": str(attrs.get("scenario", "")),
    }
    path = _write(out, q, meta)
    t0, dt = uniform_grid(q["t"])
    ltt = q["tcb/ltt"]
    return LisaExport(path=path, size=int(ltt.shape[0]), t0=t0, dt=dt, dropped_rows=i0, source=lp.source,
                      note=lp.note, ltt_range=(float(ltt.min()), float(ltt.max())), shapiro=bool(shapiro))


def _export_bcrs(traj, out, src, attrs, *, shapiro, gm, axes, time_origin) -> LisaExport:
    """The BCRS / TCB file (:func:`tqdyn.lightpath.lisa_bcrs.lisa_orbit_quantities_bcrs`, docs/lisa-export.md)."""
    ref = traj.reference
    helio = ref.origin == "sun"
    q = lisa_orbit_quantities_bcrs(traj, shapiro=shapiro, gm_earth=gm, axes=axes, time_origin=time_origin)
    i0 = _first_valid_row(q["tcb/ltt"], src)
    t_init = q["t_init"]
    q = _rows(q, i0)
    shap_parts = q["shapiro_bodies"]
    shapiro = bool(shap_parts)
    c1, c2 = tcb_jd_of_epoch(traj.epoch)
    axes_text = ("ICRF (the BCRS's own axes)" if axes == "icrf" else
                 "mean ecliptic and equinox of J2000.0 (IAU 2006, erfa.ecm06(J2000 TT): x_ecl = R x_ICRF; the "
                 "axes of lisaorbits' files)")
    source_text = ("heliocentric tqdyn run (Sun-centred BCRS, TDB) + the Sun's barycentric state (DE ephemeris "
                   "0 -> 10 at the same TDB)" if helio else
                   "geocentric tqdyn run (TT-compatible GCRS, TT) + the Earth's barycentric state at TDB(TT) + the "
                   "1PN GCRS -> BCRS transformation (IERS 2010 ch. 10, the inverse of tqdyn's bcrs_to_gcrs), "
                   "resampled to a uniform TCB grid (quintic Hermite)")
    if helio:
        tps_def = ("proper time of each satellite's centre of mass against TCB: d tau/dTCB = 1 - (GM_S/r + v^2/2)/"
                   "c^2 with r, v Sun-centred (lightpath's clock integrator with GM_S; the model of lisaorbits' "
                   "InterpolatedOrbits), converted from TDB exactly; not applied: the planets' potentials "
                   "(Jupiter ~2e-12, the Earth ~1e-13 of the rate) and the Sun's barycentric velocity in v^2 "
                   "(~4e-12 of the rate, common to the three clocks); delta_tau = 0 at t_init")
    else:
        tps_def = ("proper time of each satellite's centre of mass against TCB: lightpath's clock against TT "
                   "(d tau/dTT = (1 - (GM_E/r + v^2/2)/c^2)/(1 - L_G), GM_E = attribute gm_earth) at the "
                   "satellite's BCRS event (TT of the geocentre minus v_E.r/c^2), tau - TCB; delta_tau = 0 at "
                   "t_init for every satellite (the clocks are synchronised in TCB, not in TT)")
    meta = {
        "generator": "tqdyn export --format lisa --frame bcrs",
        "tqdyn_version": _TQDYN_VERSION,
        "frame": "BCRS: origin the solar-system barycentre, TCB-compatible coordinates (x_TCB = x_TDB / (1 - L_B)); "
                 "axes " + axes_text,
        "origin": "solar-system barycentre",
        "axes": axes,
        "coordinates_from": source_text,
        "time_scale": "TCB (the coordinate time of the BCRS); tps/* are sampled at each receiver's proper time tau "
                      "= t0 + k dt",
        "t0_convention": time_convention(time_origin),
        "time_origin": time_origin,
        "epoch_tcb_jd1": c1, "epoch_tcb_jd2": c2,
        "epoch_tdb_jd1": float(traj.epoch.tdb[0]), "epoch_tdb_jd2": float(traj.epoch.tdb[1]),
        "epoch_utc": str(attrs.get("epoch_utc", "")),
        "epoch_tdb": str(attrs.get("epoch_tdb", "")),
        "tcb_conversion": "IAU 2006 B3: TDB = TCB - L_B (JD_TCB - T0) 86400 s + TDB0, L_B = 1.550519768e-8, "
                          "T0 = 2443144.5003725, TDB0 = -6.55e-5 s; t_TCB - t_TCB(epoch) = (t_TDB - t_TDB(epoch)) "
                          "/ (1 - L_B); x / (1 - L_B); v unchanged; a (1 - L_B); ltt / (1 - L_B); d_ltt, d_ppr "
                          "unchanged" + ("" if helio else "; TT -> TDB at the geocentre by erfa.dtdb (Fairhead & "
                                         "Bretagnon)"),
        "t_init": t_init,  # delta_tau = 0 here: the trajectory's first sample
        "tt_method": "iterative (Newton, double-double, quintic Hermite dense output of the emitter), solved in "
                     "the BCRS (TDB-compatible units, then scaled to TCB)",
        "ignore_shapiro": not shapiro,
        "shapiro_bodies": (" and ".join(shap_parts) + " (2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)), r from the "
                           "body's ephemeris centre, GM_TCB = GM_TDB / (1 - L_B); added to the geometric BCRS light "
                           "time as s / (1 - n.v_e/c))") if shap_parts else "none",
        "ltt_endpoints": _endpoints(q["source"]),
        "ltt_note": q["note"],
        "link_order": "12, 23, 31, 13, 32, 21 (ij: received by spacecraft i, emitted by spacecraft j)",
        "tps_definition": tps_def,
        "gm_sun_tdb": q["gm_sun"],
        "dropped_rows": i0,
        "precision_note": "float64 datasets; dd remainder of tcb/ltt in tqdyn/ltt_lo (ltt = tcb/ltt + tqdyn/ltt_lo)",
        "source_trajectory": src,
        "source_frame": f"{ref.origin} / {ref.frame} / {ref.time_scale}",
        "tqdyn_scenario": str(attrs.get("scenario", "")),
    }
    if not helio:
        meta["gm_earth"] = q["gm_earth"]
        meta["gcrs_to_bcrs"] = ("x_B = x_E(TDB(T)) + y + dr, y = X/K (K = (1 - L_G)/(1 - L_B)), dr = -[(v_E.y) v_E/2 + "
                                "U_ext y + (a_E.y) y - a_E y^2/2 + w (v_E.y)]/c^2 (U_ext, a_E from the Sun, Moon "
                                "and planets of the ephemeris), v_B = v_E + (w + dw) dT/dt; 1PN terms of a "
                                "(< 1e-9 m/s^2) and O(c^-4) not applied")
    path = _write(out, q, meta, frame_label="BCRS" + (" (ecliptic axes)" if axes == "ecliptic" else ""))
    t0, dt = uniform_grid(q["t"])
    ltt = q["tcb/ltt"]
    return LisaExport(path=path, size=int(ltt.shape[0]), t0=t0, dt=dt, dropped_rows=i0, source=q["source"],
                      note=q["note"], ltt_range=(float(ltt.min()), float(ltt.max())), shapiro=shapiro,
                      frame="bcrs", time_scale="TCB", shapiro_bodies=" and ".join(shap_parts) or "none")
