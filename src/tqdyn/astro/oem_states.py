"""States from CCSDS OEM files (read by :mod:`tqdyn.readers.oem`): their
interpolation as the file says (:func:`states_at`), the continuity of a file
of several segments (:func:`require_continuous`), and tqdyn's systems
(:func:`to_heliocentric`, :func:`to_geocentric`: the EME2000 frame bias,
TCB -> TDB by :func:`tqdyn.astro.timescales.tcb_to_tdb`).

Interpolation (INTERPOLATION, INTERPOLATION_DEGREE of CCSDS 502.0-B-2):
HERMITE of degree 2n - 1 through the positions and velocities of n records
(the velocity is the polynomial's derivative), LAGRANGE of degree n - 1 (and
LINEAR, n = 2) through positions and velocities separately; the n records
are consecutive ones with as many on each side of the epoch as possible
(n // 2 at or before it), shifted inwards at the ends; at a record's epoch
the record itself.

Several segments (a file that :func:`tqdyn.readers.oem.read_oem` joined):

* the segment for an epoch: the one whose usable span holds it (spans in
  time order, each starting where the previous one stops; records may
  overlap outside them); at the epoch where one segment stops and the next
  starts, the next one (a later segment takes over from its start, as SPICE
  and Orekit read several segments): its record;
* windows inside that segment: the n records never mix segments, so every
  state is the one the segment itself gives (near a boundary the window is
  shifted inwards, as at the ends of a file).  Measured on ESA's CReMA 2.0
  November-launch files (tests/test_oem_segments.py): a window that would
  cross the boundary instead moves the states of the last interval before
  it by up to 27 m and 3.8e-4 m/s, while the files' records agree with their
  own interpolation only to 40 m (median), up to 190 m and 6.4e-4 m/s (each
  left out and interpolated from the others).  Only a segment with fewer
  records than a window takes the missing ones from its neighbours (the
  records of the segments that hold their epochs);
* continuity (:func:`require_continuous`), at each epoch where one segment
  takes over from the previous one: both segments interpolated there must
  agree within ``sqrt(3)/2 (u_1 + u_2) + e`` in position (and the same with
  the velocities' digits and errors), where u_1, u_2 are one unit of the last
  digit each segment prints (two roundings of <= u/2 on 3 components) and e
  is the interpolation error of the file there: the largest miss of a record
  predicted from its own segment's other records (leave one out; the n
  interior records of each segment nearest that epoch).  A jump below the
  error with which the records already agree with their interpolation is no
  discontinuity any use of the file can see; one above it is.  ESA's files:
  the two states at the shared epoch differ by 2.1 cm (printed to 1 mm) and
  not at all in velocity (printed to 0.1 mm/s); tolerance 160-210 m and
  1.6e-3-1.9e-3 m/s; a second segment shifted by 1 km, or after an impulse
  of 1 cm/s, is refused.  (A segment whose own records disagree, e.g.
  velocities shifted without the positions, raises its e with them.)

Conversions: EME2000 -> ICRF axes by the IAU 2006 frame bias, r_ICRS = B^T
r_EME2000 with B = ``erfa.bp06(...)[0]`` (the bias matrix rb: ICRS -> mean
J2000; a rotation by 23.1 mas, i.e. up to 16.8 km at 1 au); TCB time tags to
TDB (IAU 2006 B3).  ESA's TCB LISA files (``data/esa-lisa-orbits/tcb``)
carry the same numbers as their TDB files, only the time tags differ: their
coordinates are TDB-compatible (not scaled by 1 + L_B), which is the default
of :func:`to_heliocentric` (``tcb_scaled_coordinates=False``).

Errors: one-line ``ValueError`` naming the file (and the segments' spans as
the file writes them); no message names a Python function.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import weakref

import erfa
import numpy as np

from .._choices import allowed, did_you_mean
from ..readers.oem import OemTrajectory, epoch_text, require_center
from .constants import DAY_S, L_B
from .timescales import tcb_to_tdb

__all__ = ["GEOCENTRIC", "HELIOCENTRIC", "INTERPOLATIONS", "frame_bias_matrix", "require_continuous", "states_at",
           "to_geocentric", "to_heliocentric"]

INTERPOLATIONS = ("HERMITE", "LAGRANGE", "LINEAR")
"""INTERPOLATION methods that :func:`states_at` implements."""
HELIOCENTRIC = ("SUN", "ICRF", "TDB")
"""(CENTER_NAME, REF_FRAME, TIME_SYSTEM) of tqdyn's heliocentric system: Sun-centred, ICRF axes, TDB."""
GEOCENTRIC = ("EARTH", "GCRF", "TT")
"""(CENTER_NAME, REF_FRAME, TIME_SYSTEM) of tqdyn's geocentric system: the GCRS (ICRF axes), TT."""

