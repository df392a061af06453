"""Control schemes of single spacecraft: which sensor drives which actuator (docs/closed-loop-validation.md).

The plant (:mod:`tqdyn.closedloop.plant`) is the same for every mission; a scheme is its sensor rows
(plant coordinates + sensor noise -> the error signals ``e_<loop>[k]``) and its actuator commands
(controller channel -> plant input, with a gain).  The "constellation" scheme (a MOSA per TM, DWS attitude)
is :func:`tqdyn.closedloop.loop.build_closed_loop`'s own; this module holds the two single-spacecraft ones.
Their loop tables are :data:`tqdyn.scenario.closed_loop.COLLINEAR_LOOPS` and
:data:`~tqdyn.scenario.closed_loop.SINGLE_TM_LOOPS`.

**"collinear"** (LISA Pathfinder's science mode): TM 1 at +L/2 X_S, TM 2 at -L/2 X_S (L the housings'
distance), both sensitive axes X_S, housings fixed in the body (no MOSA).  With x_l = TM l minus its housing
(S components), eta_l the TM's rotation relative to its housing and phi the spacecraft's rotation, a small
phi moves housing l by phi x r_l, so (y1 - y2)/L = -phi_z and (z1 - z2)/L = +phi_y (TMs at rest):

* drag-free (thrusters, force): x on o1 = x1_x + n_1 (interferometer), y and z on the TMs' mean
  (y1 + y2)/2, (z1 + z2)/2 (capacitive);
* suspension (electrostatic force on TM 2 along X): o12 = x2_x - x1_x + n_12 (interferometer);
* attitude (thrusters, torque; the spacecraft follows the TMs): about X on -(eta1_x + eta2_x)/2, about Y on
  (z1 - z2)/L, about Z on -(y1 - y2)/L (capacitive);
* tm_rotation (electrostatic torque): eta1_y, eta1_z, eta2_y, eta2_z, and eta2_x - eta1_x (split +-1/2);
* guidance (the star tracker's attitude phi + n_st): the TMs that the attitude loops follow are turned
  electrostatically, so that the spacecraft's inertial attitude follows the star tracker below the
  guidance bandwidth: a torque about X on both TMs (x), a differential force along Z (y) and along Y (z).

**"single_tm"** (TianQin-1, one inertial sensor as an accelerometer): TM 1 at the centre of mass
(TM 2 and the MOSA angles are the plant's placeholders), suspended in all six degrees of freedom
(capacitive); the thrusters null the suspension's command along X, Y, Z (drag-free on the measured
acceleration); the attitude on the star tracker (thrusters, torque).

Units: SI; gains as in :mod:`tqdyn.closedloop.controllers` (commands are accelerations, the masses and
inertias convert them).
"""

from __future__ import annotations

import numpy as np

from .blocks import SensorRows
from .plant import PlantParameters, WorkingPoint

__all__ = ["collinear_separation", "scheme_blocks"]


def collinear_separation(p: PlantParameters) -> float:
    """L [m]: the distance of the two housings along X_S; ValueError (one line naming the key) unless the
    housings lie on X_S on both sides of the centre of mass and both sensitive axes are X_S (the geometry
    the "collinear" scheme controls)."""
    r = np.asarray(p.housing_centers, dtype=np.float64)
    e = np.asarray(p.sensitive_axes, dtype=np.float64)
    on_axis = np.allclose(r[:, 1:], 0.0, atol=1e-9) and r[0, 0] > 0 > r[1, 0]
    if p.n_tm != 2 or not on_axis or not np.allclose(e, [[1.0, 0.0, 0.0]] * 2, atol=1e-9) or p.mosa:
        raise ValueError("closed_loop.scheme: 'collinear' needs two TMs on X_S on both sides of the centre of mass, "
                         f"housings fixed in the body, sensitive axes X_S (got housings {r.round(4).tolist()}, "
                         f"{p.n_tm} TM(s)); allowed: the lpf geometry, or 'constellation' for a MOSA per TM")
    return float(r[0, 0] - r[1, 0])


