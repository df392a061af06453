"""Variational equations of coupled runs (attitude, test masses, drag-free and suspension
control): the state transition matrix and the sensitivities to the common self-gravity of
each satellite's test masses, propagated with the coupled dynamics.

State and parameters.  A coupled run without free test masses propagates the three satellites'
orbits y = (r_i, v_i) (18 values, the run's frame); attitude (the pointing law's T_S_I, omega,
omega_dot, MOSA angles), the test masses' positions (their electrode-housing centres) and the
drag-free and suspension control are functions of y and t evaluated inside the right-hand side
(:func:`tqdyn.dynamics.rhs.coupled_rhs`), so y is the whole state of the coupled system:

    y' = f(t, y, p) = (v, a(t, r, v) + G(t, y, p)),

a the scenario's force model at the satellites, G the drag-free acceleration of each satellite
(which depends on all three orbits through the beam directions of the attitude), p the (3, 3)
common self-gravity ``spacecraft.self_gravity_common`` [m/s^2 in S].  With A = df/dy (18 x 18)
and B = df/dp (18 x 9):

    Phi' = A Phi,  Phi(0) = I;    Psi' = A Psi + B,  Psi(0) = 0.

Jacobians.  A and B are taken on the dd run of the scenario (its own step) at nodes every
``node_step`` [s], by central differences of the float64 coupled right-hand side: each state
component of each satellite stepped by +-6e-6 |r_b| or +-6e-6 |v_b| (relative error
~ (h/r)^2 + eps r/h ~ 1e-10), each self-gravity component by +2^-30 m/s^2 (forward: G is linear
in it, the attitude's feedback included).  The acceleration rows are differenced as
gravity plus drag-free acceleration apart, so that the rows of the other satellites (G alone,
~1e-18 of a metre's step) carry no round-off of the ~4e-2 m/s^2 gravity.  Between the nodes A and
B are interpolated at the integrator's stage times by Lagrange polynomials through the 12 nearest
nodes (A and B change on the orbital time scale, days; on TianQin over 10 days the partials agree
with central differences to 9e-10 with nodes every 3600 s and 5400 s, 1.6e-8 at 7200 s; through
8 nodes, 4.5e-8 at 3600 s).

Integration.  The linear system is integrated with the DP87 tableau of the run at the
partials' step h (fixed): each step is the affine map Y(n+1) = M_n Y(n) + N_n of the tableau
applied to Y' = A(t) Y + F(t), whose M_n, N_n are formed for all steps at once.

Cost: per node, 46 dd evaluations of the coupled right-hand side (36 for A, 10 for B), no
further propagation: one dd run gives the states and the nodes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..dynamics.layout import CP_CONTROL, CP_SG_S, workspace
from ..dynamics.rhs import coupled_rhs
from ..dynamics.system import build_system
from ..forces.model import build_force_model
from ..numerics import dp87
from .parameters import OrbitParameters, scenario_with
from .variational import Partials, _grid, propagate_dd

__all__ = ["NODE_STEP_MAX", "jacobians", "propagate_with_partials"]

_FD_REL = 6e-6                 # difference step of the states relative to |r_b|, |v_b| (eps^(1/3))
_STEP_COMMON = 2.0 ** -30      # difference step of the common self-gravity [m/s^2]
_ORDER = 12                    # nodes per interpolating polynomial
_CHUNK = 512                   # steps whose maps are formed at once
#: Largest spacing [s] of the Jacobian nodes by default (a multiple of the partials' step; module
#: docstring for the error against it).
NODE_STEP_MAX = 5400.0


@njit(cache=True)
def _accelerations(gw, gi, control, out):
    """out (3, 3, 2) <- gravity at the satellites (dd) and (control on) their drag-free
    acceleration (float64), apart."""
    for c in range(3):
        for s in range(3):
            out[c, s, 0] = gw[c, s, 0]
            out[c, s, 1] = gw[c, s, 1] + (gi[c, s] if control else 0.0)


@njit(cache=True)
def _node_jacobians(ys, tdat, params, layout, cpar, rel, gw, fw, aux, out):
    """out (n, 9, 27) <- the acceleration rows of [A | B] at each node: columns the 18 states
    (satellite by satellite, x y z vx vy vz) then the 9 common self-gravity components; ys (n, 3, 6, 2)
    dd states, tdat (n, n_tdat) their time-only inputs, rel the states' difference step relative
    to |r_b|, |v_b|."""
    control = cpar[CP_CONTROL] != 0.0
    k = np.empty((3, 6, 2))
    ap = np.empty((3, 3, 2))
    am = np.empty((3, 3, 2))
    cp = cpar.copy()
    for n in range(ys.shape[0]):
        y = ys[n].copy()
        td = tdat[n]
        for b in range(3):
            for q in range(6):
                o = 0 if q < 3 else 3
                h = rel * np.sqrt(ys[n, b, o, 0] ** 2 + ys[n, b, o + 1, 0] ** 2 + ys[n, b, o + 2, 0] ** 2)
                y[b, q, 0] = ys[n, b, q, 0] + h
                coupled_rhs(y, td, params, layout, cpar, k, aux, gw, fw)
                _accelerations(gw, fw[18], control, ap)
                den = y[b, q, 0]
                y[b, q, 0] = ys[n, b, q, 0] - h
                den -= y[b, q, 0]          # the step actually taken (exact)
                coupled_rhs(y, td, params, layout, cpar, k, aux, gw, fw)
                _accelerations(gw, fw[18], control, am)
                y[b, q, 0] = ys[n, b, q, 0]
                for c in range(3):
                    for s in range(3):   # gravity (dd) and G apart: a row of another satellite is G's alone
                        out[n, 3 * c + s, 6 * b + q] = ((ap[c, s, 0] - am[c, s, 0]) + (ap[c, s, 1] - am[c, s, 1])) / den
        coupled_rhs(y, td, params, layout, cpar, k, aux, gw, fw)
        _accelerations(gw, fw[18], control, am)
        for j in range(9):     # G is linear in the common self-gravity: forward differences
            cp[CP_SG_S + j] = cpar[CP_SG_S + j] + _STEP_COMMON
            coupled_rhs(y, td, params, layout, cp, k, aux, gw, fw)
            _accelerations(gw, fw[18], control, ap)
            cp[CP_SG_S + j] = cpar[CP_SG_S + j]
            for c in range(3):
                for s in range(3):
                    out[n, 3 * c + s, 18 + j] = (((ap[c, s, 0] - am[c, s, 0]) + (ap[c, s, 1] - am[c, s, 1]))
                                                 / _STEP_COMMON)


def jacobians(scen, t, states, self_gravity_common=None, rel: float = _FD_REL) -> np.ndarray:
    """The acceleration rows of [df/dy | df/dp] (module docstring) of the coupled scenario at
    times t (n,) [s since the epoch] and dd states (n, 3, 6, 2) [m, m/s, the run's frame]:
    (n, 9, 27) [1/s^2, 1/s; 1 (m/s^2 per m/s^2 in S)], rows satellite by satellite (ax, ay, az),
    columns the 18 states then the 9 common self-gravity components (satellite by satellite,
    S axes).  self_gravity_common: (3, 3) [m/s^2 in S] (None: the scenario's)."""
    sv = scenario_with(scen, None, None, self_gravity_common)
    model = build_force_model(sv.forces, sv.reference)
    system = build_system(sv, model)
    model = system.with_inputs(model)
    t = np.asarray(t, np.float64)
    tdat = (model.precompute(sv.epoch, t, np.zeros_like(t)) if model.time_dependent
            else np.zeros(t.shape + (0,)))
    ys = np.ascontiguousarray(states, np.float64)
    gw, fw, aux = workspace(ys[0], system.cpar)
    out = np.empty((t.size, 9, 27))
    _node_jacobians(ys, np.ascontiguousarray(tdat), model.params, model.layout, system.cpar, float(rel), gw, fw, aux,
                    out)
    return out


def _lagrange(tau, n_nodes: int, order: int):
    """Stencil start (m,) and weights (m, order) of the Lagrange polynomial through the ``order``
    nodes nearest each tau (m,) [in node spacings]."""
    k = np.floor(tau).astype(np.int64)
    start = np.clip(k - (order // 2 - 1), 0, n_nodes - order)
    x = tau - start
    j = np.arange(order)
    w = np.ones((tau.size, order))
    for m in range(order):
        other = j != m
        w[:, other] *= ((x[:, None] - m) / (j[other] - m))[:, :]
    return start, w


def _affine_maps(jac, node_step: float, h: float, n_steps: int, tableau: str):
    """M (n_steps, 18, 18) and N (n_steps, 18, 9) of the DP87 steps of Y' = A Y + F (module
    docstring), A and F interpolated from the node rows jac (n_nodes, 9, 27)."""
    coef = dp87.step_coefficients(dp87.load_tableau(tableau), repr(h), "float64")
    ha, hb, c = coef.ha, coef.hb, coef.c
    ns = hb.shape[0]
    order = min(_ORDER, jac.shape[0])
    rows = np.array([6 * b + 3 + s for b in range(3) for s in range(3)])
    eye = np.eye(18)
    M = np.empty((n_steps, 18, 18))
    N = np.empty((n_steps, 18, 9))
    for k0 in range(0, n_steps, _CHUNK):
        m = min(_CHUNK, n_steps - k0)
        P, Q = [], []
        for i in range(ns):
            tau = ((np.arange(k0, k0 + m) + c[i]) * h) / node_step
            start, w = _lagrange(tau, jac.shape[0], order)
            J = np.einsum("mk,mkrc->mrc", w, jac[start[:, None] + np.arange(order)[None, :]])
            A = np.zeros((m, 18, 18))
            for b in range(3):
                for s in range(3):
                    A[:, 6 * b + s, 6 * b + 3 + s] = 1.0
            A[:, rows, :] = J[:, :, :18]
            F = np.zeros((m, 18, 9))
            F[:, rows, :] = J[:, :, 18:]
            X, Z = np.broadcast_to(eye, (m, 18, 18)).copy(), np.zeros((m, 18, 9))
            for j in range(i):
                if ha[i, j] != 0.0:
                    X += ha[i, j] * P[j]
                    Z += ha[i, j] * Q[j]
            P.append(A @ X)
            Q.append(A @ Z + F)
        M[k0:k0 + m] = eye + sum(hb[i] * P[i] for i in range(ns) if hb[i] != 0.0)
        N[k0:k0 + m] = sum(hb[i] * Q[i] for i in range(ns) if hb[i] != 0.0)
    return M, N


def default_node_step(h: float, span: float = np.inf) -> float:
    """The largest multiple of the partials' step h [s] at most :data:`NODE_STEP_MAX` and, over a
    short span [s], at most span / 11, so that 12 nodes interpolate (h itself when h is larger)."""
    return h * max(1, int(min(NODE_STEP_MAX, span / (_ORDER - 1)) // h))


def propagate_with_partials(scen, parameters: OrbitParameters, self_gravity_common, t_out, parameter_names,
                            step: float | None = None, node_step: float | None = None) -> Partials:
    """States at t_out [s since the epoch] (the dd run at the run's step) and their partials by
    the coupled variational equations (module docstring) of the coupled scenario (checked by the
    caller, :func:`tqdyn.od.coupled.propagate_with_partials`) with the parameter values
    (``self_gravity_common``: their (3, 3) values [m/s^2 in S], resolved), integrated with
    ``step`` [s] (None: the run's; a multiple of it dividing every t_out), Jacobians at nodes
    every ``node_step`` [s] (None: :func:`default_node_step`; a multiple of step): a
    :class:`~tqdyn.od.variational.Partials` with ``parameter_names`` the names of the
    self-gravity components."""
    par = parameters
    run_step = float(scen.integrator.step_s)
    h = run_step if step is None else float(step)
    if abs(h / run_step - round(h / run_step)) > 1e-12:
        raise ValueError(f"step: {step} s is not a multiple of integrator.step = {run_step} s")
    t_req = np.atleast_1d(np.asarray(t_out, np.float64))
    idx = _grid(t_req, h, "step")
    n_steps = max(int(idx.max()), 1)
    H = default_node_step(h, n_steps * h) if node_step is None else float(node_step)
    if abs(H / h - round(H / h)) > 1e-12:
        raise ValueError(f"node_step: {node_step} s is not a multiple of the partials' step {h} s")
    n_nodes = max(int(np.ceil(n_steps * h / H - 1e-9)) + 1, 2)
    t_nodes = np.arange(n_nodes) * H
    t_all, inv = np.unique(np.concatenate([idx * h, t_nodes]), return_inverse=True)
    _, y_all = propagate_dd(scen, par, t_all)
    y_out, y_nodes = y_all[inv[:t_req.size]], y_all[inv[t_req.size:]]
    jac = jacobians(scen, t_nodes, y_nodes, self_gravity_common)
    M, N = _affine_maps(jac, H, h, n_steps, scen.integrator.tableau)
    phi = np.empty((n_steps + 1, 18, 18))
    psi = np.empty((n_steps + 1, 18, 9))
    phi[0], psi[0] = np.eye(18), 0.0
    for k in range(n_steps):
        phi[k + 1] = M[k] @ phi[k]
        psi[k + 1] = M[k] @ psi[k] + N[k]
    return Partials.from_full(idx * h, y_out, phi[idx], psi[idx], [s.name for s in scen.satellites],
                              parameter_names)
