"""Validation helpers of the scenario dataclasses: :class:`ScenarioError`
(one line ``"<field>: <value> <problem>; allowed: <what is allowed>"``) and
the exact value conversions (Decimal) shared by :mod:`.config`,
:mod:`.initial` and :mod:`.loader`."""

from __future__ import annotations

import datetime as _dt
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, Sequence

from .._choices import allowed as _allowed, did_you_mean as _did_you_mean, shown as _shown

__all__ = ["MAX_ACCELERATION", "ScenarioError"]

#: Largest component [m/s^2] of an acceleration a scenario gives (``[accelerations]``,
#: ``spacecraft.self_gravity*``).  These keys model small forces on the satellites: solar radiation
#: pressure (~1e-7 m/s^2 on these missions' spacecraft), the spacecraft's self-gravity at its test
#: masses (~1e-9 m/s^2), empirical accelerations estimated by orbit determination (the same sizes);
#: even an electric-propulsion thruster (~0.1 N on a ~500 kg spacecraft) gives 2e-4 m/s^2.  A value
#: above 1e-3 m/s^2 is a unit or typing mistake (km/s^2, a missing exponent): it is refused at load
#: rather than driving the orbit out of range (1e300 m/s^2 overflows the state to inf, then NaN).
MAX_ACCELERATION = Decimal("1e-3")

_EXACT = 200  # Decimal working precision for exact unit conversions

_NOVALUE = object()


# --------------------------------------------------------------------------- errors


class _Exact:
    """A Decimal as the scenario writes it (``0.5``, not ``Decimal('0.5')``), for :func:`_fmt`."""

    def __init__(self, d: Decimal):
        self.d = d

    def __repr__(self) -> str:
        return str(self.d)


def _plain(value: Any) -> Any:
    """``value`` as the scenario writes it: Decimals exact (``0.5``), lists and tuples as TOML arrays."""
    if isinstance(value, Decimal):
        return _Exact(value)
    if isinstance(value, (list, tuple)):
        return [_plain(x) for x in value]
    return value


def _fmt(value: Any) -> str:
    """A value as an error message quotes it: Decimals as written, paths as strings,
    long lists and tables cut (:func:`tqdyn._choices.shown`)."""
    if isinstance(value, Decimal):
        return str(value)
    if isinstance(value, Path):
        return repr(str(value))
    return _shown(_plain(value))


class ScenarioError(ValueError):
    """Invalid scenario: one line ``"<field>: <value> <problem>; allowed: <allowed>"``.

    Attributes ``field`` (dotted TOML path such as ``"satellites.2.e"``),
    ``value`` (the offending value, or ``None``; ``has_value``: whether the
    message names one), ``problem`` and ``allowed``.
    """

    def __init__(self, field: str, value: Any = _NOVALUE, problem: str = "", allowed: str | None = None):
        self.field = field
        self.has_value = value is not _NOVALUE
        self.value = None if value is _NOVALUE else value
        self.problem = problem
        self.allowed = allowed
        parts = [f"{field}:"]
        if value is not _NOVALUE:
            parts.append(_fmt(value))
        if problem:
            parts.append(problem)
        msg = " ".join(parts)
        if allowed:
            msg += f"; allowed: {allowed}"
        super().__init__(msg.replace("\n", " "))


def _one_of(options: Sequence[str], doc: str | None = None) -> str:
    """The allowed choices of a message: all of them quoted, or (a long list) their
    number and the page ``doc`` that lists them (:func:`tqdyn._choices.allowed`)."""
    return _allowed(options, doc, quote=repr)


def _unknown_key(field: str, keys: Sequence[str], doc: str | None = None, problem: str = "is not a known key",
                 value: Any = _NOVALUE, noun: str = "keys") -> ScenarioError:
    """The error of an unknown key (``value``, by default the last part of ``field``): the
    closest of ``keys`` and where they are documented (``doc``, a docs page and anchor)."""
    key = field.rsplit(".", 1)[-1] if value is _NOVALUE else value
    return ScenarioError(field, value, problem + _did_you_mean(key, keys), _allowed(keys, doc, noun=noun))


