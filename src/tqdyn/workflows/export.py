"""Export a tqdyn trajectory to another tool's file format: the job behind ``tqdyn export``.

:func:`export_lisa` writes a LISA orbit file (lisaorbits layout 2.x, see
:mod:`tqdyn.formats.lisa`): it reads the trajectory
(:mod:`tqdyn.formats.trajectory`), solves the light travel times
(:func:`tqdyn.lightpath.light_travel_times_of`), computes the proper times
and pseudoranges (:func:`tqdyn.lightpath.proper_time.lisa_orbit_quantities`)
and writes the file (:func:`tqdyn.formats.lisa.write_lisa_orbits`) with
attributes that say how each quantity is defined.  It prints nothing; the
CLI reports.
"""

from __future__ import annotations

import os
import pathlib
import tomllib
from dataclasses import dataclass

import numpy as np

from .. import __version__ as _TQDYN_VERSION
from ..astro.constants import GM_EARTH_EGM2008
from ..formats import trajectory as _io
from ..formats.lisa import _FRAME, _TIME, _TPS_DEFINITION, _uniform_grid, write_lisa_orbits
from ..lightpath import light_travel_times_of
from ..lightpath.proper_time import lisa_orbit_quantities

__all__ = ["LisaExport", "export_lisa"]


@dataclass(frozen=True)
class LisaExport:
    """Summary of one export: ``path`` written; ``size`` samples from ``t0``
    every ``dt`` [s, TT since ``epoch_utc``]; ``dropped_rows`` leading rows
    without an emission time inside the trajectory; ``source`` "tm" | "sat"
    and ``note`` (light-path endpoints); ``ltt_range`` (min, max) [s];
    ``shapiro`` whether the Earth Shapiro delay is included."""

    path: pathlib.Path
    size: int
    t0: float
    dt: float
    dropped_rows: int
    source: str
    note: str
    ltt_range: tuple[float, float]
    shapiro: bool


def _scenario_gm(toml_text: str) -> float | None:
    """forces.gm_earth of a resolved scenario TOML, or None."""
    try:
        raw = tomllib.loads(toml_text or "")
        gm = raw.get("forces", {}).get("gm_earth")
        return float(gm) if gm is not None else None
    except (tomllib.TOMLDecodeError, TypeError, ValueError, AttributeError):
        return None


def export_lisa(trajectory, out_path, *, shapiro: bool = False, gm: float | None = None) -> LisaExport:
    """Export a tqdyn trajectory (file path or :class:`tqdyn.formats.trajectory.Trajectory`) to a LISA orbit file.

    Light travel times come from :func:`tqdyn.lightpath.light_travel_times_of`
    (test mass to test mass if the trajectory has ``tm/r``, ``tm/v``,
    ``tm/a``; satellite centres otherwise); satellite states from ``sat/r``,
    ``sat/v``, ``sat/a_gravity`` (+ ``sat/a_dragfree``); proper times with
    the Earth GM ``gm`` (default: the trajectory scenario's
    ``forces.gm_earth``, else :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`).
    The grid must be uniform and hold 3 satellites.  Leading rows whose
    emission time precedes the first sample are dropped (normally one).
    ``shapiro``: include the Earth's Shapiro delay in ltt.

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
        raise ValueError(f"{src}: n_sat = {traj.n_sat}; a LISA orbit file needs 3 satellites")
    for f in ("t", "sat/r", "sat/v", "sat/a_gravity"):
        if f not in traj:
            raise ValueError(f"{src}: has no field {f!r} (needed for the LISA export)")
    if len(traj) < 3:
        raise ValueError(f"{src}: {len(traj)} time rows; the LISA export needs at least 3")
    t = traj.dd("t")
    _uniform_grid(t, f"{src}: t")
    attrs = dict(getattr(traj, "attrs", {}) or {})
    gm_v = gm if gm is not None else _scenario_gm(str(attrs.get("scenario", "")))
    gm_v = float(GM_EARTH_EGM2008) if gm_v is None else float(gm_v)
    lp = light_travel_times_of(traj, shapiro=shapiro, gm=gm_v)
    sat_a = np.asarray(traj["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in traj:
        sat_a = sat_a + np.asarray(traj["sat/a_dragfree"], np.float64)
    q = lisa_orbit_quantities(t, traj.dd("sat/r"), traj.dd("sat/v"), sat_a, lp, gm_v)
    valid = np.all(np.isfinite(q["tcb/ltt"]), axis=1)
    i0 = int(np.argmax(valid)) if valid.any() else len(valid)
    if i0 >= len(valid) - 1 or not valid[i0:].all():
        raise ValueError(f"{src}: light travel times undefined beyond the leading rows; cannot export")
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
