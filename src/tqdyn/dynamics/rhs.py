"""The right-hand side of the propagated system.

State layout: y (n_body, 6[, 2]) with rows (x, y, z, vx, vy, vz) [m, m/s],
GCRS, geocentric, t in TT; trailing axis 2 in dd mode (see :mod:`tqdyn.numerics.dd`).

Two systems share one entry point, :func:`system_rhs`, selected by
``cpar[CP_MODE]`` (the point-mass system runs without the coupled work
arrays, ``fw`` None; the compiled loops have one kernel per system):

* ``MODE_POINT_MASS`` -- every body moves under the force model of
  :mod:`tqdyn.forces.model` (independent satellites).
* ``MODE_COUPLED`` / ``MODE_FREE_TM`` -- the drag-free constellation
  (paper eq. coreEquation): bodies 0..2 are the satellites,

      r_i'' = a(r_i) + G_i,

  with G_i the drag-free acceleration that keeps the satellite centred on its
  two TMs (nominal control, :mod:`tqdyn.constellation.control` for the
  derivation).  Per evaluation:

  1. gravity at the three satellites (dd);
  2. nominal attitude of the pointing law (:mod:`._kinematics_jit`): T_S_I,
     omega, omega_dot, MOSA angle theta and its rates, from the satellites'
     positions, velocities and accelerations (and, for the local laws, their
     jerks: monopole + Moon and Sun tidal terms + J2, :func:`_jerk_perturbation`,
     so that omega_dot is the derivative of omega to ~1e-22 rad/s^2);
  3. the EH centers r_i + T_I_S r_0,l (dd) and the differential gravity
     a(EH) - a(sat) there (float64), by ``constellation.tm_gravity``:
     "differential" (default) forms it term by term without cancellation
     (:mod:`tqdyn.forces.differential`: exact point-mass differences, the
     midpoint Jacobian of the Earth's degree 2, float64 differences of the
     small terms; error ~4e-25 m/s^2, the float64 round-off of the Earth's
     degrees >= 3 and the planets); "direct" evaluates the whole model again
     at each EH centre (dd) and subtracts, which costs six more full
     evaluations and has the same error geocentric (its float64 terms at a
     float64-rounded position) but ~1e-22 m/s^2 heliocentric, where the
     planets are float64 and a position rounds to 3e-5 m;
  4. g_l, A_c,l and G_i (:mod:`._control_jit`);
  5. G feedback: omega_dot and theta_ddot depend on the satellites'
     accelerations, which contain G.  Steps 2 and 4 are repeated once with
     a(r_i) + G_i.  The remaining inconsistency is the change of G in that
     second pass times d_TM / L ~ 1e-9, i.e. < 1e-30 m/s^2.  Without the
     second pass omega_dot would miss ~|G| / L ~ 6e-22 rad/s^2, which moves
     a TM 0.2 m from the CoM by ~1e-22 m/s^2 -- visible (~1e-11 m) in the
     10-day free-TM check, hence included.

  ``control = "off"`` skips adding G_i to the orbit (pure-gravity
  constellation); attitude and the control that would be needed are still
  evaluated (with accelerations a(r_i)).  In ``MODE_FREE_TM`` bodies 3..8
  are the six TMs (body 3 + 2 i + l), propagated as free bodies under
  gravity + self-gravity + the suspension acceleration A_c,l computed for
  the nominal TM positions (the EH centers); how far they drift from the EH
  centers verifies the control derivation and the integration.  Their
  gravity is formed like the EH centres': the satellite's plus the
  differential gravity at the TM's offset ("differential"; the method
  itself is checked against mpmath in tests/test_differential_gravity.py),
  or the full model at the TM ("direct").

Per-evaluation diagnostics (attitude, control, TM states) are written into
``aux`` (float64, layout constants ``AX_*`` below) -- the driver keeps the
ones of the first stage of each step as the output row.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..constellation._control_jit import housing_geometry, satellite_control
from ..constellation._kinematics_jit import nominal_kinematics
from ..constellation.indices import MOSA_SIGN
from ..forces.earth import j2_jerk_gcrs_z
from ..forces.differential import differential_gravity, direct_terms
from ..forces.model import ForceModel, gravity, gravity_split
from ..forces.relativity import schwarzschild_jerk
from ..forces.third_body import third_body_jerk
from ..numerics.dd import add, ld, lo_part, st, sub, to_f64
from .empirical import N_PAR, add_empirical
from .layout import (AX_AGRAV, AX_ALPHA, AX_G, AX_SAT, AX_T, AX_THETA, AX_TM, AX_TMLEN, AX_W, AX_WD, CP_CONTROL,
                     CP_C, CP_GM, CP_GMREL, CP_J2K, CP_JGM, CP_LAW, CP_MODE, CP_NJB, CP_PIV, CP_R0, CP_SCHEME, CP_SENS,
                     CP_SG_OA, CP_SG_S, CP_SGC, CP_LEN, CP_TD, CP_THNOM, CP_TMG, MODE_FREE_TM, MODE_POINT_MASS, TM_A, TM_ALPHA, TM_OFF, TM_RHI, TM_RLO,
                     TM_SUSP, TM_VHI, TM_VLO, TMG_DIRECT, make_cpar, workspace)
from ..numerics.jit import inner_kernel, kernel

__all__ = ["system_rhs", "coupled_rhs", "point_mass_rhs", "point_masses", "point_mass_system", "evaluate_rhs",
           "toward_centre"]


@njit(cache=True)
def point_masses(y, tdat, params, layout, k):
    """dy/dt of independent bodies under the force model (MODE_POINT_MASS);
    arguments as :func:`system_rhs`."""
    for b in range(y.shape[0]):
        ax, ay, az = gravity(ld(y, b, 0), ld(y, b, 1), ld(y, b, 2), ld(y, b, 3), ld(y, b, 4), ld(y, b, 5),
                             tdat, params, layout)
        for q in range(3):
            st(k, ld(y, b, q + 3), b, q)
        st(k, ax, b, 3)
        st(k, ay, b, 4)
        st(k, az, b, 5)


@kernel
def point_mass_system(y, tdat, params, layout, cpar, k):
    """dy/dt of the point-mass system (MODE_POINT_MASS): :func:`point_masses`, then, when
    cpar says so, the self-gravity toward the constellation centre (:func:`toward_centre`)
    and the satellites' acceleration parameters (:func:`tqdyn.dynamics.empirical.add_empirical`,
    from cpar[CP_LEN:]); arguments as :func:`system_rhs`."""
    point_masses(y, tdat, params, layout, k)
    if cpar[CP_SGC] >= 0.0:
        toward_centre(y, tdat[int(cpar[CP_SGC])], k)
    if cpar.shape[0] > CP_LEN:
        n = (cpar.shape[0] - CP_LEN) // N_PAR
        add_empirical(y, cpar[CP_LEN:].reshape((n, N_PAR)), k)


@njit(cache=True, inline="always")
def _gravity_into(gw, row, x, y, z, vx, vy, vz, tdat, params, layout):
    ax, ay, az = gravity(x, y, z, vx, vy, vz, tdat, params, layout)
    st(gw, ax, row, 0)
    st(gw, ay, row, 1)
    st(gw, az, row, 2)


@inner_kernel
def _breathing_angle(r_hi, r_lo, i):
    """Angle at satellite i between its two arms (instantaneous positions) [rad]."""
    j, kk = (i + 1) % 3, (i + 2) % 3
    a0 = (r_hi[j, 0] - r_hi[i, 0]) + (r_lo[j, 0] - r_lo[i, 0])
    a1 = (r_hi[j, 1] - r_hi[i, 1]) + (r_lo[j, 1] - r_lo[i, 1])
    a2 = (r_hi[j, 2] - r_hi[i, 2]) + (r_lo[j, 2] - r_lo[i, 2])
    b0 = (r_hi[kk, 0] - r_hi[i, 0]) + (r_lo[kk, 0] - r_lo[i, 0])
    b1 = (r_hi[kk, 1] - r_hi[i, 1]) + (r_lo[kk, 1] - r_lo[i, 1])
    b2 = (r_hi[kk, 2] - r_hi[i, 2]) + (r_lo[kk, 2] - r_lo[i, 2])
    cx, cy, cz = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    return np.arctan2(np.sqrt(cx * cx + cy * cy + cz * cz), a0 * b0 + a1 * b1 + a2 * b2)


@inner_kernel
def _jerk_perturbation(cpar, tdat, fw, jp):
    """Jerk of each satellite beyond the central monopole [m/s^3] into jp
    (fw[19]; None for the global law, which needs none: then nothing is
    computed, nor compiled).

    The local pointing laws need the remote satellites' jerk for omega_dot
    (it enters as jerk / c).  Modelled: the tidal terms of the jerk bodies
    (cpar[CP_NJB] bodies, states relative to the central body from tdat,
    with the bodies' ephemeris velocities) and the Earth's J2 about the GCRS
    z axis.  Geocentric: the Moon and the Sun.  Heliocentric: every third
    body of the force model (the Earth's tidal jerk on LISA is ~3e-14 m/s^3,
    1e-22 rad/s^2 of omega_dot, Venus' and Jupiter's are of that order too)
    and, heliocentric with relativity, the Sun's Schwarzschild jerk (~3e-17
    m/s^3: without it free TMs drift 3e-11 m in a year, with it 4e-14 m;
    the geocentric one, ~1e-17 m/s^3, is left out).
    The geocentric budget:  Left out, with their jerk: the Earth rotation of the sectorial
    degree-2 terms (~1e-13 m/s^3), the CIP tilt from GCRS z in J2 (~2e-14),
    degree >= 3 (~2e-14), planets, tides, relativity (< 1e-15), G (~1e-17):
    omega_dot is the derivative of omega to ~4e-22 rad/s^2 (tests/test_coupled.py
    compares it with 5-point differences; the Moon's tidal jerk alone is
    ~5e-10 m/s^3, ~2e-18 rad/s^2).  Free TMs under a local law stay within
    1e-12 m of their EH centers over 10 days (tests/test_coupled.py; with the
    monopole jerk alone they do not).
    """
    if jp is None:
        return
    v, r_hi, r_lo = fw[2], fw[0], fw[1]
    o = int(cpar[CP_TD])
    k = cpar[CP_J2K]
    nb = int(cpar[CP_NJB])
    for i in range(3):
        rx, ry, rz = r_hi[i, 0] + r_lo[i, 0], r_hi[i, 1] + r_lo[i, 1], r_hi[i, 2] + r_lo[i, 2]
        vx, vy, vz = v[i, 0], v[i, 1], v[i, 2]
        jx = jy = jz = 0.0
        if o >= 0:
            for b in range(nb):
                gm = cpar[CP_JGM + b]
                if gm != 0.0:
                    c = o + 6 * b
                    tx, ty, tz = third_body_jerk(gm, rx, ry, rz, vx, vy, vz, tdat[c], tdat[c + 1], tdat[c + 2],
                                                 tdat[c + 3], tdat[c + 4], tdat[c + 5])
                    jx, jy, jz = jx + tx, jy + ty, jz + tz
        if cpar[CP_GMREL] != 0.0:
            tx, ty, tz = schwarzschild_jerk(rx, ry, rz, vx, vy, vz, cpar[CP_GMREL], cpar[CP_C], 1.0, 1.0)
            jx += tx
            jy += ty
            jz += tz
        if k != 0.0:
            tx, ty, tz = j2_jerk_gcrs_z(k, rx, ry, rz, vx, vy, vz)
            jx += tx
            jy += ty
            jz += tz
        jp[i, 0], jp[i, 1], jp[i, 2] = jx, jy, jz


@inner_kernel
def _control_pass(cpar, fw):
    """Kinematics and EH geometry of the three satellites from the work
    arrays (positions, velocities, accelerations)."""
    r_hi, r_lo, v, a, T, om, omd, th, r0, rho, vel = fw[0], fw[1], fw[2], fw[3], fw[4], fw[5], fw[6], fw[7], \
        fw[8], fw[9], fw[10]
    nominal_kinematics(int(cpar[CP_LAW]), r_hi, r_lo, v, a, fw[19], cpar[CP_GM], cpar[CP_C], T, om, omd, th)
    r0_nom = cpar[CP_R0:CP_R0 + 6].reshape((2, 3))
    piv = cpar[CP_PIV:CP_PIV + 6].reshape((2, 3))
    for i in range(3):
        housing_geometry(i, th[i, 0], th[i, 1], r0_nom, piv, cpar[CP_THNOM], om, r0, rho, vel)


@inner_kernel
def _control_laws(cpar, tdat, fw):
    """g, A, G (S and GCRS), alpha of the three satellites from the work arrays
    (and, when cpar[CP_SGC] >= 0, the self-gravity ramp from tdat: a common
    self-gravity of both TMs along +X_S, toward the constellation's incentre)."""
    T, om, omd, th, r0, rho = fw[4], fw[5], fw[6], fw[7], fw[8], fw[9]
    dgI, dgS, sgS, g, A, GS, alp, GI = fw[11], fw[12], fw[13], fw[14], fw[15], fw[16], fw[17], fw[18]
    for i in range(3):
        h = 0.5 * th[i, 0]
        for l in range(2):
            s = MOSA_SIGN[l]
            c, sp = np.cos(s * h), np.sin(s * h)
            o = CP_SG_OA + 6 * i + 3 * l
            sx, sy, sz = cpar[o], cpar[o + 1], cpar[o + 2]
            # T_S_OA sg (columns of T_OA_S) + the common part fixed in S
            sgS[i, l, 0] = c * sx - sp * sy + cpar[CP_SG_S + 3 * i]
            if cpar[CP_SGC] >= 0.0:
                sgS[i, l, 0] += tdat[int(cpar[CP_SGC])]
            sgS[i, l, 1] = sp * sx + c * sy + cpar[CP_SG_S + 3 * i + 1]
            sgS[i, l, 2] = sz + cpar[CP_SG_S + 3 * i + 2]
            for q in range(3):
                dgS[i, l, q] = T[i, q, 0] * dgI[i, l, 0] + T[i, q, 1] * dgI[i, l, 1] + T[i, q, 2] * dgI[i, l, 2]
        satellite_control(i, int(cpar[CP_SCHEME]), cpar[CP_SENS:CP_SENS + 6].reshape((2, 3)), dgS, sgS, om, omd,
                          th[i, 0], th[i, 1], th[i, 2], r0, rho, g, A, GS, alp)
        for q in range(3):
            GI[i, q] = T[i, 0, q] * GS[i, 0] + T[i, 1, q] * GS[i, 1] + T[i, 2, q] * GS[i, 2]


@inner_kernel
def _oa_to_inertial(T, i, theta, l, x, y, z):
    """OA_l vector of satellite i -> GCRS (T_I_S T_S_OA); T: (3, 3, 3)."""
    s = MOSA_SIGN[l]
    c, sp = np.cos(s * 0.5 * theta), np.sin(s * 0.5 * theta)
    ux, uy, uz = c * x - sp * y, sp * x + c * y, z
    return (T[i, 0, 0] * ux + T[i, 1, 0] * uy + T[i, 2, 0] * uz,
            T[i, 0, 1] * ux + T[i, 1, 1] * uy + T[i, 2, 1] * uz,
            T[i, 0, 2] * ux + T[i, 1, 2] * uy + T[i, 2, 2] * uz)


@kernel
def coupled_rhs(y, tdat, params, layout, cpar, k, aux, gw, fw):
    """dy/dt of the coupled constellation (MODE_COUPLED, MODE_FREE_TM); arguments as
    :func:`system_rhs`."""
    free = cpar[CP_MODE] == MODE_FREE_TM
    control_on = cpar[CP_CONTROL] != 0.0
    r_hi, r_lo, v, a, T, om, omd, th, r0, vel = fw[0], fw[1], fw[2], fw[3], fw[4], fw[5], fw[6], fw[7], fw[8], fw[10]
    dgI, sgS, A, alp, GI, e_sat, s_sat = fw[11], fw[13], fw[15], fw[17], fw[18], fw[20], fw[21]
    direct = cpar[CP_TMG] == TMG_DIRECT
    # 1. gravity at the satellites (and, for the differential gravity, the
    # float64 parts it shares with the EH centres)
    for i in range(3):
        gx, gy, gz, e_sat[i, 0], e_sat[i, 1], e_sat[i, 2] = gravity_split(
            ld(y, i, 0), ld(y, i, 1), ld(y, i, 2), ld(y, i, 3), ld(y, i, 4), ld(y, i, 5), tdat, params, layout)
        st(gw, gx, i, 0)
        st(gw, gy, i, 1)
        st(gw, gz, i, 2)
        for q in range(3):
            x = ld(y, i, q)
            r_hi[i, q] = to_f64(x)
            r_lo[i, q] = lo_part(x)
            v[i, q] = to_f64(ld(y, i, q + 3))
            a[i, q] = to_f64(ld(gw, i, q))
        if not direct:
            s_sat[i, 0], s_sat[i, 1], s_sat[i, 2] = direct_terms(r_hi[i, 0], r_hi[i, 1], r_hi[i, 2], v[i, 0],
                                                                 v[i, 1], v[i, 2], tdat, params, layout)
    # 2. attitude and EH geometry
    if cpar[CP_LAW] != 0:
        _jerk_perturbation(cpar, tdat, fw, fw[19])
    _control_pass(cpar, fw)
    # 3. differential gravity at the EH centers: term by term
    # (:mod:`tqdyn.forces.differential`) or, "direct", the full model there (dd)
    for i in range(3):
        for l in range(2):
            ox = T[i, 0, 0] * r0[i, l, 0] + T[i, 1, 0] * r0[i, l, 1] + T[i, 2, 0] * r0[i, l, 2]
            oy = T[i, 0, 1] * r0[i, l, 0] + T[i, 1, 1] * r0[i, l, 1] + T[i, 2, 1] * r0[i, l, 2]
            oz = T[i, 0, 2] * r0[i, l, 0] + T[i, 1, 2] * r0[i, l, 1] + T[i, 2, 2] * r0[i, l, 2]
            ux = T[i, 0, 0] * vel[i, l, 0] + T[i, 1, 0] * vel[i, l, 1] + T[i, 2, 0] * vel[i, l, 2]
            uy = T[i, 0, 1] * vel[i, l, 0] + T[i, 1, 1] * vel[i, l, 1] + T[i, 2, 1] * vel[i, l, 2]
            uz = T[i, 0, 2] * vel[i, l, 0] + T[i, 1, 2] * vel[i, l, 1] + T[i, 2, 2] * vel[i, l, 2]
            hx, hy, hz = add(ld(y, i, 0), ox), add(ld(y, i, 1), oy), add(ld(y, i, 2), oz)
            hvx, hvy, hvz = add(ld(y, i, 3), ux), add(ld(y, i, 4), uy), add(ld(y, i, 5), uz)
            if direct:
                row = 3 + 2 * i + l
                _gravity_into(gw, row, hx, hy, hz, hvx, hvy, hvz, tdat, params, layout)
                for q in range(3):
                    dgI[i, l, q] = to_f64(sub(ld(gw, row, q), ld(gw, i, q)))
            else:
                dgI[i, l, 0], dgI[i, l, 1], dgI[i, l, 2] = differential_gravity(
                    r_hi[i, 0], r_hi[i, 1], r_hi[i, 2], v[i, 0], v[i, 1], v[i, 2], ox, oy, oz, ux, uy, uz,
                    e_sat[i, 0], e_sat[i, 1], e_sat[i, 2], s_sat[i, 0], s_sat[i, 1], s_sat[i, 2],
                    tdat, params, layout)
            b = AX_SAT * i + AX_TM + AX_TMLEN * l
            aux[b + TM_RHI], aux[b + TM_RHI + 1], aux[b + TM_RHI + 2] = to_f64(hx), to_f64(hy), to_f64(hz)
            aux[b + TM_RLO], aux[b + TM_RLO + 1], aux[b + TM_RLO + 2] = lo_part(hx), lo_part(hy), lo_part(hz)
            aux[b + TM_VHI], aux[b + TM_VHI + 1], aux[b + TM_VHI + 2] = to_f64(hvx), to_f64(hvy), to_f64(hvz)
            aux[b + TM_VLO], aux[b + TM_VLO + 1], aux[b + TM_VLO + 2] = lo_part(hvx), lo_part(hvy), lo_part(hvz)
            if free:
                tb = 3 + 2 * i + l
                aux[b + TM_OFF] = to_f64(sub(ld(y, tb, 0), hx))
                aux[b + TM_OFF + 1] = to_f64(sub(ld(y, tb, 1), hy))
                aux[b + TM_OFF + 2] = to_f64(sub(ld(y, tb, 2), hz))
    # 4. control
    _control_laws(cpar, tdat, fw)
    # 5. G feedback into omega_dot / theta_ddot (the orbit's accelerations contain G)
    if control_on:
        for i in range(3):
            for q in range(3):
                a[i, q] = to_f64(add(ld(gw, i, q), GI[i, q]))
        _control_pass(cpar, fw)
        _control_laws(cpar, tdat, fw)
    # derivatives of the satellites
    for i in range(3):
        for q in range(3):
            st(k, ld(y, i, q + 3), i, q)
            if control_on:
                st(k, add(ld(gw, i, q), GI[i, q]), i, q + 3)
            else:
                st(k, ld(gw, i, q), i, q + 3)
    # aux: attitude, control, TM accelerations (and the free TMs' derivatives)
    for i in range(3):
        s0 = AX_SAT * i
        for p in range(3):
            for q in range(3):
                aux[s0 + AX_T + 3 * p + q] = T[i, p, q]
        for q in range(3):
            aux[s0 + AX_W + q] = om[i, q]
            aux[s0 + AX_WD + q] = omd[i, q]
            aux[s0 + AX_G + q] = GI[i, q]
            aux[s0 + AX_AGRAV + q] = to_f64(ld(gw, i, q))
        theta = th[i, 0]
        aux[s0 + AX_THETA] = theta
        aux[s0 + AX_ALPHA] = _breathing_angle(r_hi, r_lo, i)
        for l in range(2):
            b = s0 + AX_TM + AX_TMLEN * l
            for q in range(3):
                aux[b + TM_SUSP + q] = A[i, l, q]
                aux[b + TM_ALPHA + q] = alp[i, l, q]
            # suspension (OA_l) and self-gravity (S) in GCRS
            ax_, ay_, az_ = _oa_to_inertial(T, i, theta, l, A[i, l, 0], A[i, l, 1], A[i, l, 2])
            sx, sy, sz = sgS[i, l, 0], sgS[i, l, 1], sgS[i, l, 2]
            gx = T[i, 0, 0] * sx + T[i, 1, 0] * sy + T[i, 2, 0] * sz + ax_
            gy = T[i, 0, 1] * sx + T[i, 1, 1] * sy + T[i, 2, 1] * sz + ay_
            gz = T[i, 0, 2] * sx + T[i, 1, 2] * sy + T[i, 2, 2] * sz + az_
            hrow = 3 + 2 * i + l
            if free:
                tb = 3 + 2 * i + l
                trow = 9 + 2 * i + l
                if direct:  # the full model at the TM
                    _gravity_into(gw, trow, ld(y, tb, 0), ld(y, tb, 1), ld(y, tb, 2), ld(y, tb, 3), ld(y, tb, 4),
                                  ld(y, tb, 5), tdat, params, layout)
                    tx, ty, tz = add(ld(gw, trow, 0), gx), add(ld(gw, trow, 1), gy), add(ld(gw, trow, 2), gz)
                else:  # the satellite's gravity plus the differential gravity at the TM's offset
                    fx, fy, fz = differential_gravity(
                        r_hi[i, 0], r_hi[i, 1], r_hi[i, 2], v[i, 0], v[i, 1], v[i, 2],
                        to_f64(sub(ld(y, tb, 0), ld(y, i, 0))), to_f64(sub(ld(y, tb, 1), ld(y, i, 1))),
                        to_f64(sub(ld(y, tb, 2), ld(y, i, 2))), to_f64(sub(ld(y, tb, 3), ld(y, i, 3))),
                        to_f64(sub(ld(y, tb, 4), ld(y, i, 4))), to_f64(sub(ld(y, tb, 5), ld(y, i, 5))),
                        e_sat[i, 0], e_sat[i, 1], e_sat[i, 2], s_sat[i, 0], s_sat[i, 1], s_sat[i, 2],
                        tdat, params, layout)
                    tx = add(ld(gw, i, 0), gx + fx)
                    ty = add(ld(gw, i, 1), gy + fy)
                    tz = add(ld(gw, i, 2), gz + fz)
                for q in range(3):
                    st(k, ld(y, tb, q + 3), tb, q)
                st(k, tx, tb, 3)
                st(k, ty, tb, 4)
                st(k, tz, tb, 5)
            elif direct:
                tx, ty, tz = add(ld(gw, hrow, 0), gx), add(ld(gw, hrow, 1), gy), add(ld(gw, hrow, 2), gz)
            else:  # the EH centre's gravity as the satellite's plus the differential gravity
                tx = add(ld(gw, i, 0), gx + dgI[i, l, 0])
                ty = add(ld(gw, i, 1), gy + dgI[i, l, 1])
                tz = add(ld(gw, i, 2), gz + dgI[i, l, 2])
            aux[b + TM_A], aux[b + TM_A + 1], aux[b + TM_A + 2] = to_f64(tx), to_f64(ty), to_f64(tz)


@njit(cache=True, inline="always")
def point_mass_rhs(y, tdat, params, layout, cpar, k, aux, gw, fw):
    """:func:`point_mass_system` with the arguments of :func:`system_rhs`
    (the work arrays are not used, nor passed on: their reference counts
    cost time)."""
    point_mass_system(y, tdat, params, layout, cpar, k)


def system_rhs(y, tdat, params, layout, cpar, k, aux, gw, fw):
    """dy/dt of the whole system at one instant.

    y, k: (n_body, 6[, 2]) state and derivative (m, m/s; m/s, m/s^2; GCRS);
    tdat: (n_tdat,) float64 time-only inputs of the force model at the
    instant of y (TT since the epoch); params, layout: the force model's; cpar: (CP_LEN,)
    constellation parameters (:func:`make_cpar`); aux: (AUX_LEN,) float64
    diagnostics written by the coupled modes; gw, fw: scratch
    (:func:`workspace`), fw None for the point-mass system (MODE_POINT_MASS).

    The compiled loops (:mod:`.fixed`, :mod:`.multistep`) do not branch on
    the system: each has one kernel per system, compiled with the
    right-hand side of that system (:func:`coupled_rhs` or
    :func:`point_mass_rhs`), so a run compiles only the system it runs.
    """
    if fw is None:
        point_mass_system(y, tdat, params, layout, cpar, k)
    else:
        coupled_rhs(y, tdat, params, layout, cpar, k, aux, gw, fw)


@njit(cache=True)
def toward_centre(y, g, k):
    """Add g [m/s^2] along the unit vector from each of bodies 0..2 to their
    centroid (the self-gravity toward the constellation centre of ESA's
    LISA orbits) to the accelerations in k.  The direction is formed in
    float64 from the dd positions' differences (relative error ~1e-16 of
    ~2e-9 m/s^2)."""
    cx, cy, cz = 0.0, 0.0, 0.0
    for b in range(3):
        cx += to_f64(sub(ld(y, b, 0), ld(y, 0, 0)))
        cy += to_f64(sub(ld(y, b, 1), ld(y, 0, 1)))
        cz += to_f64(sub(ld(y, b, 2), ld(y, 0, 2)))
    cx, cy, cz = cx / 3.0, cy / 3.0, cz / 3.0  # centroid relative to body 0
    for b in range(3):
        dx = cx - to_f64(sub(ld(y, b, 0), ld(y, 0, 0)))
        dy = cy - to_f64(sub(ld(y, b, 1), ld(y, 0, 1)))
        dz = cz - to_f64(sub(ld(y, b, 2), ld(y, 0, 2)))
        f = g / np.sqrt(dx * dx + dy * dy + dz * dz)
        st(k, add(ld(k, b, 3), f * dx), b, 3)
        st(k, add(ld(k, b, 4), f * dy), b, 4)
        st(k, add(ld(k, b, 5), f * dz), b, 5)


def evaluate_rhs(y: np.ndarray, tdat_row: np.ndarray, model: ForceModel, cpar: np.ndarray | None = None,
                 with_aux: bool = False):
    """dy/dt at one instant, same layout and precision as ``y``.

    cpar: the system's parameters (:attr:`System.cpar`; default: point
    masses).  With ``with_aux`` returns (k, aux), aux the (AUX_LEN,)
    diagnostics of the coupled modes (see :func:`tqdyn.dynamics.layout.aux_views`).
    The kernels called are those the propagation kernels call (compiled with them).
    """
    k = np.zeros_like(y)
    cpar = make_cpar(MODE_POINT_MASS) if cpar is None else cpar
    gw, fw, aux = workspace(y, cpar)
    system_rhs(y, tdat_row, model.params, model.kernel_layout, cpar, k, aux, gw, fw)
    return (k, aux) if with_aux else k
