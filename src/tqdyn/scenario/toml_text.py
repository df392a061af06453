"""Python values as TOML text: the resolved scenario (:meth:`Scenario.to_toml`),
sweep files and ``--set`` overrides written by code are all spelled here."""

from __future__ import annotations

import datetime as _dt
from decimal import Decimal
from typing import Any

__all__ = ["toml_str", "toml_value"]

_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def toml_str(s: str) -> str:
    """A TOML basic string (quoted, escaped)."""
    out = []
    for ch in s:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_value(value: Any) -> str:
    """A TOML value: booleans, integers, Decimals and floats (exact decimal
    form: ``str(Decimal)`` of a finite value is always valid TOML, e.g.
    "100009.5", "1E+5", "0E-7"), strings (quoted), date-times, and nested
    lists or tuples of them."""
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
        return toml_str(value)
    if isinstance(value, (_dt.datetime, _dt.date, _dt.time)):
        return value.isoformat()
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")
