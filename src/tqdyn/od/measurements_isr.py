"""Inter-satellite ranging along the constellation's arms.

Links in LISA order 12, 23, 31, 13, 32, 21 (:mod:`tqdyn.constellation.indices`:
link ab received on satellite a, emitted by satellite b).  Satellite states
(N, 3, 3) [time, satellite, xyz] at the reception times t (GCRS geocentric,
TT; Sun-centred BCRS heliocentric, TDB).

* :func:`isr_range` -- absolute ranging (a ranging code on the laser link,
  dm to m noise, :data:`ISR_ABSOLUTE_SIGMA_M`): the one-way light-path
  range c tau, c tau = |r_a(t) - x_b(t - tau)| with the emitter propagated
  back over tau by its Taylor series x_b = r_b - v_b tau + a_b tau^2 / 2
  (a_b given, or the central body's point-mass attraction; the next term,
  |da/dt| tau^3 / 6, is < 1e-7 m for TianQin's 0.57 s and < 1e-3 m for
  LISA's 8.3 s), solved by Newton iteration in float64 (resolution ~1e-8 m
  on 1e8 m, far below the noise).  No Shapiro delay (< 3 cm for TianQin;
  heliocentric runs: see the arm-length changes).
* :func:`arm_length_changes` -- the pm-level changes of the light-path
  ranges, c (tau(t) - tau(t_0)) per link, from the project's light travel
  times (:func:`tqdyn.lightpath.light_time.light_travel_times`: double-double
  Newton solution on the run's grid, Hermite dense output, Shapiro delays as
  configured there), the difference taken in double-double so that the
  1e8-1e9 m arms keep sub-pm resolution.

Partials (both): with u = (r_a - x_b) / L the unit vector from emitter to
receiver and Dn = c - u . (v_b - a_b tau), d tau (Dn) = u . (dr_a - dr_b
+ tau dv_b), hence d(c tau)/dr_a = c u / Dn, d/dr_b = -c u / Dn, d/dv_b =
c tau u / Dn, d/dv_a = 0 (the dependence of a_b on r_b, ~GM tau^2/r^3 ~
1e-11 relative, is left out).
"""

from __future__ import annotations

import numpy as np

from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from ..lightpath.light_time import light_travel_times
from ..numerics.dd import np_two_sum
from .measurements import Observable

__all__ = ["ISR_ABSOLUTE_SIGMA_M", "ISR_ARM_SIGMA_M", "arm_length_changes", "isr_range"]

#: Default noise of absolute inter-satellite ranging [m] (dm to m: 0.5 m).
ISR_ABSOLUTE_SIGMA_M = 0.5
#: Default noise of the arm-length changes [m] (pm level, per sample).
ISR_ARM_SIGMA_M = 1e-12


def _states(r, v, a, gm):
    r = np.asarray(r, np.float64)
    v = np.asarray(v, np.float64)
    if r.ndim != 3 or r.shape[1:] != (3, 3) or v.shape != r.shape:
        raise ValueError(f"satellite states: shapes {r.shape}, {v.shape} are not allowed; expected (N, 3, 3)")
    if a is None:
        gm = float(GM_EARTH_EGM2008) if gm is None else float(gm)
        a = -gm * r / np.linalg.norm(r, axis=-1, keepdims=True) ** 3
    return r, v, np.asarray(a, np.float64)


def _geometry(r, v, a, tau):
    """Unit vectors, Dn and the partials (N, 6, 2, 3) at light times tau (N, 6)."""
    rr, re, ve, ae = r[:, LINK_RECEIVER], r[:, LINK_EMITTER], v[:, LINK_EMITTER], a[:, LINK_EMITTER]
    xe = re - ve * tau[..., None] + 0.5 * ae * tau[..., None] ** 2
    D = rr - xe
    L = np.linalg.norm(D, axis=-1)
    u = D / L[..., None]
    Dn = C_LIGHT - np.einsum("nli,nli->nl", u, ve - ae * tau[..., None])
    g = C_LIGHT * u / Dn[..., None]
    d_r = np.stack([g, -g], axis=-2)
    d_v = np.stack([np.zeros_like(g), tau[..., None] * g], axis=-2)
    return L, Dn, d_r, d_v


