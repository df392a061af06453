"""The BCRS/TCB LISA orbit file of :func:`tqdyn.workflows.export.export_lisa`
(``frame = "bcrs"``): barycentric states in TCB-compatible units, light
travel times solved again in the BCRS, clocks against TCB (the conversions
are listed in :mod:`tqdyn.workflows.export`'s docstring)."""

from __future__ import annotations

import pathlib
import tomllib
from dataclasses import dataclass

import erfa
import numpy as np

from .._version import __version__ as _TQDYN_VERSION
from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008, J2000_JD, L_B
from ..astro.geocentric import gcrs_to_bcrs_offsets
from ..constellation.indices import LINK_EMITTER, LINK_RECEIVER
from ..formats.lisa import (
    _time_offset,
    _uniform_grid,
    tcb_jd_of_epoch,
    write_lisa_orbits,
)
from ..lightpath import light_travel_times, shapiro_delay
from ..lightpath.proper_time import proper_time_deviation
from ..lightpath.proper_time_bcrs import proper_time_deviation_of
from ..numerics.dd import np_dd_add, np_fast_two_sum, np_two_prod, np_two_sum

__all__ = ["TCB_SCALE", "LisaExport", "export_bcrs"]


@dataclass(frozen=True)
class LisaExport:
    """Summary of one export: ``path`` written; ``size`` samples from ``t0``
    every ``dt`` [s, TT since ``epoch_utc``]; ``dropped_rows`` leading rows
    without an emission time inside the trajectory; ``source`` "tm" | "sat"
    and ``note`` (light-path endpoints); ``ltt_range`` (min, max) [s];
    ``shapiro`` whether the Shapiro delay is included; ``frame`` "gcrs" |
    "bcrs", ``time_scale`` "TT" | "TCB" of t0 and dt."""

    path: pathlib.Path
    size: int
    t0: float
    dt: float
    dropped_rows: int
    source: str
    note: str
    ltt_range: tuple[float, float]
    shapiro: bool
    frame: str = "gcrs"
    time_scale: str = "TT"
    shapiro_bodies: str = "the Earth"


def _scenario_gm(toml_text: str) -> float | None:
    """forces.gm_earth of a resolved scenario TOML, or None."""
    try:
        raw = tomllib.loads(toml_text or "")
        gm = raw.get("forces", {}).get("gm_earth")
        return float(gm) if gm is not None else None
    except (tomllib.TOMLDecodeError, TypeError, ValueError, AttributeError):
        return None


def _first_valid_row(ltt, src) -> int:
    valid = np.all(np.isfinite(ltt), axis=1)
    i0 = int(np.argmax(valid)) if valid.any() else len(valid)
    if i0 >= len(valid) - 1 or not valid[i0:].all():
        raise ValueError(f"{src}: light travel times undefined beyond the leading rows; cannot export")
    return i0


#: S = 1 / (1 - L_B): TDB-compatible -> TCB-compatible lengths and time intervals (IAU 2006 Resolution B3).
TCB_SCALE = 1.0 + L_B / (1.0 - L_B)
_S_MINUS_1 = L_B / (1.0 - L_B)  # S - 1, exact to the last rounding
_U_EXT_BODIES = ("sun", "moon", "mercury", "venus", "mars", "jupiter", "saturn", "uranus", "neptune")
_DIFF_S = 300.0  # s: half-step of the central differences of the TDB - TT series


def _dd_scale(hi, lo, k: float):
    """(hi + lo) * k as a dd pair (k float64; relative error ~1e-32)."""
    p, e = np_two_prod(np.asarray(hi, np.float64), k)
    return np_fast_two_sum(p, e + np.asarray(lo, np.float64) * k)


def _dd_tcb(hi, lo):
    """S (hi + lo) = (hi + lo) + (S - 1)(hi + lo) as a dd pair: TDB-compatible -> TCB-compatible."""
    d = (np.asarray(hi, np.float64) + np.asarray(lo, np.float64)) * _S_MINUS_1
    s, e = np_two_sum(np.asarray(hi, np.float64), d)
    return np_fast_two_sum(s, e + lo)


