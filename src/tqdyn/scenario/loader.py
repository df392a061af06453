"""Scenario loading: TOML text or files (built-in or user) -> a validated
:class:`~tqdyn.scenario.config.Scenario`.

The TOML schema and type checks, ``--set`` overrides, ``[scenario] extends``
(a built-in scenario as the base), the lookup of the built-in scenarios
(package data ``tqdyn/scenario/builtin/*.toml``) and the duration syntax.
Numbers are read with ``tomllib.loads(..., parse_float=decimal.Decimal)`` and
kept as ``Decimal``.  Errors are :class:`~tqdyn.scenario.config.ScenarioError`.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import os
import re
import tomllib
from decimal import Decimal, localcontext
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Sequence

from ..forces.body_gms import BODY_GM_KEYS
from .config import (
    EOP_SOURCES_ALLOWED,
    INITIAL_DESIGNS,
    AccelerationsConfig,
    _EXACT,
    _NOVALUE,
    ClosedLoopConfig,
    ConstellationConfig,
    ForcesConfig,
    InitialConfig,
    IntegratorConfig,
    RunConfig,
    SatelliteConfig,
    Scenario,
    ScenarioError,
    SpacecraftConfig,
    _a,
    _require,
    _to_decimal,
    _toml_type,
)
from .._choices import did_you_mean as _did_you_mean
from .values import _one_of, _unknown_key

__all__ = [
    "builtin_scenarios",
    "closed_loop_config",
    "load_scenario",
    "loads_scenario",
    "parse_duration",
    "DEFAULT_SCENARIO",
    "DEFAULT_EPOCH_UTC",
]

DEFAULT_SCENARIO = "tianqin"
#: Epoch used when a scenario file has no ``scenario.epoch_utc`` (UTC): the
#: epoch of the TianQin Table I elements.
DEFAULT_EPOCH_UTC = "2004-06-06T00:00:00"

_UNITS = {"s": Decimal(1), "min": Decimal(60), "h": Decimal(3600), "d": Decimal(86400)}
_DURATION_RE = re.compile(r"^\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(s|min|h|d)?\s*$")
_DURATION_FORMS = 'a number of seconds or a string "<number><unit>" with unit s, min, h or d (e.g. "90d", "1.5d", "12h", "30min", "3600s")'


def _parse_duration(value: Any, name: str) -> Decimal:
    if isinstance(value, bool):
        raise ScenarioError(name, value, "is a boolean", _DURATION_FORMS)
    if isinstance(value, str):
        m = _DURATION_RE.match(value)
        if m is None:
            raise ScenarioError(name, value, "is not a duration", _DURATION_FORMS)
        with localcontext() as ctx:
            ctx.prec = _EXACT
            return Decimal(m[1]) * _UNITS[m[2] or "s"]
    if isinstance(value, (int, Decimal, float)):
        d = _to_decimal(value, name)
        return d
    raise ScenarioError(name, value, f"has type {type(value).__name__}", _DURATION_FORMS)


def parse_duration(value: Any) -> Decimal:
    """Parse a duration into seconds (``Decimal``, exact).

    Accepts numbers (seconds: int, Decimal, float) and strings
    ``"<number><unit>"`` with unit ``s``, ``min``, ``h`` or ``d`` (1 d =
    86400 s), e.g. ``"90d"`` -> 7776000, ``"1.5d"`` -> 129600.0, ``"12h"``,
    ``"30min"``, ``"3600s"``; a bare numeric string means seconds.  The sign
    is not checked here.  Raises :class:`ScenarioError` (a ``ValueError``).
    """
    return _parse_duration(value, "duration")


# --------------------------------------------------------------------------- raw table -> Scenario

_STR, _NUM, _INT, _BOOL, _DUR, _EPOCH = "string", "number", "integer", "boolean", "duration", "epoch"
_STRLIST = "list of strings"
_BOOL_OR_STR = "boolean or string"  # forces.eop: true / false or a source name
_ANY = "any"  # validated by the dataclass itself

_SCHEMA: dict[str, dict[str, str]] = {
    "scenario": {"name": _STR, "description": _STR, "epoch_utc": _EPOCH, "epoch_tdb": _EPOCH, "central_body": _STR,
                 "extends": _STR, "allow_below_surface": _BOOL},
    "run": {"duration": _DUR, "precision": _STR, "output": _STR, "output_every": _INT, "max_steps": _INT},
    "integrator": {"method": _STR, "mode": _STR, "step": _NUM, "tableau": _STR, "rtol": _NUM, "order": _INT,
                   "corrector": _STR},
    "forces": {"earth_monopole": _BOOL, "sun_monopole": _BOOL, "gm_earth": _NUM, "earth_degree": _INT, "earth_degree2_extended": _BOOL, "ephemeris": _STR,
               "third_bodies": _STRLIST, "third_bodies_extended": _STRLIST, "third_bodies_gcrs": _BOOL, "solid_tides": _BOOL, "ocean_tides_degree": _INT, "pole_tides": _BOOL,
               "atmospheric_tides": _BOOL, "moon_degree": _INT, "moon_libration": _STR, "sun_j2": _BOOL, "relativity": _BOOL,
               "earth_field_indirect": _BOOL, "eop": _BOOL_OR_STR, "eop_interpolation": _STR,
               "relativity_model": _STR,
               **{key: _NUM for key in BODY_GM_KEYS.values()}},
    "spacecraft": {"d_tm": _NUM, "d_p": _NUM, "tm_axis": _STR, "self_gravity": _ANY, "self_gravity_common": _ANY,
                   "self_gravity_center": _ANY, "self_gravity_center_span": _ANY, "architecture": _STR,
                   "dragfree": _STR, "tm_distance": _NUM, "housing_centers": _ANY, "pivots": _ANY,
                   "sensitive_axes": _ANY, "envelope_radius": _NUM},
    "initial": {"axes": _STR, "design": _STR, "arm_length": _NUM, "displacement_deg": _NUM, "rotation": _STR,
                "semi_major_axis": _NUM, "oem": _STRLIST, "oem_eme2000": _STR},
    "constellation": {"pointing": _STR, "control": _STR, "free_tms": _BOOL, "tm_gravity": _STR},
    "accelerations": {"s_frame": _ANY, "rtn": _ANY, "rtn_cos": _ANY, "rtn_sin": _ANY},
}
_SAT_SCHEMA: dict[str, str] = {
    "name": _STR, "a_km": _NUM, "e": _NUM, "i_deg": _NUM, "raan_deg": _NUM, "argp_deg": _NUM, "nu_deg": _NUM,
    "r_km": _ANY, "v_kmps": _ANY,
}
_ELEMENT_KEYS = ("a_km", "e", "i_deg", "raan_deg", "argp_deg", "nu_deg")
_TOP_KEYS = tuple(_SCHEMA) + ("satellites", "closed_loop")
#: Where the keys of each table are listed (docs/scenarios.md, "Keys"; "" the top level).
KEYS_DOC = "docs/scenarios.md#"


def keys_doc(table: str) -> str:
    """The page and anchor listing every key of scenario table ``table`` ("" the
    tables themselves, "satellites.N" a satellite's, "closed_loop..." the closed loop's)."""
    top = table.split(".", 1)[0]
    return KEYS_DOC + ({"": "keys"}.get(top, top))
#: Epoch keys: one of them sets the epoch (a file or override that sets one drops the other).
_EPOCH_KEYS = ("epoch_utc", "epoch_tdb")
# TOML key -> dataclass field, where they differ
_FIELD_OF = {"step": "step_s", "duration": "duration_s", "d_tm": "d_tm_m", "d_p": "d_p_m",
             "tm_distance": "tm_distance_m", "envelope_radius": "envelope_radius_m",
             "arm_length": "arm_length_m", "semi_major_axis": "semi_major_axis_m"}


def _typed(value: Any, kind: str, name: str) -> Any:
    """Check the TOML type of a raw value and convert it (no range checks)."""
    if kind == _STR:
        _require(isinstance(value, str), name, value, f"is {_a(_toml_type(value))}", "a string")
        return value
    if kind == _BOOL:
        _require(isinstance(value, bool), name, value, f"is {_a(_toml_type(value))}", "true or false")
        return value
    if kind == _INT:
        _require(isinstance(value, int) and not isinstance(value, bool), name, value, f"is {_a(_toml_type(value))}", "an integer")
        return value
    if kind == _NUM:
        ok = isinstance(value, (int, Decimal)) and not isinstance(value, bool)
        _require(ok, name, value, f"is {_a(_toml_type(value))}", "a number")
        _require(Decimal(value).is_finite(), name, value, "is not finite", "a finite number")
        return Decimal(value)
    if kind == _STRLIST:
        ok = isinstance(value, list) and all(isinstance(x, str) for x in value)
        _require(ok, name, value, f"is {_a(_toml_type(value))}", "a list of strings")
        return tuple(value)
    if kind == _BOOL_OR_STR:
        _require(isinstance(value, (bool, str)), name, value, f"is {_a(_toml_type(value))}", EOP_SOURCES_ALLOWED)
        return value
    if kind == _ANY:
        return value
    if kind == _DUR:
        d = _parse_duration(value, name)
        return d
    if kind == _EPOCH:
        if isinstance(value, str):
            return value
        if isinstance(value, _dt.datetime):
            off = value.utcoffset()
            _require(off is None or off == _dt.timedelta(0), name, value.isoformat(), "has a non-zero UTC offset", "a UTC date-time")
            return value.replace(tzinfo=None).isoformat()
        if isinstance(value, _dt.date):
            return value.isoformat()
        raise ScenarioError(name, value, f"is {_a(_toml_type(value))}", "a UTC date-time string YYYY-MM-DDTHH:MM:SS[.fff]")
    raise AssertionError(kind)  # pragma: no cover


def _check_table(table: Any, name: str, allowed: Sequence[str]) -> dict:
    _require(isinstance(table, dict), name, table, f"is {_a(_toml_type(table))}", "a table")
    for key in table:
        if key not in allowed:
            raise _unknown_key(f"{name}.{key}" if name else key, allowed, keys_doc(name))
    return table


def _build(cls, prefix: str, raw: Mapping[str, Any], schema: Mapping[str, str]):
    """Type-check raw TOML values, construct ``cls`` and map its errors back to TOML names."""
    kwargs: dict[str, Any] = {}
    for key, kind in schema.items():
        if key in raw:
            kwargs[_FIELD_OF.get(key, key)] = _typed(raw[key], kind, f"{prefix}.{key}")
    try:
        return cls(**kwargs)
    except ScenarioError as err:
        key = err.field.rsplit(".", 1)[-1]
        toml_key = {v: k for k, v in _FIELD_OF.items()}.get(key, key)
        value = raw.get(toml_key, err.value) if err.has_value else _NOVALUE
        raise ScenarioError(f"{prefix}.{toml_key}", value, err.problem, err.allowed) from None


def _km_vector(value: Any, name: str) -> tuple:
    """3 finite numbers in km (or km/s) -> exact Decimals in m (m/s)."""
    ok = isinstance(value, list) and len(value) == 3 and all(
        isinstance(x, (int, Decimal)) and not isinstance(x, bool) and Decimal(x).is_finite() for x in value)
    _require(ok, name, value, "is not 3 finite numbers", "an array of 3 finite numbers")
    with localcontext() as ctx:
        ctx.prec = _EXACT
        return tuple(Decimal(x) * 1000 for x in value)


def _build_satellite(raw: Any, k: int, derived: bool) -> SatelliteConfig | str:
    """A [[satellites]] table: a SatelliteConfig (elements or r, v), or only
    its name when ``derived`` (the states come from [initial])."""
    prefix = f"satellites.{k}"
    _check_table(raw, prefix, tuple(_SAT_SCHEMA))
    if derived:
        extra = [key for key in raw if key != "name"]
        _require(not extra, f"{prefix}.{extra[0] if extra else ''}", raw.get(extra[0]) if extra else None,
                 "is given, but the states come from [initial] (design or oem)",
                 "only name in [[satellites]], or initial.design = \"none\" and no initial.oem")
        return _typed(raw.get("name", f"Sat{k}"), _STR, f"{prefix}.name")
    cart = "r_km" in raw or "v_kmps" in raw
    if cart:
        given = [key for key in _ELEMENT_KEYS if key in raw]
        _require(not given, f"{prefix}.{given[0] if given else 'a_km'}", raw.get(given[0]) if given else None,
                 "is given together with r_km / v_kmps", "either Keplerian elements or a Cartesian state")
        for key in ("r_km", "v_kmps"):
            _require(key in raw, f"{prefix}.{key}", _NOVALUE, "is missing", "r_km and v_kmps, 3 numbers each")
        name = _typed(raw.get("name", f"Sat{k}"), _STR, f"{prefix}.name")
        try:
            return SatelliteConfig(name=name, r_m=_km_vector(raw["r_km"], f"{prefix}.r_km"),
                                   v_mps=_km_vector(raw["v_kmps"], f"{prefix}.v_kmps"))
        except ScenarioError as err:
            key = {"r_m": "r_km", "v_mps": "v_kmps"}.get(err.field.rsplit(".", 1)[-1])
            if key is None:
                raise
            raise ScenarioError(f"{prefix}.{key}", raw[key], err.problem, err.allowed) from None
    _require("a_km" in raw, f"{prefix}.a_km", _NOVALUE, "is missing",
             "a semi-major axis in km (> 0), or a Cartesian state r_km, v_kmps")
    vals = {key: _typed(raw[key], kind, f"{prefix}.{key}") for key, kind in _SAT_SCHEMA.items() if key in raw}
    a_km = vals.pop("a_km")
    with localcontext() as ctx:
        ctx.prec = _EXACT
        a_m = a_km * 1000
    _require(a_km > 0, f"{prefix}.a_km", a_km, "is not positive", "a_km > 0 km")
    kwargs = {"name": vals.pop("name", f"Sat{k}"), "a_m": a_m, "e": Decimal(0), "i_deg": Decimal(0),
              "raan_deg": Decimal(0), "argp_deg": Decimal(0), "nu_deg": Decimal(0)}
    kwargs.update(vals)
    try:
        return SatelliteConfig(**kwargs)
    except ScenarioError as err:
        key = err.field.rsplit(".", 1)[-1]
        key = "a_km" if key == "a_m" else key
        raise ScenarioError(f"{prefix}.{key}", raw.get(key, err.value), err.problem, err.allowed) from None


def _scenario_from_raw(raw: dict, default_name: str) -> Scenario:
    _check_table(raw, "", _TOP_KEYS)
    for sec in _SCHEMA:
        _check_table(raw.get(sec, {}), sec, tuple(_SCHEMA[sec]))
    meta = raw.get("scenario", {})
    run = _build(RunConfig, "run", raw.get("run", {}), _SCHEMA["run"])
    integ = _build(IntegratorConfig, "integrator", raw.get("integrator", {}), _SCHEMA["integrator"])
    forces = _build(ForcesConfig, "forces", raw.get("forces", {}), _SCHEMA["forces"])
    craft = _build(SpacecraftConfig, "spacecraft", raw.get("spacecraft", {}), _SCHEMA["spacecraft"])
    const = _build(ConstellationConfig, "constellation", raw.get("constellation", {}), _SCHEMA["constellation"])
    initial_raw = dict(raw.get("initial", {}))
    sats_raw = raw.get("satellites")
    # a design that is not one of INITIAL_DESIGNS is named by InitialConfig, not taken as a design
    derived = initial_raw.get("design", "none") in INITIAL_DESIGNS[1:] or bool(initial_raw.get("oem"))
    if derived and sats_raw is None:
        sats_raw = []
    else:
        _require(sats_raw is not None, "satellites", _NOVALUE, "is missing", "at least one [[satellites]] table")
        _require(isinstance(sats_raw, list) and len(sats_raw) >= 1, "satellites", sats_raw,
                 "is not a non-empty array of tables", "at least one [[satellites]] table")
    sats = tuple(_build_satellite(s, k, derived) for k, s in enumerate(sats_raw, start=1))
    initial = _build(InitialConfig, "initial", initial_raw, _SCHEMA["initial"])
    if derived:
        initial = dataclasses.replace(initial, names=sats)
        sats = ()
    name = _typed(meta.get("name", default_name), _STR, "scenario.name")
    desc = _typed(meta.get("description", ""), _STR, "scenario.description")
    _require(not ("epoch_utc" in meta and "epoch_tdb" in meta), "scenario.epoch_tdb", meta.get("epoch_tdb"),
             "is given together with scenario.epoch_utc", "one epoch: epoch_utc or epoch_tdb")
    epoch_tdb = _typed(meta["epoch_tdb"], _EPOCH, "scenario.epoch_tdb") if "epoch_tdb" in meta else ""
    epoch = _typed(meta.get("epoch_utc", DEFAULT_EPOCH_UTC), _EPOCH, "scenario.epoch_utc")
    if not epoch_tdb and "epoch_utc" not in meta and initial.oem:
        from .initial import oem_first_common_epoch

        epoch_tdb = oem_first_common_epoch(initial.oem, initial.oem_eme2000)
    body = _typed(meta.get("central_body", "earth"), _STR, "scenario.central_body")
    below = _typed(meta.get("allow_below_surface", False), _BOOL, "scenario.allow_below_surface")
    closed = _closed_loop_from_raw(raw.get("closed_loop", {}))
    acc = _build(AccelerationsConfig, "accelerations", raw.get("accelerations", {}), _SCHEMA["accelerations"])
    return Scenario(name=name, description=desc, epoch_utc=epoch, run=run, integrator=integ, forces=forces,
                    spacecraft=craft, constellation=const, satellites=sats, central_body=body,
                    epoch_tdb=epoch_tdb, initial=initial, allow_below_surface=below, closed_loop=closed,
                    accelerations=acc)


# --------------------------------------------------------------------------- [closed_loop] (nested tables)


def _closed_loop_from_raw(table: Any) -> ClosedLoopConfig:
    """The [closed_loop] table: durations ("3d") to seconds, then validated by ClosedLoopConfig."""
    _require(isinstance(table, dict), "closed_loop", table, f"is {_a(_toml_type(table))}", "a table")
    table = dict(table)
    for key in ("duration", "segment"):
        if key in table:
            table[key] = _parse_duration(table[key], f"closed_loop.{key}")
    return ClosedLoopConfig(raw=table)


def closed_loop_config(table: Any = None, overrides: Sequence[str] = ()) -> ClosedLoopConfig:
    """A validated :class:`ClosedLoopConfig` from a ``[closed_loop]`` table (a dict, e.g. ``{"mission": "lpf"}``)
    and ``--set closed_loop.KEY=VALUE`` overrides, without a scenario (the closed loop of a mission's static
    working point, ``tqdyn closed-loop --mission``).  ScenarioError (one line naming the key) otherwise."""
    raw = {"closed_loop": dict(table or {})}
    for item in ((overrides,) if isinstance(overrides, str) else overrides):
        if not isinstance(item, str) or "=" not in item or not item.split("=", 1)[0].strip().startswith("closed_loop."):
            raise ScenarioError("override", item, "is not a closed-loop key=value",
                                "closed_loop.KEY=VALUE (docs/scenarios.md#closed-loop)")
        key, text = item.split("=", 1)
        _closed_loop_override(raw, key.strip(), text)
    return _closed_loop_from_raw(raw["closed_loop"])


def _closed_loop_override(raw: dict, key: str, text: str) -> None:
    """--set closed_loop.<key>, closed_loop.plant.<key>, closed_loop.controllers.<loop>.<key>,
    closed_loop.noise.<source>.<key>: nested tables created as needed (validated with the scenario)."""
    parts = key.split(".")[1:]
    groups = {"plant": 2, "controllers": 3, "noise": 3}
    depth = groups.get(parts[0], 1) if parts else 0
    if len(parts) != depth:
        raise ScenarioError(f"override {key}", problem="is not a [closed_loop] key",
                            allowed="closed_loop.<key>, closed_loop.plant.<key>, closed_loop.controllers.<loop>.<key>, "
                                    f"closed_loop.noise.<source>.<key> ({keys_doc('closed_loop')})")
    table = raw.setdefault("closed_loop", {})
    for p in parts[:-1]:
        _require(isinstance(table, dict), "closed_loop", table, "is not a table", "a table")
        table = table.setdefault(p, {})
    table[parts[-1]] = _parse_override_value(text, _ANY)


# --------------------------------------------------------------------------- overrides


def _parse_override_value(text: str, kind: str) -> Any:
    try:
        value = tomllib.loads("v = " + text, parse_float=Decimal)["v"]
    except tomllib.TOMLDecodeError:
        if kind == _STRLIST:  # --set forces.third_bodies=sun,moon
            return [x.strip() for x in text.split(",") if x.strip()]
        return text.strip()
    if kind in (_STR, _EPOCH) and not isinstance(value, str) and not (kind == _EPOCH and isinstance(value, _dt.date)):
        return text.strip()  # e.g. --set scenario.name=123 means the string "123"
    if kind == _EPOCH and isinstance(value, _dt.datetime) and value.tzinfo is None:
        return text.strip()  # the text keeps every decimal of the seconds; a TOML date-time keeps microseconds
    return value


def _apply_overrides(raw: dict, overrides: Sequence[str]) -> None:
    for item in overrides:
        if not isinstance(item, str) or "=" not in item:
            raise ScenarioError("override", item, "is not of the form key=value",
                                '"section.key=value" or "satellites.N.key=value"')
        key, text = item.split("=", 1)
        key = key.strip()
        parts = key.split(".")
        if parts[0] == "satellites":
            sats = raw.get("satellites")
            n = len(sats) if isinstance(sats, list) else 0
            if len(parts) != 3:
                raise ScenarioError(f"override {key}", problem="is not of the form satellites.N.key",
                                    allowed=f"satellites.N.key with N in 1..{n} and a key of {keys_doc('satellites')}")
            idx_text, sat_key = parts[1], parts[2]
            if not idx_text.isdigit() or not 1 <= int(idx_text) <= n:
                raise ScenarioError(f"override {key}", idx_text, "is not a satellite index",
                                    f"1..{n} (1-based)" if n else "no satellites defined")
            if sat_key not in _SAT_SCHEMA:
                raise _unknown_key(f"override {key}", tuple(_SAT_SCHEMA), keys_doc("satellites"),
                                   "is not a satellite key", sat_key)
            sat = sats[int(idx_text) - 1]
            _require(isinstance(sat, dict), f"satellites.{idx_text}", sat, "is not a table", "a [[satellites]] table")
            sat[sat_key] = _parse_override_value(text, _SAT_SCHEMA[sat_key])
            continue
        if parts[0] == "closed_loop":
            _closed_loop_override(raw, key, text)
            continue
        if len(parts) != 2 or parts[0] not in _SCHEMA:
            raise ScenarioError(f"override {key}", problem="is not a known section.key" + _did_you_mean(
                parts[0], _TOP_KEYS), allowed=f"section.key or satellites.N.key, of the tables in {keys_doc('')}")
        sec, sub = parts
        if sub not in _SCHEMA[sec]:
            raise _unknown_key(f"override {key}", tuple(_SCHEMA[sec]), keys_doc(sec), f"is not a key of [{sec}]", sub)
        table = raw.setdefault(sec, {})
        _require(isinstance(table, dict), sec, table, "is not a table", "a table")
        table[sub] = _parse_override_value(text, _SCHEMA[sec][sub])
        if sec == "scenario" and sub in _EPOCH_KEYS:
            for other in _EPOCH_KEYS:
                if other != sub:
                    table.pop(other, None)
        if (sec, sub) == ("initial", "oem") and isinstance(table[sub], list):
            table[sub] = [_abspath(x, Path.cwd()) for x in table[sub]]


# --------------------------------------------------------------------------- public loaders


def _builtin_dir():
    return resources.files("tqdyn") / "scenario" / "builtin"


#: Where the built-in scenarios are listed.
BUILTIN_DOC = "docs/scenarios.md#built-in-scenarios"


def builtin_scenarios() -> tuple[str, ...]:
    """Names of the built-in scenarios (package data ``tqdyn/scenario/builtin/*.toml``), sorted."""
    return tuple(sorted(p.name[: -len(".toml")] for p in _builtin_dir().iterdir() if p.name.endswith(".toml")))


def loads_scenario(text: str, overrides: Sequence[str] = (), *, source: str = "<string>", default_name: str = "scenario",
                   base_dir: str | os.PathLike | None = None) -> Scenario:
    """Build a :class:`Scenario` from TOML ``text`` (see :func:`load_scenario` for overrides).

    ``source`` names the text in error messages; ``default_name`` is used when
    the text has no ``scenario.name``; relative ``initial.oem`` paths are
    relative to ``base_dir`` (default: the working directory; in a built-in
    scenario, the package's data directory; in ``--set``, the working directory).
    """
    try:
        raw = tomllib.loads(text, parse_float=Decimal)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, problem=f"invalid TOML: {exc}", allowed="a TOML document (https://toml.io)") from None
    _resolve_paths(raw, Path.cwd() if base_dir is None else Path(base_dir))
    raw = _resolve_extends(raw, source, ())
    if isinstance(overrides, str):
        overrides = (overrides,)
    _apply_overrides(raw, overrides)
    return _scenario_from_raw(raw, default_name)


def _abspath(path: Any, base: Path) -> Any:
    """``path`` made absolute against ``base`` (other values unchanged, for the validation to name)."""
    return str(base / path) if isinstance(path, str) and path.strip() and not os.path.isabs(path) else path


def _resolve_paths(raw: dict, base: Path) -> None:
    """Relative ``initial.oem`` paths of a raw table, made absolute against ``base``."""
    initial = raw.get("initial")
    if isinstance(initial, dict) and isinstance(initial.get("oem"), list):
        initial["oem"] = [_abspath(x, base) for x in initial["oem"]]


def _data_dir() -> Path:
    return Path(str(resources.files("tqdyn") / "data"))


def _resolve_extends(raw: dict, source: str, chain: tuple[str, ...]) -> dict:
    """``[scenario] extends = "<built-in>"``: the built-in scenario's tables,
    each updated key by key with this file's (``[[satellites]]``, if given,
    replaces the base's list); ``name`` and ``description`` are this file's."""
    meta = raw.get("scenario", {})
    if not isinstance(meta, dict) or "extends" not in meta:
        return raw
    base_name = meta["extends"]
    builtins = builtin_scenarios()
    if not (isinstance(base_name, str) and base_name in builtins):
        raise ScenarioError("scenario.extends", base_name, "is not a built-in scenario" + _did_you_mean(base_name, builtins),
                            _one_of(builtins, BUILTIN_DOC))
    _require(base_name not in chain, "scenario.extends", base_name, f"extends itself ({' -> '.join(chain)})",
             "a chain of built-in scenarios without cycles")
    text = (_builtin_dir() / f"{base_name}.toml").read_text(encoding="utf-8")
    base_raw = tomllib.loads(text, parse_float=Decimal)
    _resolve_paths(base_raw, _data_dir())
    base = _resolve_extends(base_raw, base_name, chain + (base_name,))
    merged = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    for key, value in raw.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key].update(value)
        else:
            merged[key] = value
    for k in _EPOCH_KEYS:
        if k in meta:
            for other in _EPOCH_KEYS:
                if other != k and other not in meta:
                    merged["scenario"].pop(other, None)
    merged["scenario"] = {k: v for k, v in merged["scenario"].items() if k != "extends"}
    merged["scenario"].setdefault("description", "")
    for k in ("name", "description"):
        if k not in meta:
            merged["scenario"].pop(k, None)
    return merged


def load_scenario(name_or_path: str | os.PathLike | None = None, overrides: Sequence[str] = ()) -> Scenario:
    """Load a scenario by built-in name or from a ``.toml`` file, apply overrides, validate.

    Parameters
    ----------
    name_or_path : str, path or None
        ``None`` -> ``"tianqin"``.  A built-in name (see
        :func:`builtin_scenarios`) or a path to a TOML file.  A string that
        ends in ``.toml`` or contains a path separator is always a path.
    overrides : sequence of str
        ``"section.key=value"`` or ``"satellites.N.key=value"`` (N 1-based).
        ``value`` is read as a TOML value (``50.0``, ``true``, ``"x"``) and
        otherwise taken as a plain string (``integrator.mode=adaptive``,
        ``run.duration=90d``).  Applied to the raw table before validation.

    Returns a validated :class:`Scenario`; raises :class:`ScenarioError`.
    """
    if name_or_path is None:
        name_or_path = DEFAULT_SCENARIO
    builtins = builtin_scenarios()
    text_name = os.fspath(name_or_path)
    looks_like_path = (
        not isinstance(name_or_path, str)
        or text_name.endswith(".toml")
        or os.sep in text_name
        or (os.altsep is not None and os.altsep in text_name)
    )
    if not looks_like_path and text_name in builtins:
        text = (_builtin_dir() / f"{text_name}.toml").read_text(encoding="utf-8")
        return loads_scenario(text, overrides, source=f"built-in scenario {text_name!r}", default_name=text_name,
                              base_dir=_data_dir())
    path = Path(text_name)
    if not path.is_file():
        what = "is not a file" if path.exists() else ("does not exist" if looks_like_path else "is neither a built-in scenario nor a file")
        hint = "" if looks_like_path else _did_you_mean(text_name, builtins)
        raise ScenarioError("scenario", text_name, what + hint, f"a .toml file or a name in {BUILTIN_DOC}")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError("scenario", text_name, f"cannot be read ({exc})", "a readable UTF-8 .toml file") from None
    return loads_scenario(text, overrides, source=str(path), default_name=path.stem, base_dir=path.resolve().parent)
