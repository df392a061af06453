"""Proper times of the satellites' clocks and the quantities of a LISA orbit file (physics).

:func:`proper_time_deviation` integrates each clock's proper time along its
orbit; :func:`lisa_orbit_quantities` combines it with the light travel times
of :mod:`tqdyn.lightpath.light_time` into every dataset of a LISA orbit file
(layout and writer: :mod:`tqdyn.formats.lisa`).  Definitions (geocentric,
GCRS, t = tqdyn's TT seconds since the epoch; the clocks' proper times
against TT):

* Proper time: each satellite's clock (centre of mass).  In the GCRS,
  d tau / dTCG = 1 - (U + v^2/2) / c^2 with U = GM_E / r (the Earth's
  monopole; GM_E the trajectory's TT-compatible value, for which U and v
  have the same numbers in TCG and TT-compatible units), and TT = (1 - L_G)
  TCG + const, so against tqdyn's coordinate time TT

      d tau / dTT = (1 - (U + v^2/2) / c^2) / (1 - L_G),

  L_G = 6.969290134e-10 (a clock on the geoid, where U + v^2/2 = L_G c^2,
  keeps TT).  Integrated along the orbit with the end-corrected trapezoidal
  rule (derivative of the integrand from r, v, a; error ~1e-24 s per step)
  from delta_tau = 0 at the trajectory's first sample (``t_init``).  Not
  applied: the tidal potentials of the Moon and the Sun at the satellites
  (~1e-17 relative, nearly common to the three clocks) and the Earth's
  non-spherical field (J2: ~1e-3 of U, 7e-14 relative).
* ppr = ltt + delta_tau_recv(t) - delta_tau_emit(t - ltt) (delta_tau_emit
  at the emission time from its Taylor series, error < 1e-21 s);
  d_ppr = (dtau_r - dtau_e + d_ltt (1 + dtau_e)) / (1 + dtau_r) with
  dtau = d(delta_tau)/dt, exactly as lisaorbits defines it.
* tps/*: the coordinate time of proper time tau = t_k is t_k + delta_t with
  delta_t = -delta_tau(t_k + delta_t) (two iterations); tps/ppr and
  tps/d_ppr are the TCB-sampled values moved by delta_t with their first
  derivatives (|delta_t| ~ 5e-4 s after 90 days; the neglected second-order
  terms are < 1e-19 s).

Heliocentric runs: the clocks' proper times against TCB or TDB are
:mod:`tqdyn.lightpath.proper_time_bcrs`; pass them to
:func:`lisa_orbit_quantities` as ``proper_time`` (same coordinate time as t
and the light travel times).

Link order: 12, 23, 31, 13, 32, 21 (:class:`~tqdyn.constellation.indices.Link`,
"ij" received by spacecraft i, emitted by spacecraft j).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008, L_G
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from .heliocentric import _scenario
from .light_time import LightTravelTimes

__all__ = ["lisa_orbit_quantities", "proper_time_deviation", "pseudorange_quantities", "scenario_gm_earth"]

_RECV, _EMIT = LINK_RECEIVER, LINK_EMITTER


# ------------------------------------------------------------------ proper time

@njit(cache=True)
def _dd_cumsum(x, out):
    """out[0] = 0, out[k] = sum of x[:k] (compensated, per column); x (N-1, M), out (N, M)."""
    M = x.shape[1]
    for m in range(M):
        s = 0.0
        e = 0.0
        out[0, m] = 0.0
        for k in range(x.shape[0]):
            y = x[k, m]
            t = s + y
            bb = t - s
            err = (s - (t - bb)) + (y - bb)
            s = t
            e += err
            out[k + 1, m] = s + e


def proper_time_deviation(t, r, v, a, gm: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Proper-time deviation delta_tau_i(t) = tau_i(t) - t of clocks on the orbits r_i(t).

    t is the coordinate time TT of the GCRS: d tau/dt = 1 - f with
    f = ((GM/|r| + |v|^2/2) / c^2 - L_G) / (1 - L_G) (the module docstring;
    the Earth's monopole), integrated with the end-corrected trapezoidal rule
    int_k^{k+1} f = h (f_k + f_{k+1}) / 2 + h^2 (f'_k - f'_{k+1}) / 12,
    f' = (-GM r.v/|r|^3 + v.a) / c^2 (error h^5 f''''/720 per step, ~1e-24 s
    at 50 s on TianQin's orbit), summed with compensation; delta_tau = 0 at
    the first sample.

    t: (N,) grid times [s] (float64, or a dd (hi, lo) pair); r, v, a: (N, B,
    3) positions [m], velocities [m/s], accelerations [m/s^2] (float64, GCRS)
    of B clocks; gm [m^3/s^2] (default :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`).
    Returns (delta_tau, rate, rate_dot), each (N, B): delta_tau [s],
    d delta_tau/dt = -f [s/s] and its derivative -f' [1/s].
    """
    gm = float(GM_EARTH_EGM2008) if gm is None else float(gm)
    if isinstance(t, tuple):
        th, tl = (np.asarray(p, np.float64) for p in t)
        h = (th[1:] - th[:-1]) + (tl[1:] - tl[:-1])
    else:
        h = np.diff(np.asarray(t, np.float64))
    r, v, a = (np.asarray(x, np.float64) for x in (r, v, a))
    rn = np.linalg.norm(r, axis=-1)
    f = ((gm / rn + 0.5 * np.einsum("...k,...k->...", v, v)) / C_LIGHT ** 2 - L_G) / (1.0 - L_G)
    fd = (-gm * np.einsum("...k,...k->...", r, v) / rn ** 3 + np.einsum("...k,...k->...", v, a)) / C_LIGHT ** 2 \
        / (1.0 - L_G)
    hh = h[:, None]
    inc = hh * 0.5 * (f[:-1] + f[1:]) + hh * hh / 12.0 * (fd[:-1] - fd[1:])
    out = np.empty_like(f)
    _dd_cumsum(np.ascontiguousarray(-inc), out)
    return out, -f, -fd


