"""Estimation of the linear TTL coefficients of one link from its readout and the measured (DWS) angles.

Model of link ``ij`` (:mod:`tqdyn.ttl.coupling`, linear part), readout y (m)::

    y(t) = c_lp phi_ij(t) + c_le eta_ij(t) + c_dp phi_ji(t - tau) + c_de eta_ji(t - tau) + n_y(t)
         = X_true(t) b + n_y(t),        b = (c_lp, c_le, c_dp, c_de)   [m/rad]  (:data:`REGRESSORS`)

The angles are known only through their DWS readout, X = X_true + N (N the DWS noise, delayed with
the distant angles).  Every fit works on the discrete Fourier transforms of the series, on the bins
k with f_lo <= f_k <= f_hi (f_k = k / (n dt), DC and Nyquist excluded): real and imaginary parts are
stacked into 2 m real equations A b = Y.  Because the model is linear and instantaneous (the delay is
applied to the measured angles as to the true ones) it holds bin by bin; for white (or circular
stationary) n_y the bins are independent with E[Re^2] = E[Im^2] = n S_y / (4 dt), S_y the one-sided
PSD (m^2/Hz), which makes the predicted covariances below exact for fixed regressors.

Ordinary least squares (OLS), :func:`ols_fit`: b = (A^T A)^-1 A^T Y; covariance s^2 (A^T A)^-1, s^2
the residual variance per real equation (2 m - p degrees of freedom).

Errors-in-variables bias of OLS (derivation): with A = A_true + A_N and A_N independent of A_true
and of n_y, A^T A / m -> S_true + S_N and A^T Y / m -> S_true b, so
E[b_OLS] -> (S_true + S_N)^-1 S_true b (:func:`ols_attenuation`), S_true and S_N the in-band
covariance matrices of the true angles and of their DWS noises (band integrals of their cross
spectra).  For mutually independent regressors and noises both are diagonal and each coefficient is
attenuated by lambda_k = var_band(true_k) / (var_band(true_k) + var_band(N_k)), the variances being
band integrals of the PSDs (:func:`band_variance`) plus A_k^2 / 2 for a manoeuvre of amplitude A_k
in the band.  Hartig, Marmor, George, Paczkowski & Sanjuan, "Tilt-to-length coupling in LISA --
uncertainty and biases", Class. Quantum Grav. 42 (2025), arXiv:2410.16475, report this bias of
least squares from angular readout noise, give an equation for it, and show that an
instrumental-variables estimator converges to an unbiased result.

Instrumental variables (IV), :func:`iv_fit`: two-stage least squares with instruments Z (known
series correlated with the true angles, independent of N and n_y).  Here the instruments are the
commanded calibration manoeuvres, sinusoids of known frequencies on phi and eta (the dedicated
sinusoidal TTL calibration manoeuvres of Wegener et al., "Design of dedicated tilt-to-length
calibration maneuvers for LISA", arXiv:2411.10409): cos and sin of each manoeuvre frequency, so
at least one manoeuvre frequency per coefficient.  A_hat = P_Z A (P_Z the projection onto the span
of the instruments' in-band parts), b = (A_hat^T A)^-1 A_hat^T Y; covariance
s^2 (A_hat^T A_hat)^-1, s^2 from the residual Y - A b over the whole band.  Its remaining bias is of
order var(N at the manoeuvre bins) / var(manoeuvre), i.e. S_N / (A^2 T), T the series' length
(the manoeuvre's DWS signal-to-noise ratio squared); OLS's does not shrink with T.

Units SI: angles rad, lengths m, coefficients m/rad, time s, frequencies Hz, ASDs one-sided
(:mod:`tqdyn.closedloop.noise`); series are 1-D arrays of shape (n,) on one uniform grid of step dt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate

from .._choices import unknown
from ..closedloop.noise import AsdModel
from .coupling import _delay

__all__ = ["REGRESSORS", "LinkFit", "LinkSimulation", "band_bins", "band_variance", "iv_fit",
           "manoeuvre_instruments", "ols_attenuation", "ols_fit", "simulate_link_fit"]

#: The coefficients of one link, in the order of b and of the regressors' columns.
REGRESSORS = ("local_phi", "local_eta", "distant_phi", "distant_eta")


@dataclass(frozen=True)
class LinkFit:
    """A fit of one link's linear TTL coefficients.

    coefficients: (p,) m/rad, order :data:`REGRESSORS`; covariance: (p, p) m^2/rad^2, predicted from
    the residual and the regressors (module docstring); residual_asd: one-sided ASD (m/Hz^1/2) of the
    in-band fit residual (readout minus fitted TTL), assumed flat in the band; band_hz: (f_lo, f_hi);
    bins: number of DFT bins used; method: "ols" or "iv"."""

    coefficients: np.ndarray
    covariance: np.ndarray
    residual_asd: float
    band_hz: tuple
    bins: int
    method: str

    @property
    def sigma(self) -> np.ndarray:
        """Predicted 1-sigma uncertainty of each coefficient (p,), m/rad."""
        return np.sqrt(np.diag(self.covariance))


def _band(field: str, band, dt: float, n: int) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError):
        raise ValueError(f"{field} = {band!r}: expected (f_lo, f_hi) in Hz") from None
    nyq = 0.5 / dt
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi <= nyq):
        raise ValueError(f"{field} = {band!r}: need 0 < f_lo < f_hi <= Nyquist = {nyq:g} Hz")
    if hi - lo < 2.0 / (n * dt):
        raise ValueError(f"{field} = {band!r}: narrower than two frequency bins ({1.0 / (n * dt):g} Hz each)")
    return lo, hi


def band_bins(n: int, dt: float, band) -> np.ndarray:
    """Indices of the rfft bins k with f_lo <= k / (n dt) <= f_hi, DC and Nyquist excluded (int array)."""
    lo, hi = _band("band", band, dt, n)
    f = np.fft.rfftfreq(n, dt)
    k = np.nonzero((f >= lo) & (f <= hi))[0]
    return k[(k > 0) & (k < n / 2)]


def _stacked(x: np.ndarray, bins: np.ndarray) -> np.ndarray:
    """Real and imaginary parts of the in-band rfft of x (n,) or (n, q) along axis 0: (2 m,) or (2 m, q)."""
    z = np.fft.rfft(x, axis=0)[bins]
    return np.concatenate([z.real, z.imag], axis=0)


def _prepare(y, regressors, dt, band):
    y = np.asarray(y, dtype=np.float64)
    x = np.asarray(regressors, dtype=np.float64)
    if y.ndim != 1:
        raise ValueError(f"y: shape {y.shape}, expected (n,)")
    if x.ndim != 2 or x.shape[0] != y.size:
        raise ValueError(f"regressors: shape {x.shape}, expected ({y.size}, p)")
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(x))):
        raise ValueError("y, regressors: must be finite (trim the NaN samples of a delayed series first)")
    step = float(dt)
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"dt = {dt!r}: must be > 0 (s)")
    bins = band_bins(y.size, step, band)
    if 2 * bins.size <= x.shape[1]:
        raise ValueError(f"band = {band!r}: {bins.size} bins, need more than {x.shape[1]} real equations")
    return y, x, step, bins


def _fit(kind, a, yv, b, cov_core, n, dt, band, bins):
    r = yv - a @ b
    s2 = float(r @ r) / (r.size - a.shape[1])
    return LinkFit(coefficients=b, covariance=s2 * cov_core, residual_asd=math.sqrt(4.0 * dt * s2 / n),
                   band_hz=tuple(float(v) for v in band), bins=int(bins.size), method=kind)


def ols_fit(y, regressors, dt: float, band) -> LinkFit:
    """Ordinary least squares of the readout y (n,) [m] on the measured angles ``regressors`` (n, p)
    [rad] in the band (f_lo, f_hi) [Hz]; dt [s].  Coefficients in the regressors' column order."""
    y, x, dt, bins = _prepare(y, regressors, dt, band)
    a, yv = _stacked(x, bins), _stacked(y, bins)
    core = np.linalg.inv(a.T @ a)
    b = core @ (a.T @ yv)
    return _fit("ols", a, yv, b, core, y.size, dt, band, bins)


