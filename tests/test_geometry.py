"""Tests of tqdyn.constellation.indices and tqdyn.constellation.geometry.

References: (1) finite differences of the same functions along a real 1-day
TianQin (Kepler) trajectory on its 50 s grid, with tolerances derived from
the step (truncation) and from float64 round-off; (2) an equilateral
triangle rotating rigidly on a circle in an inclined plane (analytic values);
(3) the angle sum of a triangle (pi).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from tqdyn.constellation import geometry as G
from tqdyn.constellation.indices import (
    LINK_OF_MOSA,
    LINKS,
    MOSA_OF_LINK,
    Link,
    Mosa,
    Sat,
)

GM = 3.986004418e14
A_ORBIT = 1.0e8  # TianQin semi-major axis [m]
N_ORB = math.sqrt(GM / A_ORBIT ** 3)  # mean motion ~2.0e-5 rad/s
H = 50.0  # grid step [s]


# ---------------------------------------------------------------- indices

def test_indices_even_permutations_and_links():
    # reference: the even permutations of (1, 2, 3) and the LISA link order, written out
    assert [(int(s), int(s.j), int(s.k)) for s in Sat] == [(1, 2, 3), (2, 3, 1), (3, 1, 2)]
    assert [int(ln) for ln in LINKS] == [12, 23, 31, 13, 32, 21]
    assert [ln.index for ln in LINKS] == list(range(6))
    for ln in Link:
        assert ln.receiver != ln.emitter
        assert ln.local is ln.receiver and ln.distant is ln.emitter
        assert ln.reverse.reverse is ln
        assert ln.mosa.remote(ln.receiver) is ln.emitter
        s, m = MOSA_OF_LINK[ln.index]
        assert LINK_OF_MOSA[s, m] == ln.index
    for s in Sat:
        assert Mosa.OA1.remote(s) is s.k and Mosa.OA2.remote(s) is s.j
        assert s.mosa_facing(s.k) is Mosa.OA1 and s.mosa_facing(s.j) is Mosa.OA2
        with pytest.raises(ValueError):
            s.mosa_facing(s)
    assert Mosa.OA1.sign == 1 and Mosa.OA2.sign == -1 and Mosa.OA1.other is Mosa.OA2


# ---------------------------------------------------------------- real trajectory

@pytest.fixture(scope="module")
def trajectory():
    from tqdyn import dynamics
    from tqdyn.scenario import load_scenario

    blocks = []
    dynamics.propagate(load_scenario("tianqin-kepler", ["run.duration=1d"]), sink=blocks.append)
    rows = dynamics.Rows.concatenate(blocks)
    assert np.all(np.diff(rows.t[0]) == H)
    return rows.t, rows.sat_r, rows.sat_v, rows.sat_a_gravity


def _fd1(f):
    """4th-order central first derivative on the grid (interior points 2..N-3);
    truncation h^4/30 max|f^(5)|, round-off <= (18/12) eps / h."""
    return (8.0 * (f[3:-1] - f[1:-3]) - (f[4:] - f[:-4])) / (12.0 * H)


def _fd2(f):
    """4th-order central second derivative; truncation h^4/90 max|f^(6)|,
    round-off <= (64/12) eps / h^2."""
    return (-f[4:] + 16.0 * f[3:-1] - 30.0 * f[2:-2] + 16.0 * f[1:-3] - f[:-4]) / (12.0 * H * H)


def _tol(scale, eps, order):
    """Bound of |FD - exact| for a quantity of size ``scale`` varying at the
    orbital rate (|f^(k)| <= scale (2 n)^k, factor 2 for the eccentricity
    and the breathing) and evaluated with absolute error ``eps``."""
    w = 2.0 * N_ORB
    if order == 1:
        return H ** 4 / 30.0 * scale * w ** 5 + 1.5 * eps / H
    return H ** 4 / 90.0 * scale * w ** 6 + 64.0 / 12.0 * eps / H ** 2


def test_derivatives_vs_finite_differences(trajectory):
    t, R, V, A = trajectory
    g = G.constellation_geometry(R, V, A)
    a = g.arms
    L = 1.7e8
    eps_n = 1e-15  # float64 unit vectors from 1.7e8 m arms: a few ulp
    checks = [
        ("n", a.n, a.n_dot, a.n_ddot, 1.0, eps_n),
        ("L [m]", a.length, a.length_dot, a.length_ddot, L, 1e-15 * L),
        ("alpha [rad]", g.alpha, g.alpha_dot, g.alpha_ddot, 1.0, 4e-15),
        ("incenter offset [m]", g.incenter.offset, g.incenter.offset_dot, g.incenter.offset_ddot,
         1e8, 1e-15 * 1e8),
    ]
    for name, f, fd, fdd, scale, eps in checks:
        e1 = np.max(np.abs(_fd1(f) - fd[2:-2]))
        e2 = np.max(np.abs(_fd2(f) - fdd[2:-2]))
        t1, t2 = _tol(scale, eps, 1), _tol(scale, eps, 2)
        print(f"{name}: |d/dt - FD| max {e1:.2e} (tol {t1:.2e}, rate scale {np.max(np.abs(fd)):.2e}); "
              f"|d2/dt2 - FD| max {e2:.2e} (tol {t2:.2e}, scale {np.max(np.abs(fdd)):.2e})")
        assert e1 < t1, name
        assert e2 < t2, name
    # incenter velocity / acceleration: offsets of satellite 1 plus its own motion
    v1 = V[0][:, 0] + V[1][:, 0]
    assert np.allclose(g.incenter.velocity, v1 + g.incenter.offset_dot[:, 0], rtol=0, atol=1e-12)
    # the printed |r_ij|-dot notation is the arm-length rate, not |r_ij dot|: check the difference is real
    assert np.max(np.abs(np.linalg.norm(a.r_dot, axis=-1) - np.abs(a.length_dot))) > 1.0  # m/s


@mpmath.workdps(40)
def test_angles_sum_to_pi_and_dd_arms(trajectory):
    t, R, V, A = trajectory
    g = G.constellation_geometry(R)
    err = np.max(np.abs(g.alpha.sum(axis=-1) - math.pi))
    print(f"|sum alpha - pi| max {err:.1e} rad; alpha range [{np.degrees(g.alpha.min()):.5f}, "
          f"{np.degrees(g.alpha.max()):.5f}] deg")
    assert err < 1e-14
    # arm vectors from dd positions vs from positions rounded to float64 first: differ by ~ulp(1e8 m)
    a_dd = G.arms(R).r
    a_64 = G.arms(R[0] + R[1]).r
    assert np.max(np.abs(a_dd - a_64)) < 1e-7
    # dd arm vector against mpmath on a few samples
    import mpmath
    for n in (0, 700, 1700):
        for ln in LINKS:
            e, r = ln.emitter.index, ln.receiver.index
            for q in range(3):
                exact = (mpmath.mpf(R[0][n, e, q]) + mpmath.mpf(R[1][n, e, q])
                         - mpmath.mpf(R[0][n, r, q]) - mpmath.mpf(R[1][n, r, q]))
                assert abs(a_dd[n, ln.index, q] - exact) <= 2.0 ** -52 * abs(exact) + 1e-300
    # incenter position in dd is the exact incenter to ~1e-8 m (mpmath)
    inc = G.incenter(R, G.arms(R))
    n = 900
    P = [[mpmath.mpf(R[0][n, s, q]) + mpmath.mpf(R[1][n, s, q]) for q in range(3)] for s in range(3)]
    d = lambda x, y: mpmath.sqrt(sum((x[q] - y[q]) ** 2 for q in range(3)))
    w = [d(P[1], P[2]), d(P[2], P[0]), d(P[0], P[1])]
    for q in range(3):
        exact = sum(w[s] * P[s][q] for s in range(3)) / sum(w)
        got = mpmath.mpf(inc.position[n, q, 0]) + mpmath.mpf(inc.position[n, q, 1])
        assert abs(got - exact) < 1e-7  # m: float64 offset of ~1e8 m


def _rigid_equilateral(times, rho=1e8, omega=2e-5, incl=0.7, raan=1.1):
    """Equilateral triangle on a circle of radius rho, rotating rigidly at omega
    in a plane with inclination incl and node raan.  Returns R, V, A (N, 3, 3),
    the plane's unit normal e3 and omega."""
    e1 = np.array([math.cos(raan), math.sin(raan), 0.0])
    e2 = np.array([-math.sin(raan) * math.cos(incl), math.cos(raan) * math.cos(incl), math.sin(incl)])
    e3 = np.cross(e1, e2)
    phi = omega * times[:, None] + 2.0 * math.pi / 3.0 * np.arange(3)[None, :]
    c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
    R = rho * (c * e1 + s * e2)
    V = rho * omega * (-s * e1 + c * e2)
    A = -omega ** 2 * R
    return R, V, A, e3, omega


