"""The jerks (and the monopole's snap) against derivatives of the accelerations they differentiate.

The local pointing laws need the remote satellites' jerk (omega_dot contains
jerk / c) and, for taylor2 and the iterative law, the snap.  Each jerk lives
next to its acceleration in :mod:`tqdyn.forces`:

* :func:`tqdyn.forces.central.monopole_jerk_snap` (compiled, 3-tuples) and
  :func:`tqdyn.forces.central.central_jerk_snap` (numpy) -- d/dt and d2/dt2 of
  -GM r/|r|^3 along a trajectory with r' = v, r'' = a;
* :func:`tqdyn.forces.third_body.third_body_jerk` -- d/dt of the third-body
  term of :func:`tqdyn.forces.third_body.third_body_accel` for a satellite
  moving with v and a body moving with u;
* :func:`tqdyn.forces.earth.j2_jerk_gcrs_z` -- d/dt of the zonal J2 term about
  the GCRS z axis.

Reference: the derivative of the acceleration formula itself, evaluated by
mpmath (``mpmath.diff``, 40 digits) along r(t) = r + v t (+ a t^2 / 2 for the
snap), s(t) = s + u t.  The tolerance is the float64 rounding of each
formula: a few units of 2^-53 times the largest term it adds (stated per test).
"""

import mpmath
import numpy as np
import pytest

from tqdyn.forces.central import monopole_jerk_snap
from tqdyn.forces.earth import j2_jerk_gcrs_z
from tqdyn.forces.third_body import third_body_accel, third_body_jerk

EPS = 2.0 ** -53
GM_EARTH = 3.986004415e14            # m^3/s^2 (EGM2008)
GM_MOON = 4.9028000661637961e12      # m^3/s^2 (DE431)
GM_SUN = 1.32712440041279419e20      # m^3/s^2 (DE431)
# a TianQin-like satellite (r = 1e8 m, |v| = 2 km/s) and the Moon and Sun near their geocentric distances
R_SAT = (6.1e7, -4.3e7, 6.6e7)
V_SAT = (-1.1e3, -1.4e3, 5.0e2)
MOON = ((2.9e8, 2.2e8, 9.0e7), (-6.2e2, 7.4e2, 2.9e2))
SUN = ((2.6e10, 1.33e11, 5.8e10), (-2.98e4, 5.0e3, 2.2e3))


def _mp(x):
    return [mpmath.mpf(float(c)) for c in x]


def _along(p, dp, t, ddp=None):
    """p + dp t (+ ddp t^2 / 2), mpmath 3-vector."""
    out = [p[q] + dp[q] * t for q in range(3)]
    if ddp is not None:
        out = [out[q] + ddp[q] * t * t / 2 for q in range(3)]
    return out


def _norm3(x):
    return mpmath.sqrt(sum(c * c for c in x))


def test_third_body_jerk_is_the_derivative_of_the_third_body_term():
    """The Moon's and the Sun's terms.  Rounding: the formula adds the direct
    and indirect jerks, each ~ gm |u| / |s|^3 (1.2e-9 m/s^3 for the Sun) and
    cancelling to ~1e-10: tolerance 4 eps times the larger term (measured
    0.6 and 0.9 eps)."""
    with mpmath.workdps(40):
        r0, v = _mp(R_SAT), _mp(V_SAT)
        for (s_pos, s_vel), gm in ((MOON, GM_MOON), (SUN, GM_SUN)):
            s0, u = _mp(s_pos), _mp(s_vel)

            def acc(t, q):
                r, s = _along(r0, v, t), _along(s0, u, t)
                d = [s[k] - r[k] for k in range(3)]
                return gm * (d[q] / _norm3(d) ** 3 - s[q] / _norm3(s) ** 3)

            ref = [float(mpmath.diff(lambda t: acc(t, q), 0)) for q in range(3)]
            got = third_body_jerk(gm, *R_SAT, *V_SAT, *s_pos, *s_vel)
            d = np.linalg.norm(np.subtract(s_pos, R_SAT))
            term = gm * max(np.linalg.norm(np.subtract(s_vel, V_SAT)) / d ** 3,
                            np.linalg.norm(s_vel) / np.linalg.norm(s_pos) ** 3) * 3
            err = np.abs(np.subtract(got, ref)).max()
            assert err <= 4 * EPS * term, (gm, err, term)
            # and its acceleration is the compiled third-body term (same sign and size)
            a_ref = [float(acc(0, q)) for q in range(3)]
            np.testing.assert_allclose(third_body_accel(*R_SAT, *s_pos, gm), a_ref, rtol=1e-12)


def test_j2_jerk_is_the_derivative_of_the_zonal_j2_term():
    """k = 1.5 J2 GM R^2 of EGM2008; J2 acceleration ~2.6e-7 m/s^2 at 1e8 m,
    its jerk ~ |a| |v| / r times a factor of order 1 (7.4e-12 m/s^3 here):
    tolerance 16 eps |a| |v| / r (the formula sums ~10 products of that
    size; measured 4.2 eps)."""
    k = 1.5 * 1.0826261738522227e-3 * GM_EARTH * 6378136.3 ** 2
    with mpmath.workdps(40):
        r0, v = _mp(R_SAT), _mp(V_SAT)

        def acc(t, q):
            r = _along(r0, v, t)
            r2 = sum(c * c for c in r)
            zz = r[2] * r[2] / r2
            f = -k / (r2 * r2 * mpmath.sqrt(r2))
            return f * r[q] * ((3 if q == 2 else 1) - 5 * zz)

        ref = [float(mpmath.diff(lambda t: acc(t, q), 0)) for q in range(3)]
        a_mag = float(_norm3([acc(0, q) for q in range(3)]))
    got = j2_jerk_gcrs_z(k, *R_SAT, *V_SAT)
    scale = a_mag * np.linalg.norm(V_SAT) / np.linalg.norm(R_SAT)
    assert np.abs(np.subtract(got, ref)).max() <= 16 * EPS * scale
    assert 0.5 * scale < np.linalg.norm(got) < 5 * scale


