"""Atmospheric tides S1 and S2 (Biancale & Bode 2006) as corrections to the
Earth's Stokes coefficients.

Model: the mean-annual prograde S1 (Doodson 164.556) and S2 (273.555)
surface-pressure tides of Biancale & Bode (2006, GFZ STR06/01; the paper's
Table II cites the same model as "Biancale & Bode 2003"), 24 terms per wave,
n <= 8, m <= 5, amplitudes A [hPa] and phases eps [deg] in
``data/atm_tides_bb2006_S1S2.txt`` (provenance in SOURCES.md), read by
:mod:`tqdyn.readers.bb2006`.

Derivation (pressure -> Stokes coefficients)
---------------------------------------------

1. *Pressure field and phase convention.*  With geocentric latitude phi,
   east longitude lambda (ITRS), fully normalised Pbar_nm (4 pi
   normalisation, no Condon-Shortley phase) and the Doodson phase theta_f =
   n_f . beta of the wave (:mod:`tqdyn.astro.tidal_arguments`, tau = theta_g
   + pi - s), the surface pressure of wave f is

       p_f(phi, lambda, t) = sum_nm A_nm Pbar_nm(sin phi) sin(theta_f + m lambda + eps_nm)
                           = sum_nm Pbar_nm(sin phi) [Pc_nm cos(m lambda) + Ps_nm sin(m lambda)],
       Pc_nm = A_nm sin(theta_f + eps_nm),   Ps_nm = A_nm cos(theta_f + eps_nm)   [Pa].

   This is the amplitude/phase form of TN36 eq. 6.21 (Delta C+ = F C+ sin eps,
   Delta S+ = F C+ cos eps) inserted in eq. 6.15: there Delta C - i Delta S =
   (C+ - i S+) e^{i theta} = -i F A e^{i (theta + eps)}, and the load it
   describes, Re[(Delta C - i Delta S) e^{i m lambda}] / F, is A sin(theta +
   m lambda + eps).  In the file note's words (Csin+ = A sin eps, Ccos+ = A
   cos eps) the pressure is Csin+ cos(theta + m lambda) + Ccos+ sin(theta +
   m lambda): the names refer to the phase, not to the function they
   multiply.  The other reading, p = Ccos+ cos(theta + m lambda) + Csin+
   sin(theta + m lambda) = A cos(theta + m lambda - eps), puts the S2
   maximum at ~04:54 / 16:54 local solar time and is rejected by the
   physical check (tests/test_atmospheric_tides.py); the convention above
   puts it at ~10:00 / 22:00 (item 5).

2. *Mass.*  Hydrostatic balance: a surface-pressure anomaly p is the weight
   of a column of surface mass density sigma = p / g.  g = 9.80665 m/s^2
   (standard gravity); the real g varies from 9.780 to 9.832 m/s^2 with
   latitude and the atmosphere's mass-weighted g is ~0.3 % below the surface
   value (mean height of its mass ~8 km): a +-0.3 % uncertainty, far inside
   that of the model.  The water density does not enter: TN36 eq. 6.21
   writes the load as an equivalent water height h_w = p / (rho_w g)
   multiplied by rho_w, which cancels.  (The shortcut "1 hPa = 1 cm of water" with rho_w = 1025 kg/m^3
   gives sigma = 10.25 kg/m^2 per hPa instead of 100 / g = 10.197: +0.5 %.)

3. *Potential of the load.*  A thin layer sigma(Omega) = sum sigma_nm
   Ybar_nm(Omega) on the sphere of radius a has, outside it, with 1/|r - r'|
   = sum_n a^n / r^(n+1) P_n(cos psi) and the addition theorem P_n(cos psi)
   = sum_m Ybar_nm(Omega) Ybar_nm(Omega') / (2n + 1),

       V_load(r, Omega) = G a^2 int sigma(Omega') / |r - r'| dOmega'
                        = sum_n 4 pi G a^2 / (2n + 1) a^n / r^(n+1) sigma_n(Omega).

   The elastic Earth deformed by the load adds k'_n V_load per degree (load
   Love numbers).  Matching V = GM/r sum (a/r)^n Pbar_nm (Delta C_nm cos m
   lambda + Delta S_nm sin m lambda) term by term:

       Delta C_nm = F_n Pc_nm,   Delta S_nm = F_n Ps_nm,
       F_n = 4 pi G a^2 (1 + k'_n) / (GM g (2n + 1))       [1/Pa]
           = 3 (1 + k'_n) / (rho_E a g (2n + 1)),  rho_E = 3 GM / (4 pi G a^3).

   TN36 eq. 6.21 has the same factor as 4 pi G rho_w / g_e with g_e =
   9.7803278 m/s^2 standing for GM/a^2 = 9.79829 m/s^2 (0.18 % apart); the
   exact form above is used, with the static field's GM and a (EGM2008:
   3.986004415e14 m^3/s^2, 6378136.3 m) and G = 6.67430e-11 m^3/(kg s^2)
   (CODATA 2018; only GM/G, the Earth's mass, enters).  The load is placed
   on the sphere of radius a, as in TN36; on the mean radius 6371.0 km it
   would be smaller by (R_mean/a)^(n+2), 0.45 % at n = 2.

   k'_n: TN36 sec. 6.3.1 (Farrell 1972) for n = 2..6: -0.3075, -0.195,
   -0.132, -0.1032, -0.0892; TN36 stops at n = 6, so n = 7, 8 take Gegout's
   values (as distributed with Orekit, ``fic.love.kp.gegout``): -0.0821,
   -0.0767 (Gegout's n = 2..6 agree with TN36 to <= 2 %).  Degrees 7 and 8
   reach a satellite at 1e5 km attenuated by (a/r)^7 ~ 4e-9: any reasonable
   k'_7, k'_8 gives the same orbit.

4. *Degrees 0 and 1* are zeroed (the file has small (0,0) and (1,m) terms):
   the total mass of Earth plus atmosphere is constant, and tqdyn's origin is
   the centre of mass of the whole system, which a redistribution inside it
   does not move (as for the ocean tides); the Earth-field term starts at
   degree 2 anyway.  Delta S_n0 = 0 (it multiplies sin 0).

5. *Doodson arguments.*  S2 = 273.555: theta = 2 tau + 2 s - 2 h =
   2 (theta_g - h + pi) (mod 2 pi), twice the mean solar time at Greenwich
   counted from midnight (h ~ the right ascension of the mean Sun), so the
   migrating (2,2) term is A sin(2 T_loc + eps) in the local mean solar time
   T_loc (angle from midnight): maximum at 2 T_loc = 90 deg - eps, i.e.
   eps = 148.8 deg gives 10:02 and 22:02 (the classical 09:45 / 21:45 of the
   barometric S2, Haurwitz & Cowley 1973).  Measured with the full
   machinery against the Sun's hour angle from DE421 over 90 days from
   2004-06-06: 09:56-10:04 and 21:56-22:04 apparent solar time (the spread
   is the equation of time; tests).  S1 = 164.556: theta = (theta_g - h +
   pi) + p_s, the mean solar time plus the longitude of the Sun's perigee p_s
   (~283 deg, 1.7 deg per century): the Cartwright-Tayler S1, whose number
   the file header states; the phases of S1 are referred to this argument
   (164.555 would move the S1 maximum by p_s / 15 deg = 18.9 h).  With it
   the migrating S1 (1,1) term peaks at 06:09-06:17 local solar time: the
   morning maximum that makes the 10:00 peak of the tropical barogram
   higher than the 22:00 one and the 16:00 minimum deeper than the 04:00
   one.

Magnitudes (tests/test_atmospheric_tides.py): F_2 = 1.21e-12 / Pa; S2
Delta C22 amplitude 6.6e-11, S1 8.0e-12; max acceleration at r = 1e8 m over
a day and over directions 7.6e-14 m/s^2 in total, 6.9e-14 from the S2 and
9.7e-15 from the S1 degree-2 terms, 1.5e-15 from degrees 3-8 (first-principles
estimate of the S2 (2,2) term alone: 3 max|Pbar_22| GM/r^2 (a/r)^2 F_2
A_S2,22 = 6.2e-14 m/s^2); along the TianQin orbits over 10 days (`tqdyn
forces`) 6.7e-14 m/s^2 max, 3.9e-14 RMS (docs/force-model.md).  The signal
is at 1 and 2 cycles per solar day, below TianQin's band (1e-4 .. 1 Hz).

Where this differs from the paper and from IERS 2010: the paper's Table II
cites Biancale & Bode (2003); the coefficients here are those of the 2006
report (the same model, the only published numbers available here,
transcribed, not checked against the report).  The IERS 2010 conventional
geopotential (TN36 chapter 6) has no atmospheric-tide term; TN36 (chapter 7)
models only the S1/S2 pressure-*loading displacement* of stations.  Not
included: the ocean's response to the S1/S2 pressure (inverted or not:
whether FES2004's S2 already contains part of it is not examined here), the
seasonal modulation of the waves (mean-annual model only) and the other
radiational lines.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..astro.constants import GM_EARTH_EGM2008, R_EARTH_EGM2008
from ..astro.tidal_arguments import delaunay_arguments, doodson_arguments, tidal_harmonic_sum
from ..readers.bb2006 import BB2006_MAX_DEGREE, AtmosphericTideModel, read_bb2006

__all__ = [
    "G_NEWTON",
    "G_SURFACE",
    "LOAD_LOVE_NUMBERS",
    "AtmosphericTides",
    "atmospheric_tide_coefficients",
    "pressure_coefficients",
    "stokes_factor",
]

#: Newtonian constant of gravitation [m^3 kg^-1 s^-2] (CODATA 2018); only
#: the Earth's mass GM/G enters (relative uncertainty 2.2e-5).
G_NEWTON = 6.67430e-11
#: Standard gravity [m/s^2] (CGPM 1901): surface pressure -> mass per area.
G_SURFACE = 9.80665
#: Load Love numbers k'_n: TN36 sec. 6.3.1 (Farrell 1972) for n = 2..6,
#: Gegout (Orekit ``fic.love.kp.gegout``) for n = 7, 8; n = 0, 1 unused.
LOAD_LOVE_NUMBERS = {2: -0.3075, 3: -0.195, 4: -0.132, 5: -0.1032, 6: -0.0892, 7: -0.0821, 8: -0.0767}
_MIN_DEGREE = 2


def stokes_factor(n, gm: float = float(GM_EARTH_EGM2008), r_ref: float = R_EARTH_EGM2008,
                  g: float = G_SURFACE) -> np.ndarray:
    """F_n = 4 pi G a^2 (1 + k'_n) / (GM g (2n + 1)) [1/Pa]: fully normalised
    Stokes coefficient per Pa of the surface-pressure coefficient of degree n
    (module docstring, item 3).  n: int or array of degrees 2..8; gm
    [m^3/s^2], r_ref = a [m]: of the static field; g [m/s^2]."""
    n = np.asarray(n, dtype=np.int64)
    if np.any((n < _MIN_DEGREE) | (n > BB2006_MAX_DEGREE)):
        raise ValueError(f"atmospheric tides: degree {n} outside {_MIN_DEGREE}..{BB2006_MAX_DEGREE} "
                         "(load Love numbers known here)")
    k = np.vectorize(LOAD_LOVE_NUMBERS.__getitem__, otypes=[np.float64])(n)
    return 4.0 * math.pi * G_NEWTON * r_ref * r_ref * (1.0 + k) / (gm * g * (2.0 * n + 1.0))


def _wave_table(model: AtmosphericTideModel, degree: int):
    """(multipliers (n_w, 6), wave index per term (k,), term mask) of the
    terms with 2 <= n <= degree."""
    names = model.waves
    mult = np.array([model.doodson[model.wave.index(w)] for w in names], dtype=np.int64)
    widx = np.array([names.index(w) for w in model.wave], dtype=np.int64)
    keep = (model.n >= _MIN_DEGREE) & (model.n <= degree)
    return mult, widx, keep


def _weights(model: AtmosphericTideModel, degree: int, scale: np.ndarray):
    """(multipliers, W_cos, W_sin): [cos theta_w] @ W_cos + [sin theta_w] @
    W_sin gives Pc then Ps (times ``scale`` per term) flattened over (n, m),
    from Pc = A sin(theta + eps) = A sin eps cos theta + A cos eps sin theta,
    Ps = A cos(theta + eps) = A cos eps cos theta - A sin eps sin theta."""
    mult, widx, keep = _wave_table(model, degree)
    k = degree + 1
    wc = np.zeros((len(mult), 2, k, k))
    ws = np.zeros((len(mult), 2, k, k))
    for j in np.flatnonzero(keep):
        w, n, m = widx[j], model.n[j], model.m[j]
        a = model.amplitude[j] * scale[j]
        se, ce = math.sin(model.phase[j]), math.cos(model.phase[j])
        wc[w, 0, n, m] += a * se
        ws[w, 0, n, m] += a * ce
        if m > 0:  # Ps_n0 multiplies sin(0 lambda) = 0
            wc[w, 1, n, m] += a * ce
            ws[w, 1, n, m] -= a * se
    return mult, wc.reshape(len(mult), 2 * k * k), ws.reshape(len(mult), 2 * k * k)


def _harmonics(beta, mult, wc, ws, k):
    out = tidal_harmonic_sum(beta, mult, wc, ws)
    out = out.reshape(out.shape[:-1] + (2, k, k))
    return out[..., 0, :, :], out[..., 1, :, :]


def pressure_coefficients(beta, model: AtmosphericTideModel, degree: int = BB2006_MAX_DEGREE):
    """Surface-pressure coefficients (Pc, Ps) [Pa] of the tide at Doodson
    arguments beta S + (6,) [rad] (:func:`tqdyn.astro.tidal_arguments.doodson_arguments`):
    p = sum_nm Pbar_nm(sin phi) [Pc_nm cos m lambda + Ps_nm sin m lambda]
    (module docstring, item 1); float64 S + (degree+1, degree+1) each,
    degrees 2..degree (0 and 1 left zero)."""
    mult, wc, ws = _weights(model, degree, np.ones(len(model.wave)))
    return _harmonics(beta, mult, wc, ws, degree + 1)


def atmospheric_tide_coefficients(beta, model: AtmosphericTideModel, degree: int = BB2006_MAX_DEGREE,
                                  gm: float = float(GM_EARTH_EGM2008), r_ref: float = R_EARTH_EGM2008,
                                  g: float = G_SURFACE):
    """(Delta C, Delta S) = F_n (Pc, Ps): dimensionless fully normalised
    Stokes corrections (ITRS), float64 S + (degree+1, degree+1) [n, m], at
    Doodson arguments beta S + (6,) [rad]; F_n of :func:`stokes_factor`."""
    mult, wc, ws = _weights(model, degree, _term_factors(model, degree, gm, r_ref, g))
    return _harmonics(beta, mult, wc, ws, degree + 1)


def _term_factors(model, degree, gm, r_ref, g) -> np.ndarray:
    """F_n of each term (0 for the terms outside 2..degree, which are dropped)."""
    out = np.zeros(len(model.wave))
    ok = (model.n >= _MIN_DEGREE) & (model.n <= degree)
    out[ok] = stokes_factor(model.n[ok], gm, r_ref, g)
    return out


@dataclass(frozen=True, eq=False)
class AtmosphericTides:
    """Biancale & Bode (2006) S1/S2 atmospheric tides as a Stokes-coefficient
    provider (same interface as :class:`tqdyn.forces.ocean_tides.OceanTides`).

    ``provider(epoch, t_hi, t_lo)`` (t = t_hi + t_lo [s TT since epoch],
    shape S) returns (dC, dS), float64 S + (degree+1, degree+1) [n, m]:
    dimensionless corrections to the fully normalised Stokes coefficients
    (ITRS), referred to ``gm``, ``r_ref`` (the static field's; EGM2008
    defaults).

    Parameters
    ----------
    degree : maximum degree, 2..8 (default 8, all of the file).
    waves : the waves to include (default both, ("S1", "S2")).
    orientation : callable (epoch, t_hi, t_lo) -> object with gmst [rad] S
        and tt (jd1, jd2); None -> :func:`tqdyn.astro.earth_orientation.earth_orientation`.
    path : coefficient file; None -> the shipped one.
    gm [m^3/s^2], r_ref [m], g [m/s^2] : constants of the conversion
        (module docstring, items 2 and 3).
    """

    degree: int = BB2006_MAX_DEGREE
    waves: tuple = ("S1", "S2")
    orientation: Callable | None = None
    path: str | None = None
    gm: float = float(GM_EARTH_EGM2008)
    r_ref: float = R_EARTH_EGM2008
    g: float = G_SURFACE
    name: str = field(default="atmospheric_tides", init=False)
    description: str = field(default="atmospheric tides S1, S2 (surface-pressure load, degrees 2-8), "
                                     "TN36 eq. 6.15/6.21 form", init=False)
    source: str = field(default="Biancale & Bode (2006), GFZ STR06/01, mean-annual S1/S2 (paper: Biancale & "
                                "Bode 2003); load Love numbers TN36 sec. 6.3.1 (n <= 6), Gegout (n = 7, 8)",
                        init=False)

    def __post_init__(self):
        deg = self.degree
        if isinstance(deg, bool) or not isinstance(deg, (int, np.integer)) or not 2 <= deg <= BB2006_MAX_DEGREE:
            raise ValueError(f"atmospheric tides: degree {deg!r} must be an integer in 2..{BB2006_MAX_DEGREE}")
        object.__setattr__(self, "degree", int(deg))
        object.__setattr__(self, "waves", tuple(self.waves))
        self._tables  # read and validate now, not in the middle of a run  # noqa: B018

    @property
    def model(self) -> AtmosphericTideModel:
        """The selected waves of the coefficient file (read once per process)."""
        full = read_bb2006(self.path)
        unknown = [w for w in self.waves if w not in full.waves]
        if unknown or not self.waves:
            raise ValueError(f"atmospheric tides: waves {list(self.waves)} must be a non-empty subset of "
                             f"{list(full.waves)}")
        keep = [i for i, w in enumerate(full.wave) if w in self.waves]
        return AtmosphericTideModel(wave=tuple(full.wave[i] for i in keep),
                                    doodson_number=tuple(full.doodson_number[i] for i in keep),
                                    doodson=full.doodson[keep], n=full.n[keep], m=full.m[keep],
                                    amplitude=full.amplitude[keep], phase=full.phase[keep])

    @functools.cached_property
    def _tables(self):
        model = self.model
        return _weights(model, self.degree, _term_factors(model, self.degree, self.gm, self.r_ref, self.g))

    def coefficients(self, beta) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS) S + (degree+1, degree+1) at Doodson arguments beta S + (6,) [rad]."""
        mult, wc, ws = self._tables
        return _harmonics(np.asarray(beta, dtype=np.float64), mult, wc, ws, self.degree + 1)

    def evaluate(self, eo, tdb=None) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS) S + (degree+1, degree+1) from an Earth orientation eo
        (gmst [rad] S, tt (jd1, jd2)); ``tdb`` is unused (same signature as
        the other providers)."""
        from .solid_tides import _tt_pair

        return self.coefficients(doodson_arguments(eo.gmst, delaunay_arguments(*_tt_pair(eo))))

    def __call__(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), float64 S + (degree+1, degree+1), at t = t_hi + t_lo [s
        TT since epoch]."""
        from .solid_tides import _resolve_orientation

        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, np.float64), np.asarray(t_lo, np.float64))
        eo = _resolve_orientation(self.orientation)(epoch, t_hi, t_lo)
        return self.evaluate(eo)
