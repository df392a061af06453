"""Light paths between test masses: iterative light travel times and ranges.

For each of the six one-way links ``ab`` (LISA order 12, 23, 31, 13, 32, 21,
:class:`~tqdyn.constellation.indices.Link`: received on satellite a, emitted
by satellite b) this module solves the light-travel-time equation

    c tau(t) = |r_e(t - tau) - r_r(t)|  [+ c * Shapiro delay, optional]

on the trajectory's own time grid t (TT seconds since the epoch, GCRS,
geocentric), where

* r_r(t) is the *receiving* body at the grid time t -- the test mass (TM) of
  satellite a in the MOSA that faces b (``Sat(a).mosa_facing(Sat(b))``) --
  taken exactly as stored (no interpolation), and
* r_e(t - tau) is the *emitting* body -- the TM of satellite b in the MOSA
  that faces a -- at the emission time, from the quintic Hermite dense output
  of its grid positions, velocities and accelerations
  (:func:`tqdyn.numerics.hermite.hermite_eval`, nodes at the two ends of
  the grid interval holding t - tau), evaluated in double-double (dd) so
  that the 1.7e8 m arms keep ~1e-24 m resolution.  The quintic's error is
  at most ~|r| (n h)^6 / 46080, about 2e-15 m on a 1e8 m orbit at h = 50 s,
  in mid-interval; t - tau lies ~0.58 s before a grid node, where it is far
  smaller (measured ~1e-18 m against exact Kepler orbits,
  ``tests/test_lightpath.py``).

The equation is solved by Newton's method in dd, starting from the
instantaneous distance |r_e(t) - r_r(t)| / c: f(tau) = tau - |D| / c with
D = r_e(t - tau) - r_r(t) and f'(tau) = 1 + (D . v_e) / (|D| c) (v_e from the
same Hermite polynomial), stopping when the Newton correction is below
``tol`` (default 1e-24 s); three iterations usually suffice.  The returned
residual is the equation's residual at the returned tau, evaluated in dd
(~1e-31 s).  Cost: ~12 s for 90 days at 50 s (155,521 rows x 6 links), after
~5 s of one-off compilation.

Rows whose emission time t - tau precedes the first grid time cannot be
interpolated: their tau, range, emitter state and residual are NaN (for a
grid starting at t = 0 that is the first row only, since tau ~ 0.57 s is
much shorter than the step).

Shapiro delay of the Earth (off by default, as in the paper):
2 GM/c^3 ln((r_e + r_r + L)/(r_e + r_r - L)) with r_e = |r_e(t - tau)|,
r_r = |r_r(t)|, L = |D|; about 7.8e-11 s (2.3 cm) for TianQin, nearly
constant (it varies with the arm lengths only).  GM defaults to
:data:`tqdyn.astro.constants.GM_EARTH_EGM2008`.  The delay by itself:
:func:`tqdyn.lightpath.shapiro.shapiro_delay`; the instantaneous ranges
(no light travel time): :func:`tqdyn.lightpath.ranges.instantaneous_ranges`.

Bodies: the core functions take arrays, either test masses ``(N, 3, 2, 3)``
[time, satellite, MOSA/TM, xyz] or satellite centres ``(N, 3, 3)`` [time,
satellite, xyz] (then receiver and emitter are the satellites' centres of
mass).  :func:`light_travel_times_of` takes a trajectory object (duck-typed
like :class:`tqdyn.formats.trajectory.Trajectory`: ``name in traj``, ``traj.dd(name)``,
``traj[name]``) and falls back to the satellite centres when it has no test
masses (pure-gravity runs), saying so in the result's ``source`` and
``note``.

dd inputs: positions and velocities are given as a ``(hi, lo)`` tuple of
float64 arrays, as a float64 array with a trailing axis of length 2
(``[..., 0] = hi``), or as plain float64 (lo = 0); accelerations are float64
(a float64 acceleration costs < 1e-15 m in the interpolated position, see
:mod:`tqdyn.numerics.hermite`).  dd outputs are ``(hi, lo)`` tuples.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from ..astro.constants import C_LIGHT
from ..constellation.indices import LINK_EMITTER, LINK_EMITTER_MOSA, LINK_RECEIVER, LINK_RECEIVER_MOSA
from ..numerics.hermite import hermite_eval
from ..numerics.dd import (
    add,
    div,
    ld,
    mul,
    np_dd_add,
    np_two_prod,
    np_two_sum,
    sqrt,
    st,
    sub,
)
from .shapiro import _default_gm

__all__ = [
    "BODY_LAYOUTS",
    "LightTravelTimes",
    "light_travel_times",
    "light_travel_times_of",
    "link_bodies",
]

BODY_LAYOUTS = ("tm", "sat")
"""Body layouts: ``"tm"`` = test masses (N, 3, 2, 3); ``"sat"`` = satellite centres (N, 3, 3)."""

# per link (LISA order): receiving / emitting satellite (0-based) and the MOSA (0-based)
# of each that faces the other one
_RECV_SAT, _EMIT_SAT = LINK_RECEIVER, LINK_EMITTER
_RECV_MOSA, _EMIT_MOSA = LINK_RECEIVER_MOSA, LINK_EMITTER_MOSA


# ------------------------------------------------------------------ input helpers

def _dd_input(x, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(hi, lo) float64 arrays from a (hi, lo) tuple, a dd array [..., 2] or float64 (lo = 0).

    A float64 array whose last axis has length 2 is taken as dd; vectors
    always have a last axis of length 3, so the forms cannot be confused."""
    if isinstance(x, tuple):
        if len(x) != 2:
            raise ValueError(f"{name}: a dd value must be a (hi, lo) pair, got a tuple of length {len(x)}")
        hi, lo = (np.asarray(p, dtype=np.float64) for p in x)
        if hi.shape != lo.shape:
            raise ValueError(f"{name}: hi shape {hi.shape} != lo shape {lo.shape}")
        return hi, lo
    arr = np.asarray(x)
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"{name}: dtype {arr.dtype} is not real numeric (float64 expected)")
    arr = arr.astype(np.float64, copy=False)
    if arr.ndim >= 1 and arr.shape[-1] == 2:
        return arr[..., 0], arr[..., 1]
    return arr, np.zeros_like(arr)


