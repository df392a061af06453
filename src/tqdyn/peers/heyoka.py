"""heyoka real128 reference peers for the Kepler and force-model benchmarks (a peer: no tqdyn physics inside).

This module propagates bodies with heyoka's adaptive Taylor integrator in
``real128`` (IEEE 754 binary128, 113-bit significand, epsilon = 2**-112 ~
1.9e-34) and samples the states on the same fixed output grid
``t_k = k * step`` that tqdyn's fixed-step double-double Runge-Kutta
integrator produces:

* :func:`propagate_kepler_grid`: independent bodies around a point mass (the
  Kepler benchmark's independent high-precision reference);
* :func:`propagate_reduced_grid`: the reduced force model (Earth EGM2008
  12x12 + Moon + Sun) built from heyoka's own models (EGM2008, IAU 2006 +
  bundled EOP, ELP2000, VSOP2013): the force-model benchmark's peer.  Its
  ephemerides are truncated analytical theories, so it differs from tqdyn's
  DE421-based reduced model at the level of the ephemeris differences (the
  benchmark reports by how much), not at the integration-error level.

heyoka is an *optional* dependency (``pip install tqdyn[heyoka]``).  It is
imported lazily inside the functions, so importing this module never needs
heyoka; calling a function without heyoka raises :class:`ImportError`.

Conventions
-----------
* Units: SI -- positions in m, velocities in m/s, gravitational parameter in
  m^3/s^2, times in s.
* Frame: GCRS (geocentric, ICRF axes); the Earth sits at the origin.
* Time: seconds (TDB) from the scenario epoch; the initial state is at t = 0.

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
    "propagate_reduced_grid",
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
    dtype = R if fp_type is R else np.float64
    state, n_bodies = _state_array(r0, v0, dtype, R)
    if dtype is R:
        pars = np.array([_scalar_to_real128(gm, R)], dtype=R)
        step_v = _scalar_to_real128(step, R)
    else:
        pars = np.array([float(gm)], dtype=np.float64)
        step_v = float(step)

    kwargs = {"fp_type": dtype, "compact_mode": compact_mode, "pars": pars}
    if tol is not None:
        kwargs["tol"] = _scalar_to_real128(tol, R) if dtype is R else float(tol)

    t0 = time.perf_counter()
    ta = hy.taylor_adaptive(_kepler_system(hy, n_bodies), state, **kwargs)
    setup_s = time.perf_counter() - t0

    out = _grid_outputs(hy, ta, dtype, n_bodies, step_v, n_steps)
    out["setup_s"] = float(setup_s)
    return out


def _state_array(r0, v0, dtype, R):
    """Flat initial state [x, y, z, vx, vy, vz] per body in dtype (real128:
    exact conversion; float64: a dd pair is collapsed to hi + lo)."""
    if dtype is R:
        r, v = to_real128(r0), to_real128(v0)
    else:
        def f64(a):
            if isinstance(a, tuple):
                return np.asarray(a[0], dtype=np.float64) + np.asarray(a[1], dtype=np.float64)
            return np.asarray(a, dtype=np.float64)
        r, v = f64(r0), f64(v0)
    if r.ndim != 2 or r.shape[1] != 3 or v.shape != r.shape:
        raise ValueError(f"r0, v0 must both be (N, 3); got {r.shape}, {v.shape}")
    state = np.empty((r.shape[0], 6), dtype=dtype)
    state[:, :3] = r
    state[:, 3:] = v
    return state.reshape(-1), r.shape[0]


def _grid_outputs(hy, ta, dtype, n_bodies, step_v, n_steps):
    """propagate_grid on t_k = k*step (computed in the working precision:
    exact for integer-valued steps such as 50 s); the dict of hi/lo outputs,
    the wall time of the call and the step statistics."""
    R = hy.real128
    grid = np.arange(n_steps + 1, dtype=np.int64).astype(dtype) * step_v
    t0 = time.perf_counter()
    res = ta.propagate_grid(grid)
    wall_s = time.perf_counter() - t0
    outcome, states = res[0], res[-1]
    if outcome != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"heyoka propagate_grid stopped early: {outcome}")
    states = np.asarray(states).reshape(n_steps + 1, n_bodies, 6)
    out = {"wall_s": float(wall_s), "tol": float(ta.tol), "order": int(ta.order),
           "n_taylor_steps": int(res[3])}
    if dtype is R:
        r_hi, r_lo = real128_to_dd(states[:, :, :3])
        v_hi, v_lo = real128_to_dd(states[:, :, 3:])
        out["fp_type"] = "real128"
    else:
        r_hi = np.ascontiguousarray(states[:, :, :3])
        v_hi = np.ascontiguousarray(states[:, :, 3:])
        r_lo, v_lo = np.zeros_like(r_hi), np.zeros_like(v_hi)
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


# ---------------------------------------------------------------------------
# reduced force model: Earth EGM2008 n x n + Moon (ELP2000) + Sun (VSOP2013)
# ---------------------------------------------------------------------------

#: Julian date of J2000.0 [d]
_J2000_JD = 2451545.0
#: astronomical unit [m] (IAU 2012 B2), the length unit of VSOP2013
_AU_M = 149597870700.0
#: EGM2008 reference radius [m]
_R_EGM2008 = 6378136.3
#: DE430/DE431 GMs [m^3/s^2] (tqdyn/data/gm_de431.tpc, BODY10/301/399 in
#: km^3/s^2 times 1e9): the values tqdyn's third-body terms use
_GM_SUN_DE431 = "1.3271244004193938e20"
_GM_MOON_DE431 = "4.9028000661637961e12"
_GM_EARTH_DE431 = "3.9860043543609598e14"

#: Default truncation thresholds of the reduced model (see
#: :func:`propagate_reduced_grid` for the accuracy they give).
ELP_THRESH = 1e-8
VSOP_THRESH = 1e-10
IAU2006_THRESH = 1e-4


def _epoch_days(epoch_tdb_jd, R):
    """Days TDB from J2000 at t = 0 as an exact real128 (jd1 - J2000) + jd2."""
    if isinstance(epoch_tdb_jd, (tuple, list)):
        if len(epoch_tdb_jd) != 2:
            raise ValueError("epoch_tdb_jd must be a JD or a two-part (jd1, jd2) pair")
        jd1, jd2 = epoch_tdb_jd
    else:
        jd1, jd2 = epoch_tdb_jd, 0.0
    return (_scalar_to_real128(jd1, R) - R(_J2000_JD)) + _scalar_to_real128(jd2, R)


def _reduced_system(hy, n_sat, degree, elp_thresh, vsop_thresh, iau2006_thresh, eop_data):
    """ODE system of n_sat satellites, geocentric GCRS, time t = s TDB since
    the epoch.  par[0] = GM_Earth (EGM2008 field), par[1] = GM_Moon,
    par[2] = GM_Sun, par[3] = days TDB from J2000 at t = 0.
    Returns (system, dict of the time-only expressions: moon, sun [m])."""
    md = hy.model
    gm, gm_moon, gm_sun, d0 = hy.par[0], hy.par[1], hy.par[2], hy.par[3]
    t = hy.time
    # TDB: seconds / Julian centuries / Julian millennia since J2000
    tdb_s = d0 * 86400.0 + t
    days = d0 + t / 86400.0
    tc = days / 36525.0
    tm = days / 365250.0
    # TT centuries for the Earth rotation (TT = TDB - (TDB - TT), heyoka's
    # periodic SPICE approximation, good to ~30 us)
    tt_c = (tdb_s - md.delta_tdb_tt(tdb_s)) / (86400.0 * 36525.0)

    # Moon, geocentric: ELP2000 (FK5 J2000 axes, km) -> ICRS axes, m
    moon = [1000.0 * c for c in md.rot_fk5j2000_icrs(md.elp2000_cartesian_fk5(tc, thresh=elp_thresh))]
    # Sun, geocentric: -(heliocentric Earth) = -(EMB_helio - f * Moon_geo),
    # f = GM_Moon / (GM_Earth + GM_Moon) (DE430 ratio); VSOP2013 ICRS axes, AU
    emb = md.vsop2013_cartesian_icrf(3, tm, thresh=vsop_thresh)[:3]
    f_moon = float(_GM_MOON_DE431) / (float(_GM_EARTH_DE431) + float(_GM_MOON_DE431))
    sun = [-_AU_M * e + f_moon * m for e, m in zip(emb, moon)]

    def indirect(s, g):
        s3 = hy.sum([c * c for c in s]) ** -1.5
        return [g * c * s3 for c in s]

    ind_moon, ind_sun = indirect(moon, gm_moon), indirect(sun, gm_sun)

    rot_kw = {"time_expr": tt_c, "thresh": iau2006_thresh, "eop_data": eop_data}
    sys = []
    for i in range(n_sat):
        x, y, z, vx, vy, vz = hy.make_vars(f"x{i}", f"y{i}", f"z{i}", f"vx{i}", f"vy{i}", f"vz{i}")
        r = [x, y, z]
        # Earth: monopole + EGM2008 degree/order n (heyoka's egm2008_acc
        # includes the central term), evaluated in the ITRS
        r_f = md.rot_icrs_itrs(r, **rot_kw)
        a_f = md.egm2008_acc(r_f, degree, degree, mu=gm, a=_R_EGM2008)
        acc = list(md.rot_itrs_icrs(a_f, **rot_kw))
        # Moon and Sun: direct - indirect
        for s, g, ind in ((moon, gm_moon, ind_moon), (sun, gm_sun, ind_sun)):
            d = [ri - si for ri, si in zip(r, s)]
            d3 = hy.sum([c * c for c in d]) ** -1.5
            acc = [a - g * dc * d3 - ic for a, dc, ic in zip(acc, d, ind)]
        sys += [(x, vx), (y, vy), (z, vz), (vx, acc[0]), (vy, acc[1]), (vz, acc[2])]
    return sys, {"moon": moon, "sun": sun}


def propagate_reduced_grid(r0, v0, epoch_tdb_jd, step, n_steps, *, gm="3.986004415e14", degree=12,
                           elp_thresh=ELP_THRESH, vsop_thresh=VSOP_THRESH, iau2006_thresh=IAU2006_THRESH,
                           gm_moon=_GM_MOON_DE431, gm_sun=_GM_SUN_DE431, tol=None, fp_type="real128",
                           compact_mode=True, eop_data=None):
    """Propagate N satellites under the reduced force model (Earth EGM2008
    degree/order ``degree`` + Moon + Sun point masses) with heyoka's Taylor
    integrator, all built from heyoka's own models, and return the states on
    the grid t_k = k*step, k = 0..n_steps (the force-model benchmark's peer).

    Model (one ``taylor_adaptive`` system, 6 N state variables; the
    time-only subexpressions -- ephemerides, rotation -- are shared):

    * Earth: ``heyoka.model.egm2008_acc`` (tide-free EGM2008, monopole
      included, GM = ``gm``, a = 6378136.3 m) at the ITRS position
      ``rot_icrs_itrs(r)``, rotated back with ``rot_itrs_icrs``: IAU
      2000/2006 precession-nutation truncated at ``iau2006_thresh`` arcsec
      (1e-4: X, Y within ~1 mas of ERFA's full ``xys06a`` over 2004), and the
      EOP (UT1-UTC, polar motion, dX, dY) of heyoka's **bundled**
      ``eop_data()`` (IERS finals2000A, nothing downloaded), piecewise
      linear in time.  The rotation's time argument is TT, formed as
      TDB - ``delta_tdb_tt`` (heyoka's periodic approximation, ~30 us).
    * Moon: ``elp2000_cartesian_fk5`` (ELP2000-82B, FK5 J2000 axes, km)
      rotated by the frame bias ``rot_fk5j2000_icrs`` to ICRS axes.
    * Sun: geocentric Sun = -(heliocentric Earth) =
      -(EMB from ``vsop2013_cartesian_icrf(3)``, ICRS axes, AU = 149597870700
      m) + GM_Moon/(GM_Earth + GM_Moon) * Moon (DE430 mass ratio).
    * Third bodies: a = -GM (d/|d|^3 + s/|s|^3), d = r - s, GMs ``gm_moon``,
      ``gm_sun`` (default: the DE430/DE431 values tqdyn uses).
    * Time: t = s TDB since the epoch; heyoka's series take Julian
      centuries (ELP2000) / millennia (VSOP2013) TDB from J2000:
      days = d0 + t/86400 with d0 = (jd1 - 2451545) + jd2 (exact in real128).

    Accuracy of the truncated series against DE421 (geocentric positions,
    90 days from 2004-06-06, 2001 samples; max / rms [m]):

    ===============  =============   ================  ===============
    ``elp_thresh``   Moon error      ``vsop_thresh``   Sun error
    ===============  =============   ================  ===============
    1e-6             5020 / 2840     1e-7              170000 / 93000
    1e-7             765 / 386       1e-8              28100 / 20000
    3e-8             327 / 157       1e-9              3220 / 2110
    1e-8 (default)   171 / 95        3e-10             2210 / 1080
    3e-9             122 / 78        1e-10 (default)   999 / 553
    0 (full series)  99 / 79
    ===============  =============   ================  ===============

    ELP2000-82B itself differs from DE421 by ~100 m (full series, mostly
    along-track): ~1 m lunar positions are out of reach of this theory.  A Moon position error dm changes the tidal
    acceleration at r = 1e5 km by ~3 GM_Moon r dm / d^4 ~ 7e-14 m/s^2 per
    metre (171 m: ~1e-11 m/s^2); a Sun error by ~8e-17 m/s^2 per metre
    (1 km: ~1e-13 m/s^2).  The Earth rotation agrees with tqdyn's IAU
    2006/2000A + EOP 14 C04 rotation to 3.5 mas (1.7e-8 rad) over the 90 days.

    Cost: the time-only series (ephemerides, rotation) dominate each Taylor
    step in real128, so coarser thresholds (e.g. elp_thresh=1e-7,
    vsop_thresh=1e-9) make it faster; ``tqdyn bench --model full`` measures
    it (the ``setup_s`` and ``wall_s`` returned here, with
    ``n_taylor_steps``).

    Parameters
    ----------
    r0, v0 : (N, 3) initial GCRS positions [m] / velocities [m/s] at t = 0,
        in any form :func:`to_real128` accepts (float64, dd pair, mpf, real128).
    epoch_tdb_jd : float or (jd1, jd2)
        TDB Julian date of t = 0 (e.g. ``Epoch.from_utc(...).tdb``).
    step, n_steps : grid spacing [s] and number of intervals.
    gm : str/float -- the EGM2008 field's GM [m^3/s^2] (decimal str exact).
    degree : int -- EGM2008 degree and order (0 = monopole only).
    elp_thresh, vsop_thresh, iau2006_thresh : series truncation thresholds.
    gm_moon, gm_sun : third-body GMs [m^3/s^2].
    tol : integrator tolerance (default: epsilon of fp_type).
    fp_type : "real128" or "float64".
    compact_mode : heyoka compact mode (needed: the system has thousands of
        time-only terms; non-compact JIT compile would take far longer).
    eop_data : a ``heyoka.eop_data`` (default: the bundled one).

    Returns
    -------
    dict with 'r_hi', 'r_lo', 'v_hi', 'v_lo' (n_steps+1, N, 3) float64
    (hi/lo split of the real128 states; lo = 0 for float64), 'wall_s' (the
    ``propagate_grid`` call only), 'setup_s' (building the expressions and
    JIT-compiling the integrator), 'n_taylor_steps', 'order', 'tol',
    'fp_type', 'thresholds'.
    """
    hy = _heyoka()
    R = hy.real128
    if fp_type in ("real128", R):
        dtype = R
    elif fp_type in ("float64", float, np.float64):
        dtype = np.float64
    else:
        raise ValueError(f"fp_type must be 'real128' or 'float64', got {fp_type!r}")
    n_steps = int(n_steps)
    if n_steps < 0:
        raise ValueError("n_steps must be >= 0")
    degree = int(degree)
    state, n_sat = _state_array(r0, v0, dtype, R)

    d0 = _epoch_days(epoch_tdb_jd, R)
    if dtype is R:
        pars = np.array([_scalar_to_real128(gm, R), _scalar_to_real128(gm_moon, R),
                         _scalar_to_real128(gm_sun, R), d0], dtype=R)
        step_v = _scalar_to_real128(step, R)
    else:
        pars = np.array([float(gm), float(gm_moon), float(gm_sun), float(d0)], dtype=np.float64)
        step_v = float(step)
    if eop_data is None:
        eop_data = hy.eop_data()

    t0 = time.perf_counter()
    sys, _ = _reduced_system(hy, n_sat, degree, float(elp_thresh), float(vsop_thresh),
                             float(iau2006_thresh), eop_data)
    kwargs = {"fp_type": dtype, "compact_mode": compact_mode, "pars": pars}
    if tol is not None:
        kwargs["tol"] = _scalar_to_real128(tol, R) if dtype is R else float(tol)
    ta = hy.taylor_adaptive(sys, state, **kwargs)
    setup_s = time.perf_counter() - t0

    out = _grid_outputs(hy, ta, dtype, n_sat, step_v, n_steps)
    out["setup_s"] = float(setup_s)
    out["thresholds"] = {"elp2000": float(elp_thresh), "vsop2013": float(vsop_thresh),
                         "iau2006": float(iau2006_thresh)}
    return out
