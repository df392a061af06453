"""Layouts of the arrays the compiled right-hand side shares with Python.

* ``cpar`` (:data:`CP_LEN` float64): the constellation parameters of
  :func:`tqdyn.dynamics.rhs.system_rhs` -- mode, pointing law, control
  switch, spacecraft geometry, self-gravity and the jerk model -- packed by
  :func:`make_cpar`.
* ``aux`` (:data:`AUX_LEN` float64): the per-evaluation diagnostics of the
  coupled modes (attitude, control, TM states), read back by
  :func:`aux_views`.
* the state y (n_body, 6[, 2]): rows (x, y, z, vx, vy, vz) [m, m/s] in the
  frame of the force model (:attr:`tqdyn.forces.model.ForceModel.reference`);
  a trailing axis 2 in dd mode (hi, lo).  Bodies 0..n_sat-1 are the
  satellites; in the free-TM mode bodies 3 + 2 i + l are the test masses.
"""

from __future__ import annotations

import numpy as np

from .._choices import unknown

__all__ = ["PRECISIONS", "check_precision", "MODE_POINT_MASS", "MODE_COUPLED", "MODE_FREE_TM", "CP_LEN", "AUX_LEN",
           "SCHEME_CODES", "TM_GRAVITY_CODES", "SYSTEM_TDAT_BODIES", "JERK_BODIES_MAX", "empirical_of", "make_cpar", "workspace",
           "aux_views"]

#: Arithmetic of a propagation: double-double states (trailing axis 2) or plain float64.
PRECISIONS = ("dd", "float64")


def check_precision(precision):
    """ValueError naming ``run.precision`` unless it is one of :data:`PRECISIONS`."""
    if precision not in PRECISIONS:
        raise ValueError(unknown("run.precision", precision, PRECISIONS))


MODE_POINT_MASS = 0
MODE_COUPLED = 1
MODE_FREE_TM = 2

# cpar layout (float64)
CP_MODE, CP_LAW, CP_CONTROL, CP_GM, CP_C, CP_SCHEME, CP_THNOM = 0, 1, 2, 3, 4, 5, 6
CP_R0 = 7          # (2, 3) EH centers at theta_nom, S [m]
CP_SG_OA = 13      # (3, 2, 3) self-gravity, OA_l [m/s^2]
CP_SG_S = 31       # (3, 3) common self-gravity, S [m/s^2]
CP_J2K, CP_TD = 40, 41   # jerk model (see _jerk_perturbation)
CP_SGC = 42        # tdat column of the self-gravity toward the constellation centre [m/s^2], -1 if off
CP_PIV = 43        # (2, 3) MOSA pivots, S [m]
CP_SENS = 49       # (2, 3) sensitive axes, unit vectors in OA_l
CP_NJB = 55        # number of jerk bodies (their states in tdat from CP_TD, 6 values each)
CP_JGM = 56        # (JERK_BODIES_MAX,) their GMs [m^3/s^2]
JERK_BODIES_MAX = 10
CP_GMREL = CP_JGM + JERK_BODIES_MAX   # GM [m^3/s^2] of the central body's Schwarzschild jerk, 0 = off
CP_TMG = CP_GMREL + 1  # TM differential gravity: TMG_DIFFERENTIAL or TMG_DIRECT (:data:`TM_GRAVITY_CODES`)
CP_LEN = CP_TMG + 1
#: cpar[CP_LEN:] (absent when all are zero, so that cpar and its hash stay those of a run without
#: them): the acceleration parameters of point-mass satellites, N_PAR per satellite
#: (:mod:`tqdyn.dynamics.empirical`), satellite by satellite
#: codes of cpar[CP_TMG] (names: ``constellation.tm_gravity``): the test masses'
#: differential gravity from :mod:`tqdyn.forces.differential` or from a second
#: full evaluation of the force model at each EH centre
TMG_DIFFERENTIAL, TMG_DIRECT = 0, 1
TM_GRAVITY_CODES = {"differential": TMG_DIFFERENTIAL, "direct": TMG_DIRECT}
#: drag-free scheme codes of cpar[CP_SCHEME] (names: spacecraft.DRAGFREE_SCHEMES)
SCHEME_CODES = {"tianqin": 0, "lisa": 1}
#: jerk bodies of the geocentric coupled system (time-only inputs appended
#: to the force model's: GCRS position [m] and velocity [m/s] of each)
SYSTEM_TDAT_BODIES = ("moon", "sun")

