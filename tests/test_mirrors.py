"""Every compiled kernel that deliberately mirrors a numpy implementation, against it.

The right-hand side runs on compiled kernels that work on 3-tuples and
preallocated arrays (no Python per step); the analysis code and the tests use
vectorised numpy versions of the same formulas.  The two are written
separately on purpose -- the numpy one is the readable reference -- so each
pair is listed here once, with the agreement it must reach (round-off of the
quantity's size; the derivations and their independent references, such as
finite differences or mpmath, are in the tests of each module).  A new
mirror gets a line in :data:`MIRRORS`.
"""

import math

import numpy as np
import pytest

from tqdyn.astro import elements as el
from tqdyn.constellation import attitude as att
from tqdyn.constellation import control as ctl
from tqdyn.constellation import geometry as geo
from tqdyn.constellation._control_jit import housing_geometry, satellite_control
from tqdyn.constellation._kinematics_jit import LAW_CODES, sat_kinematics
from tqdyn.constellation.spacecraft import Spacecraft
from tqdyn.dynamics.layout import SCHEME_CODES
from tqdyn.dynamics.rhs import _breathing_angle
from tqdyn.forces.central import central_jerk_snap, monopole_jerk_snap
from tqdyn.numerics import dd

GM = 3.986004415e14
C = 299792458.0


def _tianqin_states():
    """TianQin's Table I satellites (float64 parts of the dd states, m, m/s) and monopole accelerations."""
    elems = [("1e8", 30), ("100009.5e3", 150), ("99995e3", 270)]
    r_hi, r_lo, v = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))
    for i, (a, nu) in enumerate(elems):
        r, vv = el.elements_to_state(a, 0, el.deg("74.5"), el.deg("211.6"), el.deg(0), el.deg(nu), GM)
        y = el.state_to_dd(r, vv)
        r_hi[i], r_lo[i], v[i] = y[0:3, 0], y[0:3, 1], y[3:6, 0] + y[3:6, 1]
    r = r_hi + r_lo
    a = -GM * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3
    return r_hi, r_lo, v, a


def kinematics(law):
    """constellation._kinematics_jit.sat_kinematics vs constellation.attitude.attitude (direct method)."""
    r_hi, r_lo, v, a = _tianqin_states()
    T, w, wd, th = np.zeros((3, 3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))
    sat_kinematics(LAW_CODES[law], r_hi, r_lo, v, a, np.zeros((3, 3)), GM, C, T, w, wd, th)
    jerk, snap = central_jerk_snap((r_hi, r_lo), v, GM, a)
    ref = att.attitude((r_hi, r_lo), v, a, law=law, jerk=jerk, snap=snap)
    # measured (global/taylor1/taylor2): T 2.2e-16, omega 6.8e-21 rad/s (2 ulp of 2e-5), omega_dot 1.3e-25
    # rad/s^2 (its terms are omega^2 ~ 4e-10 cancelling to 2.5e-22), theta 2.2e-16, theta_dot 7.8e-21 rad/s
    np.testing.assert_allclose(T, ref.T_S_I, rtol=0, atol=1e-15)
    np.testing.assert_allclose(w, ref.omega, rtol=0, atol=3e-20)
    np.testing.assert_allclose(wd, ref.omega_dot, rtol=0, atol=5e-25)
    np.testing.assert_allclose(th[:, 0], ref.theta, rtol=0, atol=1e-15)
    np.testing.assert_allclose(th[:, 1], ref.theta_dot, rtol=0, atol=3e-20)


def control():
    """_control_jit.housing_geometry / satellite_control vs spacecraft.Spacecraft and the control module,
    for both drag-free schemes (tianqin line layout with a pivot offset; lisa optical-axis layout with
    tilted sensitive axes)."""
    rng = np.random.default_rng(7)
    crafts = (Spacecraft(d_tm=0.4, d_p=0.05, tm_axis="y", self_gravity_on=False),
              Spacecraft.preset("lisa", tm_distance=0.3, self_gravity_on=False,
                                sensitive_axes=[[1.0, 0.1, -0.05], [0.98, -0.2, 0.1]]))
    for craft in crafts:
        theta = np.pi / 3 + 1e-3 * rng.standard_normal(3)
        th1, th2 = 1e-9 * rng.standard_normal(3), 1e-15 * rng.standard_normal(3)
        w = np.array([1e-9, -2e-9, 2e-5]) + 1e-10 * rng.standard_normal((3, 3))
        wd = 1e-13 * rng.standard_normal((3, 3))
        dg = 1e-10 * rng.standard_normal((3, 2, 3))
        sg = 1e-10 * rng.standard_normal((3, 2, 3))
        r0, rho, vel = np.zeros((3, 2, 3)), np.zeros((3, 2, 3)), np.zeros((3, 2, 3))
        g, A, G, alpha = np.zeros((3, 2, 3)), np.zeros((3, 2, 3)), np.zeros((3, 3)), np.zeros((3, 2, 3))
        code = SCHEME_CODES[craft.scheme]
        for i in range(3):
            housing_geometry(i, theta[i], th1[i], craft.nominal_housing_centers, craft.pivots, craft.theta_nominal,
                             w, r0, rho, vel)
            satellite_control(i, code, craft.sensitive_axes_array, dg, sg, w, wd, theta[i], th1[i], th2[i], r0, rho,
                              g, A, G, alpha)
        np.testing.assert_allclose(r0, craft.housing_centers(theta), rtol=0, atol=1e-16)   # m, |r0| 0.2-0.3 m
        np.testing.assert_allclose(rho, craft.lever_arms(theta), rtol=0, atol=1e-16)
        wm, wmd = ctl.mosa_angular_rates(th1, th2)
        np.testing.assert_allclose(vel, np.cross(w[:, None, :], r0) + np.cross(wm, rho), rtol=0, atol=1e-21)  # m/s
        g_ref = ctl.tm_relative_acceleration(dg, w, wd, wm, wmd, r0, rho, sg)
        np.testing.assert_allclose(g, g_ref, rtol=0, atol=1e-24)              # m/s^2, |g| ~ 1e-10
        if craft.scheme == "tianqin":
            A_ref, G_ref = ctl.suspension_acceleration(g_ref, theta), ctl.dragfree_acceleration(g_ref, theta)
        else:
            G_ref, A_ref = ctl.dragfree_general(g_ref, theta, craft.sensitive_axes_array)
        np.testing.assert_allclose(A, A_ref, rtol=0, atol=1e-23)
        np.testing.assert_allclose(G, G_ref, rtol=0, atol=1e-23)
        np.testing.assert_allclose(alpha, ctl.tm_angular_acceleration(w, wd, wm, wmd, theta), rtol=0, atol=1e-26)