# --------------------------------------------------------------------------- value helpers


def _to_decimal(value: Any, name: str) -> Decimal:
    """Coerce int/Decimal/str/float to a finite Decimal (for direct Python construction)."""
    if isinstance(value, bool):
        raise ScenarioError(name, value, "is a boolean", "a finite number")
    if isinstance(value, Decimal):
        d = value
    elif isinstance(value, int):
        d = Decimal(value)
    elif isinstance(value, float):
        d = Decimal(repr(value))
    elif isinstance(value, str):
        try:
            d = Decimal(value.strip())
        except InvalidOperation:
            raise ScenarioError(name, value, "is not a number", "a finite number") from None
    else:
        raise ScenarioError(name, value, f"has type {type(value).__name__}", "a finite number")
    if not d.is_finite():
        raise ScenarioError(name, value, "is not finite", "a finite number")
    return d


def _require(cond: bool, name: str, value: Any, problem: str, allowed: str) -> None:
    if not cond:
        raise ScenarioError(name, value, problem, allowed)


def _require_choice(value: Any, name: str, options: Sequence[str], doc: str | None = None,
                    problem: str = "is not a valid choice") -> None:
    """ScenarioError naming ``name``, ``value`` and the closest of ``options`` (all
    of them, or the page ``doc`` that lists them) unless ``value`` is one of them."""
    if not (isinstance(value, str) and value in options):
        raise ScenarioError(name, value, problem + _did_you_mean(value, options), _one_of(options, doc))


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


# --------------------------------------------------------------------------- TOML type names (messages)


def _a(noun: str) -> str:
    return ("an " if noun[:1] in "aeiou" else "a ") + noun


def _toml_type(value: Any) -> str:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, (Decimal, float)):
        return "float"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    if isinstance(value, dict):
        return "table"
    if isinstance(value, (_dt.date, _dt.time)):
        return "date-time"
    return type(value).__name__




def _num_array(value: Any, name: str, shapes: Sequence[tuple[int, ...]], unit: str,
               max_abs: Decimal | None = None) -> tuple:
    """Nested tuples of Decimal with one of ``shapes`` (ScenarioError otherwise); with ``max_abs``,
    every |element| <= max_abs (in ``unit``; :data:`MAX_ACCELERATION` for accelerations)."""
    allowed = " or ".join(str(tuple(s)) for s in shapes)
    allowed = f"an array of shape {allowed} of finite numbers [{unit}]"

    def conv(x, depth):
        if isinstance(x, (list, tuple)):
            return tuple(conv(e, depth + 1) for e in x)
        if isinstance(x, bool) or not isinstance(x, (int, float, Decimal)):
            raise ScenarioError(name, value, f"contains {_a(_toml_type(x))}", allowed)
        d = Decimal(str(x)) if isinstance(x, float) else Decimal(x)
        _require(d.is_finite(), name, value, "is not finite", allowed)
        return d

    arr = conv(value, 0)

    def shape(x):
        if not isinstance(x, tuple):
            return ()
        inner = {shape(e) for e in x}
        return (len(x),) + inner.pop() if len(inner) == 1 else (len(x), -1)

    _require(isinstance(arr, tuple) and shape(arr) in [tuple(s) for s in shapes], name,
             value, "has the wrong shape", allowed)
    if max_abs is not None:
        def flat(x):
            return [e for y in x for e in flat(y)] if isinstance(x, tuple) else [x]

        big = max(flat(arr), key=abs)
        u = unit.split(",")[0].split(" ")[0]
        _require(abs(big) <= max_abs, name, value, f"has {big} {u}, too large for the small force this key models",
                 f"|each value| <= {max_abs} {u} (docs/scenarios.md)")
    return arr
