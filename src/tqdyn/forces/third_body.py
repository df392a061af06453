"""Third-body (point-mass) perturbations in the geocentric frame.

A body of gravitational parameter GM at geocentric position s pulls a
satellite at r and the Earth itself; the geocentric (relative) acceleration
is

    a = -GM (d / |d|^3 + s / |s|^3),   d = r - s.

Evaluated literally the two terms (~GM/|s|^2 each) nearly cancel when
|r| << |s| (the Sun: |r|/|s| ~ 7e-4, three digits lost).  With
q = r.(r - 2 s) / |s|^2, so that |d|^2 = |s|^2 (1 + q), the identity

    a = -GM / |d|^3 (r + f(q) s),   f(q) = (1+q)^(3/2) - 1
                                         = q (3 + 3q + q^2) / (1 + (1+q)^(3/2))

has no cancellation (R. H. Battin, An Introduction to the Mathematics and
Methods of Astrodynamics, AIAA 1999, sec. 8.4).  Evaluated in float64: the
largest third-body term at 1e5 km (the Moon, ~1e-5 m/s^2) is exact to
~1e-21 m/s^2.

The bodies' positions are time-only inputs: a ``position`` callable
(epoch, t_hi, t_lo) -> (..., 3) geocentric GCRS positions [m] at the times
t = t_hi + t_lo [s TT since the epoch] (an ephemeris), evaluated by the
propagator once per chunk for all stage times.

Smooth inputs.  A body position rounded to float64 (ulp 3e-5 m at the
Sun's 1.4e11 m, 6e-8 m at the Moon's 3.8e8 m) is not a smooth function of
time; times the tidal gradient (~3 GM |r| / |s|^4: Sun 8e-17 s^-2, Moon
7e-14 s^-2 at |r| = 1e8 m) it is a white noise of ~3e-21 m/s^2 in the force,
which integrators sampling at other instants turn into different random
walks.  So the positions come as dd pairs s = s_hi + s_lo when the provider
has a ``position_dd`` method (the ephemeris does): the bodies evaluated in
extended precision take s_hi + s_lo whole; the float64 bodies add the
first-order effect of s_lo (|s_lo| <= ulp(s_hi) / 2),

    a(r, s_hi + s_lo) = a(r, s_hi) + J(r, s_hi) s_lo + O(|s_lo|^2 / |s|^2),
    J = da/ds = GM [(I - 3 e e^T) / |s - r|^3 - (I - 3 u u^T) / |s|^3],

e = (s - r) / |s - r|, u = s / |s| (the derivative of x / |x|^3 is
(I - 3 x x^T / |x|^2) / |x|^3); the neglected term is ~1e-16 of the
correction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numba import njit

from .._choices import unknown as unknown_name
from ..numerics.dd import add, const, div, mul, neg, sqrt, sub
from ..numerics.jit import inner_kernel

__all__ = ["ThirdBodies", "pm_difference", "third_body_accel", "third_bodies_accel", "third_body_accel_ext",
           "third_body_jerk", "third_body_position_jacobian_times"]


@njit(cache=True, inline="always")
def pm_difference(gm, Dx, Dy, Dz, ex, ey, ez):
    """gm [(D + e) / |D + e|^3 - D / |D|^3] [m/s^2 for gm in m^3/s^2, D, e
    in m], without cancellation: with |D + e|^2 = |D|^2 + delta, delta =
    e.(2 D + e), the difference of the inverse cubes is -delta (|D|^2 +
    |D| |D + e| + |D + e|^2) / ((|D| + |D + e|) |D|^3 |D + e|^3).  float64
    scalars, any frame; returns (x, y, z)."""
    r2 = Dx * Dx + Dy * Dy + Dz * Dz
    dl = ex * (2.0 * Dx + ex) + ey * (2.0 * Dy + ey) + ez * (2.0 * Dz + ez)
    p2 = r2 + dl
    r, p = math.sqrt(r2), math.sqrt(p2)
    r3, p3 = r2 * r, p2 * p
    w = -dl * (r2 + r * p + p2) / ((r + p) * r3 * p3)
    return gm * (ex / p3 + Dx * w), gm * (ey / p3 + Dy * w), gm * (ez / p3 + Dz * w)


@inner_kernel
def third_body_accel(rx, ry, rz, sx, sy, sz, gm):
    """Geocentric acceleration [m/s^2] of a satellite at r [m] due to a point
    mass gm [m^3/s^2] at s [m] (direct minus indirect term, Battin's
    cancellation-free form).  float64 scalars; returns (ax, ay, az)."""
    s2 = sx * sx + sy * sy + sz * sz
    q = (rx * (rx - 2.0 * sx) + ry * (ry - 2.0 * sy) + rz * (rz - 2.0 * sz)) / s2
    w = math.sqrt(1.0 + q)
    f = q * (3.0 + 3.0 * q + q * q) / (1.0 + w * w * w)
    dx, dy, dz = rx - sx, ry - sy, rz - sz
    d2 = dx * dx + dy * dy + dz * dz
    k = -gm / (d2 * math.sqrt(d2))
    return k * (rx + f * sx), k * (ry + f * sy), k * (rz + f * sz)


@njit(cache=True, inline="always")
def third_body_position_jacobian_times(rx, ry, rz, sx, sy, sz, gm, ex, ey, ez):
    """J(r, s) e [m/s^2]: the change of :func:`third_body_accel` when the
    body moves from s to s + e (to first order), J = GM [(I - 3 d^ d^T) /
    |d|^3 - (I - 3 s^ s^T) / |s|^3], d = s - r (module docstring).  r, s, e
    [m], gm [m^3/s^2]: float64 scalars, one frame; returns (x, y, z)."""
    dx, dy, dz = sx - rx, sy - ry, sz - rz
    d2 = dx * dx + dy * dy + dz * dz
    id3 = 1.0 / (d2 * math.sqrt(d2))
    pd = 3.0 * (dx * ex + dy * ey + dz * ez) / d2
    s2 = sx * sx + sy * sy + sz * sz
    is3 = 1.0 / (s2 * math.sqrt(s2))
    ps = 3.0 * (sx * ex + sy * ey + sz * ez) / s2
    return (gm * ((ex - pd * dx) * id3 - (ex - ps * sx) * is3),
            gm * ((ey - pd * dy) * id3 - (ey - ps * sy) * is3),
            gm * ((ez - pd * dz) * id3 - (ez - ps * sz) * is3))


@inner_kernel
def third_body_accel_ext(rx, ry, rz, sx, sy, sz, gm, lx=0.0, ly=0.0, lz=0.0):
    """:func:`third_body_accel` in the number type of r (generic: dd tuples
    or float64): for extended-precision evaluation of the large third-body
    terms (Moon ~1e-5, Sun ~6e-6 m/s^2, whose float64 round-off, ~1e-21
    m/s^2, accumulates to ~1e-12 m per day of orbit).  s + l: the body's
    position as a dd pair (s, l float64 [m]; the float64 mode uses s alone);
    gm: float64."""
    sx, sy, sz = const(sx, lx, rx), const(sy, ly, rx), const(sz, lz, rx)
    s2 = add(add(mul(sx, sx), mul(sy, sy)), mul(sz, sz))
    q = div(add(add(mul(rx, sub(rx, mul(sx, 2.0))), mul(ry, sub(ry, mul(sy, 2.0)))),
                mul(rz, sub(rz, mul(sz, 2.0)))), s2)
    w = sqrt(add(q, 1.0))
    f = div(mul(q, add(add(mul(q, q), mul(q, 3.0)), 3.0)), add(mul(w, mul(w, w)), 1.0))
    dx, dy, dz = sub(rx, sx), sub(ry, sy), sub(rz, sz)
    d2 = add(add(mul(dx, dx), mul(dy, dy)), mul(dz, dz))
    k = neg(div(gm, mul(d2, sqrt(d2))))
    return (mul(k, add(rx, mul(f, sx))), mul(k, add(ry, mul(f, sy))), mul(k, add(rz, mul(f, sz))))


@njit(cache=True, inline="always")
def third_body_jerk(gm, rx, ry, rz, vx, vy, vz, sx, sy, sz, ux, uy, uz):
    """Time derivative [m/s^3] of the third-body acceleration
    gm [(s - r)/|s - r|^3 - s/|s|^3] of :func:`third_body_accel` for a
    satellite at r [m] moving with v [m/s] and a body at s [m] moving with
    u [m/s] (geocentric, one inertial frame; gm [m^3/s^2]).  The literal
    form: its cancellation (three digits for the Sun) costs nothing at the
    ~1e-10 m/s^3 of the Moon's and Sun's tidal jerks, which only enter the
    attitude rates through 1/c.  float64 scalars; returns (jx, jy, jz)."""
    dx, dy, dz = sx - rx, sy - ry, sz - rz
    ex, ey, ez = ux - vx, uy - vy, uz - vz
    d2 = dx * dx + dy * dy + dz * dz
    id3 = 1.0 / (d2 * np.sqrt(d2))
    q = 3.0 * (dx * ex + dy * ey + dz * ez) / d2
    s2 = sx * sx + sy * sy + sz * sz
    is3 = 1.0 / (s2 * np.sqrt(s2))
    p = 3.0 * (sx * ux + sy * uy + sz * uz) / s2
    return (gm * ((ex - q * dx) * id3 - (ux - p * sx) * is3),
            gm * ((ey - q * dy) * id3 - (uy - p * sy) * is3),
            gm * ((ez - q * dz) * id3 - (uz - p * sz) * is3))


@inner_kernel
def third_bodies_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Sum of the point-mass terms of all bodies (the perturbation-kernel
    signature of :mod:`tqdyn.forces.model`): tdat = body positions (3 n,) [m]
    at this instant, then their low parts (3 n,) [m] (dd pairs, module
    docstring), params = [n, gm_1, ..., gm_n, ext_1, ..., ext_n]; the
    bodies with ext_k != 0 are skipped here (evaluated in extended precision
    by the model).  float64, m/s^2."""
    ax, ay, az = 0.0, 0.0, 0.0
    n = int(params[0])
    for k in range(n):
        if params[1 + n + k] == 0.0:  # bodies flagged extended are evaluated by third_body_accel_ext
            sx, sy, sz = tdat[3 * k], tdat[3 * k + 1], tdat[3 * k + 2]
            gx, gy, gz = third_body_accel(rx, ry, rz, sx, sy, sz, params[1 + k])
            jx, jy, jz = third_body_position_jacobian_times(rx, ry, rz, sx, sy, sz, params[1 + k], tdat[3 * (n + k)],
                                                            tdat[3 * (n + k) + 1], tdat[3 * (n + k) + 2])
            ax, ay, az = ax + (gx + jx), ay + (gy + jy), az + (gz + jz)
    return ax, ay, az


