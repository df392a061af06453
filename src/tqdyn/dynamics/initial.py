"""Initial states of a propagation (satellites from their elements, free TMs at their housings)."""

from __future__ import annotations

import numpy as np

from ..astro import elements as _el
from ..forces.model import ForceModel, build_force_model
from . import layout as _lay
from .rhs import evaluate_rhs
from .system import System, build_system

__all__ = ["central_gm", "initial_state", "satellite_states"]


def central_gm(scenario) -> str:
    """GM [m^3/s^2] of the central body's monopole as an exact decimal
    string: ``forces.gm_earth`` (geocentric) or ``forces.gm_sun``
    (heliocentric)."""
    if scenario.central_body == "sun":
        return str(scenario.forces.gm_sun)
    return str(scenario.forces.gm_earth)


def satellite_states(scenario) -> list:
    """Initial positions [m] and velocities [m/s] of the satellites, relative
    to the central body, ICRF axes (GCRS or BCRS of the scenario's reference
    system), at the epoch: a list of (r, v), 3 mpmath numbers each (working
    precision of :mod:`tqdyn.astro.elements`).  Keplerian elements use the
    central GM (:func:`central_gm`); elements and Cartesian states in
    ``initial.axes = "ecliptic"`` are rotated to ICRF exactly."""
    import mpmath
    from mpmath import mpf

    gm = central_gm(scenario)
    rot = None
    if scenario.initial.axes == "ecliptic":
        from ..astro.constellation_design import ecliptic_to_icrf_matrix

        rot = ecliptic_to_icrf_matrix()
    out = []
    with mpmath.workdps(60):
        for sat in scenario.satellites:
            if sat.cartesian:
                r, v = [mpf(str(x)) for x in sat.r_m], [mpf(str(x)) for x in sat.v_mps]
            else:
                r, v = _el.elements_to_state(sat.a_m, sat.e, _el.deg(sat.i_deg), _el.deg(sat.raan_deg),
                                             _el.deg(sat.argp_deg), _el.deg(sat.nu_deg), gm)
            if rot is not None:
                r = [sum(rot[i][j] * r[j] for j in range(3)) for i in range(3)]
                v = [sum(rot[i][j] * v[j] for j in range(3)) for i in range(3)]
            out.append((r, v))
    return out


def initial_state(scenario, model: ForceModel | None = None, system: System | None = None) -> np.ndarray:
    """Initial GCRS states as a dd array (n_body, 6, 2): rows x, y, z [m],
    vx, vy, vz [m/s].  Satellites: exact elements converted in mpmath and
    rounded once to dd.  With free TMs (bodies 3 + 2 i + l) the TMs start
    at their EH centers with the EH centers' velocities (from the nominal
    attitude at t = 0, which needs the force model)."""
    y = np.stack([_el.state_to_dd(r, v) for r, v in satellite_states(scenario)])
    system = build_system(scenario, model) if system is None else system
    if not system.free_tms:
        return y
    model = system.with_inputs(build_force_model(scenario.forces, scenario.reference) if model is None else model)
    cpar = system.cpar.copy()
    cpar[_lay.CP_MODE] = _lay.MODE_COUPLED
    tdat = (model.precompute(scenario.epoch, np.zeros(1), np.zeros(1))[0]
            if model.time_dependent else np.zeros(0))
    _, aux = evaluate_rhs(y, tdat, model, cpar, with_aux=True)
    v = _lay.aux_views(aux)
    tm = np.zeros((6, 6, 2))
    tm[:, 0:3, 0] = v["tm_r_hi"].reshape(6, 3)
    tm[:, 0:3, 1] = v["tm_r_lo"].reshape(6, 3)
    tm[:, 3:6, 0] = v["tm_v_hi"].reshape(6, 3)
    tm[:, 3:6, 1] = v["tm_v_lo"].reshape(6, 3)
    return np.concatenate([y, tm])
