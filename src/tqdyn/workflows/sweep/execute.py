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
import signal
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...formats import trajectory as io
from ...formats.atomic import same_file
from ...formats.netcdf import netcdf_engine
from .integrity import write_sweep_netcdf
from .gathering import gather
from ..run import one_line
from .outcome import MemberOutcome
from .plan import Member, SweepPlan, plan_sweep
from .spec import SweepSpec, _err

__all__ = ["DEFAULT_CONNECT_TIMEOUT", "DEFAULT_DASHBOARD", "SweepResult", "connect", "dask_client", "default_workers",
           "check_dashboard", "check_output_dir", "make_security", "run_on_dask", "run_sweep"]


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


#: where the local cluster's dashboard listens unless told otherwise (loopback only, random port)
DEFAULT_DASHBOARD = "127.0.0.1:0"
#: seconds to wait for a remote scheduler before giving up (exit 2, nothing written)
DEFAULT_CONNECT_TIMEOUT = 10.0


def make_security(tls_ca_file=None, tls_cert=None, tls_key=None):
    """A ``distributed.security.Security`` for a remote scheduler from
    ``--tls-ca-file`` / ``--tls-cert`` / ``--tls-key`` (client side, encryption
    required), or None when none is given (then Dask's configuration
    ``distributed.comm.tls.*`` applies, as for any ``distributed.Client``).
    Missing or unreadable files raise :class:`SweepError` (one line)."""
    given = {"--tls-ca-file": tls_ca_file, "--tls-cert": tls_cert, "--tls-key": tls_key}
    if all(v is None for v in given.values()):
        return None
    for opt, value in given.items():
        if value is None:
            continue
        path = os.path.abspath(os.path.expanduser(os.fspath(value)))
        if not os.path.isfile(path) or not os.access(path, os.R_OK):
            raise _err(opt, str(value), "is not a readable file", "a PEM file")
    if tls_ca_file is None or tls_cert is None:
        raise _err("--tls-ca-file/--tls-cert", problem="must be given together (and --tls-key unless the "
                   "certificate file holds the key)", allowed="the CA certificate and this client's certificate")
    from distributed.security import Security

    def norm(v):
        return None if v is None else os.path.abspath(os.path.expanduser(os.fspath(v)))

    return Security(tls_ca_file=norm(tls_ca_file), tls_client_cert=norm(tls_cert),
                    tls_client_key=norm(tls_key), require_encryption=True)


def check_dashboard(dashboard):
    """``dashboard`` (HOST:PORT or None) if it is an address; :class:`SweepError` otherwise."""
    if dashboard is None:
        return None
    if not isinstance(dashboard, str) or not dashboard.strip() or ":" not in dashboard:
        raise _err("--dashboard", dashboard, "is not an address", 'HOST:PORT (e.g. 127.0.0.1:8787, port 0: any) or "off"')
    host, _, port = dashboard.rpartition(":")
    if not port.isdigit() or int(port) > 65535:
        raise _err("--dashboard", dashboard, "has no valid port", "HOST:PORT with a port 0..65535")
    return dashboard


def connect(scheduler, *, security=None, timeout: float = DEFAULT_CONNECT_TIMEOUT):
    """A ``distributed.Client`` connected to the scheduler at ``scheduler``
    (waiting at most ``timeout`` s), or :class:`SweepError` (one line)."""
    from distributed import Client

    if not isinstance(scheduler, str) or not scheduler.strip():
        raise _err("scheduler", scheduler, "is not an address", "a Dask scheduler address, e.g. tcp://host:8786")
    if scheduler.startswith("tls://") and security is None:
        import dask

        if not dask.config.get("distributed.comm.tls.ca-file", None):
            raise _err("scheduler", scheduler, "is a tls:// address but no TLS certificates are configured",
                       "--tls-* options, or Dask's distributed.comm.tls configuration")
    kwargs = {} if security is None else {"security": security}
    try:
        return Client(scheduler, timeout=timeout, **kwargs)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        why = "timed out" if "timed out" in str(exc).lower() else one_line(exc)
        raise _err("scheduler", scheduler, f"cannot be reached within {timeout:g} s ({why})",
                   "the address of a running Dask scheduler, e.g. tcp://host:8786") from None


