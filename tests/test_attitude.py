"""Tests for tqdyn.constellation.attitude (S / OA frames, omega, omega_dot).

Independent references (each test says which one it uses):
* definitions written out in the test: n_ij from positions, the incenter by
  the paper's formula r_inc = (r23 R1 + r31 R2 + r12 R3)/P, the rotation sense
  of OA_l checked against the beam directions themselves;
* the rigid equilateral constellation on one circular orbit (exact analytic
  case: omega_S = (0, 0, n) with n the orbital rate, omega_dot = 0,
  alpha = 60 deg, X_S = -r_hat, Z_S = orbit normal);
* finite differences of T_S_I along a real 1-day TianQin trajectory (full force
  model, tqdyn propagator, 50 s output): 5-point stencils; tolerance derived
  below from the step and the frame's higher derivatives;
* mpmath: the frames evaluated at 40 digits on the analytic Kepler states
  (tqdyn.elements.kepler_state_at), differentiated by a 5-point stencil with
  h = 1 s (truncation h^4 n^5 / 30 ~ 1e-25 rad/s, rounding ~1e-38).
Tolerances in rad, rad/s, rad/s^2.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpmath import mp, mpf

from tqdyn.constellation.attitude import attitude, beam_vectors
from tqdyn.forces.central import central_jerk_snap
from tqdyn.constellation.indices import Mosa, Sat
from tqdyn.astro.elements import deg, kepler_state_at

GM = 3.986004415e14
C = 299792458.0
# Table I of the paper: a [m], nu0 [deg]; e = 0, i = 74.5 deg, raan = 211.6 deg, argp = 0.
TABLE_I = ((100000.0e3, 30.0), (100009.5e3, 150.0), (99995.0e3, 270.0))
INC, RAAN = np.radians(74.5), np.radians(211.6)


def _circular_jets(t, sats=TABLE_I, gm=GM, orders=5):
    """Exact circular-orbit states r^(m)(t), m = 0..orders-1, (N, 3, 3) each, GCRS.

    r = a (cos u P + sin u Q), u = nu0 + n t; d^m/dt^m shifts u by m pi/2 and
    multiplies by n^m.  P = node direction, Q = W x P (argp = 0).
    """
    P = np.array([np.cos(RAAN), np.sin(RAAN), 0.0])
    W = np.array([np.sin(INC) * np.sin(RAAN), -np.sin(INC) * np.cos(RAAN), np.cos(INC)])
    Q = np.cross(W, P)
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((orders, t.size, 3, 3))
    for s, (a, nu0) in enumerate(sats):
        n = np.sqrt(gm / a**3)
        u = np.radians(nu0) + n * t
        for m in range(orders):
            um = u + m * np.pi / 2
            out[m, :, s] = a * n**m * (np.cos(um)[:, None] * P + np.sin(um)[:, None] * Q)
    return out, W


def _n(r, i, j):
    d = r[..., j, :] - r[..., i, :]
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


# ---------------------------------------------------------------- frames


def test_frames_orthonormal_bisector_normal_incenter():
    """Definitions written out here: orthonormality, det = +1, X_S bisects n_ij/n_ik and
    points at the incenter (paper's formula), Z_S normal to the plane, theta = arccos(n_ij.n_ik)."""
    t = np.linspace(0.0, 4 * 86400.0, 97)
    (r, v, a, *_), _ = _circular_jets(t)
    att = attitude(r, v, a)
    T = att.T_S_I
    eye = np.einsum("...ab,...cb->...ac", T, T)
    assert np.abs(eye - np.eye(3)).max() < 1e-15
    assert np.abs(np.linalg.det(T) - 1.0).max() < 1e-15
    L12 = np.linalg.norm(r[:, 1] - r[:, 0], axis=-1)
    L23 = np.linalg.norm(r[:, 2] - r[:, 1], axis=-1)
    L31 = np.linalg.norm(r[:, 0] - r[:, 2], axis=-1)
    inc = (L23[:, None] * r[:, 0] + L31[:, None] * r[:, 1] + L12[:, None] * r[:, 2]) / (L12 + L23 + L31)[:, None]
    for s in Sat:
        i, j, k = s.index, s.j.index, s.k.index
        X, Y, Z = T[:, i, 0], T[:, i, 1], T[:, i, 2]
        nij, nik = _n(r, i, j), _n(r, i, k)
        alpha = np.arccos(np.sum(nij * nik, axis=-1))
        assert np.abs(att.theta[:, i] - alpha).max() < 2e-15
        # bisector: equal angles alpha/2 to both beams, in the plane
        assert np.abs(np.sum(X * nij, -1) - np.cos(alpha / 2)).max() < 1e-15
        assert np.abs(np.sum(X * nik, -1) - np.cos(alpha / 2)).max() < 1e-15
        assert np.abs(np.sum(Z * nij, -1)).max() < 1e-15 and np.abs(np.sum(Z * nik, -1)).max() < 1e-15
        # Z_S = n_ij x n_ik / sin(alpha) (sense), Y = Z x X
        assert np.abs(Z - np.cross(nij, nik) / np.sin(alpha)[:, None]).max() < 1e-15
        assert np.abs(Y - np.cross(Z, X)).max() < 1e-15
        d = inc - r[:, i]
        assert np.abs(X - d / np.linalg.norm(d, axis=-1, keepdims=True)).max() < 1e-15
    # the three satellites share one normal under the global law
    assert np.abs(T[:, 0, 2] - T[:, 1, 2]).max() < 1e-15 and np.abs(T[:, 0, 2] - T[:, 2, 2]).max() < 1e-15


@pytest.mark.parametrize("law", ["global", "taylor1", "taylor2"])
def test_oa_convention_faces_remote(law):
    """OA_1 = X_S rotated by +theta/2 about Z_S faces satellite k, OA_2 (-theta/2) faces j:
    X_OA equals the beam vector towards that satellite (beam written out in the test)."""
    t = np.linspace(0.0, 86400.0, 13)
    (r, v, a, j3, _), _ = _circular_jets(t)
    att = attitude(r, v, a, law=law, jerk=j3)
    T_OA_I = att.T_OA_I
    for s in Sat:
        i = s.index
        for m in Mosa:
            rem = m.remote(s).index
            d = r[:, rem] - r[:, i]
            L = np.linalg.norm(d, axis=-1, keepdims=True)
            b = d / L
            if law != "global":
                b = b - v[:, rem] / C
            if law == "taylor2":
                b = b + a[:, rem] * L / (2 * C**2)
            b /= np.linalg.norm(b, axis=-1, keepdims=True)
            assert np.abs(T_OA_I[:, i, m.index, 0] - b).max() < 1e-15, (s, m)
            assert np.abs(T_OA_I[:, i, m.index, 2] - att.T_S_I[:, i, 2]).max() < 1e-15
            assert np.allclose(att.mosa_angle[:, i, m.index], m.sign * att.theta[:, i] / 2, rtol=0, atol=1e-16)
    # MOSA 1 of Sat 1 faces Sat 3 (k of (1, 2, 3))
    assert Mosa.OA1.remote(Sat.S1) is Sat.S3


def test_hi_lo_input_matches_float64():
    """(hi, lo) input: the arm vectors use the low parts; frames equal the float64 path to 1e-16."""
    (r, v, a, *_), _ = _circular_jets(np.array([0.0, 3600.0]))
    lo = np.full_like(r, 1e-9)
    att1 = attitude((r, lo), (v, np.zeros_like(v)), a)
    att0 = attitude(r, v, a)
    assert np.abs(att1.T_S_I - att0.T_S_I).max() < 1e-16 * 4


# ---------------------------------------------------------------- analytic rigid case


@pytest.mark.parametrize("law,method", [("global", "direct"), ("global", "p-frame"), ("taylor1", "direct"),
                                        ("taylor2", "direct")])
def test_rigid_equilateral_circular(law, method):
    """Analytic: three satellites 120 deg apart on one circular orbit rotate rigidly at
    n = sqrt(GM/a^3) about the orbit normal W; every beam (also the Taylor ones, which
    are rigid combinations of rotating vectors) turns with it.  So omega_S = (0, 0, n),
    omega_dot_S = 0, theta' = theta'' = 0, Z_S = W, and for the global law X_S = -r_hat,
    theta = 60 deg.  Tolerances: float64 rounding (the float64 input positions are rigid only
    to ~1e-16 relative): 2e-15 n = 4e-20 rad/s, 2e-15 n^2 = 8e-25 rad/s^2."""
    a0 = 1.0e8
    sats = ((a0, 30.0), (a0, 150.0), (a0, 270.0))
    t = np.linspace(0.0, 86400.0, 25)
    (r, v, a, j3, s4), W = _circular_jets(t, sats)
    att = attitude(r, v, a, law=law, method=method, jerk=j3, snap=s4)
    n = np.sqrt(GM / a0**3)
    assert np.abs(att.omega - np.array([0.0, 0.0, n])).max() < 2e-15 * n
    assert np.abs(att.omega_dot).max() < 2e-15 * n**2
    assert np.abs(att.theta_dot).max() < 2e-15 * n and np.abs(att.theta_ddot).max() < 2e-15 * n**2
    assert np.abs(att.T_S_I[..., 2, :] - W).max() < 1e-15
    # OA frames: omega_OA = T_OA_S (0, 0, n) = (0, 0, n)
    assert np.abs(att.omega_oa - np.array([0.0, 0.0, n])).max() < 2e-15 * n
    assert np.abs(att.omega_dot_oa).max() < 2e-15 * n**2
    if law == "global":
        assert np.abs(att.theta - np.pi / 3).max() < 1e-15
        rhat = r / np.linalg.norm(r, axis=-1, keepdims=True)
        assert np.abs(att.T_S_I[..., 0, :] + rhat).max() < 1e-15


# ---------------------------------------------------------------- finite differences along a real orbit


@pytest.fixture(scope="module")
def real_orbit():
    from tqdyn import dynamics
    from tqdyn.scenario import load_scenario

    blocks = []
    dynamics.propagate(load_scenario("tianqin", ["run.duration=1d", "constellation.pointing=none",
                                                                "constellation.control=off"]), sink=blocks.append)
    rows = dynamics.Rows.concatenate(blocks)
    return rows.t[0] + rows.t[1], rows.sat_r, rows.sat_v, rows.sat_a_gravity


def _fd_omega(T, h):
    """omega, omega_dot in S from 5-point central differences of T_S_I (interior points).

    [omega x] = T dT^T/dt;  [omega_dot x] = d/dt (T dT^T/dt) = T' T'^T + T T''^T (skew part)."""
    T1 = (T[:-4] - 8 * T[1:-3] + 8 * T[3:-1] - T[4:]) / (12 * h)
    T2 = (-T[:-4] + 16 * T[1:-3] - 30 * T[2:-2] + 16 * T[3:-1] - T[4:]) / (12 * h * h)
    Tc = T[2:-2]
    M = Tc @ np.swapaxes(T1, -1, -2)
    Md = T1 @ np.swapaxes(T1, -1, -2) + Tc @ np.swapaxes(T2, -1, -2)
    vee = lambda m: 0.5 * np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],  # noqa: E731
                                    m[..., 1, 0] - m[..., 0, 1]], axis=-1)
    return vee(M), vee(Md)


