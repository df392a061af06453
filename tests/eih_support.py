"""The Einstein-Infeld-Hoffmann (EIH) 1PN n-body acceleration in numpy, and the DE421 states it needs: the
independent reference of the relativistic n-body terms (tests/test_heliocentric.py, tests/test_eih.py), and
the same equations transformed to the GCRS by brute force (:func:`gcrs_reference`).

Nothing here comes from tqdyn: the bodies' barycentric states are read from the shipped DE421 file directly
with ``jplephem`` (SPK segments 0->10 Sun, 0->3 + 3->399 Earth, 0->3 + 3->301 Moon, 0->k system barycentres),
the GMs are the decimals of ``tqdyn/data/gm_de431.tpc`` (NAIF's DE430/DE431 GM kernel, km^3/s^2) parsed here
with a regular expression, and the EIH equations are written from Standish & Williams, "Orbital ephemerides of
the Sun, Moon, and planets", Explanatory Supplement ch. 8, eq. 8.1 and Park et al. 2021, AJ 161, 105, eq. 1.
:func:`eih_1pn` is checked in tests/test_heliocentric.py against its static Sun-only limit (the Schwarzschild
term), the first-order Lorentz boost of that limit, and DE421's own acceleration of Mercury.
"""

from __future__ import annotations

import atexit
import importlib.resources
import re

import mpmath
import numpy as np
from jplephem.spk import SPK
from mpmath import mpf

from tqdyn.astro.ephemeris import default_ephemeris_path

C = 299792458.0  # m/s
NAIF = {"sun": 10, "mercury": 1, "venus": 2, "earth": 399, "moon": 301, "mars": 4, "jupiter": 5, "saturn": 6,
        "uranus": 7, "neptune": 8}
#: The ten point masses of the JPL ephemerides' EIH equations here (planets as systems at their barycentres).
EIH_BODIES = ("sun", "mercury", "venus", "earth", "moon", "mars", "jupiter", "saturn", "uranus", "neptune")

_SPK = None


def spk():
    """The shipped DE421 file opened with jplephem (once; closed at exit)."""
    global _SPK
    if _SPK is None:
        _SPK = SPK.open(default_ephemeris_path())
        atexit.register(_SPK.close)
    return _SPK


def gm_decimals() -> dict[int, str]:
    """{NAIF id: the file's GM decimal [km^3/s^2]} of tqdyn/data/gm_de431.tpc."""
    text = (importlib.resources.files("tqdyn") / "data" / "gm_de431.tpc").read_text(encoding="ascii")
    return {int(k): v for k, v in re.findall(r"BODY(\d+)_GM\s*=\s*\(\s*([-+0-9.E]+)\s*\)", text)}


def gm_mp(name: str) -> mpf:
    """GM [m^3/s^2] of a body as the exact file decimal (call inside mpmath.workdps)."""
    return mpf(gm_decimals()[NAIF[name]]) * 10**9


def gm_f(name: str) -> float:
    """GM [m^3/s^2] of a body, float64."""
    return float(mpf(gm_decimals()[NAIF[name]]) * 10**9)


def segments(name: str):
    """The DE421 SPK segments (center, target) whose sum is the body's barycentric state."""
    return {"sun": ((0, 10),), "earth": ((0, 3), (3, 399)), "moon": ((0, 3), (3, 301))}.get(name, ((0, NAIF[name]),))


def bary_states(names, j1, j2):
    """Barycentric positions [m] and velocities [m/s] (n_body, 3, N) from DE421 via jplephem (numpy), at the
    two-part TDB Julian dates j1 + j2 (N,)."""
    s = spk()
    pos, vel = [], []
    for name in names:
        p, v = 0.0, 0.0
        for c, t in segments(name):
            pp, vv = s[c, t].compute_and_differentiate(j1, j2)
            p, v = p + pp * 1e3, v + vv * 1e3 / 86400.0
        pos.append(np.reshape(p, (3, -1)))
        vel.append(np.reshape(v, (3, -1)))
    return np.array(pos), np.array(vel)


def newton(pos, mu):
    """Newtonian barycentric accelerations (n, 3, N) of the point masses at pos (n, 3, N), GMs mu (n,)."""
    acc = np.zeros_like(pos)
    for j in range(len(mu)):
        for k in range(len(mu)):
            if k != j:
                d = pos[k] - pos[j]
                acc[j] += mu[k] * d / np.sum(d * d, axis=0) ** 1.5
    return acc


