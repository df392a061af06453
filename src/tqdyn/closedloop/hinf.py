"""H-infinity mixed-sensitivity design over a spacecraft's whole multivariable plant (``closed_loop.design =
"hinf"``; docs/closed-loop.md#a-multivariable-design).

The design plant G (:func:`design_plant`) is the map from the controller outputs ``c_<loop>[k]`` (the
acceleration commands, m/s^2 or rad/s^2) to the error signals ``e_<loop>[k]`` (m or rad) through the actuators,
the linearised plant and the sensors of :func:`tqdyn.closedloop.loop.loop_blocks`: 17 inputs, 17 outputs, the
plant's 40 states less the spacecraft's displacement from its orbit (``u``, ``du``: no sensor sees it, no
actuator but the drag-free thrust moves it, and its Hill modes are unstable: undetectable states no
controller can stabilise), 34 states.  No reduction is needed: the synthesis plant has 51 states.

Weights (diagonal, one per channel k, :func:`weights`):

* W1_k(s) = (s / M_s + w_k) / (s + w_k A) on the sensitivity S = (I + G K)^-1: |S| below |1/W1|, i.e. rising
  as f / f_k below the loop's bandwidth f_k = w_k / 2 pi (:data:`tqdyn.closedloop.missions.CROSSOVER_HZ`,
  the per-loop design's crossovers: docs/closed-loop.md#controllers-and-margins), a peak M_s = 2 (a
  sensitivity peak of 2 bounds every loop-at-a-time gain margin beyond [2/3, 2] and phase margin beyond
  29 deg) and a low-frequency floor A = 1e-4;
* W2_k = 1 / (r w_k)^2 on K S (the command per unit error, s^-2): the actuator authority, a command
  per unit error no larger than that of a double-integrator loop of bandwidth r f_k (r = 30: the
  actuators' bandwidth ratio).

The synthesis is python-control's mixed-sensitivity augmentation (``control.augw``) and SLICOT's
H-infinity solver (``slycot.sb10ad``, what ``control.hinfsyn`` calls; here with gamma's bisection started at
:data:`GAMMA_START` instead of 1e100, and its tolerance :data:`GAMMA_TOL`: ~10 Riccati pairs instead of
~350).  The plant's rigid-body and MOSA modes sit on the imaginary axis, where the H-infinity solution does
not exist; the design therefore shifts the axis (alpha-stability): it synthesises K_s for G(s - eps) (A +
eps I) and realises K(s) = K_s(s + eps) (A_K - eps I), so that every pole of the true closed loop is that of
the synthesised one moved left by eps = :data:`SHIFT_RAD_S` (stable by construction, with decay rate eps).

Units: SI; frequencies w in rad/s.  Time scale: the working point's (frozen coefficients).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import control
import numpy as np

from .budget import DesignError
from .loop import channel_names, loop_blocks
from .plant import PlantParameters, WorkingPoint

__all__ = ["DESIGN_KEY", "GAMMA_START", "GAMMA_TOL", "HinfController", "SHIFT_RAD_S", "design_plant",
           "synthesise", "weights"]

#: The scenario key whose value selects this design (errors name it).
DESIGN_KEY = "closed_loop.design"
#: Peak sensitivity M_s, low-frequency floor A of W1, actuator bandwidth ratio r of W2 (module docstring).
PEAK_SENSITIVITY = 2.0
SENSITIVITY_FLOOR = 1e-4
AUTHORITY_RATIO = 30.0
#: The imaginary axis shift eps [rad/s] (2 pi x 10 uHz: below every band, above the plant's near-axis modes'
#: distance from it, 3e-5 rad/s at most).
SHIFT_RAD_S = 2 * math.pi * 1e-5
#: Start and relative tolerance of gamma's bisection (``slycot.sb10ad`` job 1).
GAMMA_START = 10.0
GAMMA_TOL = 1e-2


@dataclass(frozen=True)
class HinfController:
    """A synthesised multivariable controller.

    system : control.StateSpace (continuous), inputs ``e_<loop>[k]``, outputs ``c_<loop>[k]`` (the channels'
        order, :func:`tqdyn.closedloop.loop.channel_names`); negative feedback as the per-loop controllers
        (the actuators apply -c).
    gamma : the H-infinity norm of the weighted closed loop [W1 S; W2 K S] the solver reports (< 1).
    weighted : control.StateSpace, that weighted closed loop (of the shifted plant; its H-infinity norm is gamma).
    bandwidth_hz : (n_channel,) f_k [Hz]; shift : eps [rad/s]; synthesis_s : wall time [s].
    """

    system: control.StateSpace
    gamma: float
    weighted: control.StateSpace
    bandwidth_hz: tuple
    shift: float
    synthesis_s: float
    channels: tuple

    @property
    def order(self) -> int:
        """The controller's number of states."""
        return int(self.system.nstates)