def _dd_plus(hi, lo, x):
    """(hi + lo) + x as a dd pair (x float64)."""
    s, e = np_two_sum(np.asarray(hi, np.float64), np.asarray(x, np.float64))
    return np_fast_two_sum(s, e + lo)


def _light_bodies(traj):
    """(layout, r dd, v dd, a float64) of the light-path bodies: the TMs when the trajectory has them, else the
    satellite centres (the choice of :func:`tqdyn.lightpath.light_travel_times_of`)."""
    tm = [f for f in ("tm/r", "tm/v", "tm/a") if f in traj]
    if len(tm) == 3:
        return "tm", traj.dd("tm/r"), traj.dd("tm/v"), np.asarray(traj["tm/a"], np.float64)
    if tm:
        raise ValueError("trajectory: has some but not all of tm/r, tm/v, tm/a")
    acc = np.asarray(traj["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in traj:
        acc = acc + np.asarray(traj["sat/a_dragfree"], np.float64)
    return "sat", traj.dd("sat/r"), traj.dd("sat/v"), acc


def _bc(x, ndim: int):
    """(N, 3) or (N, 1) -> (N, 1, ..., 1, k) with ndim dimensions (broadcast over bodies)."""
    return x.reshape(x.shape[:1] + (1,) * (ndim - 2) + x.shape[-1:])


def _earth_state(ephemeris, jd1, jd2):
    """Earth's barycentric position, velocity, gravitational acceleration and the external potential at the
    geocentre (Sun, Moon, planets of the DE file, DE430/DE431 GMs) at TDB JDs (N,): (N,3) x3 and (N,1)."""
    from ..astro.ephemeris import planetary_gm

    x_e, v_e = ephemeris.earth_barycentric(jd1, jd2)
    names = tuple(b for b in _U_EXT_BODIES if b in ephemeris.bodies)
    rel, _ = ephemeris.geocentric_states(names, jd1, jd2, velocity=False)
    gms = planetary_gm()
    gm = np.array([gms[b] for b in names])
    d = np.linalg.norm(rel, axis=-1)
    u_ext = np.sum(gm / d, axis=-1)[:, None]
    a_e = np.sum((gm / d ** 3)[..., None] * rel, axis=-2)
    return x_e, v_e, a_e, u_ext, names


def _uniform_tdb_grid(th, tl, e0: float, e1: float):
    """Uniform dd grid t_k = (t_0 + e0) + k ((t_{N-1} + e1) - (t_0 + e0)) / (N - 1), k = 0 .. N-1."""
    N = th.size
    tb0 = _dd_plus(th[0], tl[0], e0)
    tb1 = _dd_plus(th[-1], tl[-1], e1)
    span = (tb1[0] - tb0[0]) + (tb1[1] - tb0[1])
    kdt_h, kdt_l = np_two_prod(np.arange(N, dtype=np.float64), span / (N - 1))
    bh, bl = np_two_sum(np.full(N, tb0[0]), kdt_h)
    return np_fast_two_sum(bh, bl + (kdt_l + tb0[1]))


def _bcrs_states_geocentric(traj, bodies: dict, ephemeris) -> dict:
    """Geocentric (TT-compatible GCRS, TT) states -> BCRS states (origin the SSB, ICRF axes, TDB-compatible) on
    a uniform TDB grid.

    The grid t_k (TDB seconds since the epoch's TDB) runs from TDB(T_0) to TDB(T_{N-1}) in N uniform steps; the
    geocentre's event at t_k has the TT instant T_k = t_k - (TDB - TT)(T_k) (fixed point, 3 iterations);
    the states there come from the quintic Hermite dense output of the trajectory (accelerations: linear
    between rows).  Then y = X / K, w = V / K (K = (1 - L_G)/(1 - L_B)), r = y + dr
    (:func:`gcrs_to_bcrs_offsets`), x_B = x_E(TDB(T_k)) + r, v_B = v_E + (w + dw) dT/dt, a_B = a_E + acc/K
    (1PN terms of a, < 1e-9 m/s^2, not applied), with dT/dt = 1/(1 + d(TDB - TT)/dT).
    bodies: name -> (r dd, v dd, a float64) with leading axis N.  Returns a dict with ``t`` (hi, lo), ``T``
    (hi, lo) [s TT since the epoch], ``x_e``, ``v_e``, ``a_e`` (N, 3), ``u_ext`` (N, 1), ``dT_dt_m1`` (N,) (dT/dt - 1) and
    ``bodies``: name -> (r dd, v dd, a float64) in the BCRS, plus ``y``: name -> y (geocentric, TDB units).
    """
    from ..astro.geocentric import TDB_TO_TT_SCALE
    from ..astro.timescales import tdb_jd, tdb_minus_tt, tt_jd
    from ..numerics.dd import np_dd_div_d
    from ..numerics.hermite import interpolate_states

    epoch = traj.epoch
    th, tl = (np.asarray(p, np.float64) for p in traj.dd("t"))
    N = th.size
    d0 = float(tdb_minus_tt(*epoch.tt))

    def dtdb(hi, lo):  # (TDB - TT)(T) - (TDB - TT)(epoch) [s]
        return np.asarray(tdb_minus_tt(*tt_jd(epoch, hi, lo)), np.float64) - d0

    bh, bl = _uniform_tdb_grid(th, tl, float(dtdb(th[0], tl[0])), float(dtdb(th[-1], tl[-1])))
    Th, Tl = _dd_plus(bh, bl, -dtdb(th, tl))
    for _ in range(3):
        Th, Tl = _dd_plus(bh, bl, -dtdb(Th, Tl))
    lo_t, hi_t = th[0] + tl[0], th[-1] + tl[-1]  # rounding at the ends must not leave the grid
    Tl = np.where(Th + Tl < lo_t, lo_t - Th, np.where(Th + Tl > hi_t, hi_t - Th, Tl))
    ddt = (dtdb(Th + _DIFF_S, Tl) - dtdb(Th - _DIFF_S, Tl)) / (2 * _DIFF_S)
    dT_dt_m1 = -ddt / (1.0 + ddt)  # dT/dt - 1
    jd1, jd2 = tdb_jd(epoch, Th, Tl)
    x_e, v_e, a_e, u_ext, names = _earth_state(ephemeris, jd1, jd2)
    K = float(TDB_TO_TT_SCALE)
    nodes = np.ascontiguousarray(np.stack([th, tl], -1))
    query = np.ascontiguousarray(np.stack([Th, Tl], -1))
    jn = np.clip(np.searchsorted(th + tl, Th + Tl, side="right") - 1, 0, N - 2)
    frac = ((Th - th[jn]) + (Tl - tl[jn])) / ((th[jn + 1] - th[jn]) + (tl[jn + 1] - tl[jn]))
    out, ys = {}, {}
    for name, (r, v, a) in bodies.items():
        r = np.ascontiguousarray(np.stack([np.asarray(p, np.float64) for p in r], -1))
        v = np.ascontiguousarray(np.stack([np.asarray(p, np.float64) for p in v], -1))
        a = np.ascontiguousarray(np.asarray(a, np.float64))
        rq, vq = interpolate_states(nodes, r, v, a, query)
        fr = frac.reshape((-1,) + (1,) * (a.ndim - 1))
        acc = (a[jn] * (1 - fr) + a[jn + 1] * fr) / K
        yh, yl = np_dd_div_d(rq[..., 0], rq[..., 1], K)
        y = yh + yl
        w = (vq[..., 0] + vq[..., 1]) / K
        nd = y.ndim
        ve, ae = _bc(v_e, nd), _bc(a_e, nd)
        dr, dw = gcrs_to_bcrs_offsets(y, w, acc, ve, ae, _bc(u_ext, nd))
        xh, xl = _dd_plus(yh, yl, dr)
        xh, xl = np_dd_add(xh, xl, *np_two_sum(_bc(x_e, nd) + 0.0 * y, np.zeros_like(y)))
        rate = 1.0 + _bc(dT_dt_m1[:, None], nd)
        vh, vl = np_two_sum(ve + 0.0 * w, (w + dw) * rate)
        out[name] = ((xh, xl), (vh, vl), ae + acc * rate * rate)
        ys[name] = (y, w)
    return {"t": (bh, bl), "T": (Th, Tl), "x_e": x_e, "v_e": v_e, "a_e": a_e, "u_ext": u_ext, "dT_dt_m1": dT_dt_m1,
            "bodies": out, "y": ys, "u_ext_bodies": names}


def _bcrs_states_heliocentric(traj, bodies: dict, ephemeris) -> dict:
    """Heliocentric (Sun-centred BCRS, TDB) states -> BCRS states with the origin at the SSB: + the Sun's
    barycentric position, velocity and acceleration at the same TDB
    (:func:`tqdyn.lightpath.heliocentric.sun_barycentric_motion`).  Same grid (TDB since the epoch)."""
    from ..lightpath.heliocentric import sun_barycentric_motion

    th, tl = (np.asarray(p, np.float64) for p in traj.dd("t"))
    x_s, v_s, a_s = sun_barycentric_motion(ephemeris, traj.epoch, (th, tl), traj.reference)
    out = {}
    for name, (r, v, a) in bodies.items():
        rh, rl = (np.asarray(p, np.float64) for p in r)
        vh, vl = (np.asarray(p, np.float64) for p in v)
        nd = rh.ndim
        out[name] = (_dd_plus(rh, rl, _bc(x_s, nd) + 0.0 * rh), _dd_plus(vh, vl, _bc(v_s, nd) + 0.0 * vh),
                     np.asarray(a, np.float64) + _bc(a_s, nd))
    return {"t": (th, tl), "x_sun": x_s, "v_sun": v_s, "a_sun": a_s, "bodies": out}


def _sun_position(traj, t_hi, t_lo, ephemeris):
    from ..astro.timescales import tdb_after

    return ephemeris.sun_barycentric(*tdb_after(traj.epoch, t_hi, t_lo))[0]


def _shapiro_bcrs(lp, center, gm_tdb):
    """Shapiro delay [s, TDB units] of a body of GM gm_tdb at ``center`` (N, 3) (BCRS, TDB-compatible) on the links
    of the BCRS light paths lp, and its rate (central differences along the grid)."""
    re = (lp.r_emit[0] + lp.r_emit[1]) - center[:, None, :]
    rr = (lp.r_receive[0] + lp.r_receive[1]) - center[:, None, :]
    return shapiro_delay(re, rr, gm_tdb)


def _clocks_tcb_geocentric(traj, sat, st, gm_earth):
    """Proper-time deviations against TCB of the satellites of a geocentric (TT) run, at their BCRS samples.

    lightpath's clocks against TT (:func:`tqdyn.lightpath.proper_time.proper_time_deviation`, the Earth's
    monopole: d tau/dTT = (1 - (GM_E/r + v^2/2)/c^2)/(1 - L_G)) give tau(T) = T + delta_tau_TT(T).  The BCRS
    sample k of satellite i is its event at TCB t_c,k = S t_k, whose TT is T_ik = T_k - (v_E . y_i)/c^2 (the
    1PN simultaneity: TCB - TCG = c^-2 [int (v_E^2/2 + U_ext) dt + v_E . r]; T_k the geocentre's); its proper
    time is T_ik + delta_tau_TT(T_ik) (Taylor series from row k: |T_ik - T_row| < 1 ms);
    delta_tau_c = tau - t_c, synchronised to 0 at the first sample.  Rate: d tau/dt_c = (1 + rate_TT)
    dT_i/dt_c, dT_i/dt_c = (dT/dt - (a_E . y + v_E . w)/c^2) / S; its derivative by finite differences."""
    t = traj.dd("t")
    r, v, a = sat
    dtau, rate, rate_dot = proper_time_deviation(t, r[0] + r[1], v[0] + v[1], a, gm_earth)
    th, tl = (np.asarray(p, np.float64) for p in t)
    Th, Tl = st["T"]
    bh, bl = st["t"]
    y, w = st["y"]["sat"]
    c2 = C_LIGHT * C_LIGHT
    ve, ae = st["v_e"][:, None, :], st["a_e"][:, None, :]
    shift = -np.einsum("nsk,nsk->ns", ve, y) / c2                   # T_ik - T_k
    eps = ((Th - th) + (Tl - tl))[:, None] + shift                  # T_ik - T_row
    dtau_e = dtau + rate * eps + 0.5 * rate_dot * eps ** 2
    # tau - t_c = (T_ik - T_0) + delta_tau(T_ik) - S (t_k - t_0) - const; elapsed parts in dd
    dTb_h, dTb_l = np_two_sum(Th - bh, Tl - bl)                     # T_k - t_k: -(TDB - TT) drift, ms
    dtk = (bh - bh[0]) + (bl - bl[0])
    lin = (dTb_h + dTb_l)[:, None] - (dTb_h[0] + dTb_l[0]) - (_S_MINUS_1 * dtk)[:, None]
    raw = lin + shift + dtau_e
    dtau_c = raw - raw[0]
    q = (np.einsum("nsk,nsk->ns", ae, y) + np.einsum("nsk,nsk->ns", ve, w)) / c2
    ddt = st["dT_dt_m1"][:, None]                                   # dT/dt - 1 (|.| < 4e-10)
    rate_e = rate + eps * rate_dot
    # (1 + rate)(1 + ddt - q)(1 - L_B) - 1, small terms kept small
    g = ddt - q
    rate_c = -L_B + (1.0 - L_B) * (rate_e + g + rate_e * g)
    dt_c = TCB_SCALE * (dtk[1] - dtk[0]) if dtk.size > 1 else 1.0
    rate_dot_c = np.gradient(rate_c, dt_c, axis=0, edge_order=2)
    return dtau_c, rate_c, rate_dot_c


def _assemble(t_c, ltt, d_ltt, n, dtau, rate, rate_dot):
    """ppr, d_ppr and the tps group from TCB light travel times and clocks, as
    :func:`tqdyn.lightpath.proper_time.lisa_orbit_quantities` forms them: ppr = ltt + delta_tau_r(t) -
    delta_tau_e(t - ltt) (emitter clock by its Taylor series), d_ppr = (dtau_r - dtau_e + d_ltt (1 + dtau_e)) /
    (1 + dtau_r), delta_t = -delta_tau(tau + delta_t) (two iterations), tps values moved by delta_t with their
    first derivatives.  ltt: dd (hi, lo) (N, 6); the rest float64; t_c (N,) uniform."""
    R, E = LINK_RECEIVER, LINK_EMITTER
    lh, ll = ltt
    lf = lh + ll
    dt_r, rate_r = dtau[:, R], rate[:, R]
    dt_e = dtau[:, E] - lf * rate[:, E] + 0.5 * lf ** 2 * rate_dot[:, E]
    rate_e = rate[:, E] - lf * rate_dot[:, E]
    ppr = lh + (ll + (dt_r - dt_e))
    d_ppr = (rate_r - rate_e + d_ltt * (1.0 + rate_e)) / (1.0 + rate_r)
    delta_t = -dtau
    delta_t = -(dtau + rate * delta_t)
    shift = delta_t[:, R]
    d_ppr_dt = np.gradient(d_ppr, t_c, axis=0, edge_order=2)
    return {"tcb/ppr": ppr, "tcb/d_ppr": d_ppr, "tps/delta_t": delta_t,
            "tps/ppr": ppr + shift * d_ppr * (1.0 + rate_r), "tps/d_ppr": d_ppr + shift * d_ppr_dt}


def export_bcrs(traj, out, src, attrs, *, shapiro, gm, axes, time_origin) -> LisaExport:
    """The BCRS / TCB export (see the module docstring and docs/lisa-export.md)."""
    from ..astro.ephemeris import default_ephemeris, planetary_gm

    ephemeris = default_ephemeris()
    ref = traj.reference
    helio = ref.origin == "sun"
    if shapiro is None:  # default: the Sun's Shapiro delay in heliocentric files, none in geocentric ones
        shapiro = helio
    gms = planetary_gm()
    gm_sun = float(gms["sun"])  # TDB-compatible (DE430/DE431), the heliocentric force model's value
    layout, lr, lv, la = _light_bodies(traj)
    sat_a = np.asarray(traj["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in traj:
        sat_a = sat_a + np.asarray(traj["sat/a_dragfree"], np.float64)
    sat = (traj.dd("sat/r"), traj.dd("sat/v"), sat_a)
    bodies = {"sat": sat} if layout == "sat" else {"sat": sat, "light": (lr, lv, la)}
    if helio:
        st = _bcrs_states_heliocentric(traj, bodies, ephemeris)
        x_sun = st["x_sun"]
        # tau - TCB, rates per TCB second: the Sun's and the planets' potentials, the barycentric velocity
        dtau, rate, rate_dot = proper_time_deviation_of(traj, against="TCB", ephemeris=ephemeris)
        gm_e = None
    else:
        gm_e = gm if gm is not None else _scenario_gm(str(attrs.get("scenario", "")))
        gm_e = float(GM_EARTH_EGM2008) if gm_e is None else float(gm_e)
        st = _bcrs_states_geocentric(traj, bodies, ephemeris)
        x_sun = ephemeris.sun_barycentric(*_tdb_of(traj, st))[0]
        dtau, rate, rate_dot = _clocks_tcb_geocentric(traj, sat, st, gm_e)
    tb = st["t"]
    (xr, xv, xa) = st["bodies"]["light" if layout == "tm" else "sat"]
    note = ("test mass to test mass: receiver = TM of satellite a facing b, emitter = TM of satellite b facing a"
            if layout == "tm" else "satellite centre of mass to satellite centre of mass")
    lp = light_travel_times(tb, xr, xv, xa, note=note + " (solved in the BCRS)")
    # Shapiro delays (TDB units), added to the geometric BCRS light time: ltt = ltt_geo + s / (1 - n.v_e/c)
    s_tot = np.zeros_like(lp.tau[0])
    shap_parts = []
    if shapiro:
        s_tot = s_tot + _shapiro_bcrs(lp, x_sun, gm_sun)
        shap_parts.append("the Sun")
        if not helio:
            s_tot = s_tot + _shapiro_bcrs(lp, st["x_e"], gm_e / float(_tdb_to_tt()))
            shap_parts.append("the Earth")
    n = lp.unit_vectors
    nve = np.einsum("...k,...k->...", n, lp.v_emit)
    d_ltt = lp.tau_rate
    ltt_h, ltt_l = lp.tau
    if shapiro:
        gain = 1.0 / (1.0 - nve / C_LIGHT)
        add = s_tot * gain
        ltt_h, ltt_l = _dd_plus(ltt_h, ltt_l, add)
        tgrid = tb[0] + tb[1]
        ok = np.all(np.isfinite(add), axis=1)
        s_dot = np.full_like(add, np.nan)
        s_dot[ok] = np.gradient(add[ok], tgrid[ok], axis=0, edge_order=2)
        d_ltt = d_ltt + s_dot
    i0 = _first_valid_row(ltt_h, src)
    sl = slice(i0, None)
    # TCB: t_c = S t, x_c = S x, v unchanged, a / S, ltt S ltt; then the time origin
    tch, tcl = _dd_tcb(tb[0], tb[1])
    t_first = float(tch[i0] + tcl[i0])
    t_off, t_conv = _time_offset(time_origin, traj.epoch, t_first)
    lch, lcl = _dd_tcb(ltt_h, ltt_l)
    t_c = (tch - tch[i0]) + (tcl - tcl[i0])  # elapsed TCB since the first exported sample, for derivatives
    q = _assemble(t_c[sl], (lch[sl], lcl[sl]), d_ltt[sl], n[sl], dtau[sl], rate[sl], rate_dot[sl])
    (sxh, sxl), (svh, svl), sa = st["bodies"]["sat"]
    xh, xl = _dd_tcb(sxh, sxl)
    x, v, a = xh + xl, svh + svl, sa / TCB_SCALE
    if axes == "ecliptic":
        rot = erfa.ecm06(J2000_JD, 0.0)  # ICRS -> mean ecliptic and equinox of J2000 (IAU 2006, frame bias)
        x, v, a, n = (z @ rot.T for z in (x, v, a, n))
    th_out, tl_out = _dd_plus(tch, tcl, t_off)
    t_out = (th_out[sl], tl_out[sl])
    c1, c2 = tcb_jd_of_epoch(traj.epoch)
    endpoints = ("test masses (TM of satellite i facing j <- TM of satellite j facing i)" if layout == "tm"
                 else "satellite centres of mass (the trajectory has no test-mass fields)")
    axes_text = ("ICRF (the BCRS's own axes)" if axes == "icrf" else
                 "mean ecliptic and equinox of J2000.0 (IAU 2006, erfa.ecm06(J2000 TT): x_ecl = R x_ICRF; the "
                 "axes of lisaorbits' files)")
    source_text = ("heliocentric tqdyn run (Sun-centred BCRS, TDB) + the Sun's barycentric state (DE ephemeris "
                   "0 -> 10 at the same TDB)" if helio else
                   "geocentric tqdyn run (TT-compatible GCRS, TT) + the Earth's barycentric state at TDB(TT) + the "
                   "1PN GCRS -> BCRS transformation (IERS 2010 ch. 10, the inverse of tqdyn's bcrs_to_gcrs), "
                   "resampled to a uniform TCB grid (quintic Hermite)")
    if helio:
        tps_def = ("proper time of each satellite's centre of mass against TCB: d tau/dTCB = 1 - (GM_S/r + v^2/2)/"
                   "c^2 with r, v Sun-centred (lightpath's clock integrator with GM_S; the model of lisaorbits' "
                   "InterpolatedOrbits), converted from TDB exactly; not applied: the planets' potentials "
                   "(Jupiter ~2e-12, the Earth ~1e-13 of the rate) and the Sun's barycentric velocity in v^2 "
                   "(~4e-12 of the rate, common to the three clocks); delta_tau = 0 at t_init")
    else:
        tps_def = ("proper time of each satellite's centre of mass against TCB: lightpath's clock against TT "
                   "(d tau/dTT = (1 - (GM_E/r + v^2/2)/c^2)/(1 - L_G), GM_E = attribute gm_earth) at the "
                   "satellite's BCRS event (TT of the geocentre minus v_E.r/c^2), tau - TCB; delta_tau = 0 at "
                   "t_init for every satellite (the clocks are synchronised in TCB, not in TT)")
    meta = {
        "generator": "tqdyn export --format lisa --frame bcrs",
        "tqdyn_version": _TQDYN_VERSION,
        "frame": "BCRS: origin the solar-system barycentre, TCB-compatible coordinates (x_TCB = x_TDB / (1 - L_B)); "
                 "axes " + axes_text,
        "origin": "solar-system barycentre",
        "axes": axes,
        "coordinates_from": source_text,
        "time_scale": "TCB (the coordinate time of the BCRS); tps/* are sampled at each receiver's proper time tau "
                      "= t0 + k dt",
        "t0_convention": t_conv,
        "time_origin": time_origin,
        "epoch_tcb_jd1": c1, "epoch_tcb_jd2": c2,
        "epoch_tdb_jd1": float(traj.epoch.tdb[0]), "epoch_tdb_jd2": float(traj.epoch.tdb[1]),
        "epoch_utc": str(attrs.get("epoch_utc", "")),
        "epoch_tdb": str(attrs.get("epoch_tdb", "")),
        "tcb_conversion": "IAU 2006 B3: TDB = TCB - L_B (JD_TCB - T0) 86400 s + TDB0, L_B = 1.550519768e-8, "
                          "T0 = 2443144.5003725, TDB0 = -6.55e-5 s; t_TCB - t_TCB(epoch) = (t_TDB - t_TDB(epoch)) "
                          "/ (1 - L_B); x / (1 - L_B); v unchanged; a (1 - L_B); ltt / (1 - L_B); d_ltt, d_ppr "
                          "unchanged" + ("" if helio else "; TT -> TDB at the geocentre by erfa.dtdb (Fairhead & "
                                         "Bretagnon)"),
        "t_init": float(th_out[0] + tl_out[0]),  # delta_tau = 0 here: the trajectory's first sample
        "tt_method": "iterative (Newton, double-double, quintic Hermite dense output of the emitter), solved in "
                     "the BCRS (TDB-compatible units, then scaled to TCB)",
        "ignore_shapiro": not shapiro,
        "shapiro_bodies": (" and ".join(shap_parts) + " (2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)), r from the "
                           "body's ephemeris centre, GM_TCB = GM_TDB / (1 - L_B); added to the geometric BCRS light "
                           "time as s / (1 - n.v_e/c))") if shap_parts else "none",
        "ltt_endpoints": endpoints,
        "ltt_note": lp.note,
        "link_order": "12, 23, 31, 13, 32, 21 (ij: received by spacecraft i, emitted by spacecraft j)",
        "tps_definition": tps_def,
        "gm_sun_tdb": gm_sun,
        "dropped_rows": i0,
        "precision_note": "float64 datasets; dd remainder of tcb/ltt in tqdyn/ltt_lo (ltt = tcb/ltt + tqdyn/ltt_lo)",
        "source_trajectory": src,
        "source_frame": f"{ref.origin} / {ref.frame} / {ref.time_scale}",
        "tqdyn_scenario": str(attrs.get("scenario", "")),
    }
    if not helio:
        meta["gm_earth"] = gm_e
        meta["gcrs_to_bcrs"] = ("x_B = x_E(TDB(T)) + y + dr, y = X/K (K = (1 - L_G)/(1 - L_B)), dr = -[(v_E.y) v_E/2 + "
                                "U_ext y + (a_E.y) y - a_E y^2/2 + w (v_E.y)]/c^2 (U_ext, a_E from the Sun, Moon "
                                "and planets of the ephemeris), v_B = v_E + (w + dw) dT/dt; 1PN terms of a "
                                "(< 1e-9 m/s^2) and O(c^-4) not applied")
    ltt_lo = ((lch - (lch + lcl)) + lcl)[sl]
    path = write_lisa_orbits(
        out, t_out, x[sl], v[sl], a[sl], (lch + lcl)[sl], d_ltt[sl], n[sl], q["tcb/ppr"], q["tcb/d_ppr"],
        delta_tau=dtau[sl], tps_ppr=q["tps/ppr"], tps_d_ppr=q["tps/d_ppr"], tps_delta_t=q["tps/delta_t"],
        attrs=meta, extra={"tqdyn/ltt_lo": ltt_lo}, frame_label="BCRS" + (" (ecliptic axes)" if axes == "ecliptic"
                                                                           else ""))
    t0, dt = _uniform_grid(t_out)
    ltt = (lch + lcl)[sl]
    return LisaExport(path=path, size=int(ltt.shape[0]), t0=t0, dt=dt, dropped_rows=i0, source=layout,
                      note=lp.note, ltt_range=(float(ltt.min()), float(ltt.max())), shapiro=bool(shapiro),
                      frame="bcrs", time_scale="TCB", shapiro_bodies=" and ".join(shap_parts) or "none")


def _tdb_to_tt():
    from ..astro.geocentric import TDB_TO_TT_SCALE

    return TDB_TO_TT_SCALE


def _tdb_of(traj, st):
    from ..astro.timescales import tdb_jd

    return tdb_jd(traj.epoch, *st["T"])
