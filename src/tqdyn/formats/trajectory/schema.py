"""The ``tqdyn-trajectory`` format itself: identity, field catalogue, root attributes.

:data:`FORMAT`, :data:`FORMAT_VERSION`, the per-field description
:data:`FIELDS` (:class:`FieldSpec`), the root attributes :data:`ROOT_ATTRS`
and their checks, the two error types and the small helpers shared by
:mod:`~tqdyn.formats.trajectory.writer` and
:mod:`~tqdyn.formats.trajectory.reader`.  Conventions: see
:mod:`tqdyn.formats.trajectory` and ``docs/trajectory-format.md``.
"""

from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from ..._choices import unknown
from ..._version import __version__ as _TQDYN_VERSION
from ...astro.reference import GEOCENTRIC, REFERENCE_SYSTEMS

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "OutputIOError",
    "FieldSpec",
    "FIELDS",
    "ROOT_ATTRS",
    "SPACECRAFT_ATTRS",
    "dataset_attrs",
    "parse_vectors",
    "OutputError",
    "TrajectoryFormatError",
    "field_path",
    "row_fields",
]

FORMAT = "tqdyn-trajectory"
"""Value of the root attribute ``format``."""

FORMAT_VERSION = 2
"""Format version written by :class:`~tqdyn.formats.trajectory.TrajectoryWriter`; readers accept
any version <= this."""

# ---------------------------------------------------------------------------
# field catalogue
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class FieldSpec:
    """Description of one trajectory field (one HDF5 path).

    Attributes
    ----------
    kind : str
        ``"dd"`` (group with float64 datasets ``hi``/``lo``, value = hi + lo)
        or ``"f8"`` (one float64 dataset).
    shape : tuple of (str | int)
        Trailing shape *without* the time axis; ``"sat"`` stands for the
        satellite axis (length n_sat >= 1: 3 in coupled runs, any number in
        point-mass runs), ``"tm"`` for the test-mass / MOSA
        axis (length 2).  ``()`` for a scalar per time row.
    unit : str
        SI unit (``"1"`` for dimensionless).
    frame : str
        Frame the components are expressed in (or what the quantity refers to).
    description : str
        One-line meaning.
    time_dependent : bool
        True: stored with a leading time axis of length N (same N for every
        time-dependent field).  False: static, stored with ``shape`` only.
    dims : tuple of str
        xarray dimension names for ``shape`` (``"sat"``, ``"tm"``, ``"comp"``,
        ``"row"``, ``"col"``); the time axis (``"time"``) is not included.
    components : str
        What the components x, y, z of a vector field are (the axes of its
        frame), written as the dataset attribute ``components``; ``{frame}``
        stands for the file's frame.  ``""`` for fields that are not 3-vectors.
    """

    kind: str
    shape: tuple
    unit: str
    frame: str
    description: str
    time_dependent: bool
    dims: tuple
    components: str = ""

    def resolved_shape(self, n_sat: int) -> tuple[int, ...]:
        """Trailing shape (no time axis) with ``sat`` -> n_sat and ``tm`` -> 2."""
        return tuple(n_sat if a == "sat" else 2 if a == "tm" else int(a) for a in self.shape)


#: The axes of each frame, for the ``components`` attribute of the vector fields.
_AXES_INERTIAL = ("x, y, z: the axes of the file's frame {frame} (ICRF-aligned, non-rotating)")
_AXES_S = ("x = X_S (the bisector of the satellite's two beams, towards the constellation's incentre), "
           "y = Y_S = Z_S x X_S, z = Z_S (the constellation normal, n_ij x n_ik / sin(alpha_i))")
_AXES_OA = ("x = X_OA_l (the optical axis of MOSA l: MOSA 1 faces satellite k, MOSA 2 satellite j of the even "
            "permutation (i, j, k)), y = Y_OA_l = Z_S x X_OA_l, z = Z_OA_l = Z_S; OA_l is S turned about Z_S by "
            "mosa/angle; tm index l = MOSA l")


def _f(kind, shape, dims, unit, frame, description, time_dependent=True):
    axes = ""
    if shape and shape[-1] == 3 and dims[-1] == "comp":
        axes = {"GCRS": _AXES_INERTIAL, "S": _AXES_S, "OA_l": _AXES_OA}.get(frame, "")
    return FieldSpec(kind, tuple(shape), unit, frame, description, time_dependent, tuple(dims), axes)


