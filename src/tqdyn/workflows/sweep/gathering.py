"""Gathering a sweep: the members' trajectory files merged into one ``xarray.Dataset`` (:func:`gather`).

The varied parameters become leading dimensions (``product``: one per
parameter; ``zip``: one ``member`` dimension); failed members are NaN-filled
and flagged by ``ok``.  Writing the dataset: :func:`tqdyn.formats.netcdf.write_netcdf`.
"""

from __future__ import annotations

from collections.abc import Sequence
from decimal import Decimal
from typing import Any

import numpy as np

from ...formats import trajectory as io
from ..run import one_line
from .outcome import MemberOutcome
from .plan import SweepPlan
from ...scenario.toml_text import toml_value
from .spec import SweepSpec, _coord_values

__all__ = ["gather"]


def _param_coords(spec: SweepSpec, dims: tuple[str, ...]) -> dict:
    """Coordinates of the member dimensions: the parameter values (or labels,
    then also ``<name>_value``)."""
    coords: dict[str, Any] = {}
    for p in spec.parameters:
        dim = p.dim if spec.mode == "product" else "member"
        attrs = {"sweep_key": p.key, "description": f"swept scenario value {p.key} (units of the scenario key)"}
        if p.labels is None:
            coords[p.dim] = (dim, _coord_values(p.values), attrs)
            continue
        coords[p.dim] = (dim, np.array(p.labels, dtype=str), dict(attrs, description=f"label of {p.key}"))
        numeric = None
        try:
            arr = np.array([_to_float_nested(v) for v in p.values], dtype=np.float64)
            numeric = arr
        except (TypeError, ValueError):
            pass
        if numeric is not None:
            extra = tuple(f"{p.dim}_dim{k}" for k in range(numeric.ndim - 1))
            coords[p.dim + "_value"] = ((dim,) + extra, numeric, dict(attrs, description=f"value of {p.key}"))
        else:
            coords[p.dim + "_value"] = (dim, np.array([toml_value(v) for v in p.values], dtype=str),
                                        dict(attrs, description=f"value of {p.key} (TOML text)"))
    if spec.mode == "zip":
        coords["member"] = ("member", np.arange(spec.shape[0], dtype=np.int64), {"description": "member number - 1"})
    return coords


def _to_float_nested(v):
    if isinstance(v, tuple):
        return [_to_float_nested(x) for x in v]
    if isinstance(v, bool) or not isinstance(v, (int, Decimal)):
        raise TypeError("not numeric")
    return float(v)


