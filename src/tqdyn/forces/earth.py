"""The Earth's non-spherical gravity field (static EGM2008 + time-variable
coefficient corrections), as a tqdyn force term.

The satellite's geocentric GCRS position r is rotated into the ITRS,
r_ITRS = T_ITRS_GCRS r, the acceleration of the spherical-harmonic field of
degrees 2 .. N (orders 0 .. M) is evaluated there
(:func:`tqdyn.forces.spherical_harmonics.sh_accel_flat`, float64) and
rotated back, a_GCRS = T_ITRS_GCRS^T a_ITRS.  The monopole (degree 0) is the
separate extended-precision term :class:`tqdyn.forces.central.EarthMonopole`;
degree 1 vanishes (geocentric ITRS origin).

Time-only inputs (:meth:`EarthField.precompute`, once per chunk of
instants): the rotation matrix T_ITRS_GCRS (9 values, row-major), by default
from ``tqdyn.astro.earth_orientation.earth_orientation(epoch, t_hi, t_lo).T_ITRS_GCRS``
(IAU 2006/2000A + EOP), and the sum of the coefficient corrections dC, dS
of the tide providers in ``tides`` (solid, ocean, pole, atmospheric tides),
each a callable (epoch, t_hi, t_lo) -> (dC, dS) of shape (..., k+1, k+1)
(fully normalised, referred to this field's GM and radius), zero-padded to
the largest degree nt and summed.  The corrections are added to the static
coefficients inside the compiled kernel, so the tides cost no extra
harmonic synthesis.

Permanent tide: the default static field is EGM2008 **tide-free**, which is
consistent with an IERS 2010 solid-tide model that keeps the permanent
(time-average) part of its dC20 (TN36 sec. 6.2 step 1 as computed).  With a
zero-tide field the solid-tide model must remove it (TN36 eq. 6.14).  See
:mod:`tqdyn.readers.gravity_fields`.  A tide provider may declare
``permanent_tide = "included"`` or ``"removed"``; :class:`EarthField`
rejects a combination that counts the permanent deformation zero or two
times.

Magnitudes along a TianQin orbit (r = 1e8 m, i = 74.5 deg, EGM2008, max
over one revolution, tests/test_spherical_harmonics.py): degree 2
4.9e-7 m/s^2, 3: 2.7e-10, 4: 1.1e-11, 5: 5.8e-13, 6: 3.7e-14, 7: 2.5e-15,
8: 1.1e-16, ..., 12: 7.7e-22 m/s^2 (each degree ~ (R/r) ~ 0.064 smaller).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numba import njit

from .._choices import unknown
from ..numerics.jit import dynamic  # (importing numerics.jit registers the package-wide kernel cache)
from ..numerics.dd import add, const, div, mul, sqrt, sub
from ..readers.gravity_fields import GravityModel, egm2008
from .spherical_harmonics import NMAX_SH, sh_accel_flat
from ..numerics.jit import inner_kernel

__all__ = [
    "EarthField",
    "earth_field_accel",
    "earth_field_static_accel",
    "earth_tides_accel",
    "earth_field_accel_batch",
    "degree2_matrix",
    "itrs_from_gcrs",
    "gcrs_from_itrs",
    "degree2_accel_ext",
    "j2_jerk_gcrs_z",
    "PARAM_HEADER",
    "N_ROT",
]

#: Leading entries of :meth:`EarthField.params`: gm, radius, N, M, nt.
PARAM_HEADER = 5
#: Leading time-only inputs: T_ITRS_GCRS row-major.
N_ROT = 9


def _frames_rotation(epoch, t_hi, t_lo):
    """T_ITRS_GCRS (..., 3, 3) from :func:`tqdyn.astro.earth_orientation.earth_orientation`."""
    try:
        from ..astro.earth_orientation import earth_orientation
    except ImportError as exc:
        raise ImportError("EarthField: tqdyn.astro.earth_orientation.earth_orientation is not available; "
                          "pass a rotation provider (rotation=...)") from exc
    return earth_orientation(epoch, t_hi, t_lo).T_ITRS_GCRS


def _pack(out, col, c, filled, lt):
    """Packed lower triangle of c (n_inst, k+1, k+1) into out[:, col:col+lt]
    (index n (n+1)/2 + m): added to the entries of degree <= filled, stored
    into the others; entries beyond degree k are zeroed if filled < 0."""
    j = col
    for n in range(c.shape[1]):  # row n: entries n (n+1)/2 .. n (n+1)/2 + n, held iff n <= filled
        if n <= filled:
            out[:, j:j + n + 1] += c[:, n, :n + 1]
        else:
            out[:, j:j + n + 1] = c[:, n, :n + 1]
        j += n + 1
    if filled < 0:
        out[:, j:col + lt] = 0.0


def _provider_degree(p):
    for attr in ("degree", "nmax", "max_degree"):
        d = getattr(p, attr, None)
        if d is not None:
            return int(d)
    return None


@dataclass(frozen=True)
class EarthField:
    """The Earth's gravity field beyond the monopole, GCRS, geocentric.

    Parameters
    ----------
    degree : int
        Highest degree N of the static field (2 <= N <= the model's degree,
        90 for the shipped EGM2008).  Default 12 (the paper's Table II).
    order : int, optional
        Highest order M (default: N).
    model : GravityModel, optional
        Static field (body-fixed frame ITRS).  Default:
        ``egm2008(degree)``, tide-free.
    tides : tuple of callables
        Coefficient-correction providers (epoch, t_hi, t_lo) -> (dC, dS),
        float64 arrays (*shape(t_hi), k+1, k+1), fully normalised, ITRS,
        at t = t_hi + t_lo [s TT since epoch].  Each must expose its degree
        k as an attribute ``degree`` (or ``nmax``), unless ``tide_degree``
        is given.
    rotation : callable, optional
        (epoch, t_hi, t_lo) -> T_ITRS_GCRS (*shape(t_hi), 3, 3) float64
        (maps GCRS vectors into ITRS).  Default:
        ``tqdyn.astro.earth_orientation.earth_orientation(...).T_ITRS_GCRS``.
    tide_degree : int, optional
        Degree nt of the summed corrections (default: the largest degree of
        the providers; -1 if there are none).

    extended_degree2 : bool
        Leave degree 2 (static + corrections) to :func:`degree2_accel_ext`,
        which the model evaluates in extended precision.

    Compiled-model interface: ``params()`` = [gm, radius, N, M, nt,
    C (N+1)^2 row-major, S (N+1)^2 row-major, extended_degree2 (1.0/0.0)]; time-only inputs
    (``n_tdat`` = 9 + (nt+1)(nt+2) per instant) = [T_ITRS_GCRS row-major
    (9), dC and dS as packed lower triangles ((nt+1)(nt+2)/2 each, dC_nm
    at n (n+1)/2 + m)]; kernel :func:`earth_field_accel`.
    """

    degree: int = 12
    order: int | None = None
    model: GravityModel | None = None
    tides: tuple = ()
    rotation: Callable | None = None
    tide_degree: int | None = None
    extended_degree2: bool = False
    name: str = field(default="earth_field", init=False)
    description: str = field(
        default="Earth spherical harmonics, degrees 2..N (+ tidal coefficient corrections), ITRS via T_ITRS_GCRS",
        init=False)
    source: str = field(default="EGM2008 (Pavlis et al. 2012), tide-free, fully normalised, to degree 90 shipped",
                        init=False)

    def __post_init__(self):
        deg = self.degree
        if isinstance(deg, bool) or not isinstance(deg, (int, np.integer)):
            raise ValueError(f"EarthField: degree must be an integer, got {deg!r}")
        deg = int(deg)
        model = self.model
        if model is None:
            if deg > 90:
                raise ValueError(f"EarthField: degree {deg} requested, but the shipped EGM2008 holds degrees up to 90 only")
            if deg < 2:
                raise ValueError(f"EarthField: degree {deg} < 2 (degrees 0 and 1 are not part of this term)")
            model = egm2008(deg)
        if deg < 2:
            raise ValueError(f"EarthField: degree {deg} < 2 (degrees 0 and 1 are not part of this term)")
        if deg > model.nmax:
            raise ValueError(f"EarthField: degree {deg} requested, but {model.name} holds degrees up to {model.nmax} only")
        order = deg if self.order is None else int(self.order)
        if not 0 <= order <= deg:
            raise ValueError(f"EarthField: order {order} must be between 0 and the degree {deg}")
        tides = tuple(self.tides)
        nt = self.tide_degree
        if nt is None:
            degs = [_provider_degree(p) for p in tides]
            if any(d is None for d in degs):
                raise ValueError("EarthField: a tide provider has no 'degree' attribute; pass tide_degree=")
            nt = max(degs) if degs else -1
        nt = int(nt)
        if tides and not 2 <= nt <= NMAX_SH:
            raise ValueError(f"EarthField: tide degree {nt} must be between 2 and {NMAX_SH}")
        for p in tides:
            perm = getattr(p, "permanent_tide", None)
            if perm == "included" and model.tide_system == "zero_tide":
                raise ValueError("EarthField: a zero-tide static field with a tide model that includes the "
                                 "permanent tide counts the permanent deformation twice; use the tide-free field")
            if perm == "removed" and model.tide_system == "tide_free":
                raise ValueError("EarthField: a tide-free static field with a tide model that removes the "
                                 "permanent tide omits the permanent deformation; use the zero-tide field")
        object.__setattr__(self, "degree", deg)
        object.__setattr__(self, "order", order)
        object.__setattr__(self, "model", model.truncated(deg))
        object.__setattr__(self, "tides", tides)
        object.__setattr__(self, "tide_degree", nt)
        object.__setattr__(self, "source", f"{model.name} ({model.tide_system}), degree {deg}, order {order}: "
                                           f"{model.source}")

    @property
    def n_tdat(self) -> int:
        """Time-only inputs per instant: 9 (rotation) + (nt+1)(nt+2)
        (corrections dC, dS as packed lower triangles)."""
        nt = self.tide_degree
        return N_ROT + (nt + 1) * (nt + 2)

    def params(self) -> np.ndarray:
        """[gm, radius, N, M, nt, C (N+1)^2, S (N+1)^2] float64 (gm [m^3/s^2],
        radius [m], the fully-normalised coefficients row-major)."""
        m = self.model
        return np.concatenate([[m.gm, m.radius, self.degree, self.order, self.tide_degree],
                               m.C.ravel(), m.S.ravel(), [float(self.extended_degree2)]]).astype(np.float64)

    def j2_jerk_coefficient(self) -> float:
        """k = 1.5 J2 GM R^2 [m^5/s^2] of :func:`j2_jerk_gcrs_z` from this
        field: J2 = -sqrt(5) C20 of the static model (fully normalised C20),
        GM and R its reference values."""
        m = self.model
        return 1.5 * (-np.sqrt(5.0) * float(m.C[2, 0])) * float(m.gm) * float(m.radius) ** 2

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        """Time-only inputs at t = t_hi + t_lo [s TT since epoch]: float64
        (*shape, n_tdat) = [T_ITRS_GCRS row-major (9), dC, dS (each the
        packed lower triangle, dC_nm at n (n+1)/2 + m, (nt+1)(nt+2)/2
        values; the sum of all tide providers)], shape = broadcast shape of
        t_hi and t_lo."""
        shape = np.broadcast_shapes(np.shape(t_hi), np.shape(t_lo))
        rotation = self.rotation or _frames_rotation
        T = np.asarray(rotation(epoch, t_hi, t_lo), dtype=np.float64)
        if T.shape != shape + (3, 3):
            raise ValueError(f"EarthField: rotation provider returned shape {T.shape}, expected {shape + (3, 3)}")
        out = np.empty(shape + (self.n_tdat,))
        out[..., :N_ROT] = T.reshape(shape + (N_ROT,))
        nt = self.tide_degree
        if nt >= 0:
            # dC, dS as packed lower triangles (index n (n+1)/2 + m): the
            # first (k+1)(k+2)/2 entries are the degrees <= k, so each
            # provider adds into a prefix of the block
            lt = (nt + 1) * (nt + 2) // 2
            n_inst = int(np.prod(shape, dtype=np.int64))
            flat = out.reshape(n_inst, self.n_tdat)
            filled = -1  # degree up to which the blocks hold data
            for p in self.tides:
                c, s = p(epoch, t_hi, t_lo)
                c = np.asarray(c, dtype=np.float64)
                s = np.asarray(s, dtype=np.float64)
                k = c.shape[-1] - 1 if c.ndim >= 2 else -1
                if c.shape != shape + (k + 1, k + 1) or s.shape != c.shape:
                    raise ValueError(f"EarthField: tide provider {p!r} returned shapes {c.shape}, {s.shape}; "
                                     f"expected {shape} + (k+1, k+1)")
                if k > nt:
                    raise ValueError(f"EarthField: tide provider {p!r} returned degree {k}, above the tide degree {nt}")
                # the first provider is stored (and the rest of its block
                # zeroed), the others added: no separate zeroing pass
                _pack(flat, N_ROT, c.reshape(n_inst, k + 1, k + 1), filled, lt)
                _pack(flat, N_ROT + lt, s.reshape(n_inst, k + 1, k + 1), filled, lt)
                filled = max(filled, k)
            if filled < 0:
                flat[:, N_ROT:] = 0.0
        return out


@inner_kernel
def _earth_field(rx, ry, rz, tdat, params, static, tides):
    gm, radius = params[0], params[1]
    n = int(params[2])
    mo = int(params[3])
    nt = int(params[4])
    ld = n + 1
    L = ld * ld
    C = params[PARAM_HEADER:PARAM_HEADER + L]
    S = params[PARAM_HEADER + L:PARAM_HEADER + 2 * L]
    if not static:
        n = -1
    lt = (nt + 1) * (nt + 2) // 2 if nt >= 0 else 0
    dC = tdat[N_ROT:N_ROT + lt]
    dS = tdat[N_ROT + lt:N_ROT + 2 * lt]
    if not tides:
        nt = -1
    # degree 2 evaluated elsewhere (in extended precision, degree2_accel_ext)?
    nmin = 3 if params[PARAM_HEADER + 2 * L] != 0.0 else 2
    x, y, z = itrs_from_gcrs(tdat, rx, ry, rz)
    ax, ay, az = sh_accel_flat(x, y, z, gm, radius, C, S, ld, n, mo, dC, dS, dynamic(0), nt, nmin)
    return gcrs_from_itrs(tdat, ax, ay, az)


@njit(cache=True, inline="always")
def itrs_from_gcrs(tdat, x, y, z):
    """T_ITRS_GCRS (x, y, z): a GCRS vector in the ITRS, with the rotation
    from the Earth term's time-only inputs (tdat[0:9], row-major).  float64."""
    return (tdat[0] * x + tdat[1] * y + tdat[2] * z,
            tdat[3] * x + tdat[4] * y + tdat[5] * z,
            tdat[6] * x + tdat[7] * y + tdat[8] * z)


@njit(cache=True, inline="always")
def gcrs_from_itrs(tdat, x, y, z):
    """T_ITRS_GCRS^T (x, y, z): an ITRS vector in the GCRS (see
    :func:`itrs_from_gcrs`).  float64."""
    return (tdat[0] * x + tdat[3] * y + tdat[6] * z,
            tdat[1] * x + tdat[4] * y + tdat[7] * z,
            tdat[2] * x + tdat[5] * y + tdat[8] * z)


@inner_kernel
def degree2_matrix(tdat, params, one):
    """(GM R^2, M_xx, M_yy, M_zz, M_xy, M_xz, M_yz) of the degree-2 field
    (static + tidal corrections; see :func:`degree2_accel_ext`), ITRS, in
    the number type of ``one`` (1.0 as a dd tuple or a float64): GM R^2 in
    m^5/s^2, M dimensionless.  tdat, params: the Earth field's."""
    gm, radius = params[0], params[1]
    ld = int(params[2]) + 1
    L = ld * ld
    nt = int(params[4])
    c20, c21, c22 = params[PARAM_HEADER + 2 * ld], params[PARAM_HEADER + 2 * ld + 1], params[PARAM_HEADER + 2 * ld + 2]
    s21, s22 = params[PARAM_HEADER + L + 2 * ld + 1], params[PARAM_HEADER + L + 2 * ld + 2]
    # static coefficients plus the tidal corrections, summed in the number type of one
    c20, c21, s21, c22, s22 = mul(one, c20), mul(one, c21), mul(one, s21), mul(one, c22), mul(one, s22)
    if nt >= 2:  # packed corrections: dC_nm at n (n+1)/2 + m
        lt = (nt + 1) * (nt + 2) // 2
        c20 = add(c20, tdat[N_ROT + 3])
        c21 = add(c21, tdat[N_ROT + 4])
        c22 = add(c22, tdat[N_ROT + 5])
        s21 = add(s21, tdat[N_ROT + lt + 4])
        s22 = add(s22, tdat[N_ROT + lt + 5])
    # unnormalised coefficients and M
    u20 = mul(sqrt(mul(one, 5.0)), c20)
    k21 = sqrt(div(mul(one, 5.0), 3.0))
    k22 = sqrt(div(mul(one, 5.0), 12.0))
    u21, v21, u22, v22 = mul(k21, c21), mul(k21, s21), mul(k22, c22), mul(k22, s22)
    m_xx = sub(mul(u22, 3.0), mul(u20, 0.5))
    m_yy = sub(mul(u20, -0.5), mul(u22, 3.0))
    m_zz = u20
    m_xy = mul(v22, 3.0)
    m_xz = mul(u21, 1.5)
    m_yz = mul(v21, 1.5)
    gmr2 = mul(mul(mul(one, gm), radius), radius)
    return gmr2, m_xx, m_yy, m_zz, m_xy, m_xz, m_yz


@inner_kernel
def degree2_accel_ext(rx, ry, rz, tdat, params):
    """Degree-2 part of the Earth field (static + tidal corrections) in the
    number type of r (generic: dd tuples or float64), GCRS [m/s^2].

    Closed form: with the unnormalised C20u = sqrt(5) C20, C21u =
    sqrt(5/3) C21, C22u = sqrt(5/12) C22 (same for S), the degree-2
    potential is V2 = GM R^2 Q / r^5 with the traceless quadratic form
    Q = x^T M x, M = [[-C20u/2 + 3 C22u, 3 S22u, 3/2 C21u],
    [3 S22u, -C20u/2 - 3 C22u, 3/2 S21u], [3/2 C21u, 3/2 S21u, C20u]]
    (ITRS, :func:`degree2_matrix`), so a = GM R^2 (2 M x / r^5 - 5 Q x / r^7).
    Used by the model when ``extended_degree2`` is set (J2 is ~5e-7 m/s^2 at
    1e5 km: its float64 round-off would move the orbit by ~5e-14 m per day).
    """
    one = const(1.0, 0.0, rx)
    gmr2, m_xx, m_yy, m_zz, m_xy, m_xz, m_yz = degree2_matrix(tdat, params, one)
    # The float64 matrix T is orthogonal only to ~1e-16, not smoothly in time: |T r| - |r| ~ 1e-8 m
    # would make the zonal term (~3e-7 m/s^2 at 1e8 m, gradient ~4 a / r) a noise of ~1e-22 m/s^2.
    # So the zonal part, C20u (3 z^2 - r^2) / 2 of Q, is formed from the GCRS r itself and the pole
    # p (T's third row) normalised in dd (its direction is smooth to ~1e-19 rad), and the radial
    # term from r; only the small non-zonal terms M' = M - C20u diag(-1/2, -1/2, 1) go through T.
    px, py, pz = mul(one, tdat[6]), mul(one, tdat[7]), mul(one, tdat[8])
    pn = sqrt(add(add(mul(px, px), mul(py, py)), mul(pz, pz)))
    px, py, pz = div(px, pn), div(py, pn), div(pz, pn)
    # r_ITRS = T r (T float64, r generic)
    x = add(add(mul(rx, tdat[0]), mul(ry, tdat[1])), mul(rz, tdat[2]))
    y = add(add(mul(rx, tdat[3]), mul(ry, tdat[4])), mul(rz, tdat[5]))
    z = add(add(mul(rx, px), mul(ry, py)), mul(rz, pz))
    half = mul(m_zz, 0.5)
    n_xx, n_yy = add(m_xx, half), add(m_yy, half)
    mx = add(add(mul(x, n_xx), mul(y, m_xy)), mul(z, m_xz))
    my = add(add(mul(x, m_xy), mul(y, n_yy)), mul(z, m_yz))
    mz = add(mul(x, m_xz), mul(y, m_yz))
    r2 = add(add(mul(rx, rx), mul(ry, ry)), mul(rz, rz))
    q = add(add(add(mul(x, mx), mul(y, my)), mul(z, mz)), mul(half, sub(mul(mul(z, z), 3.0), r2)))
    r5 = mul(mul(r2, r2), sqrt(r2))
    # a = (2 GM R^2 / r^5) M x - (5 GM R^2 Q / r^7) x, with M x = M' x + (C20u / 2) (3 z p - r) (GCRS)
    s1 = div(mul(gmr2, 2.0), r5)
    s2 = div(mul(mul(gmr2, 5.0), q), mul(r5, r2))
    gx = add(add(mul(mx, tdat[0]), mul(my, tdat[3])), mul(mz, tdat[6]))  # T^T M' x
    gy = add(add(mul(mx, tdat[1]), mul(my, tdat[4])), mul(mz, tdat[7]))
    gz = add(add(mul(mx, tdat[2]), mul(my, tdat[5])), mul(mz, tdat[8]))
    z3 = mul(z, 3.0)
    gx = add(gx, mul(half, sub(mul(z3, px), rx)))
    gy = add(gy, mul(half, sub(mul(z3, py), ry)))
    gz = add(gz, mul(half, sub(mul(z3, pz), rz)))
    return sub(mul(s1, gx), mul(s2, rx)), sub(mul(s1, gy), mul(s2, ry)), sub(mul(s1, gz), mul(s2, rz))


@njit(cache=True, inline="always")
def j2_jerk_gcrs_z(k, rx, ry, rz, vx, vy, vz):
    """Time derivative [m/s^3, GCRS] of the zonal J2 acceleration with the
    pole along the GCRS z axis, a = -k / r^5 [(1 - 5 q) x, (1 - 5 q) y,
    (3 - 5 q) z], q = z^2 / r^2, k = 1.5 J2 GM R^2 [m^5/s^2] (J2 = -sqrt(5)
    C20 of the field), for a satellite at r [m] moving with v [m/s].

    A jerk *model* for the attitude rates of the local pointing laws, where
    it enters through 1/c: it leaves out the Earth rotation of the sectorial
    degree-2 terms (~1e-13 m/s^3 at 1e5 km), the tilt of the CIP from GCRS z
    (~2e-14) and degrees >= 3 (~2e-14 m/s^3).  float64 scalars; returns
    (jx, jy, jz)."""
    r2 = rx * rx + ry * ry + rz * rz
    f = -k / (r2 * r2 * np.sqrt(r2))
    rv = rx * vx + ry * vy + rz * vz
    fd = -5.0 * f * rv / r2
    q = rz * rz / r2
    qd = 2.0 * rz * vz / r2 - 2.0 * q * rv / r2
    return (fd * (1.0 - 5.0 * q) * rx + f * (-5.0 * qd * rx + (1.0 - 5.0 * q) * vx),
            fd * (1.0 - 5.0 * q) * ry + f * (-5.0 * qd * ry + (1.0 - 5.0 * q) * vy),
            fd * (3.0 - 5.0 * q) * rz + f * (-5.0 * qd * rz + (3.0 - 5.0 * q) * vz))


@inner_kernel
def earth_field_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """Acceleration [m/s^2, GCRS] of the Earth's field, degrees 2..N of the
    static model plus the tidal corrections, at the geocentric GCRS position
    (rx, ry, rz) [m] (velocity unused).  tdat: this term's (n_tdat,)
    time-only inputs at the instant; params: :meth:`EarthField.params`.
    float64 scalars; returns (ax, ay, az)."""
    return _earth_field(rx, ry, rz, tdat, params, dynamic(True), dynamic(True))


@njit(cache=True)
def earth_field_static_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """As :func:`earth_field_accel`, the static field only (no corrections):
    for force budgets.  m, m/s in, m/s^2 out, GCRS."""
    return _earth_field(rx, ry, rz, tdat, params, dynamic(True), dynamic(False))


@njit(cache=True)
def earth_tides_accel(rx, ry, rz, vx, vy, vz, tdat, params):
    """As :func:`earth_field_accel`, the summed coefficient corrections only
    (the tides' acceleration, for force budgets; for one tide model alone
    build an EarthField with that provider only).  m/s^2, GCRS."""
    return _earth_field(rx, ry, rz, tdat, params, dynamic(False), dynamic(True))


@njit(cache=True)
def _batch(r, tdat, params, static, tides, out):
    n = r.shape[0]
    one = tdat.shape[0] == 1
    for i in range(n):
        row = tdat[0] if one else tdat[i]
        ax, ay, az = _earth_field(r[i, 0], r[i, 1], r[i, 2], row, params, static, tides)
        out[i, 0], out[i, 1], out[i, 2] = ax, ay, az


def earth_field_accel_batch(r, tdat, params, part: str = "total") -> np.ndarray:
    """Accelerations [m/s^2, GCRS] at many points (analysis and force budgets).

    r: (n, 3) geocentric GCRS positions [m]; tdat: (n, n_tdat) or (n_tdat,)
    time-only inputs (from :meth:`EarthField.precompute`); params:
    :meth:`EarthField.params`; part: ``"total"`` (static + corrections),
    ``"static"`` or ``"tides"``.  Returns (n, 3) float64.
    """
    flags = {"total": (True, True), "static": (True, False), "tides": (False, True)}
    if part not in flags:
        raise ValueError(unknown("earth_field_accel_batch: part", part, flags))
    r = np.ascontiguousarray(np.atleast_2d(r), dtype=np.float64)
    tdat = np.ascontiguousarray(np.atleast_2d(tdat), dtype=np.float64)
    if r.shape[-1] != 3 or tdat.shape[0] not in (1, r.shape[0]):
        raise ValueError(f"earth_field_accel_batch: r {r.shape} and tdat {tdat.shape} do not match")
    out = np.empty(r.shape)
    _batch(r, tdat, np.ascontiguousarray(params, dtype=np.float64), *flags[part], out)
    return out
