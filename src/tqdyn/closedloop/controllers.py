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

__all__ = ["Controller", "ControllerError", "LOOPS", "lead_lag_pid"]

#: Loops: name -> (channels, what is sensed, sensor, actuator).
LOOPS = {
    "dragfree": (("tm1 sensitive axis", "tm2 sensitive axis", "mean z of the TMs"), "m",
                 "interferometer (sensitive axes), capacitive (z)", "thrusters (force)"),
    "suspension": (("tm1 p axis (Z x e_1)", "tm2 p axis (Z x e_2)", "half the z difference"), "m",
                   "capacitive", "electrostatic force"),
    "attitude": (("x", "y"), "rad", "DWS (the pitches of both MOSAs)", "thrusters (torque)"),
    "attitude_z": (("z",), "rad", "mean DWS yaw minus mean MOSA encoder angle (or the star tracker)",
                   "thrusters (torque)"),
    "mosa": (("MOSA 1", "MOSA 2"), "rad", "DWS yaw of the MOSA (spacecraft yaw + MOSA angle)", "MOSA actuator"),
    "tm_rotation": (("tm1 x", "tm1 y", "tm1 z", "tm2 x", "tm2 y", "tm2 z"), "rad", "capacitive", "electrostatic torque"),
}


class ControllerError(ValueError):
    """An invalid controller: one line naming the field (attribute ``field``)."""

    def __init__(self, field_name: str, value, problem: str, allowed: str):
        self.field = field_name
        super().__init__(f"{field_name}: {value!r} {problem}; allowed: {allowed}")


def _roots(values, name: str) -> np.ndarray:
    out = []
    for v in values:
        if isinstance(v, (list, tuple)) and len(v) == 2:
            re, im = v
            out += [complex(re, im), complex(re, -im)] if im != 0 else [complex(re, 0.0)]
        elif isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool):
            out.append(complex(v, 0.0))
        else:
            raise ControllerError(name, list(values), "is not a list of roots",
                                  "real numbers (rad/s) or [re, im] pairs for conjugate pairs")
    a = np.array(out, dtype=complex)
    if not np.all(np.isfinite(a)):
        raise ControllerError(name, list(values), "is not finite", "finite roots (rad/s)")
    return a


@dataclass(frozen=True)
class Controller:
    """C(s) = gain prod(s - z)/prod(s - p) (module docstring); ``name`` = the loop (for errors)."""

    zeros: tuple
    poles: tuple
    gain: float
    name: str = "controller"

    def __post_init__(self):
        z = _roots(self.zeros, f"closed_loop.controllers.{self.name}.zeros")
        p = _roots(self.poles, f"closed_loop.controllers.{self.name}.poles")
        g = self.gain
        if isinstance(g, bool) or not isinstance(g, (int, float, np.floating, np.integer)) or not math.isfinite(g) \
                or g <= 0:
            raise ControllerError(f"closed_loop.controllers.{self.name}.gain", g, "is not a positive number",
                                  "gain > 0 (negative feedback is built into the loop)")
        if len(z) > len(p):
            raise ControllerError(f"closed_loop.controllers.{self.name}", f"{len(z)} zeros, {len(p)} poles",
                                  "is improper", "at most as many zeros as poles")
        if np.any(p.real > 0):
            raise ControllerError(f"closed_loop.controllers.{self.name}.poles", list(self.poles),
                                  "has an unstable pole", "poles with Re <= 0 (an integrator at 0 is allowed)")

    def tf(self) -> control.TransferFunction:
        """C(s) as a python-control TransferFunction (real coefficients)."""
        z = _roots(self.zeros, "zeros")
        p = _roots(self.poles, "poles")
        return control.zpk(z, p, float(self.gain))


def lead_lag_pid(f_c: float, alpha: float = 10.0, integrator_ratio: float = 10.0, name: str = "controller") \
        -> Controller:
    """The default design for a 1/s^2 plant with crossover f_c [Hz] (module docstring)."""
    wc = 2 * math.pi * f_c
    wz, wp, wi = wc / math.sqrt(alpha), wc * math.sqrt(alpha), wc / integrator_ratio
    s = 1j * wc
    mag = abs((s + wz) * (s + wi) / (s * (s + wp))) / wc ** 2
    return Controller(zeros=(-wz, -wi), poles=(0.0, -wp), gain=1.0 / mag, name=name)
