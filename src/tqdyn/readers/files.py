"""Access to the model data shipped in ``tqdyn/data`` (see data/SOURCES.md)."""

from __future__ import annotations

import importlib.resources

__all__ = ["read_iers_table"]


def read_iers_table(name: str) -> str:
    """Text of an IERS Conventions 2010 table shipped in ``data/iers2010``
    (UTF-8); FileNotFoundError naming the file if it is missing."""
    res = importlib.resources.files("tqdyn") / "data" / "iers2010" / name
    if not res.is_file():
        raise FileNotFoundError(f"IERS table not found: tqdyn/data/iers2010/{name}")
    return res.read_text(encoding="utf-8")