def field_frame(spec: FieldSpec, time_scale: str, frame: str) -> str:
    """The ``frame`` attribute of a field in a file whose root attributes say
    ``time_scale`` and ``frame``: FIELDS's "time_scale" is the file's time
    scale, its "GCRS" (the vectors of the central body's system) the file's
    frame ("GCRS" or "BCRS"); other frames (S, OA_l ...) as FIELDS says."""
    if spec.frame == "time_scale":
        return time_scale
    return frame if spec.frame == "GCRS" else spec.frame


#: Where the fields are listed.
FIELDS_DOC = "docs/trajectory-format.md#fields"
FIELDS: dict[str, FieldSpec] = {
    "t": _f("dd", (), (), "s", "time_scale",
            "time since epoch_utc in the root attribute time_scale (TT: seconds of TT since the epoch's TT)"),
    "sat/r": _f("dd", ("sat", 3), ("sat", "comp"), "m", "GCRS",
                "satellite centre-of-mass position"),
    "sat/v": _f("dd", ("sat", 3), ("sat", "comp"), "m/s", "GCRS",
                "satellite centre-of-mass velocity"),
    "sat/a_gravity": _f("f8", ("sat", 3), ("sat", "comp"), "m/s^2", "GCRS",
                        "satellite gravitational acceleration, all gravitational terms"),
    "sat/a_dragfree": _f("f8", ("sat", 3), ("sat", "comp"), "m/s^2", "GCRS",
                         "drag-free control acceleration G_i of the satellite"),
    "sat/T_S_I": _f("f8", ("sat", 3, 3), ("sat", "row", "col"), "1", "GCRS -> S",
                    "rotation matrix inertial (GCRS) -> body frame S; rows are X_S, Y_S, Z_S "
                    "in GCRS components"),
    "sat/omega": _f("f8", ("sat", 3), ("sat", "comp"), "rad/s", "S",
                    "angular velocity of S relative to GCRS, components in S"),
    "sat/omega_dot": _f("f8", ("sat", 3), ("sat", "comp"), "rad/s^2", "S",
                        "angular acceleration of S relative to GCRS, components in S"),
    "sat/breathing_angle": _f("f8", ("sat",), ("sat",), "rad", "constellation",
                              "breathing angle alpha_i: angle at satellite i between its two arms"),
    "mosa/angle": _f("f8", ("sat", "tm"), ("sat", "tm"), "rad", "S",
                     "angle of X_OA_l from X_S about Z_S (MOSA l = 1, 2)"),
    "tm/r": _f("dd", ("sat", "tm", 3), ("sat", "tm", "comp"), "m", "GCRS",
               "test-mass centre-of-mass position"),
    "tm/v": _f("dd", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s", "GCRS",
               "test-mass centre-of-mass velocity (extension of format version 1)"),
    "tm/a": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "GCRS",
               "test-mass total acceleration: gravity + self-gravity + suspension "
               "(extension of format version 1)"),
    "tm/housing_offset": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m", "GCRS",
                            "free-TM verification mode: TM position minus its housing centre "
                            "(extension of format version 1)"),
    "tm/a_suspension": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "OA_l",
                          "test-mass suspension (actuation) acceleration"),
    "tm/alpha_suspension": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "rad/s^2", "OA_l",
                              "angular acceleration the test mass needs (suspension)"),
    "tm/self_gravity": _f("f8", ("sat", "tm", 3), ("sat", "tm", "comp"), "m/s^2", "OA_l",
                          "spacecraft self-gravity acceleration at the test mass (static)",
                          time_dependent=False),
}
"""Every field of format version 1, keyed by HDF5 path, in canonical order."""

