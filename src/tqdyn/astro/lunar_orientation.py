"""The Moon's orientation (physical libration): the rotation ICRF -> lunar
principal axes (PA) of DE421, or the IAU 2009 model mapped into PA.

Orientation
-----------
* **DE421 principal axes (default).**  The lunar principal-axis (PA) frame
  of the DE421 integration, from the NAIF binary PCK
  ``moon_pa_de421_1900-2050.bpc`` (body 31006, relative to frame 1, which for
  JPL DE data is the ICRF).  Its one segment (type 2, Chebyshev) holds the
  3-1-3 Euler angles (phi, theta, psi) [rad] of the rotation ICRF -> PA; by
  the NAIF PCK Required Reading (pck.req, "Binary PCK ... Euler angles") the
  matrix mapping ICRF vectors into PA is

      T_PA_ICRF = R3(psi) R1(theta) R3(phi),

  R_i(a) the frame (coordinate) rotation by a about axis i
  (R3(a) = [[c, s, 0], [-s, c, 0], [0, 0, 1]], as ``erfa.rz``).  Checked in
  the tests against NAIF's published example (moon_080317.tf: the Earth seen
  from the Moon in MOON_PA at 2008 MAR 17 20:10:00 UTC, printed to 1 m; we
  agree to 0.11 m, i.e. 3e-10 rad).
  Time argument: TDB.  Span: 1900-01-01 to 2051-01-01 (ValueError outside).
* **IAU 2009 (fallback, ``libration="iau"``).**  The WGCCRE 2009 model of
  the Moon (Archinal et al. 2011, Celest. Mech. Dyn. Astr. 109, 101), as in
  NAIF's ``pck00010.tpc``: BODY301_POLE_RA/DEC (T in Julian centuries of TDB
  from J2000), BODY301_PM (d in days), plus the 13 nutation-precession
  angles E1..E13 (BODY3_NUT_PREC_ANGLES, deg and deg/century) with sin terms
  in RA and W and cos terms in DEC.  It gives the *mean Earth/polar axis*
  (ME) frame,

      T_ME_ICRF = R3(W) R1(90 deg - DEC) R3(90 deg + RA).

  The field coefficients live in the PA frame, so the fallback maps ME into
  PA with the constant DE421 rotation of NAIF's moon_080317.tf (frame
  MOON_ME_DE421 = TK frame relative to MOON_PA_DE421, ANGLES = (67.92,
  78.56, 0.30) arcsec, AXES = (3, 2, 1); the TK matrix
  R3(67.92") R2(78.56") R1(0.30") maps ME vectors into PA).  The IAU series
  is a truncation of the libration series: NAIF quotes an ME difference of
  ~0.0051 deg amplitude (18") around a ~0.0025 deg (9") mean for DE421 over
  2000-2020; measured here: 18.4" max and 9.0" mean over 2000-2020, and at
  most 19.3" (9.3e-5 rad) over 1900-2050.  The constant PA-ME offset itself
  is ~104" (5e-4 rad).  (The (67.573", 78.580", 0.285") offset is DE430's
  PA -> ME rotation (Williams et al. 2013, DE430 lunar orbit, physical
  librations and surface coordinates), not DE421's.)

The kernels are read by :mod:`tqdyn.readers.pck`; the lunar gravity field that
these rotations orient is :mod:`tqdyn.forces.moon`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._choices import unknown
from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..readers.pck import IauMoonElements, LunarPaKernel, load_lunar_pa_kernel, read_iau_moon_elements
from .constants import ARCSEC_RAD, J2000_JD

__all__ = [
    "ARCSEC_RAD",
    "LIBRATIONS",
    "T_PA_ME_DE421",
    "lunar_iau_rotation",
    "lunar_pa_euler_angles",
    "lunar_pa_rotation",
]

#: One arcsecond [rad].

#: Days per Julian century.
_CENTURY_D = 36525.0

#: The lunar orientation models (``libration`` of :func:`lunar_pa_rotation`):
#: the DE421 librations (binary PCK) or the IAU rotation elements.
LIBRATIONS = ("de421", "iau")


def _r1(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def _r2(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def _r3(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


#: Constant rotation ME(DE421) -> PA(DE421), (3, 3): maps mean-Earth/polar-axis
#: vectors into the principal-axis frame.  NAIF moon_080317.tf, TKFRAME_31007:
#: ANGLES = (67.92, 78.56, 0.30) arcsec, AXES = (3, 2, 1) (from Williams,
#: Boggs & Folkner, DE421 lunar orbit, physical librations and surface
#: coordinates, JPL IOM 335-JW,DB,WF-20080314-001).  The order and signs are
#: fixed by NAIF's own example output in that kernel (see the tests).
T_PA_ME_DE421 = _r3(67.92 * ARCSEC_RAD) @ _r2(78.56 * ARCSEC_RAD) @ _r1(0.30 * ARCSEC_RAD)


@njit(cache=True)
def _euler313_into(phi, theta, psi, pre, rot, i):
    """rot[i, :] = (pre @ R3(psi) R1(theta) R3(phi)) row-major, angles [rad],
    pre (3, 3) a constant left factor (the identity for none)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    m00, m01, m02 = cp * cf - sp * ct * sf, cp * sf + sp * ct * cf, sp * st
    m10, m11, m12 = -sp * cf - cp * ct * sf, -sp * sf + cp * ct * cf, cp * st
    m20, m21, m22 = st * sf, -st * cf, ct
    for r in range(3):
        p0, p1, p2 = pre[r, 0], pre[r, 1], pre[r, 2]
        rot[i, 3 * r] = p0 * m00 + p1 * m10 + p2 * m20
        rot[i, 3 * r + 1] = p0 * m01 + p1 * m11 + p2 * m21
        rot[i, 3 * r + 2] = p0 * m02 + p1 * m12 + p2 * m22


