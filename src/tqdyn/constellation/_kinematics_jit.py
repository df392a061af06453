"""Compiled (numba) nominal-attitude kinematics of the three satellites, for the integrator's RHS.

:func:`sat_kinematics` is the scalar, allocation-free counterpart of
:func:`tqdyn.constellation.attitude.attitude` (``method="direct"``), extended
by the ``iterative`` pointing law.  It is called once per right-hand-side
evaluation (~2 million times in a 90-day run), so it works on 3-tuples of
float64, writes into preallocated arrays and uses no fastmath (IEEE order of
operations is kept; results agree with the numpy reference to rounding).

Conventions
-----------
SI units; GCRS components; TT (the kernel itself has no time argument: all
inputs are the satellites' states at one epoch t).  Satellite axis = 0-based
``Sat.index``; for satellite i, (i, j, k) is the even permutation,
j = (i + 1) % 3, k = (i + 2) % 3 (see :mod:`tqdyn.constellation.indices`).

Frame from the two beams (identical to :mod:`.attitude`)
----------------------------------------------------------
With b_ij, b_ik the unit beam vectors of satellite i (from i towards j, k as
the pointing law defines them)::

    X_S = unit(b_ij + b_ik),  Z_S = unit(b_ij x b_ik),  Y_S = Z_S x X_S
    theta = atan2(|b_ij x b_ik|, b_ij . b_ik)
    theta' = -cos'/sin,  theta'' = -(cos'' + theta'^2 cos)/sin   (cos = b_ij.b_ik, sin = |b_ij x b_ik|)
    omega_S     = (Z.Y', X.Z', Y.X')                               (Poisson relation, in S)
    omega_dot_S = (Z'.Y' + Z.Y'', X'.Z' + X.Z'', Y'.X' + Y.X'')

All derivatives are analytic "jets" (value, first and second time
derivative): for u = w/|w| with L = |w|: L' = u.w', u' = (w' - L' u)/L,
L'' = u'.w' + u.w'', u'' = (w'' - L'' u - 2 L' u')/L; products by the
Leibniz rule.

Pointing laws (``law`` codes, :data:`LAW_CODES`)
-------------------------------------------------
Arm vectors are formed from the double-double positions as
``(r_hi[j] - r_hi[i]) + (r_lo[j] - r_lo[i])`` (full float64 precision of the
~1.7e8 m arm, not of the ~1e8 m positions).  n_ij = unit(r_j - r_i), L_ij = |r_j - r_i|.

* 0 ``global``:  b_ij = n_ij; the jets need v and a of i and j.
* 1 ``taylor1``: b_ij = unit(n_ij - v_j / c); b_ij'' needs the jerk of j.
* 2 ``taylor2``: b_ij = unit(n_ij - v_j / c + a_j L_ij / (2 c^2)); b_ij' needs
  the jerk, b_ij'' the snap of j.
  These are exactly :func:`tqdyn.constellation.attitude.beam_vectors`.
* 3 ``iterative``: b_ij = unit(e_j - r_i) with e_j = P_j(t - tau) the emission
  point on satellite j's trajectory and tau the solution of the light-time
  equation c tau = |P_j(t - tau) - r_i(t)|.  P_j is the 4th-order Taylor model
  of j's trajectory about t::

      P_j(t - s) = r_j - v_j s + a_j s^2/2 - J_j s^3/6 + S_j s^4/24

  (the offset r_j - r_i is the arm difference above, the Taylor terms are
  added to it).  tau is found by Newton's method on f(s) = |D(s)| - c s,
  D(s) = P_j(t - s) - r_i, f'(s) = -(c + u.v_e), starting from L_ij/c
  (off by up to ~2e-6 s); one step reaches ~1e-22 s in exact arithmetic and
  the iteration stops when the correction is below 1e-15 tau, i.e. at the
  float64 resolution of tau (ulp(0.57 s) = 1.1e-16 s; |D| itself is rounded
  at ~1.5e-8 m = 5e-17 s).  A tau error dtau moves the emission point by
  v dtau ~ 2e3 m/s * 1e-16 s = 2e-13 m, ~1e-21 rad of beam direction.

  Model error: the neglected 5th-derivative term ~ n^5 r tau^5/120 =
  3e-16 m/s^5 * 5e-4 s^5 ~ 1e-19 m, i.e. ~1e-27 rad (n = 2e-5 rad/s,
  r = 1e8 m).  The jerk is the monopole's (from ``gm``) plus the caller's
  ``jerk_pert``; the snap is the monopole's.  Without ``jerk_pert`` the jerk
  would miss the time derivatives of the perturbing accelerations, ~4e-10
  m/s^3 (the Moon's tidal term; vs |J| ~ n^3 r ~ 8e-7 m/s^3); the snap misses
  ~1e-5 n^2 ~ 4e-15 m/s^4: the emission point moves by 4e-15 tau^4/24 ~
  2e-17 m, ~1e-25 rad.  The jerk enters omega_dot through 1/c: a missing
  5e-10 m/s^3 is ~2e-18 rad/s^2 of omega_dot that the attitude does not
  have (measured), which is why :mod:`tqdyn.dynamics` passes the Moon, Sun
  and J2 jerk.

  Time derivatives by implicit differentiation (checked numerically by
  ``tests/test_kinematics_jit.py`` against finite differences of tau and of
  the beam along an analytic trajectory).  With D = e - r_i, |D| = c tau,
  u = D/|D|, v_e = P_j'(t - tau) = v_j - a_j tau + J_j tau^2/2 - S_j tau^3/6,
  a_e = P_j''(t - tau) = a_j - J_j tau + S_j tau^2/2 (derivatives of the model
  with respect to its time argument):

      e(t) = P_j(t - tau(t))         =>  e' = v_e (1 - tau')
      c tau = |D|                    =>  c tau' = u.D' = u.(e' - v_i)
                                     =>  tau' = u.(v_e - v_i) / (c + u.v_e)
      e'' = a_e (1 - tau')^2 - v_e tau''
      c tau'' = u'.D' + u.D'',  D'' = e'' - a_i
                                     =>  tau'' = [u'.D' + u.(a_e (1 - tau')^2 - a_i)] / (c + u.v_e)
      u' = (D' - (u.D') u) / |D|

  (the tau'' line follows by moving the -u.v_e tau'' part of u.D'' to the
  left-hand side).  The beam jet is then the unit-vector jet of (D, D', D'').

Jerk and snap
-------------
For the Taylor and iterative laws, the remote satellite's jerk and snap come
from the monopole formula (:mod:`tqdyn.forces.central`, with the
*given* total acceleration a in the snap), the jerk plus ``jerk_pert``::

    J = -gm [v/r^3 - 3 (r.v) r/r^5]
    S = -gm [a/r^3 - 6 (r.v) v/r^5 - 3 (v.v + r.a) r/r^5 + 15 (r.v)^2 r/r^7]

The accelerations ``a`` are whatever the caller passes (gravity plus drag-free
control G_i if modelled): omega_dot then includes that (~1e-18 m/s^2 / L,
negligible) feedback; nothing is added here.

Accuracy (bounds of ``tests/test_kinematics_jit.py`` on exact Kepler orbits)
----------------------------------------------------------------------------
Against the numpy :func:`.attitude.attitude`: frames 3e-16, omega 1.4e-20
rad/s, omega_dot 2e-25 rad/s^2.  Iterative law against a 40-digit solution
of the light-time equation on the exact orbit: tau 1.2e-16 s, beam
1.1e-16 rad, tau'/tau''/b'/b'' to float64 rounding; taylor2 is 1.9e-11 rad,
taylor1 3.8e-11 rad and global 5.8e-6 rad from the exact beam.  Rates agree
with 5-point differences of the frames to < 3e-18 rad/s and < 3e-21 rad/s^2.
"""