def breathing_angle():
    """dynamics.rhs._breathing_angle vs constellation.geometry.breathing_angles (both from dd positions)."""
    r_hi, r_lo, _, _ = _tianqin_states()
    ref, _, _ = geo.breathing_angles(geo.arms((r_hi[None], r_lo[None])))
    got = [_breathing_angle(r_hi, r_lo, i) for i in range(3)]
    np.testing.assert_allclose(got, ref[0], rtol=0, atol=4.5e-16)         # rad, ~pi/3: 2 ulp


def monopole_jerk():
    """forces.central.monopole_jerk_snap (tuples) vs forces.central.central_jerk_snap (numpy)."""
    r_hi, r_lo, v, a = _tianqin_states()
    for i in range(3):
        r = tuple(r_hi[i] + r_lo[i])
        j, s = monopole_jerk_snap(r, tuple(v[i]), tuple(a[i]), GM)
        jn, sn = central_jerk_snap(np.array(r), v[i], GM, a[i])
        scale_j = GM * np.linalg.norm(v[i]) / np.linalg.norm(r) ** 3
        np.testing.assert_allclose(j, jn, rtol=0, atol=4 * 2.0 ** -53 * scale_j)
        np.testing.assert_allclose(s, sn, rtol=0, atol=4 * 2.0 ** -53 * scale_j * 2e-5)


def double_double():
    """The compiled dd operations of numerics.dd vs its vectorised numpy ones (identical algorithms: bit for bit)."""
    from numba import njit

    @njit
    def ops(ah, al, bh, bl, c):
        s = dd.add((ah, al), (bh, bl))
        q = dd.mul((ah, al), (ah, al))
        r = dd.sqrt((ah, al))
        d = dd.div((ah, al), c)
        return s, q, r, d

    rng = np.random.default_rng(11)
    for _ in range(200):
        ah, bh = rng.uniform(1, 1e8, 2)
        al, bl = ah * 2.0 ** -60 * rng.uniform(-1, 1), bh * 2.0 ** -60 * rng.uniform(-1, 1)
        c = float(rng.uniform(1, 1e3))
        s, q, r, d = ops(ah, al, bh, bl, c)
        for got, ref in ((s, dd.np_dd_add(ah, al, bh, bl)), (q, dd.np_dd_sqr(ah, al)), (r, dd.np_dd_sqrt(ah, al)),
                         (d, dd.np_dd_div_d(ah, al, c))):
            # the two may differ in the last bits of lo (FMA two-product vs Veltkamp): 2^-104 relative
            assert abs((got[0] - ref[0]) + (got[1] - ref[1])) <= 2.0 ** -104 * abs(ref[0]), (got, ref)


MIRRORS = [
    ("kinematics-global", lambda: kinematics("global")),
    ("kinematics-taylor1", lambda: kinematics("taylor1")),
    ("kinematics-taylor2", lambda: kinematics("taylor2")),
    ("control", control),
    ("breathing-angle", breathing_angle),
    ("monopole-jerk-snap", monopole_jerk),
    ("double-double", double_double),
]


@pytest.mark.parametrize("name, check", MIRRORS, ids=[m[0] for m in MIRRORS])
def test_compiled_kernel_matches_its_numpy_mirror(name, check):
    check()


def test_the_states_are_tianqin():
    r_hi, r_lo, v, _ = _tianqin_states()
    assert math.isclose(np.linalg.norm(r_hi[0] + r_lo[0]), 1e8, rel_tol=1e-15)
    assert math.isclose(np.linalg.norm(v[0]), math.sqrt(GM / 1e8), rel_tol=1e-14)
