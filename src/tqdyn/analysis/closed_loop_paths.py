"""Numbers for the docs: the default designs' margins and the paths from the DC working point to in-band noise.

The closed loops are evaluated here, not built: :func:`tqdyn.closedloop.loop.build_closed_loop` builds them
(with and without a part of the working point or the plant), :mod:`tqdyn.closedloop.budget` evaluates them.

:func:`dc_paths` splits the residual TM acceleration at a working point into the paths from the DC
forces, the cross-talk, the stiffness and the gravity gradient (``tqdyn report --closed-loop`` writes
them for the working points of coupled runs; docs/closed-loop.md renders them).
:func:`design_numbers` returns a JSON-ready dict of the same kind at first-principles working points
(:func:`tqdyn.closedloop.missions.representative_working_point`):
per mission, the loop-at-a-time margins of the default design at a representative working point, and
the residual TM acceleration along the sensitive axis at 1 and 10 mHz split into

* ``tm_force``: the TM force noise (LISA Pathfinder's per-TM level by default, the requirement curve in the "v0.3" preset);
* ``actuation_force``: force-proportional electrostatic actuation noise (level x the DC suspension m |A|),
  reaching the sensitive axis only through cross-talk (the scheme applies no force along it);
* ``crosstalk_commands``: the AC suspension commands leaking into the sensitive axis through cross-talk
  (the loop evaluated with and without cross-talk);
* ``stiffness``: the spacecraft-TM jitter x times the stiffness (the loop evaluated with and without it);
* ``gravity_gradient``: Gamma_xx x in the *relative* acceleration (the TM's own acceleration against its
  geodesic contains no tide: the tide is gravity).

Units: m/s^2/Hz^1/2 (one-sided), Hz, deg.
"""

from __future__ import annotations

import numpy as np

from ..closedloop.budget import closed_loop_response, loop_margins, noise_budget
from ..closedloop.loop import SOURCES, build_closed_loop, output_names, source_inputs
from ..closedloop.missions import (CONSTELLATION_MISSIONS, default_controllers, default_noise, default_plant,
                                   representative_plant, representative_working_point)
from ..closedloop.plant import PlantParameters, WorkingPoint, sensitive_basis

__all__ = ["DC_SUSPENSION_LIMIT", "dc_paths", "design_numbers"]

#: The paper's DC limit on the TM suspension acceleration [m/s^2] (TianQin's self-gravity requirement).
DC_SUSPENSION_LIMIT = 1e-10


