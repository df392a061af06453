"""Readers of the NAIF planetary-constants kernels (PCK) tqdyn ships in
``tqdyn/data`` (see ``data/SOURCES.md``):

* the lunar principal-axis binary PCK ``moon_pa_de421_1900-2050.bpc``
  (:func:`load_lunar_pa_kernel` -> :class:`LunarPaKernel`, the Chebyshev
  coefficients of the DE421 PA Euler angles; read with jplephem's DAF reader);
* the text PCK ``pck00010.tpc``: the IAU (WGCCRE 2009) rotational elements of
  the Moon (:func:`read_iau_moon_elements` -> :class:`IauMoonElements`) and
  of the Sun (:func:`read_iau_sun_elements` -> :class:`IauSunElements`),
  through the generic text-kernel parser :mod:`tqdyn.readers.naif`;
* the text PCK ``gm_de431.tpc``: the GMs of the DE430/DE431 ephemerides
  (:func:`parse_gm_tpc`; the shipped file via :func:`shipped_gm`, used by
  :func:`tqdyn.astro.ephemeris.planetary_gm`).

Readers only: the orientation models are evaluated in
:mod:`tqdyn.astro.lunar_orientation` and :mod:`tqdyn.forces.sun`.
"""

from __future__ import annotations

import functools
import importlib.resources
import re
from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from .naif import read_text_kernel

__all__ = [
    "IauMoonElements",
    "IauSunElements",
    "LunarPaKernel",
    "load_lunar_pa_kernel",
    "parse_gm_tpc",
    "read_iau_moon_elements",
    "read_iau_sun_elements",
    "shipped_gm",
]

#: Default data files (in ``tqdyn/data``).
_PA_KERNEL = "moon_pa_de421_1900-2050.bpc"
_IAU_KERNEL = "pck00010.tpc"

#: NAIF body code of the DE421 lunar PA frame in the binary PCK, and the
#: frame its angles are relative to (1 = "J2000", which for DE data is ICRF).
_PA_BODY = 31006
_PA_FRAME = 1


# --------------------------------------------------------------------------
# lunar principal axes (binary PCK)


@dataclass(frozen=True, eq=False)
class LunarPaKernel:
    """The Euler-angle segment of a lunar PA binary PCK, in memory.

    coef: (n_rec, 3, n_coef) float64 Chebyshev coefficients [rad] of
    (phi, theta, psi) per record; init [s of TDB past J2000], intlen [s]:
    start and length of the records; start_jd, end_jd: the segment's span
    [TDB Julian date]; source: file name.
    """

    coef: np.ndarray
    init: float
    intlen: float
    start_jd: float
    end_jd: float
    source: str


