"""Amplitude spectral densities of pm-level range series (and of their time derivatives).

The problem.  A TianQin light-path range is ~1.7e8 m, varies by ~1e4 m at
orbital frequencies (~1e-5 Hz) and is wanted at the ~1e-12 m/Hz^1/2 level in
the band 0.1 mHz .. 1 Hz: a dynamic range of ~1e15-1e16.  Three things keep
numerical artefacts out of such a spectrum:

1. **Extended-precision residuals.**  A float64 range has an ulp of 3e-8 m
   (white rounding "noise" of ~1e-8 m RMS, i.e. ~1e-7 m/Hz^1/2 at 50 s).  The
   double-double series (``hi + lo``) is therefore detrended
   (:func:`dd_detrend`) or differenced (:func:`dd_difference`) in dd *before*
   it is rounded to float64.  Even then the float64 residual carries rounding
   of about ``|residual| * 2**-53 / sqrt(3)`` RMS, not white (harmonics of
   the lines it rounds), and the window product and the FFT add as much
   again: a detrended residual that still holds the 1e4 m orbital variation
   reads a floor of ~2e-11 m/Hz^1/2 at 50 s sampling (measured) -- far above
   the 0.3 pm/Hz^1/2 requirement.
2. **Differencing.**  The second difference of the range (formed in dd) holds
   the orbital variation at only ~0.4 m (1e4 m * (2 pi f dt)^2 at 2e-5 Hz,
   50 s), so its float64 rounding is ~1e-17 m and the window needs ~1e4 less
   suppression.  :func:`range_asd` (default ``method="difference"``) computes
   the ASD of the n-th dd difference and divides by the exact transfer
   function of the n-th difference, ``|2 sin(pi f dt)|**n`` (it has no zero
   in 0 < f <= Nyquist); this is the recommended way to get the range ASD.
3. **A window with negligible leakage.**  The Welch estimate sees every line
   through the window's spectral response.  Hann (-31 dB first sidelobe,
   then -18 dB/octave) and even Blackman-Harris (-92 dB) leak the orbital
   line far over 1e-12 m/Hz^1/2.  The default window is a Kaiser window with
   ``beta = 40`` (:data:`DEFAULT_KAISER_BETA`): every sidelobe below ~1e-16
   of the peak (amplitude; measured ~5e-17 up to 200 bins out, at the float64
   FFT round-off floor; analytic first sidelobe ~1e-16), main-lobe half-width ``sqrt(1 + (beta/pi)**2) ~ 12.8``
   bins, equivalent noise bandwidth ~3.6 bins.  Its samples come from
   :func:`kaiser_window`, accurate to ~1 ulp: scipy's own Kaiser samples
   (``I0(beta sqrt(1 - x^2)) / I0(beta)``) carry errors of ~beta * 1e-16
   = 4e-15, which raise the far-sidelobe floor to ~5e-17 and, on a 1e4 m
   residual, the noise floor ~10-fold.  ``asd`` uses :func:`kaiser_window`
   whenever ``window`` is ``("kaiser", beta)``.

Measured on a 1e4 m sinusoid at 2e-5 Hz + 1e-12 m RMS white noise + 1.7e8 m,
90 days at 50 s (``tests/test_spectra.py``): the default method recovers the
1e-11 m/Hz^1/2 noise level in 1-10 mHz to < 1 %; ``method="detrend"`` reads
~2x too high (its float64 floor, ~2e-11 m/Hz^1/2 for a 1e4 m residual: it
is for residuals << 1e4 m); a Hann window reads ~800x too high, float64
conversion before detrending ~4000x.

Derivatives.  The ASD of the k-th time derivative (k = 1 range rate [m/s],
k = 2 range acceleration [m/s^2]) is offered two ways (``transfer``):

* ``"exact"``: ``(2 pi f)**k`` times the range ASD -- the spectrum of the
  derivative of the band-limited continuous signal.  Use it to compare with
  requirements stated for derivatives (e.g. acceleration noise).
* ``"finite"``: ``(|2 sin(pi f dt)| / dt)**k`` times the range ASD -- exactly
  the spectrum of the finite-difference series ``Delta^k x / dt**k`` (what
  differencing the samples gives; lower than "exact" by the factor
  ``sinc(f dt)**k``: 0.6 % at f = 0.1 Nyquist, 36 % (k = 1) at Nyquist).
  Use it to reproduce a spectrum of differenced data.

The two agree for f << 1/(pi dt).  :func:`derivative_asd` applies either
factor to a given range ASD.

Estimator.  :func:`asd` wraps :func:`scipy.signal.welch` (one-sided density;
the f = 0 bin is dropped).  Default segmentation: 16 segments with 75 %
overlap (the narrow high-beta Kaiser window would waste most of the data at
the usual 50 %; at equal resolution 75 % doubles the equivalent degrees of
freedom, :func:`welch_dof`).  Each Welch bin is ~chi^2 with ``welch_dof``
degrees of freedom; bins closer than ~one main lobe are correlated.  The
lowest ``~2 * sqrt(1 + (beta/pi)**2)`` bins lie within the window's main lobe
of DC and are biased (for a differenced series corrected by
``|2 sin(pi f dt)|**-n`` the bias is upward): trust ``f > ~26 df`` with
``df = fs / nperseg`` (90 days at 50 s: df = 6e-7 Hz, so f > 2e-5 Hz).

Units: time in TT seconds since the scenario epoch (any uniform sampling),
frequency in Hz, ranges in m, ASDs in (unit of the series)/Hz^1/2.  Arrays are
1-D with the time axis first (shape (N,)); the frequency arrays are (M,).
No frame is involved (ranges are scalars).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as _legendre
from scipy import signal as _signal
from scipy import special as _special

from ..numerics.dd import np_dd_add, np_fast_two_sum, np_two_prod, np_two_sum

__all__ = [
    "DEFAULT_KAISER_BETA",
    "DEFAULT_WINDOW",
    "PolynomialTrend",
    "asd",
    "band_limited_max_ratio",
    "dd_detrend",
    "dd_difference",
    "default_segments",
    "derivative_asd",
    "difference_transfer",
    "enbw",
    "kaiser_window",
    "range_asd",
    "requirement_asd",
    "requirement_band",
    "welch_dof",
]

#: Kaiser beta of the default window: sidelobes <~1e-16 of the main lobe (amplitude).
DEFAULT_KAISER_BETA = 40.0
#: Default window, in :func:`scipy.signal.get_window` form.
DEFAULT_WINDOW = ("kaiser", DEFAULT_KAISER_BETA)

_DEFAULT_SEGMENTS = 16  # Welch segments at the default 75 % overlap


# --------------------------------------------------------------------------
# requirement


def requirement_asd(f, level: float = 0.3e-12, f_knee: float = 7e-3) -> np.ndarray:
    """TianQin range-noise requirement S^1/2(f) = level * sqrt(1 + (f_knee / f)**4).

    f : float or array (any shape), Hz, > 0.  level : m/Hz^1/2 (default
    0.3 pm/Hz^1/2).  f_knee : Hz (default 7 mHz).  Returns an array of the
    shape of ``f`` in m/Hz^1/2.
    """
    f = np.asarray(f, dtype=np.float64)
    if not (np.all(np.isfinite(f)) and np.all(f > 0)):
        raise ValueError(f"f: frequencies must be finite and > 0 Hz, got min {np.min(f) if f.size else 'empty'}")
    if not (level > 0 and math.isfinite(level)):
        raise ValueError(f"level: must be a finite positive ASD in m/Hz^1/2, got {level!r}")
    if not (f_knee >= 0 and math.isfinite(f_knee)):
        raise ValueError(f"f_knee: must be a finite frequency >= 0 Hz, got {f_knee!r}")
    return level * np.sqrt(1.0 + (f_knee / f) ** 4)


def requirement_band(step_s: float) -> tuple[float, float]:
    """Measurement band (f_min, f_max) in Hz for samples ``step_s`` seconds apart:
    (0.1 mHz, min(1 Hz, Nyquist = 1 / (2 step_s)))."""
    step_s = _positive(step_s, "step_s", "a sample spacing in s")
    f_hi = min(1.0, 0.5 / step_s)
    if f_hi <= 1e-4:
        raise ValueError(f"step_s: {step_s} s gives a Nyquist frequency {0.5 / step_s:g} Hz <= 0.1 mHz; "
                         "the band needs step_s < 5000 s")
    return 1e-4, f_hi


def band_limited_max_ratio(f, asd_values, step_s: float, *, level: float = 0.3e-12, f_knee: float = 7e-3,
                           band: tuple[float, float] | None = None) -> tuple[float, float]:
    """Largest ratio ASD / requirement over the band, and where it occurs.

    f : (M,) Hz; asd_values : (M,) m/Hz^1/2 (a range ASD); step_s : sample
    spacing [s] that sets the default band :func:`requirement_band`; ``band``
    (f_min, f_max) [Hz] overrides it.  Returns (ratio, f_at_max [Hz]); ratio
    < 1 means "under the requirement in band".  See the module docstring for
    the lowest reliable frequency of a Welch estimate.
    """
    f = np.asarray(f, dtype=np.float64)
    a = np.asarray(asd_values, dtype=np.float64)
    if f.ndim != 1 or a.shape != f.shape:
        raise ValueError(f"asd_values: shape {a.shape} must equal the shape of f {f.shape} (1-D)")
    lo, hi = requirement_band(step_s) if band is None else band
    sel = (f >= lo) & (f <= hi)
    if not np.any(sel):
        raise ValueError(f"band: no frequency of f (range {f.min():g}..{f.max():g} Hz) lies in {lo:g}..{hi:g} Hz")
    ratio = a[sel] / requirement_asd(f[sel], level, f_knee)
    i = int(np.argmax(ratio))
    return float(ratio[i]), float(f[sel][i])


# --------------------------------------------------------------------------
# double-double residuals


@dataclass(frozen=True, eq=False)
class PolynomialTrend:
    """The trend removed by :func:`dd_detrend`.

    trend(t) = offset + sum_i coefficients[i] * u**i, u = (t - t0) / t_scale,
    evaluated in double-double.  t0 [s since the epoch] and t_scale [s, a
    power of two, so that u is formed exactly] map the samples into
    [-1, 1]; offset [unit of the series] and coefficients (degree + 1,)
    [unit of the series] are float64 (least-squares fit; their own rounding
    only changes which smooth polynomial is removed, not the exactness of
    the subtraction).
    """

    t0: float
    t_scale: float
    offset: float
    coefficients: np.ndarray

    def evaluate_dd(self, t_hi, t_lo=None) -> tuple[np.ndarray, np.ndarray]:
        """trend(t) as a dd pair (hi, lo) of (N,) arrays; t [s since the epoch] (float64 or a dd pair)."""
        th, tl = _pair(t_hi, t_lo, "t")
        uh, ul = self._u(th, tl)
        ph, pl = _dd_polyval(self.coefficients, uh, ul)
        return _dd_add_f(ph, pl, self.offset)

    def _u(self, th, tl):
        dh, dl = np_dd_add(th, tl, np.full_like(th, -self.t0), np.zeros_like(th))
        return dh / self.t_scale, dl / self.t_scale  # exact: t_scale is a power of two


def dd_detrend(t, hi, lo=None, degree: int = 1, *, return_trend: bool = False):
    """Residual of a dd series about a least-squares polynomial in time, subtracted in dd.

    t : (N,) TT seconds since epoch, float64 or a (t_hi, t_lo) pair.
    hi, lo : (N,) float64, the series value hi + lo (e.g. a range [m]); ``hi``
    may also be a (hi, lo) pair with ``lo`` None; ``lo`` None means zero.
    degree : polynomial degree, 0 <= degree <= 20 and < N.

    The polynomial (float64 coefficients, Legendre least-squares fit on
    u in [-1, 1], converted to powers of u) is evaluated in dd (error-free
    products and sums), subtracted from hi + lo in dd, and only then rounded:
    the returned float64 residual (N,) [unit of the series] equals the exact
    ``hi + lo - trend(t)`` to within half an ulp of the residual plus ~1e-31
    of the series.  With ``return_trend`` returns (residual,
    :class:`PolynomialTrend`).
    """
    th, tl = _pair(t, None, "t")
    yh, yl = _pair(hi, lo, "hi")
    n = yh.size
    if th.shape != yh.shape:
        raise ValueError(f"t: shape {th.shape} must equal the shape of the series {yh.shape}")
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or not 0 <= degree <= min(20, n - 1):
        raise ValueError(f"degree: must be an integer in 0..{min(20, n - 1)} for {n} samples, got {degree!r}")
    t0 = 0.5 * (float(th[0]) + float(th[-1]))
    span = max(abs(float(th[0]) - t0), abs(float(th[-1]) - t0))
    t_scale = 2.0 ** math.ceil(math.log2(span)) if span > 0 else 1.0
    offset = float(yh[n // 2])
    zh, zl = np_dd_add(yh, yl, np.full_like(yh, -offset), np.zeros_like(yh))  # series - offset, in dd
    trend0 = PolynomialTrend(t0, t_scale, offset, np.zeros(1))
    uh, ul = trend0._u(th, tl)
    leg = _legendre.legfit(uh, zh + zl, int(degree))
    coeffs = np.asarray(_legendre.leg2poly(leg), dtype=np.float64)
    trend = PolynomialTrend(t0, t_scale, offset, coeffs)
    ph, pl = _dd_polyval(coeffs, uh, ul)
    rh, rl = np_dd_add(zh, zl, -ph, -pl)
    res = rh + rl
    return (res, trend) if return_trend else res


def dd_difference(hi, lo=None, order: int = 1) -> np.ndarray:
    """n-th forward differences of a dd series, formed in dd, rounded once.

    hi, lo : (N,) float64, value hi + lo (``hi`` may be a (hi, lo) pair with
    ``lo`` None; ``lo`` None means zero).  order : 1 <= order < N.  Returns
    (N - order,) float64 [unit of the series]: Delta^n x_i = sum_j (-1)^(n-j)
    C(n, j) x_(i+j), exact to within half an ulp of the result plus ~1e-31 of
    the series (not divided by any step).
    """
    h, lo_ = _pair(hi, lo, "hi")
    n = h.size
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order < n:
        raise ValueError(f"order: must be an integer in 1..{n - 1} for {n} samples, got {order!r}")
    for _ in range(int(order)):
        h, lo_ = np_dd_add(h[1:], lo_[1:], -h[:-1], -lo_[:-1])
    return h + lo_


# --------------------------------------------------------------------------
# spectral estimation


def default_segments(n: int) -> tuple[int, int]:
    """Default (nperseg, noverlap) for n samples: 16 segments with 75 % overlap.

    nperseg is the largest multiple of 4 of the form 2^a 3^b 5^c (a fast FFT
    length) not above 4 n / 19; noverlap = 3 nperseg / 4.  n >= 76.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 76:
        raise ValueError(f"n: need at least 76 samples for the default segmentation, got {n!r}")
    target = (4 * int(n)) // (3 + _DEFAULT_SEGMENTS)
    best = 4
    p2 = 4
    while p2 <= target:
        p3 = p2
        while p3 <= target:
            p5 = p3
            while p5 <= target:
                best = max(best, p5)
                p5 *= 5
            p3 *= 3
        p2 *= 2
    return best, 3 * best // 4


