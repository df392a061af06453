"""The BCRS -> TT-compatible GCRS transformation of the third bodies (tqdyn.astro.geocentric).

References, all independent of the code under test:
* the unit scaling K = (1 - L_G)/(1 - L_B) from the IAU defining constants
  (IAU 2000 B1.9, IAU 2006 B3), in mpmath;
* the velocity terms (simultaneity and Lorentz contraction) against an exact
  Lorentz boost of a uniformly moving Earth, in mpmath at 40 digits: the 1PN
  formula must agree to O(v^4/c^4) ~ 1e-16 relative;
* the gravitational terms from the metric: the BCRS spatial metric is
  (1 + 2U/c^2) delta_ij, and the GCRS one must be isotropic with only the
  tidal part of U (no constant, no linear term: the geocentre falls freely),
  so the Jacobian dX/dx has the symmetric part (1 + (U(x_E) + grad U . r)/c^2) I.
"""

import mpmath as mp
import numpy as np
import pytest

from tqdyn.astro.constants import C_LIGHT
from tqdyn.astro.ephemeris import BODIES, default_ephemeris, planetary_gm
from tqdyn.astro.geocentric import TDB_TO_TT_SCALE, bcrs_to_gcrs
from tqdyn.astro.timescales import Epoch, tdb_jd
from tqdyn.forces.third_body_ephemeris import EphemerisPositions, third_bodies

EPOCH = Epoch.from_utc("2004-06-06T00:00:00")


def test_unit_scale_from_the_iau_constants():
    with mp.workdps(40):
        l_g, l_b = mp.mpf("6.969290134e-10"), mp.mpf("1.550519768e-8")  # defining constants
        k = (1 - l_g) / (1 - l_b)
        assert abs(mp.mpf(TDB_TO_TT_SCALE) - k) < mp.mpf("1.2e-16")   # float64 rounding of K (half an ulp of 1: 1.1e-16)
        assert abs((k - 1) - (l_b - l_g) / (1 - l_b)) < mp.mpf("1e-35")  # K - 1 = 1.4808269e-8


def _exact_boost(r, v_body, v_earth):
    """Position, in the rest frame of an Earth moving uniformly with v_earth
    [m/s] (at the origin at t = 0), of a body at r [m] at t = 0 moving with
    v_body (BCRS velocity), at the instant simultaneous in the Earth's frame
    with the geocentre's t = 0 event: exact special relativity (mpmath)."""
    with mp.workdps(40):
        c = mp.mpf(C_LIGHT)
        x0 = mp.matrix([mp.mpf(float(e)) for e in r])
        vb = mp.matrix([mp.mpf(float(e)) for e in v_body])
        ve = mp.matrix([mp.mpf(float(e)) for e in v_earth])
        dot = lambda a, b: sum(a[i] * b[i] for i in range(3))  # noqa: E731
        v2 = dot(ve, ve)
        gamma = 1 / mp.sqrt(1 - v2 / c ** 2)
        # t' = gamma (t - v.x/c^2) = 0 on the body's worldline x0 + vb t
        t = dot(ve, x0) / (c ** 2 - dot(ve, vb))
        x = x0 + vb * t
        xp = x + ve * ((gamma - 1) * dot(x, ve) / v2) - ve * (gamma * t)
        return np.array([float(xp[i]) for i in range(3)])


@pytest.mark.parametrize("r, v_rel", [
    # Sun- and Moon-like distances and relative speeds, r chosen far from
    # perpendicular to v_E (the terms scale with v_E . r)
    ((1.2e11, 8.3e10, 3.6e10), (1.7e4, 2.5e4, 1.1e4)),
    ((2.9e8, 2.3e8, 1.1e8), (-600.0, -700.0, -300.0)),
])
def test_velocity_terms_are_the_lorentz_boost(r, v_rel):
    v_earth = np.array([-1.9e4, -2.4e4, -1.05e4])  # |v_E| = 32.3 km/s (perihelion speed + margin)
    got = bcrs_to_gcrs(np.array([r]), np.array([v_rel]), v_earth, np.array([0.0]))[0] / TDB_TO_TT_SCALE
    want = _exact_boost(r, np.asarray(v_rel) + v_earth, v_earth)
    shift = np.linalg.norm(want - np.asarray(r))
    assert shift > 1e-9 * np.linalg.norm(r)      # the terms are there (~5e-9 of |r|)
    # 1PN truncation (v/c)^4 |r| ~ 1.4e-16 |r|, float64 rounding ~ 2e-16 |r| (measured 1.1e-16 |r|)
    assert np.linalg.norm(got - want) < 6e-16 * np.linalg.norm(r)


