"""Adaptive propagation: embedded-error step-size control and dense output on the output grid.

The adaptive mode drives the compiled DP87 step of :mod:`.fixed` from
Python (step-size control needs the stage times of the step being tried)
and samples the solution on the output grid with the Hermite dense output
of :mod:`tqdyn.numerics.hermite`.  Time is tracked as an exact rational
(each step is an exact binary float).
"""

from __future__ import annotations

import time as _time
from fractions import Fraction

import numpy as np

from ..numerics import dp87
from ..numerics import hermite
from . import layout as _lay
from .fixed import DEFAULT_CHUNK, _scale_tableau, _workspace, chunk_kernel
from .results import NonFiniteStateError, RunResult, check_finite_states, select_rows, to_dd
from .rhs import evaluate_rhs

__all__ = ["propagate_adaptive"]


def _dd_of(x: Fraction) -> tuple[float, float]:
    """Exact rational -> dd pair."""
    hi = float(x)
    return hi, float(x - Fraction(hi))


def _node_tdat(model, epoch, times) -> np.ndarray:
    """Time-only inputs at exact times (list of Fractions, s TT since epoch): (len, n_tdat)."""
    if not model.time_dependent:
        return np.zeros((len(times), 0))
    pairs = np.array([_dd_of(t) for t in times])
    return model.precompute(epoch, pairs[:, 0], pairs[:, 1])


#: max|r^(6)| (h/2)^6 / 6! bound of the quintic Hermite error, written as
#: |r| (w h)^6 / _QUINTIC_ERROR_DIVISOR for a motion of angular rate w.


#: max|r^(6)| (h/2)^6 / 6! bound of the quintic Hermite error, written as
#: |r| (w h)^6 / _QUINTIC_ERROR_DIVISOR for a motion of angular rate w.
_QUINTIC_ERROR_DIVISOR = 46080.0
#: Margin on that step (error ~ h^6: 0.75 -> 0.18 of the bound) for the
#: higher harmonics of eccentric motion near perigee, which the rate w does
#: not capture (without it the e = 0.1 orbit of the adaptive tests exceeds the bound).


#: Margin on that step (error ~ h^6: 0.75 -> 0.18 of the bound) for the
#: higher harmonics of eccentric motion near perigee, which the rate w does
#: not capture (without it the e = 0.1 orbit of the adaptive tests exceeds the bound).
_DENSE_OUTPUT_SAFETY = 0.75


def _dense_output_max_step(y, a, rtol) -> float:
    """Largest step [s] whose quintic Hermite dense output stays within
    rtol * |r|: h <= safety * (46080 rtol)^(1/6) / w, with the angular rate
    w = max(sqrt(|a| / |r|), |v| / |r|) [rad/s] of the fastest body (for a
    Keplerian orbit sqrt(GM / r^3) and the rate of the radius vector)."""
    y_dd = to_dd(y, 2)
    r = np.linalg.norm(y_dd[:, 0:3, 0], axis=1)
    v = np.linalg.norm(y_dd[:, 3:6, 0], axis=1)
    acc = np.linalg.norm(np.asarray(a)[..., 0] if np.ndim(a) == 3 else a, axis=1)
    w = float(np.max(np.maximum(np.sqrt(acc / r), v / r)))
    return _DENSE_OUTPUT_SAFETY * (_QUINTIC_ERROR_DIVISOR * rtol) ** (1.0 / 6.0) / w if w > 0 else np.inf


