"""Joint estimation of the 24 linear TTL coefficients of the six links, from the links or in TDI.

Unknowns b (24,) (:data:`COEFFICIENTS`): for each MOSA m of :data:`tqdyn.ttl.coupling.MOSAS` its
local_phi, local_eta, distant_phi, distant_eta (m/rad), in :mod:`tqdyn.ttl.coupling`'s convention:
link ``ij`` carries c^local_ij of the receiving MOSA ij's angles at t and c^distant_ji of the
emitting MOSA ji's angles at t - tau_ij.  Regressors: the DWS-measured angles (true + DWS noise),
the distant ones delayed by the link's light time with :mod:`tqdyn.ttl.coupling`'s order-7
Lagrange delay (:func:`link_regressors`).

(a) Six links, :func:`fit_links`: the six readouts y_ij = s_ij + n_ij are the data; each
coefficient enters one link only, so the design is block diagonal (four columns per link).

(b) TDI, :func:`fit_tdi`: in the instrument laser frequency noise (y_ij += D_ij p_j - p_i) hides the
single-link TTL; the second-generation Michelson combinations (Tinto & Dhurandhar, Living Rev.
Relativ. 24 (2021) 1; PyTDI 2.2 ``michelson.compute_factorized_michelson``)::

    X2 = (1 - D121 - D12131 + D1312121)(y13 + D13 y31) - (1 - D131 - D13121 + D1213131)(y12 + D12 y21)

(Y2, Z2 by the cyclic permutation 1 -> 2 -> 3 -> 1) cancel it.  D_ij x(t) = x(t - tau_ij(t)) and
D_{i j k ...} = D_ij D_jk ..., nested as D_ij D_jk x(t) = x(t - tau_ij(t) - tau_jk(t - tau_ij(t)))
(:func:`chain_shift`; constant or slowly varying tau given as (n,) series); every term is one
order-7 Lagrange delay of a link series by its chain's total shift (:func:`michelson`).  The TDI
operator is linear, so the design matrix is the combination applied to each coefficient's
regressor (:func:`tdi_regressors`); the data are X2, Y2, Z2 of the six readouts.

Fit (both): on the DFT bins k of a band (f_lo, f_hi) (DC and Nyquist excluded), the c channels
(6 links or 3 Michelsons) give Y_k = A_k b + e_k, A_k (c, 24) complex.  e_k is Gaussian with
E[e_k e_k^H] = sigma^2 C_k, C_k = T_k T_k^H g(f_k), T_k (c, 6) the channels' transfer from the six
links (identity for the links; for constant delays the Michelsons' sums of +/- exp(-2 pi i f tau_chain),
:func:`michelson_transfer`) and g the readout noise's PSD shape (1 = white).  Each bin is whitened
(L_k^-1 with C_k = L_k L_k^H) and real and imaginary parts stacked: 2 m c real equations with white
noise of variance s^2 each.  OLS: b = (A^T A)^-1 A^T Y, covariance s^2 (A^T A)^-1 (generalised least
squares in the un-whitened variables).  IV (two-stage least squares, :mod:`.estimation`): the
instruments are the cos and sin of the calibration manoeuvres, each at a DFT bin and distinct per
angle; their in-band span in every channel is the span of the manoeuvre bins, so P_Z A keeps those
rows, A_hat^T A = A_s^T A_s and b = (A_s^T A_s)^-1 A_s^T Y_s, covariance s^2 (A_s^T A_s)^-1 with s^2
from the whole band's residual.  s^2 = n S_eff / (4 dt) gives the per-link equivalent residual ASD
S_eff^1/2 (:attr:`JointFit.residual_asd`; the readout noise plus the DWS noise times the
coefficients).

Errors in variables: E[A^T A] = G_true + G_N for any design built by the same linear filters from
the true angles and their DWS noises; with independent angles and jitter and DWS PSDs proportional
(S_j = r S_N at every frequency) G_true = r G_N and E[b_OLS] -> r / (1 + r) b for every coefficient,
in the links and in TDI alike (:func:`predicted_attenuation`, the one-link lambda of
:mod:`.estimation`).

Degeneracies in TDI: the whitened TDI information is the six links' projected onto the complement
of the laser-noise signatures y_ij = D_ij p_j - p_i (three dimensions per frequency), so a TTL
pattern of that form is invisible.  When the two MOSAs of spacecraft i share its yaw phi_i
(spacecraft jitter, ``spacecraft_jitter_asd``), the phi coefficients c^l_ij = c^l_ik = -c^d_ij =
-c^d_ik = c put c phi_i in links ij, ik and -D_ji (c phi_i), -D_ki (c phi_i) in links ji, ki: laser
noise p_i = -c phi_i.  These three combinations (one per spacecraft) are undetermined at every frequency and
are returned in :attr:`JointFit.null_space`; the MOSAs' own jitter or manoeuvres of the individual
MOSAs lift them.  Pitch is spared while roll jitter is present (eta_ij = cos a_ij eta_i -
sin a_ij theta_i + eta^MOSA_ij with a_ij = +-30 deg differs between the two MOSAs).  With
independent MOSA angles nothing is degenerate: the round trips carry a MOSA's local and distant
coefficients as c^l + c^d (far end) and c^l + c^d D_ij D_ji (near end), but the readout noise of the
same links enters both alike and the whitened fit keeps their difference (:func:`normal_modes`).

Units SI (rad, m, s, m/rad, Hz; ASDs one-sided); series (n,) on one uniform grid of step dt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .._choices import unknown
from ..closedloop.noise import AsdModel
from .coupling import MOSAS, SPACECRAFT, TTLCoefficients, _delay, distant_mosa, mosa_angles
from .estimation import REGRESSORS, _as_asd, _band_asd, _coloured, band_bins, band_variance

__all__ = ["ANGLES", "CHANNELS", "COEFFICIENTS", "NULL_RCOND", "JointFit", "SixLinkSimulation", "chain_shift",
           "coefficient_vector", "default_manoeuvres", "fit_links", "fit_tdi", "link_regressors",
           "michelson", "michelson_terms", "michelson_transfer", "normal_modes", "predicted_attenuation",
           "simulate_six_link_fit", "tdi_regressors"]

#: The 24 coefficients, order of b: for each MOSA (ttl.MOSAS order) its four REGRESSORS.
COEFFICIENTS = tuple(f"{r}[{m}]" for m in MOSAS for r in REGRESSORS)
#: The twelve measured angles, keyed "phi12", "eta12", ...
ANGLES = tuple(f"{a}{m}" for m in MOSAS for a in ("phi", "eta"))
#: The second-generation Michelson combinations.
CHANNELS = ("X2", "Y2", "Z2")
_PERM = str.maketrans("123", "231")
#: Relative eigenvalue below which a combination of coefficients counts as undetermined (round-off of
#: the whitened normal matrix, ~1e-16, times the ~1e4 dynamic range of the regressors' scales).
NULL_RCOND = 1e-12


def coefficient_vector(coeffs: TTLCoefficients) -> np.ndarray:
    """The linear coefficients of ``coeffs`` as b (24,), m/rad, order :data:`COEFFICIENTS`."""
    return np.array([getattr(coeffs, r)[m] for m in MOSAS for r in REGRESSORS])


def _index(kind: str, mosa: str) -> int:
    return MOSAS.index(mosa) * 4 + REGRESSORS.index(kind)


def _join(a: str, b: str) -> str:
    """The chain D_a D_b ("121" + "13" -> "1213"); "" is the identity."""
    if not a or not b:
        return a or b
    return a + b[1:]


def michelson_terms(channel: str) -> list[tuple[int, str, str]]:
    """(sign, link, chain) of each term of X2, Y2 or Z2: channel = sum sign * D_chain y_link."""
    if channel not in CHANNELS:
        raise ValueError(unknown("channel", channel, CHANNELS))
    terms = []
    for sign, (near, far) in ((1, ("13", "12")), (-1, ("12", "13"))):
        a, b = near, far  # round trip along arm a (y_a + D_a y_a'), filter on the other arm b
        poly = ((1, ""), (-1, _join(b, b[::-1])), (-1, _join(_join(b, b[::-1]), _join(a, a[::-1]))),
                (1, _join(_join(_join(a, a[::-1]), b), _join(b[::-1], _join(b, b[::-1])))))
        for ps, chain in poly:
            terms.append((sign * ps, a, chain))
            terms.append((sign * ps, a[::-1], _join(chain, a)))
    rot = CHANNELS.index(channel)
    for _ in range(rot):
        terms = [(s, ln.translate(_PERM), ch.translate(_PERM)) for s, ln, ch in terms]
    return terms


@lru_cache(maxsize=512)
def _weights(dt: float, shift: float) -> tuple[int, tuple]:
    """floor(-shift/dt) and the eight weights of ttl's delay by a constant shift (s), nodes fl-3..fl+4."""
    fl = int(math.floor(-shift / dt))
    k0, size = 3 - fl, 3 - fl + 8  # output sample whose stencil is the impulse series' nodes 0..7
    return fl, tuple(float(_delay(np.eye(1, size, j)[0], dt, shift)[k0]) for j in range(8))


