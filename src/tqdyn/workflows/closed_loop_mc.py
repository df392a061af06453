"""The robustness Monte Carlo of a mission's closed-loop designs (``tqdyn closed-loop --mission NAME
--monte-carlo N``; docs/closed-loop.md#robustness-monte-carlo).

Both designs (``per_loop`` and ``hinf``, :data:`tqdyn.scenario.closed_loop.DESIGNS`) are built once at the
mission's static working point (:func:`tqdyn.closedloop.model.static_closed_loop_model`: the H-infinity
synthesis runs once); the same N draws of the uncertain parameters (:data:`tqdyn.closedloop.robust.UNCERTAINTY`,
seeded) are evaluated with each (:func:`tqdyn.closedloop.robust.evaluate`) as Dask tasks of
:data:`CHUNK` draws on a new local cluster (:func:`tqdyn.workflows.sweep.execute.dask_client`) or on the
cluster of a scheduler address; ``workers=0`` evaluates them in this process.  The result is an xarray
Dataset (dims design, sample) written as netCDF-4 (nothing at the output path on a failure).
"""

from __future__ import annotations

import functools
import json
import math
import time

import numpy as np

__all__ = ["CHUNK", "MC_FIELDS", "check_monte_carlo", "monte_carlo", "summarise"]

#: Draws per Dask task.
CHUNK = 8
#: The per-draw results (:func:`tqdyn.closedloop.robust.evaluate`): name -> (unit, meaning).
MC_FIELDS = {
    "stable": ("1", "every pole but the orbit displacement's in the left half-plane"),
    "max_pole_re": ("1/s", "the largest real part of those poles"),
    "phase_margin_min": ("deg", "the smallest loop-at-a-time phase margin over the channels"),
    "gain_margin_lower_max": ("1", "the largest factor by which a channel's gain may fall (0: none)"),
    "gain_margin_upper_min": ("1", "the smallest factor by which a channel's gain may rise (inf: none)"),
    "requirement_ratio": ("1", "the largest residual TM acceleration / requirement over 0.1 mHz - 1 Hz"),
    "ratio_f_hz": ("Hz", "where that ratio is largest"),
}


def _chunk_task(payload: dict) -> list[dict]:
    """Dask task: evaluate the draws ``payload["ks"]`` of one design (module level: pickled by path)."""
    from ..closedloop.robust import evaluate, perturbed_plant

    out = []
    for k in payload["ks"]:
        q, gains, _vals = perturbed_plant(payload["plant"], payload["z"], k)
        out.append(evaluate(q, payload["wp"], payload["controllers"], payload["noise"], payload["requirement"],
                            payload["sensor"], "constellation", gains))
    return out


def check_monte_carlo(mission, n, overrides=(), workers=None) -> None:
    """One-line ValueError for a Monte Carlo that cannot run: no mission, a single-spacecraft mission (the
    H-infinity design needs the "constellation" scheme), N < 1, workers < 0."""
    from ..closedloop.missions import CONSTELLATION_MISSIONS

    if mission is None:
        raise ValueError("--monte-carlo: needs --mission (the static working point); allowed: tqdyn closed-loop "
                         "--mission NAME --monte-carlo N --output MC.nc")
    if mission not in CONSTELLATION_MISSIONS:
        raise ValueError(f"--mission: {mission!r} has no 'hinf' design to compare; allowed with --monte-carlo: "
                         f"{', '.join(CONSTELLATION_MISSIONS)}")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"--monte-carlo: {n!r} is not allowed; allowed: an integer >= 1 (draws)")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 0):
        raise ValueError(f"--workers: {workers!r} is not allowed; allowed: an integer >= 0 (0: in this process)")
    for o in overrides:
        if str(o).split("=")[0].strip() == "closed_loop.design":
            raise ValueError(f"--set: {o!r} is not allowed with --monte-carlo; allowed: no closed_loop.design "
                             "(the Monte Carlo runs both designs)")


@functools.lru_cache(maxsize=4)
def _designs(mission, overrides: tuple) -> dict:
    """{design: (model, controllers)} of the mission's static working point (kept: a synthesis is the slow part)."""
    from ..closedloop.model import static_closed_loop_model
    from ..scenario.closed_loop import DESIGNS
    from ..scenario.loader import closed_loop_config

    out = {}
    for d in DESIGNS:
        cfg = closed_loop_config({"mission": mission, "design": d}, overrides)
        model = static_closed_loop_model(cfg, validate=True)
        out[d] = (model, model.hinf[0] if model.hinf else model.controllers)
    return out


