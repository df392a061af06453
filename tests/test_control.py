"""Tests for tqdyn.constellation.spacecraft and tqdyn.constellation.control.

Independent references used here (each test names its own):
* the three control conditions themselves, solved as a 6x6 linear system with
  numpy.linalg.solve (not the closed forms of eq:E1/E2/Greal);
* kinematics of a point fixed in a rotating, MOSA-articulated frame by
  finite differences of its inertial position, computed in mpmath (40 digits)
  along an analytic, arbitrary rotation history;
* analytic case: equilateral constellation on a circular Kepler orbit rotating
  rigidly (omega_S = n Z_S, alpha = 60 deg, Hill tidal+centrifugal
  acceleration n^2 (3x, 0, -z));
* TianQin Table I Kepler orbits in mpmath (tqdyn.elements.kepler_state_at), S
  frames built here from positions, angular rates by 5-point finite
  differences of T_S_I (h = 20 s, truncation ~h^4 w^5 ~ 1e-25 rad/s, far below
  anything tested), exact differential gravity in mpmath.
Tolerances are in m/s^2, rad/s^2 or relative to the input magnitude.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mpmath import matrix, mp, mpf

from tqdyn.astro.constants import GM_EARTH_EGM2008
from tqdyn.constellation.control import (
    dragfree_acceleration,
    dragfree_as_printed,
    mosa_angular_rates,
    nominal_control,
    oa_rotation,
    suspension_acceleration,
    tm_angular_acceleration,
    tm_relative_acceleration,
)
from tqdyn.constellation.spacecraft import TABLE_IV_SELF_GRAVITY, Spacecraft
from tqdyn.astro.elements import deg, kepler_state_at

GM = mpf(GM_EARTH_EGM2008)
TABLE_I = [("100000.0e3", "30"), ("100009.5e3", "150"), ("99995.0e3", "270")]


# --------------------------------------------------------------------------- helpers (mpmath)

def _unit(v):
    return v / mp.norm(v)


def _cross(a, b):
    return matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _s_frame(R, i):
    """T_S_I (mpmath 3x3, rows X_S, Y_S, Z_S) and alpha_i from the 3 positions (paper sec. III A)."""
    j, k = (i + 1) % 3, (i + 2) % 3
    nij, nik = _unit(R[j] - R[i]), _unit(R[k] - R[i])
    X = _unit(nij + nik)  # bisector = direction of the incenter from R_i
    Z = _unit(_cross(nij, nik))
    Y = _cross(Z, X)
    alpha = mp.acos((nij.T * nik)[0])
    return matrix([[X[c] for c in range(3)], [Y[c] for c in range(3)], [Z[c] for c in range(3)]]), alpha


def _vee(m):
    return [(m[2, 1] - m[1, 2]) / 2, (m[0, 2] - m[2, 0]) / 2, (m[1, 0] - m[0, 1]) / 2]


def _fd(fs, h):
    """5-point first and second derivatives from samples at -2h..2h."""
    d1 = (fs[0] - 8 * fs[1] + 8 * fs[3] - fs[4]) / (12 * h)
    d2 = (-fs[0] + 16 * fs[1] - 30 * fs[2] + 16 * fs[3] - fs[4]) / (12 * h * h)
    return d1, d2


def _rates(Ts, h):
    """omega, omega_dot in the rotating frame from T(t) samples: [w]x = T T'^T, [w']x = T' T'^T + T T''^T."""
    T = Ts[2]
    d1, d2 = _fd(Ts, h)
    return _vee(T * d1.T), _vee(d1 * d1.T + T * d2.T)


def _tianqin_inputs(times, tm_axis="y", h=20):
    """Control inputs along the Table I Kepler orbits (shapes (N, 3, ...)) + sat velocities in S."""
    sc = Spacecraft(tm_axis=tm_axis)
    r0 = sc.nominal_housing_centers
    N = len(times)
    out = {k: np.zeros(s) for k, s in dict(T=(N, 3, 3, 3), w=(N, 3, 3), wd=(N, 3, 3), th=(N, 3), thd=(N, 3),
                                             thdd=(N, 3), dg=(N, 3, 2, 3), vS=(N, 3, 3)).items()}
    with mp.workdps(40):
        for n, t in enumerate(times):
            states = [[kepler_state_at(a, 0, deg("74.5"), deg("211.6"), 0, deg(nu), GM, mpf(t) + m * h)
                       for a, nu in TABLE_I] for m in (-2, -1, 0, 1, 2)]
            for i in range(3):
                Ts, als = [], []
                for m in range(5):
                    T, al = _s_frame([matrix(s[0]) for s in states[m]], i)
                    Ts.append(T)
                    als.append(al)
                w, wd = _rates(Ts, h)
                a1, a2 = _fd(als, h)
                T = Ts[2]
                R = matrix(states[2][i][0])
                aS = -GM * R / mp.norm(R) ** 3
                for l in range(2):
                    d = T.T * matrix([mpf(float(x)) for x in r0[l]])
                    x = R + d
                    dga = -GM * x / mp.norm(x) ** 3 - aS
                    out["dg"][n, i, l] = [float(c) for c in dga]
                out["T"][n, i] = np.array(T.tolist(), dtype=float)
                out["w"][n, i] = [float(c) for c in w]
                out["wd"][n, i] = [float(c) for c in wd]
                out["th"][n, i] = float(als[2])
                out["thd"][n, i] = float(a1)
                out["thdd"][n, i] = float(a2)
                out["vS"][n, i] = [float(c) for c in T * matrix(states[2][i][1])]
    return sc, out


@pytest.fixture(scope="module")
def tq_y():
    return _tianqin_inputs(np.linspace(0.0, 86400.0, 5), "y")


def _run(sc, d, self_gravity=False):
    sc2 = Spacecraft(tm_axis=sc.tm_axis, self_gravity_on=self_gravity)
    wm, wmd = mosa_angular_rates(d["thd"], d["thdd"])
    return nominal_control(d["T"], d["w"], d["wd"], d["th"], wm, wmd, d["dg"], sc2)


# --------------------------------------------------------------------------- indices and spacecraft

def test_oa_rotation_matches_index_convention():
    """oa_rotation's l = 1 / 2 rotate X_S by Mosa.OA1.sign / OA2.sign * theta/2 (tqdyn.constellation.indices)."""
    from tqdyn.constellation.indices import Mosa

    th = 1.07
    for m in Mosa:
        ang = m.sign * th / 2
        np.testing.assert_allclose(oa_rotation(th)[m.index, 0], [math.cos(ang), math.sin(ang), 0], atol=1e-16)


