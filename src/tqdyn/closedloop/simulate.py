"""Time-domain evaluation: seeded coloured-noise realisations through the discretised closed loops.

* Noise: for each satellite and source, one ``numpy.random.SeedSequence(seed, spawn_key=(sat,
  crc32(source)))``: a source's realisation depends only on the seed, the satellite and its own name,
  so adding or removing a source changes no other.  Each component is white Gaussian noise of
  one-sided PSD 1 (variance fs/2) filtered by the source's shaping filter
  (:meth:`~tqdyn.closedloop.noise.AsdModel.shaping_zpk`, band [f_lo, fs/2], discretised with the
  bilinear (Tustin) transform; ``scipy.signal.sosfilt`` with its state carried across blocks) times
  the level.
* Loop: the continuous closed loop of each frozen-coefficient segment, restricted to the noise
  inputs and the time-domain outputs (the spacecraft's orbit displacement ``u`` is left out: nothing
  feeds back from it), discretised with a zero-order hold on the (coloured) noise at fs
  (``control.c2d(..., "zoh")``), run in modal form: x = V z with V the eigenvectors of the discrete
  state matrix, each mode a first-order recursion (``scipy.signal.lfilter``) and the input and output
  maps dense products per block.  The decomposition is checked (|V Lambda V^-1 - A_d| / |A_d|) and a
  direct recursion is used instead when it is poor.  At a segment boundary the state is carried in
  the loop's physical coordinates, so the coefficients change piecewise in time.
* Streaming: blocks of ``block_size`` samples go to a sink (:class:`Sink`): memory is bounded by the
  block size whatever the duration.  :class:`MemorySink` keeps everything.

Units: t [s] on the run's time axis; outputs in the units of :data:`tqdyn.closedloop.loop.OUTPUTS`.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field

import control
import numpy as np
from scipy import signal

from .loop import ClosedLoop

__all__ = ["Block", "MemorySink", "Sink", "simulate"]

#: Largest relative reconstruction error of the modal decomposition before the direct recursion is used.
_MODAL_TOLERANCE = 1e-9


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
    """Coloured noise of one satellite: sources in SOURCES order, components concatenated."""

    def __init__(self, noise: dict, sat: int, seed: int, fs: float, f_lo: float, components: dict):
        self.parts = []
        for src, n in components.items():
            model = noise.get(src)
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(sat, zlib.crc32(src.encode()))))
            if model is None or model.level == 0:
                self.parts.append((n, None, None, None, rng))
                continue
            z, p, k = model.shaping_zpk(f_lo, 0.5 * fs)
            if len(p):
                zd, pd, kd = signal.bilinear_zpk(z, p, k, fs)
                sos = signal.zpk2sos(zd, pd, kd)
                zi = np.zeros((sos.shape[0], n, 2))
            else:
                sos, zi = None, None
            self.parts.append((n, model.level, sos, zi, rng))
        self.fs = fs

    def draw(self, m: int) -> np.ndarray:
        out = []
        for i, (n, level, sos, zi, rng) in enumerate(self.parts):
            w = rng.standard_normal((m, n)).T * math.sqrt(0.5 * self.fs)   # time-major: blocks do not matter
            if level is None:
                out.append(np.zeros((n, m)))
                continue
            if sos is not None:
                w, zi = signal.sosfilt(sos, w, axis=1, zi=zi)
                self.parts[i] = (n, level, sos, zi, rng)
            out.append(level * w)
        return np.vstack(out)


class _DiscreteLoop:
    """The discretised, reduced closed loop of one segment, in modal form when well conditioned."""

    def __init__(self, cl: ClosedLoop, dt: float, outputs: list):
        sys = cl.system
        keep = [k for k, s in enumerate(sys.state_labels) if not (s.startswith("plant_u[") or s.startswith("plant_du["))]
        ii = [sys.input_labels.index(f"{src}[{k}]") for src, n in cl.source_components().items() for k in range(n)]
        oi = [sys.output_labels.index(o) for o in outputs]
        red = control.ss(sys.A[np.ix_(keep, keep)], sys.B[np.ix_(keep, ii)], sys.C[np.ix_(oi, keep)],
                         sys.D[np.ix_(oi, ii)])
        d = control.c2d(red, dt, method="zoh")
        self.A, self.B, self.C, self.D = (np.asarray(x) for x in (d.A, d.B, d.C, d.D))
        lam, V = np.linalg.eig(self.A)
        Vi = np.linalg.inv(V)
        err = np.linalg.norm(V @ np.diag(lam) @ Vi - self.A) / max(np.linalg.norm(self.A), 1e-300)
        self.modal = bool(err < _MODAL_TOLERANCE)
        if self.modal:
            self.lam, self.V, self.Vi = lam, V, Vi
            self.Bm, self.Cm = Vi @ self.B, self.C @ V

    def run(self, x0: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Outputs (n_out, m) for inputs w (n_in, m) from state x0 (physical); returns (y, x_end)."""
        m = w.shape[1]
        if not self.modal:
            x = x0.copy()
            y = np.empty((self.C.shape[0], m))
            for k in range(m):
                y[:, k] = self.C @ x + self.D @ w[:, k]
                x = self.A @ x + self.B @ w[:, k]
            return y, x
        v = self.Bm @ w                                  # (n_modes, m) complex
        z0 = self.Vi @ x0
        Z = np.empty_like(v)
        for i, lam in enumerate(self.lam):
            zz, _ = signal.lfilter([1.0], [1.0, -lam], v[i], zi=[lam * z0[i]])
            Z[i, 0] = z0[i]
            Z[i, 1:] = zz[:-1]
            v[i, 0] = zz[-1]                              # keep the end state
        z_end = v[:, 0].copy()
        y = (self.Cm @ Z).real + self.D @ w
        return y, (self.V @ z_end).real