def design_numbers(freqs=(1e-3, 1e-2)) -> dict:
    """The dict of the module docstring, for every mission."""
    out = {"asd": "one-sided", "units": {"acceleration": "m/s^2/Hz^1/2", "margin_deg": "deg", "f": "Hz"},
           "frequencies_hz": list(freqs), "missions": {}}
    f = np.asarray(freqs, dtype=np.float64)
    i_acc = output_names().index("tm1_acceleration")
    i_rel = output_names().index("tm1_relative_acceleration")
    i_x = output_names().index("tm1_sc_jitter")
    for mission in CONSTELLATION_MISSIONS:
        wp = representative_working_point(mission)
        ctl = default_controllers(mission)
        noise = default_noise(mission)
        p = representative_plant(mission)
        cl = build_closed_loop(p, wp, ctl)
        b, sources = noise_budget(cl, noise, f)
        total = np.sqrt(np.sum(b ** 2, axis=1))
        no_xt = noise_budget(build_closed_loop(representative_plant(mission, crosstalk=0.0), wp, ctl), noise, f)[0]
        no_k = noise_budget(build_closed_loop(representative_plant(mission, stiffness=(0.0, 0.0, 0.0)), wp, ctl),
                            noise, f)[0]
        tot_xt = np.sqrt(np.sum(no_xt ** 2, axis=1))
        tot_k = np.sqrt(np.sum(no_k ** 2, axis=1))
        jitter = total[i_x]
        k_x = abs(default_plant(mission)["stiffness"][0])
        margins = {m.channel: {"phase_margin_deg": round(m.phase_margin, 2), "crossover_hz": m.f_phase_margin,
                               "gain_margin": m.gain_margin, "gain_margin_hz": m.f_gain_margin}
                   for m in loop_margins(cl)}
        out["missions"][mission] = {
            "tm_acceleration_total": total[i_acc].tolist(),
            "by_source": {s: b[i_acc, j].tolist() for j, s in enumerate(sources)},
            "actuation_force": b[i_acc, sources.index("actuation_force")].tolist(),
            "crosstalk_commands": np.sqrt(np.maximum(total[i_acc] ** 2 - tot_xt[i_acc] ** 2, 0.0)).tolist(),
            "stiffness": np.sqrt(np.maximum(total[i_acc] ** 2 - tot_k[i_acc] ** 2, 0.0)).tolist(),
            "stiffness_times_jitter": (k_x * jitter).tolist(),
            "gravity_gradient_relative": (abs(wp.gamma[1, 1]) * jitter).tolist(),
            "sc_tm_jitter_m": jitter.tolist(),
            "relative_acceleration_total": total[i_rel].tolist(),
            "dc_suspension_max": float(np.max(np.abs(wp.a_suspension))),
            "gamma_s2": float(wp.gamma[0, 0]),
            "margins": margins,
        }
    return out


def _path(cl, p, wp, ctl, noise, f, azs, output):
    """ASD [output unit/Hz^1/2] of the part of ``output`` that the closed loop ``cl`` has and the loop of
    (``p``, ``wp``) has not: per source input the difference of the two transfer functions (coherent, so
    that a path is measured alone, not through the cross terms of a power difference), summed in power."""
    other = build_closed_loop(p, wp, ctl, azs)
    sources = [s for s in SOURCES if s in noise]
    inputs = [x for s in sources for x in source_inputs(s)]
    dG = (closed_loop_response(cl, f, [output], inputs) - closed_loop_response(other, f, [output], inputs))[0]
    asd = np.concatenate([np.tile(noise[s].asd(f), (SOURCES[s][0], 1)) for s in sources])
    return np.sqrt(np.sum(np.abs(dG) ** 2 * asd ** 2, axis=0))