_EYE3 = np.eye(3)


def _jd_pair(jd1, jd2):
    """Two-part dates as broadcast float64 arrays."""
    jd1 = np.asarray(jd1, dtype=np.float64)
    jd2 = np.asarray(jd2, dtype=np.float64)
    return np.broadcast_arrays(jd1, jd2)


# --------------------------------------------------------------------------
# DE421 principal axes (binary PCK Euler angles)


@njit(cache=True)
def _pa_eval(coef, init, intlen, jd1, jd2, ang, rot):
    """Chebyshev evaluation of the PA Euler angles and their matrix.

    coef (n_rec, 3, n_coef), init [s], intlen [s]: see :class:`tqdyn.readers.pck.LunarPaKernel`;
    jd1, jd2 (n,): two-part TDB JD inside the span (checked by the caller).
    Writes ang (n, 3) = (phi, theta, psi) [rad] and rot (n, 9) = R3(psi)
    R1(theta) R3(phi) row-major.  The time in the record is formed as
    ((jd1 - J2000) 86400 - init - k intlen) + jd2 86400, exact up to the
    last addition for jd1 on a half day.
    """
    n_rec, _, n_coef = coef.shape
    tk = np.empty(n_coef)
    for i in range(jd1.shape[0]):
        a = (jd1[i] - J2000_JD) * 86400.0 - init
        b = jd2[i] * 86400.0
        k = int(math.floor((a + b) / intlen))
        k = min(max(k, 0), n_rec - 1)  # the end point belongs to the last record
        s = ((a - k * intlen) + b) * (2.0 / intlen) - 1.0
        tk[0] = 1.0
        if n_coef > 1:
            tk[1] = s
        for j in range(2, n_coef):
            tk[j] = 2.0 * s * tk[j - 1] - tk[j - 2]
        for c in range(3):
            acc = 0.0
            for j in range(n_coef - 1, -1, -1):  # small terms first
                acc += coef[k, c, j] * tk[j]
            ang[i, c] = acc
        _euler313_into(ang[i, 0], ang[i, 1], ang[i, 2], _EYE3, rot, i)


def _pa_angles_and_matrix(jd1, jd2, kernel):
    """(angles (..., 3) [rad], T_PA_ICRF (..., 3, 3)) from the PA kernel."""
    k = load_lunar_pa_kernel() if kernel is None else kernel
    jd1, jd2 = _jd_pair(jd1, jd2)
    shape = jd1.shape
    j1 = np.ascontiguousarray(jd1.ravel())
    j2 = np.ascontiguousarray(jd2.ravel())
    jd = j1 + j2
    if jd.size and (jd.min() < k.start_jd or jd.max() > k.end_jd):
        bad = jd.min() if jd.min() < k.start_jd else jd.max()
        raise ValueError(
            f"lunar PA orientation: TDB JD {bad:.6f} is outside the kernel span "
            f"JD {k.start_jd:.1f} .. {k.end_jd:.1f} of {k.source} (1900-01-01 .. 2051-01-01 for DE421)")
    ang = np.empty((j1.size, 3))
    rot = np.empty((j1.size, 9))
    _pa_eval(k.coef, k.init, k.intlen, j1, j2, ang, rot)
    return ang.reshape(shape + (3,)), rot.reshape(shape + (3, 3))


# --------------------------------------------------------------------------
# orientation


