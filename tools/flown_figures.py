"""Make the figures of docs/closed-loop-validation.md, sections 4-6: LISA Pathfinder's Delta g, six-DOF
stability and in-loop coordinates, TianQin-1's residual acceleration, each beside the published values
(src/tqdyn/data/flight_results.toml).  The numbers quoted in the page come from the tests' record
(tests/test_closed_loop_flown.py), not from this script.

Run: python tools/flown_figures.py [--out docs/figures]   (needs matplotlib; ~15 s)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from tqdyn.analysis.figures_flown import plot_delta_g, plot_in_loop, plot_residual_single_tm, plot_stability
from tqdyn.closedloop.budget import closed_loop_response
from tqdyn.closedloop.controllers import lead_lag_pid, pi_controller
from tqdyn.closedloop.flight_observables import delta_g_budget, residual_acceleration_budget, stability_budget
from tqdyn.closedloop.flown import published_delta_g, published_flight_results
from tqdyn.closedloop.loop import build_closed_loop, source_inputs
from tqdyn.closedloop.model import static_closed_loop_model

ROOT = Path(__file__).resolve().parent.parent
#: In-loop coordinates of the collinear scheme: controller input -> (label, unit).
IN_LOOP = {"e_dragfree[0]": ("o1 (x, TM 1)", "m"), "e_suspension[0]": ("o12 (x2 - x1)", "m"),
           "e_dragfree[1]": ("y, TMs' mean", "m"), "e_dragfree[2]": ("z, TMs' mean", "m"),
           "e_attitude[0]": ("attitude about X (TMs)", "rad"), "e_attitude[1]": ("attitude about Y (z1 - z2)/L", "rad"),
           "e_attitude[2]": ("attitude about Z -(y1 - y2)/L", "rad"), "e_guidance[2]": ("star tracker about Z", "rad")}


def _in_loop(cl, noise, f) -> dict:
    """{label: ASD (n_f,)} of the in-loop coordinates, every noise source summed in power."""
    srcs = [s for s in noise]
    inputs = [x for s in srcs for x in source_inputs(s)]
    G = closed_loop_response(cl, f, list(IN_LOOP), inputs)
    asd = np.concatenate([np.tile(noise[s].asd(f), (len(source_inputs(s)), 1)) for s in srcs])
    return {IN_LOOP[k][0]: np.sqrt(np.sum(np.abs(G[i]) ** 2 * asd ** 2, axis=0)) for i, k in enumerate(IN_LOOP)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "figures"))
    args = ap.parse_args(argv)
    out = Path(args.out)
    pub = published_flight_results()
    f = np.logspace(-5, 0, 400)

    m = static_closed_loop_model("lpf")
    cl, p = m.loops[0][0][1], m.parts[0][0][0]
    b, sources = delta_g_budget(cl, p, m.noise, f)
    d = pub["lpf"]["delta_g"]
    points = [(x, d["floor"], "published floor 1.74 fm (2018), > 2 mHz") for x in (3e-3, 1e-2)]
    print(plot_delta_g(f, b, sources, published_delta_g(f, pub), points, out, "closed-loop-lpf-delta-g",
                       formats=("png",)))
    st, sources = stability_budget(cl, m.noise, f)
    s_pub = pub["lpf"]["stability"]
    print(plot_stability(f, st, sources, {k: s_pub[k] for k in st}, s_pub["f_hz"], out,
                         "closed-loop-lpf-stability", formats=("png",)))
    asd = _in_loop(cl, m.noise, f)
    print(plot_in_loop(f, asd, {v[0]: v[1] for v in IN_LOOP.values()}, out, "closed-loop-lpf-in-loop",
                       formats=("png",)))

    t = static_closed_loop_model("tianqin-1")
    tcl = t.loops[0][0][1]
    r = pub["tianqin-1"]["residual_acceleration"]
    curves = {"model: drag-free PI at 50 mHz (default)": np.sqrt(np.sum(
        residual_acceleration_budget(tcl, t.noise, f)[0] ** 2, axis=0))}
    # the loop that the published ratio (residual / thruster noise at 10 mHz) implies: an integrator-dominated
    # PI (zero at its crossover) whose |S(10 mHz)| is the published 1/40; shown, not used
    target = r["value"] / r["thruster_noise"]
    s10 = 2j * math.pi * r["f_hz"]

    def excess(lf):
        c = pi_controller(10 ** lf, integrator_ratio=1.0)
        C = c.gain * np.prod(s10 - np.array(c.zeros)) / np.prod(s10 - np.array(c.poles))
        return math.log(abs(1 / (1 + C)) / target)

    fc = 10 ** brentq(excess, -2.5, 1.0)
    ctl = {**t.controllers, "dragfree": pi_controller(fc, integrator_ratio=1.0, name="dragfree"),
           "suspension": lead_lag_pid(10 * fc, name="suspension")}
    tp, twp = t.parts[0][0]
    implied = build_closed_loop(tp, twp, ctl, scheme="single_tm")
    curves[f"model: integrator loop, {fc:.2f} Hz (what the published 1/40 at 10 mHz implies)"] = np.sqrt(np.sum(
        residual_acceleration_budget(implied, t.noise, f)[0] ** 2, axis=0))
    fr = pub["tianqin-1"]["first_round"]
    tpoints = [(r["f_hz"], r["value"], "published: 5e-11 at 10 mHz (Xiao et al. 2022)"),
               (0.1, fr["with_dfc_at_0p1hz"], "published: 3e-9 at 0.1 Hz with drag-free (Luo et al. 2020)")]
    thr = t.noise["thruster_force"].asd(f) / tp.sc_mass
    print(plot_residual_single_tm(f, curves, tpoints, thr, out, "closed-loop-tianqin1-residual", formats=("png",)))
    print(f"implied loop crossover: {fc:.3f} Hz")


if __name__ == "__main__":
    main()
