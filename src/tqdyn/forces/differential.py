"""Differential gravity between a satellite and a nearby point: the tidal
field that acts on a test mass relative to its satellite.

The coupled dynamics needs, at every evaluation, the difference

    dg = a(r + d, v + u) - a(r, v)        [m/s^2, the force model's frame]

between the force model's acceleration at an electrode-housing (EH) centre
r + d and at the satellite's CoM r (|d| = 0.2 .. 0.3 m, |r| = 1e8 m
geocentric or 1.5e11 m heliocentric; u is the EH centre's velocity relative
to the CoM, ~1e-5 m/s).  Evaluating the whole model at r + d and
subtracting costs a full evaluation per EH centre (six per right-hand side,
twice the satellites' own).  Here each term's difference is formed without
cancellation and at a fraction of the cost:

* **point masses** -- the central monopole and every third body (Battin's
  geocentric form and the heliocentric one alike: the indirect term is the
  same at both points and drops out): the exact difference of GM D/|D|^3
  between two points D and D + e
  (:func:`tqdyn.forces.third_body.pm_difference`), written so that
  nothing cancels -- relative error <= ~1e-15 of the result (1e-25 m/s^2
  for the monopole's 8e-11 at TianQin, measured against mpmath), and exact
  to all orders in |e| / |D| (the monopole's second-order term is ~5e-19
  m/s^2 at TianQin, the Moon's ~1e-22);
* **the Earth's degree 2** (static + tides), when the model evaluates it in
  extended precision: the Jacobian of the quadrupole field at the midpoint
  r + d/2 applied to d (:func:`quadrupole_jacobian_product`).  The midpoint
  rule is exact to second order; its error is |d^3 a| |d|^3 / 24 with
  |d^3 a| ~ 120 |a_2| / r^3, i.e. 2e-32 m/s^2 at 1e8 m (|a_2| = 4.9e-7);
* **every other term** (the Earth's degrees >= 3 with their tides, and the
  list of :func:`tqdyn.forces.model.float64_terms`: the Moon's field, the
  Sun's J2, relativity, the central J2, the EIH terms): float64 at both
  points and subtracted.  Their magnitudes (<= 3e-10 m/s^2 at TianQin,
  the Sun's Schwarzschild or EIH term 1.8e-10 at 1 au) bound the
  round-off of the difference by ~3e-26 m/s^2; the GCRS EIH terms
  (2e-13 m/s^2) sum float64 pieces of up to 1.2e-9 m/s^2 and barycentric
  velocities of 30 km/s, ~1e-24 m/s^2 of round-off.  The Earth field at
  the satellite is the value the satellite's own evaluation already formed
  (:func:`tqdyn.forces.model.gravity_split`), and the Moon's field is
  truncated at degree :data:`MOON_DEGREE_DG` = 4: its degree-n part of dg is
  ~(n + 2) |a_n| |d| / D; at the Moon's perigee distance from a TianQin
  satellite (D = 2.8e8 m, GL0660B) degree 3 gives ~2e-24 and degree 4
  ~2e-26 m/s^2, degree 5 below 1e-28;
* the Earth-field indirect term (the geocentre's acceleration) is the same
  at both points and is left out exactly.

Overall dg is exact to ~4e-25 m/s^2 geocentric: the float64 round-off of
the Earth's degrees >= 3 (2.7e-10 m/s^2 at TianQin) and of the planets,
which the direct difference (the whole model again at r + d) carries too;
both agree to 4.2e-25 m/s^2 (1.5e-24 with the GCRS EIH terms;
tests/test_differential_gravity.py, which
also checks each part against mpmath or double-double).  The float64 terms
are evaluated at r and at fl(r + d): the rounding of r + d (<= 7.5e-9 m at
1e8 m) moves their difference by <= |grad a_{>=3}| 7.5e-9 m ~ 1e-25 m/s^2,
as in the direct difference.  Heliocentric the direct difference is the
worse one (~1e-22 m/s^2: float64 planets at positions rounded to 3e-5 m),
while the exact point-mass differences here agree with mpmath to 1e-29.
Everything is float64.
"""

from __future__ import annotations

import math

from numba import njit

from ..numerics.jit import dynamic

from .earth import PARAM_HEADER as _EF_HEADER
from .earth import degree2_matrix, gcrs_from_itrs, itrs_from_gcrs
from .model import SLOT_CENTRAL_MONOPOLE, SLOT_EARTH_FIELD, SLOT_THIRD_BODY, earth_field_term, float64_terms, slot_table
from .third_body import pm_difference
from ..numerics.jit import inner_kernel

__all__ = ["pm_difference", "quadrupole_jacobian_product", "direct_terms", "differential_gravity",
           "MOON_DEGREE_DG"]

#: Highest degree of the Moon's field in the differential gravity (see the module docstring).
MOON_DEGREE_DG = 4