def _delayed(x: np.ndarray, dt: float, shift) -> np.ndarray:
    """x(t - shift) along axis 0 (x (n,) or (n, q)) by :mod:`tqdyn.ttl.coupling`'s order-7 Lagrange
    delay (NaN where its stencil leaves the series).  A constant shift uses that delay's eight weights,
    read off by delaying unit impulses, as one FIR filter (the same interpolant, ~10x faster than
    evaluating the weights per sample); a series shift calls it directly."""
    x = np.asarray(x, dtype=np.float64)
    if np.ndim(shift):
        return _delay(x, dt, shift) if x.ndim == 1 else np.stack([_delay(c, dt, shift) for c in x.T], axis=1)
    fl, w = _weights(float(dt), float(shift))
    n = x.shape[0]
    out = np.full(x.shape, np.nan)
    lo, hi = max(0, 3 - fl), min(n, n - 4 - fl)  # k with 0 <= k + fl - 3 and k + fl + 4 <= n - 1
    if hi > lo:
        acc = np.zeros((hi - lo,) + x.shape[1:])
        for j in range(8):
            acc += w[j] * x[lo + fl - 3 + j:hi + fl - 3 + j]
        out[lo:hi] = acc
    return out


def _check_delays(delays, n: int) -> dict:
    if not isinstance(delays, dict) or set(delays) != set(MOSAS):
        raise ValueError(f"delays = {delays!r}: expected a dict keyed by the six links {', '.join(MOSAS)}")
    out = {}
    for m in MOSAS:
        t = np.asarray(delays[m], dtype=np.float64)
        if t.shape not in ((), (n,)) or not np.all(np.isfinite(t)) or np.any(t < 0):
            raise ValueError(f"delays[{m!r}] = {delays[m]!r}: must be a finite number >= 0 or ({n},) array (s)")
        out[m] = float(t) if t.shape == () else t
    return out


