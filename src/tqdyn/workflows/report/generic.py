"""The generic report (``tqdyn report RUN.h5 ...``): figures and a summary of
whatever the given trajectory files contain (:func:`report_runs`), for any
constellation: TianQin (geocentric, GCRS, TT), LISA and Taiji
(heliocentric, BCRS, TDB).  The constellation's design values and
constraints (:data:`tqdyn.analysis.metrics.TIANQIN`, ``LISA``, ``TAIJI``)
are chosen from the file's central body and spacecraft architecture
(:func:`constellation_reference`); the comparisons with the TianQin paper
are made for TianQin runs only."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

import numpy as np

from ...analysis.figures import (plot_actuation, plot_arms, plot_asd, plot_breathing, plot_control, plot_deviations,
                                 plot_pointing)
from ...analysis.metrics import (
    LISA,
    TAIJI,
    TIANQIN,
    ConstellationReference,
    control_values,
    actuation_values,
    arm_lengths_of,
    link_of,
    times_s,
    is_uniform_grid,
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

__all__ = ["constellation_reference", "report_runs"]


def _describe_run(traj) -> dict:
    from ...scenario import ScenarioError, loads_scenario

    info = {"pointing": traj.attrs.get("pointing", "none"), "control": traj.attrs.get("control", "off"),
            "self_gravity": "unknown", "common": None, "center": None, "output_every": None,
            "step": traj.attrs.get("step_s"), "craft": traj.spacecraft, "design_arm": None}
    try:
        scen = loads_scenario(traj.scenario_toml, source=str(traj.path))
    except (ScenarioError, ValueError):
        return info
    _oa, common = scen.spacecraft.self_gravity_values()
    info["self_gravity"] = scen.spacecraft.self_gravity if isinstance(scen.spacecraft.self_gravity, str) else "array"
    info["common"] = common
    info["center"] = scen.spacecraft.self_gravity_center
    info["output_every"] = scen.run.output_every
    if scen.initial.design == "keplerian":
        info["design_arm"] = float(scen.initial.arm_length_m)
    return info


def constellation_reference(traj, info=None) -> ConstellationReference:
    """The design values and constraints of the constellation of ``traj``:
    :data:`~tqdyn.analysis.metrics.TIANQIN` for geocentric files (origin
    "earth"); heliocentric ones :data:`~tqdyn.analysis.metrics.TAIJI` for the
    "taiji" architecture, else :data:`~tqdyn.analysis.metrics.LISA` (the
    point-mass heliocentric built-ins are LISA's).  A heliocentric scenario
    with a Keplerian design (``initial.design``) compares with its own
    ``initial.arm_length`` [m]."""
    info = info if info is not None else _describe_run(traj)
    if traj.reference.origin == "earth":
        return TIANQIN
    craft = info.get("craft")
    ref = TAIJI if craft is not None and craft.architecture == "taiji" else LISA
    arm = info.get("design_arm")
    if arm is not None and arm != ref.arm_m:
        ref = ref.with_arm(arm, f"the scenario's design, initial.arm_length = {arm:.6g} m")
    return ref


def _no_self_gravity(info) -> bool:
    return (info["self_gravity"] == "off" and info["common"] is not None and not np.any(info["common"])
            and info["center"] is None)


def _paper_run(traj, info) -> bool:
    """A run the TianQin paper's numbers apply to: geocentric, TianQin architecture and scheme."""
    craft = info["craft"]
    return (traj.reference.origin == "earth" and craft is not None and craft.architecture == "tianqin"
            and craft.dragfree_scheme == "tianqin")


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
        craft = info["craft"]
        say(f"{label}: {tr.n_rows} rows over {_span_days(tr):.3g} days, pointing {info['pointing']}, "
            f"control {info['control']}"
            + (f", architecture {craft.architecture}, drag-free scheme {craft.dragfree_scheme}" if craft else ""))
        _generic_run_row(rep, tr, label, info)
        coupled = "tm/a_suspension" in tr
        if coupled:
            _generic_control(rep, tr, label, info)
        if tr.n_sat == 3:
            cref = constellation_reference(tr, info)
            _generic_arms(rep, tr, label, cref)
            _generic_breathing(rep, tr, label, cref)
            t = times_s(tr)
            nyquist = 0.5 / float(np.median(np.diff(t))) if t.size >= 2 else 0.0
            if not (is_uniform_grid(t) and t.size >= 80):
                rep.notes.append(f"{label}: no range ASD (needs a uniform grid of at least 80 rows)")
            elif nyquist <= 1e-4:
                rep.notes.append(f"{label}: no range ASD: the grid's Nyquist frequency {nyquist:.3g} Hz (rows "
                                 f"{1 / (2 * nyquist):.6g} s apart) is below the measurement band (0.1 mHz ..)")
            else:
                say(f"{label}: light paths and range ASD")
                _generic_asd(rep, tr, label, paper=cref is TIANQIN)
            if info["output_every"] == 1 and t.size >= 8:
                say(f"{label}: pointing laws vs iterative")
                _generic_pointing(rep, tr, label, _paper_run(tr, info) or (craft is None and cref is TIANQIN),
                                  pointing_max_rows)
            elif info["output_every"] != 1:
                rep.notes.append(f"{label}: no pointing comparison (needs the integrator grid, "
                                 f"run.output_every = 1; this run has {info['output_every']})")
        else:
            rep.notes.append(f"{label}: {tr.n_sat} satellite(s): no arm lengths, breathing angles, light paths or "
                             "pointing (defined for the 3 satellites of a triangular constellation)")
    _generic_deviations(rep, trajs, labels)
    _finish(rep, "tqdyn report", [f"{lab}: {tr.path}" for lab, tr in zip(labels, trajs)])
    return rep


def _generic_run_row(rep, tr, label, info):
    """The run's reference system, grid and (coupled runs) spacecraft."""
    ref = tr.reference
    step = info["step"]
    grid = f"step {step:g} s" if isinstance(step, (int, float)) else "step unknown"
    if info["output_every"] not in (None, 1):
        grid += f", a row every {info['output_every']} steps"
    rep.rows.append(SummaryRow(f"{label}: run", "-", f"{tr.n_rows} rows over {_span_days(tr):.4g} d ({grid})",
                               f"origin {ref.origin}, frame {ref.frame}, time scale {ref.time_scale}; pointing "
                               f"{info['pointing']}, control {info['control']}"))
    craft = info["craft"]
    if craft is None:
        return
    rep.values[f"{label}/spacecraft"] = craft

    def vec(v):
        return "[" + ", ".join(f"{x + 0.0:.4g}" for x in v) + "]"

    def axis(v, l):
        for q, name in enumerate(("X", "Y", "Z")):
            if np.array_equal(v, np.eye(3)[q]):
                return f"{name}_OA_{l}"
        return f"{vec(v)} in OA_{l}"

    where = ("recorded in the file" if craft.recorded else
             "not recorded (file written before the spacecraft attributes): the TianQin defaults")
    rep.rows.append(SummaryRow(
        f"{label}: spacecraft", "-",
        f"architecture {craft.architecture}, drag-free scheme {craft.dragfree_scheme}",
        f"EH centres TM1 {vec(craft.housing_centers[0])}, TM2 {vec(craft.housing_centers[1])} m in S; pivots "
        f"{vec(craft.pivots[0])}, {vec(craft.pivots[1])} m; sensitive axes {axis(craft.sensitive_axes[0], 1)}, "
        f"{axis(craft.sensitive_axes[1], 2)}; {where}"))


def _generic_control(rep, tr, label, info):
    rep.figures += plot_control(tr, rep.out_dir, f"{label}-control", f"{label}: electrostatic and drag-free control")
    craft = info["craft"]
    rep.figures += plot_actuation(tr, rep.out_dir, f"{label}-actuation",
                                  f"{label}: actuation per axis ({craft.architecture} architecture, "
                                  f"{craft.dragfree_scheme} drag-free scheme)" if craft else f"{label}: actuation")
    v = control_values(tr)
    rep.values[f"{label}/control"] = v
    act = actuation_values(tr)
    rep.values[f"{label}/actuation"] = act
    _actuation_rows(rep, tr, label, act)
    if not _paper_run(tr, info):
        return
    nosg = _no_self_gravity(info)
    tiv = (info["self_gravity"] == "table-iv" and info["common"] is not None and not np.any(info["common"])
           and info["center"] is None)
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


def _actuation_rows(rep, tr, label, act):
    """The suspension per TM and axis of OA_l and the drag-free acceleration per satellite and axis of S."""
    span = f" over {_span_days(tr):.3g} d"
    n_sat = act["A_axis"].shape[0]
    per_tm = "; ".join(f"TM{l + 1} " + " / ".join(f"{_e(x)}" for x in act["A_axis"][:, l, :].max(axis=0))
                       for l in range(2))
    sens = float(act["A_sensitive"].max())
    # the scale of the terms the control balances: the larger of the actuations
    scale = max(float(act["A_max"].max()), float(act["G_max"].max()))
    rep.rows.append(SummaryRow(
        f"{label}: TM suspension per axis of OA_l (x / y / z), max over satellites{span}", "-",
        per_tm + " m/s^2",
        f"along the sensitive axes max {_e(sens, 'm/s^2')} = {sens / scale if scale else 0.0:.1e} of max(|A|, |G|) "
        f"{_e(scale, 'm/s^2')}: " + ("zero to round-off, the spacecraft follows each TM along its sensitive axis"
                                     if sens <= 1e-12 * scale else "actuated along a sensitive axis")))
    rep.rows.append(SummaryRow(
        f"{label}: drag-free G per satellite{span}", "-",
        _per_sat(act["G_max"], "m/s^2", "{:.3e}").replace(" m/s^2", " m/s^2 max |G|"),
        "max |G . X_S| / |G . Y_S| / |G . Z_S|: " + "; ".join(
            f"Sat{s + 1} " + " / ".join(_e(x) for x in act["G_axis_S"][s]) for s in range(n_sat)) + " m/s^2"))


def _generic_arms(rep, tr, label, cref):
    t = times_s(tr)
    L, Ld = arm_lengths_of(tr)
    span = f" over {_span_days(tr):.3g} d"
    rep.figures += plot_arms(t, L, Ld, rep.out_dir, f"{label}-arms", f"{label}: arm lengths ({cref.name})",
                             nominal=(cref.arm_m, f"{cref.name} design {_e(cref.arm_m, 'm', 3)}"), band=cref.arm_band_m,
                             rate_max=cref.arm_rate_max, time_scale=tr.reference.time_scale)
    mean = float(L.mean())
    rel = mean / cref.arm_m - 1
    rep.values[f"{label}/arms"] = {"mean": mean, "min": float(L.min()), "max": float(L.max()),
                                   "mean_per_arm": L.mean(axis=0), "nominal": cref.arm_m,
                                   "rate_min": None if Ld is None else float(Ld.min()),
                                   "rate_max": None if Ld is None else float(Ld.max())}
    note = f"mean {rel * 100:+.3g} % of the design ({cref.arm_source})"
    if cref.arm_band_m is not None:
        inside = cref.arm_band_m[0] <= L.min() and L.max() <= cref.arm_band_m[1]
        note += (f"; {'inside' if inside else 'outside'} {cref.arm_band_m[0]:.4g} .. {cref.arm_band_m[1]:.4g} m "
                 f"({cref.constraint_source})")
    rep.rows.append(SummaryRow(f"{label}: arm lengths L_12 / L_23 / L_31{span}", f"{_e(cref.arm_m, 'm', 3)} ({cref.name})",
                               f"mean {mean:.6e} m, {L.min():.6e} .. {L.max():.6e} m", note))
    if Ld is not None:
        rmax = float(np.abs(Ld).max())
        paper = "-" if cref.arm_rate_max is None else f"|dL/dt| <= {cref.arm_rate_max:g} m/s ({cref.name})"
        verdict = "-" if cref.arm_rate_max is None else (
            ("inside" if rmax <= cref.arm_rate_max else f"exceeds it by {rmax - cref.arm_rate_max:.2g} m/s")
            + f" ({cref.constraint_source})")
        rep.rows.append(SummaryRow(f"{label}: arm-length rates{span}", paper,
                                   f"{Ld.min():.4g} .. {Ld.max():.4g} m/s", verdict))


def _generic_breathing(rep, tr, label, cref=TIANQIN):
    t = times_s(tr)
    alpha = breathing_angles_of(tr)
    deg = np.degrees(alpha)
    band = cref.breathing_band_deg
    rep.figures += plot_breathing([(label, t, alpha, "-")], rep.out_dir, f"{label}-breathing",
                                  f"{label}: breathing angles ({cref.name})", band=band is not None, band_deg=band,
                                  band_label=cref.constraint_source, time_scale=tr.reference.time_scale)
    rep.values[f"{label}/breathing_deg"] = (float(deg.min()), float(deg.max()))
    if band is None:
        paper, verdict = "-", f"no constraint used for {cref.name}"
    else:
        mid, half = 0.5 * (band[0] + band[1]), 0.5 * (band[1] - band[0])
        paper = f"{mid:g} +- {half:g} deg (requirement, {cref.name})"
        excess = max(band[0] - float(deg.min()), float(deg.max()) - band[1])
        verdict = ("inside the band" if excess <= 0 else f"leaves the band by up to {excess:.2g} deg") \
            + f" ({cref.constraint_source})"
    rep.rows.append(SummaryRow(f"{label}: breathing angles over {_span_days(tr):.3g} d", paper,
                               f"{deg.min():.4f} .. {deg.max():.4f} deg", verdict))


def _generic_pointing(rep, tr, label, paper: bool, max_rows: int):
    st = pointing_study_of(tr, max_rows=max_rows)
    rep.figures += plot_pointing(st, rep.out_dir, f"{label}-pointing", f"{label}: pointing laws vs iterative",
                                 time_scale=tr.reference.time_scale)
    for law, c in st.laws.items():
        detail = f"X_S {c.max_x_s:.1e} rad, theta {c.max_theta:.1e} rad"
        if paper:
            quoted = "~1e-6 rad" if law == "global" else "~1e-11 rad"
            ref = 1e-6 if law == "global" else 1e-11
            row = SummaryRow(f"{label}: pointing error {law} vs iterative, max per beam (Fig. 5)", quoted,
                             _e(c.max_per_beam, "rad"),
                             ("same order" if _order_ok(c.max_per_beam, ref) else "differs") + f"; {detail}")
        else:
            row = SummaryRow(f"{label}: pointing error {law} vs iterative, max per beam", "-",
                             _e(c.max_per_beam, "rad"), detail)
        rep.rows.append(row)
        rep.values[f"{label}/pointing/{law}"] = c.maxima()


def _generic_asd(rep, tr, label, paper: bool = True):
    lt = light_travel_times_of(tr)
    t = times_s(tr)
    curves = []
    worst = (0.0, None, None)
    for ln in LINKS:
        res = range_asd_in_band(t, *link_of(lt.range, ln))
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
                               f"{r.band[0]:.2g}..{r.band[1]:.2g} Hz",
                               "< 1 (Fig. 10)" if paper else "< 1 (TianQin's requirement; not this constellation's)",
                               f"link {int(worst[1])}: {r.describe()}",
                               "under the requirement" if worst[0] < 1 else "above the requirement"))


