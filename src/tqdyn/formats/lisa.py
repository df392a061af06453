"""Export a tqdyn trajectory as a LISA orbit file (format 2.x of lisaorbits).

LISA's simulation chain (lisainstrument, pytdi, lisagwresponse) reads the
HDF5 "orbit files" written by ``lisaorbits``.  This module writes the same
layout from a tqdyn trajectory, so that those tools can take a TianQin (or
any tqdyn) constellation as input.  The layout, read from the sources of
lisaorbits 2.4.2 (``Orbits.write``), lisainstrument 2.3.0
(``orbiting/orbit_file.py``, ``OrbitFileV2``) and pytdi 2.2.1
(``Data.from_orbits``):

root attributes
    ``version`` (str, ``"2.3"``: the orbit-file format version; readers
    accept "2.*"), ``t0`` [s], ``dt`` [s], ``size`` (int): the samples are at
    ``t0 + k dt``, k = 0 .. size-1; plus descriptive attributes (below).
``tcb/x``, ``tcb/v``, ``tcb/a`` (size, 3, 3)
    satellite positions [m], velocities [m/s], accelerations [m/s^2]
    [time, spacecraft 1..3, xyz].
``tcb/delta_tau`` (size, 3)
    proper-time deviation tau_i(t) - t of each satellite [s].
``tcb/n`` (size, 6, 3)
    unit vector of each link from the emitter at t - ltt to the receiver at t.
``tcb/ltt``, ``tcb/d_ltt``, ``tcb/ppr``, ``tcb/d_ppr`` (size, 6)
    light travel time [s], its rate [s/s], proper pseudorange [s] and its
    rate per unit receiver proper time [s/s], at the coordinate times t.
``tps/delta_t`` (size, 3)
    t(tau) - tau: coordinate time minus proper time at the proper times
    tau = t0 + k dt of each satellite [s].
``tps/ppr``, ``tps/d_ppr`` (size, 6)
    PPR and its rate at the receiver's proper times tau = t0 + k dt.

Link order: 12, 23, 31, 13, 32, 21, where "ij" is received by spacecraft i
and emitted by spacecraft j -- the same convention and order as tqdyn's
:class:`~tqdyn.constellation.indices.Link` (``Link.index`` is the column).
lisainstrument reads ``tcb/ltt`` + ``tcb/d_ltt`` (orbit_dataset "tcb/ltt")
or ``tps/ppr`` + ``tps/d_ppr`` + ``tcb/delta_tau`` ("tps/ppr", its default)
and integrates the rate from the first sample; pytdi reads ``tps/ppr`` or
``tcb/ltt``.  Every value must be finite (lisainstrument rejects NaN).

What the quantities mean for a geocentric constellation (stated in the
file's attributes too)
--------------------------------------------------------------------------
* Frame: the GCRS (geocentric, ICRF axes) of tqdyn -- NOT the BCRS of LISA
  orbit files.  The group name ``tcb`` is kept because readers look for it.
* Coordinate time: tqdyn's t, TDB seconds since the trajectory's
  ``epoch_utc`` (``t0`` is therefore a few seconds, not a TCB date).
* ltt: solved iteratively in double-double by :mod:`tqdyn.lightpath`
  between the test masses (TM of satellite i facing j <- TM of j facing i)
  when the trajectory has them, else between the satellites' centres of
  mass (attribute ``ltt_endpoints``); Earth Shapiro delay only if asked.
* Proper time: each satellite's clock (centre of mass) with
  d tau_i / dt = 1 - (GM_E / r_i + v_i^2 / 2) / c^2, GM_E the trajectory's
  Earth GM, integrated along the orbit with the end-corrected trapezoidal
  rule (derivative of the integrand from r, v, a; error ~1e-24 s per step)
  from delta_tau = 0 at the trajectory's first sample (``t_init``).  t is
  treated as the geocentric coordinate time TCG: the secular rate
  L_G = 6.969290134e-10 between TCG and TT/TDB, the periodic TDB - TT terms
  (~1.7 ms, annual) and the tidal potentials of Moon and Sun (~1e-17
  relative) are NOT applied; they are (nearly) common to the three clocks.
* ppr = ltt + delta_tau_recv(t) - delta_tau_emit(t - ltt) (delta_tau_emit
  at the emission time from its Taylor series, error < 1e-21 s);
  d_ppr = (dtau_r - dtau_e + d_ltt (1 + dtau_e)) / (1 + dtau_r) with
  dtau = d(delta_tau)/dt, exactly as lisaorbits defines it.
* tps/*: the coordinate time of proper time tau = t_k is t_k + delta_t with
  delta_t = -delta_tau(t_k + delta_t) (two iterations); tps/ppr and
  tps/d_ppr are the TCB-sampled values moved by delta_t with their first
  derivatives (|delta_t| ~ 5e-4 s after 90 days; the neglected second-order
  terms are < 1e-19 s).
* Samples: the trajectory's grid (uniform) minus the leading rows whose
  emission time t - ltt precedes the first sample (normally the first row).
* Precision: the format stores float64 (ulp of ltt ~ 0.58 s is 1.1e-16 s,
  i.e. 33 nm of range).  The dd remainder of ltt is kept in the extra
  dataset ``tqdyn/ltt_lo`` (value = tcb/ltt + tqdyn/ltt_lo) for pm work.

Writing is atomic: a hidden temporary file in the destination directory is
renamed into place when complete; on any error it is removed and an existing
file at the destination is left untouched.
"""

