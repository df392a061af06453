"""What is propagated: the scenario's constellation as the compiled system's parameters.

:func:`build_system` turns a scenario into a :class:`System`: the mode of
:func:`tqdyn.dynamics.rhs.system_rhs` (independent point masses, the coupled
drag-free constellation, or its free-TM verification mode) and the packed
constellation parameters (:mod:`tqdyn.dynamics.layout`): pointing law,
control switch, spacecraft geometry, self-gravity, and the jerk model of the
local pointing laws (the tidal jerks of the third bodies from their
ephemeris states -- geocentric: the Moon and the Sun; heliocentric: every
third body of the force model -- and the Earth's J2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..astro.constants import C_LIGHT
from ..constellation._kinematics_jit import LAW_CODES
from ..constellation.spacecraft import TABLE_IV_SELF_GRAVITY, Spacecraft
from ..forces.earth import EarthField
from ..forces.body_gms import body_gms
from ..astro.ephemeris import ephemeris_named
from ..forces.model import ForceModel, build_force_model
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
    jerk_bodies: tuple = ()
    reference: object = None
    spacecraft: Spacecraft | None = None

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
    system's: the position [m] and velocity [m/s] relative to the central
    body of each jerk body (:attr:`System.jerk_bodies`; geocentric GCRS
    Moon and Sun at TDB(t), or Sun-centred BCRS bodies at the TDB axis), 6
    columns each starting at the force model's ``n_tdat`` (= ``cpar[CP_TD]``),
    then the self-gravity ramp.  Everything else is the force model's."""

    def __init__(self, model: ForceModel, system: System):
        self._model = model
        self._system = system
        self.n_tdat = (model.n_tdat + (6 * len(system.jerk_bodies) if system.ephemeris is not None else 0)
                       + (1 if system.centre_ramp is not None else 0))

    def __getattr__(self, name):
        return getattr(self._model, name)

    @property
    def time_dependent(self) -> bool:
        return True

    def precompute(self, epoch, t_hi, t_lo) -> np.ndarray:
        cols = [self._model.precompute(epoch, t_hi, t_lo)]
        sy = self._system
        if sy.ephemeris is not None:
            jd1, jd2 = sy.reference.ephemeris_jd(epoch, t_hi, t_lo)
            states = (sy.ephemeris.heliocentric_states if sy.reference.origin == "sun"
                      else sy.ephemeris.geocentric_states)
            pos, vel = states(sy.jerk_bodies, jd1, jd2, velocity=True)
            cols.append(np.concatenate([pos, vel], axis=-1).reshape(np.shape(t_hi) + (6 * len(sy.jerk_bodies),)))
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
    ``constellation.pointing`` names a law; point masses carry the acceleration
    parameters of ``[accelerations]``, :mod:`.empirical`).  ``model``: the scenario's force
    model (built if None), whose time-only inputs the system's follow."""
    c = scenario.constellation
    if not c.coupled:
        ramp = scenario.self_gravity_centre_ramp()
        acc = getattr(scenario, "accelerations", None)  # [accelerations]: the satellites' parameters
        emp = acc.values(len(scenario.satellites)) if acc is not None and acc.nonzero else None
        if ramp is None:
            return System(_lay.make_cpar(_lay.MODE_POINT_MASS, empirical=emp), False, False)
        model = build_force_model(scenario.forces, scenario.reference) if model is None else model
        return System(_lay.make_cpar(_lay.MODE_POINT_MASS, centre_column=model.n_tdat, empirical=emp), False, False,
                      centre_ramp=ramp)
    craft = scenario.spacecraft.craft(self_gravity_oa(scenario))
    _, common = scenario.spacecraft.self_gravity_values()
    mode = _lay.MODE_FREE_TM if c.free_tms else _lay.MODE_COUPLED
    # jerk model of the local laws: the tidal terms of the force model's third bodies (geocentric: the
    # Moon and the Sun; heliocentric: all of them) and the Earth's J2
    f, ref = scenario.forces, scenario.reference
    law = LAW_CODES[c.pointing]
    if ref.origin == "sun":
        bodies = tuple(f.third_bodies) if law else ()
    else:
        bodies = tuple(b for b in _lay.SYSTEM_TDAT_BODIES if b in f.third_bodies) if law else ()
    eph = ephemeris_named(f.ephemeris) if bodies else None
    gms = body_gms(f)  # the scenario's forces.gm_* [m^3/s^2]
    ramp = scenario.self_gravity_centre_ramp()
    if model is None and (law or ramp is not None):
        model = build_force_model(f, ref)
    earth = next((t for t in model.terms if isinstance(t, EarthField)), None) if law else None
    j2k = earth.j2_jerk_coefficient() if earth is not None else 0.0
    gm = float(gms["sun"]) if ref.origin == "sun" else float(f.gm_earth)
    centre = model.n_tdat + (6 * len(bodies) if eph is not None else 0) if ramp is not None else -1
    cpar = _lay.make_cpar(mode, law=law, control=c.control == "on", gm=gm, c=C_LIGHT,
                          scheme=_lay.SCHEME_CODES[craft.scheme], theta_nom=craft.theta_nominal,
                          r0_nom=craft.nominal_housing_centers, pivots=craft.pivots,
                          sensitive_axes=craft.sensitive_axes_array, sg_oa=craft.self_gravity_array, sg_s=common,
                          jerk_gms=[gms[b] for b in bodies], j2k=j2k,
                          gm_relativity=gm if (law and ref.origin == "sun" and f.relativity) else 0.0,
                          tdat_offset=model.n_tdat if eph is not None else -1, centre_column=centre,
                          tm_gravity=c.tm_gravity)
    return System(cpar, True, c.free_tms, eph, centre_ramp=ramp, jerk_bodies=bodies, reference=ref,
                  spacecraft=craft)