from __future__ import annotations

from math import atan2, sqrt

from numba import njit

from .._choices import unknown
from ..numerics.vec3 import add as _add, axpy as _axpy, cross as _cross, dot as _dot
from ..numerics.vec3 import row as _row, scale as _scale, sub as _sub
from ..forces.central import monopole_jerk_snap as _monopole_jerk_snap
from ..numerics.jit import inner_kernel

__all__ = [
    "LAW_CODES",
    "LAW_GLOBAL",
    "LAW_ITERATIVE",
    "LAW_TAYLOR1",
    "LAW_TAYLOR2",
    "law_code",
    "nominal_kinematics",
    "sat_kinematics",
]

#: Pointing-law codes understood by :func:`sat_kinematics`.
LAW_GLOBAL = 0
LAW_TAYLOR1 = 1
LAW_TAYLOR2 = 2
LAW_ITERATIVE = 3
#: Law name (as in the scenario / ``pointing`` attribute) -> integer code.
LAW_CODES = {"global": LAW_GLOBAL, "taylor1": LAW_TAYLOR1, "taylor2": LAW_TAYLOR2, "iterative": LAW_ITERATIVE}

# Newton iteration of the light time: stop when |correction| <= _LT_RTOL * tau
# (the float64 resolution of tau); at most _LT_MAX_ITER steps.
_LT_RTOL = 1e-15
_LT_MAX_ITER = 8