def test_rigid_equilateral_analytic():
    # reference: rigid rotation -> L = sqrt(3) rho, L' = L'' = 0, n' = w e3 x n,
    # n'' = -w^2 n, alpha = pi/3, alpha' = alpha'' = 0, incenter at the origin.
    rho = 1e8
    R, V, A, e3, w = _rigid_equilateral(np.linspace(0.0, 3e5, 37), rho=rho)
    g = G.constellation_geometry(R, V, A)
    a = g.arms
    assert np.max(np.abs(a.length - math.sqrt(3.0) * rho)) < 1e-15 * 4 * rho
    assert np.max(np.abs(a.length_dot)) < 1e-15 * 4 * rho * w
    assert np.max(np.abs(a.length_ddot)) < 1e-15 * 8 * rho * w * w
    assert np.max(np.abs(a.n_dot - w * np.cross(e3, a.n))) < 1e-15 * 4 * w
    assert np.max(np.abs(a.n_ddot + w * w * a.n)) < 1e-15 * 8 * w * w
    assert np.max(np.abs(g.alpha - math.pi / 3.0)) < 1e-14
    assert np.max(np.abs(g.alpha_dot)) < 1e-14 * w
    assert np.max(np.abs(g.alpha_ddot)) < 1e-14 * w * w
    inc = g.incenter
    assert np.max(np.abs(inc.position)) < 1e-15 * 8 * rho
    assert np.max(np.abs(inc.offset + R)) < 1e-15 * 8 * rho
    assert np.max(np.abs(inc.offset_dot + V)) < 1e-15 * 8 * rho * w
    assert np.max(np.abs(inc.offset_ddot + A)) < 1e-15 * 8 * rho * w * w
    assert np.max(np.abs(inc.velocity)) < 1e-15 * 8 * rho * w
    assert np.max(np.abs(inc.acceleration)) < 1e-15 * 8 * rho * w * w


