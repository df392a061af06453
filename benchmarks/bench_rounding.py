"""Rounding of tqdyn's dd integrator over a long arc: the compiled dd DP87
run against the same DP87 run (identical dd-rounded coefficients and initial
state) in mpmath at 50 digits, circular r = 1e8 m orbit, 50 s steps.

The difference is the accumulated arithmetic rounding of the dd code alone.
Cost: the mpmath run takes ~0.9 ms per step (90 days: ~2.5 min).

Usage: python benchmarks/bench_rounding.py [--days 90]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import mpmath

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from mp_reference import DPS, GM, mp_dp87  # noqa: E402

from tqdyn import dynamics  # noqa: E402
from tqdyn.numerics import dp87  # noqa: E402
from tqdyn.numerics.dd import mp_from_dd  # noqa: E402
from tqdyn.scenario import loads_scenario  # noqa: E402

SCENARIO = """
[run]
duration = "{days}d"
[integrator]
step = 50
[forces]
gm_earth = {gm}
[[satellites]]
name = "Circ"
a_km = 100000
i_deg = 37.3
raan_deg = 123.4
nu_deg = 17.5
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--days", type=int, default=90)
    days = ap.parse_args().days
    scen = loads_scenario(SCENARIO.format(days=days, gm=GM))
    coef = dp87.step_coefficients(dp87.load_tableau(), scen.integrator.step_s, "dd")
    res = dynamics.propagate(scen, precision="dd")
    y0 = list(mp_from_dd(res.y0)[0])
    t0 = time.perf_counter()
    ref = mp_dp87(y0, "50", scen.n_steps, coef=coef)
    wall = time.perf_counter() - t0
    got = mp_from_dd(res.y_final)[0]
    with mpmath.workdps(DPS):
        dr = float(mpmath.sqrt(sum((got[q] - ref[q]) ** 2 for q in range(3))))
        dv = float(mpmath.sqrt(sum((got[q] - ref[q]) ** 2 for q in range(3, 6))))
    print(f"{days} days ({scen.n_steps} steps), circular r = 1e8 m, 50 s: "
          f"|r_dd - r_mpmath| = {dr:.2e} m, |v_dd - v_mpmath| = {dv:.2e} m/s "
          f"(mpmath reference {wall:.0f} s)")


if __name__ == "__main__":
    main()
