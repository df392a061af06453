"""The closed-loop benchmark (``tqdyn bench --model closed-loop``).

A short coupled TianQin run (2 h at 600 s, made inside the benchmark and not timed) gives the working
point; the three spacecraft's closed loops are then simulated in the time domain for ``duration``
(default 3 days) at ``fs`` (default 4 Hz) and streamed block by block to a closed-loop file
(:func:`tqdyn.workflows.closed_loop.closed_loop_to_file`).  Measured: the wall time of the streamed
time series (noise generation, the discretised loops, the HDF5 writes; the frequency-domain budget,
computed before on a 20-point grid, is reported apart and not included), the samples per second, the
file's size and the process's peak resident memory.
"""

from __future__ import annotations

import os
import resource
import tempfile
import time

__all__ = ["CLOSED_LOOP_DURATION", "closed_loop_benchmark", "format_closed_loop_report"]

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
