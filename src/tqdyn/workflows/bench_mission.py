"""Benchmarks of whole ``tqdyn run`` commands (``tqdyn bench --model
default-run | tianqin-5y | tianqin-5y-multistep | lisa-10y``).

Each runs the command as a child process in a temporary directory, as a user
would (start-up, JIT cache loading, propagation, output file), and measures
from outside: the wall time of the command, the child's CPU time and peak
resident set (``wait4``), its resident set sampled every
:data:`SAMPLE_S` seconds (to show whether memory grows over the run), the
size of the trajectory file, and, from the command's own summary, the
propagation wall time, the JIT time, the steps and the transcript (the
banner on stderr and the summary on stdout, as the README shows them,
with the temporary directory's path left out of the output line).  A
one-step run of the same command before it compiles and caches the
kernels, so the measured run starts as every run after the first does (a
multistep command: its start-up and two steps).

* ``default-run``: ``tqdyn run``, the README's main job (built-in
  ``tianqin``, 10 days at 50 s, the default integrator);
* ``tianqin-5y``: ``tqdyn run tianqin --duration 1826d --set
  run.output_every=72 --set integrator.method=dp87`` (five years, a row per hour, DP87);
* ``tianqin-5y-multistep``: the same with ``--set integrator.method=multistep``;
* ``lisa-10y``: ``tqdyn run lisa --duration 3653d`` (ten years at 6 h).

:func:`startup_benchmark` (``tqdyn bench --model startup``): ``tqdyn run
--duration 1h`` with each integrator, with an empty kernel cache
(``$TQDYN_CACHE_DIR`` a new directory: the first run after an install or a
change of the sources compiles the kernels) and then again with the cache it
filled; the compilations are clocked inside the command (:func:`compile_clock`).

``duration`` replaces the span (to check the pipeline quickly); the
report records the span that ran.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

__all__ = ["MISSION_RUNS", "MissionRun", "mission_benchmark", "format_mission_report", "startup_benchmark",
           "format_startup_report", "SAMPLE_S", "STARTUP_RUNS", "compile_clock"]

#: Interval of the resident-set samples [s].
SAMPLE_S = 0.5


@dataclass(frozen=True)
class MissionRun:
    """A benchmarked command: ``tqdyn run [scenario] [args]``, the default
    ``duration`` (None: the scenario's own) and what it is."""

    scenario: str | None
    args: tuple
    duration: str | None
    title: str


#: The benchmarked commands by model name.
MISSION_RUNS = {
    "default-run": MissionRun(None, (), None, "tqdyn run: the built-in tianqin scenario, 10 days at 50 s"),
    "tianqin-5y": MissionRun("tianqin", ("--set", "run.output_every=72", "--set", "integrator.method=dp87"), "1826d",
                             "coupled TianQin, five years at 50 s with DP87, a row every 72 steps"),
    "tianqin-5y-multistep": MissionRun("tianqin", ("--set", "run.output_every=72", "--set",
                                                   "integrator.method=multistep"), "1826d",
                                       "coupled TianQin, five years at 50 s with the multistep method, a row every "
                                       "72 steps"),
    "lisa-10y": MissionRun("lisa", (), "3653d", "coupled LISA, ten years at 6 h"),
}

_ENTRY = "import sys; from tqdyn.cli import main; sys.exit(main())"


def _rss_mb(pid: int) -> float | None:
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except (OSError, ValueError):
        return None
    return None


def _parse(stdout: str) -> dict:
    out = {}
    m = re.search(r"steps: (\d+) accepted.*?, (\d+) right-hand-side evaluations", stdout)
    if m:
        out["n_steps"], out["n_rhs"] = int(m.group(1)), int(m.group(2))
    m = re.search(r"wall time: ([0-9.]+) s propagation \(\+ ([0-9.]+) s JIT compilation\)", stdout)
    if m:
        out["propagation_wall_s"], out["compile_s"] = float(m.group(1)), float(m.group(2))
    m = re.search(r"output: .* \((\d+) rows, ([0-9.]+) MB\)", stdout)
    if m:
        out["rows"] = int(m.group(1))
    m = re.search(r"max first correction \|r_C - r_P\| \(component\): ([0-9.eE+-]+) m", stdout)
    if m:  # multistep runs: the largest corrector-minus-predictor position difference [m]
        out["first_correction_r_m"] = float(m.group(1))
    return out


def mission_benchmark(name: str, duration: str | None = None) -> dict:
    """Run the command of :data:`MISSION_RUNS` ``[name]`` once; returns a
    dict (times [s], memory [MB], file size [MB], the transcript).  A
    failing command raises RuntimeError with its last stderr line."""
    import subprocess

    spec = MISSION_RUNS[name]
    duration = duration or spec.duration
    args = ["run"] + ([spec.scenario] if spec.scenario else []) + (["--duration", duration] if duration else []) \
        + list(spec.args)
    shown = "tqdyn " + " ".join(args)
    from ..scenario import load_scenario

    sets = [spec.args[i + 1] for i in range(len(spec.args) - 1) if spec.args[i] == "--set"]
    scen = load_scenario(spec.scenario or "tianqin", ([f"run.duration={duration}"] if duration else []) + sets)
    # warm-up: the same command over a few steps (a multistep run's start-up and first steps), so that the
    # kernels are compiled and cached before the measured run
    n_warm = scen.integrator.order + 2 if scen.integrator.method == "multistep" else 1
    with tempfile.TemporaryDirectory(prefix="tqdyn-bench-") as tmp:
        warm = ["run"] + ([spec.scenario] if spec.scenario else []) + [
            "--duration", f"{n_warm * scen.integrator.step_s}", *spec.args, "--output", "warm-up.h5", "-q"]
        subprocess.run([sys.executable, "-c", _ENTRY, *warm], cwd=tmp, capture_output=True, check=False)
        (Path(tmp) / "warm-up.h5").unlink(missing_ok=True)
        out_f, err_f = Path(tmp) / "stdout.txt", Path(tmp) / "stderr.txt"
        with open(out_f, "w") as so, open(err_f, "w") as se:
            t0 = time.perf_counter()
            proc = subprocess.Popen([sys.executable, "-c", _ENTRY, *args, "-q"], cwd=tmp, stdout=so, stderr=se,
                                    env={**os.environ, "COLUMNS": "200"})
            samples = []
            while True:
                pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
                if pid:
                    break
                rss = _rss_mb(proc.pid)
                if rss is not None:
                    samples.append((time.perf_counter() - t0, rss))
                time.sleep(SAMPLE_S)
            wall = time.perf_counter() - t0
            proc.returncode = os.waitstatus_to_exitcode(status)
        stdout = out_f.read_text().replace(str(Path(tmp).resolve()) + os.sep, "").replace(tmp + os.sep, "")
        stderr = err_f.read_text()
        if proc.returncode != 0:
            last = (stderr.strip().splitlines() or ["no message"])[-1]
            raise RuntimeError(f"{shown} failed (exit {proc.returncode}): {last}")
        files = sorted(Path(tmp).glob("*.h5"))
        file_mb = files[0].stat().st_size / 1e6 if files else None
    parsed = _parse(stdout)
    late = [r for t, r in samples if t >= 0.1 * wall]
    keep = max(1, len(samples) // 200)
    transcript = "\n".join([f"$ {shown}"] + [ln for ln in stderr.splitlines() if ln.startswith("tqdyn ")]
                           + stdout.rstrip("\n").splitlines())
    return {"title": spec.title, "command": shown, "duration_s": float(scen.run.duration_s),
            "step_s": float(scen.integrator.step_s), "wall_s": wall, **parsed,
            "cpu_user_s": usage.ru_utime, "cpu_sys_s": usage.ru_stime, "peak_rss_mb": usage.ru_maxrss / 1024.0,
            "rss_run_min_mb": min(late) if late else None, "rss_run_max_mb": max(late) if late else None,
            "rss_samples": [[round(t, 1), round(r, 1)] for t, r in samples[::keep]],
            "file_mb": file_mb, "transcript": transcript}


def _timed_command(args, cwd, env) -> dict:
    """Run ``tqdyn ARGS`` in ``cwd``: wall time [s], peak resident set [MB], the parsed summary."""
    import subprocess

    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", _ENTRY, *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    out, err = proc.communicate()
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        last = (err.strip().splitlines() or ["no message"])[-1]
        raise RuntimeError(f"tqdyn {' '.join(args)} failed (exit {proc.returncode}): {last}")
    return {"wall_s": wall, **_parse(out)}


#: The start-up benchmark's commands: ``tqdyn run --duration 1h`` with each integrator (the method named, so
#: the record means the same whatever the default method).
STARTUP_RUNS = {"dp87": ("--set", "integrator.method=dp87"), "multistep": ("--set", "integrator.method=multistep")}

#: The child's entry point of the start-up benchmark: the command, with numba's compilations clocked
#: (:func:`compile_clock`) and their totals written to the file named by $TQDYN_BENCH_JIT_LOG.
_STARTUP_ENTRY = ("import json, os, sys\n"
                  "from tqdyn.workflows.bench_mission import compile_clock\n"
                  "from tqdyn.cli import main\n"
                  "with compile_clock() as jit:\n"
                  "    try:\n"
                  "        status = main()\n"
                  "    except SystemExit as exc:\n"
                  "        status = exc.code\n"
                  "with open(os.environ['TQDYN_BENCH_JIT_LOG'], 'w') as f:\n"
                  "    json.dump(jit, f)\n"
                  "sys.exit(status)\n")


@contextlib.contextmanager
def compile_clock():
    """Context manager clocking numba's compilations in this process: yields
    a dict whose keys ``"n"`` (compiled functions, outermost only: a kernel
    compiles what it calls inside its own compilation), ``"wall_s"`` and
    ``"cpu_s"`` (seconds, wall-clock and CPU of the compiling thread) are
    updated as compilations end (numba's "numba:compile" events; loading a
    kernel from the on-disk cache is not a compilation)."""
    from numba.core import event

    totals = {"n": 0, "wall_s": 0.0, "cpu_s": 0.0}
    local = threading.local()

    class _Clock(event.Listener):
        def on_start(self, ev):
            stack = local.__dict__.setdefault("stack", [])
            stack.append((time.perf_counter(), time.thread_time()))

        def on_end(self, ev):
            t0, c0 = local.stack.pop()
            if not local.stack:
                totals["n"] += 1
                totals["wall_s"] += time.perf_counter() - t0
                totals["cpu_s"] += time.thread_time() - c0

    with event.install_listener("numba:compile", _Clock()):
        yield totals


def _cold_run(args, tmp, env) -> dict:
    """``tqdyn ARGS`` in ``tmp`` (its kernel cache in ``env``), run by a fresh helper process so that its
    resource usage is the command's alone: wall time [s], CPU [s], peak resident set [MB], the clocked
    compilations and the parsed summary."""
    import json
    import subprocess

    log = Path(tmp) / "jit.json"
    probe = ("import json, resource, subprocess, sys, time\n"
             "t0 = time.perf_counter()\n"
             f"p = subprocess.run([sys.executable, '-c', {_STARTUP_ENTRY!r}, *{list(args)!r}], capture_output=True, "
             "text=True)\n"
             "u = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
             "print(json.dumps({'wall_s': time.perf_counter() - t0, 'status': p.returncode, 'stdout': p.stdout, "
             "'stderr': p.stderr[-2000:], 'cpu_s': u.ru_utime + u.ru_stime, 'peak_rss_mb': u.ru_maxrss / 1024.0}))\n")
    out = subprocess.run([sys.executable, "-c", probe], cwd=tmp, env={**env, "TQDYN_BENCH_JIT_LOG": str(log)},
                         capture_output=True, text=True)
    shown = "tqdyn " + " ".join(args)
    try:
        run = json.loads(out.stdout)
    except ValueError:
        raise RuntimeError(f"{shown} failed: {out.stderr[-300:]}") from None
    if run["status"] != 0:
        last = (run["stderr"].strip().splitlines() or ["no message"])[-1]
        raise RuntimeError(f"{shown} failed (exit {run['status']}): {last}")
    jit = json.loads(log.read_text())
    return {"wall_s": run["wall_s"], "cpu_s": run["cpu_s"], "peak_rss_mb": run["peak_rss_mb"],
            "jit_n": jit["n"], "jit_wall_s": jit["wall_s"], "jit_cpu_s": jit["cpu_s"], **_parse(run["stdout"])}


def startup_benchmark(duration: str | None = None) -> dict:
    """The first ``tqdyn run`` after an install or a change of the sources:
    ``tqdyn run --duration 1h`` (or ``duration``) with each integrator of
    :data:`STARTUP_RUNS`, each with a new, empty kernel cache
    ($TQDYN_CACHE_DIR a new directory), then again with the cache it
    filled.  Per command: wall time [s], the child's CPU time [s] and peak
    resident set [MB], the JIT time the command reports (``compile_s``:
    compiling or loading the propagation kernels before the propagation),
    and every compilation of the process clocked from inside (``jit_n``
    functions, ``jit_wall_s`` and ``jit_cpu_s`` seconds: also the kernels of
    the time-only inputs, compiled when the inputs are first evaluated).
    The keys ``cold`` and ``warm`` hold the DP87 command's; ``runs`` both."""
    duration = duration or "1h"
    runs = {}
    for name, extra in STARTUP_RUNS.items():
        with tempfile.TemporaryDirectory(prefix="tqdyn-bench-startup-") as tmp:
            env = {**os.environ, "TQDYN_CACHE_DIR": str(Path(tmp) / "cache")}
            args = ["run", "--duration", duration, *extra, "--output", "startup.h5", "-q"]
            cold = _cold_run(args, tmp, env)
            (Path(tmp) / "startup.h5").unlink(missing_ok=True)
            warm = _timed_command(args, tmp, env)
        runs[name] = {"command": "tqdyn " + " ".join(args[:-3]), "cold": cold, "warm": warm}
    first = runs["dp87"]
    return {"command": first["command"], "cold": first["cold"], "warm": first["warm"], "runs": runs}


def format_startup_report(report: dict) -> str:
    """Human-readable lines of a :func:`startup_benchmark` report."""
    lines = []
    for r in report.get("runs", {"dp87": report}).values():
        c, w = r["cold"], r["warm"]
        lines += [f"start-up: {r['command']}",
                  f"  empty kernel cache: {c['wall_s']:.1f} s, CPU {c.get('cpu_s', float('nan')):.1f} s (JIT "
                  f"{c.get('compile_s', float('nan')):.1f} s as the command reports; all compilations "
                  f"{c.get('jit_wall_s', float('nan')):.1f} s, CPU {c.get('jit_cpu_s', float('nan')):.1f} s), peak "
                  f"resident set {c['peak_rss_mb']:.0f} MB",
                  f"  cache filled: {w['wall_s']:.1f} s (JIT {w.get('compile_s', float('nan')):.2f} s)"]
    return "\n".join(lines)


def format_mission_report(report: dict) -> str:
    """Human-readable lines of a :func:`mission_benchmark` report."""
    r = report
    lines = [f"{r['title']}: {r['command']}",
             f"  {r.get('n_steps', '?')} steps, {r['duration_s'] / 86400:g} days; command {r['wall_s']:.1f} s "
             f"(propagation {r.get('propagation_wall_s', float('nan')):.1f} s, JIT {r.get('compile_s', float('nan')):.2f} s); "
             f"CPU {r['cpu_user_s'] + r['cpu_sys_s']:.1f} s",
             f"  peak resident set {r['peak_rss_mb']:.0f} MB"
             + (f"; over the run (after its first 10 %) {r['rss_run_min_mb']:.0f}-{r['rss_run_max_mb']:.0f} MB"
                if r["rss_run_min_mb"] is not None else "")
             + (f"; file {r['file_mb']:.1f} MB ({r.get('rows', '?')} rows)" if r["file_mb"] is not None else "")]
    return "\n".join(lines)
