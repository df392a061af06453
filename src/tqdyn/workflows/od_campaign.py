"""Orbit-determination campaigns on Dask: ``tqdyn od campaign recovery | covariance``.

A campaign is a grid of orbit-determination jobs run as Dask tasks on the sweep's machinery
(:func:`tqdyn.workflows.sweep.execute.run_on_dask`: a new ``distributed.LocalCluster`` by default,
processes of one thread each, or the cluster of a scheduler address), gathered into one
``xarray.Dataset`` written as netCDF-4/HDF5 with Fletcher-32 checksums
(:func:`tqdyn.workflows.sweep.write_sweep_netcdf`):

* ``recovery``: a Monte Carlo over noise seeds.  Each member simulates the tracking plan on the
  *truth* (the scenario with the ``truth`` overrides, e.g. an injected
  ``accelerations.s_frame``) with its seed and fits the scenario itself
  (:func:`tqdyn.workflows.od_memory.simulate`, :func:`~tqdyn.workflows.od_memory.fit`).  Per member:
  the estimate, its sigmas and covariance P, the truth, the fit's chi^2, and the estimate's
  normalised error e^T P^-1 e (e = estimate - truth), which follows a chi-square law with n (the
  number of parameters) degrees of freedom for a correct fit (Tapley, Schutz & Born, "Statistical
  Orbit Determination", 2004, section 4.3); summed over the seeds of a plan, arc and epoch it is the
  campaign's ``error_chi2_sum`` with ``error_chi2_dof`` degrees of freedom and its p-value.
* ``covariance``: the predicted covariance of each tracking plan, arc and epoch (no data).

Grid: tracking plans x arcs x epochs (x seeds), in C order.  Each member's result is a small JSON file
``<output>.parts/<digest>.json`` (the digest: a SHA-256 of the member's job), written atomically by
the task itself: a campaign run again skips every member whose file holds its job (resumable; more
seeds add members), and a member whose worker is lost is re-run by Dask on another worker (the
file is that of the complete run).  Nothing is written before every input is checked (one line).

Units: SI; arcs and intervals [s]; parameters in their own units (m, m/s, m/s^2); epochs UTC.
"""

from __future__ import annotations

import hashlib
import json
import os
import secrets
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .._choices import unknown
from ..formats.stop import check_stop
from . import od as _od

__all__ = ["KINDS", "CampaignMember", "CampaignResult", "CampaignSpec", "gather_campaign", "parse_seeds",
           "plan_campaign", "run_campaign", "run_member"]

KINDS = ("recovery", "covariance")
_SEEDS_ALLOWED = "a count N >= 1 (seeds 0..N-1), a range A-B or a list 1,5,7 of integers >= 0"


def parse_seeds(text, option: str = "--seeds") -> tuple[int, ...]:
    """``"200"`` (seeds 0..199), ``"10-19"``, ``"1,5,7"`` or a sequence of integers -> the seeds
    (distinct, >= 0); ValueError (one line) for none or a malformed one."""
    if text is None:
        raise ValueError(f"{option}: missing; a recovery campaign needs seeds; allowed: {_SEEDS_ALLOWED}")
    try:
        if isinstance(text, str):
            t = text.strip()
            if "," in t:
                seeds = [int(x) for x in t.split(",") if x.strip()]
            elif "-" in t.lstrip("-"):
                a, b = t.split("-", 1)
                seeds = list(range(int(a), int(b) + 1))
            else:
                seeds = list(range(int(t)))
        elif isinstance(text, int) and not isinstance(text, bool):
            seeds = list(range(text))
        else:
            seeds = [int(x) for x in text if not isinstance(x, bool)]
    except (TypeError, ValueError):
        raise ValueError(f"{option}: {text!r} is not allowed; allowed: {_SEEDS_ALLOWED}") from None
    if not seeds:
        raise ValueError(f"{option}: {text!r} gives no seed; allowed: {_SEEDS_ALLOWED}")
    if min(seeds) < 0 or len(set(seeds)) != len(seeds):
        raise ValueError(f"{option}: {text!r} has a negative or repeated seed; allowed: {_SEEDS_ALLOWED}")
    return tuple(seeds)