def _generic_deviations(rep, trajs, labels):
    if len(trajs) < 2:
        return
    ref_i = next((i for i, tr in enumerate(trajs) if "tm/r" not in tr and tr.attrs.get("control") == "off"), 0)
    ref = trajs[ref_i]
    series = []
    n_runs = 0  # runs with a deviation so far: one colour per run
    for i, (tr, label) in enumerate(zip(trajs, labels)):
        if i == ref_i:
            continue
        if tr.attrs.get("epoch_utc") != ref.attrs.get("epoch_utc"):
            rep.notes.append(f"{label}: other epoch than the reference {labels[ref_i]}: no deviation")
            continue
        if tr.n_sat != ref.n_sat:
            rep.notes.append(f"{label}: {tr.n_sat} satellite(s), the reference {labels[ref_i]} {ref.n_sat}: "
                             "no deviation")
            continue
        dev = orbit_deviation(tr, ref)
        if dev is None:
            rep.notes.append(f"{label}: shares no time row with {labels[ref_i]}: no deviation")
            continue
        for s in range(tr.n_sat):
            series.append((f"{label} Sat{s + 1}", dev.t, dev.norm[:, s], f"C{n_runs % 10}",
                           ("-", "--", ":", "-.")[s % 4] if tr.n_sat > 3 else ("-", "--", ":")[s % 3]))
        n_runs += 1
        rep.values[f"{label}/deviation_max"] = dev.norm.max(axis=0)
        rep.rows.append(SummaryRow(f"{label}: max orbit deviation from {labels[ref_i]} over "
                                   f"{float(dev.t[-1] - dev.t[0]) / 86400:.3g} d", "-",
                                   _per_sat(dev.norm.max(axis=0), "m", "{:.4g}"),
                                   f"along-track at the end: {_per_sat(dev.along[-1], 'm', '{:.4g}')}"))
    if series:
        rep.figures += plot_deviations(series, rep.out_dir, "deviations", f"orbit deviation from {labels[ref_i]}",
                                       log=True, time_scale=ref.reference.time_scale)
