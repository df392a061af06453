"""What is propagated: the scenario's constellation as the compiled system's parameters.

:func:`build_system` turns a scenario into a :class:`System`: the mode of
:func:`tqdyn.dynamics.rhs.system_rhs` (independent point masses, the coupled
drag-free constellation, or its free-TM verification mode) and the packed
constellation parameters (:mod:`tqdyn.dynamics.layout`): pointing law,
control switch, spacecraft geometry, self-gravity, and the jerk model of the
local pointing laws (the Moon's and Sun's tidal jerks from their ephemeris
states, the Earth's J2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..astro.constants import C_LIGHT
from ..astro.ephemeris import planetary_gm
from ..astro.timescales import tdb_jd
from ..constellation._kinematics_jit import LAW_CODES
from ..constellation.spacecraft import TABLE_IV_SELF_GRAVITY, Spacecraft
from ..forces.earth import EarthField
from ..forces.model import ForceModel, _ephemeris, build_force_model
from . import layout as _lay

__all__ = ["System", "build_system", "centre_ramp", "self_gravity_oa"]


@dataclass(frozen=True)
class System:
    """What is propagated: the mode of :func:`tqdyn.dynamics.rhs.system_rhs` and its parameters.

    cpar : (layout.CP_LEN,) float64 constellation parameters (mode, pointing
    law, control switch, spacecraft geometry, self-gravity; :mod:`.layout`);
    coupled : attitude/control diagnostics are produced (pointing != "none");
    free_tms : the six TMs are propagated as bodies 3..8.
    """

    cpar: np.ndarray
    coupled: bool
    free_tms: bool
    ephemeris: object = None
    centre_ramp: tuple | None = None

    def with_inputs(self, model: ForceModel):
        """The force model, extended by the system's own time-only inputs
        (the Moon's and Sun's states for the jerk of the local pointing
        laws; the magnitude of the self-gravity toward the constellation
        centre) when it needs any; see :class:`_SystemInputs`."""
        if (self.ephemeris is None and self.centre_ramp is None) or isinstance(model, _SystemInputs):
            return model
        return _SystemInputs(model, self)


class _SystemInputs:
    """A force model whose time-only inputs are followed by the coupled
    system's: geocentric GCRS position [m] and velocity [m/s] of the Moon and
    the Sun (at TDB(t)), :data:`tqdyn.dynamics.layout.N_SYSTEM_TDAT` columns starting at
    the force model's ``n_tdat`` (= ``cpar[CP_TD]``).  Everything else is the
    force model's."""

    def __init__(self, model: ForceModel, system: System):
        self._model = model
        self._system = system
        self.n_tdat = (model.n_tdat + (_lay.N_SYSTEM_TDAT if system.ephemeris is not None else 0)
                       + (1 if system.centre_ramp is not None else 0))

    def __getattr__(self, name):
        return getattr(self._model, name)

    @property
    def time_dependent(self) -> bool:
        return True

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        cols = [self._model.precompute(epoch, t_hi, t_lo)]
        if self._system.ephemeris is not None:
            jd1, jd2 = tdb_jd(epoch, t_hi, t_lo)
            pos, vel = self._system.ephemeris.geocentric_states(_lay.SYSTEM_TDAT_BODIES, jd1, jd2, velocity=True)
            cols.append(np.concatenate([pos, vel], axis=-1).reshape(np.shape(t_hi) + (_lay.N_SYSTEM_TDAT,)))
        if self._system.centre_ramp is not None:
            cols.append(centre_ramp(self._system.centre_ramp, np.asarray(t_hi) + np.asarray(t_lo))[..., None])
        return np.concatenate(cols, axis=-1)


def centre_ramp(ramp, t) -> np.ndarray:
    """Magnitude [m/s^2] (positive toward the constellation centre) of the
    self-gravity ramp ``(g_start, g_end, t_start, t_end)`` at t [s since the
    epoch, the run's time scale]: linear from g_start at t_start to g_end at
    t_end, held at the end values outside; float64 of the shape of t."""
    g0, g1, t0, t1 = ramp
    return g0 + (g1 - g0) * np.clip((np.asarray(t, dtype=np.float64) - t0) / (t1 - t0), 0.0, 1.0)


def self_gravity_oa(scenario) -> np.ndarray:
    """DC self-gravity of the scenario's TMs, (3, 2, 3) [m/s^2] in OA_l."""
    oa, _ = scenario.spacecraft.self_gravity_values()
    return np.broadcast_to(TABLE_IV_SELF_GRAVITY, (3, 2, 3)).copy() if oa is None else oa


def build_system(scenario, model: ForceModel | None = None) -> System:
    """The :class:`System` of a scenario (point masses unless
    ``constellation.pointing`` names a law).  ``model``: the scenario's force
    model (built if None), whose time-only inputs the system's follow."""
    c = scenario.constellation
    if not c.coupled:
        ramp = scenario.self_gravity_centre_ramp()
        if ramp is None:
            return System(_lay.make_cpar(_lay.MODE_POINT_MASS), False, False)
        model = build_force_model(scenario.forces, scenario.reference) if model is None else model
        return System(_lay.make_cpar(_lay.MODE_POINT_MASS, centre_column=model.n_tdat), False, False,
                      centre_ramp=ramp)
    sc = scenario.spacecraft
    craft = Spacecraft(d_tm=float(sc.d_tm_m), d_p=float(sc.d_p_m), tm_axis=sc.tm_axis)
    _, common = sc.self_gravity_values()
    mode = _lay.MODE_FREE_TM if c.free_tms else _lay.MODE_COUPLED
    # jerk model of the local laws: the Moon / Sun tidal terms and J2 that the force model has
    f = scenario.forces
    law = LAW_CODES[c.pointing]
    bodies = [b for b in _lay.SYSTEM_TDAT_BODIES if b in f.third_bodies] if law else []
    eph = _ephemeris(f.ephemeris) if bodies else None
    gms = planetary_gm() if bodies else {}
    if law and model is None:
        model = build_force_model(f, scenario.reference)
    earth = next((t for t in model.terms if isinstance(t, EarthField)), None) if law else None
    j2k = earth.j2_jerk_coefficient() if earth is not None else 0.0
    cpar = _lay.make_cpar(mode, law=law, control=c.control == "on",
                          gm=float(f.gm_earth), c=C_LIGHT, d_p=craft.d_p,
                          theta_nom=craft.theta_nominal, r0_nom=craft.nominal_housing_centers,
                          sg_oa=self_gravity_oa(scenario), sg_s=common,
                          gm_moon=gms.get("moon", 0.0), gm_sun=gms.get("sun", 0.0), j2k=j2k,
                          tdat_offset=model.n_tdat if eph is not None else -1)
    return System(cpar, True, c.free_tms, eph)