def _layout_of(shape: tuple, name: str) -> str:
    if len(shape) == 4 and shape[1:] == (3, 2, 3):
        return "tm"
    if len(shape) == 3 and shape[1:] == (3, 3):
        return "sat"
    raise ValueError(f"{name}: shape {shape} is neither test masses (N, 3, 2, 3) nor satellite centres "
                     "(N, 3, 3)")


def link_bodies(x: np.ndarray, layout: str) -> tuple[np.ndarray, np.ndarray]:
    """Receiver and emitter bodies of the six links from a per-body array.

    x: (N, 3, 2, ...) for layout ``"tm"`` [time, satellite, MOSA, ...] or
    (N, 3, ...) for ``"sat"``.  Returns (receiver, emitter), each (N, 6, ...)
    in LISA link order: link ab takes satellite a's TM facing b (receiver)
    and satellite b's TM facing a (emitter); for ``"sat"`` the satellites'
    centres a and b.  Units and frame are those of ``x``.
    """
    if layout == "tm":
        return x[:, _RECV_SAT, _RECV_MOSA], x[:, _EMIT_SAT, _EMIT_MOSA]
    if layout == "sat":
        return x[:, _RECV_SAT], x[:, _EMIT_SAT]
    raise ValueError(f"layout: {layout!r} is not allowed; allowed: {', '.join(BODY_LAYOUTS)}")


def _check_times(t, name: str = "t") -> tuple[np.ndarray, np.ndarray]:
    if not isinstance(t, tuple) and np.ndim(t) == 1:  # plain float64 times (lo = 0)
        th = np.asarray(t, dtype=np.float64)
        tl = np.zeros_like(th)
    else:
        th, tl = _dd_input(t, name)
    if th.ndim != 1:
        raise ValueError(f"{name}: grid times must have shape (N,) (dd), got {th.shape}")
    if th.size < 2:
        raise ValueError(f"{name}: the grid needs at least 2 times for interpolation, got {th.size}")
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(tl))):
        raise ValueError(f"{name}: grid times must be finite")
    dh, dl = np_dd_add(th[1:], tl[1:], -th[:-1], -tl[:-1])
    bad = np.nonzero(dh + dl <= 0)[0]
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"{name}: grid times must be strictly increasing; t[{k + 1}] = {th[k + 1] + tl[k + 1]!r} s "
                         f"<= t[{k}] = {th[k] + tl[k]!r} s")
    return np.ascontiguousarray(th), np.ascontiguousarray(tl)


# ------------------------------------------------------------------ compiled solver