def design_plant(p: PlantParameters, wp: WorkingPoint, attitude_z_sensor: str = "dws",
                 scheme: str = "constellation") -> control.StateSpace:
    """G: c -> e (module docstring) of a spacecraft with parameters ``p`` at working point ``wp``, without the
    orbit-displacement states; named inputs ``c_<chan>``, outputs ``e_<chan>``."""
    b = loop_blocks(p, wp, attitude_z_sensor, scheme)
    A, B, C, D, pin, pout, pst = b["plant"]
    chans = b["channels"]
    P = control.ss(A, B, C, D, inputs=pin, outputs=pout, states=pst, name="plant")
    from .blocks import static_block

    ins, outs = [f"c_{c}" for c in chans], [f"e_{c}" for c in chans]
    G = control.interconnect([P, static_block(*b["sensors"], "sensors"), static_block(*b["actuators"], "actuators")],
                             inplist=ins, outlist=outs, inputs=ins, outputs=outs, check_unused=False,
                             warn_duplicate=False)
    keep = [k for k, s in enumerate(G.state_labels) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
    drop = [k for k in range(G.nstates) if k not in keep]
    if np.any(G.A[np.ix_(keep, drop)]) or np.any(G.C[:, drop]):     # u must not reach the errors
        raise DesignError(DESIGN_KEY, "the orbit displacement reaches the sensors; allowed: 'per_loop' here")
    return control.ss(G.A[np.ix_(keep, keep)], G.B[keep], G.C[:, keep], G.D, inputs=ins, outputs=outs)


def weights(channels, peak_sensitivity: float = PEAK_SENSITIVITY, authority_ratio: float = AUTHORITY_RATIO) \
        -> tuple[control.StateSpace, control.StateSpace, np.ndarray]:
    """(W1, W2, w (n,) [rad/s]) of the ``channels`` ``<loop>[k]`` (module docstring; M_s = ``peak_sensitivity``,
    r = ``authority_ratio``)."""
    from .missions import CROSSOVER_HZ

    w = np.array([2 * math.pi * CROSSOVER_HZ[c.split("[")[0]] for c in channels])
    W1 = control.append(*[control.ss(control.tf([1.0 / peak_sensitivity, wk], [1.0, wk * SENSITIVITY_FLOOR]))
                          for wk in w])
    W2 = control.ss(np.zeros((0, 0)), np.zeros((0, len(w))), np.zeros((len(w), 0)),
                    np.diag(1.0 / (authority_ratio * w) ** 2))
    return W1, W2, w


def _sb10ad(P: control.StateSpace, n_meas: int, n_con: int):
    """SLICOT's H-infinity synthesis of the generalised plant ``P`` (python-control's ``hinfsyn`` call with
    another start of gamma's bisection): (K, closed loop, gamma)."""
    from slycot import sb10ad

    out = sb10ad(P.nstates, P.ninputs, P.noutputs, n_con, n_meas, GAMMA_START, P.A, P.B, P.C, P.D, job=1,
                 gtol=GAMMA_TOL)
    return control.ss(*out[1:5]), control.ss(*out[5:9]), float(out[0])


def synthesise(p: PlantParameters, wp: WorkingPoint, attitude_z_sensor: str = "dws",
               scheme: str = "constellation", where: str = "", peak_sensitivity: float = PEAK_SENSITIVITY,
               authority_ratio: float = AUTHORITY_RATIO) -> HinfController:
    """The H-infinity mixed-sensitivity controller (module docstring) of a spacecraft with parameters ``p`` at
    working point ``wp``, weights of peak sensitivity ``peak_sensitivity`` (``closed_loop.hinf_peak_sensitivity``)
    and authority ratio ``authority_ratio`` (``closed_loop.hinf_authority_ratio``).  DesignError (one line naming ``closed_loop.design``) for a scheme other than
    "constellation", a synthesis that fails (no stabilising controller for the weights) or a gamma > 1 (the
    weights cannot be met); ``where`` names the spacecraft in that line."""
    at = f" for {where}" if where else ""
    if scheme != "constellation":
        raise DesignError(DESIGN_KEY, f"'hinf' is not available for the {scheme!r} scheme{at}; allowed: 'hinf' "
                                      "with the 'constellation' scheme (tianqin, lisa, taiji), 'per_loop' otherwise")
    t0 = time.perf_counter()
    chans = channel_names(scheme)
    G = design_plant(p, wp, attitude_z_sensor, scheme)
    Gs = control.ss(G.A + SHIFT_RAD_S * np.eye(G.nstates), G.B, G.C, G.D)
    W1, W2, w = weights(chans, peak_sensitivity, authority_ratio)
    with warnings.catch_warnings():
        # python-control 0.10's augw calls its own deprecated connect(): not the caller's to act on
        warnings.filterwarnings("ignore", message=r"connect\(\) is deprecated", category=FutureWarning)
        P = control.augw(Gs, W1, W2, None)
    n = len(chans)
    try:
        Ks, CL, gamma = _sb10ad(P, n, n)
    except Exception as exc:  # noqa: BLE001 - slycot's errors (SlycotArithmeticError, ValueError) as one line
        why = " ".join(str(exc).split())[:90]
        raise DesignError(DESIGN_KEY, f"'hinf': the synthesis failed{at} ({why}); allowed: 'per_loop', or "
                                      "weights a stabilising controller can meet") from None
    if not gamma <= 1.0:
        raise DesignError(DESIGN_KEY, f"'hinf': the weights cannot be met{at} (gamma = {gamma:.3g} > 1 with "
                                      f"hinf_peak_sensitivity = {peak_sensitivity:g}, hinf_authority_ratio = "
                                      f"{authority_ratio:g}); allowed: larger ones (gamma <= 1), or 'per_loop'")
    # augw closes u = K (w - G u); the loop closes c = C e with e = G c (the actuators apply -c): C = -K
    K = control.ss(Ks.A - SHIFT_RAD_S * np.eye(Ks.nstates), Ks.B, -Ks.C, -Ks.D,
                   inputs=[f"e_{c}" for c in chans], outputs=[f"c_{c}" for c in chans], name="C_hinf")
    return HinfController(system=K, gamma=gamma, weighted=CL, bandwidth_hz=tuple(w / (2 * math.pi)),
                          shift=SHIFT_RAD_S, synthesis_s=time.perf_counter() - t0, channels=tuple(chans))
