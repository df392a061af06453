"""The sampled series of the closed loop: a band-limited realisation of the continuous noise budget.

What a series is.  The budget (:func:`tqdyn.closedloop.budget.noise_budget`) is the continuous closed
loop's one-sided PSD S_o(f) = sum_j |G_oj(i 2 pi f)|^2 ASD_j(f)^2 (G the loop, j the noise
components).  A series sampled at fs is the sampled realisation of that process **band-limited to the
Nyquist frequency** (an ideal anti-alias filter): its one-sided PSD is S_o(f) for 0 < f < fs/2, its
variance int_0^{fs/2} S_o(f) df, and the cross-spectrum of two outputs o, o' is the budget's,
sum_j G_oj G_o'j^* ASD_j^2.  The samples of the unfiltered continuous process are not a definition: a
white source that reaches an output directly (a thrust, a TM force) or a rising one (LISA's TM force
noise, ASD ~ f^2 above 8 mHz) has infinite variance, and what it has above fs/2 would alias.

How (docs/closed-loop.md, "Time series").  Each noise component j of source s is the sum of two
independent parts made with power-complementary Butterworth filters at f_c = fs / :data:`SPLIT_DIVISOR`,
|L(f)|^2 = 1 / (1 + (f/f_c)^(2n)), |H(f)|^2 = 1 - |L(f)|^2, n = :func:`split_order` (>= 4 and 2 more
than the source's summed log-log slopes, so that each part falls off beyond its band).  The two parts
add in power: |L|^2 S + |H|^2 S = S.

* Low band (:class:`LowBand`): white noise through the rational shaping filter of the source
  (:meth:`~tqdyn.closedloop.noise.AsdModel.shaping_zpk`) times L(s) drives the loop, shaping filters
  and loop discretised alike by the bilinear transform: the band's response is the continuous one at
  the warped frequency (fs/pi) tan(pi f/fs), a relative frequency error (pi f/fs)^2/3 (2e-4 at f_c);
  beyond f_c the band carries |L|^2 <= (f_c/f)^8 of the power.
* High band (:class:`HighBand`): for each output o and component j, an FIR filter whose DTFT is the
  continuous G_oj(i 2 pi f) level_j R_j(i 2 pi f) H(i 2 pi f) (R the same shaping filter, H the
  Butterworth high-pass) on an n_fir-point grid, centred and applied by FFT overlap-save to white
  noise through a fixed discrete high-pass Q (:func:`high_pass_ba`, divided out of the filters'
  target; it keeps their interpolation error away from f = 0; each filter's DTFT is made to vanish with
  its slope at f = 0, :func:`_double_zero`, as the target does).  n_fir doubles from :data:`FIR_MIN`
  until the filters' DTFT between the grid points is within :data:`FIR_TOL` of the target (for each
  source separately: a source's filters do not depend on the others).  The band needs no long memory:
  H removes the loop's slow modes (LISA Pathfinder's guidance loop, its crossover some uHz, decades below
  f_c at any rate of a series, is the low band's), so one split serves every mission.  In the top
  :data:`NYQUIST_BAND` of the band each transfer's phase turns to the nearest real value at fs/2 (a real
  series has a real response there), which leaves the ASDs exact and changes cross-spectra only there.

Both bands run the loop without the states that no source of nonzero level reaches
(:func:`reduced_system`): an output the budget gives 0 is exactly 0.

The rational shaping filters are exact for knees with an even 2 s (Butterworth) and within
:func:`~tqdyn.closedloop.noise.shaping_error` (<= 0.5 %) of the ASD model for the fitted ladders.

:func:`series_psd` computes the one-sided PSD that the two bands realise, exactly (the low band's
discrete transfer functions, the high band's FIR filters); ``tests/test_closed_loop_series.py``
compares it with the continuous budget and the Welch estimates of series with both.

Units: f [Hz], fs [Hz], dt [s]; PSDs one-sided in (output unit)^2/Hz.
"""

from __future__ import annotations

import math

import control
import numpy as np
from scipy import fft as sfft
from scipy import linalg, signal

