"""Atmospheric tides: NOT modelled -- what they would be and how large.

The paper (its Table II) lists atmospheric tides after Biancale & Bode
(2003), i.e. Stokes-coefficient waves (mainly S1 and S2) of the mass of the
atmosphere redistributed by the solar thermal tides.  Those coefficient
files are not available to tqdyn (nothing is downloaded), and the FES2004
ocean-tide file says "atmospheric tide NOT included".  This module therefore
models nothing; it documents the omission and gives an order-of-magnitude
estimate of the missing acceleration for ``tqdyn info`` / the force budget.

Estimate (S2, the largest and most regular: a migrating sectoral wave, so
almost all of it is in (n, m) = (2, 2)):

* surface-pressure amplitude at the equator p_0 ~ 1.2 hPa (S2 climatology,
  Haurwitz & Cowley 1973; Dai & Wang 1999), pattern ~ p_0 cos^2(phi)
  cos(2 lambda + ...);
* in fully normalised harmonics cos^2(phi) = Pbar_22(sin phi) / sqrt(15/4)
  (Pbar_22 = sqrt(15)/2 cos^2 phi, max 1.936), so the (2, 2) pressure
  coefficient is p_22 = p_0 / 1.936 ~ 62 Pa, a surface mass density
  sigma_22 = p_22 / g ~ 6.3 kg/m^2;
* a surface load sigma_nm changes the Stokes coefficients by
  dC_nm = 3 (1 + k'_n) sigma_nm / (rho_E R (2n + 1))    (Wahr, Molenaar &
  Bryan 1998, JGR 103; rho_E = 5517 kg/m^3 mean density, k'_2 = -0.3075 the
  load Love number of TN36 sec. 6.3), which gives dC_22 ~ 7.5e-11 -- inside the
  1e-11 .. 1e-10 range of the published S2 atmospheric-tide coefficients;
* a single (n, m) term accelerates a satellite at distance r by at most
  (n + 1) GM/r^2 (R/r)^n max|Pbar_nm| |dC| (radial part at the equator;
  the horizontal parts are smaller and in quadrature), i.e. for (2, 2)

      a(r) ~ 3 * 1.936 * GM/r^2 * (R/r)^2 * dC_22

  = 7.0e-14 m/s^2 at r = 1e8 m (TianQin), 4.2e-9 m/s^2 at r = R.

The signal is at 2 cycles per solar day (2.3e-5 Hz), below TianQin's
measurement band (1e-4 .. 1 Hz); S1 (1 cpd) is several times weaker at
degree 2.  An analysis that needs it must add the Biancale & Bode waves as
another Stokes-coefficient provider (same interface as
:class:`tqdyn.forces.ocean_tides.OceanTides`).
"""

from __future__ import annotations

import math

from ..astro.constants import GM_EARTH_EGM2008, R_EARTH_EGM2008

__all__ = [
    "DESCRIPTION",
    "NAME",
    "NOT_MODELLED",
    "S2_PRESSURE_AMPLITUDE_PA",
    "SOURCE",
    "estimate_accel",
    "estimated_dc22",
]

#: The atmospheric tides are not part of tqdyn's force model.
NOT_MODELLED = True
NAME = "atmospheric_tides"
DESCRIPTION = "atmospheric tides (S1, S2): NOT modelled; order-of-magnitude estimate only"
SOURCE = ("paper: Biancale & Bode (2003), coefficients not available; estimate from the S2 surface-pressure "
          "tide (~1.2 hPa, Haurwitz & Cowley 1973)")

#: S2 surface-pressure amplitude at the equator [Pa] (order of magnitude:
#: Haurwitz & Cowley 1973; Dai & Wang 1999 find 1.1-1.3 hPa).
S2_PRESSURE_AMPLITUDE_PA = 120.0

_G_SURFACE = 9.80665        # m/s^2, standard gravity (CGPM 1901), converts pressure to mass
_RHO_EARTH = 5517.0         # kg/m^3, mean density of the Earth
_K2_LOAD = -0.3075          # degree-2 load Love number k'_2 (TN36 sec. 6.3)
_PBAR22_MAX = math.sqrt(15.0) / 2.0  # max of Pbar_22(sin phi) = sqrt(15)/2 cos^2(phi), at the equator


def estimated_dc22(p0: float = S2_PRESSURE_AMPLITUDE_PA, r_ref: float = R_EARTH_EGM2008) -> float:
    """Order-of-magnitude amplitude of the S2 atmospheric-tide dC_22 (fully
    normalised, dimensionless) for an equatorial pressure amplitude p0 [Pa]
    (derivation in the module docstring).  ~7.5e-11 for the defaults."""
    sigma22 = p0 / _PBAR22_MAX / _G_SURFACE                       # kg/m^2
    return 3.0 * (1.0 + _K2_LOAD) * sigma22 / (_RHO_EARTH * r_ref * 5.0)


def estimate_accel(r: float) -> float:
    """Order-of-magnitude amplitude [m/s^2] of the (unmodelled) S2
    atmospheric-tide acceleration at geocentric distance r [m]:
    3 max|Pbar_22| GM/r^2 (R/r)^2 dC_22 (7.0e-14 m/s^2 at r = 1e8 m).
    Raises ValueError for r <= 0."""
    r = float(r)
    if not r > 0.0:
        raise ValueError(f"atmospheric tides: distance r = {r} m must be positive")
    gm = float(GM_EARTH_EGM2008)
    q = R_EARTH_EGM2008 / r
    return 3.0 * _PBAR22_MAX * gm / (r * r) * q * q * estimated_dc22()
