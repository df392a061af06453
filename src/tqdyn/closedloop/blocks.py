"""Static blocks of the closed loop's interconnection (:mod:`tqdyn.closedloop.loop`): the noise sources' input
names and the sensor rows that turn plant coordinates and sensor noise into the controllers' error signals.
Units: those of the signals (SI)."""

from __future__ import annotations

import control
import numpy as np

from ..scenario.closed_loop import SOURCES

__all__ = ["SensorRows", "source_inputs", "static_block"]


def source_inputs(source: str) -> list[str]:
    """The closed loop's input signal names of one source."""
    return [f"{source}[{k}]" for k in range(SOURCES[source][0])]


def static_block(D, inputs, outputs, name) -> control.StateSpace:
    """A static (matrix ``D``) python-control system with named ``inputs`` and ``outputs``."""
    return control.ss(np.zeros((0, 0)), np.zeros((0, len(inputs))), np.zeros((len(outputs), 0)),
                      np.asarray(D, dtype=np.float64), inputs=inputs, outputs=outputs, name=name)


class SensorRows:
    """The rows of a static sensor block: plant coordinates + sensor noise (+ ``extra`` signals) -> the error
    signals ``e_<loop>[k]``; :meth:`add` one error signal as {signal: coefficient}, :meth:`matrices` the
    block as (D, input names, output names), :meth:`block` the python-control system (every sensor-noise
    input listed, used or not)."""

    def __init__(self, extra=()):
        self.inputs = ([f"x{l}[{i}]" for l in (1, 2) for i in range(3)]
                       + [f"eta{l}[{i}]" for l in (1, 2) for i in range(3)]
                       + [f"phi[{i}]" for i in range(3)] + ["dth[0]", "dth[1]"]
                       + source_inputs("capacitive_translation") + source_inputs("capacitive_rotation")
                       + source_inputs("interferometer") + source_inputs("dws") + source_inputs("star_tracker")
                       + source_inputs("mosa_encoder") + list(extra))
        self.index = {s: k for k, s in enumerate(self.inputs)}
        self.rows, self.names = [], []

    def add(self, name: str, coeffs: dict) -> None:
        r = np.zeros(len(self.inputs))
        for sig, c in coeffs.items():
            r[self.index[sig]] += c
        self.rows.append(r)
        self.names.append(name)

    def matrices(self) -> tuple:
        return np.array(self.rows), list(self.inputs), list(self.names)

    def block(self) -> control.StateSpace:
        return static_block(*self.matrices(), "sensors")