def law_code(name: str) -> int:
    """Integer code of the pointing law ``name`` ("global", "taylor1",
    "taylor2" or "iterative") for :func:`sat_kinematics`."""
    try:
        return LAW_CODES[name]
    except (KeyError, TypeError):
        raise ValueError(unknown("pointing law", name, LAW_CODES)) from None


# ------------------------------------------------------------------ jets

@inner_kernel
def _unit_jet(w0, w1, w2):
    """Unit vector u = w/|w| and L = |w| with first and second derivatives.

    w0, w1, w2: 3-tuples (w, w', w'').  Returns (u, u', u'', L, L', L'')."""
    L = sqrt(_dot(w0, w0))
    inv = 1.0 / L
    u = _scale(inv, w0)
    L1 = _dot(u, w1)
    u1 = _scale(inv, _axpy(-L1, u, w1))
    L2 = _dot(u1, w1) + _dot(u, w2)
    u2 = _scale(inv, _axpy(-2.0 * L1, u1, _axpy(-L2, u, w2)))
    return u, u1, u2, L, L1, L2


@inner_kernel
def _cross_jet(a0, a1, a2, b0, b1, b2):
    c0 = _cross(a0, b0)
    c1 = _add(_cross(a1, b0), _cross(a0, b1))
    c2 = _add(_add(_cross(a2, b0), _scale(2.0, _cross(a1, b1))), _cross(a0, b2))
    return c0, c1, c2


# ------------------------------------------------------------------ beams

@inner_kernel
def _arm(r_hi, r_lo, i, m):
    """r_m - r_i from the dd positions, float64 (hi and lo differences summed)."""
    return ((r_hi[m, 0] - r_hi[i, 0]) + (r_lo[m, 0] - r_lo[i, 0]),
            (r_hi[m, 1] - r_hi[i, 1]) + (r_lo[m, 1] - r_lo[i, 1]),
            (r_hi[m, 2] - r_hi[i, 2]) + (r_lo[m, 2] - r_lo[i, 2]))


@inner_kernel
def _beam_taylor(law, d0, d1, d2, vm, am, jm, sm, c):
    """Beam jet for the global (0), taylor1 (1) and taylor2 (2) laws.

    d0, d1, d2: arm r_m - r_i and its derivatives; vm, am, jm, sm: velocity,
    acceleration, jerk, snap of the remote satellite m.  Returns (b, b', b'')."""
    n0, n1, n2, L0, L1, L2 = _unit_jet(d0, d1, d2)
    if law == 0:
        return n0, n1, n2
    ic = -1.0 / c
    w0 = _axpy(ic, vm, n0)
    w1 = _axpy(ic, am, n1)
    w2 = _axpy(ic, jm, n2)
    if law == 2:
        half = 1.0 / (2.0 * c * c)
        h0, h1, h2 = L0 * half, L1 * half, L2 * half
        w0 = _axpy(h0, am, w0)
        w1 = _add(w1, _axpy(h1, am, _scale(h0, jm)))
        w2 = _add(w2, _axpy(h2, am, _axpy(2.0 * h1, jm, _scale(h0, sm))))
    b0, b1, b2, _, _, _ = _unit_jet(w0, w1, w2)
    return b0, b1, b2


