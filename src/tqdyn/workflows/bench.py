"""Performance benchmarks (``tqdyn bench``, ``benchmarks/``).

Kepler benchmark: the three TianQin satellites (Table I elements) around an
Earth point mass (GM = 3.986004415e14 m^3/s^2), 90 days at 50 s by default,
propagated by

* tqdyn, double-double (dd) mode,
* tqdyn, float64 mode (the same code compiled for float64),
* tqdyn, dd mode at half the step (shows the DP87 truncation error of the
  50 s step: at 50 s it dominates the dd rounding after 90 days),
* heyoka's Taylor integrator in real128 (optional dependency), producing the
  states on the same grid with ``propagate_grid``,

each in one process, after JIT compilation (compile time reported apart).
The tqdyn runs of this benchmark, of the force-model benchmark (beside heyoka)
and the DP87 rows of the coupled one integrate with DP87 (:data:`DP87`,
whatever the default method): they measure that method against its peers;
the LISA benchmarks run the scenarios as ``tqdyn run`` does (the default
method).
All three are scored against the analytic two-body solution (mpmath, 50
digits) at the final time, and dd is compared with heyoka directly.

LISA benchmark (:func:`lisa_benchmark`): the built-in heliocentric ``lisa``
scenario (ESA's CReMA 2.0 orbits, Sun + Earth + Moon + planetary
barycentres from DE421, the self-gravity ramp toward the centre), 10 years
at its fixed 6 h step by default, in dd and float64.
"""

from __future__ import annotations

import platform
import resource
import time

import mpmath
import numpy as np

from ..astro import elements as _el
from .. import dynamics
from ..numerics.dd import mp_from_dd
from ..scenario import load_scenario
from .numbers import machine

__all__ = ["kepler_benchmark", "format_report", "force_model_benchmark", "format_force_report",
           "coupled_benchmark", "format_coupled_report", "lisa_benchmark", "format_lisa_report", "LISA_DURATION",
           "LISA_COUPLED_DURATION"]

#: Default span of the LISA benchmark: 10 years (14,610 steps of 6 h).
LISA_DURATION = "3652.5d"
#: Span of the coupled LISA benchmark (``tqdyn bench --model lisa-coupled``): one year.
LISA_COUPLED_DURATION = "365d"

#: The override of the runs that measure DP87 (module docstring).
DP87 = ["integrator.method=dp87"]

#: Pure-gravity constellation (no attitude, no drag-free control).
PURE_GRAVITY = ["constellation.pointing=none", "constellation.control=off"]

#: The reduced model of the heyoka comparison: Earth 12x12 + Sun + Moon
#: (point masses), no EOP (heyoka's Earth rotation has none).
REDUCED = ["forces.earth_degree=12", "forces.third_bodies=sun,moon", "forces.solid_tides=false",
           "forces.ocean_tides_degree=0", "forces.pole_tides=false", "forces.atmospheric_tides=false",
           "forces.moon_degree=0", "forces.sun_j2=false",
           "forces.relativity=false", "forces.earth_field_indirect=false", "forces.eop=false",
           "constellation.pointing=none", "constellation.control=off"]


def _analytic_final(scenario) -> np.ndarray:
    """(n_sat, 3) object array: analytic final positions [m] (mpmath)."""
    gm = scenario.forces.gm_earth
    t = scenario.run.duration_s
    out = []
    with mpmath.workdps(50):
        for s in scenario.satellites:
            r, _ = _el.kepler_state_at(s.a_m, s.e, _el.deg(s.i_deg), _el.deg(s.raan_deg), _el.deg(s.argp_deg),
                                       _el.deg(s.nu_deg), gm, t)
            out.append(r)
    return np.array(out, dtype=object)


def _max_dist(a, b) -> float:
    """Largest Euclidean distance [m] between rows of two (n, 3) exact arrays."""
    with mpmath.workdps(50):
        return max(float(mpmath.sqrt(sum((x - y) ** 2 for x, y in zip(ra, rb)))) for ra, rb in zip(a, b))