@dataclass(frozen=True)
class _OneBody:
    """Position provider of body k of a multi-body provider: (..., 1, 3)."""

    position: Callable
    k: int

    def __call__(self, epoch, t_hi, t_lo):
        return np.asarray(self.position(epoch, t_hi, t_lo))[..., self.k:self.k + 1, :]

    def position_dd(self, epoch, t_hi, t_lo):
        hi, lo = _positions_dd(self.position, epoch, t_hi, t_lo)
        return hi[..., self.k:self.k + 1, :], lo[..., self.k:self.k + 1, :]


def _positions_dd(position, epoch, t_hi, t_lo):
    """(hi, lo) positions [m] of a provider: its ``position_dd`` if it has
    one, else its float64 positions and zeros."""
    if hasattr(position, "position_dd"):
        hi, lo = position.position_dd(epoch, t_hi, t_lo)
        return np.asarray(hi, dtype=np.float64), np.asarray(lo, dtype=np.float64)
    hi = np.asarray(position(epoch, t_hi, t_lo), dtype=np.float64)
    return hi, np.zeros_like(hi)


@dataclass(frozen=True)
class ThirdBodies:
    """Point-mass perturbations of a list of bodies.

    names: body names; gms: their GM [m^3/s^2]; position: callable
    (epoch, t_hi, t_lo) -> (..., n_bodies, 3) float64 geocentric GCRS
    positions [m]; source: where the positions and GMs come from.
    Parameters handed to the compiled model: [n, gm_1, ..., gm_n];
    time-only inputs: the 3 n coordinates, then their 3 n low parts (the
    positions as dd pairs: ``position.position_dd`` if the provider has
    it, else zeros).  extended: names of the bodies
    whose term is evaluated in the propagation's number type (dd) instead of
    float64 -- worth it for the Moon and the Sun, whose float64 round-off
    (~1e-21 m/s^2) moves a 1e8 m orbit by ~1e-12 m per day.
    """

    names: tuple[str, ...]
    gms: tuple[float, ...]
    position: Callable
    source: str = "JPL DE ephemeris via tqdyn.astro.ephemeris (or user-supplied positions)"
    extended: tuple[str, ...] = ()
    name: str = field(default="third_body", init=False)
    description: str = field(default="point-mass third bodies, direct + indirect term (Battin)", init=False)

    @property
    def n_tdat(self) -> int:
        """Time-only inputs per instant: 3 coordinates per body and their low parts."""
        return 6 * len(self.names)

    def params(self) -> np.ndarray:
        """[n, gm_1, ..., gm_n, ext_1, ..., ext_n] float64 (ext_k = 1.0 for
        a body evaluated in extended precision)."""
        unknown = set(self.extended) - set(self.names)
        if unknown:
            raise ValueError(unknown_name("third bodies: extended", sorted(unknown)[0], self.names,
                                          problem="is not among the bodies"))
        return np.array([len(self.gms), *self.gms, *(float(n in self.extended) for n in self.names)],
                        dtype=np.float64)

    def split(self) -> tuple["ThirdBodies", ...]:
        """One single-body term per body (force budgets per body)."""
        return tuple(ThirdBodies(names=(n,), gms=(g,), position=_OneBody(self.position, k), source=self.source,
                                 extended=tuple(x for x in self.extended if x == n))
                     for k, (n, g) in enumerate(zip(self.names, self.gms)))

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Body positions at t_hi + t_lo [s TT since epoch], flattened to
        (*shape(t_hi), 6 n) float64 [m]: the 3 n coordinates (hi parts),
        then their 3 n low parts."""
        hi, lo = _positions_dd(self.position, epoch, t_hi, t_lo)
        expected = np.shape(t_hi) + (len(self.names), 3)
        if hi.shape != expected or lo.shape != expected:
            raise ValueError(f"third-body positions: shape {hi.shape}, expected {expected}")
        shape = np.shape(t_hi) + (3 * len(self.names),)
        return np.concatenate((hi.reshape(shape), lo.reshape(shape)), axis=-1)
