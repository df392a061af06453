"""The front door: a scenario, a propagation and its analysis from one import.

::

    import tqdyn
    traj = tqdyn.propagate("tianqin", {"run.duration": "2d"})   # in memory, no file
    ds = traj.to_xarray()                                       # dims time, sat, tm, comp
    lt = tqdyn.light_travel_times(traj)                         # TM-to-TM light paths
    asd = tqdyn.range_asd(lt, "13")                             # range ASD of link 13

Everything here composes the layers below (docs/design.md): scenarios
(:mod:`tqdyn.scenario`), the propagation (:mod:`tqdyn.dynamics`), the
trajectory format (:mod:`tqdyn.formats.trajectory`), light paths
(:mod:`tqdyn.lightpath`) and spectra (:mod:`tqdyn.analysis.spectra`).  Units
SI; vectors in the trajectory's reference system (``traj.reference``: GCRS
for the geocentric scenarios); times in seconds since the scenario epoch.
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Mapping, Sequence

import numpy as np

from . import dynamics
from .analysis import metrics as _metrics
from .analysis.spectra import requirement_asd
from .constellation.indices import Link
from .formats.trajectory import Trajectory, read_trajectory
from .lightpath import LightTravelTimes, light_travel_times_of
from .scenario import Scenario, ScenarioError, builtin_scenarios
from .scenario.toml_text import toml_value
from .workflows.run import RunSummary, load_run_scenario, output_attrs, run_to_file

__all__ = ["LightTravelTimes", "RunSummary", "Scenario", "ScenarioError", "Trajectory", "breathing_angles",
           "builtin_scenarios", "closed_loop_budget", "closed_loop_model", "closed_loop_timeseries",
           "light_travel_times", "load_scenario", "od_covariance", "od_fit", "od_simulate", "open_closed_loop",
           "open_measurements", "open_od_estimate", "open_trajectory", "plot_od_residuals", "propagate", "range_asd",
           "read_closed_loop", "read_od_estimate", "requirement_asd", "run"]


def _overrides(overrides) -> list[str]:
    if isinstance(overrides, str):
        return [overrides]
    if isinstance(overrides, Mapping):
        return [f"{key}={toml_value(value)}" for key, value in overrides.items()]
    return list(overrides)


def load_scenario(scenario: str | Scenario | None = None,
                  overrides: Mapping[str, object] | Sequence[str] = ()) -> Scenario:
    """A validated scenario: a built-in name (:func:`builtin_scenarios`; None
    -> ``"tianqin"``), the path of a TOML file, the path of a trajectory file
    (its recorded, resolved scenario: running it reproduces the file; a
    :class:`UserWarning` says what this tqdyn would do differently, see
    :func:`tqdyn.workflows.run.scenario_of_trajectory`), or a
    :class:`Scenario` (returned as is when there are no overrides).

    overrides : ``{"run.duration": "2d", "satellites.2.nu_deg": 151}`` or
        ``["run.duration=2d", ...]`` -- any scenario key (docs/scenarios.md),
        as ``tqdyn run --set`` takes it.
    Raises :class:`ScenarioError` (one line naming the key, the value and what is allowed).
    """
    over = _overrides(overrides)
    if isinstance(scenario, Scenario):
        if not over:
            return scenario
        from .scenario import loads_scenario

        return loads_scenario(scenario.to_toml(), over, source=f"scenario {scenario.name!r}")
    return _scenario(scenario, over, writes=False)


def _scenario(scenario, over, writes: bool) -> Scenario:
    """:func:`load_scenario` of a name or path; a trajectory file's notes as warnings."""
    scen, notes = load_run_scenario(scenario, over, writes=writes)
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=3)
    return scen


