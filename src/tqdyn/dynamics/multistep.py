"""Fixed-step multistep propagation: Gauss-Jackson positions, summed Adams velocities.

``integrator.method = "multistep"``: the satellites (and, in the free-TM mode,
the test masses) are integrated by the summed Stormer-Cowell / Adams pair of
:mod:`tqdyn.numerics.multistep` of order ``integrator.order`` K, each step
with the stages ``integrator.corrector`` ("pece": predict, evaluate,
correct, evaluate; one evaluation of the right-hand side per "e"), all at
the step's end time t_{n+1}, so the time-only inputs of the force model are
computed once per step (not 13 times as for DP87).  Attitude and control are algebraic in the state
(:func:`tqdyn.dynamics.rhs.system_rhs` forms them at every evaluation), so
nothing else is integrated.

Start-up: the first K steps are DP87 steps of the same size (the fixed-step
kernel of :mod:`.fixed`, the scenario's tableau), which give the states
y_0 .. y_K and the accelerations f_0 .. f_K; the sums are then fixed by the
corrector at t_K (:func:`tqdyn.numerics.multistep.start`).  These are the
first K steps of the DP87 run, so the start-up carries DP87's local error
of K steps, like an error of the initial state (docs/precision.md derives
what that costs: ~2K/N of the DP87 run's final error after N steps).

Output rows, progress and checkpoints follow the fixed-step mode: chunks of
steps (:func:`.fixed.chunk_plan`), the inputs of the next block computed in a
second thread while the compiled loop (nogil) runs, rows on the step grid
(every ``run.output_every``-th step) holding the state, f(state) and the
diagnostics of that evaluation.  A checkpoint holds the state and the
integrator's table (accelerations, sums and their compensations, the last
diagnostics): a resumed run is bit-identical.
"""

from __future__ import annotations

import time as _time

import numpy as np

from ..numerics import dp87
from ..numerics import multistep as _ms
from . import layout as _lay
from .fixed import (
    CheckpointClock,
    _as_precision,
    _grid_times,
    _workspace,
    chunk_kernel,
    chunk_plan,
    deliver_rows,
    input_pipeline,
    warm_up_layout,
    warm_up_systems,
)
from .loops import multistep_chunk
from .results import (
    Checkpoint,
    RunResult,
    check_finite_states,
    format_extremes,
    select_rows,
    to_dd,
    update_extremes,
)
from .rhs import evaluate_rhs

__all__ = ["INPUT_BLOCK", "propagate_multistep", "warm_up_multistep", "corrector_stages"]

#: Steps per compiled call and per evaluation of the time-only inputs: one
#: instant per step (DP87: 13), so blocks of the default chunk's length hold
#: as many instants as DP87's blocks of 315 steps (~6 MB for the coupled
#: TianQin model) and amortise the per-call cost of the inputs' evaluation.
INPUT_BLOCK = 4096


def corrector_stages(corrector: str) -> tuple[int, bool]:
    """(corrections, evaluated) of a step's stage string ("pe", "pec",
    "pece", ...): the number of C stages, and whether the last C is
    followed by an evaluation (always for "pe", whose evaluation of the
    prediction is its last stage).  Evaluations per step: corrections + 1
    if evaluated, else corrections."""
    c = corrector.lower()
    if len(c) < 2 or c[:2] != "pe" or any(c[i:i + 2] != "ce" for i in range(2, len(c) - 1, 2)):
        raise ValueError(f"integrator.corrector: {corrector!r} is not a stage string; allowed: pe, pec, pece, ...")
    return c.count("c"), c.endswith("e")


def _kernel(fw):
    """The multistep loop of the system whose work arrays ``fw`` are (None:
    point masses; :func:`tqdyn.dynamics.loops.multistep_chunk`, the kernel
    it shares with the DP87 loop of the start-up): n_steps steps P(EC)^n_corr
    [E] of the coupled constellation: predict, evaluate, n_corr times
    correct and evaluate, the last evaluation only if ``evaluated``.  Before
    step n it records the state y_n in out_y[n], the table's newest
    acceleration f_n in out_a[n] and that evaluation's diagnostics aux_cur
    in out_aux[n] (if out_aux has rows).  tdat: (n_steps, n_tdat) inputs at
    the end times t_{n+1} of the steps.  head: (1,) int64 ring index of f_n;
    stats: (2,) running maxima of the first correction's change of
    positions [m] and velocities [m/s]."""
    return multistep_chunk(fw)