# aux layout per satellite (float64), AX_SAT values each
AX_T, AX_W, AX_WD, AX_ALPHA, AX_THETA, AX_G, AX_AGRAV = 0, 9, 12, 15, 16, 17, 20
AX_TM = 23         # then per TM l: AX_TM + l * AX_TMLEN
TM_RHI, TM_RLO, TM_VHI, TM_VLO, TM_A, TM_SUSP, TM_ALPHA, TM_OFF = 0, 3, 6, 9, 12, 15, 18, 21
AX_TMLEN = 24
AX_SAT = AX_TM + 2 * AX_TMLEN
AUX_LEN = 3 * AX_SAT

# float64 work: a tuple of small arrays (indexed, never sliced, in the hot path)
_FW_SHAPES = (("r_hi", (3, 3)), ("r_lo", (3, 3)), ("v", (3, 3)), ("a", (3, 3)), ("T", (3, 3, 3)),
              ("om", (3, 3)), ("omd", (3, 3)), ("th", (3, 3)), ("r0", (3, 2, 3)), ("rho", (3, 2, 3)),
              ("vel", (3, 2, 3)), ("dgI", (3, 2, 3)), ("dgS", (3, 2, 3)), ("sgS", (3, 2, 3)), ("g", (3, 2, 3)),
              ("A", (3, 2, 3)), ("GS", (3, 3)), ("alp", (3, 2, 3)), ("GI", (3, 3)), ("jp", (3, 3)),
              ("e_sat", (3, 3)), ("s_sat", (3, 3)))


def make_cpar(mode, law=0, control=False, gm=0.0, c=299792458.0, scheme=0, theta_nom=np.pi / 3,
              r0_nom=None, pivots=None, sensitive_axes=None, sg_oa=None, sg_s=None, jerk_gms=(), j2k=0.0,
              tdat_offset=-1, centre_column=-1, gm_relativity=0.0, tm_gravity="differential",
              empirical=None) -> np.ndarray:
    """Pack the constellation parameters for :func:`system_rhs`.

    mode : MODE_*; law : pointing-law code (``_kinematics_jit.LAW_CODES``);
    control : apply G_i to the orbits; gm : central body's GM [m^3/s^2]
    (jerk/snap of the remote satellite in the local pointing laws); c : m/s;
    scheme : drag-free scheme code (:data:`SCHEME_CODES`); theta_nom :
    nominal MOSA angle [rad]; r0_nom : (2, 3) EH centers at theta_nom in S
    [m]; pivots : (2, 3) MOSA pivots in S [m] (default: r0_nom, no lever
    arm); sensitive_axes : (2, 3) unit vectors in OA_l (default X_OA_l);
    sg_oa : (3, 2, 3) self-gravity in OA_l [m/s^2]; sg_s : (3, 3) common
    self-gravity in S [m/s^2].
    jerk_gms : GMs [m^3/s^2] of the third bodies of the jerk model of the
    local pointing laws (at most :data:`JERK_BODIES_MAX`; their states,
    relative to the central body, are 6 tdat columns each from
    ``tdat_offset``); j2k = 1.5 J2 GM R^2 [m^5/s^2] of the Earth (0 = absent);
    gm_relativity : GM [m^3/s^2] of the central body's Schwarzschild term
    in the jerk model (0 = off; heliocentric runs with relativity, also
    with relativity_model = "eih", whose further terms, <= 1.1e-13 m/s^2,
    have a jerk of ~1e-13 x the orbital rate 2e-7 rad/s ~ 2e-20 m/s^3);
    tdat_offset : column of the system's time-only inputs in tdat, -1 if none;
    centre_column : column in tdat of the magnitude [m/s^2] of the
    self-gravity toward the constellation centre (positive toward it), -1 if off;
    tm_gravity : "differential" | "direct", how the TMs' differential gravity is formed
    (:data:`TM_GRAVITY_CODES`); empirical : (n_sat, N_PAR) acceleration parameters [m/s^2]
    of the point-mass satellites (:mod:`tqdyn.dynamics.empirical`), appended after CP_LEN
    unless None or all zero.
    """
    p = np.zeros(CP_LEN)
    p[CP_MODE], p[CP_LAW], p[CP_CONTROL] = mode, law, 1.0 if control else 0.0
    p[CP_GM], p[CP_C], p[CP_SCHEME], p[CP_THNOM] = gm, c, scheme, theta_nom
    if r0_nom is not None:
        p[CP_R0:CP_R0 + 6] = np.asarray(r0_nom, np.float64).ravel()
    p[CP_PIV:CP_PIV + 6] = p[CP_R0:CP_R0 + 6] if pivots is None else np.asarray(pivots, np.float64).ravel()
    p[CP_SENS:CP_SENS + 6] = ([1.0, 0.0, 0.0] * 2 if sensitive_axes is None
                              else np.asarray(sensitive_axes, np.float64).ravel())
    if sg_oa is not None:
        p[CP_SG_OA:CP_SG_OA + 18] = np.asarray(sg_oa, np.float64).ravel()
    if sg_s is not None:
        p[CP_SG_S:CP_SG_S + 9] = np.asarray(sg_s, np.float64).ravel()
    gms = [float(x) for x in jerk_gms]
    if len(gms) > JERK_BODIES_MAX:
        raise ValueError(f"jerk model: {len(gms)} bodies; allowed: at most {JERK_BODIES_MAX}")
    p[CP_NJB] = len(gms)
    p[CP_JGM:CP_JGM + len(gms)] = gms
    p[CP_J2K], p[CP_TD], p[CP_GMREL] = j2k, tdat_offset, gm_relativity
    p[CP_SGC] = centre_column
    p[CP_TMG] = TM_GRAVITY_CODES[tm_gravity]
    if empirical is not None and np.any(np.asarray(empirical, np.float64) != 0.0):
        if mode != MODE_POINT_MASS:
            raise ValueError("accelerations: the acceleration parameters need point-mass satellites; "
                             "allowed: constellation.pointing = \"none\"")
        p = np.concatenate([p, np.asarray(empirical, np.float64).ravel()])
    return p


