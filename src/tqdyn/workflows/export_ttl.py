"""Export LISA Instrument's TTL coefficient file from a closed-loop file: the job behind
``tqdyn export CL.h5 --format ttl OUT.h5``.

:func:`export_ttl` reads the closed-loop file's time grid (:mod:`tqdyn.formats.closed_loop`), builds
the coefficients (:mod:`tqdyn.ttl.coupling`: constant, optionally drifting linearly from the first
sample), samples them on that grid (or a coarser step over the same span) and writes the file
(:func:`tqdyn.formats.ttl.write_ttl_file`).  It prints nothing; the CLI reports.

Time axis: the file's ``t`` is the closed-loop file's ``t`` -- seconds on the run's time axis (its
``time_scale``) since its epoch -- which is the ``t`` of the GCRS orbit file ``tqdyn export RUN.h5
--format lisa`` writes for the same run (TT since the epoch), the axis LISA Instrument's ``t0`` and
``physics_t`` refer to when it reads that orbit file (docs/tilt-to-length.md).
"""

from __future__ import annotations

import json
import math
import pathlib
import tomllib
from dataclasses import dataclass

import numpy as np

from .._choices import unknown
from ..analysis.ttl_budget import worst_case_coefficients
from ..ttl.coupling import LINEAR_FIELDS, MOSAS, TimeVaryingTTLCoefficients, TTLCoefficients
from ..formats.atomic import check_output
from ..formats.closed_loop import read_closed_loop
from .memory import check_memory
from ..formats.ttl import write_ttl_file
from .closed_loop import file_sha256

__all__ = ["COEFFICIENT_KINDS", "TTLExport", "coefficient_set", "export_ttl", "read_coefficient_file"]

#: Built-in coefficient sets (anything else is a TOML or JSON file of per-MOSA coefficients).
COEFFICIENT_KINDS = ("worst-case", "random")
#: Memory per sample of an export [bytes]: 51 float64 measured at the peak (24 coefficient series,
#: their drifting values, t, the file's image), with --drift (27 without); 52 with a margin.
BYTES_PER_SAMPLE = 52 * 8


@dataclass(frozen=True)
class TTLExport:
    """Summary of one export: ``path`` written; ``size`` samples from ``t_start`` to ``t_stop`` [s, the
    closed-loop file's time axis]; ``step`` [s] (None: the closed-loop file's own grid); ``model``
    (the coefficient model, as stored in the file's ``coefficient_model``)."""

    path: pathlib.Path
    size: int
    t_start: float
    t_stop: float
    step: float | None
    model: dict


def read_coefficient_file(path) -> TTLCoefficients:
    """Per-MOSA linear coefficients (m/rad) from a TOML (``.toml``) or JSON (``.json``) file with the four
    tables ``local_phi``, ``local_eta``, ``distant_phi``, ``distant_eta``, each keyed by the six MOSAs
    ``12, 23, 31, 13, 32, 21`` (distant ones keyed by the emitting MOSA, as LISA Instrument's
    ``ttl_coeffs``).  One-line ValueError naming the file and the field otherwise."""
    p = pathlib.Path(path)
    if p.suffix.lower() not in (".toml", ".json"):
        raise ValueError(f"--coefficients {str(p)!r}: allowed: worst-case, random, or a .toml or .json file")
    if not p.is_file():
        raise FileNotFoundError(f"--coefficients {str(p)!r}: no such file")
    try:
        text = p.read_text(encoding="utf-8")
        data = tomllib.loads(text) if p.suffix.lower() == ".toml" else json.loads(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{p}: cannot be parsed ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict):
        raise ValueError(f"{p}: expected tables {', '.join(LINEAR_FIELDS)}")
    for k in data:
        if k not in LINEAR_FIELDS:
            raise ValueError(unknown(str(p), k, LINEAR_FIELDS, problem="is not a key"))
    try:
        return TTLCoefficients(**{f: data.get(f) for f in LINEAR_FIELDS})
    except ValueError as exc:
        raise ValueError(f"{p}: {exc}") from None


def coefficient_set(coefficients, seed=None) -> tuple[TTLCoefficients, dict]:
    """The linear TTL coefficients of the command's ``--coefficients`` and ``--seed`` (m/rad) and their
    description {"kind": ...}: "worst-case" (:func:`tqdyn.analysis.ttl_budget.worst_case_coefficients`),
    "random" (:meth:`TTLCoefficients.random` with ``seed``) or a TOML/JSON file
    (:func:`read_coefficient_file`).  One-line ValueError (or FileNotFoundError) otherwise."""
    if coefficients == "random":
        if seed is None:
            raise ValueError("--seed: required with --coefficients random (an integer >= 0)")
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise ValueError(f"--seed = {seed!r}: must be an integer >= 0")
        return TTLCoefficients.random(seed), {"kind": "random", "seed": seed}
    if seed is not None:
        raise ValueError("--seed: applies to --coefficients random only")
    if coefficients == "worst-case":
        return worst_case_coefficients(), {"kind": "worst-case"}
    c = read_coefficient_file(coefficients)
    return c, {"kind": "file", "file": pathlib.Path(coefficients).name}


