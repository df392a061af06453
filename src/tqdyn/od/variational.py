"""Variational equations of point-mass runs: the satellites' states and their partial
derivatives with respect to the initial states and the acceleration parameters.

Interface (what an estimator calls in its Gauss-Newton loop)
------------------------------------------------------------
``propagate_with_partials(scenario, parameters, t_out)`` -> :class:`Partials`: given
parameter values (:class:`~tqdyn.od.parameters.OrbitParameters`: initial states and the
(n_sat, 12) acceleration parameters; None = the scenario's), the double-double propagation
of the scenario with those values and, integrated beside it in float64, the state transition
matrix and the sensitivities, at the requested times:

* ``t`` (n,) [s since the epoch, the run's time scale (TT geocentric, TDB heliocentric)];
* ``states`` (n, n_sat, 6) float64 and ``states_dd`` (n, n_sat, 6, 2) [m, m/s, the run's
  frame: GCRS geocentric, BCRS axes Sun-centred heliocentric], from the dd propagation;
* ``stm`` (n, n_sat, 6, 6): d state_b(t) / d state_b(0) of each satellite b;
* ``sensitivities`` (n, n_sat, 6, 12): d state_b(t) / d p_b for its own 12 parameters
  ``parameter_names`` (:data:`~tqdyn.dynamics.empirical.PARAMETER_NAMES`) [s^2, s];
* ``stm_full`` (n, 6 n_sat, 6 n_sat) and ``sensitivities_full`` (n, 6 n_sat, 12 n_sat):
  the same for the whole system (the S frame and the self-gravity toward the centre couple
  the satellites; their blocks off the diagonal are at most ~ (p / L) t^2, p the coupling
  acceleration and L the arm length);
  rows and columns ordered satellite by satellite (:func:`~tqdyn.od.parameters.state_names`,
  :func:`~tqdyn.od.parameters.parameter_names`).

``propagate_dd(scenario, parameters, t_out)`` is the dd propagation alone (the truth run of
simulated tracking with injected values).  t_out must lie on the integrator's step grid
(multiples of ``integrator.step``, fixed mode); the partials use their own fixed step
(``step``: default the run's), a multiple of the run's step that divides every t_out.

Equations
---------
With y = (r, v) of all satellites, y' = f(t, y, p) = (v, a(t, r, v) + B(y) p):

    Phi' = A Phi,  Phi(0) = I;   Psi' = A Psi + [0; B],  Psi(0) = 0;   A = df/dy,

integrated with the DP87 tableau of the run (float64, fixed step) together with a float64
copy of the orbit, whose Jacobian A is taken.  A is the Jacobian of the *whole* right-hand
side of the propagation (:func:`tqdyn.dynamics.rhs.point_mass_system` in float64: the
scenario's full force model, the self-gravity ramp, the parameter accelerations): its
acceleration rows by central differences with steps 6e-6 |r_b| and 6e-6 |v_b| (relative
error ~ (h/r)^2 + eps r/h ~ 1e-10: truncation and round-off balanced), its position rows
exactly (dr/dt = v).  B = da/dp is exact (the acceleration is linear in p).  Neglected:
nothing of the model; the float64 orbit of the partials differs from the dd orbit by
float64 round-off (~1e-13 relative), which changes A by as little.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import dynamics
from ..dynamics.empirical import N_PAR, PARAMETER_NAMES, add_empirical, empirical_basis
from ..dynamics.rhs import point_mass_system, toward_centre
from ..dynamics.results import Rows
from ..dynamics.system import build_system
from ..dynamics import layout as _lay
from ..forces.model import build_force_model
from ..numerics import dp87
from ..scenario import load_scenario
from .parameters import OrbitParameters, per_satellite_names, scenario_with, state_names

__all__ = ["Partials", "off_grid", "propagate_dd", "propagate_with_partials"]

_FD_REL = 6e-6  # central-difference step relative to |r|, |v| (eps^(1/3))
_BLOCK = 256    # steps per evaluation of the time-only inputs


@dataclass
class Partials:
    """States and partials on the requested times (module docstring for shapes and units)."""

    t: np.ndarray
    states: np.ndarray
    states_dd: np.ndarray
    stm: np.ndarray
    sensitivities: np.ndarray
    stm_full: np.ndarray
    sensitivities_full: np.ndarray
    satellites: tuple
    parameter_names: tuple = PARAMETER_NAMES

    @classmethod
    def from_full(cls, t, states_dd, stm_full, sensitivities_full, satellites,
                  parameter_names=PARAMETER_NAMES) -> "Partials":
        """The Partials of the full-system matrices stm_full (n, 6 n_sat, 6 n_sat) and
        sensitivities_full (n, 6 n_sat, p n_sat) at t (n,) [s], with the dd states (n, n_sat, 6, 2):
        ``stm`` and ``sensitivities`` are their diagonal blocks, satellite by satellite."""
        n_sat, n_p = states_dd.shape[1], len(parameter_names)
        stm = np.empty((len(t), n_sat, 6, 6))
        sens = np.empty((len(t), n_sat, 6, n_p))
        for b in range(n_sat):
            stm[:, b] = stm_full[:, 6 * b:6 * b + 6, 6 * b:6 * b + 6]
            sens[:, b] = sensitivities_full[:, 6 * b:6 * b + 6, n_p * b:n_p * (b + 1)]
        return cls(t=t, states=states_dd[..., 0] + states_dd[..., 1], states_dd=states_dd, stm=stm,
                   sensitivities=sens, stm_full=stm_full, sensitivities_full=sensitivities_full,
                   satellites=tuple(satellites), parameter_names=tuple(parameter_names))

    @property
    def full_parameter_names(self) -> list[str]:
        """Column names of ``sensitivities_full``."""
        return per_satellite_names(self.satellites, self.parameter_names)

    @property
    def full_state_names(self) -> list[str]:
        """Row / column names of ``stm_full``."""
        return state_names(self.satellites)


def _load(scenario):
    return load_scenario(scenario) if isinstance(scenario, str) else scenario


def off_grid(t, step: float) -> np.ndarray:
    """True where t [s] (n,) is not a non-negative multiple of step [s] (to 1e-9 relative, 1e-9 s
    below 1 s: the 1 ns digits of a measurement file's epochs)."""
    t = np.asarray(t, np.float64)
    k = np.rint(t / step)
    return ~np.isfinite(t) | (k < 0) | (np.abs(k * step - t) > 1e-9 * np.maximum(1.0, np.abs(t)))


def _grid(t_out, step: float, name: str) -> np.ndarray:
    """Step indices of t_out [s] on the grid k step (ValueError naming ``name`` otherwise)."""
    t = np.atleast_1d(np.asarray(t_out, np.float64))
    if t.ndim != 1:
        raise ValueError(f"t_out: shape {t.shape}; allowed: a 1-D array of times [s]")
    bad = np.flatnonzero(off_grid(t, step))
    if bad.size:
        raise ValueError(f"t_out: {bad.size} of {t.size} times are not on the grid of {name} = {step} s, the first "
                         f"t_out[{bad[0]}] = {t[bad[0]]!r} s; allowed: non-negative multiples of {step} s")
    return np.rint(t / step).astype(np.int64)


def propagate_dd(scenario, parameters: OrbitParameters | None = None, t_out=None):
    """The scenario's double-double propagation with the parameter values, sampled at t_out
    [s since the epoch] (default: every step of the scenario's run).  Returns (t (n,),
    states_dd (n, n_sat, 6, 2) [m, m/s, the run's frame])."""
    scen = _load(scenario)
    if scen.integrator.mode != "fixed":
        raise ValueError('integrator.mode: "adaptive" has no step grid for t_out; allowed: "fixed"')
    step = float(scen.integrator.step_s)
    if t_out is None:
        t_out = np.arange(scen.n_steps + 1) * step
    idx = _grid(t_out, step, "integrator.step")
    n_end = max(int(idx.max()), 1)
    par = parameters or OrbitParameters()
    scen = scenario_with(scen, par.accelerations, n_end * step, par.self_gravity_common)
    scen = _with_every_step(scen)
    blocks = []
    result = dynamics.propagate(scen, sink=blocks.append, y0=par.y0_dd())
    rows = Rows.concatenate(blocks)
    r = np.stack(rows.sat_r, axis=-1)
    v = np.stack(rows.sat_v, axis=-1)
    y = np.concatenate([r, v], axis=2)  # (m, n_sat, 6, 2) on steps 0 .. m-1
    if y.shape[0] < n_end + 1:
        y = np.concatenate([y, np.asarray(result.y_final, np.float64)[None, :y.shape[1]]])
    return idx * step, y[idx]


def _with_every_step(scen):
    return dataclasses.replace(scen, run=dataclasses.replace(scen.run, output_every=1))


def propagate_with_partials(scenario, parameters: OrbitParameters | None = None, t_out=None,
                            step: float | None = None) -> Partials:
    """States (dd propagation) and partials (float64 variational equations) at t_out
    [s since the epoch] of a point-mass scenario; see the module docstring."""
    scen = _load(scenario)
    par = parameters or OrbitParameters()
    t, y_dd = propagate_dd(scen, par, t_out)
    run_step = float(scen.integrator.step_s)
    h = run_step if step is None else float(step)
    if abs(h / run_step - round(h / run_step)) > 1e-12:
        raise ValueError(f"step: {step} s is not a multiple of integrator.step = {run_step} s")
    idx = _grid(t, h, "step")
    sv = scenario_with(scen, par.accelerations)
    model = build_force_model(sv.forces, sv.reference)
    system = build_system(sv, model)
    if system.coupled:
        raise ValueError('constellation.pointing: the variational equations need point-mass satellites; '
                         'allowed: "none"')
    model = system.with_inputs(model)
    y0 = par.y0_dd()
    if y0 is None:
        y0 = dynamics.initial_state(sv, model, system)
    phi, psi = _integrate(sv, model, system, y0[..., 0] + y0[..., 1], h, int(idx.max()))
    return Partials.from_full(t, y_dd, phi[idx], psi[idx], [s.name for s in sv.satellites])


def _integrate(scen, model, system, y0, h: float, n_steps: int):
    """Phi (n_steps + 1, 6 n, 6 n) and Psi (n_steps + 1, 6 n, 12 n) on the grid k h."""
    n = y0.shape[0]
    coef = dp87.step_coefficients(dp87.load_tableau(scen.integrator.tableau), repr(h), "float64")
    cpar = system.cpar
    emp = _lay.empirical_of(cpar, N_PAR)
    coupled = bool(np.any(emp[:, :3] != 0.0)) or system.centre_ramp is not None  # satellites interact
    with_s = n == 3  # the S-frame columns of B
    y = np.ascontiguousarray(y0, np.float64)
    phi = np.eye(6 * n)
    psi = np.zeros((6 * n, N_PAR * n))
    out_phi = np.empty((n_steps + 1, 6 * n, 6 * n))
    out_psi = np.empty((n_steps + 1, 6 * n, N_PAR * n))
    out_phi[0], out_psi[0] = phi, psi
    for k0 in range(0, n_steps, _BLOCK):
        m = min(_BLOCK, n_steps - k0)
        t = (np.arange(k0, k0 + m)[:, None] + coef.c[None, :]) * h
        tdat = (model.precompute(scen.epoch, t, np.zeros_like(t)) if model.time_dependent
                else np.zeros(t.shape + (0,)))
        _steps(y, phi, psi, coef.ha, coef.hb, np.ascontiguousarray(tdat), model.params, model.layout, cpar,
               coupled, with_s, m, out_phi[k0 + 1:k0 + 1 + m], out_psi[k0 + 1:k0 + 1 + m])
    return out_phi, out_psi


@njit(cache=True)
def _coupling_terms(y, tdat, cpar, k):
    """k <- the accelerations through which the satellites act on each other (float64): the
    self-gravity toward the centre and the parameter accelerations (their S frame); gravity
    is left out, so that a difference of k has no round-off of the ~1e-2 m/s^2 gravity."""
    for b in range(k.shape[0]):
        for q in range(6):
            k[b, q] = 0.0
    if cpar[_lay.CP_SGC] >= 0.0:
        toward_centre(y, tdat[int(cpar[_lay.CP_SGC])], k)
    if cpar.shape[0] > _lay.CP_LEN:
        add_empirical(y, cpar[_lay.CP_LEN:].reshape(((cpar.shape[0] - _lay.CP_LEN) // N_PAR, N_PAR)), k)


@njit(cache=True)
def _derivs(y, phi, psi, tdat, params, layout, cpar, coupled, with_s, dy, dphi, dpsi):
    """dy, dphi, dpsi of the augmented system at one instant (float64)."""
    n = y.shape[0]
    point_mass_system(y, tdat, params, layout, cpar, dy)
    A = np.zeros((3 * n, 6 * n))  # acceleration rows of df/dy
    kp = np.empty_like(y)
    km = np.empty_like(y)
    yp = y.copy()
    for q in range(6):
        for b in range(n if coupled else 1):
            for c in range(n):
                for s in range(6):
                    yp[c, s] = y[c, s]
            hs = np.empty(n)
            for c in range(n):
                if coupled and c != b:
                    continue
                o = 0 if q < 3 else 3
                hs[c] = _FD_REL * np.sqrt(y[c, o] ** 2 + y[c, o + 1] ** 2 + y[c, o + 2] ** 2)
                yp[c, q] = y[c, q] + hs[c]
            point_mass_system(yp, tdat, params, layout, cpar, kp)
            for c in range(n):
                if coupled and c != b:
                    continue
                yp[c, q] = y[c, q] - hs[c]
            point_mass_system(yp, tdat, params, layout, cpar, km)
            for c in range(n):
                if coupled and c != b:
                    continue
                for s in range(3):
                    A[3 * c + s, 6 * c + q] = (kp[c, 3 + s] - km[c, 3 + s]) / (2.0 * hs[c])
            if coupled:  # the other satellites' rows: differences of the coupling terms alone
                _coupling_terms(yp, tdat, cpar, km)
                yp[b, q] = y[b, q] + hs[b]
                _coupling_terms(yp, tdat, cpar, kp)
                for r in range(n):
                    if r != b:
                        for s in range(3):
                            A[3 * r + s, 6 * b + q] = (kp[r, 3 + s] - km[r, 3 + s]) / (2.0 * hs[b])
    B = np.empty((3, N_PAR))
    for r in range(n):
        for s in range(3):
            for j in range(phi.shape[1]):
                dphi[6 * r + s, j] = phi[6 * r + 3 + s, j]
            for j in range(psi.shape[1]):
                dpsi[6 * r + s, j] = psi[6 * r + 3 + s, j]
        empirical_basis(y, r, with_s, B)
        for s in range(3):
            row = A[3 * r + s]
            for j in range(phi.shape[1]):
                acc = 0.0
                for m in range(6 * n):
                    acc += row[m] * phi[m, j]
                dphi[6 * r + 3 + s, j] = acc
            for j in range(psi.shape[1]):
                acc = 0.0
                for m in range(6 * n):
                    acc += row[m] * psi[m, j]
                dpsi[6 * r + 3 + s, j] = acc
            for j in range(N_PAR):
                dpsi[6 * r + 3 + s, N_PAR * r + j] += B[s, j]


@njit(cache=True)
def _steps(y, phi, psi, ha, hb, tdat, params, layout, cpar, coupled, with_s, m, out_phi, out_psi):
    """m fixed DP87 steps of the augmented system in place, recording Phi and Psi after each."""
    ns = hb.shape[0]
    Ky = np.zeros((ns,) + y.shape)
    Kphi = np.zeros((ns,) + phi.shape)
    Kpsi = np.zeros((ns,) + psi.shape)
    for k in range(m):
        for i in range(ns):
            ys, phs, pss = y.copy(), phi.copy(), psi.copy()
            for j in range(i):
                a = ha[i, j]
                if a != 0.0:
                    ys += a * Ky[j]
                    phs += a * Kphi[j]
                    pss += a * Kpsi[j]
            _derivs(ys, phs, pss, tdat[k, i], params, layout, cpar, coupled, with_s, Ky[i], Kphi[i], Kpsi[i])
        for i in range(ns):
            if hb[i] != 0.0:
                y += hb[i] * Ky[i]
                phi += hb[i] * Kphi[i]
                psi += hb[i] * Kpsi[i]
        out_phi[k] = phi
        out_psi[k] = psi
