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
(~1e-31 s).  Cost: linear in rows x links, after a one-off compilation.

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

Heliocentric runs (``reference`` :data:`tqdyn.astro.reference.HELIOCENTRIC`:
Sun-centred TDB-compatible BCRS, t in TDB seconds).  The light-time
equation holds in the barycentric coordinates, in which the Sun -- the
origin of the trajectory's coordinates -- moves at ~10-15 m/s: over the
8.3 s of a 2.5e9 m arm that is ~100 m, i.e. up to ~3e-7 s in tau (2.3e-7 s
measured for 12.4 m/s), more than the Sun's Shapiro delay.  So the solver (``_kernels._solve_bcrs``)
subtracts the Sun's displacement dS = S(t) - S(t - tau) = V tau - A tau^2/2
from the Sun-centred separation (V, A: the Sun's barycentric velocity and
acceleration at the reception time, ``origin_velocity`` /
``origin_acceleration``; the acceleration term is ~2e-14 s, the next one
~3e-13 m, 1e-21 s) and solves

    c (tau - s) = |x_e(t - tau) - dS - x_r(t)|,

s = sum of Shapiro delays (1 + gamma) GM/c^3 ln((r_e + r_r + R)/(r_e + r_r - R))
with R the barycentric separation and r_e, r_r the distances of emitter and
receiver from the deflecting body:

* the Sun, on by default (``shapiro``): r_e = |x_e(t - tau)|, r_r = |x_r(t)|
  (the Sun's positions at the emission and the reception times,
  exactly); ~1.6e-7 s (49 m) on LISA's arms at 1 au
  (tests/test_lightpath_heliocentric.py);
* optionally the Earth, the Moon and the planets (``deflectors``; from
  :func:`light_travel_times_of` ``shapiro_bodies``), their positions taken
  at the reception time t.  A moving deflector's position ought to be taken
  somewhere between emission and reception (e.g. at closest approach);
  moving it by its motion during tau, delta = v_B tau (250 m for the
  Earth, 110 m for Jupiter), changes r_e + r_r by < 2 delta and the delay
  by < (1 + gamma) GM/c^3 * 2R / (r_e + r_r)^2 * 2 delta: ~1e-20 s for the
  Earth, ~1e-17 s for Jupiter (all bodies at t - tau instead of t:
  7e-18 s measured), far below the 1e-12 s accuracy aimed at;
  so are the velocity-dependent corrections (~v_B/c relative: ~7e-15 s for
  the Sun's 13 m/s, ~1e-15 s for Jupiter) and the Sun's 2PN term
  (~(GM_S)^2 / (c^5 r) x R/r ~ 1e-15 s), not modelled.
  Sizes on LISA's arms: Jupiter ~3e-11 s, Saturn ~5e-12 s, the Earth ~1e-12 s
  at 5e10 m, Venus 1e-13..1e-12 s, the Moon ~1e-14 s (measured in the tests).

Accuracy (tests/test_lightpath_heliocentric.py): 2.5e-21 s against an mpmath
fixed-point solution on exact Kepler orbits around a moving Sun; 2.9e-16 s
on a 10-day LISA-like run at 3600 s against an mpmath iteration on
Lagrange-interpolated positions with jplephem's Sun (limited by jplephem's
float64 positions of the Sun, ~1e-7 m).

Outputs of a heliocentric solution are BCRS vectors relative to the Sun at
the reception time (:class:`~tqdyn.lightpath.results.LightTravelTimes`,
``frame = "BCRS"``), tau in TDB seconds (``time_scale = "TDB"``;
:meth:`~tqdyn.lightpath.results.LightTravelTimes.to_tcb` converts to TCB).
Geocentric runs keep exactly the solver and the results of version 0.1
(the same compiled kernel ``_kernels._solve``, bit for bit).

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

import numpy as np

from .._choices import unknown
from ..astro.constants import C_LIGHT
from ..astro.reference import GEOCENTRIC
from ..constellation.indices import LINK_EMITTER, LINK_EMITTER_MOSA, LINK_RECEIVER, LINK_RECEIVER_MOSA
from ..numerics.dd import np_dd_add, np_two_prod, np_two_sum
from ._kernels import _solve, _solve_bcrs
from . import heliocentric as _helio
from .results import LightTravelTimes
from .shapiro import _default_gm

