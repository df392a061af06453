"""Time-domain evaluation: seeded realisations of the closed loops' noise budget, sampled and streamed.

A series is the sampled realisation of the continuous closed loop's output process band-limited to the
Nyquist frequency: its one-sided PSD is the budget (:func:`tqdyn.closedloop.budget.noise_budget`) for
0 < f < fs/2, its variance the budget integrated to fs/2 (:mod:`tqdyn.closedloop.synthesis` derives
it and the method; docs/closed-loop.md, "Time series").

* Noise: for each satellite and source, one ``numpy.random.SeedSequence(seed, spawn_key=(sat,
  crc32(source)))`` and its two children (0: the low band, 1: the high band): a source's realisation
  depends only on the seed, the satellite and its own name, so adding or removing a source changes no
  other (a source that reaches no output in any segment draws nothing).  Every component is white
  Gaussian noise of one-sided PSD 1 (variance fs/2), drawn time-major (the block size does not matter).  Low band: through the source's shaping filter times the band's
  low-pass (:func:`~tqdyn.closedloop.synthesis.low_band_sos`, ``scipy.signal.sosfilt``, state carried
  across blocks) times the level.  High band: through the fixed pre-filter
  (:func:`~tqdyn.closedloop.synthesis.high_pass_ba`), drawn from FIR_MAX samples before the first one
  so that the band is stationary from the start.
* Loop: the continuous closed loop of each frozen-coefficient segment, restricted to the noise
  inputs and the time-domain outputs (the spacecraft's orbit displacement ``u`` is left out: nothing
  feeds back from it; so is every state that no source of nonzero level reaches, whose outputs are
  then exactly 0).  Low band: discretised with the bilinear transform
  (:class:`~tqdyn.closedloop.synthesis.LowBand`), run in modal form (each mode a first-order
  recursion, ``scipy.signal.lfilter``; a direct recursion when the decomposition is poor), started
  at rest.  High band: FIR filters of the continuous transfer functions by FFT overlap-save
  (:class:`~tqdyn.closedloop.synthesis.HighBand`).  At a segment boundary the low band's state is carried
  in the loop's continuous coordinates, by state name, and the high band's filters change at the first
  sample of the new segment (they act on the same noise): the coefficients change piecewise in time.
* Streaming: blocks of ``block_size`` samples go to a sink (:class:`Sink`): memory is bounded by the
  block size and the filters whatever the duration.  :class:`MemorySink` keeps everything.

Units: t [s] on the run's time axis; outputs in the units of :data:`tqdyn.closedloop.loop.OUTPUTS`.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from .loop import ClosedLoop
from .synthesis import FIR_MAX, HighBand, LowBand, high_pass_ba, low_band_sos, reduced_system

__all__ = ["Block", "MemorySink", "Sink", "simulate"]


@dataclass(frozen=True)
class Block:
    """One block of the time series: t (n,) [s]; values (n, n_sat, n_out) float64 (names: ``outputs``)."""

    t: np.ndarray
    values: np.ndarray
    outputs: tuple


class Sink:
    """Where :func:`simulate` sends its blocks: ``start(meta)`` once (meta: dict with ``outputs``,
    ``n_sat``, ``fs``, ``n_samples``, ``t0``, ``units``), ``write(block)`` per block in time order,
    ``close()`` at the end (not called when the simulation fails: a file writer then discards its file)."""

    def start(self, meta: dict) -> None:  # pragma: no cover - interface
        pass

    def write(self, block: Block) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def close(self) -> None:  # pragma: no cover - interface
        pass


@dataclass
class MemorySink(Sink):
    """Keeps every block; :attr:`t` (N,) and :attr:`values` (N, n_sat, n_out) after ``close``."""

    meta: dict = field(default_factory=dict)
    _t: list = field(default_factory=list)
    _v: list = field(default_factory=list)
    t: np.ndarray | None = None
    values: np.ndarray | None = None

    def start(self, meta):
        self.meta = dict(meta)

    def write(self, block):
        self._t.append(block.t)
        self._v.append(block.values)

    def close(self):
        self.t = np.concatenate(self._t) if self._t else np.zeros(0)
        self.values = np.concatenate(self._v) if self._v else np.zeros((0, self.meta.get("n_sat", 0), 0))
        self._t, self._v = [], []


class _Noise:
    """The noise of one satellite (sources in ``components`` order, components concatenated): per block the
    low band's shaped inputs; the high band's white inputs kept in a buffer reaching FIR_MAX samples back
    (drawn from FIR_MAX samples before the first one, so that the high band is stationary from the start).
    Sources off (level 0, or reaching no output in any segment: ``used`` False) draw nothing."""

    def __init__(self, noise: dict, sat: int, seed: int, fs: float, f_lo: float, components: dict, used: dict):
        self.parts, k = [], 0
        for src, n in components.items():
            model = noise.get(src)
            lo, hi = np.random.SeedSequence(seed, spawn_key=(sat, zlib.crc32(src.encode()))).spawn(2)
            if model is not None and model.level > 0 and used[src]:
                sos = low_band_sos(model, fs, f_lo)
                self.parts.append((slice(k, k + n), model.level, sos, np.zeros((sos.shape[0], n, 2)),
                                   np.random.default_rng(lo), np.random.default_rng(hi)))
            k += n
        self.n_in = k
        self.scale = math.sqrt(0.5 * fs)                   # unit one-sided PSD: variance fs/2
        self.q = high_pass_ba(fs)
        self.qzi = np.zeros((k, 2))
        self.buf0 = -FIR_MAX
        self.buf = self._white(FIR_MAX)

    def _white(self, m: int) -> np.ndarray:
        """The high band's next m inputs: white noise through the pre-filter Q (state carried)."""
        out = np.zeros((self.n_in, m))
        for sl, _level, _sos, _zi, _lo, hi in self.parts:
            out[sl] = hi.standard_normal((m, sl.stop - sl.start)).T        # time-major: blocks do not matter
        out, self.qzi = signal.lfilter(*self.q, out * self.scale, axis=1, zi=self.qzi)
        return out

    def draw(self, m: int) -> np.ndarray:
        """The low band's inputs (n_in, m) of the next m samples; their high-band white noise is appended to
        :attr:`buf` (samples :attr:`buf0`.. on)."""
        out = np.zeros((self.n_in, m))
        for i, (sl, level, sos, zi, lo, hi) in enumerate(self.parts):
            w = lo.standard_normal((m, sl.stop - sl.start)).T * (self.scale * level)
            out[sl], zi = signal.sosfilt(sos, w, axis=1, zi=zi)
            self.parts[i] = (sl, level, sos, zi, lo, hi)
        self.buf = np.concatenate([self.buf, self._white(m)], axis=1)
        return out

    def trim(self) -> None:
        """Forget the high band's white noise older than FIR_MAX samples before the buffer's end."""
        cut = self.buf.shape[1] - FIR_MAX
        if cut > 0:
            self.buf = self.buf[:, cut:]
            self.buf0 += cut