def propagate_adaptive(scenario, precision, model, epoch, tab, y0_dd, sink, progress, system):
    """Embedded-error step-size control (7th-order estimate, local error
    per step <= rtol * |r| and rtol * |v| per body), output sampled on the
    grid k * integrator.step_s by quintic Hermite dense output.  Time is
    tracked as an exact rational (each step is an exact binary float)."""
    rtol = float(scenario.integrator.rtol)
    T = Fraction(scenario.run.duration_s)
    dt_out = Fraction(scenario.integrator.step_s)
    unit = dp87.step_coefficients(tab, 1, precision)  # h = 1: the bare tableau
    c_nodes = [Fraction(x) for x in unit.c]
    y, comp, K, ystage, err = _workspace(y0_dd, precision)
    ha = np.zeros_like(unit.ha)
    hb = np.zeros_like(unit.hb)
    z = np.array([0.0, 1.0])
    nb = y.shape[0]
    rows: list = []
    cpar = system.cpar
    gw, fw, aux = _lay.workspace(y, cpar)
    kernel = chunk_kernel(fw)  # one step per call: the fixed-step kernel, its rows unused
    out_y1, out_a1, no_aux = np.empty((1,) + y.shape), np.empty((1, nb, 3) + y.shape[2:]), np.empty((0, _lay.AUX_LEN))

    def flush(force=False):
        if sink is not None and rows and (force or len(rows) >= DEFAULT_CHUNK):
            t_arr = np.array([r[0] for r in rows])
            y_arr = np.stack([r[1] for r in rows])
            a_arr = np.stack([r[2] for r in rows])
            aux_arr = np.stack([r[3] for r in rows])
            sink(select_rows(t_arr, y_arr, a_arr, precision, 1, 0, aux_arr, system))
            rows.clear()

    def emit(t_exact, y_row):
        k_row, aux_row = evaluate_rhs(y_row, _node_tdat(model, epoch, [t_exact])[0], model, cpar, with_aux=True)
        rows.append((_dd_of(t_exact), y_row.copy(), k_row[:, 3:6].copy(), aux_row))
        flush()

    t_start = _time.perf_counter()
    t = Fraction(0)
    k_out = 1
    emit(t, y)
    h_max = _dense_output_max_step(y, rows[0][2] if rows else evaluate_rhs(y, _node_tdat(model, epoch, [t])[0], model,
                                                                            cpar)[:, 3:6], rtol)
    h = min(float(min(dt_out, T)), h_max)
    n_acc = n_rej = n_rhs = 0
    while t < T:
        last = Fraction(h) >= T - t
        h_exact = T - t if last else Fraction(h)
        h_pair = np.array(_dd_of(h_exact))
        _scale_tableau(unit.ha, unit.hb, (h_pair[0], h_pair[1]) if precision == "dd" else h_pair[0], ha, hb)
        he = unit.he * float(h_exact)
        tdat = _node_tdat(model, epoch, [t + ci * h_exact for ci in c_nodes])
        y_try, comp_try = y.copy(), comp.copy()
        kernel(y_try, comp_try, K, ystage, err, ha, unit.nz, unit.nnz, hb, unit.nzb, unit.nnzb, he,
               np.ascontiguousarray(tdat)[None], model.params, model.kernel_layout, cpar, aux, gw, fw, 1, out_y1,
               out_a1, no_aux)
        n_rhs += 13
        norm = dp87.error_norm(y_try, err, rtol)
        if not (np.isfinite(norm) and np.isfinite(y_try).all()):  # no step size makes it finite: stop here
            t_try = _dd_of(t + h_exact)
            check_finite_states(n_acc + 1, np.array([t_try]), y_try[None])
            raise NonFiniteStateError(n_acc + 1, t_try[0] + t_try[1], int(np.argmax(~np.isfinite(err).all(axis=1))))
        if norm <= 1.0:
            t_new = t + h_exact
            a0 = K[0][:, 3:6].copy()
            a1 = evaluate_rhs(y_try, _node_tdat(model, epoch, [t_new])[0], model, cpar)[:, 3:6]
            n_rhs += 1
            while k_out * dt_out <= t_new:
                t_k = k_out * dt_out
                if t_k == t_new:
                    y_k = y_try
                else:
                    s_pair = _dd_of((t_k - t) / h_exact)
                    y_k = np.empty_like(y)
                    s = (s_pair[0], s_pair[1]) if precision == "dd" else s_pair[0]
                    hh = (h_pair[0], h_pair[1]) if precision == "dd" else h_pair[0]
                    for b in range(nb):
                        nodes_r = np.stack([y[b, 0:3], y_try[b, 0:3]])
                        nodes_v = np.stack([y[b, 3:6], y_try[b, 3:6]])
                        nodes_a = np.stack([a0[b], a1[b]])
                        hermite.hermite_eval(z, nodes_r, nodes_v, nodes_a, hh, s, y_k[b, 0:3], y_k[b, 3:6])
                emit(t_k, y_k)
                k_out += 1
            if progress is not None:
                progress(float(h_exact))
            t, y, comp = t_new, y_try, comp_try
            n_acc += 1
            h_max = _dense_output_max_step(y, a1, rtol)
        else:
            n_rej += 1
        h = min(h * dp87.next_step_factor(norm), h_max)
    flush(force=True)
    wall = _time.perf_counter() - t_start
    return RunResult(precision=precision, mode="adaptive", t_final=np.array(_dd_of(t)), y0=y0_dd,
                     y_final=to_dd(y, 2), n_steps=n_acc, n_rejected=n_rej, n_rhs=n_rhs, wall_s=wall)