def iv_fit(y, regressors, instruments, dt: float, band) -> LinkFit:
    """Instrumental-variables (two-stage least squares) fit: y (n,) [m], regressors (n, p) [rad],
    instruments (n, q) (any unit, q >= p, e.g. :func:`manoeuvre_instruments`), band (f_lo, f_hi) [Hz]."""
    y, x, dt, bins = _prepare(y, regressors, dt, band)
    z = np.asarray(instruments, dtype=np.float64)
    if z.ndim != 2 or z.shape[0] != y.size or z.shape[1] < x.shape[1]:
        raise ValueError(f"instruments: shape {z.shape}, expected ({y.size}, q) with q >= {x.shape[1]}")
    a, yv, zs = _stacked(x, bins), _stacked(y, bins), _stacked(z, bins)
    q, _ = np.linalg.qr(zs)  # orthonormal basis of the instruments' in-band span
    a_hat = q @ (q.T @ a)
    if np.linalg.matrix_rank(a_hat) < x.shape[1]:
        raise ValueError("instruments: fewer independent in-band instruments than coefficients "
                         "(need a manoeuvre frequency inside the band for each coefficient)")
    b = np.linalg.solve(a_hat.T @ a, a_hat.T @ yv)
    return _fit("iv", a, yv, b, np.linalg.inv(a_hat.T @ a_hat), y.size, dt, band, bins)