def _used(segments: list) -> dict:
    """{source: True if any of its components reaches an output (a nonzero column of B or D of the loop
    without the orbit states) in any segment} of one satellite's segments [(t_start, ClosedLoop)]."""
    out: dict = {}
    for _t, cl in segments:
        sys = reduced_system(cl, cl.time_outputs())
        k = 0
        for src, n in cl.source_components().items():
            out[src] = out.get(src, False) or bool(np.any(sys.B[:, k:k + n]) or np.any(sys.D[:, k:k + n]))
            k += n
    return out


class _Segment:
    """The two bands of one satellite's loop in one frozen-coefficient segment."""

    def __init__(self, cl: ClosedLoop, noise: dict, fs: float, f_lo: float, outputs: list):
        sys = reduced_system(cl, outputs, noise)
        self.low = LowBand(sys, 1.0 / fs)
        self.high = HighBand(sys, noise, cl.source_components(), fs, f_lo)


def simulate(loops: list, noise: dict, fs: float, n_samples: int, seed: int = 0, sink: Sink | None = None,
             t0: float = 0.0, block_size: int = 65536, f_lo: float | None = None) -> Sink:
    """Run the time-domain closed loops.

    loops : list over satellites of lists of (t_start [s], :class:`ClosedLoop`), segments in time order
        (the first applies from ``t0``; each until the next one's t_start).
    noise : {source: AsdModel} (sources missing or of level 0 are off).
    fs : sample rate [Hz]; n_samples : number of samples (t = t0 + k/fs).
    seed : the root seed (module docstring).  sink : where the blocks go (default a :class:`MemorySink`,
        returned).  f_lo : lowest frequency [Hz] of the shaping filters' band (default 0.1 fs/n_samples:
        below it an ASD that rises towards f = 0 levels off; a series of length T resolves nothing below 1/T).
    """
    sink = MemorySink() if sink is None else sink
    outputs = loops[0][0][1].time_outputs()
    dt = 1.0 / fs
    f_lo = 0.1 * fs / max(n_samples, 1) if f_lo is None else f_lo
    units = {}
    from .loop import OUTPUTS
    for o in outputs:
        units[o] = OUTPUTS[o][0] if o in OUTPUTS else ""
    sink.start({"outputs": tuple(outputs), "n_sat": len(loops), "fs": fs, "n_samples": n_samples, "t0": t0,
                "units": units, "seed": seed})
    gens = [_Noise(noise, s, seed, fs, f_lo, loops[s][0][1].source_components(), _used(loops[s]))
            for s in range(len(loops))]
    cache: dict = {}
    states = [None] * len(loops)                           # (xt at the next sample, the LowBand it belongs to)
    k = 0
    while k < n_samples:
        m = min(block_size, n_samples - k)
        t = t0 + (k + np.arange(m)) / fs
        vals = np.empty((m, len(loops), len(outputs)))
        for s, segs in enumerate(loops):
            u = gens[s].draw(m)
            # split the block at segment boundaries
            starts = [max(t0, ts) for ts, _ in segs]
            j0 = 0
            while j0 < m:
                seg = max(i for i, ts in enumerate(starts) if ts <= t[j0] + 0.5 * dt or i == 0)
                nxt = starts[seg + 1] if seg + 1 < len(starts) else math.inf
                j1 = min(m, j0 + max(1, int(np.searchsorted(t[j0:], nxt - 0.5 * dt))))
                if (s, seg) not in cache:
                    for old in [key for key in cache if key[0] == s]:
                        del cache[old]                    # segments come in time order: one per satellite
                    cache[(s, seg)] = _Segment(segs[seg][1], noise, fs, f_lo, outputs)
                sg = cache[(s, seg)]
                if states[s] is None:                     # at rest: x = 0
                    xt = sg.low.state(np.zeros(sg.low.A.shape[0]), u[:, j0])
                else:                                     # the continuous state carried across a segment boundary
                    xt, prev = states[s]
                    xt = xt if prev is sg.low else sg.low.carried(prev, xt, u[:, j0])
                y, xt = sg.low.run(xt, u[:, j0:j1])
                states[s] = (xt, sg.low)
                y += sg.high.apply(gens[s].buf, gens[s].buf0, k + j0, k + j1)
                vals[j0:j1, s, :] = y.T
                j0 = j1
            gens[s].trim()
            if k + m >= n_samples:                        # its last block: the satellite's filters are done
                cache.pop((s, seg), None)
                sg = None                                 # released before the next satellite's are designed
        sink.write(Block(t=t, values=vals, outputs=tuple(outputs)))
        k += m
    sink.close()
    return sink