def _grid(t: np.ndarray, step) -> np.ndarray:
    if step is None:
        check_memory(t.size * BYTES_PER_SAMPLE, f"the TTL file of the closed-loop file's {t.size} samples",
                     "a --step coarser than the closed-loop file's grid")
        return t
    s = float(step)
    if not math.isfinite(s) or s <= 0:
        raise ValueError(f"--step = {step!r}: must be a finite number > 0 (s)")
    span = float(t[-1] - t[0])
    n = math.floor(span / s) + 2
    check_memory(n * BYTES_PER_SAMPLE, f"--step = {step!r}: the TTL file of {n:.3g} samples",
                 lambda budget: f"--step >= {span / max(budget / BYTES_PER_SAMPLE - 2, 1):.3g} s over the closed-loop "
                                f"file's {span:g} s")
    k = np.arange(int(math.floor(span / s)) + 1)
    g = t[0] + s * k
    if g[-1] < t[-1]:
        g = np.append(g, t[-1])           # the grid covers the whole span (LISA Instrument refuses extrapolation)
    return g


def export_ttl(cl_file, out_file, *, coefficients: str = "worst-case", seed: int | None = None,
               drift: float | None = None, step: float | None = None, order: int = 5) -> TTLExport:
    """Write LISA Instrument's TTL coefficient file ``out_file`` sampled on the time grid of the
    closed-loop file ``cl_file`` (module docstring).

    coefficients: "worst-case" (every MOSA at the half-widths of LISA Instrument's random draw,
    :func:`tqdyn.analysis.ttl_budget.worst_case_coefficients`), "random" (:meth:`TTLCoefficients.random`
    with ``seed``) or the path of a TOML/JSON file (:func:`read_coefficient_file`); drift: rate (m/rad/s)
    added to every linear coefficient from the first sample on (:meth:`TimeVaryingTTLCoefficients.drifting`;
    None or 0: constant); step: sample step (s) over the closed-loop file's span (None: its own grid);
    order: the file's spline degree (3 or 5).  Bad input: a one-line ValueError (or FileNotFoundError,
    :class:`tqdyn.formats.closed_loop.ClosedLoopFormatError` for a file that is not a closed-loop file)
    before anything is written."""
    base, model = coefficient_set(coefficients, seed)
    model["base_m_per_rad"] = {f: getattr(base, f) for f in LINEAR_FIELDS}
    src = pathlib.Path(cl_file)
    check_output(out_file, "OUT", {"CL.h5": src, "--coefficients": model.get("file") and coefficients})
    cl = read_closed_loop(src)
    names = [str(o) for o in cl.timeseries(stop=1)["output"].values]
    if not names:
        raise ValueError(f"{src}: its '/timeseries' holds no output")
    ts = cl.timeseries(outputs=names[:1])
    t_cl = np.asarray(ts["time"].values, dtype=np.float64)
    if t_cl.size < 2:
        raise ValueError(f"{src}: its time series has {t_cl.size} sample(s); need at least 2")
    t = _grid(t_cl, step)
    if t.size <= order:
        raise ValueError(f"--step = {step!r}: gives {t.size} samples over {t_cl[0]:g} .. {t_cl[-1]:g} s; the spline of "
                         f"degree {order} needs more than {order}" if step is not None else
                         f"{src}: {t.size} samples; the spline of degree {order} needs more than {order}")
    if drift is not None and float(drift) != 0.0:
        r = float(drift)
        if not math.isfinite(r):
            raise ValueError(f"--drift = {drift!r}: must be a finite number (m/rad/s)")
        varying = TimeVaryingTTLCoefficients.drifting(base, r, t_ref=float(t[0]))
        model.update({"drift_m_per_rad_per_s": r, "t_ref_s": float(t[0])})
        values = {f: {m: varying.coefficient(f, m, t) for m in MOSAS} for f in LINEAR_FIELDS}
    else:
        values = {f: {m: np.full(t.shape, getattr(base, f)[m]) for m in MOSAS} for f in LINEAR_FIELDS}
    model["formula"] = "c(t) = c0 + drift (t - t_ref)" if "drift_m_per_rad_per_s" in model else "c(t) = c0"
    scale = cl.attrs.get("source_time_scale", "")
    attrs = {"time_axis": f"s on the run's time axis ({scale or 'its time_scale'}) since its epoch: the "
                          "closed-loop file's t, the t of the GCRS LISA orbit file of the same run",
             "coefficient_model": json.dumps(model, sort_keys=True),
             "source_file": src.name, "source_sha256": file_sha256(src),
             "source_epoch_utc": cl.attrs.get("source_epoch_utc", ""), "source_time_scale": scale}
    path = write_ttl_file(out_file, t, values, order=order, attrs=attrs)
    return TTLExport(path, int(t.size), float(t[0]), float(t[-1]), None if step is None else float(step), model)

