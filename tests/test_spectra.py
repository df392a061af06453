"""Tests of tqdyn.analysis.spectra on synthetic signals of known spectrum.

References are independent of the module: analytic ASDs of white noise and
of a line (ENBW), hand-computed requirement values, mpmath sums and Bessel
functions (exact dd values, Kaiser window samples, window integrals), and the
Percival & Walden degrees-of-freedom value for Hann at 50 % overlap.
Sampling is TianQin's 50 s; "90 days" is 155,520 samples.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy import signal

from tqdyn.analysis import spectra as sp
from tqdyn.numerics.dd import mp_from_pair, np_dd_add, np_fast_two_sum, np_two_prod

DT = 50.0  # s
FS = 1.0 / DT  # Hz
N90 = 155_520  # 90 days at 50 s
EPS = 2.0**-52


# --------------------------------------------------------------------------
# helpers (test side)


def _dd_of(x):
    """mpmath value -> (hi, lo) float64 (nearest, then nearest of the remainder)."""
    h = float(x)
    return h, float(x - h)


def _dd_mul(a, b):
    """dd * dd on (..., 2) arrays, numpy (test copy, Veltkamp products)."""
    p, e = np_two_prod(a[..., 0], b[..., 0])
    e = e + a[..., 0] * b[..., 1] + a[..., 1] * b[..., 0]
    return np_fast_two_sum(p, e)


def _dd_sinusoid(n, amp, f0, phase, block=480):
    """amp * sin(2 pi f0 k DT + phase), k = 0..n-1, as a dd pair accurate to ~1e-29 m.

    sin(a + b) = sin a cos b + cos a sin b with a on a coarse grid (block
    steps) and b on a fine grid, both tabulated with mpmath at 40 digits,
    products and sum in dd.  (A float64 sinusoid of 1e4 m carries ~4e-13 m
    of rounding noise: not smooth enough at the 1e-12 m level.)
    """
    assert n % block == 0
    with mpmath.workdps(40):
        w = 2 * mpmath.pi * mpmath.mpf(f0) * mpmath.mpf(DT)
        ph = mpmath.mpf(phase)
        sa = np.array([_dd_of(amp * mpmath.sin(w * k * block + ph)) for k in range(n // block)])
        ca = np.array([_dd_of(amp * mpmath.cos(w * k * block + ph)) for k in range(n // block)])
        sb = np.array([_dd_of(mpmath.sin(w * k)) for k in range(block)])
        cb = np.array([_dd_of(mpmath.cos(w * k)) for k in range(block)])
    ia = np.repeat(np.arange(n // block), block)
    ib = np.tile(np.arange(block), n // block)
    p1 = _dd_mul(sa[ia], cb[ib])
    p2 = _dd_mul(ca[ia], sb[ib])
    return np_dd_add(p1[0], p1[1], p2[0], p2[1])


def _band_mean_asd(f, a, lo, hi):
    """sqrt of the band-averaged PSD (unbiased for the mean PSD)."""
    sel = (f >= lo) & (f <= hi)
    return math.sqrt(float(np.mean(a[sel] ** 2))), int(np.sum(sel))


# --------------------------------------------------------------------------
# 4. requirement curve


def test_requirement_values_by_hand():
    # S^1/2 = 0.3e-12 sqrt(1 + (7e-3/f)^4), evaluated by hand:
    # f = 7 mHz: 0.3e-12 * sqrt(2) = 4.242640687e-13
    # f = 1 Hz: (7e-3)^4 = 2.401e-9 -> 0.3e-12 * (1 + 1.2005e-9) = 3.00000000360e-13
    # f = 0.1 mHz: (70)^4 = 24,010,000 -> 0.3e-12 * sqrt(24,010,001) = 0.3e-12 * 4900.000102 = 1.4700000306e-9
    got = sp.requirement_asd(np.array([7e-3, 1.0, 1e-4]))
    assert got[0] == pytest.approx(4.242640687e-13, rel=1e-9)
    assert got[1] == pytest.approx(3.00000000360e-13, rel=1e-11)
    assert got[2] == pytest.approx(1.4700000306e-9, rel=1e-9)
    assert sp.requirement_band(50.0) == (1e-4, 0.01)  # Nyquist of 50 s sampling
    assert sp.requirement_band(0.1) == (1e-4, 1.0)  # capped at 1 Hz
    with pytest.raises(ValueError, match="f:"):
        sp.requirement_asd([0.0, 1e-3])
    with pytest.raises(ValueError, match="step_s"):
        sp.requirement_band(-1.0)


def test_band_limited_max_ratio():
    f = np.linspace(1e-5, 1e-2, 2000)
    a = 0.5 * sp.requirement_asd(f)
    a[(f > 2e-3) & (f < 2.01e-3)] *= 3.0  # one excursion to 1.5x the requirement
    a[f < 1e-4] *= 100.0  # out of band (below 0.1 mHz): ignored
    ratio, f_max = sp.band_limited_max_ratio(f, a, DT)
    assert ratio == pytest.approx(1.5, rel=1e-12)
    assert 2e-3 < f_max < 2.01e-3
    with pytest.raises(ValueError, match="band"):
        sp.band_limited_max_ratio(f, a, DT, band=(0.5, 0.6))


# --------------------------------------------------------------------------
# 1. white noise


def test_white_noise_level_and_dof():
    sigma = 1e-12  # m RMS
    x = sigma * np.random.default_rng(1234).standard_normal(N90)
    f, a = sp.asd(x, FS)
    expect = sigma * math.sqrt(2.0 / FS)  # one-sided white-noise ASD [m/Hz^1/2] = 1e-11
    lo, hi = sp.requirement_band(DT)
    got, m = _band_mean_asd(f, a, lo, hi)
    # Statistics: each PSD bin ~ chi^2_nu / nu (nu = welch_dof ~ 31.6 for 16 Kaiser
    # segments at 75 % overlap); bins closer than ~ENBW (3.6 bins) are correlated, so the
    # band holds ~m / ENBW independent values: relative sigma of the band-mean PSD =
    # sqrt(2 / (nu m / ENBW)) ~ 0.4 %, of the ASD half that.  Tolerance 5 sigma (~1 %).
    nu = sp.welch_dof(N90)
    enbw_bins = sp.enbw(sp.DEFAULT_WINDOW, sp.default_segments(N90)[0])
    rel_sigma = 0.5 * math.sqrt(2.0 / (nu * m / enbw_bins))
    assert abs(got / expect - 1.0) < 5 * rel_sigma < 0.02
    # bin-to-bin scatter of the PSD matches the equivalent degrees of freedom
    sel = (f >= lo) & (f <= hi)
    scatter = np.std(a[sel] ** 2) / np.mean(a[sel] ** 2)
    assert scatter == pytest.approx(math.sqrt(2.0 / nu), rel=0.1)


def test_welch_dof_references():
    # No overlap: K independent segments, nu = 2K exactly.
    assert sp.welch_dof(8000, nperseg=1000, noverlap=0) == pytest.approx(16.0, rel=1e-12)
    # Hann at 50 % overlap: correlation of neighbouring segments
    # sum_{t<N/2} sin^2 cos^2 / sum sin^4 = (N/16)/(3N/8) = 1/6 (Welch 1967; Percival &
    # Walden 1993, eq. 292b): nu = 2K / (1 + 2 (1 - 1/K) / 36).
    k = 15
    nu = sp.welch_dof(8 * 1024, nperseg=1024, noverlap=512, window="hann")
    assert nu == pytest.approx(2 * k / (1 + 2 * (1 - 1 / k) / 36), rel=1e-9)


# --------------------------------------------------------------------------
# 2. a line on a bin, ENBW


def test_sinusoid_on_bin_recovers_rms():
    nperseg = sp.default_segments(N90)[0]
    k0 = 1000
    f0 = k0 * FS / nperseg  # on a bin (6.2e-4 Hz)
    amp = 3.7  # m
    t = np.arange(N90) * DT
    x = amp * np.sin(2 * np.pi * f0 * t + 0.4)
    f, a = sp.asd(x, FS)
    i = int(np.argmin(np.abs(f - f0)))
    assert f[i] == pytest.approx(f0, rel=1e-12)
    # peak ASD * sqrt(ENBW [Hz]) = A / sqrt(2) (RMS); ENBW from the window samples
    rms = a[i] * math.sqrt(sp.enbw(sp.DEFAULT_WINDOW, nperseg, fs=FS))
    assert rms == pytest.approx(amp / math.sqrt(2.0), rel=1e-2)
    # the same with a Hann window
    f, a = sp.asd(x, FS, window="hann")
    rms = a[i] * math.sqrt(sp.enbw("hann", nperseg, fs=FS))
    assert rms == pytest.approx(amp / math.sqrt(2.0), rel=1e-2)


def test_enbw_references():
    # Hann: ENBW = 1.5 bins exactly (sum sin^4 / (sum sin^2)^2 * N = (3N/8) N / (N/2)^2).
    assert sp.enbw("hann", 4096) == pytest.approx(1.5, rel=1e-12)
    # Kaiser: continuum limit 2 int w^2 / (int w)^2 on [-1, 1], w = I0(beta sqrt(1-x^2)) / I0(beta);
    # int I0(beta sqrt(1-x^2)) dx = 2 sinh(beta) / beta (closed form), int w^2 by mpmath quadrature.
    beta = sp.DEFAULT_KAISER_BETA
    with mpmath.workdps(30):
        i0b = mpmath.besseli(0, beta)
        int_w = 2 * mpmath.sinh(beta) / beta / i0b
        int_w2 = mpmath.quad(lambda x: (mpmath.besseli(0, beta * mpmath.sqrt(1 - x * x)) / i0b) ** 2, [-1, 0, 1])
        ref = float(2 * int_w2 / int_w**2)
    assert sp.enbw(sp.DEFAULT_WINDOW, 4096) == pytest.approx(ref, rel=1e-9)
    assert sp.enbw(sp.DEFAULT_WINDOW, 4096, fs=FS) == pytest.approx(ref * FS / 4096, rel=1e-9)


# --------------------------------------------------------------------------
# window accuracy and leakage floor


def test_kaiser_window_samples_vs_mpmath():
    n, beta = 4096, sp.DEFAULT_KAISER_BETA
    w = sp.kaiser_window(n, beta)
    # same definition as scipy's periodic Kaiser (scipy errs by ~beta*1e-16 itself)
    assert np.max(np.abs(w - signal.get_window(("kaiser", beta), n))) < 1e-14
    # reference: I0(beta sqrt(1 - x^2)) / I0(beta), x = (k - N/2)/(N/2), in mpmath at 30 digits
    idx = np.arange(0, n, 41)
    with mpmath.workdps(30):
        i0b = mpmath.besseli(0, beta)
        ref = np.array([float(mpmath.besseli(0, beta * mpmath.sqrt(1 - ((mpmath.mpf(int(k)) - n // 2) / (n // 2)) ** 2))
                              / i0b) for k in idx])
    assert np.max(np.abs(w[idx] - ref)) <= 2 * EPS  # ~1 ulp of the peak-1 window


def test_window_leakage_floor():
    n, pad = 4096, 8
    half_width = math.sqrt(1 + (sp.DEFAULT_KAISER_BETA / math.pi) ** 2)  # Kaiser main-lobe half-width [bins]

    def response(w):
        r = np.abs(np.fft.rfft(w, pad * n))
        return r / r[0]

    far = slice(int((half_width + 1) * pad), None)
    kaiser = response(sp.kaiser_window(n))
    assert kaiser[far].max() < 1e-15  # all sidelobes far below 1e-15 (amplitude)
    # far sidelobes sit at the float64 FFT round-off floor (median ~4e-18); scipy's own Kaiser
    # samples (errors ~beta * 1e-16) raise that floor ~10-fold
    assert np.median(kaiser[1000 * pad:]) < 1e-17
    assert np.median(response(signal.get_window(("kaiser", sp.DEFAULT_KAISER_BETA), n))[1000 * pad:]) > 2e-17
    # Blackman-Harris (4 term): -92 dB peak sidelobe = 2.5e-5 (Harris 1978): not enough
    bh = response(signal.get_window("blackmanharris", n))
    assert bh[int(5 * pad):].max() > 1e-5
    hann = response(signal.get_window("hann", n))
    assert hann[1000 * pad:].max() > 1e-11  # ~1/(pi dk^3) at 1000 bins

    # through the estimator: a unit sinusoid off-bin; far from the line the ASD is < 1e-15 of the peak
    m = 8 * 4096
    # f0 DT = 100.375 / 4096 is a binary fraction: the phase k f0 DT mod 1 is exact, so the
    # float64 test signal has only ~1e-16 rounding (2 pi f0 t in float64 would carry 1e-13)
    cycles = np.mod(np.arange(m) * (100.375 / 4096), 1.0)
    x = np.sin(2 * np.pi * cycles)
    f0 = 100.375 * FS / 4096  # 3/8 of a bin off the grid
    f, a = sp.asd(x, FS, nperseg=4096)
    lobe = 3 * half_width * FS / 4096  # away from the line and from DC (per-segment detrend)
    far = (np.abs(f - f0) > lobe) & (f > lobe)
    assert a[far].max() < 1e-15 * a.max()
    f, a = sp.asd(x, FS, nperseg=4096, window="blackmanharris")
    assert a[far].max() > 1e-8 * a.max()  # measured ~1e-6: 9 orders above the Kaiser floor


# --------------------------------------------------------------------------
# 3. dynamic range: 1.7e8 m + 1e4 m orbital line + 1e-12 m white noise, in dd


@pytest.fixture(scope="module")
def dd_range():
    sigma = 1e-12  # m RMS white noise
    sh, sl = _dd_sinusoid(N90, 1e4, 2e-5, 0.3)  # 2e-5 Hz: 34.56 bins of df = FS/32400, NOT on a bin
    noise = sigma * np.random.default_rng(99).standard_normal(N90)
    c = np.full(N90, 1.7e8 + 0.123456789)
    hi, lo = np_dd_add(c, np.zeros(N90), sh, sl)
    hi, lo = np_dd_add(hi, lo, noise, np.zeros(N90))  # the noise lands in the lo part
    t = np.arange(N90) * DT
    return t, hi, lo, sigma


def test_dynamic_range_dd_method(dd_range):
    t, hi, lo, sigma = dd_range
    expect = sigma * math.sqrt(2.0 / FS)  # 1e-11 m/Hz^1/2
    band = (1e-3, 0.5 * FS)  # 1 mHz .. Nyquist (10 mHz at 50 s)
    f, a = sp.range_asd(t, hi, lo)  # default: 2nd dd difference, Kaiser 40
    got, _ = _band_mean_asd(f, a, *band)
    assert got == pytest.approx(expect, rel=0.1)  # measured: within 1 %
    # time as a dd pair gives the same
    _, a2 = sp.range_asd((t, np.zeros_like(t)), (hi, lo))
    np.testing.assert_allclose(a2, a, rtol=1e-12)

    # the method matters: a Hann window leaks the orbital line ...
    f, a = sp.range_asd(t, hi, lo, window="hann")
    assert _band_mean_asd(f, a, *band)[0] > 10 * expect
    # ... and so does float64 conversion before detrending (ulp of 1.7e8 m = 3e-8 m)
    x64 = hi + lo
    f, a = sp.asd(signal.detrend(x64), FS)
    assert _band_mean_asd(f, a, *band)[0] > 10 * expect


def test_dynamic_range_derivatives(dd_range):
    t, hi, lo, sigma = dd_range
    band = (1e-3, 0.5 * FS)
    white = sigma * math.sqrt(2.0 / FS)
    # range rate: exact derivative (2 pi f) * white; finite differences |2 sin(pi f dt)|/dt * white
    for k, transfer, ref in [
        (1, "exact", lambda f: white * 2 * np.pi * f),
        (1, "finite", lambda f: white * np.abs(2 * np.sin(np.pi * f * DT)) / DT),
        (2, "exact", lambda f: white * (2 * np.pi * f) ** 2),
        (2, "finite", lambda f: white * (2 * np.sin(np.pi * f * DT) / DT) ** 2),
    ]:
        f, a = sp.range_asd(t, hi, lo, derivative=k, transfer=transfer)
        sel = (f >= band[0]) & (f <= band[1])
        ratio = math.sqrt(float(np.mean((a[sel] / ref(f[sel])) ** 2)))
        assert ratio == pytest.approx(1.0, rel=0.1), (k, transfer)
    # "finite" with order = k is literally the ASD of the finite-difference series Delta x / dt
    f, a = sp.range_asd(t, hi, lo, derivative=1, order=1, transfer="finite")
    f1, a1 = sp.asd(sp.dd_difference(hi, lo, 1), FS)
    np.testing.assert_array_equal(f, f1)
    np.testing.assert_allclose(a, a1 / DT, rtol=1e-12)
    # derivative_asd on a given range ASD
    fr, ar = sp.range_asd(t, hi, lo)
    np.testing.assert_allclose(sp.derivative_asd(fr, ar, 2), sp.range_asd(t, hi, lo, derivative=2)[1], rtol=1e-12)


# --------------------------------------------------------------------------
# 5. dd residuals vs mpmath


def _random_dd_series(n, rng):
    hi = 1.7e8 + 1e4 * np.sin(np.arange(n) * 0.01) + rng.uniform(-1, 1, n)
    lo = rng.uniform(-0.5, 0.5, n) * np.spacing(hi)  # |lo| <= ulp(hi)/2
    return hi, lo


def test_dd_difference_vs_mpmath():
    rng = np.random.default_rng(7)
    hi, lo = _random_dd_series(64, rng)
    with mpmath.workdps(60):
        x = [mp_from_pair(h, el) for h, el in zip(hi, lo, strict=True)]
        for order in (1, 2, 3):
            d = sp.dd_difference(hi, lo, order)
            assert d.shape == (64 - order,)
            for i in (0, 17, 63 - order):
                exact = mpmath.fsum((-1) ** (order - j) * mpmath.binomial(order, j) * x[i + j]
                                    for j in range(order + 1))
                # one final rounding (<= ulp/2) plus dd rounding ~1e-32 * 1.7e8
                assert abs(mpmath.mpf(d[i]) - exact) <= 0.5 * np.spacing(abs(d[i])) + 1e-23
    with pytest.raises(ValueError, match="order"):
        sp.dd_difference(hi, lo, 0)


def test_dd_detrend_vs_mpmath():
    rng = np.random.default_rng(8)
    n = 200
    hi, lo = _random_dd_series(n, rng)
    t_hi = 1e6 + np.arange(n) * DT  # TDB s, far from the epoch, as a dd pair
    t_lo = rng.uniform(-0.5, 0.5, n) * np.spacing(t_hi)
    for degree in (0, 1, 3):
        res, trend = sp.dd_detrend((t_hi, t_lo), hi, lo, degree, return_trend=True)
        assert res.shape == (n,)
        assert trend.coefficients.shape == (degree + 1,)
        with mpmath.workdps(60):
            for i in (0, 57, n - 1):
                t = mp_from_pair(t_hi[i], t_lo[i])
                u = (t - mpmath.mpf(trend.t0)) / mpmath.mpf(trend.t_scale)
                p = mpmath.mpf(trend.offset) + mpmath.fsum(mpmath.mpf(c) * u**j
                                                           for j, c in enumerate(trend.coefficients))
                exact = mp_from_pair(hi[i], lo[i]) - p
                assert abs(mpmath.mpf(res[i]) - exact) <= 0.5 * np.spacing(abs(res[i])) + 1e-23
        # the least-squares residual is orthogonal to the fitted basis (float64 fit)
        assert abs(np.mean(res)) < 1e-6 * np.std(res) + 1e-9
    # a dd cubic is removed down to its float64-fit accuracy, not to the 3e-8 m ulp of the range
    u = np.arange(n) / n
    ch, cl = np_dd_add(np.full(n, 1.7e8), np.zeros(n), 1e4 * u**3 - 30.0 * u, np.zeros(n))
    assert np.max(np.abs(sp.dd_detrend(t_hi, ch, cl, 3))) < 1e-9


# --------------------------------------------------------------------------
# input checks


def test_bad_input_messages():
    t = np.arange(1000) * DT
    x = np.zeros(1000)
    t_bad = t.copy()
    t_bad[500] += 1.0
    with pytest.raises(ValueError, match="t: samples must be uniformly spaced"):
        sp.range_asd(t_bad, x)
    with pytest.raises(ValueError, match="method"):
        sp.range_asd(t, x, method="fft")
    with pytest.raises(ValueError, match="degree"):
        sp.dd_detrend(t, x, None, 30)
    with pytest.raises(ValueError, match="nperseg"):
        sp.asd(x, FS, nperseg=2000)
    with pytest.raises(ValueError, match="x: contains"):
        sp.asd(np.full(1000, np.nan), FS)
    with pytest.raises(ValueError, match="transfer"):
        sp.derivative_asd([1e-3], [1.0], 1, transfer="spline")
    with pytest.raises(ValueError, match="window"):
        sp.asd(x, FS, window="no-such-window")