class _State:
    """The multistep integrator's state in the working precision: y (n_body,
    6[, 2]) the state at t_n; F (K + 1, n_body, 3[, 2]) the accelerations
    (ring, newest at head[0]); S, cS, s, cs (n_body, 3[, 2]) the sums and
    their compensations; aux (AUX_LEN,) the diagnostics of the evaluation
    at y_n."""

    def __init__(self, y, order):
        self.y = y
        tail = y.shape[2:]
        self.F = np.zeros((order + 1, y.shape[0], 3) + tail)
        self.S, self.cS, self.s, self.cs = (np.zeros((y.shape[0], 3) + tail) for _ in range(4))
        self.aux = np.zeros(_lay.AUX_LEN)
        self.head = np.zeros(1, dtype=np.int64)

    def table(self) -> np.ndarray:
        """The checkpoint's flat float64 table: F oldest first, S, cS, s, cs, aux."""
        order = np.roll(np.arange(self.F.shape[0]), -(int(self.head[0]) + 1))
        return np.concatenate([self.F[order].ravel(), self.S.ravel(), self.cS.ravel(), self.s.ravel(),
                               self.cs.ravel(), self.aux])

    def restore(self, table: np.ndarray) -> None:
        parts = [self.F, self.S, self.cS, self.s, self.cs, self.aux]
        sizes = [p.size for p in parts]
        if table is None or table.size != sum(sizes):
            got = None if table is None else table.size
            raise ValueError(f"checkpoint: the multistep table has {got} values; this run needs {sum(sizes)} "
                             f"(integrator.order {self.F.shape[0] - 1}, {self.y.shape[0]} bodies)")
        offsets = np.cumsum([0] + sizes)
        for p, a, b in zip(parts, offsets[:-1], offsets[1:]):
            p[...] = table[a:b].reshape(p.shape)
        self.head[0] = self.F.shape[0] - 1


def warm_up_multistep(precision: str = "dd", cpar: np.ndarray | None = None, model=None) -> None:
    """Compile the multistep kernel for ``precision`` (numba JIT, cached on
    disk); ``cpar`` and ``model`` as for :func:`tqdyn.dynamics.fixed.warm_up`."""
    _lay.check_precision(precision)
    tail = (2,) if precision == "dd" else ()
    y = np.zeros((3, 6) + tail)
    order = _ms.ORDERS[0]
    mc = _ms.step_coefficients(order, 1, precision)
    params, layout = warm_up_layout(model)
    st = _State(y, order)
    _ms.start(st.y, st.F, 0, mc.coef, mc.hh, st.S, st.cS, st.s, st.cs)
    for c in warm_up_systems(cpar):
        gw, fw, _ = _lay.workspace(y, c)
        _kernel(fw)(st.y, st.F, st.head, st.S, st.cS, st.s, st.cs, mc.coef, mc.hh, np.zeros_like(y),
                    np.zeros_like(y), st.aux, np.zeros(2), 1, True, np.zeros((0, 0)), params, layout, c,
                    gw, fw, 0, np.empty((0,) + y.shape), np.empty((0, 3, 3) + tail),
                    np.empty((0, _lay.AUX_LEN)))


