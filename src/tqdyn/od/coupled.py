"""Partials of coupled runs (attitude, test masses, drag-free and suspension control) for orbit
determination: by the coupled variational equations (:mod:`.coupled_variational`, the default) or
by central differences of double-double propagations (the reference, below).

Parameters of a coupled run, per satellite (:func:`parameter_names`, column order of
``sensitivities_full``): the initial state x, y, z [m], vx, vy, vz [m/s] at the epoch (the run's
frame) and ``sgc_x``, ``sgc_y``, ``sgc_z`` [m/s^2 in the satellite frame S]: the row of
``spacecraft.self_gravity_common``, the DC acceleration common to both test masses of the
satellite, which the drag-free control hands on to the orbit.

Central differences.  The partials are those of the full coupled dynamics of
:func:`tqdyn.dynamics.propagate` (the scenario's force model, attitude, test masses and control,
nothing linearised):

    d y(t) / d p_j = (y(t; p + h_j e_j) - y(t; p - h_j e_j)) / (2 h_j),

each y a double-double run of the scenario with the perturbed value, differenced in dd.  The
steps are powers of two (:data:`STEP_POSITION`, :data:`STEP_VELOCITY`, :data:`STEP_COMMON`), so
that a perturbed initial state is exact; the denominator is the float64 difference of the two
values actually used.  Truncation: the response is linear up to relative terms ~ (h / r)^2 ~ 1e-16
for the states and ~ (h t^2 / L)^2 for the common self-gravity (L the arm length; < 1e-15 over a
day), round-off: the dd runs' float64 force terms (~1e-22 m/s^2 of difference noise), far below
both.  The differenced runs use the partials' own step (:func:`tqdyn.od.problem` passes the
largest multiple of the run's step dividing the time tags, at most 600 s geocentric), the nominal
states the run's own step.

Cost: 2 runs per parameter (18 state + 9 self-gravity columns for three satellites: 54 runs per
evaluation of the Jacobian, each the length of the arc); the variational equations take one run
and 46 evaluations of the right-hand side per Jacobian node.  The two agree to ~1e-9 of each
column's largest value over 10 days (tests/test_od_coupled.py).
"""

from __future__ import annotations

import contextlib
import contextvars

import numpy as np

from . import coupled_variational
from .parameters import OrbitParameters, per_satellite_names, scenario_with
from .tracking import fail
from .variational import Partials, propagate_dd

__all__ = ["COMMON_NAMES", "METHODS", "STEP_COMMON", "STEP_POSITION", "STEP_VELOCITY", "check_scenario", "method",
           "nominal_common", "parameter_names", "propagate_with_partials"]

#: Methods of the partials: the coupled variational equations (:mod:`.coupled_variational`) or
#: central differences of dd runs.
METHODS = ("variational", "differences")
_METHOD = contextvars.ContextVar("coupled_partials_method", default="variational")
#: Names of the per-satellite common self-gravity parameters [m/s^2 in S].
COMMON_NAMES = ("sgc_x", "sgc_y", "sgc_z")
#: Central-difference steps: initial position [m], velocity [m/s], common self-gravity [m/s^2].
STEP_POSITION = 1.0
STEP_VELOCITY = 2.0 ** -13          # 1.22e-4 m/s
STEP_COMMON = 2.0 ** -30            # 9.31e-10 m/s^2


def check_scenario(scen) -> None:
    """One-line ValueError unless the coupled scenario's satellites are its whole state (three
    satellites, no free test masses)."""
    if scen.constellation.free_tms:
        fail(f"scenario {scen.name!r}: constellation.free_tms = true propagates the test masses as free "
              f"bodies; orbit determination of a coupled run needs free_tms = false")
    if len(scen.satellites) != 3:
        fail(f"scenario {scen.name!r}: a coupled run of {len(scen.satellites)} satellites; allowed: 3")


def parameter_names(satellites) -> list[str]:
    """``"<sat>/sgc_x"`` ... of every common self-gravity parameter, satellite by satellite
    (satellites: names, or a scenario)."""
    return per_satellite_names(satellites, COMMON_NAMES)


def nominal_common(scen) -> np.ndarray:
    """The scenario's ``spacecraft.self_gravity_common``, (n_sat, 3) float64 [m/s^2 in S]."""
    return scen.spacecraft.self_gravity_values()[1][:len(scen.satellites)]