@inner_kernel
def _emission_offsets(s, vm, am, jm, sm):
    """Taylor model of the remote orbit at t - s: (P(t-s) - r_m, P'(t-s), P''(t-s))."""
    off = (s * (-vm[0] + s * (0.5 * am[0] + s * (-jm[0] / 6.0 + s * (sm[0] / 24.0)))),
           s * (-vm[1] + s * (0.5 * am[1] + s * (-jm[1] / 6.0 + s * (sm[1] / 24.0)))),
           s * (-vm[2] + s * (0.5 * am[2] + s * (-jm[2] / 6.0 + s * (sm[2] / 24.0)))))
    ve = (vm[0] + s * (-am[0] + s * (0.5 * jm[0] - s * (sm[0] / 6.0))),
          vm[1] + s * (-am[1] + s * (0.5 * jm[1] - s * (sm[1] / 6.0))),
          vm[2] + s * (-am[2] + s * (0.5 * jm[2] - s * (sm[2] / 6.0))))
    ae = (am[0] + s * (-jm[0] + s * (0.5 * sm[0])),
          am[1] + s * (-jm[1] + s * (0.5 * sm[1])),
          am[2] + s * (-jm[2] + s * (0.5 * sm[2])))
    return off, ve, ae


@inner_kernel
def _beam_iterative(d0, vi, ai, vm, am, jm, sm, c):
    """Beam jet of the iterative law and the light time with its derivatives.

    d0: arm r_m - r_i [m]; vi, ai: receiver velocity/acceleration; vm, am,
    jm, sm: remote velocity, acceleration, jerk, snap (the Taylor model);
    c: m/s.  Returns ((b, b', b''), (tau, tau', tau'')) with tau in s."""
    s = sqrt(_dot(d0, d0)) / c
    converged = False
    for _ in range(_LT_MAX_ITER):
        off, ve, _ae = _emission_offsets(s, vm, am, jm, sm)
        D = _add(d0, off)
        dn = sqrt(_dot(D, D))
        step = (dn - c * s) / (c + _dot(D, ve) / dn)
        s += step
        if abs(step) <= _LT_RTOL * s:
            converged = True
            break
    if not converged:
        raise RuntimeError("sat_kinematics: light travel time (iterative law) did not converge; "
                           "check that positions, velocities and c are finite and physical")
    off, ve, ae = _emission_offsets(s, vm, am, jm, sm)
    D = _add(d0, off)
    dn = sqrt(_dot(D, D))
    u = _scale(1.0 / dn, D)
    den = 1.0 / (c + _dot(u, ve))
    tau1 = _dot(u, _sub(ve, vi)) * den
    g = 1.0 - tau1
    D1 = _axpy(g, ve, _scale(-1.0, vi))              # e' - v_i
    u1 = _scale(1.0 / dn, _axpy(-_dot(u, D1), u, D1))
    ae_g2 = _scale(g * g, ae)                         # a_e (1 - tau')^2
    tau2 = (_dot(u1, D1) + _dot(u, _sub(ae_g2, ai))) * den
    D2 = _sub(_axpy(-tau2, ve, ae_g2), ai)            # e'' - a_i
    b0, b1, b2, _, _, _ = _unit_jet(D, D1, D2)
    return (b0, b1, b2), (s, tau1, tau2)