def chain_shift(chain: str, delays: dict, dt: float):
    """Total delay (s) of D_chain at the reception times: tau_i1i2(t) + tau_i2i3(t - tau_i1i2(t)) + ...;
    a float for constant delays, else an (n,) series (tau at the delayed times by the order-7 Lagrange
    interpolant, linear with held end values where its stencil leaves the series)."""
    tot = 0.0
    for a, b in zip(chain[:-1], chain[1:]):
        tau = delays[a + b]
        if np.ndim(tau) and not (np.ndim(tot) == 0 and tot == 0.0):
            late = _delay(tau, dt, tot)  # tau at t - tot; near the ends, where the stencil leaves the
            gap = np.isnan(late)         # series, the linear interpolant with the end values held
            late[gap] = np.interp((np.arange(tau.size) - tot / dt * np.ones(tau.size))[gap], np.arange(tau.size), tau)
            tau = late
        tot = tot + tau
    return tot


def michelson(channel: str, links: dict, dt: float, delays: dict) -> np.ndarray:
    """X2, Y2 or Z2 (m) of the six link series ``links`` (dict link -> (n,) m); delays (s) per link,
    floats or (n,) series.  The first ~ 8 tau / dt + 4 samples are NaN."""
    n = np.asarray(links[MOSAS[0]]).size
    d = _check_delays(delays, n)
    out = np.zeros(n)
    for sign, link, chain in michelson_terms(channel):
        x = np.asarray(links[link], dtype=np.float64)
        out += sign * (x if not chain else _delayed(x, dt, chain_shift(chain, d, dt)))
    return out


