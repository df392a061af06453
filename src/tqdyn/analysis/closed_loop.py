"""The closed loop of a coupled run as xarray objects: its noise budget and its time series (the Python
entry point; docs/closed-loop.md).  The model is built by :func:`tqdyn.closedloop.model.closed_loop_model`
(re-exported here with :class:`~tqdyn.closedloop.model.ClosedLoopModel` and
:class:`~tqdyn.closedloop.model.ClosedLoopError`); this module evaluates it.

::

    import tqdyn
    traj = tqdyn.propagate("lisa", {"run.duration": "2d", "integrator.step": 3600})
    model = tqdyn.closed_loop_model(traj)            # per satellite and segment: the closed loops
    budget = tqdyn.closed_loop_budget(model)         # xarray.Dataset, dims (segment, sat, output, source, frequency)
    series = tqdyn.closed_loop_timeseries(model, duration_s=86400)   # xarray.Dataset, dims (time, sat, output)

Units: SI, frequencies in Hz, ASDs one-sided in (output unit)/Hz^1/2; times in seconds on the run's
time axis (``traj.reference.time_scale`` since the epoch).  Frames: :data:`tqdyn.closedloop.loop.OUTPUTS`.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..closedloop import frequency, modal
from ..closedloop.budget import grid_margins, loop_gains, noise_budget
from ..closedloop.loop import OUTPUTS, SOURCES, output_names
from ..closedloop.missions import requirement
from ..closedloop.model import ClosedLoopError, ClosedLoopModel, closed_loop_model
from ..closedloop.simulate import MemorySink, Sink, simulate
from ..scenario.closed_loop import DEFAULT_SERIES_S

__all__ = ["ClosedLoopError", "ClosedLoopModel", "closed_loop_budget", "closed_loop_model", "closed_loop_timeseries",
           "BANDS", "MARGIN_GRID", "default_series_s"]

#: Bands [Hz] of the dominant-source summary.
BANDS = ((1e-4, 1e-3), (1e-3, 1e-2), (1e-2, 1e-1), (1e-1, 1.0))


#: The grid of the loop gains whose crossovers give the margins: [Hz], [Hz], points (log-spaced).
MARGIN_GRID = (1e-6, 10.0, 1500)
#: Loops evaluated together (bounds the memory of the evaluation).
_GROUP = 8


def _cores() -> int:
    """The CPU cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _ordered_map(fn, items, threads: int | None):
    """fn over ``items``, results in order, on ``threads`` threads (default :func:`_cores`) with at most two
    items per thread ahead of the one consumed (bounds the memory of the results held)."""
    threads = _cores() if threads is None else max(1, int(threads))
    if threads == 1 or len(items) < 2:
        yield from map(fn, items)
        return
    from collections import deque
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(threads) as pool:
        it = iter(items)
        pending = deque(pool.submit(fn, x) for _, x in zip(range(2 * threads), it))
        while pending:
            out = pending.popleft().result()
            for x in it:
                pending.append(pool.submit(fn, x))
                break
            yield out