@njit(cache=True)
def _norm_dd(D):
    """|D| of a dd 3-vector stored as (3, 2) -> dd."""
    s = mul(ld(D, 0), ld(D, 0))
    s = add(s, mul(ld(D, 1), ld(D, 1)))
    s = add(s, mul(ld(D, 2), ld(D, 2)))
    return sqrt(s)


@njit(cache=True)
def _interval(tgrid, n, te_hi):
    """Grid interval k (0 <= k <= N-2) holding te, searching down from row n."""
    N = tgrid.shape[0]
    k = min(n, N - 2)
    while k > 0 and tgrid[k] > te_hi:
        k -= 1
    while k < N - 2 and tgrid[k + 1] <= te_hi:
        k += 1
    return k


@njit(cache=True)
def _emitter_state(t_nodes, tgrid, n, te, Re, Ve, Ae, link, z, out_r, out_v):
    """Hermite (quintic) dd position / velocity of the emitter of ``link`` at dd time te."""
    k = _interval(tgrid, n, te[0] + te[1])
    t0 = ld(t_nodes, k)
    h = sub(ld(t_nodes, k + 1), t0)
    s = div(sub(te, t0), h)
    hermite_eval(z, Re[k:k + 2, link], Ve[k:k + 2, link], Ae[k:k + 2, link], h, s, out_r, out_v)


@njit(cache=True)
def _emission(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, link, z, rr, out_r, out_v, D):
    """The emitter of ``link`` at t - tau (Hermite; into out_r, out_v) and the
    dd vector D = r_e(t - tau) - r_r(t) (into D); returns (t - tau, |D|), dd."""
    te = sub(t, tau)
    _emitter_state(t_nodes, tgrid, n, te, Re, Ve, Ae, link, z, out_r, out_v)
    for q in range(3):
        st(D, sub(ld(out_r, q), ld(rr, q)), q)
    return te, _norm_dd(D)


@njit(cache=True)
def _solve(t_nodes, Rr, Re, Ve, Ae, c, shap_k, tol, max_iter,
           tau_out, re_out, ve_out, resid_out, shap_out, iters_out):
    """Newton solution of c tau = |r_e(t - tau) - r_r(t)| (+ Shapiro) for every row and link.

    t_nodes (N, 2) dd [s]; Rr, Re, Ve (N, L, 3, 2) dd [m, m, m/s]; Ae (N, L, 3)
    [m/s^2]; c [m/s]; shap_k = 2 GM / c^3 [s] (0: no Shapiro term); tol [s].
    Outputs: tau_out (N, L, 2) dd [s]; re_out (N, L, 3, 2) dd [m]; ve_out
    (N, L, 3) [m/s]; resid_out, shap_out (N, L) [s]; iters_out (N, L).
    Returns the number of (row, link) pairs that did not converge."""
    N = t_nodes.shape[0]
    L = Rr.shape[1]
    z = np.array([0.0, 1.0])
    tgrid = t_nodes[:, 0] + t_nodes[:, 1]
    D = np.empty((3, 2))
    out_r = np.empty((3, 2))
    out_v = np.empty((3, 2))
    t_first = ld(t_nodes, 0)
    failed = 0
    for n in range(N):
        t = ld(t_nodes, n)
        for link in range(L):
            rr = Rr[n, link]
            rr_norm = np.sqrt(rr[0, 0] ** 2 + rr[1, 0] ** 2 + rr[2, 0] ** 2)
            for q in range(3):
                st(D, sub(ld(Re, n, link, q), ld(rr, q)), q)
            tau = div(_norm_dd(D), c)
            shap = 0.0
            it = 0
            converged = False
            while it < max_iter:
                it += 1
                te, dist = _emission(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, link, z, rr, out_r, out_v, D)
                dv = 0.0
                for q in range(3):
                    dv += D[q, 0] * out_v[q, 0]
                if shap_k != 0.0:
                    re_norm = np.sqrt(out_r[0, 0] ** 2 + out_r[1, 0] ** 2 + out_r[2, 0] ** 2)
                    sr = re_norm + rr_norm
                    shap = shap_k * np.log((sr + dist[0]) / (sr - dist[0]))
                f = sub(sub(tau, div(dist, c)), shap)
                step = (f[0] + f[1]) / (1.0 + dv / (dist[0] * c))
                tau = sub(tau, step)
                if abs(step) < tol:
                    converged = True
                    break
            if not converged:
                failed += 1
            # emitter state and residual at the returned tau
            te, dist = _emission(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, link, z, rr, out_r, out_v, D)
            res = sub(sub(tau, div(dist, c)), shap)
            before = sub(te, t_first)
            if before[0] + before[1] < 0.0:
                tau_out[n, link, 0] = np.nan
                tau_out[n, link, 1] = np.nan
                for q in range(3):
                    re_out[n, link, q, 0] = np.nan
                    re_out[n, link, q, 1] = np.nan
                    ve_out[n, link, q] = np.nan
                resid_out[n, link] = np.nan
                shap_out[n, link] = np.nan
            else:
                st(tau_out, tau, n, link)
                for q in range(3):
                    re_out[n, link, q, 0] = out_r[q, 0]
                    re_out[n, link, q, 1] = out_r[q, 1]
                    ve_out[n, link, q] = out_v[q, 0] + out_v[q, 1]
                resid_out[n, link] = res[0] + res[1]
                shap_out[n, link] = shap
            iters_out[n, link] = it
    return failed


