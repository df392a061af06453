"""Propagate a scenario: the one entry point of the dynamics layer.

:func:`propagate` builds the force model and the system of a scenario, its
initial states, and runs the fixed-step (:mod:`.fixed`) or adaptive
(:mod:`.adaptive`) integration.  It computes; it writes nothing: output rows
(:class:`~tqdyn.dynamics.results.Rows`) go to a ``sink`` callable (the run
workflow connects it to the trajectory writer), progress to a ``progress``
callable.  States are in the force model's reference system (for the
geocentric model: GCRS, SI).
"""

from __future__ import annotations

import time
from typing import Callable

import mpmath
import numpy as np

from ..forces.model import ForceModel, build_force_model
from ..numerics import dp87
from ..numerics.dd import mp_from_dd
from .adaptive import propagate_adaptive
from .fixed import DEFAULT_CHUNK, propagate_fixed
from .fixed import warm_up as _warm_up_fixed
from .initial import initial_state
from .multistep import propagate_multistep, warm_up_multistep
from .layout import PRECISIONS, check_precision
from .results import Checkpoint, NonFiniteStateError, Rows, RunResult, check_finite_states
from .system import build_system

__all__ = ["propagate", "check_inputs", "two_body_energy", "warm_up", "PRECISIONS", "Checkpoint",
           "NonFiniteStateError", "Rows", "RunResult"]


def warm_up(precision: str = "dd", method: str = "dp87", cpar: np.ndarray | None = None,
            model: ForceModel | None = None) -> None:
    """Compile the kernels of ``method`` ("dp87" | "multistep") for
    ``precision`` (numba JIT, a few seconds on first use, then cached on
    disk) so that later timings measure the propagation alone.  The DP87
    kernel is always compiled (it also starts the multistep method).
    ``cpar``: the run's system (the ``cpar`` of its
    :class:`tqdyn.dynamics.system.System`, ``build_system(scenario).cpar``), whose kernels alone are
    compiled; None: those of independent point masses and of the coupled
    constellation with the global pointing law.  ``model``: the run's
    force model, whose terms alone are compiled; None: the kernels for a
    layout table alone, with every term (which runs do not use: they pass
    their model's :attr:`~tqdyn.forces.model.ForceModel.kernel_layout`)."""
    _warm_up_fixed(precision, cpar, model)
    if method == "multistep":
        warm_up_multistep(precision, cpar, model)


def two_body_energy(y_dd: np.ndarray, gm) -> list:
    """Specific two-body energy v^2/2 - gm/|r| [J/kg] of each body, in mpmath
    (exact from the dd states).  y_dd: (n_body, 6, 2)."""
    vals = mp_from_dd(y_dd)
    out = []
    with mpmath.workdps(60):
        g = mpmath.mpf(str(gm))
        for row in vals:
            r = mpmath.sqrt(sum(x * x for x in row[:3]))
            out.append(sum(x * x for x in row[3:]) / 2 - g / r)
    return out


