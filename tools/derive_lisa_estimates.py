"""Derive the first-order estimates of docs/lisa-coupled.md with sympy and check every step.

    python tools/derive_lisa_estimates.py          # ~1 min on one core

1. The Keplerian LISA design (lisaorbits' KeplerianOrbits: e, i and the tilt
   pi/3 + 5/8 alpha as expansions in alpha = L / (2 a); tqdyn's
   :mod:`tqdyn.astro.constellation_design`) expanded to second order in alpha
   (units a = 1, n = 1, GM = 1; tau = n t, the mean anomaly of satellite 1).
2. The arm unit vectors u = D / |D| to first order; check |D1| = 2 (L = 2
   alpha a: equal arms at first order).
3. g = T(r_1) u - u'' (the bracket of eq:TMforce per unit d for a TM on its
   optical axis, pivot at the CoM): check that its zeroth order vanishes,
   print its first order in OA_l.
4. G and A of the LISA drag-free scheme (Cramer's rule) from g at first
   order with the zeroth-order geometry; their Fourier coefficients, printed
   as exact fractions (and compared with tqdyn.constellation.estimates.kepler_control).
5. Numerical check: the exact identity on the exact two-body orbits of the
   design (Kepler's equation solved to round-off) for alpha = 1e-3 .. 1e-1:
   max |G| / (alpha n^2 d) -> 4.1204 with an O(alpha) difference.
6. The Clohessy-Wiltshire response to a constant push along X_S, Y_S, Z_S
   of a cartwheel satellite at phase phi (convolution with the CW
   state-transition matrix); check that the closed forms solve the CW
   equations with a zero initial state.

Units: a = 1, n = 1 in the symbolic part; SI in the numerical check
(L, a in m, GM in m^3/s^2).  Frames: ecliptic (x, y in the ecliptic) for the
design, S / OA_l as in tqdyn for the control, the Hill frame (x radial,
y along-track, z normal) for the CW part.
"""

from __future__ import annotations

import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import sympy as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

al, tau = sp.symbols("alpha tau", real=True)
DELTA = sp.Rational(5, 8)


def trunc(x, order):
    return sp.series(sp.expand(x), al, 0, order + 1).removeO()


def design_positions():
    """Positions of the three satellites to O(alpha^2), ecliptic, a = 1 (lisaorbits' formulas)."""
    # e = sqrt(1 + 4 alpha cos(nu) / sqrt(3) + 4 alpha^2 / 3) - 1, tan i = alpha sin(nu) / (sqrt(3)/2 + alpha cos(nu)),
    # nu = pi/3 + delta alpha, to second order:
    nu = sp.pi / 3 + DELTA * al
    ecc = trunc(sp.sqrt(1 + 4 * al * sp.cos(nu) / sp.sqrt(3) + 4 * al ** 2 / 3) - 1, 2)
    inc = trunc(sp.atan(al * sp.sin(nu) / (sp.sqrt(3) / 2 + al * sp.cos(nu))), 2)
    print("  e =", sp.simplify(ecc), "  i =", sp.simplify(inc))
    out = []
    for k in (1, 2, 3):
        th = 2 * sp.pi * (k - 1) / 3
        M = -th + tau
        E = M + ecc * sp.sin(M) + ecc ** 2 / 2 * sp.sin(2 * M)
        cE, sE = trunc(sp.cos(E), 2), trunc(sp.sin(E), 2)
        p = sp.Matrix([(1 - inc ** 2 / 2) * (cE - ecc), sp.sqrt(1 - ecc ** 2) * sE, -inc * (cE - ecc)])
        p = p.applyfunc(lambda x: trunc(x, 2))
        Rz = sp.Matrix([[sp.cos(th), -sp.sin(th), 0], [sp.sin(th), sp.cos(th), 0], [0, 0, 1]])
        out.append((Rz * p).applyfunc(lambda x: sp.simplify(trunc(x, 2))))
    return out


