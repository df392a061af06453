"""The closed-loop benchmark (``tqdyn bench --model closed-loop``).

A short coupled TianQin run (2 h at 600 s, made inside the benchmark and not timed) gives the working
point; the three spacecraft's closed loops are then simulated in the time domain for ``duration``
(default 3 days) at ``fs`` (default 4 Hz) and streamed block by block to a closed-loop file
(:func:`tqdyn.workflows.closed_loop.closed_loop_to_file`).

The mission-length budget benchmarks (``tqdyn bench --model closed-loop-budget-90d`` and
``closed-loop-budget-lisa-1y``, :func:`closed_loop_budget_benchmark`): a coupled run of the span (made first
by ``tqdyn run`` in a child process, not timed), then ``tqdyn closed-loop``'s work in this process: the model
(every spacecraft and day), the budget and its file with a 60 s series, timed apart (wall; the process's CPU
time over the three), with the file's size and the process's peak resident memory; then the same file with the
per-source spectra (``--per-source``).  Measured: the wall time of the streamed
time series (noise generation, the discretised loops, the HDF5 writes; the frequency-domain budget,
computed before on a 20-point grid, is reported apart and not included), the samples per second, the
file's size and the process's peak resident memory.
"""

from __future__ import annotations

import os
import resource
import tempfile
import time

__all__ = ["BUDGET_RUNS", "CLOSED_LOOP_DURATION", "closed_loop_benchmark", "closed_loop_budget_benchmark",
           "format_budget_report", "format_closed_loop_report"]

#: Default span of the time series of the benchmark.
CLOSED_LOOP_DURATION = "3d"
_RUN = ["run.duration=2h", "integrator.step=600"]


def closed_loop_benchmark(duration: str | None = None, fs: float = 4.0) -> dict:
    """Run the benchmark (module docstring); returns its report: ``duration_s`` [s], ``fs`` [Hz],
    ``n_sat``, ``n_outputs``, ``n_samples``, ``wall_s`` [s], ``samples_per_s``, ``file_bytes``,
    ``file_mb``, ``peak_rss_mb`` [MB], ``budget_s`` [s] (not in ``wall_s``)."""
    from ..analysis.closed_loop import closed_loop_budget
    from ..scenario import load_scenario
    from .closed_loop import check_closed_loop_inputs, closed_loop_to_file
    from .run import run_to_file

    with tempfile.TemporaryDirectory(prefix="tqdyn-bench-cl-") as d:
        run = os.path.join(d, "run.h5")
        run_to_file(load_scenario("tianqin", [*_RUN, f"run.output={run}"]))
        job = check_closed_loop_inputs(run, os.path.join(d, "cl.h5"), duration=duration or CLOSED_LOOP_DURATION,
                                       fs=fs, seed=0, overrides=["closed_loop.n_freq=20"])
        t0 = time.perf_counter()
        budget = closed_loop_budget(job.model)
        budget_s = time.perf_counter() - t0
        s = closed_loop_to_file(job, budget=budget)
        n_out = len(job.model.loops[0][0][1].time_outputs())
    return {"scenario": "tianqin", "run": "2 h at 600 s (working point; not timed)", "duration_s": job.duration_s,
            "fs": job.fs, "n_sat": s.n_sat, "n_outputs": n_out, "n_samples": s.n_samples,
            "wall_s": s.timeseries_s, "samples_per_s": s.n_samples / s.timeseries_s, "file_bytes": s.size_bytes,
            "file_mb": s.size_bytes / 1e6, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
            "budget_s": budget_s, "n_freq": 20}


def format_closed_loop_report(report: dict) -> str:
    """Human-readable lines of a :func:`closed_loop_benchmark` report."""
    return "\n".join([
        f"closed-loop benchmark: {report['n_sat']} TianQin spacecraft (coupled run {report['run']}), "
        f"{report['duration_s'] / 86400:g} days at {report['fs']:g} Hz ({report['n_samples']:,} samples x "
        f"{report['n_outputs']} outputs per spacecraft), streamed to a closed-loop file",
        f"time series: {report['wall_s']:.2f} s wall ({report['samples_per_s']:,.0f} samples/s); file "
        f"{report['file_mb']:.0f} MB; peak resident memory {report['peak_rss_mb']:.0f} MB",
        f"budget ({report['n_freq']} frequencies, margins; not included): {report['budget_s']:.2f} s"])


