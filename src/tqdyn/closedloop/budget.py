"""Frequency-domain evaluation: noise budgets, closed-loop transfer functions, loop gains and margins.

The ASD of output o from source s (components j, uncorrelated, summed in power; one-sided):

    ASD_{o,s}(f) = sqrt( sum_j |G_{o,j}(i 2 pi f)|^2 ASD_s(f)^2 ),

G the closed loop (python-control ``frequency_response``).  The total of an output is the power sum
over the sources.  Loop-at-a-time gains: breaking channel k at its controller output with every
other loop closed, L_k = -T_kk / (1 + T_kk) (T_kk the closed-loop transfer from the loop-break
input ``d`` to the controller output ``c`` of channel k); margins by python-control
``stability_margins`` on L_k's frequency response (an FRD on a dense grid).  Units: Hz, ASDs in
(output unit)/Hz^1/2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from .controllers import LOOPS
from .loop import SOURCES, ClosedLoop, output_names, source_inputs

__all__ = ["DesignError", "LoopMargins", "check_stable", "closed_loop_response", "loop_gains", "loop_margins",
           "noise_budget", "dominant_sources"]


class DesignError(ValueError):
    """An unstable closed loop: one line naming the loop and its margins (attribute ``field``)."""

    def __init__(self, field_name: str, message: str):
        self.field = field_name
        super().__init__(f"{field_name}: {message}")


def closed_loop_response(cl: ClosedLoop, f, outputs=None, inputs=None, dt: float | None = None) -> np.ndarray:
    """Complex closed-loop transfer functions G (n_out, n_in, n_f) at ``f`` [Hz] between the named
    ``outputs`` (default all of :func:`~tqdyn.closedloop.loop.output_names`) and ``inputs`` (default all
    noise inputs); ``dt`` [s]: of the zero-order-hold discretisation instead (what the time domain runs)."""
    sys = cl.system
    outputs = output_names() if outputs is None else list(outputs)
    inputs = [s for src in SOURCES for s in source_inputs(src)] if inputs is None else list(inputs)
    oi = [sys.output_labels.index(o) for o in outputs]
    ii = [sys.input_labels.index(i) for i in inputs]
    sub = control.ss(sys.A, sys.B[:, ii], sys.C[oi, :], sys.D[np.ix_(oi, ii)])
    if dt is not None:
        sub = control.c2d(sub, dt, method="zoh")
    w = 2 * math.pi * np.asarray(f, dtype=np.float64)
    resp = control.frequency_response(sub, w)
    return np.asarray(resp.complex).reshape(len(oi), len(ii), len(w))


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
    T = np.asarray(control.frequency_response(sub, w).complex).reshape(len(oi), len(ii), len(w))
    Tkk = np.array([T[k, k] for k in range(len(oi))])
    return list(cl.channel_names), -Tkk / (1.0 + Tkk)


def loop_margins(cl: ClosedLoop, f_min: float = 1e-6, f_max: float = 10.0, n: int = 1500) -> list[LoopMargins]:
    """:class:`LoopMargins` of every controller channel (module docstring); the loop gains
    (:func:`loop_gains`) on ``n`` log-spaced points in [f_min, f_max] Hz."""
    f = np.logspace(math.log10(f_min), math.log10(f_max), n)
    w = 2 * math.pi * f
    chans, L = loop_gains(cl, f)
    out = []
    for k, ch in enumerate(chans):
        gm, pm, _sm, wg, wp, _ws = control.stability_margins(control.frd(L[k], w))
        out.append(LoopMargins(ch, float(gm), float(pm), float(wg) / (2 * math.pi), float(wp) / (2 * math.pi)))
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
                      f"the closed loop is unstable (pole at Re = {np.max(ev.real):.3g} 1/s; channel {worst.channel}: "
                      f"phase margin {worst.phase_margin:.3g} deg, gain margin {worst.gain_margin:.3g}); "
                      "allowed: a stabilising design (docs/closed-loop.md)")


_ = LOOPS
