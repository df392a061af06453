"""The one-degree-of-freedom closed loop: one TM and one spacecraft axis (the reference case of the tests).

x = TM minus housing along the axis [m]: x'' = -F/M - k x + a_tm, F = M c + n_thr (thrust [N]), y = x + n_s
(sensor [m]), c = C(s) (y) [m/s^2].  With P(s) = 1/(s^2 + k) the loop gain is L = C P, and

    x / n_thr = -(1/M) P / (1 + L) = -(1/M) P S,     x / n_s = -L / (1 + L) = -T,     S + T = 1.

Built with python-control ``interconnect`` from named blocks, exactly as the full model
(:func:`tqdyn.closedloop.loop.build_closed_loop`); noise inputs ``thruster_force[0]`` [N],
``interferometer[0]`` [m]; outputs ``x`` [m], ``c_dragfree[0]`` [m/s^2]; loop-break input ``d_dragfree[0]``.

:func:`two_tm_axis_loop` is the same loop with a second TM on the same axis (LISA Pathfinder's x axis,
docs/closed-loop-validation.md): TM 1 drag-free, TM 2 electrostatically suspended on the differential
readout.  With x_l = TM l minus its housing [m], k_l the stiffnesses [s^-2] (x'' = -k x; LPF writes
omega_l^2 = k_l), m the TM mass [kg]:

    x_l'' = -F_sc/M - k_l x_l + a_l (+ g2 for l = 2),   F_sc = F - m g2 (the reaction of TM 2's force),
    F = M c_df + n_thr,  c_df = C_df(o1),  g2 = -C_sus(o12),  o1 = x1 + n_1,  o12 = x2 - x1 + n_12.

The differential-acceleration estimator of the flight analysis, Delta g = o12'' + k2 o12 + (k2 - k1) o1 - g2,
is then a_2 - a_1 + (s^2 + k2) n_12 + (k2 - k1) n_1 exactly, whatever the controllers (derivation:
docs/closed-loop-validation.md).
"""

from __future__ import annotations

import control
import numpy as np

from .controllers import Controller
from .loop import ClosedLoop

__all__ = ["one_dof_loop", "two_tm_axis_loop"]


def one_dof_loop(controller: Controller, sc_mass: float, stiffness: float = 0.0) -> ClosedLoop:
    """The one-DOF closed loop (module docstring): ``sc_mass`` [kg], ``stiffness`` k [s^-2]."""
    P = control.ss([[0.0, 1.0], [-stiffness, 0.0]], [[0.0], [-1.0 / sc_mass]], [[1.0, 0.0]], [[0.0]],
                   inputs=["F"], outputs=["x"], name="plant")
    sensor = control.summing_junction(inputs=["x", "interferometer[0]"], output="y", name="sensor")
    ctl = control.ss(controller.tf())
    C = control.ss(ctl.A, ctl.B, ctl.C, ctl.D, inputs=["y"], outputs=["c_dragfree[0]"], name="controller")
    act = control.ss(np.zeros((0, 0)), np.zeros((0, 3)), np.zeros((1, 0)), [[sc_mass, sc_mass, 1.0]],
                     inputs=["c_dragfree[0]", "d_dragfree[0]", "thruster_force[0]"], outputs=["F"], name="thrusters")
    inp = ["thruster_force[0]", "interferometer[0]", "d_dragfree[0]"]
    out = ["x", "c_dragfree[0]"]
    cl = control.interconnect([P, sensor, C, act], inplist=inp, outlist=out, inputs=inp, outputs=out,
                              name="one_dof")
    return ClosedLoop(system=cl, channel_names=("dragfree[0]",), dc_force={},
                      sources=(("thruster_force", 1), ("interferometer", 1)), outputs=("x",))


def two_tm_axis_loop(dragfree: Controller, suspension: Controller, sc_mass: float, tm_mass: float,
                     stiffness=(0.0, 0.0)) -> ClosedLoop:
    """Two TMs on one axis (module docstring): ``sc_mass`` M, ``tm_mass`` m [kg], ``stiffness`` (k1, k2)
    [s^-2].  Noise inputs: ``thruster_force[0]`` [N], ``tm_force[0]``, ``tm_force[3]`` (a_1, a_2 [m/s^2]),
    ``interferometer[0]`` (n_1), ``interferometer[1]`` (n_12) [m]; loop breaks ``d_dragfree[0]``,
    ``d_suspension[0]``.  Outputs ``x1``, ``x2``, ``o1``, ``o12`` [m], ``g2`` [m/s^2] (TM 2's commanded
    electrostatic acceleration), ``c_dragfree[0]`` [m/s^2]."""
    k1, k2 = (float(k) for k in stiffness)
    r = tm_mass / sc_mass
    # states x1, x2, x1', x2'; inputs F [N], g2 [m/s^2], a_1, a_2 [m/s^2]
    A = [[0, 0, 1, 0], [0, 0, 0, 1], [-k1, 0, 0, 0], [0, -k2, 0, 0]]
    B = [[0, 0, 0, 0], [0, 0, 0, 0], [-1 / sc_mass, r, 1, 0], [-1 / sc_mass, 1 + r, 0, 1]]
    P = control.ss(A, B, [[1, 0, 0, 0], [0, 1, 0, 0]], np.zeros((2, 4)),
                   inputs=["F", "g2", "tm_force[0]", "tm_force[3]"], outputs=["x1", "x2"], name="plant")
    sens = control.ss(np.zeros((0, 0)), np.zeros((0, 4)), np.zeros((2, 0)), [[1, 0, 1, 0], [-1, 1, 0, 1]],
                      inputs=["x1", "x2", "interferometer[0]", "interferometer[1]"], outputs=["o1", "o12"],
                      name="sensors")
    blocks = [P, sens]
    for ctl, inp, out in ((dragfree, "o1", "c_dragfree[0]"), (suspension, "o12", "c_suspension[0]")):
        c = control.ss(ctl.tf())
        blocks.append(control.ss(c.A, c.B, c.C, c.D, inputs=[inp], outputs=[out], name=f"C_{out[2:-3]}"))
    blocks.append(control.ss(np.zeros((0, 0)), np.zeros((0, 5)), np.zeros((2, 0)),
                             [[sc_mass, sc_mass, 1.0, 0, 0], [0, 0, 0, -1.0, -1.0]],
                             inputs=["c_dragfree[0]", "d_dragfree[0]", "thruster_force[0]", "c_suspension[0]",
                                     "d_suspension[0]"], outputs=["F", "g2"], name="actuators"))
    inp = ["thruster_force[0]", "tm_force[0]", "tm_force[3]", "interferometer[0]", "interferometer[1]",
           "d_dragfree[0]", "d_suspension[0]"]
    out = ["x1", "x2", "o1", "o12", "g2", "c_dragfree[0]", "c_suspension[0]"]
    cl = control.interconnect(blocks, inplist=inp, outlist=out, inputs=inp, outputs=out, name="two_tm_axis")
    return ClosedLoop(system=cl, channel_names=("dragfree[0]", "suspension[0]"), dc_force={},
                      sources=(("thruster_force", 1), ("tm_force", 6), ("interferometer", 2)),
                      outputs=("x1", "x2", "o1", "o12", "g2"))
