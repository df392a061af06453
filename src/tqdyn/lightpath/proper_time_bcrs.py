"""Proper times of clocks on heliocentric orbits, against TCB or TDB, and of geocentric ones against TCB (physics).

Heliocentric trajectories (:data:`tqdyn.astro.reference.HELIOCENTRIC`) give
Sun-centred positions r, velocities v and accelerations a in the
TDB-compatible BCRS, t in TDB seconds since the epoch.  A clock's proper
time tau obeys the BCRS metric of IAU 2000 Resolution B1.3 (g_00 = -1 +
2w/c^2 - 2w^2/c^4, g_0i = -4 w^i/c^3, g_ij = delta_ij (1 + 2w/c^2)):

    d tau / dTCB = 1 - F,
    F = (w + v^2/2) / c^2 - (-v^4/8 - 3/2 v^2 w + 4 v.w_vec + w^2/2) / c^4,

* w = GM_S / |r| + sum_k GM_k / |r - x_k|: the Newtonian potential of the
  Sun and of the bodies k (default all of the ephemeris: the Earth, the
  Moon and the planets' systems; the potential is the solar system's, not
  a choice of the run's force model, so the run's third-body list does not
  restrict it unless ``bodies="third_bodies"``).  Sizes at LISA (1 au, 20
  deg behind the Earth): Sun 9.9e-9; Jupiter ~1.8e-12, Saturn ~3e-13, the
  Earth ~9e-14 at 5e10 m, Venus ~1e-13, Uranus, Neptune ~2e-14, Mars,
  Mercury, the Moon ~1e-15 (relative rates; tests/test_lightpath_heliocentric.py).
  Not modelled: the Sun's J2 (~5e-20) and the asteroids (~1e-15).
* v: the clock's *barycentric* velocity, v_sun-centred + V_S with V_S the
  Sun's barycentric velocity (~13 m/s): the metric's coordinates are the
  barycentric ones, and TCB/TDB are their coordinate times, so the
  dilation is that of the barycentric velocity.  The cross term v.V_S/c^2
  is up to ~4e-12 (2.9e-12 measured on a LISA-like run in 2035), turning
  with the orbit: an annual oscillation of ~2e-5 s amplitude in tau.
* the 1/c^4 terms (w_vec = sum_A GM_A v_A / r_A, v_A barycentric): about
  -1.1e-16 at 1 au (-9/8 (GM_S/(a c^2))^2 on a circular orbit), 3.5 ns
  per year in tau (3.46e-9 s measured over a year, e = 0.0048), with an
  annual modulation of ~1e-11 s, so they are kept (``c4=True``); the terms
  Delta of IERS 2010 eq. 10.7 (~1e-20) and the 1/c^2 corrections to the
  potentials are below 1e-19 and are not.

The TDB-compatible numbers of w and v equal the TCB-compatible ones (x, t
and GM all scale by 1 - L_B), and TDB = (1 - L_B) TCB + const, so against
tqdyn's t:

* ``against="TCB"`` (the LISA orbit files' coordinate time):
  delta_tau = tau - TCB, d delta_tau / dTDB = -F / (1 - L_B); returned
  with its rate per TCB second, d delta_tau / dTCB = -F (~ -1.48e-8), and
  that rate's derivative per TCB second, -(dF/dTDB) (1 - L_B);
* ``against="TDB"``: delta_tau = tau - TDB, d delta_tau / dTDB =
  (L_B - F) / (1 - L_B) (~ +7e-10: L_B is the rate of the Earth's clocks);
  rate and its derivative per TDB second.

Both are sampled at the grid's events (TDB t_k; the TCB of event k is
TCB(epoch) + t_k / (1 - L_B)) and are zero at the first sample, integrated
as :func:`tqdyn.lightpath.proper_time.proper_time_deviation` integrates the
geocentric ones (end-corrected trapezoid; error ~2e-20 s per hour step at 1
au, the derivative dF/dt from r, v, a and the bodies' states, its 1/c^4
part (~2e-25 /s) omitted).

Geocentric runs (GCRS, TT) in the BCRS / TCB file of the LISA export:
:func:`proper_time_deviation_geocentric_tcb` reads the clocks against TT of
:mod:`tqdyn.lightpath.proper_time` at each satellite's BCRS event and
re-expresses them against TCB.
"""