def coeff(v, k):
    return v.applyfunc(lambda x: sp.simplify(sp.expand(x).coeff(al, k)))


def first_order_control(r):
    R0, R1 = coeff(r[0], 0), coeff(r[0], 1)
    arms = {}
    for name, far in (("ik", 2), ("ij", 1)):  # MOSA 1 faces k, MOSA 2 faces j (satellite 1: j = 2, k = 3)
        D = r[far] - r[0]
        D1, D2 = coeff(D, 1), coeff(D, 2)
        n1 = sp.simplify(sp.sqrt(sp.trigsimp(D1.dot(D1))))
        assert n1 == 2, n1
        u0 = (D1 / n1).applyfunc(sp.simplify)
        u1 = ((D2 - u0 * u0.dot(D2)) / n1).applyfunc(sp.simplify)
        arms[name] = (u0, u1)
    print("  |D1| = 2 for both arms: equal arms L = 2 alpha a at first order")
    rr = R0 + al * R1
    rn2 = sp.expand(rr.dot(rr))
    T = (3 * rr * rr.T - rn2 * sp.eye(3)) * rn2 ** sp.Rational(-5, 2)
    T0 = T.applyfunc(lambda x: sp.simplify(x.subs(al, 0)))
    T1 = T.applyfunc(lambda x: sp.simplify(sp.diff(x, al).subs(al, 0)))
    g1 = {}
    for name, (u0, u1) in arms.items():
        lead = (T0 * u0 - u0.diff(tau, 2)).applyfunc(sp.simplify)
        assert lead == sp.zeros(3, 1), lead
        g1[name] = (T0 * u1 + T1 * u0 - u1.diff(tau, 2)).applyfunc(lambda x: sp.simplify(sp.expand_trig(x)))
    print("  zeroth order of T u - u'' vanishes for both arms (every point of the turning plane is a free CW orbit)")
    return arms, g1


def fourier(values, ts):
    """Fourier series (cos, sin up to 8 tau) of samples on a uniform grid over one period, as fractions."""
    c = np.fft.rfft(values) / values.size
    s3 = np.sqrt(3.0)
    terms = []
    for h in range(9):
        re, im = 2 * c[h].real, -2 * c[h].imag
        if h == 0:
            re /= 2
        for val, fn in ((re, "cos"), (im, "sin")):
            if abs(val) < 1e-9:
                continue
            f1, f2 = Fraction(val).limit_denominator(512), Fraction(val / s3).limit_denominator(512)
            txt = str(f1) if abs(float(f1) - val) < 1e-9 else (f"{f2} sqrt3" if abs(float(f2) * s3 - val) < 1e-9
                                                               else f"{val:.9f}")
            terms.append(txt if h == 0 else f"{txt} {fn}({h} tau)")
    return " + ".join(terms) or "0"


def scheme(e1, e2, g1, g2):
    n = np.cross(e2, e1)
    n /= np.linalg.norm(n, axis=-1)[:, None]
    X = e1 + e2
    X /= np.linalg.norm(X, axis=-1)[:, None]
    Y = np.cross(n, X)
    det = np.sum(e1 * np.cross(e2, n), 1)[:, None]
    G = (np.sum(e1 * g1, 1)[:, None] * np.cross(e2, n) + np.sum(e2 * g2, 1)[:, None] * np.cross(n, e1)
         + 0.5 * np.sum(n * (g1 + g2), 1)[:, None] * np.cross(e1, e2)) / det

    def oa(a, e):
        return np.stack([np.sum(a * e, 1), np.sum(a * np.cross(n, e), 1), np.sum(a * n, 1)], 1)

    return (np.stack([np.sum(G * X, 1), np.sum(G * Y, 1), np.sum(G * n, 1)], 1), oa(G - g1, e1), oa(G - g2, e2),
            oa(g1, e1), oa(g2, e2))


