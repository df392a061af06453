"""Frequency-domain evaluation: noise budgets, closed-loop transfer functions, loop gains and margins.

The ASD of output o from source s (components j, uncorrelated, summed in power; one-sided):

    ASD_{o,s}(f) = sqrt( sum_j |G_{o,j}(i 2 pi f)|^2 ASD_s(f)^2 ),

G the closed loop (:func:`frequency_response`: C (x I - A)^-1 B + D by one LU solve per frequency, as
python-control's ``frequency_response`` without slycot, batched over the frequencies).  The total of an output is the power sum
over the sources.  Loop-at-a-time gains: breaking channel k at its controller output with every
other loop closed, L_k = -T_kk / (1 + T_kk) (T_kk the closed-loop transfer from the loop-break
input ``d`` to the controller output ``c`` of channel k); margins by python-control
``stability_margins`` on L_k's frequency response (an FRD on a dense grid); by default only on a
window of grid points around each crossover (:func:`loop_margins`).  Units: Hz, ASDs in
(output unit)/Hz^1/2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from .loop import SOURCES, ClosedLoop, output_names, source_inputs

__all__ = ["DesignError", "LoopMargins", "check_stable", "closed_loop_response", "frequency_response", "grid_margins", "loop_gains",
           "loop_margins", "noise_budget", "dominant_sources"]

#: Frequencies per batched solve of :func:`frequency_response` (bounds the memory: n_f x n_state^2 complex).
_BATCH = 128
#: Grid points on each side of a crossover in the windows of :func:`loop_margins` (the interpolating cubic
#: spline of python-control's FRD forgets a far data point by a factor 2 - sqrt(3) = 0.27 per point:
#: 0.27^16 = 1e-9 of the local interpolation error).
_MARGIN_HALF_WINDOW = 16


class DesignError(ValueError):
    """An unstable closed loop: one line naming the loop and its margins (attribute ``field``)."""

    def __init__(self, field_name: str, message: str):
        self.field = field_name
        super().__init__(f"{field_name}: {message}")


def frequency_response(sys: control.StateSpace, w) -> np.ndarray:
    """Complex frequency response (n_out, n_in, n_f) of the state-space ``sys`` at angular frequencies
    ``w`` [rad/s]: C (x I - A)^-1 B + D with x = i w (continuous) or exp(i w dt) (discrete), one LU
    solve per frequency (LAPACK gesv, as python-control's ``frequency_response`` without slycot) batched
    over the frequencies.  Falls back to python-control at a pole (a singular x I - A)."""
    w = np.asarray(w, dtype=np.float64)
    A, B, C, D = (np.asarray(m, dtype=np.float64) for m in (sys.A, sys.B, sys.C, sys.D))
    x = np.exp(1j * w * sys.dt) if sys.isdtime(strict=True) else 1j * w
    n = A.shape[0]
    out = np.empty((C.shape[0], B.shape[1], len(w)), dtype=complex)
    if n == 0:
        out[:] = D[:, :, None]
        return out
    Bc, Cc, r = B.astype(complex), C.astype(complex), np.arange(n)
    try:
        for a in range(0, len(w), _BATCH):
            xs = x[a:a + _BATCH]
            M = np.broadcast_to(-A, (len(xs), n, n)).astype(complex)                  # x I - A: (nb, n, n)
            M[:, r, r] += xs[:, None]
            X = np.linalg.solve(M, np.broadcast_to(Bc, (len(xs),) + B.shape))         # (nb, n, m)
            Y = Cc @ np.ascontiguousarray(np.moveaxis(X, 0, 1)).reshape(n, -1)       # one product: (p, nb m)
            out[:, :, a:a + _BATCH] = np.moveaxis(Y.reshape(C.shape[0], len(xs), -1), 1, 2) + D[:, :, None]
    except np.linalg.LinAlgError:
        return np.asarray(control.frequency_response(sys, w).complex).reshape(out.shape)
    return out


def closed_loop_response(cl: ClosedLoop, f, outputs=None, inputs=None, dt: float | None = None) -> np.ndarray:
    """Complex closed-loop transfer functions G (n_out, n_in, n_f) at ``f`` [Hz] between the named
    ``outputs`` (default all of :func:`~tqdyn.closedloop.loop.output_names`) and ``inputs`` (default all
    noise inputs); ``dt`` [s]: of the zero-order-hold discretisation instead (a sampled loop on held noise; the time
    series realise the continuous loop: :mod:`tqdyn.closedloop.synthesis`)."""
    sys = cl.system
    outputs = output_names() if outputs is None else list(outputs)
    inputs = [s for src in SOURCES for s in source_inputs(src)] if inputs is None else list(inputs)
    oi = [sys.output_labels.index(o) for o in outputs]
    ii = [sys.input_labels.index(i) for i in inputs]
    sub = control.ss(sys.A, sys.B[:, ii], sys.C[oi, :], sys.D[np.ix_(oi, ii)])
    if dt is not None:
        sub = control.c2d(sub, dt, method="zoh")
    return frequency_response(sub, 2 * math.pi * np.asarray(f, dtype=np.float64))


def noise_budget(cl: ClosedLoop, noise: dict, f, outputs=None, dt: float | None = None) -> tuple[np.ndarray, list]:
    """ASD (n_out, n_source, n_f) of every output from every source (module docstring), and the source
    names.  ``noise``: {source: AsdModel}; ``dt``: the discretised loop's (see :func:`closed_loop_response`)
    with the sources' ASDs unchanged."""
    f = np.asarray(f, dtype=np.float64)
    sources = [s for s in SOURCES if s in noise]
    G = closed_loop_response(cl, f, outputs, [x for s in sources for x in source_inputs(s)], dt)
    out = np.zeros((G.shape[0], len(sources), len(f)))
    k = 0
    for j, s in enumerate(sources):
        n = SOURCES[s][0]
        asd = noise[s].asd(f)
        out[:, j, :] = np.sqrt(np.sum(np.abs(G[:, k:k + n, :]) ** 2, axis=1)) * asd[None, :]
        k += n
    return out, sources


def dominant_sources(budget: np.ndarray, sources: list, f, bands) -> list[list[str]]:
    """For each output (row of ``budget`` (n_out, n_source, n_f)) and band (f_lo, f_hi) [Hz], the
    source with the largest mean power in the band."""
    f = np.asarray(f)
    out = []
    for row in budget:
        r = []
        for lo, hi in bands:
            m = (f >= lo) & (f <= hi)
            r.append(sources[int(np.argmax(np.mean(row[:, m] ** 2, axis=1)))] if np.any(m) else "")
        out.append(r)
    return out


@dataclass(frozen=True)
class LoopMargins:
    """Margins of one channel's loop-at-a-time gain: gain margin (factor; inf if none), phase margin
    [deg], their frequencies [Hz], and the unity-gain crossover [Hz] (nan if none)."""

    channel: str
    gain_margin: float
    phase_margin: float
    f_gain_margin: float
    f_phase_margin: float


def loop_gains(cl: ClosedLoop, f) -> tuple[list[str], np.ndarray]:
    """Loop-at-a-time gains L_k = -T_kk / (1 + T_kk) (module docstring) of every controller channel at
    ``f`` [Hz] (one MIMO frequency response d -> c): (channel names, complex L (n_channel, n_f))."""
    sys = cl.system
    w = 2 * math.pi * np.asarray(f, dtype=np.float64)
    ii = [sys.input_labels.index(f"d_{ch}") for ch in cl.channel_names]
    oi = [sys.output_labels.index(f"c_{ch}") for ch in cl.channel_names]
    sub = control.ss(sys.A, sys.B[:, ii], sys.C[oi, :], sys.D[np.ix_(oi, ii)])
    T = frequency_response(sub, w)
    Tkk = np.array([T[k, k] for k in range(len(oi))])
    return list(cl.channel_names), -Tkk / (1.0 + Tkk)


def _crossover_windows(L: np.ndarray, half: int) -> list[tuple[int, int]]:
    """Index ranges [lo, hi) of ``L`` (n,) holding every grid interval in which python-control's
    ``stability_margins`` looks for a crossover (|L| - 1 or arg(-L) changes sign, the latter with
    Re L <= 0 at its left end), ``half`` points on each side; crossovers closer than 2 half + 2 points
    share a window, so that no two windows overlap."""
    ip = np.where(np.diff(np.sign(np.angle(-L))))[0]
    idx = np.union1d(ip[L[ip].real <= 0], np.where(np.diff(np.sign(np.abs(L) - 1.0)))[0])
    out = []
    for i in idx:
        if out and i - out[-1][1] <= 2 * half + 2:
            out[-1][1] = i
        else:
            out.append([i, i])
    return [(max(0, a - half), min(len(L), b + half + 2)) for a, b in out]


def _margins(L: np.ndarray, w: np.ndarray, method: str) -> tuple[float, float, float, float]:
    """(gain margin, phase margin [deg], phase-crossover and gain-crossover angular frequencies [rad/s])
    of the FRD (``L`` (n,), ``w`` (n,) [rad/s]) as python-control's ``stability_margins`` returns them;
    ``method`` "window": its crossovers found on small FRD windows (:func:`_crossover_windows`), the
    margins then chosen as it chooses them over the whole grid (the gain margin closest to 1 in dB,
    the phase margin smallest in magnitude, the first of equals)."""
    if method == "full":
        gm, pm, _sm, wg, wp, _ws = control.stability_margins(control.frd(L, w))
        return float(gm), float(pm), float(wg), float(wp)
    gms, pms, w180, wc = [np.zeros(0)], [np.zeros(0)], [np.zeros(0)], [np.zeros(0)]
    for lo, hi in _crossover_windows(L, _MARGIN_HALF_WINDOW):
        gm, pm, _sm, wg, wp, _ws = control.stability_margins(control.frd(L[lo:hi], w[lo:hi]), returnall=True)
        gms.append(np.asarray(gm, dtype=np.float64))
        pms.append(np.asarray(pm, dtype=np.float64))
        w180.append(np.asarray(wg, dtype=np.float64))
        wc.append(np.asarray(wp, dtype=np.float64))
    gms, pms, w180, wc = (np.concatenate(v) for v in (gms, pms, w180, wc))
    gm, wg, pm, wp = math.inf, math.nan, math.inf, math.nan
    if gms.size and not np.isinf(gms).all():
        with np.errstate(all="ignore"):
            k = int(np.argmin(np.abs(np.log(gms))))
        gm, wg = float(gms[k]), float(w180[k])
    if pms.size:
        k = int(np.argmin(np.abs(pms)))
        pm, wp = float(pms[k]), float(wc[k])
    return gm, pm, wg, wp


def loop_margins(cl: ClosedLoop, f_min: float = 1e-6, f_max: float = 10.0, n: int = 1500,
                 method: str = "window") -> list[LoopMargins]:
    """:class:`LoopMargins` of every controller channel (module docstring); the loop gains
    (:func:`loop_gains`) on ``n`` log-spaced points in [f_min, f_max] Hz.  ``method``: "window"
    (python-control's ``stability_margins`` on a few dozen grid points around each crossover, the
    margins chosen among them as it chooses them) or "full" (``stability_margins`` on the whole grid:
    the same crossovers and margins, ~20x slower)."""
    if method not in ("window", "full"):
        raise ValueError(f"method: {method!r} is not a margin method; allowed: 'window', 'full'")
    f = np.logspace(math.log10(f_min), math.log10(f_max), n)
    w = 2 * math.pi * f
    chans, L = loop_gains(cl, f)
    out = []
    for k, ch in enumerate(chans):
        gm, pm, wg, wp = _margins(L[k], w, method)
        out.append(LoopMargins(ch, gm, pm, wg / (2 * math.pi), wp / (2 * math.pi)))
    return out


def check_stable(cl: ClosedLoop, tol: float = 1e-9) -> None:
    """DesignError (one line naming the loop and its margins) when a closed-loop pole has Re > 0,
    leaving out the spacecraft's displacement from its orbit (free and Hill modes of the ``u`` states,
    which no loop controls).  The loop named is the one with the smallest phase margin."""
    sys = cl.system
    keep = [k for k, s in enumerate(sys.state_labels) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
    A = sys.A[np.ix_(keep, keep)]
    ev = np.linalg.eigvals(A)
    scale = max(1.0, float(np.max(np.abs(ev))))
    if np.max(ev.real) <= tol * scale:
        return
    ms = loop_margins(cl)
    worst = min(ms, key=lambda m: (m.phase_margin if math.isfinite(m.phase_margin) else -1e9))
    loop = worst.channel.split("[")[0]
    raise DesignError(f"closed_loop.controllers.{loop}",
                      f"the closed loop is unstable (pole Re = {np.max(ev.real):.3g} 1/s; {worst.channel}: "
                      f"phase margin {worst.phase_margin:.3g} deg" + (f", gain margin {worst.gain_margin:.3g}"
                                                                      if math.isfinite(worst.gain_margin) else "")
                      + "); allowed: a stabilising design (docs/closed-loop.md)")


def _first_min_per_row(rows, key, n_rows):
    """For each row r < ``n_rows``: the position (into ``rows``/``key``) of the smallest key, the first of equals
    (-1 for a row without entries)."""
    out = np.full(n_rows, -1)
    if len(rows):
        order = np.lexsort((np.arange(len(rows)), key, rows))
        first = np.r_[True, rows[order][1:] != rows[order][:-1]]
        out[rows[order][first]] = order[first]
    return out


def grid_margins(L, f) -> dict:
    """Margins of loop gains ``L`` (..., n) given on the increasing grid ``f`` (n,) [Hz], for every leading index
    at once, with python-control's ``stability_margins`` conventions (FRD: a phase crossover where arg(-L) changes
    sign with Re L <= 0 at the interval's left end; a gain crossover where |L| - 1 changes sign), each crossover
    located by linear interpolation in log f of arg(-L) (resp. log|L|), the gain |L| and phase there likewise.
    Returns arrays of shape L.shape[:-1]: ``gain_margin`` (the one closest to 1 in dB, python-control's choice;
    inf: none) and ``f_gain_margin`` [Hz]; ``gain_margin_lower`` (the largest margin below 1: the gain may fall
    by that factor; 0: none) and ``gain_margin_upper`` (the smallest above 1; inf: none), the gain interval
    around 1 in which the loop stays stable; ``phase_margin`` [deg] (smallest in magnitude; inf: none) and
    ``crossover`` [Hz] (nan: none)."""
    L = np.asarray(L)
    shape = L.shape[:-1]
    L2 = L.reshape(-1, L.shape[-1])
    R = L2.shape[0]
    x = np.log(np.asarray(f, dtype=np.float64))
    ang = np.angle(-L2)
    lmag = np.log(np.abs(L2))
    out = {}
    # phase crossovers
    r, i = np.nonzero((np.diff(np.sign(ang), axis=1) != 0) & (L2[:, :-1].real <= 0))
    t = ang[r, i] / (ang[r, i] - ang[r, i + 1])
    x180 = x[i] + t * (x[i + 1] - x[i])
    gm = np.exp(-(lmag[r, i] + t * (lmag[r, i + 1] - lmag[r, i])))
    with np.errstate(divide="ignore"):
        k = _first_min_per_row(r, np.abs(np.log(gm)), R)
    gm_, x180_ = np.r_[gm, math.inf], np.r_[x180, math.nan]     # index -1: none
    out["gain_margin"] = gm_[k]
    out["f_gain_margin"] = np.exp(x180_[k])
    low = np.zeros(R)
    up = np.full(R, math.inf)
    np.maximum.at(low, r[gm < 1], gm[gm < 1])
    np.minimum.at(up, r[gm > 1], gm[gm > 1])
    out["gain_margin_lower"], out["gain_margin_upper"] = low, up
    # gain crossovers
    r, i = np.nonzero(np.diff(np.sign(lmag), axis=1) != 0)
    t = lmag[r, i] / (lmag[r, i] - lmag[r, i + 1])
    xc = x[i] + t * (x[i + 1] - x[i])
    ph0 = np.angle(L2[r, i])
    dph = np.angle(L2[r, i + 1] / L2[r, i])                     # the phase step, unwrapped
    pm = np.remainder(np.degrees(ph0 + t * dph), 360.0) - 180.0
    k = _first_min_per_row(r, np.abs(pm), R)
    out["phase_margin"] = np.r_[pm, math.inf][k]
    out["crossover"] = np.exp(np.r_[xc, math.nan][k])
    return {key: v.reshape(shape) for key, v in out.items()}