@inner_kernel
def _beam_jet(law, jerk_pert, i, m, r_hi, r_lo, v, a, jm, sm, c):
    """Beam jet (b, b', b'') of satellite i towards remote satellite m
    (jerk_pert None: the global law, as in :func:`nominal_kinematics`)."""
    d0 = _arm(r_hi, r_lo, i, m)
    vi, ai = _row(v, i), _row(a, i)
    vm, am = _row(v, m), _row(a, m)
    if jerk_pert is not None:
        if law == 3:
            b, _ = _beam_iterative(d0, vi, ai, vm, am, jm, sm, c)
            return b
    return _beam_taylor(law, d0, _sub(vm, vi), _sub(am, ai), vm, am, jm, sm, c)


@njit(cache=True)
def _bad33(x):
    return x.shape[0] != 3 or x.shape[1] != 3


@njit(cache=True)
def _check(law, r_hi, r_lo, v, a, T_out, w_out, wd_out, th_out):
    if law < 0 or law > 3:
        raise ValueError("sat_kinematics: law = " + str(law) + " is not allowed; allowed: "
                         "0 (global), 1 (taylor1), 2 (taylor2), 3 (iterative)")
    if (_bad33(r_hi) or _bad33(r_lo) or _bad33(v) or _bad33(a) or _bad33(w_out) or _bad33(wd_out)
            or _bad33(th_out)):
        raise ValueError("sat_kinematics: r_hi, r_lo, v, a, w_out, wd_out and th_out must have shape (3, 3)")
    if T_out.shape[0] != 3 or T_out.shape[1] != 3 or T_out.shape[2] != 3:
        raise ValueError("sat_kinematics: T_out must have shape (3, 3, 3)")


# ------------------------------------------------------------------ kernel

@njit(cache=True)
def sat_kinematics(law, r_hi, r_lo, v, a, jerk_pert, gm, c, T_out, w_out, wd_out, th_out):
    """Nominal attitude, angular velocity and acceleration of the three satellites.

    Parameters
    ----------
    law : int -- pointing law, :data:`LAW_GLOBAL` (0), :data:`LAW_TAYLOR1` (1),
        :data:`LAW_TAYLOR2` (2) or :data:`LAW_ITERATIVE` (3) (see the module
        docstring; :func:`law_code` maps names).
    r_hi, r_lo : (3, 3) float64 -- satellite positions [m], GCRS, row =
        ``Sat.index``, as a double-double pair (value r_hi + r_lo; r_lo may be
        zeros).
    v : (3, 3) float64 -- velocities [m/s], GCRS.
    a : (3, 3) float64 -- total accelerations [m/s^2], GCRS (whatever the orbit
        follows, e.g. gravity + drag-free control).
    jerk_pert : (3, 3) float64 -- the part of each satellite's jerk d a/dt
        [m/s^3, GCRS] beyond the Earth monopole (zeros for a Kepler orbit).
        omega_dot of the local laws contains jerk / c: a jerk left out makes
        omega_dot inconsistent with the attitude (the Moon's tidal jerk,
        ~5e-10 m/s^3, would be ~2e-18 rad/s^2).
    gm : float -- Earth GM [m^3/s^2], for the remote satellites' monopole
        jerk and snap (Taylor and iterative laws).
    c : float -- speed of light [m/s].
    T_out : (3, 3, 3) float64, written -- T_S_I per satellite (rows X_S, Y_S,
        Z_S in GCRS components).
    w_out : (3, 3) float64, written -- omega_S [rad/s], inertial angular
        velocity of S expressed in S.
    wd_out : (3, 3) float64, written -- omega_dot_S [rad/s^2], expressed in S
        (= the time derivative of the S components).
    th_out : (3, 3) float64, written -- per satellite (theta [rad], theta_dot
        [rad/s], theta_ddot [rad/s^2]); theta = angle between the two beams
        (the breathing angle alpha_i for the global law).

    All inputs refer to one epoch t (TT).  Returns None.  Raises ValueError on
    an unknown law or wrong shapes, RuntimeError if the light time of the
    iterative law does not converge (non-finite input).
    """
    _check(law, r_hi, r_lo, v, a, T_out, w_out, wd_out, th_out)
    nominal_kinematics(law, r_hi, r_lo, v, a, jerk_pert, gm, c, T_out, w_out, wd_out, th_out)