def test_gravity_terms_make_the_metric_isotropic_and_tidal():
    # Sun and Moon as seen from the Earth (m), their GMs; a massless probe at p
    s = np.array([[1.2e11, -8.3e10, -3.6e10], [-2.9e8, 2.3e8, 1.1e8]])
    gm = np.array([1.32712440041e20, 4.9028e12])
    p = np.array([1.7e8, 2.6e8, -0.9e8])
    h = 1e6  # X is quadratic in the probe position: central differences are exact up to rounding

    def x_of(q):
        r = np.vstack([s, q])
        out = bcrs_to_gcrs(r, np.zeros_like(r), np.zeros(3), np.append(gm, 0.0))
        return out[2] / TDB_TO_TT_SCALE

    jac = np.column_stack([(x_of(p + h * e) - x_of(p - h * e)) / (2 * h) for e in np.eye(3)])
    with mp.workdps(30):  # U(x_E) + grad U(x_E) . p, the constant and linear part of the external potential
        u0 = sum(mp.mpf(g) / mp.norm(mp.matrix(list(sk))) for g, sk in zip(gm, s))
        lin = sum(mp.mpf(g) * sum(mp.mpf(sk[i]) * p[i] for i in range(3)) / mp.norm(mp.matrix(list(sk))) ** 3
                  for g, sk in zip(gm, s))
        factor = float((u0 + lin) / mp.mpf(C_LIGHT) ** 2)
    sym = 0.5 * (jac + jac.T) - np.eye(3)
    assert factor > 5e-9                                    # U_sun/c^2 = 9.9e-9
    # rounding of X (3e8 m * 1e-16) over 2 h: 1.5e-14 (measured 4e-15)
    assert np.abs(sym - factor * np.eye(3)).max() < 5e-14


def test_provider_interpolates_the_exact_transform():
    eph = default_ephemeris()
    gm = planetary_gm()
    t = np.sort(np.random.default_rng(7).uniform(0.0, 40 * 86400.0, 3000))
    got = EphemerisPositions(eph, BODIES, True)(EPOCH, t)
    jd1, jd2 = tdb_jd(EPOCH, t)
    pos, vel = eph.geocentric_states(BODIES, jd1, jd2, velocity=True)
    _, v_earth = eph.earth_barycentric(jd1, jd2)
    want = bcrs_to_gcrs(pos, vel, v_earth, np.array([gm[b] for b in BODIES]))
    rel = np.linalg.norm(got - want, axis=-1) / np.linalg.norm(want, axis=-1)
    assert rel.max() < 1e-15      # interpolation error < 1e-19 m; float64 rounding (measured 2.2e-16)
    # the 1PN part itself, relative: 2.9e-8 (Sun, Moon) .. 1.3e-7 (Neptune, its own velocity term)
    moved = np.linalg.norm(got - pos, axis=-1) / np.linalg.norm(pos, axis=-1)
    assert 2e-8 < moved[:, :2].min() and moved[:, :2].max() < 4e-8


def test_bcrs_switch_is_the_ephemeris_difference():
    eph = default_ephemeris()
    t = np.linspace(0.0, 86400.0, 7)
    term = third_bodies(eph, ("sun", "moon"), gcrs=False)
    pos, _ = eph.geocentric_states(("sun", "moon"), *tdb_jd(EPOCH, t), velocity=False)
    assert np.array_equal(term.position(EPOCH, t), pos)
    assert term.gms == (planetary_gm()["sun"], planetary_gm()["moon"])
    g = third_bodies(eph, ("sun", "moon"))
    assert g.gms == tuple(x * TDB_TO_TT_SCALE for x in term.gms)


