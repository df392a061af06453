"""The result of the light-time solver: :class:`LightTravelTimes` (physics, no I/O).

Produced by :func:`tqdyn.lightpath.light_time.light_travel_times` (which
documents the equations); re-exported by :mod:`tqdyn.lightpath` and
:mod:`tqdyn.lightpath.light_time`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..astro.constants import C_LIGHT
from ..astro.timescales import TCB_PER_TDB
from ..numerics.dd import np_two_prod, np_two_sum

__all__ = ["LightTravelTimes", "TCB_PER_TDB"]


def _dd_scale(x, k):
    """dd (hi, lo) times the dd constant k = (k_hi, k_lo), elementwise (float64 x: lo = 0)."""
    hi, lo = (x if isinstance(x, tuple) else (np.asarray(x, np.float64), np.zeros(np.shape(x))))
    p, e = np_two_prod(hi, k[0])
    return np_two_sum(p, e + (hi * k[1] + lo * k[0]))


@dataclass(frozen=True)
class LightTravelTimes:
    """Light travel times of the six links on a trajectory's time grid.

    Link axis: LISA order 12, 23, 31, 13, 32, 21 (``Link.index``; link ab is
    received on satellite a, emitted by satellite b).  Times are seconds of
    :attr:`time_scale` since the epoch (TT for geocentric runs, TDB for
    heliocentric ones); dd quantities are ``(hi, lo)`` tuples of float64
    arrays.  Rows whose emission time precedes the first grid time are NaN.

    Vectors [m, m/s], by :attr:`frame`:

    * ``"GCRS"`` (geocentric): geocentric GCRS positions and velocities, the
      receiver's exactly the grid values;
    * ``"BCRS"`` (heliocentric): the light-time equation holds in the
      barycentric (BCRS) coordinates, in which the Sun moves (~10 m/s).  Row
      n's vectors are BCRS vectors relative to the Sun's position at the
      reception time t_n (a constant translation of the barycentric
      coordinates for that row): the receiver's position is the grid value
      (Sun-centred at t_n), the emitter's is x_e(t_n - tau) - (S(t_n) -
      S(t_n - tau)) with S the Sun's barycentric position (its Sun-centred
      position minus the Sun's motion during tau, ~80 m), and both
      velocities are barycentric (Sun-centred + the Sun's velocity at the
      instant).  So ``r_receive - r_emit``, :attr:`unit_vectors` and
      :attr:`tau_rate` are the BCRS quantities; the Sun's barycentric
      velocity and acceleration at the grid times are :attr:`origin_velocity`
      and :attr:`origin_acceleration`.

    Attributes
    ----------
    t : (hi, lo) of (N,)
        Reception times (the grid) [s of :attr:`time_scale`].
    tau : (hi, lo) of (N, 6)
        Light travel time [s] (coordinate time of :attr:`frame`), dd.
    range : (hi, lo) of (N, 6)
        Light-path range c * tau [m], dd (c = 299792458 m/s exactly).
    r_receive : (hi, lo) of (N, 6, 3)
        Receiving body at t [m], dd (the grid values).
    v_receive : (N, 6, 3)
        Receiving body's velocity at t [m/s], float64 (GCRS: grid values;
        BCRS: barycentric).
    r_emit : (hi, lo) of (N, 6, 3)
        Emitting body at t - tau [m], dd (Hermite dense output; BCRS: see above).
    v_emit : (N, 6, 3)
        Emitting body's velocity at t - tau [m/s], float64 (BCRS: barycentric).
    residual : (N, 6)
        tau - |r_emit - r_receive| / c - shapiro at the returned tau [s].
    shapiro : (N, 6)
        Total Shapiro delay included in tau [s] (zeros if none).
    iterations : (N, 6) int
        Newton iterations used.
    source : str
        ``"tm"`` (test mass to test mass) or ``"sat"`` (satellite centres).
    note : str
        What the bodies are (and why, for a fallback).
    shapiro_k : float
        (1 + gamma) GM / c^3 [s] of the central body's Shapiro term (the
        Earth for GCRS, the Sun for BCRS), 0.0 when it is off.
    frame : str
        ``"GCRS"`` or ``"BCRS"`` (see above).
    time_scale : str
        Time scale of t and tau: ``"TT"`` (geocentric), ``"TDB"``
        (heliocentric; ``"TCB"`` after :meth:`to_tcb`).
    origin_velocity, origin_acceleration : (N, 3) or None
        BCRS: the Sun's barycentric velocity [m/s] and acceleration [m/s^2]
        at the grid times; None for GCRS.
    shapiro_parts : dict
        Body name -> (N, 6) Shapiro delay of that body [s] (the central
        body's under its name, ``"earth"`` or ``"sun"``, when on; the
        deflectors'); their sum is :attr:`shapiro`.
    gamma : float
        PPN parameter gamma of the Shapiro terms.
    """

    t: tuple[np.ndarray, np.ndarray]
    tau: tuple[np.ndarray, np.ndarray]
    range: tuple[np.ndarray, np.ndarray]
    r_receive: tuple[np.ndarray, np.ndarray]
    v_receive: np.ndarray
    r_emit: tuple[np.ndarray, np.ndarray]
    v_emit: np.ndarray
    residual: np.ndarray
    shapiro: np.ndarray
    iterations: np.ndarray
    source: str
    note: str
    shapiro_k: float = 0.0
    frame: str = "GCRS"
    time_scale: str = "TT"
    origin_velocity: np.ndarray | None = None
    origin_acceleration: np.ndarray | None = None
    shapiro_parts: dict = field(default_factory=dict)
    gamma: float = 1.0

    def select(self, rows) -> "LightTravelTimes":
        """The same light travel times at the rows ``rows`` only (a slice,
        an index array or a boolean mask along the time axis)."""
        pick = lambda x: (x[0][rows], x[1][rows]) if isinstance(x, tuple) else x[rows]  # noqa: E731
        opt = lambda x: None if x is None else x[rows]  # noqa: E731
        return replace(self, t=pick(self.t), tau=pick(self.tau), range=pick(self.range),
                       r_receive=pick(self.r_receive), v_receive=pick(self.v_receive), r_emit=pick(self.r_emit),
                       v_emit=pick(self.v_emit), residual=pick(self.residual), shapiro=pick(self.shapiro),
                       iterations=pick(self.iterations), origin_velocity=opt(self.origin_velocity),
                       origin_acceleration=opt(self.origin_acceleration),
                       shapiro_parts={k: v[rows] for k, v in self.shapiro_parts.items()})

    @property
    def tau_f64(self) -> np.ndarray:
        """tau as float64 (N, 6) [s] (hi + lo; ~1e-16 relative)."""
        return self.tau[0] + self.tau[1]

    @property
    def unit_vectors(self) -> np.ndarray:
        """(N, 6, 3) unit vectors from the emitter at t - tau to the receiver at t
        (the photon's direction of propagation, as in LISA orbit files), axes
        of :attr:`frame` (BCRS: the barycentric direction); the difference is
        formed from the dd positions."""
        d = (self.r_receive[0] - self.r_emit[0]) + (self.r_receive[1] - self.r_emit[1])
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    @property
    def tau_rate(self) -> np.ndarray:
        """d tau / dt (N, 6) [s/s]: differentiating c tau = |D| + c s (D = r_r(t) -
        r_e(t - tau), n = D / |D| = :attr:`unit_vectors`, s the Shapiro delay)
        gives (n . (v_r - v_e) + c ds/dt) / (c - n . v_e) (BCRS: barycentric
        D and velocities); ds/dt of the central body (< 1e-17 s/s for
        TianQin, ~3e-14 s/s for the Sun on LISA's arms) is included when its
        Shapiro delay is, with the geometric rate inserted into it; the
        deflectors' ds/dt (< 1e-18 s/s, tests/test_lightpath_heliocentric.py)
        is not."""
        n = self.unit_vectors
        nve = np.einsum("...k,...k->...", n, self.v_emit)
        nvr = np.einsum("...k,...k->...", n, self.v_receive)
        rate = (nvr - nve) / (C_LIGHT - nve)
        if self.shapiro_k == 0.0:
            return rate
        re = self.r_emit[0] + self.r_emit[1]
        rr = self.r_receive[0] + self.r_receive[1]
        ve, vr = self.v_emit, self.v_receive
        if self.origin_velocity is not None:  # back to the Sun-centred states at t - tau and t
            tau = self.tau_f64[..., None]
            vo, ao = self.origin_velocity[:, None, :], self.origin_acceleration[:, None, :]
            re = re + (vo * tau - 0.5 * ao * tau * tau)
            ve = ve - (vo - ao * tau)
            vr = vr - vo
        a_e, a_r = np.linalg.norm(re, axis=-1), np.linalg.norm(rr, axis=-1)
        A = a_e + a_r
        L = C_LIGHT * (self.tau_f64 - self.shapiro)
        A_dot = (np.einsum("...k,...k->...", re, ve) / a_e * (1.0 - rate)
                 + np.einsum("...k,...k->...", rr, vr) / a_r)
        L_dot = C_LIGHT * rate
        s_dot = self.shapiro_k * ((A_dot + L_dot) / (A + L) - (A_dot - L_dot) / (A - L))
        return (nvr - nve + C_LIGHT * s_dot) / (C_LIGHT - nve)

    def to_tcb(self) -> "LightTravelTimes":
        """The same light paths in TCB-compatible BCRS coordinates (heliocentric results only).

        TDB = (1 - L_B) TCB + const (IAU 2006 B3) and the TDB-compatible
        coordinates are x_TDB = (1 - L_B) x_TCB, so with k = dTCB/dTDB =
        1 / (1 - L_B) (:data:`TCB_PER_TDB`, dd): t -> k t (TCB seconds since
        the epoch's TCB), tau, range, positions, residual and Shapiro
        delays -> k x (tau: +1.3e-7 s on LISA's 8.3 s), velocities and
        :attr:`tau_rate` unchanged, accelerations -> a / k.  ValueError for
        a result whose :attr:`time_scale` is not TDB."""
        if self.time_scale != "TDB" or self.frame != "BCRS":
            raise ValueError(f"to_tcb: the light travel times are {self.frame} / {self.time_scale}; only "
                             "heliocentric BCRS / TDB results have TCB-compatible counterparts")
        k = TCB_PER_TDB
        s = k[0] + k[1]
        return replace(
            self, t=_dd_scale(self.t, k), tau=_dd_scale(self.tau, k), range=_dd_scale(self.range, k),
            r_receive=_dd_scale(self.r_receive, k), r_emit=_dd_scale(self.r_emit, k), residual=self.residual * s,
            shapiro=self.shapiro * s, shapiro_k=self.shapiro_k * s, time_scale="TCB",
            origin_acceleration=None if self.origin_acceleration is None else self.origin_acceleration / s,
            shapiro_parts={b: v * s for b, v in self.shapiro_parts.items()})
