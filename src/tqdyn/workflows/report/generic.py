"""The generic report (``tqdyn report RUN.h5 ...``): figures and a summary of
whatever the given trajectory files contain (:func:`report_runs`)."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

import numpy as np

from ...analysis.figures import plot_asd, plot_breathing, plot_control, plot_deviations, plot_pointing
from ...analysis.metrics import (
    BREATHING_BAND_DEG,
    _control_values,
    _link_dd,
    _t,
    _uniform,
    breathing_angles_of,
    flight_axis_check,
    orbit_deviation,
    range_asd_in_band,
)
from ...analysis.pointing_study import pointing_study_of
from ...constellation.indices import LINKS
from ...formats import trajectory as io
from ...lightpath import light_travel_times_of
from .summary import Report, SummaryRow, _e, _finish, _label_of, _order_ok, _per_sat, _span_days, check_out_dir

__all__ = ["report_runs"]


def _describe_run(traj) -> dict:
    from ...scenario import ScenarioError, loads_scenario

    info = {"pointing": traj.attrs.get("pointing", "none"), "control": traj.attrs.get("control", "off"),
            "self_gravity": "unknown", "common": None, "output_every": None, "step": traj.attrs.get("step_s")}
    try:
        scen = loads_scenario(traj.scenario_toml, source=str(traj.path))
    except (ScenarioError, ValueError):
        return info
    _oa, common = scen.spacecraft.self_gravity_values()
    info["self_gravity"] = scen.spacecraft.self_gravity if isinstance(scen.spacecraft.self_gravity, str) else "array"
    info["common"] = common
    info["output_every"] = scen.run.output_every
    return info


def _no_self_gravity(info) -> bool:
    return info["self_gravity"] == "off" and info["common"] is not None and not np.any(info["common"])


def report_runs(paths: Sequence[str | os.PathLike], out_dir: str | os.PathLike, *,
                progress: Callable[[str], None] | None = None, pointing_max_rows: int = 60 * 1728) -> Report:
    """Figures and a summary of the given trajectory files (see :mod:`tqdyn.workflows.report`).

    paths : trajectory files (:func:`tqdyn.formats.trajectory.read_trajectory`;
    missing file -> FileNotFoundError, not a trajectory ->
    :class:`tqdyn.formats.trajectory.TrajectoryFormatError`,
    both raised before anything is written).  out_dir : created if needed.
    progress : called with one-line messages.  pointing_max_rows : the
    pointing comparison uses at most this many rows of a run (default 60 days
    at 50 s).  Returns :class:`Report`.
    """
    say = progress or (lambda msg: None)
    trajs = []
    for p in paths:
        trajs.append(io.read_trajectory(p))
    if not trajs:
        raise ValueError("runs: no trajectory file given; allowed: one or more tqdyn trajectory (.h5) files")
    out = check_out_dir(out_dir)
    rep = Report(out_dir=out)
    used: set = set()
    labels = [_label_of(tr.path, used) for tr in trajs]
    for tr, label in zip(trajs, labels):
        info = _describe_run(tr)
        say(f"{label}: {tr.n_rows} rows over {_span_days(tr):.3g} days, pointing {info['pointing']}, "
            f"control {info['control']}")
        coupled = "tm/a_suspension" in tr
        if coupled:
            _generic_control(rep, tr, label, info)
        if tr.n_sat == 3:
            _generic_breathing(rep, tr, label)
            t = _t(tr)
            if _uniform(t) and t.size >= 80:
                say(f"{label}: light paths and range ASD")
                _generic_asd(rep, tr, label)
            else:
                rep.notes.append(f"{label}: no range ASD (needs a uniform grid of at least 80 rows)")
            if info["output_every"] == 1 and t.size >= 8:
                say(f"{label}: pointing laws vs iterative")
                st = pointing_study_of(tr, max_rows=pointing_max_rows)
                rep.figures += plot_pointing(st, out, f"{label}-pointing", f"{label}: pointing laws vs iterative")
                for law, c in st.laws.items():
                    paper = "~1e-6 rad" if law == "global" else "~1e-11 rad"
                    ref = 1e-6 if law == "global" else 1e-11
                    rep.rows.append(SummaryRow(f"{label}: pointing error {law} vs iterative, max per beam (Fig. 5)",
                                               paper, _e(c.max_per_beam, "rad"),
                                               ("same order" if _order_ok(c.max_per_beam, ref) else "differs")
                                               + f"; X_S {c.max_x_s:.1e} rad, theta {c.max_theta:.1e} rad"))
                    rep.values[f"{label}/pointing/{law}"] = c.maxima()
            elif info["output_every"] != 1:
                rep.notes.append(f"{label}: no pointing comparison (needs the 50 s integrator grid, "
                                 f"run.output_every = 1; this run has {info['output_every']})")
        else:
            rep.notes.append(f"{label}: {tr.n_sat} satellite(s): no breathing angles, light paths or pointing")
    _generic_deviations(rep, trajs, labels)
    _finish(rep, "tqdyn report", [f"{lab}: {tr.path}" for lab, tr in zip(labels, trajs)])
    return rep


def _generic_control(rep, tr, label, info):
    rep.figures += plot_control(tr, rep.out_dir, f"{label}-control", f"{label}: electrostatic and drag-free control")
    v = _control_values(tr)
    rep.values[f"{label}/control"] = v
    nosg = _no_self_gravity(info)
    tiv = info["self_gravity"] == "table-iv" and info["common"] is not None and not np.any(info["common"])
    span = f" over {_span_days(tr):.3g} d"
    if nosg:
        rep.rows += [
            SummaryRow(f"{label}: max |A| TM suspension{span} (Fig. 7)", "~1e-13 m/s^2", _e(v["max_A"], "m/s^2"),
                       "same order" if _order_ok(v["max_A"], 1e-13) else "differs"),
            SummaryRow(f"{label}: max |alpha| TM angular{span} (Fig. 7)", "~1e-13 rad/s^2",
                       _e(v["max_alpha"], "rad/s^2"), "same order" if _order_ok(v["max_alpha"], 1e-13) else "differs"),
            SummaryRow(f"{label}: max |G| drag-free{span} (sec. V.A)", "~1e-13 m/s^2", _e(v["max_G"], "m/s^2"),
                       "same order" if _order_ok(v["max_G"], 1e-13) else "differs")]
    elif tiv:
        rep.rows += [
            SummaryRow(f"{label}: max |A| TM suspension{span} (Fig. 8)", "< 1e-10 m/s^2", _e(v["max_A"], "m/s^2"),
                       "agrees" if v["max_A"] < 1e-10 else "exceeds"),
            SummaryRow(f"{label}: max |A_1 - A_2|{span}", "< 1e-10 m/s^2 (\"differential\")", _e(v["max_dA"], "m/s^2"),
                       "agrees" if v["max_dA"] < 1e-10 else "exceeds: Table IV's own z difference is 1.67e-10 m/s^2; "
                       "the per-TM actuation (half the difference) is what stays < 1e-10")]
    else:
        rep.rows += [SummaryRow(f"{label}: max |A|, |alpha|, |G|{span}", "-",
                                f"{_e(v['max_A'], 'm/s^2')}, {_e(v['max_alpha'], 'rad/s^2')}, {_e(v['max_G'], 'm/s^2')}",
                                f"self-gravity {info['self_gravity']}, common {info['common']}")]
    yv = flight_axis_check(tr)
    rep.rows.append(SummaryRow(f"{label}: flight direction in S", "-", f"Y_S . v/|v| in [{yv.min():.6f}, "
                               f"{yv.max():.6f}]", "flight direction = -Y_S" if yv.max() < -0.99 else
                               "flight direction not along -Y_S"))


def _generic_breathing(rep, tr, label):
    t = _t(tr)
    alpha = breathing_angles_of(tr)
    deg = np.degrees(alpha)
    rep.figures += plot_breathing([(label, t, alpha, "-")], rep.out_dir, f"{label}-breathing",
                                  f"{label}: breathing angles")
    inside = bool(np.all((deg >= BREATHING_BAND_DEG[0]) & (deg <= BREATHING_BAND_DEG[1])))
    rep.values[f"{label}/breathing_deg"] = (float(deg.min()), float(deg.max()))
    rep.rows.append(SummaryRow(f"{label}: breathing angles over {_span_days(tr):.3g} d", "60 +- 0.1 deg (requirement)",
                               f"{deg.min():.4f} .. {deg.max():.4f} deg",
                               "inside the band" if inside else "leaves the band"))


def _generic_asd(rep, tr, label):
    lt = light_travel_times_of(tr)
    t = _t(tr)
    curves = []
    worst = (0.0, None, None)
    for ln in LINKS:
        res = range_asd_in_band(t, *_link_dd(lt.range, ln))
        curves.append((f"link {int(ln)}", res, {"lw": 0.8}))
        if np.isfinite(res.max_ratio) and res.max_ratio > worst[0]:
            worst = (res.max_ratio, ln, res)
    what = "TM-TM" if lt.source == "tm" else "Sat-Sat"
    rep.figures += plot_asd(curves, rep.out_dir, f"{label}-range-asd", f"{label}: {what} light-path range ASD")
    if worst[1] is None:
        rep.rows.append(SummaryRow(f"{label}: light-path range ASD / requirement", "< 1 in band", "n/a",
                                   "run too short for the band"))
        return
    r = worst[2]
    rep.values[f"{label}/asd_max_ratio"] = worst[0]
    rep.rows.append(SummaryRow(f"{label}: {what} light-path range ASD / requirement, max over links and "
                               f"{r.band[0]:.2g}..{r.band[1]:.2g} Hz", "< 1 (Fig. 10)",
                               f"link {int(worst[1])}: {r.describe()}",
                               "under the requirement" if worst[0] < 1 else "above the requirement"))


def _generic_deviations(rep, trajs, labels):
    if len(trajs) < 2:
        return
    ref_i = next((i for i, tr in enumerate(trajs) if "tm/r" not in tr and tr.attrs.get("control") == "off"), 0)
    ref = trajs[ref_i]
    series = []
    for i, (tr, label) in enumerate(zip(trajs, labels)):
        if i == ref_i:
            continue
        if tr.attrs.get("epoch_utc") != ref.attrs.get("epoch_utc"):
            rep.notes.append(f"{label}: other epoch than the reference {labels[ref_i]}: no deviation")
            continue
        dev = orbit_deviation(tr, ref)
        if dev is None:
            rep.notes.append(f"{label}: shares no time row with {labels[ref_i]}: no deviation")
            continue
        for s in range(tr.n_sat):
            series.append((f"{label} Sat{s + 1}", dev.t, dev.norm[:, s], f"C{len(series) // 3 % 10}",
                           ("-", "--", ":")[s % 3]))
        rep.values[f"{label}/deviation_max"] = dev.norm.max(axis=0)
        rep.rows.append(SummaryRow(f"{label}: max orbit deviation from {labels[ref_i]} over "
                                   f"{float(dev.t[-1] - dev.t[0]) / 86400:.3g} d", "-",
                                   _per_sat(dev.norm.max(axis=0), "m", "{:.4g}"),
                                   f"along-track at the end: {_per_sat(dev.along[-1], 'm', '{:.4g}')}"))
    if series:
        rep.figures += plot_deviations(series, rep.out_dir, "deviations", f"orbit deviation from {labels[ref_i]}",
                                       log=True)
