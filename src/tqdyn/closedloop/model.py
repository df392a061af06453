"""The closed-loop model of a coupled run: one closed loop per satellite and frozen-coefficient segment
(docs/closed-loop.md).

:func:`closed_loop_model` reads a coupled :class:`~tqdyn.formats.trajectory.Trajectory` (``tqdyn.propagate``
or a file, through its fields and attributes: this layer imports no I/O), its recorded scenario (the force
model's gravity gradient, the ``[closed_loop]`` settings) and the mission's defaults
(:mod:`tqdyn.closedloop.missions`), and builds the loops (:func:`tqdyn.closedloop.loop.build_closed_loop`)
at the working point of each segment (:mod:`tqdyn.closedloop.working_point`).
:mod:`tqdyn.analysis.closed_loop` evaluates the model (noise budget and time series as xarray objects).

Units: SI; times in seconds on the run's time axis (``traj.reference.time_scale`` since the epoch).
Frames: :data:`tqdyn.closedloop.loop.OUTPUTS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .budget import check_stable
from .loop import build_closed_loop
from .frequency import STACKED_SCHEMES, closed_loop_matrices, closed_loops, stack_loops, unstable_loops
from .missions import resolve
from .plant import plant_parameters
from .working_point import segment_rows, third_body_positions, working_points

__all__ = ["REQUIRED_FIELDS", "ClosedLoopError", "ClosedLoopModel", "closed_loop_model", "run_scenario",
           "static_closed_loop_model"]

#: Fields of a trajectory that the model reads (a coupled run: attitude, MOSAs, test masses, control).
REQUIRED_FIELDS = ("sat/T_S_I", "sat/omega", "sat/omega_dot", "mosa/angle", "tm/a_suspension", "tm/alpha_suspension",
                   "sat/a_dragfree")


class ClosedLoopError(ValueError):
    """Bad input for the closed loop: one line naming the field, the value and what is allowed."""


@dataclass(frozen=True)
class ClosedLoopModel:
    """The closed loops of a run (:func:`closed_loop_model`).

    loops : list over satellites of lists of (t_start [s], ClosedLoop), one per segment.
    noise : {source: AsdModel}; mission : str; settings : dict
    (:meth:`tqdyn.scenario.closed_loop.ClosedLoopConfig.settings`: fs [Hz], duration [s] or None, seed,
    segment [s], f_min, f_max [Hz], n_freq, attitude_z_sensor, scheme (resolved)); satellite_names : tuple;
    t_span : (t0, t1) [s].
    parts : list over satellites of lists (one per segment, as ``loops``) of (PlantParameters,
    WorkingPoint) the loops were built from; controllers : {loop: Controller} (to rebuild a loop with
    changed parameters, e.g. without cross-talk); stack : the loops' blocks
    (:class:`tqdyn.closedloop.frequency.LoopStack`, satellite-major: loop ``loops[i][k]`` is entry
    i n_segment + k) for the frequency domain, or None.  hinf : with ``closed_loop.design = "hinf"``, one
    :class:`tqdyn.closedloop.hinf.HinfController` per satellite (synthesised at its first segment's working
    point, used in all its segments; ``controllers`` then holds the per-loop design it replaces), else ().
    """

    loops: list
    noise: dict
    mission: str
    settings: dict
    satellite_names: tuple
    t_span: tuple
    parts: list = field(default_factory=list)
    controllers: dict = field(default_factory=dict)
    stack: object = None
    hinf: tuple = ()


def _where(traj) -> str:
    path = getattr(traj, "path", None)
    return "the in-memory trajectory" if path is None else repr(str(path))


def run_scenario(traj):
    """The run's recorded scenario (:class:`tqdyn.scenario.Scenario`, root attribute ``scenario``).
    ClosedLoopError (one line naming the file and the key that failed) when it does not load, e.g. a
    file whose ``initial.oem`` files are no longer where the run read them: the closed loop needs its
    force model and ``[closed_loop]`` settings and takes no defaults in their place."""
    from ..scenario import loads_scenario

    where = _where(traj)
    try:
        return loads_scenario(traj.scenario_toml, source=where)
    except ValueError as exc:
        key = getattr(exc, "field", "")
        raise ClosedLoopError(f"{where}: its recorded scenario does not load"
                              + (f" ({key})" if key and key != where else "")
                              + "; allowed: a run whose scenario loads (tqdyn.load_scenario of the file says why)") \
            from None


def _gravity(scen, t) -> tuple[float, np.ndarray | None, list]:
    """The run's gravity field at the times ``t`` (N,) [s]: the central body's GM [m^3/s^2], the positions
    (N, n_b, 3) [m] of its third bodies relative to the central body (None without) and their GMs."""
    from ..forces.body_gms import body_gms

    allg = body_gms(scen.forces)
    central_gm = float(scen.forces.gm_earth) if scen.central_body == "earth" else allg["sun"]
    bodies = tuple(scen.forces.third_bodies)
    gms = [allg[b] for b in bodies]
    if not bodies:
        return central_gm, None, gms
    from ..astro.ephemeris import ephemeris_named

    return central_gm, third_body_positions(scen.reference, scen.epoch, t, bodies,
                                            ephemeris_named(scen.forces.ephemeris)), gms


def _craft(sc):
    """The :class:`tqdyn.constellation.spacecraft.Spacecraft` of a trajectory's spacecraft record."""
    from ..constellation.spacecraft import Spacecraft

    return Spacecraft(housing_centers_nominal=sc.housing_centers, pivot_points=sc.pivots,
                      sensitive_axes=sc.sensitive_axes, scheme=sc.dragfree_scheme, architecture=sc.architecture,
                      theta_nominal=sc.theta_nominal)