def test_spacecraft_defaults_and_table_iv():
    """Table III (d_TM 0.40 m, d_p = 0) and Table IV (4.94^{-11} read as 4.94e-11 m/s^2) typed in here."""
    sc = Spacecraft()
    np.testing.assert_array_equal(sc.nominal_housing_centers, [[0, 0.2, 0], [0, -0.2, 0]])
    np.testing.assert_array_equal(sc.pivots, sc.nominal_housing_centers)
    np.testing.assert_array_equal(sc.housing_centers(np.full((4, 3), 1.05)),
                                  np.broadcast_to(sc.nominal_housing_centers, (4, 3, 2, 3)))
    tab = [[4.94e-11, 6.22e-12, 1.10e-10], [5.20e-11, 5.65e-12, -5.72e-11]]
    assert sc.self_gravity_array.shape == (3, 2, 3)
    np.testing.assert_array_equal(sc.self_gravity_array, np.broadcast_to(tab, (3, 2, 3)))
    np.testing.assert_array_equal(TABLE_IV_SELF_GRAVITY, tab)
    assert not Spacecraft(self_gravity_on=False).self_gravity_array.any()
    custom = np.arange(18.0).reshape(3, 2, 3) * 1e-12
    np.testing.assert_array_equal(Spacecraft(self_gravity=custom).self_gravity_array, custom)
    # pivots with d_p > 0: EH center stays d_p from the pivot and moves with the MOSA
    sc = Spacecraft(d_p=0.1)
    r0 = sc.housing_centers(np.array([math.pi / 3, 1.1]))
    np.testing.assert_allclose(np.linalg.norm(r0 - sc.pivots, axis=-1), 0.1, rtol=1e-15)
    np.testing.assert_allclose(r0[0], sc.nominal_housing_centers, atol=1e-16)


