"""Controllers of the closed loop: continuous transfer functions per loop, and the default design.

Each loop applies one controller C(s) to each of its channels.  A channel's input is a sensed
coordinate y (m or rad, see :data:`LOOPS`); its output is the corrective acceleration command c
(m/s^2 or rad/s^2), which the actuators apply as -c to that coordinate (masses and inertias convert
it to forces and torques).  With the plant ~1/s^2 the loop gain is L(s) ~ C(s)/s^2, negative
feedback.  C(s) = gain * prod(s - z) / prod(s - p), zeros and poles in rad/s (complex ones in
conjugate pairs), gain in (s^-2) (rad/s)^(n_p - n_z): [c]/[y] = s^-2 at the loop's crossover scale.

Default design (:func:`lead_lag_pid`): a lead centred on the crossover frequency f_c (lead ratio
alpha: zero at w_c/sqrt(alpha), pole at w_c sqrt(alpha)) and an integrator with its zero at
w_c / ``integrator_ratio``, gain such that |L(i w_c)| = 1 on the pure 1/s^2 plant:

    C(s) = k (s + w_c/sqrt(alpha)) (s + w_c/r) / (s (s + w_c sqrt(alpha))),
    phase margin ~ arcsin((alpha - 1)/(alpha + 1)) - atan(1/r)   (49 deg for alpha = 10, r = 10).

The crossover frequencies per mission are in :mod:`tqdyn.closedloop.missions`; the margins
actually achieved with the full plant are computed (python-control ``stability_margins`` on the
loop-at-a-time frequency response), never assumed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from ..scenario.closed_loop import LOOPS, check_controller
from ..scenario.values import ScenarioError

__all__ = ["Controller", "ControllerError", "LOOPS", "lead_lag_pid", "pi_controller"]

#: Invalid controllers raise the scenario's one-line error naming the key.
ControllerError = ScenarioError


@dataclass(frozen=True)
class Controller:
    """C(s) = gain prod(s - z)/prod(s - p) (module docstring); ``name`` = the loop (for errors)."""

    zeros: tuple
    poles: tuple
    gain: float
    name: str = "controller"

    def __post_init__(self):
        check_controller(self.name, list(self.zeros), list(self.poles), self.gain)

    def tf(self) -> control.TransferFunction:
        """C(s) as a python-control TransferFunction (real coefficients)."""
        z, p, k = check_controller(self.name, list(self.zeros), list(self.poles), self.gain)
        return control.zpk(np.array(z), np.array(p), k)


def lead_lag_pid(f_c: float, alpha: float = 10.0, integrator_ratio: float = 10.0, name: str = "controller") \
        -> Controller:
    """The default design for a 1/s^2 plant with crossover f_c [Hz] (module docstring)."""
    wc = 2 * math.pi * f_c
    wz, wp, wi = wc / math.sqrt(alpha), wc * math.sqrt(alpha), wc / integrator_ratio
    s = 1j * wc
    mag = abs((s + wz) * (s + wi) / (s * (s + wp))) / wc ** 2
    return Controller(zeros=(-wz, -wi), poles=(0.0, -wp), gain=1.0 / mag, name=name)


def pi_controller(f_c: float, integrator_ratio: float = 10.0, name: str = "controller") -> Controller:
    """A proportional-integral design for a flat plant (a loop closed on a measured acceleration, e.g. the
    drag-free loop of an accelerometer): C(s) = k (s + w_c/r)/s with |C(i w_c)| = 1 at the crossover f_c
    [Hz] (k = 1/sqrt(1 + 1/r^2), dimensionless); below w_c/r the loop gain rises as 1/f, so the
    sensitivity falls as f: |S| ~ r f / f_c there (phase margin 90 deg - atan(1/r))."""
    wc = 2 * math.pi * f_c
    wi = wc / integrator_ratio
    return Controller(zeros=(-wi,), poles=(0.0,), gain=1.0 / math.sqrt(1.0 + 1.0 / integrator_ratio ** 2), name=name)
