"""Joint estimation of the six links' 24 TTL coefficients, from the links and in TDI
(tqdyn.closedloop.ttl_estimation_tdi).

References: (a) PyTDI 2.2's second-generation Michelson X2, Y2, Z2 (``pytdi.michelson.X2_ETA``
etc., an independent implementation of the nested delays) for the TDI operator; (b) the injected
coefficients (noise-free data return them); (c) the estimators' own predicted covariances against
their scatter over seeds (chi-square statistic of (b_hat - b)^T Cov^-1 (b_hat - b) summed over seeds,
bounds from scipy's chi-square quantiles); (d) the errors-in-variables attenuation
S_jitter / (S_jitter + S_DWS) from the stated white levels (Hartig et al., CQG 42 (2025),
arXiv:2410.16475); (e) the laser-noise signature y_ij = D_ij p_j - p_i, which TDI cancels, for the
TDI degeneracy; (f) the subtraction floor (DWS noise times the coefficients) integrated by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from tqdyn.closedloop import ttl
from tqdyn.closedloop import ttl_estimation_tdi as tt
from tqdyn.closedloop.noise import AsdModel

DT = 0.5  # s
N = 2 ** 14  # samples (8192 s)
BAND = (1e-3, 0.1)  # Hz
TAU = {m: 0.5775 + 0.0004 * k for k, m in enumerate(ttl.MOSAS)}
"""Light times (s): TianQin's arms, sqrt(3) x 1e5 km / c = 0.5777 s, made unequal by up to 2 ms."""
COEFFS = ttl.TTLCoefficients.random(seed=3)
"""LISA Instrument 2.3's coefficient ranges (2.2 mm/rad local, 2.4 mm/rad distant)."""
MAN = tt.default_manoeuvres(1e-7)
"""Calibration manoeuvres: 100 nrad sinusoids on the twelve MOSA angles at 20, 25, ..., 75 mHz."""


def _chi2(fits, b):
    """Sum over the fits of (b_hat - b)^T Cov^-1 (b_hat - b), and its degrees of freedom."""
    tot = sum(float((f.coefficients - b) @ np.linalg.solve(f.covariance, f.coefficients - b)) for f in fits)
    return tot, 24 * len(fits)


@pytest.mark.parametrize("varying", [False, True])
def test_michelson_matches_pytdi(varying):
    """X2, Y2, Z2 of six random slow link series (1-50 mHz sinusoids) against PyTDI 2.2's
    X2_ETA, Y2_ETA, Z2_ETA built from the same delays (phase units): constant unequal light times,
    and light times drifting by 1e-6 s/s (a thousand times TianQin's arm-length rates, so that the
    nesting D_ij D_jk x(t) = x(t - tau_ij(t) - tau_jk(t - tau_ij(t))) matters: ignoring the drift
    changes X2 by 1.4e-2 of it, bound > 1e-3).  Measured: largest difference 1.9e-9 of the signal (PyTDI's order-31
    interpolation against the order-7 one, and its iterated advancements); bound 1e-7."""
    from pytdi.michelson import X2_ETA, Y2_ETA, Z2_ETA

    rng = np.random.default_rng(0)
    t = np.arange(N) * DT
    links = {m: sum(rng.standard_normal() * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
                    for f in (0.001, 0.003, 0.011, 0.05)) for m in ttl.MOSAS}
    delays = {m: TAU[m] + (1e-6 * (t - t[-1] / 2) if varying else 0.0) for m in ttl.MOSAS}
    keep = slice(400, N - 400)
    for ch, comb in zip(tt.CHANNELS, (X2_ETA, Y2_ETA, Z2_ETA)):
        ref = comb.build({f"d_{m}": delays[m] for m in ttl.MOSAS}, 1 / DT)(
            {f"eta_{m}": links[m] for m in ttl.MOSAS}, unit="phase")[keep]
        ours = tt.michelson(ch, links, DT, delays)[keep]
        scale = np.max(np.abs(ref))
        assert np.max(np.abs(ours - ref)) < 1e-7 * scale, (ch, np.max(np.abs(ours - ref)) / scale)
        if varying:
            const = tt.michelson(ch, links, DT, {m: float(np.mean(delays[m])) for m in ttl.MOSAS})[keep]
            assert np.max(np.abs(const - ref)) > 1e-3 * scale


def test_michelson_cancels_laser_noise_and_matches_transfer():
    """Laser noise p_i (white, 1 um/Hz^1/2) entering link ij as D_ij p_j - p_i: X2 keeps, in the
    1-100 mHz band, a fraction of the single link's ASD bounded by 16 delayed terms times 6 times the
    order-7 Lagrange remainder (2 pi f dt)^8 / 8! at 0.1 Hz, dt = 0.5 s (2.4e-9): 2.3e-7.  Measured
    2.0e-8 over the band, growing as f^8 (6e-8 at 0.1 Hz, 6e-12 at 30 mHz).  And the TDI of a periodic series
    equals, bin by bin, michelson_transfer's sum of exp(-2 pi i f tau_chain) within 300 Lagrange
    remainders times the sum of the links' moduli above 20 mHz (measured 51; below, round-off) and
    1e-6 of the largest bin (measured 1.2e-7)."""
    rng = np.random.default_rng(1)
    wrap = np.arange(-100, N + 8) % N  # periodic extension: the cut output is exactly periodic
    p = {s: (1e-6 * rng.standard_normal(N) / math.sqrt(2 * DT))[wrap] for s in "123"}
    links = {m: ttl._delay(p[m[1]], DT, TAU[m]) - p[m[0]] for m in ttl.MOSAS}
    bins = np.nonzero((np.fft.rfftfreq(N, DT) >= BAND[0]) & (np.fft.rfftfreq(N, DT) <= BAND[1]))[0]
    x2 = tt.michelson("X2", links, DT, TAU)[100:100 + N]
    one = np.abs(np.fft.rfft(links["12"][100:100 + N])[bins])
    bound = 16 * 6 * (2 * np.pi * BAND[1] * DT) ** 8 / math.factorial(8)
    assert np.sqrt(np.mean(np.abs(np.fft.rfft(x2)[bins]) ** 2)) < bound * np.sqrt(np.mean(one ** 2))
    y = {m: (rng.standard_normal(N))[wrap] for m in ttl.MOSAS}
    tr = tt.michelson_transfer(bins / (N * DT), TAU)
    for c, ch in enumerate(tt.CHANNELS):
        got = np.fft.rfft(tt.michelson(ch, y, DT, TAU)[100:100 + N])[bins]
        yk = [np.fft.rfft(y[m][100:100 + N])[bins] for m in ttl.MOSAS]
        want = sum(tr[:, c, i] * yk[i] for i in range(6))
        eps = (2 * np.pi * bins / N) ** 8 / math.factorial(8)  # (2 pi f dt)^8 / 8! per bin
        err = np.abs(got - want) / (eps * np.sum(np.abs(yk), axis=0))
        assert np.max(err[bins > N / 100]) < 300, np.max(err)  # above 20 mHz, before round-off
        assert np.max(np.abs(got - want)) < 1e-6 * np.max(np.abs(want))
