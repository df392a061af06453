"""The orbit-determination benchmark of coupled runs (``tqdyn bench --model od-coupled-30d``).

A recovery on the coupled ``tianqin`` scenario (attitude, test masses, drag-free control):
GNSS + SLR + ISR every 1800 s over the span (default 30 days), 1e-10 m/s^2 of common
self-gravity injected along Y_S on each satellite, state and common self-gravity estimated
(27 parameters).  Timed in this process, after every kernel is compiled (a one-day recovery
first, not timed):

* ``run_s``: the span's dd propagation of the scenario (:func:`tqdyn.od.variational.propagate_dd`
  on the plan's grid, the run a fit makes once per iteration; no file);
* ``simulate_s``: the simulated measurements (not part of the fit);
* ``fit_s``: :func:`tqdyn.od.problem.fit` with the partials of the coupled variational equations
  (:mod:`tqdyn.od.coupled_variational`), and its ratio ``fit_over_run`` to ``run_s``;
* ``fit_differences_s`` (``differences`` True): the same fit with the partials by central
  differences of dd runs (54 runs per iteration), and ``fit_differences_over_run``;
* the estimates' largest error [sigma] and Sat1's Y_S sigma [m/s^2] of each fit, and the largest
  difference of the two fits' estimates [sigma].
"""

from __future__ import annotations

import resource
import time

import numpy as np

__all__ = ["OD_COUPLED_DURATION", "INJECTED", "od_coupled_benchmark", "format_od_coupled_report"]

#: Default span of the benchmark.
OD_COUPLED_DURATION = "30d"
#: Injected common self-gravity [m/s^2 in S] of each satellite.
INJECTED = (0.0, 1e-10, 0.0)
_KINDS = ("gnss", "slr", "isr")
_INTERVAL = 1800.0


def _recovery(scen, arc_s: float, method: str | None = None):
    """(simulate seconds, fit seconds, estimate, truth values) of the recovery over arc_s [s]
    with the coupled partials' ``method`` (None: the default)."""
    from ..od import coupled
    from ..od import problem as odp
    from ..od.parameters import OrbitParameters

    tr = odp.Tracking(_KINDS, arc_s, _INTERVAL, estimate=("state", "self_gravity_common"))
    nom = odp.nominal_parameters(scen)
    truth = OrbitParameters(nom.accelerations, nom.y0, np.tile(INJECTED, (3, 1)))
    t0 = time.perf_counter()
    meas = odp.simulate(scen, tr, truth, seed=0)
    t1 = time.perf_counter()
    with coupled.method(method or "variational"):
        est = odp.fit(scen, meas, tr)
    y0 = truth.y0_dd()
    x_true = np.concatenate([(y0[..., 0] + y0[..., 1]).ravel(), truth.self_gravity_common.ravel()])
    return t1 - t0, time.perf_counter() - t1, est, x_true


def _summary(est, x_true) -> dict:
    names = list(est.names)
    z = (est.values - x_true) / est.sigma
    return {"iterations": int(est.iterations), "max_error_sigma": float(np.max(np.abs(z))),
            "sat1_sgc_y_sigma": float(est.sigma[names.index("Sat1/sgc_y")])}


def od_coupled_benchmark(duration: str | None = None, differences: bool = True) -> dict:
    """Run the benchmark (module docstring); returns its report: ``arc_s`` [s], ``n_measurements``,
    ``run_s``, ``simulate_s``, ``fit_s`` [s], ``fit_over_run``, ``fit`` (iterations, largest error
    [sigma], Sat1's sgc_y sigma [m/s^2]), the same for the differences (``differences`` True),
    ``estimates_differ_sigma`` and ``peak_rss_mb`` [MB]."""
    from ..od import problem as odp
    from ..od.variational import propagate_dd
    from ..scenario import load_scenario
    from ..scenario.loader import parse_duration

    arc = float(parse_duration(duration or OD_COUPLED_DURATION))
    if arc % _INTERVAL:
        raise ValueError(f"--duration: {duration!r} is not a multiple of {_INTERVAL:.0f} s; allowed: e.g. 30d")
    scen = load_scenario("tianqin")
    _recovery(scen, 86400.0)                                    # compile every kernel (not timed)
    if differences:
        _recovery(scen, 7200.0, "differences")
    t = odp.Tracking(_KINDS, arc, _INTERVAL).times()
    t0 = time.perf_counter()
    propagate_dd(scen, None, t)
    run_s = time.perf_counter() - t0
    sim_s, fit_s, est, x_true = _recovery(scen, arc)
    out = {"scenario": "tianqin", "kinds": list(_KINDS), "interval_s": _INTERVAL, "arc_s": arc,
           "injected_sgc": list(INJECTED), "n_parameters": len(est.names), "n_measurements": int(est.residuals.size),
           "run_s": run_s, "simulate_s": sim_s, "fit_s": fit_s, "fit_over_run": fit_s / run_s,
           "fit": _summary(est, x_true)}
    if differences:
        _, fd_s, est_fd, _ = _recovery(scen, arc, "differences")
        out.update({"fit_differences_s": fd_s, "fit_differences_over_run": fd_s / run_s,
                    "fit_differences": _summary(est_fd, x_true),
                    "estimates_differ_sigma": float(np.max(np.abs(est.values - est_fd.values) / est_fd.sigma))})
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return out


def format_od_coupled_report(r: dict) -> str:
    """Human-readable lines of an :func:`od_coupled_benchmark` report."""
    lines = [f"coupled orbit determination: {r['scenario']}, {' + '.join(r['kinds'])} every {r['interval_s']:.0f} s over "
             f"{r['arc_s'] / 86400:g} d, {r['n_parameters']} parameters, {r['n_measurements']} rows",
             f"  run (dd propagation):            {r['run_s']:8.1f} s",
             f"  simulate:                        {r['simulate_s']:8.1f} s",
             f"  fit, variational equations:      {r['fit_s']:8.1f} s = {r['fit_over_run']:.1f} x the run "
             f"({r['fit']['iterations']} iterations, largest error {r['fit']['max_error_sigma']:.2f} sigma)"]
    if "fit_differences_s" in r:
        lines.append(f"  fit, central differences:        {r['fit_differences_s']:8.1f} s = "
                     f"{r['fit_differences_over_run']:.1f} x the run ({r['fit_differences']['iterations']} iterations)")
        lines.append(f"  estimates differ by at most {r['estimates_differ_sigma']:.1e} sigma")
    lines.append(f"  peak memory {r['peak_rss_mb']:.0f} MB")
    return "\n".join(lines)
