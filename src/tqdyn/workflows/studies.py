"""The study catalogue of the paper's section V and the driver that runs or reuses its runs.

A *run* (:class:`RunSpec`) is the built-in ``tianqin`` scenario (the full
force model of the paper's Table II) plus overrides, a nominal duration and
an output decimation; a *study* (:class:`Study`) is one figure or result of
the paper's section V and names the runs it needs.  Several studies share
runs (e.g. the 30-day drag-free run serves Figs. 5, 6 and 7).

Output design (the file sizes of the runs are in the ``summary.json`` of
``tqdyn report --studies`` and in docs/report.md):

* ``*-90d`` runs: 90 days, one output row every :data:`COARSE_EVERY` steps
  (600 s).  Enough for orbit deviations, breathing
  angles and the drag-free acceleration (all vary on the orbital period,
  3.65 days); the 50 s integration step is unchanged, only the output is
  decimated, so the states are those of the 50 s propagation.
* ``*-30d-50s`` runs: 30 days at every 50 s step:
  range ASDs down to ~5e-5 Hz (the Welch estimate of
  :mod:`tqdyn.analysis.spectra` is reliable above ~26 bins, 26 x 1.8e-6 Hz
  for 30 days), the Hermite dense output of the pointing study, and the
  one-month electrostatic control of Fig. 8.  A 30-day run is the first
  30 days of the 90-day run of the same scenario (same steps).

Sign of the flight direction: with Z_S = n_ij x n_ik / sin(alpha_i)
(docs/design.md, Conventions) the satellites' velocity is along **-Y_S**; :data:`FLIGHT_DIRECTION_S`
holds that.  It is not trusted here: ``tests/test_report.py`` measures
Y_S . v / |v| on a run and the report prints it from every coupled run.
The "+flight" common self-gravity of 1e-9 m/s^2 is therefore
``[0, -1e-9, 0]`` in S.

Every run integrates with DP87 at the scenario's step (:data:`STUDY_INTEGRATOR`, applied before the
run's own overrides): the paper's section V was computed with it, so the studies reproduce it with
the paper's method rather than the default of ``tqdyn run`` (the multistep method, which agrees with
DP87 to DP87's own reproducibility: docs/precision.md), and the runs' files (their digests) and
records are those measured before that default changed.

Runs live in a runs directory as ``<run name>-<digest>.h5``, the digest a
short SHA-256 of the resolved scenario (with ``run.output`` normalised), so a
scaled ("quick") set and the full set can coexist.  A run whose file is a
complete trajectory of the same resolved scenario is reused, anything else
is (re)run.  Pending runs execute as tasks on a Dask ``LocalCluster``
(processes, 1 thread each; as in :mod:`tqdyn.workflows.sweep`, whose ``run_sweep``
is not used because it gathers all members, on one time grid, into one
netCDF file) or in this process when only one worker is asked for.

Units: durations in days / seconds (TT) since the epoch 2004-06-06 00:00:00
UTC; accelerations m/s^2 in the satellite frame S; everything else SI.
"""

from __future__ import annotations

import hashlib
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from .._choices import unknown

__all__ = [
    "BASE_SCENARIO",
    "COARSE_EVERY",
    "STUDY_INTEGRATOR",
    "FLIGHT_DIRECTION_S",
    "QUICK_SCALE",
    "RUNS",
    "SG_DIRECTIONS",
    "STUDIES",
    "PlannedRun",
    "RunOutcome",
    "RunSpec",
    "Study",
    "StudyRuns",
    "plan_studies",
    "run_complete",
    "run_studies",
    "scaled_duration_s",
]

#: Base scenario of every study run (full force model, Table I elements).
BASE_SCENARIO = "tianqin"
#: Overrides of every study run, before its own: the paper's integrator, DP87 (the module docstring).
STUDY_INTEGRATOR = ("integrator.method=dp87",)
#: Output decimation of the 90-day runs (rows every 12 x 50 s = 600 s).
COARSE_EVERY = 12
#: Duration scale of ``tqdyn report --studies --quick``: 90 days -> 1 day, 30 days -> 8 h.
QUICK_SCALE = 1.0 / 90.0
#: Unit vector of the flight direction (the velocity) in the satellite frame S.
FLIGHT_DIRECTION_S = (0.0, -1.0, 0.0)
#: Magnitude of the common self-gravity of the stability studies [m/s^2].
COMMON_SG = 1e-9