@inner_kernel
def nominal_kinematics(law, r_hi, r_lo, v, a, jerk_pert, gm, c, T_out, w_out, wd_out, th_out):
    """:func:`sat_kinematics` without its checks of the law code and the
    shapes, for callers whose arrays and law are fixed by construction (the
    right-hand side of the coupled system): the checks' error messages
    would be compiled into every kernel that calls it.  ``jerk_pert`` None
    stands for the global law (law 0, which needs no jerks): the local laws'
    code is then left out when the caller is compiled."""
    z = (0.0, 0.0, 0.0)
    j0 = j1 = j2 = s0 = s1 = s2 = z
    if jerk_pert is not None:  # None: the global law (compiled without the local laws' jerks)
        if law != 0:
            j0, s0 = _monopole_jerk_snap((r_hi[0, 0] + r_lo[0, 0], r_hi[0, 1] + r_lo[0, 1], r_hi[0, 2] + r_lo[0, 2]),
                                         _row(v, 0), _row(a, 0), gm)
            j0 = _add(j0, _row(jerk_pert, 0))
            j1, s1 = _monopole_jerk_snap((r_hi[1, 0] + r_lo[1, 0], r_hi[1, 1] + r_lo[1, 1], r_hi[1, 2] + r_lo[1, 2]),
                                         _row(v, 1), _row(a, 1), gm)
            j1 = _add(j1, _row(jerk_pert, 1))
            j2, s2 = _monopole_jerk_snap((r_hi[2, 0] + r_lo[2, 0], r_hi[2, 1] + r_lo[2, 1], r_hi[2, 2] + r_lo[2, 2]),
                                         _row(v, 2), _row(a, 2), gm)
            j2 = _add(j2, _row(jerk_pert, 2))
    for i in range(3):
        j = (i + 1) % 3
        k = (i + 2) % 3
        if i == 0:
            jj, sj, jk, sk = j1, s1, j2, s2
        elif i == 1:
            jj, sj, jk, sk = j2, s2, j0, s0
        else:
            jj, sj, jk, sk = j0, s0, j1, s1
        bj0, bj1, bj2 = _beam_jet(law, jerk_pert, i, j, r_hi, r_lo, v, a, jj, sj, c)
        bk0, bk1, bk2 = _beam_jet(law, jerk_pert, i, k, r_hi, r_lo, v, a, jk, sk, c)
        X0, X1, X2, _, _, _ = _unit_jet(_add(bj0, bk0), _add(bj1, bk1), _add(bj2, bk2))
        c0, c1, c2 = _cross_jet(bj0, bj1, bj2, bk0, bk1, bk2)
        Z0, Z1, Z2, sn, _, _ = _unit_jet(c0, c1, c2)
        Y0, Y1, Y2 = _cross_jet(Z0, Z1, Z2, X0, X1, X2)
        cs0 = _dot(bj0, bk0)
        cs1 = _dot(bj1, bk0) + _dot(bj0, bk1)
        cs2 = _dot(bj2, bk0) + 2.0 * _dot(bj1, bk1) + _dot(bj0, bk2)
        th1 = -cs1 / sn
        th_out[i, 0] = atan2(sn, cs0)
        th_out[i, 1] = th1
        th_out[i, 2] = -(cs2 + th1 * th1 * cs0) / sn
        for q in range(3):
            T_out[i, 0, q] = X0[q]
            T_out[i, 1, q] = Y0[q]
            T_out[i, 2, q] = Z0[q]
        w_out[i, 0] = _dot(Z0, Y1)
        w_out[i, 1] = _dot(X0, Z1)
        w_out[i, 2] = _dot(Y0, X1)
        wd_out[i, 0] = _dot(Z1, Y1) + _dot(Z0, Y2)
        wd_out[i, 1] = _dot(X1, Z1) + _dot(X0, Z2)
        wd_out[i, 2] = _dot(Y1, X1) + _dot(Y0, X2)
