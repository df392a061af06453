"""Readers of the IERS Conventions 2010 (TN36) tables shipped in
``tqdyn/data/iers2010`` (text via :func:`tqdyn.readers.files.read_iers_table`).

* Solid Earth tides (TN36 sec. 6.2): the nominal Love numbers of Table 6.3
  (:func:`parse_love_numbers`, :func:`load_love_numbers` ->
  :class:`LoveNumbers`) and the frequency-dependent step-2 corrections of
  Tables 6.5a-c (:func:`parse_step2_table`, :func:`load_step2_table` ->
  :class:`Step2Table`); evaluated by :mod:`tqdyn.forces.solid_tides`.
* Sub-daily EOP corrections: the ocean-tide terms of Tables 8.2 and 8.3 and
  the polar-motion libration terms of Table 5.1a
  (:func:`load_tidal_eop_terms` -> :class:`TidalEOPTerms`); evaluated by
  :func:`tqdyn.astro.eop.tidal_eop_corrections`.

Doodson numbers are decoded (and checked against the printed multipliers)
with :mod:`tqdyn.astro.tidal_arguments`.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

import numpy as np

from ..astro.constants import ARCSEC_RAD
from .doodson import delaunay_multipliers, doodson_multipliers
from .files import read_iers_table

__all__ = [
    "LoveNumbers",
    "Step2Table",
    "TidalEOPTerms",
    "load_love_numbers",
    "load_step2_table",
    "load_tidal_eop_terms",
    "parse_love_numbers",
    "parse_step2_table",
]

#: One microarcsecond in radians (:data:`tqdyn.astro.eop.ARCSEC` * 1e-6).
_MICROARCSEC = ARCSEC_RAD * 1e-6

_DOODSON_TOKEN = re.compile(r"^\d{1,3},\d{3}$")


# --------------------------------------------------------------------------
# solid Earth tides: nominal Love numbers (TN36 Table 6.3) and step-2 tables (6.5a-c)


@dataclass(frozen=True, eq=False)
class LoveNumbers:
    """Nominal (anelastic) external-potential Love numbers, TN36 Table 6.3.

    k: complex (4, 4) array, k[n, m] for n = 2, 3 and m <= n (others 0);
    k_plus: float (3,), k+_2m (m = 0, 1, 2) for the degree-4 terms.
    Dimensionless.
    """

    k: np.ndarray
    k_plus: np.ndarray


@dataclass(frozen=True, eq=False)
class Step2Table:
    """Frequency-dependent Love-number corrections, TN36 Tables 6.5a-c.

    order: (n_f,) int, m = 0 (Table 6.5b), 1 (6.5a) or 2 (6.5c);
    doodson: (n_f, 6) int Doodson multipliers; ip, op: (n_f,) float64 in-phase
    and out-of-phase amplitudes A_m delta k_f H_f, dimensionless (the files'
    units of 1e-12 applied); names: Darwin names ('' where the table has none).
    """

    order: np.ndarray
    doodson: np.ndarray
    ip: np.ndarray
    op: np.ndarray
    names: tuple[str, ...]

    def __len__(self) -> int:
        return int(self.order.shape[0])

    @functools.cached_property
    def _weights(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mult (n_f, 6) float, W_cos (n_f, 5), W_sin (n_f, 5)): the five
        outputs (C20, C21, S21, C22, S22) are cos(theta) @ W_cos + sin(theta) @ W_sin."""
        m0, m1, m2 = (self.order == 0), (self.order == 1), (self.order == 2)
        ip, op = self.ip, self.op
        wc = np.zeros((len(self), 5))
        ws = np.zeros((len(self), 5))
        wc[m0, 0], ws[m0, 0] = ip[m0], -op[m0]          # C20 = ip cos - op sin
        wc[m1, 1], ws[m1, 1] = op[m1], ip[m1]           # C21 = ip sin + op cos
        wc[m1, 2], ws[m1, 2] = ip[m1], -op[m1]          # S21 = ip cos - op sin
        wc[m2, 3], ws[m2, 3] = ip[m2], -op[m2]          # C22 = ip cos - op sin
        wc[m2, 4], ws[m2, 4] = -op[m2], -ip[m2]         # S22 = -(ip sin + op cos)
        return self.doodson.astype(np.float64), wc, ws


