"""GNSS transmitters from precise orbits (SP3 files, :mod:`tqdyn.readers.sp3`): the alternative
to the nominal Walker constellations of :mod:`.measurements_gnss`, with the same interface
(``states(t)``, GCRS [m, m/s] at t [s TT since the scenario epoch]) and the satellites' ids
(``ids``: "G07", "C23"), which name the pseudoranges' peers.

Each sample of the file is moved to the time axis of the scenario (TT = the file's time system
+ :data:`tqdyn.readers.sp3.TT_MINUS`: GPS time + 51.184 s, BDT + 65.184 s) and rotated from the
file's terrestrial frame (ITRS) into the GCRS with :func:`tqdyn.astro.earth_orientation.itrs_to_gcrs`
(IAU 2006/2000A with the IERS EOP, as the ground stations).  Positions are then interpolated in
the GCRS by a Lagrange polynomial through the :data:`POINTS` samples around t (degree 9 over the
5- or 15-minute samples, the usual choice for IGS orbits); velocities are the derivative of the
same polynomial.  A satellite with an absent sample in the window has NaN position and velocity
there (its pseudoranges are then not visible).  Times closer to the file's first or last epoch
than POINTS/2 - 1 samples (where the window would be off-centre) are refused.
"""

from __future__ import annotations

import os

import numpy as np

from ..astro.earth_orientation import itrs_to_gcrs
from ..numerics import lagrange
from ..readers.sp3 import TT_MINUS, SP3Orbits, merge_sp3, read_sp3

__all__ = ["POINTS", "SP3Constellation", "sp3_constellation", "sp3_constellations"]

#: Number of samples of the Lagrange interpolation (degree POINTS - 1), even.
POINTS = 10
_DAY_S = 86400.0
_MJD0 = 2400000.5


class SP3Constellation:
    """Transmitters of an SP3 file on the time axis and in the frame of a scenario.

    orbits : :class:`tqdyn.readers.sp3.SP3Orbits`; epoch : the scenario's
    :class:`tqdyn.astro.timescales.Epoch` (t = 0); points : samples of the interpolation (even,
    >= 4); eop, use_eop : as :func:`tqdyn.astro.earth_orientation.itrs_to_gcrs`.

    Attributes: path, name (the file's path and name), ids (K,) satellite ids, t (n,) sample times [s TT since
    the epoch], positions (n, K, 3) GCRS [m] (NaN: absent), span (first, last) allowed times [s].
    """

    def __init__(self, orbits: SP3Orbits, epoch, *, points: int = POINTS, eop=None, use_eop: bool = True):
        if points < 4 or points % 2:
            raise ValueError(f"SP3 interpolation points: {points!r}; allowed: an even number >= 4")
        self.path = orbits.path
        self.name = os.path.basename(orbits.path)
        self.ids = tuple(orbits.satellites)
        self.points = int(points)
        jd1, jd2 = epoch.tt
        days = (orbits.mjd.astype(np.float64) + _MJD0 - jd1) - jd2
        self.t = days * _DAY_S + orbits.sod + TT_MINUS[orbits.time_system]          # (n,)
        n = self.t.size
        if n < points:
            raise ValueError(f"{self.name}: {n} epochs; allowed: at least {points} for the {points}-point "
                             "interpolation")
        self.step = float(self.t[1] - self.t[0])
        bad = np.flatnonzero(np.abs(np.diff(self.t) - self.step) > 1e-6)
        if not self.step > 0 or bad.size:
            k = int(bad[0]) + 1 if bad.size else 1
            raise ValueError(f"{self.name}: epoch {k + 1} is {self.t[k] - self.t[k - 1]:g} s after the previous "
                             f"one, the first two {self.step:g} s apart; allowed: equally spaced epochs")
        rot = itrs_to_gcrs(epoch, self.t, eop=eop, use_eop=use_eop)                  # (n, 3, 3)
        self.positions = np.einsum("nij,nkj->nki", rot, orbits.positions)            # (n, K, 3)
        half = points // 2
        self.span = (float(self.t[half - 1]), float(self.t[n - half]))

    def __repr__(self) -> str:
        return f"SP3Constellation({self.name!r}, {len(self.ids)} satellites)"

    def states(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Positions [m] and velocities [m/s] (N, K, 3), GCRS, at t (N,) [s TT since the epoch]
        (NaN where a sample of the window is absent, or t is NaN); ValueError (one line) outside
        ``span``."""
        t = np.atleast_1d(np.asarray(t, np.float64))
        lo, hi = self.span
        out = (t < lo) | (t > hi)           # NaN (an absent transmitter's emission time): NaN states
        if out.any():
            x = float(t[np.flatnonzero(out)[0]])
            raise ValueError(f"{self.name}: t = {x:.6g} s is outside the span of its orbits, {lo:.6g} to {hi:.6g} s "
                             f"TT since the epoch (its first and last epochs less {self.points // 2 - 1} samples "
                             f"of the {self.points}-point interpolation); allowed: an SP3 file covering the arc "
                             "with that margin")
        half = self.points // 2
        n = self.t.size
        nan = ~np.isfinite(t)
        u = np.where(nan, self.points // 2, (t - self.t[0]) / self.step)
        start = np.clip(np.floor(u).astype(np.int64) - (half - 1), 0, n - self.points)  # (N,)
        w, dw = lagrange.weights(u - start, np.arange(self.points), derivative=True)
        idx = start[:, None] + np.arange(self.points)[None, :]                        # (N, p)
        g = self.positions[idx]                                                       # (N, p, K, 3)
        r, v = np.einsum("np,npki->nki", w, g), np.einsum("np,npki->nki", dw, g) / self.step
        r[nan], v[nan] = np.nan, np.nan
        return r, v


def sp3_constellations(paths, epoch, **options) -> tuple:
    """The :class:`SP3Constellation` s of the SP3 files ``paths`` on the scenario epoch: files that
    share a satellite are joined in time (:func:`tqdyn.readers.sp3.merge_sp3`: consecutive daily
    files), the others give one constellation each; options as the class takes them."""
    groups: list[list] = []                       # [(index of the first file, orbits), ...] per group
    for i, orbits in enumerate(read_sp3(p) for p in paths):
        hit = [g for g in groups if any(set(o.satellites) & set(orbits.satellites) for _, o in g)]
        groups = [g for g in groups if g not in hit] + [[(i, orbits)] + [x for g in hit for x in g]]
    groups.sort(key=lambda g: min(i for i, _ in g))               # in the order the files were given
    return tuple(SP3Constellation(g[0][1] if len(g) == 1 else merge_sp3([o for _, o in g]), epoch, **options)
                 for g in groups)


def sp3_constellation(path, epoch, **options) -> SP3Constellation:
    """:class:`SP3Constellation` of the SP3 file ``path`` (:func:`tqdyn.readers.sp3.read_sp3`) on
    the scenario epoch ``epoch``; options as the class takes them."""
    return SP3Constellation(read_sp3(path), epoch, **options)
