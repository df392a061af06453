"""The first post-Newtonian (1PN) n-body acceleration of a spacecraft, heliocentric: the
Einstein-Infeld-Hoffmann (EIH) equations in the Sun-centred frame.

**The equation.**  The JPL ephemerides integrate the EIH equations of the Sun, the Moon and the
planets (Standish & Williams, Explanatory Supplement ch. 8, eq. 8.1; Park et al. 2021, AJ 161,
105, eq. 1).  For a massless spacecraft i at barycentric position x_i and velocity v_i among point
masses j (GM mu_j, barycentric x_j, v_j, Newtonian acceleration a_j), in general relativity
(PPN beta = gamma = 1) and the harmonic gauge of the BCRS::

    a_i = sum_j mu_j d_j / r_j^3                                                  (Newton)
        + c^-2 sum_j mu_j d_j / r_j^3 [ -4 phi_i - phi_j + v_i^2 + 2 v_j^2 - 4 v_i.v_j
                                        - 3/2 (d_j.v_j / r_j)^2 + 1/2 d_j.a_j ]
        + c^-2 sum_j mu_j / r_j^3 [ -d_j.(4 v_i - 3 v_j) ] (v_i - v_j)
        + 7/2 c^-2 sum_j mu_j a_j / r_j

with d_j = x_j - x_i, r_j = |d_j|, phi_i = sum_k mu_k / |x_k - x_i| the Newtonian potential at
the spacecraft and phi_j = sum_{k != j} mu_k / |x_k - x_j| the potential of the other bodies at
body j.  The spacecraft's own mass (~2e3 kg: GM ~ 1e-7 m^3/s^2) is neglected: it enters only
the bodies' phi_j and a_j, by ~1e-7 / (GM_sun / au) ~ 1e-16 of them.  :func:`eih_pair` is the
c^-2 part of one source j's term; :func:`eih_1pn_kernel` sums it.

**The heliocentric difference.**  tqdyn's heliocentric coordinates are the TDB-compatible BCRS
translated to the Sun's centre (a Newtonian translation, same time t): the spacecraft's
barycentric state is x_i = rho + x_S, v_i = rho' + v_S, and its heliocentric acceleration is
rho'' = a_i - a_S, both from EIH.  The Newtonian parts of the two are exactly tqdyn's Sun
monopole and third bodies with the indirect term; the 1PN part is

    a_1PN = EIH_1PN(spacecraft) - EIH_1PN(Sun)

which this term applies in place of the Sun's Schwarzschild term (it contains it: with the Sun
alone and at rest, EIH_1PN(spacecraft) is Schwarzschild in rho, rho'; the rest is the Sun's terms
with its barycentric motion (13-14 m/s, 2e-7 m/s^2), the planets' 1PN terms on the spacecraft and
the frame's own 1PN acceleration -EIH_1PN(Sun): docs/force-model.md).

**Time-only and spacecraft-dependent parts.**  Everything about the bodies depends on t only and
is precomputed per instant (:meth:`HeliocentricEIH.precompute`): the heliocentric positions
x_j - x_S, the barycentric velocities v_j, the Newtonian barycentric accelerations a_j (of the
Sun and the listed bodies on each other), the potentials phi_j, and EIH_1PN(Sun) itself.  The
spacecraft enters through d_j = (x_j - x_S) - rho (heliocentric differences: no 1.5e11 m
barycentric coordinates are subtracted), v_i = rho' + v_S and phi_i: the compiled float64
kernel :func:`heliocentric_eih_accel` forms those and the sum over j.  The bodies are the Sun
and the run's third bodies (``forces.third_bodies``), DE430/DE431 GMs, the ephemeris's states at
t (TDB).  The whole term is ~1.8e-10 m/s^2 at 1 au (Schwarzschild); its float64 round-off,
~1e-16 of its largest parts, is ~1e-25 m/s^2.

Term interface (:mod:`tqdyn.forces.model`): parameters ``[c, n, mu_0 .. mu_{n-1}]`` (body 0 the
Sun); time-only inputs per instant ``10 n + 3``: per body j ``[x_j - x_S (3) m, v_j (3) m/s,
a_j (3) m/s^2, phi_j m^2/s^2]`` (ICRF axes, BCRS), then EIH_1PN(Sun) (3) m/s^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..astro.constants import C_LIGHT
from ..astro.ephemeris import Ephemeris, default_ephemeris, planetary_gm
from ..astro.reference import HELIOCENTRIC

__all__ = ["HeliocentricEIH", "eih_pair", "eih_1pn_kernel", "heliocentric_eih_accel", "newtonian_bodies",
           "N_BODY_COLUMNS"]

#: Time-only columns per body: position (3), barycentric velocity (3), Newtonian acceleration (3), potential.
N_BODY_COLUMNS = 10


@njit(cache=True, inline="always")
def eih_pair(dx, dy, dz, vix, viy, viz, vjx, vjy, vjz, ajx, ajy, ajz, phi_i, phi_j, mu_j):
    """c^2 times the 1PN acceleration [m^3/s^4] of a massless particle i by
    one point mass j of the EIH equations (module docstring; beta = gamma = 1): d = x_j - x_i [m],
    v_i, v_j [m/s] barycentric velocities, a_j [m/s^2] body j's Newtonian barycentric acceleration,
    phi_i, phi_j [m^2/s^2] the Newtonian potentials at i (all bodies) and at j (the others), mu_j
    [m^3/s^2].  Divide by c^2 for the acceleration.  float64 scalars, any axes; returns (x, y, z)."""
    r2 = dx * dx + dy * dy + dz * dz
    r = math.sqrt(r2)
    k = mu_j / (r2 * r)
    dvj = dx * vjx + dy * vjy + dz * vjz
    bracket = (-4.0 * phi_i - phi_j + (vix * vix + viy * viy + viz * viz) + 2.0 * (vjx * vjx + vjy * vjy + vjz * vjz)
               - 4.0 * (vix * vjx + viy * vjy + viz * vjz) - 1.5 * (dvj / r) ** 2
               + 0.5 * (dx * ajx + dy * ajy + dz * ajz))
    s = -(dx * (4.0 * vix - 3.0 * vjx) + dy * (4.0 * viy - 3.0 * vjy) + dz * (4.0 * viz - 3.0 * vjz))
    g = 3.5 * mu_j / r
    return (k * (bracket * dx + s * (vix - vjx)) + g * ajx,
            k * (bracket * dy + s * (viy - vjy)) + g * ajy,
            k * (bracket * dz + s * (viz - vjz)) + g * ajz)


@njit(cache=True)
def eih_1pn_kernel(px, py, pz, vix, viy, viz, bodies, mu, skip, c):
    """The 1PN (c^-2) part of the EIH acceleration [m/s^2] of a massless particle (``skip`` < 0) or of
    body ``skip`` itself, at position p [m] (relative to the same origin as the bodies' positions) with
    barycentric velocity v_i [m/s].  bodies (10 n,): per body j, at bodies[10 j:10 j + 10], [position (3)
    m, barycentric velocity (3) m/s, Newtonian barycentric acceleration (3) m/s^2, potential of the
    others phi_j m^2/s^2]; mu (n,) [m^3/s^2]; c [m/s].  float64; returns (x, y, z)."""
    n = mu.shape[0]
    phi_i = 0.0
    for j in range(n):
        if j != skip:
            o = N_BODY_COLUMNS * j
            dx, dy, dz = bodies[o] - px, bodies[o + 1] - py, bodies[o + 2] - pz
            phi_i += mu[j] / math.sqrt(dx * dx + dy * dy + dz * dz)
    ax, ay, az = 0.0, 0.0, 0.0
    for j in range(n):
        if j != skip:
            o = N_BODY_COLUMNS * j
            gx, gy, gz = eih_pair(bodies[o] - px, bodies[o + 1] - py, bodies[o + 2] - pz, vix, viy, viz,
                                  bodies[o + 3], bodies[o + 4], bodies[o + 5], bodies[o + 6], bodies[o + 7],
                                  bodies[o + 8], phi_i, bodies[o + 9], mu[j])
            ax, ay, az = ax + gx, ay + gy, az + gz
    c2 = c * c
    return ax / c2, ay / c2, az / c2


@njit(cache=True)
def newtonian_bodies(bodies, mu):
    """Fill columns 6..9 of each body's row of ``bodies`` (10 n,) (layout of :func:`eih_1pn_kernel`)
    from the positions in columns 0..2 [m, any common origin] and the GMs mu (n,) [m^3/s^2]: the
    Newtonian acceleration of body j by the others [m/s^2] and their potential at body j [m^2/s^2]."""
    n = mu.shape[0]
    for j in range(n):
        oj = N_BODY_COLUMNS * j
        ax, ay, az, phi = 0.0, 0.0, 0.0, 0.0
        for k in range(n):
            if k != j:
                ok = N_BODY_COLUMNS * k
                dx, dy, dz = bodies[ok] - bodies[oj], bodies[ok + 1] - bodies[oj + 1], bodies[ok + 2] - bodies[oj + 2]
                r2 = dx * dx + dy * dy + dz * dz
                r = math.sqrt(r2)
                w = mu[k] / (r2 * r)
                ax, ay, az, phi = ax + w * dx, ay + w * dy, az + w * dz, phi + mu[k] / r
        bodies[oj + 6], bodies[oj + 7], bodies[oj + 8], bodies[oj + 9] = ax, ay, az, phi


@njit(cache=True)
def _fill_heliocentric(pos, vel, v_sun, mu, c, out):
    """Time-only inputs (m, 10 n + 3) from heliocentric positions pos (m, n - 1, 3) [m], velocities
    vel (m, n - 1, 3) [m/s] of the bodies other than the Sun, the Sun's barycentric velocity v_sun
    (m, 3) [m/s] and the GMs mu (n,) (the Sun first)."""
    n = mu.shape[0]
    o = N_BODY_COLUMNS * n
    for t in range(out.shape[0]):
        row = out[t]
        for q in range(3):
            row[q] = 0.0
            row[3 + q] = v_sun[t, q]
        for j in range(1, n):
            for q in range(3):
                row[N_BODY_COLUMNS * j + q] = pos[t, j - 1, q]
                row[N_BODY_COLUMNS * j + 3 + q] = vel[t, j - 1, q] + v_sun[t, q]
        newtonian_bodies(row, mu)
        row[o], row[o + 1], row[o + 2] = eih_1pn_kernel(0.0, 0.0, 0.0, row[3], row[4], row[5], row, mu, 0, c)


@njit(cache=True)
def heliocentric_eih_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """The heliocentric 1PN acceleration [m/s^2] EIH_1PN(spacecraft) - EIH_1PN(Sun) at the
    heliocentric position r [m] and velocity v [m/s] (ICRF axes, TDB-compatible BCRS translated to
    the Sun; the perturbation-kernel signature of :mod:`tqdyn.forces.model`).  tdat, params: see
    the module docstring.  float64 scalars; returns (ax, ay, az)."""
    c, n = params[0], int(params[1])
    ax, ay, az = eih_1pn_kernel(rx, ry, rz, vx + tdat[3], vy + tdat[4], vz + tdat[5], tdat, params[2:2 + n], -1, c)
    o = N_BODY_COLUMNS * n
    return ax - tdat[o], ay - tdat[o + 1], az - tdat[o + 2]


@dataclass(frozen=True)
class HeliocentricEIH:
    """The heliocentric 1PN n-body acceleration EIH_1PN(spacecraft) - EIH_1PN(Sun) (module
    docstring), in place of the Sun's Schwarzschild term.

    names: the bodies besides the Sun (names of :data:`tqdyn.astro.ephemeris.HELIOCENTRIC_BODIES`,
    the run's third bodies); ephemeris: their source (None: the shipped DE421); gms: ((body, GM
    [m^3/s^2, TDB-compatible]), ...) of the Sun and the bodies, the scenario's ``forces.gm_*`` (empty:
    DE430/DE431, ``data/gm_de431.tpc``); c = 299792458 m/s."""

    names: tuple[str, ...] = ()
    ephemeris: Ephemeris | None = None
    gms: tuple = ()
    name: str = field(default="relativity_eih", init=False)
    description: str = field(
        default="1PN n-body (Einstein-Infeld-Hoffmann) acceleration, heliocentric: EIH(spacecraft) - EIH(Sun), "
                "the Sun and the third bodies (forces.relativity_model = \"eih\")", init=False)
    source: str = field(
        default="EIH equations as integrated by the JPL ephemerides (Standish & Williams, Explanatory Supplement "
                "ch. 8 eq. 8.1; Park et al. 2021, AJ 161, 105, eq. 1), beta = gamma = 1; bodies from a JPL "
                "ephemeris, GMs of DE430/DE431", init=False)
    n_tdat: int = field(default=0, init=False)

    def __post_init__(self):
        names = tuple(str(b).lower() for b in self.names)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "n_tdat", N_BODY_COLUMNS * (1 + len(names)) + 3)

    def _ephemeris(self) -> Ephemeris:
        return default_ephemeris() if self.ephemeris is None else self.ephemeris

    def _gms(self) -> np.ndarray:
        gm = dict(self.gms) if self.gms else planetary_gm()
        return np.array([gm["sun"]] + [gm[b] for b in self.names], dtype=np.float64)

    def params(self) -> np.ndarray:
        """[c, n, mu_0 (the Sun), .., mu_{n-1}] float64 (SI)."""
        return np.concatenate([[C_LIGHT, 1.0 + len(self.names)], self._gms()])

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Time-only inputs at t = t_hi + t_lo [s TDB since the epoch's TDB]: float64
        (*broadcast shape of t_hi, t_lo, 10 n + 3) (module docstring)."""
        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, dtype=np.float64), np.asarray(t_lo, dtype=np.float64))
        shape = t_hi.shape
        jd1, jd2 = HELIOCENTRIC.ephemeris_jd(epoch, t_hi.reshape(-1), t_lo.reshape(-1))
        eph = self._ephemeris()
        m = jd1.size
        n = 1 + len(self.names)
        if self.names:
            pos, vel = eph.heliocentric_states(self.names, jd1, jd2, velocity=True)
        else:
            pos = vel = np.zeros((m, 0, 3))
        _, v_sun = eph.sun_barycentric(jd1, jd2)
        out = np.empty((m, self.n_tdat))
        _fill_heliocentric(np.ascontiguousarray(pos), np.ascontiguousarray(vel), np.ascontiguousarray(v_sun),
                           self._gms(), C_LIGHT, out)
        assert out.shape[1] == N_BODY_COLUMNS * n + 3
        return out.reshape(shape + (self.n_tdat,))