def scenario_gm_earth(trajectory) -> float:
    """The Earth's GM [m^3/s^2] of a trajectory's run, for its clocks: the scenario's ``forces.gm_earth``
    (TT-compatible), else :data:`tqdyn.astro.constants.GM_EARTH_EGM2008` (no scenario, or one that does not
    parse)."""
    try:
        gm = _scenario(trajectory).get("forces", {}).get("gm_earth")
        return float(GM_EARTH_EGM2008) if gm is None else float(gm)
    except (TypeError, ValueError, AttributeError):
        return float(GM_EARTH_EGM2008)


# ------------------------------------------------------------------ the quantities

def lisa_orbit_quantities(t, sat_r, sat_v, sat_a, lp: LightTravelTimes, gm: float | None = None, *,
                          proper_time=None) -> dict[str, Any]:
    """All datasets of a LISA orbit file from a tqdyn trajectory's arrays.

    t: dd (hi, lo) grid times (N,) [s, TT]; sat_r, sat_v, sat_a: (N, 3, 3)
    satellite positions [m] (float64 or dd (hi, lo)), velocities [m/s],
    total accelerations [m/s^2], GCRS; lp: the light travel times on the
    same grid (:func:`tqdyn.lightpath.light_travel_times`); gm: Earth GM for
    the proper times [m^3/s^2].  Definitions: see the module docstring.

    proper_time: optional (delta_tau, rate, rate_dot), each (N, 3), used
    instead of the geocentric :func:`proper_time_deviation` (``gm`` is then
    unused).  The formulas are those of the module docstring in whatever
    single coordinate time t, lp and proper_time share: for a heliocentric
    run either all in TDB (lp as solved, proper times of
    :func:`tqdyn.lightpath.proper_time_bcrs.proper_time_deviation_bcrs`
    with ``against="TDB"``) or all in TCB (t, positions, accelerations and
    ``lp.to_tcb()`` converted, proper times ``against="TCB"``).  Mixing
    them is wrong by ltt L_B ~ 1.3e-7 s in ppr.

    Returns a dict with ``t`` (N,) float64 and the arrays of the datasets
    of :mod:`tqdyn.formats.lisa` (keys ``"tcb/x"`` ...) for all N rows (rows
    without a light travel time are NaN), plus ``ltt_lo`` (N, 6) (dd remainder of tcb/ltt) and
    ``t_init`` (float, where delta_tau = 0).
    """
    th, tl = (np.asarray(p, np.float64) for p in t)

    def f64(x):
        return x[0] + x[1] if isinstance(x, tuple) else np.asarray(x, np.float64)

    x, v, a = f64(sat_r), f64(sat_v), np.asarray(sat_a, np.float64)
    if proper_time is None:
        dtau, rate, rate_dot = proper_time_deviation((th, tl), x, v, a, gm)
    else:
        dtau, rate, rate_dot = (np.asarray(p, np.float64) for p in proper_time)
        if not (dtau.shape == rate.shape == rate_dot.shape == x.shape[:2]):
            raise ValueError(f"proper_time: shapes {dtau.shape}, {rate.shape}, {rate_dot.shape}; allowed: "
                             f"{x.shape[:2]} each")
    tgrid = th + tl
    q = pseudorange_quantities(tgrid, lp.tau, lp.tau_rate, dtau, rate, rate_dot)
    return {"t": tgrid, "t_init": float(tgrid[0]), "tcb/x": x, "tcb/v": v, "tcb/a": a, "tcb/n": lp.unit_vectors,
            **q}