def _start_up(st, mc, scenario, precision, model, epoch, tab, y0_dd, sink, system, cpu):
    """The first n_s = min(K, n_total) steps by DP87 at the same step: emits
    their rows, fills the table with f_0 .. f_{n_s} and, if n_s = K, fixes
    the sums.  Returns (n_s, the rows' diagnostics or None)."""
    n_s = min(mc.order, scenario.n_steps)
    coef = dp87.step_coefficients(tab, scenario.integrator.step_s, precision)
    y, comp, K, ystage, err = _workspace(y0_dd, precision)
    h = np.array(coef.h)
    t_out = np.empty((n_s + 1, 2))
    t_nodes = np.empty((n_s + 1, 13, 2))
    _grid_times(0, n_s + 1, h, coef.c, t_out, t_nodes)
    t_cpu = _time.thread_time()
    if model.time_dependent:
        tdat = model.precompute(epoch, t_nodes[:n_s, :, 0], t_nodes[:n_s, :, 1])
        tdat_end = np.atleast_1d(model.precompute(epoch, t_out[n_s, 0], t_out[n_s, 1]))
    else:
        tdat, tdat_end = np.zeros((n_s, 13, 0)), np.zeros(0)
    cpu["inputs"] += _time.thread_time() - t_cpu
    t_cpu = _time.thread_time()
    cpar = system.cpar
    gw, fw, aux = _lay.workspace(y, cpar)
    out_y = np.empty((n_s,) + y.shape)
    out_a = np.empty((n_s, y.shape[0], 3) + y.shape[2:])
    out_aux = np.empty((n_s if system.coupled else 0, _lay.AUX_LEN))
    chunk_kernel(fw)(y, comp, K, ystage, err, coef.ha, coef.nz, coef.nnz, coef.hb, coef.nzb, coef.nnzb, coef.he,
                     tdat, model.params, model.kernel_layout, cpar, aux, gw, fw, n_s, out_y, out_a, out_aux)
    k_end, aux_end = evaluate_rhs(y, tdat_end, model, cpar, with_aux=True)
    cpu["loop"] += _time.thread_time() - t_cpu
    check_finite_states(0, t_out[:n_s], out_y)
    if sink is not None:
        sink(select_rows(t_out[:n_s], out_y, out_a, precision, scenario.run.output_every, 0, out_aux, system))
    st.y[...] = y
    st.F[:n_s] = out_a
    st.F[n_s] = k_end[:, 3:6]
    st.head[0] = n_s
    st.aux[...] = aux_end
    if n_s == mc.order:
        _ms.start(st.y, st.F, n_s, mc.coef, mc.hh, st.S, st.cS, st.s, st.cs)
    if system.coupled:
        return n_s, out_aux
    return n_s, None


