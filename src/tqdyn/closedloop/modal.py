"""Loop-at-a-time gains of many closed loops on a dense grid from each loop's eigendecomposition, the grid points
that decide a margin evaluated exactly (docs/closed-loop.md).

The margins (:func:`tqdyn.closedloop.budget.grid_margins`) read the loop gains L_k = -T_kk / (1 + T_kk) on a
dense grid only through the signs of arg(-L) and log|L| at every point, the sign of Re L where arg(-L) changes
sign, and the values at the two points around each crossover.  Each closed loop's state space (without the
states no loop controls and nothing reads: the spacecraft's displacement from its orbit, ``plant_u``,
``plant_du``) is diagonalised once, A = V diag(lambda) V^-1 (LAPACK geev), and

    T_kk(s) = D_kk + sum_i (C V)_ki (V^-1 B)_ik / (s - lambda_i)

costs n_state multiply-adds per channel and frequency instead of a 20 x 20 solve.  Its absolute error is taken
as at most kappa eps cond_1(V) sum_i |(C V)_ki (V^-1 B)_ik| / |s - lambda_i| with kappa = 10 (measured on the
TianQin and LISA loops: below the bound with kappa = 1 by a factor 25), that of L relative to |L| as that over
|T| |1 + T|.  Every grid point where the bound could flip one of the signs, and the points on both sides of
every crossover found and of every other sign change of arg(-L), are then evaluated by the exact path
(``exact``, e.g. the 20 x 20 solves of :func:`tqdyn.closedloop.frequency.loop_gains`), repeated until every
crossover's neighbours are exact: the margins are those of the exact gains on the whole grid.  A loop whose
eigenvectors are ill-conditioned (cond(V) > :data:`COND_MAX`) is evaluated exactly everywhere.  Units: Hz;
s = i 2 pi f [rad/s].

The noise ASDs are not evaluated this way: from the noise inputs to the outputs the modal sum cancels far more
(measured on the TianQin and LISA loops: it differs from the exact solves by up to the order of an output's
total), so that nearly every point would need the exact solve; it is also no cheaper there (46 x 58 transfers
per mode and frequency against the 20 x 20 solves of :func:`tqdyn.closedloop.frequency.noise_asd`).  A complex
Schur form (unitary, so without that conditioning) works on the whole 74-state loop where the exact path solves
in 20 coordinates after eliminating the controllers: measured 2-2.5 times slower, and the spacecraft's free
drift (poles near 0) leaks through it into the other outputs (up to 8e-6 of the MOSA torques' total against
5e-8 for the exact path, both against a 40-digit evaluation at 1e-5 Hz).
"""

from __future__ import annotations

import math

import numpy as np

from .frequency import rows_product

__all__ = ["COND_MAX", "KAPPA", "loop_gains", "transfer"]

#: Safety factor of the modal evaluation's error bound (module docstring).
KAPPA = 10.0
#: Largest condition number of the eigenvectors for which the modal evaluation is used.
COND_MAX = 1e10
#: Rounds of exact evaluations at the crossovers (each round adds the neighbours of crossovers it moved).
_ROUNDS = 4


def _kept_states(sys, outputs) -> list[int]:
    """The states of ``sys`` that the loop gains read: all but the spacecraft's displacement from its orbit when no
    other state's derivative and no output of ``outputs`` reads it (else all)."""
    drop = [k for k, s in enumerate(sys.state_labels) if s.startswith("plant_u[") or s.startswith("plant_du[")]
    keep = [k for k in range(sys.nstates) if k not in drop]
    if drop and (np.any(sys.A[np.ix_(keep, drop)]) or np.any(sys.C[np.ix_(outputs, drop)])):
        return list(range(sys.nstates))
    return keep


def _crossover_points(L) -> np.ndarray:
    """(n, F) bool: the grid points on either side of a crossover of any channel of ``L`` (n, nc, F) as
    :func:`tqdyn.closedloop.budget.grid_margins` finds them (a sign change of log|L|, or of arg(-L) with Re L <= 0
    at its left end), here with every sign change of arg(-L), whatever the sign of Re L."""
    with np.errstate(divide="ignore"):
        lmag = np.log(np.abs(L))
    step = (np.diff(np.sign(np.angle(-L)), axis=-1) != 0) | (np.diff(np.sign(lmag), axis=-1) != 0)
    step = np.any(step, axis=1)
    out = np.zeros(L.shape[:1] + L.shape[2:], dtype=bool)
    out[:, :-1] |= step
    out[:, 1:] |= step
    return out