def propagate(scenario: str | Scenario | None = None, overrides: Mapping[str, object] | Sequence[str] = (), *,
              progress: bool = False) -> Trajectory:
    """Propagate a scenario in memory and return its trajectory (no file).

    ``scenario``, ``overrides``: as :func:`load_scenario`; the run's span,
    step, precision and output sampling are the scenario's (``run.*``,
    ``integrator.*`` keys).  progress: show a progress bar on stderr.

    Returns a :class:`Trajectory` (the object :func:`open_trajectory` returns
    for a file, with :attr:`~Trajectory.path` None): the same fields, shapes
    and units as the file ``tqdyn run`` would write (docs/trajectory-format.md),
    ``to_xarray()`` for an xarray view, ``dd(name)`` for the exact
    double-double pairs; its attribute ``result`` is the propagation's
    :class:`tqdyn.dynamics.RunResult` (steps, wall time, final states).
    Memory: the whole trajectory (~4 kB per row of a coupled run; use
    ``run.output_every`` for long spans).
    """
    scen = load_scenario(scenario, overrides)
    model = dynamics.check_inputs(scen)
    # compile (or load the cached kernels) outside the timed propagation
    dynamics.warm_up(scen.run.precision, scen.integrator.method, dynamics.build_system(scen, model).cpar,
                     model=model)
    blocks: list = []
    bar = None
    if progress:
        from tqdm import tqdm

        total = scen.n_steps if scen.integrator.mode == "fixed" else float(scen.run.duration_s)
        bar = tqdm(total=total, file=sys.stderr, desc="propagating", dynamic_ncols=True)
    try:
        result = dynamics.propagate(scen, sink=blocks.append, model=model,
                                    progress=None if bar is None else bar.update)
    finally:
        if bar is not None:
            bar.close()
    static = {"tm/self_gravity": dynamics.self_gravity_oa(scen)} if scen.constellation.coupled else None
    traj = Trajectory.from_rows(dynamics.Rows.concatenate(blocks), output_attrs(scen, model), static)
    traj.result = result
    return traj


def run(scenario: str | Scenario | None = None, overrides: Mapping[str, object] | Sequence[str] = (), *,
        output: str | None = None, checkpoint_every: int = 0, resume: bool = False) -> RunSummary:
    """Propagate a scenario to its trajectory file, as ``tqdyn run`` does
    (atomic: no file or a complete one; ``checkpoint_every`` steps and
    ``resume`` as ``--checkpoint-every`` / ``--resume``).  ``output``: the
    file (default: the scenario's ``run.output``; a trajectory file given as
    ``scenario`` runs its recorded scenario again and may not be its own
    output).  Returns the :class:`~tqdyn.workflows.run.RunSummary` (its
    ``path``, rows, result)."""
    over = _overrides(overrides) + ([f"run.output={output}"] if output is not None else [])
    scen = load_scenario(scenario, over) if isinstance(scenario, Scenario) else _scenario(scenario, over, writes=True)
    return run_to_file(scen, checkpoint_every=checkpoint_every, resume=resume)


def open_trajectory(path) -> Trajectory:
    """Read a trajectory file (any format version this tqdyn knows) into memory."""
    return read_trajectory(path)


def light_travel_times(trajectory: Trajectory, *, shapiro: bool | None = None,
                       shapiro_bodies=None) -> LightTravelTimes:
    """The six links' light travel times on the trajectory's time grid: test
    mass to test mass for coupled runs, satellite centre to centre for
    pure-gravity runs (solved in double-double on the Hermite dense output;
    :func:`tqdyn.lightpath.light_travel_times`).  shapiro: the central body's
    Shapiro delay, None = its default (geocentric: off, as in the paper;
    heliocentric: the Sun's, on); shapiro_bodies (heliocentric): other
    bodies' Shapiro delays ("third_bodies", "all" or a list of names)."""
    kw = {} if shapiro is None else {"shapiro": shapiro}
    if shapiro_bodies is not None:
        kw["shapiro_bodies"] = shapiro_bodies
    return light_travel_times_of(trajectory, **kw)