def test_tidal_accelerations_move_as_a_rescaled_body():
    """Without its velocity terms the transform moves a body at s to
    lambda s, lambda = K (1 + f U_sun/c^2): f = 1 from the potential, and
    for the Sun f = 3/2 (its own acceleration term (a_E . s) s - a_E s^2/2
    = U s/2 for s along a_E); its GM becomes K GM.  The Sun's and the
    Moon's point-mass accelerations at 1e5 km (direct minus indirect, every
    harmonic) must follow that, up to the velocity terms: for the Sun, v_E
    is nearly perpendicular to s (e v_E ~ 0.5 km/s); for the Moon they move
    s by up to (v_E^2/2 + v_rel v_E)/c^2 = 5.2e-9 of |s|, i.e. the
    tidal acceleration by up to ~3 x 2 x 5.2e-9 = 3.1e-8 of itself."""
    eph = default_ephemeris()
    t = np.linspace(0.0, 30 * 86400.0, 61)
    new = third_bodies(eph, ("sun", "moon"))
    old = third_bodies(eph, ("sun", "moon"), gcrs=False)
    r = np.random.default_rng(3).normal(size=(t.size, 3))
    r *= 1e8 / np.linalg.norm(r, axis=-1, keepdims=True)

    def accel(s, gm):
        d = s - r
        return gm * (d / np.linalg.norm(d, axis=-1, keepdims=True) ** 3
                     - s / np.linalg.norm(s, axis=-1, keepdims=True) ** 3)

    p_new, p_old = new.position(EPOCH, t), old.position(EPOCH, t)
    u_sun = planetary_gm()["sun"] / np.linalg.norm(p_old[:, 0], axis=-1) / C_LIGHT ** 2
    k_scale = TDB_TO_TT_SCALE
    # body, f, bound on the velocity terms relative to |a| (measured 1.1e-10, 1.6e-8)
    for k, f, bound in ((0, 1.5, 5e-10), (1, 1.0, 3.5e-8)):
        lam = (k_scale * (1.0 + f * u_sun))[:, None]
        a_old = accel(p_old[:, k], old.gms[k])
        a_new = accel(p_new[:, k], new.gms[k])
        a_scaled = accel(lam * p_old[:, k], k_scale * old.gms[k])
        size = np.linalg.norm(a_old, axis=-1)
        assert (np.linalg.norm(a_new - a_old, axis=-1) / size).min() > 5e-8   # the change: 5.2e-8 .. 8.7e-8
        assert (np.linalg.norm(a_new - a_scaled, axis=-1) / size).max() < bound


def test_earth_barycentric_field_is_the_ephemeris_acceleration():
    # Reference: the ephemeris's own Earth velocity, differentiated (central differences over +-60 s, truncation
    # ~1e-13 m/s^2).  A DE integrates the Newtonian attraction of the Sun, the Moon and the planets plus their 1PN
    # terms (~1e-8 relative, 6e-11 m/s^2), the Earth-Moon figure torques and the asteroids, so a_E must be
    # dv_E/dt to ~1e-10 m/s^2 (measured 1.6e-10 of 5.8e-3 m/s^2 over 30 days from 2004-06-06); U_ext is the
    # Sun's GM/r plus 2.2e-4 .. 2.4e-4 of it (the Moon and the planets: Jupiter ~1e-4, the Moon ~6e-5).
    from tqdyn.astro.geocentric import earth_barycentric_field

    eph = default_ephemeris()
    t = np.arange(0.0, 30 * 86400.0, 3600.0)
    jd1, jd2 = EPOCH.tdb[0] + 0 * t, EPOCH.tdb[1] + t / 86400.0
    x, v, a, u, names = earth_barycentric_field(eph, jd1, jd2)
    assert names[:2] == ("sun", "moon") and x.shape == v.shape == a.shape == (t.size, 3) and u.shape == (t.size, 1)
    _, vp = eph.earth_barycentric(jd1, jd2 + 60.0 / 86400.0)
    _, vm = eph.earth_barycentric(jd1, jd2 - 60.0 / 86400.0)
    assert np.abs(a - (vp - vm) / 120.0).max() < 8e-10
    xs = eph.sun_barycentric(jd1, jd2)[0]
    share = u[:, 0] / (planetary_gm()["sun"] / np.linalg.norm(xs - x, axis=-1)) - 1
    assert 1.5e-4 < share.min() and share.max() < 3e-4
