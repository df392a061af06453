"""Noise models of the closed loop: one-sided amplitude spectral densities with knees, and their shaping filters.

Convention (the one place): every ASD in tqdyn's closed loop is **one-sided**,
in (unit)/Hz^1/2, so that the variance of a stationary series is the integral
of ASD^2 over 0 < f < infinity; the Welch estimates of the time series use the
same convention (``scipy.signal.welch(..., return_onesided=True, scaling="density")``).

An :class:`AsdModel` is a level times a product of knees,

    ASD(f) = level * prod_k sqrt(1 + (f / f_k)^(2 s_k)),

where s_k is the log-log slope of the ASD beyond knee k: s < 0 a low-frequency
knee (the ASD rises as f^s below f_k: LISA's sqrt(1 + (0.4 mHz/f)^2) is
(0.4e-3, -1), TianQin's sqrt(1 + 0.1 mHz/f) is (1e-4, -0.5)), s > 0 a
high-frequency knee (LISA's sqrt(1 + (f/8 mHz)^4) is (8e-3, 2)).

Time-domain realisations filter unit white noise through a rational
minimum-phase *shaping filter* H(s) with |H(i 2 pi f)| ~ ASD(f) / level in a
band [f_lo, f_hi] (:meth:`AsdModel.shaping_zpk`): a knee of integer 2 s is
exact (a Butterworth polynomial; a low knee's pole at s = 0 moved to
2 pi f_lo / 10, a high knee's roll-off poles put at 2 pi * 30 f_hi), any other
slope is a pole-zero ladder (poles log-spaced, zeros fitted by least squares
on the log-magnitude).  Below f_lo the realised ASD levels off (a
realisation of length T resolves nothing below 1/T); :func:`shaping_error`
measures the largest relative deviation in the band, which the tests bound.

Units: frequencies in Hz; the s-plane (zeros, poles) in rad/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..scenario.closed_loop import check_asd
from ..scenario.values import ScenarioError

__all__ = ["AsdModel", "NoiseModelError", "shaping_error"]

#: Ladder spacing of the fitted knees (poles per decade) and the band margin (decades) beyond [f_lo, f_hi].
_LADDER_PER_DECADE = 5
_BAND_MARGIN_DECADES = 1.0
#: A high knee's roll-off poles sit at this multiple of f_hi (0.06 % amplitude error at f_hi per pole).
_ROLLOFF_FACTOR = 30.0


#: Invalid noise models raise the scenario's one-line error (field, value, what is allowed).
NoiseModelError = ScenarioError


@dataclass(frozen=True)
class AsdModel:
    """A one-sided ASD ``level * prod_k sqrt(1 + (f/f_k)^(2 s_k))`` (module docstring).

    level : float
        The flat level, (unit)/Hz^1/2, >= 0 (0 switches the source off).
    knees : tuple of (f_k [Hz] > 0, s_k), s_k != 0 real
        Knee frequencies and the ASD's log-log slope beyond each knee.
    unit : str
        The unit of the noise quantity (e.g. ``"N"``, ``"m"``, ``"rad"``, ``"1"``).
    name : str
        The field name used in error messages (e.g. ``closed_loop.noise.thruster_force``).
    """

    level: float
    knees: tuple = ()
    unit: str = ""
    name: str = "noise"

    def __post_init__(self):
        level, knees = check_asd(self.name, self.level, self.knees)
        object.__setattr__(self, "level", level)
        object.__setattr__(self, "knees", knees)

    def asd(self, f) -> np.ndarray:
        """ASD at frequencies ``f`` [Hz] (> 0), shape of ``f``, (unit)/Hz^1/2."""
        f = np.asarray(f, dtype=np.float64)
        out = np.full(f.shape, self.level)
        for fk, s in self.knees:
            out = out * np.sqrt(1.0 + (f / fk) ** (2.0 * s))
        return out

    def shaping_zpk(self, f_lo: float, f_hi: float) -> tuple[np.ndarray, np.ndarray, float]:
        """(zeros, poles, gain) of a minimum-phase H(s) [rad/s] with |H(i 2 pi f)| ~ asd(f)/level
        for f_lo <= f <= f_hi [Hz] (the module docstring says how; :func:`shaping_error` measures it)."""
        zs, ps, k = [], [], 1.0
        for fk, s in self.knees:
            z, p, g = _knee_zpk(fk, s, f_lo, f_hi)
            zs += list(z)
            ps += list(p)
            k *= g
        return np.array(zs, dtype=complex), np.array(ps, dtype=complex), k


def _butterworth_roots(n: int) -> np.ndarray:
    """Roots of the normalised Butterworth polynomial B_n(s) (|B_n(i w)|^2 = 1 + w^(2n)), left half plane."""
    k = np.arange(1, n + 1)
    return np.exp(1j * math.pi * (2 * k + n - 1) / (2 * n))


def _knee_zpk(fk: float, s: float, f_lo: float, f_hi: float):
    wk = 2 * math.pi * fk
    n2 = 2 * s
    if abs(n2 - round(n2)) < 1e-12 and round(n2) % 2 == 0:
        n = int(round(abs(s)))
        r = _butterworth_roots(n) * wk                  # |prod(i w - r)| = wk^n sqrt(1 + (w/wk)^2n)
        if s > 0:                                       # B_n(s/wk) / (1 + s/w_h)^n
            wh = 2 * math.pi * _ROLLOFF_FACTOR * f_hi
            return r, np.full(n, -wh), (wh / wk) ** n
        wl = 2 * math.pi * f_lo / _ROLLOFF_FACTOR         # B_n-reversed / (s + w_l)^n: sqrt(1 + (wk/w)^2n)
        return r, np.full(n, -wl), 1.0
    return _ladder(fk, s, f_lo, f_hi)


@lru_cache(maxsize=256)
def _ladder(fk: float, s: float, f_lo: float, f_hi: float):
    """Pole-zero ladder for a knee of any slope: poles log-spaced over the band (with margins), each zero
    a fixed ratio r^(-s) from its pole (r the pole spacing: the mean slope is s), then the zeros and the
    gain refined by least squares (scipy) on the log-magnitude of sqrt(1 + (f/fk)^(2s)) over [f_lo, f_hi]."""
    from scipy.optimize import least_squares

    lo = math.log10(f_lo) - _BAND_MARGIN_DECADES
    hi = math.log10(f_hi) + _BAND_MARGIN_DECADES
    if s < 0:   # the slope lives below fk
        hi = min(hi, math.log10(fk) + 1.0)
    else:
        lo = max(lo, math.log10(fk) - 1.0)
    n = max(1, int(math.ceil((hi - lo) * _LADDER_PER_DECADE)))
    lp = np.linspace(lo, hi, n)
    f = np.logspace(math.log10(f_lo), math.log10(f_hi), 200)
    target = 0.5 * np.log(1.0 + (f / fk) ** (2 * s))
    w = 2 * math.pi * f
    den = np.sum(np.log(np.abs(1j * w[:, None] + 2 * math.pi * 10.0 ** lp[None, :])), axis=1)

    def resid(x):
        num = np.sum(np.log(np.abs(1j * w[:, None] + 2 * math.pi * 10.0 ** x[None, :-1])), axis=1)
        return x[-1] + num - den - target

    x0 = np.concatenate([lp - s / _LADDER_PER_DECADE, [0.0]])
    x0[-1] = -np.mean(resid(x0))
    bounds = (np.concatenate([np.full(n, lo - 3), [-np.inf]]), np.concatenate([np.full(n, hi + 3), [np.inf]]))
    sol = least_squares(resid, x0, bounds=bounds, xtol=1e-12, ftol=1e-12, max_nfev=200)
    return -2 * math.pi * 10.0 ** sol.x[:-1], -2 * math.pi * 10.0 ** lp, math.exp(sol.x[-1])


def shaping_error(model: AsdModel, f_lo: float, f_hi: float, n: int = 2000) -> float:
    """Largest relative deviation | |H(i 2 pi f)| level / asd(f) - 1 | over [f_lo, f_hi] of
    :meth:`AsdModel.shaping_zpk` (dimensionless)."""
    if model.level == 0 or not model.knees:
        return 0.0
    z, p, k = model.shaping_zpk(f_lo, f_hi)
    f = np.logspace(math.log10(f_lo), math.log10(f_hi), n)
    s = 2j * math.pi * f
    h = k * np.prod(s[:, None] - z[None, :], axis=1) / np.prod(s[:, None] - p[None, :], axis=1)
    return float(np.max(np.abs(np.abs(h) * model.level / model.asd(f) - 1.0)))
