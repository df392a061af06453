"""LISA orbit files (format 2.x of lisaorbits): the layout and its writer (I/O only).

LISA's simulation chain (lisainstrument, pytdi, lisagwresponse) reads the
HDF5 "orbit files" written by ``lisaorbits``.  This module writes the same
layout (:func:`write_lisa_orbits`), so that those tools can take a TianQin (or
any tqdyn) constellation as input; :func:`tqdyn.workflows.export.export_lisa`
fills it from a tqdyn trajectory with the quantities computed by
:func:`tqdyn.lightpath.proper_time.lisa_orbit_quantities`.  The layout, read from the sources of
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
* Coordinate time: tqdyn's t, TT seconds since the trajectory's
  ``epoch_utc`` (``t0`` is therefore a few seconds, not a TCB date).
* ltt: solved iteratively in double-double by :mod:`tqdyn.lightpath`
  between the test masses (TM of satellite i facing j <- TM of j facing i)
  when the trajectory has them, else between the satellites' centres of
  mass (attribute ``ltt_endpoints``); Earth Shapiro delay only if asked.
* Proper times, ppr and the tps group: as defined (and computed) by
  :mod:`tqdyn.lightpath.proper_time`.
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

import pathlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..astro.timescales import TCB_ORIGINS, tcb_jd_of_epoch
from ..lightpath.lisa_bcrs import BCRS_AXES
from . import trajectory as _io
from .atomic import replacing_h5

__all__ = [
    "AXES",
    "FRAMES",
    "GCRS_FRAME_NOTE",
    "GCRS_TIME_NOTE",
    "GCRS_TPS_DEFINITION",
    "TIME_ORIGINS",
    "LISA_LINK_ORDER",
    "tcb_jd_of_epoch",
    "time_convention",
    "uniform_grid",
    "LISA_ORBIT_FORMAT_VERSION",
    "write_lisa_orbits",
]

LISA_ORBIT_FORMAT_VERSION = "2.3"
"""Value of the root attribute ``version``: the lisaorbits 2.x file layout
(lisainstrument accepts "2.*"; pytdi and lisaorbits warn above 2.3)."""

LISA_LINK_ORDER = (12, 23, 31, 13, 32, 21)
"""Column order of the link datasets: "ij" = received by i, emitted by j (= tqdyn's Link order)."""

_UNIFORM_TOL_S = 1e-6  # max deviation of a grid time from t0 + k dt [s]

# root attributes of a GCRS/TT file (tqdyn's geocentric variant of the format): what tps, frame and time mean
GCRS_TPS_DEFINITION = (
    "proper time of each satellite's centre of mass against the coordinate time TT: d tau/dTT = (1 - (GM_E/r + "
    "v^2/2)/c^2) / (1 - L_G), L_G = 6.969290134e-10, along the tqdyn orbit (GM_E = attribute gm_earth); not "
    "applied: the tidal potentials of Moon and Sun (~1e-17); delta_tau = 0 at t_init")
GCRS_FRAME_NOTE = "GCRS (geocentric, ICRF axes) of tqdyn -- not the BCRS of LISA orbit files; group 'tcb' kept for readers"
GCRS_TIME_NOTE = ("tqdyn coordinate time t: TT seconds since epoch_utc (used in place of TCB); "
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


# ------------------------------------------------------------------ BCRS files: frames and time origins

#: Frames of ``export_lisa(frame=...)``: "gcrs" (the trajectory's own geocentric GCRS and TT; geocentric runs
#: only) or "bcrs" (barycentric, TCB).
FRAMES = ("gcrs", "bcrs")
#: Axes of a BCRS file (:data:`tqdyn.lightpath.lisa_bcrs.BCRS_AXES`): "icrf" or "ecliptic" (IAU 2006 mean
#: ecliptic and equinox of J2000, the axes of lisaorbits' files).
AXES = BCRS_AXES
#: Origins of the TCB time axis of a BCRS file (``t = t0 + k dt``; :func:`tqdyn.astro.timescales.tcb_origin_offset`).
TIME_ORIGINS = TCB_ORIGINS

_TIME_CONVENTIONS = {
    "epoch": "t = TCB seconds since the trajectory epoch's TCB instant (attributes epoch_tcb_jd1 + epoch_tcb_jd2), "
             "as lisaorbits' analytic orbits count TCB seconds from their t_init (default 0)",
    "j2000": "t = TCB seconds since J2000.0 TCB (JD 2451545.0 TCB); a float64 t near 1e9 s resolves 2.4e-7 s",
    "unix": "t0 = the Unix time of the first sample's TCB instant (astropy Time(..., scale='tcb').unix: seconds since "
            "1970-01-01T00:00:00 UTC, leap seconds not counted), as lisaorbits' OEMOrbits dates its samples; the "
            "samples t0 + k dt are TCB seconds after it (a Unix stamp at t0 only); a float64 t near 2e9 s resolves "
            "4.8e-7 s",
}


def time_convention(origin: str) -> str:
    """The sentence (attribute ``t0_convention``) that states what t of a BCRS file counts from ``origin``
    (one of :data:`TIME_ORIGINS`)."""
    return _TIME_CONVENTIONS[origin]


# ------------------------------------------------------------------ writer

def uniform_grid(t, name: str = "t") -> tuple[float, float]:
    """(t0, dt) [s] of a uniform time grid t0 + k dt: ``t`` an (N,) array or a
    dd pair (hi, lo), N >= 2, each time within 1e-6 s of the grid; else a
    one-line ValueError naming ``name``."""
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
                      extra: Mapping[str, np.ndarray] | None = None, frame_label: str = "GCRS") -> pathlib.Path:
    """Write a LISA orbit file (layout 2.x, see the module docstring), atomically.

    Parameters (N samples; float64; link axis in the order 12, 23, 31, 13,
    32, 21 with "ij" received by i from j; spacecraft axis 1, 2, 3)
    ----------
    path : str or os.PathLike
        Destination (checked with :func:`tqdyn.formats.trajectory.check_writable`; an
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
    frame_label : str
        The frame named in the vector datasets' ``description`` attributes
        (default "GCRS"; "BCRS" for barycentric files).

    Every array must be finite (lisainstrument rejects NaN).  Returns the
    absolute path written.  Raises ValueError (bad input, naming the field)
    or :class:`tqdyn.formats.trajectory.OutputError` (path not writable).
    """
    out = _io.check_writable(path)
    t0, dt = uniform_grid(t)
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

    with replacing_h5(out, "LISA orbit file") as h5:
        for key, val in root.items():
            h5.attrs[key] = val
        for name, arr in arrays.items():
            ds = h5.create_dataset(name, data=arr)
            if name in _DATASETS:
                ds.attrs["units"] = _DATASETS[name][1]
                ds.attrs["description"] = _DATASETS[name][2].replace("GCRS", frame_label)
    return out