from __future__ import annotations

import os
import pathlib
import secrets
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import h5py
import numpy as np
from numba import njit

from .. import __version__ as _TQDYN_VERSION
from . import trajectory as _io
from ..astro.constants import C_LIGHT, GM_EARTH_EGM2008
from ..constellation.indices import LINKS
from ..lightpath.light_time import LightTravelTimes, light_travel_times_of

__all__ = [
    "LISA_LINK_ORDER",
    "LISA_ORBIT_FORMAT_VERSION",
    "LisaExport",
    "export_lisa",
    "lisa_orbit_quantities",
    "proper_time_deviation",
    "write_lisa_orbits",
]

LISA_ORBIT_FORMAT_VERSION = "2.3"
"""Value of the root attribute ``version``: the lisaorbits 2.x file layout
(lisainstrument accepts "2.*"; pytdi and lisaorbits warn above 2.3)."""

LISA_LINK_ORDER = (12, 23, 31, 13, 32, 21)
"""Column order of the link datasets: "ij" = received by i, emitted by j (= tqdyn's Link order)."""

_RECV = np.array([ln.receiver.index for ln in LINKS], dtype=np.intp)
_EMIT = np.array([ln.emitter.index for ln in LINKS], dtype=np.intp)

_UNIFORM_TOL_S = 1e-6  # max deviation of a grid time from t0 + k dt [s]

# reserved root attributes (set by the writer) and their meaning
_TPS_DEFINITION = (
    "proper time of each satellite's centre of mass: d tau/dt = 1 - (GM_E/r + v^2/2)/c^2 along the tqdyn orbit "
    "(GM_E = attribute gm_earth), t taken as the geocentric coordinate time (TCG); not applied: the TCG - TT/TDB "
    "rate L_G = 6.969290134e-10, the periodic TDB - TT terms, the tidal potentials of Moon and Sun; "
    "delta_tau = 0 at t_init")
_FRAME = "GCRS (geocentric, ICRF axes) of tqdyn -- not the BCRS of LISA orbit files; group 'tcb' kept for readers"
_TIME = ("tqdyn coordinate time t: TDB seconds since epoch_utc (used in place of TCB); "
         "tps/* are sampled at each receiver's proper time tau = t0 + k dt")