_PLACEHOLDER = "study-run.h5"
_DIGEST_CHARS = 12


@dataclass(frozen=True)
class RunSpec:
    """One study run: ``scenario`` (built-in name) + ``overrides`` (as for
    ``tqdyn run --set``; after :data:`STUDY_INTEGRATOR`), ``days`` nominal duration [days],
    ``output_every`` (output row every N integrator steps), ``description``."""

    name: str
    description: str
    overrides: tuple[str, ...]
    days: float
    output_every: int
    scenario: str = BASE_SCENARIO

    def scenario_for(self, *, duration_scale: float = 1.0, extra: Sequence[str] = (), output: str | None = None):
        """The resolved :class:`tqdyn.scenario.Scenario` of this run.

        duration_scale : factor on ``days`` (> 0); the duration is rounded to
        a whole number of output rows (at least one).  extra : further
        overrides applied after the run's own (e.g. a cheaper force model for
        tests).  output : ``run.output`` (default: the placeholder name).
        Raises :class:`tqdyn.scenario.ScenarioError`.
        """
        from ..scenario import load_scenario

        own = [*STUDY_INTEGRATOR, *self.overrides, *extra]
        base = load_scenario(self.scenario, own)
        step = float(base.integrator.step_s)
        dur = scaled_duration_s(self.days, duration_scale, step * self.output_every)
        return load_scenario(self.scenario, [*own, f"run.duration={dur}",
                                             f"run.output_every={self.output_every}",
                                             f"run.output={output or _PLACEHOLDER}"])


@dataclass(frozen=True)
class Study:
    """One result of the paper's section V: ``name``, ``title``, ``paper``
    (where it is in the paper), ``runs`` (names in :data:`RUNS`),
    ``description``."""

    name: str
    title: str
    paper: str
    runs: tuple[str, ...]
    description: str


def _vec(v) -> str:
    return "[" + ", ".join(_num(x) for x in v) + "]"


def _num(x: float) -> str:
    return "0" if x == 0 else f"{x:.0e}".replace("e-0", "e-")


def _common(direction: Sequence[float]) -> str:
    return "spacecraft.self_gravity_common=" + _vec([COMMON_SG * c for c in direction])


_FLIGHT = FLIGHT_DIRECTION_S