@dataclass(frozen=True)
class CampaignMember:
    """One job of the grid: its index, its coordinates (plan, arc_s, epoch[, seed]), its job (the JSON
    text the task receives), the digest and its result file."""

    index: int
    coords: tuple
    job: str
    digest: str
    path: Path

    @property
    def label(self) -> str:
        names = ("plan", "arc_s", "epoch", "seed")
        return "member " + ", ".join(f"{n} {v}" for n, v in zip(names, self.coords) if v != "")


@dataclass(frozen=True)
class CampaignSpec:
    """A checked campaign (:func:`plan_campaign`): kind, scenario (name or absolute path), plans
    (tuples of kinds), arcs [s], epochs (UTC ISO text; "" the scenario's own), seeds (recovery),
    truth and common overrides, interval [s] or None, estimate, consider, a_priori, stations, output
    (the netCDF file) and the members."""

    kind: str
    scenario: str
    plans: tuple
    arcs: tuple
    epochs: tuple
    seeds: tuple
    truth: tuple
    overrides: tuple
    interval: float | None
    estimate: tuple
    consider: tuple
    a_priori: dict
    stations: tuple
    output: Path
    members: tuple = field(default=())

    @property
    def parts(self) -> Path:
        """The directory of the members' result files."""
        return self.output.with_name(self.output.name + ".parts")

    def done(self, member: CampaignMember) -> bool:
        """The member's result file exists and holds its job."""
        try:
            return json.loads(member.path.read_text(encoding="utf-8")).get("job") == member.job
        except (OSError, ValueError, AttributeError):
            return False


def _many(values, option: str) -> list:
    items = [values] if isinstance(values, (str, int, float)) else list(values or ())
    if not items:
        raise ValueError(f"{option}: missing; allowed: one or more (repeat the option)")
    return items


def plan_campaign(kind: str, scenario, *, tracking, arc, epoch=(), seeds=None, truth=(), overrides=(),
                  interval=None, estimate=None, consider=None, a_priori=None, stations=None, output) -> CampaignSpec:
    """Check every input and lay out the members (nothing is written).  tracking: one or more plans
    (``"gnss,slr,isr"`` each); arc: one or more arcs (seconds or ``"1d"``); epoch: UTC epochs
    (``"2030-01-01T00:00:00"``; none: the scenario's); seeds: :func:`parse_seeds` (recovery only);
    truth: overrides of the truth (recovery); the other arguments as ``tqdyn od covariance``'s.
    ValueError / FileNotFoundError (one line) otherwise."""
    from ..formats.atomic import check_output

    if kind not in KINDS:
        raise ValueError(unknown("campaign kind", kind, KINDS))
    plans = tuple(_od.parse_tracking(t) for t in _many(tracking, "--tracking"))
    if len(set(plans)) != len(plans):
        raise ValueError("--tracking: a plan is given twice; allowed: distinct plans")
    arcs = tuple(_od.parse_arc(a) for a in _many(arc, "--arc"))
    epochs = tuple(str(e).strip() for e in ([epoch] if isinstance(epoch, str) else list(epoch or ()))) or ("",)
    if kind == "recovery":
        seed_list = parse_seeds(seeds)
    elif seeds is not None:
        raise ValueError("--seeds: a covariance campaign has no seeds; allowed: --seeds with a recovery campaign")
    else:
        seed_list = ()
    truth = tuple(truth or ())
    if truth and kind != "recovery":
        raise ValueError("--truth: a covariance campaign has no truth; allowed: --truth with a recovery campaign")
    interval_s = None if interval is None else _od.parse_arc(interval, "--interval")
    est, con = _od.parse_names(estimate, "--estimate"), _od.parse_names(consider, "--consider")
    sig = _od.parse_a_priori(a_priori)
    _od._check_consider(con, sig)
    st = _od.parse_names(stations, "--stations")
    name = os.path.abspath(scenario) if scenario is not None and os.path.isfile(str(scenario)) else scenario
    out = check_output(output, "--output", {"SCENARIO": name if name and os.path.isfile(str(name)) else None})
    over = tuple(overrides or ())
    for e in epochs:                       # every scenario of the grid loads, every plan is a valid one
        extra = (f'scenario.epoch_utc="{e}"',) if e else ()
        scen = _od._scenario(name, over + extra)[0]
        if truth:
            _od._scenario(name, over + extra + truth)
        for kinds in plans:
            for a in arcs:
                _od._check_arc(scen, a, str(name if name is not None else scen.name))
                _od._tracking(kinds, a, interval_s, est, con, a_priori_sigma=sig or None,
                              **({"stations": st} if st else {}))
    spec = CampaignSpec(kind, name, plans, arcs, epochs, seed_list, truth, over, interval_s, est, con, sig, st,
                        Path(os.path.abspath(out)))
    members = []
    for kinds in plans:
        for a in arcs:
            for e in epochs:
                for s in (seed_list or ("",)):
                    job = {"kind": kind, "scenario": name, "overrides": list(over)
                           + ([f'scenario.epoch_utc="{e}"'] if e else []), "truth": list(truth),
                           "tracking": ",".join(kinds), "arc_s": a, "interval_s": interval_s, "estimate": list(est),
                           "consider": list(con), "a_priori": sig, "stations": list(st), "seed": s}
                    text = json.dumps(job, sort_keys=True)
                    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
                    members.append(CampaignMember(len(members), (",".join(kinds), a, e, s), text, digest,
                                                  spec.parts / f"{digest}.json"))
    return CampaignSpec(**{**spec.__dict__, "members": tuple(members)})


