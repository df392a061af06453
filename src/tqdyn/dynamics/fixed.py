"""Fixed-step propagation: the compiled DP87 loop, chunk by chunk.

The loop runs entirely in compiled code, one block of steps at a time.
Before each block the time-only inputs of the force model are computed for
every stage time of the block (t_n + c_i h, known in advance) and handed to
the loop as one array, so no Python runs per step; the inputs of the next
block are computed in a second thread while the compiled loop (nogil) runs.
A chunk (the unit of output rows, progress and checkpoints) is split into
blocks of at most :data:`INPUT_BLOCK` steps, which bounds the memory of the
time-only inputs (n_tdat x 13 stages x 8 bytes per step: ~2.6 MB per 128
steps for the ~200 columns of the coupled TianQin model, plus the
temporaries of their evaluation) whatever the chunk.  Time is an
integer step count times the exact step (a dd pair), never a large bare
float64.
"""

from __future__ import annotations

import time as _time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

from ..forces.model import ForceModel
from ..numerics import dp87
from ..numerics.dd import add, ld, mul, st
from . import layout as _lay
from .loops import dp87_chunk
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

__all__ = ["DEFAULT_CHUNK", "INPUT_BLOCK", "CheckpointClock", "chunk_kernel", "chunk_plan", "deliver_rows",
           "input_pipeline", "propagate_fixed", "warm_up", "warm_up_layout", "warm_up_systems"]

DEFAULT_CHUNK = 4096  # steps per chunk: rows to the sink, progress and checkpoints
INPUT_BLOCK = 512  # steps per compiled call and per evaluation of the time-only inputs


def _as_precision(y_dd: np.ndarray, precision: str) -> np.ndarray:
    """dd array -> array of the working precision (float64 drops the dd axis, rounding hi+lo)."""
    if precision == "dd":
        return np.array(y_dd, dtype=np.float64, order="C", copy=True)
    return np.ascontiguousarray(y_dd[..., 0] + y_dd[..., 1])


def _workspace(y0_dd, precision):
    """State y (a copy of y0 in the working precision), its compensation,
    the 13 stage derivatives, a stage state and the error estimate."""
    y = _as_precision(y0_dd, precision)
    return y, np.zeros_like(y), np.zeros((13,) + y.shape), np.zeros_like(y), np.zeros(y.shape[:2])


def chunk_kernel(fw):
    """The DP87 loop of the system whose work arrays ``fw`` are
    (:func:`tqdyn.dynamics.layout.workspace`: None for point masses): a
    function of ``(y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he,
    tdat, params, layout, cpar, aux, gw, fw, n_steps, out_y, out_a,
    out_aux)`` that runs n_steps DP87 steps in the compiled kernel it shares
    with the multistep loop (:func:`tqdyn.dynamics.loops.dp87_chunk`).
    Before step n it records the state y_n in out_y[n] (n_body, 6[, 2]);
    after it, f(y_n)'s acceleration (stage 1) in out_a[n] (n_body, 3[, 2])
    and its diagnostics in out_aux[n] (AUX_LEN,) (if out_aux has rows).
    tdat: (n_steps, 13, n_tdat)."""
    return dp87_chunk(fw)


@njit(cache=True)
def _grid_times(n0, m, h, c, t_out, t_nodes):
    """t_out[k] = (n0 + k) h (dd, exact for the usual decimal steps) and, if
    t_nodes has rows, the stage times t_nodes[k, i] = t_out[k] + c_i h.
    h: (2,) dd step [s]; c: (13,) nodes; t_out: (m, 2); t_nodes: (m or 0, 13, 2)."""
    hd = (h[0], h[1])
    for k in range(m):
        t = mul(hd, float(n0 + k))
        st(t_out, t, k)
        if t_nodes.shape[0] > 0:
            for i in range(c.shape[0]):
                st(t_nodes, add(t, mul(hd, c[i])), k, i)


@njit(cache=True)
def _scale_tableau(a, b, h, ha, hb):
    """ha = h * a, hb = h * b in the working precision (h: generic number)."""
    for i in range(a.shape[0]):
        st(hb, mul(ld(b, i), h), i)
        for j in range(a.shape[1]):
            st(ha, mul(ld(a, i, j), h), i, j)


