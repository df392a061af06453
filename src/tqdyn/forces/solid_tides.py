"""Solid Earth tides as corrections to the Earth's Stokes coefficients
(IERS Conventions 2010 = TN36, sec. 6.2).

Output: corrections dC[n, m], dS[n, m] (n, m <= 4) to the fully normalised,
dimensionless Stokes coefficients of the Earth's field in the ITRS, to be
added to a static field of reference radius ``r_ref`` and constant
``gm_earth`` (EGM2008 by default: 6378136.3 m, 3.986004415e14 m^3/s^2).
The TN36 tables used here are read by :mod:`tqdyn.readers.iers_tables`.

Step 1 (frequency-independent, TN36 eq. 6.6 and 6.7), for the Sun and the
Moon (j) at geocentric ITRS positions r_j (latitude Phi_j, east longitude
lambda_j, distance r_j):

    dC_nm - i dS_nm = k_nm / (2n+1) sum_j (GM_j/GM_E) (R/r_j)^(n+1)
                      Pbar_nm(sin Phi_j) exp(-i m lambda_j)        n = 2, 3
    dC_4m - i dS_4m = k+_2m / 5 sum_j (GM_j/GM_E) (R/r_j)^3
                      Pbar_2m(sin Phi_j) exp(-i m lambda_j)        m = 0, 1, 2

with the anelastic nominal Love numbers of TN36 Table 6.3
(``data/iers2010/tab6.3.txt``; complex k_2m = Re + i Im, Im < 0; real k_3m
and k+_2m).  Pbar_nm = N_nm P_nm, N_nm = sqrt((2 - delta_m0)(2n+1)(n-m)!/(n+m)!),
P_nm without the Condon-Shortley phase (geodesy convention, as in EGM2008).

Step 2 (frequency dependence of k_20, k_21, k_22; TN36 eq. 6.8a-c and
Tables 6.5a-c, ``data/iers2010/tab6.5{a,b,c}.txt``), theta_f from
:mod:`tqdyn.astro.tidal_arguments`:

    dC_20          = sum_f(2,0) [ip_f cos theta_f - op_f sin theta_f]
    dC_21 - i dS_21 = -i sum_f(2,1) (ip_f + i op_f) exp(i theta_f)
      i.e. dC_21 = sum [ip sin + op cos],  dS_21 = sum [ip cos - op sin]
    dC_22 - i dS_22 = sum_f(2,2) (ip_f + i op_f) exp(i theta_f)
      i.e. dC_22 = sum [ip cos - op sin],  dS_22 = -sum [ip sin + op cos]

(ip, op = the tables' in-phase / out-of-phase amplitudes A_m delta k_f H_f,
units 1e-12 in the files; Table 6.5c has ip only).  The eta_1 = -i, eta_2 = 1
factors are those of TN36 eq. 6.8b/c; the explicit real forms above are
TN36's own (text after eq. 6.8).

Permanent tide (TN36 sec. 6.2.2, eq. 6.13).  Step 1 with the nominal k_20
has a non-zero time average, the permanent tide

    dC20_perm = A_0 H_0 k_20,  A_0 = 1 / (R sqrt(4 pi)),  H_0 = -0.31460 m

(= -4.2007e-9 for k_20 = 0.30190, R = 6378136.3 m).  Pairing with the static
field:

* tide-free static field (EGM2008 as shipped, tqdyn's default) +
  step 1 in full -> ``remove_permanent=False`` (default).  Nothing to
  subtract: the tide-free field lacks the permanent deformation and step 1
  supplies it.
* zero-tide static field (C20 includes the permanent deformation) ->
  ``remove_permanent=True``: dC20_perm is subtracted from step 1 so that it
  is not counted twice.  Note that EGM2008's own zero-tide/tide-free offset
  is 4.1736e-9 (SOURCES.md), which corresponds to k_20 = 0.29995 in this
  formula, not 0.30190: a zero-tide EGM2008 C20 with this option differs
  from the tide-free pairing by 2.7e-11 in C20 (~3e-14 m/s^2 at r = 1e8 m).
  Keep the default.

Magnitudes at r = 1e8 m (TianQin; max over a day and over directions,
measured in tests/test_solid_tides.py): step 1 degree 2 1.2e-11 m/s^2 (of
which the permanent part 4.6e-12), degree 3 4.5e-15, degree 4 (k+)
2.3e-16; step 2 5.5e-13 m/s^2 (K1 dominant).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..astro.constants import GM_EARTH_EGM2008, R_EARTH_EGM2008
from ..astro.tidal_arguments import delaunay_arguments, doodson_arguments, tidal_harmonic_sum
from ..readers.iers_tables import LoveNumbers, Step2Table, load_love_numbers, load_step2_table

__all__ = [
    "PERMANENT_TIDE_H0_M",
    "SolidTides",
    "permanent_tide_dc20",
    "step1_coefficients",
    "step2_coefficients",
]

#: Amplitude H_0 [m] of the permanent (zero-frequency) degree-2 zonal tide,
#: TN36 sec. 6.2.2 (eq. 6.13), from the Cartwright-Tayler-Edden harmonic
#: development.
PERMANENT_TIDE_H0_M = -0.31460

_NMAX = 4  # degree of the corrections produced here (degree 4 from k+)


# --------------------------------------------------------------------------
# physics (arrays in, arrays out)


def permanent_tide_dc20(k20: float = 0.30190, r_ref: float = R_EARTH_EGM2008) -> float:
    """Time-independent part of the step-1 dC20, A_0 H_0 k_20 (TN36 eq. 6.13),
    A_0 = 1 / (r_ref sqrt(4 pi)) [1/m], H_0 = -0.31460 m.  Dimensionless
    (-4.2007e-9 for the defaults)."""
    return PERMANENT_TIDE_H0_M * k20 / (r_ref * math.sqrt(4.0 * math.pi))


# N_nm and the polynomial parts Q_nm(u) with P_nm(u) = Q_nm(u) cos^m(Phi), u = sin(Phi)
def _norm(n: int, m: int) -> float:
    return math.sqrt((2.0 - (m == 0)) * (2 * n + 1) * math.factorial(n - m) / math.factorial(n + m))


_N = np.zeros((4, 4))
for _n in (2, 3):
    for _m in range(_n + 1):
        _N[_n, _m] = _norm(_n, _m)
del _n, _m


def _step1_kernel(pos, ratio, r_ref, kre, kim, kplus, degree4, dc, ds):
    """Eq. 6.6/6.7 vectorised over the instants (numpy: nothing to compile;
    each instant's operations in the order of a per-instant loop): pos
    (n, n_b, 3) [m], ratio (n_b,), kre/kim (4, 4), kplus (3,); dc, ds
    (n, 5, 5) overwritten."""
    n20, n21, n22 = _N[2, 0], _N[2, 1], _N[2, 2]
    n30, n31, n32, n33 = _N[3, 0], _N[3, 1], _N[3, 2], _N[3, 3]
    # real and imaginary parts of sum_j rho Pbar_nm e^{-i m lambda}, per instant
    tr = np.zeros((4, 4, pos.shape[0]))
    ti = np.zeros((4, 4, pos.shape[0]))
    for j in range(pos.shape[1]):
        x, y, z = pos[:, j, 0], pos[:, j, 1], pos[:, j, 2]
        r = np.sqrt(x * x + y * y + z * z)
        u = z / r                                  # sin(latitude)
        w1r, w1i = x / r, -y / r                   # cos(lat) e^{-i lon}
        w2r, w2i = w1r * w1r - w1i * w1i, 2.0 * w1r * w1i
        w3r, w3i = w2r * w1r - w2i * w1i, w2r * w1i + w2i * w1r
        q = r_ref / r
        rho2 = ratio[j] * q * q * q                # (GM_j/GM_E)(R/r_j)^3
        rho3 = rho2 * q
        u2 = u * u
        tr[2, 0] += rho2 * n20 * 0.5 * (3.0 * u2 - 1.0)
        a = rho2 * n21 * 3.0 * u
        tr[2, 1] += a * w1r
        ti[2, 1] += a * w1i
        a = rho2 * n22 * 3.0
        tr[2, 2] += a * w2r
        ti[2, 2] += a * w2i
        tr[3, 0] += rho3 * n30 * 0.5 * (5.0 * u2 - 3.0) * u
        a = rho3 * n31 * 1.5 * (5.0 * u2 - 1.0)
        tr[3, 1] += a * w1r
        ti[3, 1] += a * w1i
        a = rho3 * n32 * 15.0 * u
        tr[3, 2] += a * w2r
        ti[3, 2] += a * w2i
        a = rho3 * n33 * 15.0
        tr[3, 3] += a * w3r
        ti[3, 3] += a * w3i
    dc[...] = 0.0
    ds[...] = 0.0
    for nn in range(2, 4):
        f = 1.0 / (2 * nn + 1)
        for m in range(nn + 1):
            # dC - i dS = k T / (2n+1), k = kre + i kim, T = tr + i ti
            dc[:, nn, m] = f * (kre[nn, m] * tr[nn, m] - kim[nn, m] * ti[nn, m])
            ds[:, nn, m] = -f * (kre[nn, m] * ti[nn, m] + kim[nn, m] * tr[nn, m])
    if degree4:
        for m in range(3):
            dc[:, 4, m] = 0.2 * kplus[m] * tr[2, m]
            ds[:, 4, m] = -0.2 * kplus[m] * ti[2, m]


def step1_coefficients(bodies_itrs, gm_ratio, love: LoveNumbers, r_ref: float = R_EARTH_EGM2008,
                       degree4: bool = True):
    """Step-1 solid-tide corrections (TN36 eq. 6.6, 6.7).

    bodies_itrs: S + (n_b, 3) float64, geocentric ITRS positions [m] of the
    tide-raising bodies (Moon, Sun); gm_ratio: (n_b,) GM_j / GM_E
    (dimensionless, GM_E of the static field); love: nominal Love numbers;
    r_ref: reference radius R [m] of the static field; degree4: include the
    k+ terms (eq. 6.7).
    Returns (dC, dS), each float64 S + (5, 5) indexed [n, m], dimensionless,
    fully normalised; degrees 0, 1 are zero, degree 4 only if ``degree4``.

    Evaluated for all instants at once (numpy) with P_nm(sin Phi) e^{-i m lambda}
    written as Q_nm(u) w^m, u = z/r, w = (x - i y)/r (no trigonometric calls);
    the spherical-coordinate form of eq. 6.6 is the test's reference.
    """
    pos = np.asarray(bodies_itrs, dtype=np.float64)
    shape, nb = pos.shape[:-2], pos.shape[-2]
    flat = np.ascontiguousarray(pos.reshape(-1, nb, 3))
    ratio = np.ascontiguousarray(np.broadcast_to(np.asarray(gm_ratio, dtype=np.float64), (nb,)))
    dc = np.empty((flat.shape[0], 5, 5))
    ds = np.empty((flat.shape[0], 5, 5))
    _step1_kernel(flat, ratio, float(r_ref), np.ascontiguousarray(love.k.real),
                  np.ascontiguousarray(love.k.imag), np.asarray(love.k_plus, dtype=np.float64),
                  bool(degree4), dc, ds)
    return dc.reshape(shape + (5, 5)), ds.reshape(shape + (5, 5))


def step2_coefficients(beta, table: Step2Table):
    """Step-2 (frequency-dependent) corrections to C20, C21, S21, C22, S22
    (TN36 eq. 6.8a-c, real forms in the module docstring).

    beta: S + (6,) Doodson arguments [rad] (tau, s, h, p, N', p_s);
    table: :class:`Step2Table` (:func:`tqdyn.readers.iers_tables.load_step2_table`).
    Returns (dC, dS), float64 S + (3, 3) indexed [n, m] (degree 2 only),
    dimensionless, fully normalised.
    """
    _, wc, ws = table._weights
    five = tidal_harmonic_sum(beta, table.doodson, wc, ws)              # S + (5,)
    shape = five.shape[:-1]
    dc = np.zeros(shape + (3, 3))
    ds = np.zeros(shape + (3, 3))
    dc[..., 2, 0] = five[..., 0]
    dc[..., 2, 1] = five[..., 1]
    ds[..., 2, 1] = five[..., 2]
    dc[..., 2, 2] = five[..., 3]
    ds[..., 2, 2] = five[..., 4]
    return dc, ds


# --------------------------------------------------------------------------
# provider


def _resolve_orientation(orientation):
    if orientation is not None:
        return orientation
    try:
        from ..astro.earth_orientation import earth_orientation
    except ImportError as exc:
        raise ImportError("tides: tqdyn.astro.earth_orientation.earth_orientation is not available "
                          f"({exc}); pass orientation=callable(epoch, t_hi, t_lo)") from None
    return earth_orientation


def _resolve_ephemeris(ephemeris):
    if ephemeris is not None:
        return ephemeris
    from ..astro.ephemeris import default_ephemeris

    return default_ephemeris()


def _sun_moon_gcrs(ephemeris, jd1, jd2) -> np.ndarray:
    """Geocentric GCRS positions [m] of the Moon and the Sun, S + (2, 3)."""
    states = getattr(ephemeris, "geocentric_states", None)
    if states is not None:
        pos, _ = states(("moon", "sun"), jd1, jd2, velocity=False)
        return pos
    return np.stack([np.asarray(ephemeris.geocentric(b, jd1, jd2)[0]) for b in ("moon", "sun")], axis=-2)


def _tt_pair(eo):
    return np.asarray(eo.tt[0], dtype=np.float64), np.asarray(eo.tt[1], dtype=np.float64)


@dataclass(frozen=True, eq=False)
class SolidTides:
    """Solid Earth tides (TN36 sec. 6.2, steps 1 and 2) as a Stokes-coefficient
    provider for the Earth field term.

    Calling ``provider(epoch, t_hi, t_lo)`` (t = t_hi + t_lo [s TT since
    ``epoch``], arrays of shape S) returns (dC, dS), float64 S + (5, 5),
    indexed [n, m], n <= 4: dimensionless corrections to the fully
    normalised Stokes coefficients of the static field (ITRS, reference
    radius ``r_ref``, constant ``gm_earth``).

    Parameters
    ----------
    step2 : include the frequency-dependent corrections (eq. 6.8).
    degree4 : include the degree-4 terms from k+ (eq. 6.7).
    remove_permanent : subtract the permanent tide A_0 H_0 k_20 from dC20
        (only for a zero-tide static field; tqdyn's EGM2008 is tide-free ->
        False, see the module docstring).
    gm_earth [m^3/s^2], r_ref [m] : of the static field (EGM2008 defaults).
    gm_moon, gm_sun [m^3/s^2] : None -> :func:`tqdyn.astro.ephemeris.planetary_gm`.
    orientation : callable (epoch, t_hi, t_lo) -> object with T_ITRS_GCRS
        S + (3, 3), gmst [rad] S, tt (jd1, jd2); None ->
        :func:`tqdyn.astro.earth_orientation.earth_orientation`.
    ephemeris : object with ``geocentric(body, jd1, jd2) -> (pos [m], vel)``
        (TDB Julian dates, GCRS); None -> the shipped DE421.
    love, table : Love numbers and step-2 table; None -> the shipped TN36
        Tables 6.3 and 6.5a-c.
    """

    step2: bool = True
    degree4: bool = True
    remove_permanent: bool = False
    gm_earth: float = float(GM_EARTH_EGM2008)
    r_ref: float = R_EARTH_EGM2008
    gm_moon: float | None = None
    gm_sun: float | None = None
    orientation: Callable | None = None
    ephemeris: object | None = None
    love: LoveNumbers | None = None
    table: Step2Table | None = None
    nmax: int = field(default=_NMAX, init=False)
    name: str = field(default="solid_tides", init=False)
    description: str = field(default="solid Earth tides, IERS 2010 steps 1 (n = 2, 3, 4) and 2 (n = 2)",
                             init=False)
    source: str = field(default="IERS Conventions 2010 (TN36) sec. 6.2, Tables 6.3, 6.5a-c", init=False)

    def __post_init__(self):
        if self.love is None:
            object.__setattr__(self, "love", load_love_numbers())
        if self.table is None:
            object.__setattr__(self, "table", load_step2_table())

    @property
    def permanent_tide(self) -> str:
        """``"included"`` (default; pair with a tide-free static field) or
        ``"removed"`` (``remove_permanent=True``; pair with a zero-tide field).
        Checked by :class:`tqdyn.forces.earth.EarthField`."""
        return "removed" if self.remove_permanent else "included"

    def _gm_ratio(self) -> np.ndarray:
        gm_moon, gm_sun = self.gm_moon, self.gm_sun
        if gm_moon is None or gm_sun is None:
            from ..astro.ephemeris import planetary_gm

            gm = planetary_gm()
            gm_moon = gm["moon"] if gm_moon is None else gm_moon
            gm_sun = gm["sun"] if gm_sun is None else gm_sun
        return np.array([gm_moon, gm_sun]) / float(self.gm_earth)

    def evaluate(self, eo, tdb) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), S + (5, 5), from already gathered inputs: eo, the Earth
        orientation at the instants (T_ITRS_GCRS S + (3, 3), gmst [rad] S,
        tt (jd1, jd2)); tdb: two-part TDB Julian dates (jd1, jd2) [d], S.
        (Lets a caller share one Earth-orientation evaluation among providers.)"""
        ephem = _resolve_ephemeris(self.ephemeris)
        pos = _sun_moon_gcrs(ephem, tdb[0], tdb[1])                    # S + (2, 3) GCRS
        T = np.asarray(eo.T_ITRS_GCRS, dtype=np.float64)
        pos_itrs = np.einsum("...ij,...bj->...bi", T, pos)
        dc, ds = step1_coefficients(pos_itrs, self._gm_ratio(), self.love, self.r_ref, self.degree4)
        if self.step2:
            beta = doodson_arguments(eo.gmst, delaunay_arguments(*_tt_pair(eo)))
            c2, s2 = step2_coefficients(beta, self.table)
            dc[..., :3, :3] += c2
            ds[..., :3, :3] += s2
        if self.remove_permanent:
            dc[..., 2, 0] -= permanent_tide_dc20(self.love.k[2, 0].real, self.r_ref)
        return dc, ds

    def __call__(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), float64 S + (5, 5) [n, m], at t = t_hi + t_lo [s TT since
        epoch] (S = broadcast shape of t_hi, t_lo)."""
        from ..astro.timescales import tdb_jd

        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, np.float64), np.asarray(t_lo, np.float64))
        eo = _resolve_orientation(self.orientation)(epoch, t_hi, t_lo)
        return self.evaluate(eo, tdb_jd(epoch, t_hi, t_lo))
