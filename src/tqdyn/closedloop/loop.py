"""The closed loop of one spacecraft: plant, sensors, controllers and actuators joined by name.

Built with ``control.interconnect`` (signals connected by their names).  The closed loop's inputs
are the noise sources (:data:`SOURCES`, each component in the unit of its ASD) and one loop-break
input ``d_<loop>[k]`` per controller channel (added to the controller output; the loop-at-a-time
gain is L = -T/(1 + T), T the closed-loop transfer from ``d`` to the controller output ``c``);
its outputs are the quantities of :data:`OUTPUTS`, the controller signals ``c_<loop>[k]`` and the
in-loop coordinates ``e_<loop>[k]`` (each controller's input).

Frames: spacecraft quantities in S (body frame at the working point), TM quantities in OA_l
(x the sensitive axis of the presets, X_OA_l).  Units SI.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from ..scenario.closed_loop import ATTITUDE_Z_SENSORS, SOURCES
from .blocks import SensorRows, source_inputs, static_block as _static
from .controllers import LOOPS, Controller
from .plant import PlantParameters, WorkingPoint, plant_matrices, sensitive_basis
from .schemes import scheme_blocks

__all__ = ["OUTPUTS", "SOURCES", "ClosedLoop", "SensorRows", "build_closed_loop", "channel_names",
           "controller_realisations", "loop_blocks", "output_names", "source_inputs"]

_AX = ("x", "y", "z")


def _output_table() -> dict:
    out = {}
    for i, a in enumerate(_AX):
        out[f"sc_attitude_{a}"] = ("rad", "S", f"spacecraft attitude jitter about {a.upper()}_S")
    for l in (1, 2):
        out[f"mosa_angle_{l}"] = ("rad", "about Z_S", f"MOSA {l} angle jitter")
    for l in (1, 2):
        for a in _AX:
            out[f"tm{l}_displacement_{a}"] = ("m", f"OA_{l}", f"TM {l} minus its housing centre, {a}")
        for a in _AX:
            out[f"tm{l}_rotation_{a}"] = ("rad", f"OA_{l}", f"TM {l} rotation relative to its housing, {a}")
        out[f"tm{l}_sc_jitter"] = ("m", "sensitive axis", f"spacecraft-TM {l} jitter along the sensitive axis")
        out[f"tm{l}_acceleration"] = ("m/s^2", "sensitive axis",
                                      f"residual (non-gravitational) acceleration of TM {l} along its sensitive axis")
        out[f"tm{l}_relative_acceleration"] = ("m/s^2", "sensitive axis",
                                               f"acceleration of TM {l} relative to its housing, sensitive axis")
    for a in _AX:
        out[f"thrust_force_{a}"] = ("N", "S", f"thrust along {a.upper()}_S (commands and noise)")
    for a in _AX:
        out[f"thrust_torque_{a}"] = ("N m", "S", f"thruster torque about {a.upper()}_S")
    for l in (1, 2):
        for a in _AX:
            out[f"tm{l}_es_force_{a}"] = ("N", f"OA_{l}", f"electrostatic force on TM {l}, {a}")
        for a in _AX:
            out[f"tm{l}_es_torque_{a}"] = ("N m", f"OA_{l}", f"electrostatic torque on TM {l}, {a}")
    for l in (1, 2):
        out[f"mosa{l}_torque"] = ("N m", "about Z_S", f"MOSA {l} actuator torque")
    for a in _AX:
        out[f"sc_position_{a}"] = ("m", "S", f"spacecraft displacement from its nominal orbit, {a.upper()}_S "
                                               "(frequency domain only)")
    return out


#: Outputs: name -> (unit, frame, meaning).
OUTPUTS = _output_table()
#: Outputs left out of the time-domain simulation (a branch nothing feeds back from: the spacecraft's
#: displacement from its nominal orbit, unstable at orbital frequencies through the Hill dynamics).
FREQUENCY_ONLY = tuple(k for k in OUTPUTS if k.startswith("sc_position"))


def output_names(time_domain: bool = False) -> list[str]:
    """The output names (:data:`OUTPUTS` order); ``time_domain``: without :data:`FREQUENCY_ONLY`."""
    return [k for k in OUTPUTS if not (time_domain and k in FREQUENCY_ONLY)]



@dataclass(frozen=True)
class ClosedLoop:
    """One spacecraft's closed loop at one working point.

    system : control.StateSpace, continuous; inputs: noise (SOURCES order) then ``d_*``; outputs:
        :data:`OUTPUTS` (order of :func:`output_names`), then the controller outputs ``c_*``, then their
        inputs ``e_*`` (the in-loop coordinates: the sensed errors, sensor noise included).
    channel_names : the controller channels ``<loop>[k]``.
    dc_force : dict of the DC levels that scale the force-proportional sources:
        ``thruster_gain`` (3,) [N], ``actuation_force`` (6,) [N], ``actuation_torque`` (6,) [N m].
    """

    system: control.StateSpace
    channel_names: tuple
    dc_force: dict
    sources: tuple = ()
    outputs: tuple = ()

    def source_components(self) -> dict:
        """{source: number of input components} of the noise inputs (``<source>[k]``)."""
        return {s: SOURCES[s][0] for s in SOURCES} if not self.sources else dict(self.sources)

    def time_outputs(self) -> list:
        """The outputs the time domain runs."""
        return output_names(time_domain=True) if not self.outputs else list(self.outputs)


def _scheme_loops(scheme: str) -> dict:
    """The loops (name -> (channels, ...)) of the control ``scheme``; ValueError (one line) for an unknown one."""
    from ..scenario.closed_loop import SCHEME_LOOPS, SCHEMES

    if scheme not in SCHEMES:
        raise ValueError(f"closed_loop.scheme: {scheme!r} is not a control scheme; allowed: {', '.join(SCHEMES)}")
    return SCHEME_LOOPS[scheme]


def channel_names(scheme: str = "constellation") -> list[str]:
    """The controller channels ``<loop>[k]`` of the ``scheme``'s loops, in their order (:data:`LOOPS` for
    "constellation")."""
    return [f"{loop}[{k}]" for loop, (ch, *_r) in _scheme_loops(scheme).items() for k in range(len(ch))]


def controller_realisations(controllers: dict, loops: dict = LOOPS) -> list[tuple]:
    """One state-space realisation (A, B, C, D) of each channel's controller (python-control's of the
    controller's transfer function), in channel order of ``loops`` (:func:`channel_names`).  ValueError (one
    line) for a loop without a controller."""
    out = []
    for loop, (channels, *_rest) in loops.items():
        ctl = controllers.get(loop)
        if ctl is None:
            raise ValueError(f"closed_loop.controllers.{loop}: no controller for this loop; allowed: one for each "
                             f"loop of the scheme ({', '.join(loops)})")
        if not isinstance(ctl, Controller):
            raise TypeError(f"controllers[{loop!r}] is not a Controller")
        tf = control.ss(ctl.tf())
        out += [(np.asarray(tf.A), np.asarray(tf.B), np.asarray(tf.C), np.asarray(tf.D))] * len(channels)
    return out


def _controllers_ss(controllers: dict, loops: dict = LOOPS) -> list:
    chans = [f"{loop}[{k}]" for loop, (ch, *_r) in loops.items() for k in range(len(ch))]
    return [control.ss(*abcd, inputs=[f"e_{c}"], outputs=[f"c_{c}"], name=f"C_{c.replace('[', '_').rstrip(']')}")
            for c, abcd in zip(chans, controller_realisations(controllers, loops))]


def _sensors(basis, yoa, attitude_z_sensor: str) -> tuple:
    """Plant coordinates + sensor noise -> the error signals ``e_<loop>[k]`` (static), "constellation" scheme:
    (D, input names, output names); ``basis`` (2, 3, 3) of :func:`~tqdyn.closedloop.plant.sensitive_basis`,
    ``yoa`` (2, 3) Y_OA_l in S."""
    sr = SensorRows()
    for l in (1, 2):      # drag-free: IFO along e_l
        e = basis[l - 1, 0]
        sr.add(f"e_dragfree[{l - 1}]", {**{f"x{l}[{i}]": e[i] for i in range(3)}, f"interferometer[{l - 1}]": 1.0})
    sr.add("e_dragfree[2]", {"x1[2]": 0.5, "x2[2]": 0.5, "capacitive_translation[2]": 0.5,
                             "capacitive_translation[5]": 0.5})
    for l in (1, 2):      # suspension: capacitive along p_l
        pv = basis[l - 1, 1]
        sr.add(f"e_suspension[{l - 1}]", {**{f"x{l}[{i}]": pv[i] for i in range(3)},
                                          **{f"capacitive_translation[{3 * (l - 1) + i}]": pv[i] for i in range(3)}})
    sr.add("e_suspension[2]", {"x1[2]": 0.5, "x2[2]": -0.5, "capacitive_translation[2]": 0.5,
                               "capacitive_translation[5]": -0.5})
    # DWS: pitch_l = Y_OA_l . phi + n, yaw_l = phi_z + dth_l + n; attitude estimate (phi_x, phi_y) from the
    # two pitches, phi_z from the mean yaw
    Pm = np.linalg.inv(yoa[:, :2])                      # (phi_x, phi_y) = Pm @ (pitch_1, pitch_2)
    pitch = [dict({f"phi[{i}]": yoa[l][i] for i in range(3)}, **{f"dws[{2 * l}]": 1.0}) for l in range(2)]
    yaw = [{"phi[2]": 1.0, f"dth[{l}]": 1.0, f"dws[{2 * l + 1}]": 1.0} for l in range(2)]

    def comb(ws, ds):
        out: dict = {}
        for w, d in zip(ws, ds):
            for s, c in d.items():
                out[s] = out.get(s, 0.0) + w * c
        return out

    for a in range(2):
        sr.add(f"e_attitude[{a}]", comb(Pm[a], pitch))
    if attitude_z_sensor == "star_tracker":
        sr.add("e_attitude_z[0]", {"phi[2]": 1.0, "star_tracker[2]": 1.0})
    else:     # mean DWS yaw minus the mean MOSA angle from the encoders
        sr.add("e_attitude_z[0]", comb((0.5, 0.5, -0.5, -0.5),
                                       yaw + [{f"dth[{l}]": 1.0, f"mosa_encoder[{l}]": 1.0} for l in range(2)]))
    for l in range(2):
        sr.add(f"e_mosa[{l}]", yaw[l])
    for l in (1, 2):
        for i in range(3):
            sr.add(f"e_tm_rotation[{3 * (l - 1) + i}]",
                   {f"eta{l}[{i}]": 1.0, f"capacitive_rotation[{3 * (l - 1) + i}]": 1.0})
    return sr.matrices()


def _constellation_commands(p: PlantParameters, basis, e_S) -> list:
    """(channel, plant input, gain) of the "constellation" scheme's actuators: ``e_S`` (2, 3) the sensitive
    axes in S.  Raises ValueError (one line) when the sensitive axes leave the drag-free loops undetermined."""
    m, Itm, Im, Msc = p.tm_mass, p.tm_inertia, p.mosa_inertia, p.sc_mass
    J = np.diag(np.asarray(p.sc_inertia, dtype=np.float64))
    out = []

    def cmd(chan, inp, gain):
        out.append((chan, inp, gain))

    Ninv = np.linalg.inv(np.array([e_S[0], e_S[1], [0.0, 0.0, 1.0]]))   # F = M N^-1 c (drag-free)
    for k in range(3):
        for i in range(3):
            cmd(f"dragfree[{k}]", f"F[{i}]", Msc * Ninv[i, k])
    for l in (1, 2):
        pv, q = basis[l - 1, 1], basis[l - 1, 2]
        for i in range(3):
            cmd(f"suspension[{l - 1}]", f"f{l}[{i}]", -m * pv[i])
            cmd("suspension[2]", f"f{l}[{i}]", -m * q[i] * (1.0 if l == 1 else -1.0))
    for a in range(3):
        for i in range(3):
            cmd(f"attitude[{a}]" if a < 2 else "attitude_z[0]", f"T[{i}]", -J[i, a])
    cmd("mosa[0]", "tm[0]", -Im)
    cmd("mosa[1]", "tm[1]", -Im)
    for l in (1, 2):
        for i in range(3):
            cmd(f"tm_rotation[{3 * (l - 1) + i}]", f"t{l}[{i}]", -Itm)
    return out


def _actuators(p: PlantParameters, wp: WorkingPoint, chans, commands) -> tuple[control.StateSpace, dict]:
    """Controller outputs ``c`` + loop breaks ``d`` + actuation noise -> the plant inputs (static), and the
    DC levels of the force-proportional sources (:attr:`ClosedLoop.dc_force`).  ``chans`` the controller
    channels ``<loop>[k]``; ``commands`` (channel, plant input, gain) triples (the scheme's)."""
    m, Itm, Msc = p.tm_mass, p.tm_inertia, p.sc_mass
    ain = ([f"c_{c}" for c in chans] + [f"d_{c}" for c in chans] + source_inputs("thruster_force")
           + source_inputs("thruster_gain") + source_inputs("thruster_torque") + source_inputs("actuation_force")
           + source_inputs("actuation_torque") + source_inputs("mosa_actuator") + source_inputs("tm_force")
           + source_inputs("tm_torque"))
    aout = ([f"F[{i}]" for i in range(3)] + [f"T[{i}]" for i in range(3)]
            + [f"f{l}[{i}]" for l in (1, 2) for i in range(3)] + [f"t{l}[{i}]" for l in (1, 2) for i in range(3)]
            + ["tm[0]", "tm[1]"] + [f"a{l}[{i}]" for l in (1, 2) for i in range(3)]
            + [f"b{l}[{i}]" for l in (1, 2) for i in range(3)])
    ai = {s: k for k, s in enumerate(ain)}
    ao = {s: k for k, s in enumerate(aout)}
    Da = np.zeros((len(aout), len(ain)))

    for chan, out, gain in commands:
        Da[ao[out], ai[f"c_{chan}"]] += gain
        Da[ao[out], ai[f"d_{chan}"]] += gain
    G = np.asarray(wp.a_dragfree, dtype=np.float64)
    dc = {"thruster_gain": Msc * np.abs(G),
          "actuation_force": m * np.abs(np.asarray(wp.a_suspension, dtype=np.float64)).reshape(6),
          "actuation_torque": Itm * np.abs(np.asarray(wp.alpha_suspension, dtype=np.float64)).reshape(6)}
    for i in range(3):
        Da[ao[f"F[{i}]"], ai[f"thruster_force[{i}]"]] = 1.0
        Da[ao[f"F[{i}]"], ai[f"thruster_gain[{i}]"]] = dc["thruster_gain"][i]
        Da[ao[f"T[{i}]"], ai[f"thruster_torque[{i}]"]] = 1.0
    for l in (1, 2):
        for i in range(3):
            k = 3 * (l - 1) + i
            Da[ao[f"f{l}[{i}]"], ai[f"actuation_force[{k}]"]] = dc["actuation_force"][k]
            Da[ao[f"t{l}[{i}]"], ai[f"actuation_torque[{k}]"]] = dc["actuation_torque"][k]
            Da[ao[f"a{l}[{i}]"], ai[f"tm_force[{k}]"]] = 1.0
            Da[ao[f"b{l}[{i}]"], ai[f"tm_torque[{k}]"]] = 1.0
    for l in range(2):
        Da[ao[f"tm[{l}]"], ai[f"mosa_actuator[{l}]"]] = 1.0
    return (Da, ain, aout), dc


def _observables(p: PlantParameters, basis) -> tuple:
    """The named outputs (:data:`OUTPUTS`) from the plant outputs and the actuator signals (static: D,
    input names, output names)."""
    oin = ([f"u[{i}]" for i in range(3)] + [f"phi[{i}]" for i in range(3)] + ["dth[0]", "dth[1]"]
           + [f"x{l}[{i}]" for l in (1, 2) for i in range(3)] + [f"eta{l}[{i}]" for l in (1, 2) for i in range(3)]
           + [f"acc{l}[{i}]" for l in (1, 2) for i in range(3)] + [f"xdd{l}[{i}]" for l in (1, 2) for i in range(3)]
           + [f"F[{i}]" for i in range(3)] + [f"T[{i}]" for i in range(3)]
           + [f"f{l}[{i}]" for l in (1, 2) for i in range(3)] + [f"t{l}[{i}]" for l in (1, 2) for i in range(3)]
           + ["tm[0]", "tm[1]"])
    oi = {s: k for k, s in enumerate(oin)}
    onames = output_names()
    Do = np.zeros((len(onames), len(oin)))
    X = np.eye(3) + p.crosstalk * (np.ones((3, 3)) - np.eye(3))

    def put(name, coeffs):
        r = onames.index(name)
        for s, c in coeffs.items():
            Do[r, oi[s]] += c

    for i, a in enumerate(_AX):
        put(f"sc_attitude_{a}", {f"phi[{i}]": 1.0})
        put(f"thrust_force_{a}", {f"F[{i}]": 1.0})
        put(f"thrust_torque_{a}", {f"T[{i}]": 1.0})
        put(f"sc_position_{a}", {f"u[{i}]": 1.0})
    for l in (1, 2):
        put(f"mosa_angle_{l}", {f"dth[{l - 1}]": 1.0})
        put(f"mosa{l}_torque", {f"tm[{l - 1}]": 1.0})
        e = basis[l - 1, 0]
        put(f"tm{l}_sc_jitter", {f"x{l}[{i}]": e[i] for i in range(3)})
        put(f"tm{l}_acceleration", {f"acc{l}[{i}]": e[i] for i in range(3)})
        put(f"tm{l}_relative_acceleration", {f"xdd{l}[{i}]": e[i] for i in range(3)})
        for i, a in enumerate(_AX):
            put(f"tm{l}_displacement_{a}", {f"x{l}[{i}]": 1.0})
            put(f"tm{l}_rotation_{a}", {f"eta{l}[{i}]": 1.0})
            put(f"tm{l}_es_force_{a}", {f"f{l}[{j}]": X[i, j] for j in range(3)})
            put(f"tm{l}_es_torque_{a}", {f"t{l}[{j}]": X[i, j] for j in range(3)})
    return Do, oin, onames


def _check_sensor(attitude_z_sensor: str) -> None:
    if attitude_z_sensor not in ATTITUDE_Z_SENSORS:
        raise ValueError(f"closed_loop.attitude_z_sensor: {attitude_z_sensor!r} is not a sensor; "
                         f"allowed: {', '.join(repr(x) for x in ATTITUDE_Z_SENSORS)}")


def _constellation_blocks(p: PlantParameters, wp: WorkingPoint, attitude_z_sensor: str):
    """(sensors, commands) of the "constellation" scheme; ValueError (one line) for sensitive axes that do
    not span the plane (collinear test masses: the DWS pitches of the two MOSAs then measure one angle)."""
    from ..constellation.control import oa_rotation
    from ..constellation.spacecraft import MIN_AXES_DETERMINANT

    basis = sensitive_basis(p)                         # (2, 3, 3) rows e, p, q in OA_l
    R = np.transpose(oa_rotation(wp.theta), (0, 2, 1))  # OA_l -> S
    e_S = np.array([R[l] @ basis[l, 0] for l in range(2)])
    yoa = np.array([R[l][:, 1] for l in range(2)])       # Y_OA_l in S
    det = float(np.dot(e_S[0], np.cross(e_S[1], [0.0, 0.0, 1.0])))
    if abs(det) < MIN_AXES_DETERMINANT or abs(np.linalg.det(yoa[:, :2])) < MIN_AXES_DETERMINANT:
        raise ValueError(f"closed_loop.scheme: 'constellation' cannot control parallel sensitive axes "
                         f"(|e_1 . (e_2 x Z_S)| = {abs(det):.3g}): the rotation about the TM line is unobservable; "
                         "allowed: 'collinear'")
    return _sensors(basis, yoa, attitude_z_sensor), _constellation_commands(p, basis, e_S)


def loop_blocks(p: PlantParameters, wp: WorkingPoint, attitude_z_sensor: str = ATTITUDE_Z_SENSORS[0],
                scheme: str = "constellation") -> dict:
    """The blocks of the closed loop of a spacecraft with parameters ``p`` at working point ``wp`` under the
    control ``scheme`` as plain matrices with their signal names (what :func:`build_closed_loop` joins):
    ``plant`` (A, B, C, D, inputs, outputs, states) of :func:`~tqdyn.closedloop.plant.plant_matrices`;
    ``sensors``, ``actuators`` and ``observables`` (D, inputs, outputs) of the static blocks; ``dc_force``
    (:attr:`ClosedLoop.dc_force`); ``channels`` (:func:`channel_names`).  ValueError (one line naming the
    key) for an unknown sensor or scheme, or a geometry the scheme cannot control."""
    _check_sensor(attitude_z_sensor)
    chans = channel_names(scheme)
    if scheme == "constellation":
        sensors, commands = _constellation_blocks(p, wp, attitude_z_sensor)
    else:
        sensors, commands = scheme_blocks(scheme, p, wp)
    actuators, dc = _actuators(p, wp, chans, commands)
    return {"plant": plant_matrices(p, wp), "sensors": sensors, "actuators": actuators,
            "observables": _observables(p, sensitive_basis(p)), "dc_force": dc, "channels": chans}


def build_closed_loop(p: PlantParameters, wp: WorkingPoint, controllers: dict,
                      attitude_z_sensor: str = ATTITUDE_Z_SENSORS[0], scheme: str = "constellation",
                      actuator_gain: dict | None = None) -> ClosedLoop:
    """The closed loop (module docstring) of a spacecraft with parameters ``p`` at working point ``wp``
    with one :class:`~tqdyn.closedloop.controllers.Controller` per loop of the ``scheme`` (or ``controllers`` a
    multivariable controller with a ``system`` e_* -> c_*, :class:`tqdyn.closedloop.hinf.HinfController`)
    (:data:`tqdyn.scenario.closed_loop.SCHEME_LOOPS`: "constellation" (default, :data:`LOOPS`), "collinear",
    "single_tm"; :mod:`tqdyn.closedloop.schemes`).  ``attitude_z_sensor`` ("constellation" only): "dws" (the
    mean DWS yaw minus the mean MOSA encoder angle, default) or "star_tracker".  The blocks
    (:func:`loop_blocks`) are joined by signal name with python-control's check of unused signals on (a
    misnamed signal would leave one unconnected).  ValueError (one line naming the key) for a geometry the
    scheme cannot control.  :func:`tqdyn.closedloop.frequency.closed_loops` builds the same loops for many
    working points at once.  ``actuator_gain`` {plant input (``F[i]``, ``T[i]``, ``f1[i]``, ``t2[i]``, ``tm[l]``):
    factor}: the actuators' true gains (1: as the controllers assume; a Monte Carlo's draws) on the commands."""
    b = loop_blocks(p, wp, attitude_z_sensor, scheme)
    if actuator_gain:
        Da, ain, aout = b["actuators"]
        cols = [k for k, s in enumerate(ain) if s.startswith(("c_", "d_"))]
        Da = Da.copy()
        for name, g in actuator_gain.items():
            Da[aout.index(name), cols] *= g
        b["actuators"] = (Da, ain, aout)
    A, B, C, D, pin, pout, pst = b["plant"]
    P = control.ss(A, B, C, D, inputs=pin, outputs=pout, states=pst, name="plant")
    chans = b["channels"]
    noise = [s for src in SOURCES for s in source_inputs(src)]
    inplist = noise + [f"d_{c}" for c in chans]
    outlist = output_names() + [f"c_{c}" for c in chans] + [f"e_{c}" for c in chans]
    ctl = [controllers.system] if hasattr(controllers, "system") else _controllers_ss(controllers, _scheme_loops(scheme))
    syslist = [P, _static(*b["sensors"], "sensors"), _static(*b["actuators"], "actuators"),
               _static(*b["observables"], "observables")] + ctl
    cl = control.interconnect(syslist, inplist=inplist, outlist=outlist, inputs=inplist, outputs=outlist,
                              name="closed_loop", warn_duplicate=False)
    return ClosedLoop(system=cl, channel_names=tuple(chans), dc_force=b["dc_force"])
