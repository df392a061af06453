"""The Moon's non-spherical gravity field acting on a geocentric orbit, with
the Moon's orientation (physical libration).

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

Field
-----
GL0660B (JPL GRAIL, Konopliv et al. 2013, JGR Planets 118, 1415), fully
normalised, tide-free C20/C22, degrees 2..n (n <= 20, the shipped file's
limit), in the DE421 PA frame, with GL0660B's own GM and reference radius
(read by :func:`tqdyn.forces.gravity_models.gl0660b`).  The Moon's monopole is
in the third-body term; this term adds only degrees >= 2, on the satellite
*minus* on the Earth (the geocentric frame is accelerated too):

    a = T_PA_GCRS^T [ g(T_PA_GCRS (r - s)) - g(-T_PA_GCRS s) ],

g the degree-2..n field acceleration at a selenocentric PA position
(:func:`tqdyn.forces.spherical_harmonics.sh_accel`), r the satellite's and s
the Moon's geocentric GCRS position.  GCRS axes are ICRF axes, so
T_PA_GCRS = T_PA_ICRF.  The Earth's part (the second term) depends on time
only and is formed in :meth:`MoonField.precompute`, once per instant rather
than once per body and stage (the kernel then costs one degree-n field
evaluation, ~0.4 us at n = 7).  Not included: the reaction of the Moon's
monopole on the Earth's oblateness (the Earth's figure in the Moon's field,
1.1e-11 .. 1.7e-11 m/s^2 on the geocentre in June 2004, twenty times this
term), which belongs with the Earth-field term.
"""

from __future__ import annotations

import functools
import importlib.resources
import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..astro.constants import J2000_JD
from ..astro.timescales import tdb_jd
from ..readers.naif import read_text_kernel
from .spherical_harmonics import sh_accel

__all__ = [
    "ARCSEC_RAD",
    "IauMoonElements",
    "LunarPaKernel",
    "MoonField",
    "T_PA_ME_DE421",
    "load_lunar_pa_kernel",
    "lunar_iau_rotation",
    "lunar_pa_euler_angles",
    "lunar_pa_rotation",
    "moon_field_accel",
    "read_iau_moon_elements",
]

#: One arcsecond [rad].
ARCSEC_RAD = np.pi / 648000.0

#: Default data files (in ``tqdyn/data``).
_PA_KERNEL = "moon_pa_de421_1900-2050.bpc"
_IAU_KERNEL = "pck00010.tpc"

#: NAIF body code of the DE421 lunar PA frame in the binary PCK, and the
#: frame its angles are relative to (1 = "J2000", which for DE data is ICRF).
_PA_BODY = 31006
_PA_FRAME = 1

#: Days per Julian century.
_CENTURY_D = 36525.0

_LIBRATIONS = ("de421", "iau")


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
# readers


@dataclass(frozen=True, eq=False)
class LunarPaKernel:
    """The Euler-angle segment of a lunar PA binary PCK, in memory.

    coef: (n_rec, 3, n_coef) float64 Chebyshev coefficients [rad] of
    (phi, theta, psi) per record; init [s of TDB past J2000], intlen [s]:
    start and length of the records; start_jd, end_jd: the segment's span
    [TDB Julian date]; source: file name.
    """

    coef: np.ndarray
    init: float
    intlen: float
    start_jd: float
    end_jd: float
    source: str