@contextlib.contextmanager
def dask_client(scheduler, n_workers: int | None, n_tasks: int, *, dashboard: str | None = DEFAULT_DASHBOARD,
                security=None, timeout: float = DEFAULT_CONNECT_TIMEOUT):
    """A distributed.Client: the given one, one connected to ``scheduler`` (an
    address; ``security``: a ``distributed.security.Security`` or None for
    Dask's configuration; ``timeout``: seconds to wait for it), or one on a
    new LocalCluster (processes, 1 thread each, at most ``n_workers``
    (default: the usable cores) and at most ``n_tasks`` workers; scheduler on
    127.0.0.1; dashboard at ``dashboard``, default ``127.0.0.1:0`` (loopback,
    any port), None: no dashboard).  The worker processes it starts with ignore Ctrl-C (SIGINT:
    this process takes it and closes the cluster), and its own log lines are silenced up to
    CRITICAL: a worker still sending its heartbeat while an interrupted command closes the cluster
    logs an ERROR with a traceback, which would follow the command's one error line on stderr; what
    fails is reported by the command itself (a failed member's line, a lost worker's note).  Also
    used by :mod:`tqdyn.workflows.studies`."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler is not None:
        with connect(scheduler, security=security, timeout=timeout) as client:
            yield client
        return
    n = default_workers() if n_workers is None else n_workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise _err("workers", n_workers, "is not a positive integer", "an integer >= 1")
    n = min(n, max(n_tasks, 1))
    dashboard = check_dashboard(dashboard)
    # no dashboard: the scheduler still serves its plain HTTP routes (health, metrics): on loopback, any port
    http = {"dashboard": dashboard is not None, "dashboard_address": dashboard or DEFAULT_DASHBOARD}
    # Ctrl-C reaches every process of the terminal's group: the workers must leave it to this process, which
    # closes the cluster (a worker taking it prints a traceback).  SIGINT is ignored while the cluster starts,
    # so the worker processes spawned then inherit SIG_IGN (a signal mask is not inherited through
    # multiprocessing's spawn); a Ctrl-C of that moment (the cluster's start, about a second) is lost.
    main = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                               scheduler_kwargs=http, silence_logs=logging.CRITICAL)
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    with cluster, Client(cluster) as client:
        yield client


def _suspicious(keys, dask_scheduler=None):
    """On the scheduler: how many times each task's worker was lost while it ran."""
    tasks = dask_scheduler.tasks
    return {k: tasks[k].suspicious for k in keys if k in tasks}


def _lost_counts(client, keys) -> dict:
    """Per task key: runs interrupted by a lost worker (scheduler state); {} if
    the scheduler does not run functions for clients."""
    try:
        return client.run_on_scheduler(_suspicious, list(keys))
    except Exception:  # noqa: BLE001 - informative only (e.g. distributed.scheduler.pickle = false)
        return {}


def run_on_dask(task, items: Sequence, key: Callable[[Any], str], scheduler, n_workers: int | None,
                done: Callable[[Any, dict], None], argument: Callable[[Any], Any] | None = None,
                **client_options) -> None:
    """Run ``task(item.scenario_toml)`` (``argument(item)`` when given) for every item as a Dask task (on
    the cluster of :func:`dask_client`, ``client_options`` passed to it) and
    call ``done(item, result)`` as each finishes, in completion order.
    ``task`` is a module-level function returning a result dict (e.g.
    :func:`_run_member`); a task that could not run at all (its worker died
    too often, the cluster went away) gives ``{"ok": False, "error": <one
    line>, "traceback": ""}``.  ``result["lost_workers"]`` is set to the
    number of times the task's worker was lost while running it (Dask then
    re-ran it on another worker; tasks must be idempotent).  ``key(item)``
    names the task.  Unfinished tasks are cancelled when this returns or
    raises."""
    from distributed import as_completed

    with dask_client(scheduler, n_workers, len(items), **client_options) as client:
        arg = argument or (lambda item: item.scenario_toml)
        futures = {client.submit(task, arg(item), key=key(item), pure=False): item for item in items}
        try:
            for fut in as_completed(list(futures)):
                try:
                    res = fut.result()
                except Exception as exc:  # noqa: BLE001 - the task could not run (e.g. its worker died)
                    res = {"ok": False, "error": one_line(exc), "traceback": ""}
                res = dict(res, lost_workers=_lost_counts(client, [fut.key]).get(fut.key, 0))
                item = futures.pop(fut)
                fut.release()  # a finished member is never recomputed if its worker is lost later
                done(item, res)
        finally:
            client.cancel(list(futures))


def _execute(pending: Sequence[Member], client, progress) -> list[MemberOutcome]:
    outcomes: list[MemberOutcome] = []

    def done(m, res):
        lost = int(res.get("lost_workers", 0) or 0)
        if res["ok"]:
            out = MemberOutcome(m, "ran", wall_s=res["wall_s"], compile_s=res["compile_s"], rows=res["rows"],
                                lost_workers=lost)
        else:
            out = MemberOutcome(m, "failed", error=res["error"], traceback=res.get("traceback", ""), lost_workers=lost)
        outcomes.append(out)
        if progress is not None:
            progress(out)

    token = secrets.token_hex(4)
    run_on_dask(_run_member, pending, lambda m: f"tqdyn-member-{m.digest}-{token}", client, None, done)
    return outcomes


