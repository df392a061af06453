"""Ocean tides (FES2004) as corrections to the Earth's Stokes coefficients
(IERS Conventions 2010 = TN36, sec. 6.3, eq. 6.15).

Model: FES2004 (Lyard et al. 2006) in the spherical-harmonic form distributed
with TN36, ``data/fes2004_Cnm-Snm.dat`` (see SOURCES.md): 18 waves (2N2 K1 K2
M2 M4 Mf Mm Msq Mtm N2 O1 Om1 Om2 P1 Q1 S2 Sa Ssa), degree and order <= 100,
coefficients DelC+-, DelS+- of the fully normalised Stokes coefficients in
units of 1e-11 (the unit fixed by the TN36 update of 23 Sep 2011).  The
paper's model is the same FES2004 to n = 10 (its Table II).  The file is
read by :mod:`tqdyn.readers.fes2004`.

TN36 eq. 6.15:

    dC_nm - i dS_nm = sum_f sum_(+,-) (C^+-_f,nm -/+ i S^+-_f,nm) exp(+- i theta_f)

i.e., expanded (TN36's own real form; Orekit ``OceanTidesWave`` uses the same):

    dC_nm = sum_f [(C+ + C-) cos theta_f + (S+ + S-) sin theta_f]
    dS_nm = sum_f [(S+ - S-) cos theta_f - (C+ - C-) sin theta_f]

with theta_f = n_f . beta the Doodson phase of the wave (TN36 sec. 6.2/6.3,
tau = theta_g + pi - s; :mod:`tqdyn.astro.tidal_arguments`).  The file's
coefficients are used as given (its header states no other phase
convention).  Known caveat (TN36 chapter 6 updates of 23 Sep and 14 Oct
2011): the phase of the C20 term of the very long-period equilibrium waves
Om1/Om2 (first two data lines) was set to pi/2 with "an ongoing discussion"
whether it should be -pi/2, i.e. the sign of their dC20 (Om1: 6.6e-11,
18.6-year period, ~7e-14 m/s^2 at r = 1e8 m, nearly constant over a 90-day
run) is uncertain.

Not done: (1) admittance for the secondary waves (TN36 sec. 6.3.2 allows
interpolating minor lines from the main ones; they are each at most a few %
of the main waves -- an estimate, not measured here -- i.e. ~1e-15 m/s^2 at
r = 1e8 m); (2) the degree-1 terms: tqdyn's origin is the center of mass
of the whole Earth including its oceans, and a mass redistribution inside
the system does not move that origin, so it exerts no degree-1 force in
this frame; degrees < ``min_degree`` = 2 are zeroed (the file's n = 1 rows
are zero anyway);
(3) the atmospheric tides (S1, S2; "atmospheric tide NOT included" in the
file header): see :mod:`tqdyn.forces.atmospheric_tides`.

Magnitude at r = 1e8 m (max over a day and over directions, measured in
tests/test_ocean_tides.py): 1.4e-12 m/s^2 in total, degree 2 1.3e-12,
degree 3 1.5e-13, degrees 5-10 together 8e-16; each degree is attenuated by
a further R/r = 0.064.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..astro.tidal_arguments import delaunay_arguments, doodson_arguments, tidal_cos_sin
from ..readers.fes2004 import OceanTideModel, read_fes2004

__all__ = [
    "OceanTides",
    "ocean_tide_coefficients",
]


def ocean_tide_coefficients(beta, model: OceanTideModel):
    """Ocean-tide corrections (TN36 eq. 6.15) at given Doodson arguments.

    beta: S + (6,) Doodson arguments [rad] (tau, s, h, p, N', p_s) at the
    instants; model: :class:`tqdyn.readers.fes2004.OceanTideModel`.
    Returns (dC, dS), float64 S + (nmax+1, nmax+1) indexed [n, m],
    dimensionless, fully normalised, ITRS (two views of one S + (2, nmax+1,
    nmax+1) array, from one matrix product; dS_n0 = 0).
    """
    c, s = tidal_cos_sin(beta, model.doodson)                           # S + (n_w,) each
    shape = c.shape[:-1]
    k = model.nmax + 1
    out = np.concatenate([c, s], axis=-1) @ model._weights                # S + (2 k^2,)
    out = out.reshape(shape + (2, k, k))
    return out[..., 0, :, :], out[..., 1, :, :]


@dataclass(frozen=True, eq=False)
class OceanTides:
    """FES2004 ocean tides (TN36 sec. 6.3) as a Stokes-coefficient provider.

    ``provider(epoch, t_hi, t_lo)`` (t = t_hi + t_lo [s TT since epoch],
    shape S) returns (dC, dS), float64 S + (nmax+1, nmax+1) [n, m]:
    dimensionless corrections to the fully normalised Stokes coefficients
    (ITRS; FES2004 is normalised like EGM2008 and independent of the field's
    GM and radius at this level).

    Parameters
    ----------
    nmax : maximum degree and order (default 10, as in the paper; <= 100).
    orientation : callable (epoch, t_hi, t_lo) -> object with gmst [rad] S
        and tt (jd1, jd2); None -> :func:`tqdyn.astro.earth_orientation.earth_orientation`.
    path : FES2004 file; None -> the shipped one.
    """

    nmax: int = 10
    orientation: Callable | None = None
    path: str | None = None
    name: str = field(default="ocean_tides", init=False)
    description: str = field(default="ocean tides FES2004 (18 waves, no admittance), eq. 6.15", init=False)
    source: str = field(default="FES2004 (Lyard et al. 2006) as distributed with IERS Conventions 2010, "
                                "sec. 6.3", init=False)

    def __post_init__(self):
        object.__setattr__(self, "nmax", int(self.nmax))
        self.model  # read (and validate nmax) now, not in the middle of a run  # noqa: B018

    @property
    def model(self) -> OceanTideModel:
        """The FES2004 waves up to ``nmax`` (read once per process)."""
        return read_fes2004(self.path, self.nmax)

    def evaluate(self, eo, tdb=None) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS) S + (nmax+1, nmax+1) from an Earth orientation eo (gmst
        [rad] S, tt (jd1, jd2)); ``tdb`` is unused (same signature as the
        other providers)."""
        from .solid_tides import _tt_pair

        beta = doodson_arguments(eo.gmst, delaunay_arguments(*_tt_pair(eo)))
        return ocean_tide_coefficients(beta, self.model)

    def __call__(self, epoch, t_hi, t_lo=0.0) -> tuple[np.ndarray, np.ndarray]:
        """(dC, dS), float64 S + (nmax+1, nmax+1), at t = t_hi + t_lo [s TT
        since epoch]."""
        from .solid_tides import _resolve_orientation

        t_hi, t_lo = np.broadcast_arrays(np.asarray(t_hi, np.float64), np.asarray(t_lo, np.float64))
        eo = _resolve_orientation(self.orientation)(epoch, t_hi, t_lo)
        return self.evaluate(eo)