def parse_love_numbers(text: str) -> LoveNumbers:
    """Parse TN36 Table 6.3 as shipped (``n m Re(k) Im(k) k+`` rows, '#'
    comments).  Returns :class:`LoveNumbers`; raises ValueError if a degree-2
    or degree-3 entry is missing or a row is malformed."""
    k = np.zeros((4, 4), dtype=np.complex128)
    kp = np.zeros(3)
    seen = set()
    for lineno, line in enumerate(text.splitlines(), 1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = s.split()
        if len(parts) != 5:
            raise ValueError(f"Love-number table line {lineno}: expected 'n m Re Im k+', got {line!r}")
        n, m = int(parts[0]), int(parts[1])
        if not (2 <= n <= 3 and 0 <= m <= n):
            raise ValueError(f"Love-number table line {lineno}: degree/order ({n}, {m}) outside n = 2..3, m <= n")
        k[n, m] = complex(float(parts[2]), float(parts[3]))
        if n == 2:
            kp[m] = float(parts[4])
        seen.add((n, m))
    missing = [(n, m) for n in (2, 3) for m in range(n + 1) if (n, m) not in seen]
    if missing:
        raise ValueError(f"Love-number table: missing entries {missing}")
    return LoveNumbers(k=k, k_plus=kp)


def parse_step2_table(text: str, order: int) -> Step2Table:
    """Parse one of TN36 Tables 6.5a (order 1), 6.5b (order 0), 6.5c (order 2)
    in the shipped text layout.

    Data rows are recognised by their Doodson number written ``ddd,ddd``.
    Column layouts after the Doodson number: 6.5a ``tau s h p N' ps l l' F D
    Omega dkR dkI ip op``; 6.5b ``deg/hr (11 multipliers) dkR ip dkI op``;
    6.5c ``deg/hr (11 multipliers) dkR ip``.  Every row's Doodson number is
    checked against its printed Doodson and Delaunay multipliers
    (ValueError on mismatch).  Amplitudes returned dimensionless (x 1e-12).
    """
    if order not in (0, 1, 2):
        raise ValueError(f"step-2 table: order must be 0, 1 or 2, got {order}")
    names, mults, ip, op = [], [], [], []
    for lineno, line in enumerate(text.splitlines(), 1):
        tok = line.split()
        idx = [i for i, t in enumerate(tok) if _DOODSON_TOKEN.match(t)]
        if not idx:
            continue
        i = idx[0]
        after = tok[i + 1:]
        try:
            if order == 1:  # 6.5a
                ints, rest = after[0:11], after[11:]
                amp_ip, amp_op = float(rest[2]), float(rest[3])
            elif order == 0:  # 6.5b
                ints, rest = after[1:12], after[12:]
                amp_ip, amp_op = float(rest[1]), float(rest[3])
            else:  # 6.5c
                ints, rest = after[1:12], after[12:]
                amp_ip, amp_op = float(rest[1]), 0.0
            ints = [int(x) for x in ints]
        except (IndexError, ValueError):
            raise ValueError(f"step-2 table (order {order}) line {lineno}: cannot parse {line!r}") from None
        n = doodson_multipliers(tok[i])
        if list(n) != ints[:6]:
            raise ValueError(f"step-2 table line {lineno}: Doodson number {tok[i]} does not match "
                             f"the printed multipliers {ints[:6]}")
        n1, big = delaunay_multipliers(n)
        if list(big) != ints[6:] or n1 != order:
            raise ValueError(f"step-2 table line {lineno}: Doodson number {tok[i]} implies Delaunay "
                             f"multipliers {list(big)} and order {n1}; printed {ints[6:]}, table order {order}")
        names.append(tok[0] if i >= 2 or (i == 1 and order != 1) else "")
        mults.append(n)
        ip.append(amp_ip * 1e-12)
        op.append(amp_op * 1e-12)
    if not mults:
        raise ValueError(f"step-2 table (order {order}): no data rows found")
    return Step2Table(order=np.full(len(mults), order, dtype=np.int64), doodson=np.array(mults, dtype=np.int64),
                      ip=np.array(ip), op=np.array(op), names=tuple(names))


@functools.lru_cache(maxsize=1)
def load_love_numbers() -> LoveNumbers:
    """The shipped TN36 Table 6.3 (``data/iers2010/tab6.3.txt``), parsed once."""
    return parse_love_numbers(read_iers_table("tab6.3.txt"))


@functools.lru_cache(maxsize=1)
def load_step2_table() -> Step2Table:
    """The shipped TN36 Tables 6.5b (m = 0), 6.5a (m = 1), 6.5c (m = 2),
    concatenated in that order (21 + 48 + 2 = 71 constituents)."""
    parts = [parse_step2_table(read_iers_table("tab6.5b.txt"), 0),
             parse_step2_table(read_iers_table("tab6.5a.txt"), 1),
             parse_step2_table(read_iers_table("tab6.5c.txt"), 2)]
    return Step2Table(order=np.concatenate([p.order for p in parts]),
                      doodson=np.concatenate([p.doodson for p in parts]),
                      ip=np.concatenate([p.ip for p in parts]),
                      op=np.concatenate([p.op for p in parts]),
                      names=sum((p.names for p in parts), ()))


# --------------------------------------------------------------------------
# sub-daily EOP corrections (ocean tides, libration): TN36 Tables 8.2, 8.3, 5.1a


@dataclass(frozen=True, eq=False)
class TidalEOPTerms:
    """Trigonometric terms of the sub-daily EOP corrections (IERS 2010).

    Each term j has integer multipliers ``mult[j]`` of the six arguments
    (gamma = GMST + pi, l, l', F, D, Omega) and coefficients of
    sin(arg) and cos(arg):

    pm_mult (n_pm, 6) int64, pm_coef (n_pm, 4) float64 [rad]:
        x_p sin, x_p cos, y_p sin, y_p cos (ocean tides, TN36 Table 8.2, plus,
        if included, the libration terms of Table 5.1a);
    ut1_mult (n_ut, 6) int64, ut1_coef (n_ut, 2) float64 [s]:
        UT1 sin, UT1 cos (ocean tides, TN36 Table 8.3).
    periods_pm, periods_ut1 : the tables' period column [d] (for checks only).
    """

    pm_mult: np.ndarray
    pm_coef: np.ndarray
    ut1_mult: np.ndarray
    ut1_coef: np.ndarray
    periods_pm: np.ndarray
    periods_ut1: np.ndarray
    source: str = ""


def _parse_tidal_table(text: str, n_coef: int, source: str):
    """Rows '... m1..m6 doodson period c1..c_ncoef' of an IERS table (Orekit
    transcription); lines starting with '#' and non-numeric lines skipped.
    Returns (mult (n,6) int64, period (n,), coef (n, n_coef))."""
    mult, per, coef = [], [], []
    need = 8 + n_coef
    for line in text.splitlines():
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        tok = s.split()
        if len(tok) < need:
            continue
        tail = tok[-need:]
        try:
            m = [int(t) for t in tail[:6]]
            doodson = float(tail[6])
            p = float(tail[7])
            c = [float(t) for t in tail[8:]]
        except ValueError:
            continue
        if "." not in tail[6] or doodson <= 0:
            continue
        mult.append(m)
        per.append(p)
        coef.append(c)
    if not mult:
        raise ValueError(f"{source}: no tidal terms found")
    return np.array(mult, dtype=np.int64), np.array(per), np.array(coef)


@functools.lru_cache(maxsize=4)
def load_tidal_eop_terms(ocean: bool = True, libration: bool = True) -> TidalEOPTerms:
    """Sub-daily EOP correction terms from the shipped IERS 2010 tables.

    ocean: diurnal and semidiurnal ocean-tide terms in x_p, y_p (TN36 Table
    8.2, 71 terms, ``iers2010/tab8.2ab.txt``) and UT1 (Table 8.3,
    ``iers2010/tab8.3ab.txt``), the coefficients of the IERS routine
    ``interp.f`` (PMUT1_OCEANS); libration: the 10 quasi-diurnal libration
    terms in polar motion (Table 5.1a, ``iers2010/tab5.1a.txt``, long-period
    terms removed as in PMSDNUT2).  The UT1 libration (Table 5.1b) is not
    shipped and not included (amplitude a few us).  Coefficients are
    converted to rad (from uas) and s (from us).  Cached.
    """
    pm_m, pm_c, pm_p = [np.zeros((0, 6), np.int64)], [np.zeros((0, 4))], [np.zeros(0)]
    ut_m, ut_c, ut_p = np.zeros((0, 6), np.int64), np.zeros((0, 2)), np.zeros(0)
    src = []
    if ocean:
        m, p, c = _parse_tidal_table(read_iers_table("tab8.2ab.txt"), 4, "tab8.2ab.txt")
        pm_m.append(m), pm_c.append(c * _MICROARCSEC), pm_p.append(p)
        ut_m, ut_p, c = _parse_tidal_table(read_iers_table("tab8.3ab.txt"), 2, "tab8.3ab.txt")
        ut_c = c * 1e-6
        src.append("ocean tides: IERS 2010 Tables 8.2, 8.3 (interp.f)")
    if libration:
        m, p, c = _parse_tidal_table(read_iers_table("tab5.1a.txt"), 4, "tab5.1a.txt")
        pm_m.append(m), pm_c.append(c * _MICROARCSEC), pm_p.append(p)
        src.append("polar-motion libration: IERS 2010 Table 5.1a (PMSDNUT2)")
    return TidalEOPTerms(np.concatenate(pm_m), np.concatenate(pm_c), ut_m, ut_c,
                         np.concatenate(pm_p), ut_p, "; ".join(src))
