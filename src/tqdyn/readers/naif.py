"""A small reader of NAIF SPICE text kernels (text PCK, FK): the
``\\begindata`` / ``\\begintext`` blocks and their ``NAME = ( values )``
assignments.

Grammar (NAIF "Kernel Required Reading", kernel.req, the subset used by the
generic kernels such as ``pck00010.tpc``):

* the part of the file before the first ``\\begindata`` line, and every
  ``\\begintext`` ... ``\\begindata`` stretch, is comment;
* inside data blocks, assignments ``NAME = value`` or ``NAME = ( v1 v2 ... )``
  (values separated by blanks and/or commas, possibly spread over several
  lines), and ``NAME += ...`` which appends to an earlier assignment;
* numbers may use the Fortran exponent letter ``D`` (``-1.4D-12``); strings are
  single-quoted (``''`` inside is a quote); ``@`` date values are kept as
  strings (``'@2000-JAN-01'`` -> ``"@2000-JAN-01"``).

This is a reader of files only; nothing here knows what the variables mean.
"""

from __future__ import annotations

import re
from pathlib import Path

__all__ = ["parse_text_kernel", "read_text_kernel"]

_TOKEN = re.compile(
    r"""\s*(?:
        (?P<str>'(?:[^']|'')*')          # quoted string
      | (?P<op>\+=|=|\(|\))              # operators and brackets
      | (?P<sep>,)                       # value separator
      | (?P<word>[^\s=(),']+)            # name, number or @date
    )""",
    re.VERBOSE,
)


def _data_text(text: str) -> str:
    """The data-block lines of a text kernel, joined (comments dropped)."""
    out, in_data = [], False
    for line in text.splitlines():
        token = line.strip()
        if token == "\\begindata":
            in_data = True
        elif token == "\\begintext":
            in_data = False
        elif in_data:
            out.append(line)
    return "\n".join(out)


def _value(tok: re.Match, where: str):
    if tok["str"] is not None:
        return tok["str"][1:-1].replace("''", "'")
    word = tok["word"]
    if word.startswith("@"):
        return word
    try:
        return float(word.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise ValueError(f"NAIF text kernel{where}: cannot read value {word!r}") from None


def parse_text_kernel(text: str, *, source: str = "") -> dict[str, list]:
    """Parse the text of a NAIF text kernel.

    Returns {variable name: list of values}, numbers as float, strings as
    str, in file order (``+=`` appends).  Raises ``ValueError`` on a
    malformed assignment, naming the variable and ``source`` (a file name,
    for messages only).
    """
    where = f" {source}" if source else ""
    data = _data_text(text)
    toks = [m for m in _TOKEN.finditer(data) if m.group(0).strip()]
    out: dict[str, list] = {}
    i, n = 0, len(toks)
    while i < n:
        name_tok = toks[i]
        if name_tok["word"] is None:
            raise ValueError(f"NAIF text kernel{where}: expected a variable name, got {name_tok.group(0).strip()!r}")
        name = name_tok["word"]
        if i + 2 > n or toks[i + 1]["op"] not in ("=", "+="):
            raise ValueError(f"NAIF text kernel{where}: variable {name!r} is not followed by '=' or '+='")
        append = toks[i + 1]["op"] == "+="
        i += 2
        values = []
        if i < n and toks[i]["op"] == "(":
            i += 1
            while i < n and toks[i]["op"] != ")":
                if toks[i]["sep"] is None:
                    if toks[i]["op"] is not None:
                        raise ValueError(f"NAIF text kernel{where}: unexpected {toks[i]['op']!r} in the values of {name!r}")
                    values.append(_value(toks[i], where))
                i += 1
            if i == n:
                raise ValueError(f"NAIF text kernel{where}: unclosed '(' in the values of {name!r}")
            i += 1  # ')'
        elif i < n and (toks[i]["str"] is not None or toks[i]["word"] is not None):
            values.append(_value(toks[i], where))
            i += 1
        else:
            raise ValueError(f"NAIF text kernel{where}: variable {name!r} has no value")
        if append:
            out.setdefault(name, []).extend(values)
        else:
            out[name] = values
    return out


def read_text_kernel(path) -> dict[str, list]:
    """Read a NAIF text kernel file (path or ``importlib.resources`` traversable);
    see :func:`parse_text_kernel`.  Raises ``FileNotFoundError`` if missing."""
    p = path if hasattr(path, "read_text") else Path(path)
    try:
        text = p.read_text(encoding="latin-1")
    except FileNotFoundError:
        raise FileNotFoundError(f"NAIF text kernel not found: {path}") from None
    return parse_text_kernel(text, source=str(getattr(p, "name", path)))