def asd(x, fs: float, *, nperseg: int | None = None, noverlap: int | None = None, window=DEFAULT_WINDOW,
        detrend="linear", average: str = "mean") -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectral density of a float64 series (Welch).

    x : (N,) float64 samples (unit U), uniformly spaced; fs : sampling
    frequency [Hz].  nperseg / noverlap: segment length and overlap in
    samples (default :func:`default_segments`; noverlap defaults to
    3 nperseg / 4).  window : anything :func:`scipy.signal.get_window`
    takes, or an (nperseg,) array of samples (default Kaiser, beta 40;
    ``("kaiser", beta)`` is computed by :func:`kaiser_window`).  detrend : "constant", "linear" or
    False (per segment).  average : "mean" or "median".
    Returns (f [Hz], asd [U/Hz^1/2]), both (M,), f > 0 only (f = k fs /
    nperseg, k = 1 .. nperseg // 2).  Feed it a residual (:func:`dd_detrend`,
    :func:`dd_difference`), never a raw float64 range.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError(f"x: must be a 1-D series, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"x: contains {int(np.sum(~np.isfinite(x)))} non-finite samples; only finite values allowed")
    fs = _positive(fs, "fs", "a sampling frequency in Hz")
    nperseg, noverlap = _segments(x.size, nperseg, noverlap)
    if detrend not in ("constant", "linear", False):
        raise ValueError(f"detrend: must be 'constant', 'linear' or False, got {detrend!r}")
    if average not in ("mean", "median"):
        raise ValueError(f"average: must be 'mean' or 'median', got {average!r}")
    w = _window_samples(window, nperseg)
    f, p = _signal.welch(x, fs=fs, window=w, nperseg=nperseg, noverlap=noverlap, detrend=detrend,
                         return_onesided=True, scaling="density", average=average)
    return f[1:], np.sqrt(p[1:])


def enbw(window=DEFAULT_WINDOW, nperseg: int = 4096, fs: float | None = None) -> float:
    """Equivalent noise bandwidth N sum(w^2) / (sum w)^2 of a window's samples.

    window : as in :func:`asd` (periodic samples, as Welch uses); nperseg :
    samples.  Returns bins, or Hz if ``fs`` [Hz] is given.
    A line of amplitude A on a bin reads ASD_peak = (A / sqrt 2) / sqrt(ENBW [Hz]).
    """
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or nperseg < 2:
        raise ValueError(f"nperseg: must be an integer >= 2, got {nperseg!r}")
    w = _window_samples(window, int(nperseg))
    bins = nperseg * float(np.sum(w * w)) / float(np.sum(w)) ** 2
    return bins if fs is None else bins * _positive(fs, "fs", "a sampling frequency in Hz") / nperseg


def kaiser_window(nperseg: int, beta: float = DEFAULT_KAISER_BETA) -> np.ndarray:
    """Periodic Kaiser window (nperseg,), dimensionless, peak 1, accurate to ~1 ulp.

    Same definition as ``scipy.signal.get_window(("kaiser", beta), nperseg)``
    (the symmetric window of nperseg + 1 points without its last point):
    w_n = I0(beta s) / I0(beta), s = sqrt(1 - x^2), x = (n - N/2) / (N/2),
    evaluated as exp(-beta x^2 / (1 + s)) * i0e(beta s) / i0e(beta), which
    avoids amplifying the rounding of beta s by I0'/I0 ~ 1 (scipy's samples
    err by ~beta * 1e-16).  beta >= 0.
    """
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or nperseg < 2:
        raise ValueError(f"nperseg: must be an integer >= 2, got {nperseg!r}")
    if not (beta >= 0 and math.isfinite(beta)):
        raise ValueError(f"beta: Kaiser beta must be finite and >= 0, got {beta!r}")
    half = nperseg / 2.0
    x = (np.arange(nperseg) - half) / half
    x2 = x * x
    s = np.sqrt(1.0 - x2)
    return np.exp(-beta * x2 / (1.0 + s)) * (_special.i0e(beta * s) / _special.i0e(beta))


def welch_dof(n: int, *, nperseg: int | None = None, noverlap: int | None = None, window=DEFAULT_WINDOW) -> float:
    """Equivalent degrees of freedom nu of a Welch PSD bin (mean average).

    Percival & Walden (1993), eq. 292b: nu = 2 K / (1 + 2 sum_{m=1}^{K-1}
    (1 - m/K) |sum_t h_t h_(t + m S)|^2), h the window normalised to
    sum h^2 = 1, S = nperseg - noverlap, K segments.  Each bin of a
    Gaussian-noise PSD estimate is ~ PSD chi^2_nu / nu (relative standard
    deviation sqrt(2 / nu); of the ASD ~ sqrt(1 / (2 nu))).  n : samples;
    segmentation as in :func:`asd`.
    """
    nperseg, noverlap = _segments(n, nperseg, noverlap)
    h = _window_samples(window, nperseg)
    h = h / math.sqrt(float(np.sum(h * h)))
    step = nperseg - noverlap
    k = (n - noverlap) // step
    s = 0.0
    for m in range(1, k):
        if m * step >= nperseg:
            break
        s += (1.0 - m / k) * float(np.dot(h[: nperseg - m * step], h[m * step:])) ** 2
    return 2.0 * k / (1.0 + 2.0 * s)


def difference_transfer(f, step_s: float, order: int = 1) -> np.ndarray:
    """|2 sin(pi f dt)|**order: gain of the n-th forward difference (dimensionless).

    f : Hz (any shape); step_s = dt [s].  ASD(Delta^n x) = this * ASD(x);
    divided by dt**n it tends to (2 pi f)**n for f << 1 / (pi dt).
    """
    step_s = _positive(step_s, "step_s", "a sample spacing in s")
    return np.abs(2.0 * np.sin(np.pi * np.asarray(f, dtype=np.float64) * step_s)) ** int(order)


def derivative_asd(f, asd_values, derivative: int, *, step_s: float | None = None,
                   transfer: str = "exact") -> np.ndarray:
    """ASD of the k-th time derivative from the ASD of the series itself.

    f : (M,) Hz; asd_values : (M,) U/Hz^1/2; derivative k >= 0.
    transfer "exact": times (2 pi f)**k (continuous derivative);
    "finite": times (|2 sin(pi f dt)| / dt)**k (the finite-difference series
    Delta^k x / dt^k; needs ``step_s`` = dt [s]).  Returns (M,) in
    U s^-k / Hz^1/2.  See the module docstring for which to use.
    """
    f = np.asarray(f, dtype=np.float64)
    a = np.asarray(asd_values, dtype=np.float64)
    if isinstance(derivative, bool) or not isinstance(derivative, (int, np.integer)) or derivative < 0:
        raise ValueError(f"derivative: must be an integer >= 0, got {derivative!r}")
    if transfer == "exact":
        return a * (2.0 * np.pi * f) ** int(derivative)
    if transfer == "finite":
        if step_s is None:
            raise ValueError("step_s: required (sample spacing in s) for transfer='finite', got None")
        return a * difference_transfer(f, step_s, derivative) / float(step_s) ** int(derivative)
    raise ValueError(f"transfer: must be 'exact' or 'finite', got {transfer!r}")


def range_asd(t, hi, lo=None, *, derivative: int = 0, method: str = "difference", order: int | None = None,
              degree: int = 1, transfer: str = "exact", nperseg: int | None = None, noverlap: int | None = None,
              window=DEFAULT_WINDOW, detrend="linear", average: str = "mean") -> tuple[np.ndarray, np.ndarray]:
    """ASD of a dd range series (k = 0), of its rate (k = 1) or acceleration (k = 2).

    t : (N,) TT seconds since epoch, float64 or a (t_hi, t_lo) pair,
    uniformly spaced (dt = step).  hi, lo : (N,) float64 range [m], value
    hi + lo (``hi`` may be a (hi, lo) pair).  derivative : k >= 0.

    method "difference" (default, recommended): the ASD of the ``order``-th
    dd difference (default max(2, k)) divided by |2 sin(pi f dt)|**order
    gives the range ASD; the orbital signal is reduced by (2 pi f dt)**order
    before any float64 rounding.  method "detrend": the ASD of the
    :func:`dd_detrend` residual (polynomial ``degree``); its float64
    floor grows with the residual (~2e-11 m/Hz^1/2 at 50 s for a 1e4 m
    orbital residual, see the module docstring): only for small residuals.
    The range ASD is then converted with :func:`derivative_asd` (``transfer``
    "exact" or "finite").  Remaining keywords go to :func:`asd`.
    Returns (f [Hz], asd [m s^-k / Hz^1/2]), (M,) each.
    """
    th, tl = _pair(t, None, "t")
    yh, yl = _pair(hi, lo, "hi")
    if th.shape != yh.shape:
        raise ValueError(f"t: shape {th.shape} must equal the shape of the series {yh.shape}")
    dt = _uniform_step(th, tl)
    fs = 1.0 / dt
    if isinstance(derivative, bool) or not isinstance(derivative, (int, np.integer)) or derivative < 0:
        raise ValueError(f"derivative: must be an integer >= 0, got {derivative!r}")
    kw = {"nperseg": nperseg, "noverlap": noverlap, "window": window, "detrend": detrend, "average": average}
    if method == "difference":
        n = max(2, int(derivative)) if order is None else order
        d = dd_difference(yh, yl, n)
        f, a = asd(d, fs, **kw)
        a = a / difference_transfer(f, dt, n)
    elif method == "detrend":
        f, a = asd(dd_detrend((th, tl), yh, yl, degree), fs, **kw)
    else:
        raise ValueError(f"method: must be 'difference' or 'detrend', got {method!r}")
    return f, derivative_asd(f, a, int(derivative), step_s=dt, transfer=transfer)


# --------------------------------------------------------------------------
# private helpers


def _positive(x, name, what):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be {what} (> 0), got {x!r}") from None
    if not (v > 0 and math.isfinite(v)):
        raise ValueError(f"{name}: must be {what} (> 0, finite), got {x!r}")
    return v


def _pair(hi, lo, name):
    """(hi, lo) float64 1-D arrays from hi (array or (hi, lo) pair) and lo (array or None)."""
    if lo is None and isinstance(hi, (tuple, list)) and len(hi) == 2:
        hi, lo = hi
    h = np.asarray(hi, dtype=np.float64)
    lo_ = np.zeros_like(h) if lo is None else np.asarray(lo, dtype=np.float64)
    if h.ndim != 1 or lo_.shape != h.shape:
        raise ValueError(f"{name}: hi and lo must be 1-D arrays of one shape, got {h.shape} and {lo_.shape}")
    if h.size < 2:
        raise ValueError(f"{name}: need at least 2 samples, got {h.size}")
    if not (np.all(np.isfinite(h)) and np.all(np.isfinite(lo_))):
        raise ValueError(f"{name}: contains non-finite values; only finite values allowed")
    return h, lo_


def _uniform_step(th, tl):
    """Sample spacing [s] of dd times; ValueError unless uniform to 1e-9 relative."""
    dh, dl = np_dd_add(th[1:], tl[1:], -th[:-1], -tl[:-1])
    d = dh + dl
    dt = float(np.median(d))
    if not dt > 0:
        raise ValueError(f"t: times must increase, got median step {dt!r} s")
    dev = float(np.max(np.abs(d - dt)))
    if dev > 1e-9 * dt:
        raise ValueError(f"t: samples must be uniformly spaced; step {dt:g} s varies by up to {dev:g} s "
                         "(resample first)")
    return dt


def _segments(n, nperseg, noverlap):
    if nperseg is None:
        nperseg, default_overlap = default_segments(n)
    else:
        if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or not 8 <= nperseg <= n:
            raise ValueError(f"nperseg: must be an integer in 8..{n} (the series length), got {nperseg!r}")
        nperseg = int(nperseg)
        default_overlap = 3 * nperseg // 4
    if noverlap is None:
        noverlap = default_overlap
    elif isinstance(noverlap, bool) or not isinstance(noverlap, (int, np.integer)) or not 0 <= noverlap < nperseg:
        raise ValueError(f"noverlap: must be an integer in 0..{nperseg - 1} (< nperseg), got {noverlap!r}")
    return nperseg, int(noverlap)


def _window_samples(window, nperseg):
    """Window samples (nperseg,): accurate Kaiser for ("kaiser", beta), else scipy's get_window."""
    if isinstance(window, tuple) and len(window) == 2 and window[0] == "kaiser":
        return kaiser_window(nperseg, float(window[1]))
    if isinstance(window, np.ndarray):
        if window.shape != (nperseg,):
            raise ValueError(f"window: array window must have shape ({nperseg},) (nperseg), got {window.shape}")
        return np.asarray(window, dtype=np.float64)
    try:
        return _signal.get_window(window, nperseg)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"window: {window!r} is not a scipy.signal.get_window spec or an array ({exc})") from None


def _dd_mul(ah, al, bh, bl):
    """Vectorised dd * dd (relative error ~ few 2**-106)."""
    p, e = np_two_prod(ah, bh)
    e = e + (ah * bl + al * bh)
    return np_fast_two_sum(p, e)


def _dd_add_f(ah, al, b):
    """Vectorised dd + float64."""
    s, e = np_two_sum(ah, b)
    return np_two_sum(s, e + al)  # not fast_two_sum: ah + b may cancel below al


def _dd_polyval(coeffs, uh, ul):
    """sum_i coeffs[i] u**i by Horner in dd; coeffs float64 ascending; u dd (|u| <= 1)."""
    ph = np.full_like(uh, coeffs[-1])
    pl = np.zeros_like(uh)
    for c in coeffs[-2::-1]:
        ph, pl = _dd_mul(ph, pl, uh, ul)
        ph, pl = _dd_add_f(ph, pl, float(c))
    return ph, pl