def monte_carlo(mission: str, n: int, seed: int = 0, overrides=(), scheduler=None, workers: int | None = None,
                progress=None):
    """The Monte Carlo's xarray Dataset (module docstring): per (design, sample) the fields of
    :data:`MC_FIELDS`; the draws (sample, ...): ``stiffness``, ``rotational_stiffness``, ``housing_offset``
    (sample, tm, axis), ``crosstalk`` (sample), ``actuator_gain`` (sample, actuator); attrs: mission, seed,
    the uncertainty table (JSON), per design the H-infinity gamma and the synthesis and evaluation times [s].
    ``progress(k)`` after each task of k draws."""
    import xarray as xr

    from ..closedloop.missions import requirement
    from ..closedloop.robust import ACTUATOR_INPUTS, UNCERTAINTY, draw, perturbed_plant

    check_monte_carlo(mission, n, overrides, workers)
    t0 = time.perf_counter()
    designs = _designs(mission, tuple(overrides))
    t_build = time.perf_counter() - t0
    z = draw(np.random.default_rng(seed), n)
    req = requirement(mission)
    tasks = []
    for d, (model, ctl) in designs.items():
        p, wp = model.parts[0][0]
        for a in range(0, n, CHUNK):
            tasks.append((d, a, {"plant": p, "wp": wp, "controllers": ctl, "noise": model.noise, "requirement": req,
                                 "sensor": model.settings["attitude_z_sensor"], "z": z,
                                 "ks": list(range(a, min(n, a + CHUNK)))}))
    results: dict = {}
    t1 = time.perf_counter()
    if workers == 0:
        for d, a, pl in tasks:
            results[(d, a)] = _chunk_task(pl)
            if progress is not None:
                progress(len(pl["ks"]))
    else:
        _on_dask(tasks, results, scheduler, workers, progress)
    t_eval = time.perf_counter() - t1
    names = list(designs)
    data = {}
    for key, (unit, meaning) in MC_FIELDS.items():
        arr = np.array([[r[key] for a in range(0, n, CHUNK) for r in results[(d, a)]] for d in names])
        data[key] = xr.DataArray(arr, dims=("design", "sample"), attrs={"units": unit, "long_name": meaning})
    vals = [perturbed_plant(designs[names[0]][0].parts[0][0][0], z, k)[2] for k in range(n)]
    for key, dims, unit in (("stiffness", ("sample", "tm", "axis"), "s^-2"),
                            ("rotational_stiffness", ("sample", "tm", "axis"), "s^-2"),
                            ("housing_offset", ("sample", "tm", "axis"), "m"), ("crosstalk", ("sample",), "1"),
                            ("actuator_gain", ("sample", "actuator"), "1")):
        data[key] = xr.DataArray(np.array([v[key] for v in vals]), dims=dims, attrs={"units": unit})
    gamma = {d: (m.hinf[0].gamma if m.hinf else math.nan) for d, (m, _c) in designs.items()}
    synth = {d: (m.hinf[0].synthesis_s if m.hinf else 0.0) for d, (m, _c) in designs.items()}
    ds = xr.Dataset(data, coords={"design": names, "sample": np.arange(n), "tm": [1, 2], "axis": ["x", "y", "z"],
                                  "actuator": list(ACTUATOR_INPUTS)},
                    attrs={"mission": mission, "seed": int(seed), "n_samples": int(n),
                           "uncertainty": json.dumps({k: list(v) for k, v in UNCERTAINTY.items()}),
                           "gamma": json.dumps(gamma), "synthesis_s": json.dumps(synth),
                           "build_s": float(t_build), "evaluation_s": float(t_eval),
                           "overrides": json.dumps(list(overrides)),
                           "scheduler": str(scheduler) if scheduler else ("in-process" if workers == 0 else "local")})
    return ds


def _on_dask(tasks, results: dict, scheduler, workers, progress) -> None:
    """Run the ``tasks`` (design, first draw, payload) as Dask tasks; fill ``results``."""
    from distributed import as_completed

    from .sweep.execute import dask_client

    with dask_client(scheduler, workers, len(tasks), dashboard=None) as client:
        futs = {client.submit(_chunk_task, pl, pure=False): (d, a, len(pl["ks"])) for d, a, pl in tasks}
        try:
            for fut in as_completed(list(futs)):
                d, a, k = futs.pop(fut)
                results[(d, a)] = fut.result()
                if progress is not None:
                    progress(k)
        finally:
            client.cancel(list(futs))


def summarise(ds) -> dict:
    """Per design: the fraction stable and the median, 5 % and 95 % quantiles of the requirement ratio and the
    margins (over the stable draws), plain JSON types (docs/data)."""
    out = {}
    for d in ds.design.values.tolist():
        x = ds.sel(design=d)
        st = x.stable.values.astype(bool)
        row = {"stable_fraction": float(np.mean(st))}
        for key in ("requirement_ratio", "phase_margin_min", "gain_margin_lower_max", "gain_margin_upper_min"):
            v = x[key].values[st]
            v = v[np.isfinite(v)]
            row[key] = ({"median": float(np.median(v)), "p05": float(np.quantile(v, 0.05)),
                         "p95": float(np.quantile(v, 0.95))} if v.size else None)
        out[d] = row
    return out