def eih_1pn(ri, vi, pos, vel, acc, mu, skip=None, sources=None, beta=1.0, gamma=1.0):
    """The 1/c^2 part of the EIH acceleration [m/s^2] (3, N) of body i (index ``skip``, or a test particle
    when None) at barycentric ri [m], vi [m/s] (3, N), from the point masses pos, vel, acc (n, 3, N), mu (n,)
    [m^3/s^2] -- Park et al. 2021 eq. 1 (Standish & Williams eq. 8.1) without its Newtonian term:

        sum_j mu_j (r_j - r_i)/r_ij^3 [-2(beta+gamma)/c^2 sum_{k!=i} mu_k/r_ik - (2 beta-1)/c^2 sum_{k!=j} mu_k/r_jk
            + gamma (v_i/c)^2 + (1+gamma)(v_j/c)^2 - 2(1+gamma)/c^2 v_i.v_j
            - 3/(2c^2) ((r_i - r_j).v_j/r_ij)^2 + 1/(2c^2) (r_j - r_i).a_j]
        + 1/c^2 sum_j mu_j/r_ij^3 [(r_i - r_j).((2+2gamma) v_i - (1+2gamma) v_j)] (v_i - v_j)
        + (3+4gamma)/(2c^2) sum_j mu_j a_j/r_ij

    ``sources``: the bodies j summed over (default all but i); the potentials sum over all bodies."""
    n = len(mu)
    others = [k for k in range(n) if k != skip]
    phi_i = sum(mu[k] / np.sqrt(np.sum((pos[k] - ri) ** 2, axis=0)) for k in others)
    vi2 = np.sum(vi * vi, axis=0)
    out = np.zeros_like(ri)
    for j in (others if sources is None else sources):
        d = pos[j] - ri
        rij = np.sqrt(np.sum(d * d, axis=0))
        phi_j = sum(mu[k] / np.sqrt(np.sum((pos[k] - pos[j]) ** 2, axis=0)) for k in range(n) if k != j)
        bracket = (-2 * (beta + gamma) * phi_i - (2 * beta - 1) * phi_j + gamma * vi2
                   + (1 + gamma) * np.sum(vel[j] ** 2, axis=0) - 2 * (1 + gamma) * np.sum(vi * vel[j], axis=0)
                   - 1.5 * (np.sum(-d * vel[j], axis=0) / rij) ** 2 + 0.5 * np.sum(d * acc[j], axis=0)) / C**2
        out += mu[j] * d / rij**3 * bracket
        out += mu[j] / rij**3 * np.sum(-d * ((2 + 2 * gamma) * vi - (1 + 2 * gamma) * vel[j]), axis=0) * (vi - vel[j]) / C**2
        out += (3 + 4 * gamma) / (2 * C**2) * mu[j] * acc[j] / rij
    return out


def schwarzschild(r, v, mu):
    """GM/(c^2 r^3) [(4 GM/r - v^2) r + 4 (r.v) v] (3, N) at r, v (3, N) [m, m/s] (IERS 2010 eq. 10.12,
    beta = gamma = 1)."""
    rn = np.sqrt(np.sum(r * r, axis=0))
    return mu / (C**2 * rn**3) * ((4 * mu / rn - np.sum(v * v, axis=0)) * r + 4 * np.sum(r * v, axis=0) * v)


# ---------------------------------------------------------------------------------------------------------
# the EIH equations transformed to the GCRS, by numerical differentiation (mpmath)