def kepler_benchmark(duration: str = "90d", step: str = "50", heyoka: bool = True) -> dict:
    """Run the Kepler benchmark; returns a dict of results (wall times [s],
    errors [m] vs the analytic solution, dd-vs-heyoka difference [m])."""
    scen = load_scenario("tianqin-kepler", [f"run.duration={duration}", f"integrator.step={step}", *DP87])
    ref = _analytic_final(scen)
    report = {"scenario": scen.name, "n_sat": len(scen.satellites), "duration_s": float(scen.run.duration_s),
              "step_s": float(scen.integrator.step_s), "n_steps": scen.n_steps,
              "machine": f"{machine()['summary']}, Python {platform.python_version()}",
              "runs": {}}
    finals = {}
    half = load_scenario("tianqin-kepler", [f"run.duration={duration}",
                                            f"integrator.step={scen.integrator.step_s / 2}", *DP87])
    for name, precision, sc in (("dd", "dd", scen), ("float64", "float64", scen), ("dd h/2", "dd", half)):
        model = dynamics.check_inputs(sc)
        t0 = time.perf_counter()
        dynamics.warm_up(precision, cpar=dynamics.build_system(sc, model).cpar, model=model)
        compile_s = time.perf_counter() - t0
        rows = []
        res = dynamics.propagate(sc, precision=precision, sink=rows.append)
        r_final = mp_from_dd(res.y_final[:, 0:3, :])
        finals[name] = r_final
        report["runs"][f"tqdyn {name}"] = {
            "wall_s": res.wall_s, "compile_s": compile_s, "us_per_step": res.wall_s / res.n_steps * 1e6,
            "steps_per_s": res.n_steps / res.wall_s,
            "err_vs_analytic_m": _max_dist(r_final, ref),
            "grid_rows": int(sum(len(r) for r in rows)),
        }
    if heyoka:
        try:
            from ..peers import heyoka as _heyoka_peer
            y0 = dynamics.initial_state(scen)
            out = _heyoka_peer.propagate_kepler_grid(
                (y0[:, 0:3, 0], y0[:, 0:3, 1]), (y0[:, 3:6, 0], y0[:, 3:6, 1]), str(scen.forces.gm_earth),
                float(scen.integrator.step_s), scen.n_steps)
        except ImportError as exc:
            report["heyoka"] = f"skipped: {exc}"
        else:
            r_final = mp_from_dd(np.stack([out["r_hi"][-1], out["r_lo"][-1]], axis=-1))
            report["runs"]["heyoka real128"] = {
                "wall_s": out["wall_s"], "compile_s": out["setup_s"],
                "us_per_step": out["wall_s"] / scen.n_steps * 1e6,
                "err_vs_analytic_m": _max_dist(r_final, ref),
                "grid_rows": int(out["r_hi"].shape[0]),
            }
            report["dd_minus_heyoka_m"] = _max_dist(finals["dd"], r_final)
    runs = report["runs"]
    report["dd_over_float64"] = runs["tqdyn dd"]["wall_s"] / runs["tqdyn float64"]["wall_s"]
    if "heyoka real128" in runs:
        hey = runs["heyoka real128"]
        report["heyoka_over_dd"] = hey["wall_s"] / runs["tqdyn dd"]["wall_s"]
        report["heyoka_over_dd_half_step"] = hey["wall_s"] / runs["tqdyn dd h/2"]["wall_s"]
        report["dd_error_over_heyoka"] = runs["tqdyn dd"]["err_vs_analytic_m"] / hey["err_vs_analytic_m"]
        report["dd_half_step_error_over_heyoka"] = runs["tqdyn dd h/2"]["err_vs_analytic_m"] / hey["err_vs_analytic_m"]
    report["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return report


def format_report(report: dict) -> str:
    """Human-readable table of a :func:`kepler_benchmark` report."""
    lines = [
        f"Kepler benchmark: {report['n_sat']} satellites ({report['scenario']}), Earth monopole, "
        f"{report['duration_s'] / 86400:g} days at {report['step_s']:g} s ({report['n_steps']} steps), "
        f"states on every grid point",
        f"machine: {report['machine']}",
        f"{'run':<16} {'wall [s]':>9} {'us/step':>9} {'compile [s]':>12} {'final error vs analytic [m]':>28}",
    ]
    for name, r in report["runs"].items():
        lines.append(f"{name:<16} {r['wall_s']:>9.3f} {r['us_per_step']:>9.2f} {r['compile_s']:>12.2f} "
                     f"{r['err_vs_analytic_m']:>28.2e}")
    lines.append(f"dd / float64 wall-time ratio: {report['dd_over_float64']:.2f}")
    if "heyoka_over_dd" in report:
        lines.append(f"heyoka real128 / dd wall-time ratio: {report['heyoka_over_dd']:.2f}; "
                     f"final-position difference dd - heyoka: {report['dd_minus_heyoka_m']:.2e} m")
    elif "heyoka" in report:
        lines.append(f"heyoka real128: {report['heyoka']}")
    lines.append(f"peak resident memory: {report['peak_rss_mb']:.0f} MB")
    return "\n".join(lines)


def _timed_run(scen, precision):
    """Propagate after a short warm-up (JIT, data files, caches: one step,
    or for the multistep method its DP87 start-up and two steps); wall
    time [s], peak resident memory of the process so far [MB], result."""
    import dataclasses

    model = dynamics.check_inputs(scen)
    warm = scen.integrator.order + 2 if scen.integrator.method == "multistep" else 1
    short = dataclasses.replace(scen, run=dataclasses.replace(
        scen.run, duration_s=scen.integrator.step_s * min(warm, scen.n_steps)))
    dynamics.propagate(short, precision=precision, model=model)
    t0 = time.perf_counter()
    res = dynamics.propagate(scen, precision=precision, model=model)
    wall = time.perf_counter() - t0
    return wall, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, res


def force_model_benchmark(duration: str = "90d", heyoka: bool = True) -> dict:
    """Full force model (tianqin scenario, pure gravity) in dd and float64, and the
    reduced model (Earth 12x12 + Sun + Moon) in dd beside heyoka real128
    (EGM2008 12x12 + ELP2000 + VSOP2013) when available; wall times [s]
    (including the per-chunk time-only inputs), peak memory [MB]."""
    report = {"duration_s": None, "runs": {}}
    full = load_scenario("tianqin", [f"run.duration={duration}"] + PURE_GRAVITY + DP87)
    reduced = load_scenario("tianqin", [f"run.duration={duration}"] + REDUCED + DP87)
    report["duration_s"] = float(full.run.duration_s)
    report["n_steps"] = full.n_steps
    for name, scen, precision in (("full model, dd", full, "dd"), ("full model, float64", full, "float64"),
                                  ("reduced model, dd", reduced, "dd")):
        wall, rss, res = _timed_run(scen, precision)
        report["runs"][name] = {"wall_s": wall, "peak_rss_mb": rss, "steps_per_s": res.n_steps / wall}
        if name == "reduced model, dd":
            report["reduced_final"] = res.y_final
    if heyoka:
        try:
            from ..peers import heyoka as _heyoka_peer
            peer = getattr(_heyoka_peer, "propagate_reduced_grid")
        except (ImportError, AttributeError) as exc:
            report["heyoka"] = f"skipped: {exc}"
        else:
            from ..astro.timescales import Epoch

            y0 = dynamics.initial_state(reduced)
            out = peer((y0[:, 0:3, 0], y0[:, 0:3, 1]), (y0[:, 3:6, 0], y0[:, 3:6, 1]),
                       Epoch.from_utc(reduced.epoch_utc).tdb, float(reduced.integrator.step_s), reduced.n_steps)
            r_final = mp_from_dd(np.stack([out["r_hi"][-1], out["r_lo"][-1]], axis=-1))
            report["runs"]["reduced model, heyoka real128"] = {
                "wall_s": out["wall_s"], "compile_s": out["setup_s"],
                "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}
            report["reduced_dd_minus_heyoka_m"] = _max_dist(mp_from_dd(report["reduced_final"][:, 0:3]), r_final)
            report["heyoka_over_reduced_dd"] = (report["runs"]["reduced model, heyoka real128"]["wall_s"]
                                                / report["runs"]["reduced model, dd"]["wall_s"])
    report.pop("reduced_final", None)
    report["dd_over_float64"] = report["runs"]["full model, dd"]["wall_s"] / report["runs"]["full model, float64"]["wall_s"]
    return report


def format_force_report(report: dict) -> str:
    """Human-readable table of a :func:`force_model_benchmark` report."""
    lines = [f"force-model benchmark: 3 TianQin satellites, {report['duration_s'] / 86400:g} days at 50 s "
             f"({report['n_steps']} steps), after compilation",
             f"{'run':<32} {'wall [s]':>9} {'peak RSS [MB]':>14}"]
    for name, r in report["runs"].items():
        lines.append(f"{name:<32} {r['wall_s']:>9.2f} {r['peak_rss_mb']:>14.0f}")
    runs = report["runs"]
    if "reduced model, heyoka real128" in runs:
        ratio = runs["reduced model, heyoka real128"]["wall_s"] / runs["reduced model, dd"]["wall_s"]
        lines.append(f"heyoka real128 / tqdyn dd (reduced model): {ratio:.2f}; final positions differ by "
                     f"{report['reduced_dd_minus_heyoka_m']:.2e} m (ELP2000/VSOP2013 vs DE421, Earth rotation models)")
    elif "heyoka" in report:
        lines.append(f"heyoka: {report['heyoka']}")
    return "\n".join(lines)


#: The multistep runs of the coupled benchmark (the method's default order and corrector).
MULTISTEP = ["integrator.method=multistep"]


def coupled_benchmark(duration: str = "90d", overrides=()) -> dict:
    """The full coupled run (built-in ``tianqin``: full force model, global
    pointing, drag-free control, Table IV self-gravity) in dd and in float64,
    with DP87 and with the multistep method: wall time of the propagation [s]
    (time-only inputs included, JIT compilation excluded), peak resident
    memory [MB] of the process (no output file: the trajectory rows are not
    formed), the CPU time of the time-only inputs and of the compiled loop,
    and the process's CPU time.  The same satellites under the same force
    model without attitude, TMs or control (``tianqin-gravity``, dd) give
    the CPU the coupled DP87 run cannot go below: on two cores its wall time
    is at least half of that run's inputs + loop, whatever the coupling
    costs.  The machine's yardstick, the Kepler run of the same span and
    step in float64 (DP87), runs first and last, and its mean divides the
    other runs' wall times (``*_over_kepler_float64``): the ratios are
    robust to a machine whose load changes during the benchmark.  The
    coupled dd run with ``constellation.tm_gravity = "direct"`` (the whole
    force model again at each electrode-housing centre) shows what the
    differential gravity saves."""
    scen = load_scenario("tianqin", [f"run.duration={duration}", *DP87, *overrides])
    multistep = load_scenario("tianqin", [f"run.duration={duration}", *overrides, *MULTISTEP])
    report = {"duration_s": float(scen.run.duration_s), "n_steps": scen.n_steps, "runs": {},
              "multistep": f"order {multistep.integrator.order}, {multistep.integrator.corrector}"}
    gravity = load_scenario("tianqin-gravity", [f"run.duration={duration}", *DP87, *overrides])
    direct = load_scenario("tianqin", [f"run.duration={duration}", *DP87, *overrides,
                                       'constellation.tm_gravity="direct"'])
    kepler = load_scenario("tianqin-kepler", [f"run.duration={duration}", f"integrator.step={scen.integrator.step_s}",
                                              *DP87])
    yardstick = [_timed_run(kepler, "float64")[0]]
    for name, sc, precision in (("coupled, dd, multistep", multistep, "dd"), ("coupled, dd", scen, "dd"),
                                ("coupled, float64, multistep", multistep, "float64"),
                                ("coupled, float64", scen, "float64"), ("gravity only, dd", gravity, "dd"),
                                ("coupled, dd, tm_gravity direct", direct, "dd")):
        wall, rss, res = _timed_run(sc, precision)
        report["runs"][name] = {"wall_s": wall, "peak_rss_mb": rss, "cpu_inputs_s": res.cpu_inputs_s,
                                "cpu_loop_s": res.cpu_loop_s, "cpu_process_s": res.cpu_process_s,
                                "n_rhs": res.n_rhs, "steps_per_s": res.n_steps / wall}
    yardstick.append(_timed_run(kepler, "float64")[0])
    report["kepler_float64_runs_s"] = yardstick
    report["kepler_float64_s"] = k = sum(yardstick) / len(yardstick)
    days = report["duration_s"] / 86400
    runs = report["runs"]
    for r in runs.values():
        r["cpu_inputs_per_day_s"] = r["cpu_inputs_s"] / days
        r["cpu_loop_per_day_s"] = r["cpu_loop_s"] / days
        r["floor_2core_s"] = 0.5 * (r["cpu_inputs_s"] + r["cpu_loop_s"])
    report["dd_over_float64"] = runs["coupled, dd"]["wall_s"] / runs["coupled, float64"]["wall_s"]
    report["dd_over_kepler_float64"] = runs["coupled, dd"]["wall_s"] / k
    report["multistep_dd_over_kepler_float64"] = runs["coupled, dd, multistep"]["wall_s"] / k
    report["dp87_over_multistep_dd"] = runs["coupled, dd"]["wall_s"] / runs["coupled, dd, multistep"]["wall_s"]
    report["direct_over_differential_loop"] = (runs["coupled, dd, tm_gravity direct"]["cpu_loop_s"]
                                               / runs["coupled, dd"]["cpu_loop_s"])
    return report


def format_coupled_report(report: dict) -> str:
    """Human-readable table of a :func:`coupled_benchmark` report."""
    runs = report["runs"]
    lines = [f"coupled benchmark: TianQin, full force model + attitude + drag-free control, "
             f"{report['duration_s'] / 86400:g} days at 50 s ({report['n_steps']} steps), after compilation",
             f"{'run':<32} {'wall [s]':>9} {'peak RSS [MB]':>14}"]
    for name, r in runs.items():
        lines.append(f"{name:<32} {r['wall_s']:>9.2f} {r['peak_rss_mb']:>14.0f}")
    ratio = runs["coupled, dd"]["wall_s"] / runs["coupled, float64"]["wall_s"]
    lines.append(f"dd / float64: {ratio:.2f} (target <= 2)")
    if "kepler_float64_s" in report:
        k = report["kepler_float64_s"]
        each = " and ".join(f"{x:.2f}" for x in report.get("kepler_float64_runs_s", [k]))
        lines.append(f"coupled dd / Kepler float64 (same span and step, DP87, {each} s, first and last): "
                     f"{runs['coupled, dd']['wall_s'] / k:.1f} (target <= 23)")
        if "coupled, dd, multistep" in runs:
            lines.append(f"coupled dd multistep ({report['multistep']}) / Kepler float64: "
                         f"{runs['coupled, dd, multistep']['wall_s'] / k:.1f} (target <= 10); DP87 / multistep: "
                         f"{report['dp87_over_multistep_dd']:.1f}")
    days = report["duration_s"] / 86400
    lines.append(f"{'CPU per simulated day [s]':<32} {'inputs':>9} {'loop':>9} {'2-core floor [s]':>17} "
                 f"{'process CPU [s]':>16}")
    for name, r in runs.items():
        if r.get("cpu_loop_s"):
            lines.append(f"{name:<32} {r['cpu_inputs_s'] / days:>9.3f} {r['cpu_loop_s'] / days:>9.3f} "
                         f"{0.5 * (r['cpu_inputs_s'] + r['cpu_loop_s']):>17.1f} {r.get('cpu_process_s', 0.0):>16.1f}")
    lines.append("dd wall time target <= 16 s for 90 days; peak memory target < 400 MB")
    return "\n".join(lines)


def lisa_benchmark(duration: str = LISA_DURATION, scenario: str = "lisa-esa") -> dict:
    """A heliocentric LISA scenario in dd and in float64: wall time of the
    propagation [s] (ephemeris inputs included, JIT compilation excluded) and
    peak resident memory [MB] of the process so far (no output file).
    ``scenario``: "lisa-esa" (three point masses, ESA's force model and
    self-gravity ramp) or "lisa" (the coupled constellation: LISA
    architecture, iterative pointing, drag-free control).  The span is
    rounded up to whole steps of the scenario (6 h), at least one."""
    from decimal import ROUND_CEILING

    from ..scenario.loader import parse_duration

    step = load_scenario(scenario).integrator.step_s
    n = max(1, int((parse_duration(duration) / step).to_integral_value(ROUND_CEILING)))
    scen = load_scenario(scenario, [f"run.duration={n * step}"])
    report = {"duration_s": float(scen.run.duration_s), "step_s": float(step), "n_steps": scen.n_steps,
              "n_sat": len(scen.satellites), "scenario": scenario, "coupled": scen.constellation.coupled,
              "runs": {}}
    for precision in ("dd", "float64"):
        wall, rss, res = _timed_run(scen, precision)
        report["runs"][f"lisa, {precision}"] = {"wall_s": wall, "peak_rss_mb": rss,
                                                "us_per_step": wall / res.n_steps * 1e6}
    report["dd_over_float64"] = report["runs"]["lisa, dd"]["wall_s"] / report["runs"]["lisa, float64"]["wall_s"]
    return report


def format_lisa_report(report: dict) -> str:
    """Human-readable table of a :func:`lisa_benchmark` report."""
    runs = report["runs"]
    what = ("coupled: LISA architecture, iterative pointing, drag-free control, 6 TMs"
            if report.get("coupled") else "point masses")
    lines = [f"LISA benchmark: {report['n_sat']} spacecraft ({report.get('scenario', 'lisa-esa')}: ESA CReMA 2.0 "
             f"start, Sun + Earth + Moon + planetary barycentres, self-gravity ramp; {what}), "
             f"{report['duration_s'] / 86400:g} days "
             f"({report['duration_s'] / 86400 / 365.25:.3g} years) at {report['step_s'] / 3600:g} h ({report['n_steps']} steps), after compilation",
             f"{'run':<32} {'wall [s]':>9} {'us/step':>9} {'peak RSS [MB]':>14}"]
    for name, r in runs.items():
        lines.append(f"{name:<32} {r['wall_s']:>9.2f} {r['us_per_step']:>9.1f} {r['peak_rss_mb']:>14.0f}")
    ratio = runs["lisa, dd"]["wall_s"] / runs["lisa, float64"]["wall_s"]
    lines.append(f"dd / float64: {ratio:.2f}")
    return "\n".join(lines)