def _build(p, wp, controllers: dict, attitude_z_sensor: str, scheme: str, validate: bool):
    try:
        cl = build_closed_loop(p, wp, controllers, attitude_z_sensor, scheme)
    except ValueError as exc:
        raise ClosedLoopError(str(exc)) from None
    if validate:
        check_stable(cl)
    return cl


def _assemble(parts, controllers: dict, attitude_z_sensor: str, scheme: str, validate: bool):
    """(closed loops, stack) of the (PlantParameters, WorkingPoint) ``parts``: every loop built at once
    (:mod:`tqdyn.closedloop.frequency`) for the schemes it stacks (:data:`~tqdyn.closedloop.frequency.
    STACKED_SCHEMES`), the unstable ones refused; otherwise ("single_tm", whose drag-free error is a
    controller's output) one loop at a time with stack None (the budget then takes the per-loop path)."""
    if scheme not in STACKED_SCHEMES:
        return [_build(p, wp, controllers, attitude_z_sensor, scheme, validate) for p, wp in parts], None
    try:
        st = stack_loops(parts, controllers, attitude_z_sensor, scheme)
    except ValueError as exc:
        raise ClosedLoopError(str(exc)) from None
    mats = closed_loop_matrices(st)
    cls = closed_loops(st, mats)
    if validate:
        for j in unstable_loops(mats[0], cls[0].system.state_labels):
            check_stable(cls[j])                   # DesignError naming the loop and its margins
    return cls, st


def _hinf_loops(parts, settings: dict, validate: bool, names=()) -> tuple[list, tuple]:
    """(closed loops, controllers) of the (PlantParameters, WorkingPoint) ``parts`` (a list per satellite of
    one per segment) under the "hinf" design: one synthesis per satellite (its first segment), every segment's
    loop built with it (checked stable with ``validate``)."""
    from .hinf import synthesise

    attitude_z_sensor, scheme = settings["attitude_z_sensor"], settings["scheme"]
    ks = tuple(synthesise(*per_sat[0], attitude_z_sensor, scheme, names[i] if i < len(names) else f"Sat{i + 1}",
                          settings["hinf_peak_sensitivity"], settings["hinf_authority_ratio"])
               for i, per_sat in enumerate(parts))
    cls = [_build(p, wp, k, attitude_z_sensor, scheme, validate) for k, per_sat in zip(ks, parts) for p, wp in per_sat]
    return cls, ks


def _loops(t, rows, wps, plant: dict, craft, controllers: dict, attitude_z_sensor: str, validate: bool,
           scheme: str = "constellation", settings: dict | None = None, names=()):
    """(loops, parts, stack) of :class:`ClosedLoopModel` from the working points ``wps`` of the segments
    ``rows`` (:func:`_assemble`)."""
    n_sat, n_seg = len(wps[0]), len(rows)
    parts = [[] for _ in range(n_sat)]
    for k in range(n_seg):
        for i in range(n_sat):
            wp = wps[k][i]
            parts[i].append((plant_parameters(plant, craft, wp.theta), wp))
    ks = ()
    if settings is not None and settings["design"] == "hinf":
        (cls, ks), st = _hinf_loops(parts, settings, validate, names), None
    else:
        cls, st = _assemble([pw for per_sat in parts for pw in per_sat], controllers, attitude_z_sensor, scheme,
                            validate)
    loops = [[(float(t[rows[k][0]]), cls[i * n_seg + k]) for k in range(n_seg)] for i in range(n_sat)]
    return loops, parts, st, ks