def simulate(loops: list, noise: dict, fs: float, n_samples: int, seed: int = 0, sink: Sink | None = None,
             t0: float = 0.0, block_size: int = 65536, f_lo: float | None = None) -> Sink:
    """Run the time-domain closed loops.

    loops : list over satellites of lists of (t_start [s], :class:`ClosedLoop`), segments in time order
        (the first applies from ``t0``; each until the next one's t_start).
    noise : {source: AsdModel} (sources missing or of level 0 are off).
    fs : sample rate [Hz]; n_samples : number of samples (t = t0 + k/fs).
    seed : the root seed (module docstring).  sink : where the blocks go (default a :class:`MemorySink`,
        returned).  f_lo : lowest frequency [Hz] of the shaping filters' band (default 0.1 fs/n_samples).
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
    gens = [_Noise(noise, s, seed, fs, f_lo, loops[s][0][1].source_components()) for s in range(len(loops))]
    cache: dict = {}
    states = [None] * len(loops)
    k = 0
    while k < n_samples:
        m = min(block_size, n_samples - k)
        t = t0 + (k + np.arange(m)) / fs
        vals = np.empty((m, len(loops), len(outputs)))
        for s, segs in enumerate(loops):
            w = gens[s].draw(m)
            # split the block at segment boundaries
            starts = [max(t0, ts) for ts, _ in segs]
            j0 = 0
            while j0 < m:
                seg = max(i for i, ts in enumerate(starts) if ts <= t[j0] + 0.5 * dt or i == 0)
                nxt = starts[seg + 1] if seg + 1 < len(starts) else math.inf
                j1 = min(m, j0 + max(1, int(np.searchsorted(t[j0:], nxt - 0.5 * dt))))
                key = (s, seg)
                if key not in cache:
                    cache.clear() if len(cache) > 2 * len(loops) else None
                    cache[key] = _DiscreteLoop(segs[seg][1], dt, outputs)
                dl = cache[key]
                x0 = np.zeros(dl.A.shape[0]) if states[s] is None else states[s]
                y, states[s] = dl.run(x0, w[:, j0:j1])
                vals[j0:j1, s, :] = y.T
                j0 = j1
        sink.write(Block(t=t, values=vals, outputs=tuple(outputs)))
        k += m
    sink.close()
    return sink
