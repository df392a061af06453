"""Estimation of one link's TTL coefficients (tqdyn.ttl.estimation).

References: (a) the injected coefficients (noise-free data must return them to round-off);
(b) the estimators' own predicted covariances against their scatter over seeds (chi-square
statistics of the normalised errors); (c) the errors-in-variables attenuation
S_jitter / (S_jitter + S_DWS) computed by hand from the stated white ASD levels (Hartig et al., CQG 42
(2025), arXiv:2410.16475: least squares biased by angular readout noise, instrumental variables not);
(d) the subtraction floor sqrt(sum b_k^2) times the DWS ASD, its knee integrated analytically.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tqdyn.ttl import coupling as ttl
from tqdyn.ttl import estimation as te
from tqdyn.closedloop.noise import AsdModel

DT = 0.5  # s
BAND = (1e-3, 0.1)  # Hz
TAU = 8.33242295  # s, LISA Instrument 2.3's STATIC_PPRS_S["12"]
_C = ttl.TTLCoefficients.random(seed=3)
B = np.array([_C.local_phi["12"], _C.local_eta["12"], _C.distant_phi["21"], _C.distant_eta["21"]])
"""Link 12: its local coefficients and the emitting MOSA 21's distant ones (m/rad), LISA's ranges."""
MAN = {"local_phi": (1e-7, 0.020), "local_eta": (1e-7, 0.025), "distant_phi": (1e-7, 0.030), "distant_eta": (1e-7, 0.035)}
"""Calibration manoeuvres: 100 nrad sinusoids at 20-35 mHz, one frequency per angle."""


def test_noise_free_ols_returns_injected_coefficients():
    """No readout and no DWS noise: OLS returns b to round-off (measured 1.6e-15 relative; bound 1e-13)."""
    s = te.simulate_link_fit(B, dt=DT, n=100_000, seed=1, band=BAND, jitter_asd=1e-8, readout_asd=0.0,
                             dws_asd=0.0, tau=TAU)
    assert np.max(np.abs(s.ols.coefficients - B) / np.abs(B)) < 1e-13
    assert s.iv is None and s.residual_ttl_asd["ols"] < 1e-13 * s.ttl_asd


def test_scatter_matches_predicted_covariance():
    """Over 12 seeds x 4 coefficients the errors divided by the predicted sigma have an RMS near 1:
    OLS without DWS noise, IV with DWS noise and manoeuvres.  48 samples: the RMS follows
    sqrt(chi2_48 / 48), whose 1e-4 tails lie near 0.65 and 1.4 (the bounds).  Measured 0.90 (OLS),
    1.10 (IV)."""
    z_ols, z_iv = [], []
    for seed in range(12):
        s = te.simulate_link_fit(B, dt=DT, n=50_000, seed=seed, band=BAND, jitter_asd=1e-8, readout_asd=1e-12,
                                 dws_asd=0.0, tau=TAU)
        z_ols.append((s.ols.coefficients - B) / s.ols.sigma)
        s = te.simulate_link_fit(B, dt=DT, n=50_000, seed=100 + seed, band=BAND, jitter_asd=1e-9, readout_asd=1e-12,
                                 dws_asd=1e-9, tau=TAU, manoeuvres=MAN)
        z_iv.append((s.iv.coefficients - B) / s.iv.sigma)
    for z in (z_ols, z_iv):
        rms = math.sqrt(float(np.mean(np.square(z))))
        assert 0.65 < rms < 1.4, rms


def test_dws_noise_biases_ols_not_iv():
    """White jitter 1 nrad/Hz^1/2 and white DWS noise 1 nrad/Hz^1/2: OLS is attenuated by
    S_j / (S_j + S_N) = 0.5 per coefficient (the mean of 10 seeds within 4 standard errors of it;
    measured 0.43-0.50, the 0.43 of the smallest coefficient at 1.0
    standard error); IV with the manoeuvres is unbiased (mean normalised error of 10 seeds within
    4 / sqrt(10); measured <= 0.59) while OLS's bias is > 100 IV sigmas (measured >= 319)."""
    lam = 1e-9 ** 2 / (1e-9 ** 2 + 1e-9 ** 2)
    ratio, z_iv = [], []
    for seed in range(10):
        kw = dict(dt=DT, n=50_000, seed=seed, band=BAND, jitter_asd=1e-9, readout_asd=1e-12, dws_asd=1e-9, tau=TAU)
        s = te.simulate_link_fit(B, **kw)
        ratio.append(s.ols.coefficients / B)
        m = te.simulate_link_fit(B, manoeuvres=MAN, **kw)
        z_iv.append((m.iv.coefficients - B) / m.iv.sigma)
    np.testing.assert_allclose(s.predicted_attenuation, lam, rtol=1e-9)
    ratio = np.array(ratio)
    sem = ratio.std(axis=0, ddof=1) / math.sqrt(len(ratio))
    assert np.all(np.abs(ratio.mean(axis=0) - lam) < 4 * sem), (ratio.mean(axis=0), sem)
    assert np.all(np.abs(np.mean(z_iv, axis=0)) < 4 / math.sqrt(len(z_iv)))
    assert np.all(np.abs(ratio.mean(axis=0) - 1) * np.abs(B) > 100 * m.iv.sigma)


