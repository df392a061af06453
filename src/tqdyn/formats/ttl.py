"""LISA Instrument's TTL coefficient file: writer and reader (I/O only; docs/tilt-to-length.md).

The layout is exactly that of LISA Instrument 2.3's ``lisainstrument.ttl.ttl_file_writer.create_ttl_file``
(read by ``ttl_file_reader.load_ttl_file`` when an ``Instrument`` is given ``ttl_coeffs=("file", path)``):

* root attribute ``interpolation_order`` (int, 3 or 5): degree of the interpolating spline
  (scipy ``InterpolatedUnivariateSpline``, ``ext="raise"``) through the samples;
* dataset ``t`` (n,) [s]: the sample times, strictly increasing (LISA Instrument evaluates the spline
  at its ``physics_t`` = its ``t0`` + k ``physics_dt``, the time axis of its orbit input);
* datasets ``c_<mosa>_phi_rx``, ``c_<mosa>_phi_tx``, ``c_<mosa>_eta_rx``, ``c_<mosa>_eta_tx`` (n,)
  [m/rad] for each MOSA of :data:`tqdyn.ttl.coupling.MOSAS`: the local (rx) and distant (tx) yaw and
  pitch coefficients (tqdyn's ``local_phi``, ``distant_phi``, ``local_eta``, ``distant_eta``); LZF
  compressed, float64.

tqdyn adds root attributes that LISA Instrument ignores (:data:`TQDYN_ATTRS`).  The file is written to a
hidden temporary file beside the output and renamed into place when complete
(:func:`tqdyn.formats.atomic.replacing_h5`): an error, a full disk or Ctrl-C leaves the output path as it
was.  Units SI.
"""

from __future__ import annotations

import pathlib
from dataclasses import dataclass

import h5py
import numpy as np

from .._choices import unknown
from .._version import __version__ as _TQDYN_VERSION
from ..ttl.coupling import LINEAR_FIELDS, MOSAS
from .atomic import replacing_h5
from .trajectory import check_writable

__all__ = ["DATASET_SUFFIX", "ORDERS", "TQDYN_ATTRS", "TTLFile", "TTLFileError", "read_ttl_file", "write_ttl_file"]

#: tqdyn's linear-coefficient name -> the suffix of LISA Instrument's dataset ``c_<mosa>_<suffix>``.
DATASET_SUFFIX = {"local_phi": "phi_rx", "distant_phi": "phi_tx", "local_eta": "eta_rx", "distant_eta": "eta_tx"}
#: Spline degrees LISA Instrument 2.3 accepts (``TTLSourceInterp``).
ORDERS = (3, 5)
#: The root attributes tqdyn adds (LISA Instrument reads none of them).
#: Where the attributes are listed.
ATTRS_DOC = "docs/tilt-to-length.md#time-varying-coefficients-and-lisa-instruments-coefficient-file"
TQDYN_ATTRS = {
    "tqdyn_version": "str, version of tqdyn that wrote the file",
    "time_axis": "str, what t is",
    "coefficient_model": "str, JSON: how the coefficients were made (kind, base, drift, seed, ...)",
    "source_file": "str, file name of the closed-loop file whose time grid t samples (may be empty)",
    "source_sha256": "str, SHA-256 of that file's bytes (may be empty)",
    "source_epoch_utc": "str, epoch_utc of the run (t = 0) (may be empty)",
    "source_time_scale": "str, time scale of t (may be empty)",
}


class TTLFileError(ValueError):
    """A file that is not a readable TTL coefficient file: one line naming the file and what was found."""


def _dataset(mosa: str, field: str) -> str:
    return f"c_{mosa}_{DATASET_SUFFIX[field]}"


def _check(t, coefficients: dict, order) -> tuple[np.ndarray, dict]:
    if isinstance(order, bool) or order not in ORDERS:
        raise ValueError(f"interpolation_order = {order!r}: allowed: 3, 5 (LISA Instrument's spline degrees)")
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1 or t.size <= order or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError(f"t: must be a 1-D strictly increasing finite array of more than {order} samples (s); "
                         f"got shape {t.shape}")
    if not isinstance(coefficients, dict) or set(coefficients) != set(LINEAR_FIELDS):
        got = sorted(coefficients) if isinstance(coefficients, dict) else type(coefficients).__name__
        raise ValueError(f"coefficients: keys {got}; expected {', '.join(LINEAR_FIELDS)}")
    out = {}
    for f in LINEAR_FIELDS:
        d = coefficients[f]
        if not isinstance(d, dict) or set(d) != set(MOSAS):
            got = sorted(d) if isinstance(d, dict) else type(d).__name__
            raise ValueError(f"coefficients.{f}: keys {got}; expected the MOSAs {', '.join(MOSAS)}")
        out[f] = {}
        for m in MOSAS:
            a = np.asarray(d[m], dtype=np.float64)
            if a.shape != t.shape or not np.all(np.isfinite(a)):
                raise ValueError(f"coefficients.{f}[{m!r}]: must be finite (m/rad) with the shape {t.shape} of t; "
                                 f"got shape {a.shape}" + ("" if a.shape != t.shape else " with non-finite values"))
            out[f][m] = a
    return t, out