#: The six directions of the common self-gravity runs (axes of S) and their unit vectors.
SG_DIRECTIONS = {"+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0),
                 "-y": (0.0, -1.0, 0.0), "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0)}


def _runs() -> dict[str, RunSpec]:
    # the physical set-ups are built-in scenarios (tqdyn run tianqin-gravity ...);
    # a study run adds only its span and output sampling (and the direction
    # of the common self-gravity)
    g, df, loc = "tianqin-gravity", "tianqin-dragfree", "tianqin-dragfree-local"
    runs = [
        RunSpec("gravity-90d", "pure-gravity orbits (no attitude, no control), 90 d, 600 s rows", (), 90,
                COARSE_EVERY, g),
        RunSpec("gravity-30d-50s", "pure-gravity orbits, 30 d at 50 s", (), 30, 1, g),
        RunSpec("dragfree-global-90d", "drag-free orbits, global pointing, no self-gravity, 90 d, 600 s rows",
                (), 90, COARSE_EVERY, df),
        RunSpec("dragfree-global-30d-50s", "drag-free orbits, global pointing, no self-gravity, 30 d at 50 s",
                (), 30, 1, df),
        RunSpec("dragfree-local-90d", "drag-free orbits, local pointing (taylor2), no self-gravity, 90 d, 600 s rows",
                (), 90, COARSE_EVERY, loc),
        RunSpec("dragfree-local-30d-50s", "drag-free orbits, local pointing (taylor2), no self-gravity, 30 d at 50 s",
                (), 30, 1, loc),
        RunSpec("table-iv-30d-50s", "drag-free orbits, global pointing, Table IV self-gravity, 30 d at 50 s",
                ("spacecraft.self_gravity=table-iv",), 30, 1, BASE_SCENARIO),
    ]
    for label, d in SG_DIRECTIONS.items():
        flight = sum(a * b for a, b in zip(d, _FLIGHT))
        what = " (+flight)" if flight > 0 else " (-flight)" if flight < 0 else ""
        runs.append(RunSpec(f"sg{label}-90d", f"common self-gravity 1e-9 m/s^2 along {label} of S{what}, "
                            "Table IV off, 90 d, 600 s rows", (_common(d),), 90, COARSE_EVERY, df))
    runs.append(RunSpec("sg-extreme-90d", "extreme case: common self-gravity 1e-9 m/s^2 Sat1 +flight, Sat2 -flight, "
                        "Sat3 +flight, 90 d, 600 s rows (built-in scenario tianqin-extreme)", (), 90, COARSE_EVERY,
                        "tianqin-extreme"))
    return {r.name: r for r in runs}


#: Every study run by name.
RUNS: dict[str, RunSpec] = _runs()

_SG_RUNS = tuple(f"sg{label}-90d" for label in SG_DIRECTIONS)

#: The studies of the paper's section V by name (in report order).
#: Where the studies are listed.
STUDIES_DOC = "docs/report.md#studies"
STUDIES: dict[str, Study] = {s.name: s for s in [
    Study("pointing", "Pointing error of the global and Taylor laws vs the iterative law", "Fig. 5",
          ("dragfree-global-30d-50s",),
          "per beam, X_S and theta, along the 30-day drag-free orbit (global pointing, no self-gravity)"),
    Study("range-asd", "Range ASD of gravity vs drag-free orbits (global and local pointing)", "Fig. 6",
          ("gravity-30d-50s", "dragfree-global-30d-50s", "dragfree-local-30d-50s"),
          "light-path range c tau between satellite centres, link 13, vs the requirement"),
    Study("control-no-sg", "Electrostatic control without self-gravity", "Fig. 7",
          ("dragfree-global-30d-50s",), "TM suspension (linear, angular) and drag-free accelerations"),
    Study("control-table-iv", "Electrostatic control with the Table IV self-gravity, one month", "Fig. 8",
          ("table-iv-30d-50s",), "TM suspension (linear, angular) and drag-free accelerations"),
    Study("dragfree-deviation", "Drag-free vs pure-gravity orbits over 3 months", "Sec. V.A",
          ("gravity-90d", "dragfree-global-90d", "dragfree-local-90d"),
          "orbit deviation and its secular along-track prediction from the mean drag-free acceleration"),
    Study("common-self-gravity", "Common self-gravity 1e-9 m/s^2 along +-x, +-y, +-z of S", "Sec. V.B.2",
          ("gravity-90d", *_SG_RUNS), "orbit deviation from the gravity orbit and breathing-angle variation"),
    Study("extreme", "Extreme self-gravity case: breathing angles vs 60 +- 0.1 deg", "Fig. 9",
          ("gravity-90d", "sg-extreme-90d"), "Sat1 +flight, Sat2 -flight, Sat3 +flight"),
    Study("light-path", "Light-path vs instantaneous TM-TM range, Sat-Sat vs TM-TM range", "Figs. 10, 11",
          ("table-iv-30d-50s",), "link 13 (received on Sat1 from Sat3), Table IV self-gravity"),
]}


def scaled_duration_s(days: float, scale: float, unit_s: float) -> int:
    """``days`` x ``scale`` in seconds, rounded to a whole number (>= 1) of
    ``unit_s`` (the output row spacing) [s].  ValueError for scale <= 0."""
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) or scale <= 0:
        raise ValueError(f"duration scale: {scale!r} is not allowed; allowed: a number > 0 (1 = the paper's spans)")
    n = max(1, round(days * 86400.0 * scale / unit_s))
    return round(n * unit_s)