def test_tianqin_like_residual_after_subtraction(record_number):
    """TianQin-like link: readout noise 1 pm/Hz^1/2, angle jitter 10 nrad/Hz^1/2 (assumed), DWS noise
    2e-10 rad/Hz^1/2 * sqrt(1 + 1 mHz / f)^2, LISA-range coefficients (link 12 of random(seed=3)),
    band 1-100 mHz, 2e5 s.  The TTL left after subtracting the fitted TTL formed from the DWS angles
    sits on the floor sqrt(sum b^2) S_N^1/2 (the DWS noise times the coefficients), whose band
    average is integrated by hand here: int (1 + (f_k/f)^2) df = width + f_k^2 (1/f_lo - 1/f_hi).
    Measured: residual / floor = 0.9998 (OLS) and 0.9999 (IV with 50 nrad manoeuvres); bounds 0.95-1.1."""
    dws = AsdModel(2e-10, ((1e-3, -1),))
    width = BAND[1] - BAND[0]
    floor = math.sqrt(float(B @ B) * 2e-10 ** 2 * (width + 1e-3 ** 2 * (1 / BAND[0] - 1 / BAND[1])) / width)
    kw = dict(dt=DT, n=400_000, seed=5, band=BAND, jitter_asd=1e-8, readout_asd=1e-12, dws_asd=dws, tau=TAU)
    plain = te.simulate_link_fit(B, **kw)
    man = te.simulate_link_fit(B, manoeuvres={k: (5e-8, f) for k, (_, f) in MAN.items()}, **kw)
    assert plain.residual_floor_asd == pytest.approx(floor, rel=1e-6)
    assert 0.95 * floor < plain.residual_ttl_asd["ols"] < 1.1 * floor
    assert 0.95 * floor < man.residual_ttl_asd["iv"] < 1.1 * floor
    rel_iv = np.abs(man.iv.coefficients / B - 1)
    assert np.all(np.abs(man.iv.coefficients - B) < 5 * man.iv.sigma)
    record_number("ttl_estimation.tianqin_ttl_before_asd_m", plain.ttl_asd, "m/Hz^1/2")
    record_number("ttl_estimation.tianqin_residual_ols_asd_m", plain.residual_ttl_asd["ols"], "m/Hz^1/2")
    record_number("ttl_estimation.tianqin_residual_iv_asd_m", man.residual_ttl_asd["iv"], "m/Hz^1/2")
    record_number("ttl_estimation.tianqin_residual_over_0p3pm", man.residual_ttl_asd["iv"] / 0.3e-12, "")
    record_number("ttl_estimation.tianqin_ols_rel_error_max", float(np.max(np.abs(plain.ols.coefficients / B - 1))), "")
    record_number("ttl_estimation.tianqin_iv_rel_error_max", float(np.max(rel_iv)), "")
    record_number("ttl_estimation.tianqin_iv_rel_sigma_max", float(np.max(man.iv.sigma / np.abs(B))), "")


@pytest.mark.parametrize("call, match", [
    (lambda: te.ols_fit(np.zeros(100), np.zeros((100, 4)), 0.5, (0.2, 0.1)), "band"),
    (lambda: te.ols_fit(np.zeros(100), np.zeros((90, 4)), 0.5, (0.01, 0.1)), "regressors"),
    (lambda: te.iv_fit(np.zeros(100), np.zeros((100, 4)), np.zeros((100, 2)), 0.5, (0.01, 0.1)), "instruments"),
    (lambda: te.simulate_link_fit([1.0, 2.0], dt=DT, n=1000, seed=0, band=BAND, jitter_asd=1e-8, readout_asd=0,
                                  dws_asd=0), "coefficients"),
    (lambda: te.simulate_link_fit(B, dt=DT, n=1000, seed=0, band=BAND, jitter_asd=1e-8, readout_asd=0,
                                  dws_asd=0, manoeuvres={"phi": (1e-8, 0.02)}), "manoeuvres"),
])
def test_refusals(call, match):
    """Bad input is refused with one line naming the field."""
    with pytest.raises(ValueError, match=match) as e:
        call()
    assert "\n" not in str(e.value)