def closed_loop_model(traj, config=None, validate: bool = True) -> ClosedLoopModel:
    """The closed loops of a coupled run, one per satellite and frozen-coefficient segment.

    traj : a coupled :class:`~tqdyn.formats.trajectory.Trajectory` (``tqdyn.propagate`` or a file).
    config : :class:`tqdyn.scenario.closed_loop.ClosedLoopConfig` or None (the run's own [closed_loop]).
    validate : refuse an unstable design (one line naming the loop and its margin).
    ClosedLoopError (one line) for a run without test masses or attitude (a pure-gravity run), with
    fewer than two rows, whose recorded scenario does not load (:func:`run_scenario`), or with
    sensitive axes out of the constellation plane.
    """
    missing = [f for f in REQUIRED_FIELDS if f not in traj.fields]
    if missing:
        raise ClosedLoopError(f"trajectory: {missing[0]} is missing (a run without test masses or attitude: "
                              f"pointing = {traj.attrs.get('pointing')!r}); allowed: a coupled run (a pointing law, "
                              "control on or off)")
    t = np.asarray(traj["t"], dtype=np.float64)
    if len(t) < 2:
        raise ClosedLoopError(f"trajectory: {len(t)} row(s); allowed: a run of at least 2 rows")
    scen = run_scenario(traj)
    cfg = scen.closed_loop if config is None else config
    settings = {**cfg.settings(), "scheme": cfg.scheme(traj.spacecraft.architecture)}
    try:
        mission, plant, ctl, noise = resolve(cfg, traj.spacecraft.architecture)
    except ValueError as exc:
        raise ClosedLoopError(str(exc)) from None
    rows = segment_rows(t, settings["segment"])
    mids = [m for _a, _b, m in rows]
    central_gm, pos, gms = _gravity(scen, t[mids])       # gravity gradient: central body + third bodies
    sg = traj["tm/self_gravity"] if "tm/self_gravity" in traj.fields else np.zeros((3, 2, 3))
    wps = working_points(t[mids], traj["sat/r"][mids], traj["sat/T_S_I"][mids], traj["sat/omega"][mids],
                         traj["sat/omega_dot"][mids], traj["mosa/angle"][mids], traj["tm/a_suspension"][mids],
                         traj["tm/alpha_suspension"][mids], traj["sat/a_dragfree"][mids], sg, central_gm, pos, gms)
    names = tuple(getattr(traj, "satellite_names", ()))
    loops, parts, stack, ks = _loops(t, rows, wps, plant, _craft(traj.spacecraft), ctl,
                                     settings["attitude_z_sensor"], validate, cfg.scheme(traj.spacecraft.architecture),
                                     settings, names)
    names = names or tuple(f"Sat{i + 1}" for i in range(len(loops)))
    return ClosedLoopModel(loops=loops, noise=noise, mission=mission, settings=settings,
                           satellite_names=names, t_span=(float(t[0]), float(t[-1])), parts=parts,
                           controllers=dict(ctl), stack=stack, hinf=ks)


def static_closed_loop_model(config=None, validate: bool = True) -> ClosedLoopModel:
    """The closed loop of a mission at its documented static working point, without a run: one spacecraft,
    one segment starting at t = 0 (docs/closed-loop.md).

    config : :class:`tqdyn.scenario.closed_loop.ClosedLoopConfig` (``closed_loop.mission`` required, e.g.
        ``tqdyn.scenario.closed_loop_config({"mission": "lpf"})``) or a mission name.
    The working point: :func:`tqdyn.closedloop.missions.representative_working_point` (the constellation
    missions' first-principles point; LISA Pathfinder's and TianQin-1's, :mod:`tqdyn.closedloop.flown`), the
    plant :func:`~tqdyn.closedloop.missions.representative_plant` with the configuration's plant values.
    ``t_span`` (0, ``closed_loop.duration`` or ``closed_loop.segment``) [s].  ClosedLoopError (one line naming
    the key) for a configuration without a mission, a geometry the scheme cannot control or an unstable design.
    """
    from ..scenario.closed_loop import ClosedLoopConfig
    from .missions import representative_plant, representative_working_point

    cfg = ClosedLoopConfig(raw={"mission": config}) if isinstance(config, str) else config
    if cfg is None or "mission" not in (cfg.raw or {}):
        raise ClosedLoopError("closed_loop.mission: missing; allowed: a mission (the static working point of a "
                              "mission needs one: tqdyn closed-loop --mission NAME)")
    settings = {**cfg.settings(), "scheme": cfg.scheme()}
    try:
        mission, plant, ctl, noise = resolve(cfg, str(cfg.raw["mission"]))
    except ValueError as exc:
        raise ClosedLoopError(str(exc)) from None
    p = representative_plant(mission, **plant)
    wp = representative_working_point(mission)
    ks = ()
    if settings["design"] == "hinf":
        ((cl,), ks), stack = _hinf_loops([[(p, wp)]], settings, validate, (mission,)), None
    else:
        (cl,), stack = _assemble([(p, wp)], ctl, settings["attitude_z_sensor"], settings["scheme"], validate)
    span = float(settings["duration"] or settings["segment"])
    return ClosedLoopModel(loops=[[(0.0, cl)]], noise=noise, mission=mission, settings=settings,
                           satellite_names=(mission,), t_span=(0.0, span), parts=[[(p, wp)]], controllers=dict(ctl),
                           stack=stack, hinf=ks)
