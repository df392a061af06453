"""JPL planetary ephemerides (SPK files, via jplephem): geocentric states of
the Sun, the Moon and the planets, and the GMs that go with them.

Physics-free data access.  tqdyn's dynamics is geocentric (GCRS: ICRF axes,
origin at the Earth's center); the JPL DE ephemerides are barycentric with
ICRF axes, so a geocentric state is a difference of segment states:

* Earth  = (0 -> 3) + (3 -> 399)           (SSB -> EMB -> Earth)
* Moon   = (3 -> 301) - (3 -> 399)         (geocentric, from the EMB segments only)
* Sun    = (0 -> 10) - Earth
* planet k = (0 -> k) - Earth              (k = 1..8: the planet's *system barycenter*)

The planets are taken at their system barycenters (Mars, Jupiter ... with
their moons), which is what a point-mass perturbation with the *system* GM
(``BODYk_GM`` of the NAIF GM file) needs.  For Mercury and Venus, which have
no moons, barycenter and body coincide in the DE files.

Time argument: TDB as a two-part Julian date ``(jd1, jd2)`` in days (ERFA
convention, see :mod:`tqdyn.astro.timescales`), kept two-part down to the
Chebyshev evaluation: the fraction of the Chebyshev interval is formed as
``((jd1 - J2000) * 86400 - init - k * intlen) + jd2 * 86400`` whose first
bracket is exact for ``jd1`` on a half day, so the time resolution is that of
``jd2`` (19 ps for |jd2| < 2 d, 1.2 ns at 90 d).

Units out: m and m/s (the SPK files hold km and km/s, or km/day for the
derivatives of type-2 polynomials), ICRF axes = GCRS directions.

The SPK segments (Chebyshev types 2 and 3) are evaluated by a compiled
(numba) Clenshaw-free forward recurrence, vectorised over instants, faster
than jplephem's numpy evaluation (jplephem itself only reads the file here;
``tqdyn bench --model kernels`` times the third bodies of one chunk).
Files with several segments for one center/target pair (DE431, DE441, split
in time) are handled by evaluating each instant in the segment that covers it.

Shipped default: DE421 (1899-07-29 .. 2053-10-09), from the PyPI package
``skyfield-data`` (a tqdyn dependency).  Any other DE file (DE430, DE440 ...)
by path.  GMs: ``data/gm_de431.tpc`` (DE430/DE431 values, km^3/s^2 in the
file, m^3/s^2 here; read by :func:`tqdyn.readers.pck.parse_gm_tpc`).  DE421 itself was integrated with slightly different
GMs (it predates DE430); the differences are small relative amounts that
only scale the point-mass terms, and the DE430 set is the one of the paper's
model (Table II: DE430).
"""

from __future__ import annotations

import atexit
import functools
import importlib.resources
import math
import os

import erfa
import numpy as np
from numba import njit

from .._choices import unknown
from ..numerics import jit as _jit  # noqa: F401  (package-wide kernel cache before any @njit)
from ..readers.pck import shipped_gm
from .constants import DAY_S, J2000_JD

__all__ = [
    "BODIES",
    "HELIOCENTRIC_BODIES",
    "NAIF_ID",
    "Ephemeris",
    "default_ephemeris",
    "default_ephemeris_path",
    "ephemeris_named",
    "planetary_gm",
]