_DATASETS = {
    # name: (trailing shape, units, description)
    "tcb/x": ((3, 3), "m", "satellite centre-of-mass positions, GCRS [time, spacecraft 1..3, xyz]"),
    "tcb/v": ((3, 3), "m/s", "satellite centre-of-mass velocities, GCRS"),
    "tcb/a": ((3, 3), "m/s^2", "satellite accelerations (gravity + drag-free control, if any), GCRS"),
    "tcb/delta_tau": ((3,), "s", "proper-time deviation tau_i(t) - t of each satellite"),
    "tcb/n": ((6, 3), "1", "unit vector from the emitter at t - ltt to the receiver at t, GCRS, links 12 ... 21"),
    "tcb/ltt": ((6,), "s", "light travel time, links 12, 23, 31, 13, 32, 21 (ij: received by i from j)"),
    "tcb/d_ltt": ((6,), "s/s", "d ltt / dt"),
    "tcb/ppr": ((6,), "s", "proper pseudorange tau_recv(t) - tau_emit(t - ltt), sampled at coordinate time t"),
    "tcb/d_ppr": ((6,), "s/s", "d ppr / d tau_recv, sampled at coordinate time t"),
    "tps/delta_t": ((3,), "s", "t(tau) - tau at each satellite's proper times tau = t0 + k dt"),
    "tps/ppr": ((6,), "s", "proper pseudorange at the receiver's proper times tau = t0 + k dt"),
    "tps/d_ppr": ((6,), "s/s", "d ppr / d tau_recv at the receiver's proper times tau = t0 + k dt"),
}
_RESERVED_ATTRS = ("version", "t0", "dt", "size")


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

    d tau/dt = 1 - f with f = (GM/|r| + |v|^2/2) / c^2 (geocentric, the
    Earth's monopole; t is taken as the geocentric coordinate time),
    integrated with the end-corrected trapezoidal rule
    int_k^{k+1} f = h (f_k + f_{k+1}) / 2 + h^2 (f'_k - f'_{k+1}) / 12,
    f' = (-GM r.v/|r|^3 + v.a) / c^2 (error h^5 f''''/720 per step, ~1e-24 s
    at 50 s on TianQin's orbit), summed with compensation; delta_tau = 0 at
    the first sample.

    t: (N,) grid times [s] (float64, or a dd (hi, lo) pair); r, v, a: (N, B,
    3) positions [m], velocities [m/s], accelerations [m/s^2] (float64, GCRS)
    of B clocks; gm [m^3/s^2] (default :data:`tqdyn.constants.GM_EARTH_EGM2008`).
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
    f = (gm / rn + 0.5 * np.einsum("...k,...k->...", v, v)) / C_LIGHT ** 2
    fd = (-gm * np.einsum("...k,...k->...", r, v) / rn ** 3 + np.einsum("...k,...k->...", v, a)) / C_LIGHT ** 2
    hh = h[:, None]
    inc = hh * 0.5 * (f[:-1] + f[1:]) + hh * hh / 12.0 * (fd[:-1] - fd[1:])
    out = np.empty_like(f)
    _dd_cumsum(np.ascontiguousarray(-inc), out)
    return out, -f, -fd


# ------------------------------------------------------------------ the quantities

def lisa_orbit_quantities(t, sat_r, sat_v, sat_a, lp: LightTravelTimes, gm: float | None = None) -> dict[str, Any]:
    """All datasets of a LISA orbit file from a tqdyn trajectory's arrays.

    t: dd (hi, lo) grid times (N,) [s, TDB]; sat_r, sat_v, sat_a: (N, 3, 3)
    satellite positions [m] (float64 or dd (hi, lo)), velocities [m/s],
    total accelerations [m/s^2], GCRS; lp: the light travel times on the
    same grid (:func:`tqdyn.lightpath.light_travel_times`); gm: Earth GM for
    the proper times [m^3/s^2].  Definitions: see the module docstring.

    Returns a dict with ``t`` (N,) float64 and the arrays of :data:`_DATASETS`
    (keys ``"tcb/x"`` ...) for all N rows (rows without a light travel time
    are NaN), plus ``ltt_lo`` (N, 6) (dd remainder of tcb/ltt) and
    ``t_init`` (float, where delta_tau = 0).
    """
    th, tl = (np.asarray(p, np.float64) for p in t)

    def f64(x):
        return x[0] + x[1] if isinstance(x, tuple) else np.asarray(x, np.float64)

    x, v, a = f64(sat_r), f64(sat_v), np.asarray(sat_a, np.float64)
    dtau, rate, rate_dot = proper_time_deviation((th, tl), x, v, a, gm)
    ltt = lp.tau[0] + lp.tau[1]
    ltt_lo = lp.tau[1] - (ltt - lp.tau[0])
    d_ltt = lp.tau_rate
    # receiver clock at t, emitter clock at t - ltt (Taylor series about the grid time t)
    dt_r, rate_r = dtau[:, _RECV], rate[:, _RECV]
    dt_e = dtau[:, _EMIT] - ltt * rate[:, _EMIT] + 0.5 * ltt ** 2 * rate_dot[:, _EMIT]
    rate_e = rate[:, _EMIT] - ltt * rate_dot[:, _EMIT]
    ppr = lp.tau[0] + (lp.tau[1] + (dt_r - dt_e))
    d_ppr = (rate_r - rate_e + d_ltt * (1.0 + rate_e)) / (1.0 + rate_r)
    # proper-time grid: coordinate time of tau = t_k is t_k + delta_t, delta_t = -delta_tau(t_k + delta_t)
    delta_t = -dtau
    delta_t = -(dtau + rate * delta_t)
    shift = delta_t[:, _RECV]
    tgrid = th + tl
    # d(d_ppr)/dt by second-order finite differences over the rows that have a light travel time
    d_ppr_dt = np.full_like(d_ppr, np.nan)
    ok = np.all(np.isfinite(d_ppr), axis=1)
    i0 = int(np.argmax(ok)) if ok.any() else ok.size
    if ok.size - i0 >= 3 and ok[i0:].all():
        d_ppr_dt[i0:] = np.gradient(d_ppr[i0:], tgrid[i0:], axis=0, edge_order=2)
    tps_ppr = ppr + shift * d_ppr * (1.0 + rate_r)
    tps_d_ppr = d_ppr + shift * d_ppr_dt
    return {
        "t": tgrid, "t_init": float(tgrid[0]),
        "tcb/x": x, "tcb/v": v, "tcb/a": a, "tcb/delta_tau": dtau, "tcb/n": lp.unit_vectors,
        "tcb/ltt": ltt, "tcb/d_ltt": d_ltt, "tcb/ppr": ppr, "tcb/d_ppr": d_ppr,
        "tps/delta_t": delta_t, "tps/ppr": tps_ppr, "tps/d_ppr": tps_d_ppr, "ltt_lo": ltt_lo,
    }


# ------------------------------------------------------------------ writer

def _uniform_grid(t, name: str = "t") -> tuple[float, float]:
    tt = (t[0] + t[1]) if isinstance(t, tuple) else np.asarray(t, np.float64)
    tt = np.asarray(tt, np.float64)
    if tt.ndim != 1 or tt.size < 2:
        raise ValueError(f"{name}: needs shape (N,) with N >= 2 samples, got shape {tt.shape}")
    if not np.all(np.isfinite(tt)):
        raise ValueError(f"{name}: times must be finite")
    t0 = float(tt[0])
    dt = float((tt[-1] - tt[0]) / (tt.size - 1))
    if not dt > 0:
        raise ValueError(f"{name}: times must increase, got t[0] = {t0!r} s, t[-1] = {float(tt[-1])!r} s")
    dev = np.abs(tt - (t0 + np.arange(tt.size) * dt))
    k = int(np.argmax(dev))
    if dev[k] > _UNIFORM_TOL_S:
        raise ValueError(f"{name}: LISA orbit files need a uniform grid t0 + k dt; t[{k}] = {float(tt[k])!r} s "
                         f"deviates by {dev[k]:.3g} s from t0 + {k} * {dt!r} s (allowed: <= {_UNIFORM_TOL_S} s)")
    return t0, dt


def _attr_value(key: str, val):
    if isinstance(val, (bool, np.bool_)):
        return np.bool_(val)
    if isinstance(val, np.generic):
        val = val.item()
    if isinstance(val, (str, int, float)):
        return val
    raise ValueError(f"attrs[{key!r}]: must be str, int, float or bool, got {type(val).__name__}")


def write_lisa_orbits(path, t, x, v, a, ltt, d_ltt, n, ppr, d_ppr, *, delta_tau, tps_ppr, tps_d_ppr,
                      tps_delta_t, attrs: Mapping[str, Any] | None = None,
                      extra: Mapping[str, np.ndarray] | None = None) -> pathlib.Path:
    """Write a LISA orbit file (layout 2.x, see the module docstring), atomically.

    Parameters (N samples; float64; link axis in the order 12, 23, 31, 13,
    32, 21 with "ij" received by i from j; spacecraft axis 1, 2, 3)
    ----------
    path : str or os.PathLike
        Destination (checked with :func:`tqdyn.io.check_writable`; an
        existing file is replaced only when the new one is complete).
    t : (N,)
        Coordinate times [s] (float64 or a dd (hi, lo) pair); must be a
        uniform grid t0 + k dt (within 1e-6 s) -> root attributes t0, dt, size.
    x, v, a : (N, 3, 3)
        Satellite positions [m], velocities [m/s], accelerations [m/s^2].
    ltt, d_ltt : (N, 6)
        Light travel times [s] and their rates [s/s].
    n : (N, 6, 3)
        Unit vectors from emitter to receiver.
    ppr, d_ppr : (N, 6)
        Proper pseudoranges [s] and rates [s/s] at the coordinate times t.
    delta_tau : (N, 3)
        Proper-time deviations tau - t [s] at the coordinate times t.
    tps_ppr, tps_d_ppr : (N, 6)
        PPR [s] and rate [s/s] at the receivers' proper times t0 + k dt.
    tps_delta_t : (N, 3)
        t(tau) - tau [s] at the proper times t0 + k dt.
    attrs : mapping, optional
        Extra root attributes (str, int, float or bool); ``version``, ``t0``,
        ``dt`` and ``size`` are set by the writer and may not be given.
    extra : mapping, optional
        Extra float64 datasets (any path not used by the format, e.g.
        ``"tqdyn/ltt_lo"``), each with N rows.

    Every array must be finite (lisainstrument rejects NaN).  Returns the
    absolute path written.  Raises ValueError (bad input, naming the field)
    or :class:`tqdyn.io.OutputError` (path not writable).
    """
    out = _io.check_writable(path)
    t0, dt = _uniform_grid(t)
    N = (t[0] if isinstance(t, tuple) else np.asarray(t)).shape[0]
    data = {"tcb/x": x, "tcb/v": v, "tcb/a": a, "tcb/delta_tau": delta_tau, "tcb/n": n, "tcb/ltt": ltt,
            "tcb/d_ltt": d_ltt, "tcb/ppr": ppr, "tcb/d_ppr": d_ppr, "tps/delta_t": tps_delta_t,
            "tps/ppr": tps_ppr, "tps/d_ppr": tps_d_ppr}
    arrays = {}
    for name, (trail, _, _) in _DATASETS.items():
        arr = np.asarray(data[name])
        if arr.dtype.kind not in "fiu":
            raise ValueError(f"{name}: dtype {arr.dtype} is not real numeric (float64 expected)")
        arr = np.ascontiguousarray(arr, dtype=np.float64)
        if arr.shape != (N,) + trail:
            raise ValueError(f"{name}: shape {arr.shape}, expected {(N,) + trail} (N = {N} samples of t)")
        bad = np.argwhere(~np.isfinite(arr))
        if bad.size:
            raise ValueError(f"{name}: non-finite value at index {tuple(int(i) for i in bad[0])}; LISA orbit files "
                             "must be finite (lisainstrument rejects NaN)")
        arrays[name] = arr
    for name, arr in (extra or {}).items():
        if name in _DATASETS or not isinstance(name, str) or not name or name.startswith("/"):
            raise ValueError(f"extra: dataset name {name!r} is not allowed (must be a new relative HDF5 path)")
        arr = np.ascontiguousarray(np.asarray(arr, dtype=np.float64))
        if arr.ndim < 1 or arr.shape[0] != N:
            raise ValueError(f"extra[{name!r}]: shape {arr.shape} needs {N} rows")
        arrays[name] = arr
    root = {}
    for key, val in (attrs or {}).items():
        if not isinstance(key, str) or not key:
            raise ValueError(f"attrs: attribute names must be non-empty str, got {key!r}")
        if key in _RESERVED_ATTRS:
            raise ValueError(f"attrs[{key!r}]: set by the writer; not allowed in attrs "
                             f"(reserved: {', '.join(_RESERVED_ATTRS)})")
        root[key] = _attr_value(key, val)
    root.update(version=LISA_ORBIT_FORMAT_VERSION, t0=float(t0), dt=float(dt), size=int(N))

    tmp = out.parent / f".{out.name}.{secrets.token_hex(6)}.tmp"
    try:
        with h5py.File(tmp, "x") as h5:
            for key, val in root.items():
                h5.attrs[key] = val
            for name, arr in arrays.items():
                ds = h5.create_dataset(name, data=arr)
                if name in _DATASETS:
                    ds.attrs["units"] = _DATASETS[name][1]
                    ds.attrs["description"] = _DATASETS[name][2]
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, out)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if isinstance(exc, OSError) and not isinstance(exc, _io.OutputError):
            raise _io.OutputError(f"cannot write LISA orbit file {str(out)!r}: {exc}") from None
        raise
    return out


# ------------------------------------------------------------------ trajectory adapter

@dataclass(frozen=True)
class LisaExport:
    """Summary of one export: ``path`` written; ``size`` samples from ``t0``
    every ``dt`` [s, TDB since ``epoch_utc``]; ``dropped_rows`` leading rows
    without an emission time inside the trajectory; ``source`` "tm" | "sat"
    and ``note`` (light-path endpoints); ``ltt_range`` (min, max) [s];
    ``shapiro`` whether the Earth Shapiro delay is included."""

    path: pathlib.Path
    size: int
    t0: float
    dt: float
    dropped_rows: int
    source: str
    note: str
    ltt_range: tuple[float, float]
    shapiro: bool


def _scenario_gm(toml_text: str) -> float | None:
    """forces.gm_earth of a resolved scenario TOML, or None."""
    try:
        raw = tomllib.loads(toml_text or "")
        gm = raw.get("forces", {}).get("gm_earth")
        return float(gm) if gm is not None else None
    except (tomllib.TOMLDecodeError, TypeError, ValueError, AttributeError):
        return None


def export_lisa(trajectory, out_path, *, shapiro: bool = False, gm: float | None = None) -> LisaExport:
    """Export a tqdyn trajectory (file path or :class:`tqdyn.io.Trajectory`) to a LISA orbit file.

    Light travel times come from :func:`tqdyn.lightpath.light_travel_times_of`
    (test mass to test mass if the trajectory has ``tm/r``, ``tm/v``,
    ``tm/a``; satellite centres otherwise); satellite states from ``sat/r``,
    ``sat/v``, ``sat/a_gravity`` (+ ``sat/a_dragfree``); proper times with
    the Earth GM ``gm`` (default: the trajectory scenario's
    ``forces.gm_earth``, else :data:`tqdyn.constants.GM_EARTH_EGM2008`).
    The grid must be uniform and hold 3 satellites.  Leading rows whose
    emission time precedes the first sample are dropped (normally one).
    ``shapiro``: include the Earth's Shapiro delay in ltt.

    Returns a :class:`LisaExport`.  Raises FileNotFoundError (no input
    file), ValueError (:class:`tqdyn.io.TrajectoryFormatError` or unusable
    content, naming the field) or :class:`tqdyn.io.OutputError`.
    """
    if isinstance(trajectory, (str, os.PathLike)):
        traj = _io.read_trajectory(trajectory)
        src = str(traj.path)
    else:
        traj = trajectory
        src = str(getattr(trajectory, "path", ""))
    out = _io.check_writable(out_path)
    if src and out.exists() and os.path.exists(src) and os.path.samefile(src, out):
        raise ValueError(f"output {str(out)!r} is the input trajectory; choose another output path")
    if traj.n_sat != 3:
        raise ValueError(f"{src}: n_sat = {traj.n_sat}; a LISA orbit file needs 3 satellites")
    for f in ("t", "sat/r", "sat/v", "sat/a_gravity"):
        if f not in traj:
            raise ValueError(f"{src}: has no field {f!r} (needed for the LISA export)")
    if len(traj) < 3:
        raise ValueError(f"{src}: {len(traj)} time rows; the LISA export needs at least 3")
    t = traj.dd("t")
    _uniform_grid(t, f"{src}: t")
    attrs = dict(getattr(traj, "attrs", {}) or {})
    gm_v = gm if gm is not None else _scenario_gm(str(attrs.get("scenario", "")))
    gm_v = float(GM_EARTH_EGM2008) if gm_v is None else float(gm_v)
    lp = light_travel_times_of(traj, shapiro=shapiro, gm=gm_v)
    sat_a = np.asarray(traj["sat/a_gravity"], np.float64)
    if "sat/a_dragfree" in traj:
        sat_a = sat_a + np.asarray(traj["sat/a_dragfree"], np.float64)
    q = lisa_orbit_quantities(t, traj.dd("sat/r"), traj.dd("sat/v"), sat_a, lp, gm_v)
    valid = np.all(np.isfinite(q["tcb/ltt"]), axis=1)
    i0 = int(np.argmax(valid)) if valid.any() else len(valid)
    if i0 >= len(valid) - 1 or not valid[i0:].all():
        raise ValueError(f"{src}: light travel times undefined beyond the leading rows; cannot export")
    sl = slice(i0, None)
    endpoints = ("test masses (TM of satellite i facing j <- TM of satellite j facing i)" if lp.source == "tm"
                 else "satellite centres of mass (the trajectory has no test-mass fields)")
    meta = {
        "generator": "tqdyn.formats.lisa",
        "tqdyn_version": _TQDYN_VERSION,
        "frame": _FRAME,
        "time_scale": _TIME,
        "epoch_utc": str(attrs.get("epoch_utc", "")),
        "t_init": q["t_init"],
        "tt_method": "iterative (Newton, double-double, quintic Hermite dense output of the emitter)",
        "ignore_shapiro": not shapiro,
        "ltt_endpoints": endpoints,
        "ltt_note": lp.note,
        "link_order": "12, 23, 31, 13, 32, 21 (ij: received by spacecraft i, emitted by spacecraft j)",
        "tps_definition": _TPS_DEFINITION,
        "gm_earth": gm_v,
        "dropped_rows": i0,
        "precision_note": "float64 datasets; dd remainder of tcb/ltt in tqdyn/ltt_lo (ltt = tcb/ltt + tqdyn/ltt_lo)",
        "source_trajectory": src,
        "tqdyn_scenario": str(attrs.get("scenario", "")),
    }
    path = write_lisa_orbits(
        out, q["t"][sl], q["tcb/x"][sl], q["tcb/v"][sl], q["tcb/a"][sl], q["tcb/ltt"][sl], q["tcb/d_ltt"][sl],
        q["tcb/n"][sl], q["tcb/ppr"][sl], q["tcb/d_ppr"][sl], delta_tau=q["tcb/delta_tau"][sl],
        tps_ppr=q["tps/ppr"][sl], tps_d_ppr=q["tps/d_ppr"][sl], tps_delta_t=q["tps/delta_t"][sl],
        attrs=meta, extra={"tqdyn/ltt_lo": q["ltt_lo"][sl]})
    t0, dt = _uniform_grid(q["t"][sl])
    ltt = q["tcb/ltt"][sl]
    return LisaExport(path=path, size=int(ltt.shape[0]), t0=t0, dt=dt, dropped_rows=i0, source=lp.source,
                      note=lp.note, ltt_range=(float(ltt.min()), float(ltt.max())), shapiro=bool(shapiro))