ROOT_ATTRS: dict[str, str] = {
    "format": f'str, always "{FORMAT}"',
    "format_version": f"int, {FORMAT_VERSION}",
    "tqdyn_version": "str, version of tqdyn that wrote the file",
    "scenario": "str, the resolved scenario as TOML text",
    "epoch_utc": "str, ISO 8601 UTC label of t = 0",
    "origin": 'str, the central body at the origin of the coordinates: "earth" or "sun" (absent in files '
              'written before version 0.2: "earth")',
    "frame": 'str, the axes and reference system of the vectors: "GCRS" (origin "earth") or "BCRS" (origin '
             '"sun": Sun-centred BCRS, ICRF axes)',
    "time_scale": 'str, the time scale of t: "TT" (geocentric), "TDB" (heliocentric; format version 1: "TDB" '
                  'means TT-elapsed seconds labelled TDB)',
    "epoch_tdb": "str, ISO 8601 TDB epoch of t = 0 when the scenario gave it in TDB (exact; epoch_utc is then its "
                 "label rounded to 1 us) (extension)",
    "precision": 'str, "dd" | "float64"',
    "step_s": "float, integrator / output step in s",
    "integrator": "str, integrator name",
    "pointing": 'str, "global" | "taylor1" | "taylor2" | "iterative" | "none"',
    "control": 'str, "on" | "off"',
    "eop": 'str, the Earth-orientation source: "auto" | "finals" | "c04-20" | "c04-14" | "off" | "custom" (extension)',
    "eop_sources": "str, which EOP source covered which days of the run (extension)",
    "eop_data": "str, the EOP files and the leap-second table used (extension)",
    "constants": "str, JSON: the fixed constants the run used (value, unit, source), the SHA-256 of the data files "
                 "it read and of the compiled force model's numbers (tqdyn.scenario.record; extension)",
}
"""Root attributes of format version 1 and their type / allowed values."""

SPACECRAFT_ATTRS: dict[str, str] = {
    "spacecraft_architecture": 'str, the spacecraft layout: "tianqin" | "lisa" | "taiji" (the preset of '
                               "spacecraft.architecture)",
    "dragfree_scheme": 'str, the drag-free scheme: "tianqin" (the paper\'s closed form, sensitive axes X_OA_l) | '
                       '"lisa" (the general solution for any independent sensitive axes)',
    "spacecraft_housing_centers": "str, JSON [[x, y, z], [x, y, z]]: the electrode-housing centres r_0,l (TM "
                                  "nominal positions) of TM 1 and TM 2 at the nominal MOSA opening angle, m, in "
                                  "the body frame S (origin the satellite's centre of mass)",
    "spacecraft_pivots": "str, JSON [[x, y, z], [x, y, z]]: the pivots of MOSA 1 and MOSA 2 (fixed in S), m, in S",
    "spacecraft_sensitive_axes": "str, JSON [[x, y, z], [x, y, z]]: the unit sensitive axis of TM 1 in OA_1 and "
                                 "of TM 2 in OA_2 (the drag-free control keeps the suspension zero along them)",
    "spacecraft_theta_nominal": "float, rad: the nominal MOSA opening angle at which the housing centres are given",
    "spacecraft_units": "str, the units and frames of the spacecraft_* attributes, in words",
}
"""Root attributes of coupled runs (``constellation.pointing`` != "none"),
written since the spacecraft architecture became configuration (format
version 2, no change in any field).  A coupled file without them was
written by the TianQin architecture: :attr:`Trajectory.spacecraft
<tqdyn.formats.trajectory.Trajectory.spacecraft>` reports its defaults."""

#: The value of ``spacecraft_units``.
SPACECRAFT_UNITS = ("spacecraft_housing_centers, spacecraft_pivots: m, in the body frame S (origin the "
                    "satellite's centre of mass), rows TM 1, TM 2, columns x, y, z (the same for the three "
                    "satellites); spacecraft_sensitive_axes: unit vectors, row l in OA_l of TM l; "
                    "spacecraft_theta_nominal: rad")
_SPACECRAFT_VECTORS = ("spacecraft_housing_centers", "spacecraft_pivots", "spacecraft_sensitive_axes")

_REQUIRED_USER_ATTRS = ("scenario", "epoch_utc", "precision", "step_s", "integrator",
                        "pointing", "control")
_CHOICES = {
    "precision": ("dd", "float64"),
    "pointing": ("global", "taylor1", "taylor2", "iterative", "none"),
    "control": ("on", "off"),
    "origin": tuple(sorted({r.origin for r in REFERENCE_SYSTEMS})),
    "time_scale": tuple(sorted({r.time_scale for r in REFERENCE_SYSTEMS})),
    "frame": tuple(sorted({r.frame for r in REFERENCE_SYSTEMS})),
}
_COORDS = {
    "tm": [1, 2],
    "comp": ["x", "y", "z"],
    "row": ["X_S", "Y_S", "Z_S"],
    "col": ["x", "y", "z"],
}


