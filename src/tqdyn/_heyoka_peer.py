"""heyoka real128 reference peer for the Kepler benchmark.

This module propagates independent bodies around a point mass with heyoka's
adaptive Taylor integrator in ``real128`` (IEEE 754 binary128, 113-bit
significand, epsilon = 2**-112 ~ 1.9e-34) and samples the states on the same
fixed output grid ``t_k = k * step`` that tqdyn's fixed-step double-double
Runge-Kutta integrator produces.  It is the independent high-precision
reference against which the benchmark measures tqdyn.

heyoka is an *optional* dependency (``pip install tqdyn[heyoka]``).  It is
imported lazily inside the functions, so importing this module never needs
heyoka; calling a function without heyoka raises :class:`ImportError`.

Conventions
-----------
* Units: SI -- positions in m, velocities in m/s, gravitational parameter in
  m^3/s^2, times in s.
* Frame: GCRS (geocentric, inertial); the point mass sits at the origin.
* Time: seconds from the scenario epoch; the initial state is at t = 0.

Outputs are returned as double-double pairs of float64 arrays ``(hi, lo)``
with ``hi = float(x)`` (round to nearest) and ``lo = float(x - hi)`` where the
subtraction is exact in real128.  A double-double carries 106 (+1 sign) bits,
a real128 113, so ``hi + lo`` reproduces the real128 value to within
``|x| * 2**-106`` (~1.2e-32 relative; in practice ~1e-33 and often exactly).
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = [
    "propagate_kepler_grid",
    "propagate_kepler_grid_float64",
    "to_real128",
    "real128_to_dd",
]

_MISSING = "heyoka is not installed; pip install tqdyn[heyoka]"


def _heyoka():
    try:
        import heyoka
    except ImportError as exc:  # pragma: no cover - depends on environment
        raise ImportError(_MISSING) from exc
    return heyoka


# ---------------------------------------------------------------------------
# conversions
# ---------------------------------------------------------------------------


def _mpf_to_real128(x, R):
    """Convert one mpmath mpf to real128, correctly rounded (to nearest)."""
    import mpmath

    x = mpmath.mpf(x)
    if not mpmath.isfinite(x):
        raise ValueError(f"non-finite value {x!r}")
    if x == 0:
        return R(0)
    # round to 113 significant bits, then split the (<=113 bit) integer
    # significand into three <=53-bit chunks, each an exact float64
    with mpmath.workprec(113):
        y = +x
    sign, man, exp, bc = y._mpf_
    total = R(0)
    shift = 0
    while man:
        chunk = man & ((1 << 53) - 1)
        if chunk:
            total = total + R(math.ldexp(float(chunk), exp + shift))
        man >>= 53
        shift += 53
    # partial sums are exact: all chunks lie inside a 113-bit window
    return -total if sign else total


def _scalar_to_real128(x, R):
    """Exact conversion of a float/int/str/mpf/real128 scalar."""
    if isinstance(x, R):
        return x
    if isinstance(x, str):
        return R(x)
    if isinstance(x, (float, np.floating)):
        return R(float(x))
    if isinstance(x, (int, np.integer)):
        return R(int(x))
    # mpmath mpf (or anything with _mpf_)
    if hasattr(x, "_mpf_"):
        return _mpf_to_real128(x, R)
    raise TypeError(f"cannot convert {type(x).__name__} to real128")


def to_real128(a, shape=None):
    """Convert an array-like to a numpy array of real128, exactly.

    Accepted inputs:

    * float64 array -- converted exactly;
    * tuple ``(hi, lo)`` of two float64 arrays (double-double), value
      ``hi + lo`` -- converted exactly as ``real128(hi) + real128(lo)`` (exact
      for any normalised double-double, whose significand spans <= 107 bits);
    * object array of mpmath ``mpf`` (or str) -- rounded to nearest real128;
    * real128 array -- returned as is.
    """
    hy = _heyoka()
    R = hy.real128
    if isinstance(a, tuple):
        if len(a) != 2:
            raise ValueError("double-double input must be a (hi, lo) pair")
        hi = np.asarray(a[0], dtype=np.float64)
        lo = np.asarray(a[1], dtype=np.float64)
        if hi.shape != lo.shape:
            raise ValueError("hi and lo must have the same shape")
        out = hi.astype(R) + lo.astype(R)
    else:
        arr = np.asarray(a)
        if arr.dtype == R:
            out = arr.copy()
        elif arr.dtype == object:
            flat = [_scalar_to_real128(v, R) for v in arr.ravel()]
            out = np.array(flat, dtype=R).reshape(arr.shape)
        elif arr.dtype == np.float64 or arr.dtype == np.float32:
            out = arr.astype(np.float64).astype(R)
        elif np.issubdtype(arr.dtype, np.integer):
            flat = [R(int(v)) for v in arr.ravel()]
            out = np.array(flat, dtype=R).reshape(arr.shape)
        else:
            raise TypeError(f"unsupported dtype {arr.dtype}")
    if shape is not None and out.shape != tuple(shape):
        raise ValueError(f"expected shape {tuple(shape)}, got {out.shape}")
    return out


def real128_to_dd(arr):
    """Split a real128 array into float64 ``(hi, lo)``.

    ``hi`` is the nearest float64, ``lo`` the nearest float64 to the exact
    real128 residual ``arr - hi``.
    """
    hy = _heyoka()
    R = hy.real128
    arr = np.asarray(arr)
    if arr.dtype != R:
        raise TypeError("expected a real128 array")
    hi = arr.astype(np.float64)
    lo = (arr - hi.astype(R)).astype(np.float64)
    return hi, lo


# ---------------------------------------------------------------------------
# integrator
# ---------------------------------------------------------------------------


def _kepler_system(hy, n_bodies):
    """ODE system for n_bodies independent Kepler problems, gm = par[0]."""
    gm = hy.par[0]
    sys = []
    for i in range(n_bodies):
        x, y, z, vx, vy, vz = hy.make_vars(
            f"x{i}", f"y{i}", f"z{i}", f"vx{i}", f"vy{i}", f"vz{i}"
        )
        r2 = hy.sum([x * x, y * y, z * z])
        # -gm / |r|^3 ; heyoka specialises pow with exponent -3/2
        k = -gm * r2 ** -1.5
        sys += [(x, vx), (y, vy), (z, vz), (vx, k * x), (vy, k * y), (vz, k * z)]
    return sys


def _propagate(r0, v0, gm, step, n_steps, tol, fp_type, compact_mode):
    hy = _heyoka()
    R = hy.real128
    n_steps = int(n_steps)
    if n_steps < 0:
        raise ValueError("n_steps must be >= 0")

    if fp_type is R:
        r = to_real128(r0)
        v = to_real128(v0)
        gm_v = _scalar_to_real128(gm, R)
        step_v = _scalar_to_real128(step, R)
        dtype = R
    else:
        r = np.asarray(r0, dtype=np.float64) if not isinstance(r0, tuple) else (
            np.asarray(r0[0], dtype=np.float64) + np.asarray(r0[1], dtype=np.float64)
        )
        v = np.asarray(v0, dtype=np.float64) if not isinstance(v0, tuple) else (
            np.asarray(v0[0], dtype=np.float64) + np.asarray(v0[1], dtype=np.float64)
        )
        gm_v = float(gm)
        step_v = float(step)
        dtype = np.float64
    if r.ndim != 2 or r.shape[1] != 3 or v.shape != r.shape:
        raise ValueError(f"r0, v0 must both be (N, 3); got {r.shape}, {v.shape}")
    n_bodies = r.shape[0]

    state = np.empty((n_bodies, 6), dtype=dtype)
    state[:, :3] = r
    state[:, 3:] = v
    state = state.reshape(-1)
    pars = np.array([gm_v], dtype=dtype)

    kwargs = dict(fp_type=dtype, compact_mode=compact_mode, pars=pars)
    if tol is not None:
        kwargs["tol"] = _scalar_to_real128(tol, R) if dtype is R else float(tol)

    t0 = time.perf_counter()
    ta = hy.taylor_adaptive(_kepler_system(hy, n_bodies), state, **kwargs)
    setup_s = time.perf_counter() - t0

    # grid t_k = k*step, computed in the working precision (exact for
    # integer-valued steps such as 50 s)
    grid = np.arange(n_steps + 1, dtype=np.int64).astype(dtype) * step_v

    t0 = time.perf_counter()
    res = ta.propagate_grid(grid)
    wall_s = time.perf_counter() - t0
    outcome, states = res[0], res[-1]
    if outcome != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"heyoka propagate_grid stopped early: {outcome}")

    states = np.asarray(states).reshape(n_steps + 1, n_bodies, 6)
    out = {
        "wall_s": float(wall_s),
        "setup_s": float(setup_s),
        "tol": float(ta.tol),
        "order": int(ta.order),
        "n_taylor_steps": int(res[3]),
    }
    if dtype is R:
        r_hi, r_lo = real128_to_dd(states[:, :, :3])
        v_hi, v_lo = real128_to_dd(states[:, :, 3:])
        out["fp_type"] = "real128"
    else:
        r_hi = np.ascontiguousarray(states[:, :, :3])
        v_hi = np.ascontiguousarray(states[:, :, 3:])
        r_lo = np.zeros_like(r_hi)
        v_lo = np.zeros_like(v_hi)
        out["fp_type"] = "float64"
    out.update(r_hi=r_hi, r_lo=r_lo, v_hi=v_hi, v_lo=v_lo)
    return out


def propagate_kepler_grid(r0, v0, gm, step, n_steps, tol=None, compact_mode=True):
    """Propagate N independent bodies around a point mass with heyoka's
    Taylor integrator in real128 and return the states on the grid
    t_k = k*step, k = 0..n_steps.

    Parameters
    ----------
    r0, v0 : (N, 3) initial positions [m] / velocities [m/s], GCRS, at t = 0.
        Each may be a float64 (N, 3) array; a double-double pair ``(hi, lo)``
        of two float64 (N, 3) arrays with value ``hi + lo`` (converted exactly
        as ``real128(hi) + real128(lo)``); an (N, 3) object array of mpmath
        ``mpf`` (rounded to nearest real128); or a real128 array.
    gm : float, str or mpf
        Gravitational parameter [m^3/s^2].  A str is parsed by
        ``heyoka.real128(str)`` (use this for decimal constants such as
        ``"3.986004415e14"``, which are not exact float64 values).
    step : float
        Grid spacing [s].  Grid points are ``k * real128(step)``.
    n_steps : int
        Number of grid intervals; n_steps + 1 states are returned.
    tol : float, str or None
        Integrator tolerance; default: real128 epsilon (2**-112).
    compact_mode : bool
        heyoka compact mode (much faster JIT compile, slightly slower steps).

    Returns
    -------
    dict with
        'r_hi', 'r_lo', 'v_hi', 'v_lo' : float64 arrays (n_steps+1, N, 3),
            hi = float(x), lo = float(x - hi) (subtraction in real128);
        'wall_s' : wall time of the ``propagate_grid`` call only [s];
        'setup_s' : time to build / JIT-compile the integrator [s];
        'fp_type' : 'real128';
        'tol' : tolerance used (as float);
        'order' : Taylor order; 'n_taylor_steps' : adaptive steps taken.
    """
    hy = _heyoka()
    return _propagate(r0, v0, gm, step, n_steps, tol, hy.real128, compact_mode)


def propagate_kepler_grid_float64(r0, v0, gm, step, n_steps, tol=None,
                                  compact_mode=True):
    """Same as :func:`propagate_kepler_grid` in float64 (quick sanity peer).

    Double-double inputs are collapsed to ``hi + lo`` in float64; the 'lo'
    outputs are zero and 'fp_type' is 'float64'.
    """
    _heyoka()
    return _propagate(r0, v0, gm, step, n_steps, tol, np.float64, compact_mode)