# --------------------------------------------------------------------------- planning


@dataclass(frozen=True)
class PlannedRun:
    """A study run resolved for a runs directory: ``spec``; ``scenario_toml``
    (resolved, ``run.output`` = ``path``); ``canonical_toml`` (same with a
    placeholder output, hashed into ``digest``); ``path``; ``done`` (the file
    is already a complete trajectory of this scenario); ``duration_s``."""

    spec: RunSpec
    scenario_toml: str
    canonical_toml: str
    digest: str
    path: Path
    done: bool
    duration_s: float

    @property
    def name(self) -> str:
        return self.spec.name


def run_complete(path, canonical_toml: str) -> bool:
    """True if ``path`` is a complete run of the study scenario
    ``canonical_toml`` (resolved with the studies' ``run.output``
    placeholder): :func:`tqdyn.formats.trajectory.run_is_complete`."""
    from ..formats.trajectory import run_is_complete

    return run_is_complete(path, canonical_toml, _PLACEHOLDER)


def _check_names(studies, catalogue=None) -> tuple[str, ...]:
    catalogue = STUDIES if catalogue is None else catalogue
    if studies is None:
        return tuple(catalogue)
    if isinstance(studies, str):
        studies = (studies,)
    for s in studies:
        if s not in catalogue:
            raise ValueError(unknown("study", s, catalogue, STUDIES_DOC, problem="is not a study"))
    return tuple(studies)


def plan_studies(runs_dir, *, studies: Sequence[str] | None = None, duration_scale: float = 1.0,
                 extra_overrides: Sequence[str] = (), check_data: bool = True,
                 catalogue: Mapping[str, Study] | None = None,
                 runs: Mapping[str, RunSpec] | None = None) -> tuple[PlannedRun, ...]:
    """Resolve the runs of ``studies`` (default: all of :data:`STUDIES`) for ``runs_dir``.

    Every scenario is validated (and, with ``check_data``, its force model's
    data limits checked) before anything runs: bad input raises ValueError /
    FileNotFoundError.  Runs shared by several studies appear once; longest
    first.  Nothing is written.  ``catalogue`` / ``runs``: another study set
    and its runs (default :data:`STUDIES` / :data:`RUNS`; e.g. the LISA set
    of :mod:`tqdyn.workflows.studies_lisa`).
    """
    from .. import dynamics

    catalogue = STUDIES if catalogue is None else catalogue
    runs = RUNS if runs is None else runs
    names = _check_names(studies, catalogue)
    runs_dir = Path(os.path.abspath(os.path.expanduser(os.fspath(runs_dir))))
    wanted: list[str] = []
    for s in names:
        for r in catalogue[s].runs:
            if r not in wanted:
                wanted.append(r)
    planned = []
    for r in wanted:
        spec = runs[r]
        scen = spec.scenario_for(duration_scale=duration_scale, extra=extra_overrides)
        canonical = scen.to_toml()
        digest = hashlib.sha256(canonical.encode("utf-8")).hexdigest()[:_DIGEST_CHARS]
        path = runs_dir / f"{spec.name}-{digest}.h5"
        final = replace(scen, run=replace(scen.run, output=str(path)))
        if check_data and not run_complete(path, canonical):
            dynamics.check_inputs(final)
        planned.append(PlannedRun(spec=spec, scenario_toml=final.to_toml(), canonical_toml=canonical, digest=digest,
                                  path=path, done=run_complete(path, canonical),
                                  duration_s=float(scen.run.duration_s)))
    planned.sort(key=lambda p: -p.duration_s)
    return tuple(planned)


# --------------------------------------------------------------------------- running


@dataclass(frozen=True)
class RunOutcome:
    """What happened to one run: ``status`` "reused" (complete file found),
    "ran" or "failed"; ``error`` one line for failures; ``wall_s`` [s] of the
    propagation (+ compilation); ``rows`` written."""

    run: PlannedRun
    status: str
    error: str = ""
    wall_s: float = 0.0
    rows: int = 0

    @property
    def ok(self) -> bool:
        return self.status != "failed"


