"""Physical and astronomical constants used by tqdyn (SI units).

Each constant states its value, unit and source.  Values whose decimal form
is the defining form are kept as exact decimal strings so that extended
precision code (mpmath, double-double) can convert them without a float64
rounding step.
"""

import math

__all__ = [
    "GM_EARTH_EGM2008",
    "R_EARTH_EGM2008",
    "C_LIGHT",
    "DAY_S",
    "J2000_JD",
    "J_EARTH_IERS2010",
    "AU_M",
    "ARCSEC_RAD",
    "MJD_JD0",
    "L_G",
    "L_B",
]

# Geocentric gravitational constant [m^3/s^2], exact decimal string as published
# with the EGM2008 model (Pavlis et al. 2012, JGR 117, B04406; EGM2008 coefficient
# file header: GM = 0.3986004415E+15).  TT-compatible value.
GM_EARTH_EGM2008 = "3.986004415e14"

# Reference radius of the EGM2008 spherical-harmonic expansion [m]
# (EGM2008 coefficient file header: a = 6378136.3 m).
R_EARTH_EGM2008 = 6378136.3

# Speed of light in vacuum [m/s], exact by definition of the metre (SI, 1983).
C_LIGHT = 299792458.0

# Length of the (SI) day [s], exact: 1 d = 86400 s (IAU convention for Julian days).
DAY_S = 86400

# Julian date of the J2000.0 epoch, 2000-01-01T12:00:00 TT [d] (IAU 1976/2000).
J2000_JD = 2451545.0

# Earth's angular momentum per unit mass |J| [m^2/s], the value quoted with the
# Lense-Thirring term of the IERS Conventions 2010 (TN36, sec. 10.3, eq. 10.12):
# |J| ~ 9.8e8 m^2/s (C Omega / M with C/(M a^2) = 0.3307, Omega = 7.292e-5 rad/s).
J_EARTH_IERS2010 = 9.8e8

# Astronomical unit [m], exact by definition (IAU 2012 Resolution B2).
AU_M = 149597870700.0

# One second of arc [rad]: pi / (180 * 3600).
ARCSEC_RAD = math.pi / 648000.0

# Julian date of MJD 0 [d]: MJD = JD - 2400000.5 (IAU 1973).
MJD_JD0 = 2400000.5

# Rate of TCG relative to TT [1], defining constant: d(TT)/d(TCG) = 1 - L_G
# (IAU 2000 Resolution B1.9); L_G c^2 is the potential of the geoid, W_0.
L_G = 6.969290134e-10

# Rate of TCB relative to TDB [1], defining constant: d(TDB)/d(TCB) = 1 - L_B
# (IAU 2006 Resolution B3).
L_B = 1.550519768e-8