def _uncertain(L, rel) -> np.ndarray:
    """(n, F) bool: grid points where a relative error ``rel`` of ``L`` (n, nc, F) could flip the sign of log|L|
    or of arg(-L) (at 0 or +-pi) of a channel.  (The sign of Re L matters only at a sign change of arg(-L), whose
    points :func:`_crossover_points` makes exact.)"""
    with np.errstate(divide="ignore", invalid="ignore"):
        ang = np.abs(np.angle(-L))
        room = np.minimum(np.abs(np.log(np.abs(L))), np.minimum(ang, math.pi - ang))
        bad = ~(rel < room)                                       # nan (T = -1, L = 0 or inf) counts as uncertain
    return np.any(bad, axis=1)


def transfer(systems, channels, f) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The modal T_kk (n, nc, F) of the closed loops ``systems`` (python-control state spaces with the same states,
    inputs ``d_<channel>`` and outputs ``c_<channel>``) for the ``channels`` at ``f`` (F,) [Hz], the bound of its
    absolute error (n, nc, F) (module docstring) and whether each loop's eigenvectors allow it (n,) bool (where
    not, T and the bound are meaningless)."""
    s = 2j * math.pi * np.asarray(f, dtype=np.float64)
    sys0 = systems[0]
    ii = [sys0.input_labels.index(f"d_{ch}") for ch in channels]
    oi = [sys0.output_labels.index(f"c_{ch}") for ch in channels]
    keep = _kept_states(sys0, oi)
    if any(tuple(x.state_labels) != tuple(sys0.state_labels) or _kept_states(x, oi) != keep for x in systems[1:]):
        raise ValueError("closed loops: the loops of one evaluation differ in their states")
    A = np.array([np.asarray(x.A)[np.ix_(keep, keep)] for x in systems])
    Bd = np.array([np.asarray(x.B)[np.ix_(keep, ii)] for x in systems]).astype(complex)
    Cc = np.array([np.asarray(x.C)[np.ix_(oi, keep)] for x in systems])
    Dd = np.array([np.asarray(x.D)[oi, ii] for x in systems])                        # (n, nc): D_kk
    n = len(systems)
    lam, V = np.linalg.eig(A)
    with np.errstate(all="ignore"):
        try:
            cond = np.linalg.cond(V, 1)                                           # 1-norm: by LU, no SVD
        except np.linalg.LinAlgError:
            cond = np.full(n, np.inf)
    ok = np.isfinite(cond) & (cond <= COND_MAX)
    V = np.where(ok[:, None, None], V, np.eye(len(keep)))
    rT = np.swapaxes(rows_product(Cc, V), 1, 2) * np.linalg.solve(V, Bd)            # (n, n_state, nc)
    gT = 1.0 / (s[None, :, None] - lam[:, None, :])                                 # (n, F, n_state)
    T = np.swapaxes(rows_product(gT, rT), 1, 2) + Dd[:, :, None]
    err = np.swapaxes(rows_product(np.abs(gT), np.abs(rT)), 1, 2)
    return T, KAPPA * np.finfo(np.float64).eps * np.where(ok, cond, 0.0)[:, None, None] * err, ok


def loop_gains(systems, channels, f, exact) -> np.ndarray:
    """Loop-at-a-time gains L (n, nc, F) of the closed loops ``systems`` (python-control state spaces with inputs
    ``d_<channel>`` and outputs ``c_<channel>``, :class:`~tqdyn.closedloop.loop.ClosedLoop`) for the ``channels``
    at ``f`` (F,) [Hz] (module docstring; loops with other states, e.g. controllers of other orders, apart): modal
    (:func:`transfer`) where its error bound leaves the margins unchanged, else ``exact(positions, f_sub)`` (the
    gains (len(positions), nc, len(f_sub)) of the loops ``systems[positions]``)."""
    f = np.asarray(f, dtype=np.float64)
    kinds = {}
    for i, x in enumerate(systems):
        kinds.setdefault(tuple(x.state_labels), []).append(i)
    if len(kinds) > 1:                                   # e.g. controllers of other orders: each kind apart
        L = np.empty((len(systems), len(channels), len(f)), dtype=complex)
        for pos in kinds.values():
            pos = np.array(pos)
            L[pos] = loop_gains([systems[i] for i in pos], channels, f, lambda q, ff, pos=pos: exact(pos[q], ff))
        return L
    T, bound, ok = transfer(systems, channels, f)
    with np.errstate(divide="ignore", invalid="ignore"):
        L = -T / (1.0 + T)
        rel = bound / (np.abs(T) * np.abs(1.0 + T))
    done = np.zeros((len(systems), len(f)), dtype=bool)
    need = _uncertain(L, rel)
    need[~ok] = True
    for _ in range(_ROUNDS):
        need = (need | _crossover_points(L)) & ~done
        rows = np.flatnonzero(np.any(need, axis=1))
        if not len(rows):
            break
        for i in rows:
            cols = np.flatnonzero(need[i])
            L[i][:, cols] = exact(np.array([i]), f[cols])[0]
        done |= need
        need[:] = False
    return L