@functools.lru_cache(maxsize=4)
def load_lunar_pa_kernel(path=None) -> LunarPaKernel:
    """Read the Euler-angle segment of a lunar PA binary PCK.

    path: file path, or None for the shipped DE421 kernel
    ``tqdyn/data/moon_pa_de421_1900-2050.bpc``.  The segment must be type 2
    (Chebyshev, angles only), body 31006 relative to frame 1 (ICRF); its
    records are [MID, RADIUS, 3 x n_coef coefficients] with the trailer
    (init, intlen, rsize, n) (NAIF pck.req; read with jplephem's DAF reader).
    Cached.  Raises FileNotFoundError, or ValueError if no such segment.
    """
    from jplephem.pck import PCK

    src = importlib.resources.files("tqdyn") / "data" / _PA_KERNEL if path is None else path
    try:
        kernel = PCK.open(str(src))
    except FileNotFoundError:
        raise FileNotFoundError(f"lunar PA kernel not found: {src}") from None
    for seg in kernel.segments:
        if seg.body == _PA_BODY and seg.frame == _PA_FRAME and seg.data_type == 2:
            init, intlen, rsize, n = seg.daf.read_array(seg.end_i - 3, seg.end_i)
            rsize, n = int(rsize), int(n)
            raw = seg.daf.map_array(seg.start_i, seg.end_i - 4).reshape(n, rsize)
            coef = np.ascontiguousarray(raw[:, 2:].reshape(n, 3, (rsize - 2) // 3), dtype=np.float64)
            coef.setflags(write=False)
            return LunarPaKernel(coef, float(init), float(intlen), float(seg.initial_jd), float(seg.final_jd),
                                 str(getattr(src, "name", src)))
    found = [(s.body, s.frame, s.data_type) for s in kernel.segments]
    raise ValueError(
        f"lunar PA kernel {src}: no type-2 segment of body {_PA_BODY} relative to frame {_PA_FRAME} "
        f"(ICRF); found (body, frame, type) = {found}")


# --------------------------------------------------------------------------
# IAU rotational elements (text PCK)


def _poly3(values, name) -> np.ndarray:
    if not 1 <= len(values) <= 3:
        raise ValueError(f"{name}: expected 1 to 3 polynomial coefficients, got {len(values)}")
    v = np.zeros(3)
    v[: len(values)] = values
    return v


@dataclass(frozen=True)
class IauMoonElements:
    """IAU (WGCCRE 2009) rotational elements of the Moon, as in a NAIF text PCK.

    All angles in degrees.  ra, dec: (3,) polynomial coefficients in T
    [Julian centuries of TDB since J2000] (deg, deg/cy, deg/cy^2); pm: (3,)
    coefficients in d [days of TDB since J2000] (deg, deg/d, deg/d^2);
    nut_ra, nut_dec, nut_pm: (k,) amplitudes [deg] of sin(E_j), cos(E_j),
    sin(E_j); angles: (k, 2) E_j = angles[j, 0] + angles[j, 1] T [deg, deg/cy].
    """

    ra: np.ndarray
    dec: np.ndarray
    pm: np.ndarray
    nut_ra: np.ndarray
    nut_dec: np.ndarray
    nut_pm: np.ndarray
    angles: np.ndarray


@functools.lru_cache(maxsize=4)
def read_iau_moon_elements(path=None) -> IauMoonElements:
    """Read the Moon's IAU rotational elements (BODY301_POLE_RA, _POLE_DEC,
    _PM, _NUT_PREC_RA/_DEC/_PM and BODY3_NUT_PREC_ANGLES) from a NAIF text PCK.

    path: file path, or None for the shipped ``tqdyn/data/pck00010.tpc``.
    Raises FileNotFoundError, or ValueError naming a missing variable.
    """
    src = importlib.resources.files("tqdyn") / "data" / _IAU_KERNEL if path is None else path
    k = read_text_kernel(src)
    need = ["BODY301_POLE_RA", "BODY301_POLE_DEC", "BODY301_PM", "BODY301_NUT_PREC_RA",
            "BODY301_NUT_PREC_DEC", "BODY301_NUT_PREC_PM", "BODY3_NUT_PREC_ANGLES"]
    missing = [n for n in need if n not in k]
    if missing:
        raise ValueError(f"IAU Moon elements: {src} lacks {', '.join(missing)}")
    ang = np.asarray(k["BODY3_NUT_PREC_ANGLES"], dtype=np.float64)
    if ang.size % 2:
        raise ValueError(f"IAU Moon elements: BODY3_NUT_PREC_ANGLES has {ang.size} values, expected pairs")
    ang = ang.reshape(-1, 2)
    nut = [np.zeros(len(ang)) for _ in range(3)]
    for arr, nm in zip(nut, need[3:6]):
        vals = np.asarray(k[nm], dtype=np.float64)
        if vals.size > len(ang):
            raise ValueError(f"IAU Moon elements: {nm} has {vals.size} terms but only {len(ang)} angles are defined")
        arr[: vals.size] = vals
    return IauMoonElements(
        ra=_poly3(k["BODY301_POLE_RA"], "BODY301_POLE_RA"),
        dec=_poly3(k["BODY301_POLE_DEC"], "BODY301_POLE_DEC"),
        pm=_poly3(k["BODY301_PM"], "BODY301_PM"),
        nut_ra=nut[0], nut_dec=nut[1], nut_pm=nut[2], angles=ang)


@dataclass(frozen=True)
class IauSunElements:
    """IAU (WGCCRE 2009) rotational elements of the Sun, in degrees.

    ra, dec: (3,) pole coefficients in T [Julian centuries of TDB since
    J2000] (deg, deg/cy, deg/cy^2); pm: (3,) prime-meridian coefficients in
    d [days of TDB since J2000] (deg, deg/d, deg/d^2).
    """

    ra: np.ndarray
    dec: np.ndarray
    pm: np.ndarray


@functools.lru_cache(maxsize=4)
def read_iau_sun_elements(path=None) -> IauSunElements:
    """Read BODY10_POLE_RA, BODY10_POLE_DEC and BODY10_PM from a NAIF text
    PCK (path, or None for the shipped ``tqdyn/data/pck00010.tpc``).
    Raises FileNotFoundError, or ValueError naming a missing variable."""
    src = importlib.resources.files("tqdyn") / "data" / _IAU_KERNEL if path is None else path
    k = read_text_kernel(src)
    need = ("BODY10_POLE_RA", "BODY10_POLE_DEC", "BODY10_PM")
    missing = [n for n in need if n not in k]
    if missing:
        raise ValueError(f"IAU Sun elements: {src} lacks {', '.join(missing)}")
    return IauSunElements(*(_poly3(k[n], n) for n in need))


# --------------------------------------------------------------------------
# GMs (text PCK)

_GM_RE = re.compile(r"BODY(\d+)_GM\s*=\s*\(\s*([-+0-9.EeDd]+)\s*\)")


def parse_gm_tpc(text: str, *, exact: bool = False) -> dict[int, float]:
    """Read the GM assignments of a NAIF text PCK (``BODYnnn_GM = ( value )``
    inside ``\\begindata`` blocks).

    text: the file's content.  Returns {NAIF id: GM [m^3/s^2]} (the file's
    km^3/s^2 times 1e9, converted from the exact decimal, one rounding; with
    ``exact`` the exact ``Decimal`` itself, for extended-precision terms).
    Raises ValueError if no GM is found.
    """
    out: dict[int, float] = {}
    data = False
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("\\begindata"):
            data = True
            continue
        if s.startswith("\\begintext"):
            data = False
            continue
        if data:
            for m in _GM_RE.finditer(s):
                gm = Decimal(m[2].replace("D", "E").replace("d", "e")) * 10**9
                out[int(m[1])] = gm if exact else float(gm)
    if not out:
        raise ValueError("GM kernel: no BODYnnn_GM assignment found inside \\begindata blocks")
    return out


@functools.lru_cache(maxsize=1)
def shipped_gm(exact: bool = False) -> dict[int, float]:
    """{NAIF id: GM [m^3/s^2]} of the shipped ``data/gm_de431.tpc`` (float64, or exact Decimals)."""
    path = importlib.resources.files("tqdyn") / "data" / "gm_de431.tpc"
    if not path.is_file():
        raise FileNotFoundError(f"tqdyn data file not found: {path}")
    return parse_gm_tpc(path.read_text(encoding="ascii", errors="replace"), exact=exact)
