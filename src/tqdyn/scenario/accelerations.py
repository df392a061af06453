"""Section ``[accelerations]``: acceleration parameters of point-mass satellites.

Four optional keys, each an array with one 3-vector [m/s^2] per satellite (in the order of
``[[satellites]]``); absent keys are zero (the default: no such acceleration, and a run
identical to one without the section); each value finite, |value| <= 1e-3 m/s^2
(:data:`tqdyn.scenario.values.MAX_ACCELERATION`)::

    [accelerations]
    s_frame = [[ax, ay, az], ...]   # constant, in the S frame of the constellation (3 satellites)
    rtn = [[r, t, n], ...]          # constant, radial / transverse / normal
    rtn_cos = [[r, t, n], ...]      # once per revolution: cos(u) (r, t, n)
    rtn_sin = [[r, t, n], ...]      # once per revolution: sin(u) (r, t, n)

The frames and the argument of latitude u: :mod:`tqdyn.dynamics.empirical`.  They act on
point-mass runs only (``constellation.pointing = "none"``).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from .toml_text import toml_value
from .values import MAX_ACCELERATION, _num_array, _require, _set

__all__ = ["ACCELERATION_KEYS", "AccelerationsConfig"]

#: The keys of [accelerations], in the order of the parameters of each satellite
#: (:data:`tqdyn.dynamics.empirical.PARAMETER_NAMES`: 3 values each).
ACCELERATION_KEYS = ("s_frame", "rtn", "rtn_cos", "rtn_sin")


@dataclass(frozen=True)
class AccelerationsConfig:
    """The [accelerations] keys: each () (zero) or a tuple of per-satellite 3-tuples of
    exact Decimal [m/s^2]."""

    s_frame: tuple = ()
    rtn: tuple = ()
    rtn_cos: tuple = ()
    rtn_sin: tuple = ()

    def __post_init__(self) -> None:
        for key in ACCELERATION_KEYS:
            value = getattr(self, key)
            if value is None or (isinstance(value, (list, tuple)) and len(value) == 0):
                _set(self, key, ())
                continue
            n = len(value) if isinstance(value, (list, tuple)) else 1
            _set(self, key, _num_array(value, f"accelerations.{key}", ((n, 3),), "m/s^2, one row per satellite",
                                       MAX_ACCELERATION))

    @property
    def nonzero(self) -> bool:
        """True if any parameter is not zero."""
        return any(x != 0 for key in ACCELERATION_KEYS for row in getattr(self, key) for x in row)

    def check(self, n_sat: int, coupled: bool) -> None:
        """ScenarioError unless every given key has one row per satellite, s_frame comes with
        three satellites and the run is a point-mass one (coupled: pointing != "none")."""
        for key in ACCELERATION_KEYS:
            rows = getattr(self, key)
            if rows:
                _require(len(rows) == n_sat, f"accelerations.{key}", [list(r) for r in rows],
                         f"has {len(rows)} rows for {n_sat} satellites", "one [x, y, z] row [m/s^2] per satellite")
        if self.s_frame and any(x != 0 for r in self.s_frame for x in r):
            _require(n_sat == 3, "accelerations.s_frame", [list(r) for r in self.s_frame],
                     f"needs the S frame of 3 satellites ({n_sat} given)", "3 satellites, or no s_frame")
        if coupled and self.nonzero:
            key = next(k for k in ACCELERATION_KEYS if any(x != 0 for r in getattr(self, k) for x in r))
            _require(False, f"accelerations.{key}", [list(r) for r in getattr(self, key)],
                     'acts on point-mass satellites only', 'constellation.pointing = "none", or zero')

    def values(self, n_sat: int) -> np.ndarray:
        """(n_sat, 12) float64 parameters [m/s^2], the keys' rows side by side (zeros where absent)."""
        out = np.zeros((n_sat, 3 * len(ACCELERATION_KEYS)))
        for g, key in enumerate(ACCELERATION_KEYS):
            for i, row in enumerate(getattr(self, key)):
                out[i, 3 * g:3 * g + 3] = [float(x) for x in row]
        return out

    @classmethod
    def from_values(cls, values) -> "AccelerationsConfig":
        """The section of (n_sat, 12) parameters [m/s^2] (float64, written exactly as decimals)."""
        v = np.asarray(values, np.float64)
        return cls(**{key: tuple(tuple(Decimal(repr(float(x))) for x in row[3 * g:3 * g + 3]) for row in v)
                      for g, key in enumerate(ACCELERATION_KEYS)})

    def to_toml_lines(self) -> list[str]:
        """The keys with a non-zero value as TOML lines (nothing when all are zero)."""
        keys = [k for k in ACCELERATION_KEYS if any(x != 0 for r in getattr(self, k) for x in r)]
        if not keys:
            return []
        return (["[accelerations]"] + [f"{k} = {toml_value([list(r) for r in getattr(self, k)])}  # m/s^2"
                                        for k in keys] + [""])
