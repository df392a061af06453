"""The H-infinity design option against the per-loop design, and their robustness Monte Carlo
(docs/closed-loop.md#a-multivariable-design).

For TianQin, LISA and Taiji at their static working points: both designs built
(:func:`tqdyn.workflows.closed_loop_mc.monte_carlo` builds them; the synthesis once per mission), the nominal
loop's stability, margins and requirement ratio (:func:`tqdyn.closedloop.robust.evaluate`), the synthesis'
gamma and time, then N draws of the uncertain parameters evaluated with both designs on a local Dask cluster
(or ``--scheduler``).

Usage:
    python tools/closed_loop_hinf.py                       # writes docs/data/closed-loop-hinf.json (N = 40)
    python tools/closed_loop_hinf.py -n 4 --out /tmp/h.json --missions tianqin

Then ``python tools/render_docs.py`` (the section's numbers are markers into the record).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from tqdyn.closedloop.missions import CONSTELLATION_MISSIONS, requirement
from tqdyn.closedloop.robust import UNCERTAINTY, evaluate
from tqdyn.workflows.closed_loop_mc import _designs, monte_carlo, summarise
from tqdyn.workflows.numbers import provenance, write_record

ROOT = Path(__file__).resolve().parent.parent


def mission_record(mission: str, n: int, seed: int, scheduler, workers) -> dict:
    """The nominal numbers of both designs and the Monte Carlo's summary of ``mission``."""
    t0 = time.perf_counter()
    designs = _designs(mission, ())
    t_build = time.perf_counter() - t0
    nominal = {}
    for d, (model, ctl) in designs.items():
        p, wp = model.parts[0][0]
        nominal[d] = evaluate(p, wp, ctl, model.noise, requirement(mission), model.settings["attitude_z_sensor"])
    k = designs["hinf"][1]
    t1 = time.perf_counter()
    ds = monte_carlo(mission, n, seed, scheduler=scheduler, workers=workers)
    t_mc = time.perf_counter() - t1
    return {"gamma": k.gamma, "controller_order": k.order, "synthesis_s": k.synthesis_s, "build_s": t_build,
            "bandwidth_hz": sorted(set(round(b, 9) for b in k.bandwidth_hz)), "shift_rad_s": k.shift,
            "nominal": nominal, "monte_carlo": {"n": n, "seed": seed, "wall_s": t_mc,
                                                "evaluation_s": ds.attrs["evaluation_s"],
                                                "summary": summarise(ds)}}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=40, help="draws per mission")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--missions", default=",".join(CONSTELLATION_MISSIONS))
    ap.add_argument("--scheduler", default=None)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--out", default=str(ROOT / "docs" / "data" / "closed-loop-hinf.json"))
    args = ap.parse_args(argv)
    missions = {}
    for m in args.missions.split(","):
        missions[m] = mission_record(m, args.n, args.seed, args.scheduler, args.workers)
        print(m, json.dumps({k: v for k, v in missions[m].items() if k != "monte_carlo"}, default=str)[:400],
              flush=True)
    data = {**provenance("tools/closed_loop_hinf.py"), "uncertainty": {k: list(v) for k, v in UNCERTAINTY.items()},
            "missions": missions}
    write_record(args.out, data)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