def michelson_transfer(f, delays: dict) -> np.ndarray:
    """T (len(f), 3, 6) complex: channel c = sum_link T[c, link] y_link at frequency f (Hz), for
    constant delays (s; series are replaced by their means)."""
    f = np.atleast_1d(np.asarray(f, dtype=np.float64))
    tau = {m: float(np.mean(delays[m])) for m in MOSAS}
    out = np.zeros((f.size, 3, 6), dtype=complex)
    for c, ch in enumerate(CHANNELS):
        for sign, link, chain in michelson_terms(ch):
            shift = sum(tau[a + b] for a, b in zip(chain[:-1], chain[1:]))
            out[:, c, MOSAS.index(link)] += sign * np.exp(-2j * np.pi * f * shift)
    return out


def link_regressors(phi: dict, eta: dict, dt: float, delays: dict) -> dict:
    """Regressors of each link: dict link -> (indices (4,) into b, columns (n, 4) rad), the receiving
    MOSA's phi, eta at t and the emitting MOSA's phi, eta delayed by the link's tau.  phi, eta: dicts
    MOSA -> (n,) measured angles (rad)."""
    n = np.asarray(phi[MOSAS[0]]).size
    d = _check_delays(delays, n)
    out = {}
    for m in MOSAS:
        e = distant_mosa(m)
        cols = [phi[m], eta[m], _delayed(phi[e], dt, d[m]), _delayed(eta[e], dt, d[m])]
        idx = [_index("local_phi", m), _index("local_eta", m), _index("distant_phi", e), _index("distant_eta", e)]
        out[m] = (np.array(idx), np.stack([np.asarray(c, dtype=np.float64) for c in cols], axis=1))
    return out


def tdi_regressors(regressors: dict, dt: float, delays: dict) -> np.ndarray:
    """The Michelson combinations of each coefficient's regressor: (n, 3, 24) (m per (m/rad)), from
    :func:`link_regressors`' output (a coefficient's column sits in its link, zero in the others)."""
    n = next(iter(regressors.values()))[1].shape[0]
    d = _check_delays(delays, n)
    out = np.zeros((n, 3, 24))
    shifts = {}
    for c, ch in enumerate(CHANNELS):
        for sign, link, chain in michelson_terms(ch):
            idx, cols = regressors[link]
            if chain and chain not in shifts:
                shifts[chain] = chain_shift(chain, d, dt)
            out[:, c, idx] += sign * (cols if not chain else _delayed(cols, dt, shifts[chain]))
    return out


@dataclass(frozen=True)
class JointFit:
    """A joint fit of the 24 coefficients.

    coefficients (24,) m/rad, order :data:`COEFFICIENTS`; covariance (24, 24) m^2/rad^2 (module
    docstring); normal (24, 24): the whitened normal matrix A^T A (OLS) or A_s^T A_s (IV), in units of
    1 / s^2 (the covariance is s^2 normal^-1); null_space (24, k): unit vectors (in b) of the k
    combinations the data do not determine (normal matrix scaled to unit diagonal has eigenvalue
    < :data:`NULL_RCOND` times its largest): the fit leaves them at zero (a pseudo-inverse) and the
    covariance excludes them -- check k == 0 before quoting sigma; residual_asd: per-link equivalent ASD of the residual
    (m/Hz^1/2, relative to the noise shape); band_hz; bins; method "ols" or "iv"; data "links" or
    "tdi"."""

    coefficients: np.ndarray
    covariance: np.ndarray
    normal: np.ndarray
    null_space: np.ndarray
    residual_asd: float
    band_hz: tuple
    bins: int
    method: str
    data: str

    @property
    def sigma(self) -> np.ndarray:
        """Predicted 1-sigma uncertainty of each coefficient (24,), m/rad."""
        return np.sqrt(np.diag(self.covariance))