def propagate(scenario, *, precision: str | None = None, sink: Callable[[Rows], None] | None = None,
              progress: Callable[[int], None] | None = None, chunk: int = DEFAULT_CHUNK,
              y0: np.ndarray | None = None, model: ForceModel | None = None,
              start: Checkpoint | None = None, checkpoint: Callable[[Checkpoint], None] | None = None,
              checkpoint_every: int = 0, checkpoint_interval_s: float = 0.0) -> RunResult:
    """Propagate the scenario's satellites over ``scenario.run.duration_s``.

    precision: "dd" | "float64" (default: the scenario's run.precision).
    sink(rows): receives output rows every chunk -- a dict with "t" (hi, lo)
    (m,) [s TT since epoch], "sat/r" and "sat/v" (hi, lo) (m, n_sat, 3)
    [m, m/s, GCRS], "sat/a_gravity" (m, n_sat, 3) float64 [m/s^2] -- on the
    output grid (every run.output_every-th step; the adaptive mode samples
    the fixed grid k * integrator.step_s by dense output).
    progress(n): called with the number of steps just completed (fixed) or
    the seconds of propagation time just covered (adaptive).
    y0: optional initial dd states (n_sat, 6, 2) instead of the scenario's elements.
    model: optional force model instead of the one built from scenario.forces.
    start: resume a fixed-step run from this checkpoint (its rows before
    start.n are not emitted again).  checkpoint(Checkpoint): called every
    ``checkpoint_every`` steps (fixed mode; 0 = never), and at the first
    chunk boundary (``chunk`` steps) after ``checkpoint_interval_s`` seconds
    of wall-clock time since the last one (0 = never), after the rows up to
    that step went to the sink.  Where the checkpoints fall does not change
    the steps: a run resumed from any of them is bit-identical.

    A state that stops being finite (inf, NaN) stops the propagation at that step, before its rows
    reach the sink: :class:`~tqdyn.dynamics.results.NonFiniteStateError` (a ``ValueError``) naming
    the step, its time and the satellite (fixed mode: every step's state is checked, per chunk;
    adaptive mode: each attempted step).
    """
    cpu0 = time.process_time()
    precision = precision or scenario.run.precision
    check_precision(precision)
    model = build_force_model(scenario.forces, scenario.reference) if model is None else model
    system = build_system(scenario, model)
    model = system.with_inputs(model)
    epoch = scenario.epoch
    tab = dp87.load_tableau(scenario.integrator.tableau)
    y0_dd = initial_state(scenario, model, system) if y0 is None else np.asarray(y0, np.float64)
    try:
        check_finite_states(0, np.zeros((1, 2)), y0_dd[None])
        if scenario.integrator.mode == "adaptive":
            if start is not None or checkpoint_every or checkpoint_interval_s:
                raise ValueError("integrator.mode: checkpoints and --resume need mode = \"fixed\"")
            result = propagate_adaptive(scenario, precision, model, epoch, tab, y0_dd, sink, progress, system)
        elif scenario.integrator.method == "multistep":
            result = propagate_multistep(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk,
                                         start, checkpoint, checkpoint_every, system, checkpoint_interval_s)
        else:
            result = propagate_fixed(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk,
                                      start, checkpoint, checkpoint_every, system, checkpoint_interval_s)
    except NonFiniteStateError as exc:
        raise NonFiniteStateError(exc.step, exc.t, exc.body, _body_name(scenario, exc.body),
                                  model.reference.time_scale) from None
    if [t.name for t in model.terms] in (["earth_monopole"], ["sun_monopole"]) and not system.coupled \
            and system.centre_ramp is None:
        e0 = two_body_energy(result.y0, model.terms[0].gm)
        e1 = two_body_energy(result.y_final, model.terms[0].gm)
        with mpmath.workdps(60):
            result.energy_rel_drift = np.array([float((b - a) / abs(a)) for a, b in zip(e0, e1)])
    result.reference = model.reference
    result.cpu_process_s = time.process_time() - cpu0
    return result


def _body_name(scenario, body: int) -> str:
    """The name of body ``body`` of the state: a satellite, or a test mass of the free-TM mode."""
    names = [s.name for s in scenario.satellites]
    if body < len(names):
        return names[body]
    sat, tm = divmod(body - len(names), 2)
    return f"{names[sat]} test mass {tm + 1}" if sat < len(names) else f"body {body}"


def check_inputs(scenario, model: ForceModel | None = None) -> ForceModel:
    """Build the scenario's force model and evaluate its time-only inputs at
    the first and last instants, so that data limits (a date outside the
    ephemeris, EOP or lunar-kernel span, a missing file, a degree above what
    a file holds) raise ValueError / FileNotFoundError before any
    propagation or output starts.  Returns the model."""
    model = build_force_model(scenario.forces, scenario.reference) if model is None else model
    epoch = scenario.epoch
    t_end = float(scenario.run.duration_s)
    if getattr(model, "eop", None) is not None:  # one line naming forces.eop if its table is too short
        from ..astro.eop_sources import check_coverage, run_span_mjd

        check_coverage(model.eop, model.eop_source, *run_span_mjd(epoch, t_end))
    model.precompute(epoch, np.array([0.0, t_end]), np.zeros(2))
    return model
