"""The Doodson-number notation of tidal constituents, as the IERS tables and FES2004 write it.

A Doodson number ``ABC.DEF`` (e.g. ``255.555`` for M2) encodes the integer
multipliers (A, B-5, C-5, D-5, E-5, F-5) of the six Doodson arguments
(tau, s, h, p, N', p_s); :func:`delaunay_multipliers` converts them to the
multipliers of (theta_g + pi) and the Delaunay arguments (l, l', F, D,
Omega) printed in TN36 Tables 6.5a-c.  The arguments themselves are theory:
:mod:`tqdyn.astro.tidal_arguments`.
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["delaunay_multipliers", "doodson_multipliers"]

_DOODSON_RE = re.compile(r"^\s*(\d{1,3})\s*[.,]\s*(\d{3})\s*$")


def doodson_multipliers(number) -> np.ndarray:
    """Multipliers n (6,) int of the Doodson arguments from a Doodson number.

    number: str like ``"255.555"``, ``"255,555"``, ``"55.565"`` (TN36 and
    FES2004 spellings; a leading 0 may be omitted) or a float such as
    255.555 (formatted with 3 decimals).  ``A B C . D E F`` ->
    (A, B-5, C-5, D-5, E-5, F-5).  Raises ValueError for anything else.
    """
    text = f"{number:.3f}" if isinstance(number, (float, np.floating)) else str(number)
    m = _DOODSON_RE.match(text)
    if m is None:
        raise ValueError(f"Doodson number {number!r}: expected 'ABC.DEF' (e.g. '255.555' or '55.565')")
    digits = m[1].rjust(3, "0") + m[2]
    n = np.array([int(c) for c in digits], dtype=np.int64)
    n[1:] -= 5
    return n


def delaunay_multipliers(n) -> tuple[np.ndarray, np.ndarray]:
    """(n_1, N) such that theta_f = n . beta = n_1 (theta_g + pi) - N . F.

    n: (..., 6) Doodson multipliers (int).  Returns n_1 (...,) and N (..., 5)
    int, N = multipliers of (l, l', F, D, Omega) as printed in TN36 Tables
    6.5a-c.
    """
    n = np.asarray(n, dtype=np.int64)
    n1, n2, n3, n4, n5, n6 = (n[..., k] for k in range(6))
    big = np.stack([n4, n6, n1 - n2 - n3 - n4 - n6, n3 + n6, n1 - n2 - n3 - n4 + n5 - n6], axis=-1)
    return n1, big