def lunar_pa_euler_angles(jd1, jd2, kernel: LunarPaKernel | None = None) -> np.ndarray:
    """Euler angles (phi, theta, psi) [rad] of the 3-1-3 rotation ICRF -> PA
    (DE421) at two-part TDB Julian dates jd1 + jd2 [d] (arrays, broadcast).

    kernel: from :func:`tqdyn.readers.pck.load_lunar_pa_kernel` (None: the shipped DE421
    kernel).  Returns (..., 3) float64.  Raises ValueError for dates outside
    the kernel's span (1900-01-01 .. 2051-01-01 TDB for DE421).
    """
    return _pa_angles_and_matrix(jd1, jd2, kernel)[0]


def lunar_iau_rotation(jd1, jd2, elements: IauMoonElements | None = None) -> np.ndarray:
    """T_ME_ICRF: ICRF -> lunar mean-Earth/polar-axis frame of the IAU 2009
    (WGCCRE) model, at two-part TDB Julian dates jd1 + jd2 [d].

    elements: from :func:`tqdyn.readers.pck.read_iau_moon_elements` (None: pck00010.tpc).
    Returns (..., 3, 3) float64 (rows: ME axes in ICRF).  No span limit (the
    model is a series; NAIF states its DE421 agreement for 2000-2020 as
    ~18" amplitude; see the module docstring).
    """
    return _iau_matrix(jd1, jd2, elements, _EYE3)


def _iau_matrix(jd1, jd2, elements, pre):
    el = read_iau_moon_elements() if elements is None else elements
    jd1, jd2 = _jd_pair(jd1, jd2)
    d = np.ascontiguousarray(((jd1 - J2000_JD) + jd2).ravel())  # days of TDB since J2000
    rot = np.empty((d.size, 9))
    _iau_eval(d, np.ascontiguousarray(el.angles), el.ra, el.dec, el.pm, el.nut_ra, el.nut_dec, el.nut_pm,
              np.ascontiguousarray(pre), rot)
    return rot.reshape(jd1.shape + (3, 3))


@njit(cache=True)
def _iau_eval(d, angles, ra_p, dec_p, pm_p, nut_ra, nut_dec, nut_pm, pre, rot):
    """IAU model at d [days of TDB since J2000] (n,) -> rot (n, 9) = pre @
    R3(W) R1(90 deg - DEC) R3(90 deg + RA) row-major; the element arrays as
    in :class:`tqdyn.readers.pck.IauMoonElements` [deg].  One sin/cos per angle and instant."""
    k = angles.shape[0]
    rad = np.pi / 180.0
    for i in range(d.shape[0]):
        t = d[i] / _CENTURY_D
        ra = ra_p[0] + t * (ra_p[1] + t * ra_p[2])
        dec = dec_p[0] + t * (dec_p[1] + t * dec_p[2])
        w = (pm_p[0] + d[i] * (pm_p[1] + d[i] * pm_p[2])) % 360.0
        for j in range(k):
            e = (angles[j, 0] + angles[j, 1] * t) * rad
            se, ce = math.sin(e), math.cos(e)
            ra += nut_ra[j] * se
            dec += nut_dec[j] * ce
            w += nut_pm[j] * se
        _euler313_into((90.0 + ra) * rad, (90.0 - dec) * rad, w * rad, pre, rot, i)


def lunar_pa_rotation(jd1, jd2, libration: str = "de421", kernel=None) -> np.ndarray:
    """T_PA_ICRF: ICRF -> lunar principal-axis frame (DE421 realisation) at
    two-part TDB Julian dates jd1 + jd2 [d] (arrays, broadcast).

    libration: ``"de421"`` -- R3(psi) R1(theta) R3(phi) from the DE421 Euler
    angles (the default; span 1900-2050, ValueError outside); ``"iau"`` --
    T_PA_ME_DE421 @ :func:`lunar_iau_rotation` (the IAU 2009 ME model mapped
    into PA with the constant DE421 offset; <= 19.3" = 9.3e-5 rad from
    DE421 over 1900-2050).  kernel: for "de421", from
    :func:`tqdyn.readers.pck.load_lunar_pa_kernel` (None: the shipped DE421 kernel).
    Returns (..., 3, 3) float64; GCRS vectors map the same way (ICRF axes).
    """
    if libration == "de421":
        return _pa_angles_and_matrix(jd1, jd2, kernel)[1]
    if libration == "iau":
        return _iau_matrix(jd1, jd2, None, T_PA_ME_DE421)
    raise ValueError(unknown("lunar orientation: libration", libration, LIBRATIONS))