# ------------------------------------------------------------------ results

@dataclass(frozen=True)
class LightTravelTimes:
    """Light travel times of the six links on a trajectory's time grid.

    Link axis: LISA order 12, 23, 31, 13, 32, 21 (``Link.index``; link ab is
    received on satellite a, emitted by satellite b).  Times are TT seconds
    since the epoch; vectors GCRS [m, m/s]; dd quantities are ``(hi, lo)``
    tuples of float64 arrays.  Rows whose emission time precedes the first
    grid time are NaN.

    Attributes
    ----------
    t : (hi, lo) of (N,)
        Reception times (the grid) [s, TT].
    tau : (hi, lo) of (N, 6)
        Light travel time [s] (coordinate time, GCRS), dd.
    range : (hi, lo) of (N, 6)
        Light-path range c * tau [m], dd (c = 299792458 m/s exactly).
    r_receive : (hi, lo) of (N, 6, 3)
        Receiving body at t [m], GCRS, dd (the grid values).
    v_receive : (N, 6, 3)
        Receiving body's velocity at t [m/s], GCRS, float64.
    r_emit : (hi, lo) of (N, 6, 3)
        Emitting body at t - tau [m], GCRS, dd (Hermite dense output).
    v_emit : (N, 6, 3)
        Emitting body's velocity at t - tau [m/s], GCRS, float64.
    residual : (N, 6)
        tau - |r_emit - r_receive| / c - shapiro at the returned tau [s].
    shapiro : (N, 6)
        Shapiro delay of the Earth included in tau [s] (zeros if off).
    iterations : (N, 6) int
        Newton iterations used.
    source : str
        ``"tm"`` (test mass to test mass) or ``"sat"`` (satellite centres).
    note : str
        What the bodies are (and why, for a fallback).
    shapiro_k : float
        2 GM / c^3 [s] of the Shapiro term, 0.0 when it is off.
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

    def select(self, rows) -> "LightTravelTimes":
        """The same light travel times at the rows ``rows`` only (a slice,
        an index array or a boolean mask along the time axis)."""
        pick = lambda x: (x[0][rows], x[1][rows]) if isinstance(x, tuple) else x[rows]  # noqa: E731
        return replace(self, t=pick(self.t), tau=pick(self.tau), range=pick(self.range),
                       r_receive=pick(self.r_receive), v_receive=pick(self.v_receive), r_emit=pick(self.r_emit),
                       v_emit=pick(self.v_emit), residual=pick(self.residual), shapiro=pick(self.shapiro),
                       iterations=pick(self.iterations))

    @property
    def tau_f64(self) -> np.ndarray:
        """tau as float64 (N, 6) [s] (hi + lo; ~1e-16 relative)."""
        return self.tau[0] + self.tau[1]

    @property
    def unit_vectors(self) -> np.ndarray:
        """(N, 6, 3) unit vectors from the emitter at t - tau to the receiver at t
        (the photon's direction of propagation, as in LISA orbit files), GCRS;
        the difference is formed from the dd positions."""
        d = (self.r_receive[0] - self.r_emit[0]) + (self.r_receive[1] - self.r_emit[1])
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    @property
    def tau_rate(self) -> np.ndarray:
        """d tau / dt (N, 6) [s/s]: differentiating c tau = |D| + c s (D = r_r(t) -
        r_e(t - tau), n = D / |D| = :attr:`unit_vectors`, s the Shapiro delay)
        gives (n . (v_r - v_e) + c ds/dt) / (c - n . v_e); ds/dt (< 1e-17 s/s
        for TianQin) is included when the Shapiro delay is, with the geometric
        rate inserted into it."""
        n = self.unit_vectors
        nve = np.einsum("...k,...k->...", n, self.v_emit)
        nvr = np.einsum("...k,...k->...", n, self.v_receive)
        rate = (nvr - nve) / (C_LIGHT - nve)
        if self.shapiro_k == 0.0:
            return rate
        re = self.r_emit[0] + self.r_emit[1]
        rr = self.r_receive[0] + self.r_receive[1]
        a_e, a_r = np.linalg.norm(re, axis=-1), np.linalg.norm(rr, axis=-1)
        A = a_e + a_r
        L = C_LIGHT * (self.tau_f64 - self.shapiro)
        A_dot = (np.einsum("...k,...k->...", re, self.v_emit) / a_e * (1.0 - rate)
                 + np.einsum("...k,...k->...", rr, self.v_receive) / a_r)
        L_dot = C_LIGHT * rate
        s_dot = self.shapiro_k * ((A_dot + L_dot) / (A + L) - (A_dot - L_dot) / (A - L))
        return (nvr - nve + C_LIGHT * s_dot) / (C_LIGHT - nve)


def light_travel_times(t, r, v, a, *, shapiro: bool = False, gm: float | None = None, tol: float = 1e-24,
                       max_iter: int = 10, note: str | None = None) -> LightTravelTimes:
    """Solve the light-travel-time equation of the six links on the grid ``t``.

    Parameters
    ----------
    t : dd (N,)
        Grid times [s, TT since the epoch], strictly increasing (any spacing):
        a (hi, lo) tuple, an (N, 2) array or plain float64 (N,).
    r, v : dd (N, 3, 2, 3) or (N, 3, 3)
        Positions [m] and velocities [m/s], GCRS, of the test masses [time,
        satellite, MOSA, xyz] or of the satellite centres [time, satellite,
        xyz] on the grid (dd: (hi, lo) tuple, trailing axis 2, or float64).
    a : float64, same shape as r
        Total accelerations [m/s^2], GCRS, on the grid (for TMs: gravity +
        self-gravity + suspension; for satellite centres: gravity + drag-free
        control, if any).
    shapiro : bool
        Include the Earth's Shapiro delay (default False, as in the paper).
    gm : float
        GM of the Earth for the Shapiro delay [m^3/s^2] (default
        :data:`tqdyn.astro.constants.GM_EARTH_EGM2008`).
    tol : float
        Convergence threshold on the Newton correction [s].
    max_iter : int
        Maximum number of Newton iterations; RuntimeError if not converged.
    note : str, optional
        Text for the result's ``note`` (default: describes the bodies).

    Returns
    -------
    LightTravelTimes
        tau (N, 6) dd [s] and range c tau (N, 6) dd [m] in LISA link order,
        with emitter states and residuals; rows whose emission time precedes
        t[0] are NaN.
    """
    th, tl = _check_times(t)
    N = th.size
    rh, rl = _dd_input(r, "r")
    layout = _layout_of(rh.shape, "r")
    vh, vl = _dd_input(v, "v")
    if vh.shape != rh.shape:
        raise ValueError(f"v: shape {vh.shape} does not match r {rh.shape}")
    ah, al = _dd_input(a, "a")
    if ah.shape != rh.shape:
        raise ValueError(f"a: shape {ah.shape} does not match r {rh.shape}")
    acc = ah + al
    if rh.shape[0] != N:
        raise ValueError(f"r: {rh.shape[0]} rows but t has {N}")
    for name, arr in (("r", rh), ("r lo", rl), ("v", vh), ("v lo", vl), ("a", acc)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name}: contains NaN or infinite values")
    if not isinstance(max_iter, (int, np.integer)) or isinstance(max_iter, bool) or max_iter < 1:
        raise ValueError(f"max_iter = {max_iter!r}; allowed: an integer >= 1")
    if not (isinstance(tol, (int, float)) and np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol = {tol!r} s; allowed: a positive finite number of seconds")
    gm_v = _default_gm() if gm is None else float(gm)
    if not (np.isfinite(gm_v) and gm_v > 0):
        raise ValueError(f"gm = {gm!r} m^3/s^2; allowed: a positive finite number")

    def per_link(hi, lo):
        rec_h, emit_h = link_bodies(hi, layout)
        rec_l, emit_l = link_bodies(lo, layout)
        return np.stack([rec_h, rec_l], -1), np.stack([emit_h, emit_l], -1)

    Rr, Re = per_link(rh, rl)
    Vr, Ve = per_link(vh, vl)
    _, Ae = link_bodies(acc, layout)
    t_nodes = np.ascontiguousarray(np.stack([th, tl], -1))
    tau = np.empty((N, 6, 2))
    r_emit = np.empty((N, 6, 3, 2))
    v_emit = np.empty((N, 6, 3))
    resid = np.empty((N, 6))
    shap = np.empty((N, 6))
    iters = np.empty((N, 6), dtype=np.int64)
    shap_k = 2.0 * gm_v / C_LIGHT ** 3 if shapiro else 0.0
    failed = _solve(t_nodes, np.ascontiguousarray(Rr), np.ascontiguousarray(Re), np.ascontiguousarray(Ve),
                    np.ascontiguousarray(Ae), C_LIGHT, shap_k, float(tol), int(max_iter),
                    tau, r_emit, v_emit, resid, shap, iters)
    if failed:
        raise RuntimeError(f"light travel time: {failed} (row, link) pairs did not converge to tol = {tol} s "
                           f"in max_iter = {max_iter} Newton iterations")
    tau_h, tau_l = tau[..., 0], tau[..., 1]
    p, e = np_two_prod(tau_h, C_LIGHT)
    rng = np_two_sum(p, e + tau_l * C_LIGHT)
    if note is None:
        note = ("test mass to test mass: receiver = TM of satellite a facing b, emitter = TM of satellite b "
                "facing a" if layout == "tm" else "satellite centre of mass to satellite centre of mass")
    return LightTravelTimes(
        t=(th, tl), tau=(tau_h, tau_l), range=rng,
        r_receive=(Rr[..., 0], Rr[..., 1]), v_receive=Vr[..., 0] + Vr[..., 1],
        r_emit=(r_emit[..., 0], r_emit[..., 1]), v_emit=v_emit,
        residual=resid, shapiro=shap,
        iterations=iters, source=layout, note=note, shapiro_k=shap_k)


def light_travel_times_of(trajectory, **kwargs) -> LightTravelTimes:
    """:func:`light_travel_times` for a trajectory object.

    ``trajectory`` is duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`
    (``name in trajectory``, ``trajectory.dd(name)`` -> (hi, lo),
    ``trajectory[name]`` -> float64).  With the test-mass fields ``tm/r``,
    ``tm/v``, ``tm/a`` the links run TM to TM (``source = "tm"``).  Without
    any ``tm/*`` state (pure-gravity runs) the satellite centres are used:
    ``sat/r``, ``sat/v`` and ``sat/a_gravity`` (+ ``sat/a_dragfree`` if
    present), ``source = "sat"``, and ``note`` says so.  A file with only
    some of the TM state fields raises ValueError.  Needs 3 satellites.
    ``kwargs`` go to :func:`light_travel_times`.
    """
    n_sat = getattr(trajectory, "n_sat", 3)
    if n_sat != 3:
        raise ValueError(f"trajectory: n_sat = {n_sat}; light paths need the 3 satellites of a constellation")
    t = trajectory.dd("t")
    tm_fields = ("tm/r", "tm/v", "tm/a")
    present = [f for f in tm_fields if f in trajectory]
    if len(present) == 3:
        return light_travel_times(t, trajectory.dd("tm/r"), trajectory.dd("tm/v"), trajectory["tm/a"], **kwargs)
    if present:
        missing = [f for f in tm_fields if f not in trajectory]
        raise ValueError(f"trajectory: has {', '.join(present)} but not {', '.join(missing)}; test-mass light "
                         "paths need tm/r, tm/v and tm/a (or none of them, for satellite centres)")
    for f in ("sat/r", "sat/v", "sat/a_gravity"):
        if f not in trajectory:
            raise ValueError(f"trajectory: has no field {f!r} (needed for light paths between satellite centres)")
    acc = np.asarray(trajectory["sat/a_gravity"], np.float64)
    parts = "sat/a_gravity"
    if "sat/a_dragfree" in trajectory:
        acc = acc + np.asarray(trajectory["sat/a_dragfree"], np.float64)
        parts += " + sat/a_dragfree"
    kwargs.setdefault("note", "no test-mass fields (tm/r, tm/v, tm/a) in the trajectory: links between the "
                              f"satellites' centres of mass (sat/r, sat/v, {parts})")
    return light_travel_times(t, trajectory.dd("sat/r"), trajectory.dd("sat/v"), acc, **kwargs)