__all__ = [
    "BODY_LAYOUTS",
    "LightTravelTimes",
    "light_travel_times",
    "light_travel_times_of",
    "link_bodies",
    "satellite_states",
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
    raise ValueError(unknown("layout", layout, BODY_LAYOUTS))


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


def _origin_motion(x, name: str, N: int) -> np.ndarray:
    arr = np.ascontiguousarray(np.broadcast_to(np.asarray(x, np.float64), (N, 3)))
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: contains NaN or infinite values")
    return arr


def _deflector_arrays(deflectors, N: int, gamma: float) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """(names, (K,) (1 + gamma) GM / c^3 [s], (N, K, 3) positions [m]) of (name, gm, positions) triples."""
    names, ks, pos = [], [], []
    for item in deflectors:
        try:
            name, gm, p = item
        except (TypeError, ValueError):
            raise ValueError(f"deflectors: {item!r} is not a (name, gm, positions) triple") from None
        gm = float(gm)
        p = np.asarray(p, np.float64)
        if not (np.isfinite(gm) and gm > 0):
            raise ValueError(f"deflectors: gm of {name!r} = {gm!r} m^3/s^2; allowed: a positive finite number")
        if p.shape != (N, 3) or not np.all(np.isfinite(p)):
            raise ValueError(f"deflectors: positions of {name!r} must be finite, shape ({N}, 3), got {p.shape}")
        names.append(str(name))
        ks.append((1.0 + gamma) * gm / C_LIGHT ** 3)
        pos.append(p)
    P = np.ascontiguousarray(np.stack(pos, 1)) if pos else np.zeros((N, 0, 3))
    return tuple(names), np.array(ks, dtype=np.float64), P


def light_travel_times(t, r, v, a, *, shapiro: bool | None = None, gm: float | None = None, tol: float = 1e-24,
                       max_iter: int = 10, note: str | None = None, reference=None, origin_velocity=None,
                       origin_acceleration=None, deflectors=(), gamma: float = 1.0) -> LightTravelTimes:
    """Solve the light-travel-time equation of the six links on the grid ``t``.

    Parameters
    ----------
    t : dd (N,)
        Grid times [s since the epoch, TT (geocentric) or TDB (heliocentric)],
        strictly increasing (any spacing): a (hi, lo) tuple, an (N, 2) array
        or plain float64 (N,).
    r, v : dd (N, 3, 2, 3) or (N, 3, 3)
        Positions [m] and velocities [m/s] relative to the central body (GCRS
        geocentric, or Sun-centred BCRS) of the test masses [time,
        satellite, MOSA, xyz] or of the satellite centres [time, satellite,
        xyz] on the grid (dd: (hi, lo) tuple, trailing axis 2, or float64).
    a : float64, same shape as r
        Total accelerations [m/s^2] on the grid, same frame (for TMs:
        gravity + self-gravity + suspension; for satellite centres: gravity
        + drag-free control, if any).
    shapiro : bool or None
        Include the central body's Shapiro delay (the Earth for geocentric,
        the Sun for heliocentric); None (default): per reference system,
        off for geocentric (as in the paper), on for heliocentric.
    gm : float
        GM of the central body for its Shapiro delay [m^3/s^2] (default:
        :data:`tqdyn.astro.constants.GM_EARTH_EGM2008` for geocentric,
        the Sun's DE430 value of :func:`tqdyn.astro.ephemeris.planetary_gm`
        for heliocentric).
    tol : float
        Convergence threshold on the Newton correction [s].
    max_iter : int
        Maximum number of Newton iterations; RuntimeError if not converged.
    note : str, optional
        Text for the result's ``note`` (default: describes the bodies).
    reference : tqdyn.astro.reference.ReferenceSystem, optional
        The coordinates of t, r, v, a: geocentric (default,
        :data:`~tqdyn.astro.reference.GEOCENTRIC`, or any with central body
        "earth": exactly the solver of version 0.1) or heliocentric
        (central body "sun": the BCRS solver, see the module docstring).
    origin_velocity, origin_acceleration : (N, 3) or (3,) float64, heliocentric only
        The Sun's barycentric velocity [m/s] (required) and acceleration
        [m/s^2] (default 0) at the grid times
        (:func:`tqdyn.lightpath.heliocentric.sun_barycentric_motion`); zeros
        for a Sun at rest.
    deflectors : sequence of (name, gm, positions), heliocentric only
        Further bodies whose Shapiro delays enter: GM [m^3/s^2] and
        positions (N, 3) [m] relative to the Sun at the grid (reception)
        times, BCRS.  Default none.
    gamma : float
        PPN parameter of every Shapiro term, (1 + gamma) GM/c^3 (default 1).

    Returns
    -------
    LightTravelTimes
        tau (N, 6) dd [s] and range c tau (N, 6) dd [m] in LISA link order,
        with emitter states and residuals; rows whose emission time precedes
        t[0] are NaN.  Heliocentric: ``frame = "BCRS"`` (vectors as
        :class:`~tqdyn.lightpath.results.LightTravelTimes` says),
        ``shapiro_parts`` per body.
    """
    ref = GEOCENTRIC if reference is None else reference
    helio = ref.central_body == "sun"
    if not helio and ref.central_body != "earth":
        raise ValueError(f"reference: central body {ref.central_body!r}; allowed: 'earth', 'sun'")
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
    if gm is None:
        gm_v = float(_helio.gm_of(("sun",))[0]) if helio else _default_gm()
    else:
        gm_v = float(gm)
    if not (np.isfinite(gm_v) and gm_v > 0):
        raise ValueError(f"gm = {gm!r} m^3/s^2; allowed: a positive finite number")
    gamma = float(gamma)
    if not (np.isfinite(gamma) and gamma > -1):
        raise ValueError(f"gamma = {gamma!r}; allowed: a finite number > -1")
    if shapiro is None:
        shapiro = helio
    if not helio:
        if origin_velocity is not None or origin_acceleration is not None or len(deflectors):
            raise ValueError("origin_velocity, origin_acceleration and deflectors are for heliocentric (BCRS) "
                             "links; in the GCRS the other bodies act through tidal potentials only, and their "
                             "BCRS Shapiro delays do not apply")
    elif origin_velocity is None:
        raise ValueError("origin_velocity: required for heliocentric links (the Sun's barycentric velocity at the "
                         "grid times, tqdyn.lightpath.heliocentric.sun_barycentric_motion; zeros for a Sun at rest)")

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
    shap_k = (1.0 + gamma) * gm_v / C_LIGHT ** 3 if shapiro else 0.0
    central = ref.central_body
    args = (t_nodes, np.ascontiguousarray(Rr), np.ascontiguousarray(Re), np.ascontiguousarray(Ve),
            np.ascontiguousarray(Ae))
    if not helio:
        failed = _solve(*args, C_LIGHT, shap_k, float(tol), int(max_iter), tau, r_emit, v_emit, resid, shap, iters)
        parts = {central: shap} if shapiro else {}
        vo = ao = None
        v_recv = Vr[..., 0] + Vr[..., 1]
    else:
        vo = _origin_motion(origin_velocity, "origin_velocity", N)
        ao = _origin_motion(0.0 if origin_acceleration is None else origin_acceleration, "origin_acceleration", N)
        names, defl_k, defl_p = _deflector_arrays(deflectors, N, gamma)
        if central in names or len(set(names)) != len(names):
            raise ValueError(f"deflectors: {', '.join(names)}: each body once, not the central body {central!r}")
        part_arr = np.empty((N, 6, len(names) + 1))
        failed = _solve_bcrs(*args, vo, ao, C_LIGHT, shap_k, defl_k, defl_p, float(tol), int(max_iter),
                             tau, r_emit, v_emit, resid, shap, part_arr, iters)
        parts = {central: part_arr[..., 0]} if shapiro else {}
        parts.update({b: part_arr[..., k + 1] for k, b in enumerate(names)})
        v_recv = Vr[..., 0] + Vr[..., 1] + vo[:, None, :]
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
        r_receive=(Rr[..., 0], Rr[..., 1]), v_receive=v_recv,
        r_emit=(r_emit[..., 0], r_emit[..., 1]), v_emit=v_emit,
        residual=resid, shapiro=shap,
        iterations=iters, source=layout, note=note, shapiro_k=shap_k,
        frame="BCRS" if helio else "GCRS", time_scale=ref.time_scale, origin_velocity=vo,
        origin_acceleration=ao, shapiro_parts=parts, gamma=gamma)