@pytest.mark.parametrize("perturbation", [0.0, 2.4e-5])
def test_monopole_jerk_and_snap_are_the_derivatives_of_the_monopole(perturbation):
    """Jerk along r' = v; snap along r'' = a with a the monopole plus a
    Moon-sized perturbation (the snap is linear in the given a).  Jerk
    ~ GM |v| / r^3 = 8e-7 m/s^3, snap ~ GM (v^2 + GM/r) / r^4; tolerance 4 eps
    (jerk) and 8 eps (snap) times those scales (measured 0.64 and 1.7 eps).
    (The numpy version :func:`central_jerk_snap` against this one: tests/test_mirrors.py.)"""
    with mpmath.workdps(40):
        r0, v = _mp(R_SAT), _mp(V_SAT)
        rn = _norm3(r0)
        a_mono = [-GM_EARTH * c / rn ** 3 for c in r0]
        a_given = [a_mono[q] + perturbation * (1, -2, 2)[q] / 3 for q in range(3)]

        def acc(t, q):
            r = _along(r0, v, t, a_given)
            return -GM_EARTH * r[q] / _norm3(r) ** 3

        jerk_ref = [float(mpmath.diff(lambda t: acc(t, q), 0, 1)) for q in range(3)]
        snap_ref = [float(mpmath.diff(lambda t: acc(t, q), 0, 2)) for q in range(3)]
        a64 = tuple(float(c) for c in a_given)
    jerk, snap = monopole_jerk_snap(R_SAT, V_SAT, a64, GM_EARTH)
    r, vv = np.linalg.norm(R_SAT), np.linalg.norm(V_SAT)
    j_scale = GM_EARTH * vv / r ** 3
    s_scale = GM_EARTH * (vv ** 2 + GM_EARTH / r) / r ** 4
    assert np.abs(np.subtract(jerk, jerk_ref)).max() <= 4 * EPS * j_scale
    assert np.abs(np.subtract(snap, snap_ref)).max() <= 8 * EPS * s_scale
    assert 0.5 < np.linalg.norm(jerk) / j_scale < 2 and 0.2 < np.linalg.norm(snap) / s_scale < 2   # the scales are the sizes


def test_moon_tidal_jerk_in_omega_dot_of_the_local_laws(default_run):
    """README (coupled dynamics, step 2): the local laws' omega_dot contains the remote satellite's jerk / c, and
    the Moon alone is 1.2e-18 rad/s^2 of it (src: "the Moon's tidal jerk, ~4e-10 m/s^3").  Along the README's
    default 10-day run (every 1000 s): the Moon's tidal jerk at the satellites (third_body_jerk with the DE421
    Moon) and the change of the compiled kernel's omega_dot when that jerk is given.  Reference: |J| / c; the
    global law does not use the jerk at all."""
    from tqdyn.astro.constants import C_LIGHT
    from tqdyn.astro.ephemeris import default_ephemeris, planetary_gm
    from tqdyn.astro.timescales import Epoch, tdb_jd
    from tqdyn.constellation._kinematics_jit import LAW_CODES, sat_kinematics
    from tqdyn.formats import trajectory as io

    status, _, err, path = default_run
    assert status == 0, err
    tr = io.read_trajectory(path)
    sl = slice(0, None, 20)
    t_hi, t_lo = (x[sl] for x in tr.dd("t"))
    jd1, jd2 = tdb_jd(Epoch.from_utc(tr.attrs["epoch_utc"]), t_hi, t_lo)
    moon, moon_v = default_ephemeris().geocentric_states(("moon",), jd1, jd2)
    gm = planetary_gm()["moon"]
    r_hi, r_lo = (x[sl] for x in tr.dd("sat/r"))
    v = tr["sat/v"][sl]
    a = (tr["sat/a_gravity"] + tr["sat/a_dragfree"])[sl]
    j_max = 0.0
    d_wd = dict.fromkeys(("global", "taylor1", "taylor2", "iterative"), 0.0)
    for n in range(t_hi.size):
        J = np.array([third_body_jerk(gm, *(r_hi[n, i] + r_lo[n, i]), *v[n, i], *moon[n, 0], *moon_v[n, 0])
                      for i in range(3)])
        j_max = max(j_max, np.linalg.norm(J, axis=1).max())
        for law in d_wd:
            wd = []
            for jerk in (np.zeros((3, 3)), J):
                out = [np.zeros((3, 3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))]
                sat_kinematics(LAW_CODES[law], r_hi[n], r_lo[n], v[n], a[n], jerk, GM_EARTH, C_LIGHT, *out)
                wd.append(out[2])
            d_wd[law] = max(d_wd[law], np.abs(wd[1] - wd[0]).max())
    print(f"\nMoon tidal jerk over 10 days: max {j_max:.2e} m/s^3 (/c {j_max / C_LIGHT:.2e}); change of omega_dot "
          + ", ".join(f"{k} {x:.2e}" for k, x in d_wd.items()) + " rad/s^2")
    # measured 4.9e-10 m/s^3 (quoted ~4e-10) and 2.16e-18 rad/s^2 for the three local laws (quoted 1.2e-18): 3x
    assert 1.3e-10 < j_max < 1.2e-9
    for law in ("taylor1", "taylor2", "iterative"):
        assert 4e-19 < d_wd[law] < 3.6e-18, (law, d_wd[law])
        assert 0.3 < d_wd[law] / (j_max / C_LIGHT) < 3
    assert d_wd["global"] == 0.0