@pytest.mark.parametrize("kw, name", [
    (dict(d_tm=0.0), "d_tm"), (dict(d_tm=-0.4), "d_tm"), (dict(d_tm=float("nan")), "d_tm"),
    (dict(d_p=-1e-3), "d_p"), (dict(tm_axis="w"), "tm_axis"),
    (dict(self_gravity=np.zeros((3, 3))), "self_gravity"), (dict(self_gravity=np.zeros((2, 2, 3))), "self_gravity"),
    (dict(self_gravity="abc"), "self_gravity"), (dict(self_gravity_on="yes"), "self_gravity_on"),
])
def test_spacecraft_validation(kw, name):
    with pytest.raises(ValueError, match=rf"Spacecraft\.{name} = .*allowed"):
        Spacecraft(**kw)


# --------------------------------------------------------------------------- conventions and conditions

def test_oa_convention_faces_k():
    """X_OA_1 (X_S rotated +alpha/2 about Z_S) = n_ik, X_OA_2 = n_ij; reference: geometry of a random triangle (mpmath)."""
    rng = np.random.default_rng(3)
    with mp.workdps(30):
        for _ in range(5):
            R = [matrix(list(rng.normal(size=3) * 1e8)) for _ in range(3)]
            for i in range(3):
                T, alpha = _s_frame(R, i)
                Tf = np.array(T.tolist(), dtype=float)
                toa = oa_rotation(float(alpha))
                nij = np.array(_unit(R[(i + 1) % 3] - R[i]).tolist(), dtype=float).ravel()
                nik = np.array(_unit(R[(i + 2) % 3] - R[i]).tolist(), dtype=float).ravel()
                np.testing.assert_allclose(Tf.T @ toa[0, 0], nik, atol=1e-15)
                np.testing.assert_allclose(Tf.T @ toa[1, 0], nij, atol=1e-15)
                for l in range(2):  # orthonormal, right-handed, Z_OA = Z_S
                    np.testing.assert_allclose(toa[l] @ toa[l].T, np.eye(3), atol=1e-15)
                    assert abs(np.linalg.det(toa[l]) - 1) < 1e-15
                    np.testing.assert_array_equal(toa[l, 2], [0, 0, 1])


def _random_case(rng, n=200, scale=1e-10):
    g = rng.normal(size=(n, 3, 2, 3)) * scale * 10 ** rng.uniform(-2, 1, size=(n, 3, 1, 1))
    th = rng.uniform(math.radians(50), math.radians(70), size=(n, 3))
    return g, th


def test_three_conditions_round_off():
    """(a) A_l + g_l = G in S, (b) A_l . X_OA_l = 0, (c) A_1z = -A_2z: residual <= 1e-15 |g| (random inputs)."""
    rng = np.random.default_rng(0)
    g, th = _random_case(rng)
    A = suspension_acceleration(g, th)
    G = dragfree_acceleration(g, th)
    A_S = np.einsum("...lji,...lj->...li", oa_rotation(th), A)
    scale = np.abs(g).max(axis=(-2, -1))
    res_a = np.abs(A_S + g - G[..., None, :]).max(axis=(-2, -1)) / scale
    assert res_a.max() < 1e-15, res_a.max()
    assert np.all(A[..., 0] == 0.0)
    assert np.all(A[..., 0, 2] == -A[..., 1, 2])


def test_e1_e2_and_g_recovered_from_conditions():
    """Solve the 6 linear conditions with numpy.linalg.solve; eq:E1/E2 and the derived G agree to 1e-15 relative."""
    rng = np.random.default_rng(1)
    g, th = _random_case(rng, n=50)
    A = suspension_acceleration(g, th)
    G = dragfree_acceleration(g, th)
    T = oa_rotation(th)
    for n in range(g.shape[0]):
        for i in range(3):
            M = np.zeros((6, 6))
            b = np.zeros(6)
            M[0:3, 0:3] = T[n, i, 0].T          # T_S_OA1 A1 - T_S_OA2 A2 = g2 - g1
            M[0:3, 3:6] = -T[n, i, 1].T
            b[0:3] = g[n, i, 1] - g[n, i, 0]
            M[3, 0] = 1.0                       # no actuation along X_OA_1
            M[4, 3] = 1.0                       # ... and X_OA_2
            M[5, 2] = M[5, 5] = 1.0             # A1z + A2z = 0
            x = np.linalg.solve(M, b)
            sc = np.abs(g[n, i]).max()
            np.testing.assert_allclose(A[n, i].ravel(), x, rtol=0, atol=2e-15 * sc)
            np.testing.assert_allclose(G[n, i], T[n, i, 0].T @ x[:3] + g[n, i, 0], rtol=0, atol=2e-15 * sc)


