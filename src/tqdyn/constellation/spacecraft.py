"""Spacecraft architecture: indices, test-mass housings, MOSA pivots, self-gravity.

Conventions (docs/design.md, Conventions)
----------------------------------
* Index enums (satellite, MOSA, link) live in :mod:`tqdyn.constellation.indices`;
  arrays here use the axes (satellite 1..3, tm/MOSA l = 1..2, component).
* Satellite index i = 1, 2, 3 as in Table I of the paper; for satellite i the
  even permutation (i, j, k) fixes Z_S = n_ij x n_ik / sin(alpha_i).
* The S frame: X_S the bisector of the two beams (towards the incenter), Z_S the
  constellation normal above, Y_S = Z_S x X_S.
* MOSA / OA frame l = 1 is X_S rotated by +theta/2 about Z_S: it faces the
  satellite k and lies on the +Y_S ("left") side; l = 2 is rotated by
  -theta/2, faces satellite j ("right" side).  theta = alpha_i (the breathing
  angle).  Under this convention the paper's eq:E1 / eq:E2 hold as printed
  (checked in tests/test_control.py).
* TM_l sits in the electrode housing (EH) of MOSA l; its nominal position is the
  EH center r_0,l.  Positions are in the S frame, metres, relative to the
  satellite's center of mass.
* Self-gravity: a constant (DC) acceleration of each TM, m/s^2, given in that
  TM's own OA_l frame.  Default: Table IV of the paper (the printed
  "4.94^{-11}" means 4.94e-11 m/s^2), the same for the three satellites.

Default architecture (Table III of the paper + docs/design.md, Conventions): the two EH
centers are collinear with the satellite CoM, d_TM = 0.40 m apart, at
+/-0.20 m along Y_S (TM_1 at +0.20 m Y_S, on the side of MOSA 1); pivots at the
EH centers (d_p = 0).  Why Y_S: the S frame of TianQin turns at about the
orbital rate n about the orbit normal with X_S near the Earth direction, so the
static tidal + centrifugal acceleration of a displacement d in S is about
(3 n^2 d_x, 0, -n^2 d_z) (Hill), n^2 = GM/r^3 ~ 4e-10 s^-2: along X_S the
suspension would be ~5e-10 m/s^2, along Y_S ~1e-13 m/s^2 (measured in
tests/test_control.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .indices import MOSA_SIGN

__all__ = [
    "TABLE_IV_SELF_GRAVITY",
    "Spacecraft",
]

#: Table IV of the paper: DC self-gravity per TM in its own OA (TM) frame,
#: shape (2, 3) = (TM_1, TM_2) x (x, y, z), m/s^2.
TABLE_IV_SELF_GRAVITY = np.array(
    [[4.94e-11, 6.22e-12, 1.10e-10],
     [5.20e-11, 5.65e-12, -5.72e-11]]
)
TABLE_IV_SELF_GRAVITY.setflags(write=False)


_AXES = {"x": 0, "y": 1, "z": 2}


def _bad(field_name: str, value, allowed: str) -> ValueError:
    return ValueError(f"Spacecraft.{field_name} = {value!r} is invalid; allowed: {allowed}")


@dataclass(frozen=True)
class Spacecraft:
    """Satellite architecture shared by the three satellites.

    Parameters
    ----------
    d_tm : float
        Distance between the two EH centers (TM nominal positions), m; > 0.
    d_p : float
        Distance of each MOSA pivot from its EH center, m; >= 0.  The pivot of
        MOSA l is fixed in S at ``r_0,l^nom - d_p u_l`` where u_l is the unit
        vector of X_OA_l at the nominal MOSA angle ``theta_nominal``; the EH
        center then moves with the MOSA (see :meth:`housing_centers`).
    tm_axis : {"x", "y", "z"}
        S-frame axis along which the EH centers lie: TM_1 at +d_tm/2, TM_2 at
        -d_tm/2 (default "y", see the module docstring).
    self_gravity : array_like or None
        DC self-gravity per TM, m/s^2, in that TM's OA_l frame; shape (2, 3)
        (same for all satellites) or (3, 2, 3) (satellite, tm, component).
        None: Table IV of the paper.
    self_gravity_on : bool
        Off switch: False makes :attr:`self_gravity_array` zero.
    theta_nominal : float
        Nominal MOSA opening angle, rad (pi/3), used only to place pivots when
        d_p > 0.
    """

    d_tm: float = 0.40
    d_p: float = 0.0
    tm_axis: str = "y"
    self_gravity: object = None
    self_gravity_on: bool = True
    theta_nominal: float = math.pi / 3
    _sg: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("d_tm", "d_p", "theta_nominal"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise _bad(name, v, "a finite real number")
        if self.d_tm <= 0:
            raise _bad("d_tm", self.d_tm, "d_tm > 0 (m)")
        if self.d_p < 0:
            raise _bad("d_p", self.d_p, "d_p >= 0 (m)")
        if not 0 < self.theta_nominal < math.pi:
            raise _bad("theta_nominal", self.theta_nominal, "0 < theta_nominal < pi (rad)")
        if self.tm_axis not in _AXES:
            raise _bad("tm_axis", self.tm_axis, '"x", "y" or "z"')
        if not isinstance(self.self_gravity_on, (bool, np.bool_)):
            raise _bad("self_gravity_on", self.self_gravity_on, "True or False")
        if self.self_gravity is None:
            sg = np.broadcast_to(TABLE_IV_SELF_GRAVITY, (3, 2, 3)).copy()
        else:
            try:
                sg = np.array(self.self_gravity, dtype=np.float64)
            except (TypeError, ValueError):
                raise _bad("self_gravity", self.self_gravity, "None or a real array of shape (2, 3) or (3, 2, 3) (m/s^2)") from None
            if sg.shape == (2, 3):
                sg = np.broadcast_to(sg, (3, 2, 3)).copy()
            if sg.shape != (3, 2, 3) or not np.all(np.isfinite(sg)):
                raise _bad("self_gravity", f"array of shape {np.shape(self.self_gravity)}",
                           "None or a finite real array of shape (2, 3) or (3, 2, 3) (m/s^2)")
        if not self.self_gravity_on:
            sg = np.zeros((3, 2, 3))
        sg.setflags(write=False)
        object.__setattr__(self, "_sg", sg)

    @property
    def self_gravity_array(self) -> np.ndarray:
        """DC self-gravity, shape (3, 2, 3) = (satellite, tm l, OA_l component), m/s^2."""
        return self._sg

    @property
    def _axis(self) -> np.ndarray:
        e = np.zeros(3)
        e[_AXES[self.tm_axis]] = 1.0
        return e

    def _nominal_oa_x(self) -> np.ndarray:
        h = 0.5 * self.theta_nominal
        return np.array([[math.cos(h), math.sin(h), 0.0], [math.cos(h), -math.sin(h), 0.0]])

    @property
    def nominal_housing_centers(self) -> np.ndarray:
        """EH centers r_0,l at theta = theta_nominal, shape (2, 3), m, in S."""
        e = self._axis
        return np.array([0.5 * self.d_tm * e, -0.5 * self.d_tm * e])

    @property
    def pivots(self) -> np.ndarray:
        """MOSA pivots r_p,l, shape (2, 3), m, in S (fixed in S)."""
        return self.nominal_housing_centers - self.d_p * self._nominal_oa_x()

    def housing_centers(self, theta) -> np.ndarray:
        """EH centers r_0,l (TM nominal positions), m, in S.

        ``theta``: MOSA opening angle(s) alpha_i, rad, any shape (...);
        returns shape (..., 2, 3).  With d_p = 0 it is the constant
        :attr:`nominal_housing_centers`; otherwise the lever arm
        ``d_p u_l`` is rotated about Z_S by ``+/-(theta - theta_nominal)/2``.
        """
        theta = np.asarray(theta, dtype=np.float64)
        rho = self.lever_arms(theta)
        return self.pivots + rho

    def lever_arms(self, theta) -> np.ndarray:
        """r_0,l - r_p,l, m, in S, shape (..., 2, 3) for ``theta`` of shape (...)."""
        theta = np.asarray(theta, dtype=np.float64)
        d = 0.5 * (theta - self.theta_nominal)
        h = 0.5 * self.theta_nominal
        out = np.zeros(theta.shape + (2, 3))
        for l, s in enumerate(MOSA_SIGN):
            ang = s * (h + d)
            out[..., l, 0] = self.d_p * np.cos(ang)
            out[..., l, 1] = self.d_p * np.sin(ang)
        return out
