"""The one test of "a number" for values read from files and options: a real number that is not a
boolean (Python's ``bool`` is an ``int``: ``true`` in a TOML or JSON file must not pass as 1) nor a
string, and is finite."""

from __future__ import annotations

import math
import numbers
from decimal import Decimal

__all__ = ["finite_number"]


def finite_number(value) -> float | None:
    """``float(value)`` if value is a finite real number (int, float, Decimal, numpy scalars), else
    None (a boolean, a string, None, inf, nan, anything else)."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, Decimal)):
        return None
    x = float(value)
    return x if math.isfinite(x) else None