def _trajectory_arrays(trajectory):
    """(t, r, v, a, kwargs) of the light paths of a trajectory (TM to TM, else satellite centres)."""
    n_sat = getattr(trajectory, "n_sat", 3)
    if n_sat != 3:
        raise ValueError(f"trajectory: n_sat = {n_sat}; light paths need the 3 satellites of a constellation")
    t = trajectory.dd("t")
    tm_fields = ("tm/r", "tm/v", "tm/a")
    present = [f for f in tm_fields if f in trajectory]
    if len(present) == 3:
        return t, trajectory.dd("tm/r"), trajectory.dd("tm/v"), trajectory["tm/a"], {}
    if present:
        missing = [f for f in tm_fields if f not in trajectory]
        raise ValueError(f"trajectory: has {', '.join(present)} but not {', '.join(missing)}; test-mass light "
                         "paths need tm/r, tm/v and tm/a (or none of them, for satellite centres)")
    for f in ("sat/r", "sat/v", "sat/a_gravity"):
        if f not in trajectory:
            raise ValueError(f"trajectory: has no field {f!r} (needed for light paths between satellite centres)")
    parts = "sat/a_gravity" + (" + sat/a_dragfree" if "sat/a_dragfree" in trajectory else "")
    note = ("no test-mass fields (tm/r, tm/v, tm/a) in the trajectory: links between the satellites' centres of "
            f"mass (sat/r, sat/v, {parts})")
    return (t, *satellite_states(trajectory), {"note": note})


