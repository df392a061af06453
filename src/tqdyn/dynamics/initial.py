"""Initial states of a propagation (satellites from their elements, free TMs at their housings)."""

from __future__ import annotations

import numpy as np

from ..astro import elements as _el
from ..astro.timescales import Epoch
from ..forces.model import ForceModel, build_force_model
from . import layout as _lay
from .rhs import evaluate_rhs
from .system import System, build_system

__all__ = ["initial_state"]


def initial_state(scenario, model: ForceModel | None = None, system: System | None = None) -> np.ndarray:
    """Initial GCRS states as a dd array (n_body, 6, 2): rows x, y, z [m],
    vx, vy, vz [m/s].  Satellites: exact elements converted in mpmath and
    rounded once to dd.  With free TMs (bodies 3 + 2 i + l) the TMs start
    at their EH centers with the EH centers' velocities (from the nominal
    attitude at t = 0, which needs the force model)."""
    gm = scenario.forces.gm_earth
    rows = []
    for sat in scenario.satellites:
        r, v = _el.elements_to_state(sat.a_m, sat.e, _el.deg(sat.i_deg), _el.deg(sat.raan_deg),
                                     _el.deg(sat.argp_deg), _el.deg(sat.nu_deg), gm)
        rows.append(_el.state_to_dd(r, v))
    y = np.stack(rows)
    system = build_system(scenario, model) if system is None else system
    if not system.free_tms:
        return y
    model = system.with_inputs(build_force_model(scenario.forces, scenario.reference) if model is None else model)
    cpar = system.cpar.copy()
    cpar[_lay.CP_MODE] = _lay.MODE_COUPLED
    tdat = (model.precompute(Epoch.from_utc(scenario.epoch_utc), np.zeros(1), np.zeros(1))[0]
            if model.time_dependent else np.zeros(0))
    _, aux = evaluate_rhs(y, tdat, model, cpar, with_aux=True)
    v = _lay.aux_views(aux)
    tm = np.zeros((6, 6, 2))
    tm[:, 0:3, 0] = v["tm_r_hi"].reshape(6, 3)
    tm[:, 0:3, 1] = v["tm_r_lo"].reshape(6, 3)
    tm[:, 3:6, 0] = v["tm_v_hi"].reshape(6, 3)
    tm[:, 3:6, 1] = v["tm_v_lo"].reshape(6, 3)
    return np.concatenate([y, tm])
