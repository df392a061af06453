"""The ``[spacecraft]`` section of a scenario: architecture, drag-free scheme, self-gravity.

:class:`SpacecraftConfig` holds the validated keys (SI units: m, m/s^2) and
builds the physics object :class:`tqdyn.constellation.spacecraft.Spacecraft`
from them (:meth:`SpacecraftConfig.craft`); the keys and their meaning are
documented in docs/scenarios.md (Spacecraft).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal
from typing import Any

from .initial import epoch_from_label
from .values import (MAX_ACCELERATION, _NOVALUE, ScenarioError, _fmt, _num_array, _require, _require_choice, _set,
                     _to_decimal)

__all__ = ["SELF_GRAVITY_MODELS", "TM_AXES", "SpacecraftConfig"]

SELF_GRAVITY_MODELS = ("table-iv", "off")
TM_AXES = ("x", "y", "z")
#: TOML key of each :class:`tqdyn.constellation.spacecraft.Spacecraft` field
_CRAFT_KEYS = {"d_tm": "d_tm", "d_p": "d_p", "tm_axis": "tm_axis", "housing_centers_nominal": "housing_centers",
               "pivot_points": "pivots", "sensitive_axes": "sensitive_axes", "scheme": "dragfree",
               "tm_distance": "tm_distance", "envelope_radius": "envelope_radius", "architecture": "architecture"}


@dataclass(frozen=True)
class SpacecraftConfig:
    """Spacecraft architecture and drag-free scheme (the same for the three satellites).

    ``architecture``: the layout preset, "tianqin" (default), "lisa" or
    "taiji" (:mod:`tqdyn.constellation.spacecraft`); ``dragfree``: the
    drag-free scheme, "tianqin" or "lisa" (default: the architecture's,
    "lisa" for "taiji").
    Line layout ("tianqin" only): ``d_tm_m`` [m] (> 0, default 0.40):
    distance between the two test masses; ``d_p_m`` [m] (>= 0, default 0):
    distance of the MOSA pivots from the electrode-housing centers;
    ``tm_axis`` (default "y"): S-frame axis along which the two TMs lie
    (TM_1 at +d_tm/2).  Optical-axis layout ("lisa", "taiji" only):
    ``tm_distance_m`` [m] (> 0, default 0.30, an assumption): distance of each
    EH center from the CoM along its MOSA's optical axis, the MOSAs turning
    about Z_S through the CoM.  Any architecture: ``housing_centers``
    [[x, y, z], [x, y, z]] [m, S, at the nominal 60 deg opening angle] and
    ``pivots`` (same shape; default: the housing centers, i.e. no lever arm)
    replace the preset's layout; ``sensitive_axes`` (2, 3) unit vectors in
    OA_l (default X_OA_l); ``envelope_radius_m`` [m] (default 1.5): every
    EH center and pivot lies within it.
    ``self_gravity``: DC self-gravity of each TM
    in its OA_l frame, "table-iv" (the paper's Table IV), "off", or an array
    of shape (2, 3) (both satellites alike) or (3, 2, 3) [m/s^2];
    ``self_gravity_common``: an extra DC acceleration on both TMs of a
    satellite, fixed in the satellite frame S, shape (3,) (all satellites)
    or (3, 3) [m/s^2] (the paper's common self-gravity studies).
    ``self_gravity_center``: [start, end] [m/s^2] (or None: off), an
    acceleration of every satellite's orbit toward the constellation's
    centre (the centroid of the three satellites), positive toward it,
    varying linearly in time from ``start`` to ``end`` over
    ``self_gravity_center_span`` = [t_start, t_end] (ISO dates, UTC unless
    suffixed " TDB"; held at the end values outside; default: the span of
    ``initial.oem``'s files) -- the model of ESA's LISA orbit files.  In a
    coupled run (``constellation.pointing`` != "none") the same ramp is a
    common self-gravity of both TMs along +X_S (toward the incentre), which
    reaches the orbit through the drag-free control.
    """

    d_tm_m: Any = None
    d_p_m: Any = None
    tm_axis: Any = None
    self_gravity: Any = "table-iv"
    self_gravity_common: Any = (Decimal(0), Decimal(0), Decimal(0))
    self_gravity_center: Any = None
    self_gravity_center_span: Any = None
    architecture: str = "tianqin"
    dragfree: Any = None
    tm_distance_m: Any = None
    housing_centers: Any = None
    pivots: Any = None
    sensitive_axes: Any = None
    envelope_radius_m: Any = Decimal("1.5")

    def __post_init__(self) -> None:
        from ..constellation.spacecraft import ARCHITECTURES, DRAGFREE_SCHEMES

        _require_choice(self.architecture, "spacecraft.architecture", ARCHITECTURES)
        line = self.architecture == "tianqin"
        for key, fld in (("d_tm", "d_tm_m"), ("d_p", "d_p_m"), ("tm_axis", "tm_axis"), ("tm_distance", "tm_distance_m")):
            own = line != (key == "tm_distance")
            _require(own or getattr(self, fld) is None, f"spacecraft.{key}", getattr(self, fld),
                     f"belongs to the {'optical-axis' if key == 'tm_distance' else 'line'} layout "
                     f"(spacecraft.architecture = {self.architecture!r})",
                     f'no {key} for this architecture ({"lisa/taiji" if key == "tm_distance" else "tianqin"} only)')
        if line:
            _set(self, "d_tm_m", _to_decimal(Decimal("0.40") if self.d_tm_m is None else self.d_tm_m, "spacecraft.d_tm_m"))
            _set(self, "d_p_m", _to_decimal(Decimal("0") if self.d_p_m is None else self.d_p_m, "spacecraft.d_p_m"))
            _set(self, "tm_axis", "y" if self.tm_axis is None else self.tm_axis)
            _require(self.d_tm_m > 0, "spacecraft.d_tm_m", self.d_tm_m, "is not positive", "d_tm > 0 m")
            _require(self.d_p_m >= 0, "spacecraft.d_p_m", self.d_p_m, "is negative", "d_p >= 0 m")
            _require_choice(self.tm_axis, "spacecraft.tm_axis", TM_AXES)
        else:
            _set(self, "tm_distance_m", _to_decimal(Decimal("0.30") if self.tm_distance_m is None else self.tm_distance_m,
                                                    "spacecraft.tm_distance_m"))
            _require(self.tm_distance_m > 0, "spacecraft.tm_distance", self.tm_distance_m, "is not positive",
                     "tm_distance > 0 m")
        _set(self, "dragfree", ("tianqin" if line else "lisa") if self.dragfree is None else self.dragfree)
        _require_choice(self.dragfree, "spacecraft.dragfree", DRAGFREE_SCHEMES)
        for key in ("housing_centers", "pivots", "sensitive_axes"):
            if getattr(self, key) is not None:
                _set(self, key, _num_array(getattr(self, key), f"spacecraft.{key}", ((2, 3),),
                                           "unit vectors in OA_l" if key == "sensitive_axes" else "m in S"))
        _set(self, "envelope_radius_m", _to_decimal(self.envelope_radius_m, "spacecraft.envelope_radius_m"))
        if isinstance(self.self_gravity, str):
            _require_choice(self.self_gravity, "spacecraft.self_gravity", SELF_GRAVITY_MODELS)
        else:
            _set(self, "self_gravity", _num_array(self.self_gravity, "spacecraft.self_gravity",
                                                  ((2, 3), (3, 2, 3)), "m/s^2 in OA_l", MAX_ACCELERATION))
        _set(self, "self_gravity_common", _num_array(self.self_gravity_common, "spacecraft.self_gravity_common",
                                                     ((3,), (3, 3)), "m/s^2 in S", MAX_ACCELERATION))
        if self.self_gravity_center is not None:
            _set(self, "self_gravity_center", _num_array(self.self_gravity_center, "spacecraft.self_gravity_center",
                                                         ((2,),), "m/s^2, positive toward the centre", MAX_ACCELERATION))
        span = self.self_gravity_center_span
        if span is not None:
            ok = isinstance(span, (list, tuple)) and len(span) == 2 and all(isinstance(x, str) for x in span)
            _require(ok, "spacecraft.self_gravity_center_span", span, "is not two dates",
                     '["START", "END"], ISO dates with an optional " UTC" (default) or " TDB" suffix')
            epochs = tuple(epoch_from_label(x, "spacecraft.self_gravity_center_span") for x in span)
            _require((epochs[1].tdb[0] - epochs[0].tdb[0]) + (epochs[1].tdb[1] - epochs[0].tdb[1]) > 0,
                     "spacecraft.self_gravity_center_span", list(span), "does not end after it starts",
                     "an end date after the start date")
            _set(self, "self_gravity_center_span", tuple(e.iso for e in epochs))
        self.craft()

    def craft(self, self_gravity=None):
        """The :class:`tqdyn.constellation.spacecraft.Spacecraft` of this
        configuration (``self_gravity``: (3, 2, 3) m/s^2 in OA_l or None for
        Table IV).  ScenarioError naming the TOML key for an architecture
        the spacecraft model refuses (a TM outside the envelope, dependent
        sensitive axes, a scheme that does not fit)."""
        import numpy as np

        from ..constellation.spacecraft import ArchitectureError, Spacecraft

        def arr(x):
            return None if x is None else np.array(x, dtype=np.float64)

        kw = dict(scheme=self.dragfree, self_gravity=self_gravity, sensitive_axes=arr(self.sensitive_axes),
                  envelope_radius=float(self.envelope_radius_m))
        try:
            if self.architecture == "tianqin":
                craft = Spacecraft.preset("tianqin", d_tm=float(self.d_tm_m), d_p=float(self.d_p_m),
                                          tm_axis=self.tm_axis, **kw)
            else:
                craft = Spacecraft.preset(self.architecture, tm_distance=float(self.tm_distance_m), **kw)
            if self.housing_centers is not None or self.pivots is not None:
                r0 = arr(self.housing_centers) if self.housing_centers is not None else craft.nominal_housing_centers
                piv = arr(self.pivots) if self.pivots is not None else r0
                craft = Spacecraft(housing_centers_nominal=r0, pivot_points=piv, architecture=self.architecture,
                                   **kw)
        except ArchitectureError as exc:
            key = _CRAFT_KEYS.get(exc.field, exc.field)
            given = getattr(self, key, None)  # the value as the scenario gives it, if it does
            value = given if given is not None else exc.value
            raise ScenarioError(f"spacecraft.{key}", value if len(_fmt(value)) <= 40 else _NOVALUE, exc.problem,
                                exc.allowed) from None
        return craft

    def self_gravity_values(self):
        """(oa, common): float64 arrays (3, 2, 3) [m/s^2, OA_l] and (3, 3) [m/s^2, S]."""
        import numpy as np

        if self.self_gravity == "off":
            oa = np.zeros((3, 2, 3))
        elif self.self_gravity == "table-iv":
            oa = None
        else:
            oa = np.broadcast_to(np.array(self.self_gravity, dtype=np.float64), (3, 2, 3)).copy()
        common = np.broadcast_to(np.array(self.self_gravity_common, dtype=np.float64), (3, 3)).copy()
        return oa, common