def test_by_mosa_layout():
    # reference: the MOSA convention (MOSA 1 <- k, MOSA 2 <- j) written out link by link
    x = np.arange(6 * 3, dtype=float).reshape(6, 3)
    y = G.by_mosa(x)
    assert y.shape == (3, 2, 3)
    for s in Sat:
        assert np.array_equal(y[s.index, 0], x[Link(10 * s + s.k).index])
        assert np.array_equal(y[s.index, 1], x[Link(10 * s + s.j).index])
    assert G.by_mosa(np.arange(6.0), axis=-1).shape == (3, 2)


@mpmath.workdps(40)
def test_second_derivatives_vs_mpmath_finite_differences(trajectory):
    """The float64 FD above is round-off limited for the tiny alpha'' (~1e-21
    rad/s^2 on a Kepler orbit).  Reference here: alpha and L evaluated in
    mpmath (40 digits) from the dd positions on a 5-point stencil, so only the
    truncation h^4/90 |f^(6)| (<= amp (2n)^6 h^4/90: ~3e-26 rad/s^2 for alpha
    with amp 1e-3 rad, ~3e-21 m/s^2 for L with amp 1e5 m) and the float64
    round-off of the analytic formula remain (~1e-25 rad/s^2, ~7e-17 m/s^2)."""
    import mpmath

    t, R, V, A = trajectory
    g = G.constellation_geometry(R, V, A)

    def pos(n, s):
        return [mpmath.mpf(R[0][n, s, q]) + mpmath.mpf(R[1][n, s, q]) for q in range(3)]

    def geo(n):
        P = [pos(n, s) for s in range(3)]
        out_L, out_alpha = [], []
        for s in Sat:
            i, j, k = P[s.index], P[s.j.index], P[s.k.index]
            rij = [j[q] - i[q] for q in range(3)]
            rik = [k[q] - i[q] for q in range(3)]
            lij = mpmath.sqrt(sum(x * x for x in rij))
            lik = mpmath.sqrt(sum(x * x for x in rik))
            out_L.append(lij)
            out_alpha.append(mpmath.acos(sum(a * b for a, b in zip(rij, rik)) / (lij * lik)))
        return out_L, out_alpha

    w = 2.0 * N_ORB
    tol_alpha = 1e-3 * w ** 6 * H ** 4 / 90.0 + 1e-25
    # L'' = r'' . n + r' . n': terms ~0.04 m/s^2 (differences of float64 accelerations, and
    # |r'| |n'| ~ 2e3 * 2e-5) cancel to ~1e-9: round-off ~8 ulp(0.04) = 8 * 2^-52 * 0.04
    tol_L = 1e5 * w ** 6 * H ** 4 / 90.0 + 8 * 2.0 ** -52 * 0.04
    worst_a = worst_L = 0.0
    for n in (100, 900, 1600):
        vals = [geo(n + m) for m in (-2, -1, 0, 1, 2)]
        for s in range(3):
            fa = [v[1][s] for v in vals]
            fl = [v[0][s] for v in vals]
            d2a = (-fa[0] + 16 * fa[1] - 30 * fa[2] + 16 * fa[3] - fa[4]) / (12 * H * H)
            d2l = (-fl[0] + 16 * fl[1] - 30 * fl[2] + 16 * fl[3] - fl[4]) / (12 * H * H)
            worst_a = max(worst_a, float(abs(d2a - g.alpha_ddot[n, s])))
            link = Link(10 * (s + 1) + Sat(s + 1).j).index
            worst_L = max(worst_L, float(abs(d2l - g.arms.length_ddot[n, link])))
    print(f"alpha'' vs mpmath FD: {worst_a:.2e} rad/s^2 (tol {tol_alpha:.1e}, alpha'' ~ "
          f"{np.max(np.abs(g.alpha_ddot)):.1e}); L'' vs mpmath FD: {worst_L:.2e} m/s^2 (tol {tol_L:.1e})")
    assert worst_a < tol_alpha
    assert worst_L < tol_L


