"""Parameter sweeps: many scenarios run in parallel on Dask (``tqdyn sweep``).

A sweep file (TOML, documented in ``docs/sweeps.md``) names a base scenario,
overrides common to every member and one or more varied parameters::

    [sweep]
    name = "self-gravity-directions"   # default: the sweep file's stem
    scenario = "tianqin"                # built-in name or path (relative: to the sweep file)
    output_dir = "sweep-out"            # default: "<sweep file stem>-out" next to the sweep file
    set = ["run.duration=1d"]           # overrides common to all members
    mode = "product"                    # "product" (grid) | "zip" (parallel lists)

    [[sweep.parameter]]
    key = "spacecraft.self_gravity_common"   # any scenario override key
    values = [[1e-9, 0, 0], [-1e-9, 0, 0]]
    labels = ["+x", "-x"]                # needed for non-scalar values
    name = "direction"                   # coordinate name (default: "self_gravity_common")

Each member is the base scenario + ``set`` + its parameter values (applied
as ``--set`` overrides would be).  Its trajectory file is
``<output_dir>/member-<hash>.h5``, the hash being a short SHA-256 of the
member's resolved scenario TOML (with ``run.output`` normalised): a re-run
skips every member whose file exists, ends at ``run.duration`` and stores
that same resolved scenario; anything else is run again.

Members run as Dask tasks (one task = one :func:`tqdyn.runner.run_to_file`,
quiet, no checkpoint) on a new ``distributed.LocalCluster`` (processes,
1 thread each) or on an existing cluster given by its scheduler address.  A
member that raises does not stop the others; it is reported with its
parameters and a one-line error.

Gathering: one ``xarray.Dataset`` holding every member's
:meth:`tqdyn.io.Trajectory.to_xarray` variables with the varied parameters as
leading dimensions (``product``: one dimension per parameter; ``zip``: one
``member`` dimension with every parameter as a coordinate on it).  Failed
members are **NaN-filled** (never dropped: the grid stays rectangular) and
flagged by the boolean variable ``ok``; ``error`` holds their one-line error.
It is written to ``<output_dir>/<name>.nc`` (netCDF-4/HDF5 through xarray's
``h5netcdf`` engine, or ``netcdf4`` if only that is installed).

Units and conventions are those of the trajectory files: SI, GCRS, time
``time`` in TDB seconds since each member's ``epoch_utc``; all members must
share one time grid (checked before anything runs).

Errors in the sweep file raise :class:`SweepError` (a ``ValueError``, one
line) before anything is submitted.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import hashlib
import importlib.util
import itertools
import logging
import os
import re
import secrets
import time
import tomllib
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np

from ..formats import trajectory as io
from ..scenario import (
    DEFAULT_SCENARIO,
    ScenarioError,
    builtin_scenarios,
    load_scenario,
    loads_scenario,
)

__all__ = [
    "MODES",
    "Member",
    "MemberOutcome",
    "Parameter",
    "SweepError",
    "SweepPlan",
    "SweepResult",
    "SweepSpec",
    "default_workers",
    "dask_client",
    "gather",
    "load_sweep",
    "loads_sweep",
    "member_done",
    "netcdf_engine",
    "plan_sweep",
    "run_sweep",
    "write_netcdf",
]

#: Sweep modes: ``product`` (every combination, one dimension per parameter)
#: and ``zip`` (the i-th values of all parameters form member i).
MODES = ("product", "zip")

_SWEEP_KEYS = ("name", "scenario", "output_dir", "set", "mode", "parameter")
_PARAM_KEYS = ("key", "values", "labels", "name")
_NAME_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.+-]*$")
_IDENT_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_KEY_RE = re.compile(r"^(?:[A-Za-z_][A-Za-z0-9_]*\.[A-Za-z_][A-Za-z0-9_]*|satellites\.[0-9]+\.[A-Za-z_][A-Za-z0-9_]*)$")
#: ``run.output`` of the scenario that is hashed (the real one is the member file).
_OUTPUT_PLACEHOLDER = "sweep-member.h5"
_DIGEST_CHARS = 12
# names the gathered dataset uses itself (trajectory dimensions and variables are added below)
_RESERVED = {"time", "sat", "tm", "comp", "row", "col", "member", "ok", "error", "member_file", "scenario", "t_lo"}
_NETCDF_ENGINES = (("h5netcdf", "h5netcdf"), ("netCDF4", "netcdf4"))


class SweepError(ScenarioError):
    """Invalid sweep: one line ``"<field>: <value> <problem>; allowed: <allowed>"``.

    ``field`` is a dotted path in the sweep file (``"sweep.parameter.2.values"``)
    or names a member (``"sweep member 3 (a_km=100010)"``).  A ``ValueError``.
    """


def _err(field_: str, *args, **kwargs) -> SweepError:
    return SweepError(field_, *args, **kwargs)


# --------------------------------------------------------------------------- values -> override text


def _toml_str(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_text(value: Any) -> str:
    """A sweep value as TOML text (the right-hand side of an override)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, (Decimal, float)):
        d = Decimal(repr(value)) if isinstance(value, float) else value
        if d.is_nan():
            return "nan"
        if d.is_infinite():
            return "-inf" if d < 0 else "inf"
        return str(d)
    if isinstance(value, str):
        return _toml_str(value)
    if isinstance(value, (_dt.datetime, _dt.date, _dt.time)):
        return value.isoformat()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")  # pragma: no cover - validated