def _collinear(p: PlantParameters):
    L = collinear_separation(p)
    m, Itm, Msc = p.tm_mass, p.tm_inertia, p.sc_mass
    J = np.diag(np.asarray(p.sc_inertia, dtype=np.float64))
    sr = SensorRows()
    sr.add("e_dragfree[0]", {"x1[0]": 1.0, "interferometer[0]": 1.0})
    for k, i in ((1, 1), (2, 2)):                       # y, z: the TMs' mean (capacitive)
        sr.add(f"e_dragfree[{k}]", {f"x1[{i}]": 0.5, f"x2[{i}]": 0.5, f"capacitive_translation[{i}]": 0.5,
                                    f"capacitive_translation[{3 + i}]": 0.5})
    sr.add("e_suspension[0]", {"x2[0]": 1.0, "x1[0]": -1.0, "interferometer[1]": 1.0})
    sr.add("e_attitude[0]", {"eta1[0]": -0.5, "eta2[0]": -0.5, "capacitive_rotation[0]": -0.5,
                             "capacitive_rotation[3]": -0.5})
    sr.add("e_attitude[1]", {"x1[2]": 1 / L, "x2[2]": -1 / L, "capacitive_translation[2]": 1 / L,
                             "capacitive_translation[5]": -1 / L})
    sr.add("e_attitude[2]", {"x1[1]": -1 / L, "x2[1]": 1 / L, "capacitive_translation[1]": -1 / L,
                             "capacitive_translation[4]": 1 / L})
    for k, (l, i) in enumerate(((1, 1), (1, 2), (2, 1), (2, 2))):
        sr.add(f"e_tm_rotation[{k}]", {f"eta{l}[{i}]": 1.0, f"capacitive_rotation[{3 * (l - 1) + i}]": 1.0})
    sr.add("e_tm_rotation[4]", {"eta2[0]": 1.0, "eta1[0]": -1.0, "capacitive_rotation[3]": 1.0,
                                "capacitive_rotation[0]": -1.0})
    for i in range(3):
        sr.add(f"e_guidance[{i}]", {f"phi[{i}]": 1.0, f"star_tracker[{i}]": 1.0})
    cmd = [("dragfree[0]", "F[0]", Msc), ("dragfree[1]", "F[1]", Msc), ("dragfree[2]", "F[2]", Msc),
           ("suspension[0]", "f2[0]", -m)]
    cmd += [(f"attitude[{a}]", f"T[{i}]", -J[i, a]) for a in range(3) for i in range(3)]
    cmd += [(f"tm_rotation[{k}]", f"t{l}[{i}]", -Itm) for k, (l, i) in enumerate(((1, 1), (1, 2), (2, 1), (2, 2)))]
    cmd += [("tm_rotation[4]", "t2[0]", -0.5 * Itm), ("tm_rotation[4]", "t1[0]", 0.5 * Itm)]
    # guidance: the attitude loops hold phi at the TMs' reference, about X their mean angle, about Y
    # (z_TM2 - z_TM1)/L, about Z (y_TM1 - y_TM2)/L (inertial TM positions); the guidance turns that
    # reference by -c (negative feedback on the star tracker's phi)
    cmd += [("guidance[0]", "t1[0]", -Itm), ("guidance[0]", "t2[0]", -Itm),
            ("guidance[1]", "f1[2]", 0.5 * m * L), ("guidance[1]", "f2[2]", -0.5 * m * L),
            ("guidance[2]", "f1[1]", -0.5 * m * L), ("guidance[2]", "f2[1]", 0.5 * m * L)]
    return sr.matrices(), cmd


def _single_tm(p: PlantParameters):
    if p.n_tm != 1 or p.mosa:
        raise ValueError(f"closed_loop.scheme: 'single_tm' needs one TM in a housing fixed in the body (got "
                         f"{p.n_tm} TMs{', on MOSAs' if p.mosa else ''}); allowed: the tianqin-1 geometry")
    m, Itm, Msc = p.tm_mass, p.tm_inertia, p.sc_mass
    J = np.diag(np.asarray(p.sc_inertia, dtype=np.float64))
    sr = SensorRows(extra=[f"c_suspension[{i}]" for i in range(3)])
    for i in range(3):
        sr.add(f"e_suspension[{i}]", {f"x1[{i}]": 1.0, f"capacitive_translation[{i}]": 1.0})
    for i in range(3):                 # the measured acceleration: the servo's command (minus its sign)
        sr.add(f"e_dragfree[{i}]", {f"c_suspension[{i}]": 1.0})
    for i in range(3):
        sr.add(f"e_attitude[{i}]", {f"phi[{i}]": 1.0, f"star_tracker[{i}]": 1.0})
    for i in range(3):
        sr.add(f"e_tm_rotation[{i}]", {f"eta1[{i}]": 1.0, f"capacitive_rotation[{i}]": 1.0})
    cmd = [(f"suspension[{i}]", f"f1[{i}]", -m) for i in range(3)]
    cmd += [(f"dragfree[{i}]", f"F[{i}]", Msc) for i in range(3)]
    cmd += [(f"attitude[{a}]", f"T[{i}]", -J[i, a]) for a in range(3) for i in range(3)]
    cmd += [(f"tm_rotation[{i}]", f"t1[{i}]", -Itm) for i in range(3)]
    return sr.matrices(), cmd


def scheme_blocks(scheme: str, p: PlantParameters, wp: WorkingPoint):
    """(sensor block (D, input names, output names), actuator commands [(channel, plant input, gain)]) of a
    single-spacecraft ``scheme``
    ("collinear" or "single_tm"); ValueError (one line naming the key) for a geometry it cannot control."""
    del wp                                  # the schemes' sensing does not depend on the working point
    if scheme == "collinear":
        return _collinear(p)
    if scheme == "single_tm":
        return _single_tm(p)
    raise ValueError(f"closed_loop.scheme: {scheme!r} is not a single-spacecraft scheme; allowed: collinear, "
                     "single_tm")