def empirical_of(cpar: np.ndarray, n_par: int) -> np.ndarray:
    """The (n_sat, n_par) acceleration parameters carried by cpar ((0, n_par) if none)."""
    return np.ascontiguousarray(cpar[CP_LEN:]).reshape(-1, n_par)


def workspace(y: np.ndarray, cpar: np.ndarray | None = None):
    """(gw, fw, aux) scratch for :func:`system_rhs` with state ``y``: gw
    (15, 3[, 2]) accelerations in the working precision, fw a tuple of
    float64 arrays, aux (AUX_LEN,).  Their types tell the compiled code
    which system runs, so that a run compiles its own only: for the
    point-mass system (``cpar`` of MODE_POINT_MASS) fw is None; for the
    coupled one with the global pointing law (cpar[CP_LAW] = 0, the
    default without cpar) its jerk array fw[19] is None (the local laws'
    jerk model is left out)."""
    if cpar is not None and cpar[CP_MODE] == MODE_POINT_MASS:
        fw = None
    else:
        local = cpar is not None and cpar[CP_LAW] != 0
        fw = tuple(None if name == "jp" and not local else np.zeros(shape) for name, shape in _FW_SHAPES)
    return np.zeros((15, 3) + y.shape[2:]), fw, np.zeros(AUX_LEN)


def aux_views(aux: np.ndarray) -> dict:
    """Named views of aux rows (..., AUX_LEN) -> arrays with (..., 3[, 2], k) shapes (float64).

    Keys: T_S_I (..., 3, 3, 3); omega, omega_dot (..., 3, 3) [S];
    breathing_angle, theta (..., 3); a_dragfree, a_gravity (..., 3, 3) [GCRS];
    tm_r_hi, tm_r_lo, tm_v_hi, tm_v_lo, tm_a (..., 3, 2, 3) [GCRS];
    tm_a_suspension, tm_alpha_suspension (..., 3, 2, 3) [OA_l];
    tm_housing_offset (..., 3, 2, 3) [GCRS, m].
    """
    a = np.asarray(aux)
    s = a.reshape(a.shape[:-1] + (3, AX_SAT))
    tm = s[..., AX_TM:].reshape(a.shape[:-1] + (3, 2, AX_TMLEN))

    def v(x, lo, n):
        return x[..., lo:lo + n]

    return {
        "T_S_I": v(s, AX_T, 9).reshape(a.shape[:-1] + (3, 3, 3)),
        "omega": v(s, AX_W, 3), "omega_dot": v(s, AX_WD, 3),
        "breathing_angle": s[..., AX_ALPHA], "theta": s[..., AX_THETA],
        "a_dragfree": v(s, AX_G, 3), "a_gravity": v(s, AX_AGRAV, 3),
        "tm_r_hi": v(tm, TM_RHI, 3), "tm_r_lo": v(tm, TM_RLO, 3),
        "tm_v_hi": v(tm, TM_VHI, 3), "tm_v_lo": v(tm, TM_VLO, 3), "tm_a": v(tm, TM_A, 3),
        "tm_a_suspension": v(tm, TM_SUSP, 3), "tm_alpha_suspension": v(tm, TM_ALPHA, 3),
        "tm_housing_offset": v(tm, TM_OFF, 3),
    }