_DAY = float(DAY_S)


def _dsec(a1, a2, b1, b2):
    """(a1 + a2) - (b1 + b2) in seconds, for JD pairs within days of each other."""
    return ((a1 - b1) + (a2 - b2)) * _DAY


# ------------------------------------------------------------------ interpolation

def _nodes(method: str, degree: int, where: str) -> int:
    if method == "HERMITE":
        if degree < 1 or degree % 2 == 0:
            raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for HERMITE must be odd and >= 1 "
                             "(n records with position and velocity give degree 2n - 1)")
        return (degree + 1) // 2
    if method == "LINEAR":
        if degree not in (None, 1):
            raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for LINEAR must be 1")
        return 2
    if degree < 1:
        raise ValueError(f"{where}: INTERPOLATION_DEGREE = {degree} for LAGRANGE must be >= 1")
    return degree + 1


def _method(where: str, file_method, file_degree, method, degree) -> tuple[str, int, int]:
    """(method, degree, records per window): the file's unless given."""
    m = (method or file_method or "").upper()
    if not m:
        raise ValueError(f"{where}: the file gives no INTERPOLATION (allowed: {allowed(INTERPOLATIONS)})")
    if m not in INTERPOLATIONS:
        raise ValueError(f"{where}: INTERPOLATION = {m!r} is not supported{did_you_mean(m, INTERPOLATIONS)} "
                         f"(allowed: {allowed(INTERPOLATIONS)})")
    deg = degree if degree is not None else (file_degree if method is None or m == file_method else None)
    if deg is None:
        if m != "LINEAR":
            raise ValueError(f"{where}: INTERPOLATION = {m} without INTERPOLATION_DEGREE "
                             "(allowed: a degree for HERMITE and LAGRANGE)")
        deg = 1
    return m, int(deg), _nodes(m, int(deg), where)


def _lagrange_basis(tau, d):
    """l_i(t) and l_i'(t) for nodes t_i: tau (M, n) = t - t_i [s], d (M, n, n) = t_i - t_j."""
    n = tau.shape[1]
    l = np.ones_like(tau)
    dl = np.zeros_like(tau)
    for i in range(n):
        others = [j for j in range(n) if j != i]
        for j in others:
            l[:, i] *= tau[:, j] / d[:, i, j]
        for k in others:
            term = 1.0 / d[:, i, k]
            for j in others:
                if j != k:
                    term = term * tau[:, j] / d[:, i, j]
            dl[:, i] += term
    return l, dl