def manoeuvre_instruments(n: int, dt: float, frequencies_hz) -> np.ndarray:
    """cos and sin (2 pi f t), t = k dt, of each manoeuvre frequency: shape (n, 2 len(frequencies))."""
    t = np.arange(n) * dt
    cols = []
    for f in frequencies_hz:
        cols += [np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)]
    return np.stack(cols, axis=1)


def band_variance(asd: AsdModel, band) -> float:
    """Integral of asd(f)^2 over f_lo <= f <= f_hi [Hz]: the in-band variance, (unit)^2."""
    lo, hi = (float(v) for v in band)
    val, _ = integrate.quad(lambda f: float(asd.asd(f)) ** 2, lo, hi, limit=200,
                            points=[10 ** e for e in range(-6, 2) if lo < 10 ** e < hi] or None)
    return val


def ols_attenuation(s_true, s_noise) -> np.ndarray:
    """M = (S_true + S_N)^-1 S_true (p, p): E[b_OLS] = M b for in-band covariance matrices S_true of
    the true angles and S_N of their DWS noises (rad^2, or any common unit); 1-D inputs are the
    diagonals (independent regressors), giving lambda_k = S_true,k / (S_true,k + S_N,k)."""
    st, sn = np.asarray(s_true, dtype=np.float64), np.asarray(s_noise, dtype=np.float64)
    st = np.diag(st) if st.ndim == 1 else st
    sn = np.diag(sn) if sn.ndim == 1 else sn
    return np.linalg.solve(st + sn, st)


def _as_asd(field: str, v, unit: str) -> AsdModel:
    if isinstance(v, AsdModel):
        return v
    return AsdModel(level=v, unit=unit, name=field)


def _coloured(rng, n: int, dt: float, asd: AsdModel) -> np.ndarray:
    """A circular stationary Gaussian series (n,) with one-sided ASD ``asd``: white noise shaped in
    the frequency domain, E|X_k|^2 = n S(f_k) / (2 dt); the DC bin is zeroed."""
    if asd.level == 0:
        return np.zeros(n)
    w = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, dt)
    g = np.zeros(f.size)
    g[1:] = np.sqrt(asd.asd(f[1:]) ** 2 / (2.0 * dt))
    return np.fft.irfft(w * g, n)


@dataclass(frozen=True)
class LinkSimulation:
    """One simulated calibration of a link (:func:`simulate_link_fit`).

    injected: (4,) m/rad; ols, iv: :class:`LinkFit` (iv None without manoeuvres); predicted_attenuation:
    (4,) lambda_k from the stated ASDs and manoeuvres (module docstring); ttl_asd: in-band ASD (m/Hz^1/2)
    of the injected TTL; residual_ttl_asd: dict method -> in-band ASD of the TTL left after subtracting
    the fitted TTL formed from the measured angles (true TTL minus fitted); residual_floor_asd: the
    part due to the DWS noise alone, sqrt(sum_k b_k^2 S_N,k) (m/Hz^1/2, at the band's mean PSD)."""

    injected: np.ndarray
    ols: LinkFit
    iv: LinkFit | None
    predicted_attenuation: np.ndarray
    ttl_asd: float
    residual_ttl_asd: dict
    residual_floor_asd: float


def _band_asd(x: np.ndarray, dt: float, bins: np.ndarray) -> float:
    """sqrt of the mean one-sided periodogram 2 dt |X_k|^2 / n over the bins (m/Hz^1/2)."""
    z = np.fft.rfft(x)[bins]
    return math.sqrt(2.0 * dt * float(np.mean(np.abs(z) ** 2)) / x.size)