def dc_paths(p: PlantParameters, wp: WorkingPoint, controllers: dict, noise: dict, f, tm: int = 1,
             limit: float = DC_SUSPENSION_LIMIT, attitude_z_sensor: str = "dws") -> dict:
    """How the DC working point reaches the residual acceleration of TM ``tm`` (1 or 2) along its sensitive
    axis at frequencies ``f`` [Hz]: a JSON-ready dict of ASDs [m/s^2/Hz^1/2, one-sided], lists over ``f``.

    ``total``; the sources ``tm_force``, ``actuation_force`` (fractional electrostatic noise x the DC
    suspension m |A|, through cross-talk), ``thruster_gain`` (fractional thrust noise x the DC thrust
    M |G|); ``dc_forces`` (every path that scales with the DC forces: the loop evaluated with and
    without A, alpha, G and the self-gravity); ``crosstalk`` (every path through the actuation
    cross-talk: the AC commands and the actuation noise; the loop with and without cross-talk);
    ``stiffness`` (with and without stiffness; each "with and without" is the coherent difference of
    the two loops' transfer functions per source, summed in power) next to ``stiffness_times_jitter`` (|K_e| x the
    spacecraft-TM jitter); ``gravity_gradient_relative`` (|e.Gamma.e| x the jitter, in the *relative*
    acceleration only: the tide is gravity); ``sc_tm_jitter_m`` [m/Hz^1/2].  At the limit: the same
    loop with the DC suspension scaled so that its largest component is ``limit`` [m/s^2] (its
    pattern kept; a working point without suspension gets ``limit`` along p_l):
    ``actuation_force_at_limit``, ``dc_forces_at_limit``.  Scalars: ``dc_suspension_max`` [m/s^2],
    ``dc_thrust_max`` = max |G| [m/s^2], ``gamma_sensitive`` = e.Gamma.e [s^-2], ``stiffness_sensitive``
    [s^-2], ``limit`` [m/s^2]."""
    from dataclasses import replace

    from ..constellation.control import oa_rotation

    f = np.asarray(f, dtype=np.float64)
    names = output_names()
    i_acc, i_x = names.index(f"tm{tm}_acceleration"), names.index(f"tm{tm}_sc_jitter")
    cl = build_closed_loop(p, wp, controllers, attitude_z_sensor)
    b, sources = noise_budget(cl, noise, f, outputs=[names[i_acc], names[i_x]])
    total = np.sqrt(np.sum(b ** 2, axis=1))
    zero = np.zeros_like
    acc = names[i_acc]
    no_dc = replace(wp, a_suspension=zero(wp.a_suspension), alpha_suspension=zero(wp.alpha_suspension),
                    a_dragfree=zero(wp.a_dragfree), self_gravity=zero(wp.self_gravity))
    args = (controllers, noise, f, attitude_z_sensor, acc)
    A = np.asarray(wp.a_suspension, dtype=np.float64)
    a_max = float(np.max(np.abs(A)))
    basis = sensitive_basis(p)
    A_lim = A * (limit / a_max) if a_max > 0 else np.array([limit * basis[l, 1] for l in range(2)])
    wp_lim = replace(wp, a_suspension=A_lim)
    cl_lim = build_closed_loop(p, wp_lim, controllers, attitude_z_sensor)
    b_lim, _ = noise_budget(cl_lim, noise, f, outputs=[acc])
    no_dc_lim = replace(wp_lim, a_suspension=zero(A_lim), alpha_suspension=zero(wp.alpha_suspension),
                        a_dragfree=zero(wp.a_dragfree), self_gravity=zero(wp.self_gravity))
    e_S = np.transpose(oa_rotation(wp.theta), (0, 2, 1))[tm - 1] @ basis[tm - 1, 0]
    gamma_e = float(e_S @ np.asarray(wp.gamma, dtype=np.float64) @ e_S)
    k_e = float(np.asarray(p.stiffness, dtype=np.float64)[tm - 1] @ basis[tm - 1, 0] ** 2)   # diagonal K in OA_l
    jitter = total[1]
    src = {s: b[0, j] for j, s in enumerate(sources)}
    act = src.get("actuation_force", zero(f))
    return {
        "total": total[0].tolist(),
        "tm_force": src.get("tm_force", zero(f)).tolist(),
        "actuation_force": act.tolist(),
        "thruster_gain": src.get("thruster_gain", zero(f)).tolist(),
        "dc_forces": _path(cl, p, no_dc, *args).tolist(),
        "crosstalk": _path(cl, replace(p, crosstalk=0.0), wp, *args).tolist(),
        "stiffness": _path(cl, replace(p, stiffness=zero(p.stiffness)), wp, *args).tolist(),
        "stiffness_times_jitter": (abs(k_e) * jitter).tolist(),
        "gravity_gradient_relative": (abs(gamma_e) * jitter).tolist(),
        "sc_tm_jitter_m": jitter.tolist(),
        "actuation_force_at_limit": b_lim[0, sources.index("actuation_force")].tolist()
        if "actuation_force" in sources else zero(f).tolist(),
        "dc_forces_at_limit": _path(cl_lim, p, no_dc_lim, *args).tolist(),
        "dc_suspension_max": a_max,
        "dc_thrust_max": float(np.max(np.abs(np.asarray(wp.a_dragfree, dtype=np.float64)))),
        "gamma_sensitive": gamma_e,
        "stiffness_sensitive": k_e,
        "limit": float(limit),
    }
