"""The standard equal-arm Keplerian constellation (LISA, Taiji): heliocentric initial states in mpmath.

:func:`keplerian_constellation` returns the heliocentric position [m] and
velocity [m/s] of the three spacecraft of an equal-arm triangular
constellation at one TDB instant, with the orbits of
``lisaorbits.KeplerianOrbits`` (lisaorbits 2.4.2): three Keplerian ellipses
whose eccentricity and inclination are chosen to second order in
``alpha = L / (2 a)`` so that the arms stay close to L (Nayak, Koshti,
Dhurandhar & Vinet, "Reducing the flexing of the arms of LISA",
gr-qc/0507105, CQG 23, 1763 (2006): ``nu = pi/3 + delta alpha``,
``delta = 5/8``).
:func:`ecliptic_to_icrf_matrix` and :func:`ecliptic_elements_to_icrf` turn
ecliptic (J2000) coordinates and elements into the ICRF axes tqdyn uses.

Conventions of this module
--------------------------
* Units: SI -- m, m/s, m^3/s^2, s; angles in rad unless a name ends in
  ``_deg`` (degrees).  Values are mpf at ``max(50, mp.dps)`` digits (inputs:
  int, str, Decimal, float or mpf, as in :mod:`.elements`), so that
  :func:`tqdyn.astro.elements.state_to_dd` rounds them once to double-double.
* Frame: heliocentric (origin the Sun's centre of mass), axes of the ICRF
  (the BCRS/ICRS axes of the JPL ephemerides, equatorial); the ``*_ecliptic``
  fields are in the axes of the IAU 2006 mean ecliptic and equinox of J2000.
* Time scale: TDB.  The epoch is a TDB instant; ``a`` and ``gm`` are read as
  TDB-compatible values (DE430's GM of the Sun is the default); a two-body
  propagation of the states runs in TDB seconds since the epoch.
* Shapes: a position or velocity is a list of 3 mpf; the constellation's
  fields are tuples of 3 of them, index 0, 1, 2 = spacecraft 1, 2, 3.

lisaorbits' conventions (read from its source, lisaorbits/orbits.py 2.4.2)
--------------------------------------------------------------------------
* Orbits: spacecraft k = 1, 2, 3 has ``theta_k = (k - 1) 2 pi / 3``, mean
  anomaly ``m_init1 - theta_k + n (t - t_init)`` and longitude of perihelion
  ``lambda_k = lambda1 + theta_k``; its position is the perifocal ellipse
  ``(a cos i (cos E - e), a sqrt(1 - e^2) sin E, -a sin i (cos E - e))``
  turned by ``lambda_k`` about the ecliptic pole (so the perihelion lies
  below the ecliptic: node ``lambda_k + pi/2``, argument of perihelion
  ``3 pi/2``), with ``e = sqrt(1 + 4 alpha cos(nu) / sqrt(3) + 4 alpha^2/3) - 1``
  and ``tan i = alpha sin(nu) / (sqrt(3)/2 + alpha cos(nu))``.  E solves
  Kepler's equation (a 4th-order series in e and ``kepler_order = 2`` Newton
  steps in float64): the trajectory is an exact Kepler ellipse, only e, i
  and the tilt are expansions in alpha.
* Frame: ``KeplerianOrbits`` names none; x, y span the ecliptic.  The one
  ecliptic lisaorbits names is in ``OEMOrbits``: it converts ESA's EME2000
  files with astropy to ``HeliocentricMeanEcliptic`` (equinox J2000), i.e.
  ``erfa.ecm06(J2000)``: the IAU 2006 mean ecliptic and equinox of J2000,
  frame bias included.  This module takes KeplerianOrbits' axes to be that
  ecliptic.
* Time: t and ``t_init`` are TCB seconds; only ``t - t_init`` enters.
* GM: ``lisaconstants.GM_SUN`` = 1.3271244e20 m^3/s^2 (the IAU 2015 nominal
  value, 8 digits, at which its TCB and TDB values agree), not a parameter.
* Earth: lisaorbits has no Earth position (and no ``kappa``); the
  constellation is placed by ``lambda1`` and ``m_init1`` only.  All three
  spacecraft share the mean longitude ``lambda1 + m_init1 + n (t - t_init)``,
  the longitude of the triangle's centre to O(alpha^3).
* Sense: lisaorbits has no parameter; ESA's orbit files (lisa-orbit-files,
  included by ``OEMOrbits.from_included``) are labelled cw/ccw, "the apparent
  rotation of the constellation as seen from the Sun".  KeplerianOrbits gives
  the clockwise one (the triangle's normal points 30 deg above the ecliptic
  towards the Sun and the triangle turns clockwise about it once a year,
  retrograde); the counterclockwise one is its mirror image in the ecliptic
  (plane tilted the other way).  In both, the labels 1, 2, 3 go
  counterclockwise around the centre seen from the ecliptic north pole (as
  in ESA's cw and ccw files; lisaconstants.indexing writes "clockwise").

Where this module differs (each is a choice, stated here)
---------------------------------------------------------
* ICRF axes: the ecliptic states are rotated with
  :func:`ecliptic_to_icrf_matrix`, ``erfa.ecm06(J2000)`` transposed,
  computed in mpmath from its defining IAU 2006 angles.
* The Earth: the centre's mean longitude at the epoch is the Earth's mean
  longitude plus ``displacement_deg`` (ESA's "mean initial displacement
  angle from the mean Earth").  The Earth's mean longitude is that of the
  Earth-Moon barycentre in Standish's "Keplerian elements for approximate
  positions of the major planets" (JPL, table 1, 1800-2050 AD, mean
  ecliptic and equinox of J2000, T in Julian centuries of TDB from J2000):
  ``L = 100.46457166 deg + 35999.37244981 deg T`` (:func:`emb_mean_elements`).
  The Earth is 4671 km (<= 6.4 arcsec at 1 au) from that barycentre.
  ``earth_mean_longitude_deg`` overrides the model.
* ``gm`` and ``a`` are parameters (defaults: DE430's GM of the Sun from
  :func:`tqdyn.astro.ephemeris.planetary_gm`, a = 1 au), read as
  TDB-compatible.  Reading lisaorbits' (a, GM, t) as TCB-compatible instead
  is the same orbit with lengths and times scaled by ``1 - L_B`` (2.3 km at
  1 au, 39 m on a 2.5e9 m arm).
* ``sense = "counterclockwise"`` (not in lisaorbits): the mirror image of
  the clockwise design in the ecliptic (node ``lambda_k - pi/2``, argument
  of perihelion ``pi/2``).
* Kepler's equation is solved to full mpmath precision.

Measured (tests/test_constellation_design.py, L = 2.5e9 m, 2035)
----------------------------------------------------------------
Against KeplerianOrbits (same parameters, rotated to its ecliptic; LISA
and a 3e9 m counterclockwise case): <= 7.6e-5 m and 1.2e-11 m/s at the
epoch, <= 2.5e-4 m and 4.9e-11 m/s over one year of two-body motion
(float64 rounding in lisaorbits).  DE430's GM instead of
lisaconstants': 4.7e-6 m/s at the epoch, 148.6 m after one year.  The
arms: max |L_ij - L| = 1.063e7 m over a year, flexing (max - min)
0.575 alpha L = 1.2017e7 m (relative flexing of first order in alpha; for
L = 5e9 m, 47,890 km with delta = 5/8 and 114,134 km with delta = 0:
Nayak et al.'s ~48,000 and ~115,000 km).  The centre: 0.415 alpha^2 a =
4336 km inside 1 au, its longitude the mean one to 7.4e-8 rad; the plane
inclined 59.971 .. 60.031 deg to the ecliptic over the year.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpmath import mp, mpf

from .._choices import did_you_mean
from .constants import AU_M, J2000_JD
from .elements import _mp, _solve_kepler, _wrap, elements_to_state, state_to_dd

__all__ = [
    "AU",
    "DELTA",
    "SENSES",
    "ConstellationDesign",
    "ecliptic_to_icrf_matrix",
    "ecliptic_to_icrf",
    "ecliptic_elements_to_icrf",
    "emb_mean_elements",
    "keplerian_constellation",
]

#: The astronomical unit [m], exact (IAU 2012 B2); lisaorbits' default semi-major axis.
AU = str(int(AU_M))
#: The two rotation senses (apparent rotation of the triangle as seen from the Sun).
SENSES = ("clockwise", "counterclockwise")
#: lisaorbits' tilt correction: nu = pi/3 + delta * alpha (KeplerianOrbits.delta).
DELTA = "0.625"
#: Largest L / a accepted: the design is an expansion in alpha = L / (2 a).
MAX_L_OVER_A = "0.1"

# IAU 2006 Fukushima-Williams bias-precession angles at J2000 (t = 0) [arcsec]
# (Hilton et al. 2006; ERFA pfw06): gamma_bar, phi_bar, psi_bar; and the
# obliquity of the ecliptic at J2000, eps_A (ERFA obl06).
_GAMB0 = "-0.052928"
_PHIB0 = "84381.412819"
_PSIB0 = "-0.041775"
_EPS0 = "84381.406"

# Standish, "Keplerian elements for approximate positions of the major planets"
# (JPL Solar System Dynamics), table 1 (1800-2050 AD), EM Bary: value at J2000,
# rate per Julian century of TDB; a [au], e [-], angles [deg].
_EMB_TABLE = {
    "a": ("1.00000261", "0.00000562"),
    "e": ("0.01671123", "-0.00004392"),
    "i": ("-0.00001531", "-0.01294668"),
    "L": ("100.46457166", "35999.37244981"),
    "varpi": ("102.93768193", "0.32327364"),
    "raan": ("0.0", "0.0"),
}
_EMB_SPAN_JD = (2378496.5, 2470172.5)  # 1800-01-01 0h .. 2051-01-01 0h (TDB)

_MIN_DPS = 50


def _dps() -> int:
    return max(_MIN_DPS, mp.dps)


def _arcsec(x: str) -> mpf:
    return mpf(x) * mp.pi / 648000


def _r1(a):
    c, s = mp.cos(a), mp.sin(a)
    return [[mpf(1), mpf(0), mpf(0)], [mpf(0), c, s], [mpf(0), -s, c]]


def _r3(a):
    c, s = mp.cos(a), mp.sin(a)
    return [[c, s, mpf(0)], [-s, c, mpf(0)], [mpf(0), mpf(0), mpf(1)]]


def _matmul(x, y):
    return [[sum(x[i][k] * y[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def _matvec(m, v):
    return [m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] for i in range(3)]


def ecliptic_to_icrf_matrix() -> list[list[mpf]]:
    """Rotation from the IAU 2006 mean ecliptic and equinox of J2000 to the ICRF axes.

    Returns the 3x3 matrix M (list of 3 rows of 3 mpf at ``max(50, mp.dps)``
    digits) with ``r_icrf = M r_ecliptic`` (any vector, any origin).  M is the
    transpose of ``erfa.ecm06(2451545.0, 0.0)`` (ICRS -> ecliptic of J2000,
    frame bias included, the matrix of astropy's ``*MeanEcliptic`` frames at
    equinox J2000), computed from its defining angles: ecm06 is
    ``R1(eps_A) . fw2m(gamb, phib, psib, eps_A)`` =
    ``R1(eps_A) R1(-eps_A) R3(-psib) R1(phib) R3(gamb)``, so at J2000 it is
    ``R3(-psib0) R1(phib0) R3(gamb0)`` with the IAU 2006 Fukushima-Williams
    angles gamb0 = -0.052928", phib0 = 84381.412819", psib0 = -0.041775"
    (the frame bias and the J2000 obliquity 84381.406" combined:
    phib0 - eps_A = 0.006819", psib0 = the bias in longitude).  float64's
    ecm06 is rounded at 1.1e-16 (17 um at 1 au), too coarse for double-double
    states.  Composing instead erfa.bi00's IAU 2000 bias (-0.041775",
    -0.0068192", -0.0146") with R1(84381.406") gives a matrix 9.0e-13 off
    (0.13 m at 1 au): its -0.0068192" is not phib0 - eps_A.
    """
    with mp.workdps(_dps()):
        ecm = _matmul(_r3(-_arcsec(_PSIB0)), _matmul(_r1(_arcsec(_PHIB0)), _r3(_arcsec(_GAMB0))))
        return [[ecm[j][i] for j in range(3)] for i in range(3)]


def ecliptic_to_icrf(vec) -> list[mpf]:
    """A 3-vector (m or m/s; any origin) from ecliptic J2000 axes to ICRF axes (list of 3 mpf)."""
    with mp.workdps(_dps()):
        v = [_mp(c, f"vec[{k}]") for k, c in enumerate(vec)]
        if len(v) != 3:
            raise ValueError(f"vec: expected 3 components, got {len(v)}")
        return _matvec(ecliptic_to_icrf_matrix(), v)


def ecliptic_elements_to_icrf(a, e, i, raan, argp, nu, gm) -> tuple[list[mpf], list[mpf]]:
    """Heliocentric Keplerian elements in ecliptic J2000 axes -> heliocentric state in ICRF axes.

    Parameters: a [m], e [-], i, raan, argp, nu [rad] (inclination, node and
    argument of perihelion measured from the mean ecliptic and equinox of
    J2000; :func:`tqdyn.astro.elements.deg` converts degrees), gm [m^3/s^2]
    (the Sun's, TDB-compatible for tqdyn).  Returns r [m], v [m/s]: lists of
    3 mpf, ICRF axes, origin the Sun, at the epoch of the elements (TDB).
    """
    with mp.workdps(_dps()):
        r, v = elements_to_state(a, e, i, raan, argp, nu, gm)
        m = ecliptic_to_icrf_matrix()
        return _matvec(m, r), _matvec(m, v)


def _tdb_jd(epoch) -> mpf:
    """TDB Julian date [d] (mpf) of an epoch: a number, a pair (jd1, jd2) or an object with ``.tdb``."""
    pair = getattr(epoch, "tdb", epoch)
    if isinstance(pair, (tuple, list)):
        if len(pair) != 2:
            raise ValueError(f"epoch: {epoch!r}; allowed: a TDB Julian date, a pair (jd1, jd2) or a tqdyn Epoch")
        return _mp(pair[0], "epoch[0]") + _mp(pair[1], "epoch[1]")
    return _mp(pair, "epoch")


def emb_mean_elements(epoch) -> dict[str, mpf]:
    """Mean heliocentric elements of the Earth-Moon barycentre at an epoch (Standish, JPL, table 1).

    ``epoch``: TDB Julian date [d] (number, str or mpf), a pair (jd1, jd2)
    or a :class:`tqdyn.astro.timescales.Epoch` (its ``tdb``); 1800-2050 AD
    (the table's span; ValueError outside).  Returns mpf: ``a`` [m], ``e``
    [-], ``i``, ``raan``, ``varpi`` (longitude of perihelion), ``L`` (mean
    longitude) [rad], referred to the mean ecliptic and equinox of J2000;
    ``L`` in [0, 2 pi).  Accuracy of the table for the EMB: tens of arcsec.
    """
    with mp.workdps(_dps()):
        jd = _tdb_jd(epoch)
        if not (_EMB_SPAN_JD[0] <= jd <= _EMB_SPAN_JD[1]):
            raise ValueError(f"epoch: TDB JD {mp.nstr(jd, 12)}; allowed: JD {_EMB_SPAN_JD[0]} .. {_EMB_SPAN_JD[1]} "
                             "(1800-2050 AD, the span of the mean Earth model; pass earth_mean_longitude_deg "
                             "for other dates)")
        t = (jd - J2000_JD) / 36525
        out = {k: mpf(v0) + mpf(rate) * t for k, (v0, rate) in _EMB_TABLE.items()}
        out["a"] *= mpf(AU)
        for k in ("i", "raan", "varpi", "L"):
            out[k] = out[k] * mp.pi / 180
        out["L"] = _wrap(out["L"])
        return out


@dataclass(frozen=True)
class ConstellationDesign:
    """Initial states and parameters of an equal-arm Keplerian constellation (:func:`keplerian_constellation`).

    r, v : tuple of 3 lists of 3 mpf -- heliocentric positions [m] and
        velocities [m/s] of spacecraft 1, 2, 3, ICRF axes, at the epoch (TDB).
    r_ecliptic, v_ecliptic : the same in ecliptic J2000 axes (lisaorbits' frame).
    elements_ecliptic : tuple of 3 dicts of mpf -- osculating elements in
        ecliptic J2000 axes: ``a`` [m], ``e``, ``i``, ``raan``, ``argp``,
        ``m0`` (mean anomaly at the epoch), ``nu`` (true anomaly) [rad].
    L, a, gm : arm length [m], semi-major axis [m], GM of the Sun [m^3/s^2].
    alpha, e, inclination, tilt : L / (2 a); eccentricity; inclination of each
        orbit to the ecliptic [rad]; nu = pi/3 + delta alpha [rad].
    lambda1, m_init1 : lisaorbits' parameters [rad]: spacecraft 1's longitude
        of perihelion and mean anomaly at the epoch (in [0, 2 pi)).
    centre_mean_longitude, earth_mean_longitude : mean ecliptic longitudes
        [rad] of the constellation (= lambda1 + m_init1) and of the Earth.
    sense : ``"clockwise"`` or ``"counterclockwise"``; epoch_tdb_jd : TDB
        Julian date [d] of the states (None if the Earth's longitude was given
        and no epoch).
    """

    r: tuple
    v: tuple
    r_ecliptic: tuple
    v_ecliptic: tuple
    elements_ecliptic: tuple
    L: mpf
    a: mpf
    gm: mpf
    alpha: mpf
    e: mpf
    inclination: mpf
    tilt: mpf
    lambda1: mpf
    m_init1: mpf
    centre_mean_longitude: mpf
    earth_mean_longitude: mpf
    sense: str
    epoch_tdb_jd: mpf | None

    def states_dd(self) -> np.ndarray:
        """``(3, 6, 2)`` float64: per spacecraft, x, y, z [m], vx, vy, vz [m/s] (ICRF) as double-doubles."""
        return np.stack([state_to_dd(r, v) for r, v in zip(self.r, self.v)])


def keplerian_constellation(L, displacement_deg, sense, epoch=None, *, a=AU, gm=None, lambda1_deg=0,
                            earth_mean_longitude_deg=None, delta=DELTA) -> ConstellationDesign:
    """Heliocentric initial states of the equal-arm constellation of ``lisaorbits.KeplerianOrbits``.

    Parameters
    ----------
    L : arm length [m] (0 < L <= a / 10).
    displacement_deg : mean displacement of the constellation from the Earth
        [deg]: centre mean longitude minus the Earth's at the epoch; negative
        trails the Earth (LISA: -20), positive leads (Taiji: +20).
    sense : ``"clockwise"`` or ``"counterclockwise"``, the apparent rotation of
        the triangle seen from the Sun (ESA's cw/ccw; KeplerianOrbits is
        clockwise; counterclockwise is its mirror image in the ecliptic).
    epoch : TDB instant of the states: TDB Julian date [d] (number, str,
        mpf), a pair (jd1, jd2) or a :class:`tqdyn.astro.timescales.Epoch`;
        it places the Earth (:func:`emb_mean_elements`, 1800-2050).  May be
        None if ``earth_mean_longitude_deg`` is given.
    a : semi-major axis [m] of the three orbits (default 1 au, as lisaorbits).
    gm : GM of the Sun [m^3/s^2], TDB-compatible; None -> DE430's
        (``tqdyn.astro.ephemeris.planetary_gm()["sun"]``).  lisaorbits uses
        ``lisaconstants.GM_SUN`` = 1.3271244e20.
    lambda1_deg : spacecraft 1's longitude of perihelion [deg] (lisaorbits'
        ``lambda1``, default 0): the orientation of the triangle in its plane.
    earth_mean_longitude_deg : the Earth's mean ecliptic longitude at the
        epoch [deg], replacing the Standish model.
    delta : the tilt correction of nu = pi/3 + delta alpha (lisaorbits: 5/8).

    Returns
    -------
    :class:`ConstellationDesign`: positions [m] and velocities [m/s] of the
    3 spacecraft (ICRF axes, Sun-centred, TDB-compatible, mpf) and the
    parameters; ``m_init1 = centre_mean_longitude - lambda1`` so that
    ``KeplerianOrbits(L, a, lambda1, m_init1)`` is the same constellation
    (ecliptic axes, clockwise sense).

    Raises ValueError (one line naming the parameter, its value and what is
    allowed) for L <= 0, L > a / 10, an unknown sense, a <= 0, gm <= 0, or a
    missing or out-of-span epoch.
    """
    with mp.workdps(_dps()):
        a = _mp(a, "a")
        if not a > 0:
            raise ValueError(f"a: {a} m; allowed: a > 0")
        L = _mp(L, "L")
        if not L > 0:
            raise ValueError(f"L: {L} m; allowed: 0 < L <= {MAX_L_OVER_A} a ({mp.nstr(mpf(MAX_L_OVER_A) * a, 6)} m)")
        if L > mpf(MAX_L_OVER_A) * a:
            raise ValueError(f"L: {mp.nstr(L, 6)} m = {mp.nstr(L / a, 4)} a; allowed: 0 < L <= {MAX_L_OVER_A} a "
                             f"({mp.nstr(mpf(MAX_L_OVER_A) * a, 6)} m; the design expands in alpha = L / (2 a))")
        if sense not in SENSES:
            raise ValueError(f"sense: {sense!r}{did_you_mean(sense, SENSES)}; allowed: "
                             f"{' or '.join(repr(s) for s in SENSES)} (apparent rotation seen from the Sun)")
        if gm is None:
            from .ephemeris import planetary_gm

            gm = planetary_gm()["sun"]
        gm = _mp(gm, "gm")
        if not gm > 0:
            raise ValueError(f"gm: {gm} m^3/s^2; allowed: gm > 0")
        disp = _mp(displacement_deg, "displacement_deg") * mp.pi / 180
        lambda1 = _wrap(_mp(lambda1_deg, "lambda1_deg") * mp.pi / 180)
        delta = _mp(delta, "delta")
        jd = None if epoch is None else _tdb_jd(epoch)
        if earth_mean_longitude_deg is not None:
            lam_e = _wrap(_mp(earth_mean_longitude_deg, "earth_mean_longitude_deg") * mp.pi / 180)
        elif jd is None:
            raise ValueError("epoch: None; allowed: a TDB Julian date, a pair (jd1, jd2) or a tqdyn Epoch "
                             "(or give earth_mean_longitude_deg)")
        else:
            lam_e = emb_mean_elements(jd)["L"]
        centre = _wrap(lam_e + disp)
        m_init1 = _wrap(centre - lambda1)

        # lisaorbits.KeplerianOrbits.__init__, in mpmath
        alpha = L / (2 * a)
        tilt = mp.pi / 3 + delta * alpha
        s3 = mp.sqrt(3)
        e = mp.sqrt(1 + 4 * alpha * mp.cos(tilt) / s3 + 4 * alpha**2 / 3) - 1
        inc = mp.atan(alpha * mp.sin(tilt) / (s3 / 2 + alpha * mp.cos(tilt)))
        # clockwise: perihelion below the ecliptic (node lambda_k + pi/2, argp 3 pi/2);
        # counterclockwise: the mirror image in the ecliptic (node lambda_k - pi/2, argp pi/2)
        node_shift, argp = (mp.pi / 2, 3 * mp.pi / 2) if sense == "clockwise" else (-mp.pi / 2, mp.pi / 2)
        m = ecliptic_to_icrf_matrix()
        out = {"r": [], "v": [], "re": [], "ve": [], "el": []}
        for k in range(3):
            theta = k * 2 * mp.pi / 3
            m0 = _wrap(m_init1 - theta)
            lam_k = lambda1 + theta
            ecc = _solve_kepler(m0, e)
            nu = _wrap(2 * mp.atan2(mp.sqrt(1 + e) * mp.sin(ecc / 2), mp.sqrt(1 - e) * mp.cos(ecc / 2)))
            raan = _wrap(lam_k + node_shift)
            r, v = elements_to_state(a, e, inc, raan, argp, nu, gm)
            out["re"].append(r)
            out["ve"].append(v)
            out["r"].append(_matvec(m, r))
            out["v"].append(_matvec(m, v))
            out["el"].append({"a": a, "e": e, "i": inc, "raan": raan, "argp": argp, "m0": m0, "nu": nu})
        return ConstellationDesign(
            r=tuple(out["r"]), v=tuple(out["v"]), r_ecliptic=tuple(out["re"]), v_ecliptic=tuple(out["ve"]),
            elements_ecliptic=tuple(out["el"]), L=L, a=a, gm=gm, alpha=alpha, e=e, inclination=inc, tilt=tilt,
            lambda1=lambda1, m_init1=m_init1, centre_mean_longitude=centre, earth_mean_longitude=lam_e,
            sense=sense, epoch_tdb_jd=jd)
