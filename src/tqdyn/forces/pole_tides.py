"""Solid Earth and ocean pole tides as corrections to C21, S21
(IERS Conventions 2010 = TN36, sec. 6.4 and 6.5; mean pole sec. 7.1.4).

The pole tides are the deformation (solid Earth) and ocean loading caused by
the centrifugal potential of the wobble: the polar motion (x_p, y_p) minus
the conventional mean pole (x_bar, y_bar),

    m_1 = x_p - x_bar,   m_2 = -(y_p - y_bar)                    (TN36 eq. 7.24)

IERS 2010 conventional mean pole (TN36 eq. 7.25, Table 7.7), t in Julian
years since 2000.0 (TT), in milliarcseconds:

    t < 10 (before 2010.0):  x_bar =  55.974 + 1.8243 t + 0.18413 t^2 + 0.007024 t^3
                             y_bar = 346.346 + 1.7896 t - 0.10729 t^2 - 0.000908 t^3
    t >= 10:                 x_bar =  23.513 + 7.6141 t
                             y_bar = 358.891 - 0.6287 t

(the two branches join at 2010.0 to 1 uas).  A 2004-06-06 + 90 d run uses
the cubic branch.  The IERS has since replaced this model by a linear
"secular pole" (2018 update of chapter 7); tqdyn keeps the 2010 model of the
paper's conventions.

Solid Earth pole tide (TN36 eq. 6.22; k_2 = 0.3077 + 0.0036 i, m in arcsec):

    dC21 = -1.333e-9 (m_1 + 0.0115 m_2),   dS21 = -1.333e-9 (m_2 - 0.0115 m_1)

Ocean pole tide, degree 2 only (TN36 eq. 6.24, the n = 2 part of the Desai
(2002) self-consistent equilibrium model, m in arcsec):

    dC21 = -2.1778e-10 (m_1 - 0.01724 m_2),   dS21 = -1.7232e-10 (m_2 - 0.03365 m_1)

Why degree 2 is enough at 1e5 km: the full ocean pole tide (TN36 eq. 6.23)
has terms of all degrees, weighted by R_n ~ (1 + k'_n)/(2n + 1) times the
Desai (2002) loading coefficients, which are of the same order for n = 2, 3,
4 ...; but a degree-n term reaches the satellite attenuated by
(R/r)^n = (0.064)^n at r = 1e8 m, so each degree above 2 is ~15x weaker
than the one before: degree 3 is at most ~6% of degree 2, i.e.
~2e-15 m/s^2 against the 3.5e-14 m/s^2 of degree 2 (an estimate; the
Desai coefficient file is not shipped).

Magnitudes on 2004-06-06 (m_1, m_2 = -0.143", -0.124"): solid dC21, dS21 =
1.9e-10, 1.6e-10 (2.4e-13 m/s^2 at r = 1e8 m), ocean 3.1e-11, 2.0e-11
(3.5e-14 m/s^2).  Both follow the Chandler (433 d) and annual wobbles:
over the 90-day reference run the solid dC21 swings from +1.9e-10 to
-1.2e-10 (measured in tests/test_pole_tides.py with the C04 series).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..astro.constants import ARCSEC_RAD
from ..astro.eop import mean_pole_iers2010  # the IERS 2010 mean pole (also the long-term EOP model)

__all__ = [
    "ARCSEC",
    "OceanPoleTide",
    "SolidPoleTide",
    "mean_pole_iers2010",
    "ocean_pole_tide",
    "solid_pole_tide",
    "wobble",
]

#: One arcsecond [rad].
ARCSEC = ARCSEC_RAD  # rad per arcsec (astro.constants)

# TN36 eq. 6.22 and 6.24 (m in arcsec)
_SOLID_SCALE, _SOLID_RATIO = -1.333e-9, 0.0115
_OCEAN_C_SCALE, _OCEAN_C_RATIO = -2.1778e-10, 0.01724
_OCEAN_S_SCALE, _OCEAN_S_RATIO = -1.7232e-10, 0.03365


def wobble(xp, yp, tt) -> tuple[np.ndarray, np.ndarray]:
    """Wobble variables m_1 = x_p - x_bar, m_2 = -(y_p - y_bar) [rad]
    (TN36 eq. 7.24).  xp, yp: polar motion [rad] (IERS EOP), shape S; tt:
    two-part TT Julian date (jd1, jd2) [d].  Returns (m1, m2), float64 S."""
    xbar, ybar = mean_pole_iers2010(tt)
    return np.asarray(xp, dtype=np.float64) - xbar, -(np.asarray(yp, dtype=np.float64) - ybar)


def solid_pole_tide(m1, m2) -> tuple[np.ndarray, np.ndarray]:
    """Solid Earth pole tide (TN36 eq. 6.22): (dC21, dS21), dimensionless,
    fully normalised, from the wobble variables m1, m2 [rad] (shape S)."""
    a1 = np.asarray(m1, dtype=np.float64) / ARCSEC
    a2 = np.asarray(m2, dtype=np.float64) / ARCSEC
    return _SOLID_SCALE * (a1 + _SOLID_RATIO * a2), _SOLID_SCALE * (a2 - _SOLID_RATIO * a1)


def ocean_pole_tide(m1, m2) -> tuple[np.ndarray, np.ndarray]:
    """Ocean pole tide, degree 2 (TN36 eq. 6.24): (dC21, dS21),
    dimensionless, fully normalised, from m1, m2 [rad] (shape S)."""
    a1 = np.asarray(m1, dtype=np.float64) / ARCSEC
    a2 = np.asarray(m2, dtype=np.float64) / ARCSEC
    return (_OCEAN_C_SCALE * (a1 - _OCEAN_C_RATIO * a2),
            _OCEAN_S_SCALE * (a2 - _OCEAN_S_RATIO * a1))


def _as_matrices(dc21, ds21):
    shape = np.shape(dc21)
    dc = np.zeros(shape + (3, 3))
    ds = np.zeros(shape + (3, 3))
    dc[..., 2, 1] = dc21
    ds[..., 2, 1] = ds21
    return dc, ds


@dataclass(frozen=True, eq=False)
class _PoleTide:
    orientation: Callable | None = None
    nmax: int = field(default=2, init=False)

    def _formula(self, m1, m2):
        raise NotImplementedError

    def evaluate(self, eo, tdb=None) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS) S + (3, 3) from an Earth orientation eo (xp, yp [rad] S,
        tt (jd1, jd2)); ``tdb`` unused."""
        m1, m2 = wobble(eo.xp, eo.yp, eo.tt)
        return _as_matrices(*self._formula(m1, m2))

    def __call__(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), float64 S + (3, 3) [n, m] (only [2, 1] non-zero), at
        t = t_hi + t_lo [s TT since epoch]."""
        from .solid_tides import _resolve_orientation

        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, np.float64), np.asarray(t_lo, np.float64))
        eo = _resolve_orientation(self.orientation)(epoch, t_hi, t_lo)
        return self.evaluate(eo)


@dataclass(frozen=True, eq=False)
class SolidPoleTide(_PoleTide):
    """Solid Earth pole tide (TN36 eq. 6.22) as a Stokes-coefficient provider.

    ``provider(epoch, t_hi, t_lo)`` -> (dC, dS), float64 S + (3, 3) [n, m],
    dimensionless, fully normalised, ITRS; only [2, 1] is non-zero.
    orientation: callable (epoch, t_hi, t_lo) -> object with xp, yp [rad]
    and tt (jd1, jd2); None -> :func:`tqdyn.astro.earth_orientation.earth_orientation`.
    """

    name: str = field(default="solid_pole_tide", init=False)
    description: str = field(default="solid Earth pole tide, dC21/dS21 from the wobble (IERS 2010 mean pole)",
                             init=False)
    source: str = field(default="IERS Conventions 2010 (TN36) eq. 6.22, mean pole eq. 7.25", init=False)

    def _formula(self, m1, m2):
        return solid_pole_tide(m1, m2)


@dataclass(frozen=True, eq=False)
class OceanPoleTide(_PoleTide):
    """Ocean pole tide, degree 2 (TN36 eq. 6.24, Desai 2002) as a
    Stokes-coefficient provider; same interface as :class:`SolidPoleTide`."""

    name: str = field(default="ocean_pole_tide", init=False)
    description: str = field(default="ocean pole tide, degree 2 (Desai 2002 equilibrium model)", init=False)
    source: str = field(default="IERS Conventions 2010 (TN36) eq. 6.24 (Desai 2002)", init=False)

    def _formula(self, m1, m2):
        return ocean_pole_tide(m1, m2)