@njit(cache=True, inline="always")
def quadrupole_jacobian_product(k, mxx, myy, mzz, mxy, mxz, myz, x, y, z, dx, dy, dz):
    """J(x) d [m/s^2] of the degree-2 field a = k (2 M x / r^5 - 5 Q x / r^7),
    Q = x^T M x (:func:`tqdyn.forces.earth.degree2_accel_ext`; k = GM R^2
    [m^5/s^2], M symmetric and traceless, x, d [m] in the body-fixed frame):

        J d = k [2 M d / r^5 - 10 (M x)(x.d) / r^7 - 10 x (M x.d) / r^7
                 - 5 Q d / r^7 + 35 Q x (x.d) / r^9].

    float64; returns the body-fixed (x, y, z)."""
    mx = mxx * x + mxy * y + mxz * z
    my = mxy * x + myy * y + myz * z
    mz = mxz * x + myz * y + mzz * z
    md_x = mxx * dx + mxy * dy + mxz * dz
    md_y = mxy * dx + myy * dy + myz * dz
    md_z = mxz * dx + myz * dy + mzz * dz
    r2 = x * x + y * y + z * z
    r5 = r2 * r2 * math.sqrt(r2)
    r7 = r5 * r2
    q = x * mx + y * my + z * mz
    xd = x * dx + y * dy + z * dz
    mxd = mx * dx + my * dy + mz * dz
    s1 = 2.0 * k / r5
    s2 = 10.0 * k * xd / r7
    s3 = 10.0 * k * mxd / r7
    s4 = 5.0 * k * q / r7
    s5 = 35.0 * k * q * xd / (r7 * r2)
    return (s1 * md_x - s2 * mx - s3 * x - s4 * dx + s5 * x,
            s1 * md_y - s2 * my - s3 * y - s4 * dy + s5 * y,
            s1 * md_z - s2 * mz - s3 * z - s4 * dz + s5 * z)


@inner_kernel
def direct_terms(rx, ry, rz, vx, vy, vz, tdat, params, layout):
    """Sum [m/s^2] of the terms whose differences :func:`differential_gravity`
    takes directly in float64, apart from the Earth field: the list of
    :func:`tqdyn.forces.model.float64_terms` (the Moon's field truncated at
    degree :data:`MOON_DEGREE_DG`, without its term on the Earth), at the
    position r [m] and velocity v [m/s] of the force model's frame.
    float64; returns (x, y, z)."""
    return float64_terms(0.0, 0.0, 0.0, rx, ry, rz, vx, vy, vz, tdat, params, layout, dynamic(MOON_DEGREE_DG))


@inner_kernel
def differential_gravity(rx, ry, rz, vx, vy, vz, dx, dy, dz, ux, uy, uz, ex, ey, ez, sx, sy, sz,
                         tdat, params, layout):
    """a(r + d, v + u) - a(r, v) [m/s^2] of the force model (see the module
    docstring for the method and its error, ~1e-25 m/s^2).

    r [m], v [m/s]: the satellite's float64 position and velocity, d [m],
    u [m/s]: the point's offset from it (|d| << |r|), all in the force
    model's frame (geocentric GCRS or heliocentric BCRS); e: the float64
    Earth-field part of the satellite's own evaluation
    (:func:`tqdyn.forces.model.gravity_split`); s: :func:`direct_terms` at
    (r, v); tdat, params, layout: the force model's.  float64; returns
    (x, y, z).
    """
    tab = slot_table(layout)
    gx, gy, gz = 0.0, 0.0, 0.0
    if tab[SLOT_CENTRAL_MONOPOLE, 0]:
        o = tab[SLOT_CENTRAL_MONOPOLE, 1]
        px, py, pz = pm_difference(params[o] + params[o + 1], rx, ry, rz, dx, dy, dz)
        gx, gy, gz = gx - px, gy - py, gz - pz
    if tab[SLOT_THIRD_BODY, 0]:
        o, c = tab[SLOT_THIRD_BODY, 1], tab[SLOT_THIRD_BODY, 2]
        n = int(params[o])
        for b in range(n):
            px, py, pz = pm_difference(params[o + 1 + b], tdat[c + 3 * b] - rx, tdat[c + 3 * b + 1] - ry,
                                       tdat[c + 3 * b + 2] - rz, -dx, -dy, -dz)
            gx, gy, gz = gx + px, gy + py, gz + pz
    hx, hy, hz = rx + dx, ry + dy, rz + dz
    wx, wy, wz = vx + ux, vy + uy, vz + uz
    if tab[SLOT_EARTH_FIELD, 0]:
        o, c = tab[SLOT_EARTH_FIELD, 1], tab[SLOT_EARTH_FIELD, 2]
        fx, fy, fz = earth_field_term(layout, (hx, hy, hz, wx, wy, wz, tdat[c:], params[o:]))
        gx, gy, gz = gx + (fx - ex), gy + (fy - ey), gz + (fz - ez)
        ld = int(params[o + 2]) + 1
        if params[o + _EF_HEADER + 2 * ld * ld] != 0.0:  # degree 2 is not in the float64 field: midpoint Jacobian
            t = tdat[c:]
            k, mxx, myy, mzz, mxy, mxz, myz = degree2_matrix(t, params[o:], 1.0)
            x, y, z = itrs_from_gcrs(t, rx + 0.5 * dx, ry + 0.5 * dy, rz + 0.5 * dz)  # the midpoint
            qx, qy, qz = itrs_from_gcrs(t, dx, dy, dz)
            jx, jy, jz = quadrupole_jacobian_product(k, mxx, myy, mzz, mxy, mxz, myz, x, y, z, qx, qy, qz)
            jx, jy, jz = gcrs_from_itrs(t, jx, jy, jz)
            gx, gy, gz = gx + jx, gy + jy, gz + jz
    fx, fy, fz = direct_terms(hx, hy, hz, wx, wy, wz, tdat, params, layout)
    return gx + (fx - sx), gy + (fy - sy), gz + (fz - sz)