def _result(job: dict) -> dict:
    """The numbers of one member (module docstring)."""
    from scipy import linalg

    from .od_memory import covariance, fit, simulate

    base = list(job["overrides"])
    common = {"interval": job["interval_s"], "stations": job["stations"] or None}
    if job["kind"] == "covariance":
        cov, *_ = covariance(job["scenario"], job["tracking"], job["arc_s"], estimate=job["estimate"],
                             consider=job["consider"], a_priori=job["a_priori"], overrides=base, **common)
        return {"names": list(cov.names), "nominal": cov.values.tolist(), "sigma": cov.sigma.tolist(),
                "consider_sigma": cov.consider_sigma.tolist(), "covariance": cov.covariance.tolist(),
                "condition_number": float(cov.condition_number)}
    s = simulate(job["scenario"], job["tracking"], job["arc_s"], seed=job["seed"], overrides=base + job["truth"],
                 **common)
    fields = {k: np.asarray(getattr(s.meas, k)) for k in ("t", "type", "sat", "peer", "value", "sigma")}
    fields["line"] = np.arange(fields["t"].size)
    f = fit(job["scenario"], fields, s.info, estimate=job["estimate"], consider=job["consider"],
            a_priori=job["a_priori"], overrides=base)
    est = f.estimate
    truth = _od._problem().build_problem(s.scenario, s.meas, f.tracking).estimated
    x_true = np.array([truth.values[truth.names.index(n)] for n in est.names])
    z = (est.values - x_true) / est.sigma            # scaled by the sigmas: P's units span 1e20
    corr = est.covariance / np.outer(est.sigma, est.sigma)
    chi = float(z @ linalg.solve(corr, z, assume_a="pos"))
    return {"names": list(est.names), "estimate": est.values.tolist(), "sigma": est.sigma.tolist(),
            "covariance": est.covariance.tolist(), "truth": x_true.tolist(), "error_chi2": chi,
            "chi2": float(est.chi2), "chi2_dof": int(est.chi2_dof), "iterations": int(est.iterations),
            "measurements": len(s.meas)}


def run_member(task: str) -> dict:
    """Dask task: run one member (``task``: JSON of its job and its result file) and write its result
    file atomically; never raises: {"ok", "error", "wall_s"}, and "no_space" (the one-line
    :class:`~tqdyn.formats.trajectory.OutputIOError`) when its file could not be written for a full
    disk or a file-size limit."""
    from ..formats.atomic import NO_SPACE, replacing
    from ..formats.trajectory import OutputIOError
    from .run import one_line

    t0 = time.perf_counter()
    item = json.loads(task)
    try:
        res = _result(json.loads(item["job"]))
        res["wall_s"] = time.perf_counter() - t0
        with replacing(Path(item["path"]), "the campaign member's result") as tmp:
            tmp.write_text(json.dumps({"job": item["job"], "result": res}), encoding="utf-8")
        return {"ok": True, "error": "", "wall_s": res["wall_s"]}
    except Exception as exc:  # noqa: BLE001 - a failed member is reported, the others go on
        full = isinstance(exc, OutputIOError) or (isinstance(exc, OSError) and exc.errno in NO_SPACE)
        return {"ok": False, "error": one_line(exc), "wall_s": time.perf_counter() - t0,
                **({"no_space": str(exc)} if full else {})}


