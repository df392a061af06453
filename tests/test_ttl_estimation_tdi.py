"""Joint estimation of the six links' 24 TTL coefficients, from the links and in TDI
(tqdyn.ttl.estimation_tdi).

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

from tqdyn.ttl import coupling as ttl
from tqdyn.ttl import estimation_tdi as tt
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


def test_noise_free_returns_injected_coefficients():
    """No readout and no DWS noise, independent MOSA angles (10 nrad/Hz^1/2): the six-link fit
    returns b to round-off (measured 5e-15 relative; bound 1e-12) and the TDI fit to the round-off
    of its whitened normal matrix (condition ~ 2 with unit diagonal, but the regressors' TDI
    responses span ~ 1e4 in the band: measured 1.4e-10; bound 1e-8); nothing is degenerate."""
    s = tt.simulate_six_link_fit(COEFFS, dt=DT, n=N, seed=1, band=BAND, jitter_asd=1e-8, readout_asd=0.0,
                                 dws_asd=0.0, delays=TAU)
    rel = {k: np.max(np.abs(f.coefficients / s.injected - 1)) for k, f in s.fits.items()}
    assert rel["links-ols"] < 1e-12 and rel["tdi-ols"] < 1e-8, rel
    assert all(f.null_space.shape == (24, 0) for f in s.fits.values())


def test_scatter_matches_predicted_covariance():
    """Ten seeds, jitter 1 nrad/Hz^1/2, DWS noise 0.1 nrad/Hz^1/2, readout noise 1 pm/Hz^1/2 (white),
    100 nrad manoeuvres on the twelve angles: for the links' IV and TDI's IV fits the statistic
    sum_seeds (b_hat - b)^T Cov^-1 (b_hat - b) follows chi-square with 240 degrees of freedom if the
    predicted covariances are right (and the fits unbiased); bounds: its 1e-4 and 1 - 1e-4 quantiles,
    167 and 330.  Measured 260 (links) and 220 (TDI).  TDI's sigmas are 1.47-1.48 times the links'
    (bound 1.2-2: whitened, TDI keeps the projection of the six links on the three-dimensional
    complement of the laser-noise signatures), and the residual ASD is the readout noise
    (measured 1.03-1.05 pm/Hz^1/2; bound 0.95-1.15 pm)."""
    fits = {"links-iv": [], "tdi-iv": []}
    for seed in range(10):
        s = tt.simulate_six_link_fit(COEFFS, dt=DT, n=N // 2, seed=seed, band=BAND, jitter_asd=1e-9,
                                     readout_asd=1e-12, dws_asd=1e-10, delays=TAU, manoeuvres=MAN)
        for k in fits:
            assert s.fits[k].null_space.shape == (24, 0)
            assert 0.95e-12 < s.fits[k].residual_asd < 1.15e-12
            fits[k].append(s.fits[k])
    lo, hi = stats.chi2.ppf([1e-4, 1 - 1e-4], 240)
    for k, f in fits.items():
        chi2, dof = _chi2(f, s.injected)
        assert dof == 240 and lo < chi2 < hi, (k, chi2)
    ratio = fits["tdi-iv"][-1].sigma / fits["links-iv"][-1].sigma
    assert np.all((ratio > 1.2) & (ratio < 2.0)), ratio


def test_dws_noise_attenuates_ols_in_links_and_tdi():
    """White jitter 1 nrad/Hz^1/2 and white DWS noise 1 nrad/Hz^1/2 on independent MOSA angles, no
    manoeuvre: OLS is attenuated by S_j / (S_j + S_N) = 0.5 on every coefficient, in the links and in
    TDI (proportional spectra: module docstring).  Statistic: the slope b_hat . b / b . b per seed, its
    mean over 10 seeds within 4 standard errors and 0.03 of 0.5.  Measured 0.5008 +/- 0.0025 (links),
    0.5019 +/- 0.0039 (TDI)."""
    slopes = {"links-ols": [], "tdi-ols": []}
    for seed in range(10):
        s = tt.simulate_six_link_fit(COEFFS, dt=DT, n=N // 2, seed=seed, band=BAND, jitter_asd=1e-9,
                                     readout_asd=1e-12, dws_asd=1e-9, delays=TAU)
        b = s.injected
        for k in slopes:
            slopes[k].append(float(s.fits[k].coefficients @ b / (b @ b)))
    np.testing.assert_allclose(s.predicted_attenuation, 0.5, rtol=1e-9)
    for k, v in slopes.items():
        sem = np.std(v, ddof=1) / math.sqrt(len(v))
        assert abs(np.mean(v) - 0.5) < min(4 * sem, 0.03), (k, np.mean(v), sem)


def test_tdi_cannot_separate_a_spacecraft_rotation_from_laser_noise():
    """Angles from spacecraft yaw, pitch and roll only (10 nrad/Hz^1/2, ttl.mosa_angles; no MOSA
    jitter): both MOSAs of spacecraft i share phi_i, and the TTL pattern c^l_ij = c^l_ik = -c^d_ij =
    -c^d_ik = c on the phi coefficients puts c phi_i in links ij, ik and -D_ji (c phi_i), -D_ki (c phi_i)
    in links ji, ki: the signature y = D_ij p_j - p_i of laser noise p_i = -c phi_i, which TDI cancels.
    The TDI fit must report exactly these three combinations (one per spacecraft) as its null space
    (measured: scaled eigenvalues 1e-16, next 0.33; the null space's projection onto the three
    predicted vectors 1 - 1e-16), the links' fit none (smallest eigenvalue 0.87; bound 0.5); with the
    same rotation plus 100 nrad manoeuvres of the individual MOSA angles, the TDI IV fit is full rank
    (its instruments are not common to a spacecraft's two MOSAs)."""
    kw = dict(dt=DT, n=N // 2, seed=2, band=BAND, jitter_asd=0.0, readout_asd=1e-12, dws_asd=0.0, delays=TAU,
              spacecraft_jitter_asd=1e-8)
    s = tt.simulate_six_link_fit(COEFFS, **kw)
    pred = np.zeros((24, 3))
    for c, sc in enumerate(ttl.SPACECRAFT):
        for m in ttl.MOSAS:
            if m[0] == sc:
                pred[tt.COEFFICIENTS.index(f"local_phi[{m}]"), c] = 0.5
                pred[tt.COEFFICIENTS.index(f"distant_phi[{m}]"), c] = -0.5
    null = s.fits["tdi-ols"].null_space
    assert null.shape == (24, 3)
    assert np.linalg.norm(pred.T @ null, axis=0) == pytest.approx(1.0, abs=1e-6)
    assert tt.normal_modes(s.fits["tdi-ols"])[0][3] > 0.05
    assert tt.normal_modes(s.fits["links-ols"])[0][0] > 0.5 and s.fits["links-ols"].null_space.shape == (24, 0)
    # OLS leaves the undetermined combinations at zero and recovers the rest of b.
    f = s.fits["tdi-ols"]
    assert np.all(np.abs(f.coefficients - (s.injected - null @ (null.T @ s.injected))) < 5 * f.sigma)
    s = tt.simulate_six_link_fit(COEFFS, manoeuvres=MAN, **kw)
    f = s.fits["tdi-iv"]
    assert f.null_space.shape == (24, 0) and np.all(np.abs(f.coefficients - s.injected) < 5 * f.sigma)


def _tianqin(n: int):
    """The TianQin-like calibration of the one-link section (tests/test_ttl_estimation.py) on all
    six links: readout 1 pm/Hz^1/2, independent MOSA angle jitter 10 nrad/Hz^1/2, DWS noise
    2e-10 rad/Hz^1/2 sqrt(1 + (1 mHz/f)^2), TTLCoefficients.random(seed=3), band 1-100 mHz,
    dt = 0.5 s, 50 nrad manoeuvres at 20-75 mHz, and laser noise 1 um/Hz^1/2 (10^6 x the readout
    noise) in the TDI data.  Returns the simulation, the hand-integrated per-link floors
    sqrt(sum_link b^2 S_N) (band mean of 1 + (f_k/f)^2: width + f_k^2 (1/f_lo - 1/f_hi)) and X2's
    floor: the DWS noise N_a of each angle a of MOSA m enters link m (c^l) and link e = distant_mosa(m)
    (c^d, delayed by tau_e), so X2 keeps sqrt(mean_k sum_a |c^l T_X2,m + c^d T_X2,e exp(-2 pi i f tau_e)|^2
    S_N(f_k)) (michelson_transfer, checked against the time-domain X2 above)."""
    dws = AsdModel(2e-10, ((1e-3, -1),))
    s = tt.simulate_six_link_fit(COEFFS, dt=DT, n=n, seed=5, band=BAND, jitter_asd=1e-8, readout_asd=1e-12,
                                 dws_asd=dws, delays=TAU, manoeuvres=tt.default_manoeuvres(5e-8), laser_asd=1e-6)
    b, width = s.injected, BAND[1] - BAND[0]
    mean_knee = (width + 1e-3 ** 2 * (1 / BAND[0] - 1 / BAND[1])) / width
    b2 = {}
    for m in ttl.MOSAS:
        e = ttl.distant_mosa(m)
        names = (f"local_phi[{m}]", f"local_eta[{m}]", f"distant_phi[{e}]", f"distant_eta[{e}]")
        b2[m] = sum(b[tt.COEFFICIENTS.index(k)] ** 2 for k in names)
    floor = {m: math.sqrt(b2[m] * 2e-10 ** 2 * mean_knee) for m in ttl.MOSAS}
    f = np.fft.rfftfreq(n, DT)
    f = f[(f >= BAND[0]) & (f <= BAND[1])]
    tx = tt.michelson_transfer(f, TAU)[:, 0, :]  # (bins, 6): X2 per link
    power = np.zeros(f.size)
    for m in ttl.MOSAS:  # the DWS noise of MOSA m's angle reaches link m (local) and link e (distant, delayed)
        e = ttl.distant_mosa(m)
        for a in ("phi", "eta"):
            amp = (b[tt.COEFFICIENTS.index(f"local_{a}[{m}]")] * tx[:, ttl.MOSAS.index(m)]
                   + b[tt.COEFFICIENTS.index(f"distant_{a}[{m}]")] * tx[:, ttl.MOSAS.index(e)]
                   * np.exp(-2j * np.pi * f * TAU[e]))
            power += np.abs(amp) ** 2
    x2_floor = math.sqrt(float(np.mean(power * 2e-10 ** 2 * (1 + (1e-3 / f) ** 2))))
    return s, floor, x2_floor


def _check_tianqin(s, floor, x2_floor):
    for name, fit in s.fits.items():
        assert fit.null_space.shape == (24, 0)
        for m in ttl.MOSAS:
            assert 0.95 * floor[m] < s.residual_ttl_asd[name][m] < 1.1 * floor[m], (name, m)
        assert 0.95 * x2_floor < s.x2_residual_asd[name] < 1.1 * x2_floor, name
    for name in ("links-iv", "tdi-iv"):
        fit = s.fits[name]
        assert np.all(np.abs(fit.coefficients - s.injected) < 5 * fit.sigma), name


def test_tianqin_residual_after_subtraction_short():
    """The TianQin-like case on 2^15 samples (4.6 h): every link's TTL left after subtracting the
    fitted coefficients (links or TDI, OLS or IV) sits on its hand-integrated floor (bounds 0.95-1.1;
    measured 0.98-1.02 at 2^17 samples), so does X2's; the IV fits are within 5 sigma of b, laser
    noise 10^6 x the readout noise notwithstanding."""
    _check_tianqin(*_tianqin(2 ** 15))


@pytest.mark.slow
def test_tianqin_residual_after_subtraction(record_number):
    """As the short test on 2e5 s (the one-link section's span, n = 400 000): before and after per
    link and in X2, recorded for docs/tilt-to-length.md.  X2 is compared with TianQin's 0.3 pm/Hz^1/2
    per-link allocation carried through X2 (0.3 pm times sqrt(mean sum_links |T_X2,link|^2))."""
    s, floor, x2_floor = _tianqin(400_000)
    _check_tianqin(s, floor, x2_floor)
    links = ttl.MOSAS
    rec = lambda key, value, unit="": record_number(f"ttl_estimation_tdi.tianqin_{key}", value, unit)  # noqa: E731
    rec("ttl_before_asd_m", [s.ttl_asd[m] for m in links], "m/Hz^1/2")
    for name in s.fits:
        key = name.replace("-", "_")
        rec(f"residual_{key}_asd_m", [s.residual_ttl_asd[name][m] for m in links], "m/Hz^1/2")
        rec(f"x2_residual_{key}_asd_m", s.x2_residual_asd[name], "m/Hz^1/2")
        rec(f"{key}_rel_error_max", float(np.max(np.abs(s.fits[name].coefficients / s.injected - 1))))
        rec(f"{key}_rel_sigma_max", float(np.max(s.fits[name].sigma / np.abs(s.injected))))
    rec("floor_asd_m", [floor[m] for m in links], "m/Hz^1/2")
    rec("x2_floor_asd_m", x2_floor, "m/Hz^1/2")
    rec("x2_before_asd_m", s.x2_ttl_asd, "m/Hz^1/2")
    rec("x2_allocation_asd_m", 0.3e-12 * s.x2_gain_rms, "m/Hz^1/2")
    rec("x2_residual_over_allocation", s.x2_residual_asd["tdi-iv"] / (0.3e-12 * s.x2_gain_rms))
    rec("residual_over_0p3pm", [s.residual_ttl_asd["tdi-iv"][m] / 0.3e-12 for m in links])
    rec("tdi_over_links_sigma", [float(v) for v in s.fits["tdi-iv"].sigma / s.fits["links-iv"].sigma])


@pytest.mark.parametrize("call, match", [
    (lambda: tt.michelson("X3", {m: np.zeros(100) for m in ttl.MOSAS}, DT, TAU), "channel"),
    (lambda: tt.michelson("X2", {m: np.zeros(100) for m in ttl.MOSAS}, DT, {"12": 1.0}), "delays"),
    (lambda: tt.michelson("X2", {m: np.zeros(100) for m in ttl.MOSAS}, DT, dict(TAU, **{"12": -1.0})), "delays"),
    (lambda: tt.fit_tdi(np.zeros((100, 3)), np.zeros((100, 3, 4)), DT, BAND, TAU), "tdi_design"),
    (lambda: tt.fit_tdi(np.full((100, 3), np.nan), np.zeros((100, 3, 24)), DT, BAND, TAU), "finite"),
    (lambda: tt.simulate_six_link_fit(COEFFS, dt=DT, n=1024, seed=0, band=BAND, jitter_asd=1e-9, readout_asd=0,
                                      dws_asd=0, delays=TAU, manoeuvres={"phi1": (1e-8, 0.02)}), "manoeuvres"),
    (lambda: tt.simulate_six_link_fit(COEFFS, dt=DT, n=1024, seed=0, band=BAND, jitter_asd=1e-9, readout_asd=0,
                                      dws_asd=0, delays=TAU,
                                      manoeuvres={"phi12": (1e-8, 0.02), "eta12": (1e-8, 0.0201)}),
     "manoeuvres"),
    (lambda: tt.simulate_six_link_fit("b", dt=DT, n=1024, seed=0, band=BAND, jitter_asd=1e-9, readout_asd=0,
                                      dws_asd=0, delays=TAU), "coeffs"),
])
def test_refusals(call, match):
    """Bad input is refused with one line naming the field."""
    with pytest.raises(ValueError, match=match) as e:
        call()
    assert "\n" not in str(e.value)