from __future__ import annotations

import numpy as np

from .._choices import unknown
from ..astro.constants import C_LIGHT, L_B
from ..astro.reference import GEOCENTRIC
from ..astro.timescales import TCB_SCALE, TCB_SCALE_MINUS_1
from ..numerics.dd import np_two_sum
from . import heliocentric as _helio
from .light_time import satellite_states
from .proper_time import _dd_cumsum, proper_time_deviation, scenario_gm_earth

__all__ = ["PROPER_TIME_SCALES", "proper_time_deviation_bcrs", "proper_time_deviation_geocentric_tcb",
           "proper_time_deviation_of"]

#: Time scales a heliocentric proper-time deviation can be taken against.
PROPER_TIME_SCALES = ("TCB", "TDB")


def _dot(x, y):
    return np.einsum("...k,...k->...", x, y)


def _steps(t) -> np.ndarray:
    if isinstance(t, tuple):
        th, tl = (np.asarray(p, np.float64) for p in t)
        return (th[1:] - th[:-1]) + (tl[1:] - tl[:-1])
    return np.diff(np.asarray(t, np.float64))


def proper_time_deviation_bcrs(t, r, v, a, *, origin_velocity, origin_acceleration=None, bodies_r=None,
                               bodies_v=None, bodies_gm=None, gm_sun: float | None = None, against: str = "TCB",
                               c4: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Proper-time deviation delta_tau of B clocks on heliocentric orbits (module docstring).

    t: (N,) grid times [s TDB since the epoch] (float64 or dd (hi, lo));
    r, v, a: (N, B, 3) Sun-centred positions [m], velocities [m/s] and
    accelerations [m/s^2] of the clocks (float64, BCRS TDB-compatible, ICRF
    axes); origin_velocity, origin_acceleration: (N, 3) (or (3,)) the Sun's
    barycentric velocity [m/s] and acceleration [m/s^2] (default 0)
    (:func:`tqdyn.lightpath.heliocentric.sun_barycentric_motion`); bodies_r,
    bodies_v: (N, K, 3) Sun-centred positions [m] and velocities [m/s] of
    the other bodies of the potential, bodies_gm (K,) [m^3/s^2] (default
    none); gm_sun [m^3/s^2] (default the DE430 value); against: "TCB" or
    "TDB"; c4: include the 1/c^4 terms.

    Returns (delta_tau, rate, rate_dot), each (N, B): delta_tau = tau -
    TCB (or - TDB) at the grid events [s], zero at the first sample; rate
    = d delta_tau / d(against) [s/s]; rate_dot = d rate / d(against) [1/s].
    """
    if against not in PROPER_TIME_SCALES:
        raise ValueError(unknown("against", against, PROPER_TIME_SCALES))
    r, v, a = (np.asarray(x, np.float64) for x in (r, v, a))
    if r.ndim != 3 or r.shape[-1] != 3 or v.shape != r.shape or a.shape != r.shape:
        raise ValueError(f"r, v, a: shapes {r.shape}, {v.shape}, {a.shape}; allowed: equal, (N, B, 3)")
    N = r.shape[0]
    h = _steps(t)
    if h.shape != (N - 1,) or not np.all(h > 0):
        raise ValueError(f"t: {h.size + 1} strictly increasing times expected for {N} rows")
    vo = np.broadcast_to(np.asarray(origin_velocity, np.float64), (N, 3))[:, None, :]
    ao = np.broadcast_to(np.asarray(0.0 if origin_acceleration is None else origin_acceleration, np.float64),
                         (N, 3))[:, None, :]
    gm_s = float(_helio.gm_of(("sun",))[0]) if gm_sun is None else float(gm_sun)
    if bodies_gm is None or len(bodies_gm) == 0:
        pk = vk = np.zeros((N, 0, 3))
        gk = np.zeros(0)
    else:
        gk = np.asarray(bodies_gm, np.float64)
        pk, vk = np.asarray(bodies_r, np.float64), np.asarray(bodies_v, np.float64)
        if pk.shape != (N, gk.size, 3) or vk.shape != pk.shape:
            raise ValueError(f"bodies_r, bodies_v: shapes {pk.shape}, {vk.shape}; allowed: ({N}, {gk.size}, 3)")
    c2 = C_LIGHT ** 2
    rn = np.linalg.norm(r, axis=-1)  # (N, B)
    d = r[:, :, None, :] - pk[:, None, :, :]  # (N, B, K, 3) clock - body
    dn = np.linalg.norm(d, axis=-1)
    w = gm_s / rn + np.sum(gk / dn, axis=-1)
    vb = v + vo  # barycentric velocity of the clocks
    v2 = _dot(vb, vb)
    F = (w + 0.5 * v2) / c2
    if c4:
        wv = gm_s / rn[..., None] * vo + np.sum((gk / dn)[..., None] * (vk + vo)[:, None, :, :], axis=-2)
        F = F - (-v2 * v2 / 8.0 - 1.5 * v2 * w + 4.0 * _dot(vb, wv) + 0.5 * w * w) / (c2 * c2)
    dv = v[:, :, None, :] - vk[:, None, :, :]
    Fd = (-gm_s * _dot(r, v) / rn ** 3 - np.sum(gk * _dot(d, dv) / dn ** 3, axis=-1) + _dot(vb, a + ao)) / c2
    k = 1.0 - L_B
    if against == "TCB":
        f, fd = F / k, Fd / k
        rate, rate_dot = -F, -Fd * k
    else:
        f, fd = (F - L_B) / k, Fd / k
        rate, rate_dot = -f, -fd
    hh = h[:, None]
    inc = hh * 0.5 * (f[:-1] + f[1:]) + hh * hh / 12.0 * (fd[:-1] - fd[1:])
    out = np.empty_like(f)
    _dd_cumsum(np.ascontiguousarray(-inc), out)
    return out, rate, rate_dot


def proper_time_deviation_geocentric_tcb(t, r, v, a, states, gm: float | None = None):
    """Proper-time deviations against TCB of clocks of a geocentric (GCRS, TT) run, at their BCRS samples.

    t: dd (hi, lo) (N,) grid times [s TT since the epoch]; r, v, a: (N, B,
    3) float64 GCRS positions [m], velocities [m/s], accelerations [m/s^2]
    of B clocks on that grid; states: the
    :func:`tqdyn.astro.geocentric.gcrs_to_bcrs_states` of the same clocks
    under the name ``"sat"`` (its uniform TDB grid t_k, the geocentre's TT
    T_k, v_E, a_E, dT/dt and the clocks' geocentric y, w at T_k); gm: the
    Earth's TT-compatible GM [m^3/s^2] (default GM_EARTH_EGM2008).

    The clocks against TT, tau(T) = T + delta_tau_TT(T)
    (:func:`tqdyn.lightpath.proper_time.proper_time_deviation`, the
    Earth's monopole: d tau/dTT = (1 - (GM_E/r + v^2/2)/c^2)/(1 - L_G)),
    are read at each clock's BCRS event: sample k of clock i is its event at
    TCB t_c,k = S t_k (S = :data:`tqdyn.astro.timescales.TCB_SCALE`), whose
    TT is T_ik = T_k - (v_E . y_i)/c^2 (the 1PN simultaneity: TCB - TCG =
    c^-2 [int (v_E^2/2 + U_ext) dt + v_E . r]); its proper time is T_ik +
    delta_tau_TT(T_ik) (Taylor series from grid row k: |T_ik - T_row| < 1
    ms), and delta_tau_c = tau - t_c, synchronised to 0 at the first
    sample.  Rate: d tau/dt_c = (1 + rate_TT) dT_i/dt_c with dT_i/dt_c =
    (dT/dt - (a_E . y + v_E . w)/c^2) / S; its derivative by second-order
    finite differences along the grid.

    Returns (delta_tau, rate, rate_dot), each (N, B): [s], [s/s] and [1/s]
    per TCB second, at the TCB instants S t_k.
    """
    dtau, rate, rate_dot = proper_time_deviation(t, r, v, a, gm)
    th, tl = (np.asarray(p, np.float64) for p in t)
    Th, Tl = states["T"]
    bh, bl = states["t"]
    y, w = states["y"]["sat"]
    c2 = C_LIGHT * C_LIGHT
    ve, ae = states["v_e"][:, None, :], states["a_e"][:, None, :]
    shift = -np.einsum("nsk,nsk->ns", ve, y) / c2                   # T_ik - T_k
    eps = ((Th - th) + (Tl - tl))[:, None] + shift                  # T_ik - T_row
    dtau_e = dtau + rate * eps + 0.5 * rate_dot * eps ** 2
    # tau - t_c = (T_ik - T_0) + delta_tau(T_ik) - S (t_k - t_0) - const; elapsed parts in dd
    dTb_h, dTb_l = np_two_sum(Th - bh, Tl - bl)                     # T_k - t_k: -(TDB - TT) drift, ms
    dtk = (bh - bh[0]) + (bl - bl[0])
    lin = (dTb_h + dTb_l)[:, None] - (dTb_h[0] + dTb_l[0]) - (TCB_SCALE_MINUS_1 * dtk)[:, None]
    raw = lin + shift + dtau_e
    dtau_c = raw - raw[0]
    q = (np.einsum("nsk,nsk->ns", ae, y) + np.einsum("nsk,nsk->ns", ve, w)) / c2
    ddt = states["dT_dt_m1"][:, None]                               # dT/dt - 1 (|.| < 4e-10)
    rate_e = rate + eps * rate_dot
    # (1 + rate)(1 + ddt - q)(1 - L_B) - 1, small terms kept small
    g = ddt - q
    rate_c = -L_B + (1.0 - L_B) * (rate_e + g + rate_e * g)
    dt_c = TCB_SCALE * (dtk[1] - dtk[0]) if dtk.size > 1 else 1.0
    rate_dot_c = np.gradient(rate_c, dt_c, axis=0, edge_order=2)
    return dtau_c, rate_c, rate_dot_c


def proper_time_deviation_of(trajectory, *, against: str | None = None, bodies="all", ephemeris=None,
                             c4: bool = True, gm: float | None = None):
    """Proper-time deviations of a trajectory's three satellite clocks (centres of mass).

    ``trajectory`` duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`
    (``sat/r``, ``sat/v``, ``sat/a_gravity`` (+ ``sat/a_dragfree``), ``t``;
    ``reference``, ``epoch``, ``scenario_toml``).

    * Geocentric (``reference.central_body == "earth"``, or no
      ``reference``): :func:`tqdyn.lightpath.proper_time.proper_time_deviation`
      (against TT, the Earth's monopole with ``gm``, default the scenario's
      ``forces.gm_earth``), exactly what the LISA export uses; ``against``
      must be None or "TT".
    * Heliocentric: :func:`proper_time_deviation_bcrs` against ``against``
      (default "TCB", what a LISA orbit file holds; or "TDB") with the
      Sun's barycentric motion and the potential of ``bodies`` ("all"
      (default), "third_bodies" = the run's, None = the Sun alone, or a
      list of names) from ``ephemeris`` (default the run's); ``gm`` is the
      Sun's; the GMs default to the run's (its scenario's ``forces.gm_*``).

    Returns (delta_tau, rate, rate_dot), each (N, 3) float64: [s], [s/s],
    [1/s] per second of the time scale against which delta_tau is taken.
    """
    t = trajectory.dd("t")
    x, vel, acc = satellite_states(trajectory)
    x, vel = x[0] + x[1], vel[0] + vel[1]
    ref = getattr(trajectory, "reference", None) or GEOCENTRIC
    if ref.central_body != "sun":
        if against not in (None, "TT"):
            raise ValueError(f"against = {against!r}: a geocentric trajectory's proper times are against TT")
        return proper_time_deviation(t, x, vel, acc, scenario_gm_earth(trajectory) if gm is None else gm)
    eph = _helio.ephemeris_of(trajectory) if ephemeris is None else ephemeris
    epoch = trajectory.epoch
    _, vo, ao = _helio.sun_barycentric_motion(eph, epoch, t, ref)
    names = _helio.resolve_bodies(bodies, trajectory)
    pk, vk = _helio.body_states(eph, epoch, t, names, ref)
    return proper_time_deviation_bcrs(t, x, vel, acc, origin_velocity=vo, origin_acceleration=ao, bodies_r=pk,
                                      bodies_v=vk, bodies_gm=_helio.gm_of(names, trajectory),
                                      gm_sun=float(_helio.gm_of(("sun",), trajectory)[0]) if gm is None else gm,
                                      against="TCB" if against is None else against, c4=c4)