#: The mission-length budget benchmarks: name -> (scenario, span, integrator step [s]).
BUDGET_RUNS = {"closed-loop-budget-90d": ("tianqin", "90d", 600), "closed-loop-budget-lisa-1y": ("lisa", "365d", 21600)}
_SERIES_S = 60.0


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def closed_loop_budget_benchmark(name: str, duration: str | None = None) -> dict:
    """Run one of :data:`BUDGET_RUNS` (module docstring); ``duration`` replaces its span.  Returns: ``scenario``,
    ``span_days``, ``n_sat``, ``n_segments``, ``n_freq``, ``model_s``, ``budget_s``, ``write_s``, ``total_s`` [s]
    (wall), ``total_cpu_s`` [s] (the process's CPU time over ``total_s``, all its threads),
    ``file_mb`` (default file: totals, dominant sources, margins; a 60 s series), ``peak_rss_mb`` [MB] after it,
    ``per_source_budget_s``, ``per_source_file_mb``, ``per_source_total_cpu_s`` and ``peak_rss_per_source_mb``
    (with ``--per-source``)."""
    import subprocess
    import sys

    from .closed_loop import check_closed_loop_inputs, closed_loop_to_file

    scenario, span, step = BUDGET_RUNS[name]
    span = duration or span
    with tempfile.TemporaryDirectory(prefix="tqdyn-bench-clb-") as d:
        run = os.path.join(d, "run.h5")
        code = ("import sys; from tqdyn.scenario import load_scenario; from tqdyn.workflows.run import run_to_file; "
                "run_to_file(load_scenario(sys.argv[1], sys.argv[2:]))")
        subprocess.run([sys.executable, "-c", code, scenario, f"run.duration={span}", f"integrator.step={step}",
                        f"run.output={run}"], check=True, capture_output=True)
        t0, c0 = time.perf_counter(), time.process_time()
        job = check_closed_loop_inputs(run, os.path.join(d, "cl.h5"), duration=_SERIES_S)
        t1 = time.perf_counter()
        s = closed_loop_to_file(job)
        t2, c2 = time.perf_counter(), time.process_time()
        rss = _rss_mb()
        job_ps = check_closed_loop_inputs(run, os.path.join(d, "cl-per-source.h5"), duration=_SERIES_S,
                                          per_source=True)
        s_ps = closed_loop_to_file(job_ps)
        c3 = time.process_time()
        n_seg = len(job.model.loops[0])
    return {"scenario": scenario, "span_days": job.model.t_span[1] / 86400.0, "run_step_s": step,
            "n_sat": s.n_sat, "n_segments": n_seg, "n_freq": job.model.settings["n_freq"],
            "model_s": t1 - t0, "budget_s": s.budget_s, "write_s": (t2 - t1) - s.budget_s, "total_s": t2 - t0,
            "total_cpu_s": c2 - c0, "per_source_total_cpu_s": c3 - c2,
            "file_bytes": s.size_bytes, "file_mb": s.size_bytes / 1e6, "series_s": _SERIES_S, "peak_rss_mb": rss,
            "per_source_budget_s": s_ps.budget_s, "per_source_file_mb": s_ps.size_bytes / 1e6,
            "peak_rss_per_source_mb": _rss_mb(), "load_average": list(os.getloadavg())}


def format_budget_report(report: dict) -> str:
    """Human-readable lines of a :func:`closed_loop_budget_benchmark` report."""
    r = report
    return "\n".join([
        f"closed-loop budget benchmark: {r['scenario']}, {r['span_days']:g} days ({r['n_sat']} spacecraft x "
        f"{r['n_segments']} segments, {r['n_freq']} frequencies; coupled run at {r['run_step_s']:g} s, not timed)",
        f"model {r['model_s']:.1f} s, budget {r['budget_s']:.1f} s, file {r['write_s']:.1f} s: {r['total_s']:.1f} s "
        f"({r['total_cpu_s']:.1f} s CPU); "
        f"file {r['file_mb']:.1f} MB ({r['series_s']:g} s series); peak resident memory {r['peak_rss_mb']:.0f} MB",
        f"with --per-source: budget {r['per_source_budget_s']:.1f} s, file {r['per_source_file_mb']:.1f} MB, peak "
        f"{r['peak_rss_per_source_mb']:.0f} MB; load average {', '.join(f'{x:.1f}' for x in r['load_average'])}"])