def _runs(scen, par: OrbitParameters, t, step: float):
    """The dd states (n, n_sat, 6, 2) of the scenario at t with the parameter values, integrated
    with ``step`` [s]."""
    return propagate_dd(scenario_with(scen, step_s=step), par, t)[1]


@contextlib.contextmanager
def method(name: str):
    """Within the ``with`` block, the partials of coupled runs that name no method (those of
    :mod:`tqdyn.od.problem`'s fits, covariances and computed measurements) are made by
    ``name``, one of :data:`METHODS`::

        with coupled.method("differences"):
            est = problem.fit("tianqin", meas, tracking)
    """
    if name not in METHODS:
        fail(f"method: {name!r}; allowed: {', '.join(METHODS)}")
    token = _METHOD.set(name)
    try:
        yield
    finally:
        _METHOD.reset(token)


def propagate_with_partials(scen, parameters: OrbitParameters | None, t_out, step: float | None = None,
                            steps=(STEP_POSITION, STEP_VELOCITY, STEP_COMMON), method: str | None = None,
                            node_step: float | None = None) -> Partials:
    """States at t_out [s since the epoch] (dd run with the run's step) and their partials,
    integrated with ``step`` [s] (None: the run's): a :class:`~tqdyn.od.variational.Partials`
    whose ``sensitivities`` (n, n_sat, 6, 3) and ``sensitivities_full`` (n, 6 n_sat, 3 n_sat)
    are with respect to the common self-gravity [s^2, s], ``parameter_names`` :data:`COMMON_NAMES`.

    method: ``"variational"``: the coupled variational equations of :mod:`.coupled_variational`
    (Jacobians at nodes every ``node_step`` [s]); ``"differences"``: central differences of dd
    runs (module docstring), steps the difference steps (position [m], velocity [m/s], common
    self-gravity [m/s^2]); None: that of the enclosing :func:`method` block, else
    ``"variational"``."""
    method = _METHOD.get() if method is None else method
    if method not in METHODS:
        fail(f"method: {method!r}; allowed: {', '.join(METHODS)}")
    check_scenario(scen)
    par = parameters or OrbitParameters()
    if method == "variational":
        sg = nominal_common(scen) if par.self_gravity_common is None else par.self_gravity_common
        return coupled_variational.propagate_with_partials(scen, par, sg, t_out, COMMON_NAMES, step, node_step)
    t, y_dd = propagate_dd(scen, par, t_out)
    n_sat = y_dd.shape[1]
    h = float(scen.integrator.step_s) if step is None else float(step)
    y0 = par.y0_dd()
    if y0 is None:
        y0 = propagate_dd(scen, par, [0.0])[1][0]
    sg = nominal_common(scen) if par.self_gravity_common is None else np.asarray(par.self_gravity_common, np.float64)
    cols = []
    for b in range(n_sat):
        for q in range(6):
            d = steps[0] if q < 3 else steps[1]
            ys = []
            for sign in (1.0, -1.0):
                y = y0.copy()
                y[b, q, 0] = y0[b, q, 0] + sign * d
                ys.append(y)
            den = (ys[0][b, q, 0] - ys[1][b, q, 0]) + (ys[0][b, q, 1] - ys[1][b, q, 1])
            cols.append((OrbitParameters(par.accelerations, ys[0], sg),
                         OrbitParameters(par.accelerations, ys[1], sg), den))
    for b in range(n_sat):
        for q in range(3):
            vals = []
            for sign in (1.0, -1.0):
                v = sg.copy()
                v[b, q] = sg[b, q] + sign * steps[2]
                vals.append(v)
            cols.append((OrbitParameters(par.accelerations, y0, vals[0]),
                         OrbitParameters(par.accelerations, y0, vals[1]), vals[0][b, q] - vals[1][b, q]))
    out = np.empty((t.size, 6 * n_sat, len(cols)))
    for j, (plus, minus, den) in enumerate(cols):
        yp, ym = _runs(scen, plus, t, h), _runs(scen, minus, t, h)
        diff = (yp[..., 0] - ym[..., 0]) + (yp[..., 1] - ym[..., 1])      # (n, n_sat, 6)
        out[:, :, j] = diff.reshape(t.size, 6 * n_sat) / den
    return Partials.from_full(t, y_dd, out[:, :, :6 * n_sat], out[:, :, 6 * n_sat:],
                              [s.name for s in scen.satellites], COMMON_NAMES)