def kepler_states(alpha, t, gm=1.0, a=1.0):
    """Exact two-body states of the design (numpy; lisaorbits' elements), ecliptic: R, V, A (N, 3, 3)."""
    nu = np.pi / 3 + 0.625 * alpha
    e = np.sqrt(1 + 4 * alpha * np.cos(nu) / np.sqrt(3) + 4 * alpha ** 2 / 3) - 1
    inc = np.arctan(alpha * np.sin(nu) / (np.sqrt(3) / 2 + alpha * np.cos(nu)))
    n = np.sqrt(gm / a ** 3)
    R, V = np.zeros((t.size, 3, 3)), np.zeros((t.size, 3, 3))
    for k in range(3):
        th = 2 * np.pi * k / 3
        M = n * t - th
        E = M.copy()
        for _ in range(50):
            E = E - (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
        Ed = n / (1 - e * np.cos(E))
        p = np.stack([a * np.cos(inc) * (np.cos(E) - e), a * np.sqrt(1 - e * e) * np.sin(E),
                      -a * np.sin(inc) * (np.cos(E) - e)], -1)
        pd = np.stack([-a * np.cos(inc) * np.sin(E) * Ed, a * np.sqrt(1 - e * e) * np.cos(E) * Ed,
                       a * np.sin(inc) * np.sin(E) * Ed], -1)
        Rz = np.array([[np.cos(th), -np.sin(th), 0], [np.sin(th), np.cos(th), 0], [0, 0, 1]])
        R[:, k], V[:, k] = p @ Rz.T, pd @ Rz.T
    A = -gm * R / np.linalg.norm(R, axis=-1, keepdims=True) ** 3
    return R, V, A


def cw_part():
    t, s, n, ph = sp.symbols("t s n phi", positive=True)

    def phi_m(tt):
        c, si = sp.cos(n * tt), sp.sin(n * tt)
        return sp.Matrix([[4 - 3 * c, 0, 0, si / n, 2 * (1 - c) / n, 0],
                          [6 * (si - n * tt), 1, 0, -2 * (1 - c) / n, (4 * si - 3 * n * tt) / n, 0],
                          [0, 0, c, 0, 0, si / n],
                          [3 * n * si, 0, 0, c, 2 * si, 0],
                          [-6 * n * (1 - c), 0, 0, -2 * si, 4 * c - 3, 0],
                          [0, 0, -n * si, 0, 0, c]])

    Acw = sp.Matrix([[0, 0, 0, 1, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1], [3 * n ** 2, 0, 0, 0, 2 * n, 0],
                     [0, 0, 0, -2 * n, 0, 0], [0, 0, -n ** 2, 0, 0, 0]])
    assert sp.simplify(phi_m(t).diff(t) - Acw * phi_m(t)) == sp.zeros(6, 6)
    print("  the CW state-transition matrix solves the CW equations")
    u0 = sp.Matrix([sp.Rational(1, 2), 0, sp.sqrt(3) / 2])
    w0 = sp.Matrix([0, -1, 0])
    N = u0.cross(w0)
    for lab, (cx, cy, cz) in {"x": (1, 0, 0), "y": (0, 1, 0), "z": (0, 0, 1)}.items():
        rho = sp.cos(n * s + ph) * u0 + sp.sin(n * s + ph) * w0
        XS, ZS = -rho, -N
        f = cx * XS + cy * ZS.cross(XS) + cz * ZS
        B = sp.Matrix([0, 0, 0, *f])
        integrand = (phi_m(t - s) * B).applyfunc(lambda e: sp.expand(sp.expand_trig(sp.expand(e))))
        sol = integrand.applyfunc(lambda e: sp.simplify(sp.integrate(e, (s, 0, t)).rewrite(sp.cos)))
        disp = [sp.simplify(sp.piecewise_fold(x).args[0][0] if isinstance(x, sp.Piecewise) else x) for x in sol[:3]]
        x_, y_, z_ = disp
        f_t = f.subs(s, t)
        eqs = [sp.diff(x_, t, 2) - 3 * n ** 2 * x_ - 2 * n * sp.diff(y_, t) - f_t[0],
               sp.diff(y_, t, 2) + 2 * n * sp.diff(x_, t) - f_t[1], sp.diff(z_, t, 2) + n ** 2 * z_ - f_t[2]]
        assert all(sp.simplify(sp.expand_trig(e)) == 0 for e in eqs)
        assert all(sp.simplify(x.subs(t, 0)) == 0 and sp.simplify(sp.diff(x, t).subs(t, 0)) == 0 for x in disp)
        print(f"  push along {lab}_S, per unit f: x, y, z =", [sp.simplify(x) for x in disp])
        from tqdyn.constellation.estimates import cartwheel_sg_displacement

        fn = sp.lambdify((t, n, ph), disp, "numpy")
        tt = np.linspace(0.0, 4e7, 101)
        for phase in (0.3, 2.0, -1.2):
            ref = np.stack(np.broadcast_arrays(*fn(tt, 2e-7, phase)), -1)
            got = cartwheel_sg_displacement(lab, 1.0, 2e-7, tt, phase)[0]
            assert np.allclose(got, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max()), lab
    print("  each solves the CW equations from a zero state; tqdyn.constellation.estimates.cartwheel_sg_displacement "
          "agrees")


def main():
    t0 = time.perf_counter()
    print("1. the Keplerian design to O(alpha^2)")
    r = design_positions()
    print("2, 3. arms and g = T u - u''")
    arms, g1 = first_order_control(r)
    print("4. G and A of the LISA scheme, first order, unit alpha n^2 d")
    f = sp.lambdify(tau, [arms["ik"][0], arms["ij"][0], g1["ik"], g1["ij"]], "numpy")
    ts = np.linspace(0, 2 * np.pi, 4097)[:-1]
    vals = [f(x) for x in ts]
    E1, E2, G1, G2 = (np.array([np.array(v[k], float).ravel() for v in vals]) for k in range(4))
    GS, A1, A2, g1o, g2o = scheme(E1, E2, G1, G2)
    for name, arr in (("G_S", GS), ("A_1 (OA_1)", A1), ("A_2 (OA_2)", A2), ("g_1 (OA_1)", g1o), ("g_2 (OA_2)", g2o)):
        for q, comp in enumerate("xyz"):
            print(f"  {name} {comp}: {fourier(arr[:, q], ts)}")
    from tqdyn.constellation.estimates import kepler_control

    g_m, G_m, A_m = kepler_control(ts)
    assert np.allclose(G_m, GS, atol=1e-12) and np.allclose(A_m[:, 0], A1, atol=1e-12) \
        and np.allclose(A_m[:, 1], A2, atol=1e-12) and np.allclose(g_m[:, 0], g1o, atol=1e-12)
    fine = np.linspace(0, 2 * np.pi, 400001)
    _, Gf, Af = kepler_control(fine)
    print(f"  max |G| = {np.linalg.norm(Gf, axis=-1).max():.9f}, max |A component| = {np.abs(Af).max():.9f} "
          "(alpha n^2 d); tqdyn.constellation.estimates.kepler_control agrees to 1e-12")
    print("5. the exact identity on the exact two-body design: max |G| / (alpha n^2 d)")
    from tqdyn.constellation.estimates import arm_identity_control

    for alpha in (1e-3, 3e-3, 8.3557e-3, 1e-2, 3e-2, 1e-1):
        t = np.linspace(0, 2 * np.pi, 2001)
        R, V, A = kepler_states(alpha, t)
        G, Asus = arm_identity_control(R, V, A, gm=1.0, d=1.0)
        print(f"  alpha = {alpha:.4g}: |G| {np.linalg.norm(G, axis=-1).max() / alpha:.5f}, "
              f"A {np.abs(Asus).max() / alpha:.5f}")
    print("6. Clohessy-Wiltshire response to a common push along the axes of S")
    cw_part()
    print(f"done in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
