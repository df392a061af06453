"""Numbers for the docs: the default designs' margins and the paths from the DC working point to in-band noise.

:func:`design_numbers` returns a JSON-ready dict (docs/closed-loop.md renders it; a test checks it):
per mission, the loop-at-a-time margins of the default design at a representative working point, and
the residual TM acceleration along the sensitive axis at 1 and 10 mHz split into

* ``tm_force``: the TM force noise (the requirement curve by default);
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

import math

import numpy as np

from .budget import closed_loop_response, loop_margins, noise_budget
from .loop import build_closed_loop, output_names
from .missions import MISSIONS, default_controllers, default_noise, default_plant
from .plant import PlantParameters, WorkingPoint

__all__ = ["design_numbers", "representative_working_point"]


def representative_working_point(mission: str, self_gravity=None) -> WorkingPoint:
    """A working point of ``mission`` from first principles: the central body's tide at the orbit
    (TianQin: GM_E/r^3 at r = 1e8 m; LISA/Taiji: GM_S/(1 au)^3) in a frame turning at the orbital rate
    about Z_S, theta = 60 deg, DC suspension from the self-gravity (default Table IV; the nominal
    scheme puts the differences dg_y, dg_z on the TMs: A_1 = -A_2 = (0, dg_y/(2 cos 30), dg_z/2)
    along Y_OA, Z), no drag-free DC acceleration along the sensitive axes.  SI units, S / OA_l frames."""
    from ..constellation.control import dragfree_general, oa_rotation
    from ..constellation.spacecraft import TABLE_IV_SELF_GRAVITY

    gm, r = (3.986004415e14, 1e8) if mission == "tianqin" else (1.32712440041e20, 1.495978707e11)
    n2 = gm / r ** 3
    sg = TABLE_IV_SELF_GRAVITY if self_gravity is None else np.asarray(self_gravity)
    T = oa_rotation(math.pi / 3)
    g_S = np.einsum("lji,lj->li", T, sg)
    G, A = dragfree_general(g_S, math.pi / 3)
    return WorkingPoint(gamma=np.diag([2 * n2, -n2, -n2]), omega=np.array([0.0, 0.0, math.sqrt(n2)]),
                        omega_dot=np.zeros(3), theta=math.pi / 3, theta_dot=0.0, a_suspension=A,
                        alpha_suspension=np.zeros((2, 3)), a_dragfree=G, self_gravity=sg)


def _plant(mission: str, **over) -> PlantParameters:
    from ..constellation.spacecraft import Spacecraft

    sc = Spacecraft.preset(mission)
    d = {**default_plant(mission), **over}
    return PlantParameters(sc_mass=d["sc_mass"], sc_inertia=d["sc_inertia"], tm_mass=d["tm_mass"],
                           tm_side=d["tm_side"], mosa_inertia=d["mosa_inertia"], mosa_stiffness=d["mosa_stiffness"],
                           stiffness=np.tile(d["stiffness"], (2, 1)),
                           rotational_stiffness=np.tile(d["rotational_stiffness"], (2, 1)), crosstalk=d["crosstalk"],
                           housing_centers=sc.housing_centers(math.pi / 3), lever_arms=sc.lever_arms(math.pi / 3),
                           sensitive_axes=sc.sensitive_axes_array)


def design_numbers(freqs=(1e-3, 1e-2)) -> dict:
    """The dict of the module docstring, for every mission."""
    out = {"asd": "one-sided", "units": {"acceleration": "m/s^2/Hz^1/2", "margin_deg": "deg", "f": "Hz"},
           "frequencies_hz": list(freqs), "missions": {}}
    f = np.asarray(freqs, dtype=np.float64)
    i_acc = output_names().index("tm1_acceleration")
    i_rel = output_names().index("tm1_relative_acceleration")
    i_x = output_names().index("tm1_sc_jitter")
    for mission in MISSIONS:
        wp = representative_working_point(mission)
        ctl = default_controllers(mission)
        noise = default_noise(mission)
        p = _plant(mission)
        cl = build_closed_loop(p, wp, ctl)
        b, sources = noise_budget(cl, noise, f)
        total = np.sqrt(np.sum(b ** 2, axis=1))
        no_xt = noise_budget(build_closed_loop(_plant(mission, crosstalk=0.0), wp, ctl), noise, f)[0]
        no_k = noise_budget(build_closed_loop(_plant(mission, stiffness=(0.0, 0.0, 0.0)), wp, ctl), noise, f)[0]
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


_ = closed_loop_response
