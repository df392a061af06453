"""One-line messages about a name that is not allowed: an unknown scenario key,
a value of an enumerated key, a command-line choice, a file's field.

Every such message names the field and the value, suggests the closest allowed
names (:func:`difflib.get_close_matches`, case-insensitive) and gives the
allowed names in full when they are few (:data:`MAX_LISTED` characters),
otherwise their number and the page of the documentation that lists them all,
so that the line stays under ~200 characters (docs/reliability.md, "Error
messages")::

    forces.gm_mon: is not a known key (did you mean 'gm_moon'?); allowed: one of the 31 keys in docs/scenarios.md#forces
    integrator.method: 'multstep' is not a valid choice (did you mean 'multistep'?); allowed: 'dp87', 'multistep'

This module imports nothing of tqdyn (it is the bottom layer next to
``_version``), so that every layer words these messages the same way.
"""

from __future__ import annotations

import difflib
from typing import Any, Iterable

__all__ = ["MAX_LISTED", "MAX_VALUE", "allowed", "closest", "did_you_mean", "shown", "unknown"]

#: Longest list of allowed names given in full [characters]; a longer list is
#: given as its number and the page that documents it.
MAX_LISTED = 80
#: Longest value (list, table) quoted in a message [characters]; a longer one
#: is cut after that many, with "...".  Strings (names, paths) are never cut.
MAX_VALUE = 60
#: How close a name must be to be suggested (difflib's ratio, 0..1), and for a value of at
#: most three characters, where one letter in common is already a ratio of 0.67 ('UTC', 'TCB').
CUTOFF = 0.6
SHORT_CUTOFF = 0.75
#: How much less close than the closest name another may be and still be suggested.
TIE = 0.05


def closest(value: Any, names: Iterable[Any], n: int = 3, cutoff: float | None = None) -> list[str]:
    """Up to ``n`` of ``names`` closest to ``value`` (difflib ratio >= ``cutoff``, by default
    :data:`CUTOFF`, or :data:`SHORT_CUTOFF` for a short value; ignoring case), best first, and
    only those as close as the best (within :data:`TIE`); none for a value that is not a string
    or an integer."""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        return []
    by_lower: dict[str, str] = {}
    for name in names:
        by_lower.setdefault(str(name).lower(), str(name))
    text = str(value).lower()
    if cutoff is None:
        cutoff = CUTOFF if len(text) > 3 else SHORT_CUTOFF
    hits = difflib.get_close_matches(text, list(by_lower), n=n, cutoff=cutoff)
    ratio = [difflib.SequenceMatcher(None, text, h).ratio() for h in hits]
    return [by_lower[h] for h, r in zip(hits, ratio) if r >= ratio[0] - TIE]


def did_you_mean(value: Any, names: Iterable[Any], *, quote=repr, cutoff: float | None = None) -> str:
    """``" (did you mean 'gm_moon'?)"`` (at most two names, joined by "or"), or
    ``""`` when no allowed name is close to ``value`` (:func:`closest`)."""
    hits = closest(value, names, n=2, cutoff=cutoff)
    return f" (did you mean {' or '.join(quote(h) for h in hits)}?)" if hits else ""


def allowed(names: Iterable[Any], doc: str | None = None, *, noun: str = "names", quote=str) -> str:
    """The allowed ``names`` as a message gives them: all of them, joined by
    commas (each through ``quote``), when that is at most :data:`MAX_LISTED`
    characters; else ``"one of the 31 keys in docs/scenarios.md#forces"``
    (``noun``, ``doc``: the page and anchor that list them all), or without
    ``doc`` the first names that fit and their number."""
    names = [str(x) for x in names]
    listed = ", ".join(quote(x) for x in names)
    if len(listed) <= MAX_LISTED:
        return listed
    if doc:
        return f"one of the {len(names)} {noun} in {doc}"
    head = []
    for x in names:
        if len(", ".join(head + [quote(x)])) > MAX_LISTED - 20:
            break
        head.append(quote(x))
    return f"{', '.join(head)}, ... ({len(names)} {noun})"


def shown(value: Any) -> str:
    """``value`` as a message quotes it: ``repr``, except that a list, tuple or
    table longer than :data:`MAX_VALUE` characters is cut there (with "...")."""
    text = repr(value)
    if isinstance(value, (list, tuple, dict, set)) and len(text) > MAX_VALUE:
        text = text[:MAX_VALUE - 3] + "..."
    return text


def unknown(field: str, value: Any, names: Iterable[Any], doc: str | None = None, *,
            problem: str = "is not allowed", noun: str = "names", quote=str) -> str:
    """The one-line message of a ``value`` of ``field`` that is not among ``names``:
    ``"<field>: <value> <problem> (did you mean ...?); allowed: <names or where they are listed>"``."""
    names = list(names)
    return (f"{field}: {shown(value)} {problem}{did_you_mean(value, names)}; "
            f"allowed: {allowed(names, doc, noun=noun, quote=quote)}")