def simulate_link_fit(coefficients, *, dt: float, n: int, seed: int, band, jitter_asd, readout_asd,
                      dws_asd, tau: float = 0.0, manoeuvres: dict | None = None,
                      angles: dict | None = None) -> LinkSimulation:
    """Simulate one link's readout and DWS angles, fit the coefficients by OLS (and IV with manoeuvres).

    coefficients: (4,) injected b [m/rad], order :data:`REGRESSORS`; dt [s]; n samples of the fitted
    series; seed: numpy ``default_rng`` seed; band (f_lo, f_hi) [Hz] of the fits; jitter_asd,
    dws_asd: ASDs [rad/Hz^1/2] (a float = white, or an :class:`AsdModel`) of the true angle jitter and
    of the DWS noise, the same for the four angles, independent; readout_asd [m/Hz^1/2] of the
    readout noise; tau [s]: the link's light travel time (the distant angles and their DWS noise are
    delayed by it with :mod:`tqdyn.ttl.coupling`'s order-7 Lagrange delay); manoeuvres: dict
    regressor name -> (amplitude [rad], frequency [Hz]), a sinusoid added to that true angle (a distant
    one at the emitting MOSA, so it arrives delayed), each frequency moved to the nearest DFT bin;
    angles: optional dict regressor name -> (n + margin,) true jitter series [rad] (e.g. a closed-loop
    run) replacing the coloured-noise draw, margin = ceil(tau/dt) + 8."""
    b = np.asarray(coefficients, dtype=np.float64)
    if b.shape != (4,) or not np.all(np.isfinite(b)):
        raise ValueError(f"coefficients = {coefficients!r}: expected 4 finite values (m/rad), order {REGRESSORS}")
    manoeuvres = dict(manoeuvres or {})
    for k in manoeuvres:
        if k not in REGRESSORS:
            raise ValueError(unknown("manoeuvres", k, REGRESSORS, problem="is not a key"))
    jit = _as_asd("jitter_asd", jitter_asd, "rad")
    dws = _as_asd("dws_asd", dws_asd, "rad")
    ro = _as_asd("readout_asd", readout_asd, "m")
    margin = int(math.ceil(tau / dt)) + 8
    ntot = n + margin
    rng = np.random.default_rng(seed)
    t = np.arange(ntot) * dt
    true, meas, freqs, man_var = {}, {}, [], np.zeros(4)
    for i, name in enumerate(REGRESSORS):
        if angles is not None and name in angles:
            x = np.asarray(angles[name], dtype=np.float64)
            if x.shape != (ntot,):
                raise ValueError(f"angles[{name!r}]: shape {x.shape}, expected ({ntot},) (n + ceil(tau/dt) + 8)")
        else:
            x = _coloured(rng, ntot, dt, jit)
        if name in manoeuvres:
            amp, f = (float(v) for v in manoeuvres[name])
            f = round(f * n * dt) / (n * dt)
            freqs.append(f)
            x = x + amp * np.sin(2 * np.pi * f * t)
            man_var[i] = 0.5 * amp * amp
        true[name] = x
        meas[name] = x + _coloured(rng, ntot, dt, dws)
    cut = slice(margin, ntot)

    def columns(src):
        cols = [src[nm] for nm in REGRESSORS[:2]] + [_delay(src[nm], dt, tau) for nm in REGRESSORS[2:]]
        return np.stack([c[cut] for c in cols], axis=1)

    x_true, x_meas = columns(true), columns(meas)
    ttl_true = x_true @ b
    y = ttl_true + _coloured(rng, n, dt, ro)
    ols = ols_fit(y, x_meas, dt, band)
    iv = None
    if freqs:
        iv = iv_fit(y, x_meas, manoeuvre_instruments(n, dt, freqs), dt, band)
    bins = band_bins(n, dt, band)
    resid = {fit.method: _band_asd(ttl_true - x_meas @ fit.coefficients, dt, bins)
             for fit in (ols, iv) if fit is not None}
    width = float(band[1]) - float(band[0])
    var_true = band_variance(jit, band) + man_var
    var_dws = np.full(4, band_variance(dws, band))
    floor = math.sqrt(float(np.sum(b * b)) * band_variance(dws, band) / width)
    return LinkSimulation(injected=b, ols=ols, iv=iv, predicted_attenuation=np.diag(ols_attenuation(var_true, var_dws)),
                          ttl_asd=_band_asd(ttl_true, dt, bins), residual_ttl_asd=resid, residual_floor_asd=floor)