def check_output_dir(plan: SweepPlan) -> None:
    """Check, creating nothing, that ``<output_dir>`` is (or can be created
    as) a writable directory and ``<output_dir>/<name>.nc`` can be written
    there, and that neither it nor a member file is one of the sweep's inputs (the sweep file, the
    base scenario file: :func:`tqdyn.formats.atomic.same_file`).  :class:`SweepError` (one line)
    otherwise."""
    out_dir = Path(os.path.abspath(plan.spec.output_dir))
    inputs = {"sweep file": plan.spec.source,
              "sweep.scenario": plan.spec.scenario if os.path.isfile(plan.spec.scenario) else None}
    for path in [plan.spec.output] + [m.path for m in plan.members]:
        for label, src in inputs.items():
            if src is not None and os.path.exists(path) and same_file(path, src):
                raise _err("sweep.output_dir", str(out_dir), f"holds the output {Path(path).name}, which is the "
                           f"{label} {str(src)!r}", "a directory where no output is an input")

    def bad(why):
        return _err("sweep.output_dir", str(out_dir), why, "a directory that can be created and written")

    if out_dir.exists():
        if not out_dir.is_dir():
            raise bad("is not a directory")
        try:
            io.check_writable(plan.spec.output)
        except (OSError, io.OutputError) as exc:
            raise bad(f"is not a writable directory ({one_line(exc)})") from None
        return
    parent = out_dir.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise bad(f"cannot be created: {str(parent)!r} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise bad(f"cannot be created: {str(parent)!r} is not writable")


def _remove_stale_temporaries(plan: SweepPlan) -> int:
    """Remove the hidden temporary files ``.member-<hash>.h5.*.tmp`` that a
    killed worker left behind for this sweep's members (their members have
    finished or failed by now).  Returns how many were removed."""
    n = 0
    for m in plan.members:
        for tmp in m.path.parent.glob(f".{m.path.name}.*.tmp"):
            with contextlib.suppress(OSError):
                tmp.unlink()
                n += 1
    return n


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
    stale_temporaries: int = 0

    @property
    def rerun(self) -> list[MemberOutcome]:
        """Outcomes of the members that Dask re-ran because their worker was lost."""
        return [o for o in self.outcomes if o.lost_workers]

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
              progress: Callable[[MemberOutcome], None] | None = None, *, dashboard: str | None = DEFAULT_DASHBOARD,
              security=None, timeout: float = DEFAULT_CONNECT_TIMEOUT,
              started: Callable[[Any], None] | None = None) -> SweepResult:
    """Run a sweep: validate it, run the members not yet done on Dask, gather
    the results into ``<output_dir>/<name>.nc`` (with HDF5 Fletcher-32
    checksums, see :func:`.integrity.write_sweep_netcdf`).

    Parameters
    ----------
    path_or_spec : a sweep file, a :class:`SweepSpec` or a :class:`SweepPlan`.
    scheduler : None (a new ``distributed.LocalCluster``: processes, 1 thread
        each, ``n_workers`` of them, scheduler and dashboard on 127.0.0.1),
        the address of a running Dask scheduler (``"tcp://host:8786"``,
        ``"tls://host:8786"``; its workers need tqdyn and the output
        directory at the same path), or a ``distributed.Client`` (used, not
        closed).
    n_workers : LocalCluster size (default: the usable CPU cores; never more
        than the members to run).
    progress : called with each :class:`MemberOutcome` as a member finishes.
    dashboard : the LocalCluster's dashboard address (default
        ``127.0.0.1:0``: loopback, any free port); None: no dashboard.
    security : ``distributed.security.Security`` for a remote scheduler
        (:func:`make_security`); None: Dask's configuration.
    timeout : seconds to wait for a remote scheduler.
    started : called once everything is checked and the cluster is
        connected, before anything is created or run, with the Client (None
        if no member needs running).

    Bad input (sweep file, scenarios, output directory, scheduler address
    or an unreachable scheduler, no netCDF engine) raises
    :class:`SweepError` / ``FileNotFoundError`` / ``ImportError`` before
    anything is created or runs.  Member failures do not raise: see
    :attr:`SweepResult.failures`.
    """
    t0 = time.perf_counter()
    plan = path_or_spec if isinstance(path_or_spec, SweepPlan) else plan_sweep(path_or_spec)
    netcdf_engine()
    check_output_dir(plan)
    outcomes = {m.index: MemberOutcome(m, "done") for m, d in zip(plan.members, plan.done) if d}
    n_stale = 0
    with contextlib.ExitStack() as stack:
        client = None
        if plan.pending:
            client = stack.enter_context(dask_client(scheduler, n_workers, len(plan.pending), dashboard=dashboard,
                                                     security=security, timeout=timeout))
        if started is not None:
            started(client)
        out_dir = plan.spec.output_dir
        try:
            out_dir.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise _err("sweep.output_dir", str(out_dir), f"cannot be created ({one_line(exc)})",
                       "a directory that can be created and written") from None
        if plan.pending:
            for o in _execute(plan.pending, client, progress):
                outcomes[o.member.index] = o
            n_stale = _remove_stale_temporaries(plan)
    ordered = [outcomes[m.index] for m in plan.members]
    dataset, ordered = gather(plan, ordered)
    output = write_sweep_netcdf(dataset, plan.spec.output) if dataset is not None else None
    return SweepResult(plan=plan, outcomes=ordered, dataset=dataset, output=output, wall_s=time.perf_counter() - t0,
                       stale_temporaries=n_stale)