def write_ttl_file(path, t, coefficients: dict, order: int = 5, attrs: dict | None = None) -> pathlib.Path:
    """Write LISA Instrument's TTL coefficient file (module docstring) at ``path``, atomically.

    t: (n,) sample times [s]; coefficients: {field: {mosa: (n,) array}} [m/rad], field in
    :data:`tqdyn.ttl.coupling.LINEAR_FIELDS`; order: ``interpolation_order`` (3 or 5); attrs: tqdyn's
    root attributes (:data:`TQDYN_ATTRS`; ``tqdyn_version`` filled in), str values.  Bad input raises a
    one-line ValueError before anything is written; a failed write raises
    :class:`tqdyn.formats.trajectory.OutputError`.  Returns the absolute path."""
    t, coeffs = _check(t, coefficients, order)
    extra = {"tqdyn_version": _TQDYN_VERSION, **{k: str(v) for k, v in (attrs or {}).items()}}
    bad = [k for k in extra if k not in TQDYN_ATTRS]
    if bad:
        raise ValueError(unknown("attrs", bad[0], TQDYN_ATTRS, ATTRS_DOC, problem="is not an attribute of the file"))
    out = check_writable(path)
    with replacing_h5(out, "TTL coefficient file") as h5:
        h5.attrs["interpolation_order"] = int(order)
        for k, v in extra.items():
            h5.attrs[k] = v
        h5.create_dataset("t", data=t, compression="lzf")
        for m in MOSAS:
            for f in ("local_phi", "distant_phi", "local_eta", "distant_eta"):
                h5.create_dataset(_dataset(m, f), data=coeffs[f][m], compression="lzf")
    return out


@dataclass(frozen=True)
class TTLFile:
    """A TTL coefficient file as read: ``t`` (n,) [s], ``order``, ``coefficients`` {field: {mosa: (n,)}}
    [m/rad] and ``attrs`` (every other root attribute, str)."""

    path: pathlib.Path
    t: np.ndarray
    order: int
    coefficients: dict
    attrs: dict


def read_ttl_file(path) -> TTLFile:
    """Read a TTL coefficient file (any writer of LISA Instrument's layout).  FileNotFoundError for a
    missing file; a one-line :class:`TTLFileError` for anything else that is not a valid one."""
    p = pathlib.Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{p}: no such file")
    try:
        h5 = h5py.File(p, "r")
    except OSError as exc:
        raise TTLFileError(f"{p}: not a readable HDF5 file ({exc})") from None
    with h5:
        names = ["t"] + [_dataset(m, f) for m in MOSAS for f in LINEAR_FIELDS]
        missing = [n for n in names if n not in h5]
        if "interpolation_order" not in h5.attrs or missing:
            what = f"dataset {missing[0]!r}" if missing else "attribute 'interpolation_order'"
            raise TTLFileError(f"{p}: {what} is missing; not a TTL coefficient file (LISA Instrument's layout)")
        try:
            arrays = {n: np.asarray(h5[n][()], dtype=np.float64) for n in names}
        except OSError as exc:
            raise TTLFileError(f"{p}: cannot read its datasets, the file is damaged ({exc})") from None
        order = h5.attrs["interpolation_order"]
        attrs = {k: (v.decode() if isinstance(v, bytes) else str(v)) for k, v in h5.attrs.items()
                 if k != "interpolation_order"}
    try:
        t, coeffs = _check(arrays["t"], {f: {m: arrays[_dataset(m, f)] for m in MOSAS} for f in LINEAR_FIELDS},
                           int(order))
    except ValueError as exc:
        raise TTLFileError(f"{p}: {exc}") from None
    return TTLFile(p, t, int(order), coeffs, attrs)