def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def gcrs_reference(j1, j2, r0, u0, mu_earth, sources=None):
    """The satellite's 1PN acceleration in the GCRS minus what IERS 2010 eq. 10.12 and the Newtonian third
    bodies at their GCRS positions give [m/s^2], by brute force (call inside ``mpmath.workdps(40)``).

    The satellite's geocentric BCRS state r0, u0 [m, m/s] (TDB-compatible) is taken at the barycentric event
    simultaneous in the GCRS with the geocentre's event at the TDB date j1 + j2 (the satellite's barycentric
    time is (v_E.r0)/c^2 later).  The bodies (:data:`EIH_BODIES`, DE421 via jplephem; the Earth's GM
    ``mu_earth``; ``sources``: the indices of the bodies kept besides the Earth, default all) move on
    polynomial worldlines about that date with their Newtonian accelerations (the Earth with its EIH
    acceleration and its Newtonian jerk, so that the transformation's a_E is the derivative of its v_E);
    the satellite on the worldline with its EIH acceleration (Newtonian + :func:`eih_1pn`).  Its GCRS
    coordinates follow from the IAU 2000 transformation (Soffel et al. 2003, AJ 126, 2687, eqs. for T and X:
    T = t - [A(t) + v_E.r]/c^2 with dA/dt = v_E^2/2 + W0, X = r + [v_E (v_E.r)/2 + W0 r + (a_E.r) r -
    a_E r^2/2]/c^2), differentiated numerically (``mpmath.diff``): d^2X/dT^2 = (X'' T' - X' T'')/T'^3.
    The model: -GM_E X/|X|^3, the bodies' Newtonian direct minus indirect terms at their GCRS positions (the
    same transformation, with the simultaneity shift (v_j - v_E)(v_E.r_j)/c^2), the Schwarzschild term with
    GM_E and the Sun's de Sitter term (if the Sun is kept), all in mpmath.

    Returns (missing (3,), X (3,), V (3,)) float64: the difference [m/s^2] and the GCRS (TDB-compatible)
    state [m, m/s] at which it holds.  Exact to O(c^-4) (the transformation's truncation)."""
    n = len(EIH_BODIES)
    e = EIH_BODIES.index("earth")
    keep = set(range(n)) - {e} if sources is None else set(sources)
    mu = np.array([mu_earth if k == e else (gm_f(b) if k in keep else 0.0) for k, b in enumerate(EIH_BODIES)])
    pos, vel = bary_states(EIH_BODIES, np.array([j1]), np.array([j2]))
    acc = newton(pos, mu)
    eih_e = eih_1pn(pos[e], vel[e], pos, vel, acc, mu, skip=e)[:, 0]
    eih_s = eih_1pn((pos[e][:, 0] + r0)[:, None], (vel[e][:, 0] + u0)[:, None], pos, vel, acc, mu)[:, 0]
    c2 = mpf(C) ** 2
    P = [[mpf(float(x)) for x in pos[k][:, 0]] for k in range(n)]
    W = [[mpf(float(x)) for x in vel[k][:, 0]] for k in range(n)]
    M = [mpf(float(m)) for m in mu]
    A = []
    for j in range(n):
        a = [mpf(0)] * 3
        for k in range(n):
            if k != j and M[k]:
                d = [P[k][q] - P[j][q] for q in range(3)]
                dn3 = mpmath.sqrt(_dot(d, d)) ** 3
                a = [a[q] + M[k] * d[q] / dn3 for q in range(3)]
        A.append(a)
    A[e] = [A[e][q] + mpf(float(eih_e[q])) for q in range(3)]
    jerk = [mpf(0)] * 3

    def x_b(k, t):
        return [P[k][q] + W[k][q] * t + A[k][q] * t * t / 2 + (jerk[q] * t**3 / 6 if k == e else 0) for q in range(3)]

    def v_b(k, t):
        return [W[k][q] + A[k][q] * t + (jerk[q] * t * t / 2 if k == e else 0) for q in range(3)]

    def a_earth(t):
        return [A[e][q] + jerk[q] * t for q in range(3)]

    def external(t):
        """Newtonian acceleration of the Earth by the bodies and their potential there."""
        xe, a, w = x_b(e, t), [mpf(0)] * 3, mpf(0)
        for k in range(n):
            if k != e and M[k]:
                d = [x_b(k, t)[q] - xe[q] for q in range(3)]
                dn = mpmath.sqrt(_dot(d, d))
                a, w = [a[q] + M[k] * d[q] / dn**3 for q in range(3)], w + M[k] / dn
        return a, w

    jerk[:] = [mpmath.diff(lambda t: external(t)[0][q], 0, 1) for q in range(3)]
    r0m, u0m = [mpf(float(x)) for x in r0], [mpf(float(x)) for x in u0]
    ts = _dot(W[e], r0m) / c2  # the satellite's barycentric time
    xs0 = [x_b(e, ts)[q] + r0m[q] for q in range(3)]
    vs0 = [v_b(e, ts)[q] + u0m[q] for q in range(3)]
    acc_s = [mpf(float(eih_s[q])) for q in range(3)]
    for k in range(n):
        if M[k]:
            d = [x_b(k, ts)[q] - xs0[q] for q in range(3)]
            dn3 = mpmath.sqrt(_dot(d, d)) ** 3
            acc_s = [acc_s[q] + M[k] * d[q] / dn3 for q in range(3)]

    def rel(t):  # r(t) = x(t) - x_E(t)
        return [xs0[q] + vs0[q] * (t - ts) + acc_s[q] * (t - ts) ** 2 / 2 - x_b(e, t)[q] for q in range(3)]

    def big_x(t, q):
        r, ve, ae, w0 = rel(t), v_b(e, t), a_earth(t), external(t)[1]
        return r[q] + (ve[q] * _dot(ve, r) / 2 + w0 * r[q] + r[q] * _dot(ae, r) - ae[q] * _dot(r, r) / 2) / c2

    ve = v_b(e, ts)
    t1 = 1 - (_dot(ve, ve) / 2 + external(ts)[1] + mpmath.diff(lambda t: _dot(v_b(e, t), rel(t)), ts, 1)) / c2
    t2 = -(_dot(ve, a_earth(ts)) + mpmath.diff(lambda t: external(t)[1], ts, 1)
           + mpmath.diff(lambda t: _dot(v_b(e, t), rel(t)), ts, 2)) / c2
    x0 = [big_x(ts, q) for q in range(3)]
    x1 = [mpmath.diff(lambda t: big_x(t, q), ts, 1) for q in range(3)]
    x2 = [mpmath.diff(lambda t: big_x(t, q), ts, 2) for q in range(3)]
    exact = [(x2[q] * t1 - x1[q] * t2) / t1**3 for q in range(3)]
    v0 = [x1[q] / t1 for q in range(3)]
    # the model at the geocentre's event (t = 0)
    ve, ae, w0 = v_b(e, 0), a_earth(0), external(0)[1]
    xn = mpmath.sqrt(_dot(x0, x0))
    model = [-M[e] * x0[q] / xn**3 for q in range(3)]
    model = [model[q] + M[e] / (c2 * xn**3) * ((4 * M[e] / xn - _dot(v0, v0)) * x0[q] + 4 * _dot(x0, v0) * v0[q])
             for q in range(3)]  # Schwarzschild
    for k in range(n):
        if k == e or not M[k]:
            continue
        rj = [x_b(k, 0)[q] - x_b(e, 0)[q] for q in range(3)]
        vj = [v_b(k, 0)[q] - ve[q] for q in range(3)]
        vr = _dot(ve, rj)
        xj = [rj[q] + (vj[q] * vr + ve[q] * vr / 2 + w0 * rj[q] + _dot(ae, rj) * rj[q] - ae[q] * _dot(rj, rj) / 2) / c2
              for q in range(3)]
        d = [xj[q] - x0[q] for q in range(3)]
        dn3, xn3 = mpmath.sqrt(_dot(d, d)) ** 3, mpmath.sqrt(_dot(xj, xj)) ** 3
        model = [model[q] + M[k] * (d[q] / dn3 - xj[q] / xn3) for q in range(3)]
        if EIH_BODIES[k] == "sun":  # de Sitter: 3 [Rdot x (-GM_S R/(c^2 R^3))] x v, R = -r_sun
            big_r, rdot = [-x for x in rj], [-x for x in vj]
            w = [-M[k] * x / (c2 * mpmath.sqrt(_dot(big_r, big_r)) ** 3) for x in big_r]
            om = [3 * (rdot[1] * w[2] - rdot[2] * w[1]), 3 * (rdot[2] * w[0] - rdot[0] * w[2]),
                  3 * (rdot[0] * w[1] - rdot[1] * w[0])]
            model = [model[0] + om[1] * v0[2] - om[2] * v0[1], model[1] + om[2] * v0[0] - om[0] * v0[2],
                     model[2] + om[0] * v0[1] - om[1] * v0[0]]
    f = lambda xs: np.array([float(x) for x in xs])  # noqa: E731
    return f([exact[q] - model[q] for q in range(3)]), f(x0), f(v0)