def isr_range(t, r, v, a=None, *, gm=None, max_iter: int = 6) -> Observable:
    """Absolute one-way inter-satellite ranges c tau of the six links.

    t : (N,) reception times [s]; r, v : (N, 3, 3) satellite positions [m]
    and velocities [m/s] at t; a : (N, 3, 3) accelerations [m/s^2] or None
    (point mass ``gm`` [m^3/s^2] at the origin, default the Earth's
    EGM2008 GM: pass the Sun's for heliocentric runs).

    Returns an Observable: value (N, 6) [m]; d_r, d_v (N, 6, 2, 3) with
    respect to the receiver (index 0) and the emitter (index 1) at t;
    visible (N, 6) all True (the arms are always in sight); extra ``tau``
    (N, 6) [s].
    """
    r, v, a = _states(r, v, a, gm)
    rr, re, ve, ae = r[:, LINK_RECEIVER], r[:, LINK_EMITTER], v[:, LINK_EMITTER], a[:, LINK_EMITTER]
    tau = np.linalg.norm(rr - re, axis=-1) / C_LIGHT
    for _ in range(max_iter):
        L, Dn, _, _ = _geometry(r, v, a, tau)
        step = (C_LIGHT * tau - L) / Dn
        tau = tau - step
        if np.all(np.abs(step) < 1e-16 * np.maximum(tau, 1.0)):
            break
    L, Dn, d_r, d_v = _geometry(r, v, a, tau)
    return Observable(C_LIGHT * tau, d_r, d_v, np.ones(tau.shape, bool), "inter-satellite range", "m",
                      {"tau": tau})


def arm_length_changes(t, r, v, a, *, reference_row: int | None = None, **kwargs) -> Observable:
    """Changes of the light-path ranges c tau of the six links, from the
    project's light travel times, relative to one row.

    t : (N,) grid [s] (dd accepted as by :func:`~tqdyn.lightpath.light_time.light_travel_times`);
    r, v : (N, 3, 3) satellite centres [m, m/s] (float64 or dd (hi, lo) tuples); a : (N, 3, 3)
    float64 [m/s^2]; reference_row : the row whose ranges are subtracted
    (default: the first row with finite light times); kwargs go to
    :func:`~tqdyn.lightpath.light_time.light_travel_times` (shapiro,
    reference, origin_velocity, ...).

    Returns an Observable: value (N, 6) = c tau(t) - c tau(t_ref) [m],
    difference taken in double-double; d_r, d_v (N, 6, 2, 3) as
    :func:`isr_range`'s; visible (N, 6) where tau is finite; extra
    ``reference_range`` (6,) float64 [m], ``reference_row``, ``light_times``
    (the :class:`~tqdyn.lightpath.results.LightTravelTimes`).
    """
    lp = light_travel_times(t, r, v, a, **kwargs)
    hi, lo = lp.range
    ok = np.isfinite(hi)
    k = int(np.argmax(ok.all(axis=1))) if reference_row is None else int(reference_row)
    s, e = np_two_sum(hi, -hi[k])
    value = s + (e + (lo - lo[k]))
    rf = np.asarray(r[0] if isinstance(r, tuple) else r, np.float64)     # hi parts suffice for partials
    vf = np.asarray(v[0] if isinstance(v, tuple) else v, np.float64)
    tau = np.nan_to_num(lp.tau[0] + lp.tau[1])
    _, _, d_r, d_v = _geometry(rf, vf, np.asarray(a, np.float64), tau)
    return Observable(value, d_r, d_v, ok, "arm-length change", "m",
                      {"reference_range": hi[k] + lo[k], "reference_row": k, "light_times": lp})