def warm_up(precision: str = "dd", cpar: np.ndarray | None = None, model: ForceModel | None = None) -> None:
    """Compile the fixed-step kernel for ``precision`` (numba JIT, a few
    seconds on first use in a process, then cached on disk) so that later
    timings measure the propagation alone.  ``cpar``: the run's system
    (the ``cpar`` of its :class:`tqdyn.dynamics.system.System`), whose kernel is compiled
    (each system has its own: independent point masses, the coupled
    constellation with the global or with a local pointing law); None: the
    point masses' and the coupled constellation's with the global law.
    ``model``: the run's force model, whose terms alone are compiled (the
    propagation passes its :attr:`~tqdyn.forces.model.ForceModel.kernel_layout`);
    None: the kernels for a layout table alone, with every term."""
    _lay.check_precision(precision)
    for c in warm_up_systems(cpar):
        _compile_chunk(precision, c, model)
    _grid_times(0, 1, np.array((1.0, 0.0)), np.zeros(13), np.empty((1, 2)), np.empty((0, 13, 2)))


def warm_up_systems(cpar: np.ndarray | None) -> tuple:
    """The system parameters whose kernels :func:`warm_up` compiles for ``cpar``."""
    if cpar is not None:
        return (cpar,)
    return _lay.make_cpar(_lay.MODE_POINT_MASS), _lay.make_cpar(_lay.MODE_COUPLED)


def warm_up_layout(model: ForceModel | None):
    """The ``params`` and ``layout`` a warm-up compiles for (:func:`warm_up`): ``model``'s
    parameters and kernel layout, or, without a model, an empty parameter vector and a layout table."""
    if model is None:
        return np.zeros(0), ForceModel([]).layout
    return model.params, model.kernel_layout


def _compile_chunk(precision: str, cpar: np.ndarray, model: ForceModel | None = None) -> None:
    """Compile the kernel of the system ``cpar`` (and force ``model``, :func:`warm_up`) for the argument
    types of a run (zero steps run)."""
    tail = (2,) if precision == "dd" else ()
    y = np.zeros((3, 6) + tail)
    coef = dp87.step_coefficients(dp87.load_tableau(), 1, precision)
    params, layout = warm_up_layout(model)
    gw, fw, aux = _lay.workspace(y, cpar)
    chunk_kernel(fw)(y, np.zeros_like(y), np.zeros((13,) + y.shape), np.zeros_like(y), np.zeros((3, 6)),
                     coef.ha, coef.nz, coef.nnz, coef.hb, coef.nzb, coef.nnzb, coef.he, np.zeros((0, 13, 0)),
                     params, layout, cpar, aux, gw, fw, 0, np.empty((0,) + y.shape),
                     np.empty((0, 3, 3) + tail), np.empty((0, _lay.AUX_LEN)))


# --------------------------------------------------------------------------
# Python driver