from .noise import AsdModel, _butterworth_roots

__all__ = ["FIR_MAX", "FIR_MIN", "FIR_TOL", "NYQUIST_BAND", "SPLIT_DIVISOR", "HighBand", "LowBand", "crossover",
           "high_pass_ba", "low_band_sos", "reduced_system", "series_psd", "split_order"]

#: The bands' crossover f_c = fs / SPLIT_DIVISOR: the low band's discretisation errors scale as (f_c/fs)^2.
SPLIT_DIVISOR = 128
#: Shortest and longest high-band FIR filters [samples]; the fixed delay of the high band is FIR_MAX // 2.
FIR_MIN, FIR_MAX = 256, 2 ** 14
#: Largest relative amplitude error of the high band's FIR filters between their grid points.
FIR_TOL = 2e-3
#: Where a source's contribution to an output is below FIR_DYNAMIC of its largest value (in power), the FIR
#: filters' error is measured against FIR_DYNAMIC times that largest value.
FIR_DYNAMIC = 1e-4
#: Fraction of an FIR window tapered (Tukey: raised-cosine edges), so that the filters' truncation stays
#: near the frequencies of the truncated tails instead of spreading over the band.
FIR_TAPER = 0.25
#: The top fraction of the band (below fs/2) in which each high-band transfer turns to a real value at fs/2.
NYQUIST_BAND = 0.05
#: Largest relative reconstruction error of a modal decomposition before the direct forms are used.
MODAL_TOLERANCE = 1e-9
#: Frames of the overlap-save per batch (bounds the memory of a block: frames x n_fir x components).
_FRAMES_PER_BATCH = 16


def crossover(fs: float) -> float:
    """The bands' crossover frequency f_c [Hz] at the sample rate ``fs`` [Hz]."""
    return fs / SPLIT_DIVISOR


def split_order(model: AsdModel) -> int:
    """Order n of the band-splitting Butterworth pair of a source: 4, or 2 more than the larger of the
    summed rising (s > 0) and summed falling (|s|, s < 0) slopes of its knees."""
    pos = sum(s for _f, s in model.knees if s > 0)
    neg = -sum(s for _f, s in model.knees if s < 0)
    return max(4, int(math.ceil(max(pos, neg))) + 2)