# Tolerance of the finite differences (h = 50 s): the frame turns at n ~ 2.0e-5 rad/s,
# so |T^(k)| <~ n^k.  Truncation: omega h^4 n^5/30 = 7e-19 rad/s; omega_dot
# h^4 n^6/90 = 4e-24 rad/s^2.  Rounding of T (delta ~ 4e-16): omega 18 delta/(12 h)
# = 1.2e-17 rad/s; omega_dot 64 delta/(12 h^2) = 8.5e-19 rad/s^2.
TOL_FD_OMEGA = 2e-17
TOL_FD_OMEGA_DOT = 1.5e-18


@pytest.mark.parametrize("law,method", [("global", "direct"), ("global", "p-frame"), ("taylor1", "direct")])
def test_omega_against_finite_differences(real_orbit, law, method):
    """FD of T_S_I along the full-force 1-day TianQin orbit (50 s grid) vs the analytic rates.

    taylor1 needs the jerk: the monopole jerk (central_jerk_snap); the neglected jerk of the
    perturbations (< ~1e-5 n m/s^3) changes omega_dot by < ~1e-18 rad/s^2 (divided by c)."""
    t, r, v, a = real_orbit
    h = t[1] - t[0]
    assert np.allclose(np.diff(t), h)
    jerk = central_jerk_snap(r, v, GM)[0] if law != "global" else None
    att = attitude(r, v, a, law=law, method=method, jerk=jerk)
    om_fd, omd_fd = _fd_omega(att.T_S_I, h)
    assert np.abs(om_fd - att.omega[2:-2]).max() < TOL_FD_OMEGA
    # taylor1: plus the neglected perturbation jerk (< ~1e-18 rad/s^2, docstring): measured 1.46e-18
    # with 14 C04, 1.50e-18 with 20 C04 (the orbit differs by um), global 3.4e-19 .. 4.6e-19
    assert np.abs(omd_fd - att.omega_dot[2:-2]).max() < TOL_FD_OMEGA_DOT + (1e-18 if law != "global" else 0.0)
    # MOSA rates: FD of theta (same stencils; theta'' rounding 64*2e-16/(12 h^2) ~ 4e-19)
    th = att.theta
    th1 = (th[:-4] - 8 * th[1:-3] + 8 * th[3:-1] - th[4:]) / (12 * h)
    th2 = (-th[:-4] + 16 * th[1:-3] - 30 * th[2:-2] + 16 * th[3:-1] - th[4:]) / (12 * h * h)
    assert np.abs(th1 - att.theta_dot[2:-2]).max() < 1e-17
    assert np.abs(th2 - att.theta_ddot[2:-2]).max() < 1e-18