def range_asd(light_times: LightTravelTimes, link: str | int | Link = "13") -> _metrics.AsdResult:
    """Amplitude spectral density of one link's light-path range c tau [m/Hz^1/2].

    link: ``"13"``, ``13`` or ``Link.L13`` (received on satellite 1, emitted
    by 3).  The ASD is that of the second difference of the range, formed
    in double-double and divided by the difference filter's gain (Kaiser
    window, Welch; :func:`tqdyn.analysis.spectra.range_asd`).  Returns an
    :class:`~tqdyn.analysis.metrics.AsdResult`: ``f`` [Hz], ``asd``, and the
    largest ratio to the requirement (:func:`requirement_asd`) in band.
    """
    try:
        ln = Link(int(link))
    except (TypeError, ValueError):
        raise ValueError(f"link: {link!r} is not a link; allowed: "
                         f"{', '.join(str(int(x)) for x in Link)}") from None
    hi, lo = light_times.range
    t = light_times.t[0] + light_times.t[1]
    return _metrics.range_asd_in_band(t, hi[:, ln.index], lo[:, ln.index])


def breathing_angles(trajectory: Trajectory) -> np.ndarray:
    """Breathing angles alpha_i [rad], (N, 3) -- the angle at each satellite
    between its two arms, from the double-double satellite positions (any
    run of 3 satellites, coupled or pure gravity; ValueError for other
    counts)."""
    return _metrics.breathing_angles_of(trajectory)


def closed_loop_model(trajectory: Trajectory, config=None, validate: bool = True):
    """The closed loops of a coupled run (docs/closed-loop.md):
    :func:`tqdyn.closedloop.model.closed_loop_model` (imported on first use)."""
    from .closedloop.model import closed_loop_model as f

    return f(trajectory, config, validate)


def closed_loop_budget(model, f=None, dt: float | None = None, per_source: bool = True):
    """The noise budget, margins and dominant sources as an ``xarray.Dataset`` (``per_source``: with the ASD of
    every output from every source): :func:`tqdyn.analysis.closed_loop.closed_loop_budget`."""
    from .analysis.closed_loop import closed_loop_budget as g

    return g(model, f, dt, per_source=per_source)


def closed_loop_timeseries(model, duration_s: float | None = None, fs: float | None = None, seed: int | None = None,
                           sink=None, block_size: int = 65536):
    """Seeded time series of every output (``xarray.Dataset``, or streamed to ``sink``):
    :func:`tqdyn.analysis.closed_loop.closed_loop_timeseries`."""
    from .analysis.closed_loop import closed_loop_timeseries as g

    return g(model, duration_s, fs, seed, sink, block_size)


def open_closed_loop(path):
    """Open a closed-loop file (docs/closed-loop-file.md): ``.budget`` (xarray.Dataset), ``.timeseries()``,
    ``.attrs``, ``.configuration`` -- :func:`tqdyn.formats.closed_loop.read_closed_loop`."""
    from .formats.closed_loop import read_closed_loop as g

    return g(path)


def od_simulate(run, tracking, arc=None, **options):
    """Simulated tracking on a run, in memory: an ``xarray.Dataset`` of measurements (dimension ``row``:
    ``value``, ``sigma`` [m, m/s for range rates] with coordinates ``t`` [s since the epoch], ``type``,
    ``sat``, ``peer``; the plan in its attributes).  ``run``: a trajectory (:func:`propagate`,
    :func:`open_trajectory`), a run file or a scenario -- its ``[accelerations]`` and initial states
    are the truth; ``tracking``: ``"gnss,slr,isr"`` or a sequence of kinds with ``arc`` (seconds or
    ``"7d"``), or a ``tqdyn.od.problem.Tracking``; keywords ``seed``, ``interval``, ``stations``,
    ``bias`` ({"slr_range": 0.02, "slr_range/Graz": -0.01} [m, m/s]), ``sp3`` (SP3 files of the GNSS
    transmitters), ``overrides`` (:func:`tqdyn.workflows.od_memory.od_simulate`; an unknown keyword or
    a bad value: one line).  ``tqdyn od simulate`` writes the same measurements as a CCSDS TDM."""
    from .workflows.od_memory import od_simulate as g

    return g(run, tracking, arc, **options)


