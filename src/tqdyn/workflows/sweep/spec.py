"""The sweep file: its schema and validation (:class:`SweepSpec`, :func:`loads_sweep`, :func:`load_sweep`).

The format is described in :mod:`tqdyn.workflows.sweep` and ``docs/sweeps.md``;
errors raise :class:`SweepError` (a ``ValueError``, one line).  Numbers are
kept exact (``Decimal``) and written back as TOML override text.
"""

from __future__ import annotations

import datetime as _dt
import os
import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np

from ...formats import trajectory as io
from ..._choices import allowed, did_you_mean
from ...scenario import DEFAULT_SCENARIO, ScenarioError, builtin_scenarios
from ...scenario.loader import BUILTIN_DOC
from ...scenario.toml_text import toml_str, toml_value

__all__ = ["MODES", "Parameter", "SweepError", "SweepSpec", "load_sweep", "loads_sweep"]

#: Sweep modes: ``product`` (every combination, one dimension per parameter)
#: and ``zip`` (the i-th values of all parameters form member i).
MODES = ("product", "zip")

_SWEEP_KEYS = ("name", "scenario", "output_dir", "set", "mode", "parameter")
_PARAM_KEYS = ("key", "values", "labels", "name")
#: Where the keys of a sweep file are listed.
_DOC = "docs/sweeps.md#the-sweep-file"
_NAME_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.+-]*$")
_IDENT_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_KEY_RE = re.compile(r"^(?:[A-Za-z_][A-Za-z0-9_]*\.[A-Za-z_][A-Za-z0-9_]*|satellites\.[0-9]+\.[A-Za-z_][A-Za-z0-9_]*)$")
# names the gathered dataset uses itself (trajectory dimensions and variables are added below)
_RESERVED = {"time", "sat", "tm", "comp", "row", "col", "member", "ok", "error", "member_file", "scenario", "t_lo"}


class SweepError(ScenarioError):
    """Invalid sweep: one line ``"<field>: <value> <problem>; allowed: <allowed>"``.

    ``field`` is a dotted path in the sweep file (``"sweep.parameter.2.values"``)
    or names a member (``"sweep member 3 (a_km=100010)"``).  A ``ValueError``.
    """


def _err(field_: str, *args, **kwargs) -> SweepError:
    return SweepError(field_, *args, **kwargs)


# --------------------------------------------------------------------------- values -> override text


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
    return value if isinstance(value, str) else toml_value(value)


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
            raise _err("sweep.mode", self.mode, "is not a valid choice" + did_you_mean(self.mode, MODES),
                       allowed(MODES, quote=repr))
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
        out = ["[sweep]", f"name = {toml_str(self.name)}", f"scenario = {toml_str(self.scenario)}",
               f"output_dir = {toml_str(str(self.output_dir))}",
               "set = [" + ", ".join(toml_str(s) for s in self.common) + "]", f"mode = {toml_str(self.mode)}"]
        for p in self.parameters:
            out += ["", "[[sweep.parameter]]", f"key = {toml_str(p.key)}", f"values = {toml_value(p.values)}"]
            if p.labels is not None:
                out.append("labels = [" + ", ".join(toml_str(s) for s in p.labels) + "]")
            if p.name is not None:
                out.append(f"name = {toml_str(p.name)}")
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
        raise _err(where, p, "is not a Parameter", "tqdyn.workflows.sweep.Parameter(key, values, labels=None, name=None)")
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
        where = f"({str(path)!r})" if looks_like_path else did_you_mean(name, builtin_scenarios()).strip()
        raise _err("sweep.scenario", name, f"is neither a built-in scenario nor a file {where}".rstrip(),
                   f"a .toml path or a name in {BUILTIN_DOC}")
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
            raise _err(f"sweep.{key}", problem="is not a known key" + did_you_mean(key, _SWEEP_KEYS),
                       allowed=allowed(_SWEEP_KEYS, _DOC, noun="keys"))

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
                raise _err(f"sweep.parameter.{i}.{key}", problem="is not a known key" + did_you_mean(key, _PARAM_KEYS),
                           allowed=allowed(_PARAM_KEYS, _DOC, noun="keys"))
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