def propagate_multistep(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk, start=None,
                        checkpoint=None, checkpoint_every=0, system=None, checkpoint_interval_s=0.0):
    """Propagate ``scenario`` with the multistep method (arguments as
    :func:`tqdyn.dynamics.fixed.propagate_fixed`; ``tab``: the DP87 tableau
    of the start-up)."""
    integ = scenario.integrator
    order = integ.order
    n_corr, evaluated = corrector_stages(integ.corrector)
    mc = _ms.step_coefficients(order, integ.step_s, precision)
    n_total = scenario.n_steps
    every = scenario.run.output_every
    st = _State(_as_precision(y0_dd, precision), order)
    h = np.array(mc.h)
    cpar = system.cpar
    gw, fw, _ = _lay.workspace(st.y, cpar)
    kernel = _kernel(fw)
    n_aux = _lay.AUX_LEN if system.coupled else 0
    cpu = {"inputs": 0.0, "loop": 0.0}
    extremes: dict = {}
    stats = np.zeros(2)
    t_start = _time.perf_counter()
    if start is None:
        n, startup_aux = _start_up(st, mc, scenario, precision, model, epoch, tab, y0_dd, sink, system, cpu)
        n_rhs = 13 * n + 1
        if startup_aux is not None and startup_aux.shape[0]:
            update_extremes(extremes, startup_aux, system)
        if progress is not None:
            progress(n)
    else:
        if start.y.shape != st.y.shape or not order <= start.n <= n_total:
            raise ValueError(f"checkpoint: state shape {start.y.shape} at step {start.n} does not fit this run "
                             f"({st.y.shape}, {n_total} steps)")
        n = int(start.n)
        st.y[...] = start.y
        st.restore(start.table)
        n_rhs = 0
    plan = chunk_plan(n, n_total, chunk, checkpoint_every)
    c_dummy = np.zeros(1)

    def eval_times(n0, m):
        """(m, 2) dd end times t_{n0+1} .. t_{n0+m} of the steps n0 .. n0 + m - 1."""
        t = np.empty((m, 2))
        _grid_times(n0 + 1, m, h, c_dummy, t, np.empty((0, 1, 2)))
        return t

    def inputs(n0, m, span):
        """Time-only inputs (m, n_tdat) of the steps n0 .. n0 + m - 1 of the
        chunk span = (first step, steps), at their end times.  A block
        shorter than its chunk is evaluated together with the chunk's first
        and last instants, whose rows are dropped (as in :mod:`.fixed`: the
        inputs of a step do not depend on the block holding it).  The
        instants are passed as an (m, 1) array, as DP87 passes (m, 13): the
        force model's matrix products (the ocean tides') then run row by
        row instead of as one large BLAS product, whose threads would spin
        beside the compiled loop (more CPU for the process, not less wall
        time: ``tqdyn bench --model coupled`` prints the process's CPU)."""
        if not model.time_dependent:
            return np.zeros((m, 0))
        t_cpu = _time.thread_time()
        try:
            c0, cm = span
            t = eval_times(n0, m)
            if (n0, m) != (c0, cm):
                t = np.concatenate([t, eval_times(c0, 1), eval_times(c0 + cm - 1, 1)])
            return model.precompute(epoch, t[:, None, 0], t[:, None, 1])[:m, 0]
        finally:
            cpu["inputs"] += _time.thread_time() - t_cpu

    ypred = np.zeros_like(st.y)
    kbuf = np.zeros_like(st.y)
    clock = CheckpointClock(checkpoint_every, checkpoint_interval_s, n_total)
    for n0, m, parts in input_pipeline(plan, inputs, INPUT_BLOCK):
        t_out = np.empty((m, 2))
        _grid_times(n0, m, h, c_dummy, t_out, np.empty((0, 1, 2)))
        out_y = np.empty((m,) + st.y.shape)
        out_a = np.empty((m,) + st.F.shape[1:])
        out_aux = np.empty((m if n_aux else 0, _lay.AUX_LEN))
        for o, e, tdat in parts:
            t_cpu = _time.thread_time()
            kernel(st.y, st.F, st.head, st.S, st.cS, st.s, st.cs, mc.coef, mc.hh, ypred, kbuf, st.aux, stats,
                   n_corr, evaluated, tdat, model.params, model.kernel_layout, cpar, gw, fw, e - o, out_y[o:e],
                   out_a[o:e], out_aux[o:e])
            cpu["loop"] += _time.thread_time() - t_cpu
            del tdat
        deliver_rows(sink, extremes, n_aux, system, precision, every, n0, t_out, out_y, out_a, out_aux)
        del out_y, out_a, out_aux
        n = n0 + m
        n_rhs += m * (n_corr + (1 if evaluated else 0))
        if progress is not None:
            progress(m)
        if checkpoint is not None and clock.due(n):
            checkpoint(Checkpoint(n, st.y.copy(), np.zeros_like(st.y), st.table()))
            clock.written()
    # the final state: its acceleration and diagnostics are the last evaluation's
    t_end = np.empty((1, 2))
    _grid_times(n_total, 1, h, c_dummy, t_end, np.empty((0, 1, 2)))
    a_end = st.F[int(st.head[0])]
    deliver_rows(sink, extremes, n_aux, system, precision, every, n_total, t_end, st.y[None], a_end[None], st.aux[None])
    wall = _time.perf_counter() - t_start
    extra = format_extremes(extremes)
    if n_corr:
        extra["max first correction |r_C - r_P| (component)"] = f"{stats[0]:.3e} m"
        extra["max first correction |v_C - v_P| (component)"] = f"{stats[1]:.3e} m/s"
    return RunResult(precision=precision, mode="fixed", t_final=t_end[0], y0=y0_dd, y_final=to_dd(st.y, 2),
                     n_steps=n_total, n_rejected=0, n_rhs=n_rhs, wall_s=wall, extra=extra,
                     cpu_inputs_s=cpu["inputs"], cpu_loop_s=cpu["loop"])