@dataclass(frozen=True)
class StudyRuns:
    """Result of :func:`run_studies`: ``studies`` (names), ``outcomes`` per
    run name, ``duration_scale``, ``runs_dir``, ``wall_s`` [s]."""

    studies: tuple[str, ...]
    outcomes: dict = field(default_factory=dict)
    duration_scale: float = 1.0
    runs_dir: Path = Path(".")
    wall_s: float = 0.0

    def path(self, run_name: str) -> Path | None:
        """The trajectory file of a run, or None if it failed / is not planned."""
        o = self.outcomes.get(run_name)
        return o.run.path if o is not None and o.ok else None

    @property
    def failures(self) -> list[RunOutcome]:
        return [o for o in self.outcomes.values() if not o.ok]


def _run_one(scenario_toml: str) -> dict:
    """Task: run one resolved scenario to its file (never raises)."""
    from .run import run_scenario_text

    return run_scenario_text(scenario_toml, source="study run")


def run_studies(runs_dir, *, studies: Sequence[str] | None = None, duration_scale: float = 1.0,
                extra_overrides: Sequence[str] = (), workers: int | None = None,
                progress: Callable[[RunOutcome], None] | None = None,
                plan: Sequence[PlannedRun] | None = None,
                catalogue: Mapping[str, Study] | None = None,
                runs: Mapping[str, RunSpec] | None = None) -> StudyRuns:
    """Run (or reuse) every run the ``studies`` need, in ``runs_dir``.

    studies : names in :data:`STUDIES` (default all); duration_scale : factor
    on the paper's spans (:data:`QUICK_SCALE` for a quick look);
    extra_overrides : overrides applied to every run after its own (e.g.
    ``"forces.earth_degree=2"``); workers : processes of the local Dask
    cluster (default: the usable CPU cores; 1 = run in this process);
    progress : called with each :class:`RunOutcome` (reused ones first).
    plan : the result of :func:`plan_studies` for the same arguments, if
    already computed (skips planning again).  catalogue / runs : another
    study set (as for :func:`plan_studies`).

    Bad input raises ValueError / FileNotFoundError before anything runs; a
    run that fails does not stop the others (see :attr:`StudyRuns.failures`).
    """
    from .run import one_line
    from .sweep.execute import default_workers, run_on_dask

    t0 = time.perf_counter()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers: {workers!r} is not allowed; allowed: an integer >= 1")
    names = _check_names(studies, catalogue)
    if plan is None:
        plan = plan_studies(runs_dir, studies=names, duration_scale=duration_scale, extra_overrides=extra_overrides,
                            catalogue=catalogue, runs=runs)
    runs_dir = Path(os.path.abspath(os.path.expanduser(os.fspath(runs_dir))))
    try:
        runs_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"runs directory: {str(runs_dir)!r} cannot be created ({one_line(exc)}); allowed: a "
                         "writable directory") from None
    outcomes: dict[str, RunOutcome] = {}
    for p in plan:
        if p.done:
            outcomes[p.name] = RunOutcome(p, "reused")
            if progress is not None:
                progress(outcomes[p.name])
    pending = [p for p in plan if not p.done]

    def record(p, res):
        if res["ok"]:
            o = RunOutcome(p, "ran", wall_s=res["wall_s"], rows=res["rows"])
        else:
            o = RunOutcome(p, "failed", error=res["error"])
        outcomes[p.name] = o
        if progress is not None:
            progress(o)

    n = min(workers or default_workers(), len(pending))
    if n <= 1:
        for p in pending:
            record(p, _run_one(p.scenario_toml))
    elif pending:
        run_on_dask(_run_one, pending, lambda p: f"tqdyn-study-{p.name}-{p.digest}", None, n, record)
    ordered = {p.name: outcomes[p.name] for p in plan}
    return StudyRuns(studies=names, outcomes=ordered, duration_scale=float(duration_scale), runs_dir=runs_dir,
                     wall_s=time.perf_counter() - t0)
