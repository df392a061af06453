"""The orbit-determination estimate file: the ``tqdyn-od-estimate`` HDF5 format (I/O only;
docs/od-files.md).

One file holds one batch least-squares fit (``tqdyn od fit SCENARIO MEAS.tdm --output EST.h5``):

* root attributes (:data:`ROOT_ATTRS`): the format, the writing tqdyn, the fit's statistics (chi^2,
  its degrees of freedom and p-value, iterations, last step, condition number, editing threshold),
  the scenario (its resolved TOML text) and the measurement file's name and SHA-256;
* ``/parameters``: the estimated parameters' ``names``, ``units``, ``values``, ``sigma``,
  ``covariance``, ``correlation``, and the consider parameters' ``consider_names``, the sensitivity
  matrix ``sensitivity``, ``consider_covariance`` and ``consider_sigma``
  (:class:`tqdyn.od.estimator.Estimate`);
* ``/measurements``: one row per measurement (m,) -- ``t`` [s since the scenario epoch, the run's
  time scale], ``type``, ``sat``, ``peer``, ``value`` and ``sigma`` [m or m/s]; and one row per row
  of the fit (m',) -- the post-fit ``residual`` [m or m/s], the ``normalised_residual``, the
  ``edited`` mask (1 = left out of the fit) and ``residual_row``, the index of the (first)
  measurement the row is formed from (m' < m when GNSS receiver clocks are eliminated:
  :func:`tqdyn.od.problem.residual_rows`; files without it have m' = m and row i = measurement i).

Every non-empty dataset is chunked with a Fletcher-32 checksum; strings are fixed-length UTF-8 bytes;
datasets carry ``units`` and ``description``.  Writing is atomic (:func:`tqdyn.formats.atomic.replacing_h5`):
a failure or an interrupt leaves no file and the output path as it was.
"""

from __future__ import annotations

import json
import math
import pathlib
from dataclasses import dataclass, field

import numpy as np

from .._version import __version__ as _TQDYN_VERSION
from .atomic import replacing_h5
from .trajectory import check_writable
from .trajectory.reader import DAMAGED, damaged_message, native_attr, open_for_reading, read_dataset, text_array

__all__ = ["FORMAT", "FORMAT_VERSION", "ROOT_ATTRS", "EstimateFile", "EstimateFormatError", "estimate_contents",
           "read_estimate_file", "write_estimate_file"]

FORMAT = "tqdyn-od-estimate"
"""Value of the root attribute ``format``."""
FORMAT_VERSION = 1
"""Format version written; readers accept any version <= this."""

#: Root attributes and their meaning.
ROOT_ATTRS = {
    "format": f'str, always "{FORMAT}"',
    "format_version": f"int, {FORMAT_VERSION}",
    "tqdyn_version": "str, version of tqdyn that wrote the file",
    "scenario": "str, the resolved scenario (TOML) the fit used",
    "scenario_name": "str, its name",
    "epoch": "str, the scenario epoch (t = 0), with its scale (UTC or TDB)",
    "time_scale": 'str, the time scale of t: "TT" (geocentric) or "TDB" (heliocentric)',
    "tdm_file": "str, file name (no directory) of the measurement file (CCSDS TDM)",
    "tdm_sha256": "str, SHA-256 of the measurement file's bytes",
    "chi2": "float, chi^2 of the kept measurements' whitened residuals plus the a priori term",
    "chi2_dof": "int, its degrees of freedom",
    "chi2_pvalue": "float, P(chi^2_dof >= chi2) (NaN for dof <= 0)",
    "iterations": "int, model evaluations of the fit",
    "last_step": "float, max |dx_j / sigma_j| of the last Gauss-Newton step",
    "condition_number": "float, condition number of the column-scaled whitened Jacobian",
    "edit_sigma": "float, k of the k-sigma outlier editing (NaN: no editing)",
    "tracking": "str, JSON: the tracking plan (kinds, arc_s, interval_s, estimate, consider)",
    "groups": "str, JSON: per measurement group {count, edited, rms, weighted_rms, normalised_rms}",
}

