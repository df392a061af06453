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

import numpy as np

from ..closedloop.budget import dominant_sources, loop_margins, noise_budget
from ..closedloop.loop import OUTPUTS, output_names
from ..closedloop.missions import requirement
from ..closedloop.model import ClosedLoopError, ClosedLoopModel, closed_loop_model
from ..closedloop.simulate import MemorySink, Sink, simulate

__all__ = ["ClosedLoopError", "ClosedLoopModel", "closed_loop_budget", "closed_loop_model", "closed_loop_timeseries",
           "BANDS"]

#: Bands [Hz] of the dominant-source summary.
BANDS = ((1e-4, 1e-3), (1e-3, 1e-2), (1e-2, 1e-1), (1e-1, 1.0))


def closed_loop_budget(model: ClosedLoopModel, f=None, dt: float | None = None, progress=None):
    """The noise budget as an ``xarray.Dataset``: ``asd`` (segment, sat, output, source, frequency) one-sided
    [output unit/Hz^1/2]; ``total`` (segment, sat, output, frequency); ``requirement`` (frequency) the
    mission's TM acceleration requirement [m/s^2/Hz^1/2]; ``dominant`` (segment, sat, output, band) the
    largest source per band (:data:`BANDS`); ``gain_margin`` [1] and ``phase_margin`` [deg] and
    ``crossover`` [Hz] per (segment, sat, channel).  ``dt`` [s]: the zero-order-hold discretised loops'
    budget (a sampled loop on held noise; the time series realise the continuous budget).  ``progress``: called with 1 after each (segment, satellite) loop
    (segments x satellites calls).  Coordinates carry units and frames (attrs)."""
    import xarray as xr

    s = model.settings
    f = np.logspace(math.log10(s["f_min"]), math.log10(s["f_max"]), s["n_freq"]) if f is None else np.asarray(f)
    outs = output_names()
    n_seg = len(model.loops[0])
    asd = None
    margins = []
    for k in range(n_seg):
        per_sat, msat = [], []
        for i in range(len(model.loops)):
            b, sources = noise_budget(model.loops[i][k][1], model.noise, f, dt=dt)
            per_sat.append(b)
            msat.append(loop_margins(model.loops[i][k][1]))
            if progress is not None:
                progress(1)
        asd = np.zeros((n_seg, len(model.loops)) + per_sat[0].shape) if asd is None else asd
        asd[k] = np.array(per_sat)
        margins.append(msat)
    total = np.sqrt(np.sum(asd ** 2, axis=3))
    dom = np.array([[dominant_sources(asd[k, i], sources, f, BANDS) for i in range(asd.shape[1])]
                    for k in range(n_seg)])
    chans = [m.channel for m in margins[0][0]]
    gm = np.array([[[m.gain_margin for m in ms] for ms in seg] for seg in margins])
    pm = np.array([[[m.phase_margin for m in ms] for ms in seg] for seg in margins])
    fc = np.array([[[m.f_phase_margin for m in ms] for ms in seg] for seg in margins])
    ds = xr.Dataset(
        {"asd": (("segment", "sat", "output", "source", "frequency"), asd),
         "total": (("segment", "sat", "output", "frequency"), total),
         "requirement": (("frequency",), requirement(model.mission).asd(f)),
         "dominant": (("segment", "sat", "output", "band"), dom),
         "gain_margin": (("segment", "sat", "channel"), gm),
         "phase_margin": (("segment", "sat", "channel"), pm),
         "crossover": (("segment", "sat", "channel"), fc)},
        coords={"segment": [lp[0] for lp in model.loops[0]], "sat": np.arange(1, len(model.loops) + 1),
                "sat_name": ("sat", list(model.satellite_names)), "output": outs, "source": sources,
                "frequency": f, "band": [f"{lo:g}-{hi:g} Hz" for lo, hi in BANDS], "channel": chans,
                "unit": ("output", [OUTPUTS[o][0] for o in outs]), "frame": ("output", [OUTPUTS[o][1] for o in outs])},
        attrs={"mission": model.mission, "asd": "one-sided", "frequency_unit": "Hz",
               "segment_unit": "s since the epoch (start of each frozen-coefficient segment)",
               "discretised_dt": float(dt) if dt is not None else 0.0})
    ds["asd"].attrs["units"] = "output unit/Hz^1/2"
    ds["phase_margin"].attrs["units"] = "deg"
    ds["crossover"].attrs["units"] = "Hz"
    return ds


def closed_loop_timeseries(model: ClosedLoopModel, duration_s: float | None = None, fs: float | None = None,
                           seed: int | None = None, sink: Sink | None = None, block_size: int = 65536):
    """Seeded time series of every output (:func:`tqdyn.closedloop.simulate.simulate`) from the run's first
    time on.  With ``sink`` None: an ``xarray.Dataset`` ``values`` (time, sat, output) [output units];
    with a sink (e.g. a file writer): the sink, after ``close``.  ``duration_s`` [s] (default: the
    settings' duration, else the run's span), ``fs`` [Hz] and ``seed`` override the settings."""
    s = model.settings
    fs = float(fs if fs is not None else s["fs"])
    dur = duration_s if duration_s is not None else (s["duration"] or (model.t_span[1] - model.t_span[0]))
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