def pseudorange_quantities(t, ltt, d_ltt, dtau, rate, rate_dot) -> dict[str, np.ndarray]:
    """The clock-dependent datasets of a LISA orbit file (the module docstring's definitions).

    In one coordinate time (TT, TDB or TCB) shared by all inputs: t (N,)
    grid times [s] (float64); ltt: dd (hi, lo) light travel times (N, 6)
    [s] and d_ltt (N, 6) their rates [s/s] (rows without a light time:
    NaN); dtau, rate, rate_dot (N, 3): the clocks' proper-time deviations
    tau - t [s], their rates [s/s] and the rates' derivatives [1/s].

    Returns a dict of (N, ...) arrays: ``tcb/ltt`` (float64) and ``ltt_lo``
    (its dd remainder), ``tcb/d_ltt``, ``tcb/delta_tau``, ``tcb/ppr`` =
    ltt + delta_tau_recv(t) - delta_tau_emit(t - ltt), ``tcb/d_ppr``,
    ``tps/delta_t``, ``tps/ppr``, ``tps/d_ppr`` (d(d_ppr)/dt by second-order
    finite differences over the rows with a light time, when there are 3 or
    more; else NaN).
    """
    ltt_hi, ltt_lo = ltt
    f = ltt_hi + ltt_lo
    # receiver clock at t, emitter clock at t - ltt (Taylor series about the grid time t)
    dt_r, rate_r = dtau[:, _RECV], rate[:, _RECV]
    dt_e = dtau[:, _EMIT] - f * rate[:, _EMIT] + 0.5 * f ** 2 * rate_dot[:, _EMIT]
    rate_e = rate[:, _EMIT] - f * rate_dot[:, _EMIT]
    ppr = ltt_hi + (ltt_lo + (dt_r - dt_e))
    d_ppr = (rate_r - rate_e + d_ltt * (1.0 + rate_e)) / (1.0 + rate_r)
    # proper-time grid: coordinate time of tau = t_k is t_k + delta_t, delta_t = -delta_tau(t_k + delta_t)
    delta_t = -dtau
    delta_t = -(dtau + rate * delta_t)
    shift = delta_t[:, _RECV]
    # d(d_ppr)/dt by second-order finite differences over the rows that have a light travel time
    d_ppr_dt = np.full_like(d_ppr, np.nan)
    ok = np.all(np.isfinite(d_ppr), axis=1)
    i0 = int(np.argmax(ok)) if ok.any() else ok.size
    if ok.size - i0 >= 3 and ok[i0:].all():
        d_ppr_dt[i0:] = np.gradient(d_ppr[i0:], t[i0:], axis=0, edge_order=2)
    return {
        "tcb/ltt": f, "ltt_lo": ltt_lo - (f - ltt_hi), "tcb/d_ltt": d_ltt, "tcb/delta_tau": dtau,
        "tcb/ppr": ppr, "tcb/d_ppr": d_ppr, "tps/delta_t": delta_t, "tps/ppr": ppr + shift * d_ppr * (1.0 + rate_r),
        "tps/d_ppr": d_ppr + shift * d_ppr_dt,
    }
