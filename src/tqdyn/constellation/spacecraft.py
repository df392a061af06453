"""Spacecraft architecture: test-mass housings, MOSA pivots, sensitive axes, drag-free scheme, self-gravity.

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
  satellite's center of mass.  The housing turns with its MOSA about Z_S
  through the MOSA's pivot r_p,l (fixed in S): r_0,l(theta) = r_p,l +
  R_z(+/-(theta - theta_nominal)/2) (r_0,l^nom - r_p,l).  A pivot at the EH
  center leaves the TM in place (it only turns).
* Sensitive axis of TM l: a unit vector fixed in OA_l (default X_OA_l, the
  optical axis); the drag-free schemes follow each TM along it.
* Self-gravity: a constant (DC) acceleration of each TM, m/s^2, given in that
  TM's own OA_l frame.  Default: Table IV of the paper (the printed
  "4.94^{-11}" means 4.94e-11 m/s^2), the same for the three satellites.

Architectures (:data:`ARCHITECTURES`; the same for the three satellites)
------------------------------------------------------------------------
``tianqin`` (Table III of the paper + docs/design.md, Conventions): the two EH
centers are collinear with the satellite CoM, d_TM = 0.40 m apart, at
+/-0.20 m along Y_S (TM_1 at +0.20 m Y_S, on the side of MOSA 1); pivots at the
EH centers (d_p = 0).  Why Y_S: the S frame of TianQin turns at about the
orbital rate n about the orbit normal with X_S near the Earth direction, so the
static tidal + centrifugal acceleration of a displacement d in S is about
(3 n^2 d_x, 0, -n^2 d_z) (Hill), n^2 = GM/r^3 ~ 4e-10 s^-2: along X_S the
suspension would be ~5e-10 m/s^2, along Y_S ~1e-13 m/s^2 (measured in
tests/test_control.py).  Drag-free scheme ``tianqin`` (the paper's closed form).

``lisa``: one TM per MOSA, on that MOSA's optical axis X_OA_l at
:data:`LISA_TM_DISTANCE_M` from the CoM, the MOSA turning about Z_S through the
CoM (pivot at the CoM), so the TM stays on the optical axis at every opening
angle.  The distance is an assumption of tqdyn (no public LISA document gives
the EH centers in the spacecraft frame): a ~2.5 m spacecraft with the two
gravitational reference sensors behind the optical benches, near the centre
(configurable: ``spacecraft.tm_distance``).  Drag-free scheme ``lisa``.

``taiji``: LISA-like (the same layout and scheme; Taiji's own EH positions are
not public either).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .attitude import T_OA_S_of
from .indices import MOSA_SIGN

__all__ = [
    "ARCHITECTURES",
    "ArchitectureError",
    "DRAGFREE_SCHEMES",
    "ENVELOPE_RADIUS_M",
    "LISA_TM_DISTANCE_M",
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

#: Spacecraft architecture presets (module docstring).
ARCHITECTURES = ("tianqin", "lisa", "taiji")
#: Drag-free schemes: "tianqin" (the paper's closed form, sensitive axes X_OA_l),
#: "lisa" (the general solution of the same kind of conditions for any
#: independent sensitive axes; :mod:`tqdyn.constellation.control`).
DRAGFREE_SCHEMES = ("tianqin", "lisa")
#: Distance [m] of each EH center from the CoM along its optical axis in the
#: ``lisa`` / ``taiji`` presets -- an assumption (module docstring).
LISA_TM_DISTANCE_M = 0.30
#: Radius [m] about the CoM inside which EH centers and pivots must lie (an
#: envelope of a 2-3 m spacecraft; ``Spacecraft.envelope_radius``).
ENVELOPE_RADIUS_M = 1.5
#: Smallest |e_1 . (e_2 x Z_S)| of the sensitive axes e_l the "lisa" scheme
#: accepts (the drag-free solution divides by it).
MIN_AXES_DETERMINANT = 1e-3

_AXES = {"x": 0, "y": 1, "z": 2}


class ArchitectureError(ValueError):
    """An invalid :class:`Spacecraft` field: one line ``Spacecraft.<field> = <value> is invalid; allowed: ...``;
    attributes ``field``, ``value``, ``allowed``."""

    def __init__(self, field_name: str, value, allowed: str, problem: str = "is invalid"):
        self.field, self.value, self.allowed, self.problem = field_name, value, allowed, problem
        super().__init__(f"Spacecraft.{field_name} = {value!r} {problem}; allowed: {allowed}")


def _bad(field_name: str, value, allowed: str, problem: str = "is invalid") -> ValueError:
    return ArchitectureError(field_name, value, allowed, problem)


def _vectors(value, name: str, unit: bool = False) -> np.ndarray:
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (2, 3) or not np.all(np.isfinite(a)):
        raise _bad(name, value, "a finite real array of shape (2, 3) (one 3-vector per TM)")
    if unit:
        n = np.linalg.norm(a, axis=-1)
        if np.any(n == 0):
            raise _bad(name, value, "two non-zero vectors (they are normalised)")
        a = a / n[:, None]
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class Spacecraft:
    """Satellite architecture shared by the three satellites.

    Parameters
    ----------
    d_tm : float
        Distance between the two EH centers (TM nominal positions), m; > 0
        (the line layout of the ``tianqin`` architecture).
    d_p : float
        Distance of each MOSA pivot from its EH center, m; >= 0 (line layout).
        The pivot of MOSA l is fixed in S at ``r_0,l^nom - d_p u_l`` where u_l
        is the unit vector of X_OA_l at the nominal MOSA angle
        ``theta_nominal``; the EH center then moves with the MOSA (see
        :meth:`housing_centers`).
    tm_axis : {"x", "y", "z"}
        S-frame axis along which the EH centers lie: TM_1 at +d_tm/2, TM_2 at
        -d_tm/2 (default "y", see the module docstring; line layout).
    self_gravity : array_like or None
        DC self-gravity per TM, m/s^2, in that TM's OA_l frame; shape (2, 3)
        (same for all satellites) or (3, 2, 3) (satellite, tm, component).
        None: Table IV of the paper.
    self_gravity_on : bool
        Off switch: False makes :attr:`self_gravity_array` zero.
    theta_nominal : float
        Nominal MOSA opening angle, rad (pi/3): the angle at which the EH
        centers and pivots are given.
    housing_centers_nominal : array_like (2, 3) or None
        EH centers at ``theta_nominal``, m, in S; replaces the line layout
        (d_tm, tm_axis, d_p).
    pivot_points : array_like (2, 3) or None
        MOSA pivots, m, in S (fixed in S); None: the line layout's, or the EH
        centers themselves when ``housing_centers_nominal`` is given.
    sensitive_axes : array_like (2, 3) or None
        Sensitive axis of each TM, a vector in its OA_l frame (normalised);
        None: X_OA_l.
    scheme : {"tianqin", "lisa"}
        Drag-free scheme (:data:`DRAGFREE_SCHEMES`).
    architecture : str
        Name of the layout (a preset of :data:`ARCHITECTURES` or "custom"),
        recorded in outputs.
    envelope_radius : float
        m; every EH center and pivot lies within this distance of the CoM.

    ValueError (one line naming the field, the value and what is allowed)
    for a TM or pivot outside the envelope, two TMs at one point, a scheme
    that does not fit the sensitive axes ("tianqin" needs X_OA_l) and
    sensitive axes that are not independent of each other and of Z_S
    ("lisa").
    """

    d_tm: float = 0.40
    d_p: float = 0.0
    tm_axis: str = "y"
    self_gravity: object = None
    self_gravity_on: bool = True
    theta_nominal: float = math.pi / 3
    housing_centers_nominal: object = None
    pivot_points: object = None
    sensitive_axes: object = None
    scheme: str = "tianqin"
    architecture: str = "tianqin"
    envelope_radius: float = ENVELOPE_RADIUS_M
    _sg: np.ndarray = field(init=False, repr=False, compare=False)
    _r0: np.ndarray = field(init=False, repr=False, compare=False)
    _piv: np.ndarray = field(init=False, repr=False, compare=False)
    _sens: np.ndarray = field(init=False, repr=False, compare=False)

    @classmethod
    def preset(cls, architecture: str, tm_distance: float | None = None, **kw) -> Spacecraft:
        """The architecture preset ``architecture`` (:data:`ARCHITECTURES`).

        ``tm_distance`` [m]: distance of each EH center from the CoM along
        its optical axis (``lisa`` / ``taiji``; default
        :data:`LISA_TM_DISTANCE_M`).  Other keywords are passed on (e.g.
        ``self_gravity``, ``d_tm`` for ``tianqin``)."""
        if architecture not in ARCHITECTURES:
            raise _bad("architecture", architecture, ", ".join(f'"{a}"' for a in ARCHITECTURES))
        if architecture == "tianqin":
            if tm_distance is not None:
                raise _bad("tm_distance", tm_distance, 'None for the "tianqin" architecture (it uses d_tm)')
            return cls(architecture="tianqin", **kw)
        d = LISA_TM_DISTANCE_M if tm_distance is None else tm_distance
        if isinstance(d, bool) or not isinstance(d, (int, float, np.floating, np.integer)) or not math.isfinite(d) \
                or d <= 0:
            raise _bad("tm_distance", d, "a finite distance > 0 (m)")
        th = kw.get("theta_nominal", math.pi / 3)
        h = 0.5 * th
        u = np.array([[math.cos(h), math.sin(h), 0.0], [math.cos(h), -math.sin(h), 0.0]])
        kw.setdefault("scheme", "lisa")
        return cls(architecture=architecture, housing_centers_nominal=d * u, pivot_points=np.zeros((2, 3)), **kw)

    def __post_init__(self):
        for name in ("d_tm", "d_p", "theta_nominal", "envelope_radius"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise _bad(name, v, "a finite real number")
        if self.d_tm <= 0:
            raise _bad("d_tm", self.d_tm, "d_tm > 0 (m)")
        if self.d_p < 0:
            raise _bad("d_p", self.d_p, "d_p >= 0 (m)")
        if self.envelope_radius <= 0:
            raise _bad("envelope_radius", self.envelope_radius, "> 0 (m)")
        if not 0 < self.theta_nominal < math.pi:
            raise _bad("theta_nominal", self.theta_nominal, "0 < theta_nominal < pi (rad)")
        if self.tm_axis not in _AXES:
            raise _bad("tm_axis", self.tm_axis, '"x", "y" or "z"')
        if self.scheme not in DRAGFREE_SCHEMES:
            raise _bad("scheme", self.scheme, ", ".join(f'"{a}"' for a in DRAGFREE_SCHEMES))
        if not isinstance(self.architecture, str) or not self.architecture:
            raise _bad("architecture", self.architecture, "a name")
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
        self._set_geometry()

    def _set_geometry(self) -> None:
        if self.housing_centers_nominal is None:
            e = np.zeros(3)
            e[_AXES[self.tm_axis]] = 1.0
            r0 = np.array([0.5 * self.d_tm * e, -0.5 * self.d_tm * e])
            piv = r0 - self.d_p * self._nominal_oa_x()
        else:
            r0 = np.array(_vectors(self.housing_centers_nominal, "housing_centers_nominal"))
            piv = r0.copy()
        if self.pivot_points is not None:
            piv = np.array(_vectors(self.pivot_points, "pivot_points"))
        for name, a in (("housing_centers_nominal", r0), ("pivot_points", piv)):
            far = np.linalg.norm(a, axis=-1)
            if np.any(far > self.envelope_radius):
                l = int(np.argmax(far))
                raise _bad(name, a.tolist(), f"points within envelope_radius = {self.envelope_radius} m of the CoM",
                           f"puts TM {l + 1}'s {far[l]:.6g} m from the CoM, outside the spacecraft")
        if np.array_equal(r0[0], r0[1]):
            raise _bad("housing_centers_nominal", r0.tolist(), "two distinct points (one per TM)")
        sens = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]) if self.sensitive_axes is None else \
            np.array(_vectors(self.sensitive_axes, "sensitive_axes", unit=True))
        if self.scheme == "tianqin" and not np.array_equal(sens, [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]):
            raise _bad("sensitive_axes", sens.tolist(),
                       '[[1, 0, 0], [1, 0, 0]], or dragfree = "lisa" (any axes)',
                       'is not X_OA_l (the "tianqin" drag-free scheme)')
        det = self.axes_determinant(self.theta_nominal, sens)
        if abs(det) < MIN_AXES_DETERMINANT:
            raise _bad("sensitive_axes", sens.tolist(),
                       f">= {MIN_AXES_DETERMINANT:g} (axes neither parallel nor both in the Z_S plane)",
                       f"leave drag-free undetermined: |e_1 . (e_2 x Z_S)| = {abs(det):.3g}")
        for a in (r0, piv, sens):
            a.setflags(write=False)
        object.__setattr__(self, "_r0", r0)
        object.__setattr__(self, "_piv", piv)
        object.__setattr__(self, "_sens", sens)

    @staticmethod
    def axes_determinant(theta, sensitive_axes_oa) -> float:
        """e_1 . (e_2 x Z_S) of the sensitive axes e_l (in S) at MOSA angle
        ``theta`` [rad]; ``sensitive_axes_oa`` (2, 3) in OA_l.  Zero when the
        drag-free conditions do not determine G."""
        e = np.einsum("lji,lj->li", T_OA_S_of(0.5 * theta * MOSA_SIGN),
                      np.asarray(sensitive_axes_oa, dtype=np.float64))
        return float(np.dot(e[0], np.cross(e[1], [0.0, 0.0, 1.0])))

    @property
    def self_gravity_array(self) -> np.ndarray:
        """DC self-gravity, shape (3, 2, 3) = (satellite, tm l, OA_l component), m/s^2."""
        return self._sg

    @property
    def sensitive_axes_array(self) -> np.ndarray:
        """Unit sensitive axis of each TM in its OA_l frame, shape (2, 3)."""
        return self._sens

    def _nominal_oa_x(self) -> np.ndarray:
        h = 0.5 * self.theta_nominal
        return np.array([[math.cos(h), math.sin(h), 0.0], [math.cos(h), -math.sin(h), 0.0]])

    @property
    def nominal_housing_centers(self) -> np.ndarray:
        """EH centers r_0,l at theta = theta_nominal, shape (2, 3), m, in S."""
        return self._r0

    @property
    def pivots(self) -> np.ndarray:
        """MOSA pivots r_p,l, shape (2, 3), m, in S (fixed in S)."""
        return self._piv

    def housing_centers(self, theta) -> np.ndarray:
        """EH centers r_0,l (TM nominal positions), m, in S.

        ``theta``: MOSA opening angle(s) alpha_i, rad, any shape (...);
        returns shape (..., 2, 3): the pivot plus the lever arm
        (:meth:`lever_arms`); the constant :attr:`nominal_housing_centers`
        when the pivots are the EH centers.
        """
        theta = np.asarray(theta, dtype=np.float64)
        return self.pivots + self.lever_arms(theta)

    def lever_arms(self, theta) -> np.ndarray:
        """r_0,l - r_p,l, m, in S, shape (..., 2, 3) for ``theta`` of shape (...):
        the nominal lever arm rotated about Z_S by +/-(theta - theta_nominal)/2."""
        theta = np.asarray(theta, dtype=np.float64)
        d = 0.5 * (theta - self.theta_nominal)
        rho_nom = self._r0 - self._piv
        out = np.zeros(theta.shape + (2, 3))
        for l, s in enumerate(MOSA_SIGN):
            out[..., l, :] = np.einsum("...ji,j->...i", T_OA_S_of(s * d), rho_nom[l])  # R_z(s d) rho
        return out