def _shaping(model: AsdModel, fs: float, f_lo: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(zeros, poles, gain) [rad/s] of the source's rational shaping filter (unit level) used by both bands:
    :meth:`~tqdyn.closedloop.noise.AsdModel.shaping_zpk` over [f_lo, 10 fs] (a rising knee's roll-off poles
    at 300 fs: 1e-6 of the ASD at fs/2)."""
    if not model.knees:
        return np.zeros(0, dtype=complex), np.zeros(0, dtype=complex), 1.0
    z, p, k = model.shaping_zpk(f_lo, 10.0 * fs)
    return np.asarray(z, dtype=complex), np.asarray(p, dtype=complex), float(k)


def _zpk_at(z, p, k, f) -> np.ndarray:
    """k prod(s - z) / prod(s - p) at s = i 2 pi f (f [Hz], any shape (n,))."""
    s = 2j * math.pi * np.asarray(f, dtype=np.float64)
    return k * np.prod(s[:, None] - z[None, :], axis=1) / np.prod(s[:, None] - p[None, :], axis=1)


class _HighGain:
    """The high band's input filter of a source: level R(s) H(s) at s = i 2 pi f (f [Hz]) with R the
    shaping filter (:func:`_shaping`) and H(s) = s^n / prod(s - w_c b_k) the Butterworth high-pass
    (|H|^2 = 1 - |L|^2); :meth:`share`: |H(f)|."""

    def __init__(self, model: AsdModel, fs: float, f_lo: float):
        self.level, self.fc, self.n = model.level, crossover(fs), split_order(model)
        z, p, k = _shaping(model, fs, f_lo)
        self.z = np.concatenate([z, np.zeros(self.n, dtype=complex)])
        self.p = np.concatenate([p, _butterworth_roots(self.n) * 2 * math.pi * self.fc])
        self.k = k * model.level

    def share(self, f) -> np.ndarray:
        f = np.asarray(f, dtype=np.float64)
        out = np.zeros(f.shape)
        pos = f > 0
        with np.errstate(over="ignore"):
            out[pos] = 1.0 / np.sqrt(1.0 + (self.fc / f[pos]) ** (2 * self.n))
        return out

    def __call__(self, f) -> np.ndarray:
        return _zpk_at(self.z, self.p, self.k, f)


def low_band_sos(model: AsdModel, fs: float, f_lo: float) -> np.ndarray:
    """Second-order sections of the low band's discrete shaping filter of a source (unit level): the
    rational shaping filter (:func:`_shaping`) times the Butterworth low-pass L of :func:`split_order` at
    :func:`crossover`, bilinear transform (exact as f -> 0; relative frequency error (pi f/fs)^2/3)."""
    n = split_order(model)
    wc = 2 * math.pi * crossover(fs)
    z, p, k = _shaping(model, fs, f_lo)
    p = np.concatenate([p, _butterworth_roots(n) * wc])
    zd, pd, kd = signal.bilinear_zpk(z, p, k * wc ** n, fs)
    return signal.zpk2sos(zd, pd, kd)


def reduced_system(cl, outputs: list, noise: dict | None = None) -> control.StateSpace:
    """The continuous closed loop ``cl`` (:class:`~tqdyn.closedloop.loop.ClosedLoop`) restricted to the noise
    inputs (``cl.source_components()`` order) and the named ``outputs``, without the states that no input
    reaches: the spacecraft's orbit displacement (nothing feeds back from it) and, with ``noise`` ({source:
    AsdModel}), every state outside the structural reach (the nonzero pattern of A and B) of the sources of
    nonzero level (a single-spacecraft loop's idle MOSA or second test mass: its outputs are then exactly 0,
    as the budget's, not the round-off of a modal form that mixes them with driven modes)."""
    sys = cl.system
    keep = [k for k, s in enumerate(sys.state_labels) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
    ii = [sys.input_labels.index(f"{src}[{k}]") for src, n in cl.source_components().items() for k in range(n)]
    oi = [sys.output_labels.index(o) for o in outputs]
    A, B = sys.A[np.ix_(keep, keep)], sys.B[np.ix_(keep, ii)]
    if noise is not None:
        on = np.array([noise.get(src) is not None and noise[src].level > 0
                       for src, n in cl.source_components().items() for _k in range(n)], dtype=bool)
        reach = np.any(B[:, on] != 0, axis=1)
        while True:                                   # states driven by a reached state
            more = reach | np.any(A[:, reach] != 0, axis=1)
            if np.array_equal(more, reach):
                break
            reach = more
        keep = [k for k, r in zip(keep, reach) if r]
        A, B = sys.A[np.ix_(keep, keep)], sys.B[np.ix_(keep, ii)]
    return control.ss(A, B, sys.C[np.ix_(oi, keep)], sys.D[np.ix_(oi, ii)],
                      states=[sys.state_labels[k] for k in keep])


def _modal(A: np.ndarray):
    """(eigenvalues, V, V^-1) of ``A`` when V diag(lam) V^-1 reproduces it to :data:`MODAL_TOLERANCE`, else None."""
    lam, V = np.linalg.eig(A)
    try:
        Vi = np.linalg.inv(V)
    except np.linalg.LinAlgError:
        return None
    err = np.linalg.norm(V @ np.diag(lam) @ Vi - A) / max(np.linalg.norm(A), 1e-300)
    return (lam, V, Vi) if err < MODAL_TOLERANCE else None


class _Transfer:
    """G(i 2 pi f) of a continuous state-space system by its modes: sum_i (C v_i)(w_i B) / (i w - lam_i) + D,
    one matrix product over the frequencies (one LU solve per frequency when A is not diagonalisable).
    With ``bound``: also sum_i |C v_i| |w_i B| / |i w - lam_i| + |D| (|C| |(i w - A)^-1 B| + |D| without
    modes), the scale of the rounding error of G (an entry below ~1e-10 of it is zero in exact arithmetic)."""

    def __init__(self, sys: control.StateSpace):
        self.A, self.B, self.C, self.D = (np.asarray(x, dtype=np.float64) for x in (sys.A, sys.B, sys.C, sys.D))
        self.modes = _modal(self.A) if self.A.size else None

    def __call__(self, f: np.ndarray, cols, bound: bool = False):
        """Complex G (n_out, len(cols), n_f) at ``f`` [Hz] for the input columns ``cols`` (and the bound)."""
        w = 2 * math.pi * np.asarray(f, dtype=np.float64)
        B, D = self.B[:, cols], self.D[:, cols]
        n_out, n = self.C.shape
        if n == 0:
            G = np.broadcast_to(D[:, :, None], D.shape + (len(w),)).astype(complex)
            return (G, np.abs(G)) if bound else G
        if self.modes is None:
            M = np.broadcast_to(-self.A, (len(w), n, n)).astype(complex)
            M[:, np.arange(n), np.arange(n)] += 1j * w[:, None]
            X = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (len(w),) + B.shape))   # (n_f, n, n_col)
            G = np.moveaxis(self.C @ X, 0, -1) + D[:, :, None]
            return (G, np.moveaxis(np.abs(self.C) @ np.abs(X), 0, -1) + np.abs(D)[:, :, None]) if bound else G
        lam, V, Vi = self.modes
        CV, VB = self.C @ V, Vi @ B
        W = 1.0 / (1j * w[:, None] - lam[None, :])                          # (n_f, n_mode)

        def modal_sum(W, CV, VB):
            R = np.ascontiguousarray(np.moveaxis(CV[:, :, None] * VB[None, :, :], 1, 0)).reshape(len(lam), -1)
            return np.moveaxis((W @ R).reshape(len(w), n_out, len(cols)), 0, -1)

        G = modal_sum(W, CV, VB) + D[:, :, None]
        return (G, modal_sum(np.abs(W), np.abs(CV), np.abs(VB)).real + np.abs(D)[:, :, None]) if bound else G