@dataclass
class CampaignResult:
    """Outcome of :func:`run_campaign`: the spec, per member its status ("done": its file was there,
    "ran", "failed"), error and lost-worker count, the dataset, the file, the wall time [s]."""

    spec: CampaignSpec
    status: list
    errors: list
    lost: list
    dataset: Any = None
    output: Path | None = None
    wall_s: float = 0.0

    @property
    def n_ran(self) -> int:
        return self.status.count("ran")

    @property
    def n_skipped(self) -> int:
        return self.status.count("done")

    @property
    def failures(self) -> list:
        return [(m, e) for m, s, e in zip(self.spec.members, self.status, self.errors) if s == "failed"]

    @property
    def rerun(self) -> list:
        return [m for m, n in zip(self.spec.members, self.lost) if n]


def run_campaign(spec: CampaignSpec, scheduler=None, n_workers: int | None = None,
                 progress: Callable[[CampaignMember, dict], None] | None = None,
                 started: Callable[[Any], None] | None = None, **client_options) -> CampaignResult:
    """Run the members not yet done on Dask (``scheduler``, ``n_workers``, ``client_options`` as
    :func:`tqdyn.workflows.sweep.run_sweep`'s), calling ``progress(member, result)`` as each finishes,
    then gather every member into the dataset and write ``spec.output``.

    A member whose result file could not be written for a full disk stops the campaign: the unfinished
    members are cancelled and :class:`~tqdyn.formats.trajectory.OutputIOError` is raised.  On any
    stop (that, Ctrl-C, a stop signal: :func:`tqdyn.formats.stop.check_stop`) the local cluster is
    closed, the temporary files of unfinished members are removed and the result files of the
    finished ones kept (a run again skips them); ``<output>.parts`` is removed if this run created it
    and it holds none."""
    from ..formats.trajectory import OutputIOError
    from .sweep.execute import dask_client, run_on_dask

    t0 = time.perf_counter()
    n = len(spec.members)
    status = ["done" if spec.done(m) else "" for m in spec.members]
    errors, lost = [""] * n, [0] * n
    pending = [m for m, s in zip(spec.members, status) if not s]
    created = not spec.parts.exists()
    spec.parts.mkdir(parents=True, exist_ok=True)

    def done(m, res):
        if res.get("no_space"):
            raise OutputIOError(res["no_space"])
        status[m.index] = "ran" if res["ok"] else "failed"
        errors[m.index] = res.get("error", "")
        lost[m.index] = int(res.get("lost_workers", 0) or 0)
        if progress is not None:
            progress(m, res)

    try:
        if pending:
            token = secrets.token_hex(4)
            with dask_client(scheduler, n_workers, len(pending), **client_options) as client:
                if started is not None:
                    started(client)
                run_on_dask(run_member, pending, lambda m: f"tqdyn-od-{m.digest}-{token}", client, None, done,
                            argument=lambda m: json.dumps({"job": m.job, "path": str(m.path)}))
        elif started is not None:
            started(None)
        check_stop()
    finally:
        for m in pending:   # temporaries of members a stop or a killed worker interrupted
            for tmp in m.path.parent.glob(f".{m.path.name}.*.tmp"):
                tmp.unlink(missing_ok=True)
        if created and not any(spec.parts.iterdir()):
            spec.parts.rmdir()
    dataset = gather_campaign(spec, status, errors)
    output = None
    if dataset is not None:
        from .sweep import write_sweep_netcdf

        output = write_sweep_netcdf(dataset, spec.output, what="the campaign file")
    return CampaignResult(spec, status, errors, lost, dataset, output, time.perf_counter() - t0)


