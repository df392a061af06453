"""Tilt-to-length (TTL) of the six links from the closed loop's angle jitter: the map from a spacecraft's
closed-loop angle outputs to its MOSAs' phi and eta, and the per-link TTL and single-link noise ASDs.

**MOSA frames** (derivation in docs/tilt-to-length.md, "Single-link budget from the closed loop").
The closed loop's angles of spacecraft i (:data:`ANGLE_OUTPUTS`, rad): the small rotation phi_S =
(``sc_attitude_x``, ``_y``, ``_z``) of the body from S (S components; X_S the bisector of the two
beams towards the incentre, Z_S = n_ij x n_ik / sin(alpha_i), (i, j, k) the even permutation) and the
MOSA angle perturbations dth_l (``mosa_angle_l``, a rotation of MOSA l about +Z_S).  MOSA l's optical
axis is X_OA_l = X_S turned by +theta/2 (l = 1, facing k) or -theta/2 (l = 2, facing j) about Z_S
(theta the opening angle, :func:`tqdyn.constellation.control.oa_rotation`).  LISA Instrument 2.3's
MOSA ``ij`` has its x axis along the optical axis towards j and is its spacecraft frame turned by the
oriented opening angle a_ij about the spacecraft's z (``eta_ij = cos(a_ij) eta_i - sin(a_ij) theta_i``:
y_ij = cos(a) y_sc - sin(a) x_sc); a_12 = +30 deg puts n_12 at +30 deg about z_sc and n_13 at -30 deg,
so z_sc = n_13 x n_12 / sin = -Z_S, and its frame is x_sc = X_S, y_sc = -Y_S, z_sc = -Z_S (S turned by
pi about X_S).  With the MOSA axes in S,

    x_m = X_OA_l,   z_m = -Z_S,   y_m = z_m x x_m = -Y_OA_l,

the MOSA's yaw (right-handed rotation about z_m, in the constellation plane) and pitch (about y_m,
out of the plane) are, to first order,

    phi_m = z_m . (phi_S + dth_l Z_S) = -(phi_S,z + dth_l)
    eta_m = y_m . phi_S = sin(s_l theta/2) phi_S,x - cos(s_l theta/2) phi_S,y      (s_1 = +1, s_2 = -1)

i.e. LISA Instrument's ``mosa_angles`` with roll theta_i = phi_S,x, pitch eta_i = -phi_S,y,
yaw phi_i = -phi_S,z, MOSA yaw -dth_l, no MOSA pitch (the MOSA turns about Z_S only) and
a_ij = -s_l theta/2.  MOSA l of spacecraft i is link ``i k`` (l = 1) or ``i j`` (l = 2) (:data:`MOSA_NAMES`).

**Link ASD** (one-sided, m/Hz^1/2) of link ij from source s with components q (independent):

    ASD_ij,s(f)^2 = sum_q ( |H^local_ij,q(f)|^2 + |H^distant_ji,q(f)|^2 ) ASD_s(f)^2
    H^k_m,q(f) = c^k_phi,m G_phi_m,q(f) + c^k_eta,m G_eta_m,q(f)

G the complex closed-loop transfer from the source's input q to the MOSA angle (phi and eta of the same
source add coherently); the local term on spacecraft i, the distant one (the emitting MOSA ji's
coefficients) on spacecraft j, whose noise is independent (the delay tau_ij is a phase: it drops out of
the power).  Linear coefficients only: a quadratic coefficient gives a second-order term and is refused.

Units SI (rad, m, m/rad, Hz); arrays (n_f,) on the frequency grid f (Hz > 0).
"""

from __future__ import annotations

import math

import numpy as np

from .._choices import unknown
from ..constellation.control import oa_rotation
from ..closedloop.budget import closed_loop_response
from ..closedloop.loop import SOURCES, ClosedLoop, source_inputs
from .coupling import MOSAS, TTLCoefficients, distant_mosa

__all__ = ["ANGLE_OUTPUTS", "MOSA_NAMES", "angle_map", "link_ttl_asd", "mosa_angles_from_outputs",
           "tm_displacement_asd"]

#: The closed-loop outputs of one spacecraft the MOSA angles are made of (rad).
ANGLE_OUTPUTS = ("sc_attitude_x", "sc_attitude_y", "sc_attitude_z", "mosa_angle_1", "mosa_angle_2")
#: LISA Instrument's MOSA (link) name of MOSA l = 1, 2 of spacecraft i = 1, 2, 3 (row i - 1).
MOSA_NAMES = (("13", "12"), ("21", "23"), ("32", "31"))


def _where(mosa: str) -> tuple[int, int]:
    """(spacecraft index 0..2, MOSA index 0..1) of LISA Instrument's MOSA ``mosa``."""
    for i, row in enumerate(MOSA_NAMES):
        if mosa in row:
            return i, row.index(mosa)
    raise ValueError(unknown("mosa", mosa, MOSAS, problem="is not a MOSA"))


def angle_map(theta: float) -> np.ndarray:
    """(2, 2, 5): row [l, 0] maps the :data:`ANGLE_OUTPUTS` of a spacecraft (rad) to phi of MOSA l + 1, row
    [l, 1] to its eta (rad) (module docstring); ``theta`` the opening angle (rad)."""
    T = oa_rotation(float(theta))                         # (2, 3, 3): rows X_OA_l, Y_OA_l, Z_OA_l in S
    Z = np.array([0.0, 0.0, 1.0])
    out = np.zeros((2, 2, 5))
    for l in range(2):
        x_m, z_m = T[l][0], -Z
        y_m = np.cross(z_m, x_m)
        out[l, 0, :3] = z_m
        out[l, 0, 3 + l] = z_m @ Z                        # dth_l turns the MOSA about +Z_S
        out[l, 1, :3] = y_m
    return out