def _interpolate(jd1, jd2, r, v, q1, q2, m: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """r, v (M, 3) at the epochs q1 + q2 (M,) from the N >= n records (jd1, jd2 (N,) strictly
    increasing, r, v (N, 3)) by method ``m`` with windows of n records."""
    N = jd1.shape[0]
    # window: records k - n//2 .. k - n//2 + n - 1, k = records at or before the epoch
    t_rec = _dsec(jd1, jd2, jd1[0], jd2[0])
    t_q = _dsec(q1, q2, jd1[0], jd2[0])
    k = np.searchsorted(t_rec, t_q, side="right")
    first = np.clip(k - n // 2, 0, N - n)
    idx = first[:, None] + np.arange(n)[None, :]                     # (M, n)
    n1, n2 = jd1[idx], jd2[idx]
    tau = _dsec(q1[:, None], q2[:, None], n1, n2)                    # t - t_i [s]
    d = _dsec(n1[:, :, None], n2[:, :, None], n1[:, None, :], n2[:, None, :])  # t_i - t_j [s]
    np.einsum("mii->mi", d)[...] = 1.0                               # unused diagonal
    x, xd = r[idx], v[idx]                                           # (M, n, 3)
    l, dl = _lagrange_basis(tau, d)
    if m == "HERMITE":
        inv = 1.0 / d
        np.einsum("mii->mi", inv)[...] = 0.0
        c = inv.sum(axis=2)                                          # l_i'(t_i)
        g = 1.0 - 2.0 * tau * c
        H = g * l * l
        K = tau * l * l
        dH = -2.0 * c * l * l + 2.0 * g * l * dl
        dK = l * l + 2.0 * tau * l * dl
        ri = np.einsum("mi,mik->mk", H, x) + np.einsum("mi,mik->mk", K, xd)
        vi = np.einsum("mi,mik->mk", dH, x) + np.einsum("mi,mik->mk", dK, xd)
    else:
        ri = np.einsum("mi,mik->mk", l, x)
        vi = np.einsum("mi,mik->mk", l, xd)
    hit_m, hit_i = np.nonzero(tau == 0.0)
    ri[hit_m] = x[hit_m, hit_i]
    vi[hit_m] = xd[hit_m, hit_i]
    return ri, vi


def _outside(traj: OemTrajectory, q1, q2) -> None:
    before = _dsec(q1, q2, *traj.start) < 0
    after = _dsec(q1, q2, *traj.stop) > 0
    if np.any(before | after):
        i = int(np.flatnonzero(before | after)[0])
        raise ValueError(f"{traj.source}: epoch {epoch_text(q1[i], q2[i])} {traj.time_system} is outside the span "
                         f"{epoch_text(*traj.start)} .. {epoch_text(*traj.stop)} {traj.time_system} of the file")


def _serving(traj: OemTrajectory, q1, q2) -> np.ndarray:
    """Index of the segment that gives the state at each epoch (-1: none): the last whose usable span holds it."""
    out = np.full(np.shape(q1), -1, dtype=np.int64)
    for k, s in enumerate(traj.segments):
        out[(_dsec(q1, q2, *s.start) >= 0) & (_dsec(q1, q2, *s.stop) <= 0)] = k
    return out


def _chain(traj: OemTrajectory) -> np.ndarray:
    """Rows of the records of the segments that give the states at their epochs, in time order (for a
    segment shorter than a window): each record whose epoch its own segment serves, and the records
    before (after) the span of the first (last) segment."""
    spans = traj.segments
    owner = np.concatenate([np.full(s.rows[1] - s.rows[0], k) for k, s in enumerate(spans)])
    serve = _serving(traj, traj.jd1, traj.jd2)
    keep = (serve == owner) | ((serve < 0) & (_dsec(traj.jd1, traj.jd2, *traj.start) < 0) & (owner == 0)) | (
        (serve < 0) & (_dsec(traj.jd1, traj.jd2, *traj.stop) > 0) & (owner == len(spans) - 1))
    rows = np.flatnonzero(keep)
    return rows[np.argsort(_dsec(traj.jd1[rows], traj.jd2[rows], traj.jd1[0], traj.jd2[0]), kind="stable")]


def _segment_states(traj: OemTrajectory, k: int, q1, q2, m: str, n: int, *, exact_window=True):
    """States of segment k at epochs q (M,) with windows of n of its records (fewer records: from the chain
    of segments if ``exact_window``, else a window of all its records, a lower degree)."""
    a, b = traj.segments[k].rows
    rows = np.arange(a, b)
    if b - a < n:
        if exact_window:
            rows = _chain(traj)
            if rows.size < n:
                raise ValueError(f"{traj.source}: {m} of degree {2 * n - 1 if m == 'HERMITE' else n - 1} needs "
                                 f"{n} records, the file's segments give {rows.size}")
        else:
            n = b - a
    return _interpolate(traj.jd1[rows], traj.jd2[rows], traj.r[rows], traj.v[rows], q1, q2, m, n)


def states_at(traj: OemTrajectory, jd1, jd2=0.0, *, method: str | None = None,
              degree: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Interpolated position [m] and velocity [m/s] at the epochs jd1 + jd2
    [d] (in ``traj.time_system``; arrays, broadcast to shape S) -> r, v of
    shape S + (3,), in the file's frame and centre.

    Method and degree: the file's INTERPOLATION / INTERPOLATION_DEGREE (of
    the segment that gives the epoch) unless given; windows and segments: see
    the module docstring.  A file of several segments must be continuous
    (:func:`require_continuous`).  Epochs outside the usable span
    (``traj.start`` .. ``traj.stop``, ends included): one-line ValueError
    naming the file.
    """
    where = traj.source
    if not traj.segments:
        m, deg, n = _method(where, traj.interpolation, traj.interpolation_degree, method, degree)
        if len(traj) < n:
            raise ValueError(f"{where}: {m} of degree {deg} needs {n} records, the segment has {len(traj)}")
    q1, q2 = np.broadcast_arrays(np.asarray(jd1, dtype=np.float64), np.asarray(jd2, dtype=np.float64))
    shape = q1.shape
    q1, q2 = q1.ravel(), q2.ravel()
    if not (np.all(np.isfinite(q1)) and np.all(np.isfinite(q2))):
        raise ValueError(f"{where}: epoch must be finite")
    _outside(traj, q1, q2)
    if not traj.segments:
        r, v = _interpolate(traj.jd1, traj.jd2, traj.r, traj.v, q1, q2, m, n)
        return r.reshape(shape + (3,)), v.reshape(shape + (3,))
    require_continuous(traj, method=method, degree=degree)
    serving = _serving(traj, q1, q2)
    r = np.empty((q1.size, 3))
    v = np.empty((q1.size, 3))
    for k in np.unique(serving).tolist():
        s = traj.segments[k]
        m, _, n = _method(f"{where} (segment {k + 1})", s.interpolation, s.interpolation_degree, method, degree)
        sel = serving == k
        r[sel], v[sel] = _segment_states(traj, k, q1[sel], q2[sel], m, n)
    return r.reshape(shape + (3,)), v.reshape(shape + (3,))


# ------------------------------------------------------------------ continuity of segments

_CONTINUOUS: weakref.WeakSet = weakref.WeakSet()  # trajectories checked with the files' own interpolation


def _leave_one_out(traj: OemTrajectory, k: int, p: tuple, m: str, n: int) -> tuple[float, float]:
    """Largest miss [m, m/s] of the n interior records of segment k nearest the epoch p, each
    interpolated from the segment's other records (0, 0 when the segment has too few)."""
    a, b = traj.segments[k].rows
    if b - a - 1 < n or b - a < 3:
        return 0.0, 0.0
    inner = np.arange(a + 1, b - 1)
    near = inner[np.argsort(np.abs(_dsec(traj.jd1[inner], traj.jd2[inner], *p)), kind="stable")[:n]]
    er = ev = 0.0
    for i in near.tolist():
        rows = np.r_[a:i, i + 1:b]
        ri, vi = _interpolate(traj.jd1[rows], traj.jd2[rows], traj.r[rows], traj.v[rows], traj.jd1[i:i + 1],
                              traj.jd2[i:i + 1], m, n)
        er = max(er, float(np.linalg.norm(ri[0] - traj.r[i])))
        ev = max(ev, float(np.linalg.norm(vi[0] - traj.v[i])))
    return er, ev


def _takeovers(traj: OemTrajectory):
    """(j, k, epoch, epoch text) for every epoch where segment k takes over from segment j = k - 1: the
    start of k's usable span, where j's stops (:func:`tqdyn.readers.oem.read_oem`)."""
    spans = traj.segments
    for k in range(1, len(spans)):
        yield k - 1, k, spans[k].start, spans[k].start_text


def require_continuous(traj: OemTrajectory, *, method: str | None = None, degree: int | None = None) -> OemTrajectory:
    """``traj`` if its segments are one continuous trajectory (always for a
    single segment), else a one-line ValueError naming the file, the two
    segments' spans as the file writes them, the epoch, the differences and
    the tolerance.  At every epoch where a segment takes over from the
    previous one both are interpolated (``method``, ``degree``: as
    :func:`states_at`) and must agree within sqrt(3)/2 (u_j + u_k) + e in
    position [m] and in velocity [m/s] (u: one unit of each segment's last
    printed digit; e: the interpolation error there, leave one out; see the
    module docstring for the derivation and ESA's numbers)."""
    if not traj.segments or (method is None and degree is None and traj in _CONTINUOUS):
        return traj
    spans = traj.segments
    for j, k, p, text in _takeovers(traj):
        q1, q2 = np.array([p[0]]), np.array([p[1]])
        states, misses = [], []
        for s in (j, k):
            m, _, n = _method(f"{traj.source} (segment {s + 1})", spans[s].interpolation,
                              spans[s].interpolation_degree, method, degree)
            states.append(_segment_states(traj, s, q1, q2, m, n, exact_window=False))
            misses.append(_leave_one_out(traj, s, p, m, n))
        dr = float(np.linalg.norm(states[0][0] - states[1][0]))
        dv = float(np.linalg.norm(states[0][1] - states[1][1]))
        tol_r = math.sqrt(3) / 2 * (spans[j].r_unit + spans[k].r_unit) + max(e[0] for e in misses)
        tol_v = math.sqrt(3) / 2 * (spans[j].v_unit + spans[k].v_unit) + max(e[1] for e in misses)
        if not (dr <= tol_r and dv <= tol_v):
            bad = [(f"positions by {dr:.4g} m", f"{tol_r:.4g} m")] if not dr <= tol_r else []
            bad += [(f"velocities by {dv:.4g} m/s", f"{tol_v:.4g} m/s")] if not dv <= tol_v else []
            raise ValueError(f"{traj.source}: segments {j + 1} and {k + 1} differ where they meet ({text}): "
                             f"{', '.join(b[0] for b in bad)}; allowed: <= {', '.join(b[1] for b in bad)}")
    if method is None and degree is None:
        _CONTINUOUS.add(traj)
    return traj


# ------------------------------------------------------------------ conversions

@functools.lru_cache(maxsize=1)
def frame_bias_matrix() -> np.ndarray:
    """The IAU 2006 frame-bias matrix B (ICRS -> mean equator and equinox of
    J2000, "EME2000"): r_EME2000 = B r_ICRS, r_ICRS = B^T r_EME2000.
    ``erfa.bp06(2451545, 0)[0]`` (the bias does not depend on the date)."""
    rb = np.array(erfa.bp06(2451545.0, 0.0)[0], dtype=np.float64)
    rb.setflags(write=False)
    return rb


def _to_icrf_axes(traj: OemTrajectory, name: str, frame_bias: bool = True) -> OemTrajectory:
    if traj.ref_frame == "EME2000" and frame_bias:
        bt = frame_bias_matrix().T
        return traj.replace(r=traj.r @ bt.T, v=traj.v @ bt.T, a=None if traj.a is None else traj.a @ bt.T,
                            ref_frame=name)
    return traj.replace(ref_frame=name)


def _tdb_pair(jd) -> tuple[float, float]:
    (j1,), (j2,) = tcb_to_tdb([jd[0]], [jd[1]])
    return float(j1), float(j2)


def to_heliocentric(traj: OemTrajectory, *, tcb_scaled_coordinates: bool = False,
                    eme2000_frame_bias: bool = True) -> OemTrajectory:
    """``traj`` in tqdyn's heliocentric system: CENTER_NAME SUN, ICRF axes, TDB.

    REF_FRAME EME2000 is rotated by the frame bias (ICRF kept) -- unless
    ``eme2000_frame_bias`` is False: then EME2000 is taken as a label of
    ICRF axes (ESA's CReMA 2.0 LISA files, whose "EME2000" states fit
    ICRF-axes dynamics: tests/test_esa_lisa.py, docs/lisa-orbits.md); TIME_SYSTEM
    TCB tags become TDB (:func:`tqdyn.astro.timescales.tcb_to_tdb`; TDB kept;
    the segments' spans too).  With
    ``tcb_scaled_coordinates`` the file's coordinates are taken as
    TCB-compatible and scaled to TDB-compatible ones: r (1 - L_B), a / (1 - L_B)
    (v unchanged); ESA's TCB LISA files are not scaled (their states equal
    those of the TDB files), hence the default False.  A file of several
    segments must be continuous (:func:`require_continuous`).  Raises
    ValueError (naming the file) for another centre, GCRF or TT.
    """
    require_center(traj, "SUN")
    if traj.ref_frame not in ("EME2000", "ICRF"):
        raise ValueError(f"{traj.source}: REF_FRAME = {traj.ref_frame!r} is not heliocentric "
                         "(allowed here: EME2000, ICRF)")
    if traj.time_system not in ("TDB", "TCB"):
        raise ValueError(f"{traj.source}: TIME_SYSTEM = {traj.time_system!r} for a heliocentric trajectory "
                         "(allowed here: TDB, TCB)")
    require_continuous(traj)
    out = _to_icrf_axes(traj, "ICRF", eme2000_frame_bias)
    if traj.time_system == "TCB":
        j1, j2 = tcb_to_tdb(traj.jd1, traj.jd2)
        (s1,), (s2,) = tcb_to_tdb([traj.start[0]], [traj.start[1]])
        (e1,), (e2,) = tcb_to_tdb([traj.stop[0]], [traj.stop[1]])
        spans = tuple(dataclasses.replace(s, start=_tdb_pair(s.start), stop=_tdb_pair(s.stop))
                      for s in traj.segments)
        out = out.replace(jd1=j1, jd2=j2, start=(float(s1), float(s2)), stop=(float(e1), float(e2)),
                          time_system="TDB", segments=spans)
        if tcb_scaled_coordinates:
            out = out.replace(r=out.r * (1.0 - L_B), a=None if out.a is None else out.a / (1.0 - L_B))
    return out


def to_geocentric(traj: OemTrajectory) -> OemTrajectory:
    """``traj`` in tqdyn's geocentric system: CENTER_NAME EARTH, GCRF (ICRF
    axes; EME2000 rotated by the frame bias), TT.  A file of several segments
    must be continuous (:func:`require_continuous`).  Raises ValueError
    (naming the file) for another centre, ICRF or a time system other than TT."""
    require_center(traj, "EARTH")
    if traj.ref_frame not in ("EME2000", "GCRF"):
        raise ValueError(f"{traj.source}: REF_FRAME = {traj.ref_frame!r} is not geocentric "
                         "(allowed here: EME2000, GCRF)")
    if traj.time_system != "TT":
        raise ValueError(f"{traj.source}: TIME_SYSTEM = {traj.time_system!r} for a geocentric trajectory "
                         "(allowed here: TT)")
    require_continuous(traj)
    return _to_icrf_axes(traj, "GCRF")