def _whitened_fit(yk, ak, ck, dt, n, band, bins, sel, data):
    """yk (m, c), ak (m, c, p) complex; ck (m, c, c) noise covariance shapes or None (identity);
    sel: boolean (m,) mask of the manoeuvre bins (IV) or None (OLS)."""
    if ck is not None:
        ell = np.linalg.cholesky(ck)
        yk = np.linalg.solve(ell, yk[..., None])[..., 0]
        ak = np.linalg.solve(ell, ak)
    p = ak.shape[-1]
    a = np.concatenate([ak.real.reshape(-1, p), ak.imag.reshape(-1, p)])
    y = np.concatenate([yk.real.ravel(), yk.imag.ravel()])
    rows = slice(None) if sel is None else np.concatenate([np.repeat(sel, yk.shape[1])] * 2)
    a_s = a[rows]
    normal = a_s.T @ a_s
    # Solve in coefficients scaled to a unit-diagonal normal matrix; combinations whose scaled
    # eigenvalue is below NULL_RCOND are not determined: left at zero, reported in ``null_space``.
    dg = np.sqrt(np.diag(normal))
    if not np.all(dg > 0):
        raise ValueError("regressors: a coefficient has no in-band regressor (a zero column)")
    ev, vec = np.linalg.eigh(normal / np.outer(dg, dg))
    keep = ev > NULL_RCOND * ev[-1]
    inv = (vec[:, keep] / ev[keep]) @ vec[:, keep].T / np.outer(dg, dg)  # pseudo-inverse of normal
    b = inv @ (a_s.T @ y[rows])
    null = vec[:, ~keep] / dg[:, None]
    null = null / np.linalg.norm(null, axis=0) if null.size else np.zeros((p, 0))
    r = y - a @ b
    s2 = float(r @ r) / (r.size - int(keep.sum()))
    return JointFit(coefficients=b, covariance=s2 * inv, normal=normal, null_space=null,
                    residual_asd=math.sqrt(4.0 * dt * s2 / n), band_hz=tuple(float(v) for v in band),
                    bins=int(bins.size), method="ols" if sel is None else "iv", data=data)


def _select(n, dt, bins, manoeuvre_hz):
    if manoeuvre_hz is None:
        return None
    k = np.rint(np.asarray(manoeuvre_hz, dtype=np.float64) * n * dt).astype(int)
    missing = [float(f) for f, kk in zip(manoeuvre_hz, k) if kk not in bins]
    if missing:
        raise ValueError(f"manoeuvre_hz: {missing} outside the band's bins")
    return np.isin(bins, k)


def _shape(noise_shape, f):
    return np.ones(f.size) if noise_shape is None else np.asarray(noise_shape(f), dtype=np.float64)


def fit_links(y: dict, regressors: dict, dt: float, band, manoeuvre_hz=None, noise_shape=None) -> JointFit:
    """Joint fit from the six link readouts y (dict link -> (n,) m) on :func:`link_regressors`'
    output; OLS, or IV on the manoeuvre bins when ``manoeuvre_hz`` (frequencies, Hz, at DFT bins)
    is given; noise_shape: callable f -> relative readout PSD (None: white), the same on each link."""
    n = y[MOSAS[0]].size
    bins = band_bins(n, dt, band)
    yk = np.stack([np.fft.rfft(y[m])[bins] for m in MOSAS], axis=1)  # (m, 6)
    ak = np.zeros((bins.size, 6, 24), dtype=complex)
    for c, m in enumerate(MOSAS):
        idx, cols = regressors[m]
        ak[:, c, idx] = np.fft.rfft(cols, axis=0)[bins]
    f = bins / (n * dt)
    ck = _shape(noise_shape, f)[:, None, None] * np.eye(6)
    return _whitened_fit(yk, ak, ck, dt, n, band, bins, _select(n, dt, bins, manoeuvre_hz), "links")


