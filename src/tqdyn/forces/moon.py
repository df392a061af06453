"""The Moon's non-spherical gravity field acting on a geocentric orbit, with
the Moon's orientation (physical libration).

Orientation
-----------
T_PA_GCRS from :func:`tqdyn.astro.lunar_orientation.lunar_pa_rotation`: the
DE421 principal axes (lunar PA binary PCK, the default) or the IAU 2009
model mapped into PA (``libration="iau"``); see
:mod:`tqdyn.astro.lunar_orientation`.

Field
-----
GL0660B (JPL GRAIL, Konopliv et al. 2013, JGR Planets 118, 1415), fully
normalised, tide-free C20/C22, degrees 2..n (n <= 20, the shipped file's
limit), in the DE421 PA frame, with GL0660B's own GM and reference radius
(read by :func:`tqdyn.readers.gravity_fields.gl0660b`).  The Moon's monopole is
in the third-body term; this term adds only degrees >= 2, on the satellite
*minus* on the Earth (the geocentric frame is accelerated too):

    a = T_PA_GCRS^T [ g(T_PA_GCRS (r - s)) - g(-T_PA_GCRS s) ],

g the degree-2..n field acceleration at a selenocentric PA position
(:func:`tqdyn.forces.spherical_harmonics.sh_accel`), r the satellite's and s
the Moon's geocentric GCRS position.  GCRS axes are ICRF axes, so
T_PA_GCRS = T_PA_ICRF.  The Earth's part (the second term) depends on time
only and is formed in :meth:`MoonField.precompute`, once per instant rather
than once per body and stage (the kernel then costs one degree-n field
evaluation; ``tqdyn bench --model kernels`` times the term's time-only inputs).  Not included: the reaction of the Moon's
monopole on the Earth's oblateness (the Earth's figure in the Moon's field,
1.1e-11 .. 1.7e-11 m/s^2 on the geocentre in June 2004, twenty times this
term), which belongs with the Earth-field term.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from .._choices import unknown
from ..numerics.jit import dynamic  # (importing numerics.jit registers the package-wide kernel cache)
from ..astro.lunar_orientation import LIBRATIONS, lunar_pa_rotation
from ..astro.timescales import tdb_jd
from .spherical_harmonics import sh_accel
from ..numerics.jit import inner_kernel

__all__ = [
    "MoonField",
    "moon_field_accel",
    "moon_field_direct",
]


# --------------------------------------------------------------------------
# the force term


@inner_kernel
def _field_gcrs(px, py, pz, tdat, params, ntrunc=-1):
    """Field acceleration [m/s^2, GCRS] at the Moon-centred GCRS position
    (px, py, pz) [m]: rotate into PA with tdat[3:12], sh_accel, rotate back;
    degrees 2 .. min(N, ntrunc) (ntrunc < 0: all N of params)."""
    gm, radius = params[0], params[1]
    n1 = int(params[2]) + 1
    nmax = n1 - 1 if ntrunc < 0 or ntrunc > n1 - 1 else ntrunc
    k = n1 * n1
    cnm = params[3:3 + k].reshape((n1, n1))
    snm = params[3 + k:3 + 2 * k].reshape((n1, n1))
    t00, t01, t02 = tdat[3], tdat[4], tdat[5]
    t10, t11, t12 = tdat[6], tdat[7], tdat[8]
    t20, t21, t22 = tdat[9], tdat[10], tdat[11]
    qx = t00 * px + t01 * py + t02 * pz
    qy = t10 * px + t11 * py + t12 * pz
    qz = t20 * px + t21 * py + t22 * pz
    fx, fy, fz = sh_accel(qx, qy, qz, gm, radius, cnm, snm, nmax, dynamic(2))
    return (t00 * fx + t10 * fy + t20 * fz,
            t01 * fx + t11 * fy + t21 * fz,
            t02 * fx + t12 * fy + t22 * fz)


@inner_kernel
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
    ax, ay, az = _field_gcrs(rx - tdat[0], ry - tdat[1], rz - tdat[2], tdat, params, dynamic(-1))
    return ax - tdat[12], ay - tdat[13], az - tdat[14]


@inner_kernel
def moon_field_direct(rx, ry, rz, tdat, params, nmax):
    """The Moon's field on a satellite at (rx, ry, rz) [m, GCRS] alone (no
    term on the Earth), degrees 2 .. min(nmax, N) [m/s^2, GCRS]; tdat and
    params as :func:`moon_field_accel`.  For differences between nearby
    points (:mod:`tqdyn.forces.differential`), where the Earth's term drops
    out.  float64 scalars."""
    return _field_gcrs(rx - tdat[0], ry - tdat[1], rz - tdat[2], tdat, params, nmax)


@njit(cache=True)
def _earth_terms(tdat, params):
    """Fill tdat[:, 12:15] with the field's acceleration of the Earth
    (Moon-centred position -s) [m/s^2, GCRS], for every row of tdat (n, 15)."""
    for i in range(tdat.shape[0]):
        row = tdat[i]
        ax, ay, az = _field_gcrs(-row[0], -row[1], -row[2], row, params, dynamic(-1))
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
    (GCRS, TDB two-part JD), None for :func:`tqdyn.astro.ephemeris.default_ephemeris`.

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
        if self.libration not in LIBRATIONS:
            raise ValueError(unknown("MoonField: libration", self.libration, LIBRATIONS))
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
        TT since epoch]: float64 (*shape(t_hi), 15).  ValueError outside
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