def test_printed_greal_violates_condition_a():
    """eq:Greal as printed (tan theta, cot theta) breaks G = A_l + g_l by |tan th - tan th/2| dg_y/2 etc."""
    rng = np.random.default_rng(2)
    g, th = _random_case(rng)
    A_S = np.einsum("...lji,...lj->...li", oa_rotation(th), suspension_acceleration(g, th))
    Gp = dragfree_as_printed(g, th)
    res = A_S + g - Gp[..., None, :]          # should be 0 for a correct G
    dg = g[..., 1, :] - g[..., 0, :]
    exp_x = 0.5 * (np.tan(th) - np.tan(th / 2)) * dg[..., 1]
    exp_y = 0.5 * (1 / np.tan(th) - 1 / np.tan(th / 2)) * dg[..., 0]
    scale = np.abs(g).max(axis=(-2, -1))
    np.testing.assert_array_less(np.abs(res[..., 0, 0] - exp_x) / scale, 1e-14)
    np.testing.assert_array_less(np.abs(res[..., 0, 1] - exp_y) / scale, 1e-14)
    # at theta = 60 deg both factors are 1/sqrt(3): the violation is ~58 % of dg
    th60 = np.full(1, math.pi / 3)
    assert abs(0.5 * (np.tan(th60) - np.tan(th60 / 2))[0] - 1 / math.sqrt(3)) < 1e-15
    rel = np.abs(res).max(axis=(-2, -1)) / np.abs(dg[..., :2]).max(axis=-1)
    print(f"\nprinted eq:Greal: condition (a) violated by {rel.min():.2f}..{rel.max():.2f} x |dg_xy|")
    assert rel.min() > 0.3


# --------------------------------------------------------------------------- kinematics of g_l and alpha