class LowBand:
    """The loop discretised with the bilinear (Tustin) transform at dt [s]: A = M^-1 (I + A_c dt/2),
    B = M^-1 B_c dt, C = C_c M^-1, D = D_c + C_c M^-1 B_c dt/2 with M = I - A_c dt/2.  Its response is
    the continuous one at the warped frequency (fs/pi) tan(pi f/fs), for every path alike (a first-order
    hold would leave the direct feedthrough exact and the dynamic paths attenuated by sinc^2(f/fs): in an
    in-loop output where the two cancel, e.g. a thrust following a sensor noise, that error is magnified
    by the cancellation).  The state xd relates to the continuous one by x = M^-1 (xd + B_c u dt/2)
    (:meth:`physical`, :meth:`state`).  Run in modal form (each mode a first-order recursion) when the
    eigen-decomposition of A is good."""

    def __init__(self, sys: control.StateSpace, dt: float):
        A, B, C, D = (np.asarray(x, dtype=np.float64) for x in (sys.A, sys.B, sys.C, sys.D))
        n = A.shape[0]
        M = np.eye(n) - 0.5 * dt * A
        self.lu = linalg.lu_factor(M) if n else None
        Mi = linalg.lu_solve(self.lu, np.eye(n)) if n else np.zeros((0, 0))
        self.M, self.hB = M, 0.5 * dt * B
        self.A, self.B = Mi @ (np.eye(n) + 0.5 * dt * A), Mi @ B * dt
        self.C, self.D = C @ Mi, D + C @ Mi @ self.hB
        self.dt, self.states = dt, list(sys.state_labels)
        modes = _modal(self.A) if n else None
        self.modal = modes is not None
        if self.modal:                            # one mode of each complex-conjugate pair, weight 2
            lam, V, Vi = modes
            keep = lam.imag >= 0
            self.lam, self.V, self.Vi = lam[keep], V[:, keep], Vi[keep]
            self.w = np.where(self.lam.imag > 0, 2.0, 1.0)
            Bm, Cm = self.Vi @ self.B, self.C @ self.V * self.w
            self.Bre, self.Bim, self.Cre, self.Cim = Bm.real.copy(), Bm.imag.copy(), Cm.real.copy(), Cm.imag.copy()

    def physical(self, xd: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The continuous state x from the discrete state xd and the input u at the same sample."""
        return linalg.lu_solve(self.lu, xd + self.hB @ u) if self.lu is not None else xd

    def state(self, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The discrete state xd of the continuous state x and the input u at the same sample."""
        return self.M @ x - self.hB @ u

    def carried(self, prev: LowBand, xd: np.ndarray, u: np.ndarray) -> np.ndarray:
        """This band's discrete state at the first sample of its segment from ``prev``'s discrete state ``xd``
        at that sample (u the input there): the continuous state carried by state name (a state that
        ``prev`` does not have starts at 0)."""
        x = dict(zip(prev.states, prev.physical(xd, u)))
        return self.state(np.array([x.get(s, 0.0) for s in self.states]), u)

    def system(self) -> control.StateSpace:
        """The discrete system (sample time dt) u -> y."""
        return control.ss(self.A, self.B, self.C, self.D, self.dt)

    def run(self, xt0: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Outputs (n_out, m) for inputs u (n_in, m) from the discrete state xt0 at the first sample; returns
        (y, the discrete state at the sample after the last)."""
        m = u.shape[1]
        if not self.modal:
            x = xt0.copy()
            y = np.empty((self.C.shape[0], m))
            for k in range(m):
                y[:, k] = self.C @ x + self.D @ u[:, k]
                x = self.A @ x + self.B @ u[:, k]
            return y, x
        v = (self.Bre @ u) + 1j * (self.Bim @ u)         # (n_modes, m): real products, u is real
        z0 = self.Vi @ xt0
        Z = np.empty_like(v)
        for i, lam in enumerate(self.lam):
            zz, _ = signal.lfilter([1.0], [1.0, -lam], v[i], zi=[lam * z0[i]])
            Z[i, 0] = z0[i]
            Z[i, 1:] = zz[:-1]
            v[i, 0] = zz[-1]                              # keep the end state
        y = self.Cre @ Z.real - self.Cim @ Z.imag + self.D @ u
        return y, ((self.V * self.w) @ v[:, 0]).real


def _nyquist_turn(f: np.ndarray, fs: float) -> np.ndarray:
    """0 below (1 - NYQUIST_BAND) fs/2, rising as sin^2 to 1 at fs/2 (f [Hz])."""
    f1 = (1.0 - NYQUIST_BAND) * 0.5 * fs
    return np.sin(0.5 * math.pi * np.clip((f - f1) / (0.5 * fs - f1), 0.0, 1.0)) ** 2


def high_pass_ba(fs: float) -> tuple[np.ndarray, np.ndarray]:
    """(b, a) of the high band's discrete pre-filter Q(z) = ((1 - z^-1) / (1 - r z^-1))^2, r = exp(-2 pi f_q / fs),
    f_q = f_c / 4: a double zero at f = 0, |Q| within 1 % of 1 above 4 f_q."""
    r = math.exp(-2 * math.pi * crossover(fs) / 4 / fs)
    return np.array([1.0, -2.0, 1.0]), np.array([1.0, -2.0 * r, r * r])


def _high_pass(f: np.ndarray, fs: float) -> np.ndarray:
    """Q(e^{i 2 pi f/fs}) of :func:`high_pass_ba` (f [Hz])."""
    b, a = high_pass_ba(fs)
    x = np.exp(-2j * math.pi * np.asarray(f, dtype=np.float64) / fs)
    return (b[0] + x * (b[1] + x * b[2])) / (a[0] + x * (a[1] + x * a[2]))


class _Source:
    """One source's part of the high-band design: its input columns, filter (:class:`_HighGain`), the phase
    psi (n_out, n_col, 1) turned off near fs/2, the rounding floor (n_out, n_col) of G."""

    def __init__(self, cols: list, gain: _HighGain, name: str):
        self.cols, self.gain, self.name = cols, gain, name
        self.psi = self.floor = self.h = self.G = None

    def target(self, f: np.ndarray, G: np.ndarray, fs: float) -> np.ndarray:
        """The FIR filters' target on ``f`` [Hz] (G: the source's columns of the loop at f):
        G gain e^{-i psi turn} / Q (0 at f = 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            q = np.where(f > 0, self.gain(f) / _high_pass(f, fs), 0.0)
        T = G * q
        top = _nyquist_turn(f, fs) > 0
        T[..., top] *= np.exp(-1j * self.psi * _nyquist_turn(f[top], fs))
        return T

    def accepts(self, h: np.ndarray, f2: np.ndarray, G2: np.ndarray, fs: float) -> bool:
        """True when the filters ``h`` (n_out, n_col, n) reproduce the target on the doubled grid ``f2`` (G2
        the loop there) within FIR_TOL (:func:`_design` says relative to what)."""
        n = h.shape[-1]
        D = sfft.rfft(h, 2 * n, axis=-1) * np.exp(1j * math.pi * f2 / fs * n)     # the delay n/2 undone
        err = np.sum(np.abs(D - self.target(f2, G2, fs)) ** 2, axis=1) * np.abs(_high_pass(f2, fs)) ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            asd = np.where(f2 > 0, np.abs(self.gain(f2)) / self.gain.share(f2), 0.0)
        ref = np.sum(np.abs(G2) ** 2 + self.floor[:, :, None], axis=1) * asd ** 2
        ref += FIR_DYNAMIC * np.max(ref, axis=1, keepdims=True)
        keep = f2 <= 0.5 * fs * (1.0 - 8.0 / n)
        return bool(np.all((err <= FIR_TOL ** 2 * ref)[:, keep]))


def _double_zero(h: np.ndarray, taper: np.ndarray) -> np.ndarray:
    """The filters ``h`` (..., n) less the combination of ``taper`` (n,) and k ``taper`` (k centred) that makes
    their DTFT vanish with its slope at f = 0 (sum h = sum k h = 0), as the target does (module docstring: a
    zero of order n_split - 2 >= 2): the truncation's error then falls as f^2 towards f = 0 instead of
    staying flat (after the pre-filter Q, as f^4 in amplitude)."""
    k = np.arange(h.shape[-1]) - h.shape[-1] // 2
    basis = np.stack([taper, k * taper])                                  # (2, n)
    moments = np.stack([np.ones_like(k, dtype=np.float64), k.astype(np.float64)])
    coef = np.linalg.solve(moments @ basis.T, np.moveaxis(h @ moments.T, -1, 0).reshape(2, -1))
    return h - (coef.T @ basis).reshape(h.shape)


def _design(tr: _Transfer, sources: list, fs: float) -> None:
    """The high band's FIR filters of every source (sets ``h`` (n_out, n_col, n_fir) of each :class:`_Source`;
    module docstring): centred, their DTFT on the n_fir-point grid is the source's target G gain
    e^{-i psi turn} / Q, so that after the pre-filter Q (:func:`high_pass_ba`) the band's transfer is
    G gain e^{-i psi turn}: Q's double zero at f = 0 keeps the filters' interpolation error out of the
    lowest frequencies; psi, the phase of G gain at fs/2 modulo pi, is turned off smoothly in the top
    NYQUIST_BAND of the band (a real series has a real response at fs/2: the periodic DTFT is then
    continuous); a Tukey taper (FIR_TAPER) keeps the truncation near the frequencies of the truncated tails.
    n_fir doubles from FIR_MIN, for each source separately, until on the doubled grid (but its last 8 cells
    below fs/2, where the kink of |G| at fs/2 is smoothed) the DTFT is within FIR_TOL of the target for every
    output, relative to the source's whole contribution sum_j |G_oj ASD_j|^2 at that frequency plus
    FIR_DYNAMIC of its largest value at that output, or to G's rounding-error scale (``_Transfer`` bound x
    1e-10).  The loop is evaluated once per grid point and source, one source's columns at a time (the doubled
    grid's even points are the old grid; the arrays held are those of one source's columns and the pending
    sources' grids)."""
    fny = np.array([0.5 * fs])
    cols = [c for src in sources for c in src.cols]
    f = np.arange(FIR_MIN // 2 + 1) * fs / FIR_MIN
    G, Gb = tr(f, cols, bound=True)
    Gny = tr(fny, cols)[..., 0]
    k = 0
    for src in sources:
        sl = slice(k, k + len(src.cols))
        k += len(src.cols)
        psi = np.angle(Gny[:, sl] * src.gain(fny)[0])
        src.psi = (psi - math.pi * np.round(psi / math.pi))[:, :, None]
        src.floor = (1e-10 * np.max(Gb[:, sl], axis=-1)) ** 2
        src.G = G[:, sl]
    pending, n = list(sources), FIR_MIN
    while pending:
        taper = signal.windows.tukey(n, FIR_TAPER, sym=False)
        f = np.arange(n // 2 + 1) * fs / n
        f2 = np.arange(n + 1) * fs / (2 * n)
        left = []
        for src in pending:                       # one source at a time: the arrays of one source's columns
            G2 = np.empty(src.G.shape[:2] + (n + 1,), dtype=complex)
            G2[..., 0::2], G2[..., 1::2] = src.G, tr(f2[1::2], src.cols)
            src.G = None
            h = _double_zero(np.roll(sfft.irfft(src.target(f, G2[..., 0::2], fs), n, axis=-1), n // 2, axis=-1)
                             * taper, taper)
            if src.accepts(h, f2, G2, fs):
                src.h, src.G = h, None
            elif 2 * n > FIR_MAX:
                raise ValueError(f"closed_loop.fs: {fs:g} Hz needs high-band filters of {src.name} longer than "
                                 f"{FIR_MAX} samples (a slowly decaying loop mode near fs/{SPLIT_DIVISOR}); "
                                 "allowed: another rate")
            else:
                src.G = G2
                left.append(src)
        pending, n = left, 2 * n


class HighBand:
    """The high band of one satellite's loop (module docstring): y_o[k] = sum_j sum_n h_oj[n] w_j[k - n - delta]
    with w_j unit white noise (one-sided PSD 1), the filters centred at n_c/2 in a common window of n_c
    samples and delta = FIR_MAX // 2 - n_c // 2 (the total delay FIR_MAX // 2 does not depend on n_c); FFT
    overlap-save with frames of about 2 n_c samples."""

    def __init__(self, sys: control.StateSpace, noise: dict, components: dict, fs: float, f_lo: float):
        tr = _Transfer(sys)
        sources, k = [], 0
        for src, n in components.items():
            model = noise.get(src)
            cols = list(range(k, k + n))
            k += n
            if model is None or model.level == 0 or not np.any(tr.B[:, cols]) and not np.any(tr.D[:, cols]):
                continue
            sources.append(_Source(cols, _HighGain(model, fs, f_lo), f"closed_loop.noise.{src}"))
        _design(tr, sources, fs)
        parts = [(src.cols, src.h) for src in sources]
        self.n_out = tr.C.shape[0]
        self.cols = [c for cols, _h in parts for c in cols]
        self.nc = max([h.shape[-1] for _c, h in parts], default=FIR_MIN)
        self.m = sfft.next_fast_len(2 * self.nc, real=True)
        self.delta = FIR_MAX // 2 - self.nc // 2
        self.Hf = np.empty((self.m // 2 + 1, self.n_out, len(self.cols)), dtype=complex)    # (F, n_out, n_col)
        for o in range(self.n_out):                      # one output at a time: no second copy of all filters
            hp = np.zeros((len(self.cols), self.nc))
            i = 0
            for cols, h in parts:
                a = (self.nc - h.shape[-1]) // 2
                hp[i:i + len(cols), a:a + h.shape[-1]] = h[o]
                i += len(cols)
            self.Hf[:, o, :] = sfft.rfft(hp, self.m, axis=-1).T

    def apply(self, buf: np.ndarray, buf0: int, k0: int, k1: int) -> np.ndarray:
        """Outputs (n_out, k1 - k0) at samples k0..k1-1 from the pre-filtered white inputs ``buf`` (n_in, L)
        holding the samples buf0..buf0+L-1 (it must reach back to k0 - delta - n_c + 1)."""
        y = np.zeros((self.n_out, k1 - k0))
        if not self.cols:
            return y
        hop = self.m - self.nc + 1
        nfr = -(-(k1 - k0) // hop)
        a = k0 - self.delta - self.nc + 1 - buf0
        need = (nfr - 1) * hop + self.m
        x = buf[self.cols, a:a + need]
        if x.shape[1] < need:
            x = np.concatenate([x, np.zeros((x.shape[0], need - x.shape[1]))], axis=1)
        frames = np.lib.stride_tricks.sliding_window_view(x, self.m, axis=1)[:, ::hop]   # (n_col, nfr, m)
        for b in range(0, nfr, _FRAMES_PER_BATCH):
            X = sfft.rfft(frames[:, b:b + _FRAMES_PER_BATCH], axis=-1)                   # (n_col, nb, F)
            Y = self.Hf @ np.ascontiguousarray(np.moveaxis(X, -1, 0))                    # (F, n_out, nb)
            out = sfft.irfft(np.moveaxis(Y, 0, -1), self.m, axis=-1)[..., self.nc - 1:]  # (n_out, nb, hop)
            j0 = b * hop
            seg = out.reshape(self.n_out, -1)[:, :max(0, min(k1 - k0 - j0, out.shape[1] * hop))]
            y[:, j0:j0 + seg.shape[1]] = seg
        return y


def series_psd(cl, noise: dict, fs: float, f, n_samples: int | None = None, f_lo: float | None = None,
               outputs=None) -> np.ndarray:
    """One-sided PSD (n_out, n_f) [(output unit)^2/Hz] at ``f`` [Hz] (0 < f <= fs/2) of the stationary series
    that :func:`tqdyn.closedloop.simulate.simulate` realises for the loop ``cl`` and the sources ``noise``
    at ``fs`` [Hz], computed exactly from its two bands: sum_j |G_d,oj(e^{i w dt})|^2 |F_j(e^{i w dt})|^2
    level_j^2 (low band: the discrete loop and shaping filters) plus sum_j |h_oj(e^{i w dt})|^2 |Q|^2 (high band:
    its FIR filters' DTFT summed directly, so that an output's PSD many decades below its largest value is
    not lost in the rounding of that value).  ``f_lo`` [Hz] as in ``simulate`` (default 0.1 fs / n_samples;
    n_samples default 2^20)."""
    f = np.asarray(f, dtype=np.float64)
    outputs = cl.time_outputs() if outputs is None else list(outputs)
    comps = cl.source_components()
    n_samples = 2 ** 20 if n_samples is None else n_samples
    f_lo = 0.1 * fs / n_samples if f_lo is None else f_lo
    sys = reduced_system(cl, outputs, noise)
    from .budget import frequency_response

    w = 2 * math.pi * f / fs
    Gd = frequency_response(LowBand(sys, 1.0 / fs).system(), w * fs)                 # (n_out, n_in, n_f)
    out = np.zeros((len(outputs), len(f)))
    k = 0
    for src, n in comps.items():
        model = noise.get(src)
        if model is not None and model.level > 0:
            _w, hf = signal.sosfreqz(low_band_sos(model, fs, f_lo), worN=w)
            out += np.sum(np.abs(Gd[:, k:k + n]) ** 2, axis=1) * (np.abs(hf) * model.level) ** 2
        k += n
    hb = HighBand(sys, noise, comps, fs, f_lo)
    if hb.cols:                  # the filters' DTFT summed directly: no cancellation of a small PSD in a large one
        h = sfft.irfft(np.moveaxis(hb.Hf, 0, -1), hb.m, axis=-1)[..., :hb.nc]          # (n_out, n_col, nc)
        E = np.exp(-1j * np.outer(np.arange(hb.nc), w))                                 # (nc, n_f)
        out += np.sum(np.abs(h @ E) ** 2, axis=1) * np.abs(_high_pass(f, fs)) ** 2
    return out