def od_fit(scenario, measurements, tracking=None, **options):
    """The batch least-squares fit of ``scenario`` (a name, TOML, run file, trajectory or
    :class:`Scenario`) to ``measurements`` (:func:`od_simulate`'s or :func:`open_measurements`'s
    Dataset), in memory: an ``xarray.Dataset`` with ``estimate``, ``sigma``, ``covariance``,
    ``correlation`` over ``parameter`` (coordinate ``unit``), the consider quantities, the residuals,
    and the chi^2 statistics in its attributes.  ``tracking``: the kinds (None: the measurements'
    own) or a ``tqdyn.od.problem.Tracking``; keywords ``estimate``, ``consider``, ``a_priori``
    ({group: sigma}, e.g. {"bias": 0.05, "state": (100.0, 0.01)}), ``edit_sigma``, ``sp3``,
    ``overrides`` and the estimator's ``step_tol``, ``max_iterations``, ``max_condition``,
    ``min_kept_fraction``, ``max_edit_passes`` (:func:`tqdyn.workflows.od_memory.od_fit`; an unknown
    keyword or a bad value: one line).  ``tqdyn od fit`` writes the same estimate as a file."""
    from .workflows.od_memory import od_fit as g

    return g(scenario, measurements, tracking, **options)


def od_covariance(scenario, tracking, arc=None, **options):
    """The predicted covariance of a tracking plan on a scenario, without measurements: an
    ``xarray.Dataset`` (``nominal``, ``sigma``, ``covariance``, ``correlation``, ``consider_sigma`` over
    ``parameter``; the condition number in its attributes).  ``tracking``, ``arc`` as
    :func:`od_simulate`; keywords ``interval``, ``estimate``, ``consider``, ``a_priori``, ``stations``,
    ``sp3``, ``overrides`` (:func:`tqdyn.workflows.od_memory.od_covariance`).  ``tqdyn od covariance
    --json`` writes the same numbers."""
    from .workflows.od_memory import od_covariance as g

    return g(scenario, tracking, arc, **options)


def open_measurements(path, scenario=None):
    """A measurement file (CCSDS TDM of ``tqdyn od simulate``) as the Dataset :func:`od_simulate`
    returns (``scenario``: check it against the scenario's epoch; None: the file's own)."""
    from .workflows.od_memory import open_measurements as g

    return g(path, scenario)


def open_od_estimate(path):
    """Read an estimate file (``tqdyn od fit --output``): ``.attrs``, ``.parameters``, ``.measurements``
    -- :func:`tqdyn.formats.od_estimate.read_estimate_file`."""
    from .formats.od_estimate import read_estimate_file

    return read_estimate_file(path)


#: The readers' former names (kept: scripts written for them keep working).
read_closed_loop = open_closed_loop
read_od_estimate = open_od_estimate


def plot_od_residuals(estimate, path, title: str | None = None):
    """Draw the normalised post-fit residuals of an estimate (an estimate file's path, what
    :func:`open_od_estimate` returned, or :func:`od_fit`'s Dataset) against time per measurement type and satellite, and their
    histogram against the unit normal, into ``path`` (``.png`` or ``.pdf``), as ``tqdyn od fit
    --figure``; returns what was drawn (:class:`tqdyn.analysis.figures_od.ResidualFigure`)."""
    from .analysis.figures_od import plot_od_residuals as plot

    if hasattr(estimate, "data_vars"):  # od_fit's Dataset
        from .workflows.od_memory import estimate_file_of

        estimate = estimate_file_of(estimate)
    return plot(estimate if hasattr(estimate, "measurements") else open_od_estimate(estimate), path, title=title)