def fit_tdi(tdi_data: np.ndarray, tdi_design: np.ndarray, dt: float, band, delays: dict, manoeuvre_hz=None,
            noise_shape=None) -> JointFit:
    """Joint fit in TDI: tdi_data (n, 3) X2, Y2, Z2 of the readouts (m), tdi_design (n, 3, 24) from
    :func:`tdi_regressors` (finite: trim the leading NaN samples), delays (s) for the noise
    covariance T T^H g(f) (:func:`michelson_transfer`); manoeuvre_hz, noise_shape as :func:`fit_links`."""
    x, a = np.asarray(tdi_data, dtype=np.float64), np.asarray(tdi_design, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3 or a.shape != (x.shape[0], 3, 24):
        raise ValueError(f"tdi_data, tdi_design: shapes {x.shape}, {a.shape}, expected (n, 3), (n, 3, 24)")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(a))):
        raise ValueError("tdi_data, tdi_design: must be finite (trim the leading NaN samples of the delays)")
    n = x.shape[0]
    bins = band_bins(n, dt, band)
    f = bins / (n * dt)
    t = michelson_transfer(f, delays)
    ck = _shape(noise_shape, f)[:, None, None] * (t @ t.conj().transpose(0, 2, 1))
    yk = np.fft.rfft(x, axis=0)[bins]
    ak = np.fft.rfft(a, axis=0)[bins]
    return _whitened_fit(yk, ak, ck, dt, n, band, bins, _select(n, dt, bins, manoeuvre_hz), "tdi")


