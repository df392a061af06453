"""The one-degree-of-freedom closed loop: one TM and one spacecraft axis (the reference case of the tests).

x = TM minus housing along the axis [m]: x'' = -F/M - k x + a_tm, F = M c + n_thr (thrust [N]), y = x + n_s
(sensor [m]), c = C(s) (y) [m/s^2].  With P(s) = 1/(s^2 + k) the loop gain is L = C P, and

    x / n_thr = -(1/M) P / (1 + L) = -(1/M) P S,     x / n_s = -L / (1 + L) = -T,     S + T = 1.

Built with python-control ``interconnect`` from named blocks, exactly as the full model
(:func:`tqdyn.closedloop.loop.build_closed_loop`); noise inputs ``thruster_force[0]`` [N],
``interferometer[0]`` [m]; outputs ``x`` [m], ``c_dragfree[0]`` [m/s^2]; loop-break input ``d_dragfree[0]``.
"""

from __future__ import annotations

import control
import numpy as np

from .controllers import Controller
from .loop import ClosedLoop

__all__ = ["one_dof_loop"]


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
