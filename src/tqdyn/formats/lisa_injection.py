"""LISA Instrument glitch (injection) files (I/O only; docs/lisa-ttl.md).

The layout LISA Instrument 2.3 reads (``lisainstrument/glitches/glitch_file.py``, ``GlitchFileV14`` and
``GlitchFileV20``, which read versions >= 1.4.dev, < 1.5 and ~= 2.0 the same way): root attributes
``version`` (str), ``size`` (int), ``dt`` (s), ``t0`` (s); one float64 dataset of ``size`` samples at
t0 + k dt per injection point and MOSA, named ``<point>_<ij>``:

* ``readout_isi_carrier``, ``readout_isi_usb`` (Hz): added to the science interferometer's carrier /
  upper-sideband beatnote frequency fluctuations of MOSA ij;
* ``readout_rfi_*``, ``readout_tmi_*`` (Hz): the same for the reference and test-mass interferometers;
* ``tm`` (m/s): added to the test-mass velocity noise of MOSA ij (``testmass_noises``);
* ``laser`` (Hz): added to the laser frequency noise of MOSA ij.

LISA Instrument interpolates each dataset by a degree-5 interpolating spline (exact at the samples) and
takes it as zero outside [t0, t0 + (size - 1) dt].  Absent datasets are zero.  tqdyn adds its own root
attributes (``generator``, ``tqdyn_version``, descriptions).  Written atomically
(:func:`tqdyn.formats.atomic.replacing_h5`).
"""

from __future__ import annotations

import math

import numpy as np

from .._choices import allowed, did_you_mean
from .._version import __version__ as _TQDYN_VERSION
from . import trajectory as _io
from .atomic import replacing_h5

__all__ = ["GLITCH_FILE_VERSION", "POINTS", "write_lisa_injection"]

#: Glitch-file format version written (read by LISA Instrument 2.3's ``GlitchFileV20``).
GLITCH_FILE_VERSION = "2.0.0"
#: Injection points and their units.
POINTS = {"readout_isi_carrier": "Hz", "readout_isi_usb": "Hz", "readout_rfi_carrier": "Hz",
          "readout_rfi_usb": "Hz", "readout_tmi_carrier": "Hz", "readout_tmi_usb": "Hz", "tm": "m/s",
          "laser": "Hz"}
_MOSAS = ("12", "23", "31", "13", "32", "21")


def write_lisa_injection(out_path, t0: float, dt: float, series: dict, attrs: dict | None = None,
                         descriptions: dict | None = None):
    """Write a glitch file at ``out_path``: ``series`` {"<point>_<ij>": (size,) float array} (points of
    :data:`POINTS`, MOSAs 12 .. 21), all of one length, finite, sampled at t0 + k dt (s); ``attrs``
    extra root attributes (str / number); ``descriptions`` {dataset: text} stored as its attribute
    ``description``.  Returns the path.  ValueError (one line) for bad input; nothing is written then."""
    out = _io.check_writable(out_path)
    t0, dt = float(t0), float(dt)
    if not (math.isfinite(t0) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"t0 = {t0!r}, dt = {dt!r}: must be finite with dt > 0 (s)")
    if not series:
        raise ValueError("series: empty; allowed: datasets <point>_<ij> of " + allowed(POINTS))
    arrays, size = {}, None
    for name, v in series.items():
        point, _, mosa = str(name).rpartition("_")
        if point not in POINTS or mosa not in _MOSAS:
            raise ValueError(f"series: dataset {name!r} is not <point>_<ij>"
                             f"{did_you_mean(name, [f'{p}_{m}' for p in POINTS for m in _MOSAS])}; allowed: point "
                             f"in {allowed(POINTS)} and ij in {allowed(_MOSAS)}")
        a = np.asarray(v, dtype=np.float64)
        if a.ndim != 1 or (size is not None and a.size != size):
            raise ValueError(f"series[{name!r}]: shape {a.shape}; expected ({size if size else 'n'},) like the others")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"series[{name!r}]: {int(np.sum(~np.isfinite(a)))} non-finite value(s)")
        size = a.size
        arrays[name] = a
    if size < 2:
        raise ValueError(f"series: {size} sample(s); need at least 2")
    with replacing_h5(out, "LISA injection file") as h5:
        h5.attrs["version"] = GLITCH_FILE_VERSION
        h5.attrs["size"] = int(size)
        h5.attrs["dt"] = dt
        h5.attrs["t0"] = t0
        h5.attrs["tqdyn_version"] = _TQDYN_VERSION
        for k, v in (attrs or {}).items():
            h5.attrs[k] = v
        for name, a in arrays.items():
            ds = h5.create_dataset(name, data=a)
            ds.attrs["units"] = POINTS[name.rpartition("_")[0]]
            if descriptions and name in descriptions:
                ds.attrs["description"] = descriptions[name]
    return out
