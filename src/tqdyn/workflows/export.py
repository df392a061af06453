"""Export a tqdyn trajectory to another tool's file format: the job behind ``tqdyn export``.

:func:`export_lisa` writes a LISA orbit file (lisaorbits layout 2.x, see
:mod:`tqdyn.formats.lisa`): it reads the trajectory
(:mod:`tqdyn.formats.trajectory`), solves the light travel times
(:func:`tqdyn.lightpath.light_travel_times_of`), computes the proper times
and pseudoranges (:func:`tqdyn.lightpath.proper_time.lisa_orbit_quantities`)
and writes the file (:func:`tqdyn.formats.lisa.write_lisa_orbits`) with
attributes that say how each quantity is defined.  It prints nothing; the
CLI reports.

Two frames (``frame``):

* ``"gcrs"`` (default for geocentric runs, tqdyn 0.2's file): the
  trajectory's own GCRS with TT as coordinate time;
* ``"bcrs"`` (default and only choice for heliocentric runs; an option for
  geocentric ones): the barycentric BCRS (origin the solar-system
  barycentre, ICRF or ecliptic axes) with TCB as coordinate time, in
  TCB-compatible units, as lisaorbits' files (``tcb/...``) mean it.  The
  conversions (docs/lisa-export.md, :func:`tqdyn.workflows.export_bcrs.export_bcrs`):

  - time: TCB - TCB_epoch = S (TDB - TDB_epoch), S = 1/(1 - L_B) (IAU 2006
    B3: TDB = TCB - L_B (JD_TCB - T0) 86400 s + TDB0 is linear in TCB, so
    intervals scale by S exactly and TDB0, T0 enter only the epoch's TCB
    date, erfa.tdbtcb); geocentric runs: TT -> TDB at the geocentre
    (:func:`tqdyn.astro.timescales.tdb_minus_tt`) first, on a uniform TDB
    (hence TCB) grid to which the geocentric states are interpolated;
  - lengths x_TCB = S x_TDB, velocities unchanged (dx/dt: both scale by S),
    accelerations / S, light travel times S ltt_TDB, rates (d_ltt, d_ppr)
    unchanged, GMs S GM_TDB;
  - origin: heliocentric + the Sun's barycentric position (ephemeris
    0 -> 10 at the same TDB); geocentric: the Earth's barycentric position
    at TDB(TT) + the 1PN GCRS -> BCRS transformation (the inverse of
    :func:`tqdyn.astro.geocentric.bcrs_to_gcrs`, :func:`tqdyn.astro.geocentric.gcrs_to_bcrs_offsets`);
  - light travel times solved again in the BCRS (the lightpath solver on
    the barycentric states), plus the Sun's Shapiro delay (and the Earth's
    for geocentric runs) with ``shapiro``;
  - clocks: the proper times of :func:`tqdyn.lightpath.proper_time.proper_time_deviation`
    against the trajectory's time, re-expressed against TCB (exact affine
    map), synchronised to TCB at the first sample, then ppr, d_ppr and the
    tps group formed as :func:`~tqdyn.lightpath.proper_time.lisa_orbit_quantities`
    forms them.
"""

from __future__ import annotations

import os

import numpy as np

from .. import __version__ as _TQDYN_VERSION
from ..astro.constants import GM_EARTH_EGM2008
from ..formats import trajectory as _io
from ..formats.lisa import (AXES, FRAMES, TIME_ORIGINS, _FRAME, _TIME, _TPS_DEFINITION, _uniform_grid, write_lisa_orbits)
from ..lightpath import light_travel_times_of
from ..lightpath.proper_time import lisa_orbit_quantities

from .export_bcrs import LisaExport, _first_valid_row, _scenario_gm, export_bcrs

__all__ = ["AXES", "FRAMES", "TIME_ORIGINS", "LisaExport", "export_lisa"]