#: Bodies whose geocentric states :meth:`Ephemeris.geocentric` provides.
BODIES = ("sun", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")

#: Bodies whose heliocentric states :meth:`Ephemeris.heliocentric_states` provides.
HELIOCENTRIC_BODIES = ("earth", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")

#: NAIF ids used for each name (planets: system barycenters); "earth" is the
#: Earth itself (399), used for its GM only.
NAIF_ID = {
    "sun": 10, "moon": 301, "mercury": 1, "venus": 2, "mars": 4, "jupiter": 5,
    "saturn": 6, "uranus": 7, "neptune": 8, "pluto": 9, "earth": 399,
}

_SSB, _EMB, _EARTH, _MOON = 0, 3, 399, 301

#: Segment chain of each body's geocentric state: (center, target) of its
#: own segment, minus the base state "emb_earth" (3->399) for the Moon or
#: "earth" ((0->3) + (3->399): the SSB -> Earth vector) for the others.
_CHAIN = {
    "moon": ((_EMB, _MOON), "emb_earth"),
    "sun": ((_SSB, 10), "earth"),
    "mercury": ((_SSB, 1), "earth"),
    "venus": ((_SSB, 2), "earth"),
    "mars": ((_SSB, 4), "earth"),
    "jupiter": ((_SSB, 5), "earth"),
    "saturn": ((_SSB, 6), "earth"),
    "uranus": ((_SSB, 7), "earth"),
    "neptune": ((_SSB, 8), "earth"),
    "pluto": ((_SSB, 9), "earth"),
}
_EARTH_CHAIN = ((_SSB, _EMB), (_EMB, _EARTH))
_BASE_INDEX = {"emb_earth": 0, "earth": 1}  # rows of the scratch base array

_KM = 1000.0  # m per km
_J2000 = float(J2000_JD)  # SPK times are TDB seconds past J2000 (compile-time constants in numba)
_DAY = float(DAY_S)


def default_ephemeris_path() -> str:
    """Path of the shipped DE421 file (PyPI package ``skyfield-data``:
    ``skyfield_data/data/de421.bsp``; located without calling
    ``skyfield_data.get_skyfield_data_path``, which warns about an unrelated
    expired file).  Raises FileNotFoundError if the package is missing."""
    try:
        path = importlib.resources.files("skyfield_data") / "data" / "de421.bsp"
    except ModuleNotFoundError:
        raise FileNotFoundError("ephemeris: the default DE421 file comes with the Python package "
                                "'skyfield-data', which is not installed (pip install skyfield-data)") from None
    return str(path)


# --------------------------------------------------------------------------
# compiled Chebyshev evaluation


@njit(cache=True)
def _cheb_eval(coef, init, intlen, type3, jd1, jd2, sel, want_vel, out_p, out_v, ob, base_p, base_v, bb, bsign):
    """Evaluate one SPK Chebyshev segment at many instants, adding a base state.

    coef: (n_rec, n_comp, n_coef) float64 Chebyshev coefficients (km; for a
    type-3 segment, components 3..5 are the velocity in km/s); init [s TDB
    past J2000], intlen [s]: start and length of the records; type3: bool;
    jd1, jd2: (n,) two-part TDB Julian dates [d], all inside [init, init +
    n_rec intlen] (checked by the caller); sel: (m,) int64 instants to
    evaluate (empty = all n).  For each selected instant i:

        out_p[i, ob, :] = position [m] + bsign * base_p[i, bb, :]
        out_v[i, ob, :] = velocity [m/s] + bsign * base_v[i, bb, :]   (if want_vel)

    out_*, base_*: (n, *, 3) float64; bsign = 0 ignores the base.
    """
    n_rec, _, n_coef = coef.shape
    tk = np.empty(n_coef)
    dk = np.zeros(n_coef)
    scale = 2.0 / intlen
    use_sel = sel.shape[0] > 0
    n = sel.shape[0] if use_sel else jd1.shape[0]
    der = want_vel and not type3
    for m in range(n):
        i = sel[m] if use_sel else m
        a = (jd1[i] - _J2000) * _DAY - init  # exact for jd1 on a half day
        b = jd2[i] * _DAY
        k = int(math.floor((a + b) / intlen))
        if k >= n_rec:  # the end point belongs to the last record
            k = n_rec - 1
        if k < 0:
            k = 0
        off = (a - k * intlen) + b  # a - k intlen exact (integers of s)
        s = off * scale - 1.0
        # Chebyshev polynomials T_j(s) and derivatives dT_j/ds, forward recurrence
        tk[0] = 1.0
        if n_coef > 1:
            tk[1] = s
            dk[1] = 1.0
        s2 = 2.0 * s
        for j in range(2, n_coef):
            tk[j] = s2 * tk[j - 1] - tk[j - 2]
        if der:
            for j in range(2, n_coef):
                dk[j] = 2.0 * tk[j - 1] + s2 * dk[j - 1] - dk[j - 2]
        for c in range(3):
            acc = 0.0
            for j in range(n_coef - 1, -1, -1):  # small terms first
                acc += coef[k, c, j] * tk[j]
            p = acc * _KM
            if bsign != 0.0:
                p += bsign * base_p[i, bb, c]
            out_p[i, ob, c] = p
            if want_vel:
                acc = 0.0
                if type3:
                    for j in range(n_coef - 1, -1, -1):
                        acc += coef[k, c + 3, j] * tk[j]
                    v = acc * _KM
                else:
                    for j in range(n_coef - 1, 0, -1):
                        acc += coef[k, c, j] * dk[j]
                    v = acc * (scale * _KM)
                if bsign != 0.0:
                    v += bsign * base_v[i, bb, c]
                out_v[i, ob, c] = v


_ALL = np.zeros(0, dtype=np.int64)  # "every instant" for _cheb_eval


class _Segment:
    """One SPK segment's Chebyshev data in memory (read lazily)."""

    __slots__ = ("seg", "start_jd", "end_jd", "data_type", "_coef", "_init", "_intlen")

    def __init__(self, seg):
        self.seg = seg
        self.start_jd = float(seg.start_jd)
        self.end_jd = float(seg.end_jd)
        self.data_type = int(seg.data_type)
        self._coef = None

    def load(self):
        """(coef (n_rec, n_comp, n_coef) C-contiguous, init [s], intlen [s])."""
        if self._coef is None:
            seg = self.seg
            if seg.daf.file.closed:
                raise ValueError("ephemeris: the file was closed (Ephemeris.close) before this segment was read")
            n_comp = {2: 3, 3: 6}[self.data_type]
            try:
                init, intlen, rsize, n = seg.daf.read_array(seg.end_i - 3, seg.end_i)
                rsize, n = int(rsize), int(n)
                raw = seg.daf.map_array(seg.start_i, seg.end_i - 4).reshape(n, rsize)
            except (TypeError, ValueError, OSError) as exc:  # e.g. "buffer is too small": a truncated file
                name = getattr(seg.daf.file, "name", "the SPK file")
                raise ValueError(f"ephemeris file {name}: segment {seg.center}->{seg.target} cannot be read "
                                 f"({exc}); the file is truncated or damaged, download it again") from None
            n_coef = (rsize - 2) // n_comp
            self._coef = np.ascontiguousarray(raw[:, 2:].reshape(n, n_comp, n_coef), dtype=np.float64)
            self._init, self._intlen = float(init), float(intlen)
        return self._coef, self._init, self._intlen

    def evaluate(self, jd1, jd2, sel, want_vel, out_p, out_v, ob, base_p, base_v, bb, bsign):
        """See :func:`_cheb_eval`."""
        coef, init, intlen = self.load()
        _cheb_eval(coef, init, intlen, self.data_type == 3, jd1, jd2, sel, want_vel,
                   out_p, out_v, ob, base_p, base_v, bb, bsign)


class _Pair:
    """All segments of one (center, target) pair, sorted in time."""

    def __init__(self, segments):
        self.segments = sorted(segments, key=lambda s: s.start_jd)
        self.start_jd = self.segments[0].start_jd
        self.end_jd = self.segments[0].end_jd
        for s in self.segments[1:]:  # contiguous coverage only
            if s.start_jd <= self.end_jd:
                self.end_jd = max(self.end_jd, s.end_jd)

    def evaluate(self, jd1, jd2, *args):
        """Each instant in the segment that covers it (the last one listed
        wins on overlaps, as in SPICE); args as :meth:`_Segment.evaluate`
        after sel."""
        if len(self.segments) == 1:
            self.segments[0].evaluate(jd1, jd2, _ALL, *args)
            return
        t = (jd1 - _J2000) + jd2
        todo = np.ones(jd1.shape[0], dtype=bool)
        for seg in reversed(self.segments):
            m = todo & (t >= seg.start_jd - _J2000) & (t <= seg.end_jd - _J2000)
            sel = np.flatnonzero(m).astype(np.int64)
            if sel.size:
                seg.evaluate(jd1, jd2, sel, *args)
                todo &= ~m


def _calendar(jd1: float, jd2: float) -> str:
    """'YYYY-MM-DDTHH:MM:SS' of a two-part JD (calendar of its own scale), or the JD."""
    try:
        y, mo, d, hmsf = erfa.d2dtf("TDB", 0, jd1, jd2)
        return f"{int(y):04d}-{int(mo):02d}-{int(d):02d}T{hmsf['h']:02d}:{hmsf['m']:02d}:{hmsf['s']:02d}"
    except Exception:  # noqa: BLE001 (dates outside ERFA's calendar)
        return f"JD {jd1 + jd2:.6f}"


class Ephemeris:
    """A JPL DE ephemeris (SPK/.bsp file) read with jplephem.

    Parameters
    ----------
    path : str or os.PathLike, optional
        SPK file; ``None`` -> DE421 shipped by the PyPI package
        ``skyfield-data`` (:func:`default_ephemeris_path`).  A missing file
        raises FileNotFoundError naming the path; a file without the Earth
        chain (0->3, 3->399) raises ValueError.

    Attributes
    ----------
    name : str
        File name without extension, upper case (``"DE421"``).
    path : str
        Absolute path of the file.
    span_jd : tuple[float, float]
        TDB Julian dates [d] covered by every segment needed for
        :data:`BODIES` that the file holds (end points included).
    bodies : tuple[str, ...]
        The names of :data:`BODIES` (and ``"pluto"``) available in the file.
    """

    def __init__(self, path=None):
        from jplephem.spk import SPK

        path = default_ephemeris_path() if path is None else os.fspath(path)
        path = os.path.abspath(path)
        if not os.path.isfile(path):
            raise FileNotFoundError(f"ephemeris file not found: {path}")
        try:
            self._spk = SPK.open(path)
        except Exception as exc:  # noqa: BLE001 (jplephem raises plain ValueError/struct errors)
            raise ValueError(f"ephemeris file {path}: not a readable SPK (DAF) file ({exc})") from None
        self.path = path
        self.name = os.path.splitext(os.path.basename(path))[0].upper()
        # a truncated file: its summaries point past the end (8-byte words, 1-based)
        size = os.path.getsize(path)
        try:
            need = max((int(seg.end_i) * 8 for seg in self._spk.segments), default=0)
        except Exception as exc:  # noqa: BLE001
            self._spk.close()
            raise ValueError(f"ephemeris file {path}: not a readable SPK (DAF) file ({exc})") from None
        if need > size:
            self._spk.close()
            raise ValueError(f"ephemeris file {path} is truncated: {size} bytes, its segments need {need}; "
                             f"download it again")
        groups: dict[tuple[int, int], list] = {}
        for seg in self._spk.segments:
            if seg.data_type in (2, 3):
                groups.setdefault((seg.center, seg.target), []).append(_Segment(seg))
        self._pairs = {key: _Pair(segs) for key, segs in groups.items()}
        missing = [f"{c}->{t}" for c, t in _EARTH_CHAIN if (c, t) not in self._pairs]
        if missing:
            raise ValueError(f"ephemeris {self.name} ({path}): no Chebyshev (type 2/3) segment "
                             f"{', '.join(missing)}; the geocentric chain needs 0->3 and 3->399")
        bodies = []
        for body, (key, _) in _CHAIN.items():
            if key in self._pairs:
                bodies.append(body)
        self.bodies = tuple(bodies)
        needed = set(_EARTH_CHAIN)
        for body in self.bodies:
            if body in BODIES:
                needed.add(_CHAIN[body][0])
        self.span_jd = (max(self._pairs[k].start_jd for k in needed),
                        min(self._pairs[k].end_jd for k in needed))

    def __repr__(self) -> str:
        return f"Ephemeris({self.path!r})"

    def __reduce__(self):  # picklable: reopen by path
        return (Ephemeris, (self.path,))

    def close(self) -> None:
        """Close the file (segments already read stay usable; others raise
        ValueError).  Ephemeris is also a context manager."""
        self._spk.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------------

    def _check_span(self, jd1: np.ndarray, jd2: np.ndarray) -> None:
        """ValueError naming the first date outside span_jd (or NaN)."""
        lo, hi = self.span_jd
        # compare day offsets from the span start: exact enough (< 1 ns) at the edges
        d = (jd1 - lo) + jd2
        bad = ~((d >= 0.0) & (d <= hi - lo))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            j1, j2 = float(jd1[i]), float(jd2[i])
            if not (math.isfinite(j1) and math.isfinite(j2)):
                raise ValueError(f"ephemeris {self.name}: date is not finite (jd1={j1}, jd2={j2})")
            raise ValueError(
                f"ephemeris {self.name} ({self.path}): date {_calendar(j1, j2)} TDB is outside its span "
                f"{_calendar(lo, 0.0).removesuffix('T00:00:00')} .. {_calendar(hi, 0.0).removesuffix('T00:00:00')} TDB")

    def validate_bodies(self, bodies) -> tuple[str, ...]:
        """Lower-cased body names, checked against :data:`BODIES` (and
        "pluto") and against the segments of this file; ValueError otherwise."""
        if isinstance(bodies, str):
            bodies = (bodies,)
        out = []
        for b in bodies:
            key = str(b).lower()
            if key not in _CHAIN:
                raise ValueError(unknown("ephemeris", b, [*BODIES, "pluto"], problem="is not a body", noun="bodies"))
            if key not in self.bodies:
                raise ValueError(f"ephemeris {self.name} ({self.path}) holds no segments for {b!r}; "
                                 f"available: {', '.join(self.bodies)}")
            out.append(key)
        return tuple(out)

    def _flat_dates(self, jd1, jd2) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
        """(shape S, jd1, jd2 flattened and contiguous) of two-part TDB
        dates broadcast against each other, checked against the span."""
        jd1, jd2 = np.broadcast_arrays(np.asarray(jd1, dtype=np.float64), np.asarray(jd2, dtype=np.float64))
        j1 = np.ascontiguousarray(jd1.reshape(-1))
        j2 = np.ascontiguousarray(jd2.reshape(-1))
        self._check_span(j1, j2)
        return jd1.shape, j1, j2

    def geocentric_states(self, bodies, jd1, jd2, *, velocity: bool = True):
        """Geocentric states of several bodies at once (the Earth chain is
        evaluated once for all of them).

        Parameters
        ----------
        bodies : sequence of str
            Names from :data:`BODIES` (case-insensitive; ``"pluto"`` too).
        jd1, jd2 : float or array_like
            Two-part TDB Julian dates [d]; broadcast against each other to
            shape S.
        velocity : bool
            Also return velocities (about twice the cost of positions alone).

        Returns
        -------
        pos : ndarray, S + (n_bodies, 3), float64 [m]
        vel : ndarray, S + (n_bodies, 3), float64 [m/s], or None if not velocity
            Geocentric position and velocity, ICRF axes (GCRS directions),
            TDB time argument.

        Raises ValueError for an unknown body or a date outside ``span_jd``.
        """
        names = self.validate_bodies(bodies)
        shape, j1, j2 = self._flat_dates(jd1, jd2)
        n = j1.shape[0]
        pos = np.empty((n, len(names), 3))
        vel = np.empty((n, len(names), 3)) if velocity else pos  # pos: unused placeholder
        # base states: [:, 0] = EMB -> Earth, [:, 1] = SSB -> Earth
        bases = {_CHAIN[name][1] for name in names}
        base_p = np.empty((n, 2, 3))
        base_v = np.empty((n, 2, 3)) if velocity else base_p
        if bases:
            self._pairs[_EARTH_CHAIN[1]].evaluate(j1, j2, velocity, base_p, base_v, 0, base_p, base_v, 0, 0.0)
        if "earth" in bases:
            self._pairs[_EARTH_CHAIN[0]].evaluate(j1, j2, velocity, base_p, base_v, 1, base_p, base_v, 0, 1.0)
        for b, name in enumerate(names):
            key, base = _CHAIN[name]
            self._pairs[key].evaluate(j1, j2, velocity, pos, vel, b, base_p, base_v, _BASE_INDEX[base], -1.0)
        pos = pos.reshape(shape + (len(names), 3))
        vel = vel.reshape(shape + (len(names), 3)) if velocity else None
        return pos, vel

    def heliocentric_states(self, bodies, jd1, jd2, *, velocity: bool = True):
        """Heliocentric states of several bodies at once: barycentric state
        of the body minus that of the Sun (0 -> 10).

        bodies: names from :data:`HELIOCENTRIC_BODIES` (``"earth"`` = the
        chain (0->3) + (3->399), ``"moon"`` = (0->3) + (3->301), the planets
        at their system barycentres (0->k)); jd1, jd2: two-part TDB Julian
        dates [d], broadcast to shape S.  Returns pos S + (n_bodies, 3)
        float64 [m] and vel (same, [m/s]) or None: Sun-centred, ICRF axes,
        TDB-compatible BCRS coordinates (a Newtonian translation of the
        barycentric ones).  ValueError for an unknown body or a date outside
        ``span_jd``.
        """
        if isinstance(bodies, str):
            bodies = (bodies,)
        names = tuple(str(b).lower() for b in bodies)
        for b in names:
            if b not in HELIOCENTRIC_BODIES:
                raise ValueError(unknown("ephemeris", b, HELIOCENTRIC_BODIES, problem="is not a heliocentric body",
                                         noun="bodies"))
        self.validate_bodies(tuple(b for b in names if b != "earth") + ("sun",))
        shape, j1, j2 = self._flat_dates(jd1, jd2)
        n = j1.shape[0]
        # scratch rows: 0 = SSB -> Sun, 1 = SSB -> EMB
        base_p = np.empty((n, 2, 3))
        base_v = np.empty((n, 2, 3)) if velocity else base_p
        self._pairs[(_SSB, 10)].evaluate(j1, j2, velocity, base_p, base_v, 0, base_p, base_v, 0, 0.0)
        if any(b in ("earth", "moon") for b in names):
            self._pairs[_EARTH_CHAIN[0]].evaluate(j1, j2, velocity, base_p, base_v, 1, base_p, base_v, 0, 0.0)
        pos = np.empty((n, len(names), 3))
        vel = np.empty((n, len(names), 3)) if velocity else pos
        for b, name in enumerate(names):
            if name in ("earth", "moon"):
                key = (_EMB, _EARTH if name == "earth" else _MOON)
                self._pairs[key].evaluate(j1, j2, velocity, pos, vel, b, base_p, base_v, 1, 1.0)
            else:
                self._pairs[_CHAIN[name][0]].evaluate(j1, j2, velocity, pos, vel, b, base_p, base_v, 0, 0.0)
                continue
            pos[:, b] -= base_p[:, 0]
            if velocity:
                vel[:, b] -= base_v[:, 0]
        for b, name in enumerate(names):
            if name not in ("earth", "moon"):
                pos[:, b] -= base_p[:, 0]
                if velocity:
                    vel[:, b] -= base_v[:, 0]
        pos = pos.reshape(shape + (len(names), 3))
        vel = vel.reshape(shape + (len(names), 3)) if velocity else None
        return pos, vel

    def earth_barycentric(self, jd1, jd2) -> tuple[np.ndarray, np.ndarray]:
        """Barycentric position [m] and velocity [m/s] of the Earth (the chain
        (0->3) + (3->399)), ICRF axes, BCRS (TDB-compatible), at the two-part
        TDB Julian dates jd1, jd2 (broadcast to shape S): two arrays S + (3,)."""
        shape, j1, j2 = self._flat_dates(jd1, jd2)
        n = j1.shape[0]
        base_p = np.empty((n, 2, 3))
        base_v = np.empty((n, 2, 3))
        self._pairs[_EARTH_CHAIN[1]].evaluate(j1, j2, True, base_p, base_v, 0, base_p, base_v, 0, 0.0)
        self._pairs[_EARTH_CHAIN[0]].evaluate(j1, j2, True, base_p, base_v, 1, base_p, base_v, 0, 1.0)
        return base_p[:, 1].reshape(shape + (3,)), base_v[:, 1].reshape(shape + (3,))

    def sun_barycentric(self, jd1, jd2) -> tuple[np.ndarray, np.ndarray]:
        """Barycentric position [m] and velocity [m/s] of the Sun (segment
        0 -> 10), ICRF axes, BCRS (TDB-compatible), at the two-part TDB Julian
        dates jd1, jd2 (broadcast to shape S): two arrays S + (3,)."""
        shape, j1, j2 = self._flat_dates(jd1, jd2)
        n = j1.shape[0]
        pos = np.empty((n, 1, 3))
        vel = np.empty((n, 1, 3))
        self._pairs[(_SSB, 10)].evaluate(j1, j2, True, pos, vel, 0, pos, vel, 0, 0.0)
        return pos[:, 0].reshape(shape + (3,)), vel[:, 0].reshape(shape + (3,))

    def geocentric_positions_dd(self, bodies, tdb_hi, tdb_lo) -> tuple[np.ndarray, np.ndarray]:
        """Geocentric positions of ``bodies`` (as :meth:`geocentric_states`)
        in double-double, smooth functions of time: Clenshaw's recurrence and
        the segment sums in dd at the dd time tdb_hi + tdb_lo [s TDB past
        J2000] (any broadcast shape S; :mod:`tqdyn.astro.ephemeris_dd`).
        Returns (hi, lo), each S + (n_bodies, 3) float64 [m], ICRF axes."""
        from .ephemeris_dd import chain_positions_dd

        names = self.validate_bodies(bodies)
        th, tl = np.broadcast_arrays(np.asarray(tdb_hi, dtype=np.float64), np.asarray(tdb_lo, dtype=np.float64))
        shape, th, tl = th.shape, np.ascontiguousarray(th.reshape(-1)), np.ascontiguousarray(tl.reshape(-1))
        self._check_span(np.full(th.shape, _J2000), (th + tl) / _DAY)
        bases = {_CHAIN[name][1] for name in names}  # base rows: 0 = EMB -> Earth, 1 = SSB -> Earth
        base_ops = [(self._pairs[_EARTH_CHAIN[1]], 0, 0, 0.0)] if bases else []
        if "earth" in bases:
            base_ops.append((self._pairs[_EARTH_CHAIN[0]], 1, 0, 1.0))
        ops = [(self._pairs[_CHAIN[n][0]], b, _BASE_INDEX[_CHAIN[n][1]], -1.0) for b, n in enumerate(names)]
        hi, lo = chain_positions_dd(base_ops, ops, th, tl)
        return hi.reshape(shape + (len(names), 3)), lo.reshape(shape + (len(names), 3))

    def geocentric(self, body, jd1, jd2) -> tuple[np.ndarray, np.ndarray]:
        """Geocentric position [m] and velocity [m/s] of ``body``.

        Parameters
        ----------
        body : str
            One of :data:`BODIES` (case-insensitive).
        jd1, jd2 : float or array_like
            Two-part TDB Julian dates [d] (e.g. from
            :func:`tqdyn.astro.timescales.tdb_jd`), broadcast to shape S.

        Returns
        -------
        pos, vel : ndarray, S + (3,) each, float64 [m], [m/s]
            ICRF axes (GCRS directions: the geocentric frame of the
            propagation), TDB time argument.  Chains: Moon = (3->301) -
            (3->399); Sun = (0->10) - ((0->3) + (3->399)); planets via their
            system barycenters (0->k) minus the same Earth chain.

        Raises ValueError for a date outside ``span_jd`` (naming the date as a
        TDB calendar date and the span) or an unknown body.
        """
        pos, vel = self.geocentric_states((body,), jd1, jd2, velocity=True)
        return pos[..., 0, :], vel[..., 0, :]


@functools.lru_cache(maxsize=1)
def default_ephemeris() -> Ephemeris:
    """The shipped DE421 :class:`Ephemeris` (opened once, cached, closed at exit)."""
    eph = Ephemeris()
    atexit.register(eph.close)
    return eph


def ephemeris_named(name_or_path: str) -> Ephemeris:
    """The JPL ephemeris a scenario names (``forces.ephemeris``): ``"de421"``
    (any case) is the shipped one (:func:`default_ephemeris`), anything else
    the path of a .bsp file."""
    return default_ephemeris() if name_or_path.lower() == "de421" else Ephemeris(name_or_path)


# --------------------------------------------------------------------------
# GMs


@functools.lru_cache(maxsize=1)
def _planetary_gm() -> tuple[tuple[str, float], ...]:
    gm = shipped_gm()
    return tuple((name, gm[naif]) for name, naif in NAIF_ID.items())


def planetary_gm() -> dict[str, float]:
    """GMs [m^3/s^2] of the DE430/DE431 ephemerides (``data/gm_de431.tpc``):
    ``sun`` (BODY10), ``moon`` (BODY301), the planetary *systems*
    ``mercury`` .. ``neptune``, ``pluto`` (BODY1..9: barycenters, planet plus
    moons, matching the barycentric positions of :class:`Ephemeris`) and
    ``earth`` (BODY399).  TDB-compatible values.  A fresh dict from a cache."""
    return dict(_planetary_gm())


