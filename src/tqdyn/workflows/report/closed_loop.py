"""The closed-loop report (``tqdyn report --closed-loop``): per mission, the default design's loops,
margins, noise budgets and residual TM acceleration at the working point of a short coupled run, and
the link between the DC self-gravity of the paper's study and the in-band noise.

:func:`report_closed_loop` runs (in memory) a short coupled run of each mission's built-in scenario
(:data:`RUNS`: TianQin with the paper's Table IV self-gravity, LISA with ESA's self-gravity ramp,
Taiji without self-gravity), builds its closed loops (:func:`tqdyn.closedloop.model.closed_loop_model`,
the run's [closed_loop] defaults: the mission's default plant, noises and controllers) and evaluates
satellite 1 in the first frozen-coefficient segment (the working point at its middle row).  Written
into ``DIR/closed-loop/`` (PNG and PDF): ``<mission>-budget`` (budget stacks of :data:`BUDGET_OUTPUTS`),
``<mission>-loops`` (the loop gain L of the first channel of every loop, with its margins),
``<mission>-tm-acceleration`` (the residual acceleration of both TMs along their sensitive axes
against the requirement), ``<mission>-ttl-budget`` (the single-link displacement budget of the six
links: TTL, readout, TM acceleration as displacement, total, requirement) and ``<mission>-ttl-sources``
(the TTL of the worst link by source); ``DIR/summary.md`` and ``DIR/summary.json`` (``values``:
:func:`_mission_values`, and per mission ``ttl``: :func:`tqdyn.analysis.ttl_budget.ttl_budget_values`,
worst-case coefficients, the three spacecraft's loops of the same segment).

Units: SI; frequencies Hz; ASDs one-sided [unit/Hz^1/2]; margins: phase in deg, gain as a factor (a
*lower* gain margin: the loops are conditionally stable, docs/closed-loop.md).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable

import numpy as np

from ..._choices import unknown
from ...analysis.closed_loop import BANDS
from ...analysis.closed_loop_paths import DC_SUSPENSION_LIMIT, dc_paths
from ...analysis.figures_closed_loop import (plot_budget_stack, plot_link_budget, plot_loop_gains,
                                             plot_residual_acceleration, plot_ttl_sources)
from ...analysis.ttl_budget import ttl_budget_values
from ...closedloop.budget import dominant_sources, loop_gains, loop_margins, noise_budget
from ...closedloop.controllers import LOOPS
from ...closedloop.loop import OUTPUTS, output_names
from ...closedloop.missions import CONSTELLATION_MISSIONS, requirement
from ...closedloop.model import closed_loop_model
from .summary import Report, SummaryRow, _e, _finish, check_out_dir

__all__ = ["BUDGET_OUTPUTS", "FREQUENCIES_HZ", "LINK_FREQUENCIES_HZ", "LINK_REQUIREMENT_TEXT", "MISSION_BAND_HZ",
           "REQUIREMENT_TEXT", "RUNS", "report_closed_loop"]

#: Per mission: (built-in scenario, overrides, description) of the coupled run whose working point is used.
RUNS = {
    "tianqin": ("tianqin", ("run.duration=1d",),
                "built-in tianqin (the paper's Table IV self-gravity, global pointing), 1 d at its 50 s step"),
    "lisa": ("lisa", ("run.duration=2d",),
             "built-in lisa (ESA's self-gravity ramp, common along +X_S: -2 nm/s^2 at the start), 2 d at its 6 h step"),
    "taiji": ("taiji", ("run.duration=2d",), "built-in taiji (no self-gravity), 2 d at its 6 h step"),
}
#: Frequencies [Hz] at which the residual TM acceleration is quoted.
FREQUENCIES_HZ = (1e-4, 1e-3, 1e-2, 1e-1)
#: Frequencies [Hz] of the DC-to-in-band paths (:func:`tqdyn.analysis.closed_loop_paths.dc_paths`).
LINK_FREQUENCIES_HZ = (1e-3, 1e-2)
#: The measurement band [Hz] in which the largest ratio to the requirement is taken (all three missions).
MISSION_BAND_HZ = (1e-4, 1.0)
#: The outputs of the budget-stack figures.
BUDGET_OUTPUTS = ("tm1_acceleration", "tm1_relative_acceleration", "tm1_sc_jitter", "tm1_displacement_y",
                  "sc_attitude_z", "mosa_angle_1")
#: Legend text of each mission's requirement (:func:`tqdyn.closedloop.missions.requirement`).
REQUIREMENT_TEXT = {
    "tianqin": "TianQin requirement 1 fm s$^{-2}$/Hz$^{1/2}$ $(1 + 0.1\\,\\mathrm{mHz}/f)^{1/2}$",
    "lisa": ("LISA requirement 3 fm s$^{-2}$/Hz$^{1/2}$ "
             "$(1+(0.4\\,\\mathrm{mHz}/f)^2)^{1/2}(1+(f/8\\,\\mathrm{mHz})^4)^{1/2}$"),
    "taiji": "Taiji requirement 3 fm s$^{-2}$/Hz$^{1/2}$ (LISA's knees)",
}
#: Legend text of each mission's single-link displacement requirement
#: (:data:`tqdyn.analysis.ttl_budget.SINGLE_LINK_REQUIREMENT`).
LINK_REQUIREMENT_TEXT = {
    "tianqin": "TianQin single-link requirement 1 pm/Hz$^{1/2}$",
    "lisa": "LISA single-link requirement 15 pm/Hz$^{1/2}$ $(1+(2\\,\\mathrm{mHz}/f)^4)^{1/2}$",
    "taiji": "Taiji single-link requirement 8 pm/Hz$^{1/2}$ (LISA's shape)",
}
_F_GRID = (1e-5, 1.0, 401)
_F_LOOPS = (1e-5, 1.0, 801)


def _coupled_run(name: str, overrides):
    """A coupled run of a built-in scenario, in memory (as :func:`tqdyn.api.propagate`)."""
    from ... import dynamics
    from ...formats.trajectory import Trajectory
    from ...scenario import load_scenario
    from ..run import output_attrs

    scen = load_scenario(name, list(overrides))
    model = dynamics.check_inputs(scen)
    dynamics.warm_up(scen.run.precision, scen.integrator.method, dynamics.build_system(scen, model).cpar, model=model)
    blocks: list = []
    dynamics.propagate(scen, sink=blocks.append, model=model)
    return Trajectory.from_rows(dynamics.Rows.concatenate(blocks), output_attrs(scen, model),
                                {"tm/self_gravity": dynamics.self_gravity_oa(scen)})


def _grid(lo, hi, n):
    return np.logspace(math.log10(lo), math.log10(hi), n)


def _mission_values(mission: str, model, run_text: str) -> tuple[dict, dict]:
    """(the JSON values of one mission, the arrays of its figures).  Values: ``working_point`` (the run,
    the time [s] of the working point, its DC suspension / drag-free maxima [m/s^2], e.Gamma.e [s^-2]),
    ``margins`` per channel (``crossover_hz``, ``phase_margin_deg``, ``gain_margin``, ``gain_margin_hz``),
    ``dominant`` per output and band, ``residual`` (the TMs' residual acceleration and the requirement at
    :data:`FREQUENCIES_HZ`, their ratio, the largest ratio in :data:`MISSION_BAND_HZ` and its
    frequency), ``link`` (:func:`tqdyn.analysis.closed_loop_paths.dc_paths` at :data:`LINK_FREQUENCIES_HZ`)."""
    p, wp = model.parts[0][0]
    cl = model.loops[0][0][1]
    f = _grid(*_F_GRID)
    budget, sources = noise_budget(cl, model.noise, f)
    names = output_names()
    dom = dominant_sources(budget, sources, f, BANDS)
    band_names = [f"{lo:g}-{hi:g} Hz" for lo, hi in BANDS]
    req = requirement(mission)
    fq = np.asarray(FREQUENCIES_HZ)
    bq, _ = noise_budget(cl, model.noise, fq, outputs=["tm1_acceleration", "tm2_acceleration"])
    tq = np.sqrt(np.sum(bq ** 2, axis=1))
    i1, i2 = names.index("tm1_acceleration"), names.index("tm2_acceleration")
    totals = np.sqrt(np.sum(budget ** 2, axis=1))
    ratio = np.maximum(totals[i1], totals[i2]) / req.asd(f)
    inband = (f >= MISSION_BAND_HZ[0]) & (f <= MISSION_BAND_HZ[1])
    k = int(np.argmax(np.where(inband, ratio, -np.inf)))
    margins = loop_margins(cl)
    fl = _grid(*_F_LOOPS)
    chans, L = loop_gains(cl, fl)
    link = dc_paths(p, wp, model.controllers, model.noise, LINK_FREQUENCIES_HZ,
                    attitude_z_sensor=model.settings["attitude_z_sensor"])
    values = {
        "working_point": {"run": run_text, "satellite": model.satellite_names[0], "t_s": float(wp.t),
                          "dc_suspension_max": float(np.max(np.abs(wp.a_suspension))),
                          "dc_dragfree_max": float(np.max(np.abs(wp.a_dragfree))),
                          "gamma_sensitive": link["gamma_sensitive"],
                          "tm_force_level": float(model.noise["tm_force"].level)},
        "stable": True,
        "margins": {m.channel: {"crossover_hz": m.f_phase_margin, "phase_margin_deg": m.phase_margin,
                                "gain_margin": m.gain_margin, "gain_margin_hz": m.f_gain_margin} for m in margins},
        "phase_margin_min_deg": min(m.phase_margin for m in margins),
        "gain_margin_max": max(m.gain_margin for m in margins),
        "dominant": {o: dict(zip(band_names, dom[j])) for j, o in enumerate(names)},
        "residual": {"frequencies_hz": list(FREQUENCIES_HZ), "tm1": tq[0].tolist(), "tm2": tq[1].tolist(),
                     "requirement": req.asd(fq).tolist(),
                     "ratio": (np.maximum(tq[0], tq[1]) / req.asd(fq)).tolist(),
                     "tm_force_input": model.noise["tm_force"].asd(fq).tolist(),
                     "band_hz": list(MISSION_BAND_HZ), "max_ratio_in_band": float(ratio[k]),
                     "max_ratio_f_hz": float(f[k])},
        "link": {"frequencies_hz": list(LINK_FREQUENCIES_HZ), **link},
    }
    first = {loop: f"{loop}[0]" for loop in LOOPS}
    arrays = {"f": f, "budget": budget, "sources": sources, "names": names, "requirement": req.asd(f),
              "f_loops": fl, "loops": [(loop, L[chans.index(ch)], next(m for m in margins if m.channel == ch))
                                       for loop, ch in first.items()],
              "tm": (totals[i1], totals[i2]), "tm_force": model.noise["tm_force"].asd(f)}
    return values, arrays


def report_closed_loop(out_dir: str | os.PathLike, missions=CONSTELLATION_MISSIONS, *,
                       progress: Callable[[str], None] | None = None, figures: bool = True) -> Report:
    """Figures (unless ``figures`` is False), summary rows and values of the closed loop of ``missions``
    (module docstring).
    Returns :class:`~tqdyn.workflows.report.summary.Report` (``values``: ``missions`` -> the values of
    :func:`_mission_values` and ``ttl`` (:func:`tqdyn.analysis.ttl_budget.ttl_budget_values`), and the
    frequencies, bands and limit they refer to)."""
    say = progress or (lambda msg: None)
    for m in missions:
        if m not in CONSTELLATION_MISSIONS:
            raise ValueError(unknown("mission", m, CONSTELLATION_MISSIONS, problem="is not a constellation mission"))
    rep = Report(out_dir=check_out_dir(out_dir))
    fig_dir = check_out_dir(rep.out_dir / "closed-loop")
    rep.values = {"frequencies_hz": list(FREQUENCIES_HZ), "link_frequencies_hz": list(LINK_FREQUENCIES_HZ),
                  "bands_hz": [list(b) for b in BANDS], "band_hz": list(MISSION_BAND_HZ),
                  "dc_suspension_limit": DC_SUSPENSION_LIMIT, "asd": "one-sided", "missions": {}}
    for mission in missions:
        name, overrides, text = RUNS[mission]
        say(f"{mission}: coupled run ({text})")
        traj = _coupled_run(name, overrides)
        model = closed_loop_model(traj)
        say(f"{mission}: loops, margins and budgets")
        v, a = _mission_values(mission, model, text)
        say(f"{mission}: single-link TTL budget")
        v["ttl"], ttl_ds = ttl_budget_values(model, band=MISSION_BAND_HZ)
        rep.values["missions"][mission] = v
        _rows(rep, mission, v)
        if not figures:
            continue
        where = f"{mission}, Sat1 at t = {v['working_point']['t_s'] / 3600:.3g} h of a coupled run"
        outs = list(BUDGET_OUTPUTS)
        idx = [a["names"].index(o) for o in outs]
        rep.figures += plot_budget_stack(a["f"], a["budget"][idx], a["sources"], outs, [OUTPUTS[o][0] for o in outs],
                                         fig_dir, f"{mission}-budget", f"{mission}: noise budget ({where})",
                                         requirement=a["requirement"])
        rep.figures += plot_loop_gains(a["f_loops"], a["loops"], fig_dir, f"{mission}-loops",
                                       f"{mission}: loop-at-a-time gains L of the default design ({where})")
        rep.figures += plot_residual_acceleration(
            a["f"], [("TM1 sensitive axis (total)", a["tm"][0]), ("TM2 sensitive axis (total)", a["tm"][1])],
            a["requirement"], fig_dir, f"{mission}-tm-acceleration",
            f"{mission}: residual TM acceleration, default noises and controllers ({where})",
            REQUIREMENT_TEXT[mission], tm_force=a["tm_force"], band=MISSION_BAND_HZ)
        rep.figures += _ttl_figures(mission, v["ttl"], ttl_ds, fig_dir, where)
    _finish(rep, "tqdyn report --closed-loop", [f"{m}: {RUNS[m][2]}" for m in missions])
    return rep


def _ttl_figures(mission: str, t: dict, ds, fig_dir, where: str) -> list:
    f = ds["frequency"].values
    links = [str(x) for x in ds["link"].values]
    req, ro = ds["requirement"].values, ds["readout"].values[0]
    coeffs = (f"TTL coefficients {t['local_m_per_rad'] * 1e3:g} (local) / {t['distant_m_per_rad'] * 1e3:g} (distant) "
              "mm/rad on every MOSA")
    paths = plot_link_budget(f, links, ds["ttl_total"].values, ro, ds["tm_acceleration_total"].values,
                             ds["total"].values, req, fig_dir, f"{mission}-ttl-budget",
                             f"{mission}: single-link budget of the six links ({coeffs})\n"
                             f"{where}; the loops of the three spacecraft", LINK_REQUIREMENT_TEXT[mission],
                             allocation=t["allocation"], band=MISSION_BAND_HZ)
    w = t["worst_link"]
    n = links.index(w)
    paths += plot_ttl_sources(f, ds["ttl"].values[n], [str(x) for x in ds["source"].values], ro, req, fig_dir,
                              f"{mission}-ttl-sources",
                              f"{mission}: TTL of link {w} by noise source ({coeffs})\n{where}",
                              LINK_REQUIREMENT_TEXT[mission], allocation=t["allocation"], band=MISSION_BAND_HZ)
    return paths


def _rows(rep: Report, mission: str, v: dict) -> None:
    m = v["margins"]
    worst = min(m, key=lambda ch: m[ch]["phase_margin_deg"])
    rep.rows.append(SummaryRow(f"{mission}: phase margins (every channel)", "-",
                               f"min {m[worst]['phase_margin_deg']:.1f} deg ({worst})",
                               "stable; crossovers " + ", ".join(f"{ch} {m[ch]['crossover_hz'] * 1e3:.3g} mHz"
                                                                 for ch in m if ch.endswith("[0]"))))
    r = v["residual"]
    rep.rows.append(SummaryRow(
        f"{mission}: residual TM acceleration at " + " / ".join(f"{x:g}" for x in r["frequencies_hz"]) + " Hz",
        "requirement " + " / ".join(_e(x) for x in r["requirement"]),
        " / ".join(_e(max(a, b)) for a, b in zip(r["tm1"], r["tm2"])) + " m/s^2/Hz^1/2",
        f"largest ratio to the requirement in {r['band_hz'][0]:g}-{r['band_hz'][1]:g} Hz: "
        f"{r['max_ratio_in_band']:.3g} at {r['max_ratio_f_hz']:.3g} Hz"))
    d = v["dominant"]["tm1_acceleration"]
    rep.rows.append(SummaryRow(f"{mission}: largest contributor to the TM1 acceleration per band", "-",
                               "; ".join(f"{b}: {s}" for b, s in d.items()), ""))
    lk = v["link"]
    rep.rows.append(SummaryRow(
        f"{mission}: DC suspension {_e(lk['dc_suspension_max'], 'm/s^2')} -> actuation noise at "
        f"{lk['frequencies_hz'][0]:g} Hz", f"limit {lk['limit']:g} m/s^2",
        f"{_e(lk['actuation_force'][0])} (at the limit {_e(lk['actuation_force_at_limit'][0])}) m/s^2/Hz^1/2",
        f"every DC-force path {_e(lk['dc_forces'][0])}; stiffness x jitter {_e(lk['stiffness_times_jitter'][0])}"))
    t = v.get("ttl")
    if t is not None:
        w = t["links"][t["worst_link"]]
        rep.rows.append(SummaryRow(
            f"{mission}: TTL of link {t['worst_link']} (worst-case coefficients) at "
            + " / ".join(f"{x:g}" for x in t["frequencies_hz"]) + " Hz",
            "requirement " + " / ".join(_e(x) for x in t["requirement"]),
            " / ".join(_e(x) for x in w["ttl"]) + " m/Hz^1/2",
            f"TTL / requirement up to {w['ttl_over_requirement_max']:.3g} at {w['ttl_over_requirement_f_hz']:.3g} Hz; "
            f"dominant source {w['dominant_source']}; smallest margin {w['worst_margin']:.3g} at "
            f"{w['worst_margin_f_hz']:.3g} Hz ({w['worst_margin_limited_by']})"))