def _margins(model: ClosedLoopModel, idx, fm) -> dict:
    """:func:`tqdyn.closedloop.budget.grid_margins` of the loops ``idx`` (satellite-major indices): the loop gains
    modal where that leaves the margins unchanged, else exact (:func:`tqdyn.closedloop.modal.loop_gains`; exact:
    the stacked 20 x 20 solves, or each loop's state space)."""
    n_seg = len(model.loops[0])
    cls = [model.loops[j // n_seg][j % n_seg][1] for j in idx]
    if model.stack is not None:
        def exact(pos, f):
            return frequency.loop_gains(model.stack, idx[pos], f)
    else:
        def exact(pos, f):
            return np.array([loop_gains(cls[p], f)[1] for p in pos])
    return grid_margins(modal.loop_gains([c.system for c in cls], cls[0].channel_names, fm, exact), fm)


def closed_loop_budget(model: ClosedLoopModel, f=None, dt: float | None = None, progress=None,
                       per_source: bool = True, threads: int | None = None):
    """The noise budget as an ``xarray.Dataset``: ``asd`` (segment, sat, output, source, frequency) one-sided
    [output unit/Hz^1/2] (only with ``per_source``); ``total`` (segment, sat, output, frequency) the sources
    summed in power; ``requirement`` (frequency) the mission's TM acceleration requirement [m/s^2/Hz^1/2];
    ``dominant`` (segment, sat, output, band) the largest source per band (:data:`BANDS`); per (segment, sat,
    channel) the margins of the loop-at-a-time gains (:func:`tqdyn.closedloop.budget.grid_margins` on
    :data:`MARGIN_GRID`): ``gain_margin`` [1] the lower gain margin (the factor the gain may fall by; 0: none),
    ``gain_margin_lower`` (the same), ``gain_margin_upper`` (the factor it may rise by; inf: none),
    ``phase_margin`` [deg] and ``crossover`` [Hz].  Every loop of the model is evaluated in the frequency
    domain at once (:mod:`tqdyn.closedloop.frequency`; loops without their blocks: each state space by
    :func:`tqdyn.closedloop.budget.noise_budget`).  ``dt`` [s]: the zero-order-hold discretised loops' budget
    (a sampled loop on held noise; the time series realise the continuous budget:
    :mod:`tqdyn.closedloop.synthesis`; one state space at a time).  ``progress``: called with 1 after each
    (segment, satellite) loop.  ``threads``: groups of loops evaluated at once by the stacked path (default: the
    CPU cores this process may use; numpy's solves and products run outside the interpreter's lock); the result
    does not depend on it.  Coordinates carry units and frames (attrs)."""
    import xarray as xr

    s = model.settings
    f = np.logspace(math.log10(s["f_min"]), math.log10(s["f_max"]), s["n_freq"]) if f is None else np.asarray(f)
    outs = output_names()
    n_sat, n_seg = len(model.loops), len(model.loops[0])
    sources = [x for x in SOURCES if x in model.noise]
    fast = dt is None and model.stack is not None
    asd = np.empty((n_seg, n_sat, len(outs), len(sources), len(f))) if per_source else None
    total = np.empty((n_seg, n_sat, len(outs), len(f)))
    bands = [(f >= lo) & (f <= hi) for lo, hi in BANDS]
    band_power = np.zeros((n_seg, n_sat, len(outs), len(sources), len(BANDS)))
    fm = np.logspace(math.log10(MARGIN_GRID[0]), math.log10(MARGIN_GRID[1]), MARGIN_GRID[2])
    margins = {}
    order = np.arange(n_sat * n_seg)
    groups = [order[a:a + _GROUP] for a in range(0, len(order), _GROUP)]

    def evaluate(idx):
        if fast:
            b, _src = frequency.noise_asd(model.stack, idx, model.noise, f)
        else:
            b = np.array([noise_budget(model.loops[j // n_seg][j % n_seg][1], model.noise, f, dt=dt)[0] for j in idx])
        b2 = b ** 2
        power = np.zeros(b.shape[:3] + (len(BANDS),))
        for m, mask in enumerate(bands):
            if np.any(mask):
                power[..., m] = np.mean(b2[..., mask], axis=-1)
        return np.sqrt(np.sum(b2, axis=2)), power, (b if per_source else None), _margins(model, idx, fm)

    for idx, (tot, power, b, marg) in zip(groups, _ordered_map(evaluate, groups, threads if fast else 1)):
        sat, seg = idx // n_seg, idx % n_seg
        total[seg, sat] = tot
        band_power[seg, sat] = power
        if per_source:
            asd[seg, sat] = b
        for key, v in marg.items():
            margins.setdefault(key, np.empty((n_seg, n_sat) + v.shape[1:]))[seg, sat] = v
        if progress is not None:
            for _ in idx:
                progress(1)
    names = np.array(sources + [""], dtype=object)
    dom = names[np.where(np.array([np.any(m) for m in bands]), np.argmax(band_power, axis=3), len(sources))]
    chans = list(model.loops[0][0][1].channel_names)
    dims_m = ("segment", "sat", "channel")
    data = {"total": (("segment", "sat", "output", "frequency"), total),
            "requirement": (("frequency",), requirement(model.mission).asd(f)),
            "dominant": (("segment", "sat", "output", "band"), dom.astype(str)),
            "gain_margin": (dims_m, margins["gain_margin_lower"]),
            "gain_margin_lower": (dims_m, margins["gain_margin_lower"]),
            "gain_margin_upper": (dims_m, margins["gain_margin_upper"]),
            "phase_margin": (dims_m, margins["phase_margin"]),
            "crossover": (dims_m, margins["crossover"])}
    if per_source:
        data = {"asd": (("segment", "sat", "output", "source", "frequency"), asd), **data}
    ds = xr.Dataset(
        data,
        coords={"segment": [lp[0] for lp in model.loops[0]], "sat": np.arange(1, n_sat + 1),
                "sat_name": ("sat", list(model.satellite_names)), "output": outs, "source": sources,
                "frequency": f, "band": [f"{lo:g}-{hi:g} Hz" for lo, hi in BANDS], "channel": chans,
                "unit": ("output", [OUTPUTS[o][0] for o in outs]), "frame": ("output", [OUTPUTS[o][1] for o in outs])},
        attrs={"mission": model.mission, "asd": "one-sided", "frequency_unit": "Hz",
               "segment_unit": "s since the epoch (start of each frozen-coefficient segment)",
               "discretised_dt": float(dt) if dt is not None else 0.0})
    if per_source:
        ds["asd"].attrs["units"] = "output unit/Hz^1/2"
    ds["total"].attrs["units"] = "output unit/Hz^1/2"
    for k in ("gain_margin", "gain_margin_lower", "gain_margin_upper"):
        ds[k].attrs["units"] = "1"
    ds["phase_margin"].attrs["units"] = "deg"
    ds["crossover"].attrs["units"] = "Hz"
    return ds


def default_series_s(model: ClosedLoopModel) -> float:
    """The time series' length [s] when none is asked for: the run's first day
    (:data:`tqdyn.scenario.closed_loop.DEFAULT_SERIES_S`), its span if shorter."""
    span = model.t_span[1] - model.t_span[0]
    return min(DEFAULT_SERIES_S, span) if span > 0 else DEFAULT_SERIES_S


def closed_loop_timeseries(model: ClosedLoopModel, duration_s: float | None = None, fs: float | None = None,
                           seed: int | None = None, sink: Sink | None = None, block_size: int = 65536):
    """Seeded time series of every output (:func:`tqdyn.closedloop.simulate.simulate`) from the run's first
    time on.  With ``sink`` None: an ``xarray.Dataset`` ``values`` (time, sat, output) [output units];
    with a sink (e.g. a file writer): the sink, after ``close``.  ``duration_s`` [s] (default: the
    settings' duration, else :func:`default_series_s`), ``fs`` [Hz] and ``seed`` override the settings."""
    s = model.settings
    fs = float(fs if fs is not None else s["fs"])
    dur = duration_s if duration_s is not None else (s["duration"] or default_series_s(model))
    if not (isinstance(dur, (int, float)) and math.isfinite(dur) and dur > 0):
        raise ClosedLoopError(f"closed_loop.duration: {dur!r} is not a positive duration; allowed: > 0 s")
    n = int(round(float(dur) * fs))
    seed = int(seed if seed is not None else s["seed"])
    out = simulate(model.loops, model.noise, fs, n, seed=seed, sink=sink if sink is not None else MemorySink(),
                   t0=model.t_span[0], block_size=block_size)
    if sink is not None:
        return out
    import xarray as xr

    outs = list(out.meta["outputs"])
    return xr.Dataset({"values": (("time", "sat", "output"), out.values)},
                      coords={"time": out.t, "sat": np.arange(1, out.values.shape[1] + 1),
                              "sat_name": ("sat", list(model.satellite_names)), "output": outs,
                              "unit": ("output", [OUTPUTS[o][0] for o in outs]),
                              "frame": ("output", [OUTPUTS[o][1] for o in outs])},
                      attrs={"mission": model.mission, "fs": fs, "seed": seed,
                             "time_unit": "s on the run's time axis since the epoch"})
