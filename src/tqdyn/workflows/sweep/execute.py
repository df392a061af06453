"""Running a sweep: its members as Dask tasks and the whole sweep (:func:`run_sweep`).

Members run as Dask tasks (one task = one :func:`tqdyn.workflows.run.run_to_file`,
quiet, no checkpoint) on a new ``distributed.LocalCluster`` (processes, 1
thread each) or on an existing cluster given by its scheduler address.  The
task function :func:`_run_member` lives here, at module level: Dask pickles it
by module path for the workers.  A member that raises does not stop the
others.  :func:`run_sweep` then gathers the members (:mod:`.gathering`) and
writes the netCDF file (:mod:`tqdyn.formats.netcdf`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import secrets
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...formats import trajectory as io
from ...formats.netcdf import netcdf_engine, write_netcdf
from .gathering import gather
from ..run import one_line
from .outcome import MemberOutcome
from .plan import Member, SweepPlan, plan_sweep
from .spec import SweepSpec, _err

__all__ = ["SweepResult", "dask_client", "default_workers", "run_on_dask", "run_sweep"]


def _run_member(scenario_toml: str) -> dict:
    """Dask task: run one member (its resolved scenario TOML) to its file
    (:func:`tqdyn.workflows.run.run_scenario_text`: never raises)."""
    from ..run import run_scenario_text

    return run_scenario_text(scenario_toml, source="sweep member")


def default_workers() -> int:
    """Default size of the local cluster: the CPU cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def dask_client(scheduler, n_workers: int | None, n_tasks: int):
    """A distributed.Client: the given one, one connected to ``scheduler`` (an
    address), or one on a new LocalCluster (processes, 1 thread each, at most
    ``n_workers`` (default: the usable cores) and at most ``n_tasks``
    workers).  Also used by :mod:`tqdyn.workflows.studies`."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler is not None:
        if not isinstance(scheduler, str) or not scheduler.strip():
            raise _err("scheduler", scheduler, "is not an address", "a Dask scheduler address, e.g. tcp://host:8786")
        try:
            client = Client(scheduler)  # timeout: dask config distributed.comm.timeouts.connect
        except (OSError, TimeoutError, ValueError) as exc:
            raise _err("scheduler", scheduler, f"cannot be reached ({one_line(exc)})",
                       "the address of a running Dask scheduler, e.g. tcp://host:8786") from None
        with client:
            yield client
        return
    n = default_workers() if n_workers is None else n_workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise _err("workers", n_workers, "is not a positive integer", "an integer >= 1")
    n = min(n, max(n_tasks, 1))
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        yield client


def run_on_dask(task, items: Sequence, key: Callable[[Any], str], scheduler, n_workers: int | None,
                done: Callable[[Any, dict], None]) -> None:
    """Run ``task(item.scenario_toml)`` for every item as a Dask task (on
    the cluster of :func:`dask_client`) and call ``done(item, result)`` as
    each finishes, in completion order.  ``task`` is a module-level function
    returning a result dict (e.g. :func:`_run_member`); a task that could not
    run at all (its worker died, the cluster went away) gives ``{"ok":
    False, "error": <one line>, "traceback": ""}``.  ``key(item)`` names the
    task.  Unfinished tasks are cancelled when this returns or raises."""
    from distributed import as_completed

    with dask_client(scheduler, n_workers, len(items)) as client:
        futures = {client.submit(task, item.scenario_toml, key=key(item), pure=False): item for item in items}
        try:
            for fut in as_completed(list(futures)):
                try:
                    res = fut.result()
                except Exception as exc:  # noqa: BLE001 - the task could not run (e.g. its worker died)
                    res = {"ok": False, "error": one_line(exc), "traceback": ""}
                done(futures[fut], res)
        finally:
            client.cancel(list(futures))


def _execute(pending: Sequence[Member], scheduler, n_workers, progress) -> list[MemberOutcome]:
    outcomes: list[MemberOutcome] = []

    def done(m, res):
        if res["ok"]:
            out = MemberOutcome(m, "ran", wall_s=res["wall_s"], compile_s=res["compile_s"], rows=res["rows"])
        else:
            out = MemberOutcome(m, "failed", error=res["error"], traceback=res.get("traceback", ""))
        outcomes.append(out)
        if progress is not None:
            progress(out)

    token = secrets.token_hex(4)
    run_on_dask(_run_member, pending, lambda m: f"tqdyn-member-{m.digest}-{token}", scheduler, n_workers, done)
    return outcomes


# --------------------------------------------------------------------------- the whole sweep


@dataclass
class SweepResult:
    """Outcome of :func:`run_sweep`.

    ``plan``: the resolved sweep; ``outcomes``: one :class:`MemberOutcome`
    per member, in member order; ``dataset``: the gathered
    ``xarray.Dataset`` (None if no member succeeded); ``output``: the
    written netCDF file (None if none); ``wall_s``: wall time [s].
    """

    plan: SweepPlan
    outcomes: list[MemberOutcome]
    dataset: Any = None
    output: Path | None = None
    wall_s: float = 0.0

    @property
    def failures(self) -> list[MemberOutcome]:
        """Outcomes of the members that failed."""
        return [o for o in self.outcomes if not o.ok]

    @property
    def files(self) -> list[Path]:
        """Trajectory files of the members that succeeded, in member order."""
        return [o.member.path for o in self.outcomes if o.ok]

    @property
    def n_skipped(self) -> int:
        """Members whose file was already complete."""
        return sum(o.status == "done" for o in self.outcomes)

    @property
    def n_ran(self) -> int:
        """Members run now and successful."""
        return sum(o.status == "ran" for o in self.outcomes)


def run_sweep(path_or_spec: str | os.PathLike | SweepSpec | SweepPlan, scheduler=None, n_workers: int | None = None,
              progress: Callable[[MemberOutcome], None] | None = None) -> SweepResult:
    """Run a sweep: validate it, run the members not yet done on Dask, gather
    the results into ``<output_dir>/<name>.nc``.

    Parameters
    ----------
    path_or_spec : a sweep file, a :class:`SweepSpec` or a :class:`SweepPlan`.
    scheduler : None (a new ``distributed.LocalCluster``: processes, 1 thread
        each, ``n_workers`` of them), the address of a running Dask scheduler
        (``"tcp://host:8786"``; its workers need tqdyn and the output
        directory at the same path), or a ``distributed.Client`` (used, not
        closed).
    n_workers : LocalCluster size (default: the usable CPU cores; never more
        than the members to run).
    progress : called with each :class:`MemberOutcome` as a member finishes.

    Bad input (sweep file, scenarios, scheduler address, no netCDF engine)
    raises :class:`SweepError` / ``FileNotFoundError`` / ``ImportError``
    before anything runs.  Member failures do not raise: see
    :attr:`SweepResult.failures`.
    """
    t0 = time.perf_counter()
    plan = path_or_spec if isinstance(path_or_spec, SweepPlan) else plan_sweep(path_or_spec)
    netcdf_engine()
    out_dir = plan.spec.output_dir
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        io.check_writable(plan.spec.output)
    except (OSError, io.OutputError) as exc:
        raise _err("sweep.output_dir", str(out_dir), f"is not a writable directory ({one_line(exc)})",
                   "a directory that can be created and written") from None
    outcomes = {m.index: MemberOutcome(m, "done") for m, d in zip(plan.members, plan.done) if d}
    if plan.pending:
        for o in _execute(plan.pending, scheduler, n_workers, progress):
            outcomes[o.member.index] = o
    ordered = [outcomes[m.index] for m in plan.members]
    dataset, ordered = gather(plan, ordered)
    output = write_netcdf(dataset, plan.spec.output) if dataset is not None else None
    return SweepResult(plan=plan, outcomes=ordered, dataset=dataset, output=output, wall_s=time.perf_counter() - t0)
