"""The compiled propagation loops: DP87 steps and multistep steps in one kernel per system.

A multistep run starts with K DP87 steps (:mod:`.multistep`), so it calls
both loops.  numba links a kernel's callees into it and optimises and
assembles them again with its own code; the right-hand side, by far the
largest part of a kernel, would be compiled once more for every kernel that
calls it.  Both loops therefore live in one kernel per system
(:func:`_chunk` for the coupled constellation, :func:`_chunk_points` for
independent point masses): it runs ``n_dp`` DP87 steps, then ``n_ms``
multistep steps, each loop exactly as it would run alone.  A DP87 run
passes an idle multistep table (:func:`dp87_chunk`), a multistep run's
loop an idle DP87 workspace (:func:`multistep_chunk`); both compile the
same kernel, the first run of either method compiles the right-hand side
into one kernel only.

The arguments of each loop travel as one tuple (``dp``, ``ms``); the
time-only inputs are (n_dp, 13, n_tdat) for DP87 (the 13 stage times of
each step) and (n_ms, n_tdat) for the multistep method (the end time of
each step).  The rows out_y (n, n_body, 6[, 2]), out_a (n, n_body, 3[, 2]),
out_aux (n or 0, AUX_LEN) are those of the loop that runs (one of n_dp,
n_ms is 0 in every call).
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from ..numerics import dp87
from ..numerics import multistep as _ms
from ..numerics.dd import copy_columns
from ..numerics.jit import kernel
from .rhs import coupled_rhs, point_mass_rhs

__all__ = ["dp87_chunk", "multistep_chunk"]


@njit(inline="always")
def _one_step(rhs, y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat_step, params, layout,
              cpar, aux0, aux, gw, fw):
    """One DP87 step in place: the 13 stages (K[0] = f(y) first, its
    diagnostics into aux0), then the compensated update of y.  tdat_step:
    (13, n_tdat) time-only inputs at the stage times; rhs: the system's
    right-hand side (:func:`tqdyn.dynamics.rhs.coupled_rhs` or
    :func:`~tqdyn.dynamics.rhs.point_mass_rhs`)."""
    rhs(y, tdat_step[0], params, layout, cpar, K[0], aux0, gw, fw)
    for i in range(1, 13):
        dp87.stage_state(y, K, ha, nz, nnz, i, ystage)
        rhs(ystage, tdat_step[i], params, layout, cpar, K[i], aux, gw, fw)
    dp87.combine(y, comp, K, hb, nzb, nnzb, he, err)


@njit(inline="always")
def _dp87_steps(rhs, y, dp, tdat, params, layout, cpar, gw, fw, n_steps, out_y, out_a, out_aux):
    """n_steps fixed DP87 steps.  Before step n it records the state y_n in
    out_y[n]; after it, f(y_n)'s acceleration (stage 1) in out_a[n] and its
    diagnostics in out_aux[n] (if out_aux has rows).  dp: (comp, K, ystage,
    err, ha, nz, nnz, hb, nzb, nnzb, he, aux) (:func:`dp87_chunk`)."""
    comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, aux = dp
    for n in range(n_steps):
        copy_columns(y, out_y[n], 0, 6)
        aux0 = out_aux[n] if out_aux.shape[0] > 0 else aux
        _one_step(rhs, y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat[n], params, layout,
                  cpar, aux0, aux, gw, fw)
        copy_columns(K[0], out_a[n], 3, 3)


@njit(inline="always")
def _multistep_steps(rhs, y, ms, tdat, params, layout, cpar, gw, fw, n_steps, out_y, out_a, out_aux):
    """n_steps steps P(EC)^n_corr [E]: predict, evaluate, n_corr times
    correct and evaluate, the last evaluation only if ``evaluated``.  Before
    step n it records the state y_n in out_y[n], the table's newest
    acceleration f_n in out_a[n] and that evaluation's diagnostics aux_cur
    in out_aux[n] (if out_aux has rows).  ms: (F, head, S, cS, s, cs, coef,
    hh, ypred, k, aux_cur, stats, n_corr, evaluated) (:func:`multistep_chunk`)."""
    F, head, S, cS, s, cs, coef, hh, ypred, k, aux_cur, stats, n_corr, evaluated = ms
    h = head[0]
    for n in range(n_steps):
        copy_columns(y, out_y[n], 0, 6)
        copy_columns(F[h], out_a[n], 0, 3)
        if out_aux.shape[0] > 0:
            for j in range(aux_cur.shape[0]):
                out_aux[n, j] = aux_cur[j]
        _ms.predict(S, cS, s, cs, F, h, coef, hh, ypred)
        rhs(ypred, tdat[n], params, layout, cpar, k, aux_cur, gw, fw)
        for it in range(n_corr):
            _ms.correct(S, cS, s, cs, F, h, k, coef, hh, y)
            if it == 0:
                _ms.max_change(y, ypred, stats)
            if evaluated or it < n_corr - 1:
                rhs(y, tdat[n], params, layout, cpar, k, aux_cur, gw, fw)
        if n_corr == 0:
            copy_columns(ypred, y, 0, 6)
        h = _ms.commit(S, cS, s, cs, F, h, k)
    head[0] = h


@kernel(nogil=True, link_only=True)
def _chunk(y, dp, ms, tdat_dp, tdat_ms, params, layout, cpar, gw, fw, n_dp, n_ms, out_y, out_a, out_aux):
    """n_dp DP87 steps, then n_ms multistep steps of the coupled constellation (the module's docstring)."""
    _dp87_steps(coupled_rhs, y, dp, tdat_dp, params, layout, cpar, gw, fw, n_dp, out_y, out_a, out_aux)
    _multistep_steps(coupled_rhs, y, ms, tdat_ms, params, layout, cpar, gw, fw, n_ms, out_y, out_a, out_aux)


@kernel(nogil=True, link_only=True)
def _chunk_points(y, dp, ms, tdat_dp, tdat_ms, params, layout, cpar, gw, fw, n_dp, n_ms, out_y, out_a, out_aux):
    """:func:`_chunk` for independent point masses (fw None)."""
    _dp87_steps(point_mass_rhs, y, dp, tdat_dp, params, layout, cpar, gw, fw, n_dp, out_y, out_a, out_aux)
    _multistep_steps(point_mass_rhs, y, ms, tdat_ms, params, layout, cpar, gw, fw, n_ms, out_y, out_a, out_aux)


def _idle_dp87(y: np.ndarray) -> tuple:
    """A DP87 workspace of the argument types of a run with y's precision (no step runs with it)."""
    return _idle_dp87_for(y.ndim)


@functools.cache
def _idle_dp87_for(ndim: int) -> tuple:
    coef = dp87.step_coefficients(dp87.load_tableau(), 1, "dd" if ndim == 3 else "float64")
    y = np.zeros((1, 6) + (2,) * (ndim - 2))
    return (y, np.zeros((13,) + y.shape), y, np.zeros((1, 6)), coef.ha, coef.nz, coef.nnz, coef.hb, coef.nzb,
            coef.nnzb, coef.he, np.zeros(1))


def _idle_multistep(y: np.ndarray) -> tuple:
    """A multistep table of the argument types of a run with y's precision (no step runs with it)."""
    tail = y.shape[2:]
    z = np.zeros((1, 3) + tail)
    return (np.zeros((1, 1, 3) + tail), np.zeros(1, dtype=np.int64), z, z, z, z, np.zeros((4, 1) + tail),
            np.zeros((2,) + tail), y, y, np.zeros(1), np.zeros(2), 0, False)


def _kernel(fw):
    return _chunk_points if fw is None else _chunk


def dp87_chunk(fw):
    """The DP87 loop of the system whose work arrays ``fw`` are (None: point
    masses), as a function of the loop's arguments ``(y, comp, K, ystage,
    err, ha, nz, nnz, hb, nzb, nnzb, he, tdat, params, layout, cpar, aux,
    gw, fw, n_steps, out_y, out_a, out_aux)``: :func:`_dp87_steps`, tdat
    (n_steps, 13, n_tdat)."""
    run = _kernel(fw)

    def dp87_loop(y, comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, tdat, params, layout, cpar, aux, gw,
                  fw, n_steps, out_y, out_a, out_aux):
        dp = (comp, K, ystage, err, ha, nz, nnz, hb, nzb, nnzb, he, aux)
        run(y, dp, _idle_multistep(y), np.ascontiguousarray(tdat), np.zeros((0, 0)), params, layout, cpar, gw, fw,
            n_steps, 0, out_y, out_a, out_aux)

    return dp87_loop


def multistep_chunk(fw):
    """The multistep loop of the system whose work arrays ``fw`` are (None:
    point masses), as a function of the loop's arguments ``(y, F, head, S,
    cS, s, cs, coef, hh, ypred, k, aux_cur, stats, n_corr, evaluated, tdat,
    params, layout, cpar, gw, fw, n_steps, out_y, out_a, out_aux)``:
    :func:`_multistep_steps`, tdat (n_steps, n_tdat)."""
    run = _kernel(fw)

    def multistep_loop(y, F, head, S, cS, s, cs, coef, hh, ypred, k, aux_cur, stats, n_corr, evaluated, tdat,
                       params, layout, cpar, gw, fw, n_steps, out_y, out_a, out_aux):
        ms = (F, head, S, cS, s, cs, coef, hh, ypred, k, aux_cur, stats, int(n_corr), bool(evaluated))
        run(y, _idle_dp87(y), ms, np.zeros((0, 13, 0)), np.ascontiguousarray(tdat), params, layout, cpar, gw, fw,
            0, n_steps, out_y, out_a, out_aux)

    return multistep_loop