def _rot(axis, a):
    c, s = mp.cos(a), mp.sin(a)
    if axis == 2:
        return matrix([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    if axis == 0:
        return matrix([[1, 0, 0], [0, c, s], [0, -s, c]])
    return matrix([[c, 0, -s], [0, 1, 0], [s, 0, c]])


def test_bracket_and_tm_angular_acceleration_vs_finite_differences():
    """g_l (kinematic part, no gravity) = -(inertial accel. of the EH center - R'') in S, and the OA_l
    angular acceleration, both against 5-point finite differences in mpmath (40 digits, h = 1e-3 s,
    truncation ~h^4 w^6 d ~ 1e-20 m/s^2) of an analytic rotation history with d_p = 0.3 m."""
    sc = Spacecraft(d_p=0.3, tm_axis="x")
    h = mpf("1e-3")
    t0 = mpf("0.7")

    def T_S_I(t):  # arbitrary smooth attitude history, rates ~ 0.1 rad/s
        return _rot(0, mpf("0.3") * mp.sin(mpf("0.2") * t)) * _rot(1, mpf("0.05") * t ** 2) * _rot(2, mpf("0.1") * t + 1)

    def theta(t):
        return mp.pi / 3 + mpf("0.2") * mp.sin(mpf("0.5") * t)

    def eh_inertial(t, l):  # EH center relative to the CoM, inertial coordinates
        sgn = 1 if l == 0 else -1
        ang = sgn * theta(t) / 2
        rp = matrix([mpf(float(x)) for x in sc.pivots[l]])
        rho = mpf("0.3") * matrix([mp.cos(ang), mp.sin(ang), 0])
        return T_S_I(t).T * (rp + rho)

    with mp.workdps(40):
        ts = [t0 + m * h for m in (-2, -1, 0, 1, 2)]
        Ts = [T_S_I(t) for t in ts]
        w, wd = _rates(Ts, h)
        th_s = [theta(t) for t in ts]
        thd, thdd = _fd(th_s, h)
        T = Ts[2]
        acc = [T * _fd([eh_inertial(t, l) for t in ts], h)[1] for l in range(2)]
        # OA_l attitude history and its rates (in OA_l)
        oa = []
        for l in range(2):
            Toa = []
            for t in ts:
                sgn = 1 if l == 0 else -1
                Toa.append(_rot(2, sgn * theta(t) / 2) * T_S_I(t))
            oa.append(_rates(Toa, h))
    f = lambda v: np.array([float(x) for x in v])
    w, wd, th, thd, thdd = f(w), f(wd), float(th_s[2]), float(thd), float(thdd)
    wm, wmd = mosa_angular_rates(thd, thdd)
    r0 = sc.housing_centers(th)
    rho = sc.lever_arms(th)
    g = tm_relative_acceleration(np.zeros((2, 3)), w, wd, wm, wmd, r0, rho)
    ref = -np.array([f(a) for a in acc])
    print(f"\n|g| = {np.abs(ref).max():.3e} m/s^2, max error {np.abs(g - ref).max():.2e} m/s^2")
    np.testing.assert_allclose(g, ref, rtol=0, atol=1e-15 * np.abs(ref).max() * 10)
    alpha = tm_angular_acceleration(w, wd, wm, wmd, th)
    ref_a = np.array([f(oa[l][1]) for l in range(2)])
    np.testing.assert_allclose(alpha, ref_a, rtol=0, atol=1e-15 * np.abs(ref_a).max() * 10)
    # and the OA angular velocity itself is w_S + w_oa rotated into OA_l
    ref_w = np.array([f(oa[l][0]) for l in range(2)])
    np.testing.assert_allclose(np.einsum("lij,lj->li", oa_rotation(th), w + wm), ref_w, atol=1e-16)


# --------------------------------------------------------------------------- analytic rigid equilateral case

@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_rigid_equilateral_circular_hill(axis):
    """Equilateral triangle on one circular orbit (r = 1e8 m), omega_S = n Z_S, omega_dot = 0, alpha = 60 deg:
    g_l = n^2 (3x, 0, -z) (Hill) up to the second-order tide 3 n^2 d^2 / r ~ 5e-19 m/s^2; exact dg in mpmath."""
    r = mpf("1e8")
    with mp.workdps(40):
        n2 = GM / r ** 3
        sc = Spacecraft(tm_axis=axis, self_gravity_on=False)
        R = matrix([r, 0, 0])   # satellite on the x axis, orbit in the xy plane, X_S = -x_I, Z_S = z_I
        T = matrix([[-1, 0, 0], [0, -1, 0], [0, 0, 1]])
        aS = -GM * R / r ** 3
        dg = np.zeros((2, 3))
        for l in range(2):
            x = R + T.T * matrix([mpf(float(c)) for c in sc.nominal_housing_centers[l]])
            dg[l] = [float(c) for c in (-GM * x / mp.norm(x) ** 3 - aS)]
    n2 = float(n2)
    Tf = np.array(T.tolist(), dtype=float)
    wm, wmd = mosa_angular_rates(0.0, 0.0)
    out = nominal_control(Tf[None], np.array([[0, 0, math.sqrt(n2)]]), np.zeros((1, 3)), np.full(1, math.pi / 3),
                          wm[None], wmd[None], (Tf.T @ np.zeros(3))[None, None] + dg[None], sc)
    r0 = sc.nominal_housing_centers
    hill = n2 * np.stack([3 * r0[:, 0], 0 * r0[:, 1], -r0[:, 2]], -1)
    np.testing.assert_allclose(out.g[0], hill, rtol=0, atol=1e-18)
    dgh = hill[1] - hill[0]
    s, c = 0.5, math.sqrt(3) / 2
    A1y = (dgh[1] * s - dgh[0] * c) / (2 * s * c)
    np.testing.assert_allclose(out.a_suspension[0, 0, 1], A1y, rtol=0, atol=1e-17)
    A = np.abs(out.a_suspension).max()
    print(f"\nrigid equilateral, TMs along {axis}_S: max |A_c| = {A:.3e} m/s^2, |G| = {np.abs(out.a_dragfree).max():.3e}")
    if axis == "x":
        assert 4e-10 < A < 6e-10     # 3 n^2 d / sin(theta/2)... = 1.2 n^2 = 4.8e-10
    elif axis == "y":
        assert A < 1e-18


# --------------------------------------------------------------------------- TianQin Kepler orbits

def test_flight_direction_is_minus_y_s(tq_y):
    """Satellite velocity expressed in S (Table I Kepler orbits): along -Y_S, not +Y_S."""
    _, d = tq_y
    u = d["vS"] / np.linalg.norm(d["vS"], axis=-1, keepdims=True)
    assert np.all(u[..., 1] < -0.999), u[..., 1].max()


def test_tianqin_kepler_magnitudes(tq_y):
    """Table I Kepler orbits over 1 day (5 epochs x 3 satellites): without self-gravity |A_c| ~1e-13 and
    |G| ~1e-13 m/s^2; with Table IV self-gravity |A_c| ~1e-10; TMs along X_S would need ~5e-10 m/s^2."""
    sc, d = tq_y
    off = _run(sc, d, self_gravity=False)
    on = _run(sc, d, self_gravity=True)
    A0 = np.abs(off.a_suspension).max()
    G0 = np.linalg.norm(off.a_dragfree, axis=-1).max()
    A1 = np.abs(on.a_suspension).max()
    G1 = np.linalg.norm(on.a_dragfree, axis=-1).max()
    al = np.abs(off.alpha_suspension).max()
    # G in GCRS is G in S rotated back
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", d["T"], off.a_dragfree), off.a_dragfree_S,
                               atol=1e-28)
    sx, dx = _tianqin_inputs(np.array([0.0]), "x")
    Ax = np.abs(_run(sx, dx).a_suspension).max()
    print(f"\nTianQin Kepler, TMs along Y_S: |A_c| {A0:.2e}, |G| {G0:.2e} m/s^2 (no self-gravity); "
          f"|A_c| {A1:.2e}, |G| {G1:.2e} (Table IV); |alpha_TM| {al:.2e} rad/s^2; TMs along X_S: |A_c| {Ax:.2e}")
    assert 1e-15 < A0 < 1e-12
    assert G0 < 1e-12
    assert 3e-11 < A1 < 3e-10
    assert 3e-10 < Ax < 7e-10
    assert al < 1e-11
    # condition (a) on the realistic case: |A_l + g_l - G| <= 1e-15 |g|
    A_S = np.einsum("...lji,...lj->...li", oa_rotation(d["th"]), on.a_suspension)
    res = np.abs(A_S + on.g - on.a_dragfree_S[..., None, :]).max()
    assert res < 1e-15 * np.abs(on.g).max(), res


def test_vectorised_shapes():
    """(N, 3, ...) inputs with N = 100000: shapes as documented (docs/trajectory-format.md); per-slice equality.
    Its cost is measured by ``tqdyn bench --model kernels``."""
    rng = np.random.default_rng(5)
    N = 100_000
    T = np.broadcast_to(np.eye(3), (N, 3, 3, 3))
    w = rng.normal(size=(N, 3, 3)) * 2e-5
    wd = rng.normal(size=(N, 3, 3)) * 1e-12
    th = rng.uniform(1.0, 1.1, size=(N, 3))
    wm, wmd = mosa_angular_rates(rng.normal(size=(N, 3)) * 1e-9, rng.normal(size=(N, 3)) * 1e-14)
    dg = rng.normal(size=(N, 3, 2, 3)) * 1e-10
    out = nominal_control(T, w, wd, th, wm, wmd, dg)
    assert out.g.shape == out.a_suspension.shape == out.alpha_suspension.shape == (N, 3, 2, 3)
    assert out.a_dragfree.shape == out.a_dragfree_S.shape == (N, 3, 3)
    one = nominal_control(T[7], w[7], wd[7], th[7], wm[7], wmd[7], dg[7])
    np.testing.assert_array_equal(one.a_suspension, out.a_suspension[7])