def parse_vectors(text, name: str) -> np.ndarray:
    """The (2, 3) float64 array of a ``spacecraft_*`` vector attribute (JSON
    text ``[[x, y, z], [x, y, z]]``); ValueError naming the attribute otherwise."""
    import json

    try:
        a = np.array(json.loads(text), dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (2, 3) or not np.all(np.isfinite(a)):
        raise ValueError(f"attrs[{name!r}] = {text!r}; must be JSON [[x, y, z], [x, y, z]] of finite numbers")
    return a


def _axis_name(v, l: int) -> str:
    for k, name in enumerate(("X", "Y", "Z")):
        for sign in (1.0, -1.0):
            if np.array_equal(v, sign * np.eye(3)[k]):
                return ("-" if sign < 0 else "") + f"{name}_OA_{l}" + (" (the optical axis)" if k == 0 else "")
    return f"a direction in OA_{l}"


def dataset_attrs(path: str, attrs: Mapping[str, Any]) -> dict[str, str]:
    """The attributes of the dataset (f8 field) or group (dd field) ``path``
    in a file with root attributes ``attrs``: ``units``, ``frame``,
    ``description`` (:data:`FIELDS`); ``components`` (what x, y, z are) for
    vector fields; for the actuation fields of a coupled run that records its
    spacecraft (:data:`SPACECRAFT_ATTRS`) also ``dragfree_scheme``
    (``sat/a_dragfree``, ``tm/a_suspension``) and ``sensitive_axes``
    (``tm/a_suspension``: the sensitive axis of each TM in its OA_l, in words)."""
    spec = _spec(path, "dataset_attrs")
    frame = field_frame(spec, attrs.get("time_scale", GEOCENTRIC.time_scale), attrs.get("frame", GEOCENTRIC.frame))
    out = {"units": spec.unit, "frame": frame, "description": spec.description}
    if spec.components:
        out["components"] = spec.components.format(frame=frame)
    scheme = attrs.get("dragfree_scheme")
    if scheme and path in ("sat/a_dragfree", "tm/a_suspension"):
        out["dragfree_scheme"] = str(scheme)
    axes = attrs.get("spacecraft_sensitive_axes")
    if axes and path == "tm/a_suspension":
        e = parse_vectors(axes, "spacecraft_sensitive_axes")
        out["sensitive_axes"] = "; ".join(
            f"TM {l}: [{', '.join(f'{x:.17g}' for x in e[l - 1])}] in OA_{l} = {_axis_name(e[l - 1], l)}"
            for l in (1, 2)) + " (no suspension along it: the spacecraft follows the TM there)"
    return out


def field_path(row_name: str) -> str:
    """The field (HDF5 path) of an output quantity of the propagation, named
    as the attribute of :class:`tqdyn.dynamics.Rows`: the first underscore is
    the group separator (``sat_r`` -> ``sat/r``, ``mosa_angle`` ->
    ``mosa/angle``, ``t`` -> ``t``).  The xarray view names variables the
    other way round (:meth:`Trajectory.to_xarray`)."""
    path = row_name.replace("_", "/", 1)
    _spec(path, "rows")
    return path


def row_fields(rows) -> dict[str, Any]:
    """A block of output rows (:class:`tqdyn.dynamics.Rows`) as the mapping
    field path -> values that :meth:`TrajectoryWriter.append` takes."""
    return {field_path(name): value for name, value in rows.items()}


class OutputError(OSError):
    """The output path cannot be written (one-line message naming the path)."""


class OutputIOError(OutputError):
    """Writing failed at run time (disk full, file-size limit, I/O error):
    one-line message naming the file and the cause.  The temporary file is
    no longer written to (HDF5 left in a state that closes safely)."""


class TrajectoryFormatError(ValueError):
    """A file is not a readable tqdyn trajectory (one-line message naming the file)."""


# ---------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------


def _fmt_shape(shape) -> str:
    return "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def _symbolic(spec: FieldSpec) -> str:
    names = {"sat": "n_sat", "tm": "tm"}
    return _fmt_shape(("rows",) + tuple(names.get(a, a) for a in spec.shape))


def _spec(path: str, where: str) -> FieldSpec:
    try:
        return FIELDS[path]
    except KeyError:
        raise ValueError(unknown(where, path, FIELDS, FIELDS_DOC, problem="is not a field", noun="fields")) from None


def _check_attrs(attrs: Mapping[str, Any]) -> dict[str, Any]:
    """Validate the caller's root attributes and return the full attribute dict."""
    if not isinstance(attrs, Mapping):
        raise TypeError(f"attrs must be a mapping, got {type(attrs).__name__}")
    missing = [k for k in _REQUIRED_USER_ATTRS if k not in attrs]
    if missing:
        raise ValueError(f"attrs: missing required root attribute(s) {', '.join(missing)}")
    out: dict[str, Any] = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "tqdyn_version": _TQDYN_VERSION,
        "origin": GEOCENTRIC.origin,
        "frame": GEOCENTRIC.frame,
        "time_scale": GEOCENTRIC.time_scale,
    }
    for key, val in attrs.items():
        if not isinstance(key, str) or not key:
            raise ValueError(f"attrs: attribute names must be non-empty str, got {key!r}")
        if isinstance(val, (bool, np.bool_)):
            raise ValueError(f"attrs[{key!r}]: bool is not allowed; use a str (e.g. \"on\"/\"off\")")
        if isinstance(val, np.generic):
            val = val.item()
        if not isinstance(val, (str, int, float)):
            raise ValueError(f"attrs[{key!r}]: must be str, int or float, got {type(val).__name__}")
        out[key] = val
    if out["format"] != FORMAT or out["format_version"] != FORMAT_VERSION:
        raise ValueError(f"attrs: format/format_version are set by the writer and must be "
                         f"{FORMAT!r}/{FORMAT_VERSION}, got {out['format']!r}/{out['format_version']!r}")
    out["format"], out["format_version"] = FORMAT, FORMAT_VERSION  # exact types (str, int)
    for key, allowed in _CHOICES.items():
        if out[key] not in allowed:
            raise ValueError(unknown(f"attrs[{key!r}]", out[key], allowed))
    if (out["origin"], out["frame"], out["time_scale"]) not in {(r.origin, r.frame, r.time_scale)
                                                                for r in REFERENCE_SYSTEMS}:
        raise ValueError(f"attrs: origin / frame / time_scale = {out['origin']!r} / {out['frame']!r} / "
                         f"{out['time_scale']!r} is not a reference system of tqdyn; allowed: "
                         + " | ".join(f"{r.origin} / {r.frame} / {r.time_scale}" for r in REFERENCE_SYSTEMS))
    for key in ("scenario", "epoch_utc", "integrator", "tqdyn_version"):
        if not isinstance(out[key], str):
            raise ValueError(f"attrs[{key!r}]: must be str, got {type(out[key]).__name__}")
    try:
        _dt.datetime.fromisoformat(out["epoch_utc"])
    except ValueError:
        raise ValueError(f"attrs['epoch_utc'] = {out['epoch_utc']!r} is not an ISO 8601 "
                         "date-time (e.g. 2034-01-01T00:00:00)") from None
    for key in ("spacecraft_architecture", "dragfree_scheme", "spacecraft_units", *_SPACECRAFT_VECTORS):
        if key in out and not (isinstance(out[key], str) and out[key]):
            raise ValueError(f"attrs[{key!r}]: must be a non-empty str, got {out[key]!r}")
    for key in _SPACECRAFT_VECTORS:
        if key in out:
            parse_vectors(out[key], key)
    if "spacecraft_theta_nominal" in out:
        th = out["spacecraft_theta_nominal"]
        if isinstance(th, str) or not 0 < th < math.pi:
            raise ValueError(f"attrs['spacecraft_theta_nominal'] = {th!r}; must be an angle in (0, pi) rad")
        out["spacecraft_theta_nominal"] = float(th)
    step = out["step_s"]
    if isinstance(step, str) or not math.isfinite(step):
        raise ValueError(f"attrs['step_s'] = {step!r}; must be a finite number of seconds")
    out["step_s"] = float(step)
    return out