def chunk_plan(n: int, n_total: int, chunk: int, checkpoint_every: int) -> list[tuple[int, int]]:
    """(first step, steps) of the chunks from step n to n_total: at most
    ``chunk`` steps each, ending at every multiple of ``checkpoint_every``
    (0: none).  The boundaries depend on n only through where the plan
    starts, so a run resumed at a boundary takes the same chunks."""
    plan = []
    while n < n_total:
        m = min(chunk, n_total - n)
        if checkpoint_every:
            m = min(m, (n // checkpoint_every + 1) * checkpoint_every - n)
        plan.append((n, m))
        n += m
    return plan


class CheckpointClock:
    """When a fixed-step run writes a checkpoint: after step ``n`` when ``n`` is a multiple of
    ``every`` (0 = never), or at the first chunk boundary ``interval_s`` seconds of wall time
    after the last one (0 = never), and never after the last step (``n_total``)."""

    def __init__(self, every: int, interval_s: float, n_total: int):
        self.every, self.interval_s, self.n_total = every, interval_s, n_total
        self.last = self.now = _time.perf_counter()

    def due(self, n: int) -> bool:
        self.now = _time.perf_counter()
        return ((bool(self.every) and n % self.every == 0)
                or (self.interval_s > 0 and self.now - self.last >= self.interval_s)) and n < self.n_total

    def written(self) -> None:
        """A checkpoint was written for the step of the last :meth:`due`."""
        self.last = self.now


def deliver_rows(sink, extremes, n_aux, system, precision, every, n0, t, y, a, aux) -> None:
    """Hand the rows of the steps n0, n0 + 1, ... (dd times ``t``, states ``y``, accelerations ``a``,
    diagnostics ``aux``) to ``sink`` (every ``every``-th step: :func:`select_rows`) and fold the
    diagnostics into ``extremes`` (when the run forms them, ``n_aux``).  A state that is not finite
    stops the run here (:func:`~tqdyn.dynamics.results.check_finite_states`), before its rows go out."""
    check_finite_states(n0, t, y)
    if sink is not None:
        sink(select_rows(t, y, a, precision, every, n0, aux, system))
    if n_aux:
        update_extremes(extremes, aux, system)


def input_pipeline(plan, inputs, block: int):
    """The chunks of ``plan`` with their time-only inputs computed one block
    ahead in a second thread (the inputs of the next block overlap the
    compiled loop of this one).

    plan: [(n0, m)] chunks of steps; inputs(b0, mb, (n0, m)) -> the inputs of
    steps b0 .. b0 + mb of chunk (n0, m); block: steps per block.  Yields
    (n0, m, parts) per chunk, where parts yields (o, e, tdat): the block's
    rows o:e inside the chunk and its inputs, in order.  Each chunk's parts
    must be consumed before the next chunk is taken."""
    blocks = [(b0, min(block, n0 + m - b0), (n0, m)) for n0, m in plan for b0 in range(n0, n0 + m, block)]
    with ThreadPoolExecutor(max_workers=1) as pool:
        queue = {"next": 0, "pending": pool.submit(inputs, *blocks[0]) if blocks else None}

        def parts(n0, m):
            while queue["next"] < len(blocks) and blocks[queue["next"]][2] == (n0, m):
                b0, mb, _ = blocks[queue["next"]]
                tdat = queue["pending"].result()
                queue["next"] += 1
                i = queue["next"]
                queue["pending"] = pool.submit(inputs, *blocks[i]) if i < len(blocks) else None
                yield b0 - n0, b0 - n0 + mb, tdat
                del tdat  # before the next block's inputs arrive

        for n0, m in plan:
            yield n0, m, parts(n0, m)


def propagate_fixed(scenario, precision, model, epoch, tab, y0_dd, sink, progress, chunk,
                     start=None, checkpoint=None, checkpoint_every=0, system=None, checkpoint_interval_s=0.0):
    coef = dp87.step_coefficients(tab, scenario.integrator.step_s, precision)
    n_total = scenario.n_steps
    every = scenario.run.output_every
    y, comp, K, ystage, err = _workspace(y0_dd, precision)
    n = 0
    if start is not None:
        if start.y.shape != y.shape or not 0 <= start.n <= n_total:
            raise ValueError(f"checkpoint: state shape {start.y.shape} at step {start.n} does not fit this run "
                             f"({y.shape}, {n_total} steps)")
        n = int(start.n)
        y[...] = start.y
        comp[...] = start.comp
    h = np.array(coef.h)
    nb = y.shape[0]
    acc_shape = (nb, 3) + y.shape[2:]
    cpar = system.cpar
    gw, fw, aux = _lay.workspace(y, cpar)
    kernel = chunk_kernel(fw)
    n_aux = _lay.AUX_LEN if system.coupled else 0
    t_start = _time.perf_counter()
    clock = CheckpointClock(checkpoint_every, checkpoint_interval_s, n_total)
    extremes: dict = {}
    # the time-only inputs of the next chunk are computed in a second thread
    # while the compiled loop (nogil) runs.
    plan = chunk_plan(n, n_total, chunk, checkpoint_every)

    def inputs(n0, m, span):
        """Time-only inputs (m, 13, n_tdat) of the steps n0 .. n0 + m - 1 of
        the chunk span = (first step, steps).  A block shorter than its chunk
        is evaluated together with one more pseudo-step holding the chunk's
        first and last instants, whose rows are dropped: the inputs of a
        step are the same whatever block holds it (terms that evaluate slow
        quantities on nodes spanning the requested instants, the CIP of the
        relativity term, see the chunk's span as in one evaluation; the
        others are instant by instant, with the 13 stages of a step in one
        row).  The stages stay (m, 13) even where two are the same instant
        (c = 1 twice, and c = 1 is the next step's c = 0): the ocean tides'
        matrix product (BLAS, one 13-row product per step) gives the 13th row
        other last bits than the 12th, so evaluating each instant once would
        change the trajectory's last bits."""
        if not model.time_dependent:
            return np.zeros((m, 13, 0))
        t_cpu = _time.thread_time()
        try:
            return _inputs(n0, m, span)
        finally:
            cpu["inputs"] += _time.thread_time() - t_cpu

    def _inputs(n0, m, span):
        c0, cm = span
        extra = 0 if (n0, m) == (c0, cm) else 1
        t_nodes = np.empty((m + extra, 13, 2))
        _grid_times(n0, m, h, coef.c, np.empty((m, 2)), t_nodes[:m])
        if extra:
            _grid_times(c0 + cm - 1, 1, h, coef.c, np.empty((1, 2)), t_nodes[m:])
            first = np.empty((1, 13, 2))
            _grid_times(c0, 1, h, coef.c, np.empty((1, 2)), first)
            t_nodes[m, 0] = first[0, 0]
        tdat = model.precompute(epoch, t_nodes[..., 0], t_nodes[..., 1])
        return tdat[:m] if extra else tdat

    cpu = {"inputs": 0.0, "loop": 0.0}
    for n0, m, parts in input_pipeline(plan, inputs, INPUT_BLOCK):
        t_out = np.empty((m, 2))
        _grid_times(n0, m, h, coef.c, t_out, np.empty((0, 13, 2)))
        out_y = np.empty((m,) + y.shape)
        out_a = np.empty((m,) + acc_shape)
        out_aux = np.empty((m if n_aux else 0, _lay.AUX_LEN))
        for o, e, tdat in parts:
            t_cpu = _time.thread_time()
            kernel(y, comp, K, ystage, err, coef.ha, coef.nz, coef.nnz, coef.hb, coef.nzb, coef.nnzb,
                   coef.he, tdat, model.params, model.kernel_layout, cpar, aux, gw, fw, e - o, out_y[o:e],
                   out_a[o:e], out_aux[o:e])
            cpu["loop"] += _time.thread_time() - t_cpu
            del tdat
        deliver_rows(sink, extremes, n_aux, system, precision, every, n0, t_out, out_y, out_a, out_aux)
        del out_y, out_a, out_aux
        n = n0 + m
        if progress is not None:
            progress(m)
        if checkpoint is not None and clock.due(n):
            checkpoint(Checkpoint(n, y.copy(), comp.copy()))
            clock.written()
    # the final state and its acceleration
    t_end = np.empty((1, 2))
    t_nodes = np.empty((1 if model.time_dependent else 0, 13, 2))
    _grid_times(n_total, 1, h, coef.c, t_end, t_nodes)
    tdat_end = (model.precompute(epoch, t_nodes[0, 0, 0], t_nodes[0, 0, 1]) if model.time_dependent
                else np.zeros(0))
    k_end, aux_end = evaluate_rhs(y, np.atleast_1d(tdat_end), model, cpar, with_aux=True)
    wall = _time.perf_counter() - t_start
    check_finite_states(n_total, t_end, y[None])
    if sink is not None:
        sink(select_rows(t_end, y[None], k_end[None, :, 3:6], precision, every, n_total, aux_end[None], system))
    return RunResult(precision=precision, mode="fixed", t_final=t_end[0], y0=y0_dd,
                     y_final=to_dd(y, 2), n_steps=n_total, n_rejected=0,
                     n_rhs=13 * n_total + 1, wall_s=wall, extra=format_extremes(extremes),
                     cpu_inputs_s=cpu["inputs"], cpu_loop_s=cpu["loop"])
