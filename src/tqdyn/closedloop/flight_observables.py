"""What the flight papers plot, from a closed loop: LISA Pathfinder's differential acceleration Delta g and
the spacecraft's stability in six degrees of freedom, TianQin-1's measured residual acceleration
(docs/closed-loop-validation.md).

**Delta g** (Armano et al. 2016, PRL 116, 231101; "collinear" scheme).  The flight estimator of the two
TMs' differential acceleration along X from the interferometer readouts o1 = x1 + n_1, o12 = x2 - x1 + n_12,
the stiffnesses k_l (x'' = -k x) and TM 2's commanded electrostatic acceleration g2:

    Delta g = o12'' + k2 o12 + (k2 - k1) o1 - g2.

With x_l'' = -a_housing_l - k_l x_l + f_l/m + a_l, the housings' accelerations along the TM line cancel
(a rotation of the spacecraft moves them across it), so Delta g = a_2 - a_1 + (f2 - m g2)/m - f1/m
+ (s^2 + k2) n_12 + (k2 - k1) n_1: the TMs' force noise, the electrostatic forces beyond the command
(actuation noise, cross-talk from the other axes) and the readout, whatever the controllers.  The loop's
transfer of every noise input is taken from its outputs: the relative accelerations x_l'' and positions x_l
along the sensitive axis and the suspension's command c (g2 = -c).

**Stability** (Armano et al. 2019, PRD 99, 082001): the spacecraft's acceleration with respect to its local
geodesic, (2 pi f)^2 |u| along X, Y, Z (u the displacement from the nominal orbit; the orbit's tide, below
1e-12 s^-2 for LISA Pathfinder, is negligible at mHz) and (2 pi f)^2 |phi| about X, Y, Z (Theta, Eta, Phi).

**Residual acceleration** (TianQin-1, Luo et al. 2020; Xiao et al. 2022; "single_tm" scheme): what the
inertial sensor measures along its axes, the servo's commanded acceleration -c_suspension.

ASDs one-sided (m s^-2/Hz^1/2, rad s^-2/Hz^1/2); frequencies in Hz; S frame.
"""

from __future__ import annotations

import math

import numpy as np

from .budget import closed_loop_response
from .loop import SOURCES, ClosedLoop, source_inputs
from .plant import PlantParameters

__all__ = ["STABILITY_DOF", "delta_g_budget", "delta_g_response", "residual_acceleration_budget",
           "stability_budget"]

#: The six degrees of freedom of the stability: name -> (output, unit of the acceleration).
STABILITY_DOF = {"X": ("sc_position_x", "m/s^2"), "Y": ("sc_position_y", "m/s^2"), "Z": ("sc_position_z", "m/s^2"),
                 "Theta": ("sc_attitude_x", "rad/s^2"), "Eta": ("sc_attitude_y", "rad/s^2"),
                 "Phi": ("sc_attitude_z", "rad/s^2")}


def _inputs(noise: dict) -> tuple[list, list]:
    sources = [s for s in SOURCES if s in noise]
    return sources, [x for s in sources for x in source_inputs(s)]


def _per_source(H: np.ndarray, noise: dict, sources: list, f) -> np.ndarray:
    """(n_source, n_f) ASD from the transfers H (n_input, n_f) of the sources' components (summed in power)."""
    out = np.zeros((len(sources), len(f)))
    k = 0
    for j, s in enumerate(sources):
        n = SOURCES[s][0]
        out[j] = np.sqrt(np.sum(np.abs(H[k:k + n]) ** 2, axis=0)) * noise[s].asd(f)
        k += n
    return out


def delta_g_response(cl: ClosedLoop, p: PlantParameters, f, inputs: list) -> np.ndarray:
    """(n_input, n_f) complex transfer from the noise ``inputs`` to the flight estimator Delta g (module
    docstring) of a "collinear" loop with plant parameters ``p`` at ``f`` [Hz]."""
    k1, k2 = float(p.stiffness[0][0]), float(p.stiffness[1][0])
    outs = ["tm1_relative_acceleration", "tm2_relative_acceleration", "tm1_sc_jitter", "tm2_sc_jitter",
            "c_suspension[0]"]
    G = closed_loop_response(cl, f, outs, inputs)
    s2 = (2j * math.pi * np.asarray(f, dtype=np.float64)) ** 2
    H = G[1] - G[0] + k2 * (G[3] - G[2]) + (k2 - k1) * G[2] + G[4]
    for name, extra in (("interferometer[1]", s2 + k2), ("interferometer[0]", (k2 - k1) + 0 * s2)):
        if name in inputs:
            H[inputs.index(name)] += extra
    return H


def delta_g_budget(cl: ClosedLoop, p: PlantParameters, noise: dict, f) -> tuple[np.ndarray, list]:
    """ASD (n_source, n_f) [m s^-2/Hz^1/2] of Delta g per noise source, and the source names."""
    f = np.asarray(f, dtype=np.float64)
    sources, inputs = _inputs(noise)
    return _per_source(delta_g_response(cl, p, f, inputs), noise, sources, f), sources


def stability_budget(cl: ClosedLoop, noise: dict, f) -> tuple[dict, list]:
    """{dof: ASD (n_source, n_f)} of the spacecraft's acceleration w.r.t. its local geodesic (module
    docstring; :data:`STABILITY_DOF`), and the source names."""
    f = np.asarray(f, dtype=np.float64)
    sources, inputs = _inputs(noise)
    G = closed_loop_response(cl, f, [o for o, _u in STABILITY_DOF.values()], inputs)
    w2 = (2 * math.pi * f) ** 2
    return {dof: _per_source(G[k] * w2, noise, sources, f) for k, dof in enumerate(STABILITY_DOF)}, sources


def residual_acceleration_budget(cl: ClosedLoop, noise: dict, f, axis: int = 0) -> tuple[np.ndarray, list]:
    """ASD (n_source, n_f) [m s^-2/Hz^1/2] of the acceleration the inertial sensor measures along S axis
    ``axis`` ("single_tm" scheme: the servo's command), and the source names."""
    f = np.asarray(f, dtype=np.float64)
    sources, inputs = _inputs(noise)
    G = closed_loop_response(cl, f, [f"c_suspension[{axis}]"], inputs)
    return _per_source(G[0], noise, sources, f), sources