def _check_value(value: Any, where: str, whole: Any) -> Any:
    """Validate one sweep value (a TOML scalar or a nested array of them); lists become tuples."""
    if isinstance(value, (list, tuple)):
        return tuple(_check_value(v, where, whole) for v in value)
    if isinstance(value, (bool, int, Decimal, str, _dt.datetime, _dt.date, _dt.time)):
        return value
    if isinstance(value, float):
        return Decimal(repr(value))
    kind = "a table" if isinstance(value, dict) else f"a {type(value).__name__}"
    raise _err(where, whole, f"contains {kind}",
               "numbers, strings, booleans, date-times, or arrays of them (as the scenario key takes)")


def _scalar_kind(value: Any) -> str | None:
    """Coordinate kind of a scalar value ("number", "string", "boolean"), None for arrays etc."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, Decimal)):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, (_dt.datetime, _dt.date, _dt.time)):
        return "date-time"
    return None


def _display(value: Any) -> str:
    """A value as it appears in reports: a string as is, anything else as its TOML text."""
    return value if isinstance(value, str) else _toml_text(value)


# --------------------------------------------------------------------------- the sweep spec


@dataclass(frozen=True)
class Parameter:
    """One varied scenario key.

    ``key``: an override key of the scenario (``"section.key"`` or
    ``"satellites.N.key"``, as for ``tqdyn run --set``); ``values``: the
    values it takes (TOML values: numbers, strings, booleans or arrays, in
    the units the scenario key implies, e.g. ``a_km`` in km,
    ``self_gravity_common`` in m/s^2); ``labels``: optional coordinate
    labels, one per value (required when the values are not all scalars of
    one kind); ``name``: coordinate / dimension name in the gathered
    dataset (default: the key's last component).
    """

    key: str
    values: tuple
    labels: tuple[str, ...] | None = None
    name: str | None = None

    @property
    def dim(self) -> str:
        """Coordinate / dimension name: ``name`` or the key's last component."""
        return self.name if self.name is not None else self.key.rsplit(".", 1)[-1]

    def display(self, i: int) -> str:
        """How value ``i`` is shown in reports: its label, else its TOML text."""
        return self.labels[i] if self.labels is not None else _display(self.values[i])


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep.

    ``name``: sweep name (file-name safe; the gathered file is
    ``<output_dir>/<name>.nc``); ``scenario``: built-in scenario name or an
    absolute path of a scenario TOML file; ``output_dir``: absolute
    directory of the member files and the gathered dataset; ``common``:
    overrides applied to every member (the sweep file's ``set``; not
    ``run.output``); ``mode``: ``"product"`` or ``"zip"``; ``parameters``:
    the varied keys (at least one); ``source``: the sweep file, if any.
    Construction validates everything that does not need the scenario
    (:func:`plan_sweep` loads every member); raises :class:`SweepError`.
    """

    name: str
    parameters: tuple[Parameter, ...]
    scenario: str = DEFAULT_SCENARIO
    output_dir: Path = Path("sweep-out")
    common: tuple[str, ...] = ()
    mode: str = "product"
    source: Path | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and _NAME_RE.match(self.name)):
            raise _err("sweep.name", self.name, "is not a valid sweep name",
                       "letters, digits and _ . + - (not starting with . + -); it names <name>.nc")
        if not (isinstance(self.scenario, str) and self.scenario.strip()):
            raise _err("sweep.scenario", self.scenario, "is not a scenario name or path",
                       "a built-in scenario (" + ", ".join(builtin_scenarios()) + ") or a .toml path")
        if not isinstance(self.output_dir, (str, os.PathLike)) or not os.fspath(self.output_dir).strip():
            raise _err("sweep.output_dir", self.output_dir, "is not a directory path", "a directory path")
        object.__setattr__(self, "output_dir", Path(os.path.abspath(os.path.expanduser(os.fspath(self.output_dir)))))
        if not isinstance(self.common, (list, tuple)) or not all(isinstance(s, str) for s in self.common):
            raise _err("sweep.set", self.common, "is not a list of strings", 'override strings "section.key=value"')
        object.__setattr__(self, "common", tuple(self.common))
        common_keys: dict[str, int] = {}
        for k, item in enumerate(self.common, start=1):
            key = item.split("=", 1)[0].strip()
            if "=" not in item or not _KEY_RE.match(key):
                raise _err(f"sweep.set.{k}", item, "is not an override",
                           '"section.key=value" or "satellites.N.key=value"')
            if key == "run.output":
                raise _err(f"sweep.set.{k}", item, "sets run.output",
                           "any other key: the sweep names the member files (sweep.output_dir)")
            common_keys[key] = k
        if self.mode not in MODES:
            raise _err("sweep.mode", self.mode, "is not a valid choice", ", ".join(repr(m) for m in MODES))
        params = self.parameters
        if isinstance(params, Parameter):
            params = (params,)
        params = tuple(params)
        if not params:
            raise _err("sweep.parameter", [], "is empty", "at least one [[sweep.parameter]] table")
        checked = []
        for i, p in enumerate(params, start=1):
            checked.append(_check_parameter(p, i, common_keys, self.mode))
        params = tuple(checked)
        seen_keys: dict[str, int] = {}
        seen_dims: dict[str, int] = {}
        for i, p in enumerate(params, start=1):
            if p.key in seen_keys:
                raise _err(f"sweep.parameter.{i}.key", p.key, f"is also the key of sweep.parameter.{seen_keys[p.key]}",
                           "each key in one parameter (use mode = \"zip\" to vary keys together)")
            seen_keys[p.key] = i
            for dim in (p.dim, p.dim + "_value"):
                if dim in seen_dims:
                    raise _err(f"sweep.parameter.{i}.name", p.dim,
                               f"clashes with the name of sweep.parameter.{seen_dims[dim]}",
                               'a unique name: give each parameter its own name = "..."')
                seen_dims[dim] = i
        if self.mode == "zip":
            n0 = len(params[0].values)
            for i, p in enumerate(params[1:], start=2):
                if len(p.values) != n0:
                    raise _err(f"sweep.parameter.{i}.values",
                               problem=f"has {len(p.values)} values, sweep.parameter.1 has {n0} (zip mode)",
                               allowed='value lists of equal length, or mode = "product"')
        object.__setattr__(self, "parameters", params)
        if self.source is not None:
            object.__setattr__(self, "source", Path(self.source))

    @property
    def dims(self) -> tuple[str, ...]:
        """Member dimensions of the gathered dataset."""
        return tuple(p.dim for p in self.parameters) if self.mode == "product" else ("member",)

    @property
    def shape(self) -> tuple[int, ...]:
        """Length of each member dimension."""
        if self.mode == "product":
            return tuple(len(p.values) for p in self.parameters)
        return (len(self.parameters[0].values),)

    @property
    def n_members(self) -> int:
        """Number of members."""
        return int(np.prod(self.shape))

    @property
    def output(self) -> Path:
        """The gathered dataset: ``<output_dir>/<name>.nc``."""
        return self.output_dir / f"{self.name}.nc"

    def to_toml(self) -> str:
        """The sweep as TOML text (paths resolved; :func:`loads_sweep` reads it back)."""
        out = ["[sweep]", f"name = {_toml_str(self.name)}", f"scenario = {_toml_str(self.scenario)}",
               f"output_dir = {_toml_str(str(self.output_dir))}",
               "set = [" + ", ".join(_toml_str(s) for s in self.common) + "]", f"mode = {_toml_str(self.mode)}"]
        for p in self.parameters:
            out += ["", "[[sweep.parameter]]", f"key = {_toml_str(p.key)}", f"values = {_toml_text(p.values)}"]
            if p.labels is not None:
                out.append("labels = [" + ", ".join(_toml_str(s) for s in p.labels) + "]")
            if p.name is not None:
                out.append(f"name = {_toml_str(p.name)}")
        return "\n".join(out) + "\n"


def _reserved_names() -> set[str]:
    names = set(_RESERVED)
    for f in io.FIELDS:
        n = f.replace("/", "_")
        names |= {n, n + "_lo"}
    return names


def _check_parameter(p: Any, i: int, common_keys: dict[str, int], mode: str) -> Parameter:
    where = f"sweep.parameter.{i}"
    if not isinstance(p, Parameter):
        raise _err(where, p, "is not a Parameter", "tqdyn.sweep.Parameter(key, values, labels=None, name=None)")
    key = p.key
    if not (isinstance(key, str) and _KEY_RE.match(key.strip())):
        raise _err(f"{where}.key", key, "is not a scenario key",
                   '"section.key" or "satellites.N.key" (as for tqdyn run --set)')
    key = key.strip()
    if key == "run.output":
        raise _err(f"{where}.key", key, "cannot be varied", "any other key: the sweep names the member files")
    if key in common_keys:
        raise _err(f"{where}.key", key, f"is also set in sweep.set (item {common_keys[key]})",
                   "a key either in sweep.set or varied, not both")
    values = p.values
    if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple)):
        raise _err(f"{where}.values", values, "is not an array", "a non-empty array of values")
    if len(values) == 0:
        raise _err(f"{where}.values", [], "is empty", "a non-empty array of values")
    values = tuple(_check_value(v, f"{where}.values", list(values)) for v in values)
    labels = p.labels
    if labels is not None:
        if isinstance(labels, str) or not isinstance(labels, (list, tuple)) \
                or not all(isinstance(s, str) and s.strip() for s in labels):
            raise _err(f"{where}.labels", labels, "is not an array of non-empty strings",
                       f"{len(values)} distinct non-empty strings, one per value")
        labels = tuple(labels)
        if len(labels) != len(values):
            raise _err(f"{where}.labels", list(labels), f"has {len(labels)} labels for {len(values)} values",
                       "one label per value")
        if len(set(labels)) != len(labels):
            dup = next(s for s in labels if labels.count(s) > 1)
            raise _err(f"{where}.labels", dup, "is repeated", "distinct labels")
    else:
        kinds = {_scalar_kind(v) for v in values}
        if None in kinds or len(kinds) != 1:
            raise _err(f"{where}.labels", problem="are missing: the values are "
                       + ("not all scalars" if None in kinds else "of mixed kinds (" + ", ".join(sorted(kinds)) + ")"),
                       allowed="labels = [...] (one string per value) for array or mixed values")
        coord = _coord_values(values)
        if mode == "product" and len(set(coord.tolist())) != len(coord):
            dup = next(values[j] for j in range(len(values)) if coord.tolist().count(coord[j]) > 1)
            raise _err(f"{where}.values", dup, "is repeated", "distinct values (each value once)")
    name = p.name
    if name is not None and not (isinstance(name, str) and _IDENT_RE.match(name)):
        raise _err(f"{where}.name", name, "is not a valid coordinate name",
                   "a name of letters, digits and _ not starting with a digit")
    dim = name if name is not None else key.rsplit(".", 1)[-1]
    if dim in _reserved_names() or dim + "_value" in _reserved_names():
        raise _err(f"{where}.name", dim, "is a name the gathered dataset already uses",
                   'another name: give name = "..."')
    return Parameter(key=key, values=values, labels=labels, name=name)


def _coord_values(values: Sequence) -> np.ndarray:
    """Index coordinate of unlabelled scalar values of one kind (numbers, strings, booleans, date-times)."""
    kind = _scalar_kind(values[0])
    if kind == "boolean":
        return np.array(values, dtype=bool)
    if kind == "number":
        if all(isinstance(v, int) for v in values):
            return np.array(values, dtype=np.int64)
        return np.array([float(v) for v in values], dtype=np.float64)
    if kind == "date-time":
        return np.array([v.isoformat() for v in values], dtype=str)
    return np.array(values, dtype=str)


# --------------------------------------------------------------------------- reading sweep files


def _resolve_scenario(name: str, base_dir: Path) -> str:
    """A built-in scenario name as is; otherwise an absolute path (relative: to ``base_dir``)."""
    looks_like_path = name.endswith(".toml") or os.sep in name or (os.altsep is not None and os.altsep in name)
    if not looks_like_path and name in builtin_scenarios():
        return name
    path = Path(os.path.expanduser(name))
    if not path.is_absolute():
        path = base_dir / path
    path = Path(os.path.abspath(path))
    if not path.is_file():
        raise _err("sweep.scenario", name, f"is neither a built-in scenario nor a file (looked for {str(path)!r})",
                   "a built-in scenario (" + ", ".join(builtin_scenarios()) + ") or a .toml path "
                   "(relative paths: relative to the sweep file)")
    return str(path)


def loads_sweep(text: str, *, base_dir: str | os.PathLike = ".", default_name: str | None = None,
                source: str = "<string>") -> SweepSpec:
    """Parse and validate a sweep from TOML ``text``.

    Relative ``scenario`` and ``output_dir`` paths are taken relative to
    ``base_dir``; ``default_name`` is the sweep name (and the stem of the
    default output directory ``<default_name>-out``) when the text has no
    ``sweep.name``; ``source`` names the text in error messages.  Numbers
    are read exactly (``Decimal``).  Raises :class:`SweepError`.
    """
    base = Path(os.path.abspath(os.path.expanduser(os.fspath(base_dir))))
    try:
        raw = tomllib.loads(text, parse_float=Decimal)
    except tomllib.TOMLDecodeError as exc:
        raise _err(source, problem=f"is not valid TOML ({exc})", allowed="a TOML document with a [sweep] table") from None
    for key in raw:
        if key != "sweep":
            raise _err(key, problem=f"is not a known key of {source}", allowed="one [sweep] table")
    table = raw.get("sweep")
    if not isinstance(table, dict):
        raise _err("sweep", problem=f"is missing from {source}" if table is None else "is not a table",
                   allowed="a [sweep] table with scenario, set, mode and [[sweep.parameter]] tables")
    for key in table:
        if key not in _SWEEP_KEYS:
            raise _err(f"sweep.{key}", problem="is not a known key", allowed=", ".join(_SWEEP_KEYS))

    def string(key, default):
        value = table.get(key, default)
        if not isinstance(value, str):
            raise _err(f"sweep.{key}", value, "is not a string", "a string")
        return value

    name = table.get("name", default_name)
    if name is None:
        raise _err("sweep.name", problem="is missing", allowed="a sweep name (letters, digits, _ . + -)")
    scenario = _resolve_scenario(string("scenario", DEFAULT_SCENARIO), base)
    out_default = f"{default_name if default_name is not None else name}-out"
    output_dir = Path(os.path.expanduser(string("output_dir", out_default)))
    if not output_dir.is_absolute():
        output_dir = base / output_dir
    common = table.get("set", [])
    if not isinstance(common, list) or not all(isinstance(s, str) for s in common):
        raise _err("sweep.set", common, "is not an array of strings", 'override strings "section.key=value"')
    mode = table.get("mode", "product")
    raw_params = table.get("parameter")
    if raw_params is None:
        raise _err("sweep.parameter", problem="is missing", allowed="at least one [[sweep.parameter]] table")
    if not isinstance(raw_params, list) or not all(isinstance(p, dict) for p in raw_params):
        raise _err("sweep.parameter", raw_params, "is not an array of tables", "[[sweep.parameter]] tables")
    params = []
    for i, p in enumerate(raw_params, start=1):
        for key in p:
            if key not in _PARAM_KEYS:
                raise _err(f"sweep.parameter.{i}.{key}", problem="is not a known key", allowed=", ".join(_PARAM_KEYS))
        for key in ("key", "values"):
            if key not in p:
                raise _err(f"sweep.parameter.{i}.{key}", problem="is missing",
                           allowed="a scenario key" if key == "key" else "a non-empty array of values")
        params.append(Parameter(key=p["key"], values=p["values"], labels=p.get("labels"), name=p.get("name")))
    return SweepSpec(name=name, parameters=tuple(params), scenario=scenario, output_dir=output_dir,
                     common=tuple(common), mode=mode, source=Path(source) if source != "<string>" else None)


def load_sweep(path: str | os.PathLike) -> SweepSpec:
    """Read a sweep file (see :func:`loads_sweep`; paths relative to its directory,
    default name its stem).  Raises :class:`SweepError` or ``FileNotFoundError``."""
    p = Path(os.path.abspath(os.path.expanduser(os.fspath(path))))
    if not p.is_file():
        raise FileNotFoundError(f"sweep file {str(p)!r} " + ("is not a file" if p.exists() else "does not exist"))
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _err("sweep file", str(p), f"cannot be read ({exc})", "a readable UTF-8 TOML file") from None
    stem = p.stem if _NAME_RE.match(p.stem) else None
    return loads_sweep(text, base_dir=p.parent, default_name=stem, source=str(p))


# --------------------------------------------------------------------------- members


@dataclass(frozen=True)
class Member:
    """One scenario of a sweep.

    ``index``: 0-based member number (C order over the grid in product
    mode); ``position``: its index along each member dimension;
    ``params``: ``(coordinate name, displayed value)`` pairs;
    ``overrides``: the scenario overrides that make it; ``digest``: short
    hash of ``canonical_toml`` (its resolved scenario with ``run.output``
    normalised); ``path``: its trajectory file; ``scenario_toml``: the
    resolved scenario it runs (``run.output`` = ``path``).
    """

    index: int
    position: tuple[int, ...]
    params: tuple[tuple[str, str], ...]
    overrides: tuple[str, ...]
    canonical_toml: str
    digest: str
    path: Path
    scenario_toml: str

    @property
    def label(self) -> str:
        """``"member 3 (a_km=100010, direction=+y)"`` (1-based number)."""
        return f"member {self.index + 1} (" + ", ".join(f"{k}={v}" for k, v in self.params) + ")"


def _positions(spec: SweepSpec) -> Iterator[tuple[tuple[int, ...], tuple[int, ...]]]:
    """(position in the dataset, value index of each parameter) of every member, in member order."""
    if spec.mode == "product":
        for pos in itertools.product(*(range(len(p.values)) for p in spec.parameters)):
            yield pos, pos
    else:
        for k in range(len(spec.parameters[0].values)):
            yield (k,), (k,) * len(spec.parameters)


def _time_grid(scen) -> tuple:
    return (scen.run.duration_s, scen.integrator.step_s, scen.run.output_every, len(scen.satellites))


def _resolve_members(spec: SweepSpec) -> tuple[Member, ...]:
    try:
        load_scenario(spec.scenario)
    except ScenarioError as exc:
        raise _err(f"sweep.scenario {spec.scenario!r}", problem=str(exc)) from None
    try:
        load_scenario(spec.scenario, spec.common)
    except ScenarioError as exc:
        raise _err("sweep.set", problem=str(exc)) from None
    for i, p in enumerate(spec.parameters, start=1):
        try:
            load_scenario(spec.scenario, spec.common + (f"{p.key}={_toml_text(p.values[0])}",))
        except ScenarioError as exc:
            if exc.field.startswith("override"):
                raise _err(f"sweep.parameter.{i}.key", problem=str(exc)) from None
    members: list[Member] = []
    by_digest: dict[str, Member] = {}
    grid0 = None
    for index, (position, which) in enumerate(_positions(spec)):
        params = tuple((p.dim, p.display(j)) for p, j in zip(spec.parameters, which))
        label = f"sweep member {index + 1} (" + ", ".join(f"{k}={v}" for k, v in params) + ")"
        overrides = spec.common + tuple(f"{p.key}={_toml_text(p.values[j])}" for p, j in zip(spec.parameters, which))
        try:
            scen = load_scenario(spec.scenario, overrides + (f"run.output={_OUTPUT_PLACEHOLDER}",))
        except ScenarioError as exc:
            raise _err(label, problem=str(exc)) from None
        grid = _time_grid(scen)
        if grid0 is None:
            grid0 = grid
        elif grid != grid0:
            raise _err(label, problem=f"has another time grid (run.duration {grid[0]} s, integrator.step {grid[1]} s, "
                       f"run.output_every {grid[2]}) than member 1 ({grid0[0]} s, {grid0[1]} s, {grid0[2]})",
                       allowed="one time grid for all members: set run.duration, integrator.step and "
                               "run.output_every in sweep.set, not as parameters")
        canonical = scen.to_toml()
        digest = hashlib.sha256(canonical.encode("utf-8")).hexdigest()[:_DIGEST_CHARS]
        if digest in by_digest:
            other = by_digest[digest]
            raise _err(label, problem=f"is the same scenario as sweep {other.label}",
                       allowed="distinct members (a value repeated, or a parameter without effect?)")
        path = spec.output_dir / f"member-{digest}.h5"
        final = dataclasses.replace(scen, run=dataclasses.replace(scen.run, output=str(path)))
        m = Member(index=index, position=position, params=params, overrides=overrides, canonical_toml=canonical,
                   digest=digest, path=path, scenario_toml=final.to_toml())
        by_digest[digest] = m
        members.append(m)
    return tuple(members)


def member_done(member: Member) -> bool:
    """True if ``member.path`` is a complete trajectory of this member: a
    readable tqdyn trajectory whose stored resolved scenario equals the
    member's (``run.output`` aside, so a moved output directory still counts)
    and whose last time row is ``run.duration``.  Anything else (missing,
    unreadable, another scenario, cut short) is False: the member is run."""
    import h5py

    try:
        with h5py.File(member.path, "r") as h5:
            if h5.attrs.get("format") != io.FORMAT:
                return False
            stored = h5.attrs.get("scenario", "")
            stored = stored.decode("utf-8") if isinstance(stored, bytes) else str(stored)
            t_hi, t_lo = h5["t/hi"], h5["t/lo"]
            n = t_hi.shape[0]
            if n == 0:
                return False
            t_end = float(t_hi[n - 1]) + float(t_lo[n - 1])
    except (OSError, KeyError, ValueError, TypeError):
        return False
    try:
        scen = loads_scenario(stored, [f"run.output={_OUTPUT_PLACEHOLDER}"])
    except ScenarioError:
        return False
    if scen.to_toml() != member.canonical_toml:
        return False
    return abs(t_end - float(scen.run.duration_s)) <= 1e-6 * max(1.0, float(scen.integrator.step_s))


@dataclass(frozen=True)
class SweepPlan:
    """A sweep resolved into members: ``spec``, ``members`` (in member order)
    and ``done`` (per member: its file is complete, see :func:`member_done`)."""

    spec: SweepSpec
    members: tuple[Member, ...]
    done: tuple[bool, ...]

    @property
    def pending(self) -> tuple[Member, ...]:
        """Members still to run."""
        return tuple(m for m, d in zip(self.members, self.done) if not d)


def plan_sweep(path_or_spec: str | os.PathLike | SweepSpec) -> SweepPlan:
    """Validate a sweep completely (file, base scenario, common overrides,
    every member's scenario, one time grid, no two identical members) and
    find which members are already done.  Submits and writes nothing.
    Raises :class:`SweepError` / ``FileNotFoundError``."""
    spec = path_or_spec if isinstance(path_or_spec, SweepSpec) else load_sweep(path_or_spec)
    members = _resolve_members(spec)
    return SweepPlan(spec=spec, members=members, done=tuple(member_done(m) for m in members))


# --------------------------------------------------------------------------- running


@dataclass(frozen=True)
class MemberOutcome:
    """What happened to one member: ``status`` is "done" (its file was
    already complete; skipped), "ran" or "failed"; ``error``: one line
    ``"<ExceptionType>: <message>"`` for failures; ``traceback``: the
    worker's traceback text (failures during the run); ``wall_s`` /
    ``compile_s``: propagation / JIT time of a run [s]; ``rows``: time rows
    written."""

    member: Member
    status: str
    error: str = ""
    traceback: str = ""
    wall_s: float = 0.0
    compile_s: float = 0.0
    rows: int = 0

    @property
    def ok(self) -> bool:
        """True if the member's trajectory file is complete."""
        return self.status != "failed"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _run_member(scenario_toml: str) -> dict:
    """Dask task: run one member (its resolved scenario TOML) to its file.
    Never raises: returns a dict with ``ok`` and the run's numbers or the error."""
    from . import run as runner

    try:
        scen = loads_scenario(scenario_toml, source="sweep member")
        summary = runner.run_to_file(scen)
    except Exception as exc:  # noqa: BLE001 - reported per member; the others go on
        return {"ok": False, "error": _one_line(exc), "traceback": traceback.format_exc()}
    return {"ok": True, "rows": int(summary.rows), "wall_s": float(summary.result.wall_s),
            "compile_s": float(summary.compile_s)}


def default_workers() -> int:
    """Default size of the local cluster: the CPU cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def dask_client(scheduler, n_workers: int | None, n_tasks: int):
    """A distributed.Client: the given one, one connected to ``scheduler`` (an
    address), or one on a new LocalCluster (processes, 1 thread each, at most
    ``n_workers`` (default: the usable cores) and at most ``n_tasks``
    workers).  Also used by :mod:`tqdyn.studies`."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler is not None:
        if not isinstance(scheduler, str) or not scheduler.strip():
            raise _err("scheduler", scheduler, "is not an address", "a Dask scheduler address, e.g. tcp://host:8786")
        try:
            client = Client(scheduler)  # timeout: dask config distributed.comm.timeouts.connect
        except (OSError, TimeoutError, ValueError) as exc:
            raise _err("scheduler", scheduler, f"cannot be reached ({_one_line(exc)})",
                       "the address of a running Dask scheduler, e.g. tcp://host:8786") from None
        with client:
            yield client
        return
    n = default_workers() if n_workers is None else n_workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise _err("workers", n_workers, "is not a positive integer", "an integer >= 1")
    n = min(n, max(n_tasks, 1))
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        yield client


def _execute(pending: Sequence[Member], scheduler, n_workers, progress) -> list[MemberOutcome]:
    from distributed import as_completed

    outcomes: list[MemberOutcome] = []
    with dask_client(scheduler, n_workers, len(pending)) as client:
        token = secrets.token_hex(4)
        futures = {client.submit(_run_member, m.scenario_toml, key=f"tqdyn-member-{m.digest}-{token}", pure=False): m
                   for m in pending}
        try:
            for fut in as_completed(list(futures)):
                m = futures[fut]
                try:
                    res = fut.result()
                except Exception as exc:  # noqa: BLE001 - the task could not run (e.g. its worker died)
                    res = {"ok": False, "error": _one_line(exc), "traceback": ""}
                if res["ok"]:
                    out = MemberOutcome(m, "ran", wall_s=res["wall_s"], compile_s=res["compile_s"], rows=res["rows"])
                else:
                    out = MemberOutcome(m, "failed", error=res["error"], traceback=res.get("traceback", ""))
                outcomes.append(out)
                if progress is not None:
                    progress(out)
        finally:
            client.cancel(list(futures))
    return outcomes


# --------------------------------------------------------------------------- gathering


def netcdf_engine() -> str:
    """The xarray engine used to write the gathered netCDF-4 file: "h5netcdf"
    (preferred: pure Python on h5py) or "netcdf4".  ImportError if neither
    package is installed."""
    for module, engine in _NETCDF_ENGINES:
        if importlib.util.find_spec(module) is not None:
            return engine
    raise ImportError("writing the sweep's netCDF file needs the h5netcdf package (pip install h5netcdf)")


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
            coords[p.dim + "_value"] = (dim, np.array([_toml_text(v) for v in p.values], dtype=str),
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
    :meth:`tqdyn.io.Trajectory.to_xarray` (``time`` [s TDB since epoch],
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
            new = MemberOutcome(m, "failed", error=f"cannot read its trajectory file: {_one_line(exc)}")
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


def write_netcdf(dataset, path: str | os.PathLike) -> Path:
    """Write ``dataset`` atomically as netCDF-4 (engine :func:`netcdf_engine`)
    to ``path`` (temporary file in the same directory, then renamed).
    Returns the absolute path."""
    path = Path(os.path.abspath(os.fspath(path)))
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(6)}.tmp")
    try:
        dataset.to_netcdf(tmp, engine=netcdf_engine())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path


# --------------------------------------------------------------------------- the whole sweep


@dataclass
class SweepResult:
    """Outcome of :func:`run_sweep`.

    ``plan``: the resolved sweep; ``outcomes``: one :class:`MemberOutcome`
    per member, in member order; ``dataset``: the gathered
    ``xarray.Dataset`` (None if no member succeeded); ``output``: the
    written netCDF file (None if none); ``wall_s``: wall time [s].
    """

    plan: SweepPlan
    outcomes: list[MemberOutcome]
    dataset: Any = None
    output: Path | None = None
    wall_s: float = 0.0

    @property
    def failures(self) -> list[MemberOutcome]:
        """Outcomes of the members that failed."""
        return [o for o in self.outcomes if not o.ok]

    @property
    def files(self) -> list[Path]:
        """Trajectory files of the members that succeeded, in member order."""
        return [o.member.path for o in self.outcomes if o.ok]

    @property
    def n_skipped(self) -> int:
        """Members whose file was already complete."""
        return sum(o.status == "done" for o in self.outcomes)

    @property
    def n_ran(self) -> int:
        """Members run now and successful."""
        return sum(o.status == "ran" for o in self.outcomes)


def run_sweep(path_or_spec: str | os.PathLike | SweepSpec | SweepPlan, scheduler=None, n_workers: int | None = None,
              progress: Callable[[MemberOutcome], None] | None = None) -> SweepResult:
    """Run a sweep: validate it, run the members not yet done on Dask, gather
    the results into ``<output_dir>/<name>.nc``.

    Parameters
    ----------
    path_or_spec : a sweep file, a :class:`SweepSpec` or a :class:`SweepPlan`.
    scheduler : None (a new ``distributed.LocalCluster``: processes, 1 thread
        each, ``n_workers`` of them), the address of a running Dask scheduler
        (``"tcp://host:8786"``; its workers need tqdyn and the output
        directory at the same path), or a ``distributed.Client`` (used, not
        closed).
    n_workers : LocalCluster size (default: the usable CPU cores; never more
        than the members to run).
    progress : called with each :class:`MemberOutcome` as a member finishes.

    Bad input (sweep file, scenarios, scheduler address, no netCDF engine)
    raises :class:`SweepError` / ``FileNotFoundError`` / ``ImportError``
    before anything runs.  Member failures do not raise: see
    :attr:`SweepResult.failures`.
    """
    t0 = time.perf_counter()
    plan = path_or_spec if isinstance(path_or_spec, SweepPlan) else plan_sweep(path_or_spec)
    netcdf_engine()
    out_dir = plan.spec.output_dir
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        io.check_writable(plan.spec.output)
    except (OSError, io.OutputError) as exc:
        raise _err("sweep.output_dir", str(out_dir), f"is not a writable directory ({_one_line(exc)})",
                   "a directory that can be created and written") from None
    outcomes = {m.index: MemberOutcome(m, "done") for m, d in zip(plan.members, plan.done) if d}
    if plan.pending:
        for o in _execute(plan.pending, scheduler, n_workers, progress):
            outcomes[o.member.index] = o
    ordered = [outcomes[m.index] for m in plan.members]
    dataset, ordered = gather(plan, ordered)
    output = write_netcdf(dataset, plan.spec.output) if dataset is not None else None
    return SweepResult(plan=plan, outcomes=ordered, dataset=dataset, output=output, wall_s=time.perf_counter() - t0)
