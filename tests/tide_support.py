"""Stand-ins and independent helpers for the tide tests (not a test module).

* :func:`standin_orientation`: an Earth orientation built directly with
  pyerfa (IAU 2006/2000A ``c2t06a``) and constant EOP values of 2004-06-06
  (EOP 14 C04, MJD 53162, the parse check of src/tqdyn/data/SOURCES.md):
  x_p = -0.074487", y_p = 0.475665", UT1-UTC = -0.4704721 s, TAI-UTC = 32 s.
  It stands in for ``tqdyn.astro.earth_orientation.earth_orientation`` (same field names).
* :class:`DirectDE421`: Sun and Moon geocentric GCRS positions read with
  jplephem from the DE421 file of ``skyfield-data`` -- independent of
  ``tqdyn.astro.ephemeris``.
* :func:`max_accel`: the largest acceleration [m/s^2] of a set of Stokes
  corrections over a sphere of radius r, from central finite differences of
  the potential V = GM/r sum (R/r)^n Pbar_nm(sin phi) (dC cos m lon + dS sin
  m lon) written with scipy's Legendre functions (Condon-Shortley phase
  removed) -- independent of tqdyn's own field code.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import erfa
import numpy as np
from scipy.special import lpmv

from tqdyn.astro.timescales import tdb_jd

ARCSEC = math.pi / 648000.0
XP_2004 = -0.074487 * ARCSEC
YP_2004 = 0.475665 * ARCSEC
TT_MINUS_UT1_2004 = 32.184 + 32.0 + 0.4704721  # s: TT-TAI + TAI-UTC - (UT1-UTC)
GM_EARTH = 3.986004415e14
R_EARTH = 6378136.3
GM_MOON = 4.9028000661637961e12  # DE430/431 (gm_de431.tpc), m^3/s^2
GM_SUN = 1.3271244004193938e20


class StandInOrientation(NamedTuple):
    T_ITRS_GCRS: np.ndarray
    era: np.ndarray
    gmst: np.ndarray
    tt: tuple
    ut1: tuple
    xp: np.ndarray
    yp: np.ndarray


def standin_orientation(epoch, t_hi, t_lo=0.0, cheap=False) -> StandInOrientation:
    """Earth orientation at t = t_hi + t_lo [s TDB since epoch] from pyerfa
    with constant 2004-06-06 EOP.  cheap=True replaces the full c2t06a
    matrix by the ERA rotation alone (shape-correct stand-in for timing)."""
    jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
    tt2 = jd2 - erfa.dtdb(jd1, jd2, 0.0, 0.0, 0.0, 0.0) / 86400.0
    tt = (jd1, tt2)
    ut1 = (jd1, tt2 - TT_MINUS_UT1_2004 / 86400.0)
    era = erfa.era00(*ut1)
    gmst = erfa.gmst06(ut1[0], ut1[1], tt[0], tt[1])
    xp = np.full(jd1.shape, XP_2004)
    yp = np.full(jd1.shape, YP_2004)
    if cheap:
        c, s = np.cos(era), np.sin(era)
        T = np.zeros(jd1.shape + (3, 3))
        T[..., 0, 0], T[..., 0, 1], T[..., 1, 0], T[..., 1, 1], T[..., 2, 2] = c, s, -s, c, 1.0
    else:
        T = erfa.c2t06a(tt[0], tt[1], ut1[0], ut1[1], xp, yp)
    return StandInOrientation(T, era, gmst, tt, ut1, xp, yp)


class DirectDE421:
    """Geocentric GCRS positions [m] of the Sun and Moon from DE421 via
    jplephem (``geocentric(body, jd1, jd2) -> (pos, vel)``, TDB dates)."""

    def __init__(self):
        from importlib.resources import files

        from jplephem.spk import SPK

        self.kernel = SPK.open(str(files("skyfield_data") / "data" / "de421.bsp"))

    def _p(self, c, t, jd1, jd2):
        return np.moveaxis(np.asarray(self.kernel[c, t].compute(jd1, jd2)), 0, -1) * 1000.0

    def geocentric(self, body, jd1, jd2):
        jd1, jd2 = np.broadcast_arrays(np.asarray(jd1, float), np.asarray(jd2, float))
        earth_from_emb = self._p(3, 399, jd1, jd2)
        if body == "moon":
            pos = self._p(3, 301, jd1, jd2) - earth_from_emb
        elif body == "sun":
            pos = self._p(0, 10, jd1, jd2) - (self._p(0, 3, jd1, jd2) + earth_from_emb)
        else:
            raise ValueError(body)
        return pos, np.zeros_like(pos)


def fibonacci_sphere(n: int) -> np.ndarray:
    """n nearly uniform unit vectors, (n, 3)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    lon = math.pi * (1.0 + math.sqrt(5.0)) * i
    rho = np.sqrt(1.0 - z * z)
    return np.stack([rho * np.cos(lon), rho * np.sin(lon), z], axis=-1)


def _pbar(n: int, m: int, x: np.ndarray) -> np.ndarray:
    """Fully normalised Pbar_nm(x) without the Condon-Shortley phase (scipy's
    lpmv has it: multiply by (-1)^m)."""
    norm = math.sqrt((2.0 - (m == 0)) * (2 * n + 1) * math.factorial(n - m) / math.factorial(n + m))
    return (-1.0) ** m * norm * lpmv(m, n, x)


def potential(points: np.ndarray, dc: np.ndarray, ds: np.ndarray, gm=GM_EARTH, r_ref=R_EARTH) -> np.ndarray:
    """Potential [m^2/s^2] of Stokes corrections at ITRS points (P, 3) [m];
    dc, ds (T, N+1, N+1) -> (T, P).  Degrees 2..N."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    r = np.sqrt(x * x + y * y + z * z)
    sinphi = z / r
    lon = np.arctan2(y, x)
    nmax = dc.shape[-1] - 1
    out = np.zeros((dc.shape[0], points.shape[0]))
    for n in range(2, nmax + 1):
        q = gm / r * (r_ref / r) ** n
        for m in range(n + 1):
            p = q * _pbar(n, m, sinphi)
            out += dc[:, n, m, None] * (p * np.cos(m * lon))[None] + ds[:, n, m, None] * (p * np.sin(m * lon))[None]
    return out


def accel(points: np.ndarray, dc: np.ndarray, ds: np.ndarray, h: float = 100.0) -> np.ndarray:
    """Acceleration grad V [m/s^2], (T, P, 3), by central differences (step h [m])."""
    comps = []
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        comps.append((potential(points + e, dc, ds) - potential(points - e, dc, ds)) / (2.0 * h))
    return np.stack(comps, axis=-1)


def max_accel(dc, ds, r=1e8, n_points=400) -> float:
    """max over times and over n_points directions at distance r [m] of |grad V| [m/s^2]."""
    dc = np.asarray(dc).reshape((-1,) + np.shape(dc)[-2:])
    ds = np.asarray(ds).reshape((-1,) + np.shape(ds)[-2:])
    pts = r * fibonacci_sphere(n_points)
    a = accel(pts, dc, ds)
    return float(np.max(np.linalg.norm(a, axis=-1)))