def normal_modes(fit: JointFit) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (24,) ascending and eigenvectors (24, 24) (columns) of the normal matrix scaled
    to unit diagonal, D^-1/2 N D^-1/2: the combinations of (scaled) coefficients that the data
    determine worst come first; eigenvalue 1 everywhere = orthogonal regressors."""
    dg = np.sqrt(np.diag(fit.normal))
    return np.linalg.eigh(fit.normal / np.outer(dg, dg))


def predicted_attenuation(jitter_var: np.ndarray, dws_var: np.ndarray) -> np.ndarray:
    """lambda (24,) = var_true / (var_true + var_DWS) per coefficient from the band variances of the
    twelve angles (12,), order :data:`ANGLES` (each coefficient takes its angle's); exact for the
    links, and in TDI for proportional jitter and DWS spectra (module docstring)."""
    lam = np.asarray(jitter_var, dtype=np.float64) / (np.asarray(jitter_var) + np.asarray(dws_var))
    out = np.empty(24)
    for i, name in enumerate(COEFFICIENTS):
        kind, m = name[:-4], name[-3:-1]
        out[i] = lam[ANGLES.index(kind.split("_")[1] + m)]
    return out


def default_manoeuvres(amplitude_rad: float, f0_hz: float = 0.020, step_hz: float = 0.005) -> dict:
    """Sinusoidal manoeuvres on the twelve angles: amplitude (rad), frequencies f0 + k step (Hz), k in
    :data:`ANGLES` order (distinct frequencies, so that each instrument picks one angle)."""
    return {a: (float(amplitude_rad), f0_hz + k * step_hz) for k, a in enumerate(ANGLES)}


@dataclass(frozen=True)
class SixLinkSimulation:
    """One simulated calibration of the six links (:func:`simulate_six_link_fit`).

    injected (24,) m/rad; fits: dict "links-ols", "links-iv", "tdi-ols", "tdi-iv" -> :class:`JointFit`
    (the IV ones only with manoeuvres); predicted_attenuation (24,) (:func:`predicted_attenuation`);
    ttl_asd: dict link -> in-band ASD (m/Hz^1/2) of the injected TTL, the manoeuvres' bins left out
    (so are they in the ASDs that follow); residual_ttl_asd: dict fit name ->
    dict link -> in-band ASD of the TTL left after subtracting the fitted TTL formed from the measured
    angles; x2_ttl_asd, x2_residual_asd (dict fit name ->): the same in X2 (m/Hz^1/2);
    x2_gain_rms: sqrt of the band mean of sum_links |T_X2,link(f)|^2, the factor that turns a white
    per-link ASD into X2's band ASD (an allocation a per link gives a * x2_gain_rms in X2)."""

    injected: np.ndarray
    fits: dict
    predicted_attenuation: np.ndarray
    ttl_asd: dict
    residual_ttl_asd: dict
    x2_ttl_asd: float
    x2_residual_asd: dict
    x2_gain_rms: float


def simulate_six_link_fit(coeffs: TTLCoefficients, *, dt: float, n: int, seed: int, band, jitter_asd, readout_asd,
                          dws_asd, delays: dict, manoeuvres: dict | None = None, laser_asd=0.0,
                          spacecraft_jitter_asd=None, tdi: bool = True) -> SixLinkSimulation:
    """Simulate the six links' readouts and DWS angles; fit the 24 coefficients from the links and in TDI.

    coeffs: injected linear coefficients (m/rad; quadratic ones must be zero); dt (s); n samples of the
    fitted series; seed: numpy ``default_rng`` seed; band (f_lo, f_hi) (Hz); jitter_asd, dws_asd:
    ASDs (rad/Hz^1/2, a float = white, or :class:`AsdModel`) of the twelve independent true angles and
    of their independent DWS noises; readout_asd (m/Hz^1/2) of each link's independent readout noise
    (its shape weights the fits); delays: dict link -> constant light time (s); manoeuvres: dict
    angle (:data:`ANGLES`) -> (amplitude rad, frequency Hz) sinusoids added to the true angles (each
    moved to the nearest DFT bin; :func:`default_manoeuvres`); laser_asd (m/Hz^1/2): laser noise p_i of
    the three spacecraft added as D_ij p_j - p_i to link ij of the TDI data only (the link fits see
    readouts without it); spacecraft_jitter_asd (rad/Hz^1/2): optional yaw, pitch and roll jitter of
    each spacecraft, added to its two MOSAs' angles by :func:`tqdyn.ttl.coupling.mosa_angles`
    (jitter_asd is then the MOSAs' own jitter); tdi: False skips the TDI fits.  predicted_attenuation
    is exact for the links; in TDI for independent MOSA angles (no spacecraft jitter) and jitter and
    DWS PSDs proportional."""
    if not isinstance(coeffs, TTLCoefficients):
        raise ValueError(f"coeffs = {coeffs!r}: expected a TTLCoefficients")
    if any(v for name in ("phiphi", "etaeta", "phieta") for k in ("local", "distant")
           for v in getattr(coeffs, f"{k}_{name}").values()):
        raise ValueError("coeffs: quadratic coefficients must be zero (the fit is linear)")
    manoeuvres = dict(manoeuvres or {})
    for k in manoeuvres:
        if k not in ANGLES:
            raise ValueError(unknown("manoeuvres", k, ANGLES, problem="is not a key"))
    d = _check_delays(delays, 1)
    jit, dws = _as_asd("jitter_asd", jitter_asd, "rad"), _as_asd("dws_asd", dws_asd, "rad")
    ro, laser = _as_asd("readout_asd", readout_asd, "m"), _as_asd("laser_asd", laser_asd, "m")
    margin = int(math.ceil(10 * max(d.values()) / dt)) + 40
    wrap = np.arange(-margin, n + 8) % n  # periodic extension (8 trailing samples: delays < 3 dt)
    ntot = wrap.size
    draw = lambda asd: _coloured(rng, n, dt, asd)[wrap]  # noqa: E731
    rng = np.random.default_rng(seed)
    t = wrap * dt
    true, meas, freqs, man_var = {}, {}, [], np.zeros(12)
    for i, a in enumerate(ANGLES):
        x = draw(jit)
        if a in manoeuvres:
            amp, f = (float(v) for v in manoeuvres[a])
            f = round(f * n * dt) / (n * dt)
            freqs.append(f)
            x = x + amp * np.sin(2 * np.pi * f * t)
            man_var[i] = 0.5 * amp * amp
        true[a] = x
        meas[a] = x + draw(dws)
    if spacecraft_jitter_asd is not None:  # yaw, pitch, roll of each spacecraft, common to its two MOSAs
        sc = _as_asd("spacecraft_jitter_asd", spacecraft_jitter_asd, "rad")
        zero = {m: 0.0 for m in MOSAS}
        sc_phi, sc_eta = mosa_angles(*({s: draw(sc) for s in SPACECRAFT} for _ in range(3)), zero, zero)
        for m in MOSAS:
            for a, part in (("phi", sc_phi[m]), ("eta", sc_eta[m])):
                true[a + m] = true[a + m] + part
                meas[a + m] = meas[a + m] + part
        man_var = man_var + band_variance(sc, band)
    if len(set(freqs)) != len(freqs):
        raise ValueError(f"manoeuvres: frequencies {sorted(freqs)} not distinct DFT bins (n dt = {n * dt:g} s)")
    b = coefficient_vector(coeffs)
    angles = lambda src, a: {m: src[a + m] for m in MOSAS}  # noqa: E731
    reg_true = link_regressors(angles(true, "phi"), angles(true, "eta"), dt, d)
    reg_meas = link_regressors(angles(meas, "phi"), angles(meas, "eta"), dt, d)
    ttl_true = {m: reg_true[m][1] @ b[reg_true[m][0]] for m in MOSAS}
    y = {m: ttl_true[m] + draw(ro) for m in MOSAS}
    cut = slice(margin, margin + n)
    shape = None if ro.level == 0 else (lambda f: (ro.asd(f) / ro.level) ** 2)
    man_hz = freqs if freqs else None
    fits = {"links-ols": fit_links({m: y[m][cut] for m in MOSAS}, {m: (i, c[cut]) for m, (i, c) in reg_meas.items()},
                                   dt, band, noise_shape=shape)}
    if man_hz:
        fits["links-iv"] = fit_links({m: y[m][cut] for m in MOSAS}, {m: (i, c[cut]) for m, (i, c) in reg_meas.items()},
                                     dt, band, manoeuvre_hz=man_hz, noise_shape=shape)
    if tdi:
        p = {s: draw(laser) for s in "123"}
        y_tdi = {m: y[m] + _delayed(p[m[1]], dt, d[m]) - p[m[0]] for m in MOSAS} if laser.level else y
        data = np.stack([michelson(ch, y_tdi, dt, d) for ch in CHANNELS], axis=1)[cut]
        design = tdi_regressors(reg_meas, dt, d)[cut]
        fits["tdi-ols"] = fit_tdi(data, design, dt, band, d, noise_shape=shape)
        if man_hz:
            fits["tdi-iv"] = fit_tdi(data, design, dt, band, d, manoeuvre_hz=man_hz, noise_shape=shape)
    bins = band_bins(n, dt, band)  # the ASDs below leave the manoeuvre bins out (the TTL of the jitter)
    bins = bins[~np.isin(bins, np.rint(np.asarray(freqs) * n * dt).astype(int))]
    resid, x2_resid = {}, {}
    x2 = lambda links: michelson("X2", links, dt, d)[cut]  # noqa: E731
    for name, fit in fits.items():
        left = {m: ttl_true[m] - reg_meas[m][1] @ fit.coefficients[reg_meas[m][0]] for m in MOSAS}
        resid[name] = {m: _band_asd(left[m][cut], dt, bins) for m in MOSAS}
        x2_resid[name] = _band_asd(x2(left), dt, bins)
    gain = michelson_transfer(bins / (n * dt), d)[:, 0, :]
    jv = band_variance(jit, band) + man_var
    return SixLinkSimulation(
        injected=b, fits=fits, predicted_attenuation=predicted_attenuation(jv, np.full(12, band_variance(dws, band))),
        ttl_asd={m: _band_asd(ttl_true[m][cut], dt, bins) for m in MOSAS}, residual_ttl_asd=resid,
        x2_ttl_asd=_band_asd(x2(ttl_true), dt, bins), x2_residual_asd=x2_resid,
        x2_gain_rms=math.sqrt(float(np.mean(np.sum(np.abs(gain) ** 2, axis=1)))))
