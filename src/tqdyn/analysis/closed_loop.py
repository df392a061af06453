"""The closed loop of a coupled run: the model from a :class:`~tqdyn.formats.trajectory.Trajectory`, its
noise budget and its time series as xarray objects (the Python entry point; docs/closed-loop.md).

::

    import tqdyn
    from tqdyn.analysis.closed_loop import closed_loop_model, closed_loop_budget, closed_loop_timeseries
    traj = tqdyn.propagate("lisa", {"run.duration": "2d", "integrator.step": 3600})
    model = closed_loop_model(traj)                  # per satellite and segment: the closed loops
    budget = closed_loop_budget(model)               # xarray.Dataset, dims (segment, sat, output, source, frequency)
    series = closed_loop_timeseries(model, duration_s=86400)   # xarray.Dataset, dims (time, sat, output)

Units: SI, frequencies in Hz, ASDs one-sided in (output unit)/Hz^1/2; times in seconds on the run's
time axis (``traj.reference.time_scale`` since the epoch).  Frames: :data:`tqdyn.closedloop.loop.OUTPUTS`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..closedloop.budget import check_stable, closed_loop_response, dominant_sources, loop_margins, noise_budget
from ..closedloop.loop import OUTPUTS, SOURCES, ClosedLoop, build_closed_loop, output_names
from ..closedloop.missions import requirement
from ..closedloop.plant import PlantParameters
from ..closedloop.simulate import MemorySink, Sink, simulate
from ..closedloop.working_point import segment_rows, third_body_positions, working_points
from ..scenario.closed_loop import FREQUENCY_GRID

__all__ = ["ClosedLoopError", "ClosedLoopModel", "closed_loop_budget", "closed_loop_model", "closed_loop_timeseries",
           "BANDS"]

#: Bands [Hz] of the dominant-source summary.
BANDS = ((1e-4, 1e-3), (1e-3, 1e-2), (1e-2, 1e-1), (1e-1, 1.0))
_NEEDED = ("sat/T_S_I", "sat/omega", "sat/omega_dot", "mosa/angle", "tm/a_suspension", "tm/alpha_suspension",
           "sat/a_dragfree")


class ClosedLoopError(ValueError):
    """Bad input for the closed loop: one line naming the field, the value and what is allowed."""


@dataclass(frozen=True)
class ClosedLoopModel:
    """The closed loops of a run (:func:`closed_loop_model`).

    loops : list over satellites of lists of (t_start [s], ClosedLoop), one per segment.
    noise : {source: AsdModel}; mission : str; settings : dict (fs [Hz], duration [s] or None, seed,
    segment [s], f_min, f_max [Hz], n_freq); satellite_names : tuple; t_span : (t0, t1) [s].
    parts : list over satellites of lists (one per segment, as ``loops``) of (PlantParameters,
    WorkingPoint) the loops were built from; controllers : {loop: Controller} (to rebuild a loop with
    changed parameters, e.g. without cross-talk).
    """

    loops: list
    noise: dict
    mission: str
    settings: dict
    satellite_names: tuple
    t_span: tuple
    parts: list = field(default_factory=list)
    controllers: dict = field(default_factory=dict)


def _config(traj, config):
    if config is not None:
        return config
    from ..scenario import loads_scenario
    from ..scenario.closed_loop import ClosedLoopConfig

    try:
        return loads_scenario(traj.scenario_toml, source="the trajectory's scenario").closed_loop
    except ValueError:
        return ClosedLoopConfig()


def closed_loop_model(traj, config=None, validate: bool = True) -> ClosedLoopModel:
    """The closed loops of a coupled run, one per satellite and frozen-coefficient segment.

    traj : a coupled :class:`~tqdyn.formats.trajectory.Trajectory` (``tqdyn.propagate`` or a file).
    config : :class:`tqdyn.scenario.closed_loop.ClosedLoopConfig` or None (the run's own [closed_loop]).
    validate : refuse an unstable design (one line naming the loop and its margin).
    ClosedLoopError (one line) for a run without test masses or attitude (a pure-gravity run), with
    fewer than two rows, or with sensitive axes out of the constellation plane.
    """
    missing = [f for f in _NEEDED if f not in traj.fields]
    if missing:
        raise ClosedLoopError(f"trajectory: {missing[0]} is missing (a run without test masses or attitude: "
                              f"pointing = {traj.attrs.get('pointing')!r}); allowed: a coupled run (a pointing law, "
                              "control on or off)")
    t = np.asarray(traj["t"], dtype=np.float64)
    if len(t) < 2:
        raise ClosedLoopError(f"trajectory: {len(t)} row(s); allowed: a run of at least 2 rows")
    cfg = _config(traj, config)
    sc = traj.spacecraft
    from ..closedloop.missions import resolve

    mission, pl, ctl, noise = resolve(cfg, sc.architecture)
    from ..constellation.spacecraft import Spacecraft

    craft = Spacecraft(housing_centers_nominal=sc.housing_centers, pivot_points=sc.pivots,
                       sensitive_axes=sc.sensitive_axes, scheme=sc.dragfree_scheme, architecture=sc.architecture,
                       theta_nominal=sc.theta_nominal)
    scen = None
    try:
        from ..scenario import loads_scenario

        scen = loads_scenario(traj.scenario_toml, source="the trajectory's scenario")
    except Exception:
        scen = None
    # gravity gradient: central body + third bodies of the run's force model
    bodies, gms, pos = (), [], None
    central_gm = 0.0
    if scen is not None:
        from ..forces.body_gms import body_gms

        allg = body_gms(scen.forces)
        central_gm = float(scen.forces.gm_earth) if scen.central_body == "earth" else allg["sun"]
        bodies = tuple(scen.forces.third_bodies)
        gms = [allg[b] for b in bodies]
    segment = float(cfg.value("segment", 86400.0))
    rows = segment_rows(t, segment)
    mids = [m for _a, _b, m in rows]
    if bodies:
        from ..astro.ephemeris import ephemeris_named

        pos = third_body_positions(scen.reference, scen.epoch, t[mids], bodies, ephemeris_named(scen.forces.ephemeris))
    sg = traj["tm/self_gravity"] if "tm/self_gravity" in traj.fields else np.zeros((3, 2, 3))
    wps = working_points(t[mids], traj["sat/r"][mids], traj["sat/T_S_I"][mids], traj["sat/omega"][mids],
                         traj["sat/omega_dot"][mids], traj["mosa/angle"][mids], traj["tm/a_suspension"][mids],
                         traj["tm/alpha_suspension"][mids], traj["sat/a_dragfree"][mids], sg, central_gm, pos, gms)
    azs = cfg.value("attitude_z_sensor", "dws")
    n_sat = len(wps[0])
    loops = [[] for _ in range(n_sat)]
    parts = [[] for _ in range(n_sat)]
    for k, (a, _b, _m) in enumerate(rows):
        for i in range(n_sat):
            wp = wps[k][i]
            p = PlantParameters(sc_mass=pl["sc_mass"], sc_inertia=pl["sc_inertia"], tm_mass=pl["tm_mass"],
                                tm_side=pl["tm_side"], mosa_inertia=pl["mosa_inertia"],
                                mosa_stiffness=pl["mosa_stiffness"], stiffness=np.tile(pl["stiffness"], (2, 1)),
                                rotational_stiffness=np.tile(pl["rotational_stiffness"], (2, 1)),
                                crosstalk=pl["crosstalk"], housing_centers=craft.housing_centers(wp.theta),
                                lever_arms=craft.lever_arms(wp.theta), sensitive_axes=craft.sensitive_axes_array)
            try:
                cl = build_closed_loop(p, wp, ctl, azs)
            except ValueError as exc:
                raise ClosedLoopError(str(exc)) from None
            if validate:
                check_stable(cl)
            loops[i].append((float(t[a]), cl))
            parts[i].append((p, wp))
    settings = {"fs": float(cfg.value("fs", 4.0)), "duration": cfg.value("duration", None),
                "seed": int(cfg.value("seed", 0)), "segment": segment, "f_min": float(cfg.value("f_min", FREQUENCY_GRID["f_min"])),
                "f_max": float(cfg.value("f_max", FREQUENCY_GRID["f_max"])),
                "n_freq": int(cfg.value("n_freq", FREQUENCY_GRID["n_freq"])),
                "attitude_z_sensor": azs}
    names = tuple(getattr(traj, "satellite_names", ())) or tuple(f"Sat{i + 1}" for i in range(n_sat))
    return ClosedLoopModel(loops=loops, noise=noise, mission=mission, settings=settings,
                           satellite_names=names, t_span=(float(t[0]), float(t[-1])), parts=parts,
                           controllers=dict(ctl))


def closed_loop_budget(model: ClosedLoopModel, f=None, dt: float | None = None, progress=None):
    """The noise budget as an ``xarray.Dataset``: ``asd`` (segment, sat, output, source, frequency) one-sided
    [output unit/Hz^1/2]; ``total`` (segment, sat, output, frequency); ``requirement`` (frequency) the
    mission's TM acceleration requirement [m/s^2/Hz^1/2]; ``dominant`` (segment, sat, output, band) the
    largest source per band (:data:`BANDS`); ``gain_margin`` [1] and ``phase_margin`` [deg] and
    ``crossover`` [Hz] per (segment, sat, channel).  ``dt`` [s]: the zero-order-hold discretised loops'
    budget (what the time domain runs).  ``progress``: called with 1 after each (segment, satellite) loop
    (segments x satellites calls).  Coordinates carry units and frames (attrs)."""
    import xarray as xr

    s = model.settings
    f = np.logspace(math.log10(s["f_min"]), math.log10(s["f_max"]), s["n_freq"]) if f is None else np.asarray(f)
    outs = output_names()
    n_seg = len(model.loops[0])
    asd = None
    margins = []
    for k in range(n_seg):
        per_sat, msat = [], []
        for i in range(len(model.loops)):
            b, sources = noise_budget(model.loops[i][k][1], model.noise, f, dt=dt)
            per_sat.append(b)
            msat.append(loop_margins(model.loops[i][k][1]))
            if progress is not None:
                progress(1)
        asd = np.zeros((n_seg, len(model.loops)) + per_sat[0].shape) if asd is None else asd
        asd[k] = np.array(per_sat)
        margins.append(msat)
    total = np.sqrt(np.sum(asd ** 2, axis=3))
    dom = np.array([[dominant_sources(asd[k, i], sources, f, BANDS) for i in range(asd.shape[1])]
                    for k in range(n_seg)])
    chans = [m.channel for m in margins[0][0]]
    gm = np.array([[[m.gain_margin for m in ms] for ms in seg] for seg in margins])
    pm = np.array([[[m.phase_margin for m in ms] for ms in seg] for seg in margins])
    fc = np.array([[[m.f_phase_margin for m in ms] for ms in seg] for seg in margins])
    ds = xr.Dataset(
        {"asd": (("segment", "sat", "output", "source", "frequency"), asd),
         "total": (("segment", "sat", "output", "frequency"), total),
         "requirement": (("frequency",), requirement(model.mission).asd(f)),
         "dominant": (("segment", "sat", "output", "band"), dom),
         "gain_margin": (("segment", "sat", "channel"), gm),
         "phase_margin": (("segment", "sat", "channel"), pm),
         "crossover": (("segment", "sat", "channel"), fc)},
        coords={"segment": [lp[0] for lp in model.loops[0]], "sat": np.arange(1, len(model.loops) + 1),
                "sat_name": ("sat", list(model.satellite_names)), "output": outs, "source": sources,
                "frequency": f, "band": [f"{lo:g}-{hi:g} Hz" for lo, hi in BANDS], "channel": chans,
                "unit": ("output", [OUTPUTS[o][0] for o in outs]), "frame": ("output", [OUTPUTS[o][1] for o in outs])},
        attrs={"mission": model.mission, "asd": "one-sided", "frequency_unit": "Hz",
               "segment_unit": "s since the epoch (start of each frozen-coefficient segment)",
               "discretised_dt": float(dt) if dt is not None else 0.0})
    ds["asd"].attrs["units"] = "output unit/Hz^1/2"
    ds["phase_margin"].attrs["units"] = "deg"
    ds["crossover"].attrs["units"] = "Hz"
    return ds


def closed_loop_timeseries(model: ClosedLoopModel, duration_s: float | None = None, fs: float | None = None,
                           seed: int | None = None, sink: Sink | None = None, block_size: int = 65536):
    """Seeded time series of every output (:func:`tqdyn.closedloop.simulate.simulate`) from the run's first
    time on.  With ``sink`` None: an ``xarray.Dataset`` ``values`` (time, sat, output) [output units];
    with a sink (e.g. a file writer): the sink, after ``close``.  ``duration_s`` [s] (default: the
    settings' duration, else the run's span), ``fs`` [Hz] and ``seed`` override the settings."""
    s = model.settings
    fs = float(fs if fs is not None else s["fs"])
    dur = duration_s if duration_s is not None else (s["duration"] or (model.t_span[1] - model.t_span[0]))
    if not (isinstance(dur, (int, float)) and math.isfinite(dur) and dur > 0):
        raise ClosedLoopError(f"closed_loop.duration: {dur!r} is not a positive duration; allowed: > 0 s")
    n = int(round(float(dur) * fs))
    seed = int(seed if seed is not None else s["seed"])
    out = simulate(model.loops, model.noise, fs, n, seed=seed, sink=sink if sink is not None else MemorySink(),
                   t0=model.t_span[0], block_size=block_size)
    if sink is not None:
        return out
    import xarray as xr

    outs = list(out.meta["outputs"])
    return xr.Dataset({"values": (("time", "sat", "output"), out.values)},
                      coords={"time": out.t, "sat": np.arange(1, out.values.shape[1] + 1),
                              "sat_name": ("sat", list(model.satellite_names)), "output": outs,
                              "unit": ("output", [OUTPUTS[o][0] for o in outs]),
                              "frame": ("output", [OUTPUTS[o][1] for o in outs])},
                      attrs={"mission": model.mission, "fs": fs, "seed": seed,
                             "time_unit": "s on the run's time axis since the epoch"})


_ = (ClosedLoop, SOURCES, closed_loop_response)