def test_p_frame_equals_direct_real_orbit(real_orbit):
    """The appendix p-frame method and the Poisson relation agree to round-off (different
    formulas, same definitions): |d omega| < 1e-19 rad/s (1e-14 relative), |d omega_dot|
    < 1e-23 rad/s^2 (omega_dot ~ 2e-13), frames to 1e-15."""
    t, r, v, a = real_orbit
    A = attitude(r, v, a)
    B = attitude(r, v, a, method="p-frame")
    assert np.abs(A.T_S_I - B.T_S_I).max() < 1e-15
    assert np.abs(A.omega - B.omega).max() < 1e-19
    assert np.abs(A.omega_dot - B.omega_dot).max() < 1e-23


def test_p_frame_trap_is_resolved_by_the_fd_check(real_orbit):
    """docs/design.md (Traps) trap: using inertial relative velocities rotated into p instead of the
    p-frame coordinate rates drops T_p_I' (R_i - r_inc), an omega error of order |omega_p|.
    With x_p tied to the plane, p turns only with the plane (precession under the Moon/Sun):
    its in-plane rate, seen here in omega_S, is ~3e-9 rad/s -- 1e8 times the FD tolerance
    (2e-17 rad/s) that the p-frame method passes above, so that test would catch the trap."""
    t, r, v, a = real_orbit
    A = attitude(r, v, a, method="p-frame")
    inplane = np.abs(A.omega[..., :2]).max()
    assert 1e-9 < inplane < 1e-8
    assert inplane > 1e6 * TOL_FD_OMEGA