@functools.lru_cache(maxsize=4)
def load_lunar_pa_kernel(path=None) -> LunarPaKernel:
    """Read the Euler-angle segment of a lunar PA binary PCK.

    path: file path, or None for the shipped DE421 kernel
    ``tqdyn/data/moon_pa_de421_1900-2050.bpc``.  The segment must be type 2
    (Chebyshev, angles only), body 31006 relative to frame 1 (ICRF); its
    records are [MID, RADIUS, 3 x n_coef coefficients] with the trailer
    (init, intlen, rsize, n) (NAIF pck.req; read with jplephem's DAF reader).
    Cached.  Raises FileNotFoundError, or ValueError if no such segment.
    """
    from jplephem.pck import PCK

    src = importlib.resources.files("tqdyn") / "data" / _PA_KERNEL if path is None else path
    try:
        kernel = PCK.open(str(src))
    except FileNotFoundError:
        raise FileNotFoundError(f"lunar PA kernel not found: {src}") from None
    for seg in kernel.segments:
        if seg.body == _PA_BODY and seg.frame == _PA_FRAME and seg.data_type == 2:
            init, intlen, rsize, n = seg.daf.read_array(seg.end_i - 3, seg.end_i)
            rsize, n = int(rsize), int(n)
            raw = seg.daf.map_array(seg.start_i, seg.end_i - 4).reshape(n, rsize)
            coef = np.ascontiguousarray(raw[:, 2:].reshape(n, 3, (rsize - 2) // 3), dtype=np.float64)
            coef.setflags(write=False)
            return LunarPaKernel(coef, float(init), float(intlen), float(seg.initial_jd), float(seg.final_jd),
                                 str(getattr(src, "name", src)))
    found = [(s.body, s.frame, s.data_type) for s in kernel.segments]
    raise ValueError(
        f"lunar PA kernel {src}: no type-2 segment of body {_PA_BODY} relative to frame {_PA_FRAME} "
        f"(ICRF); found (body, frame, type) = {found}")


@njit(cache=True)
def _pa_eval(coef, init, intlen, jd1, jd2, ang, rot):
    """Chebyshev evaluation of the PA Euler angles and their matrix.

    coef (n_rec, 3, n_coef), init [s], intlen [s]: see LunarPaKernel;
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


@dataclass(frozen=True)
class IauMoonElements:
    """IAU (WGCCRE 2009) rotational elements of the Moon, as in a NAIF text PCK.

    All angles in degrees.  ra, dec: (3,) polynomial coefficients in T
    [Julian centuries of TDB since J2000] (deg, deg/cy, deg/cy^2); pm: (3,)
    coefficients in d [days of TDB since J2000] (deg, deg/d, deg/d^2);
    nut_ra, nut_dec, nut_pm: (k,) amplitudes [deg] of sin(E_j), cos(E_j),
    sin(E_j); angles: (k, 2) E_j = angles[j, 0] + angles[j, 1] T [deg, deg/cy].
    """

    ra: np.ndarray
    dec: np.ndarray
    pm: np.ndarray
    nut_ra: np.ndarray
    nut_dec: np.ndarray
    nut_pm: np.ndarray
    angles: np.ndarray


def _poly3(values, name) -> np.ndarray:
    v = np.zeros(3)
    if not 1 <= len(values) <= 3:
        raise ValueError(f"{name}: expected 1 to 3 polynomial coefficients, got {len(values)}")
    v[: len(values)] = values
    return v


@functools.lru_cache(maxsize=4)
def read_iau_moon_elements(path=None) -> IauMoonElements:
    """Read the Moon's IAU rotational elements (BODY301_POLE_RA, _POLE_DEC,
    _PM, _NUT_PREC_RA/_DEC/_PM and BODY3_NUT_PREC_ANGLES) from a NAIF text PCK.

    path: file path, or None for the shipped ``tqdyn/data/pck00010.tpc``.
    Raises FileNotFoundError, or ValueError naming a missing variable.
    """
    src = importlib.resources.files("tqdyn") / "data" / _IAU_KERNEL if path is None else path
    k = read_text_kernel(src)
    need = ["BODY301_POLE_RA", "BODY301_POLE_DEC", "BODY301_PM", "BODY301_NUT_PREC_RA",
            "BODY301_NUT_PREC_DEC", "BODY301_NUT_PREC_PM", "BODY3_NUT_PREC_ANGLES"]
    missing = [n for n in need if n not in k]
    if missing:
        raise ValueError(f"IAU Moon elements: {src} lacks {', '.join(missing)}")
    ang = np.asarray(k["BODY3_NUT_PREC_ANGLES"], dtype=np.float64)
    if ang.size % 2:
        raise ValueError(f"IAU Moon elements: BODY3_NUT_PREC_ANGLES has {ang.size} values, expected pairs")
    ang = ang.reshape(-1, 2)
    nut = [np.zeros(len(ang)) for _ in range(3)]
    for arr, nm in zip(nut, need[3:6]):
        vals = np.asarray(k[nm], dtype=np.float64)
        if vals.size > len(ang):
            raise ValueError(f"IAU Moon elements: {nm} has {vals.size} terms but only {len(ang)} angles are defined")
        arr[: vals.size] = vals
    return IauMoonElements(
        ra=_poly3(k["BODY301_POLE_RA"], "BODY301_POLE_RA"),
        dec=_poly3(k["BODY301_POLE_DEC"], "BODY301_POLE_DEC"),
        pm=_poly3(k["BODY301_PM"], "BODY301_PM"),
        nut_ra=nut[0], nut_dec=nut[1], nut_pm=nut[2], angles=ang)


# --------------------------------------------------------------------------
# orientation


def lunar_pa_euler_angles(jd1, jd2, kernel: LunarPaKernel | None = None) -> np.ndarray:
    """Euler angles (phi, theta, psi) [rad] of the 3-1-3 rotation ICRF -> PA
    (DE421) at two-part TDB Julian dates jd1 + jd2 [d] (arrays, broadcast).

    kernel: from :func:`load_lunar_pa_kernel` (None: the shipped DE421
    kernel).  Returns (..., 3) float64.  Raises ValueError for dates outside
    the kernel's span (1900-01-01 .. 2051-01-01 TDB for DE421).
    """
    return _pa_angles_and_matrix(jd1, jd2, kernel)[0]


def lunar_iau_rotation(jd1, jd2, elements: IauMoonElements | None = None) -> np.ndarray:
    """T_ME_ICRF: ICRF -> lunar mean-Earth/polar-axis frame of the IAU 2009
    (WGCCRE) model, at two-part TDB Julian dates jd1 + jd2 [d].

    elements: from :func:`read_iau_moon_elements` (None: pck00010.tpc).
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
    in :class:`IauMoonElements` [deg].  One sin/cos per angle and instant."""
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
    :func:`load_lunar_pa_kernel` (None: the shipped DE421 kernel).
    Returns (..., 3, 3) float64; GCRS vectors map the same way (ICRF axes).
    """
    if libration == "de421":
        return _pa_angles_and_matrix(jd1, jd2, kernel)[1]
    if libration == "iau":
        return _iau_matrix(jd1, jd2, None, T_PA_ME_DE421)
    raise ValueError(f"lunar orientation: libration {libration!r} is not one of {_LIBRATIONS}")


# --------------------------------------------------------------------------
# the force term


@njit(cache=True)
def _field_gcrs(px, py, pz, tdat, params):
    """Field acceleration [m/s^2, GCRS] at the Moon-centred GCRS position
    (px, py, pz) [m]: rotate into PA with tdat[3:12], sh_accel, rotate back."""
    gm, radius = params[0], params[1]
    nmax = int(params[2])
    n1 = nmax + 1
    k = n1 * n1
    cnm = params[3:3 + k].reshape((n1, n1))
    snm = params[3 + k:3 + 2 * k].reshape((n1, n1))
    t00, t01, t02 = tdat[3], tdat[4], tdat[5]
    t10, t11, t12 = tdat[6], tdat[7], tdat[8]
    t20, t21, t22 = tdat[9], tdat[10], tdat[11]
    qx = t00 * px + t01 * py + t02 * pz
    qy = t10 * px + t11 * py + t12 * pz
    qz = t20 * px + t21 * py + t22 * pz
    fx, fy, fz = sh_accel(qx, qy, qz, gm, radius, cnm, snm, nmax, 2)
    return (t00 * fx + t10 * fy + t20 * fz,
            t01 * fx + t11 * fy + t21 * fz,
            t02 * fx + t12 * fy + t22 * fz)


@njit(cache=True)
def moon_field_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Geocentric acceleration [m/s^2, GCRS] of a satellite at (rx, ry, rz)
    [m, GCRS] from the Moon's degree >= 2 field: field on the satellite minus
    field on the Earth (the velocity is not used).  float64 scalars.

    tdat (15,): the Moon's geocentric GCRS position s [m] (3), T_PA_GCRS
    row-major (9), and the field's (time-only) acceleration of the Earth
    [m/s^2, GCRS] (3) -- see :meth:`MoonField.precompute`.  params:
    [gm (m^3/s^2), radius (m), nmax, C (nmax+1)^2 row-major, S (nmax+1)^2
    row-major] (fully normalised, PA frame).
    """
    ax, ay, az = _field_gcrs(rx - tdat[0], ry - tdat[1], rz - tdat[2], tdat, params)
    return ax - tdat[12], ay - tdat[13], az - tdat[14]


@njit(cache=True)
def _earth_terms(tdat, params):
    """Fill tdat[:, 12:15] with the field's acceleration of the Earth
    (Moon-centred position -s) [m/s^2, GCRS], for every row of tdat (n, 15)."""
    for i in range(tdat.shape[0]):
        row = tdat[i]
        ax, ay, az = _field_gcrs(-row[0], -row[1], -row[2], row, params)
        row[12], row[13], row[14] = ax, ay, az


@functools.lru_cache(maxsize=8)
def _gl0660b(degree: int):
    from ..readers.gravity_fields import gl0660b

    return gl0660b(nmax=degree)


def _default_ephemeris():
    from ..astro.ephemeris import default_ephemeris

    return default_ephemeris()


def _positions(eph, body, jd1, jd2) -> np.ndarray:
    """Geocentric GCRS position [m] of ``body`` from an ephemeris object,
    (*shape(jd1), 3); positions only when the object can skip velocities."""
    if hasattr(eph, "geocentric_states"):
        return np.asarray(eph.geocentric_states((body,), jd1, jd2, velocity=False)[0][..., 0, :], dtype=np.float64)
    return np.asarray(eph.geocentric(body, jd1, jd2)[0], dtype=np.float64)


@functools.lru_cache(maxsize=8)
def _moon_params(degree: int) -> np.ndarray:
    """[gm, radius, degree, C (degree+1)^2, S (degree+1)^2] of GL0660B,
    degrees 0 and 1 zeroed (cached; callers must not modify it)."""
    m = _gl0660b(degree)
    n1 = degree + 1
    c = np.array(m.C, dtype=np.float64)[:n1, :n1].copy()
    s = np.array(m.S, dtype=np.float64)[:n1, :n1].copy()
    if c.shape != (n1, n1) or s.shape != (n1, n1):
        raise ValueError(f"MoonField: GL0660B model holds C {c.shape}, S {s.shape}; degree {degree} needs ({n1}, {n1})")
    c[:2, :] = 0.0  # monopole and degree 1: not part of this term
    s[:2, :] = 0.0
    return np.concatenate([[float(m.gm), float(m.radius), float(degree)], c.ravel(), s.ravel()])


@dataclass(frozen=True)
class MoonField:
    """The Moon's non-central gravity field (GL0660B degrees 2..degree, PA
    frame) on the geocentric orbit: satellite minus Earth (indirect) term.

    degree: maximum degree, 2 <= degree <= 20 (the shipped GL0660B file's
    limit); libration: ``"de421"`` (DE421 PA Euler angles, default) or
    ``"iau"`` (IAU 2009 ME model + constant DE421 PA-ME offset); ephemeris:
    an object with ``geocentric(body, jd1, jd2) -> (pos [m], vel [m/s])``
    (GCRS, TDB two-part JD), None for :func:`tqdyn.ephemeris.default_ephemeris`.

    Parameters handed to the compiled model: see :func:`moon_field_accel`;
    time-only inputs (15 columns): the Moon's geocentric GCRS position [m],
    T_PA_GCRS row-major, and the field's acceleration of the Earth [m/s^2,
    GCRS] (time-only, so it is formed once per instant here instead of once
    per body and stage in the kernel: it halves the kernel's cost).
    """

    degree: int = 7
    libration: str = "de421"
    ephemeris: object = None
    name: str = field(default="moon_field", init=False)
    description: str = field(
        default="Moon's gravity field degrees 2..n (PA frame, libration), satellite minus Earth", init=False)
    source: str = field(
        default="GL0660B (Konopliv et al. 2013), tide-free, PA frame; orientation: DE421 lunar PA "
                "Euler angles (NAIF moon_pa_de421_1900-2050.bpc) or IAU 2009 (pck00010.tpc) with the "
                "DE421 ME->PA offset (NAIF moon_080317.tf)", init=False)
    n_tdat: int = field(default=15, init=False)

    def __post_init__(self):
        if isinstance(self.degree, bool) or not isinstance(self.degree, (int, np.integer)):
            raise ValueError(f"MoonField: degree must be an integer, got {self.degree!r}")
        if self.degree < 2:
            raise ValueError(f"MoonField: degree {self.degree} < 2 (the monopole is the third-body term)")
        if self.libration not in _LIBRATIONS:
            raise ValueError(f"MoonField: libration {self.libration!r} is not one of {_LIBRATIONS}")
        self.model()  # ValueError now if the degree exceeds the coefficient file's

    def model(self):
        """The GL0660B model truncated at ``degree`` (gm [m^3/s^2], radius [m],
        fully normalised C, S); ValueError if the degree exceeds the file's."""
        return _gl0660b(int(self.degree))

    def params(self) -> np.ndarray:
        """[gm, radius, degree, C.ravel(), S.ravel()] float64, C and S
        (degree+1, degree+1) fully normalised, degrees 0 and 1 set to zero."""
        return self._params().copy()

    def _params(self) -> np.ndarray:
        return _moon_params(int(self.degree))

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """[Moon position (3) [m, GCRS], T_PA_GCRS row-major (9), the field's
        acceleration of the Earth (3) [m/s^2, GCRS]] at t = t_hi + t_lo [s
        TDB since epoch]: float64 (*shape(t_hi), 15).  ValueError outside
        the ephemeris or (de421) the lunar kernel span."""
        jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
        eph = _default_ephemeris() if self.ephemeris is None else self.ephemeris
        pos = _positions(eph, "moon", jd1, jd2)
        rot = lunar_pa_rotation(jd1, jd2, self.libration)
        shape = jd1.shape
        if pos.shape != shape + (3,):
            raise ValueError(f"MoonField: ephemeris returned Moon positions of shape {pos.shape}, expected {shape + (3,)}")
        out = np.empty(shape + (15,))
        out[..., :3] = pos
        out[..., 3:12] = rot.reshape(shape + (9,))
        flat = out.reshape(-1, 15)  # a view (out is contiguous)
        _earth_terms(flat, self._params())
        return out
