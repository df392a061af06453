"""The parameters of an orbit determination: the satellites' initial states and their
acceleration parameters (:mod:`tqdyn.dynamics.empirical`).

An :class:`OrbitParameters` holds values; :func:`parameter_names` and :func:`state_names` spell
the names ``"<satellite>/<name>"`` used by the partials of :mod:`.variational` (state
components x, y, z [m], vx, vy, vz [m/s] at the epoch, in the run's frame; accelerations
s_x ... sin_n [m/s^2], :data:`~tqdyn.dynamics.empirical.PARAMETER_NAMES`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from ..dynamics.empirical import N_PAR, PARAMETER_NAMES
from ..scenario.accelerations import AccelerationsConfig

__all__ = ["N_PAR", "PARAMETER_NAMES", "STATE_NAMES", "OrbitParameters", "parameter_names", "per_satellite_names",
           "scenario_with", "state_names"]

#: Names of the six initial-state components of a satellite.
STATE_NAMES = ("x", "y", "z", "vx", "vy", "vz")


@dataclass
class OrbitParameters:
    """Values of the estimated parameters of a scenario's n_sat satellites.

    accelerations : (n_sat, N_PAR) float64 [m/s^2], columns :data:`PARAMETER_NAMES`
        (None: the scenario's ``[accelerations]``, zero by default).
    y0 : initial states at the epoch, (n_sat, 6, 2) double-double or (n_sat, 6) float64
        [m, m/s], the run's frame (None: the scenario's initial states).
    self_gravity_common : (n_sat, 3) float64 [m/s^2 in S]: ``spacecraft.self_gravity_common``
        of a coupled run (None: the scenario's).
    """

    accelerations: np.ndarray | None = None
    y0: np.ndarray | None = None
    self_gravity_common: np.ndarray | None = None

    def y0_dd(self) -> np.ndarray | None:
        """y0 as a (n_sat, 6, 2) dd array (None if not set)."""
        if self.y0 is None:
            return None
        y = np.asarray(self.y0, np.float64)
        if y.ndim == 2:
            y = np.stack([y, np.zeros_like(y)], axis=-1)
        if y.ndim != 3 or y.shape[1:] != (6, 2):
            raise ValueError(f"parameters.y0: shape {np.shape(self.y0)}; allowed: (n_sat, 6) or (n_sat, 6, 2)")
        return y


def per_satellite_names(satellites, components) -> list[str]:
    """``"<sat>/<component>"`` of each component, satellite by satellite (satellites: names, or
    a scenario)."""
    names = [s.name for s in satellites.satellites] if hasattr(satellites, "satellites") else list(satellites)
    return [f"{s}/{p}" for s in names for p in components]


def parameter_names(satellites) -> list[str]:
    """``"<sat>/<name>"`` of every acceleration parameter, satellite by satellite
    (satellites: names, or a scenario)."""
    return per_satellite_names(satellites, PARAMETER_NAMES)


def state_names(satellites) -> list[str]:
    """``"<sat>/<component>"`` of every initial-state component, satellite by satellite."""
    return per_satellite_names(satellites, STATE_NAMES)


def scenario_with(scenario, accelerations=None, duration_s=None, self_gravity_common=None, step_s=None):
    """A copy of the scenario with its ``[accelerations]`` set to (n_sat, N_PAR) values
    [m/s^2] (None: unchanged), ``run.duration`` to duration_s [s] (None: unchanged;
    a multiple of the step in fixed mode), ``spacecraft.self_gravity_common`` to (n_sat, 3)
    values [m/s^2 in S] (None: unchanged; float64 values are kept exactly) and
    ``integrator.step`` to step_s [s] (None: unchanged)."""
    kw = {}
    if self_gravity_common is not None:
        sg = np.asarray(self_gravity_common, np.float64)
        n = len(scenario.satellites)
        if sg.shape != (n, 3):
            raise ValueError(f"parameters.self_gravity_common: shape {sg.shape}; allowed: ({n}, 3) [m/s^2 in S]")
        rows = tuple(tuple(Decimal(repr(float(x))) for x in row) for row in sg)
        kw["spacecraft"] = dataclasses.replace(scenario.spacecraft, self_gravity_common=rows)
    if step_s is not None:
        kw["integrator"] = dataclasses.replace(scenario.integrator, step_s=Decimal(repr(float(step_s))))
    if accelerations is not None:
        acc = np.asarray(accelerations, np.float64)
        n = len(scenario.satellites)
        if acc.shape != (n, N_PAR):
            raise ValueError(f"parameters.accelerations: shape {acc.shape}; allowed: ({n}, {N_PAR}) [m/s^2]")
        kw["accelerations"] = AccelerationsConfig.from_values(acc)
    if duration_s is not None:
        kw["run"] = dataclasses.replace(scenario.run, duration_s=Decimal(repr(float(duration_s))))
    return dataclasses.replace(scenario, **kw) if kw else scenario