# ---------------------------------------------------------------- mpmath reference


def _mp_frames(t, law):
    """T_S_I (3 satellites) at 40 digits from the analytic Kepler states (Table I)."""
    states = [kepler_state_at(a, 0, deg("74.5"), deg("211.6"), 0, deg(nu), mpf(GM), t) for a, nu in TABLE_I]
    c = mpf(C)

    def unit(x):
        nrm = mp.sqrt(sum(e * e for e in x))
        return [e / nrm for e in x]

    def cross(x, y):
        return [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]

    out = []
    for s in Sat:
        ri = states[s.index][0]
        beams = []
        for rem in (s.j, s.k):
            rr, vv = states[rem.index]
            b = unit([rr[m] - ri[m] for m in range(3)])
            if law == "taylor1":
                b = unit([b[m] - vv[m] / c for m in range(3)])
            beams.append(b)
        X = unit([beams[0][m] + beams[1][m] for m in range(3)])
        Z = unit(cross(beams[0], beams[1]))
        Y = cross(Z, X)
        out.append([X, Y, Z])
    return out


@pytest.mark.parametrize("law", ["global", "taylor1"])
def test_against_mpmath_kepler(law):
    """mpmath reference (40 digits): omega, omega_dot from a 5-point stencil (h = 1 s) of
    the frames built from the exact Kepler states; the float64 analytic rates (states from
    the same mpmath Kepler solution, jerk exact for the monopole) agree to 1e-20 rad/s and
    5e-25 rad/s^2 (float64 rounding of the O(n^2) terms) (omega ~ 2e-5, omega_dot ~ 2e-22 for Kepler orbits)."""
    t0 = mpf(43210)
    h = mpf(1)
    with mp.workdps(40):
        Ts = [_mp_frames(t0 + k * h, law) for k in (-2, -1, 0, 1, 2)]
        ref_om, ref_omd = [], []
        for s in range(3):
            T = [[[Ts[q][s][a][b] for b in range(3)] for a in range(3)] for q in range(5)]
            d1 = [[(T[0][a][b] - 8 * T[1][a][b] + 8 * T[3][a][b] - T[4][a][b]) / (12 * h) for b in range(3)]
                  for a in range(3)]
            d2 = [[(-T[0][a][b] + 16 * T[1][a][b] - 30 * T[2][a][b] + 16 * T[3][a][b] - T[4][a][b]) / (12 * h * h)
                   for b in range(3)] for a in range(3)]
            Tc = T[2]
            M = [[sum(Tc[a][m] * d1[b][m] for m in range(3)) for b in range(3)] for a in range(3)]
            Md = [[sum(d1[a][m] * d1[b][m] + Tc[a][m] * d2[b][m] for m in range(3)) for b in range(3)]
                  for a in range(3)]
            ref_om.append([float(M[2][1]), float(M[0][2]), float(M[1][0])])
            ref_omd.append([float(Md[2][1]), float(Md[0][2]), float(Md[1][0])])
        st = [kepler_state_at(a, 0, deg("74.5"), deg("211.6"), 0, deg(nu), mpf(GM), t0) for a, nu in TABLE_I]
        r = np.array([[float(x) for x in s_[0]] for s_ in st])[None]
        rl = np.array([[float(x - mpf(float(x))) for x in s_[0]] for s_ in st])[None]
        v = np.array([[float(x) for x in s_[1]] for s_ in st])[None]
    acc = -GM * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3
    jerk = central_jerk_snap(r, v, GM)[0]
    att = attitude((r, rl), v, acc, law=law, jerk=jerk)
    assert np.abs(att.omega[0] - np.array(ref_om)).max() < 1e-20
    # omega_dot is formed from O(n^2) = 4e-10 rad/s^2 terms: float64 rounding ~1e-15 n^2
    assert np.abs(att.omega_dot[0] - np.array(ref_omd)).max() < 5e-25


# ---------------------------------------------------------------- helpers


def test_central_jerk_snap_matches_circular_derivatives():
    """Exact circular-orbit derivatives (d^m r/dt^m = n^m a rotated by m pi/2) vs the
    monopole jerk/snap formulas: relative 1e-14."""
    (r, v, a, j3, s4), _ = _circular_jets(np.linspace(0, 86400.0, 7))
    jerk, snap = central_jerk_snap(r, v, GM)
    assert np.abs(jerk - j3).max() < 1e-14 * np.abs(j3).max()
    assert np.abs(snap - s4).max() < 1e-14 * np.abs(s4).max()


def test_bad_inputs():
    (r, v, a, *_), _ = _circular_jets(np.array([0.0]))
    with pytest.raises(ValueError):
        attitude(r, v, a, law="nope")
    with pytest.raises(ValueError):
        attitude(r, v, a, law="taylor1", method="p-frame")
    with pytest.raises(ValueError):
        attitude(r, law="taylor1")
    with pytest.raises(ValueError):
        beam_vectors(r, law="x")