def _resolve_frame(traj, frame, axes, time_origin, src) -> str:
    ref = traj.reference
    helio = ref.origin == "sun"
    if frame is None:
        frame = "bcrs" if helio else "gcrs"
    if frame not in FRAMES:
        raise ValueError(f"frame = {frame!r} is not allowed; allowed: {', '.join(FRAMES)}")
    if axes not in AXES:
        raise ValueError(f"axes = {axes!r} is not allowed; allowed: {', '.join(AXES)}")
    if time_origin not in TIME_ORIGINS:
        raise ValueError(f"time_origin = {time_origin!r} is not allowed; allowed: {', '.join(TIME_ORIGINS)}")
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
    out = _io.check_writable(out_path)
    if src and out.exists() and os.path.exists(src) and os.path.samefile(src, out):
        raise ValueError(f"output {str(out)!r} is the input trajectory; choose another output path")
    if traj.n_sat != 3:
        raise ValueError(f"{src}: n_sat = {traj.n_sat}; a LISA orbit file needs 3 satellites (its six links); "
                         f"allowed: a trajectory of 3 satellites (--format oem takes any number)")
    for f in ("t", "sat/r", "sat/v", "sat/a_gravity"):
        if f not in traj:
            raise ValueError(f"{src}: has no field {f!r} (needed for the LISA export)")
    if len(traj) < 3:
        raise ValueError(f"{src}: {len(traj)} time rows; the LISA export needs at least 3")
    t = traj.dd("t")
    _uniform_grid(t, f"{src}: t")
    frame = _resolve_frame(traj, frame, axes, time_origin, src)
    attrs = dict(getattr(traj, "attrs", {}) or {})
    if frame == "bcrs":
        return export_bcrs(traj, out, src, attrs, shapiro=shapiro, gm=gm, axes=axes, time_origin=time_origin)
    shapiro = bool(shapiro)
    gm_v = gm if gm is not None else _scenario_gm(str(attrs.get("scenario", "")))
    gm_v = float(GM_EARTH_EGM2008) if gm_v is None else float(gm_v)
    lp = light_travel_times_of(traj, shapiro=shapiro, gm=gm_v)
    sat_a = np.asarray(traj["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in traj:
        sat_a = sat_a + np.asarray(traj["sat/a_dragfree"], np.float64)
    q = lisa_orbit_quantities(t, traj.dd("sat/r"), traj.dd("sat/v"), sat_a, lp, gm_v)
    i0 = _first_valid_row(q["tcb/ltt"], src)
    sl = slice(i0, None)
    endpoints = ("test masses (TM of satellite i facing j <- TM of satellite j facing i)" if lp.source == "tm"
                 else "satellite centres of mass (the trajectory has no test-mass fields)")
    meta = {
        "generator": "tqdyn export --format lisa",
        "tqdyn_version": _TQDYN_VERSION,
        "frame": _FRAME,
        "time_scale": _TIME + ("" if getattr(traj, "format_version", 2) >= 2 else
                               "; the source trajectory is of format version 1: its t is TT-elapsed seconds labelled "
                               "TDB"),
        "epoch_utc": str(attrs.get("epoch_utc", "")),
        "t_init": q["t_init"],
        "tt_method": "iterative (Newton, double-double, quintic Hermite dense output of the emitter)",
        "ignore_shapiro": not shapiro,
        "ltt_endpoints": endpoints,
        "ltt_note": lp.note,
        "link_order": "12, 23, 31, 13, 32, 21 (ij: received by spacecraft i, emitted by spacecraft j)",
        "tps_definition": _TPS_DEFINITION,
        "gm_earth": gm_v,
        "dropped_rows": i0,
        "precision_note": "float64 datasets; dd remainder of tcb/ltt in tqdyn/ltt_lo (ltt = tcb/ltt + tqdyn/ltt_lo)",
        "source_trajectory": src,
        "tqdyn_scenario": str(attrs.get("scenario", "")),
    }
    path = write_lisa_orbits(
        out, q["t"][sl], q["tcb/x"][sl], q["tcb/v"][sl], q["tcb/a"][sl], q["tcb/ltt"][sl], q["tcb/d_ltt"][sl],
        q["tcb/n"][sl], q["tcb/ppr"][sl], q["tcb/d_ppr"][sl], delta_tau=q["tcb/delta_tau"][sl],
        tps_ppr=q["tps/ppr"][sl], tps_d_ppr=q["tps/d_ppr"][sl], tps_delta_t=q["tps/delta_t"][sl],
        attrs=meta, extra={"tqdyn/ltt_lo": q["ltt_lo"][sl]})
    t0, dt = _uniform_grid(q["t"][sl])
    ltt = q["tcb/ltt"][sl]
    return LisaExport(path=path, size=int(ltt.shape[0]), t0=t0, dt=dt, dropped_rows=i0, source=lp.source,
                      note=lp.note, ltt_range=(float(ltt.min()), float(ltt.max())), shapiro=bool(shapiro))
