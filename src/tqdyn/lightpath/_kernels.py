"""Compiled (numba) kernels of the light-time solver, in double-double.

:func:`_solve` is the solver of the geocentric links (GCRS, the coordinate
origin at rest, optionally the Earth's Shapiro delay), unchanged since
version 0.1; :func:`_solve_bcrs` the one of the heliocentric links
(coordinates centred on the Sun, which moves relative to the solar-system
barycentre; the Sun's and other bodies' Shapiro delays).  Both are driven by
:func:`tqdyn.lightpath.light_time.light_travel_times`, which documents the
equations, units and shapes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..numerics.dd import add, div, ld, mul, sqrt, st, sub
from ..numerics.hermite import hermite_eval

__all__: list[str] = []


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


@njit(cache=True)
def _bcrs_geometry(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, Vo, Ao, link, z, rr, rr_norm, c, shap_k, defl_k, defl_p,
                   out_r, out_v, D, ds, vb, parts):
    """The light path of ``link`` at reception row n for the trial light time tau (dd).

    Fills out_r, out_v (the emitter's Sun-centred Hermite state at t - tau),
    ds (the origin's displacement O(t) - O(t - tau)), D (the barycentric
    separation, dd), vb (the emitter's barycentric velocity, float64) and
    parts (the Shapiro delays).  Returns (te, dist, dv, shap, f): the dd
    emission time and |D|, D . vb, the total Shapiro delay and the dd
    residual f = tau - |D| / c - shap."""
    K = defl_k.shape[0]
    tf = tau[0] + tau[1]
    for q in range(3):
        ds[q] = Vo[n, q] * tf - 0.5 * Ao[n, q] * tf * tf
    te = sub(t, tau)
    _emitter_state(t_nodes, tgrid, n, te, Re, Ve, Ae, link, z, out_r, out_v)
    for q in range(3):
        st(D, sub(sub(ld(out_r, q), ld(rr, q)), ds[q]), q)
    dist = _norm_dd(D)
    dv = 0.0
    for q in range(3):
        vb[q] = out_v[q, 0] + Vo[n, q] - Ao[n, q] * tf
        dv += D[q, 0] * vb[q]
    shap = 0.0
    parts[0] = 0.0
    if shap_k != 0.0:
        re_norm = np.sqrt(out_r[0, 0] ** 2 + out_r[1, 0] ** 2 + out_r[2, 0] ** 2)
        sr = re_norm + rr_norm
        parts[0] = shap_k * np.log((sr + dist[0]) / (sr - dist[0]))
        shap += parts[0]
    for k in range(K):
        a2 = 0.0
        b2 = 0.0
        for q in range(3):
            a2 += (out_r[q, 0] - ds[q] - defl_p[n, k, q]) ** 2
            b2 += (rr[q, 0] - defl_p[n, k, q]) ** 2
        sr = np.sqrt(a2) + np.sqrt(b2)
        parts[k + 1] = defl_k[k] * np.log((sr + dist[0]) / (sr - dist[0]))
        shap += parts[k + 1]
    f = sub(sub(tau, div(dist, c)), shap)
    return te, dist, dv, shap, f


@njit(cache=True)
def _solve_bcrs(t_nodes, Rr, Re, Ve, Ae, Vo, Ao, c, shap_k, defl_k, defl_p, tol, max_iter,
                tau_out, re_out, ve_out, resid_out, shap_out, parts_out, iters_out):
    """Newton solution of the BCRS light-time equation in coordinates centred on a moving origin.

    Positions are relative to the origin O (the Sun), which moves relative to
    the barycentre with velocity Vo and acceleration Ao (N, 3) [m/s, m/s^2]
    at the grid times.  In the BCRS the photon covers the barycentric
    separation D = x_e(t - tau) - x_r(t) - dS with dS = O(t) - O(t - tau)
    = Vo tau - Ao tau^2 / 2 (Taylor series about the reception time; the
    next term, jerk tau^3 / 6, is ~1e-12 m for the Sun), and

        tau = |D| / c + s_O + sum_k s_k,
        s_O = shap_k ln((|x_e(t - tau)| + |x_r(t)| + |D|) / (... - |D|)),
        s_k = defl_k[k] ln((|x_e(t - tau) - dS - P_k| + |x_r(t) - P_k| + |D|) / (... - |D|)),

    P_k = defl_p[:, k] (N, K, 3) the deflectors' positions relative to O at
    the reception time t [m]; shap_k, defl_k (K,) the (1 + gamma) GM / c^3
    [s] of O and of the deflectors.  Newton's derivative uses the emitter's
    barycentric velocity v_e + Vo - Ao tau.  Outputs as :func:`_solve`; the
    emitter's position is r_e = x_e(t - tau) - dS (its BCRS position
    relative to O(t)), its velocity barycentric, the residual and Shapiro
    delays re-evaluated at the returned tau; parts_out (N, L, K + 1): s_O,
    then each s_k.  Returns the number of (row, link) pairs that did not
    converge."""
    N = t_nodes.shape[0]
    L = Rr.shape[1]
    K = defl_k.shape[0]
    z = np.array([0.0, 1.0])
    tgrid = t_nodes[:, 0] + t_nodes[:, 1]
    D = np.empty((3, 2))
    out_r = np.empty((3, 2))
    out_v = np.empty((3, 2))
    ds = np.empty(3)
    vb = np.empty(3)
    parts = np.zeros(K + 1)
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
            it = 0
            converged = False
            while it < max_iter:
                it += 1
                te, dist, dv, shap, f = _bcrs_geometry(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, Vo, Ao, link, z, rr,
                                                       rr_norm, c, shap_k, defl_k, defl_p, out_r, out_v, D, ds, vb,
                                                       parts)
                step = (f[0] + f[1]) / (1.0 + dv / (dist[0] * c))
                tau = sub(tau, step)
                if abs(step) < tol:
                    converged = True
                    break
            if not converged:
                failed += 1
            # the path, its Shapiro delays and the residual at the returned tau
            te, dist, dv, shap, f = _bcrs_geometry(t_nodes, tgrid, n, t, tau, Re, Ve, Ae, Vo, Ao, link, z, rr,
                                                   rr_norm, c, shap_k, defl_k, defl_p, out_r, out_v, D, ds, vb, parts)
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
                for k in range(K + 1):
                    parts_out[n, link, k] = np.nan
            else:
                st(tau_out, tau, n, link)
                for q in range(3):
                    rq = sub(ld(out_r, q), ds[q])
                    re_out[n, link, q, 0] = rq[0]
                    re_out[n, link, q, 1] = rq[1]
                    ve_out[n, link, q] = vb[q] + out_v[q, 1]
                resid_out[n, link] = f[0] + f[1]
                shap_out[n, link] = shap
                for k in range(K + 1):
                    parts_out[n, link, k] = parts[k]
            iters_out[n, link] = it
    return failed