def gather_campaign(spec: CampaignSpec, status=None, errors=None):
    """The campaign's ``xarray.Dataset`` from the members' result files (None when none succeeded):
    dimensions ``plan``, ``arc`` (coordinate ``arc_s`` [s]), ``epoch`` (UTC; "" the scenario's), for
    a recovery ``seed``, and ``parameter`` / ``parameter_j`` (the union of the members' parameters,
    NaN where a member has none); ``ok`` and ``error`` per member.  Recovery: ``estimate``,
    ``sigma``, ``truth``, ``covariance``, ``error_chi2``, ``chi2``, ``chi2_dof``, ``iterations`` per
    member, and per plan, arc and epoch ``error_chi2_sum``, ``error_chi2_dof``,
    ``error_chi2_pvalue`` (over the members that succeeded).  Covariance: ``nominal``, ``sigma``,
    ``consider_sigma``, ``covariance``, ``condition_number``."""
    import xarray as xr
    from scipy import stats

    results = []
    for m in spec.members:
        try:
            rec = json.loads(m.path.read_text(encoding="utf-8"))
            results.append(rec["result"] if rec.get("job") == m.job else None)
        except (OSError, ValueError, KeyError):
            results.append(None)
    if not any(r is not None for r in results):
        return None
    names = list(dict.fromkeys(n for r in results if r is not None for n in r["names"]))
    recovery = spec.kind == "recovery"
    dims = ("plan", "arc", "epoch") + (("seed",) if recovery else ())
    shape = (len(spec.plans), len(spec.arcs), len(spec.epochs)) + ((len(spec.seeds),) if recovery else ())
    vectors = ("estimate", "sigma", "truth") if recovery else ("nominal", "sigma", "consider_sigma")
    scalars = ("error_chi2", "chi2", "chi2_dof", "iterations", "wall_s") if recovery else \
        ("condition_number", "wall_s")
    arr = {k: np.full(shape + (len(names),), np.nan) for k in vectors}
    arr["covariance"] = np.full(shape + (len(names), len(names)), np.nan)
    arr.update({k: np.full(shape, np.nan) for k in scalars})
    ok = np.zeros(shape, bool)
    err = np.full(shape, "", dtype=object)
    for m, r in zip(spec.members, results):
        idx = np.unravel_index(m.index, shape)
        if errors is not None and errors[m.index]:
            err[idx] = errors[m.index]
        if r is None:
            continue
        ok[idx] = True
        cols = [names.index(n) for n in r["names"]]
        for k in vectors:
            arr[k][idx + (cols,)] = r[k]
        arr["covariance"][idx + np.ix_(cols, cols)] = r["covariance"]
        for k in scalars:
            arr[k][idx] = r[k]
    pdims = ("parameter",)
    data = {k: (dims + pdims, v) for k, v in arr.items() if k in vectors}
    data["covariance"] = (dims + ("parameter", "parameter_j"), arr["covariance"])
    data.update({k: (dims, arr[k]) for k in scalars})
    data["ok"], data["error"] = (dims, ok), (dims, err.astype(str))
    coords = {"plan": [",".join(p) for p in spec.plans], "arc_s": ("arc", np.asarray(spec.arcs)),
              "epoch": list(spec.epochs), "parameter": names, "parameter_j": names,
              "unit": ("parameter", [_od._unit(n) for n in names])}
    if recovery:
        coords["seed"] = list(spec.seeds)
        total = np.where(ok, arr["error_chi2"], 0.0).sum(axis=-1)
        dof = np.where(ok, np.isfinite(arr["estimate"]).sum(axis=-1), 0).sum(axis=-1)
        data["error_chi2_sum"] = (dims[:-1], total)
        data["error_chi2_dof"] = (dims[:-1], dof.astype(np.int64))
        data["error_chi2_pvalue"] = (dims[:-1], np.where(dof > 0, stats.chi2.sf(total, np.maximum(dof, 1)), np.nan))
    attrs = {"campaign": spec.kind, "scenario": str(spec.scenario), "truth": json.dumps(list(spec.truth)),
             "overrides": json.dumps(list(spec.overrides)), "interval_s": np.nan if spec.interval is None else
             spec.interval, "estimate": ",".join(spec.estimate), "consider": ",".join(spec.consider),
             "a_priori": json.dumps(spec.a_priori), "stations": ",".join(spec.stations),
             "members": len(spec.members), "members_ok": int(ok.sum())}
    return xr.Dataset(data, coords=coords, attrs=attrs)