_PARAM = {
    "names": ("", "estimated parameters' names"),
    "units": ("", "each parameter's unit"),
    "values": ("parameter units", "estimate"),
    "sigma": ("parameter units", "1-sigma, sqrt(diag covariance)"),
    "covariance": ("parameter units squared", "covariance P_xx (measurement noise and a priori)"),
    "correlation": ("1", "correlation matrix"),
    "consider_names": ("", "consider parameters' names"),
    "sensitivity": ("parameter / consider parameter units", "sensitivity matrix S_xc"),
    "consider_covariance": ("parameter units squared", "consider covariance P_c,xx"),
    "consider_sigma": ("parameter units", "sqrt(diag consider_covariance)"),
}
_MEAS = {
    "t": ("s", "time tag, seconds since the scenario epoch (time_scale)"),
    "type": ("", "measurement type"),
    "sat": ("", "satellite index in the scenario"),
    "peer": ("", "station, GNSS transmitter or other satellite's index"),
    "value": ("m or m/s", "measured value"),
    "sigma": ("m or m/s", "noise sigma"),
    "residual": ("m or m/s", "post-fit residual y - h(x_hat)"),
    "normalised_residual": ("1", "residual over its post-fit standard deviation"),
    "edited": ("", "1 = left out of the fit by the outlier editing"),
    "residual_row": ("", "index of the (first) measurement row each residual row is formed from"),
}
#: Datasets that files written before them lack (the reader supplies them when it can).
_OPTIONAL = {"measurements": ("residual_row",)}


class EstimateFormatError(ValueError):
    """A file that is not a readable estimate file: one line naming the file and what was found."""


@dataclass
class EstimateFile:
    """The contents of an estimate file: ``attrs`` (root attributes, native types), ``parameters``
    ({name: array} of ``/parameters``: names and units as str arrays) and ``measurements`` ({name:
    array} of ``/measurements``: type and peer as str arrays, edited as bool; ``residual_row`` absent
    only for a file without it whose residual rows are not the measurement rows)."""

    path: pathlib.Path | None
    attrs: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)
    measurements: dict = field(default_factory=dict)

    def sigma_of(self, name: str) -> float:
        """The 1-sigma of the estimated parameter ``name`` (its unit)."""
        return float(self.parameters["sigma"][list(self.parameters["names"]).index(name)])


def _put(group, name: str, value, units: str, description: str):
    arr = np.asarray(value)
    if arr.dtype.kind in "USO":
        arr = text_array(arr)
    chunked = arr.ndim > 0 and arr.size > 0
    ds = group.create_dataset(name, data=arr, chunks=arr.shape if chunked else None, fletcher32=chunked)
    ds.attrs["units"] = units
    ds.attrs["description"] = description
    ds.attrs["kind"] = "text" if arr.dtype.kind == "S" else "number"


def _contents(estimate, measurements, attrs: dict, units, residual_rows) -> tuple[dict, dict, dict]:
    """(root attributes, /parameters, /measurements) of the file, as written."""
    n = len(estimate.names)
    params = {"names": np.array(estimate.names, dtype=object), "units": np.array(units or [""] * n, dtype=object),
              "values": estimate.values, "sigma": estimate.sigma, "covariance": estimate.covariance,
              "correlation": estimate.correlation, "consider_names": np.array(estimate.consider_names, dtype=object),
              "sensitivity": estimate.sensitivity, "consider_covariance": estimate.consider_covariance,
              "consider_sigma": estimate.consider_sigma}
    rows = {"t": measurements.t, "type": np.asarray(measurements.type, dtype=object), "sat": measurements.sat,
            "peer": np.asarray(measurements.peer, dtype=object), "value": measurements.value,
            "sigma": measurements.sigma, "residual": estimate.residuals,
            "normalised_residual": estimate.normalised_residuals,
            "edited": np.asarray(estimate.edited, dtype=np.uint8),
            "residual_row": np.asarray(np.arange(len(estimate.residuals)) if residual_rows is None else residual_rows,
                                       dtype=np.int64)}
    groups = {str(k): {f: getattr(g, f) for f in ("count", "edited", "rms", "weighted_rms", "normalised_rms")}
              for k, g in (estimate.groups or {}).items()}
    root = {"format": FORMAT, "format_version": FORMAT_VERSION, "tqdyn_version": _TQDYN_VERSION,
            **{k: v for k, v in attrs.items() if k not in ("format", "format_version", "tqdyn_version")},
            "chi2": float(estimate.chi2), "chi2_dof": int(estimate.chi2_dof),
            "chi2_pvalue": float(estimate.chi2_pvalue), "iterations": int(estimate.iterations),
            "last_step": float(estimate.last_step), "condition_number": float(estimate.condition_number),
            "groups": json.dumps(groups)}
    root.setdefault("edit_sigma", math.nan)
    return root, params, rows


