"""Micro-benchmarks of the kernels (``tqdyn bench --model kernels``).

What one chunk of the propagator costs, term by term: the time-only inputs
of the built-in ``tianqin`` scenario's full force model (Earth orientation,
ephemerides, tides, the Moon's and the Sun's fields, relativity) at the
instants of one chunk, 4096 DP87 steps of 50 s x 13 stages = 53,248
instants over 2.4 days; the spherical-harmonic acceleration per evaluation
(EGM2008 to degree 12 and 90, compiled loop); the vectorised numpy control
law (:func:`tqdyn.constellation.control.nominal_control`) on 100,000
instants of three satellites.

Each time is the best of ``repeat`` calls after a warm-up call (kernels
compiled, files read); wall-clock seconds of this process.  The Earth
orientation is timed on its own (new instants each call, so its memo does
not answer) and then shared by the terms, as in a run (a term's time is its
work beyond the orientation).
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = ["kernels_benchmark", "format_kernels_report", "CHUNK_STEPS", "CHUNK_STAGES"]

#: Steps of one propagator chunk and stages per DP87 step: 53,248 instants.
CHUNK_STEPS = 4096
CHUNK_STAGES = 13


def _best(fn, repeat: int) -> float:
    """Best wall time [s] of ``repeat`` calls of ``fn(k)`` (k = 1..repeat) after ``fn(0)``."""
    fn(0)
    best = math.inf
    for k in range(1, repeat + 1):
        t0 = time.perf_counter()
        fn(k)
        best = min(best, time.perf_counter() - t0)
    return best


def _sh_loop():
    from numba import njit

    from ..forces.spherical_harmonics import sh_accel

    @njit(cache=False)
    def loop(n, C, S, N, gm, R):  # pragma: no cover - compiled
        s = 0.0
        for i in range(n):
            u = i * 1e-3
            a = sh_accel(1e8 * math.cos(u), 3e7 * math.sin(u), 9e7 * math.sin(u), gm, R, C, S, N)
            s += a[0] + a[1] + a[2]
        return s

    return loop


def kernels_benchmark(repeat: int = 3) -> dict:
    """Run the micro-benchmarks; returns a dict: ``instants``, ``span_s``,
    ``chunk_ms`` (per term and input, best wall time [ms] for one chunk),
    ``sh_accel_us`` (per evaluation [us], by degree), ``nominal_control``
    (instants and wall time [ms])."""
    from .. import dynamics
    from ..astro.earth_orientation import earth_orientation
    from ..astro.timescales import Epoch
    from ..constellation.control import mosa_angular_rates, nominal_control
    from ..readers.gravity_fields import egm2008
    from ..scenario import load_scenario

    scen = load_scenario("tianqin")
    model = dynamics.check_inputs(scen)
    epoch = Epoch.from_utc(scen.epoch_utc)
    n = CHUNK_STEPS * CHUNK_STAGES
    step = float(scen.integrator.step_s)
    t = np.linspace(0.0, CHUNK_STEPS * step, n)
    eop = model.eop
    chunk: dict[str, float] = {}
    for tides, label in ((True, "earth_orientation"), (False, "earth_orientation (no sub-daily EOP terms)")):
        chunk[label] = _best(lambda k, tides=tides: earth_orientation(epoch, t + 1e-3 * k, 0.0, eop,
                                                                      use_eop=eop is not None, tidal_eop=tides),
                             repeat)
    earth_orientation(epoch, t, 0.0, eop, use_eop=eop is not None)  # the terms share it, as in a run
    for term in model.terms:
        if not term.n_tdat:
            continue
        chunk[term.name] = _best(lambda k, term=term: term.precompute(epoch, t, 0.0), repeat)
        for tide in getattr(term, "tides", ()):
            chunk[f"{term.name}: {tide.name}"] = _best(lambda k, tide=tide: tide(epoch, t, 0.0), repeat)
    chunk["all time-only inputs"] = _best(lambda k: model.precompute(epoch, t + 1e-3 * k, 0.0), repeat)

    loop = _sh_loop()
    sh = {}
    for degree, calls in ((12, 50_000), (90, 2_000)):
        m = egm2008(degree)
        sh[str(degree)] = _best(lambda k, m=m, calls=calls, degree=degree: loop(calls, m.C, m.S, degree, m.gm,
                                                                                 m.radius), repeat) / calls * 1e6

    rng = np.random.default_rng(5)
    N = 100_000
    T = np.broadcast_to(np.eye(3), (N, 3, 3, 3))
    w = rng.normal(size=(N, 3, 3)) * 2e-5
    wd = rng.normal(size=(N, 3, 3)) * 1e-12
    th = rng.uniform(1.0, 1.1, size=(N, 3))
    wm, wmd = mosa_angular_rates(rng.normal(size=(N, 3)) * 1e-9, rng.normal(size=(N, 3)) * 1e-14)
    dg = rng.normal(size=(N, 3, 2, 3)) * 1e-10
    control_s = _best(lambda k: nominal_control(T, w, wd, th, wm, wmd, dg), repeat)
    return {"scenario": scen.name, "instants": n, "chunk_steps": CHUNK_STEPS, "stages": CHUNK_STAGES,
            "span_s": CHUNK_STEPS * step, "repeat": repeat,
            "chunk_ms": {k: v * 1e3 for k, v in chunk.items()},
            "chunk_us_per_instant": {k: v / n * 1e6 for k, v in chunk.items()},
            "sh_accel_us": sh,
            "nominal_control": {"instants": N, "wall_ms": control_s * 1e3}}


def format_kernels_report(report: dict) -> str:
    """Human-readable table of a :func:`kernels_benchmark` report."""
    lines = [f"kernels: the time-only inputs of one chunk of the {report['scenario']} scenario "
             f"({report['chunk_steps']} steps x {report['stages']} stages = {report['instants']:,} instants over "
             f"{report['span_s'] / 86400:.2f} d), best of {report['repeat']}",
             f"{'input':<48} {'ms / chunk':>11} {'us / instant':>13}"]
    for k, v in report["chunk_ms"].items():
        lines.append(f"{k:<48} {v:>11.1f} {report['chunk_us_per_instant'][k]:>13.3f}")
    lines.append("sh_accel per evaluation: " + ", ".join(f"degree {d}: {v:.2f} us"
                                                         for d, v in report["sh_accel_us"].items()))
    nc = report["nominal_control"]
    lines.append(f"nominal_control (numpy), {nc['instants']:,} instants x 3 satellites: {nc['wall_ms']:.0f} ms")
    return "\n".join(lines)