def gather(plan: SweepPlan, outcomes: Sequence[MemberOutcome]) -> tuple[Any, list[MemberOutcome]]:
    """Merge the members' trajectories into one ``xarray.Dataset``.

    Dimensions: the member dimensions (``product``: one per parameter, named
    by :attr:`Parameter.dim`, coordinate = values or labels, plus
    ``<name>_value`` for labelled parameters; ``zip``: ``member`` with each
    parameter as a coordinate on it), then the trajectory dimensions of
    :meth:`tqdyn.formats.trajectory.Trajectory.to_xarray` (``time`` [s TT since epoch],
    ``sat``, ``tm``, ``comp``, ...).  Every trajectory variable gets the member
    dimensions in front (``t_lo`` excepted: one time grid); failed members
    and variables a member lacks are NaN.  Per-member variables: ``ok``
    (bool), ``error`` (str, "" if ok), ``member_file`` (file name in
    output_dir), ``scenario`` (resolved scenario TOML).  Root attributes:
    those equal in all members' files (``scenario`` aside) and ``sweep``
    (the sweep as TOML), ``sweep_name``, ``sweep_mode``.

    Returns (dataset or None if no member succeeded, outcomes updated with
    members whose file could not be read).  Raises ValueError if members
    have different time grids.
    """
    import xarray as xr

    spec = plan.spec
    by_index = {o.member.index: o for o in outcomes}
    outcomes = list(outcomes)
    datasets: dict[int, Any] = {}
    for m in plan.members:
        o = by_index.get(m.index)
        if o is None or not o.ok:
            continue
        try:
            datasets[m.index] = io.read_trajectory(m.path).to_xarray()
        except (OSError, ValueError) as exc:
            new = MemberOutcome(m, "failed", error=f"cannot read its trajectory file: {one_line(exc)}",
                                lost_workers=o.lost_workers)
            outcomes[outcomes.index(o)] = new
            by_index[m.index] = new
    if not datasets:
        return None, outcomes
    first = min(datasets)
    ref = datasets[first]
    ref_member = plan.members[first]
    coord_of: dict[str, tuple[int, Any]] = {}  # trajectory coordinates: the union over the members
    for idx, ds in datasets.items():
        for c, var in ds.coords.items():
            if c not in coord_of:
                coord_of[c] = (idx, var)
                continue
            k, seen = coord_of[c]
            if not np.array_equal(var.values, seen.values):
                what = "time grid" if c == "time" else f"coordinate {c!r}"
                raise ValueError(f"sweep {plan.members[idx].label} has another {what} than {plan.members[k].label}: "
                                 f"{_describe_coord(ds, c)} vs {_describe_coord(datasets[k], c)}; all members need "
                                 "one time grid (run.duration, integrator.step, run.output_every in sweep.set)")
        if "t_lo" in ref and "t_lo" in ds and not np.array_equal(ds["t_lo"].values, ref["t_lo"].values):
            raise ValueError(f"sweep {plan.members[idx].label} has another time grid (t_lo) than {ref_member.label}")
    dims, shape = spec.dims, spec.shape
    templates: dict[str, Any] = {}
    for ds in datasets.values():
        for name, var in ds.data_vars.items():
            if name != "t_lo":
                templates.setdefault(name, var)
    variables: dict[str, Any] = {}
    for name, var in templates.items():
        arr = np.full(shape + var.shape, np.nan, dtype=np.float64)
        for idx, ds in datasets.items():
            if name in ds:
                if ds[name].shape != var.shape:
                    raise ValueError(f"sweep {plan.members[idx].label}: variable {name!r} has shape "
                                     f"{ds[name].shape}, {ref_member.label} {var.shape}")
                arr[plan.members[idx].position] = ds[name].values
        variables[name] = (dims + var.dims, arr, dict(var.attrs))
    if "t_lo" in ref:
        variables["t_lo"] = (ref["t_lo"].dims, ref["t_lo"].values, dict(ref["t_lo"].attrs))
    ok = np.zeros(shape, dtype=bool)
    error = np.full(shape, "", dtype=object)
    files = np.full(shape, "", dtype=object)
    scenarios = np.full(shape, "", dtype=object)
    for m in plan.members:
        o = by_index.get(m.index)
        ok[m.position] = o is not None and o.ok
        error[m.position] = "" if o is None else o.error
        files[m.position] = m.path.name
        scenarios[m.position] = m.scenario_toml
    variables["ok"] = (dims, ok, {"description": "the member ran; false: its values are NaN (see error)"})
    variables["error"] = (dims, error.astype(str), {"description": "one-line error of a failed member, else empty"})
    variables["member_file"] = (dims, files.astype(str), {"description": "trajectory file of the member in the sweep's "
                                                                       "output directory"})
    variables["scenario"] = (dims, scenarios.astype(str), {"description": "resolved scenario of the member (TOML)"})
    coords = {name: (c.dims, c.values, dict(c.attrs)) for name, (_, c) in coord_of.items()}
    coords.update(_param_coords(spec, dims))
    attrs = {}
    for key, value in ref.attrs.items():
        if key != "scenario" and all(ds.attrs.get(key) == value for ds in datasets.values()):
            attrs[key] = value
    attrs.update(sweep=spec.to_toml(), sweep_name=spec.name, sweep_mode=spec.mode,
                 sweep_failed_members=int((~ok).sum()),
                 sweep_note="failed members are NaN-filled (variable ok = false, their error in variable error)")
    return xr.Dataset(variables, coords=coords, attrs=attrs), outcomes


def _describe_coord(ds, c) -> str:
    v = ds[c].values
    if v.size and c == "time":
        return f"{v.size} rows {v[0]:g}..{v[-1]:g} s"
    return f"{v.size} values"