def test_centroid_directions_exact_and_free_of_cancellation():
    # Reference: exact rational arithmetic (fractions) of (R_1 + R_2 + R_3)/3 - R_i for a LISA-sized triangle
    # 1 au from the origin, given in dd (hi, lo): the arm vectors of the dd pair keep the direction to round-off
    # (measured 1.1e-16; the same positions rounded to float64 first: 3.0e-15).
    from fractions import Fraction

    rng = np.random.default_rng(7)
    tri = 2.5e9 / math.sqrt(3) * np.array([[math.cos(a), math.sin(a), 0.3 * math.sin(2 * a)]
                                           for a in (0.1, 2.2, 4.3)])
    hi = 1.496e11 * np.array([0.6, 0.8, 0.0]) + tri + rng.uniform(-1e3, 1e3, (3, 3))
    lo = rng.uniform(-0.5, 0.5, (3, 3)) * np.spacing(hi)
    u = G.centroid_directions((hi[None], lo[None]))[0]
    exact = [[Fraction(float(hi[i, k])) + Fraction(float(lo[i, k])) for k in range(3)] for i in range(3)]
    for i in range(3):
        c = [sum(exact[j][k] for j in range(3)) / 3 - exact[i][k] for k in range(3)]
        norm = math.sqrt(float(sum(x * x for x in c)))
        assert np.abs(u[i] - [float(x) / norm for x in c]).max() < 1e-15
    # the equilateral triangle: centroid and incenter coincide
    eq = np.array([[math.cos(a), math.sin(a), 0.0] for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]) * 1e8
    inc = G.incenter(eq, G.arms(eq)).offset
    assert np.abs(G.centroid_directions(eq) - inc / np.linalg.norm(inc, axis=-1, keepdims=True)).max() < 1e-15