def satellite_states(trajectory) -> tuple[tuple, tuple, np.ndarray]:
    """The satellites' centres of a trajectory (duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`):
    positions ``sat/r`` [m] and velocities ``sat/v`` [m/s] as dd (hi, lo) pairs, and the total acceleration
    ``sat/a_gravity`` (+ ``sat/a_dragfree`` when present) [m/s^2] float64, each (N, n_sat, 3), in the
    trajectory's frame."""
    acc = np.asarray(trajectory["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in trajectory:
        acc = acc + np.asarray(trajectory["sat/a_dragfree"], np.float64)
    return trajectory.dd("sat/r"), trajectory.dd("sat/v"), acc


def light_travel_times_of(trajectory, *, shapiro_bodies=None, ephemeris=None, **kwargs) -> LightTravelTimes:
    """:func:`light_travel_times` for a trajectory object.

    ``trajectory`` is duck-typed like :class:`tqdyn.formats.trajectory.Trajectory`
    (``name in trajectory``, ``trajectory.dd(name)`` -> (hi, lo),
    ``trajectory[name]`` -> float64; ``reference``, ``epoch`` and
    ``scenario_toml`` when heliocentric; an object without ``reference`` is
    geocentric).  With the test-mass fields ``tm/r``, ``tm/v``, ``tm/a`` the
    links run TM to TM (``source = "tm"``).  Without any ``tm/*`` state
    (pure-gravity runs) the satellite centres are used: ``sat/r``,
    ``sat/v`` and ``sat/a_gravity`` (+ ``sat/a_dragfree`` if present),
    ``source = "sat"``, and ``note`` says so.  A file with only some of the
    TM state fields raises ValueError.  Needs 3 satellites.

    Heliocentric trajectories (``trajectory.reference.central_body ==
    "sun"``): the Sun's barycentric motion is read from the run's
    ephemeris (``ephemeris``: an :class:`tqdyn.astro.ephemeris.Ephemeris`;
    default the scenario's ``forces.ephemeris``) at the grid's TDB dates,
    the Sun's Shapiro delay is on unless ``shapiro=False``, ``gm`` (if
    given) must be the Sun's (within 1e-3: the Earth's GM that a geocentric
    caller passes is refused), and ``shapiro_bodies`` adds the Shapiro
    delays of other bodies: None (default: none), ``"third_bodies"`` (the
    run's ``forces.third_bodies``), ``"all"`` (Earth, Moon, Mercury ..
    Neptune) or a list of names of
    :data:`tqdyn.astro.ephemeris.HELIOCENTRIC_BODIES`; their positions at
    the grid (reception) times, GMs the run's (``forces.gm_*``, default DE430).  Geocentric trajectories
    refuse ``shapiro_bodies`` (GCRS: tidal potentials only).  Other
    ``kwargs`` (``shapiro``, ``gm``, ``tol``, ``max_iter``, ``gamma``) go
    to :func:`light_travel_times`.
    """
    t, r, v, a, extra = _trajectory_arrays(trajectory)
    for k, val in extra.items():
        kwargs.setdefault(k, val)
    ref = getattr(trajectory, "reference", None) or GEOCENTRIC
    if ref.central_body != "sun":
        if _helio.resolve_bodies(shapiro_bodies, trajectory):
            raise ValueError(f"shapiro_bodies = {shapiro_bodies!r}: only for heliocentric trajectories; in the "
                             "GCRS the other bodies act through tidal potentials only (the Earth's Shapiro delay "
                             "is shapiro=True)")
        return light_travel_times(t, r, v, a, **kwargs)
    gm = kwargs.get("gm")
    gm_sun = float(_helio.gm_of(("sun",), trajectory)[0])  # the run's
    if gm is None:
        kwargs["gm"] = gm_sun
    else:
        if not abs(float(gm) / gm_sun - 1.0) < 1e-3:
            raise ValueError(f"gm = {gm!r} m^3/s^2: a heliocentric trajectory's Shapiro delay is the Sun's "
                             f"(GM ~ {gm_sun:.6e} m^3/s^2); pass gm=None for the default")
    eph = _helio.ephemeris_of(trajectory) if ephemeris is None else ephemeris
    epoch = trajectory.epoch
    _, vo, ao = _helio.sun_barycentric_motion(eph, epoch, t, ref)
    bodies = _helio.resolve_bodies(shapiro_bodies, trajectory)
    pos, _ = _helio.body_states(eph, epoch, t, bodies, ref, velocity=False)
    defl = [(b, g, pos[:, k]) for k, (b, g) in enumerate(zip(bodies, _helio.gm_of(bodies, trajectory)))]
    return light_travel_times(t, r, v, a, reference=ref, origin_velocity=vo, origin_acceleration=ao,
                              deflectors=defl, **kwargs)