def mosa_angles_from_outputs(outputs: dict, theta) -> tuple[dict, dict]:
    """phi, eta (rad) of the six MOSAs (dicts keyed by LISA Instrument's MOSA name) from the closed-loop
    angle outputs: ``outputs[name]`` an array (..., 3) over the spacecraft (time first) for each name of
    :data:`ANGLE_OUTPUTS`; ``theta`` the opening angle (rad), a float or one per spacecraft."""
    th = np.broadcast_to(np.asarray(theta, dtype=np.float64), (3,))
    for name in ANGLE_OUTPUTS:
        if name not in outputs:
            raise ValueError(f"outputs: missing {name!r} (needed: {', '.join(ANGLE_OUTPUTS)})")
    phi, eta = {}, {}
    for i in range(3):
        M = angle_map(th[i])
        x = np.stack([np.asarray(outputs[n])[..., i] for n in ANGLE_OUTPUTS], axis=-1)   # (..., 5)
        for l in range(2):
            phi[MOSA_NAMES[i][l]] = x @ M[l, 0]
            eta[MOSA_NAMES[i][l]] = x @ M[l, 1]
    return phi, eta


def _linear_only(coeffs: TTLCoefficients) -> None:
    if not isinstance(coeffs, TTLCoefficients):
        raise ValueError(f"coeffs = {coeffs!r}: expected a TTLCoefficients")
    for kind in ("local", "distant"):
        for q in ("phiphi", "etaeta", "phieta"):
            d = getattr(coeffs, f"{kind}_{q}")
            if any(d.values()):
                raise ValueError(f"ttl.{kind}_{q} = {d!r}: the linear budget needs zero quadratic coefficients")


def _check_loops(loops, thetas) -> tuple:
    if len(loops) != 3 or not all(isinstance(c, ClosedLoop) for c in loops):
        raise ValueError(f"loops: {len(loops)} items; expected the 3 spacecraft's ClosedLoop")
    th = np.broadcast_to(np.asarray(thetas, dtype=np.float64), (3,))
    if not np.all(np.isfinite(th)):
        raise ValueError(f"theta = {thetas!r}: must be finite (rad)")
    return th


def link_ttl_asd(loops, noise: dict, f, coeffs: TTLCoefficients, theta, dt: float | None = None
                 ) -> tuple[np.ndarray, list]:
    """TTL ASD (6, n_source, n_f) [m/Hz^1/2] of the links (:data:`tqdyn.ttl.coupling.MOSAS` order) from each
    noise source (module docstring), and the source names.  ``loops``: the three spacecraft's
    :class:`ClosedLoop` (i = 1, 2, 3); ``noise`` {source: AsdModel}; ``f`` [Hz]; ``theta`` opening angle
    [rad] (float or one per spacecraft); ``dt`` [s]: the zero-order-hold discretised loops (a sampled loop on
    held noise; the time series realise the continuous budget), else continuous."""
    _linear_only(coeffs)
    th = _check_loops(loops, theta)
    f = np.asarray(f, dtype=np.float64)
    sources = [s for s in SOURCES if s in noise]
    inputs = [x for s in sources for x in source_inputs(s)]
    ang = []                                              # per spacecraft (2 MOSAs, 2 angles, n_in, n_f)
    for i in range(3):
        G = closed_loop_response(loops[i], f, list(ANGLE_OUTPUTS), inputs, dt)     # (5, n_in, n_f)
        ang.append(np.einsum("lac,cqf->laqf", angle_map(th[i]), G))

    def H(kind, mosa):
        i, l = _where(mosa)
        return (getattr(coeffs, f"{kind}_phi")[mosa] * ang[i][l, 0]
                + getattr(coeffs, f"{kind}_eta")[mosa] * ang[i][l, 1])            # (n_in, n_f)

    out = np.zeros((6, len(sources), len(f)))
    for n, m in enumerate(MOSAS):
        p = np.abs(H("local", m)) ** 2 + np.abs(H("distant", distant_mosa(m))) ** 2
        k = 0
        for j, s in enumerate(sources):
            c = SOURCES[s][0]
            out[n, j] = np.sqrt(np.sum(p[k:k + c], axis=0)) * noise[s].asd(f)
            k += c
    return out, sources


def tm_displacement_asd(tm_acceleration: np.ndarray, f) -> np.ndarray:
    """TM acceleration noise of the six links as displacement (6, ..., n_f) [m/Hz^1/2]: the residual
    acceleration ASDs of the two TMs of link ij (receiving MOSA ij on spacecraft i, emitting MOSA ji on
    spacecraft j; independent, in quadrature) over (2 pi f)^2.  ``tm_acceleration`` (3, 2, ..., n_f)
    [m/s^2/Hz^1/2]: per spacecraft i and TM l (``tm{l}_acceleration``)."""
    a = np.asarray(tm_acceleration, dtype=np.float64)
    w2 = (2 * math.pi * np.asarray(f, dtype=np.float64)) ** 2
    out = []
    for m in MOSAS:
        (i, l), (j, k) = _where(m), _where(distant_mosa(m))
        out.append(np.sqrt(a[i, l] ** 2 + a[j, k] ** 2) / w2)
    return np.array(out)