def estimate_contents(estimate, measurements, *, attrs: dict, units=None, residual_rows=None) -> EstimateFile:
    """What :func:`write_estimate_file` would write, in memory, as :func:`read_estimate_file`
    returns it (``path`` None): the same arguments."""
    root, params, rows = _contents(estimate, measurements, attrs, units, residual_rows)

    def native(d):
        return {k: (np.asarray(v).astype(str) if np.asarray(v).dtype.kind in "OUS" else np.asarray(v))
                for k, v in d.items()}

    out = EstimateFile(None, dict(root), native(params), native(rows))
    out.measurements["edited"] = out.measurements["edited"].astype(bool)
    return out


def write_estimate_file(path, estimate, measurements, *, attrs: dict, units=None, residual_rows=None) -> pathlib.Path:
    """Write the estimate file ``path`` atomically.

    estimate: a :class:`tqdyn.od.estimator.Estimate`; measurements: the fitted table (attributes t,
    type, sat, peer, value, sigma, (m,)); attrs: the root attributes of :data:`ROOT_ATTRS` other than
    the format's and the fit's (scenario, scenario_name, epoch, time_scale, tdm_file, tdm_sha256,
    edit_sigma, tracking); units: (n,) the parameters' units; residual_rows: (m',) the measurement
    row of each residual row (None: the identity, m' = m).  Raises OutputError (one line)."""
    out = check_writable(path)
    root, params, rows = _contents(estimate, measurements, attrs, units, residual_rows)
    with replacing_h5(out, "the estimate file") as h5:
        for k, v in root.items():
            h5.attrs[k] = v
        g = h5.create_group("parameters")
        for k, v in params.items():
            _put(g, k, v, *_PARAM[k])
        g = h5.create_group("measurements")
        for k, v in rows.items():
            _put(g, k, v, *_MEAS[k])
    return out


def _read(ds, fname: str):
    return read_dataset(ds, fname, EstimateFormatError, "tqdyn od fit")


def read_estimate_file(path) -> EstimateFile:
    """Read an estimate file completely.  FileNotFoundError for a missing file; a one-line
    :class:`EstimateFormatError` for anything that is not a ``tqdyn-od-estimate`` file of version
    <= :data:`FORMAT_VERSION` (another HDF5 file, a damaged file, a missing dataset)."""
    p, fname, h5 = open_for_reading(path, "estimate file", EstimateFormatError)
    try:
        with h5:
            attrs = {k: native_attr(v) for k, v in h5.attrs.items()}
            fmt, ver = attrs.get("format"), attrs.get("format_version")
            if fmt != FORMAT:
                raise EstimateFormatError(f"{fname}: format = {fmt!r}; expected format {FORMAT!r} with "
                                          f"format_version <= {FORMAT_VERSION} (a file written by tqdyn od fit)")
            if isinstance(ver, bool) or not isinstance(ver, int) or not 1 <= ver <= FORMAT_VERSION:
                raise EstimateFormatError(f"{fname}: format_version = {ver!r}; this tqdyn ({_TQDYN_VERSION}) reads "
                                          f"1..{FORMAT_VERSION}")
            out = EstimateFile(p, attrs)
            for group, names, dest in (("parameters", _PARAM, out.parameters),
                                       ("measurements", _MEAS, out.measurements)):
                optional = _OPTIONAL.get(group, ())
                missing = [k for k in names if f"{group}/{k}" not in h5 and k not in optional]
                if missing:
                    raise EstimateFormatError(f"{fname}: dataset '/{group}/{missing[0]}' is missing; re-create it "
                                              "(tqdyn od fit)")
                for k in names:
                    if f"{group}/{k}" in h5:
                        dest[k] = _read(h5[f"{group}/{k}"], fname)
    except DAMAGED as exc:
        raise EstimateFormatError(damaged_message(fname, exc, "tqdyn od fit")) from None
    meas = out.measurements
    meas["edited"] = meas["edited"].astype(bool)
    if "residual_row" not in meas and len(meas["residual"]) == len(meas["t"]):
        meas["residual_row"] = np.arange(len(meas["t"]), dtype=np.int64)
    return out
